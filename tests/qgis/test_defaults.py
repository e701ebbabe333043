"""Every algorithm's parameter defaults are its core config's defaults.

The table parameter -> config field lives in the algorithms (``CONFIG_DEFAULTS``, with the
parameters that have no config field in ``OWN_DEFAULTS``); this test reads each parameter's
``defaultValue()`` from an initialised algorithm and the field's default from the dataclass.
"""

from __future__ import annotations

import dataclasses
import importlib
import math

import pytest

pytestmark = pytest.mark.qgis

#: parameter types that carry a default a user sees (files, layers, CRSs, sinks have none)
VALUE_TYPES = {"number", "boolean", "enum", "distance"}


def _core(path: str):
    module, _, name = path.rpartition(".")
    return getattr(importlib.import_module(f"truortho.core.{module}"), name)


def _field_default(config: str, name: str):
    cls = _core(config)
    assert dataclasses.is_dataclass(cls), f"{config} is not a dataclass"
    by_name = {f.name: f for f in dataclasses.fields(cls)}
    assert name in by_name, f"{config} has no field {name!r}"
    f = by_name[name]
    if f.default is not dataclasses.MISSING:
        return f.default
    assert f.default_factory is not dataclasses.MISSING, f"{config}.{name} has no default"
    return f.default_factory()


def _same(param_value, expected) -> bool:
    if expected is None or param_value is None:
        return expected is None and param_value is None
    if isinstance(expected, bool) or isinstance(param_value, bool):
        return isinstance(param_value, bool) and isinstance(expected, bool) and param_value == expected
    return math.isclose(float(param_value), float(expected), rel_tol=0, abs_tol=1e-12)


def mismatches(alg) -> list[str]:
    """What differs between ``alg``'s parameter defaults and its config table."""
    out = []
    defs = {p.name(): p for p in alg.parameterDefinitions()}
    table, own = getattr(alg, "CONFIG_DEFAULTS", {}), getattr(alg, "OWN_DEFAULTS", {})
    for name, src in table.items():
        if name not in defs:
            out.append(f"{alg.name()}: CONFIG_DEFAULTS names {name}, which is not a parameter")
            continue
        expected = _field_default(src.config, src.field)
        if src.choices:
            choices = _core(src.choices) if isinstance(src.choices, str) else src.choices
            expected = tuple(choices).index(expected)
        elif expected is None:
            expected = src.none
        got = defs[name].defaultValue()
        if not _same(got, expected):
            out.append(f"{alg.name()}.{name}: default {got!r}, {src.config}.{src.field} gives {expected!r}")
    for name, p in defs.items():
        if p.isDestination() or p.type() not in VALUE_TYPES:
            continue
        listed = (name in table) + (name in own)
        if listed != 1:
            out.append(f"{alg.name()}.{name}: in {listed} of CONFIG_DEFAULTS/OWN_DEFAULTS (expected 1)")
    return out


@pytest.fixture(scope="module")
def algorithms(qgis_processing_ready):
    from truortho.processing.algorithms import ALGORITHMS

    out = []
    for cls in ALGORITHMS:
        alg = cls()
        alg.initAlgorithm()
        out.append(alg)
    return out


def test_every_default_comes_from_its_config(algorithms):
    assert [m for alg in algorithms for m in mismatches(alg)] == []
    n_config = sum(len(getattr(alg, "CONFIG_DEFAULTS", {})) for alg in algorithms)
    assert n_config >= 40  # the tiled algorithms' numeric parameters are all in the table


def test_a_hand_written_default_is_caught(qgis_processing_ready):
    from truortho.processing.algorithms.dsmfilter import DsmFilterAlgorithm

    class Drifted(DsmFilterAlgorithm):
        def initAlgorithm(self, config=None):  # noqa: N802 - QGIS API
            super().initAlgorithm(config)
            self.parameterDefinition(self.MAX_HOLE).setDefaultValue(12.0)  # DsmFilterConfig says 10 m
            self.parameterDefinition(self.SHARPEN).setDefaultValue(False)

    alg = Drifted()
    alg.initAlgorithm()
    found = mismatches(alg)
    assert len(found) == 2 and "MAX_HOLE" in found[0] + found[1] and "SHARPEN" in found[0] + found[1]

    class Unlisted(DsmFilterAlgorithm):
        OWN_DEFAULTS: dict[str, str] = {}  # EXECUTOR no longer explained

    alg = Unlisted()
    alg.initAlgorithm()
    assert mismatches(alg) == ["dsmfilter.EXECUTOR: in 0 of CONFIG_DEFAULTS/OWN_DEFAULTS (expected 1)"]


def test_a_missing_package_leaves_the_algorithm_loadable(qgis_processing_ready):
    """An ImportError while reading a default must not escape initAlgorithm (it would abort QGIS)."""
    from truortho.processing.algorithms.base import FromConfig
    from truortho.processing.algorithms.dsmfilter import DsmFilterAlgorithm

    class Missing(DsmFilterAlgorithm):
        CONFIG_DEFAULTS = {
            **DsmFilterAlgorithm.CONFIG_DEFAULTS,
            "MAX_HOLE": FromConfig("no_such_module.DsmFilterConfig", "max_hole"),
        }

    alg = Missing()
    alg.initAlgorithm()
    assert alg.parameterDefinition("MAX_HOLE").defaultValue() is None
    assert alg.parameterDefinition("SLOPE").defaultValue() == 0.15  # the others are read
    ok, message = alg.canExecute()
    assert not ok and "no_such_module" in message
    assert DsmFilterAlgorithm().canExecute() == (True, "")
