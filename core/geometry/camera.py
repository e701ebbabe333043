"""Pinhole camera with Brown/OpenCV distortion; conventions in :mod:`truortho.core.geometry`.

Public functions validate and broadcast; the numba kernels (``_...``) take
contiguous float64 arrays and never raise. Parameters travel to kernels as one
float64 vector ``params = [fx, fy, cx, cy, k1, k2, k3, p1, p2]``.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ..errors import InputError
from ..jit import njit, pjit, prange

PARAM_NAMES = ("fx", "fy", "cx", "cy", "k1", "k2", "k3", "p1", "p2")
DISTORTION_NAMES = ("k1", "k2", "k3", "p1", "p2")


@dataclass
class Camera:
    """Interior orientation of one physical camera (pixels).

    Parameters
    ----------
    width, height : int
        Image size in pixels of the images taken with this camera.
    fx, fy : float
        Focal lengths in pixels.
    cx, cy : float
        Principal point in pixels, (0, 0) = centre of the top-left pixel.
    k1, k2, k3, p1, p2 : float
        Brown/OpenCV radial and tangential distortion.
    id : str
        Identifier used by images to refer to this camera.
    """

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    k1: float = 0.0
    k2: float = 0.0
    k3: float = 0.0
    p1: float = 0.0
    p2: float = 0.0
    id: str = "camera"

    def __post_init__(self) -> None:
        self.validate()

    def validate(self) -> None:
        for name in ("width", "height"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | np.integer) or v <= 0 or v > 10**6:
                raise InputError(f"camera {self.id!r}: {name} must be a positive integer, got {v!r}")
            setattr(self, name, int(v))
        for name in PARAM_NAMES:
            v = getattr(self, name)
            try:
                fv = float(v)
            except (TypeError, ValueError):
                raise InputError(f"camera {self.id!r}: {name} must be a number, got {v!r}") from None
            if not np.isfinite(fv) or abs(fv) > 1e12:
                raise InputError(f"camera {self.id!r}: {name} must be finite, got {v!r}")
            setattr(self, name, fv)
        if self.fx <= 0 or self.fy <= 0:
            raise InputError(
                f"camera {self.id!r}: focal lengths must be positive (fx={self.fx}, fy={self.fy})"
            )

    @property
    def params(self) -> np.ndarray:
        """``[fx, fy, cx, cy, k1, k2, k3, p1, p2]`` as float64."""
        return np.array([getattr(self, n) for n in PARAM_NAMES], dtype=np.float64)

    @classmethod
    def from_params(cls, params, width: int, height: int, id: str = "camera") -> Camera:
        p = np.asarray(params, dtype=np.float64).reshape(-1)
        if p.shape != (9,):
            raise InputError(f"camera {id!r}: expected 9 parameters {PARAM_NAMES}, got {p.shape}")
        return cls(width, height, **{n: float(v) for n, v in zip(PARAM_NAMES, p, strict=True)}, id=id)

    @property
    def K(self) -> np.ndarray:
        """3x3 calibration matrix (pixel-centre origin)."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @property
    def dist_coeffs(self) -> np.ndarray:
        """OpenCV order ``(k1, k2, p1, p2, k3)``."""
        return np.array([self.k1, self.k2, self.p1, self.p2, self.k3])

    @property
    def has_distortion(self) -> bool:
        return any(getattr(self, n) != 0.0 for n in DISTORTION_NAMES)

    def as_dict(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def project_camera(self, xyz_cam) -> np.ndarray:
        """Pixels of points given in camera coordinates, shape (N, 3) -> (N, 2)."""
        pts = _points(xyz_cam, "xyz_cam")
        return _project_cam(pts, self.params)

    def distort(self, xy_norm) -> np.ndarray:
        """Pixels of undistorted normalised coordinates ``(X/Z, Y/Z)``, (N, 2) -> (N, 2)."""
        xy = _points(xy_norm, "xy_norm", 2)
        return _distort(xy, self.params)

    def undistort(self, uv, iterations: int = 20) -> np.ndarray:
        """Undistorted normalised coordinates of pixels, (N, 2) -> (N, 2)."""
        return undistort_points(uv, self, iterations)

    def scaled(self, factor: float, factor_y: float | None = None) -> Camera:
        """The camera of the same images resampled by ``factor`` (e.g. 0.5 = half size), or by
        ``factor`` in x and ``factor_y`` in y.

        Pixel centres map as ``x' = (x + 0.5) * factor - 0.5``.
        """
        fy = factor if factor_y is None else factor_y
        if not (factor > 0 and fy > 0):
            raise InputError(f"scale factor must be positive, got {factor}, {fy}")
        w = max(1, int(round(self.width * factor)))
        h = max(1, int(round(self.height * fy)))
        return Camera(
            w,
            h,
            self.fx * factor,
            self.fy * fy,
            (self.cx + 0.5) * factor - 0.5,
            (self.cy + 0.5) * fy - 0.5,
            self.k1,
            self.k2,
            self.k3,
            self.p1,
            self.p2,
            id=self.id,
        )


def _points(a, name: str, dim: int = 3) -> np.ndarray:
    arr = np.asarray(a, dtype=np.float64)
    if arr.ndim == 1 and arr.shape[0] == dim:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != dim:
        raise InputError(f"{name}: expected shape (N, {dim}), got {np.shape(a)}")
    return np.ascontiguousarray(arr)


# ---------------------------------------------------------------- kernels


@njit
def _distort_one(x, y, p):
    r2 = x * x + y * y
    radial = 1.0 + r2 * (p[4] + r2 * (p[5] + r2 * p[6]))
    xd = x * radial + 2.0 * p[7] * x * y + p[8] * (r2 + 2.0 * x * x)
    yd = y * radial + p[7] * (r2 + 2.0 * y * y) + 2.0 * p[8] * x * y
    return p[0] * xd + p[2], p[1] * yd + p[3]


@pjit
def _distort(xy, p):
    n = xy.shape[0]
    out = np.empty((n, 2))
    for i in prange(n):
        u, v = _distort_one(xy[i, 0], xy[i, 1], p)
        out[i, 0] = u
        out[i, 1] = v
    return out


@pjit
def _project_cam(xyz, p):
    n = xyz.shape[0]
    out = np.empty((n, 2))
    for i in prange(n):
        z = xyz[i, 2]
        if z > 0.0:
            u, v = _distort_one(xyz[i, 0] / z, xyz[i, 1] / z, p)
            out[i, 0] = u
            out[i, 1] = v
        else:
            out[i, 0] = np.nan
            out[i, 1] = np.nan
    return out


@pjit
def _project_world(X, R, C, p, uv, depth):
    n = X.shape[0]
    for i in prange(n):
        dx = X[i, 0] - C[0]
        dy = X[i, 1] - C[1]
        dz = X[i, 2] - C[2]
        xc = R[0, 0] * dx + R[0, 1] * dy + R[0, 2] * dz
        yc = R[1, 0] * dx + R[1, 1] * dy + R[1, 2] * dz
        zc = R[2, 0] * dx + R[2, 1] * dy + R[2, 2] * dz
        depth[i] = zc
        if zc > 0.0:
            u, v = _distort_one(xc / zc, yc / zc, p)
            uv[i, 0] = u
            uv[i, 1] = v
        else:
            uv[i, 0] = np.nan
            uv[i, 1] = np.nan


@njit
def _undistort_one(u, v, p, iterations):
    """Newton iterations on the distortion model; returns (x, y, converged)."""
    xd = (u - p[2]) / p[0]
    yd = (v - p[3]) / p[1]
    x = xd
    y = yd
    k1 = p[4]
    k2 = p[5]
    k3 = p[6]
    p1 = p[7]
    p2 = p[8]
    for _ in range(iterations):
        r2 = x * x + y * y
        radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
        fx = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x) - xd
        fy = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y - yd
        if abs(fx) < 1e-15 and abs(fy) < 1e-15:
            return x, y, True
        drad = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2)  # d(radial)/d(r2)
        j00 = radial + 2.0 * x * x * drad + 2.0 * p1 * y + 6.0 * p2 * x
        j01 = 2.0 * x * y * drad + 2.0 * p1 * x + 2.0 * p2 * y
        j10 = 2.0 * x * y * drad + 2.0 * p1 * x + 2.0 * p2 * y
        j11 = radial + 2.0 * y * y * drad + 6.0 * p1 * y + 2.0 * p2 * x
        det = j00 * j11 - j01 * j10
        if abs(det) < 1e-12:
            return x, y, False
        dx = (j11 * fx - j01 * fy) / det
        dy = (j00 * fy - j10 * fx) / det
        x -= dx
        y -= dy
    r2 = x * x + y * y
    radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
    fx = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x) - xd
    fy = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y - yd
    return x, y, abs(fx) < 1e-10 and abs(fy) < 1e-10


