"""Least-squares matching (LSM) and multi-image geometrically constrained matching (MGCM).

A *template* (a patch of a master image, or an ideal rendering of a target) is matched into
*search* images by Gauss-Newton on grey values:

    T(u, v) = r0 + r1 * G(x(u, v), y(u, v)) + e

with ``(u, v)`` the template's pixel offsets from its centre pixel (the template has odd
height and width; its centre is the point being measured), ``G`` the search image resampled
bilinearly, ``r0, r1`` a radiometric offset and gain, and the geometric shaping

    w = 1 + c_u u + c_v v
    x = (x0 + a_u u + a_v v) / w,   y = (y0 + b_u u + b_v v) / w

(affine: ``c_u = c_v = 0``, 6 parameters; projective: 8). The measured point is the image of
the template centre, ``(x0, y0)``. Pixel convention of :mod:`truortho.core.geometry`: the
centre of the top-left pixel is (0, 0), x right, y down.

:func:`lsm_match` matches one template into one image. :func:`mgcm` matches one template into
several oriented images at once with the collinearity condition (Gruen & Baltsavias): each
image's shift ``(x0, y0)`` is the projection of one object point ``X`` (local frame, metres),
which is an unknown of the joint adjustment together with every image's shaping and
radiometry. Including the master image (whose patch is the template) pins ``X`` to the master
ray. Both return results, never raise on a failed estimation: ``converged`` False and a
``reason``.

Precision: ``sigma0`` is the standard deviation of the grey-value residuals (unit weight);
the covariance of the unknowns is ``sigma0**2 N^-1``. In MGCM the image coordinates'
covariance is the object point's propagated into each image.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import cv2
import numpy as np

from ..errors import InputError
from ..geometry.camera import Camera, _distort_one, _undistort_one, project_points, undistort_points
from ..jit import njit

#: Order of the 10 unknowns in the kernels' normal equations.
#: 0 a_u, 1 a_v, 2 b_u, 3 b_v, 4 c_u, 5 c_v, 6 r0, 7 r1, 8 x0, 9 y0
_AFFINE_LOCAL = np.array([0, 1, 2, 3, 6, 7])
_PROJECTIVE_LOCAL = np.array([0, 1, 2, 3, 4, 5, 6, 7])
_SHIFT = np.array([8, 9])


@dataclass(frozen=True)
class LsmConfig:
    """Settings of least-squares matching.

    Parameters
    ----------
    projective : bool
        Projective (8 parameters) instead of affine (6) shaping.
    max_iterations : int
        Gauss-Newton iterations per stage.
    tolerance : float
        Convergence: largest change of the shift in an iteration, pixels.
    max_shift : float
        Failure when the point moves farther than this from its start, pixels.
    coarse_sigma : float
        Gaussian blur (pixels) of a first, coarse stage that widens the pull-in range for starts
        a few pixels off; 0 = no coarse stage.
    min_correlation : float
        A converged match with a lower normalised cross-correlation is reported as not
        converged (reason ``"low correlation"``).
    """

    projective: bool = False
    max_iterations: int = 40
    tolerance: float = 1e-3
    max_shift: float = 6.0
    coarse_sigma: float = 1.5
    min_correlation: float = 0.5

    def __post_init__(self) -> None:
        if not (isinstance(self.max_iterations, int) and self.max_iterations >= 1):
            raise InputError(
                f"LsmConfig.max_iterations must be a positive integer, got {self.max_iterations!r}"
            )
        for name in ("tolerance", "max_shift"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"LsmConfig.{name} must be positive, got {v!r}")
        if not (math.isfinite(self.coarse_sigma) and self.coarse_sigma >= 0):
            raise InputError(f"LsmConfig.coarse_sigma must be >= 0, got {self.coarse_sigma!r}")
        if not -1.0 <= self.min_correlation <= 1.0:
            raise InputError(f"LsmConfig.min_correlation must be in [-1, 1], got {self.min_correlation!r}")


@dataclass(frozen=True)
class LsmResult:
    """Outcome of one match (also one image of an MGCM solution).

    ``x, y``: the template centre in the search image (pixels); ``covariance`` (2, 2) px^2 and
    ``sigma_x, sigma_y`` its standard deviations; ``correlation``: normalised cross-correlation
    of the template and the resampled image at the solution; ``shape``: (2, 3) affine part
    ``[[a_u, a_v, x0], [b_u, b_v, y0]]``; ``perspective``: ``(c_u, c_v)``; ``gain, offset``:
    ``r1, r0``; ``sigma0``: grey-value residual standard deviation.
    """

    x: float
    y: float
    sigma_x: float
    sigma_y: float
    covariance: np.ndarray
    correlation: float
    iterations: int
    converged: bool
    reason: str
    shape: np.ndarray = field(default_factory=lambda: np.full((2, 3), np.nan))
    perspective: tuple[float, float] = (0.0, 0.0)
    gain: float = float("nan")
    offset: float = float("nan")
    sigma0: float = float("nan")

    def __bool__(self) -> bool:
        return self.converged


@dataclass(frozen=True)
class MgcmView:
    """One oriented search image of :func:`mgcm`.

    ``image``: (H, W) grey values; ``R`` (3, 3) world-to-camera; ``C`` (3,) projection centre
    in the local frame; ``camera``: its interior orientation; ``name`` for reports.
    """

    image: np.ndarray
    R: np.ndarray
    C: np.ndarray
    camera: Camera
    name: str = ""


@dataclass(frozen=True)
class MgcmResult:
    """Outcome of :func:`mgcm`: the object point and one :class:`LsmResult` per view."""

    X: np.ndarray
    covariance: np.ndarray
    views: list[LsmResult]
    iterations: int
    converged: bool
    reason: str
    sigma0: float

    @property
    def sigma(self) -> np.ndarray:
        """Standard deviations of X, Y, Z (metres)."""
        return np.sqrt(np.clip(np.diag(self.covariance), 0.0, None))

    def __bool__(self) -> bool:
        return self.converged


# ---------------------------------------------------------------- kernels


@njit
def _normals(template, img, gx, gy, p, r0, r1, N, b, resampled):
    """Normal equations of one image at parameters ``p`` (10, kernel order).

    Fills ``N`` (10, 10), ``b`` (10,) and ``resampled`` (the image under the template);
    returns ``(sum of squared residuals, number of samples, number outside the image)``.
    """
    th, tw = template.shape
    hi, wi = img.shape
    hv = th // 2
    hu = tw // 2
    for i in range(10):
        b[i] = 0.0
        for j in range(10):
            N[i, j] = 0.0
    ssr = 0.0
    n = 0
    outside = 0
    row = np.empty(10)
    for iv in range(th):
        v = float(iv - hv)
        for iu in range(tw):
            u = float(iu - hu)
            w = 1.0 + p[4] * u + p[5] * v
            if w <= 1e-6:
                outside += 1
                resampled[iv, iu] = np.nan
                continue
            x = (p[8] + p[0] * u + p[1] * v) / w
            y = (p[9] + p[2] * u + p[3] * v) / w
            if not (x >= 0.0 and y >= 0.0 and x <= wi - 1 and y <= hi - 1):
                outside += 1
                resampled[iv, iu] = np.nan
                continue
            # bilinear, NaN outside the pixel centres' hull; the weights once for the image and
            # its gradients
            x0 = min(int(x), wi - 2) if wi > 1 else 0
            y0 = min(int(y), hi - 2) if hi > 1 else 0
            fx = x - x0
            fy = y - y0
            ax = 1.0 - fx
            ay = 1.0 - fy
            x1 = min(x0 + 1, wi - 1)
            y1 = min(y0 + 1, hi - 1)
            g = (img[y0, x0] * ax + img[y0, x1] * fx) * ay + (img[y1, x0] * ax + img[y1, x1] * fx) * fy
            resampled[iv, iu] = g
            dgx = (gx[y0, x0] * ax + gx[y0, x1] * fx) * ay + (gx[y1, x0] * ax + gx[y1, x1] * fx) * fy
            dgy = (gy[y0, x0] * ax + gy[y0, x1] * fx) * ay + (gy[y1, x0] * ax + gy[y1, x1] * fx) * fy
            dgx = dgx * r1 / w
            dgy = dgy * r1 / w
            row[0] = dgx * u
            row[1] = dgx * v
            row[2] = dgy * u
            row[3] = dgy * v
            row[4] = -(dgx * x + dgy * y) * u
            row[5] = -(dgx * x + dgy * y) * v
            row[6] = 1.0
            row[7] = g
            row[8] = dgx
            row[9] = dgy
            e = template[iv, iu] - (r0 + r1 * g)
            ssr += e * e
            n += 1
            for i in range(10):
                b[i] += row[i] * e
                for j in range(i, 10):
                    N[i, j] += row[i] * row[j]
    for i in range(10):
        for j in range(i):
            N[i, j] = N[j, i]
    return ssr, n, outside


# ---------------------------------------------------------------- helpers


def _gray(a, what: str) -> np.ndarray:
    arr = np.asarray(a)
    if arr.ndim != 2 or min(arr.shape) < 3:
        raise InputError(f"{what}: expected a 2-D grey image of at least 3x3 pixels, got shape {arr.shape}")
    out = np.ascontiguousarray(arr, dtype=np.float64)
    if not np.all(np.isfinite(out)):
        raise InputError(f"{what}: contains NaN or infinite values")
    return out


def _check_template(template) -> np.ndarray:
    t = _gray(template, "template")
    if t.shape[0] % 2 == 0 or t.shape[1] % 2 == 0:
        raise InputError(f"template: height and width must be odd (centre pixel = the point), got {t.shape}")
    if float(np.std(t)) <= 1e-9 * max(1.0, float(np.abs(t).max())):
        raise InputError("template: has no contrast (constant grey values)")
    return t


def _blur(a: np.ndarray, sigma: float) -> np.ndarray:
    if sigma <= 0:
        return a
    return cv2.GaussianBlur(a, (0, 0), sigmaX=sigma, sigmaY=sigma, borderType=cv2.BORDER_REFLECT)


def _gradients(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    gy, gx = np.gradient(a)
    return np.ascontiguousarray(gx), np.ascontiguousarray(gy)


def _reach(template_shape, p) -> float:
    """Largest distance (pixels) of the template's footprint from its centre under ``p``."""
    hv, hu = template_shape[0] // 2, template_shape[1] // 2
    a = np.array([[p[0], p[1]], [p[2], p[3]]])
    return float(np.abs(a).sum(axis=1).max() * max(hu, hv) * (1.0 + 4.0 * (abs(p[4]) * hu + abs(p[5]) * hv)))


