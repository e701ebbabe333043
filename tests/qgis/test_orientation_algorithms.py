"""truortho:importorientation / exportorientation / importgcps through processing.run."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

from truortho.core.geometry import Camera, LocalFrame, opk_to_matrix, project_points
from truortho.core.orientation import Image, Orientation, SparsePoints

pytestmark = pytest.mark.qgis

DATA = Path(os.environ.get("TRUORTHO_DATA", ""))  # the shared data sets (set by tests/conftest.py)
COPR_GCPS = DATA / "copr" / "gcp_list.txt"


def block() -> Orientation:
    cam = Camera(800, 600, 700.0, 700.0, 401.3, 298.2, -0.08, 0.01, 0.0, 2e-4, -1e-4, id="cam")
    rng = np.random.default_rng(11)
    images = []
    for i in range(6):
        R = opk_to_matrix(*rng.uniform([-3, -3, -180], [3, 3, 180]), degrees=True)
        images.append(Image(f"img_{i}.png", "cam", R, [(i % 3) * 30.0, (i // 3) * 25.0, 120.0]))
    pts = SparsePoints(
        np.column_stack([rng.uniform(-10, 70, 50), rng.uniform(-10, 35, 50), rng.uniform(0, 5, 50)])
    )
    return Orientation(LocalFrame("EPSG:32632", [500000.0, 5600000.0, 300.0]), {"cam": cam}, images, pts)


def run(alg, params):
    import processing

    return processing.run(alg, params)


def test_import_colmap_with_layers(truortho_provider, tmp_path):
    from qgis.core import QgsVectorLayer, QgsWkbTypes

    from truortho.core.formats.colmap import write_colmap

    o = block()
    write_colmap(o, tmp_path / "model")
    out = tmp_path / "o.json"
    res = run(
        "truortho:importorientation",
        {
            "INPUT": str(tmp_path / "model" / "images.txt"),
            "OUTPUT": str(out),
            "CAMERAS": str(tmp_path / "cams.gpkg"),
            "FOOTPRINTS": str(tmp_path / "foot.gpkg"),
        },
    )
    back = Orientation.load(res["OUTPUT"])
    assert back.crs == "EPSG:32632"
    np.testing.assert_allclose(back.world_centers(), o.world_centers(), atol=1e-9)
    cams = QgsVectorLayer(res["CAMERAS"], "c", "ogr")
    assert cams.isValid() and cams.featureCount() == 6
    assert cams.crs().authid() == "EPSG:32632"
    assert QgsWkbTypes.hasZ(cams.wkbType())
    f = next(cams.getFeatures())
    np.testing.assert_allclose([f["x"], f["y"], f["z"]], o.world_centers()[0], atol=1e-6)
    foot = QgsVectorLayer(res["FOOTPRINTS"], "f", "ogr")
    assert foot.featureCount() == 6
    # footprint at the sparse points' median height contains the nadir point of the camera
    assert all(ft.geometry().area() > 1000 for ft in foot.getFeatures())


def test_export_opk_and_reimport_projects_identically(truortho_provider, tmp_path):
    o = block()
    src = tmp_path / "o.json"
    o.save(src)
    res = run("truortho:exportorientation", {"INPUT": str(src), "FORMAT": 1, "OUTPUT": str(tmp_path / "opk")})
    files = {Path(f).name for f in res["FILES"]}
    assert {"exterior.csv", "exterior.prj", "interior.yaml"} <= files
    res2 = run(
        "truortho:importorientation",
        {
            "INPUT": str(tmp_path / "opk" / "exterior.csv"),
            "INTERIOR": str(tmp_path / "opk" / "interior.yaml"),
            "OUTPUT": str(tmp_path / "back.json"),
            "CAMERAS": "memory:",
        },
    )
    back = Orientation.load(res2["OUTPUT"])
    rng = np.random.default_rng(3)
    X_world = (
        np.column_stack([rng.uniform(0, 60, 200), rng.uniform(0, 25, 200), rng.uniform(0, 5, 200)]) + o.offset
    )
    for a, b in zip(o.images, back.images, strict=True):
        uv_a = project_points(o.frame.to_local(X_world), a.R, a.C, o.camera_of(a))
        uv_b = project_points(back.frame.to_local(X_world), b.R, b.C, back.camera_of(b))
        np.testing.assert_allclose(uv_b, uv_a, atol=1e-6)


@pytest.mark.skipif(not COPR_GCPS.exists(), reason="shared data not available")
def test_import_gcps_copr(truortho_provider, tmp_path):
    from qgis.core import QgsVectorLayer, QgsWkbTypes

    res = run(
        "truortho:importgcps",
        {
            "INPUT": str(COPR_GCPS),
            "CHECK_POINTS": "gcp01, gcp03",
            "GCPS": str(tmp_path / "gcps.gpkg"),
            "OBSERVATIONS": str(tmp_path / "obs.gpkg"),
        },
    )
    gcps = QgsVectorLayer(res["GCPS"], "g", "ogr")
    obs = QgsVectorLayer(res["OBSERVATIONS"], "o", "ogr")
    assert gcps.featureCount() == 10 and obs.featureCount() == 27
    assert QgsWkbTypes.hasZ(gcps.wkbType())
    assert obs.wkbType() == QgsWkbTypes.NoGeometry
    roles = {f["name"]: f["role"] for f in gcps.getFeatures()}
    assert roles["gcp01"] == "check" and roles["gcp03"] == "check" and roles["gcp02"] == "gcp"
    assert "UTM" in gcps.crs().description() or gcps.crs().authid() == "EPSG:32611"
    g2 = next(f for f in gcps.getFeatures() if f["name"] == "gcp02")
    assert g2.geometry().constGet().x() == pytest.approx(235269.88)


@pytest.mark.skipif(not COPR_GCPS.exists(), reason="shared data not available")
def test_gcps_attach_to_orientation(truortho_provider, tmp_path):
    """GCP layer + observation table (from importgcps) become the orientation's ground control."""
    from truortho.core.formats.colmap import write_colmap

    o = block()
    o.frame = LocalFrame("EPSG:32611", [235000.0, 3811000.0, 0.0])
    names = sorted({ln.split("\t")[5] for ln in COPR_GCPS.read_text().splitlines()[1:]})
    o.images = [Image(n, "cam", im.R, im.C) for n, im in zip(names, o.images * 4, strict=False)]
    write_colmap(o, tmp_path / "m")
    g = run(
        "truortho:importgcps",
        {
            "INPUT": str(COPR_GCPS),
            "CHECK_POINTS": "gcp05",
            "GCPS": str(tmp_path / "g.gpkg"),
            "OBSERVATIONS": str(tmp_path / "ob.gpkg"),
        },
    )
    # keep only observations on images of this block
    from qgis.core import QgsVectorLayer

    obs = QgsVectorLayer(g["OBSERVATIONS"], "o", "ogr")
    obs.startEditing()
    obs.deleteFeatures([f.id() for f in obs.getFeatures() if f["image"] not in names[:6]])
    obs.commitChanges()
    res = run(
        "truortho:importorientation",
        {
            "INPUT": str(tmp_path / "m" / "images.txt"),
            "GCPS": g["GCPS"],
            "OBSERVATIONS": obs,
            "OUTPUT": str(tmp_path / "o.json"),
            "CAMERAS": "memory:",
        },
    )
    back = Orientation.load(res["OUTPUT"])
    assert len(back.gcps) == 10
    assert {x.name for x in back.gcps if x.role == "check"} == {"gcp05"}
    assert sum(len(x.observations) for x in back.gcps) == obs.featureCount() > 0


