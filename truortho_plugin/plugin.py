"""The object QGIS creates through ``classFactory``: provider, translations, menu and toolbar."""

from __future__ import annotations

import os

from qgis.core import QgsApplication, QgsSettings
from qgis.PyQt.QtCore import QCoreApplication, QTranslator
from qgis.PyQt.QtGui import QIcon
from qgis.PyQt.QtWidgets import QAction

from ..processing.i18n import tr
from ..processing.provider import ICON_PATH, PLUGIN_DIR, TruOrthoProvider

MENU = "&TruOrtho"
#: Menu entries: (algorithm id, label). The first one is also the toolbar button.
ENTRIES = (
    ("truortho:pipeline", "Photos to true orthophoto (whole pipeline)…"),
    ("truortho:orientimages", "Orient images…"),
    ("truortho:osgm", "Dense matching (OSGM)…"),
    ("truortho:dsmfilter", "Filter DSM…"),
    ("truortho:mesh", "DSM to mesh…"),
    ("truortho:trueortho", "True orthophoto…"),
)


def user_locale() -> str:
    """QGIS's user interface language (``de``, ``fr_CA``...), as QGIS itself decides it."""
    settings = QgsSettings()
    if settings.value("locale/overrideFlag", False, type=bool):
        loc = settings.value("locale/userLocale", "") or ""
    else:
        from qgis.PyQt.QtCore import QLocale

        loc = QLocale.system().name()
    return str(loc or "en")


def translation_file(locale: str) -> str | None:
    """``i18n/truortho_<lang>.qm`` for a locale (``de_AT`` falls back to ``de``), or None."""
    folder = os.path.join(PLUGIN_DIR, "i18n")
    for tag in (locale, locale.split("_")[0]):
        path = os.path.join(folder, f"truortho_{tag}.qm")
        if os.path.isfile(path):
            return path
    return None


class TruOrthoPlugin:
    """Registers :class:`TruOrthoProvider`, installs the translation, adds menu and toolbar entries.

    ``initProcessing`` is what ``qgis_process`` calls (hasProcessingProvider=yes);
    the desktop calls ``initGui``. Both are idempotent; ``unload`` undoes both.
    """

    def __init__(self, iface) -> None:
        self.iface = iface
        self.provider: TruOrthoProvider | None = None
        self.translator: QTranslator | None = None
        self.actions: list[QAction] = []
        self.toolbar = None
        self.gcp_action: QAction | None = None
        self.gcp_panel = None
        self.install_translator()

    # ------------------------------------------------------------ translations
    def install_translator(self, locale: str | None = None) -> bool:
        """Load ``i18n/truortho_<lang>.qm`` for the QGIS locale (or ``locale``); True when loaded."""
        path = translation_file(locale or user_locale())
        if path is None:
            return False
        translator = QTranslator()
        if not translator.load(path):
            return False
        if self.translator is not None:
            QCoreApplication.removeTranslator(self.translator)
        QCoreApplication.installTranslator(translator)
        self.translator = translator
        return True

    # ------------------------------------------------------------ processing
    def initProcessing(self) -> None:  # noqa: N802 - QGIS API
        if self.provider is None:
            provider = TruOrthoProvider()
            if QgsApplication.processingRegistry().addProvider(provider):
                self.provider = provider

    # ------------------------------------------------------------ GUI
    def initGui(self) -> None:  # noqa: N802 - QGIS API
        self.initProcessing()
        if self.actions or self.iface is None:
            return
        icon = QIcon(ICON_PATH)
        parent = self.iface.mainWindow()
        self.toolbar = self.iface.addToolBar(tr("TruOrtho"))
        self.toolbar.setObjectName("TruOrthoToolbar")
        for alg_id, label in ENTRIES:
            action = QAction(icon, tr(label), parent)
            action.setObjectName(alg_id.replace(":", "_"))
            action.setData(alg_id)
            action.triggered.connect(lambda _checked=False, a=alg_id: self.open_dialog(a))
            self.iface.addPluginToRasterMenu(tr(MENU), action)
            self.actions.append(action)
        self.toolbar.addAction(self.actions[0])
        self.gcp_action = QAction(icon, tr("GCP measurements in photos…"), parent)
        self.gcp_action.setObjectName("truortho_gcp_panel")
        self.gcp_action.setCheckable(True)
        self.gcp_action.toggled.connect(self.show_gcp_panel)
        self.iface.addPluginToRasterMenu(tr(MENU), self.gcp_action)

    def show_gcp_panel(self, visible: bool = True):
        """Show (create on first use) or hide the GCP measurement dock."""
        from qgis.PyQt.QtCore import Qt

        if self.gcp_panel is None and visible:
            from .gcp_panel import GcpPanel

            self.gcp_panel = GcpPanel(self.iface, self.iface.mainWindow())
            self.iface.addDockWidget(Qt.RightDockWidgetArea, self.gcp_panel)
            if self.gcp_action is not None:
                self.gcp_panel.visibilityChanged.connect(self.gcp_action.setChecked)
        if self.gcp_panel is not None:
            self.gcp_panel.setVisible(visible)
        return self.gcp_panel

    def open_dialog(self, alg_id: str):
        """Open the Processing dialog of an algorithm (results load into the project as layers)."""
        import processing

        registry = QgsApplication.processingRegistry()
        if registry.algorithmById(alg_id) is None:
            self.iface.messageBar().pushWarning(
                tr("TruOrtho"), tr("The algorithm {} is not available in this version.").format(alg_id)
            )
            return None
        return processing.execAlgorithmDialog(alg_id, {})

    def unload(self) -> None:
        self.unload_gui()
        if self.provider is not None:
            QgsApplication.processingRegistry().removeProvider(self.provider)
            self.provider = None
        if self.translator is not None:
            QCoreApplication.removeTranslator(self.translator)
            self.translator = None

    def unload_gui(self) -> None:
        """Remove the menu entries and the toolbar (the provider stays)."""
        for action in self.actions:
            if self.iface is not None:
                self.iface.removePluginRasterMenu(tr(MENU), action)
            action.deleteLater()
        self.actions = []
        if self.gcp_panel is not None:
            if self.iface is not None:
                self.iface.removeDockWidget(self.gcp_panel)
            self.gcp_panel.close()
            self.gcp_panel.deleteLater()
            self.gcp_panel = None
        if self.gcp_action is not None:
            if self.iface is not None:
                self.iface.removePluginRasterMenu(tr(MENU), self.gcp_action)
            self.gcp_action.deleteLater()
            self.gcp_action = None
        if self.toolbar is not None:
            self.toolbar.deleteLater()
            self.toolbar = None
