"""Matching costs on a common grid: windowed NCC, multi-image cost, census.

Every cost here compares **slices**: images already resampled onto one common
grid (one Z plane of the OSGM voxel grid, or the left image and the right
image shifted by one disparity), NaN where an image does not see a cell.
Windows are ``(2 r + 1) x (2 r + 1)`` cells of that grid, clipped at the grid
border; because they live on the common grid, images rotated or scaled
against each other compare correctly.

Cost scale
----------
Costs are ``uint16`` in ``[0, COST_MAX]``. For NCC a pair contributes
``min(max(1 - ncc, 0), 1)`` (truncated: every correlation <= 0 is simply a
mismatch) and a cell's cost is ``round(COST_MAX * mean of the k best pair
contributions)``; one cost unit is therefore ``1 / COST_MAX`` of correlation.
For census a pair contributes ``min(2 h, 1)`` with ``h`` the fraction of
differing bits (``h = 0.5`` is what unrelated windows give). For the
saturated gradient measure (the default, see :func:`multi_image_cost`) a
pair contributes ``min(m, 1)`` with ``m`` the window mean of
``(|gx_a - gx_b| + |gy_a - gy_b|) / 2`` over saturated gradients in
``[-1, 1]`` (unrelated windows give about 1). All measures thus share one
scale (``COST_MAX`` = unrelated) and one set of SGM penalties.

Valid samples (the rule used by every function here)
----------------------------------------------------
Windows are clipped at the grid border; with ``n_w`` the number of window
cells inside the grid (``(2 r + 1)^2`` away from the border), a window of an
image is *valid* when at least ``min_count = max(1, ceil(min_valid * n_w))``
of its samples are valid (not NaN). A pair is compared over the samples
valid in **both** windows and needs ``min_count`` of them. Where both
windows are complete the per-image window statistics are used directly (the
fast path: box sums of each image once per slice, then one cross box sum per
pair); where one is partial the statistics are recomputed over the common
samples (exact, slower, only near NaN borders). A window is *flat* when its
variance is at most ``FLAT_EPS^2 * (mean^2 + FLAT_EPS^2)``: NCC is undefined
there (NaN from :func:`window_ncc`; the worst contribution, 1, in
:func:`multi_image_cost`). For the gradient measure the samples are the
gradient samples (valid where the sample and at least one neighbour along
the row and one along the column are); for
census the bits (valid where the sample and the centre are; the centre
itself counts as one sample).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from ..jit import njit, pjit, prange
from ..quickselect import select_rank

#: Largest cost. Chosen so that the sum over 16 paths of path costs, each at
#: most ``COST_MAX + P2`` (see :mod:`.aggregation`), fits ``uint16`` for every
#: accepted ``P2 <= P2_MAX = 4095 - COST_MAX``.
COST_MAX = 1023
#: Relative flatness threshold (see the module docstring).
FLAT_EPS = 1e-4
_FLAT2 = FLAT_EPS * FLAT_EPS
#: Code for "flat" in the internal NCC buffers (outside [-1, 1]).
_FLAT = -2.0
#: Rows per parallel strip of the cost kernels (bounded memory per thread).
_STRIP = 32
#: Measures offered by :func:`multi_image_cost`.
MEASURES = ("gradient", "ncc", "census")
#: Default measure (chosen by measurement, see docs/methods.md).
DEFAULT_MEASURE = "gradient"
#: Default window radius (5 x 5 cells).
DEFAULT_RADIUS = 2
#: Default fraction of valid samples a window needs.
DEFAULT_MIN_VALID = 0.5


def _check_radius(radius, name: str = "radius") -> int:
    if isinstance(radius, bool) or not isinstance(radius, int | np.integer) or radius < 0:
        raise InputError(f"{name}: expected a non-negative integer window radius, got {radius!r}")
    return int(radius)


def _check_min_valid(min_valid) -> float:
    v = float(min_valid)
    if not (0.0 < v <= 1.0):
        raise InputError(f"min_valid: expected a fraction in (0, 1], got {min_valid!r}")
    return v


# ---------------------------------------------------------------------------------------------
# kernels
# ---------------------------------------------------------------------------------------------


@njit
def _window_cells(r, c, rows, cols, radius):
    """Number of window cells of (r, c) inside the grid."""
    nr = min(rows, r + radius + 1) - max(0, r - radius)
    nc = min(cols, c + radius + 1) - max(0, c - radius)
    return nr * nc


@njit
def _need(n_w, min_valid):
    """Valid samples a window with ``n_w`` in-grid cells needs."""
    k = np.int64(math.ceil(min_valid * n_w - 1e-9))
    return max(np.int64(1), min(np.int64(n_w), k))


@njit
def _box_prod(a, b, r0, r1, radius, out):
    """Window sums of ``a * b`` for rows ``r0 <= r < r1`` into ``out[r - r0]``.

    ``a``, ``b`` (rows, cols) (zero where invalid); windows clipped at the
    grid border. Running column sums then a running row sum, in float64.
    """
    rows, cols = a.shape
    colsum = np.zeros(cols, np.float64)
    for rr in range(max(0, r0 - radius), min(rows, r0 + radius + 1)):
        for c in range(cols):
            colsum[c] += np.float64(a[rr, c]) * np.float64(b[rr, c])
    for r in range(r0, r1):
        if r > r0:
            ra = r + radius
            if ra < rows:
                for c in range(cols):
                    colsum[c] += np.float64(a[ra, c]) * np.float64(b[ra, c])
            rs = r - radius - 1
            if rs >= 0:
                for c in range(cols):
                    colsum[c] -= np.float64(a[rs, c]) * np.float64(b[rs, c])
        acc = 0.0
        for c in range(min(cols, radius + 1)):
            acc += colsum[c]
        for c in range(cols):
            if c > 0:
                ca = c + radius
                if ca < cols:
                    acc += colsum[ca]
                cs = c - radius - 1
                if cs >= 0:
                    acc -= colsum[cs]
            out[r - r0, c] = acc


@njit
def _image_stats(z, vf, r0, r1, radius, tmp, cnt, mean, istd):
    """Per-window count, mean and 1/std of one image for rows ``[r0, r1)``.

    ``z`` zero-filled values, ``vf`` 1/0 validity (float32). ``istd`` is 0
    for flat windows (and for windows without samples).
    """
    h = r1 - r0
    cols = z.shape[1]
    _box_prod(vf, vf, r0, r1, radius, tmp[0])
    _box_prod(z, vf, r0, r1, radius, tmp[1])
    _box_prod(z, z, r0, r1, radius, tmp[2])
    for i in range(h):
        for c in range(cols):
            n = tmp[0, i, c]
            k = np.int32(n + 0.5)
            cnt[i, c] = k
            if k == 0:
                mean[i, c] = 0.0
                istd[i, c] = 0.0
                continue
            m = tmp[1, i, c] / k
            v = tmp[2, i, c] / k - m * m
            mean[i, c] = m
            if v <= _FLAT2 * (m * m + _FLAT2):
                istd[i, c] = 0.0
            else:
                istd[i, c] = 1.0 / math.sqrt(v)


@njit
def _ncc_exact(za, zb, va, vb, r, c, radius, min_count):
    """NCC over the samples valid in both windows at (r, c): NaN (too few) or _FLAT."""
    rows, cols = za.shape
    n = 0
    sa = 0.0
    sb = 0.0
    saa = 0.0
    sbb = 0.0
    sab = 0.0
    for rr in range(max(0, r - radius), min(rows, r + radius + 1)):
        for cc in range(max(0, c - radius), min(cols, c + radius + 1)):
            if va[rr, cc] > 0 and vb[rr, cc] > 0:
                x = np.float64(za[rr, cc])
                y = np.float64(zb[rr, cc])
                n += 1
                sa += x
                sb += y
                saa += x * x
                sbb += y * y
                sab += x * y
    if n < min_count:
        return np.nan
    ma = sa / n
    mb = sb / n
    vara = saa / n - ma * ma
    varb = sbb / n - mb * mb
    if vara <= _FLAT2 * (ma * ma + _FLAT2) or varb <= _FLAT2 * (mb * mb + _FLAT2):
        return _FLAT
    return (sab / n - ma * mb) / math.sqrt(vara * varb)


@njit
def _pair_ncc(za, zb, va, vb, r0, r1, radius, min_valid, cnta, ma, isa, cntb, mb, isb, tmp, out):
    """NCC of one pair for rows ``[r0, r1)`` into ``out`` (NaN invalid, _FLAT flat)."""
    rows, cols = za.shape
    _box_prod(za, zb, r0, r1, radius, tmp)
    for i in range(r1 - r0):
        for c in range(cols):
            full = _window_cells(r0 + i, c, rows, cols, radius)
            min_count = _need(full, min_valid)
            ka = cnta[i, c]
            kb = cntb[i, c]
            if ka < min_count or kb < min_count:
                out[i, c] = np.nan
            elif ka == full and kb == full:
                if isa[i, c] == 0.0 or isb[i, c] == 0.0:
                    out[i, c] = _FLAT
                else:
                    v = (tmp[i, c] / full - ma[i, c] * mb[i, c]) * isa[i, c] * isb[i, c]
                    out[i, c] = min(1.0, max(-1.0, v))
            else:
                v = _ncc_exact(za, zb, va, vb, r0 + i, c, radius, min_count)
                if v == v and v != _FLAT:
                    v = min(1.0, max(-1.0, v))
                out[i, c] = v


@pjit
def _window_ncc_kernel(za, zb, va, vb, radius, min_valid, strip, out):
    rows, cols = za.shape
    nstrips = (rows + strip - 1) // strip
    for s in prange(nstrips):
        r0 = s * strip
        r1 = min(rows, r0 + strip)
        h = r1 - r0
        tmp = np.empty((3, h, cols), np.float64)
        cnta = np.empty((h, cols), np.int32)
        cntb = np.empty((h, cols), np.int32)
        ma = np.empty((h, cols), np.float64)
        mb = np.empty((h, cols), np.float64)
        isa = np.empty((h, cols), np.float64)
        isb = np.empty((h, cols), np.float64)
        _image_stats(za, va, r0, r1, radius, tmp, cnta, ma, isa)
        _image_stats(zb, vb, r0, r1, radius, tmp, cntb, mb, isb)
        res = np.empty((h, cols), np.float64)
        _pair_ncc(za, zb, va, vb, r0, r1, radius, min_valid, cnta, ma, isa, cntb, mb, isb, tmp[0], res)
        for i in range(h):
            for c in range(cols):
                v = res[i, c]
                out[r0 + i, c] = np.nan if v == _FLAT else v


@njit
def _auto_k(nv):
    """Default number of best pairs for ``nv`` valid views: all pairs among
    ``nv - nv // 3`` views (at least 2), i.e. robust to a third of the views
    being occluded or otherwise wrong."""
    m = nv - nv // 3
    if m < 2:
        m = 2
    return m * (m - 1) // 2


@njit
def _smallest_sum(buf, m, k):
    """Sum of the ``k`` smallest of ``buf[:m]`` (``1 <= k <= m``), by quickselect (reorders ``buf``).

    Linear on average, where the insertion sort it replaces was quadratic in the
    number of pairs (66 for 12 views).
    """
    select_rank(buf, 0, m - 1, k - 1)
    s = 0.0
    for q in range(k):
        s += buf[q]
    return s


@njit
def _combine(pc, npairs, nv, best_k, buf):
    """Mean of the ``k`` smallest valid pair contributions ``pc[:npairs]`` (NaN skipped).

    ``best_k <= 0``: :func:`_auto_k`. Returns -1.0 when no pair is valid.
    """
    m = 0
    for p in range(npairs):
        v = pc[p]
        if v == v:
            buf[m] = v
            m += 1
    if m == 0:
        return -1.0
    k = best_k if best_k > 0 else _auto_k(nv)
    if k > m:
        k = m
    if k == m:
        s = 0.0
        for j in range(m):
            s += buf[j]
        return s / k
    return _smallest_sum(buf, m, k) / k


@pjit
def _mic_ncc_kernel(z, vf, radius, min_valid, best_k, strip, cost_out, nv_out):
    n, rows, cols = z.shape
    npairs = n * (n - 1) // 2
    cmax = np.float64(COST_MAX)
    nstrips = (rows + strip - 1) // strip
    for s in prange(nstrips):
        r0 = s * strip
        r1 = min(rows, r0 + strip)
        h = r1 - r0
        tmp = np.empty((3, h, cols), np.float64)
        cnt = np.empty((n, h, cols), np.int32)
        mean = np.empty((n, h, cols), np.float64)
        istd = np.empty((n, h, cols), np.float64)
        for i in range(n):
            _image_stats(z[i], vf[i], r0, r1, radius, tmp, cnt[i], mean[i], istd[i])
        pc = np.empty((npairs, h, cols), np.float32)
        res = np.empty((h, cols), np.float64)
        p = 0
        for i in range(n):
            for j in range(i + 1, n):
                _pair_ncc(
                    z[i], z[j], vf[i], vf[j], r0, r1, radius, min_valid,
                    cnt[i], mean[i], istd[i], cnt[j], mean[j], istd[j], tmp[0], res,
                )  # fmt: skip
                for a in range(h):
                    for c in range(cols):
                        v = res[a, c]
                        if v != v:
                            pc[p, a, c] = np.nan
                        elif v == _FLAT:
                            pc[p, a, c] = 1.0
                        else:
                            pc[p, a, c] = min(1.0, max(0.0, 1.0 - v))
                p += 1
        col = np.empty(npairs, np.float32)
        buf = np.empty(npairs, np.float32)
        for a in range(h):
            for c in range(cols):
                min_count = _need(_window_cells(r0 + a, c, rows, cols, radius), min_valid)
                nv = 0
                for i in range(n):
                    if cnt[i, a, c] >= min_count:
                        nv += 1
                nv_out[r0 + a, c] = nv
                if nv < 2:
                    cost_out[r0 + a, c] = COST_MAX
                    continue
                for q in range(npairs):
                    col[q] = pc[q, a, c]
                m = _combine(col, npairs, nv, best_k, buf)
                if m < 0.0:
                    cost_out[r0 + a, c] = COST_MAX
                else:
                    cost_out[r0 + a, c] = np.uint16(min(cmax, m * cmax + 0.5))


@njit
def _popcount(x):
    x = x - ((x >> np.uint64(1)) & np.uint64(0x5555555555555555))
    x = (x & np.uint64(0x3333333333333333)) + ((x >> np.uint64(2)) & np.uint64(0x3333333333333333))
    x = (x + (x >> np.uint64(4))) & np.uint64(0x0F0F0F0F0F0F0F0F)
    return np.int64((x * np.uint64(0x0101010101010101)) >> np.uint64(56))


@njit
def _census_image(sl, radius, words, bits, valid):
    """Census bits of one slice: bit set where a window sample is below the centre.

    ``bits``/``valid`` (rows, cols, words) uint64; a bit is valid when both the
    sample and the centre are valid (samples outside the grid are invalid).
    The centre itself is not a bit. ``cnt`` of valid bits via popcount.
    """
    rows, cols = sl.shape
    for r in range(rows):
        for c in range(cols):
            for w in range(words):
                bits[r, c, w] = 0
                valid[r, c, w] = 0
            x0 = sl[r, c]
            if x0 != x0:
                continue
            b = 0
            for dr in range(-radius, radius + 1):
                for dc in range(-radius, radius + 1):
                    if dr == 0 and dc == 0:
                        continue
                    rr = r + dr
                    cc = c + dc
                    if 0 <= rr < rows and 0 <= cc < cols:
                        x = sl[rr, cc]
                        if x == x:
                            w = b >> 6
                            m = np.uint64(1) << np.uint64(b & 63)
                            valid[r, c, w] |= m
                            if x < x0:
                                bits[r, c, w] |= m
                    b += 1


@pjit
def _mic_census_kernel(sl, radius, min_valid, best_k, cost_out, nv_out):
    n, rows, cols = sl.shape
    nbits = (2 * radius + 1) * (2 * radius + 1) - 1
    words = max(1, (nbits + 63) // 64)
    npairs = n * (n - 1) // 2
    cmax = np.float64(COST_MAX)
    bits = np.empty((n, rows, cols, words), np.uint64)
    valid = np.empty((n, rows, cols, words), np.uint64)
    for i in prange(n):
        _census_image(sl[i], radius, words, bits[i], valid[i])
    for r in prange(rows):
        col = np.empty(max(1, npairs), np.float32)
        buf = np.empty(max(1, npairs), np.float32)
        ok = np.empty(n, np.bool_)
        for c in range(cols):
            # min_count counts window samples incl. the (valid) centre; bits exclude it
            need = max(1, _need(_window_cells(r, c, rows, cols, radius), min_valid) - 1)
            nv = 0
            for i in range(n):
                k = 0
                for w in range(words):
                    k += _popcount(valid[i, r, c, w])
                ok[i] = k >= need
                if ok[i]:
                    nv += 1
            nv_out[r, c] = nv
            if nv < 2:
                cost_out[r, c] = COST_MAX
                continue
            p = 0
            for i in range(n):
                for j in range(i + 1, n):
                    col[p] = np.nan
                    if ok[i] and ok[j]:
                        cb = 0
                        hd = 0
                        for w in range(words):
                            both = valid[i, r, c, w] & valid[j, r, c, w]
                            cb += _popcount(both)
                            hd += _popcount((bits[i, r, c, w] ^ bits[j, r, c, w]) & both)
                        if cb >= need:
                            col[p] = min(1.0, 2.0 * hd / cb)
                    p += 1
            m = _combine(col, npairs, nv, best_k, buf)
            if m < 0.0:
                cost_out[r, c] = COST_MAX
            else:
                cost_out[r, c] = np.uint16(min(cmax, m * cmax + 0.5))


@njit
def _diff1(a, x, b):
    """Derivative from the samples before (a), at (x) and after (b): central
    where both neighbours exist, else one-sided, NaN without neighbour."""
    if x != x:
        return np.nan
    if a == a and b == b:
        return 0.5 * (b - a)
    if b == b:
        return b - x
    if a == a:
        return x - a
    return np.nan


@njit
def _gradients(sl, gx, gy):
    """Derivatives along columns (gx) and rows (gy): central differences, one-sided
    where a neighbour is missing (NaN or outside the grid), NaN without any."""
    rows, cols = sl.shape
    for r in range(rows):
        for c in range(cols):
            a = sl[r, c - 1] if c > 0 else np.nan
            b = sl[r, c + 1] if c < cols - 1 else np.nan
            gx[r, c] = _diff1(a, sl[r, c], b)
            a = sl[r - 1, c] if r > 0 else np.nan
            b = sl[r + 1, c] if r < rows - 1 else np.nan
            gy[r, c] = _diff1(a, sl[r, c], b)


#: Quantisation of the saturated gradients (int16 values in [-Q, Q]).
_GQ = 127
#: Largest number of samples the saturation scale (median |g|) is taken from.
_MEDIAN_SAMPLES = 65536


@njit
def _saturate(g, q, v):
    """Quantised saturated gradient ``q = round(Q clip(g / median|g|, -1, 1))``
    (int16) and validity ``v`` (uint8, 0 where ``g`` is NaN, with ``q = 0``).

    The median of |g| is taken over at most ``_MEDIAN_SAMPLES`` valid
    samples (a regular stride through the slice); a zero median (a mostly
    flat slice) uses the mean of the non-zero |g| instead.
    """
    _saturate_with(g, _gradient_scale(g), q, v)


@njit
def _gradient_scale(g):
    """The saturation scale of :func:`_saturate`: median |g| over at most ``_MEDIAN_SAMPLES``
    valid samples (a regular stride), the mean of the non-zero |g| when that is 0, 0 without any."""
    flat = g.ravel()
    stride = max(1, flat.size // _MEDIAN_SAMPLES)
    vals = np.abs(flat[::stride])
    vals = vals[vals == vals]
    scale = 0.0
    if vals.size > 0:
        scale = np.median(vals)
        if scale <= 0.0:
            nz = vals[vals > 0.0]
            scale = nz.mean() if nz.size > 0 else 0.0
    return scale


@njit
def _quantise(x, inv):
    """``round(x inv)`` clipped to ``[-Q, Q]``, int16."""
    return np.int16(round(min(float(_GQ), max(-float(_GQ), x * inv))))


@njit
def _saturate_with(g, scale, q, v):
    """:func:`_saturate` with a given scale (median |g|; 0: every valid gradient quantises to 0)."""
    inv = _GQ / scale if scale > 0.0 else 0.0
    rows, cols = g.shape
    for r in range(rows):
        for c in range(cols):
            x = g[r, c]
            if x != x:
                q[r, c] = 0
                v[r, c] = 0
            else:
                q[r, c] = _quantise(x, inv)
                v[r, c] = 1


@njit
def _need_strip(r0, r1, rows, cols, radius, min_valid, out):
    """Samples a window needs, per cell of rows ``[r0, r1)`` (see ``_need``)."""
    for r in range(r0, r1):
        for c in range(cols):
            out[r - r0, c] = _need(_window_cells(r, c, rows, cols, radius), min_valid)


@njit
def _grad_count(v, r0, r1, radius, out):
    """Valid gradient samples per window for rows ``[r0, r1)`` (integer running sums)."""
    rows, cols = v.shape
    colsum = np.zeros(cols, np.int32)
    for rr in range(max(0, r0 - radius), min(rows, r0 + radius + 1)):
        for c in range(cols):
            colsum[c] += v[rr, c]
    for r in range(r0, r1):
        if r > r0:
            ra = r + radius
            if ra < rows:
                for c in range(cols):
                    colsum[c] += v[ra, c]
            rs = r - radius - 1
            if rs >= 0:
                for c in range(cols):
                    colsum[c] -= v[rs, c]
        _hsum_i(colsum, radius, out[r - r0])


@njit
def _hsum_i(colsum, radius, out):
    """Running horizontal window sums of an int32 row."""
    cols = colsum.shape[0]
    acc = np.int32(0)
    for c in range(min(cols, radius + 1)):
        acc += colsum[c]
    for c in range(cols):
        if c > 0:
            if c + radius < cols:
                acc += colsum[c + radius]
            if c - radius - 1 >= 0:
                acc -= colsum[c - radius - 1]
        out[c] = acc


@njit
def _grad_row(ax, ay, av, bx, by, bv, rr, dsum, dcnt, sign):
    """Adds (sign +1) or removes (-1) row ``rr`` of a pair to the column sums:
    ``|ax - bx| + |ay - by|`` and the count over the samples valid in both
    (branch-free: invalid samples have q = 0 and v = 0)."""
    cols = ax.shape[1]
    for c in range(cols):
        m = np.int32(av[rr, c] & bv[rr, c])
        d = abs(np.int32(ax[rr, c]) - np.int32(bx[rr, c])) + abs(np.int32(ay[rr, c]) - np.int32(by[rr, c]))
        dsum[c] += sign * d * m
        dcnt[c] += sign * m


@njit
def _grad_pair(ax, ay, av, bx, by, bv, r0, r1, radius, need, cnta, cntb, out):
    """Pair contributions ``min(1, mean (|dgx| + |dgy|) / 2)`` for rows ``[r0, r1)``
    into ``out`` (NaN where fewer than ``need`` common samples or views)."""
    rows, cols = ax.shape
    ds = np.zeros(cols, np.int32)
    dc = np.zeros(cols, np.int32)
    hs = np.empty(cols, np.int32)
    hc = np.empty(cols, np.int32)
    for rr in range(max(0, r0 - radius), min(rows, r0 + radius + 1)):
        _grad_row(ax, ay, av, bx, by, bv, rr, ds, dc, 1)
    scale = 1.0 / (2.0 * _GQ)
    for r in range(r0, r1):
        if r > r0:
            if r + radius < rows:
                _grad_row(ax, ay, av, bx, by, bv, r + radius, ds, dc, 1)
            if r - radius - 1 >= 0:
                _grad_row(ax, ay, av, bx, by, bv, r - radius - 1, ds, dc, -1)
        _hsum_i(ds, radius, hs)
        _hsum_i(dc, radius, hc)
        i = r - r0
        for c in range(cols):
            k = need[i, c]
            if hc[c] >= k and cnta[i, c] >= k and cntb[i, c] >= k:
                out[i, c] = min(1.0, hs[c] * scale / hc[c])
            else:
                out[i, c] = np.nan


#: ``scales`` of :func:`_prep_gradients` meaning "each slice's own".
_NO_SCALES = np.zeros((0, 2), np.float64)


@pjit
def _prep_gradients(sl, qx, qy, vv, scales):
    """Saturated gradients of every slice; ``scales`` (n, 2) median |g| along columns and rows,
    or an empty array: each slice's own (:func:`_saturate`)."""
    n = sl.shape[0]
    for i in prange(n):
        tx = np.empty(sl.shape[1:], np.float32)
        ty = np.empty(sl.shape[1:], np.float32)
        _gradients(sl[i], tx, ty)
        vx = np.empty(sl.shape[1:], np.uint8)
        if scales.shape[0] == n:
            _saturate_with(tx, scales[i, 0], qx[i], vx)
            _saturate_with(ty, scales[i, 1], qy[i], vv[i])
        else:
            _saturate(tx, qx[i], vx)
            _saturate(ty, qy[i], vv[i])
        vv[i] &= vx