def _image(a, what: str) -> np.ndarray:
    """A search image as given (any real dtype): checked for shape only; windows are converted
    to float64 and checked for NaN when they are cut (:func:`_crop`), so a large image is
    neither copied nor scanned for every match."""
    arr = np.asarray(a)
    if arr.ndim != 2 or min(arr.shape) < 3 or not np.issubdtype(arr.dtype, np.number):
        raise InputError(f"{what}: expected a 2-D grey image of at least 3x3 pixels, got shape {arr.shape}")
    return arr


@njit
def _window_bounds(h, w, cx, cy, radius):
    """Pixel bounds ``(x0, y0, x1, y1)`` (end exclusive, clipped to an ``h`` x ``w`` image) of the
    window around (cx, cy) that :func:`_crop` and :func:`_window` cut: ``radius`` + 2 pixels."""
    r = int(math.ceil(radius)) + 2
    x0 = max(0, int(math.floor(cx)) - r)
    y0 = max(0, int(math.floor(cy)) - r)
    x1 = min(w, int(math.floor(cx)) + r + 2)
    y1 = min(h, int(math.floor(cy)) + r + 2)
    return x0, y0, x1, y1


def _crop(image: np.ndarray, cx: float, cy: float, radius: float):
    """Window of ``image`` around (cx, cy) of the given radius: (window, x offset, y offset).

    Raises InputError when the window holds NaN or infinite values.
    """
    x0, y0, x1, y1 = _window_bounds(image.shape[0], image.shape[1], float(cx), float(cy), float(radius))
    if x1 - x0 < 3 or y1 - y0 < 3:
        return None, x0, y0
    win = np.ascontiguousarray(image[y0:y1, x0:x1], dtype=np.float64)
    if not np.all(np.isfinite(win)):
        raise InputError(f"image: NaN or infinite values near ({cx:.1f}, {cy:.1f})")
    return win, x0, y0


def _ncc(a: np.ndarray, b: np.ndarray) -> float:
    ok = np.isfinite(b)
    if ok.sum() < 3:
        return float("nan")
    x = a[ok] - a[ok].mean()
    y = b[ok] - b[ok].mean()
    d = math.sqrt(float((x * x).sum() * (y * y).sum()))
    return float((x * y).sum() / d) if d > 0 else 0.0


def _initial_params(x: float, y: float, initial) -> np.ndarray:
    p = np.zeros(10)
    p[0] = p[3] = 1.0
    if initial is not None:
        m = np.asarray(initial, dtype=np.float64)
        if m.shape == (2, 3):
            m = np.vstack([m, [0.0, 0.0, 1.0]])
        if m.shape != (3, 3) or not np.all(np.isfinite(m)) or abs(m[2, 2]) < 1e-12:
            raise InputError(
                f"initial: expected a (2, 3) affine or (3, 3) projective matrix, got {np.shape(initial)}"
            )
        m = m / m[2, 2]
        p[0], p[1], p[2], p[3] = m[0, 0], m[0, 1], m[1, 0], m[1, 1]
        p[4], p[5] = m[2, 0], m[2, 1]
    p[8], p[9] = x, y
    return p


