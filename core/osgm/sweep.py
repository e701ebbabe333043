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
   cell (:func:`_sample_phase`); the cells of a row that cannot project into
   an image's window get NaN without being projected (:func:`_frame_columns`);
2. gradients along rows and columns (central, one-sided next to missing
   samples), divided by a saturation scale and clipped to ``[-1, 1]``,
   quantised to int16, at the cells within ``radius`` (:func:`_gradient_phase`);
3. the plane is cut into blocks of :data:`BLOCK` x :data:`BLOCK` cells, which
   the threads take in turn (:func:`_block_cost`); a block keeps only the pairs
   of views whose valid gradients have overlapping bounding boxes in it and its
   margin (:func:`_block_pairs`): the others share no valid sample there and
   can never score;
4. per sample of the block and its margin and per pair, ``|dgx| + |dgy|`` and
   whether both views are valid, packed into one integer (:func:`_block_terms`,
   :func:`_packing`; evaluated once per sample rather than on entering and on
   leaving a window);
5. for every searching cell, the window sums of every pair (running sums
   down the columns of the block and along runs of searching cells), the pair
   contributions ``min(1, mean (|dgx| + |dgy|) / 2)`` and the mean of the
   best pairs (as :func:`~truortho.core.sgm.cost._combine`, found by bisection:
   :func:`_smallest_mean`), written straight into the tile's cost volume
   (:func:`_block_sums`); at the cells where the coarser surface hides views
   (:func:`~.matching.hidden_views`), the number of best pairs counts only the views left.

Why blocks: a coarse tile that spans a whole block of photos holds photos from
its opposite ends (36 photos and 630 pairs on the coarsest levels of battery
scene 1, master seed 808, against about 10 photos per tile on the finest), and
even on the finest level a photo's footprint edge crosses the tile. Bands of
rows across the whole tile (the previous design) kept 0.45-0.55 of all pairs'
work; blocks of 32 x 32 cells keep 0.53 of the bands' pair terms (margins
included) and 0.43 of their window sums on scene 808/1 (64 x 64: 0.64 and
0.59). The costs are the same to the bit.

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

#: Side, in cells, of the square blocks a plane's window costs are computed in, each with only the
#: pairs of views that meet in it (:func:`_block_pairs`), in turn by the threads. Captured planes of
#: battery scene 808/1 (every 25th plane, the pair work timed on one thread, best of three),
#: against the row bands of before: with separate terms and counts 16, 32 and 48 took 0.75-0.76 of
#: their time, 64 0.79 and 96 0.91; with the packed terms 16 and 32 0.69, 48 0.72.
BLOCK = 32
#: Halvings of the value range at most in :func:`_smallest_mean` (a width of 2^-39); values closer
#: than that at the ``kb``-th rank are separated by a quickselect among them.
_BISECTIONS = 40
#: Subpixel steps of the bilinear sampler (cv2.remap's ``INTER_TAB_SIZE``).
_SUB = 32


#: Slack, in normalised image coordinates, of :func:`_frame_bounds` beyond the exact bound (far above
#: the rounding of the projection, about 1e-16 of its terms; 1e-7 is 3e-4 pixels at f = 3000 px).
_FRAME_SLACK = 1e-7
#: Radii in :func:`_frame_bounds`' grid.
_FRAME_GRID = 4096


