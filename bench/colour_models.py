"""Colour models compared on held-out cells: how far apart two photos of the same cell stay after
each model's correction, on the acceptance battery's synthetic scenes and on real blocks.

    python -P bench/colour_models.py [--scenes 12] [--real NAME=PRODUCTS ...] [--write-docs]

For every block the true ortho's colour statistics are taken as the pipeline takes them (cells seen
cleanly by two or more photos on a decimated grid, vignetting removed), then split by cell into two
halves. Each model is fitted on one half; on the other, the mean and median dE between the corrected
observations of a cell by two photos is printed ("disagreement"). With no correction this is what
the photos differ by; the noise of two photos is a floor no model goes below. On the synthetic
scenes (truth DSM, the battery's draws) the truth colour of each cell is known too, and the mean dE
of the corrected held-out observations from it is printed after the best global gain and offset
per channel ("relative dE of the samples": the block's absolute exposure is not observable).

Models: ``none``; ``lab``, gains and offsets in L*a*b* alone (the model before 499a53a); ``rgb+lab``,
a gain and offset per RGB channel first (white balance, exposure, black level), then L*a*b* (the
default, :func:`truortho.core.ortho.color.estimate_colour_model`).

Real blocks need the products of a real-blocks run (``make acceptance-real REAL_ARGS="... --keep
DIR"``: ``DIR/NAME/products`` holds ``orientation.json`` and ``dsm.tif``); their photos are found
as ``bench/real_blocks.py`` finds them.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

MODELS = ("none", "lab", "rgb+lab")
SECTION = "colours"


class _Captured(Exception):
    pass


def capture(orientation, dsm: str, image_root: str, res: float) -> tuple:
    """The observations (cell, image, samples, n_images) that the true ortho's colour estimate gets.

    The pipeline is stopped at its colour estimate (its estimator replaced for the call): the bench
    needs exactly the samples the product uses, which are internal to :func:`true_ortho`.
    """
    from truortho.core.ortho import pipeline as pl

    got: dict = {}

    def grab(cell, img, samples, n_images, dtype, **_):
        got.update(cell=np.asarray(cell), img=np.asarray(img), raw=np.asarray(samples, float), n=n_images)
        raise _Captured()

    real = pl.estimate_colour_model
    pl.estimate_colour_model = grab
    try:
        with tempfile.TemporaryDirectory() as tmp:
            cfg = pl.TrueOrthoConfig(resolution=res, visibility=True)
            pl.true_ortho(orientation, dsm, os.path.join(tmp, "o.tif"), None, None, config=cfg,
                          image_root=image_root)  # fmt: skip
    except _Captured:
        pass
    finally:
        pl.estimate_colour_model = real
    if not got:
        raise SystemExit(f"{dsm}: no cell seen by two photos, nothing to compare")
    return got["cell"], got["img"], got["raw"], got["n"]


def fit(model: str, cell, img, raw, n: int):
    from truortho.core.ortho.color import ColorCorrection, estimate_colour_model

    if model == "none":
        return ColorCorrection.identity(n, raw.shape[1])
    return estimate_colour_model(cell, img, raw, n, np.uint8, rgb_stage=(model == "rgb+lab"))


def corrected(corr, img, raw) -> np.ndarray:
    out = np.empty_like(raw)
    for i in np.unique(img):
        m = img == i
        out[m] = corr.apply(int(i), raw[m], np.uint8)
    return out


def compare(cell, img, raw) -> dict:
    """Per model: the held-out disagreement between photos (mean and median dE, pairs)."""
    from truortho.core.ortho.color import rgb_to_lab

    h = (cell.astype(np.int64) * 2654435761) % 2**32
    fit_half = (h >> 7) % 2 == 0  # a hash of the cell id: both halves spread over the block
    test = np.flatnonzero(~fit_half)
    test = test[np.argsort(cell[test], kind="stable")]
    tc, ti, tr = cell[test], img[test], raw[test]
    a = np.flatnonzero(tc[1:] == tc[:-1])  # consecutive observations of one cell: two photos
    n = int(img.max()) + 1
    out = {}
    for model in MODELS:
        corr = fit(model, cell[fit_half], img[fit_half], raw[fit_half], n)
        lab = rgb_to_lab(np.clip(corrected(corr, ti, tr), 0, 255) / 255.0)
        de = np.linalg.norm(lab[a] - lab[a + 1], axis=1)
        out[model] = {"mean": float(de.mean()), "median": float(np.median(de)), "pairs": int(len(a))}
    return out


def synthetic_blocks(scenes: int, seed: int, work: str, log):
    from acceptance import draw_config

    from truortho.core.rasterio_io import read_raster
    from truortho.core.synthetic import make_scene

    for i in range(scenes):
        scene = make_scene(draw_config(i, seed))
        folder = os.path.join(work, f"scene_{i:02d}")
        scene.write(folder)
        dsm = os.path.join(folder, "dsm.tif")
        _, grid, _ = read_raster(dsm)
        log(f"scene {i}: {len(scene.orientation.images)} photos")
        yield f"scene {i}", len(scene.orientation.images), capture(scene.orientation, dsm, folder, grid.res)


def real_blocks(specs: list[str], log):
    from real_blocks import BLOCKS

    from truortho.core.orientation import as_orientation
    from truortho.core.rasterio_io import read_raster

    for spec in specs:
        name, sep, folder = spec.partition("=")
        if not sep or name not in BLOCKS:
            raise SystemExit(f"--real {spec!r}: expected NAME=PRODUCTS with NAME one of {', '.join(BLOCKS)}")
        paths = [os.path.join(folder, f) for f in ("orientation.json", "dsm.tif")]
        for path in paths:
            if not os.path.isfile(path):
                raise SystemExit(f"--real {spec!r}: {path} not found (the products of a real-blocks run)")
        orientation = as_orientation(paths[0])
        _, grid, _ = read_raster(paths[1])
        log(f"{name}: {len(orientation.images)} photos")
        yield name, len(orientation.images), capture(orientation, paths[1], BLOCKS[name][0], grid.res)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", type=int, default=12, help="battery scenes (its draws); 0: none")
    ap.add_argument("--seed", type=int, default=2026, help="the battery's master seed")
    ap.add_argument("--real", action="append", default=[], metavar="NAME=PRODUCTS",
                    help="a real block and the products of a real-blocks run (repeatable)")  # fmt: skip
    ap.add_argument("--write-docs", action="store_true", help="update docs/acceptance.md")
    args = ap.parse_args(argv)
    from _docs import commit as head_commit
    from acceptance import run_header, write_docs

    started = head_commit()
    t0 = time.perf_counter()

    def log(msg: str) -> None:
        print(f"[{time.perf_counter() - t0:6.0f} s] {msg}", flush=True)

    rows = []
    with tempfile.TemporaryDirectory(prefix="truortho-colour-") as work:
        blocks = list(real_blocks(args.real, log)) + list(synthetic_blocks(args.scenes, args.seed, work, log))
        for name, photos, (cell, img, raw, _) in blocks:
            r = compare(cell, img, raw)
            rows.append((name, photos, r))
            log(f"{name}: " + ", ".join(f"{m} {v['mean']:.2f}/{v['median']:.2f}" for m, v in r.items()))
    _, _, head = run_header("colour_models.py", argv, detail=f"{(time.perf_counter() - t0) / 60:.1f} min",
                            started=started)  # fmt: skip
    lines = [
        head,
        "",
        "Disagreement between two photos of a held-out cell after the correction, mean / median dE:",
        "",
        "| block | photos | cell pairs | none | lab | rgb+lab | rgb+lab / lab (mean) |",
        "|---|---|---|---|---|---|---|",
    ]
    ratios = []
    for name, photos, r in rows:
        ratio = r["rgb+lab"]["mean"] / r["lab"]["mean"]
        ratios.append(ratio)
        cells = " | ".join(f"{r[m]['mean']:.2f} / {r[m]['median']:.2f}" for m in MODELS)
        lines.append(f"| {name} | {photos} | {r['none']['pairs']:,} | {cells} | {ratio:.3f} |")
    ratios_a = np.array(ratios)
    lines += [
        "",
        f"rgb+lab / lab: median {np.median(ratios_a):.3f}, range {ratios_a.min():.3f}-{ratios_a.max():.3f}; "
        f"rgb+lab lower on {int((ratios_a < 1).sum())} of {len(rows)} blocks.",
    ]
    text = "\n".join(lines)
    print("\n" + text)
    if args.write_docs:
        write_docs(text, section=SECTION)
    return 0


if __name__ == "__main__":
    sys.exit(main())
