"""Descriptor matching (ratio test, mutual check) and matching of image pairs.

:func:`match_descriptors` finds, for every descriptor of the first set, its
two nearest neighbours in the second (exact brute force, one float32 matrix
product giving both directions and a numba top-2 scan, up to ``bf_max``
descriptors; FLANN randomised kd-trees beyond), keeps it when ``d1 < ratio * d2``
(Lowe's ratio test on L2 distances) and, with ``cross_check``, only when the
first set's descriptor is also the nearest neighbour of its match (mutual
nearest neighbours). :func:`match_pairs` runs that and the robust two-view
geometry (:mod:`.twoview`) over a list of image pairs.

The cost of a pair grows with the product of the two feature counts, yet a feature can only
match near where the other image sees the same ground. :func:`match_pairs` therefore first
matches the largest ``overlap_features`` of each image and fits a homography to them with a
loose threshold (:func:`find_overlap`). Each feature of the first image is then compared only
with the features of the second that lie within a window about its mapped position
(:func:`match_windowed`): the window's radius is ``window_factor`` times the 95th percentile
of the coarse matches' distances to the homography (the parallax of the relief and the
homography's error, measured on the pair itself), between ``window_min`` and
``overlap_margin`` of the image's larger side. On the 12 MP scale block that is about 1 % of
the whole product, and more pairs' true matches pass the ratio test, which meets fewer
look-alikes. Pairs whose coarse pass finds fewer than ``overlap_min_coarse`` matches are taken
as not overlapping and not matched further (on that block such pairs never verified, and
matched whole they were three quarters of the matching time); pairs where the coarse pass finds
matches but no homography (a scene too 3-D for one) are matched whole, as before.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..geometry.camera import Camera
from ..jit import fastjit
from ..progress import Progress, as_progress
from .features import Features
from .twoview import TwoViewConfig, TwoViewResult, estimate_two_view


@dataclass
class MatchConfig:
    """Options of :func:`match_descriptors`.

    Attributes
    ----------
    ratio : float
        Lowe ratio test threshold on distances (0 < ratio <= 1).
    cross_check : bool
        Keep only mutual nearest neighbours.
    method : str
        ``"auto"`` (brute force when both sets have at most ``bf_max``
        descriptors, FLANN otherwise), ``"flann"`` or ``"bf"``.
    bf_max : int
        Largest set size matched by brute force with ``"auto"``.
    flann_trees, flann_checks : int
        FLANN kd-tree index: number of trees and leaves checked per query.
    """

    ratio: float = 0.8
    cross_check: bool = True
    method: str = "auto"
    bf_max: int = 8000
    flann_trees: int = 4
    flann_checks: int = 64
    #: :func:`match_pairs`: largest features of a coarse first pass that finds where two images
    #: overlap (:func:`overlap_rows`); 0 matches every feature against every other.
    overlap_features: int = 1500
    #: Margin around the other image's frame, mapped by the coarse homography, as a share of
    #: that image's larger side (parallax of relief and off-plane objects, obliques); also the
    #: largest window radius of :func:`match_windowed`.
    overlap_margin: float = 0.15
    #: Window radius of :func:`match_windowed` as a multiple of the 95th percentile of the coarse
    #: matches' distances to the homography; 0 searches the whole overlap (no windows).
    window_factor: float = 3.0
    #: Smallest window radius, as a share of the other image's larger side.
    window_min: float = 0.02
    #: :func:`match_pairs`: a pair whose coarse pass finds fewer matches is taken as not
    #: overlapping and is not matched whole (0: every pair without a homography is matched whole).
    #: Unrelated views find a few chance matches; a verified pair needs ``min_inliers`` (20).
    overlap_min_coarse: int = 12

    def validate(self) -> None:
        if not (isinstance(self.ratio, int | float) and 0 < self.ratio <= 1):
            raise InputError(f"ratio must be in (0, 1], got {self.ratio!r}")
        if self.method not in ("auto", "flann", "bf"):
            raise InputError(f"method must be 'auto', 'flann' or 'bf', got {self.method!r}")
        for n in ("bf_max", "flann_trees", "flann_checks"):
            v = getattr(self, n)
            if not isinstance(v, int | np.integer) or v < 1:
                raise InputError(f"{n} must be a positive integer, got {v!r}")
        for n in ("overlap_features", "overlap_min_coarse"):
            v = getattr(self, n)
            if not isinstance(v, int | np.integer) or v < 0:
                raise InputError(f"{n} must be an integer >= 0, got {v!r}")
        if not (isinstance(self.overlap_margin, int | float) and 0 <= self.overlap_margin <= 10):
            raise InputError(f"overlap_margin must be in [0, 10], got {self.overlap_margin!r}")
        if not (isinstance(self.window_factor, int | float) and 0 <= self.window_factor <= 100):
            raise InputError(f"window_factor must be in [0, 100], got {self.window_factor!r}")
        if not (isinstance(self.window_min, int | float) and 0 < self.window_min <= 10):
            raise InputError(f"window_min must be in (0, 10], got {self.window_min!r}")


def _products(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a @ b.T`` (float32, C order) through SciPy's Fortran BLAS.

    Inside QGIS, GSL's reference CBLAS (``libgslcblas``, loaded by QGIS) comes first
    in the process and numpy's ``cblas_sgemm`` binds to it: the descriptor product
    ran about 20 times slower in ``qgis_process`` than in Python. SciPy calls the
    Fortran ``sgemm_`` of the system BLAS (OpenBLAS), which GSL does not provide.
    """
    try:
        from scipy.linalg.blas import sgemm
    except ImportError:  # pragma: no cover - SciPy is a dependency
        return a @ b.T
    # (b a^T)^T, computed in Fortran order, is a @ b.T in C order without a copy
    return sgemm(1.0, b, a, trans_b=True).T


