"""``truortho:dsmtopointcloud`` and ``truortho:mergepointclouds``: LAS 1.4 / LAZ (+ EPT) point clouds."""

from __future__ import annotations

from qgis.core import (
    QgsProcessing,
    QgsProcessingOutputFile,
    QgsProcessingOutputNumber,
    QgsProcessingParameterFileDestination,
    QgsProcessingParameterFolderDestination,
    QgsProcessingParameterMultipleLayers,
    QgsProcessingParameterNumber,
    QgsProcessingParameterRasterLayer,
)

from ..feedback import FeedbackProgress, core_errors
from ..i18n import tr
from .base import TruOrthoAlgorithm
from .dsmfilter import _optional_number

#: File filter of LAS/LAZ outputs (the source text of :func:`las_filter`'s translation).
LAS_FILTER = "LAZ (compressed) (*.laz);;LAS (*.las)"


def las_filter() -> str:
    """``LAS_FILTER``, translated (a literal ``tr()`` so that scripts/i18n_update.py collects it)."""
    return tr("LAZ (compressed) (*.laz);;LAS (*.las)")


def _ept_folder(alg, parameters, name, context) -> str | None:
    if not parameters.get(name):
        return None
    # resolves TEMPORARY_OUTPUT (the GUI's default) to a folder in the processing temp folder
    return alg.parameterAsFileOutput(parameters, name, context) or None


class DsmToPointCloudAlgorithm(TruOrthoAlgorithm):
    NAME = "dsmtopointcloud"
    DISPLAY_NAME = "DSM to point cloud (LAS/LAZ + EPT)"
    GROUP_ID = "surface"

    INPUT = "INPUT"
    ORTHO = "ORTHO"
    CONFIDENCE = "CONFIDENCE"
    OUTPUT = "OUTPUT"
    EPT = "EPT"
    EPT_JSON = "EPT_JSON"
    POINTS = "POINTS"

    def initAlgorithm(self, config=None):  # noqa: N802 - QGIS API
        self.add(QgsProcessingParameterRasterLayer(self.INPUT, tr("DSM")))
        self.add(
            QgsProcessingParameterRasterLayer(self.ORTHO, tr("Orthoimage for point colours"), optional=True)
        )
        self.add(
            QgsProcessingParameterRasterLayer(self.CONFIDENCE, tr("Confidence raster [0, 1]"), optional=True)
        )
        self.add(QgsProcessingParameterFileDestination(self.OUTPUT, tr("Point cloud"), las_filter()))
        self.add(
            QgsProcessingParameterFolderDestination(
                self.EPT,
                tr("EPT dataset folder (opens in QGIS without PDAL)"),
                optional=True,
                createByDefault=True,
            )
        )
        self.addOutput(QgsProcessingOutputFile(self.EPT_JSON, tr("EPT ept.json")))
        self.addOutput(QgsProcessingOutputNumber(self.POINTS, tr("Points")))

    @core_errors()
    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 - QGIS API
        from ...core.surface.pointcloud import dsm_to_point_cloud

        dsm = self.parameterAsRasterLayer(parameters, self.INPUT, context)
        ortho = self.parameterAsRasterLayer(parameters, self.ORTHO, context)
        conf = self.parameterAsRasterLayer(parameters, self.CONFIDENCE, context)
        out = self.parameterAsFileOutput(parameters, self.OUTPUT, context)
        ept = _ept_folder(self, parameters, self.EPT, context)
        info = dsm_to_point_cloud(
            dsm.source(),
            out,
            ortho.source() if ortho is not None else None,
            conf.source() if conf is not None else None,
            ept,
            progress=FeedbackProgress(feedback),
        )
        feedback.pushInfo(tr("{} points written to {}").format(info["points"], out))
        if info["ept"]:
            feedback.pushInfo(tr("EPT dataset: {} (add it as a point cloud layer)").format(info["ept"]))
        return {self.OUTPUT: out, self.EPT: ept, self.EPT_JSON: info["ept"], self.POINTS: info["points"]}


class MergePointCloudsAlgorithm(TruOrthoAlgorithm):
    NAME = "mergepointclouds"
    DISPLAY_NAME = "Merge point clouds (reference systems)"
    GROUP_ID = "surface"

    INPUTS = "INPUTS"
    VOXEL = "VOXEL"
    OUTPUT = "OUTPUT"
    EPT = "EPT"
    EPT_JSON = "EPT_JSON"
    POINTS = "POINTS"

    OWN_DEFAULTS = {VOXEL: "an argument of merge_point_clouds (None = keep all points), no config"}

    def initAlgorithm(self, config=None):  # noqa: N802 - QGIS API
        self.add(
            QgsProcessingParameterMultipleLayers(
                self.INPUTS, tr("Point clouds (LAS/LAZ)"), QgsProcessing.TypeFile
            )
        )
        self.add(
            QgsProcessingParameterNumber(
                self.VOXEL,
                tr("Thin duplicates on a voxel grid (m; empty = keep all)"),
                QgsProcessingParameterNumber.Double,
                None,
                optional=True,
                minValue=0.0,
            )
        )
        self.add(QgsProcessingParameterFileDestination(self.OUTPUT, tr("Merged point cloud"), las_filter()))
        self.add(
            QgsProcessingParameterFolderDestination(
                self.EPT,
                tr("EPT dataset folder (opens in QGIS without PDAL)"),
                optional=True,
                createByDefault=False,
            )
        )
        self.addOutput(QgsProcessingOutputFile(self.EPT_JSON, tr("EPT ept.json")))
        self.addOutput(QgsProcessingOutputNumber(self.POINTS, tr("Points")))

    @core_errors()
    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 - QGIS API
        from ...core.surface.pointcloud import merge_point_clouds, read_point_cloud, write_point_cloud_file

        raw = parameters.get(self.INPUTS) or []
        paths = (
            [raw] if isinstance(raw, str) else [p.source() if hasattr(p, "source") else str(p) for p in raw]
        )
        clouds = []
        for k, p in enumerate(paths):
            feedback.setProgress(30.0 * k / max(len(paths), 1))
            clouds.append(read_point_cloud(p))
        voxel = _optional_number(self, parameters, self.VOXEL, context) or None
        merged = merge_point_clouds(clouds, voxel)
        feedback.pushInfo(
            tr("{} points from {} files ({} after thinning)").format(
                sum(len(c) for c in clouds), len(clouds), len(merged)
            )
        )
        out = self.parameterAsFileOutput(parameters, self.OUTPUT, context)
        ept = _ept_folder(self, parameters, self.EPT, context)
        info = write_point_cloud_file(out, merged, ept, progress=FeedbackProgress(feedback))
        return {self.OUTPUT: out, self.EPT: ept, self.EPT_JSON: info["ept"], self.POINTS: info["points"]}
