"""Pages of the user guide generated while it builds, so that they cannot drift from the
code: the command-line reference (from ``uq.cli.build_parser``), the scenario reference
(from the validator, :func:`uq.pipeline.reference.render`) and the performance page (from
a ``uq bench`` result file). The notebooks of ``notebooks/`` are copied into the guide's
source before it reads them.

Each generated page is a stub in ``docs/`` whose text is replaced at Sphinx's
``source-read`` event (:data:`GENERATED`); the generators are plain functions, so the
tests call them without Sphinx (``tests/test_docs.py``). A new option of a command or a
new scenario key appears in the guide without editing it.

To render the performance page from another result file (say a JSON file of a later
``uq bench``), add a reader to :data:`BENCH_READERS` keyed by its suffix: it returns
:class:`BenchResult`.
"""
import argparse
import dataclasses
import json
import math
import re
import shutil
from pathlib import Path

DOCS = Path(__file__).resolve().parents[1]
ROOT = DOCS.parent
GENERATED_NOTICE = "<!-- generated while the guide builds (docs/_ext/uqdocs.py): do not edit -->"


# --- the command-line reference ------------------------------------------------------
def _subcommands(parser):
    """(name, parser, help) of each subcommand of `parser`, in the order ``uq --help``
    lists them."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {choice.dest: choice.help or "" for choice in action._choices_actions}
            return [(name, sub, sub.description or helps.get(name, ""))
                    for name, sub in action.choices.items()]
    return []


def _flags(action):
    if not action.option_strings:
        return f"`{action.metavar or action.dest}`"
    metavar = ""
    if action.nargs != 0:
        metavar = action.metavar or action.dest.upper()
        if isinstance(metavar, tuple):
            metavar = " ".join(metavar)
        metavar = f" {metavar}"
    return ", ".join(f"`{flag}{metavar}`" for flag in action.option_strings)


def _cell(text):
    return " ".join(str(text).split()).replace("|", "\\|")


def _default(action):
    if action.default in (None, False, argparse.SUPPRESS) or action.nargs == 0:
        return ""
    if isinstance(action.default, (list, tuple)) and not action.default:
        return ""
    return f"`{action.default}`"


def cli_reference(parser=None):
    """The command-line reference in Markdown: each subcommand's usage, description and a
    table of its arguments (flags, default, help), read from the argparse parsers."""
    if parser is None:
        from uq.cli import build_parser
        parser = build_parser()
    lines = [GENERATED_NOTICE, "", "# Command-line reference", "",
             "Generated from the command's own argument parsers while this guide is built: "
             "every option `uq COMMAND --help` prints is here. Exit status of every command: "
             "0 success, 1 failure, 2 bad input (one line naming the file, the key and what "
             "is allowed; nothing written), 130 interrupted (Ctrl-C), 143 terminated "
             "(SIGTERM).", "",
             "| command | what it does |", "|---|---|"]
    commands = _subcommands(parser)
    for name, sub, text in commands:
        lines.append(f"| [`uq {name}`](#uq-{name}) | {_cell(text)} |")
    for name, sub, text in commands:
        lines += ["", f"(uq-{name})=", f"## `uq {name}`", ""]
        if text:
            lines += [_cell(text), ""]
        usage = " ".join(sub.format_usage().replace("usage: ", "", 1).split())
        lines += ["```text", usage, "```", "",
                  "| argument | default | meaning |", "|---|---|---|"]
        for action in sub._actions:
            if action.help == argparse.SUPPRESS or isinstance(action, argparse._HelpAction):
                continue
            choices = (f" (one of: {', '.join(map(str, action.choices))})"
                       if action.choices and not isinstance(action.choices, dict) else "")
            text = sub._get_formatter()._expand_help(action) if action.help else ""
            lines.append(f"| {_flags(action)} | {_default(action)} | "
                         f"{_cell(text + choices)} |")
        if sub.epilog:
            lines += ["", _cell(sub.epilog)]
    return "\n".join(lines) + "\n"


# --- the scenario reference ------------------------------------------------------------
def scenario_reference():
    """The scenario reference, rendered by the validator's own module (the same text as
    ``docs/scenario.md``, which ``tests/pipeline/test_reference.py`` keeps current)."""
    from uq.pipeline import reference
    return GENERATED_NOTICE + "\n\n" + reference.render()


# --- the performance page --------------------------------------------------------------
@dataclasses.dataclass
class BenchResult:
    """What the performance page needs from a benchmark run, whatever its file format."""
    path: Path
    figures: dict            # name -> value (the targets' figures and the other scalars)
    time_to_target: list     # rows (scene, method, seconds, extrapolated)
    machine: str             # e.g. "2 cores, Linux x86_64"
    load: str                # the load average around the run, in words
    date: str                # when it ran (UTC)
    command: str             # the command that made it


def _read_bench_netcdf(path):
    import xarray
    with xarray.open_dataset(path) as dataset:
        attributes = dict(dataset.attrs)
        rows = []
        if "time_to_target" in dataset:
            table = dataset["time_to_target"]
            flags = dataset.get("time_to_target_extrapolated")
            for scene in table["scene"].values:
                for method in table["method"].values:
                    seconds = float(table.sel({"scene": scene, "method": method}))
                    extrapolated = (bool(flags.sel({"scene": scene, "method": method}))
                                    if flags is not None else False)
                    rows.append((str(scene), str(method), seconds, extrapolated))
    figures = {k: float(v) for k, v in attributes.items()
               if isinstance(v, (int, float)) or getattr(v, "shape", None) == ()}
    history = str(attributes.get("history", ""))
    date = history.split(" ")[0] if history else "unknown"
    return BenchResult(path=Path(path), figures=figures, time_to_target=rows,
                       machine=str(attributes.get("machine", "not recorded")),
                       load=str(attributes.get("load_average", "not recorded")),
                       date=str(attributes.get("measured_at", date)),
                       command=str(attributes.get("bench_command", history)))


def _read_bench_json(path):
    data = json.loads(Path(path).read_text())
    return BenchResult(path=Path(path), figures=dict(data.get("figures", {})),
                       time_to_target=[tuple(row) for row in data.get("time_to_target", [])],
                       machine=data.get("machine", "not recorded"),
                       load=data.get("load_average", "not recorded"),
                       date=data.get("measured_at", "unknown"),
                       command=data.get("command", "uq bench"))


#: File suffix -> reader of a ``uq bench`` result.
BENCH_READERS = {".nc": _read_bench_netcdf, ".json": _read_bench_json}


def read_bench(path):
    """A ``uq bench`` result as :class:`BenchResult` (by the file's suffix)."""
    path = Path(path)
    try:
        reader = BENCH_READERS[path.suffix]
    except KeyError:
        raise ValueError(f"{path}: no reader for {path.suffix!r} files "
                         f"(known: {', '.join(BENCH_READERS)})") from None
    return reader(path)


def _number(value):
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    return f"{value:.3g}"


def performance_page(path):
    """The performance page in Markdown, from the ``uq bench`` result at `path`."""
    from uq.bench.targets import TARGETS
    result = read_bench(path)
    relative = result.path.relative_to(ROOT) if result.path.is_relative_to(ROOT) else result.path
    lines = [GENERATED_NOTICE, "", "# Performance", "",
             f"Every number on this page is read from one `uq bench` result file, "
             f"`{relative}`, written by `{result.command}`; each ratio divides two times "
             "measured in that run. Times depend on the machine and on what else runs on "
             "it: compare ratios, not seconds, with your own run (`uq bench --quick`, fewer "
             "sizes and no end-to-end runs, or the full `uq bench`). Each target's figure "
             "and what it times: `uq.bench.targets`.", "",
             f"- **machine**: {result.machine}",
             f"- **load average** (1, 5, 15 min) before and after the run: {result.load}",
             f"- **measured**: {result.date}", "",
             "## Speed targets", "",
             "| figure | measured | target | met |", "|---|---|---|---|"]
    for name, (limit, sense) in TARGETS.items():
        if name not in result.figures:
            continue
        value = result.figures[name]
        met = value <= limit if sense == "max" else value >= limit
        bound = "≤" if sense == "max" else "≥"
        lines.append(f"| `{name}` | {_number(value)} | {bound} {limit:g} | "
                     f"{'yes' if met else '**no**'} |")
    missing = [name for name in TARGETS if name not in result.figures]
    if missing:
        lines += ["", "Not measured in this run (a `uq bench --quick` leaves them out; a full "
                  "`uq bench` measures them): " + ", ".join(f"`{m}`" for m in missing) + "."]
    if result.time_to_target:
        lines += ["", "## Time to a relative error of 1e-3 in u(wind speed)", "",
                  "The wall time a method needs for |u/u_ref − 1| ≤ 1e-3 in 95 % of runs "
                  "(extrapolated as n^-1/2 where no size tried reached it).", "",
                  "| scenario | method | time [s] | extrapolated |", "|---|---|---|---|"]
        for scene, method, seconds, extrapolated in result.time_to_target:
            lines.append(f"| `{scene}` | `{method}` | {_number(seconds)} | "
                         f"{'yes' if extrapolated else 'no'} |")
    first_lines, shown = first_run_table(result.figures)
    lines += first_lines
    others = sorted(set(result.figures) - set(TARGETS) - shown)
    if others:
        lines += ["", "## Every other figure of the run", "",
                  "| figure | value |", "|---|---|"]
        lines += [f"| `{name}` | {_number(result.figures[name])} |" for name in others]
    return "\n".join(lines) + "\n"


_FIRST_RUN = re.compile(r"first_run_(?P<name>\w+)_over_warm_s")


def first_run_table(figures):
    """(Markdown lines, the figures they show) of the first-run table: each shipped
    scenario's first run with numba's cache empty against the same run with it filled
    (:mod:`uq.bench.firstrun`), the largest difference first; no lines where the run did
    not measure them."""
    names = [m["name"] for m in map(_FIRST_RUN.fullmatch, figures)
             if m and m["name"] != "worst"]
    if not names:
        return [], set()
    from uq.bench.firstrun import PAIRS_OF_LONG_RUNS, REPEATED_RUN_S
    names.sort(key=lambda name: -figures[f"first_run_{name}_over_warm_s"])
    lines = ["", "## First runs", "",
             "Each shipped scenario's command in a new process with numba's cache empty "
             "(the numpy model runs while the kernels compile in the background), then, "
             "once that compile has ended, the same command with the cache filled: wall "
             f"times. A scenario whose warm run takes {REPEATED_RUN_S:g} s or more is "
             f"measured in {PAIRS_OF_LONG_RUNS} such pairs; its row gives the medians and "
             "the range of the differences. "
             "\"Largest difference\" is the largest absolute difference of the wind "
             "outputs' Monte Carlo statistics between the two runs (`uq run` files).", "",
             "| scenario | cache empty [s] | cache filled [s] | over [s] | pairs (range [s]) "
             "| largest difference | filled run compiled |", "|---|---|---|---|---|---|---|"]
    shown = set()
    for name in names:
        keys = {key: f"first_run_{name}_{key}" for key in (
            "s", "over_warm_s", "pairs", "over_warm_min_s", "over_warm_max_s",
            "largest_difference", "warm_compiled")}
        keys["warm"] = f"warm_run_{name}_s"
        value = {key: figures.get(figure) for key, figure in keys.items()}
        pairs = int(value["pairs"] or 1)
        spread = (f"{pairs} ({value['over_warm_min_s']:+.1f} to "
                  f"{value['over_warm_max_s']:+.1f})" if pairs > 1 else "1")
        compiled = {None: "-", 1.0: "yes", 0.0: "**no**"}[value["warm_compiled"]]
        lines.append(f"| `{name}` | {value['s']:.1f} | {value['warm']:.1f} | "
                     f"{value['over_warm_s']:+.1f} | {spread} | "
                     f"{_number(value['largest_difference'])} | {compiled} |")
        shown.update(keys.values())
    return lines, shown


# --- Sphinx -----------------------------------------------------------------------------
_LITERAL = re.compile(r"``.*?``")
_BOLD = re.compile(r"\*\*[^*\s]+\*\*")
_LONE_STAR = re.compile(r"(?<![*\\])\*(?![*\s])")


def escape_lone_stars(lines):
    """Escape the lone ``*`` of shapes such as ``(n, *shape)`` in docstring lines (in
    place): reStructuredText reads it as the start of an emphasis. Only lines with an odd
    number of stars outside ``literals`` are touched (a pair is a real emphasis)."""
    for index, line in enumerate(lines):
        outside = _BOLD.sub("", _LITERAL.sub("", line))      # numpydoc bolds names: **x**
        if outside.count("*") % 2 == 0:
            continue
        parts = re.split(r"(``.*?``|\*\*[^*\s]+\*\*)", line)
        lines[index] = "".join(part if part.startswith(("``", "**")) else
                               _LONE_STAR.sub(r"\\*", part) for part in parts)


def _process_docstring(app, what, name, obj, options, lines):
    escape_lone_stars(lines)


def _generated(app):
    return {"reference/cli": cli_reference,
            "reference/scenario": scenario_reference,
            "performance": lambda: performance_page(app.config.uq_bench_file)}


def _source_read(app, docname, source):
    generator = _generated(app).get(docname)
    if generator is not None:
        source[0] = generator()


def _copy_notebooks(app):
    """The notebooks of notebooks/ into the guide's source (docs/notebooks/, not tracked)."""
    target = DOCS / "notebooks"
    target.mkdir(exist_ok=True)
    wanted = {path.name for path in (ROOT / "notebooks").glob("*.ipynb")}
    for stale in target.glob("*.ipynb"):
        if stale.name not in wanted:
            stale.unlink()
    for name in wanted:
        source = ROOT / "notebooks" / name
        copy = target / name
        if not copy.exists() or copy.read_bytes() != source.read_bytes():
            shutil.copyfile(source, copy)


def setup(app):
    app.add_config_value("uq_bench_file", str(DOCS / "data" / "bench.nc"), "env")
    app.connect("builder-inited", _copy_notebooks)
    app.connect("source-read", _source_read)
    app.connect("autodoc-process-docstring", _process_docstring)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
