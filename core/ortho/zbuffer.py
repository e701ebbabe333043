"""Depth buffers of a triangulated surface and the per-cell visibility test.

The surface is a set of generic triangles (:class:`Triangles`: vertices in the
*local* frame of the orientation, faces as vertex indices), so a DSM and a mesh
are the same input:

* :func:`dsm_triangles` turns a height grid into the boundary of the union of
  its cell columns: every cell is a flat square top at its height (two
  triangles) and every edge between neighbouring cells whose heights differ by
  more than ``wall_min`` becomes a vertical wall quad (two triangles) from the
  lower to the higher top. The result is watertight up to the steps below
  ``wall_min`` and exact at cell centres: the surface point of a cell (its
  centre at its height) lies on its own top face.
* a mesh gives its triangles directly (:mod:`.surface`).

Winding: faces are counter-clockwise seen from outside (tops face up, walls face
the lower cell). A front face projects to a *negative* signed area in pixel
coordinates (x right, y down), which :func:`render_depth` uses for back-face
culling.

:func:`render_depth` rasterises the triangles into one image's depth buffer
(camera z, metres, of the nearest surface at every buffer pixel centre, inf where
nothing is drawn) over a window of the image, with frustum culling (faces behind
the camera, outside the window or beyond the valid field of the distortion
model are skipped) and optional back-face culling; depth is interpolated
perspective-correctly (``1/z`` is linear in the image). The buffer may be
coarser than the image (``scale`` < 1, pixel centres mapping as in
:meth:`~truortho.core.geometry.camera.Camera.scaled`). Faces come in groups
(:attr:`Triangles.groups`: a DSM's by blocks of cells) with bounding boxes; a
group whose projected box, widened by half its size for lens distortion, misses
the window is skipped whole, and a vertex is projected only when a face needs it.

:func:`point_visibility` projects cell surface points into the buffer: a point
is *visible* when its depth ``z`` satisfies ``z <= zbuf + tol`` at the buffer
pixel nearest to its projection, and *near an occlusion edge* when some pixel of
the 3 x 3 neighbourhood holds a surface closer than ``z - tol`` (the image
colour sampled there may mix in the occluder). The tolerance ``tol`` is given
per point by the caller (:func:`depth_tolerance`): it grows with the cell size,
the buffer's pixel footprint and the tangent of the viewing angle, because the
depth of a flat-topped stair approximation of a smooth surface differs from the
true surface by up to that much within one buffer pixel.

That tolerance and the buffer's pixels cannot resolve an occluder right next to
the point: a wall a fraction of a cell away lies within the tolerance, and a ray
past a building's corner may run between two buffer pixel centres. The fused
pass of :func:`view_cells_into` therefore also follows the cell's own ray through
the 5 x 5 cells around it where one of them is much higher (:func:`near_step_mask`)
and hides the cell when the ray enters a cell below its top by more than the
same tolerance (on battery scene 4, ground cells diagonally next to a building's
corner were textured with the building's colour). A cell near an occlusion edge
is followed along its ray through the whole height grid around the tile
(:func:`_ray_hidden`), as far as the ray can be hidden: next to an edge the
buffer decides only to its pixel, and a ray past a diagonal roof outline or
grazing a roof's edge runs between two of its pixel centres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..geometry.camera import Camera
from ..jit import njit


@dataclass
class Triangles:
    """A triangle soup in the local frame.

    Attributes
    ----------
    vertices : (N, 3) float64
        Local coordinates (``world - offset``), metres.
    faces : (M, 3) int32
        Vertex indices, counter-clockwise seen from outside when ``oriented``.
    oriented : bool
        The winding is consistent (back-face culling allowed).
    groups : (G + 1,) int64, optional
        Face offsets of groups of nearby faces (default one group); with :attr:`boxes`, their
        bounding boxes, :func:`render_depth` skips the groups that cannot reach its window.
    """

    vertices: np.ndarray
    faces: np.ndarray
    oriented: bool = True
    groups: np.ndarray | None = None

    def __post_init__(self) -> None:
        v = np.ascontiguousarray(np.asarray(self.vertices, dtype=np.float64))
        f = np.ascontiguousarray(np.asarray(self.faces, dtype=np.int32))
        if v.ndim != 2 or v.shape[1] != 3:
            raise InputError(f"triangles: vertices must have shape (N, 3), got {v.shape}")
        if f.ndim != 2 or f.shape[1] != 3:
            raise InputError(f"triangles: faces must have shape (M, 3), got {f.shape}")
        if len(f) and (f.min() < 0 or f.max() >= len(v)):
            raise InputError("triangles: a face refers to a vertex index out of range")
        self.vertices = v
        self.faces = f
        g = np.array([0, len(f)], np.int64) if self.groups is None else np.asarray(self.groups, np.int64)
        if g.ndim != 1 or len(g) < 2 or g[0] != 0 or g[-1] != len(f) or np.any(np.diff(g) < 0):
            raise InputError("triangles: groups must be ascending face offsets from 0 to the face count")
        self.groups = np.ascontiguousarray(g)
        #: (G, 6) bounding box ``x0, y0, z0, x1, y1, z1`` of the vertices of each group's faces
        self.boxes = np.empty((len(g) - 1, 6))
        _group_boxes(v, f, self.groups, self.boxes)

    def __len__(self) -> int:
        return len(self.faces)

    def grouped(self, key: np.ndarray) -> Triangles:
        """The same triangles with the faces grouped by ``key`` (M,) int >= 0 (e.g. a plan block), so
        :func:`render_depth` can skip whole groups outside an image window."""
        k = np.asarray(key, np.int64)
        if k.shape != (len(self.faces),) or (len(k) and k.min() < 0):
            raise InputError("triangles: one non-negative group key per face expected")
        order = np.argsort(k, kind="stable")
        counts = np.bincount(k, minlength=1)
        starts = np.zeros(len(counts) + 1, np.int64)
        starts[1:] = np.cumsum(counts)
        return Triangles(self.vertices, self.faces[order], self.oriented, starts)


@njit
def _group_boxes(verts, faces, starts, out):
    for g in range(len(starts) - 1):
        for q in range(3):
            out[g, q] = np.inf
            out[g, q + 3] = -np.inf
        for f in range(starts[g], starts[g + 1]):
            for m in range(3):
                v = faces[f, m]
                for q in range(3):
                    out[g, q] = min(out[g, q], verts[v, q])
                    out[g, q + 3] = max(out[g, q + 3], verts[v, q])


# ---------------------------------------------------------------- DSM -> triangles


def dsm_triangles(
    heights,
    x_min: float,
    y_max: float,
    res: float,
    include=None,
    wall_min: float = 0.0,
    tops=True,
    block: int = 32,
):
    """Triangles of a height grid: flat cell tops plus vertical walls at steps.

    Parameters
    ----------
    heights : (rows, cols) float
        Surface heights at the cells (local z, metres); NaN = no data (no top,
        no wall).
    x_min, y_max : float
        Local coordinates of the outer north-west corner of cell (0, 0).
    res : float
        Cell size, metres.
    include : (rows, cols) bool, optional
        Cells whose top is emitted (default all valid cells). A wall is emitted
        when at least one of its two cells is included and both are valid.
    wall_min : float
        Height steps up to this value (metres) get no wall.
    tops : bool or (rows, cols) bool
        Emit the tops of all included cells (True), of none (False) or of the
        cells of a mask. Without tops (walls only, rendered double-sided) the
        triangles still decide the visibility of the DSM's own surface points
        exactly: a ray from a surface point up to a camera above the surface
        can only pass below the surface by entering a cell column through one
        of its side walls. The tops near walls make the buffer hold the
        occluding roof itself next to an occlusion boundary, for the
        near-occluder test of :func:`point_visibility`.

    block : int
        Faces are grouped by blocks of ``block`` x ``block`` cells (:attr:`Triangles.groups`).

    Returns
    -------
    Triangles
        Four vertices (corners NW, NE, SE, SW at the cell's height) for every
        cell a face uses, in row-major cell order.
    """
    h = np.ascontiguousarray(heights, dtype=np.float64)
    if h.ndim != 2:
        raise InputError(f"dsm_triangles: heights must be 2-D, got shape {h.shape}")
    if not res > 0:
        raise InputError(f"dsm_triangles: res must be positive, got {res!r}")
    if int(block) < 1:
        raise InputError(f"dsm_triangles: block must be a positive number of cells, got {block!r}")
    rows, cols = h.shape
    valid = np.isfinite(h)
    inc = valid if include is None else (np.asarray(include, dtype=bool) & valid)
    if isinstance(tops, np.ndarray):
        top = inc & np.asarray(tops, dtype=bool)
    else:
        top = inc.copy() if tops else np.zeros_like(inc)
    all_tops = bool(top.sum() == inc.sum())
    inc = np.ascontiguousarray(inc)
    top = np.ascontiguousarray(top)
    # faces grouped by blocks of cells (the block of a top's cell, of a wall's west or north cell),
    # so a depth buffer skips the blocks outside its window
    bs = int(block)
    gcols = -(-cols // bs)
    need = np.zeros((rows, cols), np.bool_)
    steps = np.zeros((rows, cols), np.uint8)
    per_block = np.zeros(max(1, -(-rows // bs) * gcols), np.int64)
    _dsm_count(h, inc, top, float(wall_min), bs, need, steps, per_block)
    starts = np.zeros(len(per_block) + 1, np.int64)
    starts[1:] = np.cumsum(per_block)
    n = int(np.count_nonzero(need))
    verts = np.empty((4 * n, 3))
    faces = np.empty((int(starts[-1]), 3), np.int32)
    _dsm_fill(h, top, bs, need, steps, float(x_min), float(y_max), float(res), starts, verts, faces)
    return Triangles(verts, faces, oriented=all_tops, groups=starts)


@njit
def _is_step(h, inc, r0, c0, r1, c1, wall_min):
    a = h[r0, c0]
    b = h[r1, c1]
    return (inc[r0, c0] or inc[r1, c1]) and np.isfinite(a) and np.isfinite(b) and abs(a - b) > wall_min


@njit
def _dsm_count(h, inc, top, wall_min, bs, need, steps, per_block):
    """Cells some face uses (``need``), walls on the east (bit 1) and south (bit 2) edge of each cell
    (``steps``) and faces per block of :func:`dsm_triangles`."""
    rows, cols = h.shape
    gcols = (cols + bs - 1) // bs
    for r in range(rows):
        for c in range(cols):
            b = (r // bs) * gcols + c // bs
            if top[r, c]:
                need[r, c] = True
                per_block[b] += 2
            if c + 1 < cols and _is_step(h, inc, r, c, r, c + 1, wall_min):
                need[r, c] = True
                need[r, c + 1] = True
                steps[r, c] |= 1
                per_block[b] += 2
            if r + 1 < rows and _is_step(h, inc, r, c, r + 1, c, wall_min):
                need[r, c] = True
                need[r + 1, c] = True
                steps[r, c] |= 2
                per_block[b] += 2


@njit
def _dsm_fill(h, top, bs, need, steps, x_min, y_max, res, starts, verts, faces):
    """Vertices (corners NW, NE, SE, SW of the needed cells, row-major) and faces by block."""
    rows, cols = h.shape
    gcols = (cols + bs - 1) // bs
    base = np.empty((rows, cols), np.int64)
    n = 0
    for r in range(rows):
        for c in range(cols):
            if not need[r, c]:
                continue
            x0 = x_min + c * res
            y0 = y_max - r * res
            z = h[r, c]
            base[r, c] = 4 * n
            verts[4 * n, 0], verts[4 * n, 1], verts[4 * n, 2] = x0, y0, z
            verts[4 * n + 1, 0], verts[4 * n + 1, 1], verts[4 * n + 1, 2] = x0 + res, y0, z
            verts[4 * n + 2, 0], verts[4 * n + 2, 1], verts[4 * n + 2, 2] = x0 + res, y0 - res, z
            verts[4 * n + 3, 0], verts[4 * n + 3, 1], verts[4 * n + 3, 2] = x0, y0 - res, z
            n += 1
    cur = starts[:-1].copy()
    NW, NE, SE, SW = 0, 1, 2, 3
    for r in range(rows):
        for c in range(cols):
            b = (r // bs) * gcols + c // bs
            a = base[r, c]
            k = cur[b]
            if top[r, c]:
                faces[k, 0], faces[k, 1], faces[k, 2] = a + NW, a + SW, a + SE
                faces[k + 1, 0], faces[k + 1, 1], faces[k + 1, 2] = a + NW, a + SE, a + NE
                k += 2
            # wall on the east edge of A = (r, c), B = (r, c + 1): faces +x when A is higher, -x otherwise
            if steps[r, c] & 1:
                e = base[r, c + 1]
                faces[k, 0], faces[k, 1], faces[k, 2] = e + SW, e + NW, a + NE
                faces[k + 1, 0], faces[k + 1, 1], faces[k + 1, 2] = e + SW, a + NE, a + SE
                k += 2
            # wall on the south edge of A = (r, c), B = (r + 1, c): -y when A is higher, +y otherwise
            if steps[r, c] & 2:
                e = base[r + 1, c]
                faces[k, 0], faces[k, 1], faces[k, 2] = e + NW, e + NE, a + SE
                faces[k + 1, 0], faces[k + 1, 1], faces[k + 1, 2] = e + NW, a + SE, a + SW
                k += 2
            cur[b] = k


def occluder_wall_min(res: float, max_view_angle_rad: float) -> float:
    """Smallest DSM step (metres) that can hide a surface point seen within the viewing angle.

    A ray from a surface point to a camera at most ``theta`` off nadir rises at
    least ``res / tan(theta)`` per cell, so a staircase of steps below that
    never rises above it (beyond the first half cell, which the depth tolerance
    covers). A quarter of it is used: the lower risers of sloped roofs also
    mark where the buffer holds the roof next to an occlusion boundary
    (measured on the synthetic scenes: half of it let 2x more ghost cells through).
    """
    return 0.25 * float(res) / math.tan(max(float(max_view_angle_rad), 1e-3))


def face_normals(tris: Triangles) -> np.ndarray:
    """Unit outward normals (M, 3) of the faces (counter-clockwise winding)."""
    v = tris.vertices[tris.faces]
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)


# ---------------------------------------------------------------- camera helpers


def scaled_params(camera: Camera, scale: float) -> np.ndarray:
    """Kernel parameters ``[fx, fy, cx, cy, k1, k2, k3, p1, p2]`` of a buffer ``scale`` x the image.

    Pixel centres map as ``x' = (x + 0.5) * scale - 0.5`` (:meth:`Camera.scaled`).
    """
    p = camera.params.copy()
    s = float(scale)
    p[0] *= s
    p[1] *= s
    p[2] = (p[2] + 0.5) * s - 0.5
    p[3] = (p[3] + 0.5) * s - 0.5
    return p


def valid_radius2(camera: Camera, margin: float = 3.0) -> float:
    """Largest squared normalised radius where the distortion model is trusted (memoised, see
    :func:`_valid_radius2`)."""
    key = (tuple(float(v) for v in np.asarray(camera.params).ravel()), int(camera.width), int(camera.height))
    return _valid_radius2_cached(key, float(margin), camera)


_R2_CACHE: dict = {}


def _valid_radius2_cached(key, margin: float, camera: Camera) -> float:
    k = (key, margin)
    v = _R2_CACHE.get(k)
    if v is None:
        if len(_R2_CACHE) > 4096:
            _R2_CACHE.clear()
        v = _R2_CACHE[k] = _valid_radius2(camera, margin)
    return v


def _valid_radius2(camera: Camera, margin: float = 3.0) -> float:
    """Largest squared normalised radius where the distortion model is trusted.

    ``margin`` times the radius of the farthest image corner (faces reaching
    beyond the frame still clip correctly), limited to where the radial model
    ``r (1 + k1 r^2 + k2 r^4 + k3 r^6)`` stops increasing: beyond that radius
    far-away points would fold back into the frame.
    """
    corners = np.array(
        [
            [-0.5, -0.5],
            [camera.width - 0.5, -0.5],
            [-0.5, camera.height - 0.5],
            [camera.width - 0.5, camera.height - 0.5],
        ]
    )
    xy = np.column_stack([(corners[:, 0] - camera.cx) / camera.fx, (corners[:, 1] - camera.cy) / camera.fy])
    r_corner = float(np.max(np.hypot(xy[:, 0], xy[:, 1])))
    r = np.linspace(0.0, max(10.0, 2 * margin * r_corner), 40001)
    r2 = r * r
    f = r * (1 + r2 * (camera.k1 + r2 * (camera.k2 + r2 * camera.k3)))
    bad = np.flatnonzero(np.diff(f) <= 0)
    r_mono = float(r[bad[0]]) if len(bad) else np.inf
    rr = min(margin * r_corner, 0.98 * r_mono) if r_mono > r_corner else r_corner
    return rr * rr


# ---------------------------------------------------------------- kernels


@njit
def _proj(x, y, z, R, C, p, r2max):
    """Pixel ``(u, v)`` and camera depth of a local point; depth <= 0 when unusable."""
    dx = x - C[0]
    dy = y - C[1]
    dz = z - C[2]
    zc = R[2, 0] * dx + R[2, 1] * dy + R[2, 2] * dz
    if zc <= 1e-6:
        return 0.0, 0.0, -1.0
    xn = (R[0, 0] * dx + R[0, 1] * dy + R[0, 2] * dz) / zc
    yn = (R[1, 0] * dx + R[1, 1] * dy + R[1, 2] * dz) / zc
    r2 = xn * xn + yn * yn
    if r2 > r2max:
        return 0.0, 0.0, -1.0
    radial = 1.0 + r2 * (p[4] + r2 * (p[5] + r2 * p[6]))
    xd = xn * radial + 2.0 * p[7] * xn * yn + p[8] * (r2 + 2.0 * xn * xn)
    yd = yn * radial + p[7] * (r2 + 2.0 * yn * yn) + 2.0 * p[8] * xn * yn
    return p[0] * xd + p[2], p[1] * yd + p[3], zc


@njit
def _project_vertices(verts, R, C, p, r2max, uvz):
    for i in range(verts.shape[0]):
        u, v, z = _proj(verts[i, 0], verts[i, 1], verts[i, 2], R, C, p, r2max)
        uvz[i, 0] = u
        uvz[i, 1] = v
        uvz[i, 2] = z


@njit
def _box_reaches(box, R, C, p, r2max, x0, y0, W, H):
    """Whether the projection of the box ``x0, y0, z0, x1, y1, z1`` may reach the buffer window:
    the bounding box of its projected corners, widened by half its size plus 2 pixels (lens
    distortion bends the box's edges), meets the window; True when a corner does not project."""
    umin = np.inf
    umax = -np.inf
    vmin = np.inf
    vmax = -np.inf
    for q in range(8):
        x = box[3] if q & 1 else box[0]
        y = box[4] if q & 2 else box[1]
        z = box[5] if q & 4 else box[2]
        u, v, d = _proj(x, y, z, R, C, p, r2max)
        if not d > 0.0:
            return True
        umin = min(umin, u)
        umax = max(umax, u)
        vmin = min(vmin, v)
        vmax = max(vmax, v)
    slack = 0.5 * max(umax - umin, vmax - vmin) + 2.0
    return (
        umax + slack >= x0
        and umin - slack <= x0 + W - 1
        and vmax + slack >= y0
        and vmin - slack <= y0 + H - 1
    )


@njit
def _render(verts, faces, groups, boxes, R, C, p, r2max, x0, y0, zbuf, cull):
    """Min-depth rasterisation into ``zbuf`` (window origin ``(x0, y0)``) of the faces of the groups
    whose box may reach the window; vertices are projected once, when a face first needs them."""
    H = zbuf.shape[0]
    W = zbuf.shape[1]
    uvz = np.empty((verts.shape[0], 3))
    done = np.zeros(verts.shape[0], np.bool_)
    drawn = 0
    for g in range(len(groups) - 1):
        if groups[g + 1] == groups[g]:
            continue
        if not _box_reaches(boxes[g], R, C, p, r2max, x0, y0, W, H):
            continue
        for f in range(groups[g], groups[g + 1]):
            for m in range(3):
                i = faces[f, m]
                if not done[i]:
                    u, v, z = _proj(verts[i, 0], verts[i, 1], verts[i, 2], R, C, p, r2max)
                    uvz[i, 0] = u
                    uvz[i, 1] = v
                    uvz[i, 2] = z
                    done[i] = True
            drawn += _raster_face(uvz, faces[f, 0], faces[f, 1], faces[f, 2], x0, y0, zbuf, cull)
    return drawn


@njit
def _span(a, b, lo, hi):
    """``[lo, hi]`` (whole pixels) narrowed to where ``a x + b >= 0`` may hold, a pixel of slack."""
    if a > 0.0:
        t = -b / a - 1.0
        if t > lo:
            lo = math.ceil(t) if t < hi else hi + 1.0
    elif a < 0.0:
        t = -b / a + 1.0
        if t < hi:
            hi = math.floor(t) if t > lo else lo - 1.0
    elif b < -1e-6:
        hi = lo - 1.0
    return lo, hi


@njit
def _raster_face(uvz, a, b, c, x0, y0, zbuf, cull):
    """Min-depth rasterisation of one face (projected vertices ``uvz``); returns the pixels set."""
    H = zbuf.shape[0]
    W = zbuf.shape[1]
    za = uvz[a, 2]
    zb = uvz[b, 2]
    zc = uvz[c, 2]
    if za <= 0.0 or zb <= 0.0 or zc <= 0.0:
        return 0
    ua = uvz[a, 0] - x0
    va = uvz[a, 1] - y0
    ub = uvz[b, 0] - x0
    vb = uvz[b, 1] - y0
    uc = uvz[c, 0] - x0
    vc = uvz[c, 1] - y0
    area = (ub - ua) * (vc - va) - (uc - ua) * (vb - va)
    if area == 0.0 or (cull and area > 0.0):
        return 0
    umin = min(ua, min(ub, uc))
    umax = max(ua, max(ub, uc))
    vmin = min(va, min(vb, vc))
    vmax = max(va, max(vb, vc))
    i0 = max(np.int64(math.ceil(umin)), 0)
    i1 = min(np.int64(math.floor(umax)), W - 1)
    j0 = max(np.int64(math.ceil(vmin)), 0)
    j1 = min(np.int64(math.floor(vmax)), H - 1)
    if i0 > i1 or j0 > j1:
        return 0
    inv = 1.0 / area
    iza = 1.0 / za
    izb = 1.0 / zb
    izc = 1.0 / zc
    drawn = 0
    # per row, the barycentric weights are linear in x: w_k = a_k x + b_k; only the span where all
    # three may be >= 0 (widened by a pixel against rounding) is tested pixel by pixel
    a0 = (vb - vc) * inv
    a1 = (vc - va) * inv
    a2 = -(a0 + a1)
    for j in range(j0, j1 + 1):
        py = float(j)
        b0 = (ub * (vc - py) - uc * (vb - py)) * inv
        b1 = (uc * (va - py) - ua * (vc - py)) * inv
        b2 = 1.0 - b0 - b1
        lo = float(i0)
        hi = float(i1)
        lo, hi = _span(a0, b0, lo, hi)
        lo, hi = _span(a1, b1, lo, hi)
        lo, hi = _span(a2, b2, lo, hi)
        if lo > hi:
            continue
        for i in range(np.int64(lo), np.int64(hi) + 1):
            px = float(i)
            w0 = ((ub - px) * (vc - py) - (uc - px) * (vb - py)) * inv
            w1 = ((uc - px) * (va - py) - (ua - px) * (vc - py)) * inv
            w2 = 1.0 - w0 - w1
            if w0 < -1e-9 or w1 < -1e-9 or w2 < -1e-9:
                continue
            iz = w0 * iza + w1 * izb + w2 * izc
            if iz <= 0.0:
                continue
            z = 1.0 / iz
            if z < zbuf[j, i]:
                zbuf[j, i] = z
                drawn += 1
    return drawn


@njit
def _visibility(P, tol, R, C, p, r2max, zbuf, x0, y0, vis, edge, u_out, v_out, z_out):
    """Depth test of points against a buffer window; pixel coordinates in buffer units."""
    H = zbuf.shape[0]
    W = zbuf.shape[1]
    for n in range(P.shape[0]):
        vis[n] = 0
        edge[n] = 0
        u, v, z = _proj(P[n, 0], P[n, 1], P[n, 2], R, C, p, r2max)
        u_out[n] = u
        v_out[n] = v
        z_out[n] = z
        if z <= 0.0:
            continue
        i = np.int64(math.floor(u - x0 + 0.5))
        j = np.int64(math.floor(v - y0 + 0.5))
        if i < 0 or j < 0 or i >= W or j >= H:
            continue
        t = tol[n]
        if z <= zbuf[j, i] + t:
            vis[n] = 1
        zmin = np.inf
        for dj in range(-1, 2):
            jj = j + dj
            if jj < 0 or jj >= H:
                continue
            for di in range(-1, 2):
                ii = i + di
                if ii < 0 or ii >= W:
                    continue
                if zbuf[jj, ii] < zmin:
                    zmin = zbuf[jj, ii]
        if zmin < z - t:
            edge[n] = 1


# ---------------------------------------------------------------- public API


def _pose(R, C):
    Rm = np.ascontiguousarray(np.asarray(R, dtype=np.float64))
    Cv = np.ascontiguousarray(np.asarray(C, dtype=np.float64).reshape(-1))
    if Rm.shape != (3, 3) or Cv.shape != (3,):
        raise InputError("depth buffer: R must be 3x3 and C a 3-vector")
    return Rm, Cv


def project(points, R, C, camera: Camera, scale: float = 1.0) -> np.ndarray:
    """``(u, v, depth)`` (N, 3) of local points (buffer pixels at ``scale``); depth -1 when unusable.

    Unusable: behind the camera or beyond the valid field of the distortion model
    (:func:`valid_radius2`).
    """
    Rm, Cv = _pose(R, C)
    P = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 3))
    uvz = np.empty((len(P), 3))
    _project_vertices(P, Rm, Cv, scaled_params(camera, scale), valid_radius2(camera), uvz)
    return uvz


