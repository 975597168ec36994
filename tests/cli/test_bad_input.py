"""A corpus of bad inputs and hostile paths (issue 14): every one exits 2 with one line
that names the file and the key (or path), no traceback, no file left that the tool
created and no file touched that it did not create.

Each case prepares files in a fresh folder and returns the command line and the words
its message must contain. The corpus runs in this process (fast) and once more in a
child process under a 2 GB address-space limit with a budget of 10 s of CPU time per
input.
"""
import hashlib
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import child_failure, cpu_limited

from uq.cli import main

ROOT = Path(__file__).resolve().parents[2]
GOOD = {"name": "tiny", "ins": {"heading": {"dist": "normal", "u": 0.1}},
        "sampling": {"n": 2000, "seed": 1}}
CASES = {}


def case(name):
    def register(function):
        CASES[name] = function
        return function
    return register


def scenario(folder, content, name="bad.yaml"):
    path = folder / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content if isinstance(content, str) else yaml.safe_dump(content))
    return path


def with_good(**sections):
    return {**GOOD, **sections}


def check_and_run(path, *names):
    """Both `uq check` and `uq run` must refuse the scenario."""
    return [(["check", str(path)], (str(path),) + names),
            (["run", str(path), "-o", str(path.parent / "out.nc")], (str(path),) + names)]


# --- file encodings and shapes -------------------------------------------------------
@case("binary garbage")
def _(d):
    return check_and_run(scenario(d, bytes(range(256)) * 64), "UTF-8")


@case("latin-1 text")
def _(d):
    return check_and_run(scenario(d, "name: tiny\ndescription: Sür Mer\n".encode("latin-1")),
                         "UTF-8", "line 2")


@case("utf-16 text")
def _(d):
    return check_and_run(scenario(d, "name: tiny\n".encode("utf-16")), "UTF-8")


@case("/dev/zero")
def _(d):
    return check_and_run(Path("/dev/zero"), "KiB")


@case("/dev/urandom")
def _(d):
    return check_and_run(Path("/dev/urandom"), "KiB")


@case("a folder")
def _(d):
    (d / "folder.yaml").mkdir()
    return check_and_run(d / "folder.yaml", "folder")


@case("missing file")
def _(d):
    return check_and_run(d / "nope.yaml", "cannot read")


@case("file larger than the limit")
def _(d):
    return check_and_run(scenario(d, "# padding\n" * 200_000), "KiB")


@case("deeply nested list")
def _(d):
    return check_and_run(scenario(d, "wind: " + "[" * 50_000 + "]" * 50_000 + "\n"), "nested")


@case("deeply nested mapping")
def _(d):
    return check_and_run(scenario(d, "wind: " + "{a: " * 50_000 + "1" + "}" * 50_000 + "\n"),
                         "nested")


@case("alias bomb")
def _(d):
    lines = ["a0: &a0 [x, x, x, x, x, x, x, x, x, x]"]
    lines += [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 10) + "]" for i in range(1, 9)]
    return check_and_run(scenario(d, "\n".join(lines) + "\ndescription: *a8\n"), "aliases",
                         "more than 100000 values once its YAML aliases are expanded")


@case("recursive alias")
def _(d):
    return check_and_run(scenario(d, "description: &a [1, *a]\n"), "refers to itself")


@case("integer of 5000 digits")
def _(d):
    return check_and_run(scenario(d, "wind: {speed: " + "9" * 5000 + "}\n"),
                         "cannot read a value")


@case("a key that is a number")
def _(d):
    return check_and_run(scenario(d, "1: 2\n"), "1", "unknown key")


@case("a number key in a section")
def _(d):
    return check_and_run(scenario(d, "wind: {1: 2}\n"), "wind.1", "unknown key")


@case("a number key in the sweep")
def _(d):
    return check_and_run(scenario(d, "sweep: {1: [1, 2]}\n"), "sweep.1")


