"""Bridges between QGIS Processing and the core's progress and error protocol.

``FeedbackProgress`` adapts a ``QgsProcessingFeedback`` to the core's
``Progress`` protocol (:mod:`truortho.core.progress`); :func:`core_errors`
turns :class:`~truortho.core.errors.TruOrthoError` into
``QgsProcessingException`` -- the one place where that happens -- and makes
``qgis_process`` print the message of a failed run once (:func:`quiet_console_echo`).
"""

from __future__ import annotations

import contextlib

from qgis.core import QgsProcessingException

from ..core.errors import CancelledError, TruOrthoError
from ..core.progress import EtaProgress
from .i18n import tr


class FeedbackProgress:
    """Core ``Progress`` backed by a ``QgsProcessingFeedback`` (or None).

    ``eta``: append the elapsed time and an estimate of the time left to the messages
    (:class:`~truortho.core.progress.EtaProgress`; off where the core does it per stage).
    """

    def __init__(self, feedback, eta: bool = True) -> None:
        self.feedback = feedback
        self._last_message: str | None = None
        self._eta = EtaProgress(None) if eta else None

    def update(self, fraction: float, message: str | None = None) -> None:
        if self.feedback is None:
            return
        f = min(max(float(fraction), 0.0), 1.0)
        self.feedback.setProgress(100.0 * f)
        if message and message != self._last_message:
            self._last_message = message
            self.feedback.pushInfo(self._eta.annotate(f, message) if self._eta is not None else message)

    def cancelled(self) -> bool:
        return bool(self.feedback is not None and self.feedback.isCanceled())


def quiet_console_echo() -> None:
    """In ``qgis_process`` only: stop echoing the message log, so a failed run's error prints once.

    ``qgis_process`` prints every critical message-log entry to stderr, and QGIS logs the message of
    a failed run twice besides its own ``ERROR:`` line (``QgsProcessingAlgorithm.run`` and
    ``QgsProcessingFeedback.reportError``): three copies. Called as the exception leaves the
    algorithm, when the run is over and ``qgis_process`` is about to exit. The desktop (a log panel,
    no echo) and ``processing.run`` are left alone.
    """
    from qgis.core import QgsApplication

    if QgsApplication.platform() != "qgis_process":
        return
    log = QgsApplication.messageLog()
    if log is not None:
        log.blockSignals(True)


class core_errors(contextlib.ContextDecorator):  # noqa: N801 - used like a function
    """Context manager and decorator: ``TruOrthoError`` -> ``QgsProcessingException``.

    ::

        with core_errors():
            result = core.something(..., progress=FeedbackProgress(feedback))

        @core_errors()
        def processAlgorithm(self, parameters, context, feedback): ...
    """

    def __enter__(self) -> core_errors:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc is None:
            return
        if isinstance(exc, QgsProcessingException | TruOrthoError):
            quiet_console_echo()
        if isinstance(exc, CancelledError):
            detail = str(exc)
            msg = tr("Cancelled by the user")
            raise QgsProcessingException(f"{msg}: {detail}" if detail else msg) from exc
        if isinstance(exc, TruOrthoError):
            raise QgsProcessingException(str(exc)) from exc
