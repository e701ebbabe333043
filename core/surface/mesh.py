"""2.5D triangle mesh of a DSM: vertical walls at height steps, error-bounded decimation.

Geometry
--------
The DSM is a grid of cell-centre samples (:class:`~truortho.core.grid.RasterGrid`).
Two 4-neighbour cells are *joined* when both are valid and their height
difference is at most the step threshold ``max(min_step, res * tan(max_slope))``;
otherwise, when both are valid, the edge between them is a *step*.

* Mesh vertices sit on the lattice of cell **corners**. Around a corner the
  (up to four) valid cells are grouped by the joined edges between them; each
  group gets its own vertex, with the height of its cells extrapolated to the
  corner along their local gradients (averaged over the group). Cells on
  either side of a step therefore never share the vertices along it.
* At every step edge the two sides are joined by a **vertical wall** (two
  triangles between the upper and the lower vertices of the shared cell
  edge, same plan position): no triangle of the surface ever spans a step.
* Flat and smooth areas are **decimated** by a restricted quadtree on the
  corner lattice: a block of ``s x s`` cells (``s = 2^k <= max_leaf``) is a
  leaf when all its cells and the edges to its neighbours are joined, and
  when every triangulation it may receive (two triangles, or a fan from its
  centre with or without any of the four edge midpoints that finer
  neighbours impose) stays within ``max_error`` of every cell value inside;
  the test is hereditary (the four children of a leaf pass it too), so the
  splits that balance the quadtree (neighbouring leaves differ by at most a
  factor two) keep the bound. Cells at steps, next to nodata or failing the
  test stay single cells (two triangles, or four from a centre vertex with
  the cell's own height when two do not fit within ``max_error``).

* **Stair corners** of walls (a corner whose four cells are single-cell leaves
  split 1 : 3 into two groups) move a quarter cell along both axes towards the
  odd cell, all their vertices alike (walls stay vertical, outlines at 45 degrees
  become straight), unless a cell's quad would lose convexity; single cells choose
  their diagonal (or centre vertex) with the moved corners.

Hence the **vertical error bound**: at every valid cell centre the mesh's
surface differs from the DSM value by at most ``max_error``.

Processing is by tiles (cores aligned to ``max_leaf``, with a margin of
``2 max_leaf + 2`` cells so that the quadtree, whose balance propagates over at
most ``2 max_leaf`` cells, is the same as a global one); vertices are shared
across tiles by their lattice keys. Nodata cells are left out (open mesh
boundary). Per-vertex colours are the mean colour of the vertex's cells in an
orthoimage resampled onto the DSM grid.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..grid import RasterGrid
from ..jit import njit
from ..progress import Progress, as_progress, check
from ._raster import colours_on_grid
from .meshio import Mesh


@dataclass
class DsmMeshConfig:
    """Parameters of :func:`mesh_from_dsm`.

    Attributes
    ----------
    max_error : float or None
        Largest vertical difference between the mesh and the DSM at any cell
        centre, metres; None = half the DSM resolution.
    min_step : float
        Smallest height difference between neighbouring cells that is a step
        (a wall), metres.
    max_slope_deg : float
        Steepest surface slope (degrees) represented by sloping triangles: the
        step threshold is ``max(min_step, res * tan(max_slope_deg))``.
    max_leaf : int
        Largest quadtree block side in cells (a power of two, 1 to 256).
    tile : int
        Tile core side in cells (rounded up to a multiple of ``max_leaf``).
    chamfer : bool
        Cut the stair corners of walls by a quarter cell (straight walls for outlines at
        45 degrees to the grid, chamfers for other angles).
    """

    max_error: float | None = None
    min_step: float = 0.5
    max_slope_deg: float = 70.0
    max_leaf: int = 64
    tile: int = 1024
    chamfer: bool = True

    def validate(self) -> None:
        if self.max_error is not None and not (math.isfinite(self.max_error) and self.max_error > 0):
            raise InputError(f"max_error must be a positive number of metres, got {self.max_error!r}")
        if not (math.isfinite(self.min_step) and self.min_step > 0):
            raise InputError(f"min_step must be a positive number of metres, got {self.min_step!r}")
        if not 1.0 <= self.max_slope_deg < 90.0:
            raise InputError(f"max_slope_deg must lie in [1, 90), got {self.max_slope_deg!r}")
        m = self.max_leaf
        if isinstance(m, bool) or not isinstance(m, int) or m < 1 or m > 256 or m & (m - 1):
            raise InputError(f"max_leaf must be a power of two from 1 to 256, got {m!r}")
        if isinstance(self.tile, bool) or not isinstance(self.tile, int) or self.tile < 16:
            raise InputError(f"tile must be an integer of at least 16 cells, got {self.tile!r}")

    def step_threshold(self, res: float) -> float:
        return max(self.min_step, res * math.tan(math.radians(self.max_slope_deg)))


@dataclass
class DsmMeshResult:
    """A mesh of a DSM and what it took.

    Attributes
    ----------
    mesh : Mesh
        World coordinates of the DSM's CRS.
    cells : int
        Valid DSM cells meshed.
    wall_faces : int
        Vertical triangles (walls).
    step_threshold, max_error : float
        The values used, metres.
    leaves : dict
        Quadtree leaves per block side (cells).
    """

    mesh: Mesh
    cells: int
    wall_faces: int
    step_threshold: float
    max_error: float
    leaves: dict = field(default_factory=dict)

    @property
    def vertex_ratio(self) -> float:
        """Vertices per valid cell."""
        return self.mesh.n_vertices / max(self.cells, 1)

    def as_dict(self) -> dict:
        return {
            "cells": self.cells,
            "vertices": self.mesh.n_vertices,
            "faces": self.mesh.n_faces,
            "wall_faces": self.wall_faces,
            "vertex_ratio": round(self.vertex_ratio, 5),
            "step_threshold_m": self.step_threshold,
            "max_error_m": self.max_error,
            "leaves": {str(k): v for k, v in sorted(self.leaves.items())},
        }


# ------------------------------------------------------------------ kernels


@njit
def _joins(z, thr):
    """Joined edges: ``jh[r, c]`` between (r, c) and (r, c+1); ``jv[r, c]`` between (r, c) and (r+1, c)."""
    nr, nc = z.shape
    jh = np.zeros((nr, max(nc - 1, 0)), np.bool_)
    jv = np.zeros((max(nr - 1, 0), nc), np.bool_)
    for r in range(nr):
        for c in range(nc - 1):
            a = z[r, c]
            b = z[r, c + 1]
            jh[r, c] = np.isfinite(a) and np.isfinite(b) and abs(a - b) <= thr
    for r in range(nr - 1):
        for c in range(nc):
            a = z[r, c]
            b = z[r + 1, c]
            jv[r, c] = np.isfinite(a) and np.isfinite(b) and abs(a - b) <= thr
    return jh, jv


@njit
def _gradients(z, jh, jv):
    """Per-cell height change per cell along columns (``gc``) and rows (``gr``), over joined neighbours."""
    nr, nc = z.shape
    gc = np.zeros((nr, nc))
    gr = np.zeros((nr, nc))
    for r in range(nr):
        for c in range(nc):
            if not np.isfinite(z[r, c]):
                continue
            left = c > 0 and jh[r, c - 1]
            right = c < nc - 1 and jh[r, c]
            if left and right:
                gc[r, c] = 0.5 * (z[r, c + 1] - z[r, c - 1])
            elif right:
                gc[r, c] = z[r, c + 1] - z[r, c]
            elif left:
                gc[r, c] = z[r, c] - z[r, c - 1]
            up = r > 0 and jv[r - 1, c]
            down = r < nr - 1 and jv[r, c]
            if up and down:
                gr[r, c] = 0.5 * (z[r + 1, c] - z[r - 1, c])
            elif down:
                gr[r, c] = z[r + 1, c] - z[r, c]
            elif up:
                gr[r, c] = z[r, c] - z[r - 1, c]
    return gc, gr


@njit
def _find(parent, a):
    while parent[a] != a:
        a = parent[a]
    return a


@njit
def _corner_groups(z, jh, jv, gc, gr, rgb, has_rgb):
    """Vertex groups and heights at every lattice corner.

    Corner (i, j) is the top-left corner of cell (i, j); its cells are
    TL (i-1, j-1) = 0, TR (i-1, j) = 1, BL (i, j-1) = 2, BR (i, j) = 3.
    ``grp[i, j, p]`` is the representative position of cell p's group (the
    smallest position of the group) or -1 when p is invalid/outside;
    ``hgt[i, j, q]`` and ``col[i, j, q]`` are the height and colour of group q
    (valid at representative positions).
    """
    nr, nc = z.shape
    grp = np.full((nr + 1, nc + 1, 4), -1, np.int8)
    hgt = np.full((nr + 1, nc + 1, 4), np.nan)
    if has_rgb:
        col = np.zeros((nr + 1, nc + 1, 4, 3), np.float32)
    else:
        col = np.zeros((1, 1, 4, 3), np.float32)
    parent = np.zeros(4, np.int64)
    cr = np.zeros(4, np.int64)
    cc = np.zeros(4, np.int64)
    ok = np.zeros(4, np.bool_)
    acc = np.zeros(4)
    cnt = np.zeros(4)
    cacc = np.zeros((4, 3))
    for i in range(nr + 1):
        for j in range(nc + 1):
            for p in range(4):
                r = i - 1 + p // 2
                c = j - 1 + p % 2
                cr[p] = r
                cc[p] = c
                ok[p] = 0 <= r < nr and 0 <= c < nc and np.isfinite(z[r, c])
                parent[p] = p
            if not (ok[0] or ok[1] or ok[2] or ok[3]):
                continue
            # joined edges around the corner (only between valid cells by construction)
            if ok[0] and ok[1] and jh[i - 1, j - 1]:
                parent[_find(parent, 1)] = _find(parent, 0)
            if ok[2] and ok[3] and jh[i, j - 1]:
                a = _find(parent, 2)
                b = _find(parent, 3)
                parent[max(a, b)] = min(a, b)
            if ok[0] and ok[2] and jv[i - 1, j - 1]:
                a = _find(parent, 0)
                b = _find(parent, 2)
                parent[max(a, b)] = min(a, b)
            if ok[1] and ok[3] and jv[i - 1, j]:
                a = _find(parent, 1)
                b = _find(parent, 3)
                parent[max(a, b)] = min(a, b)
            for q in range(4):
                acc[q] = 0.0
                cnt[q] = 0.0
                cacc[q, 0] = 0.0
                cacc[q, 1] = 0.0
                cacc[q, 2] = 0.0
            for p in range(4):
                if not ok[p]:
                    continue
                # representative = smallest position in the group
                root = _find(parent, p)
                rep = 4
                for q in range(4):
                    if ok[q] and _find(parent, q) == root and q < rep:
                        rep = q
                grp[i, j, p] = rep
                r = cr[p]
                c = cc[p]
                dr = i - (r + 0.5)
                dc = j - (c + 0.5)
                acc[rep] += z[r, c] + gr[r, c] * dr + gc[r, c] * dc
                cnt[rep] += 1.0
                if has_rgb:
                    for b in range(3):
                        cacc[rep, b] += rgb[r, c, b]
            for q in range(4):
                if cnt[q] > 0:
                    hgt[i, j, q] = acc[q] / cnt[q]
                    if has_rgb:
                        for b in range(3):
                            col[i, j, q, b] = cacc[q, b] / cnt[q]
    return grp, hgt, col


@njit
def _uniform0(z, jh, jv):
    """Cells that are valid and whose four edges are joined or face nodata (not the window border)."""
    nr, nc = z.shape
    u = np.zeros((nr, nc), np.bool_)
    for r in range(nr):
        for c in range(nc):
            if not np.isfinite(z[r, c]) or r == 0 or c == 0 or r == nr - 1 or c == nc - 1:
                continue
            good = True
            if np.isfinite(z[r, c - 1]) and not jh[r, c - 1]:
                good = False
            if np.isfinite(z[r, c + 1]) and not jh[r, c]:
                good = False
            if np.isfinite(z[r - 1, c]) and not jv[r - 1, c]:
                good = False
            if np.isfinite(z[r + 1, c]) and not jv[r, c]:
                good = False
            u[r, c] = good
    return u


@njit
def _bary(u, v, u0, v0, h0, u1, v1, h1, u2, v2, h2):
    """Linear interpolation at (u, v) of the plane through three points (their mean if degenerate)."""
    d = (v1 - v2) * (u0 - u2) + (u2 - u1) * (v0 - v2)
    if d == 0.0:
        return (h0 + h1 + h2) / 3.0
    w0 = ((v1 - v2) * (u - u2) + (u2 - u1) * (v - v2)) / d
    w1 = ((v2 - v0) * (u - u2) + (u0 - u2) * (v - v2)) / d
    return w0 * h0 + w1 * h1 + (1.0 - w0 - w1) * h2


@njit
def _inside(u, v, u0, v0, u1, v1, u2, v2):
    """Whether (u, v) lies in the triangle (or on its border); False for a degenerate triangle."""
    d = (v1 - v2) * (u0 - u2) + (u2 - u1) * (v0 - v2)
    if d == 0.0:
        return False
    w0 = ((v1 - v2) * (u - u2) + (u2 - u1) * (v - v2)) / d
    w1 = ((v2 - v0) * (u - u2) + (u0 - u2) * (v - v2)) / d
    return w0 >= -1e-12 and w1 >= -1e-12 and 1.0 - w0 - w1 >= -1e-12


@njit
def _corner_height(grp, hgt, i, j, r, c):
    """Height of the vertex that cell (r, c) uses at lattice corner (i, j).

    Parameters
    ----------
    grp : (rows + 1, cols + 1, 4) int8
        Group of each of the four cells around every corner (:func:`_corner_groups`).
    hgt : (rows + 1, cols + 1, 4) float64
        Height of each group at every corner, metres.
    i, j : int
        Lattice corner (row, column); corner (i, j) is the top-left corner of cell (i, j).
    r, c : int
        One of the four cells around the corner (``r`` in ``i - 1, i``, ``c`` in ``j - 1, j``).

    Returns
    -------
    float
        Height of the corner's vertex in the group of cell (r, c), metres (NaN if that cell
        is invalid).
    """
    p = 2 * (r - i + 1) + (c - j + 1)
    return hgt[i, j, grp[i, j, p]]


@njit
def _block_error(z, grp, hgt, r0, c0, s):
    """Largest error over the block's cells of every triangulation the block may receive."""
    h = s // 2
    tl = _corner_height(grp, hgt, r0, c0, r0, c0)
    tr = _corner_height(grp, hgt, r0, c0 + s, r0, c0 + s - 1)
    bl = _corner_height(grp, hgt, r0 + s, c0, r0 + s - 1, c0)
    br = _corner_height(grp, hgt, r0 + s, c0 + s, r0 + s - 1, c0 + s - 1)
    mt = _corner_height(grp, hgt, r0, c0 + h, r0, c0 + h)
    mb = _corner_height(grp, hgt, r0 + s, c0 + h, r0 + s - 1, c0 + h)
    ml = _corner_height(grp, hgt, r0 + h, c0, r0 + h, c0)
    mr = _corner_height(grp, hgt, r0 + h, c0 + s, r0 + h, c0 + s - 1)
    cc = _corner_height(grp, hgt, r0 + h, c0 + h, r0 + h, c0 + h)
    worst = 0.0
    for r in range(r0, r0 + s):
        for c in range(c0, c0 + s):
            zz = z[r, c]
            u = (c + 0.5 - c0) / s
            v = (r + 0.5 - r0) / s
            # two triangles split along TL-BR
            if u >= v:
                a = tl + u * (tr - tl) + v * (br - tr)
            else:
                a = tl + v * (bl - tl) + u * (br - bl)
            e = abs(a - zz)
            # fan from the centre: the sector of the cell, without and with its edge midpoint
            du = u - 0.5
            dv = v - 0.5
            if abs(du) <= abs(dv) and dv < 0:  # top edge: TL(0,0) - TR(1,0)
                f0 = _bary(u, v, 0.5, 0.5, cc, 0.0, 0.0, tl, 1.0, 0.0, tr)
                if u <= 0.5:
                    f1 = _bary(u, v, 0.5, 0.5, cc, 0.0, 0.0, tl, 0.5, 0.0, mt)
                else:
                    f1 = _bary(u, v, 0.5, 0.5, cc, 0.5, 0.0, mt, 1.0, 0.0, tr)
            elif abs(du) <= abs(dv):  # bottom edge: BL(0,1) - BR(1,1)
                f0 = _bary(u, v, 0.5, 0.5, cc, 0.0, 1.0, bl, 1.0, 1.0, br)
                if u <= 0.5:
                    f1 = _bary(u, v, 0.5, 0.5, cc, 0.0, 1.0, bl, 0.5, 1.0, mb)
                else:
                    f1 = _bary(u, v, 0.5, 0.5, cc, 0.5, 1.0, mb, 1.0, 1.0, br)
            elif du < 0:  # left edge: TL(0,0) - BL(0,1)
                f0 = _bary(u, v, 0.5, 0.5, cc, 0.0, 0.0, tl, 0.0, 1.0, bl)
                if v <= 0.5:
                    f1 = _bary(u, v, 0.5, 0.5, cc, 0.0, 0.0, tl, 0.0, 0.5, ml)
                else:
                    f1 = _bary(u, v, 0.5, 0.5, cc, 0.0, 0.5, ml, 0.0, 1.0, bl)
            else:  # right edge: TR(1,0) - BR(1,1)
                f0 = _bary(u, v, 0.5, 0.5, cc, 1.0, 0.0, tr, 1.0, 1.0, br)
                if v <= 0.5:
                    f1 = _bary(u, v, 0.5, 0.5, cc, 1.0, 0.0, tr, 1.0, 0.5, mr)
                else:
                    f1 = _bary(u, v, 0.5, 0.5, cc, 1.0, 0.5, mr, 1.0, 1.0, br)
            e = max(e, abs(f0 - zz), abs(f1 - zz))
            if e > worst:
                worst = e
    return worst


