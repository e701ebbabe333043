"""Rotation parametrisations; conventions in :mod:`truortho.core.geometry`.

All functions take and return float64 numpy arrays. Matrices are
world-to-camera unless a name says otherwise; omega-phi-kappa follow the
photogrammetric camera-to-world definition (see the package docstring).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import GeometryError, InputError

_FLIP = np.diag([1.0, -1.0, -1.0])


def _as_vector(value, n: int, name: str) -> np.ndarray:
    arr = np.asarray(value, dtype=np.float64).reshape(-1)
    if arr.shape != (n,):
        raise InputError(f"{name}: expected {n} numbers, got shape {np.shape(value)}")
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{name}: values must be finite, got {arr.tolist()}")
    return arr


def check_rotation_matrix(R, name: str = "rotation", tol: float = 1e-6) -> np.ndarray:
    """Validate a 3x3 rotation matrix (orthonormal, det +1) and return it as float64."""
    M = np.asarray(R, dtype=np.float64)
    if M.shape != (3, 3):
        raise InputError(f"{name}: expected a 3x3 matrix, got shape {M.shape}")
    if not np.all(np.isfinite(M)):
        raise InputError(f"{name}: matrix has non-finite values")
    err = np.abs(M @ M.T - np.eye(3)).max()
    if err > tol or abs(np.linalg.det(M) - 1.0) > tol:
        raise InputError(f"{name}: not a rotation matrix (orthonormality error {err:.2e})")
    return M


def orthonormalize(R) -> np.ndarray:
    """Nearest rotation matrix (SVD projection); raises for degenerate input."""
    M = np.asarray(R, dtype=np.float64)
    if M.shape != (3, 3) or not np.all(np.isfinite(M)):
        raise InputError("orthonormalize: expected a finite 3x3 matrix")
    U, s, Vt = np.linalg.svd(M)
    if s.min() < 1e-12 * max(s.max(), 1e-300):
        raise GeometryError("orthonormalize: matrix is singular")
    Q = U @ Vt
    if np.linalg.det(Q) < 0:
        U[:, -1] *= -1
        Q = U @ Vt
    return Q


def quaternion_to_matrix(q) -> np.ndarray:
    """Rotation matrix from a Hamilton quaternion ``(w, x, y, z)`` (normalised first)."""
    v = _as_vector(q, 4, "quaternion")
    n = float(np.linalg.norm(v))
    if n < 1e-12:
        raise InputError("quaternion: zero-length quaternion")
    w, x, y, z = v / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def matrix_to_quaternion(R) -> np.ndarray:
    """Hamilton quaternion ``(w, x, y, z)`` with ``w >= 0`` of a rotation matrix."""
    M = check_rotation_matrix(R)
    tr = M[0, 0] + M[1, 1] + M[2, 2]
    # Shepperd's method: pivot on the largest of w, x, y, z for accuracy.
    cand = np.array([tr, M[0, 0], M[1, 1], M[2, 2]])
    i = int(np.argmax(cand))
    if i == 0:
        s = math.sqrt(max(tr + 1.0, 0.0)) * 2
        q = [0.25 * s, (M[2, 1] - M[1, 2]) / s, (M[0, 2] - M[2, 0]) / s, (M[1, 0] - M[0, 1]) / s]
    elif i == 1:
        s = math.sqrt(max(1.0 + M[0, 0] - M[1, 1] - M[2, 2], 0.0)) * 2
        q = [(M[2, 1] - M[1, 2]) / s, 0.25 * s, (M[0, 1] + M[1, 0]) / s, (M[0, 2] + M[2, 0]) / s]
    elif i == 2:
        s = math.sqrt(max(1.0 + M[1, 1] - M[0, 0] - M[2, 2], 0.0)) * 2
        q = [(M[0, 2] - M[2, 0]) / s, (M[0, 1] + M[1, 0]) / s, 0.25 * s, (M[1, 2] + M[2, 1]) / s]
    else:
        s = math.sqrt(max(1.0 + M[2, 2] - M[0, 0] - M[1, 1], 0.0)) * 2
        q = [(M[1, 0] - M[0, 1]) / s, (M[0, 2] + M[2, 0]) / s, (M[1, 2] + M[2, 1]) / s, 0.25 * s]
    qa = np.asarray(q, dtype=np.float64)
    qa /= np.linalg.norm(qa)
    return -qa if qa[0] < 0 else qa


def axis_angle_to_matrix(rvec) -> np.ndarray:
    """Rotation matrix from a rotation vector (axis times angle in radians; Rodrigues)."""
    v = _as_vector(rvec, 3, "axis-angle")
    theta = float(np.linalg.norm(v))
    K = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    if theta < 1e-8:
        # second-order series keeps orthonormality to ~1e-16 for tiny angles
        return np.eye(3) + K + 0.5 * K @ K
    K /= theta
    return np.eye(3) + math.sin(theta) * K + (1.0 - math.cos(theta)) * (K @ K)


def matrix_to_axis_angle(R) -> np.ndarray:
    """Rotation vector (radians) of a rotation matrix, angle in [0, pi]."""
    M = check_rotation_matrix(R)
    q = matrix_to_quaternion(M)  # stable for every angle, w >= 0
    s = float(np.linalg.norm(q[1:]))
    if s < 1e-15:
        return np.zeros(3)
    theta = 2.0 * math.atan2(s, q[0])
    return q[1:] / s * theta


def _rx(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _ry(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def opk_to_matrix(omega: float, phi: float, kappa: float, degrees: bool = False) -> np.ndarray:
    """World-to-camera ``R`` (OpenCV axes) from photogrammetric omega, phi, kappa.

    ``M = Rx(omega) Ry(phi) Rz(kappa)`` is camera-to-world with PATB camera
    axes (x right, y up, z back); ``R = diag(1, -1, -1) M^T``.
    """
    a = _as_vector([omega, phi, kappa], 3, "omega-phi-kappa")
    if degrees:
        a = np.radians(a)
    M = _rx(a[0]) @ _ry(a[1]) @ _rz(a[2])
    return _FLIP @ M.T


def matrix_to_opk(R, degrees: bool = False) -> np.ndarray:
    """Omega, phi, kappa of a world-to-camera ``R``; phi in [-90°, 90°].

    At phi = ±90° (gimbal lock) omega is set to 0 and kappa takes the rest.
    """
    M = check_rotation_matrix(R).T @ _FLIP  # camera(PATB)-to-world
    sphi = min(max(M[0, 2], -1.0), 1.0)
    phi = math.asin(sphi)
    if abs(sphi) < 1.0 - 1e-12:
        omega = math.atan2(-M[1, 2], M[2, 2])
        kappa = math.atan2(-M[0, 1], M[0, 0])
    else:
        omega = 0.0
        kappa = math.atan2(M[1, 0], M[1, 1])
    out = np.array([omega, phi, kappa])
    return np.degrees(out) if degrees else out


def rotation_angle_between(R1, R2) -> float:
    """Angle in radians of the relative rotation ``R1 R2^T``."""
    A = np.asarray(R1, dtype=np.float64) @ np.asarray(R2, dtype=np.float64).T
    c = (np.trace(A) - 1.0) / 2.0
    return math.acos(min(max(c, -1.0), 1.0))
