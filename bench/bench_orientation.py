"""Benchmark of image orientation against pycolmap's incremental pipeline, when installed.

Not a test. Run from the repository root with the project's interpreter::

    source scripts/env.sh
    python -P bench/bench_orientation.py [--datasets fountain,fountain-k,copr] [--working-size 2000]

Datasets (under ``$TRUORTHO_BENCH_DATA``, default ``/work/shared/data``):

* ``fountain``: fountain-P11 (11 images, 3072 x 2048), no interior orientation given:
  TruOrtho self-calibrates from its default prior, pycolmap uses one SIMPLE_RADIAL camera;
* ``fountain-k``: fountain-P11 with the calibration matrix ``images/K.txt``: TruOrtho gets it as
  CAMERA file, pycolmap one PINHOLE camera with the same K (principal point + 0.5 px for
  COLMAP's pixel-corner convention). Both engines keep their default refinement of the intrinsics;
* ``copr``: 41 drone images; TruOrtho with the GCPs of ``gcp_list.txt`` (every second target, by
  name, a check point; plan-only control with sigma_xy = 3 m (averaged hand-held GNSS) and
  sigma_z = 50 m (heights are 0),
  pycolmap without GCPs (one SIMPLE_RADIAL camera): registration, time and memory only.

For fountain-P11 the estimated camera centres are aligned to the ground truth
(``gt_dense_cameras``) by a 7-parameter similarity; reported are the centre RMSE after the
alignment (m) and the rotation error per image (deg, mean and max). Both engines detect SIFT
features at the same working size (larger image side, ``--working-size``) with at most the same
number of features; pycolmap matches exhaustively (its default options otherwise) and runs its
incremental mapper. pycolmap is kept to 2 threads. Each engine runs in its own subprocess with
fresh temporary work folders (no feature caches carried over), so its wall time and peak resident
memory (``resource.getrusage``, self + children) are its own. TruOrtho's numba code is compiled
once and cached in ``~/.cache/truortho/numba``, as for users.

The table also gives TruOrtho's sigma0 of the final adjustment and how many images were
registered by guided matching (weakly connected images, ``core/sfm/guided.py``).
A Markdown table per dataset is printed; the results are also written (merged by dataset) to
``bench/results/orientation.json``.
"""

from __future__ import annotations

import argparse
import glob
import json
import os
import platform
import resource
import shutil
import subprocess
import sys
import tempfile
import time
import traceback

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.environ.get("TRUORTHO_BENCH_DATA", "/work/shared/data")
DATASETS = ("fountain", "fountain-k", "copr")
ENGINES = ("ours", "pycolmap")
MAX_FEATURES = 8000
THREADS = 2


def dataset_info(name: str) -> dict:
    """Image folder, image paths, and what the dataset provides."""
    if name in ("fountain", "fountain-k"):
        root = os.path.join(DATA, "fountain-P11")
        image_dir = os.path.join(root, "images")
        return dict(
            name=name,
            image_dir=image_dir,
            paths=sorted(glob.glob(os.path.join(image_dir, "*.jpg"))),
            k_file=os.path.join(image_dir, "K.txt") if name == "fountain-k" else None,
            gt_dir=os.path.join(root, "gt_dense_cameras"),
            gcp_file=None,
        )
    if name == "copr":
        root = os.path.join(DATA, "copr")
        image_dir = os.path.join(root, "images")
        return dict(
            name=name,
            image_dir=image_dir,
            paths=sorted(
                glob.glob(os.path.join(image_dir, "*.jpg")) + glob.glob(os.path.join(image_dir, "*.JPG"))
            ),
            k_file=None,
            gt_dir=None,
            gcp_file=os.path.join(root, "gcp_list.txt"),
        )
    raise SystemExit(f"unknown dataset {name!r}; known: {', '.join(DATASETS)}")


def _peak_rss_mb() -> float:
    self_ = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    children = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return (self_ + children) / 1024.0  # Linux: kB


# --------------------------------------------------------------------------------------------
# engines (each in its own subprocess)


