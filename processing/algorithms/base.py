"""Shared behaviour of TruOrtho algorithms: names, groups and help from data."""

from __future__ import annotations

import dataclasses
import importlib
from typing import Any

from qgis.core import (
    QgsProcessing,
    QgsProcessingAlgorithm,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterEnum,
    QgsProcessingParameterString,
    QgsProcessingParameterVectorLayer,
)

from ..help import help_text, parameter_help
from ..i18n import tr

GROUPS = {
    "orientation": "Orientation",
    "orthophoto": "Orthophoto",
    "surface": "Surface",
    "tools": "Tools",
}


@dataclasses.dataclass(frozen=True)
class FromConfig:
    """A parameter whose default is the default of a field of a core config dataclass.

    Attributes
    ----------
    config : str
        ``"module.Class"`` under ``truortho.core``, e.g. ``"surface.filter.DsmFilterConfig"``
        (resolved when the algorithm is initialised, so the algorithm modules import no core code).
    field : str
        Field of that dataclass.
    choices : tuple or str
        For an enum parameter: the core values in the order of the options (or ``"module.NAME"``
        of such a tuple under ``truortho.core``); the default is the index of the field's default
        among them.
    none : Any
        The parameter's value that stands for the field's ``None`` (e.g. ``0.0`` = automatic).
    """

    config: str
    field: str
    choices: tuple | str = ()
    none: Any = None

    def config_class(self) -> type:
        return _core_attribute(self.config)

    def field_default(self) -> Any:
        """The dataclass field's default value."""
        f = {f.name: f for f in dataclasses.fields(self.config_class())}[self.field]
        if f.default is not dataclasses.MISSING:
            return f.default
        if f.default_factory is not dataclasses.MISSING:
            return f.default_factory()
        raise KeyError(f"{self.config}.{self.field} has no default")

    def value(self) -> Any:
        """The parameter's default."""
        default = self.field_default()
        if self.choices:
            choices = _core_attribute(self.choices) if isinstance(self.choices, str) else self.choices
            return tuple(choices).index(default)
        return self.none if default is None else default


def _core_attribute(path: str) -> Any:
    """``"module.NAME"`` under ``truortho.core`` -> the object."""
    module, _, name = path.rpartition(".")
    return getattr(importlib.import_module(f"truortho.core.{module}"), name)


#: Values of the EXECUTOR parameter (:func:`truortho.core.parallel.make_executor`).
EXECUTOR_CHOICES = ("inprocess", "local", "scheduler")


def executor_default(config: str) -> FromConfig:
    """EXECUTOR's default from the ``executor`` field of ``config``."""
    return FromConfig(config, "executor", EXECUTOR_CHOICES)


class TruOrthoAlgorithm(QgsProcessingAlgorithm):
    """Base class: subclasses set ``NAME``, ``DISPLAY_NAME`` and ``GROUP_ID``.

    ``CONFIG_DEFAULTS`` maps a parameter to the config field that defines its default
    (:meth:`default`); ``OWN_DEFAULTS`` names, with the reason, the parameters with a default that
    no config field defines. ``tests/qgis/test_defaults.py`` checks both for every algorithm.
    """

    NAME = ""
    DISPLAY_NAME = ""
    GROUP_ID = "tools"
    CONFIG_DEFAULTS: dict[str, FromConfig] = {}
    OWN_DEFAULTS: dict[str, str] = {}

    def default(self, name: str) -> Any:
        """Default of parameter ``name``: its config field's default (``CONFIG_DEFAULTS``).

        Reading it imports the config's core module. When a package that module needs is missing
        (numba, OpenCV, ...) the parameter gets no default and :meth:`canExecute` names the
        package: an exception here, during the provider's registration, would abort QGIS.
        """
        try:
            return self.CONFIG_DEFAULTS[name].value()
        except ImportError as exc:
            self._missing = str(exc)
            return None

    def canExecute(self):  # noqa: N802 - QGIS API
        """False with the reason when the defaults could not be read (a missing package)."""
        missing = getattr(self, "_missing", None)
        if missing:
            return False, tr("TruOrtho algorithms could not be loaded: {}").format(missing)
        return True, ""

    def name(self) -> str:
        return self.NAME

    def displayName(self) -> str:  # noqa: N802 - QGIS API
        return tr(self.DISPLAY_NAME)

    def group(self) -> str:
        return tr(GROUPS[self.GROUP_ID])

    def groupId(self) -> str:  # noqa: N802 - QGIS API
        return self.GROUP_ID

    def shortHelpString(self) -> str:  # noqa: N802 - QGIS API
        return help_text(self.NAME)

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

    EXECUTOR_CHOICES = EXECUTOR_CHOICES

    def add_restore_chroma(self) -> None:
        """The advanced RESTORE_CHROMA parameter of the algorithms that make a true orthophoto."""
        self.add(
            QgsProcessingParameterBoolean(
                "RESTORE_CHROMA",
                tr("Restore the colour edges of JPEGs with half-resolution colour"),
                self.default("RESTORE_CHROMA"),
            ),
            advanced=True,
        )

    def add_edge_colour(self) -> None:
        """The advanced EDGE_COLOUR parameter of the algorithms that make a true orthophoto (options in
        the order of :data:`~truortho.core.ortho.edgecolour.EDGE_COLOURS`)."""
        self.add(
            QgsProcessingParameterEnum(
                "EDGE_COLOUR",
                tr("Colour edges from the surface's height steps"),
                options=[
                    tr("off"),
                    tr("checked: where the photos agree with the surface"),
                    tr("surface: at every height step (exact surfaces: LiDAR, building models)"),
                ],
                defaultValue=self.default("EDGE_COLOUR"),
            ),
            advanced=True,
        )

    def edge_colour_choice(self, parameters, context) -> str:
        """EDGE_COLOUR as a :attr:`~truortho.core.ortho.pipeline.TrueOrthoConfig.edge_colour` mode."""
        from ...core.ortho.edgecolour import EDGE_COLOURS

        return EDGE_COLOURS[self.parameterAsEnum(parameters, "EDGE_COLOUR", context)]

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
                defaultValue=self.default("EXECUTOR") if "EXECUTOR" in self.CONFIG_DEFAULTS else 0,
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
