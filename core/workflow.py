"""The whole chain: photos (+ GCPs) -> orientation -> OSGM -> DSM filter -> products, one report.

:func:`run_workflow` runs, with multi-step progress and cancel:

1. orientation (:func:`~truortho.core.sfm.pipeline.orient_images`), or the
   existing ``orientation.json`` of the output folder when asked to reuse it;
2. dense matching (:func:`~truortho.core.osgm.run_osgm`): raw DSM, confidence,
   orthoimage, point cloud;
3. DSM filtering (:func:`~truortho.core.surface.filter.filter_dsm`);
4. mesh of the filtered DSM (:func:`~truortho.core.surface.mesh.mesh_from_dsm`);
5. true orthophoto on the filtered DSM (:func:`~truortho.core.ortho.pipeline.true_ortho`),
   occlusion mask and seamline polygons;
6. one HTML report (+ JSON): block overview, sigma0, GCP and check-point
   tables, residual plot and tie-point statistics (from the orientation),
   a DSM hillshade with completeness, a true-ortho preview with the occluded
   share, and per-stage time and peak memory.

Products have fixed names in the output folder (:data:`PRODUCTS`); every file
is written atomically by its stage.

The tiles of stages 2, 3 and 5 run on one executor (:mod:`truortho.core.parallel`,
``WorkflowConfig.executor``: in this process, a local Dask cluster or a Dask
scheduler), made once before the orientation (a bad choice or an unusable
scheduler address fails before any work) and closed when the run ends, however
it ends; a local cluster thus starts once for the three stages.
"""

from __future__ import annotations

import dataclasses
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .cache import cache_root
from .errors import InputError
from .memory import peak_rss_mb
from .progress import EtaProgress, Progress, Steps, as_progress, check
from .report import Report, pipeline_report, reused_orientation_report

#: Product names in the output folder.
PRODUCTS = {
    "orientation": "orientation.json",
    "report": "report.html",
    "dsm_raw": "dsm_raw.tif",
    "confidence": "confidence.tif",
    "orthoimage": "orthoimage.tif",
    "dsm": "dsm.tif",
    "pointcloud": "pointcloud.laz",
    "mesh": "mesh.ply",
    "trueortho": "trueortho.tif",
    "source_index": "source_index.tif",
    "occlusion": "occlusion.tif",
    "seamlines": "seamlines.gpkg",
}


@dataclass
class WorkflowConfig:
    """Options of :func:`run_workflow`.

    Attributes
    ----------
    resolution : float, optional
        Cell size of the DSM and the true orthophoto; default the median GSD.
    camera_file : path, optional
        Interior orientation (held fixed), as for ``truortho:orientimages``.
    reuse_orientation : bool
        Skip the orientation when ``orientation.json`` exists in the output folder.
    executor : {"inprocess", "local", "scheduler"}
        Where the tiles of dense matching, the DSM filter and the true orthophoto run
        (:func:`truortho.core.parallel.make_executor`); one executor serves the three stages and
        overrides the stage configurations' own ``executor``/``scheduler_address``. A local
        cluster takes its workers and memory limit from ``osgm.workers``/``osgm.worker_memory``.
    scheduler_address : str, optional
        Dask scheduler of ``executor="scheduler"`` (default ``$TRUORTHO_DASK_SCHEDULER``).
    orient, osgm, dsm_filter, mesh, ortho : stage configurations (defaults when None)
    """

    resolution: float | None = None
    camera_file: str | os.PathLike | None = None
    reuse_orientation: bool = False
    executor: str = "inprocess"
    scheduler_address: str | None = None
    orient: Any = None
    osgm: Any = None
    dsm_filter: Any = None
    mesh: Any = None
    ortho: Any = None


@dataclass
class WorkflowResult:
    paths: dict[str, str]
    stats: dict = field(default_factory=dict)
    report: Report | None = None


