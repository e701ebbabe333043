"""Datum definition: ground control (GCPs), check points and GNSS camera priors.

From an arbitrarily scaled and placed reconstruction to the CRS:

1. **Approximate datum**: control points (role ``gcp``) with at least two
   observations in registered images are triangulated in the
   reconstruction's frame; a 7-parameter similarity to their surveyed
   coordinates (local frame) moves cameras and points. Without usable
   control, EXIF GNSS camera positions play that part.
2. **Adjustment**: the block is adjusted again with the control points as
   extra points that carry both their image observations and a weighted
   prior on their coordinates (standard deviations from the GCP layer or
   defaults); GNSS centres enter as weighted priors when there is no control.
3. **Check points** never enter the adjustment: they are triangulated from
   the adjusted cameras and compared with their surveyed coordinates
   (residual per point, RMSE per axis and in 3D).

Plan-only control (heights unknown, e.g. all 0 in the file) is expressed by
a large ``sigma_z``: the similarity then still uses the given heights (a
tilt-free, horizontal datum at the given height), and the vertical check
statistics say nothing about true heights.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import GeometryError, InputError
from ..geometry.camera import Camera, undistort_points
from ..orientation import GCP
from ..progress import Progress
from .bundle import BundleConfig, BundleProblem, bundle_adjust
from .similarity import Similarity, estimate_similarity
from .triangulation import triangulate_tracks


@dataclass
class GeorefConfig:
    """Default accuracies (metres, pixels) and adjustment options."""

    gcp_sigma_xy: float = 0.02
    gcp_sigma_z: float = 0.03
    #: image measurement sigma of GCPs without their own (``GCP.obs_sigma``)
    gcp_obs_sigma_px: float = 1.0
    gps_sigma_xy: float = 3.0
    gps_sigma_z: float = 5.0
    refine_intrinsics: tuple[str, ...] = ("f", "cx", "cy", "k1", "k2", "p1", "p2")
    max_iterations: int = 50
    #: Relative cost decrease of an accepted step below which the adjustment has converged. The
    #: solver's default (1e-8) let the 105-photo 12 MP scale block creep along a weak mode for 41
    #: iterations after the 9th, lowering its cost by 1e-6 in all and moving the check points by
    #: less than 0.1 mm (20 s against 5 s); brighton's report said "did not converge" while its cost
    #: fell by 3.2e-8 per iteration.
    function_tolerance: float = 1e-7
    loss_scale_px: float = 2.0
    #: A control group (plan or height) whose misfit after the datum fit exceeds this many times
    #: its stated sigma gets the misfit as its sigma in the adjustment (see control_sigma_scale).
    control_misfit_ratio: float = 3.0
    #: With weak control geometry, loose priors on the projection centres at their levelled start,
    #: sigma = this fraction of the flying height (0 = none).
    weak_control_center_sigma: float = 0.1


@dataclass
class Block:
    """A reconstructed block in a frame (local or arbitrary) ready for adjustment."""

    image_names: list[str]
    cameras: list[Camera]
    image_camera: np.ndarray
    rotations: np.ndarray
    centers: np.ndarray
    points: np.ndarray
    obs_image: np.ndarray
    obs_point: np.ndarray
    obs_xy: np.ndarray

    @property
    def intrinsics(self) -> np.ndarray:
        return np.array([c.params for c in self.cameras])

    def transform(self, sim) -> None:
        self.rotations = self.rotations @ sim.R.T
        self.centers = sim.apply(self.centers)
        self.points = sim.apply(self.points)


@dataclass
class GeorefResult:
    method: str
    gcp_table: list[dict] = field(default_factory=list)
    check_table: list[dict] = field(default_factory=list)
    check_rmse: dict = field(default_factory=dict)
    gcp_rmse: dict = field(default_factory=dict)
    bundle: object = None
    warnings: list[str] = field(default_factory=list)
    gcp_points: np.ndarray | None = None
    #: Factors applied to the stated control sigmas (plan, height); see control_sigma_scale.
    control_sigma_scale: list[float] = field(default_factory=lambda: [1.0, 1.0])


def _gcp_tracks(block: Block, gcps: list[GCP]):
    """Observations of every GCP on images of the block: CSR arrays + names of unknown images."""
    index = {n: i for i, n in enumerate(block.image_names)}
    offs, img, xy, unknown = [0], [], [], []
    for g in gcps:
        for name, x, y in g.observations:
            if name in index:
                img.append(index[name])
                xy.append((x, y))
            else:
                unknown.append((g.name, name))
        offs.append(len(img))
    return (
        np.array(offs),
        np.array(img, dtype=np.int64),
        np.array(xy, dtype=np.float64).reshape(-1, 2),
        unknown,
    )


def triangulate_gcps(block: Block, gcps: list[GCP]):
    """Triangulate GCPs from their image measurements with the block's cameras.

    Returns (xyz (G, 3) in the block's frame, NaN where fewer than two views; n_views (G,)).
    """
    offs, img, xy, _ = _gcp_tracks(block, gcps)
    xn = np.empty_like(xy)
    for k in range(len(img)):
        cam = block.cameras[block.image_camera[img[k]]]
        xn[k] = undistort_points(xy[k : k + 1], cam)[0]
    focal = np.array([block.cameras[c].fx for c in block.image_camera])
    res = triangulate_tracks(offs, img, xn, block.rotations, block.centers, focal)
    n_views = np.diff(offs)
    xyz = res.xyz.copy()
    xyz[~res.ok | (n_views < 2)] = np.nan
    return xyz, n_views, res.max_error


def reject_gcp_outliers(
    block: Block, gcps: list[GCP], max_error_px: float = 5.0
) -> tuple[list[GCP], list[str]]:
    """Drop the one image measurement per GCP that makes its rays miss each other.

    A GCP with at least three measurements on the block whose triangulation
    fails or leaves a reprojection error above ``max_error_px`` is
    triangulated again without each measurement in turn; when exactly the
    removal of one measurement brings every error below the threshold, that
    measurement is dropped (a mis-identified target or a typo in the list).
    Returns the (copied) GCPs and a warning per dropped measurement.
    """
    out, msgs = [], []
    names = set(block.image_names)
    for g in gcps:
        obs = [o for o in g.observations if o[0] in names]
        if len(obs) < 3:
            out.append(g)
            continue
        xyz, _, err = triangulate_gcps(block, [g])
        if np.isfinite(xyz[0, 0]) and err[0] <= max_error_px:
            out.append(g)
            continue
        fixes = []
        for k in range(len(obs)):
            trial = GCP(g.name, g.xyz, g.role, g.sigma, [o for j, o in enumerate(obs) if j != k], g.obs_sigma)
            xyz_k, _, err_k = triangulate_gcps(block, [trial])
            if np.isfinite(xyz_k[0, 0]) and err_k[0] <= max_error_px:
                fixes.append((err_k[0], k, trial))
        if len(fixes) == 1 or (len(fixes) > 1 and sorted(f[0] for f in fixes)[1] > max_error_px / 2):
            e, k, trial = min(fixes, key=lambda f: f[0])
            msgs.append(
                f"GCP {g.name}: measurement on {obs[k][0]} rejected (the other rays meet within {e:.2f} px, "
                "this one does not)"
            )
            out.append(trial)
        else:
            out.append(g)
    return out, msgs


def _near_collinear(xy: np.ndarray, ratio: float = 0.2) -> bool:
    """True when plan points spread along one line (second singular value < ratio x first)."""
    d = xy - xy.mean(axis=0)
    sv = np.linalg.svd(d, compute_uv=False)
    return bool(len(xy) < 3 or sv[1] < ratio * max(sv[0], 1e-12))


def _level_rotation(block: Block) -> np.ndarray:
    """Rotation that makes the tie points' best-fitting plane horizontal, cameras above it."""
    pts = block.points[np.all(np.isfinite(block.points), axis=1)]
    if len(pts) < 10:
        raise GeometryError("too few tie points to level the block")
    c = np.median(pts, axis=0)
    _, _, vt = np.linalg.svd(pts - c, full_matrices=False)
    n = vt[2]
    if np.dot(np.median(block.centers, axis=0) - c, n) < 0:
        n = -n
    z = np.array([0.0, 0.0, 1.0])
    v = np.cross(n, z)
    s, cth = np.linalg.norm(v), float(np.dot(n, z))
    if s < 1e-12:
        return np.eye(3) if cth > 0 else np.diag([1.0, -1.0, -1.0])
    K = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]]) / s
    ang = np.arctan2(s, cth)
    return np.eye(3) + np.sin(ang) * K + (1 - np.cos(ang)) * (K @ K)


