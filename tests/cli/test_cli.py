"""Command line: bad input exits 2 with one line naming the key, no traceback, no file."""
import subprocess
import sys
from pathlib import Path

import pytest
import xarray as xr
import yaml
from conftest import cpu_limited

from uq.cli import main

ROOT = Path(__file__).resolve().parents[2]
GOOD = {"name": "tiny", "ins": {"heading": {"dist": "normal", "u": 0.1}},
        "sampling": {"n": 2000, "seed": 1}}


def uq(*args, cwd):
    """Run the command in a new process (what a user sees, tracebacks included), bounded
    in CPU time (not wall time)."""
    return subprocess.run([sys.executable, "-m", "uq.cli", *args], cwd=cwd, capture_output=True,
                          text=True, preexec_fn=cpu_limited())


def uq_in_process(args, cwd, capsys, monkeypatch):
    """Run the command in this process (fast); returns (status, stderr)."""
    monkeypatch.chdir(cwd)
    try:
        status = main(list(args))
    except SystemExit as stop:            # argparse usage errors
        status = stop.code
    return status, capsys.readouterr().err


def write(tmp_path, content, name="bad.yaml"):
    path = tmp_path / name
    path.write_text(content if isinstance(content, str) else yaml.safe_dump(content))
    return path


# (description, scenario mapping or raw text, key the message must name)
MALFORMED = [
    ("unknown top-level key", {**GOOD, "windd": {}}, "windd"),
    ("unknown wind key", {**GOOD, "wind": {"sped": 5}}, "wind.sped"),
    ("speed is text", {**GOOD, "wind": {"speed": "fast"}}, "wind.speed"),
    ("negative speed", {**GOOD, "wind": {"speed": -1}}, "wind.speed"),
    ("direction out of range", {**GOOD, "wind": {"direction": 400}}, "wind.direction"),
    ("zero reference height", {**GOOD, "wind": {"reference_height": 0}}, "wind.reference_height"),
    ("half-cone 0", {**GOOD, "lidar": {"half_cone": 0}}, "lidar.half_cone"),
    ("half-cone 90", {**GOOD, "lidar": {"half_cone": 90}}, "lidar.half_cone"),
    ("half-cone bool", {**GOOD, "lidar": {"half_cone": True}}, "lidar.half_cone"),
    ("pitch 95", {**GOOD, "ship": {"pitch": 95}}, "ship.pitch"),
    ("negative sog", {**GOOD, "ship": {"sog": -2}}, "ship.sog"),
    ("negative uncertainty", {**GOOD, "ins": {"sog": {"dist": "normal", "u": -0.1}}}, "ins.sog.u"),
    ("unknown distribution", {**GOOD, "ins": {"sog": {"dist": "gauss", "u": 0.1}}}, "ins.sog.dist"),
    ("missing parameter", {**GOOD, "ins": {"sog": {"dist": "uniform"}}}, "ins.sog.half_width"),
    ("wrong parameter", {**GOOD, "ins": {"sog": {"dist": "normal", "half_width": 1}}}, "ins.sog"),
    ("student t dof 2", {**GOOD, "ins": {"sog": {"dist": "student_t", "u": 1, "dof": 2}}},
     "ins.sog.dof"),
    ("unknown correlation mode", {**GOOD, "ins": {"correlation": "gate"}}, "ins.correlation"),
    ("unknown ins quantity", {**GOOD, "ins": {"speed": {"dist": "normal", "u": 1}}}, "ins.speed"),
    ("unknown lidar error", {**GOOD, "lidar": {"errors": {"range": {"dist": "normal", "u": 1}}}},
     "lidar.errors.range"),
    ("unknown correction", {**GOOD, "correction": "partial"}, "correction"),
    ("unknown method", {**GOOD, "sampling": {"method": "qmc", "n": 100}}, "sampling.method"),
    ("n and digits", {**GOOD, "sampling": {"n": 100, "digits": 2}}, "sampling"),
    ("n is float", {**GOOD, "sampling": {"n": 1e5}}, "sampling.n"),
    ("n too small", {**GOOD, "sampling": {"n": 1}}, "sampling.n"),
    ("digits 0", {**GOOD, "sampling": {"digits": 0}}, "sampling.digits"),
    ("negative seed", {**GOOD, "sampling": {"n": 100, "seed": -1}}, "sampling.seed"),
    ("sweep key missing", {**GOOD, "sweep": {"wind.gust": [1, 2]}}, "sweep.wind.gust"),
    ("sweep undeclared error", {**GOOD, "sweep": {"ins.sog.u": [0.1, 0.2]}}, "sweep.ins.sog.u"),
    ("sweep a section", {**GOOD, "sweep": {"wind": [1, 2]}}, "sweep.wind"),
    ("sweep bad value", {**GOOD, "sweep": {"lidar.half_cone": [28, 95]}}, "lidar.half_cone"),
    ("sweep empty range", {**GOOD, "sweep": {"wind.speed": {"start": 5, "stop": 1, "step": 1}}},
     "sweep.wind.speed"),
    ("sweep zero step", {**GOOD, "sweep": {"wind.speed": {"start": 1, "stop": 5, "step": 0}}},
     "sweep.wind.speed"),
    ("unknown output", {**GOOD, "outputs": ["wind_speed", "turbulence"]}, "outputs"),
    ("repeated output", {**GOOD, "outputs": ["wind_speed", "wind_speed"]}, "outputs"),
    ("too few beams", {**GOOD, "lidar": {"azimuths": [0, 180]}}, "lidar.azimuths"),
    ("repeated azimuth", {**GOOD, "lidar": {"azimuths": [0, 90, 360, 180]}}, "lidar.azimuths"),
    ("empty ranges", {**GOOD, "lidar": {"ranges": []}}, "lidar.ranges"),
    ("negative range", {**GOOD, "lidar": {"ranges": [-10]}}, "lidar.ranges[0]"),
    ("vertical beam text", {**GOOD, "lidar": {"vertical_beam": "yes"}}, "lidar.vertical_beam"),
    ("bad name", {**GOOD, "name": "../escape"}, "name"),
    ("control variate not a bool", {**GOOD, "sampling": {"n": 100, "control_variate": "yes"}},
     "sampling.control_variate"),
    ("not a mapping", "- just\n- a list\n", "scenario must be a mapping"),
    ("invalid yaml", "wind: {speed: 5\n", "not valid YAML"),
]


