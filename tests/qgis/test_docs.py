"""The documentation cannot drift from the code: docs/algorithms.md is generated from the algorithms
(scripts/make_docs.py) and must equal a fresh generation; every algorithm and parameter is in it; the
README's two commands are the ones CI runs."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import pytest

pytestmark = pytest.mark.qgis

REPO_ROOT = Path(__file__).resolve().parents[2]


def _make_docs():
    path = REPO_ROOT / "scripts" / "make_docs.py"
    spec = importlib.util.spec_from_file_location("_truortho_make_docs", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_algorithms_page_is_fresh_and_complete(truortho_provider):
    page = (REPO_ROOT / "docs" / "algorithms.md").read_text(encoding="utf-8")
    assert page == _make_docs().render(truortho_provider), "docs/algorithms.md is stale: run make docs"
    for alg in truortho_provider.algorithms():
        section = page.split(f"(`{alg.id()}`)\n", 1)
        assert len(section) == 2, f"{alg.id()} has no section"
        body = section[1].split("\n## ", 1)[0]
        for p in alg.parameterDefinitions():
            assert f"`{p.name()}`" in body, f"{alg.id()}: parameter {p.name()} is not documented"


def test_user_guide_lists_every_product():
    from truortho.core.workflow import PRODUCTS

    docs = _make_docs()
    guide = (REPO_ROOT / "docs" / "user-guide.md").read_text(encoding="utf-8")
    assert guide == docs.with_section(guide, "products", docs.products_table()), "run make docs"
    for name in PRODUCTS.values():
        assert f"`{name}`" in guide, f"product {name} is not in the user guide"


def test_readme_commands_are_what_ci_runs():
    readme = (REPO_ROOT / "README.md").read_text(encoding="utf-8")
    block = re.search(r"## Two commands.*?```sh\n(.*?)```", readme, re.S)
    assert block, "README.md has no 'Two commands' shell block"
    commands = [line.split("#")[0].strip() for line in block.group(1).splitlines() if line.strip()]
    assert commands == ["make demo", "make test"]
    ci = (REPO_ROOT / ".ci" / "run").read_text(encoding="utf-8")
    ci_commands = [
        ln.strip()
        for ln in ci.splitlines()
        if ln.strip() and not ln.lstrip().startswith(("#", "set ", "cd "))
    ]
    assert ci_commands == ["make test"], ci_commands
    assert len(readme.splitlines()) <= 200, "README.md is for a five-minute read: at most 200 lines"
