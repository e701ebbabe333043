"""The DSM streak indices (:mod:`truortho.core.surface.quality`)."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.errors import InputError
from truortho.core.surface.quality import grid_streak_index, streak_index


def _red_noise(rng, n: int, beta: float) -> np.ndarray:
    """Isotropic relief with amplitude spectrum ``1 / f^beta`` (rough natural terrain for beta 1-2)."""
    f = np.hypot(np.fft.fftfreq(n)[:, None], np.fft.fftfreq(n)[None, :])
    f[0, 0] = 1.0
    return np.real(np.fft.ifft2(np.fft.fft2(rng.normal(size=(n, n))) / f**beta))


def test_isotropic_noise_is_near_one():
    rng = np.random.default_rng(1)
    for _ in range(3):
        assert 1.0 <= streak_index(rng.normal(size=(256, 256))) < 1.4
    for beta in (1.0, 1.5, 2.0):
        assert 1.0 <= streak_index(_red_noise(rng, 256, beta)) < 1.5


def test_isotropic_relief_on_a_slope_is_near_one():
    rng = np.random.default_rng(2)
    yy, xx = np.mgrid[0:200, 0:240]
    z = 0.3 * xx - 0.2 * yy + 0.5 * _red_noise(rng, 256, 1.5)[:200, :240]
    assert streak_index(z) < 1.5


def test_streaks_and_terraces_are_clearly_above_one():
    rng = np.random.default_rng(3)
    yy, xx = np.mgrid[0:256, 0:256]
    # terraces of a quantised slope (contour-parallel steps), with a little noise
    terraces = np.floor(0.3 * (xx + 2 * yy)) + 0.05 * rng.normal(size=xx.shape)
    assert streak_index(terraces) > 10
    # thin streaks along one direction on top of isotropic relief
    relief = _red_noise(rng, 256, 1.5)
    relief /= relief.std()
    streaks = relief + 0.5 * np.sin(2 * np.pi * (xx - 0.5 * yy) / 6.0)
    assert streak_index(streaks) > 3 * streak_index(relief)


def test_nan_cells_are_handled():
    rng = np.random.default_rng(4)
    yy, xx = np.mgrid[0:256, 0:256]
    noise = rng.normal(size=(256, 256))
    holes = noise.copy()
    holes[yy > 300 - xx] = np.nan  # a large corner without data, with a straight diagonal border
    holes[(yy - 100) ** 2 + (xx - 90) ** 2 < 30**2] = np.nan  # and a round hole
    holes[rng.random(holes.shape) < 0.05] = np.inf  # and scattered nodata cells
    v = streak_index(holes)
    assert np.isfinite(v) and 1.0 <= v < 1.6
    # the border of the holes does not make isotropic relief look streaky
    relief = _red_noise(rng, 256, 1.5)
    relief[yy > 300 - xx] = np.nan
    assert streak_index(relief) < 1.6
    striped = np.floor(0.3 * (xx + 2 * yy)) + np.where(np.isfinite(holes), 0.0, np.nan)
    assert streak_index(striped) > 10
    assert np.isnan(streak_index(np.full((32, 32), np.nan)))


def test_plane_and_bad_input():
    yy, xx = np.mgrid[0:64, 0:64]
    assert streak_index(0.2 * xx - 0.1 * yy + 5.0) == 1.0
    with pytest.raises(InputError):
        streak_index(np.zeros(10))
    with pytest.raises(InputError):
        streak_index(np.zeros((4, 64)))
    with pytest.raises(InputError):
        streak_index(np.zeros((64, 64)), min_wavelength=1.0)
    with pytest.raises(InputError):
        streak_index(np.zeros((64, 64)), sectors=1)


def _ripples(rng, n: int, angle_deg: float) -> np.ndarray:
    """Anisotropic natural relief: red noise stretched along ``angle_deg`` (dune ripples, furrows)."""
    fy = np.fft.fftfreq(n)[:, None]
    fx = np.fft.fftfreq(n)[None, :]
    a = np.radians(angle_deg)
    along = fx * np.cos(a) + fy * np.sin(a)
    across = -fx * np.sin(a) + fy * np.cos(a)
    f = np.hypot(4.0 * along, across)  # crests 4x longer than their spacing
    f[0, 0] = 1.0
    return np.real(np.fft.ifft2(np.fft.fft2(rng.normal(size=(n, n))) / f**1.5))


def test_grid_streak_index_tells_processing_artefacts_from_anisotropic_terrain():
    rng = np.random.default_rng(5)
    yy, xx = np.mgrid[0:256, 0:256]
    for _ in range(2):
        assert 0.8 < grid_streak_index(rng.normal(size=(256, 256))) < 1.2
    # anisotropic relief off the grid's directions: streak_index calls it streaky, this does not
    for angle in (20.0, 70.0, 115.0, 155.0):
        r = _ripples(rng, 256, angle)
        assert streak_index(r) > 3
        assert grid_streak_index(r) < 1.3
    # artefacts on the grid: terraces along an axis, SGM-like lines on a diagonal, on natural relief
    relief = _red_noise(rng, 256, 1.5)
    relief /= relief.std()
    assert grid_streak_index(np.floor(0.3 * xx) + 0.05 * rng.normal(size=xx.shape)) > 5
    assert grid_streak_index(relief + 0.5 * np.sin(2 * np.pi * (xx + yy) / 8.0)) > 3
    assert grid_streak_index(relief) < 1.3


def test_grid_streak_index_bad_input():
    assert grid_streak_index(np.full((32, 32), 2.0)) == 1.0
    assert np.isnan(grid_streak_index(np.full((32, 32), np.nan)))
    for bad in ({"half_width": 0.0}, {"half_width": 30.0}, {"min_wavelength": 1.0}):
        with pytest.raises(InputError):
            grid_streak_index(np.zeros((32, 32)), **bad)
