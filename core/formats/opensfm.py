"""OpenSfM / OpenDroneMap ``reconstruction.json``.

Cameras (``projection_type`` perspective, simple_radial, radial, brown) use
lengths normalised by ``m = max(w, h)`` with the principal point as an offset
from the image centre; OpenSfM's pixel normalisation is
``x_n = (x + 0.5 - w / 2) / m``, so ours is ``x = x_n m + w / 2 - 0.5``,
i.e. ``fx = focal_x m``, ``cx = (w - 1) / 2 + c_x m``. Brown ``k1, k2, k3,
p1, p2`` is OpenCV's 5-coefficient model. Shots: ``rotation`` is the
axis-angle of the world-to-camera rotation, ``X_cam = R X + translation``,
so ``C = -R^T t``; the shot id is the image name.

Georeferencing
--------------
With a ``reference_lla`` (inside the reconstruction or in
``reference_lla.json`` beside it) the reconstruction lives in OpenSfM's
topocentric frame: east-north-up axes at the reference point on the WGS84
ellipsoid (altitude taken as ellipsoidal height). It is converted to a
projected CRS (``crs`` argument, default the UTM zone of the reference):

* positions (camera centres, points) rigorously, point by point:
  ENU -> ECEF (exact affine map) -> CRS with pyproj (EPSG:4978 -> CRS,
  heights stay ellipsoidal);
* each camera rotation by ``R' = R Q^T`` where ``Q`` is the nearest rotation
  (SVD) to the Jacobian ``J`` of the ENU -> CRS map at the camera centre,
  estimated by central finite differences (+-1 m). ``Q`` holds the grid
  convergence and the tilt of the local vertical.

A projected CRS with ellipsoidal heights is not a Euclidean space, and a
rigid camera cannot absorb its distortions, so projections change slightly:

* horizontal scale: ``J ~ diag(s, s, 1) Q`` with ``s = k R / (R + h)`` (``k``
  the projection's scale factor, ``h`` the ellipsoidal height, ``R`` the
  earth radius); image positions move by about ``|s - 1| r`` at ``r`` pixels
  from the principal point (UTM on its central meridian, ``k = 0.9996``:
  0.4 px at 1000 px);
* earth curvature (verticals converge, grid heights do not): about
  ``r H / (2 R)`` for a flying height ``H`` above the ground, even where
  ``s = 1`` (H = 110 m: 0.02 px at r = 2500 px).

Tested: a 500 m block at 110 m flying height reprojects to < 0.01 px with
1368-px-wide cameras where the CRS scale is 1 at the block, and within the
two bounds above otherwise (tests/core/test_formats.py).
Without ``reference_lla`` the frame is kept as is
with ``crs = None``.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ..errors import FormatError, InputError
from ..geometry.camera import Camera
from ..geometry.frame import (
    LocalFrame,
    choose_offset,
    crs_to_text,
    parse_crs,
    require_metric,
    transform_points,
)
from ..geometry.rotation import axis_angle_to_matrix, orthonormalize
from ..orientation import Image, Orientation, SparsePoints
from ._text import ValueReader, check_name, load_json

SUPPORTED = ("perspective", "simple_radial", "radial", "brown")
_DIST = {
    "perspective": ("k1", "k2"),
    "simple_radial": ("k1",),
    "radial": ("k1", "k2"),
    "brown": ("k1", "k2", "k3", "p1", "p2"),
}


def _camera(r: ValueReader, cid: str, c: dict) -> Camera:
    ptype = c.get("projection_type", "perspective")
    if ptype not in SUPPORTED:
        r.fail(
            f"cameras.{cid}.projection_type",
            f"unsupported projection {ptype!r}; supported: {', '.join(SUPPORTED)}",
        )
    w = r.size(c.get("width"), f"cameras.{cid}.width")
    h = r.size(c.get("height"), f"cameras.{cid}.height")
    m = max(w, h)
    if "focal_x" in c or "focal_y" in c:
        fx = r.num(c.get("focal_x"), f"cameras.{cid}.focal_x")
        fy = r.num(c.get("focal_y"), f"cameras.{cid}.focal_y")
    else:
        fx = fy = r.num(c.get("focal"), f"cameras.{cid}.focal")
    ccx = r.num(c.get("c_x", 0.0), f"cameras.{cid}.c_x")
    ccy = r.num(c.get("c_y", 0.0), f"cameras.{cid}.c_y")
    dist = {k: r.num(c.get(k, 0.0), f"cameras.{cid}.{k}") for k in _DIST[ptype]}
    try:
        return Camera(w, h, fx * m, fy * m, (w - 1) / 2 + ccx * m, (h - 1) / 2 + ccy * m, id=cid, **dist)
    except InputError as err:
        r.fail(f"cameras.{cid}", str(err))
        raise  # unreachable


def _ecef_from_enu(lat: float, lon: float, alt: float) -> tuple[np.ndarray, np.ndarray]:
    """``(origin, M)`` with ``ecef = origin + M @ enu`` at a WGS84 reference."""
    origin = transform_points([[lon, lat, alt]], "EPSG:4979", "EPSG:4978")[0]
    p, la = math.radians(lat), math.radians(lon)
    M = np.array(
        [
            [-math.sin(la), -math.sin(p) * math.cos(la), math.cos(p) * math.cos(la)],
            [math.cos(la), -math.sin(p) * math.sin(la), math.cos(p) * math.sin(la)],
            [0.0, math.cos(p), math.sin(p)],
        ]
    )
    return origin, M


def utm_crs(lat: float, lon: float) -> str:
    """EPSG code text of the WGS84 UTM zone containing a point (no Norway/Svalbard exceptions)."""
    zone = int((lon + 180.0) // 6.0) % 60 + 1
    return f"EPSG:{(32700 if lat < 0 else 32600) + zone}"


class _Topocentric:
    """ENU at a WGS84 reference -> projected CRS (positions exact, rotations local)."""

    def __init__(self, lla: tuple[float, float, float], crs: str) -> None:
        from pyproj import Transformer

        self.origin, self.M = _ecef_from_enu(*lla)
        self.tr = Transformer.from_crs("EPSG:4978", crs, always_xy=True)

    def __call__(self, enu) -> np.ndarray:
        e = np.asarray(enu, dtype=np.float64).reshape(-1, 3)
        ecef = self.origin + e @ self.M.T
        x, y, z = self.tr.transform(ecef[:, 0], ecef[:, 1], ecef[:, 2], errcheck=True)
        return np.column_stack([x, y, z])

    def rotation(self, enu_point, step: float = 1.0) -> np.ndarray:
        """Nearest rotation to the Jacobian (CRS from ENU) at a point."""
        p = np.asarray(enu_point, dtype=np.float64)
        probes = np.vstack([p + step * np.eye(3), p - step * np.eye(3)])
        q = self(probes)
        J = (q[:3] - q[3:]).T / (2 * step)  # columns: d(CRS)/d(e), d/dn, d/du
        return orthonormalize(J)


def _reference(r: ValueReader, rec: dict, path: Path) -> tuple[float, float, float] | None:
    ref = rec.get("reference_lla")
    src = r
    if ref is None:
        side = path.with_name("reference_lla.json")
        if not side.is_file():
            return None
        src = ValueReader(side)
        ref = load_json(side, "reference_lla.json")
    ref = src.obj(ref, "reference_lla")
    lat = src.num(ref.get("latitude"), "reference_lla.latitude")
    lon = src.num(ref.get("longitude"), "reference_lla.longitude")
    alt = src.num(ref.get("altitude", 0.0), "reference_lla.altitude")
    if not (-90 < lat < 90 and -180 <= lon <= 360 and abs(alt) < 1e5):
        src.fail("reference_lla", f"out of range: latitude {lat}, longitude {lon}, altitude {alt}")
    return lat, lon, alt


def read_opensfm(path: str | os.PathLike, crs: object = None) -> Orientation:
    """Read an OpenSfM ``reconstruction.json``.

    Parameters
    ----------
    path : path
        The reconstruction file (a JSON list of reconstructions; the one with
        the most shots is read, the others are reported in ``metadata["warnings"]``).
    crs : str or int, optional
        Target projected CRS for a georeferenced (``reference_lla``)
        reconstruction; default the UTM zone of the reference.

    Returns
    -------
    Orientation

    Raises
    ------
    FormatError, MissingFileError, CRSError
    """
    from pyproj.exceptions import ProjError

    path = Path(path)
    r = ValueReader(path)
    data = load_json(path, "reconstruction.json")
    if isinstance(data, dict):
        data = [data]
    if not isinstance(data, list) or not data:
        raise FormatError(path, "top level: expected a list of reconstructions")
    recs = [r.obj(rec, f"reconstruction[{i}]") for i, rec in enumerate(data)]
    sizes = [len(rec["shots"]) if isinstance(rec.get("shots"), dict) else 0 for rec in recs]
    best = int(np.argmax(sizes))
    rec = recs[best]
    warnings = []
    if len(recs) > 1:
        others = ", ".join(f"#{i} ({s} shots)" for i, s in enumerate(sizes) if i != best)
        warnings.append(
            f"the file holds {len(recs)} reconstructions; read #{best} ({sizes[best]} shots), "
            f"ignored {others}"
        )

    cameras = {}
    for cid, c in r.obj(rec.get("cameras"), "cameras").items():
        cameras[cid] = _camera(r, r.text(cid, "camera id"), r.obj(c, f"cameras.{cid}"))
    names, cams, Rs, Cs = [], [], [], []
    for sid, s in r.obj(rec.get("shots"), "shots").items():
        s = r.obj(s, f"shots.{sid}")
        name = check_name(sid, path, None, f"shot {sid!r}")
        cam = s.get("camera")
        if not isinstance(cam, str) or cam not in cameras:
            r.fail(f"shots.{sid}.camera", f"unknown camera {cam!r}")
        try:
            R = axis_angle_to_matrix(r.vec(s.get("rotation"), 3, f"shots.{sid}.rotation"))
        except InputError as err:
            r.fail(f"shots.{sid}.rotation", str(err))
        t = np.array(r.vec(s.get("translation"), 3, f"shots.{sid}.translation"))
        names.append(name)
        cams.append(cam)
        Rs.append(R)
        Cs.append(-R.T @ t)
    xyz, rgb = [], []
    for pid, p in r.obj(rec.get("points", {}), "points").items():
        p = r.obj(p, f"points.{pid}")
        xyz.append(r.vec(p.get("coordinates"), 3, f"points.{pid}.coordinates"))
        col = r.vec(p.get("color", [128, 128, 128]), 3, f"points.{pid}.color")
        if any(not 0 <= v <= 255 for v in col):
            r.fail(f"points.{pid}.color", f"expected 0..255, got {col}")
        rgb.append(col)
    Cw = np.array(Cs).reshape(-1, 3)
    Pw = np.array(xyz).reshape(-1, 3)

    ref = _reference(r, rec, path)
    crs_text = None
    if ref is not None:
        pc = parse_crs(crs if crs is not None else utm_crs(ref[0], ref[1]))
        require_metric(pc, "target CRS")
        crs_text = crs_to_text(pc)
        topo = _Topocentric(ref, pc.to_wkt())
        try:
            Rs = [R @ topo.rotation(C).T for R, C in zip(Rs, Cw, strict=False)]
            Cw, Pw = topo(Cw), topo(Pw)
        except ProjError as err:
            raise FormatError(path, f"cannot transform the reconstruction to {crs_text}: {err}") from None
        if not (np.all(np.isfinite(Cw)) and np.all(np.isfinite(Pw))):
            r.fail("reference_lla", f"the reconstruction does not transform to {crs_text}")
        offset = choose_offset(Cw)
        warnings.append(
            "topocentric frame converted to the CRS: see truortho.core.formats.opensfm for accuracy"
        )
    else:
        offset = np.zeros(3)
    try:
        images = [Image(n, c, R, C - offset, n) for n, c, R, C in zip(names, cams, Rs, Cw, strict=False)]
        points = SparsePoints(Pw - offset, np.array(rgb).reshape(-1, 3)) if len(Pw) else None
        o = Orientation(LocalFrame(crs_text, offset), cameras, images, points)
        o.validate()
    except InputError as err:
        raise FormatError(path, str(err)) from None
    o.metadata["source"] = {"format": "opensfm", "file": str(path)}
    if ref is not None:
        o.metadata["reference_lla"] = {"latitude": ref[0], "longitude": ref[1], "altitude": ref[2]}
    if warnings:
        o.metadata["warnings"] = warnings
    return o