def render_depth(
    tris: Triangles, R, C, camera: Camera, window, scale: float = 1.0, cull: bool | None = None
) -> np.ndarray:
    """Depth buffer of the triangles in one image window.

    Parameters
    ----------
    tris : Triangles
        Local frame.
    R, C : world-to-camera rotation (3, 3) and projection centre (3,), local frame.
    camera : Camera
    window : (x0, y0, width, height)
        Buffer pixels ``x0 .. x0 + width - 1`` (columns) and rows likewise, in
        buffer pixel coordinates (``scale`` x the image).
    scale : float
        Buffer pixels per image pixel (<= 1 for a coarser buffer).
    cull : bool, optional
        Back-face culling; default ``tris.oriented``.

    Returns
    -------
    (height, width) float32
        Camera z (metres) of the nearest surface at each buffer pixel centre;
        inf where no face is drawn.
    """
    Rm, Cv = _pose(R, C)
    x0, y0, w, h = (int(v) for v in window)
    if w < 1 or h < 1:
        raise InputError(f"render_depth: window must have a positive size, got {window!r}")
    p = scaled_params(camera, scale)
    zbuf = np.full((h, w), np.inf, np.float32)
    _render(
        tris.vertices,
        tris.faces,
        tris.groups,
        tris.boxes,
        Rm,
        Cv,
        p,
        valid_radius2(camera),
        float(x0),
        float(y0),
        zbuf,
        bool(tris.oriented if cull is None else cull),
    )
    return zbuf


