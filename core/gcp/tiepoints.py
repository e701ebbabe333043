"""Least-squares refinement of tie-point observations in an oriented block.

For every tie point, the observation nearest its image's principal point is the *master*: a
template is cut around it (at the working resolution of the images given) and matched by LSM
(:func:`~.lsm.lsm_match`, affine shaping and gain/offset) into every other image that observes
the point, starting at that image's own observation, with the shaping started from the geometry
(:func:`~.lsm.plane_shape` on the plane through the point facing the master camera). Matches
that converge with a high correlation, a small move and a small standard deviation replace the
observation; the others keep it. The master observation defines the point and is unchanged.

The collinearity-constrained MGCM is deliberately not used here: its image coordinates are the
projections of one object point through the current orientation, so feeding them back into the
bundle would only confirm that orientation. Independent matches against the master carry new
information; the bundle then decides.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import CancelledError, InputError
from ..progress import Progress, as_progress
from .lsm import LsmConfig, MgcmView, extract_template, lsm_match, plane_shape


@dataclass(frozen=True)
class TieRefineConfig:
    """Settings of :func:`refine_tie_points` (pixels at the working resolution).

    Parameters
    ----------
    half_size : int
        Template half size: ``(2 half_size + 1)^2`` pixels.
    max_shift : float
        A match moving farther from the original observation is rejected.
    min_correlation : float
        Minimum normalised cross-correlation of an accepted match.
    max_sigma : float
        Largest accepted standard deviation of a match (per axis).
    """

    half_size: int = 7
    max_shift: float = 1.5
    min_correlation: float = 0.8
    max_sigma: float = 0.3

    def __post_init__(self) -> None:
        if not (isinstance(self.half_size, int) and 2 <= self.half_size <= 50):
            raise InputError(
                f"TieRefineConfig.half_size must be an integer in [2, 50], got {self.half_size!r}"
            )
        for name in ("max_shift", "max_sigma"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"TieRefineConfig.{name} must be positive, got {v!r}")
        if not -1.0 <= self.min_correlation <= 1.0:
            raise InputError(
                f"TieRefineConfig.min_correlation must be in [-1, 1], got {self.min_correlation!r}"
            )


@dataclass(frozen=True)
class TieRefinement:
    """Result of :func:`refine_tie_points`.

    ``obs_xy`` (M, 2): observations (full-resolution pixels) with the accepted matches replaced;
    ``refined`` (M,) bool; ``sigma`` (M, 2): standard deviations of the accepted matches
    (full-resolution pixels, NaN elsewhere); ``stats``: counts and the median move.
    """

    obs_xy: np.ndarray
    refined: np.ndarray
    sigma: np.ndarray
    stats: dict = field(default_factory=dict)


def refine_tie_points(
    block,
    images,
    scales,
    config: TieRefineConfig | None = None,
    progress: Progress | None = None,
) -> TieRefinement:
    """Refine the tie-point observations of an oriented block by least-squares matching.

    Parameters
    ----------
    block : :class:`~truortho.core.sfm.georef.Block`
        Oriented block: ``cameras``, ``image_camera``, ``rotations``, ``centers``, ``points``
        (local frame), ``obs_image``, ``obs_point``, ``obs_xy`` (full-resolution pixels).
    images : sequence of (H, W) arrays
        Grey image of every block image at its working resolution.
    scales : (N, 2) float
        Per image the factors ``(sx, sy)`` from full resolution to the working resolution.
    config : TieRefineConfig, optional
    progress : Progress, optional
        Cancel is checked every few hundred points.

    Returns
    -------
    TieRefinement
    """
    cfg = config or TieRefineConfig()
    prog = as_progress(progress)
    n_img = len(block.rotations)
    sc = np.asarray(scales, dtype=np.float64).reshape(-1, 2)
    if len(images) != n_img or len(sc) != n_img:
        raise InputError(
            f"refine_tie_points: {n_img} block images but {len(images)} images and {len(sc)} scales"
        )
    if not np.all(np.isfinite(sc)) or np.any(sc <= 0):
        raise InputError("refine_tie_points: scales must be positive")
    views = []
    for i in range(n_img):
        cam = block.cameras[int(block.image_camera[i])]
        views.append(
            MgcmView(
                images[i],
                block.rotations[i],
                block.centers[i],
                cam.scaled(float(sc[i, 0]), float(sc[i, 1])),
                str(i),
            )
        )
    obs_xy = np.array(block.obs_xy, dtype=np.float64, copy=True)
    refined = np.zeros(len(obs_xy), dtype=bool)
    sigma = np.full((len(obs_xy), 2), np.nan)
    order = np.argsort(block.obs_point, kind="stable")
    starts = np.flatnonzero(np.r_[True, np.diff(block.obs_point[order]) != 0, True])
    lsm_cfg = LsmConfig(coarse_sigma=0.0, max_shift=cfg.max_shift, min_correlation=cfg.min_correlation)
    tried = failed_template = 0
    moves = []
    n_pts = len(starts) - 1
    for k in range(n_pts):
        if k % 500 == 0:
            if prog.cancelled():
                raise CancelledError("cancelled by the user")
            prog.update(k / max(n_pts, 1), f"refining tie points: {k} of {n_pts}")
        idx = order[starts[k] : starts[k + 1]]
        if len(idx) < 2:
            continue
        X = block.points[int(block.obs_point[idx[0]])]
        # master: the observation nearest its camera's principal point (least distortion, most frontal)
        off = []
        for o in idx:
            cam = views[int(block.obs_image[o])].camera
            i = int(block.obs_image[o])
            xw = (obs_xy[o] + 0.5) * sc[i] - 0.5
            off.append(math.hypot((xw[0] - cam.cx) / cam.width, (xw[1] - cam.cy) / cam.height))
        m = int(idx[int(np.argmin(off))])
        mi = int(block.obs_image[m])
        mxy = (obs_xy[m] + 0.5) * sc[mi] - 0.5
        try:
            tmpl = extract_template(views[mi].image, float(mxy[0]), float(mxy[1]), cfg.half_size)
        except InputError:
            failed_template += 1
            continue
        if float(np.std(tmpl)) <= 1e-6 * max(1.0, float(np.abs(tmpl).max())):
            failed_template += 1
            continue
        normal = X - block.centers[mi]
        for o in idx:
            if o == m:
                continue
            i = int(block.obs_image[o])
            A = plane_shape(views[mi], views[i], X, normal=normal)
            if not np.all(np.isfinite(A)):
                continue
            start = (obs_xy[o] + 0.5) * sc[i] - 0.5
            tried += 1
            r = lsm_match(
                tmpl,
                views[i].image,
                float(start[0]),
                float(start[1]),
                lsm_cfg,
                initial=np.column_stack([A, [0, 0]]),
            )
            if not r.converged or max(r.sigma_x, r.sigma_y) > cfg.max_sigma:
                continue
            new = (np.array([r.x, r.y]) + 0.5) / sc[i] - 0.5
            moves.append(float(np.hypot(*(new - obs_xy[o]))))
            obs_xy[o] = new
            sigma[o] = (r.sigma_x / sc[i, 0], r.sigma_y / sc[i, 1])
            refined[o] = True
    prog.update(1.0, f"refined {int(refined.sum())} of {tried} tie-point observations")
    stats = {
        "points": n_pts,
        "observations": len(obs_xy),
        "tried": tried,
        "refined": int(refined.sum()),
        "no_template": failed_template,
        "median_move_px": float(np.median(moves)) if moves else float("nan"),
        "median_sigma_px": float(np.nanmedian(sigma[refined])) if refined.any() else float("nan"),
    }
    return TieRefinement(obs_xy, refined, sigma, stats)
