"""RasterGrid / Tile plan and the atomic raster and point-cloud writers."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.errors import CRSError, InputError
from truortho.core.grid import RasterGrid
from truortho.core.rasterio_io import (
    RasterWriter,
    raster_grid,
    read_onto_grid,
    read_preview,
    read_raster,
    valid_share,
    write_point_cloud,
    write_raster,
)


def test_grid_from_extent_matches_cell_centre_convention():
    g = RasterGrid.from_extent((100.0, 200.0, 110.05, 205.0), 0.5, "EPSG:32632")
    assert g.shape == (10, 21)  # rounded up
    assert g.geotransform == (100.0, 0.5, 0.0, 205.0, 0.0, -0.5)
    X, Y = g.centres()
    assert X[0, 0] == pytest.approx(100.25) and Y[0, 0] == pytest.approx(204.75)
    r, c = g.cell_of(X[3, 7], Y[3, 7])
    assert (r, c) == (pytest.approx(3.0), pytest.approx(7.0))


@pytest.mark.parametrize("tile,overlap", [(4, 0), (4, 2), (7, 3), (100, 5)])
def test_tiles_partition_the_grid(tile, overlap):
    g = RasterGrid(0.0, 0.0, 1.0, 13, 17)
    seen = np.zeros(g.shape, int)
    for t in g.tiles(tile, overlap):
        seen[t.core_slices] += 1
        outer = np.zeros(g.shape, int)
        outer[t.outer_slices] = 1
        sub = outer[t.outer_slices]
        assert sub[t.inner_slices].all()
        r0, c0, nr, nc = t.outer
        assert r0 >= 0 and c0 >= 0 and r0 + nr <= g.rows and c0 + nc <= g.cols
        # the margin is `overlap` wherever the grid allows it
        assert t.core[0] - r0 == min(overlap, t.core[0])
    assert (seen == 1).all()


def test_grid_rejects_bad_input():
    with pytest.raises(InputError, match="resolution"):
        RasterGrid.from_extent((0, 0, 1, 1), 0)
    with pytest.raises(InputError, match="xmin < xmax"):
        RasterGrid.from_extent((0, 0, -1, 1), 1)
    with pytest.raises(InputError, match="cells"):
        RasterGrid.from_extent((0, 0, 1e6, 1e6), 0.001)
    with pytest.raises(InputError, match="north-up"):
        RasterGrid.from_geotransform((0, 1, 0.2, 0, 0, -1), 3, 3)


def test_raster_writer_tiles_roundtrip_and_nodata(tmp_path):
    g = RasterGrid(500000.0, 5600000.0, 0.25, 300, 410, "EPSG:32632")
    rng = np.random.default_rng(1)
    full = rng.normal(size=g.shape).astype(np.float32)
    full[5:9, 5:9] = np.nan
    out = tmp_path / "dsm.tif"
    with RasterWriter(out, g, dtype="float32", nodata=-9999.0, overviews=True) as w:
        for t in g.tiles(128, 8):
            tile = full[t.outer_slices]
            w.write(np.where(np.isnan(tile), -9999.0, tile)[t.inner_slices], t.core)
    data, g2, nodata = read_raster(out)
    assert g2 == g and nodata == -9999.0
    np.testing.assert_array_equal(np.isnan(data), np.isnan(full))
    np.testing.assert_allclose(data[~np.isnan(data)], full[~np.isnan(full)])
    assert raster_grid(out).crs == "EPSG:32632"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dsm.tif"]


def test_preview_and_valid_share_read_by_windows(tmp_path):
    """The report's previews come from the overviews at the reduced size; the valid share is exact."""
    g = RasterGrid(500000.0, 5600000.0, 0.5, 2500, 1300, "EPSG:32632")
    z = np.add.outer(np.arange(g.rows), np.arange(g.cols)).astype(np.float32)
    z[100:300, 200:900] = np.nan
    write_raster(tmp_path / "z.tif", np.where(np.isnan(z), -9999.0, z), g, nodata=-9999.0, overviews=True)
    p, pg, nod = read_preview(tmp_path / "z.tif", 500)
    assert p.shape == (500, 260) and pg.res == pytest.approx(2.5) and nod == -9999.0
    assert np.nanmax(np.abs(p - z[2::5, 2::5])) <= 5 and np.isnan(p[30, 60])
    assert read_preview(tmp_path / "z.tif", 5000)[0].shape == g.shape
    assert valid_share(tmp_path / "z.tif", block=700) == pytest.approx(np.isfinite(z).mean())
    rgb = np.zeros((3, g.rows, g.cols), np.uint8)
    write_raster(tmp_path / "o.tif", rgb, g, nodata=0)
    assert read_preview(tmp_path / "o.tif", 1000, band=None)[0].shape == (3, 834, 434)
    assert valid_share(tmp_path / "o.tif") == 0.0
    with pytest.raises(InputError, match="max_side"):
        read_preview(tmp_path / "z.tif", 0)


