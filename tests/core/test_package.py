"""The core and the plugin package import without QGIS."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]


def test_core_imports_without_qgis(tmp_path):
    # A fresh interpreter: `truortho` via a symlink (never the repo root on sys.path).
    (tmp_path / "truortho").symlink_to(REPO_ROOT, target_is_directory=True)
    code = (
        "import sys; sys.path.insert(0, sys.argv[1]);"
        "import truortho, truortho.core, truortho.core.errors, truortho.core.progress;"
        "assert callable(truortho.classFactory);"
        "bad = sorted(m for m in sys.modules if m.split('.')[0] in ('qgis', 'PyQt5', 'processing'));"
        "assert not bad, bad"
    )
    proc = subprocess.run([sys.executable, "-c", code, str(tmp_path)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr


def test_errors_hierarchy():
    from truortho.core import errors

    assert issubclass(errors.FormatError, errors.TruOrthoError)
    assert issubclass(errors.FormatError, ValueError)
    assert issubclass(errors.CancelledError, errors.TruOrthoError)
