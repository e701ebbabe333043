"""Shared behaviour of TruOrtho algorithms: names, groups and help from data."""

from __future__ import annotations

from qgis.core import (
    QgsProcessing,
    QgsProcessingAlgorithm,
    QgsProcessingParameterEnum,
    QgsProcessingParameterString,
    QgsProcessingParameterVectorLayer,
)

from ..help import help_html, parameter_help
from ..i18n import tr

GROUPS = {
    "orientation": "Orientation",
    "orthophoto": "Orthophoto",
    "surface": "Surface",
    "tools": "Tools",
}


class TruOrthoAlgorithm(QgsProcessingAlgorithm):
    """Base class: subclasses set ``NAME``, ``DISPLAY_NAME`` and ``GROUP_ID``."""

    NAME = ""
    DISPLAY_NAME = ""
    GROUP_ID = "tools"

    def name(self) -> str:
        return self.NAME

    def displayName(self) -> str:  # noqa: N802 - QGIS API
        return tr(self.DISPLAY_NAME)

    def group(self) -> str:
        return tr(GROUPS[self.GROUP_ID])

    def groupId(self) -> str:  # noqa: N802 - QGIS API
        return self.GROUP_ID

    def shortHelpString(self) -> str:  # noqa: N802 - QGIS API
        return help_html(self.NAME)

    def createInstance(self):  # noqa: N802 - QGIS API
        return type(self)()

    def add(self, param, advanced: bool = False):
        """Add a parameter with its help text from the help data."""
        text = parameter_help(self.NAME, param.name())
        if text and hasattr(param, "setHelp"):
            param.setHelp(text)
        if advanced:
            param.setFlags(param.flags() | param.FlagAdvanced)
        self.addParameter(param)
        return param

    #: Values of the EXECUTOR parameter (:func:`truortho.core.parallel.make_executor`).
    EXECUTOR_CHOICES = ("inprocess", "local", "scheduler")

    def add_executor(self) -> None:
        """The advanced EXECUTOR and SCHEDULER_ADDRESS parameters of the tiled algorithms."""
        import os

        from ...core.parallel import SCHEDULER_ENV

        self.add(
            QgsProcessingParameterEnum(
                "EXECUTOR",
                tr("Run tiles on"),
                options=[
                    tr("inprocess: this process (all cores)"),
                    tr("local: a Dask cluster of worker processes on this computer"),
                    tr("scheduler: a Dask scheduler (SCHEDULER_ADDRESS)"),
                ],
                defaultValue=0,
            ),
            advanced=True,
        )
        self.add(
            QgsProcessingParameterString(
                "SCHEDULER_ADDRESS",
                tr(
                    "Dask scheduler address (tls://host:port or scheduler file; "
                    "empty = TRUORTHO_DASK_SCHEDULER)"
                ),
                defaultValue=os.environ.get(SCHEDULER_ENV, ""),
                optional=True,
            ),
            advanced=True,
        )

    def executor_choice(self, parameters, context) -> tuple[str, str | None]:
        """(EXECUTOR name, SCHEDULER_ADDRESS or None) of a run."""
        address = (self.parameterAsString(parameters, "SCHEDULER_ADDRESS", context) or "").strip()
        kind = self.EXECUTOR_CHOICES[self.parameterAsEnum(parameters, "EXECUTOR", context)]
        return kind, address or None

    def add_ground_control(self) -> None:
        """The optional GCPS point layer and OBSERVATIONS table (schema in docs/FORMATS.md)."""
        self.add(
            QgsProcessingParameterVectorLayer(
                "GCPS", tr("Ground control points"), [QgsProcessing.TypeVectorPoint], optional=True
            )
        )
        self.add(
            QgsProcessingParameterVectorLayer(
                "OBSERVATIONS",
                tr("GCP image measurements (table)"),
                [QgsProcessing.TypeVector],
                optional=True,
            )
        )
