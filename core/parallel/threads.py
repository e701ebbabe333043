"""An ordered thread map for the per-image and per-pair work of the orientation.

SIFT extraction (OpenCV), descriptor products (BLAS), the numba kernels
(``nogil``) and the two-view estimation (OpenCV; its random generator is per
thread, seeded before every estimation) all release the GIL, so threads use
every core without copying features between processes. Results come back in
the order of the inputs whatever the order of completion, so the products do
not depend on the number of threads. At most ``2 x threads`` tasks are in
flight (memory stays bounded on blocks of thousands of images); progress and
cancellation are handled in the calling thread between results.
"""

from __future__ import annotations

import os
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any

from ..progress import Progress, as_progress, check

#: Threads when none are given: the cores, at most this many.
MAX_THREADS = 8


def default_threads() -> int:
    """Threads for the orientation's per-image and per-pair work (``TRUORTHO_THREADS`` wins)."""
    env = os.environ.get("TRUORTHO_THREADS", "").strip()
    if env:
        try:
            return max(1, int(env))
        except ValueError:
            pass
    return max(1, min(os.cpu_count() or 1, MAX_THREADS))


def thread_map(
    fn: Callable[[Any], Any],
    items: Iterable[Any],
    threads: int | None = None,
    progress: Progress | None = None,
    message: Callable[[int, int], str] | None = None,
) -> Iterator[Any]:
    """``fn(item)`` for every item, in order, on ``threads`` threads (1: in this thread).

    ``message(k, n)`` is reported (fraction ``k / n``) before result ``k`` is awaited;
    a cancellation raises :class:`~truortho.core.errors.CancelledError` and drops the
    tasks not yet started. Exceptions of ``fn`` are raised in order, where they occur.
    """
    items = list(items)
    n = len(items)
    prog = as_progress(progress)
    workers = default_threads() if threads is None else max(1, int(threads))
    if workers == 1 or n < 2:
        for k, it in enumerate(items):
            check(prog)
            if message is not None:
                prog.update(k / max(n, 1), message(k, n))
            yield fn(it)
        return
    pending: deque[Future] = deque()
    with ThreadPoolExecutor(max_workers=workers, thread_name_prefix="truortho") as pool:
        nxt = 0
        try:
            for k in range(n):
                while nxt < n and len(pending) < 2 * workers:
                    pending.append(pool.submit(fn, items[nxt]))
                    nxt += 1
                check(prog)
                if message is not None:
                    prog.update(k / n, message(k, n))
                yield pending.popleft().result()
        finally:
            for f in pending:
                f.cancel()
