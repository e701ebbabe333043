"""CRS handling and the local computation frame (``local = world - offset``)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import CRSError, InputError


def parse_crs(text):
    """A :class:`pyproj.CRS` from an EPSG code, ``AUTH:CODE``, WKT or PROJ string.

    Raises :class:`CRSError` naming the text when pyproj cannot read it.
    """
    from pyproj import CRS
    from pyproj.exceptions import CRSError as _PyprojCRSError

    if text is None or (isinstance(text, str) and not text.strip()):
        raise CRSError("no CRS given: expected an EPSG code, WKT or PROJ string")
    if isinstance(text, int) or (isinstance(text, str) and text.strip().isdigit()):
        text = f"EPSG:{int(text)}"
    try:
        return CRS.from_user_input(text.strip() if isinstance(text, str) else text)
    except (_PyprojCRSError, TypeError, ValueError) as err:
        shown = str(text)
        shown = shown if len(shown) < 80 else shown[:77] + "..."
        raise CRSError(f"cannot read the CRS {shown!r}: {err}") from None


def crs_to_text(crs) -> str:
    """Compact storage form: ``AUTH:CODE`` when exact, else WKT2."""
    auth = crs.to_authority(min_confidence=100)
    if auth:
        return f"{auth[0]}:{auth[1]}"
    return crs.to_wkt()


def require_metric(crs, what: str = "CRS") -> None:
    """Raise :class:`CRSError` unless ``crs`` is projected (or geocentric) in metres."""
    if crs.is_geographic:
        raise CRSError(
            f"{what} {crs.name!r} is geographic (degrees); a projected CRS in metres is needed "
            "(e.g. the UTM zone of the block)"
        )
    units = {ax.unit_name for ax in crs.axis_info[:2]}
    if not units <= {"metre", "meter", "m"}:
        raise CRSError(f"{what} {crs.name!r} has axis units {sorted(units)}; metres are needed")


@dataclass
class LocalFrame:
    """World CRS plus the offset of the local computation frame.

    ``local = world - offset``; ``crs`` may be None for an unreferenced
    (arbitrary, e.g. close-range) frame.
    """

    crs: str | None = None
    offset: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        off = np.asarray(self.offset, dtype=np.float64).reshape(-1)
        if off.shape != (3,) or not np.all(np.isfinite(off)):
            raise InputError(f"offset: expected 3 finite numbers, got {self.offset!r}")
        self.offset = off

    def to_local(self, xyz) -> np.ndarray:
        return np.asarray(xyz, dtype=np.float64) - self.offset

    def to_world(self, xyz) -> np.ndarray:
        return np.asarray(xyz, dtype=np.float64) + self.offset

    def pyproj_crs(self):
        if self.crs is None:
            raise CRSError("the orientation has no CRS")
        return parse_crs(self.crs)


def choose_offset(world_xyz) -> np.ndarray:
    """A round offset near the centre of points (metres, multiples of 1000 in plan)."""
    pts = np.asarray(world_xyz, dtype=np.float64).reshape(-1, 3)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    if len(pts) == 0:
        return np.zeros(3)
    c = np.median(pts, axis=0)
    return np.array([np.round(c[0], -3), np.round(c[1], -3), 0.0])


def transform_points(xyz, src, dst) -> np.ndarray:
    """Transform (N, 3) points between CRSs with pyproj (always x=east, y=north)."""
    from pyproj import Transformer
    from pyproj.exceptions import ProjError

    pts = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
    try:
        tr = Transformer.from_crs(src, dst, always_xy=True)
        x, y, z = tr.transform(pts[:, 0], pts[:, 1], pts[:, 2], errcheck=True)
    except ProjError as err:
        raise CRSError(f"no transformation from {src} to {dst}: {err}") from None
    return np.column_stack([x, y, z])
