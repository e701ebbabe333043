"""Image access: header information, full or downscaled reads, windows, luminance.

Pixels are returned **as stored** in the file: the EXIF ``Orientation`` tag is
never applied (``cv2.IMREAD_IGNORE_ORIENTATION``), because every pixel
coordinate of TruOrtho (features, GCP measurements, camera models) refers to
the stored pixel grid (:mod:`truortho.core.geometry`). The tag is read by
:mod:`truortho.core.exif` for display purposes only.

Arrays are ``(H, W)`` for one band and ``(H, W, C)`` for several, bands in
file order (RGB for colour images, not OpenCV's BGR). 8- and 16-bit data keep
their dtype.

Downscaling (:func:`read_image` with ``scale < 1``) uses area averaging
(``cv2.INTER_AREA``) to ``round(W * scale) x round(H * scale)`` pixels. The
pixel centres then map as in :meth:`~truortho.core.geometry.camera.Camera.scaled`,
``x' = (x + 0.5) * sx - 0.5`` with the *effective* per-axis factors
``sx = W' / W``, ``sy = H' / H`` (:func:`scaled_size`), which differ from the
nominal ``scale`` by the rounding of the size only.

Pyramid levels (:func:`read_image_level`, used by OSGM and the true ortho) follow another,
exact convention: level ``l`` is the mean of every ``2**l x 2**l`` block of the stored pixels
(``ceil(W / 2**l)`` wide, the last blocks padded by repetition), so ``x' = (x + 0.5) / 2**l - 0.5``
whatever the size. JPEGs are decoded straight to levels 1 to 3 (libjpeg's scaled IDCT), which
takes a third of the time of a full decode and none of its memory.
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass

import numpy as np

from .errors import FormatError, InputError, MissingFileError

#: File extensions read through rasterio (windowed reads without decoding the whole file).
_RASTERIO_EXT = (".tif", ".tiff", ".vrt", ".jp2")
#: Rec. 601 luma weights for R, G, B.
REC601 = (0.299, 0.587, 0.114)
#: Rec. 601 (JPEG, JFIF) colour differences from R, G, B: Cb and Cr (without the 128 offset).
REC601_CB = (-0.168736, -0.331264, 0.5)
REC601_CR = (0.5, -0.418688, -0.081312)
#: Their inverse: ``R = Y + a Cr``, ``G = Y - b Cb - c Cr``, ``B = Y + d Cb`` with ``(a, b, c, d)``.
REC601_INV = (1.402, 0.344136, 0.714136, 1.772)


@dataclass(frozen=True)
class ImageInfo:
    """Header information of an image file (stored pixel grid).

    Attributes
    ----------
    path : str
    width, height : int
        Size in pixels as stored (EXIF orientation not applied).
    bands : int
        Number of bands (1 grey, 3 RGB, 4 RGBA, ...).
    dtype : str
        Numpy dtype name of the samples (``"uint8"``, ``"uint16"``, ...).
    """

    path: str
    width: int
    height: int
    bands: int
    dtype: str


def _check_exists(path) -> str:
    p = os.fspath(path)
    if not os.path.isfile(p):
        raise MissingFileError(p, "image file not found")
    return p


def _use_rasterio(path: str) -> bool:
    return path.lower().endswith(_RASTERIO_EXT)


def image_info(path) -> ImageInfo:
    """Size, band count and dtype of an image without decoding its pixels.

    Raises
    ------
    MissingFileError
        The file does not exist.
    FormatError
        The file is not a readable image.
    """
    p = _check_exists(path)
    if _use_rasterio(p):
        try:
            import rasterio

            with warnings.catch_warnings():
                warnings.simplefilter("ignore", rasterio.errors.NotGeoreferencedWarning)
                ds = rasterio.open(p)
            with ds:
                return ImageInfo(p, ds.width, ds.height, ds.count, str(ds.dtypes[0]))
        except ImportError:
            pass
        except Exception as exc:  # rasterio raises its own error types
            raise FormatError(p, f"not a readable image ({exc})") from None
    try:
        from PIL import Image

        with Image.open(p) as im:
            w, h = im.size
            mode = im.mode
    except Exception as exc:
        raise FormatError(p, f"not a readable image ({type(exc).__name__}: {exc})") from None
    bands = {"1": 1, "L": 1, "P": 3, "I": 1, "F": 1, "LA": 2, "RGB": 3, "RGBA": 4, "CMYK": 4, "YCbCr": 3}
    dtype = "uint16" if mode.startswith("I;16") else ("float32" if mode == "F" else "uint8")
    return ImageInfo(p, int(w), int(h), bands.get(mode, 1 if mode.startswith("I") else 3), dtype)


def scaled_size(width: int, height: int, scale: float) -> tuple[int, int, float, float]:
    """Output size and effective per-axis factors of a resampling by ``scale``.

    Returns
    -------
    (w, h, sx, sy)
        ``w = max(1, round(width * scale))`` (same for ``h``), ``sx = w / width``,
        ``sy = h / height``: pixel centres map as ``x' = (x + 0.5) * sx - 0.5``.
    """
    if not scale > 0:
        raise InputError(f"scale must be positive, got {scale}")
    w = max(1, int(round(width * scale)))
    h = max(1, int(round(height * scale)))
    return w, h, w / width, h / height


def _decode(path: str) -> np.ndarray:
    import cv2

    try:
        buf = np.fromfile(path, dtype=np.uint8)  # also handles non-ASCII paths on Windows
    except OSError as exc:
        raise FormatError(path, f"cannot read the file ({exc})") from None
    img = None
    if buf.size:
        img = cv2.imdecode(buf, cv2.IMREAD_UNCHANGED | cv2.IMREAD_IGNORE_ORIENTATION)
    if img is None:
        raise FormatError(path, "not a readable image (unknown format or corrupt data)")
    return _to_rgb(img)


def _to_rgb(img: np.ndarray) -> np.ndarray:
    """OpenCV's BGR(A) order to RGB(A) (cv2.cvtColor: several times faster than a flipped copy)."""
    import cv2

    if img.ndim == 3:
        if img.shape[2] == 3:
            return cv2.cvtColor(img, cv2.COLOR_BGR2RGB)
        if img.shape[2] == 4:
            return cv2.cvtColor(img, cv2.COLOR_BGRA2RGBA)
        return np.ascontiguousarray(img)
    return img


