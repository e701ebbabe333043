"""Bundle adjustment of an :class:`~truortho.core.orientation.Orientation`."""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError
from ...geometry.camera import Camera
from ...orientation import Image, Orientation, SparsePoints
from ...progress import Progress
from .options import BundleConfig, BundleResult
from .outliers import adjust_with_outlier_rejection
from .problem import BundleProblem
from .solver import bundle_adjust


@dataclass
class OrientationBundleConfig:
    """Options of :func:`adjust_orientation`.

    Parameters
    ----------
    bundle : BundleConfig
        Solver options.
    refine_intrinsics : collection of str or mapping camera id -> collection
        Names from :data:`~.problem.INTRINSIC_NAMES`; one collection applies to
        all cameras.
    fixed_images : collection of str
        Names of images whose pose is held.
    obs_sigma : float
        Standard deviation of tie-point and GCP image measurements, pixels (a GCP measurement
        with its own sigma in ``GCP.obs_sigma`` uses that).
    use_gcps : bool
        GCPs with role "gcp" and image measurements become control points
        (prior = their coordinates, sigma = their ``sigma`` or
        ``gcp_sigma``); "check" GCPs are adjusted as free points.
    gcp_sigma : (3,) float
        Default GCP standard deviations, metres.
    center_priors : mapping image name -> (xyz world (3,), sigma (3,))
        Camera-centre priors (e.g. GNSS), world frame, metres.
    outlier_k : float or None
        When set, run :func:`~.outliers.adjust_with_outlier_rejection` with
        this ``k_sigma``.
    """

    bundle: BundleConfig = field(default_factory=BundleConfig)
    refine_intrinsics: Collection[str] | Mapping[str, Collection[str]] = ()
    fixed_images: Collection[str] = ()
    obs_sigma: float = 1.0
    use_gcps: bool = True
    gcp_sigma: tuple[float, float, float] = (0.02, 0.02, 0.02)
    center_priors: Mapping[str, tuple] = field(default_factory=dict)
    outlier_k: float | None = None


