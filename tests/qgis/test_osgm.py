"""truortho:osgm through processing.run: a small synthetic block matched at a coarse resolution
(DSM against the analytic truth, confidence, point cloud, orthoimage) and bad input that fails
before anything is written, with a message naming the parameter."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytestmark = pytest.mark.qgis

RES = 0.6


@pytest.fixture(scope="module")
def scene_dir(tmp_path_factory):
    from truortho.core.synthetic import SceneConfig, make_scene

    cfg = SceneConfig(
        extent=(-20.0, -15.0, 20.0, 15.0),
        n_buildings=2,
        building_size=(7.0, 11.0),  # the default sizes and gap do not fit two buildings in 40 m x 30 m
        building_gap=3.0,
        tower=False,
        image_size=(240, 180),
        focal_px=300.0,
        n_oblique=0,
        seed=5,
    )
    scene = make_scene(cfg)
    root = tmp_path_factory.mktemp("osgm")
    scene.write(root)
    return scene, root


def run(params):
    import processing

    return processing.run("truortho:osgm", params)


@pytest.mark.slow
def test_osgm_outputs(truortho_provider, scene_dir, tmp_path):
    from qgis.core import QgsRasterLayer

    from truortho.core.rasterio_io import read_raster
    from truortho.core.surface.pointcloud import read_point_cloud

    scene, root = scene_dir
    res = run(
        {
            "ORIENTATION": str(root / "orientation.json"),
            "RESOLUTION": RES,
            "DSM": str(tmp_path / "dsm.tif"),
            "CONFIDENCE": str(tmp_path / "conf.tif"),
            "ORTHOIMAGE": str(tmp_path / "ortho.tif"),
            "POINT_CLOUD": str(tmp_path / "points.laz"),
        }
    )
    assert res["DSM"] == str(tmp_path / "dsm.tif")
    layer = QgsRasterLayer(res["DSM"], "dsm")
    assert layer.isValid() and layer.bandCount() == 1
    assert layer.crs().authid() == scene.orientation.crs == "EPSG:32632"

    dsm, grid, nodata = read_raster(res["DSM"])
    assert nodata is not None and dsm.dtype == np.float32
    assert grid.res == pytest.approx(RES)
    X, Y = grid.centres()
    truth = scene.height(np.column_stack([X.ravel(), Y.ravel()])).reshape(grid.shape)
    ok = np.isfinite(dsm)
    assert ok.mean() > 0.5, f"only {ok.mean():.1%} of the cells matched"
    err = np.abs(dsm[ok] - truth[ok])
    print(f"\nOSGM at {RES} m: {ok.mean():.1%} valid, median |dZ| {np.median(err):.3f} m")
    assert np.median(err) < 2 * RES

    conf, cgrid, _ = read_raster(res["CONFIDENCE"])
    assert cgrid == grid
    c = conf[np.isfinite(conf)]
    assert c.size > 0 and c.min() >= 0.0 and c.max() <= 1.0

    ortho = QgsRasterLayer(res["ORTHOIMAGE"], "ortho")
    assert ortho.isValid() and ortho.bandCount() >= 3 and ortho.crs().authid() == "EPSG:32632"

    cloud = read_point_cloud(res["POINT_CLOUD"])
    assert len(cloud) > 0
    x0, y0, x1, y1 = grid.extent
    inside = (
        (cloud.xyz[:, 0] >= x0 - RES)
        & (cloud.xyz[:, 0] <= x1 + RES)
        & (cloud.xyz[:, 1] >= y0 - RES)
        & (cloud.xyz[:, 1] <= y1 + RES)
    )
    assert inside.mean() > 0.99

    stats = json.loads(res["STATISTICS"])
    assert isinstance(stats, dict) and stats


@pytest.mark.slow
def test_osgm_z_surface_and_loading_in_the_project(truortho_provider, scene_dir):
    """Z_SURFACE bounds the search; outputs load into the project styled (as from the GUI dialog)."""
    import processing
    from qgis.core import QgsProject

    scene, root = scene_dir
    project = QgsProject.instance()
    before = set(project.mapLayers())
    res = processing.runAndLoadResults(
        "truortho:osgm",
        {
            "ORIENTATION": str(root / "orientation.json"),
            "RESOLUTION": RES,
            "Z_SURFACE": str(root / "dsm.tif"),
            "PATHS": 1,
            "OBLIQUE": 1,
            "DSM": "TEMPORARY_OUTPUT",
            "CONFIDENCE": "TEMPORARY_OUTPUT",
            "ORTHOIMAGE": "TEMPORARY_OUTPUT",
        },
    )
    try:
        stats = json.loads(res["STATISTICS"])
        assert stats["z_source"] == "Z_SURFACE" and res["DSM"].endswith(".tif")
        loaded = {project.mapLayer(i).name(): project.mapLayer(i) for i in set(project.mapLayers()) - before}
        assert loaded["DSM (OSGM)"].renderer().type() == "hillshade"
        assert loaded["Confidence (OSGM)"].renderer().type() == "singlebandpseudocolor"
        assert loaded["Orthoimage (OSGM)"].renderer().type() == "multibandcolor"
    finally:
        project.removeMapLayers(list(set(project.mapLayers()) - before))


# (parameters replacing the valid ones, message match); file names are made relative to tmp_path,
# {x0} {y0} {x1} {y1} are the scene's world extent
BAD_INPUT = {
    "missing orientation": ({"ORIENTATION": "missing.json"}, "ORIENTATION"),
    "z range inverted": ({"Z_MIN": 150.0, "Z_MAX": 120.0}, "Z_MIN.*Z_MAX"),
    "z range empty": ({"Z_MIN": 120.0, "Z_MAX": 120.0}, "Z_MIN.*Z_MAX"),
    "point cloud .txt": ({"POINT_CLOUD": "points.txt"}, "POINT_CLOUD"),
    "extent far away": ({"EXTENT": "{x1_far},{x1_farther},{y0},{y1} [EPSG:32632]"}, "EXTENT"),
    "extent in another CRS": ({"EXTENT": "8.0,8.1,40.0,40.1 [EPSG:4326]"}, "EXTENT"),
    "negative resolution": ({"RESOLUTION": -1.0}, "RESOLUTION"),
    "p2 below p1": ({"P1": 600, "P2": 500}, "P2"),
    "p2 too large": ({"P2": 5000}, "P2"),
    "two outputs, one file": ({"CONFIDENCE": "dsm.tif"}, "same path"),
    "scheduler off this machine without TLS": (
        {"EXECUTOR": 2, "SCHEDULER_ADDRESS": "tcp://198.51.100.7:8786"},
        "unauthenticated",
    ),
}
FILE_PARAMETERS = ("ORIENTATION", "POINT_CLOUD", "CONFIDENCE")


@pytest.mark.parametrize("case", list(BAD_INPUT))
def test_osgm_bad_input(truortho_provider, scene_dir, tmp_path, case):
    from qgis.core import QgsProcessingException

    scene, root = scene_dir
    x0, y0, x1, y1 = scene.extent_world()
    where = {"x0": x0, "y0": y0, "x1": x1, "y1": y1, "x1_far": x1 + 1000, "x1_farther": x1 + 1100}
    override, match = BAD_INPUT[case]
    params = {
        "ORIENTATION": str(root / "orientation.json"),
        "RESOLUTION": RES,
        "DSM": str(tmp_path / "dsm.tif"),
    }
    for key, value in override.items():
        if key in FILE_PARAMETERS:
            value = str(tmp_path / value)
        elif isinstance(value, str):
            value = value.format(**where)
        params[key] = value
    with pytest.raises(QgsProcessingException, match=match):
        run(params)
    assert not any(tmp_path.iterdir())


@pytest.mark.slow
def test_osgm_on_a_local_dask_cluster_gives_the_in_process_dsm(truortho_provider, scene_dir, tmp_path):
    """EXECUTOR = local (2 worker processes on 127.0.0.1) from Processing: the same DSM, bit for bit."""
    from truortho.core.rasterio_io import read_raster

    _scene, root = scene_dir
    dsms = {}
    for executor in (0, 1):
        res = run(
            {
                "ORIENTATION": str(root / "orientation.json"),
                "RESOLUTION": RES,
                "TILE_SIZE": 32,
                "EXECUTOR": executor,
                "DSM": str(tmp_path / f"dsm{executor}.tif"),
            }
        )
        stats = json.loads(res["STATISTICS"])
        assert stats["tiles"] > 2
        dsms[executor] = read_raster(res["DSM"])[0]
    assert stats["executor"].startswith("local Dask cluster")
    assert np.array_equal(dsms[0], dsms[1], equal_nan=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dsm0.tif", "dsm1.tif"]  # no scratch tiles left
