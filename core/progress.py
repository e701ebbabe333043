"""The tiny progress and cancel protocol that ``core`` knows.

Core functions take an optional ``progress`` argument: any object with

``update(fraction: float, message: str | None = None) -> None``
    report overall completion in [0, 1] of the current task, and
``cancelled() -> bool``
    True when the user asked to stop.

:func:`check` raises :class:`~truortho.core.errors.CancelledError` when the
user cancelled. :class:`Steps` splits one progress range into weighted
sub-ranges so nested stages report a monotonic overall fraction.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import Protocol, runtime_checkable

from .errors import CancelledError


@runtime_checkable
class Progress(Protocol):
    def update(self, fraction: float, message: str | None = None) -> None: ...

    def cancelled(self) -> bool: ...


class NullProgress:
    """Progress sink that ignores reports and is never cancelled."""

    def update(self, fraction: float, message: str | None = None) -> None:
        return None

    def cancelled(self) -> bool:
        return False


class CallbackProgress:
    """Adapter from two plain callables (e.g. for scripts and tests)."""

    def __init__(self, on_update=None, is_cancelled=None) -> None:
        self._on_update = on_update
        self._is_cancelled = is_cancelled

    def update(self, fraction: float, message: str | None = None) -> None:
        if self._on_update is not None:
            self._on_update(min(max(float(fraction), 0.0), 1.0), message)

    def cancelled(self) -> bool:
        return bool(self._is_cancelled()) if self._is_cancelled is not None else False


class SubProgress:
    """Maps [0, 1] of a sub-task onto [start, stop] of a parent progress."""

    def __init__(self, parent: Progress, start: float, stop: float) -> None:
        self.parent = parent
        self.start = float(start)
        self.stop = float(stop)

    def update(self, fraction: float, message: str | None = None) -> None:
        f = min(max(float(fraction), 0.0), 1.0)
        self.parent.update(self.start + (self.stop - self.start) * f, message)

    def cancelled(self) -> bool:
        return self.parent.cancelled()


class Steps:
    """Weighted stages of one task: ``for sub in Steps(p, [1, 3]).iter()``."""

    def __init__(self, parent: Progress | None, weights: Sequence[float]) -> None:
        self.parent = as_progress(parent)
        total = float(sum(weights)) or 1.0
        edges = [0.0]
        for w in weights:
            edges.append(edges[-1] + float(w) / total)
        self.edges = edges

    def __getitem__(self, i: int) -> SubProgress:
        return SubProgress(self.parent, self.edges[i], self.edges[i + 1])

    def __len__(self) -> int:
        return len(self.edges) - 1


def format_duration(seconds: float) -> str:
    """``"45 s"``, ``"12 min"``, ``"2 h 05 min"`` (rounded to what a user plans with)."""
    s = max(0.0, float(seconds))
    if s < 90:
        return f"{s:.0f} s"
    m = int(round(s / 60.0))
    if m < 120:
        return f"{m} min"
    return f"{m // 60} h {m % 60:02d} min"


class EtaProgress:
    """Adds the elapsed time and an estimate of the time left to the messages of one long task.

    The clock starts at the first report (stages made up front start when they start). The
    estimate is ``elapsed (1 - f) / f`` from the task's own completed fraction ``f`` (rounded
    by :func:`format_duration`); it appears once the task has run ``min_seconds`` and done
    ``min_fraction``, so the first, unrepresentative seconds do not produce wild figures.
    """

    def __init__(
        self,
        parent: Progress | None,
        min_seconds: float = 10.0,
        min_fraction: float = 0.02,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.parent = as_progress(parent)
        self.min_seconds = float(min_seconds)
        self.min_fraction = float(min_fraction)
        self.clock = clock
        self.t0: float | None = None

    def annotate(self, fraction: float, message: str | None) -> str | None:
        """``message`` with the elapsed time and the estimate appended (when due)."""
        f = min(max(float(fraction), 0.0), 1.0)
        now = self.clock()
        if self.t0 is None:
            self.t0 = now
        if message:
            elapsed = now - self.t0
            if elapsed >= self.min_seconds and self.min_fraction <= f < 1.0:
                left = elapsed * (1.0 - f) / f
                eta = f"{format_duration(elapsed)} elapsed, about {format_duration(left)} left"
                message = f"{message} ({eta})"
        return message

    def update(self, fraction: float, message: str | None = None) -> None:
        message = self.annotate(fraction, message)
        self.parent.update(min(max(float(fraction), 0.0), 1.0), message)

    def cancelled(self) -> bool:
        return self.parent.cancelled()


def as_progress(progress: Progress | None) -> Progress:
    """Return ``progress`` or a :class:`NullProgress` when it is None."""
    return NullProgress() if progress is None else progress


def check(progress: Progress | None) -> None:
    """Raise :class:`CancelledError` if the user cancelled."""
    if progress is not None and progress.cancelled():
        raise CancelledError("cancelled by the user")
