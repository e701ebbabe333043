"""truortho:detecttargets through processing.run on synthetic photos with ArUco markers and discs."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from truortho.core.synthetic.targets import render_homography

pytestmark = pytest.mark.qgis


def run(params):
    import processing

    return processing.run("truortho:detecttargets", params)


def _photo(seed: int, ids, shape=(300, 460)):
    """Markers (10 px modules + one white module) pasted with a perspective warp on noisy texture."""
    rng = np.random.default_rng(seed)
    d = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50)
    img = cv2.GaussianBlur(rng.uniform(0.3, 0.7, shape), (0, 0), 4)
    truth = {}
    for k, mid in enumerate(ids):
        pat = np.pad(cv2.aruco.generateImageMarker(d, mid, 60, borderBits=1) / 255.0, 10, constant_values=1.0)
        c = (pat.shape[0] - 1) / 2
        th = rng.uniform(0, 2 * np.pi)
        A = rng.uniform(0.4, 0.6) * np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
        H = np.eye(3)
        H[:2, :2] = A @ np.diag([1.0, rng.uniform(0.85, 1.0)])
        H[:2, 2] = np.array([90 + 150 * k, 150]) + rng.uniform(-15, 15, 2) - H[:2, :2] @ [c, c]
        H[2, :2] = rng.uniform(-2e-4, 2e-4, 2)
        q = H @ [c, c, 1.0]
        truth[mid] = q[:2] / q[2]
        cover = render_homography(np.ones_like(pat), H, shape, background=0.0)
        img = img * (1 - cover) + render_homography(pat, H, shape, background=0.0)
    img = np.clip(img * 0.8 + 0.1 + rng.normal(0, 0.01, shape), 0, 1)
    return (img * 255).round().astype(np.uint8), truth


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    root = tmp_path_factory.mktemp("aruco")
    truth = {}
    for i in range(3):
        img, t = _photo(i, (0, 1, 2))
        cv2.imwrite(str(root / f"photo_{i}.png"), cv2.cvtColor(img, cv2.COLOR_GRAY2BGR))
        truth[f"photo_{i}.png"] = t
    return root, truth


def _rows(path):
    from qgis.core import QgsVectorLayer

    layer = QgsVectorLayer(str(path), "t", "ogr")
    assert layer.isValid()
    names = [f.name() for f in layer.fields()]
    return names, [dict(zip(names, f.attributes(), strict=True)) for f in layer.getFeatures()]


def test_aruco_observation_table(truortho_provider, folder, tmp_path):
    root, truth = folder
    out = tmp_path / "obs.gpkg"
    res = run({"IMAGES": str(root), "TARGET": 0, "MARKER_IDS": "0=G0, 2=G2", "OUTPUT": str(out)})
    names, rows = _rows(res["OUTPUT"])
    for f in ("gcp", "image", "x", "y", "score", "sigma_x", "sigma_y", "flag"):
        assert f in names
    assert sorted((r["gcp"], r["image"]) for r in rows) == sorted(
        (g, f"photo_{i}.png") for g in ("G0", "G2") for i in range(3)
    )
    errs = []
    for r in rows:
        t = truth[r["image"]][int(r["gcp"][1:])]
        errs.append(np.hypot(r["x"] - t[0], r["y"] - t[1]))
        assert r["flag"] == "ok" and r["score"] > 0.8 and 0 < r["sigma_x"] < 0.2
    assert max(errs) < 0.3
    assert float(np.sqrt(np.mean(np.square(errs)))) < 0.1


def test_clear_errors_and_no_table_on_failure(truortho_provider, folder, tmp_path):
    from qgis.core import QgsProcessingException

    root, _ = folder
    out = tmp_path / "bad.gpkg"
    with pytest.raises(QgsProcessingException, match="not a folder"):
        run({"IMAGES": str(tmp_path / "nowhere"), "MARKER_IDS": "0=G0", "OUTPUT": str(out)})
    with pytest.raises(QgsProcessingException, match="ID=NAME"):
        run({"IMAGES": str(root), "MARKER_IDS": "zero=G0", "OUTPUT": str(out)})
    with pytest.raises(QgsProcessingException, match="MARKER_IDS"):
        run({"IMAGES": str(root), "OUTPUT": str(out)})
    with pytest.raises(QgsProcessingException, match="ORIENTATION and GCPS"):
        run({"IMAGES": str(root), "TARGET": 1, "OUTPUT": str(out)})
    assert not out.exists()


def test_mapping_names_must_be_in_the_gcp_layer(truortho_provider, folder, tmp_path):
    from qgis.core import QgsFeature, QgsField, QgsGeometry, QgsPoint, QgsProcessingException, QgsVectorLayer
    from qgis.PyQt.QtCore import QVariant

    root, _ = folder
    layer = QgsVectorLayer("PointZ?crs=EPSG:32632", "gcps", "memory")
    layer.dataProvider().addAttributes([QgsField("name", QVariant.String)])
    layer.updateFields()
    f = QgsFeature(layer.fields())
    f.setGeometry(QgsGeometry(QgsPoint(500000.0, 5600000.0, 300.0)))
    f.setAttributes(["G0"])
    layer.dataProvider().addFeatures([f])
    out = tmp_path / "obs.gpkg"
    with pytest.raises(QgsProcessingException, match="GX.*not in the GCP layer"):
        run({"IMAGES": str(root), "MARKER_IDS": "0=G0,1=GX", "GCPS": layer, "OUTPUT": str(out)})
    assert not out.exists()
    res = run({"IMAGES": str(root), "MARKER_IDS": "0=G0", "GCPS": layer, "OUTPUT": str(out)})
    _, rows = _rows(res["OUTPUT"])
    assert {r["gcp"] for r in rows} == {"G0"} and len(rows) == 3


def test_table_sigmas_become_measurement_weights(truortho_provider, folder, tmp_path):
    """The table's sigma_x/sigma_y reach GCP.obs_sigma (the bundle weights); a bad sigma is named."""
    from qgis.core import QgsFeature, QgsField, QgsProcessingException, QgsVectorLayer
    from qgis.PyQt.QtCore import QVariant

    from truortho.core.orientation import GCP
    from truortho.processing.layers import read_observation_table

    root, _ = folder
    res = run({"IMAGES": str(root), "MARKER_IDS": "0=G0", "OUTPUT": str(tmp_path / "obs.gpkg")})
    table = QgsVectorLayer(res["OUTPUT"], "obs", "ogr")
    gcps = [GCP("G0", [0.0, 0.0, 0.0])]
    read_observation_table(table, gcps)
    assert len(gcps[0].observations) == 3
    for f in table.getFeatures():
        expected = np.sqrt((f["sigma_x"] ** 2 + f["sigma_y"] ** 2) / 2)
        assert gcps[0].obs_sigma[f["image"]] == pytest.approx(expected)

    mem = QgsVectorLayer("None", "obs", "memory")
    mem.dataProvider().addAttributes(
        [QgsField(n, QVariant.String) for n in ("gcp", "image")]
        + [QgsField(n, QVariant.Double) for n in ("x", "y", "sigma")]
    )
    mem.updateFields()
    rows = [("G0", "a.png", 1.0, 2.0, None), ("G0", "b.png", 3.0, 4.0, 0.25)]
    for r in rows:
        f = QgsFeature(mem.fields())
        f.setAttributes(list(r))
        mem.dataProvider().addFeatures([f])
    gcps = [GCP("G0", [0.0, 0.0, 0.0])]
    read_observation_table(mem, gcps)
    assert gcps[0].obs_sigma == {"b.png": 0.25}  # an empty sigma keeps the default
    f = QgsFeature(mem.fields())
    f.setAttributes(["G0", "c.png", 1.0, 1.0, -1.0])
    mem.dataProvider().addFeatures([f])
    with pytest.raises(QgsProcessingException, match="sigma must be positive"):
        read_observation_table(mem, [GCP("G0", [0.0, 0.0, 0.0])])


def test_without_opencv_the_algorithm_says_so_instead_of_failing(monkeypatch, qgis_processing_ready):
    """Registering the algorithm must not raise when OpenCV is missing (an exception while the
    provider loads aborts QGIS): it loads, and canExecute names the missing package."""
    import sys

    from truortho.processing.algorithms.detecttargets import DetectTargetsAlgorithm

    monkeypatch.setitem(sys.modules, "truortho.core.gcp.targets", None)  # import -> ImportError
    alg = DetectTargetsAlgorithm()
    alg.initAlgorithm()
    ok, why = alg.canExecute()
    assert not ok and why
    assert alg.parameterDefinition("DICTIONARY") is not None
