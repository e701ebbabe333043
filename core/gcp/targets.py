"""Automatic detection of ground targets in photos, with a score per measurement.

Three kinds of targets (:data:`TARGET_TYPES`):

* ``aruco``: OpenCV ArUco markers anywhere in the image (``cv2.aruco.ArucoDetector``, sub-pixel
  corner refinement). The user maps marker IDs to GCP names. **The GCP is the marker's centre**:
  the intersection of the diagonals of the four refined outer corners, then refined by
  least-squares matching (:mod:`.lsm`) of the ideal marker rendered from the dictionary, with
  projective shaping started from the corners' homography.
* ``circle``: a dark disc on a light ground or a light disc on a dark ground, searched within
  ``search_radius`` pixels of a predicted position; centre from an ellipse fit, refined by LSM of
  an ideal disc (affine shaping started from the ellipse).
* ``checker``: an "X" target of two dark and two light quadrants, searched near a predicted
  position; the saddle point (most negative Hessian determinant, ``cv2.cornerSubPix``), refined by
  LSM of an ideal checker at the best of 36 orientations.

The **score** of a measurement is the normalised cross-correlation (0..1) of the ideal target
with the image after refinement. Measurements below ``min_score`` are reported with
``flag = "low score"``, never dropped; ``sigma_x``/``sigma_y`` are LSM's standard deviations
(NaN when the refinement failed, flag ``"refinement failed: <reason>"``).
Pixels: (0, 0) = centre of the top-left pixel (:mod:`truortho.core.geometry`), as OpenCV.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from ..errors import InputError
from ..progress import Progress
from ..synthetic.targets import checker_pattern, disc_pattern, render_homography
from .lsm import LsmConfig, LsmResult, lsm_match

TARGET_TYPES = ("aruco", "circle", "checker")
ARUCO_DICTIONARIES = (
    "DICT_4X4_50",
    "DICT_4X4_100",
    "DICT_4X4_250",
    "DICT_5X5_50",
    "DICT_5X5_100",
    "DICT_6X6_50",
    "DICT_6X6_250",
    "DICT_7X7_50",
    "DICT_ARUCO_ORIGINAL",
    "DICT_APRILTAG_36h11",
)


@dataclass(frozen=True)
class TargetConfig:
    """Settings of target detection.

    Parameters
    ----------
    target : str
        One of :data:`TARGET_TYPES`.
    dictionary : str
        ArUco dictionary, one of :data:`ARUCO_DICTIONARIES`.
    search_radius : float
        Circle/checker: pixels around the predicted position that are searched.
    min_score : float
        Measurements scoring lower are flagged ``"low score"`` (kept).
    refine : bool
        Refine the centre by least-squares matching of the ideal target.
    """

    target: str = "aruco"
    dictionary: str = "DICT_4X4_50"
    search_radius: float = 25.0
    min_score: float = 0.7
    refine: bool = True

    def __post_init__(self) -> None:
        if self.target not in TARGET_TYPES:
            raise InputError(f"target type must be one of {TARGET_TYPES}, got {self.target!r}")
        if self.dictionary not in ARUCO_DICTIONARIES:
            raise InputError(f"ArUco dictionary must be one of {ARUCO_DICTIONARIES}, got {self.dictionary!r}")
        if not (math.isfinite(self.search_radius) and self.search_radius >= 3):
            raise InputError(f"search radius must be at least 3 px, got {self.search_radius!r}")
        if not 0.0 <= self.min_score <= 1.0:
            raise InputError(f"min score must be in [0, 1], got {self.min_score!r}")


@dataclass(frozen=True)
class TargetMeasurement:
    """One detected target: ``gcp`` name, ``image`` name, pixel ``x, y``, ``score`` in [0, 1],
    standard deviations in pixels, ``flag`` (``"ok"``, ``"low score"``, ``"refinement failed:
    ..."``) and for ArUco the ``marker_id``."""

    gcp: str
    image: str
    x: float
    y: float
    score: float
    sigma_x: float
    sigma_y: float
    flag: str
    marker_id: int = -1


def parse_id_mapping(text: str) -> dict[int, str]:
    """``"0=GCP1, 1=GCP2"`` -> ``{0: "GCP1", 1: "GCP2"}`` (IDs and names unique).

    Raises
    ------
    InputError
        Naming the malformed item.
    """
    out: dict[int, str] = {}
    for item in (text or "").replace(";", ",").split(","):
        item = item.strip()
        if not item:
            continue
        key, sep, name = item.partition("=")
        name = name.strip()
        if not sep or not key.strip().isdigit() or not name:
            raise InputError(f"marker mapping: expected 'ID=NAME' (e.g. 0=GCP1), got {item!r}")
        mid = int(key)
        if mid in out:
            raise InputError(f"marker mapping: ID {mid} appears twice")
        if name in out.values():
            raise InputError(f"marker mapping: name {name!r} appears twice")
        out[mid] = name
    if not out:
        raise InputError("marker mapping: empty; give 'ID=NAME' pairs such as 0=GCP1,1=GCP2")
    return out


def _gray(image) -> np.ndarray:
    a = np.asarray(image)
    if a.ndim == 3:
        a = a[:, :, :3].astype(np.float64) @ np.array([0.299, 0.587, 0.114])[: a.shape[2]]
    if a.ndim != 2 or min(a.shape) < 8:
        raise InputError(
            f"image: expected a grey or colour image of at least 8x8 pixels, got shape {a.shape}"
        )
    a = a.astype(np.float64)
    if not np.all(np.isfinite(a)):
        raise InputError("image: contains NaN or infinite values")
    return a


def _u8(a: np.ndarray) -> np.ndarray:
    lo, hi = float(a.min()), float(a.max())
    if hi <= lo:
        return np.zeros(a.shape, np.uint8)
    return np.clip((a - lo) * (255.0 / (hi - lo)) + 0.5, 0, 255).astype(np.uint8)


def _flag(score: float, cfg: TargetConfig, lsm: LsmResult | None) -> str:
    if lsm is not None and not lsm.converged and lsm.reason != "low correlation":
        return f"refinement failed: {lsm.reason}"
    return "ok" if score >= cfg.min_score else "low score"


def _measurement(
    gcp, image, x, y, cfg, lsm: LsmResult | None, score: float, marker_id=-1
) -> TargetMeasurement:
    if lsm is not None and (lsm.converged or lsm.reason == "low correlation"):
        x, y = lsm.x, lsm.y
        sx, sy = lsm.sigma_x, lsm.sigma_y
        score = lsm.correlation
    else:
        sx = sy = float("nan")
    score = float(min(max(score, 0.0), 1.0)) if math.isfinite(score) else 0.0
    return TargetMeasurement(
        gcp, image, float(x), float(y), score, sx, sy, _flag(score, cfg, lsm), int(marker_id)
    )


# ---------------------------------------------------------------- ArUco


def _dictionary(name: str):
    return cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, name))


