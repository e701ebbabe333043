"""Ground-truth cameras of the synthetic generator through the exchange formats.

GCP pixel observations rendered by the generator must reproject with the
*imported* cameras (COLMAP, Orthority OPK, TruOrtho JSON) to < 0.01 px.
"""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.exchange import read_orientation, write_orientation
from truortho.core.formats.gcplist import read_gcp_list
from truortho.core.geometry import project_points
from truortho.core.synthetic import SceneConfig, make_scene


@pytest.fixture(scope="module")
def scene_folder(tmp_path_factory):
    cfg = SceneConfig(image_size=(320, 240), focal_px=400.0, seed=7)
    scene = make_scene(cfg)
    folder = tmp_path_factory.mktemp("scene")
    scene.write(folder)
    return scene, folder


def _max_gcp_error(orientation, gcps) -> tuple[float, int]:
    worst, n = 0.0, 0
    for g in gcps:
        for name, x, y in g.observations:
            im = orientation.image(name)
            uv = project_points(
                orientation.frame.to_local(g.xyz[None]), im.R, im.C, orientation.camera_of(im)
            )[0]
            worst = max(worst, float(np.hypot(uv[0] - x, uv[1] - y)))
            n += 1
    return worst, n


@pytest.mark.parametrize("fmt", ["colmap", "opk", "truortho"])
def test_gcp_observations_reproject_with_imported_cameras(scene_folder, tmp_path, fmt):
    scene, folder = scene_folder
    crs, gcps = read_gcp_list(folder / "gcp_list.txt")
    assert crs == "EPSG:32632" and len(gcps) >= 5
    if fmt == "truortho":
        o = read_orientation(folder / "orientation.json")
    else:
        write_orientation(scene.orientation, fmt, tmp_path)
        src = tmp_path / ("images.txt" if fmt == "colmap" else "exterior.csv")
        o = read_orientation(src, interior=tmp_path / "interior.yaml" if fmt == "opk" else None)
    worst, n = _max_gcp_error(o, gcps)
    assert n >= 15
    assert worst < 0.01, f"{fmt}: worst GCP reprojection {worst:.2e} px"


def test_generator_orientation_has_obliques_and_gcp_roles(scene_folder):
    scene, _ = scene_folder
    o = scene.orientation
    tilts = [np.degrees(np.arccos(-im.R[2, 2])) for im in o.images]
    assert max(tilts) > 30 and min(tilts) < 5
    roles = {g.role for g in o.gcps}
    assert roles == {"gcp", "check"}