def _levelled_similarity(block: Block, src: np.ndarray, dst: np.ndarray, sigma: np.ndarray) -> Similarity:
    """Similarity for weak control: level on the tie points, then fit scale, heading and shift in plan.

    Heights: the shift in Z is the weighted mean height difference of the
    control points (weights ``1 / sigma_z^2``), so plan-only control with
    arbitrary heights still places the block at the heights it gives.
    """
    L = _level_rotation(block)
    a = src @ L.T
    b = dst
    # 2-D similarity in plan (complex least squares)
    za = a[:, 0] + 1j * a[:, 1]
    zb = b[:, 0] + 1j * b[:, 1]
    ma, mb = za.mean(), zb.mean()
    da, db = za - ma, zb - mb
    denom = float(np.sum(np.abs(da) ** 2))
    if denom <= 1e-18:
        raise GeometryError("control points coincide in plan")
    q = np.sum(np.conj(da) * db) / denom  # scale * exp(i heading)
    scale = float(abs(q))
    th = float(np.angle(q))
    Rz = np.array([[np.cos(th), -np.sin(th), 0.0], [np.sin(th), np.cos(th), 0.0], [0.0, 0.0, 1.0]])
    R = Rz @ L
    w = 1.0 / sigma[:, 2] ** 2
    t_xy = mb - q * ma
    tz = float(np.sum(w * (b[:, 2] - scale * a[:, 2])) / np.sum(w))
    return Similarity(scale, R, np.array([t_xy.real, t_xy.imag, tz]))


