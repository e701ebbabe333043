"""Benchmark of the tie-point refinement (issue 19): orientation with and without LSM of the tie points.

Not a test. ``make bench BENCH=tiepoints`` (about 20 minutes on one core: four synthetic blocks and
copr, each oriented twice). Every block is oriented by ``orient_images`` twice from the same files,
``OrientConfig.refine_tie_points`` off and on (core/gcp/tiepoints.py: least-squares matching of every
tie-point observation against a master image at the working resolution, then the adjustment again),
and the two runs are printed side by side:

* the adjustment: sigma0 and the image RMS (pixels at full resolution);
* the check points: RMSE X/Y/Z/3-D (triangulated - given, metres);
* synthetic blocks (core/synthetic: exact cameras, GCPs and check points from the truth, the GCPs'
  image observations with 0.5 px noise): the cameras against the truth after the datum (the GCPs put
  the block in the truth's world frame): centre RMSE in metres and in nadir GSD, mean and largest
  rotation error in degrees;
* the refinement's own wall time (the LSM alone) and that of its whole step (reading the images at
  the working resolution, the LSM, the second adjustment).

On copr (41 photos of 2136x1424 with hand-held GNSS targets, /work/shared/data/copr or
``$TRUORTHO_BENCH_DATA/copr``; ``--no-copr`` skips it) there is no camera truth and the check points
are metre-level, so its check RMSE is weak evidence; sigma0 and the image RMS fall by construction
when observations are moved onto their master's match, so the camera errors of the synthetic blocks
are the figure that decides. The last lines give every figure's ratio refined/unrefined per block.

``--floor`` (seconds) prints, per synthetic block, the check RMSE with the **true** cameras: the
check points intersected from their own noisy image measurements (:func:`check_floor`). On the
four blocks it is 66-84 % of the unrefined run's check RMSE 3-D, so the check RMSE can move only in
the small part the orientation adds; the camera errors against the truth measure the refinement.
"""

from __future__ import annotations

import argparse
import glob
import math
import os
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

DATA = os.environ.get("TRUORTHO_BENCH_DATA", "/work/shared/data")


@dataclass
class Block:
    key: str
    title: str
    scene: dict = field(default_factory=dict)


#: The synthetic GCP/check blocks: nadir only and nadir+oblique, different seeds and parameters.
SYNTHETIC = (
    Block("A", "nadir only, seed 11", dict(n_oblique=0, seed=11)),
    Block(
        "B",
        "nadir only, seed 5, 8 m relief, 2x noise, JPEG 90, 1.5 deg attitude",
        dict(
            n_oblique=0, seed=5, terrain_relief=8.0, noise_sigma=2.0, jpeg_quality=90, attitude_sigma_deg=1.5
        ),
    ),
    Block("C", "nadir + 8 oblique, seed 3", dict(n_oblique=8, seed=3)),
    Block(
        "D",
        "nadir + 4 oblique at 30 deg, seed 7, 2x noise, JPEG 90",
        dict(n_oblique=4, oblique_tilt_deg=30.0, seed=7, noise_sigma=2.0, jpeg_quality=90),
    ),
)
#: Control common to the synthetic blocks.
CONTROL = dict(n_gcps=14, min_gcp_views=4, check_fraction=0.4, gcp_pixel_sigma=0.5)


class _Timed:
    """Wraps ``refine_tie_points`` to time the LSM alone (the pipeline imports it at call time)."""

    def __init__(self) -> None:
        import truortho.core.gcp.tiepoints as tp

        self.module = tp
        self.original = tp.refine_tie_points
        self.seconds = float("nan")

    def __enter__(self):
        def timed(*args, **kwargs):
            t = time.perf_counter()
            out = self.original(*args, **kwargs)
            self.seconds = time.perf_counter() - t
            return out

        self.module.refine_tie_points = timed
        return self

    def __exit__(self, *exc) -> None:
        self.module.refine_tie_points = self.original


