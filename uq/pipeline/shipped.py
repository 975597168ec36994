"""The scenarios shipped with uq, wherever it is installed, and the names a command line
takes for them.

They live in the repository's top-level ``scenarios/`` folder and are installed with
the package as ``uq.shipped`` (``pyproject.toml``), so ``uq run rubio2022_case_i`` and
``uq bench`` work from an installed wheel in any directory. ``uq plot NAME``, ``uq report
NAME`` and ``uq export NAME`` take the name of a run and read ``results/NAME.nc``. A name
that is neither a file nor a shipped scenario is refused with the closest names ("did you
mean", :func:`closest`).
"""
import difflib
import importlib.resources
from pathlib import Path

from uq.errors import DataFileError, ScenarioError

SUFFIX = ".yaml"
#: Folder where ``uq run`` writes ``NAME.nc`` by default, relative to the working directory.
RESULTS_FOLDER = Path("results")
#: How similar a name must be to be offered as "did you mean" (difflib's ratio, 0-1; its
#: own default, which takes a one-letter slip in a name of 5 letters and more).
SIMILAR = 0.6


def shipped_folder():
    """The folder of the installed shipped scenarios."""
    return Path(str(importlib.resources.files("uq.shipped")))


def shipped_names():
    """Names of the shipped scenarios (file stems), sorted."""
    return sorted(path.stem for path in shipped_folder().glob(f"*{SUFFIX}"))


def shipped_command(name):
    """The ``uq`` command that runs the shipped file `name`: ``golden`` for a golden-lidar
    configuration (a top-level ``golden`` section), ``campaign`` for a campaign
    configuration (``campaign``), else ``run`` (a scenario)."""
    import yaml
    raw = yaml.safe_load(shipped_path(name).read_text()) or {}
    return next((kind for kind in ("golden", "campaign") if kind in raw), "run")


def shipped_path(name):
    """Path of the shipped scenario `name` (with or without ``.yaml``)."""
    return shipped_folder() / (name if name.endswith(SUFFIX) else name + SUFFIX)


#: Names offered besides the closest one: those within this much of its similarity [1].
TIE = 0.05


def closest(name, names):
    """The names of `names` most like `name` (difflib's ratio of at least SIMILAR): the
    closest, and any within TIE of it; best first, at most three."""
    scored = sorted(((difflib.SequenceMatcher(None, name, other).ratio(), other)
                     for other in names), key=lambda pair: -pair[0])
    best = scored[0][0] if scored else 0.0
    return [other for ratio, other in scored[:3] if ratio >= max(SIMILAR, best - TIE)]


def did_you_mean(name, names):
    """``" (did you mean 'x'?)"`` for the names most like `name`, or ``""``."""
    close = closest(name, names)
    return f" (did you mean {' or '.join(repr(c) for c in close)}?)" if close else ""


def _is_a_name(argument):
    """Is the command-line `argument` a bare name (no folder), which may name a shipped
    scenario or a run, rather than a path?"""
    return Path(argument).name == str(argument) and str(argument) not in ("", ".", "..")


def scenario_path(argument):
    """The file a command-line scenario argument names: an existing path as given, else
    a shipped scenario of that name. A bare name that is neither is refused
    (ScenarioError) with the closest shipped names; any other path is returned as it is
    (its reader then says that it cannot be read)."""
    path = Path(argument)
    if path.exists() or not _is_a_name(argument):
        return path
    shipped = shipped_path(str(argument))
    if shipped.is_file():
        return shipped
    stem = str(argument)[:-len(SUFFIX)] if str(argument).endswith(SUFFIX) else str(argument)
    raise ScenarioError(str(argument), "", "no such file and no shipped scenario of that name"
                        f"{did_you_mean(stem, shipped_names())}; allowed: a YAML file or "
                        "the name of a shipped scenario ('uq list' shows them)")


def results_path(argument):
    """The results file a command-line argument names: an existing path as given, else
    ``results/NAME.nc`` for a bare name NAME (what ``uq run NAME`` writes). A bare name
    without results is refused (DataFileError) with the closest names of the runs in
    ``results/`` and of the shipped scenarios; any other path is returned as it is."""
    path = Path(argument)
    if path.exists() or not _is_a_name(argument):
        return path
    stem = path.stem if path.suffix == ".nc" else str(argument)
    run = RESULTS_FOLDER / f"{stem}.nc"
    if run.is_file():
        return run
    runs = sorted(p.stem for p in RESULTS_FOLDER.glob("*.nc")) if RESULTS_FOLDER.is_dir() \
        else []
    hint = "run it first ('uq run NAME' writes results/NAME.nc)" if stem in shipped_names() \
        else f"a results file or the name of a run in {RESULTS_FOLDER}/"
    raise DataFileError(str(argument), "", f"no such file and no {run}"
                        f"{did_you_mean(stem, sorted(set(runs) | set(shipped_names())))}; "
                        f"allowed: {hint}")


def describe(path):
    """One line about the scenario at `path`: its ``description`` (or the golden or
    campaign section's), white space collapsed; '' when it has none."""
    from uq.pipeline.yamlfile import read_yaml
    raw = read_yaml(path)
    if not isinstance(raw, dict):
        return ""
    text = raw.get("description") or (raw.get("golden") or {}).get("description") or \
        (raw.get("campaign") or {}).get("description") or ""
    return " ".join(str(text).split())
