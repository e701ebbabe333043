"""Orientation model and its JSON format."""

from __future__ import annotations

import json

import numpy as np
import pytest

from truortho.core.errors import FormatError, InputError, MissingFileError
from truortho.core.geometry import Camera, LocalFrame, opk_to_matrix
from truortho.core.geometry.footprint import footprint_on_plane
from truortho.core.orientation import GCP, Image, Orientation, SparsePoints


def small_block(root=".") -> Orientation:
    cams = {
        "a": Camera(600, 400, 500.0, 501.0, 299.5, 199.5, -0.1, 0.02, 0.0, 1e-4, -2e-4, id="a"),
        "b": Camera(300, 200, 250.0, 250.0, 150.2, 99.1, id="b"),
    }
    rng = np.random.default_rng(0)
    images = []
    for i in range(4):
        R = opk_to_matrix(*rng.uniform(-5, 5, 3), degrees=True)
        images.append(Image(f"sub/img_{i}.jpg", "a" if i % 2 else "b", R, [i * 10.0, 5.0, 100.0]))
    pts = SparsePoints(
        rng.uniform(-20, 20, (5, 3)),
        rgb=rng.integers(0, 255, (5, 3)),
        error=rng.uniform(0, 1, 5),
        obs_point=[0, 0, 1, 2],
        obs_image=[0, 1, 1, 3],
        obs_xy=rng.uniform(0, 100, (4, 2)),
    )
    gcps = [
        GCP("g1", [500010.0, 5600020.0, 301.5], "gcp", [0.02, 0.02, 0.03], [("sub/img_0.jpg", 10.5, 20.25)]),
        GCP("c1", [500015.0, 5600025.0, 300.0], "check"),
    ]
    return Orientation(LocalFrame("EPSG:32632", [500000.0, 5600000.0, 200.0]), cams, images, pts, gcps, root)


def test_json_round_trip_is_exact(tmp_path):
    o = small_block(str(tmp_path / "imgs"))
    path = tmp_path / "out" / "orientation.json"
    o.save(path)
    back = Orientation.load(path)
    assert back.crs == "EPSG:32632"
    np.testing.assert_array_equal(back.offset, o.offset)
    assert back.cameras == o.cameras
    for a, b in zip(o.images, back.images, strict=True):
        assert a.name == b.name and a.camera == b.camera and a.path == b.path
        np.testing.assert_array_equal(a.R, b.R)
        np.testing.assert_array_equal(a.C, b.C)
    np.testing.assert_array_equal(back.points.xyz, o.points.xyz)
    np.testing.assert_array_equal(back.points.obs_xy, o.points.obs_xy)
    assert [g.name for g in back.gcps] == ["g1", "c1"]
    assert back.gcps[0].observations == [("sub/img_0.jpg", 10.5, 20.25)]
    # image root stored relative to the file and resolved back
    assert json.loads(path.read_text())["image_root"] == "../imgs"
    assert back.resolve_image_path(back.images[0]) == tmp_path / "imgs" / "sub" / "img_0.jpg"
    assert not list(tmp_path.glob("out/.*tmp*")), "temporary file left behind"


def test_missing_images_are_named(tmp_path):
    o = small_block(str(tmp_path))
    with pytest.raises(MissingFileError, match="img_0.jpg"):
        o.check_images_exist()


@pytest.mark.parametrize("path", ["/etc/passwd", "../secret.jpg", "a/../../b.jpg", "C:\\x.jpg", ""])
def test_hostile_image_paths_are_rejected(tmp_path, path):
    d = small_block().to_dict()
    d["images"][0]["path"] = path
    f = tmp_path / "o.json"
    f.write_text(json.dumps(d))
    with pytest.raises(FormatError, match="images\\[0\\]"):
        Orientation.load(f)


@pytest.mark.parametrize(
    "mutate, match",
    [
        (lambda d: d.update(version=99), "version"),
        (lambda d: d.update(format="x"), "format"),
        (lambda d: d["images"][0].update(camera="zzz"), "unknown camera"),
        (lambda d: d["images"][0].update(rotation=[[1, 0, 0], [0, 1, 0], [0, 0, 2]]), "rotation"),
        (lambda d: d["cameras"]["a"].update(fx=-3), "focal"),
        (lambda d: d["cameras"]["a"].pop("fx"), "fx"),
        (lambda d: d["gcps"][0].update(role="maybe"), "role"),
        (lambda d: d["gcps"][0]["observations"][0].update(image="nope.jpg"), "unknown image"),
        (lambda d: d["points"]["observations"].append([99, 0, 1.0, 1.0]), "out of range"),
        (lambda d: d.update(offset=[1, 2]), "offset"),
    ],
)
def test_bad_json_gets_clear_error(tmp_path, mutate, match):
    d = small_block().to_dict()
    mutate(d)
    f = tmp_path / "o.json"
    f.write_text(json.dumps(d))
    with pytest.raises(FormatError, match=match):
        Orientation.load(f)


def test_nan_and_bad_json(tmp_path):
    f = tmp_path / "o.json"
    f.write_text(json.dumps(small_block().to_dict()).replace("500.0", "NaN", 1))
    with pytest.raises(FormatError, match="NaN"):
        Orientation.load(f)
    f.write_text('{"format": "truortho-orientation",')
    with pytest.raises(FormatError, match="line 1"):
        Orientation.load(f)
    f.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(FormatError, match="UTF-8"):
        Orientation.load(f)
    with pytest.raises(MissingFileError):
        Orientation.load(tmp_path / "absent.json")


def test_with_offset_keeps_world_coordinates():
    o = small_block()
    o2 = o.with_offset([400000.0, 5500000.0, 0.0])
    np.testing.assert_allclose(o2.world_centers(), o.world_centers(), atol=1e-9)


def test_duplicate_image_names():
    o = small_block()
    o.images.append(o.images[0])
    with pytest.raises(InputError, match="twice"):
        o.validate()


def test_footprint_of_nadir_camera():
    cam = Camera(400, 300, 400.0, 400.0, 199.5, 149.5)
    R = opk_to_matrix(0, 0, 0)
    ring = footprint_on_plane(R, [0.0, 0.0, 100.0], cam, 0.0, samples_per_edge=1)
    # half-width 200 px / 400 px focal * 100 m = 50 m, half-height 37.5 m
    np.testing.assert_allclose(np.abs(ring), [[50, 37.5]] * 4, atol=1e-9)
    assert footprint_on_plane(R, [0.0, 0.0, 100.0], cam, 200.0) is None  # plane above the camera
