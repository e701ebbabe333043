"""The one numba policy of TruOrtho.

All kernels are compiled with the decorators defined here, so caching, GIL
release and floating-point flags are decided in one place:

* ``cache=True`` with the cache in ``numba/`` of the per-user cache folder
  (:mod:`truortho.core.cache`: ``$TRUORTHO_CACHE_DIR``, else the OS cache
  folder), because the plugin folder may be read-only in a desktop install.
  An explicit ``NUMBA_CACHE_DIR`` wins. numba checks a cached kernel against
  its own file only: after editing a kernel that kernels of *other* files call
  (``synthetic.texture._colour``, called by ``synthetic.render._trace``), touch
  the callers' files or clear the cache, else they run the old code (seen while
  adding the crop fields: identical figures before and after the edit). An
  installed plugin never changes, so users are not affected.
* ``nogil=True`` so tiles can run in threads.
* ``fastmath`` only for :data:`fastjit` kernels whose results are compared
  statistically (matching costs); geometry kernels stay IEEE-exact so that
  round trips hold to 1e-9.

Kernels are private functions taking arrays and scalars only (no dicts, no
I/O); public wrappers validate their inputs first, so kernels do not raise on
data. The one exception is a guard against a broken internal contract that no
input can reach (``quickselect.select_rank``'s bounds): it raises
``ValueError``, a programming error, rather than corrupt memory.
"""

from __future__ import annotations

import os

from .cache import cache_dir


def _cache_dir() -> str:
    return str(cache_dir("numba"))


if not os.environ.get("NUMBA_CACHE_DIR"):
    os.environ["NUMBA_CACHE_DIR"] = _cache_dir()

import numba  # noqa: E402

if not getattr(numba.config, "CACHE_DIR", ""):
    numba.config.CACHE_DIR = os.environ["NUMBA_CACHE_DIR"]

prange = numba.prange

#: Exact kernels: geometry, adjustment.
njit = numba.njit(cache=True, nogil=True, fastmath=False)
#: Exact kernels parallelised with ``prange`` over independent rows.
pjit = numba.njit(cache=True, nogil=True, fastmath=False, parallel=True)
#: Kernels whose results are compared statistically (costs, aggregation).
fastjit = numba.njit(cache=True, nogil=True, fastmath=True)
#: Parallel variant of :data:`fastjit`.
pfastjit = numba.njit(cache=True, nogil=True, fastmath=True, parallel=True)
