"""``uq golden CONFIG [-o FOLDER] [--set KEY=VALUE] [--set NAME:KEY=VALUE] [--unset KEY]``."""
from uq.cli.common import EXIT_OK, add_overrides, parse_overrides

#: ``uq golden --help``: the two kinds of key ``--set`` takes.
OVERRIDES_HELP = (
    "--set takes the configuration's own keys as dotted paths of the file "
    "(golden.bins.width=1.0, golden.synthetic.seed=2, golden.kpi.availability=[0.9,0.8]) "
    "and the keys of the uq scenario a lidar names, as in uq run, behind that lidar's name "
    "and a colon: NAME:KEY=VALUE, e.g. unit:lidar.height=3.5 or "
    "golden:ins.heading.u=0.5. NAME is a role of golden.synthetic.lidars (unit, golden) "
    "or an instrument (or smc) with a scenario. KEY=null, or --unset KEY (NAME:KEY), "
    "removes an optional key. A synthetic campaign's scenario changed so is written as "
    "run into <FOLDER>/data/<NAME>.yaml.")


def add_parser(commands):
    golden = commands.add_parser("golden", help="golden-lidar verification: calibration and "
                                 "classification uncertainty per bin (IEC 61400-12-1, LUSR), "
                                 "KPIs and a report", epilog=OVERRIDES_HELP)
    golden.add_argument("config", help="golden-lidar configuration (YAML with a 'golden' "
                        "section), e.g. scenarios/golden_campaign.yaml")
    golden.add_argument("-o", "--output", help="output folder (default results/<name>/)")
    add_overrides(golden, "a configuration value (golden.KEY) or a value of a lidar's "
                  "scenario (NAME:KEY; see below)", "KEY")
    golden.set_defaults(handler=command)
    return golden


def command(args):
    """Analyse (and first simulate, for a synthetic campaign) and write the folder. As
    ``uq run --model auto``: a synthetic campaign whose lidar kernels numba's cache does
    not hold is simulated with the numpy model while they compile in the background
    (:mod:`uq.cli.firstrun`)."""
    from uq.cli import firstrun
    from uq.golden.command import run_golden
    from uq.golden.config import load_golden_config
    from uq.pipeline.shipped import scenario_path
    import io
    import sys
    path = scenario_path(args.config)
    overrides = parse_overrides(args.set)
    synthetic = load_golden_config(path, overrides).synthetic
    lidars = [scenario.settings for scenario in synthetic["lidars"].values()] \
        if synthetic else []
    background = firstrun.Background(args, lidars)
    run_golden(path, args.output, stream=io.StringIO() if args.quiet else sys.stdout,
               overrides=overrides, model="auto" if firstrun.wanted(args) else "compiled",
               kernels_missing=background.start)
    return EXIT_OK