def _frame_bounds(p, r2max, scale, shift, h, w) -> tuple[float, float, float, float]:
    """``(xlo, xhi, ylo, yhi)``: undistorted normalised coordinates outside which a point cannot be
    sampled inside the window ``h x w`` (at ``scale``, from ``shift``) of the camera ``p``
    (:func:`_sample_phase`'s model, points with ``r^2 <= r2max``).

    The distortion moves a point of radius ``r`` by at most ``D(r) = r (|k1| r^2 + |k2| r^4 +
    |k3| r^6) + 3 sqrt(2) (|p1| + |p2|) r^2``. A point that lands in the window (distorted radius at
    most ``rho``, its farthest corner) has ``r - D(r) <= rho``; the radii up to ``r2max`` where that
    can hold end at ``r1`` (found on a grid, with the Lipschitz bound of ``r - D(r)`` between its
    nodes), so the window widened by ``D(r1)`` bounds such points.
    """
    fx, fy, cx, cy, k1, k2, k3, p1, p2 = (float(v) for v in p[:9])
    if not (np.isfinite(r2max) and r2max > 0.0 and fx > 0.0 and fy > 0.0):
        return (-np.inf, np.inf, -np.inf, np.inf)
    # u = ((fx xd + cx) + 0.5) scale - 0.5 - shift_u in [0, w - 1]
    xa = (((0.5 + shift[0]) / scale - 0.5) - cx) / fx
    xb = (((w - 0.5 + shift[0]) / scale - 0.5) - cx) / fx
    ya = (((0.5 + shift[1]) / scale - 0.5) - cy) / fy
    yb = (((h - 0.5 + shift[1]) / scale - 0.5) - cy) / fy
    rho = float(np.hypot(max(abs(xa), abs(xb)), max(abs(ya), abs(yb))))
    big = float(np.sqrt(r2max))
    a1, a2, a3, t = abs(k1), abs(k2), abs(k3), 3.0 * np.sqrt(2.0) * (abs(p1) + abs(p2))
    r = np.linspace(0.0, big, _FRAME_GRID + 1)
    r2 = r * r
    lift = r - (r * r2 * (a1 + r2 * (a2 + r2 * a3)) + t * r2)
    b2 = big * big
    lip = 1.0 + (b2 * (3.0 * a1 + b2 * (5.0 * a2 + b2 * 7.0 * a3)) + 2.0 * t * big)
    low = np.minimum(lift[:-1], lift[1:]) - lip * (big / _FRAME_GRID) / 2.0
    bad = np.nonzero(low <= rho)[0]  # grid intervals where r - D(r) may be <= rho
    r1 = float(r[bad[-1] + 1]) if bad.size else 0.0
    d = r1 * r1 * r1 * (a1 + r1 * r1 * (a2 + r1 * r1 * a3)) + t * r1 * r1 + _FRAME_SLACK
    xlo, xhi = min(xa, xb) - d, max(xa, xb) + d
    ylo, yhi = min(ya, yb) - d, max(ya, yb) + d
    rr = big + _FRAME_SLACK
    return (max(xlo, -rr), min(xhi, rr), max(ylo, -rr), min(yhi, rr))


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
        #: per image, the undistorted normalised bounds of the points its window can sample
        self.frame = np.empty((n, 4), np.float64)
        for i in range(n):
            self.frame[i] = _frame_bounds(
                self.P[i], self.r2max[i], self.scale[i], self.shift[i], self.hh[i], self.ww[i]
            )

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


@njit
def _half_line(tlo, thi, coef, rhs):
    """``[tlo, thi]`` cut to the ``t`` with ``coef t >= rhs``."""
    if coef > 0.0:
        tlo = max(tlo, rhs / coef)
    elif coef < 0.0:
        thi = min(thi, rhs / coef)
    elif rhs > 0.0:
        thi = -np.inf
    return tlo, thi


@njit
def _frame_columns(bx, by, bz, sx, sy, sz, fb, c0, c1):
    """The columns ``[ca, cb)`` of ``[c0, c1)`` whose cell centres ``t = c + 0.5`` may project into
    the frame bounds ``fb`` (:func:`_frame_bounds`) with ``x = (bx + t sx) / (bz + t sz)``, ``y``
    alike and ``bz + t sz > 0``: linear constraints on ``t``, widened by a column on each side."""
    tlo = -np.inf
    thi = np.inf
    tlo, thi = _half_line(tlo, thi, sz, -bz)
    tlo, thi = _half_line(tlo, thi, sx - fb[0] * sz, fb[0] * bz - bx)
    tlo, thi = _half_line(tlo, thi, fb[1] * sz - sx, bx - fb[1] * bz)
    tlo, thi = _half_line(tlo, thi, sy - fb[2] * sz, fb[2] * bz - by)
    tlo, thi = _half_line(tlo, thi, fb[3] * sz - sy, by - fb[3] * bz)
    if not (tlo <= thi):
        return c0, c0
    lo = max(float(c0 - 2), min(float(c1 + 2), tlo - 0.5))
    hi = max(float(c0 - 2), min(float(c1 + 2), thi - 0.5))
    ca = min(c1, max(c0, int(np.floor(lo)) - 1))
    cb = min(c1, int(np.floor(hi)) + 2)
    return ca, max(ca, cb)


