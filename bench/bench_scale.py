"""Scale bench (issue 18): synthetic blocks of N photos with GNSS in EXIF, end to end through QGIS.

::

    make bench BENCH=scale                                       # 50, 100, 200, 400 photos of 12 MP
    make bench BENCH=scale BENCH_ARGS="--sizes 20,50 --megapixels 3 --write-docs"

For every size N the bench renders a synthetic nadir block of about N photos
(:func:`block_config`: a square area at 75/60 % overlap from 100 m, buildings
at a constant density, terrain relief), one image at a time straight to a
JPEG carrying its **noisy GNSS position in EXIF** (2 to 5 m, drawn per block)
and the focal length with the sensor size, so nothing but the photos and a few
GCPs go in (``gcp_list.txt`` -> ``truortho:importgcps``, a quarter of them check
points). Then it runs ``truortho:pipeline`` through ``qgis_process`` with its
defaults and reads the stages' wall time and peak memory from the products'
``report.json``. It prints one row per block and stage, the time per photo,
and the growth of the time per photo from the smallest to the largest block,
and writes a DSM hillshade beside the true ortho per block to
``bench/results/scale/block_N.jpg``.

Rendering is not timed as part of the pipeline (it is printed apart): every
block is rendered first, then the pipelines run one after the other. The
blocks are deleted after each run unless ``--keep`` is given; ``--keep DIR --reuse`` runs the
pipeline again on the blocks rendered there before (their ``render.json``: same seed and
megapixels), which saves the rendering (about 11 s per 12 MP photo). With
``--write-docs`` the table goes into ``docs/benchmarks.md`` between the
``scale`` markers (``scale-<MP>mp`` for photos of other than 12 MP), with
the command, the commit and the machine.

Beside the synthetic blocks the bench runs the real **copr** block in full (41 photos of
2136 x 1424 px from ``../shared/data/copr``, its GCPs, two check points; ``--copr auto``: when
the data is there) through the same ``truortho:pipeline`` at ``--copr-resolution`` (0.05 m), and
pycolmap's incremental pipeline on the same photos at the same working size in the same run
(:mod:`bench_orientation`): the copr goals of issue 18 (photos to true ortho in 5 minutes, 4 GB;
orientation in half pycolmap's time) are printed under the table. ``--sizes none`` with
``--copr yes`` runs copr alone (its own ``scale-copr`` section).

``--add-rows FILE`` joins the blocks of an earlier run's ``scale.json`` to this run's table, if
the product code (:data:`PRODUCT_PATHS`), megapixels and resolution are the same; the table says
which rows came from which run. It lets a long rendering run between the measurements of two
blocks without either competing with it.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
QP = os.path.join(ROOT, "scripts", "qgis_process")
DOCS = os.path.join(ROOT, "docs", "benchmarks.md")
#: Sensor width of the simulated camera (a 1" sensor), millimetres.
SENSOR_WIDTH_MM = 13.2
#: Flying height above ground, metres (the GSD follows from the image size: about 3 cm at 12 MP).
FLYING_HEIGHT = 100.0
#: Buildings per square metre of block.
BUILDING_DENSITY = 1.0 / 700.0
#: The real block run beside the synthetic ones (issue 18: "copr in full, orientation against
#: pycolmap in the same run"): 41 photos of 2136 x 1424 px with hand-held GNSS targets.
COPR = os.path.join(os.path.dirname(ROOT), "shared", "data", "copr")
#: Its check points (the other targets are GCPs), as in bench/real_blocks.py.
COPR_CHECKS = ["gcp06", "gcp08"]
#: Working size of the features, ours (the pipeline's default) and pycolmap's alike.
WORKING_SIZE = 2000


def image_size(megapixels: float) -> tuple[int, int]:
    """A 4:3 image of about ``megapixels`` (width and height multiples of 8)."""
    w = int(round(math.sqrt(megapixels * 1e6 * 4.0 / 3.0) / 8.0)) * 8
    return w, (w * 3 // 4) // 8 * 8


def _count(side: float, w: int, h: int, focal: float, height: float, fwd: float, side_ov: float) -> int:
    gsd = height / focal
    along, across = h * gsd, w * gsd
    n_along = max(3, math.ceil(max(side - along, 0) / ((1 - fwd) * along) - 1e-9) + 1)
    n_strips = max(2, math.ceil(max(side - across, 0) / ((1 - side_ov) * across) - 1e-9) + 1)
    return n_along * n_strips


def block_config(n_images: int, megapixels: float, seed: int):
    """The :class:`~truortho.core.synthetic.SceneConfig` of a square nadir block of about ``n_images``."""
    from truortho.core.synthetic import SceneConfig

    w, h = image_size(megapixels)
    focal = 0.8 * w
    height = FLYING_HEIGHT
    fwd, side_ov = 0.75, 0.6
    lo, hi = 1.0, 1e5
    for _ in range(60):  # the smallest square side whose block has at least n_images photos
        mid = 0.5 * (lo + hi)
        if _count(mid, w, h, focal, height, fwd, side_ov) >= n_images:
            hi = mid
        else:
            lo = mid
    side = hi
    half = side / 2
    cfg = SceneConfig(
        extent=(-half, -half, half, half),
        n_buildings=max(1, int(round(BUILDING_DENSITY * side * side))),
        building_size=(8.0, 20.0),
        eave_height=(4.0, 14.0),
        building_gap=4.0,
        tower=False,
        terrain_relief=4.0,
        image_size=(w, h),
        focal_px=focal,
        flying_height=height,
        forward_overlap=fwd,
        side_overlap=side_ov,
        n_oblique=0,
        jpeg_quality=0,  # encoded once, by the sink, with EXIF
        supersample=1,
        adaptive_supersampling=True,
        n_gcps=8,
        check_fraction=0.25,
        grid_margin=max(300.0, side),
        seed=seed,
    )
    return _placeable(cfg)


def _placeable(cfg):
    """``cfg`` with as many of its buildings as the generator can place (small blocks hold fewer)."""
    import dataclasses

    from truortho.core.errors import InputError
    from truortho.core.synthetic.surface import Surface

    while True:
        try:
            Surface(cfg)
            return cfg
        except InputError:
            if cfg.n_buildings <= 1:
                raise
            cfg = dataclasses.replace(cfg, n_buildings=cfg.n_buildings - 1)


def _rational(x: float, den: int = 10000) -> tuple[int, int]:
    return int(round(x * den)), den


def _dms(deg: float):
    deg = abs(deg)
    d = int(deg)
    m = int((deg - d) * 60)
    s = (deg - d - m / 60) * 3600
    return (_rational(d, 1), _rational(m, 1), _rational(s, 10000))


def jpeg_with_gnss(path: str, rgb: np.ndarray, lat: float, lon: float, alt: float, focal_px: float,
                   quality: int = 90) -> None:  # fmt: skip
    """Write an RGB uint8 image as JPEG with the GNSS position, focal length and sensor size in EXIF."""
    from PIL import Image as PILImage
    from PIL import TiffImagePlugin

    h, w = rgb.shape[:2]
    R = TiffImagePlugin.IFDRational
    ex = PILImage.Exif()
    ex[0x010F] = "TruOrtho"
    ex[0x0110] = "synthetic 1in"
    ex[0x8769] = {
        0x920A: R(*_rational(focal_px * SENSOR_WIDTH_MM / w)),
        0xA002: w,
        0xA003: h,
        0xA20E: R(*_rational(w / SENSOR_WIDTH_MM)),
        0xA20F: R(*_rational(w / SENSOR_WIDTH_MM)),
        0xA210: 4,  # millimetres
    }
    ex[0x8825] = {
        0: b"\x02\x03\x00\x00",
        1: "N" if lat >= 0 else "S",
        2: tuple(R(*v) for v in _dms(lat)),
        3: "E" if lon >= 0 else "W",
        4: tuple(R(*v) for v in _dms(lon)),
        5: b"\x00",
        6: R(*_rational(alt, 100)),
    }
    tmp = path + ".part"
    PILImage.fromarray(rgb).save(tmp, "JPEG", quality=quality, exif=ex.tobytes())
    os.replace(tmp, path)


def render_block(n_images: int, megapixels: float, seed: int, folder: str, log) -> dict:
    """Render the block into ``folder/images`` (JPEG + EXIF GNSS) and ``folder/gcp_list.txt``."""
    from pyproj import Transformer

    from truortho.core.synthetic import make_scene

    cfg = block_config(n_images, megapixels, seed)
    images = os.path.join(folder, "images")
    rng = np.random.default_rng([seed, 181])
    sigma = float(rng.uniform(2.0, 5.0))
    to_wgs = Transformer.from_crs(cfg.crs, "EPSG:4326", always_xy=True)
    off = np.asarray(cfg.offset, float)
    names = {}
    t = time.perf_counter()

    # a render interrupted half way resumes: the photos it wrote (whole files, written by rename)
    # are kept if the block is the same (seed and megapixels in render.partial.json)
    partial = os.path.join(folder, "render.partial.json")
    key = {"seed": seed, "megapixels": megapixels, "photos": n_images}
    same = False
    if os.path.isfile(partial):
        with open(partial) as fh:
            same = json.load(fh) == key
    if not same:
        shutil.rmtree(images, ignore_errors=True)
    os.makedirs(images, exist_ok=True)  # and the block's folder, where render.partial.json goes
    if not same:
        with open(partial, "w") as fh:
            json.dump(key, fh)
    kept = []

    def jpg(im):
        return os.path.join(images, os.path.splitext(im.name)[0] + ".jpg")

    def skip(k, im):
        return same and os.path.isfile(jpg(im))

    def sink(k, im, rgb):
        C = im.C + off + rng.normal(0.0, sigma, 3)
        names[im.name] = os.path.basename(jpg(im))
        if rgb is None:
            kept.append(k)
            return
        lon, lat = to_wgs.transform(C[0], C[1])
        jpeg_with_gnss(jpg(im), rgb, lat, lon, float(C[2]), cfg.focal_px)
        if (k + 1) % 25 == 0:
            log(f"    rendered {k + 1} photos ({time.perf_counter() - t:.0f} s)")

    scene = make_scene(cfg, image_sink=sink, skip_image=skip)
    if kept:
        log(f"    resumed: {len(kept)} photos were already rendered")
    lines = [cfg.crs]
    for g in scene.orientation.gcps:
        for name, u, v in g.observations:
            lines.append(
                f"{g.xyz[0]:.4f} {g.xyz[1]:.4f} {g.xyz[2]:.4f} {u:.3f} {v:.3f} {names[name]} {g.name}"
            )
    with open(os.path.join(folder, "gcp_list.txt"), "w") as fh:
        fh.write("\n".join(lines) + "\n")
    checks = [g.name for g in scene.orientation.gcps if g.role == "check"]
    w, h = cfg.image_size
    return {
        "photos": len(scene.orientation.images),
        "megapixels": round(w * h / 1e6, 1),
        "area_m": round(cfg.extent[2] - cfg.extent[0], 1),
        "gnss_sigma_m": round(sigma, 2),
        "gcps": len(scene.orientation.gcps),
        "checks": checks,
        "render_s": round(time.perf_counter() - t, 1),
        "render_resumed_photos": len(kept),
    }


def run_pipeline(
    folder: str, checks: list[str], resolution: float, log, images: str = "", gcp_list: str = ""
) -> dict:
    """``truortho:importgcps`` and ``truortho:pipeline`` on ``images`` (default ``folder/images``)
    with ``gcp_list`` (default ``folder/gcp_list.txt``); products, GeoPackages and log in ``folder``."""
    gcps = gcp_list or os.path.join(folder, "gcp_list.txt")
    images = images or os.path.join(folder, "images")
    imp = [QP, "run", "truortho:importgcps", "--", f"INPUT={gcps}", f"GCPS={folder}/gcps.gpkg",
           f"OBSERVATIONS={folder}/obs.gpkg"]  # fmt: skip
    if checks:
        imp.append(f"CHECK_POINTS={','.join(checks)}")
    p = subprocess.run(imp, capture_output=True, text=True)
    if p.returncode:
        raise SystemExit(f"importgcps failed:\n{p.stdout[-1500:]}\n{p.stderr[-1500:]}")
    products = os.path.join(folder, "products")
    args = [f"IMAGES={images}", f"GCPS={folder}/gcps.gpkg", f"OBSERVATIONS={folder}/obs.gpkg",
            f"RESOLUTION={resolution}", f"OUTPUT_FOLDER={products}"]  # fmt: skip
    sys.path.insert(0, HERE)
    from real_blocks import picture, qgis_pipeline

    # a fresh feature cache: the run extracts the features as a user's first run does (a rerun on
    # kept blocks would otherwise read them from the user's cache); the compiled kernels stay in
    # the user's numba cache (compiled once per install, not per block)
    from truortho.core.cache import cache_dir

    cache = os.path.join(folder, "cache")
    shutil.rmtree(cache, ignore_errors=True)
    saved = {k: os.environ.get(k) for k in ("TRUORTHO_CACHE_DIR", "NUMBA_CACHE_DIR")}
    os.environ["NUMBA_CACHE_DIR"] = saved["NUMBA_CACHE_DIR"] or str(cache_dir("numba"))
    os.environ["TRUORTHO_CACHE_DIR"] = cache
    try:
        wall, peak_mb = qgis_pipeline(args, folder, os.path.basename(folder))
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
        shutil.rmtree(cache, ignore_errors=True)

    picture(products, os.path.join(HERE, "results", "scale", f"{os.path.basename(folder)}.jpg"))
    with open(os.path.join(products, "report.json")) as fh:
        rep = json.load(fh)
    stages = next(t["rows"] for t in rep["tables"] if t["title"] == "Stages")
    return {
        "wall_s": round(wall, 1),
        "peak_mb": round(peak_mb) if math.isfinite(peak_mb) else None,
        "stages": [[r[0], r[1], r[2]] for r in stages],
        "summary": rep["summary"],
    }


def render_cell(r: dict) -> str:
    """Render seconds; a resumed render's time is that of the photos it rendered last."""
    kept = r.get("render_resumed_photos", 0)
    return f"{r['render_s']:.0f}" + (f" (resumed, {kept} kept)" if kept else "")


