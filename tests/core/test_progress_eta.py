"""Progress messages with the elapsed time and an estimate of the time left (core.progress.EtaProgress)."""

from __future__ import annotations

from truortho.core.progress import CallbackProgress, EtaProgress, Steps, format_duration


def test_format_duration():
    assert format_duration(0) == "0 s"
    assert format_duration(44.6) == "45 s"
    assert format_duration(300) == "5 min"
    assert format_duration(7500) == "2 h 05 min"
    assert format_duration(-3) == "0 s"


def test_eta_from_the_tasks_own_fraction_and_clock_starting_at_its_first_report():
    seen = []
    now = [100.0]
    parent = CallbackProgress(lambda f, m: seen.append((round(f, 3), m)))
    steps = Steps(parent, [1, 1])
    first = EtaProgress(steps[0], clock=lambda: now[0])
    second = EtaProgress(steps[1], clock=lambda: now[0])
    first.update(0.0, "start")
    now[0] += 5
    first.update(0.5, "early")  # under min_seconds: no estimate yet
    now[0] += 55
    first.update(0.5, "half")  # 60 s for half: about 60 s left
    assert seen[-1] == (0.25, "half (60 s elapsed, about 60 s left)")
    first.update(1.0, "done")
    assert seen[-1] == (0.5, "done")
    now[0] += 1000  # the second stage's clock starts at its own first report, not at creation
    second.update(0.0, "second")
    now[0] += 120
    second.update(0.25, "quarter")
    assert seen[-1] == (0.625, "quarter (2 min elapsed, about 6 min left)")
    assert [m for _, m in seen[:2]] == ["start", "early"]
    second.update(0.3)  # no message: nothing added
    assert seen[-1] == (0.65, None)
    assert not second.cancelled()


def test_cancel_passes_through():
    p = EtaProgress(CallbackProgress(is_cancelled=lambda: True))
    assert p.cancelled()