def point_visibility(points, tol, R, C, camera: Camera, zbuf: np.ndarray, window, scale: float = 1.0):
    """Depth test of surface points against a buffer from :func:`render_depth`.

    Parameters
    ----------
    points : (N, 3) float64
        Local surface points (cell centres at their heights).
    tol : (N,) or scalar float
        Depth tolerance, metres (:func:`depth_tolerance`).
    R, C, camera, scale : as for :func:`render_depth`.
    zbuf : (h, w) float32 and window : (x0, y0, w, h) of the buffer.

    Returns
    -------
    visible : (N,) bool
        In front, inside the buffer window and not hidden.
    near_edge : (N,) bool
        A surface closer than ``z - tol`` lies within one buffer pixel.
    uv : (N, 2) float64
        Pixel coordinates in the *full-resolution* image.
    depth : (N,) float64
        Camera z, metres (<= 0: behind the camera or outside the valid field).
    """
    Rm, Cv = _pose(R, C)
    P = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 3))
    n = len(P)
    t = np.ascontiguousarray(np.broadcast_to(np.asarray(tol, dtype=np.float64), (n,)))
    x0, y0, w, h = (int(v) for v in window)
    if zbuf.shape != (h, w):
        raise InputError(f"point_visibility: buffer of shape {zbuf.shape} for a window of {w} x {h}")
    vis = np.empty(n, np.uint8)
    edge = np.empty(n, np.uint8)
    u = np.empty(n)
    v = np.empty(n)
    z = np.empty(n)
    _visibility(
        P,
        t,
        Rm,
        Cv,
        scaled_params(camera, scale),
        valid_radius2(camera),
        zbuf,
        float(x0),
        float(y0),
        vis,
        edge,
        u,
        v,
        z,
    )
    s = float(scale)
    uv = np.column_stack([(u + 0.5) / s - 0.5, (v + 0.5) / s - 0.5])
    return vis.astype(bool), edge.astype(bool), uv, z