def run_ours(ds: dict, working_size: int, work_dir: str) -> dict:
    t0 = time.perf_counter()
    from truortho.core.sfm.pipeline import OrientConfig, orient_images

    gcps, crs = None, None
    if ds["gcp_file"]:
        from truortho.core.formats.gcplist import read_gcp_list

        crs, gcps = read_gcp_list(ds["gcp_file"])
        for k, g in enumerate(sorted(gcps, key=lambda g: g.name)):
            g.role = "check" if k % 2 else "gcp"
            # The target positions are averaged hand-held GNSS (GPS_average.txt): metre-level in plan;
            # the heights are 0, not surveyed: plan-only control.
            g.sigma = np.array([3.0, 3.0, 50.0])
    t = time.perf_counter()
    run = orient_images(
        ds["paths"],
        camera_file=ds["k_file"],
        gcps=gcps,
        crs=crs,
        config=OrientConfig(working_size=working_size, max_features=MAX_FEATURES),
        work_dir=work_dir,
        progress=None,
    )
    wall = time.perf_counter() - t
    o = run.orientation
    data = run.report.data
    bundle = data.get("bundle") or {}
    out = dict(
        engine="truortho",
        wall_s=wall,
        import_s=t - t0,
        n_images=len(ds["paths"]),
        registered=len(o.images),
        poses={im.name: dict(R=np.asarray(im.R).tolist(), C=np.asarray(im.C).tolist()) for im in o.images},
        n_points=len(o.points.xyz) if o.points is not None else 0,
        sigma0=_float(bundle.get("sigma0")),
        rms_px=_float(bundle.get("rms")),
        cameras={k: repr(c) for k, c in o.cameras.items()},
        summary=str(run.report.summary),
    )
    if ds["gcp_file"]:
        out["check_rmse"] = {k: _float(v) for k, v in (data.get("check_rmse") or {}).items()}
    guided = (data.get("stats") or {}).get("reconstruction", {}).get("guided", [])
    out["guided"] = [
        {k: e.get(k) for k in ("image", "partner", "pair_points", "guided_inliers", "rms_px")}
        | {"log10_nfa": (e.get("scale_search") or {}).get("log10_nfa")}
        for e in guided
        if e.get("registered")
    ]
    out["peak_rss_mb"] = _peak_rss_mb()
    return out


def run_pycolmap(ds: dict, working_size: int, work_dir: str) -> dict:
    t0 = time.perf_counter()
    import pycolmap

    t = time.perf_counter()
    database = os.path.join(work_dir, "database.db")
    sparse = os.path.join(work_dir, "sparse")
    os.makedirs(sparse, exist_ok=True)
    names = [os.path.relpath(p, ds["image_dir"]) for p in ds["paths"]]

    reader = pycolmap.ImageReaderOptions()
    if ds["k_file"]:
        from truortho.core.sfm.pipeline import read_k_matrix

        K = read_k_matrix(ds["k_file"])
        reader.camera_model = "PINHOLE"
        params = (K[0, 0], K[1, 1], K[0, 2] + 0.5, K[1, 2] + 0.5)
        reader.camera_params = ",".join(repr(float(v)) for v in params)
    else:
        reader.camera_model = "SIMPLE_RADIAL"
    extraction = pycolmap.FeatureExtractionOptions()
    extraction.max_image_size = working_size
    extraction.num_threads = THREADS
    extraction.use_gpu = False
    extraction.sift.max_num_features = MAX_FEATURES
    device = pycolmap.Device.cpu
    pycolmap.extract_features(
        database,
        ds["image_dir"],
        image_names=names,
        camera_mode=pycolmap.CameraMode.SINGLE,
        reader_options=reader,
        extraction_options=extraction,
        device=device,
    )
    t_feat = time.perf_counter()
    matching = pycolmap.FeatureMatchingOptions()
    matching.num_threads = THREADS
    matching.use_gpu = False
    pycolmap.match_exhaustive(database, matching_options=matching, device=device)
    t_match = time.perf_counter()
    mapping = pycolmap.IncrementalPipelineOptions()
    mapping.num_threads = THREADS
    try:
        mapping.mapper.num_threads = THREADS
    except AttributeError:
        pass
    recs = pycolmap.incremental_mapping(database, ds["image_dir"], sparse, options=mapping)
    wall = time.perf_counter() - t
    out = dict(
        engine=f"pycolmap {pycolmap.__version__}",
        wall_s=wall,
        import_s=t - t0,
        timings=dict(features=t_feat - t, matching=t_match - t_feat, mapping=time.perf_counter() - t_match),
        n_images=len(ds["paths"]),
        n_models=len(recs),
        registered=0,
        poses={},
    )
    if recs:
        rec = max(recs.values(), key=lambda r: r.num_reg_images())
        poses = {}
        for image_id in rec.reg_image_ids():
            im = rec.image(image_id)
            pose = im.cam_from_world()
            poses[im.name] = dict(
                R=np.asarray(pose.rotation.matrix()).tolist(),
                C=np.asarray(im.projection_center()).ravel().tolist(),
            )
        out.update(
            registered=len(poses),
            poses=poses,
            n_points=rec.num_points3D(),
            rms_px=float(rec.compute_mean_reprojection_error()),
            cameras={
                int(k): f"{c.model_name} {np.round(c.params, 4).tolist()}" for k, c in rec.cameras.items()
            },
        )
    out["peak_rss_mb"] = _peak_rss_mb()
    return out


