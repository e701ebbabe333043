"""Semi-global aggregation of a cost volume along 8 or 16 paths.

For every path direction ``r`` the path cost of cell ``p`` at level ``d``
follows Hirschmüller's recurrence

    L_r(p, d) = C(p, d) + min(L_r(q, d), L_r(q, d - 1) + P1, L_r(q, d + 1) + P1,
                              min_k L_r(q, k) + P2) - min_k L_r(q, k),      q = p - r,

started with ``L_r(p, d) = C(p, d)`` where ``q`` lies outside the grid, and
``S(p, d) = sum_r L_r(p, d)``.

Variable level windows
----------------------
Level ``k`` of cell ``p`` is the absolute level ``z0[p] + k`` (OSGM narrows
the Z search per cell, so neighbours cover different windows). The
recurrence is evaluated on **absolute** levels: for level ``a`` of ``p`` the
candidates are ``L_r(q, a)`` (no penalty), ``L_r(q, a - 1) + P1`` and
``L_r(q, a + 1) + P1``, each only where the neighbour's window contains that
level, and always ``min_k L_r(q, k) + P2`` (every other level of the
neighbour is a jump). A level of ``p`` that the neighbour does not cover and
is not adjacent to is thus reached by a P2 jump from the neighbour's
minimum; with equal offsets this is exactly the recurrence above.

Penalties and integer bounds
----------------------------
``P1`` applies to a change of one level, ``P2`` to larger changes; ``P2``
may vary per cell (the cell ``p`` being entered decides: see
:func:`adaptive_p2`). Since ``min(...) <= min_k L_r(q, k) + P2``, every path
cost is at most ``COST_MAX + P2``, so ``S <= 16 (COST_MAX + P2_MAX) = 65520``
fits ``uint16`` for every accepted ``P2 <= P2_MAX``; path costs and ``S`` are
``uint16``.

Parallel layout
---------------
The two horizontal paths are independent per row (``prange`` over rows).
All other paths step at least one row, so all cells of one row depend only
on earlier rows: a top-down sweep and a bottom-up sweep each carry the path
costs of the last two rows (the only buffers besides ``S``) and run the
cells of a row in parallel; the paths of one sweep are fused so that the
cost and ``S`` of a cell are touched once per sweep.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..jit import njit, pjit, prange
from .cost import COST_MAX

#: Largest accepted P2 (see the module docstring: ``16 (COST_MAX + P2_MAX) < 2^16``).
P2_MAX = 4095 - COST_MAX
#: Default P1: a quarter of ``COST_MAX`` (``COST_MAX`` is what unrelated
#: windows cost, :mod:`.cost`): a one-level change is taken where it saves a
#: quarter of a full mismatch, so slanted surfaces follow the data.
DEFAULT_P1 = 256
#: Default P2: twice ``COST_MAX``. One cell's cost can never exceed
#: ``COST_MAX``, so a larger jump needs contrary evidence from at least two
#: cells along a path: isolated outliers cannot create discontinuities.
DEFAULT_P2 = 2048
#: The path sets: (row step, column step) of the directions stepping down;
#: the bottom-up sweep uses their negatives, the horizontal paths are separate.
_DOWN8 = np.array([[1, 0], [1, 1], [1, -1]], np.int64)
_DOWN16 = np.array([[1, 0], [1, 1], [1, -1], [1, 2], [1, -2], [2, 1], [2, -1]], np.int64)
#: Sentinel of the padded path-cost buffers (never the minimum).
_SENT = 32767


@njit
def _first(cost, r, c, lout, s, assign):
    """Start of a path at (r, c): L = C. Returns min_d L."""
    nd = cost.shape[2]
    mn = 1 << 30
    for d in range(nd):
        v = np.int64(cost[r, c, d])
        lout[d + 2] = v
        if assign:
            s[r, c, d] = v
        else:
            s[r, c, d] += v
        if v < mn:
            mn = v
    return mn


@njit
def _step(cost, r, c, lq, mq, lout, off, p1, p2, s, assign):
    """One path step into (r, c) from a neighbour with path costs ``lq``.

    ``lq``/``lout`` are padded: level k at index k + 2, sentinels at 0, 1,
    nd + 2, nd + 3. ``off = z0[p] - z0[q]`` maps level d of p to level
    d + off of q. Adds (or assigns) the new path costs to ``s[r, c]``;
    returns their minimum.
    """
    nd = cost.shape[2]
    base = mq + p2
    lo = min(max(-off - 1, 0), nd)
    hi = min(max(nd - off + 1, 0), nd)
    mn = 1 << 30
    for d in range(lo):
        v = np.int64(cost[r, c, d]) + p2
        lout[d + 2] = v
        if assign:
            s[r, c, d] = v
        else:
            s[r, c, d] += v
        mn = min(mn, v)
    for d in range(lo, hi):
        e = d + off + 2
        v = min(min(np.int64(lq[e]), np.int64(lq[e - 1]) + p1), min(np.int64(lq[e + 1]) + p1, base))
        v = v + np.int64(cost[r, c, d]) - mq
        lout[d + 2] = v
        if assign:
            s[r, c, d] = v
        else:
            s[r, c, d] += v
        mn = min(mn, v)
    for d in range(hi, nd):
        v = np.int64(cost[r, c, d]) + p2
        lout[d + 2] = v
        if assign:
            s[r, c, d] = v
        else:
            s[r, c, d] += v
        mn = min(mn, v)
    return mn


@njit
def _p2_step(p2m, guide, edge, p1, r, c, rq, cq):
    """P2 of the step (rq, cq) -> (r, c): the cell's P2, lowered by the guide's
    intensity step when ``edge > 0``: ``max(p1 + 1, round(P2 edge / (edge + |g_p - g_q|)))``
    (a NaN guide step leaves P2 unchanged)."""
    p2 = np.int64(p2m[r, c])
    if edge > 0.0:
        g = abs(np.float64(guide[r, c]) - np.float64(guide[rq, cq]))
        if g == g:
            v = np.int64(p2 * edge / (edge + g) + 0.5)
            p2 = max(min(p2, np.int64(p1) + 1), v)
    return p2


@pjit
def _agg_rows(cost, z0, p2m, guide, edge, p1, s):
    """Both horizontal paths; assigns S (first kernel of :func:`aggregate`)."""
    rows, cols, nd = cost.shape
    for r in prange(rows):
        la = np.full(nd + 4, _SENT, np.uint16)
        lb = np.full(nd + 4, _SENT, np.uint16)
        mq = _first(cost, r, 0, la, s, True)
        for c in range(1, cols):
            p2 = _p2_step(p2m, guide, edge, p1, r, c, r, c - 1)
            mq = _step(cost, r, c, la, mq, lb, np.int64(z0[r, c]) - z0[r, c - 1], p1, p2, s, True)
            la, lb = lb, la
        mq = _first(cost, r, cols - 1, la, s, False)
        for c in range(cols - 2, -1, -1):
            p2 = _p2_step(p2m, guide, edge, p1, r, c, r, c + 1)
            mq = _step(cost, r, c, la, mq, lb, np.int64(z0[r, c]) - z0[r, c + 1], p1, p2, s, False)
            la, lb = lb, la


@pjit
def _agg_sweep(cost, z0, p2m, guide, edge, p1, s, dirs, down):
    """All non-horizontal paths of one vertical sweep (top-down or bottom-up); adds to S."""
    rows, cols, nd = cost.shape
    nk = dirs.shape[0]
    lbuf = np.full((3, nk, cols, nd + 4), _SENT, np.uint16)
    mbuf = np.zeros((3, nk, cols), np.int64)
    sgn = 1 if down else -1
    for i in range(rows):
        r = i if down else rows - 1 - i
        slot = i % 3
        for c in prange(cols):
            for k in range(nk):
                dr = dirs[k, 0]
                rq = r - sgn * dr
                cq = c - sgn * dirs[k, 1]
                if rq < 0 or rq >= rows or cq < 0 or cq >= cols:
                    mbuf[slot, k, c] = _first(cost, r, c, lbuf[slot, k, c], s, False)
                else:
                    qs = (i - dr) % 3
                    p2 = _p2_step(p2m, guide, edge, p1, r, c, rq, cq)
                    mbuf[slot, k, c] = _step(
                        cost, r, c, lbuf[qs, k, cq], mbuf[qs, k, cq], lbuf[slot, k, c],
                        np.int64(z0[r, c]) - z0[rq, cq], p1, p2, s, False,
                    )  # fmt: skip


def _check_p(p1, p2, shape) -> tuple[int, np.ndarray]:
    if isinstance(p1, bool) or not isinstance(p1, int | np.integer) or not (0 <= p1 < P2_MAX):
        raise InputError(f"p1: expected an integer penalty in [0, {P2_MAX}), got {p1!r}")
    p1 = int(p1)
    if np.ndim(p2) == 0:
        if isinstance(p2, bool) or not isinstance(p2, int | np.integer | float | np.floating):
            raise InputError(f"p2: expected an integer penalty or a (rows, cols) array, got {p2!r}")
        if not (p1 <= p2 <= P2_MAX) or p2 != int(p2):
            raise InputError(f"p2: expected an integer in [p1={p1}, P2_MAX={P2_MAX}], got {p2!r}")
        return p1, np.full(shape, int(p2), np.int32)
    a = np.asarray(p2)
    if a.shape != shape or not np.issubdtype(a.dtype, np.integer):
        raise InputError(f"p2: expected an integer array of shape {shape}, got {a.dtype} {a.shape}")
    if a.size and (a.min() < p1 or a.max() > P2_MAX):
        raise InputError(f"p2: values must lie in [p1={p1}, P2_MAX={P2_MAX}], got [{a.min()}, {a.max()}]")
    return p1, np.ascontiguousarray(a, dtype=np.int32)


def _check_z0(z0, shape) -> np.ndarray:
    if z0 is None:
        return np.zeros(shape, np.int32)
    a = np.asarray(z0)
    if a.shape != shape or not np.issubdtype(a.dtype, np.integer):
        raise InputError(f"z0: expected an integer array of shape {shape}, got {a.dtype} {a.shape}")
    return np.ascontiguousarray(a, dtype=np.int32)


def aggregate(
    cost: np.ndarray,
    p1: int = DEFAULT_P1,
    p2: int | np.ndarray = DEFAULT_P2,
    paths: int = 8,
    z0: np.ndarray | None = None,
    *,
    guide: np.ndarray | None = None,
    edge: float | None = None,
) -> np.ndarray:
    """Semi-global aggregation: the sum over paths of the path costs.

    Parameters
    ----------
    cost : (rows, cols, nd) uint16
        Matching costs in ``[0, COST_MAX]``; level k of cell (r, c) is the
        absolute level ``z0[r, c] + k``.
    p1 : int
        Penalty of a one-level change between neighbours (cost units).
    p2 : int or (rows, cols) integer array
        Penalty of a larger change, ``p1 <= p2 <= P2_MAX``; an array gives it
        per cell (the cell being entered along the path decides).
    paths : {8, 16}
        8: horizontal, vertical and diagonal paths (both ways); 16: plus the
        eight knight moves (1, +-2) and (2, +-1), both ways.
    z0 : (rows, cols) integer array, optional
        Absolute level of each cell's level 0 (None: all 0). Neighbours are
        compared on absolute levels (module docstring).
    guide : (rows, cols) float array, optional
        Intensity-adaptive P2 per path step (Hirschmüller): the step from q
        into p uses ``max(p1 + 1, round(P2(p) * edge / (edge + |guide[p] -
        guide[q]|)))`` (never above ``P2(p)``; NaN guide values leave P2
        unchanged), so depth jumps are cheaper across intensity edges and
        stay expensive along them.
    edge : float, optional
        Guide step that halves P2 (guide units). Default: 4 times the median
        of the non-zero horizontal and vertical guide steps (a typical texture
        step keeps 0.8 P2; invariant to the guide's gain).

    Returns
    -------
    S : (rows, cols, nd) uint16
        Sum over the paths; at most ``paths (COST_MAX + max p2) <= 65520``,
        so it cannot overflow.

    Memory: ``S`` plus path buffers of three rows per path of a sweep.
    """
    c = np.asarray(cost)
    if c.ndim != 3 or c.dtype != np.uint16 or min(c.shape) < 1:
        raise InputError(f"cost: expected a non-empty (rows, cols, nd) uint16 array, got {c.dtype} {c.shape}")
    if paths not in (8, 16):
        raise InputError(f"paths: expected 8 or 16, got {paths!r}")
    if c.size and int(c.max()) > COST_MAX:
        raise InputError(f"cost: values must lie in [0, COST_MAX={COST_MAX}], got max {int(c.max())}")
    shape = c.shape[:2]
    p1i, p2m = _check_p(p1, p2, shape)
    z = _check_z0(z0, shape)
    g, e = _check_guide(guide, edge, shape)
    c = np.ascontiguousarray(c)
    s = np.empty(c.shape, np.uint16)
    _agg_rows(c, z, p2m, g, e, p1i, s)
    dirs = _DOWN8 if paths == 8 else _DOWN16
    _agg_sweep(c, z, p2m, g, e, p1i, s, dirs, True)
    _agg_sweep(c, z, p2m, g, e, p1i, s, dirs, False)
    return s


def _default_edge(steps: np.ndarray) -> float:
    nz = steps[np.isfinite(steps) & (steps > 0)]
    return 4.0 * float(np.median(nz)) if nz.size else 1.0


def _check_guide(guide, edge, shape) -> tuple[np.ndarray, float]:
    if guide is None:
        return np.zeros((1, 1), np.float32), 0.0
    g = np.asarray(guide, dtype=np.float32)
    if g.shape != shape:
        raise InputError(f"guide: expected a (rows, cols) = {shape} image, got shape {g.shape}")
    if edge is None:
        with np.errstate(invalid="ignore"):
            steps = np.concatenate([np.abs(np.diff(g, axis=0)).ravel(), np.abs(np.diff(g, axis=1)).ravel()])
        e = _default_edge(steps)
    else:
        e = float(edge)
        if not (e > 0 and np.isfinite(e)):
            raise InputError(f"edge: expected a positive guide step, got {edge!r}")
    return np.ascontiguousarray(g), e


def adaptive_p2(
    image: np.ndarray,
    p1: int = DEFAULT_P1,
    p2: int = DEFAULT_P2,
    edge: float | None = None,
) -> np.ndarray:
    """Per-cell P2 lowered across intensity edges.

    ``P2(p) = max(p1 + 1, round(p2 * edge / (edge + g(p))))`` with ``g(p)``
    the largest absolute intensity difference between ``p`` and its 8
    neighbours (NaN neighbours ignored; 0 where ``p`` is NaN). Depth jumps
    are more likely across image edges, so they become cheaper there
    (Hirschmüller's intensity-adaptive P2, isotropic).

    Parameters
    ----------
    image : (rows, cols) float array
        The reference image on the grid (NaN = no data).
    p1, p2 : int
        The penalties; ``p1 < p2 <= P2_MAX``.
    edge : float, optional
        Intensity difference that halves P2 (image units). Default: four times
        the median of the non-zero ``g`` over the image (typical texture keeps
        about 0.8 P2, strong edges get a small fraction), so the rule is
        invariant to the image's gain.

    Returns
    -------
    (rows, cols) int32
        In ``[p1 + 1, p2]``.
    """
    img = np.asarray(image, dtype=np.float32)
    if img.ndim != 2:
        raise InputError(f"adaptive_p2: expected a 2-D image, got shape {img.shape}")
    p1i, p2a = _check_p(p1, p2, img.shape)
    p2i = int(p2a.flat[0]) if p2a.size else int(p2)
    if p2i <= p1i:
        raise InputError(f"p2: expected p2 > p1 for an adaptive P2, got p1={p1i}, p2={p2i}")
    pad = np.pad(img, 1, constant_values=np.nan)
    g = np.zeros(img.shape, np.float32)
    rows, cols = img.shape
    with np.errstate(invalid="ignore"):
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                if dr == 0 and dc == 0:
                    continue
                d = np.abs(pad[1 + dr : 1 + dr + rows, 1 + dc : 1 + dc + cols] - img)
                g = np.fmax(g, d)
    g = np.nan_to_num(g, nan=0.0)
    if edge is None:
        nz = g[g > 0]
        e = 4.0 * float(np.median(nz)) if nz.size else 1.0
    else:
        e = float(edge)
        if not (e > 0 and np.isfinite(e)):
            raise InputError(f"edge: expected a positive intensity difference, got {edge!r}")
    out = np.rint(p2i * e / (e + g.astype(np.float64)))
    return np.clip(out, p1i + 1, p2i).astype(np.int32)
