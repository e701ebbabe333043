"""OSGM from an orientation to a DSM, confidence, orthoimage and point cloud.

:func:`run_osgm` discretises object space (cells ``dX = dY`` = the
resolution, default the median GSD of the near-nadir images; ``dZ`` default
= the resolution), finds the Z range (parameters, a coarse surface raster,
the sparse tie points and GCPs, or from the block geometry), and matches
coarse to fine (:mod:`.levels`): the coarsest level searches the whole
range, every finer level a band around the result of the coarser one, so the
work per cell stays small whatever the Z range. Every level runs by XY tiles
with overlap (:func:`~.matching.match_tile`), so memory is bounded by the
tile size and the band width, whatever the extent.

Oblique blocks (``oblique="auto"``): besides the nadir system, the oblique
images are grouped by viewing direction; each group defines a reference
system whose Z axis points back along its mean viewing direction. All
orientations are rotated into it, OSGM runs there unchanged (a 2.5D surface
*as seen from that direction*: facades become its "roofs"), and its points
are rotated back into the world frame and merged with the nadir ones into
one point cloud (extra dimension ``system``).

Outputs are written atomically (temporary file, renamed on success); a
cancelled run writes nothing.
"""

from __future__ import annotations

import dataclasses
import math
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import ClassVar

import numpy as np

from ..errors import CancelledError, InputError
from ..geometry.frame import parse_crs, require_metric
from ..grid import RasterGrid
from ..optics import MAX_SPREAD, MIN_RESTORE, check_prefilter
from ..orientation import Orientation, as_orientation
from ..parallel import (
    EXECUTORS,
    Digest,
    Executor,
    InProcessExecutor,
    TileCache,
    file_identity,
    parse_memory,
    tile_run,
)
from ..progress import Progress, as_progress
from ..quickselect import nanmedian_axis0
from ..sgm import DEFAULT_P1, DEFAULT_P2, P2_MAX
from .levels import MAX_BAND, LevelPlan, coarse_windows, plan_levels, refine_bands, refine_windows
from .matching import TileParams, choose_images, sample_surface
from .systems import reference_systems, system_views
from .tiles import TileContext, TileTask, assemble_tiles, osgm_tile_task, task_memory
from .views import ImagePyramid, check_images, photo_spreads
from .zrange import check_overlap, default_extent, default_resolution, known_heights, surface_range, z_range

DSM_NODATA = -9999.0

#: Part of every cached tile's key: raise it when a change of the matching or of the edge
#: refinement changes the tiles for the same inputs and parameters (2: the edge refinement's
#: visibility march and better-half cost; 3: wall heights decided like holes; 4: only where a side
#: is more photo-consistent than the height itself; 5: the slope trend continued down to a roof's
#: eaves; 6: the image choice tests frames at the bottom and top of a tile's range too; 7: a second
#: aggregation with the tile's own trend; 8: that trend from an aggregation with half P1; 9: heights
#: fewer than two views see cost the median, not COST_MAX; 10: their lower quartile; 11: the trend
#: followed at sub-level precision; 12: its offsets faded out next to level ground; 13: the sharp
#: photos low-passed before matching, the edge refinement on them as decoded), so that a cache kept
#: from an interrupted run of an older version is not reused.
CACHE_VERSION = 13
#: Default of :attr:`OsgmConfig.prefilter` (Gaussian sigma, px; ``docs/acceptance.md``, session 28).
DEFAULT_PREFILTER = 0.6


