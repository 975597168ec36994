"""``uq plot RESULTS.nc [-o FOLDER] [--format png|pdf|svg]``."""
from pathlib import Path

from uq.cli.common import EXIT_OK, say
from uq.errors import ScenarioError


def add_parser(commands):
    plot = commands.add_parser("plot", help="draw the figures a results file supports "
                               "(Rubio & Gottschall 2022, Figs. 2-7, and more)")
    plot.add_argument("results", help="results file of uq run (netCDF)")
    plot.add_argument("-o", "--output", help="folder for the figures "
                      "(default: beside the results, <name>_figures/)")
    plot.add_argument("--format", action="append", choices=("png", "pdf", "svg"),
                      help="figure format; repeatable (default png)")
    plot.set_defaults(handler=command)
    return plot


def open_results(path):
    """(path, Dataset) of a results file of ``uq run``; bad input names the file."""
    from uq.errors import DataFileError
    from uq.pipeline.results import open_results as read
    dataset = read(Path(path))
    if "wind_speed_true" not in dataset:
        raise DataFileError(str(path), "outputs", "no wind_speed in these results; allowed: "
                            "results of a scenario whose outputs include wind_speed")
    return Path(path), dataset


def command(args):
    from uq.outputs.figures import figure_plan, make_figures
    path, dataset = open_results(args.results)
    directory = Path(args.output) if args.output else path.with_name(f"{path.stem}_figures")
    if not figure_plan(dataset):
        raise ScenarioError(str(path), "sweep", "no figure for these sweep dimensions "
                            f"({', '.join(dataset['mc_n_samples'].dims) or 'none'}); allowed: "
                            "the sweeps of the rubio2022_* scenarios or any 1-D sweep")
    formats = tuple(args.format or ["png"])
    from uq.files import check_target
    for name, _ in figure_plan(dataset):       # every target before any figure is drawn
        for extension in formats:
            check_target(directory / f"{name}.{extension}")
    for written in make_figures(dataset, directory, formats=formats):
        say(args, f"wrote {written}")
    return EXIT_OK
