"""Tile-parallel OSGM (core/parallel): the same products from every executor, fault tolerance, the tile cache.

Acceptance (issue 8, OSGM part): in-process, a local Dask cluster of 2 worker processes and a
scheduler started separately on this machine (``dask scheduler`` + ``dask worker`` on 127.0.0.1)
give a bit-identical DSM and confidence (NaN equal); a worker killed mid-run changes nothing; a rerun
reuses the cached tiles and a run with other parameters reuses none; cancel writes nothing.
"""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("cv2")
pytest.importorskip("distributed")

from truortho.core.errors import CancelledError, InputError  # noqa: E402
from truortho.core.osgm import OsgmConfig, OsgmOutputs, run_osgm  # noqa: E402
from truortho.core.parallel import (  # noqa: E402
    Digest,
    InProcessExecutor,
    LocalDaskExecutor,
    SchedulerExecutor,
    TileCache,
    make_executor,
)
from truortho.core.progress import CallbackProgress  # noqa: E402
from truortho.core.rasterio_io import read_raster  # noqa: E402
from truortho.core.synthetic import SceneConfig, make_scene  # noqa: E402

SCENE = dict(
    extent=(-20.0, -15.0, 20.0, 15.0), n_buildings=2, building_size=(7.0, 11.0), building_gap=3.0,
    tower=False, image_size=(240, 180), focal_px=300.0, n_oblique=0, seed=5,
)  # fmt: skip
RES, TILE = 0.5, 32  # 80 x 60 cells: 2 tiles on level 1, 6 on level 0


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    folder = tmp_path_factory.mktemp("parallel_scene")
    sc = make_scene(SceneConfig(**SCENE))
    sc.write(folder)
    return sc, folder


def _run(scene, out: Path, executor=None, progress=None, **cfg):
    sc, folder = scene
    config = OsgmConfig(resolution=RES, tile_size=TILE, **cfg)
    outputs = OsgmOutputs(dsm=out / "dsm.tif", confidence=out / "conf.tif")
    return run_osgm(sc.orientation, config, sc.extent_world(), outputs, folder, progress=progress,
                    executor=executor)  # fmt: skip


def _products(out: Path):
    return read_raster(out / "dsm.tif")[0], read_raster(out / "conf.tif")[0]


def _same(a, b) -> bool:
    return all(np.array_equal(x, y, equal_nan=True) for x, y in zip(a, b, strict=True))


@pytest.fixture(scope="module")
def reference(scene, tmp_path_factory):
    out = tmp_path_factory.mktemp("reference")
    r = _run(scene, out)
    assert r.stats["tiles"] == 8 and r.stats["executor"] == "inprocess"
    dsm, conf = _products(out)
    assert np.isfinite(dsm).mean() > 0.95
    assert not (out / "dsm.tif.tiles").exists()  # the run's scratch tiles are gone after success
    return dsm, conf


@pytest.fixture(scope="module")
def cluster(dask_cluster):
    return dask_cluster


@pytest.fixture(scope="module")
def scheduler_file(dask_scheduler_file):
    return dask_scheduler_file


# ------------------------------------------------------------------ the same products everywhere


@pytest.mark.slow
def test_local_cluster_gives_the_in_process_products(scene, reference, cluster, tmp_path):
    r = _run(scene, tmp_path, executor=cluster)
    assert r.stats["executor"].startswith("local Dask cluster, 2 worker")
    assert _same(_products(tmp_path), reference)


@pytest.mark.slow
def test_separate_scheduler_gives_the_in_process_products(scene, reference, scheduler_file, tmp_path):
    with SchedulerExecutor(scheduler_file) as ex:
        r = _run(scene, tmp_path, executor=ex)
        assert len(ex.client.nthreads()) == 2
    assert r.stats["executor"].startswith("Dask scheduler")
    assert _same(_products(tmp_path), reference)


