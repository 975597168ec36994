"""Command line: ``uq run``, ``uq check``, ``uq list``, ``uq plot``, ``uq report``,
``uq export``, ``uq bench``, ``uq fit``, ``uq golden``, ``uq campaign``, ``uq warmup``,
``uq --version``; one module per subcommand.

The command line dispatches; it computes nothing. Each subcommand module adds its
parser and imports what it needs only when it runs, so ``uq --help`` and ``uq --version``
load neither scipy, xarray, pandas, matplotlib nor numba.

Exit status: 0 success; 2 bad input (one line naming the file, the key and what is
allowed; no traceback; no output file); 1 anything else; 130 interrupted (Ctrl-C);
143 terminated (SIGTERM: a batch system's time limit), cleaned up as after Ctrl-C.
"""
import contextlib
import sys

from uq._version import __version__
from uq.cli import (bench, campaign, check, export, fit, golden, listing, plot, report, run,
                    warmup)
from uq.cli.common import (EXIT_BAD_INPUT, EXIT_FAILURE, EXIT_INTERRUPTED, EXIT_OK,  # noqa: F401
                           EXIT_TERMINATED, Parser, add_common_options, configure_logging,
                           interrupted_status, parse_overrides)
from uq.errors import InputError
from uq.interrupts import raise_if_stopped, stopping_on_signals

SUBCOMMANDS = (run, check, listing, plot, report, export, bench, fit, golden, campaign,
               warmup)
#: Commands that may compile numba kernels: they say so on stderr (uq.cli.compiling).
COMPILING = ("run", "plot", "report", "bench", "fit", "golden", "campaign", "warmup")


def build_parser():
    parser = Parser(prog="uq", description="Uncertainty of ship-based and floating "
                    "Doppler wind lidar: Monte Carlo beside the GUM.",
                    epilog="Run 'uq COMMAND --help' for a command's options. "
                    "Exit status: 0 success, 1 failure, 2 bad input, 130 interrupted, "
                    "143 terminated.")
    parser.add_argument("--version", action="version", version=f"uq {__version__}")
    commands = parser.add_subparsers(dest="command", parser_class=Parser,
                                     metavar="COMMAND", title="commands")
    for module in SUBCOMMANDS:
        add_common_options(module.add_parser(commands))
    return parser


def main(argv=None):
    try:
        parser = build_parser()
        args = parser.parse_args(argv)
        if args.command is None:                 # bare `uq`: the usage and the commands
            parser.print_help(sys.stderr)
            return EXIT_BAD_INPUT
        configure_logging(args)
        with stopping_on_signals(), _compile_notice(args):
            try:
                status = args.handler(args)
            except Exception:
                # a stop that library code turned into another error (a C extension's
                # import fails with "ImportError: initialization failed" when Ctrl-C
                # lands in its initialisation) is the stop
                raise_if_stopped()
                raise
            raise_if_stopped()                   # a stop some library code swallowed
            return status
    except InputError as error:
        print(f"uq: error: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt as stop:
        status = interrupted_status(stop)
        print(f"\nuq: {'terminated' if status == EXIT_TERMINATED else 'interrupted'}",
              file=sys.stderr)
        return status


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
