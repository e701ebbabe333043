"""The true orthophoto: orientation + surface -> mosaic, source index, occlusion mask, seamlines.

:func:`true_ortho` runs, tile by tile with bounded memory:

1. validation (before anything is written): orientation with a CRS, images on
   disk with one band count and data type, a surface covering the extent, a
   transformation path between the output CRS and the orientation's;
2. colour correction (optional): per-image corrections estimated by least
   squares from cells seen by several images, on a decimated copy of the output
   grid (:mod:`.color`);
3. per tile: visibility in every candidate image (:mod:`.views`), selection
   and seams (:mod:`.select`), blending (:mod:`.mosaic`), written to the
   outputs;
4. seamline polygons (one per source image) from the source index.

Reprojection: when the output CRS differs from the orientation's, the
computation runs on the *output* grid: the surface is resampled onto it, and
cell centres and depth-buffer vertices are transformed to the orientation's
frame with pyproj. The images are thus resampled exactly once, directly into
the output cells (no second warp of a finished mosaic), and the depth buffers
still work on exact local coordinates.

Outputs are GeoTIFFs written by tiles through
:class:`~truortho.core.rasterio_io.RasterWriter` (temporary file renamed on
success, tiled, internal overviews, COG layout): the mosaic with the source
images' bands and data type plus an alpha band, the source index (int16, image
index in the orientation, nodata -1) and the occlusion mask (uint8: 0 seen,
1 seen by no image, nodata 255 where the surface has no data).
"""

from __future__ import annotations

import contextlib
import math
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import CancelledError, CRSError, InputError, MissingFileError
from ..grid import RasterGrid
from ..imagery import image_info
from ..orientation import Orientation, as_orientation
from ..parallel import Digest, InProcessExecutor, file_identity, make_executor, tile_run
from ..progress import Progress, Steps, SubProgress, as_progress, check
from ..rasterio_io import COMPRESSIONS
from .color import (
    ColorCorrection,
    devignette_values,
    estimate_colour_model,
    estimate_vignetting,
    linear_luminance,
)
from .mosaic import ImageStore, MosaicParams, candidate_colours, each
from .seams import dissolve, region_polygons
from .surface import PlanTransform, open_surface, same_crs, transform_bounds
from .tiles import (
    DoneLabels,
    OrthoContext,
    OrthoTask,
    ViewPrefetch,
    ortho_tile_task,
    side_of,
    task_memory,
    tile_candidates,
    tile_costs,
    waves,
)
from .views import HeightBlocks, ViewSetup, prepare_views, tile_views
from .zbuffer import occluder_wall_min