def _orient(paths, gcps, crs, refine: bool, working_size: int, max_features: int, work: Path) -> dict:
    from truortho.core.sfm.pipeline import OrientConfig, orient_images

    cfg = OrientConfig(working_size=working_size, max_features=max_features, refine_tie_points=refine)
    with _Timed() as timer:
        t = time.perf_counter()
        run = orient_images(paths, gcps=gcps, crs=crs, config=cfg, work_dir=work)
        wall = time.perf_counter() - t
    data = run.report.data
    stats = data.get("stats") or {}
    return dict(
        orientation=run.orientation,
        sigma0=float((data.get("bundle") or {}).get("sigma0", math.nan)),
        rms=float((data.get("bundle") or {}).get("rms", math.nan)),
        check=dict(data.get("check_rmse") or {}),
        wall=wall,
        step=float((stats.get("timings") or {}).get("tie refinement", math.nan)),
        lsm=timer.seconds,
        refinement=stats.get("tie_refinement"),
    )


def _camera_errors(run: dict, truth) -> dict:
    """Centre RMSE (m) and rotation errors (deg) of the registered images against the truth."""
    o = run["orientation"]
    est = {im.name: im for im in o.images}
    names = [im.name for im in truth.images if im.name in est]
    if not names:
        return dict(n=0, centre=math.nan, rot_mean=math.nan, rot_max=math.nan)
    ce = o.world_centers()[[o.image_index()[n] for n in names]]
    ct = truth.world_centers()[[truth.image_index()[n] for n in names]]
    ang = []
    for n in names:
        R = np.asarray(est[n].R) @ np.asarray(truth.image(n).R).T
        ang.append(math.degrees(math.acos(float(np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0)))))
    return dict(
        n=len(names),
        centre=float(np.sqrt(np.mean(np.sum((ce - ct) ** 2, axis=1)))),
        rot_mean=float(np.mean(ang)),
        rot_max=float(np.max(ang)),
    )


def _row(label: str, a: str, b: str) -> str:
    return f"  {label:<34} {a:>22} {b:>22}"


def _print_block(title: str, runs: list[dict], gsd: float | None) -> dict:
    """The side-by-side table of one block; returns its figures (name -> (unrefined, refined))."""
    print(f"\n{title}")
    print(_row("", "unrefined", "refined"))
    fig: dict[str, tuple[float, float]] = {}

    def add(name: str, label: str, vals, fmt: str) -> None:
        fig[name] = (vals[0], vals[1])
        print(_row(label, *(format(v, fmt) for v in vals)))

    add("sigma0", "sigma0 [px]", [r["sigma0"] for r in runs], ".3f")
    add("image RMS", "image RMS [px]", [r["rms"] for r in runs], ".3f")
    chk = [r["check"] for r in runs]
    n_chk = chk[0].get("n", 0)
    print(
        _row(
            f"check RMSE X/Y/Z [m] ({n_chk} points)",
            *(
                f"{c.get('x', math.nan):.3f}/{c.get('y', math.nan):.3f}/{c.get('z', math.nan):.3f}"
                for c in chk
            ),
        )
    )
    for axis in ("x", "y", "z"):
        fig[f"check {axis.upper()}"] = tuple(c.get(axis, math.nan) for c in chk)  # type: ignore[assignment]
    add("check 3-D", "check RMSE 3-D [m]", [c.get("3d", math.nan) for c in chk], ".4f")
    if gsd is not None:
        cams = [r["cameras"] for r in runs]
        print(_row("registered images", *(str(c["n"]) for c in cams)))
        add("centre RMSE", "camera centre RMSE [m]", [c["centre"] for c in cams], ".4f")
        print(_row("camera centre RMSE [GSD]", *(f"{c['centre'] / gsd:.3f}" for c in cams)))
        add("rotation mean", "rotation error mean [deg]", [c["rot_mean"] for c in cams], ".4f")
        add("rotation max", "rotation error max [deg]", [c["rot_max"] for c in cams], ".4f")
    print(_row("orientation wall time [s]", *(f"{r['wall']:.1f}" for r in runs)))
    ref = runs[1]["refinement"] or {}
    print(
        f"  refinement: {ref.get('tried', 0):,} of {ref.get('observations', 0):,} observations matched, "
        f"{ref.get('refined', 0):,} accepted (median move {ref.get('median_move_px', math.nan):.3f} px, "
        f"median sigma {ref.get('median_sigma_px', math.nan):.3f} px); LSM {runs[1]['lsm']:.1f} s, "
        f"whole step (images, LSM, second adjustment) {runs[1]['step']:.1f} s"
    )
    return fig


