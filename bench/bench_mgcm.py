"""Benchmark of GCP target refinement (least-squares matching, MGCM) and ArUco detection.

Not a test. ``make bench BENCH=mgcm`` (about a minute on two cores). Synthetic images with known
truth (core/synthetic/targets.py: supersampled renderings under known affine/projective warps or
known cameras, radiometric gain/offset and noise); every figure is compared with a peer measured
in the same run on the same images:

* disc and checker targets, starts 0.5-3 px off in a random direction: LSM with the ideal target
  (affine shaping, gain/offset) against OpenCV template matching of the same ideal template
  (``cv2.matchTemplate`` TM_CCOEFF_NORMED, +-4 px, parabola sub-pixel fit) and, for checkers,
  ``cv2.cornerSubPix``;
* a textured patch from a master image matched into a view under a homography (LSM projective
  against template matching);
* MGCM on four oriented views of a textured ground patch from perturbed object points, against
  independent LSM per view;
* ArUco markers: detection rate and centre accuracy, LSM-refined centre against the diagonal
  intersection of OpenCV's sub-pixel corners;
* the tie points refined by LSM inside ``orient_images``: ``make bench BENCH=tiepoints``
  (bench_tiepoints.py: several blocks and copr, camera errors against the truth).

The goal of issue 19: refined target positions within 0.1 px RMS from starts up to 3 px off.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time

import cv2
import numpy as np

from truortho.core.gcp.lsm import LsmConfig, MgcmView, extract_template, lsm_match, mgcm, plane_shape
from truortho.core.gcp.targets import _diagonal_centre, detect_aruco
from truortho.core.geometry import project_points
from truortho.core.synthetic.cameras import look_at_rotation, make_camera, nadir_rotation
from truortho.core.synthetic.targets import (
    checker_pattern,
    disc_pattern,
    render_homography,
    render_on_plane,
)

OFFSETS = (0.5, 1.0, 2.0, 3.0)


def rms(values) -> float:
    v = np.asarray([x for x in values if np.isfinite(x)], dtype=float)
    return float(np.sqrt(np.mean(v**2))) if len(v) else float("nan")


def warp(rng, centre, pattern_centre, scale, persp):
    th = rng.uniform(0, 2 * np.pi)
    A = scale * np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    A = A @ np.array([[1.0, rng.uniform(-0.1, 0.1)], [0.0, rng.uniform(0.75, 1.05)]])
    H = np.eye(3)
    H[:2, :2] = A
    H[:2, 2] = centre - A @ np.array([pattern_centre, pattern_centre])
    H[2, :2] = rng.uniform(-persp, persp, 2)
    q = H @ np.array([pattern_centre, pattern_centre, 1.0])
    return H, q[:2] / q[2]


def template_matching(tmpl, img, start, radius=4):
    """Peer: normalised cross-correlation over integer shifts within ``radius`` + parabola fit."""
    h = tmpl.shape[0] // 2
    x0, y0 = int(round(start[0])), int(round(start[1]))
    win = img[y0 - h - radius : y0 + h + radius + 1, x0 - h - radius : x0 + h + radius + 1]
    if win.shape != (2 * (h + radius) + 1,) * 2:
        return np.array([np.nan, np.nan])
    score = cv2.matchTemplate(win.astype(np.float32), tmpl.astype(np.float32), cv2.TM_CCOEFF_NORMED)
    iy, ix = np.unravel_index(int(np.argmax(score)), score.shape)

    def sub(a, b, c):
        den = a - 2 * b + c
        return 0.5 * (a - c) / den if abs(den) > 1e-12 else 0.0

    dx = sub(score[iy, ix - 1], score[iy, ix], score[iy, ix + 1]) if 0 < ix < score.shape[1] - 1 else 0.0
    dy = sub(score[iy - 1, ix], score[iy, ix], score[iy + 1, ix]) if 0 < iy < score.shape[0] - 1 else 0.0
    return np.array([x0 - radius + ix + dx, y0 - radius + iy + dy])


def bench_targets(kind: str, seeds: int) -> None:
    print(f"\n{kind} targets: RMS error (px) of {seeds} images per start offset")
    print(
        f"{'start off':>10} {'LSM':>8} {'conv.':>6} {'NCC+parab.':>11}"
        + (f" {'cornerSubPix':>13}" if kind == "checker" else "")
    )
    for off in OFFSETS:
        e_lsm, e_tm, e_csp, conv = [], [], [], 0
        for seed in range(seeds):
            rng = np.random.default_rng(1000 * seed + int(off * 10))
            shape = (120, 120)
            if kind == "disc":
                H, truth = warp(
                    rng, np.array([60.0, 60.0]) + rng.uniform(-2, 2, 2), 40.0, rng.uniform(0.25, 0.4), 3e-5
                )
                img = render_homography(disc_pattern(81, 25.0), H, shape)
                tmpl = disc_pattern(23, 25.0 * 0.32)
            else:
                H, truth = warp(
                    rng, np.array([60.0, 60.0]) + rng.uniform(-2, 2, 2), 39.5, rng.uniform(0.3, 0.5), 3e-5
                )
                img = render_homography(checker_pattern(80), H, shape)
                tmpl = render_homography(checker_pattern(64), _about(64, 17), (17, 17))
            img = img * rng.uniform(0.4, 0.8) + rng.uniform(0.05, 0.2) + rng.normal(0, 0.01, shape)
            ang = rng.uniform(0, 2 * np.pi)
            start = truth + off * np.array([np.cos(ang), np.sin(ang)])
            init = None
            if kind == "checker":
                A = H[:2, :2] / np.sqrt(abs(np.linalg.det(H[:2, :2])))  # orientation known roughly,
                init = np.column_stack(
                    [A @ _rot(rng.normal(0, 0.1)), [0, 0]]
                )  # as after the detector's search
            r = lsm_match(tmpl, img, *start, LsmConfig(), initial=init)
            conv += r.converged
            e_lsm.append(math.hypot(r.x - truth[0], r.y - truth[1]) if r.converged else np.nan)
            peer_tmpl = tmpl
            if init is not None:  # the peer gets the same orientation as LSM's start
                h = tmpl.shape[0] // 2
                M = np.column_stack([init[:, :2], np.array([h, h]) - init[:, :2] @ [h, h]])
                peer_tmpl = cv2.warpAffine(
                    tmpl, M, tmpl.shape[::-1], flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT
                )
            p = template_matching(peer_tmpl, img, start)
            e_tm.append(math.hypot(*(p - truth)))
            if kind == "checker":
                u8 = np.clip(img * 255, 0, 255).astype(np.uint8)
                pt = np.array([[start]], dtype=np.float32)
                cv2.cornerSubPix(
                    u8, pt, (5, 5), (-1, -1), (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 40, 1e-3)
                )
                e_csp.append(math.hypot(*(pt[0, 0] - truth)))
        line = f"{off:>10.1f} {rms(e_lsm):>8.3f} {conv:>3}/{seeds:<2} {rms(e_tm):>11.3f}"
        if kind == "checker":
            line += f" {rms(e_csp):>13.3f}"
        print(line)


def _rot(t):
    return np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])


def _about(n_pattern: int, n_template: int) -> np.ndarray:
    s = 1.5 * n_template / n_pattern
    c_p, c_t = (n_pattern - 1) / 2.0, (n_template - 1) / 2.0
    return np.array([[s, 0.0, c_t - s * c_p], [0.0, s, c_t - s * c_p], [0.0, 0.0, 1.0]])


def bench_texture(seeds: int) -> None:
    print(f"\ntextured patch under a homography (master -> view), {seeds} images per start offset")
    print(f"{'start off':>10} {'LSM proj.':>10} {'conv.':>6} {'NCC+parab.':>11}")
    for off in OFFSETS:
        e_lsm, e_tm, conv = [], [], 0
        for seed in range(seeds):
            rng = np.random.default_rng(2000 * seed + int(off * 10))
            tex = cv2.GaussianBlur(rng.uniform(0, 1, (81, 81)), (0, 0), 2.5)
            tex = (tex - tex.min()) / (tex.max() - tex.min())
            H, truth = warp(rng, np.array([60.0, 60.0]), 40.0, rng.uniform(0.85, 1.1), 5e-4)
            H[:2, :2] = H[:2, :2] @ _rot(-np.arctan2(H[1, 0], H[0, 0]))  # small rotation only: the template
            q = H @ [40.0, 40.0, 1.0]  # matcher of the peer cannot rotate
            H[:2, 2] += np.array([60.0, 60.0]) - q[:2] / q[2]
            q = H @ [40.0, 40.0, 1.0]
            truth = q[:2] / q[2]
            img = render_homography(tex, H, (120, 120)) * rng.uniform(0.6, 1.0) + rng.normal(
                0, 0.01, (120, 120)
            )
            tmpl = tex[28:53, 28:53]
            ang = rng.uniform(0, 2 * np.pi)
            start = truth + off * np.array([np.cos(ang), np.sin(ang)])
            r = lsm_match(tmpl, img, *start, LsmConfig(projective=True))
            conv += r.converged
            e_lsm.append(math.hypot(r.x - truth[0], r.y - truth[1]) if r.converged else np.nan)
            e_tm.append(math.hypot(*(template_matching(tmpl, img, start) - truth)))
        print(f"{off:>10.1f} {rms(e_lsm):>10.3f} {conv:>3}/{seeds:<2} {rms(e_tm):>11.3f}")


def bench_mgcm(blocks: int, trials: int) -> None:
    print(
        f"\nMGCM: 4 oriented views of a textured ground patch, {blocks} blocks x {trials} perturbed "
        "object points (image RMS over the 3 views other than the master)"
    )
    print(
        f"{'start RMS':>10} {'MGCM RMS':>9} {'conv.':>6} {'LSM/view RMS':>13} {'X err (m)':>10} "
        f"{'sigma X (m)':>11}"
    )
    for block in range(blocks):
        rng = np.random.default_rng(300 + block)
        cam = make_camera(320, 240, 400.0, distortion=(-0.05, 0.01, 0, 0, 0))
        tex = cv2.GaussianBlur(rng.uniform(0, 1, (400, 400)), (0, 0), 12.0)
        tex = (tex - tex.min()) / (tex.max() - tex.min())
        Xt = np.array([rng.uniform(-1, 1), rng.uniform(-1, 1), 0.0])
        views = []
        for i in range(4):
            if i == 0:
                C, R = np.array([0.0, 0.0, 30.0]), nadir_rotation(rng.uniform(0, 360))
            else:
                az = math.radians(rng.uniform(0, 360))
                C = np.array([8 * math.cos(az), 8 * math.sin(az), rng.uniform(27, 32)])
                R = look_at_rotation(C, Xt)
            img = render_on_plane(tex, 0.01, (0.0, 0.0), 0.0, R, C, cam) * rng.uniform(
                0.7, 1.2
            ) + rng.uniform(-0.1, 0.1)
            views.append(MgcmView(img + rng.normal(0, 0.01, img.shape), R, C, cam, f"v{i}"))
        truth = np.array([project_points(Xt[None], v.R, v.C, cam)[0] for v in views])
        tmpl = extract_template(views[0].image, *truth[0], 10)
        for _ in range(trials):
            X0 = Xt + rng.normal(0, 0.15, 3)
            start = np.array([project_points(X0[None], v.R, v.C, cam)[0] for v in views])
            r = mgcm(tmpl, views, X0, master=0)
            e_start = np.hypot(*(start[1:] - truth[1:]).T)
            e_m = (
                np.hypot(*(np.array([[v.x, v.y] for v in r.views[1:]]) - truth[1:]).T)
                if r.converged
                else [np.nan]
            )
            e_l = []
            for v, s, t in zip(views[1:], start[1:], truth[1:], strict=True):
                q = lsm_match(
                    tmpl, v.image, *s, initial=np.column_stack([plane_shape(views[0], v, X0), [0, 0]])
                )
                e_l.append(math.hypot(q.x - t[0], q.y - t[1]) if q.converged else np.nan)
            xerr = float(np.linalg.norm(r.X - Xt)) if r.converged else np.nan
            sig = float(np.linalg.norm(r.sigma)) if r.converged else np.nan
            print(
                f"{rms(e_start):>10.2f} {rms(e_m):>9.3f} {int(r.converged):>6} {rms(e_l):>13.3f} "
                f"{xerr:>10.4f} {sig:>11.4f}"
            )


def bench_aruco(scenes: int) -> None:
    d = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50)
    shape = (300, 460)
    n_true = n_found = n_ok = 0
    e_lsm, e_diag, t_det = [], [], 0.0
    for seed in range(scenes):
        rng = np.random.default_rng(500 + seed)
        img = cv2.GaussianBlur(rng.uniform(0.3, 0.7, shape), (0, 0), 4)
        truth = {}
        for k in range(3):
            pat = np.pad(
                cv2.aruco.generateImageMarker(d, k, 60, borderBits=1) / 255.0, 10, constant_values=1.0
            )
            c = (pat.shape[0] - 1) / 2
            H, t = warp(
                rng, np.array([80 + 150 * k, 150.0]) + rng.uniform(-15, 15, 2), c, rng.uniform(0.3, 0.6), 3e-4
            )
            truth[k] = t
            cover = render_homography(np.ones_like(pat), H, shape, background=0.0)
            img = img * (1 - cover) + render_homography(pat, H, shape, background=0.0)
        img = np.clip(
            img * rng.uniform(0.6, 0.9) + 0.1 + rng.normal(0, rng.uniform(0.005, 0.02), shape), 0, 1
        )
        u8 = (img * 255).round().astype(np.uint8)
        n_true += 3
        t0 = time.perf_counter()
        found, _ = detect_aruco(u8, {0: "A", 1: "B", 2: "C"})
        t_det += time.perf_counter() - t0
        n_found += len(found)
        for m in found:
            n_ok += m.flag == "ok"
            t = truth[m.marker_id]
            if m.flag == "ok":
                e_lsm.append(math.hypot(m.x - t[0], m.y - t[1]))
        det = cv2.aruco.ArucoDetector(d, _subpix())
        corners, ids, _ = det.detectMarkers(u8)
        for c, i in zip(corners or [], ids.reshape(-1) if ids is not None else [], strict=False):
            if int(i) in truth:
                x, y = _diagonal_centre(np.asarray(c, float).reshape(4, 2))
                e_diag.append(math.hypot(x - truth[int(i)][0], y - truth[int(i)][1]))
    print(f"\nArUco (DICT_4X4_50, 3 markers x {scenes} images, modules 3-6 px, rotation, perspective, noise)")
    print(f"  detected {n_found}/{n_true}, flagged ok {n_ok}; {1000 * t_det / scenes:.0f} ms per image")
    print(
        f"  centre RMS: refined (ok) {rms(e_lsm):.3f} px; "
        f"OpenCV corners' diagonal intersection {rms(e_diag):.3f} px"
    )


def _subpix():
    p = cv2.aruco.DetectorParameters()
    p.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    return p


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=12, help="images per start offset")
    ap.add_argument("--blocks", type=int, default=3)
    ap.add_argument("--aruco", type=int, default=12, help="ArUco scenes")
    a = ap.parse_args()
    t0 = time.perf_counter()
    bench_targets("disc", a.seeds)
    bench_targets("checker", a.seeds)
    bench_texture(a.seeds)
    bench_mgcm(a.blocks, 3)
    bench_aruco(a.aruco)
    print(f"\ntotal {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from _docs import run_main

    TITLE = "Target detection and least-squares matching (MGCM)"
    sys.exit(run_main(main, "mgcm", TITLE, peers=("cv2",)))