def _brute_force(a: np.ndarray, b: np.ndarray, block: int = 1024):
    """Exact 2-NN of rows of ``a`` in ``b`` and 1-NN of rows of ``b`` in ``a`` (one product)."""
    na = np.einsum("ij,ij->i", a, a)
    nb = np.einsum("ij,ij->i", b, b)
    best_i = np.empty(len(a), np.int64)
    best_d = np.empty((len(a), 2), np.float32)
    col_best = np.full(len(b), np.inf, np.float32)
    col_arg = np.full(len(b), -1, np.int64)
    cols = np.arange(len(b), dtype=np.int64)
    for r0 in range(0, len(a), block):
        rows = np.arange(r0, min(r0 + block, len(a)), dtype=np.int64)
        _top2_window(_products(a[r0 : r0 + block], b), na, nb, rows, cols, best_i, best_d, col_best, col_arg)
    d = np.sqrt(np.maximum(best_d, 0.0))
    return best_i, d, col_arg


def _ratio_and_mutual(best, dist, back, cfg: MatchConfig) -> tuple[np.ndarray, np.ndarray]:
    """Rows ``i1`` and their matches ``i2`` that pass the ratio test (``dist`` (N, 2): nearest
    and second-nearest distances of each row, ``best`` the nearest's index, -1 when none) and,
    with ``cross_check``, the mutual check (``back``: the nearest row of each column)."""
    i1 = np.flatnonzero((best >= 0) & (dist[:, 0] < cfg.ratio * dist[:, 1]))
    i2 = best[i1]
    if cfg.cross_check:
        keep = back[i2] == i1
        i1, i2 = i1[keep], i2[keep]
    return i1, i2


def _matcher(cfg: MatchConfig):
    import cv2

    # algorithm 1 = FLANN_INDEX_KDTREE
    index: dict[str, bool | int | float | str] = {"algorithm": 1, "trees": int(cfg.flann_trees)}
    return cv2.FlannBasedMatcher(index, {"checks": int(cfg.flann_checks)})


