"""The photos' point spread: measured from their straight edges, and undone before matching.

Real photos are softer than the cells they are matched on: lens, focus, motion and demosaicing
spread a point over a Gaussian of about 0.4 to 1.5 px (``docs/acceptance.md``, *optics blur*).
A matching window then sees an edge spread over more of its cells, so windows beside a height
step take the step's height (fattened walls, eaves placed a cell off). OSGM matches on photos
restored towards a sharp camera's spread (:func:`restore`), with the spread measured on the
photos themselves (:func:`edge_spreads`, :func:`photo_spread`).

* :func:`edge_spreads` -- the Gaussian sigma at a photo's strong straight edges: for the
  strongest 0.5 % of its gradients (Sobel), the grey-level profile across the edge (12 px long,
  every 0.25 px); kept where the profile's steepest point is at the pixel and the profile is flat
  beyond 3 px on both sides (a straight step of at least :data:`MIN_STEP` of the full scale, not
  a line or a corner). A step of height ``A`` blurred by a Gaussian of sigma ``s`` has the
  largest slope ``A / (s sqrt(2 pi))``.
* :func:`excess_spread` -- the part of a measured spread beyond a sharp camera's
  (:data:`SHARP_SPREAD`: a pixel's own integration and demosaicing; the battery's unblurred
  renderings read 0.44 px, the sharpest real block here 0.42 px).
* :func:`restore` -- a first-order inverse of that excess, ``I + a (I - G_s * I)``, where the gain
  ``a`` (0 to 1) is the share of the detail layer's local power (over the matching window) that
  stands above a floor (a local Wiener gain, Lee's filter): the photo's noise, or its typical
  detail (the median of that power) where that is larger. Edges and outlines are restored;
  texture and flat noisy ground are left as they are. With the noise alone as the floor, the
  noisiest blurred battery scenes lost precision (NMAD up to +0.10 GSD, flat3 -0.8 points) for
  the same edge gain (``docs/acceptance.md``).
* :func:`noise_sigma` -- the photo's noise (Immerkaer's estimator, 1996).
* :func:`prefilter` -- a Gaussian low-pass of a sharp photo's matching band before matching
  (OSGM's ``prefilter``): the cost samples the photos bilinearly at sub-pixel positions that
  change with every height, and differentiates them; the detail beyond the band a bilinear
  sampler passes alike at every phase (aliasing, JPEG quantisation, sensor noise) then moves the
  minima. Digital image correlation removes that bias the same way (Pan, Xie & Wang 2013,
  *Bias error reduction of digital image correlation using Gaussian pre-filtering*).

Pure numpy and OpenCV (no qgis). Inputs are validated; errors are :class:`InputError`.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from .errors import InputError

#: Point spread (Gaussian sigma, px) of a sharp photo, which :func:`restore` does not undo.
SHARP_SPREAD = 0.5
#: Smallest step (share of the full scale) that :func:`edge_spreads` measures: 30 grey levels of 255.
MIN_STEP = 30.0 / 255.0
#: Fewest measured edges for a photo's spread (:func:`photo_spread`); fewer: not measured.
MIN_EDGES = 30
#: Smallest restoration (sigma, px at the level matched) worth applying.
MIN_RESTORE = 0.25
#: Largest point spread :func:`restore` accepts (px).
MAX_SPREAD = 10.0
#: Largest Gaussian sigma :func:`prefilter` accepts (px).
MAX_PREFILTER = 3.0

_STEP = 0.25  # samples per pixel along an edge's profile
_HALF = 6.0  # half length of the profile (px)


def _inner(mask: np.ndarray) -> np.ndarray:
    """The pixels of ``mask`` whose 3 x 3 neighbourhood is all in it (outside the image counts as out)."""
    from scipy.ndimage import binary_erosion

    return binary_erosion(mask, np.ones((3, 3), bool), border_value=0)


def _grey(img, name: str) -> np.ndarray:
    a = np.asarray(img)
    if a.ndim != 2 or min(a.shape) < 3:
        raise InputError(f"{name}: expected a 2-D grey image of at least 3 x 3 pixels, got shape {a.shape}")
    return np.ascontiguousarray(a, np.float32)


def edge_spreads(grey, full_scale: float = 1.0, n_max: int = 4000, seed: int = 0) -> np.ndarray:
    """The point spread (Gaussian sigma, px) at the straight edges of one grey image.

    ``full_scale``: the value of white (1 for :func:`~truortho.core.imagery.luminance` of integer
    photos, 255 for 8-bit grey levels); at most ``n_max`` of the strongest gradients are tried
    (a random choice, ``seed``). NaN pixels are allowed (their edges are not measured). Returns a
    1-D array, empty where no edge qualifies.
    """
    import cv2

    g = _grey(grey, "edge_spreads")
    if not (math.isfinite(full_scale) and full_scale > 0):
        raise InputError(f"edge_spreads: full_scale must be a positive number, got {full_scale!r}")
    if int(n_max) < 1:
        raise InputError(f"edge_spreads: n_max must be at least 1, got {n_max!r}")
    finite = np.isfinite(g)
    g0 = np.where(finite, g, 0.0).astype(np.float32)
    gx = cv2.Sobel(g0, cv2.CV_32F, 1, 0, ksize=3) / 8.0
    gy = cv2.Sobel(g0, cv2.CV_32F, 0, 1, ksize=3) / 8.0
    mag = np.hypot(gx, gy)
    # a gradient next to a NaN pixel is not the photo's
    ok = _inner(finite)
    if not ok.any():
        return np.zeros(0)
    m = int(_HALF) + 3
    ok[:m] = ok[-m:] = False
    ok[:, :m] = ok[:, -m:] = False
    if not ok.any():
        return np.zeros(0)
    thr = np.percentile(mag[ok], 99.5)
    ys, xs = np.nonzero(ok & (mag > thr))
    if len(ys) > n_max:
        sel = np.random.default_rng(seed).choice(len(ys), int(n_max), replace=False)
        ys, xs = ys[sel], xs[sel]
    if not len(ys):
        return np.zeros(0)
    t = np.arange(-_HALF, _HALF + 1e-9, _STEP)
    centre = len(t) // 2
    dx = (gx[ys, xs] / mag[ys, xs])[:, None]
    dy = (gy[ys, xs] / mag[ys, xs])[:, None]
    mx = (xs[:, None] + t[None, :] * dx).astype(np.float32)
    my = (ys[:, None] + t[None, :] * dy).astype(np.float32)
    src = np.where(finite, g, np.nan).astype(np.float32)
    prof = cv2.remap(src, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE).astype(np.float64)
    slope = np.gradient(prof, _STEP, axis=1)
    k = np.argmax(np.abs(np.nan_to_num(slope)), axis=1)
    a = prof[:, -4:].mean(axis=1) - prof[:, :4].mean(axis=1)
    peak = np.abs(slope[np.arange(len(k)), k])
    keep = (
        np.isfinite(prof).all(axis=1)
        & (np.abs(k - centre) <= 2)
        & (np.abs(a) >= MIN_STEP * full_scale)
        & (prof[:, :8].std(axis=1) <= 0.08 * np.abs(a))
        & (prof[:, -8:].std(axis=1) <= 0.08 * np.abs(a))
        & (peak > 0)
    )
    return np.abs(a[keep]) / (math.sqrt(2.0 * math.pi) * peak[keep])


def photo_spread(grey, full_scale: float = 1.0) -> float | None:
    """The median of :func:`edge_spreads`, or None with fewer than :data:`MIN_EDGES` edges."""
    s = edge_spreads(grey, full_scale)
    return float(np.median(s)) if len(s) >= MIN_EDGES else None


def excess_spread(spread: float, sharp: float = SHARP_SPREAD) -> float:
    """The Gaussian that, convolved with a sharp photo's ``sharp``, gives ``spread`` (0 if none)."""
    if not (math.isfinite(spread) and spread >= 0):
        raise InputError(f"excess_spread: expected a spread >= 0 px, got {spread!r}")
    return math.sqrt(max(spread * spread - sharp * sharp, 0.0))


