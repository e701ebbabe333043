"""The filter's stages on one window: confidence cut, sharpening, outliers, islands, smoothing."""

from __future__ import annotations

import numpy as np

from .config import CONFIDENCE_HALF, ISLAND_RING, DsmFilterConfig
from .kernels import _confidence_pass, _outlier_pass, _plane_smooth, _sharpen_pass


def _clean(z: np.ndarray, conf: np.ndarray | None, cfg: DsmFilterConfig, res: float):
    """Low-confidence cut, edge sharpening and outlier removal on a window.

    Returns ``(cleaned, outlier mask, low-confidence mask, sharpened mask)``.
    """
    t = cfg.threshold(res)
    has_conf = conf is not None
    c = np.ascontiguousarray(conf if conf is not None else np.zeros((1, 1)), dtype=np.float64)
    low = np.zeros(z.shape, bool)
    work = z.copy()
    if has_conf and cfg.min_confidence > 0:
        low = np.isfinite(work) & ~(c >= cfg.min_confidence)
        work[low] = np.nan
    if has_conf and cfg.confident > 0:
        doubt = np.zeros(z.shape, bool)
        _confidence_pass(work, c, cfg.confident, t, CONFIDENCE_HALF, doubt)
        work[doubt] = np.nan
        low |= doubt
    sharp = np.zeros(z.shape, bool)
    if cfg.sharpen:
        work, sharp = _sharpen(work, cfg, res)
    half = cfg.outlier_window // 2
    m1 = np.zeros(z.shape, bool)
    _outlier_pass(work, c, has_conf, t, half, cfg.min_support, m1)
    work[m1] = np.nan
    m2 = np.zeros(z.shape, bool)
    _outlier_pass(work, c, has_conf, t, 2 * half, 3 * cfg.min_support, m2)
    work[m2] = np.nan
    m3 = _islands(work, t, cfg.island_cells())
    work[m3] = np.nan
    out = m1 | m2 | m3
    return work, out, low, sharp & ~out


def _islands(z: np.ndarray, t: float, max_cells: int) -> np.ndarray:
    """Cells of small islands of valid data that depart from their surroundings.

    The median tests cannot judge a group of valid cells standing alone in nodata (after the
    low-confidence cut, in vegetation or at the border of the data): its window holds mostly
    itself, so its own height is the median and every cell has its fellows as support. A valid
    component (8-connected) of fewer than ``max_cells`` cells is removed when its median height
    departs by more than ``t`` from the median of the valid cells within :data:`ISLAND_RING`
    cells around it (none there: kept, nothing to judge it by). Such islands otherwise become
    the only rim of a hole filled around them: a one-cell match 5 m above the ground made a
    cone 5 m high in the filled DSM of the demo block.
    """
    from scipy import ndimage

    valid = np.isfinite(z)
    out = np.zeros(z.shape, bool)
    if max_cells <= 1 or not valid.any():
        return out
    labels, k = ndimage.label(valid, structure=np.ones((3, 3), bool))
    if not k:
        return out
    sizes = np.bincount(labels.ravel(), minlength=k + 1)
    nr, nc = z.shape
    g = ISLAND_RING
    for lab, box in enumerate(ndimage.find_objects(labels), start=1):
        if box is None or sizes[lab] >= max_cells:
            continue
        r0, r1 = max(box[0].start - g, 0), min(box[0].stop + g, nr)
        c0, c1 = max(box[1].start - g, 0), min(box[1].stop + g, nc)
        sub = labels[r0:r1, c0:c1]
        zs = z[r0:r1, c0:c1]
        others = zs[(sub != lab) & (sub > 0)]
        if not len(others):
            continue
        if abs(float(np.median(zs[sub == lab])) - float(np.median(others))) > t:
            out[r0:r1, c0:c1] |= sub == lab
    return out


def _sharpen(z: np.ndarray, cfg: DsmFilterConfig, res: float):
    out = np.empty_like(z)
    changed = np.zeros(z.shape, bool)
    _sharpen_pass(np.ascontiguousarray(z), cfg.sharpen_step(res), out, changed)
    return out, changed


def _smooth(z: np.ndarray, cfg: DsmFilterConfig, res: float):
    out = np.empty_like(z)
    changed = np.zeros(z.shape, bool)
    _plane_smooth(np.ascontiguousarray(z), cfg.smooth_radius, cfg.tolerance(res), out, changed)
    return out, changed