@dataclass
class OsgmConfig:
    """Parameters of :func:`run_osgm` (None = derived from the block, see the attributes).

    Attributes
    ----------
    resolution : float, optional
        Cell size ``dX = dY`` (CRS units); default the median GSD of the
        near-nadir images at the median ground height.
    z_step : float, optional
        Voxel height ``dZ``; default the resolution.
    z_min, z_max : float, optional
        Search range (world heights); default from sparse points and GCPs
        (0.5 / 99.5 percentiles, widened by a margin), else from the block.
    z_margin : float, optional
        Margin around the sparse range, default ``max(10 Z_STEP, 10 % of the range, 2 m)``,
        and around a coarse surface raster, default ``max(5 Z_STEP, 2 m)`` (``Z_STEP`` counts
        only when given).
    p1, p2 : int, optional
        SGM penalties in cost units (``COST_MAX`` = 1023 = unrelated windows);
        default :data:`~truortho.core.sgm.DEFAULT_P1`, ``DEFAULT_P2``.
    paths : {8, 16}
        Aggregation directions of SGM in XY. 16 by default: with 8 (the axes and diagonals) the
        hillshade of natural terrain shows a fine cross-hatch along them (grid streak index of
        the bundled sample 1.71 against 1.03, copr at 0.05 m 1.65 against 1.53), for the same
        accuracy on the acceptance battery (NMAD median 0.21 -> 0.19 GSD, edge cells within
        3 GSD 0.863 -> 0.869) and about 6 % more OSGM time.
    adaptive_p2 : bool
        Lower P2 across edges of the coarser level's orthoimage.
    max_images : int
        Images matched per tile (best coverage, then most nadir).
    max_view_angle : float
        Largest angle (degrees) between the ray to a tile and the system's Z axis.
    rim_view_angle : float
        Views steeper than ``max_view_angle`` up to this angle are taken only for the tiles
        where the others leave a part with fewer than two views (the rim of a block, which
        only obliques see twice); 0 = never.
    oblique : {"none", "auto"}
        ``"auto"``: additional reference systems for groups of oblique images. Their points
        go to the point cloud only (the DSM is the nadir system's), so :func:`run_osgm`
        skips them, and says so, when ``outputs.point_cloud`` is None.
    oblique_group_angle : float
        Largest angle between the viewing directions of the images of one
        oblique system (degrees).
    tile_size : int
        Core tile side in cells (the overlap is added).
    radius : int
        Matching window radius in cells.
    measure : {"gradient", "ncc", "census"}
    uniqueness : float
    median : int
        Median filter size (odd; 1 = off).
    refine_edges : bool
        Re-decide the side of every cell near a height step on the finest
        level with occlusion-aware 3 x 3 photo-consistency (:mod:`.edges`):
        against the fattening of window matching at building outlines.
    occlusion_pairs : bool
        On the refined levels above the finest, a cell near a height step of the coarser level
        takes the best pairs of views as if the views that the coarser surface hides from the foot
        of the step were not there (:func:`~.matching.hidden_views`): its ground is then judged on
        the pairs that see it, not outvoted by a roof's height over a uniform field. Gradient
        measure only.
    slope_max : int
        Below the coarsest level, SGM follows the coarser level's slopes up to this many Z levels
        per cell (:func:`~.matching.slope_trend`): slanted roofs are not flattened by P1; 0 = off.
        Independent of ``adaptive_p2``: the coarser surface reaches the tiles when either needs it.
    sub_level_trend : bool
        With ``slope_max``, a tile's last aggregation follows its first pass's slopes, and the
        gentle slopes that the trend leaves alone, at sub-level precision
        (:func:`~.matching.aggregate_with_trend`): no terraces along the contours. False: whole
        levels, as before session 27.
    point_spread : float, optional
        The photos' Gaussian point spread (px) beyond a sharp photo's, undone in the matching band
        before matching (:func:`~truortho.core.optics.restore`: where the detail stands above the
        noise and the photo's typical detail). None: measured per camera on the photos' straight
        edges (:func:`photo_spreads`); 0: the photos are matched as they are.
    prefilter : float
        Gaussian sigma (px) by which the matching band of the photos that are not restored is
        low-passed at full resolution before matching (:func:`~truortho.core.optics.prefilter`):
        it takes the detail that a bilinear sampler passes differently at every sub-pixel phase
        (aliasing, JPEG quantisation, noise) out of the cost. The edge refinement compares the
        photos as decoded. 0: matched as decoded.
    band : int, optional
        0-based band to match on; default the luminance.
    max_levels : int
        Upper bound of the pyramid depth.
    chunk_memory : int
        Bytes the whole-grid arrays of one coarse-to-fine run may take: a larger block is
        matched chunk after chunk (:func:`plan_chunks`), so the memory does not grow with the
        block. 0: one run whatever the size.
    cache_bytes : int
        Budget of decoded images kept in memory (per process: in this one, or per Dask worker).
    executor : {"inprocess", "local", "scheduler"}
        Where the tiles run (:mod:`truortho.core.parallel`): in this process
        (numba threads), on a local Dask cluster of worker processes on
        127.0.0.1, or on the Dask scheduler ``scheduler_address``. The results
        are identical.
    scheduler_address : str, optional
        ``tcp://127.0.0.1:8786``, ``tls://host:port`` or a scheduler file;
        default ``$TRUORTHO_DASK_SCHEDULER``.
    workers : int, optional
        Worker processes of the local cluster (default the cores).
    worker_memory : int or str, optional
        Memory limit per local worker (``"4GiB"``); default 80 % of the machine / workers.
    cache_dir : path, optional
        Keep finished tiles there (content-addressed, see
        :class:`~truortho.core.parallel.TileCache`) and reuse them on a rerun.
        Default ``<DSM>.tiles/`` beside the DSM, removed when the run
        succeeds or is cancelled and kept after a crash, so that a rerun with
        the same inputs and parameters resumes.
    """

    resolution: float | None = None
    z_step: float | None = None
    z_min: float | None = None
    z_max: float | None = None
    z_margin: float | None = None
    p1: int | None = None
    p2: int | None = None
    paths: int = 16
    adaptive_p2: bool = True
    max_images: int = 12
    max_view_angle: float = 50.0
    rim_view_angle: float = 65.0
    oblique: str = "none"
    oblique_group_angle: float = 35.0
    tile_size: int = 256
    radius: int = 2
    measure: str = "gradient"
    uniqueness: float = 0.99
    median: int = 3
    refine_edges: bool = True
    occlusion_pairs: bool = True
    slope_max: int = 2
    sub_level_trend: bool = True
    point_spread: float | None = None
    prefilter: float = DEFAULT_PREFILTER
    band: int | None = None
    max_levels: int = 5
    chunk_memory: int = 1 << 30
    cache_bytes: int = 1 << 30
    executor: str = "inprocess"
    scheduler_address: str | None = None
    workers: int | None = None
    worker_memory: int | str | None = None
    cache_dir: str | os.PathLike | None = None

    #: fields that only say where and how the work runs, never what it computes (not in tile keys)
    RUN_ONLY: ClassVar[tuple[str, ...]] = (
        "executor",
        "scheduler_address",
        "workers",
        "worker_memory",
        "cache_dir",
        "cache_bytes",
    )

    def result_fields(self) -> dict:
        """The fields that decide the result (part of every tile's cache key)."""
        return {k: v for k, v in dataclasses.asdict(self).items() if k not in self.RUN_ONLY}

    def validate(self) -> None:
        for name in ("resolution", "z_step", "z_margin"):
            v = getattr(self, name)
            if v is not None and not (math.isfinite(float(v)) and float(v) > 0):
                raise InputError(f"{name.upper()}: expected a positive number, got {v!r}")
        if self.z_min is not None and self.z_max is not None and not float(self.z_min) < float(self.z_max):
            raise InputError(f"Z_MIN ({self.z_min}) must be below Z_MAX ({self.z_max})")
        sm = self.slope_max
        if isinstance(sm, bool) or not isinstance(sm, int) or not 0 <= sm <= 16:
            raise InputError(f"slope_max: expected an integer number of Z levels per cell in [0, 16], "
                             f"got {self.slope_max!r}")  # fmt: skip
        ps = self.point_spread
        if ps is not None and (
            isinstance(ps, bool)
            or not isinstance(ps, int | float)
            or not (math.isfinite(ps) and 0 <= ps <= MAX_SPREAD)
        ):
            raise InputError(f"point_spread: expected None (measured) or px in [0, {MAX_SPREAD}], got {ps!r}")
        check_prefilter(self.prefilter, "prefilter")
        p1 = DEFAULT_P1 if self.p1 is None else int(self.p1)
        p2 = DEFAULT_P2 if self.p2 is None else int(self.p2)
        if not (0 <= p1 < p2 <= P2_MAX):
            raise InputError(f"P1, P2: expected 0 <= P1 < P2 <= {P2_MAX}, got P1={p1}, P2={p2}")
        if self.paths not in (8, 16):
            raise InputError(f"PATHS: expected 8 or 16, got {self.paths!r}")
        if int(self.max_images) < 2:
            raise InputError(f"MAX_IMAGES: at least 2 images are needed per tile, got {self.max_images!r}")
        if self.oblique not in ("none", "auto"):
            raise InputError(f"OBLIQUE: expected 'none' or 'auto', got {self.oblique!r}")
        if int(self.tile_size) < 32:
            raise InputError(f"TILE_SIZE: expected at least 32 cells, got {self.tile_size!r}")
        if self.median < 1 or self.median % 2 == 0:
            raise InputError(f"median: expected an odd size >= 1, got {self.median!r}")
        if not 0 < float(self.max_view_angle) < 90:
            raise InputError(f"max_view_angle: expected degrees in (0, 90), got {self.max_view_angle!r}")
        rim = float(self.rim_view_angle)
        if rim != 0 and not float(self.max_view_angle) <= rim < 90:
            raise InputError(
                f"rim_view_angle: expected 0 (off) or degrees in [max_view_angle {self.max_view_angle}, 90), "
                f"got {self.rim_view_angle!r}"
            )
        if self.executor not in EXECUTORS:
            raise InputError(f"EXECUTOR: expected one of {', '.join(EXECUTORS)}, got {self.executor!r}")
        if self.workers is not None and int(self.workers) < 1:
            raise InputError(f"workers: expected at least 1, got {self.workers!r}")
        parse_memory(self.worker_memory)
        if (
            isinstance(self.chunk_memory, bool)
            or not isinstance(self.chunk_memory, int)
            or self.chunk_memory < 0
        ):
            raise InputError(f"chunk_memory: expected a number of bytes >= 0, got {self.chunk_memory!r}")

    def tile_params(self) -> TileParams:
        return TileParams(
            radius=int(self.radius),
            measure=self.measure,
            p1=DEFAULT_P1 if self.p1 is None else int(self.p1),
            p2=DEFAULT_P2 if self.p2 is None else int(self.p2),
            paths=int(self.paths),
            uniqueness=float(self.uniqueness),
            max_images=int(self.max_images),
            max_view_angle=float(self.max_view_angle),
            median=int(self.median),
            rim_view_angle=float(self.rim_view_angle),
            edges=bool(self.refine_edges),
            slope_max=int(self.slope_max),
            adaptive_p2=bool(self.adaptive_p2),
            occlusion_pairs=bool(self.occlusion_pairs),
            sub_level=bool(self.sub_level_trend),
        )


