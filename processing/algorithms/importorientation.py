"""``truortho:importorientation``: COLMAP / Orthority / OpenSfM -> orientation JSON + layers."""

from __future__ import annotations

import numpy as np
from qgis.core import (
    QgsFeatureSink,
    QgsProcessing,
    QgsProcessingException,
    QgsProcessingParameterCrs,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFile,
    QgsProcessingParameterFileDestination,
    QgsProcessingParameterNumber,
    QgsWkbTypes,
)

from ..feedback import FeedbackProgress, core_errors
from ..i18n import tr
from ..layers import (
    camera_features,
    camera_fields,
    crs_text,
    footprint_feature,
    footprint_fields,
    qgs_crs,
    read_gcp_layer,
    read_observation_table,
)
from .base import TruOrthoAlgorithm


def default_footprint_height(orientation) -> float:
    """Median height (world) of the sparse points, else of the GCPs, else 0."""
    if orientation.points is not None and len(orientation.points):
        return float(np.median(orientation.points.xyz[:, 2]) + orientation.offset[2])
    if orientation.gcps:
        return float(np.median([g.xyz[2] for g in orientation.gcps]))
    return 0.0


class ImportOrientationAlgorithm(TruOrthoAlgorithm):
    NAME = "importorientation"
    DISPLAY_NAME = "Import orientation"
    GROUP_ID = "orientation"

    INPUT = "INPUT"
    INTERIOR = "INTERIOR"
    CRS = "CRS"
    IMAGE_FOLDER = "IMAGE_FOLDER"
    GCPS = "GCPS"
    OBSERVATIONS = "OBSERVATIONS"
    FOOTPRINT_HEIGHT = "FOOTPRINT_HEIGHT"
    OUTPUT = "OUTPUT"
    CAMERAS = "CAMERAS"
    FOOTPRINTS = "FOOTPRINTS"

    OWN_DEFAULTS = {FOOTPRINT_HEIGHT: "empty = default_footprint_height of the orientation, no config"}

    def initAlgorithm(self, config=None):  # noqa: N802 - QGIS API
        self.add(
            QgsProcessingParameterFile(self.INPUT, tr("Orientation file (COLMAP, Orthority CSV, OpenSfM)"))
        )
        self.add(
            QgsProcessingParameterFile(
                self.INTERIOR, tr("Interior parameter file (Orthority)"), optional=True
            )
        )
        self.add(
            QgsProcessingParameterCrs(
                self.CRS, tr("CRS of the input (when the file has none)"), optional=True
            )
        )
        self.add(
            QgsProcessingParameterFile(
                self.IMAGE_FOLDER,
                tr("Image folder"),
                behavior=QgsProcessingParameterFile.Folder,
                optional=True,
            )
        )
        self.add_ground_control()
        self.add(
            QgsProcessingParameterNumber(
                self.FOOTPRINT_HEIGHT,
                tr("Footprint height"),
                QgsProcessingParameterNumber.Double,
                optional=True,
            )
        )
        self.add(
            QgsProcessingParameterFileDestination(
                self.OUTPUT, tr("Orientation (JSON)"), tr("JSON files (*.json)")
            )
        )
        self.add(
            QgsProcessingParameterFeatureSink(
                self.CAMERAS,
                tr("Cameras"),
                QgsProcessing.TypeVectorPoint,
                optional=True,
                createByDefault=True,
            )
        )
        self.add(
            QgsProcessingParameterFeatureSink(
                self.FOOTPRINTS, tr("Footprints"), QgsProcessing.TypeVectorPolygon, optional=True
            )
        )

    @core_errors()
    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 - QGIS API
        from ...core.exchange import read_orientation
        from ...core.geometry.footprint import footprint_on_plane
        from ...core.progress import Steps

        steps = Steps(FeedbackProgress(feedback), [1, 1, 2, 2])
        path = self.parameterAsFile(parameters, self.INPUT, context)
        interior = self.parameterAsFile(parameters, self.INTERIOR, context) or None
        crs_param = self.parameterAsCrs(parameters, self.CRS, context)
        orientation = read_orientation(path, interior, crs_text(crs_param))
        feedback.pushInfo(
            tr("Read {} images, {} cameras, {} sparse points").format(
                len(orientation.images),
                len(orientation.cameras),
                0 if orientation.points is None else len(orientation.points),
            )
        )
        if not orientation.images:
            raise QgsProcessingException(tr("{}: the orientation contains no images").format(path))
        if orientation.crs is None:
            feedback.pushWarning(
                tr(
                    "The orientation has no CRS: it stays in its arbitrary (local) frame. "
                    "Give CRS (or a georef.json) to georeference it."
                )
            )
        steps[0].update(1.0)

        folder = self.parameterAsFile(parameters, self.IMAGE_FOLDER, context)
        if folder:
            orientation.image_root = folder
            orientation.check_images_exist()

        target = qgs_crs(orientation.crs)
        gcp_layer = self.parameterAsVectorLayer(parameters, self.GCPS, context)
        obs_layer = self.parameterAsVectorLayer(parameters, self.OBSERVATIONS, context)
        if obs_layer is not None and gcp_layer is None:
            raise QgsProcessingException(tr("OBSERVATIONS given without a GCPS layer"))
        if gcp_layer is not None:
            if orientation.crs is None and gcp_layer.crs().isValid():
                raise QgsProcessingException(
                    tr("GCPs need a georeferenced orientation: give CRS for the input")
                )
            gcps = read_gcp_layer(gcp_layer, target, context.transformContext())
            read_observation_table(obs_layer, gcps, {im.name for im in orientation.images})
            orientation.gcps = gcps
            feedback.pushInfo(
                tr("{} GCPs with {} image measurements").format(
                    len(gcps), sum(len(g.observations) for g in gcps)
                )
            )
        steps[1].update(1.0)

        out = self.parameterAsFileOutput(parameters, self.OUTPUT, context)
        orientation.save(out)

        fields = camera_fields()
        sink, cameras_id = self.parameterAsSink(
            parameters, self.CAMERAS, context, fields, QgsWkbTypes.PointZ, target
        )
        n = len(orientation.images)
        results = {self.OUTPUT: out}
        if sink is not None:  # optional: skipped when not asked for (qgis_process, processing.run)
            for i, feat in enumerate(camera_features(orientation, fields)):
                sink.addFeature(feat, QgsFeatureSink.FastInsert)
                steps[2].update((i + 1) / n)
            results[self.CAMERAS] = cameras_id
        fsink, foot_id = self.parameterAsSink(
            parameters, self.FOOTPRINTS, context, footprint_fields(), QgsWkbTypes.PolygonZ, target
        )
        if fsink is not None:
            height = self.parameterAsDouble(parameters, self.FOOTPRINT_HEIGHT, context)
            if parameters.get(self.FOOTPRINT_HEIGHT) is None:
                height = default_footprint_height(orientation)
            z_local = height - orientation.offset[2]
            ffields = footprint_fields()
            for i, im in enumerate(orientation.images):
                if feedback.isCanceled():
                    break
                ring = footprint_on_plane(im.R, im.C, orientation.camera_of(im), z_local)
                if ring is None:
                    feedback.pushWarning(
                        tr("Image {} does not see the plane at height {}").format(im.name, height)
                    )
                    continue
                ring_world = ring + orientation.offset[:2]
                fsink.addFeature(
                    footprint_feature(im.name, im.camera, ring_world, height, ffields),
                    QgsFeatureSink.FastInsert,
                )
                steps[3].update((i + 1) / n)
            results[self.FOOTPRINTS] = foot_id
        return results
