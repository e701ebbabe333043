"""Occlusion-aware refinement of height steps (building outlines) after OSGM's finest level.

Window-based matching *fattens* objects: a cell next to a wall, whose window straddles the
outline, often takes the height of the side with the stronger texture, and SGM spreads it. On
the synthetic battery (``bench/acceptance.py``) 30-45 % of the ground cells within three cells of
a wall came out at roof height, and a true orthophoto made on such a DSM paints roof colours on
the ground beside every building.

This pass decides, for every cell near a height step, between the two sides of the step with
evidence that no straddling window mixes:

1. **Zone**: cells within ``reach`` cells of a step (the 3 x 3 height range exceeds ``step``).
2. **Candidates**: in the cell's ``(2 w + 1)^2`` neighbourhood the heights split at the middle of
   their range into a low and a high side; each side's candidate is the median of its cells.
3. **Visibility**: the views are the tile's own (:func:`~.matching.choose_images`). Every image
   whose frame covers the tile was tried: +1.0 point of edge cells within 3 GSD on one battery
   scene, but on boruszyn it raised a 15 m patch of grass beside trees to the trees' height
   (session 13). A view takes part for a candidate only if its ray from the cell at that height
   passes above the current surface (a march over the tile's heights), so the views that cannot
   see the foot of a wall do not vote for it; this is the occlusion-aware cost, made against the
   current surface estimate. The march starts :data:`NEAR` cells away from the cell: the cells
   nearer than that are the ones this pass re-decides, and a fattened band of roof height in front
   of the foot of a wall would otherwise hide the ground from the very views that show it is
   ground (on battery scene 10, 52-97 % of the edge cells left on the wrong side had no pair of
   views on their true side). A real wall within those cells is still seen by the march further
   on, where the roof behind it stands above the ray; a view it hides nearer than that is outvoted
   by the next step.
4. **Photo-consistency**: a 3 x 3 cell patch on the candidate's plane, sampled in every visible
   view (bilinear, the matching band, normalised per view to zero mean and unit spread over the
   tile: gain and offset invariant), compared between every pair of visible views (mean
   absolute difference); the cost is the mean of the better half of those pair differences
   (at least one): one view that sees something else (an occluder the surface does not hold
   yet) spoils ``V - 1`` of the ``V (V - 1) / 2`` pairs, the worse half from four views on.
   A 3 x 3 patch straddles an outline by at most one cell.
5. **Decision**: a cell moves to the other side when that side's cost is below :data:`RATIO`
   times its own side's, with at least one pair of views on each side; it then takes the other
   side's median height. Passes repeat on the updated surface until no cell switches (at most
   :data:`PASSES`): the outer cells of a fattened band switch first, and their views then clear
   the next ones (on battery windows 2 -> 6 passes: edge cells within 3 GSD 83.7 -> 85.1 %,
   66.9 -> 68.2 %, 60.8 -> 63.3 % with 4). After the first pass only the cells within
   :data:`AFFECT` of a cell that switched are decided again.
   A switch needs evidence: not when the cell's own side is judged on a single pair of views
   (:data:`WEAK_PAIRS`) and the other side's match is one of flat patches, whose spread within each
   view (:func:`_spread`) is below the differences between the views. On ground in a uniform field
   beside a building, the views that see the ground are few (the fattened band hides it from the
   others) and the roof's height, in the air above the field, agrees in every view that sees the
   field below it; traced (a scratch script) on a cell of the realistic battery (seed 5150 scene 6,
   truth -0.03 m), matching gave -0.13 m and a switch took it to the roof's 11.65 m (ground cost
   0.33 on one pair, roof 0.19 on three, patch spreads 0.03). ``bench/osgm_battery.py --realistic``
   on seed 5150: flat3 up on 10 of 12 scenes (scene 6 96.7 -> 97.5 %, meeting the goal; scene 8
   98.4 -> 99.1 %), edge3 up on 8 by up to 0.5 points and down on 2 by at most 0.3; on the sharp
   scenes of seeds 5150 and 808, flat3 up by up to 0.45 points, edge3 within +0.2 / -1.1 (808 scene
   0 86.0 -> 84.9 %, 5150 scene 8 88.4 -> 87.5 %). Either test alone cost more: a single pair alone
   blocked, edge3 down by up to 1.9 points (808 scene 0); flat patches alone, by up to 5.4
   (realistic scene 7). On seed 4242, not used for the choice: flat3 up on 8 of 12 scenes (up to
   0.21 points), edge3 +0.8 / -0.9 (scene 8 87.6 -> 88.4 %, scene 3 86.6 -> 85.8 %).
6. **Holes and wall heights**: a cell near a step that matching left empty (no clear minimum, or
   one rejected by the uniqueness or median test: typically the foot of a wall or the rim of a
   roof), takes the more photo-consistent side, with at least one pair of views on each side, and
   a confidence of ``1 - own cost / other cost`` (the DSM filter's ``min_confidence`` drops
   near-ties). So does a height farther than ``step`` from both sides (half way up the wall, which
   a 2.5-D surface never holds: SGM's smoothing or a coarse level's band put it there) when that
   side is also more photo-consistent than the height itself (a tree crown's flank keeps its
   height). Taking the wall heights raised the edge cells within 3 GSD by 0.6 to 1.4 points on
   the battery's nadir scenes 0, 2, 4, 8 and 10, with the non-edge cells unchanged. Any hole
   counts as a wrong height, and the filter would fill it by interpolation across the step, half
   way up the wall; on the battery (scenes 0, 2, 3, 4, 8, 9) the share of edge cells within 3 GSD
   rose by 1.0 to 4.4 points (scene 2: 72.7 -> 77.1 %), completeness by 0.2 to 0.3.
7. **Heights off their side**: a cell that keeps its side but lies more than ``tol`` from that
   side's candidate (SGM's smoothing leaves a ramp at the foot of a wall and bends a roof's rim
   down) takes the candidate when the photos agree with it better than with its own height: the
   side is not in question there, only which of two heights on it fits the photos, so no
   :data:`RATIO` margin applies. A pitched roof's slope keeps its own height, which fits better
   than the window's median. On the battery (``bench/osgm_battery.py``, seeds 2026 and 7), edge
   cells within 3 GSD rose on 15 of 24 scenes (+0.01 to +0.59 points; seed 2026 scene 0 79.8 ->
   80.4 %, scene 9 77.5 -> 78.0 %), fell on 4 (-0.01 to -0.06), the rest unchanged; non-edge cells
   and NMAD unchanged to 0.05 points. A ratio of 0.6 as for a switch gained about half as much.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..jit import njit, pjit, prange
from ..sgm.selection import _finite_window

#: Cells near a step considered (beyond the matching window's radius, SGM spreads fattening).
REACH = 4
#: A cell switches side only if the other side is this much more photo-consistent (a ratio of
#: the better-half costs, which read lower and with less spread than a mean over all pairs).
RATIO = 0.6
#: Pairs of views below which a side's cost is weak evidence against it: with two views, one that
#: sees something else (an unmodelled occluder, a field's stalks from another side) makes the only
#: pair inconsistent; the better-half cost tolerates such a view from three views on.
WEAK_PAIRS = 3
#: The visibility march ignores the cells this near (in cells) to the one decided: the band that
#: the refinement re-decides (:data:`REACH`).
NEAR = REACH
#: Passes at most (until no cell switches): a fattened band is peeled from its outer edge, one or
#: two cells a pass, because its inner cells are hidden from the views by the band itself.
PASSES = REACH + 2
#: Cells around a switched cell that the next pass re-decides: those whose side heights read it
#: (``REACH + 2``) and, as far again, those whose rays to the views pass over it next to the wall.
AFFECT = 2 * (REACH + 2)


#: Cells per parallel chunk of :func:`_side_heights`.
_SIDE_CHUNK = 256


@pjit
def _side_heights(z, rows_idx, cols_idx, w, lo_out, hi_out, mid_out):
    """Median of the low and of the high heights in the window of each listed cell."""
    n_cells = rows_idx.shape[0]
    for ch in prange((n_cells + _SIDE_CHUNK - 1) // _SIDE_CHUNK):
        buf = np.empty((2 * w + 1) ** 2)
        for n in range(ch * _SIDE_CHUNK, min(n_cells, (ch + 1) * _SIDE_CHUNK)):
            k = _finite_window(z, rows_idx[n], cols_idx[n], w, buf)
            if k == 0:
                lo_out[n] = np.nan
                hi_out[n] = np.nan
                mid_out[n] = np.nan
                continue
            vals = buf[:k]
            zmin = vals.min()
            zmax = vals.max()
            mid = 0.5 * (zmin + zmax)
            lo_out[n] = np.median(vals[vals <= mid])
            hi_out[n] = np.median(vals[vals > mid]) if zmax > mid else zmax
            mid_out[n] = mid


#: Cells per side of the blocks whose highest height lets the visibility march skip a block the ray
#: passes above (a max-mipmap level): the march then costs per block, not per half cell.
BLOCK = 8


def block_max(z: np.ndarray, block: int = BLOCK) -> np.ndarray:
    """Highest height of every ``block`` x ``block`` block of ``z`` (NaN ignored; -inf: none)."""
    z = np.asarray(z, np.float64)
    if z.ndim != 2:
        raise InputError(f"block_max: expected 2-D heights, got shape {z.shape}")
    if isinstance(block, bool) or not isinstance(block, int | np.integer) or block < 1:
        raise InputError(f"block_max: block must be an integer >= 1, got {block!r}")
    rows, cols = z.shape
    br, bc = -(-rows // block), -(-cols // block)
    pad = np.full((br * block, bc * block), -np.inf)
    pad[:rows, :cols] = np.where(np.isfinite(z), z, -np.inf)
    return pad.reshape(br, block, bc, block).max(axis=(1, 3))


@pjit
def _ray_free(z, bmax, block, rows_idx, cols_idx, zc, x0, y0, res, C, tol, ztop, near, out):
    """Whether the ray from each cell centre at height ``zc[n]`` to ``C`` stays above ``z`` in the tile.

    The march tests the cells under the points ``t = res (1 + k / 2)`` along the ray (``t``: the
    horizontal distance), and skips the points of a block of ``bmax`` (:func:`block_max` of ``z``
    with ``block``) that the ray enters above its highest height plus ``tol``: the ray rises, so
    none of them can hide it (the result is the same as without skipping).
    ``ztop``: the tile's highest height; a ray above ``ztop + tol`` is free (the march stops there).
    ``near``: the march tests the heights from this distance (in cells, horizontally) on.
    """
    rows, cols = z.shape
    side = block * res
    for n in prange(rows_idx.shape[0]):
        r = rows_idx[n]
        c = cols_idx[n]
        x = x0 + (c + 0.5) * res
        y = y0 - (r + 0.5) * res
        h = zc[n]
        dx = C[0] - x
        dy = C[1] - y
        dzr = C[2] - h
        dist = np.sqrt(dx * dx + dy * dy)
        free = True
        if dzr > 0.0 and dist > 1e-9 and h == h:
            ux = dx / dist
            uy = dy / dist
            slope = dzr / dist
            k = 0
            while True:
                t = res * (1.0 + 0.5 * k)
                px = x + ux * t
                py = y + uy * t
                cc = int(np.floor((px - x0) / res))
                rr = int(np.floor((y0 - py) / res))
                if rr < 0 or rr >= rows or cc < 0 or cc >= cols:
                    break
                ray = h + slope * t
                if ray > ztop + tol:
                    break
                bi = rr // block
                bj = cc // block
                if ray > bmax[bi, bj] + tol:
                    # above the whole block from here on: resume at the first point past its exit
                    tx = np.inf
                    if ux > 0.0:
                        tx = (x0 + (bj + 1) * side - x) / ux
                    elif ux < 0.0:
                        tx = (x0 + bj * side - x) / ux
                    ty = np.inf
                    if uy < 0.0:
                        ty = (y0 - (bi + 1) * side - y) / uy
                    elif uy > 0.0:
                        ty = (y0 - bi * side - y) / uy
                    t_exit = min(tx, ty) - 1e-6 * res
                    k_exit = int(np.ceil((t_exit / res - 1.0) * 2.0))
                    k = max(k + 1, k_exit)
                    continue
                if t > near * res and not (rr == r and cc == c):
                    zz = z[rr, cc]
                    if zz == zz and zz > ray + tol:
                        free = False
                        break
                k += 1
        out[n] = free


def _samples(img, P: np.ndarray) -> np.ndarray:
    """Bilinear samples of a tile image's band at local points P (N, 3); NaN outside."""
    import cv2

    from .views import project

    v = img.view
    uv = project(P, v.R, v.C, v.camera, v.r2max)
    s = 0.5**img.level
    mu = ((uv[:, 0] + 0.5) * s - 0.5 - img.origin[0]).astype(np.float32)
    mv = ((uv[:, 1] + 0.5) * s - 0.5 - img.origin[1]).astype(np.float32)
    mu[~np.isfinite(mu)] = -1e6
    mv[~np.isfinite(mv)] = -1e6
    n = len(mu)
    width = 1024  # remap maps are images: at most 32767 on a side
    rows = -(-n // width)
    maps = [np.full(rows * width, -1e6, np.float32) for _ in range(2)]
    maps[0][:n], maps[1][:n] = mu, mv
    out = cv2.remap(  # type: ignore[call-overload]
        img.window, maps[0].reshape(rows, width), maps[1].reshape(rows, width), cv2.INTER_LINEAR,
        borderMode=cv2.BORDER_CONSTANT, borderValue=np.nan,
    )  # fmt: skip
    return out.ravel()[:n]


@njit
def _mean32(a, b):
    """Mean absolute difference of two float32 patches, summed as numpy sums a contiguous row
    (pairwise, eight accumulators from eight values on), so that it equals
    ``np.abs(a - b).mean()`` to the bit."""
    t = a.shape[0]
    if t < 8:
        res = np.float32(0.0)
        for q in range(t):
            res += np.float32(abs(a[q] - b[q]))
    else:
        r0 = np.float32(abs(a[0] - b[0]))
        r1 = np.float32(abs(a[1] - b[1]))
        r2 = np.float32(abs(a[2] - b[2]))
        r3 = np.float32(abs(a[3] - b[3]))
        r4 = np.float32(abs(a[4] - b[4]))
        r5 = np.float32(abs(a[5] - b[5]))
        r6 = np.float32(abs(a[6] - b[6]))
        r7 = np.float32(abs(a[7] - b[7]))
        i = 8
        while i < t - t % 8:
            r0 += np.float32(abs(a[i] - b[i]))
            r1 += np.float32(abs(a[i + 1] - b[i + 1]))
            r2 += np.float32(abs(a[i + 2] - b[i + 2]))
            r3 += np.float32(abs(a[i + 3] - b[i + 3]))
            r4 += np.float32(abs(a[i + 4] - b[i + 4]))
            r5 += np.float32(abs(a[i + 5] - b[i + 5]))
            r6 += np.float32(abs(a[i + 6] - b[i + 6]))
            r7 += np.float32(abs(a[i + 7] - b[i + 7]))
            i += 8
        res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
        while i < t:
            res += np.float32(abs(a[i] - b[i]))
            i += 1
    return res / np.float32(t)


#: Cells per parallel chunk of :func:`_consistency_kernel`.
_PAIR_CHUNK = 256


@pjit
def _consistency_kernel(samples, visible, cost, pairs):
    V, N, T = samples.shape
    for ch in prange((N + _PAIR_CHUNK - 1) // _PAIR_CHUNK):
        buf = np.empty(max(1, V * (V - 1) // 2), np.float64)
        ok = np.empty(V, np.bool_)
        for n in range(ch * _PAIR_CHUNK, min(N, (ch + 1) * _PAIR_CHUNK)):
            for i in range(V):
                good = visible[i, n]
                for q in range(T):
                    if not np.isfinite(samples[i, n, q]):
                        good = False
                ok[i] = good
            m = 0
            for i in range(V):
                if not ok[i]:
                    continue
                for j in range(i + 1, V):
                    if ok[j]:
                        buf[m] = np.float64(_mean32(samples[i, n], samples[j, n]))
                        m += 1
            pairs[n] = m
            if m == 0:
                cost[n] = np.inf
                continue
            buf[:m].sort()
            k = max((m + 1) // 2, 1)
            acc = 0.0
            for q in range(k):
                acc += buf[q]
            cost[n] = acc / k


def _consistency(samples: np.ndarray, visible: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean of the better half of the pair differences: ``(cost (N,), pairs (N,))``.

    ``samples`` (V, N, 9) normalised patch samples, ``visible`` (V, N). A pair's difference is the
    mean absolute difference of its two patches; over ``p`` pairs with both views visible, the
    cost is the mean of the ``max(1, ceil(p / 2))`` smallest (inf without a pair).
    """
    samples = np.ascontiguousarray(samples, np.float32)
    visible = np.ascontiguousarray(visible, np.bool_)
    if samples.ndim != 3 or visible.shape != samples.shape[:2]:
        raise InputError(
            "_consistency: expected samples (V, N, T) and visible (V, N), "
            f"got {samples.shape}, {visible.shape}"
        )
    N = samples.shape[1]
    cost = np.empty(N, np.float64)
    pairs = np.zeros(N, np.int64)
    _consistency_kernel(samples, visible, cost, pairs)
    return cost, pairs


def _between(zc, cand, step):
    """Heights farther than ``step`` from both sides ``cand`` (2, n): on the wall between them."""
    return np.isfinite(zc) & (np.abs(zc - cand[0]) > step) & (np.abs(zc - cand[1]) > step)


#: Cells whose samples in every view :func:`_cost_at` holds at once: its memory is ``views x CHUNK
#: x 37`` bytes (a 3 x 3 float32 patch and a visibility flag per view and cell), whatever the tile
#: and however many of its cells lie near a step.
CHUNK = 16384


def _cost_at(zz, bmax, ri, ci, heights, images, stats, x0, y0, res, tol, ztop, spread=None):
    """Photo-consistency ``(cost, pairs)`` of the listed cells at ``heights`` (steps 3 and 4);
    ``bmax``: :func:`block_max` of the heights ``zz``. In chunks of :data:`CHUNK` cells.
    ``spread``: optional (n,) array, filled with :func:`_spread` of the patches."""
    n = ri.size
    cost = np.empty(n, np.float64)
    pairs = np.zeros(n, np.int64)
    heights = np.asarray(heights, np.float64)
    for s in range(0, n, CHUNK):
        e = min(n, s + CHUNK)
        cost[s:e], pairs[s:e] = _cost_chunk(
            zz, bmax, ri[s:e], ci[s:e], heights[s:e], images, stats, x0, y0, res, tol, ztop,
            None if spread is None else spread[s:e],
        )  # fmt: skip
    return cost, pairs


def _spread(samples: np.ndarray, visible: np.ndarray) -> np.ndarray:
    """Mean over the visible views of the standard deviation of each view's patch: ``(N,)``, NaN
    without a view. ``samples`` (V, N, T) normalised patch samples, ``visible`` (V, N); a view with a
    missing sample does not count (as in :func:`_consistency`). Against the pair differences of
    :func:`_consistency` it says whether a match is one of texture (the patches vary more within
    themselves than between the views) or of flat patches, which agree at any height."""
    samples = np.asarray(samples, np.float32)
    ok = np.asarray(visible, bool) & np.isfinite(samples).all(axis=2)
    sd = np.where(ok, np.nan_to_num(samples).std(axis=2), 0.0)
    count = ok.sum(axis=0)
    return np.where(count > 0, sd.sum(axis=0) / np.maximum(count, 1), np.nan)


def _cost_chunk(zz, bmax, ri, ci, heights, images, stats, x0, y0, res, tol, ztop, spread=None):
    n = ri.size
    dr, dc = np.meshgrid(np.arange(-1, 2), np.arange(-1, 2), indexing="ij")
    dr, dc = dr.ravel(), dc.ravel()
    X = x0 + (ci + 0.5) * res
    Y = y0 - (ri + 0.5) * res
    samples = np.full((len(images), n, 9), np.nan, np.float32)
    visible = np.zeros((len(images), n), bool)
    P = np.column_stack([
        (X[:, None] + dc[None, :] * res).ravel(),
        (Y[:, None] - dr[None, :] * res).ravel(),
        np.repeat(heights, 9),
    ])  # fmt: skip
    h = np.ascontiguousarray(heights, np.float64)
    for v, img in enumerate(images):
        free = np.empty(n, np.bool_)
        C = np.asarray(img.view.C, np.float64)
        _ray_free(zz, bmax, BLOCK, ri, ci, h, x0, y0, res, C, tol, ztop, float(NEAR), free)
        visible[v] = free
        mu, sd = stats[v]
        samples[v] = ((_samples(img, P) - mu) / sd).reshape(n, 9)
    if spread is not None:
        spread[:] = _spread(samples, visible)
    return _consistency(samples, visible)


def _decide(zc, cand, mid, cost, npairs, step, own=None, spread=None):
    """The side decision of cells with heights ``zc`` (n,): ``(side, switch, fill)``.

    ``cand`` (2, n) low and high side heights, ``mid`` (n,) the split between them, ``cost`` and
    ``npairs`` (2, n) each side's photo-consistency and pairs of views, ``own`` (n,) the cost at
    the cell's own height where it lies between the sides (:func:`_between`; inf: none),
    ``spread`` (2, n) each side's :func:`_spread` (None: every match counts as one of texture).
    ``side`` is the cell's side (0 low, 1 high); ``switch``: a height that moves to the other side
    (its cost below :data:`RATIO` times its own, on evidence: not when its own side has fewer than
    :data:`WEAK_PAIRS` pairs of views and the other side's patches vary less within themselves than
    between the views, a match of flat patches); ``fill``: a cell that takes ``side`` outright, the
    more photo-consistent side: a hole, or a height between the sides (the wall itself, which a
    2.5-D surface never holds: matching put it between ground and roof) when a side is more
    photo-consistent than that height (a tree crown's flank keeps its height). Both need a side
    decidable: the sides more than ``step`` apart, a pair of views on each.
    """
    lo, hi = cand
    n = zc.shape[0]
    own = np.full(n, np.inf) if own is None else np.asarray(own, np.float64)
    hole = ~np.isfinite(zc)
    between = _between(zc, cand, step) & (np.minimum(cost[0], cost[1]) < own)
    outright = hole | between
    decidable = np.isfinite(mid) & (hi - lo > step) & (npairs[0] >= 1) & (npairs[1] >= 1)
    side = np.where(outright, (cost[1] < cost[0]).astype(np.int64), (zc > mid).astype(np.int64))
    idx = np.arange(n)
    own_c, oth_c = cost[side, idx], cost[1 - side, idx]
    fill = outright & decidable
    switch = ~outright & decidable & (oth_c < RATIO * own_c)
    if spread is not None:
        flat = ~(np.asarray(spread, np.float64)[1 - side, idx] > oth_c)
        switch &= ~((npairs[side, idx] < WEAK_PAIRS) & flat)
    return side, switch, fill


def _off_side(zc, side_height, side_pairs, decided, between, tol):
    """Cells that keep their side but lie more than ``tol`` from its candidate ``side_height`` (step 7):
    a height, not a hole, neither ``decided`` (switched or filled this pass) nor ``between`` the
    sides, with at least one pair of views on its side."""
    zc = np.asarray(zc, np.float64)
    sh = np.asarray(side_height, np.float64)
    ok = np.isfinite(zc) & np.isfinite(sh) & ~np.asarray(decided, bool) & ~np.asarray(between, bool)
    return ok & (np.abs(np.where(ok, zc - sh, 0.0)) > tol) & (np.asarray(side_pairs) >= 1)


def refine_edges(
    z: np.ndarray, images, x0: float, y0: float, res: float, step: float, tol: float, cancelled=None,
    conf: np.ndarray | None = None,
) -> np.ndarray:
    """Heights ``z`` (rows, cols, local, NaN = none) with the sides of height steps re-decided.

    ``images``: the tile's :class:`~.matching.TileImage` list (their matching band windows);
    ``step``: the smallest height difference (m) that is a step; ``tol``: height tolerance of the
    visibility march (m); ``cancelled``: optional callable, checked between passes (a cancelled
    refinement returns the heights of the passes done); ``conf``: optional confidence (rows, cols),
    written in place at the cells filled (holes, wall heights). See the module docstring.
    """
    from scipy.ndimage import binary_dilation, maximum_filter, minimum_filter

    z = np.asarray(z, np.float32).copy()
    if z.ndim != 2:
        raise InputError(f"refine_edges: expected 2-D heights, got shape {z.shape}")
    for name, v, ok, want in (("res", res, res > 0, "> 0"), ("step", step, step > 0, "> 0"),
                              ("tol", tol, tol >= 0, ">= 0")):  # fmt: skip
        if not (np.isfinite(v) and ok):
            raise InputError(f"refine_edges: {name} must be a finite number {want}, got {v!r}")
    if conf is not None and np.shape(conf) != z.shape:
        raise InputError(f"refine_edges: conf must have the heights' shape {z.shape}, got {np.shape(conf)}")
    if len(images) < 2 or not np.isfinite(z).any():
        return z
    stats = []
    for img in images:
        w = img.window[np.isfinite(img.window)]
        mu = float(w.mean()) if w.size else 0.0
        sd = float(w.std()) if w.size else 1.0
        stats.append((mu, sd if sd > 1e-6 else 1.0))
    active = None  # after the first pass: the cells a switch of the last pass can change
    for _ in range(PASSES):
        if cancelled is not None and cancelled():
            break
        finite = np.isfinite(z)
        zmax = maximum_filter(np.where(finite, z, -np.inf), 3)
        zmin = minimum_filter(np.where(finite, z, np.inf), 3)
        steps = finite & ((zmax - zmin) > step)
        zone = binary_dilation(steps, iterations=REACH)  # with the holes near a step
        if active is not None:
            zone &= active
        ri, ci = np.nonzero(zone)
        if ri.size == 0:
            break
        ri = ri.astype(np.int64)
        ci = ci.astype(np.int64)
        n = ri.size
        lo = np.empty(n)
        hi = np.empty(n)
        mid = np.empty(n)
        zz = z.astype(np.float64)
        ztop = float(np.nanmax(zz))
        bmax = block_max(zz)
        _side_heights(zz, ri, ci, REACH + 2, lo, hi, mid)
        cand = np.stack([lo, hi])  # (2, n)
        cost = np.full((2, n), np.inf)
        npairs = np.zeros((2, n), np.int64)
        spread = np.full((2, n), np.nan)
        for k in range(2):
            cost[k], npairs[k] = _cost_at(
                zz, bmax, ri, ci, cand[k], images, stats, x0, y0, res, tol, ztop, spread[k]
            )
        zc = z[ri, ci].astype(np.float64)
        # a height between the sides competes with them at its own height
        own = np.full(n, np.inf)
        between = _between(zc, cand, step)
        if between.any():
            b = np.nonzero(between)[0]
            own[b] = _cost_at(zz, bmax, ri[b], ci[b], zc[b], images, stats, x0, y0, res, tol, ztop)[0]
        idx = np.arange(n)
        side, switch, fill = _decide(zc, cand, mid, cost, npairs, step, own, spread)
        # a height off its own side's candidate takes it if the photos prefer it (step 7)
        settle = _off_side(zc, cand[side, idx], npairs[side, idx], switch | fill, between, tol)
        if settle.any():
            b = np.nonzero(settle)[0]
            here = _cost_at(zz, bmax, ri[b], ci[b], zc[b], images, stats, x0, y0, res, tol, ztop)[0]
            settle[b] = cost[side[b], b] < here
        if not (switch.any() or fill.any() or settle.any()):
            break
        z[ri[switch], ci[switch]] = cand[1 - side[switch], idx[switch]].astype(np.float32)
        z[ri[fill], ci[fill]] = cand[side[fill], idx[fill]].astype(np.float32)
        z[ri[settle], ci[settle]] = cand[side[settle], idx[settle]].astype(np.float32)
        if conf is not None and fill.any():
            # the margin between the sides: 0 for a tie, 1 for a side no worse than perfect
            taken, left = cost[side[fill], idx[fill]], cost[1 - side[fill], idx[fill]]
            margin = 1.0 - taken / np.maximum(left, 1e-12)
            conf[ri[fill], ci[fill]] = np.clip(margin, 0.0, 1.0).astype(conf.dtype)
        moved = np.zeros(z.shape, np.uint8)
        moved[ri[switch], ci[switch]] = 1
        moved[ri[fill], ci[fill]] = 1
        moved[ri[settle], ci[settle]] = 1
        active = maximum_filter(moved, 2 * AFFECT + 1).astype(bool)
    return z