@dataclass
class TrueOrthoConfig:
    """Parameters of :func:`true_ortho`.

    Attributes
    ----------
    resolution : float, optional
        Output cell size in CRS units (metres); default the surface's cell size
        (a DSM) or the median nadir GSD of the images (a mesh).
    extent : (xmin, ymin, xmax, ymax), optional
        In the output CRS; default the surface's extent.
    crs : str, optional
        Output CRS; default the orientation's.
    color_correction : bool
        Estimate and apply per-image corrections (:mod:`.color`).
    vignetting : bool
        With the colour correction, a radial vignetting per camera is estimated from the
        overlaps and removed first (:func:`~.color.estimate_vignetting`).
    max_view_angle : float
        Largest off-nadir angle (degrees) of a viewing ray that may texture a cell.
    blend_width : int
        Feathering width across seams, cells (0 = none).
    visibility : bool
        False gives the conventional orthorectification (no depth test), for comparisons: without
        the agreement of the views either (``consistency`` is not applied), which would otherwise
        drop most of the occluded views' colours that such an ortho is compared for.
    tile_size : int
        Core tile side in cells (memory grows with its square times the images per tile).
    depth_tolerance : float
        Factor of :func:`~.zbuffer.depth_tolerance`.
    noise_tolerance : float
        The depth test also allows ``noise_tolerance * sqrt(2) * sigma / cos(view angle)``, with
        ``sigma`` the surface's robust local height noise (:func:`~.zbuffer.height_noise`): on a
        rough matched DSM (low-texture fields, canopies) bumps within the noise do not hide the
        cells behind them from oblique views. About 0 on smooth surfaces and along walls. 0 = off.
    edge_penalty, smoothness, contrast, discontinuity, sweeps
        Selection energy (:mod:`.select`): penalty for a cell next to an
        occluder, seam weight, weight of the luminance disagreement in a seam,
        height step (m) of a discontinuity, ICM sweeps.
    edge_shift : float
        Cells next to a height discontinuity take their colour this many cells
        inside their own side (0 = at the cell centre), so building outlines do
        not mix roof and ground colours.
    wall_min : float, optional
        Height steps of the DSM below this (m) get no wall in the depth buffer
        (which holds only the DSM's walls, see :func:`~.zbuffer.dsm_triangles`);
        default :func:`~.zbuffer.occluder_wall_min` (a quarter cell over
        tan(MAX_VIEW_ANGLE); steps below twice that cannot hide a cell seen within that angle).
    zbuffer_oversample : float
        Depth-buffer pixels per output cell when the image pixel is finer than the cell.
    top_views : int
        After the visibility of a tile, only the images among the ``top_views`` best (smallest
        effective resolution) of at least one cell stay candidates of the tile (0 = all): with
        tens of images over a tile the others cannot win a cell but cost memory and time in
        the selection and blending. The colour statistics always use every image.
    views_per_cell : int
        Candidates of a tile are evaluated in order of their resolution over the tile; a cell
        takes no further candidate once this many images see it cleanly (visible, not next to
        an occluder), so later candidates run only on the cells still short of views (occluded
        cells, tile corners). 0 evaluates every image for every cell. The colour statistics
        always use every image.
    image_cache_mb : int
        Bound of the decoded-image cache.
    restore_chroma : bool
        JPEG images whose colour is stored at a lower resolution than their brightness (4:2:0 or
        4:2:2, read from the file header) get their colour edges restored from the brightness
        before they are sampled at full resolution (:mod:`truortho.core.chroma`): without it the
        decoder's smeared colour paints roof colours beside every outline.
    edge_colour : {"off", "checked", "surface"}
        The colour (not the brightness) of the cells within 3 cells of the surface's height steps
        taken from the cells of their own surface beyond the steps (:mod:`.edgecolour`): removes
        the colour fringe that JPEG leaves along roof outlines where the brightness cannot.
        ``checked`` (default): only where the cell's colour is already nearer its own surface's
        than the other side's, so that a DSM whose outlines are a cell or two off does not get
        roof colours painted on the ground. ``surface``: every such cell, for surfaces whose
        outlines are exact (LiDAR DSM, building model). RGB only.
    consistency : float
        A view whose colour differs from the consensus of a cell's views (the per-band median of
        at least three) by more than this fraction of the value scale (255 for 8-bit, 65535 for
        16-bit, 1 for float data, which should then lie in [0, 1]) on some band, where at least
        two views agree within it, is taken only when no agreeing view has pixels less than three
        times as large on the surface (:func:`~.select.add_disagreement`): where the surface is
        wrong (a matched DSM's raised ground beside a wall, a roof corner matched too low) or one
        photo holds a car that moved, the views that agree give the colour. 0 = off; not applied
        with ``visibility=False``.
    color_cells : int
        Cells of the decimated grid used to estimate the colour correction.
    workers : int
        Threads in this process: the independent tiles of a wave run in this many threads, and
        the per-image depth buffers of a tile too. With more than one (and the in-process
        executor), one background thread computes the visibility of the next tile ahead
        (:class:`~.tiles.ViewPrefetch`): during the colour statistics, and during a wave with
        fewer tiles than threads.
    cog : bool
        Cloud-Optimized GeoTIFF layout (with overviews) for the rasters.
    compression : {"deflate", "zstd", "lzw", "jpeg"}
        Compression of the orthophoto. The first three are lossless: DEFLATE (GDAL's level 6)
        gives the smallest files and is read by every GIS; ZSTD (level 1) writes about twice as
        fast and about 9 % larger; LZW for older readers. ``"jpeg"`` is lossy, for 8-bit RGB
        images only and with ``cog``: RGB is stored as YCbCr at ``jpeg_quality`` and the alpha band
        becomes the file's internal mask; about a fifth of the size. YCbCr halves the colour
        resolution, so colours blur across sharp edges: on the bench scene the ghosting measure
        (dE > 25 within 2 cells of building outlines) reads 18 % on the JPEG file against
        0.09 % on the lossless one. For delivery and viewing, not for measuring. The source
        index and the occlusion mask always stay lossless (DEFLATE when ``"jpeg"``).
    jpeg_quality : int
        JPEG quality, 1-100.
    executor : {"inprocess", "local", "scheduler"}
        Where the mosaic tiles run (:mod:`truortho.core.parallel`; the colour statistics, on a
        decimated grid, always run here). Tiles run in four waves (:mod:`.tiles`); the mosaic is
        bit-identical on every backend.
    scheduler_address : str, optional
        Dask scheduler of ``executor="scheduler"`` (default ``$TRUORTHO_DASK_SCHEDULER``).
    dask_workers : int, optional
        Worker processes of ``executor="local"`` (default the cores).
    cache_dir : path, optional
        Keep finished tiles there (content-addressed) and reuse them on a rerun; default a
        scratch folder beside the output (``<output>.tiles``), removed after success.
    """

    resolution: float | None = None
    extent: tuple[float, float, float, float] | None = None
    crs: str | None = None
    color_correction: bool = True
    #: With the colour correction, estimate and remove a radial vignetting per camera
    #: (:func:`~.color.estimate_vignetting`).
    vignetting: bool = True
    max_view_angle: float = 45.0
    blend_width: int = 5
    visibility: bool = True
    tile_size: int = 512
    depth_tolerance: float = 1.0
    noise_tolerance: float = 2.0
    edge_penalty: float = 1.0
    smoothness: float = 1.0
    contrast: float = 4.0
    discontinuity: float = 0.5
    sweeps: int = 8
    edge_shift: float = 0.75
    wall_min: float | None = None
    zbuffer_oversample: float = 1.0
    views_per_cell: int = 0
    top_views: int = 8
    image_cache_mb: int = 1024
    restore_chroma: bool = True
    edge_colour: str = "checked"
    consistency: float = 0.1
    color_cells: int = 60_000
    workers: int = 2
    cog: bool = True
    compression: str = "deflate"
    jpeg_quality: int = 90
    executor: str = "inprocess"
    scheduler_address: str | None = None
    dask_workers: int | None = None
    cache_dir: str | os.PathLike | None = None

    def validate(self) -> None:
        def bad(name, why):
            raise InputError(f"{name}: {why} (got {getattr(self, name)!r})")

        if self.resolution is not None and not (
            isinstance(self.resolution, int | float)
            and math.isfinite(self.resolution)
            and self.resolution > 0
        ):
            bad("resolution", "expected a positive cell size")
        if not 0 < float(self.max_view_angle) < 89:
            bad("max_view_angle", "expected degrees in (0, 89)")
        if not isinstance(self.blend_width, int) or not 0 <= self.blend_width <= 1000:
            bad("blend_width", "expected an integer number of cells in [0, 1000]")
        if isinstance(self.workers, bool) or not isinstance(self.workers, int) or self.workers < 1:
            bad("workers", "expected a positive number of threads")
        if self.dask_workers is not None and (
            isinstance(self.dask_workers, bool)
            or not isinstance(self.dask_workers, int)
            or self.dask_workers < 1
        ):
            bad("dask_workers", "expected a positive number of worker processes (or None)")
        if not isinstance(self.top_views, int) or not 0 <= self.top_views <= 1000:
            bad("top_views", "expected an integer >= 0 (0 = every image)")
        if not isinstance(self.views_per_cell, int) or not 0 <= self.views_per_cell <= 1000:
            bad("views_per_cell", "expected an integer >= 0 (0 = every image)")
        if not isinstance(self.tile_size, int) or not 32 <= self.tile_size <= 8192:
            bad("tile_size", "expected an integer in [32, 8192]")
        for name in ("depth_tolerance", "zbuffer_oversample"):
            if not float(getattr(self, name)) > 0:
                bad(name, "must be positive")
        for name in ("edge_penalty", "smoothness", "contrast", "discontinuity", "noise_tolerance"):
            if not float(getattr(self, name)) >= 0:
                bad(name, "must not be negative")
        if self.extent is not None and len(self.extent) != 4:
            bad("extent", "expected (xmin, ymin, xmax, ymax)")
        from .edgecolour import EDGE_COLOURS

        if self.edge_colour not in EDGE_COLOURS:
            bad("edge_colour", f"expected one of {', '.join(EDGE_COLOURS)}")
        if not isinstance(self.consistency, int | float) or not 0.0 <= self.consistency <= 1.0:
            bad("consistency", "expected a number from 0 (off) to 1")
        if self.compression not in ORTHO_COMPRESSIONS:
            bad("compression", f"expected one of {', '.join(ORTHO_COMPRESSIONS)}")
        if self.compression == "jpeg" and not self.cog:
            bad("compression", "JPEG is written in the COG layout only (cog=True)")
        if (
            isinstance(self.jpeg_quality, bool)
            or not isinstance(self.jpeg_quality, int)
            or not 1 <= self.jpeg_quality <= 100
        ):
            bad("jpeg_quality", "expected an integer in [1, 100]")
        from ..parallel import EXECUTORS

        if self.executor not in EXECUTORS:
            bad("executor", f"expected one of {', '.join(EXECUTORS)}")


