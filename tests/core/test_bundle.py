"""Bundle block adjustment: Jacobians, convergence, self-calibration, robustness, datum, errors."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.errors import CancelledError, InputError
from truortho.core.geometry import Camera, opk_to_matrix, project_points
from truortho.core.geometry.rotation import axis_angle_to_matrix
from truortho.core.orientation import GCP, Image, Orientation, SparsePoints
from truortho.core.progress import CallbackProgress
from truortho.core.sfm.bundle import (
    BundleConfig,
    BundleProblem,
    OrientationBundleConfig,
    adjust_orientation,
    adjust_with_outlier_rejection,
    bundle_adjust,
    observation_jacobians,
)
from truortho.core.sfm.similarity import estimate_similarity

CAM = Camera(3000, 2000, 2500.0, 2500.0, 1510.0, 990.0, -0.08, 0.03, 0.0, 2e-4, -1e-4)
NOISE = 0.5  # px
SELF_CAL = ("f", "cx", "cy", "k1", "k2")


def _block(seed=0, n_pts=500):
    """12 images (3 strips x 4, two flying heights, +-6 deg tilts) over a 3-D point field."""
    rng = np.random.default_rng(seed)
    Rs, Cs = [], []
    for s in range(3):
        for k in range(4):
            h = 100.0 if (s + k) % 2 == 0 else 115.0
            Cs.append([k * 30.0 + rng.uniform(-2, 2), s * 28.0 + rng.uniform(-2, 2), h])
            Rs.append(opk_to_matrix(*rng.uniform(-6, 6, 2), rng.choice([0.0, 90.0, 180.0]), degrees=True))
    Rs, Cs = np.array(Rs), np.array(Cs)
    X = np.column_stack(
        [rng.uniform(-20, 110, n_pts), rng.uniform(-20, 75, n_pts), rng.uniform(0, 25, n_pts)]
    )
    oi, op, xy = [], [], []
    for i in range(len(Rs)):
        uv = project_points(X, Rs[i], Cs[i], CAM)
        inside = (uv[:, 0] > 0) & (uv[:, 0] < CAM.width - 1) & (uv[:, 1] > 0) & (uv[:, 1] < CAM.height - 1)
        idx = np.flatnonzero(inside)
        oi.append(np.full(len(idx), i))
        op.append(idx)
        xy.append(uv[idx])
    oi, op, xy = np.concatenate(oi), np.concatenate(op), np.concatenate(xy)
    keep = np.bincount(op, minlength=n_pts)[op] >= 2
    truth = dict(R=Rs, C=Cs, X=X, intr=CAM.params)
    xy = xy[keep] + rng.normal(0, NOISE, (int(keep.sum()), 2))
    return truth, oi[keep], op[keep], xy


def _perturbed(truth, oi, op, xy, seed=1, refine=SELF_CAL, **kw):
    rng = np.random.default_rng(seed)
    Rs = np.array(
        [axis_angle_to_matrix(rng.normal(0, np.radians(1.0) / np.sqrt(3), 3)) @ R for R in truth["R"]]
    )
    intr = truth["intr"].copy()
    intr[:2] *= 1.02
    intr[4] += 0.02
    return BundleProblem(
        intrinsics=intr[None],
        image_camera=np.zeros(len(Rs), int),
        rotations=Rs,
        centers=truth["C"] + rng.normal(0, 1.0 / np.sqrt(3), truth["C"].shape),
        points=truth["X"] + rng.normal(0, 1.0 / np.sqrt(3), truth["X"].shape),
        obs_image=oi,
        obs_point=op,
        obs_xy=xy,
        refine_intrinsics=refine,
        **kw,
    )


@pytest.fixture(scope="module")
def block():
    return _block()


# ------------------------------------------------------------------ Jacobians


def test_jacobians_match_central_differences():
    rng = np.random.default_rng(5)
    for trial in range(20):
        p = np.array(
            [
                rng.uniform(800, 3000),
                0,
                rng.uniform(400, 600),
                rng.uniform(300, 500),
                rng.normal(0, 0.1),
                rng.normal(0, 0.05),
                rng.normal(0, 0.02),
                rng.normal(0, 1e-3),
                rng.normal(0, 1e-3),
            ]
        )
        p[1] = p[0] * rng.uniform(0.98, 1.02)
        R = axis_angle_to_matrix(rng.normal(0, 1, 3))
        C = rng.normal(0, 10, 3)
        X = C + R.T @ np.array([rng.uniform(-0.6, 0.6), rng.uniform(-0.5, 0.5), 1.0]) * rng.uniform(5, 50)
        obs = rng.uniform(0, 1000, 2)
        r0, Jc, Jp, valid = observation_jacobians(
            X[None], R[None], C[None], p[None], [0], [0], [0], obs[None]
        )
        assert valid[0]

        def res(X_=X, R_=R, C_=C, p_=p, obs=obs):
            return observation_jacobians(X_[None], R_[None], C_[None], p_[None], [0], [0], [0], obs[None])[0][
                0
            ]

        num = np.zeros((2, 17))
        for k in range(3):
            e = np.zeros(3)
            h = 1e-6
            e[k] = h
            num[:, k] = (res(R_=axis_angle_to_matrix(e) @ R) - res(R_=axis_angle_to_matrix(-e) @ R)) / (2 * h)
            h = 1e-5 * max(1.0, np.abs(X - C).max())
            e[k] = h
            num[:, 3 + k] = (res(C_=C + e) - res(C_=C - e)) / (2 * h)
            num[:, 14 + k] = (res(X_=X + e) - res(X_=X - e)) / (2 * h)
        # the residual is linear in every intrinsic: large steps avoid round-off
        for k, (idx, h) in enumerate(
            [(0, 1.0), (2, 1.0), (3, 1.0), (4, 1e-2), (5, 1e-2), (6, 1e-2), (7, 1e-2), (8, 1e-2)]
        ):
            pp, pm = p.copy(), p.copy()
            pp[idx] += h
            pm[idx] -= h
            if idx == 0:  # "f": fy follows fx at a fixed ratio
                pp[1] = p[1] * pp[0] / p[0]
                pm[1] = p[1] * pm[0] / p[0]
            num[:, 6 + k] = (res(p_=pp) - res(p_=pm)) / (2 * h)
        ana = np.concatenate([Jc[0], Jp[0]], axis=1)
        scale = np.maximum(np.abs(num).max(axis=0), 1e-300)
        rel = np.abs(ana - num).max(axis=0) / scale
        assert rel.max() < 1e-5, f"trial {trial}: column errors {np.round(rel, 9)}"


# ------------------------------------------------------------------ adjustment


def _aligned_center_errors(res, truth):
    sim = estimate_similarity(res.centers, truth["C"])
    return np.linalg.norm(sim.apply(res.centers) - truth["C"], axis=1)


def test_synthetic_block_converges_and_self_calibrates(block):
    truth, oi, op, xy = block
    pb = _perturbed(truth, oi, op, xy)
    res = bundle_adjust(pb, BundleConfig(max_iterations=60))
    assert res.converged, res.reason
    assert res.reason in ("cost", "step", "gradient")
    assert abs(res.sigma0 - NOISE) < 0.15 * NOISE, res.sigma0
    # rms of a 2-D residual ~ sqrt(2) * noise * sqrt(redundancy / n)
    assert 0.55 < res.rms < 0.75
    assert res.cost_history[-1] < res.cost_history[0]
    assert len(res.iteration_times) == res.n_iterations
    # centres: free network -> compare after a similarity. Tolerance: 3 x the largest posterior
    # centre std of the minimal-constraint datum (which bounds the std after the similarity,
    # the S-transformation to the best-fitting datum only lowers it); that std is ~6 cm here
    # (GSD 4-5 cm x 0.5 px noise, extrapolated over 100 m from the held image).
    err = _aligned_center_errors(res, truth)
    std_c = np.nanmax(res.pose_std[:, 3:])
    assert std_c < 0.1 and err.max() < 3 * std_c, (err.max(), std_c)
    # intrinsics: within 5 posterior sigmas of the truth and close in absolute terms
    std = res.intrinsics_std[0]
    d = res.intrinsics[0] - truth["intr"]
    for name, k in (("fx", 0), ("cx", 2), ("cy", 3), ("k1", 4), ("k2", 5)):
        assert np.isfinite(std[k]) and abs(d[k]) < 5 * std[k], (name, d[k], std[k])
    assert abs(d[0]) / truth["intr"][0] < 3e-3 and abs(d[4]) < 3e-3
    assert np.isnan(std[6]) and res.intrinsics[0, 6] == pb.intrinsics[0, 6]  # k3 held
    assert abs(res.intrinsics[0, 1] / res.intrinsics[0, 0] - truth["intr"][1] / truth["intr"][0]) < 1e-12


def test_sparse_solver_matches_dense(block):
    truth, oi, op, xy = block
    a = bundle_adjust(_perturbed(truth, oi, op, xy), BundleConfig(linear_solver="dense"))
    b = bundle_adjust(_perturbed(truth, oi, op, xy), BundleConfig(linear_solver="sparse"))
    assert b.converged
    assert np.abs(a.centers - b.centers).max() < 1e-4
    assert abs(a.sigma0 - b.sigma0) < 1e-6


@pytest.mark.parametrize("loss", ["huber", "cauchy"])
def test_gross_outliers_with_robust_loss(block, loss):
    truth, oi, op, xy = block
    rng = np.random.default_rng(7)
    xy = xy.copy()
    bad = rng.choice(len(xy), int(0.02 * len(xy)), replace=False)
    xy[bad] += rng.uniform(15, 60, (len(bad), 2)) * rng.choice([-1, 1], (len(bad), 2))
    pb = _perturbed(truth, oi, op, xy)
    res = bundle_adjust(pb, BundleConfig(loss=loss, loss_scale=1.0, max_iterations=80))
    assert res.converged, res.reason
    assert _aligned_center_errors(res, truth).max() < 0.25
    assert abs(res.intrinsics[0, 0] / truth["intr"][0] - 1) < 3e-3
    assert res.weights[bad].max() < 0.2
    assert abs(res.sigma0_mad - NOISE) < 0.15 * NOISE
    # rejection then a plain least-squares re-run: every gross error found, sigma0 back to the noise
    clean = adjust_with_outlier_rejection(
        _perturbed(truth, oi, op, xy), BundleConfig(loss=loss), reference="mad"
    )
    assert set(bad) <= set(np.flatnonzero(clean.removed))
    assert clean.n_removed < 1.3 * len(bad)
    assert abs(clean.sigma0 - NOISE) < 0.15 * NOISE


def test_control_points_fix_the_datum(block):
    truth, oi, op, xy = block
    X = truth["X"]
    nobs = np.bincount(op, minlength=len(X))
    corners = [
        int(np.argmin(np.where(nobs >= 3, (X[:, 0] - cx) ** 2 + (X[:, 1] - cy) ** 2, np.inf)))
        for cx, cy in ((0, 0), (90, 0), (0, 55), (90, 55))
    ]
    pb = _perturbed(
        truth,
        oi,
        op,
        xy,
        point_prior_index=corners,
        point_prior_xyz=X[corners],
        point_prior_sigma=np.full((4, 3), 0.01),
    )
    res = bundle_adjust(pb)
    assert res.converged and "priors" in res.gauge
    err = np.linalg.norm(res.centers - truth["C"], axis=1)  # no similarity: the true frame
    assert err.max() < 0.15, err.max()
    assert np.linalg.norm(res.points[corners] - X[corners], axis=1).max() < 0.03
    assert abs(res.sigma0 - NOISE) < 0.15 * NOISE


def test_cancel_raises(block):
    truth, oi, op, xy = block
    calls = []
    prog = CallbackProgress(lambda f, m: calls.append(f), lambda: len(calls) >= 2)
    with pytest.raises(CancelledError):
        bundle_adjust(_perturbed(truth, oi, op, xy), progress=prog)


def test_bad_input_is_reported(block):
    truth, oi, op, xy = block
    with pytest.raises(InputError, match="missing point"):
        bundle_adjust(_perturbed(truth, oi, np.where(np.arange(len(op)) == 3, 10**6, op), xy))
    bad_xy = xy.copy()
    bad_xy[5, 1] = np.nan
    with pytest.raises(InputError, match="obs_xy has non-finite values"):
        bundle_adjust(_perturbed(truth, oi, op, bad_xy))
    with pytest.raises(InputError, match="unknown name.*focal"):
        bundle_adjust(_perturbed(truth, oi, op, xy, refine=("f", "focal")))
    with pytest.raises(InputError, match="loss"):
        bundle_adjust(_perturbed(truth, oi, op, xy), BundleConfig(loss="tukey"))


def test_adjust_orientation_round_trip(block):
    truth, oi, op, xy = block
    pb = _perturbed(truth, oi, op, xy)
    cam = Camera.from_params(pb.intrinsics[0], CAM.width, CAM.height, id="cam")
    images = [Image(f"img{i}.jpg", "cam", pb.rotations[i], pb.centers[i]) for i in range(len(pb.rotations))]
    ori = Orientation(
        cameras={"cam": cam},
        images=images,
        points=SparsePoints(pb.points, obs_point=op, obs_image=oi, obs_xy=xy),
    )
    g = int(np.argmax(np.bincount(op)))
    ori.gcps = [
        GCP(
            "g1",
            truth["X"][g],
            role="check",
            observations=[(f"img{i}.jpg", *xy[k]) for k, i in enumerate(oi) if op[k] == g],
        )
    ]
    new, res = adjust_orientation(ori, OrientationBundleConfig(refine_intrinsics={"cam": SELF_CAL}))
    assert res.converged and abs(res.sigma0 - NOISE) < 0.15 * NOISE
    assert len(res.points) == len(pb.points) + 1  # tie points then the check point
    np.testing.assert_allclose(new.images[3].C, res.centers[3])
    np.testing.assert_allclose(new.points.xyz, res.points[:-1])
    assert abs(new.cameras["cam"].fx - res.intrinsics[0, 0]) < 1e-9
    assert np.nanmax(new.points.error) < 5.0
