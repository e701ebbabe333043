"""Pairwise OpenCV SGBM baseline DSM: the classic stereo pipeline as a benchmark peer of OSGM.

Not product code: the acceptance battery (``bench/acceptance.py``) runs it on
synthetic scenes with exact truth to compare accuracy and wall time of our
object-space multi-image matcher (:func:`truortho.core.osgm.run_osgm`) with
the textbook approach of matching image pairs in rectified image space.

Method (:func:`sgbm_dsm`)
-------------------------
1. **Pair selection** (:func:`choose_pairs`). Candidates are image pairs whose
   cameras have the same image size, whose optical axes differ by less than
   :data:`MAX_AXIS_ANGLE_DEG` (near-nadir pairs, and oblique pairs looking the
   same way), whose ground footprints on the plane at the middle of the height
   range overlap by at least :data:`MIN_OVERLAP` of the smaller footprint,
   whose base/height ratio lies in [:data:`MIN_BASE_HEIGHT`,
   :data:`MAX_BASE_HEIGHT`] (base = the part of the baseline across the mean
   viewing direction, height = the mean depth of the overlap's centre) and
   that can be rectified (step 2). Greedy, best first, while both images have
   fewer than ``max_pairs_per_image`` partners, on ``overlap x
   min(1, B/H / IDEAL_BASE_HEIGHT)`` discounted for ground that chosen pairs
   already cover (so the ends of the strips, seen by close neighbours only,
   are not left out).
2. **Rectification** (:func:`rectify_pair`). The rotations come from
   ``cv2.stereoRectify`` on the relative pose (``X_b = R X_a + T`` with
   ``R = R_b R_a^T``, ``T = R_b (C_a - C_b)``). OpenCV rectifies vertically
   when the baseline runs along the image columns; then x and y of the
   rectified frame are swapped (the rectified images are transposed) so that
   the epipolar lines are always rows. The rectified cameras get the smaller
   original focal length, one common ``cy`` and each its own ``cx``, placed so
   that each image border just fits (OpenCV's own ``alpha`` fit with a common
   principal point shrinks the focal length, badly for nadir/oblique pairs).
   Pairs whose rectified images would be much larger than the sources
   (:data:`MAX_RECTIFIED_GROWTH`, :data:`MAX_RECTIFIED_RAY_ANGLE_DEG`) are
   refused. ``initUndistortRectifyMap`` + ``remap`` (bilinear) produce the
   rectified images, including the removal of the Brown distortion. The image
   whose rectified camera lies in the negative-x direction of the other is
   the left one.
3. **Matching** (:func:`match_pair`). ``cv2.StereoSGBM`` in
   ``MODE_SGBM_3WAY`` on the colour images: block size 5,
   ``P1 = 8 cn bs^2``, ``P2 = 32 cn bs^2`` (cn = channels), uniqueness 10,
   speckle filter (window 100, range 2), left-right check
   ``disp12MaxDiff = 1``. The disparity range is that of the corners of the
   footprint overlap at ``z_min`` and ``z_max`` (disparity depends only on the
   rectified depth, which is affine on a plane, so its extremes lie on the
   corners), widened by :data:`DISPARITY_MARGIN` pixels; numDisparities is a
   multiple of 16. The images are padded on the left so that SGBM matches
   every column (see :func:`match_pair`). Disparities whose left or right
   pixel falls on the black border of the rectified images (eroded by the
   block radius) are dropped.
4. **Triangulation.** Rectified depth ``Z = f B / (d - cx_left + cx_right)``,
   then ``X = (u - cx_left) Z / f``, ``Y = (v - cy) Z / f`` in the left
   rectified camera, rotated and shifted back to the local frame and to the
   world (``world = local + orientation.offset``); points with world height
   outside ``[z_min, z_max]`` are dropped.
5. **Rasterisation and fusion.** Each pair's points are binned into the grid
   cells that contain them and reduced to the per-cell median; the DSM is the
   per-cell median over the pairs that reached the cell (NaN where none did).
   There is no hole filling and no interpolation: empty cells stay NaN.

Run ``python -P bench/sgbm_baseline.py`` for a self-check on a small
synthetic scene (completeness, NMAD and share within 3 GSD against the
truth).
"""

from __future__ import annotations

import dataclasses
import heapq
import itertools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

import cv2
import numpy as np

