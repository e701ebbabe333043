"""The sparse plane sweep of OSGM gives the dense multi-image cost on the cells that search a plane.

The images are aligned so that every cell centre projects onto a pixel centre (nadir cameras,
focal length = depth / cell size, camera positions on whole cells): bilinear resampling then reads
pixel values exactly in both paths (the sweep's own sampler and ``cv2.remap``), so the two costs
must agree to the last unit wherever the plane is searched, at image borders, NaN holes, grid
borders and scattered search masks alike.
"""

from __future__ import annotations

import numpy as np
import pytest

cv2 = pytest.importorskip("cv2")

from truortho.core.geometry.camera import Camera  # noqa: E402
from truortho.core.osgm.matching import TileImage, View, _remap  # noqa: E402
from truortho.core.osgm.sweep import PlaneSweep, gradient_scales  # noqa: E402
from truortho.core.sgm import COST_MAX, multi_image_cost  # noqa: E402

RES = 0.5
H = 100.0
Z = 10.0


def _images(rng, n, rows, cols):
    R = np.diag([1.0, -1.0, -1.0])  # x = east, y = south, z = down
    out = []
    for i in range(n):
        w, h = cols + 12, rows + 10
        cam = Camera(w, h, (H - Z) / RES, (H - Z) / RES, w / 2 - 0.5, h / 2 - 0.5)
        # camera centres on whole cells: cell centres fall on pixel centres
        cx, cy = rng.integers(-8, 9) * RES, rng.integers(-8, 9) * RES
        C = np.array([cols * RES / 2 + cx, -rows * RES / 2 + cy, H])
        img = cv2.GaussianBlur(rng.uniform(0, 255, (h, w)).astype(np.float32), (0, 0), 1.2)
        img[rng.random((h, w)) < 0.01] = np.nan  # scattered holes
        img[:2, :] = np.nan  # the padding of the pyramid windows
        img[-2:, :] = np.nan
        img[:, :2] = np.nan
        img[:, -2:] = np.nan
        level = 0
        origin = (0, 0)
        if i == n - 1:  # a window that does not start at the image's corner
            origin = (3, 2)
            img = np.ascontiguousarray(img[origin[1] :, origin[0] :])
        v = View(i, R, C, cam, 4.0, 1.0)
        out.append(TileImage(v, level, origin, img, 0.0))
    return out


@pytest.mark.parametrize(("n", "block"), [(2, 64), (3, 64), (6, 64), (6, 7), (3, 16)])
def test_sweep_equals_dense_cost_on_searched_cells(n, block, monkeypatch):
    """Also in blocks smaller than the tile (7: many blocks, margins of every kind)."""
    from truortho.core.osgm import sweep as sw

    monkeypatch.setattr(sw, "BLOCK", block)
    rng = np.random.default_rng(n)
    rows, cols = 57, 71
    images = _images(rng, n, rows, cols)
    x0, y0 = 0.0, 0.0
    scales = gradient_scales(images, _remap, x0, y0, RES, rows, cols, Z)
    assert scales.shape == (n, 2) and np.all(scales > 0)
    slices = np.stack([_remap(im, x0, y0, RES, rows, cols, Z) for im in images])
    dense, _ = multi_image_cost(slices, 2, measure="gradient", scales=scales)
    # scattered search: blobs, thin lines, the grid border
    need = rng.random((rows, cols)) < 0.05
    need[20, 5:60] = True
    need[:, 0] = True
    need[30:40, 50:60] = True
    nd, a = 4, 7
    z0 = np.full((rows, cols), a - 2, np.int32)
    cost = np.full((rows, cols, nd), 9999, np.uint16)
    sweep = PlaneSweep(images, rows, cols, 2, 0.5, scales)
    sweep.plane(x0, y0, RES, Z, need, a, z0, cost)
    got = cost[:, :, 2]
    assert np.array_equal(got[need], dense[need])
    assert np.all(got[~need] == 9999)  # nothing written where the plane is not searched
    assert np.all(cost[:, :, [0, 1, 3]] == 9999)
    # the comparison means something: costs vary and some cells lack views
    assert np.unique(dense[need]).size > 20
    assert (dense[need] < COST_MAX).mean() > 0.5


