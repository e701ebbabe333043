"""``truortho:dsmfilter``: raw DSM (+ confidence) -> filtered DSM (+ DTM, normalised DSM) and statistics."""

from __future__ import annotations

import json
import os

from qgis.core import (
    QgsProcessingOutputNumber,
    QgsProcessingOutputString,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterNumber,
    QgsProcessingParameterRasterDestination,
    QgsProcessingParameterRasterLayer,
)

from ..feedback import FeedbackProgress, core_errors
from ..i18n import tr
from .base import FromConfig, TruOrthoAlgorithm


def _optional_number(alg, parameters, name, context):
    """A number parameter left empty -> None (the core's automatic value)."""
    value = parameters.get(name)
    if value is None or value == "":
        return None
    return alg.parameterAsDouble(parameters, name, context)


class DsmFilterAlgorithm(TruOrthoAlgorithm):
    NAME = "dsmfilter"
    DISPLAY_NAME = "Filter DSM (outliers, holes, smoothing, DTM)"
    GROUP_ID = "surface"

    INPUT = "INPUT"
    CONFIDENCE = "CONFIDENCE"
    OUTLIER_THRESHOLD = "OUTLIER_THRESHOLD"
    OUTLIER_WINDOW = "OUTLIER_WINDOW"
    MIN_SUPPORT = "MIN_SUPPORT"
    MIN_CONFIDENCE = "MIN_CONFIDENCE"
    CONFIDENT = "CONFIDENT"
    MAX_HOLE = "MAX_HOLE"
    STEP = "STEP"
    SHARPEN = "SHARPEN"
    SMOOTH = "SMOOTH"
    SMOOTH_RADIUS = "SMOOTH_RADIUS"
    SMOOTH_TOLERANCE = "SMOOTH_TOLERANCE"
    DTM_RESOLUTION = "DTM_RESOLUTION"
    MAX_WINDOW = "MAX_WINDOW"
    SLOPE = "SLOPE"
    EXECUTOR = "EXECUTOR"
    SCHEDULER_ADDRESS = "SCHEDULER_ADDRESS"
    OUTPUT = "OUTPUT"
    DTM = "DTM"
    NDSM = "NDSM"
    STATISTICS = "STATISTICS"
    OUTLIERS_REMOVED = "OUTLIERS_REMOVED"
    CELLS_FILLED = "CELLS_FILLED"
    HOLES_REMAINING = "HOLES_REMAINING"

    CONFIG_DEFAULTS = {
        OUTLIER_THRESHOLD: FromConfig("surface.filter.DsmFilterConfig", "outlier_threshold"),
        OUTLIER_WINDOW: FromConfig("surface.filter.DsmFilterConfig", "outlier_window"),
        MIN_SUPPORT: FromConfig("surface.filter.DsmFilterConfig", "min_support"),
        MIN_CONFIDENCE: FromConfig("surface.filter.DsmFilterConfig", "min_confidence"),
        CONFIDENT: FromConfig("surface.filter.DsmFilterConfig", "confident"),
        MAX_HOLE: FromConfig("surface.filter.DsmFilterConfig", "max_hole"),
        STEP: FromConfig("surface.filter.DsmFilterConfig", "step"),
        SHARPEN: FromConfig("surface.filter.DsmFilterConfig", "sharpen"),
        SMOOTH: FromConfig("surface.filter.DsmFilterConfig", "smooth"),
        SMOOTH_RADIUS: FromConfig("surface.filter.DsmFilterConfig", "smooth_radius"),
        SMOOTH_TOLERANCE: FromConfig("surface.filter.DsmFilterConfig", "smooth_tolerance"),
        DTM_RESOLUTION: FromConfig("surface.dtm.DtmConfig", "resolution"),
        MAX_WINDOW: FromConfig("surface.dtm.DtmConfig", "max_window"),
        SLOPE: FromConfig("surface.dtm.DtmConfig", "slope"),
    }
    OWN_DEFAULTS = {"EXECUTOR": "filter_dsm takes the executor as an argument: inprocess, the first option"}

    def initAlgorithm(self, config=None):  # noqa: N802 - QGIS API
        num = QgsProcessingParameterNumber
        self.add(QgsProcessingParameterRasterLayer(self.INPUT, tr("Raw DSM")))
        self.add(
            QgsProcessingParameterRasterLayer(self.CONFIDENCE, tr("Confidence raster [0, 1]"), optional=True)
        )
        self.add(
            num(
                self.OUTLIER_THRESHOLD,
                tr("Outlier threshold (m; empty = 4 x resolution)"),
                num.Double,
                self.default(self.OUTLIER_THRESHOLD),
                optional=True,
                minValue=0.0,
            )
        )
        self.add(
            num(
                self.MAX_HOLE,
                tr("Largest hole width filled (m)"),
                num.Double,
                self.default(self.MAX_HOLE),
                minValue=0.0,
            )
        )
        self.add(
            QgsProcessingParameterBoolean(
                self.SHARPEN, tr("Sharpen blurred height steps"), self.default(self.SHARPEN)
            )
        )
        self.add(
            QgsProcessingParameterBoolean(
                self.SMOOTH, tr("Edge-preserving smoothing of planar surfaces"), self.default(self.SMOOTH)
            )
        )
        self.add(
            num(
                self.OUTLIER_WINDOW,
                tr("Outlier window (cells, odd)"),
                num.Integer,
                self.default(self.OUTLIER_WINDOW),
                minValue=3,
                maxValue=15,
            ),
            advanced=True,
        )
        self.add(
            num(
                self.MIN_SUPPORT,
                tr("Supporting neighbours that keep a cell"),
                num.Integer,
                self.default(self.MIN_SUPPORT),
                minValue=0,
            ),
            advanced=True,
        )
        self.add(
            num(
                self.MIN_CONFIDENCE,
                tr("Minimum confidence"),
                num.Double,
                self.default(self.MIN_CONFIDENCE),
                minValue=0.0,
                maxValue=1.0,
            ),
            advanced=True,
        )
        self.add(
            num(
                self.CONFIDENT,
                tr("Confident cells (confidence at least)"),
                num.Double,
                self.default(self.CONFIDENT),
                minValue=0.0,
                maxValue=1.0,
            ),
            advanced=True,
        )
        self.add(
            num(
                self.STEP,
                tr("Height step between surfaces (m)"),
                num.Double,
                self.default(self.STEP),
                minValue=0.01,
            ),
            advanced=True,
        )
        self.add(
            num(
                self.SMOOTH_RADIUS,
                tr("Smoothing radius (cells)"),
                num.Integer,
                self.default(self.SMOOTH_RADIUS),
                minValue=1,
                maxValue=7,
            ),
            advanced=True,
        )
        self.add(
            num(
                self.SMOOTH_TOLERANCE,
                tr("Smoothing height tolerance (m; empty = 2.5 x resolution)"),
                num.Double,
                self.default(self.SMOOTH_TOLERANCE),
                optional=True,
                minValue=0.0,
            ),
            advanced=True,
        )
        self.add(
            num(
                self.DTM_RESOLUTION,
                tr("Ground filter cell size (m; empty = max(1 m, resolution))"),
                num.Double,
                self.default(self.DTM_RESOLUTION),
                optional=True,
                minValue=0.0,
            ),
            advanced=True,
        )
        self.add(
            num(
                self.MAX_WINDOW,
                tr("Ground filter window radius (m)"),
                num.Double,
                self.default(self.MAX_WINDOW),
                minValue=0.1,
            ),
            advanced=True,
        )
        self.add(
            num(
                self.SLOPE,
                tr("Ground filter slope (rise/run)"),
                num.Double,
                self.default(self.SLOPE),
                minValue=0.001,
            ),
            advanced=True,
        )
        self.add_executor()
        self.add(QgsProcessingParameterRasterDestination(self.OUTPUT, tr("Filtered DSM")))
        self.add(
            QgsProcessingParameterRasterDestination(
                self.DTM, tr("Terrain model (DTM)"), optional=True, createByDefault=False
            )
        )
        self.add(
            QgsProcessingParameterRasterDestination(
                self.NDSM, tr("Normalised DSM (height above terrain)"), optional=True, createByDefault=False
            )
        )
        self.addOutput(QgsProcessingOutputString(self.STATISTICS, tr("Statistics (JSON)")))
        self.addOutput(QgsProcessingOutputNumber(self.OUTLIERS_REMOVED, tr("Outliers removed (cells)")))
        self.addOutput(QgsProcessingOutputNumber(self.CELLS_FILLED, tr("Hole cells filled")))
        self.addOutput(QgsProcessingOutputNumber(self.HOLES_REMAINING, tr("Holes left as nodata")))

    @core_errors()
    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 - QGIS API
        from ...core.parallel import make_executor
        from ...core.progress import Steps
        from ...core.surface.dtm import DtmConfig, dtm_from_dsm
        from ...core.surface.filter import DsmFilterConfig, filter_dsm

        src = self.parameterAsRasterLayer(parameters, self.INPUT, context)
        conf = self.parameterAsRasterLayer(parameters, self.CONFIDENCE, context)
        out = self.parameterAsOutputLayer(parameters, self.OUTPUT, context)
        dtm = self.parameterAsOutputLayer(parameters, self.DTM, context) if parameters.get(self.DTM) else ""
        ndsm = (
            self.parameterAsOutputLayer(parameters, self.NDSM, context) if parameters.get(self.NDSM) else ""
        )
        cfg = DsmFilterConfig(
            outlier_threshold=_optional_number(self, parameters, self.OUTLIER_THRESHOLD, context),
            outlier_window=self.parameterAsInt(parameters, self.OUTLIER_WINDOW, context),
            min_support=self.parameterAsInt(parameters, self.MIN_SUPPORT, context),
            min_confidence=self.parameterAsDouble(parameters, self.MIN_CONFIDENCE, context),
            confident=self.parameterAsDouble(parameters, self.CONFIDENT, context),
            max_hole=self.parameterAsDouble(parameters, self.MAX_HOLE, context),
            step=self.parameterAsDouble(parameters, self.STEP, context),
            sharpen=self.parameterAsBool(parameters, self.SHARPEN, context),
            smooth=self.parameterAsBool(parameters, self.SMOOTH, context),
            smooth_radius=self.parameterAsInt(parameters, self.SMOOTH_RADIUS, context),
            smooth_tolerance=_optional_number(self, parameters, self.SMOOTH_TOLERANCE, context),
        )
        executor_kind, address = self.executor_choice(parameters, context)
        executor = make_executor(executor_kind, address)
        progress = FeedbackProgress(feedback)
        steps = Steps(progress, [3, 1 if (dtm or ndsm) else 0])
        try:
            stats = filter_dsm(
                src.source(),
                out,
                conf.source() if conf is not None else None,
                cfg,
                steps[0],
                executor=executor,
            )
        finally:
            executor.close()
        feedback.pushInfo(stats.summary())
        if stats.holes_remaining:
            feedback.pushWarning(
                tr("{} holes ({} cells, widest {:.1f} m) are wider than {} m and stay nodata").format(
                    stats.holes_remaining, stats.cells_remaining, stats.largest_remaining_hole_m, cfg.max_hole
                )
            )
        data = {"filter": stats.as_dict()}
        results = {self.OUTPUT: out}
        if dtm or ndsm:
            dcfg = DtmConfig(
                resolution=_optional_number(self, parameters, self.DTM_RESOLUTION, context),
                max_window=self.parameterAsDouble(parameters, self.MAX_WINDOW, context),
                slope=self.parameterAsDouble(parameters, self.SLOPE, context),
            )
            import tempfile

            target = dtm
            scratch = None
            if not target:  # only the nDSM was asked for: the DTM goes to a scratch file
                scratch = tempfile.mkdtemp(prefix="truortho-dtm-")
                target = os.path.join(scratch, "dtm.tif")
            try:
                dstats = dtm_from_dsm(out, target, dcfg, ndsm or None, steps[1])
            finally:
                if scratch is not None:
                    import shutil

                    shutil.rmtree(scratch, ignore_errors=True)
            data["dtm"] = dstats.as_dict()
            feedback.pushInfo(
                tr("Ground filter at {:.2f} m: {:.1f} % of the cells are ground").format(
                    dstats.working_resolution, 100 * dstats.ground_fraction
                )
            )
            if dtm:
                results[self.DTM] = dtm
            if ndsm:
                results[self.NDSM] = ndsm
        from ..styles import style_on_load

        style_on_load(context, out, "dsm", tr("Filtered DSM"))
        if dtm:
            style_on_load(context, dtm, "dsm", tr("DTM"))
        results[self.STATISTICS] = json.dumps(data)
        results[self.OUTLIERS_REMOVED] = stats.outliers_removed + stats.low_confidence_removed
        results[self.CELLS_FILLED] = stats.cells_filled
        results[self.HOLES_REMAINING] = stats.holes_remaining
        return results