def _failed(x, y, it, reason, corr=float("nan")) -> LsmResult:
    return LsmResult(
        float(x), float(y), float("nan"), float("nan"), np.full((2, 2), np.nan), corr, it, False, reason
    )


#: Marquardt damping of the shaping parameters during the iterations: a rotationally symmetric
#: target (a disc) leaves the rotation of the shaping undetermined, and undamped steps let the
#: shape wander along that null direction. The centre and the final covariance are undamped.
_SHAPE_DAMPING = 0.1


def _damped(N: np.ndarray, shape_idx) -> np.ndarray:
    Nd = N.copy()
    Nd[shape_idx, shape_idx] *= 1.0 + _SHAPE_DAMPING
    return Nd


def _solve(N: np.ndarray, b: np.ndarray):
    """Solution and inverse of a small normal matrix; None when (nearly) singular."""
    scale = np.sqrt(np.clip(np.diag(N), 1e-300, None))
    Ns = N / np.outer(scale, scale)
    try:
        if np.linalg.cond(Ns) > 1e12:
            return None
        inv = np.linalg.inv(Ns) / np.outer(scale, scale)
    except np.linalg.LinAlgError:
        return None
    return inv @ b, inv


# ---------------------------------------------------------------- LSM kernels

#: Status codes of :func:`_lm_stage` and :func:`_match_many`, index into :data:`_REASONS`.
_REASONS = (
    "",
    "singular (no texture)",
    "left the image",
    "moved farther than max_shift",
    "degenerate shape",
    "no convergence",
    "start outside the image",
    "image: NaN or infinite values near the start",
)


@njit
def _solve_small(N, b, sol, inv):
    """:func:`_solve` in a kernel: fills ``sol`` and ``inv``; False when (nearly) singular."""
    m = N.shape[0]
    scale = np.empty(m)
    for i in range(m):
        scale[i] = math.sqrt(max(N[i, i], 1e-300))
    Ns = np.empty((m, m))
    for i in range(m):
        for j in range(m):
            Ns[i, j] = N[i, j] / (scale[i] * scale[j])
    if not np.all(np.isfinite(Ns)):
        return False
    # Ns is symmetric: its singular values are the moduli of its eigenvalues (np.linalg.cond)
    ev = np.abs(np.linalg.eigvalsh(Ns))
    if not ev.min() > 0.0 or ev.max() / ev.min() > 1e12:
        return False
    Ni = np.linalg.inv(Ns)
    for i in range(m):
        for j in range(m):
            inv[i, j] = Ni[i, j] / (scale[i] * scale[j])
    for i in range(m):
        acc = 0.0
        for j in range(m):
            acc += inv[i, j] * b[j]
        sol[i] = acc
    return True


@njit
def _gradients_k(a, gx, gy):
    """``np.gradient`` of a 2-D array (central inside, one-sided at the borders)."""
    h, w = a.shape
    for i in range(h):
        for j in range(w):
            if j == 0:
                gx[i, j] = a[i, 1] - a[i, 0]
            elif j == w - 1:
                gx[i, j] = a[i, w - 1] - a[i, w - 2]
            else:
                gx[i, j] = (a[i, j + 1] - a[i, j - 1]) / 2.0
            if i == 0:
                gy[i, j] = a[1, j] - a[0, j]
            elif i == h - 1:
                gy[i, j] = a[h - 1, j] - a[h - 2, j]
            else:
                gy[i, j] = (a[i + 1, j] - a[i - 1, j]) / 2.0


@njit
def _lm_stage(t, window, gx, gy, pc, r, idx, n_shape, max_iter, tol, max_shift, ox, oy, sx, sy, inv, res):
    """Levenberg-Marquardt iterations of one LSM stage (window pixels).

    ``pc`` (10,) and ``r`` (r0, r1) are updated in place; ``idx``: the unknowns estimated (kernel
    order), the first ``n_shape`` of them the damped shaping; ``(ox, oy)``: the window's offset in
    the image and ``(sx, sy)`` the start in image pixels. On success ``inv`` (len(idx), len(idx))
    holds the inverse normal matrix and ``res`` the image resampled under the template.
    Returns ``(status, iterations, ssr, n)``; a step that does not lower the residuals is retried
    with more damping (symmetric targets otherwise make the shaping oscillate).
    """
    m = idx.shape[0]
    N = np.zeros((10, 10))
    b = np.zeros(10)
    Nt = np.zeros((10, 10))
    bt = np.zeros(10)
    Ns = np.empty((m, m))
    Nd = np.empty((m, m))
    bs = np.empty(m)
    sol = np.empty(m)
    full = np.zeros(10)
    trial = np.empty(10)
    lam = 1e-3
    done = False
    it = 0
    ssr, n, outside = _normals(t, window, gx, gy, pc, r[0], r[1], N, b, res)
    if outside:
        return 2, it, ssr, n
    for _ in range(max_iter):
        it += 1
        for i in range(m):
            bs[i] = b[idx[i]]
            for j in range(m):
                Ns[i, j] = N[idx[i], idx[j]]
        for i in range(n_shape):
            Ns[i, i] *= 1.0 + _SHAPE_DAMPING
        accepted = False
        step = np.inf
        for _attempt in range(10):
            Nd[:, :] = Ns
            for i in range(m):
                Nd[i, i] *= 1.0 + lam
            if not _solve_small(Nd, bs, sol, inv):
                return 1, it, ssr, n
            full[:] = 0.0
            for i in range(m):
                full[idx[i]] = sol[i]
            trial[:] = pc
            for i in range(6):
                trial[i] += full[i]
            trial[8] += full[8]
            trial[9] += full[9]
            r0t = r[0] + full[6]
            r1t = r[1] + full[7]
            if np.all(np.isfinite(trial)) and r1t > 0:
                ssr_t, n_t, out_t = _normals(t, window, gx, gy, trial, r0t, r1t, Nt, bt, res)
                if not out_t and ssr_t <= ssr:
                    pc[:] = trial
                    r[0] = r0t
                    r[1] = r1t
                    ssr = ssr_t
                    n = n_t
                    N[:, :] = Nt
                    b[:] = bt
                    lam = max(lam * 0.3, 1e-7)
                    accepted = True
                    step = math.hypot(full[8], full[9])
                    break
            lam *= 10.0
        if not accepted:
            done = True  # no step lowers the residuals: at the minimum
        if math.hypot(pc[8] + ox - sx, pc[9] + oy - sy) > max_shift:
            return 3, it, ssr, n
        det = pc[0] * pc[3] - pc[1] * pc[2]
        if not 0.1 < abs(det) < 10.0:
            return 4, it, ssr, n
        if done or step < tol:
            _normals(t, window, gx, gy, pc, r[0], r[1], N, b, res)
            for i in range(m):
                bs[i] = b[idx[i]]
                for j in range(m):
                    Ns[i, j] = N[idx[i], idx[j]]
            if not _solve_small(Ns, bs, sol, inv):
                for i in range(n_shape):
                    Ns[i, i] *= 1.0 + _SHAPE_DAMPING
                if not _solve_small(Ns, bs, sol, inv):
                    return 1, it, ssr, n
            return 0, it, ssr, n
    return 5, it, ssr, n