@case("a list key")
def _(d):
    return check_and_run(scenario(d, "? [a, b]\n: 1\n"), "YAML")


@case("repeated section")
def _(d):
    text = ("ins:\n  heading: {dist: normal, u: 0.1}\nwind: {speed: 5}\n"
            "ins:\n  sog: {dist: normal, u: 0.1}\n")
    return check_and_run(scenario(d, text), "ins", "lines 1 and 4")


@case("repeated key in a section")
def _(d):
    return check_and_run(scenario(d, "wind:\n  speed: 5\n  speed: 7\n"), "speed",
                         "lines 2 and 3")


@case("empty file")
def _(d):
    return check_and_run(scenario(d, ""), "mapping")


@case("a scalar document")
def _(d):
    return check_and_run(scenario(d, "42\n"), "mapping")


@case("tab indentation")
def _(d):
    return check_and_run(scenario(d, "wind:\n\tspeed: 5\n"), "not valid YAML")


# --- values ----------------------------------------------------------------------------
@case("speed of 400 digits")
def _(d):
    return check_and_run(scenario(d, "wind: {speed: " + "9" * 400 + "}\n"), "wind.speed",
                         "400 digits")


@case("seed of 400 digits")
def _(d):
    return check_and_run(scenario(d, "sampling: {seed: " + "9" * 400 + "}\n"),
                         "sampling.seed")


@case("seed beyond 64 bits")
def _(d):
    return check_and_run(scenario(d, with_good(sampling={"n": 100, "seed": 2**64})),
                         "sampling.seed")


@case("n of 400 digits")
def _(d):
    return check_and_run(scenario(d, "sampling: {n: " + "9" * 400 + "}\n"), "sampling.n")


@case("n too small for the interval")
def _(d):
    return check_and_run(scenario(d, with_good(sampling={"n": 2})), "sampling.n", "20")


@case("wind speed 1e308")
def _(d):
    return check_and_run(scenario(d, with_good(wind={"speed": 1e308})), "wind.speed",
                         "magnitude")


@case("NaN")
def _(d):
    return check_and_run(scenario(d, "wind: {speed: .nan}\n"), "wind.speed")


@case("infinity")
def _(d):
    return check_and_run(scenario(d, "ship: {heave: -.inf}\n"), "ship.heave")


@case("same_as given a list")
def _(d):
    return check_and_run(scenario(d, with_good(sweep={"wind.direction": [0, 90],
                                                      "ship.cog": {"same_as": ["a"]}})),
                         "sweep.ship.cog.same_as")


@case("same_as given a mapping")
def _(d):
    return check_and_run(scenario(d, with_good(sweep={"wind.direction": [0, 90],
                                                      "ship.cog": {"same_as": {"a": 1}}})),
                         "sweep.ship.cog.same_as")


@case("same_as of an unswept key")
def _(d):
    return check_and_run(scenario(d, with_good(sweep={"ship.cog": {"same_as": "wind.speed"}})),
                         "sweep.ship.cog.same_as")


@case("sweep step 5e-324")
def _(d):
    return check_and_run(scenario(d, with_good(sweep={"wind.speed": {
        "start": 0, "stop": 1, "step": 5e-324}})), "sweep.wind.speed", "UQ_MAX_SCENES")


@case("10^9 values of one key")
def _(d):
    return check_and_run(scenario(d, with_good(sweep={"wind.direction": {
        "start": 0, "stop": 1, "step": 1e-9}})), "sweep.wind.direction", "UQ_MAX_SCENES")


@case("10^9 scenes")
def _(d):
    three = {key: {"start": 0, "stop": 10, "step": 0.01}
             for key in ("wind.direction", "ship.cog", "wind.speed")}
    return check_and_run(scenario(d, with_good(sweep=three)), "sweep", "scenes")


