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
All paths of one vertical direction are fused into one sweep: the top-down
sweep (left to right within a row) carries the left-to-right horizontal path
and the paths stepping down (vertical, both diagonals, and for 16 paths the
four knight moves), the bottom-up sweep (right to left) the mirror images;
each carries the path costs of its last three rows (the only buffers
besides ``S``), and a cell's costs and ``S`` are touched once per sweep. The
two sweeps run on two threads with a single synchronisation: first the
down sweep over the top half of the rows and the up sweep over the bottom
half, then the other halves; in each phase they write disjoint rows of
``S``. (Per-row parallelism would need a barrier per row, which costs more
than it gains on a loaded two-core machine.)
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


_U = np.uint64


@njit
def _first(cf, cb, lf, ob, sf, nd, assign):
    """Start of a path at the cell whose costs start at ``cf[cb]``: L = C.

    Flat buffers with unsigned offsets (no array views: each view costs an
    atomic reference count, and signed indices cost wraparound code that
    stops vectorisation): ``lf[ob + 2 + d]`` receives L, ``sf[cb + d]`` (S has
    the layout of the costs) is increased by it (set to it when ``assign``:
    the first path written into a cell). Returns min_d L.
    """
    mn = np.uint16(65535)
    o = ob + _U(2)
    if assign:  # separate loops: a conditional load would not vectorise
        for d in range(nd):
            i = _U(d)
            v = cf[cb + i]
            lf[o + i] = v
            sf[cb + i] = v
            mn = min(mn, v)
    else:
        for d in range(nd):
            i = _U(d)
            v = cf[cb + i]
            lf[o + i] = v
            sf[cb + i] = np.uint16(sf[cb + i] + v)
            mn = min(mn, v)
    return np.int64(mn)


@njit
def _step(cf, cb, lf, qb, mq, ob, off, p1, p2, sf, nd, assign):
    """One path step into the cell with costs ``cf[cb:cb + nd]`` from a neighbour
    whose path costs are ``lf[qb + 2 + k]`` (minimum ``mq``).

    Path-cost buffers are padded: level k at offset k + 2, sentinels at 0, 1,
    nd + 2, nd + 3. ``off = z0[p] - z0[q]`` maps level d of p to level
    d + off of q. Writes the new path costs to ``lf[ob + 2 + d]``, adds them
    to ``sf[cb + d]`` (or sets it, ``assign``); returns their minimum. All arithmetic stays in
    ``uint16`` (no value exceeds ``COST_MAX + P2_MAX`` or the sentinel plus
    P1, and ``min(...) >= mq``), so the main loop vectorises.
    """
    u1 = np.uint16(p1)
    u2 = np.uint16(p2)
    m16 = np.uint16(mq)
    base = np.uint16(mq + p2)
    lo = min(max(-off - 1, 0), nd)
    hi = min(max(nd - off + 1, 0), nd)
    o = ob + _U(2)
    mn = np.uint16(65535)
    for d in range(lo):
        i = _U(d)
        v = np.uint16(cf[cb + i] + u2)
        lf[o + i] = v
        sf[cb + i] = v if assign else np.uint16(sf[cb + i] + v)
        mn = min(mn, v)
    e = qb + _U(lo + off + 1)  # offset of neighbour level (lo + off - 1); lo + off + 1 >= 0
    c0 = cb + _U(lo)
    o0 = o + _U(lo)
    if assign:  # separate loops: a conditional load would not vectorise
        for d in range(hi - lo):
            t = _U(d)
            a = min(lf[e + _U(1) + t], np.uint16(lf[e + t] + u1))
            b = min(np.uint16(lf[e + _U(2) + t] + u1), base)
            v = np.uint16(np.uint16(min(a, b) - m16) + cf[c0 + t])
            lf[o0 + t] = v
            sf[c0 + t] = v
            mn = min(mn, v)
    else:
        for d in range(hi - lo):
            t = _U(d)
            a = min(lf[e + _U(1) + t], np.uint16(lf[e + t] + u1))
            b = min(np.uint16(lf[e + _U(2) + t] + u1), base)
            v = np.uint16(np.uint16(min(a, b) - m16) + cf[c0 + t])
            lf[o0 + t] = v
            sf[c0 + t] = np.uint16(sf[c0 + t] + v)
            mn = min(mn, v)
    for d in range(hi, nd):
        i = _U(d)
        v = np.uint16(cf[cb + i] + u2)
        lf[o + i] = v
        sf[cb + i] = v if assign else np.uint16(sf[cb + i] + v)
        mn = min(mn, v)
    return np.int64(mn)


