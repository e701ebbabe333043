"""The coarse-to-fine plan of OSGM: pyramid levels and per-cell Z windows.

Level ``l`` has cells ``2^l`` times the resolution and Z steps ``2^l dZ``
(the voxel stays proportioned). The coarsest level is chosen so that the
whole Z range needs at most :data:`COARSE_LEVELS` steps there (and at least
two halvings, as long as the coarse grid keeps :data:`MIN_COARSE_CELLS`
cells across), so its full-range search is cheap.

On every finer level a cell searches only the band between the lowest and
the highest coarse result of its 5 x 5 coarse neighbourhood, widened by
:data:`MARGIN_STEPS` coarse steps: a cell at a building outline keeps both the
ground and the roof in its band. Where the coarse level has no result
(rejected as ambiguous), the band comes from a 7 x 7 neighbourhood, else from
the tile's range, else the whole range. Bands wider than :data:`MAX_BAND`
levels are cut around the coarse value of the cell.

A neighbourhood that holds two surfaces (the ground and a roof beside it) does
not need the heights between them: :func:`refine_bands` also gives every cell
the widest *gap* of its band, the levels farther than the margin from every
coarse value of the neighbourhood (a wall's height range), which the plane
sweep skips. A cell at a building outline then searches about twice a flat
cell's band instead of ground to roof: on the acceptance battery these 12 % of
the cells had been half of all the costs evaluated. The first refined level
(below the full-range search) keeps whole bands (:meth:`LevelPlan.gaps`): the
coarsest level's blunders, a roof matched 30 m too high, are corrected there,
and a gap would hide the true height between the blunder and the ground (seen
on a battery scene: a whole roof lost).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..grid import RasterGrid
from ..jit import njit
from ..sgm.selection import _finite_window

#: Z steps the coarsest level may need for the whole range. It sets the coarsest cell: about
#: ``range / COARSE_LEVELS`` to twice that, so a tall building makes the small ones few cells wide
#: there. With 64, battery scene 3 (a 48 m tower; 1.86 m cells) matched three low-texture roofs of
#: 6-16 m at the ground: their 5 x 5 windows held more ground than roof, and the finer levels, which
#: search a band around the coarser result, could not climb back 5-16 m. With 128 (0.93 m cells)
#: they were found, and scene 3's edge3 rose from 74.0 to 83.9 %, flat3 from 95.8 to 98.4 %.
COARSE_LEVELS = 128
#: Smallest side of the coarsest grid, cells.
MIN_COARSE_CELLS = 16
#: Coarse steps added above and below the coarse neighbourhood's range (and around each coarse
#: value, for the gaps). Two were measured: about a fifth less time and the same battery figures
#: (six scenes: flat3 -0.1/+0.4 points, edge3 -1.6/+1.1), but 3 % less facade coverage from the
#: oblique systems (tests/core/test_osgm.py, 0.247 -> 0.239), whose steep surfaces the coarse
#: levels place less well. Two on the finest level only were also measured: 11 % less OSGM time on
#: the battery with every figure within 0.3 points, but on boruszyn (28 real photos, 0.25 m) 18 %
#: more cells in holes (45,500 -> 53,900; holes of 1 m^2 or more 144 -> 247): a minimum on a
#: band's border is rejected, and level 1 misplaced the trees and steep ground there by more than
#: two of its steps.
MARGIN_STEPS = 3
#: Widest band of levels a cell searches on a refined level.
MAX_BAND = 192


@dataclass
class LevelPlan:
    z_base: float  # local Z of absolute level 0
    z_top: float
    dz0: float  # finest Z step
    levels: list[int]  # coarse to fine, e.g. [3, 2, 1, 0]

    def dz(self, lv: int) -> float:
        return self.dz0 * 2**lv

    def count(self, lv: int) -> int:
        """Absolute levels ``0 .. count - 1`` at pyramid level ``lv``."""
        return int(math.floor((self.z_top - self.z_base) / self.dz(lv) + 1e-9)) + 1

    def grid(self, grid: RasterGrid, lv: int) -> RasterGrid:
        return grid if lv == 0 else grid.scaled(2**lv)

    def gaps(self, lv: int) -> bool:
        """Whether level ``lv`` skips the gaps of its bands (module docstring): every refined level
        but the first."""
        return len(self.levels) > 2 and lv < self.levels[1]

    def level_params(self, params, lv: int):
        """The tile parameters of level ``lv``: P2 divided by ``2^lv``.

        A height jump costs P2 per cell step along a path, and an object ``w``
        metres wide spans ``w / (2^lv res)`` cells whose matching evidence must
        pay for two jumps: scaling P2 with the cell size keeps the price of a
        jump per metre of object the same on every level, so small buildings
        are not flattened away on the coarse levels.

        The coarser levels also keep near-ties (no uniqueness test): their heights only set the
        bands of the next level, and a near-tie's height guides better than a hole, whose band
        falls back to a 7 x 7 neighbourhood or the tile's range. On the acceptance battery
        (``bench/osgm_battery.py``; uniqueness 0.99 on level 0 only) edge cells within 3 GSD rose
        on 7 of 12 scenes by up to 0.7 points (scene 2: 79.7 -> 80.4 %) and fell on the other 5 by
        at most 0.2, flat3 and NMAD were unchanged; on boruszyn the holes of OSGM's DSM fell by 1 %
        (holes of 1 m^2 or more 143 -> 130) with the same roughness. Switching the test off on
        level 0 as well kept 6,092 more cells over the battery, 43 % of them more than 3 GSD off:
        there the test stays.

        The occlusion-aware count of best pairs (``occlusion_pairs``,
        :func:`~.matching.hidden_views`) is for the levels above the finest: there it keeps the
        ground beside a wall in the bands; on the finest level it cost pitched roofs' eaves and
        roof rims (``docs/methods.md``), and the edge refinement decides the sides there.
        """
        if lv == 0:
            return dataclasses.replace(params, occlusion_pairs=False) if params.occlusion_pairs else params
        return dataclasses.replace(
            params, p2=max(params.p1 + 1, int(round(params.p2 / 2**lv))), edges=False, uniqueness=1.0
        )


def plan_levels(z_min: float, z_max: float, dz: float, grid: RasterGrid, max_levels: int = 5) -> LevelPlan:
    """The pyramid levels (coarse to fine) for the Z range ``[z_min, z_max]`` searched in steps ``dz``."""
    if not (math.isfinite(z_min) and math.isfinite(z_max) and z_max > z_min):
        raise InputError(f"Z range: expected finite z_min < z_max, got {z_min!r} .. {z_max!r}")
    if not (math.isfinite(dz) and dz > 0):
        raise InputError(f"Z_STEP: expected a positive number, got {dz!r}")
    n = (z_max - z_min) / dz
    need = max(0, math.ceil(math.log2(max(n / COARSE_LEVELS, 1.0))))
    top = max(need, 2)
    while top > 0 and min(grid.scaled(2**top).shape) < MIN_COARSE_CELLS:
        top -= 1
    top = max(0, min(top, int(max_levels)))
    # the range is extended so that every level's steps cover it
    step = dz * 2**top
    z_top = z_min + math.ceil((z_max - z_min) / step - 1e-9) * step
    return LevelPlan(float(z_min), float(z_top), float(dz), list(range(top, -1, -1)))


def neighbourhood_minmax(z: np.ndarray, radius: int) -> tuple[np.ndarray, np.ndarray]:
    """NaN-aware minimum and maximum over ``(2 radius + 1)^2`` windows (NaN where all are NaN)."""
    from scipy.ndimage import maximum_filter, minimum_filter

    size = 2 * radius + 1
    lo = minimum_filter(np.where(np.isfinite(z), z, np.inf), size=size, mode="nearest")
    hi = maximum_filter(np.where(np.isfinite(z), z, -np.inf), size=size, mode="nearest")
    lo[~np.isfinite(lo)] = np.nan
    hi[~np.isfinite(hi)] = np.nan
    return lo, hi


def _to_levels(plan: LevelPlan, lv: int, zlo, zhi, centre=None) -> tuple[np.ndarray, np.ndarray]:
    n = plan.count(lv)
    d = plan.dz(lv)
    lo = np.floor((zlo - plan.z_base) / d)
    hi = np.ceil((zhi - plan.z_base) / d)
    full = ~(np.isfinite(lo) & np.isfinite(hi))
    lo = np.where(full, 0, np.clip(lo, 0, n - 1))
    hi = np.where(full, n - 1, np.clip(hi, 0, n - 1))
    wide = (hi - lo + 1) > MAX_BAND
    if centre is not None and wide.any():
        c = np.clip(np.rint((centre - plan.z_base) / d), 0, n - 1)
        c = np.where(np.isfinite(c), c, 0.5 * (lo + hi))
        nlo = np.clip(c - MAX_BAND // 2, lo, None)
        nhi = np.minimum(nlo + MAX_BAND - 1, hi)
        lo = np.where(wide, nlo, lo)
        hi = np.where(wide, nhi, hi)
    return lo.astype(np.int32), hi.astype(np.int32)


def coarse_windows(plan: LevelPlan, lv: int, shape, surface=None) -> tuple[np.ndarray, np.ndarray]:
    """Windows of the coarsest level: the whole range, or the bounds of a surface raster."""
    if surface is None:
        return (np.zeros(shape, np.int32), np.full(shape, plan.count(lv) - 1, np.int32))
    zlo, zhi = surface
    return _to_levels(plan, lv, zlo, zhi)


@njit
def _widest_gaps(z, radius, margin, glo, ghi):
    """Per cell of ``z``: the widest interval ``(v_k + margin, v_k+1 - margin)`` between consecutive
    finite values ``v`` of its ``(2 radius + 1)^2`` neighbourhood, NaN where none is open."""
    rows, cols = z.shape
    buf = np.empty((2 * radius + 1) ** 2, np.float64)
    for r in range(rows):
        for c in range(cols):
            m = _finite_window(z, r, c, radius, buf)
            glo[r, c] = np.nan
            ghi[r, c] = np.nan
            if m < 2:
                continue
            vals = np.sort(buf[:m])
            best = 2.0 * margin
            for k in range(m - 1):
                d = vals[k + 1] - vals[k]
                if d > best:
                    best = d
                    glo[r, c] = vals[k] + margin
                    ghi[r, c] = vals[k + 1] - margin


def refine_windows(plan: LevelPlan, lv: int, coarse: np.ndarray, window) -> tuple[np.ndarray, np.ndarray]:
    """Windows of the cells ``window = (r0, c0, rows, cols)`` of level ``lv`` from level ``lv + 1``."""
    lo, hi, _ = _refine(plan, lv, coarse, window)
    return lo, hi


def refine_bands(
    plan: LevelPlan, lv: int, coarse: np.ndarray, window
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Windows ``lo, hi`` of the cells ``window = (r0, c0, rows, cols)`` of level ``lv`` from level
    ``lv + 1`` (as :func:`refine_windows`) and the gap ``glo .. ghi`` inside each (levels not
    searched; ``glo > ghi``: none).

    The gap is the widest run of levels of the band farther than the margin from every
    coarse value of the cell's neighbourhood (module docstring).
    """
    lo, hi, (patch, ix, margin) = _refine(plan, lv, coarse, window)
    gz_lo = np.empty(patch.shape, np.float64)
    gz_hi = np.empty(patch.shape, np.float64)
    _widest_gaps(np.ascontiguousarray(patch, np.float64), 2, float(margin), gz_lo, gz_hi)
    d = plan.dz(lv)
    with np.errstate(invalid="ignore"):
        # the levels on both sides of the gap stay searched (outward rounding, as the band's)
        glo = np.ceil((gz_lo[ix] - plan.z_base) / d) + 1
        ghi = np.floor((gz_hi[ix] - plan.z_base) / d) - 1
    has = np.isfinite(glo) & np.isfinite(ghi)
    glo = np.where(has, np.maximum(glo, lo + 1), hi + 1)
    ghi = np.where(has, np.minimum(ghi, hi - 1), hi)
    return lo, hi, glo.astype(np.int32), ghi.astype(np.int32)


