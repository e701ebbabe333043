"""core.parallel.threads: ordered results, bounded in-flight tasks, cancellation, errors."""

from __future__ import annotations

import threading
import time

import pytest

from truortho.core.errors import CancelledError
from truortho.core.parallel.threads import default_threads, thread_map
from truortho.core.progress import CallbackProgress


@pytest.mark.parametrize("threads", [1, 2, 4])
def test_results_in_input_order_whatever_the_completion_order(threads):
    def slow_first(x):
        time.sleep(0.02 if x % 3 == 0 else 0.0)
        return x * x

    seen = []
    prog = CallbackProgress(lambda f, m: seen.append(m))
    got = list(thread_map(slow_first, range(10), threads, prog, lambda k, n: f"{k}/{n}"))
    assert got == [x * x for x in range(10)]
    assert seen == [f"{k}/10" for k in range(10)]


def test_work_runs_on_several_threads_and_in_bounded_flight():
    names = set()
    running = [0]
    peak = [0]
    lock = threading.Lock()

    def work(x):
        with lock:
            running[0] += 1
            peak[0] = max(peak[0], running[0])
            names.add(threading.current_thread().name)
        time.sleep(0.01)
        with lock:
            running[0] -= 1
        return x

    assert list(thread_map(work, range(20), 2)) == list(range(20))
    assert len(names) == 2 and peak[0] <= 2


def test_cancel_stops_between_results_and_errors_surface_in_order():
    calls = []

    def work(x):
        calls.append(x)
        if x == 5:
            raise ValueError("bad item 5")
        return x

    stop = [False]
    prog = CallbackProgress(is_cancelled=lambda: stop[0])
    it = thread_map(work, range(100), 2, prog)
    assert [next(it) for _ in range(3)] == [0, 1, 2]
    stop[0] = True
    with pytest.raises(CancelledError):
        next(it)
    assert len(calls) <= 3 + 4  # nothing started beyond the bounded window
    with pytest.raises(ValueError, match="bad item 5"):
        list(thread_map(work, range(8), 2))


def test_default_threads(monkeypatch):
    monkeypatch.setenv("TRUORTHO_THREADS", "3")
    assert default_threads() == 3
    monkeypatch.setenv("TRUORTHO_THREADS", "nonsense")
    assert 1 <= default_threads() <= 8
