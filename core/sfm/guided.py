"""Guided registration of weakly connected images: relative orientation, scale from guided matches.

The problem
-----------
Resection (PnP) needs points of the block seen in the new image. An image
whose only *verified* link is a pair with one registered image ``p`` (the edge
of a block, a turn of the flight line, a small overlap between strips) often
has hardly any: its matches with ``p`` are two-view tracks, not triangulated
before the image is oriented, and plain descriptor matching against the other
images of the block failed (ratio test, too few inliers for a two-view
verification). The two-view geometry with ``p`` fixes the rotation of the
image and the *direction* of its baseline, not the baseline length: the
one-parameter family ``C_k(s) = C_p + s b`` remains. Taking ``s`` from an
assumption (a terrain height, the length of other baselines) would be a
guess.

The mechanism
-------------
``s`` is measured, with points of the block:

1. **Candidates.** A block point ``X`` (triangulated from registered images)
   projects into image ``k`` on a straight segment as ``s`` varies, its
   epipolar segment ``x(s) = pi(A - s T)`` with ``A = R_k (X - C_p)`` and
   ``T = R_k b``. Every feature of ``k`` within ``window_px`` of the segment
   is a geometric candidate, with its descriptor distance to the point (the
   smallest over the point's observations).
2. **Scale hypotheses and their significance.** For a hypothesis ``s`` a
   point counts as matched when its best descriptor in the window around
   ``x(s)`` lies within ``threshold_px`` of it, is closer than the
   ``descriptor_quantile`` of unrelated descriptor pairs (measured on the
   data) and passes a ratio test against the best candidate at another
   position in the window. The number of points that would match *by chance*
   is estimated from the same windows (feature density times the descriptor
   acceptance rate), and the hypothesis is scored by its number of false
   alarms ``NFA = n_hypotheses * P(Poisson(lambda) >= count)`` (a-contrario
   testing as in ORSA/AC-RANSAC). The best hypothesis is accepted only with
   at least ``min_points`` matched points and ``NFA <= max_nfa``.
3. **Refinement.** ``s`` is refined by least squares on the matched points.

The search range of ``s`` is bounded (not chosen) by the depths of the block
points seen in ``p``: the points of the pair lie at depths within the range
``p`` sees, widened by ``scale_range_factor``.

The caller (:mod:`.incremental`) then verifies the pose in a local
adjustment (only the new image free), adds the matched observations to the
tracks and continues the incremental reconstruction. An image whose link is
purely two-view (no block point visible in the overlap) is *not* registered:
no hypothesis is significant.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..jit import njit


@dataclass
class GuidedConfig:
    """Options of the guided registration (pixels at full resolution).

    Attributes
    ----------
    enabled : bool
        Try guided registration when resection stalls.
    min_partner_tracks : int
        Fewest shared observations (two-view inliers) with a registered partner.
    max_partners : int
        Registered partners tried per image (most shared tracks first).
    threshold_px : float
        Largest distance between a guided match and the point's projection.
    window_px : float
        Radius of the window of the ratio test and of the density estimate.
    ratio : float
        Ratio test of a guided match against the best candidate at another position.
    descriptor_quantile : float
        Descriptor acceptance: the distance below which this fraction of
        unrelated (point, feature) pairs falls.
    duplicate_px : float
        Features closer than this are one position (SIFT gives several
        orientations at one keypoint).
    min_points : int
        Fewest matched block points to accept a scale.
    max_nfa : float
        Largest number of false alarms of the accepted scale hypothesis.
    scale_range_factor : float
        Widening of the depth-based search range of the baseline length.
    max_hypotheses : int
        Scale hypotheses evaluated (the candidates' own scales, thinned).
    """

    enabled: bool = True
    min_partner_tracks: int = 30
    max_partners: int = 3
    threshold_px: float = 2.0
    window_px: float = 8.0
    ratio: float = 0.9
    descriptor_quantile: float = 0.05
    duplicate_px: float = 1.5
    min_points: int = 6
    max_nfa: float = 1e-3
    scale_range_factor: float = 2.0
    max_hypotheses: int = 4000

    def validate(self) -> None:
        for name in ("threshold_px", "window_px", "duplicate_px", "scale_range_factor", "max_nfa"):
            v = getattr(self, name)
            if not (isinstance(v, int | float) and np.isfinite(v) and v > 0):
                raise InputError(f"guided.{name} must be a positive number, got {v!r}")
        if self.window_px < self.threshold_px:
            raise InputError("guided.window_px must not be smaller than guided.threshold_px")
        if not 0 < self.ratio <= 1:
            raise InputError(f"guided.ratio must be in (0, 1], got {self.ratio!r}")
        if not 0 < self.descriptor_quantile < 1:
            raise InputError(
                f"guided.descriptor_quantile must be in (0, 1), got {self.descriptor_quantile!r}"
            )
        for name in ("min_partner_tracks", "max_partners", "min_points", "max_hypotheses"):
            v = getattr(self, name)
            if not isinstance(v, int | np.integer) or v < 1:
                raise InputError(f"guided.{name} must be a positive integer, got {v!r}")
        if self.min_partner_tracks < 8:
            raise InputError("guided.min_partner_tracks must be at least 8 (relative orientation)")


@dataclass
class ScaleSearch:
    """Result of :func:`search_scale`.

    Attributes
    ----------
    ok : bool
        A significant hypothesis with enough points was found.
    reason : str
        Why not ("" when ok).
    scale : float
        Baseline length ``s`` (NaN when none).
    count : int
        Matched block points at ``scale``.
    expected_false : float
        Expected number of chance matches at ``scale`` (``lambda``).
    log10_nfa : float
        ``log10`` of the number of false alarms of the best hypothesis.
    n_hypotheses, n_candidates : int
    points, features : (count,) int64
        Matched point indices (rows of ``A``) and feature indices.
    errors_px : (count,) float64
        Distance of each match to the point's projection at ``scale``.
    descriptor_cap : float
        Descriptor distance acceptance threshold used.
    """

    ok: bool
    reason: str = ""
    scale: float = float("nan")
    count: int = 0
    expected_false: float = float("nan")
    log10_nfa: float = float("inf")
    n_hypotheses: int = 0
    n_candidates: int = 0
    points: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    features: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    errors_px: np.ndarray = field(default_factory=lambda: np.zeros(0))
    descriptor_cap: float = float("nan")

    def summary(self) -> dict:
        return {
            "ok": self.ok,
            "reason": self.reason,
            "scale": self.scale,
            "points": self.count,
            "expected_chance_matches": self.expected_false,
            "log10_nfa": self.log10_nfa,
            "hypotheses": self.n_hypotheses,
            "candidates": self.n_candidates,
        }


@njit
def _count_line_candidates(A, T, u, s_lo, s_hi, max_perp):
    """Number of (point, feature) pairs within ``max_perp`` of the point's epipolar segment, per point."""
    n = A.shape[0]
    m = u.shape[0]
    counts = np.zeros(n, np.int64)
    for i in range(n):
        lx = A[i, 1] * T[2] - A[i, 2] * T[1]
        ly = A[i, 2] * T[0] - A[i, 0] * T[2]
        lz = A[i, 0] * T[1] - A[i, 1] * T[0]
        nl = np.sqrt(lx * lx + ly * ly)
        if nl < 1e-15:
            continue
        # the segment's end points bound the search box
        z0 = A[i, 2] - s_lo * T[2]
        z1 = A[i, 2] - s_hi * T[2]
        if z0 <= 0.0 and z1 <= 0.0:
            continue
        for j in range(m):
            d = abs(lx * u[j, 0] + ly * u[j, 1] + lz) / nl
            if d < max_perp:
                s = _fit_scale(A[i], T, u[j, 0], u[j, 1])
                if s_lo <= s <= s_hi and A[i, 2] - s * T[2] > 0.0:
                    counts[i] += 1
    return counts


@njit
def _fit_scale(a, T, ux, uy):
    """``s`` minimising ``|(a - s T) x (u, 1)|^2`` (algebraic projection error)."""
    # a x u and T x u with u = (ux, uy, 1)
    ax = a[1] - a[2] * uy
    ay = a[2] * ux - a[0]
    az = a[0] * uy - a[1] * ux
    tx = T[1] - T[2] * uy
    ty = T[2] * ux - T[0]
    tz = T[0] * uy - T[1] * ux
    den = tx * tx + ty * ty + tz * tz
    if den < 1e-30:
        return np.nan
    return (ax * tx + ay * ty + az * tz) / den


@njit
def _fill_line_candidates(A, T, u, s_lo, s_hi, max_perp, offsets, feat, scale):
    n = A.shape[0]
    m = u.shape[0]
    for i in range(n):
        k = offsets[i]
        if offsets[i + 1] == k:
            continue
        lx = A[i, 1] * T[2] - A[i, 2] * T[1]
        ly = A[i, 2] * T[0] - A[i, 0] * T[2]
        lz = A[i, 0] * T[1] - A[i, 1] * T[0]
        nl = np.sqrt(lx * lx + ly * ly)
        for j in range(m):
            d = abs(lx * u[j, 0] + ly * u[j, 1] + lz) / nl
            if d < max_perp:
                s = _fit_scale(A[i], T, u[j, 0], u[j, 1])
                if s_lo <= s <= s_hi and A[i, 2] - s * T[2] > 0.0:
                    feat[k] = j
                    scale[k] = s
                    k += 1


@njit
def _min_descriptor_distance(cand_pt, cand_fe, pt_offsets, pt_desc, feat_desc, out):
    """Smallest L2 distance between feature ``cand_fe`` and the descriptors of point ``cand_pt``."""
    dim = feat_desc.shape[1]
    for c in range(cand_pt.shape[0]):
        p = cand_pt[c]
        f = cand_fe[c]
        best = np.inf
        for o in range(pt_offsets[p], pt_offsets[p + 1]):
            acc = 0.0
            for d in range(dim):
                t = pt_desc[o, d] - feat_desc[f, d]
                acc += t * t
            if acc < best:
                best = acc
        out[c] = np.sqrt(best)


@njit
def _scan_scales(hyps, A, T, u, offsets, feat, dist, group, thr, win, ratio, cap, q_desc, counts, lam):
    """Matched points and expected chance matches for every scale hypothesis.

    Candidates of point ``i`` are ``offsets[i]:offsets[i+1]``, sorted by descriptor distance.
    ``thr`` and ``win`` are in normalised units (pixels / focal length).
    """
    n = offsets.shape[0] - 1
    area = (thr * thr) / (win * win)
    for h in range(hyps.shape[0]):
        s = hyps[h]
        c = 0
        lm = 0.0
        for i in range(n):
            a, b = offsets[i], offsets[i + 1]
            if a == b:
                continue
            z = A[i, 2] - s * T[2]
            if z <= 0.0:
                continue
            px = (A[i, 0] - s * T[0]) / z
            py = (A[i, 1] - s * T[1]) / z
            n_win = 0
            best = -1
            second = np.inf
            for k in range(a, b):
                dx = u[feat[k], 0] - px
                dy = u[feat[k], 1] - py
                e2 = dx * dx + dy * dy
                if e2 < win * win:
                    n_win += 1
                    if best < 0:
                        best = k
                    elif second == np.inf and group[feat[k]] != group[feat[best]]:
                        second = dist[k]
            if n_win == 0:
                continue
            lm += n_win * area * q_desc
            if best < 0:
                continue
            dx = u[feat[best], 0] - px
            dy = u[feat[best], 1] - py
            if dx * dx + dy * dy < thr * thr and dist[best] < cap and dist[best] < ratio * second:
                c += 1
        counts[h] = c
        lam[h] = lm


@njit
def _matches_at(s, A, T, u, offsets, feat, dist, group, thr, win, ratio, cap, out_pt, out_fe, out_err):
    """Matched points (and their features, errors) at one scale; returns their number."""
    n = offsets.shape[0] - 1
    m = 0
    for i in range(n):
        a, b = offsets[i], offsets[i + 1]
        if a == b:
            continue
        z = A[i, 2] - s * T[2]
        if z <= 0.0:
            continue
        px = (A[i, 0] - s * T[0]) / z
        py = (A[i, 1] - s * T[1]) / z
        best = -1
        second = np.inf
        for k in range(a, b):
            dx = u[feat[k], 0] - px
            dy = u[feat[k], 1] - py
            if dx * dx + dy * dy < win * win:
                if best < 0:
                    best = k
                elif second == np.inf and group[feat[k]] != group[feat[best]]:
                    second = dist[k]
        if best < 0:
            continue
        dx = u[feat[best], 0] - px
        dy = u[feat[best], 1] - py
        e2 = dx * dx + dy * dy
        if e2 < thr * thr and dist[best] < cap and dist[best] < ratio * second:
            out_pt[m] = i
            out_fe[m] = feat[best]
            out_err[m] = np.sqrt(e2)
            m += 1
    return m


def _duplicate_groups(xy: np.ndarray, radius: float) -> np.ndarray:
    """Group id per feature: features closer than ``radius`` share the smallest index of their cluster."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    n = len(xy)
    if n == 0:
        return np.zeros(0, np.int64)
    pairs = cKDTree(xy).query_pairs(radius, output_type="ndarray")
    if len(pairs) == 0:
        return np.arange(n, dtype=np.int64)
    g = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(g, directed=False)
    return label.astype(np.int64)


def _log10_poisson_sf(count: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """``log10 P(Poisson(lam) >= count)``."""
    from scipy.stats import poisson

    with np.errstate(divide="ignore"):
        out = poisson.logsf(np.asarray(count) - 1, np.maximum(np.asarray(lam, float), 1e-12)) / np.log(10.0)
    return np.clip(np.where(np.asarray(count) <= 0, 0.0, out), -300.0, 0.0)


def search_scale(
    A,
    T,
    u,
    focal_px: float,
    feature_xy,
    feature_desc,
    point_offsets,
    point_desc,
    s_range: tuple[float, float],
    config: GuidedConfig | None = None,
    seed: int = 0,
) -> ScaleSearch:
    """Baseline length of a one-parameter pose family from guided matches of block points.

    Parameters
    ----------
    A : (N, 3) float64
        Block points in the new camera's frame for ``s = 0``: ``R_k (X - C_p)``.
    T : (3,) float64
        Baseline direction in the new camera's frame (``R_k b``); the camera
        coordinates of point ``i`` are ``A[i] - s T``.
    u : (M, 2) float64
        Normalised (undistorted) image coordinates of the new image's features.
    focal_px : float
        Focal length, pixels (converts the pixel tolerances).
    feature_xy : (M, 2) float64
        Pixel positions of the features (duplicate detection).
    feature_desc : (M, D) float32
        Their descriptors.
    point_offsets : (N + 1,) int64; point_desc : (K, D) float32
        Descriptors of the observations of point ``i``: ``point_desc[point_offsets[i]:point_offsets[i+1]]``.
    s_range : (lo, hi)
        Search range of ``s`` (positive).
    config : GuidedConfig, optional
    seed : int
        Seed of the sample of unrelated descriptor pairs.

    Returns
    -------
    ScaleSearch
        Never raises for an unsuccessful search (``ok`` False with a reason).
    """
    cfg = config or GuidedConfig()
    cfg.validate()
    A = np.ascontiguousarray(np.asarray(A, np.float64).reshape(-1, 3))
    T = np.ascontiguousarray(np.asarray(T, np.float64).reshape(3))
    u = np.ascontiguousarray(np.asarray(u, np.float64).reshape(-1, 2))
    fdesc = np.ascontiguousarray(np.asarray(feature_desc, np.float32))
    pdesc = np.ascontiguousarray(np.asarray(point_desc, np.float32))
    poff = np.asarray(point_offsets, np.int64).reshape(-1)
    if len(poff) != len(A) + 1 or len(fdesc) != len(u) or len(feature_xy) != len(u):
        raise InputError("search_scale: inconsistent point / feature arrays")
    s_lo, s_hi = float(s_range[0]), float(s_range[1])
    if not (0 < s_lo < s_hi and np.isfinite(s_hi)):
        raise InputError(f"search_scale: s_range must be 0 < lo < hi, got {s_range!r}")
    if not focal_px > 0:
        raise InputError("search_scale: focal_px must be positive")
    thr = cfg.threshold_px / focal_px
    win = cfg.window_px / focal_px
    valid_u = np.all(np.isfinite(u), axis=1)
    u_k = np.where(valid_u[:, None], u, 1e9)  # undistortion failures never match
    # points without a descriptor can never match: no candidates for them
    per_point = np.zeros(len(A), np.int64)
    has_desc = np.flatnonzero(np.diff(poff) > 0)
    per_point[has_desc] = _count_line_candidates(A[has_desc], T, u_k, s_lo, s_hi, win)
    offsets = np.concatenate([[0], np.cumsum(per_point)]).astype(np.int64)
    n_cand = int(offsets[-1])
    if n_cand == 0:
        return ScaleSearch(False, "no block point projects near a feature of the image in the search range")
    feat = np.zeros(n_cand, np.int64)
    scale = np.zeros(n_cand)
    _fill_line_candidates(A, T, u_k, s_lo, s_hi, win, offsets, feat, scale)
    cand_pt = np.repeat(np.arange(len(A), dtype=np.int64), per_point)
    dist = np.zeros(n_cand, np.float32)
    _min_descriptor_distance(cand_pt, feat, poff, pdesc, fdesc, dist)
    # descriptor acceptance from unrelated pairs: random point (with candidates) x random feature
    rng = np.random.default_rng(seed)
    pts_with = np.flatnonzero(per_point > 0)
    n_s = 4000
    rp = pts_with[rng.integers(0, len(pts_with), n_s)]
    rf = rng.integers(0, len(u), n_s).astype(np.int64)
    rd = np.zeros(n_s, np.float32)
    _min_descriptor_distance(rp, rf, poff, pdesc, fdesc, rd)
    cap = float(np.quantile(rd, cfg.descriptor_quantile))
    # candidates of every point sorted by descriptor distance
    order = np.lexsort((dist, cand_pt))
    feat, scale, dist = feat[order], scale[order], dist[order]
    group = _duplicate_groups(np.asarray(feature_xy, np.float64), cfg.duplicate_px)
    # hypotheses: the scales of descriptor-plausible candidates
    hyps = np.unique(scale[dist < cap])
    if len(hyps) == 0:
        return ScaleSearch(
            False, "no candidate passes the descriptor test", n_candidates=n_cand, descriptor_cap=cap
        )
    if len(hyps) > cfg.max_hypotheses:
        hyps = hyps[np.linspace(0, len(hyps) - 1, cfg.max_hypotheses).round().astype(np.int64)]
    counts = np.zeros(len(hyps), np.int64)
    lam = np.zeros(len(hyps))
    args = (A, T, u_k, offsets, feat, dist, group, thr, win, cfg.ratio, cap)
    _scan_scales(hyps, *args, cfg.descriptor_quantile, counts, lam)
    lnfa = np.log10(len(hyps)) + _log10_poisson_sf(counts, lam)
    best = int(np.lexsort((-counts, lnfa))[0])
    s = float(hyps[best])
    # refine s by least squares on the matched points, then match again
    for _ in range(3):
        pts, fes, errs = _matches(s, args, len(A))
        if len(pts) < 2:
            break
        s = _refine_scale(s, A[pts], T, u_k[fes])
    pts, fes, errs = _matches(s, args, len(A))
    c1 = np.zeros(1, np.int64)
    l1 = np.zeros(1)
    _scan_scales(np.array([s]), *args, cfg.descriptor_quantile, c1, l1)
    lnfa_s = float(np.log10(len(hyps)) + _log10_poisson_sf(c1, l1)[0])
    res = ScaleSearch(
        True,
        scale=s,
        count=len(pts),
        expected_false=float(l1[0]),
        log10_nfa=lnfa_s,
        n_hypotheses=len(hyps),
        n_candidates=n_cand,
        points=pts,
        features=fes,
        errors_px=errs * focal_px,
        descriptor_cap=cap,
    )
    if res.count < cfg.min_points:
        res.ok = False
        res.reason = f"{res.count} guided matches at the best scale (< {cfg.min_points})"
    elif res.log10_nfa > np.log10(cfg.max_nfa):
        res.ok = False
        res.reason = (
            f"best scale not significant ({res.count} matches, {res.expected_false:.2f} expected by chance, "
            f"log10 NFA {res.log10_nfa:.1f})"
        )
    return res


def _matches(s, args, n):
    out_pt = np.zeros(n, np.int64)
    out_fe = np.zeros(n, np.int64)
    out_err = np.zeros(n)
    m = _matches_at(float(s), *args, out_pt, out_fe, out_err)
    return out_pt[:m], out_fe[:m], out_err[:m]


def _refine_scale(s: float, A: np.ndarray, T: np.ndarray, u: np.ndarray) -> float:
    """Gauss-Newton on ``sum |pi(A - s T) - u|^2`` over one unknown."""
    for _ in range(10):
        P = A - s * T
        z = P[:, 2]
        if np.any(z <= 0):
            break
        x = P[:, :2] / z[:, None]
        r = (x - u).ravel()
        # d x / d s = (-T_xy z + P_xy T_z) / z^2
        J = ((-T[:2][None, :] * z[:, None] + P[:, :2] * T[2]) / (z[:, None] ** 2)).ravel()
        den = float(J @ J)
        if den <= 0:
            break
        step = -float(J @ r) / den
        s_new = s + step
        if not np.isfinite(s_new) or s_new <= 0:
            break
        s = s_new
        if abs(step) < 1e-9 * max(abs(s), 1.0):
            break
    return float(s)


def relative_pose(xn_k: np.ndarray, xn_p: np.ndarray, focal_px: float, threshold_px: float, seed: int = 0):
    """Relative orientation of image k (as the pair's frame) to image p from normalised matches.

    Returns
    -------
    R, t : (3, 3), (3,) or None
        ``x_p ~ R x_k + t`` (camera-k axes as world), ``|t| = 1``; None when it fails.
    inliers : (N,) bool
    median_angle_deg : float
        Median intersection angle of the inlier rays.
    """
    import cv2

    from .twoview import _median_angle, refine_pose

    n = len(xn_k)
    none = (None, None, np.zeros(n, bool), float("nan"))
    if n < 8:
        return none
    cv2.setRNGSeed(int(seed))
    try:
        E, mask = cv2.findEssentialMat(
            xn_k, xn_p, np.eye(3), method=cv2.USAC_MAGSAC, prob=0.9999, threshold=threshold_px / focal_px
        )
    except cv2.error:
        return none
    if E is None or E.shape != (3, 3) or mask is None:
        return none
    try:
        _, R, t, pmask = cv2.recoverPose(E, xn_k, xn_p, np.eye(3), mask=mask.copy())
    except cv2.error:
        return none
    inl = pmask.ravel() > 0
    if inl.sum() < 8:
        return none
    R, t = refine_pose(
        np.asarray(R, float), np.asarray(t, float).ravel(), xn_k[inl], xn_p[inl], threshold_px / focal_px
    )
    return R, np.asarray(t, float).ravel(), inl, _median_angle(xn_k[inl], xn_p[inl], R, t)