def test_failed_write_leaves_nothing_and_keeps_old_file(tmp_path):
    g = RasterGrid(0.0, 10.0, 1.0, 10, 10, "EPSG:32632")
    out = tmp_path / "a.tif"
    write_raster(out, np.ones(g.shape, np.float32), g, nodata=-1.0)
    with pytest.raises(RuntimeError):
        with RasterWriter(out, g) as w:
            w.write(np.zeros((10, 10), np.float32))
            raise RuntimeError("cancelled half way")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.tif"]
    assert read_raster(out)[0].min() == 1.0


def test_cog_rgba(tmp_path):
    g = RasterGrid(0.0, 600.0, 1.0, 600, 600, "EPSG:32632")
    rgba = np.zeros((4, 600, 600), np.uint8)
    rgba[:3] = 120
    rgba[3, :300] = 255
    out = tmp_path / "ortho.tif"
    write_raster(out, rgba, g, nodata=None, alpha=True, cog=True)
    import rasterio

    with rasterio.open(out) as ds:
        assert ds.count == 4 and ds.overviews(1) and ds.colorinterp[3].name == "alpha"
        assert ds.profile["tiled"]
        # the fast temporary codec (ZSTD when GDAL has it) never reaches the product: DEFLATE, COG layout
        assert ds.compression.name.lower() == "deflate"
        assert ds.tags(ns="IMAGE_STRUCTURE").get("LAYOUT") == "COG"
        np.testing.assert_array_equal(ds.read(), rgba)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ortho.tif"]  # no temporary left


@pytest.mark.parametrize("compress", ["zstd", "lzw", "none"])
def test_cog_lossless_compressions_keep_every_value(tmp_path, compress):
    from truortho.core.rasterio_io import _has_zstd

    if compress == "zstd" and not _has_zstd():
        pytest.skip("this GDAL has no ZSTD")
    g = RasterGrid(0.0, 600.0, 1.0, 600, 600, "EPSG:32632")
    rng = np.random.default_rng(2)
    rgba = rng.integers(0, 256, (4, 600, 600), dtype=np.uint8)
    out = tmp_path / "o.tif"
    write_raster(out, rgba, g, alpha=True, cog=True, compress=compress)
    import rasterio

    with rasterio.open(out) as ds:
        assert (ds.compression.name.lower() if ds.compression else "none") == compress
        assert ds.tags(ns="IMAGE_STRUCTURE").get("LAYOUT") == "COG" and ds.count == 4
        np.testing.assert_array_equal(ds.read(), rgba)


