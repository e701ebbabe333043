"""SGM kernels against slow, obviously-correct references (small random inputs)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from truortho.core.errors import InputError
from truortho.core.sgm import (
    COST_MAX,
    P2_MAX,
    adaptive_p2,
    aggregate,
    median_filter,
    multi_image_cost,
    select,
    valid_cells,
    window_ncc,
)
from truortho.core.sgm import aggregation as agg_mod
from truortho.core.sgm import cost as cost_mod
from truortho.core.sgm import selection as sel_mod

FLAT2 = cost_mod.FLAT_EPS**2

# ------------------------------------------------------------------------------------------
# references
# ------------------------------------------------------------------------------------------


def _window(shape, r, c, radius):
    rows, cols = shape
    rs = slice(max(0, r - radius), min(rows, r + radius + 1))
    return rs, slice(max(0, c - radius), min(cols, c + radius + 1))


def _need(n_w, min_valid):
    return max(1, min(n_w, math.ceil(min_valid * n_w - 1e-9)))


def ref_pair(a, b, r, c, radius, min_valid):
    """(ncc or None if too few samples, flat flag)."""
    w = _window(a.shape, r, c, radius)
    wa, wb = a[w].astype(np.float64), b[w].astype(np.float64)
    need = _need(wa.size, min_valid)
    if np.isfinite(wa).sum() < need or np.isfinite(wb).sum() < need:
        return None, False
    both = np.isfinite(wa) & np.isfinite(wb)
    if both.sum() < need:
        return None, False
    x, y = wa[both], wb[both]
    vx, vy = x.var(), y.var()
    if vx <= FLAT2 * (x.mean() ** 2 + FLAT2) or vy <= FLAT2 * (y.mean() ** 2 + FLAT2):
        return None, True
    return float(np.clip(((x - x.mean()) * (y - y.mean())).mean() / math.sqrt(vx * vy), -1, 1)), False


def ref_window_ncc(a, b, radius, min_valid=0.5):
    out = np.full(a.shape, np.nan)
    for r in range(a.shape[0]):
        for c in range(a.shape[1]):
            v, _ = ref_pair(a, b, r, c, radius, min_valid)
            if v is not None:
                out[r, c] = v
    return out


def ref_k(nv, best_k):
    if best_k is not None:
        return best_k
    m = max(2, nv - nv // 3)
    return m * (m - 1) // 2


def ref_multi_cost(slices, radius, best_k=None, min_valid=0.5, measure="ncc"):
    n, rows, cols = slices.shape
    cost = np.zeros((rows, cols), np.int64)
    nviews = np.zeros((rows, cols), np.int64)
    for r in range(rows):
        for c in range(cols):
            w = _window((rows, cols), r, c, radius)
            need = _need(slices[0][w].size, min_valid)
            if measure == "ncc":
                ok = [np.isfinite(slices[i][w]).sum() >= need for i in range(n)]
            else:
                ok = [
                    np.isfinite(slices[i][r, c]) and np.isfinite(slices[i][w]).sum() >= need for i in range(n)
                ]
            nv = sum(ok)
            nviews[r, c] = nv
            contrib = []
            for i in range(n):
                for j in range(i + 1, n):
                    if not (ok[i] and ok[j]):
                        continue
                    if measure == "ncc":
                        v, flat = ref_pair(slices[i], slices[j], r, c, radius, min_valid)
                        if flat:
                            contrib.append(1.0)
                        elif v is not None:
                            contrib.append(min(1.0, max(0.0, 1.0 - v)))
                    else:
                        h = ref_census_pair(slices[i], slices[j], r, c, radius, need - 1)
                        if h is not None:
                            contrib.append(h)
            if nv < 2 or not contrib:
                cost[r, c] = COST_MAX
                continue
            k = min(ref_k(nv, best_k), len(contrib))
            m = float(np.mean(sorted(contrib)[:k]))
            cost[r, c] = int(math.floor(min(COST_MAX, m * COST_MAX + 0.5)))
    return cost, nviews


def ref_derivative(x, axis):
    x = np.moveaxis(x.astype(np.float64), axis, 0)
    pad = np.full((1,) + x.shape[1:], np.nan)
    a = np.concatenate([pad, x[:-1]])  # before
    b = np.concatenate([x[1:], pad])  # after
    g = np.where(np.isfinite(a) & np.isfinite(b), 0.5 * (b - a), np.where(np.isfinite(b), b - x, x - a))
    return np.moveaxis(np.where(np.isfinite(x), g, np.nan), 0, axis)


def ref_saturated_gradients(x):
    gx, gy = ref_derivative(x, 1), ref_derivative(x, 0)
    out = []
    for g in (gx, gy):
        v = np.abs(g[np.isfinite(g)])
        s = np.median(v) if v.size else 0.0
        if s <= 0 and v.size:
            s = v[v > 0].mean() if (v > 0).any() else 0.0
        sat = np.clip(g / s, -1, 1) if s > 0 else np.where(np.isfinite(g), 0.0, np.nan)
        out.append(np.rint(sat * cost_mod._GQ) / cost_mod._GQ)  # quantised to int16 steps in the kernel
    return out


def ref_gradient_cost(slices, radius, best_k=None, min_valid=0.5):
    n, rows, cols = slices.shape
    g = [ref_saturated_gradients(s) for s in slices]
    cost = np.zeros((rows, cols), np.int64)
    nviews = np.zeros((rows, cols), np.int64)
    for r in range(rows):
        for c in range(cols):
            w = _window((rows, cols), r, c, radius)
            need = _need(slices[0][w].size, min_valid)
            ok = [(np.isfinite(g[i][0][w]) & np.isfinite(g[i][1][w])).sum() >= need for i in range(n)]
            nv = sum(ok)
            nviews[r, c] = nv
            contrib = []
            for i in range(n):
                for j in range(i + 1, n):
                    if not (ok[i] and ok[j]):
                        continue
                    dd = 0.5 * (np.abs(g[i][0][w] - g[j][0][w]) + np.abs(g[i][1][w] - g[j][1][w]))
                    if np.isfinite(dd).sum() >= need:
                        contrib.append(min(1.0, float(np.nanmean(dd))))
            if nv < 2 or not contrib:
                cost[r, c] = COST_MAX
                continue
            k = min(ref_k(nv, best_k), len(contrib))
            m = float(np.mean(sorted(contrib)[:k]))
            cost[r, c] = int(math.floor(min(COST_MAX, m * COST_MAX + 0.5)))
    return cost, nviews


def ref_census_pair(a, b, r, c, radius, need):
    rows, cols = a.shape
    nb = nd = 0
    for dr in range(-radius, radius + 1):
        for dc in range(-radius, radius + 1):
            if dr == 0 and dc == 0:
                continue
            rr, cc = r + dr, c + dc
            if not (0 <= rr < rows and 0 <= cc < cols):
                continue
            if not (np.isfinite(a[rr, cc]) and np.isfinite(b[rr, cc])):
                continue
            nb += 1
            nd += (a[rr, cc] < a[r, c]) != (b[rr, cc] < b[r, c])
    if nb < max(1, need):
        return None
    return min(1.0, 2.0 * nd / nb)


def _dirs(paths):
    d = [(0, 1), (1, 0), (1, 1), (1, -1)]
    if paths == 16:
        d += [(1, 2), (1, -2), (2, 1), (2, -1)]
    return d + [(-a, -b) for a, b in d]


def ref_aggregate(cost, p1, p2, paths=8, z0=None, guide=None, edge=0.0, trend=None, trend_max=0):
    rows, cols, nd = cost.shape
    z0 = np.zeros((rows, cols), int) if z0 is None else z0
    p2 = np.broadcast_to(np.asarray(p2), (rows, cols))
    S = np.zeros(cost.shape, np.int64)
    for dr, dc in _dirs(paths):
        L = {}
        rr = range(rows) if dr >= 0 else range(rows - 1, -1, -1)
        cc = range(cols) if dc >= 0 else range(cols - 1, -1, -1)
        for r in rr:
            for c in cc:
                C = cost[r, c].astype(np.int64)
                q = (r - dr, c - dc)
                if not (0 <= q[0] < rows and 0 <= q[1] < cols):
                    Lp = C.copy()
                else:
                    Lq = L[q]
                    mq = Lq.min()
                    lo = z0[q]  # absolute level of the neighbour's level 0
                    if trend is not None:  # a slope of the trend: p's level a continues q's a - rise
                        rise = int(trend[r, c]) - int(trend[q])
                        lo += rise if abs(rise) <= trend_max else 0
                    Lp = np.empty(nd, np.int64)
                    pen2 = int(p2[r, c])
                    if guide is not None:
                        g = abs(float(guide[r, c]) - float(guide[q]))
                        pen2 = max(min(pen2, p1 + 1), int(math.floor(pen2 * edge / (edge + g) + 0.5)))
                    for d in range(nd):
                        a = z0[r, c] + d
                        cand = [mq + pen2]
                        for b, pen in ((a, 0), (a - 1, p1), (a + 1, p1)):
                            if lo <= b < lo + nd:
                                cand.append(Lq[b - lo] + pen)
                        Lp[d] = C[d] + min(cand) - mq
                L[(r, c)] = Lp
                S[r, c] += Lp
    return S


def ref_select(S, z0, uniq, valid=None, reject_edges=False):
    rows, cols, nd = S.shape
    lev = np.full((rows, cols), np.nan)
    conf = np.full((rows, cols), np.nan)
    for r in range(rows):
        for c in range(cols):
            if valid is not None and not valid[r, c]:
                continue
            s = S[r, c].astype(np.float64)
            b = int(np.argmin(s))
            m = s[b]
            others = [s[d] for d in range(nd) if abs(d - b) > 1]
            m2 = min(others) if others else None
            if m2 is not None and m > uniq * m2:
                continue
            if reject_edges and nd > 1 and b in (0, nd - 1):
                continue
            delta = 0.0
            if 0 < b < nd - 1:
                den = max(s[b - 1] - m, s[b + 1] - m)
                if den > 0:
                    delta = float(np.clip(0.5 * (s[b - 1] - s[b + 1]) / den, -0.5, 0.5))
            lev[r, c] = z0[r, c] + b + delta
            conf[r, c] = 1 - m / m2 if (m2 is not None and m2 > 0) else 0.0
    return lev, conf


def ref_median(x, size, min_count=1):
    rad = size // 2
    out = np.full(x.shape, np.nan)
    for r in range(x.shape[0]):
        for c in range(x.shape[1]):
            if np.isnan(x[r, c]):
                continue
            w = x[_window(x.shape, r, c, rad)]
            w = w[np.isfinite(w)]
            if w.size >= min_count:
                out[r, c] = np.median(w)
    return out


# ------------------------------------------------------------------------------------------
# inputs
# ------------------------------------------------------------------------------------------


def _images(rng, n, shape, nan_frac=0.08, related=True):
    base = rng.random(shape)
    out = []
    for i in range(n):
        x = base + 0.3 * rng.random(shape) if related else rng.random(shape)
        x = (0.5 + i) * x + 3.0 * i  # gain and offset per image
        x[rng.random(shape) < nan_frac] = np.nan
        out.append(x)
    s = np.stack(out).astype(np.float32)
    s[0, :2, :3] = np.nan  # a block of missing samples
    return s


# ------------------------------------------------------------------------------------------
# cost
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("radius,min_valid", [(1, 0.5), (2, 0.5), (2, 1.0), (3, 0.3)])
def test_window_ncc_matches_reference(rng, radius, min_valid):
    s = _images(rng, 2, (13, 17))
    got = window_ncc(s[0], s[1], radius, min_valid=min_valid)
    want = ref_window_ncc(s[0], s[1], radius, min_valid)
    assert got.dtype == np.float32 and got.shape == s[0].shape
    np.testing.assert_array_equal(np.isnan(got), np.isnan(want))
    np.testing.assert_allclose(got[np.isfinite(want)], want[np.isfinite(want)], atol=2e-5)
    assert np.isfinite(want).sum() >= (0.5 * want.size if min_valid < 1 else 1)


def test_window_ncc_is_gain_offset_invariant_and_flags_flat(rng):
    a = rng.random((12, 12)).astype(np.float32)
    b = (3.0 * a + 7.0).astype(np.float32)
    n = window_ncc(a, b, 2)
    assert np.allclose(n, 1.0, atol=1e-4)
    assert np.allclose(window_ncc(a, -b, 2), -1.0, atol=1e-4)
    flat = np.full((12, 12), 0.25, np.float32)
    assert np.isnan(window_ncc(a, flat, 2)).all()


@pytest.mark.parametrize("n,best_k", [(2, None), (3, None), (4, None), (5, 2), (6, None)])
def test_multi_image_cost_matches_reference(rng, n, best_k):
    s = _images(rng, n, (11, 14))
    s[n - 1, 5:, 6:] = np.nan  # an image that misses a corner
    cost, nv = multi_image_cost(s, 2, best_k=best_k, measure="ncc")
    want, wnv = ref_multi_cost(s, 2, best_k)
    assert cost.dtype == np.uint16 and nv.dtype == np.uint8
    np.testing.assert_array_equal(nv, wnv)
    assert np.abs(cost.astype(int) - want).max() <= 1  # rounding of float sums
    assert (cost[wnv < 2] == COST_MAX).all()


def test_multi_image_cost_occluded_view_is_ignored(rng):
    """Best-k pairs: one view that sees something else does not spoil the cost."""
    base = rng.random((20, 20)).astype(np.float32)
    good = [g * base + o for g, o in ((1, 0), (2, 1), (0.5, 3), (1.5, -1))]
    bad = rng.random((20, 20)).astype(np.float32)
    c_clean, _ = multi_image_cost(np.stack(good), 2, measure="ncc")
    c_occl, nv = multi_image_cost(np.stack(good + [bad]), 2, measure="ncc")
    assert (nv == 5).all()
    assert c_clean.max() <= 2 and c_occl.max() <= 2  # 5 views: best 6 pairs, all among the good 4
    c_all, _ = multi_image_cost(np.stack(good + [bad]), 2, best_k=10, measure="ncc")
    assert np.median(c_all) > 200  # averaging all pairs would be hurt


@pytest.mark.parametrize("n,radius,best_k", [(2, 2, None), (3, 1, None), (4, 2, 2), (5, 3, None)])
def test_gradient_cost_matches_reference(rng, n, radius, best_k):
    s = _images(rng, n, (12, 15))
    s[n - 1, 6:, 8:] = np.nan
    cost, nv = multi_image_cost(s, radius, best_k=best_k, measure="gradient")
    want, wnv = ref_gradient_cost(s, radius, best_k)
    np.testing.assert_array_equal(nv, wnv)
    assert np.abs(cost.astype(int) - want).max() <= 1
    assert (cost[wnv < 2] == COST_MAX).all()


def test_gradient_cost_is_gain_offset_invariant(rng):
    base = rng.random((16, 18)).astype(np.float32)
    s = np.stack([base, 3.0 * base + 2.0, 0.5 * base - 1.0])
    cost, nv = multi_image_cost(s, 2, measure="gradient")
    assert (nv == 3).all() and cost.max() <= 1
    other = np.stack([base, rng.random((16, 18)).astype(np.float32)])
    assert np.median(multi_image_cost(other, 2, measure="gradient")[0]) > 0.6 * COST_MAX


@pytest.mark.parametrize("radius", [1, 2, 4])
def test_census_cost_matches_reference(rng, radius):
    s = _images(rng, 3, (10, 13))
    cost, nv = multi_image_cost(s, radius, measure="census")
    want, wnv = ref_multi_cost(s, radius, measure="census")
    np.testing.assert_array_equal(nv, wnv)
    np.testing.assert_array_equal(cost.astype(int), want)


def test_multi_image_cost_writes_into_a_volume_view(rng):
    s = _images(rng, 3, (9, 10))
    vol = np.zeros((9, 10, 4), np.uint16)
    nv = np.zeros((9, 10), np.uint8)
    c, n = multi_image_cost(s, 1, out=(vol[:, :, 2], nv))
    assert np.shares_memory(c, vol)
    np.testing.assert_array_equal(vol[:, :, 2], multi_image_cost(s, 1)[0])


def test_cost_inputs_are_checked(rng):
    s = _images(rng, 2, (6, 6))
    with pytest.raises(InputError, match="slices"):
        multi_image_cost(s[0], 1)
    with pytest.raises(InputError, match="measure"):
        multi_image_cost(s, 1, measure="sad")
    with pytest.raises(InputError, match="radius"):
        window_ncc(s[0], s[1], -1)
    with pytest.raises(InputError, match="best_k"):
        multi_image_cost(s, 1, best_k=0)
    with pytest.raises(InputError, match="min_valid"):
        window_ncc(s[0], s[1], 1, min_valid=0)


# ------------------------------------------------------------------------------------------
# aggregation
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("paths", [8, 16])
@pytest.mark.parametrize("offsets,per_cell_p2", [(False, False), (True, False), (True, True)])
def test_aggregate_matches_reference(rng, paths, offsets, per_cell_p2):
    rows, cols, nd = 9, 12, 6
    cost = rng.integers(0, COST_MAX + 1, (rows, cols, nd)).astype(np.uint16)
    z0 = rng.integers(-3, 4, (rows, cols)).astype(np.int32) if offsets else None
    p1 = 70
    p2 = rng.integers(p1, 900, (rows, cols)).astype(np.int32) if per_cell_p2 else 300
    S = aggregate(cost, p1, p2, paths=paths, z0=z0)
    want = ref_aggregate(cost, p1, p2, paths, z0)
    assert S.dtype == np.uint16
    np.testing.assert_array_equal(S.astype(np.int64), want)


@pytest.mark.parametrize("paths", [8, 16])
def test_aggregate_guided_p2_matches_reference(rng, paths):
    rows, cols, nd = 8, 11, 5
    cost = rng.integers(0, COST_MAX + 1, (rows, cols, nd)).astype(np.uint16)
    guide = rng.random((rows, cols)).astype(np.float32)
    z0 = rng.integers(-2, 3, (rows, cols)).astype(np.int32)
    S = aggregate(cost, 50, 700, paths=paths, z0=z0, guide=guide, edge=0.3)
    np.testing.assert_array_equal(S.astype(np.int64), ref_aggregate(cost, 50, 700, paths, z0, guide, 0.3))
    # default edge: 4 x median step; a constant guide changes nothing
    flat = aggregate(cost, 50, 700, paths=paths, guide=np.ones((rows, cols), np.float32))
    np.testing.assert_array_equal(flat, aggregate(cost, 50, 700, paths=paths))


@pytest.mark.parametrize("paths", [8, 16])
def test_aggregate_trend_matches_reference(rng, paths):
    """The trend's slopes (rises of at most trend_max per step) are compensated; steps and
    TREND_NONE cells compare absolute levels."""
    from truortho.core.sgm import TREND_NONE

    rows, cols, nd = 9, 12, 6
    cost = rng.integers(0, COST_MAX + 1, (rows, cols, nd)).astype(np.uint16)
    z0 = rng.integers(-3, 4, (rows, cols)).astype(np.int32)
    trend = (np.arange(cols)[None, :] // 2 + rng.integers(0, 2, (rows, cols))).astype(np.int32)
    trend[:, 7:] += 9  # a step: compared on absolute levels
    trend[rng.random((rows, cols)) < 0.15] = TREND_NONE
    S = aggregate(cost, 60, 500, paths=paths, z0=z0, trend=trend, trend_max=2)
    np.testing.assert_array_equal(S.astype(np.int64), ref_aggregate(cost, 60, 500, paths, z0, trend=trend,
                                                                     trend_max=2))  # fmt: skip
    assert not np.array_equal(S, aggregate(cost, 60, 500, paths=paths, z0=z0))
    # trend_max 0 or a constant trend change nothing
    np.testing.assert_array_equal(aggregate(cost, 60, 500, paths=paths, z0=z0, trend=trend, trend_max=0),
                                  aggregate(cost, 60, 500, paths=paths, z0=z0))  # fmt: skip
    np.testing.assert_array_equal(
        aggregate(cost, 60, 500, paths=paths, z0=z0, trend=np.full((rows, cols), 4, np.int32), trend_max=2),
        aggregate(cost, 60, 500, paths=paths, z0=z0),
    )
    with pytest.raises(InputError, match="trend"):
        aggregate(cost, 60, 500, trend=trend[:, :-1], trend_max=2)
    with pytest.raises(InputError, match="trend_max"):
        aggregate(cost, 60, 500, trend=trend, trend_max=-1)


def test_trend_keeps_a_weakly_textured_slope():
    """A slope of 0.4 levels per cell whose costs are weak and noisy: plain SGM flattens it into
    long terraces (P1 at every climbed level is not paid back), with its trend it follows it."""
    rng = np.random.default_rng(11)
    rows, cols, nd = 40, 60, 40
    true = 4.0 + 0.4 * np.arange(cols)[None, :] + np.zeros((rows, 1))
    d = np.arange(nd)[None, None, :]
    cost = np.minimum(np.abs(d - true[..., None]) * 40.0, 400.0) + rng.normal(0, 120, (rows, cols, nd))
    cost = np.clip(cost + 1000, 0, COST_MAX).astype(np.uint16)
    trend = np.rint(true).astype(np.int32)
    err = {}
    for name, kw in (("plain", {}), ("trend", {"trend": trend, "trend_max": 2})):
        S = aggregate(cost, 256, 2048, **kw)
        err[name] = np.abs(S.argmin(axis=2) - true)
    share = {k: float((e <= 1).mean()) for k, e in err.items()}
    print(f"\nshare within 1 level: {share}")  # plain 0.705, trend 0.882
    assert share["trend"] > 0.85
    assert share["trend"] > share["plain"] + 0.1


def test_aggregate_worst_case_does_not_overflow():
    rng = np.random.default_rng(5)
    cost = np.where(rng.random((6, 7, 5)) < 0.5, COST_MAX, 0).astype(np.uint16)
    S = aggregate(cost, 0, P2_MAX, paths=16)
    np.testing.assert_array_equal(S.astype(np.int64), ref_aggregate(cost, 0, P2_MAX, 16))
    assert S.max() <= 16 * (COST_MAX + P2_MAX) < 2**16


def test_aggregate_far_offsets_reduce_to_jumps(rng):
    """Neighbours whose windows do not overlap at all: every step is a P2 jump."""
    cost = rng.integers(0, 500, (5, 6, 4)).astype(np.uint16)
    z0 = (np.arange(6)[None, :] * 100 + np.arange(5)[:, None] * 1000).astype(np.int32)
    S = aggregate(cost, 10, 200, z0=z0)
    np.testing.assert_array_equal(S.astype(np.int64), ref_aggregate(cost, 10, 200, 8, z0))


def test_aggregate_inputs_are_checked(rng):
    cost = rng.integers(0, 100, (4, 5, 3)).astype(np.uint16)
    with pytest.raises(InputError, match="cost"):
        aggregate(cost.astype(np.int32))
    with pytest.raises(InputError, match="paths"):
        aggregate(cost, paths=4)
    with pytest.raises(InputError, match="p2"):
        aggregate(cost, 100, 50)
    with pytest.raises(InputError, match="p2"):
        aggregate(cost, 10, P2_MAX + 1)
    with pytest.raises(InputError, match="z0"):
        aggregate(cost, z0=np.zeros((4, 4), np.int32))
    with pytest.raises(InputError, match="COST_MAX"):
        aggregate(np.full((2, 2, 2), COST_MAX + 1, np.uint16))


def test_adaptive_p2_lowers_penalty_on_edges():
    img = np.zeros((10, 10), np.float32)
    img[:, 5:] = 1.0
    img += np.random.default_rng(1).random(img.shape).astype(np.float32) * 0.01
    p2 = adaptive_p2(img, 100, 800)
    assert p2.dtype == np.int32 and p2.min() >= 101 and p2.max() <= 800
    assert p2[:, 4:6].max() < 200 and p2[:, :3].min() > 500
    assert adaptive_p2(img * 50 + 3, 100, 800).tolist() == p2.tolist()  # gain invariant default edge
    with pytest.raises(InputError, match="p2"):
        adaptive_p2(img, 100, 100)


# ------------------------------------------------------------------------------------------
# selection and median
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("uniq,reject_edges", [(1.0, False), (0.9, False), (0.97, True)])
def test_select_matches_reference(rng, uniq, reject_edges):
    rows, cols, nd = 8, 9, 7
    S = rng.integers(0, 3000, (rows, cols, nd)).astype(np.uint16)
    S[0, 0] = 100  # flat column: m == m2
    z0 = rng.integers(-5, 5, (rows, cols)).astype(np.int32)
    valid = rng.random((rows, cols)) > 0.1
    lev, conf = select(S, z0, uniq, valid=valid, reject_edges=reject_edges)
    wl, wc = ref_select(S, z0, uniq, valid, reject_edges)
    np.testing.assert_array_equal(np.isnan(lev), np.isnan(wl))
    np.testing.assert_allclose(lev[np.isfinite(wl)], wl[np.isfinite(wl)], atol=1e-5)
    np.testing.assert_allclose(conf[np.isfinite(wc)], wc[np.isfinite(wc)], atol=1e-6)
    ok = np.isfinite(conf)
    assert (conf[ok] >= 0).all() and (conf[ok] <= 1).all()


def test_select_sub_level_is_not_locked_to_the_levels():
    """Aggregated costs rise by about P1 per level on both sides of the minimum (V-shaped): the
    equiangular fit recovers any sub-level position. A parabola through the same three costs pulls
    the result towards the nearest level (pixel locking; terraces on a gentle slope): it misses
    3.3 by 0.09 and 3.15 by 0.06, and concentrates fractions near 0."""
    d = np.arange(9, dtype=np.float64)
    truths = np.linspace(2.55, 5.45, 59)
    S = np.rint(1000 + 400 * np.abs(d[None, :] - truths[:, None])).astype(np.uint16)[None]
    lev, conf = select(S, np.full((1, len(truths)), 10, np.int32), 1.0)
    np.testing.assert_allclose(lev[0], 10 + truths, atol=0.01)
    assert ((conf[0] > 0) & (conf[0] < 1)).all()
    # a smooth (quadratic) minimum still lands within a tenth of a level
    q = np.rint(1000 + 50 * (d - 3.3) ** 2).astype(np.uint16)[None, None, :]
    lq, _ = select(q, np.full((1, 1), 10, np.int32), 1.0)
    assert lq[0, 0] == pytest.approx(13.3, abs=0.1)


def test_valid_cells():
    c = np.full((2, 2, 3), COST_MAX, np.uint16)
    c[1, 1, 2] = 5
    assert valid_cells(c).tolist() == [[False, False], [False, True]]


@pytest.mark.parametrize("size,min_count", [(3, 1), (5, 1), (3, 4), (1, 1)])
def test_median_filter_matches_reference(rng, size, min_count):
    x = rng.random((9, 11)).astype(np.float32)
    x[rng.random(x.shape) < 0.3] = np.nan
    got = median_filter(x, size, min_count=min_count)
    want = ref_median(x, size, min_count)
    np.testing.assert_array_equal(np.isnan(got), np.isnan(want))
    np.testing.assert_allclose(got[np.isfinite(want)], want[np.isfinite(want)], rtol=1e-6)
    with pytest.raises(InputError, match="size"):
        median_filter(x, 2)


# ------------------------------------------------------------------------------------------
# kernels without the JIT (coverage honest): .py_func on tiny inputs
# ------------------------------------------------------------------------------------------


def test_kernels_pure_python_on_tiny_inputs(rng):
    s = _images(rng, 3, (6, 7))
    z, vf = cost_mod._prepare(s)
    c = np.empty((6, 7), np.uint16)
    nv = np.empty((6, 7), np.uint8)
    cost_mod._mic_ncc_kernel.py_func(z, vf, 1, 0.5, 0, 4, c, nv)
    want, wnv = ref_multi_cost(s, 1, measure="ncc")
    np.testing.assert_array_equal(nv, wnv)
    assert np.abs(c.astype(int) - want).max() <= 1
    qx = np.empty(s.shape, np.int16)
    qy = np.empty(s.shape, np.int16)
    vv = np.empty(s.shape, np.uint8)
    cost_mod._prep_gradients.py_func(s, qx, qy, vv, cost_mod._NO_SCALES)
    cost_mod._mic_grad_kernel.py_func(qx, qy, vv, 1, 0.5, 0, 4, c, nv)
    assert np.abs(c.astype(int) - ref_gradient_cost(s, 1)[0]).max() <= 1
    tx = np.empty((6, 7), np.float32)
    ty = np.empty((6, 7), np.float32)
    cost_mod._gradients.py_func(s[0], tx, ty)
    q0 = np.empty((6, 7), np.int16)
    v0 = np.empty((6, 7), np.uint8)
    cost_mod._saturate.py_func(tx, q0, v0)
    want = ref_saturated_gradients(s[0])[0]
    np.testing.assert_array_equal(v0 == 1, np.isfinite(want))
    np.testing.assert_allclose(q0[v0 == 1] / cost_mod._GQ, want[np.isfinite(want)], atol=1e-6)
    cost_mod._mic_census_kernel.py_func(s, 1, 0.5, 0, c, nv)
    np.testing.assert_array_equal(c.astype(int), ref_multi_cost(s, 1, measure="census")[0])
    out = np.empty((6, 7), np.float32)
    cost_mod._window_ncc_kernel.py_func(z[0], z[1], vf[0], vf[1], 1, 0.5, 4, out)
    w = ref_window_ncc(s[0], s[1], 1)
    np.testing.assert_allclose(out[np.isfinite(w)], w[np.isfinite(w)], atol=2e-5)

    cost = rng.integers(0, COST_MAX + 1, (5, 6, 4)).astype(np.uint16)
    z0 = rng.integers(-2, 3, (5, 6)).astype(np.int32)
    p2 = np.full((5, 6), 300, np.int32)
    guide = rng.random((5, 6)).astype(np.float32)
    trend = (np.arange(6)[None, :] + rng.integers(0, 2, (5, 6))).astype(np.int32)
    trend[:, 4:] += 5  # a step
    S = np.zeros(cost.shape, np.uint16)
    agg_mod._aggregate_kernel.py_func(cost, z0, p2, guide, 0.2, 60, S, agg_mod._DOWN16, trend, 2)
    want = ref_aggregate(cost, 60, 300, 16, z0, guide, 0.2, trend, 2)
    np.testing.assert_array_equal(S.astype(np.int64), want)
    S2 = np.zeros(cost.shape, np.uint16)  # the sweeps themselves without the JIT, in two row ranges
    for down in (True, False):
        lf = np.full((3 * 3 * 6 + 2) * 8, agg_mod._SENT, np.uint16)
        mb = np.zeros((3, 3, 6), np.int64)
        for i0, i1 in ((0, 2), (2, 5)):
            args = (cost, z0, p2, guide, 0.2, 60, S2, agg_mod._DOWN8, down, i0, i1, lf, mb, False, trend, 2)
            agg_mod._sweep.py_func(*args)
    want = ref_aggregate(cost, 60, 300, 8, z0, guide, 0.2, trend, 2)
    np.testing.assert_array_equal(S2.astype(np.int64), want)
    assert agg_mod._rise.py_func(7, 5, 2) == 2 and agg_mod._rise.py_func(9, 5, 2) == 0
    assert agg_mod._p2_step.py_func(p2, guide, 0.2, 60, 1, 1, 0, 0) >= 61
    U = np.uint64
    cf = cost.reshape(-1)
    L = np.full(16, agg_mod._SENT, np.uint16)
    sf = np.zeros(cf.size, np.uint16)
    m0 = agg_mod._first.py_func(cf, U(0), L, U(0), sf, 4, False)
    m = agg_mod._step.py_func(cf, U(4), L, U(0), m0, U(8), 1, 60, 300, sf, 4, True)
    assert m == L[10:14].min() and m0 == cost[0, 0].min()
    assert (L[2:6] == cost[0, 0]).all() and (sf[:4] == cost[0, 0]).all()
    assert (sf[4:8] == L[10:14]).all()
    # the fused four-path step equals four single steps
    L4 = np.full(8 * 8, agg_mod._SENT, np.uint16)
    for q in range(4):
        L4[q * 8 + 2 : q * 8 + 6] = cost[1, q]
    sa = np.zeros(cf.size, np.uint16)
    sb = np.zeros(cf.size, np.uint16)
    mq = [int(cost[1, q].min()) for q in range(4)]
    qb = [U(q * 8) for q in range(4)]
    ob = [U(32 + q * 8) for q in range(4)]
    m4 = agg_mod._step4.py_func(cf, U(8), L4, *qb, *mq, *ob, 60, 300, 310, 320, 330, sa, 4, False)
    Lb = L4.copy()
    m1 = [
        agg_mod._step(cf, U(8), Lb, qb[q], mq[q], ob[q], 0, 60, 300 + 10 * q, sb, 4, False) for q in range(4)
    ]
    assert list(m4) == m1 and (sa == sb).all() and (L4 == Lb).all()

    lev = np.empty((5, 6), np.float32)
    conf = np.empty((5, 6), np.float32)
    valid = np.ones((5, 6), bool)
    sel_mod._select_kernel.py_func(S, z0, valid, 0.95, False, lev, conf)
    wl, wc = ref_select(S, z0, 0.95)
    np.testing.assert_allclose(lev[np.isfinite(wl)], wl[np.isfinite(wl)], atol=1e-5)
    np.testing.assert_array_equal(np.isnan(lev), np.isnan(wl))
    x = rng.random((5, 6)).astype(np.float32)
    x[1, 2] = np.nan
    mo = np.empty_like(x)
    sel_mod._median_kernel.py_func(x, 1, 1, mo)
    np.testing.assert_allclose(mo, ref_median(x, 3), rtol=1e-6)


@pytest.fixture
def rng():
    return np.random.default_rng(20240)


def test_rectified_costs_equal_per_slice_calls(rng):
    """The rectified gradient path prepares each image once; per-slice calls agree but at the edges."""
    from truortho.core.sgm import disparity_costs

    base = rng.random((30, 60)).astype(np.float32)
    left, right = base[:, 10:50], 1.3 * base[:, 13:53] + 0.2  # disparity 3, other gain/offset
    fast = disparity_costs(left, right, -2, 8)
    slow = np.empty_like(fast)
    xs = np.arange(40)
    for k in range(8):
        pair = np.stack([left, right[:, np.clip(xs - (k - 2), 0, 39)]])
        slow[:, :, k] = multi_image_cost(pair, 2)[0]
    inner = np.s_[:, 12:-3]  # away from the replicated and the slice edges
    assert np.abs(fast[inner].astype(int) - slow[inner]).max() <= 0.1 * COST_MAX  # only the scale differs
    assert (np.argmin(fast[inner], axis=2) == np.argmin(slow[inner], axis=2)).mean() > 0.97
    assert (np.argmin(fast[inner], axis=2) == 5).mean() > 0.9  # d = 3 is level 5


def test_match_rectified_options_on_a_random_dot_pair(rng):
    from truortho.core.sgm import match_rectified

    tex = rng.random((40, 90))
    left = (255 * tex[:, 10:80]).astype(np.uint8)
    right = (200 * tex[:, 16:86] + 20).astype(np.uint8)  # disparity 6, other gain and offset
    colour = np.repeat(left[:, :, None], 3, axis=2)
    d = match_rectified(colour, right, 0, 12)
    inner = np.s_[3:-3, 12:-3]
    assert d.dtype == np.float32 and d.shape == left.shape
    assert (np.abs(d[inner] - 6) < 0.5).mean() > 0.97
    d_lr = match_rectified(left, right, 0, 12, lr_check=1.0)
    assert (np.abs(d_lr[inner] - 6) < 0.5).mean() > 0.95
    assert np.isnan(d_lr).sum() >= np.isnan(d).sum()
    d_nan = match_rectified(left, right, 4, 8, border="nan", median=1)
    assert np.isnan(d_nan[:, :2]).all()  # with d >= 4 these columns' windows lie outside the right image
    assert (np.abs(d_nan[inner] - 6) < 0.5).mean() > 0.97
    d16 = match_rectified(left.astype(np.uint16) * 257, right, 0, 12, measure="ncc", paths=16, adaptive=False)
    assert (np.abs(d16[inner] - 6) < 0.5).mean() > 0.95
    with pytest.raises(InputError, match="right"):
        match_rectified(left, right[:, :-1], 0, 12)
    with pytest.raises(InputError, match="num_disp"):
        match_rectified(left, right, 0, 0)
    with pytest.raises(InputError, match="median"):
        match_rectified(left, right, 0, 12, median=2)
    with pytest.raises(InputError, match="border"):
        match_rectified(left, right, 0, 12, border="wrap")
