"""The visibility check across OSGM's reference systems (core/osgm/fusion.py)."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.errors import InputError
from truortho.core.geometry.camera import Camera
from truortho.core.osgm.fusion import CONFIDENT, MARGIN_CELLS, visible_points

RES = 0.05


def _cameras():
    """Three photos 1.5 m above the ground looking along +Y at a wall 10 m away."""
    cam = Camera(200, 150, 150.0, 150.0, 99.5, 74.5)
    R = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # x right, y down, z along +Y
    return [(R, np.array([x, 0.0, 1.5]), cam) for x in (-2.0, 0.0, 2.0)]


def _plane(y, x0, x1, z0, z1, step=RES):
    x, z = np.meshgrid(np.arange(x0, x1, step), np.arange(z0, z1, step))
    return np.column_stack([x.ravel(), np.full(x.size, y), z.ravel()])


def test_points_behind_a_confident_wall_are_removed():
    wall = _plane(10.0, -6.0, 6.0, 0.0, 5.0)
    on_wall = _plane(10.0, -1.0, 1.0, 1.0, 2.0, 0.1)
    behind = _plane(10.0 + 40 * RES, -1.0, 1.0, 1.0, 2.0, 0.1)  # 2 m behind: hidden from every photo
    slightly = _plane(10.0 + 0.5 * MARGIN_CELLS * RES, -1.0, 1.0, 1.0, 2.0, 0.1)  # within the margin
    front = _plane(8.0, -1.0, 1.0, 1.0, 2.0, 0.1)
    pts = np.vstack([on_wall, behind, slightly, front])
    conf = np.full(len(pts), 0.1)
    keep = visible_points([pts], [conf], [[0, 1, 2]], _cameras(), RES, occluders=wall)[0]
    n = len(on_wall)
    assert keep[:n].all()
    assert not keep[n : 2 * n].any()
    assert keep[2 * n : 3 * n].all()
    assert keep[3 * n :].all()
    # the same wall as the confident points of another system hides them as well
    keep2 = visible_points([pts, wall], [conf, np.full(len(wall), CONFIDENT)], [[0, 1, 2], [0, 1, 2]],
                           _cameras(), RES)  # fmt: skip
    assert np.array_equal(keep2[0], keep) and keep2[1].all()


def test_no_evidence_keeps_points():
    behind = _plane(12.0, -1.0, 1.0, 1.0, 2.0, 0.1)
    conf = np.full(len(behind), 0.1)
    # no occluder at all
    assert visible_points([behind], [conf], [[0, 1, 2]], _cameras(), RES)[0].all()
    # an occluder that is not confident hides nothing
    wall = _plane(10.0, -6.0, 6.0, 0.0, 5.0)
    keep = visible_points([behind, wall], [conf, np.full(len(wall), CONFIDENT / 2)], [[0, 1, 2], [0, 1, 2]],
                          _cameras(), RES)  # fmt: skip
    assert keep[0].all()
    # a point that only one photo of its system frames (the wall hides it there): no pair, no evidence
    keep = visible_points([behind], [conf], [[1]], _cameras(), RES, occluders=wall)
    assert keep[0].all()


def test_one_free_pair_keeps_a_point():
    """A wall hides the points from the left photo only: the other two see them, a pair."""
    behind = _plane(12.0, 2.0, 3.0, 1.0, 2.0, 0.1)
    stub = _plane(6.0, -0.3, 0.7, 0.0, 4.0)  # between the left photo and the points only
    conf = np.full(len(behind), 0.1)
    keep = visible_points([behind], [conf], [[0, 1, 2]], _cameras(), RES, occluders=stub)[0]
    assert keep.all()
    # hidden from the left and the middle photo: one view left, removed
    wide = _plane(6.0, -0.3, 1.7, 0.0, 4.0)
    assert not visible_points([behind], [conf], [[0, 1, 2]], _cameras(), RES, occluders=wide)[0].any()


def test_bad_input():
    with pytest.raises(InputError, match="res"):
        visible_points([np.zeros((1, 3))], [np.zeros(1)], [[0]], _cameras(), 0.0)
    with pytest.raises(InputError, match="confidences"):
        visible_points([np.zeros((2, 3))], [np.zeros(3)], [[0]], _cameras(), RES)
    with pytest.raises(InputError, match="one confidence"):
        visible_points([np.zeros((2, 3))], [], [[0]], _cameras(), RES)
    with pytest.raises(InputError, match=r"shape \(N, 3\)"):
        visible_points([np.zeros((4, 2))], [np.zeros(4)], [[0]], _cameras(), RES)
    with pytest.raises(InputError, match="image indices"):
        visible_points([np.zeros((2, 3))], [np.zeros(2)], [[0, 3]], _cameras(), RES)


def test_cancel():
    from truortho.core.errors import CancelledError
    from truortho.core.progress import CallbackProgress

    seen = []
    pts = _plane(10.0, -1.0, 1.0, 1.0, 2.0, 0.1)
    visible_points([pts], [np.full(len(pts), 0.1)], [[0, 1, 2]], _cameras(), RES,
                   progress=CallbackProgress(lambda f, m=None: seen.append(f)))  # fmt: skip
    assert seen[0] == 0.0 and seen[-1] == 1.0 and len(seen) == 4
    with pytest.raises(CancelledError):
        visible_points([pts], [np.full(len(pts), 0.1)], [[0, 1, 2]], _cameras(), RES,
                       progress=CallbackProgress(is_cancelled=lambda: True))  # fmt: skip


def test_a_dsm_hides_behind_its_walls():
    """A 2.5-D grid has no points on its walls: drawn as cell columns (dsm_triangles) it is opaque,
    as points its walls let the rays through."""
    from truortho.core.ortho.zbuffer import dsm_triangles

    # a DSM 8 m deep from y = 8 to 16, ground at 0 with a 4 m high block from y = 9.5 to 10.5
    x0, y_max = -6.0, 16.0
    rows, cols = int(8.0 / RES), int(12.0 / RES)
    y = y_max - (np.arange(rows) + 0.5) * RES
    h = np.zeros((rows, cols))
    h[(y > 9.5) & (y < 10.5), :] = 4.0
    behind = _plane(12.0, -1.0, 1.0, 0.5, 2.0, 0.1)  # on the far side of the block, below its top
    conf = np.full(len(behind), 0.1)
    tris = dsm_triangles(h, x0, y_max, RES)
    assert not visible_points([behind], [conf], [[0, 1, 2]], _cameras(), RES, surface=tris)[0].any()
    X, Y = np.meshgrid(x0 + (np.arange(cols) + 0.5) * RES, y)
    cells = np.column_stack([X.ravel(), Y.ravel(), h.ravel()])
    assert visible_points([behind], [conf], [[0, 1, 2]], _cameras(), RES, occluders=cells)[0].all()
