"""Texture selection: which image colours each cell.

Data term
---------
For cell ``p`` and candidate image ``i`` that sees it (:mod:`.zbuffer`), the
*effective ground resolution* ``e_i(p) = |P - C_i| / (f_i cos(theta_i))`` is the
size (metres) of one image pixel on the surface, with ``theta_i`` the angle
between the viewing ray and the surface normal: it grows with distance and with
grazing incidence. The data cost is ``D_i(p) = e_i(p) / min_j e_j(p) - 1``
(0 for the best image of the cell) plus ``edge_penalty`` when the cell lies
within one depth-buffer pixel of an occluder in image ``i`` (its colour there
may mix in the occluding facade or roof). Cells no image sees have no label.

Smoothness term
---------------
Potts: a seam between 4-neighbours ``p, q`` with labels ``a != b`` costs
``smoothness * w_pq * (1 + contrast * (|I_a(p) - I_b(p)| + |I_a(q) - I_b(q)|))``
with ``w_pq = exp(-|h_p - h_q| / h0)``: cutting along a height discontinuity
(a building outline) is nearly free, cutting across a roof or open ground is
not, and where the two images disagree in luminance ``I`` (misregistration,
strong edges seen differently) a seam is more expensive
(Kwatra et al.'s graph-cut-textures seam cost).

Agreement of the views
----------------------
Where the surface is wrong (a matched DSM's raised ground beside a wall, a roof corner matched
too low) or a photo holds what the others do not (a car that moved, a person), the image that wins
the data term can show something other than the cell, although the other images that see the cell
agree on its colour. With at least three candidates, the per-band median of their (corrected)
colours is the cell's consensus; a candidate farther than ``tau`` from it on some band, in a cell
where at least two candidates lie within ``tau``, costs :data:`DISAGREE_PENALTY` more
(:func:`add_disagreement`). One or two candidates say nothing about which is right and are left
alone, as are cells whose candidates scatter.

Optimisation
------------
The energy is minimised approximately (:func:`select_labels`):

1. *segments*: cells connected through 4-neighbour steps below the
   discontinuity height (roofs, terrain patches); every segment smaller than
   ``max_segment_cells`` (a building's roof plane or a whole roof) is
   initialised with the single image of least total cost among those that see
   at least ``segment_cover`` of its cells, so no seam starts inside a roof;
   larger segments (open ground; also a segment cut by the window border that
   fills a quarter of the window) start from the per-cell best label. Labels
   written by neighbouring tiles are kept and their segments continue them;
2. iterated conditional modes (sequential sweeps, each cell takes the label of
   least local energy given its neighbours) until no label changes or
   ``sweeps`` is reached. ICM only lowers the energy; with the segment start it
   moves seams onto discontinuities and removes islands.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from ..jit import njit
from ..quickselect import median_of

NO_LABEL = -1


def data_costs(eff_res: np.ndarray, visible: np.ndarray, near_edge: np.ndarray, edge_penalty: float = 1.0):
    """Data cost ``(K, rows, cols)`` float32, inf where not visible (see module docstring)."""
    K = visible.shape[0]
    out = np.empty(visible.shape, np.float32)
    if K:
        _data_costs(
            np.ascontiguousarray(eff_res, np.float32),
            np.ascontiguousarray(visible),
            np.ascontiguousarray(near_edge),
            float(edge_penalty),
            out,
        )
    return out


@njit
def _data_costs(eff, vis, edge, penalty, out):
    K, rows, cols = vis.shape
    for r in range(rows):
        for c in range(cols):
            best = np.inf
            for k in range(K):
                if vis[k, r, c] and eff[k, r, c] < best:
                    best = eff[k, r, c]
            best = max(best, 1e-30)
            for k in range(K):
                if vis[k, r, c]:
                    v = np.float64(eff[k, r, c]) / np.float64(best) - 1.0
                    if edge[k, r, c]:
                        v += penalty
                    out[k, r, c] = v
                else:
                    out[k, r, c] = np.inf


#: Data cost added to a candidate whose colour disagrees with the consensus of a cell's views
#: (module docstring): an agreeing view wins unless its pixels on the surface are more than three
#: times as large.
DISAGREE_PENALTY = 2.0


def add_disagreement(cost: np.ndarray, colours: np.ndarray, usable: np.ndarray, tau: float) -> np.ndarray:
    """Add :data:`DISAGREE_PENALTY` to ``cost`` (K, rows, cols) float32, in place, for the usable
    candidates whose colour (``colours`` (K, rows, cols, bands), NaN where not sampled) lies more
    than ``tau`` (value units) from the per-band median of the cell's usable candidates on some
    band, in the cells with at least three usable candidates of which at least two lie within
    ``tau`` (module docstring). Returns the (K, rows, cols) bool mask of the penalised entries (the
    blend leaves them out too)."""
    if usable.ndim != 3 or colours.ndim != 4:
        raise InputError(
            f"add_disagreement: expected usable (K, rows, cols) and colours (K, rows, cols, bands), "
            f"got {usable.shape} and {colours.shape}"
        )
    K, rows, cols = usable.shape
    if colours.shape[:3] != (K, rows, cols) or cost.shape != (K, rows, cols):
        shapes = f"{cost.shape}, {colours.shape}, {usable.shape}"
        raise InputError(f"add_disagreement: shapes {shapes} of cost, colours and usable do not match")
    if not (tau > 0.0 and math.isfinite(tau)):
        raise InputError(f"add_disagreement: tau must be a positive number, got {tau!r}")
    far = np.zeros((K, rows, cols), np.bool_)
    if K >= 3:
        _add_disagreement(cost, colours, usable, float(tau), DISAGREE_PENALTY, far)
    return far


@njit
def _add_disagreement(cost, colours, usable, tau, penalty, out):
    K, rows, cols, B = colours.shape
    idx = np.empty(K, np.int64)
    vals = np.empty(K)
    med = np.empty(B)
    far = np.empty(K, np.bool_)
    for r in range(rows):
        for c in range(cols):
            n = 0
            for k in range(K):
                if usable[k, r, c] and colours[k, r, c, 0] == colours[k, r, c, 0]:
                    idx[n] = k
                    n += 1
            if n < 3:
                continue
            for b in range(B):
                for j in range(n):
                    vals[j] = colours[idx[j], r, c, b]
                med[b] = median_of(vals, n)
            agree = 0
            for j in range(n):
                far[j] = False
                for b in range(B):
                    if abs(colours[idx[j], r, c, b] - med[b]) > tau:
                        far[j] = True
                        break
                if not far[j]:
                    agree += 1
            if agree >= 2:
                for j in range(n):
                    if far[j]:
                        cost[idx[j], r, c] += penalty
                        out[idx[j], r, c] = True


def edge_weights(h: np.ndarray, h0: float):
    """Potts weights of horizontal (rows, cols-1) and vertical (rows-1, cols) neighbour pairs."""
    hz = np.where(np.isfinite(h), h, -1e6)
    with np.errstate(over="ignore"):
        wh = np.exp(-np.abs(hz[:, 1:] - hz[:, :-1]) / h0).astype(np.float32)
        wv = np.exp(-np.abs(hz[1:, :] - hz[:-1, :]) / h0).astype(np.float32)
    return wh, wv


def segments(h: np.ndarray, step: float) -> np.ndarray:
    """Connected components (4-neighbours) of cells joined by height steps <= ``step``; -1 for no data.

    Components are numbered in the order of their first cell (row-major).
    """
    hh = np.ascontiguousarray(h, dtype=np.float64)
    out = np.empty(hh.shape, np.int64)
    _segments(hh, float(step), out)
    return out


@njit
def _root(parent, x):
    while parent[x] != x:
        parent[x] = parent[parent[x]]
        x = parent[x]
    return x


@njit
def _segments(h, step, out):
    rows, cols = h.shape
    parent = np.arange(rows * cols)
    for r in range(rows):
        for c in range(cols):
            a = h[r, c]
            if not np.isfinite(a):
                continue
            i = r * cols + c
            if c + 1 < cols and np.isfinite(h[r, c + 1]) and abs(h[r, c + 1] - a) <= step:
                x, y = _root(parent, i), _root(parent, i + 1)
                if x != y:
                    parent[max(x, y)] = min(x, y)
            if r + 1 < rows and np.isfinite(h[r + 1, c]) and abs(h[r + 1, c] - a) <= step:
                x, y = _root(parent, i), _root(parent, i + cols)
                if x != y:
                    parent[max(x, y)] = min(x, y)
    label = np.full(rows * cols, -1, np.int64)
    n = 0
    for r in range(rows):
        for c in range(cols):
            if not np.isfinite(h[r, c]):
                out[r, c] = -1
                continue
            x = _root(parent, r * cols + c)
            if label[x] < 0:
                label[x] = n
                n += 1
            out[r, c] = label[x]


def initial_labels(
    cost: np.ndarray,
    h: np.ndarray,
    step: float,
    max_segment_cells: int,
    segment_cover: float = 0.9,
    fixed: np.ndarray | None = None,
) -> np.ndarray:
    """Per-cell best label, replaced by one label per small segment (module docstring, step 1).

    ``fixed`` (rows, cols) holds labels decided by neighbouring tiles (-1 = free): a segment
    with fixed cells takes their most frequent label when that image sees enough of it, and
    fixed cells keep their label.
    """
    K, rows, cols = cost.shape
    cost = np.ascontiguousarray(cost, np.float32)
    lab = np.empty((rows, cols), np.int32)
    _best_label(cost, lab)
    any_vis = lab >= 0
    if fixed is not None:
        fx = np.asarray(fixed)
        fixed_ok = (fx >= 0) & np.isfinite(np.take_along_axis(cost, np.clip(fx, 0, K - 1)[None], axis=0)[0])
    if K < 2:
        return lab
    seg = segments(h, step)
    valid = seg >= 0
    if not valid.any():
        return lab
    if fixed is None:
        fixed_ok = np.zeros((rows, cols), bool)
    s = seg[valid]
    nseg = int(s.max()) + 1
    size = np.bincount(s, minlength=nseg)
    small = (size >= 2) & (size <= max_segment_cells)
    # a segment cut by the window border may be much larger than it looks (open ground): one that
    # fills a quarter of the window is treated as large
    border = np.unique(np.concatenate([seg[0], seg[-1], seg[:, 0], seg[:, -1]]))
    border = border[border >= 0]
    small[border] &= size[border] <= 0.25 * rows * cols
    if not small.any():
        return lab
    # per segment and image: cells seen and summed cost
    seen = np.zeros((K, nseg))
    total = np.zeros((K, nseg))
    _segment_sums(cost, seg, small, seen, total)
    cover = seen / np.maximum(size[None, :], 1)
    score = np.where(cover >= segment_cover, total / np.maximum(seen, 1) + (1.0 - cover) * 10.0, np.inf)
    if fixed is not None and fixed_ok.any():
        # segments continuing a neighbouring tile keep that tile's image
        fs = seg[fixed_ok]
        fl = np.asarray(fixed)[fixed_ok].astype(np.int64)
        votes = np.zeros((K, nseg))
        np.add.at(votes, (fl, fs), 1.0)
        has_vote = votes.sum(axis=0) > 0
        pref = np.argmax(votes, axis=0)
        keep = has_vote & np.isfinite(score[pref, np.arange(nseg)])
        score[:, keep] = np.inf
        score[pref[keep], np.flatnonzero(keep)] = 0.0
    best = np.argmin(score, axis=0)
    has = np.isfinite(score[best, np.arange(nseg)]) & small
    seg_label = np.where(has, best, -1)
    full = np.full((rows, cols), -1, np.int64)
    full[valid] = seg_label[seg[valid]]
    take = (full >= 0) & any_vis
    kk = np.clip(full, 0, K - 1)
    ok = take & np.isfinite(np.take_along_axis(cost, kk[None], axis=0)[0])
    lab[ok] = full[ok]
    if fixed is not None:
        lab[fixed_ok] = np.asarray(fixed)[fixed_ok]
    return lab


@njit
def _best_label(cost, out):
    """``out[r, c]``: the first k of smallest finite ``cost[k, r, c]``, -1 where none is finite."""
    K, rows, cols = cost.shape
    for r in range(rows):
        for c in range(cols):
            best = np.inf
            lab = NO_LABEL
            for k in range(K):
                v = cost[k, r, c]
                if v < best:
                    best = v
                    lab = k
            out[r, c] = lab


@njit
def _segment_sums(cost, seg, small, seen, total):
    """Per small segment s and image k: cells of s with a finite cost of k, and their summed cost."""
    K, rows, cols = cost.shape
    for r in range(rows):
        for c in range(cols):
            s = seg[r, c]
            if s < 0 or not small[s]:
                continue
            for k in range(K):
                v = cost[k, r, c]
                if v < np.inf:
                    seen[k, s] += 1.0
                    total[k, s] += v


@njit
def _pair_cost(a, b, r0, c0, r1, c1, w, lum, contrast):
    """Seam cost between cells (r0, c0) labelled a and (r1, c1) labelled b."""
    if a == b:
        return 0.0
    d = 0.0
    la = lum[a, r0, c0]
    lb = lum[b, r0, c0]
    d += abs(la - lb) if (la == la and lb == lb) else 1.0
    la = lum[a, r1, c1]
    lb = lum[b, r1, c1]
    d += abs(la - lb) if (la == la and lb == lb) else 1.0
    return w * (1.0 + contrast * d)


@njit
def _local_energy(k, r, c, labels, cost, lum, wh, wv, smooth, contrast, rows, cols):
    e = cost[k, r, c]
    if c > 0:
        q = labels[r, c - 1]
        if q >= 0:
            e += smooth * _pair_cost(k, q, r, c, r, c - 1, wh[r, c - 1], lum, contrast)
    if c < cols - 1:
        q = labels[r, c + 1]
        if q >= 0:
            e += smooth * _pair_cost(k, q, r, c, r, c + 1, wh[r, c], lum, contrast)
    if r > 0:
        q = labels[r - 1, c]
        if q >= 0:
            e += smooth * _pair_cost(k, q, r, c, r - 1, c, wv[r - 1, c], lum, contrast)
    if r < rows - 1:
        q = labels[r + 1, c]
        if q >= 0:
            e += smooth * _pair_cost(k, q, r, c, r + 1, c, wv[r, c], lum, contrast)
    return e


@njit
def _icm(labels, frozen, cost, lum, wh, wv, smooth, contrast, sweeps):
    """ICM sweeps; ``cost`` and ``lum`` are (K, rows, cols).

    The labels tried at a cell are its current one, its data-best one and those of
    its four neighbours: any other label pays a seam to every neighbour for no gain
    in the data term.
    """
    K = cost.shape[0]
    rows = labels.shape[0]
    cols = labels.shape[1]
    best_data = np.full((rows, cols), -1, np.int64)
    free = np.zeros((rows, cols), np.bool_)
    for r in range(rows):
        for c in range(cols):
            if labels[r, c] < 0 or frozen[r, c]:
                continue
            n = 0
            bd = -1
            bv = np.inf
            for k in range(K):
                v = cost[k, r, c]
                if v < np.inf:
                    n += 1
                    if v < bv:
                        bv = v
                        bd = k
            free[r, c] = n > 1
            best_data[r, c] = bd
    cand = np.empty(6, np.int64)
    total_changes = 0
    for _ in range(sweeps):
        changes = 0
        for r in range(rows):
            for c in range(cols):
                if not free[r, c]:
                    continue
                cur = labels[r, c]
                if (
                    cur == best_data[r, c]
                    and (c == 0 or labels[r, c - 1] == cur)
                    and (c == cols - 1 or labels[r, c + 1] == cur)
                    and (r == 0 or labels[r - 1, c] == cur)
                    and (r == rows - 1 or labels[r + 1, c] == cur)
                ):
                    continue  # no seam and the best data cost: no label can do better
                cand[0] = cur
                cand[1] = best_data[r, c]
                cand[2] = labels[r, c - 1] if c > 0 else -1
                cand[3] = labels[r, c + 1] if c < cols - 1 else -1
                cand[4] = labels[r - 1, c] if r > 0 else -1
                cand[5] = labels[r + 1, c] if r < rows - 1 else -1
                best = cur
                best_e = _local_energy(cur, r, c, labels, cost, lum, wh, wv, smooth, contrast, rows, cols)
                for m in range(1, 6):
                    k = cand[m]
                    if k < 0 or k == cur or not cost[k, r, c] < np.inf:
                        continue
                    seen_before = False
                    for mm in range(1, m):
                        if cand[mm] == k:
                            seen_before = True
                    if seen_before:
                        continue
                    e = _local_energy(k, r, c, labels, cost, lum, wh, wv, smooth, contrast, rows, cols)
                    if e < best_e - 1e-7:
                        best_e = e
                        best = k
                if best != cur:
                    labels[r, c] = best
                    changes += 1
        total_changes += changes
        if changes == 0:
            break
    return total_changes


def select_labels(
    cost: np.ndarray,
    h: np.ndarray,
    lum: np.ndarray | None,
    res: float,
    smoothness: float = 1.0,
    contrast: float = 4.0,
    discontinuity: float = 0.5,
    max_segment_cells: int | None = None,
    sweeps: int = 8,
    fixed: np.ndarray | None = None,
) -> np.ndarray:
    """Image label per cell (index into the candidate axis of ``cost``; -1 where none sees the cell).

    Parameters
    ----------
    cost : (K, rows, cols) float32
        Data costs (:func:`data_costs`), inf where image k does not see the cell.
    h : (rows, cols) float
        Surface heights (metres), NaN where unknown.
    lum : (K, rows, cols) float32 or None
        Luminance in [0, 1] of every candidate at every cell (NaN where not
        seen), for the contrast part of the seam cost.
    res : float
        Cell size (metres).
    smoothness, contrast : float
        Weight of a seam edge relative to the data cost, and of the luminance
        disagreement within it.
    discontinuity : float
        Height step (metres) that counts as a discontinuity; the Potts weight
        decays with ``h0 = max(discontinuity, 2 res)``.
    max_segment_cells : int, optional
        Largest segment labelled as a whole (default: a 60 m x 60 m roof).
    sweeps : int
        ICM sweeps.
    fixed : (rows, cols) int, optional
        Labels already decided by neighbouring tiles (-1 = free); they are kept,
        and segments and seams continue them, so tiles join without new seams.
    """
    K = cost.shape[0]
    h0 = max(float(discontinuity), 2.0 * float(res))
    if max_segment_cells is None:
        max_segment_cells = int(math.ceil((60.0 / res) ** 2))
    labels = initial_labels(cost, h, h0, max_segment_cells, fixed=fixed)
    if K < 2 or smoothness <= 0 or sweeps <= 0:
        return labels
    frozen = np.zeros(labels.shape, np.bool_)
    if fixed is not None:
        frozen = (np.asarray(fixed) >= 0) & (labels == np.asarray(fixed))
    wh, wv = edge_weights(h, h0)
    if lum is None:
        lum = np.full(cost.shape, np.nan, np.float32)
    _icm(
        labels,
        frozen,
        np.ascontiguousarray(cost, dtype=np.float32),
        np.ascontiguousarray(lum, dtype=np.float32),
        wh,
        wv,
        float(smoothness),
        float(contrast),
        int(sweeps),
    )
    return labels