from truortho.core.geometry.camera import Camera
from truortho.core.geometry.footprint import footprint_on_plane, frame_outline
from truortho.core.grid import RasterGrid
from truortho.core.imagery import read_image_sized, to_uint8
from truortho.core.orientation import Image, Orientation

#: Largest angle between the optical axes of a pair, degrees.
MAX_AXIS_ANGLE_DEG = 25.0
#: Smallest footprint overlap of a pair, as a fraction of the smaller footprint.
MIN_OVERLAP = 0.3
#: Accepted base/height range.
MIN_BASE_HEIGHT, MAX_BASE_HEIGHT = 0.1, 0.6
#: Base/height from which a pair's geometry counts as fully good in the score.
IDEAL_BASE_HEIGHT = 0.3
#: SGBM block size (pixels, odd).
BLOCK_SIZE = 5
#: Pixels added on either side of the predicted disparity range.
DISPARITY_MARGIN = 4
#: Largest angle between a pixel's ray and the rectified optical axis, degrees.
MAX_RECTIFIED_RAY_ANGLE_DEG = 70.0
#: Largest rectified image, as a multiple of the source image's pixels.
MAX_RECTIFIED_GROWTH = 4.0

Progress = Callable[[float, str], object]


@dataclass(frozen=True)
class Pair:
    """A stereo pair chosen by :func:`choose_pairs` (image indices into the orientation)."""

    a: int
    b: int
    overlap: float  # overlap area / smaller footprint area, on the mid-height plane
    base_height: float
    score: float  # geometry weight; after choose_pairs the priority at acceptance


@dataclass
class RectifiedView:
    """One image of a rectified pair.

    ``M`` rotates the local frame into the rectified camera frame (possibly
    with determinant -1, see :func:`_rectifying_rotations`); the rectified pixel of a
    local point ``P`` is ``(f x / z + cx, f y / z + cy)`` with
    ``(x, y, z) = M (P - C)``.
    """

    index: int
    maps: tuple[np.ndarray, np.ndarray]
    M: np.ndarray
    C: np.ndarray
    cx: float


@dataclass
class RectifiedPair:
    """Rectification of one pair: epipolar lines are image rows, ``left`` sees points further right.

    Both views share the rotation ``M``, the focal ``f``, ``cy`` and the image
    size; ``base`` (> 0) is the right camera's x in the left rectified frame,
    so the disparity ``u_left - u_right`` of a point at rectified depth ``z``
    is ``f base / z + left.cx - right.cx``.
    """

    left: RectifiedView
    right: RectifiedView
    f: float
    cy: float
    base: float

    def disparity_of_depth(self, z: np.ndarray) -> np.ndarray:
        return self.f * self.base / z + (self.left.cx - self.right.cx)

    def depth_of_disparity(self, d: np.ndarray) -> np.ndarray:
        return self.f * self.base / (d - (self.left.cx - self.right.cx))


# ------------------------------------------------------------------ pair selection


def _footprint_hull(orientation: Orientation, im: Image, z_local: float) -> np.ndarray | None:
    """Convex hull (float32, (M, 1, 2)) of an image's footprint on the plane ``Z = z_local``."""
    fp = footprint_on_plane(im.R, im.C, orientation.camera_of(im), z_local)
    if fp is None:
        return None
    return cv2.convexHull(fp.astype(np.float32))


def _overlap(h1: np.ndarray, h2: np.ndarray) -> tuple[float, np.ndarray | None]:
    """Area and polygon ((K, 2) float64) of the intersection of two convex polygons."""
    area, poly = cv2.intersectConvexConvex(h1, h2)
    if poly is None or area <= 0:
        return 0.0, None
    return float(area), poly.reshape(-1, 2).astype(np.float64)