@njit
def _leaf_levels(z, grp, hgt, uni, tol, kmax):
    """Per-cell quadtree level (leaf side ``2^level``) before balancing; -1 for nodata.

    A block of level k >= 1 is *ok* when all its cells are uniform (k = 1) or its
    four children are ok (k >= 2), and every triangulation it may receive is within
    ``tol``. Ok is hereditary, so the level of a cell is that of the largest ok block
    containing it (0 if none), computed bottom-up in one array.
    """
    nr, nc = z.shape
    lev = np.full((nr, nc), -1, np.int8)
    for r in range(nr):
        for c in range(nc):
            if np.isfinite(z[r, c]):
                lev[r, c] = 0
    for k in range(1, kmax + 1):
        s = 1 << k
        for bi in range(nr // s):
            for bj in range(nc // s):
                r0 = bi * s
                c0 = bj * s
                good = True
                for r in range(r0, r0 + s):
                    for c in range(c0, c0 + s):
                        if (k == 1 and not uni[r, c]) or lev[r, c] < k - 1:
                            good = False
                            break
                    if not good:
                        break
                if good and _block_error(z, grp, hgt, r0, c0, s) <= tol:
                    for r in range(r0, r0 + s):
                        for c in range(c0, c0 + s):
                            lev[r, c] = k
    return lev


@njit
def _balance(lev, kmax):
    """Split leaves until edge neighbours differ by at most one level (children of ok blocks are ok)."""
    nr, nc = lev.shape
    changed = True
    sweeps = 0
    while changed:
        changed = False
        sweeps += 1
        for k in range(kmax, 0, -1):
            s = 1 << k
            for bi in range(nr // s):
                for bj in range(nc // s):
                    r0 = bi * s
                    c0 = bj * s
                    if lev[r0, c0] != k:
                        continue
                    split = False
                    for t in range(s):
                        if r0 > 0 and 0 <= lev[r0 - 1, c0 + t] < k - 1:
                            split = True
                        if r0 + s < nr and 0 <= lev[r0 + s, c0 + t] < k - 1:
                            split = True
                        if c0 > 0 and 0 <= lev[r0 + t, c0 - 1] < k - 1:
                            split = True
                        if c0 + s < nc and 0 <= lev[r0 + t, c0 + s] < k - 1:
                            split = True
                    if split:
                        for r in range(r0, r0 + s):
                            for c in range(c0, c0 + s):
                                lev[r, c] = k - 1
                        changed = True
    return sweeps


@njit
def _corner_shifts(z, grp, lev):
    """Chamfer of the stair corners of walls: per lattice corner, the (row, col) shift in cells.

    A corner whose four cells are single-cell leaves, valid, and split into exactly two groups,
    one of them a single cell (the corner of a staircase outline, convex or concave), moves a
    quarter cell along both axes towards that cell's centre; every vertex there (the top and
    the bottom of the walls) moves alike, so walls stay vertical and a 45-degree staircase becomes
    a straight wall.
    """
    nr, nc = z.shape
    sr = np.zeros((nr + 1, nc + 1))
    sc = np.zeros((nr + 1, nc + 1))
    for i in range(1, nr):
        for j in range(1, nc):
            good = True
            for p in range(4):
                r = i - 1 + p // 2
                c = j - 1 + p % 2
                if lev[r, c] != 0 or not np.isfinite(z[r, c]):
                    good = False
            if not good:
                continue
            # groups: representatives; count members of each
            n0 = 0
            odd = -1
            for q in range(4):
                members = 0
                for p in range(4):
                    if grp[i, j, p] == q:
                        members += 1
                if members > 0:
                    n0 += 1
                    if members == 1:
                        for p in range(4):
                            if grp[i, j, p] == q:
                                odd = p
            if n0 != 2 or odd < 0:
                continue
            sr[i, j] = 0.25 if odd >= 2 else -0.25
            sc[i, j] = 0.25 if odd % 2 == 1 else -0.25
    # a cell whose shifted corners no longer form a convex quad (neighbouring chamfers pulling
    # two ways) keeps its corners in place
    changed = True
    while changed:
        changed = False
        for r in range(nr):
            for c in range(nc):
                if lev[r, c] != 0:
                    continue
                if not _convex_cell(sr, sc, r, c):
                    for i, j in ((r, c), (r, c + 1), (r + 1, c + 1), (r + 1, c)):
                        if sr[i, j] != 0.0 or sc[i, j] != 0.0:
                            sr[i, j] = 0.0
                            sc[i, j] = 0.0
                            changed = True
    return sr, sc


@njit
def _convex_cell(sr, sc, r, c):
    """Whether the (shifted) corners of cell (r, c) form a strictly convex quad (margin 0.05 cell^2)."""
    us = np.empty(4)
    vs = np.empty(4)
    k = 0
    for i, j, du, dv in (
        (r, c, 0.0, 0.0),
        (r, c + 1, 1.0, 0.0),
        (r + 1, c + 1, 1.0, 1.0),
        (r + 1, c, 0.0, 1.0),
    ):
        us[k] = du + sc[i, j]
        vs[k] = dv + sr[i, j]
        k += 1
    for k in range(4):
        a = (k + 1) % 4
        b = (k + 2) % 4
        cross = (us[a] - us[k]) * (vs[b] - vs[a]) - (vs[a] - vs[k]) * (us[b] - us[a])
        if cross < 0.05:
            return False
    return True


@njit
def _put_vertex(out_k, out_v, nv, key, li, lj, z, col, i, j, q, has_rgb):
    """Append one vertex record at index ``nv``; returns ``nv + 1``.

    Parameters
    ----------
    out_k : (V,) int64
        Vertex keys (see :func:`_emit`); ``out_k[nv]`` is written.
    out_v : (V, 6) float64
        Vertex records: lattice row, lattice column, height (metres), red, green, blue (0-255);
        row ``nv`` is written (the colour only when ``has_rgb``).
    nv : int
        Index of the record to write.
    key : int
        Key of the vertex.
    li, lj : float
        Lattice row and column of the vertex (cells, fractional for chamfered corners and
        cell centres), in the global grid.
    z : float
        Height, metres.
    col : (rows + 1, cols + 1, 4, 3) float32
        Colour of every group at every corner (:func:`_corner_groups`).
    i, j, q : int
        Corner (tile lattice) and group whose colour the vertex takes.
    has_rgb : bool
        Whether ``col`` holds colours.
    """
    out_k[nv] = key
    out_v[nv, 0] = li
    out_v[nv, 1] = lj
    out_v[nv, 2] = z
    if has_rgb:
        out_v[nv, 3] = col[i, j, q, 0]
        out_v[nv, 4] = col[i, j, q, 1]
        out_v[nv, 5] = col[i, j, q, 2]
    return nv + 1


@njit
def _tile_capacity(z, lev, jh, jv, core):
    """Upper bounds of the faces and vertex records :func:`_emit` writes for a tile core.

    Parameters
    ----------
    z : (rows, cols) float64
        Heights of the tile window, metres; NaN = nodata.
    lev : (rows, cols) int8
        Quadtree level of every cell after balancing (leaf side ``2^level``; -1 = nodata).
    jh : (rows, cols - 1) bool
        Joined horizontal edges (:func:`_joins`).
    jv : (rows - 1, cols) bool
        Joined vertical edges.
    core : (4,) int64
        Core of the tile in window cells: first row, first column, end row, end column.

    Returns
    -------
    faces, vertices : int
        At most 4 faces and 5 vertex records per single cell, 8 and 9 per larger leaf (a fan
        with its four edge midpoints), 2 and 4 per wall edge.
    """
    nr, nc = z.shape
    nf = 0
    nv = 0
    for r in range(core[0], core[2]):
        for c in range(core[1], core[3]):
            k = lev[r, c]
            if k >= 0 and r % (1 << k) == 0 and c % (1 << k) == 0:
                nf += 4 if k == 0 else 8
                nv += 5 if k == 0 else 9
            if not np.isfinite(z[r, c]):
                continue
            if c + 1 < nc and np.isfinite(z[r, c + 1]) and not jh[r, c]:
                nf += 2
                nv += 4
            if r + 1 < nr and np.isfinite(z[r + 1, c]) and not jv[r, c]:
                nf += 2
                nv += 4
    return nf, nv


@njit
def _finer_neighbour(lev, ra, ca, rb, cb, k):
    """Whether a leaf edge needs its midpoint: a neighbour across it is a finer leaf.

    Parameters
    ----------
    lev : (rows, cols) int8
        Quadtree level of every cell (leaf side ``2^level``; -1 = nodata).
    ra, ca, rb, cb : int
        The two neighbouring cells across the edge, one per half of the edge; cells outside the
        window count as not finer.
    k : int
        Level of the leaf.

    Returns
    -------
    bool
        True when either cell is valid and of a level below ``k``.
    """
    nr, nc = lev.shape
    for r, c in ((ra, ca), (rb, cb)):
        if 0 <= r < nr and 0 <= c < nc and 0 <= lev[r, c] < k:
            return True
    return False


@njit
def _emit(
    z,
    grp,
    hgt,
    col,
    has_rgb,
    lev,
    jh,
    jv,
    sr,
    sc,
    core,
    tol,
    gorigin,
    gcols,
    grows,
    out_f,
    out_w,
    out_k,
    out_v,
):
    """Triangles of the leaves and walls of the tile core.

    Vertex keys: lattice corner (gi, gj) with group q -> ``(gi * (gcols + 1) + gj) * 4 + q``;
    the centre of cell (gr, gc) -> ``(grows + 1) * (gcols + 1) * 4 + gr * gcols + gc``.
    ``out_f`` (M, 3) keys, ``out_w`` (M, 2) direction (drow, dcol) towards the lower side for
    walls, (0, 0) for surface faces; ``out_k`` (V,) keys and ``out_v`` (V, 6) lattice row,
    lattice col, z, r, g, b of the vertex records (one per emitted vertex, duplicates allowed;
    lattice coordinates of a cell centre are +0.5). Returns (faces, vertex records).
    """
    nr, nc = z.shape
    r0c, c0c, r1c, c1c = core[0], core[1], core[2], core[3]
    gr0 = gorigin[0]
    gc0 = gorigin[1]
    base = (grows + 1) * (gcols + 1) * 4
    nf = 0
    nv = 0
    keys = np.zeros(16, np.int64)
    ii = np.zeros(8, np.int64)
    jj = np.zeros(8, np.int64)
    rr = np.zeros(8, np.int64)
    cc_ = np.zeros(8, np.int64)
    ks = np.zeros(4, np.int64)
    for r in range(r0c, r1c):
        for c in range(c0c, c1c):
            k = lev[r, c]
            if k < 0:
                continue
            s = 1 << k
            if (r % s) != 0 or (c % s) != 0:
                continue  # not the top-left cell of its leaf
            h = s // 2
            # ring of the leaf: lattice points (i, j), cell used for the group
            # order: TL, [T], TR, [R], BR, [B], BL, [L]
            cnt = 0
            ii[cnt], jj[cnt], rr[cnt], cc_[cnt] = r, c, r, c
            cnt += 1
            if k >= 1 and _finer_neighbour(lev, r - 1, c, r - 1, c + h, k):
                ii[cnt], jj[cnt], rr[cnt], cc_[cnt] = r, c + h, r, c + h
                cnt += 1
            ii[cnt], jj[cnt], rr[cnt], cc_[cnt] = r, c + s, r, c + s - 1
            cnt += 1
            if k >= 1 and _finer_neighbour(lev, r, c + s, r + h, c + s, k):
                ii[cnt], jj[cnt], rr[cnt], cc_[cnt] = r + h, c + s, r + h, c + s - 1
                cnt += 1
            ii[cnt], jj[cnt], rr[cnt], cc_[cnt] = r + s, c + s, r + s - 1, c + s - 1
            cnt += 1
            if k >= 1 and _finer_neighbour(lev, r + s, c, r + s, c + h, k):
                ii[cnt], jj[cnt], rr[cnt], cc_[cnt] = r + s, c + h, r + s - 1, c + h
                cnt += 1
            ii[cnt], jj[cnt], rr[cnt], cc_[cnt] = r + s, c, r + s - 1, c
            cnt += 1
            if k >= 1 and _finer_neighbour(lev, r, c - 1, r + h, c - 1, k):
                ii[cnt], jj[cnt], rr[cnt], cc_[cnt] = r + h, c, r + h, c
                cnt += 1
            for t in range(cnt):
                i = ii[t]
                j = jj[t]
                p = 2 * (rr[t] - i + 1) + (cc_[t] - j + 1)
                q = grp[i, j, p]
                keys[t] = ((gr0 + i) * (gcols + 1) + (gc0 + j)) * 4 + q
                nv = _put_vertex(
                    out_k,
                    out_v,
                    nv,
                    keys[t],
                    gr0 + i + sr[i, j],
                    gc0 + j + sc[i, j],
                    hgt[i, j, q],
                    col,
                    i,
                    j,
                    q,
                    has_rgb,
                )
            centre = -1
            if cnt > 4:
                # fan from the leaf centre (a lattice point of the uniform block)
                i = r + h
                j = c + h
                q = grp[i, j, 3]
                centre = ((gr0 + i) * (gcols + 1) + (gc0 + j)) * 4 + q
                nv = _put_vertex(
                    out_k, out_v, nv, centre, gr0 + i, gc0 + j, hgt[i, j, q], col, i, j, q, has_rgb
                )
            elif k == 0:
                # a single cell: the better diagonal, or a centre vertex with the cell's height
                zz = z[r, c]
                htl = hgt[ii[0], jj[0], grp[ii[0], jj[0], 3]]
                htr = hgt[ii[1], jj[1], grp[ii[1], jj[1], 2]]
                hbr = hgt[ii[2], jj[2], grp[ii[2], jj[2], 0]]
                hbl = hgt[ii[3], jj[3], grp[ii[3], jj[3], 1]]
                # corners in cell coordinates (u = column, v = row), with their chamfer shifts
                u0, v0 = sc[ii[0], jj[0]], sr[ii[0], jj[0]]
                u1, v1 = 1.0 + sc[ii[1], jj[1]], sr[ii[1], jj[1]]
                u2, v2 = 1.0 + sc[ii[2], jj[2]], 1.0 + sr[ii[2], jj[2]]
                u3, v3 = sc[ii[3], jj[3]], 1.0 + sr[ii[3], jj[3]]
                # height at the centre under diagonal TL-BR and under TR-BL
                if _inside(0.5, 0.5, u0, v0, u1, v1, u2, v2):
                    a1 = _bary(0.5, 0.5, u0, v0, htl, u1, v1, htr, u2, v2, hbr)
                else:
                    a1 = _bary(0.5, 0.5, u0, v0, htl, u2, v2, hbr, u3, v3, hbl)
                if _inside(0.5, 0.5, u0, v0, u1, v1, u3, v3):
                    a2 = _bary(0.5, 0.5, u0, v0, htl, u1, v1, htr, u3, v3, hbl)
                else:
                    a2 = _bary(0.5, 0.5, u1, v1, htr, u2, v2, hbr, u3, v3, hbl)
                e1 = abs(a1 - zz)
                e2 = abs(a2 - zz)
                if min(e1, e2) > tol:
                    centre = base + (gr0 + r) * gcols + (gc0 + c)
                    out_k[nv] = centre
                    out_v[nv, 0] = gr0 + r + 0.5
                    out_v[nv, 1] = gc0 + c + 0.5
                    out_v[nv, 2] = zz
                    if has_rgb:  # colour: mean of the corner colours of the cell's own groups
                        for b in range(3):
                            out_v[nv, 3 + b] = 0.25 * (
                                col[ii[0], jj[0], grp[ii[0], jj[0], 3], b]
                                + col[ii[1], jj[1], grp[ii[1], jj[1], 2], b]
                                + col[ii[2], jj[2], grp[ii[2], jj[2], 0], b]
                                + col[ii[3], jj[3], grp[ii[3], jj[3], 1], b]
                            )
                    nv += 1
                elif e2 < e1:
                    # diagonal TR-BL (ring order TL, TR, BR, BL)
                    out_f[nf, 0], out_f[nf, 1], out_f[nf, 2] = keys[0], keys[3], keys[1]
                    nf += 1
                    out_f[nf, 0], out_f[nf, 1], out_f[nf, 2] = keys[1], keys[3], keys[2]
                    nf += 1
                    continue
            if centre >= 0:
                for t in range(cnt):
                    a = keys[t]
                    b = keys[(t + 1) % cnt]
                    out_f[nf, 0], out_f[nf, 1], out_f[nf, 2] = centre, b, a
                    nf += 1
            else:
                # two triangles split along TL-BR (ring order TL, TR, BR, BL)
                out_f[nf, 0], out_f[nf, 1], out_f[nf, 2] = keys[0], keys[2], keys[1]
                nf += 1
                out_f[nf, 0], out_f[nf, 1], out_f[nf, 2] = keys[0], keys[3], keys[2]
                nf += 1
    # walls: the right and bottom edges of every core cell
    for r in range(r0c, r1c):
        for c in range(c0c, c1c):
            if not np.isfinite(z[r, c]):
                continue
            for d in range(2):
                if d == 0:
                    if c + 1 >= nc or not np.isfinite(z[r, c + 1]) or jh[r, c]:
                        continue
                    # shared edge: lattice column j = c + 1 from (r, j) to (r + 1, j)
                    j = c + 1
                    a0 = (r, j, 2)
                    a1 = (r + 1, j, 0)
                    b0 = (r, j, 3)
                    b1 = (r + 1, j, 1)
                    lower_dr, lower_dc = 0.0, 1.0 if z[r, c + 1] < z[r, c] else -1.0
                else:
                    if r + 1 >= nr or not np.isfinite(z[r + 1, c]) or jv[r, c]:
                        continue
                    i = r + 1
                    a0 = (i, c, 1)
                    a1 = (i, c + 1, 0)
                    b0 = (i, c, 3)
                    b1 = (i, c + 1, 2)
                    lower_dr, lower_dc = (1.0 if z[r + 1, c] < z[r, c] else -1.0), 0.0
                t = 0
                for ijp in (a0, a1, b1, b0):
                    i = ijp[0]
                    j = ijp[1]
                    q = grp[i, j, ijp[2]]
                    ks[t] = ((gr0 + i) * (gcols + 1) + (gc0 + j)) * 4 + q
                    nv = _put_vertex(
                        out_k,
                        out_v,
                        nv,
                        ks[t],
                        gr0 + i + sr[i, j],
                        gc0 + j + sc[i, j],
                        hgt[i, j, q],
                        col,
                        i,
                        j,
                        q,
                        has_rgb,
                    )
                    t += 1
                for tri in range(2):
                    x0 = ks[0]
                    x1 = ks[1 + tri]
                    x2 = ks[2 + tri]
                    if x0 == x1 or x1 == x2 or x0 == x2:
                        continue
                    out_f[nf, 0], out_f[nf, 1], out_f[nf, 2] = x0, x1, x2
                    out_w[nf, 0] = lower_dr
                    out_w[nf, 1] = lower_dc
                    nf += 1
    return nf, nv


# ------------------------------------------------------------------ pipeline


WindowReader = Callable[[int, int, int, int], tuple[np.ndarray, np.ndarray | None]]


def _array_reader(z: np.ndarray, rgb: np.ndarray | None) -> WindowReader:
    rows, cols = z.shape

    def read(r0: int, c0: int, nr: int, nc: int):
        out = np.full((nr, nc), np.nan)
        col = np.zeros((nr, nc, 3)) if rgb is not None else None
        a0, b0 = max(r0, 0), max(c0, 0)
        a1, b1 = min(r0 + nr, rows), min(c0 + nc, cols)
        if a1 > a0 and b1 > b0:
            out[a0 - r0 : a1 - r0, b0 - c0 : b1 - c0] = z[a0:a1, b0:b1]
            if rgb is not None and col is not None:
                col[a0 - r0 : a1 - r0, b0 - c0 : b1 - c0] = rgb[a0:a1, b0:b1]
        return out, col

    return read


def _mesh_tiles(
    read: WindowReader,
    grid: RasterGrid,
    config: DsmMeshConfig,
    has_rgb: bool,
    progress: Progress | None,
) -> DsmMeshResult:
    prog = as_progress(progress)
    res = grid.res
    thr = config.step_threshold(res)
    tol = float(config.max_error) if config.max_error is not None else 0.5 * res
    s_max = config.max_leaf
    kmax = s_max.bit_length() - 1
    tile = -(-config.tile // s_max) * s_max
    margin = 2 * s_max + 2
    margin = -(-margin // s_max) * s_max  # aligned so window blocks align with global blocks
    rows, cols = grid.rows, grid.cols
    faces_l: list[np.ndarray] = []
    walls_l: list[np.ndarray] = []
    verts_l: list[np.ndarray] = []
    keys_l: list[np.ndarray] = []
    leaves: dict[int, int] = {}
    n_cells = 0
    tiles = grid.tiles(tile, 0)
    for n, t in enumerate(tiles):
        check(prog)
        r0, c0, nr, nc = t.core
        wr0, wc0 = r0 - margin, c0 - margin
        wnr, wnc = nr + 2 * margin, nc + 2 * margin
        z, rgb = read(wr0, wc0, wnr, wnc)
        z = np.ascontiguousarray(z, dtype=np.float64)
        core_valid = np.isfinite(z[margin : margin + nr, margin : margin + nc])
        nvalid = int(core_valid.sum())
        if nvalid == 0:
            prog.update((n + 1) / len(tiles), f"mesh tile {n + 1}/{len(tiles)}: nodata")
            continue
        n_cells += nvalid
        rgb_a = np.ascontiguousarray(rgb, dtype=np.float64) if rgb is not None else np.zeros((1, 1, 3))
        jh, jv = _joins(z, thr)
        gc, gr = _gradients(z, jh, jv)
        use_rgb = has_rgb and rgb is not None
        grp, hgt, col = _corner_groups(z, jh, jv, gc, gr, rgb_a, use_rgb)
        uni = _uniform0(z, jh, jv)
        lev = _leaf_levels(z, grp, hgt, uni, tol, kmax)
        _balance(lev, kmax)
        core_lev = lev[margin : margin + nr, margin : margin + nc]
        for k in range(kmax + 1):
            s = 1 << k
            cnt = int(np.count_nonzero(core_lev == k)) // (s * s)
            if cnt:
                leaves[s] = leaves.get(s, 0) + cnt
        core = np.array([margin, margin, margin + nr, margin + nc], np.int64)
        cap_f, cap_v = _tile_capacity(z, lev, jh, jv, core)
        out_f = np.zeros((cap_f, 3), np.int64)
        out_w = np.zeros((cap_f, 2), np.int8)
        out_k = np.zeros(cap_v, np.int64)
        out_v = np.zeros((cap_v, 6))
        if config.chamfer:
            sr, sc = _corner_shifts(z, grp, lev)
        else:
            sr = sc = np.zeros((z.shape[0] + 1, z.shape[1] + 1))
        nf, nv = _emit(
            z,
            grp,
            hgt,
            col,
            use_rgb,
            lev,
            jh,
            jv,
            sr,
            sc,
            core,
            tol,
            np.array([wr0, wc0], np.int64),
            cols,
            rows,
            out_f,
            out_w,
            out_k,
            out_v,
        )
        faces_l.append(out_f[:nf].copy())
        walls_l.append(out_w[:nf].copy())
        keys_l.append(out_k[:nv].copy())
        verts_l.append(out_v[:nv].copy())
        del out_f, out_w, out_k, out_v, grp, hgt, col
        prog.update((n + 1) / len(tiles), f"mesh tile {n + 1}/{len(tiles)}")
    if n_cells == 0:
        raise InputError("the DSM has no valid cells (all nodata): nothing to mesh")
    fkeys = np.concatenate(faces_l)
    wdir = np.concatenate(walls_l)
    vrec = np.concatenate(verts_l)
    vkeys = np.concatenate(keys_l)
    ukeys, first = np.unique(vkeys, return_index=True)
    vr = vrec[first]
    faces = np.searchsorted(ukeys, fkeys).astype(np.int64)
    x = grid.x_min + vr[:, 1] * res
    y = grid.y_max - vr[:, 0] * res
    vertices = np.column_stack([x, y, vr[:, 2]])
    colours = np.clip(np.round(vr[:, 3:6]), 0, 255).astype(np.uint8) if has_rgb else None
    faces = _orient(vertices, faces, wdir)
    mesh = Mesh(vertices, faces, colours, grid.crs)
    n_walls = int(np.count_nonzero(np.any(wdir != 0, axis=1)))
    return DsmMeshResult(mesh, n_cells, n_walls, thr, tol, leaves)


def _orient(vertices: np.ndarray, faces: np.ndarray, wdir: np.ndarray) -> np.ndarray:
    """Surface faces counter-clockwise from above; walls facing their lower side."""
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    n = np.cross(b - a, c - a)
    wall = np.any(wdir != 0, axis=1)
    # lattice (drow, dcol) -> world (dx, dy) = (dcol, -drow)
    facing = n[:, 0] * wdir[:, 1] - n[:, 1] * wdir[:, 0]
    flip = np.where(wall, facing < 0, n[:, 2] < 0)
    out = faces.copy()
    out[flip, 1], out[flip, 2] = faces[flip, 2], faces[flip, 1]
    return out


def _check_dsm(z: np.ndarray, grid: RasterGrid) -> np.ndarray:
    a = np.asarray(z)
    if a.ndim != 2 or a.shape != grid.shape:
        raise InputError(f"DSM: expected an array of the grid's shape {grid.shape}, got {a.shape}")
    if a.dtype.kind != "f":
        raise InputError(f"DSM: expected float heights with NaN for nodata, got {a.dtype}")
    return a


def mesh_from_dsm_array(
    z: np.ndarray,
    grid: RasterGrid,
    config: DsmMeshConfig | None = None,
    rgb: np.ndarray | None = None,
    progress: Progress | None = None,
) -> DsmMeshResult:
    """Mesh a DSM held in memory.

    Parameters
    ----------
    z : (rows, cols) float
        Heights (metres, CRS of ``grid``) at cell centres; NaN = nodata.
    grid : RasterGrid
        Georeferencing of ``z``.
    config : DsmMeshConfig, optional
    rgb : (rows, cols, 3) array, optional
        Colour of every cell (0-255), for vertex colours.

    Returns
    -------
    DsmMeshResult
        ``mesh`` in world coordinates of ``grid.crs``.
    """
    cfg = config or DsmMeshConfig()
    cfg.validate()
    a = _check_dsm(z, grid)
    if rgb is not None:
        rgb = np.asarray(rgb)
        if rgb.shape != grid.shape + (3,):
            raise InputError(f"colours: expected shape {grid.shape + (3,)}, got {rgb.shape}")
    if not np.isfinite(a).any():
        raise InputError("the DSM has no valid cells (all nodata): nothing to mesh")
    return _mesh_tiles(_array_reader(a, rgb), grid, cfg, rgb is not None, progress)


def mesh_from_dsm(
    path,
    config: DsmMeshConfig | None = None,
    ortho_path=None,
    progress: Progress | None = None,
) -> DsmMeshResult:
    """Mesh a DSM GeoTIFF tile by tile (only windows and the mesh are held in memory).

    Parameters
    ----------
    path : str or os.PathLike
        Single-band DSM raster with a projected CRS; its nodata is left out.
    config : DsmMeshConfig, optional
    ortho_path : str or os.PathLike, optional
        RGB(A) orthoimage for vertex colours, resampled (reprojected if needed) onto the
        DSM grid window by window.

    Raises
    ------
    CRSError
        The DSM has no CRS or a geographic one.
    InputError
        All cells are nodata, or a bad parameter.
    """
    from ..geometry.frame import parse_crs, require_metric
    from ..rasterio_io import raster_grid, read_raster

    cfg = config or DsmMeshConfig()
    cfg.validate()
    grid = raster_grid(path, require_crs=True)
    require_metric(parse_crs(grid.crs), f"DSM {path}")
    ortho_grid = None
    if ortho_path is not None:
        ortho_grid = raster_grid(ortho_path, require_crs=True)

    def read(r0: int, c0: int, nr: int, nc: int):
        out = np.full((nr, nc), np.nan)
        a0, b0 = max(r0, 0), max(c0, 0)
        a1, b1 = min(r0 + nr, grid.rows), min(c0 + nc, grid.cols)
        col = None
        if a1 > a0 and b1 > b0:
            data, _, _ = read_raster(path, 1, (a0, b0, a1 - a0, b1 - b0))
            out[a0 - r0 : a1 - r0, b0 - c0 : b1 - c0] = data
        if ortho_grid is not None:
            col = colours_on_grid(ortho_path, grid.window(r0, c0, nr, nc), ortho_grid)
        return out, col

    return _mesh_tiles(read, grid, cfg, ortho_path is not None, progress)


# ------------------------------------------------------------------ mesh -> raster


@njit
def _raster_faces(v, f, x0, y0, res, rows, cols, out):
    eps = 1e-9
    for n in range(f.shape[0]):
        ax, ay, az = v[f[n, 0], 0], v[f[n, 0], 1], v[f[n, 0], 2]
        bx, by, bz = v[f[n, 1], 0], v[f[n, 1], 1], v[f[n, 1], 2]
        cx, cy, cz = v[f[n, 2], 0], v[f[n, 2], 1], v[f[n, 2], 2]
        d = (by - cy) * (ax - cx) + (cx - bx) * (ay - cy)
        if abs(d) < 1e-12 * res * res:
            continue  # vertical or degenerate
        cmin = max(int(np.floor((min(ax, bx, cx) - x0) / res - 0.5)), 0)
        cmax = min(int(np.ceil((max(ax, bx, cx) - x0) / res - 0.5)), cols - 1)
        rmin = max(int(np.floor((y0 - max(ay, by, cy)) / res - 0.5)), 0)
        rmax = min(int(np.ceil((y0 - min(ay, by, cy)) / res - 0.5)), rows - 1)
        for r in range(rmin, rmax + 1):
            py = y0 - (r + 0.5) * res
            for c in range(cmin, cmax + 1):
                px = x0 + (c + 0.5) * res
                w0 = ((by - cy) * (px - cx) + (cx - bx) * (py - cy)) / d
                w1 = ((cy - ay) * (px - cx) + (ax - cx) * (py - cy)) / d
                w2 = 1.0 - w0 - w1
                if w0 < -eps or w1 < -eps or w2 < -eps:
                    continue
                zz = w0 * az + w1 * bz + w2 * cz
                if not zz <= out[r, c]:  # NaN or lower
                    out[r, c] = zz


def rasterize_mesh(mesh: Mesh, grid: RasterGrid) -> np.ndarray:
    """Highest mesh surface at every cell centre of ``grid``.

    Parameters
    ----------
    mesh : Mesh
        World coordinates in the CRS of ``grid``.
    grid : RasterGrid

    Returns
    -------
    (rows, cols) float64
        Height of the highest non-vertical triangle above each cell centre; NaN where
        no triangle covers it.
    """
    if not isinstance(mesh, Mesh):
        raise InputError(f"expected a Mesh, got {type(mesh).__name__}")
    out = np.full(grid.shape, np.nan)
    _raster_faces(mesh.vertices, mesh.faces, grid.x_min, grid.y_max, grid.res, grid.rows, grid.cols, out)
    return out


# ------------------------------------------------------------------ point cloud -> mesh


def mesh_from_point_cloud(
    cloud, max_edge: float | None = None, max_angle_deg: float = 80.0, progress: Progress | None = None
) -> Mesh:
    """A mesh of a (merged, oblique) point cloud: one 2.5D Delaunay mesh per reference system.

    For every reference system the points are projected onto the plane normal to its
    viewing direction (``ReferenceSystem.view_direction``; nadir ``(0, 0, -1)`` when
    unknown) and triangulated (Delaunay, scipy); triangles with an edge longer than
    ``max_edge`` (default 4 x the median nearest-neighbour spacing) or seen at more
    than ``max_angle_deg`` from the viewing direction (they would bridge depth
    discontinuities) are dropped. The meshes of the systems are concatenated: where
    two systems see the same surface their layers overlap (no fusion), and the mesh is
    not watertight. Faces face the cameras of their system.

    Parameters
    ----------
    cloud : PointCloud
        See :mod:`.pointcloud`; ``system`` ids select the systems (all one system when absent).

    Returns
    -------
    Mesh
        World coordinates, vertex colours when the cloud has them.
    """
    from scipy.spatial import Delaunay, cKDTree

    from .pointcloud import PointCloud

    if not isinstance(cloud, PointCloud):
        raise InputError(f"expected a PointCloud, got {type(cloud).__name__}")
    if len(cloud) < 3:
        raise InputError(f"a mesh needs at least 3 points, the cloud has {len(cloud)}")
    if not 1.0 <= max_angle_deg < 90.0:
        raise InputError(f"max_angle_deg must lie in [1, 90), got {max_angle_deg!r}")
    prog = as_progress(progress)
    sys_ids = cloud.system if cloud.system is not None else np.zeros(len(cloud), np.uint16)
    dirs = {s.id: s.view_direction for s in cloud.systems}
    verts, faces, cols = [], [], []
    base = 0
    ids = np.unique(sys_ids)
    cos_max = math.cos(math.radians(max_angle_deg))
    for n, sid in enumerate(ids):
        check(prog)
        idx = np.nonzero(sys_ids == sid)[0]
        if len(idx) < 3:
            continue
        v = np.asarray(dirs.get(int(sid)) or (0.0, 0.0, -1.0), dtype=np.float64)
        if not np.all(np.isfinite(v)) or np.linalg.norm(v) == 0:
            raise InputError(f"reference system {int(sid)}: invalid view direction {v.tolist()}")
        v = v / np.linalg.norm(v)
        a = np.array([1.0, 0.0, 0.0]) if abs(v[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        e1 = np.cross(v, a)
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(v, e1)
        p = cloud.xyz[idx]
        centre = p.mean(axis=0)
        q = np.column_stack([(p - centre) @ e1, (p - centre) @ e2])
        try:
            tri = Delaunay(q).simplices.astype(np.int64)
        except Exception as exc:  # degenerate (collinear) input
            raise InputError(
                f"reference system {int(sid)}: the points cannot be triangulated ({exc})"
            ) from None
        edge = max_edge
        if edge is None:
            d, _ = cKDTree(q).query(q, k=2)
            edge = 4.0 * float(np.median(d[:, 1]))
        A, B, C = p[tri[:, 0]], p[tri[:, 1]], p[tri[:, 2]]
        longest = np.max(
            np.stack(
                [np.linalg.norm(B - A, axis=1), np.linalg.norm(C - B, axis=1), np.linalg.norm(A - C, axis=1)]
            ),
            axis=0,
        )
        nrm = np.cross(B - A, C - A)
        nn = np.linalg.norm(nrm, axis=1)
        facing = -(nrm @ v) / np.where(nn > 0, nn, 1.0)
        keep = (longest <= edge) & (np.abs(facing) >= cos_max) & (nn > 0)
        t = tri[keep]
        flip = facing[keep] < 0
        t[flip] = t[flip][:, [0, 2, 1]]
        used = np.unique(t)
        remap = -np.ones(len(p), np.int64)
        remap[used] = np.arange(len(used))
        verts.append(p[used])
        faces.append(remap[t] + base)
        if cloud.rgb is not None:
            cols.append(cloud.rgb[idx][used])
        base += len(used)
        prog.update((n + 1) / len(ids), f"meshing reference system {int(sid)}")
    if base == 0:
        raise InputError("no triangle of the point cloud passed the edge-length and angle tests")
    return Mesh(
        np.concatenate(verts), np.concatenate(faces), np.concatenate(cols) if cols else None, cloud.crs
    )
