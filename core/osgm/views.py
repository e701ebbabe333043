"""Images as OSGM sees them: plane maps, image pyramids and windows.

A voxel ``(X, Y, Z)`` of a reference system projects into an image through
the collinearity equations with Brown distortion (:mod:`..geometry.camera`).
For one Z plane of a tile the projections of all cell centres form a
*plane map* (two float32 arrays of pixel coordinates, :func:`plane_map`),
which OpenCV's ``remap`` turns into a slice of the image resampled onto the
object grid. No rectification and no depth map of any image pair is built.

Pixels beyond the radius where the distortion polynomial stops being
monotonic are never used (:func:`monotonic_radius2`): there the model folds
back and would map far-away object points into the frame.

:class:`ImagePyramid` serves the matching band (luminance by default) of an
image at the reduced level whose pixel is closest to (not larger than) the
object cell, by windows: tiled GeoTIFF/VRT/JPEG 2000 sources are read window
by window at that level (rasterio uses their overviews), other formats are
decoded once and kept in a least-recently-used cache bounded in bytes.
"""

from __future__ import annotations

import math
from collections import OrderedDict

import numpy as np

from ..errors import InputError
from ..geometry.camera import Camera, _distort_one
from ..imagery import (
    _use_rasterio,
    check_image_size,
    image_info,
    level_size,
    luminance,
    read_image_level,
    read_level_window,
)
from ..jit import njit


def monotonic_radius2(camera: Camera, limit: float = 4.0) -> float:
    """Largest squared normalised radius up to which ``r (1 + k1 r^2 + k2 r^4 + k3 r^6)`` increases."""
    k1, k2, k3 = camera.k1, camera.k2, camera.k3
    r = np.linspace(0.0, math.sqrt(limit), 4001)
    r2 = r * r
    d = 1.0 + 3.0 * k1 * r2 + 5.0 * k2 * r2 * r2 + 7.0 * k3 * r2 * r2 * r2
    bad = np.nonzero(d <= 0.05)[0]
    rmax = r[bad[0] - 1] if bad.size else r[-1]
    return float(rmax * rmax)


@njit
def _plane_map(x0, y0, res, rows, cols, z, R, C, p, r2max, scale, shift_u, shift_v, mu, mv):
    """Pixel coordinates (at a pyramid level, minus a window origin) of cell centres at height z."""
    for r in range(rows):
        Y = y0 - (r + 0.5) * res
        for c in range(cols):
            X = x0 + (c + 0.5) * res
            dx = X - C[0]
            dy = Y - C[1]
            dz = z - C[2]
            xc = R[0, 0] * dx + R[0, 1] * dy + R[0, 2] * dz
            yc = R[1, 0] * dx + R[1, 1] * dy + R[1, 2] * dz
            zc = R[2, 0] * dx + R[2, 1] * dy + R[2, 2] * dz
            if zc <= 0.0:
                mu[r, c] = -1e6
                mv[r, c] = -1e6
                continue
            xn = xc / zc
            yn = yc / zc
            if xn * xn + yn * yn > r2max:
                mu[r, c] = -1e6
                mv[r, c] = -1e6
                continue
            u, v = _distort_one(xn, yn, p)
            mu[r, c] = (u + 0.5) * scale - 0.5 - shift_u
            mv[r, c] = (v + 0.5) * scale - 0.5 - shift_v


def plane_map(x0, y0, res, rows, cols, z, R, C, camera: Camera, r2max, level=0, origin=(0, 0)):
    """Float32 maps ``(mu, mv)`` for ``cv2.remap``: where cell centres at height ``z`` fall.

    ``(x0, y0)`` is the outer north-west corner of the cell window in the
    (local) frame of ``R``/``C``; coordinates are pixels of pyramid level
    ``level`` (halvings) minus ``origin`` (the window's top-left pixel).
    Invalid projections (behind the camera, beyond the monotonic radius) get
    -1e6 (outside every window).
    """
    mu = np.empty((rows, cols), np.float32)
    mv = np.empty((rows, cols), np.float32)
    _plane_map(
        float(x0),
        float(y0),
        float(res),
        int(rows),
        int(cols),
        float(z),
        np.ascontiguousarray(R, np.float64),
        np.ascontiguousarray(C, np.float64),
        camera.params,
        float(r2max),
        0.5 ** int(level),
        float(origin[0]),
        float(origin[1]),
        mu,
        mv,
    )
    return mu, mv


@njit
def _project_many(P, R, C, p, r2max, out):
    for i in range(P.shape[0]):
        dx = P[i, 0] - C[0]
        dy = P[i, 1] - C[1]
        dz = P[i, 2] - C[2]
        xc = R[0, 0] * dx + R[0, 1] * dy + R[0, 2] * dz
        yc = R[1, 0] * dx + R[1, 1] * dy + R[1, 2] * dz
        zc = R[2, 0] * dx + R[2, 1] * dy + R[2, 2] * dz
        if zc <= 0.0 or (xc / zc) ** 2 + (yc / zc) ** 2 > r2max:
            out[i, 0] = np.nan
            out[i, 1] = np.nan
        else:
            u, v = _distort_one(xc / zc, yc / zc, p)
            out[i, 0] = u
            out[i, 1] = v


