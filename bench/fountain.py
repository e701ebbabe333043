"""fountain-P11 through ``truortho:osgm`` with its ground-truth cameras (issue 17, part 4).

Not a test. The EPFL/Strecha block (``../shared/data/fountain-P11``: 11 photos of 3072 x 2048 px of
a fountain on a wall, taken from the ground, with ground-truth interior and exterior orientation)
is the close-range case of the real-photo battery: a facade seen only by horizontal views, which
the nadir reference system cannot match and the oblique ones (``OBLIQUE=auto``) must. Run from the
repository root::

    make acceptance-fountain [FOUNTAIN_ARGS="--resolution 0.02 --keep DIR --write-docs"]

What it does, as a user with given cameras would:

1. writes the ground-truth cameras as a TruOrtho orientation JSON. The files' world frame has its
   Z axis pointing down (the cameras' image y axes are close to +Z); the bench turns it 180 degrees
   about X so that Z is up. The block has no CRS and OSGM needs a metric one: the bench places it
   in a stand-in, EPSG:32632 shifted by (500000, 5600000) m, which changes no figure below;
2. runs ``truortho:osgm`` through ``qgis_process`` with ``OBLIQUE=auto``, the extent and height
   range of the fountain (a 16 m square around the point nearest to every optical axis, from 4 m
   below to 10 m above it: what a user reads off the camera positions), and a point cloud output;
3. measures on the point cloud, without a truth surface (:func:`measures`), on every point and
   on the points of confidence at least :data:`CONFIDENT`:

   * **points** per reference system, and the **coverage** of the middle photo's frame (0005): the
     share of its 16 x 16 px cells that a point projects into;
   * the **wall plane**: a RANSAC plane through the points (inliers within 3 cells); **roughness**
     is the robust spread (1.4826 MAD) of the inliers' distances to it (the brick joints add a few
     mm), and **behind the wall** the share of the points within the wall's extent that lie more
     than 0.3 m behind it, away from the cameras. The wall is opaque: nothing there can be seen, so
     those points are false surfaces (blunders);
   * **agreement between the systems**: the distance from every point of the second system to the
     nearest point of the first, where the two overlap (nearest within 0.5 m): median, and the
     share within 3 cells;
   * the wall time and the peak resident memory of ``qgis_process``, after a warm-up
     (``acceptance.warm_up``) so that the time does not include numba's compilation of kernels
     whose cache is stale (about 50 s on this block's first run after a code change);

4. writes a picture (the middle photo, the cloud's colours and its depth seen from that photo) to
   ``bench/results/real/fountain.jpg``, and with ``--write-docs`` the marked section of
   ``docs/acceptance.md``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DATA = os.path.join(os.path.dirname(ROOT), "shared", "data", "fountain-P11")

#: The stand-in CRS and the shift of the block into it (the block itself has none).
CRS = "EPSG:32632"
SHIFT = np.array([500000.0, 5600000.0, 0.0])
#: The files' Z axis points down: this turn about X makes it point up (a rotation: det +1).
FLIP = np.diag([1.0, -1.0, -1.0])
#: The confidence of the second row of figures: the DSM filter's ``confident`` (DsmFilterConfig), the
#: level it trusts a cell at. The point cloud carries the confidence; a QGIS user filters on it.
CONFIDENT = 0.4
#: The photo the coverage and the picture are made from (the middle of the strip).
MIDDLE = "0005.jpg"


def read_cameras(folder: str = DATA) -> list[tuple[str, np.ndarray, np.ndarray, np.ndarray, tuple[int, int]]]:
    """``(name, K, R world->camera, C, (width, height))`` of every ``.camera`` file, in the turned
    frame (:data:`FLIP`); R is re-orthonormalised (the files give 6-7 digits)."""
    out = []
    cams = os.path.join(folder, "gt_dense_cameras")
    if not os.path.isdir(cams):
        raise SystemExit(f"fountain: {cams} not found (the shared data)")
    for fn in sorted(os.listdir(cams)):
        if not fn.endswith(".camera"):
            continue
        v = np.array(open(os.path.join(cams, fn)).read().split(), float)
        if v.size != 26:
            raise SystemExit(f"fountain: {fn}: expected 26 numbers (K, distortion, R, C, size), got {v.size}")
        K = v[:9].reshape(3, 3)
        u, _, vt = np.linalg.svd(v[12:21].reshape(3, 3))  # camera -> world
        R = (u @ vt).T @ FLIP.T
        out.append((fn[: -len(".camera")], K, R, FLIP @ v[21:24], (int(v[24]), int(v[25]))))
    return out


def write_orientation(path: str) -> np.ndarray:
    """The orientation JSON of the ground-truth cameras; returns the point nearest to every optical
    axis (local frame): the middle of what the photos look at."""
    from truortho.core.geometry.camera import Camera
    from truortho.core.geometry.frame import LocalFrame
    from truortho.core.orientation import Image, Orientation

    cams = read_cameras()
    K, size = cams[0][1], cams[0][4]
    camera = Camera(size[0], size[1], K[0, 0], K[1, 1], K[0, 2], K[1, 2], id="strecha")
    images = [Image(name, "strecha", R, C, path=name) for name, _, R, C, _ in cams]
    o = Orientation(frame=LocalFrame(CRS, SHIFT), cameras={"strecha": camera}, images=images,
                    image_root=os.path.join(DATA, "images"))  # fmt: skip
    o.save(path)
    A = np.zeros((3, 3))
    b = np.zeros(3)
    for im in images:
        m = np.eye(3) - np.outer(im.R[2], im.R[2])
        A += m
        b += m @ im.C
    return np.linalg.solve(A, b)


def read_cloud(path: str, min_confidence: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(xyz local, rgb uint8, system id)`` of the LAS/LAZ point cloud's points with at least
    ``min_confidence``."""
    import laspy

    las = laspy.read(path)
    keep = np.asarray(las["confidence"]) >= min_confidence
    xyz = np.column_stack([np.asarray(las.x), np.asarray(las.y), np.asarray(las.z)])[keep] - SHIFT
    rgb = np.column_stack([las.red, las.green, las.blue])[keep].astype(np.float64)
    if rgb.size and rgb.max() > 255:
        rgb /= 256.0
    return xyz, rgb.clip(0, 255).astype(np.uint8), np.asarray(las["system"])[keep].astype(np.int64)


