"""Mesh files: PLY (binary write, binary/ASCII read) and OBJ round trips, conventions, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.errors import FormatError, InputError, MissingFileError
from truortho.core.surface.meshio import Mesh, read_mesh, write_mesh

CRS_WKT = (
    'PROJCRS["WGS 84 / UTM zone 32N",BASEGEOGCRS["WGS 84",DATUM["World Geodetic System 1984",'
    'ELLIPSOID["WGS 84",6378137,298.257223563]]],CONVERSION["UTM zone 32N",METHOD["Transverse Mercator"],'
    'PARAMETER["Latitude of natural origin",0],PARAMETER["Longitude of natural origin",9],'
    'PARAMETER["Scale factor at natural origin",0.9996],PARAMETER["False easting",500000],'
    'PARAMETER["False northing",0]],CS[Cartesian,2],AXIS["easting",east],AXIS["northing",north],'
    'LENGTHUNIT["metre",1]]'
)


def random_mesh(rng, n=200, m=300, colours=True, crs="EPSG:32632"):
    v = rng.uniform([500100.0, 5600200.0, 80.0], [500400.0, 5600500.0, 140.0], (n, 3))
    f = rng.integers(0, n, (m, 3))
    c = rng.integers(0, 256, (n, 3)).astype(np.uint8) if colours else None
    return Mesh(v, f, c, crs)


@pytest.mark.parametrize("ext", [".ply", ".obj"])
@pytest.mark.parametrize("frame", ["crs", "local"])
@pytest.mark.parametrize("colours", [True, False])
def test_round_trip(tmp_path, ext, frame, colours):
    rng = np.random.default_rng(4)
    mesh = random_mesh(rng, colours=colours)
    path = write_mesh(tmp_path / f"m{ext}", mesh, frame=frame)
    back = read_mesh(path)
    # PLY local: float32 local coordinates (< 0.5 mm); OBJ: 6 decimals
    tol = 5e-4 if (frame == "local" and ext == ".ply") else 2e-6
    np.testing.assert_allclose(back.vertices, mesh.vertices, atol=tol, rtol=0)
    np.testing.assert_array_equal(back.faces, mesh.faces)
    assert back.crs == "EPSG:32632"
    if colours:
        np.testing.assert_array_equal(back.colours, mesh.colours)
    else:
        assert back.colours is None
    if frame == "local":
        np.testing.assert_allclose(back.offset, [500000.0, 5600000.0, 0.0])
    else:
        assert back.offset is None
    assert not list(tmp_path.glob(".*tmp*"))


def test_ply_header_conventions_and_given_offset(tmp_path):
    rng = np.random.default_rng(1)
    mesh = random_mesh(rng, crs=CRS_WKT)
    p = write_mesh(tmp_path / "m.ply", mesh, frame="local", offset=(500200.0, 5600300.0, 100.0))
    raw = p.read_bytes()
    header = raw[: raw.index(b"end_header")].decode()
    assert "format binary_little_endian 1.0" in header
    assert "comment offset 500200.000000 5600300.000000 100.000000" in header
    assert f"comment crs {CRS_WKT}" in header
    assert "property float x" in header and "property list uchar int vertex_indices" in header
    back = read_mesh(p)
    assert back.crs == CRS_WKT
    np.testing.assert_allclose(back.vertices, mesh.vertices, atol=1e-4, rtol=0)
    # CRS frame: doubles, no offset comment
    p2 = write_mesh(tmp_path / "w.ply", mesh, frame="crs")
    raw2 = p2.read_bytes()
    h2 = raw2[: raw2.index(b"end_header")].decode()
    assert "property double x" in h2 and "comment offset" not in h2


def test_ascii_ply_and_polygons_and_big_endian(tmp_path):
    text = """ply