def _candidate_pairs(orientation: Orientation, z_mid_local: float) -> list[tuple[Pair, np.ndarray, float]]:
    """Every acceptable pair with its overlap polygon on the plane and the smaller footprint area."""
    images = orientation.images
    hulls = [_footprint_hull(orientation, im, z_mid_local) for im in images]
    areas = [0.0 if h is None else float(cv2.contourArea(h)) for h in hulls]
    cos_max = math.cos(math.radians(MAX_AXIS_ANGLE_DEG))
    out = []
    for i, j in itertools.combinations(range(len(images)), 2):
        a, b = images[i], images[j]
        hi, hj = hulls[i], hulls[j]
        ca, cb = orientation.camera_of(a), orientation.camera_of(b)
        if hi is None or hj is None or min(areas[i], areas[j]) <= 0:
            continue
        if (ca.width, ca.height) != (cb.width, cb.height):
            continue
        if float(a.viewing_direction @ b.viewing_direction) < cos_max:
            continue
        area, poly = _overlap(hi, hj)
        smaller = min(areas[i], areas[j])
        if poly is None or area < MIN_OVERLAP * smaller:
            continue
        centre = np.append(poly.mean(axis=0), z_mid_local)
        height = 0.5 * (float(a.R[2] @ (centre - a.C)) + float(b.R[2] @ (centre - b.C)))
        axis = a.viewing_direction + b.viewing_direction
        axis /= np.linalg.norm(axis)
        baseline = b.C - a.C
        base = float(np.linalg.norm(baseline - (baseline @ axis) * axis))
        if not (height > 0 and MIN_BASE_HEIGHT <= base / height <= MAX_BASE_HEIGHT):
            continue
        if rectified_layout(orientation, a, b) is not None:
            bh = base / height
            out.append((Pair(i, j, area / smaller, bh, min(1.0, bh / IDEAL_BASE_HEIGHT)), poly, smaller))
    return out


def choose_pairs(orientation: Orientation, z_mid_local: float, max_pairs_per_image: int) -> list[Pair]:
    """Stereo pairs in the order chosen, at most ``max_pairs_per_image`` partners per image.

    Greedy on ``priority = geometry x novel overlap / smaller footprint``:
    ``geometry = min(1, B/H / IDEAL_BASE_HEIGHT)``; the overlap polygon is
    rasterised on a coarse plan grid (1/20 of the median footprint side) and
    each of its cells counts ``0.5 ** k`` with ``k`` the pairs already chosen
    that cover it. So the best-looking pairs come first, but a pair that alone
    covers some ground (e.g. at the end of a strip) outranks one more pair
    over ground that is already matched. Priorities only decrease, so a lazy
    heap finds the maximum. ``Pair.score`` is the priority at acceptance.
    """
    candidates = _candidate_pairs(orientation, z_mid_local)
    if not candidates:
        return []
    polys = np.concatenate([poly for _, poly, _ in candidates])
    cell = math.sqrt(float(np.median([smaller for _, _, smaller in candidates]))) / 20.0
    origin = polys.min(axis=0)
    shape = tuple(int(v) + 1 for v in np.ceil((polys.max(axis=0) - origin) / cell)[::-1])
    cells = []
    for _, poly, _ in candidates:  # flat indices of the plan cells inside each overlap polygon
        pix = (poly - origin) / cell
        x0, y0 = np.floor(pix.min(axis=0)).astype(int)
        x1, y1 = np.ceil(pix.max(axis=0)).astype(int)
        mask = np.zeros((y1 - y0 + 1, x1 - x0 + 1), np.uint8)
        cv2.fillConvexPoly(mask, np.rint(pix - (x0, y0)).astype(np.int32), 1)
        r, c = np.nonzero(mask)
        cells.append(np.ravel_multi_index((r + y0, c + x0), shape))
    cover = np.zeros(shape[0] * shape[1], np.int32)

    def priority(k: int) -> float:
        pair, _, smaller = candidates[k]
        novel = float(np.sum(0.5 ** cover[cells[k]])) * cell * cell
        return pair.score * novel / smaller

    heap = [(-priority(k), k) for k in range(len(candidates))]
    heapq.heapify(heap)
    degree = [0] * len(orientation.images)
    chosen: list[Pair] = []
    while heap:
        _, k = heapq.heappop(heap)
        pair = candidates[k][0]
        if degree[pair.a] >= max_pairs_per_image or degree[pair.b] >= max_pairs_per_image:
            continue
        prio = priority(k)
        if heap and prio < -heap[0][0]:
            heapq.heappush(heap, (-prio, k))
            continue
        chosen.append(dataclasses.replace(pair, score=prio))
        cover[cells[k]] += 1
        degree[pair.a] += 1
        degree[pair.b] += 1
    return chosen


# ------------------------------------------------------------------ rectification


_SWAP_XY = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])


