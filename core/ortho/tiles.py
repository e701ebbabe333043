"""True-orthophoto tile tasks that can run anywhere: in this process or on a Dask worker.

One task (:func:`ortho_tile_task`) computes one tile of the mosaic: visibility
in every candidate image (:mod:`.views`), selection, seams and blending
(:mod:`.mosaic`). Its inputs are plain data: the :class:`OrthoContext` shared
by all tiles of a run (view setup, surface, output grid, plan transform,
image paths, colour correction, parameters) and an :class:`OrthoTask` (the
tile and the labels its neighbours already chose inside its outer window).
It returns the tile's *core*: values + alpha in the images' data type, the
source index (int16) and the occlusion mask (uint8), plus two counters.

Order of tiles (:func:`waves`): a tile continues the labels of the tiles
whose cores meet its outer window (row above: left, same, right; same row:
left), so that seams do not start at tile borders. Tile ``(i, j)`` therefore
runs after those four; all tiles with the same ``2 i + j`` (a *wave*) are
independent of each other and run in parallel. Every backend runs the same
waves with the same inputs, so the mosaic is bit-identical everywhere.

On a worker, the images are decoded through an :class:`~.mosaic.ImageStore`
kept per worker process (:func:`worker_store`, an LRU of two keyed by the
paths); in this process the run's own store is used (never pickled).

Memory of one task (:func:`task_memory`): for ``K`` candidate images over an
outer window of ``n`` cells, the per-candidate arrays (pixel coordinates
8 B, effective resolution 4 B, flags 2 B, data cost 4 B, luminance 4 B,
blend weight 4 B, colours ``4 x bands`` B), i.e. ``K n (26 + 4 bands)``
bytes, plus the occluder region (``(side + 2 margin)^2 x 26`` B: heights,
masks, triangles) and the decoded images the worker caches
(``image_cache_mb``). With the default 512-cell tile (+ 2 x 13 overlap),
16 candidates and RGB: 16 x 538^2 x 38 B = 176 MB.
"""

from __future__ import annotations

import os
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np

from ..grid import RasterGrid, Tile
from ..parallel import Digest, current_cancel
from .color import ColorCorrection
from .mosaic import ImageStore, MosaicParams, mosaic_tile, to_dtype
from .surface import PlanTransform
from .views import ViewSetup, tile_views


@dataclass
class OrthoContext:
    """What all tiles of a run share (pickled once per wave for Dask)."""

    setup: ViewSetup
    surface: object
    grid: RasterGrid
    to_local: PlanTransform
    paths: tuple[str, ...]
    sizes: tuple[tuple[int, int], ...]
    bands: int
    dtype: str
    cache_bytes: int
    correction: ColorCorrection | None
    params: MosaicParams
    workers: int
    #: the run's own image store, used in this process; never pickled (workers open their own)
    store: ImageStore | None = field(default=None, compare=False)

    def __getstate__(self):
        state = dict(self.__dict__)
        state["store"] = None
        return state

    def store_key(self) -> tuple:
        return (self.paths, self.sizes, int(self.bands), str(self.dtype), int(self.cache_bytes))


@dataclass
class OrthoTask:
    """One tile and the labels (global image indices, -1 free) fixed by its neighbours."""

    tile: Tile
    fixed: np.ndarray  # (outer rows, outer cols) int16

    def key(self, base: str) -> str:
        return Digest(base, "ortho-tile", list(self.tile.outer), list(self.tile.core), self.fixed).hexdigest()


_STORES: OrderedDict = OrderedDict()
_MAX_STORES = 2


def worker_store(ctx: OrthoContext) -> ImageStore:
    """The run's image store in this process, else this worker process's own (LRU of two)."""
    if ctx.store is not None:
        return ctx.store
    k = ctx.store_key()
    st = _STORES.get(k)
    if st is None:
        st = ImageStore(list(ctx.paths), list(ctx.sizes), ctx.bands, np.dtype(ctx.dtype), ctx.cache_bytes)
        _STORES[k] = st
        while len(_STORES) > _MAX_STORES:
            _STORES.popitem(last=False)
    else:
        _STORES.move_to_end(k)
    return st


def _threads(ctx: OrthoContext) -> int:
    """Depth-buffer threads: the run's setting, at most the worker's numba threads on a worker."""
    if ctx.store is not None:
        return max(1, int(ctx.workers))
    try:
        cap = int(os.environ.get("NUMBA_NUM_THREADS", "0"))
    except ValueError:
        cap = 0
    return max(1, min(int(ctx.workers), cap)) if cap > 0 else max(1, int(ctx.workers))