#: Control points from which a height misfit may be read as the block's bowl (:func:`bowl_misfit`:
#: four parameters, three points to spare).
BOWL_MIN_POINTS = 7


def bowl_misfit(xy: np.ndarray, dz: np.ndarray) -> tuple[float, float]:
    """How much of a height misfit a bowl explains: ``dz ~ a + b x + c y + d (x^2 + y^2)``.

    A nadir block adjusted from its photos alone, with the focal length and the radial distortion
    estimated, is bent into a bowl (doming): those parameters trade against height, and the tie
    points cannot tell. The control's height misfit after the datum fit is then that bowl, a smooth
    function of the position, not the control's error.

    Returns
    -------
    rms : float
        Residual height misfit after the bowl, metres (RMS with the four parameters' degrees of
        freedom taken out); NaN with fewer than :data:`BOWL_MIN_POINTS` points.
    amplitude : float
        Range of the fitted bowl over the points, metres.
    """
    xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    dz = np.asarray(dz, dtype=np.float64).reshape(-1)
    n = len(dz)
    if n < BOWL_MIN_POINTS:
        return float("nan"), float("nan")
    c = xy - xy.mean(axis=0)
    c /= max(float(np.abs(c).max()), 1e-9)
    A = np.column_stack([np.ones(n), c, (c**2).sum(axis=1)])
    sol, *_ = np.linalg.lstsq(A, dz, rcond=None)
    fit = A @ sol
    rms = float(np.sqrt(np.sum((dz - fit) ** 2) / (n - A.shape[1])))
    return rms, float(np.ptp(fit))


