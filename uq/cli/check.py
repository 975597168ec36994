"""``uq check SCENARIO``: validate a scenario or a golden-lidar configuration; for a
scenario, say the run's size and an estimate of its time (:mod:`uq.pipeline.estimate`)."""
from uq.cli.common import EXIT_OK, add_overrides, parse_overrides, say


def add_parser(commands):
    check = commands.add_parser("check", help="validate a scenario (or a golden-lidar "
                                "configuration) without running it")
    check.add_argument("scenario", help="scenario YAML file, or the name of a shipped "
                       "scenario")
    add_overrides(check)
    check.set_defaults(handler=command)
    return check


def command(args):
    from uq.pipeline.scenario import SCENARIO_KIND, load_scenario
    from uq.pipeline.yamlfile import read_yaml
    from uq.pipeline.shipped import scenario_path
    path = scenario_path(args.scenario)
    raw = read_yaml(path, kind=SCENARIO_KIND)
    if isinstance(raw, dict) and "golden" in raw:
        from uq.golden.config import load_golden_config
        config = load_golden_config(path, parse_overrides(args.set))
        what = "synthetic campaign" if config.synthetic else \
            f"{len(config.comparisons)} comparison(s)"
        say(args, f"{args.scenario}: ok (golden-lidar configuration {config.name}: {what})")
        return EXIT_OK
    from uq.pipeline.estimate import run_size
    scenario = load_scenario(path, parse_overrides(args.set))
    size = run_size(scenario)
    say(args, f"{args.scenario}: ok ({scenario.name}: {size.describe()}; outputs "
        f"{', '.join(scenario.outputs)})")
    say(args, size.estimate())
    return EXIT_OK
