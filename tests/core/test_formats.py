"""Exchange formats: round trips, conventions and error reporting (truortho.core.formats)."""

from __future__ import annotations

import json
import os
import warnings
from pathlib import Path

import numpy as np
import pytest

from truortho.core.errors import CRSError, FormatError, MissingFileError
from truortho.core.formats import (
    GCPListWarning,
    read_colmap,
    read_gcp_list,
    read_opensfm,
    read_opk,
    write_colmap,
    write_gcp_list,
    write_opk,
)
from truortho.core.formats.opensfm import utm_crs
from truortho.core.geometry import Camera, LocalFrame, matrix_to_axis_angle, opk_to_matrix, project_points
from truortho.core.orientation import GCP, Image, Orientation, SparsePoints

COPR = Path(os.environ["TRUORTHO_DATA"]) / "copr" / "gcp_list.txt"
BORUSZYN = Path(os.environ["TRUORTHO_DATA"]) / "boruszyn" / "gcp_list.txt"


def make_orientation(seed: int = 1) -> Orientation:
    """2 cameras (one portrait with full distortion), 6 images, 40 points with observations."""
    rng = np.random.default_rng(seed)
    cams = {
        "plain": Camera(4000, 3000, 3400.0, 3400.0, 2010.3, 1490.7, id="plain"),
        "dist": Camera(
            3000, 4000, 2900.5, 2901.25, 1497.2, 2003.9, -0.12, 0.05, -0.01, 1e-4, -2e-4, id="dist"
        ),
    }
    images = []
    for i in range(6):
        R = opk_to_matrix(*rng.uniform(-4, 4, 2), rng.uniform(-180, 180), degrees=True)
        C = np.array([-150.0 + 60 * i, rng.uniform(-20, 20), 120.0 + rng.uniform(-5, 5)])
        images.append(Image(f"img_{i}.jpg", "plain" if i % 2 else "dist", R, C))
    xyz = np.column_stack([rng.uniform(-200, 200, 40), rng.uniform(-60, 60, 40), rng.uniform(-5, 10, 40)])
    op, oi, oxy = [], [], []
    for k, im in enumerate(images):
        cam = cams[im.camera]
        uv = project_points(xyz, im.R, im.C, cam)
        ok = (uv[:, 0] > 0) & (uv[:, 0] < cam.width - 1) & (uv[:, 1] > 0) & (uv[:, 1] < cam.height - 1)
        for p in np.flatnonzero(ok):
            op.append(p)
            oi.append(k)
            oxy.append(uv[p])
    pts = SparsePoints(xyz, rng.integers(0, 256, (40, 3)), rng.uniform(0, 2, 40), op, oi, np.array(oxy))
    assert len(op) > 10
    return Orientation(LocalFrame("EPSG:32632", [500000.0, 5600000.0, 100.0]), cams, images, pts)


def assert_same(a: Orientation, b: Orientation, tol: float = 1e-9) -> None:
    assert a.crs == b.crs
    assert [im.name for im in a.images] == [im.name for im in b.images]
    for ia, ib in zip(a.images, b.images, strict=True):
        assert ia.camera == ib.camera
        np.testing.assert_allclose(ia.R, ib.R, atol=tol, rtol=0)
        np.testing.assert_allclose(ia.C + a.offset, ib.C + b.offset, atol=tol, rtol=0)
    assert a.cameras.keys() == b.cameras.keys()
    for k in a.cameras:
        np.testing.assert_allclose(a.cameras[k].params, b.cameras[k].params, atol=tol, rtol=0)
        assert (a.cameras[k].width, a.cameras[k].height) == (b.cameras[k].width, b.cameras[k].height)


def world_projections(o: Orientation, world_xyz: np.ndarray) -> np.ndarray:
    """(n_images, N, 2) pixels; NaN behind the camera or outside the image (+-10 %)."""
    out = []
    for im in o.images:
        cam = o.camera_of(im)
        uv = project_points(world_xyz - o.offset, im.R, im.C, cam)
        bad = (np.abs(uv[:, 0] / cam.width - 0.5) > 0.6) | (np.abs(uv[:, 1] / cam.height - 0.5) > 0.6)
        uv[bad] = np.nan
        out.append(uv)
    return np.stack(out)


# ---------------------------------------------------------------- COLMAP


