"""``truortho:orientimages``: images (+ GCPs) -> adjusted orientation, report and layers."""

from __future__ import annotations

import os

from qgis.core import (
    QgsFeature,
    QgsFeatureSink,
    QgsField,
    QgsFields,
    QgsGeometry,
    QgsPoint,
    QgsProcessing,
    QgsProcessingException,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterCrs,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFile,
    QgsProcessingParameterFileDestination,
    QgsProcessingParameterMultipleLayers,
    QgsProcessingParameterNumber,
    QgsWkbTypes,
)
from qgis.PyQt.QtCore import QVariant

from ..feedback import FeedbackProgress, core_errors
from ..i18n import tr
from ..layers import camera_features, camera_fields, crs_text, ground_control, qgs_crs
from .base import FromConfig, TruOrthoAlgorithm


def report_beside(orientation_json: str) -> str:
    """Where the report goes when REPORT is not given: ``<orientation stem>_report.html`` beside it."""
    stem, _ = os.path.splitext(orientation_json)
    return stem + "_report.html"


def tie_point_fields() -> QgsFields:
    fields = QgsFields()
    fields.append(QgsField("multiplicity", QVariant.Int))
    fields.append(QgsField("error_px", QVariant.Double))
    for c in ("red", "green", "blue"):
        fields.append(QgsField(c, QVariant.Int))
    return fields


def residual_fields() -> QgsFields:
    fields = QgsFields()
    fields.append(QgsField("name", QVariant.String))
    fields.append(QgsField("role", QVariant.String))
    for c in ("dx", "dy", "dz", "d3"):
        fields.append(QgsField(c, QVariant.Double))
    fields.append(QgsField("images", QVariant.Int))
    return fields


