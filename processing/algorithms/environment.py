"""``truortho:environment``: report the versions TruOrtho runs with.

Writes a JSON file with the versions of QGIS, the GDAL QGIS uses, rasterio and
the GDAL rasterio is linked to, numpy, numba, OpenCV and pyproj, and fails if
rasterio's GDAL is not QGIS's GDAL (two GDALs in one process corrupt each
other's drivers and CRS handling).
"""

from __future__ import annotations

import importlib
import json
import os
import platform
import sys

from qgis.core import (
    Qgis,
    QgsProcessingAlgorithm,
    QgsProcessingException,
    QgsProcessingOutputString,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterFileDestination,
)

from ..i18n import tr


def qgis_gdal_version() -> str:
    """GDAL version QGIS itself runs with (``osgeo.gdal`` is the same library)."""
    from osgeo import gdal

    return str(gdal.__version__)


def _module_version(name: str, attr: str = "__version__") -> str | None:
    try:
        module = importlib.import_module(name)
    except Exception:  # missing or broken optional package: report, don't crash
        return None
    value = getattr(module, attr, None)
    return None if value is None else str(value)


def collect_versions() -> dict[str, str | None]:
    """Versions of everything TruOrtho depends on (None when not importable)."""
    return {
        "truortho": _plugin_version(),
        "truortho_path": _plugin_dir(),
        "qgis": Qgis.version(),
        "qgis_gdal": qgis_gdal_version(),
        "python": platform.python_version(),
        "python_executable": sys.executable,
        "rasterio": _module_version("rasterio"),
        "rasterio_gdal": _module_version("rasterio", "__gdal_version__"),
        "numpy": _module_version("numpy"),
        "scipy": _module_version("scipy"),
        "numba": _module_version("numba"),
        "opencv": _module_version("cv2"),
        "pyproj": _module_version("pyproj"),
        "proj": _module_version("pyproj", "proj_version_str"),
        "shapely": _module_version("shapely"),
        "laspy": _module_version("laspy"),
    }


def _plugin_dir() -> str:
    from ..provider import PLUGIN_DIR

    return PLUGIN_DIR


def _plugin_version() -> str:
    from ..provider import _version

    return _version()


class EnvironmentAlgorithm(QgsProcessingAlgorithm):
    OUTPUT = "OUTPUT"
    VERSIONS = "VERSIONS"
    CLEAR_CACHE = "CLEAR_CACHE"
    #: parameter defaults no core config defines (see TruOrthoAlgorithm.CONFIG_DEFAULTS)
    OWN_DEFAULTS = {CLEAR_CACHE: "an action of this run, not a setting: off"}

    def name(self) -> str:
        return "environment"

    def displayName(self) -> str:  # noqa: N802 - QGIS API
        return tr("Check environment")

    def group(self) -> str:
        return tr("Tools")

    def groupId(self) -> str:  # noqa: N802 - QGIS API
        return "tools"

    def shortHelpString(self) -> str:  # noqa: N802 - QGIS API
        return tr(
            "Reports the versions of QGIS, GDAL, rasterio, numpy, numba, OpenCV and pyproj "
            "that TruOrtho runs with, and writes them to a JSON file. Fails if rasterio is "
            "linked to a different GDAL than QGIS. Also reports TruOrtho's cache folder (compiled "
            "kernels and image features; the environment variable TRUORTHO_CACHE_DIR moves it, "
            "default the per-user cache folder of the system) and its size; CLEAR_CACHE empties it."
        )

    def createInstance(self) -> EnvironmentAlgorithm:  # noqa: N802 - QGIS API
        return EnvironmentAlgorithm()

    def initAlgorithm(self, config=None) -> None:  # noqa: N802 - QGIS API
        self.addParameter(
            QgsProcessingParameterFileDestination(
                self.OUTPUT, tr("Versions (JSON)"), tr("JSON files (*.json)")
            )
        )
        self.addParameter(
            QgsProcessingParameterBoolean(
                self.CLEAR_CACHE,
                tr("Clear the cache (compiled kernels, image features)"),
                False,
                optional=True,
            )
        )
        self.addOutput(QgsProcessingOutputString(self.VERSIONS, tr("Versions as JSON text")))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 - QGIS API
        from ...core.cache import cache_root, cache_size, clear_cache

        if self.parameterAsBool(parameters, self.CLEAR_CACHE, context):
            freed = clear_cache()
            feedback.pushInfo(tr("Cache cleared: {:.1f} MB freed").format(freed / 1e6))
        versions = collect_versions()
        versions["cache_dir"] = str(cache_root())
        versions["cache_mb"] = f"{cache_size() / 1e6:.1f}"
        for key, value in versions.items():
            feedback.pushInfo(f"{key}: {value if value is not None else tr('not available')}")

        missing = [k for k in ("rasterio", "numpy", "numba", "opencv", "pyproj") if versions[k] is None]
        if missing:
            feedback.reportError(tr("Not importable: {}").format(", ".join(missing)), False)

        if versions["rasterio"] is not None and versions["rasterio_gdal"] != versions["qgis_gdal"]:
            message = tr("rasterio is linked to GDAL {} but QGIS uses GDAL {}: use Debian's python3-rasterio")
            raise QgsProcessingException(message.format(versions["rasterio_gdal"], versions["qgis_gdal"]))

        path = self.parameterAsFileOutput(parameters, self.OUTPUT, context)
        text = json.dumps(versions, indent=2, sort_keys=True, ensure_ascii=False)
        if path:
            os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
            with open(path, "w", encoding="utf-8") as fh:
                fh.write(text + "\n")
        feedback.setProgress(100)
        return {self.OUTPUT: path, self.VERSIONS: text}
