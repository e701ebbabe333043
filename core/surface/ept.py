"""Entwine Point Tile (EPT) datasets: an octree of LAZ nodes that QGIS opens without PDAL.

QGIS 3.22 as packaged by Debian has no PDAL provider, so it cannot open a
plain ``.las``/``.laz`` file as a point cloud layer; its ``ept`` provider
reads EPT (``QgsPointCloudLayer(".../ept.json", name, "ept")``). A dataset is

* ``ept.json``: ``version`` 1.0.0, ``bounds`` (the octree cube),
  ``boundsConforming`` (the data's bounding box), ``dataType`` ``laszip``,
  ``hierarchyType`` ``json``, ``points``, ``span``, ``schema`` (the
  dimensions with name, type and size; X, Y, Z with scale and offset, which
  readers apply to every node) and ``srs`` (``authority``, ``horizontal``
  and ``wkt``);
* ``ept-data/D-X-Y-Z.laz``: the points of octree node (depth, x, y, z), LAS
  1.4 point format 6/7 with the same scale, offset and extra dimensions;
* ``ept-hierarchy/0-0-0-0.json``: ``{"D-X-Y-Z": point count}`` of every
  node (one hierarchy file).

Octree: the root is the cube around the data; a node at depth ``d`` keeps
one point per cell of a ``span``\\ :sup:`3` grid over its cube (the point with
the highest priority, e.g. confidence) and passes the others to its eight
children; a node holding at most ``max_node_points`` points keeps them all
(a leaf). Every point is stored exactly once, and every node's parent
exists. The dataset is built in memory (the points' arrays); the folder is
written beside its destination and renamed into place when complete.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import FormatError, InputError
from ..progress import Progress, as_progress, check

#: more points than this are not indexed in memory (about 3 GB of temporaries)
MAX_EPT_POINTS = 60_000_000

_LAS_DIMS = [  # (name, type, size) of LAS 1.4 point formats 6/7 after X, Y, Z, as PDAL names them
    ("Intensity", "unsigned", 2),
    ("ReturnNumber", "unsigned", 1),
    ("NumberOfReturns", "unsigned", 1),
    ("ScanChannel", "unsigned", 1),
    ("ScanDirectionFlag", "unsigned", 1),
    ("EdgeOfFlightLine", "unsigned", 1),
    ("Classification", "unsigned", 1),
    ("UserData", "unsigned", 1),
    ("ScanAngleRank", "float", 4),
    ("PointSourceId", "unsigned", 2),
    ("GpsTime", "float", 8),
]


def _type_of(dt: np.dtype) -> tuple[str, int]:
    kind = {"f": "float", "u": "unsigned", "i": "signed"}.get(dt.kind)
    if kind is None:
        raise InputError(f"EPT: unsupported dimension type {dt}")
    return kind, dt.itemsize


def octree_nodes(
    xyz: np.ndarray,
    cube_min: np.ndarray,
    cube_size: float,
    span: int,
    max_node_points: int,
    priority: np.ndarray | None = None,
    max_depth: int = 24,
) -> tuple[np.ndarray, np.ndarray]:
    """Assign every point to an octree node.

    Parameters
    ----------
    xyz : (N, 3) float64
    cube_min : (3,) float64
        Lower corner of the root cube.
    cube_size : float
        Side of the root cube.
    span : int
        Voxel grid side per node.
    max_node_points : int
        A node with at most this many points keeps them all.
    priority : (N,) float, optional
        Higher keeps a point in a shallower node (default: input order).

    Returns
    -------
    depth : (N,) int64
    key : (N, 3) int64
        Node (x, y, z) index at its depth.
    """
    n = len(xyz)
    depth = np.full(n, -1, np.int64)
    key = np.zeros((n, 3), np.int64)
    order = np.arange(n) if priority is None else np.argsort(-np.asarray(priority), kind="stable")
    rel = (xyz[order] - cube_min) / cube_size  # in [0, 1]
    remaining = np.arange(n)  # positions in `order`
    for d in range(max_depth + 1):
        if not len(remaining):
            break
        cells = 1 << d
        r = rel[remaining]
        nk = np.clip(np.floor(r * cells).astype(np.int64), 0, cells - 1)
        node_id = (nk[:, 0] * cells + nk[:, 1]) * cells + nk[:, 2]
        uniq, inv, counts = np.unique(node_id, return_inverse=True, return_counts=True)
        leaf = counts[inv] <= max_node_points
        if d == max_depth:
            leaf[:] = True
        vk = np.clip(np.floor(r * cells * span).astype(np.int64), 0, cells * span - 1)
        vid = (vk[:, 0] * (cells * span) + vk[:, 1]) * (cells * span) + vk[:, 2]
        # first point (highest priority: `remaining` is in priority order) of each voxel
        _, first = np.unique(vid, return_index=True)
        keep = leaf.copy()
        keep[first] = True
        idx = order[remaining[keep]]
        depth[idx] = d
        key[idx] = nk[keep]
        remaining = remaining[~keep]
    return depth, key


def write_ept(
    folder,
    xyz: np.ndarray,
    rgb: np.ndarray | None = None,
    extra: dict[str, np.ndarray] | None = None,
    crs: str | None = None,
    scale: float = 0.001,
    span: int = 128,
    max_node_points: int = 100_000,
    priority: np.ndarray | None = None,
    data_type: str = "binary",
    progress: Progress | None = None,
) -> Path:
    """Write an EPT dataset (see the module docstring) into ``folder`` (replaced atomically).

    Parameters
    ----------
    folder : str or os.PathLike
        Destination folder; ``folder/ept.json`` is the file QGIS opens.
    xyz : (N, 3) float64
        World coordinates.
    rgb : (N, 3) uint8 or uint16, optional
    extra : dict name -> (N,) array, optional
        Extra dimensions (e.g. ``confidence`` float32, ``system`` uint16).
    crs : str, optional
        Written as ``srs`` (WKT, and the EPSG code when it has one).
    scale : float
        Coordinate resolution of the nodes, metres.
    span : int
        Voxel grid side of a node (EPT's ``span``).
    max_node_points : int
        Nodes with at most this many points are leaves.
    priority : (N,) float, optional
        Points kept in the shallow (overview) nodes first, e.g. the confidence.

    Returns
    -------
    Path of ``ept.json``.
    """
    from ..rasterio_io import PointCloudWriter

    prog = as_progress(progress)
    dest = Path(os.fspath(folder))
    pts = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
    n = len(pts)
    if n == 0:
        raise InputError(f"EPT {dest}: no points to write")
    if n > MAX_EPT_POINTS:
        raise InputError(
            f"EPT {dest}: {n:,} points exceed the in-memory limit of {MAX_EPT_POINTS:,}; "
            "use a coarser resolution or thin the cloud (voxel size)"
        )
    if not np.all(np.isfinite(pts)):
        raise InputError(f"EPT {dest}: point coordinates must be finite")
    if span < 16 or span & (span - 1):
        raise InputError(f"EPT {dest}: span must be a power of two of at least 16, got {span}")
    if data_type not in ("laszip", "binary"):
        raise InputError(f"EPT {dest}: data type must be 'laszip' or 'binary', got {data_type!r}")
    extra = {k: np.asarray(v) for k, v in (extra or {}).items()}
    rec_fields = [(ax, "<i4") for ax in "XYZ"]
    if rgb is not None:
        rec_fields += [(c, "<u2") for c in ("Red", "Green", "Blue")]
    rec_fields += [(k, v.dtype.newbyteorder("<")) for k, v in extra.items()]
    rec_dtype = np.dtype(rec_fields)
    for k, v in extra.items():
        if v.shape != (n,):
            raise InputError(f"EPT {dest}: extra dimension {k!r} has shape {v.shape}, expected ({n},)")
    lo = pts.min(axis=0)
    hi = pts.max(axis=0)
    size = float(max(hi - lo)) * 1.0001 + 4 * scale
    centre = (lo + hi) / 2
    cube_min = centre - size / 2
    offsets = np.round(centre / scale) * scale
    depth, key = octree_nodes(pts, cube_min, size, span, max_node_points, priority)
    check(prog)
    node = np.column_stack([depth, key])
    order = np.lexsort((node[:, 3], node[:, 2], node[:, 1], node[:, 0]))
    node_s = node[order]
    change = np.nonzero(np.any(np.diff(node_s, axis=0) != 0, axis=1))[0] + 1
    starts = np.concatenate([[0], change])
    ends = np.concatenate([change, [n]])
    tmp = dest.with_name(f".{dest.name}.tmp{os.getpid()}")
    if tmp.exists():
        shutil.rmtree(tmp)
    (tmp / "ept-data").mkdir(parents=True)
    (tmp / "ept-hierarchy").mkdir()
    try:
        hierarchy: dict[str, int] = {}
        dtypes = {k: v.dtype for k, v in extra.items()}
        for m, (a, b) in enumerate(zip(starts, ends, strict=True)):
            check(prog)
            idx = order[a:b]
            d, x, y, z = (int(v) for v in node_s[a])
            name = f"{d}-{x}-{y}-{z}"
            hierarchy[name] = int(b - a)
            if data_type == "laszip":
                with PointCloudWriter(
                    tmp / "ept-data" / f"{name}.laz",
                    crs,
                    rgb is not None,
                    dtypes,
                    offsets=offsets,
                    scale=scale,
                    legacy=True,
                ) as w:
                    w.write(
                        pts[idx],
                        None if rgb is None else np.asarray(rgb)[idx],
                        **{k: v[idx] for k, v in extra.items()},
                    )
            else:
                rec = np.zeros(len(idx), dtype=rec_dtype)
                for i, ax in enumerate("XYZ"):
                    rec[ax] = np.round((pts[idx, i] - offsets[i]) / scale).astype(np.int32)
                if rgb is not None:
                    c = np.asarray(rgb)[idx]
                    c16 = c.astype(np.uint16) * 257 if c.dtype == np.uint8 else c.astype(np.uint16)
                    rec["Red"], rec["Green"], rec["Blue"] = c16[:, 0], c16[:, 1], c16[:, 2]
                for k, v in extra.items():
                    rec[k] = v[idx]
                (tmp / "ept-data" / f"{name}.bin").write_bytes(rec.tobytes())
            prog.update((m + 1) / len(starts), f"EPT: node {m + 1}/{len(starts)}")
        schema = [
            {"name": ax, "type": "signed", "size": 4, "scale": scale, "offset": float(offsets[i])}
            for i, ax in enumerate("XYZ")
        ]
        if data_type == "laszip":
            schema += [{"name": nm, "type": t, "size": sz} for nm, t, sz in _LAS_DIMS]
        if rgb is not None:
            schema += [{"name": c, "type": "unsigned", "size": 2} for c in ("Red", "Green", "Blue")]
        for k, dt in dtypes.items():
            t, sz = _type_of(dt)
            entry: dict = {"name": k, "type": t, "size": sz}
            v = extra[k]
            if v.size:
                entry.update({"minimum": float(v.min()), "maximum": float(v.max())})
            schema.append(entry)
        doc = {
            "version": "1.0.0",
            "bounds": [float(v) for v in np.concatenate([cube_min, cube_min + size])],
            "boundsConforming": [float(v) for v in np.concatenate([lo, hi])],
            "dataType": data_type,
            "hierarchyType": "json",
            "points": int(n),
            "schema": schema,
            "span": int(span),
            "srs": _srs(crs),
        }
        (tmp / "ept-hierarchy" / "0-0-0-0.json").write_text(json.dumps(hierarchy), encoding="utf-8")
        (tmp / "ept.json").write_text(json.dumps(doc, indent=1), encoding="utf-8")
        _replace_folder(tmp, dest)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
    return dest / "ept.json"


def _srs(crs: str | None) -> dict:
    if crs is None:
        return {}
    from ..geometry.frame import parse_crs

    c = parse_crs(crs)
    out: dict = {"wkt": c.to_wkt()}
    auth = c.to_authority(min_confidence=90)
    if auth:
        out["authority"], out["horizontal"] = auth[0], auth[1]
    return out


def _replace_folder(tmp: Path, dest: Path) -> None:
    """Move ``tmp`` onto ``dest``; an existing EPT folder there is replaced."""
    if dest.exists():
        if not dest.is_dir() or not ((dest / "ept.json").exists() or not any(dest.iterdir())):
            raise InputError(f"EPT {dest}: exists and is not an EPT dataset; choose another folder")
        old = dest.with_name(f".{dest.name}.old{os.getpid()}")
        os.replace(dest, old)
        try:
            os.replace(tmp, dest)
        except OSError:
            os.replace(old, dest)
            raise
        shutil.rmtree(old, ignore_errors=True)
    else:
        dest.parent.mkdir(parents=True, exist_ok=True)
        os.replace(tmp, dest)


def _binary_dtype(schema: list[dict]) -> np.dtype:
    kinds = {"signed": "i", "unsigned": "u", "float": "f"}
    return np.dtype([(d["name"], f"<{kinds[d['type']]}{d['size']}") for d in schema])


def read_ept(path) -> dict:
    """Read every node of an EPT dataset back (for tests and tools).

    Returns ``{"xyz", "rgb", "extra", "info" (ept.json), "hierarchy"}``.
    """
    from ..rasterio_io import read_point_cloud_arrays

    p = Path(os.fspath(path))
    root = p.parent if p.name == "ept.json" else p
    try:
        info = json.loads((root / "ept.json").read_text(encoding="utf-8"))
        hierarchy = json.loads((root / "ept-hierarchy" / "0-0-0-0.json").read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise FormatError(root, f"not an EPT dataset ({exc})") from None
    parts: list[dict[str, Any]] = []
    if info.get("dataType") == "binary":
        dt = _binary_dtype(info["schema"])
        names = list(dt.names or ())
        sc = {d["name"]: (d.get("scale", 1.0), d.get("offset", 0.0)) for d in info["schema"]}
        for name in sorted(hierarchy):
            rec = np.frombuffer((root / "ept-data" / f"{name}.bin").read_bytes(), dtype=dt)
            xyz = np.column_stack([rec[a] * sc[a][0] + sc[a][1] for a in "XYZ"])
            rgb = np.column_stack([rec[c] for c in ("Red", "Green", "Blue")]) if "Red" in names else None
            ext = {k: rec[k].copy() for k in names if k not in ("X", "Y", "Z", "Red", "Green", "Blue")}
            parts.append({"xyz": xyz, "rgb": rgb, "extra": ext})
    else:
        for name in sorted(hierarchy):
            parts.append(read_point_cloud_arrays(root / "ept-data" / f"{name}.laz"))
    xyz = np.concatenate([q["xyz"] for q in parts])
    rgb = np.concatenate([q["rgb"] for q in parts]) if parts and parts[0]["rgb"] is not None else None
    keys = list(parts[0]["extra"]) if parts else []
    extra = {k: np.concatenate([q["extra"][k] for q in parts]) for k in keys}
    return {"xyz": xyz, "rgb": rgb, "extra": extra, "info": info, "hierarchy": hierarchy}