def test_colmap_round_trip(tmp_path):
    o = make_orientation()
    write_colmap(o, tmp_path / "a")
    a = read_colmap(tmp_path / "a")
    write_colmap(a, tmp_path / "b")
    b = read_colmap(tmp_path / "b")
    for r in (a, b):
        assert_same(o, r)
        np.testing.assert_allclose(r.offset, o.offset)
        np.testing.assert_allclose(r.points.xyz, o.points.xyz, atol=1e-9)
        np.testing.assert_array_equal(r.points.rgb, o.points.rgb)
        np.testing.assert_array_equal(r.points.obs_point, o.points.obs_point)
        np.testing.assert_array_equal(r.points.obs_image, o.points.obs_image)
        np.testing.assert_allclose(r.points.obs_xy, o.points.obs_xy, atol=1e-9)
    assert "FULL_OPENCV" in (tmp_path / "a" / "cameras.txt").read_text()


def test_colmap_half_pixel_shift_and_models(tmp_path):
    (tmp_path / "cameras.txt").write_text(
        "# c\n1 SIMPLE_PINHOLE 100 80 90 50 40\n2 PINHOLE 100 80 90 91 50 40\n"
        "3 SIMPLE_RADIAL 100 80 90 50 40 -0.1\n4 RADIAL 100 80 90 50 40 -0.1 0.01\n"
        "5 OPENCV 100 80 90 91 50 40 -0.1 0.01 0.001 0.002\n"
    )
    (tmp_path / "images.txt").write_text(
        "# images\n1 1 0 0 0 1 2 3 1 sub/a.jpg\n10.5 20.5 7 3 3 -1 4 4 99\n"
        "2 0 1 0 0 0 0 5 5 b with space.jpg\n\n"
    )
    (tmp_path / "points3D.txt").write_text("7 1 2 3 255 0 10 0.5 1 0\n")
    o = read_colmap(tmp_path)
    assert o.crs is None and np.all(o.offset == 0)
    assert o.cameras["1"].fx == o.cameras["1"].fy == 90 and o.cameras["1"].cx == 49.5
    assert o.cameras["3"].k1 == -0.1 and o.cameras["4"].k2 == 0.01
    c5 = o.cameras["5"]
    assert (c5.fy, c5.k1, c5.k2, c5.p1, c5.p2, c5.cy) == (91, -0.1, 0.01, 0.001, 0.002, 39.5)
    np.testing.assert_allclose(o.images[0].C, [-1, -2, -3])
    assert o.images[0].path == "sub/a.jpg" and o.images[1].name == "b with space.jpg"
    # only the observation with a POINT3D_ID present in points3D.txt is kept, shifted by -0.5
    np.testing.assert_array_equal(o.points.obs_point, [0])
    np.testing.assert_allclose(o.points.obs_xy, [[10.0, 20.0]])


def test_colmap_georef_passed_and_sidecar(tmp_path):
    o = make_orientation()
    write_colmap(o, tmp_path)
    (tmp_path / "georef.json").unlink()
    assert read_colmap(tmp_path).crs is None
    r = read_colmap(tmp_path, georef={"crs": "EPSG:25832", "offset": [1, 2, 3]})
    assert r.crs == "EPSG:25832" and list(r.offset) == [1, 2, 3]
    with pytest.raises(CRSError):
        read_colmap(tmp_path, georef={"crs": "EPSG:4326"})


# ---------------------------------------------------------------- OPK


@pytest.mark.parametrize("ext", [".yaml", ".json"])
def test_opk_round_trip_and_projection_matches_colmap(tmp_path, ext):
    pytest.importorskip("yaml") if ext == ".yaml" else None
    o = make_orientation()
    write_opk(o, tmp_path / "ext.csv", tmp_path / f"int{ext}")
    assert (tmp_path / "ext.prj").is_file()
    a = read_opk(tmp_path / "ext.csv", tmp_path / f"int{ext}")
    assert_same(o, a)
    write_opk(a, tmp_path / "ext2.csv", tmp_path / f"int2{ext}")
    assert_same(o, read_opk(tmp_path / "ext2.csv", tmp_path / f"int2{ext}"))
    assert a.offset[0] % 1000 == 0 and a.metadata.get("warnings") is None  # sensor_size written

    write_colmap(o, tmp_path / "colmap")
    c = read_colmap(tmp_path / "colmap")
    rng = np.random.default_rng(5)
    world = o.offset + np.column_stack(
        [rng.uniform(-250, 250, 200), rng.uniform(-80, 80, 200), rng.uniform(-5, 20, 200)]
    )
    uv0, uv1, uv2 = world_projections(o, world), world_projections(a, world), world_projections(c, world)
    ok = np.isfinite(uv0)
    assert ok.sum() > 300
    np.testing.assert_array_equal(ok, np.isfinite(uv1))
    assert np.abs(uv1[ok] - uv0[ok]).max() < 1e-6
    assert np.abs(uv2[ok] - uv0[ok]).max() < 1e-6


