"""``uq run --device gpu``: refused before any work (exit 2, one line naming the flag and
why), whether CuPy and a GPU are there or not: no run of this version makes its boxes on a
GPU, and a flag that warned and ran on the CPU would not do what it says."""
import pytest

from uq.cli import main


@pytest.mark.parametrize("text", [
    "turbulence: {intensity: 0.1}\nsampling: {method: none}\n",      # record mode
    "sampling: {n: 100}\n",                                           # no box at all
])
def test_gpu_is_refused_with_one_line(tmp_path, capsys, text):
    scenario = tmp_path / "s.yaml"
    scenario.write_text(text)
    output = tmp_path / "out.nc"
    status = main(["run", str(scenario), "-o", str(output), "--device", "gpu"])
    error = capsys.readouterr().err.strip()
    assert status == 2 and not output.exists()
    assert len(error.splitlines()) == 1 and "--device" in error and "CPU only" in error
    assert "allowed: --device cpu" in error


def test_cpu_runs(tmp_path):
    scenario = tmp_path / "s.yaml"
    scenario.write_text("sampling: {n: 100}\n")
    assert main(["run", str(scenario), "-q", "-o", str(tmp_path / "o.nc"),
                 "--device", "cpu"]) == 0
