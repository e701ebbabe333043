"""Image footprints: where an image's frame meets a horizontal plane."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from .camera import Camera, pixel_to_ray


def frame_outline(camera: Camera, samples_per_edge: int = 8) -> np.ndarray:
    """Pixels along the image border (outer pixel edges), counter-clockwise in the image, (M, 2)."""
    if samples_per_edge < 1:
        raise InputError("samples_per_edge must be >= 1")
    w, h = camera.width, camera.height
    t = np.linspace(0.0, 1.0, samples_per_edge, endpoint=False)
    x0, x1, y0, y1 = -0.5, w - 0.5, -0.5, h - 0.5
    top = np.column_stack([x0 + t * (x1 - x0), np.full_like(t, y0)])
    right = np.column_stack([np.full_like(t, x1), y0 + t * (y1 - y0)])
    bottom = np.column_stack([x1 - t * (x1 - x0), np.full_like(t, y1)])
    left = np.column_stack([np.full_like(t, x0), y1 - t * (y1 - y0)])
    return np.vstack([top, right, bottom, left])


def footprint_on_plane(
    R, C, camera: Camera, z: float, samples_per_edge: int = 8, max_distance: float | None = None
) -> np.ndarray | None:
    """Polygon (M, 2) in the local frame where the image frame meets the plane ``Z = z``.

    Rays that point away from the plane (above the horizon of an oblique
    image) are cut at ``max_distance`` (default: 20 times the height above
    the plane) along their horizontal direction. Returns None when the camera
    sees none of the plane.
    """
    C = np.asarray(C, dtype=np.float64).reshape(3)
    height = C[2] - float(z)
    if not np.isfinite(height):
        raise InputError("footprint height must be finite")
    if max_distance is None:
        max_distance = 20.0 * max(abs(height), 1.0)
    uv = frame_outline(camera, samples_per_edge)
    _, d = pixel_to_ray(uv, R, C, camera)
    ok = np.all(np.isfinite(d), axis=1)
    d = d[ok]
    if len(d) == 0:
        return None
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (float(z) - C[2]) / d[:, 2]
    hits = s > 0
    if not hits.any():
        return None
    pts = np.empty((len(d), 2))
    pts[hits] = C[:2] + d[hits, :2] * s[hits, None]
    horiz = d[~hits, :2]
    norm = np.linalg.norm(horiz, axis=1, keepdims=True)
    norm[norm == 0] = 1.0
    pts[~hits] = C[:2] + horiz / norm * max_distance
    # cap far hits of grazing rays, too
    off = pts - C[:2]
    dist = np.linalg.norm(off, axis=1)
    far = dist > max_distance
    pts[far] = C[:2] + off[far] / dist[far, None] * max_distance
    return pts