def test_sweep_reuses_its_work_arrays_between_planes():
    """A plane's stale samples must never leak into the next plane's cells."""
    rng = np.random.default_rng(11)
    rows, cols = 40, 44
    images = _images(rng, 3, rows, cols)
    scales = gradient_scales(images, _remap, 0.0, 0.0, RES, rows, cols, Z)
    sweep = PlaneSweep(images, rows, cols, 2, 0.5, scales)
    z0 = np.zeros((rows, cols), np.int32)
    cost = np.full((rows, cols, 2), 9999, np.uint16)
    full = np.ones((rows, cols), bool)
    sweep.plane(0.0, 0.0, RES, Z + 3.3, full, 0, z0, cost)  # fills the work arrays everywhere
    need = np.zeros((rows, cols), bool)
    need[10:13, 10:30] = True
    sweep.plane(0.0, 0.0, RES, Z, need, 1, z0, cost)
    slices = np.stack([_remap(im, 0.0, 0.0, RES, rows, cols, Z) for im in images])
    dense, _ = multi_image_cost(slices, 2, measure="gradient", scales=scales)
    assert np.array_equal(cost[:, :, 1][need], dense[need])


def test_given_scales_are_checked():
    s = np.zeros((3, 10, 10), np.float32)
    from truortho.core.errors import InputError

    with pytest.raises(InputError, match="scales"):
        multi_image_cost(s, 2, measure="gradient", scales=np.ones((2, 2)))
    with pytest.raises(InputError, match="scales"):
        multi_image_cost(s, 2, measure="gradient", scales=np.full((3, 2), np.nan))


def test_given_scales_equal_to_the_slices_own_give_the_same_cost():
    from truortho.core.osgm.sweep import slice_scales

    rng = np.random.default_rng(5)
    s = cv2.GaussianBlur(rng.uniform(0, 255, (40, 50)).astype(np.float32), (0, 0), 1.0)
    noise = rng.normal(0, 2, (4, *s.shape)).astype(np.float32)
    slices = np.stack([np.roll(s, k, axis=1) + noise[k] for k in range(4)])
    slices[1, :, :5] = np.nan
    own, _ = multi_image_cost(slices, 2, measure="gradient")
    sc = np.array([slice_scales(x) for x in slices])
    given, _ = multi_image_cost(slices, 2, measure="gradient", scales=sc)
    assert np.array_equal(own, given)
    doubled, _ = multi_image_cost(slices, 2, measure="gradient", scales=2 * sc)
    assert not np.array_equal(own, doubled)


def test_sweep_kernels_without_the_jit():
    """The sweep's kernels as plain Python on a tiny tile (coverage honest), against the JIT result."""
    from truortho.core.osgm import sweep as sw

    rng = np.random.default_rng(3)
    rows, cols = 9, 10
    images = _images(rng, 3, rows, cols)
    scales = gradient_scales(images, _remap, 0.0, 0.0, RES, rows, cols, Z)
    need = np.zeros((rows, cols), bool)
    need[2:6, 3:8] = True
    need[8, 0] = True
    z0 = np.zeros((rows, cols), np.int32)
    want = np.full((rows, cols, 1), 9999, np.uint16)
    PlaneSweep(images, rows, cols, 1, 0.5, scales).plane(0.0, 0.0, RES, Z, need, 0, z0, want)
    p = PlaneSweep(images, rows, cols, 1, 0.5, scales)
    need8 = need.astype(np.uint8)
    box = np.array(sw._box.py_func(need8, 2), np.int64)
    sw._dilate.py_func(need8, 2, box, p.tmp, p.samp)
    sw._dilate.py_func(need8, 1, box, p.tmp, p.win)
    got = np.full((rows, cols, 1), 9999, np.uint16)
    k = p.pack
    sw._sample_phase.py_func(
        k.buf,
        k.off,
        k.hh,
        k.ww,
        k.R,
        k.C,
        k.P,
        k.r2max,
        k.scale,
        k.shift,
        k.frame,
        0.0,
        0.0,
        RES,
        Z,
        p.samp,
        box,
        p.s,
    )
    sw._gradient_phase.py_func(p.s, p.samp, p.win, box, p.inv, p.qx, p.qy, p.vv)
    blocks = sw._blocks.py_func(need8, box, 4)
    assert len(blocks) > 2
    oi, oj = np.empty(len(p.pi), np.int64), np.empty(len(p.pi), np.int64)
    for blk in blocks:
        t0, t1 = max(0, blk[0] - 1), min(rows, blk[1] + 1)
        e0, e1 = max(0, blk[2] - 1), min(cols, blk[3] + 1)
        m = sw._block_pairs.py_func(
            p.vv, p.win, t0, t1, e0, e1, p.pi, p.pj, oi, oj, np.empty((4, 3), np.int64)
        )
        tp = np.empty((t1 - t0, e1 - e0, m), p.unit.dtype)
        sw._block_terms.py_func(p.qx, p.qy, p.vv, p.win, t0, t1, e0, e1, oi[:m], oj[:m], p.unit[0], tp)
        work = sw._work_arrays.py_func(e1 - e0, m, len(images), p.unit)
        sw._block_sums.py_func(
            tp, p.unit, p.sh, p.vv, need8, p.win, blk, t0, e0, 1, 0.5, 0, oi[:m], oj[:m], 0, z0, got, work,
            p.no_occ, p.no_hid,
        )  # fmt: skip
    assert np.array_equal(got, want)
    assert np.all(got[need] < 9999) and np.all(got[~need] == 9999)


