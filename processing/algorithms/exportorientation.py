"""``truortho:exportorientation``: orientation JSON -> COLMAP text model or Orthority files."""

from __future__ import annotations

from qgis.core import (
    QgsProcessingOutputMultipleLayers,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFile,
    QgsProcessingParameterFolderDestination,
)

from ..feedback import core_errors
from ..i18n import tr
from .base import TruOrthoAlgorithm

FORMATS = ["colmap", "opk"]


class ExportOrientationAlgorithm(TruOrthoAlgorithm):
    NAME = "exportorientation"
    DISPLAY_NAME = "Export orientation"
    GROUP_ID = "orientation"

    INPUT = "INPUT"
    FORMAT = "FORMAT"
    OUTPUT = "OUTPUT"
    FILES = "FILES"

    OWN_DEFAULTS = {FORMAT: "the first format of FORMATS, no config"}

    def initAlgorithm(self, config=None):  # noqa: N802 - QGIS API
        self.add(QgsProcessingParameterFile(self.INPUT, tr("Orientation (TruOrtho JSON)"), extension="json"))
        self.add(
            QgsProcessingParameterEnum(
                self.FORMAT,
                tr("Format"),
                [tr("COLMAP text model"), tr("Orthority OPK CSV + interior file")],
                defaultValue=0,
            )
        )
        self.add(QgsProcessingParameterFolderDestination(self.OUTPUT, tr("Output folder")))
        self.addOutput(QgsProcessingOutputMultipleLayers(self.FILES, tr("Files written")))

    @core_errors()
    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 - QGIS API
        from ...core.exchange import write_orientation
        from ...core.orientation import Orientation

        orientation = Orientation.load(self.parameterAsFile(parameters, self.INPUT, context))
        fmt = FORMATS[self.parameterAsEnum(parameters, self.FORMAT, context)]
        folder = self.parameterAsString(parameters, self.OUTPUT, context)
        files = write_orientation(orientation, fmt, folder)
        for f in files:
            feedback.pushInfo(tr("Wrote {}").format(f))
        feedback.setProgress(100)
        return {self.OUTPUT: folder, self.FILES: files}
