"""OpenDroneMap / OpenSfM ``gcp_list.txt``.

Format::

    <CRS>
    geo_x geo_y geo_z im_x im_y image_name [gcp_name] [extra ...]

The first non-empty, non-comment line is the CRS: ``EPSG:nnnn`` (or a bare
code), a PROJ string (``+proj=...``), ``WGS84 UTM <zone>[N|S]`` (EPSG:326nn /
327nn; without a letter: north) or ``WGS84`` (lon/lat, EPSG:4326). Fields are
separated by tabs (when the line has a tab) or whitespace; ``#`` starts a
comment line. Lines are grouped into GCPs by ``gcp_name``; unnamed lines by
identical coordinates (named ``gcp_1``, ``gcp_2``, ...).

Pixel coordinates are taken as they are: ODM and OpenSfM read them with the
centre of the top-left pixel at (0, 0) (OpenSfM normalises with
``(x + 0.5 - w / 2) / max(w, h)``), which is TruOrtho's convention too.
Coordinates of a geographic header CRS (lon, lat) are returned unchanged with
that CRS; the caller reprojects them.
"""

from __future__ import annotations

import os
import re
import warnings
from pathlib import Path

from ..errors import FormatError, InputError
from ..geometry.frame import crs_to_text, parse_crs
from ..orientation import GCP, atomic_write_text
from ._text import check_name, data_lines, fmt, parse_float, read_text

_UTM = re.compile(r"^WGS\s*84\s+UTM\s+(\d{1,2})\s*([NS]?)$", re.IGNORECASE)


_FIELDS = ("geo_x", "geo_y", "geo_z", "im_x", "im_y")


class GCPListWarning(UserWarning):
    """A recoverable oddity in a gcp_list file (e.g. a duplicate observation)."""


def parse_crs_header(header: str, path: object = "<gcp_list>", line: int | None = 1) -> str:
    """Normalised CRS text (``EPSG:nnnn`` when exact, else WKT) of a gcp_list header line."""
    from ..errors import CRSError

    h = header.strip().strip("'\"")
    m = _UTM.match(h)
    if m:
        zone = int(m.group(1))
        if not 1 <= zone <= 60:
            raise FormatError(path, f"UTM zone must be 1..60, got {zone}", line=line)
        return f"EPSG:{(32700 if m.group(2).upper() == 'S' else 32600) + zone}"
    if h.upper() in ("WGS84", "WGS 84"):
        return "EPSG:4326"
    if not (h.isdigit() or h.upper().startswith("EPSG:") or "+proj" in h):
        raise FormatError(
            path,
            f"unrecognised CRS header {h[:60]!r}: expected 'EPSG:<code>', a PROJ string "
            "or 'WGS84 UTM <zone>[N|S]'",
            line=line,
        )
    try:
        crs = parse_crs(h)
    except CRSError as err:
        raise FormatError(path, str(err), line=line) from None
    text = crs_to_text(crs)
    if ":" not in text.split("[", 1)[0]:  # WKT: try an equivalent EPSG code (PROJ strings of UTM zones etc.)
        code = crs.to_epsg()
        if code is not None and parse_crs(f"EPSG:{code}").equals(crs, ignore_axis_order=True):
            text = f"EPSG:{code}"
    return text


def read_gcp_list(path: str | os.PathLike, warnings_out: list[str] | None = None) -> tuple[str, list[GCP]]:
    """Read a ``gcp_list.txt``.

    Parameters
    ----------
    path : path
        The file.
    warnings_out : list, optional
        Receives warnings (duplicate observations that were dropped); they are
        also issued as :class:`GCPListWarning`.

    Returns
    -------
    crs : str
        CRS of the coordinates (``EPSG:nnnn`` or WKT).
    gcps : list of GCP
        In order of first appearance; coordinates in the header CRS, pixel
        measurements as in the file.

    Raises
    ------
    FormatError, MissingFileError
    """
    path = Path(path)
    text = read_text(path, "GCP list")
    lines = data_lines(text)
    first = next(lines, None)
    if first is None:
        raise FormatError(path, "empty file: expected a CRS line and GCP lines")
    crs = parse_crs_header(first[1], path, first[0])

    groups: dict[str, dict] = {}
    unnamed: dict[tuple[float, float, float], str] = {}
    msgs: list[str] = []
    for n, line in lines:
        tok = line.split("\t") if "\t" in line else line.split()
        tok = [t.strip() for t in tok if t.strip()]
        if len(tok) < 6:
            raise FormatError(path, "expected 'geo_x geo_y geo_z im_x im_y image_name [gcp_name]'", line=n)
        x, y, z, u, v = (parse_float(t, path, n, w) for t, w in zip(tok[:5], _FIELDS, strict=True))
        image = check_name(tok[5], path, n)
        xyz = (x, y, z)
        if len(tok) > 6:
            name = tok[6]
        else:
            name = unnamed.get(xyz) or ""
            if not name:
                k = len(unnamed) + 1
                while f"gcp_{k}" in groups:
                    k += 1
                name = unnamed[xyz] = f"gcp_{k}"
        g = groups.get(name)
        if g is None:
            groups[name] = g = {"xyz": xyz, "line": n, "obs": [], "seen": {}}
        elif g["xyz"] != xyz:
            raise FormatError(
                path,
                f"GCP {name!r} has coordinates {list(xyz)} here but {list(g['xyz'])} on line {g['line']}",
                line=n,
            )
        if image in g["seen"]:
            msg = (
                f"{path}, line {n}: GCP {name!r} is measured twice on image {image!r}; kept the "
                f"measurement of line {g['seen'][image]}"
            )
            msgs.append(msg)
            continue
        g["seen"][image] = n
        g["obs"].append((image, u, v))
    if not groups:
        raise FormatError(path, "no GCP lines after the CRS line")
    try:
        gcps = [GCP(name, g["xyz"], observations=g["obs"]) for name, g in groups.items()]
    except InputError as err:
        raise FormatError(path, str(err)) from None
    for msg in msgs:
        warnings.warn(msg, GCPListWarning, stacklevel=2)
    if warnings_out is not None:
        warnings_out.extend(msgs)
    return crs, gcps


def write_gcp_list(crs_text: str, gcps: list[GCP], path: str | os.PathLike) -> None:
    """Write GCPs (world coordinates, pixel measurements) as a tab-separated ``gcp_list.txt``.

    The header is ``EPSG:nnnn`` when the CRS has an exact EPSG code, else its
    PROJ string. GCPs without observations cannot be represented and are
    skipped.
    """
    crs = parse_crs(crs_text)
    auth = crs.to_authority(min_confidence=100)
    header = f"{auth[0]}:{auth[1]}" if auth and auth[0] == "EPSG" else crs.to_proj4()
    out = [header]
    for g in gcps:
        if not g.name or any(c.isspace() for c in g.name):
            raise InputError(f"GCP name {g.name!r} cannot be written to gcp_list.txt (empty or has blanks)")
        for image, u, v in g.observations:
            if any(c in image for c in "\t\r\n") or image != image.strip():
                raise InputError(f"image name {image!r} cannot be written to gcp_list.txt")
            out.append(
                "\t".join([fmt(g.xyz[0]), fmt(g.xyz[1]), fmt(g.xyz[2]), fmt(u), fmt(v), image, g.name])
            )
    atomic_write_text(path, "\n".join(out) + "\n")
