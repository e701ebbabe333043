"""OSGM alone on the acceptance battery's scenes: DSM figures and time per scene, no ortho, no SGBM.

Not a test. The quick loop for changes to dense matching (about 2 minutes for the 12 scenes here,
against 5 for the whole battery). The scenes are drawn as ``bench/acceptance.py`` draws them and
rendered once into ``--keep DIR`` (with the truth masks the figures need); later runs reuse them::

    source scripts/env.sh && python -P bench/osgm_battery.py --keep DIR [--tag NAME] [--only 0,2]
        [--z-step-factor 1.5] [--uniqueness 0.99] [--set refine_edges=False ...]

Prints, per scene, the OSGM wall time and the figures of ``acceptance.dsm_figures`` (completeness,
NMAD in GSD, flat3, edge3), what the failed edge cells are (``acceptance.edge_failures``) and the
DSM's roughness (1.4826 x the median departure from its 9 x 9
median surface away from edges, in GSD: noise, where NMAD also counts offsets), writes them to
``DIR/<tag>.json`` and each DSM to ``DIR/scene_NN/osgm_<tag>.tif``, so that two variants of the
code can be compared cell by cell.
The figures cited in ``core/osgm/levels.py`` and ``core/osgm/pipeline.py`` were measured with this
loop (scenes 1-11 for times: the first scene also loads the compiled kernels).

``--rotate-px X`` matches with every photo turned by a random rotation of X pixels (normal, sigma
per axis, at the photo's focal length; drawn per scene, the same on every run): cameras as a
bundle adjustment leaves them instead of the exact ones. ``--scene FIELD=VALUE`` renders every
scene with a ``SceneConfig`` field changed (``optics_blur=2.0``, ``crop_share=0.5``), into its own
``--keep`` folder. ``--realistic`` draws the scenes of ``acceptance.py --realistic`` (optics blur,
crop fields; the DSM figures in a field against the interval from the soil to the stalks' tops).
"""

from __future__ import annotations

import argparse
import ast
import json
import os
import pickle
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def _scene(i: int, seed: int, folder: str, changes: dict | None = None, realistic: bool = False) -> dict:
    """The cached scene ``i`` (rendered and pickled on first use), drawn as ``acceptance.py
    [--realistic]`` draws it, with ``changes`` to its ``SceneConfig`` (a folder holds the scene of
    one draw and one set of changes only)."""
    import dataclasses

    from acceptance import draw_config, dsm_masks

    from truortho.core.rasterio_io import read_raster

    changes = dict(changes or {})
    path = os.path.join(folder, "scene.pkl")
    if not os.path.exists(path):
        from truortho.core.ortho import evaluate as ev
        from truortho.core.synthetic import make_scene

        cfg = dataclasses.replace(draw_config(i, seed, realistic), **changes)
        scene = make_scene(cfg)
        scene.write(folder)
        truth, grid, _ = read_raster(os.path.join(folder, "dsm.tif"))
        d = {
            "o": scene.orientation, "res": grid.res, "ext": scene.extent_world(), "gsd": cfg.gsd,
            "zlo": float(np.nanmin(truth)) - 5.0, "zhi": float(np.nanmax(truth)) + 5.0,
            "nvis": ev.truth_view_counts(scene, grid, tol=0.05), "edge": dsm_masks(truth, cfg.gsd, grid.res),
            "scene_changes": changes, "realistic": realistic, "stalks": scene.crop_heights(grid.res),
        }  # fmt: skip
        with open(path, "wb") as fh:
            pickle.dump(d, fh)
    with open(path, "rb") as fh:
        d = pickle.load(fh)
    if d.get("scene_changes", {}) != changes:
        raise SystemExit(
            f"{folder}: rendered with the scene changes {d.get('scene_changes', {})}, not {changes}: "
            "give these another --keep folder"
        )
    if d.get("realistic", False) != realistic:
        raise SystemExit(
            f"{folder}: rendered {'with' if d.get('realistic') else 'without'} --realistic: "
            "give this run another --keep folder"
        )
    return d


def dataclass_fields(ap: argparse.ArgumentParser, option: str, items: list[str], cls) -> dict:
    """``FIELD=VALUE`` items of ``option`` (values as Python literals) naming fields of the dataclass
    ``cls``; anything else stops ``ap`` with a message naming the item."""
    out = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or name not in cls.__dataclass_fields__:
            ap.error(f"{option} {item!r}: expected FIELD=VALUE with a {cls.__name__} field")
        try:
            out[name] = ast.literal_eval(value)
        except (ValueError, SyntaxError):
            ap.error(f"{option} {item!r}: {value!r} is not a Python literal")
    return out


def _rotated(orientation, px: float, index: int):
    """A copy of ``orientation`` with every photo turned by a random rotation of ``px`` pixels."""
    import copy

    from scipy.spatial.transform import Rotation

    o = copy.deepcopy(orientation)
    rng = np.random.default_rng(1000 + index)
    for im in o.images:
        f = float(o.cameras[im.camera].fx)
        im.R = Rotation.from_rotvec(rng.normal(0.0, px / f, 3)).as_matrix() @ np.asarray(im.R)
    return o


def departures(dsm: np.ndarray) -> np.ndarray:
    """The DSM's departures from its 9 x 9 median surface (NaN where it has no height; its holes
    enter the median as the DSM's median height)."""
    from scipy.ndimage import median_filter

    fill = float(np.nanmedian(dsm)) if np.isfinite(dsm).any() else 0.0
    return dsm - median_filter(np.nan_to_num(dsm, nan=fill), 9)