def adjust_orientation(
    orientation: Orientation, config: OrientationBundleConfig | None = None, progress: Progress | None = None
) -> tuple[Orientation, BundleResult]:
    """Adjust the images, cameras and sparse points of an orientation.

    Tie points come from ``orientation.points`` (``obs_point``, ``obs_image``,
    ``obs_xy``); GCP measurements are appended as extra points (results for
    them are not written into the sparse points). Returns a new orientation
    (same frame, CRS, GCPs and metadata) and the :class:`BundleResult`, whose
    point-related arrays cover tie points first, then GCPs in order.
    """
    cfg = config or OrientationBundleConfig()
    orientation.validate()
    if not orientation.images:
        raise InputError("adjust_orientation: the orientation has no images")
    names = orientation.image_index()
    cam_ids = list(orientation.cameras)
    cam_index = {c: i for i, c in enumerate(cam_ids)}
    pts = orientation.points or SparsePoints(np.zeros((0, 3)))
    xyz = [pts.xyz]
    o_img, o_pt, o_xy = [pts.obs_image], [pts.obs_point], [pts.obs_xy]
    o_sig = [np.full(len(pts.obs_image), float(cfg.obs_sigma))]
    pri_idx, pri_xyz, pri_sig = [], [], []
    n = len(pts.xyz)
    if cfg.use_gcps:
        for g in orientation.gcps:
            if not g.observations:
                continue
            local = orientation.frame.to_local(g.xyz)
            xyz.append(local[None])
            o_img.append(np.array([names[i] for i, _, _ in g.observations], dtype=np.int64))
            o_pt.append(np.full(len(g.observations), n, dtype=np.int64))
            o_xy.append(np.array([[x, y] for _, x, y in g.observations], dtype=np.float64))
            o_sig.append(
                np.array([g.obs_sigma.get(i, cfg.obs_sigma) for i, _, _ in g.observations], dtype=float)
            )
            if g.role == "gcp":
                pri_idx.append(n)
                pri_xyz.append(local)
                pri_sig.append(g.sigma if g.sigma is not None else np.asarray(cfg.gcp_sigma, dtype=float))
            n += 1
    if isinstance(cfg.refine_intrinsics, Mapping):
        unknown = set(cfg.refine_intrinsics) - set(cam_ids)
        if unknown:
            raise InputError(f"adjust_orientation: refine_intrinsics names unknown cameras {sorted(unknown)}")
        refine: object = {cam_index[c]: v for c, v in cfg.refine_intrinsics.items()}
    else:
        refine = cfg.refine_intrinsics
    fixed = []
    for name in cfg.fixed_images:
        if name not in names:
            raise InputError(f"adjust_orientation: fixed image {name!r} is not in the orientation")
        fixed.append(names[name])
    c_idx, c_xyz, c_sig = [], [], []
    for name, (cxyz, csig) in cfg.center_priors.items():
        if name not in names:
            raise InputError(f"adjust_orientation: centre prior for unknown image {name!r}")
        c_idx.append(names[name])
        c_xyz.append(orientation.frame.to_local(np.asarray(cxyz, dtype=float).reshape(3)))
        c_sig.append(np.asarray(csig, dtype=float).reshape(3))
    obs_image = np.concatenate(o_img)
    problem = BundleProblem(
        intrinsics=np.array([orientation.cameras[c].params for c in cam_ids]),
        image_camera=np.array([cam_index[im.camera] for im in orientation.images]),
        rotations=np.array([im.R for im in orientation.images]),
        centers=np.array([im.C for im in orientation.images]),
        points=np.concatenate(xyz).reshape(-1, 3),
        obs_image=obs_image,
        obs_point=np.concatenate(o_pt),
        obs_xy=np.concatenate(o_xy).reshape(-1, 2),
        obs_sigma=np.concatenate(o_sig),
        refine_intrinsics=refine,
        fixed_images=fixed,
        point_prior_index=np.array(pri_idx, dtype=np.int64),
        point_prior_xyz=np.array(pri_xyz).reshape(-1, 3),
        point_prior_sigma=np.array(pri_sig).reshape(-1, 3),
        center_prior_index=np.array(c_idx, dtype=np.int64),
        center_prior_xyz=np.array(c_xyz).reshape(-1, 3),
        center_prior_sigma=np.array(c_sig).reshape(-1, 3),
    )
    if cfg.outlier_k is not None:
        res = adjust_with_outlier_rejection(problem, cfg.bundle, k_sigma=cfg.outlier_k, progress=progress)
    else:
        res = bundle_adjust(problem, cfg.bundle, progress)
    return _write_back(orientation, cam_ids, res), res


def _write_back(orientation: Orientation, cam_ids: list[str], res: BundleResult) -> Orientation:
    cams = {}
    for i, cid in enumerate(cam_ids):
        old = orientation.cameras[cid]
        cams[cid] = Camera.from_params(res.intrinsics[i], old.width, old.height, id=cid)
    images = [
        Image(im.name, im.camera, res.rotations[k], res.centers[k], im.path)
        for k, im in enumerate(orientation.images)
    ]
    points = None
    p = orientation.points
    if p is not None:
        n = len(p.xyz)
        m = len(p.obs_point)
        r = res.residuals[:m]
        norm = np.linalg.norm(r, axis=1)
        ok = np.isfinite(norm)
        mean = np.bincount(p.obs_point[ok], weights=norm[ok], minlength=n)
        cnt = np.bincount(p.obs_point[ok], minlength=n)
        with np.errstate(invalid="ignore", divide="ignore"):
            err = mean / cnt  # mean reprojection error per point, pixels (NaN: unobserved)
        points = SparsePoints(res.points[:n], p.rgb, err, p.obs_point, p.obs_image, p.obs_xy)
    out = Orientation(
        orientation.frame,
        cams,
        images,
        points,
        list(orientation.gcps),
        orientation.image_root,
        dict(orientation.metadata),
    )
    return out