@pjit
def _undistort(uv, p, iterations):
    n = uv.shape[0]
    out = np.empty((n, 2))
    for i in prange(n):
        x, y, ok = _undistort_one(uv[i, 0], uv[i, 1], p, iterations)
        if ok:
            out[i, 0] = x
            out[i, 1] = y
        else:
            out[i, 0] = np.nan
            out[i, 1] = np.nan
    return out


# ------------------------------------------------------------- public API


def project_points(points, R, C, camera: Camera, return_depth: bool = False):
    """Project local-frame points into an image.

    Parameters
    ----------
    points : (N, 3) float64
        Points in the local frame, metres.
    R : (3, 3) float64
        World-to-camera rotation.
    C : (3,) float64
        Projection centre in the local frame.
    camera : Camera
        Interior orientation.
    return_depth : bool
        Also return the depth (camera z) of every point.

    Returns
    -------
    uv : (N, 2) float64
        Pixel coordinates; NaN for points behind the camera (depth <= 0).
    depth : (N,) float64, only when ``return_depth``
    """
    X = _points(points, "points")
    Rm = np.ascontiguousarray(np.asarray(R, dtype=np.float64))
    Cv = np.ascontiguousarray(np.asarray(C, dtype=np.float64).reshape(-1))
    if Rm.shape != (3, 3) or Cv.shape != (3,):
        raise InputError("project_points: R must be 3x3 and C a 3-vector")
    uv = np.empty((X.shape[0], 2))
    depth = np.empty(X.shape[0])
    _project_world(X, Rm, Cv, camera.params, uv, depth)
    return (uv, depth) if return_depth else uv


def undistort_points(uv, camera: Camera, iterations: int = 20) -> np.ndarray:
    """Normalised, undistorted image coordinates ``(X/Z, Y/Z)`` of pixels.

    Newton's method on the distortion model; pixels where it does not converge
    (far outside the valid field of a strong distortion) give NaN.
    """
    pts = _points(uv, "uv", 2)
    return _undistort(pts, camera.params, int(iterations))


def pixel_to_ray(uv, R, C, camera: Camera):
    """Viewing rays of pixels in the local frame.

    Returns
    -------
    origin : (3,) float64
        The projection centre ``C``.
    directions : (N, 3) float64
        Unit direction vectors (NaN where undistortion failed).
    """
    xy = undistort_points(uv, camera)
    d_cam = np.column_stack([xy, np.ones(len(xy))])
    d = d_cam @ np.asarray(R, dtype=np.float64)  # R^T d_cam, row-wise
    d = d / np.linalg.norm(d, axis=1, keepdims=True)
    return np.asarray(C, dtype=np.float64).reshape(3).copy(), d
