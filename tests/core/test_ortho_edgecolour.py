"""Colour edges put back on the surface's height steps (core/ortho/edgecolour.py): on a mosaic whose
colour is smeared across a roof outline as JPEG smears it (brightness sharp), the colour of the
cells near the step comes back to their own surface's (every cell in mode ``surface``, those whose
colour the photo already puts on their side in mode ``checked``), the brightness and every other
cell unchanged; with the outline two cells off in the heights, ``checked`` leaves the cells the
heights put on the wrong side alone; through the pipeline, on JPEG photos with the exact DSM, the
colours along the outlines come closer to the truth."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.ndimage import uniform_filter1d

from truortho.core.errors import InputError
from truortho.core.ortho import evaluate as ev
from truortho.core.ortho.edgecolour import REACH, surface_edge_colour


def _ycc(v):
    r, g, b = v
    y = 0.299 * r + 0.587 * g + 0.114 * b
    return y, -0.168736 * r - 0.331264 * g + 0.5 * b, 0.5 * r - 0.418688 * g - 0.081312 * b


def _rgb(y, cb, cr):
    return np.stack([y + 1.402 * cr, y - 0.344136 * cb - 0.714136 * cr, y + 1.772 * cb])


def _tile(seed: int, rows=60, cols=80, smear=5):
    """A red roof (6 m) beside brown ground (0 m) of about the same brightness, both textured in
    brightness; the outline a random line. Returns truth RGB, the smeared RGB (colour averaged
    over ``smear`` cells across the outline, brightness kept), heights and the roof mask."""
    rng = np.random.default_rng(seed)
    r, c = np.mgrid[:rows, :cols]
    a = rng.uniform(-0.4, 0.4)
    roof = c > cols / 2 + a * (r - rows / 2) + rng.uniform(-5, 5)
    h = np.where(roof, 6.0, 0.0) + rng.normal(0, 0.02, (rows, cols))
    roof_rgb = np.array([170.0, 60.0, 50.0])
    ground_rgb = np.array([110.0, 95.0, 60.0])
    base = np.where(roof[None], roof_rgb[:, None, None], ground_rgb[:, None, None])
    y, cb, cr = _ycc(base)
    y = y + rng.normal(0, 6, y.shape)  # brightness texture
    truth = _rgb(y, cb, cr)
    cb_s = uniform_filter1d(uniform_filter1d(cb, smear, axis=1), smear, axis=0)
    cr_s = uniform_filter1d(uniform_filter1d(cr, smear, axis=1), smear, axis=0)
    return truth, _rgb(y, cb_s, cr_s), h, roof


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("checked", [False, True])
def test_colour_near_the_step_comes_back_to_its_own_surface(seed, checked):
    truth, smeared, h, roof = _tile(seed)
    alpha = np.ones(roof.shape, bool)
    alpha[:3, :5] = False  # some cells without colour
    out = surface_edge_colour(smeared, alpha, h, 0.5, 255.0, checked=checked)
    assert out.dtype == np.float32 and out.shape == smeared.shape
    de = lambda x: ev.delta_e(np.moveaxis(np.clip(x, 0, 255) / 255, 0, -1), np.moveaxis(truth, 0, -1) / 255)  # noqa: E731
    near = alpha & (np.hypot(*np.gradient(roof.astype(float))) > 0)  # the cells on the outline
    before, after = de(smeared), de(out)
    assert before[near].mean() > 15.0  # the smear is a fringe a user sees
    # the outline cells are about half-mixed: "checked" restores the ones nearer their own side
    b, a = before[near].mean(), after[near].mean()
    assert a < (0.6 if checked else 0.35) * b, (b, a)
    assert (after[near] > 25).mean() < (0.25 if checked else 0.02)
    # the brightness is kept everywhere, the cells far from the step and without colour untouched
    assert np.allclose(_ycc(out)[0], _ycc(smeared)[0], atol=1e-3)
    from scipy.ndimage import distance_transform_edt

    d = np.minimum(distance_transform_edt(roof), distance_transform_edt(~roof))
    far = d > REACH + 1
    assert np.array_equal(out[:, far & alpha], smeared[:, far & alpha].astype(np.float32))
    assert np.array_equal(out[:, ~alpha], smeared[:, ~alpha].astype(np.float32))


def test_checked_leaves_the_cells_a_misplaced_outline_puts_on_the_wrong_side():
    """Heights whose outline is two cells off the photo's (the roof widened eastwards, as matching
    fattens it): mode ``surface`` paints the roof's colour on the ground cells the heights raise,
    mode ``checked`` leaves them as the photo shows them (ground), and still restores the cells on
    the right side."""
    from scipy.ndimage import binary_dilation

    rows, cols = 40, 60
    r, c = np.mgrid[:rows, :cols]
    roof = c >= 30
    red, brown = np.array([170.0, 60.0, 50.0]), np.array([110.0, 95.0, 60.0])
    base = np.where(roof[None], red[:, None, None], brown[:, None, None])
    y, cb, cr = _ycc(base)
    truth = _rgb(y, cb, cr)
    smeared = _rgb(y, uniform_filter1d(cb, 3, axis=1), uniform_filter1d(cr, 3, axis=1))
    wide = binary_dilation(roof, structure=np.array([[1, 1, 1]]), iterations=2)  # columns 28-29 raised
    h = np.where(wide, 6.0, 0.0)
    alpha = np.ones(roof.shape, bool)
    de = lambda x: ev.delta_e(np.moveaxis(np.clip(x, 0, 255) / 255, 0, -1), np.moveaxis(truth, 0, -1) / 255)  # noqa: E731
    raised = wide & ~roof
    everywhere = surface_edge_colour(smeared, alpha, h, 0.5, 255.0, checked=False)
    checked = surface_edge_colour(smeared, alpha, h, 0.5, 255.0, checked=True)
    assert de(everywhere)[raised].min() > 25  # roof colour on the ground
    assert np.array_equal(checked[:, raised], smeared[:, raised].astype(np.float32))
    assert de(checked)[raised].max() < de(smeared)[raised].max() + 1e-6
    inside = roof & (c <= 31)  # the roof's smeared first columns, on the right side of the heights
    assert de(checked)[inside].mean() < 0.5 * de(smeared)[inside].mean()


def test_without_steps_nothing_changes():
    truth, smeared, h, roof = _tile(7)
    flat = np.zeros_like(h)
    out = surface_edge_colour(smeared, np.ones(h.shape, bool), flat, 0.5, 255.0)
    assert np.array_equal(out, smeared.astype(np.float32))
    # a step below the threshold is no step
    out = surface_edge_colour(smeared, np.ones(h.shape, bool), h, 10.0, 255.0)
    assert np.array_equal(out, smeared.astype(np.float32))


def test_bad_input_is_named():
    v = np.zeros((3, 4, 5), np.float32)
    ok = np.ones((4, 5), bool)
    with pytest.raises(InputError, match=r"\(3, rows, cols\)"):
        surface_edge_colour(v[:2], ok, np.zeros((4, 5)), 0.5, 255.0)
    with pytest.raises(InputError, match="heights"):
        surface_edge_colour(v, ok, np.zeros((4, 6)), 0.5, 255.0)
    with pytest.raises(InputError, match="step"):
        surface_edge_colour(v, ok, np.zeros((4, 5)), 0.0, 255.0)
    with pytest.raises(InputError, match="scale"):
        surface_edge_colour(v, ok, np.zeros((4, 5)), 0.5, float("nan"))


def test_mosaic_params_name_an_unknown_mode():
    """Code that builds the mosaic's parameters itself gets an error, not ``surface``, for a typo."""
    from truortho.core.ortho.mosaic import MosaicParams

    with pytest.raises(InputError, match="edge_colour.*off, checked, surface.*'checkd'"):
        MosaicParams(edge_colour="checkd")
    assert MosaicParams().edge_colour == "off"
    assert MosaicParams(edge_colour="surface").edge_colour == "surface"