def check_floor(orientation) -> dict:
    """Check-point RMSE (m) with the **true** cameras: each check point intersected from its own
    (noisy) image measurements by the rays of the exact orientation (least squares). No
    orientation can do better on average: this part of the check RMSE is the check points'
    measurement noise, which refining tie points does not touch."""
    from truortho.core.geometry import project_points
    from truortho.core.geometry.camera import pixel_to_ray

    o = orientation
    ims = {im.name: im for im in o.images}
    off = np.asarray(o.offset, dtype=np.float64)
    errs, px = [], []
    for g in o.gcps:
        if g.role != "check" or len(g.observations) < 2:
            continue
        A, rhs = np.zeros((3, 3)), np.zeros(3)
        X0 = np.asarray(g.xyz, dtype=np.float64) - off
        for name, u, v in g.observations:
            im = ims[name]
            cam = o.cameras[im.camera]
            px.append(float(np.hypot(*(project_points(X0[None], im.R, im.C, cam)[0] - (u, v)))))
            C, d = pixel_to_ray(np.array([[u, v]]), im.R, im.C, cam)
            d = np.asarray(d, dtype=np.float64).reshape(3) / np.linalg.norm(d)
            P = np.eye(3) - np.outer(d, d)
            A += P
            rhs += P @ np.asarray(C, dtype=np.float64).reshape(3)
        errs.append(np.linalg.solve(A, rhs) - X0)
    e = np.array(errs).reshape(-1, 3)
    r = np.sqrt((e**2).mean(axis=0)) if len(e) else np.full(3, math.nan)
    return {
        "n": len(e),
        "px": float(np.sqrt(np.mean(np.square(px)))) if px else math.nan,
        "xyz": r,
        "3d": float(np.sqrt((e**2).sum(axis=1).mean())) if len(e) else math.nan,
    }


def run_floor(block: Block) -> None:
    from truortho.core.synthetic import SceneConfig, make_scene

    f = check_floor(make_scene(SceneConfig(**{**CONTROL, **block.scene})).orientation)
    x, y, z = f["xyz"]
    head = f"{block.key}: {f['n']} check points measured {f['px']:.3f} px RMS off their truth"
    print(f"{head}; check RMSE with the true cameras X/Y/Z {x:.3f}/{y:.3f}/{z:.3f} m, 3-D {f['3d']:.4f} m")


def run_synthetic(block: Block, working_size: int) -> dict:
    from truortho.core.formats.gcplist import read_gcp_list
    from truortho.core.synthetic import SceneConfig, make_scene

    cfg = SceneConfig(**{**CONTROL, **block.scene})
    scene = make_scene(cfg)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        scene.write(folder)
        crs, gcps = read_gcp_list(folder / "gcp_list.txt")
        roles = {g.name: g.role for g in scene.orientation.gcps}
        for g in gcps:
            g.role = roles[g.name]
        paths = sorted(str(folder / im.name) for im in scene.orientation.images)  # PNG, or JPEG files
        runs = []
        for refine in (False, True):
            r = _orient(paths, gcps, crs, refine, working_size, 8000, folder / f"work{int(refine)}")
            r["cameras"] = _camera_errors(r, scene.orientation)
            runs.append(r)
    n_gcp = sum(g.role == "gcp" for g in gcps)
    w, h = cfg.image_size
    title = (
        f"{block.key}: {block.title}; {len(paths)} images of {w}x{h}, GSD {cfg.gsd:.3f} m, "
        f"{n_gcp} GCPs + {len(gcps) - n_gcp} check points (GCP image noise {cfg.gcp_pixel_sigma} px), "
        f"working size {working_size}"
    )
    return _print_block(title, runs, cfg.gsd)


