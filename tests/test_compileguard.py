"""uq.compileguard.cached_kernels: a kernel module only where numba's cache holds its
kernels while a run leaves the missing ones to numpy (numpy_while_uncached), imported
as usual otherwise; in new processes with their own numba cache."""
import os
import subprocess
import sys
from pathlib import Path

from tests.conftest import child_failure, cpu_limited

ROOT = Path(__file__).resolve().parents[1]

CHILD = """
import sys, uq.compileguard as guard
name = "uq.physics.spectralkernels"
with guard.numpy_while_uncached():
    first = guard.cached_kernels(name)
    looked = dict(guard._MISSED)
    again = guard.cached_kernels(name)          # within RETRY_SECONDS: not looked for
    print(first is None, again is None, name in looked, name in sys.modules,
          looked == guard._MISSED)
if sys.argv[1] == "compile":
    module = guard.cached_kernels(name)         # outside: imported, compiled
    print(module.__name__ == name)
"""


def _child(cache, *argv):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": str(ROOT)}
    done = subprocess.run([sys.executable, "-c", CHILD, *argv], env=env, capture_output=True,
                          text=True, preexec_fn=cpu_limited())
    assert done.returncode == 0, child_failure(done)
    return done.stdout.split()


def test_a_module_missing_from_the_cache_is_none_and_compiles_nothing(tmp_path):
    cache = tmp_path / "numba"
    assert _child(cache, "only") == ["True", "True", "True", "False", "True"]
    assert not list(cache.rglob("*.nbi"))       # nothing was compiled into the cache


def test_a_module_in_the_cache_is_loaded(tmp_path):
    # one process compiles it (outside the guard); the next one finds it within
    cache = tmp_path / "numba"
    assert _child(cache, "compile") == ["True", "True", "True", "False", "True", "True"]
    assert list(cache.rglob("*.nbi"))
    code = ("import uq.compileguard as guard\n"
            "with guard.numpy_while_uncached():\n"
            "    print(guard.cached_kernels('uq.physics.spectralkernels') is not None)")
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": str(ROOT)}
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                          text=True, preexec_fn=cpu_limited())
    assert done.returncode == 0, child_failure(done)
    assert done.stdout.split() == ["True"]


def test_threads_asking_at_once_each_get_the_whole_module(tmp_path):
    # several threads ask for a module none has imported yet (a campaign's threads): each
    # gets it whole, not the half-made module another thread is importing
    code = ("import threading, uq.compileguard as guard\n"
            "got = []\n"
            "def ask():\n"
            "    got.append(hasattr(guard.cached_kernels('uq.physics.spectralkernels'),"
            " 'vector_sums'))\n"
            "threads = [threading.Thread(target=ask) for _ in range(4)]\n"
            "[t.start() for t in threads]; [t.join() for t in threads]\n"
            "print(got)\n")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}     # the suite's cache: compiled there
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                          text=True, preexec_fn=cpu_limited())
    assert done.returncode == 0, child_failure(done)
    assert done.stdout.split() == ["[True,", "True,", "True,", "True]"]