def _refine(plan: LevelPlan, lv: int, coarse: np.ndarray, window):
    """The windows of :func:`refine_windows` and what the gaps need: ``(lo, hi, (patch, ix, margin))``
    with the coarse patch read, the index of each cell's coarse cell in it, and the margin (m)."""
    coarse = np.asarray(coarse)
    if coarse.ndim != 2:
        raise InputError(f"refine_windows: the coarser level must be 2-D heights, got shape {coarse.shape}")
    if len(window) != 4 or min(window[2], window[3]) < 1 or min(window[0], window[1]) < 0:
        raise InputError(
            f"refine_windows: window must be (r0 >= 0, c0 >= 0, rows >= 1, cols >= 1), got {window}"
        )
    r0, c0, nr, nc = (int(v) for v in window)
    m = 4  # coarse cells of context around the window
    cr0, cc0 = max(0, r0 // 2 - m), max(0, c0 // 2 - m)
    cr1 = min(coarse.shape[0], (r0 + nr - 1) // 2 + m + 1)
    cc1 = min(coarse.shape[1], (c0 + nc - 1) // 2 + m + 1)
    patch = coarse[cr0:cr1, cc0:cc1]
    lo3, hi3 = neighbourhood_minmax(patch, 2)
    lo7, hi7 = neighbourhood_minmax(patch, 3)
    lo = np.where(np.isfinite(lo3), lo3, lo7)
    hi = np.where(np.isfinite(hi3), hi3, hi7)
    if np.isfinite(patch).any():
        lo = np.where(np.isfinite(lo), lo, np.nanmin(patch))
        hi = np.where(np.isfinite(hi), hi, np.nanmax(patch))
    margin = MARGIN_STEPS * plan.dz(lv + 1)
    rr = np.clip(np.arange(r0, r0 + nr) // 2 - cr0, 0, patch.shape[0] - 1)
    cc = np.clip(np.arange(c0, c0 + nc) // 2 - cc0, 0, patch.shape[1] - 1)
    ix = np.ix_(rr, cc)
    lo_l, hi_l = _to_levels(plan, lv, lo[ix] - margin, hi[ix] + margin, patch[ix])
    return lo_l, hi_l, (patch, ix, margin)
