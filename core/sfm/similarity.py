"""7-parameter similarity (Helmert) transformation between point sets."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import GeometryError, InputError


@dataclass
class Similarity:
    """``y = scale * R @ x + t``."""

    scale: float
    R: np.ndarray
    t: np.ndarray

    def apply(self, x) -> np.ndarray:
        return self.scale * (np.asarray(x, dtype=np.float64) @ self.R.T) + self.t

    def apply_pose(self, R_wc: np.ndarray, C: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Transform a camera pose (world-to-camera ``R``, centre ``C``) into the new frame."""
        return R_wc @ self.R.T, self.apply(C)

    def inverse(self) -> Similarity:
        Ri = self.R.T
        return Similarity(1.0 / self.scale, Ri, -(Ri @ self.t) / self.scale)


def estimate_similarity(src, dst, weights=None, with_scale: bool = True) -> Similarity:
    """Least-squares similarity ``dst ≈ s R src + t`` (Umeyama 1991).

    Works for coplanar (but not collinear) points: the reflection ambiguity is
    resolved by requiring ``det R = +1``.

    Parameters
    ----------
    src, dst : (N, 3) float64
        Corresponding points, N >= 3.
    weights : (N,) float64, optional
        Non-negative weights.
    """
    a = np.asarray(src, dtype=np.float64).reshape(-1, 3)
    b = np.asarray(dst, dtype=np.float64).reshape(-1, 3)
    if len(a) != len(b):
        raise InputError("estimate_similarity: src and dst differ in length")
    if len(a) < 3:
        raise InputError(f"estimate_similarity: needs at least 3 points, got {len(a)}")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise InputError("estimate_similarity: points must be finite")
    w = np.ones(len(a)) if weights is None else np.asarray(weights, dtype=np.float64).reshape(-1)
    if len(w) != len(a) or np.any(w < 0) or w.sum() <= 0:
        raise InputError("estimate_similarity: weights must be non-negative with a positive sum")
    w = w / w.sum()
    ma = w @ a
    mb = w @ b
    da = a - ma
    db = b - mb
    cov = (db * w[:, None]).T @ da
    U, S, Vt = np.linalg.svd(cov)
    var_a = float(w @ np.sum(da * da, axis=1))
    if var_a <= 0 or S[1] < 1e-12 * max(S[0], 1e-300):
        raise GeometryError("estimate_similarity: points are collinear or coincident")
    D = np.eye(3)
    if np.linalg.det(U) * np.linalg.det(Vt) < 0:
        D[2, 2] = -1.0
    R = U @ D @ Vt
    s = float(np.trace(np.diag(S) @ D) / var_a) if with_scale else 1.0
    t = mb - s * R @ ma
    return Similarity(s, R, t)