@case("10^5 structural groups")
def _(d):
    return check_and_run(scenario(d, with_good(sweep={
        "ins.heading.u": {"start": 0.001, "stop": 1, "step": 0.01},
        "lidar.vertical_beam": [True, False], "correction": ["none", "yaw", "tilt2d", "full"],
        "sampling.n": {"start": 100, "stop": 1100, "step": 10}})), "sweep", "structural")


@case("a swept value of the wrong type")
def _(d):
    return check_and_run(scenario(d, with_good(sweep={"wind.speed": [5, "fast"]})),
                         "sweep.wind.speed")


@case("a swept mapping")
def _(d):
    return check_and_run(scenario(d, with_good(sweep={"wind.speed": {"from": 1}})),
                         "sweep.wind.speed")


@case("a sweep that is a list")
def _(d):
    return check_and_run(scenario(d, with_good(sweep=["wind.speed"])), "sweep")


@case("beams that do not determine the wind")
def _(d):
    return check_and_run(scenario(d, with_good(lidar={"azimuths": [0, 180],
                                                      "vertical_beam": True})),
                         "lidar.azimuths", "do not determine")


@case("swept half-cone that breaks the beams")
def _(d):
    return check_and_run(scenario(d, with_good(lidar={"azimuths": [0, 90], "vertical_beam":
                                                      True},
                                               sweep={"lidar.half_cone": [28, 0]})),
                         "lidar.half_cone")


@case("10^5 range gates")
def _(d):
    return check_and_run(scenario(d, "lidar: {ranges: [" + ", ".join(
        str(i + 1) for i in range(100_000)) + "]}\n"),
        "lidar.ranges: more than 100000 values", "at most 1000 range gates")


@case("5000 range gates")
def _(d):
    return check_and_run(scenario(d, "lidar: {ranges: [" + ", ".join(
        str(i + 1) for i in range(5000)) + "]}\n"), "lidar.ranges", "at most")


@case("10^4 azimuths")
def _(d):
    return check_and_run(scenario(d, with_good(lidar={"azimuths": [i * 0.01 for i in
                                                                  range(10_000)]})),
                         "lidar.azimuths", "at most")


@case("a chunk size of 10^12")
def _(d):
    return check_and_run(scenario(d, with_good(sampling={"n": 100, "chunk_size": 10**12})),
                         "sampling.chunk_size")


@case("ranges nested")
def _(d):
    return check_and_run(scenario(d, with_good(lidar={"ranges": [[1, 2]]})),
                         "lidar.ranges[0]")


@case("a probe of an unknown kind")
def _(d):
    return check_and_run(scenario(d, with_good(lidar={"probe": {"kind": "flash"}})),
                         "lidar.probe.kind", "point, pulsed, cw")


@case("an error of a probe parameter the probe does not give")
def _(d):
    return check_and_run(scenario(d, with_good(lidar={
        "probe": {"kind": "pulsed", "gate_length": 30, "pulse_fwhm": 22.5},
        "errors": {"beam_radius": {"dist": "normal", "u": 1.0}}})),
        "lidar.errors.beam_radius", "lidar.probe.beam_radius")


@case("outputs as text")
def _(d):
    return check_and_run(scenario(d, with_good(outputs="wind_speed")), "outputs")


@case("an error that is a number")
def _(d):
    return check_and_run(scenario(d, with_good(ins={"sog": 0.1})), "ins.sog")


@case("an error parameter that is text")
def _(d):
    return check_and_run(scenario(d, with_good(ins={"sog": {"dist": "normal", "u": "0.1"}})),
                         "ins.sog.u")


@case("a description that is a list")
def _(d):
    return check_and_run(scenario(d, with_good(description=["a"])), "description")


@case("a name with a separator")
def _(d):
    return check_and_run(scenario(d, with_good(name="a/b")), "name")


@case("a correction list")
def _(d):
    return check_and_run(scenario(d, with_good(correction=["full"])), "correction")


@case("a golden section with a run")
def _(d):
    path = scenario(d, {"golden": {"name": "x"}})
    return [(["run", str(path)], (str(path), "uq golden"))]