def block_gsd(megapixels: float) -> float:
    """Ground sample distance of the blocks of :func:`block_config`, metres."""
    return FLYING_HEIGHT / (0.8 * image_size(megapixels)[0])


def check_cell(summary: dict, gsd: float) -> str:
    """Check-point RMSE in plan and height from the report's summary (the accuracy that the
    speed must not cost: the 406-photo block's check heights were 17 GSD off at 01c155c)."""
    text = summary.get("check points RMSE X / Y / Z / 3D [m]")
    try:
        x, y, z, _ = (float(v) for v in str(text).split("/"))
    except ValueError:
        return ""
    return f"{math.hypot(x, y):.3f} / {z:.3f} ({z / gsd:.1f})"


def table(rows: list[dict]) -> list[str]:
    names: list[str] = []
    for r in rows:
        for s in r["run"]["stages"]:
            if s[0] not in names:
                names.append(s[0])
    head = (
        "| photos | MP | area [m] | render [s] | pipeline [s] | s / photo | peak [MB] | "
        + " | ".join(f"{n} [s]" for n in names)
        + " | check XY / Z [m] (Z in GSD) |"
    )
    out = [head, "|" + "---|" * (8 + len(names))]
    for r in rows:
        st = {s[0]: s for s in r["run"]["stages"]}
        wall = r["run"]["wall_s"]
        peak = r["run"].get("peak_mb")  # the qgis_process's peak RSS (else the stages' own)
        if peak is None:
            peak = max((s[2] for s in r["run"]["stages"] if s[2] is not None), default=float("nan"))
        cells = [str(r["photos"]), f"{r['megapixels']:.1f}", f"{r['area_m']:.0f}", render_cell(r),
                 f"{wall:.0f}", f"{wall / r['photos']:.2f}", f"{peak:.0f}"]  # fmt: skip
        cells += [f"{st[n][1]:.0f}" if n in st else "" for n in names]
        cells.append(check_cell(r["run"].get("summary", {}), block_gsd(r["megapixels"])))
        out.append("| " + " | ".join(cells) + " |")
    if len(rows) >= 2:
        a, b = rows[0], rows[-1]
        g = (b["run"]["wall_s"] / b["photos"]) / (a["run"]["wall_s"] / a["photos"])
        out.append("")
        out.append(
            f"Time per photo from {a['photos']} to {b['photos']} photos: x{g:.2f} "
            "(goal <= 1.5 from 100 to 400)."
        )
    return out


