"""TruOrtho's QGIS Processing provider and algorithms.

This is ``truortho.processing``; it never imports QGIS's own ``processing``
package. It is the only layer that translates between QGIS (parameters,
feedback, exceptions) and the QGIS-free ``truortho.core``.
"""
