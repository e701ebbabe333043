"""TruOrtho computational core.

Pure numpy/numba/scipy: this package never imports QGIS or Qt. Processing
algorithms (``truortho.processing``) call into it; it reports progress and
honours cancel only through :mod:`truortho.core.progress`.
"""