format ascii 1.0
comment crs EPSG:2056
comment offset 2600000 1200000 400
element vertex 5
property float x
property float y
property float z
property uchar red
property uchar green
property uchar blue
element face 2
property list uchar int vertex_indices
element edge 1
property int vertex1
property int vertex2
end_header
0 0 0 255 0 0
1 0 0 0 255 0
1 1 0.5 0 0 255
0 1 0.5 10 20 30
2 2 1 1 2 3
4 0 1 2 3
3 1 4 2
0 1
"""
    p = tmp_path / "a.ply"
    p.write_text(text)
    m = read_mesh(p)
    np.testing.assert_allclose(m.vertices[2], [2600001.0, 1200001.0, 400.5])
    np.testing.assert_array_equal(m.faces, [[0, 1, 2], [0, 2, 3], [1, 4, 2]])
    np.testing.assert_array_equal(m.colours[3], [10, 20, 30])
    assert m.crs == "EPSG:2056"
    # big-endian binary, double coordinates, int indices with a list count of uint8
    v = np.array([[0, 0, 1], [1, 0, 2], [0, 1, 3]], ">f8")
    body = v.tobytes() + np.array([3], "u1").tobytes() + np.array([0, 1, 2], ">i4").tobytes()
    hdr = (
        "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
        "property double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    )
    q = tmp_path / "b.ply"
    q.write_bytes(hdr.encode() + body)
    mb = read_mesh(q)
    np.testing.assert_allclose(mb.vertices, v.astype(float))
    np.testing.assert_array_equal(mb.faces, [[0, 1, 2]])
    assert mb.crs is None and mb.offset is None and mb.colours is None


def test_obj_reader_variants(tmp_path):
    p = tmp_path / "x.obj"
    p.write_text(
        "# crs EPSG:32632\n# offset 500000 5600000 0\nmtllib x.mtl\no thing\n"
        "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 0.5 0.5 0.5\nvt 0 0\nvn 0 0 1\n"
        "f 1/1/1 2/1/1 3/1/1 4/1/1\nf -4 -2 -1\n"
    )
    m = read_mesh(p)
    np.testing.assert_allclose(m.vertices[2], [500001.0, 5600001.0, 0.0])
    np.testing.assert_array_equal(m.faces, [[0, 1, 2], [0, 2, 3], [0, 2, 3]])
    np.testing.assert_array_equal(m.colours[0], [255, 0, 0])
    np.testing.assert_array_equal(m.colours[3], [128, 128, 128])


def test_bad_input(tmp_path):
    rng = np.random.default_rng(0)
    mesh = random_mesh(rng)
    with pytest.raises(InputError, match=r"unknown mesh extension '\.stl'.*\.ply or \.obj"):
        write_mesh(tmp_path / "m.stl", mesh)
    with pytest.raises(InputError, match="unknown mesh extension"):
        read_mesh(tmp_path / "m")
    with pytest.raises(InputError, match="frame"):
        write_mesh(tmp_path / "m.ply", mesh, frame="utm")
    with pytest.raises(MissingFileError):
        read_mesh(tmp_path / "none.ply")
    with pytest.raises(InputError, match="outside"):
        Mesh(np.zeros((3, 3)), [[0, 1, 3]])
    with pytest.raises(InputError, match=r"\(N, 3\)"):
        Mesh(np.zeros((3, 2)), [[0, 1, 2]])
    bad = tmp_path / "bad.ply"
    bad.write_bytes(
        b"ply\nformat binary_little_endian 1.0\nelement vertex 10\nproperty float x\n"
        b"property float y\nproperty float z\nend_header\n" + b"\0" * 20
    )
    with pytest.raises(FormatError, match="truncated"):
        read_mesh(bad)
    bad.write_bytes(b"solid stl\n")
    with pytest.raises(FormatError, match="not a PLY"):
        read_mesh(bad)
    obj = tmp_path / "bad.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nf 1 2 5\n")
    with pytest.raises(FormatError, match="outside"):
        read_mesh(obj)
    obj.write_text("v 0 0 zero\n")
    with pytest.raises(FormatError, match="line 1"):
        read_mesh(obj)
    assert not (tmp_path / "m.stl").exists() and not (tmp_path / "m.ply").exists()


def test_face_normals_point_up_for_ccw():
    m = Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    np.testing.assert_allclose(m.face_normals(), [[0, 0, 1]])
