"""metadata.txt is complete and valid for plugins.qgis.org."""

from __future__ import annotations

import configparser
import re
from pathlib import Path

import pytest

pytestmark = pytest.mark.qgis

REPO_ROOT = Path(__file__).resolve().parents[2]

# Mandatory for plugins.qgis.org uploads, plus the ones this project always sets.
REQUIRED = [
    "name",
    "qgisMinimumVersion",
    "description",
    "about",
    "version",
    "author",
    "email",
    "repository",
    "tracker",
    "homepage",
    "tags",
    "category",
    "icon",
    "experimental",
    "deprecated",
    "hasProcessingProvider",
    "license",
]


@pytest.fixture(scope="module")
def meta() -> configparser.SectionProxy:
    parser = configparser.ConfigParser(interpolation=None)
    parser.optionxform = str  # keys are case sensitive (qgisMinimumVersion)
    assert parser.read(REPO_ROOT / "metadata.txt", encoding="utf-8")
    return parser["general"]


@pytest.mark.parametrize("key", REQUIRED)
def test_required_key_present(meta, key):
    assert meta.get(key, "").strip(), f"metadata.txt: {key} missing or empty"


def test_values(meta):
    assert meta["name"] == "TruOrtho"
    assert re.fullmatch(r"\d+\.\d+\.\d+", meta["version"])
    assert re.fullmatch(r"3\.\d+", meta["qgisMinimumVersion"])
    assert meta["qgisMinimumVersion"] == "3.22"
    assert meta["experimental"] in ("True", "False")
    assert meta["deprecated"] in ("True", "False")
    assert meta["hasProcessingProvider"] == "yes"
    assert meta["repository"].startswith("https://")
    assert meta["tracker"].startswith("https://")
    assert re.fullmatch(r"[^@\s]+@[^@\s]+\.[a-z]+", meta["email"])
    assert len(meta["about"].split(". ")) >= 3, "about should be several sentences"
    tags = [t.strip() for t in meta["tags"].split(",")]
    assert "photogrammetry" in tags and "true orthophoto" in tags
    assert meta["category"] in ("Raster", "Vector", "Database", "Web", "Analysis", "Plugins")


def test_icon_is_a_png(meta):
    from qgis.PyQt.QtGui import QImage

    icon = REPO_ROOT / meta["icon"]
    assert icon.is_file()
    image = QImage(str(icon))
    assert not image.isNull()
    assert (image.width(), image.height()) == (64, 64)


def test_qgis_reads_metadata(qgis_processing_ready):
    """QGIS's own plugin scanner finds the plugin and reads the same metadata."""
    import qgis.utils

    found = dict(qgis.utils.findPlugins(str(REPO_ROOT / ".venv" / "qgis-plugins")))
    if "truortho" not in found:
        pytest.fail("run scripts/setup.sh first: .venv/qgis-plugins/truortho missing")
    cp = found["truortho"]
    assert cp.get("general", "name") == "TruOrtho"
    assert cp.get("general", "qgisMinimumVersion") == "3.22"


def test_license_file():
    text = (REPO_ROOT / "LICENSE").read_text()
    assert "GNU GENERAL PUBLIC LICENSE" in text and "Version 2" in text
