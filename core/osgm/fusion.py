"""Visibility check across OSGM's reference systems: points that confident surfaces hide from their
own photos.

An oblique reference system (:mod:`.systems`) matches every cell of its grid along its own viewing
direction, and on a part of the scene that few of its photos see it can settle on a height far
behind the visible surface: on fountain-P11 (``bench/fountain.py``) a quarter of the raw points lay
more than 0.3 m behind the wall. Such a point cannot have been seen: between it and its photos
stands a surface that the block reconstructs with confidence. The check (:func:`visible_points`):

1. **Occluders**: the points of every oblique system whose confidence is at least
   :data:`CONFIDENT`, the level the DSM filter trusts a cell at, and the nadir DSM's cells of that
   confidence drawn as cell columns with their walls (:func:`~truortho.core.ortho.zbuffer.dsm_triangles`,
   steps over :data:`MARGIN_CELLS` cells): a 2.5-D grid has no points on its walls, and drawn as
   points it would let the rays through them.
2. **Depth buffers**: for every photo of an oblique system, the occluders' depths along its optical
   axis, the nearest per buffer pixel; a pixel spans :data:`PIXEL_SPACINGS` times the median
   spacing of the occluders in that photo, so that a surface leaves few empty pixels. The DSM's
   columns are rasterised into the same buffer (:func:`~truortho.core.ortho.zbuffer.render_depth`).
3. **Visibility**: a point is hidden in a photo that frames it when the buffer there holds a depth
   more than :data:`MARGIN_CELLS` cells nearer than the point's own. A point is kept when at least
   :data:`MIN_VIEWS` photos of its own system frame it and do not hide it (matching needs a pair),
   or when fewer than that frame it at all (no evidence against it).

The check only removes points; the nadir DSM is not changed.
"""

from __future__ import annotations

import numpy as np

from ..errors import CancelledError, InputError
from ..jit import njit
from ..ortho.zbuffer import render_depth
from ..progress import Progress, as_progress
from ..surface.filter.config import DsmFilterConfig
from .views import _project_many, monotonic_radius2

#: The confidence from which a point hides others (the DSM filter's ``confident``).
CONFIDENT = DsmFilterConfig.confident
#: Depth margin (cells of the grid) by which an occluder must be nearer than the point it hides.
MARGIN_CELLS = 6.0
#: Photos of its own system that must see a point (a pair: what matching needs).
MIN_VIEWS = 2
#: Buffer pixel side in median occluder spacings (a surface fills its pixels).
PIXEL_SPACINGS = 1.5


@njit
def _depths(P, R, C):
    n = P.shape[0]
    out = np.empty(n)
    for i in range(n):
        out[i] = R[2, 0] * (P[i, 0] - C[0]) + R[2, 1] * (P[i, 1] - C[1]) + R[2, 2] * (P[i, 2] - C[2])
    return out


@njit
def _pixel(uv, i, scale, h, w):
    """Buffer pixel ``(row, col)`` of point ``i`` (``uv`` pixels, NaN = not framed); ``(-1, -1)``
    where it is not framed."""
    u = uv[i, 0]
    v = uv[i, 1]
    if not (u == u and v == v):
        return -1, -1
    iu = int((u + 0.5) * scale)
    iv = int((v + 0.5) * scale)
    if 0 <= iu < w and 0 <= iv < h:
        return iv, iu
    return -1, -1


@njit
def _splat(uv, depth, scale, zbuf):
    """Nearest depth per buffer pixel."""
    h, w = zbuf.shape
    for i in range(uv.shape[0]):
        r, c = _pixel(uv, i, scale, h, w)
        if r >= 0 and depth[i] < zbuf[r, c]:
            zbuf[r, c] = depth[i]


@njit
def _count(uv, depth, scale, zbuf, margin, framed, seen):
    """Per point: one more photo that frames it, and one more that sees it (no buffer depth more
    than ``margin`` nearer)."""
    h, w = zbuf.shape
    for i in range(uv.shape[0]):
        r, c = _pixel(uv, i, scale, h, w)
        if r >= 0:
            framed[i] += 1
            if not (zbuf[r, c] < depth[i] - margin):
                seen[i] += 1


def _project(P, view):
    uv = np.empty((len(P), 2))
    _project_many(P, np.ascontiguousarray(view[0], np.float64), np.ascontiguousarray(view[1], np.float64),
                  view[2].params, float(view[3]), uv)  # fmt: skip
    return uv


