"""DSM mesh: acceptance on a flat-roofed synthetic scene (RMSE, vertex budget, vertical walls), the
error bound, tile invariance and topology, colours, files, point-cloud meshes and bad input."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.errors import CRSError, InputError
from truortho.core.grid import RasterGrid
from truortho.core.rasterio_io import write_raster
from truortho.core.surface.mesh import (
    DsmMeshConfig,
    mesh_from_dsm,
    mesh_from_dsm_array,
    mesh_from_point_cloud,
    rasterize_mesh,
)
from truortho.core.surface.meshio import read_mesh, write_mesh

GSD = 0.125


@pytest.fixture(scope="module")
def flat_scene():
    from truortho.core.synthetic import SceneConfig, make_scene
    from truortho.core.synthetic.degrade import flatten_roofs

    scene = make_scene(SceneConfig(image_size=(320, 240), focal_px=250.0, n_oblique=0, seed=1, supersample=1))
    flatten_roofs(scene)
    z, gt = scene.dsm(GSD)
    grid = RasterGrid.from_geotransform(gt, z.shape[0], z.shape[1], scene.config.crs)
    rgb, _ = scene.orthophoto(GSD)
    return scene, z.astype(np.float64), grid, rgb


def _inside_distance(scene, xy_world):
    """Signed-free distance of world plan points to the nearest footprint outline (inside or out)."""
    p = np.asarray(xy_world) - scene.offset[:2]
    d = np.full(len(p), np.inf)
    for b in scene.surface.buildings:
        uv = np.abs(b.to_uv(p))
        a, bb = b.half_size
        out = np.hypot(np.maximum(uv[:, 0] - a, 0), np.maximum(uv[:, 1] - bb, 0))
        inside = np.minimum(a - uv[:, 0], bb - uv[:, 1])
        d = np.minimum(d, np.where((uv[:, 0] <= a) & (uv[:, 1] <= bb), inside, out))
    return d


def _edges(mesh):
    f = mesh.faces
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    return np.unique(e, axis=0, return_counts=True)


def test_flat_roof_acceptance(flat_scene):
    scene, z, grid, rgb = flat_scene
    res = mesh_from_dsm_array(z, grid, DsmMeshConfig(max_error=0.5 * GSD), rgb=rgb)
    mesh = res.mesh
    top = rasterize_mesh(mesh, grid)
    err = top - z
    rmse = float(np.sqrt(np.mean(err**2)))
    ratio = mesh.n_vertices / z.size
    print(
        f"\nmesh of {z.size} cells: {mesh.n_vertices} vertices ({ratio:.4f} per cell), "
        f"{mesh.n_faces} faces ({res.wall_faces} wall), vertical RMSE {rmse:.4f} m = {rmse / GSD:.3f} GSD, "
        f"max {np.abs(err).max():.4f} m; leaves {res.leaves}"
    )
    assert not np.isnan(top).any()
    assert rmse <= 0.5 * GSD and np.abs(err).max() <= 0.5 * GSD + 1e-9
    assert mesh.n_vertices <= z.size / 4
    # walls: vertical triangles exist, the others are never steep
    n = mesh.face_normals()
    vertical = np.abs(n[:, 2]) < 1e-9
    assert vertical.sum() == res.wall_faces > 0
    assert np.abs(n[~vertical, 2]).min() > np.cos(np.radians(80))
    # no sloping triangle spans a height step: inside every non-vertical triangle the mesh follows the
    # analytic surface, except within a cell of a footprint outline (the DSM's own staircase)
    a, b, c = (mesh.vertices[mesh.faces[~vertical, k]] for k in range(3))
    bary = np.array([[1 / 3, 1 / 3], [0.6, 0.2], [0.2, 0.6], [0.2, 0.2], [0.45, 0.45]])
    for u, v in bary:
        p = a + u * (b - a) + v * (c - a)
        near = _inside_distance(scene, p[:, :2]) < 1.5 * GSD
        h = scene.height(p[:, :2])
        assert np.abs(p[~near, 2] - h[~near]).max() < 0.5 * GSD
    # wall area ~ outline x height of the buildings (staircase outlines are longer: factor <= 4/pi)
    wa, wb, wc = (mesh.vertices[mesh.faces[vertical, k]] for k in range(3))
    wall_area = 0.5 * np.linalg.norm(np.cross(wb - wa, wc - wa), axis=1).sum()
    expected = sum(
        4 * (bd.half_size[0] + bd.half_size[1]) * (bd.eave_top - bd.base) for bd in scene.surface.buildings
    )
    assert 0.9 * expected < wall_area < 1.4 * (4 / np.pi) * expected
    # vertex colours come from the orthoimage
    assert mesh.colours is not None and mesh.colours.std() > 10


def test_error_bound_nodata_and_tiles():
    from truortho.core.synthetic import SceneConfig
    from truortho.core.synthetic.degrade import degrade_dsm
    from truortho.core.synthetic.surface import Surface
    from truortho.core.synthetic.truth import dsm as truth_dsm

    cfg = SceneConfig(seed=4, n_buildings=6)
    surf = Surface(cfg)
    z, gt = truth_dsm(surf, 0.25, (-40.0, -30.0, 40.0, 30.0), np.zeros(3))
    d = degrade_dsm(z, 0.25, seed=1)  # noisy, holes, outliers: every kind of cell
    grid = RasterGrid.from_geotransform(gt, z.shape[0], z.shape[1], "EPSG:32632")
    dsm = d.dsm.astype(np.float64)
    tol = 0.08
    r1 = mesh_from_dsm_array(dsm, grid, DsmMeshConfig(max_error=tol, max_leaf=16, tile=64))
    r2 = mesh_from_dsm_array(dsm, grid, DsmMeshConfig(max_error=tol, max_leaf=16, tile=4096))
    top = rasterize_mesh(r1.mesh, grid)
    ok = np.isfinite(dsm)
    assert np.array_equal(np.isfinite(top), ok)  # nodata cells are left out, valid cells covered
    assert np.abs(top[ok] - dsm[ok]).max() <= tol + 1e-9
    # the same mesh whatever the tiles
    assert r1.mesh.n_vertices == r2.mesh.n_vertices and r1.mesh.n_faces == r2.mesh.n_faces
    key = lambda m: np.sort(np.round(m.vertices[m.faces].reshape(-1, 9), 6), axis=0)  # noqa: E731
    np.testing.assert_array_equal(key(r1.mesh), key(r2.mesh))
    # no T-junction or crack: edges used once lie on the raster border or along nodata, or are the
    # vertical edges where three or four walls meet at a corner (collinear, so still closed)
    edges, counts = _edges(r1.mesh)
    assert counts.max() <= 2
    once = edges[counts == 1]
    v = r1.mesh.vertices
    vert_edge = np.linalg.norm(v[once[:, 0], :2] - v[once[:, 1], :2], axis=1) < 1e-9
    once = once[~vert_edge]
    # the cells on either side of a boundary edge: one of them is nodata or outside the grid
    p, q = v[once[:, 0], :2], v[once[:, 1], :2]
    d = q - p
    nrm = np.column_stack([-d[:, 1], d[:, 0]]) / np.linalg.norm(d, axis=1)[:, None]
    mid = (p + q) / 2
    near_nodata = np.zeros(len(once), bool)
    for side in (-0.25, 0.25):
        s_pt = mid + side * grid.res * nrm
        rr, cc = grid.cell_of(s_pt[:, 0], s_pt[:, 1])
        r, c = np.round(rr).astype(int), np.round(cc).astype(int)
        inside = (r >= 0) & (r < grid.rows) & (c >= 0) & (c < grid.cols)
        near_nodata |= ~inside
        near_nodata[inside] |= ~ok[r[inside], c[inside]]
    assert near_nodata.all()


def test_dsm_file_colours_frames_and_bad_input(tmp_path, flat_scene):
    scene, z, grid, rgb = flat_scene
    sub = grid.window(100, 150, 160, 200)
    zs = z[100:260, 150:350].astype(np.float32)
    write_raster(tmp_path / "dsm.tif", zs, sub, nodata=-9999.0)
    write_raster(tmp_path / "ortho.tif", np.moveaxis(rgb[100:260, 150:350], -1, 0), sub)
    res = mesh_from_dsm(tmp_path / "dsm.tif", DsmMeshConfig(tile=64, max_leaf=16), tmp_path / "ortho.tif")
    ref = mesh_from_dsm_array(
        zs.astype(np.float64), sub, DsmMeshConfig(tile=64, max_leaf=16), rgb=rgb[100:260, 150:350]
    )
    np.testing.assert_allclose(res.mesh.vertices, ref.mesh.vertices)
    np.testing.assert_array_equal(res.mesh.faces, ref.mesh.faces)
    assert np.abs(res.mesh.colours.astype(int) - ref.mesh.colours.astype(int)).max() <= 1
    assert res.mesh.crs == "EPSG:32632"
    for name, frame in (("m.ply", "local"), ("m.obj", "crs")):
        p = write_mesh(tmp_path / name, res.mesh, frame=frame)
        back = read_mesh(p)
        np.testing.assert_allclose(back.vertices, res.mesh.vertices, atol=1e-3)
        np.testing.assert_array_equal(back.faces, res.mesh.faces)
    nocrs = RasterGrid(sub.x_min, sub.y_max, sub.res, sub.rows, sub.cols, None)
    write_raster(tmp_path / "nocrs.tif", zs, nocrs, nodata=-9999.0)
    with pytest.raises(CRSError, match="no CRS"):
        mesh_from_dsm(tmp_path / "nocrs.tif")
    write_raster(tmp_path / "empty.tif", np.full(zs.shape, -9999.0, np.float32), sub, nodata=-9999.0)
    with pytest.raises(InputError, match="all nodata"):
        mesh_from_dsm(tmp_path / "empty.tif")
    with pytest.raises(InputError, match="max_leaf"):
        mesh_from_dsm_array(z, grid, DsmMeshConfig(max_leaf=48))
    with pytest.raises(InputError, match="unknown mesh extension"):
        write_mesh(tmp_path / "m.stl", res.mesh)


def test_mesh_from_oblique_point_cloud():
    from truortho.core.surface.pointcloud import PointCloud, ReferenceSystem

    rng = np.random.default_rng(3)
    # a box 10 x 10 x 6 m seen from above (system 0) and from the south, 45 deg (system 1)
    top = np.column_stack([rng.uniform(0, 10, 3000), rng.uniform(0, 10, 3000), np.full(3000, 6.0)])
    ground = rng.uniform(-10, 20, (6000, 2))
    ground = ground[~((ground[:, 0] > 0) & (ground[:, 0] < 10) & (ground[:, 1] > 0) & (ground[:, 1] < 10))]
    ground = np.column_stack([ground, np.zeros(len(ground))])
    facade = np.column_stack([rng.uniform(0, 10, 1500), np.zeros(1500), rng.uniform(0, 6, 1500)])
    xyz0 = np.concatenate([top, ground])
    south = np.array([0.0, np.sqrt(0.5), -np.sqrt(0.5)])
    cloud = PointCloud(
        np.concatenate([xyz0, facade]) + [500000, 5600000, 100],
        system=np.concatenate([np.zeros(len(xyz0)), np.ones(len(facade))]).astype(np.uint16),
        systems=[ReferenceSystem(0, "nadir", (0, 0, -1)), ReferenceSystem(1, "south", tuple(south))],
        crs="EPSG:32632",
    )
    mesh = mesh_from_point_cloud(cloud)
    n = mesh.face_normals()
    c = mesh.vertices[mesh.faces].mean(axis=1) - [500000, 5600000, 100]
    on_facade = (np.abs(c[:, 1]) < 0.3) & (c[:, 2] > 0.5) & (c[:, 2] < 5.5)
    # the facade is meshed (from system 1) and faces south, towards its cameras
    assert on_facade.sum() > 500 and np.median(n[on_facade, 1]) < -0.95
    # no nadir triangle bridges the 6 m step between roof and ground
    nadir_tris = ~on_facade
    zr = mesh.vertices[mesh.faces[nadir_tris]][:, :, 2]
    assert (zr.max(axis=1) - zr.min(axis=1)).max() < 1.0
    with pytest.raises(InputError, match="at least 3"):
        mesh_from_point_cloud(PointCloud(np.zeros((2, 3))))


def test_cancel_mesh(tmp_path, flat_scene):
    from truortho.core.errors import CancelledError
    from truortho.core.progress import CallbackProgress

    _, z, grid, _ = flat_scene
    with pytest.raises(CancelledError):
        mesh_from_dsm_array(z, grid, DsmMeshConfig(tile=128), progress=CallbackProgress(None, lambda: True))
