"""Procedural colour of the synthetic surface (3D value noise).

The colour of a surface point is ``base(material, building) * shade(x, y, z)``
with ``shade`` a contrast-stretched multi-octave 3D value noise: octave
lattice spacings ``texture_scale * 2**k``, ``k = 0 .. octaves-1`` (about 1 to
20 GSD with the defaults), so the texture is matchable at every scale. Ground
mixes two base colours with a slow noise; every roof and every building's
walls have their own base colour, chosen so that ground, roof and wall colours
are far apart (CIE76 ΔE*ab well above 25 between the bases). Optional, for harder scenes
(:func:`texture_params`): a lower texture contrast on chosen roofs (nearly uniform roofs), and
a repetitive grid of dark windows on the walls.

Colours are floats in [0, 1] (display RGB, no gamma handling: they *are* the
pixel values divided by 255).
"""

from __future__ import annotations

import numpy as np

from ..jit import njit, pjit, prange

GROUND = 0
ROOF = 1
WALL = 2
SKY = -1

SKY_RGB = (0.62, 0.76, 0.92)

GROUND_RGB = ((0.30, 0.50, 0.20), (0.55, 0.45, 0.30))
ROOF_RGB = (
    (0.78, 0.26, 0.18),  # terracotta
    (0.24, 0.34, 0.70),  # slate blue
    (0.90, 0.58, 0.10),  # orange
    (0.58, 0.22, 0.62),  # purple
    (0.15, 0.62, 0.70),  # teal
    (0.85, 0.20, 0.45),  # raspberry
)
WALL_RGB = (
    (0.93, 0.90, 0.80),  # cream
    (0.86, 0.86, 0.92),  # light grey-blue
    (0.95, 0.84, 0.84),  # pale pink
    (0.90, 0.93, 0.78),  # pale yellow-green
)


def palette(n_buildings: int) -> np.ndarray:
    """Base colours, shape ``(2 + 2 n, 3)`` float64.

    Rows 0 and 1: ground; row ``2 + 2 b``: roof of building ``b``; row
    ``3 + 2 b``: its walls.
    """
    pal = np.zeros((2 + 2 * n_buildings, 3))
    pal[0], pal[1] = GROUND_RGB
    for b in range(n_buildings):
        pal[2 + 2 * b] = ROOF_RGB[b % len(ROOF_RGB)]
        pal[3 + 2 * b] = WALL_RGB[b % len(WALL_RGB)]
    return pal


def texture_params(seed: int, scale: float, octaves: int, contrast: float, windows: bool = False,
                   roof_contrast=(), crop_share: float = 0.0, crop_height: float = 0.0) -> np.ndarray:
    """Packed texture parameters for the kernels.

    ``[seed, scale, octaves, contrast, windows, crop_share, crop_height, c_0, ..., c_{n-1}]``:
    ``windows`` (0/1) puts a repetitive grid of dark windows on every wall; ``crop_share`` of the
    ground is fields of stalks ``crop_height`` metres tall (see :func:`_colour`); ``c_b`` scales
    the texture contrast of the roof of building ``b`` (1 when absent: a contrast near 0 is a
    nearly uniform roof).
    """
    rc = [float(v) for v in roof_contrast]
    head = [float(seed), float(scale), float(octaves), float(contrast), float(bool(windows))]
    return np.array(head + [float(crop_share), float(crop_height)] + rc)


#: Index in :func:`texture_params` of the first roof's contrast factor.
_ROOF0 = 7
#: Side (metres) of the lattice of the noise that lays the fields out on the ground.
CROP_PATCH = 25.0
#: Heights at which :func:`_colour` looks for a stalk on a ray through a field's stalk layer.
CROP_SLICES = 6
#: Level of the stalk noise above which a point of the ground holds a stalk (about a fifth of it).
_STALK_LEVEL = 0.62


# ---------------------------------------------------------------- kernels


@njit
def _hash01(ix, iy, iz, seed):
    h = ((ix * 73856093) ^ (iy * 19349663) ^ (iz * 83492791) ^ (seed * 2654435761)) & 0xFFFFFFFF
    h = (((h >> 15) ^ h) * 0x2C1B3C6D) & 0xFFFFFFFF
    h = (h >> 12) ^ h
    return (h & 0xFFFFFF) / 16777215.0