@pytest.mark.parametrize("description, content, key", MALFORMED, ids=[m[0] for m in MALFORMED])
def test_malformed_scenario_exits_2_with_one_line(tmp_path, capsys, monkeypatch, description,
                                                  content, key):
    path = write(tmp_path, content)
    for args in (["check", str(path)], ["run", str(path), "-o", str(tmp_path / "out.nc")]):
        status, stderr = uq_in_process(args, tmp_path, capsys, monkeypatch)
        assert status == 2, (description, stderr)
        lines = stderr.strip().splitlines()
        assert len(lines) == 1, stderr
        assert key in lines[0] and str(path) in lines[0]
        assert not (tmp_path / "out.nc").exists()
        assert not (tmp_path / "results").exists()
        assert not list(tmp_path.glob(".*.part"))


@pytest.mark.parametrize("index", [0, 11, 26, 41])
def test_malformed_scenario_in_a_new_process_has_no_traceback(tmp_path, index):
    _, content, key = MALFORMED[index]
    result = uq("run", str(write(tmp_path, content)), cwd=tmp_path)
    assert result.returncode == 2
    assert "Traceback" not in result.stderr and key in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


def test_missing_file_is_bad_input(tmp_path):
    result = uq("check", str(tmp_path / "nope.yaml"), cwd=tmp_path)
    assert result.returncode == 2 and "cannot read" in result.stderr


