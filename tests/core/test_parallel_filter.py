"""Tile-parallel DSM filter (core/surface/filter/ on core/parallel): the same filtered DSM and
statistics from every executor, the tile cache, the in-memory path.

Acceptance (issue 8, DSM-filter part): in-process, a local Dask cluster of 2 worker processes and a
scheduler started separately on this machine (``dask scheduler`` + ``dask worker`` on 127.0.0.1)
give a bit-identical filtered DSM (NaN equal) and equal statistics; a rerun with a cache folder
reuses every tile and a run with another parameter (or a rewritten input) none;
``filter_dsm_array`` gives what ``filter_dsm`` writes.
"""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.grid import RasterGrid
from truortho.core.parallel import InProcessExecutor, SchedulerExecutor
from truortho.core.rasterio_io import read_raster, write_raster
from truortho.core.surface import filter as F
from truortho.core.surface.filter import DsmFilterConfig, filter_dsm, filter_dsm_array

RES = 0.5
ROWS, COLS = 80, 100
TILE = 32  # 3 x 4 = 12 tiles
CONFIG = dict(tile=TILE, max_hole=4.0, smooth=True)
#: holes (r0, c0, rows, cols): small ones across tile borders and inside tiles, one wider than max_hole
SMALL_HOLES = [(30, 20, 4, 3), (10, 62, 3, 5), (60, 60, 2, 2), (45, 31, 3, 3)]
LARGE_HOLE = (56, 8, 14, 16)


def _dsm(seed: int = 7):
    """Ground plane + two flat-roof buildings, spikes and pits, small and large holes, a confidence."""
    rng = np.random.default_rng(seed)
    rr, cc = np.mgrid[0:ROWS, 0:COLS]
    z = 100.0 + 0.02 * rr + 0.01 * cc + rng.normal(0, 0.03, (ROWS, COLS))
    z[12:28, 14:40] += 9.0  # a building across a tile border (column 32)
    z[40:58, 70:90] += 6.0
    spikes = rng.choice(ROWS * COLS, 60, replace=False)
    z.flat[spikes] += rng.choice([-8.0, 12.0], 60)
    for r0, c0, nr, nc in [*SMALL_HOLES, LARGE_HOLE]:
        z[r0 : r0 + nr, c0 : c0 + nc] = np.nan
    conf = np.clip(rng.uniform(0.3, 1.0, (ROWS, COLS)), 0, 1)
    conf.flat[rng.choice(ROWS * COLS, 40, replace=False)] = 0.01  # below min_confidence
    return z.astype(np.float32), conf.astype(np.float32)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("filter_parallel")
    z, conf = _dsm()
    grid = RasterGrid(500000.0, 5600000.0, RES, ROWS, COLS, "EPSG:32632")
    write_raster(folder / "raw.tif", np.where(np.isfinite(z), z, -9999.0), grid, nodata=-9999.0)
    write_raster(folder / "conf.tif", conf, grid, nodata=None)
    return folder, grid, z, conf


def _filter(files, out, executor=None, cache_dir=None, **cfg):
    folder = files[0]
    config = DsmFilterConfig(**{**CONFIG, **cfg})
    stats = filter_dsm(
        folder / "raw.tif", out, folder / "conf.tif", config, executor=executor, cache_dir=cache_dir
    )
    return read_raster(out)[0], stats.as_dict()


@pytest.fixture(scope="module")
def reference(files, tmp_path_factory):
    out = tmp_path_factory.mktemp("filter_reference") / "filtered.tif"
    dsm, stats = _filter(files, out)
    grid = files[1]
    assert len(grid.tiles(TILE)) >= 4
    # the scene exercises every stage, and the merge across tile borders
    assert stats["outliers_removed"] > 0 and stats["low_confidence_removed"] > 0
    assert stats["holes_filled"] >= len(SMALL_HOLES) and stats["smoothed"] > 0
    assert stats["holes_remaining"] == 1 and stats["largest_remaining_hole_m"] > CONFIG["max_hole"]
    r0, c0, nr, nc = LARGE_HOLE
    assert np.isnan(dsm[r0 : r0 + nr, c0 : c0 + nc]).all()  # nodata (read as NaN)
    for r0, c0, nr, nc in SMALL_HOLES:
        assert np.isfinite(dsm[r0 : r0 + nr, c0 : c0 + nc]).all()
    return dsm, stats


def _same(a, b) -> bool:
    return a[0].dtype == b[0].dtype and np.array_equal(a[0], b[0], equal_nan=True) and a[1] == b[1]


