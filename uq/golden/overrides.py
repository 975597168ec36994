"""``uq golden --set``: the overrides of a golden-lidar configuration and of the uq
scenarios its lidars name (``NAME:KEY=VALUE``), shared by :mod:`uq.golden.config` and
:mod:`uq.golden.campaign`."""
from uq.errors import ScenarioError

#: Separates the name of a scenario from its key in an override (``unit:lidar.height``).
SCENARIO_SEPARATOR = ":"


def split_overrides(overrides):
    """(the configuration's own overrides, {scenario NAME: its overrides}) of ``--set``
    keys, ``NAME:dotted`` naming a lidar's scenario."""
    own, scenarios = {}, {}
    for key, value in overrides.items():
        name, separator, dotted = key.partition(SCENARIO_SEPARATOR)
        if separator:
            scenarios.setdefault(name, {})[dotted] = value
        else:
            own[key] = value
    return own, scenarios


def load_lidar_scenario(path, name, scenarios):
    """The uq scenario at `path` of the lidar `name`, with its overrides from
    `scenarios` (:func:`split_overrides`); an error of one names ``NAME:KEY``."""
    from uq.pipeline.scenario import load_scenario
    try:
        return load_scenario(path, scenarios.get(name) or None)
    except ScenarioError as error:
        for prefix in ("--set ", "--unset "):
            if error.source.startswith(prefix):
                raise ScenarioError(f"{prefix}{name}{SCENARIO_SEPARATOR}"
                                    f"{error.source[len(prefix):]}", error.key,
                                    error.problem) from None
        raise