@njit
def _masked_moments(a, b):
    """Count, means and centred sums of squares and products of ``a`` and ``b`` over the finite
    values of ``b``: ``(n, mean_a, mean_b, saa, sbb, sab)`` (means 0 when ``n`` is 0)."""
    cnt = 0
    sa = 0.0
    sb = 0.0
    for i in range(a.shape[0]):
        for j in range(a.shape[1]):
            if np.isfinite(b[i, j]):
                cnt += 1
                sa += a[i, j]
                sb += b[i, j]
    if cnt == 0:
        return 0, 0.0, 0.0, 0.0, 0.0, 0.0
    ma = sa / cnt
    mb = sb / cnt
    saa = 0.0
    sbb = 0.0
    sab = 0.0
    for i in range(a.shape[0]):
        for j in range(a.shape[1]):
            if np.isfinite(b[i, j]):
                x = a[i, j] - ma
                y = b[i, j] - mb
                saa += x * x
                sbb += y * y
                sab += x * y
    return cnt, ma, mb, saa, sbb, sab


@njit
def _ncc_k(a, b):
    """:func:`_ncc` in a kernel: normalised cross-correlation over the finite values of ``b``."""
    cnt, _, _, sxx, syy, sxy = _masked_moments(a, b)
    if cnt < 3:
        return np.nan
    d = math.sqrt(sxx * syy)
    return sxy / d if d > 0 else 0.0


@njit
def _radiometric_start(t, probe, r):
    """Gain and offset matching the means and spreads of ``t`` and the finite ``probe`` values."""
    cnt, mt, mp, vt, vp, _ = _masked_moments(t, probe)
    if cnt <= 3:
        return
    if vp > 0:
        r1 = math.sqrt(vt / cnt) / math.sqrt(vp / cnt)
        r[0] = mt - r1 * mp
        r[1] = r1


@njit
def _window(image, cx, cy, radius):
    """:func:`_crop` in a kernel: (float64 window or an empty one, x offset, y offset, all finite)."""
    x0, y0, x1, y1 = _window_bounds(image.shape[0], image.shape[1], cx, cy, radius)
    if x1 - x0 < 3 or y1 - y0 < 3:
        return np.empty((0, 0)), x0, y0, True
    win = np.empty((y1 - y0, x1 - x0))
    finite = True
    for i in range(y1 - y0):
        for j in range(x1 - x0):
            v = float(image[y0 + i, x0 + j])
            win[i, j] = v
            if not np.isfinite(v):
                finite = False
    return win, x0, y0, finite


@njit
def _match_many(templates, tindex, image, starts, shapes, idx, n_shape, max_iter, tol, max_shift, out):
    """Single-stage LSM of ``templates[tindex[k]]`` into ``image`` from ``starts[k]`` with the
    shaping started at ``shapes[k]`` (2, 2). ``out`` (K, 6): x, y, sigma_x, sigma_y, correlation,
    status (:data:`_REASONS`)."""
    th = templates.shape[1]
    tw = templates.shape[2]
    hv = th // 2
    hu = tw // 2
    h, w = image.shape
    m = idx.shape[0]
    inv = np.empty((m, m))
    res = np.empty((th, tw))
    probe = np.empty((th, tw))
    Nd = np.empty((10, 10))
    bd = np.empty(10)
    pc = np.zeros(10)
    r = np.empty(2)
    for k in range(starts.shape[0]):
        t = templates[tindex[k]]
        x = starts[k, 0]
        y = starts[k, 1]
        for c in range(5):
            out[k, c] = np.nan
        if not (x >= 0 and y >= 0 and x <= w - 1 and y <= h - 1):
            out[k, 5] = 6
            continue
        pc[:] = 0.0
        pc[0] = shapes[k, 0, 0]
        pc[1] = shapes[k, 0, 1]
        pc[2] = shapes[k, 1, 0]
        pc[3] = shapes[k, 1, 1]
        reach = max(abs(pc[0]) + abs(pc[1]), abs(pc[2]) + abs(pc[3])) * max(hu, hv)
        window, ox, oy, finite = _window(image, x, y, reach + max_shift + 2.0)
        if window.shape[0] == 0:
            out[k, 5] = 6
            continue
        if not finite:
            out[k, 5] = 7
            continue
        gx = np.empty(window.shape)
        gy = np.empty(window.shape)
        _gradients_k(window, gx, gy)
        pc[8] = x - ox
        pc[9] = y - oy
        _normals(t, window, gx, gy, pc, 0.0, 1.0, Nd, bd, probe)
        r[0] = 0.0
        r[1] = 1.0
        _radiometric_start(t, probe, r)
        status, _it, ssr, n = _lm_stage(
            t, window, gx, gy, pc, r, idx, n_shape, max_iter, tol, max_shift, ox, oy, x, y, inv, res
        )
        out[k, 0] = pc[8] + ox
        out[k, 1] = pc[9] + oy
        out[k, 5] = status
        if status:
            continue
        s2 = ssr / max(n - m, 1)
        out[k, 2] = math.sqrt(max(s2 * inv[m - 2, m - 2], 0.0))
        out[k, 3] = math.sqrt(max(s2 * inv[m - 1, m - 1], 0.0))
        out[k, 4] = _ncc_k(t, res)


@njit
def _extract_many(image, centres, out):
    """Templates ``out`` (K, n, n) of ``image`` centred bilinearly on ``centres`` (K, 2); NaN
    where a template reaches outside the image or onto non-finite values."""
    n = out.shape[1]
    half = n // 2
    zeros = np.zeros((n, n))
    N = np.empty((10, 10))
    b = np.empty(10)
    p = np.zeros(10)
    for k in range(centres.shape[0]):
        x = centres[k, 0]
        y = centres[k, 1]
        out[k, :, :] = np.nan
        if not (np.isfinite(x) and np.isfinite(y)):
            continue
        window, ox, oy, finite = _window(image, x, y, half + 2)
        if window.shape[0] == 0 or not finite:
            continue
        p[:] = 0.0
        p[0] = 1.0
        p[3] = 1.0
        p[8] = x - ox
        p[9] = y - oy
        _normals(zeros, window, window, window, p, 0.0, 1.0, N, b, out[k])


