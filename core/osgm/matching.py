"""OSGM on one tile of one pyramid level: voxel costs, aggregation, selection.

The tile is a window of cells of a reference system's grid (cell centres
``(X, Y)``, Z levels ``z = z_base + a dz`` with an absolute level index
``a``). Every cell has its own search window of absolute levels ``[lo, hi]``
(the whole range on the coarsest level, a band around the coarser result
below). The cost volume holds ``nd`` levels per cell starting at ``z0``;
levels outside the cell's own window keep ``COST_MAX`` (no evidence) and are
never computed.

1. **Images**: those that see the tile (projections of a lattice of the tile
   at its lowest and highest Z inside the frame), at most ``max_images`` by
   coverage, then by the angle between their viewing ray and the system's Z
   axis; for each, the pyramid level whose pixel is closest to the cell size
   and the pixel window the tile can project into.
2. **Costs** per absolute level (a plane ``Z = const`` of the voxel grid),
   on the cells that search that level and the margin their windows read
   (:mod:`.sweep`, the default saturated-gradient measure: every image
   sampled there, all of them compared at once, mean of the best pairs:
   robust to the views that are occluded there; near a height step of the
   coarser surface, on the levels above the finest, the number of best pairs
   counts only the views that see the step's foot: :func:`hidden_views`); the other measures
   resample every image onto the bounding box of those cells
   (:func:`~.views.plane_map` + ``cv2.remap``) and call
   :func:`~truortho.core.sgm.multi_image_cost`. The gradients' saturation
   scale is one per image for the tile (:func:`.sweep.gradient_scales`).
3. :func:`~truortho.core.sgm.aggregate` along 8 or 16 paths in XY (P1, P2;
   P2 lowered across edges of a guide image: the images sampled on the
   coarser level's surface, median over the views; on slopes the levels follow a trend:
   :func:`slope_trend`, :func:`gentle_trend`), :func:`~truortho.core.sgm.select`
   (winner-take-all, equiangular sub-voxel fit, uniqueness, confidence), minima on the border
   of a cell's own window rejected (the surface lies outside it), and a
   NaN-aware median as an outlier test (:func:`median_outliers`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..geometry.camera import Camera
from ..jit import pjit, prange
from ..quickselect import nanmedian_axis0, select_rank
from ..sgm import COST_MAX, aggregate, median_filter, multi_image_cost, select, valid_cells
from .views import ImagePyramid, plane_map, project


@dataclass
class View:
    """An image in the frame of a reference system."""

    index: int  # position in the orientation (and the pyramid)
    R: np.ndarray
    C: np.ndarray
    camera: Camera
    r2max: float
    axis_cos: float  # cosine between its optical axis and the system's -Z (viewing) direction


@dataclass
class TileImage:
    view: View
    level: int
    origin: tuple[int, int]
    window: np.ndarray  # float32 matching band, NaN outside the image
    angle: float  # degrees between the viewing ray to the tile centre and the system's Z axis


@dataclass
class TileParams:
    radius: int
    measure: str
    p1: int
    p2: int
    paths: int
    uniqueness: float
    max_images: int
    max_view_angle: float
    median: int
    edges: bool = False  # refine the sides of height steps (:mod:`.edges`; the finest level only)
    rim_view_angle: float = 0.0  # steeper views, only where the others leave points short (0 = off)
    slope_max: int = 0  # SGM follows the coarser surface's slopes up to this many levels per cell (0 = off)
    adaptive_p2: bool = True  # P2 adapts to the image gradient of the coarser surface (needs ``guide_z``)
    occlusion_pairs: bool = False  # near a step of the coarser surface, best pairs of the views it leaves
    sub_level: bool = True  # the last aggregation follows the trend at sub-level precision


#: Cells of the box mean that smooths the coarser surface into the trend (:func:`slope_trend`).
TREND_SMOOTH = 5
#: Slopes (levels per cell) below which a cell keeps absolute levels: flat ground stays as before.
TREND_MIN_SLOPE = 0.2


def _box_mean(x: np.ndarray, ok: np.ndarray, size: int) -> np.ndarray:
    """Mean of ``x`` (0 where not ``ok``) over the ``ok`` cells of a ``size`` x ``size`` box; NaN
    where fewer than half of the box's cells are ``ok``."""
    from scipy.ndimage import uniform_filter

    num = uniform_filter(x, size, mode="nearest")
    den = uniform_filter(ok.astype(np.float64), size, mode="nearest")
    return np.where(den > 0.5, num / np.maximum(den, 1e-12), np.nan)


def _box_range(x: np.ndarray, ok: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray]:
    """Largest and smallest ``ok`` value of ``x`` in a ``size`` x ``size`` box (-inf, inf: none)."""
    from scipy.ndimage import maximum_filter, minimum_filter

    hi = maximum_filter(np.where(ok, x, -np.inf), size, mode="nearest")
    lo = minimum_filter(np.where(ok, x, np.inf), size, mode="nearest")
    return hi, lo