class _Stages:
    """Wall time and peak memory per stage."""

    def __init__(self) -> None:
        self.rows: list[list] = []
        self._t = 0.0
        self._name = ""

    def start(self, name: str) -> None:
        self._name, self._t = name, time.perf_counter()

    def stop(self, note: str = "") -> None:
        """Record the stage, then hand what it freed back to the system before the next one
        (:func:`~.memory.release_freed_memory`: otherwise the next stage's arrays come on top)."""
        from .memory import release_freed_memory

        peak = peak_rss_mb()
        self.rows.append(
            [
                self._name,
                round(time.perf_counter() - self._t, 2),
                None if peak is None else round(peak, 1),
                note,
            ]
        )
        release_freed_memory()


def _paths(folder: Path) -> dict[str, str]:
    return {k: str(folder / v) for k, v in PRODUCTS.items()}


def run_workflow(
    images,
    output_folder,
    gcps=None,
    crs: str | None = None,
    config: WorkflowConfig | None = None,
    progress: Progress | None = None,
) -> WorkflowResult:
    """Run the whole chain on a block of photos; products go to ``output_folder`` (:data:`PRODUCTS`).

    Parameters
    ----------
    images : list of path
        The photos (non-image files are skipped by the orientation).
    output_folder : path
        Created when missing.
    gcps : list of GCP, optional
        Control and check points with their image measurements (world coordinates in ``crs``).
    crs : str, optional
        CRS of the GCPs and the products.

    Raises
    ------
    InputError
        Bad parameters (RESOLUTION, EXECUTOR, SCHEDULER_ADDRESS) before any work, or bad input.
    """
    from .ortho.pipeline import TrueOrthoConfig
    from .osgm import OsgmConfig
    from .parallel import EXECUTORS, make_executor, parse_memory

    cfg = config or WorkflowConfig()
    if cfg.resolution is not None and not (np.isfinite(cfg.resolution) and cfg.resolution > 0):
        raise InputError(f"RESOLUTION: expected a positive number of metres, got {cfg.resolution!r}")
    if cfg.executor not in EXECUTORS:
        raise InputError(f"EXECUTOR: expected one of {', '.join(EXECUTORS)}, got {cfg.executor!r}")
    # the stages' configurations name the workflow's executor (their validation sees it); the
    # caller's objects are not changed
    ocfg = dataclasses.replace(
        cfg.osgm or OsgmConfig(), executor=cfg.executor, scheduler_address=cfg.scheduler_address
    )
    if cfg.resolution is not None:
        ocfg.resolution = float(cfg.resolution)
    tcfg = dataclasses.replace(
        cfg.ortho or TrueOrthoConfig(), executor=cfg.executor, scheduler_address=cfg.scheduler_address
    )
    ocfg.validate()
    tcfg.validate()
    # cheap: a local cluster starts on its first tiles, a scheduler is reached then (its address is
    # checked here)
    executor = make_executor(
        cfg.executor,
        cfg.scheduler_address,
        n_workers=ocfg.workers,
        memory_limit=parse_memory(ocfg.worker_memory),
    )
    try:
        return _run(images, output_folder, gcps, crs, cfg, ocfg, tcfg, executor, progress)
    finally:
        executor.close()


