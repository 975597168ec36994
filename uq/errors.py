"""Exceptions with messages meant for users: one hierarchy for every kind of bad input.

:class:`InputError` is the base: the command line prints ``str(error)`` on one line and
exits with status 2 (no traceback, no output file). Its subclasses say what was bad:

* :class:`ScenarioError`: a scenario or configuration file (YAML), a ``--set`` value or a
  command-line argument;
* :class:`DataFileError`: a data file the tool reads (results netCDF, CSV tables, the
  records of a golden-lidar campaign);
* :class:`CheckpointError`: the checkpoint folder of an interrupted run;
* :class:`OutputError`: an output the tool may not write (a name that is a path, a
  target it did not create, a folder it cannot write).

Each names the source (file or option), the key (dotted scenario key, column, path) and
what is allowed. :class:`Terminated` (not bad input) is a KeyboardInterrupt raised on
SIGTERM, so that a batch system's stop cleans up as Ctrl-C does.
"""


import unicodedata

#: Longest echo of an input (a key, a value) in a message [characters]: a key or a
#: ``--set`` value of thousands of characters is shortened in its middle, so that the
#: message stays one readable line.
MAX_ECHO = 80
#: Longest source (a file's path, or ``--set KEY=VALUE (applied to PATH)``) [characters].
MAX_SOURCE = 400
#: Longest message [characters] (what is wrong and what is allowed included).
MAX_MESSAGE = 1000


def one_line(text, limit=MAX_MESSAGE):
    """`text` on one line of at most `limit` characters: line breaks and other control
    characters of an echoed input shown as escapes (``\\n``), the middle of a longer
    text replaced by `` ... ``.

    >>> one_line("wind.spe\\ned")
    'wind.spe\\\\ned'
    >>> len(one_line("x" * 5000, 40))
    40
    """
    text = "".join(repr(c)[1:-1] if unicodedata.category(c) in ("Cc", "Zl", "Zp") else c
                   for c in str(text))
    if len(text) <= limit:
        return text
    keep = limit - len(" ... ")
    return f"{text[:keep - keep // 3]} ... {text[len(text) - keep // 3:]}"


class Terminated(KeyboardInterrupt):
    """The process was asked to stop (SIGTERM: a batch system's time limit, ``timeout``,
    ``kill``): handled like Ctrl-C (every clean-up of an interrupt runs), exit 143."""


class InputError(ValueError):
    """Bad input: names the source, the key and what is allowed.

    Parameters
    ----------
    source : str
        The file or command-line option the bad value came from.
    key : str
        The dotted key, column or path inside it ('' when the whole source is bad).
    problem : str
        What is wrong and what is allowed.
    """

    def __init__(self, source, key, problem):
        self.source, self.key, self.problem = source, key, problem
        source, key = one_line(source, MAX_SOURCE), one_line(key, 2 * MAX_ECHO)
        super().__init__(one_line(f"{source}: {key}: {problem}" if key else
                                  f"{source}: {problem}"))


class ScenarioError(InputError):
    """A scenario or configuration (YAML), a ``--set`` value or a command-line argument."""


class DataFileError(InputError):
    """A data file the tool reads: results, CSV tables, campaign records."""


class CheckpointError(InputError):
    """The checkpoint folder of an interrupted run (``--resume``)."""


class OutputError(InputError):
    """An output the tool may not write or replace."""