def slope_trend(
    guide_z: np.ndarray, z_base: float, dz: float, slope_max: int, real: bool = False
) -> np.ndarray:
    """The SGM trend (:func:`~truortho.core.sgm.aggregate`) of a tile from the coarser level's heights.

    Low-texture pitched roofs came out flattened towards their eaves (on battery scene 9 whole roofs
    0.5-1.3 m low): along a path P1 is paid at every level the slope climbs, and the data term of a
    weakly textured roof does not pay it back. The coarser level has seen the slope; the trend hands
    it on, so the finer level pays only for departing from it.

    The trend is the coarser surface smoothed over :data:`TREND_SMOOTH` cells, in levels. It is
    :data:`~truortho.core.sgm.TREND_NONE` (absolute levels, as without it) where the coarser
    surface is missing, where its slope is below :data:`TREND_MIN_SLOPE` levels per cell (flat
    ground: on scene 9, following the coarse level's noise there raised the ground's NMAD from
    0.24 to 0.41 GSD), and where its range over ``TREND_SMOOTH + 2`` cells exceeds what a plane of
    ``slope_max`` levels per cell spans (a height step: its smoothed ramp must not invite a ramp).

    That last rule took the trend from the lowest cells of every pitched roof, along its eaves, and
    P1 flattened them there: on the battery (master seed 99, scene 2) a 45-degree roof read
    6.3-6.4 m over its lowest 4-6 cells where the truth rises from 5.7 to 6.2 m; the raw cost of one
    such cell was lowest within 0.2 m of the true height, the aggregated one 0.55 m above it. On a
    step's high side such a cell continues the slope of the nearest cell that kept its trend
    (:func:`_eave_trend`).
    Measured with ``bench/osgm_battery.py`` on master seeds 2026 and 99: edge cells within 3 GSD up
    on 17 of 24 scenes (up to 2.3 points; seed 99 scene 2: 76.2 -> 78.4 %), down on 5 by at most
    0.5; flat3 within 0.2 points and NMAD within 0.004 GSD on every scene.

    ``real``: the trend before rounding, in levels (float64, NaN where there is none), for
    :func:`aggregate_with_trend`'s sub-level trend.
    """
    from ..sgm import TREND_NONE

    gz = np.asarray(guide_z, np.float64)
    if gz.ndim != 2:
        raise InputError(f"slope_trend: expected 2-D coarser heights, got shape {gz.shape}")
    if not (np.isfinite(dz) and dz > 0):
        raise InputError(f"slope_trend: dz must be a finite number > 0, got {dz!r}")
    if isinstance(slope_max, bool) or not isinstance(slope_max, int | np.integer) or slope_max < 0:
        raise InputError(f"slope_trend: slope_max must be an integer >= 0, got {slope_max!r}")
    ok = np.isfinite(gz)
    t = _box_mean(np.where(ok, gz, 0.0), ok, TREND_SMOOTH)
    t = (t - z_base) / dz
    gy, gx = np.gradient(np.nan_to_num(t, nan=0.0))
    span = TREND_SMOOTH + 2
    hi, lo = _box_range(gz, ok, span)
    flat_enough = hi - lo <= (span - 1) * slope_max * dz
    keep = np.isfinite(t) & (np.hypot(gx, gy) >= TREND_MIN_SLOPE) & flat_enough
    # next to a step, on its high side: the eaves of a roof
    with np.errstate(invalid="ignore"):  # hi + lo is -inf + inf only where no cell around is finite
        eaves = ok & np.isfinite(t) & ~flat_enough & (gz > 0.5 * (hi + lo))
    if keep.any() and eaves.any():
        zl = np.where(ok, (gz - z_base) / dz, np.nan)
        t, keep = _eave_trend(t, gx, gy, zl, keep, eaves, float(slope_max), span)
    if real:
        return np.where(keep, t, np.nan)
    return np.where(keep, np.rint(np.nan_to_num(t, nan=0.0)), TREND_NONE).astype(np.int32)


#: Cells of the box mean that smooths a tile's own heights into the surface its gentle slopes follow
#: (:func:`gentle_trend`).
GENTLE_SMOOTH = 9
#: Cells of the box mean whose slope decides whether a cell lies on a slope at all (:func:`gentle_trend`).
GENTLE_SLOPE_SPAN = 27
#: Slope (levels per cell, over :data:`GENTLE_SLOPE_SPAN` cells) from which a cell follows the gentle
#: trend: a level crossed at least every 20 cells.
GENTLE_MIN_SLOPE = 0.05


def gentle_trend(heights: np.ndarray, z_base: float, dz: float, trend: np.ndarray | None = None):
    """The surface that the levels of gentle slopes follow: ``(t, mask, level)``.

    ``t``: ``heights`` smoothed over :data:`GENTLE_SMOOTH` cells, in levels (real numbers).
    ``mask``: where it applies. That is where ``trend`` (:func:`slope_trend`, None: everywhere) has
    none, no height step lies within ``GENTLE_SMOOTH + 2`` cells (their range is at most what a
    slope of :data:`TREND_MIN_SLOPE` levels per cell spans, plus two levels), and the heights
    smoothed over :data:`GENTLE_SLOPE_SPAN` cells slope by :data:`GENTLE_MIN_SLOPE` or more.
    ``level``: level ground, the cells that meet every condition but the slope.

    Why: with absolute levels, SGM pays P1 wherever a gentle slope crosses a level and nowhere
    between, so its heights form terraces, one per level. They are thin lines along the contours
    in a hillshade (seed 5150 scene 10; denser with half the Z step, gone with a sixteenth of P1,
    which made the ground noisy). :func:`aggregate_with_trend` shifts the costs of the masked cells
    by ``t - rint(t)`` levels and gives them the trend ``rint(t)``. A level is then a surface
    parallel to ``t``, and P1 is paid only for departing from it.

    Why not on level ground: there the flat prior is right, and following the noise of a smoothed
    surface is not. On master seed 2026 scene 4 (flat, weakly textured ground) the NMAD of the
    ground rose from 0.16 to 0.24 GSD without the slope test. Its span averages that noise away.
    """
    from ..sgm import TREND_NONE

    gz = np.asarray(heights, np.float64)
    if gz.ndim != 2:
        raise InputError(f"gentle_trend: expected 2-D heights, got shape {gz.shape}")
    if not (np.isfinite(dz) and dz > 0):
        raise InputError(f"gentle_trend: dz must be a finite number > 0, got {dz!r}")
    if trend is not None and np.shape(trend) != gz.shape:
        raise InputError(f"gentle_trend: trend must be {gz.shape} like the heights, got {np.shape(trend)}")
    ok = np.isfinite(gz)
    zl = np.where(ok, (gz - z_base) / dz, 0.0)
    t = _box_mean(zl, ok, GENTLE_SMOOTH)
    gy, gx = np.gradient(np.nan_to_num(_box_mean(zl, ok, GENTLE_SLOPE_SPAN), nan=0.0))
    span = GENTLE_SMOOTH + 2
    hi, lo = _box_range(zl, ok, span)
    with np.errstate(invalid="ignore"):
        no_step = hi - lo <= (span - 1) * TREND_MIN_SLOPE + 2.0
    sloped = np.hypot(gx, gy) >= GENTLE_MIN_SLOPE
    mask = np.isfinite(t) & no_step & sloped
    level = np.isfinite(t) & no_step & ~sloped
    if trend is not None:
        mask &= np.asarray(trend) == TREND_NONE
        level &= np.asarray(trend) == TREND_NONE
    return np.where(mask, t, np.nan), mask, level


@pjit
def _shift_levels(cost, frac, out):
    """``out[r, c, k]``: the cost of level ``k + frac[r, c]`` (``|frac| <= 0.5``), linear between the
    levels of ``cost`` (the window's first/last level repeated beyond it)."""
    rows, cols, nd = cost.shape
    for r in prange(rows):
        for c in range(cols):
            f = frac[r, c]
            a = abs(f)
            s = 1 if f > 0.0 else -1
            for k in range(nd):
                if a == 0.0:
                    out[r, c, k] = cost[r, c, k]
                else:
                    k2 = min(nd - 1, max(0, k + s))
                    out[r, c, k] = np.uint16((1.0 - a) * cost[r, c, k] + a * cost[r, c, k2] + 0.5)


def shift_levels(cost: np.ndarray, frac: np.ndarray) -> np.ndarray:
    """The cost volume resampled ``frac`` (rows, cols) levels up: ``out[..., k]`` is the cost at level
    ``k + frac`` (linear between levels; ``|frac| <= 0.5``)."""
    c = np.ascontiguousarray(cost)
    f = np.ascontiguousarray(frac, np.float64)
    if c.ndim != 3 or c.dtype != np.uint16 or f.shape != c.shape[:2]:
        raise InputError(
            f"shift_levels: expected a uint16 (rows, cols, nd) volume and (rows, cols) offsets, got "
            f"{c.dtype} {c.shape} and {f.shape}"
        )
    if not (np.isfinite(f).all() and np.abs(f).max(initial=0.0) <= 0.5):
        raise InputError("shift_levels: offsets must be finite and within [-0.5, 0.5] levels")
    out = np.empty_like(c)
    _shift_levels(c, f, out)
    return out


