"""``truortho:trueortho``: orientation + surface (DSM or mesh) -> true orthophoto and its companions."""

from __future__ import annotations

from qgis.core import (
    QgsFeature,
    QgsFeatureSink,
    QgsField,
    QgsFields,
    QgsGeometry,
    QgsProcessing,
    QgsProcessingException,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterCrs,
    QgsProcessingParameterEnum,
    QgsProcessingParameterExtent,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFile,
    QgsProcessingParameterNumber,
    QgsProcessingParameterRasterDestination,
    QgsWkbTypes,
)
from qgis.PyQt.QtCore import QVariant

from ..feedback import FeedbackProgress, core_errors
from ..i18n import tr
from ..layers import crs_text, qgs_crs
from .base import FromConfig, TruOrthoAlgorithm, executor_default


def seamline_fields() -> QgsFields:
    fields = QgsFields()
    fields.append(QgsField("image_index", QVariant.Int))
    fields.append(QgsField("image", QVariant.String))
    fields.append(QgsField("cells", QVariant.LongLong))
    fields.append(QgsField("area", QVariant.Double))
    return fields


class TrueOrthoAlgorithm(TruOrthoAlgorithm):
    NAME = "trueortho"
    DISPLAY_NAME = "True orthophoto"
    GROUP_ID = "orthophoto"

    ORIENTATION = "ORIENTATION"
    SURFACE = "SURFACE"
    EXTENT = "EXTENT"
    RESOLUTION = "RESOLUTION"
    CRS = "CRS"
    COLOR_CORRECTION = "COLOR_CORRECTION"
    VIGNETTING = "VIGNETTING"
    RESTORE_CHROMA = "RESTORE_CHROMA"
    EDGE_COLOUR = "EDGE_COLOUR"
    MAX_VIEW_ANGLE = "MAX_VIEW_ANGLE"
    BLEND_WIDTH = "BLEND_WIDTH"
    TILE_SIZE = "TILE_SIZE"
    COMPRESSION = "COMPRESSION"
    JPEG_QUALITY = "JPEG_QUALITY"
    EXECUTOR = "EXECUTOR"
    SCHEDULER_ADDRESS = "SCHEDULER_ADDRESS"
    OUTPUT = "OUTPUT"
    SOURCE_INDEX = "SOURCE_INDEX"
    OCCLUSION = "OCCLUSION"
    SEAMLINES = "SEAMLINES"

    CONFIG_DEFAULTS = {
        RESOLUTION: FromConfig("ortho.pipeline.TrueOrthoConfig", "resolution", none=0.0),
        COLOR_CORRECTION: FromConfig("ortho.pipeline.TrueOrthoConfig", "color_correction"),
        VIGNETTING: FromConfig("ortho.pipeline.TrueOrthoConfig", "vignetting"),
        RESTORE_CHROMA: FromConfig("ortho.pipeline.TrueOrthoConfig", "restore_chroma"),
        # EDGE_COLOUR's options are listed in the order of EDGE_COLOURS
        EDGE_COLOUR: FromConfig(
            "ortho.pipeline.TrueOrthoConfig", "edge_colour", "ortho.edgecolour.EDGE_COLOURS"
        ),
        MAX_VIEW_ANGLE: FromConfig("ortho.pipeline.TrueOrthoConfig", "max_view_angle"),
        BLEND_WIDTH: FromConfig("ortho.pipeline.TrueOrthoConfig", "blend_width"),
        TILE_SIZE: FromConfig("ortho.pipeline.TrueOrthoConfig", "tile_size"),
        # COMPRESSION's options are listed in the order of ORTHO_COMPRESSIONS
        COMPRESSION: FromConfig(
            "ortho.pipeline.TrueOrthoConfig", "compression", "ortho.pipeline.ORTHO_COMPRESSIONS"
        ),
        JPEG_QUALITY: FromConfig("ortho.pipeline.TrueOrthoConfig", "jpeg_quality"),
        "EXECUTOR": executor_default("ortho.pipeline.TrueOrthoConfig"),
    }

    def initAlgorithm(self, config=None):  # noqa: N802 - QGIS API
        self.add(
            QgsProcessingParameterFile(self.ORIENTATION, tr("Orientation (TruOrtho JSON)"), extension="json")
        )
        self.add(
            QgsProcessingParameterFile(
                self.SURFACE,
                tr("Surface: DSM raster or mesh"),
                fileFilter=tr("Surfaces (*.tif *.tiff *.vrt *.ply *.obj);;All files (*.*)"),
            )
        )
        self.add(
            QgsProcessingParameterExtent(self.EXTENT, tr("Extent (default: the surface's)"), optional=True)
        )
        self.add(
            QgsProcessingParameterNumber(
                self.RESOLUTION,
                tr("Resolution (CRS units; 0 = the surface's cell size)"),
                QgsProcessingParameterNumber.Double,
                self.default(self.RESOLUTION),
                minValue=0.0,
            )
        )
        self.add(
            QgsProcessingParameterCrs(self.CRS, tr("Output CRS (default: the orientation's)"), optional=True)
        )
        self.add(
            QgsProcessingParameterBoolean(
                self.COLOR_CORRECTION, tr("Colour correction"), self.default(self.COLOR_CORRECTION)
            )
        )
        self.add(
            QgsProcessingParameterBoolean(
                self.VIGNETTING,
                tr("Remove vignetting (with the colour correction)"),
                self.default(self.VIGNETTING),
            )
        )
        self.add_restore_chroma()
        self.add_edge_colour()
        self.add(
            QgsProcessingParameterNumber(
                self.MAX_VIEW_ANGLE,
                tr("Maximum off-nadir viewing angle (degrees)"),
                QgsProcessingParameterNumber.Double,
                self.default(self.MAX_VIEW_ANGLE),
                minValue=1.0,
                maxValue=88.0,
            )
        )
        self.add(
            QgsProcessingParameterNumber(
                self.BLEND_WIDTH,
                tr("Blend width across seamlines (cells)"),
                QgsProcessingParameterNumber.Integer,
                self.default(self.BLEND_WIDTH),
                minValue=0,
                maxValue=1000,
            )
        )
        self.add(
            QgsProcessingParameterNumber(
                self.TILE_SIZE,
                tr("Tile size (cells)"),
                QgsProcessingParameterNumber.Integer,
                self.default(self.TILE_SIZE),
                minValue=32,
                maxValue=8192,
            ),
            advanced=True,
        )
        self.add(
            QgsProcessingParameterEnum(
                self.COMPRESSION,
                tr("Compression of the orthophoto"),
                options=[
                    tr("DEFLATE (lossless, read by every GIS)"),
                    tr("ZSTD (lossless, fastest to write, larger)"),
                    tr("LZW (lossless)"),
                    tr("JPEG (lossy, 8-bit RGB images only; alpha becomes a mask)"),
                ],
                defaultValue=self.default(self.COMPRESSION),
            )
        )
        self.add(
            QgsProcessingParameterNumber(
                self.JPEG_QUALITY,
                tr("JPEG quality"),
                QgsProcessingParameterNumber.Integer,
                self.default(self.JPEG_QUALITY),
                minValue=1,
                maxValue=100,
            ),
            advanced=True,
        )
        self.add_executor()
        self.add(QgsProcessingParameterRasterDestination(self.OUTPUT, tr("True orthophoto")))
        self.add(
            QgsProcessingParameterRasterDestination(
                self.SOURCE_INDEX, tr("Source image index"), optional=True, createByDefault=False
            )
        )
        self.add(
            QgsProcessingParameterRasterDestination(
                self.OCCLUSION, tr("Occlusion mask"), optional=True, createByDefault=False
            )
        )
        self.add(
            QgsProcessingParameterFeatureSink(
                self.SEAMLINES,
                tr("Seamlines (source image regions)"),
                QgsProcessing.TypeVectorPolygon,
                optional=True,
                createByDefault=False,
            )
        )

    @core_errors()
    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 - QGIS API
        from ...core.orientation import Orientation
        from ...core.ortho.pipeline import ORTHO_COMPRESSIONS, TrueOrthoConfig, check_output_paths, true_ortho

        orientation = Orientation.load(self.parameterAsFile(parameters, self.ORIENTATION, context))
        surface = self.parameterAsFile(parameters, self.SURFACE, context)
        if not surface:
            raise QgsProcessingException(tr("SURFACE: give a DSM raster or a mesh file"))
        crs = self.parameterAsCrs(parameters, self.CRS, context)
        out_crs = crs_text(crs) if crs.isValid() else orientation.crs
        extent = None
        if parameters.get(self.EXTENT):
            target = qgs_crs(out_crs) if out_crs else crs
            r = self.parameterAsExtent(parameters, self.EXTENT, context, target)
            if not r.isNull() and r.width() > 0 and r.height() > 0:
                extent = (r.xMinimum(), r.yMinimum(), r.xMaximum(), r.yMaximum())
        res = self.parameterAsDouble(parameters, self.RESOLUTION, context)
        executor_kind, address = self.executor_choice(parameters, context)
        cfg = TrueOrthoConfig(
            resolution=res if res > 0 else None,
            extent=extent,
            crs=out_crs,
            color_correction=self.parameterAsBool(parameters, self.COLOR_CORRECTION, context),
            vignetting=self.parameterAsBool(parameters, self.VIGNETTING, context),
            restore_chroma=self.parameterAsBool(parameters, self.RESTORE_CHROMA, context),
            edge_colour=self.edge_colour_choice(parameters, context),
            max_view_angle=self.parameterAsDouble(parameters, self.MAX_VIEW_ANGLE, context),
            blend_width=self.parameterAsInt(parameters, self.BLEND_WIDTH, context),
            tile_size=self.parameterAsInt(parameters, self.TILE_SIZE, context),
            # COMPRESSION's options are listed in the order of ORTHO_COMPRESSIONS
            compression=ORTHO_COMPRESSIONS[self.parameterAsEnum(parameters, self.COMPRESSION, context)],
            jpeg_quality=self.parameterAsInt(parameters, self.JPEG_QUALITY, context),
            # true_ortho makes the executor from these and closes it at the end
            executor=executor_kind,
            scheduler_address=address,
        )
        out = self.parameterAsOutputLayer(parameters, self.OUTPUT, context)
        idx = self.parameterAsOutputLayer(parameters, self.SOURCE_INDEX, context) or None
        occ = self.parameterAsOutputLayer(parameters, self.OCCLUSION, context) or None
        check_output_paths(out, idx, occ)
        run = true_ortho(orientation, surface, out, idx, occ, cfg, FeedbackProgress(feedback))
        st = run.stats
        feedback.pushInfo(
            tr("{} x {} cells, {} images used, coverage {:.2%}, {} cells seen by no image").format(
                st["rows"], st["cols"], st["images_used"], st["coverage"], st["cells_occluded"]
            )
        )
        cc = st.get("color_correction")
        if isinstance(cc, dict) and cc.get("median_before") and cc.get("median_after"):
            feedback.pushInfo(
                tr("colour correction ({}): disagreement between photos, median {:.2f} -> {:.2f}").format(
                    cc.get("model", ""), cc["median_before"][0], cc["median_after"][0]
                )
            )
        results = {self.OUTPUT: out}
        if idx:
            results[self.SOURCE_INDEX] = idx
        if occ:
            results[self.OCCLUSION] = occ
        fields = seamline_fields()
        sink, sid = self.parameterAsSink(
            parameters, self.SEAMLINES, context, fields, QgsWkbTypes.MultiPolygon, qgs_crs(out_crs)
        )
        if sink is not None:
            for region in run.seamlines:
                f = QgsFeature(fields)
                g = QgsGeometry.fromWkt(region.wkt)
                g.convertToMultiType()
                f.setGeometry(g)
                f.setAttributes([region.image_index, region.image_name, region.cells, g.area()])
                sink.addFeature(f, QgsFeatureSink.FastInsert)
            results[self.SEAMLINES] = sid
        return results
