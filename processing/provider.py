"""The TruOrtho Processing provider (id ``truortho``)."""

from __future__ import annotations

import os

from qgis.core import QgsMessageLog, QgsProcessingProvider
from qgis.PyQt.QtGui import QIcon

from .i18n import tr

PLUGIN_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ICON_PATH = os.path.join(PLUGIN_DIR, "icon.png")


def _version() -> str:
    try:
        with open(os.path.join(PLUGIN_DIR, "metadata.txt"), encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("version="):
                    return line.split("=", 1)[1].strip()
    except OSError:
        pass
    return "0"


class TruOrthoProvider(QgsProcessingProvider):
    """Provides the algorithms listed in ``truortho.processing.algorithms.ALGORITHMS``.

    Importing this module needs only QGIS: the algorithm modules import numba,
    OpenCV etc. lazily, so a missing optional package shows up as a clear
    error when an algorithm runs, not as a provider that fails to load.
    """

    def id(self) -> str:
        return "truortho"

    def name(self) -> str:
        return tr("TruOrtho")

    def longName(self) -> str:  # noqa: N802 - QGIS API
        return tr("TruOrtho {} — orientation, dense matching and true orthophotos").format(_version())

    def icon(self) -> QIcon:
        return QIcon(ICON_PATH)

    def svgIconPath(self) -> str:  # noqa: N802 - QGIS API
        return ICON_PATH

    def versionInfo(self) -> str:  # noqa: N802 - QGIS API
        return _version()

    def loadAlgorithms(self) -> None:  # noqa: N802 - QGIS API
        try:
            from .algorithms import ALGORITHMS
        except Exception as err:  # keep QGIS alive; say why nothing loaded
            QgsMessageLog.logMessage(
                tr("TruOrtho algorithms could not be loaded: {}").format(err), "TruOrtho"
            )
            return
        for cls in ALGORITHMS:
            self.addAlgorithm(cls())
