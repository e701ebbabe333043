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


class _FakeResource:
    """A stand-in for ``resource`` whose peak is 2 GiB in the platform's own unit."""

    RUSAGE_SELF = 0

    def __init__(self, maxrss: int):
        self._maxrss = maxrss

    def getrusage(self, who):
        assert who == self.RUSAGE_SELF
        return type("Usage", (), {"ru_maxrss": self._maxrss})()


def test_peak_memory_units(monkeypatch):
    """ru_maxrss counts kB on Linux and bytes on macOS; both give MiB."""
    from truortho.core import memory

    monkeypatch.setattr(sys, "platform", "linux")
    monkeypatch.setitem(sys.modules, "resource", _FakeResource(2 * 1024 * 1024))  # kB
    assert memory.peak_rss_mb() == 2048.0
    monkeypatch.setattr(sys, "platform", "darwin")
    monkeypatch.setitem(sys.modules, "resource", _FakeResource(2 * 1024**3))  # bytes
    assert memory.peak_rss_mb() == 2048.0


def test_peak_memory_windows_without_psapi(monkeypatch):
    """On "win32" the helper asks psapi and never touches ``resource``; no psapi gives None, not an error."""
    from truortho.core import memory

    monkeypatch.setattr(sys, "platform", "win32")
    monkeypatch.setitem(sys.modules, "resource", _FakeResource(1))  # must not be read
    assert memory.peak_rss_mb() is None  # this Linux ctypes has no windll


def test_freed_memory_goes_back_to_the_system_between_stages(monkeypatch):
    """glibc keeps freed heap memory in its arenas: a stage's freed arrays stayed resident and the
    next stage's came on top (the 406-photo pipeline peaked at 4.6 GB). ``release_freed_memory``
    returns them; elsewhere it does nothing and raises nothing."""
    import platform

    import pytest

    from truortho.core import memory

    if not sys.platform.startswith("linux") or platform.libc_ver()[0] != "glibc":
        pytest.skip("malloc_trim is glibc's")
    code = textwrap.dedent(
        """
        from truortho.core.memory import current_rss_mb, release_freed_memory
        blocks = [bytearray(100_000) for _ in range(3000)]  # 300 MB in heap-sized pieces
        for b in blocks:
            b[::4096] = b"x" * len(b[::4096])  # touched: resident
        pin = blocks[-1]  # the heap's top stays in use, so free() alone cannot shrink it
        del blocks[:-1]
        before = current_rss_mb()
        release_freed_memory()
        after = current_rss_mb()
        print(before, after)
        """
    )
    p = subprocess.run([sys.executable, "-P", "-c", code], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr[-2000:]
    before, after = map(float, p.stdout.split())
    assert before - after > 150.0, (before, after)
    monkeypatch.setattr(sys, "platform", "win32")
    assert memory.release_freed_memory() is None
