"""Guided registration of a weakly connected image group (core/sfm/guided.py, incremental step 5).

The synthetic case reproduces the situation of a flight start or a turn: a strip of images and,
before it, a group of three images that overlap each other well but the strip only at its edge.
The matching found the group's two-view link with the first strip image (points seen by only
those two) and missed the points the group shares with two or more strip images: those exist as
features of the group's images (same point, noisy descriptor) but are in no track. Resection of
the group is then impossible (no triangulated point is seen by it); guided matching finds them.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from truortho.core.errors import InputError
from truortho.core.geometry import Camera, opk_to_matrix, project_points
from truortho.core.sfm.guided import GuidedConfig, search_scale
from truortho.core.sfm.incremental import IncrementalConfig, reconstruct
from truortho.core.sfm.similarity import estimate_similarity

CAM = Camera(1200, 800, 1000.0, 1000.0, 601.3, 398.2, -0.05, 0.01, 0.0, 2e-4, -1e-4)


class _Feats:
    """The part of :class:`~truortho.core.sfm.features.Features` registration reads (float descriptors)."""

    def __init__(self, xy, descriptors) -> None:
        self.xy, self.descriptors = xy, descriptors

    def descriptor_rows(self, rows):
        return self.descriptors[rows]


def weak_group_block(
    seed=0, group_sees_strip=True, descriptor_noise=0.08, noise_px=0.3, clutter=0.3, complete=False
):
    """Tracks, features and truth of a strip (6 images) with a weakly linked group of 3 before it.

    Strip images at x = 0, 25, ..., 125 m, group at x = -150, -125, -100 m, height 120 m (footprint
    144 x 96 m). The group's last image overlaps the first strip image by 44 m and the second by
    19 m. ``group_sees_strip=False`` removes from the group's features every point also seen by a
    strip image other than the first (a purely two-view link: its scale cannot be measured);
    ``complete=True`` puts the missed observations into the tracks (perfect matching: the reference).
    """
    rng = np.random.default_rng(seed)
    xs = [-150.0, -125.0, -100.0] + [25.0 * k for k in range(6)]
    group = {0, 1, 2}
    Rs = np.array([opk_to_matrix(*rng.normal(0, 1.5, 2), rng.normal(0, 2), degrees=True) for _ in xs])
    Cs = np.array([[x + rng.normal(0, 1), rng.normal(0, 1), 120 + rng.normal(0, 1)] for x in xs])
    n_pts = 6000
    X = np.column_stack(
        [rng.uniform(-230, 210, n_pts), rng.uniform(-50, 50, n_pts), rng.uniform(0, 12, n_pts)]
    )
    desc_X = rng.normal(size=(n_pts, 64)).astype(np.float32)
    desc_X /= np.linalg.norm(desc_X, axis=1, keepdims=True)
    vis = np.zeros((len(xs), n_pts), bool)
    uv = np.zeros((len(xs), n_pts, 2))
    for i in range(len(xs)):
        uv[i] = project_points(X, Rs[i], Cs[i], CAM)
        vis[i] = (
            (uv[i, :, 0] > 2)
            & (uv[i, :, 0] < CAM.width - 3)
            & (uv[i, :, 1] > 2)
            & (uv[i, :, 1] < CAM.height - 3)
        )
    strip_views = vis[3:].sum(axis=0)
    first = 3  # first strip image
    # observations in tracks: strip points as seen by the strip; group points among the group; the
    # group's two-view link with the first strip image (points seen by no other strip image)
    in_track = vis.copy()
    missed = np.zeros_like(vis)
    for g in group:
        shared_strip = vis[g] & (strip_views > 0)
        link = shared_strip & vis[first] & (strip_views == 1)
        in_track[g] = vis[g] & (~shared_strip | (link if g == 2 else False))
        missed[g] = shared_strip & ~in_track[g]
        if not group_sees_strip:
            missed[g] &= strip_views == 1
        if complete:
            in_track[g] |= missed[g]
            missed[g] = False
    features, tr, im, xy, fe = [], [], [], [], []
    for i in range(len(xs)):
        pts = np.flatnonzero(in_track[i] | missed[i])
        n_clutter = int(clutter * len(pts))
        f_xy = np.vstack(
            [
                uv[i, pts] + rng.normal(0, noise_px, (len(pts), 2)),
                rng.uniform([0, 0], [CAM.width - 1, CAM.height - 1], (n_clutter, 2)),
            ]
        )
        d = np.vstack(
            [
                desc_X[pts] + rng.normal(0, descriptor_noise, (len(pts), 64)).astype(np.float32),
                rng.normal(size=(n_clutter, 64)).astype(np.float32),
            ]
        )
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        features.append(_Feats(f_xy, d.astype(np.float32)))
        t = np.flatnonzero(in_track[i, pts])
        tr.append(pts[t])
        im.append(np.full(len(t), i))
        xy.append(f_xy[t])
        fe.append(t)
    tr, im, xy, fe = map(np.concatenate, (tr, im, xy, fe))
    # keep tracks seen at least twice, renumbered
    mult = np.bincount(tr, minlength=n_pts)
    keep = mult[tr] >= 2
    _, tr_new = np.unique(tr[keep], return_inverse=True)
    return dict(track=tr_new, image=im[keep], xy=xy[keep], feature=fe[keep], features=features, R=Rs, C=Cs)


def _run(b, **kw):
    prior = Camera(CAM.width, CAM.height, 1040.0, 1040.0, 599.5, 399.5)
    return reconstruct(
        b["track"], b["image"], b["xy"], np.zeros(len(b["R"]), int), [prior], IncrementalConfig(), **kw
    )


@pytest.fixture(scope="module")
def block():
    return weak_group_block()


def test_weak_group_is_left_out_by_resection(block):
    rec = _run(block)
    assert rec.registered[3:].all()
    assert not rec.registered[:3].any()


def test_weak_group_registered_by_guided_matching(block):
    rec = _run(block, features=block["features"], obs_feature=block["feature"])
    print(rec.stats["guided"])
    assert rec.registered.all(), rec.stats["guided"]
    guided = [e for e in rec.stats["guided"] if e["registered"]]
    assert {e["image"] for e in guided} <= {0, 1, 2} and len(guided) >= 1
    for e in guided:
        assert e["guided_inliers"] >= 6 and e["rms_px"] < 1.0
        assert e["scale_search"]["log10_nfa"] < -3
    # the group where perfect matching (the missed observations in the tracks) puts it: both
    # aligned to the truth on the strip; the group's extrapolation error is the block's, not the link's
    ref = weak_group_block(complete=True)
    rec_ref = _run(ref)
    assert rec_ref.registered.all()

    def strip_aligned_errors(r):
        sim = estimate_similarity(r.centers[3:], block["C"][3:])
        return np.linalg.norm(sim.apply(r.centers) - block["C"], axis=1)

    e, e_ref = strip_aligned_errors(rec), strip_aligned_errors(rec_ref)
    print("centre errors [m], guided", np.round(e, 3), "complete matching", np.round(e_ref, 3))
    # (a wrong baseline length would put the group metres off: 1 % of the 100 m to the strip is 1 m)
    assert np.all(e[:3] <= 2.0 * e_ref[:3] + 0.15)
    assert e[3:].max() < 0.1
    # the added observations are those of their tracks' true points (feature index = point row)
    n_in = len(block["track"])
    assert len(rec.obs_track) > n_in and np.all(rec.obs_feature[:n_in] == block["feature"])
    assert rec.stats["final_bundle"]["rms_px"] < 0.6


def test_purely_two_view_link_is_not_registered():
    b = weak_group_block(group_sees_strip=False)
    rec = _run(b, features=b["features"], obs_feature=b["feature"])
    assert rec.registered[3:].all()
    assert not rec.registered[:3].any(), "a scale-free link must not give a pose"
    tried = [e for e in rec.stats["guided"] if e["image"] == 2]
    assert tried and not any(e["registered"] for e in tried)


def test_displaced_features_give_no_scale(block):
    # the group's features of the missed points moved by 15-80 px (descriptors kept): what lies near
    # an epipolar segment with a similar descriptor is then chance, and no scale is significant
    rng = np.random.default_rng(5)
    feats = [_Feats(f.xy.copy(), f.descriptors) for f in block["features"]]
    for g in range(3):
        in_track = np.zeros(len(feats[g].xy), bool)
        in_track[block["feature"][block["image"] == g]] = True
        idx = np.flatnonzero(~in_track)
        ang, r = rng.uniform(0, 2 * np.pi, len(idx)), rng.uniform(15, 80, len(idx))
        feats[g].xy[idx] += np.column_stack([r * np.cos(ang), r * np.sin(ang)])
    rec = _run(block, features=feats, obs_feature=block["feature"])
    assert rec.registered[3:].all()
    assert not rec.registered[:3].any(), rec.stats["guided"]
    assert all(not e["registered"] for e in rec.stats["guided"])


def test_search_scale_recovers_a_known_baseline():
    rng = np.random.default_rng(2)
    n = 400
    A0 = np.column_stack([rng.uniform(-0.5, 0.5, n), rng.uniform(-0.4, 0.4, n), np.ones(n)]) * rng.uniform(
        9, 11, (n, 1)
    )
    T = np.array([0.6, 0.1, 0.05])
    s_true = 2.5
    P = A0 - s_true * T
    u_true = P[:, :2] / P[:, 2:]
    f = 1000.0
    seen = np.flatnonzero((np.abs(u_true[:, 0]) < 0.6) & (np.abs(u_true[:, 1]) < 0.4))[:40]
    d = rng.normal(size=(n, 32)).astype(np.float32)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    u = np.vstack([u_true[seen] + rng.normal(0, 0.3 / f, (len(seen), 2)), rng.uniform(-0.6, 0.6, (300, 2))])
    fd = np.vstack([d[seen] + 0.05 * rng.normal(size=(len(seen), 32)), rng.normal(size=(300, 32))]).astype(
        np.float32
    )
    fd /= np.linalg.norm(fd, axis=1, keepdims=True)
    res = search_scale(A0, T, u, f, u * f, fd, np.arange(n + 1), d, (0.5, 10.0))
    assert res.ok, res.summary()
    assert abs(res.scale - s_true) / s_true < 1e-3
    assert res.count >= 0.9 * len(seen) and np.all(seen[np.argsort(res.features)] >= 0)
    assert set(res.points.tolist()) <= set(seen.tolist())
    assert res.expected_false < 1.0
    with pytest.raises(InputError, match="s_range"):
        search_scale(A0, T, u, f, u * f, fd, np.arange(n + 1), d, (2.0, 1.0))
    with pytest.raises(InputError, match="guided.ratio"):
        search_scale(A0, T, u, f, u * f, fd, np.arange(n + 1), d, (0.5, 10.0), GuidedConfig(ratio=1.5))


@pytest.mark.parametrize(
    ("lat", "lon", "epsg"),
    [(50.82, -0.14, "EPSG:32630"), (42.53, -83.78, "EPSG:32617"), (-33.87, 151.21, "EPSG:32756")],
)
def test_gnss_only_block_gets_the_utm_zone_of_its_positions(lat, lon, epsg):
    """A block with EXIF GNSS and no CRS or GCPs (a drone flight): UTM zone of the positions, metres."""
    from truortho.core.geometry.frame import transform_points
    from truortho.core.sfm.pipeline import _gps_local

    rng = np.random.default_rng(3)
    exifs = [
        SimpleNamespace(has_gps=True, latitude=lat + d[0], longitude=lon + d[1], altitude=120.0 + d[2])
        for d in rng.normal(0.0, [2e-4, 2e-4, 1.0], (5, 3))
    ]
    exifs.append(SimpleNamespace(has_gps=False, latitude=None, longitude=None, altitude=None))
    warnings: list[str] = []
    xyz, crs = _gps_local(exifs, None, warnings)
    assert crs == epsg and warnings and epsg in warnings[0]
    assert np.isnan(xyz[-1]).all() and np.isfinite(xyz[:-1]).all()
    back = transform_points(xyz[:-1], crs, "EPSG:4979")
    assert np.allclose(back[:, 1], [e.latitude for e in exifs[:-1]], atol=1e-7)
    assert np.allclose(back[:, 2], [e.altitude for e in exifs[:-1]], atol=1e-3)
    # a span of ~40 m in latitude is ~40 m of northing
    assert 10.0 < np.ptp(xyz[:-1, 1]) < 200.0
