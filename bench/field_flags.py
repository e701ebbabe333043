"""OSGM and the true ortho again on a window of a real block's products: how rough the raw DSM is
there and how many cells the ortho flags as seen by no photo, with the gradient cost's
saturation scale as it is or floored.

Not a test. For a window of the products that ``bench/real_blocks.py --keep DIR`` keeps (their
``orientation.json`` and ``dsm.tif``), run from the repository root::

    source scripts/env.sh && python -P bench/field_flags.py DIR/boruszyn/products \\
        --rows 150:400 --cols 350:600 [--margin 50] [--floor 0,0.02] [--set radius=3 ...]

For every ``--floor`` (0: OSGM as it is; else every tile's saturation scale, the median
|gradient| of ``sweep.gradient_scales``, is raised to at least that share of the photos' full
scale) it runs ``run_osgm`` on the window grown by ``--margin`` cells (the products' resolution,
Z range from their DSM there, -5/+10 m), and prints for the window: the departures of the raw DSM
from its 9 x 9 median (5 and 95 %, and 1.4826 x their median absolute value), its holes, and the
share of the window's cells that ``true_ortho`` on that DSM flags as seen by no photo. ``--set
FIELD=VALUE`` changes an ``OsgmConfig`` field (``radius=3``, ``measure='census'``). The figures
of boruszyn's harvested field in docs/acceptance.md (*Real photo blocks*) were measured this way.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time

import numpy as np


def _span(text: str, name: str) -> tuple[int, int]:
    try:
        a, b = (int(v) for v in text.split(":"))
    except ValueError:
        raise SystemExit(f"--{name}: expected FIRST:STOP (cells), got {text!r}") from None
    if not 0 <= a < b:
        raise SystemExit(f"--{name}: expected 0 <= FIRST < STOP, got {text!r}")
    return a, b


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("products", help="a products folder of a real block (orientation.json, dsm.tif)")
    ap.add_argument("--rows", required=True, help="FIRST:STOP rows of the products' DSM")
    ap.add_argument("--cols", required=True, help="FIRST:STOP columns of the products' DSM")
    ap.add_argument("--margin", type=int, default=50, help="cells of OSGM's extent around the window")
    ap.add_argument("--floor", default="0", help="comma-separated floors of the saturation scale (0: none)")
    ap.add_argument("--set", action="append", default=[], metavar="FIELD=VALUE",
                    help="an OsgmConfig field, as a Python literal (radius=3); repeatable")  # fmt: skip
    args = ap.parse_args(argv)
    (r0, r1), (c0, c1) = _span(args.rows, "rows"), _span(args.cols, "cols")
    if args.margin < 0:
        raise SystemExit(f"--margin: expected cells >= 0, got {args.margin}")
    try:
        floors = [float(v) for v in args.floor.split(",") if v]
    except ValueError:
        raise SystemExit(f"--floor: expected comma-separated numbers >= 0, got {args.floor!r}") from None
    if not floors or min(floors) < 0:
        raise SystemExit(f"--floor: expected comma-separated numbers >= 0, got {args.floor!r}")
    for name in ("orientation.json", "dsm.tif"):
        if not os.path.isfile(os.path.join(args.products, name)):
            raise SystemExit(f"{args.products}: {name} not found (real_blocks.py --keep keeps it)")

    from scipy.ndimage import median_filter

    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from osgm_battery import dataclass_fields

    import truortho.core.osgm.sweep as sweep
    from truortho.core.orientation import Orientation
    from truortho.core.ortho.pipeline import TrueOrthoConfig, true_ortho
    from truortho.core.osgm import OsgmConfig, OsgmOutputs, run_osgm
    from truortho.core.rasterio_io import read_raster

    changes = dataclass_fields(ap, "--set", args.set, OsgmConfig)
    o = Orientation.load(os.path.join(args.products, "orientation.json"))
    dsm, grid, _ = read_raster(os.path.join(args.products, "dsm.tif"))
    if r1 > grid.rows or c1 > grid.cols:
        raise SystemExit(f"--rows/--cols: the DSM has {grid.rows} x {grid.cols} cells")
    res, m = grid.res, int(args.margin)
    g0, g1 = max(0, r0 - m), min(grid.rows, r1 + m)
    h0, h1 = max(0, c0 - m), min(grid.cols, c1 + m)
    x, y = grid.x_min, grid.y_max
    extent = (x + h0 * res, y - g1 * res, x + h1 * res, y - g0 * res)
    window = (x + c0 * res, y - r1 * res, x + c1 * res, y - r0 * res)
    part = dsm[g0:g1, h0:h1]
    if not np.isfinite(part).any():
        raise SystemExit("--rows/--cols: the DSM has no height there")
    zlo, zhi = float(np.nanmin(part)) - 5.0, float(np.nanmax(part)) + 10.0
    own = sweep.gradient_scales
    out_dir = tempfile.mkdtemp(prefix="truortho-field-")
    for floor in floors:

        def floored(*a, _f=floor):
            return np.maximum(own(*a), _f)

        sweep.gradient_scales = floored if floor > 0 else own
        try:
            path = os.path.join(out_dir, f"osgm_{floor:g}.tif")
            t = time.perf_counter()
            ocfg = OsgmConfig(resolution=res, z_min=zlo, z_max=zhi, **changes)
            run_osgm(o, ocfg, extent, OsgmOutputs(dsm=path))
            seconds = time.perf_counter() - t
        finally:
            sweep.gradient_scales = own
        z, _, _ = read_raster(path)
        zw = z[r0 - g0 : r1 - g0, c0 - h0 : c1 - h0]
        d = zw - median_filter(np.nan_to_num(zw, nan=float(np.nanmedian(zw))), 9)
        ortho = os.path.join(out_dir, f"ortho_{floor:g}.tif")
        occ = ortho.replace(".tif", "_occ.tif")
        true_ortho(o, path, ortho, None, occ, config=TrueOrthoConfig(resolution=res, extent=window))
        flags, _, _ = read_raster(occ)
        lo, hi = np.nanpercentile(d, [5, 95])
        print(
            f"floor {floor:g}: OSGM {seconds:.0f} s; raw DSM departures from its 9x9 median "
            f"{lo:+.3f}/{hi:+.3f} m (5/95 %), robust sigma {1.4826 * np.nanmedian(np.abs(d)):.3f} m, "
            f"holes {100 * np.isnan(zw).mean():.2f} %; ortho cells seen by no photo "
            f"{100 * float(np.mean(flags == 1)):.2f} %",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
