"""DSM filter: synthetic acceptance (filtered closer to the truth than raw), kernels vs references,
hole filling, tile invariance, files and bad input."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.errors import CRSError, InputError
from truortho.core.grid import RasterGrid
from truortho.core.rasterio_io import raster_grid, read_raster, write_raster
from truortho.core.surface import filter as F
from truortho.core.surface.filter import DsmFilterConfig, filter_dsm, filter_dsm_array

RES = 0.25


@pytest.fixture(scope="module")
def scene_dsm():
    from truortho.core.synthetic import SceneConfig, make_scene
    from truortho.core.synthetic.degrade import degrade_dsm

    scene = make_scene(SceneConfig(image_size=(320, 240), focal_px=250.0, n_oblique=0, seed=1, supersample=1))
    z, gt = scene.dsm(RES)
    grid = RasterGrid.from_geotransform(gt, z.shape[0], z.shape[1], scene.config.crs)
    return scene, z.astype(np.float64), grid, degrade_dsm(z, RES, seed=3)


def _score(a, truth, where=None):
    """RMSE over the valid cells (of ``where`` when given) and share of all cells within 3 GSD."""
    e = a - truth
    ok = np.isfinite(e) if where is None else where
    return float(np.sqrt(np.mean(e[ok] ** 2))), float(np.sum(np.abs(e[ok]) <= 3 * RES) / e.size)


def test_filtered_dsm_is_closer_to_the_truth(scene_dsm):
    _, truth, grid, d = scene_dsm
    raw_rmse, raw_share = _score(d.dsm, truth)
    out, stats = filter_dsm_array(d.dsm, grid, d.confidence)
    rmse, share = _score(out, truth)
    rmse_common = _score(out, truth, np.isfinite(d.dsm))[0]
    print(f"\nraw DSM: RMSE {raw_rmse:.3f} m, {100 * raw_share:.2f} % of all cells within 3 GSD")
    print(
        f"filtered: RMSE {rmse:.3f} m ({rmse_common:.3f} m on the raw DSM's valid cells), "
        f"{100 * share:.2f} % within 3 GSD; {stats.summary()}"
    )
    assert rmse < 0.5 * raw_rmse and rmse_common < 0.5 * raw_rmse
    assert share > raw_share + 0.01
    # away from the (blurred) building edges the filter removes the outliers' error almost entirely
    from scipy import ndimage

    edge_zone = ndimage.binary_dilation(d.edges, iterations=2)
    e = out - truth
    assert np.sqrt(np.mean(e[~edge_zone] ** 2)) < 0.15 * np.sqrt(np.nanmean((d.dsm - truth)[~edge_zone] ** 2))
    # the statistics tell what happened
    n_out = int(d.outliers.sum())
    assert 0.8 * n_out <= stats.outliers_removed + stats.low_confidence_removed <= 2.0 * n_out
    assert stats.holes_filled > 0 and stats.cells_filled >= int(d.holes.sum())
    assert stats.holes_remaining == 0 and stats.valid_output == truth.size
    # without confidence it works too
    out2, _ = filter_dsm_array(d.dsm, grid)
    assert _score(out2, truth)[0] < 0.85 * raw_rmse


def test_results_do_not_depend_on_the_tile_size(scene_dsm):
    _, _, grid, d = scene_dsm
    a, sa = filter_dsm_array(d.dsm, grid, d.confidence, DsmFilterConfig(tile=1024))
    b, sb = filter_dsm_array(d.dsm, grid, d.confidence, DsmFilterConfig(tile=96))
    np.testing.assert_array_equal(np.isnan(a), np.isnan(b))
    assert np.nanmax(np.abs(a - b)) < 1e-3
    assert sa.as_dict() == sb.as_dict()


def _outlier_reference(z, conf, t, half, min_support):
    """Slow, obviously-correct version of the median/support test."""
    out = np.zeros(z.shape, bool)
    for r in range(z.shape[0]):
        for c in range(z.shape[1]):
            if not np.isfinite(z[r, c]):
                continue
            tc = t * (0.5 + 0.5 * conf[r, c]) if conf is not None else t
            vals, wts = [], []
            for rr in range(max(r - half, 0), min(r + half + 1, z.shape[0])):
                for cc in range(max(c - half, 0), min(c + half + 1, z.shape[1])):
                    if (rr, cc) != (r, c) and np.isfinite(z[rr, cc]):
                        vals.append(z[rr, cc])
                        wts.append(conf[rr, cc] + 1e-3 if conf is not None else 1.0)
            if not vals:
                continue
            support = sum(abs(v - z[r, c]) <= tc for v in vals)
            if support >= min_support:
                continue
            order = np.argsort(vals, kind="stable")
            cum = np.cumsum(np.asarray(wts)[order])
            med = np.asarray(vals)[order][np.searchsorted(cum, 0.5 * cum[-1])]
            out[r, c] = abs(z[r, c] - med) > tc
    return out


@pytest.mark.parametrize("with_conf", [False, True])
def test_outlier_kernel_matches_reference(with_conf):
    rng = np.random.default_rng(5)
    z = rng.normal(10, 0.05, (23, 31))
    z[5:12, 8:20] += 6.0  # a building: its corners and edges must survive
    spikes = rng.choice(z.size, 25, replace=False)
    z.flat[spikes] += rng.choice([-1, 1], 25) * rng.uniform(2, 8, 25)
    z[rng.random(z.shape) < 0.05] = np.nan
    conf = rng.uniform(0, 1, z.shape) if with_conf else None
    got = np.zeros(z.shape, bool)
    F._outlier_pass(z, conf if with_conf else np.zeros((1, 1)), with_conf, 1.0, 2, 4, got)
    np.testing.assert_array_equal(got, _outlier_reference(z, conf, 1.0, 2, 4))
    # the building's corners are not outliers
    assert not got[5, 8] and not got[11, 19]


def test_holes_plane_exact_wall_foot_from_ground_large_hole_stays():
    res = 0.5
    rows, cols = 120, 160
    grid = RasterGrid(500000.0, 5600000.0, res, rows, cols, "EPSG:32632")
    X, Y = grid.centres()
    plane = 100.0 + 0.02 * (X - 500000.0) - 0.03 * (Y - 5600000.0)
    z = plane.copy()
    z[40:80, 100:140] += 8.0  # a flat-roofed building
    truth = z.copy()
    z[10:14, 10:15] = np.nan  # small hole on the ground: the plane is restored exactly
    z[50:60, 96:100] = np.nan  # occlusion strip at the foot of the west wall: ground, not a ramp
    z[85:115, 20:60] = np.nan  # 15 m wide: stays nodata
    cfg = DsmFilterConfig(max_hole=6.0, sharpen=False)
    out, stats = filter_dsm_array(z, grid, config=cfg)
    np.testing.assert_allclose(out[10:14, 10:15], truth[10:14, 10:15], atol=1e-6)
    np.testing.assert_allclose(out[50:60, 96:100], truth[50:60, 96:100], atol=0.05)
    assert np.isnan(out[85:115, 20:60]).all()
    assert stats.holes_filled == 2 and stats.holes_remaining == 1
    assert stats.cells_remaining == 30 * 40 and stats.cells_filled == 20 + 40
    assert stats.largest_remaining_hole_m > 6.0
    assert np.array_equal(np.isfinite(out[:, :]), ~np.isnan(out))


def test_narrow_bays_open_to_the_outside_are_filled_the_wide_outside_is_not():
    """A gap narrower than max_hole that opens onto the nodata around the data (a vegetated
    border that lost its low-confidence cells) is filled from its rim, like an enclosed hole;
    the wide nodata beyond the data (and the corners of a wide enclosed hole) stay nodata, and
    nothing is extrapolated towards the raster's border."""
    res = 0.5
    rows, cols = 100, 120
    grid = RasterGrid(500000.0, 5600000.0, res, rows, cols, "EPSG:32632")
    X, Y = grid.centres()
    plane = 50.0 + 0.02 * (X - 500000.0) - 0.03 * (Y - 5600000.0)
    z = plane.copy()
    z[:, 90:] = np.nan  # the outside: 15 m of nodata up to the raster's east border
    z[40:48, 60:90] = np.nan  # a bay 4 m wide, 15 m deep, open onto the outside
    z[70:100, 10:50] = np.nan  # 15 x 20 m open onto the south border: stays (corners too)
    cfg = DsmFilterConfig(max_hole=6.0, sharpen=False)
    out, stats = filter_dsm_array(z, grid, config=cfg)
    np.testing.assert_allclose(out[40:48, 60:88], plane[40:48, 60:88], atol=0.05)
    assert np.isnan(out[:, 92:]).all()  # no extrapolation into the outside
    assert np.isnan(out[72:100, 12:48]).all()
    # the wide holes are still reported as remaining, their narrow gaps as filled cells
    assert stats.holes_remaining >= 1 and stats.cells_filled >= 8 * 28
    assert stats.valid_output == int(np.isfinite(out).sum())
    # the same result on small tiles
    small, _ = filter_dsm_array(z, grid, config=DsmFilterConfig(max_hole=6.0, sharpen=False, tile=32))
    np.testing.assert_array_equal(np.isfinite(small), np.isfinite(out))
    np.testing.assert_allclose(small, out, atol=0.05)
    # a bay running up a 45 degree slope is a ramp from its whole rim, not flat from its lowest cell
    steep = 50.0 + 1.0 * (X - 500000.0)
    zs = np.where(np.isnan(z), np.nan, steep)
    out_s, _ = filter_dsm_array(zs, grid, config=cfg)
    # (towards its mouth the zero-flux boundary onto the open side flattens it a little)
    np.testing.assert_allclose(out_s[40:48, 60:80], steep[40:48, 60:80], atol=0.3)
    assert np.abs(out_s[40:48, 60:88] - steep[40:48, 60:88]).max() < 2.0  # flat would be 14 m off


