"""The orientation model and its versioned JSON format.

An :class:`Orientation` holds everything later stages need: the world CRS and
local offset, interior orientations (:class:`~.geometry.camera.Camera`),
exterior orientations (:class:`Image`), optional sparse tie points and
ground control (:class:`GCP`). Conventions: :mod:`truortho.core.geometry`.

JSON format ``truortho-orientation`` version 1 (documented in docs/FORMATS.md)::

    {
      "format": "truortho-orientation", "version": 1,
      "crs": "EPSG:32632" | "<WKT>" | null,
      "offset": [E, N, H],               # local = world - offset
      "image_root": ".",                 # folder of the images, relative to this file or absolute
      "cameras": {"cam": {"width":..., "height":..., "fx":..., "fy":..., "cx":..., "cy":...,
                          "k1":0, "k2":0, "k3":0, "p1":0, "p2":0}},
      "images": [{"name": "IMG_1.jpg", "path": "IMG_1.jpg", "camera": "cam",
                  "rotation": [[r11, r12, r13], [..], [..]],   # world-to-camera
                  "center": [X, Y, Z]}],                       # local frame
      "points": {"xyz": [[X, Y, Z], ...], "rgb": [[r, g, b], ...], "error": [...],
                 "observations": [[point_index, image_index, x, y], ...]},   # optional
      "gcps": [{"name": "g1", "role": "gcp" | "check", "xyz": [E, N, H],  # world frame
                "sigma": [sx, sy, sz] | null,
                "observations": [{"image": "IMG_1.jpg", "x": px, "y": py,
                                  "sigma": px_sigma}]}]    # optional; sigma optional (pixels)
    }

Image ``path``s are relative to ``image_root`` and may not be absolute or
contain ``..``: every file the orientation refers to lies under the one
folder the file names, so reading an untrusted orientation never reaches
outside it.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath, PureWindowsPath
from typing import NoReturn

import numpy as np

from .errors import FormatError, InputError, MissingFileError
from .geometry.camera import Camera
from .geometry.frame import LocalFrame
from .geometry.rotation import check_rotation_matrix

FORMAT_NAME = "truortho-orientation"
FORMAT_VERSION = 1
GCP_ROLES = ("gcp", "check")
MAX_JSON_BYTES = 2 * 1024**3


@dataclass
class Image:
    """Exterior orientation of one image.

    ``R`` rotates world (local frame) to camera; ``C`` is the projection centre
    in the local frame; ``path`` is relative to the orientation's image root.
    """

    name: str
    camera: str
    R: np.ndarray
    C: np.ndarray
    path: str | None = None

    def __post_init__(self) -> None:
        self.R = check_rotation_matrix(self.R, f"image {self.name!r} rotation")
        C = np.asarray(self.C, dtype=np.float64).reshape(-1)
        if C.shape != (3,) or not np.all(np.isfinite(C)):
            raise InputError(f"image {self.name!r}: center must be 3 finite numbers")
        self.C = C
        if self.path is None:
            self.path = self.name

    @property
    def t(self) -> np.ndarray:
        """Translation of ``X_cam = R X + t`` (COLMAP/OpenSfM form)."""
        return -self.R @ self.C

    @property
    def viewing_direction(self) -> np.ndarray:
        """Unit optical-axis direction in the local frame."""
        return self.R[2].copy()


def isotropic_sigma(sigma_x: float | None, sigma_y: float | None) -> float | None:
    """One measurement sigma for both image axes (the bundle weights x and y alike): the RMS of
    ``sigma_x`` and ``sigma_y``, the one given when the other is None, None when neither is."""
    given = [float(s) for s in (sigma_x, sigma_y) if s is not None]
    if not given:
        return None
    return math.sqrt(sum(s * s for s in given) / len(given))


@dataclass
class GCP:
    """A ground control or check point: world coordinates and image measurements.

    ``obs_sigma`` maps an image name to the standard deviation (pixels, the same in x and y) of
    the measurement on that image, e.g. from least-squares matching (:mod:`.gcp.lsm`); the
    bundle weights that observation with it. Images not in it get the adjustment's default.
    """

    name: str
    xyz: np.ndarray
    role: str = "gcp"
    sigma: np.ndarray | None = None
    observations: list[tuple[str, float, float]] = field(default_factory=list)
    obs_sigma: dict[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        xyz = np.asarray(self.xyz, dtype=np.float64).reshape(-1)
        if xyz.shape != (3,) or not np.all(np.isfinite(xyz)):
            raise InputError(f"GCP {self.name!r}: coordinates must be 3 finite numbers")
        self.xyz = xyz
        if self.role not in GCP_ROLES:
            raise InputError(f"GCP {self.name!r}: role must be one of {GCP_ROLES}, got {self.role!r}")
        if self.sigma is not None:
            s = np.asarray(self.sigma, dtype=np.float64).reshape(-1)
            if s.shape != (3,) or not np.all(np.isfinite(s)) or np.any(s <= 0):
                raise InputError(f"GCP {self.name!r}: sigma must be 3 positive numbers")
            self.sigma = s
        obs_sigma = {}
        for image, v in dict(self.obs_sigma or {}).items():
            try:
                fv = float(v)
            except (TypeError, ValueError):
                fv = float("nan")
            if not (math.isfinite(fv) and fv > 0):
                raise InputError(
                    f"GCP {self.name!r}: the measurement sigma on image {image!r} must be a positive number, "
                    f"got {v!r}"
                )
            obs_sigma[str(image)] = fv
        self.obs_sigma = obs_sigma


@dataclass
class SparsePoints:
    """Tie points (local frame) and their image observations."""

    xyz: np.ndarray
    rgb: np.ndarray | None = None
    error: np.ndarray | None = None
    obs_point: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    obs_image: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    obs_xy: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))

    def __post_init__(self) -> None:
        self.xyz = np.asarray(self.xyz, dtype=np.float64).reshape(-1, 3)
        n = len(self.xyz)
        if self.rgb is not None:
            rgb = np.asarray(self.rgb, dtype=np.float64).reshape(-1, 3)
            if len(rgb) != n or not np.all(np.isfinite(rgb)):
                raise InputError("points: rgb must have one finite row per point")
            self.rgb = np.clip(np.round(rgb), 0, 255).astype(np.uint8)
        if self.error is not None:
            self.error = np.asarray(self.error, dtype=np.float64).reshape(-1)
            if len(self.error) != n:
                raise InputError("points: error must have one value per point")
        self.obs_point = np.asarray(self.obs_point, dtype=np.int64).reshape(-1)
        self.obs_image = np.asarray(self.obs_image, dtype=np.int64).reshape(-1)
        self.obs_xy = np.asarray(self.obs_xy, dtype=np.float64).reshape(-1, 2)
        if not (len(self.obs_point) == len(self.obs_image) == len(self.obs_xy)):
            raise InputError("points: observation arrays differ in length")
        if len(self.obs_point) and (self.obs_point.min() < 0 or self.obs_point.max() >= n):
            raise InputError("points: an observation refers to a point index out of range")

    def __len__(self) -> int:
        return len(self.xyz)


@dataclass
class Orientation:
    """A block of oriented images."""

    frame: LocalFrame = field(default_factory=LocalFrame)
    cameras: dict[str, Camera] = field(default_factory=dict)
    images: list[Image] = field(default_factory=list)
    points: SparsePoints | None = None
    gcps: list[GCP] = field(default_factory=list)
    image_root: str = "."
    metadata: dict = field(default_factory=dict)

    # ------------------------------------------------------------ access
    @property
    def crs(self) -> str | None:
        return self.frame.crs

    @property
    def offset(self) -> np.ndarray:
        return self.frame.offset

    def image(self, name: str) -> Image:
        for im in self.images:
            if im.name == name:
                return im
        raise InputError(f"no image named {name!r} in the orientation")

    def image_index(self) -> dict[str, int]:
        return {im.name: i for i, im in enumerate(self.images)}

    def camera_of(self, image: Image) -> Camera:
        try:
            return self.cameras[image.camera]
        except KeyError:
            raise InputError(f"image {image.name!r} refers to unknown camera {image.camera!r}") from None

    def validate(self) -> None:
        """Check references between images, cameras, points and GCPs."""
        names = set()
        for im in self.images:
            if im.name in names:
                raise InputError(f"image name {im.name!r} appears twice")
            names.add(im.name)
            self.camera_of(im)
            check_relative_path(im.path or im.name, f"image {im.name!r} path")
        if self.points is not None and len(self.points.obs_image):
            if self.points.obs_image.min() < 0 or self.points.obs_image.max() >= len(self.images):
                raise InputError("points: an observation refers to an image index out of range")
        for g in self.gcps:
            for img, _, _ in g.observations:
                if img not in names:
                    raise InputError(f"GCP {g.name!r}: observation on unknown image {img!r}")

    def resolve_image_path(self, image: Image, base: str | os.PathLike | None = None) -> Path:
        """Absolute path of an image (``base`` overrides the stored image root)."""
        root = Path(base) if base is not None else Path(self.image_root)
        rel = check_relative_path(image.path or image.name, f"image {image.name!r} path")
        return root / rel

    def check_images_exist(self, base: str | os.PathLike | None = None) -> None:
        """Raise :class:`MissingFileError` naming the first image absent on disk."""
        for im in self.images:
            p = self.resolve_image_path(im, base)
            if not p.is_file():
                raise MissingFileError(p, f"image {im.name!r} referenced by the orientation is absent")

    def world_centers(self) -> np.ndarray:
        """(N, 3) projection centres in the world CRS."""
        if not self.images:
            return np.zeros((0, 3))
        return self.frame.to_world(np.array([im.C for im in self.images]))

    def with_offset(self, offset) -> Orientation:
        """The same block expressed with another local offset."""
        new = LocalFrame(self.frame.crs, offset)
        shift = self.frame.offset - new.offset
        images = [Image(im.name, im.camera, im.R.copy(), im.C + shift, im.path) for im in self.images]
        pts = None
        if self.points is not None:
            p = self.points
            pts = SparsePoints(p.xyz + shift, p.rgb, p.error, p.obs_point, p.obs_image, p.obs_xy)
        return Orientation(
            new, dict(self.cameras), images, pts, list(self.gcps), self.image_root, dict(self.metadata)
        )

    # --------------------------------------------------------------- JSON
    def to_dict(self, image_root: str | None = None) -> dict:
        d: dict = {
            "format": FORMAT_NAME,
            "version": FORMAT_VERSION,
            "crs": self.frame.crs,
            "offset": [float(v) for v in self.frame.offset],
            "image_root": image_root if image_root is not None else self.image_root,
            "cameras": {
                cid: {k: v for k, v in cam.as_dict().items() if k != "id"}
                for cid, cam in self.cameras.items()
            },
            "images": [
                {
                    "name": im.name,
                    "path": im.path,
                    "camera": im.camera,
                    "rotation": [[float(v) for v in row] for row in im.R],
                    "center": [float(v) for v in im.C],
                }
                for im in self.images
            ],
        }
        if self.points is not None:
            p = self.points
            pd: dict = {"xyz": p.xyz.tolist()}
            if p.rgb is not None:
                pd["rgb"] = p.rgb.astype(int).tolist()
            if p.error is not None:
                pd["error"] = p.error.tolist()
            pd["observations"] = [
                [int(a), int(b), float(x), float(y)]
                for a, b, (x, y) in zip(p.obs_point, p.obs_image, p.obs_xy, strict=True)
            ]
            d["points"] = pd
        if self.gcps:
            d["gcps"] = [
                {
                    "name": g.name,
                    "role": g.role,
                    "xyz": [float(v) for v in g.xyz],
                    "sigma": None if g.sigma is None else [float(v) for v in g.sigma],
                    "observations": [
                        {"image": i, "x": float(x), "y": float(y)}
                        | ({"sigma": g.obs_sigma[i]} if i in g.obs_sigma else {})
                        for i, x, y in g.observations
                    ],
                }
                for g in self.gcps
            ]
        if self.metadata:
            d["metadata"] = self.metadata
        return d

    def save(self, path: str | os.PathLike) -> None:
        """Write the JSON atomically (temporary file + rename).

        The stored ``image_root`` is made relative to the file's folder when
        possible, absolute otherwise.
        """
        path = Path(path)
        root = Path(self.image_root)
        if not root.is_absolute():
            root = Path(os.path.abspath(root))
        try:
            rel = os.path.relpath(root, path.parent.resolve())
        except ValueError:  # other drive on Windows
            rel = str(root)
        text = json.dumps(self.to_dict(image_root=rel.replace(os.sep, "/")), indent=1, allow_nan=False)
        atomic_write_text(path, text)

    @classmethod
    def from_dict(cls, d: object, source: str = "<orientation>", base_dir: str | None = None) -> Orientation:
        return _from_dict(d, source, base_dir)

    @classmethod
    def load(cls, path: str | os.PathLike) -> Orientation:
        """Read an orientation JSON; errors name the file and the offending field."""
        path = Path(path)
        if not path.is_file():
            raise MissingFileError(path, "orientation file not found")
        if path.stat().st_size > MAX_JSON_BYTES:
            raise FormatError(path, "file too large for an orientation JSON")
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError as err:
            raise FormatError(path, f"not UTF-8 text ({err.reason} at byte {err.start})") from None
        try:
            d = json.loads(text, parse_constant=_reject_constant)
        except json.JSONDecodeError as err:
            raise FormatError(path, f"invalid JSON: {err.msg}", line=err.lineno) from None
        except (ValueError, RecursionError) as err:
            raise FormatError(path, f"invalid JSON: {err}") from None
        return _from_dict(d, str(path), str(path.parent.resolve()))


def _reject_constant(name: str):
    raise ValueError(f"{name} is not allowed")


def atomic_write_text(path: str | os.PathLike, text: str) -> None:
    """Write text to ``path`` through a temporary file in the same folder and rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    try:
        with open(tmp, "w", encoding="utf-8", newline="\n") as fh:
            fh.write(text)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def check_relative_path(p: object, what: str) -> str:
    """Validate a path that must stay below its root: relative, no ``..``, no drive."""
    if not isinstance(p, str) or not p or "\x00" in p or len(p) > 4096:
        raise InputError(f"{what}: expected a non-empty relative path, got {p!r}")
    posix = PurePosixPath(p.replace("\\", "/"))
    if posix.is_absolute() or PureWindowsPath(p).drive or PureWindowsPath(p).is_absolute():
        raise InputError(
            f"{what}: absolute paths are not allowed ({p!r}); give it relative to the image folder"
        )
    if any(part == ".." for part in posix.parts):
        raise InputError(f"{what}: '..' is not allowed in {p!r}; images must lie under the image folder")
    return str(posix)


