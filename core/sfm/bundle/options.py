"""Configuration, result and robust losses of the bundle adjustment."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError

LOSSES = ("none", "huber", "cauchy", "soft_l1")


@dataclass
class BundleConfig:
    """Options of :func:`~.solver.bundle_adjust`.

    Parameters
    ----------
    max_iterations : int
        Levenberg–Marquardt trials (accepted or rejected steps).
    function_tolerance : float
        Stop when an accepted step lowers the cost by less than this fraction.
    parameter_tolerance : float
        Stop when ``|h| <= tol * (|x| + tol)`` (all unknowns stacked).
    gradient_tolerance : float
        Stop when ``max|g| <= tol * max|g_0|`` (relative to the first gradient).
    loss : {"none", "huber", "cauchy", "soft_l1"}
        Robust loss on the reprojection error norm, applied by IRLS weights
        recomputed at every linearisation.
    loss_scale : float
        Scale ``k`` of the loss, pixels: residuals with ``|r| <= k`` have
        (nearly) full weight.
    initial_damping : float
        Initial ``lambda`` of ``(A + lambda diag(A)) h = g``; Nielsen update.
    gauge : {"auto", "none"}
        Datum fixing without priors (see :mod:`.problem`).
    linear_solver : {"auto", "dense", "sparse"}
        Reduced camera system: dense Cholesky, or scipy.sparse CSR with
        Jacobi-preconditioned conjugate gradients (fastest measured for large
        systems; SuperLU ``spsolve`` was 4-15x slower). "auto": dense up to
        ``dense_limit`` columns.
    dense_limit : int
        Largest reduced system solved densely in "auto".
    compute_covariance : bool
        Posterior standard deviations of the camera-side unknowns (inverse of
        the reduced system) when it is dense.
    """

    max_iterations: int = 50
    function_tolerance: float = 1e-8
    parameter_tolerance: float = 1e-10
    gradient_tolerance: float = 1e-10
    loss: str = "none"
    loss_scale: float = 1.0
    initial_damping: float = 1e-4
    gauge: str = "auto"
    linear_solver: str = "auto"
    dense_limit: int = 3000
    compute_covariance: bool = True

    def validate(self) -> None:
        if not isinstance(self.max_iterations, int | np.integer) or self.max_iterations < 1:
            raise InputError(
                f"bundle: max_iterations must be a positive integer, got {self.max_iterations!r}"
            )
        for name in ("function_tolerance", "parameter_tolerance", "gradient_tolerance", "initial_damping"):
            v = getattr(self, name)
            if not (isinstance(v, int | float) and np.isfinite(v) and v >= 0):
                raise InputError(f"bundle: {name} must be a non-negative number, got {v!r}")
        if self.loss not in LOSSES:
            raise InputError(f"bundle: loss must be one of {LOSSES}, got {self.loss!r}")
        if not (np.isfinite(self.loss_scale) and self.loss_scale > 0):
            raise InputError(f"bundle: loss_scale must be positive (pixels), got {self.loss_scale!r}")
        if self.linear_solver not in ("auto", "dense", "sparse"):
            raise InputError(
                f"bundle: linear_solver must be auto, dense or sparse, got {self.linear_solver!r}"
            )
        if self.gauge not in ("auto", "none"):
            raise InputError(f"bundle: gauge must be 'auto' or 'none', got {self.gauge!r}")


@dataclass
class BundleResult:
    """Outcome of a bundle adjustment (an estimation failure is reported, not raised).

    Attributes
    ----------
    intrinsics : (n_cam, 9); rotations : (n_img, 3, 3); centers : (n_img, 3); points : (n_pt, 3)
        Adjusted values (local frame, pixels, world-to-camera rotations).
    residuals : (n_obs, 2)
        ``projected - observed`` pixels at the solution; NaN for invalid
        observations (point behind the camera).
    weights : (n_obs,)
        Final robust (IRLS) weight factor in [0, 1] per observation, 0 if invalid.
    valid : (n_obs,) bool
        Observations that took part.
    sigma0 : float
        A posteriori standard deviation of unit weight:
        ``sqrt((sum_o w_o |r_o|^2 / sigma_o^2 + sum priors (e / sigma)^2) / redundancy)``
        with ``redundancy = 2 n_obs + 3 n_point_priors + 3 n_centre_priors
        - n_camera_unknowns - 3 n_points`` (valid observations, estimated
        points only). About 1 when ``obs_sigma`` is right; equal to the pixel
        noise when ``obs_sigma = 1``. NaN when the redundancy is not positive.
    sigma0_mad : float
        Robust counterpart: ``1.4826 median |r / sigma|`` over residual
        coordinates times ``sqrt(n_equations / redundancy)`` (residuals are
        smaller than the noise by that factor on average); insensitive to
        outliers.
    redundancy : int
    rms : float
        Reprojection error ``sqrt(mean |r|^2)``, pixels, over valid observations.
    rms_per_image : (n_img,)
        Same per image (NaN for images without observations).
    n_iterations : int
    converged : bool
    reason : str
        "cost", "step", "gradient", "max_iterations", "damping" (no step
        lowered the cost) or "no_unknowns".
    cost_history : list of float
        ``0.5 * sum rho`` after each iteration (first entry = initial cost).
    iteration_times : list of float
        Seconds per iteration.
    intrinsics_std : (n_cam, 9) or None
        Posterior standard deviations (``sigma0^2`` times the inverse of the
        reduced normal matrix; relative to the datum); NaN for held values.
    pose_std : (n_img, 6) or None
        Same for ``[rotation (rad, camera axes), C (m)]``.
    gauge : str
        How the datum was defined.
    n_removed : int
        Observations removed by :func:`~.outliers.adjust_with_outlier_rejection`.
    """

    intrinsics: np.ndarray
    rotations: np.ndarray
    centers: np.ndarray
    points: np.ndarray
    residuals: np.ndarray
    weights: np.ndarray
    valid: np.ndarray
    sigma0: float
    sigma0_mad: float
    redundancy: int
    rms: float
    rms_per_image: np.ndarray
    n_iterations: int
    converged: bool
    reason: str
    cost_history: list[float] = field(default_factory=list)
    iteration_times: list[float] = field(default_factory=list)
    intrinsics_std: np.ndarray | None = None
    pose_std: np.ndarray | None = None
    gauge: str = ""
    n_removed: int = 0
    removed: np.ndarray | None = None

    def summary(self) -> str:
        return (
            f"bundle: {self.reason} after {self.n_iterations} iterations, sigma0 {self.sigma0:.3f}, "
            f"RMS {self.rms:.3f} px, redundancy {self.redundancy}, removed {self.n_removed}"
        )


def robust_weights(s: np.ndarray, loss: str, k: float) -> tuple[np.ndarray, np.ndarray]:
    """``rho(s)`` and ``rho'(s)`` of squared residual norms ``s`` (pixels^2).

    ``rho(s) = s`` for "none"; Huber ``2k sqrt(s) - k^2`` beyond ``k``;
    Cauchy ``k^2 log(1 + s / k^2)``; soft-L1 ``2 k^2 (sqrt(1 + s / k^2) - 1)``.
    """
    if loss == "none":
        return s, np.ones_like(s)
    k2 = k * k
    if loss == "huber":
        big = s > k2
        root = np.sqrt(np.where(big, s, 1.0))
        return np.where(big, 2.0 * k * root - k2, s), np.where(big, k / root, 1.0)
    if loss == "cauchy":
        return k2 * np.log1p(s / k2), 1.0 / (1.0 + s / k2)
    q = np.sqrt(1.0 + s / k2)
    return 2.0 * k2 * (q - 1.0), 1.0 / q
