"""Checkpoints are verified before they are trusted, have one owner, and survive faults:
a flipped bit, a truncated chunk, a chunk of another run, a full disk, kill -9."""
import errno
import logging
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import xarray as xr
import yaml
from conftest import cpu_limited

import uq.pipeline.sweep
from uq.cli import main
from uq.errors import CheckpointError
from uq.pipeline.checkpoint import Checkpoint
from uq.pipeline.runner import run
from uq.pipeline.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]
SWEEP = {"name": "tiny", "ins": {"heading": {"dist": "normal", "u": 0.3}},
         "lidar": {"errors": {"radial_velocity": {"dist": "normal", "u": 0.1}}},
         "sampling": {"n": 3000, "seed": 7},
         "sweep": {"wind.direction": [0.0, 90.0, 180.0, 270.0], "ins.heading.u": [0.2, 0.5]}}


@pytest.fixture
def one_scene_per_chunk(monkeypatch):
    monkeypatch.setattr(uq.pipeline.sweep, "SWEEP_CHUNK_ELEMENTS", 1)
    monkeypatch.setattr(uq.pipeline.sweep, "SWEEP_CHUNK_ELEMENTS_COMPILED", 1)
    scenario = load_scenario(SWEEP)
    assert len(uq.pipeline.sweep.sweep_plan(scenario).chunks) == 8
    return scenario


def same(a, b):
    xr.testing.assert_identical(a.drop_attrs(), b.drop_attrs())


def interrupted(scenario, directory, after=3):
    def stop(done, total):
        if done == after:
            raise KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt):
        run(scenario, progress=stop, checkpoint=Checkpoint(directory))
    return sorted(directory.glob("chunk-*.nc"))


