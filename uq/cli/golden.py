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
    synthetic = load_golden_config(path).synthetic
    lidars = [scenario.settings for scenario in synthetic["lidars"].values()] \
        if synthetic else []
    background = firstrun.Background(args, lidars)
    run_golden(path, args.output, stream=io.StringIO() if args.quiet else sys.stdout,
               model="auto" if firstrun.wanted(args) else "compiled",
               kernels_missing=background.start)
    return EXIT_OK
