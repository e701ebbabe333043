"""``truortho:detecttargets``: a folder of photos -> observation table of detected ground targets."""

from __future__ import annotations

from qgis.core import (
    QgsFeature,
    QgsFeatureSink,
    QgsField,
    QgsFields,
    QgsProcessing,
    QgsProcessingException,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFile,
    QgsProcessingParameterNumber,
    QgsProcessingParameterString,
    QgsProcessingParameterVectorLayer,
    QgsWkbTypes,
)
from qgis.PyQt.QtCore import QVariant

from ..feedback import FeedbackProgress, core_errors
from ..i18n import tr
from ..layers import observation_fields, qgs_crs, read_gcp_layer
from .base import FromConfig, TruOrthoAlgorithm

_CONFIG = "gcp.targets.TargetConfig"


def target_observation_fields() -> QgsFields:
    """The observation table (``gcp, image, x, y``) plus ``score, sigma_x, sigma_y, flag``."""
    fields = observation_fields()
    for name in ("score", "sigma_x", "sigma_y"):
        fields.append(QgsField(name, QVariant.Double))
    fields.append(QgsField("flag", QVariant.String))
    return fields


class DetectTargetsAlgorithm(TruOrthoAlgorithm):
    NAME = "detecttargets"
    DISPLAY_NAME = "Detect ground targets"
    GROUP_ID = "orientation"

    IMAGES = "IMAGES"
    TARGET = "TARGET"
    DICTIONARY = "DICTIONARY"
    MARKER_IDS = "MARKER_IDS"
    ORIENTATION = "ORIENTATION"
    GCPS = "GCPS"
    SEARCH_RADIUS = "SEARCH_RADIUS"
    MIN_SCORE = "MIN_SCORE"
    REFINE = "REFINE"
    OUTPUT = "OUTPUT"

    CONFIG_DEFAULTS = {
        TARGET: FromConfig(_CONFIG, "target", "gcp.targets.TARGET_TYPES"),
        DICTIONARY: FromConfig(_CONFIG, "dictionary", "gcp.targets.ARUCO_DICTIONARIES"),
        SEARCH_RADIUS: FromConfig(_CONFIG, "search_radius"),
        MIN_SCORE: FromConfig(_CONFIG, "min_score"),
        REFINE: FromConfig(_CONFIG, "refine"),
    }

    def initAlgorithm(self, config=None):  # noqa: N802 - QGIS API
        try:  # needs OpenCV: without it the algorithm says so (canExecute) instead of aborting QGIS
            from ...core.gcp.targets import ARUCO_DICTIONARIES
        except ImportError as exc:
            self._missing = str(exc)
            ARUCO_DICTIONARIES = ("DICT_4X4_50",)  # noqa: N806 - the name of the real table

        self.add(
            QgsProcessingParameterFile(
                self.IMAGES, tr("Image folder"), behavior=QgsProcessingParameterFile.Folder
            )
        )
        self.add(
            QgsProcessingParameterEnum(
                self.TARGET,
                tr("Target type"),
                options=[tr("ArUco markers"), tr("Circular targets"), tr("Checkerboard (X) targets")],
                defaultValue=self.default(self.TARGET),
            )
        )
        self.add(
            QgsProcessingParameterEnum(
                self.DICTIONARY,
                tr("ArUco dictionary"),
                options=list(ARUCO_DICTIONARIES),
                defaultValue=self.default(self.DICTIONARY),
            )
        )
        self.add(
            QgsProcessingParameterString(
                self.MARKER_IDS, tr("Marker IDs -> GCP names (e.g. 0=GCP1,1=GCP2)"), optional=True
            )
        )
        self.add(
            QgsProcessingParameterFile(
                self.ORIENTATION, tr("Orientation (TruOrtho JSON)"), extension="json", optional=True
            )
        )
        self.add(
            QgsProcessingParameterVectorLayer(
                self.GCPS, tr("Ground control points"), [QgsProcessing.TypeVectorPoint], optional=True
            )
        )
        self.add(
            QgsProcessingParameterNumber(
                self.SEARCH_RADIUS,
                tr("Search radius around predicted positions (px)"),
                QgsProcessingParameterNumber.Double,
                self.default(self.SEARCH_RADIUS),
                minValue=3.0,
            )
        )
        self.add(
            QgsProcessingParameterNumber(
                self.MIN_SCORE,
                tr("Minimum score (lower scores are flagged)"),
                QgsProcessingParameterNumber.Double,
                self.default(self.MIN_SCORE),
                minValue=0.0,
                maxValue=1.0,
            )
        )
        self.add(
            QgsProcessingParameterBoolean(
                self.REFINE, tr("Refine by least-squares matching"), self.default(self.REFINE)
            ),
            advanced=True,
        )
        self.add(
            QgsProcessingParameterFeatureSink(
                self.OUTPUT, tr("Target measurements (observation table)"), QgsProcessing.TypeVector
            )
        )

    def _names(self, parameters, context, gcp_names: set[str] | None) -> dict[int, str] | None:
        from ...core.gcp.targets import parse_id_mapping

        text = (self.parameterAsString(parameters, self.MARKER_IDS, context) or "").strip()
        if not text:
            return None
        names = parse_id_mapping(text)
        if gcp_names is not None:
            unknown = sorted(set(names.values()) - gcp_names)
            if unknown:
                raise QgsProcessingException(
                    tr("MARKER_IDS: GCP name(s) {} are not in the GCP layer (it has {})").format(
                        ", ".join(unknown), ", ".join(sorted(gcp_names)) or "-"
                    )
                )
        return names

    @core_errors()
    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 - QGIS API
        from ...core.gcp.measurements import GroundPoint, list_images, predict
        from ...core.gcp.targets import ARUCO_DICTIONARIES, TARGET_TYPES, TargetConfig, detect_targets
        from ...core.orientation import Orientation

        folder = self.parameterAsFile(parameters, self.IMAGES, context)
        cfg = TargetConfig(
            target=TARGET_TYPES[self.parameterAsEnum(parameters, self.TARGET, context)],
            dictionary=ARUCO_DICTIONARIES[self.parameterAsEnum(parameters, self.DICTIONARY, context)],
            search_radius=self.parameterAsDouble(parameters, self.SEARCH_RADIUS, context),
            min_score=self.parameterAsDouble(parameters, self.MIN_SCORE, context),
            refine=self.parameterAsBool(parameters, self.REFINE, context),
        )
        photos = list_images(folder)
        orientation_file = self.parameterAsFile(parameters, self.ORIENTATION, context)
        orientation = Orientation.load(orientation_file) if orientation_file else None
        layer = self.parameterAsVectorLayer(parameters, self.GCPS, context)
        gcps = []
        if layer is not None:
            target_crs = qgs_crs(orientation.crs) if orientation is not None else None
            gcps = read_gcp_layer(layer, target_crs, context.transformContext())
        names = self._names(parameters, context, {g.name for g in gcps} if layer is not None else None)
        predictions = None
        if cfg.target != "aruco":
            if orientation is None or not gcps:
                raise QgsProcessingException(
                    tr(
                        "{} targets are searched near their predicted positions: give ORIENTATION and GCPS"
                    ).format(cfg.target)
                )
            points = [GroundPoint(g.name, tuple(float(v) for v in g.xyz)) for g in gcps]
            predictions = predict(orientation, points, photos)
            if not predictions:
                raise QgsProcessingException(
                    tr(
                        "No GCP projects into an image of {} with this orientation (the same photos?)"
                    ).format(folder)
                )
            feedback.pushInfo(tr("{} predicted positions").format(len(predictions)))
        elif names is None:
            raise QgsProcessingException(
                tr("MARKER_IDS: give the mapping of marker IDs to GCP names, e.g. 0=GCP1,1=GCP2")
            )
        result = detect_targets(folder, cfg, names, predictions, FeedbackProgress(feedback))
        for w in result.warnings:
            feedback.pushWarning(w)
        # the sink is created only once everything succeeded: a failed run leaves no partial table
        fields = target_observation_fields()
        sink, dest = self.parameterAsSink(parameters, self.OUTPUT, context, fields, QgsWkbTypes.NoGeometry)
        if sink is None:
            raise QgsProcessingException(self.invalidSinkError(parameters, self.OUTPUT))
        for m in sorted(result.measurements, key=lambda m: (m.gcp, m.image)):
            f = QgsFeature(fields)
            f.setAttributes([m.gcp, m.image, m.x, m.y, m.score, _num(m.sigma_x), _num(m.sigma_y), m.flag])
            sink.addFeature(f, QgsFeatureSink.FastInsert)
        feedback.pushInfo(
            tr("{} measurements ({} flagged) in {} images").format(
                len(result.measurements), sum(m.flag != "ok" for m in result.measurements), result.images
            )
        )
        return {self.OUTPUT: dest}


def _num(v: float):
    """NaN (no standard deviation) is written as NULL."""
    return None if v != v else float(v)
