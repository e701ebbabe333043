"""Every module imports where the POSIX-only ``resource`` and ``fcntl`` do not exist (Windows QGIS)."""

from __future__ import annotations

import importlib
import pkgutil
import subprocess
import sys
import textwrap

import truortho


def _modules() -> list[str]:
    out = []
    for sub in ("core", "processing", "truortho_plugin"):
        pkg = importlib.import_module(f"truortho.{sub}")
        out.append(pkg.__name__)
        out += [m.name for m in pkgutil.walk_packages(pkg.__path__, pkg.__name__ + ".")]
    return out


def test_modules_import_without_posix_only_modules():
    code = textwrap.dedent(
        f"""
        import sys
        sys.modules["resource"] = None  # import resource -> ImportError, as on Windows
        sys.modules["fcntl"] = None
        import importlib
        failed = []
        for name in {_modules()!r}:
            try:
                importlib.import_module(name)
            except ImportError as exc:
                if "resource" in str(exc) or "fcntl" in str(exc):
                    failed.append(f"{{name}}: {{exc}}")
        print("\\n".join(failed))
        sys.exit(1 if failed else 0)
        """
    )
    p = subprocess.run([sys.executable, "-P", "-c", code], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stdout + p.stderr[-3000:]


def test_peak_memory_everywhere(monkeypatch):
    from truortho.core import memory

    peak = memory.peak_rss_mb()
    assert peak is not None and 10.0 < peak < 64 * 1024  # MiB on Linux (ru_maxrss in kB)
    monkeypatch.setitem(sys.modules, "resource", None)
    assert memory.peak_rss_mb() is None  # a platform that cannot tell: no error
    assert truortho.core is not None
