"""Descriptor matching (ratio test, mutual check) and matching of image pairs.

:func:`match_descriptors` finds, for every descriptor of the first set, its
two nearest neighbours in the second (exact brute force, one float32 matrix
product giving both directions and a numba top-2 scan, up to ``bf_max``
descriptors; FLANN randomised kd-trees beyond), keeps it when ``d1 < ratio * d2``
(Lowe's ratio test on L2 distances) and, with ``cross_check``, only when the
first set's descriptor is also the nearest neighbour of its match (mutual
nearest neighbours). :func:`match_pairs` runs that and the robust two-view
geometry (:mod:`.twoview`) over a list of image pairs.

The cost of a pair grows with the product of the two feature counts, yet only the features
in the images' common part can match. :func:`match_pairs` therefore first matches the
largest ``overlap_features`` of each image, fits a homography to them with a loose
threshold, and matches only the features that fall inside the other image's frame mapped
through it (grown by ``overlap_margin`` for relief): :func:`overlap_rows`. Pairs where that
fails (few coarse matches, a scene too 3-D for one homography, little to save) are matched
whole, as before.
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
    #: that image's larger side (parallax of relief and off-plane objects, obliques).
    overlap_margin: float = 0.15

    def validate(self) -> None:
        if not (isinstance(self.ratio, int | float) and 0 < self.ratio <= 1):
            raise InputError(f"ratio must be in (0, 1], got {self.ratio!r}")
        if self.method not in ("auto", "flann", "bf"):
            raise InputError(f"method must be 'auto', 'flann' or 'bf', got {self.method!r}")
        for n in ("bf_max", "flann_trees", "flann_checks"):
            v = getattr(self, n)
            if not isinstance(v, int | np.integer) or v < 1:
                raise InputError(f"{n} must be a positive integer, got {v!r}")
        if not isinstance(self.overlap_features, int | np.integer) or self.overlap_features < 0:
            raise InputError(f"overlap_features must be an integer >= 0, got {self.overlap_features!r}")
        if not (isinstance(self.overlap_margin, int | float) and 0 <= self.overlap_margin <= 10):
            raise InputError(f"overlap_margin must be in [0, 10], got {self.overlap_margin!r}")


@fastjit
def _top2_block(dot, na, nb, row0, best_i, best_d, col_best, col_arg):
    """Two smallest squared distances per row of a block; smallest per column so far."""
    m, n = dot.shape
    for r in range(m):
        d1 = np.inf
        d2 = np.inf
        j1 = -1
        for c in range(n):
            d = na[row0 + r] + nb[c] - 2.0 * dot[r, c]
            if d < d2:
                if d < d1:
                    d2 = d1
                    d1 = d
                    j1 = c
                else:
                    d2 = d
            if d < col_best[c]:
                col_best[c] = d
                col_arg[c] = row0 + r
        best_i[row0 + r] = j1
        best_d[row0 + r, 0] = d1
        best_d[row0 + r, 1] = d2


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
    for r0 in range(0, len(a), block):
        _top2_block(_products(a[r0 : r0 + block], b), na, nb, r0, best_i, best_d, col_best, col_arg)
    d = np.sqrt(np.maximum(best_d, 0.0))
    return best_i, d, col_arg


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
        i1 = np.flatnonzero((best >= 0) & (dist[:, 0] < cfg.ratio * dist[:, 1]))
        i2 = best[i1]
        if cfg.cross_check:
            keep = back[i2] == i1
            i1, i2 = i1[keep], i2[keep]
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


def overlap_rows(fi: Features, fj: Features, config: MatchConfig | None = None):
    """Rows of the features of two images that can lie in their common part, or None.

    A coarse pass matches the ``overlap_features`` largest features of each image and fits a
    homography to them with a loose threshold (3 % of the diagonal): the images' frames mapped
    through it, grown by ``overlap_margin``, bound where matches can be. Returns
    ``(rows_i, rows_j)`` (increasing) of the features inside the other image's mapped frame,
    or None when the pair should be matched whole: too few features or coarse matches, a
    homography that explains less than :data:`OVERLAP_MIN_INLIER_SHARE` of them (strong relief,
    close range), a frame that maps across the horizon, or a saving under
    :data:`OVERLAP_MIN_SAVING`. Deterministic (seeded).
    """
    import cv2

    cfg = config or MatchConfig()
    cfg.validate()
    k = int(cfg.overlap_features)
    ni, nj = len(fi), len(fj)
    if k <= 0 or ni < 2 * k or nj < 2 * k:
        return None
    # the largest features: they repeat across views far more often than the strongest (on the
    # 12 MP scale block the 1,500 largest of 8,000 found 30 % of a pair's matches, the strongest 5 %)
    ti = np.sort(np.argsort(-fi.size, kind="stable")[:k])
    tj = np.sort(np.argsort(-fj.size, kind="stable")[:k])
    m0, _ = match_descriptors(fi.descriptor_rows(ti), fj.descriptor_rows(tj), cfg)
    if len(m0) < OVERLAP_MIN_MATCHES:
        return None
    p, q = fi.xy[ti[m0[:, 0]]], fj.xy[tj[m0[:, 1]]]
    diag = 0.5 * (math.hypot(fi.width, fi.height) + math.hypot(fj.width, fj.height))
    cv2.setRNGSeed(0)
    try:
        H, mask = cv2.findHomography(p, q, cv2.RANSAC, 0.03 * diag, maxIters=2000, confidence=0.999)
    except cv2.error:
        return None
    if H is None or mask is None:
        return None
    n_in = int(mask.sum())
    if n_in < OVERLAP_MIN_MATCHES or n_in < OVERLAP_MIN_INLIER_SHARE * len(m0):
        return None
    try:
        Hinv = np.linalg.inv(H)
    except np.linalg.LinAlgError:
        return None
    corners_i = np.array([[0, 0], [fi.width, 0], [fi.width, fi.height], [0, fi.height]], float)
    corners_j = np.array([[0, 0], [fj.width, 0], [fj.width, fj.height], [0, fj.height]], float)
    for c, M in ((corners_i, H), (corners_j, Hinv)):
        if not np.all(np.column_stack([c, np.ones(4)]) @ M[2] > 1e-9):
            return None  # a frame corner maps behind the other camera: no bounded overlap
    ri = np.flatnonzero(_inside(fi.xy, H, fj.width, fj.height, cfg.overlap_margin * max(fj.width, fj.height)))
    rj = np.flatnonzero(
        _inside(fj.xy, Hinv, fi.width, fi.height, cfg.overlap_margin * max(fi.width, fi.height))
    )
    if len(ri) * len(rj) > (1.0 - OVERLAP_MIN_SAVING) * ni * nj:
        return None
    return ri, rj


def match_features(fi: Features, fj: Features, config: MatchConfig | None = None) -> tuple[np.ndarray, bool]:
    """Matches ``(M, 2)`` of two images' features (sorted by the first index), and whether
    they were searched in the overlap that :func:`overlap_rows` found only."""
    cfg = config or MatchConfig()
    rows = overlap_rows(fi, fj, cfg)
    if rows is None:
        m, _ = match_descriptors(fi.descriptors, fj.descriptors, cfg)
        return m, False
    ri, rj = rows
    m, _ = match_descriptors(fi.descriptor_rows(ri), fj.descriptor_rows(rj), cfg)
    if len(m):
        m = np.column_stack([ri[m[:, 0]], rj[m[:, 1]]])
    return m, True


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
    #: Matched within the overlap a coarse pass found (:func:`overlap_rows`), not whole.
    restricted: bool = False

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
        ``seconds_geometry`` (totals).
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
        m, restricted = match_features(fi, fj, mcfg)
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
        return PairMatches(i, j, len(m), geo, t1 - t, time.perf_counter() - t1, restricted)

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
    }
    return out, stats