def noise_sigma(grey) -> float:
    """The standard deviation of a grey image's noise (Immerkaer 1996: the mean absolute response
    to the difference of two Laplacians, which cancels linear and quadratic relief). NaN pixels
    and their neighbours are left out; 0 for an image without three valid rows and columns."""
    import cv2

    g = _grey(grey, "noise_sigma")
    finite = np.isfinite(g)
    k = np.array([[1, -2, 1], [-2, 4, -2], [1, -2, 1]], np.float32)
    r = cv2.filter2D(np.where(finite, g, 0.0).astype(np.float32), -1, k, borderType=cv2.BORDER_REFLECT)
    ok = _inner(finite)
    ok[0, :] = ok[-1, :] = False
    ok[:, 0] = ok[:, -1] = False
    if not ok.any():
        return 0.0
    return float(math.sqrt(math.pi / 2.0) * np.abs(r[ok]).mean() / 6.0)


def _kernel(sigma: float) -> np.ndarray:
    import cv2

    n = max(3, 2 * int(math.ceil(3.0 * sigma)) + 1)
    return cv2.getGaussianKernel(n, sigma).astype(np.float32)


def restore_margin(sigma: float, window: int) -> int:
    """Pixels of context :func:`restore` needs around an area to restore it as in the whole image."""
    if not (math.isfinite(sigma) and 0 <= sigma <= MAX_SPREAD):
        raise InputError(f"restore_margin: sigma must be in [0, {MAX_SPREAD}] px, got {sigma!r}")
    if int(window) != window or window < 1:
        raise InputError(f"restore_margin: window must be a whole number of pixels >= 1, got {window!r}")
    return int(math.ceil(3.0 * sigma)) + int(window) // 2 + 1