# --- --set -----------------------------------------------------------------------------
@case("--set into a list")
def _(d):
    path = scenario(d, GOOD, "good.yaml")
    return [(["run", str(path), "--set", "lidar.ranges.0=5", "-o", str(d / "o.nc")],
             ("lidar.ranges",))]


@case("--set of a huge sweep")
def _(d):
    path = scenario(d, GOOD, "good.yaml")
    return [(["check", str(path), "--set", "sweep.wind.speed={start: 0, stop: 1e9, step: 1}"],
             ("sweep.wind.speed",))]


@case("--set without a value")
def _(d):
    path = scenario(d, GOOD, "good.yaml")
    return [(["check", str(path), "--set", "wind.speed"], ("--set", "wind.speed"))]


@case("--set of a section to a number")
def _(d):
    path = scenario(d, GOOD, "good.yaml")
    return [(["check", str(path), "--set", "wind=3"], ("wind",))]


@case("--set through a number")
def _(d):
    path = scenario(d, GOOD, "good.yaml")
    return [(["check", str(path), "--set", "wind.speed.x=3"], ("wind.speed",))]


# --- commands on files they did not expect --------------------------------------------
def results_file(d, **changes):
    import uq
    from uq.files import write_netcdf
    path = d / "results.nc"
    write_netcdf(uq.run({**GOOD, "sampling": {"n": 200, "seed": 1}, **changes}), path)
    return path


@case("plot of results without any uncertainty")
def _(d):
    path = results_file(d, outputs=["vertical_wind"], ins={})
    return [(["plot", str(path), "-o", str(d / "figures")], (str(path), "outputs",
                                                             "no output has an uncertainty"))]


@case("plot of a 4-D sweep without --select")
def _(d):
    path = results_file(d, sweep={"wind.direction": [0, 90], "ship.sog": [1, 2],
                                  "wind.speed": [4, 8], "ins.heading.u": [0.1, 0.2, 0.3, 0.4,
                                                                          0.5]})
    return [(["plot", str(path), "-o", str(d / "figures")], (str(path), "--select"))]


@case("plot --select of an unknown dimension")
def _(d):
    path = results_file(d, sweep={"wind.direction": [0, 90]})
    return [(["plot", str(path), "--select", "colour=red", "-o", str(d / "figures")],
             ("--select", "colour"))]


@case("report -o not html")
def _(d):
    path = results_file(d)
    return [(["report", str(path), "-o", str(d / "r.pdf")], ("r.pdf", ".html"))]


@case("plot of a text file")
def _(d):
    path = scenario(d, "not netCDF\n", "fake.nc")
    return [(["plot", str(path)], (str(path), "netCDF"))]


@case("report of a missing file")
def _(d):
    return [(["report", str(d / "none.nc")], (str(d / "none.nc"),))]


@case("fit of a netCDF whose scenario is not YAML")
def _(d):
    import xarray as xr
    path = results_file(d)
    with xr.open_dataset(path) as ds:
        broken = ds.load()
    broken.attrs["scenario"] = "wind: {speed: [\n"
    path.unlink()
    broken.to_netcdf(path)
    return [(["fit", str(path), "-o", str(d / "fit.nc")], (str(path), "scenario"))]


@case("fit of a header-only CSV")
def _(d):
    path = scenario(d, "height,speed\n", "table.csv")
    return [(["fit", str(path), "-o", str(d / "fit.nc")], (str(path),))]


@case("fit of an empty CSV")
def _(d):
    path = scenario(d, "", "table.csv")
    return [(["fit", str(path), "-o", str(d / "fit.nc")], (str(path),))]


@case("fit of a CSV with units in a number")
def _(d):
    path = scenario(d, "height,speed\n40,5 m/s\n60,6 m/s\n80,7 m/s\n", "table.csv")
    return [(["fit", str(path), "-o", str(d / "fit.nc")], (str(path), "speed"))]


