"""The orientation report: numbers (JSON) and plots (HTML) of one orientation run."""

from __future__ import annotations

import numpy as np

from ..report import Report, Table
from .accuracy import check_point_notes, control_geometry, convergence_note


def _plt():
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def orientation_report(
    title: str,
    image_names: list[str],
    registered: np.ndarray,
    centers_world: np.ndarray,
    points_world: np.ndarray,
    multiplicity: np.ndarray,
    bundle,
    obs_image: np.ndarray,
    obs_xy: np.ndarray,
    georef,
    stats: dict,
    cameras: list,
) -> Report:
    """Build the report of :func:`~.pipeline.orient_images`.

    Parameters
    ----------
    image_names : list of str
        All input images.
    registered : (n_img,) bool
    centers_world : (n_reg, 3)
        Projection centres of the registered images, world CRS.
    points_world : (n_pt, 3)
        Tie points, world CRS.
    multiplicity : (n_pt,) int
        Images per tie point.
    bundle : BundleResult
        The final adjustment (residuals per observation of the tie points first).
    obs_image, obs_xy : (n_obs,), (n_obs, 2)
        Block image index and pixel position of the tie observations.
    georef : GeorefResult
    stats : dict
        Free numbers of the stages (pairs tried, timings ...).
    cameras : list of Camera
        Adjusted interior orientations.
    """
    rep = Report(title)
    n_img = len(image_names)
    n_reg = int(np.sum(registered))
    n_obs = len(obs_image)
    res = bundle.residuals[:n_obs] if bundle is not None else np.zeros((0, 2))
    err = np.linalg.norm(res, axis=1) if len(res) else np.zeros(0)
    rep.summary = {
        "images": n_img,
        "registered images": f"{n_reg} ({100.0 * n_reg / max(n_img, 1):.1f} %)",
        "tie points": len(points_world),
        "image observations": n_obs,
        "sigma0 [px]": float(bundle.sigma0) if bundle is not None else float("nan"),
        "image RMS [px]": float(bundle.rms) if bundle is not None else float("nan"),
        "datum": georef.method if georef is not None else "none",
    }
    for k, v in stats.get("summary", {}).items():
        rep.summary[k] = v
    if georef is not None and georef.check_rmse:
        c = georef.check_rmse
        rep.summary["check points RMSE X / Y / Z / 3D [m]"] = (
            f"{c['x']:.4f} / {c['y']:.4f} / {c['z']:.4f} / {c['3d']:.4f}"
        )
    if georef is not None:
        rep.warnings += list(georef.warnings)
    rep.warnings += list(stats.get("warnings", []))
    if bundle is not None:
        note = convergence_note(bundle.converged, bundle.reason, bundle.n_iterations, bundle.cost_history)
        if note:
            rep.warnings.append(note)
    check_notes = _check_notes(georef, centers_world, points_world, cameras)

    # per-image residual statistics
    reg_names = [n for n, r in zip(image_names, registered, strict=True) if r]
    rows = []
    for b, name in enumerate(reg_names):
        sel = obs_image == b
        e = err[sel]
        e = e[np.isfinite(e)]
        rows.append(
            [
                name,
                int(sel.sum()),
                float(np.sqrt(np.mean(e**2))) if len(e) else float("nan"),
                float(np.median(e)) if len(e) else float("nan"),
                float(e.max()) if len(e) else float("nan"),
            ]
        )
    for name, r in zip(image_names, registered, strict=True):
        if not r:
            rows.append([name, 0, float("nan"), float("nan"), float("nan")])
    rep.tables.append(
        Table(
            "Images",
            ["image", "observations", "RMS [px]", "median [px]", "max [px]"],
            rows,
            "Images with 0 observations were not oriented.",
        )
    )
    guided = [e for e in stats.get("reconstruction", {}).get("guided", []) if e.get("registered")]
    if guided:
        rep.tables.append(
            Table(
                "Images registered by guided matching",
                [
                    "image",
                    "partner",
                    "pair points",
                    "median angle [°]",
                    "scale points",
                    "expected by chance",
                    "log10 NFA",
                    "RMS [px]",
                ],
                [
                    [
                        image_names[e["image"]],
                        image_names[e["partner"]],
                        e["pair_points"],
                        e["pair_median_angle_deg"],
                        e["guided_inliers"],
                        e["scale_search"]["expected_chance_matches"],
                        e["scale_search"]["log10_nfa"],
                        e["rms_px"],
                    ]
                    for e in guided
                ],
                "Rotation and baseline direction from the relative orientation to the partner; the baseline "
                "length from guided matches of block points (number, and how many would match by chance); "
                "pose confirmed by an adjustment of the image alone against the block.",
            )
        )
    if cameras:
        cols = ["camera", "fx", "fy", "cx", "cy", "k1", "k2", "k3", "p1", "p2"]
        rep.tables.append(
            Table(
                "Interior orientation (adjusted)",
                cols,
                [[c.id, c.fx, c.fy, c.cx, c.cy, c.k1, c.k2, c.k3, c.p1, c.p2] for c in cameras],
            )
        )
    if georef is not None and georef.gcp_table:
        rep.tables.append(
            _gcp_table("Ground control points (adjusted − surveyed)", georef.gcp_table, georef.gcp_rmse)
        )
    if georef is not None and georef.check_table:
        rep.tables.append(
            _gcp_table(
                "Check points (triangulated − surveyed)",
                georef.check_table,
                georef.check_rmse,
                " ".join(check_notes),
            )
        )

    rep.data = {
        "stats": stats,
        "bundle": None
        if bundle is None
        else {
            "sigma0": bundle.sigma0,
            "sigma0_mad": bundle.sigma0_mad,
            "rms": bundle.rms,
            "iterations": bundle.n_iterations,
            "converged": bundle.converged,
            "reason": bundle.reason,
            "redundancy": bundle.redundancy,
            "cost_history": bundle.cost_history,
        },
        "images": [
            {"name": r[0], "observations": r[1], "rms_px": r[2], "median_px": r[3], "max_px": r[4]}
            for r in rows
        ],
        "gcps": [] if georef is None else georef.gcp_table,
        "gcp_rmse": {} if georef is None else georef.gcp_rmse,
        "check_points": [] if georef is None else georef.check_table,
        "check_rmse": {} if georef is None else georef.check_rmse,
        "check_notes": check_notes,
        "multiplicity_histogram": np.bincount(multiplicity.astype(np.int64)).tolist()
        if len(multiplicity)
        else [],
    }
    _figures(rep, centers_world, points_world, multiplicity, obs_xy, res, georef, cameras)
    return rep