@dataclass
class OsgmOutputs:
    """Destinations; ``dsm`` is required, the others optional."""

    dsm: str | os.PathLike
    confidence: str | os.PathLike | None = None
    orthoimage: str | os.PathLike | None = None
    point_cloud: str | os.PathLike | None = None

    def validate(self) -> None:
        if self.dsm is None:
            raise InputError("DSM: an output path is required")
        paths = [("DSM", self.dsm), ("CONFIDENCE", self.confidence), ("ORTHOIMAGE", self.orthoimage)]
        for name, p in paths:
            if p is not None and Path(p).suffix.lower() not in (".tif", ".tiff"):
                raise InputError(f"{name}: expected a GeoTIFF path (.tif), got {p}")
        if self.point_cloud is not None and Path(self.point_cloud).suffix.lower() not in (".las", ".laz"):
            raise InputError(f"POINT_CLOUD: expected a .las or .laz path, got {self.point_cloud}")
        given = [str(Path(p).resolve()) for _, p in paths if p is not None]
        if self.point_cloud is not None:
            given.append(str(Path(self.point_cloud).resolve()))
        if len(set(given)) != len(given):
            raise InputError("outputs: two outputs have the same path")

    @property
    def wants_colours(self) -> bool:
        """Whether the nadir cells need colours: only the orthoimage and the point cloud use them."""
        return self.orthoimage is not None or self.point_cloud is not None


@dataclass
class OsgmResult:
    grid: RasterGrid
    stats: dict = field(default_factory=dict)
    paths: dict = field(default_factory=dict)

    def summary(self) -> str:
        s = self.stats
        text = (
            f"OSGM DSM {s['cols']} x {s['rows']} cells at {s['resolution']:.3f} m, dZ {s['z_step']:.3f} m, "
            f"Z {s['z_min']:.2f} .. {s['z_max']:.2f} ({s['z_source']}), {s['levels']} pyramid level(s), "
            f"{s['tiles']} tiles; completeness {100 * s['completeness']:.2f} %, "
            f"mean confidence {s['mean_confidence']:.3f}; {s['seconds']:.1f} s"
        )
        oblique = 0
        for sysd in s.get("systems", [])[1:]:
            text += f"; system {sysd['id']} ({sysd['name']}): {sysd['points']} points"
            oblique += int(sysd["points"])
        for cam, d in s.get("point_spread", {}).items():
            if d["restored"] > 0:
                measured = "" if d["measured"] is None else f"measured {d['measured']:.2f} px, "
                text += (f"; photos of {cam}: point spread {measured}{d['restored']:.2f} px undone at full "
                         f"resolution (halved per pyramid level, none under {MIN_RESTORE} px)")  # fmt: skip
        pf = s.get("prefilter", {})
        if pf.get("images"):
            text += f"; {pf['images']} sharp photo(s) low-passed by {pf['sigma']:.2f} px before matching"
        if s["completeness"] <= 0.0:
            # an empty DSM reads like a failure; say why and where the result is
            if oblique:
                text += (". The DSM is empty: no pair of photos matched the ground from above (photos "
                         "taken sideways, as of a facade); the oblique systems' points are the result "
                         "(POINT_CLOUD)")  # fmt: skip
            else:
                text += (". Nothing matched: check that Z_MIN/Z_MAX enclose the surface and that the "
                         "extent is seen by at least two photos; photos taken sideways (a facade) "
                         "need OBLIQUE=auto and a POINT_CLOUD output")  # fmt: skip
        return text


# ------------------------------------------------------------------ one system


@dataclass
class SystemResult:
    grid: RasterGrid  # in the system frame (local, rotated); crs of the orientation for nadir
    z: np.ndarray
    confidence: np.ndarray
    rgb: np.ndarray | None
    plan: LevelPlan
    tiles: int
    max_volume: int = 0  # largest rows x cols x nd of a task (cost volume cells)


#: Cells on each side of a tile seam over which neighbouring tiles' heights are blended
#: (:func:`~.tiles.assemble_tiles`; at most the tiles' margin).
SEAM_BLEND = 16
#: Largest spread of the tiles' heights at a seam cell, in Z steps of the level, that is blended.
SEAM_TOLERANCE = 2.0
#: Overlap (cells) of the finest level's tiles. The coarser levels' tiles overlap by
#: ``max(16, tile_size / 8)`` cells, the run-up SGM's paths need where a cell may search the whole
#: height range. On the finest level every cell searches a narrow band around level 1's result, so
#: the paths need less: 16 instead of 32 cells (tile size 256) made OSGM 12 % faster on the
#: acceptance battery (``bench/osgm_battery.py``, scenes 1-11, 122 -> 108 s) with the mean
#: figures unchanged or better (NMAD 0.247 -> 0.243 GSD, edge3 0.855 -> 0.856; per scene edge3
#: -0.9 to +1.8 points), and 31 %
#: faster on boruszyn (28 real photos at 0.25 m, 176 -> 121 s) with the same holes (45,600 cells
#: against 45,500). About 30 % of the finest level's work had been the tiles' overlap.
FINE_OVERLAP = 16


