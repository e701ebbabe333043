"""The shipped Processing model truortho:truortho_chain (processing/models/truortho_chain.model3) run
through qgis_process on a small synthetic block with ground control: orient images -> OSGM -> DSM
filter -> true orthophoto and mesh; every output written, in the block's CRS and not empty."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.qgis

REPO_ROOT = Path(__file__).resolve().parents[2]
MODEL_ID = "truortho:truortho_chain"
RES = 0.5

#: model output (parameter name ``<child>:<output>``) -> file name
OUTPUTS = {
    "orientimages:orientation": "orientation.json",
    "orientimages:report": "report.html",
    "dsmfilter:dsm": "dsm.tif",
    "osgm:pointcloud": "points.laz",
    "mesh:mesh": "mesh.ply",
    "trueortho:trueortho": "ortho.tif",
    "trueortho:occlusion": "occlusion.tif",
    "trueortho:seamlines": "seamlines.gpkg",
}




@pytest.fixture(scope="module")
def block(tmp_path_factory, run_qgis_process):
    """A 6-image nadir block: images alone in images/, the GCP layer and table from its gcp_list.txt."""
    if not (REPO_ROOT / ".venv" / "qgis-config").is_dir():
        pytest.fail("run scripts/setup.sh (make setup) first: no .venv/qgis-config")
    from truortho.core.synthetic import SceneConfig, make_scene

    scene = make_scene(
        SceneConfig(
            extent=(-20.0, -15.0, 20.0, 15.0),
            n_buildings=2,
            building_size=(7.0, 11.0),
            building_gap=3.0,
            tower=False,
            image_size=(320, 240),
            focal_px=300.0,
            n_oblique=0,
            seed=5,
        )
    )
    root = tmp_path_factory.mktemp("model")
    scene.write(root / "scene")  # its orientation.json is not given to the model
    images = root / "images"
    images.mkdir()
    for im in scene.orientation.images:
        shutil.copy(root / "scene" / im.name, images / im.name)
    checks = ",".join(g.name for g in scene.orientation.gcps if g.role == "check")
    proc = run_qgis_process(
        "run",
        "truortho:importgcps",
        "--",
        f"INPUT={root / 'scene' / 'gcp_list.txt'}",
        f"CHECK_POINTS={checks}",
        f"GCPS={root / 'gcps.gpkg'}",
        f"OBSERVATIONS={root / 'observations.gpkg'}",
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return scene, root


def test_model_listed(run_qgis_process):
    proc = run_qgis_process("help", MODEL_ID)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    for name in ("IMAGES", "GCPS", "OBSERVATIONS", "CRS", "RESOLUTION", *OUTPUTS):
        assert f"{name}:" in proc.stdout, name


@pytest.mark.slow
def test_model_runs_whole_chain(block, tmp_path, run_qgis_process):
    import rasterio
    from osgeo import ogr

    from truortho.core.surface.pointcloud import read_point_cloud

    scene, root = block
    crs = scene.config.crs
    out = {name: tmp_path / fname for name, fname in OUTPUTS.items()}
    proc = run_qgis_process(
        "run",
        MODEL_ID,
        "--",
        f"IMAGES={root / 'images'}",
        f"GCPS={root / 'gcps.gpkg'}",
        f"OBSERVATIONS={root / 'observations.gpkg'}",
        f"CRS={crs}",
        f"RESOLUTION={RES}",
        *(f"{name}={path}" for name, path in out.items()),
        timeout=900,
    )
    log = proc.stdout + proc.stderr
    assert proc.returncode == 0, log
    assert "Model processed OK" in log, log
    for name, path in out.items():
        assert path.is_file() and path.stat().st_size > 0, f"{name}: {path} missing\n{log}"

    # orientation: every image oriented, in the requested CRS
    o = json.loads(out["orientimages:orientation"].read_text())
    assert o["crs"] == crs
    assert sorted(im["name"] for im in o["images"]) == sorted(im.name for im in scene.orientation.images)
    assert not o["metadata"].get("unregistered")
    report = json.loads(out["orientimages:report"].with_suffix(".json").read_text())
    assert len(report["data"]["registered_images"]) == len(scene.orientation.images)
    assert report["data"]["check_rmse"]["xy"] < scene.config.gsd * 3
    assert "<html" in out["orientimages:report"].read_text().lower()

    # filtered DSM: the block's CRS, the requested cell size, mostly valid, plausible heights
    with rasterio.open(out["dsmfilter:dsm"]) as ds:
        assert ds.crs.to_string() == crs
        assert ds.res == pytest.approx((RES, RES))
        dsm = ds.read(1, masked=True)
        dsm_bounds = ds.bounds
    assert dsm.count() > 0.5 * dsm.size
    x0, y0, x1, y1 = scene.config.extent
    assert dsm_bounds.left < x0 + 500000 and dsm_bounds.right > x1 + 500000
    heights = dsm.compressed()
    assert np.isfinite(heights).all() and -20 < np.median(heights) < 20

    # true orthophoto: RGB + alpha on the DSM grid, covered
    with rasterio.open(out["trueortho:trueortho"]) as ds:
        assert ds.crs.to_string() == crs
        assert ds.count == 4 and ds.res == pytest.approx((RES, RES))
        alpha = ds.read(4)
        rgb = ds.read((1, 2, 3))
    # the surface's holes stay empty; nearly every cell with a height is coloured
    assert alpha.shape == dsm.shape
    assert (alpha[~dsm.mask] > 0).mean() > 0.95
    assert rgb[:, alpha > 0].std() > 5  # image content, not a constant fill
    with rasterio.open(out["trueortho:occlusion"]) as ds:
        assert ds.crs.to_string() == crs
        assert set(np.unique(ds.read(1))) <= {0, 1, 255}

    seams = ogr.Open(str(out["trueortho:seamlines"]))
    layer = seams.GetLayer(0)
    assert 1 <= layer.GetFeatureCount() <= len(scene.orientation.images)
    assert layer.GetSpatialRef().GetAuthorityCode(None) == crs.split(":")[1]
    seams = None

    with open(out["mesh:mesh"], "rb") as fh:
        header = fh.read(1 << 16).split(b"end_header")[0]
    assert header.startswith(b"ply")
    n_vertices = int(header.split(b"element vertex ")[1].split()[0])
    assert n_vertices > 100

    cloud = read_point_cloud(str(out["osgm:pointcloud"]))
    assert len(cloud.xyz) > 1000
    # the same inputs through truortho:pipeline give the same products
    pipe = tmp_path / "pipeline"
    proc = run_qgis_process(
        "run", "truortho:pipeline", "--", f"IMAGES={root / 'images'}", f"GCPS={root / 'gcps.gpkg'}",
        f"OBSERVATIONS={root / 'observations.gpkg'}", f"CRS={crs}", f"RESOLUTION={RES}",
        f"OUTPUT_FOLDER={pipe}",
        timeout=900,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stdout + proc.stderr
    from truortho.core.orientation import Orientation

    om, op = Orientation.load(out["orientimages:orientation"]), Orientation.load(pipe / "orientation.json")
    assert [im.name for im in om.images] == [im.name for im in op.images]
    assert np.abs(om.world_centers() - op.world_centers()).max() < 1e-6
    pairs = (
        ("dsmfilter:dsm", "dsm.tif"),
        ("trueortho:trueortho", "trueortho.tif"),
        ("trueortho:occlusion", "occlusion.tif"),
    )
    for name, fname in pairs:
        with rasterio.open(out[name]) as a, rasterio.open(pipe / fname) as b:
            assert a.transform == b.transform and a.crs == b.crs
            da, db = a.read(masked=True), b.read(masked=True)
            assert np.array_equal(da.mask, db.mask), name
            assert np.allclose(da.filled(0), db.filled(0), atol=1e-4), name


def test_model_bad_input(tmp_path, run_qgis_process):
    """A missing image folder stops the model at its first step with a message naming IMAGES."""
    out = {name: tmp_path / fname for name, fname in OUTPUTS.items()}
    proc = run_qgis_process(
        "run", MODEL_ID, "--", f"IMAGES={tmp_path / 'nowhere'}", "CRS=EPSG:32632",
        *(f"{name}={path}" for name, path in out.items()),
    )  # fmt: skip
    assert proc.returncode != 0
    assert "IMAGES" in proc.stdout + proc.stderr
    assert not any(p.exists() for p in out.values())


def test_shipped_model_is_what_make_model_writes(tmp_path):
    """processing/models/truortho_chain.model3 is regenerated from the algorithms (scripts/make_model.py):
    a changed default or a new mandatory parameter of a child must reach the shipped model, or the
    model and truortho:pipeline make different products (PATHS 8 against 16 did)."""
    import subprocess
    import sys

    root = Path(__file__).resolve().parents[2]
    out = tmp_path / "chain.model3"
    proc = subprocess.run(
        [sys.executable, "-P", str(root / "scripts" / "make_model.py"), "--output", str(out)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stdout + proc.stderr
    shipped = root / "processing" / "models" / "truortho_chain.model3"
    assert out.read_bytes() == shipped.read_bytes(), (
        "the shipped model is stale: run `source scripts/env.sh && python -P scripts/make_model.py`"
    )
