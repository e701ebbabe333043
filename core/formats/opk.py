"""Orthority frame-camera files: exterior CSV (x, y, z, omega, phi, kappa) + interior YAML/JSON.

Exterior CSV: a header row names the columns (case-insensitive; ``filename,
x, y, z, omega, phi, kappa`` required, ``camera`` optional, others ignored);
without a header the legacy order ``filename x y z omega phi kappa`` applies.
The delimiter is one of ``,`` ``;`` tab or spaces. Angles are degrees;
``M = Rx(omega) Ry(phi) Rz(kappa)`` rotates camera (x right, y up, z back) to
the CRS grid, which is exactly :func:`~truortho.core.geometry.opk_to_matrix`.
``filename`` is reduced to its base name (as Orthority does). The CRS comes
from the ``crs`` argument or a ``.prj`` sidecar with the CSV's stem.

Interior file (Orthority ``oty`` format), ``{camera_id: {type, im_size,
focal_len, sensor_size, cx, cy, k1, k2, p1, p2, k3}}`` or one flat dict:

* ``cx, cy``: principal-point offset from the image centre divided by
  ``m = max(w, h)``: ``cx_px = (w - 1) / 2 + m cx`` (pixel centres, as ours);
* ``focal_len`` (scalar or ``[fx, fy]``) with ``sensor_size [sw, sh]``:
  ``fx = f w / sw``, ``fy = f h / sh``; without ``sensor_size`` it is taken as
  normalised by ``m`` (Orthority's documentation; its code uses the width,
  which is the same for landscape images -- portrait images read without
  ``sensor_size`` get a warning in ``metadata["warnings"]``).

:func:`write_opk` always writes ``sensor_size = [w/m, h/m]`` with the focal
length normalised by ``m``, which both readings interpret identically.
"""

from __future__ import annotations

import csv
import json
import os
from pathlib import Path

import numpy as np

from ..errors import CRSError, FormatError, InputError
from ..geometry.camera import Camera
from ..geometry.frame import LocalFrame, choose_offset, crs_to_text, parse_crs, require_metric
from ..geometry.rotation import matrix_to_opk, opk_to_matrix
from ..orientation import Image, Orientation, atomic_write_text
from ._text import ValueReader, check_name, data_lines, fmt, parse_float, parse_json, read_text

try:  # PyYAML is optional: JSON interior files work without it
    import yaml  # type: ignore[import-untyped]
except ImportError:  # pragma: no cover - depends on the environment
    yaml = None

REQUIRED = ("filename", "x", "y", "z", "omega", "phi", "kappa")
_USED = {"pinhole": (), "brown": ("k1", "k2", "p1", "p2", "k3"), "opencv": ("k1", "k2", "p1", "p2", "k3")}
_OPENCV_UNSUPPORTED = ("k4", "k5", "k6", "s1", "s2", "s3", "s4", "tx", "ty")


# ------------------------------------------------------------------ interior


def _load_mapping(path: Path) -> object:
    text = read_text(path, "interior parameter file")
    if path.suffix.lower() == ".json" or yaml is None:
        return parse_json(text, path)
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        line = mark.line + 1 if mark is not None else None
        problem = getattr(err, "problem", None) or str(err).splitlines()[0]
        raise FormatError(path, f"invalid YAML: {problem}", line=line) from None
    except (RecursionError, ValueError, OverflowError) as err:
        raise FormatError(path, f"invalid YAML: {type(err).__name__}") from None


