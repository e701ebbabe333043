"""The plane sweep of one OSGM tile on the cells that search each plane only.

On a refined pyramid level a cell searches a band of a few tens of Z levels
around the coarser result, but the tile as a whole spans ground to roof: a
plane ``Z = const`` is searched by a thin, scattered set of cells (the
outlines of the buildings at that height, the ground around them, ...).
Resampling every image onto the whole bounding box of that set and running
the dense cost over it spent 6 to 27 times the work the cells need
(measured on the acceptance battery's tiles). This module evaluates a plane
on the cells that search it, and on the margin their windows read, with the
same arithmetic as the dense saturated-gradient cost
(:func:`~truortho.core.sgm.multi_image_cost`, ``measure="gradient"``):

1. every image is sampled (bilinear at 1/32 pixel as ``cv2.remap``, NaN
   outside its window) at the cells within ``radius + 1`` of a searching
   cell (:func:`_sample_phase`);
2. gradients along rows and columns (central, one-sided next to missing
   samples), divided by a saturation scale and clipped to ``[-1, 1]``,
   quantised to int16, at the cells within ``radius`` (:func:`_gradient_phase`);
3. per sample and pair, ``|dgx| + |dgy|`` and whether both views are valid
   (:func:`_pair_terms`, evaluated once per sample rather than on entering
   and on leaving a window);
4. for every searching cell, the window sums of every pair (running sums
   down the columns of a strip and along runs of searching cells), the pair
   contributions ``min(1, mean (|dgx| + |dgy|) / 2)`` and the mean of the
   best pairs (as :func:`~truortho.core.sgm.cost._combine`, found by bisection:
   :func:`_smallest_mean`), written straight into the tile's cost volume
   (:func:`_window_cost`).

Pairs whose views share no valid sample can never score, and a coarse tile that spans a whole
block holds photos from its opposite ends (36 photos and 630 pairs on the coarsest levels of battery
scene 1, master seed 808, against about 10 photos per tile on the finest). Each plane is therefore
swept in bands of rows (``STRIP`` times the threads), each with only the pairs whose views' valid
gradients have overlapping bounding boxes in it (:func:`_meeting_pairs`), when that saves enough
(:data:`BAND_GAIN`): the costs are the same to the bit, and the pair work of phases 3 and 4 fell to
0.45-0.55 of all pairs' on battery scenes 808/1 and 2026/2 and 2026/9.

Comparing every view with the per-sample median of the views instead of
every pair (``n`` terms instead of ``n (n - 1) / 2``) was measured on the
battery and rejected: at most 1.4x faster per tile and 0 to 6 points fewer
edge cells within 3 GSD (scene 9: 0.688 -> 0.631).

The saturation scale is one per image and axis for the whole tile
(:func:`gradient_scales`: the median absolute gradient of the image sampled
on the tile's middle plane), so costs of different planes and of different
parts of the tile share one scale.
"""

from __future__ import annotations

import numba
import numpy as np

from ..errors import InputError
from ..jit import njit, pjit, prange
from ..quickselect import select_rank
from ..sgm import COST_MAX
from ..sgm.cost import _GQ, _auto_k, _diff1, _gradient_scale, _gradients, _need, _quantise, _window_cells

#: Rows per parallel strip of the window sums.
STRIP = 32
#: A plane is swept in bands of rows, each with only the pairs of views that meet in it
#: (:meth:`PlaneSweep.plane`), when that leaves at most this share of the pair work of one pass with
#: the pairs that meet anywhere in the tile; else in one pass (a band costs a pass of both kernels).
BAND_GAIN = 0.75
#: Halvings of the value range at most in :func:`_smallest_mean` (a width of 2^-39); values closer
#: than that at the ``kb``-th rank are separated by a quickselect among them.
_BISECTIONS = 40
#: Subpixel steps of the bilinear sampler (cv2.remap's ``INTER_TAB_SIZE``).
_SUB = 32


