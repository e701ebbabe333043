"""True-orthophoto tile tasks that can run anywhere: in this process or on a Dask worker.

One task (:func:`ortho_tile_task`) computes one tile of the mosaic: visibility
in every candidate image (:mod:`.views`), selection, seams and blending
(:mod:`.mosaic`). Its inputs are plain data: the :class:`OrthoContext` shared
by all tiles of a run (view setup, surface, output grid, plan transform,
image paths, colour correction, parameters) and an :class:`OrthoTask` (the
tile and the labels its neighbours already chose inside its outer window).
It returns the tile's *core*: values + alpha in the images' data type, the
source index (int16) and the occlusion mask (uint8), plus two counters.

Order of tiles (:func:`waves`): a tile continues the labels that finished
neighbouring tiles wrote inside its outer window, so that seams do not start
at tile borders. The tiles run in four *waves* by the parity of their index
``(i, j)``: first every ``(even, even)`` tile (their outer windows meet no
other core of the wave), then ``(even, odd)`` (continuing their left and
right neighbours), then ``(odd, even)`` (above and below), then
``(odd, odd)`` (all eight neighbours). Tiles of one wave are independent, so
a wave is one parallel call of a quarter of the tiles, whatever the size of
the grid. Every backend runs the same waves with the same inputs, so the
mosaic is bit-identical everywhere. Between waves the client keeps only the
border strips (overlap wide) of the finished tiles' labels
(:class:`DoneLabels`).

On a worker, the images are decoded through an :class:`~.mosaic.ImageStore`
kept per worker process (:func:`worker_store`, an LRU of two keyed by the
paths); in this process the run's own store is used (never pickled).

Memory of one task (:func:`task_memory`): for ``K`` candidate images over an
outer window of ``n`` cells, the per-candidate arrays (pixel coordinates
8 B, effective resolution 4 B, flags 2 B, data cost 4 B, luminance 4 B,
blend weight 4 B, colours ``4 x bands`` B), i.e. ``K n (26 + 4 bands)``
bytes, plus the occluder region (``(side + 2 margin)^2 x 26`` B: heights,
masks, triangles) and the decoded images of the candidates (at most
``image_cache_mb``, the worker's image cache; 4/3 of the image for its
reduced levels). With the default 512-cell tile (+ 2 x 13 overlap), 16
candidates and RGB: 16 x 538^2 x 38 B = 176 MB.
"""

from __future__ import annotations

import os
import threading
from dataclasses import dataclass, field

import numpy as np

from ..grid import RasterGrid, Tile
from ..parallel import Digest, ProcessLRU, task_cancelled, tune_worker_malloc
from .color import ColorCorrection
from .mosaic import ImageStore, MosaicParams, mosaic_tile, to_dtype
from .surface import PlanTransform
from .views import ViewSetup, all_tile_views, prune_views, views_need_prefer


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
    #: per image, the JPEG colour subsampling the store restores (:class:`~.mosaic.ImageStore`)
    chroma: tuple = ()
    #: the run's own image store, used in this process; never pickled (workers open their own)
    store: ImageStore | None = field(default=None, compare=False)
    #: visibility computed ahead in this process (:class:`ViewPrefetch`); never pickled
    prefetch: ViewPrefetch | None = field(default=None, compare=False)

    def __getstate__(self):
        state = dict(self.__dict__)
        state["store"] = None
        state["prefetch"] = None
        return state

    def store_key(self) -> tuple:
        return (self.paths, self.sizes, int(self.bands), str(self.dtype), int(self.cache_bytes), self.chroma)


@dataclass
class OrthoTask:
    """One tile and the labels (global image indices, -1 free) fixed by its neighbours."""

    tile: Tile
    fixed: np.ndarray  # (outer rows, outer cols) int16

    def key(self, base: str) -> str:
        return Digest(base, "ortho-tile", list(self.tile.outer), list(self.tile.core), self.fixed).hexdigest()


_STORES = ProcessLRU(2)


def worker_store(ctx: OrthoContext) -> ImageStore:
    """The run's image store in this process, else this worker process's own (LRU of two)."""
    if ctx.store is not None:
        return ctx.store
    return _STORES.get(
        ctx.store_key(),
        lambda: ImageStore(
            list(ctx.paths), list(ctx.sizes), ctx.bands, np.dtype(ctx.dtype), ctx.cache_bytes,
            chroma=list(ctx.chroma) or None,
        ),
    )


