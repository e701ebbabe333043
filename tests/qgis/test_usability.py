"""Frictions a new user met from a fresh clone (issue 20, part 4), each pinned by a test:

* ``qgis_process help`` and the toolbox show the help as plain lines (no HTML, no entities);
* a failed run prints its error once through ``qgis_process``;
* optional outputs (CAMERAS, REPORT) need not be given, through ``qgis_process`` too;
* caches stay out of the output folder (per-user cache folder, TRUORTHO_CACHE_DIR);
* the pipeline help names every product of the products folder.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.qgis

REPO_ROOT = Path(__file__).resolve().parents[2]




def _run(alg, params):
    import processing

    return processing.run(alg, params)


def _small_orientation(tmp_path: Path) -> Path:
    from truortho.core.geometry import Camera, LocalFrame, opk_to_matrix
    from truortho.core.orientation import Image, Orientation, SparsePoints

    cam = Camera(800, 600, 700.0, 700.0, 399.5, 299.5, id="cam")
    images = [
        Image(f"img_{i}.png", "cam", opk_to_matrix(0.0, 0.0, 10.0 * i, degrees=True), [30.0 * i, 0.0, 120.0])
        for i in range(3)
    ]
    pts = SparsePoints(np.array([[10.0, 5.0, 1.0], [40.0, -5.0, 2.0]]))
    o = Orientation(LocalFrame("EPSG:32632", [500000.0, 5600000.0, 300.0]), {"cam": cam}, images, pts)
    path = tmp_path / "in.json"
    o.save(path)
    return path


def test_help_is_plain_text(truortho_provider):
    for alg in truortho_provider.algorithms():
        text = alg.shortHelpString()
        # the toolbox wraps each line in <p>; the terminal prints it as it is: no markup either way
        assert not any(c in text for c in "<>&"), (alg.id(), [c for c in "<>&" if c in text])
        for p in alg.parameterDefinitions():
            if alg.name() != "environment":
                assert f"\n{p.name()}: " in text, f"{alg.id()}: {p.name()} missing from the help"


def test_qgis_process_help_and_single_error(tmp_path, run_qgis_process):
    out = run_qgis_process("help", "truortho:orientimages")
    assert out.returncode == 0, out.stderr
    assert "&#" not in out.stdout and "<p>" not in out.stdout and "<dt>" not in out.stdout
    assert "\nIMAGES: Folder of the images" in out.stdout

    missing = tmp_path / "no_such_folder"
    res = run_qgis_process(
        "run", "truortho:orientimages", "--", f"IMAGES={missing}", f"ORIENTATION={tmp_path / 'o.json'}"
    )
    assert res.returncode != 0
    message = f"{missing} is not a folder"
    assert (res.stdout + res.stderr).count(message) == 1, res.stderr
    assert f"ERROR:\tIMAGES: {message}" in res.stderr
    assert "mandatory parameters" not in res.stderr  # CAMERAS and REPORT are optional


def test_importorientation_without_cameras_through_qgis_process(tmp_path, run_qgis_process):
    src = _small_orientation(tmp_path)
    res = run_qgis_process(
        "run", "truortho:importorientation", "--", f"INPUT={src}", f"OUTPUT={tmp_path / 'o.json'}"
    )
    assert res.returncode == 0, res.stderr
    assert json.loads((tmp_path / "o.json").read_text())["images"]
    assert "CAMERAS" not in res.stdout.split("Results")[-1]


def test_orientimages_needs_only_inputs_and_keeps_caches_out(truortho_provider, tmp_path, monkeypatch):
    from truortho.core.cache import cache_dir
    from truortho.core.synthetic import SceneConfig, make_scene

    scene = make_scene(SceneConfig(image_size=(400, 300), focal_px=500.0, n_gcps=6, seed=5))
    scene.write(tmp_path / "scene")
    images = tmp_path / "images"
    images.mkdir()
    for p in sorted((tmp_path / "scene").glob("img_*.png")):
        shutil.copy(p, images / p.name)
    cache = tmp_path / "user-cache"
    monkeypatch.setenv("TRUORTHO_CACHE_DIR", str(cache))
    g = _run(
        "truortho:importgcps",
        {"INPUT": str(tmp_path / "scene" / "gcp_list.txt"), "GCPS": "memory:", "OBSERVATIONS": "memory:"},
    )
    out = tmp_path / "out"
    out.mkdir()
    res = _run(
        "truortho:orientimages",
        {
            "IMAGES": str(images),
            "GCPS": g["GCPS"],
            "OBSERVATIONS": g["OBSERVATIONS"],
            "WORKING_SIZE": 400,
            "ORIENTATION": str(out / "block.json"),
        },
    )
    assert "CAMERAS" not in res
    assert json.loads((out / "block.json").read_text())["images"]
    assert Path(res["REPORT"]) == out / "block_report.html" and (out / "block_report.html").is_file()
    # only products in the output folder; the features went to the user cache
    assert sorted(p.name for p in out.iterdir()) == ["block.json", "block_report.html", "block_report.json"]
    assert len(list(cache_dir("features").glob("*.npz"))) == len(list(images.iterdir()))


def test_pipeline_help_names_every_product(truortho_provider):
    from truortho.core.products import PRODUCT_DESCRIPTIONS
    from truortho.core.workflow import PRODUCTS

    names = set(PRODUCTS.values()) | {"report.json"}
    assert set(PRODUCT_DESCRIPTIONS) == names
    text = truortho_provider.algorithm("pipeline").shortHelpString()
    folder_help = next(line for line in text.split("\n") if line.startswith("OUTPUT_FOLDER: "))
    for name in sorted(names):
        assert name in folder_help, name
    assert ".truortho-cache" not in text and "TRUORTHO_CACHE_DIR" in folder_help