def _run(images, output_folder, gcps, crs, cfg, ocfg, tcfg, executor, progress) -> WorkflowResult:
    """:func:`run_workflow` after its checks, on ``executor`` (closed by the caller)."""
    from .orientation import Orientation
    from .ortho.pipeline import true_ortho
    from .osgm import OsgmOutputs, run_osgm
    from .rasterio_io import write_seamlines
    from .sfm.pipeline import OrientConfig, orient_images
    from .surface.filter import DsmFilterConfig, filter_dsm
    from .surface.mesh import DsmMeshConfig, mesh_from_dsm
    from .surface.meshio import write_mesh

    folder = Path(output_folder)
    folder.mkdir(parents=True, exist_ok=True)
    paths = _paths(folder)
    progress = as_progress(progress)
    weights = [0.35, 0.35, 0.04, 0.06, 0.18, 0.02]
    stage_steps = Steps(progress, weights)
    # every stage's messages carry its elapsed time and an estimate of its time left
    steps = [EtaProgress(stage_steps[k]) for k in range(len(weights))]
    stages = _Stages()
    t0 = time.perf_counter()

    # 1. orientation
    stages.start("orientation")
    reuse = cfg.reuse_orientation and Path(paths["orientation"]).exists()
    if reuse:
        orientation = Orientation.load(paths["orientation"])
        orient_report = reused_orientation_report(folder / "report.json")
        stages.stop("reused orientation.json")
    else:
        if not images:
            raise InputError("IMAGES: no image files given")
        run = orient_images(
            list(images), camera_file=cfg.camera_file, gcps=gcps or [], crs=crs,
            config=cfg.orient or OrientConfig(), work_dir=cache_root(), progress=steps[0],
        )  # fmt: skip
        orientation = run.orientation
        if orientation.crs is None:
            raise InputError(
                "CRS: the block has no georeference (no GCPs and no EXIF GNSS); the DSM and the true "
                "orthophoto need one"
            )
        orientation.save(paths["orientation"])
        orient_report = run.report
        stages.stop(f"{len(orientation.images)} of {len(images)} images oriented")
    steps[0].update(1.0, "orientation done")
    check(progress)

    # 2. OSGM
    stages.start("dense matching (OSGM)")
    osgm = run_osgm(
        orientation, ocfg, None,
        OsgmOutputs(dsm=paths["dsm_raw"], confidence=paths["confidence"], orthoimage=paths["orthoimage"],
                    point_cloud=paths["pointcloud"]),
        progress=steps[1], executor=executor,
    )  # fmt: skip
    stages.stop(osgm.summary())
    res = osgm.stats["resolution"]

    # 3. DSM filter
    stages.start("DSM filter")
    fcfg = cfg.dsm_filter or DsmFilterConfig()
    fstats = filter_dsm(
        paths["dsm_raw"], paths["dsm"], paths["confidence"], fcfg, progress=steps[2], executor=executor
    )
    stages.stop(fstats.summary())

    # 4. mesh
    stages.start("mesh")
    mres = mesh_from_dsm(paths["dsm"], cfg.mesh or DsmMeshConfig(), paths["orthoimage"], progress=steps[3])
    write_mesh(paths["mesh"], mres.mesh)
    note = f"{len(mres.mesh.vertices)} vertices, {len(mres.mesh.faces)} faces"
    del mres  # written: the true ortho does not need the mesh, and its memory is released below
    stages.stop(note)

    # 5. true orthophoto
    stages.start("true orthophoto")
    if tcfg.resolution is None:
        tcfg.resolution = res
    tres = true_ortho(
        orientation, paths["dsm"], paths["trueortho"], paths["source_index"], paths["occlusion"], tcfg,
        steps[4], executor=executor,
    )  # fmt: skip
    write_seamlines(paths["seamlines"], tres.seamlines, tres.grid.crs)
    st = tres.stats
    stages.stop(f"coverage {100 * st['coverage']:.2f} %, {st['cells_occluded']} cells seen by no image")

    # 6. report
    stages.start("report")
    report = pipeline_report(
        "TruOrtho pipeline report", orient_report, orientation, osgm, fstats, paths["dsm"],
        paths["trueortho"], tres, reuse, paths["confidence"],
    )  # fmt: skip
    ran_on = executor.describe() if hasattr(executor, "describe") else type(executor).__name__
    report.summary["tiles ran on"] = ran_on
    stages.stop()
    report.tables[-1].rows = stages.rows
    report.summary["total time [s]"] = round(time.perf_counter() - t0, 1)
    report.save(paths["report"])
    steps[5].update(1.0, "report written")
    stats = {
        "seconds": time.perf_counter() - t0,
        "stages": stages.rows,
        "osgm": osgm.stats,
        "trueortho": {k: v for k, v in st.items() if isinstance(v, int | float | str)},
        "filter": fstats.summary(),
        "peak_mb": max((r[2] for r in stages.rows if r[2] is not None), default=None),
        "executor": ran_on,
    }
    progress.update(1.0, "pipeline done")
    return WorkflowResult(paths, stats, report)