#: Cells over which the sub-level offsets of :func:`aggregate_with_trend` fade out towards the cells
#: without a trend (:func:`_taper`).
SUB_LEVEL_TAPER = 4


def _taper(level: np.ndarray) -> np.ndarray:
    """Weights of the sub-level offsets: 0 next to a cell of level ground (``level``), 1 from
    :data:`SUB_LEVEL_TAPER` cells away. Where a cell with offset ``f`` met level ground, the path
    compared their whole levels, so the heights stepped by ``f``: faint rings in the hillshade
    around copr's mounds, where their slopes meet level ground. Fading the offsets out towards the
    cells near height steps as well cost edge cells (seed 2026 scene 4 -0.5 points)."""
    from scipy.ndimage import distance_transform_edt

    if not level.any():
        return np.ones(level.shape)
    d = distance_transform_edt(~level)
    return np.clip((d - 1.0) / SUB_LEVEL_TAPER, 0.0, 1.0)


#: Aggregations of a tile that take the trend of the tile's own result (:func:`aggregate_with_trend`).
TREND_PASSES = 1
#: P1 of those aggregations, as a fraction of the tile's P1 (the last aggregation, whose result the
#: tile keeps, pays the whole P1): the slopes they hand on as the trend are less flattened.
TREND_P1 = 0.5


def aggregate_with_trend(cost, params: TileParams, z0, guide, trend, valid, z_base: float, dz: float,
                         passes: int = TREND_PASSES, p1_factor: float = TREND_P1,
                         sub_level: bool = True) -> tuple[np.ndarray, np.ndarray | None]:  # fmt: skip
    """SGM aggregation (:func:`~truortho.core.sgm.aggregate`) of a tile's ``cost`` with ``trend`` (the
    coarser level's, :func:`slope_trend`; None on the coarsest level), then ``passes`` times again
    with the trend of the heights the last one selected (``valid``: the cells selected). Returns
    ``(S, frac)``: the last aggregated volume, and None or the offsets (rows, cols) by which its
    levels lie above the absolute ones (below). Without ``params.slope_max`` there is no trend and
    one aggregation.

    With ``sub_level`` (and a pass before it), the last aggregation follows the trend of the heights
    the pass selected at sub-level precision: ``t`` in levels (real numbers) is their
    :func:`slope_trend` before rounding, and on gentle slopes, where that has none, their
    :func:`gentle_trend`. The costs of those cells are shifted by ``frac = t - rint(t)`` levels
    (:func:`shift_levels`) and their trend is ``rint(t)``, so the level ``k`` of such a cell is the
    height ``z0 + k + frac``, and a level runs parallel to ``t``. With the rounded trend alone the
    heights kept the rounding's steps: rings along the contours of a pyramid roof (seed 5150 scene
    10), as the absolute levels of gentle slopes do (:func:`gentle_trend`).

    The trend a level hands on is flatter than the roof: the coarsest level has none, and each
    level pays P1 where its data term is too weak to follow the slope its coarser level missed.
    On battery scene 0 (master seed 2026) a roof rising 0.08 m per cell from its eaves at 8.9 m
    read 10.3 m flat on the coarsest level, 9.65-10.6 m where the truth spans 8.9-10.8 m on the
    next, and 9.45-9.6 m over its lowest 8 cells on the finest. A pass with the level's own trend
    lets SGM follow the slope it found without paying for it, and go further where the data ask.
    Measured with ``bench/osgm_battery.py`` on master seeds 2026 and 99: edge cells within 3 GSD
    up on 22 of 24 scenes (seed 2026 scene 0 75.4 -> 79.8 %, seed 99 scene 2 78.4 -> 81.7 %),
    down on 2 by at most 0.1 point; flat3 within -0.0/+0.8 points, NMAD within +0.012/-0.039 GSD;
    OSGM time: 548 s against 521 s over the 48 scenes of the four battery seeds in docs, with the
    three-height image choice (about 5 %, within the machine's variance; 0-4 % on brighton alone).
    A second pass added at most 1 point of edge3 on any scene; passes on the coarser levels alone
    kept less than half the gain.

    The first aggregations pay only ``p1_factor`` (:data:`TREND_P1`) of P1; the last, whose heights
    the tile keeps, the whole P1. With the whole P1 the first result was still flattened where the
    data term is weak against P1 (on seed 2026 scene 9 a hip roof's ridge at 22.0 m read 21.2 m flat
    over 24 cells, where the truth spans 21.3-22.0 m), and its trend handed that on. With P1 / 4
    alone the ridge was found (the data term knows it), but the ground's NMAD rose (scene 9 0.24 ->
    0.38 GSD); as the first pass only, its slopes reach the final aggregation through the trend,
    which stays off on flat ground (:data:`TREND_MIN_SLOPE`). Measured with
    ``bench/osgm_battery.py`` against the whole P1: factor 1/2 on master seeds 2026 and 7, edge3 up
    on 17 of 24 scenes (up to 2.1 points: seed 2026 scene 2 82.6 -> 84.7 %), down on 6 by at most
    0.14; seed 2026 scene 9 flat3 96.9 -> 97.1 %. 1/4 gained more edge3 (seed 2026 scene 2 +2.9
    points) but raised the NMAD on flat ground (seed 7 scene 2 0.456 -> 0.507 GSD, seed 2026 scene 4
    0.203 -> 0.235), 1/2 by at most 0.011. On seeds 808, 13 and 99, not used for the choice: edge3
    up on 28 of 36 scenes (up to 2.5 points: seed 808 scene 10 85.9 -> 88.4 %), down on 7 (seed 99
    scene 1 by 0.48, the others by at most 0.05), flat3 up on 28, NMAD within +0.006/-0.018 GSD. The
    number of aggregations and the time stay the same.
    """
    from ..sgm import TREND_NONE

    if isinstance(passes, bool) or not isinstance(passes, int | np.integer) or passes < 0:
        raise InputError(f"aggregate_with_trend: passes must be an integer >= 0, got {passes!r}")
    if not isinstance(sub_level, bool | np.bool_):
        raise InputError(f"aggregate_with_trend: sub_level must be True or False, got {sub_level!r}")
    number = isinstance(p1_factor, float | int) and not isinstance(p1_factor, bool)
    if not (number and 0.0 < p1_factor <= 1.0):
        raise InputError(f"aggregate_with_trend: p1_factor must be a number in (0, 1], got {p1_factor!r}")
    if params.slope_max <= 0:
        passes = 0
    p1_first = max(1, int(round(params.p1 * p1_factor)))
    frac = None
    for q in range(passes):
        S = aggregate(cost, p1_first, params.p2, params.paths, z0, guide=guide, trend=trend,
                      trend_max=params.slope_max)  # fmt: skip
        level, _ = select(S, z0, params.uniqueness, valid=valid)
        del S
        heights = z_base + level.astype(np.float64) * dz
        t = slope_trend(heights, z_base, dz, params.slope_max, real=True)
        trend = np.where(np.isfinite(t), np.rint(np.nan_to_num(t)), TREND_NONE).astype(np.int32)
        if sub_level and q == passes - 1:
            tg, gentle, level_ground = gentle_trend(heights, z_base, dz, trend)
            t = np.where(gentle, tg, t)
            mask = np.isfinite(t) & np.asarray(valid, bool)
            if mask.any():
                ti = np.rint(np.where(mask, t, 0.0))
                frac = np.where(mask, t - ti, 0.0) * _taper(level_ground)
                trend = np.where(mask, ti, trend).astype(np.int32)
                cost = shift_levels(cost, frac)
    S = aggregate(cost, params.p1, params.p2, params.paths, z0, guide=guide, trend=trend,
                  trend_max=params.slope_max)  # fmt: skip
    return S, frac


