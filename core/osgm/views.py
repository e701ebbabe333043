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
decoded once and kept in a least-recently-used cache bounded in bytes. With a point spread per
image (``spread``), the matching band is restored towards a sharp photo's spread at every level
(:func:`~truortho.core.optics.restore`, the spread halved per level) before it is served.
The matching band of a photo that is not restored is low-passed at full resolution by a Gaussian of
``prefilter`` px (:func:`~truortho.core.optics.prefilter`); the reduced levels are band-limited by
their reduction already. ``window(..., raw=True)`` serves the band without that low-pass (the edge
refinement compares 3 x 3 patches at the outlines, which the low-pass would soften).
"""

from __future__ import annotations

import math
from collections import OrderedDict

import numpy as np

from ..errors import CancelledError, InputError
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
from ..optics import (
    MAX_SPREAD,
    MIN_RESTORE,
    check_prefilter,
    excess_spread,
    photo_spread,
    prefilter,
    prefilter_margin,
    restore,
    restore_margin,
)


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
    spread : sequence of float, optional
        Per image, the Gaussian point spread (px at full resolution) to undo in the matching band
        (:func:`~truortho.core.optics.restore`; 0 or None: served as decoded). Colours are never
        restored.
    window : int
        The restoration's window (px, odd): the matching window's width.
    prefilter : float
        Gaussian sigma (px) by which the matching band of every image that is not restored is
        low-passed at full resolution (:meth:`prefilter_sigma`; 0: none).
    """

    def __init__(
        self, paths, sizes, band: int | None = None, max_bytes: int = 1 << 30, spread=None, window: int = 5,
        prefilter: float = 0.0,
    ) -> None:
        self.paths = [str(p) for p in paths]
        self.sizes = [tuple(int(v) for v in s) for s in sizes]
        self.band = band
        self.max_bytes = int(max_bytes)
        if spread is None:
            spread = [0.0] * len(self.paths)
        self.spread = tuple(float(v) for v in spread)
        if len(self.spread) != len(self.paths) or not all(
            math.isfinite(v) and 0.0 <= v <= MAX_SPREAD for v in self.spread
        ):
            raise InputError(
                f"ImagePyramid: spread must give one number in [0, {MAX_SPREAD}] px per image "
                f"({len(self.paths)}), got {list(spread)!r}"
            )
        if int(window) != window or window < 1 or window % 2 == 0:
            raise InputError(f"ImagePyramid: window must be an odd number of pixels >= 1, got {window!r}")
        self.window_px = int(window)
        self.prefilter = check_prefilter(prefilter, "ImagePyramid: prefilter")
        #: what the run measured and restored, per camera (set by the OSGM run; for its statistics)
        self.spread_report: dict = {}
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

    def _full(self, i: int, level: int, colour: bool, raw: bool = False) -> np.ndarray:
        lowpass = 0.0 if colour or raw else self.prefilter_sigma(i, level)
        key = (i, level, colour, lowpass)
        if key in self._cache:
            self._cache.move_to_end(key)
            return self._cache[key]
        # only the level asked for is cached (JPEGs decode directly at up to 1/8 scale); the
        # conversion to float comes before any area halving, which then does not round
        out = read_image_level(self.paths[i], self.sizes[i], level, lambda img: self._convert(img, colour))
        if not colour and self.restoration(i, level) > 0.0:
            out = restore(out, self.restoration(i, level), self.window_px)
        if lowpass > 0.0:
            out = prefilter(out, lowpass)
        self.reads += 1
        self._put(key, out)
        return out

    def restoration(self, i: int, level: int) -> float:
        """The point spread (px of ``level``) undone in image ``i``'s matching band (0: none)."""
        s = self.spread[i] / 2**level
        return s if s >= MIN_RESTORE else 0.0

    def prefilter_sigma(self, i: int, level: int) -> float:
        """The Gaussian sigma (px) image ``i``'s matching band is low-passed by at ``level``: the
        pyramid's ``prefilter`` at full resolution for a photo that is not restored, else 0."""
        if level != 0 or self.restoration(i, 0) > 0.0:
            return 0.0
        return self.prefilter

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

    def band_scale(self, i: int) -> float:
        """The value of white in image ``i``'s matching band (the luminance of integer data is
        scaled to 1; a chosen band keeps the file's values)."""
        return 1.0 if self.band is None else self.value_max(i)

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
        self, i: int, level: int, x0: int, y0: int, w: int, h: int, colour: bool = False, raw: bool = False
    ) -> np.ndarray:
        """Window ``[x0, x0 + w) x [y0, y0 + h)`` of level ``level`` (float32, NaN outside the image);
        ``raw``: the matching band without the low-pass (:meth:`prefilter_sigma`)."""
        W, H = self.level_size(i, level)
        ix0, iy0, ix1, iy1 = max(x0, 0), max(y0, 0), min(x0 + w, W), min(y0 + h, H)
        nb = 3 if colour else 1
        out = np.full((h, w, nb) if colour else (h, w), np.nan, np.float32)
        if ix1 <= ix0 or iy1 <= iy0:
            return out
        if self._windowed[i]:
            part = self._read_window(i, level, ix0, iy0, ix1 - ix0, iy1 - iy0, colour, raw)
        else:
            part = self._full(i, level, colour, raw)[iy0:iy1, ix0:ix1]
        if colour and part.ndim == 2:
            part = part[:, :, None]
        if colour and part.shape[2] == 1:
            part = np.repeat(part, 3, axis=2)
        out[iy0 - y0 : iy1 - y0, ix0 - x0 : ix1 - x0] = part
        return out

    def _read_window(self, i, level, x0, y0, w, h, colour, raw=False) -> np.ndarray:
        """Windowed read of a rasterio source at a reduced level (its overviews when present);
        a restored or low-passed band is read with the context that needs and cropped."""
        s = 0.0 if colour else self.restoration(i, level)
        lp = 0.0 if colour or raw else self.prefilter_sigma(i, level)
        if s > 0.0 or lp > 0.0:
            W, H = self.level_size(i, level)
            m = (restore_margin(s, self.window_px) if s > 0.0 else 0) + prefilter_margin(lp)
            ax0, ay0 = max(x0 - m, 0), max(y0 - m, 0)
            ax1, ay1 = min(x0 + w + m, W), min(y0 + h + m, H)
            img = read_level_window(self.paths[i], self.sizes[i], level, ax0, ay0, ax1 - ax0, ay1 - ay0)
            self.reads += 1
            big = self._convert(img, False)
            if s > 0.0:
                big = restore(big, s, self.window_px)
            if lp > 0.0:
                big = prefilter(big, lp)
            return big[y0 - ay0 : y0 - ay0 + h, x0 - ax0 : x0 - ax0 + w]
        img = read_level_window(self.paths[i], self.sizes[i], level, x0, y0, w, h)
        self.reads += 1
        out = self._convert(img, colour)
        if out.ndim == 2 and colour:
            out = out[:, :, None]
        return out


