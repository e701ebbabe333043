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
4. **Holes** (connected nodata regions, 4-connected, after the above) whose
   width (twice the largest distance of a hole cell to valid data, minus one
   cell) is at most ``max_hole`` metres are filled by harmonic (Laplace)
   interpolation from their boundary cells, solved exactly as a sparse linear
   system. Boundary cells more than ``step`` above the lowest boundary cell
   within ``max_hole`` (the top of a wall beside an occlusion hole, where
   matching fails at the foot of walls) are not used (zero flux), so such
   holes are filled with the ground and walls stay sharp. Larger holes stay
   nodata and are counted in the statistics.
5. **Smoothing** (optional, edge-preserving): every cell is replaced by the
   value at its centre of the least-squares plane through the neighbours
   within ``smooth_radius`` cells whose heights are within
   ``smooth_tolerance`` of its own, when that plane fits them to RMS
   ``smooth_tolerance / 2`` (a planar patch: flat or pitched roof, street);
   steps, never within tolerance of both sides, stay sharp.

Tiling: each tile is computed on its core plus a margin (windows, hole widths,
interpolation reach, smoothing radius). Hole decisions are global: a first
pass labels the holes of every tile core and finds whether each contains a
cell farther than ``max_hole / 2`` from valid data, labels are merged across
tile borders (union-find), and the second pass fills only holes whose merged
component is small enough. Results do not depend on the tile size, except
for interpolated values of holes longer than the margin (truncated there,
with differences far below the noise).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np

