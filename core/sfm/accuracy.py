"""What limits the check-point accuracy of a block, and whether the adjustment converged: the
sentences the orientation report prints next to the numbers, computed from the data.

Everything here reads the control (coordinates, stated standard deviations, image measurements),
the check-point errors, the ground sample distance and the bundle result; nothing is specific to
a sample. World coordinates in metres (a projected CRS).
"""

from __future__ import annotations

import numpy as np

#: Below this ratio of the smaller to the larger plan spread, control points count as "on a line".
COLLINEAR_RATIO = 0.25
#: Heights spanning less than this (metres) count as "all equal" (plan-only control).
FLAT_HEIGHTS_M = 0.001


def control_geometry(xyz: np.ndarray, sigma: np.ndarray | None = None) -> dict:
    """Spread and shape of the control points.

    Parameters
    ----------
    xyz : (n, 3) float64
        Control point coordinates, metres.
    sigma : (n, 3) float64, optional
        Their stated standard deviations (X, Y, Z), metres.

    Returns
    -------
    dict
        ``n``; ``spread_along_m`` / ``spread_across_m`` (root-mean-square distance from the centroid
        along the principal plan axis and across it); ``across_ratio`` (across / along, 0 for points
        on a line, 1 for an even spread; NaN for fewer than 2 points); ``height_range_m``;
        ``flat_heights`` (all heights equal: plan-only control); ``sigma_xy_m`` / ``sigma_z_m``
        (medians of the stated sigmas, NaN when unknown).
    """
    p = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
    n = len(p)
    out: dict = {"n": n}
    if n >= 2:
        d = p[:, :2] - p[:, :2].mean(0)
        s = np.linalg.svd(d, compute_uv=False) / np.sqrt(n)
        along, across = float(s[0]), float(s[1]) if len(s) > 1 else 0.0
        out.update(
            spread_along_m=along,
            spread_across_m=across,
            across_ratio=across / along if along > 0 else float("nan"),
            height_range_m=float(np.ptp(p[:, 2])),
        )
        out["flat_heights"] = bool(out["height_range_m"] < FLAT_HEIGHTS_M)
    else:
        out.update(spread_along_m=0.0, spread_across_m=0.0, across_ratio=float("nan"))
        out.update(height_range_m=0.0, flat_heights=False)
    if sigma is not None and len(sigma):
        sg = np.asarray(sigma, dtype=np.float64).reshape(-1, 3)
        out["sigma_xy_m"] = float(np.median(sg[:, :2]))
        out["sigma_z_m"] = float(np.median(sg[:, 2]))
    else:
        out["sigma_xy_m"] = out["sigma_z_m"] = float("nan")
    return out


def check_point_notes(
    geometry: dict, check_rmse: dict, gsd_m: float, n_check: int, control_views: dict | None = None
) -> list[str]:
    """Sentences that explain the check-point errors (what limits them, what to expect).

    Parameters
    ----------
    geometry : dict
        :func:`control_geometry` of the control points.
    check_rmse : dict
        ``x``, ``y``, ``z`` RMSE of the check points, metres (empty when there are none).
    gsd_m : float
        Median ground sample distance of the photos, metres (NaN when unknown).
    n_check : int
        Number of check points evaluated.
    control_views : dict, optional
        Images measuring each control point (name -> count).
    """
    notes: list[str] = []
    n = int(geometry.get("n", 0))
    if not check_rmse or n_check == 0:
        return notes
    xy = float(np.hypot(check_rmse["x"], check_rmse["y"]))
    z = float(check_rmse["z"])
    limits = []
    if n < 4:
        why = "no redundancy: a wrong point goes unseen" if n == 3 else "fewer than the 3 that fix a datum"
        limits.append(f"only {n} control point(s) ({why})")
    ratio = geometry.get("across_ratio", float("nan"))
    if n >= 3 and np.isfinite(ratio) and ratio < COLLINEAR_RATIO:
        limits.append(
            f"the control points lie nearly on a line ({geometry['spread_across_m']:.1f} m across against "
            f"{geometry['spread_along_m']:.1f} m along): the block's tilt about that line is weakly fixed, "
            "so errors grow with the distance from it"
        )
    if geometry.get("flat_heights"):
        limits.append(
            "all control heights are equal (plan-only control): heights are relative to a horizontal "
            "plane through the targets, and the Z of the check points measures that plane, not the block"
        )
    few = sorted(name for name, k in (control_views or {}).items() if k < 3)
    if few:
        limits.append(
            f"control point(s) {', '.join(few)} measured in fewer than 3 images (a point seen twice is "
            "barely checked and, between neighbouring photos, poorly intersected)"
        )
    sxy = geometry.get("sigma_xy_m", float("nan"))
    if np.isfinite(sxy) and xy > 5.0 * max(sxy, 1e-6):
        limits.append(
            f"the check-point error in plan ({xy:.2f} m) is {xy / max(sxy, 1e-6):.0f} times the stated "
            f"control accuracy (sigma XY {sxy:.3f} m): the control is less accurate than stated, or its "
            "geometry does not fix the block (errors of metres are typical of hand-held GNSS positions)"
        )
    lead = f"Check points: plan RMSE {xy:.2f} m, height RMSE {z:.2f} m from {n_check} point(s)"
    if np.isfinite(gsd_m) and gsd_m > 0:
        lead += f" ({xy / gsd_m:.0f} and {z / gsd_m:.0f} times the ground sample distance of {gsd_m:.3f} m)"
    notes.append(lead + ".")
    if limits:
        notes.append("What limits them: " + "; ".join(limits) + ".")
    if np.isfinite(gsd_m) and gsd_m > 0:
        notes.append(
            "With survey-grade control (1-2 cm, at least 5 points spread around the block with varied "
            f"heights), expect about 1-2 GSD in plan and 2-3 GSD in height: {gsd_m:.3f}-{2 * gsd_m:.3f} m "
            f"and {2 * gsd_m:.3f}-{3 * gsd_m:.3f} m here."
        )
    return notes


def convergence_note(converged: bool, reason: str, iterations: int, cost_history) -> str | None:
    """A warning when the bundle adjustment stopped without converging (None when it converged).

    Parameters
    ----------
    converged : bool; reason : str; iterations : int
        From :class:`~.bundle.options.BundleResult`.
    cost_history : sequence of float
        Cost after each iteration (first entry = initial cost).
    """
    if converged:
        return None
    h = np.asarray(cost_history, dtype=np.float64)
    tail = ""
    if len(h) >= 6 and h[-6] > 0:
        rate = (h[-6] - h[-1]) / h[-6] / 5.0
        tail = f" while its cost was still falling by {100.0 * rate:.2g} % per iteration"
    return (
        f"The bundle adjustment did not converge: it stopped ({reason}) after {iterations} "
        f"iterations{tail}. The orientation is the last iterate, not an optimum; its accuracy is "
        "uncertain. Common causes: weak ground control (few points, on a line, plan-only) or a "
        "block that is not rigid (weak overlap)."
    )
