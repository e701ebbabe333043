"""DSM post-processing: outlier removal, edge sharpening, hole filling, smoothing.

:func:`filter_dsm` (files, by tiles) and :func:`filter_dsm_array` (in memory)
run these stages on a raw DSM (e.g. OSGM's), optionally with its confidence
raster (float in [0, 1]):

1. **Confidence**: cells with ``c < min_confidence`` are removed.
2. **Edge sharpening** (optional, on by default): a cell lying between the two
   levels (20th and 80th percentiles) of its 5 x 5 window, when these differ
   by more than ``max(step, 2 res tan 70 deg)`` (a blurred wall, never a roof
   slope), is snapped to the nearer level.
3. **Outliers** (median-based). For every cell, the median of its valid
   neighbours in a ``w x w`` window (weighted by confidence when given) and
   its *support*, the number of neighbours within ``t`` of its own height,
   are computed; the cell is removed when it departs from the median by more
   than ``t`` **and** has fewer than ``min_support`` supporters. The support
   test keeps true edges and corners of roofs (a roof corner cell has many
   supporters on its roof although the median lies on the ground) and thin
   structures one cell wide, and removes isolated spikes and pits and small
   blobs; a second pass with a window twice as wide and three times the
   support removes blobs up to about 3 x 3 cells. With a confidence raster,
   ``t`` is scaled by ``0.5 + 0.5 c`` (a less confident cell must agree better).
   Islands (valid components of fewer than ``3 min_support`` cells alone in
   nodata, which the median tests cannot judge: they are their own median and
   support) are removed when their median departs by more than ``t`` from the
   valid cells within 7 cells around them (:func:`_islands`).
4. **Holes** (connected nodata regions, 4-connected, after the above) whose
   width (twice the largest distance of a hole cell to valid data, minus one
   cell) is at most ``max_hole`` metres are filled by harmonic (Laplace)
   interpolation from their boundary cells, solved exactly as a sparse linear
   system. Boundary cells more than ``step`` above the lowest boundary cell
   within ``max_hole`` (the top of a wall beside an occlusion hole, where
   matching fails at the foot of walls) are not used (zero flux), so such
   holes are filled with the ground and walls stay sharp. Of a larger hole
   (in particular the nodata around the data, to which every gap open to the
   outside belongs), the cells inside the morphological closing of the valid
   cells by a disc of diameter ``max_hole`` and reach farther than a quarter of
   ``max_hole`` from its wide part (not the rounded-off corners of a wide hole)
   are filled the same way (zero flux towards the rest of the hole): bays and
   gaps narrower than ``max_hole`` that open onto a wide hole or onto the
   outside, which the width test alone
   left empty (on a block whose vegetated border lost its low-confidence cells
   most gaps are such open bays); beyond the raster's border counts as
   nodata, so nothing is extrapolated outward. The rest stays nodata and is
   counted in the statistics.
5. **Smoothing** (optional, edge-preserving): every cell is replaced by the
   value at its centre of the least-squares plane through the neighbours
   within ``smooth_radius`` cells whose heights are within
   ``smooth_tolerance`` of its own, when that plane fits them to RMS
   ``smooth_tolerance / 2`` (a planar patch: flat or pitched roof, street);
   steps, never within tolerance of both sides, stay sharp.

Tiling: each tile is computed on its core plus a margin (windows, hole widths,
interpolation reach, the closing's reach of twice its radius, smoothing
radius). Hole decisions are global: a first pass labels the holes of every
tile core and finds whether each contains a cell farther than ``max_hole / 2``
from valid data, labels are merged across tile borders (union-find), and the
second pass fills the holes whose merged component is small enough and the
narrow gaps of the others. Results do not depend on the tile size, except
for interpolated values of holes longer than the margin (truncated there,
with differences far below the noise for enclosed holes; a long bay open onto
a wide hole is a zero-flux boundary where a window cuts it, and on the demo
block tiles of 64 cells changed 773 of 21,607 filled cells by more than
1 cm against tiles of 1024).

Parallel execution
------------------
Each pass is a :meth:`~truortho.core.parallel.Executor.map_tiles` call over
the tiles (:func:`filter_pass1_task`, :func:`filter_pass2_task`; the tiles of
a pass are independent given the merge), so :func:`filter_dsm` runs them in
this process (default), on a local Dask cluster or on a Dask scheduler
(``executor``); the files are read by every task itself through a
:class:`FileReader`. The union-find merge, the statistics (summed from the
task results, in tile order) and the writing of the cores stay in this
process; pass 2 is submitted in batches of at most :data:`WRITE_BATCH_BYTES`
(256 MiB) of float32 cores (64 tiles of 1024 x 1024 cells, a raster of
8192 x 8192 cells, per call) so that this process never holds more of the
output than that. The tile logic is the same everywhere, so the result is
bit-identical whichever executor runs it. With ``cache_dir``, finished tile
tasks are kept in a content-addressed :class:`~truortho.core.parallel.TileCache`
keyed by :data:`CACHE_VERSION`, the input files (path, size, mtime), the
band, the grid, every :class:`DsmFilterConfig` field, the tile's windows and,
in pass 2, which of its holes the merge declared small.

Memory of one task (:func:`task_memory`, passed as ``memory=`` to the
executor): about :data:`TASK_BYTES_PER_CELL` = 96 bytes per cell of the outer
window (core + margin): up to eight float64 arrays live at once (heights,
confidence, the cleaned heights, the sharpened copy, the hole widths or the
filled and re-solved copies, the smoothed copy, the solver's int64 cell index)
plus about 32 bytes of int32 labels and boolean masks. The margin is
``outlier_margin + max_hole / 2 res + 2`` cells in pass 1 and up to
``outlier_margin + 2.5 max_hole / res + smooth_radius + 7`` in pass 2; with
the defaults (tile 1024, max_hole 10 m) at 0.25 m, pass 1 tasks have
1100 x 1100 cells (116 MB) and pass 2 tasks at most 1274 x 1274 (156 MB). The
sparse Laplace solve of a tile's small holes comes on top (proportional to the
hole cells, a small share of the tile).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np

from ..errors import InputError
from ..grid import RasterGrid
from ..jit import pjit, prange
from ..parallel import Digest, Executor, InProcessExecutor, TileCache, file_identity, tune_worker_malloc
from ..progress import Progress, Steps, as_progress

#: half side of the window of the confidence pass (15 x 15 cells)
CONFIDENCE_HALF = 7


@dataclass
class DsmFilterConfig:
    """Parameters of :func:`filter_dsm` (lengths in metres, windows in cells).

    Attributes
    ----------
    outlier_threshold : float or None
        ``t``: largest departure from the neighbourhood median (metres) before a
        cell with little support is removed; None = 4 x the resolution.
    outlier_window : int
        Side of the median window, cells (odd, 3 to 15).
    min_support : int
        Neighbours within ``t`` that keep a cell although it departs from the median.
    min_confidence : float
        With a confidence raster: cells below it are removed (0 = none).
    confident : float
        With a confidence raster: cells below it are removed when they depart by more than
        ``t`` from the median of the cells at least this confident in their 15 x 15 window
        (0 = off).
    max_hole : float
        Largest width of a hole that is filled, metres (0 = no filling).
    step : float
        Height difference between two surfaces (a wall), metres: hole boundary cells
        more than ``step`` above nearby boundary cells are not interpolated from, and
        steps of more than ``max(step, 2 res tan 70 deg)`` are sharpened.
    sharpen : bool
        Snap the cells of blurred height steps to the nearer side (see the module docstring).
    smooth : bool
        Apply the edge-preserving plane smoothing.
    smooth_radius : int
        Radius of the smoothing neighbourhood, cells (1 to 7).
    smooth_tolerance : float or None
        Height tolerance of the smoothing neighbourhood, metres; None = 2.5 x resolution.
    tile : int
        Tile core side, cells.
    """

    outlier_threshold: float | None = None
    outlier_window: int = 5
    min_support: int = 4
    min_confidence: float = 0.05
    confident: float = 0.4
    max_hole: float = 10.0
    step: float = 1.0
    sharpen: bool = True
    smooth: bool = False
    smooth_radius: int = 2
    smooth_tolerance: float | None = None
    tile: int = 1024

    def validate(self) -> None:
        def positive(name: str, allow_zero: bool = False) -> None:
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise InputError(f"{name}: expected a number, got {v!r}")
            if v < 0 or (v == 0 and not allow_zero):
                raise InputError(
                    f"{name}: expected a {'non-negative' if allow_zero else 'positive'} number, got {v!r}"
                )

        if self.outlier_threshold is not None:
            positive("outlier_threshold")
        w = self.outlier_window
        if isinstance(w, bool) or not isinstance(w, int) or w % 2 == 0 or not 3 <= w <= 15:
            raise InputError(f"outlier_window: expected an odd number of cells from 3 to 15, got {w!r}")
        if (
            isinstance(self.min_support, bool)
            or not isinstance(self.min_support, int)
            or not (0 <= self.min_support < w * w)
        ):
            raise InputError(
                f"min_support: expected an integer from 0 to {w * w - 1}, got {self.min_support!r}"
            )
        if not 0.0 <= self.confident <= 1.0:
            raise InputError(f"confident: expected a value in [0, 1], got {self.confident!r}")
        if not 0.0 <= self.min_confidence <= 1.0:
            raise InputError(f"min_confidence: expected a value in [0, 1], got {self.min_confidence!r}")
        positive("max_hole", allow_zero=True)
        positive("step")
        r = self.smooth_radius
        if isinstance(r, bool) or not isinstance(r, int) or not 1 <= r <= 7:
            raise InputError(f"smooth_radius: expected an integer from 1 to 7 cells, got {r!r}")
        if self.smooth_tolerance is not None:
            positive("smooth_tolerance")
        if isinstance(self.tile, bool) or not isinstance(self.tile, int) or self.tile < 32:
            raise InputError(f"tile: expected an integer of at least 32 cells, got {self.tile!r}")

    def threshold(self, res: float) -> float:
        return float(self.outlier_threshold) if self.outlier_threshold is not None else 4.0 * res

    def tolerance(self, res: float) -> float:
        return float(self.smooth_tolerance) if self.smooth_tolerance is not None else 2.5 * res

    def outlier_margin(self) -> int:
        # confidence pass, sharpening (2), both outlier passes, islands (their extent and ring)
        return CONFIDENCE_HALF + 2 + 3 * (self.outlier_window // 2) + 1 + self.island_cells() + ISLAND_RING

    def island_cells(self) -> int:
        """Valid components smaller than this are judged as islands (the second pass's support)."""
        return 3 * self.min_support

    def sharpen_step(self, res: float) -> float:
        return max(self.step, 2.0 * res * math.tan(math.radians(70.0)))

    def hole_cells(self, res: float) -> int:
        return int(math.ceil(self.max_hole / res))


@dataclass
class FilterStats:
    """What :func:`filter_dsm` did (cell counts unless stated).

    Attributes
    ----------
    cells : int
        Cells of the raster.
    valid_input : int
        Valid cells of the input.
    outliers_removed : int
        Cells removed by the median/support test.
    low_confidence_removed : int
        Cells removed for confidence below ``min_confidence``.
    holes_filled, cells_filled : int
        Holes filled and their cells (``cells_filled`` also counts the narrow gaps filled in wide
        holes, which stay counted in ``holes_remaining``).
    holes_remaining, cells_remaining : int
        Holes left as nodata (wider than ``max_hole``) and their cells.
    largest_remaining_hole_m : float
        Width (metres) of the widest remaining hole (0 if none).
    sharpened : int
        Cells of blurred steps snapped to the nearer level.
    smoothed : int
        Cells changed by the smoothing.
    valid_output : int
    """

    cells: int = 0
    valid_input: int = 0
    outliers_removed: int = 0
    low_confidence_removed: int = 0
    holes_filled: int = 0
    cells_filled: int = 0
    holes_remaining: int = 0
    cells_remaining: int = 0
    largest_remaining_hole_m: float = 0.0
    sharpened: int = 0
    smoothed: int = 0
    valid_output: int = 0

    def as_dict(self) -> dict:
        return asdict(self)

    def summary(self) -> str:
        return (
            f"{self.outliers_removed} outliers and {self.low_confidence_removed} low-confidence cells "
            f"removed; {self.sharpened} cells of blurred steps sharpened; "
            f"{self.holes_filled} holes ({self.cells_filled} cells) filled; {self.holes_remaining} holes "
            f"({self.cells_remaining} cells, widest {self.largest_remaining_hole_m:.2f} m) remain nodata; "
            f"{self.smoothed} cells smoothed; {self.valid_output} of {self.cells} cells valid "
            f"({self.valid_input} before)"
        )


# ------------------------------------------------------------------ kernels


@pjit
def _outlier_pass(z, conf, has_conf, t, half, min_support, out_mask):
    """Flag cells that depart from their (confidence-weighted) window median by more than
    their threshold and have fewer than ``min_support`` neighbours within it."""
    nr, nc = z.shape
    n_max = (2 * half + 1) ** 2
    for r in prange(nr):
        vals = np.empty(n_max)
        wts = np.empty(n_max)
        for c in range(nc):
            zc = z[r, c]
            if not np.isfinite(zc):
                continue
            tc = t * (0.5 + 0.5 * conf[r, c]) if has_conf else t
            support = 0
            n = 0
            for rr in range(max(r - half, 0), min(r + half + 1, nr)):
                for cc in range(max(c - half, 0), min(c + half + 1, nc)):
                    if rr == r and cc == c:
                        continue
                    v = z[rr, cc]
                    if not np.isfinite(v):
                        continue
                    if abs(v - zc) <= tc:
                        support += 1
                    vals[n] = v
                    wts[n] = (conf[rr, cc] + 1e-3) if has_conf else 1.0
                    n += 1
            if support >= min_support or n == 0:
                continue
            order = np.argsort(vals[:n])
            total = 0.0
            for k in range(n):
                total += wts[k]
            acc = 0.0
            med = vals[order[n - 1]]
            for k in range(n):
                acc += wts[order[k]]
                if acc >= 0.5 * total:
                    med = vals[order[k]]
                    break
            if abs(zc - med) > tc:
                out_mask[r, c] = True


@pjit
def _confidence_pass(z, conf, c_ref, t, half, out_mask):
    """Flag cells less confident than ``c_ref`` that depart by more than ``t`` from the median of
    the confident cells (``conf >= c_ref``) of their window (at least 8 of them)."""
    nr, nc = z.shape
    n_max = (2 * half + 1) ** 2
    for r in prange(nr):
        vals = np.empty(n_max)
        for c in range(nc):
            zc = z[r, c]
            if not np.isfinite(zc) or conf[r, c] >= c_ref:
                continue
            n = 0
            for rr in range(max(r - half, 0), min(r + half + 1, nr)):
                for cc in range(max(c - half, 0), min(c + half + 1, nc)):
                    v = z[rr, cc]
                    if np.isfinite(v) and conf[rr, cc] >= c_ref:
                        vals[n] = v
                        n += 1
            if n < 8:
                continue
            srt = np.sort(vals[:n])
            med = srt[n // 2] if n % 2 else 0.5 * (srt[n // 2 - 1] + srt[n // 2])
            if abs(zc - med) > t:
                out_mask[r, c] = True


@pjit
def _sharpen_pass(z, step, out, changed):
    """Snap cells between two levels of their 5x5 window (a blurred step) to the nearer level.

    Levels are the 20th and 80th percentiles of the valid neighbours; a cell is snapped when
    they differ by more than ``step`` and the cell is farther than a quarter of that from both.
    """
    nr, nc = z.shape
    for r in prange(nr):
        vals = np.empty(24)
        for c in range(nc):
            zc = z[r, c]
            out[r, c] = zc
            if not np.isfinite(zc):
                continue
            n = 0
            lo = np.inf
            hi = -np.inf
            for rr in range(max(r - 2, 0), min(r + 3, nr)):
                for cc in range(max(c - 2, 0), min(c + 3, nc)):
                    if rr == r and cc == c:
                        continue
                    v = z[rr, cc]
                    if np.isfinite(v):
                        vals[n] = v
                        n += 1
                        lo = min(lo, v)
                        hi = max(hi, v)
            if n < 8 or hi - lo <= step:
                continue
            srt = np.sort(vals[:n])
            p20 = srt[int(0.1 * (n - 1) + 0.5)]
            p80 = srt[int(0.9 * (n - 1) + 0.5)]
            gap = p80 - p20
            if gap <= step:
                continue
            d_lo = abs(zc - p20)
            d_hi = abs(zc - p80)
            if min(d_lo, d_hi) <= 0.25 * gap or zc < p20 or zc > p80:
                continue
            out[r, c] = p20 if d_lo < d_hi else p80
            changed[r, c] = True


@pjit
def _plane_smooth(z, radius, tol, out, changed):
    nr, nc = z.shape
    for r in prange(nr):
        for c in range(nc):
            zc = z[r, c]
            out[r, c] = zc
            if not np.isfinite(zc):
                continue
            # normal equations of z = a + b dx + c dy over the tolerant neighbours
            s1 = 0.0
            sx = 0.0
            sy = 0.0
            sxx = 0.0
            syy = 0.0
            sxy = 0.0
            sz = 0.0
            sxz = 0.0
            syz = 0.0
            szz = 0.0
            for rr in range(max(r - radius, 0), min(r + radius + 1, nr)):
                for cc in range(max(c - radius, 0), min(c + radius + 1, nc)):
                    v = z[rr, cc]
                    if not np.isfinite(v) or abs(v - zc) > tol:
                        continue
                    dx = float(cc - c)
                    dy = float(rr - r)
                    dv = v - zc
                    s1 += 1.0
                    sx += dx
                    sy += dy
                    sxx += dx * dx
                    syy += dy * dy
                    sxy += dx * dy
                    sz += dv
                    sxz += dx * dv
                    syz += dy * dv
                    szz += dv * dv
            if s1 < 6:
                continue
            # solve the 3x3 system by Cramer's rule
            a11, a12, a13 = s1, sx, sy
            a22, a23 = sxx, sxy
            a33 = syy
            det = (
                a11 * (a22 * a33 - a23 * a23) - a12 * (a12 * a33 - a23 * a13) + a13 * (a12 * a23 - a22 * a13)
            )
            if abs(det) < 1e-9:
                continue
            d0 = sz * (a22 * a33 - a23 * a23) - a12 * (sxz * a33 - a23 * syz) + a13 * (sxz * a23 - a22 * syz)
            d1 = a11 * (sxz * a33 - a23 * syz) - sz * (a12 * a33 - a23 * a13) + a13 * (a12 * syz - sxz * a13)
            d2 = a11 * (a22 * syz - sxz * a23) - a12 * (a12 * syz - sxz * a13) + sz * (a12 * a23 - a22 * a13)
            p0 = d0 / det
            p1 = d1 / det
            p2 = d2 / det
            # residual sum of squares: sum (dv - p0 - p1 dx - p2 dy)^2
            rss = (
                szz
                - 2.0 * (p0 * sz + p1 * sxz + p2 * syz)
                + p0 * p0 * s1
                + p1 * p1 * sxx
                + p2 * p2 * syy
                + 2.0 * (p0 * p1 * sx + p0 * p2 * sy + p1 * p2 * sxy)
            )
            if rss / s1 <= 0.25 * tol * tol:
                out[r, c] = zc + p0
                changed[r, c] = abs(p0) > 1e-3 * tol


# ------------------------------------------------------------------ stages on a window


def _clean(z: np.ndarray, conf: np.ndarray | None, cfg: DsmFilterConfig, res: float):
    """Low-confidence cut, edge sharpening and outlier removal on a window.

    Returns ``(cleaned, outlier mask, low-confidence mask, sharpened mask)``.
    """
    t = cfg.threshold(res)
    has_conf = conf is not None
    c = np.ascontiguousarray(conf if conf is not None else np.zeros((1, 1)), dtype=np.float64)
    low = np.zeros(z.shape, bool)
    work = z.copy()
    if has_conf and cfg.min_confidence > 0:
        low = np.isfinite(work) & ~(c >= cfg.min_confidence)
        work[low] = np.nan
    if has_conf and cfg.confident > 0:
        doubt = np.zeros(z.shape, bool)
        _confidence_pass(work, c, cfg.confident, t, CONFIDENCE_HALF, doubt)
        work[doubt] = np.nan
        low |= doubt
    sharp = np.zeros(z.shape, bool)
    if cfg.sharpen:
        work, sharp = _sharpen(work, cfg, res)
    half = cfg.outlier_window // 2
    m1 = np.zeros(z.shape, bool)
    _outlier_pass(work, c, has_conf, t, half, cfg.min_support, m1)
    work[m1] = np.nan
    m2 = np.zeros(z.shape, bool)
    _outlier_pass(work, c, has_conf, t, 2 * half, 3 * cfg.min_support, m2)
    work[m2] = np.nan
    m3 = _islands(work, t, cfg.island_cells())
    work[m3] = np.nan
    out = m1 | m2 | m3
    return work, out, low, sharp & ~out


#: width (cells) of the ring around an island whose valid cells give its reference height
ISLAND_RING = CONFIDENCE_HALF


def _islands(z: np.ndarray, t: float, max_cells: int) -> np.ndarray:
    """Cells of small islands of valid data that depart from their surroundings.

    The median tests cannot judge a group of valid cells standing alone in nodata (after the
    low-confidence cut, in vegetation or at the border of the data): its window holds mostly
    itself, so its own height is the median and every cell has its fellows as support. A valid
    component (8-connected) of fewer than ``max_cells`` cells is removed when its median height
    departs by more than ``t`` from the median of the valid cells within :data:`ISLAND_RING`
    cells around it (none there: kept, nothing to judge it by). Such islands otherwise become
    the only rim of a hole filled around them: a one-cell match 5 m above the ground made a
    cone 5 m high in the filled DSM of the demo block.
    """
    from scipy import ndimage

    valid = np.isfinite(z)
    out = np.zeros(z.shape, bool)
    if max_cells <= 1 or not valid.any():
        return out
    labels, k = ndimage.label(valid, structure=np.ones((3, 3), bool))
    if not k:
        return out
    sizes = np.bincount(labels.ravel(), minlength=k + 1)
    nr, nc = z.shape
    g = ISLAND_RING
    for lab, box in enumerate(ndimage.find_objects(labels), start=1):
        if box is None or sizes[lab] >= max_cells:
            continue
        r0, r1 = max(box[0].start - g, 0), min(box[0].stop + g, nr)
        c0, c1 = max(box[1].start - g, 0), min(box[1].stop + g, nc)
        sub = labels[r0:r1, c0:c1]
        zs = z[r0:r1, c0:c1]
        others = zs[(sub != lab) & (sub > 0)]
        if not len(others):
            continue
        if abs(float(np.median(zs[sub == lab])) - float(np.median(others))) > t:
            out[r0:r1, c0:c1] |= sub == lab
    return out


def _closed_gaps(valid: np.ndarray, radius: float, open_sides=(True, True, True, True)) -> np.ndarray:
    """Nodata cells of the narrow gaps and bays of ``valid``: gaps narrower than ``2 radius`` cells,
    enclosed or open onto a wider hole.

    The wide part of the nodata is its opening by a disc of ``radius`` cells (every disc that fits
    in it; by Euclidean distance transforms); the rest of the nodata is the closing of the valid
    cells. Its components reaching farther than ``radius / 2`` from the wide part are the gaps; the
    others are the rounded-off corners of the wide part (at most ``(sqrt 2 - 1) radius`` deep at a
    right angle), which stay nodata. ``open_sides`` (top, bottom, left, right): the sides of the
    window that are the raster's border; beyond them counts as nodata (nothing is closed towards
    the outside of the raster). Other sides are window cuts: the caller's margin (at least
    ``2 radius``) makes the closing exact on the core.
    """
    from scipy import ndimage

    pad = int(math.ceil(2.0 * radius)) + 2
    widths = [(pad if open_sides[0] else 0, pad if open_sides[1] else 0),
              (pad if open_sides[2] else 0, pad if open_sides[3] else 0)]  # fmt: skip
    v = np.pad(valid, widths, constant_values=False)
    if not v.any() or v.all():
        return np.zeros(valid.shape, bool)
    dilated = ndimage.distance_transform_edt(~v) <= radius
    if dilated.all():
        return np.zeros(valid.shape, bool)
    wide = ndimage.distance_transform_edt(dilated) <= radius  # the opening of the nodata
    rest = ~v & ~wide
    labels, k = ndimage.label(rest, structure=_FOUR)
    if k:
        depth = ndimage.distance_transform_edt(~wide)
        deep = np.asarray(ndimage.maximum(depth, labels, np.arange(1, k + 1))) > 0.5 * radius + 1.0
        rest = np.concatenate([[False], deep])[labels]
    r0, c0 = widths[0][0], widths[1][0]
    return rest[r0 : r0 + valid.shape[0], c0 : c0 + valid.shape[1]]


def _hole_width(nodata: np.ndarray) -> np.ndarray:
    """Per nodata cell: 2 x its distance (cells) to the nearest valid cell - 1; 0 on valid cells."""
    from scipy import ndimage

    if not nodata.any():
        return np.zeros(nodata.shape)
    if nodata.all():
        return np.full(nodata.shape, np.inf)
    d = ndimage.distance_transform_edt(nodata)
    return np.where(nodata, 2.0 * d - 1.0, 0.0)


_FOUR = np.array([[0, 1, 0], [1, 1, 1], [0, 1, 0]], bool)


def _fill_holes(
    z: np.ndarray, fill: np.ndarray, step: float, reach, hint: np.ndarray | None = None
) -> np.ndarray:
    """Harmonic interpolation of the cells ``fill`` (nodata) from their valid 4-neighbours.

    Each connected component is solved with Dirichlet values on its valid boundary
    cells, except boundary cells more than ``step`` above the lowest boundary cell of
    the same hole within ``reach`` cells (an int, or a per-cell int array whose maximum over
    a hole is that hole's reach) (the top of a wall beside an occlusion hole;
    a local rule, so that tiles agree): those are zero-flux, as the window border is. A component
    left without any Dirichlet cell keeps all its boundary cells.

    ``hint`` (the raw heights, NaN where the input had no data): a cell removed by the
    filter whose raw height is closer to the interpolation from the dropped (upper)
    boundary cells than to the lower one takes the upper one (a blurred roof edge next to
    an occlusion hole belongs to the roof). Returns a filled copy.
    """
    from scipy import ndimage

    out = z.copy()
    if not fill.any():
        return out
    labels, _ = ndimage.label(fill, structure=_FOUR)
    valid = np.isfinite(z)
    allowed = valid.copy()
    upper = np.zeros(z.shape, bool)
    nr, nc = z.shape
    for k, box in enumerate(ndimage.find_objects(labels), start=1):
        if box is None:
            continue
        r0, r1 = max(box[0].start - 1, 0), min(box[0].stop + 1, nr)
        c0, c1 = max(box[1].start - 1, 0), min(box[1].stop + 1, nc)
        sub = labels[r0:r1, c0:c1] == k
        zs = z[r0:r1, c0:c1]
        ring = ndimage.binary_dilation(sub, structure=_FOUR) & np.isfinite(zs)
        hz = zs[ring]
        if hz.size == 0 or hz.max() - hz.min() <= step:
            continue
        # the lowest boundary cell of this hole within `reach` of each boundary cell
        rk = int(reach[r0:r1, c0:c1][sub].max()) if isinstance(reach, np.ndarray) else int(reach)
        low = ndimage.minimum_filter(np.where(ring, zs, np.inf), size=2 * max(rk, 1) + 1, mode="nearest")
        drop = ring & (zs > low + step)
        allowed[r0:r1, c0:c1] &= ~drop
        upper[r0:r1, c0:c1] |= drop
    # components whose whole boundary was dropped use every valid neighbour
    ring_all = ndimage.binary_dilation(fill, structure=_FOUR) & valid
    touched = ndimage.binary_dilation(ring_all & allowed, structure=_FOUR) & fill
    has_d = np.zeros(int(labels.max()) + 1, bool)
    has_d[np.unique(labels[touched])] = True
    orphan = fill & ~has_d[labels]
    if orphan.any():
        allowed |= ndimage.binary_dilation(orphan, structure=_FOUR) & valid
    low_fill = _solve(out, fill, labels, valid, allowed)
    if hint is None or not upper.any():
        return low_fill
    hinted = fill & np.isfinite(hint)
    if not hinted.any():
        return low_fill
    high_fill = _solve(z.copy(), fill, labels, valid, upper)
    take = hinted & np.isfinite(high_fill) & (np.abs(hint - high_fill) < np.abs(hint - low_fill))
    low_fill[take] = high_fill[take]
    return low_fill


def _solve(out, fill, labels, valid, allowed):
    """Sparse Laplace solve, in place in ``out``, of the ``fill`` cells with Dirichlet values
    on their ``allowed`` valid 4-neighbours (zero flux elsewhere); components without any
    Dirichlet neighbour stay NaN."""
    from scipy import sparse
    from scipy.sparse.linalg import spsolve

    z = out
    nr, nc = z.shape
    fr, fc = np.nonzero(fill)
    m = len(fr)
    idx = -np.ones(z.shape, np.int64)
    idx[fr, fc] = np.arange(m)
    n = int(labels.max())
    lab_f = labels[fr, fc]
    diag = np.zeros(m)
    rhs = np.zeros(m)
    cnt_d = np.zeros(m)
    rows_l = []
    cols_l = []
    for dr, dc in ((0, 1), (0, -1), (1, 0), (-1, 0)):
        nr_ = fr + dr
        nc_ = fc + dc
        inside = (nr_ >= 0) & (nr_ < nr) & (nc_ >= 0) & (nc_ < nc)
        a = np.nonzero(inside)[0]
        nbr_r, nbr_c = nr_[a], nc_[a]
        j = idx[nbr_r, nbr_c]
        unk = j >= 0
        rows_l.append(a[unk])
        cols_l.append(j[unk])
        diag[a[unk]] += 1.0
        dirich = (~unk) & allowed[nbr_r, nbr_c] & valid[nbr_r, nbr_c]
        diag[a[dirich]] += 1.0
        cnt_d[a[dirich]] += 1.0
        np.add.at(rhs, a[dirich], z[nbr_r[dirich], nbr_c[dirich]])
    has_d = np.zeros(n + 1, bool)
    np.logical_or.at(has_d, lab_f, cnt_d > 0)
    solvable = has_d[lab_f]
    lap = sparse.csr_matrix(
        (-np.ones(sum(len(r) for r in rows_l)), (np.concatenate(rows_l), np.concatenate(cols_l))),
        shape=(m, m),
    )
    A = (lap + sparse.diags(diag)).tocsr()
    keep = np.nonzero(solvable & (diag > 0))[0]
    if len(keep):
        A = A[keep][:, keep]
        x = spsolve(A.tocsc(), rhs[keep])
        out[fr[keep], fc[keep]] = x
    return out


def _sharpen(z: np.ndarray, cfg: DsmFilterConfig, res: float):
    out = np.empty_like(z)
    changed = np.zeros(z.shape, bool)
    _sharpen_pass(np.ascontiguousarray(z), cfg.sharpen_step(res), out, changed)
    return out, changed


def _smooth(z: np.ndarray, cfg: DsmFilterConfig, res: float):
    out = np.empty_like(z)
    changed = np.zeros(z.shape, bool)
    _plane_smooth(np.ascontiguousarray(z), cfg.smooth_radius, cfg.tolerance(res), out, changed)
    return out, changed


# ------------------------------------------------------------------ union-find over tiles


class _Components:
    """Hole components of all tile cores, merged across tile borders."""

    def __init__(self) -> None:
        self.parent: list[int] = []
        self.deep: list[bool] = []
        self.size: list[int] = []
        self.width: list[float] = []

    def add(self, deep: np.ndarray, size: np.ndarray, width: np.ndarray) -> int:
        base = len(self.parent)
        for k in range(len(deep)):
            self.parent.append(base + k)
            self.deep.append(bool(deep[k]))
            self.size.append(int(size[k]))
            self.width.append(float(width[k]))
        return base

    def find(self, a: int) -> int:
        p = self.parent
        while p[a] != a:
            p[a] = p[p[a]]
            a = p[a]
        return a

    def union(self, a: int, b: int) -> None:
        ra, rb = self.find(a), self.find(b)
        if ra == rb:
            return
        if ra > rb:
            ra, rb = rb, ra
        self.parent[rb] = ra
        self.deep[ra] = self.deep[ra] or self.deep[rb]
        self.size[ra] += self.size[rb]
        self.width[ra] = max(self.width[ra], self.width[rb])


# ------------------------------------------------------------------ tile tasks (run anywhere)


@dataclass(frozen=True)
class FileReader:
    """Windows of a DSM GeoTIFF (and its confidence raster) as float64, NaN for nodata.

    Plain data (picklable), so that a Dask worker opens the files itself.
    """

    path: str
    band: int
    nodata: float | None
    confidence: str | None
    same_grid: bool
    grid: RasterGrid  # the DSM's grid (the confidence raster is resampled onto it unless same_grid)

    def __call__(self, r0: int, c0: int, nr: int, nc: int) -> tuple[np.ndarray, np.ndarray | None]:
        from ..rasterio_io import read_onto_grid, read_raster

        z, _, _ = read_raster(self.path, self.band, (r0, c0, nr, nc))
        z = z.astype(np.float64)
        if z.dtype.kind == "f" and self.nodata is not None and not math.isnan(self.nodata):
            z[z == self.nodata] = np.nan
        conf = None
        if self.confidence is not None:
            if self.same_grid:
                conf, _, _ = read_raster(self.confidence, 1, (r0, c0, nr, nc))
            else:
                conf = read_onto_grid(self.confidence, self.grid.window(r0, c0, nr, nc))
            conf = np.nan_to_num(conf.astype(np.float64), nan=0.0)
        return z, conf

    def identity(self) -> list:
        """What the windows depend on (part of the tile cache keys): files (path, size, mtime), band."""
        return [
            "dsm-filter-files",
            list(file_identity(self.path)),
            self.band,
            self.nodata,
            None if self.confidence is None else list(file_identity(self.confidence)),
            self.same_grid,
        ]


@dataclass(frozen=True)
class ArrayReader:
    """Windows of arrays held in memory (:func:`filter_dsm_array`; in-process only, never cached)."""

    z: np.ndarray  # float64, NaN = nodata
    confidence: np.ndarray | None  # float64 in [0, 1], NaN already 0

    def __call__(self, r0: int, c0: int, nr: int, nc: int) -> tuple[np.ndarray, np.ndarray | None]:
        c = self.confidence
        return self.z[r0 : r0 + nr, c0 : c0 + nc], (None if c is None else c[r0 : r0 + nr, c0 : c0 + nc])


@dataclass(frozen=True)
class FilterContext:
    """What every tile task of a run shares (shipped once per pass to a cluster)."""

    reader: FileReader | ArrayReader
    grid: RasterGrid
    config: DsmFilterConfig


@dataclass(frozen=True)
class Pass1Task:
    """Outliers and hole labels of one tile core, computed on ``outer`` (core + margin)."""

    core: tuple[int, int, int, int]
    outer: tuple[int, int, int, int]

    def key(self, base: str) -> str:
        return Digest(base, "dsm-filter-pass1", list(self.core), list(self.outer)).hexdigest()


@dataclass(frozen=True)
class Pass2Task:
    """Hole filling and smoothing of one tile core; ``small[l - 1]`` tells whether the merged
    component of the core's hole label ``l`` (pass 1) is small enough to be filled."""

    core: tuple[int, int, int, int]
    outer: tuple[int, int, int, int]
    small: np.ndarray  # (holes of the core,) bool

    def key(self, base: str) -> str:
        return Digest(
            base, "dsm-filter-pass2", list(self.core), list(self.outer), np.asarray(self.small, bool)
        ).hexdigest()


#: part of every tile cache key: bump when the arithmetic of the tile tasks changes
CACHE_VERSION = "dsm-filter-2"
#: reach (cells) of the wall-top rule of :func:`_fill_holes` in the narrow gaps of wide holes: only a
#: rim cell more than ``step`` above an adjacent rim cell (the rim crossing a wall) is dropped. With
#: the ``max_hole`` reach of the small holes, a bay running up a slope (a dune's lee side, a
#: hillside) lost every upslope rim cell and was filled flat from its lowest point, a cliff of
#: metres (demo block: cells more than 3 m below the median of their 8 neighbours 233 -> 22).
GAP_REACH = 1
#: bytes per cell of a task's outer window (module docstring, "Parallel execution")
TASK_BYTES_PER_CELL = 8 * 8 + 32
#: largest size of the filtered cores held by this process between two writes (pass 2 batches)
WRITE_BATCH_BYTES = 256 << 20


def task_memory(rows: int, cols: int) -> int:
    """Bytes one tile task needs at most for an outer window of ``rows x cols`` cells."""
    return int(rows) * int(cols) * TASK_BYTES_PER_CELL


def _read_padded(read, outer: tuple[int, int, int, int]):
    z, c = read(*outer)
    return np.ascontiguousarray(z, dtype=np.float64), (
        None if c is None else np.ascontiguousarray(c, dtype=np.float64)
    )


def filter_pass1_task(ctx: FilterContext, task: Pass1Task) -> tuple[np.ndarray, ...]:
    """Pass 1 of one tile: low-confidence, sharpening and outlier stages, hole labels of the core.

    Returns ``(counts, width, size, top, bottom, left, right)``: ``counts`` = int64 [valid input,
    outliers, low confidence, sharpened] over the core; per hole label ``l = 1..k`` of the core
    (4-connected) its largest width (cells, float64) and its cell count (int64); the labels of
    the core's four border lines (int32).
    """
    tune_worker_malloc()
    from scipy import ndimage

    cfg = ctx.config
    res = ctx.grid.res
    z, conf = _read_padded(ctx.reader, task.outer)
    valid_in = np.isfinite(z)
    clean, out_mask, low, sharp = _clean(z, conf, cfg, res)
    sl = _inner(task.core, task.outer)
    counts = np.array(
        [int(valid_in[sl].sum()), int(out_mask[sl].sum()), int(low[sl].sum()), int(sharp[sl].sum())],
        np.int64,
    )
    nodata = ~np.isfinite(clean)
    width = _hole_width(nodata)
    labels, k = ndimage.label(nodata[sl], structure=_FOUR)
    if k:
        idx = np.arange(1, k + 1)
        wmax = np.asarray(ndimage.maximum(width[sl], labels, idx), np.float64)
        sizes = np.asarray(ndimage.sum_labels(np.ones_like(labels), labels, idx)).astype(np.int64)
    else:
        wmax = np.zeros(0, np.float64)
        sizes = np.zeros(0, np.int64)
    borders = (labels[0], labels[-1], labels[:, 0], labels[:, -1])
    return (counts, wmax, sizes, *(np.ascontiguousarray(b, np.int32) for b in borders))


def filter_pass2_task(ctx: FilterContext, task: Pass2Task) -> tuple[np.ndarray, np.ndarray]:
    """Pass 2 of one tile: the same cleaning, the small holes filled, smoothing.

    Returns ``(core, counts)``: the filtered core (float32, NaN = nodata) and int64 [smoothed,
    valid output, cells of wide holes filled as narrow gaps] over the core.
    """
    tune_worker_malloc()
    from scipy import ndimage

    cfg = ctx.config
    res = ctx.grid.res
    hole_cells = cfg.hole_cells(res)
    z, conf = _read_padded(ctx.reader, task.outer)
    clean, _, _, _ = _clean(z, conf, cfg, res)
    sl = _inner(task.core, task.outer)
    nodata = ~np.isfinite(clean)
    core_labels, k = ndimage.label(nodata[sl], structure=_FOUR)
    fill = np.zeros(nodata.shape, bool)
    gaps = np.zeros(nodata.shape, bool)
    reach = np.zeros(nodata.shape, np.int32)
    if k and cfg.max_hole > 0:
        n = len(task.small)
        small = np.array([False] + [bool(s) for s in task.small])
        width_c = np.array([0] + [max(hole_cells, 1)] * n)
        core_fill = small[core_labels]
        # every window hole connected to a small core hole is the same (small) hole
        wl, _ = ndimage.label(nodata, structure=_FOUR)
        seed_labels = np.unique(wl[sl][core_fill])
        seed_labels = seed_labels[seed_labels > 0]
        fill = np.isin(wl, seed_labels)
        # reach of the wall-top rule for each window hole (max_hole; per hole for future use)
        lab_reach = np.zeros(int(wl.max()) + 1, np.int32)
        np.maximum.at(lab_reach, wl[sl][core_fill], width_c[core_labels][core_fill])
        reach = lab_reach[wl]
        # the narrow gaps of the wide holes (bays open onto them or onto the outside)
        if not small.all():
            g = ctx.grid
            r0, c0, nr, nc = task.outer
            sides = (r0 == 0, r0 + nr == g.rows, c0 == 0, c0 + nc == g.cols)
            gaps = _closed_gaps(~nodata, 0.5 * cfg.max_hole / res, sides) & ~fill
            reach = np.where(gaps, GAP_REACH, reach)
            fill = fill | gaps
    filled = _fill_holes(clean, fill, cfg.step, reach, z) if fill.any() else clean
    smoothed = 0
    if cfg.smooth:
        out, changed = _smooth(filled, cfg, res)
        smoothed = int(changed[sl].sum())
        filled = out
    core = filled[sl]
    gap_cells = int((gaps[sl] & np.isfinite(filled[sl])).sum())
    counts = np.array([smoothed, int(np.isfinite(core).sum()), gap_cells], np.int64)
    return np.ascontiguousarray(core, np.float32), counts


# ------------------------------------------------------------------ pipeline

Writer = Callable[[np.ndarray, tuple[int, int, int, int]], None]


def _run(
    ctx: FilterContext,
    write: Writer,
    executor: Executor,
    cache: TileCache | None,
    progress: Progress | None,
) -> FilterStats:
    from ..progress import SubProgress

    grid, cfg = ctx.grid, ctx.config
    res = grid.res
    steps = Steps(as_progress(progress), [1, 2])
    om = cfg.outlier_margin()
    hole_cells = cfg.hole_cells(res)
    margin1 = om + hole_cells // 2 + 2
    stats = FilterStats(cells=grid.rows * grid.cols)
    base = ""
    if cache is not None:
        base = Digest(
            CACHE_VERSION,
            ctx.reader.identity() if isinstance(ctx.reader, FileReader) else None,
            [grid.x_min, grid.y_max, grid.res, grid.rows, grid.cols, grid.crs],
            asdict(cfg),
        ).hexdigest()
    tiles = grid.tiles(cfg.tile, 0)
    # pass 1: outliers, hole labels per core, border labels
    tasks1 = [Pass1Task(t.core, _grow(t.core, margin1, grid)) for t in tiles]
    results1 = executor.map_tiles(
        filter_pass1_task,
        tasks1,
        steps[0],
        shared=ctx,
        cache=cache,
        key=(lambda t: t.key(base)) if cache is not None else None,
        label="DSM filter: outliers and holes",
        memory=task_memory(*_largest(tasks1)),
    )
    comps = _Components()
    bases: list[int] = []
    n_labels: list[int] = []
    borders: list[tuple[np.ndarray, ...]] = []
    for counts, wmax, sizes, *border in results1:
        stats.valid_input += int(counts[0])
        stats.outliers_removed += int(counts[1])
        stats.low_confidence_removed += int(counts[2])
        stats.sharpened += int(counts[3])
        k = len(wmax)
        if k:
            base_k = comps.add(wmax * res > cfg.max_hole + 1e-9, sizes, wmax * res)
        else:
            base_k = len(comps.parent)
        bases.append(base_k - 1)  # local label l -> base - 1 + l
        n_labels.append(k)
        borders.append(tuple(border))
    del results1
    # merge labels across tile borders
    index = {tt.index: i for i, tt in enumerate(tiles)}
    for i, t in enumerate(tiles):
        ti, tj = t.index
        for nb, (mine, theirs) in (((ti + 1, tj), (1, 0)), ((ti, tj + 1), (3, 2))):
            j = index.get(nb)
            if j is None:
                continue
            a = borders[i][mine]
            b = borders[j][theirs]
            both = (a > 0) & (b > 0)
            for la, lb in set(zip(a[both].tolist(), b[both].tolist(), strict=True)):
                comps.union(bases[i] + la, bases[j] + lb)
    roots = {comps.find(k) for k in range(len(comps.parent))}
    for rt in roots:
        if comps.deep[rt]:
            stats.holes_remaining += 1
            stats.cells_remaining += comps.size[rt]
            stats.largest_remaining_hole_m = max(stats.largest_remaining_hole_m, comps.width[rt])
        else:
            stats.holes_filled += 1
            stats.cells_filled += comps.size[rt]
    # pass 2: recompute, fill the small holes, smooth, write the cores. The margin of a tile with
    # small holes touching its core covers 1.5 times the widest of them (the interpolation) plus
    # the reach of the wall-top rule (max_hole), so the result does not depend on the tiles
    tasks2: list[Pass2Task] = []
    for n, t in enumerate(tiles):
        roots_t = [comps.find(bases[n] + lab) for lab in range(1, n_labels[n] + 1)]
        small_w = [comps.width[rt] for rt in roots_t if not comps.deep[rt]]
        w_cells = int(math.ceil(max(small_w) / res)) + 2 if (small_w and cfg.max_hole > 0) else 0
        small = np.array([not comps.deep[rt] for rt in roots_t], bool)
        fill_margin = (3 * w_cells) // 2 + hole_cells if w_cells else 0
        if cfg.max_hole > 0 and not small.all():
            # the closing of a wide hole's narrow gaps reaches twice its radius (max_hole), and their
            # interpolation as far as a small hole's
            fill_margin = max(fill_margin, hole_cells + (3 * hole_cells) // 2 + 2)
        margin2 = om + fill_margin + cfg.smooth_radius + 4
        tasks2.append(Pass2Task(t.core, _grow(t.core, margin2, grid), small))
    # batches of tiles whose cores this process holds before writing them (bounded memory)
    per_batch = max(1, WRITE_BATCH_BYTES // (4 * cfg.tile * cfg.tile))
    for start in range(0, len(tasks2), per_batch):
        batch = tasks2[start : start + per_batch]
        stop = start + len(batch)
        label = "DSM filter: filling"
        if len(batch) < len(tasks2):
            label += f" (tiles {start + 1}-{stop} of {len(tasks2)})"
        results2 = executor.map_tiles(
            filter_pass2_task,
            batch,
            SubProgress(steps[1], start / len(tasks2), stop / len(tasks2)),
            shared=ctx,
            cache=cache,
            key=(lambda t: t.key(base)) if cache is not None else None,
            label=label,
            memory=task_memory(*_largest(batch)),
        )
        for task, (core, counts) in zip(batch, results2, strict=True):
            stats.smoothed += int(counts[0])
            stats.valid_output += int(counts[1])
            stats.cells_filled += int(counts[2])
            stats.cells_remaining -= int(counts[2])
            write(core, task.core)
        del results2
    return stats


def _largest(tasks) -> tuple[int, int]:
    """(rows, cols) of the largest outer window of ``tasks`` (for their memory estimate)."""
    t = max(tasks, key=lambda t: t.outer[2] * t.outer[3])
    return t.outer[2], t.outer[3]


def _grow(core: tuple[int, int, int, int], margin: int, grid: RasterGrid) -> tuple[int, int, int, int]:
    r0, c0, nr, nc = core
    a0, b0 = max(r0 - margin, 0), max(c0 - margin, 0)
    a1, b1 = min(r0 + nr + margin, grid.rows), min(c0 + nc + margin, grid.cols)
    return (a0, b0, a1 - a0, b1 - b0)


def _inner(core, outer) -> tuple[slice, slice]:
    r = core[0] - outer[0]
    c = core[1] - outer[1]
    return slice(r, r + core[2]), slice(c, c + core[3])


def _check_array(name: str, a, grid: RasterGrid) -> np.ndarray:
    arr = np.asarray(a)
    if arr.shape != grid.shape:
        raise InputError(f"{name}: expected an array of the grid's shape {grid.shape}, got {arr.shape}")
    if arr.dtype.kind not in "fiu":
        raise InputError(f"{name}: expected numbers, got {arr.dtype}")
    return arr


def filter_dsm_array(
    z: np.ndarray,
    grid: RasterGrid,
    confidence: np.ndarray | None = None,
    config: DsmFilterConfig | None = None,
    progress: Progress | None = None,
) -> tuple[np.ndarray, FilterStats]:
    """Filter a DSM held in memory (same tiling and tile tasks as :func:`filter_dsm`, in this process).

    Parameters
    ----------
    z : (rows, cols) float
        Heights in metres; NaN = nodata.
    grid : RasterGrid
    confidence : (rows, cols) float in [0, 1], optional
        NaN is treated as 0.
    config : DsmFilterConfig, optional

    Returns
    -------
    (filtered (rows, cols) float32 with NaN for nodata, FilterStats)
    """
    cfg = config or DsmFilterConfig()
    cfg.validate()
    a = _check_array("DSM", z, grid).astype(np.float64)
    if not np.isfinite(a).any():
        raise InputError("DSM: every cell is nodata; nothing to filter")
    c = None
    if confidence is not None:
        c = np.nan_to_num(_check_array("confidence", confidence, grid).astype(np.float64), nan=0.0)
    out = np.full(grid.shape, np.nan, np.float32)

    def write(data, core):
        r0, c0, nr, nc = core
        out[r0 : r0 + nr, c0 : c0 + nc] = data

    ctx = FilterContext(ArrayReader(a, c), grid, cfg)
    stats = _run(ctx, write, InProcessExecutor(), None, progress)
    return out, stats


def filter_dsm(
    input_path,
    output_path,
    confidence_path=None,
    config: DsmFilterConfig | None = None,
    progress: Progress | None = None,
    executor: Executor | None = None,
    cache_dir=None,
) -> FilterStats:
    """Filter a DSM GeoTIFF by tiles into a new GeoTIFF (atomic; CRS, grid and nodata kept).

    Parameters
    ----------
    input_path : str or os.PathLike
        Single-band DSM with a projected CRS (OSGM's raw DSM: float32, nodata -9999).
    output_path : str or os.PathLike
        ``.tif`` destination; float32 with the input's nodata value (-9999 when it has none).
    confidence_path : str or os.PathLike, optional
        Confidence raster in [0, 1] (OSGM's CONFIDENCE); resampled onto the DSM grid when
        its grid differs.
    config : DsmFilterConfig, optional
    executor : truortho.core.parallel.Executor, optional
        Where the tile tasks run (module docstring, "Parallel execution"); default in this
        process. Not closed here.
    cache_dir : str or os.PathLike, optional
        Keep every finished tile task there (:class:`~truortho.core.parallel.TileCache`) and
        reuse it on a rerun with the same input files and parameters.

    Raises
    ------
    CRSError
        The DSM (or the confidence raster) has no CRS, or the DSM's CRS is geographic.
    InputError
        Every cell of the DSM is nodata, or a bad parameter.
    """
    from ..geometry.frame import parse_crs, require_metric
    from ..rasterio_io import RasterWriter, raster_grid, read_raster

    cfg = config or DsmFilterConfig()
    cfg.validate()
    grid = raster_grid(input_path, require_crs=True)
    require_metric(parse_crs(grid.crs), f"DSM {input_path}")
    _, _, nodata = read_raster(input_path, 1, (0, 0, 1, 1))
    out_nodata = -9999.0 if nodata is None or (isinstance(nodata, float) and math.isnan(nodata)) else nodata
    same_grid = False
    if confidence_path is not None:
        cgrid = raster_grid(confidence_path, require_crs=True)
        same_grid = (
            cgrid.shape == grid.shape
            and np.allclose(cgrid.geotransform, grid.geotransform)
            and parse_crs(cgrid.crs) == parse_crs(grid.crs)
        )
    _require_some_data(input_path, grid)
    reader = FileReader(
        os.path.abspath(os.fspath(input_path)),
        1,
        None if nodata is None else float(nodata),
        None if confidence_path is None else os.path.abspath(os.fspath(confidence_path)),
        bool(same_grid),
        grid,
    )
    ctx = FilterContext(reader, grid, cfg)
    cache = TileCache(cache_dir) if cache_dir is not None else None

    with RasterWriter(
        output_path, grid, bands=1, dtype="float32", nodata=out_nodata, descriptions=["filtered DSM height"]
    ) as w:

        def write(data, core):
            w.write(np.where(np.isfinite(data), data, out_nodata).astype(np.float32), core)

        stats = _run(ctx, write, executor if executor is not None else InProcessExecutor(), cache, progress)
    return stats


def _require_some_data(path, grid: RasterGrid) -> None:
    """Raise InputError when every cell of the raster is nodata (read by tiles)."""
    from ..rasterio_io import read_raster

    for t in grid.tiles(2048, 0):
        z, _, nodata = read_raster(path, 1, t.core)
        z = z.astype(np.float64)
        if nodata is not None:
            z[z == nodata] = np.nan
        if np.isfinite(z).any():
            return
    raise InputError(f"{path}: every cell is nodata; nothing to filter")
