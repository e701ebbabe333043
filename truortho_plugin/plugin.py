"""The object QGIS creates through ``classFactory``: registers the Processing provider."""

from __future__ import annotations

from qgis.core import QgsApplication

from ..processing.provider import TruOrthoProvider


class TruOrthoPlugin:
    """Registers :class:`TruOrthoProvider` with the Processing registry.

    ``initProcessing`` is what ``qgis_process`` calls (hasProcessingProvider=yes);
    the desktop calls ``initGui``. Both are idempotent.
    """

    def __init__(self, iface) -> None:
        self.iface = iface
        self.provider: TruOrthoProvider | None = None

    def initProcessing(self) -> None:  # noqa: N802 - QGIS API
        if self.provider is None:
            self.provider = TruOrthoProvider()
            QgsApplication.processingRegistry().addProvider(self.provider)

    def initGui(self) -> None:  # noqa: N802 - QGIS API
        self.initProcessing()

    def unload(self) -> None:
        if self.provider is not None:
            QgsApplication.processingRegistry().removeProvider(self.provider)
            self.provider = None
