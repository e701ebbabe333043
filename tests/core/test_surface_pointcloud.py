"""Point clouds: LAS/LAZ round trips through laspy, reference systems, merging, EPT octrees,
DSM export."""

from __future__ import annotations

import json

import numpy as np
import pytest

from truortho.core.errors import CRSError, InputError
from truortho.core.grid import RasterGrid
from truortho.core.rasterio_io import write_raster
from truortho.core.surface.ept import octree_nodes, read_ept, write_ept
from truortho.core.surface.pointcloud import (
    PointCloud,
    ReferenceSystem,
    dsm_to_point_cloud,
    merge_point_clouds,
    read_point_cloud,
    thin_voxel,
    write_point_cloud_file,
)


def _cloud(rng, n=3000, sid=0):
    xyz = rng.uniform([500100, 5600100, 90], [500300, 5600250, 140], (n, 3))
    return PointCloud(
        xyz,
        rng.integers(0, 256, (n, 3)).astype(np.uint8),
        rng.uniform(0, 1, n).astype(np.float32),
        np.full(n, sid, np.uint16),
        "EPSG:32632",
        [ReferenceSystem(sid, f"system {sid}", (0.0, 0.5, -0.866))],
    )


@pytest.mark.parametrize("ext", [".las", ".laz"])
def test_laspy_round_trip(tmp_path, ext):
    import laspy

    rng = np.random.default_rng(1)
    cloud = _cloud(rng)
    info = write_point_cloud_file(tmp_path / f"pc{ext}", cloud)
    assert info["points"] == len(cloud) and info["ept"] is None
    las = laspy.read(tmp_path / f"pc{ext}")
    assert las.header.version.major == 1 and las.header.version.minor == 4
    assert las.header.point_format.id == 7 and las.header.global_encoding.wkt
    assert las.header.parse_crs().to_epsg() == 32632
    assert set(las.point_format.extra_dimension_names) == {"confidence", "system"}
    np.testing.assert_allclose(np.column_stack([las.x, las.y, las.z]), cloud.xyz, atol=6e-4)
    np.testing.assert_array_equal(np.asarray(las.red), cloud.rgb[:, 0].astype(np.uint16) * 257)
    np.testing.assert_array_equal(np.asarray(las["confidence"]), cloud.confidence)
    np.testing.assert_array_equal(np.asarray(las["system"]), cloud.system)
    np.testing.assert_allclose(las.header.mins, cloud.xyz.min(axis=0), atol=1e-3)
    back = read_point_cloud(tmp_path / f"pc{ext}")
    np.testing.assert_array_equal(back.rgb, cloud.rgb)
    assert back.systems[0].name == "system 0" and back.systems[0].view_direction == (0.0, 0.5, -0.866)
    assert not list(tmp_path.glob(".*tmp*"))
    if ext == ".laz":  # compressed: well below the 30 + 6 bytes per point of an uncompressed record
        assert (tmp_path / "pc.laz").stat().st_size < 30 * len(cloud)


def test_merge_systems_and_voxel_thinning(tmp_path):
    rng = np.random.default_rng(2)
    a, b = _cloud(rng, 2000, 0), _cloud(rng, 1500, 3)
    # system 3 repeats 500 points of system 0 with a higher confidence: the voxel keeps those
    dup = np.arange(500)
    b.xyz[:500] = a.xyz[dup]
    b.confidence[:500] = np.maximum(a.confidence[dup] + 0.01, 0.0)
    merged = merge_point_clouds([a, b])
    assert len(merged) == 3500 and sorted(s.id for s in merged.systems) == [0, 3]
    thin = merge_point_clouds([a, b], voxel=0.01)
    assert len(thin) == 3000
    dup_keys = {tuple(p) for p in a.xyz[dup]}
    kept_dup = np.array([tuple(p) in dup_keys for p in thin.xyz])
    assert kept_dup.sum() == 500
    assert np.all(thin.system[kept_dup] == 3)
    # thinning keeps the most confident point of every voxel (reference: a dictionary)
    best: dict = {}
    key = np.floor((merged.xyz - merged.xyz.min(axis=0)) / 5.0).astype(int)
    for i, k in enumerate(map(tuple, key)):
        if k not in best or merged.confidence[i] > merged.confidence[best[k]]:
            best[k] = i
    t5 = thin_voxel(merged, 5.0)
    assert sorted(t5.confidence.tolist()) == sorted(merged.confidence[list(best.values())].tolist())
    info = write_point_cloud_file(tmp_path / "m.laz", thin, ept_folder=tmp_path / "ept")
    back = read_point_cloud(info["path"])
    assert len(back) == len(thin) and set(np.unique(back.system)) == {0, 3}
    with pytest.raises(InputError, match="different CRS"):
        merge_point_clouds([a, PointCloud(b.xyz, crs="EPSG:2056")])
    with pytest.raises(InputError, match="no point clouds"):
        merge_point_clouds([])


