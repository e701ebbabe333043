"""Colour model and least-squares corrections (core/ortho/color.py)."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.ortho.color import (
    ColorCorrection,
    devignette_values,
    estimate_colour_model,
    estimate_corrections,
    estimate_vignetting,
    from_channels,
    lab_to_rgb,
    linear_luminance,
    rgb_to_lab,
    to_channels,
)
from truortho.core.synthetic import srgb_to_lab


def test_lab_matches_the_generator_and_round_trips():
    rgb = np.random.default_rng(0).uniform(0, 1, (500, 3))
    assert np.allclose(rgb_to_lab(rgb), srgb_to_lab(rgb), atol=1e-9)
    assert np.allclose(lab_to_rgb(rgb_to_lab(rgb)), rgb, atol=1e-6)
    u16 = (rgb * 65535).round()
    assert np.allclose(from_channels(to_channels(u16, "uint16"), "uint16"), u16, atol=0.05)


def test_estimate_recovers_relative_gains_with_outliers():
    rng = np.random.default_rng(1)
    n_img, n_cell = 6, 3000
    g_true = rng.uniform(0.8, 1.2, (n_img, 2))
    g_true /= g_true.mean(axis=0)
    o_true = rng.normal(0, 3, (n_img, 2))
    o_true -= o_true.mean(axis=0)
    x = rng.uniform(10, 90, (n_cell, 2))
    cells, imgs, vals = [], [], []
    for c in range(n_cell):
        for i in rng.choice(n_img, size=rng.integers(2, 5), replace=False):
            # observed = inverse of the correction applied to the common truth
            y = (x[c] - o_true[i]) / g_true[i] + rng.normal(0, 0.2, 2)
            if rng.random() < 0.03:
                y = y + rng.normal(0, 40, 2)  # occlusion error, moving object
            cells.append(c)
            imgs.append(i)
            vals.append(y)
    corr = estimate_corrections(np.array(cells), np.array(imgs), np.array(vals), n_img)
    assert np.allclose(corr.gain, g_true, atol=0.01)
    assert np.allclose(corr.offset, o_true, atol=0.6)
    assert all(
        a < 0.3 * b for a, b in zip(corr.stats["median_after"], corr.stats["median_before"], strict=True)
    )
    assert np.allclose(corr.gain.mean(axis=0), 1.0, atol=1e-3) and np.allclose(
        corr.offset.mean(axis=0), 0, atol=1e-2
    )


def test_apply_keeps_the_range_of_the_dtype():
    c = ColorCorrection(np.array([[1.5, 1.0, 1.0]]), np.array([[10.0, 0.0, 0.0]]), True)
    s = np.array([[250.0, 250.0, 250.0], [0.0, 0.0, 0.0]])
    out = c.apply(0, s, "uint8")
    assert out.min() >= 0 and out.max() <= 255 and out[0, 0] == pytest.approx(255)
    assert ColorCorrection.identity(2, 1).apply(1, s[:, :1], "float32") is not None


def _white_balanced_block(rng, n_img=6, n_cell=3000):
    """Cells of sRGB colours over the whole lightness range, seen by 2-4 images each; every image
    scales and shifts each channel of the stored values (white balance, exposure, black level)."""
    g = 1.0 + rng.normal(0, 0.06, (n_img, 1)) + rng.normal(0, 0.03, (n_img, 3))
    o = rng.normal(0, 0.015, (n_img, 3))
    truth = rng.uniform(0.05, 0.85, (n_cell, 3))
    cells, imgs, vals = [], [], []
    for c in range(n_cell):
        for i in rng.choice(n_img, size=rng.integers(2, 5), replace=False):
            cells.append(c)
            imgs.append(i)
            vals.append(np.clip(np.round(255 * (truth[c] * g[i] + o[i]) + rng.normal(0, 1.0, 3)), 0, 255))
    # the exact inverse, as a first stage
    exact = ColorCorrection.identity(n_img, 3)
    exact.rgb_gain, exact.rgb_offset = 1.0 / g, -255.0 * o / g
    return np.array(cells), np.array(imgs), np.array(vals, float), exact


def _disagreement(corr, cells, imgs, vals) -> float:
    """Mean dE between the corrected observations of the same cell (consecutive pairs)."""
    out = np.empty_like(vals)
    for i in np.unique(imgs):
        out[imgs == i] = corr.apply(int(i), vals[imgs == i], "uint8")
    same = np.flatnonzero(cells[1:] == cells[:-1])
    lab = rgb_to_lab(out / 255.0)
    return float(np.linalg.norm(lab[same] - lab[same + 1], axis=1).mean())


def test_colour_model_undoes_a_white_balance_that_lab_alone_cannot():
    """A gain per RGB channel moves a* and b* by an amount that grows with the lightness: L*a*b*
    gains and offsets leave part of it between images; the first stage per RGB channel removes it."""
    rng = np.random.default_rng(5)
    cells, imgs, vals, exact = _white_balanced_block(rng)
    lab_only = estimate_colour_model(cells, imgs, vals, 6, "uint8", rgb_stage=False)
    assert lab_only.rgb_gain is None and lab_only.lab
    both = estimate_colour_model(cells, imgs, vals, 6, "uint8")
    before = _disagreement(ColorCorrection.identity(6, 3), cells, imgs, vals)
    d_lab, d_both = _disagreement(lab_only, cells, imgs, vals), _disagreement(both, cells, imgs, vals)
    # what the observation noise (1 DN per channel) leaves between two images
    floor = _disagreement(exact, cells, imgs, vals)
    assert d_both < 1.1 * floor < 1.4 * floor < d_lab < 0.5 * before, (before, floor, d_lab, d_both)
    assert both.rgb_gain is not None and both.rgb_offset is not None
    assert np.allclose(both.rgb_gain.mean(axis=0), 1.0, atol=1e-3)
    # the statistics compare the samples before both stages with those after them
    assert both.stats["median_after"][0] < 0.3 * both.stats["median_before"][0], both.stats
    # the second stage has little left to do
    assert np.abs(both.gain - 1.0).max() < 0.05 and np.abs(both.offset).max() < 1.0
    d = both.as_dict()
    assert d["model"].startswith("per-channel RGB") and len(d["images"][0]["rgb_gain"]) == 3
    # non-RGB data: one stage per band, as before
    single = estimate_colour_model(cells, imgs, vals[:, :1], 6, "uint8")
    assert single.rgb_gain is None and not single.lab
    with pytest.raises(Exception, match="samples"):
        estimate_colour_model(cells, imgs, vals[:10], 6, "uint8")


def test_weakly_correlated_samples_do_not_shrink_the_gains():
    """Fine cells on fine imagery: the samples of one cell differ between images as much as cells differ.

    A regression of one image's samples on another's shrinks the gains of well connected images towards
    zero (and inflates the others to keep the mean); matching robust moments stays near the truth.
    """
    rng = np.random.default_rng(4)
    n_img, n_cell = 8, 6000
    g_true = rng.uniform(0.85, 1.15, n_img)
    g_true /= g_true.mean()
    x = rng.uniform(20, 80, n_cell)
    cells, imgs, vals = [], [], []
    for c in range(n_cell):
        # uneven connectivity: images 0-5 overlap a lot, 6-7 only on a tenth of the cells
        pool = np.arange(n_img) if c % 10 == 0 else np.arange(6)
        for i in rng.choice(pool, size=3, replace=False):
            cells.append(c)
            imgs.append(i)
            vals.append([x[c] / g_true[i] + rng.normal(0, 12)])  # noise ~ content spread (17)
    corr = estimate_corrections(np.array(cells), np.array(imgs), np.array(vals), n_img)
    assert np.abs(corr.gain[:, 0] - g_true).max() < 0.08
    assert corr.gain.min() > 0.7 and corr.gain.max() < 1.3


def test_group_percentiles_equal_the_ranks_of_the_sorted_groups():
    from truortho.core.ortho.color import _group_percentiles

    rng = np.random.default_rng(0)
    qs = np.array([0.5, 0.1587, 0.8413])
    for _ in range(100):
        k = int(rng.integers(1, 8))
        n = rng.integers(1, 300, k)
        xs = np.round(rng.normal(size=int(n.sum())), int(rng.integers(0, 3)))  # many ties too
        starts = np.concatenate([[0], np.cumsum(n)[:-1]])
        out = np.zeros((k, 3))
        _group_percentiles(xs.copy(), starts, n, qs, out)
        for g in range(k):
            v = np.sort(xs[starts[g] : starts[g] + n[g]])
            want = [v[min(int(np.floor(q * (n[g] - 1))), n[g] - 1)] for q in qs]
            np.testing.assert_array_equal(out[g], want)


def test_apply_inplace_equals_apply():
    rng = np.random.default_rng(1)
    for bands, dt in ((3, "uint8"), (4, "uint16"), (1, "float32"), (3, "float32"), (5, "uint16")):
        c = ColorCorrection.identity(3, bands)
        c.gain[1] = rng.uniform(0.8, 1.2, bands)
        c.offset[1] = rng.uniform(-5, 5, bands)
        if bands in (3, 4):  # with the first stage per RGB channel (in the data's units)
            c.rgb_gain, c.rgb_offset = np.ones((3, 3)), np.zeros((3, 3))
            scale0 = {"uint8": 255.0, "uint16": 65535.0}.get(dt, 1.0)
            c.rgb_gain[1] = rng.uniform(0.9, 1.1, 3)
            c.rgb_offset[1] = rng.uniform(-0.02, 0.02, 3) * scale0
        scale = {"uint8": 255.0, "uint16": 65535.0}.get(dt, 1.0)
        s = (rng.uniform(0, 1, (30, 20, bands)) * scale).astype(np.float32)
        m = rng.uniform(size=(30, 20)) > 0.3
        want = s.copy()
        want[m] = c.apply(1, s[m], dt)
        got = s.copy()
        c.apply_inplace(1, got, m, dt)
        np.testing.assert_allclose(got, want, rtol=0, atol=2e-5 * scale)  # interpolated tables
        assert np.array_equal(got[~m], s[~m])
        same = s.copy()
        c.apply_inplace(0, same, m, dt)  # identity: untouched
        assert np.array_equal(same, s)


def test_group_ids_equal_unique_and_stable_argsort():
    from truortho.core.ortho.color import _group_ids

    rng = np.random.default_rng(0)
    for n in (1, 5, 40, 3000):
        ids = rng.integers(0, n * n, int(rng.integers(0, 5000)))
        for id_range in (n * n, 10**12):  # by counting, and by sorting
            uniq, inverse, counts, order = _group_ids(ids, id_range)
            u2, inv2, c2 = np.unique(ids, return_inverse=True, return_counts=True)
            np.testing.assert_array_equal(uniq, u2)
            np.testing.assert_array_equal(inverse, inv2)
            np.testing.assert_array_equal(counts, c2)
            np.testing.assert_array_equal(order, np.argsort(inv2, kind="stable"))


def test_thin_groups_keeps_evenly_spaced_members_of_every_group():
    from truortho.core.ortho.color import _group_ids, _thin_groups

    rng = np.random.default_rng(3)
    ids = rng.integers(0, 40, 5000)
    ids[ids == 7] = 8  # an absent group
    _, inverse, counts, order = _group_ids(ids, 40)
    for m in (1, 5, 50, 10_000):
        sub = _thin_groups(counts, order, m)
        assert np.all(np.diff(sub) > 0)  # ascending item indices, no repeats
        kept = np.bincount(inverse[sub], minlength=len(counts))
        assert np.array_equal(kept, np.minimum(counts, m))
        for g in np.flatnonzero(counts > m)[:5]:  # spread over the group, not its head
            members = np.flatnonzero(inverse == g)
            pos = np.searchsorted(members, sub[inverse[sub] == g])
            assert pos.min() < counts[g] / m + 1 and pos.max() >= counts[g] - counts[g] / m - 1


def test_a_long_strip_of_images_keeps_every_image_pair():
    """200 images in a strip, each cell seen by three neighbours: every image pair keeps its
    evidence at a small per-pair bound, and the gains are recovered along the whole strip."""
    rng = np.random.default_rng(5)
    n_img, per_img = 200, 150
    g_true = rng.uniform(0.85, 1.15, n_img)
    g_true /= g_true.mean()
    first = np.repeat(np.arange(n_img - 2), per_img)  # a cell in images first, first+1, first+2
    x = rng.uniform(20, 80, len(first))
    cells = np.repeat(np.arange(len(first)), 3)
    imgs = (first[:, None] + np.arange(3)[None]).ravel()
    vals = (np.repeat(x, 3) / g_true[imgs] + rng.normal(0, 0.3, len(imgs)))[:, None]
    corr = estimate_corrections(cells, imgs, vals, n_img, per_pair=100)
    assert corr.stats["image_pairs"] == (n_img - 1) + (n_img - 2)  # (i, i+1) and (i, i+2)
    assert corr.stats["pairs_used"] <= 100 * corr.stats["image_pairs"] and corr.stats["per_image_pair"] == 100
    # the budget bounds the whole: 20,000 over 397 image pairs is 50 each, raised to the floor of 250
    assert estimate_corrections(cells, imgs, vals, n_img, budget=20_000).stats["per_image_pair"] == 250
    assert estimate_corrections(cells, imgs, vals, n_img, budget=200_000).stats["per_image_pair"] == 503
    # the strip is a chain, so errors accumulate along it: still a few per cent at its far end
    err = np.abs(corr.gain[:, 0] - g_true).max()
    assert err < 0.04
    # the same number of pairs drawn at random over the block (a global cap) leaves some image
    # pairs with fewer samples, and the chain is worse
    glob = estimate_corrections(
        cells, imgs, vals, n_img, per_pair=0, budget=0, max_pairs=corr.stats["pairs_used"]
    )
    assert np.abs(glob.gain[:, 0] - g_true).max() > 1.2 * err


def _vignetted_block(corner, seed=0, n_images=12, n_cells=6000, views=4):
    """Observations of cells seen by several images of one camera: linear albedo x exposure x
    vignetting ``exp(c rho^2)`` with ``exp(c) = corner``, sRGB-encoded to uint8 range."""
    rng = np.random.default_rng(seed)
    c = np.log(corner)
    albedo = rng.uniform(0.05, 0.6, (n_cells, 3))
    exposure = rng.uniform(0.8, 1.2, n_images)
    cells, imgs, rho2s, vals = [], [], [], []
    for cell in range(n_cells):
        for i in rng.choice(n_images, views, replace=False):
            rho2 = rng.uniform(0.0, 1.0)
            lin = np.clip(albedo[cell] * exposure[i] * np.exp(c * rho2), 0, 1)
            enc = np.where(lin <= 0.0031308, 12.92 * lin, 1.055 * lin ** (1 / 2.4) - 0.055)
            cells.append(cell)
            imgs.append(i)
            rho2s.append(rho2)
            vals.append(enc * 255.0 + rng.normal(0, 0.5, 3))
    return np.array(cells), np.array(imgs), np.array(rho2s), np.array(vals), n_images


@pytest.mark.parametrize("corner", [0.45, 0.75, 1.0])
def test_vignetting_is_recovered_from_overlaps(corner):
    cells, imgs, rho2, vals, n = _vignetted_block(corner)
    lum = linear_luminance(vals, np.uint8)
    coef, stats = estimate_vignetting(cells, imgs, lum, rho2, np.zeros(n, int))
    est = float(np.exp(coef[0].sum()))
    if corner == 1.0:
        # nothing to remove: a corner factor within 2 % of 1 (or not used at all)
        assert abs(est - 1.0) < 0.02, stats
    else:
        assert stats["cameras"][0]["used"], stats
        assert abs(est - corner) < 0.02, (est, stats)
        # removed, the log luminance about each cell's mean no longer falls with the radius
        f = np.exp(coef[imgs, 0] * rho2 + coef[imgs, 1] * rho2**2)
        fixed = linear_luminance(devignette_values(vals, f, np.uint8), np.uint8)

        def slope(y):
            d = np.log(y) - np.bincount(cells, np.log(y))[cells] / np.bincount(cells)[cells]
            r = rho2 - np.bincount(cells, rho2)[cells] / np.bincount(cells)[cells]
            return float((d @ r) / (r @ r))

        assert slope(lum) < 0.8 * np.log(corner)
        assert abs(slope(fixed)) < 0.02


def test_vignetting_needs_overlap_and_apply_inplace_removes_it():
    # too little overlap (fewer observation pairs than min_pairs): nothing estimated
    cells, imgs, rho2, vals, n = _vignetted_block(0.6, n_cells=40)
    coef, stats = estimate_vignetting(cells, imgs, linear_luminance(vals, np.uint8), rho2, np.zeros(n, int))
    assert stats["pairs"] < 500 and np.all(coef == 0.0) and not stats["cameras"], stats
    # apply_inplace with the pixel positions: a corner sample is brightened by 1 / corner (linear light)
    c = np.log(0.6)
    corr = ColorCorrection.identity(1, 3)
    corr.vignetting = np.array([[c, 0.0]])
    corr.centre, corr.inv_norm = np.array([[50.0, 40.0]]), np.array([1.0 / 64.0])
    grey = 0.3 * 0.6  # linear value at the corner
    enc = 1.055 * grey ** (1 / 2.4) - 0.055
    colours = np.full((1, 2, 3), enc * 255.0, np.float32)
    uv = np.array([[[50.0 + 64.0, 40.0], [50.0, 40.0]]])  # rho = 1, then the centre
    corr.apply_inplace(0, colours, np.ones((1, 2), bool), np.uint8, uv)
    back = ((colours[0, 0, 0] / 255.0 + 0.055) / 1.055) ** 2.4
    assert back == pytest.approx(0.3, rel=2e-3)
    assert colours[0, 1, 0] == pytest.approx(enc * 255.0, abs=0.05)  # at the principal point: unchanged
    with pytest.raises(Exception, match="uv"):
        corr.apply_inplace(0, colours, np.ones((1, 2), bool), np.uint8, uv[:, :1])