@case("fit of a CSV of 10^6 rows")
def _(d):
    rows = np.arange(1, 10**6 + 1) % 200 + 20.0
    path = d / "table.csv"
    np.savetxt(path, np.column_stack([rows, 8 + rows / 100]), delimiter=",", fmt="%.3f",
               header="height,speed", comments="")
    return [(["fit", str(path), "-o", str(d / "fit.nc")], (str(path), "1000000 rows"))]


@case("fit of binary garbage")
def _(d):
    path = scenario(d, bytes(range(256)) * 16, "table.csv")
    return [(["fit", str(path), "-o", str(d / "fit.nc")], (str(path),))]


def golden_config(d, name="campaign", files=None):
    files = files or {"flsa": "flsa.csv", "mast": "mast.csv"}
    config = {"golden": {"name": name, "instruments": {
        key: {"file": file, "heights": {80: {"speed": "ws", "direction": "wd"}}}
        for key, file in files.items()},
        "comparisons": [{"unit": "flsa", "reference": "mast"}]}}
    if "mast" in files:
        config["golden"]["instruments"]["mast"]["calibration"] = {"absolute": 0.05,
                                                                  "relative": 0.005}
        config["golden"]["instruments"]["mast"]["class_number"] = 1.0
    return scenario(d, config, "golden.yaml")


def good_records(path, zone=""):
    rows = ["timestamp,ws,wd"] + [f"2016-06-01T{h:02d}:{m:02d}:00{zone},{5 + (h % 10)},200"
                                  for h in range(24) for m in range(0, 60, 10)]
    path.write_text("\n".join(rows) + "\n")


@case("golden on an empty CSV")
def _(d):
    good_records(d / "mast.csv")
    (d / "flsa.csv").write_text("")
    return [(["golden", str(golden_config(d)), "-o", str(d / "g")], ("flsa.csv",))]


@case("golden on a header-only CSV")
def _(d):
    good_records(d / "mast.csv")
    (d / "flsa.csv").write_text("timestamp,ws,wd\n")
    return [(["golden", str(golden_config(d)), "-o", str(d / "g")], ("flsa.csv",))]


@case("golden on binary garbage")
def _(d):
    good_records(d / "mast.csv")
    (d / "flsa.csv").write_bytes(bytes(range(256)) * 64)
    return [(["golden", str(golden_config(d)), "-o", str(d / "g")], ("flsa.csv",))]


@case("golden on a folder")
def _(d):
    good_records(d / "mast.csv")
    (d / "flsa.csv").mkdir()
    return [(["golden", str(golden_config(d)), "-o", str(d / "g")], ("flsa.csv",))]


@case("golden with mixed time zones")
def _(d):
    good_records(d / "mast.csv", zone="+00:00")
    good_records(d / "flsa.csv")
    text = (d / "flsa.csv").read_text().splitlines()
    text[5] = text[5].replace(":00,", ":00+02:00,", 1)
    (d / "flsa.csv").write_text("\n".join(text) + "\n")
    return [(["golden", str(golden_config(d)), "-o", str(d / "g")], ("flsa.csv",))]


@case("golden name empty")
def _(d):
    return [(["golden", str(golden_config(d, name=""))], ("golden.name",))]


@case("golden name ..")
def _(d):
    return [(["golden", str(golden_config(d, name=".."))], ("golden.name",))]


@case("golden name ../sibling")
def _(d):
    return [(["golden", str(golden_config(d, name="../sibling"))], ("golden.name",))]


@case("golden name with a slash")
def _(d):
    return [(["golden", str(golden_config(d, name="a/b"))], ("golden.name",))]


# --- outputs -------------------------------------------------------------------------
@case("run -o an existing folder")
def _(d):
    path = scenario(d, GOOD, "good.yaml")
    (d / "taken.nc").mkdir()
    (d / "taken.nc" / "keep.txt").write_text("mine")
    return [(["run", str(path), "-o", str(d / "taken.nc")], ("taken.nc", "folder"))]


