"""``truortho:importgcps``: ODM gcp_list.txt -> GCP point layer + observation table."""

from __future__ import annotations

from qgis.core import (
    QgsCoordinateTransform,
    QgsFeatureSink,
    QgsProcessing,
    QgsProcessingException,
    QgsProcessingParameterCrs,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFile,
    QgsProcessingParameterNumber,
    QgsProcessingParameterString,
    QgsWkbTypes,
)

from ..feedback import core_errors
from ..i18n import tr
from ..layers import gcp_feature, gcp_fields, observation_features, observation_fields, qgs_crs
from .base import FromConfig, TruOrthoAlgorithm


class ImportGcpsAlgorithm(TruOrthoAlgorithm):
    NAME = "importgcps"
    DISPLAY_NAME = "Import GCP list"
    GROUP_ID = "orientation"

    INPUT = "INPUT"
    CHECK_POINTS = "CHECK_POINTS"
    SIGMA_XY = "SIGMA_XY"
    SIGMA_Z = "SIGMA_Z"
    CRS = "CRS"
    GCPS = "GCPS"
    OBSERVATIONS = "OBSERVATIONS"

    # the accuracies the adjustment assumes for a GCP without its own
    CONFIG_DEFAULTS = {
        SIGMA_XY: FromConfig("sfm.georef.GeorefConfig", "gcp_sigma_xy"),
        SIGMA_Z: FromConfig("sfm.georef.GeorefConfig", "gcp_sigma_z"),
    }

    def initAlgorithm(self, config=None):  # noqa: N802 - QGIS API
        self.add(QgsProcessingParameterFile(self.INPUT, tr("GCP list (ODM gcp_list.txt)")))
        self.add(
            QgsProcessingParameterString(
                self.CHECK_POINTS, tr("Check point names (comma-separated)"), optional=True
            )
        )
        self.add(
            QgsProcessingParameterNumber(
                self.SIGMA_XY,
                tr("Default sigma XY [m]"),
                QgsProcessingParameterNumber.Double,
                self.default(self.SIGMA_XY),
                minValue=1e-6,
            )
        )
        self.add(
            QgsProcessingParameterNumber(
                self.SIGMA_Z,
                tr("Default sigma Z [m]"),
                QgsProcessingParameterNumber.Double,
                self.default(self.SIGMA_Z),
                minValue=1e-6,
            )
        )
        self.add(QgsProcessingParameterCrs(self.CRS, tr("Reproject to CRS"), optional=True))
        self.add(
            QgsProcessingParameterFeatureSink(
                self.GCPS, tr("Ground control points"), QgsProcessing.TypeVectorPoint
            )
        )
        self.add(
            QgsProcessingParameterFeatureSink(
                self.OBSERVATIONS, tr("GCP image measurements"), QgsProcessing.TypeVector
            )
        )

    @core_errors()
    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 - QGIS API
        from ...core.formats.gcplist import read_gcp_list

        path = self.parameterAsFile(parameters, self.INPUT, context)
        crs_txt, gcps = read_gcp_list(path)
        src = qgs_crs(crs_txt)
        dst = self.parameterAsCrs(parameters, self.CRS, context)
        if dst.isValid() and dst != src:
            tr_ = QgsCoordinateTransform(src, dst, context.transformContext())
            for g in gcps:
                p = tr_.transform(float(g.xyz[0]), float(g.xyz[1]))
                g.xyz[0], g.xyz[1] = p.x(), p.y()
            src = dst
        names = {g.name for g in gcps}
        checks = [
            s.strip()
            for s in (self.parameterAsString(parameters, self.CHECK_POINTS, context) or "").split(",")
            if s.strip()
        ]
        unknown = [c for c in checks if c not in names]
        if unknown:
            raise QgsProcessingException(
                tr("CHECK_POINTS: unknown GCP name(s) {}; the file has {}").format(
                    ", ".join(unknown), ", ".join(sorted(names))
                )
            )
        for g in gcps:
            g.role = "check" if g.name in checks else "gcp"
        sxy = self.parameterAsDouble(parameters, self.SIGMA_XY, context)
        sz = self.parameterAsDouble(parameters, self.SIGMA_Z, context)

        fields = gcp_fields()
        sink, gcps_id = self.parameterAsSink(parameters, self.GCPS, context, fields, QgsWkbTypes.PointZ, src)
        if sink is None:
            raise QgsProcessingException(self.invalidSinkError(parameters, self.GCPS))
        for g in gcps:
            sink.addFeature(gcp_feature(g, fields, sxy, sz), QgsFeatureSink.FastInsert)
        ofields = observation_fields()
        osink, obs_id = self.parameterAsSink(
            parameters, self.OBSERVATIONS, context, ofields, QgsWkbTypes.NoGeometry
        )
        if osink is None:
            raise QgsProcessingException(self.invalidSinkError(parameters, self.OBSERVATIONS))
        n_obs = 0
        for f in observation_features(gcps, ofields):
            osink.addFeature(f, QgsFeatureSink.FastInsert)
            n_obs += 1
        feedback.pushInfo(
            tr("{} GCPs ({} check points), {} image measurements").format(len(gcps), len(checks), n_obs)
        )
        feedback.setProgress(100)
        return {self.GCPS: gcps_id, self.OBSERVATIONS: obs_id}
