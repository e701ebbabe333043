"""Reports as data: a JSON document plus a self-contained HTML rendering.

Every stage returns plain numbers (dicts of floats, lists, tables) that are
saved as JSON for machines and rendered here for people. Figures are
matplotlib PNGs embedded as base64, so the HTML opens offline.

:func:`pipeline_report` assembles the whole chain's report (the orientation's part, the DSM
hillshade, the true-ortho preview); :func:`reused_orientation_report` reads the orientation's
part back from an earlier ``report.json``.
"""

from __future__ import annotations

import base64
import html
import io
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .orientation import atomic_write_text


@dataclass
class Table:
    """A table: ``columns`` names and ``rows`` of values (numbers formatted on render)."""

    title: str
    columns: list[str]
    rows: list[list]
    note: str = ""


@dataclass
class Report:
    """A report under construction: key figures, tables, figures and free JSON data."""

    title: str
    summary: dict = field(default_factory=dict)
    tables: list[Table] = field(default_factory=list)
    figures: list[tuple[str, str]] = field(default_factory=list)  # (caption, base64 PNG)
    data: dict = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)

    def add_figure(self, caption: str, fig) -> None:
        """Embed a matplotlib figure (closed afterwards)."""
        import matplotlib.pyplot as plt

        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
        plt.close(fig)
        self.figures.append((caption, base64.b64encode(buf.getvalue()).decode("ascii")))

    def to_json(self) -> dict:
        return _clean(
            {
                "title": self.title,
                "summary": self.summary,
                "tables": [
                    {"title": t.title, "columns": t.columns, "rows": t.rows, "note": t.note}
                    for t in self.tables
                ],
                "warnings": self.warnings,
                "data": self.data,
            }
        )

    def to_html(self) -> str:
        esc = html.escape
        out = [
            "<!DOCTYPE html><html><head><meta charset='utf-8'>",
            f"<title>{esc(self.title)}</title><style>{_CSS}</style></head><body>",
            f"<h1>{esc(self.title)}</h1>",
        ]
        if self.warnings:
            out.append("<div class='warn'><b>Warnings</b><ul>")
            out += [f"<li>{esc(w)}</li>" for w in self.warnings]
            out.append("</ul></div>")
        if self.summary:
            out.append("<table class='kv'>")
            for k, v in self.summary.items():
                out.append(f"<tr><th>{esc(str(k))}</th><td>{esc(_fmt(v))}</td></tr>")
            out.append("</table>")
        for t in self.tables:
            out.append(f"<h2>{esc(t.title)}</h2><table><tr>")
            out += [f"<th>{esc(c)}</th>" for c in t.columns]
            out.append("</tr>")
            for row in t.rows:
                out.append("<tr>" + "".join(f"<td>{esc(_fmt(v))}</td>" for v in row) + "</tr>")
            out.append("</table>")
            if t.note:
                out.append(f"<p class='note'>{esc(t.note)}</p>")
        for caption, png in self.figures:
            out.append(f"<figure><img src='data:image/png;base64,{png}' alt='{esc(caption)}'>")
            out.append(f"<figcaption>{esc(caption)}</figcaption></figure>")
        out.append("</body></html>")
        return "\n".join(out)

    @classmethod
    def from_json(cls, d: dict) -> Report:
        """A report from its JSON document (:meth:`to_json`; figures are not in the JSON)."""
        return cls(
            str(d.get("title", "")),
            dict(d.get("summary", {})),
            [Table(t["title"], t["columns"], t["rows"], t.get("note", "")) for t in d.get("tables", [])],
            [],
            dict(d.get("data", {})),
            list(d.get("warnings", [])),
        )

    def save(
        self, html_path: str | os.PathLike, json_path: str | os.PathLike | None = None
    ) -> tuple[str, str]:
        """Write the HTML and the JSON (default: same name, ``.json``) atomically."""
        hp = Path(html_path)
        jp = Path(json_path) if json_path is not None else hp.with_suffix(".json")
        atomic_write_text(jp, json.dumps(self.to_json(), indent=1, allow_nan=False))
        atomic_write_text(hp, self.to_html())
        return str(hp), str(jp)