@njit
def _plane_shapes(X, normals, master, view, R, C, P, out):
    """:func:`plane_shape` for many (point, master, view): ``out`` (K, 2, 2)."""
    uv0 = np.empty(2)
    q = np.empty((4, 2))
    d = np.empty(3)
    pt = np.empty(3)
    for k in range(X.shape[0]):
        mi = master[k]
        vi = view[k]
        out[k, :, :] = np.nan
        _project_one(X[k], R[mi], C[mi], P[mi], uv0)
        if not (np.isfinite(uv0[0]) and np.isfinite(uv0[1])):
            continue
        num = 0.0
        for c in range(3):
            num += (X[k, c] - C[mi, c]) * normals[k, c]
        for j in range(4):
            du = 1.0 if j == 0 else (-1.0 if j == 1 else 0.0)
            dv = 1.0 if j == 2 else (-1.0 if j == 3 else 0.0)
            x, y, ok = _undistort_one(uv0[0] + du, uv0[1] + dv, P[mi], 20)
            if not ok:
                q[j, 0] = np.nan
                q[j, 1] = np.nan
                continue
            den = 0.0
            for c in range(3):
                d[c] = x * R[mi, 0, c] + y * R[mi, 1, c] + R[mi, 2, c]
                den += d[c] * normals[k, c]
            if den == 0.0:
                q[j, 0] = np.nan
                q[j, 1] = np.nan
                continue
            lam = num / den
            for c in range(3):
                pt[c] = C[mi, c] + lam * d[c]
            _project_one(pt, R[vi], C[vi], P[vi], q[j])
        out[k, 0, 0] = (q[0, 0] - q[1, 0]) / 2.0
        out[k, 1, 0] = (q[0, 1] - q[1, 1]) / 2.0
        out[k, 0, 1] = (q[2, 0] - q[3, 0]) / 2.0
        out[k, 1, 1] = (q[2, 1] - q[3, 1]) / 2.0


# ---------------------------------------------------------------- LSM


def _lsm_stage(t, window, ox, oy, p, r, cfg, start, it0):
    """Levenberg-Marquardt iterations on one (possibly blurred) stage (:func:`_lm_stage`).

    Returns ``(p, r, it, reason, extras)``; a step that does not lower the residuals is retried
    with more damping (symmetric targets otherwise make the shaping oscillate).
    """
    gx, gy = _gradients(window)
    local = _PROJECTIVE_LOCAL if cfg.projective else _AFFINE_LOCAL
    idx = np.concatenate([local, _SHIFT])
    m = len(idx)
    pc = p.copy()
    pc[8] -= ox
    pc[9] -= oy
    rr = np.array(r, dtype=np.float64)
    inv = np.zeros((m, m))
    res = np.zeros(t.shape)
    status, k, ssr, n = _lm_stage(
        np.ascontiguousarray(t, dtype=np.float64),
        window,
        gx,
        gy,
        pc,
        rr,
        idx,
        len(local) - 2,
        cfg.max_iterations,
        float(cfg.tolerance),
        float(cfg.max_shift),
        float(ox),
        float(oy),
        float(start[0]),
        float(start[1]),
        inv,
        res,
    )
    it = it0 + int(k)
    r = (float(rr[0]), float(rr[1]))
    if status:
        return pc, r, it, _REASONS[int(status)], None
    pc[8] += ox
    pc[9] += oy
    return pc, r, it, "", (float(ssr), int(n), m, inv, res)


def lsm_match(
    template, image, x: float, y: float, config: LsmConfig | None = None, initial=None
) -> LsmResult:
    """Match a template into an image by least squares from a start position.

    Parameters
    ----------
    template : (h, w) array, h and w odd
        Grey values; its centre pixel is the point to measure.
    image : (H, W) array
        Search image (grey values on the template's scale up to a gain and offset).
    x, y : float
        Start position of the template centre in ``image``, pixels ((0, 0) = centre of the
        top-left pixel).
    config : LsmConfig, optional
    initial : (2, 3) or (3, 3) array, optional
        Start of the shaping (template offsets -> image pixels; its translation column is
        ignored, ``x, y`` is the start). Default: identity.

    Returns
    -------
    LsmResult
        ``converged`` False with a ``reason`` when the estimation fails (never raises on data).

    Raises
    ------
    InputError
        For malformed inputs (shapes, non-finite values, constant template).
    """
    cfg = config or LsmConfig()
    t = _check_template(template)
    img = _image(image, "image")
    if not (math.isfinite(x) and math.isfinite(y)):
        raise InputError(f"lsm_match: start position must be finite, got ({x}, {y})")
    p = _initial_params(float(x), float(y), initial)
    h, w = img.shape
    if not (0 <= x <= w - 1 and 0 <= y <= h - 1):
        return _failed(x, y, 0, "start outside the image")
    r = (0.0, 1.0)
    # radiometric start: match means and spreads
    it = 0
    stages = [cfg.coarse_sigma, 0.0] if cfg.coarse_sigma > 0 else [0.0]
    extras = None
    for s in stages:
        radius = _reach(t.shape, p) + cfg.max_shift + 3.0 * s + 2.0
        window, ox, oy = _crop(img, p[8], p[9], radius)
        if window is None:
            return _failed(p[8], p[9], it, "start outside the image")
        tw = _blur(t, s)
        ww = _blur(window, s)
        pc = p.copy()
        pc[8] -= ox
        pc[9] -= oy
        probe = np.zeros(t.shape)
        _normals(tw, ww, *_gradients(ww), pc, 0.0, 1.0, np.zeros((10, 10)), np.zeros(10), probe)
        ok = np.isfinite(probe)
        if ok.sum() > 3 and np.std(probe[ok]) > 0:
            r1 = float(np.std(tw[ok]) / np.std(probe[ok]))
            r = (float(tw[ok].mean() - r1 * probe[ok].mean()), r1)
        p, r, it, reason, extras = _lsm_stage(tw, ww, ox, oy, p, r, cfg, (x, y), it)
        if reason:
            return _failed(p[8] + ox, p[9] + oy, it, reason)
    assert extras is not None
    ssr, n, k, inv, res = extras
    dof = max(n - k, 1)
    sigma0 = math.sqrt(ssr / dof)
    cov = sigma0**2 * inv[-2:, -2:]
    corr = _ncc(t, res)
    converged = bool(corr >= cfg.min_correlation)
    return LsmResult(
        float(p[8]),
        float(p[9]),
        float(math.sqrt(max(cov[0, 0], 0.0))),
        float(math.sqrt(max(cov[1, 1], 0.0))),
        cov,
        corr,
        it,
        converged,
        "" if converged else "low correlation",
        np.array([[p[0], p[1], p[8]], [p[2], p[3], p[9]]]),
        (float(p[4]), float(p[5])),
        float(r[1]),
        float(r[0]),
        sigma0,
    )


