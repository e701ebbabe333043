"""OSGM and the true ortho on a battery scene whose ground is partly crop fields, at several optics blurs.

Not a test. Run from the repository root::

    source scripts/env.sh && python -P bench/crop_fields.py --seed 5150 --scene 3 \\
        [--share 0.5] [--height 0.3] [--blur 0,1,2,3] [--keep DIR]

For every ``--blur`` (``SceneConfig.optics_blur``, pixels) it renders scene ``--scene`` of the
battery's ``--seed`` (``acceptance.draw_config``) with ``crop_share`` / ``crop_height`` fields, runs
OSGM with its defaults (only Z_MIN/Z_MAX given) and the true ortho on the OSGM DSM (defaults), and
prints for the field cells (5 cells inside a field, away from height steps) and for the other
ground away from steps: NMAD and median error of the DSM against the soil, in GSD; its roughness
(1.4826 x the median departure from its 9 x 9 median surface, GSD); the share of those cells
that the true ortho flags as seen by no photo. The figures of docs/acceptance.md (*What the
battery's photos do not have*) were measured this way.
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


def _numbers(text: str, name: str) -> list[float]:
    try:
        out = [float(v) for v in text.split(",") if v]
    except ValueError:
        raise SystemExit(f"--{name}: expected comma-separated numbers, got {text!r}") from None
    if not out or min(out) < 0:
        raise SystemExit(f"--{name}: expected comma-separated numbers >= 0, got {text!r}")
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seed", type=int, required=True, help="the battery's master seed")
    ap.add_argument("--scene", type=int, required=True, help="the scene's index (0-11)")
    ap.add_argument("--share", type=float, default=0.5, help="SceneConfig.crop_share")
    ap.add_argument("--height", type=float, default=0.3, help="SceneConfig.crop_height, metres")
    ap.add_argument("--blur", default="0,1,2,3", help="comma-separated SceneConfig.optics_blur values, px")
    ap.add_argument("--keep", default="", help="keep the scenes and products in this folder")
    args = ap.parse_args(argv)
    blurs = _numbers(args.blur, "blur")

    import acceptance as acc
    from osgm_battery import departures, roughness
    from scipy.ndimage import binary_erosion

    from truortho.core.errors import InputError
    from truortho.core.ortho.pipeline import TrueOrthoConfig, true_ortho
    from truortho.core.osgm import OsgmConfig, OsgmOutputs, run_osgm
    from truortho.core.rasterio_io import read_raster
    from truortho.core.synthetic import make_scene
    from truortho.core.synthetic.truth import grid_centres

    work = args.keep or tempfile.mkdtemp(prefix="truortho-crop-")
    try:
        for blur in blurs:
            try:
                cfg = dataclasses.replace(acc.draw_config(args.scene, args.seed), crop_share=args.share,
                                          crop_height=args.height, optics_blur=blur)  # fmt: skip
            except InputError as e:
                raise SystemExit(str(e)) from None
            folder = os.path.join(work, f"scene_{args.scene:02d}_blur{blur:g}")
            t = time.perf_counter()
            scene = make_scene(cfg)
            scene.write(folder)
            truth, grid, _ = read_raster(os.path.join(folder, "dsm.tif"))
            res, gsd = grid.res, cfg.gsd
            xy, shape, _ = grid_centres(res, scene.extent_world(), np.asarray(cfg.offset, float))
            _, bid = scene.surface.height(xy)
            ground = (bid < 0).reshape(shape)
            inside = scene.crop_heights(res) > 0
            edge = acc.dsm_masks(truth, gsd, res)
            masks = (("fields", binary_erosion(inside, iterations=5) & ~edge),
                     ("other ground", ~inside & ground & ~edge))  # fmt: skip
            zlo, zhi = float(np.nanmin(truth)) - 5.0, float(np.nanmax(truth)) + 5.0
            out = OsgmOutputs(dsm=os.path.join(folder, "osgm.tif"))
            ocfg = OsgmConfig(resolution=res, z_min=zlo, z_max=zhi)
            run_osgm(scene.orientation, ocfg, scene.extent_world(), out, folder)
            z, _, _ = read_raster(out.dsm)
            ortho = os.path.join(folder, "ortho_osgm.tif")
            occ_path = ortho.replace(".tif", "_occ.tif")
            tcfg = TrueOrthoConfig(resolution=res, extent=scene.extent_world())
            true_ortho(scene.orientation, out.dsm, ortho, None, occ_path, config=tcfg, image_root=folder)
            occ, _, _ = read_raster(occ_path)
            dev = departures(z)
            err = z - truth
            for name, m in masks:
                m = m & np.isfinite(err)
                if not m.any():
                    print(f"blur {blur:g} px, {name}: no cells", flush=True)
                    continue
                bias = float(np.median(err[m]))
                nmad = 1.4826 * float(np.median(np.abs(err[m] - bias)))
                rough = roughness(dev, m)
                print(f"blur {blur:g} px, {name:12s} ({100 * m.mean():.1f} % of the cells): NMAD "
                      f"{nmad / gsd:.2f} GSD, median error {bias / gsd:+.2f} GSD, "
                      f"roughness {rough / gsd:.3f} GSD, flagged {100 * float(np.mean(occ[m] == 1)):.2f} %",
                      flush=True)  # fmt: skip
            print(f"blur {blur:g} px: {time.perf_counter() - t:.0f} s", flush=True)
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