#: Tables :func:`pipeline_report` adds after the orientation's (they belong to one run of the chain; a
#: reused orientation's report drops them); the stage table comes last (the workflow fills it in).
_CHAIN_TABLES = ("Dense matching and DSM filter", "Colour correction", "Stages")


def reused_orientation_report(json_path: str | os.PathLike) -> Report | None:
    """The orientation's part of an earlier pipeline report (``report.json``), or None.

    Keeps the tables and the summary entries of the orientation; those of the rest of the chain
    (dense matching and DSM filter, stages, DSM, true orthophoto, totals, executor) belong to the
    new run.
    """
    p = Path(json_path)
    if not p.exists():
        return None
    try:
        d = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    old = Report.from_json(d)
    rep = Report("orientation (reused)")
    rep.tables = [t for t in old.tables if t.title not in _CHAIN_TABLES]
    this_run = ("DSM", "true", "total", "tiles")  # the rest of the chain, not the orientation
    rep.summary = {k: v for k, v in old.summary.items() if not str(k).startswith(this_run)}
    return rep


def pipeline_report(
    title: str,
    orient_report: Report | None,
    orientation,
    osgm,
    fstats,
    dsm_path,
    ortho_path,
    tres,
    reused: bool,
    confidence_path=None,
) -> Report:
    """The whole chain's report (:func:`truortho.core.workflow.run_workflow`), but its stage table.

    Parameters
    ----------
    title : str
    orient_report : Report or None
        The orientation's report (tables, figures, warnings are taken over).
    orientation : Orientation
    osgm : OsgmResult
        Dense matching (``stats``, ``summary()``).
    fstats : DsmFilterStats
        The DSM filter's statistics.
    dsm_path, ortho_path : path
        The filtered DSM and the true orthophoto (read for the hillshade and the preview).
    tres : TrueOrthoResult
        The true orthophoto's result (``stats``: coverage, occluded cells, size).
    reused : bool
        The orientation was read from an existing file.
    confidence_path : path, optional
        OSGM's confidence raster, for its histogram.

    Returns
    -------
    Report
        Ending with an empty "Stages" table (stage, time [s], peak memory [MB], result) for the
        caller to fill.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .rasterio_io import read_preview, valid_share

    report = Report(title)
    if orient_report is not None:
        report.data["orientation"] = orient_report.data
        report.summary.update(orient_report.summary)
        report.tables.extend(orient_report.tables)
        report.figures.extend(orient_report.figures)
        report.warnings.extend(orient_report.warnings)
    if reused:
        report.warnings.append("The orientation was reused from orientation.json (not recomputed).")
    report.summary["images oriented"] = len(orientation.images)
    report.summary["CRS"] = orientation.crs
    s = osgm.stats
    report.data["osgm"] = s
    report.data["filter"] = fstats.as_dict()
    report.data["trueortho"] = {k: v for k, v in tres.stats.items() if isinstance(v, int | float | str)}
    report.summary["DSM resolution [m]"] = s["resolution"]
    report.summary["DSM completeness (raw) [%]"] = round(100 * s["completeness"], 2)
    # previews (from the overviews): a large block's full DSM and ortho are never read at once
    dsm, grid, _ = read_preview(dsm_path, 1200)
    filtered_share = valid_share(dsm_path)
    report.summary["DSM completeness (filtered) [%]"] = round(100 * filtered_share, 2)
    st = tres.stats
    occl = float(st.get("cells_occluded", 0)) / max(1, int(st.get("rows", 1)) * int(st.get("cols", 1)))
    report.summary["true ortho coverage [%]"] = round(100 * float(st["coverage"]), 2)
    report.summary["true ortho occluded share [%]"] = round(100 * occl, 2)
    report.tables.append(
        Table(_CHAIN_TABLES[0], ["what", "value"], [["OSGM", osgm.summary()], ["filter", fstats.summary()]])
    )
    # DSM hillshade
    fig, ax = plt.subplots(figsize=(7, 6))
    z = np.where(np.isfinite(dsm), dsm, np.nanmedian(dsm) if np.isfinite(dsm).any() else 0)
    gy, gx = np.gradient(z, grid.res)
    slope = np.pi / 2 - np.arctan(np.hypot(gx, gy))
    aspect = np.arctan2(-gx, gy)
    az, alt = np.radians(315), np.radians(45)
    shade = np.sin(alt) * np.sin(slope) + np.cos(alt) * np.cos(slope) * np.cos(az - aspect)
    ext = (grid.extent[0], grid.extent[2], grid.extent[1], grid.extent[3])
    ax.imshow(np.where(np.isfinite(dsm), shade, np.nan), cmap="gray", extent=ext)
    im = ax.imshow(np.where(np.isfinite(dsm), dsm, np.nan), cmap="terrain", alpha=0.45, extent=ext)
    fig.colorbar(im, ax=ax, label="height [m]")
    ax.ticklabel_format(useOffset=False, style="plain")
    ax.set_title(f"Filtered DSM ({100 * filtered_share:.1f} % of the cells)")
    report.add_figure("DSM hillshade (filtered DSM)", fig)
    _overlap_figure(report, plt, orientation, dsm_path)
    if confidence_path is not None:
        _confidence_figure(report, plt, confidence_path)
    # true ortho preview
    ortho, og, _ = read_preview(ortho_path, 1200, band=None)
    o = np.moveaxis(ortho, 0, -1)
    fig, ax = plt.subplots(figsize=(7, 6))
    if o.shape[2] >= 4:
        rgb = o[:, :, :3].astype(np.float32)
        if rgb.max() > 255:
            rgb = rgb / max(float(rgb.max()), 1.0) * 255
        alpha = o[:, :, -1] > 0
        show = np.where(alpha[..., None], rgb, 0).astype(np.uint8)
    else:
        show = o[:, :, 0]
    oext = (og.extent[0], og.extent[2], og.extent[1], og.extent[3])
    ax.imshow(show, extent=oext)
    ax.ticklabel_format(useOffset=False, style="plain")
    ax.set_title(f"True orthophoto (black: seen by no image, {100 * occl:.2f} %)")
    report.add_figure("True orthophoto preview", fig)
    cc = tres.stats.get("color_correction")
    if isinstance(cc, dict) and cc.get("images"):
        report.data["trueortho"]["color_correction"] = cc
        report.tables.append(colour_table(cc))
        before, after = cc.get("median_before"), cc.get("median_after")
        if before and after:
            report.summary["true ortho colour disagreement between photos (median, before -> after)"] = (
                f"{before[0]:.2f} -> {after[0]:.2f} ({'L*' if 'L*a*b*' in cc.get('model', '') else 'band 1'})"
            )
    report.tables.append(Table(_CHAIN_TABLES[-1], ["stage", "time [s]", "peak memory [MB]", "result"], []))
    return report


def colour_table(cc: dict) -> Table:
    """The true ortho's colour correction per photo (:meth:`ColorCorrection.as_dict`): vignetting at
    the corner, the RGB stage's gains and offsets (data units) and the L*a*b* (or per-band) ones."""
    lab = "L*a*b*" in str(cc.get("model", ""))
    rgb = any("rgb_gain" in r for r in cc["images"])
    columns = ["photo", "vignetting at the corner"]
    if rgb:
        columns += ["gain R / G / B", "offset R / G / B"]
    columns += ["gain L* / a* / b*", "offset L* / a* / b*"] if lab else ["gain per band", "offset per band"]

    def values(v) -> str:
        return " / ".join(f"{float(x):.3f}" for x in v)

    rows = []
    for r in cc["images"]:
        row = [r["image"], float(r.get("vignetting_at_corner", 1.0))]
        if rgb:
            row += [values(r.get("rgb_gain", [])), values(r.get("rgb_offset", []))]
        rows.append(row + [values(r["gain"]), values(r["offset"])])
    note = f"Model: {cc.get('model', '?')}; estimated from {cc.get('pairs_used', '?')} pairs of observations."
    return Table(_CHAIN_TABLES[1], columns, rows, note)