def project(xyz: np.ndarray, K, R, C) -> tuple[np.ndarray, np.ndarray]:
    """Pixels (N, 2) and depths (N,) of points in a ground-truth camera."""
    pc = (xyz - C) @ R.T
    with np.errstate(divide="ignore", invalid="ignore"):
        uv = np.column_stack([K[0, 0] * pc[:, 0] / pc[:, 2] + K[0, 2],
                              K[1, 1] * pc[:, 1] / pc[:, 2] + K[1, 2]])  # fmt: skip
    return uv, pc[:, 2]


def wall_plane(xyz: np.ndarray, tol: float, seed: int = 0, trials: int = 400) -> tuple[np.ndarray, float]:
    """RANSAC plane ``(unit normal n, d)`` with ``n . x = d`` holding the most points within ``tol``,
    refined by least squares on its inliers."""
    rng = np.random.default_rng(seed)
    best, best_n = None, -1
    for _ in range(trials):
        p = xyz[rng.choice(len(xyz), 3, replace=False)]
        n = np.cross(p[1] - p[0], p[2] - p[0])
        norm = np.linalg.norm(n)
        if norm < 1e-9:
            continue
        n /= norm
        k = int((np.abs(xyz @ n - n @ p[0]) <= tol).sum())
        if k > best_n:
            best, best_n = (n, float(n @ p[0])), k
    n, d = best
    inl = xyz[np.abs(xyz @ n - d) <= tol]
    c = inl.mean(axis=0)
    n = np.linalg.svd(inl - c, full_matrices=False)[2][2]
    return n, float(n @ c)


