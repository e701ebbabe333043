"""The battery's true orthos again on kept scenes, with changed true-ortho parameters.

Not a test. For scenes that ``bench/acceptance.py --seed N --keep DIR`` kept (their photos,
``dsm.tif`` and ``osgm.tif``), run from the repository root::

    source scripts/env.sh && python -P bench/ortho_rerun.py DIR --seed N [--only 0,4] \\
        [--set noise_tolerance=4 --set consistency=0] [--surfaces dsm.tif,osgm.tif] [--realistic]

For every scene and surface it runs ``true_ortho`` once with the defaults and once with the
``--set`` changes (fields of ``TrueOrthoConfig``; without ``--set`` only the defaults), into a
temporary folder, and prints the battery's figures for both (``acceptance.ortho_figures``:
ghosting in the 2-GSD band, beyond the outline, wrong fill, relative dE) and the share of cells
flagged as seen by no photo, then the largest change of each figure over the scenes. A true-ortho
change is measured this way in a few minutes instead of a whole battery (the scenes are
regenerated from the seed for their truth, which takes a few seconds each; OSGM does not run).
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
sys.path.insert(0, HERE)

FIGURES = ("ghosting", "ghosting_beyond_outline", "wrong_fill", "relative_dE", "flagged")


def _changes(items: list[str]) -> dict:
    from truortho.core.ortho.pipeline import TrueOrthoConfig

    fields = {f.name: f for f in dataclasses.fields(TrueOrthoConfig)}
    out: dict = {}
    for item in items:
        name, sep, text = item.partition("=")
        if not sep or name not in fields:
            raise SystemExit(f"--set: expected FIELD=VALUE with a field of TrueOrthoConfig, got {item!r}")
        default = getattr(TrueOrthoConfig(), name)
        try:
            if isinstance(default, bool):
                if text.lower() not in ("0", "1", "true", "false"):
                    raise ValueError(text)
                value: object = text.lower() in ("1", "true")
            elif isinstance(default, int | float):
                value = type(default)(float(text)) if isinstance(default, float) else int(text)
            else:
                value = text
        except ValueError:
            raise SystemExit(f"--set {name}: expected a value like {default!r}, got {text!r}") from None
        out[name] = value
    return out


def _show(fig: dict, m: str) -> str:
    """A figure as printed: shares in per cent, dE as it is."""
    return f"{fig[m] if m == 'relative_dE' else 100 * fig[m]:.2f}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("folder", help="a folder of scenes kept by acceptance.py --keep")
    ap.add_argument("--seed", type=int, required=True, help="the battery's master seed of those scenes")
    ap.add_argument("--only", default="", help="comma-separated scene indices (default every kept one)")
    ap.add_argument("--set", action="append", default=[], help="FIELD=VALUE of TrueOrthoConfig")
    ap.add_argument("--surfaces", default="dsm.tif,osgm.tif", help="comma-separated surfaces of a scene")
    ap.add_argument("--realistic", action="store_true", help="scenes kept by acceptance.py --realistic")
    args = ap.parse_args(argv)

    import acceptance as acc
    from scipy.ndimage import binary_erosion

    from truortho.core.ortho import evaluate as ev
    from truortho.core.ortho.pipeline import TrueOrthoConfig, true_ortho
    from truortho.core.rasterio_io import read_raster
    from truortho.core.synthetic import make_scene

    changes = _changes(args.set)
    if not os.path.isdir(args.folder):
        raise SystemExit(f"{args.folder}: not a folder")
    kept = sorted(int(d[6:]) for d in os.listdir(args.folder) if d.startswith("scene_") and d[6:].isdigit())
    try:
        only = [int(v) for v in args.only.split(",") if v] or kept
    except ValueError:
        raise SystemExit(f"--only: expected comma-separated scene indices, got {args.only!r}") from None
    surfaces = [s for s in args.surfaces.split(",") if s]
    variants = [("default", {})] + ([("changed", changes)] if changes else [])
    work = tempfile.mkdtemp(prefix="truortho-rerun-")
    worst: dict = {}
    try:
        for index in only:
            folder = os.path.join(args.folder, f"scene_{index:02d}")
            for name in ["dsm.tif", "orientation.json"] + surfaces:
                if not os.path.isfile(os.path.join(folder, name)):
                    raise SystemExit(f"{folder}: {name} not found (acceptance.py --keep keeps it)")
            cfg = acc.draw_config(index, args.seed, args.realistic)
            scene = make_scene(cfg)
            truth, grid, _ = read_raster(os.path.join(folder, "dsm.tif"))
            res = grid.res
            truth_rgb, _ = scene.orthophoto(res)
            buildings = ev.building_mask(scene, grid)
            seen = ev.truth_view_counts(scene, grid, TrueOrthoConfig().max_view_angle, tol=0.05) >= 1
            unseen_core = binary_erosion(~seen, iterations=1)
            for surface in surfaces:
                figs = {}
                for tag, kw in variants:
                    path = os.path.join(work, f"{index}_{surface[:-4]}_{tag}.tif")
                    occ = path.replace(".tif", "_occ.tif")
                    t = time.perf_counter()
                    ocfg = TrueOrthoConfig(resolution=res, extent=scene.extent_world(), **kw)
                    true_ortho(scene.orientation, os.path.join(folder, surface), path, None, occ, config=ocfg,
                               image_root=folder)  # fmt: skip
                    f = acc.ortho_figures(path, truth_rgb, buildings, seen, unseen_core, cfg.gsd, res)
                    flags, _, _ = read_raster(occ)
                    f["flagged"] = float(np.mean(flags == 1))
                    f["seconds"] = time.perf_counter() - t
                    figs[tag] = f
                shown = (" -> ".join(_show(figs[t], m) for t, _ in variants) for m in FIGURES)
                line = " ".join(f"{m} {v}" for m, v in zip(FIGURES, shown, strict=True))
                print(f"scene {index:2d} {surface:10s} {line}", flush=True)
                if changes:
                    for m in FIGURES:
                        key = (surface, m)
                        worst[key] = max(worst.get(key, -np.inf), figs["changed"][m] - figs["default"][m])
    finally:
        shutil.rmtree(work, ignore_errors=True)
    if changes:
        print("largest increase over the scenes (ghosting, wrong fill, flagged in points; dE as it is):")
        for (surface, m), v in sorted(worst.items()):
            print(f"  {surface:10s} {m:24s} {100 * v if m != 'relative_dE' else v:+.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
