"""``uq check SCENARIO``: validate a scenario, a golden-lidar or a campaign
configuration; for a scenario, say the run's size and an estimate of its time
(:mod:`uq.pipeline.estimate`)."""
from uq.cli.common import EXIT_OK, add_overrides, parse_overrides, say


def add_parser(commands):
    check = commands.add_parser("check", help="validate a scenario (or a golden-lidar or "
                                "campaign configuration, and the campaign's files) without "
                                "running it")
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
    if isinstance(raw, dict) and "campaign" in raw:
        return _check_campaign(args, path)
    from uq.pipeline.estimate import run_size
    scenario = load_scenario(path, parse_overrides(args.set))
    size = run_size(scenario)
    say(args, f"{args.scenario}: ok ({scenario.name}: {size.describe()}; outputs "
        f"{', '.join(scenario.outputs)})")
    say(args, size.estimate())
    return EXIT_OK


def _check_campaign(args, path):
    """A campaign configuration and its files (records, motion, reference) read and
    checked, the model not run."""
    from uq.campaign.config import load_campaign_config
    from uq.campaign.motioninput import load_motion
    from uq.campaign.recordsfile import load_records, load_reference
    from uq.errors import ScenarioError
    if args.set:
        raise ScenarioError("--set", args.set[0], "does not apply to a campaign "
                            "configuration; allowed: edit the file")
    config = load_campaign_config(path)
    records = load_records(config.records)
    times = records["time"].values
    if config.motion is not None:
        load_motion(config.motion, times)
    if config.reference is not None:
        load_reference(config.reference, times, list(config.heights))
    say(args, f"{args.scenario}: ok (campaign configuration {config.name}: "
        f"{records.sizes['time']} periods at {len(config.heights)} height(s), motion "
        f"{config.motion.kind if config.motion else 'none'}, "
        f"{'a' if config.reference else 'no'} reference)")
    return EXIT_OK
