"""Selection of the image pairs to match.

Strategies (:func:`select_pairs`, ``strategy="auto"`` picks the first that applies):

``"exhaustive"``
    All ``n (n - 1) / 2`` pairs, when ``n <= exhaustive_max``.
``"gps"``
    Every image has an EXIF GPS position. Positions are projected to the UTM
    zone of their mean (pyproj), heights above ground are estimated
    (``altitude - ground_height``; the ground is the given
    ``ground_height``, else the median of ``altitude - relative_altitude``
    when DJI XMP relative altitudes exist, else the median altitude minus
    ``flying_height``). The footprint of a nadir image is approximated by
    the disc of equal area to its ground rectangle, radius
    ``H * sqrt(w h / pi) / f`` (heading unknown); pairs whose discs overlap
    (centre distance < ``footprint_margin * (r_i + r_j)``) are kept, plus
    the ``gps_neighbors`` nearest neighbours of every image (oblique
    images, wrong heights).
``"retrieval"``
    No GPS: a low-resolution SIFT pass (``retrieval_max_dimension``,
    ``retrieval_features``), a small visual vocabulary (k-means on a sample
    of RootSIFT descriptors, fixed seed) and a VLAD global descriptor per
    image (intra- and power-normalised); every image is paired with its
    ``retrieval_k`` most similar images (cosine similarity).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..progress import Progress, Steps, as_progress, check


@dataclass
class PairConfig:
    """Options of :func:`select_pairs` (metres, pixels)."""

    #: "auto", "exhaustive", "gps" or "retrieval".
    strategy: str = "auto"
    #: Largest block matched exhaustively with "auto".
    exhaustive_max: int = 30
    #: Nearest GPS neighbours always paired with every image.
    gps_neighbors: int = 6
    #: Ground height in the GPS altitude's datum, metres (None: estimated, see module docstring).
    ground_height: float | None = None
    #: Assumed flying height above ground when nothing better is known, metres.
    flying_height: float = 100.0
    #: Factor on the sum of the footprint radii below which two images are paired.
    footprint_margin: float = 1.0
    #: Most similar images paired with every image by retrieval.
    retrieval_k: int = 10
    #: Working resolution and feature count of the retrieval pass.
    retrieval_max_dimension: int = 640
    retrieval_features: int = 500
    #: Visual words of the VLAD vocabulary.
    vocabulary_size: int = 64
    seed: int = 0

    def validate(self) -> None:
        if self.strategy not in ("auto", "exhaustive", "gps", "retrieval"):
            raise InputError(f"strategy must be auto, exhaustive, gps or retrieval, got {self.strategy!r}")
        for n in ("exhaustive_max", "gps_neighbors", "retrieval_k", "retrieval_features", "vocabulary_size"):
            v = getattr(self, n)
            if not isinstance(v, int | np.integer) or v < 0:
                raise InputError(f"{n} must be a non-negative integer, got {v!r}")
        if not self.flying_height > 0 or not self.footprint_margin > 0:
            raise InputError("flying_height and footprint_margin must be positive")


@dataclass
class PairSelection:
    """Selected pairs and how they were chosen.

    Attributes
    ----------
    pairs : (P, 2) int64
        ``(i, j)`` with ``i < j``, sorted.
    strategy : str
    n_images : int
    details : dict
        Strategy-specific numbers (heights, radii, timings...).
    """

    pairs: np.ndarray
    strategy: str
    n_images: int
    details: dict = field(default_factory=dict)

    @property
    def n_pairs(self) -> int:
        return len(self.pairs)

    @property
    def n_exhaustive(self) -> int:
        return self.n_images * (self.n_images - 1) // 2


def _normalise_pairs(a, b) -> np.ndarray:
    a, b = np.asarray(a, np.int64).ravel(), np.asarray(b, np.int64).ravel()
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    keep = lo != hi
    if not keep.any():
        return np.zeros((0, 2), np.int64)
    return np.unique(np.column_stack([lo[keep], hi[keep]]), axis=0)


def exhaustive_pairs(n: int) -> np.ndarray:
    """All ``(i, j)``, ``i < j < n``, as a (n (n - 1) / 2, 2) int64 array."""
    i, j = np.triu_indices(int(n), k=1)
    return np.column_stack([i, j]).astype(np.int64)


def _knn_pairs(dist: np.ndarray, k: int) -> np.ndarray:
    n = len(dist)
    k = min(k, n - 1)
    if k <= 0:
        return np.zeros((0, 2), np.int64)
    d = dist.copy()
    np.fill_diagonal(d, np.inf)
    nn = np.argsort(d, axis=1, kind="stable")[:, :k]
    return _normalise_pairs(np.repeat(np.arange(n), k), nn.ravel())


def gps_pairs(exifs, sizes, focals_px, config: PairConfig | None = None) -> PairSelection:
    """Pairs from GPS positions and approximate footprints (module docstring).

    Parameters
    ----------
    exifs : list of ExifData
        All with ``latitude``/``longitude``.
    sizes : (n, 2)
        Image ``(width, height)``, pixels.
    focals_px : (n,)
        Focal length priors, pixels (e.g. :func:`~truortho.core.exif.focal_prior_px`).
    """
    from pyproj import Transformer

    cfg = config or PairConfig()
    cfg.validate()
    n = len(exifs)
    sizes = np.asarray(sizes, np.float64).reshape(-1, 2)
    f = np.asarray(focals_px, np.float64).reshape(-1)
    if len(sizes) != n or len(f) != n:
        raise InputError(f"gps_pairs: {n} images but {len(sizes)} sizes and {len(f)} focal lengths")
    missing = [k for k, e in enumerate(exifs) if not e.has_gps]
    if missing:
        raise InputError(f"gps_pairs: images {missing[:5]} have no GPS position")
    lat = np.array([e.latitude for e in exifs])
    lon = np.array([e.longitude for e in exifs])
    zone = int(np.floor((np.mean(lon) + 180.0) / 6.0)) % 60 + 1
    epsg = (32600 if np.mean(lat) >= 0 else 32700) + zone
    xs, ys = Transformer.from_crs(4326, epsg, always_xy=True).transform(lon, lat)
    xy = np.column_stack([xs, ys])
    alt = np.array([np.nan if e.altitude is None else e.altitude for e in exifs])
    rel = np.array([np.nan if e.relative_altitude is None else e.relative_altitude for e in exifs])
    if cfg.ground_height is not None:
        ground, source = float(cfg.ground_height), "given"
    elif np.isfinite(alt - rel).any():
        ground, source = float(np.nanmedian(alt - rel)), "relative_altitude"
    elif np.isfinite(alt).any():
        ground, source = float(np.nanmedian(alt) - cfg.flying_height), "flying_height"
    else:
        ground, source = float("nan"), "flying_height"
    height = alt - ground
    height = np.where(np.isfinite(height), height, cfg.flying_height)
    height = np.maximum(height, 1.0)
    radius = height * np.sqrt(sizes[:, 0] * sizes[:, 1] / np.pi) / f
    dist = np.linalg.norm(xy[:, None, :] - xy[None, :, :], axis=2)
    i, j = np.nonzero(np.triu(dist < cfg.footprint_margin * (radius[:, None] + radius[None, :]), k=1))
    overlap = _normalise_pairs(i, j)
    knn = _knn_pairs(dist, cfg.gps_neighbors)
    pairs = _normalise_pairs(np.r_[overlap[:, 0], knn[:, 0]], np.r_[overlap[:, 1], knn[:, 1]])
    details = {
        "epsg": epsg,
        "ground_height": ground,
        "ground_source": source,
        "median_height_m": float(np.median(height)),
        "median_radius_m": float(np.median(radius)),
        "footprint_pairs": len(overlap),
        "knn_pairs": len(knn),
        "local_xy": xy - xy.mean(axis=0),
    }
    return PairSelection(pairs, "gps", n, details)


def _vocabulary(desc: np.ndarray, k: int, seed: int) -> np.ndarray:
    import cv2

    cv2.setRNGSeed(int(seed))
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 25, 1e-4)
    _, _, centres = cv2.kmeans(  # type: ignore[call-overload]
        desc.astype(np.float32), k, None, crit, 1, cv2.KMEANS_PP_CENTERS
    )
    return centres


def vlad(descriptors: np.ndarray, vocabulary: np.ndarray) -> np.ndarray:
    """VLAD vector (K * D,) of one image: residual sums per word, intra-, power- and L2-normalised."""
    K, D = vocabulary.shape
    v = np.zeros((K, D), np.float64)
    if len(descriptors):
        d = descriptors.astype(np.float64)
        dist = (d**2).sum(1)[:, None] - 2.0 * d @ vocabulary.T + (vocabulary**2).sum(1)[None, :]
        word = np.argmin(dist, axis=1)
        np.add.at(v, word, d - vocabulary[word])
    norms = np.linalg.norm(v, axis=1, keepdims=True)
    v = np.where(norms > 0, v / np.maximum(norms, 1e-12), 0.0)
    v = np.sign(v) * np.sqrt(np.abs(v))
    v = v.ravel()
    nv = np.linalg.norm(v)
    return v / nv if nv > 0 else v


def retrieval_pairs(features, config: PairConfig | None = None) -> PairSelection:
    """Pairs of visually similar images (VLAD on low-resolution features).

    Parameters
    ----------
    features : list of Features
        Low-resolution features (RootSIFT recommended) of every image.
    """
    cfg = config or PairConfig()
    cfg.validate()
    n = len(features)
    t0 = time.perf_counter()
    rng = np.random.default_rng(cfg.seed)
    per = max(1, 20000 // max(n, 1))
    sample = [f.descriptor_rows(rng.permutation(len(f))[:per]) for f in features if len(f)]
    allsample = np.concatenate(sample) if sample else np.zeros((0, 128), np.float32)
    k = min(cfg.vocabulary_size, len(allsample))
    if n < 2 or k < 2:
        return PairSelection(
            exhaustive_pairs(n), "exhaustive", n, {"reason": "too few features for retrieval"}
        )
    voc = _vocabulary(allsample, k, cfg.seed)
    G = np.stack([vlad(f.descriptors, voc) for f in features])
    sim = G @ G.T
    pairs = _knn_pairs(-sim, cfg.retrieval_k)
    return PairSelection(
        pairs,
        "retrieval",
        n,
        {"vocabulary_size": k, "similarity": sim, "seconds": time.perf_counter() - t0},
    )


def select_pairs(
    paths,
    exifs=None,
    sizes=None,
    focals_px=None,
    config: PairConfig | None = None,
    cache_dir=None,
    progress: Progress | None = None,
) -> PairSelection:
    """Choose the pairs to match (see the module docstring for the strategies).

    Parameters
    ----------
    paths : list of path
        The images.
    exifs : list of ExifData, optional
        Read from the files when None and the GPS strategy is possible.
    sizes : (n, 2), optional
        Image sizes (read from the headers when None).
    focals_px : (n,), optional
        Focal priors in pixels (from EXIF when None).
    config : PairConfig, optional
    cache_dir : optional
        Feature cache of the retrieval pass.
    progress : Progress, optional

    Returns
    -------
    PairSelection
        ``details["seconds"]`` and ``details["reason"]`` (why this strategy) included.
    """
    from ..exif import focal_prior_px, read_exif
    from ..imagery import image_info

    cfg = config or PairConfig()
    cfg.validate()
    prog = as_progress(progress)
    t0 = time.perf_counter()
    paths = list(paths)
    n = len(paths)
    strategy = cfg.strategy
    reason = "requested"
    if strategy == "auto" and n <= cfg.exhaustive_max:
        strategy, reason = "exhaustive", f"{n} images <= exhaustive_max {cfg.exhaustive_max}"
    if strategy == "exhaustive":
        sel = PairSelection(exhaustive_pairs(n), "exhaustive", n, {})
    else:
        steps = Steps(prog, [1, 4])
        if exifs is None and strategy in ("auto", "gps"):
            exifs = []
            for k, p in enumerate(paths):
                check(prog)
                steps[0].update(k / n, "reading EXIF")
                exifs.append(read_exif(p))
        if sizes is None:
            sizes = [(i.width, i.height) for i in map(image_info, paths)]
        if strategy == "auto":
            if all(e.has_gps for e in exifs):
                strategy, reason = "gps", "all images have GPS positions"
            else:
                strategy, reason = "retrieval", "images without GPS position"
        if strategy == "gps":
            if exifs is None:
                exifs = [read_exif(p) for p in paths]
            if focals_px is None:
                focals_px = [focal_prior_px(e, w, h)[0] for e, (w, h) in zip(exifs, sizes, strict=True)]
            sel = gps_pairs(exifs, sizes, focals_px, cfg)
        else:
            from .features import FeatureConfig, extract_all

            fcfg = FeatureConfig(
                max_dimension=cfg.retrieval_max_dimension, max_features=cfg.retrieval_features
            )
            feats, fst = extract_all(paths, fcfg, cache_dir, steps[1])
            sel = retrieval_pairs(feats, cfg)
            sel.details["seconds_features"] = fst["seconds"]
    sel.details["reason"] = reason
    sel.details["seconds"] = time.perf_counter() - t0
    prog.update(1.0, f"{sel.n_pairs} of {sel.n_exhaustive} pairs ({sel.strategy})")
    return sel