def run_copr(folder: str, resolution: float, log) -> dict:
    """copr through ``truortho:pipeline`` (cold feature cache, like the synthetic blocks), then
    pycolmap's incremental pipeline on the same photos at the same working size
    (:func:`bench_orientation.run_engine_subprocess`, 2 threads, exhaustive matching)."""
    images = os.path.join(COPR, "images")
    if not os.path.isdir(images):
        raise SystemExit(f"--copr: image folder {images} not found")
    os.makedirs(folder, exist_ok=True)
    shutil.rmtree(os.path.join(folder, "products"), ignore_errors=True)
    photos = len([f for f in os.listdir(images) if f.lower().endswith((".jpg", ".jpeg"))])
    log(f"copr: truortho:pipeline on {photos} photos at RESOLUTION {resolution}")
    run = run_pipeline(
        folder, COPR_CHECKS, resolution, log, images=images, gcp_list=os.path.join(COPR, "gcp_list.txt")
    )
    row = {"photos": photos, "resolution": resolution, "run": run}
    try:
        import pycolmap
    except ImportError as err:  # the bench says so rather than failing
        log(f"copr: pycolmap not available ({err}): no orientation comparison")
        return row
    sys.path.insert(0, HERE)
    from bench_orientation import run_engine_subprocess

    log(f"copr: pycolmap {pycolmap.__version__} on the same photos (working size {WORKING_SIZE} px)")
    res = run_engine_subprocess("pycolmap", "copr", WORKING_SIZE, timeout=4 * 3600)
    if "error" in res:
        log(f"  pycolmap failed: {res['error']}")
    row["pycolmap"] = {
        "engine": res.get("engine", f"pycolmap {pycolmap.__version__}"),
        "wall_s": res.get("wall_s"),
        "peak_mb": res.get("peak_rss_mb"),
        "registered": res.get("registered"),
        "error": res.get("error"),
    }
    return row