@njit
def _fade(t):
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


@njit
def _value_noise(x, y, z, seed):
    """Smooth value noise in [0, 1] on the unit lattice."""
    fx = np.floor(x)
    fy = np.floor(y)
    fz = np.floor(z)
    ix = np.int64(fx)
    iy = np.int64(fy)
    iz = np.int64(fz)
    u = _fade(x - fx)
    v = _fade(y - fy)
    w = _fade(z - fz)
    c000 = _hash01(ix, iy, iz, seed)
    c100 = _hash01(ix + 1, iy, iz, seed)
    c010 = _hash01(ix, iy + 1, iz, seed)
    c110 = _hash01(ix + 1, iy + 1, iz, seed)
    c001 = _hash01(ix, iy, iz + 1, seed)
    c101 = _hash01(ix + 1, iy, iz + 1, seed)
    c011 = _hash01(ix, iy + 1, iz + 1, seed)
    c111 = _hash01(ix + 1, iy + 1, iz + 1, seed)
    a = c000 + u * (c100 - c000)
    b = c010 + u * (c110 - c010)
    c = c001 + u * (c101 - c001)
    d = c011 + u * (c111 - c011)
    e = a + v * (b - a)
    f = c + v * (d - c)
    return e + w * (f - e)


@njit
def _fbm(x, y, z, seed, scale, octaves):
    """Multi-octave noise in [0, 1]; finest lattice spacing ``scale``."""
    total = 0.0
    norm = 0.0
    amp = 1.0
    s = scale * 2.0 ** (octaves - 1)
    for k in range(octaves):
        total += amp * _value_noise(x / s, y / s, z / s, seed + 101 * k)
        norm += amp
        amp *= 0.8
        s *= 0.5
    return total / norm


@njit
def _field(x, y, seed, share):
    """Whether the ground point (x, y) lies in a field (``share`` of the ground, in patches)."""
    if share <= 0.0:
        return False
    return _value_noise(x / CROP_PATCH, y / CROP_PATCH, 0.0, seed + 17) < share


@pjit
def _field_many(xy, seed, share, out):
    for i in prange(xy.shape[0]):
        out[i] = _field(xy[i, 0], xy[i, 1], seed, share)


