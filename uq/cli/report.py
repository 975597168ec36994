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
    report.add_argument("--target", action="append", metavar="OUTPUT=U",
                        help="a target standard uncertainty of an output of the run, in its "
                        "units (e.g. wind_speed=0.1 [m s-1], yaw_misalignment=0.5 [deg]; a "
                        "bare number is the wind speed's): the report says which swept "
                        "values and range gates keep u under it, and the best scene; "
                        "repeatable. With wind and ship speed swept, the wind speed's "
                        "targets also set the largest velocity ratio (default 0.05, 0.06 "
                        "and 0.07 m s-1)")
    report.add_argument("--true-ti", type=float, metavar="PERCENT",
                        help="true turbulence intensity [%%] to which a run with motion and "
                        "no turbulence records adds the motion's TI increment in "
                        "quadrature (default 6); refused for other runs")
    add_select(report)
    report.set_defaults(handler=command)
    return report


def parse_targets(texts, dataset):
    """``["wind_speed=0.1", "0.05"]`` -> ``{"wind_speed": (0.1, 0.05)}``; an output the run
    does not have, or a value that is not a positive number, is refused with one line."""
    from uq.pipeline.metadata import QUANTITIES
    outputs = [q for q in QUANTITIES if f"{q}_gum_u" in dataset
               and "beam" not in dataset[f"{q}_gum_u"].dims]
    targets = {}
    for text in texts or []:
        name, _, value = text.rpartition("=")
        name = name.strip() or "wind_speed"
        if name not in outputs:
            raise ScenarioError("--target", text, "allowed: OUTPUT=U with OUTPUT one of this "
                                f"run's outputs ({', '.join(outputs)})")
        try:
            number = float(value)
        except ValueError:
            number = float("nan")
        if not number > 0 or number == float("inf"):
            raise ScenarioError("--target", text, "allowed: a positive number, the target u "
                                f"in the output's units ({QUANTITIES[name]['units']})")
        targets.setdefault(name, ())
        targets[name] += (number,)
    return targets


def command(args):
    from uq.outputs.report import write_report
    path, dataset = open_results(args.results)
    output = Path(args.output) if args.output else path.with_name(f"{path.stem}_report.html")
    if output.suffix not in (".html", ".htm"):
        raise ScenarioError("-o", str(output), "the report file must end in .html")
    from uq.files import check_target
    check_target(output)
    targets = parse_targets(args.target, dataset)
    true_ti = None
    if args.true_ti is not None:
        if "wind_speed_motion_ti" not in dataset or "turbulence_intensity_spectral" in dataset:
            raise ScenarioError("--true-ti", str(args.true_ti), "does not apply: the run has "
                                "no motion-induced TI increment, or it has turbulence "
                                "records whose TI the report gives; allowed: leave it out")
        if not 0 <= args.true_ti < 100:
            raise ScenarioError("--true-ti", str(args.true_ti),
                                "allowed: a percentage in [0, 100)")
        true_ti = args.true_ti / 100
    write_report(dataset, output, source=path, select=parse_select(args.select),
                 true_ti=true_ti, targets=targets)
    say(args, f"wrote {output}")
    return EXIT_OK
