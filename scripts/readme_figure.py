"""The README's picture: conventional beside true orthophoto of the bundled sample (issue 20).

    bash scripts/demo.sh
    source scripts/env.sh && .venv/bin/python -P scripts/readme_figure.py [--products build/demo/products]

Reads the demo's products (orientation.json, dsm.tif, trueortho.tif, occlusion.tif), computes the
conventional orthophoto on the same DSM and grid (``TrueOrthoConfig(visibility=False)``: every cell
from the best image by ground resolution, no depth test), and writes both side by side, the true
orthophoto's cells seen by no image in magenta, to docs/img/sample-conventional-vs-true.jpg.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "img" / "sample-conventional-vs-true.jpg"


def _rgb(path: Path) -> np.ndarray:
    from truortho.core.rasterio_io import read_raster

    data = read_raster(path, band=None)[0]
    rgb = np.moveaxis(data[:3], 0, -1).astype(np.float32)
    if data.dtype != np.uint8:
        rgb = rgb / max(float(rgb.max()), 1.0) * 255
    alpha = data[3] > 0 if data.shape[0] >= 4 else np.ones(rgb.shape[:2], bool)
    return np.where(alpha[..., None], rgb, 255).astype(np.uint8)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--products", default=str(ROOT / "build" / "demo" / "products"))
    ap.add_argument("--output", default=str(OUT))
    ap.add_argument("--width", type=int, default=1400, help="width of the picture, pixels")
    args = ap.parse_args(argv)
    from PIL import Image

    from truortho.core.ortho.pipeline import TrueOrthoConfig, true_ortho
    from truortho.core.rasterio_io import raster_grid, read_raster

    products = Path(args.products)
    for name in ("orientation.json", "dsm.tif", "trueortho.tif", "occlusion.tif"):
        if not (products / name).is_file():
            raise SystemExit(f"{products / name}: missing; run bash scripts/demo.sh first")
    grid = raster_grid(products / "trueortho.tif")
    with tempfile.TemporaryDirectory(prefix="truortho-figure-") as tmp:
        conv = Path(tmp) / "conventional.tif"
        cfg = TrueOrthoConfig(resolution=grid.res, extent=grid.extent, visibility=False, crs=grid.crs)
        true_ortho(products / "orientation.json", products / "dsm.tif", conv, config=cfg)
        left = _rgb(conv)
    right = _rgb(products / "trueortho.tif")
    occl = read_raster(products / "occlusion.tif")[0] == 1
    right[occl] = (255, 0, 255)
    rows = min(left.shape[0], right.shape[0])
    cols = min(left.shape[1], right.shape[1])
    gap = np.full((rows, max(cols // 60, 4), 3), 255, np.uint8)
    both = np.concatenate([left[:rows, :cols], gap, right[:rows, :cols]], axis=1)
    img = Image.fromarray(both)
    if img.width != args.width:  # the sample's products are small: enlarged for reading, or reduced
        img = img.resize((args.width, round(img.height * args.width / img.width)), Image.LANCZOS)
    out = Path(args.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp_out = out.with_suffix(".tmp.jpg")
    img.save(tmp_out, quality=85)
    tmp_out.replace(out)
    print(f"wrote {out} ({img.width} x {img.height})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