@pjit
def _sample_phase(buf, off, hh, ww, R, C, P, r2max, scl, shift, frame, x0, y0, res, z, samp, box, s):
    """Every image sampled at the cells of ``samp`` (inside ``box``) on the plane ``z`` into ``s``.

    On a plane the camera coordinates are affine in the column: each row starts
    from its first cell and steps by ``res`` times the rotation's first column.
    The cells of a row that cannot project into an image's window
    (:func:`_frame_columns`, from the bounds ``frame``) get NaN without being
    projected. On battery scene 808/1 that skips 0.56 of the samples (0.575 are
    NaN), but the phase took only about 15 % less time (every 25th plane, one
    thread, best of three: 0.236 against 0.276 s): the valid samples'
    interpolation is most of its work.
    """
    n = off.shape[0]
    nan = np.float32(np.nan)
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
            ca, cb = _frame_columns(bx, by, bz, sx, sy, sz, frame[i], box[2], box[3])
            for c in range(box[2], ca):
                s[r, c, i] = nan
            for c in range(cb, box[3]):
                s[r, c, i] = nan
            for c in range(ca, cb):
                if samp[r, c] == 0:
                    continue
                t = c + 0.5
                zc = bz + t * sz
                val = nan
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


@njit
def _blocks(need, box, size):
    """The blocks ``[r0, r1, c0, c1]`` of ``size`` x ``size`` cells tiling ``box`` that hold a cell
    with ``need``."""
    b0, b1, d0, d1 = box[0], box[1], box[2], box[3]
    nbr = (b1 - b0 + size - 1) // size
    nbc = (d1 - d0 + size - 1) // size
    out = np.empty((max(0, nbr * nbc), 4), np.int64)
    m = 0
    for i in range(nbr):
        r0 = b0 + i * size
        r1 = min(b1, r0 + size)
        for j in range(nbc):
            c0 = d0 + j * size
            c1 = min(d1, c0 + size)
            found = False
            for r in range(r0, r1):
                for c in range(c0, c1):
                    if need[r, c]:
                        found = True
                        break
                if found:
                    break
            if found:
                out[m, 0] = r0
                out[m, 1] = r1
                out[m, 2] = c0
                out[m, 3] = c1
                m += 1
    return out[:m]


@njit
def _block_pairs(vv, win, t0, t1, e0, e1, pi, pj, oi, oj, bb):
    """The pairs of ``pi``/``pj`` whose views' valid gradients (inside ``win``) have overlapping
    bounding boxes in rows ``t0 .. t1 - 1`` and columns ``e0 .. e1 - 1``, into ``oi``/``oj``;
    returns their number. The others have no valid sample in common there. ``bb`` (4, n) int64:
    work array for the boxes (overwritten)."""
    n = vv.shape[2]
    rlo, rhi, clo, chi = bb[0], bb[1], bb[2], bb[3]
    rlo[:] = t1
    rhi[:] = -1
    clo[:] = e1
    chi[:] = -1
    for r in range(t0, t1):
        for c in range(e0, e1):
            if win[r, c] == 0:
                continue
            for i in range(n):
                if vv[r, c, i]:
                    rlo[i] = min(rlo[i], r)
                    rhi[i] = r
                    clo[i] = min(clo[i], c)
                    chi[i] = max(chi[i], c)
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
def _block_terms(qx, qy, vv, win, t0, t1, e0, e1, pi, pj, one, tp):
    """Per sample of rows ``t0 .. t1 - 1``, columns ``e0 .. e1 - 1`` and pair, packed into one
    integer: ``|dqx| + |dqy| + one`` where both views are valid, else 0 (also outside ``win``), into
    the block's ``tp`` (indexed from ``t0, e0``). ``one`` (a power of two, :func:`_packing`) is
    above every window sum of the first part, so window sums of ``tp`` hold both the sum of the
    differences (below ``one``) and the number of valid samples (the multiple of ``one``)."""
    nt = pi.shape[0]
    for r in range(t0, t1):
        for c in range(e0, e1):
            lr = r - t0
            lc = c - e0
            if win[r, c] == 0:
                for q in range(nt):
                    tp[lr, lc, q] = 0
                continue
            for q in range(nt):
                i = pi[q]
                j = pj[q]
                m = vv[r, c, i] & vv[r, c, j]
                d = abs(np.int32(qx[r, c, i]) - np.int32(qx[r, c, j])) + abs(
                    np.int32(qy[r, c, i]) - np.int32(qy[r, c, j])
                )
                tp[lr, lc, q] = (d + one) * m