from ..errors import InputError
from ..grid import RasterGrid
from ..jit import pjit, prange
from ..progress import Progress, Steps, as_progress, check


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
        return 2 + 3 * (self.outlier_window // 2) + 1  # sharpening (2), both outlier passes

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
        Holes filled and their cells.
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
    return work, m1 | m2, low, sharp & ~(m1 | m2)


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


def _fill_holes(z: np.ndarray, fill: np.ndarray, step: float, reach: int,
                hint: np.ndarray | None = None) -> np.ndarray:
    """Harmonic interpolation of the cells ``fill`` (nodata) from their valid 4-neighbours.

    Each connected component is solved with Dirichlet values on its valid boundary
    cells, except boundary cells more than ``step`` above the lowest boundary cell of
    the same hole within ``reach`` cells (the top of a wall beside an occlusion hole;
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
        low = ndimage.minimum_filter(np.where(ring, zs, np.inf), size=2 * reach + 1, mode="nearest")
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


# ------------------------------------------------------------------ pipeline

Reader = Callable[[int, int, int, int], tuple[np.ndarray, np.ndarray | None]]
Writer = Callable[[np.ndarray, tuple[int, int, int, int]], None]


def _read_padded(read: Reader, grid: RasterGrid, outer: tuple[int, int, int, int]):
    z, c = read(*outer)
    return np.ascontiguousarray(z, dtype=np.float64), (
        None if c is None else np.ascontiguousarray(c, dtype=np.float64)
    )


def _run(
    read: Reader,
    write: Writer,
    grid: RasterGrid,
    cfg: DsmFilterConfig,
    has_conf: bool,
    progress: Progress | None,
) -> FilterStats:
    from scipy import ndimage

    res = grid.res
    steps = Steps(as_progress(progress), [1, 2])
    om = cfg.outlier_margin()
    hole_cells = cfg.hole_cells(res)
    margin1 = om + hole_cells // 2 + 2
    margin2 = om + (5 * hole_cells) // 2 + cfg.smooth_radius + 4
    stats = FilterStats(cells=grid.rows * grid.cols)
    comps = _Components()
    tiles = grid.tiles(cfg.tile, 0)
    bases: list[int] = []
    borders: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
    # pass 1: outliers, hole labels per core, border labels
    for n, t in enumerate(tiles):
        check(steps.parent)
        outer = _grow(t.core, margin1, grid)
        z, conf = _read_padded(read, grid, outer)
        valid_in = np.isfinite(z)
        clean, out_mask, low, sharp = _clean(z, conf, cfg, res)
        sl = _inner(t.core, outer)
        stats.valid_input += int(valid_in[sl].sum())
        stats.outliers_removed += int(out_mask[sl].sum())
        stats.low_confidence_removed += int(low[sl].sum())
        stats.sharpened += int(sharp[sl].sum())
        nodata = ~np.isfinite(clean)
        width = _hole_width(nodata)
        core_nd = nodata[sl]
        labels, k = ndimage.label(core_nd, structure=_FOUR)
        if k:
            idx = np.arange(1, k + 1)
            wmax = ndimage.maximum(width[sl], labels, idx)
            sizes = ndimage.sum_labels(np.ones_like(labels), labels, idx)
            deep = np.asarray(wmax) * res > cfg.max_hole + 1e-9
            base = comps.add(deep, np.asarray(sizes), np.asarray(wmax) * res)
        else:
            base = len(comps.parent)
        bases.append(base - 1)  # local label l -> base - 1 + l
        borders.append((labels[0].copy(), labels[-1].copy(), labels[:, 0].copy(), labels[:, -1].copy()))
        steps[0].update((n + 1) / len(tiles), f"DSM filter: outliers and holes, tile {n + 1}/{len(tiles)}")
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
    # pass 2: recompute, fill the small holes, smooth, write the cores
    for n, t in enumerate(tiles):
        check(steps.parent)
        outer = _grow(t.core, margin2, grid)
        z, conf = _read_padded(read, grid, outer)
        clean, _, _, _ = _clean(z, conf, cfg, res)
        sl = _inner(t.core, outer)
        nodata = ~np.isfinite(clean)
        core_labels, k = ndimage.label(nodata[sl], structure=_FOUR)
        fill = np.zeros(nodata.shape, bool)
        if k and cfg.max_hole > 0:
            small = np.array(
                [False] + [not comps.deep[comps.find(bases[n] + lab)] for lab in range(1, k + 1)]
            )
            core_fill = small[core_labels]
            # every window hole connected to a small core hole is the same (small) hole
            wl, _ = ndimage.label(nodata, structure=_FOUR)
            seed_labels = np.unique(wl[sl][core_fill])
            fill = np.isin(wl, seed_labels[seed_labels > 0])
        filled = _fill_holes(clean, fill, cfg.step, max(hole_cells, 1), z) if fill.any() else clean
        if cfg.smooth:
            smoothed, changed = _smooth(filled, cfg, res)
            stats.smoothed += int(changed[sl].sum())
            filled = smoothed
        core = filled[sl]
        stats.valid_output += int(np.isfinite(core).sum())
        write(core, t.core)
        steps[1].update((n + 1) / len(tiles), f"DSM filter: filling, tile {n + 1}/{len(tiles)}")
    return stats


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
    """Filter a DSM held in memory (same tiling as :func:`filter_dsm`).

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

    def read(r0, c0, nr, nc):
        return a[r0 : r0 + nr, c0 : c0 + nc], (None if c is None else c[r0 : r0 + nr, c0 : c0 + nc])

    def write(data, core):
        r0, c0, nr, nc = core
        out[r0 : r0 + nr, c0 : c0 + nc] = data

    stats = _run(read, write, grid, cfg, c is not None, progress)
    return out, stats


def filter_dsm(
    input_path,
    output_path,
    confidence_path=None,
    config: DsmFilterConfig | None = None,
    progress: Progress | None = None,
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

    Raises
    ------
    CRSError
        The DSM (or the confidence raster) has no CRS, or the DSM's CRS is geographic.
    InputError
        Every cell of the DSM is nodata, or a bad parameter.
    """
    from ..geometry.frame import parse_crs, require_metric
    from ..rasterio_io import RasterWriter, raster_grid, read_onto_grid, read_raster

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

    def read(r0, c0, nr, nc):
        z, _, _ = read_raster(input_path, 1, (r0, c0, nr, nc))
        z = z.astype(np.float64)
        if z.dtype.kind == "f" and nodata is not None and not math.isnan(nodata):
            z[z == nodata] = np.nan
        conf = None
        if confidence_path is not None:
            if same_grid:
                conf, _, _ = read_raster(confidence_path, 1, (r0, c0, nr, nc))
            else:
                conf = read_onto_grid(confidence_path, grid.window(r0, c0, nr, nc))
            conf = np.nan_to_num(conf.astype(np.float64), nan=0.0)
        return z, conf

    with RasterWriter(
        output_path, grid, bands=1, dtype="float32", nodata=out_nodata, descriptions=["filtered DSM height"]
    ) as w:

        def write(data, core):
            w.write(np.where(np.isfinite(data), data, out_nodata).astype(np.float32), core)

        stats = _run(read, write, grid, cfg, confidence_path is not None, progress)
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
