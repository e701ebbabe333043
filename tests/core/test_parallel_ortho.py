"""Tile-parallel true orthophoto (core/ortho/tiles.py on core/parallel).

Acceptance (issue 8, orthophoto part): in-process, a local Dask cluster of 2 worker processes and a
scheduler started separately (``dask scheduler`` + ``dask worker`` on 127.0.0.1) give a bit-identical
mosaic, source index and occlusion mask and the same seamline areas; a worker killed mid-run changes
nothing; a rerun reuses the cached tiles and a run with other parameters reuses none.
"""

from __future__ import annotations

import os
import signal

import numpy as np
import pytest

pytest.importorskip("cv2")
pytest.importorskip("distributed")

from truortho.core.ortho.pipeline import TrueOrthoConfig, true_ortho  # noqa: E402
from truortho.core.ortho.tiles import waves  # noqa: E402
from truortho.core.parallel import SchedulerExecutor  # noqa: E402
from truortho.core.progress import CallbackProgress  # noqa: E402
from truortho.core.rasterio_io import read_raster  # noqa: E402
from truortho.core.synthetic import SceneConfig, make_scene  # noqa: E402

SCENE = dict(
    extent=(-20.0, -15.0, 20.0, 15.0), n_buildings=2, building_size=(7.0, 11.0), building_gap=3.0,
    tower=False, image_size=(240, 180), focal_px=300.0, n_oblique=0, seed=5,
)  # fmt: skip
RES, TILE = 0.25, 48  # 160 x 120 cells: 4 x 3 tiles in 4 waves


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    folder = tmp_path_factory.mktemp("parallel_ortho_scene")
    sc = make_scene(SceneConfig(**SCENE))
    sc.write(folder)
    return sc, folder


def _run(scene, out, executor=None, progress=None, **cfg):
    sc, folder = scene
    config = TrueOrthoConfig(resolution=RES, tile_size=TILE, extent=sc.extent_world(), **cfg)
    return true_ortho(folder / "orientation.json", folder / "dsm.tif", out / "ortho.tif", out / "idx.tif",
                      out / "occ.tif", config, progress=progress, executor=executor)  # fmt: skip


def _products(out):
    return tuple(read_raster(out / n, band=None)[0] for n in ("ortho.tif", "idx.tif", "occ.tif"))


def _same(a, b) -> bool:
    return all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))


@pytest.fixture(scope="module")
def reference(scene, tmp_path_factory):
    out = tmp_path_factory.mktemp("ortho_reference")
    r = _run(scene, out)
    assert r.stats["tiles"] == 12 and r.stats["executor"] == "inprocess"
    assert r.stats["coverage"] > 0.95 and not (out / "ortho.tif.tiles").exists()
    return _products(out), {s.image_index: round(s.geometry.area, 6) for s in r.seamlines}


def test_waves_are_four_independent_parity_classes():
    from truortho.core.grid import RasterGrid

    g = RasterGrid.from_extent((0, 0, 100, 80), 1.0, None)
    tiles = g.tiles(16, 4)
    ws = waves(tiles)
    assert len(ws) == 4 and sorted(t.index for w in ws for t in w) == sorted(t.index for t in tiles)
    for w in ws:
        # no two tiles of a wave touch (their outer windows never meet each other's cores)
        idx = [t.index for t in w]
        for a in idx:
            for b in idx:
                assert a == b or max(abs(a[0] - b[0]), abs(a[1] - b[1])) >= 2
    assert ws[0][0].index == (0, 0) and len(ws[0]) * 4 >= len(tiles)


@pytest.mark.slow
def test_local_cluster_gives_the_in_process_orthophoto(scene, reference, dask_cluster, tmp_path):
    r = _run(scene, tmp_path, executor=dask_cluster)
    assert r.stats["executor"] == "local"
    assert _same(_products(tmp_path), reference[0])
    assert {s.image_index: round(s.geometry.area, 6) for s in r.seamlines} == reference[1]


@pytest.mark.slow
def test_separate_scheduler_gives_the_in_process_orthophoto(scene, reference, dask_scheduler_file, tmp_path):
    with SchedulerExecutor(dask_scheduler_file) as ex:
        r = _run(scene, tmp_path, executor=ex)
    assert r.stats["executor"] == "scheduler"
    assert _same(_products(tmp_path), reference[0])


