"""SIFT features at a working resolution, with an on-disk cache.

Each image is read as stored (:mod:`truortho.core.imagery`), reduced so that
its larger side is at most ``FeatureConfig.max_dimension`` (area averaging),
converted to 8-bit luminance and passed to OpenCV's SIFT. Keypoints are
returned in **full-resolution** pixel coordinates of our convention (centre
of the top-left pixel = (0, 0)): ``x = (x_w + 0.5) / sx - 0.5`` with the
effective per-axis factor ``sx`` of :func:`~truortho.core.imagery.scaled_size`.
OpenCV's SIFT reports positions biased by +0.25 px in x and y: it doubles
the image for its first octave and maps the doubled image's pixel ``i`` to
``i / 2`` instead of ``(i + 0.5) / 2 - 0.5``. The bias is the same in every
octave (coarser octaves subsample the doubled grid at even pixels) and is
removed here (:data:`OPENCV_SIFT_BIAS`; measured by detecting on an image and
its 180° rotation, see ``tests/core/test_features.py``).

Cache: one ``.npz`` per image in ``cache_dir``, named after the image stem
and a hash of (absolute path, modification time, size, detection
parameters, format version); descriptors are stored as the raw uint8 SIFT
values, RootSIFT is applied on loading, so ``root_sift`` does not
invalidate the cache.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from dataclasses import asdict, dataclass

import numpy as np

from ..errors import InputError
from ..imagery import luminance, read_image, resample, scaled_size, to_uint8
from ..progress import Progress, as_progress

_CACHE_VERSION = 2
#: Position bias of cv2.SIFT keypoints, working-resolution pixels (see the module docstring).
OPENCV_SIFT_BIAS = 0.25


@dataclass
class FeatureConfig:
    """Options of :func:`extract_features`.

    Attributes
    ----------
    max_dimension : int
        Larger image side of the working resolution, pixels; images already
        smaller are not enlarged.
    max_features : int
        Most features kept per image (strongest responses).
    contrast_threshold, edge_threshold, sigma : float
        OpenCV SIFT parameters (defaults as OpenCV / Lowe).
    root_sift : bool
        Apply RootSIFT (L1 normalisation, square root) to the descriptors.
    """

    max_dimension: int = 2000
    max_features: int = 8000
    contrast_threshold: float = 0.04
    edge_threshold: float = 10.0
    sigma: float = 1.6
    root_sift: bool = True

    def validate(self) -> None:
        if not isinstance(self.max_dimension, int | np.integer) or self.max_dimension < 32:
            raise InputError(f"max_dimension must be an integer >= 32, got {self.max_dimension!r}")
        if not isinstance(self.max_features, int | np.integer) or self.max_features < 1:
            raise InputError(f"max_features must be a positive integer, got {self.max_features!r}")
        for n in ("contrast_threshold", "edge_threshold", "sigma"):
            v = getattr(self, n)
            if not (isinstance(v, int | float) and np.isfinite(v) and v > 0):
                raise InputError(f"{n} must be a positive number, got {v!r}")

    def detection_key(self) -> dict:
        """The parameters that change the detected features (cache key)."""
        d = asdict(self)
        d.pop("root_sift")
        return d


@dataclass
class Features:
    """Features of one image.

    Attributes
    ----------
    xy : (N, 2) float64
        Keypoint positions, full-resolution pixels, our convention.
    size : (N,) float32
        Keypoint diameter (OpenCV ``size``) in full-resolution pixels.
    angle : (N,) float32
        Orientation, degrees (OpenCV convention).
    response : (N,) float32
        Detector response.
    sift : (N, 128) uint8
        The raw SIFT descriptors as OpenCV computes them (integers 0..255), kept in memory
        at a quarter of the float32 size: 1,000 images of 8,000 features hold 1 GB, not 4.
    root_sift : bool
        Whether :attr:`descriptors` applies RootSIFT.
    colors : (N, 3) uint8
        RGB at the keypoint (nearest pixel of the working image).
    width, height : int
        Full-resolution image size.
    scale : float
        Working resolution / full resolution (mean of the two axes).
    """

    xy: np.ndarray
    size: np.ndarray
    angle: np.ndarray
    response: np.ndarray
    sift: np.ndarray
    colors: np.ndarray
    width: int
    height: int
    scale: float
    root_sift: bool = True

    def __len__(self) -> int:
        return len(self.xy)

    @property
    def descriptors(self) -> np.ndarray:
        """(N, 128) float32 descriptors for matching: RootSIFT (unit L2 norm) when
        :attr:`root_sift`, else the raw SIFT values; made on every access (about 1 ms per
        1,000 features), so that only the compact :attr:`sift` stays in memory."""
        return self.descriptor_rows(None)

    def descriptor_rows(self, rows) -> np.ndarray:
        """:attr:`descriptors` of the features ``rows`` (an index array; None: all)."""
        d = self.sift if rows is None else self.sift[rows]
        return _root_sift(d) if self.root_sift else d.astype(np.float32)


def _root_sift(d: np.ndarray) -> np.ndarray:
    d = d.astype(np.float32)
    d /= np.maximum(d.sum(axis=1, keepdims=True), 1e-12)
    return np.sqrt(d, out=d)


def _detect(path: str, cfg: FeatureConfig) -> dict:
    import cv2

    img = read_image(path)
    h, w = img.shape[:2]
    s = min(1.0, cfg.max_dimension / max(w, h))
    ww, wh, sx, sy = scaled_size(w, h, s)
    if s < 1.0:
        img = resample(img, s)
    if img.ndim == 3 and img.shape[2] >= 3:
        rgb = to_uint8(img[:, :, :3])
    else:
        g = to_uint8(img if img.ndim == 2 else img[:, :, 0])
        rgb = np.repeat(g[:, :, None], 3, axis=2)
    gray = to_uint8(luminance(rgb))  # luminance in [0, 1] -> 8 bit
    sift = cv2.SIFT_create(  # type: ignore[attr-defined]
        nfeatures=int(cfg.max_features),
        contrastThreshold=float(cfg.contrast_threshold),
        edgeThreshold=float(cfg.edge_threshold),
        sigma=float(cfg.sigma),
    )
    kps, desc = sift.detectAndCompute(gray, None)
    n = len(kps)
    if n == 0 or desc is None:
        desc = np.zeros((0, 128), np.float32)
    kxy = np.array([k.pt for k in kps], dtype=np.float64).reshape(n, 2)
    order = np.argsort(-np.array([k.response for k in kps], dtype=np.float32), kind="stable")[
        : cfg.max_features
    ]
    kps = [kps[i] for i in order]
    kxy, desc = kxy[order], desc[order]
    ix = np.clip(np.rint(kxy[:, 0]).astype(np.intp), 0, ww - 1)
    iy = np.clip(np.rint(kxy[:, 1]).astype(np.intp), 0, wh - 1)
    xy = np.empty_like(kxy)
    xy[:, 0] = (kxy[:, 0] - OPENCV_SIFT_BIAS + 0.5) / sx - 0.5
    xy[:, 1] = (kxy[:, 1] - OPENCV_SIFT_BIAS + 0.5) / sy - 0.5
    return {
        "xy": xy,
        "size": np.array([k.size for k in kps], np.float32) / np.float32(0.5 * (sx + sy)),
        "angle": np.array([k.angle for k in kps], np.float32),
        "response": np.array([k.response for k in kps], np.float32),
        "descriptors": np.clip(np.rint(desc), 0, 255).astype(np.uint8),
        "colors": rgb[iy, ix].astype(np.uint8).reshape(-1, 3),
        "width": np.int64(w),
        "height": np.int64(h),
        "scale": np.float64(0.5 * (sx + sy)),
    }


def _to_features(d, cfg: FeatureConfig) -> Features:
    desc = np.asarray(d["descriptors"])
    if desc.dtype != np.uint8:
        raise InputError(f"feature cache: descriptors must be uint8 SIFT values, got {desc.dtype}")
    return Features(
        xy=np.asarray(d["xy"], np.float64),
        size=np.asarray(d["size"], np.float32),
        angle=np.asarray(d["angle"], np.float32),
        response=np.asarray(d["response"], np.float32),
        sift=np.ascontiguousarray(desc),
        colors=np.asarray(d["colors"], np.uint8),
        width=int(d["width"]),
        height=int(d["height"]),
        scale=float(d["scale"]),
        root_sift=bool(cfg.root_sift),
    )


def cache_path(path, cache_dir, config: FeatureConfig) -> str:
    """Cache file of an image's features for ``config`` (existing or not)."""
    p = os.path.abspath(os.fspath(path))
    st = os.stat(p)
    key = json.dumps([p, st.st_mtime_ns, st.st_size, config.detection_key(), _CACHE_VERSION], sort_keys=True)
    h = hashlib.sha1(key.encode()).hexdigest()[:20]
    stem = os.path.splitext(os.path.basename(p))[0]
    return os.path.join(os.fspath(cache_dir), f"{stem}-{h}.npz")


