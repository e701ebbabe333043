"""The plugin zip: built by scripts/build_zip.py, installed into a clean profile, enabled, run."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.qgis


@pytest.fixture(scope="module")
def plugin_zip(tmp_path_factory):
    out = tmp_path_factory.mktemp("dist")
    script = REPO_ROOT / "scripts" / "build_zip.py"
    proc = subprocess.run(
        [sys.executable, "-P", str(script), "--output", str(out)], capture_output=True, text=True
    )
    assert proc.returncode == 0, proc.stderr
    (zpath,) = out.glob("truortho-*.zip")
    return zpath


def test_zip_layout(plugin_zip):
    with zipfile.ZipFile(plugin_zip) as zf:
        names = zf.namelist()
    assert all(n.startswith("truortho/") for n in names)
    for required in (
        "truortho/__init__.py",
        "truortho/metadata.txt",
        "truortho/LICENSE",
        "truortho/processing/provider.py",
        "truortho/core/jit.py",
        "truortho/icon.png",
    ):
        assert required in names
    for banned in ("tests/", "bench/", "scripts/", ".ci/", ".git/"):
        assert not any(n.startswith("truortho/" + banned) for n in names), banned
    assert not any(n.endswith((".pyc", ".ts")) or "__pycache__" in n for n in names)
    size = plugin_zip.stat().st_size
    assert size < 20e6, f"zip is {size / 1e6:.1f} MB"


def test_zip_installs_into_clean_profile_and_runs(plugin_zip, tmp_path):
    plugins = tmp_path / "plugins"
    plugins.mkdir()
    with zipfile.ZipFile(plugin_zip) as zf:
        zf.extractall(plugins)
    env = dict(os.environ)
    env.update(
        QGIS_PLUGINPATH=str(plugins),
        QGIS_CUSTOM_CONFIG_PATH=str(tmp_path / "profile"),
        QT_QPA_PLATFORM="offscreen",
    )
    enable = subprocess.run(
        ["qgis_process.bin", "plugins", "enable", "truortho"],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert enable.returncode == 0, enable.stdout + enable.stderr
    ini = tmp_path / "profile" / "profiles" / "default" / "QGIS" / "QGIS3.ini"
    assert "truortho=true" in ini.read_text()
    out = tmp_path / "env.json"
    run = subprocess.run(
        ["qgis_process.bin", "run", "truortho:environment", "--", f"OUTPUT={out}"],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    info = json.loads(out.read_text())
    # the algorithm ran from the unpacked zip, not from the repository
    assert Path(info["truortho_path"]).resolve() == (plugins / "truortho").resolve()
    assert info["rasterio_gdal"] == info["qgis_gdal"]