def read_interior(path: str | os.PathLike) -> tuple[dict[str, Camera], list[str]]:
    """Cameras of an Orthority interior-parameter file (YAML, or JSON by extension).

    Returns
    -------
    cameras : dict
        Camera id -> :class:`Camera`.
    warnings : list of str
    """
    path = Path(path)
    r = ValueReader(path)
    d = r.obj(_load_mapping(path), "top level")
    if "type" in d or "im_size" in d:  # flat dict: one camera
        d = {str(d.get("name") or "unknown"): d}
    if not d:
        r.fail("top level", "no camera defined")
    cameras: dict[str, Camera] = {}
    warnings: list[str] = []
    for key, c in d.items():
        cid = r.text(str(key), "camera id")
        c = r.obj(c, cid)
        ctype = r.text(c.get("type"), f"{cid}.type").lower()
        if ctype not in _USED:
            r.fail(f"{cid}.type", f"unsupported camera type {ctype!r}; supported: pinhole, brown, opencv")
        if ctype == "opencv":
            for k in _OPENCV_UNSUPPORTED:
                if k in c and r.num(c[k], f"{cid}.{k}") != 0.0:
                    r.fail(f"{cid}.{k}", f"nonzero {k} is unsupported (only k1, k2, p1, p2, k3 are used)")
        w, h = (
            r.size(v, f"{cid}.im_size[{i}]")
            for i, v in enumerate(_pair(r, c.get("im_size"), f"{cid}.im_size"))
        )
        m = max(w, h)
        flen = c.get("focal_len")
        fxy = (
            r.vec(flen, 2, f"{cid}.focal_len")
            if isinstance(flen, list)
            else [r.num(flen, f"{cid}.focal_len")] * 2
        )
        if c.get("sensor_size") is not None:
            sw, sh = r.vec(c["sensor_size"], 2, f"{cid}.sensor_size")
            if sw <= 0 or sh <= 0:
                r.fail(f"{cid}.sensor_size", "must be positive")
            fx, fy = fxy[0] * w / sw, fxy[1] * h / sh
        else:
            fx, fy = fxy[0] * m, fxy[1] * m
            if h > w:
                warnings.append(
                    f"camera {cid!r}: portrait image without sensor_size; focal_len taken as "
                    "normalised by max(width, height) (Orthority's code uses the width)"
                )
        cx = r.num(c.get("cx", 0.0), f"{cid}.cx")
        cy = r.num(c.get("cy", 0.0), f"{cid}.cy")
        dist = {k: r.num(c.get(k, 0.0), f"{cid}.{k}") for k in _USED[ctype]}
        try:
            cameras[cid] = Camera(w, h, fx, fy, (w - 1) / 2 + m * cx, (h - 1) / 2 + m * cy, id=cid, **dist)
        except InputError as err:
            r.fail(cid, str(err))
    return cameras, warnings


def _pair(r: ValueReader, v: object, field: str) -> list:
    if not isinstance(v, list) or len(v) != 2:
        r.fail(field, "expected [width, height]")
    return v  # type: ignore[return-value]


def interior_dict(cameras: dict[str, Camera]) -> dict:
    """Orthority interior parameters of cameras (focal and principal point normalised by max(w, h))."""
    out: dict = {}
    for cid, c in cameras.items():
        m = float(max(c.width, c.height))
        d: dict = {"type": "brown" if c.has_distortion else "pinhole", "im_size": [c.width, c.height]}
        d["focal_len"] = c.fx / m if c.fx == c.fy else [c.fx / m, c.fy / m]
        d["sensor_size"] = [c.width / m, c.height / m]
        d["cx"] = (c.cx - (c.width - 1) / 2) / m
        d["cy"] = (c.cy - (c.height - 1) / 2) / m
        if c.has_distortion:
            d.update(k1=c.k1, k2=c.k2, p1=c.p1, p2=c.p2, k3=c.k3)
        out[cid] = d
    return out


# ------------------------------------------------------------------ exterior


def _split(line: str, delim: str | None, path: Path, n: int) -> list[str]:
    if delim is None:
        return line.split()
    try:
        return [t.strip() for t in next(csv.reader([line], delimiter=delim, skipinitialspace=True))]
    except (csv.Error, StopIteration) as err:
        raise FormatError(path, f"cannot split the line: {err}", line=n) from None


def _sniff(line: str) -> str | None:
    for d in (",", ";", "\t"):
        if d in line:
            return d
    return None