@njit
def _col_step(tp, vv, ra, rs, cc, t0, e0, vp, vc):
    """Column ``cc``'s sums of every packed term and view: + sample row ``ra``, - sample row ``rs``
    (-1: none), in one pass (``tp`` and the sums indexed from row ``t0``, column ``e0``)."""
    lc = cc - e0
    nt = vp.shape[1]
    if ra >= 0 and rs >= 0:
        for q in range(nt):
            vp[lc, q] += tp[ra - t0, lc, q] - tp[rs - t0, lc, q]
        for i in range(vv.shape[2]):
            vc[lc, i] += np.int32(vv[ra, cc, i]) - np.int32(vv[rs, cc, i])
    elif ra >= 0:
        for q in range(nt):
            vp[lc, q] += tp[ra - t0, lc, q]
        for i in range(vv.shape[2]):
            vc[lc, i] += np.int32(vv[ra, cc, i])
    elif rs >= 0:
        for q in range(nt):
            vp[lc, q] -= tp[rs - t0, lc, q]
        for i in range(vv.shape[2]):
            vc[lc, i] -= np.int32(vv[rs, cc, i])


@njit
def _row_step(vp, vc, ca, cs, hp, hc):
    """Window sums: + column sums ``ca``, - column sums ``cs`` (-1: none), in one pass."""
    if ca >= 0 and cs >= 0:
        for q in range(hp.shape[0]):
            hp[q] += vp[ca, q] - vp[cs, q]
        for i in range(hc.shape[0]):
            hc[i] += vc[ca, i] - vc[cs, i]
    elif ca >= 0:
        for q in range(hp.shape[0]):
            hp[q] += vp[ca, q]
        for i in range(hc.shape[0]):
            hc[i] += vc[ca, i]
    elif cs >= 0:
        for q in range(hp.shape[0]):
            hp[q] -= vp[cs, q]
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


@njit
def _block_sums(
    tp, unit, sh, vv, need, win, blk, t0, e0, radius, min_valid, best_k, pi, pj, a, z0, cost, work, occ, hid
):
    """Window sums of the packed pair terms ``tp`` (the block's, indexed from ``t0, e0``) at the
    cells with ``need`` of the block ``blk`` ``[r0, r1, c0, c1]``, and the multi-image cost from
    them (mean of the best pairs, as :func:`~truortho.core.sgm.multi_image_cost`) into
    ``cost[r, c, a - z0[r, c]]``.

    Running sums down the columns (within ``radius`` of a searching cell of the block) and along
    runs of searching cells. The pair contributions of a cell are written for every pair, 2 for the
    pairs without enough valid samples, and :func:`_smallest_mean` takes the mean of the best; the
    same cost, to the bit, as compacting the valid ones and quickselecting
    (:func:`~truortho.core.sgm.cost._combine`), and about a fifth less time (a captured 13-image
    plane of battery scene 9: 52 -> 41 ms on one thread). ``_combine`` keeps its quickselect: its
    NCC and census contributions are not multiples of a common quantum, so there the order of the
    additions could change the last bit.

    ``occ`` (rows, cols) marks the cells where ``hid`` (rows, cols, n) lists views that the coarser
    surface hides (:func:`~.matching.hidden_views`): there the number of best pairs counts only the
    valid views that are not hidden (at least two), all pairs still competing.
    """
    rows, cols = need.shape
    nt = pi.shape[0]
    n = vv.shape[2]
    r0, r1, c0, c1 = blk[0], blk[1], blk[2], blk[3]
    e1 = min(cols, c1 + radius)
    wc = e1 - e0
    cmax = np.float64(COST_MAX)
    scale = 1.0 / (2.0 * _GQ)
    vp, vc, last, hp, hc, vok, val = _views(work, wc, nt, n)
    last[:] = -10  # row whose column sums vp/vc hold (set afresh where not the previous row)
    low = unit[0] - 1
    for r in range(r0, r1):
        # column sums at every column within `radius` of a searching cell of this row and block
        for cc in range(e0, e1):
            if win[r, cc] == 0:
                continue
            used = False
            for c in range(max(c0, cc - radius), min(c1, cc + radius + 1)):
                if need[r, c]:
                    used = True
                    break
            if not used:
                continue
            if last[cc - e0] == r - 1:
                ra = r + radius if r + radius < rows else -1
                _col_step(tp, vv, ra, r - radius - 1, cc, t0, e0, vp, vc)
            else:
                vp[cc - e0, :] = 0
                vc[cc - e0, :] = 0
                for rr in range(max(0, r - radius), min(rows, r + radius + 1)):
                    _col_step(tp, vv, rr, -1, cc, t0, e0, vp, vc)
            last[cc - e0] = r
        # window sums along runs of searching cells
        prev = -10
        for c in range(c0, c1):
            if need[r, c] == 0:
                continue
            if prev == c - 1:
                ca = c + radius - e0 if c + radius < cols else -1
                cs = c - radius - 1 - e0 if c - radius - 1 >= 0 else -1
                _row_step(vp, vc, ca, cs, hp, hc)
            else:
                hp[:] = 0
                hc[:] = 0
                for cc in range(max(0, c - radius), min(cols, c + radius + 1)):
                    _row_step(vp, vc, cc - e0, -1, hp, hc)
            prev = c
            k = _need(_window_cells(r, c, rows, cols, radius), min_valid)
            nv = 0
            for i in range(n):
                ok = hc[i] >= k
                vok[i] = ok
                nv += ok
            nk = nv
            if occ[r, c]:
                for i in range(n):
                    if vok[i] and hid[r, c, i]:
                        nk -= 1
                nk = max(nk, 2)
            kk = a - z0[r, c]
            if nv < 2:
                cost[r, c, kk] = COST_MAX
                continue
            m = 0
            for q in range(nt):
                h = hp[q] >> sh
                ok = (h >= k) & (vok[pi[q]] != 0) & (vok[pj[q]] != 0)
                x = np.float32(min(1.0, (hp[q] & low) * scale / max(h, 1)))
                val[q] = x if ok else np.float32(2.0)
                m += ok
            if m == 0:
                cost[r, c, kk] = COST_MAX
                continue
            kb = best_k if best_k > 0 else _auto_k(nk)
            if kb >= m:
                mean = _sum_le(val, 1.0) / m
            else:
                mean = _smallest_mean(val, kb)
            cost[r, c, kk] = np.uint16(min(cmax, mean * cmax + 0.5))