def _marker_template(dictionary, marker_id: int, module_px: float):
    """Ideal marker with a one-module white margin; returns (template, half side in px)."""
    bits = dictionary.markerSize
    cells = cv2.aruco.generateImageMarker(dictionary, int(marker_id), bits + 2, borderBits=1)
    pattern = np.pad(cells.astype(np.float64) / 255.0, 1, constant_values=1.0)
    n = pattern.shape[0]
    s = float(module_px)
    h = int(math.ceil(s * n / 2.0))
    H = np.array([[s, 0.0, h - s * (n - 1) / 2.0], [0.0, s, h - s * (n - 1) / 2.0], [0.0, 0.0, 1.0]])
    return render_homography(pattern, H, (2 * h + 1, 2 * h + 1), background=1.0), s * (bits + 2) / 2.0


def _diagonal_centre(c: np.ndarray) -> tuple[float, float]:
    """Intersection of the diagonals c0-c2 and c1-c3 of a quadrilateral (4, 2)."""
    p, r = c[0], c[2] - c[0]
    q, s = c[1], c[3] - c[1]
    den = r[0] * s[1] - r[1] * s[0]
    if abs(den) < 1e-12:
        m = c.mean(axis=0)
        return float(m[0]), float(m[1])
    t = ((q[0] - p[0]) * s[1] - (q[1] - p[1]) * s[0]) / den
    return float(p[0] + t * r[0]), float(p[1] + t * r[1])