def visible_points(
    points, confidence, system_images, cameras, res: float, occluders=None, surface=None,
    progress: Progress | None = None,
) -> list[np.ndarray]:
    """Which points of every system its own photos can see (module docstring).

    Parameters
    ----------
    points : list of (N_k, 3) arrays, local frame, one per oblique system
    confidence : list of (N_k,) arrays in [0, 1]
    system_images : list of lists of image indices (the photos of each system)
    cameras : list of ``(R, C, Camera)`` per image index (world -> camera rotation, centre, local)
    res : float
        Cell size of the grids (m): the depth margin is :data:`MARGIN_CELLS` cells.
    occluders : (M, 3) array, optional
        More confident surface points, local frame.
    surface : :class:`~truortho.core.ortho.zbuffer.Triangles`, optional
        A confident surface drawn into the buffers as triangles (the nadir DSM's confident cells
        with their walls, :func:`~truortho.core.ortho.zbuffer.dsm_triangles`): points cannot hide
        what lies behind a wall, since a 2.5-D grid has no points on its walls.
    progress : Progress, optional
        Reported per photo; a cancelled check raises :class:`~truortho.core.errors.CancelledError`.

    Returns
    -------
    list of (N_k,) bool arrays: True = kept.
    """
    if not (np.isfinite(res) and res > 0):
        raise InputError(f"visible_points: res must be a number > 0, got {res!r}")
    if not (len(points) == len(confidence) == len(system_images)):
        raise InputError("visible_points: expected one confidence array and one image list per system")
    pts = [np.ascontiguousarray(np.asarray(p, np.float64)) for p in points]
    for p, c in zip(pts, confidence, strict=True):
        if p.ndim != 2 or p.shape[1] != 3:
            raise InputError(f"visible_points: points must have shape (N, 3), got {p.shape}")
        if np.shape(c) != (len(p),):
            raise InputError(f"visible_points: {len(p)} points but {np.shape(c)} confidences")
    users = sorted({int(i) for imgs in system_images for i in imgs})
    if users and (users[0] < 0 or users[-1] >= len(cameras)):
        raise InputError(
            f"visible_points: image indices must lie in 0 .. {len(cameras) - 1}, got {users[0]}..{users[-1]}"
        )
    progress = as_progress(progress)
    parts = [p[np.asarray(c) >= CONFIDENT] for p, c in zip(pts, confidence, strict=True)]
    if occluders is not None and len(occluders):
        parts.append(np.asarray(occluders, np.float64).reshape(-1, 3))
    occ = np.ascontiguousarray(np.concatenate(parts) if parts else np.zeros((0, 3)))
    framed = [np.zeros(len(p), np.int64) for p in pts]
    seen = [np.zeros(len(p), np.int64) for p in pts]
    margin = MARGIN_CELLS * res
    for j, i in enumerate(users):
        if progress.cancelled():
            raise CancelledError("visibility check cancelled")
        progress.update(j / len(users), "visibility check of the oblique points")
        R0, C0, cam = cameras[i]
        R, C = np.ascontiguousarray(R0, np.float64), np.ascontiguousarray(C0, np.float64)
        view = (R, C, cam, monotonic_radius2(cam))
        uv = _project(occ, view)
        d_occ = _depths(occ, R, C)
        # buffer pixel: PIXEL_SPACINGS median occluder spacings (f res / depth pixels)
        d, ok = d_occ, np.isfinite(uv[:, 0]) & (d_occ > 0)
        if surface is not None and not ok.any():
            sv = np.ascontiguousarray(surface.vertices)
            d = _depths(sv, R, C)
            ok = (d > 0) & np.isfinite(_project(sv, view)[:, 0])
        spacing = float(np.median(cam.fx * res / d[ok])) if ok.any() else 1.0
        scale = 1.0 / max(PIXEL_SPACINGS * spacing, 1.0)
        zbuf = np.full((int(cam.height * scale) + 1, int(cam.width * scale) + 1), np.inf)
        _splat(uv, d_occ, scale, zbuf)
        if surface is not None and len(surface):
            drawn = render_depth(surface, R, C, cam, (0, 0, zbuf.shape[1], zbuf.shape[0]), scale, cull=False)
            np.minimum(zbuf, drawn, out=zbuf)
        for k, imgs in enumerate(system_images):
            if i not in imgs or not len(pts[k]):
                continue
            _count(_project(pts[k], view), _depths(pts[k], R, C), scale, zbuf, margin, framed[k], seen[k])
    progress.update(1.0, "visibility check of the oblique points")
    return [(s >= MIN_VIEWS) | (f < MIN_VIEWS) for f, s in zip(framed, seen, strict=True)]