def depth_tolerance(res: float, pixel_footprint, tan_view, factor: float = 1.0, slope=0.0) -> np.ndarray:
    """Depth tolerance (metres) of the visibility test.

    ``factor * (max(res, pixel_footprint) * (1 + tan_view) + res * slope)``:
    within one buffer pixel of footprint ``pixel_footprint`` (metres on the
    ground) the depth of a surface seen at off-nadir angle ``atan(tan_view)``
    varies by about ``pixel_footprint * tan_view``, and the flat cell tops of a
    DSM of cell size ``res`` deviate from a surface of gradient ``slope`` by up
    to one stair step ``res * slope`` (the slope from the smaller one-sided
    height differences, so a cell next to a wall keeps the slope of its own
    roof or ground). The fused pass of :func:`view_cells_into` uses the same formula.
    """
    base = np.maximum(float(res), pixel_footprint) * (1.0 + np.asarray(tan_view))
    return factor * (base + float(res) * np.asarray(slope))


# ---------------------------------------------------------------- fused per-image cell passes


@njit
def _frame_pass(
    P, index, R, C, p, r2max, width, height, cos_max, box, cell_out, u_out, v_out, z_out, dist_out
):
    """Compacts the points ``P[index[i]]`` in front, inside the frame and within the viewing angle:
    their index into ``P``, full-resolution pixel ``(u, v)``, camera depth and distance go to the
    first ``m`` entries of the outputs, in the order of ``index``; returns ``m``. Points outside the
    plan box ``x0, y0, x1, y1`` (a bound of the footprint) are rejected first."""
    m = 0
    for i in range(index.shape[0]):
        j = index[i]
        if P[j, 0] < box[0] or P[j, 0] > box[2] or P[j, 1] < box[1] or P[j, 1] > box[3]:
            continue
        dx = C[0] - P[j, 0]
        dy = C[1] - P[j, 1]
        dz = C[2] - P[j, 2]
        dist = math.sqrt(dx * dx + dy * dy + dz * dz)
        if dist <= 0.0 or dz / dist < cos_max:
            continue
        u, v, z = _proj(P[j, 0], P[j, 1], P[j, 2], R, C, p, r2max)
        if z <= 0.0 or u < -0.5 or v < -0.5 or u > width - 0.5 or v > height - 0.5:
            continue
        cell_out[m] = j
        u_out[m] = u
        v_out[m] = v
        z_out[m] = z
        dist_out[m] = dist
        m += 1
    return m


