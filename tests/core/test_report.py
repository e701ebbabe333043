"""core.report: the JSON round trip and the orientation's part of an earlier pipeline report."""

from __future__ import annotations

import json

from truortho.core.report import Report, Table, reused_orientation_report


def _pipeline_like() -> Report:
    rep = Report("TruOrtho pipeline report")
    rep.summary = {
        "sigma0": 0.8,
        "images oriented": 6,
        "DSM resolution [m]": 0.5,
        "true ortho coverage [%]": 99.0,
        "total time [s]": 12.0,
        "tiles ran on": "inprocess",
    }
    rep.tables = [
        Table("Control points", ["name", "dX"], [["g1", 0.01]], "metres"),
        Table("Dense matching and DSM filter", ["what", "value"], [["OSGM", "..."]]),
        Table("Stages", ["stage", "time [s]"], [["orientation", 3.0]]),
    ]
    rep.warnings = ["w"]
    rep.data = {"x": [1, 2]}
    return rep


def test_from_json_round_trip():
    rep = _pipeline_like()
    back = Report.from_json(json.loads(json.dumps(rep.to_json())))
    assert back.to_json() == rep.to_json()
    assert back.figures == []


def test_reused_orientation_report_keeps_the_orientation_part(tmp_path):
    _pipeline_like().save(tmp_path / "report.html")
    rep = reused_orientation_report(tmp_path / "report.json")
    assert rep is not None and rep.title == "orientation (reused)"
    assert rep.summary == {"sigma0": 0.8, "images oriented": 6}  # DSM, true ortho, totals, tiles dropped
    # the dense matching and stage tables belong to the new run (they were kept twice before)
    assert [t.title for t in rep.tables] == ["Control points"]
    assert rep.tables[0].note == "metres" and rep.tables[0].rows == [["g1", 0.01]]
    assert reused_orientation_report(tmp_path / "missing.json") is None
    (tmp_path / "bad.json").write_text("{not json", encoding="utf-8")
    assert reused_orientation_report(tmp_path / "bad.json") is None


def test_photo_counts_is_the_frame_test_of_every_photo():
    """The report's coverage map counts, per cell, the photos whose frame holds the cell's surface
    point (in front of the camera); the synthetic truth with occlusion switched off agrees exactly."""
    import numpy as np

    from truortho.core.grid import RasterGrid
    from truortho.core.report import photo_counts
    from truortho.core.synthetic import SceneConfig, make_scene

    scene = make_scene(SceneConfig(image_size=(160, 120), focal_px=200.0, n_oblique=2, seed=4))
    ext = scene.extent_world()
    grid = RasterGrid.from_extent(ext, 2.0, scene.orientation.crs)
    X, Y = grid.centres()
    Pw = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    z = scene.height(Pw[:, :2]).reshape(grid.shape)
    Pw[:, 2] = z.ravel()
    truth = sum(
        scene.visibility(Pw, i, tol=1e9)[0].astype(int) for i in range(len(scene.orientation.images))
    ).reshape(grid.shape)
    got = photo_counts(scene.orientation, z.astype(np.float32), grid)
    assert got.shape == grid.shape and got.max() >= 4
    assert (got == truth).mean() > 0.999  # a cell centre exactly on a frame border may go either way
