"""OSGM tile tasks that can run anywhere: in this process or on a Dask worker.

One task matches one tile of one pyramid level (:func:`osgm_tile_task`). Its
inputs are plain data: the :class:`TileContext` of the reference system
(image paths and sizes, the views already rotated into the system, the
matching band; shared by all tasks of a level) and a :class:`TileTask` (the
tile's corner, cell size, per-cell Z windows ``lo``/``hi`` and the guide
heights, both computed from the previous level's result by the caller, the
level's parameters, the core window). It returns ``(z, confidence)`` of the
tile's *core* cells, float32.

Given the previous level, the tiles of one level are independent, so a
level is one :meth:`~truortho.core.parallel.Executor.map_tiles` call.

On a worker, the images are opened through an :class:`~.views.ImagePyramid`
kept per worker process (:func:`worker_pyramid`, a small LRU keyed by the
paths), so the decoded images are reused by the next tiles; in this process
the run's own pyramid is used (it is not pickled with the context).

Memory of one task (:func:`task_memory`): the cost volume and the aggregated
volume, ``rows x cols x nd`` uint16 each (``nd`` the widest band of Z levels
of a cell: up to :data:`~.levels.MAX_BAND` below the coarsest level, at most
about :data:`~.levels.COARSE_LEVELS` on it), i.e. ``cells x nd x 2 bytes x
2``, plus the image windows (float32, up to ``max_images`` of them) and a few
per-cell arrays. With the default tile of 256 cells (+ 2 x 32 overlap) and
``nd = 192``: 320² x 192 x 4 B = 79 MB, plus the windows. A worker also keeps
its decoded images (``cache_bytes``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..parallel import Digest, ProcessLRU, current_cancel, file_identity, tune_worker_malloc
from .matching import TileParams, View, match_tile
from .views import ImagePyramid


@dataclass
class TileContext:
    """What all tasks of one reference system share (pickled once per level for Dask)."""

    paths: tuple[str, ...]
    sizes: tuple[tuple[int, int], ...]
    band: int | None
    cache_bytes: int
    views: list[View]
    #: per image, the point spread its matching band is restored by (``ImagePyramid.spread``)
    spread: tuple[float, ...] = ()
    #: the restoration's window (``ImagePyramid.window_px``)
    window: int = 5
    #: the low-pass of the matching band of photos not restored (``ImagePyramid.prefilter``)
    prefilter: float = 0.0
    #: the run's own pyramid, used in this process; never pickled (workers open their own)
    pyramid: ImagePyramid | None = field(default=None, compare=False)

    def __getstate__(self):
        state = dict(self.__dict__)
        state["pyramid"] = None
        return state

    def pyramid_key(self) -> tuple:
        return (
            tuple(self.paths), tuple(tuple(s) for s in self.sizes), self.band, int(self.cache_bytes),
            tuple(self.spread), int(self.window), float(self.prefilter),
        )  # fmt: skip

    def digest(self) -> Digest:
        """Identity of the inputs: image files (path, size, mtime), views, band."""
        d = Digest(
            "osgm-context", [file_identity(p) for p in self.paths], [list(s) for s in self.sizes], self.band,
            [float(v) for v in self.spread], int(self.window), float(self.prefilter),
        )  # fmt: skip
        for v in self.views:
            d.add(
                [
                    v.index,
                    np.asarray(v.R, np.float64),
                    np.asarray(v.C, np.float64),
                    np.asarray(v.camera.params, np.float64),
                    [int(v.camera.width), int(v.camera.height)],
                    float(v.r2max),
                    float(v.axis_cos),
                ]
            )
        return d


@dataclass
class TileTask:
    """One tile of one level: inputs of :func:`match_tile` and where its core lies."""

    level: int
    outer: tuple[int, int, int, int]  # (r0, c0, rows, cols) in the level's grid
    core: tuple[int, int, int, int]
    x0: float  # outer north-west corner (system frame)
    y0: float
    res: float
    lo: np.ndarray  # (rows, cols) int32 absolute Z levels
    hi: np.ndarray
    z_base: float
    dz: float
    params: TileParams
    guide: np.ndarray | None  # (rows, cols) float32 heights of the coarser level, or None
    gap_lo: np.ndarray | None = None  # (rows, cols) int32 levels not searched (levels.refine_bands)
    gap_hi: np.ndarray | None = None
    blend: int = 0  # cells beyond the core returned for blending the seams (blend_window)

    def returned(self) -> tuple[slice, slice]:
        """Slices (in the outer window) of what the task returns: its blend window."""
        r0, c0, nr, nc = blend_window(self.core, self.outer, self.blend)
        r, c = r0 - self.outer[0], c0 - self.outer[1]
        return slice(r, r + nr), slice(c, c + nc)

    def key(self, base: str) -> str:
        """Cache key: ``base`` (inputs and parameters of the run) + every input of this task."""
        return (
            Digest(
                base,
                "osgm-tile",
                self.level,
                list(self.outer),
                list(self.core),
                float(self.x0),
                float(self.y0),
                float(self.res),
                self.lo,
                self.hi,
                float(self.z_base),
                float(self.dz),
                dataclasses.asdict(self.params),
                self.guide,
                self.gap_lo,
                self.gap_hi,
                int(self.blend),
            )
        ).hexdigest()


def blend_window(core, outer, blend: int) -> tuple[int, int, int, int]:
    """``(r0, c0, rows, cols)``: the core grown by ``blend`` cells on every side, within ``outer``."""
    r0 = max(core[0] - blend, outer[0])
    c0 = max(core[1] - blend, outer[1])
    r1 = min(core[0] + core[2] + blend, outer[0] + outer[2])
    c1 = min(core[1] + core[3] + blend, outer[1] + outer[3])
    return r0, c0, r1 - r0, c1 - c0


def _ramp(start: int, n: int, core_start: int, core_n: int, blend: int) -> np.ndarray:
    """Weights along one axis of a blend window: 1 well inside the core, falling linearly to 0
    over ``2 blend`` cells centred on the core's edges; two neighbours' weights sum to 1."""
    i = np.arange(start, start + n)
    s = np.minimum(i - core_start, core_start + core_n - 1 - i)  # < 0 outside the core
    return np.clip((s + 0.5 + blend) / (2.0 * blend), 0.0, 1.0)


def assemble_tiles(shape, tiles, results, blend: int, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Heights and confidences ``(shape)`` of a level from its tiles' results (their blend windows).

    Every cell keeps its core owner's validity and confidence. Within ``blend`` cells of a seam the
    height is the weighted mean of the tiles that matched the cell (weights ramping across the seam,
    :func:`_ramp`) where they all agree within ``tol``; where they disagree (a wall that one tile
    placed a cell away, a different match), the owner's height stays: blending would put a height
    between two surfaces. Tiles are matched with different images and borders, so their heights
    differ slightly at a seam (on copr at 0.05 m about twice the cell-to-cell difference): cut hard,
    the seams showed as straight lines on the tile grid in a hillshade.
    """
    if isinstance(blend, bool) or not isinstance(blend, int | np.integer) or blend < 0:
        raise InputError(f"assemble_tiles: blend must be a number of cells >= 0, got {blend!r}")
    if not (np.isfinite(tol) and tol >= 0):
        raise InputError(f"assemble_tiles: tol must be a finite height >= 0, got {tol!r}")
    z = np.full(shape, np.nan, np.float32)
    conf = np.full(shape, np.nan, np.float32)
    if blend > 0:
        sw = np.zeros(shape, np.float32)
        swz = np.zeros(shape, np.float64)
        zmin = np.full(shape, np.inf, np.float32)
        zmax = np.full(shape, -np.inf, np.float32)
        count = np.zeros(shape, np.uint8)  # tiles that matched the cell
    for tile, (zt, ct) in zip(tiles, results, strict=True):
        r0, c0, nr, nc = blend_window(tile.core, tile.outer, blend)
        if zt.shape != (nr, nc) or ct.shape != (nr, nc):
            raise InputError(
                f"assemble_tiles: tile {tile.index} returned heights {zt.shape} and confidences "
                f"{ct.shape}, expected its blend window {(nr, nc)} (core {tile.core}, blend {blend})"
            )
        a, b = tile.core[0] - r0, tile.core[1] - c0
        core = tile.core_slices
        z[core] = zt[a : a + tile.core[2], b : b + tile.core[3]]
        conf[core] = ct[a : a + tile.core[2], b : b + tile.core[3]]
        if blend > 0:
            win = slice(r0, r0 + nr), slice(c0, c0 + nc)
            wr = _ramp(r0, nr, tile.core[0], tile.core[2], blend)
            w = np.outer(wr, _ramp(c0, nc, tile.core[1], tile.core[3], blend)).astype(np.float32)
            ok = np.isfinite(zt)
            w[~ok] = 0.0
            sw[win] += w
            count[win] += ok
            swz[win] += w * np.nan_to_num(zt)
            np.fmin(zmin[win], zt, out=zmin[win])  # fmin/fmax skip NaN
            np.fmax(zmax[win], zt, out=zmax[win])
    if blend > 0:
        mix = np.isfinite(z) & (count > 1) & (sw > 0) & (zmax - zmin <= tol)
        z[mix] = (swz[mix] / sw[mix]).astype(np.float32)
    return z, conf


