"""Translation helper shared by the provider and the algorithms."""

from __future__ import annotations

from qgis.PyQt.QtCore import QCoreApplication

CONTEXT = "TruOrtho"


def tr(text: str) -> str:
    """Translate a display string in the ``TruOrtho`` context."""
    return QCoreApplication.translate(CONTEXT, text)
