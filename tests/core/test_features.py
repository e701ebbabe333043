"""Features, matching, two-view geometry and pair selection on the shared real data.

fountain-P11 at a 1000 px working resolution against its ground-truth cameras
(R in the .camera files is camera-to-world: ours is its transpose), brighton
GPS pair selection, copr retrieval. Timings are printed (``pytest -s``).
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np
import pytest

from truortho.core.errors import CancelledError, FormatError, InputError
from truortho.core.geometry import Camera
from truortho.core.progress import CallbackProgress
from truortho.core.sfm.features import FeatureConfig, cache_path, extract_all, extract_features
from truortho.core.sfm.matching import MatchConfig, match_descriptors, match_pairs
from truortho.core.sfm.pairs import PairConfig, exhaustive_pairs, select_pairs
from truortho.core.sfm.twoview import TwoViewConfig, estimate_two_view

DATA = Path(os.environ["TRUORTHO_DATA"])
FOUNTAIN = DATA / "fountain-P11"
pytestmark = pytest.mark.skipif(not DATA.is_dir(), reason="shared data sets not available")


def _rot_angle_deg(Ra, Rb) -> float:
    import cv2

    v, _ = cv2.Rodrigues(Ra.T @ Rb)
    return float(np.degrees(np.linalg.norm(v)))


def _gt_pose(i: int):
    v = np.loadtxt(FOUNTAIN / f"gt_dense_cameras/{i:04d}.jpg.camera", max_rows=8)
    return v[4:7].T, v[7]  # world->camera R (file: camera->world), centre


@pytest.fixture(scope="module")
def fountain(tmp_path_factory):
    cache = tmp_path_factory.mktemp("features")
    paths = [FOUNTAIN / f"images/{i:04d}.jpg" for i in range(11)]
    feats, st = extract_all(paths, FeatureConfig(max_dimension=1000), cache_dir=cache)
    print(f"\nSIFT @1000 px: {np.mean(st['seconds_per_image']):.2f} s/image, {st['n_features']} features")
    K = np.loadtxt(FOUNTAIN / "images/K.txt")
    cam = Camera(3072, 2048, K[0, 0], K[1, 1], K[0, 2], K[1, 2])
    return paths, feats, cam, cache


def test_features_full_resolution_coordinates_and_cache(fountain):
    paths, feats, cam, cache = fountain
    f = feats[0]
    assert 1000 < len(f) <= 8000 and f.descriptors.shape == (len(f), 128)
    assert f.descriptors.dtype == np.float32
    assert np.allclose(np.linalg.norm(f.descriptors, axis=1), 1.0, atol=1e-4)  # RootSIFT
    # in memory only the raw uint8 SIFT values (a quarter of float32); rows convert alone
    assert f.sift.dtype == np.uint8 and f.sift.shape == (len(f), 128)
    rows = np.array([5, 0, len(f) - 1])
    assert np.array_equal(f.descriptor_rows(rows), f.descriptors[rows])
    assert (f.width, f.height) == (3072, 2048) and f.scale == pytest.approx(1000 / 3072, rel=1e-3)
    assert f.xy[:, 0].max() > 2500 and f.xy[:, 1].max() > 1500 and f.xy.min() > -0.5
    assert f.colors.shape == (len(f), 3) and f.colors.dtype == np.uint8
    # the cache answers the rerun, independent of root_sift
    cp = cache_path(paths[0], cache, FeatureConfig(max_dimension=1000, root_sift=False))
    assert Path(cp).is_file()
    t = time.perf_counter()
    g = extract_features(paths[0], FeatureConfig(max_dimension=1000, root_sift=False), cache_dir=cache)
    assert time.perf_counter() - t < 0.2
    assert np.array_equal(g.xy, f.xy) and not np.allclose(g.descriptors, f.descriptors)
    assert np.array_equal(g.descriptors, f.sift.astype(np.float32))


def test_feature_errors_and_cancel(tmp_path):
    bad = tmp_path / "bad.jpg"
    bad.write_bytes(b"\xff\xd8 not really")
    with pytest.raises(FormatError, match="bad.jpg"):
        extract_features(bad)
    with pytest.raises(InputError, match="max_features"):
        extract_features(bad, FeatureConfig(max_features=0))
    with pytest.raises(CancelledError):
        extract_all([bad], progress=CallbackProgress(is_cancelled=lambda: True))


def test_match_descriptors_mutual_and_ratio():
    rng = np.random.default_rng(0)
    a = rng.normal(size=(300, 32)).astype(np.float32)
    perm = rng.permutation(300)
    b = a[perm] + rng.normal(0, 0.01, (300, 32)).astype(np.float32)
    for method in ("bf", "flann"):
        m, d = match_descriptors(a, b, MatchConfig(method=method))
        assert len(m) > 290 and np.all(perm[m[:, 1]] == m[:, 0])
    # a duplicated descriptor fails the ratio test
    m, _ = match_descriptors(a[:1], np.vstack([a[:1], a[:1] + 1e-4]))
    assert len(m) == 0
    with pytest.raises(InputError, match="ratio"):
        match_descriptors(a, b, MatchConfig(ratio=1.5))


def test_fountain_essential_pose_vs_ground_truth(fountain):
    paths, feats, cam, _ = fountain
    pairs = [(i, i + 1) for i in range(10)]
    res, st = match_pairs(feats, pairs, [cam] * 11)
    print(
        f"\nmatching (exact BF, mutual, ratio 0.8): {st['seconds_matching'] / len(pairs):.3f} s/pair, "
        f"essential + pose: {st['seconds_geometry'] / len(pairs):.3f} s/pair"
    )
    for r in res:
        g = r.geometry
        assert r.ok and g.model == "essential", (r.i, r.j, g.reason)
        assert g.n_inliers > 100
        Ri, Ci = _gt_pose(r.i)
        Rj, Cj = _gt_pose(r.j)
        err = _rot_angle_deg(Rj @ Ri.T, g.R)
        t_gt = Rj @ (Ci - Cj)
        t_err = np.degrees(np.arccos(np.clip(t_gt @ g.t / np.linalg.norm(t_gt), -1, 1)))
        print(
            f"  {r.i:04d}-{r.j:04d}: {r.n_putative} matches, {g.n_inliers} inliers, "
            f"H ratio {g.h_ratio:.2f}, rot err {err:.3f} deg, t err {t_err:.2f} deg"
        )
        assert err < 1.0 and t_err < 3.0
        assert 2.0 < g.median_angle_deg < 30.0


def test_matching_results_do_not_depend_on_the_threads(fountain):
    """Pairs matched on one thread and on three: the same matches, inliers and poses."""
    paths, feats, cam, _ = fountain
    pairs = [(0, 1), (1, 2), (2, 3), (3, 5), (4, 5), (0, 2)]
    one, _ = match_pairs(feats, pairs, [cam] * 11, threads=1)
    three, _ = match_pairs(feats, pairs, [cam] * 11, threads=3)
    for a, b in zip(one, three, strict=True):
        assert (a.i, a.j, a.n_putative) == (b.i, b.j, b.n_putative)
        assert np.array_equal(a.geometry.inliers, b.geometry.inliers)
        assert np.array_equal(a.geometry.R, b.geometry.R) and np.array_equal(a.geometry.t, b.geometry.t)


def test_fountain_fundamental_without_k(fountain):
    paths, feats, cam, _ = fountain
    res, _ = match_pairs(feats, [(0, 1), (4, 5), (9, 10)])
    for r in res:
        g = r.geometry
        assert r.ok and g.model == "fundamental" and g.R is None and g.n_inliers > 100
        # the ground-truth epipolar geometry agrees with the inliers
        Ri, Ci = _gt_pose(r.i)
        Rj, Cj = _gt_pose(r.j)
        Rrel, t = Rj @ Ri.T, Rj @ (Ci - Cj)
        tx = np.array([[0, -t[2], t[1]], [t[2], 0, -t[0]], [-t[1], t[0], 0]])
        Kinv = np.linalg.inv(cam.K)
        F = Kinv.T @ tx @ Rrel @ Kinv
        x1 = np.column_stack([feats[r.i].xy[g.inliers[:, 0]], np.ones(g.n_inliers)])
        x2 = np.column_stack([feats[r.j].xy[g.inliers[:, 1]], np.ones(g.n_inliers)])
        l2 = x1 @ F.T
        dist = np.abs(np.sum(x2 * l2, axis=1)) / np.linalg.norm(l2[:, :2], axis=1)
        assert np.median(dist) < 3.0  # full-resolution pixels, features from 1000 px


def test_two_view_rejects_with_reason():
    rng = np.random.default_rng(0)
    xy1 = rng.uniform(0, 1000, (15, 2))
    r = estimate_two_view(xy1, xy1 + 1.0)
    assert not r.ok and "too few matches" in r.reason
    r = estimate_two_view(rng.uniform(0, 1000, (200, 2)), rng.uniform(0, 1000, (200, 2)))
    assert not r.ok and r.reason
    with pytest.raises(InputError, match="differ"):
        estimate_two_view(xy1, xy1[:5])
    with pytest.raises(InputError, match="method"):
        TwoViewConfig(method="lmeds").validate()


def test_planar_scene_is_flagged():
    rng = np.random.default_rng(1)
    cam = Camera(1000, 800, 900.0, 900.0, 499.5, 399.5)
    X = np.column_stack([rng.uniform(-20, 20, 300), rng.uniform(-15, 15, 300), np.zeros(300)])
    from truortho.core.geometry import opk_to_matrix, project_points

    R1, R2 = opk_to_matrix(0, 0, 0), opk_to_matrix(2.0, -1.0, 3.0, degrees=True)
    uv1 = project_points(X, R1, [0, 0, 60.0], cam)
    uv2 = project_points(X, R2, [12.0, 1.0, 60.0], cam)
    r = estimate_two_view(uv1, uv2, cam, cam)
    assert r.ok and r.configuration == "planar_or_panoramic" and r.h_ratio > 0.8


def test_brighton_gps_pairs(tmp_path):
    paths = sorted((DATA / "brighton/images").glob("*.JPG"))
    t = time.perf_counter()
    sel = select_pairs(paths, config=PairConfig(strategy="gps"))
    print(
        f"\nGPS pairs: {sel.n_pairs} of {sel.n_exhaustive} in {time.perf_counter() - t:.2f} s, "
        f"ground from {sel.details['ground_source']}, H {sel.details['median_height_m']:.1f} m"
    )
    assert sel.strategy == "gps" and sel.n_pairs < sel.n_exhaustive
    assert sel.details["ground_source"] == "relative_altitude"
    assert 35 < sel.details["median_height_m"] < 45
    # consecutive pairs that really overlap (verified by low-resolution matching) are selected
    feats, _ = extract_all(paths, FeatureConfig(max_dimension=640, max_features=1500), cache_dir=tmp_path)
    consecutive = [(i, i + 1) for i in range(len(paths) - 1)]
    res, st = match_pairs(feats, consecutive, twoview_config=TwoViewConfig(min_inliers=20))
    verified = {(r.i, r.j) for r in res if r.ok}
    assert len(verified) >= 12
    assert verified <= {tuple(p) for p in sel.pairs.tolist()}
    # auto: 18 images -> exhaustive
    assert select_pairs(paths).strategy == "exhaustive"


def test_copr_retrieval_pairs(tmp_path):
    paths = sorted((DATA / "copr/images").glob("*.jpg"))
    cfg = PairConfig(retrieval_k=8, retrieval_max_dimension=480, retrieval_features=400)
    sel = select_pairs(paths, config=cfg, cache_dir=tmp_path)
    print(
        f"\nretrieval: {sel.n_pairs} of {sel.n_exhaustive} pairs, "
        f"features {sel.details['seconds_features']:.1f} s,"
        f" VLAD {sel.details['seconds'] - sel.details['seconds_features']:.2f} s"
    )
    assert sel.strategy == "retrieval" and sel.n_pairs < 0.3 * sel.n_exhaustive
    feats, _ = extract_all(paths, FeatureConfig(max_dimension=480, max_features=400), cache_dir=tmp_path)
    res, st = match_pairs(feats, exhaustive_pairs(len(paths)), twoview_config=TwoViewConfig(min_inliers=20))
    print(f"exhaustive low-res verification: {st['seconds']:.1f} s for {st['pairs']} pairs")
    strong = {(r.i, r.j) for r in res if r.ok and r.geometry.n_inliers >= 60}
    S = {tuple(p) for p in sel.pairs.tolist()}
    recall = len(strong & S) / max(len(strong), 1)
    print(f"recall of strong pairs: {recall:.2f} ({len(strong)} strong)")
    assert len(strong) > 40 and recall > 0.85


def test_keypoint_positions_have_no_half_pixel_bias(tmp_path):
    """A feature at x in an image is at W - 1 - x in its 180° rotation (pixel-centre convention)."""
    import cv2

    from truortho.core.sfm.features import FeatureConfig, extract_features

    rng = np.random.default_rng(0)
    img = cv2.GaussianBlur(rng.integers(0, 255, (240, 320)).astype(np.uint8), (0, 0), 2.0)
    img = cv2.normalize(img, None, 0, 255, cv2.NORM_MINMAX)
    cv2.imwrite(str(tmp_path / "a.png"), img)
    cv2.imwrite(str(tmp_path / "b.png"), img[::-1, ::-1].copy())
    cfg = FeatureConfig(max_dimension=320, max_features=2000, root_sift=False)
    fa, fb = extract_features(tmp_path / "a.png", cfg), extract_features(tmp_path / "b.png", cfg)
    m = cv2.BFMatcher(crossCheck=True).match(fa.descriptors, fb.descriptors)
    pa = fa.xy[[x.queryIdx for x in m]]
    pb = fb.xy[[x.trainIdx for x in m]]
    s = pa + pb - [319, 239]
    ok = np.all(np.abs(s) < 1.0, axis=1)
    assert ok.sum() > 50
    np.testing.assert_allclose(np.median(s[ok], axis=0) / 2, [0.0, 0.0], atol=0.03)


def _views_of_a_texture(tmp_path, shifts, angle_deg=4.0):
    """Views (1200 x 900) of one large textured plane, shifted along x and slightly rotated, and
    the affine maps from the first view to each."""
    import cv2

    rng = np.random.default_rng(7)
    H, W = 1400, 3200
    tex = np.zeros((H, W), np.float32)
    for s in (3, 7, 17, 41):
        n = rng.normal(0, 1, (H // s + 2, W // s + 2)).astype(np.float32)
        tex += cv2.resize(n, (W, H), interpolation=cv2.INTER_CUBIC) * (s**0.5)
    tex = np.clip(128 + 25 * tex / tex.std(), 0, 255).astype(np.uint8)
    paths, maps = [], []
    for n, dx in enumerate(shifts):
        a = np.radians(angle_deg * n)
        # view pixel -> texture pixel: rotate about the view centre, then shift
        A = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0]])
        A[:, 2] = [100 + dx, 250] + np.array([600, 450]) - A[:, :2] @ [600, 450]
        view = cv2.warpAffine(tex, A, (1200, 900), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP)
        p = tmp_path / f"view{n}.png"
        cv2.imwrite(str(p), view)
        paths.append(p)
        maps.append(np.vstack([A, [0, 0, 1]]))
    return paths, maps


def test_pairs_are_matched_in_their_overlap_only(tmp_path):
    """The coarse pass finds the overlap of two views of a plane: the product shrinks, and the
    matches consistent with the true mapping stay (a few more pass the ratio test, which now
    meets fewer competitors). Disjoint views, and overlap_features 0, are matched whole."""
    from truortho.core.sfm.matching import match_features, overlap_rows

    paths, maps = _views_of_a_texture(tmp_path, [0, 600, 1900])
    feats = [extract_features(p, FeatureConfig(max_features=4000)) for p in paths]
    f0, f1 = feats[0], feats[1]
    assert len(f0) > 3000 and len(f1) > 3000

    def correct(m, k):  # matches within 2 px of the true mapping of view 0 to view k
        T = np.linalg.inv(maps[k]) @ maps[0]
        q = f0.xy[m[:, 0]] @ T[:2, :2].T + T[:2, 2]
        return int((np.linalg.norm(q - feats[k].xy[m[:, 1]], axis=1) < 2.0).sum())

    rows = overlap_rows(f0, f1, MatchConfig())
    assert rows is not None
    ri, rj = rows
    assert len(ri) * len(rj) < 0.5 * len(f0) * len(f1)  # half the views overlap
    # the kept features are those of the common part (x > 600 - margin in view 0)
    assert f0.xy[ri, 0].min() > 600 - 0.15 * 1200 - 60
    whole, w_restricted = match_features(f0, f1, MatchConfig(overlap_features=0))
    part, p_restricted = match_features(f0, f1, MatchConfig())
    assert p_restricted and not w_restricted
    assert correct(part, 1) >= 0.98 * correct(whole, 1) and correct(whole, 1) > 300
    assert np.all(np.diff(part[:, 0]) >= 0)  # sorted by the first index, as match_descriptors
    # no overlap: no homography to trust, matched whole
    assert overlap_rows(f0, feats[2], MatchConfig()) is None
    res, st = match_pairs(feats, [(0, 1), (0, 2)])
    assert st["overlap_restricted"] == 1 and res[0].restricted and not res[1].restricted
    assert res[0].ok and not res[1].ok
    with pytest.raises(InputError, match="overlap_margin"):
        MatchConfig(overlap_margin=-1).validate()


def _synthetic_features(xy, sift, width=4000, height=3000):
    from truortho.core.sfm.features import Features

    n = len(xy)
    return Features(
        np.asarray(xy, float), np.full(n, 10.0, np.float32), np.zeros(n, np.float32),
        np.ones(n, np.float32), np.asarray(sift, np.uint8), np.zeros((n, 3), np.uint8),
        width, height, 0.5,
    )  # fmt: skip


def test_windowed_matching_searches_about_the_mapped_position():
    """Each feature meets only the features near where the homography maps it: a look-alike
    farther than the window (repetitive texture) no longer fails the ratio test, a point whose
    parallax exceeds the window is not matched, and the result is the whole search's where the
    window holds every true partner."""
    from truortho.core.sfm.matching import match_windowed

    rng = np.random.default_rng(3)
    n = 3000
    xy = np.column_stack([rng.uniform(0, 4000, n), rng.uniform(0, 3000, n)])
    xy[:2] = [[800.0, 1000.0], [900.0, 2000.0]]
    sift = rng.integers(0, 60, (n, 128))
    H = np.array([[0.98, 0.03, 700.0], [-0.03, 0.98, -150.0], [1e-6, 2e-6, 1.0]])
    q = np.column_stack([xy, np.ones(n)]) @ H.T
    xy_j = q[:, :2] / q[:, 2:3] + rng.normal(0, 3.0, (n, 2))  # relief parallax of a few px
    sift_j = np.clip(sift + rng.integers(-4, 5, (n, 128)), 0, 255)
    # a twin of feature 0's partner 1,500 px away (repetitive facade), and point 1 off by 900 px
    # (the 3 x 3 cells searched reach at most 2 cells of max(radius, 4000 / 16) px)
    xy_j = np.vstack([xy_j, xy_j[0] + [1500.0, 0.0]])
    sift_j = np.vstack([sift_j, np.clip(sift_j[0] + rng.integers(-1, 2, 128), 0, 255)])
    xy_j[1] += [900.0, 0.0]
    fi, fj = _synthetic_features(xy, sift), _synthetic_features(xy_j, sift_j)
    inside = (xy_j[:n, 0] >= 0) & (xy_j[:n, 0] < 4000) & (xy_j[:n, 1] >= 0) & (xy_j[:n, 1] < 3000)
    assert inside[0] and inside[1] and 1500 < inside.sum() < n

    m = match_windowed(fi, fj, H, radius=60.0)
    assert np.all(np.diff(m[:, 0]) > 0)
    right = m[:, 0] == m[:, 1]
    assert right.mean() > 0.999
    found = set(m[right, 0])
    assert 0 in found  # its twin lies outside the window
    assert 1 not in found  # moved beyond the window
    assert len(found) > 0.98 * (inside.sum() - 1)
    whole, _ = match_descriptors(fi.descriptors, fj.descriptors)
    assert 0 not in set(whole[:, 0])  # the whole search meets the twin: ratio test fails
    true_whole = whole[(whole[:, 0] == whole[:, 1]) & inside[whole[:, 0]], 0]
    assert set(true_whole) - {0, 1} <= found
    # a radius larger than the frame is the whole search restricted to the mapped frame
    m_all = match_windowed(fi, fj, H, radius=5000.0)
    assert 0 not in set(m_all[:, 0]) and 1 in set(m_all[:, 0])
    with pytest.raises(InputError, match="window_factor"):
        MatchConfig(window_factor=-1).validate()
    with pytest.raises(InputError, match="window_min"):
        MatchConfig(window_min=0).validate()


def test_two_view_inliers_do_not_depend_on_the_sample():
    """Nearly flat terrain (dunes, +-1 m at 60 m): the estimator's own inlier set depends on the
    sample it ends with; after refinement and re-selection every seed finds the same true inliers."""
    from truortho.core.geometry import opk_to_matrix, project_points

    rng = np.random.default_rng(7)
    cam = Camera(2000, 1400, 1800.0, 1800.0, 999.5, 699.5)
    n, n_out = 1500, 300
    X = np.column_stack([rng.uniform(-25, 25, n), rng.uniform(-12, 12, n), rng.uniform(-1, 1, n)])
    R1, R2 = opk_to_matrix(1.0, -2.0, 0.5, degrees=True), opk_to_matrix(-1.5, 1.0, 2.0, degrees=True)
    uv1 = project_points(X, R1, [0, 0, 60.0], cam) + rng.normal(0, 0.4, (n, 2))
    uv2 = project_points(X, R2, [15.0, 1.0, 60.5], cam) + rng.normal(0, 0.4, (n, 2))
    uv1 = np.vstack([uv1, rng.uniform([0, 0], [2000, 1400], (n_out, 2))])
    uv2 = np.vstack([uv2, rng.uniform([0, 0], [2000, 1400], (n_out, 2))])
    sets = []
    for seed in range(4):
        r = estimate_two_view(uv1, uv2, cam, cam, TwoViewConfig(seed=seed))
        assert r.ok
        true_in = np.count_nonzero(r.inlier_mask[:n])
        assert true_in >= 0.97 * n, (seed, true_in)
        assert np.count_nonzero(r.inlier_mask[n:]) <= 0.02 * n_out
        sets.append(r.inlier_mask)
    common = np.logical_and.reduce(sets)
    assert np.count_nonzero(common[:n]) >= 0.97 * n


def test_refine_pose_reaches_the_robust_minimum():
    """refine_pose (Huber on Sampson distances) from a perturbed pose, with 10 % gross outliers,
    on random two-view geometries: the pose moves to the truth (within the noise) and no small step
    of any of its five parameters lowers the robust cost (a minimum, not an early stop)."""
    from truortho.core.sfm.twoview import _huber_cost, _rodrigues, _sampson, _skew, refine_pose

    rng = np.random.default_rng(7)
    f = 2400.0
    for _ in range(8):
        n = int(rng.integers(100, 2000))
        X = np.column_stack([rng.uniform(-20, 20, n), rng.uniform(-15, 15, n), rng.uniform(40, 80, n)])
        R_true = _rodrigues(rng.normal(0, 0.1, 3))
        t_true = np.array([rng.uniform(5, 15), rng.normal(0, 2), rng.normal(0, 1)])
        n1 = X[:, :2] / X[:, 2:]
        Xc = X @ R_true.T + t_true
        n2 = Xc[:, :2] / Xc[:, 2:]
        n1 = n1 + rng.normal(0, 0.5 / f, n1.shape)
        n2 = n2 + rng.normal(0, 0.5 / f, n2.shape)
        out = rng.random(n) < 0.1
        n2[out] += rng.normal(0, 5 / f, (int(out.sum()), 2))
        R0 = _rodrigues(rng.normal(0, 0.01, 3)) @ R_true
        t0 = t_true / np.linalg.norm(t_true) + rng.normal(0, 0.03, 3)
        s = 2.0 / f
        R, t = refine_pose(R0, t0, n1, n2, s)
        assert abs(np.linalg.norm(t) - 1.0) < 1e-12
        assert _rot_angle_deg(R, R_true) < 0.05 < _rot_angle_deg(R0, R_true)
        t_err = np.degrees(np.arccos(np.clip(t @ t_true / np.linalg.norm(t_true), -1, 1)))
        assert t_err < 0.5
        x1 = np.column_stack([n1, np.ones(n)])
        x2 = np.column_stack([n2, np.ones(n)])
        c = _huber_cost(_sampson(_skew(t) @ R, x1, x2), s)
        for k in range(3):
            for sign in (-1, 1):
                w = np.zeros(3)
                w[k] = sign * 1e-5
                tk = t + sign * 1e-4 * np.eye(3)[k]
                tk /= np.linalg.norm(tk)
                assert _huber_cost(_sampson(_skew(t) @ (_rodrigues(w) @ R), x1, x2), s) >= c * (1 - 1e-9)
                assert _huber_cost(_sampson(_skew(tk) @ R, x1, x2), s) >= c * (1 - 1e-9)
    # too few points, or no scale: the input comes back
    R, t = refine_pose(np.eye(3), np.array([1.0, 0, 0]), np.zeros((5, 2)), np.zeros((5, 2)), 1e-3)
    assert np.array_equal(R, np.eye(3)) and np.array_equal(t, [1.0, 0, 0])