@njit
def _near_field_hidden(n, P, hloc, cols, res, C, tol_h, reach):
    """Whether the cell ``n``'s own ray towards ``C`` enters one of the cells within ``reach`` cells
    (the ``2 reach + 1`` square neighbourhood) below that cell's top by more than ``tol_h`` (metres).

    The exact raster geometry next to the point, which the depth buffer cannot resolve: an
    occluder whose depth lies within the depth tolerance (a wall a fraction of a cell away, the
    ray past a building's corner) or between two buffer pixel centres. Each neighbour is an
    axis-aligned square of side ``res`` centred at its point (slab test); the ray's height is
    taken where it enters the square, its lowest point there.
    """
    N = hloc.shape[0]
    rows = N // cols
    r = n // cols
    c = n - r * cols
    x0 = P[n, 0]
    y0 = P[n, 1]
    z0 = hloc[n]
    dx = C[0] - x0
    dy = C[1] - y0
    dh = math.sqrt(dx * dx + dy * dy)
    if dh <= 1e-12:
        return False
    rise = (C[2] - z0) / dh
    ux = dx / dh
    uy = dy / dh
    half = 0.5 * res
    for rr in range(max(r - reach, 0), min(r + reach + 1, rows)):
        for cc in range(max(c - reach, 0), min(c + reach + 1, cols)):
            m = rr * cols + cc
            hm = hloc[m]
            if m == n or not (hm > z0 + tol_h):
                continue
            # slab test of the ray (s >= 0, horizontal distance) against the square around P[m]
            lo = 0.0
            hi = np.inf
            ok = True
            for axis in range(2):
                u = ux if axis == 0 else uy
                o = (x0 - P[m, 0]) if axis == 0 else (y0 - P[m, 1])
                if abs(u) < 1e-12:
                    if abs(o) > half:
                        ok = False
                        break
                    continue
                t1 = (-half - o) / u
                t2 = (half - o) / u
                if t1 > t2:
                    t1, t2 = t2, t1
                lo = max(lo, t1)
                hi = min(hi, t2)
            if not ok or lo > hi:
                continue
            if hm > z0 + lo * rise + tol_h:
                return True
    return False


