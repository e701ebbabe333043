"""Benchmark of the bundle adjustment against pycolmap (Ceres), when installed.

Not a test. Run from the repository root with the project's interpreter::

    PYTHONPATH=/path/containing/truortho python bench/bench_bundle.py [--images 100] [--points 30000]

A synthetic aerial block (a grid of nadir-ish images over a 3-D point field,
Brown distortion, 0.5 px Gaussian noise; poses perturbed by ~1 deg / 1 m,
points by 1 m, f by 2 %, k1 by 0.02) is adjusted with self-calibration of
f, cx, cy, k1, k2, p1, p2 by TruOrtho and by pycolmap's Ceres bundle
adjuster (OPENCV camera model, +0.5 px principal point / observation shift,
same perturbed start, gauge: TruOrtho's minimal constraints vs COLMAP's
TWO_CAMS_FROM_WORLD). Each engine runs in its own subprocess so the peak
resident memory (``core.memory.peak_rss_mb``) is its own.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

FTOL = 1e-6
MAX_IT = 100


def make_problem(n_images: int, n_points: int, seed: int = 0) -> dict:
    from truortho.core.geometry import Camera, opk_to_matrix, project_points
    from truortho.core.geometry.rotation import axis_angle_to_matrix

    rng = np.random.default_rng(seed)
    cam = Camera(4000, 3000, 3000.0, 3000.0, 2005.0, 1495.0, -0.08, 0.03, 0.0, 2e-4, -1e-4)
    nx = int(round(np.sqrt(n_images)))
    Rs, Cs = [], []
    for k in range(n_images):
        s, c = divmod(k, nx)
        Cs.append(
            [c * 48.0 + rng.uniform(-3, 3), s * 38.0 + rng.uniform(-3, 3), 100.0 + rng.uniform(-10, 10)]
        )
        Rs.append(opk_to_matrix(*rng.uniform(-5, 5, 2), rng.choice([0.0, 180.0]), degrees=True))
    Rs, Cs = np.array(Rs), np.array(Cs)
    lo, hi = Cs.min(0) - 40, Cs.max(0) + 40
    X = np.column_stack(
        [
            rng.uniform(lo[0], hi[0], n_points),
            rng.uniform(lo[1], hi[1], n_points),
            rng.uniform(0, 25, n_points),
        ]
    )
    oi, op, xy = [], [], []
    for i in range(n_images):
        uv = project_points(X, Rs[i], Cs[i], cam)
        ok = (uv[:, 0] > 0) & (uv[:, 0] < cam.width - 1) & (uv[:, 1] > 0) & (uv[:, 1] < cam.height - 1)
        idx = np.flatnonzero(ok)
        oi.append(np.full(len(idx), i))
        op.append(idx)
        xy.append(uv[idx])
    oi, op, xy = np.concatenate(oi), np.concatenate(op), np.concatenate(xy)
    keep = np.bincount(op, minlength=n_points)[op] >= 2
    oi, op, xy = oi[keep], op[keep], xy[keep] + rng.normal(0, 0.5, (int(keep.sum()), 2))
    used = np.unique(op)
    remap = np.full(n_points, -1)
    remap[used] = np.arange(len(used))
    op, X = remap[op], X[used]
    intr = cam.params.copy()
    intr[:2] *= 1.02
    intr[4] += 0.02
    R0 = np.array([axis_angle_to_matrix(rng.normal(0, np.radians(1) / np.sqrt(3), 3)) @ R for R in Rs])
    return dict(
        width=cam.width,
        height=cam.height,
        true_intr=cam.params,
        true_C=Cs,
        true_R=Rs,
        true_X=X,
        intr=intr,
        R=R0,
        C=Cs + rng.normal(0, 1 / np.sqrt(3), Cs.shape),
        X=X + rng.normal(0, 1 / np.sqrt(3), X.shape),
        oi=oi,
        op=op,
        xy=xy,
    )


def _rss_mb() -> float:
    from truortho.core.memory import peak_rss_mb  # the one peak-memory helper (kB/bytes/Windows)

    peak = peak_rss_mb()
    return float("nan") if peak is None else peak


def run_ours(d: dict) -> dict:
    from truortho.core.sfm.bundle import BundleConfig, BundleProblem, bundle_adjust

    def problem(n=None):
        sl = slice(0, n)
        return BundleProblem(
            d["intr"][None],
            np.zeros(len(d["R"]), int),
            d["R"],
            d["C"],
            d["X"],
            d["oi"][sl],
            d["op"][sl],
            d["xy"][sl],
            refine_intrinsics=("f", "cx", "cy", "k1", "k2", "p1", "p2"),
        )

    cfg = BundleConfig(max_iterations=MAX_IT, function_tolerance=FTOL, compute_covariance=False)
    t = time.perf_counter()
    bundle_adjust(problem(5000), BundleConfig(max_iterations=2))  # JIT / cache load
    warm = time.perf_counter() - t
    base = _rss_mb()
    t = time.perf_counter()
    res = bundle_adjust(problem(), cfg)
    total = time.perf_counter() - t
    from truortho.core.sfm.similarity import estimate_similarity

    sim = estimate_similarity(res.centers, d["true_C"])
    err = np.linalg.norm(sim.apply(res.centers) - d["true_C"], axis=1)
    return dict(
        engine="truortho",
        total_s=total,
        warmup_s=warm,
        iterations=res.n_iterations,
        per_iteration_s=float(np.mean(res.iteration_times)),
        reason=res.reason,
        final_cost=res.cost_history[-1],
        rms_px=res.rms,
        sigma0=res.sigma0,
        max_center_error_m=float(err.max()),
        fx=float(res.intrinsics[0, 0]),
        rss_before_mb=base,
        peak_rss_mb=_rss_mb(),
    )


def run_pycolmap(d: dict) -> dict:
    import pycolmap

    base = _rss_mb()
    t = time.perf_counter()
    rec = pycolmap.Reconstruction()
    p = d["intr"]
    cam = pycolmap.Camera(
        model="OPENCV",
        width=int(d["width"]),
        height=int(d["height"]),
        camera_id=1,
        params=[p[0], p[1], p[2] + 0.5, p[3] + 0.5, p[4], p[5], p[7], p[8]],
    )
    rec.add_camera_with_trivial_rig(cam)
    oi, op, xy = d["oi"], d["op"], d["xy"]
    order = np.argsort(oi, kind="stable")
    starts = np.searchsorted(oi[order], np.arange(len(d["R"]) + 1))
    point2d_idx = np.empty(len(oi), dtype=np.int64)
    for i in range(len(d["R"])):
        sel = order[starts[i] : starts[i + 1]]
        point2d_idx[sel] = np.arange(len(sel))
        img = pycolmap.Image(name=f"img{i}", keypoints=xy[sel] + 0.5, camera_id=1, image_id=i + 1)
        R, C = d["R"][i], d["C"][i]
        rec.add_image_with_trivial_frame(img, pycolmap.Rigid3d(np.hstack([R, (-R @ C)[:, None]])))
    by_pt = np.argsort(op, kind="stable")
    pstarts = np.searchsorted(op[by_pt], np.arange(len(d["X"]) + 1))
    for j in range(len(d["X"])):
        sel = by_pt[pstarts[j] : pstarts[j + 1]]
        track = pycolmap.Track()
        for o in sel:
            track.add_element(int(oi[o]) + 1, int(point2d_idx[o]))
        rec.add_point3D(d["X"][j], track)
    build = time.perf_counter() - t
    opts = pycolmap.BundleAdjustmentOptions()
    opts.refine_focal_length = opts.refine_principal_point = opts.refine_extra_params = True
    opts.print_summary = False
    so = opts.ceres.solver_options
    so.function_tolerance, so.gradient_tolerance, so.parameter_tolerance = FTOL, 1e-10, 1e-10
    so.max_num_iterations, so.num_threads = MAX_IT, os.cpu_count() or 1
    config = pycolmap.BundleAdjustmentConfig()
    for i in range(len(d["R"])):
        config.add_image(i + 1)
    config.fix_gauge(pycolmap.BundleAdjustmentGauge.TWO_CAMS_FROM_WORLD)
    adjuster = pycolmap.create_default_bundle_adjuster(opts, config, rec)
    t = time.perf_counter()
    summary = adjuster.solve()
    total = time.perf_counter() - t
    cs = summary.ceres_summary if hasattr(summary, "ceres_summary") else None
    brief = summary.brief_report()
    n_it = int(brief.split("Iterations:")[1].split(",")[0]) if "Iterations:" in brief else -1
    rec.update_point_3d_errors()
    centers = np.array([rec.image(i + 1).projection_center() for i in range(len(d["R"]))])
    from truortho.core.sfm.similarity import estimate_similarity

    sim = estimate_similarity(centers, d["true_C"])
    err = np.linalg.norm(sim.apply(centers) - d["true_C"], axis=1)
    return dict(
        engine=f"pycolmap {pycolmap.__version__}",
        total_s=total,
        build_s=build,
        iterations=n_it,
        per_iteration_s=total / max(n_it, 1),
        reason=str(summary.termination_type),
        final_cost=float(cs.final_cost) if cs is not None else float("nan"),
        rms_px=float(rec.compute_mean_reprojection_error()),
        max_center_error_m=float(err.max()),
        fx=float(rec.camera(1).params[0]),
        brief=brief,
        linear_solver=str(cs.linear_solver_type_used) if cs is not None else "",
        rss_before_mb=base,
        peak_rss_mb=_rss_mb(),
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--images", type=int, default=100)
    ap.add_argument("--points", type=int, default=30000)
    ap.add_argument("--engine", choices=["ours", "pycolmap"], help=argparse.SUPPRESS)
    ap.add_argument("--data", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.engine:
        d = dict(np.load(a.data))
        out = run_ours(d) if a.engine == "ours" else run_pycolmap(d)
        print(json.dumps(out))
        return
    d = make_problem(a.images, a.points)
    print(
        f"problem: {len(d['R'])} images, {len(d['X'])} points, {len(d['oi'])} observations "
        f"(mean track {len(d['oi']) / len(d['X']):.2f}), {os.cpu_count()} CPUs"
    )
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "problem.npz")
        np.savez(path, **d)
        for engine in ("ours", "pycolmap"):
            proc = subprocess.run(
                [sys.executable, __file__, "--engine", engine, "--data", path], capture_output=True, text=True
            )
            if proc.returncode != 0:
                tail = (proc.stderr.strip().splitlines() or ["?"])[-1]
                print(f"{engine}: not run ({tail})")
                continue
            results[engine] = json.loads(proc.stdout.strip().splitlines()[-1])
            print(json.dumps(results[engine], indent=1))
    if len(results) == 2:
        o, c = results["ours"], results["pycolmap"]
        print(
            f"time to convergence ours/pycolmap: {o['total_s']:.2f} s / {c['total_s']:.2f} s "
            f"= {o['total_s'] / c['total_s']:.2f}"
        )
        print(
            f"time per iteration ours/pycolmap: {o['per_iteration_s']:.3f} s / {c['per_iteration_s']:.3f} s "
            f"= {o['per_iteration_s'] / c['per_iteration_s']:.2f}"
        )
        print(
            f"peak RSS ours/pycolmap: {o['peak_rss_mb']:.0f} MB / {c['peak_rss_mb']:.0f} MB "
            f"= {o['peak_rss_mb'] / c['peak_rss_mb']:.2f}"
        )


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from _docs import run_main

    TITLE = "Bundle adjustment against pycolmap (Ceres)"
    sys.exit(run_main(main, "bundle", TITLE, peers=("pycolmap",)))
