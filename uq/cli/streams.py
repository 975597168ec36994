"""Standard output that a command cannot write: a closed pipe (``uq list | head -1``) or a
full device (``uq list > /dev/full``).

While a command runs, ``sys.stdout`` is a :class:`GuardedStdout`: a write or flush that
fails raises :class:`StdoutUnwritable` (not an OSError, which argparse's help and
library code would take for something else, or swallow), which ``uq.cli.main`` turns
into the command's end (:func:`unwritable_status`):

* the reader of a pipe went away (EPIPE): quietly, status 141 (128 + SIGPIPE, what a
  shell reports for ``yes | head -1``'s writer);
* any other error (a full disk): one line on stderr, status 1.

Either way the rest of standard output goes to ``/dev/null``, so that the interpreter's
last flush at exit reports nothing. Standard library only.
"""
import errno
import os
import sys

#: The exit status after the reader of standard output went away (128 + SIGPIPE).
EXIT_PIPE_CLOSED = 141


class StdoutUnwritable(Exception):
    """Standard output cannot be written; `error` is the OSError it raised."""

    def __init__(self, error):
        super().__init__(str(error))
        self.error = error


class GuardedStdout:
    """A text stream that passes everything to `stream` and turns an OSError of a write
    or flush into :class:`StdoutUnwritable`."""

    def __init__(self, stream):
        self.stream = stream

    def write(self, text):
        try:
            return self.stream.write(text)
        except OSError as error:
            raise StdoutUnwritable(error) from None

    def writelines(self, lines):
        for line in lines:
            self.write(line)

    def flush(self):
        try:
            self.stream.flush()
        except OSError as error:
            raise StdoutUnwritable(error) from None

    def __getattr__(self, name):               # isatty, fileno, encoding, buffer, ...
        return getattr(self.stream, name)


def unwritable_status(failure, stream):
    """The exit status after `failure` (:class:`StdoutUnwritable`) on `stream`, the real
    standard output; what was left to write goes to ``/dev/null`` (see the module
    docstring)."""
    _discard(stream)
    if failure.error.errno == errno.EPIPE:
        return EXIT_PIPE_CLOSED
    reason = failure.error.strerror or str(failure.error)
    try:
        print(f"uq: error: cannot write to standard output ({reason})", file=sys.stderr)
    except OSError:
        pass
    return 1


def _discard(stream):
    """Point the file descriptor of `stream` at ``/dev/null`` (what it still buffers is
    then written there), if it has one."""
    try:
        descriptor = stream.fileno()
    except (AttributeError, OSError, ValueError):
        return
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, descriptor)
    finally:
        os.close(null)
