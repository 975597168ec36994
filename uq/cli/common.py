"""What every subcommand shares: exit codes, the parser that reports usage errors as bad
input, and ``--set`` overrides. Imports nothing heavy (``uq --help`` stays fast)."""
import argparse

from uq.errors import ScenarioError

EXIT_OK, EXIT_FAILURE, EXIT_BAD_INPUT = 0, 1, 2
EXIT_INTERRUPTED = 130          # the shell's code for SIGINT


class Parser(argparse.ArgumentParser):
    """argparse that reports usage errors as bad input (exit 2, one line)."""

    def error(self, message):
        self.exit(EXIT_BAD_INPUT, f"uq: error: {message}\n")


def parse_overrides(items, source="--set"):
    """``['a.b=1', ...]`` -> ``{'a.b': 1}`` (values parsed as YAML)."""
    import yaml
    overrides = {}
    for item in items:
        key, sep, text = item.partition("=")
        if not sep or not key.strip():
            raise ScenarioError(source, item, "expected KEY=VALUE with a dotted key")
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