def _threads(ctx: OrthoContext) -> int:
    """Depth-buffer threads: the run's setting, at most the worker's numba threads on a worker."""
    cap = os.environ.get("NUMBA_NUM_THREADS", "")
    if ctx.store is None and cap.isdigit() and int(cap) > 0:
        return max(1, min(ctx.workers, int(cap)))
    return max(1, ctx.workers)


def ortho_tile_task(ctx: OrthoContext, task: OrthoTask):
    """One tile: ``(values + alpha (bands + 1, r, c) dtype, index int16, occlusion uint8, counters)``.

    ``counters`` = int64 ``[cell-image samples in the core, triangles of the depth buffers]``.
    """
    from ..errors import CancelledError

    tune_worker_malloc()
    tile = task.tile
    if task_cancelled():
        raise CancelledError("cancelled by the user")
    fixed = np.asarray(task.fixed).astype(np.int64)
    prefer = np.unique(fixed[fixed >= 0])
    threads = _threads(ctx)
    views = ctx.prefetch.take(tile) if ctx.prefetch is not None else None
    if views is None:
        views = all_tile_views(ctx.setup, ctx.surface, ctx.grid, tile, ctx.to_local, threads, prefer)
    views = prune_views(views, ctx.setup, prefer)
    sl = tile.inner_slices
    n_samples = int(views.usable[:, sl[0], sl[1]].sum()) if len(views.cands) else 0
    dtype = np.dtype(ctx.dtype)
    m = mosaic_tile(views, worker_store(ctx), ctx.correction, ctx.grid.res, ctx.params, fixed, threads)
    vals = to_dtype(m.values[:, sl[0], sl[1]], dtype)
    alpha = m.alpha[sl]
    vals[:, ~alpha] = 0
    amax = np.iinfo(dtype).max if dtype.kind in "ui" else 1.0
    a = np.where(alpha, amax, 0).astype(dtype)
    out = np.ascontiguousarray(np.concatenate([vals, a[None]], axis=0))
    lab = np.ascontiguousarray(m.label[sl].astype(np.int16))
    occ = np.ascontiguousarray(m.occlusion[sl])
    return out, lab, occ, np.array([n_samples, views.triangles], np.int64)


class ViewPrefetch:
    """The visibility of coming tiles (:func:`~.views.all_tile_views`), computed ahead in one
    background thread of this process.

    A tile's visibility does not depend on its neighbours' labels (only the pruning of
    :func:`~.views.prune_views` does), so the next wave's depth buffers can run while this wave
    selects, blends and writes, and the first wave's while the colour statistics run: the cores
    idle in those serial parts get work. :func:`ortho_tile_task` takes a tile's views from here
    when they were submitted, and computes them itself otherwise; the result is the same either
    way (the tile cache keys do not change). At most ``limit`` tiles' views wait here (memory:
    one task's per-candidate arrays each, :func:`task_memory`). Not used with the lazy
    ``views_per_cell`` order, which depends on the neighbours' labels.
    """

    def __init__(self, ctx: OrthoContext, limit: int = 1) -> None:
        from concurrent.futures import ThreadPoolExecutor

        self.ctx = ctx
        self.limit = max(1, int(limit))
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="truortho-views")
        self._futures: dict = {}
        self._lock = threading.Lock()  # tile threads take while the client submits
        self.taken = 0

    @staticmethod
    def usable(setup: ViewSetup) -> bool:
        return not views_need_prefer(setup)

    def _compute(self, tile: Tile):
        c = self.ctx
        return all_tile_views(c.setup, c.surface, c.grid, tile, c.to_local, _threads(c))

    def submit(self, tiles, besides=()) -> None:
        """Start the views of ``tiles`` (in order) while fewer than ``limit`` wait, not counting
        those of the tiles ``besides`` (the running wave's, about to be taken)."""
        skip = {t.index for t in besides}
        with self._lock:
            for t in tiles:
                if sum(1 for k in self._futures if k not in skip) >= self.limit:
                    break
                if t.index not in self._futures:
                    self._futures[t.index] = self._pool.submit(self._compute, t)

    def take(self, tile: Tile):
        """The views of ``tile`` if submitted (waits for them; re-raises their error), else None."""
        with self._lock:
            f = self._futures.pop(tile.index, None)
            if f is None:
                return None
            self.taken += 1
        return f.result()

    def discard(self, tiles) -> None:
        """Forget ``tiles`` (e.g. found in the tile cache, so never taken)."""
        with self._lock:
            for t in tiles:
                f = self._futures.pop(t.index, None)
                if f is not None:
                    f.cancel()

    def close(self) -> None:
        """Drop what waits and end the thread (after the tile it may be computing)."""
        with self._lock:
            for f in self._futures.values():
                f.cancel()
            self._futures.clear()
        self._pool.shutdown(wait=True)