def ortho_tile_task(ctx: OrthoContext, task: OrthoTask):
    """One tile: ``(values + alpha (bands + 1, r, c) dtype, index int16, occlusion uint8, counters)``.

    ``counters`` = int64 ``[cell-image samples in the core, triangles of the depth buffers]``.
    """
    from ..errors import CancelledError

    tile = task.tile
    cancel = current_cancel()
    if cancel is not None and cancel():
        raise CancelledError("cancelled by the user")
    fixed = np.asarray(task.fixed).astype(np.int64)
    prefer = np.unique(fixed[fixed >= 0])
    views = tile_views(ctx.setup, ctx.surface, ctx.grid, tile, ctx.to_local, _threads(ctx), prefer=prefer)
    sl = tile.inner_slices
    n_samples = int(views.usable[:, sl[0], sl[1]].sum()) if len(views.cands) else 0
    dtype = np.dtype(ctx.dtype)
    m = mosaic_tile(views, worker_store(ctx), ctx.correction, ctx.grid.res, ctx.params, fixed)
    vals = to_dtype(m.values[:, sl[0], sl[1]], dtype)
    alpha = m.alpha[sl]
    vals[:, ~alpha] = 0
    amax = np.iinfo(dtype).max if dtype.kind in "ui" else 1.0
    a = np.where(alpha, amax, 0).astype(dtype)
    out = np.ascontiguousarray(np.concatenate([vals, a[None]], axis=0))
    lab = np.ascontiguousarray(m.label[sl].astype(np.int16))
    occ = np.ascontiguousarray(m.occlusion[sl])
    return out, lab, occ, np.array([n_samples, views.triangles], np.int64)


def waves(tiles: list[Tile]) -> list[list[Tile]]:
    """Tiles grouped by ``2 i + j`` (module docstring), each group in row-major order."""
    groups: dict[int, list[Tile]] = {}
    for t in tiles:
        groups.setdefault(2 * t.index[0] + t.index[1], []).append(t)
    return [groups[k] for k in sorted(groups)]


def fixed_labels(tile: Tile, done: dict) -> np.ndarray:
    """Labels already decided in the tile's outer window by finished tiles (-1 elsewhere), int16."""
    r0, c0, nr, nc = tile.outer
    out = np.full((nr, nc), -1, np.int16)
    for (cr0, cc0, cnr, cnc), lab in done.values():
        a0, a1 = max(r0, cr0), min(r0 + nr, cr0 + cnr)
        b0, b1 = max(c0, cc0), min(c0 + nc, cc0 + cnc)
        if a1 > a0 and b1 > b0:
            out[a0 - r0 : a1 - r0, b0 - c0 : b1 - c0] = lab[a0 - cr0 : a1 - cr0, b0 - cc0 : b1 - cc0]
    return out


def task_memory(outer_side: int, margin: int, candidates: int, bands: int, cache_bytes: int) -> int:
    """Bytes one task needs at most (module docstring)."""
    n = int(outer_side) ** 2
    per_candidate = int(candidates) * n * (26 + 4 * int(bands))
    region = (int(outer_side) + 2 * int(margin)) ** 2 * 26
    return per_candidate + region + int(cache_bytes)


def candidates_bound(setup: ViewSetup, grid: RasterGrid, side: int) -> int:
    """Most images whose footprint boxes meet one square window of ``side`` cells (a bound of K)."""
    b = setup.boxes
    ok = np.all(np.isfinite(b), axis=1)
    if not ok.any():
        return 1
    w = side * grid.res
    sizes = np.maximum(b[ok, 2] - b[ok, 0], b[ok, 3] - b[ok, 1])
    # an image meets a window of side w when the centres are within (size + w) / 2; bound by
    # the images whose box can reach any single point (the densest overlap), plus the window
    cx, cy = 0.5 * (b[ok, 0] + b[ok, 2]), 0.5 * (b[ok, 1] + b[ok, 3])
    best = 0
    for x, y in zip(cx, cy, strict=True):
        reach = 0.5 * (sizes + w)
        best = max(best, int(np.sum((np.abs(cx - x) <= reach) & (np.abs(cy - y) <= reach))))
    return max(1, min(best, len(sizes)))


def side_of(tile_size: int, overlap: int) -> int:
    return int(tile_size) + 2 * int(overlap)


__all__ = [
    "OrthoContext",
    "OrthoTask",
    "candidates_bound",
    "fixed_labels",
    "ortho_tile_task",
    "side_of",
    "task_memory",
    "waves",
    "worker_store",
]
