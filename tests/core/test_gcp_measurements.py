"""The GCP measurement model (core/gcp/measurements.py): place/move/delete with undo/redo, prediction
against synthetic cameras with known truth, CSV and gcp_list round trips, bad input, atomic saves."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

from truortho.core.errors import FormatError, InputError
from truortho.core.gcp.measurements import (
    MEASURED,
    NONE,
    PREDICTED,
    GroundPoint,
    Measurement,
    MeasurementSet,
    Photo,
    list_images,
    predict,
)
from truortho.core.geometry.camera import project_points
from truortho.core.geometry.frame import LocalFrame
from truortho.core.orientation import Image, Orientation
from truortho.core.synthetic import make_camera, nadir_block

CRS = "EPSG:32632"
OFFSET = np.array([500000.0, 5600000.0, 0.0])


def _gcps(rng, n=6, crs=CRS):
    xy = rng.uniform(-40, 40, (n, 2))
    z = rng.uniform(-2, 5, n)
    return [
        GroundPoint(f"g{k}", (OFFSET[0] + xy[k, 0], OFFSET[1] + xy[k, 1], z[k]), crs, check=k == n - 1)
        for k in range(n)
    ]


@pytest.fixture
def block():
    """A nadir block with distortion (no rendering) and GCPs in its area."""
    cam = make_camera(320, 240, 400.0, (1.3, -0.8), (-0.08, 0.02, 3e-4, -2e-4, 0.0))
    images = nadir_block((-40, -40, 40, 40), cam, 60.0, 0.0, 0.7, 0.5, 90.0, 0.8, 0.3, seed=5)
    o = Orientation(LocalFrame(CRS, OFFSET), {cam.id: cam}, images)
    photos = [Photo(im.name, im.name, cam.width, cam.height) for im in images]
    return o, photos, _gcps(np.random.default_rng(11))


@pytest.fixture
def mset(block):
    _o, photos, gcps = block
    return MeasurementSet(gcps, photos)


# ---------------------------------------------------------------------- editing


def test_place_move_delete_undo_redo(mset):
    im0, im1 = mset.photos[0].name, mset.photos[1].name
    assert mset.state("g0", im0) == NONE and not mset.can_undo
    mset.place("g0", im0, 10.25, 20.5)
    mset.place("g1", im1, 100.0, 50.0, sigma_x=0.5, sigma_y=0.7)
    assert mset.state("g0", im0) == MEASURED and len(mset) == 2
    mset.place("g0", im0, 12.0, 21.0)  # move
    assert (mset.get("g0", im0).x, mset.get("g0", im0).y) == (12.0, 21.0)
    assert mset.undo_label() == f"move g0 on {im0}"
    assert mset.delete("g1", im1) and mset.get("g1", im1) is None
    assert not mset.delete("g1", im1)  # nothing to delete: no command
    assert mset.undo()  # delete undone
    assert mset.get("g1", im1).sigma_x == 0.5
    # the sigmas reach the bundle as the measurement's weight (one sigma: the RMS of x and y)
    rec = {g.name: g for g in mset.to_gcp_records()}
    assert rec["g1"].obs_sigma == {im1: pytest.approx(((0.5**2 + 0.7**2) / 2) ** 0.5)}
    assert rec["g0"].obs_sigma == {}
    assert mset.undo()  # move undone
    assert (mset.get("g0", im0).x, mset.get("g0", im0).y) == (10.25, 20.5)
    assert mset.redo()  # move redone
    assert mset.get("g0", im0).x == 12.0
    mset.place("g2", im0, 1.0, 1.0)  # a new command clears the redo stack
    assert not mset.can_redo and not mset.redo()
    while mset.undo():
        pass
    assert len(mset) == 0 and not mset.can_undo
    rev = mset.revision
    mset.place("g0", im0, 5.0, 5.0)
    mset.place("g0", im0, 5.0, 5.0)  # unchanged: not a second command
    assert mset.undo() and not mset.can_undo and mset.revision == rev + 2
    mset.place("g1", im1, 2.0, 3.0)
    mset.clear_history()
    assert not mset.can_undo and not mset.undo() and mset.get("g1", im1).x == 2.0


def test_bad_input_changes_nothing(mset):
    im0 = mset.photos[0].name
    mset.place("g0", im0, 10.0, 10.0)
    before = (mset.measurements(), mset.revision, mset.undo_label())
    with pytest.raises(InputError, match="unknown GCP 'nope'.*known: g0"):
        mset.place("nope", im0, 1.0, 1.0)
    with pytest.raises(InputError, match="'other.jpg' is not in the image folder"):
        mset.place("g0", "other.jpg", 1.0, 1.0)
    for x, y in ((-0.51, 3.0), (319.51, 3.0), (3.0, 239.6), (math.nan, 1.0)):
        with pytest.raises(InputError, match="outside the image"):
            mset.place("g0", im0, x, y)
    with pytest.raises(InputError, match="sigma_x must be a positive"):
        mset.place("g0", im0, 1.0, 1.0, sigma_x=0.0)
    with pytest.raises(InputError, match="source must be one of"):
        mset.place("g0", im0, 1.0, 1.0, source="guessed")
    with pytest.raises(InputError, match="twice"):
        mset.replace_all([Measurement("g1", im0, 1, 1), Measurement("g1", im0, 2, 2)])
    assert (mset.measurements(), mset.revision, mset.undo_label()) == before
    # the image's edges are on it: -0.5 .. W - 0.5
    mset.place("g1", im0, -0.5, 239.5)
    assert mset.get("g1", im0).y == 239.5


# ---------------------------------------------------------------------- prediction


def test_prediction_matches_the_camera_model(block):
    """Every prediction is exactly core.geometry.camera's projection; every GCP that projects into a
    frame in front of the camera is predicted there, and no other one."""
    o, photos, gcps = block
    preds = predict(o, gcps, photos)
    got = {(p.gcp, p.image): (p.x, p.y) for p in preds}
    cam = o.cameras["synthetic"]
    local = np.array([g.xyz for g in gcps]) - OFFSET
    expected = {}
    for im in o.images:
        uv, depth = project_points(local, im.R, im.C, cam, return_depth=True)
        for k, g in enumerate(gcps):
            u, v = uv[k]
            if depth[k] > 0 and -0.5 <= u <= cam.width - 0.5 and -0.5 <= v <= cam.height - 0.5:
                expected[(g.name, im.name)] = (u, v)
    assert set(got) == set(expected) and len(got) >= 2 * len(gcps)
    assert all(got[k] == expected[k] for k in got)
    # independent reference: OpenCV's projectPoints (same Brown model)
    cv2 = pytest.importorskip("cv2")
    for (g, name), (u, v) in list(got.items())[:10]:
        im = o.image(name)
        X = np.array([gcps[int(g[1:])].xyz]) - OFFSET
        rvec, _ = cv2.Rodrigues(im.R)
        ref, _ = cv2.projectPoints(X, rvec, im.t, cam.K, cam.dist_coeffs)
        assert abs(ref[0, 0, 0] - u) < 1e-6 and abs(ref[0, 0, 1] - v) < 1e-6
    # the set keeps them as states
    ms = MeasurementSet(gcps, photos)
    assert ms.predict_from(o) == len(preds)
    p = preds[0]
    assert ms.state(p.gcp, p.image) == PREDICTED and ms.images_of(p.gcp)[0] == p.image
    ms.place(p.gcp, p.image, p.x, p.y, source="predicted")
    assert ms.state(p.gcp, p.image) == MEASURED and ms.counts(p.gcp)[0] == 1


def test_prediction_visibility_behind_and_folded_distortion():
    """A point behind the camera is not predicted; nor is one far outside the field that a strong
    barrel distortion folds back into the frame (found by the round trip through undistortion)."""
    cam = make_camera(400, 300, 300.0, (0, 0), (-0.3, 0.0, 0.0, 0.0, 0.0))
    R = np.diag([1.0, -1.0, -1.0])  # nadir
    im = Image("a.png", cam.id, R, np.array([0.0, 0.0, 100.0]))
    o = Orientation(LocalFrame(None), {cam.id: cam}, [im])
    # x' = 2: x'' = 2 (1 - 0.3 * 4) = -0.4 -> folded into the frame at u = -120 + 199.5
    far = GroundPoint("far", (200.0, 0.0, 0.0))
    near = GroundPoint("near", (10.0, -5.0, 0.0))
    above = GroundPoint("above", (0.0, 0.0, 150.0))
    uv = project_points(np.array([far.xyz]), R, im.C, cam)
    assert -0.5 <= uv[0, 0] <= 399.5 and -0.5 <= uv[0, 1] <= 299.5  # the fold is real
    names = {p.gcp for p in predict(o, [far, near, above])}
    assert names == {"near"}


def test_prediction_reprojects_gcps_and_checks_sizes(block):
    """GCPs in another CRS (UTM 32N as a PROJ transverse Mercator with another false easting) are moved to
    the orientation's CRS in plan; a folder whose images differ in size from the camera is refused."""
    o, photos, gcps = block
    shifted = "+proj=tmerc +lat_0=0 +lon_0=9 +k=0.9996 +x_0=400000 +y_0=0 +datum=WGS84 +units=m +no_defs"
    moved = [GroundPoint(g.name, (g.xyz[0] - 100000.0, g.xyz[1], g.xyz[2]), shifted) for g in gcps]
    a = {(p.gcp, p.image): (p.x, p.y) for p in predict(o, gcps, photos)}
    b = {(p.gcp, p.image): (p.x, p.y) for p in predict(o, moved, photos)}
    assert a.keys() == b.keys()
    assert max(abs(a[k][0] - b[k][0]) + abs(a[k][1] - b[k][1]) for k in a) < 1e-5
    small = [Photo(p.name, p.path, p.width // 2, p.height // 2) for p in photos]
    with pytest.raises(InputError, match="160 x 120 pixels but its camera"):
        predict(o, gcps, small)
    o.frame.crs = None
    with pytest.raises(InputError, match="orientation has no CRS"):
        predict(o, gcps, photos)


# ---------------------------------------------------------------------- files


def _fill(ms, rng, n=8):
    for k in range(n):
        p = ms.photos[k % len(ms.photos)]
        g = ms.gcps[k % len(ms.gcps)]
        sig = (0.3 + k / 10, 0.4) if k % 2 else (None, None)
        ms.place(g.name, p.name, rng.uniform(0, p.width - 1), rng.uniform(0, p.height - 1), *sig)


def test_csv_round_trip_and_undo_of_load(mset, tmp_path):
    _fill(mset, np.random.default_rng(2))
    path = tmp_path / "obs.csv"
    mset.save_csv(path)
    assert path.read_text().splitlines()[0] == "gcp,image,x,y,sigma_x,sigma_y,source"
    assert (tmp_path / "obs.csvt").read_text().startswith('"String","String","Real","Real"')
    other = MeasurementSet(mset.gcps, mset.photos)
    other.place("g5", mset.photos[3].name, 7.0, 7.0)
    assert other.load_csv(path) == 8
    assert other.measurements() == mset.measurements()  # exact floats
    assert other.undo() and [m.gcp for m in other.measurements()] == ["g5"]


def test_gcp_list_round_trip(mset, tmp_path):
    _fill(mset, np.random.default_rng(3))
    path = tmp_path / "gcp_list.txt"
    mset.save_gcp_list(path)
    from truortho.core.formats.gcplist import read_gcp_list

    crs, records = read_gcp_list(path)
    assert crs == CRS
    assert {r.name: tuple(r.xyz) for r in records} == {
        g.name: g.xyz for g in mset.gcps if any(m.gcp == g.name for m in mset.measurements())
    }
    other = MeasurementSet(mset.gcps, mset.photos)
    assert other.load_gcp_list(path) == 8
    # gcp_list has no sigmas or sources
    assert [(m.gcp, m.image, m.x, m.y) for m in other.measurements()] == [
        (m.gcp, m.image, m.x, m.y) for m in mset.measurements()
    ]


def test_bad_tables_name_the_line_and_change_nothing(mset, tmp_path):
    im0, im1 = mset.photos[0].name, mset.photos[1].name
    mset.place("g0", im0, 3.0, 4.0)
    before = mset.measurements()
    cases = {
        "gcp,image,x\n": "missing column\\(s\\) y",
        f"gcp,image,x,y\ng0,{im0},1,2\nghost,{im1},1,2\n": "line 3: unknown GCP 'ghost'",
        "gcp,image,x,y\ng1,missing.png,1,2\n": "line 2: image 'missing.png' is not in the image folder",
        f"gcp,image,x,y\ng1,{im1},400,2\n": "line 2: GCP 'g1': pixel \\(400.00, 2.00\\) is outside the image",
        f"gcp,image,x,y\ng1,{im1},abc,2\n": "line 2: x: expected a number, got 'abc'",
        f"gcp,image,x,y\ng1,{im1},1,2\n\ng1,{im1},3,4\n": "line 4: GCP 'g1' on .* again \\(first on line 2",
        "": "empty file",
    }
    for k, (text, msg) in enumerate(cases.items()):
        p = tmp_path / f"bad{k}.csv"
        p.write_text(text)
        with pytest.raises(FormatError, match=msg):
            mset.load_csv(p)
    assert mset.measurements() == before and mset.undo_label() == f"place g0 on {im0}"
    bad_list = tmp_path / "gcp_list.txt"
    bad_list.write_text(f"EPSG:32632\n1 2 3 10 10 {im0} unknown_gcp\n")
    with pytest.raises(FormatError, match="unknown GCP 'unknown_gcp'"):
        mset.load_gcp_list(bad_list)
    assert mset.measurements() == before


def test_failed_save_leaves_the_old_file(mset, tmp_path, monkeypatch):
    _fill(mset, np.random.default_rng(4), n=3)
    path = tmp_path / "obs.csv"
    mset.save_csv(path)
    good = path.read_bytes()
    mset.place("g4", mset.photos[2].name, 9.0, 9.0)

    def fail(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", fail)
    with pytest.raises(OSError, match="No space left"):
        mset.save_csv(path)
    monkeypatch.undo()
    assert path.read_bytes() == good
    assert sorted(os.listdir(tmp_path)) == ["obs.csv", "obs.csvt"]  # no temporary file left behind
    # a GCP name gcp_list.txt cannot hold: nothing written
    lst = tmp_path / "gcp_list.txt"
    mset.save_gcp_list(lst)
    old = lst.read_bytes()
    blank = MeasurementSet([GroundPoint("a b", (1.0, 2.0, 3.0), CRS)], mset.photos)
    blank.place("a b", mset.photos[0].name, 1.0, 1.0)
    with pytest.raises(InputError, match="cannot be written to gcp_list.txt"):
        blank.save_gcp_list(lst)
    assert lst.read_bytes() == old
    with pytest.raises(InputError, match="no measurement to write"):
        MeasurementSet(mset.gcps, mset.photos).save_gcp_list(tmp_path / "empty.txt")
    assert not (tmp_path / "empty.txt").exists()


def test_list_images(tmp_path):
    cv2 = pytest.importorskip("cv2")
    cv2.imwrite(str(tmp_path / "b.png"), np.zeros((30, 50, 3), np.uint8))
    cv2.imwrite(str(tmp_path / "a.JPG"), np.zeros((20, 40, 3), np.uint8))
    (tmp_path / "notes.txt").write_text("x")
    photos = list_images(tmp_path)
    assert [(p.name, p.width, p.height) for p in photos] == [("a.JPG", 40, 20), ("b.png", 50, 30)]
    with pytest.raises(InputError, match="is not a folder"):
        list_images(tmp_path / "nothing")
    (tmp_path / "empty").mkdir()
    with pytest.raises(InputError, match="holds no image"):
        list_images(tmp_path / "empty")


def test_ground_point_and_set_validation():
    with pytest.raises(InputError, match="non-empty name"):
        GroundPoint(" g", (0, 0, 0))
    with pytest.raises(InputError, match="3 finite numbers"):
        GroundPoint("g", (0, math.inf, 0))
    with pytest.raises(InputError, match="GCP names must be unique"):
        MeasurementSet([GroundPoint("g", (0, 0, 0)), GroundPoint("g", (1, 0, 0))], [])


# ---------------------------------------------------------------------- refinement (MGCM)


@pytest.fixture
def textured_block(tmp_path):
    """Four photos (uint8 PNG) of a textured ground plane with known cameras; a GCP at Xt on it."""
    cv2 = pytest.importorskip("cv2")
    from truortho.core.synthetic.cameras import look_at_rotation, nadir_rotation
    from truortho.core.synthetic.targets import render_on_plane

    rng = np.random.default_rng(5)
    cam = make_camera(320, 240, 400.0, distortion=(-0.05, 0.01, 0, 0, 0))
    tex = cv2.GaussianBlur(rng.uniform(0, 1, (400, 400)), (0, 0), 10.0)
    tex = (tex - tex.min()) / (tex.max() - tex.min())
    Xt = np.array([1.0, -0.5, 0.0])
    images, photos = [], []
    for i, C in enumerate([[0, 0, 30], [8, 2, 28], [-6, 7, 31], [3, -9, 29]]):
        C = np.array(C, float)
        R = nadir_rotation(20.0) if i == 0 else look_at_rotation(C, Xt)
        img = render_on_plane(tex, 0.01, (0.0, 0.0), 0.0, R, C, cam) * rng.uniform(0.7, 1.0) + 0.05
        name = f"v{i}.png"
        cv2.imwrite(str(tmp_path / name), np.clip(np.round(img * 230), 0, 255).astype(np.uint8))
        images.append(Image(name, cam.id, R, C))
        photos.append(Photo(name, str(tmp_path / name), 320, 240))
    o = Orientation(LocalFrame(CRS, OFFSET), {cam.id: cam}, images)
    truth = {im.name: project_points(Xt[None], im.R, im.C, cam)[0] for im in images}
    # the GCP's given coordinates are off by decimetres (as a datum or a survey error would be): the
    # predictions and the start of the matching are pixels away from the truth
    gcp = GroundPoint("t1", tuple(Xt + OFFSET + [0.3, -0.2, 0.6]), CRS)
    return o, photos, gcp, truth


def test_refine_measures_the_other_images(textured_block):
    """From one measurement, MGCM finds the GCP in the three other photos to < 0.15 px of the truth
    (uint8 images; the start, on the master ray at the GCP's height 0.6 m too high, is 2.1-2.5 px
    off; measured 0.003-0.023 px), as one undoable command; the master measurement is untouched."""
    from truortho.core.gcp.measurements import refine_gcp

    o, photos, gcp, truth = textured_block
    ms = MeasurementSet([gcp], photos)
    assert ms.predict_from(o) == 4
    off = [
        np.hypot(*(np.array([ms.prediction("t1", n).x, ms.prediction("t1", n).y]) - truth[n])) for n in truth
    ]
    assert min(off) > 2.0, off
    ms.place("t1", "v0.png", *truth["v0.png"])
    before = ms.get("t1", "v0.png")
    rep = refine_gcp(ms, o, "t1", "v0.png")
    assert rep, rep.reason
    assert sorted(rep.refined) == ["v1.png", "v2.png", "v3.png"] and not rep.failed
    err = [np.hypot(ms.get("t1", n).x - truth[n][0], ms.get("t1", n).y - truth[n][1]) for n in rep.refined]
    assert max(err) < 0.15, err
    assert all(ms.get("t1", n).source == "refined" and 0 < ms.get("t1", n).sigma_x < 0.5 for n in rep.refined)
    assert ms.get("t1", "v0.png") == before
    assert ms.undo() and len(ms) == 1  # one command


def test_refine_failures_change_nothing(textured_block, tmp_path):
    from truortho.core.gcp.measurements import refine_gcp

    cv2 = pytest.importorskip("cv2")
    o, photos, gcp, truth = textured_block
    ms = MeasurementSet([gcp], photos)
    ms.predict_from(o)
    with pytest.raises(InputError, match="not measured on 'v0.png'"):
        refine_gcp(ms, o, "t1", "v0.png")
    # a textureless master: a report with a reason, no change
    cv2.imwrite(photos[0].path, np.full((240, 320), 128, np.uint8))
    ms.place("t1", "v0.png", *truth["v0.png"])
    rev = ms.revision
    rep = refine_gcp(ms, o, "t1", "v0.png")
    assert not rep and rep.reason and ms.revision == rev and len(ms) == 1
