"""Editing a scenario from the command line: ``--set KEY=VALUE``, ``--set KEY=null`` and
``--unset KEY`` (uq.cli.common.add_overrides, uq.pipeline.scenario.apply_overrides), on
every command that takes --set; an option or key that does not apply is refused."""
import pytest
import xarray as xr
import yaml

from uq.cli import main
from uq.cli.common import parse_overrides
from uq.pipeline.scenario import load_scenario

SURGING = {"name": "surging", "ins": {"heading": {"dist": "normal", "u": 0.1}, "rate": 10},
           "motion": {"pitch": {"amplitude": 2.0, "period": 8.0, "phase": 0.0},
                      "surge": {"amplitude": 1.0, "period": 8.0, "phase": 0.0}},
           "correction": "pointwise", "sampling": {"n": 200, "seed": 1},
           "outputs": ["wind_speed"]}


def write(tmp_path, mapping):
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(mapping))
    return path


def one_line(capsys):
    line, = capsys.readouterr().err.strip().splitlines()
    return line


@pytest.mark.parametrize("removal", [["--unset", "motion.surge"], ["--set", "motion.surge=null"]])
def test_a_key_removed_from_the_command_line_is_gone_from_the_run(tmp_path, removal):
    """Switching surge off took amplitude 0, which stayed in the scenario (and titles);
    removed, the run is the one of the file without it, its scenario text too."""
    path = write(tmp_path, SURGING)
    assert main(["run", str(path), "-o", str(tmp_path / "a.nc"), "-q", *removal]) == 0
    without = {**SURGING, "motion": {"pitch": SURGING["motion"]["pitch"]}}
    assert main(["run", str(write(tmp_path, without)), "-o", str(tmp_path / "b.nc"),
                 "-q"]) == 0
    a, b = (xr.open_dataset(tmp_path / name).load() for name in ("a.nc", "b.nc"))
    assert "surge" not in yaml.safe_load(a.attrs["scenario"])["motion"]
    assert a.attrs["scenario"] == b.attrs["scenario"]
    xr.testing.assert_identical(a.drop_attrs(), b.drop_attrs())


def test_check_takes_unset_too(tmp_path, capsys):
    """A whole section removed: the file without it (ins.rate then has no effect, which
    the validator says)."""
    path = write(tmp_path, SURGING)
    assert main(["check", str(path), "--unset", "motion.surge"]) == 0
    assert main(["check", str(path), "--unset", "motion"]) == 0
    assert "ins.rate: has no effect without a motion section" in capsys.readouterr().err


def test_removing_a_required_key_is_refused_in_one_line(tmp_path, capsys):
    path = write(tmp_path, {**SURGING, "motion": {"spectrum": {"hs": 2.0, "tp": 7.0},
                                                  "response": {"heave": {"factor": 1.0}}}})
    assert main(["check", str(path), "--unset", "motion.spectrum.hs"]) == 2
    line = one_line(capsys)
    assert line.startswith("uq: error: --unset motion.spectrum.hs (applied to ")
    assert "motion.spectrum.hs: missing" in line


def test_removing_a_key_the_scenario_does_not_set_is_refused(tmp_path, capsys):
    path = write(tmp_path, SURGING)
    assert main(["check", str(path), "--unset", "motion.sway"]) == 2
    line = one_line(capsys)
    assert "motion.sway" in line and "nothing to remove" in line and "pitch, surge" in line


def test_the_order_of_set_and_unset_is_kept(tmp_path):
    """--unset then --set of a key below it: the set wins, in the order given."""
    path = write(tmp_path, SURGING)
    assert main(["check", str(path), "--unset", "motion.surge",
                 "--set", "motion.surge={amplitude: 0.5, period: 9}"]) == 0
    overrides = parse_overrides(["motion.surge=null", "motion.surge={amplitude: 0.5, period: 9}"])
    scenario = load_scenario(str(path), overrides)
    assert scenario.settings["motion"]["surge"]["amplitude"] == 0.5