def run_copr(working_size: int) -> dict | None:
    from truortho.core.formats.gcplist import read_gcp_list

    root = os.path.join(DATA, "copr")
    paths = sorted(
        glob.glob(os.path.join(root, "images", "*.jpg")) + glob.glob(os.path.join(root, "images", "*.JPG"))
    )
    if not paths:
        print(f"\ncopr: no images under {root}; skipped")
        return None
    crs, gcps = read_gcp_list(os.path.join(root, "gcp_list.txt"))
    # as bench_orientation.run_ours: every other target a check point; averaged hand-held GNSS,
    # metre-level in plan, heights not surveyed (plan-only control)
    for k, g in enumerate(sorted(gcps, key=lambda g: g.name)):
        g.role = "check" if k % 2 else "gcp"
        g.sigma = np.array([3.0, 3.0, 50.0])
    with tempfile.TemporaryDirectory() as tmp:
        runs = [
            _orient(paths, gcps, crs, refine, working_size, 8000, Path(tmp) / f"w{int(refine)}")
            for refine in (False, True)
        ]
    n = len(runs[1]["orientation"].images)
    title = (
        f"copr: {len(paths)} photos of 2136x1424 ({n} registered), hand-held GNSS targets "
        f"(every other one a check point, metre-level: weak evidence), working size {working_size}"
    )
    return _print_block(title, runs, None)


def _summary(figures: dict[str, dict]) -> None:
    keys = list(figures)
    names = [
        "sigma0",
        "image RMS",
        "check X",
        "check Y",
        "check Z",
        "check 3-D",
        "centre RMSE",
        "rotation mean",
        "rotation max",
    ]
    print("\nratio refined / unrefined (below 1: the refinement lowered the figure)")
    print(f"  {'figure':<16}" + "".join(f"{k:>8}" for k in keys) + f"{'lower in':>12}")
    for name in names:
        vals = []
        for k in keys:
            a, b = figures[k].get(name, (math.nan, math.nan))
            vals.append(b / a if a and math.isfinite(a) and math.isfinite(b) else math.nan)
        known = [v for v in vals if math.isfinite(v)]
        if not known:
            continue
        lower = sum(v < 1.0 for v in known)
        print(
            f"  {name:<16}"
            + "".join(f"{v:>8.3f}" if math.isfinite(v) else f"{'-':>8}" for v in vals)
            + f"{f'{lower} of {len(known)}':>12}"
        )


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--blocks", default=",".join(b.key for b in SYNTHETIC), help="synthetic blocks to run")
    ap.add_argument("--no-copr", action="store_true", help="skip copr")
    ap.add_argument("--working-size", type=int, default=640, help="synthetic blocks (640: full resolution)")
    ap.add_argument("--copr-working-size", type=int, default=2000, help="as bench_orientation")
    ap.add_argument("--floor", action="store_true", help="only the check RMSE with the true cameras of "
                    "the synthetic blocks (seconds; use without --write-docs)")  # fmt: skip
    a = ap.parse_args()
    if a.floor:
        for block in SYNTHETIC:
            run_floor(block)
        return 0
    t0 = time.perf_counter()
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    threads = ", ".join(f"{k}={os.environ.get(k, 'unset')}" for k in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS"))
    print(f"process allowed on {cores} core(s) of {os.cpu_count()}; {threads}")
    want = {k.strip() for k in a.blocks.split(",") if k.strip()}
    figures: dict[str, dict] = {}
    for block in SYNTHETIC:
        if block.key in want:
            figures[block.key] = run_synthetic(block, a.working_size)
    if not a.no_copr:
        fig = run_copr(a.copr_working_size)
        if fig is not None:
            figures["copr"] = fig
    if figures:
        _summary(figures)
    print(f"\ntotal {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from _docs import run_main

    sys.exit(run_main(main, "tiepoints", "Tie-point refinement (LSM of the tie points, issue 19)"))
