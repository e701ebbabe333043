"""The report's explanations: what limits the check points (computed from the control), and a
warning when the bundle adjustment stops without converging (issue 20, part 4)."""

from __future__ import annotations

import numpy as np
import pytest

from truortho.core.sfm.accuracy import check_point_notes, control_geometry, convergence_note
from truortho.core.sfm.bundle import BundleResult


def _spread_control(rng, n=6, sigma=0.01):
    ang = np.linspace(0, 2 * np.pi, n, endpoint=False) + rng.uniform(0, 0.3)
    xyz = np.column_stack([500 + 80 * np.cos(ang), 300 + 60 * np.sin(ang), rng.uniform(10, 25, n)])
    return xyz, np.tile([sigma, sigma, 1.5 * sigma], (n, 1))


def test_geometry_of_spread_and_collinear_control():
    rng = np.random.default_rng(4)
    xyz, sig = _spread_control(rng)
    g = control_geometry(xyz, sig)
    assert g["n"] == 6 and 0.6 < g["across_ratio"] <= 1.0 and not g["flat_heights"]
    assert g["sigma_xy_m"] == pytest.approx(0.01) and g["sigma_z_m"] == pytest.approx(0.015)
    # on a line 40 m long, 0.5 m off it at most, all at height 0
    t = np.array([0.0, 13.0, 40.0])
    line = np.column_stack([100 + t * 0.8, 200 + t * 0.6, np.zeros(3)]) + [
        [0.3, -0.4, 0],
        [0, 0, 0],
        [0, 0, 0],
    ]
    g = control_geometry(line)
    assert g["across_ratio"] < 0.05 and g["flat_heights"] and g["height_range_m"] == 0.0
    assert np.isnan(g["sigma_xy_m"])
    # rotating the layout does not change the shape figures
    c, s = np.cos(0.7), np.sin(0.7)
    rot = line @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]).T
    assert control_geometry(rot)["across_ratio"] == pytest.approx(g["across_ratio"])


def test_notes_name_the_limits_found_in_the_data():
    t = np.array([0.0, 10.0, 21.0])
    weak = control_geometry(
        np.column_stack([t, 0.5 * t + np.array([0, 1.0, 0]), np.zeros(3)]),
        np.tile([0.02, 0.02, 0.03], (3, 1)),
    )
    notes = check_point_notes(weak, {"x": 2.0, "y": 1.0, "z": 2.0}, 0.02, 2, {"a": 3, "b": 2, "c": 4})
    text = " ".join(notes)
    assert "plan RMSE 2.24 m" in text and "112 and 100 times the ground sample distance" in text
    for phrase in ("only 3 control point", "nearly on a line", "plan-only", "112 times the stated", " b "):
        assert phrase in text, phrase
    assert "0.020-0.040 m" in text  # 1-2 GSD with survey-grade control, from the GSD given

    # a well-posed block with errors of its GSD: no limit named, only the figures and the expectation
    rng = np.random.default_rng(1)
    good = control_geometry(*_spread_control(rng))
    notes = check_point_notes(good, {"x": 0.012, "y": 0.01, "z": 0.02}, 0.01, 4, {"g": 5})
    assert len(notes) == 2 and not any("What limits them" in n for n in notes)
    assert check_point_notes(good, {}, 0.01, 0) == []


def test_convergence_note():
    assert convergence_note(True, "cost", 12, [10.0, 1.0]) is None
    hist = [100.0 * 0.99**k for k in range(51)]
    note = convergence_note(False, "max_iterations", 50, hist)
    assert "did not converge" in note and "max_iterations" in note and "50 iterations" in note
    assert "by 0.98 % per iteration" in note  # (1 - 0.99**5) / 5


def test_orientation_report_warns_when_the_bundle_did_not_converge():
    from truortho.core.sfm.report import orientation_report

    def result(converged: bool) -> BundleResult:
        return BundleResult(
            intrinsics=np.zeros((1, 9)), rotations=np.tile(np.eye(3), (2, 1, 1)), centers=np.zeros((2, 3)),
            points=np.zeros((1, 3)), residuals=np.zeros((2, 2)), weights=np.ones(2), valid=np.ones(2, bool),
            sigma0=1.0, sigma0_mad=1.0, redundancy=1, rms=0.5, rms_per_image=np.ones(2), n_iterations=50,
            converged=converged, reason="cost" if converged else "max_iterations",
            cost_history=[10.0, 9.0, 8.5, 8.2, 8.0, 7.9, 7.8],
        )  # fmt: skip

    def report(converged):
        return orientation_report(
            "t", ["a", "b"], np.ones(2, bool), np.zeros((2, 3)), np.zeros((1, 3)), np.array([2]),
            result(converged), np.array([0, 1]), np.zeros((2, 2)), None, {}, [],
        )  # fmt: skip

    rep = report(False)
    assert any("did not converge" in w for w in rep.warnings)
    assert rep.data["bundle"]["converged"] is False
    assert not any("did not converge" in w for w in report(True).warnings)
