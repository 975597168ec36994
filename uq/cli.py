"""Command line: ``uq run``, ``uq check``, ``uq plot``, ``uq report``, ``uq bench``,
``uq fit``, ``uq golden``, ``uq --version``.

Exit status: 0 success; 2 bad input (one line naming the file, the key and what is
allowed; no traceback; no output file); 1 anything else.
"""
import argparse
import contextlib
import sys
from pathlib import Path

import yaml

from . import __version__
from .errors import ScenarioError

EXIT_OK, EXIT_FAILURE, EXIT_BAD_INPUT = 0, 1, 2
EXIT_INTERRUPTED = 130          # the shell's code for SIGINT


class _Parser(argparse.ArgumentParser):
    """argparse that reports usage errors as bad input (exit 2, one line)."""

    def error(self, message):
        self.exit(EXIT_BAD_INPUT, f"uq: error: {message}\n")


def build_parser():
    parser = _Parser(prog="uq", description="Uncertainty of ship-based and floating "
                     "Doppler wind lidar: Monte Carlo beside the GUM.")
    parser.add_argument("--version", action="version", version=f"uq {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    run = commands.add_parser("run", help="run a scenario and write its results (netCDF)")
    run.add_argument("scenario", help="scenario YAML file")
    run.add_argument("-o", "--output", help="output file (default results/<name>.nc)")
    run.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                     help="override a scenario value (dotted key, YAML value); repeatable")
    run.add_argument("--quiet", action="store_true", help="no summary table or progress")
    run.add_argument("--resume", action="store_true",
                     help="continue an interrupted run: reuse the finished chunks kept in "
                     "OUT.nc.partial/ and compute only the missing scenes")
    scale = run.add_mutually_exclusive_group()
    scale.add_argument("--workers", type=int, metavar="N",
                       help="run the sweep on a local dask cluster of N processes "
                       "(needs the 'dask' extra); same numbers as a single process")
    scale.add_argument("--scheduler", metavar="ADDRESS",
                       help="run the sweep on the dask scheduler at ADDRESS "
                       "(e.g. tcp://host:8786)")
    plot = commands.add_parser("plot", help="draw the figures a results file supports "
                               "(Rubio & Gottschall 2022, Figs. 2-7, and more)")
    plot.add_argument("results", help="results file of uq run (netCDF)")
    plot.add_argument("-o", "--output", help="folder for the figures "
                      "(default: beside the results, <name>_figures/)")
    plot.add_argument("--format", action="append", choices=("png", "pdf", "svg"),
                      help="figure format; repeatable (default png)")
    report = commands.add_parser("report", help="write a self-contained HTML report of a "
                                 "results file: scenario, figures, tables, planning answers")
    report.add_argument("results", help="results file of uq run (netCDF)")
    report.add_argument("-o", "--output", help="report file (default: beside the results, "
                        "<name>_report.html)")
    report.add_argument("--target", type=float, action="append", metavar="U",
                        help="target u(wind speed) [m s-1] for the largest velocity ratio; "
                        "repeatable (default 0.05, 0.06 and 0.07)")
    bench = commands.add_parser("bench", help="benchmark: error in u(wind speed) against "
                                "wall time for every sampling method (results/bench.nc)")
    bench.add_argument("-o", "--output", default="results/bench.nc", help="results file")
    bench.add_argument("--quick", action="store_true", help="fewer sizes and repeats (~1 min)")
    fit = commands.add_parser("fit", help="fit a wind profile with emcee, beside least "
                              "squares: posterior summary, predictive band, corner plot, chain")
    fit.add_argument("input", help="results of uq run (.nc) with range gates and the "
                     "gate_height output, or a CSV of heights and speeds (.csv)")
    fit.add_argument("-c", "--config", help="YAML file with a 'fit' section (default: the "
                     "results' scenario's fit section, else the defaults)")
    fit.add_argument("-o", "--output", help="fit results (.nc; default beside the input, "
                     "<name>_fit.nc); figures beside it")
    fit.add_argument("--set", action="append", default=[], metavar="fit.KEY=VALUE",
                     help="override a fit setting (dotted key, YAML value); repeatable")
    golden = commands.add_parser("golden", help="golden-lidar verification: calibration and "
                                 "classification uncertainty per bin (IEC 61400-12-1, LUSR), "
                                 "KPIs and a report")
    golden.add_argument("config", help="golden-lidar configuration (YAML with a 'golden' "
                        "section), e.g. scenarios/golden_campaign.yaml")
    golden.add_argument("-o", "--output", help="output folder (default results/<name>/)")
    check = commands.add_parser("check", help="validate a scenario (or a golden-lidar "
                                "configuration) without running it")
    check.add_argument("scenario", help="scenario YAML file")
    check.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    return parser