# ------------------------------------------------------------------ parsing helpers


class _Reader:
    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, field_: str, msg: str) -> NoReturn:
        raise FormatError(self.source, f"{field_}: {msg}")

    def num(self, v: object, field_: str) -> float:
        if isinstance(v, bool) or not isinstance(v, int | float):
            self.fail(field_, f"expected a number, got {type(v).__name__}")
        f = float(v)  # type: ignore[arg-type]
        if not math.isfinite(f) or abs(f) > 1e15:
            self.fail(field_, f"expected a finite number of reasonable size, got {v!r}")
        return f

    def vec(self, v: object, n: int, field_: str) -> np.ndarray:
        if not isinstance(v, list) or len(v) != n:
            self.fail(field_, f"expected a list of {n} numbers")
        return np.array([self.num(x, f"{field_}[{i}]") for i, x in enumerate(v)])  # type: ignore[arg-type]

    def text(self, v: object, field_: str) -> str:
        if not isinstance(v, str) or not v or len(v) > 4096:
            self.fail(field_, "expected a non-empty string")
        return v  # type: ignore[return-value]

    def obj(self, v: object, field_: str) -> dict:
        if not isinstance(v, dict):
            self.fail(field_, f"expected an object, got {type(v).__name__}")
        return v  # type: ignore[return-value]

    def lst(self, v: object, field_: str) -> list:
        if not isinstance(v, list):
            self.fail(field_, f"expected a list, got {type(v).__name__}")
        return v  # type: ignore[return-value]