#: A cell takes the slope of the nearest cell with a trend (:func:`_eave_trend`) only when it lies
#: within this angle's cosine of that cell's downslope direction (45 degrees: the eaves below a
#: roof's slope, not a gable, where the ridge runs towards the step and a slope continued along it
#: would cut the ridge).
EAVE_COS = math.cos(math.radians(45.0))
#: Levels by which a cell's coarser height may depart from a plane of the largest slope through the
#: nearest cell with a trend and still count as the same surface (the coarser level's rounding).
EAVE_TOL = 1.0


def _eave_trend(t, gx, gy, zl, keep, eaves, slope_max: float, reach: int):
    """The trend (levels) continued from the cells that keep one into the ``eaves`` cells: the value
    and slope of the nearest cell with a trend, extrapolated to the cell, where that cell is at most
    ``reach`` cells away, the cell lies downslope of it (:data:`EAVE_COS`) and its coarser height
    ``zl`` is within what ``slope_max`` levels per cell (plus :data:`EAVE_TOL`) reach from that
    cell's (the same surface, not the far side of the step). Returns the new ``t`` and ``keep``."""
    from scipy.ndimage import distance_transform_edt

    _, (ir, ic) = distance_transform_edt(~keep, return_indices=True)
    rr, cc = np.indices(t.shape)
    dr, dc = rr - ir, cc - ic
    dist = np.hypot(dr, dc)
    sx, sy = gx[ir, ic], gy[ir, ic]
    ext = t[ir, ic] + sy * dr + sx * dc
    with np.errstate(invalid="ignore"):
        downslope = -(sy * dr + sx * dc) >= EAVE_COS * np.hypot(sx, sy) * dist
        same = np.abs(zl - zl[ir, ic]) <= slope_max * dist + EAVE_TOL
    take = eaves & (dist <= reach) & downslope & same & np.isfinite(ext)
    return np.where(take, ext, t), keep | take


#: Points across a tile at which the image choice counts views (:func:`_select`), at three heights
#: (:func:`choose_images`).
LATTICE = 17


def _lattice(x0, y0, res, rows, cols, n=LATTICE):
    xs = x0 + np.linspace(0.0, cols, n) * res
    ys = y0 - np.linspace(0.0, rows, n) * res
    X, Y = np.meshgrid(xs, ys)
    return X.ravel(), Y.ravel()


#: Views per tile point the image choice aims at before it prefers the most nadir image.
TARGET_VIEWS = 4
#: Views a cell needs to be matched at all (:func:`_select` exceeds ``max_images`` for them).
MIN_VIEWS = 2


def _select(cand, max_images: int):
    """Greedy choice of at most ``max_images`` images for a tile.

    Every tile lattice point should be seen by :data:`TARGET_VIEWS` images: each step
    takes the image that adds most views where points still lack them (ties: the smaller
    viewing angle), so the corners of a tile are not left to one image when the most
    nadir images all cover its centre; once every point has its views, the most nadir
    remaining images follow. Points short of the :data:`MIN_VIEWS` that matching needs
    come first (the rim of a block, seen by a few frames that cover little of a tile:
    counting only up to 4 views, the bundled sample's choice of 12 of 17 images left 9 %
    of the area two photos see unmatched), and where ``max_images`` images cannot give
    every point the views its candidates can, more are taken for those points alone.
    """
    if len(cand) <= max_images:
        return [(a, d, v) for _, a, d, v in sorted(cand, key=lambda t: t[1])]
    count = np.zeros(len(cand[0][0]), np.int64)
    left = list(range(len(cand)))
    chosen: list[int] = []
    # the views a point can have at all (its candidates), up to the two matching needs
    avail = np.minimum(np.sum([c[0] for c in cand], axis=0), MIN_VIEWS)
    while left and len(chosen) < max_images:
        short = np.maximum(avail - count, 0)
        need = np.maximum(TARGET_VIEWS - count, 0)
        best = max(
            left, key=lambda k: (int(short[cand[k][0]].sum()), int(need[cand[k][0]].sum()), -cand[k][1])
        )
        chosen.append(best)
        left.remove(best)
        count += cand[best][0]
    # beyond the cap, only where the chosen images still leave a point with fewer than the two views
    # matching needs while the candidates give it two
    chosen += _fill_short(cand, left, count, avail)
    return [(cand[k][1], cand[k][2], cand[k][3]) for k in chosen]


def _fill_short(cand, left: list[int], count: np.ndarray, target) -> list[int]:
    """Greedily the candidates ``left`` that give most points short of ``target`` views a view
    (ties: the smaller angle), until none is short or none helps. Returns their indices; ``count``
    gets their views and ``left`` loses them."""
    taken = []
    while left:
        short = count < target
        if not short.any():
            break
        best = max(left, key=lambda k: (int(np.count_nonzero(short & cand[k][0])), -cand[k][1]))
        if not np.any(short & cand[best][0]):
            break
        taken.append(best)
        left.remove(best)
        count += cand[best][0]
    return taken


def _rim_views(cand, near, steep):
    """Steep views for the points that the chosen near views leave with fewer than :data:`MIN_VIEWS`.

    ``cand``: the near candidates ``(inside, angle, dist, view)``; ``near``: :func:`_select`'s
    choice among them; ``steep``: candidates steeper than the tile's limit. Greedily the steep
    view that gives most short points a view (ties: the less steep) is taken, until none is
    short or none helps; then only the views that see a point they brought to two views stay.
    Taken everywhere, views up to 60 degrees cost battery scene 3 (obliques at 44 degrees) 0.5
    points of flat3 and 2.4 of edge3; taken only here, they match the rim of a block that only
    the obliques see twice.
    """
    if not steep:
        return []
    chosen = {id(v) for _, _, v in near}
    base = np.zeros(len(steep[0][0]), np.int64)
    for inside, _, _, v in cand:
        if id(v) in chosen:
            base += inside
    count = base.copy()
    taken = [steep[k] for k in _fill_short(steep, list(range(len(steep))), count, MIN_VIEWS)]
    helped = (base < MIN_VIEWS) & (count >= MIN_VIEWS)
    return [(a, d, v) for inside, a, d, v in taken if np.any(inside & helped)]


