"""EXIF (and DJI XMP) metadata of photos: camera, focal length, GPS position.

Only what orientation needs is read: make/model, focal length (mm) and its
35 mm equivalent, the sensor size derived from ``FocalPlaneX/YResolution``,
the image size, the ``Orientation`` tag, the capture time and the GPS
position. DJI drones also write ``drone-dji:RelativeAltitude`` (height above
the take-off point) in XMP; it is read when present.

Orientation tag rule
--------------------
TruOrtho works on the pixel grid **as stored** (:mod:`truortho.core.imagery`
never rotates). The ``Orientation`` tag (1..8) is only recorded here; all
pixel coordinates, interior orientations and sensor sizes refer to the
stored grid: ``FocalPlaneXResolution`` and ``PixelXDimension`` are along the
stored x axis. ODM ``gcp_list.txt`` image coordinates are taken in the
stored grid too (verified on the boruszyn data set, whose images carry
``Orientation = 8``: its GCP coordinates are valid only without rotation).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass

import numpy as np

from .errors import FormatError, MissingFileError

# EXIF tag numbers
_EXIF_IFD, _GPS_IFD = 0x8769, 0x8825
_MAKE, _MODEL, _ORIENTATION, _DATETIME = 0x010F, 0x0110, 0x0112, 0x0132
_DATETIME_ORIGINAL, _FOCAL, _FOCAL35 = 0x9003, 0x920A, 0xA405
_PIXEL_X, _PIXEL_Y = 0xA002, 0xA003
_FP_XRES, _FP_YRES, _FP_UNIT = 0xA20E, 0xA20F, 0xA210
#: FocalPlaneResolutionUnit -> millimetres per unit (2 = inch is the EXIF default).
_UNIT_MM = {1: 25.4, 2: 25.4, 3: 10.0, 4: 1.0, 5: 0.001}

#: Default focal length when nothing is known, as a multiple of the larger image side
#: (about a 45 deg horizontal field of view for the longer side; COLMAP uses 1.2 too).
DEFAULT_FOCAL_RATIO = 1.2
#: Priors outside ``[min, max] * max(w, h)`` are considered wrong tags and ignored.
FOCAL_RATIO_RANGE = (0.2, 20.0)


@dataclass
class ExifData:
    """Photo metadata; None where the file has no (valid) value.

    Attributes
    ----------
    make, model : str or None
    focal_mm : float or None
        ``FocalLength``, millimetres.
    focal_35mm : float or None
        ``FocalLengthIn35mmFilm``, millimetres.
    sensor_width_mm, sensor_height_mm : float or None
        From ``FocalPlaneX/YResolution`` and the EXIF pixel dimensions,
        along the stored x and y axes.
    exif_width, exif_height : int or None
        ``PixelX/YDimension`` (size the focal-plane resolution refers to).
    orientation : int
        EXIF ``Orientation`` 1..8 (1 when absent); informative only.
    datetime : str or None
        ``DateTimeOriginal`` (or ``DateTime``), ``"YYYY:MM:DD HH:MM:SS"``.
    latitude, longitude : float or None
        WGS 84 degrees, north and east positive.
    altitude : float or None
        ``GPSAltitude`` in metres (negative when ``GPSAltitudeRef`` = 1).
    relative_altitude : float or None
        DJI XMP ``RelativeAltitude``: height above the take-off point, metres.
    """

    make: str | None = None
    model: str | None = None
    focal_mm: float | None = None
    focal_35mm: float | None = None
    sensor_width_mm: float | None = None
    sensor_height_mm: float | None = None
    exif_width: int | None = None
    exif_height: int | None = None
    orientation: int = 1
    datetime: str | None = None
    latitude: float | None = None
    longitude: float | None = None
    altitude: float | None = None
    relative_altitude: float | None = None

    @property
    def has_gps(self) -> bool:
        return self.latitude is not None and self.longitude is not None


def _num(v) -> float | None:
    try:
        if isinstance(v, tuple) and len(v) == 2:  # raw rational
            f = float(v[0]) / float(v[1])
        else:
            f = float(v)
    except (TypeError, ValueError, ZeroDivisionError):
        return None
    return f if np.isfinite(f) else None


def _pos(v) -> float | None:
    f = _num(v)
    return f if f is not None and f > 0 else None


def _text(v) -> str | None:
    if v is None:
        return None
    if isinstance(v, bytes):
        v = v.decode("latin-1", "replace")
    s = str(v).replace("\x00", "").strip()
    return s or None


def _dms(v, ref) -> float | None:
    try:
        d, m, s = (_num(x) for x in v)
    except (TypeError, ValueError):
        return _num(v)
    if d is None or m is None or s is None:
        return None
    deg = d + m / 60.0 + s / 3600.0
    r = _text(ref)
    return -deg if r in ("S", "W") else deg


_XMP_RE = re.compile(
    rb'drone-dji:RelativeAltitude\s*=\s*"([+\-0-9.eE]+)"|<drone-dji:RelativeAltitude>([+\-0-9.eE]+)<'
)


def _dji_relative_altitude(path: str) -> float | None:
    try:
        with open(path, "rb") as fh:
            head = fh.read(256 * 1024)
    except OSError:
        return None
    m = _XMP_RE.search(head)
    if not m:
        return None
    return _num((m.group(1) or m.group(2)).decode())


def read_exif(path) -> ExifData:
    """Metadata of one photo (all fields None when the file has no EXIF).

    Raises
    ------
    MissingFileError
        The file does not exist.
    FormatError
        The file is not an image Pillow can open.
    """
    p = os.fspath(path)
    if not os.path.isfile(p):
        raise MissingFileError(p, "image file not found")
    try:
        from PIL import Image

        with Image.open(p) as im:
            ex = im.getexif()
            sub = dict(ex.get_ifd(_EXIF_IFD))
            gps = dict(ex.get_ifd(_GPS_IFD))
            base = dict(ex)
    except Exception as exc:
        raise FormatError(
            p, f"cannot read EXIF: not a readable image ({type(exc).__name__}: {exc})"
        ) from None

    d = ExifData()
    d.make, d.model = _text(base.get(_MAKE)), _text(base.get(_MODEL))
    o = base.get(_ORIENTATION)
    d.orientation = int(o) if isinstance(o, int) and 1 <= o <= 8 else 1
    d.datetime = _text(sub.get(_DATETIME_ORIGINAL)) or _text(base.get(_DATETIME))
    d.focal_mm = _pos(sub.get(_FOCAL))
    d.focal_35mm = _pos(sub.get(_FOCAL35))
    w, h = _pos(sub.get(_PIXEL_X)), _pos(sub.get(_PIXEL_Y))
    d.exif_width = int(w) if w else None
    d.exif_height = int(h) if h else None
    unit = sub.get(_FP_UNIT, 2)
    unit_mm = _UNIT_MM.get(int(unit) if isinstance(unit, int) else 2, 25.4)
    xres, yres = _pos(sub.get(_FP_XRES)), _pos(sub.get(_FP_YRES))
    if xres and d.exif_width:
        d.sensor_width_mm = d.exif_width / xres * unit_mm
    if yres and d.exif_height:
        d.sensor_height_mm = d.exif_height / yres * unit_mm
    if gps:
        lat = _dms(gps.get(2), gps.get(1)) if 2 in gps else None
        lon = _dms(gps.get(4), gps.get(3)) if 4 in gps else None
        if (
            lat is not None
            and lon is not None
            and abs(lat) <= 90
            and abs(lon) <= 180
            and (lat, lon) != (0, 0)
        ):
            d.latitude, d.longitude = lat, lon
            alt = _num(gps.get(6))
            if alt is not None:
                ref = gps.get(5)
                below = ref in (1, b"\x01") or (isinstance(ref, bytes) and ref[:1] == b"\x01")
                d.altitude = -alt if below else alt
    d.relative_altitude = _dji_relative_altitude(p)
    return d


def focal_prior_px(exif: ExifData | None, width: int, height: int) -> tuple[float, str]:
    """Prior focal length in pixels of the stored image, and where it came from.

    In order of preference:

    1. ``"exif_sensor"``: ``FocalLength`` and the sensor width from the
       focal-plane resolution, ``f_px = f_mm / sensor_width_mm * width``
       (the sensor refers to ``PixelXDimension``, so the prior stays valid
       for resized images whose tags were updated);
    2. ``"exif_35mm"``: ``f_px = f35 / 36 * max(width, height)`` (the
       OpenSfM convention; exact for 3:2 images, about 5 % long for 16:9);
    3. ``"default"``: ``f_px = 1.2 * max(width, height)``.

    A prior outside ``FOCAL_RATIO_RANGE * max(width, height)`` is skipped as
    a wrong tag. The prior is refined by self-calibration in the adjustment.

    Parameters
    ----------
    exif : ExifData or None
    width, height : int
        Stored image size in pixels.

    Returns
    -------
    (f_px, source)
    """
    side = float(max(width, height))
    lo, hi = FOCAL_RATIO_RANGE[0] * side, FOCAL_RATIO_RANGE[1] * side
    if exif is not None:
        if exif.focal_mm and exif.sensor_width_mm:
            f = exif.focal_mm / exif.sensor_width_mm * float(width)
            if lo <= f <= hi:
                return f, "exif_sensor"
        if exif.focal_35mm:
            f = exif.focal_35mm / 36.0 * side
            if lo <= f <= hi:
                return f, "exif_35mm"
    return DEFAULT_FOCAL_RATIO * side, "default"
