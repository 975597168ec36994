"""numba's cache folder when the package is installed read-only (issue 28).

The choice of folder is tested on a stand-in package whose ``__pycache__`` folders cannot
be created (a file holds their name: refused even for root, whom permission bits do not
stop). The whole path is tested once for real: ``uq run`` from a copy of the package on a
read-only mount (root) or with its write permissions removed (anyone else), with a home
folder numba cannot write either; its results equal those of the writable checkout.
"""
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from uq import numbacache

ROOT = Path(__file__).resolve().parents[1]
TINY = "name: tiny\nins: {heading: {dist: normal, u: 0.1}}\nsampling: {n: 2000, seed: 1}\n"


def read_only_package(folder):
    """A stand-in package whose kernel folders cannot hold a ``__pycache__``."""
    for name in numbacache.KERNEL_PACKAGES:
        (folder / name).mkdir(parents=True)
        (folder / name / "__pycache__").write_text("a file where the folder would go")
    return folder


def test_a_set_cache_variable_is_kept(tmp_path):
    environ = {"NUMBA_CACHE_DIR": str(tmp_path / "mine")}
    assert numbacache.configure(environ, read_only_package(tmp_path / "pkg")) == \
        str(tmp_path / "mine")
    assert environ == {"NUMBA_CACHE_DIR": str(tmp_path / "mine")}


def test_a_writable_package_keeps_its_cache_beside_the_code(tmp_path):
    environ = {"HOME": str(tmp_path / "home")}
    for name in numbacache.KERNEL_PACKAGES:
        (tmp_path / "pkg" / name).mkdir(parents=True)
    assert numbacache.configure(environ, tmp_path / "pkg") is None
    assert "NUMBA_CACHE_DIR" not in environ
    assert not (tmp_path / "home").exists()


def test_a_read_only_package_uses_the_users_cache_folder(tmp_path):
    environ = {"XDG_CACHE_HOME": str(tmp_path / "xdg"), "HOME": str(tmp_path / "home")}
    chosen = numbacache.configure(environ, read_only_package(tmp_path / "pkg"))
    assert chosen == str(tmp_path / "xdg" / "uq" / "numba") == environ["NUMBA_CACHE_DIR"]
    assert Path(chosen).is_dir()

    environ = {"HOME": str(tmp_path / "home")}
    chosen = numbacache.configure(environ, tmp_path / "pkg")
    assert chosen == str(tmp_path / "home" / ".cache" / "uq" / "numba")


def test_without_a_writable_home_the_private_temporary_folder(tmp_path, monkeypatch):
    (tmp_path / "home").write_text("not a folder: nothing can be made below it")
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    environ = {"HOME": str(tmp_path / "home"), "XDG_CACHE_HOME": str(tmp_path / "home")}
    chosen = Path(numbacache.configure(environ, read_only_package(tmp_path / "pkg")))
    assert chosen == tmp_path / "tmp" / f"uq-numba-{os.getuid()}"
    assert chosen.stat().st_mode & 0o777 == numbacache.PRIVATE_MODE


def test_a_planted_link_in_the_temporary_folder_is_not_followed(tmp_path, monkeypatch):
    (tmp_path / "home").write_text("not a folder")
    (tmp_path / "tmp").mkdir()
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "tmp" / f"uq-numba-{os.getuid()}").symlink_to(tmp_path / "elsewhere")
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    monkeypatch.setattr(numbacache, "NOTES", [])
    environ = {"HOME": str(tmp_path / "home")}
    chosen = Path(numbacache.configure(environ, read_only_package(tmp_path / "pkg")))
    # not None (numba then failed with its "no locator available" traceback): a new
    # owner-only folder of this process, beside the planted name, said in one note
    assert chosen.parent == tmp_path / "tmp" and chosen.name.startswith(
        f"uq-numba-{os.getuid()}-") and not chosen.is_symlink()
    assert chosen.stat().st_mode & 0o777 == numbacache.PRIVATE_MODE
    assert environ["NUMBA_CACHE_DIR"] == str(chosen)
    assert len(numbacache.NOTES) == 1 and "NUMBA_CACHE_DIR" in numbacache.NOTES[0]
    assert list((tmp_path / "elsewhere").iterdir()) == []


def test_a_planted_link_and_no_temporary_folder_leave_the_choice_to_numba(tmp_path,
                                                                           monkeypatch):
    (tmp_path / "home").write_text("not a folder")
    (tmp_path / "tmp").mkdir()
    (tmp_path / "tmp" / f"uq-numba-{os.getuid()}").symlink_to(tmp_path / "elsewhere")
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    monkeypatch.setattr(tempfile, "mkdtemp", lambda **kw: (_ for _ in ()).throw(
        PermissionError(13, "Permission denied")))
    environ = {"HOME": str(tmp_path / "home")}
    assert numbacache.configure(environ, read_only_package(tmp_path / "pkg")) is None
    assert "NUMBA_CACHE_DIR" not in environ


