"""``uq plot RESULTS.nc | NAME [-o FOLDER] [--format png|pdf|svg] [--select DIM=VALUE]``."""
from pathlib import Path

from uq.cli.common import EXIT_OK, say
from uq.errors import ScenarioError


def add_parser(commands):
    plot = commands.add_parser("plot", help="draw the figures a results file supports: "
                               "single scenes, sweeps of 1-3 dimensions, Rubio & Gottschall "
                               "(2022) Figs. 2-7")
    plot.add_argument("results", help="results file of uq run (netCDF), or the name of a "
                      "run (results/NAME.nc)")
    plot.add_argument("-o", "--output", help="folder for the figures "
                      "(default: beside the results, <name>_figures/)")
    plot.add_argument("--format", action="append", choices=("png", "pdf", "svg"),
                      help="figure format; repeatable (default png)")
    add_select(plot)
    plot.set_defaults(handler=command)
    return plot


def add_select(parser):
    parser.add_argument("--select", action="append", default=[], metavar="DIM=VALUE",
                        help="draw the scenes at this value of a sweep dimension (the "
                        "nearest swept value); repeatable")


def parse_select(items):
    """``['dim=value', ...]`` -> ``{dim: value}`` (the value as typed)."""
    select = {}
    for item in items:
        dim, sep, value = item.partition("=")
        if not sep or not dim.strip():
            raise ScenarioError("--select", item, "expected DIM=VALUE with a sweep dimension")
        select[dim.strip()] = value.strip()
    return select


def open_results(argument):
    """(path, Dataset) of the results file of ``uq run`` that a command-line argument
    names (a path, or the name of a run: ``results/NAME.nc``); bad input names the file."""
    from uq.pipeline.results import open_results as read
    from uq.pipeline.shipped import results_path
    path = results_path(argument)
    return path, read(path)


def command(args):
    from uq.outputs.figures import make_figures, no_figure_reason, select_scenes
    path, dataset = open_results(args.results)
    select = parse_select(args.select)
    directory = Path(args.output) if args.output else path.with_name(f"{path.stem}_figures")
    reason = no_figure_reason(select_scenes(dataset, select))
    if reason:
        raise ScenarioError(str(path), "sweep" if "--select" in reason else "outputs", reason)
    formats = tuple(args.format or ["png"])
    for written in make_figures(dataset, directory, formats=formats, select=select):
        say(args, f"wrote {written}")
    return EXIT_OK
