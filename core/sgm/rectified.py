"""Semi-global matching of a rectified stereo pair with the OSGM kernels.

The disparity space is treated exactly like OSGM's Z levels: for disparity
``d`` the two *slices* are the left image and the right image shifted right
by ``d`` columns (``right_d[y, x] = right[y, x - d]``; where ``x - d`` leaves
the image the right image's border column is repeated (``border="replicate"``,
as most matchers do: those pixels have no true match, and uniform pseudo
costs let the smoothness term extend the neighbouring surface into them) or
the slice is NaN (``border="nan"``)), and the same :func:`~.cost.multi_image_cost`,
:func:`~.aggregation.aggregate`, :func:`~.selection.select` and
:func:`~.selection.median_filter` run on them.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..imagery import luminance
from ..progress import Progress, check
from .aggregation import DEFAULT_P1, DEFAULT_P2, aggregate
from .cost import COST_MAX, DEFAULT_MEASURE, DEFAULT_MIN_VALID, DEFAULT_RADIUS, multi_image_cost
from .selection import DEFAULT_UNIQUENESS, median_filter, select, valid_cells


def _grey(img: np.ndarray, name: str) -> np.ndarray:
    a = np.asarray(img)
    if a.ndim not in (2, 3) or a.shape[0] < 1 or a.shape[1] < 1:
        raise InputError(f"{name}: expected an (H, W) or (H, W, C) image, got shape {a.shape}")
    if not (np.issubdtype(a.dtype, np.integer) or np.issubdtype(a.dtype, np.floating)):
        raise InputError(f"{name}: expected integer or float pixels, got {a.dtype}")
    return luminance(a)


def disparity_costs(
    left: np.ndarray,
    right: np.ndarray,
    min_disp: int,
    num_disp: int,
    radius: int = DEFAULT_RADIUS,
    *,
    measure: str = DEFAULT_MEASURE,
    border: str = "replicate",
    min_valid: float = DEFAULT_MIN_VALID,
    progress: Progress | None = None,
) -> np.ndarray:
    """Cost volume of a rectified pair: level k is disparity ``min_disp + k``.

    ``left``, ``right`` are (H, W) float32 luminance images; returns
    (H, W, num_disp) uint16 from :func:`~.cost.multi_image_cost` of the
    slices ``[left, right shifted by d]`` (``border``: module docstring).
    """
    if border not in ("replicate", "nan"):
        raise InputError(f"border: expected 'replicate' or 'nan', got {border!r}")
    h, w = left.shape
    cost = np.empty((h, w, num_disp), np.uint16)
    nv = np.empty((h, w), np.uint8)
    if measure == "gradient" and border == "replicate":
        _gradient_costs(left, right, min_disp, num_disp, radius, min_valid, cost, nv, progress)
        return cost
    pair = np.empty((2, h, w), np.float32)
    pair[0] = left
    xs = np.arange(w)
    for k in range(num_disp):
        check(progress)
        d = min_disp + k
        src = xs - d
        inside = (src >= 0) & (src < w)
        if border == "replicate":
            pair[1] = right[:, np.clip(src, 0, w - 1)]
        else:
            pair[1].fill(np.nan)
            pair[1][:, inside] = right[:, src[inside]]
        c = np.empty((h, w), np.uint16)
        multi_image_cost(pair, radius, measure=measure, out=(c, nv), min_valid=min_valid)
        cost[:, :, k] = c
        if progress is not None:
            progress.update(0.5 * (k + 1) / num_disp, "matching costs")
    return cost


def _gradient_costs(left, right, min_disp, num_disp, radius, min_valid, cost, nv, progress) -> None:
    """The gradient measure's cost kernel per disparity, each image prepared once.

    The preparation of :func:`~.cost.multi_image_cost` (gradients, saturation
    at the median |g|) runs once on the left image and once on the right image
    extended by replicated border columns; each disparity then runs the cost
    kernel on the left preparation and the shifted right one. This equals
    per-slice calls except that the saturation scale is the whole image's
    (not each shifted slice's) and the slice edges use the extended image's
    central differences.
    """
    from .cost import _NO_SCALES, _STRIP, _mic_grad_kernel, _prep_gradients

    h, w = left.shape
    lo = max(0, min_disp + num_disp - 1)  # columns added left of the right image
    hi = max(0, -min_disp)  # and right of it
    ext = np.concatenate([np.repeat(right[:, :1], lo, 1), right, np.repeat(right[:, -1:], hi, 1)], axis=1)
    we = ext.shape[1]
    ql = [np.empty((1, h, w), np.int16) for _ in range(2)] + [np.empty((1, h, w), np.uint8)]
    _prep_gradients(left[None], ql[0], ql[1], ql[2], _NO_SCALES)
    qr = [np.empty((1, h, we), np.int16) for _ in range(2)] + [np.empty((1, h, we), np.uint8)]
    _prep_gradients(np.ascontiguousarray(ext[None]), qr[0], qr[1], qr[2], _NO_SCALES)
    pair = [np.empty((2, h, w), a.dtype) for a in ql]
    for a, b in zip(pair, ql, strict=True):
        a[0] = b[0]
    c = np.empty((h, w), np.uint16)
    for k in range(num_disp):
        check(progress)
        x0 = lo - (min_disp + k)  # right_d[:, x] = ext[:, x0 + x]
        for a, b in zip(pair, qr, strict=True):
            a[1] = b[0, :, x0 : x0 + w]
        _mic_grad_kernel(pair[0], pair[1], pair[2], radius, min_valid, 0, _STRIP, c, nv)
        cost[:, :, k] = c
        if progress is not None:
            progress.update(0.5 * (k + 1) / num_disp, "matching costs")


def match_rectified(
    left: np.ndarray,
    right: np.ndarray,
    min_disp: int,
    num_disp: int,
    p1: int = DEFAULT_P1,
    p2: int = DEFAULT_P2,
    paths: int = 8,
    radius: int = DEFAULT_RADIUS,
    *,
    measure: str = DEFAULT_MEASURE,
    adaptive: bool = True,
    uniqueness: float = DEFAULT_UNIQUENESS,
    median: int = 3,
    lr_check: float | None = None,
    border: str = "replicate",
    min_valid: float = DEFAULT_MIN_VALID,
    progress: Progress | None = None,
) -> np.ndarray:
    """Dense disparity of a rectified stereo pair by semi-global matching.

    Parameters
    ----------
    left, right : (H, W) or (H, W, C) array, uint8, uint16 or float
        The rectified pair (corresponding points on the same row); the left
        image is the reference. Colour images are reduced to luminance
        (:func:`truortho.core.imagery.luminance`: Rec. 601 luma of the first
        three bands; integers scaled by their dtype maximum).
    min_disp, num_disp : int
        Disparities ``min_disp <= d < min_disp + num_disp`` (pixels) are
        searched, ``d = x_left - x_right``.
    p1, p2 : int
        SGM penalties in cost units (:mod:`.aggregation`).
    paths : {8, 16}
        Aggregation paths.
    radius : int
        Cost window radius (window side ``2 radius + 1``).
    measure : {"gradient", "ncc", "census"}
        Matching cost (:func:`~.cost.multi_image_cost`).
    adaptive : bool
        Lower P2 per path step across intensity edges of the left image
        (``guide`` of :func:`~.aggregation.aggregate`, default edge).
    uniqueness : float in (0, 1]
        Uniqueness ratio of :func:`~.selection.select` (1 disables it).
    median : int
        Side of the NaN-aware median filter applied last (1: none).
    lr_check : float, optional
        If given, also match right-to-left (the same cost volume, sheared) and
        reject pixels whose two disparities differ by more than this many
        pixels. Off by default: it doubles the aggregation time.
    border : {"replicate", "nan"}
        Right image beyond its border (module docstring). With ``"nan"``,
        pixels whose disparities all leave the right image are NaN.
    min_valid : float in (0, 1]
        Fraction of a window that must be valid (:mod:`.cost`).
    progress : Progress, optional
        Progress and cancel.

    Returns
    -------
    (H, W) float32
        Disparity in pixels (sub-pixel), NaN where no disparity was
        accepted (no overlap, uniqueness, left-right check).
    """
    lg = _grey(left, "left")
    rg = _grey(right, "right")
    if lg.shape != rg.shape:
        raise InputError(f"right: expected the shape of the left image {lg.shape}, got {rg.shape}")
    for name, v in (("min_disp", min_disp), ("num_disp", num_disp)):
        if isinstance(v, bool) or not isinstance(v, int | np.integer):
            raise InputError(f"{name}: expected an integer, got {v!r}")
    if num_disp < 1:
        raise InputError(f"num_disp: expected at least 1 disparity, got {num_disp}")
    if isinstance(median, bool) or not isinstance(median, int | np.integer) or median < 1 or median % 2 == 0:
        raise InputError(f"median: expected an odd window side >= 1, got {median!r}")
    if lr_check is not None and not (float(lr_check) >= 0):
        raise InputError(f"lr_check: expected a non-negative disparity tolerance or None, got {lr_check!r}")
    cost = disparity_costs(
        lg, rg, int(min_disp), int(num_disp), radius, measure=measure, border=border,
        min_valid=min_valid, progress=progress,
    )  # fmt: skip
    check(progress)
    s = aggregate(cost, p1, p2, paths, guide=lg if adaptive else None)
    level, _ = select(s, uniqueness=uniqueness, valid=valid_cells(cost))
    del s
    disp = level + np.float32(min_disp)
    if lr_check is not None:
        check(progress)
        # right-reference volume: cost_R(y, x, k) = cost_L(y, x + d_k, k)
        h, w, nd = cost.shape
        cr = np.full_like(cost, COST_MAX)
        for k in range(nd):
            d = int(min_disp) + k
            if d >= 0:
                if d < w:
                    cr[:, : w - d, k] = cost[:, d:, k]
            elif -d < w:
                cr[:, -d:, k] = cost[:, : w + d, k]
        sr = aggregate(cr, p1, p2, paths, guide=rg if adaptive else None)
        lr, _ = select(sr, uniqueness=uniqueness, valid=valid_cells(cr))
        del sr
        dr = lr + np.float32(min_disp)
        xs = np.arange(w, dtype=np.float32)[None, :] - disp
        xi = np.rint(np.nan_to_num(xs, nan=-1.0)).astype(np.int64)
        inside = (xi >= 0) & (xi < w) & np.isfinite(disp)
        back = np.full(disp.shape, np.nan, np.float32)
        rows = np.broadcast_to(np.arange(h)[:, None], disp.shape)
        back[inside] = dr[rows[inside], xi[inside]]
        with np.errstate(invalid="ignore"):
            bad = ~(np.abs(back - disp) <= float(lr_check))
        disp[bad] = np.nan
    if median > 1:
        disp = median_filter(disp, int(median))
    if progress is not None:
        progress.update(1.0, "disparity")
    return disp
