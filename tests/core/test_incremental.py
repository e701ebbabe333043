"""Incremental reconstruction on synthetic tracks with known geometry."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.errors import CancelledError, InputError
from truortho.core.geometry import Camera, opk_to_matrix, project_points
from truortho.core.progress import CallbackProgress
from truortho.core.sfm.incremental import IncrementalConfig, reconstruct
from truortho.core.sfm.similarity import estimate_similarity


def synthetic_tracks(seed=0, n_points=1500, noise=0.5, strips=3, per_strip=6):
    rng = np.random.default_rng(seed)
    cam = Camera(1200, 800, 1000.0, 1000.0, 601.3, 398.2, -0.06, 0.015, 0.0, 3e-4, -2e-4)
    Rs, Cs = [], []
    for s in range(strips):
        for k in range(per_strip):
            kappa = 0.0 if s % 2 == 0 else 180.0
            Rs.append(opk_to_matrix(*rng.normal(0, 2, 2), kappa + rng.normal(0, 2), degrees=True))
            Cs.append([k * 25.0 + rng.normal(0, 1), s * 45.0 + rng.normal(0, 1), 120.0 + rng.normal(0, 2)])
    Rs, Cs = np.array(Rs), np.array(Cs)
    X = np.column_stack(
        [rng.uniform(-40, 165, n_points), rng.uniform(-35, 125, n_points), rng.uniform(0, 15, n_points)]
    )
    tr, im, xy = [], [], []
    for i in range(len(Rs)):
        uv = project_points(X, Rs[i], Cs[i], cam)
        inside = (uv[:, 0] > 0) & (uv[:, 0] < cam.width - 1) & (uv[:, 1] > 0) & (uv[:, 1] < cam.height - 1)
        idx = np.flatnonzero(inside)
        tr.append(idx)
        im.append(np.full(len(idx), i))
        xy.append(uv[idx] + rng.normal(0, noise, (len(idx), 2)))
    tr, im, xy = np.concatenate(tr), np.concatenate(im), np.concatenate(xy)
    return cam, Rs, Cs, X, tr, im, xy


def test_reconstructs_block_with_self_calibration():
    cam, Rs, Cs, X, tr, im, xy = synthetic_tracks()
    # prior: focal 8 % off, no distortion known
    prior = Camera(cam.width, cam.height, 1080.0, 1080.0, 599.5, 399.5)
    rec = reconstruct(tr, im, xy, np.zeros(len(Rs), int), [prior])
    assert rec.registered.all(), rec.stats
    sim = estimate_similarity(rec.centers, Cs)
    err = np.linalg.norm(sim.apply(rec.centers) - Cs, axis=1)
    assert np.sqrt(np.mean(err**2)) < 0.1, err  # metres, at 120 m height with 0.5 px noise
    assert abs(rec.intrinsics[0, 0] - cam.fx) < 5.0
    assert abs(rec.intrinsics[0, 4] - cam.k1) < 0.01
    assert rec.stats["final_bundle"]["rms_px"] < 0.8
    assert rec.point_ok.sum() > 0.9 * len(X)


def test_cancel_and_bad_input():
    cam, Rs, Cs, X, tr, im, xy = synthetic_tracks(n_points=300, strips=1, per_strip=4)
    with pytest.raises(CancelledError):
        reconstruct(tr, im, xy, np.zeros(4, int), [cam], progress=CallbackProgress(is_cancelled=lambda: True))
    with pytest.raises(InputError, match="two images"):
        reconstruct(tr, im, xy, np.zeros(1, int), [cam])
    with pytest.raises(InputError, match="refine_intrinsics"):
        reconstruct(tr, im, xy, np.zeros(4, int), [cam], IncrementalConfig(refine_intrinsics=("zoom",)))


def test_images_without_overlap_stay_unregistered():
    cam, Rs, Cs, X, tr, im, xy = synthetic_tracks(n_points=600, strips=1, per_strip=5)
    # an extra image whose observations are of tracks nobody else sees
    extra_tracks = tr.max() + 1 + np.arange(50)
    rng = np.random.default_rng(1)
    tr = np.concatenate([tr, extra_tracks])
    im = np.concatenate([im, np.full(50, 5)])
    xy = np.concatenate([xy, rng.uniform(0, 800, (50, 2))])
    rec = reconstruct(tr, im, xy, np.zeros(6, int), [cam])
    assert rec.registered[:5].all() and not rec.registered[5]


def _centre_rmse(rec, Cs, images):
    sim = estimate_similarity(rec.centers[images], Cs[images])
    return float(np.sqrt(np.mean(np.linalg.norm(sim.apply(rec.centers[images]) - Cs[images], axis=1) ** 2)))


def test_second_pass_resumes_the_first_reconstruction():
    """``finalize=False`` then ``start=``: the images a first pass could not link (here the third
    strip, whose observations it does not get) join the block registered so far, and the result
    is as accurate as one reconstruction from all observations; ``register=False`` only finalizes."""
    cam, Rs, Cs, X, tr, im, xy = synthetic_tracks(seed=2)
    prior = Camera(cam.width, cam.height, 1080.0, 1080.0, 599.5, 399.5)
    cams, n = [prior], len(Rs)
    first = im < 12
    rec1 = reconstruct(tr[first], im[first], xy[first], np.zeros(n, int), cams, finalize=False)
    assert rec1.registered[:12].all() and not rec1.registered[12:].any()
    assert rec1.stats["finalized"] is False and "final_bundle" not in rec1.stats
    rec2 = reconstruct(tr, im, xy, np.zeros(n, int), cams, start=rec1)
    assert rec2.registered.all() and rec2.stats["finalized"] is True
    assert [a.get("resumed") for a in rec2.stats["adjustments"]].count(True) == 1
    whole = reconstruct(tr, im, xy, np.zeros(n, int), cams)
    all_images = np.arange(n)
    assert _centre_rmse(rec2, Cs, all_images) < 0.1
    assert _centre_rmse(rec2, Cs, all_images) < 1.5 * _centre_rmse(whole, Cs, all_images) + 0.01
    assert abs(rec2.intrinsics[0, 0] - cam.fx) < 5.0
    # only finalize: the same observations, points and registrations kept, then adjusted
    done = reconstruct(
        rec1.obs_track, rec1.obs_image, rec1.obs_xy, np.zeros(n, int), cams, start=rec1, register=False
    )
    assert np.array_equal(done.registered, rec1.registered) and done.stats["finalized"] is True
    assert _centre_rmse(done, Cs, np.arange(12)) < 0.1
    with pytest.raises(InputError, match="another block"):
        reconstruct(tr, im, xy, np.zeros(n + 1, int), cams, start=rec1)


def test_second_pass_pairs_are_bounded_and_nearest_first():
    from truortho.core.sfm.pairs import PairSelection
    from truortho.core.sfm.pipeline import second_pass_pairs

    n = 300
    xy = np.column_stack([np.arange(n) * 10.0, np.zeros(n)])  # a strip, 10 m apart
    first = np.array([(i, j) for i in range(n) for j in range(i + 1, min(n, i + 3))])
    sel = PairSelection(first, "gps", n, {"local_xy": xy})
    extra = second_pass_pairs(sel, [150, 7], 20)
    assert len(extra) == 40 and len(set(extra)) == 40
    for m in (150, 7):
        partners = sorted({a + b - m for a, b in extra if m in (a, b)})
        tried = {a + b - m for a, b in first if m in (a, b)}
        assert not tried & set(partners)
        # the 20 nearest not yet paired (on the strip: distance rank, ties to the lower index)
        cand = sorted((j for j in range(n) if j != m and j not in tried), key=lambda j: (abs(j - m), j))
        assert partners == sorted(cand[:20])
    # similarity ranking without positions; 0 = every image
    sim = -np.abs(np.subtract.outer(np.arange(n), np.arange(n))).astype(float)
    sel2 = PairSelection(first, "retrieval", n, {"similarity": sim})
    p2 = second_pass_pairs(sel2, [150], 20)
    assert len(p2) == 20 and max(abs(a + b - 300) for a, b in p2) <= 12
    assert len(second_pass_pairs(sel2, [150], 0)) == n - 1 - 4
    with pytest.raises(InputError, match="second_pass_partners"):
        second_pass_pairs(sel, [1], -1)


def test_second_pass_retries_the_pairs_taken_as_not_overlapping():
    """A left-out image's first-pass pairs that the coarse pass skipped are matched again (whole);
    skipped pairs of registered images and matched pairs of the left-out image are not."""
    from types import SimpleNamespace

    from truortho.core.sfm.pipeline import skipped_pairs_of

    def r(i, j, skipped):
        return SimpleNamespace(i=i, j=j, skipped=skipped)

    results = [r(0, 1, False), r(0, 5, True), r(1, 2, True), r(3, 5, False), r(2, 5, True)]
    assert skipped_pairs_of(results, [5]) == {1, 4}
    assert skipped_pairs_of(results, np.array([2, 5])) == {1, 2, 4}
    assert skipped_pairs_of(results, []) == set()


def test_second_pass_plan_matches_new_partners_as_the_first_pass_and_skipped_pairs_whole():
    """The second pass: a left-out image's new partners (nearest first, not tried yet), its
    first-pass pairs that the coarse pass skipped (to be matched whole), and the first-pass results
    kept without those."""
    from types import SimpleNamespace

    from truortho.core.sfm.pipeline import second_pass_plan

    xy = np.array([[0.0, 0], [10, 0], [20, 0], [30, 0], [40, 0], [50, 0]])
    sel = SimpleNamespace(n_images=6, pairs=np.array([[0, 1], [1, 2], [3, 4], [4, 5], [3, 5]]),
                          details={"local_xy": xy})  # fmt: skip
    results = [
        SimpleNamespace(i=0, j=1, skipped=False),
        SimpleNamespace(i=1, j=2, skipped=False),
        SimpleNamespace(i=3, j=4, skipped=False),
        SimpleNamespace(i=4, j=5, skipped=False),
        SimpleNamespace(i=3, j=5, skipped=True),
    ]
    new, whole, kept = second_pass_plan(sel, results, [5], partners=2)
    assert sorted(new) == [(1, 5), (2, 5)], new  # the two nearest not tried yet (4 was)
    assert whole == [(3, 5)]
    assert [(r.i, r.j) for r in kept] == [(0, 1), (1, 2), (3, 4), (4, 5)]
    new, whole, kept = second_pass_plan(sel, results, [0], partners=0)
    assert sorted(new) == [(0, 2), (0, 3), (0, 4), (0, 5)] and whole == [] and kept == results