#: compressions of the orthophoto (:attr:`TrueOrthoConfig.compression`): the writer's, but "none"
ORTHO_COMPRESSIONS = tuple(c for c in COMPRESSIONS if c != "none")


@dataclass
class SeamRegion:
    """The cells of one source image: ``geometry`` a shapely (multi)polygon in the output CRS."""

    image_index: int
    image_name: str
    cells: int
    geometry: object

    @property
    def wkt(self) -> str:
        return self.geometry.wkt  # type: ignore[attr-defined]


@dataclass
class TrueOrthoResult:
    """Paths, grid, seam regions, colour correction and statistics of a run."""

    output: Path
    source_index: Path | None
    occlusion: Path | None
    grid: RasterGrid
    seamlines: list[SeamRegion]
    correction: ColorCorrection | None
    stats: dict = field(default_factory=dict)


def _default_resolution(surface, orientation: Orientation, out_crs) -> float:
    """The DSM's cell size when it is in the output CRS, else the median nadir GSD."""
    same = surface.crs is None or out_crs is None or same_crs(surface.crs, out_crs)
    if getattr(surface, "res", None) and same:
        return float(surface.res)
    lo, hi = surface.height_range()
    z = 0.5 * (lo + hi) - orientation.offset[2]
    g = [
        abs(im.C[2] - z) / orientation.camera_of(im).fx
        for im in orientation.images
        if im.R[2, 2] < -math.cos(math.radians(20))
    ]
    if not g:
        g = [abs(im.C[2] - z) / orientation.camera_of(im).fx for im in orientation.images]
    return float(np.median(g))


#: Bytes one tile's visibility and mosaic may take, candidates included (:func:`_bounded_tiles`).
TILE_MEMORY_BUDGET = 512 << 20
#: Smallest side a tile is cut down to, cells.
MIN_TILE_SIZE = 128


def _bounded_tiles(setup, grid, to_local, tile_size: int, overlap: int, bands: int):
    """Tiles whose work fits :data:`TILE_MEMORY_BUDGET`: ``(tile_size, tiles, candidates per tile)``.

    A tile's visibility buffers grow with its cells times its candidate images. At a coarse
    resolution a tile of the configured size spans a large part of a big block, and every
    image becomes a candidate (105 photos at 4x GSD: 1.2 GB per tile, two in flight). The side is
    halved, down to :data:`MIN_TILE_SIZE`, until the costliest tile fits; the products do not
    depend on the tiling beyond the seamlines' placement.
    """
    size = int(tile_size)
    while True:
        tiles = grid.tiles(size, overlap)
        k_tile = tile_candidates(setup, grid, tiles, to_local)
        k_max = int(max(1, k_tile.max())) if len(k_tile) else 1
        need = task_memory(side_of(size, overlap), setup.margin_cells, k_max, bands, 0)
        if need <= TILE_MEMORY_BUDGET or size // 2 < MIN_TILE_SIZE:
            return size, tiles, k_tile
        size //= 2


@dataclass(frozen=True)
class OrthoPlan:
    """Stage 1 of :func:`true_ortho`: the checked inputs and the output grid.

    ``to_local`` maps output-CRS plan coordinates to the orientation's local frame; ``grid``
    is the output raster (cell size ``res`` in output CRS units).
    """

    orientation: Orientation
    surface: object
    out_crs: str | None
    to_local: PlanTransform
    grid: RasterGrid
    res: float


@dataclass(frozen=True)
class OrthoCandidates:
    """Stage 2: the per-image visibility setup and the images that can texture the grid.

    ``relevant`` (K,) indices of the images whose footprint meets the extent (the others'
    boxes are NaN in ``setup``); ``paths`` and ``sizes`` (width, height) of every image;
    ``bands``/``dtype`` shared by the relevant images; ``store`` their decoded-image cache.
    """

    setup: ViewSetup
    relevant: np.ndarray
    paths: list[str]
    sizes: list[tuple[int, int]]
    bands: int
    dtype: np.dtype
    store: ImageStore


