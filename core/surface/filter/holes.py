"""Hole filling: hole widths, the narrow gaps of wide holes, harmonic (Laplace) interpolation."""

from __future__ import annotations

import math

import numpy as np


def _closed_gaps(valid: np.ndarray, radius: float, open_sides=(True, True, True, True)) -> np.ndarray:
    """Nodata cells of the narrow gaps and bays of ``valid``: gaps narrower than ``2 radius`` cells,
    enclosed or open onto a wider hole.

    The wide part of the nodata is its opening by a disc of ``radius`` cells (every disc that fits
    in it; by Euclidean distance transforms); the rest of the nodata is the closing of the valid
    cells. Its components reaching farther than ``radius / 2`` from the wide part are the gaps; the
    others are the rounded-off corners of the wide part (at most ``(sqrt 2 - 1) radius`` deep at a
    right angle), which stay nodata. ``open_sides`` (top, bottom, left, right): the sides of the
    window that are the raster's border; beyond them counts as nodata (nothing is closed towards
    the outside of the raster). Other sides are window cuts: the caller's margin (at least
    ``2 radius``) makes the closing exact on the core.
    """
    from scipy import ndimage

    pad = int(math.ceil(2.0 * radius)) + 2
    widths = [(pad if open_sides[0] else 0, pad if open_sides[1] else 0),
              (pad if open_sides[2] else 0, pad if open_sides[3] else 0)]  # fmt: skip
    v = np.pad(valid, widths, constant_values=False)
    if not v.any() or v.all():
        return np.zeros(valid.shape, bool)
    dilated = ndimage.distance_transform_edt(~v) <= radius
    if dilated.all():
        return np.zeros(valid.shape, bool)
    wide = ndimage.distance_transform_edt(dilated) <= radius  # the opening of the nodata
    rest = ~v & ~wide
    labels, k = ndimage.label(rest, structure=_FOUR)
    if k:
        depth = ndimage.distance_transform_edt(~wide)
        deep = np.asarray(ndimage.maximum(depth, labels, np.arange(1, k + 1))) > 0.5 * radius + 1.0
        rest = np.concatenate([[False], deep])[labels]
    r0, c0 = widths[0][0], widths[1][0]
    return rest[r0 : r0 + valid.shape[0], c0 : c0 + valid.shape[1]]


def _hole_width(nodata: np.ndarray) -> np.ndarray:
    """Per nodata cell: 2 x its distance (cells) to the nearest valid cell - 1; 0 on valid cells."""
    from scipy import ndimage

    if not nodata.any():
        return np.zeros(nodata.shape)
    if nodata.all():
        return np.full(nodata.shape, np.inf)
    d = ndimage.distance_transform_edt(nodata)
    return np.where(nodata, 2.0 * d - 1.0, 0.0)


_FOUR = np.array([[0, 1, 0], [1, 1, 1], [0, 1, 0]], bool)