@njit
def _work_arrays(wmax, npairs, n, unit):
    """One thread's work arrays for :func:`_block_sums`, for blocks up to ``wmax`` columns wide
    (margins included) and ``npairs`` pairs, allocated once rather than per block."""
    return (
        np.empty(wmax * npairs, unit.dtype),
        np.empty(wmax * n, np.int32),
        np.empty(wmax, np.int64),
        np.empty(npairs, unit.dtype),
        np.empty(n, np.int32),
        np.empty(n, np.uint8),
        np.empty(npairs, np.float32),
    )


@njit
def _views(work, wc, nt, n):
    """The work arrays shaped for a block ``wc`` columns wide with ``nt`` pairs."""
    vp, vc, last, hp, hc, vok, val = work
    return (
        vp[: wc * nt].reshape((wc, nt)),
        vc[: wc * n].reshape((wc, n)),
        last[:wc],
        hp[:nt],
        hc[:n],
        vok[:n],
        val[:nt],
    )


@pjit
def _block_cost(
    qx, qy, vv, need, win, blocks, workers, radius, min_valid, best_k, pi, pj, unit, sh, a, z0, cost, occ, hid
):
    """The costs of the cells with ``need`` in every block of ``blocks``, each block with only the
    pairs that meet in it (:func:`_block_pairs`); ``workers`` threads take the blocks in turn."""
    rows, cols = need.shape
    n = vv.shape[2]
    nb = blocks.shape[0]
    npairs = pi.shape[0]
    hmax = 1
    wmax = 1
    for b in range(nb):
        hmax = max(hmax, blocks[b, 1] - blocks[b, 0] + 2 * radius)
        wmax = max(wmax, blocks[b, 3] - blocks[b, 2] + 2 * radius)
    for w in prange(workers):
        oi = np.empty(npairs, np.int64)
        oj = np.empty(npairs, np.int64)
        bb = np.empty((4, n), np.int64)
        tbuf = np.empty(hmax * wmax * npairs, unit.dtype)
        work = _work_arrays(wmax, npairs, n, unit)
        for b in range(w, nb, workers):
            blk = blocks[b]
            t0 = max(0, blk[0] - radius)
            t1 = min(rows, blk[1] + radius)
            e0 = max(0, blk[2] - radius)
            e1 = min(cols, blk[3] + radius)
            m = _block_pairs(vv, win, t0, t1, e0, e1, pi, pj, oi, oj, bb)
            tp = tbuf[: (t1 - t0) * (e1 - e0) * m].reshape((t1 - t0, e1 - e0, m))
            _block_terms(qx, qy, vv, win, t0, t1, e0, e1, oi[:m], oj[:m], unit[0], tp)
            bi, bj = oi[:m], oj[:m]
            _block_sums(
                tp, unit, sh, vv, need, win, blk, t0, e0, radius, min_valid, best_k, bi, bj, a, z0, cost,
                work, occ, hid,
            )  # fmt: skip