def photo_counts(orientation, dsm, grid) -> np.ndarray:
    """How many photos see each cell of ``dsm`` (on ``grid``, world heights; NaN cells at the median
    height): the cell's surface point in front of the camera and inside the frame. Occlusion is not
    tested (this is the coverage of the flight, not of the true orthophoto)."""
    from .errors import InputError
    from .geometry import project_points

    dsm = np.asarray(dsm)
    if dsm.shape != grid.shape:
        raise InputError(f"photo_counts: heights of shape {dsm.shape} for a grid of {grid.shape}")
    X, Y = grid.centres()
    z = np.where(np.isfinite(dsm), dsm, np.nanmedian(dsm) if np.isfinite(dsm).any() else 0.0)
    off = np.asarray(orientation.offset, np.float64)
    P = np.column_stack([X.ravel() - off[0], Y.ravel() - off[1], z.ravel() - off[2]])
    count = np.zeros(len(P), np.int32)
    for im in orientation.images:
        cam = orientation.camera_of(im)
        uv, depth = project_points(P, im.R, im.C, cam, return_depth=True)
        u, v = uv[:, 0], uv[:, 1]
        with np.errstate(invalid="ignore"):  # NaN: behind the camera
            count += (
                (depth > 0) & (u >= -0.5) & (v >= -0.5) & (u <= cam.width - 0.5) & (v <= cam.height - 0.5)
            )
    return count.reshape(grid.shape)


