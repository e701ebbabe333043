"""Selection energy, ICM and feathering (core/ortho/select.py, seams.py) against references."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.errors import InputError
from truortho.core.ortho.seams import feather_weights
from truortho.core.ortho.select import (
    DISAGREE_PENALTY,
    add_disagreement,
    edge_weights,
    initial_labels,
    select_labels,
)


def _energy(labels, cost, lum, h, h0, smooth, contrast):
    """Obvious-but-slow energy of a labelling (same definition as the module docstring)."""
    wh, wv = edge_weights(h, h0)
    rows, cols = labels.shape
    e = 0.0
    for r in range(rows):
        for c in range(cols):
            a = labels[r, c]
            if a < 0:
                continue
            e += cost[a, r, c]
            for dr, dc, w in (
                (0, 1, wh[r, c] if c < cols - 1 else 0),
                (1, 0, wv[r, c] if r < rows - 1 else 0),
            ):
                rr, cc = r + dr, c + dc
                if rr >= rows or cc >= cols or labels[rr, cc] < 0 or labels[rr, cc] == a:
                    continue
                b = labels[rr, cc]
                d = 0.0
                for p in ((r, c), (rr, cc)):
                    la, lb = lum[a][p], lum[b][p]
                    d += abs(la - lb) if np.isfinite(la) and np.isfinite(lb) else 1.0
                e += smooth * w * (1 + contrast * d)
    return e


def test_icm_lowers_the_energy_and_keeps_fixed_labels():
    rng = np.random.default_rng(5)
    K, R, C = 4, 24, 30
    cost = rng.uniform(0, 1, (K, R, C)).astype(np.float32)
    cost[rng.uniform(size=cost.shape) < 0.25] = np.inf
    cost[0, :, :] = np.where(np.isfinite(cost[0]), cost[0], 0.5)  # every cell seen by image 0
    lum = rng.uniform(0, 1, (K, R, C)).astype(np.float32)
    lum[~np.isfinite(cost)] = np.nan
    h = np.zeros((R, C))
    h[5:15, 8:20] = 6.0  # a building
    res = 0.25
    h0 = max(0.5, 2 * res)
    start = initial_labels(cost, h, h0, 10_000)
    fixed = np.full((R, C), -1, np.int32)
    fixed[:, 0] = 0
    out = select_labels(cost, h, lum, res, smoothness=1.0, contrast=4.0, fixed=fixed)
    assert np.all(out[:, 0] == 0)
    assert np.all(np.isfinite(np.take_along_axis(cost, out[None].astype(np.int64), 0)[0]))
    e0 = _energy(start, cost, lum, h, h0, 1.0, 4.0)
    e1 = _energy(out, cost, lum, h, h0, 1.0, 4.0)
    assert e1 < e0


def test_roof_segment_gets_one_image():
    K, R, C = 3, 40, 40
    cost = np.random.default_rng(1).uniform(0, 0.3, (K, R, C)).astype(np.float32)
    h = np.zeros((R, C))
    h[10:30, 12:28] = 8.0
    lab = select_labels(cost, h, None, 0.25)
    roof = lab[10:30, 12:28]
    assert len(np.unique(roof)) == 1


def test_feather_weights_sum_to_one_and_respect_visibility():
    R, C = 20, 30
    labels = np.zeros((R, C), np.int64)
    labels[:, 15:] = 1
    clean = np.ones((2, R, C), bool)
    clean[1, :, :10] = False  # image 1 does not see the west part
    w = feather_weights(labels, clean, 5)
    assert np.allclose(w.sum(axis=0), 1.0)
    assert np.all(w[1][:, :10] == 0)
    ramp = w[1][10]
    assert ramp[12] == 0 and 0 < ramp[14] < ramp[15] < ramp[16] < 1 and ramp[18] == 1
    assert np.all(feather_weights(labels, clean, 0)[1] == (labels == 1))


def test_segments_are_the_step_connected_components():
    from collections import deque

    from truortho.core.ortho.select import segments

    rng = np.random.default_rng(0)
    for _ in range(20):
        rows, cols = (int(v) for v in rng.integers(1, 40, 2))
        h = np.round(rng.uniform(0, 3, (rows, cols)), 0)
        h[rng.uniform(size=h.shape) < 0.1] = np.nan
        got = segments(h, 0.5)
        # reference: breadth-first search, components numbered by their first cell
        ref = np.full(h.shape, -1)
        n = 0
        for r0 in range(rows):
            for c0 in range(cols):
                if np.isnan(h[r0, c0]) or ref[r0, c0] >= 0:
                    continue
                ref[r0, c0] = n
                todo = deque([(r0, c0)])
                while todo:
                    r, c = todo.popleft()
                    for rr, cc in ((r, c + 1), (r, c - 1), (r + 1, c), (r - 1, c)):
                        if 0 <= rr < rows and 0 <= cc < cols and ref[rr, cc] < 0 and not np.isnan(h[rr, cc]):
                            if abs(h[rr, cc] - h[r, c]) <= 0.5:
                                ref[rr, cc] = n
                                todo.append((rr, cc))
                n += 1
        np.testing.assert_array_equal(got, ref)


def _disagreement_reference(colours, usable, tau):
    """Obvious-but-slow penalty of every (candidate, cell): module docstring, *Agreement of the views*."""
    K, R, C, B = colours.shape
    out = np.zeros((K, R, C))
    for r in range(R):
        for c in range(C):
            ks = [k for k in range(K) if usable[k, r, c] and np.isfinite(colours[k, r, c, 0])]
            if len(ks) < 3:
                continue
            med = np.median(colours[ks, r, c].astype(np.float64), axis=0)
            far = [k for k in ks if np.any(np.abs(colours[k, r, c] - med) > tau)]
            if len(ks) - len(far) >= 2:
                out[far, r, c] = DISAGREE_PENALTY
    return out


def test_disagreeing_views_pay_where_others_agree():
    rng = np.random.default_rng(11)
    K, R, C, B = 6, 40, 50, 3
    truth = rng.uniform(0, 255, (R, C, B))
    colours = (truth[None] + rng.normal(0, 4, (K, R, C, B))).astype(np.float32)
    # a few views see something else (an outlier), some cells have views scattered everywhere
    odd = rng.random((K, R, C)) < 0.2
    colours[odd] = rng.uniform(0, 255, (int(odd.sum()), B))
    scatter = rng.random((R, C)) < 0.1
    colours[:, scatter] = rng.uniform(0, 255, (K, int(scatter.sum()), B))
    usable = rng.random((K, R, C)) < 0.8
    colours[~usable & (rng.random((K, R, C)) < 0.5)] = np.nan  # not sampled where not usable
    cost = rng.uniform(0, 1, (K, R, C)).astype(np.float32)
    before = cost.copy()
    far = add_disagreement(cost, colours, usable, 25.0)
    ref = _disagreement_reference(colours, usable, 25.0)
    np.testing.assert_allclose(cost - before, ref, atol=1e-6)
    assert np.array_equal(far, ref > 0)
    # the rule does what it is for: the odd views pay, the views that agree do not
    paid = (cost - before) > 0
    majority = ((usable & ~odd).sum(0) > (usable & odd).sum(0)) & ((usable & ~odd).sum(0) >= 2) & ~scatter
    assert paid[odd & usable & majority[None]].mean() > 0.95
    assert paid[~odd & usable & ~scatter[None]].mean() < 0.01
    # one or two views say nothing; the unusable never pay
    assert not paid[:, usable.sum(0) < 3].any() and not paid[~usable].any()


def test_disagreement_checks_its_input():
    cost = np.zeros((3, 2, 2), np.float32)
    colours = np.zeros((3, 2, 2, 3), np.float32)
    usable = np.ones((3, 2, 2), bool)
    with pytest.raises(InputError, match="tau"):
        add_disagreement(cost, colours, usable, 0.0)
    with pytest.raises(InputError, match="shapes"):
        add_disagreement(cost, colours[:2], usable, 10.0)
    # two candidates: nothing to compare
    assert not add_disagreement(cost[:2], colours[:2], usable[:2], 10.0).any()
