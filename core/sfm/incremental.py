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
5. **Guided registration** (:mod:`.guided`, when the features are given):
   when no image can be resected any more, an unregistered image with a
   verified two-view link to a registered partner gets its rotation and
   baseline direction from the relative orientation to that partner and its
   baseline length from guided matches of block points along their epipolar
   segments, accepted only when significant (a-contrario test) and
   confirmed by a local adjustment (only the new image free: reprojection
   error of the guided matches, number of points, intersection angle). The
   matches become observations of their tracks.
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
from .guided import GuidedConfig, relative_pose, search_scale
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
    #: Datum of the adjustments (the frame is arbitrary here): "none" leaves the 7 similarity
    #: parameters to the damping (a free network); "auto" holds the first image and one centre
    #: coordinate. On copr's last adjustment (41 images, self-calibration) "none" converged in 43
    #: iterations where "auto" still crept down after 150: holding one image puts the whole block
    #: on a lever arm around it, which the linearisation follows only in small steps.
    gauge: str = "none"
    #: Iterations of the intermediate adjustments.
    ba_iterations: int = 15
    #: Iterations of the final adjustment.
    final_ba_iterations: int = 50
    #: Huber scale of the adjustments, pixels.
    loss_scale_px: float = 2.0
    #: Seed of the random sample consensus steps.
    seed: int = 0
    #: Guided registration of weakly connected images (needs the features, see :func:`reconstruct`).
    guided: GuidedConfig = field(default_factory=GuidedConfig)

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
        if self.gauge not in ("auto", "none"):
            raise InputError(f"gauge must be 'auto' or 'none', got {self.gauge!r}")
        self.guided.validate()


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
        Observations used by the final model (inliers), over ``obs_*``.
    stats : dict
        Initial pair, registration order, adjustments (sigma0, RMS), guided
        registrations, timings.
    obs_track, obs_image, obs_feature : (n_obs,) int64; obs_xy : (n_obs, 2) float64
        The observations of the model: the input ones (same order, first)
        followed by those added by guided matching (``obs_feature`` -1 where
        the input gave none).
    """

    registered: np.ndarray
    rotations: np.ndarray
    centers: np.ndarray
    intrinsics: np.ndarray
    points: np.ndarray
    obs_valid: np.ndarray
    stats: dict = field(default_factory=dict)
    obs_track: np.ndarray | None = None
    obs_image: np.ndarray | None = None
    obs_xy: np.ndarray | None = None
    obs_feature: np.ndarray | None = None

    @property
    def point_ok(self) -> np.ndarray:
        return np.all(np.isfinite(self.points), axis=1)


class _State:
    """Arrays of the reconstruction while it grows."""

    def __init__(
        self, obs_track, obs_image, obs_xy, image_camera, cameras: list[Camera], obs_feature=None
    ) -> None:
        self.track = obs_track
        self.image = obs_image
        self.xy = obs_xy
        self.feature = (
            np.full(len(obs_track), -1, np.int64)
            if obs_feature is None
            else np.asarray(obs_feature, np.int64)
        )
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
        self.xn: np.ndarray = np.empty_like(self.xy)
        self._index_tracks()
        self.focal = self.intr[image_camera, 0]
        self.normalize()

    def _index_tracks(self) -> None:
        # track -> observations (CSR)
        order = np.argsort(self.track, kind="stable")
        self.t_order = order
        self.t_offsets = np.searchsorted(self.track[order], np.arange(self.n_tracks + 1))

    def add_observations(self, track, image, xy, feature) -> None:
        """Append (valid) observations of existing tracks."""
        n0 = len(self.track)
        self.track = np.concatenate([self.track, np.asarray(track, np.int64)])
        self.image = np.concatenate([self.image, np.asarray(image, np.int64)])
        self.xy = np.vstack([self.xy, np.asarray(xy, np.float64).reshape(-1, 2)])
        self.feature = np.concatenate([self.feature, np.asarray(feature, np.int64)])
        self.valid = np.concatenate([self.valid, np.ones(len(self.track) - n0, bool)])
        xn_new = np.empty((len(self.track) - n0, 2))
        cam_of_obs = self.image_camera[self.image[n0:]]
        for c, cam in enumerate(self.cameras):
            idx = np.flatnonzero(cam_of_obs == c)
            if len(idx):
                k = Camera.from_params(self.intr[c], cam.width, cam.height, cam.id)
                xn_new[idx] = undistort_points(self.xy[n0:][idx], k)
        self.xn = np.vstack([self.xn, xn_new])
        self._index_tracks()

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
        max_iterations=iterations,
        loss="huber",
        loss_scale=cfg.loss_scale_px,
        compute_covariance=False,
        gauge=cfg.gauge,
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


def _valid_pair_counts(st: _State):
    """Shared valid observations per image pair: dense (n_img, n_img) int array."""
    from scipy import sparse

    v = np.flatnonzero(st.valid)
    A = sparse.csr_matrix(
        (np.ones(len(v), dtype=np.int32), (st.image[v], st.track[v])), shape=(st.n_img, st.n_tracks)
    )
    return np.asarray((A @ A.T).todense())


def _point_descriptors(st: _State, features, tracks: np.ndarray, exclude_image: int):
    """CSR descriptors of the valid observations (in registered images other than ``exclude_image``)."""
    parts_off = [0]
    imgs = []
    feats = []
    for t in tracks:
        o = st.track_obs(int(t))
        o = o[st.valid[o] & st.reg[st.image[o]] & (st.image[o] != exclude_image) & (st.feature[o] >= 0)]
        imgs.append(st.image[o])
        feats.append(st.feature[o])
        parts_off.append(parts_off[-1] + len(o))
    img = np.concatenate(imgs) if imgs else np.zeros(0, np.int64)
    fe = np.concatenate(feats) if feats else np.zeros(0, np.int64)
    dim = features[0].descriptor_rows(np.zeros(0, np.int64)).shape[-1] if len(features) else 128
    desc = np.zeros((len(img), dim), np.float32)
    for i in np.unique(img):
        sel = img == i
        desc[sel] = features[int(i)].descriptor_rows(fe[sel])
    return np.array(parts_off, dtype=np.int64), desc


def _guided_pairs(st: _State, cfg: IncrementalConfig, attempts: dict):
    """(image, partner) pairs worth a guided attempt, best linked first, and the pair counts."""
    g = cfg.guided
    n_reg = int(st.reg.sum())
    unreg = np.flatnonzero(~st.reg)
    reg = np.flatnonzero(st.reg)
    if len(unreg) == 0 or len(reg) < 2:
        return [], None
    S = _valid_pair_counts(st)
    links = S[np.ix_(unreg, reg)]
    out = []
    for a in np.argsort(-links.max(axis=1), kind="stable"):
        k = int(unreg[a])
        for p in reg[np.argsort(-links[a], kind="stable")][: g.max_partners]:
            p = int(p)
            last = attempts.get((k, p))
            # a failed pair is tried again once the block has grown by 10 % (at least one image)
            if S[k, p] >= g.min_partner_tracks and (last is None or n_reg >= max(last + 1, 1.1 * last)):
                out.append((k, p))
    return out, S


def _guided_register(st: _State, cfg: IncrementalConfig, features, pairs, S, attempts: dict, log: list):
    """Register one unregistered image by relative orientation + guided scale (module docstring, step 5).

    Returns the registered image index, or None. Every attempt (also a failed one) is appended to
    ``log``.
    """
    n_reg = int(st.reg.sum())
    for k, p in pairs:
        attempts[(k, p)] = n_reg
        entry = _guided_attempt(st, cfg, features, k, p, S)
        log.append(entry)
        if entry["registered"]:
            return k
    return None


def _guided_attempt(st: _State, cfg: IncrementalConfig, features, k: int, p: int, S) -> dict:
    g = cfg.guided
    entry: dict = {"image": k, "partner": p, "registered": False}
    ok_k, ok_p = _shared_tracks(st, k, p)
    f = float(0.5 * (st.focal[k] + st.focal[p]))
    R, t, inl, angle = relative_pose(st.xn[ok_k], st.xn[ok_p], f, cfg.ransac_threshold_px, cfg.seed)
    entry.update(shared=len(ok_k), relative_inliers=int(inl.sum()), median_angle_deg=angle)
    if R is None or inl.sum() < g.min_partner_tracks:
        entry["reason"] = "relative orientation to the partner failed"
        return entry
    if not angle >= cfg.min_tri_angle_deg:
        entry["reason"] = f"baseline to the partner too short (median angle {angle:.2f} deg)"
        return entry
    Rp, Cp = st.R[p], st.C[p]
    Rk = R.T @ Rp
    b = Rp.T @ t
    T = Rk @ b
    # search range of the baseline length: the pair's points (at s = 1) lie at depths seen from p
    n = int(inl.sum())
    pair = triangulate_tracks(
        np.arange(0, 2 * n + 1, 2),
        np.tile([0, 1], n),
        np.column_stack([st.xn[ok_k[inl]], st.xn[ok_p[inl]]]).reshape(-1, 2),
        np.stack([Rk, Rp]),
        np.stack([Cp + b, Cp]),
        np.array([f, f]),
    )
    depth_pair = ((pair.xyz[pair.ok] - Cp) @ Rp.T)[:, 2]
    obs_p = np.flatnonzero((st.image == p) & st.valid)
    obs_p = obs_p[st.point_ok[st.track[obs_p]]]
    depth_p = ((st.X[st.track[obs_p]] - Cp) @ Rp.T)[:, 2]
    depth_pair, depth_p = depth_pair[depth_pair > 0], depth_p[depth_p > 0]
    if len(depth_pair) < 5 or len(depth_p) < 5:
        entry["reason"] = "too few points to bound the baseline length"
        return entry
    d0 = float(np.median(depth_pair))
    s_lo = float(np.percentile(depth_p, 5)) / d0 / g.scale_range_factor
    s_hi = float(np.percentile(depth_p, 95)) / d0 * g.scale_range_factor
    # block points that can be in view: those of the partner and of its registered neighbours
    near = np.flatnonzero(st.reg & (S[p] >= g.min_partner_tracks))
    near = np.union1d(near, [p])
    o_near = np.flatnonzero(np.isin(st.image, near) & st.valid)
    pts = np.unique(st.track[o_near])
    pts = pts[st.point_ok[pts]]
    A = (st.X[pts] - Cp) @ Rk.T
    poff, pdesc = _point_descriptors(st, features, pts, k)
    cam = Camera.from_params(
        st.intr[st.image_camera[k]],
        st.cameras[st.image_camera[k]].width,
        st.cameras[st.image_camera[k]].height,
    )
    fk = features[k]
    u = undistort_points(np.asarray(fk.xy, np.float64), cam)
    res = search_scale(A, T, u, float(cam.fx), fk.xy, fk.descriptors, poff, pdesc, (s_lo, s_hi), g, cfg.seed)
    entry["scale_search"] = res.summary()
    entry["scale_range"] = [s_lo, s_hi]
    if not res.ok:
        entry["reason"] = res.reason
        return entry
    Ck = Cp + res.scale * b
    ver = _verify_guided(st, cfg, k, p, Rk, Ck, pts[res.points], res.features, ok_k[inl], ok_p[inl], features)
    entry.update({key: v for key, v in ver.items() if key not in ("R", "C", "add_track", "add_feature")})
    if not ver["ok"]:
        entry["reason"] = ver["reason"]
        return entry
    # commit: the pose, the verified guided matches as observations of their tracks
    xy_new = np.asarray(fk.xy, np.float64)[ver["add_feature"]]
    st.add_observations(ver["add_track"], np.full(len(ver["add_track"]), k), xy_new, ver["add_feature"])
    st.R[k], st.C[k] = ver["R"], ver["C"]
    st.reg[k] = True
    entry["registered"] = True
    entry["points"] = int(ver["guided_inliers"])
    return entry


def _verify_guided(st, cfg, k, p, Rk, Ck, match_tracks, match_feat, pair_k, pair_p, features) -> dict:
    """Local adjustment of image k alone (the block fixed) on its guided and two-view observations.

    Returns ``ok``, ``reason``, the adjusted pose ``R, C``, the guided matches kept
    (``add_track``, ``add_feature``), ``guided_inliers``, ``rms_px`` (image k),
    ``pair_points`` and their ``pair_median_angle_deg``, ``scale_change``.
    """
    g = cfg.guided
    xy_k = np.asarray(features[k].xy, np.float64)
    # a match is new (track not yet seen in k, feature free), confirms an existing observation of
    # the track in k (same feature), or conflicts with one (dropped)
    used = set(st.feature[(st.image == k) & st.valid].tolist())
    status = np.zeros(len(match_tracks), np.int64)  # 0 drop, 1 new, 2 existing
    for i, (t, fe) in enumerate(zip(match_tracks, match_feat, strict=True)):
        o = st.track_obs(int(t))
        o = o[st.image[o] == k]
        if len(o) == 0:
            status[i] = 0 if int(fe) in used else 1
        elif st.valid[o[0]] and st.feature[o[0]] == fe:
            status[i] = 2
    keep = status > 0
    m_tr, m_fe, m_new = np.asarray(match_tracks)[keep], np.asarray(match_feat)[keep], status[keep] == 1
    out: dict = {"ok": False, "reason": "", "guided_matches": int(len(m_tr))}
    if len(m_tr) < g.min_points:
        out["reason"] = f"{len(m_tr)} guided matches left after removing conflicts with existing observations"
        return out
    # points: guided block points (with their registered observations), two-view points of the pair
    f = float(st.focal[k])
    n2 = len(pair_k)
    tri = triangulate_tracks(
        np.arange(0, 2 * n2 + 1, 2),
        np.tile([0, 1], n2),
        np.column_stack([st.xn[pair_k], st.xn[pair_p]]).reshape(-1, 2),
        np.stack([Rk, st.R[p]]),
        np.stack([Ck, st.C[p]]),
        np.array([f, f]),
    )
    good2 = tri.ok & (tri.max_error <= cfg.max_reproj_px)
    obs_img, obs_pt, obs_xy, pts = [], [], [], []
    for i, t in enumerate(m_tr):
        o = st.track_obs(int(t))
        o = o[st.valid[o] & st.reg[st.image[o]] & (st.image[o] != k)]
        obs_img += [st.image[o], [k]]
        obs_pt += [np.full(len(o) + 1, i)]
        obs_xy += [st.xy[o], xy_k[m_fe[i] : m_fe[i] + 1]]
        pts.append(st.X[t])
    n_g = len(m_tr)
    sel2 = np.flatnonzero(good2)
    for q, j in enumerate(sel2):
        obs_img += [[k], [p]]
        obs_pt += [np.full(2, n_g + q)]
        obs_xy += [st.xy[pair_k[j] : pair_k[j] + 1], st.xy[pair_p[j] : pair_p[j] + 1]]
        pts.append(tri.xyz[j])
    img_all = np.concatenate([np.asarray(a, np.int64) for a in obs_img])
    images = np.unique(img_all)
    imap = -np.ones(st.n_img, np.int64)
    imap[images] = np.arange(len(images))
    R0 = st.R[images].copy()
    C0 = st.C[images].copy()
    R0[imap[k]], C0[imap[k]] = Rk, Ck
    pb = BundleProblem(
        intrinsics=st.intr,
        image_camera=st.image_camera[images],
        rotations=R0,
        centers=C0,
        points=np.array(pts).reshape(-1, 3),
        obs_image=imap[img_all],
        obs_point=np.concatenate(obs_pt),
        obs_xy=np.vstack(obs_xy),
        fixed_images=[int(imap[i]) for i in images if i != k],
    )
    res = bundle_adjust(
        pb,
        BundleConfig(
            max_iterations=cfg.ba_iterations,
            loss="huber",
            loss_scale=cfg.loss_scale_px,
            compute_covariance=False,
        ),
    )
    err = np.linalg.norm(res.residuals, axis=1)
    on_k = pb.obs_image == imap[k]
    guided_obs = on_k & (pb.obs_point < n_g)
    e_g = err[guided_obs]
    inl = e_g <= cfg.max_reproj_px
    R1, C1 = res.rotations[imap[k]], res.centers[imap[k]]
    e_k = err[on_k]
    e_k = e_k[np.isfinite(e_k) & (e_k <= cfg.max_reproj_px)]
    # intersection angles of the pair's points after the adjustment
    P2 = res.points[n_g:]
    r1 = P2 - C1
    r2 = P2 - st.C[p]
    cosang = np.sum(r1 * r2, axis=1) / np.maximum(
        np.linalg.norm(r1, axis=1) * np.linalg.norm(r2, axis=1), 1e-300
    )
    ang = np.degrees(np.arccos(np.clip(cosang, -1, 1)))
    base0 = float(np.linalg.norm(Ck - st.C[p]))
    out.update(
        R=R1,
        C=C1,
        add_track=m_tr[inl & m_new],
        add_feature=m_fe[inl & m_new],
        guided_inliers=int(inl.sum()),
        rms_px=float(np.sqrt(np.mean(e_k**2))) if len(e_k) else float("nan"),
        guided_rms_px=float(np.sqrt(np.mean(e_g[inl] ** 2))) if inl.any() else float("nan"),
        pair_points=int(len(sel2)),
        pair_median_angle_deg=float(np.median(ang)) if len(ang) else float("nan"),
        scale_change=float(np.linalg.norm(C1 - st.C[p]) / base0 - 1.0) if base0 > 0 else float("nan"),
    )
    if inl.sum() < g.min_points:
        out["reason"] = (
            f"{int(inl.sum())} guided matches within {cfg.max_reproj_px} px after the local adjustment"
        )
    elif len(sel2) < g.min_partner_tracks:
        out["reason"] = f"{len(sel2)} two-view points with the partner after triangulation"
    elif not out["pair_median_angle_deg"] >= cfg.min_tri_angle_deg:
        out["reason"] = "intersection angle with the partner too small"
    elif abs(out["scale_change"]) > 0.05:
        out["reason"] = f"the local adjustment moved the baseline length by {100 * out['scale_change']:.1f} %"
    else:
        out["ok"] = True
    return out


def reconstruct(
    obs_track,
    obs_image,
    obs_xy,
    image_camera,
    cameras: list[Camera],
    config: IncrementalConfig | None = None,
    progress: Progress | None = None,
    features=None,
    obs_feature=None,
    start: Reconstruction | None = None,
    finalize: bool = True,
    register: bool = True,
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
    features : list of Features, optional
        Features of every image (full-resolution ``xy``, ``descriptors``); with
        ``obs_feature`` they enable the guided registration of weakly
        connected images (``config.guided``).
    obs_feature : (M,) int, optional
        Feature index of every observation in its image's ``features``.
    start : Reconstruction, optional
        Continue this reconstruction (made with ``finalize=False``) instead of starting from an
        initial pair: its registered images keep their poses and the block its intrinsics. When
        the observations are the ones ``start`` was made from, its points and inlier flags are
        kept too; otherwise (more tracks, e.g. after a second matching pass) every track is
        triangulated from those poses and the block is adjusted before registration goes on.
    finalize : bool
        Run the final self-calibrating adjustments (False leaves them to a later call with
        ``start``: a second matching pass then does not pay for them twice).
    register : bool
        Register further images (False: only finalize ``start``).
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
    guide = features is not None and obs_feature is not None and cfg.guided.enabled
    if features is not None and len(features) != n_img:
        raise InputError(f"reconstruct: {len(features)} feature sets for {n_img} images")
    if obs_feature is not None:
        obs_feature = np.asarray(obs_feature, dtype=np.int64).reshape(-1)
        if len(obs_feature) != len(obs_track):
            raise InputError("reconstruct: obs_feature differs in length from the observations")

    st = _State(obs_track, obs_image, obs_xy, image_camera, cameras, obs_feature)
    if start is not None:
        stats, last_ba = _resume(st, start, cfg)
    else:
        stats = {"registration": [], "adjustments": [], "failed_resections": {}, "guided": []}
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
        _bundle(st, cfg, (), cfg.ba_iterations)
        stats["registration"] += [
            {"image": i, "inliers": init["inliers"]},
            {"image": j, "inliers": init["inliers"]},
        ]
        last_ba = 2
    failures: dict[int, int] = {}
    guided_attempts: dict[tuple[int, int], int] = {}
    calibrated_at = -1
    while register:
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
        guided_now = False
        if not registered_one and guide and (~st.reg).any():
            pairs, S = _guided_pairs(st, cfg, guided_attempts)
            if pairs and calibrated_at != int(st.reg.sum()) and cfg.refine_intrinsics:
                # guided matching predicts positions: it needs the interior orientation of the block
                # (distortion included), not only the focal length of the incremental phase
                res, n_bad = _bundle(st, cfg, cfg.refine_intrinsics, cfg.ba_iterations)
                _triangulate(st, np.flatnonzero(~st.point_ok), cfg)
                stats["adjustments"].append(
                    {
                        "images": int(st.reg.sum()),
                        "rms_px": res.rms,
                        "rejected": n_bad,
                        "self_calibration": True,
                    }
                )
                calibrated_at = int(st.reg.sum())
                pairs, S = _guided_pairs(st, cfg, guided_attempts)
            k_g = _guided_register(st, cfg, features, pairs, S, guided_attempts, stats["guided"])
            if k_g is not None:
                registered_one = guided_now = True
                stats["registration"].append({"image": int(k_g), "inliers": stats["guided"][-1]["points"]})
                new_tracks = np.unique(st.track[(st.image == k_g) & st.valid])
                _triangulate(st, new_tracks[~st.point_ok[new_tracks]], cfg)
        if not registered_one:
            break
        n_reg = int(st.reg.sum())
        if guided_now or n_reg <= 6 or n_reg >= last_ba * cfg.ba_growth:
            refine = (
                ("f",) if (cfg.refine_focal_early and "f" in cfg.refine_intrinsics and n_reg >= 3) else ()
            )
            res, n_bad = _bundle(st, cfg, refine, cfg.ba_iterations)
            stats["adjustments"].append({"images": n_reg, "rms_px": res.rms, "rejected": n_bad})
            last_ba = n_reg
            # retriangulate tracks that lost or never had a point
            _triangulate(st, np.flatnonzero(~st.point_ok), cfg)
    failed = {int(k): v for k, v in failures.items()}
    stats["failed_resections"] = {**stats.get("failed_resections", {}), **failed}
    if not finalize:
        stats["finalized"] = False
        prog.update(1.0, f"registered {int(st.reg.sum())} of {n_img} images")
        return _result(st, stats, t0)
    stats["finalized"] = True
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


def _resume(st: _State, start: Reconstruction, cfg: IncrementalConfig) -> tuple[dict, int]:
    """Set ``st`` (fresh, from the observations) to the state of ``start``; returns its stats and
    the image count of its last adjustment (see :func:`reconstruct`, ``start``)."""
    if start.registered.shape != st.reg.shape or start.intrinsics.shape != st.intr.shape:
        raise InputError("reconstruct: start is a reconstruction of another block")
    st.intr = start.intrinsics.copy()
    st.normalize()
    st.reg = start.registered.copy()
    st.R[st.reg] = start.rotations[st.reg]
    st.C[st.reg] = start.centers[st.reg]
    stats = {k: (list(v) if isinstance(v, list) else v) for k, v in start.stats.items()}
    stats.pop("finalized", None)
    same = (
        start.obs_track is not None
        and len(start.obs_track) == len(st.track)
        and np.array_equal(start.obs_track, st.track)
        and start.obs_image is not None
        and np.array_equal(start.obs_image, st.image)
    )
    n_reg = int(st.reg.sum())
    if same:
        st.X = start.points.copy()
        # observations start rejected stay out; those of its unregistered images and untriangulated
        # tracks stay in
        st.valid = start.obs_valid | ~st.reg[st.image] | ~start.point_ok[st.track]
        return stats, n_reg
    _triangulate(st, np.arange(st.n_tracks), cfg)
    res, n_bad = _bundle(st, cfg, (), cfg.ba_iterations)
    _triangulate(st, np.flatnonzero(~st.point_ok), cfg)
    stats["adjustments"].append({"images": n_reg, "rms_px": res.rms, "rejected": n_bad, "resumed": True})
    return stats, n_reg


def _result(st: _State, stats: dict, t0: float) -> Reconstruction:
    stats["seconds"] = time.perf_counter() - t0
    stats["registered"] = int(st.reg.sum())
    stats["points"] = int(st.point_ok.sum())
    valid = st.valid & st.reg[st.image] & st.point_ok[st.track]
    return Reconstruction(
        st.reg.copy(),
        st.R.copy(),
        st.C.copy(),
        st.intr.copy(),
        st.X.copy(),
        valid,
        stats,
        st.track.copy(),
        st.image.copy(),
        st.xy.copy(),
        st.feature.copy(),
    )
