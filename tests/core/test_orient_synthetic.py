"""Issue acceptance: orientation of the synthetic nadir + oblique block with GCPs and check points."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.formats.gcplist import read_gcp_list
from truortho.core.sfm.pipeline import OrientConfig, orient_images
from truortho.core.synthetic import SceneConfig, make_scene


@pytest.fixture(scope="module")
def synthetic_block(tmp_path_factory):
    # nadir block (80/60) + 8 obliques; 14 GCPs seen in >= 4 images, 40 % of them check points;
    # 0.5 px noise on the GCP image measurements (tie points carry the matching noise)
    cfg = SceneConfig(
        n_oblique=8, n_gcps=14, min_gcp_views=4, check_fraction=0.4, gcp_pixel_sigma=0.5, seed=3
    )
    scene = make_scene(cfg)
    folder = tmp_path_factory.mktemp("block")
    scene.write(folder)
    return scene, folder


def test_orientation_accuracy_with_gcps(synthetic_block, tmp_path):
    scene, folder = synthetic_block
    gsd = scene.config.flying_height / scene.config.focal_px
    crs, gcps = read_gcp_list(folder / "gcp_list.txt")
    truth = {g.name: g for g in scene.orientation.gcps}
    for g in gcps:
        g.role = truth[g.name].role
    assert sum(g.role == "check" for g in gcps) >= 3
    paths = sorted(str(p) for p in folder.glob("img_*.png"))
    run = orient_images(paths, gcps=gcps, crs=crs, config=OrientConfig(working_size=640), work_dir=tmp_path)
    o = run.orientation
    rep = run.report.data
    print("summary", run.report.summary)
    print("check RMSE", rep["check_rmse"], "GSD", gsd)
    assert len(o.images) == len(paths)
    c = rep["check_rmse"]
    assert c["n"] >= 3
    assert c["xy"] <= 1.0 * gsd and c["z"] <= 1.5 * gsd
    # camera centres against the ground truth (world coordinates)
    true_c = {im.name: scene.orientation.frame.to_world(im.C) for im in scene.orientation.images}
    d = np.array([o.frame.to_world(im.C) - true_c[im.name] for im in o.images])
    print("max centre error", np.abs(d).max(axis=0))
    assert np.linalg.norm(d, axis=1).max() <= 1.0 * gsd
    assert rep["bundle"]["sigma0"] < 1.0
    assert run.report.to_html().count("<img") >= 3


def test_bad_inputs(tmp_path):
    from truortho.core.errors import InputError

    (tmp_path / "notes.txt").write_text("not an image")
    with pytest.raises(InputError, match="at least two images"):
        orient_images([tmp_path / "notes.txt"])
