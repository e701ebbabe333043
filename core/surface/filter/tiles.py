"""Tile plumbing of the DSM filter: hole components merged across tiles, readers, the two passes' tasks.

The tasks run anywhere (this process, a local Dask cluster, a scheduler): they take picklable
contexts and readers only (see "Parallel execution" in :mod:`truortho.core.surface.filter`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...grid import RasterGrid
from ...parallel import Digest, file_identity, tune_worker_malloc
from .config import DsmFilterConfig
from .holes import _FOUR, _closed_gaps, _fill_holes, _hole_width
from .stages import _clean, _smooth

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
        from ...rasterio_io import read_onto_grid, read_raster

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


def task_memory(rows: int, cols: int) -> int:
    """Bytes one tile task needs at most for an outer window of ``rows x cols`` cells."""
    return int(rows) * int(cols) * TASK_BYTES_PER_CELL


def _inner(core, outer) -> tuple[slice, slice]:
    r = core[0] - outer[0]
    c = core[1] - outer[1]
    return slice(r, r + core[2]), slice(c, c + core[3])


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
