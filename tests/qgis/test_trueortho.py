"""truortho:trueortho through processing.run on a small synthetic scene."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

pytestmark = pytest.mark.qgis


@pytest.fixture(scope="module")
def scene_dir(tmp_path_factory):
    from truortho.core.synthetic import SceneConfig, make_scene

    scene = make_scene(SceneConfig(image_size=(240, 180), focal_px=300.0, n_buildings=4, n_oblique=2, seed=5))
    root = tmp_path_factory.mktemp("trueortho")
    scene.write(root)
    return scene, root


def run(params, feedback=None):
    import processing

    return processing.run("truortho:trueortho", params, feedback=feedback)


def test_trueortho_executor_parameters(truortho_provider):
    """EXECUTOR (inprocess | local | scheduler, default inprocess) and SCHEDULER_ADDRESS: advanced."""
    from qgis.core import QgsApplication, QgsProcessingParameterDefinition

    alg = QgsApplication.processingRegistry().algorithmById("truortho:trueortho")
    executor = alg.parameterDefinition("EXECUTOR")
    address = alg.parameterDefinition("SCHEDULER_ADDRESS")
    assert executor is not None and address is not None
    assert len(executor.options()) == 3 and executor.defaultValue() == 0
    assert [o.split(":")[0] for o in executor.options()] == ["inprocess", "local", "scheduler"]
    assert address.flags() & QgsProcessingParameterDefinition.FlagOptional
    for p in (executor, address):
        assert p.flags() & QgsProcessingParameterDefinition.FlagAdvanced, p.name()
    comp = alg.parameterDefinition("COMPRESSION")
    assert [o.split(" ")[0] for o in comp.options()] == ["DEFLATE", "ZSTD", "LZW", "JPEG"]
    assert comp.defaultValue() == 0 and not comp.flags() & QgsProcessingParameterDefinition.FlagAdvanced
    assert alg.parameterDefinition("JPEG_QUALITY").defaultValue() == 90


def test_trueortho_outputs(truortho_provider, scene_dir, tmp_path):
    from qgis.core import QgsProcessingFeedback, QgsRasterLayer, QgsVectorLayer

    from truortho.core.rasterio_io import read_raster

    class Recording(QgsProcessingFeedback):
        def __init__(self):
            super().__init__()
            self.infos: list[str] = []

        def pushInfo(self, info):  # noqa: N802 - QGIS API
            self.infos.append(info)
            super().pushInfo(info)

    fb = Recording()
    scene, root = scene_dir
    res = run(
        {
            "ORIENTATION": str(root / "orientation.json"),
            "SURFACE": str(root / "dsm.tif"),
            "BLEND_WIDTH": 3,
            "EXECUTOR": 0,  # inprocess (the default), explicitly
            "OUTPUT": str(tmp_path / "ortho.tif"),
            "SOURCE_INDEX": str(tmp_path / "idx.tif"),
            "OCCLUSION": str(tmp_path / "occ.tif"),
            "SEAMLINES": str(tmp_path / "seams.gpkg"),
        },
        fb,
    )
    # the log tells what the colour correction did (the scene's photos differ in exposure)
    told = [t for t in fb.infos if t.startswith("colour correction (per-channel RGB")]
    assert len(told) == 1, fb.infos
    before, after = (float(v) for v in told[0].rsplit("median ", 1)[1].split(" -> "))
    assert after < before
    ortho = QgsRasterLayer(res["OUTPUT"], "o")
    assert ortho.isValid() and ortho.bandCount() == 4 and ortho.crs().authid() == "EPSG:32632"
    idx, _, _ = read_raster(res["SOURCE_INDEX"])
    seams = QgsVectorLayer(res["SEAMLINES"], "s", "ogr")
    assert seams.featureCount() == len(np.unique(idx[idx >= 0]))
    total = sum(f["cells"] for f in seams.getFeatures())
    assert total == int((idx >= 0).sum())
    names = {f["image"] for f in seams.getFeatures()}
    assert names <= {im.name for im in scene.orientation.images}
    a, _, _ = read_raster(res["OUTPUT"], band=4)
    assert (a > 0).mean() > 0.95
    assert not list(tmp_path.glob("*.tiles"))  # the scratch tiles are gone after success


def test_trueortho_extent_and_crs(truortho_provider, scene_dir, tmp_path):
    from qgis.core import QgsRasterLayer

    scene, root = scene_dir
    x0, y0, x1, y1 = scene.extent_world()
    res = run(
        {
            "ORIENTATION": str(root / "orientation.json"),
            "SURFACE": str(root / "dsm.tif"),
            "EXTENT": f"{x0 + 10},{x0 + 50},{y0 + 10},{y0 + 40} [EPSG:32632]",
            "RESOLUTION": 0.5,
            "CRS": "EPSG:25832",
            "COLOR_CORRECTION": False,
            "COMPRESSION": 3,  # JPEG
            "JPEG_QUALITY": 80,
            "OUTPUT": str(tmp_path / "o25832.tif"),
        }
    )
    lyr = QgsRasterLayer(res["OUTPUT"], "o")
    assert lyr.crs().authid() == "EPSG:25832"
    assert lyr.width() == pytest.approx(80, abs=2) and lyr.height() == pytest.approx(60, abs=2)
    # JPEG: RGB as YCbCr, the alpha band became the internal mask
    import rasterio

    with rasterio.open(res["OUTPUT"]) as ds:
        assert ds.count == 3 and ds.compression.name.lower() == "jpeg" and ds.photometric.name == "ycbcr"
        assert ds.mask_flag_enums[0] == [rasterio.enums.MaskFlags.per_dataset]
        assert (ds.dataset_mask() > 0).mean() > 0.9


def test_trueortho_bad_input(truortho_provider, scene_dir, tmp_path):
    from qgis.core import QgsProcessingException

    from truortho.core.orientation import Orientation

    scene, root = scene_dir
    x0, y0, x1, y1 = scene.extent_world()
    with pytest.raises(QgsProcessingException, match="SURFACE"):
        run(
            {
                "ORIENTATION": str(root / "orientation.json"),
                "SURFACE": str(root / "dsm.tif"),
                "EXTENT": f"{x0 - 100},{x1},{y0},{y1} [EPSG:32632]",
                "OUTPUT": str(tmp_path / "bad.tif"),
            }
        )
    o = Orientation.load(root / "orientation.json")
    dataclasses.replace(o, image_root=str(tmp_path / "gone")).save(tmp_path / "moved.json")
    with pytest.raises(QgsProcessingException, match="absent"):
        run(
            {
                "ORIENTATION": str(tmp_path / "moved.json"),
                "SURFACE": str(root / "dsm.tif"),
                "OUTPUT": str(tmp_path / "bad2.tif"),
            }
        )
    # a plain tcp:// scheduler off this machine is refused (before any output is written)
    with pytest.raises(QgsProcessingException, match="unauthenticated"):
        run(
            {
                "ORIENTATION": str(root / "orientation.json"),
                "SURFACE": str(root / "dsm.tif"),
                "COLOR_CORRECTION": False,
                "EXECUTOR": 2,
                "SCHEDULER_ADDRESS": "tcp://198.51.100.7:8786",
                "OUTPUT": str(tmp_path / "bad3.tif"),
            }
        )
    assert not list(tmp_path.glob("bad*"))


def test_trueortho_vignetting_parameter(truortho_provider, scene_dir, tmp_path):
    """VIGNETTING (default on) reaches the colour correction: the synthetic images darken towards
    their corners (vignetting 0.15), and with it the mosaic is closer to the truth once the block's
    absolute exposure (not observable from the images: their gains are jittered) is taken out by
    the best global gain and offset per channel."""
    from qgis.core import QgsApplication

    from truortho.core.ortho import evaluate as ev
    from truortho.core.rasterio_io import read_raster

    alg = QgsApplication.processingRegistry().algorithmById("truortho:trueortho")
    assert alg.parameterDefinition("VIGNETTING").defaultValue() is True
    scene, root = scene_dir
    truth, _ = scene.orthophoto(scene.config.gsd)
    dE = {}
    for vig in (False, True):
        out = tmp_path / f"ortho_{int(vig)}.tif"
        params = {"ORIENTATION": str(root / "orientation.json"), "SURFACE": str(root / "dsm.tif")}
        run({**params, "VIGNETTING": vig, "OUTPUT": str(out)})
        a, _, _ = read_raster(out, band=None)
        valid = a[3] > 0
        x = np.moveaxis(a[:3], 0, -1)[valid].astype(np.float64)
        y = truth[valid].astype(np.float64)
        fitted = np.empty_like(x)
        for ch in range(3):
            A = np.column_stack([x[:, ch], np.ones(len(x))])
            fitted[:, ch] = A @ np.linalg.lstsq(A, y[:, ch], rcond=None)[0]
        fitted = np.clip(np.round(fitted), 0, 255).astype(np.uint8)
        dE[vig] = float(ev.delta_e(fitted[None], truth[valid][None]).mean())
    assert dE[True] < dE[False] - 0.05, dE


def test_trueortho_restore_chroma_parameter(truortho_provider, tmp_path):
    """RESTORE_CHROMA (advanced, default on) reaches the mosaic: on a block of 4:2:0 JPEG files the
    colours along the building outlines come closer to the truth (the decoder smears them)."""
    from qgis.core import QgsApplication, QgsProcessingParameterDefinition
    from scipy.ndimage import binary_dilation, binary_erosion

    from truortho.core.ortho import evaluate as ev
    from truortho.core.rasterio_io import read_raster
    from truortho.core.synthetic import SceneConfig, make_scene

    alg = QgsApplication.processingRegistry().algorithmById("truortho:trueortho")
    p = alg.parameterDefinition("RESTORE_CHROMA")
    assert p.defaultValue() is True and p.flags() & QgsProcessingParameterDefinition.FlagAdvanced
    plain = dict(noise_sigma=0.0, gain_sigma=0.0, offset_sigma=0.0, vignetting=0.0, jpeg_quality=85)
    cfg = SceneConfig(image_size=(320, 240), focal_px=400.0, n_buildings=6, n_oblique=0, seed=11, **plain)
    scene = make_scene(cfg)
    root = tmp_path / "jpeg"
    scene.write(root)
    assert (root / scene.orientation.images[0].name).suffix == ".jpg"
    err = {}
    for on in (False, True):
        out = tmp_path / f"ortho_{int(on)}.tif"
        params = {"ORIENTATION": str(root / "orientation.json"), "SURFACE": str(root / "dsm.tif")}
        # EDGE_COLOUR off: the fringe it removes is what this test measures
        run({**params, "RESTORE_CHROMA": on, "COLOR_CORRECTION": False, "EDGE_COLOUR": 0, "OUTPUT": str(out)})
        a, grid, _ = read_raster(out, band=None)
        truth, _ = scene.orthophoto(grid.res)
        roofs = ev.building_mask(scene, grid)
        band = binary_dilation(roofs, iterations=2) & ~binary_erosion(roofs, iterations=2) & (a[3] > 0)
        assert band.sum() > 200
        x = np.moveaxis(a[:3], 0, -1)[band]
        err[on] = float(ev.delta_e(x[None], truth[band][None]).mean())
    assert err[True] < 0.9 * err[False], err


def test_trueortho_edge_colour_parameter(truortho_provider, scene_dir, tmp_path):
    """EDGE_COLOUR (advanced; off | checked | surface, default checked; also in truortho:pipeline)
    reaches the mosaic: against off, the colours change only near the surface's height steps, no fewer
    cells with surface than with checked (as many on these sharp PNG photos), and there the
    brightness stays (up to rounding, and clipping where a channel saturates)."""
    from qgis.core import QgsApplication, QgsProcessingParameterDefinition
    from scipy.ndimage import maximum_filter, minimum_filter

    from truortho.core.ortho.edgecolour import REACH
    from truortho.core.rasterio_io import read_raster

    for alg_id in ("truortho:trueortho", "truortho:pipeline"):
        p = QgsApplication.processingRegistry().algorithmById(alg_id).parameterDefinition("EDGE_COLOUR")
        assert [o.split(":")[0] for o in p.options()] == ["off", "checked", "surface"], alg_id
        assert p.defaultValue() == 1 and p.flags() & QgsProcessingParameterDefinition.FlagAdvanced
    _, root = scene_dir
    a = {}
    for mode in (0, 1, 2):
        out = tmp_path / f"ortho_{mode}.tif"
        params = {"ORIENTATION": str(root / "orientation.json"), "SURFACE": str(root / "dsm.tif")}
        run({**params, "EDGE_COLOUR": mode, "OUTPUT": str(out)})
        a[mode], _, _ = read_raster(out, band=None)
    h, _, _ = read_raster(root / "dsm.tif")
    steps = (maximum_filter(h, 3) - minimum_filter(h, 3)) > 0.5
    near = maximum_filter(steps, 2 * (REACH + 2) + 1)
    changed = {m: np.any(a[m][:3] != a[0][:3], axis=0) for m in (1, 2)}
    assert 50 < changed[1].sum() <= changed[2].sum()
    luma = lambda x: np.moveaxis(x[:3].astype(float), 0, -1) @ np.array([0.299, 0.587, 0.114])  # noqa: E731
    for m in (1, 2):
        assert not (changed[m] & ~near).any()
        d = np.abs(luma(a[m]) - luma(a[0]))[changed[m]]
        assert np.percentile(d, 95) <= 1.0, np.percentile(d, [50, 95, 100])
        assert np.array_equal(a[m][3], a[0][3])
