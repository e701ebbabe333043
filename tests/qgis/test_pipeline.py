"""truortho:pipeline through processing.run: products from a reused orientation (the orientation stage
itself runs in the model test and the demo), loading into the project, and bad input."""

from __future__ import annotations

import json
import shutil

import pytest
from qgis.core import QgsProcessingException

pytestmark = pytest.mark.qgis


@pytest.fixture(scope="module")
def block(tmp_path_factory):
    from truortho.core.synthetic import SceneConfig, make_scene

    cfg = SceneConfig(
        extent=(-20.0, -15.0, 20.0, 15.0), n_buildings=2, building_size=(7.0, 11.0), building_gap=3.0,
        tower=False, image_size=(240, 180), focal_px=300.0, n_oblique=0, seed=5,
    )  # fmt: skip
    scene = make_scene(cfg)
    root = tmp_path_factory.mktemp("pipeline")
    scene.write(root / "block")
    return scene, root


def _folder_with_orientation(scene, root, tmp_path):
    out = tmp_path / "products"
    out.mkdir()
    o = scene.orientation
    o.image_root = str((root / "block").resolve())
    o.save(out / "orientation.json")
    return out


@pytest.mark.slow
def test_pipeline_reusing_the_orientation(truortho_provider, block, tmp_path):
    import processing
    from qgis.core import QgsProcessingContext, QgsProject, QgsRasterLayer

    scene, root = block
    out = _folder_with_orientation(scene, root, tmp_path)
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())
    res = processing.run(
        "truortho:pipeline",
        {"REUSE_ORIENTATION": True, "RESOLUTION": 0.6, "EXECUTOR": 0, "OUTPUT_FOLDER": str(out)},
        context=context,
    )
    for key, name in (
        ("ORIENTATION", "orientation.json"), ("REPORT", "report.html"), ("DSM", "dsm.tif"),
        ("POINT_CLOUD", "pointcloud.laz"), ("MESH", "mesh.ply"), ("TRUE_ORTHO", "trueortho.tif"),
        ("OCCLUSION", "occlusion.tif"), ("SEAMLINES", "seamlines.gpkg"),
    ):  # fmt: skip
        assert res[key] == str(out / name) and (out / name).exists(), key
    dsm = QgsRasterLayer(res["DSM"], "dsm")
    assert dsm.isValid() and dsm.crs().authid() == "EPSG:32632"
    rep = json.loads((out / "report.json").read_text())
    assert rep["summary"]["images oriented"] == len(scene.orientation.images)
    assert rep["summary"]["tiles ran on"] == "inprocess"
    # the GUI run registers the products to load on completion
    assert context.willLoadLayerOnCompletion(res["TRUE_ORTHO"]) and context.willLoadLayerOnCompletion(
        res["DSM"]
    )


def test_pipeline_executor_parameters(truortho_provider):
    """One EXECUTOR (inprocess | local | scheduler, default inprocess) and SCHEDULER_ADDRESS, advanced."""
    from qgis.core import QgsApplication, QgsProcessingParameterDefinition

    alg = QgsApplication.processingRegistry().algorithmById("truortho:pipeline")
    executor = alg.parameterDefinition("EXECUTOR")
    address = alg.parameterDefinition("SCHEDULER_ADDRESS")
    assert executor is not None and address is not None
    assert [o.split(":")[0] for o in executor.options()] == ["inprocess", "local", "scheduler"]
    assert executor.defaultValue() == 0
    assert address.flags() & QgsProcessingParameterDefinition.FlagOptional
    for p in (executor, address):
        assert p.flags() & QgsProcessingParameterDefinition.FlagAdvanced, p.name()


def test_pipeline_restore_chroma_reaches_the_true_ortho(truortho_provider, monkeypatch, tmp_path):
    """RESTORE_CHROMA (advanced, default on, as truortho:trueortho's) is handed to the workflow's
    true-ortho stage."""
    import processing
    from qgis.core import QgsApplication, QgsProcessingParameterDefinition

    from truortho.core import workflow

    alg = QgsApplication.processingRegistry().algorithmById("truortho:pipeline")
    p = alg.parameterDefinition("RESTORE_CHROMA")
    assert p.defaultValue() is True and p.flags() & QgsProcessingParameterDefinition.FlagAdvanced
    seen = []

    def fake(images, folder, gcps, crs, cfg, progress):
        seen.append(cfg.ortho.restore_chroma)
        raise workflow.InputError("stop here")

    monkeypatch.setattr(workflow, "run_workflow", fake)
    (tmp_path / "images").mkdir()
    for on in (False, True):
        with pytest.raises(QgsProcessingException, match="stop here"):
            processing.run(
                "truortho:pipeline",
                {"IMAGES": str(tmp_path / "images"), "RESTORE_CHROMA": on,
                 "OUTPUT_FOLDER": str(tmp_path / "o")},  # fmt: skip
            )
    assert seen == [False, True]


def test_pipeline_bad_input(truortho_provider, block, tmp_path):
    import processing

    scene, root = block
    with pytest.raises(QgsProcessingException, match="IMAGES"):
        processing.run("truortho:pipeline", {"OUTPUT_FOLDER": str(tmp_path / "a")})
    with pytest.raises(QgsProcessingException, match="IMAGES"):
        processing.run(
            "truortho:pipeline", {"IMAGES": str(tmp_path / "missing"), "OUTPUT_FOLDER": str(tmp_path)}
        )
    images = root / "block"
    with pytest.raises(QgsProcessingException, match="RESOLUTION"):
        processing.run(
            "truortho:pipeline",
            {"IMAGES": str(images), "RESOLUTION": -1, "OUTPUT_FOLDER": str(tmp_path / "b")},
        )
    # a plain tcp:// scheduler off this machine: refused before the orientation starts
    with pytest.raises(QgsProcessingException, match="unauthenticated"):
        processing.run(
            "truortho:pipeline",
            {
                "IMAGES": str(images),
                "EXECUTOR": 2,
                "SCHEDULER_ADDRESS": "tcp://198.51.100.7:8786",
                "OUTPUT_FOLDER": str(tmp_path / "s"),
            },
        )
    assert not (tmp_path / "s" / "orientation.json").exists()
    # GCPS without OBSERVATIONS
    from qgis.core import QgsVectorLayer

    gcps = QgsVectorLayer("PointZ?crs=EPSG:32632&field=name:string&field=role:string", "gcps", "memory")
    with pytest.raises(QgsProcessingException, match="OBSERVATIONS"):
        processing.run(
            "truortho:pipeline", {"IMAGES": str(images), "GCPS": gcps, "OUTPUT_FOLDER": str(tmp_path / "c")}
        )
    # a folder without photos: the orientation says what it expected
    empty = tmp_path / "empty"
    empty.mkdir()
    shutil.copy(__file__, empty / "notes.txt")
    with pytest.raises(QgsProcessingException):
        processing.run("truortho:pipeline", {"IMAGES": str(empty), "OUTPUT_FOLDER": str(tmp_path / "d")})
    assert not (tmp_path / "d" / "trueortho.tif").exists()
