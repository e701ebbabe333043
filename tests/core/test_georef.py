"""Datum from GCPs, check points, GNSS priors on a synthetic block."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.errors import InputError
from truortho.core.geometry import Camera, project_points
from truortho.core.orientation import GCP
from truortho.core.sfm.georef import block_from_reconstruction, georeference, validate_gcps
from truortho.core.sfm.incremental import reconstruct

OFFSET = np.array([500000.0, 5600000.0, 200.0])


@pytest.fixture(scope="module")
def block_and_truth():
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from test_incremental import synthetic_tracks

    cam, Rs, Cs, X, tr, im, xy = synthetic_tracks(seed=3)
    prior = Camera(cam.width, cam.height, 1050.0, 1050.0, 599.5, 399.5)
    rec = reconstruct(tr, im, xy, np.zeros(len(Rs), int), [prior])
    names = [f"img_{i}.jpg" for i in range(len(Rs))]
    rng = np.random.default_rng(5)
    gcps = []
    for k, p in enumerate(rng.uniform([0, 0, 0], [120, 90, 10], (10, 3))):
        obs = []
        for i in range(len(Rs)):
            uv = project_points(p[None], Rs[i], Cs[i], cam)[0]
            if 0 < uv[0] < cam.width - 1 and 0 < uv[1] < cam.height - 1:
                obs.append((names[i], *(uv + rng.normal(0, 0.5, 2))))
        gcps.append(GCP(f"g{k}", p + OFFSET, "check" if k % 5 in (1, 3) else "gcp", None, obs))
    return rec, (tr, im, xy), names, prior, Rs, Cs, gcps


def test_gcps_fix_datum_and_check_points_are_accurate(block_and_truth):
    rec, (tr, im, xy), names, prior, Rs, Cs, gcps = block_and_truth
    block, _ = block_from_reconstruction(rec, tr, im, xy, names, [prior], np.zeros(len(names), int))
    res = georeference(block, gcps, OFFSET)
    assert res.method == "gcp", res.warnings
    # GSD = 120 m / 1000 px = 0.12 m; checks within 1 GSD in plan, 1.5 in height
    assert res.check_rmse["n"] == 4
    assert res.check_rmse["xy"] < 0.12 and res.check_rmse["z"] < 0.18, res.check_rmse
    d = block.centers - Cs[rec.registered]
    # In a nadir-only block over low relief the self-calibrated principal point and focal length
    # correlate with the centres (shift = height x pp error / f): centres within 2 GSD in plan and
    # 4 GSD in height, while ground points (the check points above) stay within 1 GSD.
    assert np.abs(d[:, :2]).max() < 0.24, d
    assert np.abs(d[:, 2]).max() < 0.5, d
    assert res.bundle.sigma0 < 1.0


def test_gps_priors_when_no_gcps(block_and_truth):
    rec, (tr, im, xy), names, prior, Rs, Cs, _ = block_and_truth
    block, _ = block_from_reconstruction(rec, tr, im, xy, names, [prior], np.zeros(len(names), int))
    rng = np.random.default_rng(1)
    gps = Cs[rec.registered] + rng.normal(0, [1.0, 1.0, 2.0], (int(rec.registered.sum()), 3))
    res = georeference(block, [], OFFSET, gps_centers=gps)
    assert res.method == "gps"
    err = np.linalg.norm(block.centers - Cs[rec.registered], axis=1)
    assert np.median(err) < 2.0


def test_unusable_gcps_are_reported(block_and_truth):
    rec, (tr, im, xy), names, prior, Rs, Cs, gcps = block_and_truth
    block, _ = block_from_reconstruction(rec, tr, im, xy, names, [prior], np.zeros(len(names), int))
    few = [GCP(g.name, g.xyz, "gcp", None, g.observations[:1]) for g in gcps[:4]]
    res = georeference(block, few, OFFSET)
    assert res.method == "none"
    assert any("at least 2" in w for w in res.warnings)
    assert validate_gcps([GCP("x", OFFSET, "gcp")], set(names)) == ["GCP x has no image observations"]
    with pytest.raises(InputError, match="unknown images"):
        validate_gcps([GCP("y", OFFSET, "gcp", None, [("nope.jpg", 1.0, 2.0)])], set(names))


def test_wrong_gcp_measurement_is_rejected(block_and_truth):
    rec, (tr, im, xy), names, prior, Rs, Cs, gcps = block_and_truth
    block, _ = block_from_reconstruction(rec, tr, im, xy, names, [prior], np.zeros(len(names), int))
    g = next(g for g in gcps if g.role == "gcp" and len(g.observations) >= 4)
    bad_name, x, y = g.observations[1]
    g_bad = GCP(
        g.name,
        g.xyz,
        "gcp",
        None,
        [*g.observations[:1], (bad_name, x + 150.0, y - 90.0), *g.observations[2:]],
    )
    res = georeference(block, [g_bad if h is g else h for h in gcps], OFFSET)
    assert any(f"measurement on {bad_name} rejected" in w for w in res.warnings), res.warnings
    assert res.check_rmse["xy"] < 0.12


def test_plan_only_control_is_levelled(block_and_truth):
    """Plan-only control (huge sigma_z, e.g. heights all 0 in the file) still gives plan accuracy."""
    rec, (tr, im, xy), names, prior, Rs, Cs, gcps = block_and_truth
    block, _ = block_from_reconstruction(rec, tr, im, xy, names, [prior], np.zeros(len(names), int))
    plan = [GCP(g.name, g.xyz, g.role, [0.02, 0.02, 50.0], g.observations) for g in gcps]
    res = georeference(block, plan, OFFSET)
    assert res.method == "gcp" and any("levelled" in w for w in res.warnings)
    assert res.check_rmse["xy"] < 0.12, res.check_rmse
    assert np.all(block.centers[:, 2] > 100)  # cameras above the ground, not flipped