def _fill_holes(
    z: np.ndarray, fill: np.ndarray, step: float, reach, hint: np.ndarray | None = None
) -> np.ndarray:
    """Harmonic interpolation of the cells ``fill`` (nodata) from their valid 4-neighbours.

    Each connected component is solved with Dirichlet values on its valid boundary
    cells, except boundary cells more than ``step`` above the lowest boundary cell of
    the same hole within ``reach`` cells (an int, or a per-cell int array whose maximum over
    a hole is that hole's reach) (the top of a wall beside an occlusion hole;
    a local rule, so that tiles agree): those are zero-flux, as the window border is. A component
    left without any Dirichlet cell keeps all its boundary cells.

    ``hint`` (the raw heights, NaN where the input had no data): a cell removed by the
    filter whose raw height is closer to the interpolation from the dropped (upper)
    boundary cells than to the lower one takes the upper one (a blurred roof edge next to
    an occlusion hole belongs to the roof). Returns a filled copy.
    """
    from scipy import ndimage

    out = z.copy()
    if not fill.any():
        return out
    labels, _ = ndimage.label(fill, structure=_FOUR)
    valid = np.isfinite(z)
    allowed = valid.copy()
    upper = np.zeros(z.shape, bool)
    nr, nc = z.shape
    for k, box in enumerate(ndimage.find_objects(labels), start=1):
        if box is None:
            continue
        r0, r1 = max(box[0].start - 1, 0), min(box[0].stop + 1, nr)
        c0, c1 = max(box[1].start - 1, 0), min(box[1].stop + 1, nc)
        sub = labels[r0:r1, c0:c1] == k
        zs = z[r0:r1, c0:c1]
        ring = ndimage.binary_dilation(sub, structure=_FOUR) & np.isfinite(zs)
        hz = zs[ring]
        if hz.size == 0 or hz.max() - hz.min() <= step:
            continue
        # the lowest boundary cell of this hole within `reach` of each boundary cell
        rk = int(reach[r0:r1, c0:c1][sub].max()) if isinstance(reach, np.ndarray) else int(reach)
        low = ndimage.minimum_filter(np.where(ring, zs, np.inf), size=2 * max(rk, 1) + 1, mode="nearest")
        drop = ring & (zs > low + step)
        allowed[r0:r1, c0:c1] &= ~drop
        upper[r0:r1, c0:c1] |= drop
    # components whose whole boundary was dropped use every valid neighbour
    ring_all = ndimage.binary_dilation(fill, structure=_FOUR) & valid
    touched = ndimage.binary_dilation(ring_all & allowed, structure=_FOUR) & fill
    has_d = np.zeros(int(labels.max()) + 1, bool)
    has_d[np.unique(labels[touched])] = True
    orphan = fill & ~has_d[labels]
    if orphan.any():
        allowed |= ndimage.binary_dilation(orphan, structure=_FOUR) & valid
    low_fill = _solve(out, fill, labels, valid, allowed)
    if hint is None or not upper.any():
        return low_fill
    hinted = fill & np.isfinite(hint)
    if not hinted.any():
        return low_fill
    high_fill = _solve(z.copy(), fill, labels, valid, upper)
    take = hinted & np.isfinite(high_fill) & (np.abs(hint - high_fill) < np.abs(hint - low_fill))
    low_fill[take] = high_fill[take]
    return low_fill


def _solve(out, fill, labels, valid, allowed):
    """Sparse Laplace solve, in place in ``out``, of the ``fill`` cells with Dirichlet values
    on their ``allowed`` valid 4-neighbours (zero flux elsewhere); components without any
    Dirichlet neighbour stay NaN."""
    from scipy import sparse
    from scipy.sparse.linalg import spsolve

    z = out
    nr, nc = z.shape
    fr, fc = np.nonzero(fill)
    m = len(fr)
    idx = -np.ones(z.shape, np.int64)
    idx[fr, fc] = np.arange(m)
    n = int(labels.max())
    lab_f = labels[fr, fc]
    diag = np.zeros(m)
    rhs = np.zeros(m)
    cnt_d = np.zeros(m)
    rows_l = []
    cols_l = []
    for dr, dc in ((0, 1), (0, -1), (1, 0), (-1, 0)):
        nr_ = fr + dr
        nc_ = fc + dc
        inside = (nr_ >= 0) & (nr_ < nr) & (nc_ >= 0) & (nc_ < nc)
        a = np.nonzero(inside)[0]
        nbr_r, nbr_c = nr_[a], nc_[a]
        j = idx[nbr_r, nbr_c]
        unk = j >= 0
        rows_l.append(a[unk])
        cols_l.append(j[unk])
        diag[a[unk]] += 1.0
        dirich = (~unk) & allowed[nbr_r, nbr_c] & valid[nbr_r, nbr_c]
        diag[a[dirich]] += 1.0
        cnt_d[a[dirich]] += 1.0
        np.add.at(rhs, a[dirich], z[nbr_r[dirich], nbr_c[dirich]])
    has_d = np.zeros(n + 1, bool)
    np.logical_or.at(has_d, lab_f, cnt_d > 0)
    solvable = has_d[lab_f]
    lap = sparse.csr_matrix(
        (-np.ones(sum(len(r) for r in rows_l)), (np.concatenate(rows_l), np.concatenate(cols_l))),
        shape=(m, m),
    )
    A = (lap + sparse.diags(diag)).tocsr()
    keep = np.nonzero(solvable & (diag > 0))[0]
    if len(keep):
        A = A[keep][:, keep]
        x = spsolve(A.tocsc(), rhs[keep])
        out[fr[keep], fc[keep]] = x
    return out