@dataclass(frozen=True)
class OrthoSchedule:
    """Stage 3: the tiles, in waves cut into batches (the costliest of a wave first).

    ``k_max`` is the most candidate images of a tile and ``memory`` the bytes one tile task
    may take (:func:`~.tiles.task_memory`), given to the executor.
    """

    overlap: int
    tile_size: int
    tiles: list
    batches: list[list]
    k_max: int
    memory: int


@dataclass(frozen=True)
class OrthoMosaic:
    """Stage 4: what running the tiles wrote and counted (the rasters are closed).

    ``counts`` (N,) cells taken from every image; the ``n_*`` counters are cells of the grid;
    ``stats`` the run's entries of :attr:`TrueOrthoResult.stats` (colour, executor, memory, times).
    """

    correction: ColorCorrection | None
    regions: list[SeamRegion]
    counts: np.ndarray
    n_valid: int
    n_seen: int
    n_occluded: int
    n_samples: int
    max_triangles: int
    stats: dict


def true_ortho(
    orientation,
    surface,
    output,
    source_index=None,
    occlusion=None,
    config: TrueOrthoConfig | None = None,
    progress: Progress | None = None,
    image_root: str | os.PathLike | None = None,
    executor=None,
) -> TrueOrthoResult:
    """Compute a true orthophoto.

    The stages: :func:`plan_ortho` (inputs, grid) -> :func:`ortho_candidates` (visibility setup,
    images) -> :func:`schedule_tiles` -> :func:`run_mosaic` (colour correction, tiles, rasters,
    seamlines) -> the result and its statistics.

    Parameters
    ----------
    orientation : Orientation or path to an orientation JSON
        Images, cameras and the CRS/offset of the local frame.
    surface : path (GeoTIFF DSM, PLY/OBJ mesh), :class:`~.surface.DsmSurface`,
        :class:`~.surface.ArraySurface`, :class:`~.surface.MeshSurface` or any
        object with ``vertices``/``faces``/``crs``.
    output : path
        The mosaic GeoTIFF (bands of the images + alpha).
    source_index, occlusion : path, optional
        Source-index (int16) and occlusion-mask (uint8) GeoTIFFs.
    config : TrueOrthoConfig
    progress : Progress, optional
        Reports per tile; cancelling leaves no output.
    image_root : path, optional
        Overrides the orientation's image folder.
    executor : :class:`~truortho.core.parallel.Executor`, optional
        Where the tiles run; default one made from ``config.executor`` (closed at the end).

    Returns
    -------
    TrueOrthoResult

    Raises
    ------
    InputError, MissingFileError, CRSError, FormatError
        Bad input, detected before any output is written.
    CancelledError
    """
    t_start = time.perf_counter()
    cfg = config or TrueOrthoConfig()
    cfg.validate()
    if executor is None:
        # a malformed EXECUTOR / SCHEDULER_ADDRESS fails here, before any work (nothing connects yet)
        make_executor(cfg.executor, cfg.scheduler_address, n_workers=cfg.dask_workers).close()
    steps = Steps(progress, [1, 3 if cfg.color_correction else 0, 12, 1])
    plan = plan_ortho(orientation, surface, cfg, source_index)
    cand = ortho_candidates(plan, cfg, image_root, progress)
    grid = plan.grid
    steps[0].update(
        1.0, f"true ortho: {grid.rows} x {grid.cols} cells of {plan.res:g}, {len(cand.relevant)} images"
    )
    stats: dict = {
        "rows": grid.rows,
        "cols": grid.cols,
        "resolution": plan.res,
        "crs": plan.out_crs,
        "images_relevant": int(len(cand.relevant)),
        "bands": cand.bands,
        "dtype": cand.dtype.name,
        "visibility": cfg.visibility,
        "margin_cells": cand.setup.margin_cells,
        "reprojected": not plan.to_local.identity,
    }
    sched = schedule_tiles(plan, cand, cfg)
    stats["tile_size"] = sched.tile_size
    mosaic = run_mosaic(plan, cand, sched, cfg, output, source_index, occlusion, steps, progress, executor)
    stats.update(mosaic.stats)
    stats.update(
        {
            "tiles": len(sched.tiles),
            "cells": grid.rows * grid.cols,
            "cells_with_surface": mosaic.n_valid,
            "cells_textured": mosaic.n_seen,
            "cells_occluded": mosaic.n_occluded,
            "coverage": round(mosaic.n_seen / mosaic.n_valid, 6) if mosaic.n_valid else 0.0,
            "images_used": int(np.count_nonzero(mosaic.counts)),
            "image_reads": cand.store.reads,
            "image_window_reads": cand.store.window_reads,
            "max_triangles_per_tile": int(mosaic.max_triangles),
            "cell_image_samples": mosaic.n_samples,
            "seconds_total": round(time.perf_counter() - t_start, 3),
        }
    )
    steps[3].update(1.0, "true orthophoto written")
    as_progress(progress).update(1.0, None)
    return TrueOrthoResult(
        Path(os.fspath(output)),
        Path(source_index) if source_index else None,
        Path(occlusion) if occlusion else None,
        grid,
        mosaic.regions,
        mosaic.correction,
        stats,
    )