def _check_notes(georef, centers_world, points_world, cameras) -> list[str]:
    """The check-point explanation (:func:`.accuracy.check_point_notes`) of a georeferenced block."""
    if georef is None or not georef.check_table:
        return []
    ctrl = georef.gcp_table
    xyz = np.array([[r["x"], r["y"], r["z"]] for r in ctrl]).reshape(-1, 3)
    sig = None
    if ctrl and all("sigma_xy" in r for r in ctrl):
        sig = np.array([[r["sigma_xy"], r["sigma_xy"], r["sigma_z"]] for r in ctrl])
    return check_point_notes(
        control_geometry(xyz, sig),
        georef.check_rmse,
        _gsd(centers_world, points_world, cameras),
        len(georef.check_table),
        {r["name"]: int(r["views"]) for r in ctrl},
    )


def _gsd(centers_world, points_world, cameras) -> float:
    """Median ground sample distance, metres: camera height above the median tie point over f."""
    if not len(centers_world) or not len(points_world) or not cameras:
        return float("nan")
    height = float(np.median(centers_world[:, 2]) - np.median(points_world[:, 2]))
    f = float(np.median([c.fx for c in cameras]))
    return height / f if height > 0 and f > 0 else float("nan")


def _gcp_table(title, rows, rmse, note: str = "") -> Table:
    out = [
        [
            r["name"],
            r["dx"],
            r["dy"],
            r["dz"],
            float(np.sqrt(r["dx"] ** 2 + r["dy"] ** 2 + r["dz"] ** 2)),
            r["views"],
        ]
        for r in rows
    ]
    if rmse:
        out.append(["RMSE", rmse["x"], rmse["y"], rmse["z"], rmse["3d"], rmse["n"]])
    return Table(title, ["name", "dX [m]", "dY [m]", "dZ [m]", "3D [m]", "images"], out, note)


