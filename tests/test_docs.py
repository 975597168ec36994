"""The README and the user guide are checked like code: the guide builds with warnings as
errors (its notebooks executed), every link resolves, the generated references list every
option and key, the README is short, its tables are what their commands give and its
figures what the figure script made, and no user-facing file carries internal
bookkeeping (issue numbers, session words, commit hashes)."""
import argparse
import importlib.util
import json
import hashlib
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import child_failure, cpu_limited

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
README = ROOT / "README.md"
#: The longest README a newcomer reads in five minutes.
README_MAX_LINES = 250
#: The notebooks, one per kind of user (and the mast example).
NOTEBOOKS = ("validate_gum", "campaign_planning", "floating_lidar_ti", "nacelle_floating",
             "golden_lidar", "mast_shear")


def _module(path, name):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


uqdocs = _module(DOCS / "_ext" / "uqdocs.py", "uqdocs")
figures = _module(ROOT / "scripts" / "docs_figures.py", "docs_figures")


def guide_pages():
    """The guide's own Markdown pages (not the build, nor the copied notebooks)."""
    return sorted(p for p in DOCS.rglob("*.md")
                  if "_build" not in p.parts and "notebooks" not in p.parts)


def user_facing_files():
    """What a user reads: the README, the changelog, the guide's pages, the notebooks."""
    return [README, ROOT / "CHANGELOG.md", *guide_pages(),
            *sorted((ROOT / "notebooks").glob("*.ipynb")), ROOT / "notebooks" / "README.md"]


# --- the README ---------------------------------------------------------------------------
def test_the_readme_is_short():
    assert len(README.read_text().splitlines()) <= README_MAX_LINES


def test_the_readme_starts_with_the_two_commands_in_separate_environments():
    text = README.read_text()
    block = text[text.index("```bash") + len("```bash"):].split("```")[0].strip().splitlines()
    assert len(block) == 2
    first, second = block
    assert "uq run" in first and "pytest" in second
    environment = re.compile(r"python3 -m venv (\S+)")
    assert environment.search(first).group(1) != environment.search(second).group(1)
    assert ".ci/run" in text


def test_the_quick_start_has_the_five_commands():
    text = README.read_text()
    quick = text[text.index("## Quick start"):].split("```")[1]
    commands = [line.split()[1] for line in quick.splitlines() if line.startswith("uq ")]
    assert commands == ["list", "run", "report", "export", "plot"]
    assert "--set" in quick


#: A bookkeeping word of the developers: an issue number, a session word, a commit hash
#: (7-40 hex digits with at least one digit and one letter).
BOOKKEEPING = re.compile(r"\bissues? #?\d+|\bthis (round|session)\b|\blast round\b|"
                         r"\bround \d+\b|\bitem \d+\b|"
                         r"\b(?=[0-9a-f]*\d)(?=[0-9a-f]*[a-f])[0-9a-f]{7,40}\b", re.I)


def _prose(path):
    """A file's text as a user reads it (a notebook's cells and outputs)."""
    if path.suffix != ".ipynb":
        return path.read_text()
    cells = json.loads(path.read_text())["cells"]
    return "\n".join("".join(cell["source"]) for cell in cells)


