"""The DSM filter's runs: :func:`filter_dsm` (files, by tiles) and :func:`filter_dsm_array` (in memory)."""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import asdict

import numpy as np

from ...errors import InputError
from ...grid import RasterGrid
from ...parallel import Digest, Executor, InProcessExecutor, TileCache
from ...progress import Progress, Steps, as_progress
from .config import DsmFilterConfig, FilterStats
from .tiles import (
    CACHE_VERSION,
    ArrayReader,
    FileReader,
    FilterContext,
    Pass1Task,
    Pass2Task,
    _Components,
    filter_pass1_task,
    filter_pass2_task,
    task_memory,
)

# ------------------------------------------------------------------ pipeline

#: largest size of the filtered cores held by this process between two writes (pass 2 batches)
WRITE_BATCH_BYTES = 256 << 20

Writer = Callable[[np.ndarray, tuple[int, int, int, int]], None]


def _run(
    ctx: FilterContext,
    write: Writer,
    executor: Executor,
    cache: TileCache | None,
    progress: Progress | None,
) -> FilterStats:
    from ...progress import SubProgress

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
    from ...geometry.frame import parse_crs, require_metric
    from ...rasterio_io import RasterWriter, raster_grid, read_raster

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
    from ...rasterio_io import read_raster

    for t in grid.tiles(2048, 0):
        z, _, nodata = read_raster(path, 1, t.core)
        z = z.astype(np.float64)
        if nodata is not None:
            z[z == nodata] = np.nan
        if np.isfinite(z).any():
            return
    raise InputError(f"{path}: every cell is nodata; nothing to filter")