@case("run -o a foreign file")
def _(d):
    path = scenario(d, GOOD, "good.yaml")
    (d / "theirs.nc").write_text("somebody's netCDF")
    return [(["run", str(path), "-o", str(d / "theirs.nc")], ("theirs.nc", "not written by uq"))]


@case("run -o into a file")
def _(d):
    path = scenario(d, GOOD, "good.yaml")
    (d / "plain").write_text("a file")
    return [(["run", str(path), "-o", str(d / "plain" / "out.nc")], ("plain",))]


@case("run -o into a read-only place")
def _(d):
    path = scenario(d, GOOD, "good.yaml")
    return [(["run", str(path), "-o", "/proc/uq-test/out.nc"], ("/proc/uq-test",))]


@case("run -o a foreign checkpoint folder")
def _(d):
    path = scenario(d, GOOD, "good.yaml")
    (d / "out.nc.partial").mkdir()
    (d / "out.nc.partial" / "notes.txt").write_text("mine")
    return [(["run", str(path), "-o", str(d / "out.nc")], ("out.nc.partial",))]


@case("report -o a foreign page")
def _(d):
    path = results_file(d)
    (d / "page.html").write_text("<html>my page</html>")
    return [(["report", str(path), "-o", str(d / "page.html")], ("page.html", "not written"))]


@case("plot -o a folder with a foreign figure")
def _(d):
    path = results_file(d, sweep={"wind.direction": [0, 90, 180]})
    (d / "figs").mkdir()
    from uq.outputs.figures import figure_plan
    import xarray as xr
    with xr.open_dataset(path) as ds:
        name = figure_plan(ds.load())[0][0]
    (d / "figs" / f"{name}.png").write_bytes(b"\x89PNG my own figure")
    return [(["plot", str(path), "-o", str(d / "figs")], (f"{name}.png", "not written"))]


@case("fit -o a foreign file")
def _(d):
    path = scenario(d, "height,speed\n40,5\n60,6\n80,7\n", "table.csv")
    (d / "fit.nc").write_text("theirs")
    return [(["fit", str(path), "-o", str(d / "fit.nc")], ("fit.nc", "not written"))]


@case("bench -o a foreign file")
def _(d):
    (d / "bench.nc").write_text("theirs")
    return [(["bench", "--quick", "-o", str(d / "bench.nc")], ("bench.nc", "not written"))]


@case("golden -o a foreign folder")
def _(d):
    (d / "theirs").mkdir()
    (d / "theirs" / "data.txt").write_text("mine")
    return [(["golden", str(ROOT / "scenarios" / "golden_campaign.yaml"), "-o",
              str(d / "theirs")], ("theirs", "not written by uq"))]


@case("golden -o a foreign file")
def _(d):
    (d / "theirs").write_text("mine")
    return [(["golden", str(ROOT / "scenarios" / "golden_campaign.yaml"), "-o",
              str(d / "theirs")], ("theirs",))]


# --- the harness ---------------------------------------------------------------------
def snapshot(folder):
    """Every path below `folder` -> digest of its content (folders: None)."""
    out = {}
    for path in sorted(folder.rglob("*")):
        if path.is_symlink() or not (path.is_file() or path.is_dir()):
            continue
        out[str(path)] = None if path.is_dir() else hashlib.sha256(path.read_bytes()).hexdigest()
    return out


def run_in_process(argv, cwd, capsys, monkeypatch):
    monkeypatch.chdir(cwd)
    try:
        status = main(list(argv))
    except SystemExit as stop:
        status = stop.code
    captured = capsys.readouterr()
    return status, captured.err


