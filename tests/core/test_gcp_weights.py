"""GCP image measurements carry their own sigma (GCP.obs_sigma) into the bundle as weights."""

from __future__ import annotations

import json

import numpy as np
import pytest

from truortho.core.errors import FormatError, InputError
from truortho.core.geometry import Camera, project_points
from truortho.core.orientation import GCP, Image, Orientation
from truortho.core.sfm.georef import block_from_reconstruction, georeference
from truortho.core.sfm.incremental import reconstruct

OFFSET = np.array([500000.0, 5600000.0, 200.0])


@pytest.fixture(scope="module", params=[5, 7])
def block_and_gcps(request):
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from test_incremental import synthetic_tracks

    cam, Rs, Cs, X, tr, im, xy = synthetic_tracks(seed=3)
    prior = Camera(cam.width, cam.height, 1050.0, 1050.0, 599.5, 399.5)
    rec = reconstruct(tr, im, xy, np.zeros(len(Rs), int), [prior])
    names = [f"img_{i}.jpg" for i in range(len(Rs))]
    block, _ = block_from_reconstruction(rec, tr, im, xy, names, [prior], np.zeros(len(names), int))
    rng = np.random.default_rng(request.param)
    noisy = []
    for k, p in enumerate(rng.uniform([0, 0, 0], [120, 90, 10], (10, 3))):
        obs_n, s = [], {}
        role = "check" if k % 5 in (1, 3) else "gcp"
        for i in range(len(Rs)):
            uv = project_points(p[None], Rs[i], Cs[i], cam)[0]
            if 0 < uv[0] < cam.width - 1 and 0 < uv[1] < cam.height - 1:
                # every other measurement of a control point is poor (3 px noise), the rest good
                # (0.1 px); check points are measured well, so they show the datum's quality
                poor = role == "gcp" and len(obs_n) % 2 == 1
                e = rng.normal(0, 3.0 if poor else 0.1, 2)
                obs_n.append((names[i], *(uv + e)))
                s[names[i]] = 3.0 if poor else 0.1
        noisy.append((f"g{k}", p + OFFSET, role, obs_n, s))
    return block, noisy


def test_measurement_sigmas_weight_the_bundle(block_and_gcps):
    """Same measurements: with their sigmas the check points come out better than with one default."""
    import copy

    block, noisy = block_and_gcps
    flat = [GCP(n, xyz, role, None, obs) for n, xyz, role, obs, _ in noisy]
    weighted = [GCP(n, xyz, role, None, obs, s) for n, xyz, role, obs, s in noisy]
    r_flat = georeference(copy.deepcopy(block), flat, OFFSET)
    r_w = georeference(copy.deepcopy(block), weighted, OFFSET)
    assert r_flat.method == r_w.method == "gcp"
    e_flat = np.hypot(r_flat.check_rmse["xy"], r_flat.check_rmse["z"])
    e_w = np.hypot(r_w.check_rmse["xy"], r_w.check_rmse["z"])
    print(f"check RMSE: one default sigma {e_flat:.4f} m, measurement sigmas {e_w:.4f} m")
    assert e_w < 0.5 * e_flat, (e_w, e_flat)


def test_obs_sigma_validation_and_json_round_trip(tmp_path):
    g = GCP(
        "g",
        [1.0, 2.0, 3.0],
        observations=[("a.jpg", 1.0, 2.0), ("b.jpg", 3.0, 4.0)],
        obs_sigma={"a.jpg": 0.2},
    )
    cam = Camera(100, 80, 90.0, 90.0, 49.5, 39.5, id="cam")
    images = [Image(n, "cam", np.eye(3), [0.0, 0.0, 10.0]) for n in ("a.jpg", "b.jpg")]
    o = Orientation(cameras={"cam": cam}, images=images, gcps=[g])
    o.save(tmp_path / "o.json")
    d = json.loads((tmp_path / "o.json").read_text())
    assert d["gcps"][0]["observations"][0]["sigma"] == 0.2 and "sigma" not in d["gcps"][0]["observations"][1]
    back = Orientation.load(tmp_path / "o.json")
    assert back.gcps[0].obs_sigma == {"a.jpg": 0.2}
    for bad in (0.0, -1.0, float("nan"), "x"):
        with pytest.raises(InputError, match="sigma on image 'a.jpg'"):
            GCP("g", [1.0, 2.0, 3.0], obs_sigma={"a.jpg": bad})
    d["gcps"][0]["observations"][0]["sigma"] = -0.5
    (tmp_path / "bad.json").write_text(json.dumps(d))
    with pytest.raises(FormatError, match="sigma"):
        Orientation.load(tmp_path / "bad.json")
