"""The end-to-end chain (core/workflow.py) from an existing orientation: OSGM, filter, mesh, true ortho."""

from __future__ import annotations

import json

import numpy as np
import pytest

from truortho.core.errors import InputError
from truortho.core.osgm import OsgmConfig
from truortho.core.progress import CallbackProgress
from truortho.core.rasterio_io import read_raster
from truortho.core.synthetic import SceneConfig, make_scene
from truortho.core.workflow import PRODUCTS, WorkflowConfig, run_workflow


@pytest.mark.slow
def test_workflow_products_and_report_from_a_reused_orientation(tmp_path):
    cfg = SceneConfig(
        extent=(-20.0, -15.0, 20.0, 15.0), n_buildings=2, building_size=(7.0, 11.0), building_gap=3.0,
        tower=False, image_size=(240, 180), focal_px=300.0, n_oblique=0, seed=5,
    )  # fmt: skip
    scene = make_scene(cfg)
    scene.write(tmp_path / "block")
    out = tmp_path / "products"
    out.mkdir()
    o = scene.orientation
    o.image_root = str((tmp_path / "block").resolve())
    o.save(out / "orientation.json")
    res = 2 * cfg.gsd
    fractions = []
    r = run_workflow(
        [], out, config=WorkflowConfig(resolution=res, reuse_orientation=True, executor="inprocess"),
        progress=CallbackProgress(lambda f, m: fractions.append(f)),
    )  # fmt: skip
    for key, name in PRODUCTS.items():
        assert (out / name).exists(), key
        assert r.paths[key] == str(out / name)
    dsm, grid, nodata = read_raster(out / "dsm.tif")
    X, Y = grid.centres()
    truth = scene.height(np.column_stack([X.ravel(), Y.ravel()])).reshape(grid.shape)
    ok = np.isfinite(dsm)
    assert ok.mean() > 0.7 and np.median(np.abs(dsm[ok] - truth[ok])) < res
    ortho, og, _ = read_raster(out / "trueortho.tif", band=None)
    assert ortho.shape[0] == 4 and og.crs and (ortho[3] > 0).mean() > 0.5
    rep = json.loads((out / "report.json").read_text())
    assert rep["summary"]["images oriented"] == len(o.images)
    assert rep["summary"]["tiles ran on"] == r.stats["executor"] == "inprocess"
    stages = [t for t in rep["tables"] if t["title"] == "Stages"][0]["rows"]
    assert [s[0] for s in stages][:5] == [
        "orientation", "dense matching (OSGM)", "DSM filter", "mesh", "true orthophoto",
    ]  # fmt: skip
    assert all(s[1] >= 0 and s[2] > 0 for s in stages)
    # the colour correction per photo (the scene's photos differ in exposure and white balance)
    colour = [t for t in rep["tables"] if t["title"] == "Colour correction"][0]
    assert len(colour["rows"]) == len(o.images) and colour["columns"][2] == "gain R / G / B"
    gains = np.array([[float(v) for v in row[2].split(" / ")] for row in colour["rows"]])
    assert np.allclose(gains.mean(axis=0), 1.0, atol=0.01) and gains.std() > 0.01
    cc = rep["data"]["trueortho"]["color_correction"]
    assert cc["median_after"][0] < cc["median_before"][0]
    assert "colour disagreement" in " ".join(rep["summary"])
    html = (out / "report.html").read_text()
    assert html.count("data:image/png;base64,") >= 2  # offline: images embedded, nothing linked
    assert "src='http" not in html and 'src="http' not in html and "<link" not in html
    assert "reused" in html
    assert fractions[-1] == pytest.approx(1.0)
    from osgeo import ogr

    ds = ogr.Open(str(out / "seamlines.gpkg"))
    assert ds.GetLayer(0).GetFeatureCount() >= 2


@pytest.mark.slow
def test_workflow_on_a_local_cluster_gives_the_in_process_products(tmp_path):
    """EXECUTOR=local for the whole chain (one cluster for OSGM, DSM filter and true ortho): the
    DSM, filtered DSM, true orthophoto, source index and occlusion mask equal the in-process ones."""
    pytest.importorskip("distributed")
    cfg = SceneConfig(
        extent=(-15.0, -12.0, 15.0, 12.0), n_buildings=1, building_size=(7.0, 9.0), building_gap=3.0,
        tower=False, image_size=(200, 150), focal_px=250.0, n_oblique=0, seed=7,
    )  # fmt: skip
    scene = make_scene(cfg)
    scene.write(tmp_path / "block")
    outs = {}
    for kind in ("inprocess", "local"):
        out = tmp_path / kind
        out.mkdir()
        o = scene.orientation
        o.image_root = str((tmp_path / "block").resolve())
        o.save(out / "orientation.json")
        wc = WorkflowConfig(resolution=2 * cfg.gsd, reuse_orientation=True, executor=kind)
        if kind == "local":
            wc.osgm = OsgmConfig(workers=2, worker_memory="1.5GiB")
        r = run_workflow([], out, config=wc)
        assert r.stats["executor"].startswith(kind)
        outs[kind] = out
    for name in ("dsm_raw.tif", "dsm.tif", "trueortho.tif", "source_index.tif", "occlusion.tif"):
        a = read_raster(outs["inprocess"] / name, band=None)[0]
        b = read_raster(outs["local"] / name, band=None)[0]
        assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), name


def test_workflow_bad_input(tmp_path):
    with pytest.raises(InputError, match="IMAGES"):
        run_workflow([], tmp_path)
    with pytest.raises(InputError, match="RESOLUTION"):
        run_workflow(["x.jpg"], tmp_path, config=WorkflowConfig(resolution=-1.0))


def test_workflow_executor_choice(tmp_path, monkeypatch):
    """WorkflowConfig.executor: a bad name or scheduler address fails first with a clear InputError; a
    valid one makes one executor, closed however the run ends (here: no images)."""
    import truortho.core.parallel as parallel

    with pytest.raises(InputError, match="EXECUTOR: expected one of inprocess, local, scheduler"):
        run_workflow(["x.jpg"], tmp_path, config=WorkflowConfig(executor="gpu"))
    monkeypatch.delenv(parallel.SCHEDULER_ENV, raising=False)
    with pytest.raises(InputError, match="SCHEDULER_ADDRESS"):
        run_workflow(["x.jpg"], tmp_path, config=WorkflowConfig(executor="scheduler"))
    with pytest.raises(InputError, match="unauthenticated"):
        run_workflow(
            ["x.jpg"], tmp_path,
            config=WorkflowConfig(executor="scheduler", scheduler_address="tcp://198.51.100.7:8786"),
        )  # fmt: skip
    assert not any(tmp_path.iterdir())  # nothing written
    made, closed = [], []
    real = parallel.make_executor

    def spy(*args, **kw):
        ex = real(*args, **kw)
        close = ex.close

        def recorded_close():
            closed.append(ex.name)
            close()

        ex.close = recorded_close
        made.append(ex.name)
        return ex

    monkeypatch.setattr(parallel, "make_executor", spy)
    for kind in ("inprocess", "local"):
        with pytest.raises(InputError, match="IMAGES"):
            run_workflow([], tmp_path / kind, config=WorkflowConfig(executor=kind))
    assert made == closed == ["inprocess", "local"]