def copr_table(r: dict) -> list[str]:
    """The copr row: the pipeline's stages, the goals (<= 5 min, <= 4 GB) and the orientation
    against pycolmap's (goal <= 0.5)."""
    st = {s[0]: s for s in r["run"]["stages"]}
    wall = r["run"]["wall_s"]
    peak = r["run"].get("peak_mb")
    ours = st.get("orientation", [None, float("nan")])[1]
    summ = r["run"].get("summary", {})
    out = [
        "| block | photos | RESOLUTION [m] | oriented | pipeline [s] | peak [MB] | "
        + " | ".join(f"{n} [s]" for n in st)
        + " |",
        "|" + "---|" * (6 + len(st)),
        "| copr | "
        + " | ".join(
            [str(r["photos"]), f"{r['resolution']:g}", str(summ.get("registered images", "?")),
             f"{wall:.0f}", f"{peak:.0f}" if peak is not None else "?"]  # fmt: skip
            + [f"{st[n][1]:.0f}" for n in st]
        )
        + " |",
        "",
        f"Photos to true ortho: {wall:.0f} s (goal <= 300 s), peak "
        + (f"{peak:.0f}" if peak is not None else "?")
        + " MB (goal <= 4096 MB).",
    ]
    chk = summ.get("check points RMSE X / Y / Z / 3D [m]")
    if chk:
        out.append(f"Check points ({', '.join(COPR_CHECKS)}) RMSE X / Y / Z / 3D: {chk} m.")
    pc = r.get("pycolmap")
    if pc and pc.get("wall_s"):
        out.append(
            f"Orientation against {pc['engine']} in the same run (features, matching, reconstruction; "
            f"{WORKING_SIZE} px, 2 threads): ours {ours:.0f} s (the pipeline's orientation stage, with "
            f"its GCPs), pycolmap {pc['wall_s']:.0f} s ({pc.get('registered')} of {r['photos']} "
            f"registered, peak {pc.get('peak_mb') or float('nan'):.0f} MB): ratio "
            f"{ours / pc['wall_s']:.2f} (goal <= 0.5)."
        )
    elif pc:
        out.append(f"pycolmap failed: {pc.get('error')}")
    return out