@pytest.mark.parametrize("argv", [["run", "X", "--unset", "a=b"], ["check", "X", "--set", "a="]])
def test_malformed_overrides_are_one_line(argv, tmp_path, capsys):
    argv = [str(write(tmp_path, SURGING)) if a == "X" else a for a in argv]
    try:
        status = main(argv)
    except SystemExit as stop:
        status = stop.code
    assert status == 2 and "Traceback" not in one_line(capsys)


def test_removing_a_swept_key(tmp_path):
    path = write(tmp_path, {**SURGING, "sweep": {"wind.direction": [0.0, 90.0]}})
    scenario = load_scenario(str(path), parse_overrides(["sweep.wind.direction=null"]))
    assert scenario.sweep == ()


# --- options and keys that do not apply are refused ------------------------------------
def test_warmup_set_without_for_is_refused(capsys):
    """It was accepted and ignored (every kernel compiled, no scenario read)."""
    assert main(["warmup", "--set", "wind.speed=3"]) == 2
    assert "applies only to the scenario of --for" in one_line(capsys)
    assert main(["warmup", "--unset", "motion"]) == 2
    assert "--set/--unset: motion" in one_line(capsys)


@pytest.mark.parametrize("key, value", [("n", 5000), ("digits", 2), ("control_variate", True),
                                        ("interval", "shortest"), ("chunk_size", 1024),
                                        ("stopping", "confident")])
def test_monte_carlo_keys_with_method_none_are_refused(key, value):
    with pytest.raises(Exception) as refused:
        load_scenario({"sampling": {"method": "none", key: value}})
    assert refused.value.key == f"sampling.{key}" and "--unset" in str(refused.value)


def test_method_none_keeps_what_applies():
    """The seed (recorded) and the defaults a validated scenario carries pass; so does
    a validated scenario of method none validated again (a sweep's values)."""
    scenario = load_scenario({"sampling": {"method": "none", "seed": 3},
                              "sweep": {"wind.speed": [4.0, 6.0]}})
    assert load_scenario(scenario.settings).sampling["method"] == "none"


def test_record_count_with_method_none_is_refused(tmp_path, capsys):
    """record.count asks for Monte Carlo records, which method none does not draw: it was
    accepted and ignored. Switching the Monte Carlo off from the command line drops the
    file's own Monte Carlo keys (written for the method it replaces); one given with it
    is refused."""
    path = write(tmp_path, {"name": "r", "turbulence": {"intensity": 0.1},
                            "record": {"count": 5}, "sampling": {"method": "none"}})
    assert main(["check", str(path)]) == 2
    line = one_line(capsys)
    assert "record.count: 5 Monte Carlo records" in line and "--unset record.count" in line
    assert main(["check", str(path), "--unset", "record.count"]) == 0
    assert main(["check", "sathe2011_ti", "--set", "sampling.method=none"]) == 0
    capsys.readouterr()
    assert main(["check", "sathe2011_ti", "--set", "sampling.method=none",
                 "--set", "record.count=3"]) == 2
    assert one_line(capsys).startswith("uq: error: --set record.count=3 (applied to ")


def test_switching_monte_carlo_off_from_the_command_line_drops_the_files_keys():
    """The documented GUM-only grid, --set sampling.method=none on a scenario with n and
    a seed: the file's n is dropped (not refused), the seed kept; an n given with it is
    refused."""
    scenario = load_scenario({"sampling": {"n": 5000, "seed": 3, "interval": "shortest"}},
                             {"sampling.method": "none"})
    assert scenario.sampling["method"] == "none" and scenario.sampling["seed"] == 3
    assert scenario.sampling["n"] == 100_000 and scenario.sampling["interval"] == "symmetric"
    with pytest.raises(Exception, match="sampling.n"):
        load_scenario({"sampling": {"n": 5000}}, {"sampling.method": "none",
                                                  "sampling.n": 4000})


@pytest.mark.parametrize("changes, key", [({"ins": {"correlation": "beam"}}, "ins.correlation")])
def test_keys_without_effect_that_were_silent_are_refused(changes, key):
    """Readings per beam without an INS error changed nothing and were accepted without
    a word."""
    with pytest.raises(Exception) as refused:
        load_scenario({"name": "x", **changes})
    assert refused.value.key == key and "has no effect" in str(refused.value)
