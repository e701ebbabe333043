"""Where TruOrtho keeps its caches: one per-user folder, never the products folder.

Two caches live there, both safe to delete at any time (they only save time):

* ``numba/``: compiled kernels (:mod:`truortho.core.jit`); a first run compiles them;
* ``features/``: SIFT features per photo (:mod:`truortho.core.sfm.features`), keyed by the
  photo's absolute path, modification time, size and the detection parameters, so blocks share
  the folder safely and a changed photo is detected again.

The folder is ``$TRUORTHO_CACHE_DIR`` when set, else the operating system's per-user cache
folder: ``%LOCALAPPDATA%\\truortho\\cache`` on Windows, ``~/Library/Caches/truortho`` on macOS,
``$XDG_CACHE_HOME/truortho`` (default ``~/.cache/truortho``) elsewhere. :func:`clear_cache`
empties it (``truortho:environment`` reports its size and clears it on request).

Pure standard library: :mod:`truortho.core.jit` reads it before numba is imported.
"""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

#: Environment variable that overrides the cache folder.
CACHE_ENV = "TRUORTHO_CACHE_DIR"
#: The sub-folders TruOrtho writes (what :func:`clear_cache` removes).
CACHE_KINDS = ("numba", "features")


def cache_root() -> Path:
    """The cache folder of this user (not created here).

    Returns
    -------
    Path
        ``$TRUORTHO_CACHE_DIR`` if set and not empty, else the per-user cache folder of the OS.
    """
    env = os.environ.get(CACHE_ENV, "").strip()
    if env:
        return Path(env).expanduser()
    home = Path.home()
    if sys.platform.startswith("win"):
        base = os.environ.get("LOCALAPPDATA") or str(home / "AppData" / "Local")
        return Path(base) / "truortho" / "cache"
    if sys.platform == "darwin":
        return home / "Library" / "Caches" / "truortho"
    base = os.environ.get("XDG_CACHE_HOME", "").strip() or str(home / ".cache")
    return Path(base) / "truortho"


def cache_dir(kind: str) -> Path:
    """The folder of one cache, ``kind`` in :data:`CACHE_KINDS` (not created here)."""
    if kind not in CACHE_KINDS:
        raise ValueError(f"cache kind must be one of {CACHE_KINDS}, got {kind!r}")
    return cache_root() / kind


def cache_size() -> int:
    """Bytes held by the TruOrtho caches (0 when the folder does not exist)."""
    total = 0
    for kind in CACHE_KINDS:
        for dirpath, _, files in os.walk(cache_dir(kind)):
            for name in files:
                try:
                    total += os.path.getsize(os.path.join(dirpath, name))
                except OSError:
                    pass
    return total


def clear_cache() -> int:
    """Delete the TruOrtho caches (:data:`CACHE_KINDS` only, never other files of the folder).

    Returns
    -------
    int
        Bytes freed. Kernels compiled into this process stay usable; the next process
        compiles them again.
    """
    freed = cache_size()
    for kind in CACHE_KINDS:
        shutil.rmtree(cache_dir(kind), ignore_errors=True)
    return freed