#: What the products depend on: an earlier run's rows join a table only if these are unchanged.
PRODUCT_PATHS = ("core", "processing", "truortho_plugin", "metadata.txt")


def load_rows(path: str, started: str, megapixels: float, resolution: float) -> dict:
    """An earlier run's ``scale.json`` whose rows may join this run's table: same megapixels and
    resolution, and no change to :data:`PRODUCT_PATHS` between its commit and this one."""
    try:
        with open(path) as fh:
            earlier = json.load(fh)
    except (OSError, ValueError) as err:
        raise SystemExit(f"--add-rows: cannot read {path}: {err}") from err
    if not isinstance(earlier, dict) or "commit" not in earlier or not earlier.get("blocks"):
        raise SystemExit(f"--add-rows: {path} is not a scale.json with a commit and blocks")
    if (earlier.get("megapixels"), earlier.get("resolution")) != (megapixels, resolution):
        raise SystemExit(
            f"--add-rows: {path} measured {earlier.get('megapixels')} MP at RESOLUTION "
            f"{earlier.get('resolution')}, this run {megapixels} MP at {resolution}"
        )
    a, b = str(earlier["commit"]), started
    if "+dirty" in a or "+dirty" in b or a == "unknown" or b == "unknown":
        raise SystemExit(f"--add-rows: both runs must be of committed code (got {a} and {b})")
    diff = subprocess.run(["git", "-C", ROOT, "diff", "--quiet", a, b, "--", *PRODUCT_PATHS])
    if diff.returncode != 0:
        changed = ", ".join(PRODUCT_PATHS)
        raise SystemExit(f"--add-rows: the product code ({changed}) changed between {a} and {b}")
    return earlier


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="50,100,200,400", help="comma-separated photo counts")
    ap.add_argument("--megapixels", type=float, default=12.0)
    ap.add_argument("--resolution", type=float, default=0.0, help="RESOLUTION of the pipeline (0 = the GSD)")
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--keep", default="", help="keep the blocks and products in this folder")
    ap.add_argument(
        "--reuse",
        action="store_true",
        help="with --keep: run again on the blocks already rendered there (their render.json)",
    )
    ap.add_argument(
        "--render-only",
        action="store_true",
        help="with --keep: render the blocks (render.json) and stop; a later --reuse run measures them",
    )
    ap.add_argument(
        "--copr",
        choices=("auto", "yes", "no"),
        default="auto",
        help="also run the real copr block (41 photos) and pycolmap on it; auto: when its data is there",
    )
    ap.add_argument(
        "--copr-resolution", type=float, default=0.05, help="RESOLUTION of the copr run (m; 0 = the GSD)"
    )
    ap.add_argument(
        "--add-rows",
        default="",
        help="a scale.json of an earlier run of the same product code, megapixels and resolution: "
        "its blocks join this run's table (named as such under it)",
    )
    ap.add_argument("--write-docs", action="store_true", help=f"update the scale section of {DOCS}")
    args = ap.parse_args(argv)
    if args.render_only and (not args.keep or args.write_docs):
        raise SystemExit("--render-only: needs --keep DIR (where the blocks stay) and no --write-docs")
    spec = "" if args.sizes.strip().lower() == "none" else args.sizes
    sizes = [int(s) for s in spec.split(",") if s.strip()]
    copr = args.copr == "yes" or (args.copr == "auto" and os.path.isdir(COPR) and not args.render_only)
    if (not sizes and not copr) or (sizes and min(sizes) < 6):
        raise SystemExit('--sizes: expected photo counts of at least 6 (or "none", with --copr yes)')

    def log(msg: str) -> None:
        print(msg, flush=True)

    rows = []
    copr_row = None
    sys.path.insert(0, HERE)
    from _docs import commit as head_commit

    started = head_commit()  # the code measured: taken before the run, not after it
    earlier = load_rows(args.add_rows, started, args.megapixels, args.resolution) if args.add_rows else None
    base = args.keep or tempfile.mkdtemp(prefix="truortho-scale-")
    try:
        # every block is rendered first, then the pipelines run one after the other: the measured
        # part of the bench is one stretch of time (nothing else of the bench competes with it)
        blocks = []
        for n in sizes:
            folder = os.path.join(base, f"block_{n}")
            log(f"block of {n} photos at {args.megapixels} MP:")
            rendered = os.path.join(folder, "render.json")
            info = None
            if args.reuse and os.path.isfile(rendered):
                with open(rendered) as fh:
                    info = json.load(fh)
                key = (info.get("seed"), info.get("megapixels_asked"))
                if key != (args.seed, args.megapixels):
                    raise SystemExit(f"--reuse: {rendered} was rendered with seed/megapixels {key}")
                shutil.rmtree(os.path.join(folder, "products"), ignore_errors=True)
                log(f"  reusing the {info['photos']} photos rendered in {folder}")
            else:
                info = render_block(n, args.megapixels, args.seed, folder, log)
                info.update(seed=args.seed, megapixels_asked=args.megapixels)
                with open(rendered, "w") as fh:
                    json.dump(info, fh, indent=1)
            log(
                f"  {info['photos']} photos rendered in {info['render_s']} s; "
                f"GNSS sigma {info['gnss_sigma_m']} m"
            )
            blocks.append((folder, info))
        if args.render_only:
            log(f"rendered {len(blocks)} blocks in {base}; measure them with --keep {base} --reuse")
            return 0
        for folder, info in blocks:
            log(f"pipeline on {info['photos']} photos ({folder}):")
            info["run"] = run_pipeline(folder, info["checks"], args.resolution, log)
            for s in info["run"]["stages"]:
                log(f"  {s[0]:<24} {s[1]:>8.1f} s  peak {s[2]} MB")
            log(
                f"  pipeline {info['run']['wall_s']} s "
                f"({info['run']['wall_s'] / info['photos']:.2f} s per photo)"
            )
            rows.append(info)
            if not args.keep:
                shutil.rmtree(folder, ignore_errors=True)
        copr_row = run_copr(os.path.join(base, "copr"), args.copr_resolution, log) if copr else None
    finally:
        if not args.keep:
            shutil.rmtree(base, ignore_errors=True)
    result = {
        "commit": started,
        "date": time.strftime("%Y-%m-%d %H:%M"),
        "megapixels": args.megapixels,
        "resolution": args.resolution,
        "blocks": list(rows),
        "copr": copr_row,
    }
    if earlier is not None:
        # a block measured again in this run keeps this run's row (checked here: the photo counts
        # are known only once the blocks are rendered)
        mine = {r["photos"] for r in rows}
        dropped = sorted(r["photos"] for r in earlier["blocks"] if r["photos"] in mine)
        if dropped:
            log(f"--add-rows: this run measured {dropped} photos again; its rows replace the earlier ones")
        earlier["blocks"] = [r for r in earlier["blocks"] if r["photos"] not in mine]
        rows = sorted(earlier["blocks"] + rows, key=lambda r: r["photos"])
    lines = table(rows) if rows else []
    if earlier is not None and earlier["blocks"]:
        named = ", ".join(str(r["photos"]) for r in earlier["blocks"])
        lines.append(
            f"The row(s) of {named} photos come from an earlier run of the same product code "
            f"(commit {earlier['commit']}, {earlier['date']}; `--add-rows`)."
        )
    if copr_row is not None:
        lines += ([""] if lines else []) + copr_table(copr_row)
    print("\n".join(lines))
    os.makedirs(os.path.join(HERE, "results"), exist_ok=True)
    with open(os.path.join(HERE, "results", "scale.json"), "w") as fh:
        json.dump(result, fh, indent=1)
    if args.write_docs:
        sys.path.insert(0, HERE)
        from _docs import header, shown_argv, write_section

        argv = shown_argv(sys.argv[1:], drop=("--write-docs", "--reuse"))
        cmd = 'make bench BENCH=scale BENCH_ARGS="' + " ".join(argv) + '"'
        # the 12 MP run (issue 18's goal) and runs at other sizes each keep their own section
        mp = f"{args.megapixels:g}"
        key, title = ("scale", "Scale: photos to true ortho") if mp == "12" else (
            f"scale-{mp}mp", f"Scale at {mp} MP: photos to true ortho")
        if not rows:
            key, title = "scale-copr", "Scale: copr in full, against pycolmap"
        write_section(key, title, [header(cmd, started=started), "", *lines])
    return 0


if __name__ == "__main__":
    sys.exit(main())
