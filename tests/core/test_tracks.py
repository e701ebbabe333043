"""Tracks from pairwise matches (union-find, consistency) and tie-point decimation."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.errors import InputError
from truortho.core.sfm.tracks import build_tracks, decimate_tracks


def _as_sets(t):
    return sorted(
        tuple(sorted(zip(t.image[t.track == k].tolist(), t.feature[t.track == k].tolist(), strict=True)))
        for k in range(t.n_tracks)
    )


def test_union_find_chains_pairs_into_tracks():
    # image 0 f0 - image 1 f3 - image 2 f1 (chain), and 0/f2 - 2/f4 (pair)
    pm = [(0, 1, [[0, 3]]), (1, 2, [[3, 1]]), (0, 2, [[2, 4]])]
    t = build_tracks([5, 5, 5], pm)
    assert t.n_tracks == 2
    assert _as_sets(t) == [((0, 0), (1, 3), (2, 1)), ((0, 2), (2, 4))]
    assert t.histogram().tolist() == [0, 0, 1, 1]
    assert t.stats["inconsistent"] == 0
    # sorted by track then image
    assert np.all(np.diff(t.track) >= 0)


def test_inconsistent_track_is_dropped():
    # 0/f0 - 1/f0 - 2/f0 - 0/f1: two features of image 0 in one component
    pm = [(0, 1, [[0, 0], [5, 5]]), (1, 2, [[0, 0]]), (0, 2, [[1, 0]])]
    t = build_tracks([6, 6, 6], pm, keypoints=[np.arange(12.0).reshape(6, 2)] * 3)
    assert t.stats["inconsistent"] == 1
    assert _as_sets(t) == [((0, 5), (1, 5))]
    assert np.allclose(t.xy, [[10, 11], [10, 11]])


def test_bad_input_names_the_pair():
    with pytest.raises(InputError, match=r"\(0, 1\)"):
        build_tracks([2, 2], [(0, 1, [[0, 2]])])
    with pytest.raises(InputError, match="pair"):
        build_tracks([2, 2], [(0, 0, [[0, 1]])])
    assert build_tracks([3, 3], []).n_tracks == 0


def test_decimation_keeps_high_multiplicity_tracks_in_all_images():
    # 3 images 100x100, cell 50 px. Track A: images 0,1,2 ; track B: images 0,1 in the same
    # cell of image 0 as A; track C: images 1,2 alone in its cell of image 2.
    kp = [
        np.array([[10.0, 10.0], [12.0, 12.0], [80.0, 80.0]]),  # image 0: f0 (A), f1 (B), f2 (D)
        np.array([[10.0, 10.0], [20.0, 20.0], [70.0, 20.0], [30.0, 30.0]]),  # image 1: A, B, C, D
        np.array([[10.0, 10.0], [80.0, 80.0]]),  # image 2: f0 (A), f1 (C)
    ]
    pm = [
        (0, 1, [[0, 0], [1, 1], [2, 3]]),
        (1, 2, [[0, 0], [2, 1]]),
    ]
    t = build_tracks([3, 4, 2], pm, kp)
    assert t.n_tracks == 4
    d = decimate_tracks(t, [(100, 100)] * 3, 50.0)
    kept = _as_sets(d)
    A = ((0, 0), (1, 0), (2, 0))
    B = ((0, 1), (1, 1))
    C = ((1, 2), (2, 1))
    D = ((0, 2), (1, 3))
    # B loses to A everywhere (same cells, lower multiplicity); C and D win cells of their own
    assert A in kept and C in kept and D in kept and B not in kept
    # a kept track keeps all its observations (D shares image 1's top-left cell with A)
    assert d.n_tracks == 3 and len(d.track) == 7
    assert d.stats["decimation"]["tracks_before"] == 4


def test_decimation_tie_break_on_feature_scale():
    kp = [np.array([[5.0, 5.0], [6.0, 6.0]]), np.array([[5.0, 5.0], [60.0, 60.0]])]
    pm = [(0, 1, [[0, 0], [1, 1]])]
    t = build_tracks([2, 2], pm, kp)
    # image 0: both tracks in one cell, same multiplicity; feature 1 is finer
    d = decimate_tracks(t, [(100, 100)] * 2, 50.0, feature_scale=[np.array([8.0, 2.0]), np.array([1.0, 1.0])])
    # track of feature 0/1 wins image 0's cell; track 0/0 still wins image 1's top-left cell
    assert d.n_tracks == 2
    d = decimate_tracks(
        t, [(100, 100)] * 2, 200.0, feature_scale=[np.array([8.0, 2.0]), np.array([3.0, 1.0])]
    )
    assert _as_sets(d) == [((0, 1), (1, 1))]


def test_decimation_random_block_properties():
    rng = np.random.default_rng(3)
    n_img, n_pts = 6, 3000
    X = rng.uniform(0, 1000, (n_pts, 2))
    feats, kp = [], []
    for _ in range(n_img):
        vis = np.flatnonzero(rng.random(n_pts) < 0.6)
        feats.append(vis)
        kp.append(X[vis] + rng.normal(0, 0.3, (len(vis), 2)))
    pm = []
    for i in range(n_img):
        for j in range(i + 1, n_img):
            common, ai, bj = np.intersect1d(feats[i], feats[j], return_indices=True)
            pm.append((i, j, np.column_stack([ai, bj])))
    t = build_tracks([len(f) for f in feats], pm, kp)
    d = decimate_tracks(t, [(1000, 1000)] * n_img, 100.0)
    assert 0 < d.n_tracks < t.n_tracks
    # every kept track with all its images
    assert np.array_equal(np.bincount(d.track), d.multiplicity)
    full = dict(zip(map(tuple, _as_sets(t)), range(t.n_tracks), strict=False))
    assert all(tuple(s) in full for s in _as_sets(d))
    # the kept tracks are more multiple than average
    assert d.multiplicity.mean() > t.multiplicity.mean()

    # every cell of every image that had an observation still has one
    def cells(tt, i):
        c = np.minimum(np.floor((tt.xy[tt.image == i] + 0.5) / 100.0), 9).astype(int)
        return set(map(tuple, c.tolist()))

    for i in range(n_img):
        assert cells(d, i) == cells(t, i)


def test_decimation_keeps_the_links_of_a_weakly_connected_image():
    # images 0-2: a block with dense three-image tracks; images 3-5: a group with its own dense
    # three-image tracks. The group's only link to the block, image 3 - image 2, is two-view
    # tracks that lie in cells where the longer tracks win, in image 2 and in image 3.
    rng = np.random.default_rng(4)
    n_long, n_weak = 600, 40
    pos_a = rng.uniform(0, 400, (n_long, 2))
    pos_b = rng.uniform(0, 400, (n_long, 2))
    pos_weak = rng.uniform(0, 400, (n_weak, 2))
    kp = [pos_a, pos_a, np.vstack([pos_a, pos_weak + 0.5]), np.vstack([pos_b, pos_weak]), pos_b, pos_b]
    idx = np.arange(n_long)
    same = np.column_stack([idx, idx])
    weak = np.column_stack([n_long + np.arange(n_weak), n_long + np.arange(n_weak)])
    pm = [(0, 1, same), (1, 2, same), (3, 4, same), (4, 5, same), (2, 3, weak)]
    nf = [n_long, n_long, n_long + n_weak, n_long + n_weak, n_long, n_long]
    t = build_tracks(nf, pm, kp)

    def links(d, i=2, j=3):
        return len(np.intersect1d(d.track[d.image == i], d.track[d.image == j]))

    sizes = [(400, 400)] * 6
    plain = decimate_tracks(t, sizes, 20.0)
    assert links(plain) < n_weak // 2  # the weak pair lost most of its links
    kept = decimate_tracks(t, sizes, 20.0, min_pair_tracks=30)
    assert links(kept) == 30  # protection restores it up to min_pair_tracks
    everything = decimate_tracks(t, sizes, 20.0, min_pair_tracks=100)
    assert links(everything) == n_weak
    assert everything.stats["decimation"]["pairs_restored"] >= 1
    # the block's own pairs had more than the minimum: untouched
    assert links(kept, 0, 1) == links(plain, 0, 1) and links(kept, 3, 4) == links(plain, 3, 4)
    with pytest.raises(InputError, match="min_pair_tracks"):
        decimate_tracks(t, sizes, 20.0, min_pair_tracks=-1)