def detect_aruco(image, names: dict[int, str], image_name: str = "", config: TargetConfig | None = None):
    """ArUco markers of ``names`` in one image.

    Parameters
    ----------
    image : (H, W) or (H, W, C) array
    names : dict int -> str
        Marker ID -> GCP name.
    image_name : str
        Written into the measurements.
    config : TargetConfig, optional

    Returns
    -------
    measurements : list of TargetMeasurement
        One per detected marker whose ID is mapped.
    unmapped : list of int
        IDs found in the image that the mapping does not name.
    """
    cfg = config or TargetConfig()
    gray = _gray(image)
    d = _dictionary(cfg.dictionary)
    params = cv2.aruco.DetectorParameters()
    params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    detector = cv2.aruco.ArucoDetector(d, params)
    corners, ids, _ = detector.detectMarkers(_u8(gray))
    out: list[TargetMeasurement] = []
    unmapped: list[int] = []
    if ids is None:
        return out, unmapped
    for c, mid in zip(corners, ids.reshape(-1), strict=True):
        mid = int(mid)
        if mid not in names:
            unmapped.append(mid)
            continue
        quad = np.asarray(c, dtype=np.float64).reshape(4, 2)
        cx, cy = _diagonal_centre(quad)
        lsm = None
        score = float("nan")
        side = float(np.mean(np.linalg.norm(quad - np.roll(quad, 1, axis=0), axis=1)))
        module = min(max(side / (d.markerSize + 2), 3.0), 8.0)
        tmpl, a = _marker_template(d, mid, module)
        src = np.array([[-a, -a], [a, -a], [a, a], [-a, a]], dtype=np.float32)
        H = cv2.getPerspectiveTransform(src, quad.astype(np.float32))
        if cfg.refine:
            lsm = lsm_match(
                tmpl,
                gray,
                cx,
                cy,
                LsmConfig(projective=True, coarse_sigma=0.0, max_shift=3.0, min_correlation=0.0),
                initial=H,
            )
        else:
            score = _score_at(tmpl, gray, H)
        out.append(_measurement(names[mid], image_name, cx, cy, cfg, lsm, score, mid))
    return out, unmapped


def _score_at(tmpl: np.ndarray, gray: np.ndarray, H: np.ndarray) -> float:
    """NCC of a template under a homography (template offsets -> image) without refinement."""
    h = tmpl.shape[0] // 2
    T = np.array([[1.0, 0.0, -h], [0.0, 1.0, -h], [0.0, 0.0, 1.0]])
    warped = cv2.warpPerspective(tmpl, H @ T, (gray.shape[1], gray.shape[0]), flags=cv2.INTER_LINEAR)
    mask = cv2.warpPerspective(np.ones_like(tmpl), H @ T, (gray.shape[1], gray.shape[0])) > 0.99
    if mask.sum() < 9:
        return 0.0
    a = warped[mask] - warped[mask].mean()
    b = gray[mask] - gray[mask].mean()
    den = math.sqrt(float((a * a).sum() * (b * b).sum()))
    return float((a * b).sum() / den) if den > 0 else 0.0


# ---------------------------------------------------------------- circle / checker


def _window(gray: np.ndarray, x: float, y: float, r: float):
    h, w = gray.shape
    ri = int(math.ceil(r))
    x0, y0 = max(0, int(round(x)) - ri), max(0, int(round(y)) - ri)
    x1, y1 = min(w, int(round(x)) + ri + 1), min(h, int(round(y)) + ri + 1)
    if x1 - x0 < 8 or y1 - y0 < 8:
        return None, x0, y0
    return gray[y0:y1, x0:x1], x0, y0