@njit
def _traversal_axis(x, d):
    """One axis of a grid traversal from the coordinate ``x`` moving ``d`` cells per unit of the ray:
    the step (-1, 0, 1), the ray's parameter at the first cell boundary, and between boundaries."""
    k = math.floor(x)
    if d > 0.0:
        return 1, (k + 1.0 - x) / d, 1.0 / d
    if d < 0.0:
        return -1, (k - x) / d, -1.0 / d
    return 0, np.inf, np.inf


@njit
def _ray_hidden(hz, ri, ci, dr, dc, z0, rise, tol, ztop):
    """Whether a ray leaving the point ``(ri, ci)`` (fractional row and column of a height grid
    ``hz``, local heights, NaN = none) enters a cell below that cell's top by more than ``tol``.

    The ray moves ``(dr, dc)`` rows and columns and rises ``rise`` metres per metre of horizontal
    distance ``s``; its height at ``s`` is ``z0 + rise s``. The cells it crosses are walked in order
    (Amanatides and Woo's traversal), each taken at the ray's height where it enters the cell, its
    lowest point there. The walk ends where the ray leaves the grid (nothing known beyond: not
    hidden) or rises above ``ztop + tol`` (no cell can be above it).
    """
    R, Cn = hz.shape
    r = int(math.floor(ri))
    c = int(math.floor(ci))
    sc, tc, dtc = _traversal_axis(ci, dc)
    sr, tr, dtr = _traversal_axis(ri, dr)
    if sc == 0 and sr == 0:
        return False
    while True:
        if tc < tr:
            s = tc
            c += sc
            tc += dtc
        else:
            s = tr
            r += sr
            tr += dtr
        if r < 0 or c < 0 or r >= R or c >= Cn:
            return False
        zr = z0 + s * rise
        if zr > ztop + tol:
            return False
        h = hz[r, c]
        if h > zr + tol:
            return True


@njit
def _view_pass(
    cells,
    us,
    vs,
    zs,
    dists,
    P,
    S,
    moved,
    normals,
    R,
    C,
    p_full,
    r2max,
    scale,
    res,
    tol_factor,
    min_cos_inc,
    zbuf,
    x0,
    y0,
    use_vis,
    hloc,
    near_step,
    cols,
    reach,
    hnoise,
    ray_hz,
    ray_at,
    ray_inv,
    ray_top,
    usable,
    edge,
    uv,
    eff,
):
    """Depth test (optional), incidence, effective resolution and sample coordinates of the cells of
    :func:`_frame_pass` (``cells`` with their pixel ``us, vs``, depth ``zs``, distance ``dists``),
    written at each cell's index into ``usable, edge, uv, eff`` (N,) / (N, 2); returns the usable count.

    ``P`` surface points, ``S`` colour sample points (projected only where ``moved``, elsewhere
    ``S`` = ``P``), ``normals`` unit normals, all (N, 3). The buffer pixel of a cell is its image
    pixel at ``scale`` (``x' = (x + 0.5) scale - 0.5``), the buffer window's origin ``(x0, y0)``.
    Tolerance as :func:`depth_tolerance`, plus ``hnoise / cos(view angle)`` (the surface's own
    height noise, :func:`height_noise`). Where ``near_step`` is set (cells of a ``cols``-wide grid,
    heights ``hloc``, NaN = none), a cell that passes the depth test is still hidden when its ray
    enters a cell within ``reach[n]`` cells below that cell's top (:func:`_near_field_hidden`).
    A cell next to an occlusion edge in the buffer is hidden when its ray enters a cell of
    ``ray_hz`` (the heights around the grid, its cell ``(r, c)`` at ``(r + ray_at, c + ray_at)``;
    empty: no test) below that cell's top, anywhere below ``ray_top`` (:func:`_ray_hidden`);
    ``ray_inv`` turns a local plan direction into rows and columns.
    """
    H = zbuf.shape[0]
    W = zbuf.shape[1]
    fx = p_full[0]
    count = 0
    for m in range(cells.shape[0]):
        n = cells[m]
        dist = dists[m]
        dx = C[0] - P[n, 0]
        dy = C[1] - P[n, 1]
        dz = C[2] - P[n, 2]
        cos_view = dz / dist
        cos_inc = (normals[n, 0] * dx + normals[n, 1] * dy + normals[n, 2] * dz) / dist
        if cos_inc <= min_cos_inc or cos_view <= 1e-6:
            continue
        near = False
        if use_vis:
            z = zs[m]
            i = np.int64(math.floor((us[m] + 0.5) * scale - 0.5 - x0 + 0.5))
            j = np.int64(math.floor((vs[m] + 0.5) * scale - 0.5 - y0 + 0.5))
            if i < 0 or j < 0 or i >= W or j >= H:
                continue
            tan_view = math.sqrt(max(1.0 - cos_view * cos_view, 0.0)) / cos_view
            foot = dist / (fx * scale) / cos_view
            nz = max(abs(normals[n, 2]), 1e-6)
            slope = math.sqrt(max(1.0 - nz * nz, 0.0)) / nz  # the cell's own stair step per cell
            t = tol_factor * (max(res, foot) * (1.0 + tan_view) + res * slope) + hnoise[n] / cos_view
            if z > zbuf[j, i] + t:
                continue
            zmin = np.inf
            for jj in range(max(j - 1, 0), min(j + 2, H)):
                for ii in range(max(i - 1, 0), min(i + 2, W)):
                    if zbuf[jj, ii] < zmin:
                        zmin = zbuf[jj, ii]
            near = zmin < z - t
            # next to a much higher cell, the exact raster geometry decides with the same tolerance
            # (the buffer's pixels cannot: the ray past a corner, an occluder within the tolerance)
            if near_step[n] and _near_field_hidden(n, P, hloc, cols, res, C, t, reach[n]):
                continue
            # next to an occlusion edge the buffer's pixels decide only to a pixel, and a ray past a
            # roof's corner or edge (a diagonal outline, a grazing ray) runs between two of their
            # centres: the cell's own ray through the raster decides, as far as the ray can be hidden
            if near and ray_hz.shape[0] > 0:
                rn = n // cols
                dh = math.sqrt(dx * dx + dy * dy)
                if dh > 1e-12:
                    ux = dx / dh
                    uy = dy / dh
                    dc = ray_inv[0, 0] * ux + ray_inv[0, 1] * uy
                    dr = ray_inv[1, 0] * ux + ray_inv[1, 1] * uy
                    ri = rn + ray_at + 0.5
                    ci = n - rn * cols + ray_at + 0.5
                    if _ray_hidden(ray_hz, ri, ci, dr, dc, P[n, 2], dz / dh, t, ray_top):
                        continue
        if moved[n]:
            su, sv, sz = _proj(S[n, 0], S[n, 1], S[n, 2], R, C, p_full, r2max)
            if sz <= 0.0:
                continue
        else:
            su = us[m]
            sv = vs[m]
        if near:
            su = math.floor(su + 0.5)
            sv = math.floor(sv + 0.5)
        usable[n] = True
        edge[n] = near
        uv[n, 0] = su
        uv[n, 1] = sv
        eff[n] = dist / (fx * cos_inc)
        count += 1
    return count


