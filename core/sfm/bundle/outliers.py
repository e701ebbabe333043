"""Bundle adjustment with rejection of gross observation errors."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...errors import InputError
from ...progress import Progress, Steps
from .options import BundleConfig, BundleResult
from .problem import BundleProblem
from .solver import bundle_adjust


def adjust_with_outlier_rejection(
    problem: BundleProblem,
    config: BundleConfig | None = None,
    k_sigma: float = 4.0,
    threshold_px: float | None = None,
    max_rounds: int = 3,
    reference: str = "sigma0",
    rerun_loss: str | None = "none",
    progress: Progress | None = None,
) -> BundleResult:
    """Adjust, remove observations with large residuals, adjust again.

    An observation is removed when its residual norm ``|r|`` (pixels)
    exceeds ``threshold_px``, or, when that is None, when ``|r| / obs_sigma >
    k_sigma * s0`` with ``s0`` the result's ``sigma0`` (``reference="sigma0"``)
    or ``sigma0_mad`` (``"mad"``, preferable with a robust loss, whose
    ``sigma0`` is inflated by the down-weighted outliers). For Gaussian noise
    the norm of a 2-D residual exceeds ``4 s0`` with probability
    ``exp(-8) = 0.03 %``. Each round restarts from the previous solution;
    rounds stop when nothing more is removed. The re-runs use the loss
    ``rerun_loss`` (default plain least squares, so that the final ``sigma0``
    and posterior standard deviations are those of the cleaned data; None
    keeps ``config.loss``).

    Returns
    -------
    BundleResult
        Of the last adjustment, with ``residuals`` / ``valid`` / ``weights``
        for *all* input observations (removed ones: ``valid`` False,
        residual computed at the solution is kept for inspection),
        ``n_removed`` and ``removed`` (n_obs,) bool.
    """
    if not (k_sigma > 0) or (threshold_px is not None and not threshold_px > 0):
        raise InputError("outlier rejection: k_sigma and threshold_px must be positive")
    if reference not in ("sigma0", "mad"):
        raise InputError(f"outlier rejection: reference must be 'sigma0' or 'mad', got {reference!r}")
    problem.validate()
    n = problem.n_observations
    keep = np.ones(n, dtype=bool)
    steps = Steps(progress, [1.0] * (max_rounds + 1))
    cfg = config or BundleConfig()
    res = bundle_adjust(problem, cfg, steps[0])
    rerun_cfg = cfg if rerun_loss is None else replace(cfg, loss=rerun_loss)
    full_r = res.residuals
    for rnd in range(max_rounds):
        norm = np.linalg.norm(full_r, axis=1)
        if threshold_px is not None:
            bad = norm > threshold_px
        else:
            s0 = res.sigma0 if reference == "sigma0" else res.sigma0_mad
            bad = norm / problem.obs_sigma > k_sigma * s0
        bad &= keep
        if not bad.any():
            break
        keep &= ~bad
        sub = replace(
            problem,
            intrinsics=res.intrinsics,
            rotations=res.rotations,
            centers=res.centers,
            points=res.points,
            obs_image=problem.obs_image[keep],
            obs_point=problem.obs_point[keep],
            obs_xy=problem.obs_xy[keep],
            obs_sigma=np.asarray(problem.obs_sigma)[keep],
        )
        res = bundle_adjust(sub, rerun_cfg, steps[rnd + 1])
        full_r = _full_residuals(problem, res)
        full_r_valid = np.zeros(n, dtype=bool)
        full_r_valid[np.flatnonzero(keep)] = res.valid
        weights = np.zeros(n)
        weights[np.flatnonzero(keep)] = res.weights
        res.valid, res.weights = full_r_valid, weights
        res.residuals = full_r
    res.removed = ~keep
    res.n_removed = int((~keep).sum())
    return res


def _full_residuals(problem: BundleProblem, res: BundleResult) -> np.ndarray:
    """Residuals of every input observation at the solution of ``res`` (NaN behind a camera)."""
    from .jacobians import _residuals

    n = problem.n_observations
    r = np.zeros((n, 2))
    valid = np.zeros(n, dtype=np.bool_)
    _residuals(
        res.points,
        res.rotations,
        res.centers,
        res.intrinsics,
        problem.image_camera,
        problem.obs_image,
        problem.obs_point,
        problem.obs_xy,
        r,
        valid,
    )
    r[~valid] = np.nan
    return r
