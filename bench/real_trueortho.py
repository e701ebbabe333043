"""True orthophoto of a real block, with a preview PNG (not a test).

    source scripts/env.sh
    python -P bench/real_trueortho.py ORIENTATION.json OUT_DIR [--dsm DSM.tif] [--res 0.1] \\
        [--preview docs/x.png] [--extent xmin,ymin,xmax,ymax]

Without ``--dsm`` a coarse surface is interpolated from the orientation's tie points (linear
Delaunay interpolation of the median tie-point height per 1 m cell, holes filled by nearest
neighbour): enough to run the whole chain on real images, but without sharp building outlines,
so it is no substitute for a dense-matching DSM (OSGM) where true-ortho quality matters.
Prints the statistics of the run and writes the preview (alpha shown as black) downscaled to at
most 1200 px.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np


def tie_point_dsm(orientation, path: str, cell: float = 1.0) -> str:
    from scipy.interpolate import LinearNDInterpolator
    from scipy.ndimage import distance_transform_edt

    from truortho.core.grid import RasterGrid
    from truortho.core.rasterio_io import write_raster

    pts = orientation.frame.to_world(orientation.points.xyz)
    lo, hi = np.percentile(pts[:, 2], [1, 99])
    pts = pts[(pts[:, 2] >= lo - 5) & (pts[:, 2] <= hi + 5)]
    x0, y0 = np.floor(pts[:, :2].min(axis=0))
    x1, y1 = np.ceil(pts[:, :2].max(axis=0))
    grid = RasterGrid.from_extent((x0, y0, x1, y1), cell, orientation.crs)
    r = ((grid.y_max - pts[:, 1]) / cell).astype(int).clip(0, grid.rows - 1)
    c = ((pts[:, 0] - grid.x_min) / cell).astype(int).clip(0, grid.cols - 1)
    key = r * grid.cols + c
    order = np.argsort(key)
    k, start = np.unique(key[order], return_index=True)
    med = np.array(
        [np.median(pts[order][s:e, 2]) for s, e in zip(start, list(start[1:]) + [len(order)], strict=True)]
    )
    X, Y = grid.centres()
    cx = grid.x_min + (k % grid.cols + 0.5) * cell
    cy = grid.y_max - (k // grid.cols + 0.5) * cell
    h = LinearNDInterpolator(np.column_stack([cx, cy]), med)(X, Y)
    bad = ~np.isfinite(h)
    if bad.any():
        _, (ir, ic) = distance_transform_edt(bad, return_indices=True)
        h = h[ir, ic]
    write_raster(path, h.astype(np.float32), grid, nodata=-9999.0)
    return path


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("orientation")
    ap.add_argument("out")
    ap.add_argument("--dsm")
    ap.add_argument("--res", type=float)
    ap.add_argument("--preview")
    ap.add_argument("--extent", help="xmin,ymin,xmax,ymax")
    args = ap.parse_args()
    from truortho.core.orientation import Orientation
    from truortho.core.ortho.pipeline import TrueOrthoConfig, true_ortho
    from truortho.core.progress import CallbackProgress

    os.makedirs(args.out, exist_ok=True)
    o = Orientation.load(args.orientation)
    dsm = args.dsm or tie_point_dsm(o, os.path.join(args.out, "tiepoint_dsm.tif"))
    ext = tuple(float(v) for v in args.extent.split(",")) if args.extent else None
    cfg = TrueOrthoConfig(resolution=args.res, extent=ext)
    t = time.perf_counter()
    last = [0.0]

    def show(f, m):
        if f - last[0] >= 0.1:
            last[0] = f
            print(f"{f:.0%} {m or ''}", flush=True)

    r = true_ortho(
        o,
        dsm,
        os.path.join(args.out, "trueortho.tif"),
        os.path.join(args.out, "source.tif"),
        os.path.join(args.out, "occlusion.tif"),
        cfg,
        CallbackProgress(show),
    )
    print(json.dumps({k: v for k, v in r.stats.items() if k != "color_correction"}, indent=1))
    print(f"{time.perf_counter() - t:.1f} s")
    if args.preview:
        import cv2

        from truortho.core.rasterio_io import read_raster

        a, _, _ = read_raster(r.output, band=None)
        rgb = np.moveaxis(a[:3], 0, -1).copy()
        rgb[a[-1] == 0] = 0
        s = min(1.0, 1200 / max(rgb.shape[:2]))
        if s < 1:
            rgb = cv2.resize(rgb, None, fx=s, fy=s, interpolation=cv2.INTER_AREA)
        cv2.imwrite(args.preview, rgb[:, :, ::-1], [cv2.IMWRITE_PNG_COMPRESSION, 9])
        print("preview", args.preview, rgb.shape)
    return 0


if __name__ == "__main__":
    sys.exit(main())