#: Photos per camera whose point spread :func:`photo_spreads` measures (every k-th of them).
SPREAD_PHOTOS = 8
#: Side (px) of the central crop of a photo that its point spread is measured on.
SPREAD_CROP = 2048


def photo_spreads(paths, sizes, cameras, band: int | None = None, progress=None) -> tuple[list[float], dict]:
    """Per image, the point spread to undo before matching, and a report per camera.

    The photos of one camera (``cameras[i]``, any hashable) share their optics: their spread is
    the median of :func:`~truortho.core.optics.photo_spread` over up to :data:`SPREAD_PHOTOS` of
    them (spread evenly over the camera's list), each measured on its central
    :data:`SPREAD_CROP` pixels square of the matching band, and the part beyond a sharp photo's
    (:func:`~truortho.core.optics.excess_spread`) is undone. A camera none of whose photos shows
    enough straight edges is left as it is (0). The report maps each camera (``str``) to
    ``{"measured": px or None, "photos": measured photos, "restored": px}``. ``progress``
    (optional) is asked whether to stop between photos.
    """
    n = len(paths)
    if len(sizes) != n or len(cameras) != n:
        raise InputError(f"photo_spreads: expected as many sizes and cameras as paths ({n}), "
                         f"got {len(sizes)} and {len(cameras)}")  # fmt: skip
    probe = ImagePyramid(paths, sizes, band, max_bytes=0)
    groups: dict = {}
    for i, c in enumerate(cameras):
        groups.setdefault(c, []).append(i)
    out = [0.0] * n
    report = {}
    for cam, idx in groups.items():
        step = max(1, math.ceil(len(idx) / SPREAD_PHOTOS))
        vals = []
        for i in idx[::step]:
            if progress is not None and progress.cancelled():
                raise CancelledError("cancelled")
            W, H = probe.level_size(i, 0)
            w, h = min(W, SPREAD_CROP), min(H, SPREAD_CROP)
            g = probe.window(i, 0, (W - w) // 2, (H - h) // 2, w, h)
            v = photo_spread(g, probe.band_scale(i))
            if v is not None:
                vals.append(v)
        measured = float(np.median(vals)) if vals else None
        s = excess_spread(min(measured, MAX_SPREAD)) if measured is not None else 0.0
        for i in idx:
            out[i] = s
        report[str(cam)] = {"measured": measured, "photos": len(vals), "restored": s}
    return out, report


def check_images(paths, sizes) -> None:
    """Every image exists, is readable and has its camera's size (before anything is written)."""
    for p, size in zip(paths, sizes, strict=True):
        check_image_size(p, size)