@pytest.mark.slow
def test_reprojected_output_and_mesh_surface_on_the_cluster(scene, dask_cluster, tmp_path):
    """Another output CRS (pyproj rebuilt on the workers) and a mesh surface (arrays shipped to the
    workers): the cluster gives the in-process result."""
    from truortho.core.ortho.surface import MeshSurface, transform_bounds
    from truortho.core.ortho.zbuffer import dsm_triangles

    sc, folder = scene
    ext = sc.extent_world()
    crs = sc.config.crs
    b = transform_bounds((ext[0] + 5, ext[1] + 5, ext[2] - 5, ext[3] - 5), crs, "EPSG:32633")
    h, gt = sc.dsm(RES)
    tris = dsm_triangles(h, gt[0], gt[3], RES)
    mesh = MeshSurface(tris.vertices, tris.faces, crs)
    for name, surface, cfg in (
        ("utm33", folder / "dsm.tif", dict(crs="EPSG:32633", extent=b)),
        ("mesh", mesh, dict(extent=ext)),
    ):
        runs = {}
        for where, ex in (("in", None), ("dask", dask_cluster)):
            out = tmp_path / f"{name}_{where}.tif"
            config = TrueOrthoConfig(resolution=RES, tile_size=TILE, color_correction=False, **cfg)
            r = true_ortho(folder / "orientation.json", surface, out, config=config, executor=ex)
            runs[where] = read_raster(out, band=None)[0]
        assert r.stats["tiles"] >= 4 and (name != "utm33" or r.stats["reprojected"])
        assert np.array_equal(runs["in"], runs["dask"]), name
        assert (runs["in"][-1] > 0).mean() > 0.9


@pytest.mark.slow
def test_a_worker_killed_mid_run_changes_nothing(scene, reference, dask_cluster, tmp_path):
    pids = dask_cluster.worker_pids()
    killed = []

    def on_update(fraction, message):
        # a wave of two tiles has finished one: the other is running (or queued) on a worker
        if not killed and message and "true ortho: tile 1/2" in message:
            busy = [a for a, keys in dask_cluster.client.processing().items() if keys]
            if busy and busy[0] in pids:
                os.kill(pids[busy[0]], signal.SIGKILL)
                killed.append(pids[busy[0]])

    _run(scene, tmp_path, executor=dask_cluster, progress=CallbackProgress(on_update))
    assert killed, "no worker was killed"
    assert _same(_products(tmp_path), reference[0])


def test_cache_reuses_tiles_of_the_same_run_only(scene, reference, tmp_path):
    cache = tmp_path / "cache"
    r1 = _run(scene, tmp_path / "a", cache_dir=cache)
    assert r1.stats["tile_cache"] == {"hits": 0, "written": 12}
    r2 = _run(scene, tmp_path / "b", cache_dir=cache, workers=1)  # threads are not part of the key
    assert r2.stats["tile_cache"] == {"hits": 12, "written": 0}
    assert _same(_products(tmp_path / "b"), reference[0])
    r3 = _run(scene, tmp_path / "c", cache_dir=cache, blend_width=2)
    assert r3.stats["tile_cache"]["hits"] == 0
    assert not _same(_products(tmp_path / "c"), reference[0])


def test_cache_of_another_version_is_not_reused(scene, reference, tmp_path, monkeypatch):
    """Tiles cached by a version whose visibility or mosaic differed are not reused (the key holds
    the module's CACHE_VERSION)."""
    from truortho.core.ortho import pipeline

    cache = tmp_path / "cache"
    monkeypatch.setattr(pipeline, "CACHE_VERSION", pipeline.CACHE_VERSION - 1)
    assert _run(scene, tmp_path / "old", cache_dir=cache).stats["tile_cache"]["written"] == 12
    monkeypatch.undo()
    r = _run(scene, tmp_path / "new", cache_dir=cache)
    assert r.stats["tile_cache"] == {"hits": 0, "written": 12}
    assert _same(_products(tmp_path / "new"), reference[0])


def test_rerun_after_a_crash_resumes_from_the_finished_tiles(scene, reference, tmp_path):
    seen = []

    def on_update(fraction, message):
        if message and "true ortho: tile" in message:
            seen.append(message)
            if len(seen) == 5:
                raise RuntimeError("simulated crash")

    with pytest.raises(RuntimeError, match="simulated crash"):
        _run(scene, tmp_path, progress=CallbackProgress(on_update))
    assert not (tmp_path / "ortho.tif").exists()
    assert len(list((tmp_path / "ortho.tif.tiles").glob("*.npz"))) == 5
    r = _run(scene, tmp_path)
    assert r.stats["tile_cache"] == {"hits": 5, "written": 7}
    assert _same(_products(tmp_path), reference[0])
    assert not (tmp_path / "ortho.tif.tiles").exists()


