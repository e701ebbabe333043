"""Ground control in the photos: measurements of GCPs in images, their prediction from an
orientation, automatic target detection and multi-image least-squares matching (MGCM).

QGIS-free; the desktop panel (``truortho_plugin``) and the Processing algorithms use it.
"""
