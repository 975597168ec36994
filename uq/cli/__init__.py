"""Command line: ``uq run``, ``uq check``, ``uq list``, ``uq plot``, ``uq report``,
``uq export``, ``uq bench``, ``uq fit``, ``uq golden``, ``uq campaign``, ``uq warmup``,
``uq --version``; one module per subcommand.

The command line dispatches; it computes nothing. Each subcommand module adds its
parser and imports what it needs only when it runs, so ``uq --help`` and ``uq --version``
load neither scipy, xarray, pandas, matplotlib nor numba. The subcommand modules
themselves are imported by :func:`build_parser`, inside :func:`main`'s handling of
Ctrl-C: importing this package costs a few milliseconds, and a Ctrl-C at any moment of
the command (its start included: :func:`uq.interrupts.hold_while_starting`) ends it
with one line.

Exit status: 0 success; 2 bad input (one line naming the file, the key and what is
allowed; no traceback; no output file); 1 anything else (standard output that cannot be
written, a full disk: one line); 130 interrupted (Ctrl-C); 141 the reader of standard
output went away (a closed pipe: quietly); 143 terminated (SIGTERM: a batch system's
time limit), cleaned up as after Ctrl-C.
"""
import contextlib
import importlib
import sys

from uq._version import __version__
from uq.cli.common import (EXIT_BAD_INPUT, EXIT_FAILURE, EXIT_INTERRUPTED, EXIT_OK,  # noqa: F401
                           EXIT_TERMINATED, Parser, add_common_options, configure_logging,
                           interrupted_status, parse_overrides)
from uq.cli.streams import GuardedStdout, StdoutUnwritable, unwritable_status
from uq.errors import InputError
from uq.interrupts import raise_if_stopped, stopping_on_signals

#: The subcommand modules of :mod:`uq.cli`, in the order of ``uq --help``.
SUBCOMMANDS = ("run", "check", "listing", "plot", "report", "export", "bench", "fit",
               "golden", "campaign", "warmup")
#: Commands that may compile numba kernels: they say so on stderr (uq.cli.compiling).
COMPILING = ("run", "plot", "report", "bench", "fit", "golden", "campaign", "warmup")


def build_parser():
    parser = Parser(prog="uq", description="Uncertainty of ship-based and floating "
                    "Doppler wind lidar: Monte Carlo beside the GUM.",
                    epilog="Run 'uq COMMAND --help' for a command's options. "
                    "Exit status: 0 success, 1 failure, 2 bad input, 130 interrupted, "
                    "141 standard output closed, 143 terminated.")
    parser.add_argument("--version", action="version", version=f"uq {__version__}")
    commands = parser.add_subparsers(dest="command", parser_class=Parser,
                                     metavar="COMMAND", title="commands")
    for name in SUBCOMMANDS:
        module = importlib.import_module(f"uq.cli.{name}")
        add_common_options(module.add_parser(commands))
    return parser


def main(argv=None):
    """Run the command line `argv` (default ``sys.argv[1:]``); returns the exit status."""
    stdout = sys.stdout
    sys.stdout = GuardedStdout(stdout)
    try:
        with stopping_on_signals():
            raise_if_stopped()                   # a Ctrl-C held while uq was starting
            status = _command(argv)
            sys.stdout.flush()                   # a full or closed stdout: said here
            return status
    except StdoutUnwritable as failure:
        return unwritable_status(failure, stdout)
    except InputError as error:
        print(f"uq: error: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt as stop:
        status = interrupted_status(stop)
        print(f"\nuq: {'terminated' if status == EXIT_TERMINATED else 'interrupted'}",
              file=sys.stderr)
        return status
    finally:
        sys.stdout = stdout


def _command(argv):
    """Parse `argv` and run its command (within :func:`main`'s handling)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit:                       # --help, --version, a usage error: what
        sys.stdout.flush()                   # they printed must reach stdout first
        raise
    if args.command is None:                 # bare `uq`: the usage and the commands
        parser.print_help(sys.stderr)
        return EXIT_BAD_INPUT
    configure_logging(args)
    if args.command in COMPILING:
        _cache_notes()
    with _compile_notice(args):
        try:
            status = args.handler(args)
        except Exception as error:
            # a stop that library code turned into another error (a C extension's
            # import fails with "ImportError: initialization failed" when Ctrl-C
            # lands in its initialisation) is the stop
            raise_if_stopped()
            if isinstance(error, RuntimeError) and NO_CACHE_FOLDER in str(error):
                return _no_cache_folder()
            raise
        raise_if_stopped()                   # a stop some library code swallowed
        return status


#: numba's words when it has no folder to keep a compiled kernel in.
NO_CACHE_FOLDER = "no locator available"


def _cache_notes():
    """Warn of what :func:`uq.numbacache.configure` settled for (a planted link)."""
    import logging
    from uq import numbacache
    for note in numbacache.NOTES:
        logging.getLogger("uq.numbacache").warning(note)


def _no_cache_folder():
    """One line, status 1: numba found no writable folder for its compiled kernels."""
    import os
    print("uq: error: numba has no writable folder to keep its compiled kernels in (the "
          "package's, ~/.cache and the temporary folder are not writable, or not this "
          f"user's); allowed: set NUMBA_CACHE_DIR to a writable folder (now "
          f"{os.environ.get('NUMBA_CACHE_DIR') or 'unset'})", file=sys.stderr)
    return EXIT_FAILURE


@contextlib.contextmanager
def _compile_notice(args):
    """Say on stderr when the command compiles numba kernels (uq.cli.compiling; imports
    numba: only for the commands that may compile)."""
    if args.command not in COMPILING:
        yield
        return
    from uq.cli import compiling
    with compiling.notice(args) as args.compile_notice:
        yield


if __name__ == "__main__":
    sys.exit(main())