@njit
def _step4(
    cf, cb, lf, q0, q1, q2, q3, m0, m1, m2, m3, o0, o1, o2, o3, p1, p20, p21, p22, p23, sf, nd, assign
):
    """Four path steps into one cell at once, for neighbours on the same level
    window (offset 0): one pass over the levels, one update of S. Path k reads
    ``lf[qk + 2 + d]`` (minimum ``mk``) and writes ``lf[ok + 2 + d]``; returns the
    four minima. Same arithmetic as :func:`_step`."""
    u1 = np.uint16(p1)
    a0 = np.uint16(m0)
    a1 = np.uint16(m1)
    a2 = np.uint16(m2)
    a3 = np.uint16(m3)
    b0 = np.uint16(m0 + p20)
    b1 = np.uint16(m1 + p21)
    b2 = np.uint16(m2 + p22)
    b3 = np.uint16(m3 + p23)
    n0 = np.uint16(65535)
    n1 = np.uint16(65535)
    n2 = np.uint16(65535)
    n3 = np.uint16(65535)
    two = _U(2)
    one = _U(1)
    if assign:  # separate loops: a conditional load would not vectorise
        for d in range(nd):
            t = _U(d)
            cc = cf[cb + t]
            e = q0 + one + t
            v0 = np.uint16(
                np.uint16(
                    min(min(lf[e + one], np.uint16(lf[e] + u1)), min(np.uint16(lf[e + two] + u1), b0)) - a0
                )
                + cc
            )
            e = q1 + one + t
            v1 = np.uint16(
                np.uint16(
                    min(min(lf[e + one], np.uint16(lf[e] + u1)), min(np.uint16(lf[e + two] + u1), b1)) - a1
                )
                + cc
            )
            e = q2 + one + t
            v2 = np.uint16(
                np.uint16(
                    min(min(lf[e + one], np.uint16(lf[e] + u1)), min(np.uint16(lf[e + two] + u1), b2)) - a2
                )
                + cc
            )
            e = q3 + one + t
            v3 = np.uint16(
                np.uint16(
                    min(min(lf[e + one], np.uint16(lf[e] + u1)), min(np.uint16(lf[e + two] + u1), b3)) - a3
                )
                + cc
            )
            lf[o0 + two + t] = v0
            lf[o1 + two + t] = v1
            lf[o2 + two + t] = v2
            lf[o3 + two + t] = v3
            v = np.uint16(np.uint16(v0 + v1) + np.uint16(v2 + v3))
            sf[cb + t] = v
            n0 = min(n0, v0)
            n1 = min(n1, v1)
            n2 = min(n2, v2)
            n3 = min(n3, v3)
    else:
        for d in range(nd):
            t = _U(d)
            cc = cf[cb + t]
            e = q0 + one + t
            v0 = np.uint16(
                np.uint16(
                    min(min(lf[e + one], np.uint16(lf[e] + u1)), min(np.uint16(lf[e + two] + u1), b0)) - a0
                )
                + cc
            )
            e = q1 + one + t
            v1 = np.uint16(
                np.uint16(
                    min(min(lf[e + one], np.uint16(lf[e] + u1)), min(np.uint16(lf[e + two] + u1), b1)) - a1
                )
                + cc
            )
            e = q2 + one + t
            v2 = np.uint16(
                np.uint16(
                    min(min(lf[e + one], np.uint16(lf[e] + u1)), min(np.uint16(lf[e + two] + u1), b2)) - a2
                )
                + cc
            )
            e = q3 + one + t
            v3 = np.uint16(
                np.uint16(
                    min(min(lf[e + one], np.uint16(lf[e] + u1)), min(np.uint16(lf[e + two] + u1), b3)) - a3
                )
                + cc
            )
            lf[o0 + two + t] = v0
            lf[o1 + two + t] = v1
            lf[o2 + two + t] = v2
            lf[o3 + two + t] = v3
            v = np.uint16(np.uint16(v0 + v1) + np.uint16(v2 + v3))
            sf[cb + t] = np.uint16(sf[cb + t] + v)
            n0 = min(n0, v0)
            n1 = min(n1, v1)
            n2 = min(n2, v2)
            n3 = min(n3, v3)
    return np.int64(n0), np.int64(n1), np.int64(n2), np.int64(n3)


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