# ------------------------------------------------------------------ bad input


def test_csv_without_crs_is_a_clear_error(truortho_provider, tmp_path):
    from qgis.core import QgsProcessingException

    o = block()
    src = tmp_path / "o.json"
    o.save(src)
    run("truortho:exportorientation", {"INPUT": str(src), "FORMAT": 1, "OUTPUT": str(tmp_path / "opk")})
    (tmp_path / "opk" / "exterior.prj").unlink()
    with pytest.raises(QgsProcessingException, match="CRS"):
        run(
            "truortho:importorientation",
            {
                "INPUT": str(tmp_path / "opk" / "exterior.csv"),
                "INTERIOR": str(tmp_path / "opk" / "interior.yaml"),
                "OUTPUT": str(tmp_path / "x.json"),
                "CAMERAS": "memory:",
            },
        )
    assert not (tmp_path / "x.json").exists()


def test_missing_image_is_named(truortho_provider, tmp_path):
    from qgis.core import QgsProcessingException

    from truortho.core.formats.colmap import write_colmap

    write_colmap(block(), tmp_path / "m")
    (tmp_path / "imgs").mkdir()
    (tmp_path / "imgs" / "img_0.png").write_bytes(b"x")
    with pytest.raises(QgsProcessingException, match="img_1.png"):
        run(
            "truortho:importorientation",
            {
                "INPUT": str(tmp_path / "m" / "images.txt"),
                "IMAGE_FOLDER": str(tmp_path / "imgs"),
                "OUTPUT": str(tmp_path / "x.json"),
                "CAMERAS": "memory:",
            },
        )
    assert not (tmp_path / "x.json").exists()


