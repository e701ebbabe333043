"""Update the Qt translation sources ``i18n/truortho_<lang>.ts`` from the code.

    python -P scripts/i18n_update.py            # rewrite the .ts files (keeps existing translations)
    python -P scripts/i18n_update.py --check    # exit 1 if a .ts file is out of date

Every user-facing string of ``processing/`` and ``truortho_plugin/`` goes through ``tr()`` in the
context ``TruOrtho`` (:mod:`truortho.processing.i18n`). The strings are collected from the source
without importing it (no QGIS needed):

* literal first arguments of ``tr("...")`` calls (implicit concatenations included);
* ``DISPLAY_NAME`` class attributes (shown through ``tr(self.DISPLAY_NAME)``);
* the values of ``GROUPS`` in ``processing/algorithms/base.py``;
* the labels and ``MENU`` of ``truortho_plugin/plugin.py`` (``ENTRIES``);
* the help texts of ``processing/help`` (summaries, parameter help, notes).

Existing translations are kept; new strings are added as ``unfinished``; strings no longer in
the code are marked ``obsolete`` (kept, so a translation is not lost when a string comes back).
Compiled ``.qm`` files are build products (``scripts/build_zip.py``), never committed.
"""

from __future__ import annotations

import argparse
import ast
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CONTEXT = "TruOrtho"
LANGUAGES = ("de", "fr")
SOURCES = ("processing", "truortho_plugin")


def _literal(node) -> str | None:
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.JoinedStr):
        return None
    return None


def _strings_in(node) -> list[str]:
    """Every string literal inside a (nested) literal container."""
    out = []
    for sub in ast.walk(node):
        s = _literal(sub)
        if s:
            out.append(s)
    return out


def extract(root: Path = ROOT) -> dict[str, str]:
    """``{source text: 'file:line'}`` of every translatable string, in order of appearance."""
    found: dict[str, str] = {}

    def add(text: str, where: str) -> None:
        if text and text.strip() and text not in found:
            found[text] = where

    for top in SOURCES:
        for path in sorted((root / top).rglob("*.py")):
            rel = path.relative_to(root).as_posix()
            tree = ast.parse(path.read_text(encoding="utf-8"), rel)
            help_module = rel == "processing/help/__init__.py"
            for node in ast.walk(tree):
                if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "tr" and node.args:
                    s = _literal(node.args[0])
                    if s is not None:
                        add(s, f"{rel}:{node.lineno}")
                elif isinstance(node, ast.Assign) and len(node.targets) == 1:
                    name = getattr(node.targets[0], "id", None)
                    if name == "DISPLAY_NAME" or (name == "MENU" and top == "truortho_plugin"):
                        s = _literal(node.value)
                        if s:
                            add(s, f"{rel}:{node.lineno}")
                    elif help_module and name and name.endswith("_HELP"):
                        # shared help texts (e.g. _SCHEDULER_HELP) used by several HELP entries
                        s = _literal(node.value)
                        if s:
                            add(s, f"{rel}:{node.lineno}")
                    elif name == "GROUPS" and isinstance(node.value, ast.Dict):
                        for v in node.value.values:
                            for s in _strings_in(v):
                                add(s, f"{rel}:{node.lineno}")
                    elif name == "ENTRIES" and isinstance(node.value, ast.Tuple):
                        for entry in node.value.elts:
                            if isinstance(entry, ast.Tuple) and len(entry.elts) == 2:
                                s = _literal(entry.elts[1])
                                if s:
                                    add(s, f"{rel}:{entry.lineno}")
                elif (
                    help_module
                    and isinstance(node, ast.AnnAssign)
                    and getattr(node.target, "id", "") == "HELP"
                ):
                    _help_strings(node.value, rel, add)
    return found


def _help_strings(node, rel: str, add) -> None:
    """summary / notes / parameter texts of the HELP dict (keys are not translated)."""
    if not isinstance(node, ast.Dict):
        return
    for alg_value in node.values:
        if not isinstance(alg_value, ast.Dict):
            continue
        for key, value in zip(alg_value.keys, alg_value.values, strict=True):
            k = _literal(key) if key is not None else None
            if k in ("summary", "notes"):
                s = _literal(value)
                if s:
                    add(s, f"{rel}:{value.lineno}")
            elif k == "parameters" and isinstance(value, ast.Dict):
                for v in value.values:
                    s = _literal(v)
                    if s:
                        add(s, f"{rel}:{v.lineno}")


def read_ts(path: Path) -> dict[str, tuple[str, str | None]]:
    """``{source: (translation, type attribute or None)}`` of an existing .ts file."""
    if not path.exists():
        return {}
    tree = ET.parse(path)
    out = {}
    for msg in tree.iter("message"):
        src = msg.findtext("source") or ""
        tr_el = msg.find("translation")
        out[src] = (
            (tr_el.text or "") if tr_el is not None else "",
            tr_el.get("type") if tr_el is not None else None,
        )
    return out


def render_ts(lang: str, strings: dict[str, str], old: dict[str, tuple[str, str | None]]) -> str:
    ts = ET.Element("TS", version="2.1", language=lang)
    ctx = ET.SubElement(ts, "context")
    ET.SubElement(ctx, "name").text = CONTEXT
    for src, where in strings.items():
        msg = ET.SubElement(ctx, "message")
        file, line = where.rsplit(":", 1)
        ET.SubElement(msg, "location", filename=f"../{file}", line=line)
        ET.SubElement(msg, "source").text = src
        text, kind = old.get(src, ("", "unfinished"))
        el = ET.SubElement(msg, "translation")
        el.text = text
        if not text or kind == "unfinished":
            el.set("type", "unfinished")
    for src, (text, _kind) in old.items():
        if src not in strings and text:
            msg = ET.SubElement(ctx, "message")
            ET.SubElement(msg, "source").text = src
            ET.SubElement(msg, "translation", type="obsolete").text = text
    ET.indent(ts, space="    ")
    return (
        '<?xml version="1.0" encoding="utf-8"?>\n<!DOCTYPE TS>\n' + ET.tostring(ts, encoding="unicode") + "\n"
    )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="fail if a .ts file would change")
    args = ap.parse_args(argv)
    strings = extract(ROOT)
    stale = []
    for lang in LANGUAGES:
        path = ROOT / "i18n" / f"truortho_{lang}.ts"
        text = render_ts(lang, strings, read_ts(path))
        current = path.read_text(encoding="utf-8") if path.exists() else ""
        if text != current:
            stale.append(path)
            if not args.check:
                path.write_text(text, encoding="utf-8")
        done = (
            sum(1 for t, k in read_ts(path).values() if t and k not in ("unfinished", "obsolete"))
            if not args.check
            else None
        )
        print(
            f"{path.relative_to(ROOT)}: {len(strings)} strings"
            + (f", {done} translated" if done is not None else "")
        )
    if args.check and stale:
        print(
            "out of date: "
            + ", ".join(str(p.relative_to(ROOT)) for p in stale)
            + " (run scripts/i18n_update.py)"
        )
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