@pytest.mark.slow
def test_a_worker_killed_mid_run_changes_nothing(scene, reference, cluster, tmp_path):
    before = cluster.worker_pids()
    assert len(before) == 2
    killed = []

    def on_update(fraction, message):
        # the first finished tile of the fine level: the other level-0 tiles are running or queued
        if not killed and message and "level 0: tile 1/" in message:
            busy = [a for a, keys in cluster.client.processing().items() if keys]
            assert busy, "no worker has a tile to lose"
            pid = before[busy[0]]
            os.kill(pid, signal.SIGKILL)  # its running tile must be recomputed elsewhere
            killed.append(pid)

    _run(scene, tmp_path, executor=cluster, progress=CallbackProgress(on_update))
    assert killed, "no worker was killed"
    assert _same(_products(tmp_path), reference)
    # the nanny started a new worker process in place of the killed one
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        after = cluster.worker_pids()
        if len(after) == 2 and killed[0] not in after.values():
            break
        time.sleep(0.5)
    assert killed[0] not in cluster.worker_pids().values()


# ------------------------------------------------------------------ the tile cache


@pytest.mark.slow
def test_cache_reuses_tiles_of_the_same_run_only(scene, reference, tmp_path):
    cache = tmp_path / "cache"
    r1 = _run(scene, tmp_path / "a", cache_dir=cache)
    assert (r1.stats["cache_hits"], r1.stats["cache_tiles_written"]) == (0, 8)
    assert len(list(cache.glob("*.npz"))) == 8
    assert _same(_products(tmp_path / "a"), reference)
    # the same inputs and parameters: every tile from the cache, the same products
    r2 = _run(scene, tmp_path / "b", cache_dir=cache)
    assert (r2.stats["cache_hits"], r2.stats["cache_tiles_written"]) == (8, 0)
    assert _same(_products(tmp_path / "b"), reference)
    # where the work runs is not part of the key (a local cluster would reuse them too)
    assert "executor" not in OsgmConfig().result_fields()
    # other parameters: no tile reused (and none overwritten)
    r3 = _run(scene, tmp_path / "c", cache_dir=cache, uniqueness=0.95)
    assert (r3.stats["cache_hits"], r3.stats["cache_tiles_written"]) == (0, 8)
    r4 = _run(scene, tmp_path / "d", cache_dir=cache, p2=1500)
    assert r4.stats["cache_hits"] == 0
    assert len(list(cache.glob("*.npz"))) == 24
    assert not _same(_products(tmp_path / "c"), reference)
    # a changed image (same size, new mtime) invalidates every tile that reads it
    sc, folder = scene
    img = Path(folder) / sc.orientation.images[0].name
    st = img.stat()
    try:
        os.utime(img, ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))
        r5 = _run(scene, tmp_path / "e", cache_dir=cache)
        assert r5.stats["cache_hits"] == 0
    finally:
        os.utime(img, ns=(st.st_atime_ns, st.st_mtime_ns))


@pytest.mark.slow
def test_cache_of_another_version_is_not_reused(scene, reference, tmp_path, monkeypatch):
    """Tiles cached by a version whose matching differed are not reused (the key holds the module's
    CACHE_VERSION)."""
    from truortho.core.osgm import pipeline

    cache = tmp_path / "cache"
    monkeypatch.setattr(pipeline, "CACHE_VERSION", pipeline.CACHE_VERSION - 1)
    assert _run(scene, tmp_path / "old", cache_dir=cache).stats["cache_tiles_written"] == 8
    monkeypatch.undo()
    r = _run(scene, tmp_path / "new", cache_dir=cache)
    assert (r.stats["cache_hits"], r.stats["cache_tiles_written"]) == (0, 8)
    assert _same(_products(tmp_path / "new"), reference)


@pytest.mark.slow
def test_rerun_after_a_crash_resumes_from_the_finished_tiles(scene, reference, tmp_path):
    """A run dies after 4 tiles; its scratch tiles stay beside the DSM, the rerun computes only the rest."""
    done = []

    def on_update(fraction, message):
        if message and ": tile " in message:
            done.append(message)
            if len(done) == 4:
                raise RuntimeError("simulated crash")

    with pytest.raises(RuntimeError, match="simulated crash"):
        _run(scene, tmp_path, progress=CallbackProgress(on_update))
    scratch = tmp_path / "dsm.tif.tiles"
    assert len(list(scratch.glob("*.npz"))) == 4 and not (tmp_path / "dsm.tif").exists()
    r = _run(scene, tmp_path)
    assert (r.stats["cache_hits"], r.stats["cache_tiles_written"]) == (4, 4)
    assert _same(_products(tmp_path), reference)
    assert not scratch.exists()