def control_sigma_scale(
    fitted: np.ndarray, surveyed: np.ndarray, stated: np.ndarray, ratio: float = 3.0
) -> tuple[np.ndarray, list[str]]:
    """Factors on the stated control sigmas that make them credible, and a note for each.

    A least-squares adjustment trusts its weights: control stated at 2 cm that disagrees with the
    photos by a metre bends or tilts the block to fit it (and converges slowly, if at all). The
    misfit of the control after the datum fit measures its real accuracy; when it exceeds ``ratio``
    times the stated sigma (for plan or height separately), that group's sigma becomes the misfit.

    Except in height when the misfit is the block's own bowl (:func:`bowl_misfit`, from
    :data:`BOWL_MIN_POINTS` control points): if what remains after a bowl is within ``ratio`` times
    the stated sigma, the control is right and the free block is bent, so the stated sigma stays
    and the adjustment removes the bowl. On the 105-photo 12 MP scale block the misfit was 0.30 m,
    a 0.93 m bowl explained all but 1 cm of it, and keeping the stated sigma took the check heights
    from 0.144 to 0.012 m with the same image sigma0 (on the 406-photo block the relaxed control had
    left them 0.53 m off, 17 GSD).

    Parameters
    ----------
    fitted : (n, 3) float64
        Control points triangulated from the photos, moved into the frame by the datum fit, metres.
    surveyed : (n, 3) float64
        Their surveyed coordinates, same frame.
    stated : (n, 3) float64
        Stated standard deviations (X, Y, Z), metres.
    ratio : float
        Misfit over stated sigma beyond which the sigma is replaced.

    Returns
    -------
    scale : (2,) float64
        Factors for the plan and the height sigmas (1 when credible).
    notes : list of str
    """
    d = np.asarray(fitted, dtype=np.float64) - np.asarray(surveyed, dtype=np.float64)
    sg = np.asarray(stated, dtype=np.float64).reshape(-1, 3)
    scale = np.ones(2)
    notes: list[str] = []
    if len(d) < 3:
        return scale, notes
    misfit = np.array([np.sqrt(np.mean(d[:, :2] ** 2)), np.sqrt(np.mean(d[:, 2] ** 2))])
    s0 = np.array([np.median(sg[:, :2]), np.median(sg[:, 2])])
    for k, name in enumerate(("plan", "height")):
        f = misfit[k] / max(s0[k], 1e-12)
        if f <= ratio:
            continue
        if k == 1:
            rest, amplitude = bowl_misfit(np.asarray(surveyed, dtype=np.float64)[:, :2], d[:, 2])
            if rest <= ratio * s0[k]:
                notes.append(
                    f"ground control disagrees with the photos in height by {misfit[k]:.3f} m (RMS after the "
                    f"datum fit), but a bowl of {amplitude:.3f} m explains all but {rest:.3f} m of it: the "
                    "block adjusted from its photos alone is bent (on nadir blocks the focal length and the "
                    "radial distortion trade against height); adjusted with the control at its stated sigma "
                    f"of {s0[k]:.3f} m, which removes the bowl"
                )
                continue
        scale[k] = f
        notes.append(
            f"ground control disagrees with the photos in {name} by {misfit[k]:.3f} m (RMS per axis "
            f"after the datum fit), {f:.0f} times its stated sigma of {s0[k]:.3f} m: adjusted with sigma "
            f"{misfit[k]:.3f} m, so that the control does not bend the block; state realistic "
            "accuracies (importgcps SIGMA_XY/SIGMA_Z, or the sigma_xy/sigma_z fields of the GCP layer)"
        )
    return scale, notes


def _rmse(d: np.ndarray) -> dict:
    if len(d) == 0:
        return {}
    return {
        "n": int(len(d)),
        "x": float(np.sqrt(np.mean(d[:, 0] ** 2))),
        "y": float(np.sqrt(np.mean(d[:, 1] ** 2))),
        "z": float(np.sqrt(np.mean(d[:, 2] ** 2))),
        "xy": float(np.sqrt(np.mean(d[:, 0] ** 2 + d[:, 1] ** 2))),
        "3d": float(np.sqrt(np.mean(np.sum(d**2, axis=1)))),
    }