class PackedImages:
    """The tile's image windows and cameras as flat arrays for the kernels."""

    def __init__(self, images) -> None:
        n = len(images)
        sizes = [im.window.size for im in images]
        self.off = np.zeros(n, np.int64)
        if n > 1:
            self.off[1:] = np.cumsum(sizes)[:-1]
        self.buf = np.concatenate([np.ascontiguousarray(im.window, np.float32).ravel() for im in images])
        self.hh = np.array([im.window.shape[0] for im in images], np.int64)
        self.ww = np.array([im.window.shape[1] for im in images], np.int64)
        self.R = np.ascontiguousarray(np.stack([im.view.R for im in images]), np.float64)
        self.C = np.ascontiguousarray(np.stack([im.view.C for im in images]), np.float64)
        self.P = np.ascontiguousarray(np.stack([im.view.camera.params for im in images]), np.float64)
        self.r2max = np.array([im.view.r2max for im in images], np.float64)
        self.scale = np.array([0.5**im.level for im in images], np.float64)
        self.shift = np.array([im.origin for im in images], np.float64).reshape(n, 2)

    @property
    def n(self) -> int:
        return len(self.off)


@njit
def _bilinear(buf, off, h, w, u, v):
    """Bilinear sample of the window ``buf[off:off + h w]`` (row-major ``h x w``) at pixel ``(u, v)``."""
    if not (u >= 0.0 and v >= 0.0 and u <= w - 1 and v <= h - 1):
        return np.float32(np.nan)
    # positions rounded to 1/32 pixel, as cv2.remap does (a neighbour of weight 0 is not read)
    qu = int(u * _SUB + 0.5)
    qv = int(v * _SUB + 0.5)
    iu = min(qu // _SUB, w - 2) if w > 1 else 0
    iv = min(qv // _SUB, h - 2) if h > 1 else 0
    fu = (qu - iu * _SUB) / _SUB
    fv = (qv - iv * _SUB) / _SUB
    k = off + iv * w + iu
    a = buf[k]
    b = buf[k + 1] if w > 1 else a
    if h > 1:
        c = buf[k + w]
        d = buf[k + w + 1] if w > 1 else c
    else:
        c = a
        d = b
    return np.float32((a * (1.0 - fu) + b * fu) * (1.0 - fv) + (c * (1.0 - fu) + d * fu) * fv)


@njit
def _box(mask, margin):
    """Bounding box ``(r0, r1, c0, c1)`` of a uint8 mask widened by ``margin`` (clipped; empty: r0 = r1)."""
    rows, cols = mask.shape
    r0, r1, c0, c1 = rows, -1, cols, -1
    for r in range(rows):
        for c in range(cols):
            if mask[r, c]:
                r0 = min(r0, r)
                r1 = max(r1, r)
                c0 = min(c0, c)
                c1 = max(c1, c)
    if r1 < 0:
        return 0, 0, 0, 0
    return max(0, r0 - margin), min(rows, r1 + margin + 1), max(0, c0 - margin), min(cols, c1 + margin + 1)


@njit
def _dilate_line(src, dst, lo, hi, rad):
    """``dst[k] = 1`` where ``src`` has a non-zero within ``rad`` of ``k``, for ``lo <= k < hi``
    (only ``src[lo:hi]`` is read; running count)."""
    acc = 0
    for k in range(lo, min(hi, lo + rad)):
        acc += src[k]
    for k in range(lo, hi):
        if k + rad < hi:
            acc += src[k + rad]
        if k - rad - 1 >= lo:
            acc -= src[k - rad - 1]
        dst[k] = 1 if acc > 0 else 0


@njit
def _dilate(mask, rad, box, tmp, out):
    """Box dilation (``(2 rad + 1)^2``) of a uint8 mask inside ``box`` (separable: rows, then columns).

    Only the cells of ``box`` are written; the mask must be zero outside it.
    """
    b0, b1, d0, d1 = box[0], box[1], box[2], box[3]
    for r in range(b0, b1):
        _dilate_line(mask[r], tmp[r], d0, d1, rad)
    for c in range(d0, d1):
        _dilate_line(tmp[:, c], out[:, c], b0, b1, rad)


@pjit
def _sample_phase(buf, off, hh, ww, R, C, P, r2max, scl, shift, x0, y0, res, z, samp, box, s):
    """Every image sampled at the cells of ``samp`` (inside ``box``) on the plane ``z`` into ``s``.

    On a plane the camera coordinates are affine in the column: each row starts
    from its first cell and steps by ``res`` times the rotation's first column.
    """
    n = off.shape[0]
    for r in prange(box[0], box[1]):
        Y = y0 - (r + 0.5) * res
        for i in range(n):
            p = P[i]
            dx = x0 - C[i, 0]
            dy = Y - C[i, 1]
            dz = z - C[i, 2]
            bx = R[i, 0, 0] * dx + R[i, 0, 1] * dy + R[i, 0, 2] * dz
            by = R[i, 1, 0] * dx + R[i, 1, 1] * dy + R[i, 1, 2] * dz
            bz = R[i, 2, 0] * dx + R[i, 2, 1] * dy + R[i, 2, 2] * dz
            sx, sy, sz = R[i, 0, 0] * res, R[i, 1, 0] * res, R[i, 2, 0] * res
            o, h, w = off[i], hh[i], ww[i]
            sc, su, sv, rmax = scl[i], shift[i, 0], shift[i, 1], r2max[i]
            for c in range(box[2], box[3]):
                if samp[r, c] == 0:
                    continue
                t = c + 0.5
                zc = bz + t * sz
                val = np.float32(np.nan)
                if zc > 0.0:
                    xn = (bx + t * sx) / zc
                    yn = (by + t * sy) / zc
                    r2 = xn * xn + yn * yn
                    if r2 <= rmax:
                        radial = 1.0 + r2 * (p[4] + r2 * (p[5] + r2 * p[6]))
                        xd = xn * radial + 2.0 * p[7] * xn * yn + p[8] * (r2 + 2.0 * xn * xn)
                        yd = yn * radial + p[7] * (r2 + 2.0 * yn * yn) + 2.0 * p[8] * xn * yn
                        u = ((p[0] * xd + p[2]) + 0.5) * sc - 0.5 - su
                        v = ((p[1] * yd + p[3]) + 0.5) * sc - 0.5 - sv
                        val = _bilinear(buf, o, h, w, u, v)
                s[r, c, i] = val


@pjit
def _gradient_phase(s, samp, win, box, inv, qx, qy, vv):
    """Saturated, quantised gradients at the cells of ``win`` (neighbours read inside ``samp`` only)."""
    rows, cols, n = s.shape
    for r in prange(box[0], box[1]):
        for c in range(box[2], box[3]):
            if win[r, c] == 0:
                continue
            for i in range(n):
                x = s[r, c, i]
                al = s[r, c - 1, i] if c > 0 and samp[r, c - 1] else np.float32(np.nan)
                ar = s[r, c + 1, i] if c < cols - 1 and samp[r, c + 1] else np.float32(np.nan)
                au = s[r - 1, c, i] if r > 0 and samp[r - 1, c] else np.float32(np.nan)
                ad = s[r + 1, c, i] if r < rows - 1 and samp[r + 1, c] else np.float32(np.nan)
                gx = _diff1(al, x, ar)
                gy = _diff1(au, x, ad)
                if gx != gx or gy != gy:
                    qx[r, c, i] = 0
                    qy[r, c, i] = 0
                    vv[r, c, i] = 0
                else:
                    qx[r, c, i] = _quantise(gx, inv[i, 0])
                    qy[r, c, i] = _quantise(gy, inv[i, 1])
                    vv[r, c, i] = 1


@pjit
def _pair_terms(qx, qy, vv, win, box, pi, pj, td, tm):
    """Per sample and pair: ``|dqx| + |dqy|`` and 1 where both views are valid (else 0, 0)."""
    for r in prange(box[0], box[1]):
        for c in range(box[2], box[3]):
            if win[r, c] == 0:
                continue
            for q in range(pi.shape[0]):
                i = pi[q]
                j = pj[q]
                m = vv[r, c, i] & vv[r, c, j]
                d = abs(np.int32(qx[r, c, i]) - np.int32(qx[r, c, j])) + abs(
                    np.int32(qy[r, c, i]) - np.int32(qy[r, c, j])
                )
                td[r, c, q] = np.int16(d * m)
                tm[r, c, q] = m


@pjit
def _row_spans(vv, win, box, cmin, cmax):
    """Per row of ``box`` and view: the first and last column with a valid gradient (``cmax < cmin``:
    none)."""
    n = vv.shape[2]
    for r in prange(box[0], box[1]):
        for i in range(n):
            cmin[r, i] = box[3]
            cmax[r, i] = -1
        for c in range(box[2], box[3]):
            if win[r, c] == 0:
                continue
            for i in range(n):
                if vv[r, c, i]:
                    if c < cmin[r, i]:
                        cmin[r, i] = c
                    cmax[r, i] = c


@njit
def _meeting_pairs(cmin, cmax, r0, r1, pi, pj, oi, oj):
    """The pairs of ``pi``/``pj`` whose views' valid gradients have overlapping bounding boxes in rows
    ``r0 .. r1 - 1`` (the others have no valid sample in common on this plane) into ``oi``/``oj``;
    returns their number."""
    n = cmin.shape[1]
    rlo = np.full(n, r1, np.int64)
    rhi = np.full(n, -1, np.int64)
    clo = np.full(n, np.iinfo(np.int64).max, np.int64)
    chi = np.full(n, -1, np.int64)
    for r in range(r0, r1):
        for i in range(n):
            if cmax[r, i] >= cmin[r, i]:
                rlo[i] = min(rlo[i], r)
                rhi[i] = r
                clo[i] = min(clo[i], cmin[r, i])
                chi[i] = max(chi[i], cmax[r, i])
    m = 0
    for q in range(pi.shape[0]):
        i = pi[q]
        j = pj[q]
        if rhi[i] < 0 or rhi[j] < 0:
            continue
        if rhi[i] >= rlo[j] and rhi[j] >= rlo[i] and chi[i] >= clo[j] and chi[j] >= clo[i]:
            oi[m] = i
            oj[m] = j
            m += 1
    return m


@njit
def _col_step(td, tm, vv, ra, rs, cc, vd, vm, vc, nt):
    """Column ``cc``'s sums of every term and view: + sample row ``ra``, - sample row ``rs``
    (-1: none), in one pass."""
    if ra >= 0 and rs >= 0:
        for q in range(nt):
            vd[cc, q] += np.int32(td[ra, cc, q]) - np.int32(td[rs, cc, q])
            vm[cc, q] += np.int32(tm[ra, cc, q]) - np.int32(tm[rs, cc, q])
        for i in range(vv.shape[2]):
            vc[cc, i] += np.int32(vv[ra, cc, i]) - np.int32(vv[rs, cc, i])
    elif ra >= 0:
        for q in range(nt):
            vd[cc, q] += np.int32(td[ra, cc, q])
            vm[cc, q] += np.int32(tm[ra, cc, q])
        for i in range(vv.shape[2]):
            vc[cc, i] += np.int32(vv[ra, cc, i])
    elif rs >= 0:
        for q in range(nt):
            vd[cc, q] -= np.int32(td[rs, cc, q])
            vm[cc, q] -= np.int32(tm[rs, cc, q])
        for i in range(vv.shape[2]):
            vc[cc, i] -= np.int32(vv[rs, cc, i])


@njit
def _row_step(vd, vm, vc, ca, cs, hd, hm, hc):
    """Window sums: + column sums ``ca``, - column sums ``cs`` (-1: none), in one pass."""
    if ca >= 0 and cs >= 0:
        for q in range(hd.shape[0]):
            hd[q] += vd[ca, q] - vd[cs, q]
            hm[q] += vm[ca, q] - vm[cs, q]
        for i in range(hc.shape[0]):
            hc[i] += vc[ca, i] - vc[cs, i]
    elif ca >= 0:
        for q in range(hd.shape[0]):
            hd[q] += vd[ca, q]
            hm[q] += vm[ca, q]
        for i in range(hc.shape[0]):
            hc[i] += vc[ca, i]
    elif cs >= 0:
        for q in range(hd.shape[0]):
            hd[q] -= vd[cs, q]
            hm[q] -= vm[cs, q]
        for i in range(hc.shape[0]):
            hc[i] -= vc[cs, i]


@njit
def _count_le(v, t):
    """Number of entries of ``v`` that are ``<= t``."""
    c = 0
    for q in range(v.shape[0]):
        c += v[q] <= t
    return c


@njit
def _sum_le(v, t):
    """Sum (float64) of the entries of ``v`` that are ``<= t``, in four running sums.

    The order of the additions does not change the sum of pair contributions: they are float32 in
    ``{0} U [1 / (2 _GQ W), 1]`` (``W`` the window's cells), so every one is a multiple of
    ``2^-43`` while ``W <= 4096`` (radius <= 31), and fewer than ``2^10`` of them add up exactly in
    float64's 53 bits. The four sums only break the chain of dependent additions.
    """
    nt = v.shape[0]
    s0 = 0.0
    s1 = 0.0
    s2 = 0.0
    s3 = 0.0
    q = 0
    while q + 4 <= nt:
        x0 = v[q]
        x1 = v[q + 1]
        x2 = v[q + 2]
        x3 = v[q + 3]
        s0 += x0 if x0 <= t else 0.0
        s1 += x1 if x1 <= t else 0.0
        s2 += x2 if x2 <= t else 0.0
        s3 += x3 if x3 <= t else 0.0
        q += 4
    while q < nt:
        x0 = v[q]
        s0 += x0 if x0 <= t else 0.0
        q += 1
    return (s0 + s1) + (s2 + s3)


@njit
def _smallest_mean(v, kb):
    """Mean of the ``kb`` smallest entries of ``v`` that are ``<= 1`` (at least ``kb`` of them; the
    entries above 1 mark invalid pairs). Reorders ``v``.

    The same value as :func:`~truortho.core.sgm.cost._combine`'s quickselect, found by bisecting
    the value range ``(-1, 1]`` until the entries ``<= b`` are exactly the ``kb`` smallest (a
    counting loop that vectorises), then summing them; ties at the ``kb``-th value that bisection
    cannot separate end in a quickselect among the few entries of the last interval.
    """
    a = -1.0
    b = 1.0
    ca = 0
    cb = _count_le(v, b)
    it = 0
    while cb != kb and it < _BISECTIONS:
        mid = 0.5 * (a + b)
        cm = _count_le(v, mid)
        if cm >= kb:
            b = mid
            cb = cm
        else:
            a = mid
            ca = cm
        it += 1
    if cb == kb:
        return _sum_le(v, b) / kb
    s = _sum_le(v, a)
    nb = 0
    for q in range(v.shape[0]):
        x = v[q]
        if x > a and x <= b:
            v[nb] = x
            nb += 1
    r = kb - ca
    if r < nb:
        select_rank(v, 0, nb - 1, r - 1)
    for j in range(r):
        s += v[j]
    return s / kb


@pjit
def _window_cost(td, tm, vv, need, win, box, radius, min_valid, best_k, pi, pj, a, z0, cost):
    """Window sums of the pair terms at the cells with ``need``, and the multi-image cost from them
    (mean of the best pairs, as :func:`~truortho.core.sgm.multi_image_cost`) into
    ``cost[r, c, a - z0[r, c]]``.

    The pair contributions of a cell are written for every pair, 2 for the pairs without enough
    valid samples, and :func:`_smallest_mean` takes the mean of the best; the same cost, to the
    bit, as compacting the valid ones and quickselecting (:func:`~truortho.core.sgm.cost._combine`),
    and about a fifth less time for this kernel (a captured 13-image plane of battery scene 9:
    52 -> 41 ms on one thread). ``_combine`` keeps its quickselect: its NCC and census
    contributions are not multiples of a common quantum, so there the order of the additions
    could change the last bit.
    """
    rows, cols = td.shape[0], td.shape[1]
    nt = pi.shape[0]
    n = vv.shape[2]
    b0, b1, d0, d1 = box[0], box[1], box[2], box[3]
    nstrips = (b1 - b0 + STRIP - 1) // STRIP
    cmax = np.float64(COST_MAX)
    scale = 1.0 / (2.0 * _GQ)
    for st in prange(nstrips):
        r0 = b0 + st * STRIP
        r1 = min(b1, r0 + STRIP)
        vd = np.zeros((cols, nt), np.int32)
        vm = np.zeros((cols, nt), np.int32)
        vc = np.zeros((cols, n), np.int32)
        last = np.full(cols, -10, np.int64)  # row whose column sums vd/vm/vc hold
        hd = np.zeros(nt, np.int32)
        hm = np.zeros(nt, np.int32)
        hc = np.zeros(n, np.int32)
        vok = np.zeros(n, np.uint8)
        val = np.empty(nt, np.float32)
        for r in range(r0, r1):
            # column sums at every column within `radius` of a searching cell of this row
            for cc in range(d0, d1):
                if win[r, cc] == 0:
                    continue
                used = False
                for c in range(max(0, cc - radius), min(cols, cc + radius + 1)):
                    if need[r, c]:
                        used = True
                        break
                if not used:
                    continue
                if last[cc] == r - 1:
                    ra = r + radius if r + radius < rows else -1
                    _col_step(td, tm, vv, ra, r - radius - 1, cc, vd, vm, vc, nt)
                else:
                    vd[cc, :] = 0
                    vm[cc, :] = 0
                    vc[cc, :] = 0
                    for rr in range(max(0, r - radius), min(rows, r + radius + 1)):
                        _col_step(td, tm, vv, rr, -1, cc, vd, vm, vc, nt)
                last[cc] = r
            # window sums along runs of searching cells
            prev = -10
            for c in range(d0, d1):
                if need[r, c] == 0:
                    continue
                if prev == c - 1:
                    ca = c + radius if c + radius < cols else -1
                    _row_step(vd, vm, vc, ca, c - radius - 1, hd, hm, hc)
                else:
                    hd[:] = 0
                    hm[:] = 0
                    hc[:] = 0
                    for cc in range(max(0, c - radius), min(cols, c + radius + 1)):
                        _row_step(vd, vm, vc, cc, -1, hd, hm, hc)
                prev = c
                k = _need(_window_cells(r, c, rows, cols, radius), min_valid)
                nv = 0
                for i in range(n):
                    ok = hc[i] >= k
                    vok[i] = ok
                    nv += ok
                kk = a - z0[r, c]
                if nv < 2:
                    cost[r, c, kk] = COST_MAX
                    continue
                m = 0
                for q in range(nt):
                    h = hm[q]
                    ok = (h >= k) & (vok[pi[q]] != 0) & (vok[pj[q]] != 0)
                    x = np.float32(min(1.0, hd[q] * scale / max(h, 1)))
                    val[q] = x if ok else np.float32(2.0)
                    m += ok
                if m == 0:
                    cost[r, c, kk] = COST_MAX
                    continue
                kb = best_k if best_k > 0 else _auto_k(nv)
                if kb >= m:
                    mean = _sum_le(val, 1.0) / m
                else:
                    mean = _smallest_mean(val, kb)
                cost[r, c, kk] = np.uint16(min(cmax, mean * cmax + 0.5))


def slice_scales(sl: np.ndarray) -> tuple[float, float]:
    """The saturation scales of one sampled slice (rows, cols): median |gradient| along columns
    and along rows, as :func:`~truortho.core.sgm.cost._saturate` takes them (0 without gradient)."""
    s = np.ascontiguousarray(sl, np.float64)
    if s.ndim != 2:
        raise InputError(f"slice_scales: expected a 2-D slice, got shape {s.shape}")
    gx = np.empty(s.shape, np.float64)
    gy = np.empty(s.shape, np.float64)
    _gradients(s, gx, gy)
    return float(_gradient_scale(gx)), float(_gradient_scale(gy))


def gradient_scales(images, sample, x0, y0, res, rows, cols, z) -> np.ndarray:
    """``(n, 2)`` saturation scales per image: the median |gradient| along columns and along rows.

    ``sample(image, x0, y0, res, rows, cols, z)`` resamples one image onto the
    plane ``z``; the central 256 x 256 cells of the tile at most (the median
    of the gradients needs no more). 0 where an image has no gradient there.
    """
    h, w = min(rows, 256), min(cols, 256)
    r0, c0 = (rows - h) // 2, (cols - w) // 2
    out = np.zeros((len(images), 2), np.float64)
    for i, im in enumerate(images):
        out[i] = slice_scales(sample(im, x0 + c0 * res, y0 - r0 * res, res, h, w, z))
    return out


class PlaneSweep:
    """Work arrays of one tile's sweep, reused for every plane."""

    def __init__(
        self, images, rows: int, cols: int, radius: int, min_valid: float, scales: np.ndarray
    ) -> None:
        self.pack = PackedImages(images)
        n = self.pack.n
        self.radius = int(radius)
        self.min_valid = float(min_valid)
        sc = np.asarray(scales, np.float64)
        self.inv = np.ascontiguousarray(np.where(sc > 0.0, _GQ / np.where(sc > 0.0, sc, 1.0), 0.0))
        pi, pj = np.triu_indices(n, 1)
        self.pi = pi.astype(np.int64)
        self.pj = pj.astype(np.int64)
        nt = len(self.pi)
        self.s = np.empty((rows, cols, n), np.float32)
        self.qx = np.empty((rows, cols, n), np.int16)
        self.qy = np.empty((rows, cols, n), np.int16)
        self.vv = np.empty((rows, cols, n), np.uint8)
        self.td = np.empty((rows, cols, max(1, nt)), np.int16)
        self.tm = np.empty((rows, cols, max(1, nt)), np.uint8)
        self.tmp = np.empty((rows, cols), np.uint8)
        self.samp = np.empty((rows, cols), np.uint8)
        self.win = np.empty((rows, cols), np.uint8)
        self.cmin = np.empty((rows, n), np.int64)
        self.cmax = np.empty((rows, n), np.int64)
        bands = (rows + 2 * STRIP - 1) // (2 * STRIP) + 1  # the whole plane, then each band
        self.oi = np.empty((bands, max(1, nt)), np.int64)
        self.oj = np.empty((bands, max(1, nt)), np.int64)

    def plane(
        self, x0, y0, res, z, need: np.ndarray, a: int, z0: np.ndarray, cost: np.ndarray, best_k=0
    ) -> None:
        """Costs of plane ``z`` (absolute level ``a``) for the cells with ``need`` into ``cost``.

        ``need`` (rows, cols) bool; ``z0`` (rows, cols) int32 and ``cost`` (rows, cols, nd) uint16,
        C-ordered (written in place), with ``0 <= a - z0 < nd`` wherever ``need`` is set (the
        caller's per-cell windows guarantee it; the kernels do not check it again).
        """
        shape = self.samp.shape
        if np.shape(need) != shape or np.shape(z0) != shape:
            raise InputError(
                f"PlaneSweep.plane: need and z0 must be {shape}, got {np.shape(need)}, {np.shape(z0)}"
            )
        if z0.dtype != np.int32 or not z0.flags.c_contiguous:
            raise InputError("PlaneSweep.plane: z0 must be a C-ordered int32 array")
        if (
            cost.ndim != 3
            or cost.shape[:2] != shape
            or cost.dtype != np.uint16
            or not cost.flags.c_contiguous
        ):
            raise InputError(f"PlaneSweep.plane: cost must be a C-ordered uint16 {shape} x nd volume")
        need8 = np.ascontiguousarray(need, np.uint8)
        box = np.array(_box(need8, self.radius + 1), np.int64)
        if box[1] <= box[0]:
            return
        _dilate(need8, self.radius + 1, box, self.tmp, self.samp)
        _dilate(need8, self.radius, box, self.tmp, self.win)
        p = self.pack
        _sample_phase(
            p.buf, p.off, p.hh, p.ww, p.R, p.C, p.P, p.r2max, p.scale, p.shift,
            float(x0), float(y0), float(res), float(z), self.samp, box, self.s,
        )  # fmt: skip
        _gradient_phase(self.s, self.samp, self.win, box, self.inv, self.qx, self.qy, self.vv)
        _row_spans(self.vv, self.win, box, self.cmin, self.cmax)
        b0, b1 = int(box[0]), int(box[1])
        rad = self.radius
        band = STRIP * max(2, numba.get_num_threads())
        nb = (b1 - b0 + band - 1) // band
        whole = _meeting_pairs(self.cmin, self.cmax, b0, b1, self.pi, self.pj, self.oi[0], self.oj[0])
        parts = [(b0, b1, b0, b1, whole)]
        if nb > 1:
            banded = []
            work = 0
            for k in range(nb):
                r0 = b0 + k * band
                r1 = min(b1, r0 + band)
                t0, t1 = max(b0, r0 - rad), min(b1, r1 + rad)
                oi, oj = self.oi[k + 1], self.oj[k + 1]
                m = _meeting_pairs(self.cmin, self.cmax, t0, t1, self.pi, self.pj, oi, oj)
                banded.append((r0, r1, t0, t1, m))
                work += m * (t1 - t0)
            if work <= BAND_GAIN * whole * (b1 - b0):
                parts = banded
        for k, (r0, r1, t0, t1, m) in enumerate(parts):
            row = 0 if len(parts) == 1 else k + 1
            pi, pj = self.oi[row, :m], self.oj[row, :m]
            tbox = np.array([t0, t1, box[2], box[3]], np.int64)
            _pair_terms(self.qx, self.qy, self.vv, self.win, tbox, pi, pj, self.td, self.tm)
            wbox = np.array([r0, r1, box[2], box[3]], np.int64)
            _window_cost(
                self.td, self.tm, self.vv, need8, self.win, wbox, rad, self.min_valid, int(best_k or 0),
                pi, pj, int(a), z0, cost,
            )  # fmt: skip