def extract_features(path, config: FeatureConfig | None = None, cache_dir=None) -> Features:
    """SIFT features of one image (from the cache when available).

    Parameters
    ----------
    path : str or os.PathLike
        Image file (read as stored, EXIF orientation ignored).
    config : FeatureConfig, optional
    cache_dir : str or os.PathLike, optional
        Folder of the feature cache (created when missing); no caching when None.

    Raises
    ------
    MissingFileError, FormatError
        The image does not exist or cannot be read (the message names the file).
    """
    cfg = config or FeatureConfig()
    cfg.validate()
    p = os.fspath(path)
    cpath = None
    if cache_dir is not None:
        if not os.path.isfile(p):
            from ..errors import MissingFileError

            raise MissingFileError(p, "image file not found")
        os.makedirs(cache_dir, exist_ok=True)
        cpath = cache_path(p, cache_dir, cfg)
        if os.path.isfile(cpath):
            try:
                with np.load(cpath) as z:
                    return _to_features({k: z[k] for k in z.files}, cfg)
            except (OSError, ValueError, KeyError):
                pass  # unreadable cache entry: recompute and overwrite
    d = _detect(p, cfg)
    if cpath is not None:
        tmp = cpath + f".{os.getpid()}.tmp.npz"
        np.savez(tmp, **d)
        os.replace(tmp, cpath)
    return _to_features(d, cfg)