def _packing(radius: int) -> tuple[np.ndarray, int]:
    """The unit ``[2^sh]`` (int32 where the window sums fit, else int64) and ``sh`` of the packed
    pair terms (:func:`_block_terms`): a term is at most ``4 _GQ``, so a window's sum of them stays
    below ``2^sh`` and its count of valid samples, times ``2^sh``, below the integer's sign bit."""
    w = (2 * int(radius) + 1) ** 2
    top = 4 * _GQ * w
    sh = max(1, top.bit_length())
    if sh + w.bit_length() <= 31:
        return np.array([1 << sh], np.int32), sh
    return np.array([1 << 32], np.int64), 32


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
        self.s = np.empty((rows, cols, n), np.float32)
        self.qx = np.empty((rows, cols, n), np.int16)
        self.qy = np.empty((rows, cols, n), np.int16)
        self.vv = np.empty((rows, cols, n), np.uint8)
        self.tmp = np.empty((rows, cols), np.uint8)
        self.samp = np.empty((rows, cols), np.uint8)
        self.win = np.empty((rows, cols), np.uint8)
        self.unit, self.sh = _packing(self.radius)
        #: no view hidden anywhere (:meth:`plane` without ``hidden``; ``no_hid`` is never read)
        self.no_occ = np.zeros((rows, cols), np.uint8)
        self.no_hid = np.zeros((1, 1, n), np.uint8)

    def plane(
        self, x0, y0, res, z, need: np.ndarray, a: int, z0: np.ndarray, cost: np.ndarray, best_k=0,
        hidden=None,
    ) -> None:
        """Costs of plane ``z`` (absolute level ``a``) for the cells with ``need`` into ``cost``.

        ``need`` (rows, cols) bool; ``z0`` (rows, cols) int32 and ``cost`` (rows, cols, nd) uint16,
        C-ordered (written in place), with ``0 <= a - z0 < nd`` wherever ``need`` is set (the
        caller's per-cell windows guarantee it; the kernels do not check it again). ``hidden``:
        ``(occ, hid)`` of :func:`~.matching.hidden_views` (None: no view hidden).
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
        if hidden is None:
            occ, hid = self.no_occ, self.no_hid
        else:
            occ, hid = hidden
            n = self.vv.shape[2]
            if (
                np.shape(occ) != shape
                or np.shape(hid) != (*shape, n)
                or occ.dtype != np.uint8
                or hid.dtype != np.uint8
                or not (occ.flags.c_contiguous and hid.flags.c_contiguous)
            ):
                raise InputError(
                    f"PlaneSweep.plane: hidden must be C-ordered uint8 {shape} and {(*shape, n)} arrays, "
                    f"got {np.shape(occ)} and {np.shape(hid)}"
                )
        need8 = np.ascontiguousarray(need, np.uint8)
        box = np.array(_box(need8, self.radius + 1), np.int64)
        if box[1] <= box[0]:
            return
        _dilate(need8, self.radius + 1, box, self.tmp, self.samp)
        _dilate(need8, self.radius, box, self.tmp, self.win)
        p = self.pack
        _sample_phase(
            p.buf, p.off, p.hh, p.ww, p.R, p.C, p.P, p.r2max, p.scale, p.shift, p.frame,
            float(x0), float(y0), float(res), float(z), self.samp, box, self.s,
        )  # fmt: skip
        _gradient_phase(self.s, self.samp, self.win, box, self.inv, self.qx, self.qy, self.vv)
        blocks = _blocks(need8, box, BLOCK)
        workers = max(1, min(numba.get_num_threads(), len(blocks)))
        _block_cost(
            self.qx, self.qy, self.vv, need8, self.win, blocks, workers, self.radius, self.min_valid,
            int(best_k or 0), self.pi, self.pj, self.unit, self.sh, int(a), z0, cost, occ, hid,
        )  # fmt: skip