def test_bad_set_override_is_bad_input(tmp_path):
    path = write(tmp_path, GOOD, "good.yaml")
    result = uq("run", str(path), "--set", "lidar.half_cone=120", cwd=tmp_path)
    assert result.returncode == 2 and "lidar.half_cone" in result.stderr
    assert not (tmp_path / "results").exists()
    result = uq("run", str(path), "--set", "nonsense", cwd=tmp_path)
    assert result.returncode == 2


def test_usage_error_exits_2(tmp_path):
    assert uq("frobnicate", cwd=tmp_path).returncode == 2


def test_version_and_help(tmp_path):
    result = uq("--version", cwd=tmp_path)
    assert result.returncode == 0 and result.stdout.startswith("uq ")
    assert uq("run", "--help", cwd=tmp_path).returncode == 0


def test_every_help_prints(capsys):
    """uq --help and every command's --help: argparse formats each help text with %, so
    a bare % in one (a '95 % interval') breaks every help that lists it."""
    from uq.cli import SUBCOMMANDS, main
    names = ["list" if name == "listing" else name for name in SUBCOMMANDS]
    for argv in [["--help"]] + [[name, "--help"] for name in names]:
        with pytest.raises(SystemExit) as raised:
            main(argv)
        assert raised.value.code == 0, argv
        assert "usage: uq" in capsys.readouterr().out