def extract_all(
    paths,
    config: FeatureConfig | None = None,
    cache_dir=None,
    progress: Progress | None = None,
    threads: int | None = None,
) -> tuple[list[Features], dict]:
    """Features of several images, with progress and cancellation per image.

    ``threads``: images extracted at once (default
    :func:`~truortho.core.parallel.threads.default_threads`); the features do not
    depend on it.

    Returns
    -------
    features : list of Features
        In the order of ``paths``.
    stats : dict
        ``seconds`` (total), ``seconds_per_image`` (list), ``cached`` (count of
        images read from the cache), ``n_features`` (list).
    """
    from ..parallel.threads import thread_map

    cfg = config or FeatureConfig()
    cfg.validate()
    prog = as_progress(progress)
    paths = [os.fspath(p) for p in paths]
    out: list[Features] = []
    times: list[float] = []
    cached = sum(
        1
        for p in paths
        if cache_dir is not None and os.path.isfile(p) and os.path.isfile(cache_path(p, cache_dir, cfg))
    )
    t0 = time.perf_counter()

    def one(p):
        t = time.perf_counter()
        return extract_features(p, cfg, cache_dir), time.perf_counter() - t

    def message(k, n):
        return f"features of {os.path.basename(paths[k])}"

    for f, dt in thread_map(one, paths, threads, prog, message):
        out.append(f)
        times.append(dt)
    prog.update(1.0, f"features of {len(paths)} images")
    stats = {
        "seconds": time.perf_counter() - t0,
        "seconds_per_image": times,
        "cached": cached,
        "n_features": [len(f) for f in out],
    }
    return out, stats
