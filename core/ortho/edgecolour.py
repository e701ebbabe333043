"""Colour edges of a true orthophoto put back on the surface's height steps.

A photo stores the colour of a roof's outline smeared over a few pixels across it: JPEG keeps the
colour (Cb, Cr) at half the resolution of the brightness (4:2:0) and quantises it further, and the
decoder interpolates it back. :mod:`truortho.core.chroma` restores what the brightness tells, but
where roof and ground are about as bright, it cannot: the first cells of a red roof read brown
and the ground beside it reddish, a colour fringe along every outline. On the acceptance battery's
scenes (JPEG quality 70-95) that fringe is most of the ghosting left on the **exact** DSM (median
0.30 % of the 2-GSD band around the buildings, worst 1.33 %: seed 7, scene 10, quality 70).

The surface knows where the outlines are. For every mosaic cell within :data:`REACH` cells of a
height step (a 4-neighbour on another surface segment, :func:`~.select.segments` with the
selection's discontinuity height), :func:`surface_edge_colour` computes the colour (Cb, Cr, BT.601)
of its own surface: the weighted mean of the cells of its segment around it, weighted by their
distance to the step (none on the step, full from :data:`REACH` cells on: the cells beyond the
smear), by their distance to the cell, and by their brightness difference (so a roof's own colour
patterns stay). The brightness (Y) is never changed.

That is only as right as the surface's outlines. On a matched DSM whose outlines are a cell or two
off, taking every cell's colour from its DSM side paints the roof's colour onto the ground cells
that the DSM puts on the roof. Mode ``checked`` (the default) therefore replaces a cell's colour
only when the photo agrees: when the cell's colour is already nearer its own surface's than the
other side's (the same weighted mean over the other segments' cells). A cell that the photo shows
as the other side, a ground cell the DSM raised to the roof, keeps its colour. Mode ``surface``
replaces every cell near a step, for exact surfaces (a LiDAR DSM, a building model).

Measured on the battery's 12 scenes of seed 2026 (``bench/acceptance.py``, figures in
``docs/acceptance.md``; here with the battery's OSGM DSMs and truth DSMs of one run), ghosting
median / worst: on the truth DSM 0.30 / 0.84 % without, 0.21 / 0.31 % ``checked``, 0.11 / 0.20 %
``surface``; on OSGM's DSM 14.1 / 22.0 % without, 13.7 / 21.3 % ``checked`` (lower on all 12),
16.7 / 23.6 % ``surface``.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..imagery import REC601, REC601_CB, REC601_CR, REC601_INV
from ..jit import njit

#: Cells from a height step whose colour is replaced: the smear of 4:2:0 JPEG colour after the
#: decoder and the ortho's bilinear sampling, at an output cell about the image pixel (2-3 pixels).
REACH = 3
#: Half side of the window the colour is taken from (cells): reaches :data:`REACH` + 2 cells past
#: the step from the cells next to it.
WINDOW = REACH + 2
#: Spread of the brightness difference (fraction of the value range) over which a cell's weight
#: falls by e^-1/2: a roof's own texture stays, a bright and a dark material do not mix.
SIGMA_LUMA = 0.1
#: The modes of :attr:`~.pipeline.TrueOrthoConfig.edge_colour`: ``off``; ``checked`` (default), a
#: cell's colour is replaced only when it is already nearer its own surface's colour than the
#: other side's; ``surface``, every cell near a step (for exact surfaces).
EDGE_COLOURS = ("off", "checked", "surface")


@njit
def _kernel(y, cb, cr, seg, alpha, dstep, reach, space, sy, gate, out_b, out_r):
    """``out_b``, ``out_r``: Cb, Cr of every cell within ``reach`` of a step (``dstep``, distance to
    the nearest step cell) replaced by its own segment's weighted mean over the ``(2 win + 1)^2``
    window of the spatial weights ``space`` (with ``gate``: only where the cell's colour is nearer
    that mean than the other segments'); every other cell's copied."""
    rows, cols = y.shape
    win = space.shape[0] // 2
    for i in range(rows):
        for j in range(cols):
            out_b[i, j] = cb[i, j]
            out_r[i, j] = cr[i, j]
            if not alpha[i, j] or seg[i, j] < 0 or dstep[i, j] > reach:
                continue
            nb = 0.0
            nr = 0.0
            den = 0.0
            ob = 0.0
            orr = 0.0
            oden = 0.0
            for di in range(-win, win + 1):
                ii = i + di
                if ii < 0 or ii >= rows:
                    continue
                for dj in range(-win, win + 1):
                    jj = j + dj
                    if jj < 0 or jj >= cols or not alpha[ii, jj] or seg[ii, jj] < 0:
                        continue
                    f = min(1.0, dstep[ii, jj] / reach)
                    if f <= 0.0:
                        continue
                    ws = f * f * space[di + win, dj + win]
                    if seg[ii, jj] != seg[i, j]:
                        ob += ws * cb[ii, jj]
                        orr += ws * cr[ii, jj]
                        oden += ws
                        continue
                    dy = (y[ii, jj] - y[i, j]) / sy
                    w = ws * np.exp(-0.5 * dy * dy)
                    nb += w * cb[ii, jj]
                    nr += w * cr[ii, jj]
                    den += w
            if den > 1e-6:
                vb = nb / den
                vr = nr / den
                if gate and oden > 1e-6:
                    # only a colour already nearer its own surface's than the other side's
                    d_own = (cb[i, j] - vb) ** 2 + (cr[i, j] - vr) ** 2
                    d_oth = (cb[i, j] - ob / oden) ** 2 + (cr[i, j] - orr / oden) ** 2
                    if d_own > d_oth:
                        continue
                out_b[i, j] = vb
                out_r[i, j] = vr


def surface_edge_colour(
    values: np.ndarray,
    alpha: np.ndarray,
    heights: np.ndarray,
    step: float,
    scale: float,
    checked: bool = True,
) -> np.ndarray:
    """``values`` (3, rows, cols) RGB of a mosaic, as float32, with the colour of the cells near
    height steps taken from their own surface (module docstring): a new array, the brightness and
    every other cell unchanged (not clipped: the caller's conversion to the output type clips).

    ``alpha`` (rows, cols): cells with a colour; ``heights`` (rows, cols): the surface on the same
    cells (NaN: none); ``step``: the smallest height difference (m) between two neighbouring cells
    that separates two surfaces; ``scale``: the value range (255 for 8-bit data), which the
    brightness weight is relative to; ``checked``: replace a cell's colour only when it is nearer
    its own surface's colour (the weighted mean) than the other surfaces' in the window (the same
    weights without the brightness term): the photo must put the cell on the side the heights do.

    Raises
    ------
    InputError
        ``values`` not (3, rows, cols), ``alpha`` or ``heights`` of another shape, ``step`` or
        ``scale`` not a finite number > 0.
    """
    v = np.asarray(values, np.float64)
    if v.ndim != 3 or v.shape[0] != 3:
        raise InputError(f"surface_edge_colour: expected (3, rows, cols) RGB values, got shape {v.shape}")
    shape = v.shape[1:]
    a = np.asarray(alpha, bool)
    h = np.asarray(heights, np.float64)
    if a.shape != shape or h.shape != shape:
        raise InputError(
            f"surface_edge_colour: alpha {a.shape} and heights {h.shape} must be the values' {shape}"
        )
    for name, x in (("step", step), ("scale", scale)):
        if not (np.isfinite(x) and x > 0):
            raise InputError(f"surface_edge_colour: {name} must be a finite number > 0, got {x!r}")
    from scipy.ndimage import distance_transform_edt

    from .select import segments

    seg = segments(np.where(a, h, np.nan), float(step))
    # the steps: cells with a 4-neighbour on another segment (neither without a surface)
    edge = np.zeros(shape, bool)
    across = (seg[:, 1:] != seg[:, :-1]) & (seg[:, 1:] >= 0) & (seg[:, :-1] >= 0)
    down = (seg[1:, :] != seg[:-1, :]) & (seg[1:, :] >= 0) & (seg[:-1, :] >= 0)
    edge[:, 1:] |= across
    edge[:, :-1] |= across
    edge[1:, :] |= down
    edge[:-1, :] |= down
    out = v.astype(np.float32)
    if not edge.any():
        return out
    dstep = distance_transform_edt(~edge)
    r, g, b = v
    y = REC601[0] * r + REC601[1] * g + REC601[2] * b
    cb = REC601_CB[0] * r + REC601_CB[1] * g + REC601_CB[2] * b
    cr = REC601_CR[0] * r + REC601_CR[1] * g + REC601_CR[2] * b
    ob = np.empty_like(cb)
    orr = np.empty_like(cr)
    # spatial weight of the window's cells, spread half the window (computed once, not per cell)
    d2 = np.add.outer(np.arange(-WINDOW, WINDOW + 1) ** 2, np.arange(-WINDOW, WINDOW + 1) ** 2)
    space = np.exp(-0.5 * d2 / ((WINDOW * WINDOW) / 4.0))
    sy = SIGMA_LUMA * float(scale)
    _kernel(y, cb, cr, seg, a, dstep, float(REACH), space, sy, bool(checked), ob, orr)
    zone = (ob != cb) | (orr != cr)  # the cells whose colour the kernel replaced
    ir, igb, igr, ib = REC601_INV
    new = (y + ir * orr, y - igb * ob - igr * orr, y + ib * ob)
    for k in range(3):
        out[k][zone] = new[k][zone]
    return out
