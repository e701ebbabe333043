"""What the true-ortho goals of the acceptance battery measure: the same scenes, image defects removed.

Not a test. Run from the repository root::

    make acceptance-ablation
    source scripts/env.sh && python -P bench/acceptance_ablation.py [--only 0,4,10] [--write-docs]

For every scene of the battery (:func:`acceptance.draw_config`, same seeds), the true ortho
(defaults, visibility on) is made on the **truth DSM with the given cameras** from the images
rendered as drawn, and again from the same scene re-rendered without some of the image defects
the battery draws:

* ``no JPEG``: ``jpeg_quality = 0`` (no JPEG round trip, so no 4:2:0 chroma subsampling either);
* ``no noise, no JPEG``: also ``noise_sigma = 0``;
* ``clean``: also no exposure / white-balance jitter (``gain_sigma = offset_sigma = 0``) and no
  vignetting.

The geometry (scene, cameras, DSM) is identical in every variant, so what changes in the figures
is what the images themselves cost.

The figures are those of the battery (``acceptance.ortho_figures``): ``ghosting`` (2-GSD band,
dE > 25), ``ghosting_beyond_outline`` (1-6 cells out), ``mean_dE`` and ``relative_dE``.
``--write-docs`` replaces the marked ``ablation`` section of ``docs/acceptance.md``.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import shutil
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)

import acceptance  # noqa: E402
from _docs import commit as head_commit  # noqa: E402

#: (name, SceneConfig changes)
VARIANTS = (
    ("as drawn", {}),
    ("no JPEG", {"jpeg_quality": 0}),
    ("no noise, no JPEG", {"jpeg_quality": 0, "noise_sigma": 0.0}),
    (
        "clean",
        {"jpeg_quality": 0, "noise_sigma": 0.0, "gain_sigma": 0.0, "offset_sigma": 0.0, "vignetting": 0.0},
    ),
)
FIGURES = ("ghosting", "ghosting_beyond_outline", "mean_dE", "relative_dE")


def run_scene(index: int, seed: int, work: str, log) -> dict:
    from scipy.ndimage import binary_erosion

    from truortho.core.ortho import evaluate as ev
    from truortho.core.ortho.pipeline import TrueOrthoConfig, true_ortho
    from truortho.core.rasterio_io import read_raster
    from truortho.core.synthetic import make_scene

    base = acceptance.draw_config(index, seed)
    row: dict = {"scene": index, "config": acceptance.describe(base), "variants": {}}
    log(f"scene {index}: {row['config']}")
    for name, changes in VARIANTS:
        t = time.perf_counter()
        cfg = dataclasses.replace(base, **changes)
        scene = make_scene(cfg)
        folder = os.path.join(work, f"scene_{index:02d}_{len(row['variants'])}")
        scene.write(folder)
        _, grid, _ = read_raster(os.path.join(folder, "dsm.tif"))
        buildings = ev.building_mask(scene, grid)
        if not row["variants"]:  # the geometry is the same in every variant
            truth_rgb, _ = scene.orthophoto(grid.res)
            seen = ev.truth_view_counts(scene, grid, TrueOrthoConfig().max_view_angle, tol=0.05) >= 1
            unseen = binary_erosion(~seen, iterations=1)
        path = os.path.join(folder, "ortho.tif")
        ocfg = TrueOrthoConfig(resolution=grid.res, visibility=True, extent=scene.extent_world())
        true_ortho(scene.orientation, os.path.join(folder, "dsm.tif"), path, None,
                   os.path.join(folder, "occlusion.tif"), config=ocfg, image_root=folder)  # fmt: skip
        fig = acceptance.ortho_figures(path, truth_rgb, buildings, seen, unseen, cfg.gsd, grid.res)
        row["variants"][name] = {k: fig[k] for k in FIGURES}
        figures = ", ".join(f"{k} {fig[k]:.4g}" for k in FIGURES)
        log(f"  {name}: {figures} ({time.perf_counter() - t:.0f} s)")
        shutil.rmtree(folder, ignore_errors=True)
    return row


def tables(rows: list[dict]) -> list[str]:
    names = [n for n, _ in VARIANTS]
    lines = [
        "Ghosting (2-GSD band, goal <= 1 %) of the true ortho on the truth DSM, per image variant; "
        "in brackets, ghosting beyond the outline (1-6 cells):",
        "",
        "| scene | " + " | ".join(names) + " |",
        "|---|" + "---|" * len(names),
    ]
    pct = lambda x: f"{100 * x:.2f} %"  # noqa: E731
    for r in rows:
        v = r["variants"]
        cells = [f"{pct(v[n]['ghosting'])} ({pct(v[n]['ghosting_beyond_outline'])})" for n in names]
        lines.append(f"| {r['scene']} | " + " | ".join(cells) + " |")
    lines += [
        "",
        "Mean dE (goal <= 3) and, in brackets, relative dE (after the best global gain and offset per "
        "channel):",
        "",
        "| scene | " + " | ".join(names) + " |",
        "|---|" + "---|" * len(names),
    ]
    for r in rows:
        v = r["variants"]
        lines.append(f"| {r['scene']} | " + " | ".join(
            f"{v[n]['mean_dE']:.2f} ({v[n]['relative_dE']:.2f})" for n in names) + " |")  # fmt: skip
    lines += ["", "| figure, over the scenes | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]
    for key, goal in (("ghosting", 0.01), ("mean_dE", 3.0)):
        vals = {n: np.array([r["variants"][n][key] for r in rows]) for n in names}
        lines.append(f"| {key}: median / worst / scenes meeting the goal | " + " | ".join(
            f"{np.median(vals[n]):.4g} / {vals[n].max():.4g} / {int((vals[n] <= goal).sum())} of {len(rows)}"
            for n in names) + " |")  # fmt: skip
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", type=int, default=12)
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--only", default="", help="comma-separated scene indices (default all)")
    ap.add_argument("--write-docs", action="store_true", help="update the marked ablation section of "
                    "docs/acceptance.md")  # fmt: skip
    args = ap.parse_args(argv)
    indices = [int(v) for v in args.only.split(",") if v] or list(range(args.scenes))
    work = tempfile.mkdtemp(prefix="truortho-ablation-")
    t0 = time.perf_counter()
    try:
        started = head_commit()  # the code measured: taken before the run
        rows = [run_scene(i, args.seed, work, lambda m: print(m, flush=True)) for i in indices]
    finally:
        shutil.rmtree(work, ignore_errors=True)
    _, _, head = acceptance.run_header("acceptance_ablation.py", argv, started=started)
    head += f"; {len(rows)} scenes, master seed {args.seed}, {(time.perf_counter() - t0) / 60:.1f} min"
    text = "\n".join([head, "", *tables(rows), ""])
    print("\n" + text)
    if args.write_docs:
        acceptance.write_docs(text, "ablation")
    return 0


if __name__ == "__main__":
    sys.exit(main())