def level_overlap(tile_size: int, lv: int) -> int:
    """Cells of overlap of the tiles of pyramid level ``lv`` (0: the finest) for ``tile_size``."""
    if int(tile_size) < 1 or int(lv) < 0:
        raise InputError(f"level_overlap: expected tile_size >= 1 and lv >= 0, got {tile_size!r}, {lv!r}")
    coarse = max(16, int(tile_size) // 8)
    return coarse if lv > 0 else min(coarse, FINE_OVERLAP)


class _LevelTasks(Sequence):
    """The tile tasks of one level, built when the executor asks for them (bounded memory)."""

    def __init__(
        self, tiles, g: RasterGrid, lv: int, plan: LevelPlan, params, cfg, prev_z, prev_filled, zsw,
        blend: int,
    ):  # fmt: skip
        self.tiles, self.g, self.lv, self.plan = tiles, g, lv, plan
        self.params = plan.level_params(params, lv)
        self.cfg, self.prev_z, self.prev_filled, self.zsw = cfg, prev_z, prev_filled, zsw
        self.max_cells_levels = 0
        self.blend = blend  # cells beyond the core each task returns for the seams (assemble_tiles)

    def __len__(self) -> int:
        return len(self.tiles)

    def __getitem__(self, i):  # type: ignore[override]
        tile = self.tiles[i]
        plan, lv, g = self.plan, self.lv, self.g
        r0, c0, nr, nc = tile.outer
        if self.prev_z is None:
            lo, hi = coarse_windows(
                plan,
                lv,
                (nr, nc),
                None if self.zsw is None else tuple(w[r0 : r0 + nr, c0 : c0 + nc] for w in self.zsw),
            )
            guide = None
            glo = ghi = None
        else:
            if plan.gaps(lv):
                lo, hi, glo, ghi = refine_bands(plan, lv, self.prev_z, (r0, c0, nr, nc))
            else:
                lo, hi = refine_windows(plan, lv, self.prev_z, (r0, c0, nr, nc))
                glo = ghi = None
            assert self.prev_filled is not None
            # the coarser surface, for the adaptive P2's guide, the slope trend and the hidden views
            wanted = self.cfg.adaptive_p2 or self.cfg.slope_max > 0 or self.cfg.occlusion_pairs
            guide = _interpolate(self.prev_filled, (r0, c0, nr, nc)) if wanted else None
        search = lo <= hi
        nd = int(max(3, (hi - lo + 1)[search].max())) if search.any() else 0
        self.max_cells_levels = max(self.max_cells_levels, nr * nc * nd)
        return TileTask(
            lv,
            tuple(tile.outer),
            tuple(tile.core),
            g.x_min + c0 * g.res,
            g.y_max - r0 * g.res,
            g.res,
            lo,
            hi,
            plan.z_base,
            plan.dz(lv),
            self.params,
            guide,
            glo,
            ghi,
            self.blend,
        )


def _match_system(
    o,
    system,
    pyr,
    grid,
    plan: LevelPlan,
    cfg: OsgmConfig,
    progress,
    z_surface_windows=None,
    want_colour=False,
    executor: Executor | None = None,
    cache: TileCache | None = None,
    cache_base: str = "",
) -> SystemResult:
    """Coarse-to-fine OSGM of one reference system over ``grid`` (system frame, local).

    Every level is one ``executor.map_tiles`` call over its tiles (independent
    given the coarser level's result); finished tiles go to ``cache`` when given.
    """
    from ..progress import SubProgress

    executor = executor or InProcessExecutor()
    params = cfg.tile_params()
    views = system_views(o, system)
    ctx = TileContext(
        tuple(pyr.paths), tuple(pyr.sizes), pyr.band, pyr.max_bytes, views, pyr.spread, pyr.window_px,
        pyr.prefilter, pyramid=pyr,
    )  # fmt: skip
    base = ""
    if cache is not None:
        base = Digest(cache_base, ctx.digest().hexdigest(), np.asarray(system.Q, np.float64)).hexdigest()
    prev_z: np.ndarray | None = None
    prev_filled: np.ndarray | None = None
    n_tiles = 0
    total = sum(plan.grid(grid, lv).rows * plan.grid(grid, lv).cols for lv in plan.levels)
    done_cells = 0
    max_volume = 0
    for lv in plan.levels:  # coarse to fine
        if progress.cancelled():
            raise CancelledError("OSGM cancelled")
        g = plan.grid(grid, lv)
        ts = int(cfg.tile_size)
        ov = level_overlap(ts, lv)
        side = ts + 2 * ov  # outer tile side, for the memory a task asks of the scheduler
        tiles = g.tiles(ts, ov)
        tasks = _LevelTasks(
            tiles, g, lv, plan, params, cfg, prev_z, prev_filled, z_surface_windows, min(SEAM_BLEND, ov)
        )
        sub = SubProgress(progress, done_cells / total, (done_cells + g.rows * g.cols) / total)
        try:
            results = executor.map_tiles(
                osgm_tile_task,
                tasks,
                sub,
                shared=ctx,
                cache=cache,
                key=(lambda t: t.key(base)) if cache is not None else None,
                label=f"{system.name}: level {lv}",
                memory=task_memory(side, side, MAX_BAND, params.max_images, 4 * side * side, params.radius),
            )
        except CancelledError:
            raise CancelledError("OSGM cancelled") from None
        z, conf = assemble_tiles(g.shape, tiles, results, tasks.blend, SEAM_TOLERANCE * plan.dz(lv))
        n_tiles += len(tiles)
        done_cells += g.rows * g.cols
        max_volume = max(max_volume, tasks.max_cells_levels)
        prev_z = z
        prev_filled = _fill_nearest(z)
    assert prev_z is not None
    rgb = _colours(views, pyr, grid, prev_z, cfg, progress) if want_colour else None
    return SystemResult(grid, prev_z, conf, rgb, plan, n_tiles, max_volume)


def _fill_nearest(z: np.ndarray) -> np.ndarray:
    """NaN cells take the value of the nearest valid cell (all NaN stays NaN)."""
    from scipy.ndimage import distance_transform_edt

    bad = ~np.isfinite(z)
    if not bad.any() or bad.all():
        return z
    idx = distance_transform_edt(bad, return_distances=False, return_indices=True)
    return z[tuple(idx)]


def _interpolate(coarse: np.ndarray, window) -> np.ndarray:
    """Bilinear values of the coarser level at the cell centres ``window`` of the finer one."""
    from scipy.ndimage import map_coordinates

    r0, c0, nr, nc = window
    rr = (np.arange(r0, r0 + nr) + 0.5) / 2 - 0.5
    cc = (np.arange(c0, c0 + nc) + 0.5) / 2 - 0.5
    R, C = np.meshgrid(rr, cc, indexing="ij")
    return map_coordinates(coarse, [R, C], order=1, mode="nearest").astype(np.float32)


def _colours(views, pyr, grid: RasterGrid, z: np.ndarray, cfg: OsgmConfig, progress: Progress) -> np.ndarray:
    """Colour of the best visible image per cell (uint8 RGB, 0 where none).

    Per tile, every image that sees it is sampled at the matched surface; an
    image counts as seeing a cell when its luminance is within 0.1 of the median
    of all views there (an occluded view sees something else), and among those
    the one whose ray from the cell is closest to the system's Z axis gives the
    colour (decided per cell, so the choice does not jump at tile borders).
    """
    params = cfg.tile_params()
    params.max_images = len(views)  # every image that sees the tile, on both sides of a tile border
    out = np.zeros(grid.shape + (3,), np.uint8)
    for tile in grid.tiles(int(cfg.tile_size), 0):
        if progress.cancelled():
            raise CancelledError("OSGM cancelled")
        r0, c0, nr, nc = tile.outer
        zt = z[r0 : r0 + nr, c0 : c0 + nc]
        ok = np.isfinite(zt)
        if not ok.any():
            continue
        tx0, ty0 = grid.x_min + c0 * grid.res, grid.y_max - r0 * grid.res
        lo, hi = float(np.nanmin(zt)), float(np.nanmax(zt))
        imgs = choose_images(views, pyr, tx0, ty0, grid.res, nr, nc, lo, hi, params, colour=True)
        if not imgs:
            continue
        col = sample_surface(imgs, tx0, ty0, grid.res, zt)  # (n, rows, cols, 3)
        scale = np.array([pyr.value_max(im.view.index) for im in imgs])
        lum = (col[..., 0] * 0.299 + col[..., 1] * 0.587 + col[..., 2] * 0.114) / scale[:, None, None]
        med = nanmedian_axis0(lum)
        agree = np.abs(lum - med[None]) <= 0.1
        X = tx0 + (np.arange(nc) + 0.5) * grid.res
        Y = ty0 - (np.arange(nr) + 0.5) * grid.res
        cos_ray = np.stack([_cos_to_axis(im.view.C, X, Y, zt) for im in imgs])
        score = np.where(agree, -cos_ray, np.inf)
        best = np.argmin(score, axis=0)
        has = np.isfinite(np.take_along_axis(score, best[None], 0)[0]) & ok
        c = np.take_along_axis(col, best[None, :, :, None], 0)[0] / scale[best][..., None] * 255.0
        tile_rgb = np.where(has[..., None], np.clip(np.nan_to_num(c) + 0.5, 1, 255), 0).astype(np.uint8)
        out[r0 : r0 + nr, c0 : c0 + nc] = tile_rgb
    return out


def _cos_to_axis(C, X, Y, z) -> np.ndarray:
    """Cosine between the ray from every cell (X[col], Y[row], z) to ``C`` and the system's Z axis."""
    dx = C[0] - X[None, :]
    dy = C[1] - Y[:, None]
    dz = C[2] - z
    return dz / np.sqrt(dx * dx + dy * dy + dz * dz)


# ------------------------------------------------------------------ the entry point


def run_osgm(
    orientation,
    config: OsgmConfig | None = None,
    extent=None,
    outputs: OsgmOutputs | None = None,
    image_root=None,
    z_surface=None,
    progress: Progress | None = None,
    executor: Executor | None = None,
) -> OsgmResult:
    """Object-space semi-global multi-image matching of an oriented block.

    Parameters
    ----------
    orientation : Orientation or path of an orientation JSON
    config : OsgmConfig
    extent : (xmin, ymin, xmax, ymax), optional
        World coordinates in the orientation's CRS; default the area seen by at
        least two near-nadir images, and the sparse points (:func:`default_extent`).
    outputs : OsgmOutputs
        DSM (float32 GeoTIFF, nodata -9999), CONFIDENCE (float32 in [0, 1]),
        ORTHOIMAGE (uint8 RGB, 0 = no data), POINT_CLOUD (LAS/LAZ with RGB,
        confidence and reference system).
    image_root : path, optional
        Folder the image paths are relative to (default the orientation's).
    z_surface : path, optional
        A coarse DSM/DTM raster: per-cell search bounds ``[min - margin, max + margin]``
        of its 3 x 3 neighbourhood on the coarsest level.
    progress : Progress, optional
    executor : Executor, optional
        Runs the tiles (:mod:`truortho.core.parallel`); default one made from
        ``config.executor`` (in-process unless told otherwise) and closed at the end.

    Returns
    -------
    OsgmResult
    """
    t0 = time.perf_counter()
    progress = as_progress(progress)
    cfg = config or OsgmConfig()
    cfg.validate()
    if outputs is None:
        raise InputError("DSM: an output path is required")
    outputs.validate()
    if cfg.oblique != "none" and outputs.point_cloud is None:
        # the oblique systems' only product is the point cloud (the DSM is the nadir system's, the same
        # with or without them): without POINT_CLOUD their matching would be lost work
        cfg = replace(cfg, oblique="none")
        progress.update(0.0, "OBLIQUE=auto without a POINT_CLOUD output: the oblique reference systems "
                             "are skipped (their points go only to the point cloud)")  # fmt: skip
    o = as_orientation(orientation)
    o.validate()
    if o.crs is None:
        raise InputError("ORIENTATION: the orientation has no CRS; georeference it first")
    require_metric(parse_crs(o.crs), "orientation CRS")
    if len(o.images) < 2:
        raise InputError("ORIENTATION: at least two oriented images are needed")
    paths = [str(o.resolve_image_path(im, image_root)) for im in o.images]
    sizes = [(o.camera_of(im).width, o.camera_of(im).height) for im in o.images]
    o.check_images_exist(image_root)
    check_images(paths, sizes)

    if z_surface is not None and (cfg.z_min is None or cfg.z_max is None):
        zmin, zmax, zsrc = surface_range(z_surface, o, cfg, extent)
    else:
        zmin, zmax, zsrc = z_range(o, cfg)
    zs_mid = 0.5 * (zmin + zmax)
    known = known_heights(o)
    ground = float(np.median(known)) if len(known) else zmin
    res = float(cfg.resolution) if cfg.resolution else default_resolution(o, ground)
    dz = float(cfg.z_step) if cfg.z_step else res
    if extent is None:
        extent = default_extent(o, ground, cfg.max_view_angle)
    grid = RasterGrid.from_extent(extent, res, o.crs)
    check_overlap(o, grid, ground)
    off = o.offset
    local = RasterGrid(grid.x_min - off[0], grid.y_max - off[1], res, grid.rows, grid.cols, o.crs)
    if cfg.point_spread is None:
        cams = [im.camera for im in o.images]
        spread, spread_report = photo_spreads(paths, sizes, cams, cfg.band, progress)
    else:
        spread = [float(cfg.point_spread)] * len(paths)
        spread_report = {"given": {"measured": None, "photos": 0, "restored": float(cfg.point_spread)}}
    pyr = ImagePyramid(
        paths, sizes, cfg.band, cfg.cache_bytes, spread, 2 * int(cfg.radius) + 1, float(cfg.prefilter)
    )
    pyr.spread_report = spread_report
    # everything a tile's result depends on besides its own inputs: block, parameters, grid, Z surface
    cache_base = Digest(
        "osgm-run",
        CACHE_VERSION,
        o.to_dict(),
        cfg.result_fields(),
        [local.x_min, local.y_max, local.res, local.rows, local.cols],
        None if z_surface is None else list(file_identity(z_surface)),
    ).hexdigest()
    with tile_run(
        executor,
        cfg.executor,
        cfg.scheduler_address,
        scratch=f"{outputs.dsm}.tiles",
        cache_dir=cfg.cache_dir,
        n_workers=cfg.workers,
        memory_limit=parse_memory(cfg.worker_memory),
    ) as (executor, cache):
        return _run_systems(
            o, cfg, outputs, grid, local, pyr, executor, cache, cache_base, zmin, zmax, zsrc, zs_mid, dz, res,
            z_surface, progress, t0,
        )  # fmt: skip


@dataclass
class _Surface:
    """What the reference systems matched over one grid (world heights; before any writing)."""

    dsm: np.ndarray  # (rows, cols) float32 world heights, NaN where rejected
    conf: np.ndarray  # (rows, cols) float32 in [0, 1], NaN where rejected
    rgb: np.ndarray | None  # (rows, cols, 3) uint8, 0 = no colour
    clouds: list  # (world xyz, rgb, confidence) of every oblique system
    systems: list
    levels: int
    tiles: int
    max_volume: int


def _match_surface(
    o, cfg, grid, local, pyr, executor, cache, cache_base, zmin, zmax, dz, z_surface, progress, want_rgb,
    want_colour=True,
) -> _Surface:
    """Every reference system over ``grid`` (world) / ``local`` (the same cells in the local frame).

    ``want_rgb``: the oblique systems' points get colours; ``want_colour``: the nadir DSM's cells get
    theirs (:func:`_colours`; for the orthoimage and the point cloud only, about 5-8 % of OSGM's time
    on battery scene 808/1 and not needed for the DSM alone)."""
    off = o.offset
    systems = reference_systems(o, cfg.oblique, cfg.oblique_group_angle)
    weights = [1.0] + [0.5] * (len(systems) - 1)
    wsum = sum(weights)
    from ..progress import SubProgress

    # --- nadir system
    plan = plan_levels(zmin, zmax, dz, local, cfg.max_levels)
    zsw = None
    if z_surface is not None:
        zsw = _surface_windows(z_surface, grid, plan, cfg, off[2])
    nadir = _match_system(
        o,
        systems[0],
        pyr,
        local,
        plan,
        cfg,
        SubProgress(progress, 0, 0.8 * weights[0] / wsum),
        zsw,
        want_colour=want_colour,
        executor=executor,
        cache=cache,
        cache_base=cache_base,
    )
    dsm = np.where(np.isfinite(nadir.z), nadir.z + off[2], np.nan).astype(np.float32)
    conf = np.where(np.isfinite(nadir.z), np.clip(np.nan_to_num(nadir.confidence), 0, 1), np.nan).astype(
        np.float32
    )

    # --- oblique systems
    clouds = []
    pos = 0.8 * weights[0] / wsum
    for s, w in zip(systems[1:], weights[1:], strict=True):
        sub = SubProgress(progress, pos, pos + 0.8 * w / wsum)
        pos += 0.8 * w / wsum
        clouds.append(
            _oblique_points(
                o,
                s,
                pyr,
                local,
                zmin,
                zmax,
                dz,
                cfg,
                sub,
                want_rgb,
                executor,
                cache,
                cache_base,
            )  # fmt: skip
        )
    if clouds:
        clouds = _visible_clouds(o, systems, clouds, dsm, conf, local, SubProgress(progress, 0.8, 0.85))
    return _Surface(dsm, conf, nadir.rgb, clouds, systems, len(plan.levels), nadir.tiles, nadir.max_volume)


def _visible_clouds(o, systems, clouds, dsm, conf, local: RasterGrid, progress) -> list:
    """The oblique systems' points without those that confident surfaces hide from their own photos
    (:mod:`.fusion`); the nadir DSM's confident cells, with their walls, are occluders too."""
    from ..ortho.zbuffer import dsm_triangles
    from .fusion import CONFIDENT, MARGIN_CELLS, visible_points

    off = o.offset
    sure = np.isfinite(dsm) & (np.nan_to_num(conf) >= CONFIDENT)
    heights = np.where(sure, dsm.astype(np.float64) - off[2], np.nan)
    surface = dsm_triangles(heights, local.x_min, local.y_max, local.res, wall_min=MARGIN_CELLS * local.res)
    cams = [(im.R, im.C, o.camera_of(im)) for im in o.images]
    images = [s.images for s in systems[1:]]
    keep = visible_points([c[0] - off for c in clouds], [c[2] for c in clouds], images, cams, local.res,
                          surface=surface, progress=progress)  # fmt: skip
    out = []
    for (w, rgb, cf), k in zip(clouds, keep, strict=True):
        out.append((w[k], None if rgb is None else rgb[k], cf[k]))
    return out


def _system_stats(systems, nadir_points: int, oblique_points: list[int], n_images: int) -> list[dict]:
    out = [{"id": 0, "name": "nadir", "view_direction": [0.0, 0.0, -1.0], "images": n_images,
            "points": int(nadir_points)}]  # fmt: skip
    for s, n in zip(systems[1:], oblique_points, strict=True):
        out.append(
            {
                "id": s.id,
                "name": s.name,
                "view_direction": [float(v) for v in s.direction],
                "images": len(s.images),
                "points": int(n),
            }
        )
    return out


def _run_systems(
    o, cfg, outputs, grid, local, pyr, executor, cache, cache_base, zmin, zmax, zsrc, zs_mid, dz, res,
    z_surface, progress, t0,
) -> OsgmResult:  # fmt: skip
    if z_surface is not None:
        zsrc = "Z_SURFACE"
    chunks = plan_chunks(grid, cfg, plan_levels(zmin, zmax, dz, local, cfg.max_levels).levels[0])
    if len(chunks) > 1:
        return _run_chunked(
            o, cfg, outputs, grid, local, pyr, executor, cache, cache_base, zmin, zmax, zsrc, zs_mid, dz, res,
            z_surface, progress, t0, chunks,
        )  # fmt: skip
    surf = _match_surface(
        o, cfg, grid, local, pyr, executor, cache, cache_base, zmin, zmax, dz, z_surface, progress,
        outputs.point_cloud is not None, outputs.wants_colours,
    )  # fmt: skip
    dsm, conf = surf.dsm, surf.conf
    sys_stats = _system_stats(surf.systems, int(np.isfinite(dsm).sum()), [len(c[0]) for c in surf.clouds],
                              len(o.images))  # fmt: skip
    if progress.cancelled():
        raise CancelledError("OSGM cancelled")
    progress.update(0.85, "writing outputs")
    written = _write_outputs(o, grid, dsm, conf, surf.rgb, surf.clouds, surf.systems, outputs, res)
    ok = np.isfinite(dsm)
    run = _RunInfo(o, grid, res, dz, zmin, zmax, zsrc, zs_mid, pyr, executor, cache, t0)
    stats = run.stats(surf.levels, surf.tiles, 1, float(ok.mean()),
                      float(np.nanmean(conf)) if ok.any() else 0.0, sys_stats, surf.max_volume)  # fmt: skip
    progress.update(1.0, "OSGM done")
    return OsgmResult(grid, stats, written)


@dataclass
class _RunInfo:
    """What the statistics of a run say besides its results (one run or chunks)."""

    o: Orientation
    grid: RasterGrid
    res: float
    dz: float
    zmin: float
    zmax: float
    zsrc: str
    zs_mid: float
    pyr: ImagePyramid
    executor: object
    cache: TileCache
    t0: float

    def stats(self, levels, tiles, chunks, completeness, mean_confidence, systems, max_volume) -> dict:
        off, g, ex = self.o.offset, self.grid, self.executor
        return {
            "rows": g.rows,
            "cols": g.cols,
            "resolution": self.res,
            "z_step": self.dz,
            "z_min": self.zmin + off[2],
            "z_max": self.zmax + off[2],
            "z_source": self.zsrc,
            "z_mid": self.zs_mid + off[2],
            "levels": levels,
            "tiles": tiles,
            "chunks": chunks,
            "extent": list(g.extent),
            "completeness": completeness,
            "mean_confidence": mean_confidence,
            "systems": systems,
            "images": len(self.o.images),
            "image_reads": self.pyr.reads,
            "point_spread": self.pyr.spread_report,
            "prefilter": {
                "sigma": self.pyr.prefilter,
                "images": sum(self.pyr.prefilter_sigma(i, 0) > 0.0 for i in range(len(self.pyr.paths))),
            },
            "executor": ex.describe() if hasattr(ex, "describe") else type(ex).__name__,
            "cache_hits": self.cache.hits,
            "cache_tiles_written": self.cache.written,
            "task_volume_bytes": 4 * max_volume,
            "seconds": time.perf_counter() - self.t0,
        }


#: Bytes per finest-level cell that a chunk holds at once: the levels' heights and confidences
#: (float32, the coarser levels add a third), the filled guide, the world DSM and confidence,
#: the colours, and the chunk's share of the point cloud (xyz float64, colour, confidence, id).
CHUNK_BYTES_PER_CELL = 96 + 24  # + the seam blending's accumulators (assemble_tiles)


def plan_chunks(grid: RasterGrid, cfg: OsgmConfig, top_level: int):
    """The chunks of ``grid`` that OSGM matches one after the other (a list of :class:`~..grid.Tile`).

    A chunk's arrays are whole-grid arrays of its own coarse-to-fine run, so a block too
    large for ``cfg.chunk_memory`` bytes (:data:`CHUNK_BYTES_PER_CELL` per cell) is cut
    into square chunks that fit. Every chunk is matched on its core plus a margin as wide
    as the tiles' overlap on the coarsest level ``top_level`` (``max(16, tile_size / 8)``
    cells there, i.e. ``2^top_level`` times that on the finest level), so a chunk's border
    is no worse than a tile's border on every level; core and margin are multiples of
    ``2^top_level`` cells, so the chunks' coarse levels fall on the cells of the whole grid's.
    A grid that fits is one chunk.
    """
    budget = int(cfg.chunk_memory)
    if budget <= 0 or grid.rows * grid.cols * CHUNK_BYTES_PER_CELL <= budget:
        return grid.tiles(max(grid.rows, grid.cols), 0)
    unit = 2 ** max(int(top_level), 0)
    margin = max(16, int(cfg.tile_size) // 8) * unit
    side = int(math.isqrt(budget // CHUNK_BYTES_PER_CELL)) - 2 * margin
    side = max(2 * margin, side // unit * unit)
    return grid.tiles(side, margin)


def _references(systems) -> list:
    """The point cloud's reference-system table (id, name, viewing direction) of ``systems``."""
    from ..surface.pointcloud import ReferenceSystem

    return [
        ReferenceSystem(s.id, s.name, (float(s.direction[0]), float(s.direction[1]), float(s.direction[2])))
        for s in systems
    ]


def _cloud_parts(grid: RasterGrid, dsm, rgb, conf, clouds, refs, crs, core=None) -> tuple[list, list[int]]:
    """The point clouds of the nadir DSM's valid cells (``grid``) and of the oblique systems, and the
    points per system. ``core``: ``(x0, y0, x1, y1)`` keeps only the oblique points whose plan
    position lies in it (a chunk's core: every point in exactly one chunk)."""
    from ..surface.pointcloud import PointCloud

    ok = np.isfinite(dsm)
    X, Y = grid.centres()
    nadir = np.column_stack([X[ok], Y[ok], dsm[ok].astype(np.float64)])
    parts = [PointCloud(nadir, rgb[ok], conf[ok], np.zeros(len(nadir), np.uint16), crs, [refs[0]])]
    counts = [len(nadir)]
    for (xyz, prgb, pconf), ref in zip(clouds, refs[1:], strict=True):
        if core is not None:
            x0, y0, x1, y1 = core
            keep = (xyz[:, 0] >= x0) & (xyz[:, 0] < x1) & (xyz[:, 1] > y0) & (xyz[:, 1] <= y1)
            xyz, pconf = xyz[keep], pconf[keep]
            prgb = prgb[keep] if prgb is not None else None
        counts.append(len(xyz))
        if len(xyz):
            parts.append(PointCloud(xyz, prgb, pconf, np.full(len(xyz), ref.id, np.uint16), crs, [ref]))
    return parts, counts


def _run_chunked(
    o, cfg, outputs, grid, local, pyr, executor, cache, cache_base, zmin, zmax, zsrc, zs_mid, dz, res,
    z_surface, progress, t0, chunks,
) -> OsgmResult:  # fmt: skip
    """OSGM chunk by chunk (:func:`plan_chunks`): only the cores are written, window by window."""
    from contextlib import ExitStack

    from ..progress import SubProgress
    from ..rasterio_io import RasterWriter
    from ..surface.pointcloud import PointCloudFile, merge_point_clouds

    systems = reference_systems(o, cfg.oblique, cfg.oblique_group_angle)
    refs = _references(systems)
    valid = tiles = levels = max_volume = 0
    conf_sum = 0.0
    points = [0] * len(systems)
    written: dict = {}
    with ExitStack() as stack:
        w_dsm = stack.enter_context(
            RasterWriter(outputs.dsm, grid, 1, "float32", DSM_NODATA, ["height"], overviews=True)
        )
        w_conf = w_rgb = cloud_file = None
        if outputs.confidence is not None:
            w_conf = stack.enter_context(
                RasterWriter(outputs.confidence, grid, 1, "float32", -1.0, ["confidence"])
            )
        if outputs.orthoimage is not None:
            w_rgb = stack.enter_context(RasterWriter(outputs.orthoimage, grid, 3, "uint8", 0, overviews=True))
        if outputs.point_cloud is not None:
            cloud_file = stack.enter_context(PointCloudFile(outputs.point_cloud, o.crs, refs))
        for k, ch in enumerate(chunks):
            if progress.cancelled():
                raise CancelledError("OSGM cancelled")
            sub = SubProgress(progress, 0.95 * k / len(chunks), 0.95 * (k + 1) / len(chunks))
            surf = _match_surface(
                o, cfg, ch.outer_grid(grid), ch.outer_grid(local), pyr, executor, cache, cache_base,
                zmin, zmax, dz, z_surface, sub, outputs.point_cloud is not None, outputs.wants_colours,
            )  # fmt: skip
            ins = ch.inner_slices
            dsm, conf = surf.dsm[ins], surf.conf[ins]
            rgb = surf.rgb[ins] if surf.rgb is not None else np.zeros(dsm.shape + (3,), np.uint8)
            ok = np.isfinite(dsm)
            valid += int(ok.sum())
            conf_sum += float(conf[ok].sum())
            tiles += surf.tiles
            levels = max(levels, surf.levels)
            max_volume = max(max_volume, surf.max_volume)
            w_dsm.write(np.where(ok, dsm, DSM_NODATA).astype(np.float32), ch.core)
            if w_conf is not None:
                w_conf.write(np.where(ok, conf, -1.0).astype(np.float32), ch.core)
            if w_rgb is not None:
                w_rgb.write(np.moveaxis(rgb, -1, 0), ch.core)
            core = ch.core_grid(grid)
            parts, counts = _cloud_parts(core, dsm, rgb, conf, surf.clouds, refs, o.crs, core.extent)
            points = [a + c for a, c in zip(points, counts, strict=True)]
            if cloud_file is not None:
                merged = merge_point_clouds(parts, voxel=None) if len(parts) > 1 else parts[0]
                cloud_file.add(merged)
            del surf, parts
        progress.update(0.96, "writing outputs")
    written["dsm"] = str(outputs.dsm)
    for name in ("confidence", "orthoimage", "point_cloud"):
        if getattr(outputs, name) is not None:
            written[name] = str(getattr(outputs, name))
    cells = grid.rows * grid.cols
    run = _RunInfo(o, grid, res, dz, zmin, zmax, zsrc, zs_mid, pyr, executor, cache, t0)
    stats = run.stats(levels, tiles, len(chunks), valid / max(cells, 1), conf_sum / valid if valid else 0.0,
                      _system_stats(systems, points[0], points[1:], len(o.images)), max_volume)  # fmt: skip
    progress.update(1.0, "OSGM done")
    return OsgmResult(grid, stats, written)


def _surface_windows(path, grid: RasterGrid, plan: LevelPlan, cfg: OsgmConfig, off_z: float):
    from ..rasterio_io import read_onto_grid
    from .levels import neighbourhood_minmax

    lv = plan.levels[0]
    g = plan.grid(grid, lv)
    surf = read_onto_grid(path, g, resampling="bilinear") - off_z
    if not np.isfinite(surf).any():
        raise InputError(f"Z_SURFACE: {path} has no data over the extent")
    lo, hi = neighbourhood_minmax(surf, 1)
    margin = cfg.z_margin or max(5 * plan.dz(lv), 2.0)
    return lo - margin, hi + margin


def _oblique_points(
    o, system, pyr, local: RasterGrid, zmin, zmax, dz, cfg, progress, want_rgb, executor, cache, cache_base
):
    """Points (world xyz, rgb, confidence) of one oblique reference system."""
    Q = system.Q
    x0, y0, x1, y1 = local.extent
    corners = np.array([[x, y, z] for x in (x0, x1) for y in (y0, y1) for z in (zmin, zmax)])
    sc = corners @ Q.T
    s_lo, s_hi = sc.min(axis=0), sc.max(axis=0)
    res = local.res
    sgrid = RasterGrid.from_extent((s_lo[0], s_lo[1], s_hi[0], s_hi[1]), res, None)
    plan = plan_levels(float(s_lo[2]), float(s_hi[2]), dz, sgrid, cfg.max_levels)
    r = _match_system(o, system, pyr, sgrid, plan, cfg, progress, None, want_rgb, executor, cache, cache_base)
    ok = np.isfinite(r.z)
    X, Y = sgrid.centres()
    S = np.column_stack([X[ok], Y[ok], r.z[ok].astype(np.float64)])
    L = S @ Q  # system -> local
    inside = (L[:, 0] >= x0) & (L[:, 0] <= x1) & (L[:, 1] >= y0) & (L[:, 1] <= y1)
    inside &= (L[:, 2] >= zmin) & (L[:, 2] <= zmax)
    world = L[inside] + o.offset
    rgb = r.rgb[ok][inside] if r.rgb is not None else None
    conf = np.clip(np.nan_to_num(r.confidence[ok][inside]), 0, 1).astype(np.float32)
    return world, rgb, conf


def _write_outputs(o, grid, dsm, conf, rgb, clouds, systems, outputs: OsgmOutputs, res) -> dict:
    from ..rasterio_io import write_raster

    written = {}
    nod = np.where(np.isfinite(dsm), dsm, DSM_NODATA).astype(np.float32)
    write_raster(outputs.dsm, nod, grid, nodata=DSM_NODATA, overviews=True, descriptions=["height"])
    written["dsm"] = str(outputs.dsm)
    if outputs.confidence is not None:
        write_raster(
            outputs.confidence,
            np.where(np.isfinite(conf), conf, -1.0).astype(np.float32),
            grid,
            nodata=-1.0,
            descriptions=["confidence"],
        )
        written["confidence"] = str(outputs.confidence)
    if outputs.orthoimage is not None:
        write_raster(outputs.orthoimage, np.moveaxis(rgb, -1, 0), grid, nodata=0, overviews=True)
        written["orthoimage"] = str(outputs.orthoimage)
    if outputs.point_cloud is not None:
        from ..surface.pointcloud import merge_point_clouds, write_point_cloud_file

        refs = _references(systems)
        parts, _ = _cloud_parts(grid, dsm, rgb, conf, clouds, refs, o.crs)
        cloud = merge_point_clouds(parts, voxel=None) if len(parts) > 1 else parts[0]
        cloud.systems = refs
        write_point_cloud_file(outputs.point_cloud, cloud)
        written["point_cloud"] = str(outputs.point_cloud)
    return written
