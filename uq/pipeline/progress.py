"""A progress bar on stderr for long runs. No physics.

Silent for the first :data:`DELAY_S` seconds (short runs print nothing) and when stderr
is not a terminal (logs stay clean); then one line, redrawn in place::

    uq run  [##########----------]  512/1024 chunks  12 s, about 12 s left
"""
import sys
import time

#: Seconds before the bar appears [s]: runs shorter than this never show it.
DELAY_S = 2.0
WIDTH = 30


class ProgressBar:
    """Callable ``bar(done, total)``; see the module docstring."""

    def __init__(self, label="uq run", stream=None, force=False):
        self.label, self.stream = label, stream or sys.stderr
        self.enabled = force or self.stream.isatty()
        self.started = time.perf_counter()
        self.shown = False

    def __call__(self, done, total):
        elapsed = time.perf_counter() - self.started
        if not self.enabled or (elapsed < DELAY_S and done < total) or total <= 1:
            return
        if done == total and not self.shown:
            return
        filled = int(WIDTH * done / total)
        rate = elapsed / max(done, 1)
        left = f", about {rate * (total - done):.0f} s left" if done < total else ""
        self.stream.write(f"\r{self.label}  [{'#' * filled}{'-' * (WIDTH - filled)}]  "
                          f"{done}/{total} chunks  {elapsed:.0f} s{left}   ")
        self.shown = True
        if done == total:
            self.stream.write("\n")
        self.stream.flush()
