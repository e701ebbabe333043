"""Fuzzing the parsers: hostile input gives a valid Orientation or a TruOrthoError, nothing else."""

from __future__ import annotations

import importlib.util
import json
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from truortho.core.errors import TruOrthoError
from truortho.core.formats import (
    read_colmap,
    read_gcp_list,
    read_opensfm,
    read_opk,
    write_colmap,
    write_gcp_list,
    write_opk,
)
from truortho.core.geometry import matrix_to_axis_angle
from truortho.core.orientation import GCP, Orientation

_spec = importlib.util.spec_from_file_location(
    "_formats_helpers", Path(__file__).with_name("test_formats.py")
)
_helpers = importlib.util.module_from_spec(_spec)  # type: ignore[arg-type]
_spec.loader.exec_module(_helpers)  # type: ignore[union-attr]

FUZZ = settings(
    max_examples=150,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
HOSTILE_NUMBERS = [
    b"nan",
    b"NaN",
    b"inf",
    b"-inf",
    b"1e400",
    b"1e16",
    b"-1e16",
    b"-5",
    b"0",
    b"-0",
    b"99999999999999999999999",
    b"1" * 5000,
    b"0x10",
    b"",
    b"1e-400",
    b"3.0.0",
]
HOSTILE_TEXT = [
    b"../x.jpg",
    b"/etc/passwd",
    b"C:\\x.jpg",
    b"a/../../b.jpg",
    b"\xe9\xe8",
    b"\x00",
    b"#",
    b"[" * 200,
    b"{",
    b'"',
    b"\t",
    b"  ",
    b"FISHEYE",
    b"-1",
    b"\xff\xfe",
]
NUMBER = re.compile(rb"-?\d+(?:\.\d+)?(?:e-?\d+)?")


def _seeds(folder: Path) -> dict[str, bytes]:
    o = _helpers.make_orientation()
    o.points.xyz = o.points.xyz[:8]  # keep inputs small
    keep = o.points.obs_point < 8
    o.points = type(o.points)(
        o.points.xyz,
        o.points.rgb[:8],
        o.points.error[:8],
        o.points.obs_point[keep],
        o.points.obs_image[keep],
        o.points.obs_xy[keep],
    )
    write_colmap(o, folder / "colmap")
    write_opk(o, folder / "ext.csv", folder / "int.yaml")
    write_opk(o, folder / "ext2.csv", folder / "int.json")
    o.save(folder / "orientation.json")
    gcps = [
        GCP(
            "g1", [500010.0, 5600020.0, 101.0], observations=[("img_0.jpg", 10.5, 20.25), ("img_1.jpg", 3, 4)]
        ),
        GCP("g2", [500110.0, 5600020.0, 99.0], observations=[("img_2.jpg", 1, 2)]),
    ]
    write_gcp_list("EPSG:32632", gcps, folder / "gcp_list.txt")
    shots = {
        im.name: {
            "camera": "c",
            "rotation": matrix_to_axis_angle(im.R).tolist(),
            "translation": im.t.tolist(),
        }
        for im in o.images[:3]
    }
    rec = {
        "cameras": {
            "c": {
                "projection_type": "brown",
                "width": 400,
                "height": 300,
                "focal_x": 0.8,
                "focal_y": 0.8,
                "c_x": 0.01,
                "c_y": 0,
                "k1": -0.1,
                "k2": 0.01,
                "p1": 0,
                "p2": 0,
                "k3": 0,
            }
        },
        "shots": shots,
        "points": {"1": {"coordinates": [1, 2, 3], "color": [1, 2, 3]}},
        "reference_lla": {"latitude": 50.1, "longitude": 8.2, "altitude": 120.0},
    }
    (folder / "reconstruction.json").write_text(json.dumps([rec], indent=1))
    files = {
        "cameras": folder / "colmap" / "cameras.txt",
        "images": folder / "colmap" / "images.txt",
        "points": folder / "colmap" / "points3D.txt",
        "csv": folder / "ext.csv",
        "yaml": folder / "int.yaml",
        "json": folder / "int.json",
        "opensfm": folder / "reconstruction.json",
        "gcp": folder / "gcp_list.txt",
        "orientation": folder / "orientation.json",
    }
    return {k: p.read_bytes() for k, p in files.items()}


@pytest.fixture(scope="module")
def seeds(tmp_path_factory) -> dict[str, bytes]:
    return _seeds(tmp_path_factory.mktemp("seeds"))


@pytest.fixture(scope="module")
def work(tmp_path_factory, seeds) -> Path:
    d = tmp_path_factory.mktemp("fuzz")
    return d


@st.composite
def mutations(draw, kind: str):
    """A recipe applied to a seed file: list of (operation, parameters)."""
    ops = st.one_of(
        st.tuples(st.just("truncate"), st.floats(0, 1)),
        st.tuples(st.just("delete"), st.floats(0, 1)),
        st.tuples(st.just("duplicate"), st.floats(0, 1)),
        st.tuples(st.just("number"), st.floats(0, 1), st.sampled_from(HOSTILE_NUMBERS)),
        st.tuples(st.just("insert"), st.floats(0, 1), st.sampled_from(HOSTILE_TEXT)),
        st.tuples(st.just("bytes"), st.floats(0, 1), st.binary(min_size=1, max_size=8)),
    )
    if draw(st.integers(0, 9)) == 0:
        return ("random", draw(st.binary(max_size=300)))
    return ("mutate", draw(st.lists(ops, min_size=1, max_size=4)))


def apply(seed: bytes, recipe) -> bytes:
    kind, arg = recipe
    if kind == "random":
        return arg
    data = seed
    for op in arg:
        lines = data.split(b"\n")
        i = min(int(op[1] * len(lines)), len(lines) - 1)
        if op[0] == "truncate":
            data = data[: int(op[1] * len(data))]
            continue
        if op[0] == "delete" and len(lines) > 1:
            del lines[i]
        elif op[0] == "duplicate":
            lines.insert(i, lines[i])
        elif op[0] == "number":
            nums = list(NUMBER.finditer(lines[i]))
            if nums:
                m = nums[int(op[1] * 997) % len(nums)]
                lines[i] = lines[i][: m.start()] + op[2] + lines[i][m.end() :]
        elif op[0] in ("insert", "bytes"):
            pos = int(op[1] * 7919) % (len(lines[i]) + 1)
            lines[i] = lines[i][:pos] + op[2] + lines[i][pos:]
        data = b"\n".join(lines)
    return data


def must_be_clean(fn) -> None:
    try:
        result = fn()
    except TruOrthoError:
        return
    if isinstance(result, Orientation):
        result.validate()
        for im in result.images:
            assert (
                np.all(np.isfinite(im.C)) and not im.path.startswith("/") and ".." not in im.path.split("/")
            )


def _colmap_case(work: Path, seeds, which: str, recipe) -> None:
    d = work / "colmap"
    d.mkdir(exist_ok=True)
    for k, name in (("cameras", "cameras.txt"), ("images", "images.txt"), ("points", "points3D.txt")):
        data = apply(seeds[k], recipe) if k == which else seeds[k]
        (d / name).write_bytes(data)
    must_be_clean(lambda: read_colmap(d, georef={"crs": None, "offset": [0, 0, 0]}))


@FUZZ
@given(recipe=mutations("cameras"))
def test_fuzz_colmap_cameras(work, seeds, recipe):
    _colmap_case(work, seeds, "cameras", recipe)


@FUZZ
@given(recipe=mutations("images"))
def test_fuzz_colmap_images(work, seeds, recipe):
    _colmap_case(work, seeds, "images", recipe)


@FUZZ
@given(recipe=mutations("points"))
def test_fuzz_colmap_points(work, seeds, recipe):
    _colmap_case(work, seeds, "points", recipe)


@FUZZ
@given(recipe=mutations("csv"))
def test_fuzz_opk_csv(work, seeds, recipe):
    (work / "int.json").write_bytes(seeds["json"])
    (work / "ext.csv").write_bytes(apply(seeds["csv"], recipe))
    must_be_clean(lambda: read_opk(work / "ext.csv", work / "int.json", crs="EPSG:32632"))


@FUZZ
@given(recipe=mutations("yaml"), ext=st.sampled_from(["yaml", "json"]))
def test_fuzz_opk_interior(work, seeds, recipe, ext):
    if ext == "yaml":
        pytest.importorskip("yaml")
    (work / "ext.csv").write_bytes(seeds["csv"])
    (work / f"int.{ext}").write_bytes(apply(seeds[ext], recipe))
    must_be_clean(lambda: read_opk(work / "ext.csv", work / f"int.{ext}", crs="EPSG:32632"))


@FUZZ
@given(recipe=mutations("opensfm"))
def test_fuzz_opensfm(work, seeds, recipe):
    (work / "reconstruction.json").write_bytes(apply(seeds["opensfm"], recipe))
    must_be_clean(lambda: read_opensfm(work / "reconstruction.json"))


@pytest.mark.filterwarnings("ignore::truortho.core.formats.GCPListWarning")
@FUZZ
@given(recipe=mutations("gcp"))
def test_fuzz_gcp_list(work, seeds, recipe):
    (work / "gcp_list.txt").write_bytes(apply(seeds["gcp"], recipe))
    must_be_clean(lambda: read_gcp_list(work / "gcp_list.txt", warnings_out=[]))


@FUZZ
@given(recipe=mutations("orientation"))
def test_fuzz_orientation_json(work, seeds, recipe):
    (work / "orientation.json").write_bytes(apply(seeds["orientation"], recipe))
    must_be_clean(lambda: Orientation.load(work / "orientation.json"))


def test_seeds_are_valid(work, seeds):
    """The unmutated seed files read back (so the fuzzing starts from valid input)."""
    _colmap_case(work, seeds, "none", None)
    assert len(read_colmap(work / "colmap").images) == 6
    for ext in ("yaml", "json"):
        (work / f"int.{ext}").write_bytes(seeds[ext])
    (work / "ext.csv").write_bytes(seeds["csv"])
    assert len(read_opk(work / "ext.csv", work / "int.json", crs="EPSG:32632").images) == 6
    (work / "reconstruction.json").write_bytes(seeds["opensfm"])
    assert len(read_opensfm(work / "reconstruction.json").images) == 3
    (work / "gcp_list.txt").write_bytes(seeds["gcp"])
    assert len(read_gcp_list(work / "gcp_list.txt")[1]) == 2
    (work / "orientation.json").write_bytes(seeds["orientation"])
    assert len(Orientation.load(work / "orientation.json").images) == 6


@pytest.mark.parametrize("depth", [50, 5000, 100000])
def test_deeply_nested_json(work, depth):
    nested = "[" * depth + "]" * depth
    for name, fn in (
        ("reconstruction.json", lambda p: read_opensfm(p)),
        ("orientation.json", lambda p: Orientation.load(p)),
        ("int.json", lambda p: read_opk(work / "e.csv", p, crs=32632)),
    ):
        (work / "e.csv").write_text("a.jpg 1 2 3 0 0 0\n")
        (work / name).write_text(nested)
        must_be_clean(lambda: fn(work / name))  # noqa: B023