def test_opk_formats_header_legacy_and_crs(tmp_path):
    (tmp_path / "int.json").write_text(
        json.dumps(
            {"type": "brown", "im_size": [400, 300], "focal_len": 0.8, "cx": 0.01, "cy": -0.02, "k1": -0.2}
        )
    )
    (tmp_path / "a.csv").write_text(
        "Camera; Kappa; FileName; X; Y; Z; Omega; Phi; extra\n"
        "unknown; 10; C:\\data\\x1.tif; 500100; 5600200; 300; 1; 2; q\n"
    )
    o = read_opk(tmp_path / "a.csv", tmp_path / "int.json", crs=32632)
    cam = o.cameras["unknown"]
    assert (
        cam.fx == pytest.approx(320)
        and cam.cx == pytest.approx(199.5 + 4)
        and cam.cy == pytest.approx(149.5 - 8)
    )
    im = o.images[0]
    assert im.name == "x1.tif" and o.crs == "EPSG:32632"
    np.testing.assert_allclose(im.C + o.offset, [500100, 5600200, 300])
    np.testing.assert_allclose(im.R, opk_to_matrix(1, 2, 10, degrees=True))
    (tmp_path / "b.txt").write_text("x1.tif 500100 5600200 300 1 2 10\nx2.tif\t500200 5600200 300 1 2 10\n")
    with pytest.raises(CRSError, match="no CRS: give CRS or a .prj file"):
        read_opk(tmp_path / "b.txt", tmp_path / "int.json")
    (tmp_path / "b.prj").write_text("EPSG:25832")
    b = read_opk(tmp_path / "b.txt", tmp_path / "int.json")
    assert b.crs == "EPSG:25832" and [i.name for i in b.images] == ["x1.tif", "x2.tif"]


def test_opk_interior_focal_with_sensor_size_and_portrait_warning(tmp_path):
    (tmp_path / "int.json").write_text(
        json.dumps(
            {
                "a": {
                    "type": "pinhole",
                    "im_size": [150, 200],
                    "focal_len": 120.0,
                    "sensor_size": [75.0, 100.0],
                },
                "b": {"type": "opencv", "im_size": [300, 400], "focal_len": [0.5, 0.6], "k3": 0.1, "k4": 0.0},
            }
        )
    )
    (tmp_path / "e.csv").write_text(
        "filename,x,y,z,omega,phi,kappa,camera\ni.tif,1,2,3,0,0,0,a\nj.tif,1,2,3,0,0,0,b\n"
    )
    o = read_opk(tmp_path / "e.csv", tmp_path / "int.json", crs="EPSG:32632")
    assert (o.cameras["a"].fx, o.cameras["a"].fy) == (240.0, 240.0)
    assert (o.cameras["b"].fx, o.cameras["b"].fy, o.cameras["b"].k3) == (200.0, 240.0, 0.1)
    assert any("portrait" in w for w in o.metadata["warnings"])


# ---------------------------------------------------------------- OpenSfM


