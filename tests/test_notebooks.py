"""The notebooks run headless: their code cells, in order, in a fresh interpreter."""
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import child_failure, cpu_limited

NOTEBOOKS = sorted((Path(__file__).resolve().parents[1] / "notebooks").glob("*.ipynb"))


def test_there_are_notebooks():
    assert NOTEBOOKS


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_runs_headless(notebook, tmp_path):
    cells = json.loads(notebook.read_text())["cells"]
    code = "\n\n".join("".join(c["source"]) for c in cells if c["cell_type"] == "code")
    script = tmp_path / f"{notebook.stem}.py"
    script.write_text(code)
    run = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True,
                         text=True, env={**os.environ, "MPLBACKEND": "Agg"},
                         preexec_fn=cpu_limited())
    assert run.returncode == 0, child_failure(run)
    assert "Warning" not in run.stderr, run.stderr[-2000:]
    assert sorted(p.name for p in tmp_path.iterdir()) == [script.name]   # writes no file


def test_the_notebooks_write_nothing_into_the_checkout():
    """Running a notebook leaves the checkout clean: no savefig or to_netcdf into a
    relative path (the notebook runs with the notebooks/ folder as its directory)."""
    for notebook in NOTEBOOKS:
        for cell in json.loads(notebook.read_text())["cells"]:
            code = [line for line in cell["source"] if not line.lstrip().startswith("#")]
            assert not any(("savefig(" in line or "to_netcdf(" in line or "write_" in line)
                           for line in code), notebook.name
