"""Peak memory of this process on every platform QGIS runs on (no POSIX-only import at module level).

``resource.getrusage(...).ru_maxrss`` exists only on POSIX and counts kilobytes on Linux but bytes
on macOS; Windows has no ``resource`` module at all, its peak working set comes from
``GetProcessMemoryInfo`` (psapi). :func:`peak_rss_mb` hides the three.

:func:`release_freed_memory` hands memory that the process has freed back to the system between
the stages of a long run (glibc keeps it otherwise; elsewhere it does nothing).
"""

from __future__ import annotations

import sys


def peak_rss_mb() -> float | None:
    """Peak resident memory of this process in MiB, or None where the platform does not tell."""
    if sys.platform == "win32":
        return _windows_peak()
    try:
        import resource
    except ImportError:
        return None
    peak = float(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
    return peak / (1024.0 * 1024.0) if sys.platform == "darwin" else peak / 1024.0


def _windows_peak() -> float | None:
    try:
        import ctypes
        from ctypes import wintypes

        class Counters(ctypes.Structure):
            _fields_ = [
                ("cb", wintypes.DWORD),
                ("PageFaultCount", wintypes.DWORD),
                ("PeakWorkingSetSize", ctypes.c_size_t),
                ("WorkingSetSize", ctypes.c_size_t),
                ("QuotaPeakPagedPoolUsage", ctypes.c_size_t),
                ("QuotaPagedPoolUsage", ctypes.c_size_t),
                ("QuotaPeakNonPagedPoolUsage", ctypes.c_size_t),
                ("QuotaNonPagedPoolUsage", ctypes.c_size_t),
                ("PagefileUsage", ctypes.c_size_t),
                ("PeakPagefileUsage", ctypes.c_size_t),
            ]

        c = Counters()
        c.cb = ctypes.sizeof(c)
        process = ctypes.windll.kernel32.GetCurrentProcess()  # type: ignore[attr-defined]
        if not ctypes.windll.psapi.GetProcessMemoryInfo(process, ctypes.byref(c), c.cb):  # type: ignore[attr-defined]
            return None
        return c.PeakWorkingSetSize / (1024.0 * 1024.0)
    except (OSError, AttributeError, ImportError):
        return None


def release_freed_memory() -> None:
    """Collect garbage and, with glibc (Linux), return the freed heap pages to the system.

    glibc keeps what a stage frees in its arenas: after the orientation of 105 photos the process
    held 752 MB, 239 MB after ``malloc_trim(0)``. The next stage's arrays then came on top of
    that, and the pipeline's peak was the orientation's retained memory plus the dense matching's
    (406 photos: 2.8 GB after the orientation, 4.2 GB peak in OSGM with a 1 GiB chunk). Called
    between the stages of :func:`~truortho.core.workflow.run_workflow`. No-op on Windows, macOS and
    C libraries without ``malloc_trim``.
    """
    import gc

    gc.collect()
    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes

        libc = ctypes.CDLL("libc.so.6")
        libc.malloc_trim(0)
    except (OSError, AttributeError):
        return


def current_rss_mb() -> float | None:
    """Resident memory of this process now, MiB (Linux ``/proc``); None elsewhere."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmRSS:"):
                    return float(line.split()[1]) / 1024.0
    except OSError:
        return None
    return None
