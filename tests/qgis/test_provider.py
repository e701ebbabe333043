"""The provider registers with QGIS Processing and its algorithms run."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

pytestmark = pytest.mark.qgis

REPO_ROOT = Path(__file__).resolve().parents[2]


def test_provider_registered(truortho_provider):
    from qgis.core import QgsApplication

    assert truortho_provider.id() == "truortho"
    assert truortho_provider.name() == "TruOrtho"
    assert "TruOrtho" in truortho_provider.longName()
    assert not truortho_provider.icon().isNull()
    alg = QgsApplication.processingRegistry().algorithmById("truortho:environment")
    assert alg is not None
    assert alg.displayName()


def test_algorithms_list_matches_provider(truortho_provider):

    from truortho.processing.algorithms import ALGORITHMS
    from truortho.processing.provider import MODELS_DIR

    ids = {alg.id() for alg in truortho_provider.algorithms()}
    models = {f"truortho:{n[: -len('.model3')]}" for n in os.listdir(MODELS_DIR) if n.endswith(".model3")}
    assert models  # the shipped model (processing/models/) is an algorithm of the provider
    assert ids == {f"truortho:{cls().name()}" for cls in ALGORITHMS} | models


def test_unload_removes_and_init_readds(truortho_plugin):
    from qgis.core import QgsApplication

    registry = QgsApplication.processingRegistry()
    truortho_plugin.unload()
    assert registry.providerById("truortho") is None
    truortho_plugin.initProcessing()
    truortho_plugin.initProcessing()  # idempotent
    assert registry.providerById("truortho") is not None


def test_environment_algorithm_runs(truortho_provider, tmp_path):
    import processing
    import rasterio
    from osgeo import gdal
    from qgis.core import Qgis

    out = tmp_path / "env.json"
    result = processing.run("truortho:environment", {"OUTPUT": str(out)})
    assert result["OUTPUT"] == str(out)
    versions = json.loads(out.read_text())
    assert versions == json.loads(result["VERSIONS"])
    assert versions["qgis"] == Qgis.version()
    # One GDAL in the process: rasterio must be linked to the GDAL QGIS uses.
    assert versions["rasterio_gdal"] == versions["qgis_gdal"] == gdal.__version__
    assert rasterio.__gdal_version__ == gdal.__version__
    assert versions["numpy"].startswith("1.")
    for key in ("numba", "opencv", "pyproj", "rasterio"):
        assert versions[key], key


def test_environment_algorithm_rejects_foreign_gdal(truortho_provider, tmp_path, monkeypatch):
    import processing
    from qgis.core import QgsProcessingException

    from truortho.processing.algorithms import environment

    monkeypatch.setattr(environment, "qgis_gdal_version", lambda: "0.0.0")
    with pytest.raises(QgsProcessingException, match="GDAL"):
        processing.run("truortho:environment", {"OUTPUT": str(tmp_path / "env.json")})




@pytest.fixture(scope="module")
def set_up():
    if not (REPO_ROOT / ".venv" / "qgis-config").is_dir():
        pytest.fail("run scripts/setup.sh (make setup) first: no .venv/qgis-config")


def test_qgis_process_lists_algorithm(set_up, run_qgis_process):
    proc = run_qgis_process("list")
    assert proc.returncode == 0, proc.stderr
    assert "truortho:environment" in proc.stdout, proc.stdout + proc.stderr


def test_qgis_process_runs_environment(set_up, tmp_path, run_qgis_process):
    out = tmp_path / "env.json"
    proc = run_qgis_process("run", "truortho:environment", "--", f"OUTPUT={out}")
    assert proc.returncode == 0, proc.stdout + proc.stderr
    versions = json.loads(out.read_text())
    assert versions["rasterio_gdal"] == versions["qgis_gdal"]
    # qgis_process.bin embeds /usr/bin/python3; the wrapper makes venv packages visible.
    assert versions["numba"] and versions["opencv"], versions
