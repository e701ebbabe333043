"""Incremental reconstruction: initial pair, resection, triangulation, bundle adjustment.

Input is a set of feature tracks (every observation: track id, image, pixel
position) and approximate interior orientations; output is a
:class:`Reconstruction` in an arbitrary similarity frame (the first camera of
the initial pair at the origin, unit baseline), to be georeferenced by
:mod:`.georef`.

Method (as COLMAP/OpenSfM, with the adjustment written here):

1. **Initial pair**: among the pairs sharing the most tracks, the relative
   orientation from the essential matrix (MAGSAC, fixed seed) on
   undistorted normalised coordinates; the pair with the most well-conditioned
   triangulated points (intersection angle above ``min_init_angle_deg``) wins.
2. **Resection**: the unregistered image observing the most triangulated
   tracks is oriented by PnP-RANSAC on normalised coordinates, refined by
   Levenberg–Marquardt on the inliers.
3. **Triangulation** of the tracks that gained a second registered view, with
   acceptance tests on the intersection angle, depth and reprojection error.
4. **Bundle adjustment** of the whole block whenever it grew by
   ``ba_growth`` (and for the first images), robust (Huber) loss; the focal
   length is refined once three images are registered, the configured
   intrinsics subset in the final adjustment; observations with residuals
   above ``max_reproj_px`` are then rejected and points re-triangulated.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import cv2
import numpy as np

from ..errors import InputError
from ..geometry.camera import Camera, undistort_points
from ..progress import Progress, as_progress, check
from .bundle import BundleConfig, BundleProblem, bundle_adjust
from .triangulation import triangulate_tracks


@dataclass
class IncrementalConfig:
    """Options of :func:`reconstruct` (pixels, degrees)."""

    #: Pairs (most shared tracks first) tried for the initialisation.
    init_candidates: int = 25
    #: Minimal median intersection angle of the initial pair's points.
    min_init_angle_deg: float = 2.0
    #: Minimal number of good points of the initial pair.
    min_init_points: int = 50
    #: RANSAC threshold of the essential matrix.
    ransac_threshold_px: float = 2.0
    #: RANSAC threshold of the resection (PnP).
    pnp_threshold_px: float = 4.0
    #: Fewest 2D-3D inliers to register an image.
    min_pnp_inliers: int = 15
    #: Smallest intersection angle of an accepted point.
    min_tri_angle_deg: float = 1.5
    #: Largest reprojection error of an accepted observation.
    max_reproj_px: float = 4.0
    #: Intrinsics estimated in the final adjustment (subset of f, cx, cy, k1, k2, k3, p1, p2).
    refine_intrinsics: tuple[str, ...] = ("f", "cx", "cy", "k1", "k2", "p1", "p2")
    #: Refine the focal length during the incremental phase (needed when it is only a guess).
    refine_focal_early: bool = True
    #: Global adjustment whenever the number of registered images grew by this factor.
    ba_growth: float = 1.25
    #: Iterations of the intermediate adjustments.
    ba_iterations: int = 15
    #: Iterations of the final adjustment.
    final_ba_iterations: int = 50
    #: Huber scale of the adjustments, pixels.
    loss_scale_px: float = 2.0
    #: Seed of the random sample consensus steps.
    seed: int = 0

    def validate(self) -> None:
        from .bundle.problem import INTRINSIC_NAMES

        bad = [n for n in self.refine_intrinsics if n not in INTRINSIC_NAMES]
        if bad:
            raise InputError(
                f"refine_intrinsics: unknown name(s) {bad}; expected a subset of {INTRINSIC_NAMES}"
            )
        for name in ("ransac_threshold_px", "pnp_threshold_px", "max_reproj_px", "loss_scale_px"):
            if not getattr(self, name) > 0:
                raise InputError(f"{name} must be positive")


@dataclass
class Reconstruction:
    """Result of :func:`reconstruct` (arbitrary similarity frame).

    Attributes
    ----------
    registered : (n_img,) bool
    rotations : (n_img, 3, 3)
        World-to-camera; NaN for unregistered images.
    centers : (n_img, 3)
        NaN for unregistered images.
    intrinsics : (n_cam, 9)
        ``[fx, fy, cx, cy, k1, k2, k3, p1, p2]`` after self-calibration.
    points : (n_tracks, 3)
        One point per track; NaN where the track is not triangulated.
    obs_valid : (n_obs,) bool
        Observations used by the final model (inliers).
    stats : dict
        Initial pair, registration order, adjustments (sigma0, RMS), timings.
    """

    registered: np.ndarray
    rotations: np.ndarray
    centers: np.ndarray
    intrinsics: np.ndarray
    points: np.ndarray
    obs_valid: np.ndarray
    stats: dict = field(default_factory=dict)

    @property
    def point_ok(self) -> np.ndarray:
        return np.all(np.isfinite(self.points), axis=1)


class _State:
    """Arrays of the reconstruction while it grows."""

    def __init__(self, obs_track, obs_image, obs_xy, image_camera, cameras: list[Camera]) -> None:
        self.track = obs_track
        self.image = obs_image
        self.xy = obs_xy
        self.image_camera = image_camera
        self.cameras = cameras
        self.intr = np.array([c.params for c in cameras])
        self.n_img = len(image_camera)
        self.n_tracks = int(obs_track.max()) + 1 if len(obs_track) else 0
        self.R = np.full((self.n_img, 3, 3), np.nan)
        self.C = np.full((self.n_img, 3), np.nan)
        self.reg = np.zeros(self.n_img, dtype=bool)
        self.X = np.full((self.n_tracks, 3), np.nan)
        self.valid = np.ones(len(obs_track), dtype=bool)
        # track -> observations (CSR)
        order = np.argsort(obs_track, kind="stable")
        self.t_order = order
        self.t_offsets = np.searchsorted(obs_track[order], np.arange(self.n_tracks + 1))
        self.focal = self.intr[image_camera, 0]
        self.normalize()

    def normalize(self) -> None:
        self.xn = np.empty_like(self.xy)
        cam_of_obs = self.image_camera[self.image]
        for c, cam in enumerate(self.cameras):
            idx = np.flatnonzero(cam_of_obs == c)
            if len(idx):
                k = Camera.from_params(self.intr[c], cam.width, cam.height, cam.id)
                self.xn[idx] = undistort_points(self.xy[idx], k)
        self.focal = self.intr[self.image_camera, 0]

    def track_obs(self, t: int) -> np.ndarray:
        return self.t_order[self.t_offsets[t] : self.t_offsets[t + 1]]

    @property
    def point_ok(self) -> np.ndarray:
        return np.isfinite(self.X[:, 0])


def _shared_tracks(st: _State, i: int, j: int):
    oi = np.flatnonzero((st.image == i) & st.valid)
    oj = np.flatnonzero((st.image == j) & st.valid)
    _, a, b = np.intersect1d(st.track[oi], st.track[oj], assume_unique=False, return_indices=True)
    return oi[a], oj[b]


def _pair_counts(st: _State):
    from scipy import sparse

    A = sparse.csr_matrix(
        (np.ones(len(st.track), dtype=np.int32), (st.image, st.track)), shape=(st.n_img, st.n_tracks)
    )
    A.data[:] = 1
    S = (A @ A.T).tocoo()
    keep = S.row < S.col
    return S.row[keep], S.col[keep], S.data[keep]


def _triangulate(st: _State, tracks: np.ndarray, cfg: IncrementalConfig) -> int:
    """(Re)triangulate ``tracks`` from their valid observations in registered images."""
    if len(tracks) == 0:
        return 0
    offs = [0]
    obs_list = []
    for t in tracks:
        o = st.track_obs(int(t))
        o = o[st.valid[o] & st.reg[st.image[o]]]
        obs_list.append(o)
        offs.append(offs[-1] + len(o))
    obs = np.concatenate(obs_list) if obs_list else np.zeros(0, np.int64)
    Rs = np.nan_to_num(st.R)
    Cs = np.nan_to_num(st.C)
    res = triangulate_tracks(np.array(offs), st.image[obs], st.xn[obs], Rs, Cs, st.focal)
    good = res.ok & (res.angle >= np.radians(cfg.min_tri_angle_deg)) & (res.max_error <= cfg.max_reproj_px)
    st.X[tracks[good]] = res.xyz[good]
    return int(good.sum())


def _initial_pair(st: _State, cfg: IncrementalConfig, tried: set) -> dict | None:
    ii, jj, cnt = _pair_counts(st)
    order = np.argsort(-cnt)
    best = None
    for k in order[: cfg.init_candidates]:
        i, j = int(ii[k]), int(jj[k])
        if (i, j) in tried or cnt[k] < cfg.min_init_points:
            continue
        oi, oj = _shared_tracks(st, i, j)
        f = 0.5 * (st.focal[i] + st.focal[j])
        cv2.setRNGSeed(cfg.seed)
        E, mask = cv2.findEssentialMat(
            st.xn[oi],
            st.xn[oj],
            np.eye(3),
            method=cv2.USAC_MAGSAC,
            prob=0.9999,
            threshold=cfg.ransac_threshold_px / f,
        )
        if E is None or E.shape != (3, 3):
            continue
        n_in, R, t, mask = cv2.recoverPose(E, st.xn[oi], st.xn[oj], np.eye(3), mask=mask)
        inl = mask.ravel() > 0
        if n_in < cfg.min_init_points:
            continue
        Rs = np.stack([np.eye(3), R])
        Cs = np.stack([np.zeros(3), (-R.T @ t).ravel()])
        n = int(inl.sum())
        res = triangulate_tracks(
            np.arange(0, 2 * n + 1, 2),
            np.tile([0, 1], n),
            np.column_stack([st.xn[oi[inl]], st.xn[oj[inl]]]).reshape(-1, 2),
            Rs,
            Cs,
            np.array([f, f]),
        )
        good = (
            res.ok & (res.angle >= np.radians(cfg.min_tri_angle_deg)) & (res.max_error <= cfg.max_reproj_px)
        )
        med_angle = float(np.degrees(np.median(res.angle[good]))) if good.any() else 0.0
        score = int(good.sum()) * min(med_angle, 3 * cfg.min_init_angle_deg)
        cand = dict(
            pair=(i, j),
            R=R,
            C=Cs[1],
            inliers=n,
            points=int(good.sum()),
            median_angle_deg=med_angle,
            score=score,
            shared=int(cnt[k]),
        )
        if best is None or cand["score"] > best["score"]:
            best = cand
    return best


def _bundle(st: _State, cfg: IncrementalConfig, refine, iterations: int, progress=None):
    imgs = np.flatnonzero(st.reg)
    img_map = -np.ones(st.n_img, dtype=np.int64)
    img_map[imgs] = np.arange(len(imgs))
    pts = np.flatnonzero(st.point_ok)
    pt_map = -np.ones(st.n_tracks, dtype=np.int64)
    pt_map[pts] = np.arange(len(pts))
    use = st.valid & st.reg[st.image] & st.point_ok[st.track]
    obs = np.flatnonzero(use)
    # refine only cameras that registered images use (others have no observations)
    used = np.unique(st.image_camera[imgs])
    refine = {int(c): tuple(refine) for c in used} if refine else ()
    pb = BundleProblem(
        intrinsics=st.intr,
        image_camera=st.image_camera[imgs],
        rotations=st.R[imgs],
        centers=st.C[imgs],
        points=st.X[pts],
        obs_image=img_map[st.image[obs]],
        obs_point=pt_map[st.track[obs]],
        obs_xy=st.xy[obs],
        refine_intrinsics=refine,
    )
    conf = BundleConfig(
        max_iterations=iterations, loss="huber", loss_scale=cfg.loss_scale_px, compute_covariance=False
    )
    res = bundle_adjust(pb, conf, progress)
    st.R[imgs] = res.rotations
    st.C[imgs] = res.centers
    st.X[pts] = res.points
    if refine:
        st.intr = res.intrinsics.copy()
        st.normalize()
    # reject observations with large residuals; drop points left with < 2 observations
    err = np.linalg.norm(res.residuals, axis=1)
    bad = ~(err <= cfg.max_reproj_px)
    st.valid[obs[bad]] = False
    cnt = np.bincount(st.track[st.valid & st.reg[st.image]], minlength=st.n_tracks)
    st.X[cnt < 2] = np.nan
    return res, int(bad.sum())


def _resect(st: _State, i: int, cfg: IncrementalConfig):
    o = np.flatnonzero((st.image == i) & st.valid)
    o = o[st.point_ok[st.track[o]]]
    if len(o) < cfg.min_pnp_inliers:
        return None, len(o)
    obj = st.X[st.track[o]]
    img = st.xn[o]
    f = st.focal[i]
    cv2.setRNGSeed(cfg.seed)
    ok, rvec, tvec, inl = cv2.solvePnPRansac(
        obj,
        img,
        np.eye(3),
        np.zeros(4),
        iterationsCount=2000,
        reprojectionError=cfg.pnp_threshold_px / f,
        confidence=0.9999,
        flags=cv2.SOLVEPNP_EPNP,
    )
    if not ok or inl is None or len(inl) < cfg.min_pnp_inliers:
        return None, 0 if inl is None else len(inl)
    inl = inl.ravel()
    rvec, tvec = cv2.solvePnPRefineLM(obj[inl], img[inl], np.eye(3), np.zeros(4), rvec, tvec)
    R, _ = cv2.Rodrigues(rvec)
    C = (-R.T @ tvec).ravel()
    # mark outlier observations of this image
    outl = np.ones(len(o), dtype=bool)
    outl[inl] = False
    st.valid[o[outl]] = False
    return (R, C), len(inl)


def reconstruct(
    obs_track,
    obs_image,
    obs_xy,
    image_camera,
    cameras: list[Camera],
    config: IncrementalConfig | None = None,
    progress: Progress | None = None,
) -> Reconstruction:
    """Incremental reconstruction of a block from feature tracks.

    Parameters
    ----------
    obs_track, obs_image : (M,) int
        Track and image of every observation (at most one per track and image).
    obs_xy : (M, 2) float64
        Pixel coordinates (our convention).
    image_camera : (n_img,) int
        Camera index of every image.
    cameras : list of Camera
        Approximate interior orientations (priors; refined by self-calibration).
    """
    cfg = config or IncrementalConfig()
    cfg.validate()
    prog = as_progress(progress)
    t0 = time.perf_counter()
    obs_track = np.asarray(obs_track, dtype=np.int64).reshape(-1)
    obs_image = np.asarray(obs_image, dtype=np.int64).reshape(-1)
    obs_xy = np.asarray(obs_xy, dtype=np.float64).reshape(-1, 2)
    image_camera = np.asarray(image_camera, dtype=np.int64).reshape(-1)
    if not (len(obs_track) == len(obs_image) == len(obs_xy)):
        raise InputError("reconstruct: observation arrays differ in length")
    n_img = len(image_camera)
    if n_img < 2:
        raise InputError(f"reconstruct: at least two images are needed, got {n_img}")
    if len(obs_image) and (obs_image.min() < 0 or obs_image.max() >= n_img):
        raise InputError("reconstruct: an observation refers to an image index out of range")
    if len(image_camera) and (image_camera.min() < 0 or image_camera.max() >= len(cameras)):
        raise InputError("reconstruct: image_camera refers to a missing camera")
    if len(obs_track) == 0 or not np.all(np.isfinite(obs_xy)):
        raise InputError("reconstruct: no (finite) observations: the images share no tie points")

    st = _State(obs_track, obs_image, obs_xy, image_camera, cameras)
    stats: dict = {"registration": [], "adjustments": [], "failed_resections": {}}
    tried: set = set()
    init = _initial_pair(st, cfg, tried)
    if init is None:
        return _result(st, {**stats, "failure": "no image pair with enough well-conditioned matches"}, t0)
    i, j = init["pair"]
    st.R[i], st.C[i] = np.eye(3), np.zeros(3)
    st.R[j], st.C[j] = init["R"], init["C"]
    st.reg[[i, j]] = True
    stats["initial_pair"] = {k: v for k, v in init.items() if k not in ("R", "C")}
    _triangulate(st, np.unique(st.track[(st.image == i) | (st.image == j)]), cfg)
    res, _ = _bundle(st, cfg, (), cfg.ba_iterations)
    stats["registration"] += [
        {"image": i, "inliers": init["inliers"]},
        {"image": j, "inliers": init["inliers"]},
    ]
    last_ba = 2
    failures: dict[int, int] = {}
    while True:
        check(prog)
        prog.update(st.reg.sum() / n_img, f"registered {int(st.reg.sum())} of {n_img} images")
        cand = np.flatnonzero(~st.reg)
        if len(cand) == 0:
            break
        tri_obs = st.valid & st.point_ok[st.track]
        counts = np.bincount(st.image[tri_obs], minlength=n_img)[cand]
        order = cand[np.argsort(-counts)]
        registered_one = False
        for k in order[:5]:
            if failures.get(int(k), 0) >= 3 or counts[np.searchsorted(cand, k)] < cfg.min_pnp_inliers:
                continue
            pose, n_in = _resect(st, int(k), cfg)
            if pose is None:
                failures[int(k)] = failures.get(int(k), 0) + 1
                continue
            st.R[k], st.C[k] = pose
            st.reg[k] = True
            stats["registration"].append({"image": int(k), "inliers": int(n_in)})
            registered_one = True
            new_tracks = np.unique(st.track[(st.image == k) & st.valid])
            _triangulate(st, new_tracks[~st.point_ok[new_tracks]], cfg)
            break
        if not registered_one:
            break
        n_reg = int(st.reg.sum())
        if n_reg <= 6 or n_reg >= last_ba * cfg.ba_growth:
            refine = (
                ("f",) if (cfg.refine_focal_early and "f" in cfg.refine_intrinsics and n_reg >= 3) else ()
            )
            res, n_bad = _bundle(st, cfg, refine, cfg.ba_iterations)
            stats["adjustments"].append({"images": n_reg, "rms_px": res.rms, "rejected": n_bad})
            last_ba = n_reg
            # retriangulate tracks that lost or never had a point
            _triangulate(st, np.flatnonzero(~st.point_ok), cfg)
    stats["failed_resections"] = {int(k): v for k, v in failures.items()}
    # final: self-calibration, two rounds with rejection in between
    for _ in range(2):
        check(prog)
        res, n_bad = _bundle(st, cfg, cfg.refine_intrinsics, cfg.final_ba_iterations)
        _triangulate(st, np.flatnonzero(~st.point_ok), cfg)
        stats["adjustments"].append(
            {"images": int(st.reg.sum()), "rms_px": res.rms, "rejected": n_bad, "final": True}
        )
    res, _ = _bundle(st, cfg, cfg.refine_intrinsics, cfg.final_ba_iterations)
    stats["final_bundle"] = {
        "sigma0": res.sigma0,
        "rms_px": res.rms,
        "iterations": res.n_iterations,
        "converged": res.converged,
        "reason": res.reason,
    }
    prog.update(1.0, f"registered {int(st.reg.sum())} of {n_img} images")
    return _result(st, stats, t0)


def _result(st: _State, stats: dict, t0: float) -> Reconstruction:
    stats["seconds"] = time.perf_counter() - t0
    stats["registered"] = int(st.reg.sum())
    stats["points"] = int(st.point_ok.sum())
    valid = st.valid & st.reg[st.image] & st.point_ok[st.track]
    return Reconstruction(st.reg.copy(), st.R.copy(), st.C.copy(), st.intr.copy(), st.X.copy(), valid, stats)