def project(P, R, C, camera: Camera, r2max) -> np.ndarray:
    """Pixels (N, 2) of points (N, 3) of the frame of ``R``/``C``; NaN where not valid."""
    P = np.ascontiguousarray(np.asarray(P, np.float64).reshape(-1, 3))
    out = np.empty((len(P), 2))
    _project_many(
        P,
        np.ascontiguousarray(R, np.float64),
        np.ascontiguousarray(C, np.float64),
        camera.params,
        float(r2max),
        out,
    )
    return out


class ImagePyramid:
    """Matching band and colours of the images, by pyramid level and window.

    Parameters
    ----------
    paths : list of str
    sizes : list of (width, height)
        The sizes the cameras expect (checked on first read).
    band : int or None
        0-based band to match on; None: luminance (Rec. 601 of the first three
        bands, or the first band).
    max_bytes : int
        Budget of the cache of decoded images.
    """

    def __init__(self, paths, sizes, band: int | None = None, max_bytes: int = 1 << 30) -> None:
        self.paths = [str(p) for p in paths]
        self.sizes = [tuple(int(v) for v in s) for s in sizes]
        self.band = band
        self.max_bytes = int(max_bytes)
        self._cache: OrderedDict = OrderedDict()
        self._bytes = 0
        self.reads = 0
        self._windowed = [_use_rasterio(p) for p in self.paths]
        self._value_max: dict[int, float] = {}

    # ------------------------------------------------------------ cache
    def _put(self, key, value) -> None:
        self._cache[key] = value
        self._bytes += value.nbytes
        while self._bytes > self.max_bytes and len(self._cache) > 1:
            _, old = self._cache.popitem(last=False)
            self._bytes -= old.nbytes

    def _full(self, i: int, level: int, colour: bool) -> np.ndarray:
        key = (i, level, colour)
        if key in self._cache:
            self._cache.move_to_end(key)
            return self._cache[key]
        # only the level asked for is cached (JPEGs decode directly at up to 1/8 scale); the
        # conversion to float comes before any area halving, which then does not round
        out = read_image_level(self.paths[i], self.sizes[i], level, lambda img: self._convert(img, colour))
        self.reads += 1
        self._put(key, out)
        return out

    def _convert(self, img: np.ndarray, colour: bool) -> np.ndarray:
        if colour:
            rgb = img if img.ndim == 3 else img[:, :, None]
            rgb = rgb[:, :, :3] if rgb.shape[2] >= 3 else rgb[:, :, :1]
            return np.ascontiguousarray(rgb.astype(np.float32))
        if self.band is not None:
            nb = 1 if img.ndim == 2 else img.shape[2]
            if not 0 <= self.band < nb:
                raise InputError(
                    f"BAND: band {self.band + 1} does not exist in {self.paths[0]} ({nb} band(s))"
                )
            b = img if img.ndim == 2 else img[:, :, self.band]
            return np.ascontiguousarray(b.astype(np.float32))
        return luminance(img)

    def value_max(self, i: int) -> float:
        """Full-scale value of image ``i`` (255 for 8-bit, 65535 for 16-bit, 1 for float data)."""
        if i not in self._value_max:
            dt = np.dtype(image_info(self.paths[i]).dtype)
            self._value_max[i] = float(np.iinfo(dt).max) if dt.kind in "ui" else 1.0
        return self._value_max[i]

    def level_size(self, i: int, level: int) -> tuple[int, int]:
        """(width, height) of image ``i`` at ``level`` (:func:`~truortho.core.imagery.level_size`)."""
        return level_size(self.sizes[i], level)

    def window(
        self, i: int, level: int, x0: int, y0: int, w: int, h: int, colour: bool = False
    ) -> np.ndarray:
        """Window ``[x0, x0 + w) x [y0, y0 + h)`` of level ``level`` (float32, NaN outside the image)."""
        W, H = self.level_size(i, level)
        ix0, iy0, ix1, iy1 = max(x0, 0), max(y0, 0), min(x0 + w, W), min(y0 + h, H)
        nb = 3 if colour else 1
        out = np.full((h, w, nb) if colour else (h, w), np.nan, np.float32)
        if ix1 <= ix0 or iy1 <= iy0:
            return out
        if self._windowed[i]:
            part = self._read_window(i, level, ix0, iy0, ix1 - ix0, iy1 - iy0, colour)
        else:
            part = self._full(i, level, colour)[iy0:iy1, ix0:ix1]
        if colour and part.ndim == 2:
            part = part[:, :, None]
        if colour and part.shape[2] == 1:
            part = np.repeat(part, 3, axis=2)
        out[iy0 - y0 : iy1 - y0, ix0 - x0 : ix1 - x0] = part
        return out

    def _read_window(self, i, level, x0, y0, w, h, colour) -> np.ndarray:
        """Windowed read of a rasterio source at a reduced level (its overviews when present)."""
        img = read_level_window(self.paths[i], self.sizes[i], level, x0, y0, w, h)
        self.reads += 1
        out = self._convert(img, colour)
        if out.ndim == 2 and colour:
            out = out[:, :, None]
        return out


def check_images(paths, sizes) -> None:
    """Every image exists, is readable and has its camera's size (before anything is written)."""
    for p, size in zip(paths, sizes, strict=True):
        check_image_size(p, size)
