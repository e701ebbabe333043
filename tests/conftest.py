"""Shared test setup.

Layout: ``tests/core/`` tests need only numpy & co. and run everywhere;
``tests/qgis/`` tests (marked ``qgis``) need QGIS and are not collected when
``qgis.core`` cannot be imported. There is deliberately no ``__init__.py`` in
``tests/`` (the repository root is itself the ``truortho`` package) and tests
run with ``--import-mode=importlib``.

QGIS is started by pytest-qgis (``qgis_app``/``qgis_processing`` fixtures)
when that plugin is installed (it is, in .venv); otherwise by the fallback here.
"""

from __future__ import annotations

import importlib.util
import os
import sys
import tempfile
import time
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parent.parent

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")


def _shared_data_dir() -> str:
    """The shared data sets: $TRUORTHO_DATA, else ../shared/data beside the clone, else /work/shared/data.

    Test modules read ``os.environ["TRUORTHO_DATA"]`` (set here before they are imported)
    and skip when the folder is missing.
    """
    for cand in (os.environ.get("TRUORTHO_DATA"), REPO_ROOT.parent / "shared" / "data", "/work/shared/data"):
        if cand and Path(cand).is_dir():
            return str(cand)
    return str(REPO_ROOT.parent / "shared" / "data")


os.environ["TRUORTHO_DATA"] = _shared_data_dir()


def _ensure_truortho_importable() -> None:
    """Make ``import truortho`` work even outside the venv (whose .pth does it).

    The repository root must never be on sys.path itself: its ``processing/``
    would shadow QGIS's ``processing``. Link it as ``truortho`` in a temp dir.
    """
    spec = importlib.util.find_spec("truortho")
    if spec is not None and spec.origin and Path(spec.origin).resolve().parent == REPO_ROOT:
        return
    link_dir = Path(tempfile.mkdtemp(prefix="truortho-path-"))
    (link_dir / "truortho").symlink_to(REPO_ROOT, target_is_directory=True)
    sys.path.insert(0, str(link_dir))


_ensure_truortho_importable()

# pytest imports the repository root's __init__.py (a package) under the name of the checkout's
# folder; a checkout in a folder named "dask" would then shadow Dask for every later import. Import
# the real Dask first (core/parallel and its tests need it).
try:
    import dask  # noqa: F401
    import distributed  # noqa: F401
except ImportError:
    pass

try:
    import qgis.core  # noqa: F401

    HAVE_QGIS = True
except ImportError:
    HAVE_QGIS = False

collect_ignore: list[str] = [] if HAVE_QGIS else ["qgis"]


def pytest_report_header(config):
    return f"truortho: {REPO_ROOT}; QGIS tests {'enabled' if HAVE_QGIS else 'NOT collected (no qgis.core)'}"


def _startup_qgis_temp_dirs() -> list[Path]:
    """The empty /tmp/QGIS3-XXXXXX folders made while this process started (pytest-qgis starts
    QGIS before this file is imported, and QGIS 3.22 leaves that folder behind, empty, at exit)."""
    try:
        import psutil

        start = psutil.Process().create_time() - 1.0
    except Exception:
        return []
    found = []
    for d in Path(tempfile.gettempdir()).glob("QGIS3-*"):
        try:
            st = d.stat()
        except OSError:
            continue
        if start <= st.st_ctime <= _IMPORTED and st.st_uid == os.getuid() and not any(d.iterdir()):
            found.append(d)
    return found


_IMPORTED = time.time()
_QGIS_STARTUP_DIRS = _startup_qgis_temp_dirs()


def pytest_unconfigure(config):
    for d in _QGIS_STARTUP_DIRS:
        try:
            d.rmdir()  # only if still empty
        except OSError:
            pass


def pytest_collection_modifyitems(config, items):
    qgis_dir = REPO_ROOT / "tests" / "qgis"
    for item in items:
        if qgis_dir in Path(str(item.path)).parents and item.get_closest_marker("qgis") is None:
            item.add_marker(pytest.mark.qgis)


@pytest.fixture(scope="session")
def qgis_processing_ready(request):
    """A running QgsApplication with QGIS's Processing framework initialized."""
    if not HAVE_QGIS:
        pytest.skip("QGIS is not importable")
    if request.config.pluginmanager.hasplugin("pytest_qgis"):
        request.getfixturevalue("qgis_processing")
        from qgis.core import QgsApplication

        return QgsApplication.instance()

    from qgis.core import QgsApplication

    app = QgsApplication.instance()
    if app is None:
        app = QgsApplication([], False)
        app.initQgis()
        request.config._truortho_qgis_app = app  # keep a reference for the session
    plugins = os.path.join(QgsApplication.pkgDataPath(), "python", "plugins")
    if plugins not in sys.path:
        sys.path.append(plugins)
    from processing.core.Processing import Processing

    Processing.initialize()
    return app


@pytest.fixture(scope="session")
def truortho_plugin(qgis_processing_ready):
    """The plugin started as QGIS starts it (classFactory + initProcessing)."""
    import truortho

    plugin = truortho.classFactory(None)
    plugin.initProcessing()
    yield plugin
    plugin.unload()


@pytest.fixture
def truortho_provider(truortho_plugin):
    """The registered provider, looked up per test (a GUI test may unload and re-register it)."""
    from qgis.core import QgsApplication

    truortho_plugin.initProcessing()

    provider = QgsApplication.processingRegistry().providerById("truortho")
    assert provider is not None, "TruOrtho provider is not registered"
    return provider


@pytest.fixture(scope="session")
def run_qgis_process():
    """``run(*args, timeout=300)``: scripts/qgis_process (this environment, QGIS's own variables
    dropped so the isolated profile applies) as a subprocess, captured, with no stdin."""
    import subprocess

    exe = REPO_ROOT / "scripts" / "qgis_process"
    if not (REPO_ROOT / ".venv" / "qgis-config").is_dir():
        pytest.fail("run scripts/setup.sh (make setup) first: no .venv/qgis-config")

    def run(*args: str, timeout: float = 300) -> subprocess.CompletedProcess:
        env = {k: v for k, v in os.environ.items() if not k.startswith("QGIS_")}
        cmd = [str(exe), *args]
        kw = {"capture_output": True, "text": True, "timeout": timeout, "env": env}
        return subprocess.run(cmd, stdin=subprocess.DEVNULL, **kw)

    return run
