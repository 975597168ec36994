"""``uq report RESULTS.nc | NAME [-o REPORT.html] [--target U]``."""
from pathlib import Path

from uq.cli.common import EXIT_OK, say
from uq.cli.plot import add_select, open_results, parse_select
from uq.errors import ScenarioError


def add_parser(commands):
    report = commands.add_parser("report", help="write a self-contained HTML report of a "
                                 "results file: scenario, figures, tables, planning answers")
    report.add_argument("results", help="results file of uq run (netCDF), or the name of "
                        "a run (results/NAME.nc)")
    report.add_argument("-o", "--output", help="report file (default: beside the results, "
                        "<name>_report.html)")
    report.add_argument("--target", type=float, action="append", metavar="U",
                        help="target u(wind speed) [m s-1] for the largest velocity ratio; "
                        "repeatable (default 0.05, 0.06 and 0.07)")
    report.add_argument("--true-ti", type=float, default=6.0, metavar="PERCENT",
                        help="true turbulence intensity [%%] for the apparent TI of results "
                        "with motion (default 6)")
    add_select(report)
    report.set_defaults(handler=command)
    return report


def command(args):
    from uq.outputs.report import write_report
    path, dataset = open_results(args.results)
    output = Path(args.output) if args.output else path.with_name(f"{path.stem}_report.html")
    if output.suffix not in (".html", ".htm"):
        raise ScenarioError("-o", str(output), "the report file must end in .html")
    from uq.files import check_target
    check_target(output)
    for target in args.target or []:
        if not target > 0:
            raise ScenarioError("--target", str(target), "allowed: a positive number [m s-1]")
    if not 0 <= args.true_ti < 100:
        raise ScenarioError("--true-ti", str(args.true_ti), "allowed: a percentage in [0, 100)")
    write_report(dataset, output, source=path, select=parse_select(args.select),
                 true_ti=args.true_ti / 100,
                 **({"targets": tuple(args.target)} if args.target else {}))
    say(args, f"wrote {output}")
    return EXIT_OK