class OrientImagesAlgorithm(TruOrthoAlgorithm):
    NAME = "orientimages"
    DISPLAY_NAME = "Orient images (bundle block adjustment)"
    GROUP_ID = "orientation"

    IMAGES = "IMAGES"
    IMAGE_FILES = "IMAGE_FILES"
    CAMERA = "CAMERA"
    GCPS = "GCPS"
    OBSERVATIONS = "OBSERVATIONS"
    CRS = "CRS"
    WORKING_SIZE = "WORKING_SIZE"
    MAX_FEATURES = "MAX_FEATURES"
    SELF_CALIBRATION = "SELF_CALIBRATION"
    ORIENTATION = "ORIENTATION"
    REPORT = "REPORT"
    CAMERAS = "CAMERAS"
    TIE_POINTS = "TIE_POINTS"
    GCP_RESIDUALS = "GCP_RESIDUALS"

    CONFIG_DEFAULTS = {
        WORKING_SIZE: FromConfig("sfm.pipeline.OrientConfig", "working_size"),
        MAX_FEATURES: FromConfig("sfm.pipeline.OrientConfig", "max_features"),
        SELF_CALIBRATION: FromConfig("sfm.pipeline.OrientConfig", "self_calibration"),
    }

    def initAlgorithm(self, config=None):  # noqa: N802 - QGIS API
        self.add(
            QgsProcessingParameterFile(
                self.IMAGES, tr("Image folder"), behavior=QgsProcessingParameterFile.Folder, optional=True
            )
        )
        self.add(
            QgsProcessingParameterMultipleLayers(
                self.IMAGE_FILES,
                tr("Image files (instead of a folder)"),
                QgsProcessing.TypeFile,
                optional=True,
            )
        )
        self.add(
            QgsProcessingParameterFile(self.CAMERA, tr("Interior orientation file (optional)"), optional=True)
        )
        self.add_ground_control()
        self.add(QgsProcessingParameterCrs(self.CRS, tr("Output CRS"), optional=True))
        self.add(
            QgsProcessingParameterNumber(
                self.WORKING_SIZE,
                tr("Working resolution (max image side, px)"),
                QgsProcessingParameterNumber.Integer,
                self.default(self.WORKING_SIZE),
                minValue=200,
            ),
            advanced=True,
        )
        self.add(
            QgsProcessingParameterNumber(
                self.MAX_FEATURES,
                tr("Features per image"),
                QgsProcessingParameterNumber.Integer,
                self.default(self.MAX_FEATURES),
                minValue=100,
            ),
            advanced=True,
        )
        self.add(
            QgsProcessingParameterBoolean(
                self.SELF_CALIBRATION, tr("Self-calibration"), self.default(self.SELF_CALIBRATION)
            ),
            advanced=True,
        )
        self.add(
            QgsProcessingParameterFileDestination(
                self.ORIENTATION, tr("Orientation (JSON)"), tr("JSON files (*.json)")
            )
        )
        self.add(
            QgsProcessingParameterFileDestination(
                self.REPORT,
                tr("Report (HTML)"),
                tr("HTML files (*.html)"),
                optional=True,
                createByDefault=True,
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
                self.TIE_POINTS, tr("Tie points"), QgsProcessing.TypeVectorPoint, optional=True
            )
        )
        self.add(
            QgsProcessingParameterFeatureSink(
                self.GCP_RESIDUALS,
                tr("GCP and check point residuals"),
                QgsProcessing.TypeVectorPoint,
                optional=True,
            )
        )

    def _image_paths(self, parameters, context) -> list[str]:
        folder = self.parameterAsFile(parameters, self.IMAGES, context)
        raw = parameters.get(self.IMAGE_FILES) or []
        if isinstance(raw, str):
            raw = [raw]
        files = [f.source() if hasattr(f, "source") else str(f) for f in raw]
        if folder and files:
            raise QgsProcessingException(tr("Give either IMAGES (a folder) or IMAGE_FILES, not both"))
        if folder:
            if not os.path.isdir(folder):
                raise QgsProcessingException(tr("IMAGES: {} is not a folder").format(folder))
            return [
                os.path.join(folder, n)
                for n in sorted(os.listdir(folder))
                if os.path.isfile(os.path.join(folder, n))
            ]
        if not files:
            raise QgsProcessingException(tr("IMAGES: give an image folder or a list of image files"))
        return files

    @core_errors()
    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 - QGIS API
        from ...core.cache import cache_root
        from ...core.sfm.pipeline import OrientConfig, orient_images

        paths = self._image_paths(parameters, context)
        crs = self.parameterAsCrs(parameters, self.CRS, context)
        gcp_layer = self.parameterAsVectorLayer(parameters, self.GCPS, context)
        obs_layer = self.parameterAsVectorLayer(parameters, self.OBSERVATIONS, context)
        gcps, crs = ground_control(gcp_layer, obs_layer, crs, context.transformContext())
        if gcps:
            feedback.pushInfo(
                tr("{} control and {} check points").format(
                    sum(g.role == "gcp" for g in gcps), sum(g.role == "check" for g in gcps)
                )
            )
        cfg = OrientConfig(
            working_size=self.parameterAsInt(parameters, self.WORKING_SIZE, context),
            max_features=self.parameterAsInt(parameters, self.MAX_FEATURES, context),
            self_calibration=self.parameterAsBool(parameters, self.SELF_CALIBRATION, context),
        )
        camera_file = self.parameterAsFile(parameters, self.CAMERA, context) or None
        out_json = self.parameterAsFileOutput(parameters, self.ORIENTATION, context)
        out_html = self.parameterAsFileOutput(parameters, self.REPORT, context) or report_beside(out_json)
        run = orient_images(
            paths,
            camera_file=camera_file,
            gcps=gcps,
            crs=crs_text(crs),
            config=cfg,
            work_dir=str(cache_root()),  # the per-user cache, never beside the products
            progress=FeedbackProgress(feedback),
        )
        for w in run.report.warnings:
            feedback.pushWarning(w)
        o = run.orientation
        o.save(out_json)
        run.report.save(out_html)
        feedback.pushInfo(
            tr("Registered {} of {} images; sigma0 {:.3f} px").format(
                len(o.images), len(paths), run.report.data.get("bundle", {}).get("sigma0", float("nan"))
            )
        )

        target = qgs_crs(o.crs)
        results = {self.ORIENTATION: out_json, self.REPORT: out_html}
        fields = camera_fields()
        sink, cid = self.parameterAsSink(
            parameters, self.CAMERAS, context, fields, QgsWkbTypes.PointZ, target
        )
        if sink is not None:  # optional: skipped when not asked for (qgis_process, processing.run)
            for f in camera_features(o, fields):
                sink.addFeature(f, QgsFeatureSink.FastInsert)
            results[self.CAMERAS] = cid
        tfields = tie_point_fields()
        tsink, tid = self.parameterAsSink(
            parameters, self.TIE_POINTS, context, tfields, QgsWkbTypes.PointZ, target
        )
        if tsink is not None:
            for p, m, e, c in zip(run.tie_xyz, run.tie_multiplicity, run.tie_error, run.tie_rgb, strict=True):
                f = QgsFeature(tfields)
                f.setGeometry(QgsGeometry(QgsPoint(float(p[0]), float(p[1]), float(p[2]))))
                f.setAttributes([int(m), float(e), int(c[0]), int(c[1]), int(c[2])])
                tsink.addFeature(f, QgsFeatureSink.FastInsert)
            results[self.TIE_POINTS] = tid
        rfields = residual_fields()
        rsink, rid = self.parameterAsSink(
            parameters, self.GCP_RESIDUALS, context, rfields, QgsWkbTypes.PointZ, target
        )
        if rsink is not None:
            for row in run.gcp_residuals:
                f = QgsFeature(rfields)
                f.setGeometry(QgsGeometry(QgsPoint(float(row["x"]), float(row["y"]), float(row["z"]))))
                d3 = float((row["dx"] ** 2 + row["dy"] ** 2 + row["dz"] ** 2) ** 0.5)
                f.setAttributes(
                    [
                        row["name"],
                        row["role"],
                        float(row["dx"]),
                        float(row["dy"]),
                        float(row["dz"]),
                        d3,
                        int(row["views"]),
                    ]
                )
                rsink.addFeature(f, QgsFeatureSink.FastInsert)
            results[self.GCP_RESIDUALS] = rid
        return results