def georeference(
    block: Block,
    gcps: list[GCP],
    offset: np.ndarray,
    gps_centers: np.ndarray | None = None,
    config: GeorefConfig | None = None,
    progress: Progress | None = None,
) -> GeorefResult:
    """Move ``block`` (in place) into the local frame ``world - offset`` and adjust it.

    Parameters
    ----------
    block : Block
        Reconstruction in an arbitrary frame; updated in place.
    gcps : list of GCP
        Ground control and check points, world coordinates.
    offset : (3,) float64
        Local frame offset.
    gps_centers : (n_img, 3) float64, optional
        GNSS camera positions in the local frame (NaN rows where unknown).
    """
    cfg = config or GeorefConfig()
    result = GeorefResult(method="none")
    gcps, rejected = reject_gcp_outliers(block, gcps)
    result.warnings += rejected
    control = [g for g in gcps if g.role == "gcp"]
    checks = [g for g in gcps if g.role == "check"]
    _, _, _, unknown = _gcp_tracks(block, gcps)
    for gname, iname in unknown:
        result.warnings.append(
            f"GCP {gname}: observation on image {iname!r}, which is not oriented or not in the block"
        )

    ctrl_xyz, ctrl_views, _ = (
        triangulate_gcps(block, control) if control else (np.zeros((0, 3)), np.zeros(0), None)
    )
    usable = np.isfinite(ctrl_xyz[:, 0]) if len(control) else np.zeros(0, bool)
    for g, ok, nv in zip(control, usable, ctrl_views, strict=True):
        if not ok and nv < 2:
            result.warnings.append(
                f"GCP {g.name}: {int(nv)} observation(s) on oriented images; at least 2 are needed, not used"
            )
        elif not ok:
            result.warnings.append(
                f"GCP {g.name}: its {int(nv)} image measurements do not intersect (triangulation failed); "
                "check them; not used"
            )
    target = np.array([g.xyz for g in control]).reshape(-1, 3) - offset
    sim = None
    weak = False
    n_use = int(usable.sum())
    if n_use >= 2:
        sig = np.array(
            [g.sigma if g.sigma is not None else [cfg.gcp_sigma_xy] * 2 + [cfg.gcp_sigma_z] for g in control]
        ).reshape(-1, 3)[usable]
        weak = n_use < 4 or _near_collinear(target[usable, :2]) or bool(np.all(sig[:, 2] > 10 * sig[:, 0]))
        try:
            if weak:
                sim = _levelled_similarity(block, ctrl_xyz[usable], target[usable], sig)
                result.warnings.append(
                    "weak control geometry (fewer than 4 points, nearly collinear, or plan-only heights): "
                    "the block was levelled on its tie points before fitting the control in plan"
                )
            else:
                sim = estimate_similarity(ctrl_xyz[usable], target[usable])
            result.method = "gcp"
        except GeometryError as err:
            result.warnings.append(f"control points unusable for the datum: {err}")
    if sim is None and gps_centers is not None:
        ok = np.all(np.isfinite(gps_centers), axis=1)
        if ok.sum() >= 3:
            try:
                sim = estimate_similarity(block.centers[ok], gps_centers[ok])
                result.method = "gps"
            except GeometryError as err:
                result.warnings.append(f"GNSS positions unusable for the datum: {err}")
    if sim is None:
        if gcps:
            result.warnings.append(
                "fewer than 2 usable control points: the block stays in an arbitrary frame"
            )
        return result
    block.transform(sim)
    # factors on the stated control sigmas (plan, height): the control's misfit after the fit
    ctrl_scale = np.ones(2)
    bowl_kept, sz, misfit_z = False, 0.0, 0.0
    if result.method == "gcp":
        stated = np.array(
            [g.sigma if g.sigma is not None else [cfg.gcp_sigma_xy] * 2 + [cfg.gcp_sigma_z] for g in control]
        ).reshape(-1, 3)[usable]
        ctrl_scale, notes = control_sigma_scale(
            sim.apply(ctrl_xyz[usable]), target[usable], stated, cfg.control_misfit_ratio
        )
        result.warnings += notes
        result.control_sigma_scale = ctrl_scale.tolist()
        # a height misfit read as the free block's bowl keeps the stated sigma; the adjustment must
        # then honour it (checked below), or the control is relaxed after all
        dz = sim.apply(ctrl_xyz[usable])[:, 2] - target[usable, 2]
        sz = float(np.median(stated[:, 2]))
        misfit_z = float(np.sqrt(np.mean(dz**2))) if len(dz) else 0.0
        bowl_kept = ctrl_scale[1] == 1.0 and misfit_z > cfg.control_misfit_ratio * sz

    # adjustment with control points as prior-weighted points
    n_tie = len(block.points)
    pts = [block.points]
    obs_img, obs_pt, obs_xy = [block.obs_image], [block.obs_point], [block.obs_xy]
    sig = [np.ones(len(block.obs_image))]
    prior_idx, prior_xyz, prior_sig = [], [], []
    if result.method == "gcp":
        ctrl_local = sim.apply(ctrl_xyz[usable])
        index = {n: i for i, n in enumerate(block.image_names)}
        k = 0
        for g, ok in zip(control, usable, strict=True):
            if not ok:
                continue
            pid = n_tie + k
            pts.append(ctrl_local[k : k + 1])
            for name, x, y in g.observations:
                if name in index:
                    obs_img.append(np.array([index[name]]))
                    obs_pt.append(np.array([pid]))
                    obs_xy.append(np.array([[x, y]]))
                    sig.append(np.array([g.obs_sigma.get(name, cfg.gcp_obs_sigma_px)]))
            s = (
                g.sigma
                if g.sigma is not None
                else np.array([cfg.gcp_sigma_xy, cfg.gcp_sigma_xy, cfg.gcp_sigma_z])
            )
            prior_idx.append(pid)
            prior_xyz.append(g.xyz - offset)
            prior_sig.append(s * ctrl_scale[[0, 0, 1]])
            k += 1
    pb = BundleProblem(
        intrinsics=block.intrinsics,
        image_camera=block.image_camera,
        rotations=block.rotations,
        centers=block.centers,
        points=np.vstack(pts),
        obs_image=np.concatenate(obs_img),
        obs_point=np.concatenate(obs_pt),
        obs_xy=np.vstack(obs_xy),
        obs_sigma=np.concatenate(sig),
        refine_intrinsics=cfg.refine_intrinsics,
        point_prior_index=np.array(prior_idx, dtype=np.int64),
        point_prior_xyz=np.array(prior_xyz).reshape(-1, 3),
        point_prior_sigma=np.array(prior_sig).reshape(-1, 3),
    )
    if result.method == "gps":
        ok = np.all(np.isfinite(gps_centers), axis=1)  # type: ignore[arg-type]
        pb.center_prior_index = np.flatnonzero(ok)
        pb.center_prior_xyz = gps_centers[ok]  # type: ignore[index]
        pb.center_prior_sigma = np.tile(
            [cfg.gps_sigma_xy, cfg.gps_sigma_xy, cfg.gps_sigma_z], (int(ok.sum()), 1)
        )
    if result.method == "gcp" and weak and cfg.weak_control_center_sigma > 0:
        # The control leaves the block's tilt weakly fixed and the start was levelled on the tie
        # points: keep that levelling, loosely, rather than let the control's errors tilt the block
        # (on the bundled sample: 57 degrees, 158 iterations, with 2 cm control that was off by 1 m).
        height = float(np.median(block.centers[:, 2]) - np.median(block.points[:, 2]))
        s_c = cfg.weak_control_center_sigma * max(abs(height), 1.0)
        pb.center_prior_index = np.arange(len(block.centers))
        pb.center_prior_xyz = block.centers.copy()
        pb.center_prior_sigma = np.full((len(block.centers), 3), s_c)
        result.warnings.append(
            f"weak control geometry: the projection centres are held loosely where the levelled start put "
            f"them (sigma {s_c:.2f} m, {cfg.weak_control_center_sigma:g} x the flying height) so that the "
            "control's errors do not tilt the block; add control points spread around the block"
        )
    conf = BundleConfig(
        max_iterations=cfg.max_iterations,
        loss="huber",
        loss_scale=cfg.loss_scale_px,
        function_tolerance=cfg.function_tolerance,
    )
    res = bundle_adjust(pb, conf, progress)
    if bowl_kept:
        rz = res.points[n_tie:, 2] - pb.point_prior_xyz[:, 2]
        rms_z = float(np.sqrt(np.mean(rz**2)))
        if rms_z > cfg.control_misfit_ratio * sz:
            # the block could not take the control's heights without straining its photos: what
            # looked like a bowl was not one; adjust as for any control that disagrees
            f = misfit_z / sz
            pb.point_prior_sigma = pb.point_prior_sigma * np.array([1.0, 1.0, f])
            result.control_sigma_scale[1] = f
            result.warnings.append(
                f"the control's heights still disagree with the adjusted block by {rms_z:.3f} m (RMS), "
                f"more than {cfg.control_misfit_ratio:g} times their stated sigma of {sz:.3f} m: adjusted "
                f"again with sigma {misfit_z:.3f} m, so that the control does not bend the block; state "
                "realistic accuracies (importgcps SIGMA_XY/SIGMA_Z, or the sigma_xy/sigma_z fields of the "
                "GCP layer)"
            )
            res = bundle_adjust(pb, conf, progress)
    result.bundle = res
    block.rotations, block.centers = res.rotations, res.centers
    block.points = res.points[:n_tie]
    for c, cam in enumerate(block.cameras):
        block.cameras[c] = Camera.from_params(res.intrinsics[c], cam.width, cam.height, cam.id)

    # control residuals (adjusted minus surveyed) and check points
    if result.method == "gcp":
        adj = res.points[n_tie:]
        d = adj - np.array(prior_xyz)
        used_ctrl = [g for g, ok in zip(control, usable, strict=True) if ok]
        result.gcp_table = [
            {
                "name": g.name,
                "x": g.xyz[0],
                "z": g.xyz[2],
                "y": g.xyz[1],
                "dx": v[0],
                "dy": v[1],
                "dz": v[2],
                "views": int(len(g.observations)),
                # stated accuracy (for the report's check-point notes)
                "sigma_xy": float(cfg.gcp_sigma_xy if g.sigma is None else np.median(g.sigma[:2])),
                "sigma_z": float(cfg.gcp_sigma_z if g.sigma is None else g.sigma[2]),
            }
            for g, v in zip(used_ctrl, d, strict=True)
        ]
        result.gcp_rmse = _rmse(d)
        result.gcp_points = adj
    if checks:
        xyz, nv, reproj = triangulate_gcps(block, checks)
        rows, ds = [], []
        for g, p, n, e in zip(checks, xyz, nv, reproj, strict=True):
            if not np.all(np.isfinite(p)):
                result.warnings.append(
                    f"check point {g.name}: {int(n)} observation(s) on oriented images; not evaluated"
                )
                continue
            dv = p - (g.xyz - offset)
            ds.append(dv)
            rows.append(
                {
                    "name": g.name,
                    "x": g.xyz[0],
                    "y": g.xyz[1],
                    "z": g.xyz[2],
                    "dx": dv[0],
                    "dy": dv[1],
                    "dz": dv[2],
                    "views": int(n),
                    "max_reproj_px": e,
                }
            )
        result.check_table = rows
        result.check_rmse = _rmse(np.array(ds).reshape(-1, 3))
    return result