def field_mask(xy, seed: int, share: float) -> np.ndarray:
    """(N,) bool: which local ground points ``xy`` (N, 2) lie in a crop field (:func:`_field`) of a
    scene with texture seed ``seed`` and ``crop_share`` ``share``."""
    from ..errors import InputError

    p = np.ascontiguousarray(xy, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 2:
        raise InputError(f"field_mask: expected (N, 2) points, got shape {p.shape}")
    if not (0.0 <= float(share) <= 1.0):
        raise InputError(f"field_mask: share must lie in [0, 1], got {share!r}")
    out = np.zeros(len(p), np.bool_)
    _field_many(p, np.int64(seed), float(share), out)
    return out


@njit
def _straw(pal, shade):
    """The second ground colour (straw, soil) at ``shade``."""
    return min(pal[1, 0] * shade, 1.0), min(pal[1, 1] * shade, 1.0), min(pal[1, 2] * shade, 1.0)


@njit
def _colour(x, y, z, mat, b, pal, tex, vx=0.0, vy=0.0):
    """RGB in [0, 1] of the surface point (x, y, z) of material ``mat`` (building ``b``), seen along
    a ray that moves ``(vx, vy)`` horizontally per metre it rises towards the camera (0, 0 from
    straight above).

    In a field (:func:`_field`) the soil is nearly uniform and carries vertical stalks of up to
    ``crop_height``: clumps a texture lattice spacing wide on about a fifth of the ground, each of
    its own height. The ray is followed down through the stalk layer (:data:`CROP_SLICES` heights,
    ``crop_height (vx, vy)`` of horizontal travel in all) and shows the first stalk it meets, darker
    the lower it is hit, else the soil. A photo from straight above sees the stalks' tops, an
    oblique one their sides at other heights and other places: as on a real stubble or crop field,
    the photos do not see one surface.
    """
    seed = np.int64(tex[0])
    if mat == 0 and tex.shape[0] >= _ROOF0 and _field(x, y, seed, tex[5]):
        h = tex[6]
        s = tex[1]
        for k in range(CROP_SLICES):
            hk = h * (1.0 - (k + 0.5) / CROP_SLICES)
            xt = x + hk * vx
            yt = y + hk * vy
            if _value_noise(xt / s, yt / s, 0.0, seed + 23) > _STALK_LEVEL:
                top = h * _value_noise(xt / s, yt / s, 0.0, seed + 29)
                if top >= hk:
                    grain = _value_noise(xt / s, yt / s, 0.0, seed + 31)
                    shade = (0.84 + 0.08 * hk / max(h, 1e-9)) * (0.97 + 0.06 * grain)
                    return _straw(pal, shade)
        return _straw(pal, 0.8 + 0.06 * _fbm(x, y, z, seed, s, np.int64(tex[2])))
    n = _fbm(x, y, z, seed + 37 * mat, tex[1], np.int64(tex[2]))
    contrast = tex[3]
    if mat == 1 and tex.shape[0] > _ROOF0 + b:
        contrast *= tex[_ROOF0 + b]
    v = 0.5 + contrast * (n - 0.5)
    v = min(max(v, 0.0), 1.0)
    shade = 0.45 + 0.9 * v
    if mat == 2 and tex.shape[0] > 4 and tex[4] > 0.5:
        # storeys of 3 m and a window every 2.4 m along the wall (x + y runs along any wall
        # not at 135 degrees); windows are dark and nearly uniform: a repetitive facade
        fz = z / 3.0 - np.floor(z / 3.0)
        fs = (x + y) / 2.4 - np.floor((x + y) / 2.4)
        if 0.35 < fz < 0.8 and 0.3 < fs < 0.75:
            shade = 0.25 + 0.1 * v
    if mat == 0:
        m = _value_noise(x / 9.0, y / 9.0, z / 9.0, seed + 5)
        m = min(max(2.0 * m - 0.5, 0.0), 1.0)
        r = (1.0 - m) * pal[0, 0] + m * pal[1, 0]
        g = (1.0 - m) * pal[0, 1] + m * pal[1, 1]
        bl = (1.0 - m) * pal[0, 2] + m * pal[1, 2]
    else:
        row = 2 + 2 * b + (1 if mat == 2 else 0)
        r = pal[row, 0]
        g = pal[row, 1]
        bl = pal[row, 2]
    return min(r * shade, 1.0), min(g * shade, 1.0), min(bl * shade, 1.0)


@pjit
def _colour_many(pts, mat, bid, pal, tex):
    n = pts.shape[0]
    out = np.empty((n, 3))
    for i in prange(n):
        r, g, b = _colour(pts[i, 0], pts[i, 1], pts[i, 2], mat[i], bid[i], pal, tex)
        out[i, 0] = r
        out[i, 1] = g
        out[i, 2] = b
    return out


def srgb_to_lab(rgb) -> np.ndarray:
    """CIE L*a*b* (D65) of sRGB colours in [0, 1], shape (..., 3) -> (..., 3).

    For ΔE*ab (CIE76) checks: ``np.linalg.norm(lab1 - lab2, axis=-1)``.
    """
    c = np.clip(np.asarray(rgb, dtype=np.float64), 0.0, 1.0)
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    M = np.array([[0.4124564, 0.3575761, 0.1804375],
                  [0.2126729, 0.7151522, 0.0721750],
                  [0.0193339, 0.1191920, 0.9503041]])
    xyz = lin @ M.T / np.array([0.95047, 1.0, 1.08883])
    f = np.where(xyz > (6 / 29) ** 3, np.cbrt(xyz), xyz / (3 * (6 / 29) ** 2) + 4 / 29)
    L = 116 * f[..., 1] - 16
    a = 500 * (f[..., 0] - f[..., 1])
    b = 200 * (f[..., 1] - f[..., 2])
    return np.stack([L, a, b], axis=-1)
