"""QGIS desktop integration of TruOrtho (plugin entry object)."""
