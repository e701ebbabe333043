"""Level selection from aggregated costs, and the NaN-aware median filter."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..jit import njit, pjit, prange
from .cost import COST_MAX

#: Default uniqueness ratio: the best level must cost at most 0.95 times the
#: best level outside its +-1 neighbourhood (OpenCV's ``uniquenessRatio`` 5).
DEFAULT_UNIQUENESS = 0.95


@pjit
def _select_kernel(s, z0, valid, uniq, reject_edges, level, conf):
    rows, cols, nd = s.shape
    for r in prange(rows):
        for c in range(cols):
            if not valid[r, c]:
                level[r, c] = np.nan
                conf[r, c] = np.nan
                continue
            best = 0
            m = np.int64(s[r, c, 0])
            for d in range(1, nd):
                v = np.int64(s[r, c, d])
                if v < m:
                    m = v
                    best = d
            m2 = np.int64(-1)
            for d in range(nd):
                if d < best - 1 or d > best + 1:
                    v = np.int64(s[r, c, d])
                    if m2 < 0 or v < m2:
                        m2 = v
            if m2 >= 0 and m > uniq * m2:
                level[r, c] = np.nan
                conf[r, c] = np.nan
                continue
            if reject_edges and nd > 1 and (best == 0 or best == nd - 1):
                level[r, c] = np.nan
                conf[r, c] = np.nan
                continue
            delta = 0.0
            if 0 < best < nd - 1:
                a = np.float64(s[r, c, best - 1])
                b = np.float64(s[r, c, best + 1])
                den = max(a - m, b - m)
                if den > 0.0:
                    delta = 0.5 * (a - b) / den
                    delta = min(0.5, max(-0.5, delta))
            level[r, c] = np.float32(z0[r, c] + best + delta)
            if m2 > 0:
                conf[r, c] = np.float32(1.0 - m / m2)
            else:
                conf[r, c] = 0.0


def valid_cells(cost: np.ndarray) -> np.ndarray:
    """Cells with at least one level below ``COST_MAX``.

    Parameters
    ----------
    cost : (rows, cols, nd) uint16
        Matching costs.

    Returns
    -------
    (rows, cols) bool
        False where the whole cost column is ``COST_MAX`` (nothing was
        matched there); pass it to :func:`select` as ``valid``.
    """
    c = np.asarray(cost)
    if c.ndim != 3:
        raise InputError(f"cost: expected a (rows, cols, nd) array, got shape {c.shape}")
    return np.asarray((c < COST_MAX).any(axis=2))


def select(
    S: np.ndarray,
    z0: np.ndarray | None = None,
    uniqueness: float = DEFAULT_UNIQUENESS,
    *,
    valid: np.ndarray | None = None,
    reject_edges: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """Winner-take-all level with sub-level refinement, uniqueness and confidence.

    Parameters
    ----------
    S : (rows, cols, nd) integer array
        Aggregated costs (:func:`~.aggregation.aggregate`).
    z0 : (rows, cols) integer array, optional
        Absolute level of each cell's level 0 (None: 0).
    uniqueness : float in (0, 1]
        With ``m`` the smallest cost (at level ``d*``) and ``m2`` the smallest
        cost among levels ``|d - d*| > 1``, the cell is accepted only when
        ``m <= uniqueness * m2`` (1 disables the test; without such levels,
        i.e. ``nd <= 3`` near the minimum, the test passes).
    valid : (rows, cols) bool, optional
        Cells to select at all (e.g. :func:`valid_cells` of the cost volume);
        the others are NaN. Default: all cells.
    reject_edges : bool
        Also reject minima on the first or last level of a window (the true
        level may lie outside it).

    Returns
    -------
    level : (rows, cols) float32
        Absolute level ``z0 + d* + delta``, ``delta`` in [-0.5, 0.5] the
        equiangular (V) fit through ``S[d* - 1], S[d*], S[d* + 1]``:
        ``(S[d*-1] - S[d*+1]) / (2 max(S[d*-1] - S[d*], S[d*+1] - S[d*]))``
        (0 on the window's first/last level or for a flat triple); NaN where
        rejected or invalid. Aggregated costs rise by about P1 per level on
        both sides of their minimum, a V rather than a parabola: a parabola
        pulls the result towards the nearest level (pixel locking). On the
        copr block's OSGM DSM the fractions of the heights (in Z steps) were
        1.6 times as frequent near 0 as on average with the parabola, and
        within 0.85-1.18 of the average with this fit.
    confidence : (rows, cols) float32
        ``1 - m / m2`` in [0, 1] (0 when ``m2`` does not exist or is 0): how
        much the best level beats the best distinct alternative; NaN where
        ``level`` is NaN.
    """
    s = np.asarray(S)
    if s.ndim != 3 or not np.issubdtype(s.dtype, np.integer) or min(s.shape) < 1:
        raise InputError(f"S: expected a non-empty (rows, cols, nd) integer array, got {s.dtype} {s.shape}")
    shape = s.shape[:2]
    u = float(uniqueness)
    if not (0.0 < u <= 1.0):
        raise InputError(f"uniqueness: expected a ratio in (0, 1], got {uniqueness!r}")
    if z0 is None:
        z = np.zeros(shape, np.int32)
    else:
        z = np.asarray(z0)
        if z.shape != shape or not np.issubdtype(z.dtype, np.integer):
            raise InputError(f"z0: expected an integer array of shape {shape}, got {z.dtype} {z.shape}")
        z = z.astype(np.int32, copy=False)
    if valid is None:
        v = np.ones(shape, np.bool_)
    else:
        v = np.asarray(valid, dtype=np.bool_)
        if v.shape != shape:
            raise InputError(f"valid: expected a boolean array of shape {shape}, got {v.shape}")
    level = np.empty(shape, np.float32)
    conf = np.empty(shape, np.float32)
    _select_kernel(np.ascontiguousarray(s), z, v, u, bool(reject_edges), level, conf)
    return level, conf


@njit
def _median_of(buf, n):
    """Median of buf[:n] (sorts it in place; insertion sort: n is small)."""
    for i in range(1, n):
        x = buf[i]
        j = i
        while j > 0 and buf[j - 1] > x:
            buf[j] = buf[j - 1]
            j -= 1
        buf[j] = x
    h = n // 2
    if n % 2 == 1:
        return buf[h]
    return 0.5 * (buf[h - 1] + buf[h])


@njit
def _finite_window(x, r, c, rad, buf):
    """Copies the finite values of the ``(2 rad + 1)^2`` window of ``x`` around ``(r, c)`` (cut at
    the borders) into ``buf``; returns how many there are."""
    rows, cols = x.shape
    n = 0
    for rr in range(max(0, r - rad), min(rows, r + rad + 1)):
        for cc in range(max(0, c - rad), min(cols, c + rad + 1)):
            v = x[rr, cc]
            if v == v:
                buf[n] = v
                n += 1
    return n


@pjit
def _median_kernel(x, rad, min_count, out):
    rows, cols = x.shape
    for r in prange(rows):
        buf = np.empty((2 * rad + 1) * (2 * rad + 1), np.float64)
        for c in range(cols):
            if x[r, c] != x[r, c]:
                out[r, c] = np.nan
                continue
            n = _finite_window(x, r, c, rad, buf)
            if n < min_count:
                out[r, c] = np.nan
            else:
                out[r, c] = _median_of(buf, n)


def median_filter(values: np.ndarray, size: int = 3, *, min_count: int = 1) -> np.ndarray:
    """NaN-aware median filter.

    Parameters
    ----------
    values : (rows, cols) float array
        NaN = no value.
    size : int
        Odd window side (1 returns a copy).
    min_count : int
        A valid cell whose window (clipped at the border) holds fewer than
        ``min_count`` valid values becomes NaN (removes isolated values);
        the default 1 keeps every valid cell (its own value always counts).

    Returns
    -------
    (rows, cols) float32
        NaN cells stay NaN; every other cell gets the median of the valid
        values of its window (for an even count the mean of the two middle
        values), so a cell with few valid neighbours is the median of just
        those.
    """
    x = np.asarray(values, dtype=np.float32)
    if x.ndim != 2:
        raise InputError(f"median_filter: expected a 2-D array, got shape {x.shape}")
    if isinstance(size, bool) or not isinstance(size, int | np.integer) or size < 1 or size % 2 == 0:
        raise InputError(f"size: expected an odd positive window side, got {size!r}")
    if isinstance(min_count, bool) or not isinstance(min_count, int | np.integer) or min_count < 1:
        raise InputError(f"min_count: expected a positive integer, got {min_count!r}")
    out = np.empty(x.shape, np.float32)
    _median_kernel(np.ascontiguousarray(x), int(size) // 2, int(min_count), out)
    return out