@njit
def _sweep(cost, z0, p2m, guide, edge, p1, s, dirs, down, i0, i1, lf, mbuf, touch, tr, kmax):
    """Steps ``i0 <= i < i1`` of one vertical sweep, all its paths fused.

    Down (``down``): rows ``i`` top to bottom, columns left to right, with the
    left-to-right horizontal path; up: rows ``rows - 1 - i``, columns right
    to left, with the right-to-left path. ``dirs`` are the non-horizontal
    directions (row step > 0, negated for the up sweep). ``lf`` is flat
    ``(3, k, cols, nd + 4)`` followed by ``(2, nd + 4)``: the path costs of
    the last three rows and of the horizontal path; ``mbuf`` (3, k, cols)
    their minima. The buffers persist between calls, so a sweep can be split
    in row ranges (the horizontal path restarts on every row). ``touch``: this
    call is the first to write these rows of ``s`` (it assigns instead of
    adding). Paths are stepped four at a time (:func:`_step4`) where the four
    neighbours share the cell's level window.
    """
    rows, cols, nd = cost.shape
    nk = dirs.shape[0]
    npth = nk + 1
    cf = cost.reshape(-1)
    sf = s.reshape(-1)
    w = nd + 4
    und = _U(nd)
    hoff = 3 * nk * cols * w
    sgn = 1 if down else -1
    reach = 0  # largest column step of the directions
    for k in range(nk):
        reach = max(reach, abs(dirs[k, 1]))
    start = np.empty(npth, np.bool_)
    qbs = np.empty(npth, np.uint64)
    obs = np.empty(npth, np.uint64)
    mqs = np.empty(npth, np.int64)
    offs = np.empty(npth, np.int64)
    p2s = np.empty(npth, np.int64)
    mout = np.empty(npth, np.int64)
    hm = np.int64(0)  # a local: the two sweeps' threads must not share a cache line
    for i in range(i0, i1):
        r = i if down else rows - 1 - i
        slot = i % 3
        qs1 = (i - 1) % 3
        rq1 = r - sgn
        inner_row = nk == 3 and 0 <= rq1 < rows
        for j in range(cols):
            c = j if down else cols - 1 - j
            cb = _U(r * cols + c) * und
            zc = np.int64(z0[r, c])
            if inner_row and j > 0 and reach <= c < cols - reach:
                # 8 paths, interior cell: horizontal, vertical, both diagonals in one pass
                c1 = c - sgn * dirs[1, 1]
                c2 = c - sgn * dirs[2, 1]
                cq = c - sgn
                tc = tr[r, c]
                if (
                    z0[r, cq] == zc and z0[rq1, c] == zc and z0[rq1, c1] == zc and z0[rq1, c2] == zc
                    and _rise(tc, tr[r, cq], kmax) == 0 and _rise(tc, tr[rq1, c], kmax) == 0
                    and _rise(tc, tr[rq1, c1], kmax) == 0 and _rise(tc, tr[rq1, c2], kmax) == 0
                ):  # fmt: skip
                    row = (qs1 * nk) * cols
                    hm, m1, m2, m3 = _step4(
                        cf, cb, lf,
                        _U(hoff + ((j - 1) % 2) * w), _U((row + c) * w),
                        _U((row + cols + c1) * w), _U((row + 2 * cols + c2) * w),
                        hm, mbuf[qs1, 0, c], mbuf[qs1, 1, c1], mbuf[qs1, 2, c2],
                        _U(hoff + (j % 2) * w), _U(((slot * nk) * cols + c) * w),
                        _U(((slot * nk + 1) * cols + c) * w), _U(((slot * nk + 2) * cols + c) * w),
                        p1, _p2_step(p2m, guide, edge, p1, r, c, r, cq),
                        _p2_step(p2m, guide, edge, p1, r, c, rq1, c),
                        _p2_step(p2m, guide, edge, p1, r, c, rq1, c1),
                        _p2_step(p2m, guide, edge, p1, r, c, rq1, c2), sf, nd, touch,
                    )  # fmt: skip
                    mbuf[slot, 0, c] = m1
                    mbuf[slot, 1, c] = m2
                    mbuf[slot, 2, c] = m3
                    continue
            # path 0: horizontal (from c - 1 going down, from c + 1 going up)
            obs[0] = _U(hoff + (j % 2) * w)
            start[0] = j == 0
            if j > 0:
                cq = c - sgn
                qbs[0] = _U(hoff + ((j - 1) % 2) * w)
                mqs[0] = hm
                offs[0] = zc - z0[r, cq] - _rise(tr[r, c], tr[r, cq], kmax)
                p2s[0] = _p2_step(p2m, guide, edge, p1, r, c, r, cq)
            for k in range(nk):
                dr = dirs[k, 0]
                rq = r - sgn * dr
                cq = c - sgn * dirs[k, 1]
                obs[k + 1] = _U(((slot * nk + k) * cols + c) * w)
                st = rq < 0 or rq >= rows or cq < 0 or cq >= cols
                start[k + 1] = st
                if not st:
                    qs = (i - dr) % 3
                    qbs[k + 1] = _U(((qs * nk + k) * cols + cq) * w)
                    mqs[k + 1] = mbuf[qs, k, cq]
                    offs[k + 1] = zc - z0[rq, cq] - _rise(tr[r, c], tr[rq, cq], kmax)
                    p2s[k + 1] = _p2_step(p2m, guide, edge, p1, r, c, rq, cq)
            g = 0
            assign = touch
            while g < npth:
                if g + 4 <= npth:
                    fuse = True
                    for q in range(g, g + 4):
                        if start[q] or offs[q] != 0:
                            fuse = False
                    if fuse:
                        mout[g], mout[g + 1], mout[g + 2], mout[g + 3] = _step4(
                            cf, cb, lf, qbs[g], qbs[g + 1], qbs[g + 2], qbs[g + 3],
                            mqs[g], mqs[g + 1], mqs[g + 2], mqs[g + 3],
                            obs[g], obs[g + 1], obs[g + 2], obs[g + 3],
                            p1, p2s[g], p2s[g + 1], p2s[g + 2], p2s[g + 3], sf, nd, assign,
                        )  # fmt: skip
                        assign = False
                        g += 4
                        continue
                if start[g]:
                    mout[g] = _first(cf, cb, lf, obs[g], sf, nd, assign)
                else:
                    mout[g] = _step(cf, cb, lf, qbs[g], mqs[g], obs[g], offs[g], p1, p2s[g], sf, nd, assign)
                assign = False
                g += 1
            hm = mout[0]
            for k in range(nk):
                mbuf[slot, k, c] = mout[k + 1]


