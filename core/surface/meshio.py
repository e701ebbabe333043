"""Triangle meshes and their files: PLY (binary, ASCII read) and OBJ.

:class:`Mesh` holds **world** coordinates (the CRS of the products, metres):
``vertices (N, 3) float64``, ``faces (M, 3) int64`` (counter-clockwise seen
from the outside, i.e. from above for a 2.5D surface), optional
``colours (N, 3) uint8`` and the CRS as text. :func:`write_mesh` and
:func:`read_mesh` are the only file interface; other modules (the true
orthophoto reads its SURFACE with :func:`read_mesh`) never parse mesh files.

File conventions
----------------
PLY (written ``binary_little_endian 1.0``; ASCII and big-endian are read)::

    ply
    format binary_little_endian 1.0
    comment crs EPSG:32632                  <- CRS text: AUTH:CODE or one-line WKT
    comment offset 500000.0 5600000.0 0.0   <- only in the local frame
    element vertex N
    property float x                        <- float in the local frame when the local
    property float y                           coordinates fit (|v| < 8192 m, ulp < 0.5 mm),
    property float z                           double otherwise and always in the CRS frame
    property uchar red                      <- optional vertex colours
    property uchar green
    property uchar blue
    element face M
    property list uchar int vertex_indices
    end_header

OBJ (ASCII)::

    # crs EPSG:32632
    # offset 500000.0 5600000.0 0.0
    v x y z [r g b]          <- colours as floats in [0, 1] (the common MeshLab extension)
    f i j k                  <- 1-based

Coordinates in a file are ``local + offset`` when an offset is recorded (the
local frame of :mod:`truortho.core.geometry`: ``local = world - offset``),
otherwise world coordinates. Readers add the offset back, so
:func:`read_mesh` always returns world coordinates and keeps the recorded
offset in :attr:`Mesh.offset` (information only). Polygons with more than
three vertices are fan-triangulated on reading; texture coordinates and
normals are ignored.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import FormatError, InputError, MissingFileError
from ..rasterio_io import atomic_output

MESH_EXTENSIONS = (".ply", ".obj")
FRAMES = ("crs", "local")
#: local coordinates below this magnitude (metres) are stored as float32 (ulp < 0.5 mm)
FLOAT32_LIMIT = 8192.0


@dataclass
class Mesh:
    """A triangle mesh in world coordinates.

    Attributes
    ----------
    vertices : (N, 3) float64
        World coordinates (CRS units, metres), easting, northing, height.
    faces : (M, 3) int64
        Vertex indices of each triangle, counter-clockwise seen from outside.
    colours : (N, 3) uint8, optional
        Per-vertex RGB.
    crs : str, optional
        CRS of the vertices as ``AUTH:CODE`` or WKT.
    offset : (3,) float64, optional
        The local-frame offset recorded in the file it was read from
        (``local = world - offset``); None when the file held world coordinates.
    """

    vertices: np.ndarray
    faces: np.ndarray
    colours: np.ndarray | None = None
    crs: str | None = None
    offset: np.ndarray | None = None

    def __post_init__(self) -> None:
        v = np.asarray(self.vertices, dtype=np.float64)
        if v.ndim != 2 or v.shape[1] != 3:
            raise InputError(f"mesh vertices: expected an (N, 3) array, got shape {v.shape}")
        if not np.all(np.isfinite(v)):
            raise InputError("mesh vertices must be finite")
        f = np.asarray(self.faces)
        if f.size == 0:
            f = np.zeros((0, 3), np.int64)
        if f.ndim != 2 or f.shape[1] != 3 or f.dtype.kind not in "iu":
            raise InputError(f"mesh faces: expected an (M, 3) integer array, got shape {f.shape} {f.dtype}")
        f = f.astype(np.int64, copy=False)
        if f.size and (f.min() < 0 or f.max() >= len(v)):
            raise InputError(f"mesh faces refer to vertices outside 0..{len(v) - 1}")
        self.vertices = np.ascontiguousarray(v)
        self.faces = np.ascontiguousarray(f)
        if self.colours is not None:
            c = np.asarray(self.colours)
            if c.shape != (len(v), 3):
                raise InputError(f"mesh colours: expected ({len(v)}, 3), got {c.shape}")
            if c.dtype != np.uint8:
                if c.dtype.kind == "f" and c.size and float(np.nanmax(c)) <= 1.0:
                    c = np.round(c * 255.0)
                c = np.clip(c, 0, 255).astype(np.uint8)
            self.colours = np.ascontiguousarray(c)
        if self.offset is not None:
            off = np.asarray(self.offset, dtype=np.float64).reshape(-1)
            if off.shape != (3,) or not np.all(np.isfinite(off)):
                raise InputError(f"mesh offset: expected 3 finite numbers, got {self.offset!r}")
            self.offset = off

    @property
    def n_vertices(self) -> int:
        return len(self.vertices)

    @property
    def n_faces(self) -> int:
        return len(self.faces)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """``(min (3,), max (3,))`` of the vertices (world)."""
        if not len(self.vertices):
            raise InputError("the mesh has no vertices")
        return self.vertices.min(axis=0), self.vertices.max(axis=0)

    def face_normals(self) -> np.ndarray:
        """Unit normals (M, 3) of the faces (zero for degenerate faces)."""
        a, b, c = (self.vertices[self.faces[:, k]] for k in range(3))
        n = np.cross(b - a, c - a)
        norm = np.linalg.norm(n, axis=1, keepdims=True)
        return np.divide(n, norm, out=np.zeros_like(n), where=norm > 0)


# ------------------------------------------------------------------ writing


def check_mesh_path(path, what: str = "mesh") -> Path:
    """``path`` as a Path if it ends in .ply or .obj, else :class:`InputError` naming it."""
    return _check_path(path, what)


def _check_path(path, what: str = "mesh") -> Path:
    p = Path(os.fspath(path))
    if p.suffix.lower() not in MESH_EXTENSIONS:
        raise InputError(
            f"{what} {str(p)!r}: unknown mesh extension {p.suffix or '(none)'!r}; expected .ply or .obj"
        )
    return p


def _one_line(text: str | None) -> str | None:
    if text is None:
        return None
    return " ".join(str(text).split())


def write_mesh(path, mesh: Mesh, frame: str = "crs", offset=None) -> Path:
    """Write a mesh atomically as PLY (binary little-endian) or OBJ, by extension.

    Parameters
    ----------
    path : str or os.PathLike
        ``.ply`` or ``.obj``.
    mesh : Mesh
        World coordinates.
    frame : ``"crs"`` or ``"local"``
        ``"crs"`` writes world coordinates (PLY: double); ``"local"`` writes
        ``world - offset`` and records the offset in the header.
    offset : (3,) array, optional
        The local-frame offset; default :func:`~truortho.core.geometry.frame.choose_offset`
        of the vertices (rounded to 1000 m in plan, 0 in height).

    Returns
    -------
    Path of the written file.
    """
    p = _check_path(path)
    if not isinstance(mesh, Mesh):
        raise InputError(f"{p}: expected a Mesh, got {type(mesh).__name__}")
    if frame not in FRAMES:
        raise InputError(f"{p}: frame must be 'crs' or 'local', got {frame!r}")
    off = None
    coords = mesh.vertices
    if frame == "local":
        if offset is None:
            from ..geometry.frame import choose_offset

            off = choose_offset(mesh.vertices)
        else:
            off = np.asarray(offset, dtype=np.float64).reshape(-1)
            if off.shape != (3,) or not np.all(np.isfinite(off)):
                raise InputError(f"{p}: offset must be 3 finite numbers, got {offset!r}")
        coords = mesh.vertices - off
    crs = _one_line(mesh.crs)
    with atomic_output(p) as tmp:
        if p.suffix.lower() == ".ply":
            _write_ply(tmp, coords, mesh.faces, mesh.colours, crs, off)
        else:
            _write_obj(tmp, coords, mesh.faces, mesh.colours, crs, off)
    return p


def _write_ply(path: Path, coords, faces, colours, crs, off) -> None:
    use_float = off is not None and (not len(coords) or float(np.abs(coords).max()) < FLOAT32_LIMIT)
    ctype, cdt = ("float", "<f4") if use_float else ("double", "<f8")
    lines = ["ply", "format binary_little_endian 1.0", "comment generator TruOrtho"]
    if crs:
        lines.append(f"comment crs {crs}")
    if off is not None:
        lines.append("comment offset {:.6f} {:.6f} {:.6f}".format(*off))
    lines.append(f"element vertex {len(coords)}")
    lines += [f"property {ctype} {a}" for a in "xyz"]
    fields = [("x", cdt), ("y", cdt), ("z", cdt)]
    if colours is not None:
        lines += [f"property uchar {c}" for c in ("red", "green", "blue")]
        fields += [("red", "u1"), ("green", "u1"), ("blue", "u1")]
    lines += [f"element face {len(faces)}", "property list uchar int vertex_indices", "end_header"]
    vert = np.empty(len(coords), dtype=fields)
    for k, a in enumerate("xyz"):
        vert[a] = coords[:, k]
    if colours is not None:
        for k, c in enumerate(("red", "green", "blue")):
            vert[c] = colours[:, k]
    face = np.empty(len(faces), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    face["n"] = 3
    if len(faces) and faces.max() >= 2**31:
        raise InputError(f"{path}: too many vertices for a PLY int index")
    face["i"] = faces
    with open(path, "wb") as fh:
        fh.write(("\n".join(lines) + "\n").encode("ascii", errors="replace"))
        fh.write(vert.tobytes())
        fh.write(face.tobytes())


def _write_obj(path: Path, coords, faces, colours, crs, off) -> None:
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write("# TruOrtho mesh\n")
        if crs:
            fh.write(f"# crs {crs}\n")
        if off is not None:
            fh.write("# offset {:.6f} {:.6f} {:.6f}\n".format(*off))
        fh.write(f"# vertices {len(coords)} faces {len(faces)}\n")
        if colours is not None:
            data = np.column_stack([coords, colours.astype(np.float64) / 255.0])
            np.savetxt(fh, data, fmt="v %.6f %.6f %.6f %.5f %.5f %.5f")
        else:
            np.savetxt(fh, coords, fmt="v %.6f %.6f %.6f")
        if len(faces):
            np.savetxt(fh, faces + 1, fmt="f %d %d %d")


# ------------------------------------------------------------------ reading

_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}  # fmt: skip


def read_mesh(path) -> Mesh:
    """Read a PLY (binary or ASCII) or OBJ mesh into world coordinates.

    Raises
    ------
    MissingFileError
        The file does not exist.
    InputError
        The extension is neither .ply nor .obj.
    FormatError
        The file is not a valid mesh of its format (the message names the line or field).
    """
    p = _check_path(path)
    if not p.is_file():
        raise MissingFileError(p, "mesh file not found")
    if p.suffix.lower() == ".ply":
        coords, faces, colours, crs, off = _read_ply(p)
    else:
        coords, faces, colours, crs, off = _read_obj(p)
    if off is not None:
        coords = coords + off
    try:
        return Mesh(coords, faces, colours, crs, off)
    except InputError as exc:
        raise FormatError(p, str(exc)) from None


def _parse_offset(p: Path, text: str, line: int | None = None) -> np.ndarray:
    try:
        off = np.array([float(v) for v in text.split()], dtype=np.float64)
    except ValueError:
        raise FormatError(p, f"offset comment: expected 'offset E N H', got {text!r}", line) from None
    if off.shape != (3,) or not np.all(np.isfinite(off)):
        raise FormatError(p, f"offset comment: expected 3 finite numbers, got {text!r}", line)
    return off


def _read_ply(p: Path):
    with open(p, "rb") as fh:
        data = fh.read()
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise FormatError(p, "not a PLY file (expected 'ply' ... 'end_header')")
    nl = data.find(b"\n", end)
    body_start = nl + 1 if nl >= 0 else len(data)
    header = data[:end].decode("ascii", errors="replace").splitlines()
    fmt = None
    crs = None
    off = None
    elements: list[dict] = []
    for ln, raw in enumerate(header, start=1):
        parts = raw.strip().split()
        if not parts:
            continue
        key = parts[0]
        if key == "format":
            if len(parts) < 2 or parts[1] not in ("ascii", "binary_little_endian", "binary_big_endian"):
                raise FormatError(p, f"unknown PLY format {raw.strip()!r}", ln)
            fmt = parts[1]
        elif key in ("comment", "obj_info"):
            rest = raw.strip()[len(key) :].strip()
            if rest.startswith("crs "):
                crs = rest[4:].strip() or None
            elif rest.startswith("offset "):
                off = _parse_offset(p, rest[7:], ln)
        elif key == "element":
            if len(parts) != 3 or not parts[2].isdigit():
                raise FormatError(p, f"bad element line {raw.strip()!r}", ln)
            elements.append({"name": parts[1], "count": int(parts[2]), "props": []})
        elif key == "property":
            if not elements:
                raise FormatError(p, "property before any element", ln)
            if len(parts) == 5 and parts[1] == "list":
                if parts[2] not in _PLY_TYPES or parts[3] not in _PLY_TYPES:
                    raise FormatError(p, f"unknown PLY list types in {raw.strip()!r}", ln)
                elements[-1]["props"].append((parts[4], "list", _PLY_TYPES[parts[2]], _PLY_TYPES[parts[3]]))
            elif len(parts) == 3 and parts[1] in _PLY_TYPES:
                elements[-1]["props"].append((parts[2], "scalar", _PLY_TYPES[parts[1]], None))
            else:
                raise FormatError(p, f"unknown PLY property {raw.strip()!r}", ln)
        elif key not in ("ply",):
            raise FormatError(p, f"unexpected PLY header line {raw.strip()!r}", ln)
    if fmt is None:
        raise FormatError(p, "PLY header has no 'format' line")
    body = data[body_start:]
    parsed = (
        _ply_ascii(p, body, elements)
        if fmt == "ascii"
        else _ply_binary(p, body, elements, "<" if fmt == "binary_little_endian" else ">")
    )
    if "vertex" not in parsed:
        raise FormatError(p, "PLY file has no 'vertex' element")
    vert = parsed["vertex"]
    for a in "xyz":
        if a not in vert:
            raise FormatError(p, f"PLY vertex element has no '{a}' property")
    coords = np.column_stack([np.asarray(vert[a], dtype=np.float64) for a in "xyz"])
    colours = None
    colour_names = (
        ("red", "green", "blue"),
        ("diffuse_red", "diffuse_green", "diffuse_blue"),
        ("r", "g", "b"),
    )
    for names in colour_names:
        if all(n in vert for n in names):
            c = np.column_stack([np.asarray(vert[n]) for n in names])
            if c.dtype.kind == "f":
                c = np.round(c * 255.0) if c.size and float(c.max()) <= 1.0 else c
            elif c.dtype.itemsize > 1 and c.size and c.max() > 255:
                c = c / 257.0
            colours = np.clip(c, 0, 255).astype(np.uint8)
            break
    faces = np.zeros((0, 3), np.int64)
    if "face" in parsed:
        lists = parsed["face"].get("vertex_indices", parsed["face"].get("vertex_index"))
        if lists is None:
            raise FormatError(p, "PLY face element has no 'vertex_indices' list")
        faces = _triangulate(p, lists, len(coords))
    return coords, faces, colours, crs, off


def _ply_binary(p: Path, body: bytes, elements: list[dict], endian: str) -> dict:
    out: dict = {}
    pos = 0
    for el in elements:
        n = el["count"]
        props = el["props"]
        if all(kind == "scalar" for _, kind, _, _ in props):
            dt = np.dtype([(name, endian + t) for name, _, t, _ in props])
            size = dt.itemsize * n
            if pos + size > len(body):
                raise FormatError(p, f"PLY element {el['name']!r} is truncated ({n} records expected)")
            arr = np.frombuffer(body, dtype=dt, count=n, offset=pos)
            pos += size
            out[el["name"]] = {name: arr[name] for name, _, _, _ in props}
            continue
        # lists: fast path when every list has the same length (triangles)
        values: dict = {name: [] for name, _, _, _ in props}
        if len(props) == 1 and n:
            name, _, ct, it = props[0]
            cdt = np.dtype(endian + ct)
            if pos + cdt.itemsize > len(body):
                raise FormatError(p, f"PLY element {el['name']!r} is truncated")
            k = int(np.frombuffer(body, dtype=cdt, count=1, offset=pos)[0])
            rec = np.dtype([("n", endian + ct), ("i", endian + it, (k,))]) if k > 0 else None
            if rec is not None and pos + rec.itemsize * n <= len(body):
                arr = np.frombuffer(body, dtype=rec, count=n, offset=pos)
                if np.all(arr["n"] == k):
                    out[el["name"]] = {name: arr["i"]}
                    pos += rec.itemsize * n
                    continue
        for _ in range(n):
            for name, kind, t, it in props:
                dt = np.dtype(endian + t)
                if pos + dt.itemsize > len(body):
                    raise FormatError(p, f"PLY element {el['name']!r} is truncated")
                v = np.frombuffer(body, dtype=dt, count=1, offset=pos)[0]
                pos += dt.itemsize
                if kind == "scalar":
                    values[name].append(v)
                    continue
                idt = np.dtype(endian + it)
                cnt = int(v)
                if cnt < 0 or pos + idt.itemsize * cnt > len(body):
                    raise FormatError(p, f"PLY element {el['name']!r} has a bad list length {cnt}")
                values[name].append(np.frombuffer(body, dtype=idt, count=cnt, offset=pos))
                pos += idt.itemsize * cnt
        out[el["name"]] = values
    return out


def _ply_ascii(p: Path, body: bytes, elements: list[dict]) -> dict:
    tokens = body.decode("ascii", errors="replace").split()
    pos = 0
    out: dict = {}

    def take(k: int) -> list[str]:
        nonlocal pos
        if pos + k > len(tokens):
            raise FormatError(p, "ASCII PLY body is truncated")
        t = tokens[pos : pos + k]
        pos += k
        return t

    for el in elements:
        props = el["props"]
        n = el["count"]
        if all(kind == "scalar" for _, kind, _, _ in props):
            arr = (
                np.array(take(n * len(props)), dtype=np.float64).reshape(n, len(props))
                if n
                else np.zeros((0, len(props)))
            )
            out[el["name"]] = {name: arr[:, k].astype(np.dtype(t)) for k, (name, _, t, _) in enumerate(props)}
            continue
        values: dict = {name: [] for name, _, _, _ in props}
        try:
            for _ in range(n):
                for name, kind, _t, _it in props:
                    if kind == "scalar":
                        values[name].append(float(take(1)[0]))
                    else:
                        cnt = int(float(take(1)[0]))
                        values[name].append(np.array([int(float(v)) for v in take(cnt)], dtype=np.int64))
        except ValueError as exc:
            raise FormatError(p, f"ASCII PLY element {el['name']!r}: {exc}") from None
        out[el["name"]] = values
    return out


def _triangulate(p: Path, lists, n_vertices: int) -> np.ndarray:
    if isinstance(lists, np.ndarray) and lists.ndim == 2:
        k = lists.shape[1]
        if k == 3:
            return lists.astype(np.int64)
        if k < 3:
            raise FormatError(p, f"faces with {k} vertices")
        tris = [lists[:, [0, j, j + 1]] for j in range(1, k - 1)]
        return np.stack(tris, axis=1).reshape(-1, 3).astype(np.int64)
    out = []
    for poly in lists:
        poly = np.asarray(poly, dtype=np.int64)
        if len(poly) < 3:
            raise FormatError(p, f"a face with {len(poly)} vertices")
        for j in range(1, len(poly) - 1):
            out.append((poly[0], poly[j], poly[j + 1]))
    return np.array(out, dtype=np.int64).reshape(-1, 3)


def _read_obj(p: Path):
    verts: list[list[float]] = []
    cols: list[list[float]] = []
    faces: list[tuple[int, int, int]] = []
    crs = None
    off = None
    with open(p, encoding="utf-8", errors="replace") as fh:
        for ln, raw in enumerate(fh, start=1):
            s = raw.strip()
            if not s:
                continue
            if s.startswith("#"):
                c = s[1:].strip()
                if c.startswith("crs "):
                    crs = c[4:].strip() or None
                elif c.startswith("offset "):
                    off = _parse_offset(p, c[7:], ln)
                continue
            parts = s.split()
            key = parts[0]
            if key == "v":
                if len(parts) not in (4, 5, 7, 8):
                    raise FormatError(p, f"vertex line: expected 'v x y z [r g b]', got {s[:60]!r}", ln)
                try:
                    vals = [float(v) for v in parts[1:]]
                except ValueError:
                    raise FormatError(p, f"vertex line: not numbers: {s[:60]!r}", ln) from None
                verts.append(vals[:3])
                if len(vals) >= 6:
                    cols.append(vals[-3:] if len(vals) in (6, 7) else vals[3:6])
            elif key == "f":
                if len(parts) < 4:
                    raise FormatError(p, f"face line: expected at least 3 vertices, got {s[:60]!r}", ln)
                idx = []
                for tok in parts[1:]:
                    head = tok.split("/")[0]
                    try:
                        i = int(head)
                    except ValueError:
                        raise FormatError(p, f"face line: bad vertex index {tok!r}", ln) from None
                    if i == 0:
                        raise FormatError(p, "face line: OBJ indices are 1-based (0 found)", ln)
                    idx.append(i - 1 if i > 0 else len(verts) + i)
                for j in range(1, len(idx) - 1):
                    faces.append((idx[0], idx[j], idx[j + 1]))
            # vt, vn, g, o, s, usemtl, mtllib, l, p: ignored
    coords = np.array(verts, dtype=np.float64).reshape(-1, 3)
    colours = None
    if cols:
        if len(cols) != len(verts):
            raise FormatError(p, f"{len(cols)} of {len(verts)} vertices have colours; expected all or none")
        rgb = np.array(cols, dtype=np.float64)
        if rgb.size and rgb.max() <= 1.0:
            rgb = rgb * 255.0
        colours = np.clip(np.round(rgb), 0, 255).astype(np.uint8)
    f = np.array(faces, dtype=np.int64).reshape(-1, 3)
    if f.size and (f.min() < 0 or f.max() >= len(coords)):
        raise FormatError(p, f"faces refer to vertices outside 1..{len(coords)}")
    return coords, f, colours, crs, off
