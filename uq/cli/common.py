"""What every subcommand shares: exit codes, the parser that reports usage errors as bad
input, and ``--set`` overrides. Imports nothing heavy (``uq --help`` stays fast)."""
import argparse
import logging
import sys

from uq.errors import ScenarioError, one_line

EXIT_OK, EXIT_FAILURE, EXIT_BAD_INPUT = 0, 1, 2
EXIT_INTERRUPTED = 130          # the shell's code for SIGINT
EXIT_TERMINATED = 143           # the shell's code for SIGTERM (128 + 15)


def interrupted_status(error):
    """The exit status after an interrupt, which is now handled (no longer pending,
    :func:`uq.interrupts.acknowledge`): 143 for SIGTERM, 130 for Ctrl-C."""
    from uq.errors import Terminated
    from uq.interrupts import acknowledge
    acknowledge()
    return EXIT_TERMINATED if isinstance(error, Terminated) else EXIT_INTERRUPTED


class Parser(argparse.ArgumentParser):
    """argparse that reports usage errors as bad input (exit 2, one line)."""

    def error(self, message):
        self.exit(EXIT_BAD_INPUT, f"uq: error: {message}\n")


def add_overrides(parser, what="a scenario value", example="KEY"):
    """``--set KEY=VALUE`` and ``--unset KEY`` (both repeatable, applied in the order
    given) into ``args.set``, read by :func:`parse_overrides`."""
    parser.add_argument("--set", action="append", default=[], metavar=f"{example}=VALUE",
                        help=f"override {what} (dotted key, YAML value); repeatable; "
                        f"{example}=null removes the key, as --unset does")
    parser.add_argument("--unset", action="append", dest="set", type=_unset,
                        metavar=example, help="remove an optional key (what the file "
                        "says without it: its default, or nothing); repeatable; a required "
                        "key is refused")


def _unset(key):
    """``--unset KEY`` as the override ``KEY=null`` (:func:`parse_overrides`)."""
    if "=" in key or not key.strip():
        raise argparse.ArgumentTypeError(f"{key!r}: expected a dotted key alone (no =VALUE)")
    return f"{key.strip()}=null"


def parse_overrides(items, source="--set"):
    """``['a.b=1', 'c=null', ...]`` -> ``{'a.b': 1, 'c': None}`` (values parsed as YAML;
    None removes the key: ``--set c=null`` or ``--unset c``)."""
    import yaml
    overrides = {}
    for item in items:
        key, sep, text = item.partition("=")
        if not sep or not key.strip():
            raise ScenarioError(source, item, "expected KEY=VALUE with a dotted key")
        if not text.strip():
            raise ScenarioError(source, key, "no value after '='; allowed: a YAML value, or "
                                f"--unset {key.strip()} to remove the key")
        try:
            overrides[key.strip()] = _number_or_value(yaml.safe_load(text))
        except yaml.YAMLError:
            raise ScenarioError(source, key, f"value {text!r} is not valid YAML") from None
    return overrides


def _number_or_value(value):
    """YAML 1.1 reads ``1e-9`` (no dot) as a string; a user typing it means a number."""
    if isinstance(value, str):
        try:
            return float(value) if value.strip().lower() not in ("nan", "inf", "-inf",
                                                                  "infinity") else value
        except ValueError:
            return value
    return value


class _StderrHandler(logging.StreamHandler):
    """A handler that writes to whatever sys.stderr is at the time of each message."""

    def __init__(self):
        super().__init__()

    @property
    def stream(self):
        return sys.stderr

    @stream.setter
    def stream(self, value):
        pass


class _Formatter(logging.Formatter):
    """``uq: warning: ...`` (``uq golden: warning: ...`` from a wing)."""

    def format(self, record):
        parts = record.name.split(".")
        prefix = f"uq {parts[1]}" if len(parts) > 1 and parts[1] in WINGS else "uq"
        return f"{prefix}: {record.levelname.lower()}: {one_line(record.getMessage())}"


WINGS = ("golden", "fit", "bench", "campaign")


def add_common_options(parser):
    """-q/--quiet and -v/--verbose, on every subcommand."""
    parser.add_argument("-q", "--quiet", action="store_true",
                        help="print only errors (no summary, progress or warnings)")
    parser.add_argument("-v", "--verbose", action="count", default=0,
                        help="more diagnostics on stderr (-vv: debugging)")


def configure_logging(args):
    """Diagnostics through logging on stderr; results stay on stdout. Third-party
    warnings are logged at debug level (shown with -vv), not leaked."""
    quiet, verbose = getattr(args, "quiet", False), getattr(args, "verbose", 0)
    level = logging.ERROR if quiet else (logging.WARNING, logging.INFO, logging.DEBUG)[
        min(verbose, 2)]
    logger = logging.getLogger("uq")
    if not any(isinstance(h, _StderrHandler) for h in logger.handlers):
        handler = _StderrHandler()
        handler.setFormatter(_Formatter())
        logger.addHandler(handler)
    logger.setLevel(level)
    logging.captureWarnings(True)
    warnings_logger = logging.getLogger("py.warnings")
    warnings_logger.setLevel(logging.DEBUG if verbose >= 2 else logging.CRITICAL)
    for name in ("distributed", "matplotlib", "root"):
        logging.getLogger(name if name != "root" else None).setLevel(
            logging.DEBUG if verbose >= 2 else logging.ERROR)


def say(args, text):
    """Print a result line on stdout unless --quiet."""
    if not getattr(args, "quiet", False):
        print(text)
