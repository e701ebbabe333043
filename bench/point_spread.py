"""The photos' point spread, estimated from their strong straight edges (Gaussian sigma, pixels).

Not a test. Run from the repository root, one glob per block (the first ``--photos`` of each)::

    source scripts/env.sh && python -P bench/point_spread.py "DIR/images/*.jpg" ["OTHER/*.JPG" ...] \\
        [--photos 4]

For the strongest 0.5 % of a photo's gradients (Sobel) it samples the grey-level profile across
the edge (12 px long, every 0.25 px) and keeps the edges whose profile peaks at the pixel and is
flat beyond 3 px on both sides (a straight step of at least 30 grey levels, not a line or a
corner). A step of height A blurred by a Gaussian of sigma s has the largest slope
A / (s sqrt(2 pi)), so s = A / (sqrt(2 pi) max slope); the median over the edges is printed.
Synthetic photos of the battery with ``SceneConfig.optics_blur`` 0, 1 and 2 px read 0.44, 1.02
and 1.82 (the rendering's own pixel integration is the 0.44), so a block's figure F corresponds
to an ``optics_blur`` of about sqrt(F^2 - 0.44^2). docs/acceptance.md cites its figures.
"""

from __future__ import annotations

import argparse
import glob
import sys

import numpy as np

#: Samples per pixel along an edge's profile, and its half length in pixels.
_STEP = 0.25
_HALF = 6.0


def edge_sigmas(path: str, n_max: int = 4000, seed: int = 0) -> np.ndarray:
    """The point spread (sigma, px) at the straight edges of one photo (at most ``n_max`` tried)."""
    import cv2

    im = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
    if im is None:
        raise SystemExit(f"{path}: not a readable image")
    im = im.astype(np.float32)
    gx = cv2.Sobel(im, cv2.CV_32F, 1, 0, ksize=3) / 8.0
    gy = cv2.Sobel(im, cv2.CV_32F, 0, 1, ksize=3) / 8.0
    mag = np.hypot(gx, gy)
    ys, xs = np.nonzero(mag > np.percentile(mag, 99.5))
    m = int(_HALF) + 3
    keep = (ys >= m) & (xs >= m) & (ys < im.shape[0] - m) & (xs < im.shape[1] - m)
    ys, xs = ys[keep], xs[keep]
    if len(ys) > n_max:
        sel = np.random.default_rng(seed).choice(len(ys), n_max, replace=False)
        ys, xs = ys[sel], xs[sel]
    t = np.arange(-_HALF, _HALF + 1e-9, _STEP)
    centre = len(t) // 2
    out = []
    for y, x in zip(ys, xs, strict=True):
        dx, dy = gx[y, x] / mag[y, x], gy[y, x] / mag[y, x]
        mx = (x + t * dx).astype(np.float32)[None]
        my = (y + t * dy).astype(np.float32)[None]
        prof = cv2.remap(im, mx, my, cv2.INTER_LINEAR)[0]
        slope = np.gradient(prof, _STEP)
        k = int(np.argmax(np.abs(slope)))
        if abs(k - centre) > 2:
            continue
        a = float(prof[-4:].mean() - prof[:4].mean())
        if abs(a) < 30.0 or prof[:8].std() > 0.08 * abs(a) or prof[-8:].std() > 0.08 * abs(a):
            continue
        out.append(abs(a) / (np.sqrt(2.0 * np.pi) * abs(float(slope[k]))))
    return np.asarray(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("globs", nargs="+", help="one glob of photos per block")
    ap.add_argument("--photos", type=int, default=4, help="photos per block (the first by name)")
    args = ap.parse_args(argv)
    if args.photos < 1:
        raise SystemExit(f"--photos: expected at least 1, got {args.photos}")
    for pattern in args.globs:
        files = sorted(glob.glob(pattern))[: args.photos]
        if not files:
            raise SystemExit(f"{pattern}: no photo matches")
        s = np.concatenate([edge_sigmas(f) for f in files])
        if not len(s):
            print(f"{pattern}: no straight edge found", flush=True)
            continue
        q1, med, q3 = np.percentile(s, [25, 50, 75])
        print(f"{pattern}: {len(s)} edges in {len(files)} photos, sigma median {med:.2f} px "
              f"(25/75 % {q1:.2f}/{q3:.2f})", flush=True)  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
