"""In-place selection of the value of a given rank (quickselect), shared by the compiled kernels.

Linear on average: the multi-view matching cost (:mod:`truortho.core.sgm.cost`) sums the smallest
pair costs of a voxel with it, and the colour statistics of the true ortho
(:mod:`truortho.core.ortho.color`) take group percentiles with it.
"""

from __future__ import annotations

from .jit import njit


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
