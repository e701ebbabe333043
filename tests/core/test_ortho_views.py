"""Per-tile view helpers (core/ortho/views.py)."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.ortho.views import _normals


def _normals_numpy(h: np.ndarray, res: float) -> np.ndarray:
    """The array formula the compiled normals replaced (the reference of the test below)."""
    hz = np.where(np.isfinite(h), h, np.nan)

    def d(axis):
        fwd = np.diff(hz, axis=axis, append=np.nan)
        bwd = np.diff(hz, axis=axis, prepend=np.nan)
        a = np.where(np.isnan(fwd), bwd, fwd)
        b = np.where(np.isnan(bwd), fwd, bwd)
        out = np.where(np.abs(a) <= np.abs(b), a, b)
        return np.where(np.isfinite(out), out, 0.0) / res

    dzdx = d(1)
    dzdy = -d(0)  # rows go south
    n = np.stack([-dzdx, -dzdy, np.ones_like(dzdx)], axis=-1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def test_normals_leave_out_the_surface_noise():
    """On a rough matched surface the one-sided differences of a pit or a bump tilt the cell away
    from every camera (boruszyn's fields: 20,700 isolated cells without a view, with or without the
    visibility tests). With the cell's noise term, each difference is shrunk towards 0 by it: a pit
    within the noise is flat, a deeper one keeps the excess; without noise nothing changes."""
    h = np.zeros((5, 5))
    h[2, 2] = -0.3  # a pit: every one-sided difference is 0.3 m
    rough = _normals(h, 0.25)[2, 2]
    assert rough[2] < 0.7  # tilted by a slope of 1.2 on both axes
    flat = _normals(h, 0.25, np.full(h.shape, 0.4))[2, 2]
    assert np.allclose(flat, [0.0, 0.0, 1.0])
    part = _normals(h, 0.25, np.full(h.shape, 0.2))[2, 2]  # 0.1 m of the 0.3 m is beyond the noise
    assert np.allclose(part, _normals(h / 3.0, 0.25)[2, 2])
    assert np.array_equal(_normals(h, 0.25, np.zeros(h.shape)), _normals(h, 0.25))
    # a plane is a plane: the noise only removes slope up to its own size per cell
    yy, xx = np.mgrid[0:5, 0:6] * 1.0
    n = _normals(0.5 * xx, 1.0, np.full(xx.shape, 0.1))
    assert np.allclose(n, np.array([-0.4, 0.0, 1.0]) / np.sqrt(1.16))
    with pytest.raises(Exception, match="noise"):
        _normals(h, 0.25, np.full((2, 2), 0.1))


def test_compiled_normals_equal_the_array_formula():
    """The compiled normals are bit-identical to the array formula (smaller one-sided difference,
    the forward one on a tie, holes and infinities as missing neighbours)."""
    rng = np.random.default_rng(0)
    for t in range(60):
        h = rng.normal(size=(int(rng.integers(1, 30)), int(rng.integers(1, 30)))) * 3
        h = np.round(h, int(rng.integers(0, 2)))  # ties
        h[rng.random(h.shape) < 0.2] = np.nan
        if t % 3 == 0:
            h[rng.random(h.shape) < 0.05] = np.inf
        a = _normals(h, 0.5)
        assert np.array_equal(a, _normals_numpy(h, 0.5))
        assert np.allclose(np.linalg.norm(a, axis=-1), 1.0) and (a[..., 2] > 0).all()
    # a plane z = 0.2 x - 0.1 y (x east, rows south): normal (-0.2, 0.1, 1) / norm
    yy, xx = np.mgrid[0:5, 0:6] * 1.0
    n = _normals(0.2 * xx + 0.1 * yy, 1.0)  # y = -row
    assert np.allclose(n, np.array([-0.2, 0.1, 1.0]) / np.sqrt(1.05))