def test_pipeline_on_jpeg_photos_with_the_exact_dsm(tmp_path):
    """``edge_colour`` reaches the mosaic: on 4:2:0 JPEG photos (quality 75) with the truth DSM, fewer
    cells of the 2-cell band around the outlines are more than dE 25 off the truth and their mean dE
    is lower, with ``surface`` more than with ``checked``; away from the outlines the mosaic is the
    same."""
    from scipy.ndimage import binary_dilation, binary_erosion

    from truortho.core.ortho.pipeline import TrueOrthoConfig, true_ortho
    from truortho.core.rasterio_io import read_raster
    from truortho.core.synthetic import SceneConfig, make_scene

    plain = dict(noise_sigma=0.0, gain_sigma=0.0, offset_sigma=0.0, vignetting=0.0, jpeg_quality=75)
    cfg = SceneConfig(image_size=(320, 240), focal_px=400.0, n_buildings=6, n_oblique=0, seed=5, **plain)
    scene = make_scene(cfg)
    scene.write(tmp_path)
    res = {}
    for mode in ("off", "checked", "surface"):
        out = tmp_path / f"ortho_{mode}.tif"
        true_ortho(tmp_path / "orientation.json", tmp_path / "dsm.tif", out, None, None,
                   TrueOrthoConfig(edge_colour=mode, color_correction=False))  # fmt: skip
        a, grid, _ = read_raster(out, band=None)
        res[mode] = a
    truth, _ = scene.orthophoto(grid.res)
    roofs = ev.building_mask(scene, grid)
    valid = res["off"][3] > 0
    band = binary_dilation(roofs, iterations=2) & ~binary_erosion(roofs, iterations=2) & valid
    assert band.sum() > 200
    de = {m: ev.delta_e(np.moveaxis(a[:3], 0, -1), truth) for m, a in res.items()}
    ghosts = {m: int((d[band] > 25).sum()) for m, d in de.items()}
    mean = {m: float(d[band].mean()) for m, d in de.items()}
    # (seeds 1-6 of this scene: checked 14-33 % fewer cells off by more than dE 25 and 4-7 % lower mean
    # dE, surface 31-78 % and 5-10 %)
    assert ghosts["surface"] <= ghosts["checked"] <= 0.9 * ghosts["off"], ghosts
    assert mean["surface"] <= mean["checked"] < 0.97 * mean["off"], mean
    far = valid & ~binary_dilation(roofs & ~binary_erosion(roofs), iterations=REACH + 4)
    assert far.sum() > 1000
    for m in ("checked", "surface"):
        assert np.array_equal(res[m][:, far], res["off"][:, far])
