"""Help texts of the algorithms, as data (keyed by algorithm name).

Each entry: ``summary`` (one paragraph), ``parameters`` (name -> text) and
optional ``notes``. Texts go through ``tr()`` when shown.
"""

from __future__ import annotations

from ..i18n import tr

#: Help of EDGE_COLOUR, the same for every algorithm that makes a true orthophoto.
_EDGE_COLOUR_HELP = (
    "JPEG photos smear colour over a few pixels across roof outlines, where roof and ground are about "
    "as bright (the brightness cannot restore it). Within 3 cells of the surface's height steps, a "
    "cell's colour (not its brightness) can be taken from the cells of its own surface farther from "
    "the step. checked (the default): only where the cell's colour is already nearer its own "
    "surface's than the other side's, so that a DSM from image matching, whose outlines may be a cell "
    "or two off, does not get roof colours painted on the ground. surface: every such cell, for a "
    "surface whose outlines are exact (a LiDAR DSM, a building model). off: the mosaic's colours as "
    "sampled. RGB images only."
)
#: Help of SCHEDULER_ADDRESS, the same for every tiled algorithm.
_SCHEDULER_HELP = (
    "Address of the Dask scheduler for EXECUTOR = scheduler: tls://host:8786, "
    "or the path of a scheduler file; empty = the environment variable TRUORTHO_DASK_SCHEDULER. "
    "Security: a Dask scheduler executes any code its clients send, so it must never be reachable "
    "unauthenticated. Use TLS with certificates for a remote scheduler (configured in Dask's "
    "configuration, distributed.comm.tls), or an SSH tunnel to 127.0.0.1; a plain tcp:// address "
    "that is not on this computer is refused."
)