def test_small_islands_are_judged_by_their_surroundings():
    """A few valid cells alone in a hole have only themselves as support and median: the island
    test removes them when they depart from the valid cells around them, keeps them otherwise."""
    res = 0.5
    grid = RasterGrid(500000.0, 5600000.0, res, 60, 60, "EPSG:32632")
    X, Y = grid.centres()
    plane = 20.0 + 0.05 * (X - 500000.0)
    z = plane.copy()
    z[20:40, 10:30] = np.nan  # a hole
    z[24:26, 14:16] = plane[24:26, 14:16] + 5.0  # a 2 x 2 false match 5 m up in it
    z[33:35, 23:25] = plane[33:35, 23:25]  # a true 2 x 2 patch of ground in it
    cfg = DsmFilterConfig(max_hole=20.0, sharpen=False)
    out, stats = filter_dsm_array(z, grid, config=cfg)
    assert stats.outliers_removed == 4
    np.testing.assert_allclose(out[20:40, 10:30], plane[20:40, 10:30], atol=0.05)  # no cone
    np.testing.assert_array_equal(F._islands(z, 1.0, 12)[33:35, 23:25], False)


def test_sharpening_and_smoothing_keep_edges_and_reduce_noise():
    rng = np.random.default_rng(2)
    res = 0.25
    grid = RasterGrid(0.0, 100.0, res, 80, 80, "EPSG:32632")
    truth = np.full(grid.shape, 50.0)
    truth[20:60, 20:60] = 58.0
    z = truth + rng.normal(0, 0.05, grid.shape)
    # blur the edges as a matching window would
    from scipy import ndimage

    edge = np.abs(ndimage.laplace(truth)) > 0
    z[edge] = ndimage.uniform_filter(truth, 3)[edge] + rng.normal(0, 0.05, int(edge.sum()))
    out, stats = filter_dsm_array(z, grid, config=DsmFilterConfig(smooth=True))
    assert stats.sharpened >= 0.8 * edge.sum() and stats.smoothed > 0.8 * truth.size
    # the step is sharp again; only the four roof corners (4/9 roof in a 3 x 3 blur) snap to the ground
    wrong = np.argwhere(np.abs(out - truth) > 0.2)
    assert len(wrong) <= 4 and all(tuple(w) in {(20, 20), (20, 59), (59, 20), (59, 59)} for w in wrong)
    flat = (truth == 58.0) & ~ndimage.binary_dilation(edge, iterations=3)
    assert np.std(out[flat] - 58.0) < 0.5 * np.std(z[flat] - 58.0)