def _from_dict(d: object, source: str, base_dir: str | None) -> Orientation:
    r = _Reader(source)
    d = r.obj(d, "top level")
    if d.get("format") != FORMAT_NAME:
        r.fail("format", f"expected {FORMAT_NAME!r}, got {d.get('format')!r}")
    version = d.get("version")
    if version != FORMAT_VERSION:
        r.fail("version", f"unsupported version {version!r} (this TruOrtho reads version {FORMAT_VERSION})")
    crs = d.get("crs")
    if crs is not None:
        crs = r.text(crs, "crs")
    offset = r.vec(d.get("offset", [0, 0, 0]), 3, "offset")
    root = d.get("image_root", ".")
    root = r.text(root, "image_root")
    if "\x00" in root:
        r.fail("image_root", "contains a NUL character")
    if base_dir is not None and not os.path.isabs(root):
        root = os.path.normpath(os.path.join(base_dir, root))

    cameras: dict[str, Camera] = {}
    for cid, c in r.obj(d.get("cameras", {}), "cameras").items():
        c = r.obj(c, f"cameras.{cid}")
        kw: dict[str, float] = {}
        for key in ("fx", "fy", "cx", "cy", "k1", "k2", "k3", "p1", "p2"):
            if key in c:
                kw[key] = r.num(c[key], f"cameras.{cid}.{key}")
            elif key in ("fx", "fy", "cx", "cy"):
                r.fail(f"cameras.{cid}.{key}", "missing")
        size = []
        for key in ("width", "height"):
            v = c.get(key)
            if isinstance(v, bool) or not isinstance(v, int) or not 0 < v <= 10**6:
                r.fail(f"cameras.{cid}.{key}", f"expected a positive integer, got {v!r}")
            size.append(v)
        try:
            cameras[cid] = Camera(size[0], size[1], id=cid, **kw)
        except InputError as err:
            r.fail(f"cameras.{cid}", str(err))

    images: list[Image] = []
    for i, im in enumerate(r.lst(d.get("images", []), "images")):
        im = r.obj(im, f"images[{i}]")
        name = r.text(im.get("name"), f"images[{i}].name")
        cam = r.text(im.get("camera"), f"images[{i}].camera")
        if cam not in cameras:
            r.fail(f"images[{i}].camera", f"unknown camera {cam!r}")
        rows = r.lst(im.get("rotation"), f"images[{i}].rotation")
        if len(rows) != 3:
            r.fail(f"images[{i}].rotation", "expected 3 rows")
        R = np.array([r.vec(row, 3, f"images[{i}].rotation[{j}]") for j, row in enumerate(rows)])
        C = r.vec(im.get("center"), 3, f"images[{i}].center")
        path = im.get("path", name)
        try:
            path = check_relative_path(path, f"images[{i}].path")
            images.append(Image(name, cam, R, C, path))
        except InputError as err:
            r.fail(f"images[{i}]", str(err))

    points = None
    if d.get("points") is not None:
        p = r.obj(d["points"], "points")
        xyz = np.array(
            [r.vec(v, 3, f"points.xyz[{k}]") for k, v in enumerate(r.lst(p.get("xyz", []), "points.xyz"))]
        )
        rgb = None
        if p.get("rgb") is not None:
            rgb = np.array(
                [r.vec(v, 3, f"points.rgb[{k}]") for k, v in enumerate(r.lst(p["rgb"], "points.rgb"))]
            )
        err_ = None
        if p.get("error") is not None:
            err_ = np.array(
                [r.num(v, f"points.error[{k}]") for k, v in enumerate(r.lst(p["error"], "points.error"))]
            )
        obs = [
            r.vec(v, 4, f"points.observations[{k}]")
            for k, v in enumerate(r.lst(p.get("observations", []), "points.observations"))
        ]
        oa = np.array(obs).reshape(-1, 4)
        if np.any(oa[:, :2] != np.round(oa[:, :2])):
            r.fail("points.observations", "point and image indices must be integers")
        try:
            points = SparsePoints(
                xyz.reshape(-1, 3), rgb, err_, oa[:, 0].astype(np.int64), oa[:, 1].astype(np.int64), oa[:, 2:]
            )
        except InputError as err:
            r.fail("points", str(err))

    gcps: list[GCP] = []
    for i, g in enumerate(r.lst(d.get("gcps", []) or [], "gcps")):
        g = r.obj(g, f"gcps[{i}]")
        name = r.text(g.get("name"), f"gcps[{i}].name")
        xyz = r.vec(g.get("xyz"), 3, f"gcps[{i}].xyz")
        sigma = None if g.get("sigma") is None else r.vec(g["sigma"], 3, f"gcps[{i}].sigma")
        gobs: list[tuple[str, float, float]] = []
        gsig: dict[str, float] = {}
        for k, o in enumerate(r.lst(g.get("observations", []), f"gcps[{i}].observations")):
            o = r.obj(o, f"gcps[{i}].observations[{k}]")
            gobs.append(
                (
                    r.text(o.get("image"), f"gcps[{i}].observations[{k}].image"),
                    r.num(o.get("x"), f"gcps[{i}].observations[{k}].x"),
                    r.num(o.get("y"), f"gcps[{i}].observations[{k}].y"),
                )
            )
            if o.get("sigma") is not None:
                gsig[gobs[-1][0]] = r.num(o.get("sigma"), f"gcps[{i}].observations[{k}].sigma")
        try:
            gcps.append(GCP(name, xyz, g.get("role", "gcp"), sigma, gobs, gsig))
        except InputError as err:
            r.fail(f"gcps[{i}]", str(err))

    meta = d.get("metadata") or {}
    if not isinstance(meta, dict):
        r.fail("metadata", "expected an object")
    try:
        o = Orientation(LocalFrame(crs, offset), cameras, images, points, gcps, root, meta)
        o.validate()
    except InputError as err:
        raise FormatError(source, str(err)) from None
    return o


def as_orientation(orientation, name: str = "ORIENTATION") -> Orientation:
    """An :class:`Orientation` given as itself or as the path of its JSON file."""
    if isinstance(orientation, Orientation):
        return orientation
    if isinstance(orientation, str | os.PathLike):
        return Orientation.load(orientation)
    raise InputError(f"{name}: expected an orientation file or object, got {type(orientation).__name__}")
