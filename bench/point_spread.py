"""The photos' point spread, estimated from their strong straight edges (Gaussian sigma, pixels).

Not a test. Run from the repository root, one glob per block (the first ``--photos`` of each)::

    source scripts/env.sh && python -P bench/point_spread.py "DIR/images/*.jpg" ["OTHER/*.JPG" ...] \\
        [--photos 4]

The measure is OSGM's own (:func:`truortho.core.optics.edge_spreads`): for the strongest 0.5 % of
a photo's gradients (Sobel) it samples the grey-level profile across the edge (12 px long, every
0.25 px) and keeps the edges whose profile peaks at the pixel and is flat beyond 3 px on both sides
(a straight step of at least 30 grey levels, not a line or a corner). A step of height A blurred by
a Gaussian of sigma s has the largest slope A / (s sqrt(2 pi)), so s = A / (sqrt(2 pi) max slope);
the median over the edges is printed.
Synthetic photos of the battery with ``SceneConfig.optics_blur`` 0, 1 and 2 px read 0.44, 1.02
and 1.82 (the rendering's own pixel integration is the 0.44), so a block's figure F corresponds
to an ``optics_blur`` of about sqrt(F^2 - 0.44^2). docs/acceptance.md cites its figures.

For JPEG photos it also prints what the compression did: the quality of the luminance quantisation
table on the IJG scale (:func:`jpeg_quality`; the libjpeg/OpenCV/camera ``quality`` setting when the
encoder scaled the standard table) and the blockiness (:func:`block_edge_ratio`): in the 30 % least
textured parts of the photo, the mean grey-level step across the 8-pixel block boundaries over the
mean step inside the blocks (1: no visible blocks).
"""

from __future__ import annotations

import argparse
import glob
import sys

import numpy as np


def grey(path: str) -> np.ndarray:
    """The photo's grey levels (float32, 0-255); stops with a message naming an unreadable file."""
    import cv2

    im = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
    if im is None:
        raise SystemExit(f"{path}: not a readable image")
    return im.astype(np.float32)


def edge_sigmas(im: np.ndarray, n_max: int = 4000, seed: int = 0) -> np.ndarray:
    """The point spread (sigma, px) at the straight edges of one photo's grey levels :func:`grey`
    (at most ``n_max`` edges tried): :func:`truortho.core.optics.edge_spreads`, which OSGM uses."""
    from truortho.core.optics import edge_spreads

    return edge_spreads(im, 255.0, n_max, seed)


#: The IJG (libjpeg) standard luminance quantisation table at quality 50, in natural (row) order.
_IJG_LUMA = np.array([
    16, 11, 10, 16, 24, 40, 51, 61, 12, 12, 14, 19, 26, 58, 60, 55, 14, 13, 16, 24, 40, 57, 69, 56,
    14, 17, 22, 29, 51, 87, 80, 62, 18, 22, 37, 56, 68, 109, 103, 77, 24, 35, 55, 64, 81, 104, 113, 92,
    49, 64, 78, 87, 103, 121, 120, 101, 72, 92, 95, 98, 112, 100, 103, 99,
], np.float64)  # fmt: skip
#: Natural-order index of each zigzag position (a DQT segment lists its table in zigzag order).
_ZIGZAG = np.array([
    0, 1, 8, 16, 9, 2, 3, 10, 17, 24, 32, 25, 18, 11, 4, 5, 12, 19, 26, 33, 40, 48, 41, 34, 27, 20, 13, 6,
    7, 14, 21, 28, 35, 42, 49, 56, 57, 50, 43, 36, 29, 22, 15, 23, 30, 37, 44, 51, 58, 59, 52, 45, 38, 31,
    39, 46, 53, 60, 61, 54, 47, 55, 62, 63,
])  # fmt: skip


def luma_table(path: str) -> np.ndarray | None:
    """The JPEG's first quantisation table (table 0: luminance) in natural order, None if the file is
    not a JPEG or has none. Read from the DQT segments before the first scan."""
    with open(path, "rb") as fh:
        data = fh.read(1 << 20)
    if data[:2] != b"\xff\xd8":
        return None
    i = 2
    while i + 4 <= len(data) and data[i] == 0xFF:
        marker, length = data[i + 1], int.from_bytes(data[i + 2 : i + 4], "big")
        if marker == 0xDA:  # start of scan: no table before it
            return None
        if marker == 0xDB:
            j, end = i + 4, i + 2 + length
            while j < end:
                precision, table = data[j] >> 4, data[j] & 15
                size = 128 if precision else 64
                raw = data[j + 1 : j + 1 + size]
                vals = np.frombuffer(raw, ">u2" if precision else "u1").astype(np.float64)
                if table == 0 and vals.size == 64:
                    out = np.empty(64)
                    out[_ZIGZAG] = vals
                    return out
                j += 1 + size
        i += 2 + length
    return None


def jpeg_quality(table: np.ndarray) -> float:
    """The IJG quality whose scaled standard table is nearest ``table`` (64 entries in natural order,
    as :func:`luma_table`; least squares in log)."""
    table = np.asarray(table, np.float64)
    if table.shape != (64,) or not np.isfinite(table).all():
        raise ValueError(f"jpeg_quality: expected 64 finite quantisation steps, got shape {table.shape}")
    q = np.arange(1, 101)
    scale = np.where(q < 50, 5000.0 / q, 200.0 - 2.0 * q)
    tables = np.clip(np.floor((_IJG_LUMA[None, :] * scale[:, None] + 50.0) / 100.0), 1, 255)
    err = (np.log(tables) - np.log(np.maximum(table, 1.0))[None, :]) ** 2
    return float(q[int(np.argmin(err.sum(axis=1)))])


def block_edge_ratio(im: np.ndarray, share: float = 0.3) -> float:
    """Mean |grey-level step| across the 8-pixel block boundaries over the mean inside the blocks, both
    axes, in the ``share`` of the photo (grey levels, :func:`grey`) with the least local texture (a
    9 x 9 mean of the steps)."""
    import cv2

    across, inside = [], []
    for d in (np.abs(np.diff(im, axis=1)), np.abs(np.diff(im, axis=0)).T):
        calm = cv2.blur(d, (9, 9)) <= np.quantile(cv2.blur(d, (9, 9)), share)
        boundary = (np.arange(d.shape[1]) % 8 == 7)[None, :]
        across.append(d[calm & boundary])
        inside.append(d[calm & ~boundary])
    a, b = float(np.concatenate(across).mean()), float(np.concatenate(inside).mean())
    return a / b if b > 0 else float("nan")


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
        images = [grey(f) for f in files]
        s = np.concatenate([edge_sigmas(im) for im in images])
        if not len(s):
            print(f"{pattern}: no straight edge found", flush=True)
            continue
        q1, med, q3 = np.percentile(s, [25, 50, 75])
        jpeg = ""
        tables = [luma_table(f) for f in files]
        if all(t is not None for t in tables):
            quality = np.median([jpeg_quality(t) for t in tables])
            ratio = np.median([block_edge_ratio(im) for im in images])
            jpeg = f"; JPEG quality about {quality:.0f}, block edges {ratio:.2f}x the steps inside blocks"
        print(f"{pattern}: {len(s)} edges in {len(files)} photos, sigma median {med:.2f} px "
              f"(25/75 % {q1:.2f}/{q3:.2f}){jpeg}", flush=True)  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