def _float(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return None


# --------------------------------------------------------------------------------------------
# evaluation


def read_ground_truth(gt_dir: str) -> dict:
    """name -> (R world->camera, C) from Strecha's ``NNNN.jpg.camera`` files."""
    gt = {}
    for f in sorted(glob.glob(os.path.join(gt_dir, "*.camera"))):
        v = np.array(open(f, encoding="utf-8").read().split(), float)
        R_c2w = v[12:21].reshape(3, 3)  # columns: camera axes in the world
        gt[os.path.basename(f)[: -len(".camera")]] = (R_c2w.T, v[21:24])
    return gt


def evaluate(res: dict, ds: dict) -> dict:
    """Accuracy against the ground truth (fountain) after a similarity alignment of the centres."""
    if not ds["gt_dir"] or not res.get("poses"):
        return {}
    from truortho.core.geometry.rotation import rotation_angle_between
    from truortho.core.sfm.similarity import estimate_similarity

    gt = read_ground_truth(ds["gt_dir"])
    names = [n for n in sorted(res["poses"]) if n in gt]
    if len(names) < 3:
        return {"accuracy_note": f"only {len(names)} registered image(s) with ground truth"}
    C = np.array([res["poses"][n]["C"] for n in names])
    Cg = np.array([gt[n][1] for n in names])
    sim = estimate_similarity(C, Cg)
    err = np.linalg.norm(sim.apply(C) - Cg, axis=1)
    rot = np.array(
        [
            np.degrees(rotation_angle_between(np.array(res["poses"][n]["R"]) @ np.asarray(sim.R).T, gt[n][0]))
            for n in names
        ]
    )
    return dict(
        n_evaluated=len(names),
        centre_rmse_m=float(np.sqrt(np.mean(err**2))),
        centre_max_m=float(err.max()),
        rot_err_mean_deg=float(rot.mean()),
        rot_err_max_deg=float(rot.max()),
        rot_err_deg={n: float(r) for n, r in zip(names, rot, strict=True)},
        scene_extent_m=float(np.linalg.norm(np.ptp(Cg, axis=0))),
    )


# --------------------------------------------------------------------------------------------
# driver


def run_engine_subprocess(engine: str, dataset: str, working_size: int, timeout: float) -> dict:
    """Run one engine on one dataset in a fresh subprocess and work folder."""
    tmp = tempfile.mkdtemp(prefix=f"bench-orient-{engine}-{dataset}-")
    try:
        out_json = os.path.join(tmp, "result.json")
        work = os.path.join(tmp, "work")
        os.makedirs(work)
        log = os.path.join(tmp, "log.txt")
        cmd = [
            sys.executable,
            "-P",
            os.path.abspath(__file__),
            "--engine",
            engine,
            "--dataset",
            dataset,
            "--working-size",
            str(working_size),
            "--work-dir",
            work,
            "--json",
            out_json,
        ]
        t = time.perf_counter()
        with open(log, "w") as fh:
            try:
                proc = subprocess.run(cmd, stdout=fh, stderr=subprocess.STDOUT, timeout=timeout)
                rc = proc.returncode
            except subprocess.TimeoutExpired:
                rc = None
        process_s = time.perf_counter() - t
        if rc == 0 and os.path.isfile(out_json):
            with open(out_json) as fh:
                res = json.load(fh)
            res["process_s"] = process_s
            return res
        tail = open(log, errors="replace").read().strip().splitlines()[-15:]
        reason = f"timeout after {timeout:.0f} s" if rc is None else f"exit code {rc}"
        err = next((ln for ln in reversed(tail) if ln.strip()), "?")
        return dict(error=f"{reason}: {err}", log_tail=tail, process_s=process_s)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _fmt(v, spec=".2f"):
    return "–" if v is None else format(v, spec)


def _ratio(a, b):
    return None if a is None or b in (None, 0) else a / b


def print_table(dataset: str, results: dict) -> None:
    print(f"\n### {dataset}\n")
    head = [
        "engine",
        "registered",
        "wall time [s]",
        "peak memory [MB]",
        "centre RMSE [m]",
        "rotation error mean/max [deg]",
        "sigma0 [px]",
        "guided",
    ]
    if dataset == "copr":
        head.append("check RMSE X/Y [m]")
    print("| " + " | ".join(head) + " |")
    print("|" + "|".join("---" for _ in head) + "|")
    for engine in ENGINES:
        r = results.get(engine)
        if r is None:
            continue
        if "error" in r:
            row = [engine, "failed"] + ["–"] * (len(head) - 2)
        else:
            n, reg = r["n_images"], r["registered"]
            acc = r.get("accuracy", {})
            rot = (
                f"{acc['rot_err_mean_deg']:.3f} / {acc['rot_err_max_deg']:.3f}"
                if "rot_err_mean_deg" in acc
                else "–"
            )
            row = [
                r.get("engine", engine),
                f"{reg}/{n} ({100.0 * reg / max(n, 1):.0f} %)",
                _fmt(r.get("wall_s"), ".1f"),
                _fmt(r.get("peak_rss_mb"), ".0f"),
                _fmt(acc.get("centre_rmse_m"), ".4f"),
                rot,
                _fmt(r.get("sigma0"), ".3f"),
                str(len(r["guided"])) if "guided" in r else "–",
            ]
            if dataset == "copr":
                c = r.get("check_rmse") or {}
                row.append(
                    f"{c['x']:.3f} / {c['y']:.3f} (n={int(c.get('n') or 0)})"
                    if c.get("x") is not None and c.get("y") is not None
                    else "–"
                )
        print("| " + " | ".join(row) + " |")
    for engine in ENGINES:
        r = results.get(engine)
        if r and "error" in r:
            print(f"\n{engine} failed on {dataset}: {r['error']}")
    o, c = results.get("ours"), results.get("pycolmap")
    if o and c and "error" not in o and "error" not in c:
        rt = _ratio(o.get("wall_s"), c.get("wall_s"))
        rm = _ratio(o.get("peak_rss_mb"), c.get("peak_rss_mb"))
        print(f"\nours/pycolmap: wall time {_fmt(rt)}, peak memory {_fmt(rm)}")
        results["ratios"] = dict(wall_time=rt, peak_memory=rm)


def child_main(a) -> None:
    ds = dataset_info(a.dataset)
    fn = run_ours if a.engine == "ours" else run_pycolmap
    try:
        res = fn(ds, a.working_size, a.work_dir)
    except Exception:
        traceback.print_exc()
        sys.exit(1)
    with open(a.json, "w") as fh:
        json.dump(res, fh)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--datasets", default=",".join(DATASETS), help="comma-separated: " + ", ".join(DATASETS))
    ap.add_argument("--working-size", type=int, default=2000, help="larger image side for features, px")
    ap.add_argument("--engines", default=",".join(ENGINES), help="comma-separated: ours, pycolmap")
    ap.add_argument("--timeout", type=float, default=3600.0, help="per engine and dataset, s")
    ap.add_argument("--output", default=os.path.join(HERE, "results", "orientation.json"))
    ap.add_argument("--engine", choices=ENGINES, help=argparse.SUPPRESS)
    ap.add_argument("--dataset", help=argparse.SUPPRESS)
    ap.add_argument("--work-dir", help=argparse.SUPPRESS)
    ap.add_argument("--json", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.engine:
        child_main(a)
        return

    datasets = [d.strip() for d in a.datasets.split(",") if d.strip()]
    engines = [e.strip() for e in a.engines.split(",") if e.strip()]
    for e in engines:
        if e not in ENGINES:
            raise SystemExit(f"unknown engine {e!r}; known: {', '.join(ENGINES)}")
    try:
        import pycolmap

        pycolmap_version = pycolmap.__version__
    except Exception as err:  # noqa: BLE001 - any import failure means: not available
        pycolmap_version = None
        if "pycolmap" in engines:
            print(f"pycolmap not available ({err}); running TruOrtho only")
            engines = [e for e in engines if e != "pycolmap"]
    print(
        f"orientation benchmark: working size {a.working_size} px, max {MAX_FEATURES} features, "
        f"{os.cpu_count()} CPUs, pycolmap {pycolmap_version or 'missing'} ({THREADS} threads)",
        flush=True,
    )

    all_results = {}
    for dataset in datasets:
        ds = dataset_info(dataset)
        if len(ds["paths"]) < 2:
            print(f"\n{dataset}: skipped, no images in {ds['image_dir']}")
            continue
        results = {}
        for engine in engines:
            print(f"running {engine} on {dataset} ({len(ds['paths'])} images) ...", flush=True)
            res = run_engine_subprocess(engine, dataset, a.working_size, a.timeout)
            if "error" not in res:
                try:
                    res["accuracy"] = evaluate(res, ds)
                except Exception as err:  # noqa: BLE001 - report and continue
                    res["accuracy"] = {"accuracy_note": f"evaluation failed: {err}"}
                print(
                    f"  {res['registered']}/{res['n_images']} registered, {res['wall_s']:.1f} s, "
                    f"{res['peak_rss_mb']:.0f} MB",
                    flush=True,
                )
            else:
                print(f"  failed: {res['error']}", flush=True)
            results[engine] = res
        print_table(dataset, results)
        for r in results.values():
            if isinstance(r, dict):
                r.pop("poses", None)
        results["meta"] = dict(
            working_size=a.working_size,
            max_features=MAX_FEATURES,
            date=time.strftime("%Y-%m-%d %H:%M:%S"),
            cpus=os.cpu_count(),
            machine=platform.platform(),
            pycolmap=pycolmap_version,
            pycolmap_threads=THREADS,
        )
        all_results[dataset] = results

    os.makedirs(os.path.dirname(os.path.abspath(a.output)), exist_ok=True)
    merged = {}
    if os.path.isfile(a.output):
        try:
            with open(a.output) as fh:
                merged = json.load(fh)
        except (OSError, ValueError):
            merged = {}
    merged.update(all_results)
    with open(a.output, "w") as fh:
        json.dump(merged, fh, indent=1, default=str)
    print(f"\nresults written to {os.path.relpath(a.output)}")


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from _docs import run_main

    TITLE = "Orientation against pycolmap"
    sys.exit(run_main(main, "orientation", TITLE, peers=("pycolmap", "cv2")))
