"""Orientation of ../shared/data/fountain-P11 against its ground-truth cameras (with and without K)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from truortho.core.geometry.rotation import rotation_angle_between
from truortho.core.sfm.pipeline import OrientConfig, orient_images
from truortho.core.sfm.similarity import estimate_similarity

DATA = Path(os.environ["TRUORTHO_DATA"]) / "fountain-P11"
pytestmark = pytest.mark.skipif(not DATA.exists(), reason="shared data not available")


def ground_truth() -> dict:
    gt = {}
    for f in sorted((DATA / "gt_dense_cameras").glob("*.camera")):
        v = np.array(f.read_text().split(), dtype=float)
        # R is camera-to-world (columns = camera axes in world); ours is world-to-camera
        gt[f.name.replace(".camera", "")] = (v[12:21].reshape(3, 3).T, v[21:24])
    return gt


@pytest.mark.parametrize("with_k", [False, True], ids=["self-calibrated", "K.txt"])
def test_fountain_orientation(with_k, tmp_path):
    paths = sorted(str(p) for p in (DATA / "images").glob("*.jpg"))
    camera = str(DATA / "images" / "K.txt") if with_k else None
    run = orient_images(paths, camera_file=camera, config=OrientConfig(working_size=1200), work_dir=tmp_path)
    o = run.orientation
    assert len(o.images) == 11
    gt = ground_truth()
    C = np.array([im.C for im in o.images])
    Cg = np.array([gt[im.name][1] for im in o.images])
    sim = estimate_similarity(C, Cg)
    rmse = float(np.sqrt(np.mean(np.sum((sim.apply(C) - Cg) ** 2, axis=1))))
    rot = np.degrees([rotation_angle_between(im.R @ sim.R.T, gt[im.name][0]) for im in o.images])
    f = next(iter(o.cameras.values())).fx
    print(
        f"fountain {'K' if with_k else 'self-cal'}: centre RMSE {rmse * 1000:.1f} mm, rotation error mean "
        f"{rot.mean():.3f} max {rot.max():.3f} deg, fx {f:.1f} px (truth 2759.5)"
    )
    # the scene spans ~15 m; pycolmap shows ~0.5 deg rotation error here
    assert rmse < 0.01
    assert rot.max() < 0.3
    assert abs(f - 2759.5) < 10
