"""LSM refinement of tie-point observations (core/gcp/tiepoints.py) on a textured ground plane."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from truortho.core.errors import InputError
from truortho.core.gcp.tiepoints import TieRefineConfig, refine_tie_points
from truortho.core.geometry import pixel_to_ray, project_points
from truortho.core.sfm.georef import Block
from truortho.core.synthetic.cameras import look_at_rotation, make_camera, nadir_rotation
from truortho.core.synthetic.targets import render_on_plane


def test_refined_observations_match_the_master():
    rng = np.random.default_rng(11)
    cam = make_camera(320, 240, 400.0)
    tex = cv2.GaussianBlur(rng.uniform(0, 1, (800, 800)), (0, 0), 10.0)
    tex = (tex - tex.min()) / (tex.max() - tex.min())
    Cs = [np.array([0.0, 0.0, 30.0]), np.array([6.0, 1.0, 29.0]), np.array([-2.0, 6.0, 31.0])]
    Rs = [
        nadir_rotation(10.0),
        look_at_rotation(Cs[1], [0.5, 0.0, 0.0]),
        look_at_rotation(Cs[2], [0.0, 0.5, 0.0]),
    ]
    images = [
        render_on_plane(tex, 0.01, (0.0, 0.0), 0.0, R, C, cam) + rng.normal(0, 0.005, (240, 320))
        for R, C in zip(Rs, Cs, strict=True)
    ]
    X = np.column_stack([rng.uniform(-2.5, 2.5, 40), rng.uniform(-2.0, 2.0, 40), np.zeros(40)])
    obs_img, obs_pt, obs_xy = [], [], []
    for i, (R, C) in enumerate(zip(Rs, Cs, strict=True)):
        uv = project_points(X, R, C, cam)
        for k in range(len(X)):
            obs_img.append(i)
            obs_pt.append(k)
            obs_xy.append(uv[k] + rng.normal(0, 0.4, 2))  # matching noise
    obs_img, obs_pt, obs_xy = np.array(obs_img), np.array(obs_pt), np.array(obs_xy)
    block = Block(
        [f"i{i}" for i in range(3)],
        [cam],
        np.zeros(3, int),
        np.array(Rs),
        np.array(Cs),
        X,
        obs_img,
        obs_pt,
        obs_xy,
    )
    ref = refine_tie_points(block, images, np.ones((3, 2)))
    assert ref.stats["refined"] >= 0.9 * 2 * len(X)
    errs_before, errs_after = [], []
    for k in range(len(X)):
        idx = np.flatnonzero(obs_pt == k)
        master = [o for o in idx if not ref.refined[o]]
        assert len(master) >= 1  # the master keeps its observation and defines the point
        if len(master) > 1:  # a rejected match also kept its observation: master unknown here
            continue
        m = master[0]
        # the point the master observation really shows: its ray on the ground plane
        o, d = pixel_to_ray(obs_xy[m][None], Rs[obs_img[m]], Cs[obs_img[m]], cam)
        P = o + d[0] * (-o[2] / d[0, 2])
        for j in idx:
            if ref.refined[j]:
                t = project_points(P[None], Rs[obs_img[j]], Cs[obs_img[j]], cam)[0]
                errs_before.append(np.hypot(*(obs_xy[j] - t)))
                errs_after.append(np.hypot(*(ref.obs_xy[j] - t)))
                assert 0 < ref.sigma[j, 0] < 0.3
    rms_b = float(np.sqrt(np.mean(np.square(errs_before))))
    rms_a = float(np.sqrt(np.mean(np.square(errs_after))))
    assert rms_a < 0.1 and rms_a < 0.3 * rms_b, (rms_a, rms_b)


def test_bad_input():
    cam = make_camera(64, 48, 50.0)
    block = Block(["a"], [cam], np.zeros(1, int), np.eye(3)[None], np.zeros((1, 3)), np.zeros((0, 3)),
                  np.zeros(0, int), np.zeros(0, int), np.zeros((0, 2)))  # fmt: skip
    with pytest.raises(InputError, match="1 block images"):
        refine_tie_points(block, [], np.ones((1, 2)))
    with pytest.raises(InputError, match="positive"):
        refine_tie_points(block, [np.zeros((48, 64))], np.zeros((1, 2)))
    with pytest.raises(InputError):
        TieRefineConfig(half_size=1)
    assert refine_tie_points(block, [np.zeros((48, 64))], np.ones((1, 2))).stats["refined"] == 0