def test_unknown_camera_model_names_file_and_line(truortho_provider, tmp_path):
    from qgis.core import QgsProcessingException

    from truortho.core.formats.colmap import write_colmap

    write_colmap(block(), tmp_path / "m")
    cams = tmp_path / "m" / "cameras.txt"
    text = cams.read_text().replace("OPENCV", "THIN_PRISM_FISHEYE")
    cams.write_text(text)
    with pytest.raises(QgsProcessingException, match=r"cameras.txt.*line \d+.*THIN_PRISM_FISHEYE"):
        run(
            "truortho:importorientation",
            {
                "INPUT": str(tmp_path / "m" / "images.txt"),
                "OUTPUT": str(tmp_path / "x.json"),
                "CAMERAS": "memory:",
            },
        )


def test_gcp_layer_without_name_field(truortho_provider, tmp_path):
    from qgis.core import QgsFeature, QgsGeometry, QgsPoint, QgsProcessingException, QgsVectorLayer

    from truortho.core.formats.colmap import write_colmap

    write_colmap(block(), tmp_path / "m")
    layer = QgsVectorLayer("PointZ?crs=EPSG:32632&field=id:string", "bad_gcps", "memory")
    f = QgsFeature(layer.fields())
    f.setGeometry(QgsGeometry(QgsPoint(500010, 5600010, 300)))
    f.setAttributes(["a"])
    layer.dataProvider().addFeatures([f])
    with pytest.raises(QgsProcessingException, match="bad_gcps.*name"):
        run(
            "truortho:importorientation",
            {
                "INPUT": str(tmp_path / "m" / "images.txt"),
                "GCPS": layer,
                "OUTPUT": str(tmp_path / "x.json"),
                "CAMERAS": "memory:",
            },
        )


def test_malformed_gcp_list_names_line(truortho_provider, tmp_path):
    from qgis.core import QgsProcessingException

    bad = tmp_path / "gcp_list.txt"
    bad.write_text("EPSG:32632\n500000 5600000 10 100 200 a.jpg g1\n500000 5600000 ten 100 200 b.jpg g1\n")
    with pytest.raises(QgsProcessingException, match="line 3"):
        run("truortho:importgcps", {"INPUT": str(bad), "GCPS": "memory:", "OBSERVATIONS": "memory:"})


def test_unknown_check_point_name(truortho_provider, tmp_path):
    from qgis.core import QgsProcessingException

    f = tmp_path / "gcp_list.txt"
    f.write_text("EPSG:32632\n500000 5600000 10 100 200 a.jpg g1\n")
    with pytest.raises(QgsProcessingException, match="nope"):
        run(
            "truortho:importgcps",
            {"INPUT": str(f), "CHECK_POINTS": "nope", "GCPS": "memory:", "OBSERVATIONS": "memory:"},
        )


def test_every_algorithm_has_help(truortho_provider):
    for alg in truortho_provider.algorithms():
        assert len(alg.shortHelpString()) > 80, alg.id()
        if alg.name() == "environment":
            continue
        for p in alg.parameterDefinitions():
            assert p.help(), f"{alg.id()} parameter {p.name()} has no help"


def test_json_is_valid_after_import(truortho_provider, tmp_path):
    from truortho.core.formats.colmap import write_colmap

    write_colmap(block(), tmp_path / "m")
    res = run(
        "truortho:importorientation",
        {
            "INPUT": str(tmp_path / "m" / "images.txt"),
            "OUTPUT": str(tmp_path / "o.json"),
            "CAMERAS": "memory:",
        },
    )
    d = json.loads(Path(res["OUTPUT"]).read_text())
    assert d["format"] == "truortho-orientation" and d["version"] == 1