@njit
def _rise(tp, tq, kmax):
    """The trend's rise from q into p if it is a slope (``|rise| <= kmax``), else 0."""
    d = np.int64(tp) - np.int64(tq)
    return d if -kmax <= d <= kmax else np.int64(0)


@pjit
def _aggregate_kernel(cost, z0, p2m, guide, edge, p1, s, dirs, tr, kmax):
    """Both sweeps on two threads: phase 0 runs the down sweep on the top half
    of the rows and the up sweep on the bottom half (each writes its rows of
    ``s`` first), phase 1 swaps the halves (adding); in each phase the two
    tasks touch disjoint rows of ``s``."""
    rows, cols, nd = cost.shape
    nk = dirs.shape[0]
    n = (3 * nk * cols + 2) * (nd + 4)
    lf = np.full(2 * n, _SENT, np.uint16)
    mbuf = np.zeros((2, 3, nk, cols), np.int64)
    half = rows // 2
    for phase in range(2):
        for t in prange(2):
            if t == 0:
                a = 0 if phase == 0 else half
                b = half if phase == 0 else rows
                _sweep(cost, z0, p2m, guide, edge, p1, s, dirs, True, a, b, lf[:n], mbuf[0], phase == 0,
                       tr, kmax)  # fmt: skip
            else:
                a = 0 if phase == 0 else rows - half
                b = rows - half if phase == 0 else rows
                _sweep(cost, z0, p2m, guide, edge, p1, s, dirs, False, a, b, lf[n:], mbuf[1], phase == 0,
                       tr, kmax)  # fmt: skip


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


#: A cell without a trend (:func:`aggregate`): its rise to any neighbour exceeds every ``trend_max``.
TREND_NONE = -(1 << 30)


def _check_trend(trend, trend_max, shape) -> tuple[np.ndarray, int]:
    k = trend_max
    if isinstance(k, bool) or not isinstance(k, int | np.integer) or not 0 <= k < 1 << 20:
        raise InputError(f"trend_max: expected an integer number of levels in [0, 2^20), got {trend_max!r}")
    if trend is None or trend_max == 0:
        return np.zeros(shape, np.int32), 0  # the kernel reads every cell's trend
    a = np.asarray(trend)
    if a.shape != shape or not np.issubdtype(a.dtype, np.integer):
        raise InputError(f"trend: expected an integer array of shape {shape}, got {a.dtype} {a.shape}")
    return np.ascontiguousarray(a, dtype=np.int32), int(trend_max)


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
    trend: np.ndarray | None = None,
    trend_max: int = 0,
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
    trend : (rows, cols) integer array, optional
        A smooth prior of each cell's absolute level (e.g. the coarser pyramid
        level's surface) or :data:`TREND_NONE`. A step from q into p whose
        trend rises by ``t = trend[p] - trend[q]`` with ``|t| <= trend_max``
        compares p's level ``a`` with q's level ``a - t``: a slanted surface
        that follows the trend pays no P1/P2 for its slope, only for departing
        from it. Larger rises (height steps) and :data:`TREND_NONE` cells are
        compared on absolute levels, as without a trend.
    trend_max : int
        Largest trend rise per step that is compensated (0: none).

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
    s = np.empty(c.shape, np.uint16)  # every cell is assigned by its first sweep
    t, kmax = _check_trend(trend, trend_max, shape)
    _aggregate_kernel(c, z, p2m, g, e, p1i, s, _DOWN8 if paths == 8 else _DOWN16, t, kmax)
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