#: Pyramid levels a JPEG decoder reaches directly (scaled IDCT at 1/2, 1/4, 1/8).
JPEG_DIRECT_LEVELS = 3


def _decode_jpeg_reduced(path: str, level: int, bands: int) -> np.ndarray | None:
    """An 8-bit grey or RGB JPEG decoded at 1/2**level (1 <= level <= 3) by libjpeg's scaled IDCT,
    which gives the means of 2**level-pixel blocks without the full-size image
    (ceil(W / 2**level) x ceil(H / 2**level) pixels: the halvings rounded up). None when the file
    is not a JPEG."""
    import cv2

    try:
        with open(path, "rb") as fh:  # the signature first: another format is not read twice
            if fh.read(3) != b"\xff\xd8\xff":
                return None
        buf = np.fromfile(path, dtype=np.uint8)
    except OSError as exc:
        raise FormatError(path, f"cannot read the file ({exc})") from None
    grey = {
        1: cv2.IMREAD_REDUCED_GRAYSCALE_2,
        2: cv2.IMREAD_REDUCED_GRAYSCALE_4,
        3: cv2.IMREAD_REDUCED_GRAYSCALE_8,
    }
    colour = {1: cv2.IMREAD_REDUCED_COLOR_2, 2: cv2.IMREAD_REDUCED_COLOR_4, 3: cv2.IMREAD_REDUCED_COLOR_8}
    flag = (grey if bands == 1 else colour)[level]
    img = cv2.imdecode(buf, flag | cv2.IMREAD_IGNORE_ORIENTATION)
    if img is None:
        raise FormatError(path, "not a readable image (corrupt JPEG data)")
    return _to_rgb(img)


