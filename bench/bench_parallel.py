"""Benchmark of tile-parallel OSGM and true ortho: in-process, and a local Dask cluster of 1 and 2 workers.

Not a test. Run from the repository root with the project's interpreter::

    source scripts/env.sh
    python -P bench/bench_parallel.py [--scale 2] [--resolution 0.25] [--tile 128] [--skip-inprocess]
                                      [--stage osgm|ortho|all] [--ortho-tile 512]

The scene is the default synthetic scene (``core/synthetic``: 120 x 100 m, 7 buildings and a
tower) with its extent scaled by ``--scale`` in both directions (default 2: 4x the area, 4x the
buildings) at the same flight parameters, so it has about 4x the images (84 of 640 x 480 px). The
DSM cell defaults to twice the GSD (0.25 m, 960 x 800 cells): at the GSD one in-process run alone
takes about 9 minutes here.

Each configuration runs ``run_osgm`` on the same scene and grid (the DSM must be bit-identical in
all of them, which is checked):

* ``inprocess``: this process, numba kernels on all cores (the default executor);
* ``dask-1`` and ``dask-2``: a LocalCluster of 1 and 2 worker processes on 127.0.0.1, one thread
  and ``NUMBA_NUM_THREADS=1`` each, so the speed-up is only the tile parallelism.

Printed: wall time of ``run_osgm`` (cluster start-up excluded, measured separately), peak resident
memory of every worker process (``VmHWM``) and of this process (``ru_maxrss``), the parallel efficiency
``t(1 worker) / (2 t(2 workers))``, and per-tile costs of the finest level from the Dask task
stream of the 1-worker run (seconds per tile and per million cells, all levels included). The
machine is shared (2 cores): wall times are indicative. Results go to ``bench/results/parallel.json``.

``--stage ortho`` (and ``all``) does the same for ``true_ortho`` onto the scene's truth DSM at the GSD
(colour correction on; the mosaic, source index and occlusion mask must be bit-identical in all
runs); its tiles run in waves (``core/ortho/tiles.py``), so the efficiency also shows what the waves
cost. The colour statistics (on a decimated grid) run in the client in every configuration.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def _maxrss_mb() -> float:
    from truortho.core.memory import peak_rss_mb  # the one peak-memory helper (kB/bytes/Windows)

    peak = peak_rss_mb()
    return float("nan") if peak is None else peak


def _peak_rss_mb() -> float:
    """VmHWM of this process: its own peak (ru_maxrss survives exec, so a spawned worker would
    report its parent's peak)."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def _run(scene, folder, out, res, tile, executor):
    from truortho.core.osgm import OsgmConfig, OsgmOutputs, run_osgm

    t = time.perf_counter()
    r = run_osgm(
        scene.orientation,
        OsgmConfig(resolution=res, tile_size=tile),
        scene.extent_world(),
        OsgmOutputs(dsm=out),
        folder,
        executor=executor,
    )
    return time.perf_counter() - t, r


def _ortho(scene, folder, out, tile, executor):
    from truortho.core.ortho.pipeline import TrueOrthoConfig, true_ortho

    t = time.perf_counter()
    r = true_ortho(
        folder / "orientation.json", folder / "dsm.tif", out, str(out)[:-4] + "_idx.tif",
        str(out)[:-4] + "_occ.tif", TrueOrthoConfig(tile_size=tile, extent=scene.extent_world()),
        executor=executor,
    )  # fmt: skip
    return time.perf_counter() - t, r


def _bench_ortho(scene, folder, tmp, tile, skip_inprocess) -> dict:
    """In-process, 1 and 2 Dask workers for the true orthophoto (module docstring)."""
    from truortho.core.parallel import LocalDaskExecutor
    from truortho.core.rasterio_io import read_raster

    def products(p):
        return [read_raster(x, band=None)[0] for x in (p, str(p)[:-4] + "_idx.tif", str(p)[:-4] + "_occ.tif")]

    res: dict = {"tile": tile, "runs": {}}
    prods = {}
    if not skip_inprocess:
        wall, r = _ortho(scene, folder, tmp / "o_inprocess.tif", tile, None)
        prods["inprocess"] = products(tmp / "o_inprocess.tif")
        st = r.stats
        res["grid"] = [st["cols"], st["rows"], st["tiles"]]
        res["task_memory_mb"] = st["task_memory_mb"]
        res["runs"]["inprocess"] = {"wall": wall, "seconds_color": st["seconds_color"]}
        print(f"true ortho inprocess: {wall:.1f} s, {st['cols']} x {st['rows']} cells, {st['tiles']} tiles; "
              f"colour statistics {st['seconds_color']:.1f} s; estimated memory per task "
              f"{st['task_memory_mb']:.0f} MB")  # fmt: skip
    for n in (1, 2):
        ex = LocalDaskExecutor(n_workers=n, memory_limit="4GiB", numba_threads=1)
        t = time.perf_counter()
        client = ex._client()
        client.run(lambda: __import__("truortho.core.ortho.tiles"))
        start = time.perf_counter() - t
        from distributed import get_task_stream

        with get_task_stream(client) as stream:
            wall, r = _ortho(scene, folder, tmp / f"o_dask{n}.tif", tile, ex)
        secs = np.array([
            sum(x["stop"] - x["start"] for x in d["startstops"] if x["action"] == "compute")
            for d in stream.data if str(d["key"]).startswith("truortho-tile-")
        ])  # fmt: skip
        peaks = sorted(client.run(_peak_rss_mb).values())
        ex.close()
        prods[f"dask-{n}"] = products(tmp / f"o_dask{n}.tif")
        res["runs"][f"dask-{n}"] = {"wall": wall, "startup": start, "peak_mb_per_worker": peaks,
                                    "task_compute_s": float(secs.sum()), "tiles": len(secs),
                                    "seconds_color": r.stats["seconds_color"]}  # fmt: skip
        print(f"true ortho dask-{n}: {wall:.1f} s (+ {start:.1f} s cluster start), peak RSS per worker "
              + ", ".join(f"{p:.0f} MB" for p in peaks)
              + f"; tile compute summed {secs.sum():.1f} s over {len(secs)} tiles (mean {secs.mean():.2f} s, "
              f"max {secs.max():.2f} s)")  # fmt: skip
        if n == 1:
            cells = r.stats["rows"] * r.stats["cols"]
            res["s_per_mcell"] = float(secs.sum() / cells * 1e6)
            res["serial_s"] = wall - float(secs.sum())
            print(f"  {secs.sum() / cells * 1e6:.2f} s of one core per million ortho cells (tiles only); "
                  f"client time outside the tiles {wall - secs.sum():.1f} s "
                  f"({(wall - secs.sum()) / cells * 1e6:.2f} s per million cells: colour statistics, "
                  f"writing, seamlines)")  # fmt: skip
    ref = next(iter(prods.values()))
    same = all(all(np.array_equal(a, b) for a, b in zip(ref, p, strict=True)) for p in prods.values())
    t1, t2 = res["runs"]["dask-1"]["wall"], res["runs"]["dask-2"]["wall"]
    res["efficiency_2"] = t1 / (2 * t2)
    res["identical"] = same
    print(f"true ortho parallel efficiency with 2 workers: t1 / (2 t2) = {t1:.1f} / (2 x {t2:.1f}) = "
          f"{t1 / (2 * t2):.2f}; mosaic, index and occlusion bit-identical: {same}")  # fmt: skip
    return res


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scale", type=float, default=2.0, help="extent factor per axis (2 = 4x the area)")
    ap.add_argument("--resolution", type=float, default=None, help="DSM cell (default twice the GSD)")
    ap.add_argument("--tile", type=int, default=128)
    ap.add_argument("--skip-inprocess", action="store_true")
    ap.add_argument("--stage", choices=("osgm", "ortho", "all"), default="all")
    ap.add_argument("--ortho-tile", type=int, default=512)
    ap.add_argument("--keep", action="store_true", help="keep the temporary scene and products")
    args = ap.parse_args(argv)

    from truortho.core.parallel import LocalDaskExecutor
    from truortho.core.rasterio_io import read_raster
    from truortho.core.synthetic import SceneConfig, make_scene

    base = SceneConfig()
    x0, y0, x1, y1 = base.extent
    s = args.scale
    cfg = SceneConfig(
        extent=(x0 * s, y0 * s, x1 * s, y1 * s), n_buildings=int(round(base.n_buildings * s * s))
    )
    t = time.perf_counter()
    scene = make_scene(cfg)
    tmp = Path(tempfile.mkdtemp(prefix="bench_parallel_"))
    if not args.keep:  # the scene and products (~100 MB) go when the run ends
        import atexit
        import shutil

        atexit.register(shutil.rmtree, tmp, True)
    folder = tmp / "scene"
    folder.mkdir()
    scene.write(folder)
    res = args.resolution or 2 * cfg.gsd
    n_img = len(scene.orientation.images)
    w, h = cfg.image_size
    print(
        f"scene: {(x1 - x0) * s:.0f} x {(y1 - y0) * s:.0f} m ({s * s:.1f}x the default area), "
        f"{cfg.n_buildings} buildings, {n_img} images of {w} x {h} px, GSD {cfg.gsd:.3f} m; "
        f"made in {time.perf_counter() - t:.1f} s"
    )
    results: dict = {"scene": {"scale": s, "images": n_img, "image_size": [w, h], "gsd": cfg.gsd},
                     "resolution": res, "tile": args.tile, "runs": {}}  # fmt: skip
    ok = True
    if args.stage in ("ortho", "all"):
        results["ortho"] = _bench_ortho(scene, folder, tmp, args.ortho_tile, args.skip_inprocess)
        ok = ok and results["ortho"]["identical"]
    if args.stage == "ortho":
        _save(results)
        return 0 if ok else 1
    products = {}
    if not args.skip_inprocess:
        wall, r = _run(scene, folder, tmp / "inprocess.tif", res, args.tile, None)
        products["inprocess"] = read_raster(tmp / "inprocess.tif")[0]
        results["runs"]["inprocess"] = {"wall": wall, "peak_mb_this_process": _maxrss_mb()}
        st = r.stats
        print(f"inprocess: {wall:.1f} s, {st['cols']} x {st['rows']} cells, {st['tiles']} tiles, "
              f"{st['levels']} levels; peak RSS of this process {_maxrss_mb():.0f} MB")  # fmt: skip
        results["grid"] = [r.stats["cols"], r.stats["rows"], r.stats["tiles"], r.stats["levels"]]
        results["task_volume_bytes"] = r.stats["task_volume_bytes"]
    for n in (1, 2):
        ex = LocalDaskExecutor(n_workers=n, memory_limit="4GiB", numba_threads=1)
        t = time.perf_counter()
        client = ex._client()
        client.run(lambda: __import__("truortho.core.osgm.tiles"))  # imports (numba cache) before timing
        start = time.perf_counter() - t
        from distributed import get_task_stream

        with get_task_stream(client) as stream:
            wall, r = _run(scene, folder, tmp / f"dask{n}.tif", res, args.tile, ex)
        tasks = [
            (d["key"], sum(x["stop"] - x["start"] for x in d["startstops"] if x["action"] == "compute"))
            for d in stream.data
            if str(d["key"]).startswith("truortho-tile-")
        ]
        peaks = sorted(client.run(_peak_rss_mb).values())
        ex.close()
        products[f"dask-{n}"] = read_raster(tmp / f"dask{n}.tif")[0]
        results["runs"][f"dask-{n}"] = {"wall": wall, "startup": start, "peak_mb_per_worker": peaks}
        compute = sum(c for _k, c in tasks)
        results["runs"][f"dask-{n}"]["task_compute_s"] = compute
        print(f"dask-{n}: {wall:.1f} s (+ {start:.1f} s cluster start), peak RSS per worker "
              + ", ".join(f"{p:.0f} MB" for p in peaks)
              + f"; tile compute time summed over the workers {compute:.1f} s")  # fmt: skip
        if n == 1:
            secs = np.array([c for _k, c in tasks])
            cells = r.stats["rows"] * r.stats["cols"]
            results["tasks"] = {
                "n": len(secs), "compute_s": float(secs.sum()), "mean_s": float(secs.mean()),
                "max_s": float(secs.max()), "s_per_mcell": float(secs.sum() / cells * 1e6), "cells": cells,
            }  # fmt: skip
            # what the client does between and around the tasks: level set-up, assembling, colours, writing
            serial = wall - float(secs.sum())
            print(f"  client-side time outside the tiles: {serial:.1f} s")
            results["serial_s"] = serial
            print(f"  tiles (all levels): {len(secs)}, compute {secs.sum():.1f} s, mean {secs.mean():.2f} s, "
                  f"max {secs.max():.2f} s; {secs.sum() / cells * 1e6:.1f} s per million DSM cells "
                  f"(one core, all levels)")  # fmt: skip
    ref = next(iter(products.values()))
    same = all(np.array_equal(ref, p, equal_nan=True) for p in products.values())
    t1, t2 = results["runs"]["dask-1"]["wall"], results["runs"]["dask-2"]["wall"]
    eff = t1 / (2 * t2)
    results["efficiency_2"] = eff
    results["identical"] = same
    c1, c2 = results["runs"]["dask-1"]["task_compute_s"], results["runs"]["dask-2"]["task_compute_s"]
    # the same tiles take longer when the cores are shared (other processes, the client): c2 / c1 > 1
    results["compute_inflation_2"] = c2 / c1
    print(f"the same tiles took {c2 / c1:.2f}x the compute time with 2 workers (core contention)")
    print(f"parallel efficiency with 2 workers: t1 / (2 t2) = {t1:.1f} / (2 x {t2:.1f}) = {eff:.2f}; "
          f"DSMs bit-identical: {same}")  # fmt: skip
    _save(results)
    return 0 if (same and ok) else 1


def _save(results: dict) -> None:
    out = Path(__file__).resolve().parent / "results"
    out.mkdir(exist_ok=True)
    (out / "parallel.json").write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from _docs import run_main

    TITLE = "Scale-out: in-process against a local Dask cluster"
    sys.exit(run_main(main, "parallel", TITLE, peers=("dask", "distributed")))