def test_files_keep_crs_nodata_grid_and_bad_input(tmp_path, scene_dsm):
    _, truth, grid, d = scene_dsm
    raw = np.where(np.isfinite(d.dsm), d.dsm, -9999.0).astype(np.float32)
    write_raster(tmp_path / "raw.tif", raw, grid, nodata=-9999.0)
    write_raster(tmp_path / "conf.tif", d.confidence, grid, nodata=None)
    stats = filter_dsm(
        tmp_path / "raw.tif", tmp_path / "out.tif", tmp_path / "conf.tif", DsmFilterConfig(tile=256)
    )
    g = raster_grid(tmp_path / "out.tif")
    assert g == grid
    out, _, nodata = read_raster(tmp_path / "out.tif")
    assert nodata == -9999.0 and out.dtype == np.float32
    ref, _ = filter_dsm_array(d.dsm, grid, d.confidence, DsmFilterConfig(tile=256))
    np.testing.assert_allclose(out, ref, atol=1e-4)
    assert stats.valid_output == truth.size
    # a raster without CRS
    nocrs = RasterGrid(grid.x_min, grid.y_max, grid.res, grid.rows, grid.cols, None)
    write_raster(tmp_path / "nocrs.tif", raw, nocrs, nodata=-9999.0)
    with pytest.raises(CRSError, match="no CRS"):
        filter_dsm(tmp_path / "nocrs.tif", tmp_path / "x.tif")
    # all nodata
    write_raster(tmp_path / "empty.tif", np.full(grid.shape, -9999.0, np.float32), grid, nodata=-9999.0)
    with pytest.raises(InputError, match="every cell is nodata"):
        filter_dsm(tmp_path / "empty.tif", tmp_path / "x.tif")
    with pytest.raises(InputError, match="every cell is nodata"):
        filter_dsm_array(np.full(grid.shape, np.nan), grid)
    with pytest.raises(InputError, match="outlier_window"):
        filter_dsm_array(d.dsm, grid, config=DsmFilterConfig(outlier_window=4))
    assert not (tmp_path / "x.tif").exists()