def _is_number(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


def read_opk(
    csv_path: str | os.PathLike, interior_path: str | os.PathLike, crs: object = None
) -> Orientation:
    """Read Orthority exterior (CSV) and interior (YAML/JSON) parameters.

    Parameters
    ----------
    csv_path : path
        Exterior CSV; a ``.prj`` file with the same stem gives the CRS.
    interior_path : path
        Interior parameter file (``.json`` is JSON, otherwise YAML).
    crs : str or int, optional
        CRS of x, y, z (EPSG code, WKT, PROJ); overrides the ``.prj`` file.

    Returns
    -------
    Orientation
        With a round local offset (:func:`~truortho.core.geometry.frame.choose_offset`).

    Raises
    ------
    FormatError, MissingFileError, CRSError
    """
    path = Path(csv_path)
    cameras, warnings = read_interior(interior_path)
    text = read_text(path, "exterior CSV")
    if crs is None:
        prj = path.with_suffix(".prj")
        if not prj.is_file():
            raise CRSError(f"{path}: no CRS: give CRS or a .prj file ({prj.name})")
        crs = read_text(prj, ".prj file", max_bytes=1024**2)
    pcrs = parse_crs(crs)
    require_metric(pcrs, f"{path}: CRS")

    rows = list(data_lines(text))
    if not rows:
        raise FormatError(path, "no data rows")
    delim = _sniff(rows[0][1])
    first = [t.lower() for t in _split(rows[0][1], delim, path, rows[0][0])]
    if "filename" in first or (len(first) > 1 and not _is_number(first[1])):
        missing = [k for k in REQUIRED if k not in first]
        if missing:
            raise FormatError(
                path,
                f"header lacks the column(s) {', '.join(missing)} "
                f"(required: {', '.join(REQUIRED)}; lat/lon and roll/pitch/yaw are not supported)",
                line=rows[0][0],
            )
        cols = {k: first.index(k) for k in (*REQUIRED, "camera") if k in first}
        rows = rows[1:]
    else:
        cols = {k: i for i, k in enumerate(REQUIRED)}
    need = max(cols.values()) + 1

    names, cams, world, Rs = [], [], [], []
    seen: dict[str, int] = {}
    for n, line in rows:
        tok = _split(line, delim, path, n)
        if len(tok) < need:
            raise FormatError(path, f"expected {need} fields ({', '.join(cols)}), got {len(tok)}", line=n)
        name = check_name(tok[cols["filename"]].replace("\\", "/").rsplit("/", 1)[-1], path, n)
        if name in seen:
            raise FormatError(path, f"image {name!r} appears twice (also line {seen[name]})", line=n)
        seen[name] = n
        xyz = [parse_float(tok[cols[k]], path, n, k) for k in "xyz"]
        opk = [parse_float(tok[cols[k]], path, n, k) for k in ("omega", "phi", "kappa")]
        if "camera" in cols and tok[cols["camera"]]:
            cam = tok[cols["camera"]]
            if cam not in cameras:
                raise FormatError(
                    path,
                    f"image {name!r}: camera {cam!r} is not in the interior file (has: {', '.join(cameras)})",
                    line=n,
                )
        elif len(cameras) == 1:
            cam = next(iter(cameras))
        else:
            raise FormatError(
                path, f"image {name!r} names no camera and the interior file has {len(cameras)}", line=n
            )
        names.append(name)
        cams.append(cam)
        world.append(xyz)
        Rs.append(opk_to_matrix(opk[0], opk[1], opk[2], degrees=True))
    offset = choose_offset(world)
    images = [
        Image(nm, cam, R, np.asarray(w) - offset, nm)
        for nm, cam, w, R in zip(names, cams, world, Rs, strict=True)
    ]
    o = Orientation(LocalFrame(crs_to_text(pcrs), offset), cameras, images)
    o.metadata["source"] = {"format": "orthority", "exterior": str(path), "interior": str(interior_path)}
    if warnings:
        o.metadata["warnings"] = warnings
    return o


def write_opk(
    orientation: Orientation, csv_path: str | os.PathLike, interior_path: str | os.PathLike
) -> None:
    """Write Orthority exterior CSV (+ ``.prj`` when the CRS is known) and interior YAML/JSON.

    Coordinates are world (local + offset), angles degrees, floats at full
    precision. The interior file is JSON when its extension is ``.json``,
    YAML otherwise.
    """
    o = orientation
    o.validate()
    csv_path = Path(csv_path)
    interior_path = Path(interior_path)
    lines = ["filename,x,y,z,omega,phi,kappa,camera"]
    world = o.world_centers()
    for im, w in zip(o.images, world, strict=False):
        for s in (im.name, im.camera):
            if any(c in s for c in "\r\n"):
                raise InputError(f"{s!r} cannot be written to a CSV line")
        opk = matrix_to_opk(im.R, degrees=True)
        lines.append(
            ",".join([_quote(im.name)] + [fmt(v) for v in w] + [fmt(v) for v in opk] + [_quote(im.camera)])
        )
    d = interior_dict(o.cameras)
    if interior_path.suffix.lower() == ".json" or yaml is None:
        if interior_path.suffix.lower() != ".json":
            raise InputError("PyYAML is not installed: give the interior file a .json extension")
        itext = json.dumps(d, indent=4) + "\n"
    else:
        itext = yaml.safe_dump(d, sort_keys=False, indent=4, default_flow_style=None)
    atomic_write_text(csv_path, "\n".join(lines) + "\n")
    if o.crs is not None:
        atomic_write_text(csv_path.with_suffix(".prj"), parse_crs(o.crs).to_wkt() + "\n")
    atomic_write_text(interior_path, itext)


def _quote(s: str) -> str:
    if any(c in s for c in ',;"\t ') or s != s.strip():
        return '"' + s.replace('"', '""') + '"'
    return s
