"""The compile notice (uq.cli.compiling) and results that do not depend on numba's cache."""
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
from numba import njit

from uq.cli import compiling

ROOT = Path(__file__).resolve().parents[2]


def test_a_compile_says_so_once_per_kernel_and_a_loaded_one_says_nothing():
    stream = io.StringIO()
    with compiling.CompileNotice(stream) as notice:
        _compile_and_call(notice, stream)
    njit(lambda x: x - 1.0)(1.0)                # after the command: not counted
    assert notice.kernels == 1


def _compile_and_call(notice, stream):

    def helper(x):
        return 2.0 * x

    inner = njit(helper)

    def kernel(x):
        return inner(x) + 1.0

    compiled = njit(kernel)
    assert compiled(1.0) == 3.0
    lines = stream.getvalue().splitlines()
    # the first line, then one line for the kernel (its helper is part of it)
    assert lines[0] == compiling.FIRST_LINE and len(lines) == 2
    assert lines[1].startswith(f"{compiling.PREFIX} test_compiling.kernel (float) ...")
    assert notice.kernels == 1 and notice.seconds > 0
    compiled(2.0)                               # the same signature: no compile
    assert notice.kernels == 1 and stream.getvalue().splitlines() == lines


def test_a_quiet_notice_prints_nothing_but_counts():
    with compiling.CompileNotice(None) as notice:
        assert njit(lambda x: x + 1j)(1.0) == 1.0 + 1j
    assert notice.kernels == 1


#: A child that evaluates the static model's INS kernel (the cheapest to compile) on a
#: fixed draw, in the numba cache folder it is given, and prints its result's bytes and
#: whether it compiled.
CHILD = """
import json, sys
import numpy as np
from uq.cli import compiling
notice = compiling.CompileNotice(None).install()
from uq.physics import fusedkernels
rng = np.random.default_rng(5)
ins = tuple(rng.normal(size=(64, 1, 1)) for _ in range(6))
table = rng.normal(size=(1, fusedkernels.TABLE_WIDTH))
cos_out, sin_out = np.empty((4, 1, 64)), np.empty((4, 1, 64))
fusedkernels.compiled(float)["ins_trig"](ins, table, 0, 1, 0, 64, False, cos_out, sin_out,
                                         np.empty(64))
print(json.dumps({"compiled": notice.kernels, "result": (cos_out.tobytes() + sin_out.tobytes()).hex()}))
"""


def test_a_cold_and_a_warm_cache_give_the_same_numbers(tmp_path):
    """The first run compiles into an empty cache, the second loads from it: the kernel
    gives the same bytes either way (and the second compiles nothing)."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path), "PYTHONPATH": str(ROOT)}
    runs = [json.loads(subprocess.run([sys.executable, "-c", CHILD], env=env, check=True,
                                      capture_output=True, text=True).stdout)
            for _ in range(2)]
    assert runs[0]["compiled"] >= 1 and runs[1]["compiled"] == 0
    assert runs[0]["result"] == runs[1]["result"]
    assert np.frombuffer(bytes.fromhex(runs[0]["result"])).size == 2 * 4 * 64