def detect_circle(
    image, x: float, y: float, gcp: str = "", image_name: str = "", config: TargetConfig | None = None
):
    """A circular target near the predicted pixel ``(x, y)``; None when no blob is found.

    Otsu threshold of the search window in both polarities; the blob closest to the prediction
    among the round ones (area / ellipse area > 0.8) gives the ellipse start of the refinement.
    """
    cfg = config or TargetConfig(target="circle")
    gray = _gray(image)
    win, ox, oy = _window(gray, x, y, cfg.search_radius + 4)
    if win is None:
        return None
    u8 = _u8(cv2.GaussianBlur(win, (0, 0), 0.7))
    _, binary = cv2.threshold(u8, 0, 255, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
    best = None
    for mask in (binary, 255 - binary):
        # outer boundaries of components only (a hole's boundary has the opposite polarity)
        contours, hierarchy = cv2.findContours(mask, cv2.RETR_CCOMP, cv2.CHAIN_APPROX_NONE)
        hier_all = hierarchy[0] if hierarchy is not None else np.zeros((0, 4), int)
        for c, hier in zip(contours, hier_all, strict=False):
            if len(c) < 8 or hier[3] != -1:
                continue
            area = cv2.contourArea(c)
            # a ring (a component with a sizeable hole, e.g. the light surround of a dark disc)
            # is not a disc
            child, holes = hier[2], 0.0
            while child != -1:
                holes += cv2.contourArea(contours[child])
                child = hier_all[child][0]
            if holes > 0.05 * area:
                continue
            (ex, ey), (ea, eb), ang = cv2.fitEllipse(c)
            if area < 12 or min(ea, eb) < 3:
                continue
            bx, by, bw, bh = cv2.boundingRect(c)
            if bx <= 0 or by <= 0 or bx + bw >= mask.shape[1] or by + bh >= mask.shape[0]:
                continue
            roundness = area / (math.pi * ea * eb / 4.0)
            if not 0.8 < roundness < 1.2 or max(ea, eb) > 3 * min(ea, eb):
                continue
            dist = math.hypot(ex + ox - x, ey + oy - y)
            if dist > cfg.search_radius:
                continue
            if best is None or dist < best[0]:
                best = (dist, ex + ox, ey + oy, ea / 2.0, eb / 2.0, math.radians(ang), mask is binary)
    if best is None:
        return None
    _, cx, cy, a, b, th, light = best
    rt = float(min(max(math.sqrt(a * b), 3.0), 10.0))
    half = int(math.ceil(1.45 * rt))
    tmpl = disc_pattern(2 * half + 1, rt, dark=not light)
    rot = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
    A = rot @ np.diag([a / rt, b / rt]) @ rot.T
    lsm = None
    if cfg.refine:
        lsm = lsm_match(tmpl, gray, cx, cy, LsmConfig(coarse_sigma=0.0, max_shift=3.0, min_correlation=0.0),
                        initial=np.column_stack([A, [0.0, 0.0]]))  # fmt: skip
        score = float("nan")
    else:
        H = np.eye(3)
        H[:2, :2] = A
        H[:2, 2] = [cx, cy]
        score = _score_at(tmpl, gray, H)
    return _measurement(gcp, image_name, cx, cy, cfg, lsm, score)


def detect_checker(
    image, x: float, y: float, gcp: str = "", image_name: str = "", config: TargetConfig | None = None
):
    """An "X" (checker) target near the predicted pixel ``(x, y)``; None when no saddle is found."""
    cfg = config or TargetConfig(target="checker")
    gray = _gray(image)
    win, ox, oy = _window(gray, x, y, cfg.search_radius + 6)
    if win is None:
        return None
    sm = cv2.GaussianBlur(win, (0, 0), 1.5)
    gyy, gyx = np.gradient(np.gradient(sm, axis=0))
    gxy, gxx = np.gradient(np.gradient(sm, axis=1))
    det = gxx * gyy - gxy * gyx
    yy, xx = np.mgrid[0 : win.shape[0], 0 : win.shape[1]]
    inside = (np.hypot(xx + ox - x, yy + oy - y) <= cfg.search_radius) & (xx > 3) & (yy > 3)
    inside &= (xx < win.shape[1] - 4) & (yy < win.shape[0] - 4)
    if not inside.any():
        return None
    det = np.where(inside, det, np.inf)
    iy, ix = np.unravel_index(int(np.argmin(det)), det.shape)
    if not det[iy, ix] < 0:
        return None
    pt = np.array([[[ix, iy]]], dtype=np.float32)
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 40, 1e-3)
    cv2.cornerSubPix(_u8(win).copy(), pt, (4, 4), (-1, -1), crit)
    cx, cy = float(pt[0, 0, 0]) + ox, float(pt[0, 0, 1]) + oy
    half = 8
    tmpl = render_homography(
        checker_pattern(64), _scale_about(64, 2 * half + 1), (2 * half + 1, 2 * half + 1)
    )
    best_score, best_rot = -2.0, np.eye(2)
    for k in range(36):
        th = math.radians(5.0 * k)
        rot = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
        H = np.eye(3)
        H[:2, :2] = rot
        H[:2, 2] = [cx, cy]
        s = _score_at(tmpl, gray, H)
        if s > best_score:
            best_score, best_rot = s, rot
    lsm = None
    if cfg.refine:
        lsm = lsm_match(tmpl, gray, cx, cy, LsmConfig(coarse_sigma=0.0, max_shift=3.0, min_correlation=0.0),
                        initial=np.column_stack([best_rot, [0.0, 0.0]]))  # fmt: skip
    return _measurement(gcp, image_name, cx, cy, cfg, lsm, best_score)


