"""``uq run --device gpu`` without CuPy or a GPU: exit 2, one line, nothing written."""
import importlib.util

import pytest

from uq.cli import main


@pytest.mark.skipif(importlib.util.find_spec("cupy") is not None,
                    reason="CuPy is installed: the refusal path needs a machine without it")
def test_gpu_without_cupy_exits_2_with_one_line(tmp_path, capsys):
    scenario = tmp_path / "ti.yaml"
    scenario.write_text("turbulence: {intensity: 0.1}\nsampling: {method: none}\n")
    output = tmp_path / "out.nc"
    status = main(["run", str(scenario), "-o", str(output), "--device", "gpu"])
    error = capsys.readouterr().err.strip()
    assert status == 2 and not output.exists()
    assert len(error.splitlines()) == 1 and "--device" in error and "CuPy" in error