def extract_template(image, x: float, y: float, half_size: int) -> np.ndarray:
    """The ``(2 half_size + 1)^2`` patch of ``image`` centred (bilinearly) on ``(x, y)``.

    Raises
    ------
    InputError
        When the patch does not lie inside the image.
    """
    img = _image(image, "image")
    if not (isinstance(half_size, int | np.integer) and half_size >= 1):
        raise InputError(f"half_size must be a positive integer, got {half_size!r}")
    n = 2 * int(half_size) + 1
    p = _initial_params(float(x), float(y), None)
    out = np.full((n, n), np.nan)
    if math.isfinite(x) and math.isfinite(y):
        window, ox, oy = _crop(img, x, y, half_size + 2)
        if window is not None:
            p[8] -= ox
            p[9] -= oy
            _normals(
                np.zeros((n, n)), window, window, window, p, 0.0, 1.0, np.zeros((10, 10)), np.zeros(10), out
            )
    if not np.all(np.isfinite(out)):
        raise InputError(
            f"template at ({x:.1f}, {y:.1f}) with half size {half_size} reaches outside the image"
        )
    return out


@dataclass(frozen=True)
class LsmMatches:
    """Outcome of :func:`lsm_match_many`, one row per match.

    ``xy`` (K, 2) and ``sigma`` (K, 2): the template centre in the image and its standard
    deviations (pixels); ``correlation`` (K,); ``converged`` (K,) bool (converged with at least
    the configured correlation); ``reason`` (K,) str, empty where converged.
    """

    xy: np.ndarray
    sigma: np.ndarray
    correlation: np.ndarray
    converged: np.ndarray
    reason: np.ndarray


def lsm_match_many(
    templates, image, starts, shapes=None, config: LsmConfig | None = None, template_index=None
) -> LsmMatches:
    """:func:`lsm_match` of many templates into one image in one compiled loop.

    The same estimation as :func:`lsm_match` with ``initial`` a (2, 2) shaping, for the
    single-stage case (``config.coarse_sigma`` must be 0). The image is read as given (any real
    dtype; only the windows around the starts are converted), templates are not checked for
    contrast (a constant one gives "singular").

    Parameters
    ----------
    templates : (T, h, w) array, h and w odd
    image : (H, W) array
    starts : (K, 2) float
        Start of every match, pixels.
    shapes : (K, 2, 2) float, optional
        Start of every shaping (template offsets -> pixels). Default: identity.
    config : LsmConfig, optional
    template_index : (K,) int, optional
        The template of every match (default: match k uses template k; then T == K). Templates
        no match uses are not read (they may hold NaN).

    Returns
    -------
    LsmMatches
    """
    cfg = config or LsmConfig(coarse_sigma=0.0)
    if cfg.coarse_sigma != 0:
        raise InputError("lsm_match_many: config.coarse_sigma must be 0 (single stage)")
    tm = np.ascontiguousarray(templates, dtype=np.float64)
    if tm.ndim != 3 or tm.shape[1] % 2 == 0 or tm.shape[2] % 2 == 0 or min(tm.shape[1:]) < 3:
        raise InputError(f"lsm_match_many: templates must be (T, h, w) with h, w odd, got {tm.shape}")
    img = _image(image, "image")
    st = np.ascontiguousarray(starts, dtype=np.float64).reshape(-1, 2)
    k = len(st)
    if shapes is None:
        sh = np.tile(np.eye(2), (k, 1, 1))
    else:
        sh = np.ascontiguousarray(shapes, dtype=np.float64)
    ti = np.arange(k) if template_index is None else np.asarray(template_index).astype(np.int64)
    if sh.shape != (k, 2, 2) or ti.shape != (k,):
        raise InputError(f"lsm_match_many: {k} starts need (K, 2, 2) shapes and (K,) template indices")
    if k and (ti.min() < 0 or ti.max() >= len(tm)):
        raise InputError(f"lsm_match_many: template indices must be in [0, {len(tm)})")
    if not (np.all(np.isfinite(st)) and np.all(np.isfinite(sh))):
        raise InputError("lsm_match_many: starts and shapes must be finite")
    if k and not np.all(np.isfinite(tm[np.unique(ti)])):
        raise InputError("lsm_match_many: a template used contains NaN or infinite values")
    local = _PROJECTIVE_LOCAL if cfg.projective else _AFFINE_LOCAL
    out = np.empty((k, 6))
    _match_many(
        tm,
        ti,
        img,
        st,
        sh,
        np.concatenate([local, _SHIFT]),
        len(local) - 2,
        cfg.max_iterations,
        float(cfg.tolerance),
        float(cfg.max_shift),
        out,
    )
    status = out[:, 5].astype(np.int64)
    corr = out[:, 4]
    ok = (status == 0) & (corr >= cfg.min_correlation)
    reason = np.array([_REASONS[c] for c in status], dtype=object)
    reason[(status == 0) & ~ok] = "low correlation"
    return LsmMatches(out[:, :2].copy(), out[:, 2:4].copy(), corr.copy(), ok, reason)


def extract_templates(image, centres, half_size: int) -> np.ndarray:
    """:func:`extract_template` at many centres: (K, n, n) with ``n = 2 half_size + 1``, all NaN
    for a template that reaches outside the image (or onto NaN values) instead of raising."""
    img = _image(image, "image")
    if not (isinstance(half_size, int | np.integer) and half_size >= 1):
        raise InputError(f"half_size must be a positive integer, got {half_size!r}")
    c = np.ascontiguousarray(centres, dtype=np.float64).reshape(-1, 2)
    n = 2 * int(half_size) + 1
    out = np.empty((len(c), n, n))
    _extract_many(img, c, out)
    bad = ~np.all(np.isfinite(out.reshape(len(c), -1)), axis=1)
    out[bad] = np.nan
    return out


# ---------------------------------------------------------------- MGCM


@njit
def _project_one(X, R, C, p, out):
    dx = X[0] - C[0]
    dy = X[1] - C[1]
    dz = X[2] - C[2]
    zc = R[2, 0] * dx + R[2, 1] * dy + R[2, 2] * dz
    if not zc > 0.0:
        out[0] = np.nan
        out[1] = np.nan
        return zc
    xc = R[0, 0] * dx + R[0, 1] * dy + R[0, 2] * dz
    yc = R[1, 0] * dx + R[1, 1] * dy + R[1, 2] * dz
    u, v = _distort_one(xc / zc, yc / zc, p)
    out[0] = u
    out[1] = v
    return zc