def _opensfm_block(lat: float, lon: float, rng, size: int = 4000) -> tuple[dict, list, np.ndarray]:
    w, h = size, size * 3 // 4
    cams = {
        "v2 brown": {
            "projection_type": "brown",
            "width": w,
            "height": h,
            "focal_x": 0.85,
            "focal_y": 0.851,
            "c_x": 0.004,
            "c_y": -0.003,
            "k1": -0.1,
            "k2": 0.02,
            "k3": -0.003,
            "p1": 1e-4,
            "p2": -1e-4,
        },
        "persp": {
            "projection_type": "perspective",
            "width": h,
            "height": w,
            "focal": 0.9,
            "k1": -0.05,
            "k2": 0.0,
        },
    }
    shots, truth = {}, []
    for i in range(8):
        R = opk_to_matrix(*rng.uniform(-5, 5, 2), rng.uniform(-180, 180), degrees=True)
        C = np.array([-200 + 55 * i, rng.uniform(-100, 100), 110 + rng.uniform(-5, 5)])
        cam = "v2 brown" if i % 2 else "persp"
        shots[f"DJI_{i:04d}.JPG"] = {
            "camera": cam,
            "rotation": matrix_to_axis_angle(R).tolist(),
            "translation": (-R @ C).tolist(),
        }
        truth.append((R, C, cam))
    pts = np.column_stack([rng.uniform(-260, 260, 300), rng.uniform(-160, 160, 300), rng.uniform(-3, 8, 300)])
    points = {str(k): {"coordinates": p.tolist(), "color": [1, 2, 3]} for k, p in enumerate(pts)}
    rec = {
        "cameras": cams,
        "shots": shots,
        "points": points,
        "reference_lla": {"latitude": lat, "longitude": lon, "altitude": 150.0},
    }
    return rec, truth, pts


def _projection_change(o: Orientation, truth, pts) -> tuple[float, int]:
    """Worst pixel change of in-field points between the topocentric and the converted block."""
    worst, n = 0.0, 0
    for (R, C, cname), im in zip(truth, o.images, strict=True):
        cam = o.cameras[cname]
        xc = (pts - C) @ R.T
        half = np.array([cam.width, cam.height]) / 2 / np.array([cam.fx, cam.fy])
        ok = (xc[:, 2] > 0) & np.all(np.abs(xc[:, :2] / xc[:, 2:]) < half, axis=1)
        uv0 = project_points(pts[ok], R, C, cam)
        uv1 = project_points(o.points.xyz[ok], im.R, im.C, cam)
        n += ok.sum()
        worst = max(worst, float(np.abs(uv1 - uv0).max()))
    return worst, n


# A transverse Mercator "ground-scaled" to the block height (k = 1 + h / R, h ~ 260 m): the CRS scale is 1
# at the block, so what remains is the rigour of the conversion itself.
GROUND_TM = "+proj=tmerc +lat_0=50 +lon_0=11.5 +k=1.0000321 +datum=WGS84 +units=m +no_defs"
R_EARTH = 6.381e6


@pytest.mark.parametrize(("crs", "size"), [(None, 4000), (GROUND_TM, 4000), (GROUND_TM, 1368)])
def test_opensfm_topocentric_projection_preserved(tmp_path, crs, size):
    """Intrinsic limit (module docstring): ~ r_px (|k_eff - 1| + H / (2 R)), H = flying height."""
    from pyproj import Proj

    lat, lon = 50.0, 11.5
    rng = np.random.default_rng(3)
    rec, truth, pts = _opensfm_block(lat, lon, rng, size)
    small = {"cameras": rec["cameras"], "shots": dict(list(rec["shots"].items())[:1])}
    (tmp_path / "reconstruction.json").write_text(json.dumps([small, rec]))
    o = read_opensfm(tmp_path / "reconstruction.json", crs=crs)
    assert len(o.images) == 8 and "2 reconstructions" in o.metadata["warnings"][0]
    cam = o.cameras["v2 brown"]
    assert cam.fx == pytest.approx(0.85 * size) and cam.cx == pytest.approx((size - 1) / 2 + 0.004 * size)
    assert o.cameras["persp"].cy == pytest.approx((size - 1) / 2) and o.cameras["persp"].fx == pytest.approx(
        0.9 * size
    )
    # points transformed point-wise, cameras rotated: projections agree up to the scale-factor effect
    worst, n = _projection_change(o, truth, pts)
    assert n > 100
    if crs is None:
        assert o.crs == utm_crs(lat, lon) == "EPSG:32632"
        # effective horizontal scale k R / (R + h) at the mean ellipsoidal height h ~ 205 m
        k = Proj("EPSG:32632").get_factors(lon, lat).meridional_scale * R_EARTH / (R_EARTH + 205)
        assert worst < size * 0.7 * (abs(k - 1) + 110 / (2 * R_EARTH)) + 0.005, worst
    elif size == 4000:  # scale 1 at mid-height: only the flying-height term is left
        assert worst < size * 0.7 * 110 / (2 * R_EARTH) + 0.005, worst
    else:  # ODM-sized cameras (1368 px), a few hundred metres of block: < 0.01 px
        assert worst < 0.01, worst
    # centres are metric CRS coordinates near the reference
    from truortho.core.geometry.frame import parse_crs, transform_points

    ref = transform_points([[lon, lat, 150.0]], "EPSG:4979", parse_crs(o.crs))[0]
    assert np.abs(o.world_centers()[:, :2] - ref[:2]).max() < 400
    assert np.abs(o.world_centers()[:, 2] - 260).max() < 10