def _figures(rep, centers, points, mult, obs_xy, res, georef, cameras) -> None:
    plt = _plt()
    # block overview
    fig, ax = plt.subplots(figsize=(6, 6))
    if len(points):
        sub = points[:: max(1, len(points) // 20000)]
        ax.scatter(sub[:, 0], sub[:, 1], s=0.5, c=sub[:, 2], cmap="terrain")
    if len(centers):
        ax.plot(centers[:, 0], centers[:, 1], "r^", ms=5, label="projection centres")
    ax.set_aspect("equal")
    ax.set_xlabel("X [m]")
    ax.set_ylabel("Y [m]")
    ax.legend(loc="best", fontsize=8)
    rep.add_figure("Block overview: projection centres and tie points (colour: height)", fig)
    # multiplicity histogram
    if len(mult):
        fig, ax = plt.subplots(figsize=(5, 3))
        ax.hist(mult, bins=np.arange(1.5, mult.max() + 1.5), color="steelblue")
        ax.set_xlabel("images per tie point")
        ax.set_ylabel("tie points")
        rep.add_figure("Tie-point multiplicity", fig)
    # residual vectors over the sensor (binned means)
    ok = np.all(np.isfinite(res), axis=1) if len(res) else np.zeros(0, bool)
    if ok.sum() > 10 and cameras:
        w, h = cameras[0].width, cameras[0].height
        nx, ny = 12, max(2, int(round(12 * h / w)))
        ix = np.clip((obs_xy[ok, 0] / w * nx).astype(int), 0, nx - 1)
        iy = np.clip((obs_xy[ok, 1] / h * ny).astype(int), 0, ny - 1)
        cnt = np.zeros((ny, nx))
        sx = np.zeros((ny, nx))
        sy = np.zeros((ny, nx))
        np.add.at(cnt, (iy, ix), 1)
        np.add.at(sx, (iy, ix), res[ok, 0])
        np.add.at(sy, (iy, ix), res[ok, 1])
        with np.errstate(invalid="ignore"):
            mx, my = sx / cnt, sy / cnt
        gx, gy = np.meshgrid((np.arange(nx) + 0.5) * w / nx, (np.arange(ny) + 0.5) * h / ny)
        fig, ax = plt.subplots(figsize=(6, 6 * h / w + 0.5))
        ax.quiver(gx, gy, mx, -my, angles="xy")
        ax.set_xlim(0, w)
        ax.set_ylim(h, 0)
        ax.set_aspect("equal")
        ax.set_title("mean image residual per cell (arrows not to scale)", fontsize=9)
        rep.add_figure("Image residual vectors over the sensor", fig)
    # GCP / check residual vectors in plan, at the points' positions
    if georef is not None and (georef.gcp_table or georef.check_table):
        rows_all = list(georef.gcp_table) + list(georef.check_table)
        xy = np.array([[r["x"], r["y"]] for r in rows_all])
        d = np.array([[r["dx"], r["dy"]] for r in rows_all])
        extent = max(float(np.ptp(xy[:, 0])), float(np.ptp(xy[:, 1])), 1.0)
        scale = 0.15 * extent / max(float(np.abs(d).max()), 1e-9)
        fig, ax = plt.subplots(figsize=(6, 6))
        for rows, colour, label in (
            (georef.gcp_table, "tab:blue", "GCP"),
            (georef.check_table, "tab:red", "check"),
        ):
            if rows:
                p = np.array([[r["x"], r["y"]] for r in rows])
                v = np.array([[r["dx"], r["dy"]] for r in rows]) * scale
                ax.quiver(
                    p[:, 0],
                    p[:, 1],
                    v[:, 0],
                    v[:, 1],
                    color=colour,
                    label=label,
                    angles="xy",
                    scale_units="xy",
                    scale=1,
                )
                ax.plot(p[:, 0], p[:, 1], "o", color=colour, ms=3)
                for (px, py), r in zip(p, rows, strict=True):
                    ax.annotate(r["name"], (px, py), fontsize=7)
        ax.set_aspect("equal")
        ax.set_title(f"plan residuals, exaggerated {scale:.0f}x", fontsize=9)
        ax.legend(fontsize=8)
        rep.add_figure("Control and check point residual vectors (plan)", fig)