@pjit
def _mic_grad_kernel(qx, qy, vv, radius, min_valid, best_k, strip, cost_out, nv_out):
    n, rows, cols = qx.shape
    npairs = n * (n - 1) // 2
    cmax = np.float64(COST_MAX)
    nstrips = (rows + strip - 1) // strip
    for s in prange(nstrips):
        r0 = s * strip
        r1 = min(rows, r0 + strip)
        h = r1 - r0
        need = np.empty((h, cols), np.int64)
        _need_strip(r0, r1, rows, cols, radius, min_valid, need)
        cnt = np.empty((n, h, cols), np.int32)
        for i in range(n):
            _grad_count(vv[i], r0, r1, radius, cnt[i])
        pc = np.empty((npairs, h, cols), np.float32)
        p = 0
        for i in range(n):
            for j in range(i + 1, n):
                _grad_pair(
                    qx[i], qy[i], vv[i], qx[j], qy[j], vv[j], r0, r1, radius, need, cnt[i], cnt[j], pc[p]
                )
                p += 1
        col = np.empty(max(1, npairs), np.float32)
        buf = np.empty(max(1, npairs), np.float32)
        for a in range(h):
            for c in range(cols):
                k = need[a, c]
                nv = 0
                for i in range(n):
                    if cnt[i, a, c] >= k:
                        nv += 1
                nv_out[r0 + a, c] = nv
                if nv < 2:
                    cost_out[r0 + a, c] = COST_MAX
                    continue
                if npairs == 1:
                    m = pc[0, a, c]
                    m = -1.0 if m != m else m
                else:
                    for q in range(npairs):
                        col[q] = pc[q, a, c]
                    m = _combine(col, npairs, nv, best_k, buf)
                if m < 0.0:
                    cost_out[r0 + a, c] = COST_MAX
                else:
                    cost_out[r0 + a, c] = np.uint16(min(cmax, m * cmax + 0.5))