def choose_images(
    views, pyr: ImagePyramid, x0, y0, res, rows, cols, z_lo, z_hi, params: TileParams, colour: bool = False
) -> list[TileImage]:
    """The images that see the tile, with their pyramid level and pixel window.

    Which frames cover which tile points is tested at the bottom, the middle and the top of the
    tile's height range: the surface may lie anywhere in it, and a frame
    that covers a point at mid-height may miss it at the surface's height. Tested at mid-height
    only, a tile at the rim of battery scene 9 (master seed 2026) took two obliques that saw its
    ground points at 11 m and no steep view (:func:`_rim_views`) for the ground at 1 m, which one
    nadir photo and an oblique at 54 degrees saw: its coarsest level put the ground at 11 m.
    """
    X, Y = _lattice(x0, y0, res, rows, cols)
    zc = 0.5 * (z_lo + z_hi)
    heights = [zc] + ([z_lo, z_hi] if z_hi > z_lo else [])
    lattice = np.vstack([np.column_stack([X, Y, np.full(X.size, z)]) for z in heights])
    centre = np.array([x0 + 0.5 * cols * res, y0 - 0.5 * rows * res, zc])
    cand: list[tuple[np.ndarray, float, float, View]] = []
    steep: list[tuple[np.ndarray, float, float, View]] = []
    limit = max(params.max_view_angle, params.rim_view_angle)
    for v in views:
        ray = centre - v.C
        dist = float(np.linalg.norm(ray))
        angle = math.degrees(math.acos(min(1.0, max(-1.0, -ray[2] / max(dist, 1e-12)))))
        if angle > limit:
            continue
        uv_pts = project(lattice, v.R, v.C, v.camera, v.r2max)
        w, h = v.camera.width, v.camera.height
        inside = (uv_pts[:, 0] >= -0.5) & (uv_pts[:, 0] <= w - 0.5) & (uv_pts[:, 1] >= -0.5)
        inside &= uv_pts[:, 1] <= h - 0.5
        if inside.mean() < 0.02:
            continue
        (cand if angle <= params.max_view_angle else steep).append((inside, angle, dist, v))
    out = []
    near = _select(cand, params.max_images)
    for angle, dist, v in near + _rim_views(cand, near, steep):
        depth = dist * max(v.axis_cos, 0.2)
        gsd = depth / v.camera.fx
        level = max(0, int(math.floor(math.log2(max(res / gsd, 1.0)) + 1e-6)))
        pts = np.vstack([np.column_stack([X, Y, np.full(X.size, z)]) for z in (z_lo, z_hi)])
        uv = project(pts, v.R, v.C, v.camera, v.r2max)
        uv = uv[np.isfinite(uv[:, 0])]
        if len(uv) == 0:
            continue
        s = 0.5**level
        W, H = pyr.level_size(v.index, level)
        u0 = int(math.floor((uv[:, 0].min() + 0.5) * s - 0.5)) - 3
        u1 = int(math.ceil((uv[:, 0].max() + 0.5) * s - 0.5)) + 4
        v0 = int(math.floor((uv[:, 1].min() + 0.5) * s - 0.5)) - 3
        v1 = int(math.ceil((uv[:, 1].max() + 0.5) * s - 0.5)) + 4
        u0, v0, u1, v1 = max(u0, -2), max(v0, -2), min(u1, W + 2), min(v1, H + 2)
        if u1 <= u0 or v1 <= v0:
            continue
        win = pyr.window(v.index, level, u0, v0, u1 - u0, v1 - v0, colour=colour)
        out.append(TileImage(v, level, (u0, v0), win, angle))
    return out


def as_decoded(images: list[TileImage], pyr: ImagePyramid) -> list[TileImage]:
    """``images`` with their matching bands as the pyramid serves them without its low-pass
    (:meth:`~.views.ImagePyramid.prefilter_sigma`; the same windows, restored where the photos are):
    the edge refinement compares 3 x 3 patches at the outlines, which the low-pass would soften.
    The list itself when no image is low-passed."""
    if not any(pyr.prefilter_sigma(t.view.index, t.level) > 0.0 for t in images):
        return images
    out = []
    for t in images:
        h, w = t.window.shape[:2]
        win = pyr.window(t.view.index, t.level, t.origin[0], t.origin[1], w, h, raw=True)
        out.append(TileImage(t.view, t.level, t.origin, win, t.angle))
    return out


def _remap(img: TileImage, x0, y0, res, rows, cols, z) -> np.ndarray:
    import cv2

    mu, mv = plane_map(
        x0,
        y0,
        res,
        rows,
        cols,
        z,
        img.view.R,
        img.view.C,
        img.view.camera,
        img.view.r2max,
        img.level,
        img.origin,
    )
    return cv2.remap(  # type: ignore[call-overload]
        img.window, mu, mv, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=np.nan
    )


def sample_surface(images: list[TileImage], x0, y0, res, z: np.ndarray) -> np.ndarray:
    """Samples (n, rows, cols[, bands]) of every image at the cells' own heights ``z`` (NaN = none)."""
    import cv2

    rows, cols = z.shape
    zz = np.where(np.isfinite(z), z, np.nanmedian(z) if np.isfinite(z).any() else 0.0)
    out = []
    X = x0 + (np.arange(cols) + 0.5) * res
    Y = y0 - (np.arange(rows) + 0.5) * res
    Xg, Yg = np.meshgrid(X, Y)
    P = np.column_stack([Xg.ravel(), Yg.ravel(), zz.ravel()])
    for img in images:
        uv = project(P, img.view.R, img.view.C, img.view.camera, img.view.r2max)
        s = 0.5**img.level
        mu = ((uv[:, 0] + 0.5) * s - 0.5 - img.origin[0]).reshape(rows, cols).astype(np.float32)
        mv = ((uv[:, 1] + 0.5) * s - 0.5 - img.origin[1]).reshape(rows, cols).astype(np.float32)
        mu[~np.isfinite(mu)] = -1e6
        mv[~np.isfinite(mv)] = -1e6
        out.append(
            cv2.remap(  # type: ignore[call-overload]
                img.window, mu, mv, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=np.nan
            )
        )
    return np.stack(out) if out else np.full((0, rows, cols), np.nan, np.float32)


#: A cell departing from the median of its neighbourhood by more than this many Z levels is an outlier.
MEDIAN_TOLERANCE = 1.0


