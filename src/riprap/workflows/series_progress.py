"""What a test series says while it runs (``riprap.workflows.series``): its messages, kept in the
series folder's log (``series.log``) as well as said, and each step's progress (simulated time,
waves made so far, wall time, time to go) in that log every ``PROGRESS_PERIOD_S`` wall seconds.
A campaign (``riprap.workflows.campaign``) follows its members' logs, so that its terminal and
its own ``campaign.log`` show every member's progress; a member's warnings go to its log as
``riprap: warning:`` lines.
"""
from __future__ import annotations

import contextlib
import time as wallclock
import warnings
from pathlib import Path

from riprap.io.log_file import append_log_lines
from riprap.outputs.base import Writer
from riprap.work_estimate import duration_words, warning_line

__all__ = ["SERIES_LOG", "PROGRESS_PERIOD_S", "SeriesLog", "StepProgress", "duration_words"]

#: The series folder's log: every message of the series and its steps' progress.
SERIES_LOG = "series.log"
#: Wall seconds between two progress lines of a step (its first and last are always written).
PROGRESS_PERIOD_S = 30.0


class SeriesLog:
    """The messages of a series: each said (``say``) and appended to the log file once it is
    opened (``open``: after the series folder was claimed, so that a refused folder is not
    touched; what was said before goes in first). ``note`` only logs (progress lines)."""

    def __init__(self, say):
        self.say = say
        self.path = None
        self._waiting = []

    def open(self, path) -> None:
        self.path = Path(path)
        append_log_lines(self.path, self._waiting)
        self._waiting = []

    def __call__(self, line: str) -> None:
        self.say(line)
        self.note(line)

    def note(self, line: str) -> None:
        if self.path is None:
            self._waiting.append(line)
        else:
            append_log_lines(self.path, [line])

    @contextlib.contextmanager
    def warnings_logged(self):
        """Within: warnings are not printed by Python (with their source line) but logged (and
        said) as ``riprap: warning:`` lines, each once; a worker process uses this, where no
        terminal shows them."""
        said = set()

        def show(message, category, filename, lineno, file=None, line=None):
            text = warning_line(message, category)
            if text is not None and text not in said:
                said.add(text)
                self(text)

        with warnings.catch_warnings():     # the filters as they are: shown as Python would
            warnings.showwarning = show
            yield


class StepProgress(Writer):
    """A writer on the run's frames that logs a series step's progress: simulated time, about how
    many of the step's waves were made, wall time so far and the time to go, for the step and for
    the series at this step's pace. Writes no file of the run (and no schedule of its own, so the
    run's steps land where they would without it)."""

    name = "series_progress"

    def __init__(self, log: SeriesLog, *, label: str, end_time: float, sea_duration: float,
                 waves: float, later_simulated_s: float, period_s: float = PROGRESS_PERIOD_S):
        super().__init__(None)
        self.log = log
        self.label = label
        self.end_time = end_time
        self.sea_duration = sea_duration
        self.waves = waves
        self.later = later_simulated_s
        self.period = period_s
        self._start = None
        self._last = None

    def run_ends_at(self, end_time: float) -> None:
        """The run ends at ``end_time`` (a smoke run's cut), not at the step's: the later steps
        are cut alike."""
        if end_time != self.end_time and self.end_time > 0:
            self.later *= end_time / self.end_time
            self.end_time = end_time

    def open(self, model, directory, *, append):
        self._start = (wallclock.perf_counter(), float(model.time))
        self._last = None
        if append:
            self.log(f"riprap: {self.label}: resumed from its checkpoint at t = "
                     f"{float(model.time):.4g} s of {self.end_time:.4g} s")

    def write(self, model, entry):
        now = wallclock.perf_counter()
        if self._last is None or now - self._last >= self.period:
            self._last = now
            self.log.note(self.line(float(model.time), now))

    def close(self, model):
        self.log.note(self.line(float(model.time), wallclock.perf_counter(), done=True))
        return {}

    def line(self, time: float, now: float, done: bool = False) -> str:
        """The progress at simulated ``time`` and wall-clock ``now``."""
        wall = now - self._start[0]
        words = [f"t = {time:.4g} / {self.end_time:.4g} s simulated"]
        if self.waves > 0 and self.sea_duration > 0:
            made = self.waves * min(max(time, 0.0), self.sea_duration) / self.sea_duration
            words.append(f"about {made:.0f} of {self.waves:.0f} waves made")
        words.append(f"{duration_words(wall)} of wall time")
        ran = time - self._start[1]
        if done:
            words.append("step done")
        elif ran > 0 and wall > 0:
            pace = wall / ran                       # wall seconds per simulated second
            step_left = max(self.end_time - time, 0.0) * pace
            words.append(f"about {duration_words(step_left)} to go in this step"
                         + (f", {duration_words(step_left + self.later * pace)} in the series"
                            if self.later > 0 else ""))
        return f"riprap: {self.label}: " + ", ".join(words)
