"""Quality measures of an orthophoto against a ground-truth orthophoto.

* :func:`ghosting` -- the share of cells within ``band`` metres (default 2 GSD)
  of a building outline whose colour differs from the truth by more than
  ``threshold`` dE*ab (CIE76; default 25): double-mapped roofs, facades and
  displaced edges all exceed it, exposure differences do not.
* :func:`phase_shift` -- median length of the shift between result and truth
  found by phase correlation (OpenCV, Hanning window) on tiles with data,
  in cells.
* :func:`coverage` -- share of reference cells (e.g. those seen by at least
  one image) that have data.
* :func:`mean_delta_e` -- mean dE*ab over the cells with data.

:func:`truth_seen` and :func:`building_mask` derive the reference masks of a
synthetic scene (:mod:`truortho.core.synthetic`).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from ..grid import RasterGrid
from .color import rgb_to_lab


def delta_e(rgb_a: np.ndarray, rgb_b: np.ndarray) -> np.ndarray:
    """dE*ab (CIE76) between sRGB images ``(rows, cols, 3)`` (uint8 or floats in [0, 1])."""

    def lab(x):
        x = np.asarray(x)
        f = x.astype(np.float64) / 255.0 if x.dtype == np.uint8 else x.astype(np.float64)
        return rgb_to_lab(f)

    return np.linalg.norm(lab(rgb_a) - lab(rgb_b), axis=-1)


def edge_band(mask: np.ndarray, width_cells: float) -> np.ndarray:
    """Cells within ``width_cells`` of the boundary of ``mask`` (inside and outside)."""
    from scipy.ndimage import distance_transform_edt

    m = np.asarray(mask, dtype=bool)
    if m.all() or not m.any():
        return np.zeros(m.shape, bool)
    d_in = distance_transform_edt(m)  # inside: distance to the nearest outside cell
    d_out = distance_transform_edt(~m)
    # distance of a cell centre to the outline: about d - 0.5 cells
    return (m & (d_in - 0.5 <= width_cells)) | (~m & (d_out - 0.5 <= width_cells))


def ghosting(result_rgb, truth_rgb, valid, buildings, band_cells: float, threshold: float = 25.0) -> dict:
    """Ghosting measure (module docstring).

    Parameters
    ----------
    result_rgb, truth_rgb : (rows, cols, 3)
    valid : (rows, cols) bool, cells with data in the result
    buildings : (rows, cols) bool, cells on a building (truth)
    band_cells : float, band half-width in cells (2 GSD / resolution)

    Returns
    -------
    dict with ``share`` (fraction of band cells with data over the threshold),
    ``cells`` (band cells with data) and ``ghost_cells``.
    """
    band = edge_band(buildings, band_cells) & np.asarray(valid, bool)
    de = delta_e(result_rgb, truth_rgb)
    ghost = band & (de > threshold)
    n = int(band.sum())
    return {"share": float(ghost.sum() / n) if n else 0.0, "cells": n, "ghost_cells": int(ghost.sum())}


def phase_shift(
    result_lum, truth_lum, valid, tile: int = 64, min_valid: float = 0.98, min_contrast: float = 0.02
) -> dict:
    """Median shift (cells) between two luminance images by phase correlation on tiles.

    Tiles with less than ``min_valid`` data or less than ``min_contrast``
    standard deviation in the truth are skipped.
    """
    import cv2

    a = np.asarray(result_lum, dtype=np.float64)
    b = np.asarray(truth_lum, dtype=np.float64)
    v = np.asarray(valid, bool)
    if a.shape != b.shape or a.shape != v.shape:
        raise InputError("phase_shift: images and mask differ in shape")
    win = cv2.createHanningWindow((tile, tile), cv2.CV_64F)
    shifts = []
    for r0 in range(0, a.shape[0] - tile + 1, tile):
        for c0 in range(0, a.shape[1] - tile + 1, tile):
            sl = (slice(r0, r0 + tile), slice(c0, c0 + tile))
            if v[sl].mean() < min_valid or b[sl].std() < min_contrast:
                continue
            ta = np.where(v[sl], a[sl], b[sl].mean())
            (dx, dy), resp = cv2.phaseCorrelate(np.ascontiguousarray(ta), np.ascontiguousarray(b[sl]), win)
            if resp > 0.05:
                shifts.append(math.hypot(dx, dy))
    if not shifts:
        return {"median": float("nan"), "tiles": 0, "p90": float("nan")}
    s = np.array(shifts)
    return {"median": float(np.median(s)), "p90": float(np.percentile(s, 90)), "tiles": len(s)}


def coverage(valid, reference) -> float:
    """Share of ``reference`` cells that are ``valid``."""
    ref = np.asarray(reference, bool)
    n = int(ref.sum())
    return float((np.asarray(valid, bool) & ref).sum() / n) if n else 1.0


def mean_delta_e(result_rgb, truth_rgb, valid) -> float:
    de = delta_e(result_rgb, truth_rgb)
    v = np.asarray(valid, bool)
    return float(de[v].mean()) if v.any() else float("nan")


# ------------------------------------------------------------------ synthetic truth


def grid_points(scene, grid: RasterGrid) -> np.ndarray:
    """World points (rows * cols, 3) of the cell centres on the truth surface."""
    X, Y = grid.centres()
    xy = np.column_stack([X.ravel(), Y.ravel()])
    return np.column_stack([xy, scene.height(xy)])


def building_mask(scene, grid: RasterGrid) -> np.ndarray:
    """Cells whose centre lies on a building footprint (truth)."""
    X, Y = grid.centres()
    xy = np.column_stack([X.ravel(), Y.ravel()]) - scene.offset[:2]
    _, bid = scene.surface.height(xy)
    return (bid >= 0).reshape(grid.shape)


def truth_view_counts(scene, grid: RasterGrid, max_view_angle: float = 90.0, tol: float = 0.02) -> np.ndarray:
    """Images (rows, cols) int32 that see each cell's truth surface point within ``max_view_angle``.

    :func:`truth_seen` is the same test stopping at the first image; dense matching needs the
    count (nothing can be matched where fewer than two images see).
    """
    if not 0.0 < float(max_view_angle) <= 90.0:
        raise InputError(f"max_view_angle: expected degrees in (0, 90], got {max_view_angle!r}")
    P = grid_points(scene, grid)
    count = np.zeros(len(P), np.int32)
    cosmax = math.cos(math.radians(max_view_angle))
    for i, im in enumerate(scene.orientation.images):
        d = im.C + scene.offset - P
        todo = d[:, 2] / np.linalg.norm(d, axis=1) >= cosmax
        if todo.any():
            vis, _, _ = scene.visibility(P[todo], i, tol=tol)
            count[np.flatnonzero(todo)[vis]] += 1
    return count.reshape(grid.shape)


def truth_seen(scene, grid: RasterGrid, max_view_angle: float = 90.0, tol: float = 0.02) -> np.ndarray:
    """Cells whose truth surface point is seen by at least one image within ``max_view_angle``."""
    P = grid_points(scene, grid)
    seen = np.zeros(len(P), bool)
    cosmax = math.cos(math.radians(max_view_angle))
    for i, im in enumerate(scene.orientation.images):
        C = im.C + scene.offset
        d = C[None, :] - P
        cz = d[:, 2] / np.linalg.norm(d, axis=1)
        todo = ~seen & (cz >= cosmax)
        if not todo.any():
            continue
        vis, _, _ = scene.visibility(P[todo], i, tol=tol)
        idx = np.flatnonzero(todo)
        seen[idx[vis]] = True
    return seen.reshape(grid.shape)