@njit
def _project_jac(X, R, C, p, uv, J):
    """Pixel ``uv`` (2,) of X and its derivative ``J`` (2, 3) by central differences."""
    depth = _project_one(X, R, C, p, uv)
    h = max(1e-6, 1e-6 * abs(depth))
    Y = X.copy()
    a = np.empty(2)
    b = np.empty(2)
    for k in range(3):
        Y[k] = X[k] + h
        _project_one(Y, R, C, p, a)
        Y[k] = X[k] - h
        _project_one(Y, R, C, p, b)
        Y[k] = X[k]
        J[0, k] = (a[0] - b[0]) / (2.0 * h)
        J[1, k] = (a[1] - b[1]) / (2.0 * h)


def _project_with_jacobian(X: np.ndarray, view: MgcmView) -> tuple[np.ndarray, np.ndarray]:
    """Pixel of X in a view and its (2, 3) derivative (NaN behind the camera)."""
    uv = np.empty(2)
    J = np.empty((2, 3))
    _project_jac(
        np.ascontiguousarray(X, dtype=np.float64),
        np.ascontiguousarray(view.R, dtype=np.float64),
        np.ascontiguousarray(view.C, dtype=np.float64).reshape(3),
        view.camera.params,
        uv,
        J,
    )
    return uv, J


def plane_shape(master: MgcmView, view: MgcmView, X, normal=(0.0, 0.0, 1.0)) -> np.ndarray:
    """Affine start (2, 2) of the shaping from ``master`` pixels to ``view`` pixels at ``X``.

    The local homography induced by the plane through ``X`` (local frame) with ``normal``
    (default horizontal: ground targets), linearised at the projection of ``X`` (central
    differences of one pixel). NaN when a ray misses the plane.
    """
    Xv = np.asarray(X, dtype=np.float64).reshape(3)
    nrm = np.asarray(normal, dtype=np.float64).reshape(3)
    uv0 = project_points(Xv[None], master.R, master.C, master.camera)[0]
    offs = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
    xy = undistort_points(uv0[None] + offs, master.camera)
    d = np.column_stack([xy, np.ones(4)]) @ np.asarray(master.R, dtype=np.float64)
    Cm = np.asarray(master.C, dtype=np.float64).reshape(3)
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = ((Xv - Cm) @ nrm) / (d @ nrm)
    pts = Cm[None] + lam[:, None] * d
    q = project_points(pts, view.R, view.C, view.camera)
    return np.column_stack([(q[0] - q[1]) / 2.0, (q[2] - q[3]) / 2.0])


def plane_shapes(points, normals, master, view, rotations, centers, cameras) -> np.ndarray:
    """:func:`plane_shape` for many (point, master image, view image) triples in one loop.

    ``points``, ``normals`` (K, 3) local frame; ``master``, ``view`` (K,) image indices into
    ``rotations`` (N, 3, 3), ``centers`` (N, 3) and ``cameras`` (N Camera). Returns (K, 2, 2),
    NaN where a ray misses the plane or a point is behind a camera.
    """
    X = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 3)
    nrm = np.ascontiguousarray(normals, dtype=np.float64).reshape(-1, 3)
    mi = np.asarray(master).astype(np.int64).reshape(-1)
    vi = np.asarray(view).astype(np.int64).reshape(-1)
    R = np.ascontiguousarray(rotations, dtype=np.float64).reshape(-1, 3, 3)
    C = np.ascontiguousarray(centers, dtype=np.float64).reshape(-1, 3)
    P = np.ascontiguousarray([c.params for c in cameras], dtype=np.float64).reshape(-1, 9)
    k = len(X)
    if not (len(nrm) == len(mi) == len(vi) == k and len(R) == len(C) == len(P)):
        raise InputError("plane_shapes: points, normals, master and view must have the same length")
    if k and (min(mi.min(), vi.min()) < 0 or max(mi.max(), vi.max()) >= len(R)):
        raise InputError(f"plane_shapes: image indices must be in [0, {len(R)})")
    out = np.empty((k, 2, 2))
    _plane_shapes(X, nrm, mi, vi, R, C, P, out)
    return out