def waves(tiles: list[Tile]) -> list[list[Tile]]:
    """The tiles in four parity waves (module docstring), each in row-major order."""
    order = ((0, 0), (0, 1), (1, 0), (1, 1))
    out = [[t for t in tiles if (t.index[0] % 2, t.index[1] % 2) == p] for p in order]
    return [w for w in out if w]


class DoneLabels:
    """Border strips (``width`` cells) of the labels of finished tile cores, by tile index."""

    def __init__(self, width: int) -> None:
        self.width = max(int(width), 1)
        self._strips: dict[tuple[int, int], list[tuple[int, int, np.ndarray]]] = {}

    def add(self, tile: Tile, labels: np.ndarray) -> None:
        r0, c0, nr, nc = tile.core
        w = self.width
        lab = np.asarray(labels)
        strips = [(r0, c0, lab[:w].copy()), (r0 + max(nr - w, 0), c0, lab[max(nr - w, 0) :].copy())]
        strips += [(r0, c0, lab[:, :w].copy()), (r0, c0 + max(nc - w, 0), lab[:, max(nc - w, 0) :].copy())]
        self._strips[tile.index] = strips

    def fixed(self, tile: Tile) -> np.ndarray:
        """Labels already decided in the tile's outer window (-1 elsewhere), int16."""
        r0, c0, nr, nc = tile.outer
        out = np.full((nr, nc), -1, np.int16)
        for strips in self._strips.values():
            for sr0, sc0, lab in strips:
                snr, snc = lab.shape
                a0, a1 = max(r0, sr0), min(r0 + nr, sr0 + snr)
                b0, b1 = max(c0, sc0), min(c0 + nc, sc0 + snc)
                if a1 > a0 and b1 > b0:
                    out[a0 - r0 : a1 - r0, b0 - c0 : b1 - c0] = lab[a0 - sr0 : a1 - sr0, b0 - sc0 : b1 - sc0]
        return out


def task_memory(outer_side: int, margin: int, candidates: int, bands: int, image_bytes: int) -> int:
    """Bytes one task needs at most (module docstring); ``image_bytes``: the decoded images it may
    hold (at most the image cache)."""
    n = int(outer_side) ** 2
    per_candidate = int(candidates) * n * (26 + 4 * int(bands))
    region = (int(outer_side) + 2 * int(margin)) ** 2 * 26
    return per_candidate + region + int(image_bytes)


def tile_candidates(
    setup: ViewSetup, grid: RasterGrid, tiles: list[Tile], to_local: PlanTransform
) -> np.ndarray:
    """Candidate images per tile (footprint boxes meeting its outer window), int."""
    b = setup.boxes
    out = np.zeros(len(tiles), np.int64)
    for n, t in enumerate(tiles):
        x0, y0, x1, y1 = t.outer_grid(grid).extent
        lx, ly = to_local.xy(np.array([x0, x1, x0, x1]), np.array([y0, y0, y1, y1]))
        with np.errstate(invalid="ignore"):
            hit = (b[:, 0] <= lx.max()) & (b[:, 2] >= lx.min())
            hit &= (b[:, 1] <= ly.max()) & (b[:, 3] >= ly.min())
        out[n] = int(np.count_nonzero(hit))
    return out


def tile_costs(setup: ViewSetup, grid: RasterGrid, tiles: list[Tile], candidates: np.ndarray) -> np.ndarray:
    """Relative cost of each tile: candidates x outer cells + the occluder region's cells.

    Used to start the costliest tiles of a wave first (longest-processing-time order), so a
    tile near a tower does not start last and keep the other workers waiting.
    """
    out = np.empty(len(tiles))
    tan_v = float(np.tan(setup.max_view))
    for n, t in enumerate(tiles):
        og = t.outer_grid(grid)
        m = setup.margin_cells
        if setup.blocks is not None and m > 0:
            m = setup.blocks.margin(og, m, tan_v)
        cells = og.rows * og.cols
        out[n] = max(int(candidates[n]), 1) * cells + 0.5 * (og.rows + 2 * m) * (og.cols + 2 * m)
    return out


def side_of(tile_size: int, overlap: int) -> int:
    return int(tile_size) + 2 * int(overlap)


__all__ = [
    "OrthoContext",
    "OrthoTask",
    "ViewPrefetch",
    "tile_candidates",
    "tile_costs",
    "DoneLabels",
    "ortho_tile_task",
    "side_of",
    "task_memory",
    "waves",
    "worker_store",
]
