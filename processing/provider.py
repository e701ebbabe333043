"""The TruOrtho Processing provider (id ``truortho``)."""

from __future__ import annotations

import os

from qgis.core import QgsApplication, QgsMessageLog, QgsProcessingModelAlgorithm, QgsProcessingProvider
from qgis.PyQt.QtGui import QIcon

from .i18n import tr

PLUGIN_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ICON_PATH = os.path.join(PLUGIN_DIR, "icon.png")
MODELS_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "models")


def _version() -> str:
    try:
        with open(os.path.join(PLUGIN_DIR, "metadata.txt"), encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("version="):
                    return line.split("=", 1)[1].strip()
    except OSError:
        pass
    return "0"


class _Model(QgsProcessingModelAlgorithm):
    """A shipped model whose help is plain lines, like the algorithms' (:func:`..help.help_text`).

    QGIS renders a model's help map as HTML with escaped quotes, which ``qgis_process help``
    prints as it is (``&#x27;``); the toolbox wraps each line of plain text in a paragraph.
    """

    def shortHelpString(self) -> str:  # noqa: N802 - QGIS API
        content = self.helpContent()
        lines = [str(content.get("ALG_DESC", ""))]
        names = [p.name() for p in self.parameterDefinitions()] + [o.name() for o in self.outputDefinitions()]
        for name in names:
            # model outputs are named "<child>:<output>", their help under "<output>"
            text = content.get(name) or content.get(name.split(":")[-1])
            if text:
                lines.append(f"{name}: {text}")
        return "\n".join(line.replace("\n", " ") for line in lines if line)


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
        self._load_models()

    def _load_models(self) -> None:
        """The Processing models shipped in ``processing/models/*.model3`` (ids ``truortho:<name>``)."""
        try:
            names = sorted(n for n in os.listdir(MODELS_DIR) if n.endswith(".model3"))
        except OSError:
            return
        for name in names:
            model = _Model()
            if model.fromFile(os.path.join(MODELS_DIR, name)):
                self.addAlgorithm(model)
            else:
                QgsMessageLog.logMessage(tr("TruOrtho model {} could not be loaded").format(name), "TruOrtho")
        registry = QgsApplication.processingRegistry()
        if names and registry.providerById(self.id()) is None:
            # First load (inside addProvider): the models' child algorithms (truortho:*) are not in
            # the registry yet, so attach them once this provider is registered.
            registry.providerAdded.connect(self._attach_models)

    def _attach_models(self, provider_id: str) -> None:
        if provider_id != self.id():
            return
        QgsApplication.processingRegistry().providerAdded.disconnect(self._attach_models)
        for alg in self.algorithms():
            if isinstance(alg, QgsProcessingModelAlgorithm):
                for child_id in alg.childAlgorithms():
                    alg.childAlgorithm(child_id).reattach()
                alg.updateDestinationParameters()