HELP: dict[str, dict] = {
    "importorientation": {
        "summary": (
            "Imports the orientation of an image block (interior and exterior orientation of every "
            "image, sparse points) from COLMAP, Orthority or OpenSfM/ODM files into TruOrtho's "
            "orientation JSON, and writes a layer of projection centres and a layer of image "
            "footprints. Conventions (camera axes, rotations, pixel origin) are converted at import; "
            "see docs/FORMATS.md."
        ),
        "parameters": {
            "INPUT": (
                "COLMAP text model (cameras.txt, images.txt or points3D.txt; the folder is used, with "
                'an optional georef.json {"crs": ..., "offset": [E, N, H]}), Orthority exterior '
                "CSV (filename, x, y, z, omega, phi, kappa[, camera]; degrees), OpenSfM/ODM "
                "reconstruction.json, or a TruOrtho orientation JSON."
            ),
            "INTERIOR": "Orthority interior parameter file (YAML or JSON); required with a CSV input.",
            "CRS": "CRS of the input coordinates when the file does not state it (CSV without .prj, "
            "COLMAP without georef.json); target CRS for OpenSfM's topocentric frame.",
            "IMAGE_FOLDER": "Folder holding the images; every image of the block must be present there.",
            "GCPS": "Optional ground control: point layer with 'name', 'role' (gcp|check), PointZ or a 'z' "
            "field, optional 'sigma_xy'/'sigma_z' in metres. Reprojected to the orientation's CRS.",
            "OBSERVATIONS": "Image measurements of the GCPs: table with 'gcp', 'image', 'x', 'y' in pixels "
            "((0, 0) = centre of the top-left pixel).",
            "FOOTPRINT_HEIGHT": "Height (in the CRS) of the plane the footprints are drawn on; default the "
            "median height of the sparse points, or of the GCPs, or 0.",
            "OUTPUT": "The orientation JSON (TruOrtho format, version 1).",
            "CAMERAS": "Optional: projection centres as PointZ with name, camera, x, y, z, omega, phi, kappa "
            "(degrees); skipped when not given.",
            "FOOTPRINTS": "Image footprints on the horizontal plane at FOOTPRINT_HEIGHT.",
        },
    },
    "exportorientation": {
        "summary": (
            "Exports a TruOrtho orientation JSON to a COLMAP text model (cameras.txt, images.txt, "
            "points3D.txt and georef.json) or to Orthority frame-camera files (exterior.csv with a "
            ".prj sidecar and interior.yaml)."
        ),
        "parameters": {
            "INPUT": "A TruOrtho orientation JSON.",
            "FORMAT": "colmap or opk (Orthority CSV + interior file).",
            "OUTPUT": "Folder the files are written to (created if needed).",
        },
    },
    "importgcps": {
        "summary": (
            "Reads an ODM/OpenSfM gcp_list.txt (first line EPSG code, PROJ string or 'WGS84 UTM nnX'; "
            "then 'X Y Z px py image [name]') into a GCP point layer and an observation table, the "
            "two inputs ground control takes everywhere in TruOrtho."
        ),
        "parameters": {
            "INPUT": "The gcp_list.txt file.",
            "CHECK_POINTS": "Comma-separated GCP names to mark as check points (role 'check').",
            "SIGMA_XY": "Default planimetric standard deviation of the GCP coordinates, metres.",
            "SIGMA_Z": "Default height standard deviation of the GCP coordinates, metres.",
            "CRS": "Optional CRS to reproject the GCPs to (default: the file's CRS).",
            "GCPS": "GCP point layer (PointZ): name, role, z, sigma_xy, sigma_z.",
            "OBSERVATIONS": "Observation table: gcp, image, x, y (pixels, (0, 0) = centre of the "
            "top-left pixel, as in gcp_list.txt).",
        },
    },
    "detecttargets": {
        "summary": (
            "Finds ground targets in every photo of a folder and writes an observation table with a "
            "score per measurement. ArUco markers are found anywhere; the GCP is the marker's centre "
            "(intersection of the diagonals of its outer corners), refined by least-squares matching "
            "of the ideal marker. Circular and checkerboard (X) targets are searched near the "
            "positions an orientation predicts for the GCPs, then refined the same way. Measurements "
            "with a low score are kept and flagged, never dropped."
        ),
        "parameters": {
            "IMAGES": "Folder of the photos (jpg, png, tif, jp2, bmp).",
            "TARGET": "ArUco markers, circular targets (a dark disc on a light ground or the "
            "reverse) or checkerboard targets (two dark and two light quadrants).",
            "DICTIONARY": "The ArUco dictionary the markers were printed from.",
            "MARKER_IDS": "ArUco only: marker ID to GCP name, e.g. 0=GCP1,1=GCP2. With a GCP layer, "
            "every name must be in it.",
            "ORIENTATION": "Circular and checkerboard targets: the orientation (TruOrtho JSON) of the "
            "photos, used to predict where each GCP appears.",
            "GCPS": "Point layer of the GCPs ('name' field; PointZ or a 'z' field) whose positions are "
            "predicted; for ArUco it only checks the names of MARKER_IDS.",
            "SEARCH_RADIUS": "Circular and checkerboard targets are searched this many pixels around "
            "their predicted positions.",
            "MIN_SCORE": "Measurements scoring lower (normalised cross-correlation of the ideal target "
            "with the photo, 0 to 1) are flagged 'low score'.",
            "REFINE": "Refine every centre by least-squares matching of the ideal target (gives the "
            "standard deviations).",
            "OUTPUT": "Observation table: gcp, image, x, y (pixels, (0, 0) = centre of the top-left "
            "pixel), score, sigma_x, sigma_y (pixels, empty when the refinement failed) and flag "
            "(ok, low score, refinement failed: reason).",
        },
    },
    "orientimages": {
        "summary": (
            "Orients a block of overlapping photos: SIFT features at a working resolution, pair selection "
            "(exhaustive for small blocks, EXIF GNSS footprints, or a low-resolution retrieval pass), robust "
            "two-view geometry, tie-point tracks decimated on a grid by multiplicity, incremental "
            "reconstruction and a bundle block adjustment written for TruOrtho (collinearity equations with "
            "Brown distortion, Levenberg-Marquardt with the Schur complement, Huber loss, self-calibration). "
            "Ground control fixes the datum (7-parameter similarity, then weighted GCP observations); check "
            "points never enter the adjustment and are reported with per-axis RMSE. Without GCPs, EXIF GNSS "
            "positions serve as weighted priors; without either the block stays in an arbitrary frame."
        ),
        "parameters": {
            "IMAGES": "Folder of the images (non-image files are skipped with a warning in the report).",
            "IMAGE_FILES": "The image files, instead of a folder.",
            "CAMERA": "Interior orientation: an Orthority interior file (YAML/JSON) or a text file with the "
            "3x3 matrix K, taken as a calibration and held fixed. Without it: EXIF focal length and sensor "
            "size, else f = 1.2 x max(w, h), refined by self-calibration.",
            "GCPS": "Ground control and check points: point layer with 'name', 'role' (gcp|check), PointZ or "
            "'z', optional 'sigma_xy'/'sigma_z' (metres). Reprojected to CRS.",
            "OBSERVATIONS": "Image measurements of the GCPs: table with 'gcp', 'image' (file name), 'x', 'y' "
            "(pixels, (0, 0) = centre of the top-left pixel).",
            "CRS": "CRS of the output (default: the GCP layer's, else the UTM zone of the EXIF GNSS "
            "positions).",
            "WORKING_SIZE": "Larger image side at which features are detected, pixels.",
            "MAX_FEATURES": "Features kept per image.",
            "SELF_CALIBRATION": "Estimate f, cx, cy, k1, k2, p1, p2 in the adjustment when no CAMERA file is "
            "given (else hold the prior interior orientation).",
            "ORIENTATION": "The adjusted orientation (TruOrtho JSON).",
            "REPORT": "HTML report (and a JSON file of the same name): sigma0, image RMS, per-image "
            "residuals, GCP and check point tables, residual vector plots, tie-point multiplicity "
            "histogram, block overview. Optional: by default written beside ORIENTATION as "
            "name_report.html.",
            "CAMERAS": "Optional: projection centres (PointZ) with omega, phi, kappa; skipped when not "
            "given.",
            "TIE_POINTS": "Tie points (PointZ) with multiplicity, mean reprojection error and colour.",
            "GCP_RESIDUALS": "GCPs and check points with dX, dY, dZ (adjusted or triangulated minus "
            "surveyed).",
        },
    },
    "pipeline": {
        "summary": (
            "The whole chain from photos to a true orthophoto in one run: image orientation with the "
            "ground control (bundle block adjustment), dense matching in object space (OSGM), DSM "
            "filtering, a mesh, and the true orthophoto with its occlusion mask and seamlines, plus one "
            "HTML report (block overview, sigma0, GCP and check point tables, residual plot, DSM "
            "hillshade, true-orthophoto preview, time and memory per stage). The products are written "
            "to OUTPUT_FOLDER with fixed names: orientation.json, report.html, dsm.tif, pointcloud.laz, "
            "mesh.ply, trueortho.tif, occlusion.tif, seamlines.gpkg (and the raw DSM, confidence and "
            "orthoimage of the matching)."
        ),
        "parameters": {
            "IMAGES": "Folder of the photos (JPEG, TIFF, PNG...); other files are skipped.",
            "CAMERA": "Optional interior orientation (Orthority YAML/JSON or a 3x3 K text file), held "
            "fixed; otherwise EXIF priors refined by self-calibration.",
            "GCPS": "Optional point layer of ground control and check points (fields name, role "
            "gcp|check, optional z, sigma_xy, sigma_z), as for Orient images. Needed for a georeferenced "
            "product unless the photos carry EXIF GNSS positions.",
            "OBSERVATIONS": "Table of the GCP image measurements (gcp, image, x, y), given with GCPS.",
            "CRS": "CRS of the products; default the GCP layer's CRS.",
            "RESOLUTION": "Cell size of the DSM and the true orthophoto in metres; 0 = the median ground "
            "sample distance of the near-nadir images.",
            "REUSE_ORIENTATION": "Skip the orientation when OUTPUT_FOLDER already holds orientation.json "
            "(e.g. to rerun matching and the orthophoto with another resolution).",
            "RESTORE_CHROMA": "Most cameras store JPEG colour at half the resolution of the brightness "
            "(4:2:0 or 4:2:2, read from each file's header), so colours smear across building outlines. "
            "When on, the colour edges of such images are restored from the brightness before they are "
            "sampled at full resolution. Other images are not changed.",
            "EDGE_COLOUR": _EDGE_COLOUR_HELP,
            "EXECUTOR": "Where the tiles of dense matching, DSM filtering and the true orthophoto are "
            "computed, by one executor for the three stages (a local cluster starts once); the products "
            "are identical with every choice. inprocess: in QGIS's process, one tile after the other on "
            "all cores (the default). local: a Dask cluster of worker processes on this computer, "
            "listening on 127.0.0.1 only (one worker per core, a memory limit each). scheduler: an "
            "existing Dask cluster given by SCHEDULER_ADDRESS; its workers must read the photos and "
            "OUTPUT_FOLDER at the same paths (shared storage) and have TruOrtho installed. A worker that "
            "dies has its tiles recomputed by the others. The orientation, the mesh and the report are "
            "computed in QGIS's process. The address is checked before the orientation starts; the scheduler "
            "is first contacted by dense matching.",
            "SCHEDULER_ADDRESS": _SCHEDULER_HELP,
            "OUTPUT_FOLDER": "Folder of the products (created when missing; existing products are replaced). "
            "It holds only products: orientation.json (adjusted orientation), report.html and report.json "
            "(the quality report and its data), dsm_raw.tif (DSM as matched, before filtering), "
            "confidence.tif (matching confidence 0 to 1), orthoimage.tif (colour of each DSM cell from the "
            "matching, not a true orthophoto), dsm.tif (filtered DSM), pointcloud.laz, mesh.ply, "
            "trueortho.tif, source_index.tif (which photo each true-orthophoto cell comes from), "
            "occlusion.tif and seamlines.gpkg. Caches (compiled kernels, image features) are kept in "
            "the per-user cache folder (environment variable TRUORTHO_CACHE_DIR; truortho:environment "
            "shows and clears it).",
            "ORIENTATION": "orientation.json: the adjusted orientation.",
            "REPORT": "report.html (and report.json): the quality report of the run.",
            "DSM": "dsm.tif: the filtered DSM (float32, nodata -9999).",
            "POINT_CLOUD": "pointcloud.laz: the matched points with colour and confidence.",
            "MESH": "mesh.ply: 2.5D mesh of the filtered DSM with vertical walls and vertex colours.",
            "TRUE_ORTHO": "trueortho.tif: the true orthophoto (bands of the photos + alpha, COG).",
            "OCCLUSION": "occlusion.tif: 1 where no photo sees the surface.",
            "SEAMLINES": "seamlines.gpkg: one polygon per source photo.",
        },
    },
    "osgm": {
        "summary": (
            "Dense image matching in object space (OSGM): computes a DSM directly on a ground grid from "
            "the oriented images, without rectification or pairwise depth maps. For every tile of the grid "
            "the images that see it (at most MAX_IMAGES) are resampled onto the horizontal plane of every "
            "search height (voxels of RESOLUTION x RESOLUTION x Z_STEP); a matching cost from all of them "
            "per cell and height is aggregated by semi-global matching along 8 or 16 paths (penalty P1 for "
            "a change of one height step, P2 for larger jumps, lowered across image edges), and each cell "
            "takes the height of least aggregated cost, refined between steps, with a confidence in "
            "[0, 1]. Matching runs coarse to fine over an image pyramid, by tiles, with progress and cancel. "
            "Cells without a reliable match are nodata (filter and fill them with truortho:dsmfilter). "
            "Optionally writes the confidence, an orthoimage coloured from the matched images, and a point "
            "cloud; with OBLIQUE = auto, groups of oblique images are matched in extra reference systems "
            "along their viewing directions, whose points (facades) go to the point cloud."
        ),
        "parameters": {
            "ORIENTATION": "Orientation JSON (from Orient images or Import orientation) with a projected "
            "CRS (metres) and at least two images, which must be on disk.",
            "EXTENT": "Area to match (reprojected to the orientation's CRS); default the extent of the "
            "sparse points (1-99 %), else the union of the near-nadir image footprints. It must intersect "
            "the area the images see.",
            "RESOLUTION": "Cell size of the DSM, metres; empty or 0 = the median ground sample distance of "
            "the near-nadir images.",
            "Z_STEP": "Height step between two search planes, metres; empty or 0 = the resolution. A "
            "larger step (1.5 x the resolution) is about 10 % faster, with crisper building edges and "
            "fewer holes, and noisier on flat ground.",
            "Z_MIN": "Lowest height searched (world Z, the orientation's vertical datum); empty = from the "
            "sparse points (0.5 % percentile minus a margin), else from the GCP heights. Must be below "
            "Z_MAX.",
            "Z_MAX": "Highest height searched; empty = from the sparse points (99.5 % percentile plus a "
            "margin), else half the flying height above the highest GCP. Always kept below the cameras. "
            "Without sparse points or GCPs give Z_MIN and Z_MAX.",
            "Z_SURFACE": "Optional coarse DSM or DTM raster: the search at each cell is bounded by the "
            "lowest and highest height of its neighbourhood plus a margin, which speeds up matching and "
            "avoids wrong heights on rough terrain.",
            "PATHS": "Number of aggregation directions of semi-global matching: 16 (the default) or 8 "
            "(about 6 % faster; the hillshade of natural terrain then shows a fine cross-hatch along the "
            "grid's axes and diagonals).",
            "OBLIQUE": "none: one nadir reference system (the DSM). auto: groups of oblique images also get "
            "reference systems along their viewing directions, whose points go to the point cloud with "
            "their 'system' id (without a POINT_CLOUD output they are skipped: the DSM is the same).",
            "P1": "Penalty for a change of one height step between neighbouring cells, in cost units "
            "(unrelated image windows cost 1023); empty = 256.",
            "P2": "Penalty for a larger height jump, above P1 and at most 3072; empty = 2048 (a jump then "
            "needs contrary evidence from two cells).",
            "MAX_IMAGES": "Largest number of images matched per tile (best coverage first, then the most "
            "nadir; more only where fewer would leave part of the tile with under 2 views); memory and "
            "time grow with it.",
            "TILE_SIZE": "Tile side in cells; memory grows with its square, the number of search heights "
            "and MAX_IMAGES.",
            "EXECUTOR": "Where the tiles are matched; the DSM and confidence are identical with every "
            "choice. inprocess: in QGIS's process, one tile after the other on all cores (the default). "
            "local: a Dask cluster of worker processes on this computer, listening on 127.0.0.1 only "
            "(one worker per core, a memory limit each). scheduler: an existing Dask cluster given by "
            "SCHEDULER_ADDRESS; its workers must read the images at the same paths (shared storage) and "
            "have TruOrtho installed. A worker that dies has its tiles recomputed by the others. "
            "Finished tiles are kept beside the DSM (DSM.tif.tiles) until the run ends, so a rerun with "
            "the same inputs and parameters after a crash reuses them.",
            "SCHEDULER_ADDRESS": _SCHEDULER_HELP,
            "DSM": "The raw DSM: GeoTIFF, float32, in the orientation's CRS, nodata -9999.",
            "CONFIDENCE": "Optional confidence GeoTIFF (float32 in [0, 1], nodata -1) on the DSM grid, for "
            "truortho:dsmfilter.",
            "ORTHOIMAGE": "Optional RGB orthoimage GeoTIFF (uint8, 0 = no data) on the DSM grid, coloured "
            "from the matched images; not a true orthophoto (use truortho:trueortho for that).",
            "POINT_CLOUD": "Optional point cloud (.laz or .las; LAS 1.4 with colours, 'confidence' and "
            "'system', the reference system of each point).",
            "STATISTICS": "JSON: grid size, resolution, height step and range (and where it came from), "
            "pyramid levels, tiles, completeness, mean confidence, reference systems, time.",
        },
    },
    "trueortho": {
        "summary": (
            "Computes a true orthophoto from oriented images and a surface (a DSM raster such as OSGM's, "
            "or a PLY/OBJ mesh): every cell is coloured from an image that really sees it, found with a "
            "depth buffer of the surface per image (DSM cells as flat tops with vertical walls at height "
            "steps, or the mesh's triangles; frustum and back-face culling). Among the images that see a "
            "cell the one with the finest effective ground resolution (distance and incidence on the "
            "surface) is preferred; roofs are textured from one image each and seamlines follow height "
            "discontinuities and avoid places where the images disagree (label smoothing), with feathering "
            "across seams only between images that both see the cells. Per-image colour corrections (a "
            "gain/offset per RGB channel for white balance and exposure, then one in CIE L*a*b*; per-band "
            "gain/offset for non-RGB data) are estimated by least squares from cells seen by several "
            "images. Cells no image sees get alpha 0 and appear in the occlusion mask. "
            "Any band count and data type of the images is kept (RGB, 16-bit panchromatic, thermal). "
            "Processing runs by tiles with bounded memory; progress and cancel per tile."
        ),
        "parameters": {
            "ORIENTATION": "Orientation JSON (from Orient images or Import orientation); its images must "
            "be on disk.",
            "SURFACE": "DSM GeoTIFF (any CRS; resampled onto the output grid by nearest neighbour) or a "
            "PLY/OBJ mesh. Heights must use the orientation's vertical datum. It must cover the extent.",
            "EXTENT": "Output extent; default the surface's extent.",
            "RESOLUTION": "Output cell size in units of the output CRS; 0 = the DSM's cell size.",
            "CRS": "Output CRS; default the orientation's. When it differs, the computation runs on the "
            "output grid and cell centres are transformed to the orientation's CRS (images are resampled "
            "once).",
            "COLOR_CORRECTION": "Estimate and apply per-image colour corrections before mosaicking.",
            "VIGNETTING": "With the colour correction: estimate a radial darkening towards the image corners "
            "per camera from the overlaps and remove it first. Images without vignetting get a factor of "
            "about 1; switch it off for images already corrected in processing.",
            "RESTORE_CHROMA": "Most cameras store JPEG colour at half the resolution of the brightness "
            "(4:2:0 or 4:2:2, read from each file's header), so colours smear across building outlines. "
            "When on, the colour edges of such images are restored from the brightness before they are "
            "sampled at full resolution. Other images are not changed.",
            "EDGE_COLOUR": _EDGE_COLOUR_HELP,
            "MAX_VIEW_ANGLE": "Largest off-nadir angle of the viewing ray (degrees) for an image to texture "
            "a cell; also bounds how far outside a tile occluders are searched.",
            "BLEND_WIDTH": "Width of the feathering across seamlines, in cells (0 = hard seams).",
            "TILE_SIZE": "Tile side in cells; memory grows with its square and the images per tile.",
            "COMPRESSION": "Compression of the orthophoto. DEFLATE (the default), ZSTD and LZW are "
            "lossless: DEFLATE gives the smallest files and every GIS reads it; ZSTD (level 1) writes "
            "about twice as fast and about 9 % larger (GDAL 2.3 or later reads it); LZW is for older "
            "readers. JPEG is lossy (about a fifth of the size), for 8-bit RGB images only: RGB is stored as "
            "YCbCr with halved colour resolution, so colours blur across sharp edges such as building "
            "outlines (deliver and view with it; measure on a lossless one), and the alpha band becomes "
            "the file's internal mask. The source index and occlusion mask always stay lossless.",
            "JPEG_QUALITY": "JPEG quality (1-100) when COMPRESSION is JPEG.",
            "EXECUTOR": "Where the tiles of the mosaic are computed; the true orthophoto, source index, "
            "occlusion mask and seamlines are identical with every choice. inprocess: in QGIS's process, "
            "the independent tiles of a wave in parallel threads (the default). local: a Dask cluster of "
            "worker processes on this "
            "computer, listening on 127.0.0.1 only (one worker per core, a memory limit each). scheduler: "
            "an existing Dask cluster given by SCHEDULER_ADDRESS; its workers must read the images and the "
            "surface at the same paths (shared storage) and have TruOrtho installed. A worker that dies "
            "has its tiles recomputed by the others. The colour correction (on a decimated grid) is "
            "estimated in QGIS's process. Finished tiles are kept in a folder beside the output (its name "
            "plus '.tiles') until the run succeeds, so a rerun with the same inputs and parameters after a "
            "crash reuses them.",
            "SCHEDULER_ADDRESS": _SCHEDULER_HELP,
            "OUTPUT": "GeoTIFF with the images' bands and data type plus an alpha band (an internal mask "
            "with JPEG compression), tiled, with overviews, Cloud-Optimized GeoTIFF layout.",
            "SOURCE_INDEX": "Int16 GeoTIFF: index (0-based, orientation order) of the image each cell "
            "comes from; -1 = nodata.",
            "OCCLUSION": "UInt8 GeoTIFF: 1 where no image sees the cell, 0 where seen, 255 where the "
            "surface has no data.",
            "SEAMLINES": "Polygons, one feature per source image: the cells it colours (image_index, "
            "image, cells, area).",
        },
    },
    "dsmfilter": {
        "summary": (
            "Cleans a raw DSM (e.g. the dense-matching DSM of TruOrtho's OSGM step) tile by tile: snaps the "
            "cells of blurred height steps to the nearer side, removes outliers (cells that depart from the "
            "confidence-weighted median of their window by more than the threshold and have too few "
            "neighbours at their height, so roof edges and corners survive), fills holes up to a maximum "
            "width by harmonic interpolation (holes at the foot of walls from the ground side only; wider "
            "holes stay nodata and are reported), and optionally smooths planar surfaces without blurring "
            "their edges. Optionally derives a terrain model (DTM) by SMRF-style ground filtering and the "
            "normalised DSM (height above terrain). Outputs keep the input's CRS, grid and nodata; the "
            "statistics (removed outliers, filled cells, remaining holes) are returned and logged."
        ),
        "parameters": {
            "INPUT": "Raw DSM: single-band raster with a projected CRS (metres); its nodata cells are holes.",
            "CONFIDENCE": "Optional confidence raster in [0, 1] (OSGM's CONFIDENCE): cells below the minimum "
            "confidence are removed, less confident cells must agree better with their neighbours, and the "
            "median is weighted by confidence.",
            "OUTLIER_THRESHOLD": "Largest departure from the neighbourhood median, metres (empty: 4 x the "
            "resolution).",
            "OUTLIER_WINDOW": "Side of the median window in cells (odd); a second pass uses twice the "
            "window.",
            "MIN_SUPPORT": "Neighbours within the threshold of a cell's height that keep it although it "
            "departs from the median (edges, corners, thin structures).",
            "MIN_CONFIDENCE": "With a confidence raster: cells below this confidence are removed.",
            "CONFIDENT": "With a confidence raster: less confident cells are removed when they depart by "
            "more than the threshold from the median of the cells at least this confident in their 15 x 15 "
            "window (0: off).",
            "MAX_HOLE": "Largest hole width (metres) that is interpolated; 0 fills nothing.",
            "STEP": "Height difference between two surfaces (a wall), metres: hole boundary cells that much "
            "above nearby boundary cells are not interpolated from.",
            "SHARPEN": "Snap the cells of blurred height steps (between the two levels of their 5 x 5 "
            "window) to the nearer level.",
            "SMOOTH": "Replace cells by a local plane fitted to the neighbours at their height (flat and "
            "pitched roofs, streets); steps stay sharp.",
            "SMOOTH_RADIUS": "Radius of the smoothing neighbourhood, cells.",
            "SMOOTH_TOLERANCE": "Neighbours within this height of a cell belong to its surface, metres "
            "(empty: 2.5 x the resolution).",
            "DTM_RESOLUTION": "Cell size of the ground filter, metres (empty: max(1 m, the DSM resolution)); "
            "the DTM is written on the DSM grid.",
            "MAX_WINDOW": "Largest opening radius of the ground filter, metres: more than half the width of "
            "the largest building.",
            "SLOPE": "Terrain slope (rise over run) the ground filter keeps as ground.",
            "EXECUTOR": "Where the tiles are filtered; the filtered DSM and the statistics are identical "
            "with every choice. inprocess: in QGIS's process, one tile after the other on all cores (the "
            "default). local: a Dask cluster of worker processes on this computer, listening on 127.0.0.1 "
            "only (one worker per core, a memory limit each). scheduler: an existing Dask cluster given "
            "by SCHEDULER_ADDRESS; its workers must read the DSM and the confidence raster at the same "
            "paths (shared storage) and have TruOrtho installed. A worker that dies has its tiles "
            "recomputed by the others. The terrain model is computed in QGIS's process.",
            "SCHEDULER_ADDRESS": _SCHEDULER_HELP,
            "OUTPUT": "Filtered DSM (GeoTIFF, float32).",
            "DTM": "Optional terrain model (GeoTIFF, float32, DSM grid).",
            "NDSM": "Optional normalised DSM: DSM minus DTM, heights above the terrain.",
            "STATISTICS": "JSON: the filter statistics (and the ground filter's).",
            "OUTLIERS_REMOVED": "Cells removed as outliers or for low confidence.",
            "CELLS_FILLED": "Hole cells interpolated.",
            "HOLES_REMAINING": "Holes wider than MAX_HOLE, left as nodata.",
        },
    },
    "mesh": {
        "summary": (
            "Builds a triangle mesh. From a DSM: a 2.5D mesh whose height steps are vertical walls (no "
            "triangle ever spans a step) and whose flat and smooth areas are decimated by a restricted "
            "quadtree with a guaranteed vertical error bound at every cell centre; vertex colours from an "
            "optional orthoimage. From a point cloud (LAS/LAZ or EPT, e.g. merged oblique matching): one "
            "2.5D Delaunay mesh per reference system, seen along its viewing direction (overlapping layers "
            "where systems see the same surface; not watertight). Writes PLY (binary) or OBJ, in the CRS or "
            "in a local frame whose offset is recorded in the header; truortho:trueortho reads it as SURFACE."
        ),
        "parameters": {
            "INPUT": "DSM raster (projected CRS) or point cloud (.las, .laz, or an EPT ept.json).",
            "ORTHO": "Optional orthoimage (RGB) for the vertex colours of a DSM mesh.",
            "MAX_ERROR": "Largest vertical difference between mesh and DSM at any cell centre, metres "
            "(empty: half the DSM resolution).",
            "MIN_STEP": "Smallest height difference between neighbouring cells that becomes a wall, metres.",
            "MAX_SLOPE": "Steepest slope kept as sloping triangles, degrees: the step threshold is "
            "max(MIN_STEP, resolution x tan(MAX_SLOPE)).",
            "MAX_LEAF": "Largest block of cells one pair of triangles may cover (a power of two).",
            "MAX_EDGE": "Point clouds: longest triangle edge, metres (empty: 4 x the median point spacing).",
            "FRAME": "CRS: world coordinates (PLY doubles). Local: world minus an offset recorded as "
            "'comment offset E N H' (PLY) or '# offset E N H' (OBJ), for viewers that need small numbers.",
            "OUTPUT": "The mesh: .ply (binary little-endian, 'comment crs ...') or .obj ('# crs ...', vertex "
            "colours as 'v x y z r g b').",
            "VERTICES": "Number of vertices.",
            "FACES": "Number of triangles.",
            "WALL_FACES": "Number of vertical wall triangles (DSM meshes).",
        },
    },
    "dsmtopointcloud": {
        "summary": (
            "Exports a DSM as a point cloud, one point per valid cell centre, with colours from an "
            "orthoimage and per-point confidence from a confidence raster: LAS 1.4 or LAZ (point format 7, "
            "CRS as WKT, extra dimensions 'confidence' and 'system' (the reference system), a TruOrtho VLR "
            "describing the reference systems), readable by PDAL, laspy, LAStools and CloudCompare. An "
            "Entwine Point Tile (EPT) dataset is written beside it: QGIS builds without PDAL (as Debian's "
            "QGIS 3.22) open it as a point cloud layer (menu Layer, Add Layer, Add Point Cloud Layer; "
            "choose ept.json)."
        ),
        "parameters": {
            "INPUT": "DSM raster with a projected CRS.",
            "ORTHO": "Optional orthoimage (RGB) for the point colours.",
            "CONFIDENCE": "Optional confidence raster in [0, 1], stored as the 'confidence' dimension.",
            "OUTPUT": "The point cloud (.laz compressed, or .las).",
            "EPT": "Folder of the EPT dataset (ept.json, ept-data/, ept-hierarchy/); leave empty to skip.",
            "EPT_JSON": "Path of the EPT dataset's ept.json.",
            "POINTS": "Number of points written.",
        },
    },
    "mergepointclouds": {
        "summary": (
            "Merges point clouds of several reference systems (e.g. the nadir and oblique systems of "
            "dense matching) into one LAS 1.4 / LAZ file, keeping each point's 'system' (files without it "
            "get the index of their file) and confidence; optionally thins duplicates on a voxel grid, "
            "keeping the most confident point of each voxel; optionally writes an EPT dataset for QGIS."
        ),
        "parameters": {
            "INPUTS": "LAS/LAZ files in one CRS.",
            "VOXEL": "Voxel size for thinning, metres (empty: keep every point).",
            "OUTPUT": "The merged point cloud (.laz or .las).",
            "EPT": "Optional folder for an EPT dataset of the merged cloud.",
            "EPT_JSON": "Path of the EPT dataset's ept.json.",
            "POINTS": "Number of points written.",
        },
    },
}


def help_text(name: str) -> str:
    """The help of algorithm ``name`` as plain text, one paragraph per line.

    ``qgis_process help`` prints ``shortHelpString()`` as it is, and the toolbox wraps each line
    of it in ``<p>`` (QGIS's ``formatHelp``), so plain lines read well in both; the texts hold
    no ``<``, ``>`` or ``&`` (tested), which the toolbox would take for markup.
    """
    entry = HELP.get(name)
    if not entry:
        return ""
    lines = [tr(entry["summary"])]
    for key, text in entry.get("parameters", {}).items():
        lines.append(f"{key}: {tr(text)}")
    if entry.get("notes"):
        lines.append(tr(entry["notes"]))
    return "\n".join(line.replace("\n", " ") for line in lines)


def parameter_help(name: str, parameter: str) -> str:
    text = HELP.get(name, {}).get("parameters", {}).get(parameter, "")
    return tr(text) if text else ""