@pytest.mark.parametrize("name", list(CASES))
def test_bad_input_is_refused_cleanly(name, tmp_path, capsys, monkeypatch):
    folder = tmp_path / "work"
    folder.mkdir()
    commands = CASES[name](folder)
    capsys.readouterr()
    before = snapshot(folder)
    for argv, words in commands:
        status, err = run_in_process(argv, folder, capsys, monkeypatch)
        lines = err.strip().splitlines()
        assert status == 2, (name, argv, err)
        assert len(lines) == 1 and "Traceback" not in err, (name, err)
        for word in words:
            assert word in lines[0], (name, word, lines[0])
        assert snapshot(folder) == before, (name, "files changed")


def test_the_corpus_is_large():
    assert len(CASES) >= 60


#: CPU time one bad input may cost `uq check` or `uq run` before it is refused [s]. The
#: costliest, 10^5 range gates, takes ~4 s of CPU; the bound is on work (CPU time of
#: the child, ITIMER_PROF), not on wall time, so a loaded machine does not fail it.
CPU_PER_INPUT = 10

BOUNDED = textwrap.dedent("""
    import json, resource, signal, sys, io, contextlib, tempfile, pathlib, time
    resource.setrlimit(resource.RLIMIT_AS, (2 * 1024**3, 2 * 1024**3))
    sys.path[:0] = [{tests!r}, {conftest!r}]     # the corpus, and the helpers it imports
    import test_bad_input as corpus
    from uq.cli import main
    # the tool's fixed cost, paid once before any input is timed: the imports of a run
    # and its compiled kernels (compiled into numba's cache if it is cold)
    import uq.pipeline.runner, uq.outputs.summary, uq.engine.statkernels
    import uq.physics.fusedmotionkernels
    from uq.physics import fusedkernels
    fusedkernels.compiled(float)
    fusedkernels.compiled(complex)
    class OverBudget(BaseException):      # not an Exception: no handler of uq's takes it
        pass
    def over_budget(*_):
        raise OverBudget
    signal.signal(signal.SIGPROF, over_budget)
    failures, costs = [], []
    for name in {names!r}:
        folder = pathlib.Path(tempfile.mkdtemp())
        commands = corpus.CASES[name](folder)
        for argv, _ in commands:
            if argv[0] not in ("check", "run"):
                continue
            print(name, argv[0], file=sys.__stderr__, flush=True)  # the last one, if killed
            err = io.StringIO()
            started = time.process_time()
            signal.setitimer(signal.ITIMER_PROF, {budget})     # CPU time, all threads
            try:
                with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                    status = main(argv)
            except OverBudget:
                status = "more than {budget} s of CPU"
            except MemoryError:
                status = "more than 2 GB"
            except SystemExit as stop:
                status = stop.code
            except Exception as error:
                status = f"{{type(error).__name__}}: {{error}}"[:300]
            finally:
                signal.setitimer(signal.ITIMER_PROF, 0)
            used = time.process_time() - started
            costs.append((used, name, argv[0]))
            if status != 2:
                failures.append((name, argv[0], status, err.getvalue()[-300:]))
    print(json.dumps({{"failures": failures, "costliest": max(costs)}}))
""")


def test_no_input_costs_more_than_2_gb_or_10_s():
    """uq check and uq run refuse every scenario of the corpus under a 2 GB address-space
    limit, each within CPU_PER_INPUT seconds of CPU time (one child process for the whole
    corpus, itself bounded in CPU time). A child that fails says why: its status, its
    stderr (the last input it started) and its stdout."""
    names = [name for name in CASES if "golden" not in name and "fit" not in name
             and "plot" not in name and "report" not in name and "bench" not in name]
    code = BOUNDED.format(tests=str(Path(__file__).parent), conftest=str(ROOT / "tests"),
                          names=names, budget=CPU_PER_INPUT)
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            cwd=ROOT, preexec_fn=cpu_limited())
    lines = result.stdout.strip().splitlines()
    assert result.returncode == 0 and lines, child_failure(result)
    report = json.loads(lines[-1])
    assert report["failures"] == [], report
    assert report["costliest"][0] < CPU_PER_INPUT, report