def plan_ortho(orientation, surface, cfg: TrueOrthoConfig, source_index=None) -> OrthoPlan:
    """Check the orientation, the surface and the CRSs; the output grid (stage 1 of :func:`true_ortho`).

    Parameters
    ----------
    orientation : Orientation or path
    surface : path or surface object (see :func:`true_ortho`)
    cfg : TrueOrthoConfig
        Validated; ``resolution``, ``extent`` and ``crs`` are used here.
    source_index : path, optional
        Only checked: an int16 index holds at most 32767 images.

    Raises
    ------
    InputError, CRSError
        No image, an orientation without CRS for a georeferenced surface, a non-metric CRS, an
        extent the surface does not cover, no transformation between the CRSs.
    """
    o = as_orientation(orientation)
    if not o.images:
        raise InputError("ORIENTATION: the orientation holds no image")
    if len(o.images) > 32767 and source_index is not None:
        raise InputError(f"SOURCE_INDEX: {len(o.images)} images do not fit an int16 index (at most 32767)")
    surf = open_surface(surface)
    o_crs = o.crs
    if o_crs is None and (surf.crs is not None or cfg.crs is not None):
        raise CRSError(
            "ORIENTATION: the orientation has no CRS; a true orthophoto of a georeferenced "
            "surface needs a georeferenced orientation"
        )
    if o_crs is not None:
        from ..geometry.frame import parse_crs, require_metric

        require_metric(parse_crs(o_crs), "ORIENTATION CRS")
    out_crs = cfg.crs or o_crs
    if out_crs is not None:
        from ..geometry.frame import parse_crs

        parse_crs(out_crs)
    to_local = PlanTransform(out_crs, o_crs, o.offset)
    s_bounds = transform_bounds(surf.bounds, surf.crs or out_crs, out_crs)
    res = float(cfg.resolution) if cfg.resolution else _default_resolution(surf, o, out_crs)
    extent = tuple(float(v) for v in (cfg.extent or s_bounds))
    grid = RasterGrid.from_extent(extent, res, out_crs)
    gx0, gy0, gx1, gy1 = grid.extent
    tol = 0.5 * res + 1e-6 * max(abs(gx0), abs(gy1), 1.0)
    if surf.crs is not None and out_crs is not None and not same_crs(surf.crs, out_crs):
        tol += 2.0 * res  # the surface's cells, reprojected, may end up to a cell inside
    if (
        gx0 < s_bounds[0] - tol
        or gy0 < s_bounds[1] - tol
        or gx1 > s_bounds[2] + tol
        or gy1 > s_bounds[3] + tol
    ):
        raise InputError(
            f"SURFACE {surf.path}: covers {tuple(round(v, 3) for v in s_bounds)} but EXTENT is "
            f"{tuple(round(v, 3) for v in grid.extent)} (in {out_crs}); give a smaller extent or a "
            "surface covering it"
        )
    # transformation path for the whole extent (raises CRSError)
    to_local.xy(
        np.array([gx0, gx1, gx0, gx1, 0.5 * (gx0 + gx1)]), np.array([gy0, gy0, gy1, gy1, 0.5 * (gy0 + gy1)])
    )
    return OrthoPlan(o, surf, out_crs, to_local, grid, res)


def ortho_candidates(
    plan: OrthoPlan, cfg: TrueOrthoConfig, image_root=None, progress=None
) -> OrthoCandidates:
    """The visibility setup and the images that can contribute (stage 2 of :func:`true_ortho`).

    Only images whose footprint box meets the extent stay candidates; they must exist on disk,
    share one band count and dtype, match their camera's size and suit the compression.

    Raises
    ------
    InputError, MissingFileError
    """
    o, surf, grid, to_local = plan.orientation, plan.surface, plan.grid, plan.to_local
    wall_min = (
        cfg.wall_min
        if cfg.wall_min is not None
        else occluder_wall_min(plan.res, math.radians(cfg.max_view_angle))
    )
    setup = prepare_views(
        o,
        surf,
        to_local,
        plan.res,
        cfg.max_view_angle,
        cfg.visibility,
        cfg.depth_tolerance,
        cfg.zbuffer_oversample,
        wall_min,
        cfg.discontinuity,
        cfg.edge_shift,
        views_per_cell=cfg.views_per_cell,
        top_views=cfg.top_views,
        noise_tolerance=cfg.noise_tolerance,
    )
    if cfg.visibility and setup.margin_cells > 0:
        setup.blocks = HeightBlocks.of(surf, grid, progress=progress)
    gx0, gy0, gx1, gy1 = grid.extent
    ex_x, ex_y = to_local.xy(np.array([gx0, gx1, gx0, gx1]), np.array([gy0, gy0, gy1, gy1]))
    b = setup.boxes
    with np.errstate(invalid="ignore"):
        relevant = np.flatnonzero(
            (b[:, 0] <= ex_x.max())
            & (b[:, 2] >= ex_x.min())
            & (b[:, 1] <= ex_y.max())
            & (b[:, 3] >= ex_y.min())
        )
    if not len(relevant):
        raise InputError("EXTENT: no image of the orientation sees the extent")
    paths = [str(o.resolve_image_path(im, image_root)) for im in o.images]
    missing = [paths[i] for i in relevant if not os.path.isfile(paths[i])]
    if missing:
        more = f" (and {len(missing) - 1} more)" if len(missing) > 1 else ""
        raise MissingFileError(missing[0], f"image referenced by the orientation is absent{more}")
    infos = {i: image_info(paths[i]) for i in relevant}
    first = infos[relevant[0]]
    for i in relevant:
        inf = infos[i]
        if inf.bands != first.bands or inf.dtype != first.dtype:
            raise InputError(
                f"{inf.path}: {inf.bands} band(s) of {inf.dtype}, but {first.path} has "
                f"{first.bands} band(s) of {first.dtype}; all images of a mosaic must match"
            )
        cam = setup.cameras[i]
        if (inf.width, inf.height) != (cam.width, cam.height):
            raise InputError(
                f"{inf.path}: image is {inf.width} x {inf.height} pixels but its camera "
                f"{cam.id!r} is {cam.width} x {cam.height}"
            )
    # only relevant images are candidates
    setup.boxes[np.setdiff1d(np.arange(len(o.images)), relevant)] = np.nan
    bands, dtype = first.bands, np.dtype(first.dtype)
    if cfg.compression == "jpeg" and (dtype != np.uint8 or bands != 3):
        raise InputError(
            f"compression: JPEG needs 8-bit RGB images, but {first.path} has {bands} band(s) of "
            f"{dtype.name}; use a lossless compression ('deflate', 'zstd' or 'lzw')"
        )
    if cfg.compression == "zstd":
        from ..rasterio_io import _has_zstd

        if not _has_zstd():
            raise InputError("compression: this GDAL cannot write ZSTD; use 'deflate' or 'lzw'")
    sizes = [(c.width, c.height) for c in setup.cameras]
    chroma = None
    if cfg.restore_chroma and dtype == np.uint8 and bands == 3:
        from ..chroma import jpeg_chroma_subsampling

        chroma = [jpeg_chroma_subsampling(p) for p in paths]
    store = ImageStore(paths, sizes, bands, dtype, cfg.image_cache_mb << 20, chroma=chroma)
    return OrthoCandidates(setup, relevant, paths, sizes, bands, dtype, store)


