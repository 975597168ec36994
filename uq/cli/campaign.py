"""``uq campaign CONFIG [-o FOLDER] [--workers N | --scheduler ADDRESS]``."""
from uq.cli.common import EXIT_OK


def add_parser(commands):
    campaign = commands.add_parser(
        "campaign", help="correct a floating lidar's ten-minute records for the platform's "
        "motion and the lidar's filtering: each record's TI with its uncertainty and 95 %% "
        "interval, the mean speed, per-bin errors against a reference, and a report")
    campaign.add_argument("config", help="campaign configuration (YAML with a 'campaign' "
                          "section), or the name of a shipped one, e.g. campaign_buoy")
    campaign.add_argument("-o", "--output", help="output folder (default results/<name>/)")
    scale = campaign.add_mutually_exclusive_group()
    scale.add_argument("--workers", type=int, metavar="N",
                       help="compute the model's tables and the records on a local dask "
                       "cluster of N processes (needs the 'dask' extra); same numbers")
    scale.add_argument("--scheduler", metavar="ADDRESS",
                       help="... on the dask scheduler at ADDRESS (e.g. tcp://host:8786)")
    campaign.set_defaults(handler=command)
    return campaign


def command(args):
    import io
    import sys
    from uq.campaign.command import run_campaign
    from uq.cli.run import check_scale_out, dask_client
    from uq.pipeline.shipped import scenario_path
    config = scenario_path(args.config)
    check_scale_out(args)
    with dask_client(args) as client:
        run_campaign(config, args.output, stream=io.StringIO() if args.quiet else sys.stdout,
                     client=client, kernels_missing=_background(args))
    return EXIT_OK


#: How a campaign's numbers with the numpy motion model compare with the compiled one's
#: (measured on campaign_buoy: corrected speeds 1.3e-8 m s-1 apart, the motion's bias
#: being a second difference of the model at a phase step of 1e-3; corrected TI 1e-10).
CAMPAIGN_AGREEMENT = ("the same numbers to rounding: corrected speeds within 1e-7 m s-1, "
                      "TI within 1e-9")


def _background(args):
    """The campaign's `kernels_missing`: the compile of its lidar's kernels in the
    background (:mod:`uq.cli.firstrun`), said on stderr as ``uq run`` says it; None
    where no background compile is wanted (the campaign then compiles what it calls)."""
    from uq.cli import firstrun
    if not firstrun.wanted(args):
        return None

    def start(error, settings):
        firstrun.Background(args, settings, CAMPAIGN_AGREEMENT).start(error)
    return start