def validate_gcps(gcps: list[GCP], image_names: set[str]) -> list[str]:
    """Problems that make GCPs unusable, as messages (empty list: fine).

    Raises :class:`InputError` for a GCP whose observations name no known image at all.
    """
    msgs = []
    for g in gcps:
        if not g.observations:
            msgs.append(f"GCP {g.name} has no image observations")
            continue
        known = [o for o in g.observations if o[0] in image_names]
        if not known:
            raise InputError(
                f"GCP {g.name}: its observations refer only to unknown images "
                f"({', '.join(sorted({o[0] for o in g.observations}))})"
            )
    return msgs


def block_from_reconstruction(
    rec, obs_track, obs_image, obs_xy, image_names, cameras: list[Camera], image_camera
):
    """A :class:`Block` of the registered images and triangulated tracks of a reconstruction.

    Returns the block and, for every block point, its track id.
    """
    reg = np.flatnonzero(rec.registered)
    img_map = -np.ones(len(rec.registered), dtype=np.int64)
    img_map[reg] = np.arange(len(reg))
    ok = rec.point_ok
    tracks = np.flatnonzero(ok)
    pt_map = -np.ones(len(ok), dtype=np.int64)
    pt_map[tracks] = np.arange(len(tracks))
    use = np.flatnonzero(rec.obs_valid)
    cams = [
        Camera.from_params(rec.intrinsics[c], cam.width, cam.height, cam.id) for c, cam in enumerate(cameras)
    ]
    block = Block(
        image_names=[image_names[i] for i in reg],
        cameras=cams,
        image_camera=np.asarray(image_camera)[reg],
        rotations=rec.rotations[reg],
        centers=rec.centers[reg],
        points=rec.points[tracks],
        obs_image=img_map[np.asarray(obs_image)[use]],
        obs_point=pt_map[np.asarray(obs_track)[use]],
        obs_xy=np.asarray(obs_xy)[use],
    )
    return block, tracks