# ---------------------------------------------------------------------------------------------
# public API
# ---------------------------------------------------------------------------------------------


def _prepare(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    valid = np.isfinite(x)
    z = np.where(valid, x, np.float32(0.0)).astype(np.float32, copy=False)
    return z, valid.astype(np.float32)


def window_ncc(
    a: np.ndarray, b: np.ndarray, radius: int = DEFAULT_RADIUS, *, min_valid: float = DEFAULT_MIN_VALID
) -> np.ndarray:
    """Normalised cross-correlation of two images over square windows.

    Parameters
    ----------
    a, b : (rows, cols) float array
        Two images on the same grid; NaN marks invalid samples.
    radius : int
        Window radius ``r``: windows are ``(2 r + 1) x (2 r + 1)`` cells,
        clipped at the grid border.
    min_valid : float in (0, 1]
        Fraction of the window (clipped at the grid border) that must be valid in **both** images
        (see the module docstring for the exact rule).

    Returns
    -------
    (rows, cols) float32
        NCC in [-1, 1] over the samples valid in both windows; NaN where
        fewer than ``min_count`` such samples exist (module docstring) or where
        either window is flat (variance <= ``FLAT_EPS^2 (mean^2 + FLAT_EPS^2)``).
    """
    radius = _check_radius(radius)
    min_valid = _check_min_valid(min_valid)
    a = np.asarray(a, dtype=np.float32)
    b = np.asarray(b, dtype=np.float32)
    if a.ndim != 2 or a.shape != b.shape:
        raise InputError(f"window_ncc: expected two equally shaped 2-D images, got {a.shape} and {b.shape}")
    za, va = _prepare(a)
    zb, vb = _prepare(b)
    out = np.empty(a.shape, np.float32)
    _window_ncc_kernel(za, zb, va, vb, radius, min_valid, _STRIP, out)
    return out


def multi_image_cost(
    slices: np.ndarray,
    radius: int = DEFAULT_RADIUS,
    best_k: int | None = None,
    measure: str = DEFAULT_MEASURE,
    out: tuple[np.ndarray, np.ndarray] | None = None,
    *,
    min_valid: float = DEFAULT_MIN_VALID,
    scales: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Matching cost of n images resampled onto one common grid.

    Parameters
    ----------
    slices : (n, rows, cols) float array
        The n images sampled at the cells of one grid (for OSGM: at the cell
        centres of one plane Z = const), NaN where an image does not see the
        cell. ``2 <= n <= 255``. Several planes may be stacked along the rows
        in one call (fewer calls, and for ``"gradient"`` one saturation scale
        per image for all of them) if the cells read from each plane are at
        least ``radius`` rows (``radius + 1`` for ``"gradient"``, whose row
        derivative looks one row further) away from the plane's edges.
    radius : int
        Window radius ``r`` (windows of ``(2 r + 1)^2`` cells).
    best_k : int or None
        Number of best pairs averaged per cell. ``None`` (default): all pairs
        among ``v - v // 3`` of the ``v`` valid views (at least 2), i.e. the
        best ``m (m - 1) / 2`` pairs with ``m = max(2, v - v // 3)``: 1 pair
        for 2 or 3 views, 3 for 4, 6 for 5 or 6, 10 for 7, 15 for 9; robust to
        a third of the views being occluded. An integer caps k at the number
        of valid pairs.
    measure : {"gradient", "ncc", "census"}
        ``"gradient"`` (default): each slice's gradients along rows and
        columns of the grid (central differences, one-sided next to missing
        samples),
        divided by the slice's median absolute gradient and clipped to
        [-1, 1] (invariant to gain and offset per image; weak texture stays
        weak evidence instead of being normalised up, and the saturation
        makes strong edges robust to contrast changes); a pair compares the
        window mean of ``(|gx_a - gx_b| + |gy_a - gy_b|) / 2`` over the
        samples valid in both. ``"ncc"``: pairwise NCC (invariant to gain
        and offset). ``"census"``: each image's window compared with its own
        centre sample, Hamming distance between the images' bit strings over
        the bits valid in both (invariant to monotonic radiometry).
    out : (cost, n_views), optional
        Preallocated ``(rows, cols)`` uint16 and uint8 arrays (e.g. views of
        one level of a cost volume ``cost[:, :, k]``) to write into.
    min_valid : float in (0, 1]
        Fraction of a window that must be valid (module docstring).
    scales : (n, 2) float array, optional
        ``"gradient"`` only: the saturation scales (median absolute gradient
        along columns and along rows) of each image, instead of each slice's
        own; OSGM takes one per image for a whole tile, so that the costs of
        all its planes share one scale.

    Returns
    -------
    cost : (rows, cols) uint16
        In ``[0, COST_MAX]``: ``round(COST_MAX * mean of the k best pair
        contributions)`` (module docstring). ``COST_MAX`` where fewer than
        two views are valid or no pair could be compared.
    n_views : (rows, cols) uint8
        Number of images whose window is valid at the cell.
    """
    radius = _check_radius(radius)
    min_valid = _check_min_valid(min_valid)
    if measure not in MEASURES:
        raise InputError(f"measure: expected one of {MEASURES}, got {measure!r}")
    s = np.asarray(slices)
    if s.ndim != 3 or not (2 <= s.shape[0] <= 255):
        raise InputError(f"slices: expected an (n, rows, cols) array with 2 <= n <= 255, got shape {s.shape}")
    s = s.astype(np.float32, copy=False)
    if best_k is None:
        k = 0
    else:
        if isinstance(best_k, bool) or not isinstance(best_k, int | np.integer) or best_k < 1:
            raise InputError(f"best_k: expected a positive integer or None, got {best_k!r}")
        k = int(best_k)
    shape = s.shape[1:]
    if out is None:
        cost = np.empty(shape, np.uint16)
        nv = np.empty(shape, np.uint8)
    else:
        cost, nv = out
        if cost.shape != shape or cost.dtype != np.uint16 or nv.shape != shape or nv.dtype != np.uint8:
            raise InputError(f"out: expected ({shape} uint16, {shape} uint8) arrays")
    # kernels write through strided views too
    if measure == "gradient":
        qx = np.empty(s.shape, np.int16)
        qy = np.empty(s.shape, np.int16)
        vv = np.empty(s.shape, np.uint8)
        if scales is None:
            sc = _NO_SCALES
        else:
            sc = np.asarray(scales, np.float64)
            if sc.shape != (s.shape[0], 2) or not np.all(np.isfinite(sc) & (sc >= 0)):
                raise InputError(
                    f"scales: expected ({s.shape[0]}, 2) finite non-negative scales, got shape {sc.shape}"
                )
        _prep_gradients(np.ascontiguousarray(s), qx, qy, vv, np.ascontiguousarray(sc))
        _mic_grad_kernel(qx, qy, vv, radius, min_valid, k, _STRIP, cost, nv)
    elif measure == "ncc":
        z, vf = _prepare(s)
        _mic_ncc_kernel(z, vf, radius, min_valid, k, _STRIP, cost, nv)
    else:
        _mic_census_kernel(np.ascontiguousarray(s), radius, min_valid, k, cost, nv)
    return cost, nv