def _rectifying_rotations(orientation: Orientation, a: Image, b: Image) -> tuple[np.ndarray, np.ndarray]:
    """Camera-to-rectified rotations of ``a`` and ``b`` that put the baseline along the rectified x axis.

    ``cv2.stereoRectify`` aligns the baseline with x or, when it runs along
    the image columns, with y; then x and y are swapped (an improper but
    orthogonal matrix: the rectified images are transposed).
    """
    cam_a, cam_b = orientation.camera_of(a), orientation.camera_of(b)
    Ra, Rb = cv2.stereoRectify(
        cam_a.K,
        cam_a.dist_coeffs,
        cam_b.K,
        cam_b.dist_coeffs,
        (cam_a.width, cam_a.height),
        b.R @ a.R.T,
        b.R @ (a.C - b.C),
    )[:2]
    base = Ra @ a.R @ (b.C - a.C)
    if abs(base[1]) > abs(base[0]):
        return _SWAP_XY @ Ra, _SWAP_XY @ Rb
    return Ra, Rb


def _rectified_box(camera: Camera, rotation: np.ndarray, f: float) -> np.ndarray | None:
    """``(x_min, y_min, x_max, y_max)`` of the image border in rectified pixels from the principal point.

    None when a border ray is more than :data:`MAX_RECTIFIED_RAY_ANGLE_DEG`
    from the rectified axis (or cannot be undistorted): planar rectification
    would stretch the image beyond use.
    """
    xy = camera.undistort(frame_outline(camera, 16))
    rays = np.column_stack([xy, np.ones(len(xy))]) @ rotation.T
    cos = rays[:, 2] / np.linalg.norm(rays, axis=1)
    if not np.all(np.isfinite(cos)) or cos.min() < math.cos(math.radians(MAX_RECTIFIED_RAY_ANGLE_DEG)):
        return None
    p = f * rays[:, :2] / rays[:, 2:3]
    return np.r_[p.min(axis=0), p.max(axis=0)]


@dataclass
class _Layout:
    """Rectified geometry of a pair before any map is built (:func:`rectified_layout`)."""

    rot_a: np.ndarray
    rot_b: np.ndarray
    f: float
    cx_a: float
    cx_b: float
    cy: float
    size: tuple[int, int]


def rectified_layout(orientation: Orientation, a: Image, b: Image) -> _Layout | None:
    """Rotations, focal, principal points and size of the rectified pair; None when it cannot be rectified.

    Rotations from ``cv2.stereoRectify`` (:func:`_rectifying_rotations`); the
    rectified cameras get the smaller original focal length and each its own
    ``cx`` so that its image border just fits (rows shared), instead of
    OpenCV's ``alpha`` fit with one common principal point, which shrinks the
    focal length badly for pairs with a large disparity or rotation. Pairs
    whose rectified images would exceed :data:`MAX_RECTIFIED_GROWTH` times the
    source pixels, or with a ray too far from the rectified axis, are refused.
    """
    cam_a, cam_b = orientation.camera_of(a), orientation.camera_of(b)
    rot_a, rot_b = _rectifying_rotations(orientation, a, b)
    f = min(cam_a.fx, cam_a.fy, cam_b.fx, cam_b.fy)
    box_a, box_b = _rectified_box(cam_a, rot_a, f), _rectified_box(cam_b, rot_b, f)
    if box_a is None or box_b is None:
        return None
    y0 = math.floor(min(box_a[1], box_b[1]))
    height = math.ceil(max(box_a[3], box_b[3])) - y0 + 1
    width = max(math.ceil(box[2]) - math.floor(box[0]) + 1 for box in (box_a, box_b))
    if width * height > MAX_RECTIFIED_GROWTH * max(cam_a.width * cam_a.height, cam_b.width * cam_b.height):
        return None
    cx_a, cx_b = float(-math.floor(box_a[0])), float(-math.floor(box_b[0]))
    return _Layout(rot_a, rot_b, f, cx_a, cx_b, float(-y0), (width, height))


def rectify_pair(orientation: Orientation, ia: int, ib: int) -> RectifiedPair | None:
    """Rectify images ``ia`` and ``ib`` (see :class:`RectifiedPair`); None when they cannot be."""
    a, b = orientation.images[ia], orientation.images[ib]
    lay = rectified_layout(orientation, a, b)
    if lay is None:
        return None
    views = []
    for index, im, rot, cx in ((ia, a, lay.rot_a, lay.cx_a), (ib, b, lay.rot_b, lay.cx_b)):
        cam = orientation.camera_of(im)
        K = np.array([[lay.f, 0.0, cx], [0.0, lay.f, lay.cy], [0.0, 0.0, 1.0]])
        maps = cv2.initUndistortRectifyMap(cam.K, cam.dist_coeffs, rot, K, lay.size, cv2.CV_32FC1)
        views.append(RectifiedView(index, maps, rot @ im.R, im.C, cx))
    base = float((views[0].M @ (b.C - a.C))[0])
    if base > 0:
        return RectifiedPair(views[0], views[1], lay.f, lay.cy, base)
    return RectifiedPair(views[1], views[0], lay.f, lay.cy, -base)


