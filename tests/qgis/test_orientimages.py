"""truortho:orientimages through processing.run on a small synthetic block."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

pytestmark = pytest.mark.qgis


@pytest.fixture(scope="module")
def block(tmp_path_factory):
    from truortho.core.synthetic import SceneConfig, make_scene

    scene = make_scene(
        SceneConfig(image_size=(400, 300), focal_px=500.0, n_gcps=10, check_fraction=0.3, seed=2)
    )
    root = tmp_path_factory.mktemp("orient")
    scene.write(root / "scene")
    images = root / "images"
    images.mkdir()
    for p in sorted((root / "scene").glob("img_*.png")):
        shutil.copy(p, images / p.name)
    (images / "notes.txt").write_text("flight notes, not an image")
    return scene, root


def _tiny_png() -> bytes:
    import io

    import numpy as np
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(np.zeros((60, 80, 3), np.uint8)).save(buf, format="PNG")
    return buf.getvalue()


def _gcp_layer(folder: Path, crs: str):
    """A one-point GCP list in ``crs`` imported with truortho:importgcps: (GCP layer, observations)."""
    (folder / "gcps.txt").write_text(
        f"{crs}\n8.5 47.3 400.0 10 20 i0.png g1\n8.5 47.3 400.0 12 22 i1.png g1\n"
    )
    g = run(
        "truortho:importgcps",
        {
            "INPUT": str(folder / "gcps.txt"),
            "GCPS": str(folder / "g.gpkg"),
            "OBSERVATIONS": str(folder / "o.gpkg"),
        },
    )
    return g["GCPS"], g["OBSERVATIONS"]


def run(alg, params):
    import processing

    return processing.run(alg, params)


def test_orientimages_with_gcps(truortho_provider, block, tmp_path):
    from qgis.core import QgsVectorLayer, QgsWkbTypes

    scene, root = block
    checks = ",".join(g.name for g in scene.orientation.gcps if g.role == "check")
    g = run(
        "truortho:importgcps",
        {
            "INPUT": str(root / "scene" / "gcp_list.txt"),
            "CHECK_POINTS": checks,
            "GCPS": str(tmp_path / "g.gpkg"),
            "OBSERVATIONS": str(tmp_path / "o.gpkg"),
        },
    )
    # the GCP layer in another CRS (geographic): reprojected to the output CRS by the algorithm
    g4326 = run(
        "native:reprojectlayer",
        {"INPUT": g["GCPS"], "TARGET_CRS": "EPSG:4326", "OUTPUT": str(tmp_path / "g4326.gpkg")},
    )["OUTPUT"]
    assert QgsVectorLayer(g4326, "g", "ogr").crs().authid() == "EPSG:4326"
    res = run(
        "truortho:orientimages",
        {
            "IMAGES": str(root / "images"),
            "GCPS": g4326,
            "OBSERVATIONS": g["OBSERVATIONS"],
            "CRS": "EPSG:32632",
            "WORKING_SIZE": 400,
            "ORIENTATION": str(tmp_path / "orientation.json"),
            "REPORT": str(tmp_path / "r.html"),
            "CAMERAS": str(tmp_path / "cams.gpkg"),
            "TIE_POINTS": str(tmp_path / "ties.gpkg"),
            "GCP_RESIDUALS": str(tmp_path / "res.gpkg"),
        },
    )
    d = json.loads(Path(res["ORIENTATION"]).read_text())
    assert d["crs"] == "EPSG:32632" and len(d["images"]) == len(scene.orientation.images)
    report = json.loads((tmp_path / "r.json").read_text())
    assert any("notes.txt" in w for w in report["warnings"]), report["warnings"]
    gsd = scene.config.flying_height / scene.config.focal_px
    assert report["data"]["check_rmse"]["xy"] < gsd
    html = Path(res["REPORT"]).read_text()
    assert html.count("data:image/png;base64") >= 3 and "Check points" in html
    cams = QgsVectorLayer(res["CAMERAS"], "c", "ogr")
    ties = QgsVectorLayer(res["TIE_POINTS"], "t", "ogr")
    resid = QgsVectorLayer(res["GCP_RESIDUALS"], "r", "ogr")
    assert cams.featureCount() == len(scene.orientation.images)
    assert ties.featureCount() > 500 and QgsWkbTypes.hasZ(ties.wkbType())
    assert min(f["multiplicity"] for f in ties.getFeatures()) >= 2
    roles = {f["role"] for f in resid.getFeatures()}
    assert roles == {"gcp", "check"} and resid.crs().authid() == "EPSG:32632"


def test_orientimages_bad_input(truortho_provider, tmp_path):
    from qgis.core import QgsProcessingException

    (tmp_path / "one").mkdir()
    (tmp_path / "one" / "a.txt").write_text("x")
    with pytest.raises(QgsProcessingException, match="at least two images"):
        run(
            "truortho:orientimages",
            {
                "IMAGES": str(tmp_path / "one"),
                "ORIENTATION": str(tmp_path / "o.json"),
                "REPORT": str(tmp_path / "r.html"),
                "CAMERAS": "memory:",
            },
        )
    assert not (tmp_path / "o.json").exists()
    # ground control in a geographic CRS without an output CRS: the block needs metres
    (tmp_path / "two").mkdir()
    for k in range(2):
        (tmp_path / "two" / f"i{k}.png").write_bytes(_tiny_png())
    gcp = _gcp_layer(tmp_path, "EPSG:4326")
    with pytest.raises(QgsProcessingException, match="geographic"):
        run(
            "truortho:orientimages",
            {
                "IMAGES": str(tmp_path / "two"),
                "GCPS": gcp[0],
                "OBSERVATIONS": gcp[1],
                "ORIENTATION": str(tmp_path / "o.json"),
                "REPORT": str(tmp_path / "r.html"),
                "CAMERAS": "memory:",
            },
        )
    assert not (tmp_path / "o.json").exists()
    with pytest.raises(QgsProcessingException, match="IMAGES"):
        run(
            "truortho:orientimages",
            {
                "ORIENTATION": str(tmp_path / "o.json"),
                "REPORT": str(tmp_path / "r.html"),
                "CAMERAS": "memory:",
            },
        )


def test_images_that_do_not_overlap(truortho_provider, tmp_path):
    import numpy as np
    from PIL import Image
    from qgis.core import QgsProcessingException

    rng = np.random.default_rng(0)
    for k in range(3):
        Image.fromarray(rng.integers(0, 255, (200, 300, 3), dtype=np.uint8)).save(tmp_path / f"n{k}.png")
    with pytest.raises(QgsProcessingException, match="do not overlap|could not be oriented|no image pair"):
        run(
            "truortho:orientimages",
            {
                "IMAGES": str(tmp_path),
                "ORIENTATION": str(tmp_path / "o.json"),
                "REPORT": str(tmp_path / "r.html"),
                "CAMERAS": "memory:",
            },
        )
    assert not (tmp_path / "o.json").exists()
