"""In-place selection of the value of a given rank (quickselect), shared by the compiled kernels.

Linear on average: the multi-view matching cost (:mod:`truortho.core.sgm.cost`) sums the smallest
pair costs of a voxel with it, and the colour statistics of the true ortho
(:mod:`truortho.core.ortho.color`) take group percentiles with it. :func:`median_of` (a kernel's
median of a small buffer: the true ortho's agreement of the views) and :func:`nanmedian_axis0`
(``numpy.nanmedian(a, axis=0)`` compiled: OSGM's median over the views) are built on it.
"""

from __future__ import annotations

import numpy as np

from .errors import InputError
from .jit import njit, pjit, prange


@njit
def select_rank(buf, lo, hi, k):
    """Reorder ``buf[lo..hi]`` (inclusive, ``lo <= k <= hi``) in place so that ``buf[k]`` holds the
    value of rank ``k - lo`` among them, values <= it before and >= it after (median-of-three
    pivots, Hoare partition)."""
    if lo < 0 or hi >= len(buf) or not lo <= k <= hi:
        raise ValueError("select_rank: expected 0 <= lo <= k <= hi < len(buf)")
    while lo < hi:
        mid = (lo + hi) // 2
        # median of three as the pivot
        a, b, c = buf[lo], buf[mid], buf[hi]
        if a > b:
            a, b = b, a
        if b > c:
            b = c
            if a > b:
                b = a
        pivot = b
        i = lo
        j = hi
        while i <= j:
            while buf[i] < pivot:
                i += 1
            while buf[j] > pivot:
                j -= 1
            if i <= j:
                t = buf[i]
                buf[i] = buf[j]
                buf[j] = t
                i += 1
                j -= 1
        # buf[lo..j] <= pivot <= buf[i..hi]
        if k <= j:
            hi = j
        elif k >= i:
            lo = i
        else:
            break


@njit
def median_of(buf, n):
    """Median of ``buf[:n]`` (``n >= 1``; reorders it): the middle value, or the mean of the two
    middle values for even ``n`` (as ``numpy.median``, in ``buf``'s precision)."""
    h = n // 2
    select_rank(buf, 0, n - 1, h)
    high = buf[h]
    if n % 2 == 1:
        return high
    low = buf[0]  # the other middle value: the largest of the lower half
    for j in range(1, h):
        low = max(low, buf[j])
    return 0.5 * (low + high)  # the sum in buf's precision, as numpy.mean of the two


@pjit
def _nanmedian_axis0_kernel(a, out):
    n = a.shape[0]
    m = a.shape[1]
    for j in prange(m):
        buf = np.empty(n, a.dtype)
        k = 0
        for i in range(n):
            v = a[i, j]
            if v == v:
                buf[k] = v
                k += 1
        out[j] = median_of(buf, k) if k > 0 else np.nan


def nanmedian_axis0(a: np.ndarray) -> np.ndarray:
    """``numpy.nanmedian(a, axis=0)`` for float arrays (NaN where a column holds no value), without
    its warning and without numpy's masked-array path, which sorts every column: on OSGM's guide
    images and colour choice (a few to 40 views per cell) that path took about 5 % of a battery
    scene's matching time."""
    x = np.asarray(a)
    if x.ndim < 1 or x.dtype not in (np.float32, np.float64):
        raise InputError(f"nanmedian_axis0: expected a float32 or float64 array, got {x.dtype} {x.shape}")
    rest = x.shape[1:]
    out = np.full(int(np.prod(rest)), np.nan, x.dtype)
    if x.shape[0] > 0 and out.size > 0:
        _nanmedian_axis0_kernel(np.ascontiguousarray(x.reshape(x.shape[0], out.size)), out)
    return out.reshape(rest)