def disparity_range(
    orientation: Orientation, rp: RectifiedPair, z_min_local: float, z_max_local: float
) -> tuple[float, float] | None:
    """Smallest and largest disparity of the footprint overlap at both ends of the height range."""
    left, right = orientation.images[rp.left.index], orientation.images[rp.right.index]
    disparities = []
    for z in (z_min_local, z_max_local):
        hl, hr = _footprint_hull(orientation, left, z), _footprint_hull(orientation, right, z)
        if hl is None or hr is None:
            continue
        _, poly = _overlap(hl, hr)
        if poly is None:
            continue
        corners = np.column_stack([poly, np.full(len(poly), z)])
        depth = (corners - rp.left.C) @ rp.left.M[2]
        disparities.append(rp.disparity_of_depth(depth[depth > 0]))
    d = np.concatenate(disparities) if disparities else np.zeros(0)
    if d.size == 0:
        return None
    return float(d.min()), float(d.max())


# ------------------------------------------------------------------ matching


def _border_mask(maps: tuple[np.ndarray, np.ndarray], width: int, height: int) -> np.ndarray:
    """Rectified pixels that come from inside the source image, eroded by the block radius."""
    ones = np.full((height, width), 255, np.uint8)
    inside = cv2.remap(ones, maps[0], maps[1], cv2.INTER_NEAREST, borderValue=0)
    kernel = np.ones((BLOCK_SIZE, BLOCK_SIZE), np.uint8)
    return cv2.erode(inside, kernel) > 0


def match_pair(
    rp: RectifiedPair, img_left: np.ndarray, img_right: np.ndarray, d_range: tuple[float, float]
) -> np.ndarray:
    """SGBM on a rectified pair; returns the triangulated points (N, 3) in the local frame.

    OpenCV's SGBM leaves the ``minDisparity + numDisparities`` leftmost
    columns unmatched and fails when they exceed the width. So the rectified
    images are padded with black on the left: the left one by
    ``shift_l >= numDisparities`` columns and the right one by
    ``shift_r = shift_l + min_d``, which turns the disparity range into
    ``[0, numDisparities)`` and lets every column of the left image be
    matched; ``d = d' + min_d``.
    """
    rect_l = cv2.remap(img_left, *rp.left.maps, cv2.INTER_LINEAR, borderValue=0)
    rect_r = cv2.remap(img_right, *rp.right.maps, cv2.INTER_LINEAR, borderValue=0)
    h, w = rect_l.shape[:2]
    min_d = int(math.floor(d_range[0])) - DISPARITY_MARGIN
    num_d = 16 * math.ceil((math.ceil(d_range[1]) + DISPARITY_MARGIN + 1 - min_d) / 16)
    shift_l = num_d + max(0, -min_d)
    shift_r = shift_l + min_d
    width = w + max(shift_l, shift_r)
    pad_l = cv2.copyMakeBorder(rect_l, 0, 0, shift_l, width - w - shift_l, cv2.BORDER_CONSTANT, value=0)
    pad_r = cv2.copyMakeBorder(rect_r, 0, 0, shift_r, width - w - shift_r, cv2.BORDER_CONSTANT, value=0)
    cn = 1 if rect_l.ndim == 2 else rect_l.shape[2]
    sgbm = cv2.StereoSGBM_create(
        minDisparity=0,
        numDisparities=num_d,
        blockSize=BLOCK_SIZE,
        P1=8 * cn * BLOCK_SIZE**2,
        P2=32 * cn * BLOCK_SIZE**2,
        disp12MaxDiff=1,
        preFilterCap=63,
        uniquenessRatio=10,
        speckleWindowSize=100,
        speckleRange=2,
        mode=cv2.STEREO_SGBM_MODE_SGBM_3WAY,
    )
    disp = sgbm.compute(pad_l, pad_r)[:, shift_l : shift_l + w].astype(np.float32) / 16.0
    ok = (disp >= 0) & _border_mask(rp.left.maps, img_left.shape[1], img_left.shape[0])
    v, u = np.nonzero(ok)
    d = disp[v, u].astype(np.float64) + min_d
    ur = np.rint(u - d).astype(np.int64)
    inside = (ur >= 0) & (ur < w)
    v, u, d, ur = v[inside], u[inside], d[inside], ur[inside]
    keep = _border_mask(rp.right.maps, img_right.shape[1], img_right.shape[0])[v, ur]
    v, u, d = v[keep], u[keep], d[keep]
    z = rp.depth_of_disparity(d)
    ok = z > 0
    u, v, z = u[ok], v[ok], z[ok]
    cam_pts = np.column_stack([(u - rp.left.cx) * z / rp.f, (v - rp.cy) * z / rp.f, z])
    return cam_pts @ rp.left.M + rp.left.C  # M^-1 = M^T for the (possibly improper) orthogonal M