@dataclass
class FrameCells:
    """Cells of :func:`frame_cells` (compact, in the order of the index given): index into the
    points, full-resolution pixel ``u, v``, camera depth ``z`` and distance (metres)."""

    cells: np.ndarray
    u: np.ndarray
    v: np.ndarray
    z: np.ndarray
    dist: np.ndarray

    def __len__(self) -> int:
        return len(self.cells)


def frame_cells(points, R, C, camera: Camera, max_view_rad: float, index=None, box=None) -> FrameCells:
    """Cells seen inside the frame, in front, within the viewing angle.

    ``points`` (N, 3) local; ``index`` (optional): the rows of ``points`` to test (default all);
    ``box`` (optional): ``x0, y0, x1, y1``, a plan box holding every point the image can see
    (a padded footprint bound), tested first.
    """
    Rm, Cv = _pose(R, C)
    P = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 3))
    ix = np.arange(len(P)) if index is None else np.ascontiguousarray(np.asarray(index, dtype=np.int64))
    if len(ix) and (ix.min() < 0 or ix.max() >= len(P)):
        raise InputError("frame_cells: index out of range of the points")
    if box is not None and np.shape(box) != (4,):
        raise InputError(f"frame_cells: box must be (x0, y0, x1, y1), got shape {np.shape(box)}")
    n = len(ix)
    cells = np.empty(n, np.int64)
    u, v, z, d = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    m = _frame_pass(
        P,
        ix,
        Rm,
        Cv,
        camera.params,
        valid_radius2(camera),
        float(camera.width),
        float(camera.height),
        math.cos(max_view_rad),
        np.array([-np.inf, -np.inf, np.inf, np.inf]) if box is None else np.asarray(box, np.float64),
        cells,
        u,
        v,
        z,
        d,
    )
    return FrameCells(cells[:m], u[:m], v[:m], z[:m], d[:m])


def view_cells_into(
    fc: FrameCells,
    points,
    samples,
    moved,
    normals,
    R,
    C,
    camera: Camera,
    zbuf,
    window,
    scale: float,
    res: float,
    out: tuple,
    tol_factor: float = 1.0,
    visibility: bool = True,
    min_cos_inc: float = 0.02,
    near_field: tuple | None = None,
    noise: np.ndarray | None = None,
    ray_grid: tuple | None = None,
) -> int:
    """Per-cell result of one image in one pass (the depth test of :func:`point_visibility` +
    incidence + sampling) for the cells of :func:`frame_cells`.

    Parameters
    ----------
    fc : FrameCells
    points, samples, normals : (N, 3) float64, C-contiguous
        Surface points, colour sample points (local frame) and unit surface normals.
    moved : (N,) bool
        Where ``samples`` differs from ``points``.
    zbuf, window, scale : the depth buffer of :func:`render_depth` (ignored without ``visibility``).
    out : (usable (N,) bool, near_edge (N,) bool, uv (N, 2) float32, eff (N,) float32)
        Written at the cells found usable (visible when tested, facing the camera, sample point in
        front): near an occlusion edge, full-resolution sample coordinates (rounded to the pixel
        centre next to an occluder), effective ground resolution ``distance / (fx cos incidence)``.

    near_field : (heights (N,) float64, near_step (N,) bool, cols[, reach]), optional
        With the depth test: the points are the cells of a grid ``cols`` wide, row-major, with their
        heights (local z, NaN = no data); where ``near_step`` is set (a much higher cell within the
        cell's ``reach``, cells, one integer or one per point, default 2, :func:`near_step_mask`), a
        cell visible in the buffer is still hidden when its ray towards the camera enters a cell
        within its reach below that cell's top by more than the depth tolerance. The depth buffer
        cannot see such occluders: their
        depth lies within the tolerance, or between two buffer pixel centres (a ground cell
        diagonally next to a building's corner, seen past the corner).
    noise : (N,) float64, optional
        With the depth test: a height tolerance per cell (metres, >= 0) for the surface's own noise,
        added to the depth tolerance divided by the cosine of the viewing angle (see
        :func:`height_noise`); default 0.
    ray_grid : (heights (R, C) float64, at int, inv (2, 2) float64, top float), optional
        With the depth test and ``near_field``: the heights (local z, NaN = none) of a grid around
        the points' grid, whose cell ``(r, c)`` is the heights' ``(r + at, c + at)``; ``inv`` turns
        a local plan direction ``(x, y)`` into ``(columns, rows)``; ``top`` the highest height. A
        cell near an occlusion edge (some buffer pixel of its 3 x 3 neighbourhood nearer than its
        depth by more than the tolerance) is hidden when its ray towards the camera enters a cell
        of that grid below the cell's top by more than the depth tolerance: next to an edge the
        buffer decides only to its pixel (a diagonal roof outline, a grazing ray past a roof's edge
        run between two pixel centres), the raster geometry exactly.

    Returns
    -------
    int : the cells found usable.
    """
    Rm, Cv = _pose(R, C)
    P, Sm, N = points, samples, normals
    if not (P.shape == Sm.shape == N.shape and P.ndim == 2 and P.shape[1] == 3 and moved.shape == (len(P),)):
        raise InputError("view_cells_into: points, samples and normals must be (N, 3) arrays of one shape")
    usable, edge, uv, eff = out
    n = len(P)
    if not (
        usable.shape == edge.shape == eff.shape == (n,)
        and uv.shape == (n, 2)
        and usable.dtype == edge.dtype == moved.dtype == np.bool_
        and uv.dtype == eff.dtype == np.float32
    ):
        raise InputError("view_cells_into: out must be (N,) bool, (N,) bool, (N, 2) and (N,) float32")
    if len(fc) and fc.cells.max() >= n:
        raise InputError("view_cells_into: the frame cells refer to points beyond the arrays")
    if zbuf is None:
        zbuf = np.full((1, 1), np.inf, np.float32)
        window = (0, 0, 1, 1)
    reach = np.full(n, 2, np.int64)
    if near_field is None:
        hloc, near_step, cols = np.zeros(0), np.zeros(n, np.bool_), 1
    else:
        hloc, near_step, cols = near_field[:3]
        cols = int(cols)
        if len(near_field) > 3:
            reach = np.broadcast_to(np.asarray(near_field[3]), (n,))
        if (
            np.shape(hloc) != (n,)
            or np.shape(near_step) != (n,)
            or near_step.dtype != np.bool_
            or cols < 1
            or n % cols
            or len(near_field) > 4
            or reach.dtype.kind not in "iu"
            or (n and reach.min() < 1)
        ):
            raise InputError(
                "view_cells_into: near_field must be (N,) heights, (N,) bool, the grid's columns and "
                "optionally the reach in cells (an integer >= 1, or one per point)"
            )
        hloc = np.ascontiguousarray(hloc, np.float64)
        reach = np.ascontiguousarray(reach, np.int64)
    if noise is None:
        hnoise = np.zeros(n)
    else:
        hnoise = np.ascontiguousarray(noise, np.float64)
        if hnoise.shape != (n,) or not (hnoise >= 0).all():
            raise InputError(
                f"view_cells_into: noise must be ({n},) heights >= 0, got shape {hnoise.shape}"
            )
    ray_hz, ray_at, ray_inv, ray_top = np.zeros((0, 0)), 0, np.zeros((2, 2)), 0.0
    if ray_grid is not None:
        if near_field is None or len(ray_grid) != 4:
            raise InputError("view_cells_into: ray_grid must be (heights, at, inv, top), with near_field")
        ray_hz = np.ascontiguousarray(ray_grid[0], np.float64)
        ray_at = int(ray_grid[1])
        ray_inv = np.ascontiguousarray(ray_grid[2], np.float64)
        ray_top = float(ray_grid[3])
        if ray_hz.ndim != 2 or ray_inv.shape != (2, 2) or ray_at < 0 or not math.isfinite(ray_top):
            raise InputError(
                "view_cells_into: ray_grid must be 2-D heights, an offset >= 0, a (2, 2) direction "
                "transform and a finite top height"
            )
        if ray_hz.shape[0] < n // cols + 2 * ray_at or ray_hz.shape[1] < cols + 2 * ray_at:
            raise InputError(
                f"view_cells_into: ray_grid's heights {ray_hz.shape} do not hold the points' grid "
                f"({n // cols} x {cols}) at offset {ray_at}"
            )
    return int(
        _view_pass(
            fc.cells,
            fc.u,
            fc.v,
            fc.z,
            fc.dist,
            P,
            Sm,
            moved,
            N,
            Rm,
            Cv,
            camera.params,
            valid_radius2(camera),
            float(scale),
            float(res),
            float(tol_factor),
            float(min_cos_inc),
            zbuf,
            float(window[0]),
            float(window[1]),
            bool(visibility),
            hloc,
            near_step,
            cols,
            reach,
            hnoise,
            ray_hz,
            ray_at,
            ray_inv,
            ray_top,
            usable,
            edge,
            uv,
            eff,
        )
    )


