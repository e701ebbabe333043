"""Depth buffers and visibility (core/ortho/zbuffer.py, surface.py) against references and scene truth."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.geometry.camera import Camera, pixel_to_ray
from truortho.core.grid import RasterGrid
from truortho.core.ortho.surface import MeshSurface
from truortho.core.ortho.zbuffer import (
    Triangles,
    depth_tolerance,
    dsm_triangles,
    face_normals,
    frame_cells,
    height_noise,
    near_step_mask,
    point_visibility,
    render_depth,
    view_cells_into,
)
from truortho.core.synthetic import SceneConfig, make_scene
from truortho.core.synthetic.cameras import look_at_rotation


def test_dsm_triangles_tops_up_walls_face_the_lower_cell():
    rng = np.random.default_rng(3)
    h = np.round(rng.uniform(0, 3, (6, 7)), 1)
    h[2, 3] = np.nan
    tris = dsm_triangles(h, 10.0, 20.0, 0.5)
    n = face_normals(tris)
    v = tris.vertices[tris.faces]
    tops = n[:, 2] > 0.99
    assert tops.sum() == 2 * np.isfinite(h).sum()
    walls = ~tops
    assert np.allclose(n[walls, 2], 0.0)
    # every wall: the cell on its normal side is the lower one
    centre = v[walls].mean(axis=1)
    for c, nn in zip(centre, n[walls], strict=True):

        def cell_h(p):
            col = int(np.floor((p[0] - 10.0) / 0.5))
            row = int(np.floor((20.0 - p[1]) / 0.5))
            return h[row, col]

        front = cell_h(c[:2] + 0.25 * nn[:2])
        back = cell_h(c[:2] - 0.25 * nn[:2])
        assert front < back
    # walls span exactly the steps between valid neighbours
    steps = np.isfinite(h[:, 1:] - h[:, :-1]) & (h[:, 1:] != h[:, :-1])
    steps_v = np.isfinite(h[1:] - h[:-1]) & (h[1:] != h[:-1])
    assert walls.sum() == 2 * (steps.sum() + steps_v.sum())


def _reference_depth(tris, R, C, cam):
    """Per-pixel ray casting against every triangle (Moller-Trumbore), camera-z depth."""
    W, H = cam.width, cam.height
    xs, ys = np.meshgrid(np.arange(W, dtype=float), np.arange(H, dtype=float))
    _, d = pixel_to_ray(np.column_stack([xs.ravel(), ys.ravel()]), R, C, cam)
    v = tris.vertices[tris.faces]
    e1, e2 = v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]
    best = np.full(len(d), np.inf)
    for k in range(len(v)):
        p = np.cross(d, e2[k])
        det = p @ e1[k]
        ok = np.abs(det) > 1e-12
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        s = C - v[k, 0]
        u = (p @ s) * inv
        q = np.cross(s, e1[k])
        w = (d @ q) * inv
        t = (e2[k] @ q) * inv
        hit = ok & (u >= 0) & (w >= 0) & (u + w <= 1) & (t > 0)
        z = t * (d @ R[2])
        best = np.where(hit & (z < best), z, best)
    return best.reshape(H, W)


def test_render_depth_matches_ray_casting_reference():
    rng = np.random.default_rng(7)
    cam = Camera(48, 36, 40.0, 40.0, 23.3, 17.6)
    C = np.array([1.0, -2.0, 20.0])
    R = look_at_rotation(C, (0.0, 0.0, 0.0))
    centres = rng.uniform(-6, 6, (25, 3)) * [1, 1, 0.5]
    verts = (centres[:, None, :] + rng.normal(0, 2.0, (25, 3, 3))).reshape(-1, 3)
    tris = Triangles(verts, np.arange(75).reshape(25, 3), oriented=False)
    zb = render_depth(tris, R, C, cam, (0, 0, cam.width, cam.height))
    ref = _reference_depth(tris, R, C, cam)
    both = np.isfinite(ref) & np.isfinite(zb)
    # coverage identical up to pixels exactly on triangle edges
    assert (np.isfinite(ref) != np.isfinite(zb)).sum() <= 0.01 * ref.size
    assert both.sum() > 0.1 * ref.size
    assert np.allclose(zb[both], ref[both], rtol=1e-5, atol=1e-4)


@pytest.fixture(scope="module")
def scene():
    return make_scene(SceneConfig(image_size=(240, 180), focal_px=300.0, n_buildings=5, seed=4))


def test_visibility_agrees_with_scene_truth_and_culling_changes_nothing(scene):
    res = 0.2
    h, gt = scene.dsm(res)
    o = scene.offset
    tris = dsm_triangles(h - o[2], gt[0] - o[0], gt[3] - o[1], res)
    rows, cols = h.shape
    X = gt[0] + (np.arange(cols) + 0.5) * res
    Y = gt[3] - (np.arange(rows) + 0.5) * res
    XX, YY = np.meshgrid(X, Y)
    P = np.column_stack([XX.ravel(), YY.ravel(), h.ravel()]).astype(float)
    cam = scene.camera
    win = (0, 0, cam.width, cam.height)
    for i in (0, scene.n_nadir - 1, scene.n_nadir, len(scene.images) - 1):  # nadir and oblique
        im = scene.orientation.images[i]
        zb = render_depth(tris, im.R, im.C, cam, win)
        zb_all = render_depth(tris, im.R, im.C, cam, win, cull=False)
        fin = np.isfinite(zb)
        assert np.array_equal(fin, np.isfinite(zb_all)) and np.allclose(zb[fin], zb_all[fin], atol=1e-4)
        d = P - o - im.C
        dist = np.linalg.norm(d, axis=1)
        cz = -d[:, 2] / dist
        tanv = np.sqrt(1 - cz**2) / cz
        tol = depth_tolerance(res, dist / cam.fx / cz, tanv)
        vis, _, _, _ = point_visibility(P - o, tol, im.R, im.C, cam, zb, win)
        truth, _, _ = scene.visibility(P, i, tol=0.02)
        seen = vis | truth
        agree = (vis == truth)[seen].mean()
        assert agree > 0.99, (i, agree)
        # depth of the buffer equals the rendered truth depth where both see the DSM interior
        dm = scene.depth_map(i)
        ok = np.isfinite(dm) & fin
        assert np.median(np.abs(zb[ok] - dm[ok])) < 0.02


def test_mesh_top_raster_reproduces_the_dsm(scene):
    res = 0.5
    h, gt = scene.dsm(res)
    tris = dsm_triangles(h, gt[0], gt[3], res)  # world coordinates
    mesh = MeshSurface(tris.vertices, tris.faces, scene.config.crs)
    grid = RasterGrid.from_geotransform(gt, *h.shape, scene.config.crs)
    top = mesh.heights_on(grid)
    assert np.allclose(top, h, atol=1e-4)
    sub = mesh.heights_on(grid.window(10, 20, 30, 40))
    assert np.allclose(sub, h[10:40, 20:60], atol=1e-4)


def test_walls_only_buffer_decides_like_the_full_surface(scene):
    """Walls (+ tops next to them), double-sided, give the visibility of the full DSM surface."""
    from truortho.core.ortho.surface import PlanTransform, grid_triangles

    res = 0.2
    h, gt = scene.dsm(res)
    o = scene.offset
    grid = RasterGrid.from_geotransform(gt, *h.shape, scene.config.crs)
    full = dsm_triangles(h - o[2], gt[0] - o[0], gt[3] - o[1], res)
    walls = grid_triangles(grid, h.astype(float), None, PlanTransform(None, None, o), 0.05)
    assert not walls.oriented and len(walls) < 0.3 * len(full)
    X, Y = grid.centres()
    P = np.column_stack([X.ravel(), Y.ravel(), h.ravel()]) - o
    cam = scene.camera
    win = (0, 0, cam.width, cam.height)
    for i in (0, len(scene.images) - 1):
        im = scene.orientation.images[i]
        d = P - im.C
        dist = np.linalg.norm(d, axis=1)
        cz = -d[:, 2] / dist
        tol = depth_tolerance(res, dist / cam.fx / cz, np.sqrt(1 - cz**2) / cz)
        v_full = point_visibility(P, tol, im.R, im.C, cam, render_depth(full, im.R, im.C, cam, win), win)[0]
        v_walls = point_visibility(P, tol, im.R, im.C, cam, render_depth(walls, im.R, im.C, cam, win), win)[0]
        seen = v_full | v_walls
        assert (v_full == v_walls)[seen].mean() > 0.995


@pytest.mark.parametrize("k1", [0.0, -0.25, 0.15])
def test_grouped_faces_skip_nothing_the_window_needs(scene, k1):
    """Faces grouped by plan blocks give the same buffer as one group, over sub-windows of the image,
    also with strong lens distortion (a block's projected corners do not bound its edges)."""
    from dataclasses import replace

    res = 0.2
    h, gt = scene.dsm(res)
    o = scene.offset
    grouped = dsm_triangles(h - o[2], gt[0] - o[0], gt[3] - o[1], res, block=8)
    assert len(grouped.groups) - 1 == -(-h.shape[0] // 8) * -(-h.shape[1] // 8)
    one = Triangles(grouped.vertices, grouped.faces, grouped.oriented)
    assert len(one.groups) == 2
    cam = replace(scene.camera, k1=k1) if k1 else scene.camera
    for i in (0, len(scene.images) - 1):
        im = scene.orientation.images[i]
        corner = (cam.width - 40, cam.height - 30, 40, 30)
        for win in ((0, 0, cam.width, cam.height), (30, 20, 60, 50), corner):
            a = render_depth(grouped, im.R, im.C, cam, win)
            b = render_depth(one, im.R, im.C, cam, win)
            assert np.isfinite(a).any()
            np.testing.assert_array_equal(a, b)
    # groups re-sorted by any key render the same too (a mesh's faces are grouped like this)
    key = np.random.default_rng(0).integers(0, 50, len(one))
    im = scene.orientation.images[0]
    win = (0, 0, cam.width, cam.height)
    np.testing.assert_array_equal(
        render_depth(one.grouped(key), im.R, im.C, cam, win), render_depth(one, im.R, im.C, cam, win)
    )


def test_concurrent_resampled_dsm_reads_equal_serial_reads(tmp_path):
    """Tile threads resample the DSM concurrently (output cells differ from the DSM's); rasterio then
    now and then warns 'no geotransform', but every read must give the serial result."""
    import threading
    import warnings

    from truortho.core.ortho.surface import DsmSurface
    from truortho.core.rasterio_io import write_raster

    src = RasterGrid(500000.0, 5600030.0, 1.0 / 3.0, 90, 120, "EPSG:32632")
    X, Y = src.centres()
    h = (10.0 + 0.05 * (X - 500000.0) + 3.0 * ((X - 500020.0) ** 2 + (Y - 5600015.0) ** 2 < 25.0)).astype(
        np.float32
    )
    write_raster(tmp_path / "dsm.tif", h, src, nodata=-9999.0)
    surf = DsmSurface(tmp_path / "dsm.tif")
    out = RasterGrid(500000.0, 5600030.0, 0.25, 120, 160, "EPSG:32632")
    windows = [out.window(-20 + 13 * i, -20 + 17 * i, 80 + i, 90 + i) for i in range(6)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = [surf.heights_on(w) for w in windows]
        bad = []

        def run(i):
            for _ in range(10):
                if not np.array_equal(surf.heights_on(windows[i]), ref[i], equal_nan=True):
                    bad.append(i)

        threads = [threading.Thread(target=run, args=(i,)) for i in range(len(windows))]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    assert all(np.isfinite(r).any() for r in ref)
    assert not bad


def _near_field_views(h, res, C, near_field: bool, noise=None, reach=None):
    """``view_cells_into`` of every cell of the grid ``h`` (cell (0, 0) centred at (res/2, -res/2))
    for a camera at ``C`` looking at the grid's centre, against an empty depth buffer (the depth
    test passes everywhere): only the near-field test can hide a cell."""
    rows, cols = h.shape
    r, c = np.mgrid[0:rows, 0:cols]
    P = np.column_stack([((c + 0.5) * res).ravel(), (-(r + 0.5) * res).ravel(), h.ravel()]).astype(float)
    centre = P.mean(axis=0)
    R = look_at_rotation(C, centre)
    cam = Camera(400, 400, 2000.0, 2000.0, 199.5, 199.5)
    fc = frame_cells(P, R, C, cam, np.radians(45.0))
    assert len(fc) == rows * cols  # every cell is in the frame
    n = len(P)
    gx, gy = np.gradient(h, res)
    normals = np.column_stack([-gx.ravel(), gy.ravel(), np.ones(n)])
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    out = (np.zeros(n, bool), np.zeros(n, bool), np.zeros((n, 2), np.float32), np.zeros(n, np.float32))
    zbuf = np.full((400, 400), np.inf, np.float32)
    nf = None
    if near_field:
        nf = (h.ravel().astype(float), near_step_mask(h, res).ravel(), cols)
        if reach is not None:
            step = near_step_mask(h, res, reach=reach.reshape(h.shape)).ravel()
            nf = (h.ravel().astype(float), step, cols, reach)
    view_cells_into(fc, P, P, np.zeros(n, bool), normals, R, C, cam, zbuf, (0, 0, 400, 400), 1.0, res, out,
                    near_field=nf, noise=noise)  # fmt: skip
    return out[0].reshape(rows, cols)


def test_near_field_hides_a_cell_seen_past_a_building_corner():
    """A ground cell diagonally next to a building's corner, its ray to the camera passing the
    corner: the depth buffer's pixels and tolerance cannot resolve the occluder there, the raster
    geometry does (the cell was textured with the building's colour on battery scene 4)."""
    res = 0.1
    h = np.zeros((11, 11))
    h[6:, 6:] = 17.0  # a building to the south-east of cell (5, 5)
    az = np.radians(-40.0)  # towards the east-south-east, past the building's north-west corner
    C = np.array([0.55 + 38.7 * np.cos(az), -0.55 + 38.7 * np.sin(az), 116.0])
    without = _near_field_views(h, res, C, near_field=False)
    with_nf = _near_field_views(h, res, C, near_field=True)
    assert without[5, 5] and without[4, 4]
    # hidden: the ray enters the building cell (6, 6) about 0.2 m (resp. 0.7 m) above the ground
    assert not with_nf[5, 5] and not with_nf[4, 4]
    # cells whose ray passes no higher cell, and the roof, are untouched
    assert with_nf[0:3, 0:3].all() and with_nf[0:3, 8:].all()
    assert (with_nf[6:, 6:] == without[6:, 6:]).all() and with_nf[7:, 7:].all()
    assert (with_nf <= without).all()  # the test only ever hides


def test_near_field_reaches_as_far_as_the_noise_tolerance():
    """A ground cell 3 cells behind a 10 m building, its ray to an oblique camera through the
    building (entering its wall 0.29 m up, 0.38 m along the ray): where the depth buffer misses the
    building's far side, the noise term of the tolerance (0.3 m here) lets the depth test pass, and
    a near field of two cells does not reach the wall; one that reaches as far as the tolerance
    (:func:`near_field_reach`) hides the cell (seed 7's scene 3 textured such cells with the roof)."""
    from truortho.core.ortho.views import NEAR_FIELD_MAX, near_field_reach

    res = 0.1
    h = np.zeros((7, 14))
    h[:, 10:] = 10.0  # a building east of the wall at x = 1.0
    theta = np.radians(41.0)
    C = np.array([0.75 + 120.0 * np.sin(theta), -0.35, 120.0 * np.cos(theta)])  # east, 41 degrees off nadir
    n = h.size
    noise = np.full(n, 2.0 * np.sqrt(2.0) * 0.08)  # sigma 8 cm, as next to that wall
    reach = near_field_reach(noise, np.radians(45.0), res)
    assert (reach == 2 + 4).all() and (near_field_reach(np.zeros(3), np.radians(45.0), res) == 2).all()
    assert (near_field_reach(np.full(3, 100.0), np.radians(45.0), res) == NEAR_FIELD_MAX).all()
    for bad in ((noise, 2.0, res), (noise, np.radians(45.0), 0.0), (-noise, np.radians(45.0), res)):
        with pytest.raises(Exception, match="near_field_reach"):
            near_field_reach(*bad)
    short = _near_field_views(h, res, C, near_field=True, noise=noise)
    far = _near_field_views(h, res, C, near_field=True, noise=noise, reach=reach)
    assert short[3, 7] and not far[3, 7]  # the cell 3 cells west of the wall
    assert not far[:, 4:10].any()  # every ground cell within the reach: hidden (the empty buffer alone
    assert short[:, :8].all()  # shows all of them; the short near field hides the two next to the wall)
    assert far[:, 11:].all() and (far[:, 10:] == short[:, 10:]).all()  # the roof is left alone
    assert (far <= short).all()


def test_ray_through_the_raster_hides_cells_next_to_an_occlusion_edge():
    """Ground cells west of a 12 m building, seen from a camera 6 degrees east of nadir: the ray of a
    cell less than 12 m x tan(6 deg) = 1.26 m from the wall enters it, 2-12 cells away, beyond the
    near field. When the depth buffer around the cell's pixel holds a nearer surface (here a
    checkerboard of near pixels: every cell that passes the depth test is next to an edge), its
    own pixel decides only to a pixel; the cell's ray through the raster decides exactly (seed 13's
    scenes 2 and 8 and seed 7's scene 8 textured such cells, on a diagonal roof outline and under a
    grazing ray, from a photo that does not see them)."""
    res = 0.1
    rows, cols = 12, 40
    h = np.zeros((rows, cols))
    h[:, 30:] = 12.0  # the wall at x = 3.0 m
    r, c = np.mgrid[0:rows, 0:cols]
    P = np.column_stack([((c + 0.5) * res).ravel(), (-(r + 0.5) * res).ravel(), h.ravel()]).astype(float)
    theta = np.radians(6.0)
    C = np.array([2.0 + 150.0 * np.sin(theta), -0.6, 150.0 * np.cos(theta)])
    R = look_at_rotation(C, np.array([2.0, -0.6, 0.0]))
    cam = Camera(400, 400, 2000.0, 2000.0, 199.5, 199.5)
    fc = frame_cells(P, R, C, cam, np.radians(45.0))
    assert len(fc) == rows * cols
    n = len(P)
    normals = np.tile([0.0, 0.0, 1.0], (n, 1))
    zbuf = np.where((np.add.outer(np.arange(400), np.arange(400)) % 2) == 0, np.inf, 0.01).astype(np.float32)
    nf = (h.ravel(), near_step_mask(h, res).ravel(), cols)
    margin = 3
    region = np.pad(h, margin, constant_values=np.nan)
    inv = np.linalg.inv(np.array([[res, 0.0], [0.0, -res]]))

    def views(ray_grid):
        out = (np.zeros(n, bool), np.zeros(n, bool), np.zeros((n, 2), np.float32), np.zeros(n, np.float32))
        view_cells_into(fc, P, P, np.zeros(n, bool), normals, R, C, cam, zbuf, (0, 0, 400, 400), 1.0, res,
                        out, near_field=nf, ray_grid=ray_grid)  # fmt: skip
        return out[0].reshape(rows, cols), out[1].reshape(rows, cols)

    seen, edge = views(None)
    seen_ray, _ = views((region, margin, inv, 12.0))
    ground = seen & (c < 30)
    assert ground.sum() > 100 and edge[ground].all()  # every cell the buffer passes is next to an edge
    d = 3.0 - (c + 0.5) * res  # from the cell's centre to the wall
    behind = ground & (d > 2.5 * res) & (d < 1.15)  # beyond the near field's two cells, ray into the wall
    assert behind.sum() > 30 and not seen_ray[behind].any()
    assert (seen_ray == seen)[~(c < 30) | (d > 1.4)].all()  # the roof and the cells farther away: unchanged
    assert (seen_ray <= seen).all()
    with pytest.raises(Exception, match="ray_grid"):
        views((region[3:-3], margin, inv, 12.0))  # the heights must hold the points' grid


def test_near_field_keeps_a_steep_slope_facing_the_camera():
    """A plane rising towards the camera at 50 degrees (a step of 1.2 cells per cell, so every
    cell is tested) is seen everywhere: the flat cell tops' stairs do not hide each other."""
    res = 0.1
    r, c = np.mgrid[0:11, 0:11]
    h = 1.2 * res * c  # rises to the east, where the camera is
    C = np.array([0.55 + 38.0, -0.55, 116.0])
    assert near_step_mask(h, res)[:, :-2].all()
    assert _near_field_views(h, res, C, near_field=True).all()


def test_near_step_mask_marks_cells_within_two_cells_of_a_higher_one():
    h = np.zeros((9, 9))
    h[4, 4] = 1.0
    h[0, 8] = np.nan
    m = near_step_mask(h, 0.25, step_cells=2.0)
    expect = np.zeros((9, 9), bool)
    expect[2:7, 2:7] = True
    expect[4, 4] = False
    assert (m == expect).all()
    assert not near_step_mask(h, 0.25, step_cells=4.0).any()
    with pytest.raises(Exception, match="near_step_mask"):
        near_step_mask(np.zeros(5), 0.25)



def test_height_noise_reads_bumps_not_structures():
    rng = np.random.default_rng(11)
    r, c = np.mgrid[0:80, 0:80]
    # white noise: the deviation; correlated bumps (a matched DSM's noise): about their deviation
    assert abs(np.median(height_noise(rng.normal(0.0, 0.3, (200, 200)))) - 0.3) < 0.03
    from scipy.ndimage import gaussian_filter

    bumps = gaussian_filter(rng.normal(0.0, 1.0, (200, 200)), 1.0)
    bumps *= 0.4 / bumps.std()
    assert 0.2 < np.median(height_noise(bumps)) < 0.45
    # planes, straight and diagonal walls, corners, a small building: 0
    shapes = [
        0.3 * c + 0.1 * r,
        np.where(c >= 40, 10.0, 0.0),
        np.where(r + c > 80, 10.0, 0.0),
        np.where((r >= 40) & (c >= 40), 10.0, 0.0),
        np.where((r >= 20) & (r < 28) & (c >= 20) & (c < 28), 3.0, 0.0),
    ]
    for h in shapes:  # (the median surface is extended at the border: the interior is exact)
        assert np.abs(height_noise(h)[10:-10, 10:-10]).max() < 1e-9
    # no data: left out, not read as a step
    h = np.zeros((40, 40))
    h[10:20, 10:20] = np.nan
    assert np.abs(height_noise(h)).max() < 1e-9
    with pytest.raises(Exception, match="height_noise"):
        height_noise(np.zeros(5))


def test_noise_tolerance_lets_a_cell_be_seen_past_bumps_of_the_noise_level():
    """Seen at 45 degrees from the east, a cell 0.75 m west of a 1 m bump (a matched DSM's noise on a
    field) is hidden by the depth test alone and seen with a height tolerance of 2 sqrt(2) x 0.3 m;
    a cell 1.9 m west of a 5 m wall stays hidden with the same tolerance."""
    res = 0.25
    h = np.zeros((3, 16))
    h[0, 8] = 1.0  # bump, 3 cells east of cell (0, 5)
    h[2, 8:10] = 5.0  # wall, 8 cells east of cell (2, 0)
    cols = h.shape[1]
    r, c = np.mgrid[0:3, 0:cols]
    P = np.column_stack([((c + 0.5) * res).ravel(), (-(r + 0.5) * res).ravel(), h.ravel()])
    target = P[1 * cols + 4]
    C = np.array([target[0] + 40.0, target[1], 40.0])  # 45 degrees to the east
    R = look_at_rotation(C, target)
    cam = Camera(800, 800, 2000.0, 2000.0, 399.5, 399.5)
    tris = dsm_triangles(h, 0.0, 0.0, res)
    fc = frame_cells(P, R, C, cam, np.radians(50.0))
    assert len(fc) == len(P)
    win = (0, 0, 800, 800)
    zbuf = render_depth(tris, R, C, cam, win, 1.0)
    n = len(P)
    normals = np.tile([0.0, 0.0, 1.0], (n, 1))

    def usable(noise):
        out = (np.zeros(n, bool), np.zeros(n, bool), np.zeros((n, 2), np.float32), np.zeros(n, np.float32))
        view_cells_into(fc, P, P, np.zeros(n, bool), normals, R, C, cam, zbuf, win, 1.0, res, out,
                        noise=noise)  # fmt: skip
        return out[0].reshape(h.shape)

    strict = usable(None)
    lenient = usable(np.full(n, 2.0 * np.sqrt(2.0) * 0.3))  # 2 sqrt(2) sigma, sigma = 0.3 m
    assert not strict[0, 5] and lenient[0, 5]
    assert not strict[2, 0] and not lenient[2, 0]
    assert (lenient >= strict).all()
    with pytest.raises(Exception, match="noise"):
        usable(np.zeros(3))
