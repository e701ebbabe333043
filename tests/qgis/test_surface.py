"""Surface algorithms through processing.run: dsmfilter (+ DTM), mesh, dsmtopointcloud, mergepointclouds;
EPT datasets open as QGIS point cloud layers with the right CRS and point count; bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest

from truortho.core.grid import RasterGrid
from truortho.core.rasterio_io import raster_grid, read_raster, write_raster

pytestmark = pytest.mark.qgis

RES = 0.25


def run(alg, params):
    import processing

    return processing.run(alg, params)


@pytest.fixture(scope="module")
def rasters(tmp_path_factory):
    from truortho.core.synthetic import SceneConfig, make_scene
    from truortho.core.synthetic.degrade import degrade_dsm

    scene = make_scene(SceneConfig(image_size=(320, 240), focal_px=250.0, n_oblique=0, seed=1, supersample=1))
    truth, gt = scene.dsm(RES, extent=(499960.0, 5599960.0, 500040.0, 5600030.0))
    grid = RasterGrid.from_geotransform(gt, truth.shape[0], truth.shape[1], scene.config.crs)
    d = degrade_dsm(truth, RES, seed=3)
    rgb, _ = scene.orthophoto(RES, extent=(499960.0, 5599960.0, 500040.0, 5600030.0))
    root = tmp_path_factory.mktemp("surface")
    write_raster(
        root / "raw.tif",
        np.where(np.isfinite(d.dsm), d.dsm, -9999.0).astype(np.float32),
        grid,
        nodata=-9999.0,
    )
    write_raster(root / "conf.tif", d.confidence, grid)
    write_raster(root / "truth.tif", truth, grid, nodata=-9999.0)
    write_raster(root / "ortho.tif", np.moveaxis(np.maximum(rgb, 1), -1, 0), grid, nodata=0)
    nocrs = RasterGrid(grid.x_min, grid.y_max, grid.res, grid.rows, grid.cols, None)
    write_raster(root / "nocrs.tif", truth, nocrs, nodata=-9999.0)
    write_raster(root / "empty.tif", np.full(grid.shape, -9999.0, np.float32), grid, nodata=-9999.0)
    return root, grid, truth, d


def test_dsmfilter_with_dtm(truortho_provider, rasters, tmp_path):
    root, grid, truth, d = rasters
    res = run(
        "truortho:dsmfilter",
        {
            "INPUT": str(root / "raw.tif"),
            "CONFIDENCE": str(root / "conf.tif"),
            "OUTPUT": str(tmp_path / "filtered.tif"),
            "DTM": str(tmp_path / "dtm.tif"),
            "NDSM": str(tmp_path / "ndsm.tif"),
            "EXECUTOR": 0,  # inprocess (the default), explicitly
        },
    )
    stats = json.loads(res["STATISTICS"])
    assert (
        res["OUTLIERS_REMOVED"]
        == stats["filter"]["outliers_removed"] + stats["filter"]["low_confidence_removed"]
        > 0
    )
    assert res["CELLS_FILLED"] >= int(d.holes.sum()) and res["HOLES_REMAINING"] == 0
    out, g, nodata = read_raster(res["OUTPUT"])
    assert g == grid and nodata == -9999.0
    # closer to the truth: RMSE on the cells the raw DSM has, share within 3 GSD over all cells
    ok = np.isfinite(d.dsm)
    assert np.mean((out - truth)[ok] ** 2) < np.mean((d.dsm - truth)[ok] ** 2)
    assert np.mean(np.abs(out - truth) <= 3 * RES) > np.mean(np.abs(d.dsm - truth) <= 3 * RES) + 0.01
    for key in ("DTM", "NDSM"):
        assert raster_grid(res[key]) == grid
    assert "dtm" in stats and stats["dtm"]["ground_fraction"] > 0.5


def test_dsmfilter_refuses_an_unauthenticated_remote_scheduler(truortho_provider, rasters, tmp_path):
    from qgis.core import QgsProcessingException

    root = rasters[0]
    params = {
        "INPUT": str(root / "raw.tif"),
        "OUTPUT": str(tmp_path / "filtered.tif"),
        "EXECUTOR": 2,
        "SCHEDULER_ADDRESS": "tcp://198.51.100.7:8786",
    }
    with pytest.raises(QgsProcessingException, match="unauthenticated"):
        run("truortho:dsmfilter", params)
    assert not any(tmp_path.iterdir())


def test_mesh_from_dsm_for_trueortho(truortho_provider, rasters, tmp_path):
    from truortho.core.surface.mesh import rasterize_mesh
    from truortho.core.surface.meshio import read_mesh

    root, grid, truth, _ = rasters
    res = run(
        "truortho:mesh",
        {
            "INPUT": str(root / "truth.tif"),
            "ORTHO": str(root / "ortho.tif"),
            "FRAME": 1,
            "OUTPUT": str(tmp_path / "m.ply"),
        },
    )
    mesh = read_mesh(res["OUTPUT"])
    assert mesh.n_vertices == res["VERTICES"] and mesh.n_faces == res["FACES"] and res["WALL_FACES"] > 0
    assert mesh.crs == "EPSG:32632" and mesh.offset is not None and mesh.colours is not None
    top = rasterize_mesh(mesh, grid)
    assert np.abs(top - truth).max() <= 0.5 * RES + 1e-3
    res2 = run("truortho:mesh", {"INPUT": str(root / "truth.tif"), "OUTPUT": str(tmp_path / "m.obj")})
    assert read_mesh(res2["OUTPUT"]).n_faces == res["FACES"]


def test_point_cloud_ept_opens_in_qgis(truortho_provider, rasters, tmp_path):
    import laspy
    from qgis.core import QgsDoubleRange, QgsGeometry, QgsPointCloudLayer

    root, grid, truth, _ = rasters
    res = run(
        "truortho:dsmtopointcloud",
        {
            "INPUT": str(root / "truth.tif"),
            "ORTHO": str(root / "ortho.tif"),
            "CONFIDENCE": str(root / "conf.tif"),
            "OUTPUT": str(tmp_path / "pc.laz"),
            "EPT": str(tmp_path / "pc_ept"),
        },
    )
    n = truth.size
    assert res["POINTS"] == n
    las = laspy.read(res["OUTPUT"])
    assert len(las.points) == n and las.header.parse_crs().to_epsg() == 32632
    layer = QgsPointCloudLayer(res["EPT_JSON"], "pc", "ept")
    assert layer.isValid()
    assert layer.crs().authid() == "EPSG:32632"
    assert layer.pointCount() == n
    names = {a.name() for a in layer.attributes().attributes()}
    assert {"X", "Y", "Z", "Red", "Green", "Blue", "confidence", "system"} <= names
    # the nodes decode: points read back through QGIS match the DSM
    ext = layer.extent().buffered(1.0)  # identify() drops points on the rectangle's border
    pts = layer.dataProvider().identify(1e-4, QgsGeometry.fromRect(ext), QgsDoubleRange(), 10**7)
    assert len(pts) == n
    xyz = np.array([[p["X"], p["Y"], p["Z"]] for p in pts])
    r, c = grid.cell_of(xyz[:, 0], xyz[:, 1])
    np.testing.assert_allclose(xyz[:, 2], truth[np.round(r).astype(int), np.round(c).astype(int)], atol=2e-3)
    # merging with a second "system" (the same cloud, shifted) and thinning
    res2 = run(
        "truortho:mergepointclouds",
        {
            "INPUTS": [res["OUTPUT"], res["OUTPUT"]],
            "VOXEL": 0.1,
            "OUTPUT": str(tmp_path / "merged.laz"),
            "EPT": str(tmp_path / "merged_ept"),
        },
    )
    assert res2["POINTS"] == n  # exact duplicates: one per voxel
    assert QgsPointCloudLayer(res2["EPT_JSON"], "m", "ept").pointCount() == n
    # a mesh of the point cloud (one 2.5D Delaunay mesh per reference system)
    res3 = run("truortho:mesh", {"INPUT": res["OUTPUT"], "OUTPUT": str(tmp_path / "pc.ply")})
    from truortho.core.surface.meshio import read_mesh

    pm = read_mesh(res3["OUTPUT"])
    assert pm.n_vertices > 0.95 * n and pm.colours is not None and pm.crs is not None


@pytest.mark.parametrize(
    "alg,params,match",
    [
        ("truortho:dsmfilter", {"INPUT": "nocrs.tif", "OUTPUT": "o.tif"}, "no CRS"),
        ("truortho:dsmfilter", {"INPUT": "empty.tif", "OUTPUT": "o.tif"}, "every cell is nodata"),
        ("truortho:mesh", {"INPUT": "truth.tif", "OUTPUT": "m.stl"}, r"unknown mesh extension '\.stl'"),
        ("truortho:mesh", {"INPUT": "nocrs.tif", "OUTPUT": "m.ply"}, "no CRS"),
        ("truortho:mesh", {"INPUT": "empty.tif", "OUTPUT": "m.ply"}, "all nodata"),
        ("truortho:dsmtopointcloud", {"INPUT": "nocrs.tif", "OUTPUT": "p.laz"}, "no CRS"),
        ("truortho:dsmtopointcloud", {"INPUT": "empty.tif", "OUTPUT": "p.laz", "EPT": "e"}, "nodata"),
    ],
)
def test_bad_input_is_a_clear_error(truortho_provider, rasters, tmp_path, alg, params, match):
    from qgis.core import QgsProcessingException

    root = rasters[0]
    p = {k: (str(root / v) if k == "INPUT" else str(tmp_path / v)) for k, v in params.items()}
    with pytest.raises(QgsProcessingException, match=match):
        run(alg, p)
    assert not any(tmp_path.iterdir())