def near_step_mask(heights: np.ndarray, res: float, step_cells: float = 2.0, reach=2) -> np.ndarray:
    """Cells (rows, cols) with a cell more than ``step_cells`` cell sizes higher within their reach
    (``reach``: cells, one integer or one per cell): where :func:`view_cells_into`'s near-field
    test runs (elsewhere the depth test is enough)."""
    from scipy.ndimage import maximum_filter

    h = np.asarray(heights, dtype=np.float64)
    if h.ndim != 2:
        raise InputError(f"near_step_mask: expected a 2-D height grid, got shape {h.shape}")
    for name, v in (("res", res), ("step_cells", step_cells)):
        if isinstance(v, bool) or not (math.isfinite(float(v)) and float(v) > 0):
            raise InputError(f"near_step_mask: {name} must be a finite number > 0, got {v!r}")
    r = np.asarray(reach)
    if r.dtype.kind not in "iu" or r.shape not in ((), h.shape) or (r.size and r.min() < 1):
        raise InputError(f"near_step_mask: reach must be integers >= 1 (one, or one per cell), got {reach!r}")
    r = np.broadcast_to(r, h.shape)
    hz = np.where(np.isfinite(h), h, -np.inf)
    out = np.zeros(h.shape, bool)
    for k in np.unique(r):
        top = maximum_filter(hz, size=2 * int(k) + 1, mode="constant", cval=-np.inf)
        with np.errstate(invalid="ignore"):
            out |= (r == k) & np.isfinite(h) & (top - h > float(step_cells) * float(res))
    return out


def height_noise(heights: np.ndarray, half: int = 3, scale: int = 9) -> np.ndarray:
    """Robust local height noise (rows, cols) float64, metres, of a height grid (NaN = no data).

    ``1.4826 x`` the median over the ``(2 half + 1)^2`` window of ``|h - median_scale(h)|``, the
    departures from the ``scale x scale`` median surface: the deviation of the bumps shorter than
    about ``scale`` cells (a matched DSM's noise is correlated over the matching window, so a
    second difference would read a fraction of it). The median surface keeps planes, straight
    walls, corners and buildings wider than half the window, so they read 0; a matched DSM of
    low-texture fields or a canopy reads its roughness. Cells without a height take the nearest
    height for the median surface and are left out of the window medians; 0 at cells without a
    height and where fewer than 9 cells of the window have one.
    """
    from scipy.ndimage import distance_transform_edt, median_filter

    from ..sgm import median_filter as nan_median_filter

    h = np.ascontiguousarray(np.asarray(heights, dtype=np.float64))
    if h.ndim != 2:
        raise InputError(f"height_noise: expected a 2-D height grid, got shape {h.shape}")
    for name, v, lo, hi in (("half", half, 1, 7), ("scale", scale, 3, 31)):
        if isinstance(v, bool) or not isinstance(v, int | np.integer) or not lo <= v <= hi:
            raise InputError(f"height_noise: {name} must be an integer from {lo} to {hi}, got {v!r}")
    valid = np.isfinite(h)
    if not valid.any():
        return np.zeros(h.shape)
    filled = h
    if not valid.all():
        idx = distance_transform_edt(~valid, return_distances=False, return_indices=True)
        filled = h[tuple(idx)]
    dev = np.where(valid, np.abs(h - median_filter(filled, size=int(scale), mode="nearest")), np.nan)
    # the NaN-aware window median of the matching's outlier test; NaN where fewer than 9 values
    med = nan_median_filter(dev, 2 * int(half) + 1, min_count=9)
    return 1.4826 * np.nan_to_num(med.astype(np.float64), nan=0.0)
