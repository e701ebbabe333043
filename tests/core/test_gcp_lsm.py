"""Least-squares matching and MGCM (core/gcp/lsm.py) against synthetic truth."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from truortho.core.errors import InputError
from truortho.core.gcp.lsm import (
    LsmConfig,
    MgcmView,
    extract_template,
    extract_templates,
    lsm_match,
    lsm_match_many,
    mgcm,
    plane_shape,
    plane_shapes,
)
from truortho.core.geometry import project_points
from truortho.core.synthetic.cameras import look_at_rotation, make_camera, nadir_rotation
from truortho.core.synthetic.targets import disc_pattern, render_homography, render_on_plane


def _warp(rng, centre, scale, persp=0.0):
    th = rng.uniform(0, np.pi)
    A = scale * np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    A = A @ np.array([[1.0, rng.uniform(-0.1, 0.1)], [0.0, 1.0 + rng.uniform(-0.2, 0.2)]])
    H = np.eye(3)
    H[:2, :2] = A
    H[:2, 2] = centre - A @ np.array([40.0, 40.0])
    H[2, :2] = rng.uniform(-persp, persp, 2)
    q = H @ np.array([40.0, 40.0, 1.0])
    return H, q[:2] / q[2]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_disc_target_from_3px_off(seed):
    """An ideal disc template finds the target centre to < 0.1 px RMS from starts 3 px off,
    under affine distortion, a little perspective, gain/offset and noise."""
    rng = np.random.default_rng(seed)
    pat = disc_pattern(81, 25.0)
    tmpl = disc_pattern(23, 25.0 * 0.3)
    errs, sig = [], []
    for _ in range(8):
        H, truth = _warp(rng, np.array([60.0, 58.0]) + rng.uniform(-2, 2, 2), rng.uniform(0.25, 0.35), 2e-5)
        img = render_homography(pat, H, (120, 120)) * rng.uniform(0.4, 0.8) + rng.uniform(0.05, 0.2)
        img += rng.normal(0, 0.01, img.shape)
        ang = rng.uniform(0, 2 * np.pi)
        start = truth + 3.0 * np.array([np.cos(ang), np.sin(ang)])
        r = lsm_match(tmpl, img, *start)
        assert r.converged, r.reason
        errs.append(np.hypot(r.x - truth[0], r.y - truth[1]))
        sig.append(np.hypot(r.sigma_x, r.sigma_y))
        assert r.correlation > 0.95
    rms = float(np.sqrt(np.mean(np.square(errs))))
    assert rms < 0.1
    # the precision is of the order of the error (not a constant, not wildly off)
    assert 0.002 < float(np.mean(sig)) < 0.1


def test_projective_shaping_recovers_texture_homography():
    """A textured patch under a homography: projective shaping finds the point where affine is biased."""
    rng = np.random.default_rng(5)
    tex = cv2.GaussianBlur(rng.uniform(0, 1, (81, 81)), (0, 0), 2.5)
    H, truth = _warp(rng, np.array([60.0, 60.0]), 0.9, 2e-3)
    img = render_homography(tex, H, (120, 120)) + rng.normal(0, 0.002, (120, 120))
    tmpl = tex[40 - 12 : 40 + 13, 40 - 12 : 40 + 13]
    init = H / H[2, 2]
    start = truth + [1.5, -1.0]
    rp = lsm_match(tmpl, img, *start, LsmConfig(projective=True), initial=init)
    assert rp.converged, rp.reason
    assert np.hypot(rp.x - truth[0], rp.y - truth[1]) < 0.05


def test_failures_are_results():
    rng = np.random.default_rng(0)
    tmpl = disc_pattern(21, 6.0)
    flat = np.full((80, 80), 0.5) + rng.normal(0, 1e-3, (80, 80))
    r = lsm_match(tmpl, flat, 40.0, 40.0)
    assert not r.converged and r.reason
    r = lsm_match(tmpl, flat, 500.0, 40.0)
    assert not r.converged and "outside" in r.reason
    edge = render_homography(disc_pattern(81, 25.0), np.diag([0.3, 0.3, 1.0]), (60, 60))
    r = lsm_match(tmpl, edge, 2.0, 2.0)  # the template reaches outside the image
    assert not r.converged and r.reason
    with pytest.raises(InputError, match="odd"):
        lsm_match(np.ones((20, 21)), flat, 40.0, 40.0)
    with pytest.raises(InputError, match="contrast"):
        lsm_match(np.ones((21, 21)), flat, 40.0, 40.0)
    with pytest.raises(InputError, match="NaN"):
        lsm_match(tmpl, np.full((80, 80), np.nan), 40.0, 40.0)
    with pytest.raises(InputError):
        LsmConfig(max_shift=0.0)


@pytest.fixture(scope="module")
def block():
    rng = np.random.default_rng(3)
    cam = make_camera(320, 240, 400.0, distortion=(-0.05, 0.01, 0, 0, 0))
    tex = cv2.GaussianBlur(rng.uniform(0, 1, (400, 400)), (0, 0), 12.0)
    tex = (tex - tex.min()) / (tex.max() - tex.min())
    Xt = np.array([1.0, -0.5, 0.0])
    views = []
    for i, C in enumerate([[0, 0, 30], [8, 2, 28], [-6, 7, 31], [3, -9, 29]]):
        C = np.array(C, float)
        R = nadir_rotation(20.0) if i == 0 else look_at_rotation(C, Xt)
        img = render_on_plane(tex, 0.01, (0.0, 0.0), 0.0, R, C, cam) + rng.normal(0, 0.01, (240, 320))
        img = img * rng.uniform(0.7, 1.2) + rng.uniform(-0.1, 0.1)
        views.append(MgcmView(img, R, C, cam, f"v{i}"))
    truth = np.array([project_points(Xt[None], v.R, v.C, cam)[0] for v in views])
    return views, Xt, truth


def test_mgcm_constrained_from_3px_off(block):
    views, Xt, truth = block
    rng = np.random.default_rng(7)
    tmpl = extract_template(views[0].image, *truth[0], 10)
    errs = []
    for _ in range(4):
        # start point whose projections are about 2.5-3 px off in every view
        X0 = Xt + rng.normal(0, 0.1, 3)
        r = mgcm(tmpl, views, X0, master=0)
        assert r.converged, r.reason
        assert np.linalg.norm(r.X - Xt) < 0.02  # GSD ~ 7.5 cm
        assert np.all(r.sigma < 0.01) and np.all(r.sigma > 0)
        xy = np.array([[v.x, v.y] for v in r.views])
        errs.append(np.hypot(*(xy - truth).T))
        for v, res in zip(views, r.views, strict=True):
            np.testing.assert_allclose(
                [res.x, res.y], project_points(r.X[None], v.R, v.C, v.camera)[0], atol=1e-9
            )
    assert float(np.sqrt(np.mean(np.square(errs)))) < 0.1


def test_mgcm_bad_input_and_failure(block):
    views, Xt, truth = block
    tmpl = extract_template(views[0].image, *truth[0], 10)
    with pytest.raises(InputError, match="two views"):
        mgcm(tmpl, views[:1], Xt)
    with pytest.raises(InputError, match="X0"):
        mgcm(tmpl, views, [0.0, 1.0])
    r = mgcm(tmpl, views, Xt + [0.0, 0.0, 40.0], master=0)  # behind the cameras
    assert not r.converged and "behind" in r.reason
    with pytest.raises(InputError, match="outside"):
        extract_template(views[0].image, 2.0, 2.0, 10)
    A = plane_shape(views[0], views[0], Xt)
    np.testing.assert_allclose(A, np.eye(2), atol=1e-6)


def test_batched_matching_equals_one_by_one(block):
    """lsm_match_many, extract_templates and plane_shapes (the compiled loops of the tie-point
    refinement) give what lsm_match, extract_template and plane_shape give one at a time,
    including the failures."""
    views, Xt, truth = block
    rng = np.random.default_rng(12)
    X = Xt + np.column_stack([rng.uniform(-1.5, 1.5, (12, 2)), np.zeros(12)])
    master = views[0]
    uv_m = project_points(X, master.R, master.C, master.camera)
    centres = np.vstack([uv_m, [[2.0, 2.0]]])  # the last one reaches outside the image
    tm = extract_templates(master.image, centres, 7)
    assert np.all(np.isnan(tm[-1])) and np.all(np.isfinite(tm[:-1]))
    for k in range(len(X)):
        np.testing.assert_array_equal(tm[k], extract_template(master.image, *centres[k], 7))
    cfg = LsmConfig(coarse_sigma=0.0, max_shift=1.5, min_correlation=0.8)
    cams = [v.camera for v in views]
    Rs = np.array([v.R for v in views])
    Cs = np.array([v.C for v in views])
    for j in (1, 2, 3):
        v = views[j]
        nrm = X - master.C
        A = plane_shapes(X, nrm, np.zeros(len(X), int), np.full(len(X), j), Rs, Cs, cams)
        for k in range(len(X)):
            one = plane_shape(master, v, X[k], normal=nrm[k])
            np.testing.assert_allclose(A[k], one, rtol=1e-9, atol=1e-12)
        starts = project_points(X, v.R, v.C, v.camera) + rng.normal(0, 0.6, (len(X), 2))
        starts[0] = (-5.0, 10.0)  # outside the image
        starts[1] += 4.0  # too far for max_shift
        r = lsm_match_many(tm, v.image, starts, A, cfg, template_index=np.arange(len(X)))
        for k in range(len(X)):
            one = lsm_match(tm[k], v.image, *starts[k], cfg, initial=np.column_stack([A[k], [0, 0]]))
            assert bool(r.converged[k]) == one.converged and r.reason[k] == one.reason, (k, one.reason)
            if one.converged:
                np.testing.assert_allclose(r.xy[k], [one.x, one.y], atol=1e-9)
                np.testing.assert_allclose(r.sigma[k], [one.sigma_x, one.sigma_y], rtol=1e-6)
                assert abs(r.correlation[k] - one.correlation) < 1e-9
        assert r.converged.sum() >= len(X) // 2 and "outside" in r.reason[0] and not r.converged[1]
    with pytest.raises(InputError, match="coarse_sigma"):
        lsm_match_many(tm[:2], views[1].image, uv_m[:2], config=LsmConfig())
    with pytest.raises(InputError, match="NaN"):  # a template used that is all NaN
        lsm_match_many(tm, views[1].image, uv_m[:1], config=cfg, template_index=[len(X)])