def _overlap_figure(report: Report, plt, orientation, dsm_path) -> None:
    """Coverage and overlap: photos per DSM cell on a preview of at most 300 cells a side."""
    from .rasterio_io import read_preview

    dsm, grid, _ = read_preview(dsm_path, 300)
    count = photo_counts(orientation, dsm, grid)
    fig, ax = plt.subplots(figsize=(7, 6))
    top = max(int(count.max()), 1)
    cmap = plt.get_cmap("viridis", top + 1)
    ext = (grid.extent[0], grid.extent[2], grid.extent[1], grid.extent[3])
    im = ax.imshow(np.where(count > 0, count, np.nan), cmap=cmap, vmin=-0.5, vmax=top + 0.5, extent=ext)
    fig.colorbar(im, ax=ax, label="photos that see the cell", ticks=range(0, top + 1, max(1, top // 10)))
    inside = np.isfinite(dsm)
    low = float((count[inside] < 2).mean()) if inside.any() else 0.0
    ax.ticklabel_format(useOffset=False, style="plain")
    ax.set_title(f"{100 * low:.1f} % of the DSM's cells are seen by fewer than 2 photos", fontsize=10)
    report.add_figure("Coverage and overlap (photos per cell)", fig)
    report.data["coverage"] = {
        "photos_per_cell_histogram": np.bincount(count[inside].ravel(), minlength=top + 1).tolist(),
        "share_below_2": low,
    }


def _confidence_figure(report: Report, plt, confidence_path) -> None:
    """Histogram of OSGM's matching confidence (0 to 1) over the cells it matched."""
    from .rasterio_io import read_preview

    conf, _, _ = read_preview(confidence_path, 1200)
    values = conf[np.isfinite(conf) & (conf >= 0)]
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.hist(values, bins=40, range=(0, 1), color="#4477aa")
    ax.set_xlabel("matching confidence (1 - best / second-best cost)")
    ax.set_ylabel("cells")
    med = float(np.median(values)) if len(values) else float("nan")
    ax.set_title(f"DSM confidence: median {med:.2f} over {len(values)} cells (preview)")
    report.add_figure("DSM confidence histogram", fig)


def _fmt(v) -> str:
    if isinstance(v, float | np.floating):
        f = float(v)
        if not math.isfinite(f):
            return "–"
        return f"{f:.4g}" if abs(f) < 1e5 else f"{f:.2f}"
    return str(v)


def _clean(obj):
    """JSON-safe copy: numpy scalars/arrays to Python, NaN/inf to None."""
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _clean(obj.tolist())
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, float | np.floating):
        f = float(obj)
        return f if math.isfinite(f) else None
    return obj


_CSS = """
body{font-family:sans-serif;margin:2em;max-width:1100px;color:#222}
table{border-collapse:collapse;margin:.5em 0}
th,td{border:1px solid #ccc;padding:3px 8px;text-align:right}
th{background:#f0f0f0}
table.kv th{text-align:left}
.warn{background:#fff4e0;border:1px solid #e0a040;padding:.5em 1em}
figure{display:inline-block;margin:1em}
.note{color:#555;font-size:90%}
"""
