"""Ground truth of a synthetic scene: DSM, true orthophoto, visibility, GCPs.

Rasters are north-up grids in the *world* frame described by a GDAL
geotransform ``(x_min, res, 0, y_max, 0, -res)``; the value of cell
``(row, col)`` is the surface sampled at its centre
``(x_min + (col + 0.5) res, y_max - (row + 0.5) res)`` (a point sample, not
a cell maximum or mean).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from ..geometry.camera import Camera, project_points
from ..orientation import GCP, Image
from .raycast import cast_rays
from .surface import Surface
from .texture import GROUND, ROOF, _colour_many


def grid_centres(resolution: float, extent_world, offset):
    """Local cell-centre coordinates and the geotransform of a world extent.

    Returns
    -------
    xy : (rows * cols, 2) float64 local cell centres, row-major, row 0 north.
    shape : (rows, cols)
    geotransform : (x_min, res, 0, y_max, 0, -res), world frame.
    """
    res = float(resolution)
    if not (math.isfinite(res) and res > 0):
        raise InputError(f"resolution must be a positive number of metres, got {resolution!r}")
    x0, y0, x1, y1 = (float(v) for v in extent_world)
    if not (x1 > x0 and y1 > y0):
        raise InputError(f"extent must be (xmin, ymin, xmax, ymax) with xmin < xmax and ymin < ymax, "
                         f"got {extent_world}")
    cols = max(1, int(math.ceil((x1 - x0) / res - 1e-9)))
    rows = max(1, int(math.ceil((y1 - y0) / res - 1e-9)))
    if rows * cols > 200_000_000:
        raise InputError(f"grid of {rows} x {cols} cells is too large; use a coarser resolution")
    xs = x0 + (np.arange(cols) + 0.5) * res - offset[0]
    ys = y1 - (np.arange(rows) + 0.5) * res - offset[1]
    X, Y = np.meshgrid(xs, ys)
    return np.column_stack([X.ravel(), Y.ravel()]), (rows, cols), (x0, res, 0.0, y1, 0.0, -res)


def dsm(surface: Surface, resolution: float, extent_world, offset):
    """Surface heights (world z) at cell centres: ``(float32 (rows, cols), geotransform)``."""
    xy, shape, gt = grid_centres(resolution, extent_world, offset)
    h, _ = surface.height(xy)
    return (h + offset[2]).reshape(shape).astype(np.float32), gt


def orthophoto(surface: Surface, palette, tex, resolution: float, extent_world, offset, sun=None):
    """True colour seen vertically from above at cell centres.

    Returns ``(float32 (rows, cols, 3) in [0, 1], geotransform)``: roofs
    and ground only (walls are never seen from straight above), no exposure
    differences; cast shadows of ``sun`` (:func:`~.render.sun_vector`) as in the images.
    """
    xy, shape, gt = grid_centres(resolution, extent_world, offset)
    h, bid = surface.height(xy)
    mat = np.where(bid >= 0, ROOF, GROUND).astype(np.int64)
    pts = np.ascontiguousarray(np.column_stack([xy, h]))
    rgb = _colour_many(pts, mat, np.ascontiguousarray(bid), palette, tex)
    if sun is not None and sun[3] > 0:
        from .render import sunlight_many

        rgb *= sunlight_many(pts, np.asarray(sun, dtype=np.float64), surface.terr, surface.bld, surface.grid,
                             surface.cell_max, surface.cell_bld)[:, None]
    return rgb.reshape(shape + (3,)).astype(np.float32), gt


def visibility(surface: Surface, points_local, image: Image, camera: Camera, tol: float = 0.01,
               check_frame: bool = True, margin: float = 0.0):
    """Whether local points are seen by an image.

    A point is visible when it lies in front of the camera, projects inside
    the frame shrunk by ``margin`` pixels (if ``check_frame``), and the ray
    from the projection centre towards it hits nothing closer than
    ``|P - C| - tol`` (metres). Points on the surface are found at their own
    distance to ~1e-9 m.

    Returns
    -------
    visible : (N,) bool
    uv : (N, 2) float64 pixel coordinates (NaN behind the camera)
    hit_distance : (N,) float64 distance of the first hit along the ray (NaN: none)
    """
    P = np.asarray(points_local, dtype=np.float64).reshape(-1, 3)
    if not np.all(np.isfinite(P)):
        raise InputError("visibility: points must be finite")
    uv, depth = project_points(P, image.R, image.C, camera, return_depth=True)
    d = P - image.C
    dist = np.linalg.norm(d, axis=1)
    ok = (depth > 0) & (dist > 0)
    if check_frame:
        with np.errstate(invalid="ignore"):
            ok &= ((uv[:, 0] >= -0.5 + margin) & (uv[:, 0] <= camera.width - 0.5 - margin)
                   & (uv[:, 1] >= -0.5 + margin) & (uv[:, 1] <= camera.height - 0.5 - margin))
    hit = np.full(len(P), np.nan)
    idx = np.flatnonzero(ok)
    if len(idx):
        t, _, _ = cast_rays(surface, image.C, d[idx], dist[idx] + 1.0)
        hit[idx] = t
        ok[idx] = np.isnan(t) | (t >= dist[idx] - tol)
    return ok, uv, hit


def select_gcps(surface: Surface, images: list[Image], camera: Camera, offset, n: int, on_roof: bool,
                check_fraction: float, pixel_sigma: float, clearance: float, min_views: int,
                seed: int) -> list[GCP]:
    """Well-spread ground control on open ground (plus optionally one flat-roof point).

    Candidates on a regular grid over the extent at least ``clearance`` from
    every footprint and seen (20 px inside the frame) by at least
    ``min_views`` images are picked by farthest-point sampling from the
    south-west corner. The last ``round(check_fraction * total)`` points in
    that order (the roof point last) get role ``'check'``. Observations are
    the projections into every image where the point is visible, plus
    Gaussian noise ``pixel_sigma`` (seeded); coordinates are world.
    """
    x0, y0, x1, y1 = surface.config.extent
    step = max(1.0, min(x1 - x0, y1 - y0) / 50)
    xs = np.arange(x0 + 0.05 * (x1 - x0), x1 - 0.05 * (x1 - x0) + 1e-9, step)
    ys = np.arange(y0 + 0.05 * (y1 - y0), y1 - 0.05 * (y1 - y0) + 1e-9, step)
    X, Y = np.meshgrid(xs, ys)
    xy = np.column_stack([X.ravel(), Y.ravel()])
    xy = xy[surface.footprint_distance(xy) >= clearance]
    pts = np.column_stack([xy, surface.height(xy)[0]])
    views = np.zeros(len(pts), np.int64)
    for im in images:
        views += visibility(surface, pts, im, camera, margin=20.0)[0]
    pts = pts[views >= min_views]
    if len(pts) < n:
        raise InputError(f"only {len(pts)} open-ground GCP candidates are seen by {min_views} images; "
                         f"reduce n_gcps, gcp_clearance or min_gcp_views")
    chosen: list[int] = []
    if n > 0:
        chosen.append(int(np.argmin(np.hypot(pts[:, 0] - x0, pts[:, 1] - y0))))
        dmin = np.hypot(pts[:, 0] - pts[chosen[0], 0], pts[:, 1] - pts[chosen[0], 1])
        while len(chosen) < n:
            k = int(np.argmax(dmin))
            chosen.append(k)
            dmin = np.minimum(dmin, np.hypot(pts[:, 0] - pts[k, 0], pts[:, 1] - pts[k, 1]))
    sel = [pts[k] for k in chosen]
    names = [f"gcp_{i + 1:02d}" for i in range(len(sel))]
    if on_roof:
        flat = [b for b in surface.buildings if b.roof == "flat" and not b.tower]
        flat = flat or [b for b in surface.buildings if b.roof == "flat"]
        if flat:
            b = flat[0]
            sel.append(np.array([b.center[0], b.center[1], b.eave_top]))
            names.append("gcp_roof")
    total = len(sel)
    n_check = int(round(check_fraction * total))
    rng = np.random.default_rng([seed, 31])
    gcps = []
    P = np.array(sel).reshape(-1, 3)
    vis = [visibility(surface, P, im, camera) for im in images]
    for k in range(total):
        obs = []
        for im, (ok, uv, _) in zip(images, vis, strict=True):
            if ok[k]:
                u, v = uv[k]
                if pixel_sigma > 0:
                    u, v = u + rng.normal(0.0, pixel_sigma), v + rng.normal(0.0, pixel_sigma)
                obs.append((im.name, float(u), float(v)))
        role = "check" if k >= total - n_check else "gcp"
        gcps.append(GCP(names[k], P[k] + np.asarray(offset, dtype=np.float64), role, None, obs))
    return gcps
