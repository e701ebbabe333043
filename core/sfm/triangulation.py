"""Multi-view triangulation of tracks (local frame).

A track's point is the least-squares intersection of its viewing rays (the
point minimising the sum of squared perpendicular distances to the rays), then
refined by a few Gauss-Newton steps on the reprojection error in normalised
image coordinates. Each point gets its largest pairwise intersection angle
and its maximal reprojection error (pixels) for the acceptance tests of the
reconstruction.

Tracks are given in CSR form: observations of track ``t`` are
``obs[offsets[t]:offsets[t+1]]``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..jit import njit, pjit, prange


@dataclass
class Triangulated:
    """Triangulation result per track.

    Attributes
    ----------
    xyz : (T, 3) float64
        Points, local frame (NaN where triangulation failed).
    angle : (T,) float64
        Largest intersection angle between two rays of the track, radians.
    max_error : (T,) float64
        Largest reprojection error over the track's observations, in the units
        of the ``scale`` passed (pixels when ``scale`` is the focal length).
    ok : (T,) bool
        Finite, in front of every camera that observes it.
    """

    xyz: np.ndarray
    angle: np.ndarray
    max_error: np.ndarray
    ok: np.ndarray


@njit
def _solve3(A, b):
    # Cramer's rule for a symmetric 3x3 system; returns (x, det)
    a00, a01, a02 = A[0, 0], A[0, 1], A[0, 2]
    a11, a12, a22 = A[1, 1], A[1, 2], A[2, 2]
    c00 = a11 * a22 - a12 * a12
    c01 = a02 * a12 - a01 * a22
    c02 = a01 * a12 - a02 * a11
    det = a00 * c00 + a01 * c01 + a02 * c02
    x = np.empty(3)
    if abs(det) < 1e-300:
        x[:] = np.nan
        return x, det
    c11 = a00 * a22 - a02 * a02
    c12 = a01 * a02 - a00 * a12
    c22 = a00 * a11 - a01 * a01
    x[0] = (c00 * b[0] + c01 * b[1] + c02 * b[2]) / det
    x[1] = (c01 * b[0] + c11 * b[1] + c12 * b[2]) / det
    x[2] = (c02 * b[0] + c12 * b[1] + c22 * b[2]) / det
    return x, det


@njit
def _to_camera(Rs, Cs, i, X):
    """Camera coordinates ``R_i (X - C_i)`` of a point."""
    p = np.empty(3)
    for r in range(3):
        p[r] = (
            Rs[i, r, 0] * (X[0] - Cs[i, 0])
            + Rs[i, r, 1] * (X[1] - Cs[i, 1])
            + Rs[i, r, 2] * (X[2] - Cs[i, 2])
        )
    return p


@njit
def _ray_intersection(img, xy, Rs, Cs, s, e, dirs):
    """Least-squares intersection of the viewing rays of one track.

    Minimises the sum of squared perpendicular distances to the rays: with ``d_k`` the unit
    direction of ray ``k`` and ``P_k = I - d_k d_k^T``, solves ``(sum P_k) X = sum P_k C_k``.

    Parameters
    ----------
    img : (M,) int64
        Image of every observation.
    xy : (M, 2) float64
        Normalised image coordinates ``(X/Z, Y/Z)`` of every observation.
    Rs : (N, 3, 3) float64
        World-to-camera rotations.
    Cs : (N, 3) float64
        Projection centres, local frame, metres.
    s, e : int
        The track's observations are ``s`` to ``e - 1`` (at least two).
    dirs : (e - s, 3) float64
        Output: unit ray directions ``R^T (x, y, 1) / |.|`` in the local frame.

    Returns
    -------
    X : (3,) float64
        The point, local frame, metres; NaN when the rays are (nearly) parallel.
    """
    A = np.zeros((3, 3))
    b = np.zeros(3)
    for k in range(e - s):
        i = img[s + k]
        # ray direction in the local frame: R^T (x, y, 1)
        dx = Rs[i, 0, 0] * xy[s + k, 0] + Rs[i, 1, 0] * xy[s + k, 1] + Rs[i, 2, 0]
        dy = Rs[i, 0, 1] * xy[s + k, 0] + Rs[i, 1, 1] * xy[s + k, 1] + Rs[i, 2, 1]
        dz = Rs[i, 0, 2] * xy[s + k, 0] + Rs[i, 1, 2] * xy[s + k, 1] + Rs[i, 2, 2]
        nrm = np.sqrt(dx * dx + dy * dy + dz * dz)
        d0, d1, d2 = dx / nrm, dy / nrm, dz / nrm
        dirs[k, 0], dirs[k, 1], dirs[k, 2] = d0, d1, d2
        P = np.empty((3, 3))
        P[0, 0] = 1 - d0 * d0
        P[0, 1] = -d0 * d1
        P[0, 2] = -d0 * d2
        P[1, 0] = -d1 * d0
        P[1, 1] = 1 - d1 * d1
        P[1, 2] = -d1 * d2
        P[2, 0] = -d2 * d0
        P[2, 1] = -d2 * d1
        P[2, 2] = 1 - d2 * d2
        for r in range(3):
            for c in range(3):
                A[r, c] += P[r, c]
            b[r] += P[r, 0] * Cs[i, 0] + P[r, 1] * Cs[i, 1] + P[r, 2] * Cs[i, 2]
    X, _ = _solve3(A, b)
    return X


@njit
def _largest_ray_angle(dirs):
    """Largest angle between two of the unit rays ``dirs`` ((m, 3) float64), radians."""
    m = dirs.shape[0]
    mind = 1.0  # cos of the largest angle = the smallest dot product
    for k in range(m):
        for q in range(k + 1, m):
            dd = dirs[k, 0] * dirs[q, 0] + dirs[k, 1] * dirs[q, 1] + dirs[k, 2] * dirs[q, 2]
            if dd < mind:
                mind = dd
    return np.arccos(min(max(mind, -1.0), 1.0))


@njit
def _refine_point(img, xy, Rs, Cs, s, e, X, iterations):
    """Gauss-Newton steps on the normalised reprojection error of one track's point, in place.

    Minimises ``sum_k |pi(R_k (X - C_k)) - xy_k|^2`` with ``pi(p) = (p_x / p_z, p_y / p_z)``;
    stops early when the point falls behind a camera or the normal equations are singular.

    Parameters
    ----------
    img, xy, Rs, Cs, s, e
        As for :func:`_ray_intersection`.
    X : (3,) float64
        The point, local frame, metres; updated in place.
    iterations : int
        Largest number of steps.
    """
    for _ in range(iterations):
        H = np.zeros((3, 3))
        g = np.zeros(3)
        behind = False
        for k in range(e - s):
            i = img[s + k]
            p = _to_camera(Rs, Cs, i, X)
            if p[2] <= 0:
                behind = True
                break
            iz = 1.0 / p[2]
            rx = p[0] * iz - xy[s + k, 0]
            ry = p[1] * iz - xy[s + k, 1]
            for c in range(3):
                jx = (Rs[i, 0, c] - p[0] * iz * Rs[i, 2, c]) * iz
                jy = (Rs[i, 1, c] - p[1] * iz * Rs[i, 2, c]) * iz
                g[c] += jx * rx + jy * ry
                for c2 in range(3):
                    jx2 = (Rs[i, 0, c2] - p[0] * iz * Rs[i, 2, c2]) * iz
                    jy2 = (Rs[i, 1, c2] - p[1] * iz * Rs[i, 2, c2]) * iz
                    H[c, c2] += jx * jx2 + jy * jy2
        if behind:
            break
        step, _ = _solve3(H, g)
        if not np.isfinite(step[0]):
            break
        X[0] -= step[0]
        X[1] -= step[1]
        X[2] -= step[2]


@njit
def _largest_reprojection_error(img, xy, Rs, Cs, scale, s, e, X):
    """Largest reprojection error of a track's point and whether every camera sees it in front.

    Parameters
    ----------
    img, xy, Rs, Cs, s, e
        As for :func:`_ray_intersection`.
    scale : (N,) float64
        Per image, multiplies normalised errors into the reported unit (pixels with the focal
        length).
    X : (3,) float64
        The point, local frame, metres.

    Returns
    -------
    worst : float
        Largest error over the observations, in ``scale`` units (of those checked before a
        camera saw the point behind it).
    in_front : bool
        False when the point lies behind (or in the plane of) a camera.
    """
    worst = 0.0
    for k in range(e - s):
        i = img[s + k]
        p = _to_camera(Rs, Cs, i, X)
        if p[2] <= 0:
            return worst, False
        ex = (p[0] / p[2] - xy[s + k, 0]) * scale[i]
        ey = (p[1] / p[2] - xy[s + k, 1]) * scale[i]
        err = np.sqrt(ex * ex + ey * ey)
        if err > worst:
            worst = err
    return worst, True


@pjit
def _triangulate(offsets, img, xy, Rs, Cs, scale, iterations, out, angle, max_err, ok):
    """Triangulate every track (parallel over tracks): rays -> point -> refinement -> checks.

    Parameters
    ----------
    offsets : (T + 1,) int64
        CSR offsets of the tracks into the observations.
    img : (M,) int64
        Image of every observation (index into ``Rs``, ``Cs``, ``scale``).
    xy : (M, 2) float64
        Undistorted normalised image coordinates of the observations.
    Rs : (N, 3, 3) float64
        World-to-camera rotations.
    Cs : (N, 3) float64
        Projection centres, local frame, metres.
    scale : (N,) float64
        Normalised error -> reported unit (pixels with the focal length).
    iterations : int
        Gauss-Newton steps per point.
    out : (T, 3) float64
        Output: points, local frame, metres (NaN where the rays do not intersect).
    angle : (T,) float64
        Output: largest intersection angle, radians (0 for tracks of fewer than two rays).
    max_err : (T,) float64
        Output: largest reprojection error, ``scale`` units (inf where not triangulated).
    ok : (T,) bool
        Output: triangulated, in front of every camera, finite error.
    """
    n_tracks = offsets.shape[0] - 1
    for t in prange(n_tracks):
        s, e = offsets[t], offsets[t + 1]
        ok[t] = False
        angle[t] = 0.0
        max_err[t] = np.inf
        out[t, :] = np.nan
        if e - s < 2:
            continue
        dirs = np.empty((e - s, 3))
        X = _ray_intersection(img, xy, Rs, Cs, s, e, dirs)
        if not np.isfinite(X[0]):
            continue
        angle[t] = _largest_ray_angle(dirs)
        _refine_point(img, xy, Rs, Cs, s, e, X, iterations)
        worst, in_front = _largest_reprojection_error(img, xy, Rs, Cs, scale, s, e, X)
        out[t, 0], out[t, 1], out[t, 2] = X[0], X[1], X[2]
        max_err[t] = worst
        ok[t] = in_front and np.isfinite(worst)


def triangulate_tracks(
    offsets, image_index, xy_norm, Rs, Cs, scale=None, iterations: int = 3
) -> Triangulated:
    """Triangulate many tracks at once.

    Parameters
    ----------
    offsets : (T + 1,) int64
        CSR offsets of the tracks into the observation arrays.
    image_index : (M,) int64
        Image of every observation (index into ``Rs``/``Cs``).
    xy_norm : (M, 2) float64
        Undistorted normalised image coordinates ``(X/Z, Y/Z)`` of the observations.
    Rs : (N, 3, 3) float64
        World-to-camera rotations of the images.
    Cs : (N, 3) float64
        Projection centres, local frame.
    scale : (N,) float64, optional
        Multiplies normalised errors into pixels (the focal length); default 1.
    iterations : int
        Gauss-Newton refinement steps.
    """
    offsets = np.ascontiguousarray(offsets, dtype=np.int64)
    img = np.ascontiguousarray(image_index, dtype=np.int64)
    xy = np.ascontiguousarray(xy_norm, dtype=np.float64).reshape(-1, 2)
    Rs = np.ascontiguousarray(Rs, dtype=np.float64).reshape(-1, 3, 3)
    Cs = np.ascontiguousarray(Cs, dtype=np.float64).reshape(-1, 3)
    if offsets.ndim != 1 or len(offsets) < 1 or offsets[0] != 0 or offsets[-1] != len(img):
        raise InputError("triangulate_tracks: offsets must start at 0 and end at the number of observations")
    if np.any(np.diff(offsets) < 0):
        raise InputError("triangulate_tracks: offsets must be non-decreasing")
    if len(xy) != len(img):
        raise InputError("triangulate_tracks: image_index and xy_norm differ in length")
    if len(img) and (img.min() < 0 or img.max() >= len(Rs) or len(Rs) != len(Cs)):
        raise InputError("triangulate_tracks: image index out of range")
    sc = np.ones(len(Rs)) if scale is None else np.ascontiguousarray(scale, dtype=np.float64).reshape(-1)
    n = len(offsets) - 1
    out = np.empty((n, 3))
    angle = np.empty(n)
    err = np.empty(n)
    ok = np.empty(n, dtype=np.bool_)
    _triangulate(offsets, img, xy, Rs, Cs, sc, int(iterations), out, angle, err, ok)
    return Triangulated(out, angle, err, ok)
