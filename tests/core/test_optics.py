"""The photos' point spread (core/optics.py): measured on straight edges, undone before OSGM matches.

Against images of known blur: the measured spread follows the blur, the restoration narrows a
blurred edge towards a sharp one and leaves flat noise alone, and on a blurred synthetic block OSGM
places more cells near building edges within 3 GSD with the restoration than without it, at the
same precision elsewhere.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

cv2 = pytest.importorskip("cv2")

from truortho.core import optics  # noqa: E402
from truortho.core.errors import InputError  # noqa: E402


def _steps(blur: float, size: int = 256, seed: int = 0, up: int = 8) -> np.ndarray:
    """Grey levels 0-1 of random axis-parallel and slanted rectangles (steps of 0.3-0.7), rendered
    ``up`` times finer, blurred by ``blur`` px and averaged down to the pixel (its own integration)."""
    rng = np.random.default_rng(seed)
    big = np.full((size * up, size * up), 0.3, np.float32)
    for _ in range(14):
        cx, cy = rng.uniform(0.15, 0.85, 2) * size * up
        w, h = rng.uniform(0.08, 0.2, 2) * size * up
        box = cv2.boxPoints(((cx, cy), (w, h), rng.uniform(0, 90)))
        cv2.fillPoly(big, [box.astype(np.int32)], float(rng.choice([0.0, 1.0])) * 0.7 + 0.3 * rng.uniform())
    if blur > 0:
        big = cv2.GaussianBlur(big, (0, 0), blur * up)
    return cv2.resize(big, (size, size), interpolation=cv2.INTER_AREA)


@pytest.mark.parametrize("blur", [0.0, 0.8, 1.3])
def test_edge_spread_follows_the_blur(blur):
    img = _steps(blur)
    s = optics.photo_spread(img)
    # a pixel's own integration reads about SHARP_SPREAD; a blur adds in quadrature (the pattern
    # reads 0.53-0.58 / 0.96-0.97 / 1.36-1.41 px at 0 / 0.8 / 1.3 px of blur over three seeds)
    expect = math.hypot(blur, optics.SHARP_SPREAD)
    assert s is not None and abs(s - expect) < 0.1 * expect + 0.05, (blur, s)
    # the same photo as 8-bit grey levels reads the same
    assert optics.photo_spread(img * 255.0, 255.0) == pytest.approx(s, abs=1e-3)


def test_no_spread_without_straight_edges():
    rng = np.random.default_rng(1)
    assert optics.photo_spread(rng.uniform(0, 1, (200, 200)).astype(np.float32)) is None
    assert optics.photo_spread(np.full((64, 64), 0.5, np.float32)) is None
    # NaN pixels (outside the photo) are allowed and measure nothing
    img = _steps(1.0)
    img[:, :60] = np.nan
    s = optics.edge_spreads(img)
    assert len(s) and np.isfinite(s).all()


def test_excess_spread_and_noise():
    assert optics.excess_spread(0.3) == 0.0
    assert optics.excess_spread(optics.SHARP_SPREAD) == 0.0
    assert optics.excess_spread(1.3) == pytest.approx(math.sqrt(1.3**2 - optics.SHARP_SPREAD**2))
    rng = np.random.default_rng(2)
    yy, xx = np.mgrid[0:300, 0:300]
    ramp = (0.2 + 0.001 * xx + 0.0005 * yy + 1e-6 * xx * yy).astype(np.float32)
    for sigma in (0.005, 0.02):
        noisy = ramp + rng.normal(0, sigma, ramp.shape).astype(np.float32)
        assert optics.noise_sigma(noisy) == pytest.approx(sigma, rel=0.1)


def test_restore_sharpens_edges_and_leaves_flat_noise_alone():
    blurred = _steps(1.3)
    before = optics.photo_spread(blurred)
    s = optics.excess_spread(before)
    restored = optics.restore(blurred, s, 5)
    after = optics.photo_spread(restored)
    # a first-order inverse: the steepest slope of a Gaussian edge of spread b becomes
    # 2 / b - 1 / hypot(b, s) (times the step over sqrt(2 pi)), read as its inverse
    theory = 1.0 / (2.0 / before - 1.0 / math.hypot(before, s))
    assert after == pytest.approx(theory, rel=0.1), (before, after, theory)
    assert after < before - 0.25
    assert abs(float(restored.mean()) - float(blurred.mean())) < 1e-3
    # flat ground with noise: the detail is all noise, so the gain stays near 0
    rng = np.random.default_rng(3)
    flat = (0.5 + rng.normal(0, 0.01, (200, 200))).astype(np.float32)
    out = optics.restore(flat, 1.0, 5)
    assert np.std(out) < 1.15 * np.std(flat)
    # the same noise across a blurred step: the step is restored, not the noise beside it
    step = blurred + rng.normal(0, 0.01, blurred.shape).astype(np.float32)
    noisy_after = optics.photo_spread(optics.restore(step, s, 5))
    assert noisy_after < before - 0.15
    # NaN stays NaN and does not spread; below MIN_RESTORE nothing changes
    holed = blurred.copy()
    holed[100:140, 100:140] = np.nan
    r = optics.restore(holed, s, 5)
    assert np.array_equal(np.isnan(r), np.isnan(holed))
    assert np.array_equal(optics.restore(blurred, 0.2, 5), blurred)


def test_optics_name_bad_input():
    img = _steps(0.5, size=64)
    with pytest.raises(InputError, match="window"):
        optics.restore(img, 1.0, 4)
    with pytest.raises(InputError, match="sigma"):
        optics.restore(img, -1.0, 5)
    with pytest.raises(InputError, match="sigma"):
        optics.restore(img, float("nan"), 5)
    with pytest.raises(InputError, match="2-D"):
        optics.edge_spreads(np.zeros((8, 8, 3)))
    with pytest.raises(InputError, match="full_scale"):
        optics.edge_spreads(img, 0.0)
    with pytest.raises(InputError, match="spread"):
        optics.excess_spread(-0.1)


def _write_block(folder, blurs, size=(160, 120)):
    """One PNG per blur value, each a different crop of the step pattern."""
    paths = []
    for i, b in enumerate(blurs):
        g = _steps(b, size=256, seed=10 + i)[: size[1], : size[0]]
        p = folder / f"p{i}.png"
        cv2.imwrite(str(p), np.clip(g * 255 + 0.5, 0, 255).astype(np.uint8))
        paths.append(str(p))
    return paths


def test_photo_spreads_per_camera_and_the_pyramid_restores_the_band_only(tmp_path):
    from truortho.core.osgm.views import ImagePyramid, photo_spreads

    paths = _write_block(tmp_path, [1.2, 1.2, 1.2, 0.0, 0.0])
    sizes = [(160, 120)] * 5
    cams = ["soft", "soft", "soft", "sharp", "sharp"]
    spread, report = photo_spreads(paths, sizes, cams)
    assert report["soft"]["photos"] == 3 and report["sharp"]["photos"] == 2
    assert 0.8 < spread[0] == spread[1] == spread[2] < 1.4
    # the sharp photos read about a pixel's own spread: too little to restore
    assert spread[3] == spread[4] < optics.MIN_RESTORE
    assert report["soft"]["restored"] == spread[0]
    plain = ImagePyramid(paths, sizes)
    pyr = ImagePyramid(paths, sizes, spread=spread, window=5)
    assert pyr.restoration(0, 0) == pytest.approx(spread[0])
    assert pyr.restoration(0, 1) == pytest.approx(spread[0] / 2)
    assert pyr.restoration(0, 3) == 0.0 == pyr.restoration(3, 0)  # below MIN_RESTORE
    a = pyr.window(0, 0, -5, -5, 80, 60)
    b = plain.window(0, 0, -5, -5, 80, 60)
    assert np.array_equal(np.isnan(a), np.isnan(b))
    assert optics.photo_spread(pyr.window(0, 0, 0, 0, 160, 120)) < optics.photo_spread(
        plain.window(0, 0, 0, 0, 160, 120)
    )
    # colours are served as decoded; the sharp camera's band too
    rgb = pyr.window(0, 0, 0, 0, 50, 40, colour=True)
    assert np.array_equal(rgb, plain.window(0, 0, 0, 0, 50, 40, colour=True))
    assert np.array_equal(pyr.window(3, 0, 0, 0, 50, 40), plain.window(3, 0, 0, 0, 50, 40))
    with pytest.raises(InputError, match="spread"):
        ImagePyramid(paths, sizes, spread=[1.0])
    with pytest.raises(InputError, match="window"):
        ImagePyramid(paths, sizes, spread=spread, window=4)


def test_windowed_reads_restore_as_the_whole_image(tmp_path):
    """A tiled GeoTIFF is read window by window: with the context the restoration needs, its
    restored windows equal those of the decoded whole image."""
    import rasterio

    from truortho.core.osgm.views import ImagePyramid

    (png,) = _write_block(tmp_path, [1.2], size=(200, 150))
    img = cv2.imread(png, cv2.IMREAD_GRAYSCALE)
    tif = tmp_path / "p.tif"
    with rasterio.open(tif, "w", driver="GTiff", width=200, height=150, count=1, dtype="uint8", tiled=True,
                       blockxsize=64, blockysize=64) as ds:  # fmt: skip
        ds.write(img[None])
    windowed = ImagePyramid([str(tif)], [(200, 150)], spread=[1.0])
    decoded = ImagePyramid([png], [(200, 150)], spread=[1.0])
    assert windowed._windowed[0] and not decoded._windowed[0]
    a = windowed.window(0, 0, 40, 30, 100, 80)
    b = decoded.window(0, 0, 40, 30, 100, 80)
    # the noise is estimated over the area read, so the gains differ a little
    assert np.abs(a - b).max() < 0.02 and np.abs(a - b).mean() < 2e-3


def _dsm_figures(scene, path, gsd: float) -> tuple[float, float, float]:
    """NMAD (GSD) and the shares within 3 GSD away from and within 2 cells of the building outlines
    of the DSM at ``path`` against the synthetic ``scene``, over the cells two photos see."""
    from scipy.ndimage import maximum_filter, minimum_filter

    from truortho.core.rasterio_io import read_raster

    dsm, grid, _ = read_raster(path)
    X, Y = grid.centres()
    truth = scene.height(np.column_stack([X.ravel(), Y.ravel()])).reshape(grid.shape)
    P = np.column_stack([X.ravel(), Y.ravel(), truth.ravel()])
    n = sum(scene.visibility(P, i, tol=0.05)[0].astype(int) for i in range(len(scene.orientation.images)))
    seen = n.reshape(grid.shape) >= 2
    e = dsm - truth
    ok = np.isfinite(e) & seen
    step = (maximum_filter(truth, 3) - minimum_filter(truth, 3)) > 1.0
    edge = maximum_filter(step.astype(np.uint8), 5).astype(bool)
    good = np.abs(np.nan_to_num(e, nan=1e9)) <= 3 * gsd
    nmad = 1.4826 * np.median(np.abs(e[ok] - np.median(e[ok]))) / gsd
    return float(nmad), float(good[seen & ~edge].mean()), float(good[seen & edge].mean())


def test_osgm_restores_blurred_photos_and_edges_gain(tmp_path):
    """A nadir block rendered with a 1.2 px optics blur: OSGM measures about that spread and, with
    the restoration, places more cells near building edges within 3 GSD than without it (1.2-1.4
    points more on three such blocks, seeds 1-3), with the same precision away from them."""
    from truortho.core.osgm import OsgmConfig, OsgmOutputs, run_osgm
    from truortho.core.synthetic import SceneConfig, make_scene

    cfg = SceneConfig(image_size=(320, 240), focal_px=400.0, seed=1, n_oblique=0, optics_blur=1.2)
    scene = make_scene(cfg)
    scene.write(tmp_path)
    gsd = cfg.gsd
    figures = {}
    for name, ps in (("restored", None), ("as decoded", 0.0)):
        out = OsgmOutputs(dsm=tmp_path / f"dsm_{ps}.tif")
        ocfg = OsgmConfig(resolution=gsd, point_spread=ps, prefilter=0.6 if ps is None else 0.0)
        res = run_osgm(scene.orientation, ocfg, scene.extent_world(), out, tmp_path)
        figures[name] = (
            *_dsm_figures(scene, tmp_path / f"dsm_{ps}.tif", gsd),
            res.stats["point_spread"],
            res.summary(),
        )
    print("\n" + "\n".join(f"{k}: NMAD {v[0]:.3f} GSD, flat3 {v[1]:.4f}, edge3 {v[2]:.4f}; {v[3]}"
                           for k, v in figures.items()))  # fmt: skip
    (n1, f1, e1, rep, summary), (n0, f0, e0, rep0, _) = figures["restored"], figures["as decoded"]
    (cam,) = rep
    assert 1.0 < rep[cam]["measured"] < 1.4 and rep[cam]["photos"] >= 4
    assert rep[cam]["restored"] == pytest.approx(optics.excess_spread(rep[cam]["measured"]))
    assert f"{rep[cam]['restored']:.2f} px undone at full resolution" in summary
    assert rep0 == {"given": {"measured": None, "photos": 0, "restored": 0.0}}
    assert e1 >= e0 + 0.006
    assert n1 <= n0 + 0.05 and f1 >= f0 - 0.005


def test_point_spread_config_is_checked():
    from truortho.core.osgm import OsgmConfig

    for bad in (-1.0, float("nan"), 11.0, True, "1"):
        with pytest.raises(InputError, match="point_spread"):
            OsgmConfig(point_spread=bad).validate()
    OsgmConfig(point_spread=0.0).validate()
    OsgmConfig(point_spread=1.5).validate()


def test_prefilter_is_a_gaussian_that_keeps_missing_pixels_out():
    rng = np.random.default_rng(3)
    g = rng.random((40, 50)).astype(np.float32)
    k = cv2.getGaussianKernel(5, 0.6).astype(np.float32)
    ref = cv2.sepFilter2D(g, -1, k, k, borderType=cv2.BORDER_REFLECT)
    out = optics.prefilter(g, 0.6)
    assert out.dtype == np.float32 and np.abs(out - ref).max() < 1e-6
    assert out[5:-5, 5:-5].std() < 0.8 * g[5:-5, 5:-5].std()  # white noise loses most of its power
    assert np.array_equal(optics.prefilter(g, 0.0), g)
    # NaN stays NaN and does not darken its neighbours: a constant band stays constant
    c = np.full((30, 30), 0.4, np.float32)
    c[10:14, 3:20] = np.nan
    f = optics.prefilter(c, 1.0)
    assert np.array_equal(np.isnan(f), np.isnan(c))
    assert np.abs(f[np.isfinite(f)] - 0.4).max() < 1e-6
    assert optics.prefilter_margin(0.6) == 3 and optics.prefilter_margin(0.0) == 0
    for bad in (-0.1, float("nan"), optics.MAX_PREFILTER + 1):
        with pytest.raises(InputError, match="prefilter"):
            optics.prefilter(g, bad)
        with pytest.raises(InputError, match="prefilter_margin"):
            optics.prefilter_margin(bad)


def test_the_pyramid_low_passes_sharp_photos_at_full_resolution_only(tmp_path):
    """``prefilter``: the matching band of a photo that is not restored is low-passed at full
    resolution; ``raw`` windows, the reduced levels, the colours and restored photos are not."""
    import rasterio

    from truortho.core.osgm.views import ImagePyramid

    paths = _write_block(tmp_path, [1.2, 0.0], size=(160, 120))
    sizes = [(160, 120)] * 2
    plain = ImagePyramid(paths, sizes)
    pyr = ImagePyramid(paths, sizes, spread=[1.0, 0.0], prefilter=0.6)
    assert pyr.prefilter_sigma(1, 0) == 0.6 and pyr.prefilter_sigma(1, 1) == 0.0
    assert pyr.prefilter_sigma(0, 0) == 0.0  # restored instead
    whole = plain.window(1, 0, 0, 0, 160, 120)
    a = pyr.window(1, 0, -4, 10, 90, 70)
    b = optics.prefilter(whole, 0.6)
    ref = np.full((70, 90), np.nan, np.float32)
    ref[:, 4:] = b[10:80, :86]
    assert np.array_equal(np.isnan(a), np.isnan(ref))
    assert np.abs(a[np.isfinite(a)] - ref[np.isfinite(ref)]).max() < 1e-6
    assert np.array_equal(
        pyr.window(1, 0, -4, 10, 90, 70, raw=True), plain.window(1, 0, -4, 10, 90, 70), equal_nan=True
    )
    assert np.array_equal(pyr.window(1, 1, 0, 0, 40, 30), plain.window(1, 1, 0, 0, 40, 30))
    rgb = pyr.window(1, 0, 0, 0, 50, 40, colour=True)
    assert np.array_equal(rgb, plain.window(1, 0, 0, 0, 50, 40, colour=True))
    restored = ImagePyramid(paths, sizes, spread=[1.0, 0.0])
    assert np.array_equal(pyr.window(0, 0, 0, 0, 50, 40), restored.window(0, 0, 0, 0, 50, 40))
    # a tiled GeoTIFF read window by window, with the context the low-pass needs: as the whole image
    img = cv2.imread(paths[1], cv2.IMREAD_GRAYSCALE)
    tif = tmp_path / "p.tif"
    with rasterio.open(tif, "w", driver="GTiff", width=160, height=120, count=1, dtype="uint8", tiled=True,
                       blockxsize=64, blockysize=64) as ds:  # fmt: skip
        ds.write(img[None])
    windowed = ImagePyramid([str(tif)], sizes[:1], prefilter=0.6)
    decoded = ImagePyramid(paths[1:], sizes[:1], prefilter=0.6)
    assert windowed._windowed[0]
    w1, w2 = windowed.window(0, 0, 30, 20, 70, 60), decoded.window(0, 0, 30, 20, 70, 60)
    assert np.abs(w1 - w2).max() < 1e-5
    for bad in (-1.0, float("nan"), optics.MAX_PREFILTER + 1, True):
        with pytest.raises(InputError, match="prefilter"):
            ImagePyramid(paths, sizes, prefilter=bad)


def test_prefilter_config_is_checked():
    from truortho.core.osgm import OsgmConfig

    for bad in (-0.1, float("nan"), optics.MAX_PREFILTER + 0.5, True, "0.6"):
        with pytest.raises(InputError, match="prefilter"):
            OsgmConfig(prefilter=bad).validate()
    OsgmConfig(prefilter=0.0).validate()
    OsgmConfig(prefilter=1.0).validate()


def test_osgm_is_more_precise_on_low_passed_photos(tmp_path):
    """A nadir block in JPEG quality 70 with weak texture: matched on photos low-passed by a
    Gaussian of 0.6 px (the default ``prefilter``), OSGM's NMAD is about 0.81 of the NMAD on the
    photos as decoded (seeds 1-3: 0.387 -> 0.318, 0.432 -> 0.350, 0.369 -> 0.299 GSD); cells away
    from edges are within 3 GSD as often, and the edge cells within 1.3 points (the edge refinement
    compares the photos as decoded)."""
    from truortho.core.osgm import OsgmConfig, OsgmOutputs, run_osgm
    from truortho.core.synthetic import SceneConfig, make_scene

    cfg = SceneConfig(image_size=(320, 240), focal_px=400.0, seed=1, n_oblique=0, jpeg_quality=70,
                      noise_sigma=1.5, texture_contrast=1.5)  # fmt: skip
    scene = make_scene(cfg)
    scene.write(tmp_path)
    gsd = cfg.gsd
    figures = {}
    for pf in (0.0, 0.6):
        out = OsgmOutputs(dsm=tmp_path / f"dsm_{pf}.tif")
        ocfg = OsgmConfig(resolution=gsd, prefilter=pf)
        summary = run_osgm(scene.orientation, ocfg, scene.extent_world(), out, tmp_path).summary()
        assert ("low-passed by 0.60 px before matching" in summary) == (pf > 0), summary
        figures[pf] = _dsm_figures(scene, tmp_path / f"dsm_{pf}.tif", gsd)
    print("\n" + "\n".join(f"prefilter {k}: NMAD {v[0]:.3f} GSD, flat3 {v[1]:.4f}, edge3 {v[2]:.4f}"
                           for k, v in figures.items()))  # fmt: skip
    (n0, f0, e0), (n1, f1, e1) = figures[0.0], figures[0.6]
    assert n1 <= 0.9 * n0
    assert f1 >= f0 - 0.003 and e1 >= e0 - 0.02
