"""Benchmark of the surface products against simple peers measured in the same run.

Not a test. Run with ``make bench BENCH=surface`` (or ``python -P bench/bench_surface.py [--res 0.125]``).

On the default synthetic scene (120 x 100 m, 7 buildings and a 32 m tower, seed 1; truth DSM at
``--res``, degraded by :func:`truortho.core.synthetic.degrade.degrade_dsm` with seed 3):

* **DSM filter** vs a common peer: a 3 x 3 median filter followed by GDAL's inverse-distance
  ``FillNodata`` (``rasterio.fill.fillnodata``, max distance = the same 10 m): RMSE on the raw
  DSM's valid cells, share of all cells within 3 GSD of the truth, wall time.
* **DTM** (SMRF-style, ours) vs a single morphological opening with the largest window (the
  classic one-step filter): RMSE to the analytic terrain.
* **Mesh** of the truth DSM with all roofs flattened: vertices per cell, RMSE and largest
  vertical error at the cell centres, vs the full-resolution grid mesh (two triangles per 4
  cell centres, one vertex per cell; its walls slope across every step).
* **Point cloud**: LAZ + EPT writing speed of the DSM's points.

Wall times on a shared machine are indicative only.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def _mesh_at(mesh, pts: np.ndarray) -> np.ndarray:
    """Height of the highest non-vertical triangle above each plan point (NaN if none)."""
    from scipy.spatial import cKDTree

    v, f = mesh.vertices, mesh.faces
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    d = (b[:, 1] - c[:, 1]) * (a[:, 0] - c[:, 0]) + (c[:, 0] - b[:, 0]) * (a[:, 1] - c[:, 1])
    keep = np.abs(d) > 1e-12
    a, b, c, d = a[keep], b[keep], c[keep], d[keep]
    centre = (a + b + c)[:, :2] / 3
    radius = np.max(np.stack([np.linalg.norm(q[:, :2] - centre, axis=1) for q in (a, b, c)]), axis=0)
    tree = cKDTree(centre)
    out = np.full(len(pts), np.nan)
    for i, cand in enumerate(tree.query_ball_point(pts, radius.max() + 1e-9)):
        if not cand:
            continue
        k = np.asarray(cand)
        px, py = pts[i]
        w0 = ((b[k, 1] - c[k, 1]) * (px - c[k, 0]) + (c[k, 0] - b[k, 0]) * (py - c[k, 1])) / d[k]
        w1 = ((c[k, 1] - a[k, 1]) * (px - c[k, 0]) + (a[k, 0] - c[k, 0]) * (py - c[k, 1])) / d[k]
        w2 = 1 - w0 - w1
        inside = (w0 >= -1e-9) & (w1 >= -1e-9) & (w2 >= -1e-9)
        if inside.any():
            z = w0 * a[k, 2] + w1 * b[k, 2] + w2 * c[k, 2]
            out[i] = z[inside].max()
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--res", type=float, default=0.125)
    args = ap.parse_args()
    from scipy import ndimage

    from truortho.core.grid import RasterGrid
    from truortho.core.rasterio_io import write_raster
    from truortho.core.surface.dtm import dtm_from_dsm_array
    from truortho.core.surface.filter import DsmFilterConfig, filter_dsm_array
    from truortho.core.surface.mesh import DsmMeshConfig, mesh_from_dsm_array, rasterize_mesh
    from truortho.core.surface.meshio import Mesh
    from truortho.core.surface.pointcloud import dsm_to_point_cloud
    from truortho.core.synthetic import SceneConfig, make_scene
    from truortho.core.synthetic.degrade import degrade_dsm, flatten_roofs

    res = args.res
    scene = make_scene(SceneConfig(image_size=(320, 240), focal_px=250.0, n_oblique=0, seed=1, supersample=1))
    truth, gt = scene.dsm(res)
    truth = truth.astype(np.float64)
    grid = RasterGrid.from_geotransform(gt, truth.shape[0], truth.shape[1], scene.config.crs)
    d = degrade_dsm(truth, res, seed=3)
    print(f"scene: {truth.shape[1]} x {truth.shape[0]} cells at {res} m")

    def score(a):
        ok = np.isfinite(d.dsm)
        e = a - truth
        return float(np.sqrt(np.nanmean(e[ok] ** 2))), float(
            np.mean(np.abs(np.nan_to_num(e, nan=1e9)) <= 3 * res)
        )

    filter_dsm_array(d.dsm[:200, :200], grid.window(0, 0, 200, 200))  # JIT warm-up
    t = time.perf_counter()
    ours, stats = filter_dsm_array(d.dsm, grid, d.confidence, DsmFilterConfig())
    t_ours = time.perf_counter() - t
    from rasterio.fill import fillnodata

    t = time.perf_counter()
    med = ndimage.generic_filter(d.dsm, np.nanmedian, size=3, mode="nearest")
    med[np.isnan(d.dsm)] = np.nan
    mask = np.isfinite(med)
    peer = fillnodata(
        np.nan_to_num(med, nan=0.0).astype(np.float32), mask.astype(np.uint8), max_search_distance=10.0 / res
    )
    peer = np.where(peer == 0, np.nan, peer)
    t_peer = time.perf_counter() - t
    raw = score(d.dsm)
    o = score(ours)
    p = score(peer)
    print("DSM filter            RMSE(valid)  within 3 GSD  time")
    print(f"  raw                  {raw[0]:8.3f} m   {100 * raw[1]:6.2f} %")
    print(f"  TruOrtho dsmfilter   {o[0]:8.3f} m   {100 * o[1]:6.2f} %   {t_ours:6.2f} s")
    print(f"  median3 + FillNodata {p[0]:8.3f} m   {100 * p[1]:6.2f} %   {t_peer:6.2f} s")
    print(f"  ratio RMSE ours/peer {o[0] / p[0]:.2f}; {stats.summary()}")

    X, Y = grid.centres()
    xy = np.column_stack([X.ravel(), Y.ravel()]) - scene.offset[:2]
    terrain = (scene.surface.terrain(xy) + scene.offset[2]).reshape(truth.shape)
    t = time.perf_counter()
    dtm, _ = dtm_from_dsm_array(ours, grid)
    t_dtm = time.perf_counter() - t
    import cv2

    f = max(1, int(round(1.0 / res)))
    from truortho.core.surface.dtm import _min_pool, _upsample

    zmin = _min_pool(ours, f)
    k = int(18.0 / (res * f))
    se = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * k + 1, 2 * k + 1))
    opened = cv2.dilate(cv2.erode(zmin.astype(np.float32), se), se)
    one = _upsample(opened.astype(np.float64), f, (0, 0, grid.rows, grid.cols))
    r_dtm = float(np.sqrt(np.mean((dtm - terrain) ** 2)))
    r_one = float(np.sqrt(np.mean((one - terrain) ** 2)))
    print(
        f"DTM: SMRF-style RMSE {r_dtm:.3f} m ({t_dtm:.2f} s); single opening {r_one:.3f} m; "
        f"ratio {r_dtm / r_one:.2f}"
    )

    flatten_roofs(scene)
    flat, _ = scene.dsm(res)
    flat = flat.astype(np.float64)
    rgb, _ = scene.orthophoto(res)
    t = time.perf_counter()
    m = mesh_from_dsm_array(flat, grid, DsmMeshConfig(max_error=0.5 * res), rgb=rgb)
    t_mesh = time.perf_counter() - t
    e = rasterize_mesh(m.mesh, grid) - flat
    rows, cols = grid.shape
    idx = np.arange(rows * cols).reshape(rows, cols)
    a, b, c, dd = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    full = Mesh(
        np.column_stack([X.ravel(), Y.ravel(), flat.ravel()]),
        np.concatenate([np.column_stack([a, c, b]), np.column_stack([a, dd, c])]),
        None,
        grid.crs,
    )
    # both meshes against the analytic surface at random plan points (not only at cell centres)
    rng = np.random.default_rng(0)
    x0, y0, x1, y1 = grid.extent
    pts = np.column_stack(
        [rng.uniform(x0 + res, x1 - res, 200_000), rng.uniform(y0 + res, y1 - res, 200_000)]
    )
    z_true = scene.height(pts)
    e_ours = _mesh_at(m.mesh, pts) - z_true
    e_full = _mesh_at(full, pts) - z_true
    print(
        f"Mesh (flat roofs): {m.mesh.n_vertices} vertices = {m.vertex_ratio:.4f} per cell, "
        f"{m.mesh.n_faces} faces ({m.wall_faces} walls), {t_mesh:.2f} s; at cell centres RMSE "
        f"{np.sqrt(np.mean(e**2)):.4f} m, max {np.abs(e).max():.4f} m"
    )
    for name, e_ in (("TruOrtho mesh", e_ours), ("full-resolution grid mesh", e_full)):
        ok = np.isfinite(e_)
        print(
            f"  {name:26s} at 200k random points vs the analytic surface: RMSE "
            f"{np.sqrt(np.mean(e_[ok] ** 2)):.3f} m, {100 * np.mean(np.abs(e_[ok]) > 1.0):.2f} % off by > 1 m"
        )
    print(f"  ratio of vertices ours/full {m.mesh.n_vertices / full.n_vertices:.3f}")

    with tempfile.TemporaryDirectory() as tmp:
        write_raster(Path(tmp) / "dsm.tif", ours.astype(np.float32), grid, nodata=-9999.0)
        t = time.perf_counter()
        info = dsm_to_point_cloud(Path(tmp) / "dsm.tif", Path(tmp) / "pc.laz", ept_folder=Path(tmp) / "ept")
        t_pc = time.perf_counter() - t
        size = (Path(tmp) / "pc.laz").stat().st_size
        print(
            f"Point cloud: {info['points']} points, LAZ {size / info['points']:.1f} bytes/point, "
            f"LAZ + EPT in {t_pc:.2f} s ({info['points'] / t_pc / 1e6:.2f} M points/s)"
        )


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from _docs import run_main

    TITLE = "Surface products against simple peers"
    sys.exit(run_main(main, "surface", TITLE, peers=("scipy", "rasterio")))
