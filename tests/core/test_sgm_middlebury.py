"""match_rectified against ground truth on Middlebury teddy and tsukuba, side by side with OpenCV.

Bad-pixel rate: ``|d - gt| > 1`` px over the pixels with ground truth (teddy
``disp2.pgm``: value / 4, 0 unknown; tsukuba ``groundtruth.png``: value / 16,
0 unknown = the 18-pixel border); **a NaN (no disparity) counts as bad, for
both matchers**.

The peer, with settings comparable to ours (``pytest -s`` prints the table):
OpenCV StereoSGBM ``MODE_HH`` (8 paths, as ours), the same luminance input
as 8-bit grey, the same disparity range, ``blockSize = 2 radius + 1`` (5),
OpenCV's recommended ``P1 = 8 bs^2``, ``P2 = 32 bs^2`` (P2 = 4 P1 relative to
its cost range; ours are COST_MAX/4 and 2 COST_MAX, reasoned in
``core/sgm/aggregation.py``, not fitted to these pairs), ``uniquenessRatio``
5 (our ``uniqueness`` 0.95), no speckle filter and no left-right check
(neither is on in ours). OpenCV marks the leftmost ``minDisparity +
numDisparities`` columns invalid; to not count that against it, both images
are padded on the left by ``num_disp`` replicated columns and the output is
cropped (the same border rule as our ``border="replicate"``). Its result is
scored raw and after our 3x3 NaN-aware median (our post-processing), and
the better of the two is the reference. ``MODE_SGBM_3WAY`` (3 paths) is
printed for information.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

cv2 = pytest.importorskip("cv2")

from truortho.core.imagery import luminance  # noqa: E402
from truortho.core.sgm import DEFAULT_RADIUS, DEFAULT_UNIQUENESS, match_rectified, median_filter  # noqa: E402

DATA = Path(os.environ.get("TRUORTHO_DATA", "")) / "stereo-middlebury"

PAIRS = {
    # name: (left, right, ground truth, scale, num_disp)
    "teddy": ("teddy/im2.png", "teddy/im6.png", "teddy/disp2.pgm", 4.0, 64),
    "tsukuba": ("tsukuba/left.png", "tsukuba/right.png", "tsukuba/groundtruth.png", 16.0, 16),
}


def _load(name):
    lf, rf, gf, scale, nd = PAIRS[name]
    paths = [DATA / f for f in (lf, rf, gf)]
    if not all(p.is_file() for p in paths):
        pytest.skip(f"Middlebury pair {name} not found under {DATA}")
    left = cv2.imread(str(paths[0]), cv2.IMREAD_COLOR)[:, :, ::-1]
    right = cv2.imread(str(paths[1]), cv2.IMREAD_COLOR)[:, :, ::-1]
    # tsukuba's ground truth is a palette PNG with an identity grey palette
    gt = cv2.imread(str(paths[2]), cv2.IMREAD_GRAYSCALE).astype(np.float32) / scale
    return np.ascontiguousarray(left), np.ascontiguousarray(right), gt, nd


def bad_rate(d: np.ndarray, gt: np.ndarray) -> tuple[float, float]:
    """(% bad over ground-truth pixels with NaN counted bad, % NaN)."""
    m = gt > 0
    err = np.abs(d - gt)
    bad = ~(err <= 1.0)  # NaN -> bad
    return 100.0 * float(bad[m].mean()), 100.0 * float(np.isnan(d[m]).mean())


def opencv_sgbm(left, right, num_disp, mode, bs, uniqueness_ratio):
    a = np.clip(np.rint(luminance(left) * 255), 0, 255).astype(np.uint8)
    b = np.clip(np.rint(luminance(right) * 255), 0, 255).astype(np.uint8)
    sgbm = cv2.StereoSGBM_create(
        minDisparity=0,
        numDisparities=num_disp,
        blockSize=bs,
        P1=8 * bs * bs,
        P2=32 * bs * bs,
        disp12MaxDiff=-1,
        uniquenessRatio=uniqueness_ratio,
        speckleWindowSize=0,
        mode=mode,
    )
    pad = num_disp
    ap = cv2.copyMakeBorder(a, 0, 0, pad, 0, cv2.BORDER_REPLICATE)
    bp = cv2.copyMakeBorder(b, 0, 0, pad, 0, cv2.BORDER_REPLICATE)
    d = sgbm.compute(ap, bp)[:, pad:].astype(np.float32) / 16.0
    d[d < 0] = np.nan
    return d


@pytest.mark.slow
def test_match_rectified_beats_opencv_sgbm_on_middlebury():
    bs = 2 * DEFAULT_RADIUS + 1
    ur = int(round(100 * (1 - DEFAULT_UNIQUENESS)))
    rows = []
    results = {}
    for name in PAIRS:
        left, right, gt, nd = _load(name)
        ours = match_rectified(left, right, 0, nd)
        assert ours.shape == gt.shape and ours.dtype == np.float32
        hh = opencv_sgbm(left, right, nd, cv2.STEREO_SGBM_MODE_HH, bs, ur)
        way3 = opencv_sgbm(left, right, nd, cv2.STEREO_SGBM_MODE_SGBM_3WAY, bs, ur)
        r_ours = bad_rate(ours, gt)
        r_hh = bad_rate(hh, gt)
        r_hh_med = bad_rate(median_filter(hh, 3), gt)
        r_3w = bad_rate(way3, gt)
        results[name] = (r_ours[0], min(r_hh[0], r_hh_med[0]))
        rows.append((name, r_ours, r_hh, r_hh_med, r_3w))
    print("\nMiddlebury bad-pixel rate (|d - gt| > 1 px over ground-truth pixels, NaN counted bad)")
    print(f"{'pair':8} {'TruOrtho':>19} {'OpenCV HH':>19} {'HH + median 3':>19} {'(3WAY, 3 paths)':>19}")
    for name, *rs in rows:
        print(f"{name:8} " + " ".join(f"{b:5.2f}% ({n:3.1f}% NaN)".rjust(19) for b, n in rs))
    for name, (ours, peer) in results.items():
        assert ours <= peer, f"{name}: {ours:.2f}% bad vs OpenCV StereoSGBM {peer:.2f}%"
        assert ours < 25.0  # and not merely a bad peer
