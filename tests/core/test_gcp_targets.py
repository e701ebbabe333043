"""Target detection (core/gcp/targets.py) against synthetic truth."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from truortho.core.errors import InputError
from truortho.core.gcp.targets import (
    TargetConfig,
    detect_aruco,
    detect_checker,
    detect_circle,
    parse_id_mapping,
)
from truortho.core.synthetic.targets import checker_pattern, disc_pattern, render_homography


def _similarity(rng, ctr, centre_pattern, scale, squeeze=1.0):
    th = rng.uniform(0, 2 * np.pi)
    A = scale * np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]]) @ np.diag([1.0, squeeze])
    H = np.eye(3)
    H[:2, :2] = A
    H[:2, 2] = ctr - A @ np.array([centre_pattern, centre_pattern])
    return H


def aruco_scene(seed: int, ids=(0, 1, 2), shape=(300, 460)):
    """Markers (10 px modules, one white module of margin) pasted with a homography on texture."""
    rng = np.random.default_rng(seed)
    d = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50)
    img = cv2.GaussianBlur(rng.uniform(0.3, 0.7, shape), (0, 0), 4)
    truth = {}
    for k, mid in enumerate(ids):
        m = cv2.aruco.generateImageMarker(d, mid, 60, borderBits=1).astype(float) / 255
        pat = np.pad(m, 10, constant_values=1.0)
        c = (pat.shape[0] - 1) / 2
        ctr = np.array([80 + 150 * k, shape[0] / 2]) + rng.uniform(-15, 15, 2)
        H = _similarity(rng, ctr, c, rng.uniform(0.4, 0.6), rng.uniform(0.85, 1.0))
        H[2, :2] = rng.uniform(-2e-4, 2e-4, 2)
        q = H @ [c, c, 1.0]
        truth[mid] = q[:2] / q[2]
        cover = render_homography(np.ones_like(pat), H, shape, background=0.0)
        img = img * (1 - cover) + render_homography(pat, H, shape, background=0.0)
    img = img * 0.8 + 0.1 + rng.normal(0, 0.01, shape)
    return (np.clip(img, 0, 1) * 255).round().astype(np.uint8), truth


def test_aruco_centres_against_truth():
    errs = []
    for seed in (0, 1, 3):
        img, truth = aruco_scene(seed)
        found, unmapped = detect_aruco(img, {0: "A", 1: "B", 2: "C"}, "img.png")
        assert sorted(m.gcp for m in found) == ["A", "B", "C"] and unmapped == []
        for m in found:
            assert m.image == "img.png" and m.flag == "ok", m
            assert m.score > 0.85 and 0 < m.sigma_x < 0.2
            errs.append(np.hypot(m.x - truth[m.marker_id][0], m.y - truth[m.marker_id][1]))
    assert float(np.sqrt(np.mean(np.square(errs)))) < 0.1


def test_aruco_unmapped_ids_and_low_scores_are_reported():
    img, truth = aruco_scene(4, ids=(3, 7))
    found, unmapped = detect_aruco(img, {3: "G3"}, "i", TargetConfig(min_score=0.999))
    assert unmapped == [7]
    assert len(found) == 1 and found[0].gcp == "G3"
    assert found[0].flag == "low score"  # kept, flagged
    found, _ = detect_aruco(np.full((100, 100), 128, np.uint8), {0: "A"})
    assert found == []


@pytest.mark.parametrize("dark", [True, False])
def test_circle_from_prediction_8px_off(dark):
    errs = []
    for seed in range(6):
        rng = np.random.default_rng(seed)
        pat = disc_pattern(81, 25.0, dark=dark)
        ctr = np.array([100.0, 90.0]) + rng.uniform(-5, 5, 2)
        H = _similarity(rng, ctr, 40.0, rng.uniform(0.3, 0.45), rng.uniform(0.7, 1.0))
        bg = cv2.GaussianBlur(rng.uniform(0.3, 0.6, (200, 200)), (0, 0), 5)
        cover = render_homography(np.ones((81, 81)), H, (200, 200), background=0.0)
        img = bg * (1 - cover) + render_homography(pat, H, (200, 200), background=0.0) * 0.8 * cover
        img += rng.normal(0, 0.01, img.shape)
        m = detect_circle(img, *(ctr + rng.uniform(-8, 8, 2)), "g", "i")
        assert m is not None and m.flag == "ok", m
        errs.append(np.hypot(m.x - ctr[0], m.y - ctr[1]))
    assert float(np.sqrt(np.mean(np.square(errs)))) < 0.1


def test_checker_saddle():
    errs = []
    for seed in range(6):
        rng = np.random.default_rng(seed)
        ctr = np.array([100.0, 90.0]) + rng.uniform(-5, 5, 2)
        H = _similarity(rng, ctr, 39.5, rng.uniform(0.4, 0.6))
        img = render_homography(checker_pattern(80), H, (200, 200), background=0.5) * 0.7 + 0.15
        img += rng.normal(0, 0.01, img.shape)
        m = detect_checker(img, *(ctr + rng.uniform(-8, 8, 2)), "g", "i")
        assert m is not None and m.flag == "ok", m
        errs.append(np.hypot(m.x - ctr[0], m.y - ctr[1]))
    assert float(np.sqrt(np.mean(np.square(errs)))) < 0.1


def test_nothing_there_and_bad_input():
    rng = np.random.default_rng(0)
    flat = np.full((120, 120), 0.5) + rng.normal(0, 0.002, (120, 120))
    assert detect_circle(flat, 60, 60) is None or detect_circle(flat, 60, 60).flag != "ok"
    assert detect_circle(flat, 500, 500) is None
    assert detect_checker(flat, 500, 500) is None
    assert parse_id_mapping("0=GCP1, 1=GCP2;7 = X") == {0: "GCP1", 1: "GCP2", 7: "X"}
    for bad in ("", "a=GCP1", "0=", "0=A,0=B", "0=A,1=A", "0:A"):
        with pytest.raises(InputError):
            parse_id_mapping(bad)
    with pytest.raises(InputError, match="target type"):
        TargetConfig(target="square")
    with pytest.raises(InputError, match="dictionary"):
        TargetConfig(dictionary="DICT_9X9")
    with pytest.raises(InputError):
        detect_aruco(np.zeros((4, 4)), {0: "A"})


def test_detect_targets_in_a_folder(tmp_path):
    from truortho.core.gcp.measurements import Prediction
    from truortho.core.gcp.targets import detect_targets

    truths = {}
    for seed in (0, 1):
        img, truth = aruco_scene(seed, ids=(0, 5))
        cv2.imwrite(str(tmp_path / f"img_{seed}.png"), img)
        truths[f"img_{seed}.png"] = truth
    (tmp_path / "notes.txt").write_text("not an image")
    res = detect_targets(tmp_path, TargetConfig(), {0: "G0", 9: "G9"})
    assert res.images == 2
    assert sorted((m.image, m.gcp) for m in res.measurements) == [("img_0.png", "G0"), ("img_1.png", "G0")]
    for m in res.measurements:
        t = truths[m.image][0]
        assert np.hypot(m.x - t[0], m.y - t[1]) < 0.2
    text = " ".join(res.warnings)
    assert "marker ID 5" in text and "'G9' was not found" in text
    with pytest.raises(InputError, match="mapping"):
        detect_targets(tmp_path, TargetConfig(), {})
    with pytest.raises(InputError, match="not a folder"):
        detect_targets(tmp_path / "missing", TargetConfig(), {0: "G0"})
    with pytest.raises(InputError, match="predicted"):
        detect_targets(tmp_path, TargetConfig(target="circle"))
    with pytest.raises(InputError, match="not in the folder"):
        detect_targets(
            tmp_path, TargetConfig(target="circle"), predictions=[Prediction("G0", "x.png", 5, 5, 10)]
        )
