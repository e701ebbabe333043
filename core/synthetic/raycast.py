"""Ray casting against the analytic surface of :mod:`.surface`.

A ray ``X(t) = o + t d`` (local frame, ``|d| = 1``, ``t`` in metres) starts at
the plane ``z = z_top`` above everything and marches forward:

* over a coarse cell whose height bound ``cell_max`` lies below the ray, it
  jumps to the cell exit (or to where the ray reaches the bound);
* otherwise it steps by the larger of ``fine_step`` (horizontally, and 1 m
  vertically) and a *safe* step that provably cannot pass through the
  surface: the terrain's Lipschitz bound and, for every building of the
  cell, the horizontal distance to its footprint, its roof slope or its top
  (sphere tracing; clipped at the cell exit). Only features thinner than
  ``fine_step`` can thus be stepped over;
* the first sample below the surface brackets the hit with the last sample
  above it; safeguarded false position (Illinois, to 1e-7 m) then converges
  onto the surface, or onto the vertical discontinuity of a wall, where the ray point stays below the
  higher side: that hit is classified as *wall* of the building on that side.

Kernels return ``t`` (NaN when the ray leaves without a hit), the material
(:data:`~.texture.GROUND`, ``ROOF``, ``WALL``, ``SKY`` = -1) and the building
index (-1 for ground and sky).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..jit import njit, pjit, prange
from .surface import Surface, _height, _terrain

WALL_TOL = 1e-5  # metres of height gap that make a hit a wall hit
T_TOL = 1e-7  # bracket length (metres along the ray) ending the refinement
F_TOL = 1e-8  # |z - h| (metres) ending the refinement on smooth surfaces


@njit
def _refine(ox, oy, oz, dx, dy, dz, lo, flo, hi, fhi, terr, bld, g, cbld):
    """Root of ``f(t) = z(t) - h(t)`` in ``[lo, hi]`` (``f(lo) > 0 >= f(hi)``).

    Illinois false position, safeguarded by bisection, until the bracket is
    shorter than ``T_TOL``; a hit whose height gap stays above ``WALL_TOL``
    is on the vertical discontinuity of a wall.
    """
    side = 0
    for it in range(100):
        if hi - lo <= T_TOL:
            break
        if it % 4 == 3:  # guaranteed halving every 4th step
            m = 0.5 * (lo + hi)
        else:
            m = (lo * fhi - hi * flo) / (fhi - flo)
            w = hi - lo
            if not (lo + 0.01 * w < m < hi - 0.01 * w):
                m = min(max(m, lo + 0.01 * w), hi - 0.01 * w)
        hm, bm = _height(ox + m * dx, oy + m * dy, terr, bld, g, cbld)
        fm = oz + m * dz - hm
        if fm > 0.0:
            lo = m
            flo = fm
            if side == 1:
                fhi *= 0.5
            side = 1
        else:
            hi = m
            fhi = fm
            if side == -1:
                flo *= 0.5
            side = -1
            if fm > -F_TOL:  # on a smooth surface: done
                break
    hh, bb = _height(ox + hi * dx, oy + hi * dy, terr, bld, g, cbld)
    gap = hh - (oz + hi * dz)
    if bb < 0:
        return hi, 0, -1
    if gap > WALL_TOL:
        return hi, 2, bb
    return hi, 1, bb


@njit
def _probe(x, y, z, dxy, adz, dz, terr, bld, g, cbld, i, j, inside):
    """``(z - h, building, safe_step)`` at a ray point.

    ``safe_step`` (metres along the ray) cannot reach the surface of the
    terrain or of any building listed in cell (i, j): terrain by its
    Lipschitz bound, a building by the horizontal distance to its footprint,
    the slope of its (extended) roof planes or its top height.
    """
    ht = _terrain(x, y, terr, g)
    h = ht
    best = -1
    step = 0.0
    if z > ht:
        step = (z - ht) / (adz + g[8] * dxy)
    if inside:
        for m in range(cbld.shape[2]):
            k = cbld[j, i, m]
            if k < 0:
                break
            ex = x - bld[k, 0]
            ey = y - bld[k, 1]
            u = bld[k, 2] * ex + bld[k, 3] * ey
            v = -bld[k, 3] * ex + bld[k, 2] * ey
            a = bld[k, 4]
            b = bld[k, 5]
            r = bld[k, 8]
            shape = np.int64(bld[k, 9])
            if shape == 1:
                hr = bld[k, 7] + r * (1.0 - abs(v) / b)
                slope = r / b
            elif shape == 2:
                hr = bld[k, 7] + r * min(1.0 - abs(v) / b, (a - abs(u)) / b)
                slope = r / b
            elif shape == 3:
                hr = bld[k, 7] + r * (v + b) / (2.0 * b)
                slope = r / (2.0 * b)
            else:
                hr = bld[k, 7]
                slope = 0.0
            ou = max(abs(u) - a, 0.0)
            ov = max(abs(v) - b, 0.0)
            if ou == 0.0 and ov == 0.0 and hr > h:
                h = hr
                best = k
            sk = 0.0
            if z > hr:
                sk = (z - hr) / (adz + slope * dxy)
            dfp = np.sqrt(ou * ou + ov * ov)
            if dfp > 0.0:
                sk = max(sk, dfp / dxy if dxy > 1e-15 else 1e300)
            top = bld[k, 7] + r
            if z > top:
                sk = max(sk, (z - top) / adz if dz < 0.0 else 1e300)
            step = min(step, sk)
    return z - h, best, step


@njit
def _cast_one(ox, oy, oz, dx, dy, dz, tmax, terr, bld, g, cmax, cbld):
    """First hit of one ray; returns ``(t, material, building)``."""
    x0 = g[0]
    y0 = g[1]
    cs = g[2]
    nx = np.int64(g[3])
    ny = np.int64(g[4])
    zlow = g[6]
    ztop = g[7]
    dxy = np.sqrt(dx * dx + dy * dy)
    adz = abs(dz)
    dt_fine = 1e30
    if dxy > 1e-15:
        dt_fine = g[9] / dxy
    if adz > 1e-15:
        dt_fine = min(dt_fine, 1.0 / adz)
    t = 0.0
    if oz > ztop:
        if dz >= 0.0:
            return np.nan, -1, -1
        t = (oz - ztop) / (-dz)
    if t > tmax:
        return np.nan, -1, -1
    t_prev = -1.0  # last point known to lie above the surface (-1: none yet)
    f_prev = np.nan  # its z - h when known
    while True:
        x = ox + t * dx
        y = oy + t * dy
        z = oz + t * dz
        if z < zlow or (z > ztop and dz >= 0.0):
            return np.nan, -1, -1
        fi = np.floor((x - x0) / cs)
        fj = np.floor((y - y0) / cs)
        i = np.int64(fi)
        j = np.int64(fj)
        inside = 0 <= i < nx and 0 <= j < ny
        cm = cmax[j, i] if inside else g[5]
        t_exit = 1e300
        if dx > 0.0:
            t_exit = (x0 + (fi + 1.0) * cs - ox) / dx
        elif dx < 0.0:
            t_exit = (x0 + fi * cs - ox) / dx
        if dy > 0.0:
            t_exit = min(t_exit, (y0 + (fj + 1.0) * cs - oy) / dy)
        elif dy < 0.0:
            t_exit = min(t_exit, (y0 + fj * cs - oy) / dy)
        if z > cm:  # the whole cell lies below the ray: skip it
            t_next = t_exit
            if dz < 0.0:
                t_next = min(t_next, (oz - cm) / (-dz))
            t_prev = t
            f_prev = np.nan
            t_next += 1e-9
        else:
            f, b, step = _probe(x, y, z, dxy, adz, dz, terr, bld, g, cbld, i, j, inside)
            if f <= 0.0:
                if t_prev < 0.0:  # the ray starts in or under the surface
                    return t, (0 if b < 0 else 1), b
                if not f_prev == f_prev:
                    hp, bp = _height(ox + t_prev * dx, oy + t_prev * dy, terr, bld, g, cbld)
                    f_prev = oz + t_prev * dz - hp
                return _refine(ox, oy, oz, dx, dy, dz, t_prev, f_prev, t, f, terr, bld, g, cbld)
            t_prev = t
            f_prev = f
            t_next = min(t + max(step, dt_fine), t_exit + 1e-9)
        t_next = max(t_next, t + 1e-7)
        if t >= tmax:
            return np.nan, -1, -1
        t = min(t_next, tmax)


@pjit
def _cast_many(orig, dirs, tmax, terr, bld, g, cmax, cbld, t_out, mat_out, bid_out):
    for n in prange(dirs.shape[0]):
        t, m, b = _cast_one(orig[n, 0], orig[n, 1], orig[n, 2], dirs[n, 0], dirs[n, 1], dirs[n, 2], tmax[n],
                            terr, bld, g, cmax, cbld)
        t_out[n] = t
        mat_out[n] = m
        bid_out[n] = b


def cast_rays(surface: Surface, origins, directions, tmax=1e6):
    """First intersections of rays with the surface.

    Parameters
    ----------
    surface : Surface
    origins : (3,) or (N, 3) float64
        Ray origins in the local frame, metres.
    directions : (N, 3) float64
        Directions (normalised here).
    tmax : float or (N,) float64
        Largest distance searched, metres.

    Returns
    -------
    t : (N,) float64
        Distance to the hit along the ray, metres; NaN when nothing is hit
        before ``tmax``.
    material : (N,) int64
        0 ground, 1 roof, 2 wall, -1 sky (no hit).
    building : (N,) int64
        Index into ``surface.buildings``, -1 for ground and sky.
    """
    d = np.asarray(directions, dtype=np.float64)
    if d.ndim == 1 and d.shape[0] == 3:
        d = d[None]
    if d.ndim != 2 or d.shape[1] != 3:
        raise InputError(f"cast_rays: directions must have shape (N, 3), got {np.shape(directions)}")
    n = len(d)
    norm = np.linalg.norm(d, axis=1, keepdims=True)
    if not np.all(np.isfinite(d)) or np.any(norm == 0):
        raise InputError("cast_rays: directions must be finite and non-zero")
    d = np.ascontiguousarray(d / norm)
    o = np.asarray(origins, dtype=np.float64)
    o = np.ascontiguousarray(np.broadcast_to(o.reshape(-1, 3) if o.size != 3 else o.reshape(1, 3), (n, 3)))
    tm = np.ascontiguousarray(np.broadcast_to(np.asarray(tmax, dtype=np.float64), (n,)))
    if not np.all(np.isfinite(o)) or np.any(~(tm > 0)):
        raise InputError("cast_rays: origins must be finite and tmax positive")
    t = np.empty(n)
    mat = np.empty(n, np.int64)
    bid = np.empty(n, np.int64)
    _cast_many(o, d, tm, surface.terr, surface.bld, surface.grid, surface.cell_max, surface.cell_bld,
               t, mat, bid)
    return t, mat, bid