def roughness(dev: np.ndarray, cells: np.ndarray) -> float:
    """1.4826 x the median |departure| (:func:`departures`) over ``cells`` that have one (NaN: none)."""
    m = cells & np.isfinite(dev)
    return float(1.4826 * np.median(np.abs(dev[m]))) if m.any() else float("nan")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--keep", required=True, help="folder of the cached scenes and the results")
    ap.add_argument("--tag", default="run", help="name of this variant's outputs")
    ap.add_argument("--only", default="", help="comma-separated scene indices (default 0-11)")
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--z-step-factor", type=float, default=0.0,
                    help="Z_STEP as a multiple of the cell (0: the default)")  # fmt: skip
    ap.add_argument("--uniqueness", type=float, default=None, help="OsgmConfig.uniqueness (default its own)")
    ap.add_argument("--rotate-px", type=float, default=0.0,
                    help="turn every photo by a random rotation of so many px (sigma per axis)")  # fmt: skip
    ap.add_argument("--realistic", action="store_true",
                    help="the scenes of acceptance.py --realistic (optics blur, crop fields)")  # fmt: skip
    ap.add_argument("--scene", action="append", default=[], metavar="FIELD=VALUE",
                    help="a SceneConfig field of every scene (optics_blur=2.0); its own --keep")  # fmt: skip
    ap.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="FIELD=VALUE",
        help="another OsgmConfig field, as a Python literal (refine_edges=False); repeatable",
    )
    args = ap.parse_args(argv)
    sys.path.insert(0, HERE)
    from acceptance import dsm_figures, edge_failures, within_stalks

    from truortho.core.osgm import OsgmConfig, OsgmOutputs, run_osgm
    from truortho.core.rasterio_io import read_raster

    indices = [int(v) for v in args.only.split(",") if v] or list(range(12))
    from truortho.core.synthetic import SceneConfig

    extra = {} if args.uniqueness is None else {"uniqueness": args.uniqueness}
    extra.update(dataclass_fields(ap, "--set", args.set, OsgmConfig))
    scene_changes = dataclass_fields(ap, "--scene", args.scene, SceneConfig)
    if not (args.rotate_px >= 0.0 and np.isfinite(args.rotate_px)):
        ap.error(f"--rotate-px: expected pixels >= 0, got {args.rotate_px}")
    results = {}
    for i in indices:
        folder = os.path.join(args.keep, f"scene_{i:02d}")
        d = _scene(i, args.seed, folder, scene_changes, args.realistic)
        truth, _, _ = read_raster(os.path.join(folder, "dsm.tif"))
        out = OsgmOutputs(dsm=os.path.join(folder, f"osgm_{args.tag}.tif"),
                          confidence=os.path.join(folder, f"conf_{args.tag}.tif"))  # fmt: skip
        cfg = OsgmConfig(resolution=d["res"], z_min=d["zlo"], z_max=d["zhi"],
                         z_step=(args.z_step_factor * d["res"]) or None, **extra)  # fmt: skip
        o = _rotated(d["o"], args.rotate_px, i) if args.rotate_px > 0 else d["o"]
        t = time.perf_counter()
        run_osgm(o, cfg, d["ext"], out, folder)
        seconds = time.perf_counter() - t
        dsm, _, _ = read_raster(out.dsm)
        # in crop fields any height in the stalk layer is right (as acceptance.py measures it)
        stalks = d.get("stalks", np.zeros_like(truth))
        ref = within_stalks(dsm, truth, stalks)
        f = dict(dsm_figures(dsm, ref, d["nvis"] >= 2, d["edge"], d["gsd"]), seconds=seconds)
        f["roughness_gsd"] = roughness(departures(dsm), ~d["edge"]) / d["gsd"]
        # what the edge cells off by more than 3 GSD are (shares of the edge cells)
        f.update(edge_failures(dsm, ref, d["nvis"] >= 2, d["edge"], d["gsd"], d["res"]))
        fields = ""
        if (stalks > 0).any():
            # the same figures inside and outside the crop fields
            # (no NMAD in the fields: any height in the stalk layer reads an error of 0 there)
            for name, m, keys in (("fields", stalks > 0, ("flat3", "edge3")),
                                  ("other", stalks <= 0, ("nmad_gsd", "flat3", "edge3"))):  # fmt: skip
                g = dsm_figures(dsm, ref, (d["nvis"] >= 2) & m, d["edge"], d["gsd"])
                f.update({f"{k}_{name}": g[k] for k in keys})
            fields = (f"; fields {float((stalks > 0).mean()):.0%}: flat3 {f['flat3_fields']:.4f} edge3 "
                      f"{f['edge3_fields']:.4f}, elsewhere nmad {f['nmad_gsd_other']:.3f} flat3 "
                      f"{f['flat3_other']:.4f} edge3 {f['edge3_other']:.4f}")
        results[str(i)] = f
        print(f"{args.tag} scene {i}: {seconds:6.1f} s, completeness {f['completeness']:.4f}, "
              f"nmad {f['nmad_gsd']:.3f} GSD, flat3 {f['flat3']:.4f}, edge3 {f['edge3']:.4f}, "
              f"roughness {f['roughness_gsd']:.3f} GSD, edge cells fattened {f['edge_fattened']:.3f} eroded "
              f"{f['edge_eroded']:.3f} own side {f['edge_own_side']:.3f}{fields}",
              flush=True)  # fmt: skip
    with open(os.path.join(args.keep, f"{args.tag}.json"), "w") as fh:
        json.dump(results, fh, indent=1)
    later = [f["seconds"] for k, f in results.items() if k != str(indices[0])]
    print(f"{args.tag}: {sum(f['seconds'] for f in results.values()):.1f} s in all, "
          f"{sum(later):.1f} s without the first scene")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
