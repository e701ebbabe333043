"""Benchmark of the SGM machinery (core/sgm) against OpenCV StereoSGBM.

Not a test. Run from the repository root: ``make bench BENCH=sgm``
(or ``python -P bench/bench_sgm.py [--size 1024] [--disp 128] [--reps 5]``).

Aggregation: :func:`truortho.core.sgm.aggregate` (8 paths, uint16 costs and
S) on a ``size x size x disp`` cost volume against OpenCV StereoSGBM on a
pair of ``size x (size + disp)`` images, so that both handle ``size x size``
cells times ``disp`` disparities (OpenCV computes costs only where all
disparities fit). Throughput = cells x levels x paths per second: 8 paths for
ours, 3 for ``MODE_SGBM_3WAY`` (``cv2.setNumThreads(2)``), 8 for ``MODE_HH``
(single-threaded in OpenCV; printed for information). OpenCV's time
**includes its cost computation** (block-matching BT costs) and, for 3WAY,
needs no full S volume; ours is the aggregation alone into a full S (which
OSGM needs for its selection), so the comparison is conservative for us.

Cost: :func:`truortho.core.sgm.multi_image_cost` on ``n`` slices of
``size x size`` cells per level (one OSGM Z plane per call); throughput =
cells x levels x images per second, per measure.

Both peers run interleaved ``--reps`` times; the medians and the median of
the per-round ratios are printed. The machine is shared: timings are
indicative only. Because wall-clock times on a loaded machine mostly measure
the scheduler, the same comparison is also made per core: one thread each
(``numba.set_num_threads(1)``, ``cv2.setNumThreads(1)``) timed by CPU time.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np


def _median(x):
    return float(np.median(np.asarray(x, dtype=np.float64)))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--disp", type=int, default=128)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--images", type=int, default=5)
    ap.add_argument("--cost-size", type=int, default=512)
    args = ap.parse_args()

    import cv2

    from truortho.core.sgm import COST_MAX, aggregate, multi_image_cost

    cv2.setNumThreads(2)
    n, nd = args.size, args.disp
    rng = np.random.default_rng(0)
    threads = os.environ.get("NUMBA_NUM_THREADS", "default")
    print(f"numba threads: {threads}, OpenCV threads: 2, load average {os.getloadavg()[0]:.1f}")

    # ---------------------------------------------------------------- aggregation
    cost = rng.integers(0, COST_MAX + 1, (n, n, nd), dtype=np.uint16)
    tex = cv2.GaussianBlur((rng.random((n, n + nd)) * 255).astype(np.float32), (0, 0), 1.0)
    left = np.clip(tex, 0, 255).astype(np.uint8)
    right = np.roll(left, -17, axis=1)
    sgbm3 = cv2.StereoSGBM_create(0, nd, 5, P1=200, P2=800, mode=cv2.STEREO_SGBM_MODE_SGBM_3WAY)
    sgbmh = cv2.StereoSGBM_create(0, nd, 5, P1=200, P2=800, mode=cv2.STEREO_SGBM_MODE_HH)
    aggregate(cost[:16, :16].copy())  # compile
    sgbm3.compute(left[:64], right[:64])
    work = n * n * nd
    t_ours, t_cv3, ratios = [], [], []
    for _ in range(args.reps):
        t0 = time.perf_counter()
        S = aggregate(cost)
        t1 = time.perf_counter()
        del S
        sgbm3.compute(left, right)
        t2 = time.perf_counter()
        t_ours.append(t1 - t0)
        t_cv3.append(t2 - t1)
        ratios.append((work * 8 / (t1 - t0)) / (work * 3 / (t2 - t1)))
    t0 = time.perf_counter()
    sgbmh.compute(left, right)
    t_hh = time.perf_counter() - t0
    print(f"\naggregation, {n} x {n} cells x {nd} levels (medians of {args.reps} interleaved rounds)")
    to, t3 = _median(t_ours), _median(t_cv3)
    print(f"  TruOrtho aggregate, 8 paths      {to:7.3f} s  {work * 8 / to / 1e9:6.2f} G/s")
    print(f"  OpenCV SGBM_3WAY, 3 paths, +cost {t3:7.3f} s  {work * 3 / t3 / 1e9:6.2f} G/s")
    hh = work * 8 / t_hh / 1e9
    print(f"  OpenCV HH, 8 paths, +cost        {t_hh:7.3f} s  {hh:6.2f} G/s  (1 thread; info)")
    print(f"  ratio of throughputs (ours / 3WAY), median per round: {_median(ratios):.2f}")

    import numba

    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    cv2.setNumThreads(1)
    c_ours, c_cv3, c_ratio = [], [], []
    for _ in range(args.reps):
        t0 = time.process_time()
        S = aggregate(cost)
        t1 = time.process_time()
        del S
        sgbm3.compute(left, right)
        t2 = time.process_time()
        c_ours.append(t1 - t0)
        c_cv3.append(t2 - t1)
        c_ratio.append((work * 8 / (t1 - t0)) / (work * 3 / (t2 - t1)))
    numba.set_num_threads(threads)
    cv2.setNumThreads(2)
    co, c3 = _median(c_ours), _median(c_cv3)
    print("  per core (1 thread each, CPU time):")
    print(f"    TruOrtho aggregate, 8 paths      {co:7.3f} s  {work * 8 / co / 1e9:6.2f} G/s")
    print(f"    OpenCV SGBM_3WAY, 3 paths, +cost {c3:7.3f} s  {work * 3 / c3 / 1e9:6.2f} G/s")
    print(f"    ratio (ours / 3WAY), median per round: {_median(c_ratio):.2f}")
    del cost

    # ---------------------------------------------------------------- cost
    m, k = args.cost_size, args.images
    base = cv2.GaussianBlur((rng.random((m + 8, m + 8)) * 255).astype(np.float32), (0, 0), 1.0)
    slices = np.stack([(0.8 + 0.1 * i) * base[i : i + m, 0:m] + 3 * i for i in range(k)]).astype(np.float32)
    slices[0, : m // 4, : m // 4] = np.nan
    levels = 8
    print(f"\ncost, {m} x {m} cells x {levels} levels x {k} images")
    print(f"  {'measure':9s} {'wall':>8s} {'(2 threads)':>28s} {'CPU, 1 thread':>36s}")
    for measure in ("gradient", "ncc", "census"):
        multi_image_cost(slices[:, :32, :32], 2, measure=measure)
        walls, cpus = [], []
        for _ in range(max(1, args.reps // 2)):
            t0 = time.perf_counter()
            for _lev in range(levels):
                multi_image_cost(slices, 2, measure=measure)
            walls.append(time.perf_counter() - t0)
            numba.set_num_threads(1)
            t0 = time.process_time()
            for _lev in range(levels):
                multi_image_cost(slices, 2, measure=measure)
            cpus.append(time.process_time() - t0)
            numba.set_num_threads(threads)
        tw, tc = _median(walls), _median(cpus)
        rate = m * m * levels * k / 1e6
        print(
            f"  {measure:9s} {tw:7.3f} s {rate / tw:8.1f} M cell-level-images/s"
            f" {tc:7.3f} s {rate / tc:8.1f} M cell-level-images/s"
        )


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from _docs import run_main

    TITLE = "SGM kernels against OpenCV"
    sys.exit(run_main(main, "sgm", TITLE, peers=("cv2",)))
