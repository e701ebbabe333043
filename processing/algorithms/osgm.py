"""``truortho:osgm``: oriented images -> DSM by object-space semi-global matching (+ confidence,
orthoimage, point cloud).

Parameter parsing, validation and feedback only; :func:`truortho.core.osgm.run_osgm` does the work
(and checks the extent against the area the images see). Parameter checks run before the
orientation is read, so bad input fails fast and writes nothing.
"""

from __future__ import annotations

import json
import os

from qgis.core import (
    QgsProcessingException,
    QgsProcessingOutputString,
    QgsProcessingParameterEnum,
    QgsProcessingParameterExtent,
    QgsProcessingParameterFile,
    QgsProcessingParameterFileDestination,
    QgsProcessingParameterNumber,
    QgsProcessingParameterRasterDestination,
    QgsProcessingParameterRasterLayer,
)

from ..feedback import FeedbackProgress, core_errors
from ..i18n import tr
from ..layers import qgs_crs
from .base import FromConfig, TruOrthoAlgorithm, executor_default
from .dsmfilter import _optional_number
from .pointcloud import LAS_FILTER

POINT_CLOUD_SUFFIXES = (".las", ".laz")


class OsgmAlgorithm(TruOrthoAlgorithm):
    NAME = "osgm"
    DISPLAY_NAME = "Dense matching (OSGM)"
    GROUP_ID = "surface"

    ORIENTATION = "ORIENTATION"
    EXTENT = "EXTENT"
    RESOLUTION = "RESOLUTION"
    Z_STEP = "Z_STEP"
    Z_MIN = "Z_MIN"
    Z_MAX = "Z_MAX"
    Z_SURFACE = "Z_SURFACE"
    PATHS = "PATHS"
    OBLIQUE = "OBLIQUE"
    P1 = "P1"
    P2 = "P2"
    MAX_IMAGES = "MAX_IMAGES"
    TILE_SIZE = "TILE_SIZE"
    EXECUTOR = "EXECUTOR"
    SCHEDULER_ADDRESS = "SCHEDULER_ADDRESS"
    DSM = "DSM"
    CONFIDENCE = "CONFIDENCE"
    ORTHOIMAGE = "ORTHOIMAGE"
    POINT_CLOUD = "POINT_CLOUD"
    STATISTICS = "STATISTICS"

    PATH_CHOICES = [8, 16]
    OBLIQUE_CHOICES = ["none", "auto"]

    CONFIG_DEFAULTS = {
        RESOLUTION: FromConfig("osgm.pipeline.OsgmConfig", "resolution"),
        Z_STEP: FromConfig("osgm.pipeline.OsgmConfig", "z_step"),
        Z_MIN: FromConfig("osgm.pipeline.OsgmConfig", "z_min"),
        Z_MAX: FromConfig("osgm.pipeline.OsgmConfig", "z_max"),
        PATHS: FromConfig("osgm.pipeline.OsgmConfig", "paths", tuple(PATH_CHOICES)),
        OBLIQUE: FromConfig("osgm.pipeline.OsgmConfig", "oblique", tuple(OBLIQUE_CHOICES)),
        P1: FromConfig("osgm.pipeline.OsgmConfig", "p1"),
        P2: FromConfig("osgm.pipeline.OsgmConfig", "p2"),
        MAX_IMAGES: FromConfig("osgm.pipeline.OsgmConfig", "max_images"),
        TILE_SIZE: FromConfig("osgm.pipeline.OsgmConfig", "tile_size"),
        "EXECUTOR": executor_default("osgm.pipeline.OsgmConfig"),
    }

    def initAlgorithm(self, config=None):  # noqa: N802 - QGIS API
        num = QgsProcessingParameterNumber
        self.add(
            QgsProcessingParameterFile(self.ORIENTATION, tr("Orientation (TruOrtho JSON)"), extension="json")
        )
        self.add(
            QgsProcessingParameterExtent(
                self.EXTENT, tr("Extent (default: the area seen by the images)"), optional=True
            )
        )
        self.add(
            num(
                self.RESOLUTION,
                tr("Resolution (m; empty or 0 = median ground sample distance)"),
                num.Double,
                self.default(self.RESOLUTION),
                optional=True,
                minValue=0.0,
            )
        )
        self.add(
            num(
                self.Z_STEP,
                tr("Height step of the search (m; empty or 0 = the resolution)"),
                num.Double,
                self.default(self.Z_STEP),
                optional=True,
                minValue=0.0,
            )
        )
        self.add(
            num(
                self.Z_MIN,
                tr("Lowest height searched (m; empty = automatic)"),
                num.Double,
                self.default(self.Z_MIN),
                optional=True,
            )
        )
        self.add(
            num(
                self.Z_MAX,
                tr("Highest height searched (m; empty = automatic)"),
                num.Double,
                self.default(self.Z_MAX),
                optional=True,
            )
        )
        self.add(
            QgsProcessingParameterRasterLayer(
                self.Z_SURFACE, tr("Coarse surface bounding the search per cell (DSM/DTM)"), optional=True
            )
        )
        self.add(
            QgsProcessingParameterEnum(
                self.PATHS,
                tr("Aggregation paths"),
                options=[str(p) for p in self.PATH_CHOICES],
                defaultValue=self.default(self.PATHS),
            )
        )
        self.add(
            QgsProcessingParameterEnum(
                self.OBLIQUE,
                tr("Oblique images"),
                options=[tr("none: one nadir reference system"), tr("auto: extra systems for obliques")],
                defaultValue=self.default(self.OBLIQUE),
            )
        )
        self.add(
            num(
                self.P1,
                tr("Penalty P1, one height step (cost units; empty = default)"),
                num.Integer,
                self.default(self.P1),
                optional=True,
                minValue=0,
            ),
            advanced=True,
        )
        self.add(
            num(
                self.P2,
                tr("Penalty P2, larger height jumps (cost units; empty = default)"),
                num.Integer,
                self.default(self.P2),
                optional=True,
                minValue=0,
            ),
            advanced=True,
        )
        self.add(
            num(
                self.MAX_IMAGES,
                tr("Images per tile (at most)"),
                num.Integer,
                self.default(self.MAX_IMAGES),
                minValue=2,
            ),
            advanced=True,
        )
        self.add(
            num(
                self.TILE_SIZE,
                tr("Tile size (cells)"),
                num.Integer,
                self.default(self.TILE_SIZE),
                minValue=32,
                maxValue=8192,
            ),
            advanced=True,
        )
        self.add_executor()
        self.add(QgsProcessingParameterRasterDestination(self.DSM, tr("DSM (OSGM)")))
        self.add(
            QgsProcessingParameterRasterDestination(
                self.CONFIDENCE, tr("Confidence [0, 1]"), optional=True, createByDefault=False
            )
        )
        self.add(
            QgsProcessingParameterRasterDestination(
                self.ORTHOIMAGE, tr("Orthoimage (matching colours)"), optional=True, createByDefault=False
            )
        )
        self.add(
            QgsProcessingParameterFileDestination(
                self.POINT_CLOUD,
                tr("Point cloud"),
                tr(LAS_FILTER),
                optional=True,
                createByDefault=False,
            )
        )
        self.addOutput(QgsProcessingOutputString(self.STATISTICS, tr("Statistics (JSON)")))

    # ------------------------------------------------------------------ parsing

    def _optional_output(self, parameters, name, context, raster: bool) -> str | None:
        if not parameters.get(name):
            return None
        if raster:
            path = self.parameterAsOutputLayer(parameters, name, context)
        else:
            path = self.parameterAsFileOutput(parameters, name, context)
        return path or None

    def _extent(self, parameters, context, orientation):
        """EXTENT in the orientation's CRS as (xmin, ymin, xmax, ymax), or None."""
        if not parameters.get(self.EXTENT):
            return None
        r = self.parameterAsExtent(parameters, self.EXTENT, context, qgs_crs(orientation.crs))
        if r.isNull() or not (r.width() > 0 and r.height() > 0):
            raise QgsProcessingException(tr("EXTENT: the extent is empty"))
        return (r.xMinimum(), r.yMinimum(), r.xMaximum(), r.yMaximum())

    def _optional_int(self, parameters, name, context) -> int | None:
        value = _optional_number(self, parameters, name, context)
        return None if value is None else int(round(value))

    @core_errors()
    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 - QGIS API
        from ...core.orientation import Orientation

        path = self.parameterAsFile(parameters, self.ORIENTATION, context)
        if not path or not os.path.isfile(path):
            raise QgsProcessingException(tr("ORIENTATION: the file {!r} does not exist").format(path))

        res = _optional_number(self, parameters, self.RESOLUTION, context)
        z_step = _optional_number(self, parameters, self.Z_STEP, context)
        for name, value in ((self.RESOLUTION, res), (self.Z_STEP, z_step)):
            if value is not None and value < 0:
                raise QgsProcessingException(
                    tr("{}: must be positive (or empty), got {}").format(name, value)
                )
        z_min = _optional_number(self, parameters, self.Z_MIN, context)
        z_max = _optional_number(self, parameters, self.Z_MAX, context)
        if z_min is not None and z_max is not None and z_min >= z_max:
            raise QgsProcessingException(tr("Z_MIN ({}) must be below Z_MAX ({})").format(z_min, z_max))
        z_layer = self.parameterAsRasterLayer(parameters, self.Z_SURFACE, context)
        z_surface = None
        if z_layer is not None:
            if z_layer.providerType() != "gdal" or not os.path.isfile(z_layer.source()):
                raise QgsProcessingException(
                    tr("Z_SURFACE: expected a raster file (GeoTIFF), got {!r}").format(z_layer.source())
                )
            z_surface = z_layer.source()

        dsm = self.parameterAsOutputLayer(parameters, self.DSM, context)
        confidence = self._optional_output(parameters, self.CONFIDENCE, context, raster=True)
        ortho = self._optional_output(parameters, self.ORTHOIMAGE, context, raster=True)
        cloud = self._optional_output(parameters, self.POINT_CLOUD, context, raster=False)
        if cloud and os.path.splitext(cloud)[1].lower() not in POINT_CLOUD_SUFFIXES:
            raise QgsProcessingException(
                tr("POINT_CLOUD: expected a .las or .laz file, got {!r}").format(os.path.basename(cloud))
            )

        from ...core.osgm import OsgmConfig, OsgmOutputs, run_osgm

        executor_kind, address = self.executor_choice(parameters, context)

        cfg = OsgmConfig(
            resolution=res or None,
            z_step=z_step or None,
            z_min=z_min,
            z_max=z_max,
            p1=self._optional_int(parameters, self.P1, context),
            p2=self._optional_int(parameters, self.P2, context),
            paths=self.PATH_CHOICES[self.parameterAsEnum(parameters, self.PATHS, context)],
            max_images=self.parameterAsInt(parameters, self.MAX_IMAGES, context),
            oblique=self.OBLIQUE_CHOICES[self.parameterAsEnum(parameters, self.OBLIQUE, context)],
            tile_size=self.parameterAsInt(parameters, self.TILE_SIZE, context),
            executor=executor_kind,
            scheduler_address=address,
        )
        outputs = OsgmOutputs(dsm=dsm, confidence=confidence, orthoimage=ortho, point_cloud=cloud)
        cfg.validate()  # the core's checks (penalties, output types, ...), before the orientation is read
        outputs.validate()

        orientation = Orientation.load(path)
        extent = self._extent(parameters, context, orientation)
        result = run_osgm(
            orientation, cfg, extent, outputs, z_surface=z_surface, progress=FeedbackProgress(feedback)
        )
        feedback.pushInfo(result.summary())

        from ..styles import style_on_load

        results = {self.DSM: dsm, self.STATISTICS: json.dumps(result.stats)}
        style_on_load(context, dsm, "dsm", tr("DSM (OSGM)"))
        if confidence:
            results[self.CONFIDENCE] = confidence
            style_on_load(context, confidence, "confidence", tr("Confidence (OSGM)"))
        if ortho:
            results[self.ORTHOIMAGE] = ortho
            style_on_load(context, ortho, "ortho", tr("Orthoimage (OSGM)"))
        if cloud:
            results[self.POINT_CLOUD] = cloud
        return results
