"""Benchmark of the true orthophoto against Orthority's conventional orthorectification.

Not a test. Run from the repository root with the project's interpreter::

    source scripts/env.sh
    python -P bench/bench_trueortho.py [--size 640x480] [--focal 800] [--seed 3] [--tile 512]
        [--compress deflate|zstd|lzw|jpeg]

What is measured, in one run on the same synthetic scene (``core/synthetic``: buildings, a tower,
nadir block + 4 obliques, per-image exposure differences):

* **ours**: ``true_ortho`` with its defaults (depth-buffer visibility in every image, selection,
  seams, feathering, colour correction), output at the nominal GSD onto the truth DSM
  (``dsm.tif``), in its own subprocess; the same call in *conventional* mode
  (``visibility=False``) for the quality comparison;
* ``--surface PATH``: another DSM of the same scene (e.g. from ``truortho:osgm``) instead of the
  truth DSM, for ours and Orthority alike; the quality is still measured against the truth;
* **Orthority + GDAL mosaic**: Orthority's per-image orthos are not a mosaic; a finished conventional
  block ortho also needs them mosaicked: ``gdal.BuildVRT`` over them on our grid (last image on
  top) + ``gdal.Translate`` to a COG with overviews like ours, timed in its own subprocess. The
  ratio of mosaic output rates compares like with like: the same cells and bands written;
* **I/O floor**: only decoding the images (``ImageStore``, two threads) and writing ours' three
  finished products again with the pipeline's writers (``open_products``: COG, overviews,
  DEFLATE), best of three, nothing computed: the output rate no implementation writing these
  products could beat on this machine;
* **Orthority** (pip ``orthority``, installed into a throw-away virtual environment under
  ``$TMPDIR`` on first use, never into .venv): ``oty.Ortho.process`` of every image onto the same
  DSM at the same resolution, bilinear image and DEM interpolation, one ortho per image (what a
  conventional orthorectification produces; Orthority does not mosaic), in its own subprocess.
  The cameras are exported with TruOrtho's Orthority exporter (``exterior.csv`` + ``interior.yaml``).

Output rate = output megapixels (all bands, alpha/mask excluded) per second of the processing call
(imports and interpreter start excluded; numba code is loaded from its cache as for users, and the
first call of ours is a warm-up). For Orthority every pixel of every per-image ortho counts, also
its nodata border; the number of *valid* pixels is printed too. Peak resident memory per
subprocess (``ru_maxrss``). Quality against the scene truth for ours, ours-conventional and
Orthority's nearest-nadir choice (each cell from the image whose centre is nearest in plan,
among the orthos that have data there): ghosting, median shift, coverage, mean dE (see
``core/ortho/evaluate.py``).

The machine is shared: wall times are indicative; ratios from one run are comparable.
Results go to ``bench/results/trueortho.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import textwrap
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
VENV = os.path.join(tempfile.gettempdir(), "truortho-bench-orthority-venv")

OURS = textwrap.dedent(
    """
    import json, resource, sys, time
    from truortho.core.ortho.pipeline import TrueOrthoConfig, true_ortho
    folder, out, res, tile, vis, warm = sys.argv[1], sys.argv[2], float(sys.argv[3]), int(sys.argv[4]), \\
        sys.argv[5] == "1", sys.argv[6] == "1"
    dsm, extent = sys.argv[7], tuple(float(v) for v in sys.argv[8].split(","))
    cfg = TrueOrthoConfig(resolution=res, tile_size=tile, visibility=vis, extent=extent,
                          compression=sys.argv[9])
    if warm:
        true_ortho(folder + "/orientation.json", dsm, out, config=cfg)
    t = time.perf_counter()
    r = true_ortho(folder + "/orientation.json", dsm, out, out[:-4] + "_idx.tif",
                   out[:-4] + "_occ.tif", config=cfg)
    dt = time.perf_counter() - t
    keys = ("tiles", "images_used", "seconds_color", "seconds_mosaic", "max_triangles_per_tile",
            "margin_cells", "cell_image_samples")
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(json.dumps({"seconds": dt, "cells": r.grid.rows * r.grid.cols,
                      "textured": r.stats["cells_textured"], "bands": r.stats["bands"], "maxrss_mb": rss,
                      "stats": {k: r.stats[k] for k in keys}}))
    """
)

ORTHORITY = textwrap.dedent(
    """
    import glob, json, os, resource, sys, time
    import numpy as np
    import orthority as oty
    import rasterio
    folder, out, res, dsm = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4]
    cams = oty.FrameCameras(folder + "/opk/interior.yaml", folder + "/opk/exterior.csv")
    files = sorted(glob.glob(folder + "/img_*.png"))
    os.makedirs(out, exist_ok=True)
    t = time.perf_counter()
    for f in files:
        cam = cams.get(f)
        o = oty.Ortho(f, dsm, cam, crs=cams.crs)
        o.process(os.path.join(out, os.path.basename(f)[:-4] + ".tif"), resolution=(res, res),
                  interp="bilinear", dem_interp="bilinear", overwrite=True)
    dt = time.perf_counter() - t
    px = valid = 0
    for p in sorted(glob.glob(out + "/*.tif")):
        with rasterio.open(p) as ds:
            m = ds.dataset_mask()
            px += ds.width * ds.height * ds.count
            valid += int((m > 0).sum()) * ds.count
    print(json.dumps({"seconds": dt, "pixels": px, "valid_pixels": valid, "images": len(files),
                      "version": oty.__version__ if hasattr(oty, "__version__") else "?",
                      "maxrss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
    """
)


MOSAIC = textwrap.dedent(
    """
    import glob, json, resource, sys, time
    from osgeo import gdal
    gdal.UseExceptions()
    folder, out, extent, res = sys.argv[1], sys.argv[2], [float(v) for v in sys.argv[3].split(",")], \\
        float(sys.argv[4])
    files = sorted(glob.glob(folder + "/*.tif"))
    t = time.perf_counter()
    vrt = gdal.BuildVRT(out + ".vrt", files, outputBounds=extent, xRes=res, yRes=res, srcNodata=None,
                        resampleAlg="nearest")
    vrt = None
    gdal.Translate(out, out + ".vrt", format="COG", creationOptions=["COMPRESS=DEFLATE", "PREDICTOR=YES",
                   "NUM_THREADS=ALL_CPUS", "BLOCKSIZE=256", "OVERVIEW_RESAMPLING=AVERAGE"])
    dt = time.perf_counter() - t
    ds = gdal.Open(out)
    print(json.dumps({"seconds": dt, "pixels": ds.RasterXSize * ds.RasterYSize * 3,
                      "maxrss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
    """
)


def ensure_orthority() -> str:
    py = os.path.join(VENV, "bin", "python")
    if not os.path.exists(py):
        print(f"installing orthority into {VENV} (throw-away venv) ...", flush=True)
        subprocess.run(["python3", "-m", "venv", VENV], check=True)
        subprocess.run([py, "-m", "pip", "install", "-q", "orthority"], check=True)
    return py


def run_json(cmd: list[str], env=None) -> dict:
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        raise RuntimeError(f"{cmd[:3]} failed:\n{p.stderr[-3000:]}")
    return json.loads(p.stdout.strip().splitlines()[-1])


def quality(scene, path, grid, truth, buildings, seen) -> dict:
    import rasterio

    from truortho.core.rasterio_io import read_raster

    a, _, _ = read_raster(path, band=None)
    rgb = np.moveaxis(a[:3], 0, -1)
    with rasterio.open(path) as ds:
        valid = ds.dataset_mask() > 0  # the alpha band, or the mask of a JPEG output
    return _quality(rgb, valid, truth, buildings, seen)


def _quality(rgb, valid, truth, buildings, seen) -> dict:
    from truortho.core.ortho import evaluate as ev

    gh = ev.ghosting(rgb, truth, valid, buildings, 2.0)
    sh = ev.phase_shift(rgb.astype(float).mean(-1) / 255, truth.astype(float).mean(-1) / 255, valid)
    return {
        "ghosting": round(gh["share"], 5),
        "shift_gsd": round(sh["median"], 3),
        "coverage": round(ev.coverage(valid, seen), 5),
        "mean_dE": round(ev.mean_delta_e(rgb, truth, valid), 2),
    }


def orthority_nearest_nadir(scene, out_dir, grid):
    """Mosaic of Orthority's per-image orthos: each cell from the nearest projection centre with data."""
    import rasterio
    from rasterio.warp import Resampling, reproject

    rgb = np.zeros(grid.shape + (3,), np.uint8)
    best = np.full(grid.shape, np.inf)
    X, Y = grid.centres()
    for im in scene.orientation.images[: scene.n_nadir]:
        p = os.path.join(out_dir, im.name[:-4] + ".tif")
        with rasterio.open(p) as ds:
            dst = np.zeros((3,) + grid.shape, np.uint8)
            reproject(
                ds.read([1, 2, 3]),
                dst,
                src_transform=ds.transform,
                src_crs=ds.crs,
                dst_transform=grid.transform,
                dst_crs=ds.crs,
                resampling=Resampling.nearest,
            )
            m = np.zeros(grid.shape, np.uint8)
            reproject(
                ds.dataset_mask(),
                m,
                src_transform=ds.transform,
                src_crs=ds.crs,
                dst_transform=grid.transform,
                dst_crs=ds.crs,
                resampling=Resampling.nearest,
            )
        c = im.C + scene.offset
        d = np.hypot(X - c[0], Y - c[1])
        take = (m > 0) & (d < best)
        best[take] = d[take]
        rgb[take] = np.moveaxis(dst, 0, -1)[take]
    return rgb, np.isfinite(best)


FLOOR = textwrap.dedent(
    """
    import contextlib, glob, json, resource, sys, time
    from concurrent.futures import ThreadPoolExecutor
    import numpy as np
    from truortho.core.imagery import image_info
    from truortho.core.ortho.mosaic import ImageStore
    from truortho.core.ortho.pipeline import open_products
    from truortho.core.rasterio_io import read_raster
    folder, ours, workers, compression = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
    # the finished products of ours, read back (not timed)
    a, grid, _ = read_raster(ours, band=None)
    if compression == "jpeg":  # 3 bands and a mask: the alpha band back from the mask
        import rasterio
        with rasterio.open(ours) as ds:
            a = np.concatenate([a, ds.dataset_mask()[None]])
    idx = read_raster(ours[:-4] + "_idx.tif")[0]
    occ = read_raster(ours[:-4] + "_occ.tif")[0]
    files = sorted(glob.glob(folder + "/img_*.png"))
    infos = [image_info(f) for f in files]
    best = None
    for rep in range(3):
        store = ImageStore(files, [(i.width, i.height) for i in infos], infos[0].bands, infos[0].dtype)
        t = time.perf_counter()
        with ThreadPoolExecutor(workers) as ex:  # decoding every image, in parallel as ours does
            list(ex.map(store.get, range(len(files))))
        t1 = time.perf_counter()
        with contextlib.ExitStack() as stack:  # writing the three products as ours writes them
            base = ours[:-4] + "_floor"
            w_out, w_idx, w_occ = open_products(stack, grid, base + ".tif", base + "_idx.tif",
                                                base + "_occ.tif", a.shape[0] - 1, a.dtype, True,
                                                compression)
            w_out.write(a)
            w_idx.write(idx)
            w_occ.write(occ)
        t2 = time.perf_counter()
        if best is None or t2 - t < best[0]:
            best = (t2 - t, t1 - t, t2 - t1)
    print(json.dumps({"seconds": best[0], "seconds_decode": best[1], "seconds_write": best[2],
                      "cells": grid.rows * grid.cols, "bands": int(a.shape[0] - 1), "images": len(files),
                      "maxrss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
    """
)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", default="640x480")
    ap.add_argument("--focal", type=float, default=800.0)
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--tile", type=int, default=512)
    ap.add_argument("--compress", default="deflate", choices=("deflate", "zstd", "lzw", "jpeg"),
                    help="compression of ours' orthophoto (Orthority writes JPEG by default)")
    ap.add_argument("--no-orthority", action="store_true")
    ap.add_argument("--surface", help="another DSM of the same scene (e.g. OSGM's) instead of the truth DSM")
    ap.add_argument("--keep", action="store_true", help="keep the temporary scene and products")
    args = ap.parse_args()
    w, h = (int(v) for v in args.size.split("x"))

    from truortho.core.exchange import write_orientation
    from truortho.core.grid import RasterGrid
    from truortho.core.orientation import Orientation
    from truortho.core.ortho import evaluate as ev
    from truortho.core.synthetic import SceneConfig, make_scene

    cfg = SceneConfig(image_size=(w, h), focal_px=args.focal, seed=args.seed)
    work = tempfile.mkdtemp(prefix="bench-trueortho-")
    if not args.keep:  # the scene and products (~100 MB) go when the run ends
        import atexit
        import shutil

        atexit.register(shutil.rmtree, work, True)
    t = time.perf_counter()
    scene = make_scene(cfg)
    scene.write(work)
    write_orientation(
        Orientation.load(os.path.join(work, "orientation.json")), "opk", os.path.join(work, "opk")
    )
    res = cfg.gsd
    dsm, gt = scene.dsm(res)
    grid = RasterGrid.from_geotransform(gt, dsm.shape[0], dsm.shape[1], cfg.crs)
    truth, _ = scene.orthophoto(res)
    buildings = ev.building_mask(scene, grid)
    seen = ev.truth_seen(scene, grid, 45.0)
    print(
        f"scene: {len(scene.images)} images {w}x{h}, GSD {res} m, ortho {grid.cols}x{grid.rows} cells "
        f"({time.perf_counter() - t:.0f} s to build)",
        flush=True,
    )

    env = dict(os.environ)
    results: dict = {
        "scene": {
            "images": len(scene.images),
            "image_size": [w, h],
            "gsd": res,
            "cells": grid.rows * grid.cols,
            "seed": args.seed,
        },
        "compression": args.compress,
    }
    py = sys.executable
    dsm_path = os.path.abspath(args.surface) if args.surface else os.path.join(work, "dsm.tif")
    results["surface"] = args.surface or "truth DSM"
    ext = ",".join(str(v) for v in grid.extent)
    tile = str(args.tile)
    ours = run_json([py, "-P", "-c", OURS, work, os.path.join(work, "ours.tif"), str(res), tile, "1", "1",
                     dsm_path, ext, args.compress], env)
    conv = run_json([py, "-P", "-c", OURS, work, os.path.join(work, "conv.tif"), str(res), tile, "0", "0",
                     dsm_path, ext, args.compress], env)
    ours_mpx = ours["cells"] * ours["bands"] / ours["seconds"] / 1e6
    results["ours"] = {
        **ours,
        "mpix_per_s": round(ours_mpx, 3),
        "quality": quality(scene, os.path.join(work, "ours.tif"), grid, truth, buildings, seen),
    }
    results["ours_conventional"] = {
        **conv,
        "mpix_per_s": round(conv["cells"] * conv["bands"] / conv["seconds"] / 1e6, 3),
        "quality": quality(scene, os.path.join(work, "conv.tif"), grid, truth, buildings, seen),
    }
    if not args.no_orthority:
        opy = ensure_orthority()
        oo = run_json([opy, "-c", ORTHORITY, work, os.path.join(work, "orthority"), str(res), dsm_path])
        rgb, valid = orthority_nearest_nadir(scene, os.path.join(work, "orthority"), grid)
        results["orthority"] = {
            **oo,
            "mpix_per_s": round(oo["pixels"] / oo["seconds"] / 1e6, 3),
            "valid_mpix_per_s": round(oo["valid_pixels"] / oo["seconds"] / 1e6, 3),
            "quality_nearest_nadir_mosaic": _quality(rgb, valid, truth, buildings, seen),
        }
        results["ratio_output_rate"] = round(ours_mpx / results["orthority"]["mpix_per_s"], 3)
        results["ratio_output_rate_valid"] = round(ours_mpx / results["orthority"]["valid_mpix_per_s"], 3)
        results["ratio_time_for_the_block"] = round(oo["seconds"] / ours["seconds"], 3)
        # a finished conventional mosaic: Orthority's orthos mosaicked by GDAL (VRT, last image on top,
        # + COG with overviews like ours), the same grid and pixels as ours
        mo = run_json([py, "-P", "-c", MOSAIC, os.path.join(work, "orthority"),
                       os.path.join(work, "orthority_mosaic.tif"), ext, str(res)], env)  # fmt: skip
        results["orthority_mosaic"] = mo
        block = oo["seconds"] + mo["seconds"]
        results["ratio_mosaic_rate"] = round(block / ours["seconds"], 3)
        # like with like: one Orthority ortho pixel with data = one (cell, image) sample of ours
        ours_sps = ours["stats"]["cell_image_samples"] * ours["bands"] / ours["seconds"] / 1e6
        results["ours"]["sample_mpix_per_s"] = round(ours_sps, 3)
        results["ratio_sample_rate"] = round(ours_sps / results["orthority"]["valid_mpix_per_s"], 3)
        # the floor: only decoding the images and writing the three products (best of three)
        fl = run_json([py, "-P", "-c", FLOOR, work, os.path.join(work, "ours.tif"), "2", args.compress], env)
        fl["mpix_per_s"] = round(fl["cells"] * fl["bands"] / fl["seconds"] / 1e6, 3)
        results["io_floor"] = fl
        o_rate = results["orthority"]["mpix_per_s"]
        results["ratio_output_rate_io_floor"] = round(fl["mpix_per_s"] / o_rate, 3)

    print("\n| run | s | Mpx/s | peak MB | ghosting | shift (GSD) | coverage | mean dE |")
    print("|---|---|---|---|---|---|---|---|")
    for key in ("ours", "ours_conventional", "orthority"):
        if key not in results:
            continue
        r = results[key]
        q = r.get("quality") or r.get("quality_nearest_nadir_mosaic")
        print(
            f"| {key} | {r['seconds']:.2f} | {r['mpix_per_s']:.2f} | {r['maxrss_mb']:.0f} | "
            f"{q['ghosting']:.4f} | {q['shift_gsd']:.3f} | {q['coverage']:.4f} | {q['mean_dE']:.2f} |"
        )
    if "orthority" in results:
        print(
            f"\nratio output rate ours / Orthority: {results['ratio_output_rate']} (all written pixels), "
            f"{results['ratio_output_rate_valid']} (valid pixels only); Orthority time / ours for the whole "
            f"block: {results['ratio_time_for_the_block']}; (cell, image) samples per second of ours / "
            f"Orthority's valid pixels per second: {results['ratio_sample_rate']}"
        )
        mo = results["orthority_mosaic"]
        print(
            f"finished mosaic of the block (same {ours['cells']} cells x {ours['bands']} bands): Orthority "
            f"{results['orthority']['seconds']:.2f} s + GDAL VRT/COG mosaic {mo['seconds']:.2f} s; "
            f"ratio of mosaic output rates ours / (Orthority + GDAL): {results['ratio_mosaic_rate']}"
        )
        fl = results["io_floor"]
        print(
            f"I/O floor (decoding the {fl['images']} images + writing the three products as ours does, "
            f"nothing computed): {fl['seconds']:.3f} s ({fl['seconds_decode']:.3f} decode + "
            f"{fl['seconds_write']:.3f} write); its output rate / Orthority's, all written pixels: "
            f"{results['ratio_output_rate_io_floor']}"
        )
    os.makedirs(os.path.join(HERE, "results"), exist_ok=True)
    name = "trueortho.json" if not args.surface else "trueortho_surface.json"
    with open(os.path.join(HERE, "results", name), "w") as fh:
        json.dump(results, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from _docs import run_main

    TITLE = "True orthophoto against Orthority"
    sys.exit(run_main(main, "trueortho", TITLE, peers=("orthority",)))
