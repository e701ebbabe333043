"""Quality measures of a DSM (pure numpy): what a look at its hillshade would tell.

:func:`streak_index`
    Directional anisotropy of the DSM's fine relief: regular streaks (height
    quantisation terraces, aggregation-path artefacts of SGM, tile seams) put
    their power in one direction of the spectrum, natural terrain spreads it
    over all directions.
:func:`grid_streak_index`
    The same power along the processing grid's axes and diagonals against the other
    directions: the artefacts of the processing, not the terrain's own anisotropy.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError


def _box_sum(a: np.ndarray, half: int) -> np.ndarray:
    """Sums of ``a`` over ``(2 half + 1)^2`` windows clipped at the border (integral image)."""
    rows, cols = a.shape
    ii = np.zeros((rows + 1, cols + 1), np.float64)
    ii[1:, 1:] = np.cumsum(np.cumsum(a, axis=0), axis=1)
    r0 = np.clip(np.arange(rows) - half, 0, rows)
    r1 = np.clip(np.arange(rows) + half + 1, 0, rows)
    c0 = np.clip(np.arange(cols) - half, 0, cols)
    c1 = np.clip(np.arange(cols) + half + 1, 0, cols)
    return ii[np.ix_(r1, c1)] - ii[np.ix_(r0, c1)] - ii[np.ix_(r1, c0)] + ii[np.ix_(r0, c0)]


def _local_residual(z: np.ndarray, ok: np.ndarray, half: int) -> np.ndarray:
    """``z`` minus its least-squares plane over the valid cells of its ``(2 half + 1)^2`` window.

    A high-pass that ignores the nodata cells: a locally planar surface leaves
    no residual, up to the border of a hole or of the array, so holes do not
    add edges of their own. 0 where not valid (and where the window's valid
    cells are too few or collinear for a plane: the local mean is used there).
    """
    rows, cols = z.shape
    w = ok.astype(np.float64)
    zf = np.where(ok, z, 0.0)
    # coordinates centred on each cell's own window are not separable; use global ones, centred
    y = (np.arange(rows, dtype=np.float64) - 0.5 * rows)[:, None] * np.ones((1, cols))
    x = np.ones((rows, 1)) * (np.arange(cols, dtype=np.float64) - 0.5 * cols)[None, :]
    s = {k: _box_sum(v, half) for k, v in {
        "n": w, "x": w * x, "y": w * y, "xx": w * x * x, "xy": w * x * y, "yy": w * y * y,
        "z": zf, "xz": zf * x, "yz": zf * y,
    }.items()}  # fmt: skip
    n = np.maximum(s["n"], 1.0)
    mx, my, mz = s["x"] / n, s["y"] / n, s["z"] / n
    cxx = s["xx"] / n - mx * mx
    cxy = s["xy"] / n - mx * my
    cyy = s["yy"] / n - my * my
    cxz = s["xz"] / n - mx * mz
    cyz = s["yz"] / n - my * mz
    det = cxx * cyy - cxy * cxy
    good = det > 1e-6 * np.maximum(cxx * cyy, 1e-12)
    det = np.where(good, det, 1.0)
    gx = np.where(good, (cxz * cyy - cyz * cxy) / det, 0.0)
    gy = np.where(good, (cyz * cxx - cxz * cxy) / det, 0.0)
    plane = mz + gx * (x - mx) + gy * (y - my)
    return np.where(ok, z - plane, 0.0)


def _soft_mask(ok: np.ndarray, half: int) -> np.ndarray:
    """The valid mask tapered towards nodata and the array border (twice a box mean, 0 off the mask)."""
    okf = ok.astype(np.float64)
    ones = np.ones_like(okf)
    m = _box_sum(okf, half) / _box_sum(ones, half)
    m = _box_sum(m, half) / _box_sum(ones, half)
    return np.where(ok, np.clip(2.0 * m - 1.0, 0.0, 1.0), 0.0)


def _whitened_band(dsm, min_wavelength: float, max_wavelength: float):
    """The whitened power of the DSM's high-pass band and the direction of each sample.

    Returns ``(power, theta)`` (1-D, theta in degrees in [0, 180)), or a float: 1.0 for a
    surface without relief in the band, NaN with fewer than 16 valid cells. See
    :func:`streak_index` for the high-pass, the taper and the whitening.
    """
    z = np.asarray(dsm, dtype=np.float64)
    if z.ndim != 2:
        raise InputError(f"dsm: expected a 2-D array, got shape {z.shape}")
    if min(z.shape) < 8:
        raise InputError(f"dsm: expected at least 8 x 8 cells, got {z.shape}")
    if not (math.isfinite(min_wavelength) and math.isfinite(max_wavelength)):
        raise InputError("min_wavelength, max_wavelength: expected finite numbers of cells")
    if not 2.0 <= min_wavelength < max_wavelength:
        raise InputError(
            "wavelengths: expected 2 <= min_wavelength < max_wavelength, "
            f"got {min_wavelength}, {max_wavelength}"
        )
    ok = np.isfinite(z)
    if ok.sum() < 16:
        return float("nan")
    zc = z - float(np.mean(z[ok]))
    resid = _local_residual(zc, ok, max(1, int(round(max_wavelength / 2))))
    if np.abs(resid).max() <= 1e-9 * max(1.0, float(np.abs(zc[ok]).max())):
        return 1.0  # a plane: no relief in any direction
    rows, cols = z.shape
    taper = np.outer(np.hanning(rows + 2)[1:-1], np.hanning(cols + 2)[1:-1])
    taper *= _soft_mask(ok, max(1, int(math.ceil(min_wavelength))))
    power = np.abs(np.fft.rfft2(resid * taper)) ** 2
    fy = np.fft.fftfreq(rows, d=1.0)[:, None]
    fx = np.fft.rfftfreq(cols, d=1.0)[None, :]
    radius = np.hypot(fx, fy)
    band = (radius >= 1.0 / max_wavelength) & (radius <= 1.0 / min_wavelength)
    # direction of the frequency vector folded onto [0, 180) degrees (rfft keeps fx >= 0)
    theta = np.broadcast_to(np.degrees(np.arctan2(fy, fx)) % 180.0, power.shape)[band]
    # whitening: every sample is divided by the median power of its ring (rings one frequency step
    # wide), so that every wavelength of the band weighs the same whatever the spectral slope of the
    # relief; the median, not the mean, so that the power of a streak does not whiten itself away
    ring = np.broadcast_to(np.rint(radius * min(rows, cols)).astype(np.int64), power.shape)[band]
    p: np.ndarray = power[band]
    order = np.argsort(ring, kind="stable")
    starts = np.flatnonzero(np.r_[True, np.diff(ring[order]) != 0])
    ring_median = np.empty(len(p))
    for a, b in zip(starts, np.r_[starts[1:], len(order)], strict=True):
        ring_median[order[a:b]] = np.median(p[order[a:b]])
    if not (ring_median > 0).all():
        return 1.0
    return p.astype(np.float64) / ring_median, theta


def streak_index(
    dsm: np.ndarray,
    *,
    min_wavelength: float = 2.5,
    max_wavelength: float = 40.0,
    sectors: int = 12,
) -> float:
    """Anisotropy of the high-pass power spectrum of a DSM: ~1 for natural relief, > 1 with streaks.

    The DSM is high-passed in space: every valid cell minus the least-squares
    plane through the valid cells of its window of side about
    ``max_wavelength`` (a locally planar surface leaves nothing, also at the
    border of a hole, so holes add no edges of their own); NaN cells count as
    0. The residual is tapered by a 2-D Hann window and by the valid mask,
    softened over about ``min_wavelength`` cells, and of its power spectrum only
    the ring of wavelengths ``[min_wavelength, max_wavelength]`` cells is kept
    (every direction has the same frequencies there). Each sample is divided by
    the median power of its ring (one frequency step wide), so every
    wavelength weighs the same whatever the spectral slope of the relief, and
    the ring is split into ``sectors`` equal angular sectors over 180 degrees
    (the spectrum of a real array is point-symmetric). The index is the largest
    sector mean of the whitened power divided by the smallest.

    Isotropic relief (white noise, rough natural terrain with an amplitude
    spectrum ``1 / f`` to ``1 / f^2``) gives values near 1 (a little above,
    from the estimation noise of the sector means: about 1.1-1.2 for a
    256 x 256 array, 1.3-1.5 for 128 x 128, about 2 for 64 x 64, so compare
    arrays of similar size); streaks of one direction, such as contour-parallel
    terraces of a quantised slope, runs of equal heights left by a median
    filter on a slope, or the lines SGM leaves along a path direction,
    concentrate their power in one sector and give values of a few units to
    orders of magnitude. Very smooth relief (amplitude ``1 / f^3``) with large
    straight-edged holes can still read high: little power is left in the band
    beside the leakage of the hole's edge.

    Parameters
    ----------
    dsm : (rows, cols) array_like of float
        Heights; NaN (or inf) = no data. Cell units: the wavelengths are in
        cells, so the index does not depend on the resolution or the height unit.
    min_wavelength : float
        Shortest wavelength kept, cells (>= 2, the Nyquist wavelength).
    max_wavelength : float
        Longest wavelength kept, cells (the high-pass cut-off).
    sectors : int
        Angular sectors over 180 degrees (at least 2).

    Returns
    -------
    float
        ``max / min`` of the sector mean powers (>= 1); 1.0 for a surface with
        no relief in the band (a plane), NaN when fewer than 16 cells are valid.

    Raises
    ------
    InputError
        A non-2-D array, an array smaller than 8 x 8, or bad band / sector parameters.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> round(streak_index(rng.normal(size=(128, 128))), 1) < 1.6
    True
    >>> yy, xx = np.mgrid[0:128, 0:128]
    >>> streak_index(np.round(0.3 * (xx + yy)) + 0.01 * rng.normal(size=(128, 128))) > 5
    True
    """
    if isinstance(sectors, bool) or not isinstance(sectors, int | np.integer) or sectors < 2:
        raise InputError(f"sectors: expected an integer >= 2, got {sectors!r}")
    band = _whitened_band(dsm, min_wavelength, max_wavelength)
    if not isinstance(band, tuple):
        return band
    p, theta = band
    s = np.minimum((theta / (180.0 / sectors)).astype(np.int64), sectors - 1)
    count = np.bincount(s, minlength=sectors).astype(np.float64)
    if (count == 0).any():
        raise InputError(f"dsm: {np.shape(dsm)} is too small for {sectors} sectors in the wavelength band")
    mean = np.bincount(s, weights=p, minlength=sectors) / count
    top = float(mean.max())
    if top <= 1e-300:
        return 1.0
    low = float(mean.min())
    return float(top / low) if low > 0 else float("inf")


#: Directions of the processing grid (degrees): the image axes and diagonals, along which SGM's
#: 8 paths, square tiles and axis-aligned pyramids leave their artefacts.
GRID_DIRECTIONS = (0.0, 45.0, 90.0, 135.0)


def grid_streak_index(
    dsm: np.ndarray,
    *,
    min_wavelength: float = 2.5,
    max_wavelength: float = 40.0,
    half_width: float = 7.5,
) -> float:
    """Excess of the DSM's fine relief along the processing grid's directions: ~1 unless the
    processing left artefacts on its own axes.

    The whitened high-pass power of :func:`streak_index`, averaged over the directions within
    ``half_width`` degrees of :data:`GRID_DIRECTIONS` (a third of the half-circle), divided by
    its average over the other directions. :func:`streak_index` takes the strongest direction
    against the weakest, whatever they are: a dune field's ripples, or a ploughed field, are
    anisotropic in their own direction and read as streaks there (the copr crops read 3.3 to
    7.8, with their strongest sectors at 75-135 degrees). The artefacts of the processing lie
    on its grid: SGM's 8 paths, tile seams and terraces of a quantised slope along the axes.
    Natural relief falls on the grid only by chance, so this ratio stays near 1 for it, anisotropic
    or not, and rises with the processing's artefacts.

    Returns
    -------
    float
        The ratio (> 0); 1.0 for a surface without relief in the band; NaN with fewer than 16
        valid cells.

    Raises
    ------
    InputError
        As :func:`streak_index`, and a ``half_width`` outside (0, 22.5) degrees.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> 0.8 < grid_streak_index(rng.normal(size=(128, 128))) < 1.25
    True
    >>> yy, xx = np.mgrid[0:128, 0:128]
    >>> grid_streak_index(np.round(0.3 * xx) + 0.01 * rng.normal(size=(128, 128))) > 3
    True
    """
    if not (isinstance(half_width, int | float) and 0 < half_width < 22.5):
        raise InputError(f"half_width: expected degrees in (0, 22.5), got {half_width!r}")
    band = _whitened_band(dsm, min_wavelength, max_wavelength)
    if not isinstance(band, tuple):
        return band
    p, theta = band
    d = np.min([np.abs((theta - g + 90.0) % 180.0 - 90.0) for g in GRID_DIRECTIONS], axis=0)
    on = d <= half_width
    if not on.any() or on.all():
        raise InputError(f"dsm: {np.shape(dsm)} is too small to tell the grid directions apart")
    off_mean = float(p[~on].mean())
    on_mean = float(p[on].mean())
    if off_mean <= 0:
        return 1.0 if on_mean <= 0 else float("inf")
    return on_mean / off_mean