def test_opensfm_sidecar_reference_and_no_reference(tmp_path):
    rec, truth, _ = _opensfm_block(-33.9, 18.4, np.random.default_rng(1))
    ref = rec.pop("reference_lla")
    (tmp_path / "reconstruction.json").write_text(json.dumps([rec]))
    o = read_opensfm(tmp_path / "reconstruction.json")
    assert o.crs is None
    np.testing.assert_allclose(o.images[0].C, truth[0][1], atol=1e-9)
    np.testing.assert_allclose(o.images[0].R, truth[0][0], atol=1e-12)
    (tmp_path / "reference_lla.json").write_text(json.dumps(ref))
    assert read_opensfm(tmp_path / "reconstruction.json").crs == "EPSG:32734"
    assert read_opensfm(tmp_path / "reconstruction.json", crs="EPSG:22234").crs == "EPSG:22234"


def test_opensfm_unsupported(tmp_path):
    rec = {
        "cameras": {"f": {"projection_type": "fisheye", "width": 10, "height": 10, "focal": 1}},
        "shots": {},
    }
    (tmp_path / "r.json").write_text(json.dumps([rec]))
    with pytest.raises(FormatError, match="unsupported projection 'fisheye'"):
        read_opensfm(tmp_path / "r.json")
    rec = {
        "cameras": {"c": {"width": 10, "height": 10, "focal": 1}},
        "shots": {"../x.jpg": {"camera": "c", "rotation": [0, 0, 0], "translation": [0, 0, 0]}},
    }
    (tmp_path / "r.json").write_text(json.dumps([rec]))
    with pytest.raises(FormatError, match=r"'\.\.' is not allowed"):
        read_opensfm(tmp_path / "r.json")


# ---------------------------------------------------------------- gcp_list


@pytest.mark.parametrize(
    ("header", "crs"),
    [
        ("EPSG:32611", "EPSG:32611"),
        ("32611", "EPSG:32611"),
        ("+proj=utm +zone=11 +ellps=WGS84 +datum=WGS84 +units=m +no_defs", "EPSG:32611"),
        ("WGS84 UTM 11N", "EPSG:32611"),
        ("WGS84 UTM 33S", "EPSG:32733"),
        ("WGS84 UTM 33", "EPSG:32633"),
        ("EPSG:4326", "EPSG:4326"),
    ],
)
def test_gcp_list_headers(tmp_path, header, crs):
    (tmp_path / "g.txt").write_text(f"# comment\n\n{header}\n1 2 3 4.5 5 a.jpg g1\n1 2 3 6 7 b.jpg g1\n")
    got, gcps = read_gcp_list(tmp_path / "g.txt")
    assert got == crs
    assert len(gcps) == 1 and gcps[0].observations == [("a.jpg", 4.5, 5.0), ("b.jpg", 6.0, 7.0)]


def test_gcp_list_grouping_duplicates_and_round_trip(tmp_path):
    text = "EPSG:2180\n10 20 30 1 2 a.jpg\n10 20 30 3 4 b.jpg\n11 20 30 1 2 a.jpg\n10 20 30 9 9 a.jpg\n"
    (tmp_path / "g.txt").write_text(text)
    out: list[str] = []
    with pytest.warns(GCPListWarning, match="line 5"):
        crs, gcps = read_gcp_list(tmp_path / "g.txt", warnings_out=out)
    assert [g.name for g in gcps] == ["gcp_1", "gcp_2"] and len(out) == 1
    assert gcps[0].observations == [("a.jpg", 1.0, 2.0), ("b.jpg", 3.0, 4.0)]
    write_gcp_list(crs, gcps, tmp_path / "h.txt")
    crs2, gcps2 = read_gcp_list(tmp_path / "h.txt")
    assert crs2 == crs and [(g.name, list(g.xyz), g.observations) for g in gcps2] == [
        (g.name, list(g.xyz), g.observations) for g in gcps
    ]


