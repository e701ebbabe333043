"""Issue acceptance: orientation of the synthetic nadir + oblique block with GCPs and check points."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.errors import CRSError, InputError
from truortho.core.formats.gcplist import read_gcp_list
from truortho.core.orientation import GCP
from truortho.core.sfm.pipeline import OrientConfig, orient_images, stage_weights
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


class _Recorder:
    def __init__(self, fractions):
        self.fractions = fractions

    def update(self, fraction, message=None):
        self.fractions.append(float(fraction))

    def cancelled(self):
        return False


def test_stage_weights_follow_the_block():
    # the 406-photo scale block: features 4.5 min, matching 6,915 pairs in 19 min, the rest 4 min
    w = np.array(stage_weights(406, 6915))
    share = w / w.sum()
    assert share[1] == pytest.approx(19 / 27.5, abs=0.05)
    assert share[0] == pytest.approx(4.5 / 27.5, abs=0.05)
    # more pairs per image: matching takes more of the bar; a pair-free block still progresses
    assert (lambda v: v[1] / v.sum())(np.array(stage_weights(40, 780))) > share[1]
    assert all(x > 0 for x in stage_weights(1, 0))


def test_orientation_accuracy_with_gcps(synthetic_block, tmp_path):
    scene, folder = synthetic_block
    gsd = scene.config.flying_height / scene.config.focal_px
    crs, gcps = read_gcp_list(folder / "gcp_list.txt")
    truth = {g.name: g for g in scene.orientation.gcps}
    for g in gcps:
        g.role = truth[g.name].role
    assert sum(g.role == "check" for g in gcps) >= 3
    paths = sorted(str(p) for p in folder.glob("img_*.png"))
    # bad input that must only cost a warning: a non-image file among the images, a GCP without
    # observations, an observation on an image that is not in the block
    (folder / "flight_log.txt").write_text("not an image")
    gcps.append(GCP("lonely", gcps[0].xyz + 5.0, "gcp"))
    check = next(g for g in gcps if g.role == "check")
    check.observations.append(("not_in_block.png", 10.0, 20.0))
    fractions: list[float] = []
    run = orient_images(
        paths + [str(folder / "flight_log.txt")],
        gcps=gcps,
        crs=crs,
        config=OrientConfig(working_size=640),
        work_dir=tmp_path,
        progress=_Recorder(fractions),
    )
    # the progress only moves forward, through every stage, to the end
    assert fractions and np.all(np.diff(fractions) >= -1e-9) and fractions[-1] == pytest.approx(1.0)
    o = run.orientation
    rep = run.report.data
    print("summary", run.report.summary)
    print("check RMSE", rep["check_rmse"], "GSD", gsd)
    warnings = " | ".join(run.report.warnings)
    assert "skipped flight_log.txt" in warnings
    assert "GCP lonely has no image observations" in warnings
    assert f"GCP {check.name}: observation on image 'not_in_block.png'" in warnings
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
    from PIL import Image

    (tmp_path / "notes.txt").write_text("not an image")
    with pytest.raises(InputError, match="at least two images"):
        orient_images([tmp_path / "notes.txt"])
    # one image and a non-image file: still fewer than two images
    rng = np.random.default_rng(0)
    noise = []
    for k in range(3):
        p = tmp_path / f"noise{k}.png"
        Image.fromarray(rng.integers(0, 255, (240, 320, 3), dtype=np.uint8)).save(p)
        noise.append(p)
    with pytest.raises(InputError, match="at least two images are needed, found 1 readable"):
        orient_images([noise[0], tmp_path / "notes.txt"])
    # images that do not overlap
    with pytest.raises(InputError, match="do not overlap"):
        orient_images(noise, config=OrientConfig(working_size=320, max_features=500), work_dir=tmp_path)
    g = GCP("g1", [500000.0, 5600000.0, 100.0], "gcp", None, [("noise0.png", 10.0, 10.0)])
    # ground control in a geographic CRS (a GCP layer in degrees), or without any CRS
    with pytest.raises(CRSError, match="geographic"):
        orient_images(noise, gcps=[g], crs="EPSG:4326")
    with pytest.raises(InputError, match="GCPS: ground control needs a CRS"):
        orient_images(noise, gcps=[g])
    # a GCP whose observations all name images that are not given
    bad = GCP("g2", [500000.0, 5600000.0, 100.0], "gcp", None, [("elsewhere.jpg", 1.0, 2.0)])
    with pytest.raises(InputError, match="GCP g2: its observations refer only to unknown images"):
        orient_images(noise, gcps=[bad], crs="EPSG:32632")