_PYRAMIDS = ProcessLRU(2)


def worker_pyramid(ctx: TileContext) -> ImagePyramid:
    """The run's pyramid in this process, else this worker process's own (LRU of two)."""
    if ctx.pyramid is not None:
        return ctx.pyramid
    return _PYRAMIDS.get(
        ctx.pyramid_key(),
        lambda: ImagePyramid(
            list(ctx.paths), list(ctx.sizes), ctx.band, ctx.cache_bytes, ctx.spread or None, ctx.window,
            ctx.prefilter,
        ),
    )


def osgm_tile_task(ctx: TileContext, task: TileTask) -> tuple[np.ndarray, np.ndarray]:
    """Match one tile; ``(z, confidence)`` of its blend window (its core and ``task.blend`` cells
    around it within the outer window; float32, NaN where rejected)."""
    tune_worker_malloc()
    res = match_tile(
        ctx.views,
        worker_pyramid(ctx),
        task.x0,
        task.y0,
        task.res,
        task.lo,
        task.hi,
        task.z_base,
        task.dz,
        task.params,
        task.guide,
        current_cancel(),
        task.gap_lo,
        task.gap_hi,
    )
    ins = task.returned()
    return np.ascontiguousarray(res.z[ins]), np.ascontiguousarray(res.confidence[ins])


def task_memory(rows: int, cols: int, nd: int, n_images: int, window_pixels: int, radius: int = 2) -> int:
    """Bytes one task needs at most (module docstring): volumes, windows, per-cell arrays."""
    from ..jit import numba
    from .sweep import BLOCK, _packing

    cells = int(rows) * int(cols)
    volumes = cells * int(nd) * 2 * 2  # cost + aggregated, uint16
    windows = int(n_images) * int(window_pixels) * 4  # float32 image windows
    per_cell = cells * 4 * 16  # lo, hi, z0, guide, remapped slices, level, confidence, ...
    n = int(n_images)
    # the plane sweep's work arrays (.sweep): samples, gradients and validity per image, and every
    # thread's packed pair terms of one block with its margins
    side = BLOCK + 2 * int(radius)
    terms = side * side * (n * (n - 1) // 2) * _packing(int(radius))[0].itemsize
    sweep = cells * n * (4 + 2 + 2 + 1) + int(numba.config.NUMBA_NUM_THREADS) * terms
    # and its windows packed once more into one buffer
    return volumes + 2 * windows + per_cell + sweep