def test_gcp_list_same_name_different_coordinates(tmp_path):
    (tmp_path / "g.txt").write_text("EPSG:2180\n10 20 30 1 2 a.jpg p\n\n10 21 30 1 2 b.jpg p\n")
    with pytest.raises(FormatError, match=r"g\.txt, line 4: GCP 'p' .* on line 2"):
        read_gcp_list(tmp_path / "g.txt")


@pytest.mark.skipif(not COPR.is_file(), reason="copr sample data absent")
def test_gcp_list_copr():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        crs, gcps = read_gcp_list(COPR)
    assert crs == "EPSG:32611"
    assert len(gcps) == 10 and sum(len(g.observations) for g in gcps) == 27
    assert gcps[0].name == "gcp02" and gcps[0].observations[0][0] == "IMG_0037.jpg"


@pytest.mark.skipif(not BORUSZYN.is_file(), reason="boruszyn sample data absent")
def test_gcp_list_boruszyn():
    crs, gcps = read_gcp_list(BORUSZYN)
    assert crs == "EPSG:2180" and len(gcps) >= 1
    assert all(g.observations for g in gcps)


# ---------------------------------------------------------------- bad input


def _colmap_dir(tmp_path, cameras="1 PINHOLE 100 80 90 90 50 40\n", images="1 1 0 0 0 0 0 0 1 a.jpg\n\n"):
    d = tmp_path / "m"
    d.mkdir(exist_ok=True)
    (d / "cameras.txt").write_text(cameras) if isinstance(cameras, str) else (d / "cameras.txt").write_bytes(
        cameras
    )
    (d / "images.txt").write_text(images)
    return d


@pytest.mark.parametrize(
    ("cameras", "images", "file", "line", "match"),
    [
        ("# x\n1 FOV 100 80 90 50 40 0.1\n", None, "cameras.txt", 2, "supported: SIMPLE_PINHOLE, PINHOLE"),
        ("1 PINHOLE 100 80 90 nan 50 40\n", None, "cameras.txt", 1, "finite"),
        ("1 PINHOLE 100 80 90 1e16 50 40\n", None, "cameras.txt", 1, "finite"),
        ("1 PINHOLE 100 80 90 90 50\n", None, "cameras.txt", 1, "expects 4 parameters"),
        ("1 PINHOLE 100 80 -90 90 50 40\n", None, "cameras.txt", 1, "focal lengths must be positive"),
        (None, "1 1 0 0 0 0 0 0 1 /etc/a.jpg\n\n", "images.txt", 1, "absolute paths"),
        (None, "\n1 1 0 0 0 0 0 0 1 ../a.jpg\n\n", "images.txt", 2, r"'\.\.'"),
        (None, "1 1 0 0 0 0 0 0 2 a.jpg\n\n", "images.txt", 1, "CAMERA_ID 2"),
        (None, "1 1 0 0 0 0 0 0 1 a.jpg\n1 2\n", "images.txt", 2, "triplets"),
        (None, "1 1 0 0 inf 0 0 0 1 a.jpg\n\n", "images.txt", 1, "QZ"),
        (None, "1 0 0 0 0 0 0 0 1 a.jpg\n\n", "images.txt", 1, "zero-length quaternion"),
        (None, "1 1 0 0 0 0 0\n", "images.txt", 1, "IMAGE_ID QW"),
    ],
)
def test_colmap_bad_input(tmp_path, cameras, images, file, line, match):
    kw = {k: v for k, v in (("cameras", cameras), ("images", images)) if v is not None}
    d = _colmap_dir(tmp_path, **kw)
    with pytest.raises(FormatError, match=match) as e:
        read_colmap(d)
    assert e.value.path.endswith(file) and e.value.line == line
    assert f"{file}, line {line}:" in str(e.value)


def test_non_utf8_missing_and_huge_files(tmp_path):
    d = _colmap_dir(tmp_path, cameras="1 PINHOLE 100 80 90 90 50 40\n# caf\xe9\n".encode("latin-1"))
    with pytest.raises(FormatError, match="not UTF-8") as e:
        read_colmap(d)
    assert e.value.line == 2
    (d / "cameras.txt").unlink()
    with pytest.raises(MissingFileError):
        read_colmap(d)
    big = tmp_path / "big.txt"
    with open(big, "wb") as fh:  # sparse: no disk used
        fh.truncate(513 * 1024**2)
    with pytest.raises(FormatError, match="too large"):
        read_gcp_list(big)


