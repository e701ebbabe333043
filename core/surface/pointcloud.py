"""Point clouds: LAS 1.4/LAZ products with confidence and reference system, merging, DSM export.

A :class:`PointCloud` holds world coordinates with optional RGB, per-point
confidence and the id of the *reference system* each point comes from (the
matching geometry of OSGM: the nadir DSM system and each oblique system).
Files (:func:`write_point_cloud_file`):

* LAS 1.4 point format 7 (RGB) or 6, ``.las`` or ``.laz`` (LASzip), CRS as a
  WKT VLR, extra dimensions ``confidence`` (float32, [0, 1]) and ``system``
  (uint16), and a VLR (user id ``TruOrtho``, record 1) holding the systems
  as JSON ``[{"id", "name", "view_direction"}]``;
* optionally an Entwine Point Tile dataset beside it (:mod:`.ept`), which
  QGIS 3.22 opens without PDAL.

:func:`merge_point_clouds` merges the clouds of several reference systems,
optionally thinning duplicates on a voxel grid (keeping the most confident
point of each voxel); :func:`dsm_to_point_cloud` exports a DSM raster (one
point per valid cell, colour from an orthoimage, confidence from a raster)
tile by tile.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import FormatError, InputError
from ..progress import Progress, Steps, as_progress, check

CONFIDENCE = "confidence"
SYSTEM = "system"
SYSTEMS_VLR = ("TruOrtho", 1)


@dataclass
class ReferenceSystem:
    """A reference system of the matching (a viewing geometry the points were computed in).

    Attributes
    ----------
    id : int
        Value of the ``system`` dimension (0-65535).
    name : str
    view_direction : (3,) float, optional
        Unit vector (world frame) of the viewing direction, from the cameras towards
        the scene; ``(0, 0, -1)`` for nadir. Used to mesh the system's points.
    """

    id: int
    name: str = ""
    view_direction: tuple[float, float, float] | None = None

    def as_dict(self) -> dict:
        return {
            "id": int(self.id),
            "name": self.name,
            "view_direction": None
            if self.view_direction is None
            else [float(v) for v in self.view_direction],
        }


@dataclass
class PointCloud:
    """Points in world coordinates.

    Attributes
    ----------
    xyz : (N, 3) float64
        World coordinates (metres, CRS ``crs``).
    rgb : (N, 3) uint8, optional
    confidence : (N,) float32, optional
        In [0, 1].
    system : (N,) uint16, optional
        Reference system id of every point.
    crs : str, optional
    systems : list of ReferenceSystem
    """

    xyz: np.ndarray
    rgb: np.ndarray | None = None
    confidence: np.ndarray | None = None
    system: np.ndarray | None = None
    crs: str | None = None
    systems: list[ReferenceSystem] = field(default_factory=list)

    def __post_init__(self) -> None:
        xyz = np.asarray(self.xyz, dtype=np.float64)
        if xyz.ndim != 2 or xyz.shape[1] != 3:
            raise InputError(f"point cloud: expected (N, 3) coordinates, got shape {xyz.shape}")
        if not np.all(np.isfinite(xyz)):
            raise InputError("point cloud: coordinates must be finite")
        n = len(xyz)
        self.xyz = xyz
        if self.rgb is not None:
            c = np.asarray(self.rgb)
            if c.shape != (n, 3):
                raise InputError(f"point cloud: colours of shape {c.shape}, expected ({n}, 3)")
            self.rgb = c if c.dtype == np.uint8 else np.clip(c, 0, 255).astype(np.uint8)
        if self.confidence is not None:
            v = np.asarray(self.confidence, dtype=np.float32)
            if v.shape != (n,):
                raise InputError(f"point cloud: confidence of shape {v.shape}, expected ({n},)")
            self.confidence = v
        if self.system is not None:
            s = np.asarray(self.system)
            if s.shape != (n,) or (s.size and (s.min() < 0 or s.max() > 65535)):
                raise InputError(f"point cloud: system ids must be ({n},) integers in 0..65535")
            self.system = s.astype(np.uint16)

    def __len__(self) -> int:
        return len(self.xyz)

    def subset(self, index) -> PointCloud:
        return PointCloud(
            self.xyz[index],
            None if self.rgb is None else self.rgb[index],
            None if self.confidence is None else self.confidence[index],
            None if self.system is None else self.system[index],
            self.crs,
            list(self.systems),
        )


# ------------------------------------------------------------------ merge and thin


def thin_voxel(cloud: PointCloud, voxel: float) -> PointCloud:
    """Keep the most confident point of every ``voxel`` x ``voxel`` x ``voxel`` cell (metres).

    Without confidence the first point of each cell is kept.
    """
    if not (math.isfinite(voxel) and voxel > 0):
        raise InputError(f"voxel size must be a positive number of metres, got {voxel!r}")
    if len(cloud) == 0:
        return cloud
    key = np.floor((cloud.xyz - cloud.xyz.min(axis=0)) / voxel).astype(np.int64)
    order = (
        np.argsort(-cloud.confidence, kind="stable")
        if cloud.confidence is not None
        else np.arange(len(cloud))
    )
    _, first = np.unique(key[order], axis=0, return_index=True)
    return cloud.subset(np.sort(order[first]))


def merge_point_clouds(clouds, voxel: float | None = None) -> PointCloud:
    """Merge the point clouds of several reference systems into one.

    Parameters
    ----------
    clouds : sequence of PointCloud
        Same CRS (or None). A cloud without ``system`` ids takes the id of its single
        entry in ``systems``, else its position in the sequence.
    voxel : float, optional
        Thin duplicates on a voxel grid of this size (metres), keeping the most
        confident point of every voxel.

    Returns
    -------
    PointCloud
        With ``system`` ids, the union of the ``systems`` tables, and confidence / colour
        where every input has them (else 1.0 / grey 128 for the inputs lacking them).
    """
    clouds = list(clouds)
    if not clouds:
        raise InputError("merge: no point clouds given")
    for c in clouds:
        if not isinstance(c, PointCloud):
            raise InputError(f"merge: expected PointCloud objects, got {type(c).__name__}")
    crs = {c.crs for c in clouds if c.crs is not None}
    if len(crs) > 1:
        from ..geometry.frame import parse_crs

        if len({parse_crs(c).to_wkt() for c in crs}) > 1:
            raise InputError(
                f"merge: the point clouds have different CRSs {sorted(crs)}; reproject them first"
            )
    systems: dict[int, ReferenceSystem] = {}
    sys_ids = []
    for k, c in enumerate(clouds):
        for s in c.systems:
            systems.setdefault(int(s.id), s)
        if c.system is not None:
            sys_ids.append(c.system)
        else:
            sid = c.systems[0].id if len(c.systems) == 1 else k
            systems.setdefault(int(sid), ReferenceSystem(int(sid)))
            sys_ids.append(np.full(len(c), sid, np.uint16))
    has_rgb = any(c.rgb is not None for c in clouds)
    has_conf = any(c.confidence is not None for c in clouds)
    merged = PointCloud(
        np.concatenate([c.xyz for c in clouds]),
        np.concatenate([c.rgb if c.rgb is not None else np.full((len(c), 3), 128, np.uint8) for c in clouds])
        if has_rgb
        else None,
        np.concatenate(
            [c.confidence if c.confidence is not None else np.ones(len(c), np.float32) for c in clouds]
        )
        if has_conf
        else None,
        np.concatenate(sys_ids),
        next(iter(crs)) if crs else None,
        [systems[k] for k in sorted(systems)],
    )
    return thin_voxel(merged, voxel) if voxel else merged


# ------------------------------------------------------------------ files


def _systems_vlr(systems: list[ReferenceSystem]) -> list[tuple[str, int, str, bytes]]:
    if not systems:
        return []
    data = json.dumps([s.as_dict() for s in systems]).encode("utf-8")
    return [(SYSTEMS_VLR[0], SYSTEMS_VLR[1], "reference systems (JSON)", data)]


def write_point_cloud_file(
    path, cloud: PointCloud, ept_folder=None, scale: float = 0.001, progress: Progress | None = None
) -> dict:
    """Write a point cloud as LAS 1.4 / LAZ (by extension), and optionally as EPT.

    Parameters
    ----------
    path : str or os.PathLike
        ``.las`` or ``.laz``.
    cloud : PointCloud
    ept_folder : str or os.PathLike, optional
        Also write an Entwine Point Tile dataset there (``ept_folder/ept.json`` opens in
        QGIS without PDAL).
    scale : float
        Coordinate resolution, metres.

    Returns
    -------
    dict with ``points``, ``path`` and ``ept`` (path of ept.json or None).
    """
    from ..rasterio_io import PointCloudWriter

    if not isinstance(cloud, PointCloud):
        raise InputError(f"{path}: expected a PointCloud, got {type(cloud).__name__}")
    extra, dims = _extra(cloud)
    steps = Steps(as_progress(progress), [1, 2 if ept_folder else 0])
    with PointCloudWriter(
        path, cloud.crs, cloud.rgb is not None, dims, scale=scale, vlrs=_systems_vlr(cloud.systems)
    ) as w:
        for a in range(0, max(len(cloud), 1), 1_000_000):
            check(steps.parent)
            b = min(a + 1_000_000, len(cloud))
            w.write(
                cloud.xyz[a:b],
                None if cloud.rgb is None else cloud.rgb[a:b],
                **{k: v[a:b] for k, v in extra.items()},
            )
            steps[0].update(b / max(len(cloud), 1), "writing the point cloud")
    ept = None
    if ept_folder is not None:
        from .ept import write_ept

        ept = write_ept(
            ept_folder,
            cloud.xyz,
            cloud.rgb,
            extra,
            cloud.crs,
            scale=scale,
            priority=cloud.confidence,
            progress=steps[1],
        )
    return {"points": len(cloud), "path": str(path), "ept": None if ept is None else str(ept)}


class PointCloudFile:
    """One LAS/LAZ file written from several :class:`PointCloud` chunks (bounded memory).

    Every chunk must have what the file was opened for: colours when ``rgb``, confidence
    and system ids when ``confidence`` / ``system``. Use as a context manager; the file is
    renamed into place when the block ends without an error (:class:`PointCloudWriter`)::

        with PointCloudFile(path, crs, systems) as f:
            for cloud in chunks:
                f.add(cloud)
    """

    def __init__(
        self,
        path,
        crs: str | None,
        systems: list[ReferenceSystem],
        rgb: bool = True,
        confidence: bool = True,
        system: bool = True,
        scale: float = 0.001,
    ) -> None:
        from ..rasterio_io import PointCloudWriter

        dims: dict[str, np.dtype] = {}
        if confidence:
            dims[CONFIDENCE] = np.dtype(np.float32)
        if system:
            dims[SYSTEM] = np.dtype(np.uint16)
        self._dims = dims
        self._rgb = bool(rgb)
        self._writer = PointCloudWriter(path, crs, self._rgb, dims, scale=scale, vlrs=_systems_vlr(systems))

    @property
    def count(self) -> int:
        return int(self._writer.count)

    def __enter__(self) -> PointCloudFile:
        self._writer.__enter__()
        return self

    def add(self, cloud: PointCloud) -> None:
        if len(cloud) == 0:
            return
        extra, _ = _extra(cloud)
        if set(extra) != set(self._dims) or (cloud.rgb is not None) != self._rgb:
            raise InputError(
                f"{self._writer.path}: a chunk with {sorted(extra)} and rgb={cloud.rgb is not None}, "
                f"but the file holds {sorted(self._dims)} and rgb={self._rgb}"
            )
        for a in range(0, len(cloud), 1_000_000):
            b = min(a + 1_000_000, len(cloud))
            self._writer.write(
                cloud.xyz[a:b],
                None if cloud.rgb is None else cloud.rgb[a:b],
                **{k: v[a:b] for k, v in extra.items()},
            )

    def __exit__(self, exc_type, exc, tb) -> None:
        self._writer.__exit__(exc_type, exc, tb)


def _extra(cloud: PointCloud) -> tuple[dict[str, np.ndarray], dict[str, np.dtype]]:
    extra: dict[str, np.ndarray] = {}
    if cloud.confidence is not None:
        extra[CONFIDENCE] = cloud.confidence.astype(np.float32)
    if cloud.system is not None:
        extra[SYSTEM] = cloud.system.astype(np.uint16)
    return extra, {k: v.dtype for k, v in extra.items()}


def read_point_cloud(path) -> PointCloud:
    """Read a LAS/LAZ file (or an EPT ``ept.json``) written by TruOrtho or any LAS 1.x writer.

    16-bit colours are reduced to 8 bits; ``confidence`` and ``system`` extra
    dimensions and the reference-system VLR are read when present.
    """
    from ..rasterio_io import read_point_cloud_arrays

    p = Path(os.fspath(path))
    if p.name == "ept.json" or p.is_dir():
        from .ept import read_ept

        d = read_ept(p)
        crs = d["info"].get("srs", {}).get("wkt") or None
        vlrs: dict = {}
    else:
        d = read_point_cloud_arrays(p)
        crs = d["crs"]
        vlrs = d["vlrs"]
    rgb = d["rgb"]
    if rgb is not None:
        rgb = np.asarray(rgb)
        rgb = (rgb // 257 if np.all(rgb % 257 == 0) else rgb >> 8).astype(np.uint8)
    systems = []
    raw = vlrs.get(SYSTEMS_VLR)
    if raw:
        try:
            systems = [
                ReferenceSystem(
                    int(s["id"]),
                    str(s.get("name", "")),
                    None if s.get("view_direction") is None else tuple(s["view_direction"]),
                )
                for s in json.loads(raw.rstrip(b"\0").decode("utf-8"))
            ]
        except (ValueError, KeyError, TypeError) as exc:
            raise FormatError(p, f"bad TruOrtho reference-system record ({exc})") from None
    extra = d["extra"]
    return PointCloud(d["xyz"], rgb, extra.get(CONFIDENCE), extra.get(SYSTEM), crs, systems)


# ------------------------------------------------------------------ DSM -> point cloud


def dsm_to_point_cloud(
    dsm_path,
    output_path,
    ortho_path=None,
    confidence_path=None,
    ept_folder=None,
    system: ReferenceSystem | None = None,
    tile: int = 1024,
    progress: Progress | None = None,
) -> dict:
    """One point per valid DSM cell centre, written as LAS/LAZ (and optionally EPT).

    Parameters
    ----------
    dsm_path : str or os.PathLike
        Single-band DSM with a projected CRS.
    output_path : str or os.PathLike
        ``.las`` or ``.laz``.
    ortho_path : str or os.PathLike, optional
        RGB orthoimage for the point colours (resampled onto the DSM grid).
    confidence_path : str or os.PathLike, optional
        Confidence raster in [0, 1] (OSGM's), resampled onto the DSM grid.
    ept_folder : str or os.PathLike, optional
        Also write an EPT dataset (built in memory: at most
        :data:`~.ept.MAX_EPT_POINTS` cells).
    system : ReferenceSystem, optional
        The reference system of the DSM (default id 0, "nadir DSM", looking down).

    Returns
    -------
    dict with ``points``, ``path``, ``ept``.
    """
    from ..geometry.frame import parse_crs, require_metric
    from ..rasterio_io import PointCloudWriter, raster_grid, read_onto_grid, read_raster
    from ._raster import colours_on_grid
    from .ept import MAX_EPT_POINTS, write_ept

    grid = raster_grid(dsm_path, require_crs=True)
    require_metric(parse_crs(grid.crs), f"DSM {dsm_path}")
    if ept_folder is not None and grid.rows * grid.cols > MAX_EPT_POINTS:
        raise InputError(
            f"DSM {dsm_path}: {grid.rows * grid.cols:,} cells exceed the {MAX_EPT_POINTS:,} points an EPT "
            "dataset is built for in memory; export without EPT or from a coarser DSM"
        )
    ortho_grid = raster_grid(ortho_path, require_crs=True) if ortho_path is not None else None
    if confidence_path is not None:
        raster_grid(confidence_path, require_crs=True)
    sysref = system or ReferenceSystem(0, "nadir DSM", (0.0, 0.0, -1.0))
    dims = (
        {CONFIDENCE: np.dtype(np.float32), SYSTEM: np.dtype(np.uint16)}
        if confidence_path is not None
        else {SYSTEM: np.dtype(np.uint16)}
    )
    steps = Steps(as_progress(progress), [3, 1 if ept_folder is not None else 0])
    keep: dict[str, list[np.ndarray]] = {"xyz": [], "rgb": [], CONFIDENCE: [], SYSTEM: []}
    tiles = grid.tiles(tile, 0)
    x0, y0, _, _ = grid.extent
    with PointCloudWriter(
        output_path,
        grid.crs,
        ortho_path is not None,
        dims,
        offsets=(math.floor(x0), math.floor(y0), 0.0),
        vlrs=_systems_vlr([sysref]),
    ) as w:
        for n, t in enumerate(tiles):
            check(steps.parent)
            z, _, _ = read_raster(dsm_path, 1, t.core)
            z = z.astype(np.float64)
            ok = np.isfinite(z)
            g = t.core_grid(grid)
            X, Y = g.centres()
            xyz = np.column_stack([X[ok], Y[ok], z[ok]])
            rgb = None
            if ortho_grid is not None:
                rgb = np.clip(np.round(colours_on_grid(ortho_path, g, ortho_grid)[ok]), 0, 255).astype(
                    np.uint8
                )
            extra = {SYSTEM: np.full(len(xyz), sysref.id, np.uint16)}
            if confidence_path is not None:
                c = read_onto_grid(confidence_path, g, resampling="nearest")
                extra[CONFIDENCE] = np.clip(np.nan_to_num(c[ok], nan=0.0), 0.0, 1.0).astype(np.float32)
            w.write(xyz, rgb, **extra)
            if ept_folder is not None:
                keep["xyz"].append(xyz)
                if rgb is not None:
                    keep["rgb"].append(rgb)
                for k, v in extra.items():
                    keep[k].append(v)
            steps[0].update((n + 1) / len(tiles), f"DSM to points: tile {n + 1}/{len(tiles)}")
        count = w.count
        if count == 0:
            raise InputError(f"DSM {dsm_path}: every cell is nodata; no points to write")
        ept = None
        if ept_folder is not None:
            xyz_all = np.concatenate(keep["xyz"])
            extra_all = {k: np.concatenate(keep[k]) for k in dims}
            ept = write_ept(
                ept_folder,
                xyz_all,
                np.concatenate(keep["rgb"]) if keep["rgb"] else None,
                extra_all,
                grid.crs,
                priority=extra_all.get(CONFIDENCE),
                progress=steps[1],
            )
    return {"points": int(count), "path": str(output_path), "ept": None if ept is None else str(ept)}
