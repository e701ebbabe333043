"""DTM by SMRF-style ground filtering, against the synthetic terrain (without buildings)."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.errors import InputError
from truortho.core.grid import RasterGrid
from truortho.core.rasterio_io import raster_grid, read_raster, write_raster
from truortho.core.surface.dtm import DtmConfig, dtm_from_dsm, dtm_from_dsm_array

RES = 0.25


@pytest.fixture(scope="module")
def scene():
    from truortho.core.synthetic import SceneConfig, make_scene

    sc = make_scene(SceneConfig(image_size=(320, 240), focal_px=250.0, n_oblique=0, seed=1, supersample=1))
    z, gt = sc.dsm(RES)
    grid = RasterGrid.from_geotransform(gt, z.shape[0], z.shape[1], sc.config.crs)
    X, Y = grid.centres()
    xy = np.column_stack([X.ravel(), Y.ravel()]) - sc.offset[:2]
    terrain = (sc.surface.terrain(xy) + sc.offset[2]).reshape(z.shape)
    fd = sc.surface.footprint_distance(xy).reshape(z.shape)
    return sc, z.astype(np.float64), grid, terrain, fd


def test_dtm_matches_the_terrain(scene):
    sc, z, grid, terrain, fd = scene
    dtm, stats = dtm_from_dsm_array(z, grid)
    e = dtm - terrain
    rmse, open_rmse, under = (float(np.sqrt(np.mean(e[m] ** 2))) for m in (fd >= 0, fd > 2, fd == 0))
    print(f"\nDTM of the truth DSM: RMSE {rmse:.3f} m (open ground {open_rmse:.3f}, "
          f"under buildings {under:.3f}); {stats.as_dict()}")
    assert open_rmse < 0.02 and under < 0.15 and rmse < 0.05
    building_share = float(np.mean(fd == 0))
    assert abs((1 - stats.ground_fraction) - building_share) < 0.03
    # from the filtered, degraded DSM
    from truortho.core.surface.filter import filter_dsm_array
    from truortho.core.synthetic.degrade import degrade_dsm

    d = degrade_dsm(z, RES, seed=3)
    f, _ = filter_dsm_array(d.dsm, grid, d.confidence)
    dtm2, _ = dtm_from_dsm_array(f, grid)
    e2 = dtm2 - terrain
    rmse2, open2 = float(np.sqrt(np.mean(e2**2))), float(np.sqrt(np.mean(e2[fd > 2] ** 2)))
    print(f"DTM of the filtered degraded DSM: RMSE {rmse2:.3f} m (open ground {open2:.3f})")
    assert open2 < 0.03 and rmse2 < 0.15


def test_dtm_files_and_ndsm(tmp_path, scene):
    sc, z, grid, terrain, fd = scene
    zz = z.copy()
    zz[:20, :30] = np.nan
    write_raster(tmp_path / "dsm.tif", np.where(np.isfinite(zz), zz, -9999).astype(np.float32), grid,
                 nodata=-9999.0)
    stats = dtm_from_dsm(tmp_path / "dsm.tif", tmp_path / "dtm.tif", DtmConfig(tile=128),
                         ndsm_path=tmp_path / "ndsm.tif")
    assert stats.working_resolution == 1.0
    dtm, g, nodata = read_raster(tmp_path / "dtm.tif")
    ndsm, _, _ = read_raster(tmp_path / "ndsm.tif")
    assert g == grid and nodata == -9999.0 and raster_grid(tmp_path / "ndsm.tif") == grid
    assert np.isnan(dtm[:20, :30]).all() and np.isnan(ndsm[:20, :30]).all()
    ok = np.isfinite(zz)
    np.testing.assert_allclose(ndsm[ok], (zz - dtm)[ok], atol=1e-3)
    tall = fd[ok] == 0
    assert np.median(ndsm[ok][tall]) > 3.0 and np.abs(np.median(ndsm[ok][fd[ok] > 2])) < 0.05
    write_raster(tmp_path / "empty.tif", np.full(grid.shape, -9999.0, np.float32), grid, nodata=-9999.0)
    with pytest.raises(InputError, match="all nodata"):
        dtm_from_dsm(tmp_path / "empty.tif", tmp_path / "x.tif")
    with pytest.raises(InputError, match="slope"):
        dtm_from_dsm_array(z, grid, DtmConfig(slope=0))
    assert not (tmp_path / "x.tif").exists()