def median_outliers(level: np.ndarray, size: int, tolerance: float = MEDIAN_TOLERANCE) -> np.ndarray:
    """The median filter of the selected levels, used as an outlier test only.

    A cell whose window (``size x size``) holds fewer than half valid cells
    becomes NaN, and a cell more than ``tolerance`` levels away from the
    NaN-aware median of its window takes the median (a spike or a pit); every
    other cell keeps its own sub-level value. Replacing *every* cell by the
    median would throw the sub-level refinement away: on a slope the median
    of a window is, most of the time, a value copied from the cells beside
    the centre along the contour line, so runs of equal heights form along
    the contours and the DSM gets streaks parallel to them.
    """
    med = median_filter(level, size, min_count=max(1, (size * size) // 2))
    keep = np.isfinite(med) & (np.abs(level - med) <= tolerance)
    return np.where(keep, level, med).astype(np.float32)


def _median_view(samples: np.ndarray) -> np.ndarray:
    """Median over the views (NaN where none sees the cell)."""
    return nanmedian_axis0(np.asarray(samples, np.float32))


def _plane_need(search, lo, hi, gaps, a: int) -> np.ndarray:
    """The cells that search absolute level ``a``: inside their window and outside its gap."""
    need = search & (lo <= a) & (a <= hi)
    if gaps is not None:
        need &= ~((gaps[0] <= a) & (a <= gaps[1]))
    return need


def _dense_sweep(
    images, x0, y0, res, search, lo, hi, z0, z_base, dz, a_min, a_max, params, cost, cancelled, gaps=None
) -> int:
    """Costs plane by plane, each on the bounding box of the cells that search it (every measure)."""
    rows, cols = search.shape
    pad = params.radius + 2
    scales = None
    if params.measure == "gradient":
        from .sweep import gradient_scales

        scales = gradient_scales(images, _remap, x0, y0, res, rows, cols, z_base + 0.5 * (a_min + a_max) * dz)
    evaluated = 0
    for a in range(a_min, a_max + 1):
        if cancelled is not None and cancelled():
            break
        need = _plane_need(search, lo, hi, gaps, a)
        rr = np.nonzero(need.any(axis=1))[0]
        if rr.size == 0:
            continue
        cc = np.nonzero(need.any(axis=0))[0]
        r0, r1 = max(0, rr[0] - pad), min(rows, rr[-1] + pad + 1)
        c0, c1 = max(0, cc[0] - pad), min(cols, cc[-1] + pad + 1)
        # a minimum size keeps the windows of the other measures meaningful
        if r1 - r0 < 24:
            r0, r1 = max(0, min(r0, rows - 24)), min(rows, max(r1, r0 + 24))
        if c1 - c0 < 24:
            c0, c1 = max(0, min(c0, cols - 24)), min(cols, max(c1, c0 + 24))
        za = z_base + a * dz
        bx0, by0 = x0 + c0 * res, y0 - r0 * res
        slices = np.stack([_remap(im, bx0, by0, res, r1 - r0, c1 - c0, za) for im in images])
        c_b, _ = multi_image_cost(slices, params.radius, measure=params.measure, scales=scales)
        ii, jj = np.nonzero(need[r0:r1, c0:c1])
        gi, gj = ii + r0, jj + c0
        cost[gi, gj, a - z0[gi, gj]] = c_b[ii, jj]
        evaluated += 1
    return evaluated


#: Side (cells of the level) of the neighbourhood whose lowest and highest heights on the coarser
#: surface tell a cell near a height step (:func:`hidden_views`): the refined bands' 5 x 5 coarser
#: cells (:mod:`.levels`) are 9 to 10 of the level's.
OCCLUSION_WINDOW = 9


def hidden_views(images, x0, y0, res, guide_z, search, dz):
    """The views that the coarser surface hides from the ground beside a height step.

    A cell whose :data:`OCCLUSION_WINDOW` neighbourhood on the coarser surface ``guide_z`` (local
    heights at the tile's cells) spans more than a step (``max(1 m, 4 dz)``, as the edge
    refinement's) may lie on the low side: ground at the foot of a wall, which the views on the far
    side of the building cannot see. For each view, the ray from the cell at the neighbourhood's
    lowest height is marched over the coarser surface (:func:`~.edges._ray_free`: from
    :data:`~.edges.NEAR` cells on, so that a band the coarser level fattened beside the wall does
    not hide the ground from the very views that show it; tolerance ``2 dz``).

    Returns ``(occ, hid)``: ``occ`` (rows, cols) uint8, 1 at the searching cells with at least one
    view hidden, and ``hid`` (rows, cols, V) uint8 the hidden views there; None where no cell of the
    tile is near a step. The plane sweep takes the best pairs at such a cell as if only the views
    not hidden were valid (:func:`~.sweep._block_sums`): every pair still competes, at every height.
    """
    from .edges import BLOCK, NEAR, _ray_free, block_max
    from .levels import neighbourhood_minmax

    g = np.asarray(guide_z, np.float64)
    if g.ndim != 2 or np.shape(search) != g.shape:
        raise InputError(
            "hidden_views: expected 2-D guide_z and search of one shape, got "
            f"{g.shape} and {np.shape(search)}"
        )
    if not (np.isfinite(res) and res > 0 and np.isfinite(dz) and dz > 0):
        raise InputError(f"hidden_views: expected res > 0 and dz > 0, got {res!r} and {dz!r}")
    rows, cols = g.shape
    fin = np.isfinite(g)
    if len(images) < 3 or not fin.any():
        return None
    zmin, zmax = neighbourhood_minmax(g, OCCLUSION_WINDOW // 2)
    cells = np.asarray(search, bool) & np.isfinite(zmin) & np.isfinite(zmax)
    cells &= zmax - zmin > max(1.0, 4.0 * dz)
    if not cells.any():
        return None
    ri, ci = np.nonzero(cells)
    ri = ri.astype(np.int64)
    ci = ci.astype(np.int64)
    zc = np.ascontiguousarray(zmin[cells])
    zz = np.ascontiguousarray(np.where(fin, g, np.nan))
    bmax = block_max(zz)
    ztop = float(np.nanmax(zz))
    hid = np.zeros((rows, cols, len(images)), np.uint8)
    free = np.empty(ri.size, np.bool_)
    for v, img in enumerate(images):
        C = np.ascontiguousarray(img.view.C, np.float64)
        _ray_free(zz, bmax, BLOCK, ri, ci, zc, x0, y0, res, C, 2.0 * dz, ztop, float(NEAR), free)
        hid[ri, ci, v] = ~free
    occ = np.ascontiguousarray(hid.any(axis=2), np.uint8)
    if not occ.any():
        return None
    return occ, hid


def _sweep(
    images, x0, y0, res, search, lo, hi, z0, z_base, dz, a_min, a_max, params, cost, cancelled, gaps=None,
    hidden=None,
) -> int:
    """Costs plane by plane on the cells that search each plane only (:mod:`.sweep`, gradient measure);
    ``hidden``: :func:`hidden_views` (None: none)."""
    from ..sgm.cost import DEFAULT_MIN_VALID
    from .sweep import PlaneSweep, gradient_scales

    rows, cols = search.shape
    z_mid = z_base + 0.5 * (a_min + a_max) * dz
    scales = gradient_scales(images, _remap, x0, y0, res, rows, cols, z_mid)
    sweep = PlaneSweep(images, rows, cols, params.radius, DEFAULT_MIN_VALID, scales)
    z0 = np.ascontiguousarray(z0, np.int32)
    evaluated = 0
    for a in range(a_min, a_max + 1):
        if cancelled is not None and cancelled():
            break
        need = _plane_need(search, lo, hi, gaps, a)
        if not need.any():
            continue
        sweep.plane(x0, y0, res, z_base + a * dz, need, a, z0, cost, hidden=hidden)
        evaluated += 1
    return evaluated


#: Evaluate the gradient cost on the cells that search each plane only (:mod:`.sweep`); False: the
#: dense evaluation over each plane's bounding box (kept for the other measures and for comparison).
SPARSE_SWEEP = True


@dataclass
class TileResult:
    z: np.ndarray  # (rows, cols) float32, NaN where rejected
    confidence: np.ndarray  # (rows, cols) float32
    images: list[TileImage]
    levels: int  # absolute levels evaluated
    nd: int


#: Rank, as a fraction of the costs a cell measured, of the cost given to its heights that fewer than
#: two views see (:func:`fill_unseen`): 0.25, the lower quartile, so that an unseen height is better
#: than the cell's typical height and worse than its good ones (measured against the median there).
UNSEEN_QUANTILE = 0.25


@pjit
def _fill_unseen_kernel(cost, lo, hi, z0, glo, ghi, q):
    rows, cols, nd = cost.shape
    for r in prange(rows):
        buf = np.empty(nd, np.uint16)
        for c in range(cols):
            if lo[r, c] > hi[r, c]:
                continue
            b = z0[r, c]
            k0 = max(0, lo[r, c] - b)
            k1 = min(nd, hi[r, c] - b + 1)
            n = 0
            unseen = 0
            for k in range(k0, k1):
                if glo[r, c] <= b + k <= ghi[r, c]:
                    continue
                v = cost[r, c, k]
                if v >= COST_MAX:
                    unseen += 1
                else:
                    buf[n] = v
                    n += 1
            if n == 0 or unseen == 0:
                continue
            rank = int(q * (n - 1))
            select_rank(buf, 0, n - 1, rank)
            fill = buf[rank]
            for k in range(k0, k1):
                if cost[r, c, k] >= COST_MAX and not glo[r, c] <= b + k <= ghi[r, c]:
                    cost[r, c, k] = fill


def fill_unseen(cost, lo, hi, z0, gaps=None, quantile: float = UNSEEN_QUANTILE) -> None:
    """Give the heights of a cell that fewer than two views see a neutral cost, in place.

    The sweeps write ``COST_MAX`` where a voxel has fewer than two views whose window holds enough
    valid samples (out of their frames, or no valid pair): that is no evidence, not a mismatch. Left
    at ``COST_MAX`` it is the worst a height can score, and the aggregation took the heights that
    more images see instead. Frames cover less area the higher a plane lies, so under a tall roof
    these are the lower heights: on the acceptance battery (master seed 808, scene 4) the corners
    of a 59 m tower's roof, in 1 or 2 of the 18 frames at the roof's height, were matched 10-30 m
    low inside the tower, where 3 to 8 frames see the volume's heights. Such a height
    now costs the ``quantile`` (:data:`UNSEEN_QUANTILE`) of the ``n`` costs the cell measured in
    its band (the value of rank ``int(quantile (n - 1))``: for 0.5 the lower median, for 0.25 the
    lower quartile), and the aggregation decides it from the neighbours. Cells that measured nothing keep
    their ``COST_MAX`` column (no height); levels outside ``lo .. hi`` and inside ``gaps``
    (``(gap_lo, gap_hi)``, not searched) are not touched. The sweeps write the same ``COST_MAX``
    for a measured cost whose best pairs all saturate (the mean rounds to it), and the fill cannot
    tell the two apart: such a height gets the fill too. It is rare (every best pair differing by
    the whole saturated gradient range), and the pairwise rectified SGM (:mod:`truortho.core.sgm.rectified`),
    whose out-of-frame disparities are not a matter of height, keeps ``COST_MAX``.

    ``cost`` (rows, cols, nd) uint16 C-ordered, level ``k`` of cell (r, c) the absolute level
    ``z0[r, c] + k``; ``lo``, ``hi``, ``z0`` (rows, cols) int.

    Measured with ``bench/osgm_battery.py`` against ``COST_MAX`` on master seeds 808 and 2026: edge
    cells within 3 GSD up on 12 of 24 scenes (up to 0.69 points: seed 808 scene 8 82.3 -> 83.0 %),
    down on 5 by at most 0.18, flat3 up on 17 (up to 0.39: seed 2026 scene 2), NMAD within
    -0.008/+0.000 GSD, the time the same. On seeds 13 and 99 and six scenes of seed 7: edge3 up on
    15 of 30, down on 5 (seed 7 scene 10 by 0.56, the others by at most 0.27). The tower's corners
    stay wrong (seed 808 scene 4 edge3 77.95 -> 77.78 %): the tower's inside, which the roof's faint
    texture matches in every frame that sees it, still costs less than the median. Lower quantiles
    gained more edge3 on most of six scenes (0.25: seed 808 scene 8 +1.07 points, 0.1: +1.18), and 0
    (the cell's best cost) broke whole scenes (seed 808 scene 4: completeness 56 %, ties everywhere
    above the ground).

    **The lower quartile, not the median** (session 21). Under the 49.6 m tower of seed 7 scene 2
    (6 nadir photos from 118 m) the coarsest level's raw costs of the wrongly matched roof cells
    are high at every seen height (about 550-900 of 1023, the lowest often near the ground), and
    the lowest just below the unseen band of heights, where the roof is: the median fill made the
    unseen roof cost about 800 a cell, so the aggregation gave up the roof seen beside them within
    a few cells. The lower quartile lets it carry further. Measured with ``bench/osgm_battery.py``
    (the quantile patched by a scratch script) against the median on master seeds 7, 808 and 2026:
    edge cells within 3 GSD up on 20 of 36 scenes (up to +0.69 points, seed 808 scene 0), down on
    4 by at most 0.35; flat3 within 0.15 points, NMAD within 0.004 GSD, completeness within 0.03
    points; the cells of *any* view count more than 10 GSD off (those a true ortho paints beside
    walls) down from 7.08 to 5.11 % (seed 7 scene 2), 4.11 -> 2.87 (7/3), 3.01 -> 2.21 (808/8), 4.77 -> 3.76
    (2026/9), 2.48 -> 1.86 (808/0), 2.73 -> 2.09 (2026/4), and a little more cells without a
    height (0.1-1.5 points, at the block's rim and under the tower). On seeds 13 and 99, run after
    the choice: edge3 up on 13 of 24 scenes, down on 3 (by at most 0.56 points, seed 99 scene 0),
    cells more than 10 GSD off 4.11 -> 2.52 % (99/4), 3.03 -> 2.38 (13/2), 2.09 -> 1.39 (13/6),
    99/0 1.52 -> 1.18, on the others down by up to 0.2 points or up by at most 0.02. 0.1 went over the
    edge on seed 7 scene 0 (completeness 99.9 -> 98.4 %, flat3 99.4 -> 97.7 %): ties among the
    unseen heights, which the uniqueness test rejects.
    """
    q = quantile
    if not (isinstance(q, float | int) and not isinstance(q, bool) and 0.0 <= q <= 1.0):
        raise InputError(f"fill_unseen: quantile must be a number in [0, 1], got {quantile!r}")
    if cost.ndim != 3 or cost.dtype != np.uint16 or not cost.flags.c_contiguous:
        raise InputError("fill_unseen: cost must be a C-ordered uint16 (rows, cols, nd) volume")
    shape = cost.shape[:2]
    if np.shape(lo) != shape or np.shape(hi) != shape or np.shape(z0) != shape:
        raise InputError(
            f"fill_unseen: lo, hi and z0 must be {shape}, got {np.shape(lo)}, {np.shape(hi)}, {np.shape(z0)}"
        )
    if gaps is None:
        glo = np.ones(shape, np.int64)
        ghi = np.zeros(shape, np.int64)
    else:
        glo, ghi = (np.ascontiguousarray(g, np.int64) for g in gaps)
        if glo.shape != shape or ghi.shape != shape:
            raise InputError(f"fill_unseen: the gaps must be {shape}, got {glo.shape}, {ghi.shape}")
    i64 = [np.ascontiguousarray(a, np.int64) for a in (lo, hi, z0)]
    _fill_unseen_kernel(cost, i64[0], i64[1], i64[2], glo, ghi, float(q))


def match_tile(
    views,
    pyr: ImagePyramid,
    x0,
    y0,
    res,
    lo: np.ndarray,
    hi: np.ndarray,
    z_base: float,
    dz: float,
    params: TileParams,
    guide_z: np.ndarray | None = None,
    cancelled=None,
    gap_lo: np.ndarray | None = None,
    gap_hi: np.ndarray | None = None,
) -> TileResult:
    """Match one tile: ``lo``/``hi`` (rows, cols) int32 absolute level windows (lo > hi: no search).

    ``gap_lo``/``gap_hi``: levels inside a cell's window that it does not search
    (:func:`~.levels.refine_bands`; ``gap_lo > gap_hi``: none). A minimum next to a
    gap is rejected like one on the window's border: the surface lies in the gap.

    ``guide_z``: heights of the coarser level at these cells. With ``params.adaptive_p2`` the
    images sampled there (median over the views) form the guide of the intensity-adaptive P2;
    with ``params.slope_max`` its slopes form the aggregation's trend (:func:`slope_trend`).
    """
    rows, cols = lo.shape
    gaps = None
    if (gap_lo is None) != (gap_hi is None):
        raise InputError("match_tile: gap_lo and gap_hi go together (both or neither)")
    if gap_lo is not None and gap_hi is not None:
        if np.shape(gap_lo) != (rows, cols) or np.shape(gap_hi) != (rows, cols):
            raise InputError(
                f"match_tile: gap_lo and gap_hi must be {(rows, cols)} like lo, got "
                f"{np.shape(gap_lo)} and {np.shape(gap_hi)}"
            )
        if (gap_lo <= gap_hi).any():
            gaps = (gap_lo, gap_hi)
    search = lo <= hi
    nan = np.full((rows, cols), np.nan, np.float32)
    if not search.any():
        return TileResult(nan, nan.copy(), [], 0, 0)
    a_min, a_max = int(lo[search].min()), int(hi[search].max())
    images = choose_images(
        views, pyr, x0, y0, res, rows, cols, z_base + a_min * dz, z_base + a_max * dz, params
    )
    if len(images) < 2:
        return TileResult(nan, nan.copy(), images, 0, 0)
    width = np.where(search, hi - lo + 1, 0)
    nd = int(max(3, width.max()))
    centre = (lo + hi) // 2
    z0 = np.where(search, np.clip(centre - nd // 2, None, lo), 0)
    z0 = np.where(search, np.maximum(z0, hi - nd + 1), 0).astype(np.int32)
    cost = np.full((rows, cols, nd), COST_MAX, np.uint16)
    sweep = _sweep if params.measure == "gradient" and SPARSE_SWEEP else _dense_sweep
    hidden = None
    if params.occlusion_pairs and guide_z is not None and sweep is _sweep:
        hidden = hidden_views(images, x0, y0, res, guide_z, search, dz)
    evaluated = sweep(
        images, x0, y0, res, search, lo, hi, z0, z_base, dz, a_min, a_max, params, cost, cancelled, gaps,
        **({"hidden": hidden} if hidden is not None else {}),
    )  # fmt: skip
    fill_unseen(cost, lo, hi, z0, gaps)
    guide = None
    if params.adaptive_p2 and guide_z is not None:
        guide = _median_view(sample_surface(images, x0, y0, res, guide_z))
    trend = None
    if params.slope_max > 0 and guide_z is not None:
        trend = slope_trend(guide_z, z_base, dz, params.slope_max)
    valid = valid_cells(cost) & search
    S, frac = aggregate_with_trend(
        cost, params, z0, guide, trend, valid, z_base, dz, sub_level=params.sub_level
    )
    level, conf = select(S, z0, params.uniqueness, valid=valid)
    del S
    li = np.rint(np.nan_to_num(level, nan=-1e9)).astype(np.int64)
    edge = np.isfinite(level) & ((li <= lo) | (li >= hi))
    if gaps is not None:
        edge |= np.isfinite(level) & (gaps[0] <= gaps[1]) & ((li == gaps[0] - 1) | (li == gaps[1] + 1))
    level[edge] = np.nan
    conf[edge] = np.nan
    if frac is not None:  # the levels of the cells that follow the trend lie frac above the absolute ones
        level = (level + frac).astype(np.float32)
    if params.median > 1:
        level = median_outliers(level, params.median)
        conf[~np.isfinite(level)] = np.nan
    z = (z_base + level.astype(np.float64) * dz).astype(np.float32)
    if params.edges:
        from .edges import refine_edges

        decoded = as_decoded(images, pyr)
        z = refine_edges(z, decoded, x0, y0, res, max(1.0, 4.0 * dz), 2.0 * dz, cancelled, conf)
    return TileResult(z, conf.astype(np.float32), images, evaluated, nd)
