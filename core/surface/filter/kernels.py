"""numba kernels of the DSM filter: confidence and outlier tests, edge sharpening, plane smoothing.

Arrays in, arrays out (masks and outputs preallocated by the caller); the stages that call them
are in :mod:`.stages`.
"""

from __future__ import annotations

import numpy as np

from ...jit import pjit, prange


@pjit
def _outlier_pass(z, conf, has_conf, t, half, min_support, out_mask):
    """Flag cells that depart from their (confidence-weighted) window median by more than
    their threshold and have fewer than ``min_support`` neighbours within it."""
    nr, nc = z.shape
    n_max = (2 * half + 1) ** 2
    for r in prange(nr):
        vals = np.empty(n_max)
        wts = np.empty(n_max)
        for c in range(nc):
            zc = z[r, c]
            if not np.isfinite(zc):
                continue
            tc = t * (0.5 + 0.5 * conf[r, c]) if has_conf else t
            support = 0
            n = 0
            for rr in range(max(r - half, 0), min(r + half + 1, nr)):
                for cc in range(max(c - half, 0), min(c + half + 1, nc)):
                    if rr == r and cc == c:
                        continue
                    v = z[rr, cc]
                    if not np.isfinite(v):
                        continue
                    if abs(v - zc) <= tc:
                        support += 1
                    vals[n] = v
                    wts[n] = (conf[rr, cc] + 1e-3) if has_conf else 1.0
                    n += 1
            if support >= min_support or n == 0:
                continue
            order = np.argsort(vals[:n])
            total = 0.0
            for k in range(n):
                total += wts[k]
            acc = 0.0
            med = vals[order[n - 1]]
            for k in range(n):
                acc += wts[order[k]]
                if acc >= 0.5 * total:
                    med = vals[order[k]]
                    break
            if abs(zc - med) > tc:
                out_mask[r, c] = True


@pjit
def _confidence_pass(z, conf, c_ref, t, half, out_mask):
    """Flag cells less confident than ``c_ref`` that depart by more than ``t`` from the median of
    the confident cells (``conf >= c_ref``) of their window (at least 8 of them)."""
    nr, nc = z.shape
    n_max = (2 * half + 1) ** 2
    for r in prange(nr):
        vals = np.empty(n_max)
        for c in range(nc):
            zc = z[r, c]
            if not np.isfinite(zc) or conf[r, c] >= c_ref:
                continue
            n = 0
            for rr in range(max(r - half, 0), min(r + half + 1, nr)):
                for cc in range(max(c - half, 0), min(c + half + 1, nc)):
                    v = z[rr, cc]
                    if np.isfinite(v) and conf[rr, cc] >= c_ref:
                        vals[n] = v
                        n += 1
            if n < 8:
                continue
            srt = np.sort(vals[:n])
            med = srt[n // 2] if n % 2 else 0.5 * (srt[n // 2 - 1] + srt[n // 2])
            if abs(zc - med) > t:
                out_mask[r, c] = True


@pjit
def _sharpen_pass(z, step, out, changed):
    """Snap cells between two levels of their 5x5 window (a blurred step) to the nearer level.

    Levels are the 20th and 80th percentiles of the valid neighbours; a cell is snapped when
    they differ by more than ``step`` and the cell is farther than a quarter of that from both.
    """
    nr, nc = z.shape
    for r in prange(nr):
        vals = np.empty(24)
        for c in range(nc):
            zc = z[r, c]
            out[r, c] = zc
            if not np.isfinite(zc):
                continue
            n = 0
            lo = np.inf
            hi = -np.inf
            for rr in range(max(r - 2, 0), min(r + 3, nr)):
                for cc in range(max(c - 2, 0), min(c + 3, nc)):
                    if rr == r and cc == c:
                        continue
                    v = z[rr, cc]
                    if np.isfinite(v):
                        vals[n] = v
                        n += 1
                        lo = min(lo, v)
                        hi = max(hi, v)
            if n < 8 or hi - lo <= step:
                continue
            srt = np.sort(vals[:n])
            p20 = srt[int(0.1 * (n - 1) + 0.5)]
            p80 = srt[int(0.9 * (n - 1) + 0.5)]
            gap = p80 - p20
            if gap <= step:
                continue
            d_lo = abs(zc - p20)
            d_hi = abs(zc - p80)
            if min(d_lo, d_hi) <= 0.25 * gap or zc < p20 or zc > p80:
                continue
            out[r, c] = p20 if d_lo < d_hi else p80
            changed[r, c] = True


@pjit
def _plane_smooth(z, radius, tol, out, changed):
    nr, nc = z.shape
    for r in prange(nr):
        for c in range(nc):
            zc = z[r, c]
            out[r, c] = zc
            if not np.isfinite(zc):
                continue
            # normal equations of z = a + b dx + c dy over the tolerant neighbours
            s1 = 0.0
            sx = 0.0
            sy = 0.0
            sxx = 0.0
            syy = 0.0
            sxy = 0.0
            sz = 0.0
            sxz = 0.0
            syz = 0.0
            szz = 0.0
            for rr in range(max(r - radius, 0), min(r + radius + 1, nr)):
                for cc in range(max(c - radius, 0), min(c + radius + 1, nc)):
                    v = z[rr, cc]
                    if not np.isfinite(v) or abs(v - zc) > tol:
                        continue
                    dx = float(cc - c)
                    dy = float(rr - r)
                    dv = v - zc
                    s1 += 1.0
                    sx += dx
                    sy += dy
                    sxx += dx * dx
                    syy += dy * dy
                    sxy += dx * dy
                    sz += dv
                    sxz += dx * dv
                    syz += dy * dv
                    szz += dv * dv
            if s1 < 6:
                continue
            # solve the 3x3 system by Cramer's rule
            a11, a12, a13 = s1, sx, sy
            a22, a23 = sxx, sxy
            a33 = syy
            det = (
                a11 * (a22 * a33 - a23 * a23) - a12 * (a12 * a33 - a23 * a13) + a13 * (a12 * a23 - a22 * a13)
            )
            if abs(det) < 1e-9:
                continue
            d0 = sz * (a22 * a33 - a23 * a23) - a12 * (sxz * a33 - a23 * syz) + a13 * (sxz * a23 - a22 * syz)
            d1 = a11 * (sxz * a33 - a23 * syz) - sz * (a12 * a33 - a23 * a13) + a13 * (a12 * syz - sxz * a13)
            d2 = a11 * (a22 * syz - sxz * a23) - a12 * (a12 * syz - sxz * a13) + sz * (a12 * a23 - a22 * a13)
            p0 = d0 / det
            p1 = d1 / det
            p2 = d2 / det
            # residual sum of squares: sum (dv - p0 - p1 dx - p2 dy)^2
            rss = (
                szz
                - 2.0 * (p0 * sz + p1 * sxz + p2 * syz)
                + p0 * p0 * s1
                + p1 * p1 * sxx
                + p2 * p2 * syy
                + 2.0 * (p0 * p1 * sx + p0 * p2 * sy + p1 * p2 * sxy)
            )
            if rss / s1 <= 0.25 * tol * tol:
                out[r, c] = zc + p0
                changed[r, c] = abs(p0) > 1e-3 * tol