def test_opk_bad_input(tmp_path):
    i = tmp_path / "int.json"
    i.write_text(json.dumps({"c": {"type": "opencv", "im_size": [4, 3], "focal_len": 1, "k4": 0.1}}))
    (tmp_path / "e.csv").write_text("filename,x,y,z,omega,phi,kappa\na.tif,1,2,3,0,0,0\n")
    with pytest.raises(FormatError, match="nonzero k4 is unsupported"):
        read_opk(tmp_path / "e.csv", i, crs=32632)
    i.write_text(json.dumps({"c": {"type": "fisheye", "im_size": [4, 3], "focal_len": 1}}))
    with pytest.raises(FormatError, match="unsupported camera type 'fisheye'"):
        read_opk(tmp_path / "e.csv", i, crs=32632)
    i.write_text(
        json.dumps(
            {
                "c": {"type": "brown", "im_size": [4, 3], "focal_len": 1},
                "d": {"type": "brown", "im_size": [4, 3], "focal_len": 1},
            }
        )
    )
    with pytest.raises(FormatError, match=r"e\.csv, line 2: image 'a.tif' names no camera"):
        read_opk(tmp_path / "e.csv", i, crs=32632)
    i.write_text('{"c": {"type": "brown", "im_size": [4, 3], "focal_len": NaN}}')
    with pytest.raises(FormatError, match="NaN is not allowed"):
        read_opk(tmp_path / "e.csv", i, crs=32632)
    i.write_text(json.dumps({"c": {"type": "brown", "im_size": [4, 3], "focal_len": 1}}))
    (tmp_path / "e.csv").write_text("filename,x,y,z,omega,phi,kappa\na.tif,1,2,3,0,0,0\nb.tif,1,2,x,0,0,0\n")
    with pytest.raises(FormatError, match=r"e\.csv, line 3: z: expected a number"):
        read_opk(tmp_path / "e.csv", i, crs=32632)
    (tmp_path / "e.csv").write_text("filename,x,y,z,omega,phi\na.tif,1,2,3,0,0\n")
    with pytest.raises(FormatError, match="lacks the column.*kappa"):
        read_opk(tmp_path / "e.csv", i, crs=32632)
    (tmp_path / "e.csv").write_text("filename,x,y,z,omega,phi,kappa\n..,1,2,3,0,0,0\n")
    with pytest.raises(FormatError, match=r"line 2: .*'\.\.'"):
        read_opk(tmp_path / "e.csv", i, crs=32632)
    with pytest.raises(CRSError):
        read_opk(tmp_path / "e.csv", i, crs="EPSG:4326")


def test_gcp_list_bad_input(tmp_path):
    g = tmp_path / "g.txt"
    cases = [
        ("EPSG:2180\n1 2 3 4 5\n", 2, "expected 'geo_x"),
        ("EPSG:2180\n1 2 NaN 4 5 a.jpg\n", 2, "geo_z"),
        ("EPSG:2180\n1 2 3 4 5 /abs/a.jpg\n", 2, "absolute"),
        ("EPSG:2180\n1 2 3 4 5 ..\\a.jpg\n", 2, r"'\.\.'"),
        ("Lambert 93\n1 2 3 4 5 a.jpg\n", 1, "unrecognised CRS header"),
        ("WGS84 UTM 61N\n1 2 3 4 5 a.jpg\n", 1, "UTM zone"),
        ("EPSG:99999999\n1 2 3 4 5 a.jpg\n", 1, "cannot read the CRS"),
    ]
    for text, line, match in cases:
        g.write_text(text)
        with pytest.raises(FormatError, match=match) as e:
            read_gcp_list(g)
        assert e.value.line == line and str(g) in str(e.value)
    g.write_text("EPSG:2180\n")
    with pytest.raises(FormatError, match="no GCP lines"):
        read_gcp_list(g)


def test_write_gcp_list_rejects_unwritable_names(tmp_path):
    with pytest.raises(ValueError, match="blanks"):
        write_gcp_list(
            "EPSG:2180", [GCP("a b", [1, 2, 3], observations=[("x.jpg", 1, 2)])], tmp_path / "g.txt"
        )