def parse_overrides(items, source="--set"):
    """``['a.b=1', ...]`` -> ``{'a.b': 1}`` (values parsed as YAML)."""
    overrides = {}
    for item in items:
        key, sep, text = item.partition("=")
        if not sep or not key.strip():
            raise ScenarioError(source, item, "expected KEY=VALUE with a dotted key")
        try:
            overrides[key.strip()] = _number_or_value(yaml.safe_load(text))
        except yaml.YAMLError:
            raise ScenarioError(source, key, f"value {text!r} is not valid YAML") from None
    return overrides


def _number_or_value(value):
    """YAML 1.1 reads ``1e-9`` (no dot) as a string; a user typing it means a number."""
    if isinstance(value, str):
        try:
            return float(value) if value.strip().lower() not in ("nan", "inf", "-inf",
                                                                  "infinity") else value
        except ValueError:
            return value
    return value


def main(argv=None):
    args = build_parser().parse_args(argv)
    try:
        return _COMMANDS[args.command](args)
    except ScenarioError as error:
        print(f"uq: error: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT


def _check(args):
    from .scenario import load_scenario, read_yaml
    raw = read_yaml(Path(args.scenario))
    if isinstance(raw, dict) and "golden" in raw:
        from .golden.config import load_golden_config
        config = load_golden_config(args.scenario)
        what = "synthetic campaign" if config.synthetic else \
            f"{len(config.comparisons)} comparison(s)"
        print(f"{args.scenario}: ok (golden-lidar configuration {config.name}: {what})")
        return EXIT_OK
    scenario = load_scenario(args.scenario, parse_overrides(args.set))
    scenes = 1
    for _, values in scenario.sweep:
        scenes *= len(values)
    print(f"{args.scenario}: ok ({scenario.name}: {scenes} scene(s), outputs "
          f"{', '.join(scenario.outputs)})")
    return EXIT_OK


def _run(args):
    from .checkpoint import Checkpoint, checkpoint_directory
    from .io import write_results
    from .progress import ProgressBar
    from .pipeline import run
    from .scenario import load_scenario
    from .summary import summary_table
    scenario = load_scenario(args.scenario, parse_overrides(args.set))
    output = Path(args.output) if args.output else Path("results") / f"{scenario.name}.nc"
    if output.suffix != ".nc":
        raise ScenarioError("-o", str(output), "the output file must end in .nc")
    progress = None if args.quiet else ProgressBar()
    checkpoint = Checkpoint(checkpoint_directory(output), resume=args.resume)
    try:
        with _dask_client(args) as client:
            dataset = run(scenario, progress=progress, client=client, checkpoint=checkpoint)
    except KeyboardInterrupt:
        print(f"\nuq: interrupted; finished chunks are kept in {checkpoint.directory}; "
              "run the same command with --resume to continue", file=sys.stderr)
        return EXIT_INTERRUPTED
    write_results(dataset, output)
    checkpoint.clear()
    if not args.quiet:
        print(summary_table(dataset))
        print(f"wrote {output}")
    return EXIT_OK


@contextlib.contextmanager
def _dask_client(args):
    """A dask.distributed Client for --workers / --scheduler, else None."""
    if args.workers is None and args.scheduler is None:
        yield None
        return
    if args.workers is not None and args.workers < 1:
        raise ScenarioError("--workers", str(args.workers), "allowed: an integer >= 1")
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise ScenarioError("--workers/--scheduler", "dask", "dask.distributed is not "
                            "installed; allowed: pip install 'uq[dask]'") from None
    if args.scheduler:
        with Client(args.scheduler) as client:
            yield client
        return
    with LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        yield client


def _open_results(path):
    from .io import open_results
    return Path(path), open_results(Path(path))


def _plot(args):
    from .figures import figure_plan, make_figures
    path, dataset = _open_results(args.results)
    directory = Path(args.output) if args.output else path.with_name(f"{path.stem}_figures")
    if not figure_plan(dataset):
        raise ScenarioError(str(path), "sweep", "no figure for these sweep dimensions "
                            f"({', '.join(dataset['mc_n_samples'].dims) or 'none'}); allowed: "
                            "the sweeps of the rubio2022_* scenarios or any 1-D sweep")
    for written in make_figures(dataset, directory, formats=tuple(args.format or ["png"])):
        print(f"wrote {written}")
    return EXIT_OK


def _report(args):
    from .report import write_report
    path, dataset = _open_results(args.results)
    output = Path(args.output) if args.output else path.with_name(f"{path.stem}_report.html")
    if output.suffix not in (".html", ".htm"):
        raise ScenarioError("-o", str(output), "the report file must end in .html")
    for target in args.target or []:
        if not target > 0:
            raise ScenarioError("--target", str(target), "allowed: a positive number [m s-1]")
    write_report(dataset, output, source=path,
                 **({"targets": tuple(args.target)} if args.target else {}))
    print(f"wrote {output}")
    return EXIT_OK


def _bench(args):
    from . import bench
    from .io import write_results
    from .plots import plot_bench
    output = Path(args.output)
    if output.suffix != ".nc":
        raise ScenarioError("-o", str(output), "the output file must end in .nc")
    sizes = [2**k for k in ((10, 13, 16, 18) if args.quick else (10, 12, 14, 16, 18, 19))]
    repeats = 3 if args.quick else 8
    dataset = bench.measure(sizes, repeats,
                            progress=lambda text: print(f"  {text}", file=sys.stderr))
    floors = {name: bench.draw_floor(name, sizes[-1]) for name in bench.SCENES}
    median = dataset["time_s"].median("repeat")
    for name, (floor, dimension) in floors.items():
        plain = float(median.sel({"scene": name, "method": "mc", "n": sizes[-1]}))
        dataset.attrs[f"{name}_mc_over_draw_floor"] = plain / floor
        print(f"{name}: plain mc at n = {sizes[-1]} takes {plain:.3f} s, drawing its "
              f"{dimension} normals per trial {floor:.3f} s: {plain / floor:.1f}x the floor")
    targets = bench.time_to_target(dataset)
    for name in bench.SCENES:
        plain = targets[name, "mc"][0]
        for method in bench.METHODS:
            seconds, extrapolated = targets[name, method]
            dataset.attrs[f"{name}_{method}_time_to_1e-3_s"] = seconds
            print(f"{name:22s} {method:9s} time to 1e-3 in 95 % of runs: {seconds:9.3f} s"
                  f"{' (extrapolated)' if extrapolated else ''}  speed-up vs mc "
                  f"{plain / seconds:7.1f}x")
    scans = bench.scan_throughput()
    dataset.attrs["scans_1e6_s"] = scans
    print(f"10^6 four-beam scans with radial noise: {scans:.3f} s")
    if not args.quick:
        seconds, megabytes = bench.scale()
        dataset.attrs.update(scale_1e8_s=seconds, scale_1e8_peak_rss_mb=megabytes)
        print(f"10^8 trials of the same scene: {seconds:.1f} s, peak resident memory "
              f"{megabytes:.0f} MB")
    write_results(dataset, output)
    figure = plot_bench(dataset)
    figure.savefig(output.with_suffix(".png"), dpi=120)
    print(f"wrote {output} and {output.with_suffix('.png')}")
    return EXIT_OK


def _fit(args):
    from .fitcommand import run_fit
    return run_fit(args.input, args.config, args.output, parse_overrides(args.set))


def _golden(args):
    from .golden.command import run_golden
    run_golden(args.config, args.output)
    return EXIT_OK


_COMMANDS = {"run": _run, "check": _check, "plot": _plot, "report": _report, "bench": _bench,
             "fit": _fit, "golden": _golden}

if __name__ == "__main__":
    sys.exit(main())