def halve_image(img: np.ndarray) -> np.ndarray:
    """One pyramid level: the mean of every 2 x 2 block, ceil(W / 2) x ceil(H / 2), same dtype.

    An odd last column or row is repeated first, so the blocks stay aligned on the stored pixel
    grid at every level (``x' = (x + 0.5) / 2 - 0.5``, as a JPEG's scaled decoding has them);
    an area resampling to the rounded-up size would instead stretch the grid by ``W' / (W / 2)``.
    """
    import cv2

    h, w = img.shape[:2]
    if h % 2 or w % 2:
        img = np.pad(img, ((0, h % 2), (0, w % 2)) + ((0, 0),) * (img.ndim - 2), mode="edge")
    size = ((w + 1) // 2, (h + 1) // 2)
    if img.ndim == 3 and img.shape[2] > 4:  # cv2.resize handles at most 4 channels reliably
        return np.stack(
            [cv2.resize(img[:, :, c], size, interpolation=cv2.INTER_AREA) for c in range(img.shape[2])], -1
        )
    return np.ascontiguousarray(cv2.resize(img, size, interpolation=cv2.INTER_AREA))


def level_size(size, level: int) -> tuple[int, int]:
    """(width, height) of an image of ``size`` at pyramid ``level`` (halvings rounded up)."""
    w, h = (int(v) for v in size)
    for _ in range(int(level)):
        w, h = max(1, (w + 1) // 2), max(1, (h + 1) // 2)
    return w, h


def read_image_level(path, size, level: int, convert=None) -> np.ndarray:
    """The image whose camera expects ``size = (width, height)`` at pyramid ``level``.

    Level ``l`` has :func:`level_size` pixels, each the mean of a ``2**l`` block of the stored
    image (the last ones padded by repetition), and the pixel centres map as
    ``x' = (x + 0.5) / 2**l - 0.5`` whatever the size. 8-bit grey and RGB
    JPEGs are decoded directly at up to 1/8 scale (:data:`JPEG_DIRECT_LEVELS`; a fraction of
    the time and none of the memory of the full image); further levels, and other formats, are
    halved by area averaging (:func:`halve_image`). TIFF/VRT/JPEG 2000 files are read through
    rasterio, decimated by averaging (with the file's overviews when it has them); there GDAL
    fits the whole image to the rounded-up size, so for a size not divisible by ``2**l`` the grid
    is stretched by ``W' 2**l / W`` instead of kept exact, as in :func:`read_level_window`.

    ``convert`` (optional) maps the decoded array before the area halvings (e.g. to float
    luminance, so that the averaging does not round to the file's integers).

    Raises
    ------
    MissingFileError, FormatError
        The file is missing, unreadable, or not ``size``.
    InputError
        ``level`` is negative.
    """
    if int(level) != level or level < 0:
        raise InputError(f"{os.fspath(path)}: image level must be a whole number >= 0, got {level!r}")
    level = int(level)
    p = _check_exists(path)
    info = check_image_size(p, size)
    target = level_size(size, level)
    img: np.ndarray | None = None
    done = 0
    if level > 0 and _use_rasterio(p):
        img = _read_rasterio(p, out_shape=(target[1], target[0]))
        done = level if img is not None else 0
    elif level > 0 and info.dtype == "uint8" and info.bands in (1, 3):
        done = min(level, JPEG_DIRECT_LEVELS)
        img = _decode_jpeg_reduced(p, done, info.bands)
        if img is None:
            done = 0
    if img is None:
        img = read_image(p)
    if img.shape[1::-1] != level_size(size, done):
        raise FormatError(
            p,
            f"decoded at level {done} to {img.shape[1]} x {img.shape[0]} pixels, "
            f"expected {level_size(size, done)}",
        )
    out: np.ndarray = img if convert is None else convert(img)
    for _ in range(done, level):
        out = halve_image(out)
    return out


def _read_rasterio(path: str, window=None, out_shape=None) -> np.ndarray | None:
    """All bands of ``path`` (or of ``window = (x, y, w, h)``), (h, w) or (h, w, bands); with
    ``out_shape = (rows, cols)`` decimated by averaging (rasterio uses the file's overviews).
    None without rasterio."""
    try:
        import rasterio
        from rasterio.enums import Resampling
        from rasterio.windows import Window
    except ImportError:
        return None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", rasterio.errors.NotGeoreferencedWarning)
            ds = rasterio.open(path)
        with ds:
            win = None if window is None else Window(*window)
            shape = None if out_shape is None else (ds.count, int(out_shape[0]), int(out_shape[1]))
            data = ds.read(window=win, out_shape=shape, resampling=Resampling.average)
    except Exception as exc:
        raise FormatError(path, f"not a readable image ({exc})") from None
    return data[0] if data.shape[0] == 1 else np.ascontiguousarray(np.moveaxis(data, 0, -1))


def read_level_window(
    path, size: tuple[int, int], level: int, x0: int, y0: int, w: int, h: int
) -> np.ndarray:
    """Window ``[x0, x0 + w) x [y0, y0 + h)`` of an image at pyramid ``level`` (halvings of
    ``size = (width, height)``), read through rasterio: decimated by averaging (the file's overviews
    when it has them), native dtype, cropped at the image border.

    Raises
    ------
    InputError
        ``level`` or the window is invalid, or rasterio is missing.
    FormatError
        The file cannot be read.
    """
    if level < 0 or w <= 0 or h <= 0 or x0 < 0 or y0 < 0:
        raise InputError(f"{path}: bad image window level {level}, ({x0}, {y0}, {w}, {h})")
    f = 2**level
    W, H = size
    win = (x0 * f, y0 * f, min(w * f, W - x0 * f), min(h * f, H - y0 * f))
    if win[2] <= 0 or win[3] <= 0:
        raise InputError(f"{path}: window ({x0}, {y0}, {w}, {h}) at level {level} is outside the image")
    shape = None if level == 0 else (-(-win[3] // f), -(-win[2] // f))
    img = _read_rasterio(str(path), win, shape)
    if img is None:
        raise InputError(f"{path}: rasterio is needed to read windows of this image")
    return img[:h, :w]


def _select_band(img: np.ndarray, band: int | None, path: str) -> np.ndarray:
    if band is None:
        return img
    nb = 1 if img.ndim == 2 else img.shape[2]
    if not 0 <= band < nb:
        raise InputError(f"{path}: band {band} out of range (the image has {nb} band(s), 0-based)")
    return img if img.ndim == 2 else np.ascontiguousarray(img[:, :, band])


def resample(img: np.ndarray, scale: float) -> np.ndarray:
    """Resample an array by ``scale`` (area averaging when shrinking, bilinear when enlarging)."""
    import cv2

    if scale == 1.0:
        return img
    h, w = img.shape[:2]
    nw, nh, _, _ = scaled_size(w, h, scale)
    interp = cv2.INTER_AREA if scale < 1.0 else cv2.INTER_LINEAR
    src = img if img.dtype != np.int64 else img.astype(np.float64)
    if img.ndim == 3 and img.shape[2] > 4:  # cv2.resize handles at most 4 channels reliably
        return np.stack(
            [cv2.resize(src[:, :, c], (nw, nh), interpolation=interp) for c in range(img.shape[2])], -1
        )
    return cv2.resize(src, (nw, nh), interpolation=interp)


def read_image(path, scale: float = 1.0, band: int | None = None) -> np.ndarray:
    """Read an image as stored (EXIF orientation ignored), optionally downscaled.

    Parameters
    ----------
    path : str or os.PathLike
    scale : float
        Resampling factor in (0, 1] for a reduced read (e.g. 0.25), or > 1.
        The output size is :func:`scaled_size`.
    band : int, optional
        0-based band to return (a 2-D array); all bands when None.

    Returns
    -------
    (H, W) or (H, W, C) ndarray
        Bands in file order (RGB), original dtype (uint8, uint16, float32...).

    Raises
    ------
    MissingFileError, FormatError, InputError
    """
    p = _check_exists(path)
    if not (isinstance(scale, int | float) and np.isfinite(scale) and scale > 0):
        raise InputError(f"{p}: scale must be a positive number, got {scale!r}")
    img = _read_rasterio(p) if _use_rasterio(p) else None
    if img is None:
        img = _decode(p)
    img = _select_band(img, band, p)
    return resample(img, float(scale))


def read_window(path, x0: int, y0: int, w: int, h: int, band: int | None = None, fill=0) -> np.ndarray:
    """Read the pixel window ``[x0, x0 + w) x [y0, y0 + h)`` (columns, rows) of the stored image.

    Parts of the window outside the image are filled with ``fill``. TIFF /
    VRT / JPEG 2000 files are read through rasterio (only the window is
    decoded); other formats are decoded whole and cropped.

    Returns
    -------
    (h, w) or (h, w, C) ndarray, the file's dtype.
    """
    p = _check_exists(path)
    x0, y0, w, h = (int(v) for v in (x0, y0, w, h))
    if w <= 0 or h <= 0:
        raise InputError(f"{p}: window size must be positive, got {w}x{h}")
    info = image_info(p)
    ix0, iy0 = max(x0, 0), max(y0, 0)
    ix1, iy1 = min(x0 + w, info.width), min(y0 + h, info.height)
    part = None
    if ix1 > ix0 and iy1 > iy0:
        if _use_rasterio(p):
            part = _read_rasterio(p, (ix0, iy0, ix1 - ix0, iy1 - iy0))
        if part is None:
            part = _decode(p)[iy0:iy1, ix0:ix1]
        part = _select_band(part, band, p)
    nb = info.bands if band is None else 1
    if part is not None and (part.shape[0], part.shape[1]) == (h, w):
        return part
    if part is not None:
        dtype, nb = part.dtype, (1 if part.ndim == 2 else part.shape[2])
    else:
        dtype = np.dtype(info.dtype)
    out = np.full((h, w) if nb == 1 else (h, w, nb), fill, dtype=dtype)
    if part is not None:
        out[iy0 - y0 : iy1 - y0, ix0 - x0 : ix1 - x0] = part
    return out


def luminance(img: np.ndarray) -> np.ndarray:
    """Luminance of an image as float32.

    * 3 or more bands: Rec. 601 luma ``0.299 R + 0.587 G + 0.114 B`` of the
      first three bands (assumed R, G, B; an alpha band is ignored);
    * 1 or 2 bands: the first band.

    Integer data are scaled to [0, 1] by the dtype's maximum (255 for uint8,
    65535 for uint16); float data are returned unscaled.

    Returns
    -------
    (H, W) float32
    """
    a = np.asarray(img)
    if a.ndim not in (2, 3):
        raise InputError(f"luminance: expected an (H, W) or (H, W, C) array, got shape {a.shape}")
    if a.ndim == 3:
        if a.shape[2] >= 3:
            w = np.asarray(REC601, dtype=np.float32)
            lum = a[:, :, 0] * w[0] + a[:, :, 1] * w[1] + a[:, :, 2] * w[2]
            lum = lum.astype(np.float32)
        else:
            lum = a[:, :, 0].astype(np.float32)
    else:
        lum = a.astype(np.float32)
    if np.issubdtype(a.dtype, np.integer):
        lum *= np.float32(1.0 / np.iinfo(a.dtype).max)
    return lum


def to_uint8(img: np.ndarray) -> np.ndarray:
    """8-bit version of an image for display / 8-bit algorithms.

    uint8 unchanged; other integer types divided by their maximum; float
    data (and 16-bit data using a small part of their range, e.g. 12-bit
    sensors) stretched between the 0.1 and 99.9 percentiles.
    """
    a = np.asarray(img)
    if a.dtype == np.uint8:
        return a
    f = a.astype(np.float32)
    lo, hi = np.nanpercentile(f, [0.1, 99.9]) if f.size else (0.0, 1.0)
    if np.issubdtype(a.dtype, np.integer) and hi > 0.25 * np.iinfo(a.dtype).max:
        lo, hi = 0.0, float(np.iinfo(a.dtype).max)
    if not hi > lo:
        hi = lo + 1.0
    return np.clip((f - lo) * (255.0 / (hi - lo)) + 0.5, 0, 255).astype(np.uint8)


def check_image_size(path, size) -> ImageInfo:
    """The header of an image whose camera expects ``size = (width, height)``; FormatError otherwise."""
    info = image_info(path)
    w, h = (int(v) for v in size)
    if (info.width, info.height) != (w, h):
        raise FormatError(
            info.path, f"image is {info.width} x {info.height} pixels but its camera says {w} x {h}"
        )
    return info


def read_image_sized(path, size) -> np.ndarray:
    """:func:`read_image` of an image whose camera expects ``size = (width, height)``.

    Raises FormatError naming the file when the sizes differ.
    """
    img = read_image(path)
    w, h = (int(v) for v in size)
    if img.shape[:2] != (h, w):
        raise FormatError(
            str(path), f"image is {img.shape[1]} x {img.shape[0]} pixels but its camera says {w} x {h}"
        )
    return img
