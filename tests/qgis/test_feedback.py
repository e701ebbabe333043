"""truortho.processing.feedback: core progress protocol and error conversion."""

from __future__ import annotations

import pytest

pytestmark = pytest.mark.qgis


class RecordingFeedback:
    def __init__(self):
        self.progress: list[float] = []
        self.infos: list[str] = []
        self.canceled = False

    def setProgress(self, value):  # noqa: N802 - QGIS API
        self.progress.append(value)

    def pushInfo(self, text):  # noqa: N802 - QGIS API
        self.infos.append(text)

    def isCanceled(self):  # noqa: N802 - QGIS API
        return self.canceled


def test_feedback_progress_implements_core_protocol():
    from truortho.core.progress import Progress
    from truortho.processing.feedback import FeedbackProgress

    fb = RecordingFeedback()
    p = FeedbackProgress(fb)
    assert isinstance(p, Progress)
    p.update(0.25, "matching")
    p.update(0.5)
    p.update(2.0, "matching")
    assert fb.progress == [25.0, 50.0, 100.0]
    assert fb.infos == ["matching"]
    assert not p.cancelled()
    fb.canceled = True
    assert p.cancelled()


def test_feedback_progress_appends_an_estimate_of_the_time_left():
    from truortho.processing.feedback import FeedbackProgress

    now = [0.0]
    fb = RecordingFeedback()
    p = FeedbackProgress(fb)
    p._eta.clock = lambda: now[0]
    p.update(0.0, "tile 1/4")
    now[0] = 20.0
    p.update(0.25, "tile 2/4")
    assert fb.infos == ["tile 1/4", "tile 2/4 (20 s elapsed, about 60 s left)"]
    q = FeedbackProgress(RecordingFeedback(), eta=False)  # the pipeline: the workflow does it per stage
    q.update(0.5, "x")
    assert q.feedback.infos == ["x"]


def test_feedback_progress_with_real_feedback(qgis_processing_ready):
    from qgis.core import QgsProcessingFeedback

    from truortho.processing.feedback import FeedbackProgress

    fb = QgsProcessingFeedback()
    p = FeedbackProgress(fb)
    p.update(0.4, "step")
    assert fb.progress() == pytest.approx(40.0)
    fb.cancel()
    assert p.cancelled()
    assert FeedbackProgress(None).cancelled() is False


def test_core_errors_converts():
    from qgis.core import QgsProcessingException

    from truortho.core.errors import CancelledError, FormatError
    from truortho.processing.feedback import core_errors

    with pytest.raises(QgsProcessingException, match=r"cam\.txt, line 3: bad focal length"):
        with core_errors():
            raise FormatError("cam.txt", "bad focal length", line=3)

    @core_errors()
    def cancelled():
        raise CancelledError()

    with pytest.raises(QgsProcessingException, match="[Cc]ancelled"):
        cancelled()

    with pytest.raises(KeyError):  # non-TruOrtho errors pass through unchanged
        with core_errors():
            raise KeyError("x")

    with core_errors():
        pass
