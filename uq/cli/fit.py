"""``uq fit RESULTS.nc | TABLE.csv [-c CONFIG] [-o OUT.nc] [--set fit.k=v]``."""
from uq.cli.common import add_overrides, parse_overrides


def add_parser(commands):
    fit = commands.add_parser("fit", help="fit a wind profile with emcee, beside least "
                              "squares: posterior summary, predictive band, corner plot, chain")
    fit.add_argument("input", help="results of uq run (.nc, or the name of a run: "
                     "results/NAME.nc) with range gates and the gate_height output, or a "
                     "CSV of heights and speeds (.csv)")
    fit.add_argument("-c", "--config", help="YAML file with a 'fit' section (default: the "
                     "results' scenario's fit section, else the defaults)")
    fit.add_argument("-o", "--output", help="fit results (.nc; default beside the input, "
                     "<name>_fit.nc); figures beside it")
    add_overrides(fit, "a fit setting", "fit.KEY")
    fit.set_defaults(handler=command)
    return fit


def command(args):
    from pathlib import Path

    from uq.fit.command import run_fit
    from uq.pipeline.shipped import results_path
    named = Path(args.input).suffix in ("", ".nc")       # a run's name, or its results
    source = results_path(args.input) if named else args.input
    return run_fit(source, args.config, args.output, parse_overrides(args.set),
                   quiet=args.quiet)
