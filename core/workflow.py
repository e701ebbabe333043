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
import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .errors import InputError
from .memory import peak_rss_mb
from .progress import EtaProgress, Progress, Steps, as_progress, check
from .report import Report, Table

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
        peak = peak_rss_mb()
        self.rows.append(
            [
                self._name,
                round(time.perf_counter() - self._t, 2),
                None if peak is None else round(peak, 1),
                note,
            ]
        )


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
    report = Report("TruOrtho pipeline report")
    t0 = time.perf_counter()

    # 1. orientation
    stages.start("orientation")
    reuse = cfg.reuse_orientation and Path(paths["orientation"]).exists()
    if reuse:
        orientation = Orientation.load(paths["orientation"])
        orient_report = _previous_orientation_report(folder)
        stages.stop("reused orientation.json")
    else:
        if not images:
            raise InputError("IMAGES: no image files given")
        run = orient_images(
            list(images), camera_file=cfg.camera_file, gcps=gcps or [], crs=crs,
            config=cfg.orient or OrientConfig(), work_dir=folder / ".truortho-cache", progress=steps[0],
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
    stages.stop(f"{len(mres.mesh.vertices)} vertices, {len(mres.mesh.faces)} faces")

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
    _fill_report(report, orient_report, orientation, osgm, fstats, paths, tres, stages, reuse)
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


def write_seamlines(path, regions, crs) -> None:
    """Seamline polygons (one feature per source image) as a GeoPackage, atomically."""
    from osgeo import ogr, osr

    from .rasterio_io import atomic_output

    with atomic_output(path) as tmp:
        drv = ogr.GetDriverByName("GPKG")
        ds = drv.CreateDataSource(str(tmp))
        srs = osr.SpatialReference()
        if crs:
            srs.SetFromUserInput(str(crs))
            srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
        layer = ds.CreateLayer("seamlines", srs if crs else None, ogr.wkbMultiPolygon)
        for name, kind in (("image", ogr.OFTInteger), ("name", ogr.OFTString), ("cells", ogr.OFTInteger)):
            layer.CreateField(ogr.FieldDefn(name, kind))
        for r in regions:
            f = ogr.Feature(layer.GetLayerDefn())
            geom = ogr.ForceToMultiPolygon(ogr.CreateGeometryFromWkt(r.wkt))
            f.SetGeometry(geom)
            f.SetField("image", int(r.image_index))
            f.SetField("name", str(r.image_name))
            f.SetField("cells", int(r.cells))
            layer.CreateFeature(f)
        ds = None  # close before the rename
        del ds


def _previous_orientation_report(folder: Path) -> Report | None:
    p = folder / "report.json"
    if not p.exists():
        return None
    try:
        d = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    rep = Report("orientation (reused)")
    for t in d.get("tables", []):
        if str(t.get("title", "")).startswith("Stage"):
            continue
        rep.tables.append(Table(t["title"], t["columns"], t["rows"], t.get("note", "")))
    this_run = ("DSM", "true", "total", "tiles")  # the rest of the chain, not the orientation
    rep.summary = {k: v for k, v in d.get("summary", {}).items() if not str(k).startswith(this_run)}
    return rep


def _fill_report(
    report: Report, orient_report, orientation, osgm, fstats, paths, tres, stages, reused
) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .rasterio_io import read_raster

    if orient_report is not None:
        report.data["orientation"] = orient_report.data
        report.summary.update(orient_report.summary)
        report.tables.extend(orient_report.tables)
        report.figures.extend(orient_report.figures)
        report.warnings.extend(orient_report.warnings)
    if reused:
        report.warnings.append("The orientation was reused from orientation.json (not recomputed).")
    report.summary["images oriented"] = len(orientation.images)
    report.summary["CRS"] = orientation.crs
    s = osgm.stats
    report.data["osgm"] = s
    report.data["filter"] = fstats.as_dict()
    report.data["trueortho"] = {k: v for k, v in tres.stats.items() if isinstance(v, int | float | str)}
    report.summary["DSM resolution [m]"] = s["resolution"]
    report.summary["DSM completeness (raw) [%]"] = round(100 * s["completeness"], 2)
    dsm, grid, _ = read_raster(paths["dsm"])
    report.summary["DSM completeness (filtered) [%]"] = round(100 * float(np.isfinite(dsm).mean()), 2)
    st = tres.stats
    occl = float(st.get("cells_occluded", 0)) / max(1, int(st.get("rows", 1)) * int(st.get("cols", 1)))
    report.summary["true ortho coverage [%]"] = round(100 * float(st["coverage"]), 2)
    report.summary["true ortho occluded share [%]"] = round(100 * occl, 2)
    report.tables.append(
        Table("Dense matching and DSM filter", ["what", "value"],
              [["OSGM", osgm.summary()], ["filter", fstats.summary()]])
    )  # fmt: skip
    # DSM hillshade
    fig, ax = plt.subplots(figsize=(7, 6))
    z = np.where(np.isfinite(dsm), dsm, np.nanmedian(dsm) if np.isfinite(dsm).any() else 0)
    gy, gx = np.gradient(z, grid.res)
    slope = np.pi / 2 - np.arctan(np.hypot(gx, gy))
    aspect = np.arctan2(-gx, gy)
    az, alt = np.radians(315), np.radians(45)
    shade = np.sin(alt) * np.sin(slope) + np.cos(alt) * np.cos(slope) * np.cos(az - aspect)
    ext = (grid.extent[0], grid.extent[2], grid.extent[1], grid.extent[3])
    ax.imshow(np.where(np.isfinite(dsm), shade, np.nan), cmap="gray", extent=ext)
    im = ax.imshow(np.where(np.isfinite(dsm), dsm, np.nan), cmap="terrain", alpha=0.45, extent=ext)
    fig.colorbar(im, ax=ax, label="height [m]")
    ax.set_title(f"Filtered DSM ({100 * float(np.isfinite(dsm).mean()):.1f} % of the cells)")
    report.add_figure("DSM hillshade (filtered DSM)", fig)
    # true ortho preview
    ortho, og, _ = read_raster(paths["trueortho"], band=None)
    step = max(1, int(np.ceil(max(ortho.shape[1:]) / 1200)))
    o = np.moveaxis(ortho[:, ::step, ::step], 0, -1)
    fig, ax = plt.subplots(figsize=(7, 6))
    if o.shape[2] >= 4:
        rgb = o[:, :, :3].astype(np.float32)
        if rgb.max() > 255:
            rgb = rgb / max(float(rgb.max()), 1.0) * 255
        alpha = o[:, :, -1] > 0
        show = np.where(alpha[..., None], rgb, 0).astype(np.uint8)
    else:
        show = o[:, :, 0]
    oext = (og.extent[0], og.extent[2], og.extent[1], og.extent[3])
    ax.imshow(show, extent=oext)
    ax.set_title(f"True orthophoto (black: seen by no image, {100 * occl:.2f} %)")
    report.add_figure("True orthophoto preview", fig)
    report.tables.append(Table("Stages", ["stage", "time [s]", "peak memory [MB]", "result"], []))
