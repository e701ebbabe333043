"""Format detection: read any supported orientation file, write any export format.

Supported inputs (see :mod:`truortho.core.formats`):

* COLMAP text model: a folder with ``cameras.txt`` and ``images.txt`` (or one
  of the model files, whose folder is used);
* Orthority exterior CSV (``.csv``/``.txt``) plus an interior parameter file;
* OpenSfM/ODM ``reconstruction.json`` (a JSON list);
* TruOrtho orientation JSON (a JSON object with ``"format": "truortho-orientation"``).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from .errors import FormatError, InputError, MissingFileError
from .orientation import FORMAT_NAME, Orientation

COLMAP_FILES = ("cameras.txt", "images.txt", "points3D.txt")
EXPORT_FORMATS = ("colmap", "opk")


def detect_format(path: str | os.PathLike) -> str:
    """``colmap``, ``opk``, ``opensfm`` or ``truortho`` for an input path."""
    p = Path(path)
    if p.is_dir():
        if (p / "cameras.txt").is_file() and (p / "images.txt").is_file():
            return "colmap"
        raise InputError(f"{p}: folder is not a COLMAP text model (cameras.txt and images.txt expected)")
    if not p.exists():
        raise MissingFileError(p, "input not found")
    if p.name in COLMAP_FILES:
        return "colmap"
    suffix = p.suffix.lower()
    if suffix in (".csv", ".txt"):
        return "opk"
    if suffix == ".json":
        with open(p, "rb") as fh:
            head = fh.read(4096).lstrip()
        if head.startswith(b"["):
            return "opensfm"
        if head.startswith(b"{"):
            if FORMAT_NAME.encode() in head:
                return "truortho"
            try:
                d = json.loads(p.read_text(encoding="utf-8"))
            except (UnicodeDecodeError, ValueError) as err:
                raise FormatError(p, f"invalid JSON: {err}") from None
            if isinstance(d, dict) and d.get("format") == FORMAT_NAME:
                return "truortho"
            raise FormatError(p, "JSON is neither a TruOrtho orientation nor an OpenSfM reconstruction")
        raise FormatError(p, "empty or not a JSON document")
    raise InputError(
        f"{p}: unknown orientation format (expected a COLMAP model folder or file, an Orthority "
        ".csv, an OpenSfM reconstruction.json or a TruOrtho orientation .json)"
    )


def read_orientation(path, interior=None, crs: str | None = None) -> Orientation:
    """Read an orientation in any supported format (see module docstring)."""
    fmt = detect_format(path)
    p = Path(path)
    if fmt == "colmap":
        from .formats.colmap import read_colmap

        folder = p if p.is_dir() else p.parent
        o = read_colmap(folder)
        if o.crs is None and crs:
            from .geometry.frame import crs_to_text, parse_crs

            o.frame.crs = crs_to_text(parse_crs(crs))
        return o
    if fmt == "opk":
        if not interior:
            raise InputError(f"{p}: an Orthority CSV needs an interior parameter file (INTERIOR)")
        from .formats.opk import read_opk

        return read_opk(p, interior, crs=crs)
    if fmt == "opensfm":
        from .formats.opensfm import read_opensfm

        return read_opensfm(p, crs=crs)
    return Orientation.load(p)


def write_orientation(orientation: Orientation, fmt: str, folder) -> list[str]:
    """Export to ``fmt`` (``colmap`` or ``opk``) into ``folder``; returns the files written."""
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    if fmt == "colmap":
        from .formats.colmap import write_colmap

        write_colmap(orientation, out)
        names = list(COLMAP_FILES) + ["georef.json"]
    elif fmt == "opk":
        from .formats.opk import write_opk

        write_opk(orientation, out / "exterior.csv", out / "interior.yaml")
        names = ["exterior.csv", "exterior.prj", "interior.yaml"]
    else:
        raise InputError(f"unknown export format {fmt!r}; expected one of {EXPORT_FORMATS}")
    return [str(out / n) for n in names if (out / n).exists()]
