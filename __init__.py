"""TruOrtho QGIS plugin (photogrammetry: orientation, dense matching, true orthophoto).

This folder is the plugin, installed as ``truortho/``. Nothing here imports QGIS
at module level, so ``import truortho.core`` works without QGIS.
"""


def classFactory(iface):  # noqa: N802 - name required by QGIS
    from .truortho_plugin.plugin import TruOrthoPlugin

    return TruOrthoPlugin(iface)