def test_the_command_says_where_the_kernels_went_in_one_line(monkeypatch, capsys):
    """The note of a planted link is one warning line of a compiling command; numba's
    'no locator available' (no folder at all) is one error line, status 1, where it was
    a traceback."""
    import uq.cli.warmup
    from uq.cli import main
    monkeypatch.setattr(numbacache, "NOTES", ["/tmp/uq-numba-0 is not a folder of this "
                                              "user"])
    monkeypatch.setattr(uq.cli.warmup, "command", lambda args: 0)
    assert main(["warmup"]) == 0
    assert capsys.readouterr().err.splitlines() == [
        "uq: warning: /tmp/uq-numba-0 is not a folder of this user"]

    def no_locator(args):
        raise RuntimeError("cannot cache function 'moments': no locator available for "
                           "file '/opt/uq/engine/statkernels.py'")
    monkeypatch.setattr(numbacache, "NOTES", [])
    monkeypatch.setattr(uq.cli.warmup, "command", no_locator)
    assert main(["warmup"]) == 1
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "NUMBA_CACHE_DIR" in err and "Traceback" not in err


@pytest.fixture
def read_only_copy():
    """A copy of the package (without compiled caches) that nobody can write: a read-only
    bind mount for root, removed write permissions for anyone else. Under /tmp itself, not
    pytest's owner-only folder, and removed afterwards."""
    base = Path(tempfile.mkdtemp(prefix="uq-readonly-"))
    source = base / "source"
    shutil.copytree(ROOT / "uq", source / "uq",
                    ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"))
    mounted = base / "installed"
    mounted.mkdir()
    try:
        if os.geteuid() == 0:
            commands = [["mount", "--bind", str(source), str(mounted)],
                        ["mount", "-o", "remount,bind,ro", str(mounted)]]
            for command in commands:
                done = subprocess.run(command, capture_output=True, text=True)
                if done.returncode:
                    subprocess.run(["umount", str(mounted)], capture_output=True)
                    pytest.skip(f"root cannot make a read-only mount here: {done.stderr}")
        else:
            mounted.rmdir()
            source.rename(mounted)
            subprocess.run(["chmod", "-R", "a-w", str(mounted)], check=True)
        yield base, mounted
    finally:
        if os.geteuid() == 0:
            subprocess.run(["umount", str(mounted)], capture_output=True)
        subprocess.run(["chmod", "-R", "u+w", str(base)], capture_output=True)
        shutil.rmtree(base, ignore_errors=True)


@pytest.mark.slow
def test_uq_run_from_a_read_only_install(read_only_copy, tmp_path):
    """The crash of issue 28 ('cannot cache function ...: no locator available'): the code
    and the home folder read-only, numba compiles into the private temporary folder; the
    results are those of the writable checkout, value for value."""
    base, installed = read_only_copy
    assert not numbacache.writable(installed / "uq" / "engine" / "__pycache__")
    scenario = tmp_path / "tiny.yaml"
    scenario.write_text(TINY)
    (base / "tmp").mkdir()
    environment = {"PATH": os.environ.get("PATH", "/usr/bin:/bin"), "HOME": str(installed),
                   "TMPDIR": str(base / "tmp"), "PYTHONPATH": str(installed)}
    # --model compiled: numba compiles in this process (the crash was there); auto would
    # run the numpy model while a background process compiles, equal only to rounding
    done = subprocess.run([sys.executable, "-m", "uq.cli", "run", str(scenario), "-q", "-o",
                           str(tmp_path / "installed.nc"), "--model", "compiled"],
                          env=environment, cwd=tmp_path,
                          capture_output=True, text=True, timeout=1200)   # (-m imports from cwd)
    assert done.returncode == 0, done.stderr[-2000:]
    assert list((base / "tmp" / f"uq-numba-{os.getuid()}").rglob("*.nbi"))
    done = subprocess.run([sys.executable, "-m", "uq.cli", "run", str(scenario), "-q", "-o",
                           str(tmp_path / "checkout.nc"), "--model", "compiled"], cwd=ROOT,
                          env={**os.environ, "PYTHONPATH": str(ROOT)}, capture_output=True,
                          text=True, timeout=1200)
    assert done.returncode == 0, done.stderr[-2000:]
    with xr.open_dataset(tmp_path / "installed.nc") as a, \
            xr.open_dataset(tmp_path / "checkout.nc") as b:
        assert set(a.data_vars) == set(b.data_vars)
        for name in a.data_vars:           # same seed, same code: identical, bit for bit
            np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
