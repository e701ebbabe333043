"""Translations: i18n/*.ts cover the code (every algorithm name, group, parameter and output
description and menu label translated); the compiled German and French translators make the provider
speak German and French through the plugin's install_translator; English comes back when removed."""

from __future__ import annotations

import importlib.util
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

pytestmark = pytest.mark.qgis

REPO_ROOT = Path(__file__).resolve().parents[2]
LANGUAGES = ("de", "fr")
#: A few translations checked literally (the rest is read from the .ts files).
EXPECTED = {
    "de": {
        "Orient images (bundle block adjustment)": "Bilder orientieren (Bündelblockausgleichung)",
        "Orthophoto": "Orthophoto",
        "Surface: DSM raster or mesh": "Oberfläche: DOM-Raster oder Dreiecksnetz",
    },
    "fr": {
        "Orient images (bundle block adjustment)": "Orienter les images (compensation par faisceaux)",
        "True orthophoto": "Orthophoto vraie",
        "Surface: DSM raster or mesh": "Surface : raster MNS ou maillage",
    },
}


def _script(name: str):
    """A module of scripts/ (not a package), loaded from its file."""
    path = REPO_ROOT / "scripts" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"_truortho_script_{name}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def i18n_update():
    return _script("i18n_update")


def _ts(lang: str) -> dict[str, tuple[str, str | None]]:
    """{source: (translation, type)} of i18n/truortho_<lang>.ts, read with ElementTree."""
    tree = ET.parse(REPO_ROOT / "i18n" / f"truortho_{lang}.ts")
    assert tree.getroot().get("language") == lang
    contexts = {c.findtext("name") for c in tree.iter("context")}
    assert contexts == {"TruOrtho"}
    out = {}
    for msg in tree.iter("message"):
        el = msg.find("translation")
        out[msg.findtext("source")] = (el.text or "", el.get("type"))
    return out


def _finished(lang: str) -> dict[str, str]:
    return {src: text for src, (text, kind) in _ts(lang).items() if text and kind is None}


@pytest.fixture(scope="module")
def qm_dir(tmp_path_factory):
    """i18n/*.ts compiled by the build's own lrelease step (scripts/build_zip.py) into a temp folder
    laid out like the plugin (``<dir>/i18n/truortho_<lang>.qm``); falls back to the tree's i18n/*.qm."""
    root = tmp_path_factory.mktemp("plugin")
    (root / "i18n").mkdir()
    try:
        built = _script("build_zip").compile_translations(REPO_ROOT, root / "i18n", None)
    except SystemExit:  # no lrelease
        built = []
        for lang in LANGUAGES:
            qm = REPO_ROOT / "i18n" / f"truortho_{lang}.qm"
            if not qm.is_file():
                pytest.skip("lrelease not found and i18n/*.qm not compiled (run scripts/setup.sh)")
            built.append(Path(shutil.copy(qm, root / "i18n" / qm.name)))
    assert sorted(p.name for p in built) == [f"truortho_{lang}.qm" for lang in LANGUAGES]
    return root


@pytest.fixture
def english(truortho_plugin):
    """No TruOrtho translator during the test, the session's one (if any) restored afterwards."""
    from qgis.PyQt.QtCore import QCoreApplication

    from truortho.processing.i18n import tr

    before = truortho_plugin.translator
    if before is not None:
        QCoreApplication.removeTranslator(before)
        truortho_plugin.translator = None
    assert tr("True orthophoto") == "True orthophoto"
    yield truortho_plugin
    if truortho_plugin.translator is not None:
        QCoreApplication.removeTranslator(truortho_plugin.translator)
    truortho_plugin.translator = before
    if before is not None:
        QCoreApplication.installTranslator(before)


@pytest.fixture
def translated(english, qm_dir, monkeypatch):
    """install(locale): the plugin's install_translator with the freshly compiled .qm files."""
    from truortho.truortho_plugin import plugin as plugin_module

    monkeypatch.setattr(plugin_module, "PLUGIN_DIR", str(qm_dir))

    def install(locale: str) -> None:
        assert plugin_module.translation_file(locale) is not None
        assert english.install_translator(locale), locale

    return install


def _algorithm_classes():
    from truortho.processing.algorithms import ALGORITHMS

    return ALGORITHMS


def _texts_of(alg) -> dict[str, str]:
    """The user-facing texts of an initialised algorithm: display name, group, every parameter's
    and output's description."""
    texts = {"displayName": alg.displayName(), "group": alg.group()}
    for p in alg.parameterDefinitions():
        texts[f"parameter {p.name()}"] = p.description()
    for o in alg.outputDefinitions():
        texts[f"output {o.name()}"] = o.description()
    return texts


def _fresh(alg_id: str):
    from qgis.core import QgsApplication

    alg = QgsApplication.processingRegistry().createAlgorithmById(alg_id)
    assert alg is not None, alg_id
    return alg