def _knn(matcher, q: np.ndarray, t: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Indices and distances (len(q), k) of the k nearest rows of ``t`` (-1 / inf when missing)."""
    idx = np.full((len(q), k), -1, np.int64)
    dist = np.full((len(q), k), np.inf, np.float32)
    if len(q) == 0 or len(t) == 0:
        return idx, dist
    for i, ms in enumerate(matcher.knnMatch(q, t, k=min(k, len(t)))):
        for j, m in enumerate(ms):
            idx[i, j] = m.trainIdx
            dist[i, j] = m.distance
    return idx, dist


def match_descriptors(d1, d2, config: MatchConfig | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Match two descriptor sets.

    Parameters
    ----------
    d1 : (N1, D) float32
    d2 : (N2, D) float32
    config : MatchConfig, optional

    Returns
    -------
    matches : (M, 2) int64
        Index pairs ``(i1, i2)``, sorted by ``i1``.
    distances : (M,) float32
        L2 descriptor distances.
    """
    import cv2

    cfg = config or MatchConfig()
    cfg.validate()
    a = np.ascontiguousarray(np.asarray(d1, dtype=np.float32))
    b = np.ascontiguousarray(np.asarray(d2, dtype=np.float32))
    if a.ndim != 2 or b.ndim != 2 or (len(a) and len(b) and a.shape[1] != b.shape[1]):
        raise InputError(f"match_descriptors: expected (N, D) arrays of equal D, got {a.shape} and {b.shape}")
    empty = (np.zeros((0, 2), np.int64), np.zeros(0, np.float32))
    if len(a) < 1 or len(b) < 2:
        return empty
    use_bf = cfg.method == "bf" or (cfg.method == "auto" and max(len(a), len(b)) <= cfg.bf_max)
    if use_bf:
        best, dist, back = _brute_force(a, b)
        i1, i2 = _ratio_and_mutual(best, dist, back, cfg)
        if len(i1) == 0:
            return empty
        return np.column_stack([i1, i2]).astype(np.int64), dist[i1, 0]
    cv2.setRNGSeed(0)
    idx, dist = _knn(_matcher(cfg), a, b, 2)
    ok = (idx[:, 0] >= 0) & (dist[:, 0] < cfg.ratio * dist[:, 1])
    i1 = np.flatnonzero(ok)
    i2 = idx[i1, 0]
    if cfg.cross_check and len(i1):
        # one query per distinct candidate of the second set
        u2, inv = np.unique(i2, return_inverse=True)
        back, _ = _knn(_matcher(cfg), b[u2], a, 1)
        keep = back[inv, 0] == i1
        i1, i2 = i1[keep], i2[keep]
    if len(i1) == 0:
        return empty
    return np.column_stack([i1, i2]).astype(np.int64), dist[i1, 0]


#: Fewest coarse matches, and homography inliers among them, that locate an overlap.
OVERLAP_MIN_MATCHES = 24
#: Share of the coarse matches a homography must explain (within 3 % of the image diagonal)
#: before the overlap it maps is trusted; a strongly 3-D pair (close range) fails and is matched whole.
OVERLAP_MIN_INLIER_SHARE = 0.5
#: The restricted product must save at least this share of the full one, else the pair is matched whole.
OVERLAP_MIN_SAVING = 0.25


def _inside(xy: np.ndarray, H: np.ndarray, width: int, height: int, margin: float) -> np.ndarray:
    """Points mapped by ``H`` that land in the ``width x height`` frame grown by ``margin`` px."""
    q = np.column_stack([xy, np.ones(len(xy))]) @ H.T
    w = q[:, 2]
    ok = w > 1e-9
    u = np.where(ok, q[:, 0] / np.where(ok, w, 1.0), np.nan)
    v = np.where(ok, q[:, 1] / np.where(ok, w, 1.0), np.nan)
    with np.errstate(invalid="ignore"):
        return ok & (u >= -margin) & (u <= width + margin) & (v >= -margin) & (v <= height + margin)


@dataclass
class Overlap:
    """Where two images overlap, from :func:`find_overlap` (full-resolution pixels).

    Attributes
    ----------
    H : (3, 3)
        Homography from the first image to the second, fitted to the coarse matches.
    rows_i, rows_j : (N,) int64
        Features of each image inside the other's frame mapped through ``H``, grown by
        ``overlap_margin`` (increasing).
    residual_q95 : float
        95th percentile of the coarse inliers' distances to ``H`` in the second image, pixels.
    """

    H: np.ndarray
    rows_i: np.ndarray
    rows_j: np.ndarray
    residual_q95: float


def find_overlap(fi: Features, fj: Features, config: MatchConfig | None = None) -> Overlap | None:
    """The homography and common part of two images from a coarse pass, or None.

    The coarse pass matches the ``overlap_features`` largest features of each image and fits a
    homography to them with a loose threshold (3 % of the diagonal). Returns None when the pair
    should be matched whole: too few features or coarse matches, a homography that explains less
    than :data:`OVERLAP_MIN_INLIER_SHARE` of them (strong relief, close range), or a frame that
    maps across the horizon. Deterministic (seeded).
    """
    cfg = config or MatchConfig()
    cfg.validate()
    return _coarse(fi, fj, cfg)[0]


def _coarse(fi: Features, fj: Features, cfg: MatchConfig) -> tuple[Overlap | None, int]:
    """:func:`find_overlap`, and the number of coarse matches (-1: no coarse pass)."""
    import cv2

    k = int(cfg.overlap_features)
    ni, nj = len(fi), len(fj)
    if k <= 0 or ni < 2 * k or nj < 2 * k:
        return None, -1
    # the largest features: they repeat across views far more often than the strongest (on the
    # 12 MP scale block the 1,500 largest of 8,000 found 30 % of a pair's matches, the strongest 5 %)
    ti = np.sort(np.argsort(-fi.size, kind="stable")[:k])
    tj = np.sort(np.argsort(-fj.size, kind="stable")[:k])
    m0, _ = match_descriptors(fi.descriptor_rows(ti), fj.descriptor_rows(tj), cfg)
    nc = len(m0)
    if nc < OVERLAP_MIN_MATCHES:
        return None, nc
    p, q = fi.xy[ti[m0[:, 0]]], fj.xy[tj[m0[:, 1]]]
    diag = 0.5 * (math.hypot(fi.width, fi.height) + math.hypot(fj.width, fj.height))
    cv2.setRNGSeed(0)
    try:
        H, mask = cv2.findHomography(p, q, cv2.RANSAC, 0.03 * diag, maxIters=2000, confidence=0.999)
    except cv2.error:
        return None, nc
    if H is None or mask is None:
        return None, nc
    inl = mask.ravel().astype(bool)
    n_in = int(inl.sum())
    if n_in < OVERLAP_MIN_MATCHES or n_in < OVERLAP_MIN_INLIER_SHARE * nc:
        return None, nc
    try:
        Hinv = np.linalg.inv(H)
    except np.linalg.LinAlgError:
        return None, nc
    corners_i = np.array([[0, 0], [fi.width, 0], [fi.width, fi.height], [0, fi.height]], float)
    corners_j = np.array([[0, 0], [fj.width, 0], [fj.width, fj.height], [0, fj.height]], float)
    for c, M in ((corners_i, H), (corners_j, Hinv)):
        if not np.all(np.column_stack([c, np.ones(4)]) @ M[2] > 1e-9):
            return None, nc  # a frame corner maps behind the other camera: no bounded overlap
    ri = np.flatnonzero(_inside(fi.xy, H, fj.width, fj.height, cfg.overlap_margin * max(fj.width, fj.height)))
    rj = np.flatnonzero(
        _inside(fj.xy, Hinv, fi.width, fi.height, cfg.overlap_margin * max(fi.width, fi.height))
    )
    hp = np.column_stack([p[inl], np.ones(n_in)]) @ H.T
    res = np.linalg.norm(hp[:, :2] / hp[:, 2:3] - q[inl], axis=1)
    return Overlap(H, ri, rj, float(np.percentile(res, 95))), nc


def overlap_rows(fi: Features, fj: Features, config: MatchConfig | None = None):
    """Rows ``(rows_i, rows_j)`` of the features of two images that can lie in their common
    part (:func:`find_overlap`), or None: no overlap found, or one that would save less than
    :data:`OVERLAP_MIN_SAVING` of the whole product."""
    ov = find_overlap(fi, fj, config)
    if ov is None or not _saves_enough(ov, fi, fj):
        return None
    return ov.rows_i, ov.rows_j


def _saves_enough(ov: Overlap, fi: Features, fj: Features) -> bool:
    """Whether matching only the overlap's rows saves :data:`OVERLAP_MIN_SAVING` of the product."""
    return len(ov.rows_i) * len(ov.rows_j) <= (1.0 - OVERLAP_MIN_SAVING) * len(fi) * len(fj)


@fastjit
def _top2_window(dot, na, nb, rows, cand, best_i, best_d, col_best, col_arg):
    """Two smallest squared distances (``na + nb - 2 dot``) of each of the features ``rows`` of
    the first image among the candidates ``cand`` of the second (``dot[r, c]`` their descriptor
    products), and the smallest so far of each candidate; indices are global."""
    for r in range(len(rows)):
        i = rows[r]
        d1 = np.inf
        d2 = np.inf
        j1 = -1
        for c in range(len(cand)):
            j = cand[c]
            d = na[i] + nb[j] - 2.0 * dot[r, c]
            if d < d2:
                if d < d1:
                    d2 = d1
                    d1 = d
                    j1 = j
                else:
                    d2 = d
            if d < col_best[j]:
                col_best[j] = d
                col_arg[j] = i
        best_i[i] = j1
        best_d[i, 0] = d1
        best_d[i, 1] = d2


def match_windowed(fi: Features, fj: Features, H, radius: float, config: MatchConfig | None = None):
    """Matches ``(M, 2)`` (sorted by the first index) of two images whose features are compared
    only within ``radius`` pixels (full resolution, in the second image) of where ``H`` maps them.

    The second image's frame, grown by ``radius``, is cut into square cells of at least
    ``radius`` (and at least 1/16 of its larger side); a feature of the first image is compared
    with the features of the 3 x 3 cells about the cell of its mapped position, a superset of its
    window. Ratio test and mutual check as :func:`match_descriptors`, over those candidates: the
    second-nearest neighbour and the back-match are searched among the features that could be
    the same point.
    """
    cfg = config or MatchConfig()
    cfg.validate()
    H = np.asarray(H, np.float64)
    if H.shape != (3, 3) or not np.all(np.isfinite(H)):
        raise InputError(f"match_windowed: H must be a finite 3x3 homography, got shape {H.shape}")
    r = float(radius)
    if not (math.isfinite(r) and r >= 0):
        raise InputError(f"match_windowed: radius must be a finite number of pixels >= 0, got {radius!r}")
    empty = np.zeros((0, 2), np.int64)
    if len(fi) < 1 or len(fj) < 2:
        return empty
    s = max(r, max(fj.width, fj.height) / 16.0, 1.0)
    q = np.column_stack([fi.xy, np.ones(len(fi))]) @ H.T
    ok = q[:, 2] > 1e-9
    w = np.where(ok, q[:, 2], 1.0)
    u, v = q[:, 0] / w, q[:, 1] / w
    with np.errstate(invalid="ignore"):
        ok &= (u >= -r) & (u <= fj.width + r) & (v >= -r) & (v <= fj.height + r)
    ri = np.flatnonzero(ok)
    nx = int(math.floor((fj.width + 2 * r) / s)) + 1
    ny = int(math.floor((fj.height + 2 * r) / s)) + 1

    def cell(x, y):
        cx = np.clip(np.floor((x + r) / s).astype(np.int64), 0, nx - 1)
        cy = np.clip(np.floor((y + r) / s).astype(np.int64), 0, ny - 1)
        return cy * nx + cx

    ci = cell(u[ri], v[ri])
    cj = cell(fj.xy[:, 0], fj.xy[:, 1])
    oi = ri[np.argsort(ci, kind="stable")]
    ci = np.sort(ci, kind="stable")
    oj = np.argsort(cj, kind="stable")
    start_j = np.searchsorted(cj[oj], np.arange(nx * ny + 1))
    a = fi.descriptors
    b = fj.descriptors
    na = np.einsum("ij,ij->i", a, a)
    nb = np.einsum("ij,ij->i", b, b)
    best_i = np.full(len(fi), -1, np.int64)
    best_d = np.full((len(fi), 2), np.inf, np.float32)
    col_best = np.full(len(fj), np.inf, np.float32)
    col_arg = np.full(len(fj), -1, np.int64)
    cells, first = np.unique(ci, return_index=True)
    last = np.r_[first[1:], len(ci)]
    for c, k0, k1 in zip(cells, first, last, strict=True):
        cx, cy = int(c % nx), int(c // nx)
        x0, x1 = max(cx - 1, 0), min(cx + 2, nx)
        cand = np.concatenate(
            [oj[start_j[y * nx + x0] : start_j[y * nx + x1]] for y in range(max(cy - 1, 0), min(cy + 2, ny))]
        )
        if len(cand) < 2:
            continue
        rows = oi[k0:k1]
        _top2_window(_products(a[rows], b[cand]), na, nb, rows, cand, best_i, best_d, col_best, col_arg)
    i1, i2 = _ratio_and_mutual(best_i, np.sqrt(np.maximum(best_d, 0.0)), col_arg, cfg)
    if len(i1) == 0:
        return empty
    return np.column_stack([i1, i2]).astype(np.int64)


def window_radius(ov: Overlap, fj: Features, config: MatchConfig) -> float:
    """Search radius of :func:`match_windowed` for an overlap, pixels of the second image."""
    side = max(fj.width, fj.height)
    lo, hi = config.window_min * side, config.overlap_margin * side
    return float(min(hi, max(lo, config.window_factor * ov.residual_q95)))


def match_features(fi: Features, fj: Features, config: MatchConfig | None = None) -> tuple[np.ndarray, bool]:
    """Matches ``(M, 2)`` of two images' features (sorted by the first index), and whether
    they were searched in the overlap that :func:`find_overlap` found only (windows about the
    mapped positions, :func:`match_windowed`; or the whole overlap with ``window_factor`` 0).
    Every pair without an overlap is matched whole (``overlap_min_coarse`` is
    :func:`match_pairs`' rule)."""
    cfg = config or MatchConfig()
    cfg.validate()
    m, restricted, _, _ = _match_pair(fi, fj, cfg, 0)
    return m, restricted


def _match_pair(
    fi: Features, fj: Features, cfg: MatchConfig, min_coarse: int
) -> tuple[np.ndarray, bool, int, bool]:
    """Matches; whether they were searched in the overlap only; the coarse matches (-1: no coarse
    pass); and whether the pair was skipped (fewer than ``min_coarse`` coarse matches and no
    overlap found: no matches)."""
    ov, nc = _coarse(fi, fj, cfg)
    if ov is not None and cfg.window_factor > 0:
        return match_windowed(fi, fj, ov.H, window_radius(ov, fj, cfg), cfg), True, nc, False
    if ov is not None and _saves_enough(ov, fi, fj):
        ri, rj = ov.rows_i, ov.rows_j
        m, _ = match_descriptors(fi.descriptor_rows(ri), fj.descriptor_rows(rj), cfg)
        if len(m):
            m = np.column_stack([ri[m[:, 0]], rj[m[:, 1]]])
        return m, True, nc, False
    if 0 <= nc < min_coarse:
        return np.zeros((0, 2), np.int64), False, nc, True
    m, _ = match_descriptors(fi.descriptors, fj.descriptors, cfg)
    return m, False, nc, False


@dataclass
class PairMatches:
    """Matching result of one image pair.

    Attributes
    ----------
    i, j : int
        Image indices (``i < j`` as given in the pair list).
    n_putative : int
        Matches after the ratio test and the mutual check.
    geometry : TwoViewResult
        Robust two-view geometry; ``geometry.inliers`` are the verified matches
        (feature indices in images i and j).
    seconds_matching, seconds_geometry : float
    """

    i: int
    j: int
    n_putative: int
    geometry: TwoViewResult
    seconds_matching: float
    seconds_geometry: float
    #: Matched within the overlap a coarse pass found (:func:`find_overlap`), not whole.
    restricted: bool = False
    #: Matches of the coarse pass (-1: none ran).
    coarse_matches: int = -1
    #: The coarse pass found fewer than ``overlap_min_coarse`` matches: taken as not
    #: overlapping, not matched further (no matches, ``geometry`` says why).
    skipped: bool = False

    @property
    def ok(self) -> bool:
        return self.geometry.ok

    @property
    def inliers(self) -> np.ndarray:
        return self.geometry.inliers


def match_pairs(
    features: list[Features],
    pairs,
    cameras: list[Camera | None] | None = None,
    match_config: MatchConfig | None = None,
    twoview_config: TwoViewConfig | None = None,
    progress: Progress | None = None,
    threads: int | None = None,
) -> tuple[list[PairMatches], dict]:
    """Match and geometrically verify image pairs.

    Pairs are matched ``threads`` at a time (default
    :func:`~truortho.core.parallel.threads.default_threads`); the results do not depend on it.

    Parameters
    ----------
    features : list of Features
    pairs : (P, 2) int
        Image index pairs.
    cameras : list of (Camera or None), optional
        Approximate interior orientation per image (full resolution); when
        both images of a pair have one the essential matrix is estimated,
        the fundamental matrix otherwise.
    match_config, twoview_config : optional
    progress : Progress, optional
        Reports per pair; cancellation raises CancelledError.

    Returns
    -------
    results : list of PairMatches
        One per pair, in the given order (failed pairs included, with their reason).
    stats : dict
        ``pairs``, ``verified``, ``seconds``, ``seconds_matching`` and
        ``seconds_geometry`` (totals), ``overlap_restricted`` (pairs matched in the overlap
        that a coarse pass found) and ``no_overlap`` (pairs taken as not overlapping).
    """
    mcfg = match_config or MatchConfig()
    mcfg.validate()
    tcfg = twoview_config or TwoViewConfig()
    tcfg.validate()
    prog = as_progress(progress)
    P = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    n = len(features)
    if len(P) and (P.min() < 0 or P.max() >= n or np.any(P[:, 0] == P[:, 1])):
        raise InputError(f"match_pairs: pairs must be distinct image indices in [0, {n})")
    if cameras is not None and len(cameras) != n:
        raise InputError(f"match_pairs: {len(cameras)} cameras for {n} images")
    from ..parallel.threads import thread_map

    out: list[PairMatches] = []
    t0 = time.perf_counter()
    tm = tg = 0.0

    def one(pair) -> PairMatches:
        i, j = int(pair[0]), int(pair[1])
        fi, fj = features[i], features[j]
        t = time.perf_counter()
        m, restricted, nc, skipped = _match_pair(fi, fj, mcfg, int(mcfg.overlap_min_coarse))
        t1 = time.perf_counter()
        cam_i = cameras[i] if cameras is not None else None
        cam_j = cameras[j] if cameras is not None else None
        geo = estimate_two_view(
            fi.xy[m[:, 0]],
            fj.xy[m[:, 1]],
            cam_i,
            cam_j,
            tcfg,
            pixel_scale=1.0 / min(fi.scale, fj.scale),
            matches=m,
        )
        return PairMatches(i, j, len(m), geo, t1 - t, time.perf_counter() - t1, restricted, nc, skipped)

    for r in thread_map(one, P, threads, prog, lambda k, n: f"matching pair {k + 1} of {n}"):
        tm += r.seconds_matching
        tg += r.seconds_geometry
        out.append(r)
    prog.update(1.0, f"matched {len(P)} pairs")
    stats = {
        "pairs": len(P),
        "verified": sum(r.ok for r in out),
        "seconds": time.perf_counter() - t0,
        "seconds_matching": tm,
        "seconds_geometry": tg,
        "overlap_restricted": sum(r.restricted for r in out),
        "no_overlap": sum(r.skipped for r in out),
    }
    return out, stats