def test_cog_jpeg_turns_alpha_into_a_mask(tmp_path):
    import rasterio

    g = RasterGrid(0.0, 600.0, 1.0, 600, 600, "EPSG:32632")
    yy, xx = np.mgrid[0:600, 0:600]
    rng = np.random.default_rng(5)
    tex = 60 * np.sin(xx / 7.0) * np.cos(yy / 5.0) + rng.normal(0, 3, xx.shape)  # texture + noise
    rgba = np.stack(
        [np.clip(90 + tex + xx * 0.1, 0, 255), np.clip(120 + tex, 0, 255), np.clip(140 - tex, 0, 255),
         np.where((xx - 300) ** 2 + (yy - 300) ** 2 < 250**2, 255, 0)]
    ).astype(np.uint8)  # fmt: skip
    sizes = {}
    for comp in ("deflate", "jpeg"):
        out = tmp_path / f"{comp}.tif"
        write_raster(out, rgba, g, alpha=True, cog=True, compress=comp, quality=85)
        sizes[comp] = out.stat().st_size
    with rasterio.open(tmp_path / "jpeg.tif") as ds:
        assert ds.count == 3 and ds.compression.name.lower() == "jpeg" and ds.photometric.name == "ycbcr"
        assert ds.tags(ns="IMAGE_STRUCTURE").get("LAYOUT") == "COG" and ds.overviews(1)
        valid = rgba[3] > 0
        np.testing.assert_array_equal(ds.dataset_mask() > 0, valid)
        got = ds.read().astype(int)
    err = np.abs(got - rgba[:3].astype(int))[:, valid]
    print("JPEG error mean", err.mean(), "p99", np.percentile(err, 99), sizes)
    assert err.mean() < 4.0 and np.percentile(err, 99) <= 15  # lossy (noise sigma 3), but close
    assert sizes["jpeg"] < sizes["deflate"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["deflate.tif", "jpeg.tif"]


def test_writer_rejects_bad_compressions(tmp_path):
    g = RasterGrid(0.0, 64.0, 1.0, 64, 64, "EPSG:32632")
    with pytest.raises(InputError, match="JPEG compression needs 8-bit data, got uint16"):
        RasterWriter(tmp_path / "a.tif", g, 1, "uint16", cog=True, compress="jpeg")
    for bands in (2, 6):  # grey + alpha (the alpha would be compressed lossy), or too many bands
        with pytest.raises(InputError, match=f"3-band .RGB. data, got {bands - 1} band"):
            RasterWriter(tmp_path / "a.tif", g, bands, "uint8", alpha=True, cog=True, compress="jpeg")
    with pytest.raises(InputError, match="COG layout only"):
        RasterWriter(tmp_path / "a.tif", g, 4, "uint8", alpha=True, compress="jpeg")
    with pytest.raises(InputError, match="JPEG quality must be an integer in \\[1, 100\\], got 0"):
        RasterWriter(tmp_path / "a.tif", g, 3, "uint8", cog=True, compress="jpeg", quality=0)
    with pytest.raises(InputError, match="'webp' is not one of deflate, zstd, lzw, jpeg, none"):
        RasterWriter(tmp_path / "a.tif", g, 3, "uint8", compress="webp")
    assert not list(tmp_path.iterdir())


def test_writers_closed_early_in_threads_are_complete_and_leave_no_temporary(tmp_path):
    """``close()`` finishes a raster inside its ``with`` block (the true ortho closes its three
    rasters at once in threads); the exit after it changes nothing."""
    from concurrent.futures import ThreadPoolExecutor

    g = RasterGrid(0.0, 600.0, 1.0, 600, 600, "EPSG:32632")
    data = np.arange(600 * 600, dtype=np.float32).reshape(1, 600, 600)
    paths = [tmp_path / f"r{i}.tif" for i in range(3)]
    with (
        RasterWriter(paths[0], g, 1, "float32", cog=True) as a,
        RasterWriter(paths[1], g, 1, "float32", overviews=True) as b,
        RasterWriter(paths[2], g, 1, "float32") as c,
    ):
        for w in (a, b, c):
            w.write(data)
        with ThreadPoolExecutor(3) as pool:
            list(pool.map(lambda w: w.close(), (a, b, c)))
        assert all(p.exists() for p in paths)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r0.tif", "r1.tif", "r2.tif"]
    for p in paths:
        got, _, _ = read_raster(p)
        np.testing.assert_array_equal(got, data[0])
    with pytest.raises(InputError, match="outside its 'with' block"):
        a.write(data)


def test_read_onto_grid_reprojects(tmp_path):
    g = RasterGrid(500000.0, 5600100.0, 1.0, 100, 100, "EPSG:32632")
    X, Y = g.centres()
    write_raster(tmp_path / "plane.tif", (0.01 * (X - 500000) + 2.0).astype(np.float32), g, nodata=-9999.0)
    sub = g.window(10, 10, 20, 20).scaled(1)
    got = read_onto_grid(tmp_path / "plane.tif", sub)
    Xs, _ = sub.centres()
    np.testing.assert_allclose(got, 0.01 * (Xs - 500000) + 2.0, atol=1e-4)
    with pytest.raises(CRSError):
        read_onto_grid(tmp_path / "plane.tif", RasterGrid(0.0, 1.0, 1.0, 2, 2, None))


@pytest.mark.parametrize("suffix", [".las", ".laz"])
def test_point_cloud_roundtrip(tmp_path, suffix):
    import laspy

    rng = np.random.default_rng(0)
    xyz = rng.uniform(0, 100, (500, 3)) + [500000.0, 5600000.0, 100.0]
    rgb = rng.integers(0, 256, (500, 3)).astype(np.uint8)
    conf = rng.uniform(0, 1, 500).astype(np.float32)
    out = write_point_cloud(tmp_path / f"pc{suffix}", xyz, rgb, "EPSG:32632", {"confidence": conf})
    las = laspy.read(out)
    assert las.header.version.minor == 4 and len(las.points) == 500
    np.testing.assert_allclose(np.column_stack([las.x, las.y, las.z]), xyz, atol=6e-4)
    np.testing.assert_array_equal(np.asarray(las.red) // 257, rgb[:, 0])
    np.testing.assert_allclose(np.asarray(las["confidence"]), conf)
    assert las.header.parse_crs().to_epsg() == 32632
    with pytest.raises(InputError, match=".las or .laz"):
        write_point_cloud(tmp_path / "pc.xyz", xyz)