def _scale_about(n_pattern: int, n_template: int) -> np.ndarray:
    """Homography pattern -> template mapping the pattern centre to the template centre, the
    pattern's width onto 1.5 template widths (the quadrants fill the template)."""
    s = 1.5 * n_template / n_pattern
    c_p, c_t = (n_pattern - 1) / 2.0, (n_template - 1) / 2.0
    return np.array([[s, 0.0, c_t - s * c_p], [0.0, s, c_t - s * c_p], [0.0, 0.0, 1.0]])


# ---------------------------------------------------------------- a folder


@dataclass(frozen=True)
class TargetDetection:
    """Result of :func:`detect_targets`: the measurements (low scores included, flagged), the
    warnings for a report (unmapped marker IDs, GCPs never found) and the number of images."""

    measurements: list[TargetMeasurement]
    warnings: list[str]
    images: int


def detect_targets(
    folder,
    config: TargetConfig | None = None,
    names: dict[int, str] | None = None,
    predictions=None,
    progress: Progress | None = None,
) -> TargetDetection:
    """Detect targets in every image of a folder.

    Parameters
    ----------
    folder : str or os.PathLike
        Folder of the images (:func:`truortho.core.gcp.measurements.list_images`).
    config : TargetConfig, optional
    names : dict int -> str
        ArUco marker ID -> GCP name; required for ``target = "aruco"``.
    predictions : sequence of :class:`~truortho.core.gcp.measurements.Prediction`
        Predicted pixel of each GCP in each image (from an orientation); required for circle and
        checker targets, which are searched within ``search_radius`` of them. Ignored for ArUco.
    progress : Progress, optional
        Per image; cancel between images.

    Returns
    -------
    TargetDetection

    Raises
    ------
    InputError
        Bad folder, a missing mapping or missing predictions, a prediction for an image that is
        not in the folder.
    """
    from ..imagery import luminance, read_image
    from ..progress import as_progress, check
    from .measurements import list_images

    cfg = config or TargetConfig()
    photos = list_images(folder)
    prog = as_progress(progress)
    warnings: list[str] = []
    out: list[TargetMeasurement] = []
    by_image: dict[str, list] = {}
    if cfg.target == "aruco":
        if not names:
            raise InputError("ArUco targets need the marker mapping 'ID=NAME' (e.g. 0=GCP1,1=GCP2)")
    else:
        if not predictions:
            raise InputError(
                f"{cfg.target} targets are searched near predicted positions: give an orientation and "
                "GCPs that project into the images"
            )
        known = {p.name for p in photos}
        for pr in predictions:
            if pr.image not in known:
                raise InputError(
                    f"prediction of GCP {pr.gcp!r} on image {pr.image!r}, which is not in the folder"
                )
            by_image.setdefault(pr.image, []).append(pr)
    unmapped: dict[int, list[str]] = {}
    for k, photo in enumerate(photos):
        check(prog)
        prog.update(k / len(photos), f"{photo.name}: looking for {cfg.target} targets")
        if cfg.target != "aruco" and photo.name not in by_image:
            continue
        gray = luminance(read_image(photo.path))
        if cfg.target == "aruco":
            found, ids = detect_aruco(gray, names or {}, photo.name, cfg)
            out.extend(found)
            for i in ids:
                unmapped.setdefault(i, []).append(photo.name)
            continue
        detect = detect_circle if cfg.target == "circle" else detect_checker
        for pr in by_image[photo.name]:
            m = detect(gray, pr.x, pr.y, pr.gcp, photo.name, cfg)
            if m is None:
                warnings.append(
                    f"{photo.name}: no {cfg.target} target of GCP {pr.gcp!r} within {cfg.search_radius:g} px "
                    f"of its predicted position ({pr.x:.1f}, {pr.y:.1f})"
                )
            else:
                out.append(m)
    prog.update(1.0, f"{len(out)} measurements in {len(photos)} images")
    for i, imgs in sorted(unmapped.items()):
        warnings.append(f"marker ID {i} (not in the mapping) seen in {len(imgs)} image(s), e.g. {imgs[0]}")
    seen = {m.gcp for m in out}
    expected = set(names.values()) if cfg.target == "aruco" and names else {p.gcp for p in predictions or []}
    for g in sorted(expected - seen):
        warnings.append(f"GCP {g!r} was not found in any image")
    low = sum(m.flag != "ok" for m in out)
    if low:
        warnings.append(f"{low} measurement(s) flagged (low score or failed refinement): check them")
    return TargetDetection(out, warnings, len(photos))
