"""COLMAP text models (``cameras.txt``, ``images.txt``, ``points3D.txt``).

Conventions (see :mod:`truortho.core.geometry`): COLMAP's ``QW QX QY QZ`` is
the Hamilton quaternion of the world-to-camera rotation and ``T`` the
translation of ``X_cam = R X + T``, so ``C = -R^T T``. Camera axes are ours.
COLMAP puts the top-left pixel *corner* at (0, 0): principal points and
observations are shifted by -0.5 px on import and +0.5 px on export.

Georeferencing: a ``georef.json`` beside the model,
``{"crs": "EPSG:25832", "offset": [E, N, H]}``, states that COLMAP's world
frame is ``CRS - offset``, i.e. our local frame. Without it the model is
unreferenced (``crs=None``, offset 0). The optional ``camera_names`` map
(COLMAP id -> name) written by :func:`write_colmap` restores camera ids.

Supported camera models: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL,
OPENCV and FULL_OPENCV (the latter only with ``k4 = k5 = k6 = 0``, which is
how :func:`write_colmap` stores a camera with ``k3``).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from ..errors import FormatError, InputError
from ..geometry.camera import Camera
from ..geometry.frame import LocalFrame, crs_to_text, parse_crs, require_metric
from ..geometry.rotation import matrix_to_quaternion, quaternion_to_matrix
from ..orientation import Image, Orientation, SparsePoints, atomic_write_text
from ._text import (
    ValueReader,
    check_name,
    data_lines,
    fmt,
    load_json,
    numbered_lines,
    parse_float,
    parse_int,
    read_text,
)

# model -> parameter names in file order (fx == fy for "f")
MODELS: dict[str, tuple[str, ...]] = {
    "SIMPLE_PINHOLE": ("f", "cx", "cy"),
    "PINHOLE": ("fx", "fy", "cx", "cy"),
    "SIMPLE_RADIAL": ("f", "cx", "cy", "k1"),
    "RADIAL": ("f", "cx", "cy", "k1", "k2"),
    "OPENCV": ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2"),
    "FULL_OPENCV": ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"),
}
_MODEL_IDS = {
    "0": "SIMPLE_PINHOLE",
    "1": "PINHOLE",
    "2": "SIMPLE_RADIAL",
    "3": "RADIAL",
    "4": "OPENCV",
    "6": "FULL_OPENCV",
}


def _read_georef(georef: object, folder: Path) -> tuple[str | None, np.ndarray, dict]:
    if georef is None:
        cand = folder / "georef.json"
        if not cand.is_file():
            return None, np.zeros(3), {}
        georef = cand
    if isinstance(georef, dict):
        src: object = "georef"
        d: object = georef
    else:
        src = georef
        d = load_json(georef, "georef.json")  # type: ignore[arg-type]
    r = ValueReader(src)
    g = r.obj(d, "top level")
    crs = g.get("crs")
    if crs is not None:
        pc = parse_crs(r.text(crs, "crs"))
        require_metric(pc, f"{src}: CRS")
        crs = crs_to_text(pc)
    offset = np.array(r.vec(g.get("offset", [0.0, 0.0, 0.0]), 3, "offset"))
    names = g.get("camera_names") or {}
    names = {str(k): r.text(v, f"camera_names.{k}") for k, v in r.obj(names, "camera_names").items()}
    return crs, offset, names


def _read_cameras(path: Path, names: dict) -> tuple[dict[str, Camera], dict[str, str]]:
    text = read_text(path, "COLMAP cameras.txt")
    cameras: dict[str, Camera] = {}
    id_map: dict[str, str] = {}
    for n, line in data_lines(text):
        tok = line.split()
        if len(tok) < 4:
            raise FormatError(path, "expected 'CAMERA_ID MODEL WIDTH HEIGHT PARAMS...'", line=n)
        cid = str(parse_int(tok[0], path, n, "CAMERA_ID"))
        model = _MODEL_IDS.get(tok[1], tok[1].upper())
        if model not in MODELS:
            raise FormatError(
                path, f"unsupported camera model {tok[1]!r}; supported: {', '.join(MODELS)}", line=n
            )
        w = parse_int(tok[2], path, n, "WIDTH")
        h = parse_int(tok[3], path, n, "HEIGHT")
        keys = MODELS[model]
        if len(tok) != 4 + len(keys):
            raise FormatError(
                path,
                f"model {model} expects {len(keys)} parameters ({', '.join(keys)}), got {len(tok) - 4}",
                line=n,
            )
        vals = {k: parse_float(t, path, n, k) for k, t in zip(keys, tok[4:], strict=False)}
        if any(vals.get(k, 0.0) != 0.0 for k in ("k4", "k5", "k6")):
            raise FormatError(
                path, "FULL_OPENCV with nonzero k4, k5, k6 (rational model) is not supported", line=n
            )
        if cid in id_map:
            raise FormatError(path, f"CAMERA_ID {cid} appears twice", line=n)
        name = names.get(cid, cid)
        f = vals.get("f", 0.0)
        try:
            cam = Camera(
                w,
                h,
                vals.get("fx", f),
                vals.get("fy", f),
                vals["cx"] - 0.5,
                vals["cy"] - 0.5,
                vals.get("k1", 0.0),
                vals.get("k2", 0.0),
                vals.get("k3", 0.0),
                vals.get("p1", 0.0),
                vals.get("p2", 0.0),
                id=name,
            )
        except InputError as err:
            raise FormatError(path, str(err), line=n) from None
        if name in cameras:
            raise FormatError(path, f"camera name {name!r} appears twice", line=n)
        id_map[cid] = name
        cameras[name] = cam
    return cameras, id_map


def _read_points(path: Path) -> tuple[dict[int, int], list, list, list]:
    text = read_text(path, "COLMAP points3D.txt")
    index: dict[int, int] = {}
    xyz: list[list[float]] = []
    rgb: list[list[float]] = []
    err: list[float] = []
    for n, line in data_lines(text):
        tok = line.split()
        if len(tok) < 8 or (len(tok) - 8) % 2:
            raise FormatError(
                path, "expected 'POINT3D_ID X Y Z R G B ERROR (IMAGE_ID POINT2D_IDX)...'", line=n
            )
        pid = parse_int(tok[0], path, n, "POINT3D_ID")
        if pid in index:
            raise FormatError(path, f"POINT3D_ID {pid} appears twice", line=n)
        index[pid] = len(xyz)
        xyz.append([parse_float(t, path, n, a) for t, a in zip(tok[1:4], "XYZ", strict=False)])
        c = [parse_float(t, path, n, a) for t, a in zip(tok[4:7], "RGB", strict=False)]
        if any(not 0 <= v <= 255 for v in c):
            raise FormatError(path, f"colour must be 0..255, got {tok[4:7]}", line=n)
        rgb.append(c)
        err.append(parse_float(tok[7], path, n, "ERROR"))
    return index, xyz, rgb, err


def read_colmap(folder: str | os.PathLike, georef: str | os.PathLike | dict | None = None) -> Orientation:
    """Read a COLMAP text model.

    Parameters
    ----------
    folder : path
        Folder with ``cameras.txt``, ``images.txt`` and optionally ``points3D.txt``.
    georef : path or dict, optional
        Georeferencing ``{"crs": ..., "offset": [E, N, H]}``; default: ``georef.json``
        in ``folder`` when present.

    Returns
    -------
    Orientation
        Image names (and paths) are COLMAP's ``NAME``; tie-point observations are
        those of ``images.txt`` whose POINT3D_ID exists in ``points3D.txt``.

    Raises
    ------
    FormatError, MissingFileError, CRSError
    """
    folder = Path(folder)
    crs, offset, names = _read_georef(georef, folder)
    cameras, id_map = _read_cameras(folder / "cameras.txt", names)
    pts_path = folder / "points3D.txt"
    p_index: dict[int, int] = {}
    xyz: list[list[float]] = []
    rgb: list[list[float]] = []
    perr: list[float] = []
    if pts_path.is_file():
        p_index, xyz, rgb, perr = _read_points(pts_path)

    path = folder / "images.txt"
    text = read_text(path, "COLMAP images.txt")
    images: list[Image] = []
    seen_ids: set[int] = set()
    obs_p: list[int] = []
    obs_i: list[int] = []
    obs_xy: list[list[float]] = []
    lines = numbered_lines(text)
    for n, raw in lines:
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        tok = line.split(maxsplit=9)
        if len(tok) != 10:
            raise FormatError(path, "expected 'IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME'", line=n)
        iid = parse_int(tok[0], path, n, "IMAGE_ID")
        if iid in seen_ids:
            raise FormatError(path, f"IMAGE_ID {iid} appears twice", line=n)
        seen_ids.add(iid)
        q = [parse_float(t, path, n, a) for t, a in zip(tok[1:5], ("QW", "QX", "QY", "QZ"), strict=False)]
        t = np.array([parse_float(v, path, n, a) for v, a in zip(tok[5:8], ("TX", "TY", "TZ"), strict=False)])
        cid = str(parse_int(tok[8], path, n, "CAMERA_ID"))
        if cid not in id_map:
            raise FormatError(path, f"CAMERA_ID {cid} is not in cameras.txt", line=n)
        name = check_name(tok[9].strip(), path, n)
        try:
            R = quaternion_to_matrix(q)
            images.append(Image(name, id_map[cid], R, -R.T @ t, name))
        except InputError as err:
            raise FormatError(path, str(err), line=n) from None
        n2, pline = next(lines, (n + 1, ""))
        ptok = pline.split()
        if len(ptok) % 3:
            raise FormatError(
                path, "expected POINTS2D triplets 'X Y POINT3D_ID' for the image above", line=n2
            )
        for k in range(0, len(ptok), 3):
            pid = parse_int(ptok[k + 2], path, n2, "POINT3D_ID")
            x = parse_float(ptok[k], path, n2, "X")
            y = parse_float(ptok[k + 1], path, n2, "Y")
            if pid != -1 and pid in p_index:
                obs_p.append(p_index[pid])
                obs_i.append(len(images) - 1)
                obs_xy.append([x - 0.5, y - 0.5])
    points = None
    if xyz:
        points = SparsePoints(
            np.array(xyz),
            np.array(rgb),
            np.array(perr),
            np.array(obs_p, np.int64),
            np.array(obs_i, np.int64),
            np.array(obs_xy).reshape(-1, 2),
        )
    o = Orientation(LocalFrame(crs, offset), cameras, images, points)
    try:
        o.validate()
    except InputError as err:
        raise FormatError(path, str(err)) from None
    o.metadata["source"] = {"format": "colmap", "folder": str(folder)}
    return o


def _check_token(s: str, what: str) -> str:
    if not s or any(c in s for c in "\r\n") or s != s.strip():
        raise InputError(f"{what} {s!r} cannot be written to a COLMAP text file")
    return s


def write_colmap(orientation: Orientation, folder: str | os.PathLike) -> None:
    """Write ``cameras.txt``, ``images.txt``, ``points3D.txt`` and ``georef.json``.

    Cameras get COLMAP ids 1..n (names kept in ``georef.json``), images ids
    1..n in order; a camera with ``k3`` is written as FULL_OPENCV, with other
    distortion as OPENCV, without as PINHOLE. Image ``NAME`` is the image path.
    """
    folder = Path(folder)
    o = orientation
    o.validate()
    cam_ids = {name: i + 1 for i, name in enumerate(o.cameras)}
    lines = [
        "# Camera list with one line of data per camera:",
        "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]",
        f"# Number of cameras: {len(o.cameras)}",
    ]
    for name, c in o.cameras.items():
        base = [c.fx, c.fy, c.cx + 0.5, c.cy + 0.5]
        if c.k3 != 0.0:
            model, params = "FULL_OPENCV", base + [c.k1, c.k2, c.p1, c.p2, c.k3, 0.0, 0.0, 0.0]
        elif c.has_distortion:
            model, params = "OPENCV", base + [c.k1, c.k2, c.p1, c.p2]
        else:
            model, params = "PINHOLE", base
        lines.append(
            " ".join([str(cam_ids[name]), model, str(c.width), str(c.height)] + [fmt(v) for v in params])
        )
    cameras_txt = "\n".join(lines) + "\n"

    pts = o.points
    per_image: list[list[tuple[float, float, int]]] = [[] for _ in o.images]
    tracks: list[list[tuple[int, int]]] = [[] for _ in range(len(pts) if pts is not None else 0)]
    if pts is not None:
        for p, i, (x, y) in zip(pts.obs_point, pts.obs_image, pts.obs_xy, strict=False):
            tracks[p].append((int(i) + 1, len(per_image[i])))
            per_image[i].append((x + 0.5, y + 0.5, int(p) + 1))
    lines = [
        "# Image list with two lines of data per image:",
        "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME",
        "#   POINTS2D[] as (X, Y, POINT3D_ID)",
        f"# Number of images: {len(o.images)}",
    ]
    for i, im in enumerate(o.images):
        q = matrix_to_quaternion(im.R)
        t = im.t
        name = _check_token(im.path or im.name, "image name")
        lines.append(
            " ".join(
                [str(i + 1)] + [fmt(v) for v in q] + [fmt(v) for v in t] + [str(cam_ids[im.camera]), name]
            )
        )
        lines.append(" ".join(f"{fmt(x)} {fmt(y)} {p}" for x, y, p in per_image[i]))
    images_txt = "\n".join(lines) + "\n"

    lines = [
        "# 3D point list with one line of data per point:",
        "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)",
    ]
    if pts is not None:
        rgb = pts.rgb if pts.rgb is not None else np.full((len(pts), 3), 128, np.uint8)
        err = pts.error if pts.error is not None else np.zeros(len(pts))
        for k in range(len(pts)):
            lines.append(
                " ".join(
                    [str(k + 1)]
                    + [fmt(v) for v in pts.xyz[k]]
                    + [str(int(v)) for v in rgb[k]]
                    + [fmt(err[k])]
                    + [f"{a} {b}" for a, b in tracks[k]]
                )
            )
    points_txt = "\n".join(lines) + "\n"

    georef = {
        "crs": o.crs,
        "offset": [float(v) for v in o.offset],
        "camera_names": {str(i): name for name, i in cam_ids.items()},
    }
    atomic_write_text(folder / "cameras.txt", cameras_txt)
    atomic_write_text(folder / "images.txt", images_txt)
    atomic_write_text(folder / "points3D.txt", points_txt)
    atomic_write_text(folder / "georef.json", json.dumps(georef, indent=1) + "\n")