@pytest.mark.parametrize("damage", ["flip one bit", "truncate", "drop the checksum"])
def test_a_damaged_chunk_is_recomputed_with_a_warning(tmp_path, one_scene_per_chunk, damage,
                                                      caplog):
    directory = tmp_path / "out.nc.partial"
    chunks = interrupted(one_scene_per_chunk, directory)
    victim = chunks[1]
    data = bytearray(victim.read_bytes())
    if damage == "flip one bit":
        data[len(data) // 2] ^= 0x10
        victim.write_bytes(bytes(data))
    elif damage == "truncate":
        victim.write_bytes(bytes(data[:len(data) // 3]))
    else:
        victim.with_name(victim.name + ".sha256").unlink()
    seen = []
    with caplog.at_level(logging.WARNING, logger="uq.pipeline.checkpoint"):
        resumed = run(one_scene_per_chunk, progress=lambda d, t: seen.append(d),
                      checkpoint=Checkpoint(directory, resume=True))
    assert victim.name in caplog.text and "recomputed" in caplog.text
    assert seen[0] == 2                              # two intact chunks reused
    same(resumed, run(one_scene_per_chunk))


def test_a_chunk_of_another_run_is_not_mixed_in(tmp_path, one_scene_per_chunk, caplog):
    """A chunk written by a run of another seed, dropped into this checkpoint (the race of
    two runs on one output), is recomputed: resumed results equal a clean run."""
    mine, theirs = tmp_path / "a.nc.partial", tmp_path / "b.nc.partial"
    interrupted(one_scene_per_chunk, mine)
    other = one_scene_per_chunk.with_values({"sampling.seed": 8})
    foreign = interrupted(other, theirs, after=5)[4]
    for suffix in ("", ".sha256"):
        (mine / (foreign.name + suffix)).write_bytes((theirs / (foreign.name + suffix)).read_bytes())
    with caplog.at_level(logging.WARNING, logger="uq.pipeline.checkpoint"):
        resumed = run(one_scene_per_chunk, checkpoint=Checkpoint(mine, resume=True))
    assert "another run" in caplog.text
    same(resumed, run(one_scene_per_chunk))


def test_a_checkpoint_has_one_owner(tmp_path):
    directory = tmp_path / "out.nc.partial"
    first = Checkpoint(directory).acquire()
    with pytest.raises(CheckpointError, match=f"in use by another run \\(process {os.getpid()}"):
        Checkpoint(directory).acquire()
    first.release()
    Checkpoint(directory).acquire().release()


def test_a_second_command_on_the_same_output_is_refused(tmp_path):
    """Two `uq run` on one output: the second is refused at once (exit 2), the first
    finishes with the uninterrupted result. The first stops itself (SIGSTOP) once it holds
    the checkpoint, so the second always meets it running, however loaded the machine."""
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(SWEEP))
    first = subprocess.Popen([sys.executable, "-c", KILLABLE, str(path)], cwd=tmp_path,
                             env={**os.environ, STOP_AT: "start"}, stderr=subprocess.PIPE,
                             text=True, preexec_fn=cpu_limited())
    wait_until_stopped(first)
    try:
        second = subprocess.run([sys.executable, "-m", "uq.cli", "run", str(path), "--quiet",
                                 "-o", "out.nc"], cwd=tmp_path, capture_output=True,
                                text=True, preexec_fn=cpu_limited())
    finally:
        first.send_signal(signal.SIGCONT)
    assert first.wait() == 0, first.stderr.read()
    assert second.returncode == 2 and "in use by another run" in second.stderr
    assert len(second.stderr.strip().splitlines()) == 1
    assert (tmp_path / "out.nc").exists()


def wait_until_stopped(child):
    """Wait until `child` has stopped itself (SIGSTOP); fail if it exited instead."""
    _, status = os.waitpid(child.pid, os.WUNTRACED)
    if not os.WIFSTOPPED(status):
        child.returncode = os.waitstatus_to_exitcode(status)
        raise AssertionError(f"the child exited with status {child.returncode} before it "
                             f"stopped: {child.stderr.read() if child.stderr else ''}")


def test_kill_9_then_resume_is_bit_identical(tmp_path):
    """kill -9 after exactly the second chunk (the child stops itself there), then
    --resume: the result of an uninterrupted run, bit for bit."""
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump({**SWEEP, "sampling": {"n": 60_000, "seed": None}}))
    env = dict(os.environ)
    child = subprocess.Popen([sys.executable, "-c", KILLABLE, str(path)], cwd=tmp_path,
                             env={**env, STOP_AT: "save 2"}, preexec_fn=cpu_limited())
    partial = tmp_path / "out.nc.partial"
    wait_until_stopped(child)
    child.send_signal(signal.SIGKILL)
    child.wait()
    assert len(list(partial.glob("chunk-*.nc.sha256"))) == 2
    assert not (tmp_path / "out.nc").exists()
    resumed = subprocess.run([sys.executable, "-c", KILLABLE, str(path), "--resume"],
                             cwd=tmp_path, env=env, capture_output=True, text=True,
                             preexec_fn=cpu_limited())
    assert resumed.returncode == 0, resumed.stderr
    with xr.open_dataset(tmp_path / "out.nc") as ds:
        out = ds.load()
    clean = subprocess.run([sys.executable, "-c", KILLABLE, str(path), "-o", "clean.nc",
                            "--set", f"sampling.seed={out.attrs['seed']}"],
                           cwd=tmp_path, env=env, capture_output=True, text=True,
                           preexec_fn=cpu_limited())
    assert clean.returncode == 0, clean.stderr
    with xr.open_dataset(tmp_path / "clean.nc") as ds:
        same(out, ds.load())
    assert not partial.exists()


#: Environment variable that makes KILLABLE stop itself (SIGSTOP): "start" once it holds
#: the checkpoint and has written its manifest, "save N" after its N-th chunk.
STOP_AT = "UQ_TEST_STOP_AT"

#: `uq run` with one scene per chunk (so the sweep has several chunks to kill between).
KILLABLE = """
import os, signal, sys
import uq.pipeline.sweep
from uq.pipeline.checkpoint import Checkpoint
uq.pipeline.sweep.SWEEP_CHUNK_ELEMENTS = uq.pipeline.sweep.SWEEP_CHUNK_ELEMENTS_COMPILED = 1
where, _, count = os.environ.get("UQ_TEST_STOP_AT", "").partition(" ")
def stopping(method, after):
    calls = []
    def wrapped(self, *args):
        result = method(self, *args)
        calls.append(1)
        if len(calls) == after:
            os.kill(os.getpid(), signal.SIGSTOP)
        return result
    return wrapped
if where:
    setattr(Checkpoint, where, stopping(getattr(Checkpoint, where), int(count or 1)))
from uq.cli import main
args = sys.argv[1:]
extra = [] if "-o" in args else ["-o", "out.nc"]
sys.exit(main(["run", args[0], "--quiet"] + extra + args[1:]))
"""


def test_a_full_disk_is_survived(tmp_path, one_scene_per_chunk, monkeypatch, capsys):
    """The disk fills while the fourth chunk is written: exit 2 with one line, no results
    file and no temporary file left; after space is freed, --resume completes to the
    uninterrupted result."""
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(SWEEP, sort_keys=False))
    monkeypatch.chdir(tmp_path)
    original = xr.Dataset.to_netcdf
    writes = []

    def fill_up(self, target, *args, **kwargs):
        writes.append(target)
        if len(writes) == 4:
            Path(target).write_bytes(b"\0" * 100)       # half a file, then the disk is full
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return original(self, target, *args, **kwargs)
    monkeypatch.setattr(xr.Dataset, "to_netcdf", fill_up)
    assert main(["run", str(path), "--quiet", "-o", "out.nc"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "No space left on device" in err[0] and "chunk-000003" in err[0]
    assert not (tmp_path / "out.nc").exists()
    assert not [p for p in tmp_path.rglob("*.part")]
    assert len(list((tmp_path / "out.nc.partial").glob("chunk-*.nc"))) == 3
    monkeypatch.setattr(xr.Dataset, "to_netcdf", original)
    assert main(["run", str(path), "--quiet", "-o", "out.nc", "--resume"]) == 0
    with xr.open_dataset(tmp_path / "out.nc") as ds:
        same(ds.load(), run(one_scene_per_chunk))


@pytest.fixture
def small_disk(tmp_path):
    """A real 2 MiB file system (tmpfs), so that the netCDF library fails as it does on a
    full disk ('NetCDF: HDF error', not the ENOSPC an injected fault raises). Skipped,
    saying why, only where no such file system can be mounted."""
    folder = tmp_path / "disk"
    folder.mkdir()
    if os.geteuid() != 0:
        pytest.skip("mounting a 2 MiB tmpfs needs root (no other small file system here)")
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", str(folder)],
                          capture_output=True, text=True)
    if done.returncode:
        pytest.skip(f"cannot mount a 2 MiB tmpfs here: {done.stderr.strip()}")
    try:
        yield folder
    finally:
        # lazy: the tool under test may still hold a file there (the netCDF library)
        subprocess.run(["umount", "-l", str(folder)], capture_output=True)


def test_a_real_full_disk_is_one_line_and_resumable(small_disk, tmp_path, monkeypatch,
                                                    capsys):
    """rubio2022_misalignment (chunks of ~50 KiB each) on 2 MiB: exit 2 with one line naming
    the chunk and the full file system, no temporary file; with space added, --resume
    completes to the result of a run on a roomy disk."""
    monkeypatch.chdir(tmp_path)
    output = small_disk / "r.nc"
    assert main(["run", "rubio2022_misalignment", "--quiet", "-o", str(output)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in err[0], err
    assert "chunk-" in err[0] and "file system is full" in err[0] and "--resume" in err[0]
    assert not output.exists() and not list(small_disk.rglob("*.part"))
    subprocess.run(["mount", "-o", "remount,size=64m", str(small_disk)], check=True)
    assert main(["run", "rubio2022_misalignment", "--quiet", "-o", str(output),
                 "--resume"]) == 0
    assert main(["run", "rubio2022_misalignment", "--quiet", "-o", "roomy.nc"]) == 0
    with xr.open_dataset(output) as resumed, xr.open_dataset("roomy.nc") as roomy:
        same(resumed.load(), roomy.load())
    assert sorted(p.name for p in small_disk.iterdir()) == ["r.nc"]


def test_a_foreign_folder_is_never_removed(tmp_path):
    directory = tmp_path / "out.nc.partial"
    directory.mkdir()
    (directory / "thesis.tex").write_text("years of work")
    with pytest.raises(CheckpointError, match="not written by uq"):
        Checkpoint(directory).acquire()
    assert (directory / "thesis.tex").read_text() == "years of work"


def test_clearing_keeps_files_uq_did_not_write(tmp_path, caplog):
    directory = tmp_path / "out.nc.partial"
    checkpoint = Checkpoint(directory).acquire()
    (directory / "notes.txt").write_text("mine")
    with caplog.at_level(logging.WARNING, logger="uq.pipeline.checkpoint"):
        checkpoint.clear()
    assert (directory / "notes.txt").read_text() == "mine" and "kept" in caplog.text


def test_a_fresh_run_after_an_interrupted_one_starts_afresh(tmp_path, one_scene_per_chunk):
    """Without --resume the checkpoint of an interrupted run is replaced (it is uq's own),
    and the result is the uninterrupted one."""
    directory = tmp_path / "out.nc.partial"
    interrupted(one_scene_per_chunk, directory)
    seen = []
    again = run(one_scene_per_chunk, progress=lambda d, t: seen.append(d),
                checkpoint=Checkpoint(directory))
    assert seen == list(range(1, 9))                # every chunk computed again
    same(again, run(one_scene_per_chunk))


def write_record(path, scale=1.0):
    """A motion record (CSV) of roll, pitch and heave; `scale` multiplies pitch and heave
    (the edit of the issue: doubled)."""
    import numpy as np
    t = np.arange(600) * 0.1
    lines = ["time,roll,pitch,heave"] + [
        f"{a:.1f},{3 * np.sin(0.9 * a):.6f},{scale * 2 * np.sin(1.3 * a + 1):.6f},"
        f"{scale * 0.8 * np.sin(0.7 * a):.6f}" for a in t]
    path.write_text("\n".join(lines) + "\n")


#: A motion record's scenario of 6 scenes, one per chunk under KILLABLE.
RECORDED = {"name": "recorded", "wind": {"speed": 8.0},
            "ins": {"heading": {"dist": "normal", "u": 0.3}},
            "motion": {"series": {"file": "record.csv", "time": "time",
                                  "columns": {"roll": "roll", "pitch": "pitch",
                                              "heave": "heave"}, "components": 16}},
            "sampling": {"n": 40_000, "seed": 3}, "outputs": ["wind_speed"],
            "sweep": {"wind.direction": [0.0, 60.0, 120.0, 180.0, 240.0, 300.0]}}


def killed_after_two_chunks(folder, path):
    """`uq run` on `path`, killed (SIGKILL) once two chunks are on disk."""
    child = subprocess.Popen([sys.executable, "-c", KILLABLE, str(path)], cwd=folder)
    partial = folder / "out.nc.partial"
    deadline = time.monotonic() + 300               # a first run may compile the kernels
    while len(list(partial.glob("chunk-*.nc.sha256"))) < 2:
        assert time.monotonic() < deadline and child.poll() is None
        time.sleep(0.02)
    child.send_signal(signal.SIGKILL)
    child.wait()
    return partial


def test_resume_after_editing_the_motion_record_is_refused(tmp_path):
    """kill -9, then the motion record is edited (pitch and heave doubled): --resume is
    refused with one line naming the record and its key (it would mix chunks of the old
    record into the result), and the checkpoint is kept; with the record restored, the
    resume completes, bit for bit the uninterrupted run."""
    write_record(tmp_path / "record.csv")
    original = (tmp_path / "record.csv").read_bytes()
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(RECORDED))
    partial = killed_after_two_chunks(tmp_path, path)
    kept = sorted(p.name for p in partial.iterdir())
    write_record(tmp_path / "record.csv", scale=2.0)
    refused = subprocess.run([sys.executable, "-c", KILLABLE, str(path), "--resume"],
                             cwd=tmp_path, capture_output=True, text=True)
    lines = refused.stderr.strip().splitlines()
    assert refused.returncode == 2 and len(lines) == 1, refused.stderr
    assert "record.csv" in lines[0] and "motion.series.file" in lines[0]
    assert not (tmp_path / "out.nc").exists()
    assert sorted(p.name for p in partial.iterdir()) == kept
    (tmp_path / "record.csv").write_bytes(original)
    resumed = subprocess.run([sys.executable, "-c", KILLABLE, str(path), "--resume"],
                             cwd=tmp_path, capture_output=True, text=True)
    assert resumed.returncode == 0, resumed.stderr
    clean = subprocess.run([sys.executable, "-c", KILLABLE, str(path), "-o", "clean.nc"],
                           cwd=tmp_path, capture_output=True, text=True)
    assert clean.returncode == 0, clean.stderr
    with xr.open_dataset(tmp_path / "out.nc") as a, xr.open_dataset(tmp_path / "clean.nc") as b:
        same(a.load(), b.load())


def test_a_record_edited_during_the_run_is_not_mixed_in(tmp_path, monkeypatch):
    """The record is edited while the run goes (after the second of six chunks): the run
    stops with the error naming the record, before a chunk of the new record is kept."""
    import uq.pipeline.sweep as sweep
    from uq.errors import DataFileError
    monkeypatch.setattr(sweep, "SWEEP_CHUNK_ELEMENTS", 1)
    monkeypatch.setattr(sweep, "SWEEP_CHUNK_ELEMENTS_COMPILED", 1)
    write_record(tmp_path / "record.csv")
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump({**RECORDED, "sampling": {"n": 2000, "seed": 3}}))
    scenario = load_scenario(path)

    def edit(done, total):
        if done == 2:
            write_record(tmp_path / "record.csv", scale=2.0)
    directory = tmp_path / "out.nc.partial"
    with pytest.raises(DataFileError, match="record.csv.*motion.series.file.*changed while"):
        run(scenario, progress=edit, checkpoint=Checkpoint(directory))
    assert len(list(directory.glob("chunk-*.nc"))) == 2


def test_a_chunk_encoded_elsewhere_resumes_like_one_written_here(tmp_path,
                                                                 one_scene_per_chunk):
    """A dask worker encodes a chunk's file (encode_chunk) and the run's process writes
    its bytes: --resume takes it as it takes a chunk written in the process."""
    from uq.pipeline.checkpoint import encode_chunk
    here = tmp_path / "here.partial"
    direct = run(one_scene_per_chunk, checkpoint=Checkpoint(here))
    plan = uq.pipeline.sweep.sweep_plan(one_scene_per_chunk)
    written = Checkpoint(here, resume=True).acquire()
    written.start(one_scene_per_chunk, 7, plan.chunks)
    elsewhere = Checkpoint(tmp_path / "elsewhere.partial").acquire()
    elsewhere.start(one_scene_per_chunk, 7, plan.chunks)
    for index, dataset in written.load().items():
        elsewhere.save(index, dataset, encode_chunk(dataset, elsewhere.digest))
    written.release(), elsewhere.release()
    seen = []
    resumed = run(one_scene_per_chunk, progress=lambda done, total: seen.append(done),
                  checkpoint=Checkpoint(tmp_path / "elsewhere.partial", resume=True))
    assert seen == [8]                      # every chunk from the encoded files
    same(resumed, direct)


RECORD_SWEEP = {"name": "records", "wind": {"speed": 10.0, "reference_height": 100.0},
                "lidar": {"height": 0.0, "ranges": [100.0], "half_cone": 30.0,
                          "scan": {"beam_duration": 1.0},
                          "probe": {"kind": "pulsed", "gate_length": 18.75,
                                    "pulse_fwhm": 24.75}},
                "turbulence": {"intensity": 0.06}, "record": {"duration": 600},
                "sampling": {"method": "none"}, "outputs": ["wind_speed"],
                "sweep": {"turbulence.intensity": [0.04, 0.06, 0.08, 0.1, 0.12]}}


@pytest.mark.parametrize("after", [1, 2, 4])
def test_a_record_mode_run_resumed_after_any_chunk_is_bit_identical(tmp_path, after,
                                                                    monkeypatch):
    """A record-mode sweep of turbulence.intensity (a chunk per intensity), stopped after
    `after` chunks and resumed in a fresh process (the spectral paths it kept dropped):
    the uninterrupted run's numbers bit for bit, spectral variables included (each
    lidar's path is computed at unit intensity and scaled, so it does not depend on the
    intensity a process met first)."""
    from uq.pipeline import records
    scenario = load_scenario(RECORD_SWEEP)
    monkeypatch.setattr(records, "_SPECTRAL_PATHS", type(records._SPECTRAL_PATHS)())
    clean = run(scenario)
    records._SPECTRAL_PATHS.clear()
    directory = tmp_path / "out.nc.partial"
    interrupted(scenario, directory, after=after)
    records._SPECTRAL_PATHS.clear()             # a new process
    resumed = run(scenario, checkpoint=Checkpoint(directory, resume=True))
    same(resumed, clean)
    assert "turbulence_intensity_spectral" in resumed and "turbulence_v_ratio" in resumed


def test_resume_says_how_many_chunks_it_reused_and_how_many_remain(tmp_path,
                                                                   one_scene_per_chunk,
                                                                   capsys, monkeypatch):
    """`uq run --resume` said nothing of what it reused. Three of the chunks were
    finished before the stop; the resumed run says 3 reused and the rest to compute, on
    stderr (nothing with --quiet); without a checkpoint, that all are to compute."""
    path = tmp_path / "s.yaml"
    path.write_text(one_scene_per_chunk.text)
    directory = tmp_path / "out.nc.partial"
    interrupted(one_scene_per_chunk, directory, after=3)
    total = 8                                    # chunks (one_scene_per_chunk)
    monkeypatch.chdir(tmp_path)
    assert main(["run", str(path), "-o", "out.nc", "--resume"]) == 0
    err = capsys.readouterr().err
    assert f"uq: resuming from out.nc.partial: 3 of {total} chunks reused, {total - 3} to " \
        "compute" in err.splitlines(), err
    assert main(["run", str(path), "-o", "other.nc", "--resume"]) == 0
    assert (f"uq: --resume: no finished chunk in other.nc.partial; all {total} chunks to "
            "compute") in capsys.readouterr().err.splitlines()
    (tmp_path / "other.nc").unlink()
    assert main(["run", str(path), "-o", "other.nc", "--resume", "-q"]) == 0
    assert capsys.readouterr().err == ""
