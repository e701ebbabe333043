"""Real photo blocks through the whole pipeline, measured without a truth DSM (issue 17, part 4).

Not a test. Run from the repository root::

    make acceptance-real                      # the bundled sample (make demo's block)
    source scripts/env.sh && python -P bench/real_blocks.py --blocks sample,brighton,boruszyn,copr \
        [--resolution 0 | --resolution sample=0.25,copr=0.05] [--keep DIR] [--write-docs]

Each block runs as a user would run it: ``truortho:importgcps`` (where the block has an ODM
``gcp_list.txt``), then ``truortho:pipeline`` through ``qgis_process`` with its defaults (the
check points named below stay out of the adjustment). On the products (:func:`measures`):

* **completeness**: the share of valid cells of the filtered DSM among the cells that at least two
  near-nadir photos see (footprints on the median ground height, within 45 degrees off nadir);
* **holes**: the share of those cells without a height in the raw OSGM DSM, and the holes of at
  least 1 m^2 counted;
* **roughness**: the median RMS residual of a plane fitted to 2 m x 2 m windows of the filtered DSM
  whose slope is under 10 degrees (flat ground: noise, streaks and pits raise it);
* **streak index** of the filtered DSM (:func:`truortho.core.surface.quality.streak_index`): near 1
  on isotropic terrain, but also high on terrain that is anisotropic in its own right (dune ripples);
* **interior streak index**: the streak index of the filtered DSM without its outermost
  :data:`RIM_CELLS` cells. The rim, seen by two photos at the edge of their frames, carries bands
  of noise across it, and on a small block whose valid area is a long strip they set the index of
  the whole DSM (the sample: 18.5, and 1.55 with 8 cells of rim left out; ``bench/rim_streak.py``);
* **grid streak index** (:func:`truortho.core.surface.quality.grid_streak_index`): the same power
  along the processing grid's axes and diagonals against the other directions, near 1 unless the
  processing (SGM paths, tiles, height steps) left artefacts on its own axes;
* **empty share** of the true ortho's frame (the cells with no colour) and its isolated empty
  cells (no colour, all 8 neighbours coloured: speckle), and the cells flagged in OCCLUSION;
* the wall time and the peak resident memory of the pipeline's process, after a warm-up
  (``acceptance.warm_up``: OSGM and a true ortho on a tiny synthetic scene) so that the first
  block's time does not include numba's compilation of kernels whose cache is stale, and a
  picture per block (hillshade beside the ortho) in ``bench/results/real/``.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DATA = os.path.join(os.path.dirname(ROOT), "shared", "data")
DOCS = os.path.join(ROOT, "docs", "acceptance.md")
QP = os.path.join(ROOT, "scripts", "qgis_process")

#: name: (image folder, gcp_list.txt or None, check points)
SAMPLE = os.path.join(ROOT, "sample", "copr")
BLOCKS = {
    "sample": (os.path.join(SAMPLE, "images"), os.path.join(SAMPLE, "gcp_list.txt"), "gcp06,gcp08"),
    "copr": (os.path.join(DATA, "copr", "images"), os.path.join(DATA, "copr", "gcp_list.txt"), "gcp06,gcp08"),
    "boruszyn": (
        os.path.join(DATA, "boruszyn", "images"),
        os.path.join(DATA, "boruszyn", "gcp_list.txt"),
        "",
    ),
    "brighton": (os.path.join(DATA, "brighton", "images"), None, ""),
}


def qgis_run(algorithm: str, args: list[str], log: str, label: str) -> tuple[float, float]:
    """``algorithm`` through ``qgis_process`` with ``args``; its output goes to the file ``log``.
    Returns the wall time (s) and the peak resident memory of the process tree (MB; NaN where
    ``os.wait4`` is missing); a failure ends the bench."""
    t = time.perf_counter()
    with open(log, "w") as fh:
        cmd = [QP, "run", algorithm, "--", *args]
        p = subprocess.Popen(cmd, stdout=fh, stderr=subprocess.STDOUT)
        if hasattr(os, "wait4"):
            _, status, usage = os.wait4(p.pid, 0)
            p.returncode = os.waitstatus_to_exitcode(status)
            peak = usage.ru_maxrss / 1024.0  # Linux: kB
        else:  # pragma: no cover - Windows
            p.wait()
            peak = math.nan
    seconds = time.perf_counter() - t
    if p.returncode:
        with open(log) as fh:
            tail = fh.read()[-2000:]
        raise SystemExit(f"{label}: {algorithm} failed (see {log}):\n{tail}")
    return seconds, peak


def qgis_pipeline(args: list[str], folder: str, label: str) -> tuple[float, float]:
    """``truortho:pipeline`` through :func:`qgis_run`, its output in ``folder/pipeline.log``."""
    return qgis_run("truortho:pipeline", args, os.path.join(folder, "pipeline.log"), label)


def resolution_of(spec: str, block: str) -> float:
    """The RESOLUTION of ``block`` from ``--resolution`` (a number, or ``name=value,...``)."""
    if "=" not in spec:
        return float(spec)
    for part in spec.split(","):
        name, _, value = part.partition("=")
        if name.strip() == block:
            return float(value)
    return 0.0


def run_block(name: str, out: str, resolution: float, log) -> dict:
    images, gcps, checks = BLOCKS[name]
    if not os.path.isdir(images):
        raise SystemExit(f"{name}: image folder {images} not found")
    os.makedirs(out, exist_ok=True)
    args = [f"IMAGES={images}", f"RESOLUTION={resolution}", f"OUTPUT_FOLDER={os.path.join(out, 'products')}"]
    if gcps:
        imp = [QP, "run", "truortho:importgcps", "--", f"INPUT={gcps}", f"GCPS={out}/gcps.gpkg",
               f"OBSERVATIONS={out}/obs.gpkg"] + ([f"CHECK_POINTS={checks}"] if checks else [])  # fmt: skip
        subprocess.run(imp, check=True, capture_output=True)
        args += [f"GCPS={out}/gcps.gpkg", f"OBSERVATIONS={out}/obs.gpkg"]
    log(f"{name}: truortho:pipeline on {len(os.listdir(images))} photos")
    seconds, peak = qgis_pipeline(args, out, name)
    m = measures(os.path.join(out, "products"))
    m.update(block=name, seconds=seconds, peak_mb=peak)
    picture(os.path.join(out, "products"), os.path.join(HERE, "results", "real", f"{name}.jpg"))
    log(f"  {json.dumps(m)}")
    return m


def footprint_count(orientation, grid, z_world: float, max_view_angle: float = 45.0) -> np.ndarray:
    """Near-nadir photos whose frame holds each cell centre at height ``z_world``."""
    from truortho.core.geometry import project_points

    X, Y = grid.centres()
    off = orientation.offset
    P = np.column_stack([X.ravel() - off[0], Y.ravel() - off[1], np.full(X.size, z_world - off[2])])
    count = np.zeros(X.size, np.int32)
    tan_max = math.tan(math.radians(max_view_angle))
    for im in orientation.images:
        if im.R[2, 2] > -math.cos(math.radians(30.0)):  # not near nadir
            continue
        cam = orientation.camera_of(im)
        near = np.hypot(P[:, 0] - im.C[0], P[:, 1] - im.C[1]) <= tan_max * max(im.C[2] - P[0, 2], 0.0)
        uv = project_points(P[near], im.R, im.C, cam)
        inside = (
            (uv[:, 0] >= -0.5)
            & (uv[:, 0] <= cam.width - 0.5)
            & (uv[:, 1] >= -0.5)
            & (uv[:, 1] <= cam.height - 0.5)
        )
        idx = np.flatnonzero(near)[inside]
        count[idx] += 1
    return count.reshape(grid.shape)


def roughness(z: np.ndarray, res: float, window_m: float = 2.0, max_slope_deg: float = 10.0) -> float:
    """Median RMS residual (m) of planes fitted to ``window_m`` windows sloping under ``max_slope_deg``."""
    n = max(3, int(round(window_m / res)))
    yy, xx = np.mgrid[0:n, 0:n]
    A = np.column_stack([xx.ravel() * res, yy.ravel() * res, np.ones(n * n)])
    out = []
    for r0 in range(0, z.shape[0] - n + 1, n):
        for c0 in range(0, z.shape[1] - n + 1, n):
            w = z[r0 : r0 + n, c0 : c0 + n].ravel()
            if not np.isfinite(w).all():
                continue
            coef, *_ = np.linalg.lstsq(A, w, rcond=None)
            if math.degrees(math.atan(math.hypot(coef[0], coef[1]))) > max_slope_deg:
                continue
            out.append(float(np.sqrt(np.mean((w - A @ coef) ** 2))))
    return float(np.median(out)) if out else float("nan")


#: Cells left out at the rim of the valid area for the interior streak index.
RIM_CELLS = 8


def measures(products: str) -> dict:
    import rasterio
    from scipy.ndimage import binary_erosion, convolve, label

    from truortho.core.orientation import as_orientation
    from truortho.core.rasterio_io import read_raster
    from truortho.core.surface.quality import grid_streak_index, streak_index

    o = as_orientation(os.path.join(products, "orientation.json"))
    dsm, grid, _ = read_raster(os.path.join(products, "dsm.tif"))
    raw, _, _ = read_raster(os.path.join(products, "dsm_raw.tif"))
    ground = float(np.nanmedian(dsm))
    seen2 = footprint_count(o, grid, ground) >= 2
    with rasterio.open(os.path.join(products, "trueortho.tif")) as ds:
        valid = ds.dataset_mask() > 0
    with rasterio.open(os.path.join(products, "occlusion.tif")) as ds:
        occ = ds.read(1)
    _, ogrid, _ = read_raster(os.path.join(products, "occlusion.tif"))
    oseen2 = seen2 if ogrid.shape == grid.shape else footprint_count(o, ogrid, ground) >= 2
    empty = ~valid
    neighbours = convolve(valid.astype(np.int32), np.ones((3, 3), np.int32), mode="constant") - valid
    holes, n_holes = label(seen2 & ~np.isfinite(raw))
    big = int((np.bincount(holes.ravel())[1:] * grid.res**2 >= 1.0).sum()) if n_holes else 0
    return {
        "cells": int(grid.rows * grid.cols),
        "resolution": grid.res,
        "area_seen2_m2": float(seen2.sum() * grid.res**2),
        "completeness": float(np.isfinite(dsm)[seen2].mean()) if seen2.any() else 0.0,
        "raw_holes": float((~np.isfinite(raw))[seen2].mean()) if seen2.any() else 0.0,
        "holes_over_1m2": big,
        "roughness_m": roughness(dsm, grid.res),
        "streak_index": streak_index(dsm),
        "streak_index_interior": streak_index(
            np.where(binary_erosion(np.isfinite(dsm), iterations=RIM_CELLS), dsm, np.nan)
        ),
        "grid_streak_index": grid_streak_index(dsm),
        "ortho_empty": float(empty.mean()),
        "ortho_empty_seen2": float(empty[oseen2].mean()) if oseen2.any() else 0.0,
        "ortho_speckle": int((empty & (neighbours == 8)).sum()),
        "occlusion_flagged": int((occ == 1).sum()),
    }


def picture(products: str, path: str) -> None:
    """The filtered DSM's hillshade beside the true ortho, as a JPEG."""
    sys.path.insert(0, HERE)
    from acceptance import hillshade_bgr, ortho_bgr, save_mosaic

    tiles = [
        hillshade_bgr(os.path.join(products, "dsm.tif")),
        ortho_bgr(os.path.join(products, "trueortho.tif")),
    ]
    save_mosaic([tiles], path, width=1600.0)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--blocks", default="sample", help=f"comma-separated, of {', '.join(BLOCKS)}")
    ap.add_argument("--resolution", default="0", help="RESOLUTION of the pipeline (0 = the GSD): one value "
                    "for every block, or per block as name=value,... (the others 0)")  # fmt: skip
    ap.add_argument("--keep", default="", help="keep the products in this folder")
    ap.add_argument("--write-docs", action="store_true", help=f"update the marked section of {DOCS}")
    args = ap.parse_args(argv)
    names = [b for b in args.blocks.split(",") if b]
    for b in names:
        if b not in BLOCKS:
            raise SystemExit(f"--blocks: unknown block {b!r} (expected {', '.join(BLOCKS)})")
    work = args.keep or tempfile.mkdtemp(prefix="truortho-real-")
    sys.path.insert(0, HERE)
    from _docs import commit as head_commit
    from _docs import measured_commit

    started = head_commit()  # the code measured: taken before the run, not after it
    from acceptance import warm_up

    warm_up(work, lambda m: print(m, flush=True))  # no block's time includes numba's compilation
    rows = [
        run_block(b, os.path.join(work, b), resolution_of(args.resolution, b), lambda m: print(m, flush=True))
        for b in names
    ]
    commit = measured_commit(started)
    from _docs import load_average, shown_argv

    cmd = "python -P bench/real_blocks.py " + " ".join(shown_argv(argv if argv is not None else sys.argv[1:]))
    load = load_average()  # the s and peak columns are only comparable on an equally idle machine
    lines = [
        f"`{cmd.strip()}` on {commit or '?'}, {datetime.date.today()}, {os.cpu_count()} cores{load}",
        "",
        "| block | cells (res m) | area seen by >= 2 photos m^2 | completeness | raw holes | holes >= 1 m^2 "
        f"| roughness m | streak index (without {RIM_CELLS} cells of rim) | grid streak index "
        "| ortho empty (frame / seen by 2) | speckle "
        "| occluded | s | peak MB |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['block']} | {r['cells']} ({r['resolution']:.3f}) | {r['area_seen2_m2']:.0f} | "
            f"{100 * r['completeness']:.1f} % | {100 * r['raw_holes']:.1f} % | {r['holes_over_1m2']} | "
            f"{r['roughness_m']:.3f} | {r['streak_index']:.2f} "
            f"({r.get('streak_index_interior', math.nan):.2f}) | "
            f"{r['grid_streak_index']:.2f} | "
            f"{100 * r['ortho_empty']:.1f} / "
            f"{100 * r['ortho_empty_seen2']:.1f} % | {r['ortho_speckle']} | {r['occlusion_flagged']} | "
            f"{r['seconds']:.0f} | {r.get('peak_mb', math.nan):.0f} |"
        )
    text = "\n".join(lines)
    print("\n" + text)
    os.makedirs(os.path.join(HERE, "results"), exist_ok=True)
    with open(os.path.join(HERE, "results", "real_blocks.json"), "w") as fh:
        json.dump({"command": cmd, "commit": commit, "rows": rows}, fh, indent=1)
    if args.write_docs:
        begin, end = "<!-- real:begin -->", "<!-- real:end -->"
        doc = open(DOCS, encoding="utf-8").read()
        if begin not in doc or end not in doc:
            raise SystemExit(f"{DOCS}: the markers {begin} / {end} are missing")
        new = doc[: doc.index(begin) + len(begin)] + "\n" + text + "\n" + doc[doc.index(end) :]
        with open(DOCS + ".tmp", "w", encoding="utf-8") as fh:
            fh.write(new)
        os.replace(DOCS + ".tmp", DOCS)
    return 0


if __name__ == "__main__":
    sys.exit(main())