class _Spy(InProcessExecutor):
    """In-process, counting the tasks it runs and recording the cache and memory it was given."""

    def __init__(self) -> None:
        self.ran = 0
        self.calls: list[dict] = []

    def map_tiles(self, fn, tasks, progress=None, **kw):
        def counted(*args):
            self.ran += 1
            return fn(*args)

        out = super().map_tiles(counted, tasks, progress, **kw)
        self.calls.append(dict(kw, n=len(tasks)))
        return out


# ------------------------------------------------------------------ in this process


def test_array_path_equals_the_file_path(files, reference):
    _, grid, z, conf = files
    out, stats = filter_dsm_array(z, grid, conf, DsmFilterConfig(**CONFIG))
    assert stats.as_dict() == reference[1]
    assert out.dtype == reference[0].dtype and np.array_equal(out, reference[0], equal_nan=True)


def test_each_pass_is_one_map_tiles_call_with_a_memory_estimate(files, reference, tmp_path):
    spy = _Spy()
    assert _same(_filter(files, tmp_path / "f.tif", executor=spy), reference)
    n = len(files[1].tiles(TILE))
    assert [c["n"] for c in spy.calls] == [n, n] and spy.ran == 2 * n
    assert [c["label"] for c in spy.calls] == ["DSM filter: outliers and holes", "DSM filter: filling"]
    for c in spy.calls:
        assert c["cache"] is None and c["shared"] is not None
        assert TILE * TILE * F.TASK_BYTES_PER_CELL < c["memory"] <= ROWS * COLS * F.TASK_BYTES_PER_CELL


def test_pass_two_in_write_batches_gives_the_same_result(files, reference, tmp_path, monkeypatch):
    monkeypatch.setattr(F.pipeline, "WRITE_BATCH_BYTES", 5 * 4 * TILE * TILE)  # 5 tiles per batch
    spy = _Spy()
    assert _same(_filter(files, tmp_path / "f.tif", executor=spy), reference)
    assert [c["n"] for c in spy.calls] == [12, 5, 5, 2]


def test_cache_reuses_the_tiles_of_the_same_run_only(files, reference, tmp_path):
    folder, grid = files[0], files[1]
    n = len(grid.tiles(TILE))
    cache = tmp_path / "cache"

    def run(name, **cfg):
        spy = _Spy()
        got = _filter(files, tmp_path / f"{name}.tif", executor=spy, cache_dir=cache, **cfg)
        tile_cache = spy.calls[0]["cache"]
        assert all(c["cache"] is tile_cache for c in spy.calls)  # one TileCache per run
        return got, spy.ran, tile_cache.hits

    first, ran, hits = run("first")
    assert _same(first, reference) and (ran, hits) == (2 * n, 0)
    assert len(list(cache.glob("*.npz"))) == 2 * n
    again, ran, hits = run("again")
    assert _same(again, reference) and (ran, hits) == (0, 2 * n)
    # another parameter: other keys, nothing reused (and nothing of the first run overwritten)
    other, ran, hits = run("other", outlier_threshold=3.0)
    assert (ran, hits) == (2 * n, 0) and not _same(other, reference)
    assert len(list(cache.glob("*.npz"))) == 4 * n
    # a rewritten input (new size/mtime): nothing reused
    raw = read_raster(folder / "raw.tif")
    copy = tmp_path / "raw_copy.tif"
    write_raster(copy, np.where(np.isfinite(raw[0]), raw[0], -9999.0), raw[1], nodata=raw[2])
    spy = _Spy()
    filter_dsm(copy, tmp_path / "copy.tif", folder / "conf.tif", DsmFilterConfig(**CONFIG), executor=spy,
               cache_dir=cache)  # fmt: skip
    assert spy.ran == 2 * n and spy.calls[0]["cache"].hits == 0
    assert np.array_equal(read_raster(tmp_path / "copy.tif")[0], reference[0], equal_nan=True)


# ------------------------------------------------------------------ on Dask


@pytest.mark.slow
def test_local_cluster_gives_the_in_process_result(files, reference, dask_cluster, tmp_path):
    got = _filter(files, tmp_path / "f.tif", executor=dask_cluster)
    assert _same(got, reference)


@pytest.mark.slow
def test_separate_scheduler_gives_the_in_process_result(files, reference, dask_scheduler_file, tmp_path):
    with SchedulerExecutor(dask_scheduler_file) as ex:
        got = _filter(files, tmp_path / "f.tif", executor=ex, cache_dir=tmp_path / "cache")
        assert len(ex.client.nthreads()) == 2
    assert _same(got, reference)
    n = len(files[1].tiles(TILE))
    assert len(list((tmp_path / "cache").glob("*.npz"))) == 2 * n  # stored in this process