def test_cancel_leaves_no_output(tmp_path, scene_dsm):
    from truortho.core.errors import CancelledError
    from truortho.core.progress import CallbackProgress
    from truortho.core.surface.dtm import dtm_from_dsm

    _, _, grid, d = scene_dsm
    write_raster(
        tmp_path / "raw.tif", np.nan_to_num(d.dsm, nan=-9999.0).astype(np.float32), grid, nodata=-9999.0
    )
    calls = []

    def cancelled():
        calls.append(1)
        return len(calls) > 3

    with pytest.raises(CancelledError):
        filter_dsm(
            tmp_path / "raw.tif",
            tmp_path / "out.tif",
            config=DsmFilterConfig(tile=128),
            progress=CallbackProgress(None, cancelled),
        )
    calls.clear()
    with pytest.raises(CancelledError):
        dtm_from_dsm(
            tmp_path / "raw.tif",
            tmp_path / "dtm.tif",
            ndsm_path=tmp_path / "ndsm.tif",
            progress=CallbackProgress(None, cancelled),
        )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["raw.tif"]


def test_confidence_kernel_matches_reference():
    rng = np.random.default_rng(8)
    z = rng.normal(20, 0.05, (30, 27))
    conf = rng.uniform(0, 1, z.shape)
    blob = (slice(10, 16), slice(8, 15))  # a 6 x 7 wrong blob of low confidence: the support test keeps it
    z[blob] += 3.0
    conf[blob] = rng.uniform(0, 0.3, (6, 7))
    z[rng.random(z.shape) < 0.05] = np.nan
    got = np.zeros(z.shape, bool)
    F._confidence_pass(z, conf, 0.4, 1.0, 7, got)
    ref = np.zeros(z.shape, bool)
    for r in range(z.shape[0]):
        for c in range(z.shape[1]):
            if not np.isfinite(z[r, c]) or conf[r, c] >= 0.4:
                continue
            win = (slice(max(r - 7, 0), r + 8), slice(max(c - 7, 0), c + 8))
            v = z[win][np.isfinite(z[win]) & (conf[win] >= 0.4)]
            ref[r, c] = len(v) >= 8 and abs(z[r, c] - np.median(v)) > 1.0
    np.testing.assert_array_equal(got, ref)
    assert got[blob][np.isfinite(z[blob])].all()