# ------------------------------------------------------------------ cancel


def _cancel_after_first_tile():
    state = {"tiles": 0}

    def on_update(fraction, message):
        if message and ": tile " in message:
            state["tiles"] += 1

    return CallbackProgress(on_update, lambda: state["tiles"] >= 1), state


@pytest.mark.slow
@pytest.mark.parametrize("where", ["inprocess", "local"])
def test_cancel_stops_and_writes_nothing(scene, cluster, tmp_path, where):
    progress, state = _cancel_after_first_tile()
    ex = cluster if where == "local" else InProcessExecutor()
    t0 = time.perf_counter()
    with pytest.raises(CancelledError):
        _run(scene, tmp_path, executor=ex, progress=progress)
    assert state["tiles"] == 1  # nothing was scheduled, finished or reported after the cancel
    assert time.perf_counter() - t0 < 30
    assert list(tmp_path.iterdir()) == []  # no DSM, no confidence, no scratch tiles
    if where == "local":
        # the cancelled futures are gone from the cluster, which stays usable
        deadline = time.monotonic() + 10
        while cluster.client.processing() and any(cluster.client.processing().values()):
            assert time.monotonic() < deadline, "tasks still running after cancel"
            time.sleep(0.2)


# ------------------------------------------------------------------ the pieces


def _square(x):
    return x * x


def _scaled(k, x):
    return k * x


def test_in_process_executor_keeps_task_order_caches_and_cancels(tmp_path):
    ex = make_executor("inprocess")
    seen = []
    out = ex.map_tiles(_square, [3, 1, 2], CallbackProgress(lambda f, m: seen.append((f, m))), label="demo")
    assert out == [9, 1, 4] and seen[-1] == (1.0, "demo: tile 3/3")
    assert ex.map_tiles(_scaled, [1, 2], shared=10) == [10, 20]
    cache = TileCache(tmp_path / "c")
    key = lambda x: Digest("k", x).hexdigest()  # noqa: E731
    first = ex.map_tiles(lambda x: (np.full(2, x, np.float32),), [1, 2], cache=cache, key=key)
    again = ex.map_tiles(lambda x: pytest.fail("computed again"), [1, 2], cache=cache, key=key)
    assert cache.hits == 2 and cache.written == 2
    assert all(np.array_equal(a[0], b[0]) for a, b in zip(first, again, strict=True))
    calls = []
    with pytest.raises(CancelledError):
        ex.map_tiles(lambda x: calls.append(x), [1, 2, 3], CallbackProgress(None, lambda: len(calls) >= 1))
    assert calls == [1]


@pytest.mark.slow
def test_local_cluster_listens_on_loopback_only(cluster):
    """Every listening socket of the local cluster (scheduler and nannies in this process, the
    worker processes) is bound to 127.0.0.1: nothing is reachable from another machine."""
    import psutil

    pids = [os.getpid(), *cluster.worker_pids().values()]
    def conns(pid):
        p = psutil.Process(pid)
        return (getattr(p, "net_connections", None) or p.connections)(kind="inet")  # psutil < 6

    listening = [c.laddr for pid in pids for c in conns(pid) if c.status == psutil.CONN_LISTEN]
    assert len(listening) >= 3  # scheduler + a worker each at least
    assert all(a.ip == "127.0.0.1" for a in listening), listening


def test_executor_and_ortho_parameters_are_checked():
    from truortho.core.ortho.pipeline import TrueOrthoConfig

    with pytest.raises(InputError, match="threads"):
        InProcessExecutor(threads=0)
    with pytest.raises(InputError, match="memory"):
        LocalDaskExecutor(1, memory_limit="lots")  # before any cluster starts
    with pytest.raises(InputError, match="workers"):
        TrueOrthoConfig(workers=0).validate()
    with pytest.raises(InputError, match="dask_workers"):
        TrueOrthoConfig(dask_workers=0).validate()
    with pytest.raises(InputError, match="executor"):
        TrueOrthoConfig(executor="gpu").validate()


