"""The shared rank selection and NaN-aware median of the kernels (:mod:`truortho.core.quickselect`)."""

import warnings

import numpy as np
import pytest

from truortho.core.errors import InputError
from truortho.core.quickselect import median_of, nanmedian_axis0, select_rank


@pytest.mark.parametrize("n", [1, 2, 3, 8, 33])
def test_select_rank_and_median_of_agree_with_numpy(n):
    rng = np.random.default_rng(n)
    for _ in range(20):
        x = rng.integers(0, 6, n).astype(np.float64)  # ties on purpose
        k = int(rng.integers(0, n))
        buf = x.copy()
        select_rank(buf, 0, n - 1, k)
        assert buf[k] == np.sort(x)[k]
        assert np.all(buf[:k] <= buf[k]) and np.all(buf[k + 1 :] >= buf[k])
        assert median_of(x.copy(), n) == np.median(x)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("views", [1, 2, 3, 4, 7, 12])
def test_nanmedian_axis0_equals_numpy_to_the_bit(dtype, views):
    rng = np.random.default_rng(views)
    a = (rng.normal(size=(views, 30, 40, 3)) * 1e3).astype(dtype)
    a[rng.random(a.shape) < 0.4] = np.nan
    a[:, 0, 0, :] = np.nan  # a cell no view sees
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        ref = np.nanmedian(a, axis=0)
    got = nanmedian_axis0(a)
    assert got.dtype == dtype and got.shape == a.shape[1:]
    assert np.array_equal(got, ref, equal_nan=True)
    assert np.isnan(got[0, 0]).all()


def test_nanmedian_axis0_of_no_views_and_bad_input():
    assert np.isnan(nanmedian_axis0(np.empty((0, 4, 5), np.float32))).all()
    assert nanmedian_axis0(np.empty((0, 4, 5), np.float32)).shape == (4, 5)
    with pytest.raises(InputError, match="float32 or float64"):
        nanmedian_axis0(np.zeros((3, 4), np.int32))
