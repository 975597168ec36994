"""The progress bar: silent for short runs and off a terminal, one redrawn line otherwise."""
import io

import uq.pipeline.progress
from uq.pipeline.progress import ProgressBar


def test_silent_when_quick_or_not_a_terminal():
    stream = io.StringIO()                     # not a tty
    bar = ProgressBar(stream=stream)
    for done in range(1, 11):
        bar(done, 10)
    assert stream.getvalue() == ""
    forced = ProgressBar(stream=stream, force=True)
    for done in range(1, 11):                  # finished before the delay: nothing shown
        forced(done, 10)
    assert stream.getvalue() == ""


def test_long_run_draws_one_line_and_ends_it(monkeypatch):
    monkeypatch.setattr(uq.pipeline.progress, "DELAY_S", -1.0)
    stream = io.StringIO()
    bar = ProgressBar(stream=stream, force=True)
    bar(1, 4)
    bar(4, 4)
    text = stream.getvalue()
    assert text.count("\r") == 2 and text.endswith("\n")
    assert "1/4 chunks" in text and "4/4 chunks" in text and "left" in text