def test_in_process_threads_keep_task_order_and_stop_on_cancel():
    import threading

    ex = InProcessExecutor(threads=2)
    names = set()

    def slow_square(x):
        names.add(threading.current_thread().name)
        time.sleep(0.02 * (5 - x))  # later tasks finish first
        return x * x

    seen = []
    out = ex.map_tiles(slow_square, [1, 2, 3, 4], CallbackProgress(lambda f, m: seen.append(m)), label="t")
    assert out == [1, 4, 9, 16] and seen[-1] == "t: tile 4/4" and len(names) == 2
    calls = []
    with pytest.raises(CancelledError):
        stop = CallbackProgress(None, lambda: len(calls) >= 1)
        ex.map_tiles(lambda x: calls.append(x), list(range(20)), stop)
    assert 1 <= len(calls) <= 4  # at most 2 x threads tasks were in flight when the cancel came


def test_tile_cache_is_exact_atomic_and_robust(tmp_path):
    c = TileCache(tmp_path / "t")
    k = Digest("a", np.arange(3)).hexdigest()
    z = np.array([[1.5, np.nan]], np.float32)
    assert c.get(k) is None
    c.put(k, (z, z * 2))
    got = c.get(k)
    assert got is not None and np.array_equal(got[0], z, equal_nan=True) and got[0].dtype == np.float32
    assert [p.name for p in (tmp_path / "t").iterdir()] == [f"{k}.npz"]  # no temporary file left
    (tmp_path / "t" / f"{k}.npz").write_bytes(b"truncated")
    assert c.get(k) is None and not (tmp_path / "t" / f"{k}.npz").exists()
    with pytest.raises(ValueError):
        c.get("../evil")
    # keys see values, types, shapes and dtypes
    keys = {
        Digest(np.zeros(2, np.float32)).hexdigest(),
        Digest(np.zeros(2, np.float64)).hexdigest(),
        Digest(np.zeros((1, 2), np.float32)).hexdigest(),
        Digest(1).hexdigest(),
        Digest(1.0).hexdigest(),
        Digest("1").hexdigest(),
        Digest({"p2": 1}).hexdigest(),
    }
    assert len(keys) == 7
    scratch = TileCache(tmp_path / "s", remove_when_done=True)
    scratch.put(k, (z,))
    scratch.finish()
    assert not (tmp_path / "s").exists()


def test_executor_choices_and_scheduler_security(monkeypatch):
    assert isinstance(make_executor(None), InProcessExecutor)
    with pytest.raises(InputError, match="EXECUTOR"):
        make_executor("threads")
    with pytest.raises(InputError, match="EXECUTOR"):
        OsgmConfig(executor="cluster").validate()
    monkeypatch.delenv("TRUORTHO_DASK_SCHEDULER", raising=False)
    with pytest.raises(InputError, match="TRUORTHO_DASK_SCHEDULER"):
        make_executor("scheduler")
    monkeypatch.setenv("TRUORTHO_DASK_SCHEDULER", "tcp://127.0.0.1:8786")
    assert make_executor("scheduler").address == "tcp://127.0.0.1:8786"  # connects only when used
    monkeypatch.delenv("TRUORTHO_DASK_ALLOW_INSECURE", raising=False)
    with pytest.raises(InputError, match="unauthenticated"):
        SchedulerExecutor("tcp://203.0.113.5:8786")
    assert SchedulerExecutor("tls://203.0.113.5:8786").address.startswith("tls://")
    assert SchedulerExecutor("localhost:8786").address == "localhost:8786"
    with pytest.raises(InputError, match="does not exist"):
        SchedulerExecutor("/nowhere/scheduler.json")
    ex = LocalDaskExecutor(n_workers=2, memory_limit="1GiB")
    assert ex.cluster is None  # nothing starts before the first map_tiles
    ex.close()
