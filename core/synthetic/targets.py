"""Synthetic ground targets with known truth (for the GCP measurement tests and bench).

A *pattern* is a 2-D grey raster. It is either warped into an image by a known homography
(:func:`render_homography`: image pixel = H @ pattern pixel, both with (0, 0) = centre of the
top-left pixel) or laid on the horizontal plane ``Z = z`` of the local frame and photographed
by a camera (:func:`render_on_plane`; pattern row 0 is north, column 0 west, texel size in
metres, the pattern centred on ``(x, y)``). Both supersample every pixel ``s x s`` times, so
edges are anti-aliased as a camera integrates them and sub-pixel truth is meaningful.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..geometry.camera import Camera, undistort_points


def disc_pattern(size: int, radius: float, dark: bool = True, supersample: int = 4) -> np.ndarray:
    """Square ``size x size`` raster of a centred disc (0 on 1 when ``dark``), anti-aliased."""
    s = int(supersample)
    c = (size - 1) / 2.0
    o = (np.arange(s) + 0.5) / s - 0.5
    g = np.arange(size)[:, None] + o[None, :]
    yy = g.reshape(-1)[:, None]
    xx = g.reshape(-1)[None, :]
    inside = ((xx - c) ** 2 + (yy - c) ** 2 <= radius**2).astype(np.float64)
    inside = inside.reshape(size, s, size, s).mean(axis=(1, 3))
    return 1.0 - inside if dark else inside


def checker_pattern(size: int) -> np.ndarray:
    """``size x size`` raster of two black and two white quadrants meeting at the centre ("X" target).

    ``size`` even puts the saddle point on the corner between the four central texels, i.e.
    at pattern pixel ``((size - 1) / 2, (size - 1) / 2)``.
    """
    i = np.arange(size)
    top = i[:, None] < size / 2
    left = i[None, :] < size / 2
    return (top == left).astype(np.float64)


def _lookup(pattern: np.ndarray, px: np.ndarray, py: np.ndarray, background: float) -> np.ndarray:
    """Bilinear lookup with ``background`` outside (pixel-centre convention)."""
    h, w = pattern.shape
    padded = np.pad(pattern, 1, constant_values=background)
    x = np.clip(px + 1.0, 0.0, w + 1.0)
    y = np.clip(py + 1.0, 0.0, h + 1.0)
    x0 = np.clip(np.floor(x).astype(np.int64), 0, w)
    y0 = np.clip(np.floor(y).astype(np.int64), 0, h)
    fx = x - x0
    fy = y - y0
    v = (
        padded[y0, x0] * (1 - fx) * (1 - fy)
        + padded[y0, x0 + 1] * fx * (1 - fy)
        + padded[y0 + 1, x0] * (1 - fx) * fy
        + padded[y0 + 1, x0 + 1] * fx * fy
    )
    outside = (px < -1) | (py < -1) | (px > w) | (py > h)
    v[outside] = background
    return v


def _subpixels(shape, supersample: int) -> tuple[np.ndarray, np.ndarray]:
    h, w = shape
    s = int(supersample)
    o = (np.arange(s) + 0.5) / s - 0.5
    xs = (np.arange(w)[:, None] + o[None, :]).reshape(-1)
    ys = (np.arange(h)[:, None] + o[None, :]).reshape(-1)
    gx, gy = np.meshgrid(xs, ys)
    return gx, gy


def render_homography(pattern, H, shape, supersample: int = 4, background: float | None = None) -> np.ndarray:
    """Warp ``pattern`` into an image of ``shape = (H, W)`` through ``image = H @ pattern``.

    Returns
    -------
    (H, W) float64
        Grey values, each pixel the mean of ``supersample**2`` samples; outside the pattern
        ``background`` (default: the pattern's border mean).
    """
    pat = np.asarray(pattern, dtype=np.float64)
    Hm = np.asarray(H, dtype=np.float64)
    if pat.ndim != 2 or Hm.shape != (3, 3):
        raise InputError("render_homography: pattern must be 2-D and H 3x3")
    bg = (
        float(np.concatenate([pat[0], pat[-1], pat[:, 0], pat[:, -1]]).mean())
        if background is None
        else background
    )
    X, Y = _subpixels(shape, supersample)
    Hi = np.linalg.inv(Hm)
    d = Hi[2, 0] * X + Hi[2, 1] * Y + Hi[2, 2]
    px = (Hi[0, 0] * X + Hi[0, 1] * Y + Hi[0, 2]) / d
    py = (Hi[1, 0] * X + Hi[1, 1] * Y + Hi[1, 2]) / d
    v = _lookup(pat, px, py, bg)
    s = int(supersample)
    return v.reshape(shape[0], s, shape[1], s).mean(axis=(1, 3))


def render_on_plane(
    pattern,
    texel: float,
    centre_xy,
    z: float,
    R,
    C,
    camera: Camera,
    supersample: int = 3,
    background: float | None = None,
    window: tuple[int, int, int, int] | None = None,
) -> np.ndarray:
    """Photograph a pattern lying on the plane ``Z = z`` (local frame) with a camera.

    Parameters
    ----------
    pattern : (h, w) array
        Grey raster, row 0 north, column 0 west.
    texel : float
        Size of one pattern texel on the ground, metres.
    centre_xy : (2,) float
        Local X, Y of the pattern's centre (between texels for even sizes).
    z : float
        Height of the plane, metres.
    R, C, camera
        Exterior (world-to-camera rotation, centre) and interior orientation.
    window : (x0, y0, width, height), optional
        Render only this window of the image (default the whole image).

    Returns
    -------
    (height, width) float64
    """
    pat = np.asarray(pattern, dtype=np.float64)
    bg = (
        float(np.concatenate([pat[0], pat[-1], pat[:, 0], pat[:, -1]]).mean())
        if background is None
        else background
    )
    x0, y0, w, h = window if window is not None else (0, 0, camera.width, camera.height)
    X, Y = _subpixels((h, w), supersample)
    uv = np.column_stack([X.reshape(-1) + x0, Y.reshape(-1) + y0])
    xy = undistort_points(uv, camera)
    d = np.column_stack([xy, np.ones(len(xy))]) @ np.asarray(R, dtype=np.float64)
    Cv = np.asarray(C, dtype=np.float64).reshape(3)
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = (z - Cv[2]) / d[:, 2]
    gx = Cv[0] + lam * d[:, 0]
    gy = Cv[1] + lam * d[:, 1]
    ph, pw = pat.shape
    px = (gx - centre_xy[0]) / texel + (pw - 1) / 2.0
    py = (centre_xy[1] - gy) / texel + (ph - 1) / 2.0
    bad = ~np.isfinite(px) | ~np.isfinite(py) | ~(lam > 0)
    px[bad] = -1e9
    py[bad] = -1e9
    v = _lookup(pat, px, py, bg)
    s = int(supersample)
    return v.reshape(h, s, w, s).mean(axis=(1, 3))