def test_views_computed_ahead_give_the_same_mosaic(scene, reference, tmp_path, monkeypatch):
    """In this process the coming tiles' visibility runs ahead in a background thread
    (``ViewPrefetch``); the products are bit-identical to computing it in the tile task."""
    from truortho.core.ortho import tiles as T

    taken: list[bool] = []
    take = T.ViewPrefetch.take

    def counting_take(self, tile):
        v = take(self, tile)
        taken.append(v is not None)
        return v

    monkeypatch.setattr(T.ViewPrefetch, "take", counting_take)
    (tmp_path / "ahead").mkdir()
    _run(scene, tmp_path / "ahead")  # 2 threads, waves of >= 2 tiles: only the first wave looks ahead
    assert sum(taken) == 1
    assert _same(_products(tmp_path / "ahead"), reference[0])
    taken.clear()
    (tmp_path / "ahead5").mkdir()
    _run(scene, tmp_path / "ahead5", workers=5)  # waves of 4, 4, 2, 2 tiles: one tile of each ahead
    assert sum(taken) == 4
    assert _same(_products(tmp_path / "ahead5"), reference[0])
    taken.clear()
    (tmp_path / "one").mkdir()
    _run(scene, tmp_path / "one", workers=1)  # one thread: nothing runs ahead
    assert not taken
    assert _same(_products(tmp_path / "one"), reference[0])
    monkeypatch.setattr(T.ViewPrefetch, "usable", staticmethod(lambda setup: False))
    taken.clear()
    (tmp_path / "inline").mkdir()
    _run(scene, tmp_path / "inline")
    assert not taken
    assert _same(_products(tmp_path / "inline"), reference[0])


def test_an_error_in_the_look_ahead_reaches_the_caller_and_nothing_is_written(scene, tmp_path, monkeypatch):
    import threading

    from truortho.core.ortho import tiles as T

    def failing(*args, **kwargs):
        if threading.current_thread().name.startswith("truortho-views"):
            raise MemoryError("simulated failure in the look-ahead thread")
        return real(*args, **kwargs)

    real = T.all_tile_views
    monkeypatch.setattr(T, "all_tile_views", failing)
    with pytest.raises(MemoryError, match="look-ahead"):
        _run(scene, tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # no product, no temporary, no scratch
    assert not [t for t in threading.enumerate() if t.name.startswith("truortho-views")]


def test_prune_views_keeps_the_top_and_the_preferred_images():
    from truortho.core.grid import RasterGrid
    from truortho.core.ortho.views import TileViews, ViewSetup, prune_views

    K, r, c = 5, 3, 4
    g = RasterGrid.from_extent((0, 0, c, r), 1.0, None)
    rng = np.random.default_rng(0)
    v = TileViews(
        g, np.zeros((r, c)), np.array([2, 4, 7, 9, 11]), rng.random((K, r, c)) > 0.3,
        np.zeros((K, r, c), bool), rng.random((K, r, c, 2)).astype(np.float32),
        rng.random((K, r, c)).astype(np.float32), np.arange(K, dtype=float), 10,
        np.array([True, False, True, False, False]),
    )  # fmt: skip
    setup = ViewSetup([], [], np.zeros((0, 4)), 0.0, 1.0, 0.7, 0, True, 1.0, 1.0, 0.0, top_views=2)
    p = prune_views(v, setup)
    assert list(p.cands) == [2, 7] and p.top is None and p.triangles == 10
    assert np.array_equal(p.uv, v.uv[[0, 2]]) and np.array_equal(p.usable, v.usable[[0, 2]])
    p = prune_views(v, setup, prefer=np.array([9, 30]))
    assert list(p.cands) == [2, 7, 9] and np.array_equal(p.eff_res, v.eff_res[[0, 2, 3]])
    # no pruning pending, or no bound: unchanged
    import dataclasses

    assert list(prune_views(dataclasses.replace(v, top=None), setup).cands) == [2, 4, 7, 9, 11]
    assert list(prune_views(v, dataclasses.replace(setup, top_views=0)).cands) == [2, 4, 7, 9, 11]