def restore(grey, sigma: float, window: int, noise: float | None = None) -> np.ndarray:
    """``grey`` with a Gaussian point spread of ``sigma`` px undone to first order where its detail
    stands out: ``I + a (I - G_sigma * I)`` with ``a = max(v - f, 0) / v``, ``v`` the detail
    layer's mean square over ``window`` x ``window`` pixels (the matching window) and ``f`` the
    larger of the noise's share of it (``noise`` sigma, else :func:`noise_sigma`, times the detail
    filter's gain for white noise) and the median of ``v`` over the image (its typical detail).
    Edges and outlines are restored; texture and noise are left as they are, since sharpening
    them amplifies the noise more than the texture. NaN pixels stay NaN (they are filled with the
    blurred valid values first, so a border does not ring). ``sigma`` below :data:`MIN_RESTORE`
    returns the image unchanged (a copy as float32).
    """
    import cv2

    g = _grey(grey, "restore")
    if not (math.isfinite(sigma) and 0 <= sigma <= MAX_SPREAD):
        raise InputError(f"restore: sigma must be in [0, {MAX_SPREAD}] px, got {sigma!r}")
    if int(window) != window or window < 1 or window % 2 == 0:
        raise InputError(f"restore: window must be an odd number of pixels >= 1, got {window!r}")
    if noise is not None and not (math.isfinite(noise) and noise >= 0):
        raise InputError(f"restore: noise must be a number >= 0, got {noise!r}")
    if sigma < MIN_RESTORE:
        return g.copy()
    finite = np.isfinite(g)
    f = g
    if not finite.all():
        if not finite.any():
            return g.copy()
        # NaN (outside the photo) filled with the blurred valid values, so the border does not ring
        w = finite.astype(np.float32)
        kk = _kernel(max(sigma, 2.0))
        num = cv2.sepFilter2D(np.where(finite, g, 0.0).astype(np.float32), -1, kk, kk,
                              borderType=cv2.BORDER_REFLECT)  # fmt: skip
        den = cv2.sepFilter2D(w, -1, kk, kk, borderType=cv2.BORDER_REFLECT)
        fill = np.where(den > 1e-6, num / np.maximum(den, 1e-6), np.float32(np.nanmean(g)))
        f = np.where(finite, g, fill).astype(np.float32)
    kern = _kernel(sigma)
    detail = f - cv2.sepFilter2D(f, -1, kern, kern, borderType=cv2.BORDER_REFLECT)
    n = noise_sigma(g) if noise is None else float(noise)
    # the detail filter (identity minus the Gaussian) passes this share of white noise's variance
    k2 = kern @ kern.T
    c = k2.shape[0] // 2
    gain = float((k2 * k2).sum() - 2.0 * k2[c, c] + 1.0)
    nd = n * n * gain
    v = cv2.blur(detail * detail, (int(window), int(window)), borderType=cv2.BORDER_REFLECT)
    # the floor: the noise's share, or the photo's typical detail where that is larger
    floor = max(nd, float(np.median(v[finite])))
    a = np.maximum(v - floor, 0.0) / np.maximum(v, np.float32(1e-20))
    out = (f + a * detail).astype(np.float32)
    out[~finite] = np.nan
    return out


def check_prefilter(sigma, where: str) -> float:
    """``sigma`` as a float if it is a Gaussian sigma :func:`prefilter` takes (a real number in
    ``[0, MAX_PREFILTER]`` px, not a bool); else an :class:`InputError` that starts with ``where``."""
    ok = isinstance(sigma, numbers.Real) and not isinstance(sigma, bool | np.bool_)
    if not (ok and math.isfinite(sigma) and 0 <= sigma <= MAX_PREFILTER):
        raise InputError(f"{where}: expected a Gaussian sigma in [0, {MAX_PREFILTER}] px, got {sigma!r}")
    return float(sigma)


def prefilter_margin(sigma: float) -> int:
    """Pixels of context :func:`prefilter` needs around an area to filter it as in the whole image."""
    sigma = check_prefilter(sigma, "prefilter_margin: sigma")
    return int(math.ceil(3.0 * sigma)) + 1 if sigma > 0 else 0


def prefilter(grey, sigma: float) -> np.ndarray:
    """``grey`` low-passed by a Gaussian of ``sigma`` px (float32; 0 returns a copy). NaN pixels stay
    NaN and do not spread: each pixel is the weighted mean of the valid pixels around it
    (normalised convolution), so the border of a photo's window is not darkened."""
    import cv2

    g = _grey(grey, "prefilter")
    sigma = check_prefilter(sigma, "prefilter: sigma")
    if sigma == 0:
        return g.copy()
    kern = _kernel(sigma)
    finite = np.isfinite(g)
    if finite.all():
        return cv2.sepFilter2D(g, -1, kern, kern, borderType=cv2.BORDER_REFLECT).astype(np.float32)
    w = finite.astype(np.float32)
    num = cv2.sepFilter2D(np.where(finite, g, 0.0).astype(np.float32), -1, kern, kern,
                          borderType=cv2.BORDER_REFLECT)  # fmt: skip
    den = cv2.sepFilter2D(w, -1, kern, kern, borderType=cv2.BORDER_REFLECT)
    out = (num / np.maximum(den, np.float32(1e-6))).astype(np.float32)
    out[~finite] = np.nan
    return out
