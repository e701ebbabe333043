"""Least-squares refinement of tie-point observations in an oriented block.

For every tie point, the observation nearest its image's principal point is the *master*: a
template is cut around it (at the working resolution of the images given) and matched by LSM
(the estimation of :func:`~.lsm.lsm_match`, affine shaping and gain/offset) into every other
image that observes the point, starting at that image's own observation, with the shaping started
from the geometry (:func:`~.lsm.plane_shape` on the plane through the point facing the master
camera). Matches that converge with a high correlation, a small move and a small standard
deviation replace the observation; the others keep it. The master observation defines the point
and is unchanged.

Cost: the templates are cut per master image and the matches run per search image in compiled
loops (:func:`~.lsm.extract_templates`, :func:`~.lsm.plane_shapes`, :func:`~.lsm.lsm_match_many`);
bench/bench_tiepoints.py prints the wall time with the accuracy figures.

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
from .lsm import LsmConfig, extract_templates, lsm_match_many, plane_shapes


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
        Cancel is checked before every search image.

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
    cams = [
        block.cameras[int(block.image_camera[i])].scaled(float(sc[i, 0]), float(sc[i, 1]))
        for i in range(n_img)
    ]
    obs_img = np.asarray(block.obs_image, dtype=np.int64)
    obs_pt = np.asarray(block.obs_point, dtype=np.int64)
    obs_xy = np.array(block.obs_xy, dtype=np.float64, copy=True).reshape(-1, 2)
    n_obs = len(obs_xy)
    refined = np.zeros(n_obs, dtype=bool)
    sigma = np.full((n_obs, 2), np.nan)
    lsm_cfg = LsmConfig(coarse_sigma=0.0, max_shift=cfg.max_shift, min_correlation=cfg.min_correlation)
    # every observation at the working resolution
    xw = (obs_xy + 0.5) * sc[obs_img] - 0.5
    geom = np.array([(c.cx, c.cy, c.width, c.height) for c in cams], dtype=np.float64).reshape(-1, 4)[obs_img]
    off = np.hypot((xw[:, 0] - geom[:, 0]) / geom[:, 2], (xw[:, 1] - geom[:, 1]) / geom[:, 3])
    # master of every point: the observation nearest its camera's principal point (least
    # distortion, most frontal); ties to the first observation
    order = np.lexsort((np.arange(n_obs), off, obs_pt))
    first = np.flatnonzero(np.r_[True, np.diff(obs_pt[order]) != 0]) if n_obs else np.zeros(0, int)
    n_pts = len(first)
    counts = np.diff(np.r_[first, n_obs])
    masters = order[first[counts >= 2]]  # points seen at least twice
    # templates, cut per master image
    half = cfg.half_size
    templates = np.full((len(masters), 2 * half + 1, 2 * half + 1), np.nan)
    m_img = obs_img[masters]
    for i in np.unique(m_img):
        sel = np.flatnonzero(m_img == i)
        templates[sel] = extract_templates(images[i], xw[masters[sel]], half)
    flat = templates.reshape(len(masters), (2 * half + 1) ** 2)
    with np.errstate(invalid="ignore"):
        good = np.all(np.isfinite(flat), axis=1) & (
            np.std(flat, axis=1) > 1e-6 * np.maximum(1.0, np.abs(flat).max(axis=1, initial=0.0))
        )
    failed_template = int((~good).sum())
    # the other observations of the points with a template
    slot = np.full(int(obs_pt.max()) + 1 if n_obs else 0, -1, dtype=np.int64)
    slot[obs_pt[masters[good]]] = np.flatnonzero(good)
    is_master = np.zeros(n_obs, dtype=bool)
    is_master[masters] = True
    cand = np.flatnonzero((slot[obs_pt] >= 0) & ~is_master) if n_obs else np.zeros(0, int)
    tslot = slot[obs_pt[cand]]
    mi = obs_img[masters[tslot]]
    X = np.asarray(block.points, dtype=np.float64)[obs_pt[cand]]
    centers = np.asarray(block.centers, dtype=np.float64)
    shapes = plane_shapes(X, X - centers[mi], mi, obs_img[cand], block.rotations, centers, cams)
    finite = np.all(np.isfinite(shapes.reshape(-1, 4)), axis=1)
    cand, tslot, shapes = cand[finite], tslot[finite], shapes[finite]
    tried = len(cand)
    moves = []
    search = obs_img[cand]
    todo = np.unique(search)
    for step, i in enumerate(todo):
        if prog.cancelled():
            raise CancelledError("cancelled by the user")
        prog.update(step / max(len(todo), 1), f"refining tie points: image {step + 1} of {len(todo)}")
        sel = np.flatnonzero(search == i)
        o = cand[sel]
        r = lsm_match_many(templates, images[i], xw[o], shapes[sel], lsm_cfg, template_index=tslot[sel])
        ok = r.converged & np.all(r.sigma <= cfg.max_sigma, axis=1)
        o, xy, sg = o[ok], r.xy[ok], r.sigma[ok]
        new = (xy + 0.5) / sc[i] - 0.5
        moves.append(np.hypot(*(new - obs_xy[o]).T))
        obs_xy[o] = new
        sigma[o] = sg / sc[i]
        refined[o] = True
    moves_all = np.concatenate(moves) if moves else np.zeros(0)
    prog.update(1.0, f"refined {int(refined.sum())} of {tried} tie-point observations")
    stats = {
        "points": n_pts,
        "observations": n_obs,
        "tried": tried,
        "refined": int(refined.sum()),
        "no_template": failed_template,
        "median_move_px": float(np.median(moves_all)) if len(moves_all) else float("nan"),
        "median_sigma_px": float(np.nanmedian(sigma[refined])) if refined.any() else float("nan"),
    }
    return TieRefinement(obs_xy, refined, sigma, stats)
