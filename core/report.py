"""Reports as data: a JSON document plus a self-contained HTML rendering.

Every stage returns plain numbers (dicts of floats, lists, tables) that are
saved as JSON for machines and rendered here for people. Figures are
matplotlib PNGs embedded as base64, so the HTML opens offline.
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

    def save(
        self, html_path: str | os.PathLike, json_path: str | os.PathLike | None = None
    ) -> tuple[str, str]:
        """Write the HTML and the JSON (default: same name, ``.json``) atomically."""
        hp = Path(html_path)
        jp = Path(json_path) if json_path is not None else hp.with_suffix(".json")
        atomic_write_text(jp, json.dumps(self.to_json(), indent=1, allow_nan=False))
        atomic_write_text(hp, self.to_html())
        return str(hp), str(jp)


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
