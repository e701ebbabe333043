"""Camera model and rotations against OpenCV and closed-form references."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from truortho.core.errors import InputError
from truortho.core.geometry import (
    Camera,
    LocalFrame,
    axis_angle_to_matrix,
    matrix_to_axis_angle,
    matrix_to_opk,
    matrix_to_quaternion,
    opk_to_matrix,
    pixel_to_ray,
    project_points,
    quaternion_to_matrix,
    undistort_points,
)
from truortho.core.geometry.rotation import rotation_angle_between


def random_rotation(rng) -> np.ndarray:
    q = rng.normal(size=4)
    return quaternion_to_matrix(q / np.linalg.norm(q))


@pytest.fixture
def cam() -> Camera:
    return Camera(4000, 3000, 3500.0, 3490.0, 2010.3, 1490.7, -0.12, 0.05, -0.01, 0.0007, -0.0004)


def test_projection_matches_opencv(cam):
    rng = np.random.default_rng(1)
    R = random_rotation(rng)
    C = rng.normal(size=3) * 10
    # points in front of the camera, filling the frame
    xy = rng.uniform(-0.5, 0.5, size=(5000, 2))
    z = rng.uniform(5, 50, size=5000)
    pc = np.column_stack([xy * z[:, None], z])
    X = pc @ R + C  # R^T pc + C
    uv, depth = project_points(X, R, C, cam, return_depth=True)
    rvec, _ = cv2.Rodrigues(R)
    tvec = -R @ C
    ref, _ = cv2.projectPoints(X, rvec, tvec, cam.K, cam.dist_coeffs)
    np.testing.assert_allclose(uv, ref.reshape(-1, 2), atol=1e-6)
    np.testing.assert_allclose(depth, z, rtol=1e-12)


def test_behind_camera_is_nan(cam):
    uv, depth = project_points([[0.0, 0.0, -5.0], [0.0, 0.0, 5.0]], np.eye(3), np.zeros(3), cam, True)
    assert np.isnan(uv[0]).all() and np.isfinite(uv[1]).all()
    assert depth[0] < 0


def test_undistort_inverts_distort(cam):
    rng = np.random.default_rng(2)
    # normalised coordinates covering the whole frame incl. corners
    xy = rng.uniform([-0.6, -0.45], [0.6, 0.45], size=(20000, 2))
    uv = cam.distort(xy)
    back = undistort_points(uv, cam)
    np.testing.assert_allclose(back, xy, atol=1e-10)
    # against OpenCV's iterative undistortion (less exact: 5 iterations by default)
    ref = cv2.undistortPointsIter(
        uv.reshape(-1, 1, 2),
        cam.K,
        cam.dist_coeffs,
        None,
        None,
        (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 50, 1e-12),
    ).reshape(-1, 2)
    np.testing.assert_allclose(back, ref, atol=1e-7)


def test_pixel_to_ray_round_trip(cam):
    rng = np.random.default_rng(3)
    R = random_rotation(rng)
    C = np.array([10.0, -4.0, 120.0])
    uv = rng.uniform([0, 0], [cam.width - 1, cam.height - 1], size=(1000, 2))
    origin, d = pixel_to_ray(uv, R, C, cam)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-12)
    X = origin + d * rng.uniform(1, 100, size=(1000, 1))
    np.testing.assert_allclose(project_points(X, R, C, cam), uv, atol=1e-7)


def test_scaled_camera_maps_pixel_centres(cam):
    half = cam.scaled(0.5)
    X = np.array([[0.3, -0.2, 10.0]])
    full = project_points(X, np.eye(3), np.zeros(3), cam)
    small = project_points(X, np.eye(3), np.zeros(3), half)
    np.testing.assert_allclose(small, (full + 0.5) * 0.5 - 0.5, atol=1e-9)


def test_quaternion_round_trip():
    rng = np.random.default_rng(4)
    for _ in range(500):
        R = random_rotation(rng)
        q = matrix_to_quaternion(R)
        assert q[0] >= 0
        np.testing.assert_allclose(quaternion_to_matrix(q), R, atol=1e-14)
    # half-turns (w = 0) are handled
    for axis in np.eye(3):
        R = axis_angle_to_matrix(axis * math.pi)
        np.testing.assert_allclose(quaternion_to_matrix(matrix_to_quaternion(R)), R, atol=1e-14)


def test_axis_angle_matches_opencv():
    rng = np.random.default_rng(5)
    for _ in range(300):
        r = rng.normal(size=3)
        r *= rng.uniform(0, math.pi - 1e-6) / np.linalg.norm(r)
        R = axis_angle_to_matrix(r)
        ref, _ = cv2.Rodrigues(r)
        np.testing.assert_allclose(R, ref, atol=1e-13)
        np.testing.assert_allclose(matrix_to_axis_angle(R), r, atol=1e-9)
    np.testing.assert_allclose(axis_angle_to_matrix([1e-12, 0, 0]), np.eye(3), atol=1e-11)


def test_opk_definition_and_round_trip():
    # nadir camera, kappa = 0: image x points east, image y (down) points south
    R = opk_to_matrix(0.0, 0.0, 0.0)
    np.testing.assert_allclose(R[0], [1, 0, 0], atol=1e-15)  # camera x = east
    np.testing.assert_allclose(R[1], [0, -1, 0], atol=1e-15)  # camera y (down the image) = south
    np.testing.assert_allclose(R[2], [0, 0, -1], atol=1e-15)  # looking down
    # omega = +10 deg tilts the view towards +Y? M = Rx(w): camera -z (view) -> world
    R = opk_to_matrix(10.0, 0.0, 0.0, degrees=True)
    view = R[2]
    assert view[1] > 0 and view[2] < 0
    rng = np.random.default_rng(6)
    for _ in range(500):
        a = rng.uniform([-180, -89, -180], [180, 89, 180])
        R = opk_to_matrix(*a, degrees=True)
        np.testing.assert_allclose(matrix_to_opk(R, degrees=True), a, atol=1e-9)
    # gimbal lock gives an equivalent rotation
    R = opk_to_matrix(0.3, math.pi / 2, 0.2)
    assert rotation_angle_between(opk_to_matrix(*matrix_to_opk(R)), R) < 1e-12


def test_local_frame():
    f = LocalFrame("EPSG:32632", [500000.0, 5600000.0, 100.0])
    p = np.array([[500123.456789, 5600987.654321, 234.5]])
    np.testing.assert_array_equal(f.to_world(f.to_local(p)), p)


@pytest.mark.parametrize(
    "kwargs",
    [dict(fx=-1.0), dict(width=0), dict(k1=float("nan")), dict(fy="abc"), dict(height=2.5)],
)
def test_bad_camera(kwargs):
    base = dict(width=100, height=80, fx=100.0, fy=100.0, cx=50.0, cy=40.0)
    base.update(kwargs)
    with pytest.raises(InputError):
        Camera(**base)