def mgcm(
    template, views, X0, config: LsmConfig | None = None, master: int | None = None, initial_shapes=None
) -> MgcmResult:
    """Multi-image geometrically constrained least-squares matching.

    Parameters
    ----------
    template : (h, w) array, h and w odd
        The patch to find (its centre pixel is the point), e.g. from
        :func:`extract_template` on a master image that is also one of ``views``.
    views : sequence of MgcmView
        Oriented search images (at least two).
    X0 : (3,) float
        Start of the object point, local frame, metres.
    config : LsmConfig, optional
        ``max_shift`` bounds the movement of every projection from its start.
    master : int, optional
        Index of the view the template was cut from: the other views' shaping starts from the
        geometry (:func:`plane_shape` on the horizontal plane through ``X0``).
    initial_shapes : sequence of (2, 2) arrays, optional
        Start of every view's shaping (template offsets -> pixels); overrides ``master``.

    Returns
    -------
    MgcmResult
        The object point ``X`` (3,) with its covariance (3, 3) m^2 and per view the projection
        of ``X`` with its propagated covariance, the correlation, gain/offset and shape.
        ``converged`` False with a ``reason`` on failure.
    """
    cfg = config or LsmConfig()
    t = _check_template(template)
    X = np.asarray(X0, dtype=np.float64).reshape(-1)
    if X.shape != (3,) or not np.all(np.isfinite(X)):
        raise InputError(f"mgcm: X0 must be 3 finite numbers, got {X0!r}")
    views = list(views)
    if len(views) < 2:
        raise InputError(f"mgcm: needs at least two views, got {len(views)}")
    imgs = [_image(v.image, f"view {v.name or i!r} image") for i, v in enumerate(views)]
    local = _PROJECTIVE_LOCAL if cfg.projective else _AFFINE_LOCAL
    k = len(local)
    nv = len(views)
    starts = []
    for v in views:
        uv, _ = _project_with_jacobian(X, v)
        if not np.all(np.isfinite(uv)):
            return _mgcm_failed(X, nv, 0, f"X0 is behind view {v.name!r}")
        starts.append(uv)
    params = np.zeros((nv, 10))
    params[:, 0] = params[:, 3] = 1.0
    if initial_shapes is not None:
        shapes = [np.asarray(a, dtype=np.float64) for a in initial_shapes]
        if len(shapes) != nv or any(a.shape != (2, 2) or not np.all(np.isfinite(a)) for a in shapes):
            raise InputError(f"mgcm: initial_shapes must be {nv} finite (2, 2) arrays")
    elif master is not None:
        if not (isinstance(master, int | np.integer) and 0 <= master < nv):
            raise InputError(f"mgcm: master must be a view index in [0, {nv}), got {master!r}")
        shapes = [np.eye(2) if j == master else plane_shape(views[master], v, X) for j, v in enumerate(views)]
        if any(not np.all(np.isfinite(a)) for a in shapes):
            return _mgcm_failed(X, nv, 0, "a view's start shaping is undefined (ray parallel to the plane)")
    else:
        shapes = [np.eye(2)] * nv
    for j, a in enumerate(shapes):
        params[j, 0], params[j, 1], params[j, 2], params[j, 3] = a[0, 0], a[0, 1], a[1, 0], a[1, 1]
    radiometry = np.tile([0.0, 1.0], (nv, 1))
    it = 0
    stages = [cfg.coarse_sigma, 0.0] if cfg.coarse_sigma > 0 else [0.0]
    final = None
    for s in stages:
        tw = _blur(t, s)
        prepared = []
        for j, (v, img) in enumerate(zip(views, imgs, strict=True)):
            uv, _ = _project_with_jacobian(X, v)
            params[j, 8:] = uv
            radius = _reach(t.shape, params[j]) + cfg.max_shift + 3.0 * s + 2.0
            window, ox, oy = _crop(img, uv[0], uv[1], radius)
            if window is None:
                return _mgcm_failed(X, nv, it, f"view {v.name!r}: the point is outside the image")
            ww = _blur(window, s)
            gx, gy = _gradients(ww)
            prepared.append((ww, gx, gy, ox, oy))
            if it == 0:
                probe = np.zeros(t.shape)
                pc = params[j].copy()
                pc[8] -= ox
                pc[9] -= oy
                _normals(tw, ww, gx, gy, pc, 0.0, 1.0, np.zeros((10, 10)), np.zeros(10), probe)
                ok = np.isfinite(probe)
                if ok.sum() > 3 and np.std(probe[ok]) > 0:
                    r1 = float(np.std(tw[ok]) / np.std(probe[ok]))
                    radiometry[j] = (float(tw[ok].mean() - r1 * probe[ok].mean()), r1)
        for _ in range(cfg.max_iterations):
            it += 1
            n_unk = 3 + nv * k
            NN = np.zeros((n_unk, n_unk))
            bb = np.zeros(n_unk)
            ssr_total, n_total = 0.0, 0
            jac = []
            residual_patches = []
            for j, v in enumerate(views):
                ww, gx, gy, ox, oy = prepared[j]
                uv, A = _project_with_jacobian(X, v)
                if not np.all(np.isfinite(uv)) or not np.all(np.isfinite(A)):
                    return _mgcm_failed(X, nv, it, f"view {v.name!r}: the point left the field of view")
                params[j, 8:] = uv
                jac.append(A)
                pc = params[j].copy()
                pc[8] -= ox
                pc[9] -= oy
                N = np.zeros((10, 10))
                b = np.zeros(10)
                res = np.zeros(t.shape)
                ssr, n, outside = _normals(tw, ww, gx, gy, pc, radiometry[j, 0], radiometry[j, 1], N, b, res)
                if outside:
                    return _mgcm_failed(X, nv, it, f"view {v.name!r}: the template left the image")
                residual_patches.append(res)
                ssr_total += ssr
                n_total += n
                sl = slice(3 + j * k, 3 + (j + 1) * k)
                NLL = N[np.ix_(local, local)]
                NLS = N[np.ix_(local, _SHIFT)]
                NSS = N[np.ix_(_SHIFT, _SHIFT)]
                NN[:3, :3] += A.T @ NSS @ A
                NN[:3, sl] += A.T @ NLS.T
                NN[sl, :3] += NLS @ A
                NN[sl, sl] += NLL
                bb[:3] += A.T @ b[_SHIFT]
                bb[sl] += b[local]
            shape_idx = np.concatenate([3 + j * k + np.arange(k - 2) for j in range(nv)])
            sol = _solve(_damped(NN, shape_idx), bb)
            undamped = _solve(NN, bb)
            if sol is None:
                return _mgcm_failed(X, nv, it, "singular (no texture or parallel rays)")
            d = sol[0]
            inv = (undamped or sol)[1]
            X = X + d[:3]
            for j in range(nv):
                dl = np.zeros(10)
                dl[local] = d[3 + j * k : 3 + (j + 1) * k]
                params[j, :6] += dl[:6]
                radiometry[j] += dl[6:8]
            moves = []
            for j, v in enumerate(views):
                uv, _ = _project_with_jacobian(X, v)
                if not np.all(np.isfinite(uv)):
                    return _mgcm_failed(X, nv, it, f"view {v.name!r}: the point left the field of view")
                moves.append(float(np.hypot(*(uv - params[j, 8:]))))
                if float(np.hypot(*(uv - starts[j]))) > cfg.max_shift:
                    return _mgcm_failed(X, nv, it, f"view {v.name!r}: moved farther than max_shift")
                det = params[j, 0] * params[j, 3] - params[j, 1] * params[j, 2]
                if not 0.1 < abs(det) < 10.0 or radiometry[j, 1] <= 0:
                    return _mgcm_failed(X, nv, it, f"view {v.name!r}: degenerate shape")
                params[j, 8:] = uv
            if max(moves) < cfg.tolerance:
                final = (ssr_total, n_total, n_unk, inv, jac, residual_patches)
                break
        else:
            return _mgcm_failed(X, nv, it, "no convergence")
    assert final is not None
    ssr_total, n_total, n_unk, inv, jac, patches = final
    sigma0 = math.sqrt(ssr_total / max(n_total - n_unk, 1))
    covX = sigma0**2 * inv[:3, :3]
    results = []
    converged = True
    for j in range(nv):
        cov = jac[j] @ covX @ jac[j].T
        corr = _ncc(t, patches[j])
        view_ok = bool(corr >= cfg.min_correlation)
        converged = converged and view_ok
        results.append(
            LsmResult(
                float(params[j, 8]),
                float(params[j, 9]),
                float(math.sqrt(max(cov[0, 0], 0.0))),
                float(math.sqrt(max(cov[1, 1], 0.0))),
                cov,
                corr,
                it,
                view_ok,
                "" if view_ok else "low correlation",
                np.array(
                    [[params[j, 0], params[j, 1], params[j, 8]], [params[j, 2], params[j, 3], params[j, 9]]]
                ),
                (float(params[j, 4]), float(params[j, 5])),
                float(radiometry[j, 1]),
                float(radiometry[j, 0]),
                sigma0,
            )
        )
    reason = (
        ""
        if converged
        else "low correlation in "
        + ", ".join(repr(v.name) for v, r in zip(views, results, strict=True) if not r.converged)
    )
    return MgcmResult(X, covX, results, it, converged, reason, sigma0)


def _mgcm_failed(X, nv: int, it: int, reason: str) -> MgcmResult:
    nan = float("nan")
    views = [_failed(nan, nan, it, reason) for _ in range(nv)]
    return MgcmResult(
        np.asarray(X, dtype=np.float64).copy(), np.full((3, 3), np.nan), views, it, False, reason, nan
    )