def test_octree_invariants_and_ept_round_trip(tmp_path):
    rng = np.random.default_rng(3)
    n = 60000
    xy = rng.uniform(0, 300, (n, 2))
    xyz = np.column_stack([xy + [500000, 5600000], 50 + 3 * np.sin(xy[:, 0] / 30)])
    conf = rng.uniform(0, 1, n).astype(np.float32)
    lo, size = xyz.min(axis=0) - 0.01, float(np.ptp(xyz, axis=0).max()) + 0.02
    depth, key = octree_nodes(xyz, lo, size, 32, 2000, priority=conf)
    assert (depth >= 0).all()
    cell = size / 2.0 ** depth
    inside = (xyz >= lo + key * cell[:, None] - 1e-9) & (xyz <= lo + (key + 1) * cell[:, None] + 1e-9)
    assert inside.all()
    nodes = {(int(d), *map(int, k)) for d, k in zip(depth, key, strict=True)}
    for d, x, y, z in nodes:
        if d:
            assert (d - 1, x // 2, y // 2, z // 2) in nodes
    # the root keeps the most confident point of each of its voxels
    root = depth == 0
    assert conf[root].mean() > conf.mean() + 0.1
    ept = write_ept(tmp_path / "e", xyz, None, {"confidence": conf}, "EPSG:32632", span=32,
                    max_node_points=2000, priority=conf)
    doc = json.loads(ept.read_text())
    assert doc["points"] == n and doc["dataType"] == "binary" and doc["hierarchyType"] == "json"
    assert doc["srs"]["horizontal"] == "32632" and "PROJCRS" in doc["srs"]["wkt"]
    b = doc["bounds"]
    assert np.allclose(b[3] - b[0], b[4] - b[1]) and np.allclose(b[3] - b[0], b[5] - b[2])
    hier = json.loads((tmp_path / "e" / "ept-hierarchy" / "0-0-0-0.json").read_text())
    assert sum(hier.values()) == n and len(hier) == len(nodes) and max(hier.values()) <= 32**3
    back = read_ept(ept)
    order_a = np.lexsort(np.round(xyz, 3).T)
    order_b = np.lexsort(np.round(back["xyz"], 3).T)
    np.testing.assert_allclose(back["xyz"][order_b], xyz[order_a], atol=6e-4)
    np.testing.assert_array_equal(back["extra"]["confidence"][order_b], conf[order_a])
    # laszip nodes are written too (point format 2 for old LASzip decoders)
    ept2 = write_ept(tmp_path / "e2", xyz[:5000], None, {}, "EPSG:32632", data_type="laszip")
    assert len(read_ept(ept2)["xyz"]) == 5000
    # replacing an EPT folder is atomic; other folders are never overwritten
    write_ept(tmp_path / "e", xyz[:100], crs="EPSG:32632")
    assert json.loads(ept.read_text())["points"] == 100
    (tmp_path / "notept").mkdir()
    (tmp_path / "notept" / "keep.txt").write_text("x")
    with pytest.raises(InputError, match="not an EPT dataset"):
        write_ept(tmp_path / "notept", xyz[:100])


def test_dsm_to_point_cloud(tmp_path):
    import laspy

    rng = np.random.default_rng(4)
    grid = RasterGrid(500000.0, 5600100.0, 0.5, 60, 80, "EPSG:32632")
    z = 100 + rng.normal(0, 1, grid.shape).astype(np.float32)
    z[:5, :7] = -9999
    conf = rng.uniform(0, 1, grid.shape).astype(np.float32)
    rgb = rng.integers(0, 256, (3,) + grid.shape).astype(np.uint8)
    write_raster(tmp_path / "dsm.tif", z, grid, nodata=-9999.0)
    write_raster(tmp_path / "conf.tif", conf, grid)
    write_raster(tmp_path / "ortho.tif", rgb, grid)
    info = dsm_to_point_cloud(tmp_path / "dsm.tif", tmp_path / "pc.laz", tmp_path / "ortho.tif",
                              tmp_path / "conf.tif", ept_folder=tmp_path / "ept", tile=32)
    n = z.size - 35
    assert info["points"] == n
    las = laspy.read(tmp_path / "pc.laz")
    assert len(las.points) == n and las.header.parse_crs().to_epsg() == 32632
    r, c = grid.cell_of(np.asarray(las.x), np.asarray(las.y))
    r, c = np.round(r).astype(int), np.round(c).astype(int)
    np.testing.assert_allclose(np.asarray(las.z), z[r, c], atol=6e-4)
    np.testing.assert_array_equal(np.asarray(las.red) // 257, rgb[0, r, c])
    np.testing.assert_allclose(np.asarray(las["confidence"]), conf[r, c])
    assert read_ept(info["ept"])["xyz"].shape == (n, 3)
    nocrs = RasterGrid(grid.x_min, grid.y_max, grid.res, grid.rows, grid.cols, None)
    write_raster(tmp_path / "nocrs.tif", z, nocrs, nodata=-9999.0)
    with pytest.raises(CRSError, match="no CRS"):
        dsm_to_point_cloud(tmp_path / "nocrs.tif", tmp_path / "x.laz")
    write_raster(tmp_path / "empty.tif", np.full(grid.shape, -9999.0, np.float32), grid, nodata=-9999.0)
    with pytest.raises(InputError, match="nodata"):
        dsm_to_point_cloud(tmp_path / "empty.tif", tmp_path / "x.laz")
    with pytest.raises(InputError, match=".las or .laz"):
        dsm_to_point_cloud(tmp_path / "dsm.tif", tmp_path / "x.xyz")
    assert not (tmp_path / "x.laz").exists()
