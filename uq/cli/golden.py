"""``uq golden CONFIG [-o FOLDER]``."""
from uq.cli.common import EXIT_OK


def add_parser(commands):
    golden = commands.add_parser("golden", help="golden-lidar verification: calibration and "
                                 "classification uncertainty per bin (IEC 61400-12-1, LUSR), "
                                 "KPIs and a report")
    golden.add_argument("config", help="golden-lidar configuration (YAML with a 'golden' "
                        "section), e.g. scenarios/golden_campaign.yaml")
    golden.add_argument("-o", "--output", help="output folder (default results/<name>/)")
    golden.set_defaults(handler=command)
    return golden


def command(args):
    from uq.golden.command import run_golden
    from uq.pipeline.shipped import scenario_path
    import io
    import sys
    run_golden(scenario_path(args.config), args.output,
               stream=io.StringIO() if args.quiet else sys.stdout)
    return EXIT_OK
