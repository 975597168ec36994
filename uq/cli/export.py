"""``uq export RESULTS.nc | NAME [-o TABLE.csv] [--select DIM=VALUE] [--force]``."""
from pathlib import Path

from uq.cli.common import EXIT_OK, say
from uq.cli.plot import add_select, open_results, parse_select
from uq.errors import ScenarioError


def add_parser(commands):
    export = commands.add_parser("export", help="write a results file as a CSV table: one "
                                 "row per scene and range gate, a column per variable with "
                                 "its unit in the header")
    export.add_argument("results", help="results file of uq run (netCDF), or the name of a "
                        "run (results/NAME.nc)")
    export.add_argument("-o", "--output", help="table file (.csv; default: beside the "
                        "results, <name>.csv)")
    export.add_argument("--force", action="store_true", help="replace the table file even "
                        "if uq did not write it (uq otherwise replaces only its own files)")
    add_select(export)
    export.set_defaults(handler=command)
    return export


def command(args):
    from uq.files import check_target, write_text
    from uq.outputs.figures import select_scenes
    from uq.outputs.table import table_text
    path, dataset = open_results(args.results)
    output = Path(args.output) if args.output else path.with_suffix(".csv")
    if output.suffix != ".csv":
        raise ScenarioError("-o", str(output), "the table file must end in .csv")
    if not args.force:
        check_target(output)                 # before any work: refused targets cost nothing
    text = table_text(select_scenes(dataset, parse_select(args.select)), str(path))
    write_text(output, text, replace_any=args.force)
    say(args, f"wrote {output}")
    return EXIT_OK
