"""The stages of a long run add up its wall time under their keys (pcbdyn.progress)."""

from pcbdyn import progress
from pcbdyn.progress import Stages


def test_stages_add_up_their_wall_seconds_and_pass_every_message_on(monkeypatch):
    clock = iter([0.0, 1.0, 3.5, 4.0, 10.0, 10.25])
    monkeypatch.setattr(progress.time, "perf_counter", lambda: next(clock))
    said = []
    s = Stages(said.append)  # t = 0
    s.stage("models", "building")  # t = 1: the second before any stage belongs to none
    s("  a detail")
    s.stage("search", "searching")  # t = 3.5
    s.stage("models", "building again")  # t = 4
    s.stage("refine", "refining")  # t = 10
    assert s.seconds() == {"models": 2.5 + 6.0, "search": 0.5, "refine": 0.25}  # t = 10.25
    assert said == ["building", "  a detail", "searching", "building again", "refining"]
