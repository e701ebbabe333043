"""The Z range OSGM searches, and the other defaults it takes from the block (resolution, extent).

:func:`z_range` from the parameters, the sparse tie points and GCPs or the block geometry;
:func:`surface_range` from a coarse surface raster; :func:`default_resolution` (median GSD of the
near-nadir images) and :func:`default_extent` (the area seen by the images), which
:func:`check_overlap` compares with a given extent.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError
from ..grid import RasterGrid
from ..orientation import Orientation

if TYPE_CHECKING:
    from .pipeline import OsgmConfig


def known_heights(o: Orientation) -> np.ndarray:
    """Local Z of sparse points and GCPs."""
    zs = []
    if o.points is not None and len(o.points):
        zs.append(o.points.xyz[:, 2])
    if o.gcps:
        zs.append(np.array([g.xyz[2] for g in o.gcps], np.float64) - o.offset[2])
    return np.concatenate(zs) if zs else np.zeros(0)


def nadir_images(o: Orientation) -> list[int]:
    idx = [i for i, im in enumerate(o.images) if im.R[2, 2] < -math.cos(math.radians(25))]
    return idx or list(range(len(o.images)))


def z_range(o: Orientation, cfg: OsgmConfig) -> tuple[float, float, str]:
    """Local (zmin, zmax) and where it comes from."""
    off = o.offset[2]
    if cfg.z_min is not None and cfg.z_max is not None:
        return float(cfg.z_min) - off, float(cfg.z_max) - off, "Z_MIN/Z_MAX"
    zs = known_heights(o)
    cams = np.array([o.images[i].C[2] for i in nadir_images(o)])
    if len(zs) >= 2 and o.points is not None and len(o.points) >= 20:
        lo, hi = np.percentile(zs, [0.5, 99.5])
        margin = cfg.z_margin or max(10 * (cfg.z_step or 0.0), 0.1 * (hi - lo), 2.0)
        lo, hi, src = lo - margin, hi + margin, "sparse points"
    elif len(zs):
        # ground known (GCPs) but not the objects on it: up to half the flying height above the highest
        ground_lo, ground_hi = float(zs.min()), float(zs.max())
        height = float(np.median(cams)) - ground_hi
        if not height > 0:
            raise InputError("Z_MIN/Z_MAX: the cameras are not above the control points; give the Z range")
        lo, hi, src = (
            ground_lo - max(2.0, 0.05 * height),
            ground_hi + 0.5 * height,
            "GCP heights and flying height",
        )
    else:
        raise InputError(
            "Z_MIN/Z_MAX: the orientation has no sparse points or GCPs to derive the height range from; "
            "give Z_MIN and Z_MAX or a Z_SURFACE raster"
        )
    if cfg.z_min is not None:
        lo = float(cfg.z_min) - off
    if cfg.z_max is not None:
        hi = float(cfg.z_max) - off
    if not hi > lo:
        raise InputError(f"Z_MIN/Z_MAX: empty height range {lo + off:.3f} .. {hi + off:.3f}")
    # never at or above the cameras
    top = float(np.min(cams)) - 1.0
    if hi > top:
        hi = max(top, lo + 1.0)
    return float(lo), float(hi), src


def default_resolution(o: Orientation, z_local: float) -> float:
    g = [abs(o.images[i].C[2] - z_local) / o.camera_of(o.images[i]).fx for i in nadir_images(o)]
    return float(np.median(g))


#: Cells across the longer side of the raster on which :func:`default_extent` counts the footprints.
EXTENT_CELLS = 256


def _inside_polygon(px: np.ndarray, py: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Even-odd test of the points ``(px, py)`` (same shapes) against the polygon ``poly`` (M, 2)."""
    inside = np.zeros(px.shape, bool)
    x, y = poly[:, 0], poly[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    for x0, y0, x1, y1 in zip(x, y, xn, yn, strict=True):
        if y0 == y1:
            continue
        cross = (y0 > py) != (y1 > py)
        xi = x0 + (py - y0) * (x1 - x0) / (y1 - y0)
        inside ^= cross & (px < xi)
    return inside


def default_extent(
    o: Orientation, z_local: float, max_view_angle: float | None = None, min_views: int = 2
) -> tuple[float, float, float, float]:
    """World extent: the area seen by at least ``min_views`` near-nadir images, and the sparse points.

    The footprints of the near-nadir images on the plane ``Z = z_local`` are
    counted on a raster of :data:`EXTENT_CELLS` cells across (a cell counts for
    an image when it lies in its footprint and, with ``max_view_angle``, its
    ray to the camera is at most that far from the vertical, as in the
    matching); the extent is the bounding box of the cells seen by at least
    ``min_views`` of them (every one, when no cell is), united with the 1-99 %
    box of the sparse points (terrain above or below ``z_local`` is seen a
    little elsewhere). The sparse points alone would leave out the parts of the
    block where few tie points were kept, often a large share of the area the
    photos see.
    """
    from ..geometry.footprint import footprint_on_plane

    off = o.offset
    feet = []
    for i in nadir_images(o):
        im = o.images[i]
        fp = footprint_on_plane(im.R, im.C, o.camera_of(im), z_local)
        if fp is not None and np.isfinite(fp).all():
            feet.append((fp, np.asarray(im.C, np.float64)))
    boxes = []
    if feet:
        allp = np.vstack([f for f, _ in feet])
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        step = max(float(np.max(hi - lo)) / EXTENT_CELLS, 1e-9)
        xs = lo[0] + (np.arange(int(np.ceil((hi[0] - lo[0]) / step)) + 1)) * step
        ys = lo[1] + (np.arange(int(np.ceil((hi[1] - lo[1]) / step)) + 1)) * step
        X, Y = np.meshgrid(xs, ys)
        count = np.zeros(X.shape, np.int32)
        tan_max = math.tan(math.radians(max_view_angle)) if max_view_angle is not None else None
        for fp, C in feet:
            seen = _inside_polygon(X, Y, fp)
            if tan_max is not None:
                height = C[2] - float(z_local)
                seen &= np.hypot(X - C[0], Y - C[1]) <= tan_max * max(height, 0.0)
            count += seen
        need = min(int(min_views), len(feet))
        ok = count >= need
        if not ok.any():
            ok = count >= 1
        if ok.any():
            boxes.append((X[ok].min() - step, Y[ok].min() - step, X[ok].max() + step, Y[ok].max() + step))
    if o.points is not None and len(o.points) >= 20:
        plo = np.percentile(o.points.xyz[:, :2], 1, axis=0)
        phi = np.percentile(o.points.xyz[:, :2], 99, axis=0)
        boxes.append((plo[0], plo[1], phi[0], phi[1]))
    if not boxes:
        raise InputError("EXTENT: no image sees the ground; give an extent")
    b = np.array(boxes, np.float64)
    x0, y0 = b[:, 0].min(), b[:, 1].min()
    x1, y1 = b[:, 2].max(), b[:, 3].max()
    return (float(x0 + off[0]), float(y0 + off[1]), float(x1 + off[0]), float(y1 + off[1]))


def check_overlap(o: Orientation, grid: RasterGrid, ground: float) -> None:
    """The extent must meet the area the images see (clear error instead of an empty DSM)."""
    x0, y0, x1, y1 = grid.extent
    try:
        bx0, by0, bx1, by1 = default_extent(o, ground, min_views=1)
    except InputError:
        return
    if x1 < bx0 or x0 > bx1 or y1 < by0 or y0 > by1:
        raise InputError(
            f"EXTENT: ({x0:.2f}, {y0:.2f}, {x1:.2f}, {y1:.2f}) does not intersect the area the images see "
            f"({bx0:.2f}, {by0:.2f}, {bx1:.2f}, {by1:.2f}) in {o.crs}"
        )


def surface_range(path, o: Orientation, cfg: OsgmConfig, extent) -> tuple[float, float, str]:
    """Local Z range of a surface raster over the extent (or all of it), widened by the margin."""
    from ..rasterio_io import raster_grid, read_onto_grid

    sg = raster_grid(path, require_crs=True)
    ext = extent if extent is not None else sg.extent
    step = max(sg.res, (ext[2] - ext[0]) / 512, (ext[3] - ext[1]) / 512)
    g = RasterGrid.from_extent(ext, step, o.crs)
    vals = read_onto_grid(path, g, resampling="nearest")
    if not np.isfinite(vals).any():
        raise InputError(f"Z_SURFACE: {path} has no data over the extent")
    lo, hi = float(np.nanmin(vals)), float(np.nanmax(vals))
    margin = cfg.z_margin or max(5 * (cfg.z_step or 0.0), 2.0)
    off = o.offset[2]
    zlo = (float(cfg.z_min) if cfg.z_min is not None else lo - margin) - off
    zhi = (float(cfg.z_max) if cfg.z_max is not None else hi + margin) - off
    if not zhi > zlo:
        raise InputError(f"Z_MIN/Z_MAX: empty height range {zlo + off:.3f} .. {zhi + off:.3f}")
    return zlo, zhi, "Z_SURFACE"
