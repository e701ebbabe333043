"""Content-addressed cache of finished tiles (one ``.npz`` per task, named by its key).

A task's key is the SHA-256 of everything its result depends on (the caller
builds it with :class:`Digest`: the identity of the inputs, the parameters,
the tile window and the arrays handed to the task). A rerun after a crash
finds the tiles that were finished and computes only the others; a run with
other parameters or inputs has other keys, so tiles of different runs are
never mixed. Files are written atomically (temporary file, rename), so an
interrupted write leaves no truncated tile; an unreadable file counts as a
miss and is replaced.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

#: Bump when the arithmetic of a tile task changes, so older tiles are never reused.
CACHE_FORMAT = "truortho-tile-cache-1"


class Digest:
    """Incremental SHA-256 of plain values and arrays (type, shape and dtype included)."""

    def __init__(self, *parts) -> None:
        self._h = hashlib.sha256(CACHE_FORMAT.encode())
        for p in parts:
            self.add(p)

    def add(self, value) -> Digest:
        h = self._h
        if value is None:
            h.update(b"N;")
        elif isinstance(value, np.ndarray):
            a = np.ascontiguousarray(value)
            h.update(f"A{a.dtype.str}{a.shape};".encode())
            h.update(a.tobytes())
        elif isinstance(value, bytes):
            h.update(b"B%d;" % len(value))
            h.update(value)
        elif isinstance(value, list | tuple):
            h.update(b"L%d;" % len(value))
            for v in value:
                self.add(v)
        elif isinstance(value, dict):
            h.update(b"D" + json.dumps(value, sort_keys=True, default=repr).encode() + b";")
        elif isinstance(value, float):
            h.update(b"F" + float(value).hex().encode() + b";")
        else:
            h.update(f"{type(value).__name__}:{value!r};".encode())
        return self

    def hexdigest(self) -> str:
        return self._h.hexdigest()


def file_identity(path) -> tuple[str, int, int]:
    """(absolute path, size, mtime in ns) of a file: a changed image gives new keys."""
    st = os.stat(path)
    return (os.path.abspath(os.fspath(path)), int(st.st_size), int(st.st_mtime_ns))


class TileCache:
    """Finished tiles in ``folder`` as ``<key>.npz`` (arrays stored exactly as returned).

    ``hits`` and ``misses`` count lookups since creation; ``written`` counts stored tiles.
    """

    def __init__(self, folder, remove_when_done: bool = False) -> None:
        self.folder = Path(folder)
        self.remove_when_done = bool(remove_when_done)
        self.hits = 0
        self.misses = 0
        self.written = 0

    def _path(self, key: str) -> Path:
        if not key or any(ch not in "0123456789abcdef" for ch in key):
            raise ValueError(f"tile cache key must be a hex digest, got {key!r}")
        return self.folder / f"{key}.npz"

    def get(self, key: str) -> tuple[np.ndarray, ...] | None:
        path = self._path(key)
        if not path.is_file():
            self.misses += 1
            return None
        try:
            with np.load(path, allow_pickle=False) as f:
                if str(f["key"]) != key:
                    raise ValueError("key mismatch")
                n = int(f["n"])
                out = tuple(np.array(f[f"a{i}"]) for i in range(n))
        except Exception:  # truncated or foreign file: recompute and overwrite
            self.misses += 1
            path.unlink(missing_ok=True)
            return None
        self.hits += 1
        return out

    def put(self, key: str, arrays) -> None:
        path = self._path(key)
        self.folder.mkdir(parents=True, exist_ok=True)
        arrays = tuple(np.asarray(a) for a in arrays)
        fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix=".npz", dir=self.folder)
        try:
            with os.fdopen(fd, "wb") as f:
                np.savez(
                    f,
                    key=np.array(key),
                    n=np.array(len(arrays)),
                    **{f"a{i}": a for i, a in enumerate(arrays)},
                )
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
        self.written += 1

    def finish(self) -> None:
        """Remove the folder when it was only this run's scratch space (``remove_when_done``)."""
        if self.remove_when_done:
            shutil.rmtree(self.folder, ignore_errors=True)


class ProcessLRU:
    """Objects a worker process keeps between tasks (decoded images, pyramids), by key, LRU.

    ``get(key, make)`` returns the object of ``key``, made by ``make()`` on a miss; at most
    ``size`` objects are kept. Module-level instances live as long as the worker process.
    """

    def __init__(self, size: int = 2) -> None:
        from collections import OrderedDict

        self.size = max(1, int(size))
        self._items: OrderedDict = OrderedDict()

    def get(self, key, make):
        obj = self._items.get(key)
        if obj is None:
            obj = self._items[key] = make()
            while len(self._items) > self.size:
                self._items.popitem(last=False)
        else:
            self._items.move_to_end(key)
        return obj