def test_plane_checks_its_arrays():
    from truortho.core.errors import InputError

    rng = np.random.default_rng(4)
    images = _images(rng, 2, 10, 12)
    p = PlaneSweep(images, 10, 12, 2, 0.5, np.ones((2, 2)))
    need = np.ones((10, 12), bool)
    z0 = np.zeros((10, 12), np.int32)
    cost = np.zeros((10, 12, 2), np.uint16)
    with pytest.raises(InputError, match="need and z0"):
        p.plane(0.0, 0.0, RES, Z, need[:5], 0, z0, cost)
    with pytest.raises(InputError, match="int32"):
        p.plane(0.0, 0.0, RES, Z, need, 0, z0.astype(np.int64), cost)
    with pytest.raises(InputError, match="uint16"):
        p.plane(0.0, 0.0, RES, Z, need, 0, z0, cost.astype(np.int32))


def test_smallest_mean_equals_the_quickselect_mean_to_the_bit():
    """The window cost's mean of the best pairs (bisection) against sgm.cost._combine (quickselect):
    the same float64 on random pair contributions, with ties, zeros, saturated ones and invalid pairs."""
    from truortho.core.osgm.sweep import _smallest_mean
    from truortho.core.sgm.cost import _combine

    rng = np.random.default_rng(11)
    checked = 0
    for trial in range(3000):
        nt = int(rng.integers(1, 130))
        w = int(rng.choice([9, 25, 49, 121]))  # window cells (radius 1, 2, 3, 5)
        hd = rng.integers(0, 4 * 127 * w, nt)
        if trial % 3 == 0:  # ties: few distinct window sums, saturation and zeros
            hd = rng.choice([0, 1, 7, 127 * w, 2 * 127 * w, 4 * 127 * w], nt)
        hm = rng.integers(w // 2, w + 1, nt)
        x = np.minimum(1.0, hd * (1.0 / 254.0) / hm).astype(np.float32)
        valid = rng.random(nt) < 0.8
        if not valid.any():
            continue
        m = int(valid.sum())
        kb = int(rng.integers(1, m + 1))
        col = np.where(valid, x, np.float32(np.nan)).astype(np.float32)
        want = _combine(col, nt, 2, kb, np.empty(nt, np.float32))
        v = np.where(valid, x, np.float32(2.0)).astype(np.float32)
        fn = _smallest_mean.py_func if trial < 100 else _smallest_mean
        got = fn(v, kb) if kb < m else np.sum(x[valid], dtype=np.float64) / m
        assert got == want, (trial, nt, kb, m)
        checked += 1
    assert checked > 2500


def test_pairs_that_share_no_valid_sample_are_skipped_with_the_same_costs(monkeypatch):
    """Views whose footprints on the plane do not meet form pairs that can never be valid: each block
    of the sweep keeps only the pairs meeting in it (a block's far-apart photos in one coarse tile),
    and its costs stay those of every pair (the dense cost) to the bit."""
    from truortho.core.osgm import sweep as sw

    rng = np.random.default_rng(7)
    rows, cols = 200, 40
    images = _images(rng, 5, rows, cols)
    for im, (a, b) in zip(images, [(0, 80), (0, 80), (120, 200), (120, 200), (0, 200)], strict=True):
        cut = np.full(im.window.shape[0], np.nan, np.float32)
        cut[a + 5 : b + 5] = 0.0  # each photo covers only these rows of the tile (the fifth all)
        im.window[:] = im.window + cut[:, None]
    scales = gradient_scales(images, _remap, 0.0, 0.0, RES, rows, cols, Z)
    need = np.ones((rows, cols), bool)
    z0 = np.zeros((rows, cols), np.int32)
    got = np.full((rows, cols, 1), 9999, np.uint16)
    monkeypatch.setattr(sw, "BLOCK", 30)
    p = PlaneSweep(images, rows, cols, 2, 0.5, scales)
    p.plane(0.0, 0.0, RES, Z, need, 0, z0, got)
    oi, oj = np.empty(len(p.pi), np.int64), np.empty(len(p.pi), np.int64)

    def meeting(r0, r1):
        m = sw._block_pairs(p.vv, p.win, r0, r1, 0, cols, p.pi, p.pj, oi, oj, np.empty((4, 5), np.int64))
        return sorted(zip(oi[:m].tolist(), oj[:m].tolist(), strict=True))

    assert meeting(0, rows) == [(0, 1), (0, 4), (1, 4), (2, 3), (2, 4), (3, 4)]
    assert meeting(0, 60) == [(0, 1), (0, 4), (1, 4)]  # the top blocks
    assert meeting(140, rows) == [(2, 3), (2, 4), (3, 4)]
    slices = np.stack([_remap(im, 0.0, 0.0, RES, rows, cols, Z) for im in images])
    every, _ = multi_image_cost(slices, 2, measure="gradient", scales=scales)
    assert np.array_equal(got[:, :, 0], every)
    assert (got < COST_MAX).mean() > 0.6  # all but rows 80-120, which only the fifth photo sees


def test_cells_outside_a_frame_are_not_projected_and_the_samples_are_the_same():
    """The sampler skips the cells of a row that cannot fall in a photo's window (bounds on the
    undistorted coordinates widened by the most the distortion can move a point): tilted photos with
    strong radial and tangential distortion, pyramid windows at an offset, a plane reaching beyond
    every frame. The samples, valid and NaN, equal those of projecting every cell."""
    from truortho.core.osgm import sweep as sw

    rng = np.random.default_rng(21)
    rows, cols, res = 90, 120, 1.5  # 135 m x 180 m; a footprint is about 100 m across
    out = []
    for i in range(6):
        w, h = 160, 120
        k1 = 0.25 * (-1) ** i
        cx, cy = w / 2 + rng.normal(0, 4), h / 2 + rng.normal(0, 4)
        cam = Camera(w, h, 150.0, 152.0, cx, cy, k1, -0.08, 0.03, 0.004, -0.006)
        tilt, az = np.radians(rng.uniform(0, 40)), rng.uniform(0, 2 * np.pi)
        down = np.array([np.sin(tilt) * np.cos(az), np.sin(tilt) * np.sin(az), -np.cos(tilt)])
        x = np.cross(down, [0.0, 0.0, 1.0]) if tilt > 1e-6 else np.array([1.0, 0.0, 0.0])
        x /= np.linalg.norm(x)
        R = np.stack([x, np.cross(down, x), down])
        C = np.array([rng.uniform(0, cols * res), -rng.uniform(0, rows * res), H]) - 40.0 * np.array(
            [down[0], down[1], 0.0]
        )
        img = rng.uniform(0, 255, (h // 2 - 7, w // 2 - 9)).astype(np.float32)
        out.append(TileImage(View(i, R, C, cam, 0.5, 1.0), 1, (5, 4), img, 0.0))
    pack = sw.PackedImages(out)
    assert np.all(np.isfinite(pack.frame))
    samp = np.ones((rows, cols), np.uint8)
    box = np.array([0, rows, 0, cols], np.int64)
    got = np.empty((rows, cols, len(out)), np.float32)
    want = np.empty_like(got)
    unbounded = np.tile([-np.inf, np.inf, -np.inf, np.inf], (len(out), 1))
    for z in (-30.0, Z, 60.0):
        args = (
            pack.buf,
            pack.off,
            pack.hh,
            pack.ww,
            pack.R,
            pack.C,
            pack.P,
            pack.r2max,
            pack.scale,
            pack.shift,
        )
        sw._sample_phase(*args, pack.frame, 0.0, 0.0, res, z, samp, box, got)
        sw._sample_phase(*args, unbounded, 0.0, 0.0, res, z, samp, box, want)
        assert np.array_equal(got, want, equal_nan=True)
        valid = np.isfinite(want).mean(axis=(0, 1))
        assert np.all(valid > 0.01) and np.all(valid < 0.8), valid  # every photo sees part of the plane


def test_frame_columns_stay_inside_the_row():
    """The column range of a row that may project into a frame is always inside ``[c0, c1]`` (the
    sampler writes NaN on either side of it): frames left of, right of, across and off the row, rays
    parallel to the plane, and non-finite bounds."""
    from truortho.core.osgm.sweep import _frame_columns

    rng = np.random.default_rng(9)
    c0, c1 = 7, 50
    for trial in range(20000):
        bx, by, bz = rng.normal(0, 50, 3)
        sx, sy, sz = rng.normal(0, 1, 3) * rng.choice([0.0, 1e-9, 1.0, 5.0], 3)
        fb = np.sort(rng.normal(0, 1, 2)).tolist() + np.sort(rng.normal(0, 1, 2)).tolist()
        if trial % 7 == 0:
            fb[rng.integers(0, 4)] = rng.choice([np.inf, -np.inf, np.nan])
        ca, cb = _frame_columns(bx, by, bz, sx, sy, sz, np.array(fb), c0, c1)
        assert c0 <= ca <= cb <= c1, (trial, ca, cb)
        # the range holds every column whose centre projects inside the bounds
        t = np.arange(c0, c1) + 0.5
        zc = bz + t * sz
        with np.errstate(all="ignore"):
            x, y = (bx + t * sx) / zc, (by + t * sy) / zc
            inside = (zc > 0) & (x >= fb[0]) & (x <= fb[1]) & (y >= fb[2]) & (y <= fb[3])
        cols = np.arange(c0, c1)[inside]
        assert np.all((cols >= ca) & (cols < cb)), (trial, ca, cb, cols)


def test_views_hidden_by_the_coarser_surface_leave_fewer_best_pairs():
    """At a cell with hidden views (core/osgm/matching.py hidden_views) the sweep takes the best pairs
    as if only the views left were valid (at least two), every pair still competing: the dense cost
    with that number of best pairs; elsewhere the cost stays the same to the bit."""
    from truortho.core.errors import InputError
    from truortho.core.sgm.cost import _auto_k

    rng = np.random.default_rng(21)
    n, rows, cols = 6, 40, 44
    images = _images(rng, n, rows, cols)
    scales = gradient_scales(images, _remap, 0.0, 0.0, RES, rows, cols, Z)
    slices = np.stack([_remap(im, 0.0, 0.0, RES, rows, cols, Z) for im in images])
    dense, nv = multi_image_cost(slices, 2, measure="gradient", scales=scales)
    occ = np.zeros((rows, cols), np.uint8)
    hid = np.zeros((rows, cols, n), np.uint8)
    occ[5:20, 5:30] = 1
    hid[5:20, 5:30, :2] = 1  # two of six hidden: the best pairs of four views
    occ[25:35, 10:40] = 1
    hid[25:35, 10:40, :5] = 1  # five hidden: the best pair (never fewer than two views)
    need = np.ones((rows, cols), bool)
    z0 = np.zeros((rows, cols), np.int32)
    cost = np.full((rows, cols, 1), 9999, np.uint16)
    sweep = PlaneSweep(images, rows, cols, 2, 0.5, scales)
    sweep.plane(0.0, 0.0, RES, Z, need, 0, z0, cost, hidden=(occ, hid))
    got = cost[:, :, 0]
    full = nv == n
    for sl, k in ((np.s_[5:20, 5:30], _auto_k(4)), (np.s_[25:35, 10:40], _auto_k(2))):
        want, _ = multi_image_cost(slices, 2, measure="gradient", scales=scales, best_k=k)
        cells = np.zeros((rows, cols), bool)
        cells[sl] = True
        cells &= full
        assert cells.sum() > 100
        assert np.array_equal(got[cells], want[cells])
        assert (got[cells] < dense[cells]).mean() > 0.5  # fewer best pairs: lower means
    assert np.array_equal(got[occ == 0], dense[occ == 0])
    # the same plane without hidden views is the dense cost everywhere
    sweep.plane(0.0, 0.0, RES, Z, need, 0, z0, cost)
    assert np.array_equal(cost[:, :, 0], dense)
    with pytest.raises(InputError, match="hidden"):
        sweep.plane(0.0, 0.0, RES, Z, need, 0, z0, cost, hidden=(occ, hid[:, :, :3]))