# ------------------------------------------------------------------ rasterisation


def _group_median(keys: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distinct keys and the median of the values of each."""
    order = np.lexsort((values, keys))
    k, v = keys[order], values[order]
    starts = np.flatnonzero(np.r_[True, k[1:] != k[:-1]])
    counts = np.diff(np.r_[starts, len(k)])
    lo, hi = starts + (counts - 1) // 2, starts + counts // 2
    return k[starts], 0.5 * (v[lo] + v[hi])


def _cells(points_world: np.ndarray, grid: RasterGrid) -> tuple[np.ndarray, np.ndarray]:
    """Flat cell index and height of the points that fall inside the grid."""
    col = np.floor((points_world[:, 0] - grid.x_min) / grid.res).astype(np.int64)
    row = np.floor((grid.y_max - points_world[:, 1]) / grid.res).astype(np.int64)
    inside = (col >= 0) & (col < grid.cols) & (row >= 0) & (row < grid.rows)
    return row[inside] * grid.cols + col[inside], points_world[inside, 2]


# ------------------------------------------------------------------ public entry


def _read_uint8(orientation: Orientation, image_root, index: int) -> np.ndarray:
    """The image as 8-bit RGB (or one band), checked against its camera's size."""
    im = orientation.images[index]
    cam = orientation.camera_of(im)
    img = to_uint8(read_image_sized(orientation.resolve_image_path(im, image_root), (cam.width, cam.height)))
    if img.ndim == 3:
        img = img[:, :, :3] if img.shape[2] >= 3 else img[:, :, 0]
    return np.ascontiguousarray(img)


def sgbm_dsm(
    orientation: Orientation,
    image_root,
    grid: RasterGrid,
    z_min: float,
    z_max: float,
    *,
    max_pairs_per_image: int = 3,
    progress: Progress | None = None,
) -> tuple[np.ndarray, dict]:
    """Pairwise SGBM DSM of ``grid`` (world frame) from the images of ``orientation``.

    Parameters
    ----------
    orientation : Orientation
    image_root : path or None
        Folder of the images (None = the orientation's image root).
    grid : RasterGrid
        Output grid in world coordinates.
    z_min, z_max : float
        World height range searched; points outside it are dropped.
    max_pairs_per_image : int
        Most stereo partners per image.
    progress : callable, optional
        ``progress(fraction, message)``.

    Returns
    -------
    dsm : (rows, cols) float32
        World heights, NaN where no pair produced a point.
    info : dict
        ``seconds`` (wall time of the call), ``pairs`` (pairs matched),
        ``points`` (triangulated points inside the height range and the grid),
        ``pair_details`` (per pair: image names, overlap, base/height,
        disparity range, points).
    """
    t0 = time.perf_counter()
    if not z_min < z_max:
        raise ValueError(f"z_min ({z_min}) must be below z_max ({z_max})")
    if max_pairs_per_image < 1:
        raise ValueError(f"max_pairs_per_image must be at least 1, got {max_pairs_per_image}")
    off = orientation.offset
    zl_min, zl_max = z_min - off[2], z_max - off[2]
    pairs = choose_pairs(orientation, 0.5 * (zl_min + zl_max), max_pairs_per_image)
    read = lru_cache(maxsize=4)(lambda i: _read_uint8(orientation, image_root, i))
    cell_keys, cell_values, details = [], [], []
    n_points = 0
    for k, pair in enumerate(pairs):
        if progress is not None:
            progress(k / max(len(pairs), 1), f"SGBM pair {k + 1}/{len(pairs)}")
        rp = rectify_pair(orientation, pair.a, pair.b)
        d_range = None if rp is None else disparity_range(orientation, rp, zl_min, zl_max)
        if rp is None or d_range is None:
            continue
        pts = match_pair(rp, read(rp.left.index), read(rp.right.index), d_range) + off
        pts = pts[(pts[:, 2] >= z_min) & (pts[:, 2] <= z_max)]
        keys, heights = _cells(pts, grid)
        details.append(
            {
                "left": orientation.images[rp.left.index].name,
                "right": orientation.images[rp.right.index].name,
                "overlap": pair.overlap,
                "base_height": pair.base_height,
                "disparity_range": d_range,
                "points": int(len(keys)),
            }
        )
        if len(keys):
            n_points += len(keys)
            keys, medians = _group_median(keys, heights)
            cell_keys.append(keys)
            cell_values.append(medians)
    dsm = np.full(grid.rows * grid.cols, np.nan, np.float32)
    if cell_keys:
        keys, medians = _group_median(np.concatenate(cell_keys), np.concatenate(cell_values))
        dsm[keys] = medians
    if progress is not None:
        progress(1.0, "SGBM done")
    info = {
        "seconds": time.perf_counter() - t0,
        "pairs": len(details),
        "points": n_points,
        "pair_details": details,
    }
    return dsm.reshape(grid.shape), info


# ------------------------------------------------------------------ self-check


def _self_check() -> None:
    """Run on a small synthetic scene and print the accuracy against the truth."""
    import tempfile

    from scipy import ndimage

    from truortho.core.geometry import project_points
    from truortho.core.synthetic import SceneConfig, make_scene

    cfg = SceneConfig(image_size=(480, 360), focal_px=600.0, n_oblique=0, seed=3)
    scene = make_scene(cfg)
    gsd = cfg.gsd
    grid = RasterGrid.from_extent(scene.extent_world(), gsd, cfg.crs)
    X, Y = grid.centres()
    truth = scene.height(np.column_stack([X.ravel(), Y.ravel()])).reshape(grid.shape)
    z_min, z_max = float(truth.min()) - 5.0, float(truth.max()) + 5.0
    with tempfile.TemporaryDirectory() as folder:
        scene.write(folder)
        dsm, info = sgbm_dsm(scene.orientation, folder, grid, z_min, z_max)
    # building edges: height steps over 1 m between neighbouring cells, widened by 5 cells
    steps = ndimage.maximum_filter(truth, 3) - ndimage.minimum_filter(truth, 3) > 1.0
    near_edge = ndimage.binary_dilation(steps, iterations=5)
    # cells whose truth point falls inside the frame of at least two images (occlusions ignored)
    local = np.column_stack([X.ravel(), Y.ravel(), truth.ravel()]) - scene.offset
    in_frames = np.zeros(local.shape[0], np.int64)
    for im in scene.orientation.images:
        cam = scene.orientation.camera_of(im)
        u, v = project_points(local, im.R, im.C, cam).T
        in_frames += (u >= -0.5) & (u <= cam.width - 0.5) & (v >= -0.5) & (v <= cam.height - 0.5)
    stereo = (in_frames >= 2).reshape(grid.shape)
    print(f"SGBM baseline: {info['pairs']} pairs, {info['points']:,} points, {info['seconds']:.2f} s")
    for p in info["pair_details"]:
        lo, hi = p["disparity_range"]
        print(
            f"  {p['left']} / {p['right']}: overlap {p['overlap']:.2f}, B/H {p['base_height']:.2f}, "
            f"disparity {lo:.0f}..{hi:.0f} px, {p['points']:,} points"
        )
    regions = (
        ("all cells", np.ones(grid.shape, bool)),
        ("away from edges", ~near_edge),
        ("in >= 2 frames", stereo),
        ("both", stereo & ~near_edge),
    )
    for label, cells in regions:
        e = (dsm - truth)[cells]
        valid = np.isfinite(e)
        e = e[valid] / gsd
        nmad = 1.4826 * float(np.median(np.abs(e - np.median(e))))
        print(
            f"{label:>16}: completeness {100 * valid.mean():.1f} %, median error {np.median(e):+.3f} GSD, "
            f"NMAD {nmad:.3f} GSD, within 3 GSD {100 * np.mean(np.abs(e) <= 3):.1f} %"
        )


if __name__ == "__main__":
    _self_check()
