"""The files of the products folder of ``truortho:pipeline``, described for people.

:data:`truortho.core.workflow.PRODUCTS` names the files; this module says what each one is
(tested to cover every one of them). The Processing help of the pipeline lists the same.
"""

from __future__ import annotations

#: What each file of the products folder is (file name -> description); ``report.json`` is the
#: report's data, written beside ``report.html``. Caches are not products: they live in the
#: per-user cache folder (:mod:`truortho.core.cache`), never here.
PRODUCT_DESCRIPTIONS: dict[str, str] = {
    "orientation.json": "adjusted orientation of every photo (TruOrtho orientation JSON)",
    "report.html": "quality report for people (orientation, check points, DSM, true orthophoto, times)",
    "report.json": "the same report as data (every figure of report.html)",
    "dsm_raw.tif": "DSM as matched by OSGM, before filtering (float32, nodata -9999)",
    "confidence.tif": "matching confidence per DSM cell, 0 to 1 (of dsm_raw.tif)",
    "orthoimage.tif": "colour of each DSM cell from the matching (a quick look, not a true orthophoto)",
    "dsm.tif": "filtered DSM: outliers removed, small holes filled (float32, nodata -9999)",
    "pointcloud.laz": "matched points with colour and confidence (LAS 1.4, LAZ)",
    "mesh.ply": "2.5D mesh of dsm.tif with vertical walls and vertex colours",
    "trueortho.tif": "true orthophoto: photo bands plus alpha, cloud-optimised GeoTIFF",
    "source_index.tif": "index of the photo each true-orthophoto cell comes from (named in seamlines.gpkg)",
    "occlusion.tif": "1 where no photo sees the surface (holes of the true orthophoto)",
    "seamlines.gpkg": "one polygon per source photo of the true orthophoto",
}