def measures(cloud: str, resolution: float, min_confidence: float = 0.0) -> dict:
    from scipy.spatial import cKDTree

    xyz, _, system = read_cloud(cloud, min_confidence)
    cams = {name: (K, R, C, size) for name, K, R, C, size in read_cameras()}
    out: dict = {"points": int(len(xyz))}
    for s in np.unique(system):
        out[f"points_system_{s}"] = int((system == s).sum())
    K, R, C, (w, h) = cams[MIDDLE]
    uv, depth = project(xyz, K, R, C)
    ok = (depth > 0) & (uv[:, 0] >= 0) & (uv[:, 0] < w) & (uv[:, 1] >= 0) & (uv[:, 1] < h)
    cell = np.zeros((h // 16 + 1, w // 16 + 1), bool)
    cell[(uv[ok, 1] // 16).astype(int), (uv[ok, 0] // 16).astype(int)] = True
    out["coverage_middle"] = float(cell[: h // 16, : w // 16].mean())

    tol = 3.0 * resolution
    n, d = wall_plane(xyz, tol)
    centres = np.array([c for _, _, c, _ in cams.values()])
    if np.median(centres @ n - d) < 0:  # the normal towards the cameras
        n, d = -n, -d
    dist = xyz @ n - d
    inl = np.abs(dist) <= tol
    out["wall_points"] = float(inl.mean())
    r = dist[inl]
    out["wall_roughness_m"] = float(1.4826 * np.median(np.abs(r - np.median(r))))
    # the wall's extent: 5-95 % of its inliers along two in-plane axes
    e1 = np.cross(n, [0.0, 0.0, 1.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    a, b = xyz @ e1, xyz @ e2
    a0, a1 = np.percentile(a[inl], [5, 95])
    b0, b1 = np.percentile(b[inl], [5, 95])
    within = (a >= a0) & (a <= a1) & (b >= b0) & (b <= b1)
    out["behind_wall"] = float((within & (dist < -0.3)).sum() / max(within.sum(), 1))

    ids = np.unique(system)
    if ids.size >= 2:
        p, q = xyz[system == ids[0]], xyz[system == ids[1]]
        dd, _ = cKDTree(p).query(q, distance_upper_bound=0.5)
        dd = dd[np.isfinite(dd)]
        out["systems_overlap_points"] = int(dd.size)
        out["systems_median_m"] = float(np.median(dd)) if dd.size else math.nan
        out["systems_within3"] = float((dd <= tol).mean()) if dd.size else math.nan
    return out


def picture(cloud: str, path: str, scale: float = 0.25) -> None:
    """The middle photo, the cloud's colours and its depth seen from it (near blue, far red)."""
    import cv2

    xyz, rgb, _ = read_cloud(cloud)
    K, R, C, (w, h) = {n: (K, R, C, s) for n, K, R, C, s in read_cameras()}[MIDDLE]
    uv, depth = project(xyz, K, R, C)
    W, H = int(w * scale), int(h * scale)
    u, v = uv[:, 0] * scale, uv[:, 1] * scale
    ok = (depth > 0) & (u >= 0) & (u < W - 1) & (v >= 0) & (v < H - 1)
    order = np.argsort(-depth[ok])  # far first: the near points are drawn last
    ui, vi = u[ok][order].astype(int), v[ok][order].astype(int)
    zz, cc = depth[ok][order], rgb[ok][order]
    zbuf = np.full((H, W), np.nan)
    col = np.zeros((H, W, 3), np.uint8)
    for dy in (0, 1):
        for dx in (0, 1):
            zbuf[vi + dy, ui + dx] = zz
            col[vi + dy, ui + dx] = cc
    lo, hi = np.nanpercentile(zbuf, [2, 98]) if np.isfinite(zbuf).any() else (0.0, 1.0)
    grey = np.clip((np.nan_to_num(zbuf, nan=lo) - lo) / max(hi - lo, 1e-9) * 255, 0, 255).astype(np.uint8)
    dimg = cv2.applyColorMap(grey, cv2.COLORMAP_JET)
    dimg[~np.isfinite(zbuf)] = 0
    photo = cv2.resize(cv2.imread(os.path.join(DATA, "images", MIDDLE)), (W, H), interpolation=cv2.INTER_AREA)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    cv2.imwrite(path, np.hstack([photo, col[..., ::-1], dimg]), [cv2.IMWRITE_JPEG_QUALITY, 85])


def run_osgm(out: str, resolution: float) -> tuple[float, float]:
    """``truortho:osgm`` through ``qgis_process``; returns wall seconds and peak MB."""
    centre = write_orientation(os.path.join(out, "orientation.json"))
    x, y, z = centre + SHIFT
    args = [
        f"ORIENTATION={out}/orientation.json",
        f"EXTENT={x - 8:.3f},{x + 8:.3f},{y - 8:.3f},{y + 8:.3f} [{CRS}]",
        f"RESOLUTION={resolution}",
        f"Z_MIN={z - 4:.3f}",
        f"Z_MAX={z + 10:.3f}",
        "OBLIQUE=1",
        f"DSM={out}/dsm.tif",
        f"POINT_CLOUD={out}/cloud.las",
    ]
    from real_blocks import qgis_run

    return qgis_run("truortho:osgm", args, os.path.join(out, "osgm.log"), "fountain")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--resolution", type=float, default=0.02, help="RESOLUTION of truortho:osgm (m)")
    ap.add_argument("--keep", default="", help="keep the products in this folder")
    ap.add_argument("--write-docs", action="store_true", help="update docs/acceptance.md")
    args = ap.parse_args(argv)
    if not args.resolution > 0:
        raise SystemExit(f"--resolution: expected a length > 0 (m), got {args.resolution}")
    sys.path.insert(0, HERE)
    from _docs import commit as head_commit
    from acceptance import run_header, warm_up, write_docs

    started = head_commit()
    out = args.keep or tempfile.mkdtemp(prefix="truortho-fountain-")
    os.makedirs(out, exist_ok=True)
    warm_up(out, lambda m: print(m, flush=True))  # the time below without numba's compilation
    seconds, peak = run_osgm(out, args.resolution)
    rows = [measures(os.path.join(out, "cloud.las"), args.resolution, c) for c in (0.0, CONFIDENT)]
    for m in rows:
        m.update(seconds=seconds, peak_mb=peak, resolution=args.resolution)
    picture(os.path.join(out, "cloud.las"), os.path.join(HERE, "results", "real", "fountain.jpg"))
    print(json.dumps(rows, indent=1))
    _, _, head = run_header("fountain.py", argv, started=started)
    lines = [
        head,
        "",
        "| points | number (per system) | coverage of 0005's frame | on the wall plane | wall roughness m "
        "| behind the wall | systems: median distance m (within 3 cells) |",
        "|---|---|---|---|---|---|---|",
    ]
    for label, m in zip(("all", f"confidence >= {CONFIDENT:g}"), rows, strict=True):
        systems = ", ".join(f"{m[k]:,}" for k in sorted(m) if k.startswith("points_system_"))
        lines.append(
            f"| {label} | {m['points']:,} ({systems}) | {100 * m['coverage_middle']:.1f} % | "
            f"{100 * m['wall_points']:.1f} % | {m['wall_roughness_m']:.4f} | "
            f"{100 * m['behind_wall']:.2f} % | "
            f"{m.get('systems_median_m', math.nan):.4f} ({100 * m.get('systems_within3', math.nan):.1f} %) |"
        )
    lines += ["", f"`truortho:osgm`: {seconds:.0f} s, peak {peak:.0f} MB."]
    text = "\n".join(lines)
    print("\n" + text)
    with open(os.path.join(HERE, "results", "fountain.json"), "w") as fh:
        json.dump(rows, fh, indent=1)
    if args.write_docs:
        write_docs(text, section="fountain")
    return 0


if __name__ == "__main__":
    sys.exit(main())
