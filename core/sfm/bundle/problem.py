"""The bundle adjustment problem: unknowns, observations, priors and the gauge.

Conventions are those of :mod:`truortho.core.geometry`: local frame, ``R``
world-to-camera, ``X_cam = R (X - C)``, pixel (0, 0) at the centre of the
top-left pixel, intrinsics vector ``[fx, fy, cx, cy, k1, k2, k3, p1, p2]``.

Unknowns
--------
* per image not held fixed: a rotation increment ``delta`` (3, radians) with
  the *left* multiplicative update ``R <- exp([delta]x) R`` (the increment is
  a small rotation of the camera axes, expressed in the camera frame) and the
  centre ``C`` (3, metres, local frame);
* per camera: the intrinsics named in ``refine_intrinsics``, a subset of
  :data:`INTRINSIC_NAMES`. ``"f"`` moves ``fx`` and scales ``fy`` with it,
  keeping the aspect ratio ``fy / fx``;
* every point ``X`` (3, metres, local frame).

Datum (gauge)
-------------
Image observations alone leave a 7-parameter similarity free. It is fixed by
the priors when there are at least three prior equations groups (control
points with :attr:`BundleProblem.point_prior_index`, camera-centre priors with
:attr:`BundleProblem.center_prior_index`, or at least two fixed images).
Otherwise (``gauge="auto"`` in the solver configuration) the first image's
pose is held (6 dof) and, of the image farthest from it, the centre
coordinate along the largest baseline component is held (1 dof: scale). That
is a minimal constraint: it changes no residual, only removes the rank defect.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError

#: Refinable intrinsics in the order of the kernel's Jacobian columns 6..13.
INTRINSIC_NAMES = ("f", "cx", "cy", "k1", "k2", "k3", "p1", "p2")
#: Column of the 14-column per-observation camera Jacobian of each name.
N_POSE = 6
N_CAMCOLS = N_POSE + len(INTRINSIC_NAMES)


@dataclass
class BundleProblem:
    """Input of :func:`~.solver.bundle_adjust`.

    Parameters
    ----------
    intrinsics : (n_cam, 9) float64
        ``[fx, fy, cx, cy, k1, k2, k3, p1, p2]`` per camera, pixels.
    image_camera : (n_img,) int
        Camera index of every image.
    rotations : (n_img, 3, 3) float64
        World-to-camera rotations.
    centers : (n_img, 3) float64
        Projection centres, local frame, metres.
    points : (n_pt, 3) float64
        Tie / control points, local frame, metres.
    obs_image, obs_point : (n_obs,) int
        Image and point index of every observation.
    obs_xy : (n_obs, 2) float64
        Measured pixel coordinates.
    obs_sigma : (n_obs,) float64, optional
        Standard deviation of each coordinate of an observation, pixels
        (default 1).
    refine_intrinsics : collection of str, or a sequence / mapping per camera
        Names from :data:`INTRINSIC_NAMES` to estimate. One collection applies
        to every camera; a sequence (or a ``{camera index: names}`` mapping)
        gives them per camera. Default: none (intrinsics held).
    fixed_images : sequence of int
        Images whose pose is held.
    point_prior_index : (k,) int; point_prior_xyz : (k, 3); point_prior_sigma : (k, 3)
        Ground control: a weighted observation ``X ~ prior`` of point
        ``index`` with standard deviations per axis (metres, local frame).
    center_prior_index : (m,) int; center_prior_xyz : (m, 3); center_prior_sigma : (m, 3)
        Camera-centre priors (e.g. GNSS), local frame, metres.
    """

    intrinsics: np.ndarray
    image_camera: np.ndarray
    rotations: np.ndarray
    centers: np.ndarray
    points: np.ndarray
    obs_image: np.ndarray
    obs_point: np.ndarray
    obs_xy: np.ndarray
    obs_sigma: np.ndarray | None = None
    refine_intrinsics: object = ()
    fixed_images: Sequence[int] = ()
    point_prior_index: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    point_prior_xyz: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    point_prior_sigma: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    center_prior_index: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    center_prior_xyz: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    center_prior_sigma: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

    @property
    def n_cameras(self) -> int:
        return len(self.intrinsics)

    @property
    def n_images(self) -> int:
        return len(self.rotations)

    @property
    def n_points(self) -> int:
        return len(self.points)

    @property
    def n_observations(self) -> int:
        return len(self.obs_image)

    def validate(self) -> None:
        """Normalise arrays in place; raise :class:`InputError` naming what is wrong."""
        self.intrinsics = _float(self.intrinsics, (-1, 9), "intrinsics")
        n_cam = len(self.intrinsics)
        if n_cam == 0:
            raise InputError("bundle: at least one camera is needed")
        if np.any(self.intrinsics[:, :2] <= 0):
            raise InputError("bundle: focal lengths fx, fy must be positive")
        self.rotations = _float(self.rotations, (-1, 3, 3), "rotations")
        n_img = len(self.rotations)
        orth = np.abs(np.einsum("nij,nkj->nik", self.rotations, self.rotations) - np.eye(3)).max(initial=0)
        if orth > 1e-6 or (n_img and np.any(np.abs(np.linalg.det(self.rotations) - 1) > 1e-6)):
            raise InputError(f"bundle: rotations must be orthonormal with det +1 (error {orth:.1e})")
        self.centers = _float(self.centers, (n_img, 3), "centers")
        self.image_camera = _index(self.image_camera, n_img, n_cam, "image_camera", "camera")
        self.points = _float(self.points, (-1, 3), "points")
        n_pt = len(self.points)
        n_obs = len(np.asarray(self.obs_image).reshape(-1))
        self.obs_image = _index(self.obs_image, n_obs, n_img, "obs_image", "image")
        self.obs_point = _index(self.obs_point, n_obs, n_pt, "obs_point", "point")
        self.obs_xy = _float(self.obs_xy, (n_obs, 2), "obs_xy")
        if self.obs_sigma is None:
            self.obs_sigma = np.ones(n_obs)
        self.obs_sigma = _float(self.obs_sigma, (n_obs,), "obs_sigma")
        if np.any(self.obs_sigma <= 0):
            raise InputError("bundle: obs_sigma must be positive")
        fixed = np.asarray(list(self.fixed_images), dtype=np.int64).reshape(-1)
        if np.any((fixed < 0) | (fixed >= n_img)):
            raise InputError(f"bundle: fixed_images refers to an image index outside [0, {n_img})")
        self.fixed_images = np.unique(fixed)
        for kind, n in (("point", n_pt), ("center", n_img)):
            idx = np.asarray(getattr(self, f"{kind}_prior_index"), dtype=np.int64).reshape(-1)
            k = len(idx)
            xyz = _float(getattr(self, f"{kind}_prior_xyz"), (k, 3), f"{kind}_prior_xyz")
            sig = _float(getattr(self, f"{kind}_prior_sigma"), (k, 3), f"{kind}_prior_sigma")
            if np.any((idx < 0) | (idx >= n)):
                raise InputError(f"bundle: {kind}_prior_index refers to an index outside [0, {n})")
            if len(np.unique(idx)) != k:
                raise InputError(f"bundle: {kind}_prior_index has duplicates")
            if np.any(sig <= 0):
                raise InputError(f"bundle: {kind}_prior_sigma must be positive")
            setattr(self, f"{kind}_prior_index", idx)
            setattr(self, f"{kind}_prior_xyz", xyz)
            setattr(self, f"{kind}_prior_sigma", sig)
        self.refine_intrinsics = _refine_sets(self.refine_intrinsics, n_cam)

    def has_datum(self) -> bool:
        """True when priors or fixed images define position, orientation and scale."""
        n = len(self.point_prior_index) + len(self.center_prior_index) + (len(self.fixed_images) >= 2) * 3
        return n >= 3


def _float(a, shape, name) -> np.ndarray:
    try:
        arr = np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"bundle: {name} must be numeric") from None
    want = tuple(shape)
    try:
        arr = arr.reshape(want)
    except ValueError:
        raise InputError(f"bundle: {name} has shape {arr.shape}, expected {want} (-1 = any)") from None
    if not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr.reshape(len(arr), -1)))[0, 0] if arr.size else 0
        raise InputError(f"bundle: {name} has non-finite values (first at row {bad})")
    return np.ascontiguousarray(arr)


def _index(a, n, upper, name, what) -> np.ndarray:
    arr = np.asarray(a).reshape(-1)
    if arr.size and not np.issubdtype(arr.dtype, np.integer):
        if not np.all(np.isfinite(arr.astype(float))) or np.any(arr != np.round(arr)):
            raise InputError(f"bundle: {name} must hold integers")
    arr = arr.astype(np.int64)
    if len(arr) != n:
        raise InputError(f"bundle: {name} has {len(arr)} entries, expected {n}")
    bad = np.flatnonzero((arr < 0) | (arr >= upper))
    if len(bad):
        raise InputError(
            f"bundle: {name}[{bad[0]}] = {arr[bad[0]]} refers to a missing {what} "
            f"(there are {upper}); {len(bad)} such entries"
        )
    return arr


def _refine_sets(spec, n_cam) -> list[frozenset[str]]:
    if spec is None or (isinstance(spec, Collection) and not isinstance(spec, str | Mapping) and not spec):
        sets: list = [()] * n_cam
    elif isinstance(spec, str):
        sets = [(spec,)] * n_cam
    elif isinstance(spec, Mapping):
        sets = [spec.get(i, ()) for i in range(n_cam)]
        extra = set(spec) - set(range(n_cam))
        if extra:
            raise InputError(f"bundle: refine_intrinsics names unknown cameras {sorted(extra, key=str)}")
    else:
        items = list(spec)
        if all(isinstance(s, str) for s in items):
            sets = [items] * n_cam
        elif len(items) == n_cam:
            sets = [[s] if isinstance(s, str) else list(s or ()) for s in items]
        else:
            raise InputError(
                f"bundle: refine_intrinsics must be one set of names or one per camera ({n_cam})"
            )
    out = []
    for c, s in enumerate(sets):
        names = frozenset(s)
        unknown = names - set(INTRINSIC_NAMES)
        if unknown:
            raise InputError(
                f"bundle: refine_intrinsics for camera {c}: unknown name(s) {sorted(unknown)}; "
                f"allowed: {', '.join(INTRINSIC_NAMES)}"
            )
        out.append(names)
    return out


@dataclass
class Layout:
    """Column indices of the reduced (camera) system.

    Attributes
    ----------
    pose_cols : (n_img, 6) int64
        Column of ``[d_rot(3), d_C(3)]`` per image, -1 when held.
    intr_cols : (n_cam, 8) int64
        Column of each :data:`INTRINSIC_NAMES` entry per camera, -1 when held.
    image_cols : (n_img, 14) int64
        ``pose_cols`` and the image's camera's ``intr_cols`` side by side: the
        columns of the per-observation camera Jacobian.
    n_cols : int
        Size of the reduced system.
    gauge : str
        How the datum was fixed (for reports).
    """

    pose_cols: np.ndarray
    intr_cols: np.ndarray
    image_cols: np.ndarray
    n_cols: int
    gauge: str


def build_layout(problem: BundleProblem, gauge: str = "auto") -> Layout:
    """Number the camera-side unknowns; hold what the gauge needs (module docstring)."""
    n_img, n_cam = problem.n_images, problem.n_cameras
    held = np.zeros((n_img, N_POSE), dtype=bool)
    held[problem.fixed_images] = True
    seen = np.bincount(problem.obs_image, minlength=n_img) > 0
    held[~seen] = True  # an image without observations cannot be oriented: keep its pose
    cam_seen = np.bincount(problem.image_camera[seen], minlength=n_cam) > 0
    note = "datum from priors / fixed images"
    if gauge == "auto" and not problem.has_datum():
        first = int(problem.fixed_images[0]) if len(problem.fixed_images) else int(np.argmax(seen))
        held[first] = True
        d = (problem.centers - problem.centers[first]) * seen[:, None]
        far = int(np.argmax(np.einsum("ij,ij->i", d, d)))
        if far == first or not np.any(d[far]):
            raise InputError("bundle: cannot fix the scale; all camera centres coincide and no priors")
        axis = int(np.argmax(np.abs(d[far])))
        held[far, 3 + axis] = True
        note = f"minimal: pose of image {first} and centre coordinate {'XYZ'[axis]} of image {far} held"
    elif gauge == "none":
        note = "none (free network; the system may be singular)"
    elif gauge != "auto":
        raise InputError(f"bundle: gauge must be 'auto' or 'none', got {gauge!r}")
    pose_cols = np.full((n_img, N_POSE), -1, dtype=np.int64)
    free = ~held
    pose_cols[free] = np.arange(int(free.sum()))
    n = int(free.sum())
    intr_cols = np.full((n_cam, len(INTRINSIC_NAMES)), -1, dtype=np.int64)
    refine_sets: list[frozenset[str]] = list(problem.refine_intrinsics)  # type: ignore[call-overload]
    for c, names in enumerate(refine_sets):
        if not cam_seen[c]:
            continue
        for k, name in enumerate(INTRINSIC_NAMES):
            if name in names:
                intr_cols[c, k] = n
                n += 1
    image_cols = np.ascontiguousarray(np.hstack([pose_cols, intr_cols[problem.image_camera]]))
    return Layout(pose_cols, intr_cols, image_cols, n, note)