@pytest.mark.parametrize("lang", LANGUAGES)
def test_provider_speaks_the_language(translated, truortho_provider, lang):
    from qgis.core import QgsApplication

    from truortho.truortho_plugin.plugin import MENU

    finished = _finished(lang)
    translated(lang)
    registry = QgsApplication.processingRegistry()
    alg = registry.algorithmById("truortho:trueortho")
    assert alg.displayName() == finished["True orthophoto"] != "True orthophoto"
    assert alg.group() == finished["Orthophoto"]
    orient = registry.algorithmById("truortho:orientimages")
    assert orient.displayName() == EXPECTED[lang]["Orient images (bundle block adjustment)"]
    # parameters are created with the translator active
    fresh = _fresh("truortho:trueortho")  # keep it: it owns its parameters
    surface = fresh.parameterDefinition("SURFACE")
    assert surface.description() == EXPECTED[lang]["Surface: DSM raster or mesh"]
    for source, text in EXPECTED[lang].items():
        assert finished[source] == text
    from truortho.processing.i18n import tr

    assert tr(MENU) == finished[MENU]


def test_region_falls_back_to_language(translated, truortho_provider):
    from qgis.core import QgsApplication

    translated("de_AT")
    assert (
        QgsApplication.processingRegistry().algorithmById("truortho:osgm").displayName()
        == (_finished("de")["Dense matching (OSGM)"])
    )


def test_english_without_translator(english, truortho_provider):
    from qgis.core import QgsApplication

    from truortho.truortho_plugin.plugin import translation_file

    assert translation_file("xx_YY") is None
    assert not english.install_translator("xx_YY")
    alg = QgsApplication.processingRegistry().algorithmById("truortho:trueortho")
    assert alg.displayName() == "True orthophoto"


@pytest.mark.parametrize("lang", LANGUAGES)
def test_every_algorithm_text_is_translated(english, truortho_provider, i18n_update, lang):
    """displayName, group and every parameter and output description of every algorithm is collected
    by scripts/i18n_update.py and has a finished translation (checked in English: the sources)."""
    collected = i18n_update.extract()
    finished = _finished(lang)
    missing = []
    for cls in _algorithm_classes():
        alg = _fresh(f"truortho:{cls().name()}")
        for what, text in _texts_of(alg).items():
            if text not in collected:
                missing.append(f"{alg.name()} {what}: {text!r} not collected by scripts/i18n_update.py")
            elif text not in finished:
                missing.append(f"{alg.name()} {what}: {text!r} has no finished {lang} translation")
    assert not missing, "\n".join(missing)


@pytest.mark.parametrize("lang", LANGUAGES)
def test_ts_files_cover_the_code(i18n_update, lang):
    """Every string scripts/i18n_update.py collects is in the .ts file (line numbers and order may
    have moved since: the location-exact comparison is ``scripts/i18n_update.py --check``); the menu
    labels are translated; no translation loses or adds a placeholder, HTML tag or accelerator."""
    import re

    from truortho.truortho_plugin.plugin import ENTRIES, MENU

    collected = i18n_update.extract()
    entries = _ts(lang)
    missing = [src for src in collected if src not in entries or entries[src][1] == "obsolete"]
    assert not missing, (
        f"{len(missing)} strings missing from i18n/truortho_{lang}.ts: {missing[:5]} "
        "(run `python -P scripts/i18n_update.py` and translate them)"
    )
    finished = _finished(lang)
    labels = [MENU, "TruOrtho", *(label for _alg, label in ENTRIES)]
    assert not [label for label in labels if label not in finished]
    placeholder = re.compile(r"\{[^{}]*\}|%\d|<[^>]+>|&(?=\w)|…")
    broken = [src for src, text in finished.items() if placeholder.findall(src) != placeholder.findall(text)]
    assert not broken, f"{lang} translations change placeholders: {broken}"
    unfinished = [src for src in collected if src not in finished]
    if unfinished:  # help texts and messages fall back to English: allowed, but say so
        print(f"{len(unfinished)} unfinished {lang} translations (English is shown): {unfinished[:3]}")


def test_update_keeps_translations_and_check_mode(i18n_update, tmp_path, monkeypatch, capsys):
    """On a copy of the tree: the update rewrites the .ts files without losing a translation, --check
    then passes; a new tr() string makes --check fail and comes in unfinished."""
    for top in ("processing", "truortho_plugin", "i18n"):
        shutil.copytree(REPO_ROOT / top, tmp_path / top, ignore=shutil.ignore_patterns("__pycache__", "*.qm"))
    monkeypatch.setattr(i18n_update, "ROOT", tmp_path)
    assert i18n_update.main([]) == 0
    assert i18n_update.main(["--check"]) == 0
    for lang in LANGUAGES:
        kept = i18n_update.read_ts(tmp_path / "i18n" / f"truortho_{lang}.ts")
        for src, text in _finished(lang).items():
            assert kept[src][0] == text, src
    with open(tmp_path / "processing" / "i18n.py", "a", encoding="utf-8") as fh:
        fh.write('\n\nNEW = tr("A brand-new message")\n')
    capsys.readouterr()
    assert i18n_update.main(["--check"]) == 1
    assert "out of date" in capsys.readouterr().out
    assert i18n_update.main([]) == 0
    added = i18n_update.read_ts(tmp_path / "i18n" / "truortho_de.ts")["A brand-new message"]
    assert added == ("", "unfinished")
