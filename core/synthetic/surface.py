"""The analytic 2.5D surface of a synthetic scene: terrain plus buildings.

``h(x, y)`` (local frame, metres) is the maximum of

* the terrain ``ground_height + sum_i a_i sin(k_i . (x, y) + phi_i)``,
  sampled every quarter coarse cell (0.5 m) over the acceleration grid and
  interpolated bilinearly (clamped outside the grid): the interpolant *is*
  the terrain truth (it differs from the sines by < 1 mm), and

* every building whose (rotated rectangular) footprint contains ``(x, y)``:
  ``eave_top + roof(u, v)`` with ``(u, v)`` the footprint coordinates (``u``
  along the long half-side ``a``, ``v`` across, half-side ``b <= a``) and the
  roof profile flat ``0``, gable ``r (1 - |v|/b)``, hip
  ``r min(1 - |v|/b, (a - |u|)/b)`` or shed ``r (v + b) / (2 b)``.

``eave_top`` lies above the highest terrain under the footprint, so every
footprint edge is a height discontinuity: walls are exactly vertical. The
buildings are evaluated analytically (no height grid); a coarse grid of
conservative per-cell maximum heights and per-cell building lists
accelerates ray casting (:mod:`.raycast`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..jit import njit, pjit, prange
from .config import SceneConfig

FLAT, GABLE, HIP, SHED = 0, 1, 2, 3
ROOF_SHAPES = ("flat", "gable", "hip", "shed")
MAX_PER_CELL = 6


@dataclass(frozen=True)
class Building:
    """One building (local frame, metres, angle in radians).

    ``half_size = (a, b)`` with ``a >= b``; ``angle`` rotates the ``u`` axis
    from local x towards local y; ``base`` is the highest terrain under the
    footprint, ``eave_top`` the absolute height of the wall tops and
    ``ridge`` the roof rise above them.
    """

    center: tuple[float, float]
    half_size: tuple[float, float]
    angle: float
    base: float
    eave_top: float
    ridge: float
    roof: str
    tower: bool = False

    @property
    def top(self) -> float:
        """Highest point of the roof (absolute local height)."""
        return self.eave_top + self.ridge

    @property
    def radius(self) -> float:
        return math.hypot(*self.half_size)

    def corners(self) -> np.ndarray:
        """(4, 2) footprint corners, counter-clockwise."""
        a, b = self.half_size
        c, s = math.cos(self.angle), math.sin(self.angle)
        uv = np.array([[a, b], [-a, b], [-a, -b], [a, -b]])
        return np.column_stack([self.center[0] + c * uv[:, 0] - s * uv[:, 1],
                                self.center[1] + s * uv[:, 0] + c * uv[:, 1]])

    def to_uv(self, xy) -> np.ndarray:
        """Footprint coordinates ``(u, v)`` of local (N, 2) points."""
        p = np.asarray(xy, dtype=np.float64).reshape(-1, 2) - np.asarray(self.center)
        c, s = math.cos(self.angle), math.sin(self.angle)
        return np.column_stack([c * p[:, 0] + s * p[:, 1], -s * p[:, 0] + c * p[:, 1]])

    def from_uv(self, uv) -> np.ndarray:
        """Local (N, 2) points of footprint coordinates."""
        q = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
        c, s = math.cos(self.angle), math.sin(self.angle)
        return np.column_stack([self.center[0] + c * q[:, 0] - s * q[:, 1],
                                self.center[1] + s * q[:, 0] + c * q[:, 1]])


# ---------------------------------------------------------------- kernels


@njit
def _terrain(x, y, terr, g):
    """Bilinear interpolation of the terrain grid (clamped at its border)."""
    fx = (x - g[11]) / g[13]
    fy = (y - g[12]) / g[13]
    nx = terr.shape[1]
    ny = terr.shape[0]
    fx = min(max(fx, 0.0), nx - 1.0)
    fy = min(max(fy, 0.0), ny - 1.0)
    i = min(np.int64(fx), nx - 2)
    j = min(np.int64(fy), ny - 2)
    u = fx - i
    v = fy - j
    a = terr[j, i] + u * (terr[j, i + 1] - terr[j, i])
    b = terr[j + 1, i] + u * (terr[j + 1, i + 1] - terr[j + 1, i])
    return a + v * (b - a)


@pjit
def _terrain_many(xy, terr, g, out):
    for n in prange(xy.shape[0]):
        out[n] = _terrain(xy[n, 0], xy[n, 1], terr, g)


@njit
def _building_height(k, x, y, bld):
    """Height of building ``k`` at (x, y), ``-inf`` outside its footprint."""
    dx = x - bld[k, 0]
    dy = y - bld[k, 1]
    u = bld[k, 2] * dx + bld[k, 3] * dy
    v = -bld[k, 3] * dx + bld[k, 2] * dy
    a = bld[k, 4]
    b = bld[k, 5]
    if abs(u) > a or abs(v) > b:
        return -np.inf
    shape = np.int64(bld[k, 9])
    r = bld[k, 8]
    if shape == 1:
        return bld[k, 7] + r * (1.0 - abs(v) / b)
    if shape == 2:
        return bld[k, 7] + r * min(1.0 - abs(v) / b, (a - abs(u)) / b)
    if shape == 3:
        return bld[k, 7] + r * (v + b) / (2.0 * b)
    return bld[k, 7]


@njit
def _height(x, y, terr, bld, g, cbld):
    """Surface height and building index (-1 = terrain) at (x, y)."""
    h = _terrain(x, y, terr, g)
    best = -1
    i = np.int64(np.floor((x - g[0]) / g[2]))
    j = np.int64(np.floor((y - g[1]) / g[2]))
    if 0 <= i < np.int64(g[3]) and 0 <= j < np.int64(g[4]):
        for m in range(cbld.shape[2]):
            k = cbld[j, i, m]
            if k < 0:
                break
            hb = _building_height(k, x, y, bld)
            if hb > h:
                h = hb
                best = k
    return h, best


@pjit
def _height_many(xy, terr, bld, g, cbld, h, bid):
    for n in prange(xy.shape[0]):
        hh, bb = _height(xy[n, 0], xy[n, 1], terr, bld, g, cbld)
        h[n] = hh
        bid[n] = bb


# ------------------------------------------------------------- surface


class Surface:
    """Terrain, buildings and the packed arrays the kernels use.

    Attributes
    ----------
    buildings : list of Building
    waves : (n, 4) float64
        Analytic terrain components ``[amplitude, kx, ky, phase]``.
    terr : (nty, ntx) float64
        The terrain sampled on nodes ``(x0 + i s, y0 + j s)``, ``s`` = a
        quarter coarse cell; the surface uses its bilinear interpolation
        (clamped outside), which is the terrain truth.
    bld : (nb, 10) float64
        Packed buildings ``[cx, cy, cos, sin, a, b, base, eave_top, ridge, shape]``.
    grid : (14,) float64
        ``[x0, y0, cell, nx, ny, z_max_outside, z_low, z_top, lipschitz, fine_step, z0,
        tx0, ty0, t_step]``.
    cell_max : (ny, nx) float64
        Upper bound of ``h`` over each coarse cell.
    cell_bld : (ny, nx, MAX_PER_CELL) int64
        Indices of the buildings that may touch each cell, -1 padded.
    """

    def __init__(self, config: SceneConfig) -> None:
        self.config = config
        c = config
        self.waves = _make_terrain(config)
        self.z0 = float(config.ground_height)
        cs = float(c.coarse_cell)
        x0 = c.extent[0] - c.grid_margin
        y0 = c.extent[1] - c.grid_margin
        nx = int(math.ceil((c.extent[2] - c.extent[0] + 2 * c.grid_margin) / cs))
        ny = int(math.ceil((c.extent[3] - c.extent[1] + 2 * c.grid_margin) / cs))
        ts = cs / 4
        tx = x0 + np.arange(4 * nx + 1) * ts
        ty = y0 + np.arange(4 * ny + 1) * ts
        w = self.waves
        phase = tx[None, :, None] * w[:, 1] + ty[:, None, None] * w[:, 2] + w[:, 3]
        terr = self.z0 + np.sum(w[:, 0] * np.sin(phase), axis=2)
        self.terr = np.ascontiguousarray(terr)
        # bilinear interpolant: gradient components are convex combinations of node differences
        gx = np.abs(np.diff(terr, axis=1)).max() / ts
        gy = np.abs(np.diff(terr, axis=0)).max() / ts
        self.lipschitz = float(math.hypot(gx, gy)) * 1.000001 + 1e-12
        self.grid = np.array([x0, y0, cs, nx, ny, terr.max() + 1e-6, terr.min() - 1.0, 0.0, self.lipschitz,
                              float(c.fine_step), self.z0, x0, y0, ts])
        self.buildings = _place_buildings(config, self)
        self.bld = _pack(self.buildings)
        # exact terrain maximum per coarse cell (a bilinear patch peaks at a node)
        cmax = terr[: 4 * ny + 1, : 4 * nx + 1]
        cmax = np.maximum.reduce([cmax[j: j + 4 * ny: 4, i: i + 4 * nx: 4]
                                  for j in range(5) for i in range(5)])
        cmax = cmax + 1e-6
        cbld = np.full((ny, nx, MAX_PER_CELL), -1, np.int64)
        count = np.zeros((ny, nx), np.int64)
        for k, b in enumerate(self.buildings):
            r = b.radius + 1e-6
            i0, i1 = int((b.center[0] - r - x0) // cs), int((b.center[0] + r - x0) // cs)
            j0, j1 = int((b.center[1] - r - y0) // cs), int((b.center[1] + r - y0) // cs)
            for j in range(max(j0, 0), min(j1, ny - 1) + 1):
                for i in range(max(i0, 0), min(i1, nx - 1) + 1):
                    if count[j, i] >= MAX_PER_CELL:
                        raise InputError("too many buildings share one grid cell; reduce coarse_cell")
                    cbld[j, i, count[j, i]] = k
                    count[j, i] += 1
                    cmax[j, i] = max(cmax[j, i], b.top + 1e-6)
        self.cell_max = np.ascontiguousarray(cmax)
        self.cell_bld = cbld
        self.grid[7] = float(cmax.max()) + 0.5

    # ---------------------------------------------------------- python side
    def terrain(self, xy) -> np.ndarray:
        """Terrain height (ignoring buildings) at local (N, 2) points."""
        p = np.ascontiguousarray(np.asarray(xy, dtype=np.float64).reshape(-1, 2))
        out = np.empty(len(p))
        _terrain_many(p, self.terr, self.grid, out)
        return out

    def height(self, xy) -> tuple[np.ndarray, np.ndarray]:
        """Surface height and building index (-1 = open ground).

        Parameters
        ----------
        xy : (N, 2) float64
            Local plan coordinates, metres.

        Returns
        -------
        h : (N,) float64
            Height in the local frame; on a footprint edge the roof wins.
        building : (N,) int64
        """
        p = np.asarray(xy, dtype=np.float64)
        if p.ndim == 1 and p.shape[0] == 2:
            p = p[None]
        if p.ndim != 2 or p.shape[1] != 2 or not np.all(np.isfinite(p)):
            raise InputError(f"height: expected finite (N, 2) local coordinates, got shape {np.shape(xy)}")
        h = np.empty(len(p))
        bid = np.empty(len(p), np.int64)
        _height_many(np.ascontiguousarray(p), self.terr, self.bld, self.grid, self.cell_bld, h, bid)
        return h, bid

    def footprint_distance(self, xy) -> np.ndarray:
        """Horizontal distance (m) from local (N, 2) points to the nearest footprint (0 inside)."""
        p = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        d = np.full(len(p), np.inf)
        for b in self.buildings:
            uv = np.abs(b.to_uv(p))
            out = np.maximum(uv - np.asarray(b.half_size), 0.0)
            d = np.minimum(d, np.hypot(out[:, 0], out[:, 1]))
        return d

    @property
    def z_top(self) -> float:
        return float(self.grid[7])


def _make_terrain(c: SceneConfig) -> np.ndarray:
    rng = np.random.default_rng([c.seed, 11])
    n = 4
    weights = rng.uniform(0.5, 1.0, n)
    amp = c.terrain_relief * weights / weights.sum()
    lam = np.exp(rng.uniform(math.log(c.terrain_wavelengths[0]), math.log(c.terrain_wavelengths[1]), n))
    ang = rng.uniform(0.0, math.pi, n)
    k = 2 * math.pi / lam
    phase = rng.uniform(0.0, 2 * math.pi, n)
    return np.column_stack([amp, k * np.cos(ang), k * np.sin(ang), phase])


def _place_buildings(c: SceneConfig, surf: Surface) -> list[Building]:
    rng = np.random.default_rng([c.seed, 12])
    x0, y0, x1, y1 = c.extent
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    specs = []  # (a, b, shape, tower)
    if c.tower:
        specs.append((c.tower_size / 2, c.tower_size / 2, FLAT, True))
    for k in range(c.n_buildings):
        L = rng.uniform(*c.building_size)
        W = rng.uniform(c.building_size[0], L)
        specs.append((L / 2, W / 2, k % 4, False))
    placed: list[Building] = []
    for a, b, shape, tower in specs:
        r = math.hypot(a, b)
        for _attempt in range(5000):
            if tower:
                px = cx + rng.uniform(-0.1, 0.1) * (x1 - x0)
                py = cy + rng.uniform(-0.1, 0.1) * (y1 - y0)
            else:
                px = rng.uniform(x0 + r + 2, x1 - r - 2)
                py = rng.uniform(y0 + r + 2, y1 - r - 2)
            if all(math.hypot(px - q.center[0], py - q.center[1]) >= r + q.radius + c.building_gap
                   for q in placed):
                break
        else:
            raise InputError(
                f"could not place {len(specs)} buildings with gap {c.building_gap} m in the extent "
                f"{c.extent}; enlarge the extent or reduce n_buildings / building_size"
            )
        angle = float(rng.uniform(0.0, math.pi))
        proto = Building((px, py), (a, b), angle, 0.0, 0.0, 0.0, ROOF_SHAPES[shape], tower)
        g = np.linspace(-1.0, 1.0, 9)
        uv = np.column_stack([np.repeat(g * a, 9), np.tile(g * b, 9)])
        base = float(surf.terrain(proto.from_uv(uv)).max()) + surf.lipschitz * math.hypot(a, b) / 8
        eave = c.tower_height if tower else float(rng.uniform(*c.eave_height))
        pitch = math.radians(float(rng.uniform(*c.roof_pitch)))
        ridge = {FLAT: 0.0, GABLE: b * math.tan(pitch), HIP: b * math.tan(pitch),
                 SHED: 2 * b * math.tan(pitch / 2)}[shape]
        placed.append(Building((px, py), (a, b), angle, base, base + eave, ridge, ROOF_SHAPES[shape], tower))
    return placed


def _pack(buildings: list[Building]) -> np.ndarray:
    out = np.zeros((max(len(buildings), 1), 10))
    for k, b in enumerate(buildings):
        out[k] = [b.center[0], b.center[1], math.cos(b.angle), math.sin(b.angle), b.half_size[0],
                  b.half_size[1], b.base, b.eave_top, b.ridge, ROOF_SHAPES.index(b.roof)]
    return out