@pytest.mark.parametrize("path", user_facing_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_no_internal_bookkeeping_in_user_facing_files(path):
    found = [match.group(0) for match in BOOKKEEPING.finditer(_prose(path))]
    assert found == [], f"{path.relative_to(ROOT)}: {found}"


def test_the_bookkeeping_check_catches_what_it_is_for():
    for text in ("as in issue 26", "this round", "main at 7a033f7", "(issue 24, item 3)"):
        assert BOOKKEEPING.search(text), text
    for text in ("JCGM 101 clause 8", "IEC 61400-12-1", "a decade", "2026-11-25",
                 "a session of measurements", "10^5 trials"):
        assert not BOOKKEEPING.search(text), text


_LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")


def _local_links(path):
    for target in _LINK.findall(path.read_text()):
        if re.match(r"[a-z]+:", target) or target.startswith("#"):
            continue
        yield target.split("#")[0]


@pytest.mark.parametrize("path", [README, *guide_pages()],
                         ids=lambda p: str(p.relative_to(ROOT)))
def test_every_local_link_resolves(path):
    missing = []
    for target in _local_links(path):
        resolved = (path.parent / target).resolve()
        if target.startswith("notebooks/") or "/notebooks/" in target:
            # a notebook page of the guide: the notebook itself in notebooks/
            resolved = ROOT / "notebooks" / Path(target).name
        if not resolved.exists():
            missing.append(target)
    assert missing == [], f"{path.relative_to(ROOT)}: {missing}"


def test_every_readme_figure_is_the_one_its_commands_made():
    """Each README figure is made by scripts/docs_figures.py from the commands it
    records in docs/figures.json, and the file is the one it made (SHA-256)."""
    manifest = json.loads((DOCS / "figures.json").read_text())
    shown = re.findall(r"!\[[^\]]*\]\(docs/([^)]+\.png)\)", README.read_text())
    assert shown
    for name in shown:
        assert name in figures.PLOTTED, f"{name}: no command in scripts/docs_figures.py makes it"
        assert name in manifest, f"{name}: run python scripts/docs_figures.py --only {name}"
        digest = hashlib.sha256((DOCS / name).read_bytes()).hexdigest()
        assert digest == manifest[name]["sha256"], \
            f"docs/{name} is not the figure its commands made: python scripts/docs_figures.py"
        made_by = [" ".join(["uq", *c]) for run in figures.PLOTTED[name][0]
                   for c in figures.RUNS[run]]
        assert manifest[name]["commands"][:len(made_by)] == made_by


def test_every_readme_table_is_generated():
    """Every table of numbers in the README lies between the markers of a table that
    scripts/docs_figures.py writes (the command table of the quick start has none)."""
    text = README.read_text()
    outside = figures.BLOCK.sub("", text)
    numeric_rows = [line for line in outside.splitlines()
                    if line.startswith("|") and re.search(r"\d\.\d", line)]
    assert numeric_rows == []
    assert set(figures.readme_tables(text)) == set(figures.TABLES) | {"speed"}


#: A time or a memory size: a number with its unit.
_MEASURE = re.compile(r"\b\d+(\.\d+)?(-\d+(\.\d+)?)? ?(s|ms|min|MB|GB|GiB)\b")
_MEASURED = re.compile(r"<!-- measured: (?P<what>.*?) -->\n(?P<body>.*?)<!-- end measured -->",
                       re.S)


def test_readme_times_are_marked_with_machine_and_date():
    text = README.read_text()
    for block in _MEASURED.finditer(text):
        assert re.search(r"\d+-core|\d+ cores", block.group("what")), block.group("what")
        assert re.search(r"\d{4}-\d{2}-\d{2}", block.group("body")), "no date"
        assert "load" in block.group("body") or "idle" in block.group("body")
    outside = _MEASURED.sub("", figures.BLOCK.sub("", text))
    outside = re.sub(r"```.*?```", "", outside, flags=re.S)        # commands' comments
    unmarked = [m.group(0) for m in _MEASURE.finditer(outside)]
    # a wave period or a beam's dwell is an input of a scenario, not a measurement
    unmarked = [u for u in unmarked if u not in ("25 s", "8 s", "7 s", "1 s")]
    assert unmarked == []


_NUMBER = re.compile(r"[+-]?\d+(?:\.\d+)?")


def _same_numbers(written, computed, tolerances=None):
    """The two texts say the same, numbers within one unit of the written last digit
    (the Monte Carlo values' last digit may differ between platforms' libm), or within
    `tolerances` (absolute, one per number of `computed` in order; None: the last digit)."""
    assert _NUMBER.sub("#", written) == _NUMBER.sub("#", computed), (written, computed)
    numbers = list(zip(_NUMBER.findall(written), _NUMBER.findall(computed)))
    tolerances = tolerances or [None] * len(numbers)
    assert len(tolerances) == len(numbers), (len(tolerances), len(numbers))
    for (a, b), tolerance in zip(numbers, tolerances):
        decimals = len(a.split(".")[1]) if "." in a else 0
        if tolerance is None:
            tolerance = 1.01 * 10.0 ** -decimals
        assert math.isclose(float(a), float(b), abs_tol=tolerance), (a, b, tolerance)


@pytest.mark.parametrize("name", sorted(figures.TABLES))
def test_readme_table_is_what_its_commands_give(name, tmp_path):
    runs, render = figures.TABLES[name]
    for run in runs:
        for command in figures.RUNS[run]:
            result = subprocess.run([sys.executable, "-m", "uq.cli", *command, "-q"],
                                    cwd=tmp_path, capture_output=True, text=True,
                                    preexec_fn=cpu_limited())
            assert result.returncode == 0, child_failure(result)
    written = figures.readme_tables(README.read_text())[name].strip()
    assert written, f"empty README table {name}: python scripts/docs_figures.py"
    try:
        tolerances = figures.TOLERANCES.get(name)
        _same_numbers(written, render(tmp_path).strip(),
                      tolerances(tmp_path) if tolerances else None)
    except AssertionError as error:
        raise AssertionError(f"README table {name} is not what its commands give now: "
                             f"python scripts/docs_figures.py --only {name}\n{error}") from None


def test_readme_speed_table_is_the_shipped_bench_result():
    """The README's speed table is what the guide's benchmark file (one ``uq bench``
    run) gives, exactly: python scripts/docs_figures.py --only speed."""
    written = figures.readme_tables(README.read_text())["speed"].strip()
    assert written == figures.table_speed().strip(), \
        "python scripts/docs_figures.py --only speed"


def test_the_number_comparison_fails_on_a_changed_number():
    _same_numbers("| a | 0.0453 |", "| a | 0.0454 |")
    _same_numbers("| a | 9.072 | 9 |", "| a | 9.065 | 9 |", [0.008, None])
    with pytest.raises(AssertionError):                          # beyond its tolerance
        _same_numbers("| a | 9.072 | 9 |", "| a | 9.062 | 9 |", [0.008, None])
    with pytest.raises(AssertionError):                          # the last digit's
        _same_numbers("| a | 9.072 | 9 |", "| a | 9.072 | 7 |", [0.008, None])
    with pytest.raises(AssertionError):
        _same_numbers("| a | 0.0453 |", "| a | 0.0456 |")
    with pytest.raises(AssertionError):
        _same_numbers("| a | 0.0453 |", "| b | 0.0453 |")


# --- generated references --------------------------------------------------------------
def test_the_cli_reference_lists_every_command_and_option():
    from uq.cli import build_parser
    page = uqdocs.cli_reference()
    for name, sub, _ in uqdocs._subcommands(build_parser()):
        assert f"## `uq {name}`" in page
        for action in sub._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            for flag in action.option_strings:
                assert f"`{flag}" in page, (name, flag)


def test_a_new_option_appears_in_the_cli_reference_without_editing_the_guide():
    from uq.cli import build_parser
    parser = build_parser()
    for name, sub, _ in uqdocs._subcommands(parser):
        if name == "run":
            sub.add_argument("--brand-new-option", metavar="X", help="a new option's help")
    page = uqdocs.cli_reference(parser)
    assert "`--brand-new-option X`" in page and "a new option's help" in page


def test_the_scenario_reference_is_the_validators(monkeypatch):
    from uq.pipeline import reference
    page = uqdocs.scenario_reference()
    assert reference.render() in page
    for key in reference.documented_keys(reference.recorded_checks()):
        assert f"`{key}`" in page, key
    monkeypatch.setattr(reference, "render", lambda: "| `wind.brand_new_key` | ... |")
    assert "`wind.brand_new_key`" in uqdocs.scenario_reference()


def test_the_guide_pages_that_are_generated_are_stubs():
    for docname in ("reference/cli", "reference/scenario", "performance"):
        text = (DOCS / f"{docname}.md").read_text()
        assert text.startswith(uqdocs.GENERATED_NOTICE) and len(text.splitlines()) < 10


def test_the_performance_page_is_read_from_a_bench_file(tmp_path):
    from uq.bench.targets import TARGETS
    page = uqdocs.performance_page(DOCS / "data" / "bench.nc")
    result = uqdocs.read_bench(DOCS / "data" / "bench.nc")
    assert result.machine != "not recorded" and result.load != "not recorded"
    assert result.machine in page and result.load in page and result.date in page
    for name in TARGETS:                         # a row for each target measured
        assert (f"| `{name}` |" in page) == (name in result.figures), name
    # another format: a reader per suffix
    other = tmp_path / "bench.json"
    other.write_text(json.dumps({"figures": {"sweep_mc_over_draw_floor": 2.25},
                                 "machine": "16 cores", "load_average": "0.1",
                                 "measured_at": "2030-01-01", "command": "uq bench"}))
    page = uqdocs.performance_page(other)
    assert "| `sweep_mc_over_draw_floor` | 2.25 | ≤ 2.5 | yes |" in page and "16 cores" in page


def test_the_performance_page_tables_every_first_run(tmp_path):
    """Each scenario's first run is a row of the bench's own figures, the largest
    difference first; a repeated one shows its pairs' range; the row's figures are not
    listed again below."""
    figures = {"first_run_a_s": 4.0, "warm_run_a_s": 3.5, "first_run_a_over_warm_s": 0.5,
               "first_run_a_pairs": 1, "first_run_a_over_warm_min_s": 0.5,
               "first_run_a_over_warm_max_s": 0.5, "first_run_a_largest_difference": 1e-14,
               "first_run_a_warm_compiled": 1,
               "first_run_b_s": 30.0, "warm_run_b_s": 27.0, "first_run_b_over_warm_s": 3.0,
               "first_run_b_pairs": 3, "first_run_b_over_warm_min_s": -1.0,
               "first_run_b_over_warm_max_s": 9.0, "first_run_b_load": 0.4,
               "first_run_worst_over_warm_s": 3.0}
    path = tmp_path / "bench.json"
    path.write_text(json.dumps({"figures": figures, "machine": "2 cores"}))
    page = uqdocs.performance_page(path)
    table = page[page.index("## First runs"):page.index("## Every other")]
    rows = [line for line in table.splitlines() if line.startswith("| `")]
    assert rows == ["| `b` | 30.0 | 27.0 | +3.0 | 3 (-1.0 to +9.0) | - | - |",
                    "| `a` | 4.0 | 3.5 | +0.5 | 1 | 1e-14 | yes |"]
    rest = page[page.index("## Every other"):]
    assert "`first_run_b_load`" in rest and "`first_run_a_s`" not in rest


def test_the_validation_page_names_tests_that_exist():
    text = (DOCS / "validation.md").read_text()
    named = set(re.findall(r"`(tests/[\w/]+\.py)`", text))
    assert len(named) > 20
    assert [n for n in sorted(named) if not (ROOT / n).is_file()] == []


def test_every_test_file_a_guide_page_names_exists():
    missing = []
    for page in guide_pages():
        for name in re.findall(r"`(tests/[\w/]+\.py)", page.read_text()):
            if not (ROOT / name).is_file():
                missing.append((page.name, name))
    assert missing == []


def test_one_notebook_per_kind_of_user():
    assert {p.stem for p in (ROOT / "notebooks").glob("*.ipynb")} == set(NOTEBOOKS)
    index = (DOCS / "index.md").read_text()
    for name in NOTEBOOKS:
        assert f"notebooks/{name}" in index


def test_the_getting_started_python_runs(tmp_path):
    """The Python example of the guide's getting-started page, as written, from the
    project's root (its paths are the shipped scenarios')."""
    text = (DOCS / "getting-started.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert blocks
    script = tmp_path / "example.py"
    script.write_text("\n".join(blocks))
    result = subprocess.run([sys.executable, str(script)], cwd=ROOT, capture_output=True,
                            text=True, preexec_fn=cpu_limited())
    assert result.returncode == 0, child_failure(result)


# --- the guide builds --------------------------------------------------------------------
def test_the_guide_builds_with_warnings_as_errors(tmp_path):
    """sphinx-build -W: every cross-reference, image, toctree entry and docstring must
    be right; the notebooks are executed against the installed package (a failing cell
    fails the build); the generated pages come from the code."""
    result = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
         "-d", str(tmp_path / "doctrees"), str(DOCS), str(tmp_path / "html")],
        cwd=ROOT, capture_output=True, text=True, preexec_fn=cpu_limited(),
        env={**{k: v for k, v in os.environ.items() if k != "MPLBACKEND"},   # inline figures
             "UQ_DOCS_EXECUTE": "force"})
    assert result.returncode == 0, child_failure(result)
    html = tmp_path / "html"
    for page in ("reference/cli.html", "reference/scenario.html", "performance.html",
                 *(f"notebooks/{n}.html" for n in NOTEBOOKS)):
        assert (html / page).is_file(), page
    built = (html / "reference" / "cli.html").read_text()
    assert "--set" in built and "uq golden" in built
    for name in NOTEBOOKS:                       # executed: outputs are in the pages
        assert "cell_output" in (html / "notebooks" / f"{name}.html").read_text(), name
