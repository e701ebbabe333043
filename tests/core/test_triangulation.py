"""Triangulation of tracks and the 7-parameter similarity."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.errors import GeometryError, InputError
from truortho.core.geometry import Camera, opk_to_matrix, project_points, undistort_points
from truortho.core.geometry.rotation import quaternion_to_matrix
from truortho.core.sfm.similarity import estimate_similarity
from truortho.core.sfm.triangulation import triangulate_tracks


def test_triangulation_recovers_points_with_noise():
    rng = np.random.default_rng(0)
    cam = Camera(1000, 800, 900.0, 900.0, 499.5, 399.5, -0.05, 0.01)
    Rs, Cs = [], []
    for i in range(5):
        Rs.append(opk_to_matrix(*rng.uniform(-4, 4, 3), degrees=True))
        Cs.append([i * 15.0, rng.uniform(-2, 2), 100.0])
    Rs, Cs = np.array(Rs), np.array(Cs)
    X = np.column_stack([rng.uniform(0, 60, 300), rng.uniform(-20, 20, 300), rng.uniform(0, 10, 300)])
    offsets, img, xy = [0], [], []
    for p in X:
        for i in range(5):
            uv = project_points(p[None], Rs[i], Cs[i], cam) + rng.normal(0, 0.3, 2)
            xy.append(undistort_points(uv, cam)[0])
            img.append(i)
        offsets.append(len(img))
    res = triangulate_tracks(np.array(offsets), np.array(img), np.array(xy), Rs, Cs, np.full(5, 900.0))
    assert res.ok.all()
    err = np.linalg.norm(res.xyz - X, axis=1)
    # 0.3 px at ~100 m with f = 900 px: 3 cm across, ~10 cm in depth for this base
    assert np.median(err) < 0.1 and err.max() < 0.5
    assert np.all(res.max_error < 1.5)
    assert np.all(res.angle > np.radians(20))


def test_point_behind_a_camera_is_not_ok():
    Rs = np.array([np.eye(3), np.eye(3)])
    Cs = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    # rays that intersect behind the cameras (z < 0)
    xy = np.array([[0.1, 0.0], [0.2, 0.0]])
    res = triangulate_tracks(np.array([0, 2]), np.array([0, 1]), xy, Rs, Cs)
    assert not res.ok[0]


def test_single_observation_track_fails_cleanly():
    res = triangulate_tracks(
        np.array([0, 1]), np.array([0]), np.zeros((1, 2)), np.eye(3)[None], np.zeros((1, 3))
    )
    assert not res.ok[0] and np.isnan(res.xyz[0]).all()
    with pytest.raises(InputError):
        triangulate_tracks(
            np.array([0, 5]), np.array([0]), np.zeros((1, 2)), np.eye(3)[None], np.zeros((1, 3))
        )


def test_similarity_exact_and_coplanar():
    rng = np.random.default_rng(1)
    q = rng.normal(size=4)
    R = quaternion_to_matrix(q)
    src = rng.uniform(-50, 50, (10, 3))
    src[:, 2] = 0.0  # coplanar control (e.g. heights all 0)
    dst = 2.5 * src @ R.T + [1000.0, -300.0, 42.0]
    sim = estimate_similarity(src, dst)
    np.testing.assert_allclose(sim.apply(src), dst, atol=1e-8)
    assert sim.scale == pytest.approx(2.5)
    np.testing.assert_allclose(sim.inverse().apply(dst), src, atol=1e-8)
    with pytest.raises(GeometryError):
        estimate_similarity(np.outer(np.arange(5.0), [1, 1, 0]), np.outer(np.arange(5.0), [1, 0, 0]))
    with pytest.raises(InputError):
        estimate_similarity(src[:2], dst[:2])