def schedule_tiles(plan: OrthoPlan, cand: OrthoCandidates, cfg: TrueOrthoConfig) -> OrthoSchedule:
    """Tiles within the memory budget, in waves and batches (stage 3 of :func:`true_ortho`).

    Tiles of a wave do not touch each other; a wave runs in batches of at most ~256 MiB of
    results (the client's memory stays bounded), the costliest tiles first (results do not
    depend on the order).
    """
    grid, setup, bands, dtype = plan.grid, cand.setup, cand.bands, cand.dtype
    overlap = max(cfg.blend_width, 4) + 8
    tile_size, tiles, k_tile = _bounded_tiles(setup, grid, plan.to_local, cfg.tile_size, overlap, bands)
    k_max = int(max(1, k_tile.max()))
    cost = dict(zip((t.index for t in tiles), tile_costs(setup, grid, tiles, k_tile), strict=True))
    per_tile = (tile_size**2) * ((bands + 1) * dtype.itemsize + 3) + 1
    batch_tiles = max(1, (256 << 20) // per_tile)
    ordered = [sorted(w, key=lambda t: (-cost[t.index], t.index)) for w in waves(tiles)]
    batches = [w[i : i + batch_tiles] for w in ordered for i in range(0, len(w), batch_tiles)]
    img_bytes = (
        max(w * h for w, h in (cand.sizes[i] for i in cand.relevant)) * bands * dtype.itemsize * 4 // 3
    )
    memory = task_memory(
        side_of(tile_size, overlap),
        setup.margin_cells,
        k_max,
        bands,
        min(cfg.image_cache_mb << 20, k_max * img_bytes),
    )
    return OrthoSchedule(overlap, tile_size, tiles, batches, k_max, memory)


def run_mosaic(
    plan: OrthoPlan,
    cand: OrthoCandidates,
    sched: OrthoSchedule,
    cfg: TrueOrthoConfig,
    output,
    source_index,
    occlusion,
    steps: Steps,
    progress: Progress | None,
    executor,
) -> OrthoMosaic:
    """Colour correction, the tiles on the executor, the rasters and the seamlines (stage 4).

    ``steps`` are :func:`true_ortho`'s four progress steps (the colour correction reports on the
    second, the tiles on the third, the overviews on the fourth). The rasters are written by
    windows and closed (overviews, COG copies) before this returns.
    """
    o, surf, grid, to_local = plan.orientation, plan.surface, plan.grid, plan.to_local
    setup, paths, sizes, bands, dtype, store = (
        cand.setup,
        cand.paths,
        cand.sizes,
        cand.bands,
        cand.dtype,
        cand.store,
    )
    tiles, batches = sched.tiles, sched.batches
    params = MosaicParams(
        cfg.edge_penalty,
        cfg.smoothness,
        cfg.contrast,
        cfg.discontinuity,
        cfg.blend_width,
        cfg.sweeps,
        cfg.edge_colour,
        float(cfg.consistency) if cfg.visibility else 0.0,
    )
    workers = max(1, int(cfg.workers))
    stats: dict = {}
    sub = steps[2]
    ctx = OrthoContext(
        setup,
        surf,
        grid,
        to_local,
        tuple(paths),
        tuple((int(sw), int(sh)) for sw, sh in sizes),
        bands,
        dtype.name,
        cfg.image_cache_mb << 20,
        None,  # the colour correction, set below
        params,
        workers,
        chroma=tuple(store.chroma) if store is not None else (),
        store=store,
    )
    in_process = isinstance(executor, InProcessExecutor) or (executor is None and cfg.executor == "inprocess")
    parts: dict[int, list] = {}
    counts = np.zeros(len(o.images), np.int64)
    n_seen = n_valid = n_occl = n_samples = 0
    out_path = Path(os.fspath(output))
    with contextlib.ExitStack() as stack:
        if in_process and workers > 1 and ViewPrefetch.usable(setup):
            # the visibility of the coming tiles runs ahead in a background thread: the first
            # wave's during the colour statistics, the next wave's during this one's mosaic when
            # the wave has fewer tiles than threads; one tile ahead (not with one thread: a
            # single-threaded run stays on one core)
            ctx.prefetch = ViewPrefetch(ctx, limit=1)
            stack.callback(ctx.prefetch.close)
            ctx.prefetch.submit(batches[0])
        # colour correction
        correction = None
        t0 = time.perf_counter()
        if cfg.color_correction and len(cand.relevant) > 1:
            correction = _estimate_colour(
                setup, surf, grid, to_local, store, cfg, steps[1], workers, len(o.images), _optics(o)
            )
            stats["color_correction"] = correction.as_dict([im.name for im in o.images])
        ctx.correction = correction
        stats["seconds_color"] = round(time.perf_counter() - t0, 3)
        # mosaic
        t0 = time.perf_counter()
        # scratch tiles beside the output: a rerun after a crash resumes from them
        executor, cache = stack.enter_context(
            tile_run(
                executor,
                cfg.executor,
                cfg.scheduler_address,
                scratch=f"{os.fspath(output)}.tiles",
                cache_dir=cfg.cache_dir,
                n_workers=cfg.dask_workers,
            )
        )
        stats["executor"] = getattr(executor, "name", type(executor).__name__)
        tile_executor = executor
        if isinstance(executor, InProcessExecutor) and executor.threads < workers:
            # in this process the tiles of a wave run in ``workers`` threads (they are independent)
            tile_executor = InProcessExecutor(threads=workers)

        w_out, w_idx, w_occ = open_products(
            stack,
            grid,
            out_path,
            source_index,
            occlusion,
            bands,
            dtype,
            cfg.cog,
            cfg.compression,
            cfg.jpeg_quality,
        )
        tri_max = 0
        done = DoneLabels(sched.overlap)  # border strips of the labels of finished tiles
        stats["max_candidates_per_tile"] = sched.k_max
        stats["task_memory_mb"] = round(sched.memory / 2**20, 1)
        base = _cache_base(o, paths, cand.relevant, surf, cfg, correction, grid, plan.out_crs)
        n_done = 0
        for bi, wave in enumerate(batches):
            check(progress)
            if ctx.prefetch is not None and bi + 1 < len(batches) and len(wave) < workers:
                # fewer tiles than threads in this wave: a core would idle (with enough tiles the
                # look-ahead only competed for the cores and held memory on the 4x bench scene)
                ctx.prefetch.submit(batches[bi + 1], besides=wave)
            tasks = [OrthoTask(t, done.fixed(t)) for t in wave]
            wsub = SubProgress(sub, n_done / len(tiles), (n_done + len(wave)) / len(tiles))
            try:
                results = tile_executor.map_tiles(
                    ortho_tile_task,
                    tasks,
                    wsub,
                    shared=ctx,
                    cache=cache,
                    key=lambda t: t.key(base),
                    label="true ortho",
                    memory=sched.memory,
                )
            except CancelledError:
                raise CancelledError("true orthophoto cancelled") from None
            if ctx.prefetch is not None:
                ctx.prefetch.discard(wave)  # tiles found in the tile cache were not taken
            for tile, (out_t, lab, occ, counters) in zip(wave, results, strict=True):
                n_samples += int(counters[0])
                tri_max = max(tri_max, int(counters[1]))
                w_out.write(out_t, tile.core)
                done.add(tile, lab)
                if w_idx is not None:
                    w_idx.write(lab, tile.core)
                if w_occ is not None:
                    w_occ.write(occ, tile.core)
                n_valid += int(np.count_nonzero(occ != 255))
                n_occl += int(np.count_nonzero(occ == 1))
                n_seen += int(np.count_nonzero(out_t[-1]))
                ok = lab >= 0
                counts += np.bincount(lab[ok], minlength=len(o.images))
                for k, polys in region_polygons(lab, tile.core_grid(grid).transform).items():
                    parts.setdefault(k, []).extend(polys)
            n_done += len(wave)
            sub.update(n_done / len(tiles), f"tile {n_done}/{len(tiles)}")
        check(progress)
        steps[3].update(0.0, "writing overviews")
        # the seamline polygons while the rasters get their overviews and COG copies (one after
        # the other: GDAL compresses in threads already, and two copies at once were no faster)
        dissolved: dict = {}

        def close_rasters():
            for w in (w_out, w_idx, w_occ):
                if w is not None:
                    w.close()

        each(lambda job: job(), [close_rasters, lambda: dissolved.update(dissolve(parts))], workers)
    stats["seconds_mosaic"] = round(time.perf_counter() - t0, 3)
    stats["tile_cache"] = {"hits": cache.hits, "written": cache.written}
    regions = [SeamRegion(k, o.images[k].name, int(counts[k]), g) for k, g in dissolved.items()]
    return OrthoMosaic(correction, regions, counts, n_valid, n_seen, n_occl, n_samples, tri_max, stats)


#: Config fields that do not change the mosaic (left out of the tile cache keys).
_NOT_IN_KEY = {
    "executor",
    "scheduler_address",
    "dask_workers",
    "cache_dir",
    "workers",
    "image_cache_mb",
    "cog",
    "compression",
    "jpeg_quality",
}


def open_products(
    stack: contextlib.ExitStack,
    grid: RasterGrid,
    output,
    source_index,
    occlusion,
    bands: int,
    dtype,
    cog: bool = True,
    compression: str = "deflate",
    jpeg_quality: int = 90,
):
    """The writers of the three raster products, entered on ``stack``: the ortho (``bands`` +
    alpha, average overviews, ``compression``), the source index (int16, nodata -1) and the
    occlusion mask (uint8, nodata 255), both lossless with nearest overviews; ``None`` for a
    product not asked for. Each is written to a temporary file and renamed into place when
    ``stack`` closes without error."""
    from ..rasterio_io import RasterWriter

    dtype = np.dtype(dtype)
    lossless = "deflate" if compression == "jpeg" else compression
    names = [f"band {k + 1}" for k in range(bands)] + ["alpha"]
    w_out = stack.enter_context(
        RasterWriter(
            output,
            grid,
            bands=bands + 1,
            dtype=dtype,
            nodata=None,
            descriptions=names,
            alpha=True,
            overviews=True,
            cog=cog,
            photometric="RGB" if bands == 3 else "MINISBLACK",
            compress=compression,
            quality=jpeg_quality,
        )
    )
    w_idx = w_occ = None
    if source_index is not None:
        w_idx = stack.enter_context(
            RasterWriter(
                source_index,
                grid,
                1,
                "int16",
                nodata=-1,
                overviews=True,
                overview_resampling="nearest",
                cog=cog,
                compress=lossless,
                descriptions=["source image index"],
            )
        )
    if occlusion is not None:
        w_occ = stack.enter_context(
            RasterWriter(
                occlusion,
                grid,
                1,
                "uint8",
                nodata=255,
                overviews=True,
                overview_resampling="nearest",
                cog=cog,
                compress=lossless,
                descriptions=["1 = seen by no image"],
            )
        )
    return w_out, w_idx, w_occ


#: Part of every cached tile's key: raise it when a change of the visibility, selection or mosaic
#: changes the tiles for the same inputs and parameters (2: near-field visibility, noise tolerance),
#: so that a cache kept from an interrupted run of an older version is not reused.
CACHE_VERSION = 3


def _cache_base(o, paths, relevant, surf, cfg, correction, grid, out_crs) -> str:
    """Identity of a run's inputs and parameters: every tile key starts from it."""
    import dataclasses

    files = [file_identity(paths[i]) for i in relevant]
    d = Digest("true-ortho", CACHE_VERSION, files, out_crs, list(grid.geotransform))
    d.add([grid.rows, grid.cols])
    d.add(o.to_dict())  # cameras, poses, offset, CRS (as OSGM's key)
    path = getattr(surf, "path", None)
    if path and os.path.isfile(str(path)):
        d.add(file_identity(path))
    elif hasattr(surf, "h"):
        d.add(np.asarray(surf.h))
    elif hasattr(surf, "vertices"):
        d.add([np.asarray(surf.vertices), np.asarray(surf.faces)])
    d.add({k: v for k, v in dataclasses.asdict(cfg).items() if k not in _NOT_IN_KEY})
    if correction is not None:
        d.add([np.asarray(correction.gain), np.asarray(correction.offset), bool(correction.lab)])
        if correction.vignetting is not None:
            d.add([np.asarray(correction.vignetting), np.asarray(correction.centre)])
        if correction.rgb_gain is not None:
            d.add([np.asarray(correction.rgb_gain), np.asarray(correction.rgb_offset)])
    return d.hexdigest()


def _optics(o) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per image: camera index, principal point (full-resolution pixels) and 1 / half diagonal."""
    ids = {cid: k for k, cid in enumerate(sorted(o.cameras))}
    cams = [o.cameras[im.camera] for im in o.images]
    image_camera = np.array([ids[im.camera] for im in o.images], dtype=np.int64)
    centre = np.array([[c.cx, c.cy] for c in cams], dtype=np.float64).reshape(-1, 2)
    inv_norm = np.array([2.0 / math.hypot(c.width, c.height) for c in cams], dtype=np.float64)
    return image_camera, centre, inv_norm


def _estimate_colour(
    setup,
    surf,
    grid: RasterGrid,
    to_local,
    store: ImageStore,
    cfg: TrueOrthoConfig,
    progress,
    workers: int,
    n_images: int,
    optics: tuple[np.ndarray, np.ndarray, np.ndarray],
) -> ColorCorrection:
    """Corrections from a decimated copy of the output grid (cells seen cleanly by >= 2 images):
    the vignetting per camera first (with ``cfg.vignetting``), then gains and offsets on the
    samples it corrected."""
    f = max(1, int(math.ceil(math.sqrt(grid.rows * grid.cols / max(cfg.color_cells, 1000)))))
    g = grid.scaled(f)
    # the depth margin is in cells of the grid used
    import dataclasses

    st = dataclasses.replace(
        setup, margin_cells=int(math.ceil(setup.margin_cells / f)) + 1, views_per_cell=0, top_views=0
    )
    tiles = g.tiles(cfg.tile_size, 0)
    cells, imgs, vals, uvs = [], [], [], []
    for n, tile in enumerate(tiles):
        check(progress)
        views = tile_views(st, surf, g, tile, to_local, workers)
        if len(views.cands) >= 2:
            clean = views.usable & ~views.near_edge & np.isfinite(views.heights)[None]
            multi = clean.sum(axis=0) >= 2
            need = clean & multi[None]
            col = candidate_colours(views, store, None, g.res, need, workers)
            r0, c0 = tile.outer[0], tile.outer[1]
            rr, cc = np.nonzero(multi)
            cid = (rr + r0) * g.cols + (cc + c0)
            for k in range(len(views.cands)):
                mk = need[k][rr, cc]
                if not mk.any():
                    continue
                v = col[k][rr[mk], cc[mk]]
                good = np.all(np.isfinite(v), axis=1)
                cells.append(cid[mk][good])
                imgs.append(np.full(int(good.sum()), int(views.cands[k])))
                vals.append(v[good])
                uvs.append(np.asarray(views.uv[k][rr[mk], cc[mk]], np.float64)[good])
        progress.update((n + 1) / len(tiles), f"colour statistics {n + 1}/{len(tiles)}")
    if not cells:
        return ColorCorrection.identity(n_images, store.bands)
    cell, img, raw = np.concatenate(cells), np.concatenate(imgs), np.concatenate(vals)
    vig = None
    image_camera, centre, inv_norm = optics
    if cfg.vignetting:
        d = (np.concatenate(uvs) - centre[img]) * inv_norm[img][:, None]
        rho2 = (d**2).sum(axis=1)
        vig, vstats = estimate_vignetting(cell, img, linear_luminance(raw, store.dtype), rho2, image_camera)
        if np.any(vig != 0.0):
            factor = np.exp(vig[img, 0] * rho2 + vig[img, 1] * rho2**2)
            raw = devignette_values(raw, factor, store.dtype)
        else:
            vig = None
    corr = estimate_colour_model(cell, img, raw, n_images, store.dtype)
    corr.stats["grid_factor"] = f
    if cfg.vignetting:
        corr.stats["vignetting"] = vstats
    if vig is not None:
        corr.vignetting, corr.centre, corr.inv_norm = vig, centre, inv_norm
    return corr


def check_output_paths(*paths) -> None:
    """Raise InputError when two outputs share a path."""
    seen = set()
    for p in paths:
        if p is None:
            continue
        k = os.path.abspath(os.fspath(p))
        if k in seen:
            raise InputError(f"output {p!r} is given twice")
        seen.add(k)


__all__ = ["SeamRegion", "TrueOrthoConfig", "TrueOrthoResult", "check_output_paths", "true_ortho"]
