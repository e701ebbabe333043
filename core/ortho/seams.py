"""Feathering across seamlines and the seamline polygons.

Feathering (:func:`feather_weights`): the weight of image ``a`` at a cell is the
share of cells labelled ``a`` in the ``(2 B + 1)`` square window around it
(a box filter of the label's indicator, i.e. a linear ramp of width ``2 B + 1``
cells across a straight seam), multiplied by whether image ``a`` sees the cell
*cleanly* (visible and not next to an occluder), so blending only happens
between images that both see the cells; the cell's own label always keeps a
positive weight. Weights are normalised to sum 1.

Seamlines (:func:`region_polygons`): the source-index raster of a tile is
polygonised (rasterio, 4-connected); the regions of one image from all tiles
are dissolved into one (multi)polygon per image at the end.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..jit import njit


def feather_weights(labels: np.ndarray, clean: np.ndarray, width: int) -> np.ndarray:
    """Blend weights ``(K, rows, cols)`` float32 for labels in ``[0, K)`` (``-1`` = none).

    Parameters
    ----------
    labels : (rows, cols) int
    clean : (K, rows, cols) bool
        Image k sees the cell without an occluder next to it.
    width : int
        BLEND_WIDTH in cells: the ramp spans ``2 * (width // 2) + 1`` cells; 0 = no feathering.
    """
    import cv2

    K = clean.shape[0]
    lab = np.ascontiguousarray(labels, dtype=np.int64)
    if lab.shape != clean.shape[1:]:
        raise InputError("feather_weights: labels and visibility differ in shape")
    out = np.zeros(clean.shape, np.float32)
    half = max(int(width) // 2, 0)
    if half > 0:
        present = np.zeros(K + 1, bool)
        present[np.clip(lab, -1, K - 1).ravel() + 1] = True
        for k in np.flatnonzero(present[1:]):
            # share of the window labelled k (box filter of the indicator)
            cv2.blur(
                (lab == k).astype(np.float32),
                (2 * half + 1, 2 * half + 1),
                dst=out[k],
                borderType=cv2.BORDER_REFLECT,
            )
    _feather_finish(lab, np.ascontiguousarray(clean), out)
    return out


@njit
def _feather_finish(lab, clean, w):
    """Weights ``w`` (K, rows, cols) kept where the image sees the cell cleanly, the cell's own label at
    least 1e-3, normalised to sum 1 over k; 0 where the cell has no label."""
    K, rows, cols = w.shape
    for r in range(rows):
        for c in range(cols):
            lb = lab[r, c]
            if lb < 0 or lb >= K:
                for k in range(K):
                    w[k, r, c] = 0.0
                continue
            s = np.float32(0.0)
            for k in range(K):
                v = w[k, r, c] if clean[k, r, c] else np.float32(0.0)
                if k == lb and v < 1e-3:
                    v = np.float32(1e-3)
                w[k, r, c] = v
                s += v
            for k in range(K):
                w[k, r, c] = w[k, r, c] / s


def region_polygons(index: np.ndarray, transform) -> dict[int, list]:
    """Polygons (shapely) of the cells of every image index (>= 0) of a raster window."""
    from rasterio.features import shapes
    from shapely.geometry import shape

    a = np.ascontiguousarray(index.astype(np.int32))
    out: dict[int, list] = {}
    for geom, value in shapes(a, mask=a >= 0, connectivity=4, transform=transform):
        out.setdefault(int(value), []).append(shape(geom))
    return out


def dissolve(parts: dict[int, list]) -> dict[int, object]:
    """One (multi)polygon per image index from the per-tile polygons."""
    from shapely.ops import unary_union

    return {k: unary_union(v) for k, v in sorted(parts.items()) if v}
