"""Radiometric correction between images before mosaicking.

Model
-----
Every image ``i`` gets a gain and an offset per channel, ``y = g_ic * x + o_ic``,
applied to its samples before they enter the mosaic:

* RGB data (3 or 4 bands, the first three taken as sRGB-encoded red, green,
  blue scaled to [0, 1] by the dtype's maximum; float data as given): two stages.
  First a gain and an offset per colour channel on the values as stored
  (``rgb_gain``, ``rgb_offset``, in the data's units): a camera's white balance and
  exposure scale each channel separately (in linear light, which the sRGB curve keeps
  a gain per channel, close enough), and its black level shifts it. Then a gain and
  an offset per channel of CIE L*a*b* (D65) on the result, so lightness and the two
  chroma axes are matched separately and perceptually evenly (:func:`rgb_to_lab`,
  :func:`lab_to_rgb`): what differs in tone rather than per channel. An L*a*b* model
  alone cannot undo a white balance: a channel's gain moves a* and b* by an amount
  that grows with the lightness (``a* = 500 (f(X) - f(Y))``), which no offset of a*
  matches over dark and bright surfaces at once. A 4th band (alpha or NIR) is
  corrected per band like non-RGB data, in the second stage.
* any other band count (panchromatic, thermal, multispectral): the equivalent
  per-band linear model in the data's own units (one stage).

Vignetting (:func:`estimate_vignetting`): before the gains and offsets, a radial
fall-off per camera, ``V(rho) = exp(c1 rho^2 + c2 rho^4)`` with ``rho`` the distance from the
principal point over the half diagonal, applied in linear light (sRGB decoded; other data as
given): a sample is divided by ``V``. It is estimated from the same cells: for every pair of
observations of a cell, ``log Y_a - log Y_b = u_a - u_b + log V_A(rho_a) - log V_B(rho_b)``
(``Y`` linear luminance, ``u`` a log exposure per image, ``A``/``B`` the cameras), solved by
Huber-reweighted least squares; a camera whose fit is poorly determined (its observations span
too few radii) or implausible (``V`` at the corner outside [0.3, 1.15]) keeps ``V = 1``.

Estimation (:func:`estimate_corrections`; both stages: :func:`estimate_colour_model`)
------------------------------------------------------------------------------------
Each stage the same way, the second on the samples the first corrected. From cells seen by several
images: for every pair of images, the robust moments (median, half the 16-84 % spread) of both
images over the cells they share. Gains equalise the spreads (``log g_a - log g_b = log s_b - log
s_a``), offsets then the medians, each solved by least squares over the image pairs (weight the
square root of the shared cells, Huber-reweighted, so a pair spoilt by occlusions or moving objects
does not bias the fit); the level of the whole block is fixed by mean gain 1 and mean offset 0, and
a weak prior towards the identity keeps images without overlap determined. Matching moments instead
of regressing one image's samples on another's keeps the gains unbiased when the samples of a cell
correlate weakly between images (fine cells, vegetation), where regression shrinks them (see
:func:`_moment_match`). The result reports the RMS disagreement between images before and after.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..jit import njit, pjit, prange
from ..quickselect import select_rank

_M = np.array(
    [[0.4124564, 0.3575761, 0.1804375], [0.2126729, 0.7151522, 0.0721750], [0.0193339, 0.1191920, 0.9503041]]
)
_M_INV = np.linalg.inv(_M)
_WHITE = np.array([0.95047, 1.0, 1.08883])
_D = 6.0 / 29.0


def _srgb_decode(c: np.ndarray) -> np.ndarray:
    """Linear light of sRGB-encoded values in [0, 1] (the sRGB transfer function's inverse)."""
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def _srgb_encode(lin: np.ndarray) -> np.ndarray:
    """sRGB-encoded values of linear light (non-negative)."""
    return np.where(lin <= 0.0031308, 12.92 * lin, 1.055 * lin ** (1 / 2.4) - 0.055)


def rgb_to_lab(rgb) -> np.ndarray:
    """CIE L*a*b* (D65) of sRGB colours in [0, 1], (..., 3) -> (..., 3) float64."""
    lin = _srgb_decode(np.clip(np.asarray(rgb, dtype=np.float64), 0.0, 1.0))
    xyz = lin @ _M.T / _WHITE
    f = np.where(xyz > _D**3, np.cbrt(xyz), xyz / (3 * _D**2) + 4.0 / 29.0)
    return np.stack(
        [116.0 * f[..., 1] - 16.0, 500.0 * (f[..., 0] - f[..., 1]), 200.0 * (f[..., 1] - f[..., 2])], axis=-1
    )


def lab_to_rgb(lab) -> np.ndarray:
    """sRGB in [0, 1] (clipped) of CIE L*a*b* (D65) colours, (..., 3) -> (..., 3) float64."""
    lab = np.asarray(lab, dtype=np.float64)
    fy = (lab[..., 0] + 16.0) / 116.0
    fx = fy + lab[..., 1] / 500.0
    fz = fy - lab[..., 2] / 200.0
    f = np.stack([fx, fy, fz], axis=-1)
    xyz = np.where(f > _D, f**3, 3 * _D**2 * (f - 4.0 / 29.0)) * _WHITE
    return _srgb_encode(np.clip(xyz @ _M_INV.T, 0.0, 1.0))


def value_scale(dtype) -> float:
    """The value that maps to 1.0 (integer dtypes: their maximum; float: 1)."""
    dt = np.dtype(dtype)
    return float(np.iinfo(dt).max) if dt.kind in "ui" else 1.0


def value_range(dtype) -> tuple[float, float]:
    """The values a dtype holds: its limits for integer dtypes, unbounded for float."""
    dt = np.dtype(dtype)
    return (float(np.iinfo(dt).min), float(np.iinfo(dt).max)) if dt.kind in "ui" else (-np.inf, np.inf)


def uses_lab(bands: int) -> bool:
    """Whether data of ``bands`` bands is corrected in L*a*b* (RGB, RGB + one extra band)."""
    return bands in (3, 4)


def to_channels(samples: np.ndarray, dtype) -> np.ndarray:
    """Correction channels of samples (N, bands): L*a*b* (+ extra bands) or the values themselves."""
    s = np.asarray(samples, dtype=np.float64)
    if uses_lab(s.shape[1]):
        lab = rgb_to_lab(s[:, :3] / value_scale(dtype))
        return np.concatenate([lab, s[:, 3:]], axis=1)
    return s


def from_channels(channels: np.ndarray, dtype) -> np.ndarray:
    """Inverse of :func:`to_channels` (float64, not yet clipped to the dtype's range for non-RGB)."""
    c = np.asarray(channels, dtype=np.float64)
    if uses_lab(c.shape[1]):
        rgb = lab_to_rgb(c[:, :3]) * value_scale(dtype)
        return np.concatenate([rgb, c[:, 3:]], axis=1)
    return c


@dataclass
class ColorCorrection:
    """Per-image, per-channel ``gain`` and ``offset`` (channels of :func:`to_channels`), after an
    optional first stage per RGB channel (module docstring).

    Attributes
    ----------
    gain, offset : (n_images, channels) float64
    lab : bool
        Channels 0-2 are L*a*b*.
    rgb_gain, rgb_offset : (n_images, 3) float64 or None
        The first stage: gain and offset of the first three bands as stored (data units),
        applied before ``gain`` and ``offset``.
    stats : dict
        ``observations``, ``pairs``, ``rms_before``, ``rms_after``, ``median_before``,
        ``median_after`` (absolute pair disagreement, channel units), ``images_constrained``.
    """

    gain: np.ndarray
    offset: np.ndarray
    lab: bool
    stats: dict = field(default_factory=dict)
    #: (n_images, 2) ``c1, c2`` of the vignetting (module docstring), or None.
    vignetting: np.ndarray | None = None
    #: (n_images, 2) principal point (full-resolution pixels) and (n_images,) 1 / half diagonal.
    centre: np.ndarray | None = None
    inv_norm: np.ndarray | None = None
    rgb_gain: np.ndarray | None = None
    rgb_offset: np.ndarray | None = None

    @classmethod
    def identity(cls, n_images: int, bands: int) -> ColorCorrection:
        return cls(np.ones((n_images, bands)), np.zeros((n_images, bands)), uses_lab(bands), {})

    def has_vignetting(self, i: int) -> bool:
        return self.vignetting is not None and bool(np.any(self.vignetting[i] != 0.0))

    def has_rgb_stage(self, i: int) -> bool:
        return (
            self.rgb_gain is not None
            and self.rgb_offset is not None
            and bool(np.any(self.rgb_gain[i] != 1.0) or np.any(self.rgb_offset[i] != 0.0))
        )

    def is_identity(self, i: int) -> bool:
        return (
            bool(np.all(self.gain[i] == 1.0) and np.all(self.offset[i] == 0.0))
            and not self.has_vignetting(i)
            and not self.has_rgb_stage(i)
        )

    def _rgb_stage(self, i: int, bands: int) -> tuple[np.ndarray, np.ndarray]:
        """The first stage as per-band arrays over ``bands`` (identity beyond the first three)."""
        assert self.rgb_gain is not None and self.rgb_offset is not None
        g, o = np.ones(bands), np.zeros(bands)
        g[:3], o[:3] = self.rgb_gain[i], self.rgb_offset[i]
        return g, o

    def apply(self, i: int, samples: np.ndarray, dtype) -> np.ndarray:
        """Corrected samples (N, bands) of image ``i`` in the data's dtype range (float64)."""
        s = np.asarray(samples, dtype=np.float64)
        if self.is_identity(i) or len(s) == 0:
            return s
        dt = np.dtype(dtype)
        lo, hi = value_range(dt)
        if self.has_rgb_stage(i) and uses_lab(s.shape[1]):
            g, o = self._rgb_stage(i, s.shape[1])
            s = np.clip(s * g + o, lo, hi)
        ch = to_channels(s, dtype) * self.gain[i] + self.offset[i]
        return np.clip(from_channels(ch, dtype), lo, hi)

    def apply_inplace(self, i: int, colours: np.ndarray, mask: np.ndarray, dtype, uv=None) -> None:
        """:meth:`apply` to the samples ``colours`` (..., bands) float32 of image ``i`` where ``mask``
        (the leading shape of ``colours``), in place, in one compiled pass; with ``uv`` (..., 2), the
        samples' full-resolution pixel positions, the vignetting is removed first."""
        if self.is_identity(i):
            return
        if colours.dtype != np.float32 or not colours.flags.c_contiguous or mask.shape != colours.shape[:-1]:
            raise InputError("apply_inplace: colours must be C-contiguous float32 (..., bands) like the mask")
        dt = np.dtype(dtype)
        lo, hi = value_range(dt)
        if uv is not None and self.has_vignetting(i):
            uv = np.asarray(uv)
            if uv.shape != mask.shape + (2,):
                raise InputError("apply_inplace: uv must be (..., 2) like the mask")
            assert self.centre is not None and self.inv_norm is not None and self.vignetting is not None
            _devignette(
                colours.reshape(-1, colours.shape[-1]),
                np.ascontiguousarray(mask).reshape(-1),
                np.ascontiguousarray(uv).reshape(-1, 2),  # float32 views as is: no copy per tile
                float(self.centre[i, 0]),
                float(self.centre[i, 1]),
                float(self.inv_norm[i]),
                float(self.vignetting[i, 0]),
                float(self.vignetting[i, 1]),
                uses_lab(colours.shape[-1]),
                value_scale(dt),
                lo,
                hi,
                _LUTS,
                _LUT_N,
                _LUT_TOP,
            )
        flat = colours.reshape(-1, colours.shape[-1])
        m = np.ascontiguousarray(mask).reshape(-1)

        def stage(gain, offset, lab: bool) -> None:
            g, o = np.ascontiguousarray(gain, np.float64), np.ascontiguousarray(offset, np.float64)
            _correct(flat, m, g, o, lab, value_scale(dt), lo, hi, _M, _M_INV, _WHITE, _LUTS, _LUT_N, _LUT_TOP)

        if self.has_rgb_stage(i) and uses_lab(colours.shape[-1]):
            stage(*self._rgb_stage(i, colours.shape[-1]), False)
        if np.all(self.gain[i] == 1.0) and np.all(self.offset[i] == 0.0):
            return
        stage(self.gain[i], self.offset[i], bool(self.lab and uses_lab(colours.shape[-1])))

    def as_dict(self, names: list[str] | None = None) -> dict:
        rows: list[dict] = []
        rgb = self.rgb_gain is not None and self.rgb_offset is not None
        for i in range(len(self.gain)):
            row: dict = {"image": names[i] if names else i}
            if rgb:
                assert self.rgb_gain is not None and self.rgb_offset is not None
                row["rgb_gain"] = [round(float(v), 5) for v in self.rgb_gain[i]]
                row["rgb_offset"] = [round(float(v), 5) for v in self.rgb_offset[i]]
            row["gain"] = [round(float(v), 5) for v in self.gain[i]]
            row["offset"] = [round(float(v), 5) for v in self.offset[i]]
            rows.append(row)
        model = "L*a*b* gain/offset" if self.lab else "per-band gain/offset"
        out = {
            "model": f"per-channel RGB gain/offset, then {model}" if rgb else model,
            "images": rows,
            **self.stats,
        }
        if self.vignetting is not None:
            corner = np.exp(self.vignetting[:, 0] + self.vignetting[:, 1])
            for k, row in enumerate(rows):
                row["vignetting_at_corner"] = round(float(corner[k]), 4)
        return out


@njit
def _lab_f(t):
    d = 6.0 / 29.0
    return t ** (1.0 / 3.0) if t > d * d * d else t / (3.0 * d * d) + 4.0 / 29.0


@njit
def _lab_finv(f):
    d = 6.0 / 29.0
    return f * f * f if f > d else 3.0 * d * d * (f - 4.0 / 29.0)


#: Tables of the sRGB transfer functions and the L*a*b* cube root on [0, _LUT_TOP] (8192 steps),
#: interpolated linearly by :func:`_correct` (error about 1e-5 of the unit range, 1e-3 dE).
_LUT_N = 8192
_LUT_TOP = 1.0625
_LUT_X = np.linspace(0.0, _LUT_TOP, _LUT_N + 1)
_LUT_DEC = _srgb_decode(_LUT_X)
_LUT_ENC = _srgb_encode(_LUT_X)
_LUT_F = np.where(_LUT_X > _D**3, np.cbrt(_LUT_X), _LUT_X / (3 * _D**2) + 4.0 / 29.0)
_LUTS = np.ascontiguousarray(np.stack([_LUT_DEC, _LUT_ENC, _LUT_F]))


@njit
def _lut(luts, k, x, n, top):
    """Table ``k`` of :data:`_LUTS` at ``x`` in [0, top] (linear interpolation)."""
    t = x * (n / top)
    i = min(max(np.int64(t), 0), n - 1)
    w = t - i
    return luts[k, i] + w * (luts[k, i + 1] - luts[k, i])


@njit
def _correct(c, m, gain, offset, lab, scale, lo, hi, M, M_inv, white, luts, n_lut, top):
    """Samples ``c`` (n, bands) float32 where ``m``: the channels of :func:`to_channels` times ``gain``
    plus ``offset``, back through :func:`from_channels`, clipped to ``[lo, hi]``, in place."""
    n, B = c.shape
    lin = np.empty(3)
    f = np.empty(3)
    for p in range(n):
        if not m[p]:
            continue
        start = 0
        if lab:
            for q in range(3):
                lin[q] = _lut(luts, 0, min(max(np.float64(c[p, q]) / scale, 0.0), 1.0), n_lut, top)
            for q in range(3):
                t = (M[q, 0] * lin[0] + M[q, 1] * lin[1] + M[q, 2] * lin[2]) / white[q]
                f[q] = _lut(luts, 2, t, n_lut, top) if t <= top else _lab_f(t)
            L = (116.0 * f[1] - 16.0) * gain[0] + offset[0]
            A = 500.0 * (f[0] - f[1]) * gain[1] + offset[1]
            Bb = 200.0 * (f[1] - f[2]) * gain[2] + offset[2]
            fy = (L + 16.0) / 116.0
            f[0] = _lab_finv(fy + A / 500.0) * white[0]
            f[1] = _lab_finv(fy) * white[1]
            f[2] = _lab_finv(fy - Bb / 200.0) * white[2]
            for q in range(3):
                v = min(max(M_inv[q, 0] * f[0] + M_inv[q, 1] * f[1] + M_inv[q, 2] * f[2], 0.0), 1.0)
                c[p, q] = min(max(_lut(luts, 1, v, n_lut, top) * scale, lo), hi)
            start = 3
        for q in range(start, B):
            c[p, q] = min(max(np.float64(c[p, q]) * gain[q] + offset[q], lo), hi)


@njit
def _devignette(c, m, uv, cx, cy, inv_norm, c1, c2, rgb, scale, lo, hi, luts, n_lut, top):
    """Samples ``c`` (n, bands) float32 where ``m``, seen at pixels ``uv`` (n, 2): divided by the
    vignetting ``exp(c1 rho^2 + c2 rho^4)`` in linear light (sRGB decoded for the first three bands
    when ``rgb``), clipped to ``[lo, hi]``, in place."""
    n, B = c.shape
    for p in range(n):
        if not m[p]:
            continue
        du = (uv[p, 0] - cx) * inv_norm
        dv = (uv[p, 1] - cy) * inv_norm
        r2 = du * du + dv * dv
        if not r2 == r2:
            continue
        g = math.exp(-(c1 * r2 + c2 * r2 * r2))
        start = 0
        if rgb:
            for q in range(3):
                lin = _lut(luts, 0, min(max(np.float64(c[p, q]) / scale, 0.0), 1.0), n_lut, top) * g
                c[p, q] = min(max(_lut(luts, 1, min(lin, top), n_lut, top) * scale, lo), hi)
            start = 3
        for q in range(start, B):
            c[p, q] = min(max(np.float64(c[p, q]) * g, lo), hi)


def linear_luminance(values: np.ndarray, dtype) -> np.ndarray:
    """Linear-light luminance (K,) of samples (K, bands) in the data's units: Rec. 709 weights of
    the sRGB-decoded first three bands of RGB data, the first band (taken as linear) otherwise."""
    v = np.asarray(values, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] < 1:
        raise InputError(f"linear_luminance: samples must be (K, bands), got shape {v.shape}")
    if uses_lab(v.shape[1]):
        lin = _srgb_decode(np.clip(v[:, :3] / value_scale(dtype), 0.0, 1.0))
        return lin @ np.array([0.2126, 0.7152, 0.0722])
    return v[:, 0] / value_scale(dtype)


def devignette_values(values: np.ndarray, factor: np.ndarray, dtype) -> np.ndarray:
    """Samples (K, bands) divided by the vignetting ``factor`` (K,) in linear light (as
    :func:`_devignette`), in the data's units (float64)."""
    v = np.array(values, dtype=np.float64)
    f = np.asarray(factor, dtype=np.float64)
    if v.ndim != 2 or f.shape != (len(v),) or not np.all(f > 0):
        raise InputError(
            "devignette_values: expected samples (K, bands) and K positive factors, "
            f"got {v.shape} and {f.shape}"
        )
    start = 0
    if uses_lab(v.shape[1]):
        sc = value_scale(dtype)
        lin = _srgb_decode(np.clip(v[:, :3] / sc, 0.0, 1.0)) / f[:, None]
        v[:, :3] = _srgb_encode(np.clip(lin, 0.0, None)) * sc
        start = 3
    v[:, start:] /= f[:, None]
    return v


def estimate_vignetting(
    obs_cell,
    obs_image,
    obs_lum,
    obs_rho2,
    image_camera,
    max_pairs: int = 400_000,
    seed: int = 0,
    huber: float = 1.5,
    iterations: int = 5,
    lum_range: tuple[float, float] = (0.005, 0.85),
    min_pairs: int = 500,
    corner_range: tuple[float, float] = (0.3, 1.15),
) -> tuple[np.ndarray, dict]:
    """Vignetting per camera from observations of the same cells (module docstring).

    Parameters
    ----------
    obs_cell, obs_image : (K,) int
    obs_lum : (K,) float, linear luminance (:func:`linear_luminance`); observations outside
        ``lum_range`` (near black, near saturation) are not used
    obs_rho2 : (K,) float, squared distance from the principal point over the half diagonal
    image_camera : (n_images,) int, camera index of every image

    Returns
    -------
    (coefficients (n_images, 2): ``c1, c2`` of each image's camera, stats dict)
    """
    cell = np.asarray(obs_cell, dtype=np.int64).reshape(-1)
    img = np.asarray(obs_image, dtype=np.int64).reshape(-1)
    lum = np.asarray(obs_lum, dtype=np.float64).reshape(-1)
    rho2 = np.asarray(obs_rho2, dtype=np.float64).reshape(-1)
    cam_of = np.asarray(image_camera, dtype=np.int64).reshape(-1)
    n = len(cam_of)
    if not (len(img) == len(cell) == len(lum) == len(rho2)):
        raise InputError("estimate_vignetting: observation arrays differ in length")
    if len(img) and (img.min() < 0 or img.max() >= n):
        raise InputError("estimate_vignetting: image index out of range")
    if n and cam_of.min() < 0:
        raise InputError("estimate_vignetting: image_camera holds a negative camera index")
    n_cam = int(cam_of.max()) + 1 if n else 0
    coef = np.zeros((n, 2))
    stats: dict = {"cameras": {}}
    ok = np.isfinite(lum) & np.isfinite(rho2) & (lum > lum_range[0]) & (lum < lum_range[1])
    idx = np.flatnonzero(ok)
    ii, jj = _pairs(cell[idx], max_pairs, seed)
    ii, jj = idx[ii], idx[jj]
    keep = img[ii] != img[jj]
    ii, jj = ii[keep], jj[keep]
    stats["pairs"] = int(len(ii))
    if len(ii) < min_pairs or n_cam == 0:
        return coef, stats
    ia, ib = img[ii], img[jj]
    d = np.log(lum[ii]) - np.log(lum[jj])
    # unknowns: u (n images), then c1, c2 per camera
    import scipy.sparse as sp

    nu = n + 2 * n_cam
    m = len(ii)
    ca, cb = cam_of[ia], cam_of[ib]
    # six entries per pair (sparse: the normal matrix is only images + 2 cameras square)
    cols = np.column_stack([ia, ib, n + 2 * ca, n + 2 * ca + 1, n + 2 * cb, n + 2 * cb + 1])
    vals = np.column_stack([np.ones(m), -np.ones(m), rho2[ii], rho2[ii] ** 2, -rho2[jj], -(rho2[jj] ** 2)])
    A = sp.csr_matrix((vals.ravel(), (np.repeat(np.arange(m), 6), cols.ravel())), shape=(m, nu))
    w = np.ones(m)
    ridge = np.full(nu, 1e-6 * m)
    ridge[:n] = 1e-3  # u: only their sum is fixed, by this pull to 0
    x = np.zeros(nu)
    r = d
    for _ in range(int(iterations)):
        N = (A.T @ A.multiply(w[:, None])).toarray() + np.diag(ridge)
        x = np.linalg.solve(N, A.T @ (w * d))
        r = d - A @ x
        s = 1.4826 * np.median(np.abs(r)) + 1e-12
        t = huber * s
        w = np.where(np.abs(r) <= t, 1.0, t / np.maximum(np.abs(r), 1e-300))
    # precision of each camera's corner value from the weighted normal matrix
    N = (A.T @ A.multiply(w[:, None])).toarray() + np.diag(ridge)
    cov = np.linalg.inv(N) * (float(np.sum(w * r * r)) / max(len(r) - nu, 1))
    for c in range(n_cam):
        c1, c2 = float(x[n + 2 * c]), float(x[n + 2 * c + 1])
        e = np.zeros(nu)
        e[n + 2 * c] = e[n + 2 * c + 1] = 1.0
        sd = math.sqrt(max(float(e @ cov @ e), 0.0))
        corner = math.exp(c1 + c2)
        used = bool(corner_range[0] <= corner <= corner_range[1] and sd < 0.05 and np.any(cam_of[ia] == c))
        stats["cameras"][c] = {
            "corner_factor": round(corner, 4),
            "corner_sd": round(sd, 4),
            "used": used,
        }
        if used:
            coef[cam_of == c] = (c1, c2)
    return coef, stats


def estimate_corrections(
    obs_cell,
    obs_image,
    obs_values,
    n_images: int,
    prior: float = 1e-3,
    huber: float = 1.5,
    iterations: int = 4,
    max_pairs: int = 4_000_000,
    seed: int = 0,
    min_pair: int = 30,
    per_pair: int = 2_000,
    budget: int = 400_000,
    values_before=None,
) -> ColorCorrection:
    """Least-squares gains and offsets from multiply observed cells.

    Parameters
    ----------
    obs_cell : (K,) int
        Cell id of each observation (any integer labels).
    obs_image : (K,) int
        Image index in ``[0, n_images)``.
    obs_values : (K, channels) float64
        Channel values (:func:`to_channels`).
    n_images : int
    prior : float
        Weight of the pull towards the identity relative to one pair residual.
    huber : float
        Huber threshold in robust standard deviations (MAD of the residuals).
    max_pairs : int
        Bound of the observation pairs enumerated (memory); beyond it they are subsampled
        (seeded) before the per-image-pair thinning.
    min_pair : int
        Common observations an image pair needs to enter the estimate.
    per_pair : int
        At most this many observation pairs per image pair, evenly spaced in cell order (so
        spread over the overlap): the robust moments of a pair need no more (their standard
        error is ~3 % of the spread at 2,000). 0: no bound.
    budget : int
        About this many observation pairs in all: an image pair keeps at most ``budget / image
        pairs`` of them (between 250 and ``per_pair``), so the cost stays bounded as blocks grow
        while every image pair keeps its evidence (a global random draw would leave some pairs
        of a large block with few samples). 0: no budget.

    Returns
    -------
    ColorCorrection
    """
    cell = np.asarray(obs_cell, dtype=np.int64).reshape(-1)
    img = np.asarray(obs_image, dtype=np.int64).reshape(-1)
    val = np.asarray(obs_values, dtype=np.float64)
    if val.ndim != 2 or len(val) != len(cell) or len(img) != len(cell):
        raise InputError("estimate_corrections: observations must be (K,), (K,) and (K, channels)")
    ref = val if values_before is None else np.asarray(values_before, dtype=np.float64)
    if ref.shape != val.shape:
        raise InputError("estimate_corrections: values_before must be shaped like the observations")
    nch = val.shape[1]
    n = int(n_images)
    for name, v in (("max_pairs", max_pairs), ("per_pair", per_pair), ("budget", budget)):
        if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < 0:
            raise InputError(f"estimate_corrections: {name} must be a non-negative integer, got {v!r}")
    if len(img) and (img.min() < 0 or img.max() >= n):
        raise InputError("estimate_corrections: image index out of range")
    ii, jj = _pairs(cell, max_pairs, seed)
    gain = np.ones((n, nch))
    offset = np.zeros((n, nch))
    stats: dict = {"observations": int(len(cell)), "pairs": int(len(ii))}
    if len(ii) == 0:
        stats.update(rms_before=None, rms_after=None, images_constrained=0)
        return ColorCorrection(gain, offset, uses_lab(nch), stats)
    ia, ib = img[ii], img[jj]
    keep = ia != ib
    ii, jj, ia, ib = ii[keep], jj[keep], ia[keep], ib[keep]
    # orient every pair (lower image index first) so that image pairs can be grouped
    swap = ia > ib
    ii, jj = np.where(swap, jj, ii), np.where(swap, ii, jj)
    ia, ib = img[ii], img[jj]
    stats["pairs"] = int(len(ii))
    stats["images_constrained"] = int(np.count_nonzero(np.bincount(np.concatenate([ia, ib]), minlength=n)))
    pair_id = ia * n + ib
    upairs, inverse, counts, order = _group_ids(pair_id, n * n)
    cap = int(per_pair) if per_pair > 0 else len(ii)
    if budget > 0 and len(counts):
        cap = min(cap, max(int(budget) // len(counts), 250))
    stats["per_image_pair"] = cap
    if cap > 0 and counts.max() > cap:
        sub = _thin_groups(counts, order, cap)
        ii, jj, ia, ib = ii[sub], jj[sub], ia[sub], ib[sub]
        upairs, inverse, counts, order = _group_ids(ia * n + ib, n * n)
    stats["pairs_used"] = int(len(ii))
    rms_before, rms_after, mad_before, mad_after = [], [], [], []
    for ch in range(nch):
        xa, xb = val[ii, ch], val[jj, ch]
        g, o = _moment_match(
            upairs, inverse, counts, xa, xb, ia, ib, n, prior, huber, iterations, min_pair, order
        )
        gain[:, ch] = g
        offset[:, ch] = o
        ra = (ref[ii, ch] - ref[jj, ch]) ** 2
        rb = ((g[ia] * xa + o[ia]) - (g[ib] * xb + o[ib])) ** 2
        rms_before.append(float(np.sqrt(np.mean(ra))))
        rms_after.append(float(np.sqrt(np.mean(rb))))
        mad_before.append(float(np.median(np.sqrt(ra))))
        mad_after.append(float(np.median(np.sqrt(rb))))
    stats["image_pairs"] = int(np.sum(counts >= min_pair))
    stats["rms_before"] = [round(v, 4) for v in rms_before]
    stats["rms_after"] = [round(v, 4) for v in rms_after]
    stats["median_before"] = [round(v, 4) for v in mad_before]
    stats["median_after"] = [round(v, 4) for v in mad_after]
    return ColorCorrection(gain, offset, uses_lab(nch), stats)


def estimate_colour_model(
    obs_cell, obs_image, samples, n_images: int, dtype, rgb_stage: bool = True, **kwargs
) -> ColorCorrection:
    """Both stages of the model (module docstring) from multiply observed cells.

    ``samples`` (K, bands) are the observations as stored (the data's units, vignetting already
    removed). RGB data: gains and offsets per RGB channel first, then, on the samples they
    corrected, L*a*b* gains and offsets (:func:`estimate_corrections` each, with ``kwargs``); other
    data: the per-band stage alone. ``stats`` are the last stage's, with the disagreement before
    both stages (``*_before``, L*a*b*), the first stage's under ``"rgb_stage"`` (data units).
    ``rgb_stage=False``: the L*a*b* stage alone (the model before the RGB stage; for comparisons,
    ``bench/colour_models.py``).
    """
    cell = np.asarray(obs_cell, dtype=np.int64).reshape(-1)
    img = np.asarray(obs_image, dtype=np.int64).reshape(-1)
    raw = np.asarray(samples, dtype=np.float64)
    if raw.ndim != 2 or len(raw) != len(cell):
        raise InputError("estimate_colour_model: samples must be (K, bands) like the observations")
    if not uses_lab(raw.shape[1]):
        return estimate_corrections(cell, img, raw, n_images, **kwargs)
    if not rgb_stage:
        return estimate_corrections(cell, img, to_channels(raw, dtype), n_images, **kwargs)
    first = estimate_corrections(cell, img, raw[:, :3], n_images, **kwargs)
    lo, hi = value_range(dtype)
    staged = raw.copy()
    staged[:, :3] = np.clip(raw[:, :3] * first.gain[img] + first.offset[img], lo, hi)
    corr = estimate_corrections(
        cell, img, to_channels(staged, dtype), n_images, values_before=to_channels(raw, dtype), **kwargs
    )
    corr.rgb_gain, corr.rgb_offset = first.gain, first.offset
    corr.stats["rgb_stage"] = first.stats
    return corr


def _group_ids(ids: np.ndarray, id_range: int):
    """``np.unique(ids, return_inverse=True, return_counts=True)`` plus the stable order that groups
    the ids (``argsort(inverse, kind="stable")``), by counting when ``id_range`` is moderate."""
    if id_range > 16 * max(len(ids), 1 << 16):
        uniq, inverse, counts = np.unique(ids, return_inverse=True, return_counts=True)
        return uniq, inverse, counts, np.argsort(inverse, kind="stable")
    full = np.bincount(ids, minlength=id_range)
    uniq = np.flatnonzero(full)
    rank = np.zeros(id_range, np.int64)
    rank[uniq] = np.arange(len(uniq))
    inverse = rank[ids]
    counts = full[uniq]
    order = np.empty(len(ids), np.int64)
    _counting_order(inverse, counts, order)
    return uniq, inverse, counts, order


def _thin_groups(counts: np.ndarray, order: np.ndarray, m: int) -> np.ndarray:
    """Item indices (ascending) keeping at most ``m`` evenly spaced items of every group
    (``order`` lists the items grouped, each group in item order)."""
    starts = np.zeros(len(counts), np.int64)
    starts[1:] = np.cumsum(counts)[:-1]
    take = np.minimum(counts, m)
    g = np.repeat(np.arange(len(counts)), take)
    j = np.arange(int(take.sum())) - np.repeat(np.cumsum(take) - take, take)
    pos = starts[g] + ((j + 0.5) * counts[g] // take[g]).astype(np.int64)
    return np.sort(order[pos])


@njit
def _counting_order(inverse, counts, order):
    """Stable order of ``inverse`` (group of each item) by counting sort."""
    start = np.zeros(len(counts), np.int64)
    for g in range(1, len(counts)):
        start[g] = start[g - 1] + counts[g - 1]
    for i in range(len(inverse)):
        g = inverse[i]
        order[start[g]] = i
        start[g] += 1


def _robust_moments(x: np.ndarray, inverse: np.ndarray, k: int, order: np.ndarray | None = None):
    """Per group: median and robust spread (half the 16-84 % interpercentile range).

    ``order`` (optional, reused across calls): ``argsort(inverse, kind="stable")``.
    """
    if order is None:
        order = np.argsort(inverse, kind="stable")
    n = np.bincount(inverse, minlength=k).astype(np.int64)
    starts = np.zeros(k, np.int64)
    starts[1:] = np.cumsum(n)[:-1]
    out = np.zeros((k, 3))
    xs = np.ascontiguousarray(np.asarray(x, np.float64)[order])
    _group_percentiles(xs, starts, n, np.array([0.5, 0.1587, 0.8413]), out)
    return out[:, 0], 0.5 * (out[:, 2] - out[:, 1])


@pjit
def _group_percentiles(xs, starts, n, qs, out):
    """``out[g, j]``: the value of rank ``floor(qs[j] (n_g - 1))`` of group g (values grouped in xs);
    groups in parallel."""
    order = np.argsort(qs)
    for g in prange(len(starts)):
        m = n[g]
        if m <= 0:
            continue
        v = xs[starts[g] : starts[g] + m].copy()
        lo = 0
        for jj in range(len(qs)):  # ascending ranks: each selection leaves the larger values after it
            j = order[jj]
            r = min(int(np.floor(qs[j] * (m - 1))), m - 1)
            select_rank(v, lo, m - 1, r)
            out[g, j] = v[r]
            lo = r


def _moment_match(upairs, inverse, counts, xa, xb, ia, ib, n, prior, huber, iterations, min_pair, order=None):
    """Gains and offsets that equalise the robust moments of every overlapping image pair.

    ``xa``, ``xb``: the two values of every observation pair, ``ia``, ``ib`` their images
    (``ia * n + ib`` is the pair id that ``upairs[inverse]`` groups); ``order`` (optional)
    ``argsort(inverse, kind="stable")``.

    For an image pair ``(a, b)`` seen together on ``m`` cells with robust spreads
    ``s`` over those cells, the corrected images have equal spreads when
    ``g_a s_a = g_b s_b``, linear in ``log g`` (``log g_a - log g_b = log s_b -
    log s_a``); with those gains, the offsets make the median of the paired
    differences ``(g_a x_a + o_a) - (g_b x_b + o_b)`` zero. Both are solved by weighted least squares
    (weight ``sqrt(m)``, Huber-reweighted over the pairs) with the block's level
    fixed by mean ``log g = 0`` (then rescaled to mean gain 1) and mean offset 0, plus a weak pull towards the
    identity for images without overlap. Matching moments (rather than
    regressing one image's samples on another's) does not shrink gains when the
    per-cell samples of two images correlate weakly (fine cells, residual
    misregistration, vegetation): regression would pull the gains of well
    connected images towards zero and push the others up to keep the mean.
    """
    k = len(upairs)
    if order is None:
        order = np.argsort(inverse, kind="stable")
    _, sa = _robust_moments(xa, inverse, k, order)
    _, sb = _robust_moments(xb, inverse, k, order)
    ok = (counts >= min_pair) & (sa > 1e-9) & (sb > 1e-9)
    a_img, b_img = upairs // n, upairs % n
    w0 = np.sqrt(counts.astype(np.float64))
    if not ok.any():
        return np.ones(n), np.zeros(n)
    lg = _pair_solve(
        a_img[ok], b_img[ok], np.log(sb[ok]) - np.log(sa[ok]), w0[ok], n, prior, huber, iterations
    )
    g = np.exp(lg)
    g /= g.mean()  # the block's level: mean gain 1 (the ratios are what the pairs determine)
    # offsets: given the gains, the median of the paired differences of the cells (content cancels)
    dmed, _ = _robust_moments(g[ib] * xb - g[ia] * xa, inverse, k, order)
    scale = float(np.median(np.concatenate([sa[ok], sb[ok]])))
    o = _pair_solve(a_img[ok], b_img[ok], dmed[ok], w0[ok], n, prior, huber, iterations, scale)
    return g, o


def _pair_solve(a, b, d, w0, n, prior, huber, iterations, scale=1.0, target=0.0):
    """Least squares of ``u_a - u_b = d`` per pair, mean ``u`` = ``target``, weak prior ``u = target``."""
    w = w0.copy()
    u = np.full(n, target)
    for _ in range(max(1, iterations)):
        N = np.zeros((n, n))
        rhs = np.zeros(n)
        np.add.at(N, (a, a), w)
        np.add.at(N, (b, b), w)
        np.add.at(N, (a, b), -w)
        np.add.at(N, (b, a), -w)
        np.add.at(rhs, a, w * d)
        np.add.at(rhs, b, -w * d)
        lam = prior * max(float(np.sum(w)) / n, 1.0)
        N[np.diag_indices(n)] += lam
        rhs += lam * target
        big = 1e3 * max(float(np.sum(w)) / n, 1.0)
        N += big / n
        rhs += big * target
        u = _solve_spd(N, rhs)
        r = (u[a] - u[b]) - d
        t = huber * (1.4826 * float(np.median(np.abs(r))) + 1e-9 * scale)
        w = w0 * np.where(np.abs(r) <= t, 1.0, t / np.maximum(np.abs(r), 1e-300))
    return u


def _solve_spd(N: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """``N u = rhs`` for the symmetric positive definite normal matrices of :func:`_pair_solve`:
    a compiled Cholesky up to a few hundred images (LAPACK's threads, woken right after the
    parallel percentile kernel, cost milliseconds for a system of microseconds), LAPACK above."""
    if len(N) > 256:
        return np.linalg.solve(N, rhs)
    u = np.array(rhs, np.float64)
    L = np.array(N, np.float64)
    if not _cholesky_solve(L, u):
        return np.linalg.solve(N, rhs)  # not positive definite (cannot happen with the prior)
    return u


@njit
def _cholesky_solve(L, u):
    """In place: ``L`` becomes the Cholesky factor of the SPD matrix it holds (lower triangle), ``u``
    the solution of ``L L^T x = u``; False when a pivot is not positive."""
    n = L.shape[0]
    for j in range(n):
        s = L[j, j]
        for k in range(j):
            s -= L[j, k] * L[j, k]
        if not s > 0.0:
            return False
        d = np.sqrt(s)
        L[j, j] = d
        for i in range(j + 1, n):
            t = L[i, j]
            for k in range(j):
                t -= L[i, k] * L[j, k]
            L[i, j] = t / d
    for i in range(n):  # forward: L y = u
        t = u[i]
        for k in range(i):
            t -= L[i, k] * u[k]
        u[i] = t / L[i, i]
    for i in range(n - 1, -1, -1):  # back: L^T x = y
        t = u[i]
        for k in range(i + 1, n):
            t -= L[k, i] * u[k]
        u[i] = t / L[i, i]
    return True


def _pairs(cell: np.ndarray, max_pairs: int, seed: int):
    """Index pairs of observations of the same cell (every pair of each group; subsampled)."""
    if len(cell) < 2:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    order = np.argsort(cell, kind="stable")
    sc = cell[order]
    starts = np.flatnonzero(np.r_[True, sc[1:] != sc[:-1]])
    counts = np.diff(np.r_[starts, len(sc)])
    ii_list, jj_list = [], []
    for k in np.unique(counts):
        if k < 2:
            continue
        grp = starts[counts == k]
        a, b = np.triu_indices(int(k), 1)
        ii_list.append((grp[:, None] + a[None, :]).ravel())
        jj_list.append((grp[:, None] + b[None, :]).ravel())
    if not ii_list:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    ii = order[np.concatenate(ii_list)]
    jj = order[np.concatenate(jj_list)]
    if len(ii) > max_pairs:
        sel = np.random.default_rng(seed).choice(len(ii), max_pairs, replace=False)
        ii, jj = ii[sel], jj[sel]
    return ii, jj
