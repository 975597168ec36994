"""``uq bench [-o OUT.nc] [--quick]``."""
from uq.cli.common import EXIT_OK


def add_parser(commands):
    bench = commands.add_parser("bench", help="benchmark: error in u(wind speed) against "
                                "wall time for every sampling method (results/bench.nc)")
    bench.add_argument("-o", "--output", default="results/bench.nc", help="results file")
    bench.add_argument("--quick", action="store_true",
                       help="fewer sizes and repeats; no end-to-end runs, GUM grid or 10^8 "
                       "trials (~25 s)")
    bench.set_defaults(handler=command)
    return bench


def command(args):
    from uq.bench.command import run_bench
    run_bench(args.output, quick=args.quick)
    return EXIT_OK