def test_run_writes_default_path_and_set_overrides(tmp_path):
    path = write(tmp_path, GOOD, "good.yaml")
    result = uq("run", str(path), "--set", "wind.speed=7.5", "--set", "sampling.n=3000",
                cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "wind_speed" in result.stdout
    with xr.open_dataset(tmp_path / "results" / "tiny.nc") as ds:
        assert float(ds["wind_speed_true"]) == 7.5
        assert ds.attrs["n_samples"] == 3000
        assert "speed: 7.5" in ds.attrs["scenario"]
    assert uq("check", str(path), cwd=tmp_path).returncode == 0


def test_shipped_scenarios_validate():
    for path in sorted((ROOT / "scenarios").glob("*.yaml")):
        result = uq("check", str(path), cwd=ROOT)
        assert result.returncode == 0, result.stderr


def test_scale_out_options_are_checked(tmp_path, capsys, monkeypatch):
    path = write(tmp_path, GOOD, "good.yaml")
    status, err = uq_in_process(["run", str(path), "--workers", "0"], tmp_path, capsys,
                                monkeypatch)
    assert status == 2 and "--workers" in err
    status, err = uq_in_process(["run", str(path), "--workers", "1", "--scheduler", "x"],
                                tmp_path, capsys, monkeypatch)
    assert status == 2 and "not allowed with" in err
    assert not (tmp_path / "results").exists()


def test_set_reads_exponent_numbers_as_numbers():
    from uq.cli import parse_overrides
    assert parse_overrides(["ins.sog.u=1e-9", "name=abc", "x=nan"]) == {
        "ins.sog.u": 1e-9, "name": "abc", "x": "nan"}


def test_interrupted_run_keeps_its_checkpoint_and_resumes(tmp_path, capsys, monkeypatch):
    """Ctrl-C: exit 130, no results file, the finished chunks kept; --resume completes."""
    import uq.pipeline.sweep
    monkeypatch.setattr(uq.pipeline.sweep, "SWEEP_CHUNK_ELEMENTS", 1)       # one scene per chunk
    path = write(tmp_path, {**GOOD, "sweep": {"wind.direction": [0, 90, 180]}}, "good.yaml")
    import uq.pipeline.checkpoint
    save = uq.pipeline.checkpoint.Checkpoint.save

    def save_then_interrupt(self, index, dataset, *encoded):
        save(self, index, dataset, *encoded)
        raise KeyboardInterrupt
    monkeypatch.setattr(uq.pipeline.checkpoint.Checkpoint, "save", save_then_interrupt)
    status, err = uq_in_process(["run", str(path), "--quiet"], tmp_path, capsys, monkeypatch)
    assert status == 130 and "--resume" in err
    assert not (tmp_path / "results" / "tiny.nc").exists()
    assert len(list((tmp_path / "results" / "tiny.nc.partial").glob("chunk-*.nc"))) == 1
    monkeypatch.setattr(uq.pipeline.checkpoint.Checkpoint, "save", save)
    status, _ = uq_in_process(["run", str(path), "--quiet", "--resume"], tmp_path, capsys,
                              monkeypatch)
    assert status == 0 and (tmp_path / "results" / "tiny.nc").exists()
    assert not (tmp_path / "results" / "tiny.nc.partial").exists()


def test_bare_uq_prints_the_usage_and_the_commands(tmp_path):
    result = uq(cwd=tmp_path)
    assert result.returncode == 2
    for command in ("run", "check", "plot", "report", "bench", "fit", "golden"):
        assert f"\n    {command} " in result.stderr
    assert "usage: uq" in result.stderr and "Traceback" not in result.stderr


@pytest.mark.parametrize("command", ["run", "check", "plot", "report", "bench", "fit",
                                     "golden"])
def test_every_command_has_quiet_and_verbose(command, tmp_path):
    text = uq(command, "--help", cwd=tmp_path).stdout
    assert "-q, --quiet" in text and "-v, --verbose" in text


def test_quiet_prints_nothing_and_results_go_to_stdout(tmp_path):
    path = write(tmp_path, GOOD, "good.yaml")
    quiet = uq("run", str(path), "-q", "-o", "q.nc", cwd=tmp_path)
    assert quiet.returncode == 0 and quiet.stdout == "" and quiet.stderr == ""
    loud = uq("run", str(path), "-o", "l.nc", cwd=tmp_path)
    assert "wrote l.nc" in loud.stdout and "wrote" not in loud.stderr


@pytest.mark.parametrize("text, shown", [
    ("name: y\nlidar:\n  ranges: [100, 200,, 300]\n",
     "at line 3, column 21: expected the node content, but found ',' "
     "(here: 'ranges: [100, 200,^, 300]')"),
    ("name: y\n  lidar: 3\n", "at line 2, column 8: mapping values are not allowed here "
     "(here: 'lidar^: 3')"),
])
def test_a_yaml_syntax_error_shows_its_line_and_a_caret(text, shown, tmp_path, capsys,
                                                         monkeypatch):
    path = write(tmp_path, text)
    status, err = uq_in_process(["check", str(path)], tmp_path, capsys, monkeypatch)
    assert status == 2 and err.strip() == f"uq: error: {path}: not valid YAML {shown}"


@pytest.mark.parametrize("override, key", [("lidar.half_cone=95", "lidar.half_cone"),
                                           ("lidar.ranges=[1, -2]", "lidar.ranges[1]"),
                                           ("sweep.wind.direction=abc", "sweep.wind.direction"),
                                           ("lidar.foo=1", "lidar.foo")])
def test_a_bad_override_is_blamed_on_the_set_option(override, key, tmp_path, capsys,
                                                    monkeypatch):
    path = write(tmp_path, GOOD, "good.yaml")
    status, err = uq_in_process(["check", str(path), "--set", override], tmp_path, capsys,
                                monkeypatch)
    assert status == 2 and len(err.splitlines()) == 1
    assert err.startswith(f"uq: error: --set {override.split('=')[0]}=") and \
        f"(applied to {path}): {key}: " in err, err
    # the same value in the file is the file's error
    status, err = uq_in_process(["check", str(write(tmp_path, "lidar: {half_cone: 95}\n"))],
                                tmp_path, capsys, monkeypatch)
    assert status == 2 and err.startswith(f"uq: error: {tmp_path / 'bad.yaml'}: ")
