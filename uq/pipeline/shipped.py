"""The scenarios shipped with uq, wherever it is installed.

They live in the repository's top-level ``scenarios/`` folder and are installed with
the package as ``uq.shipped`` (``pyproject.toml``), so ``uq run rubio2022_case_i`` and
``uq bench`` work from an installed wheel in any directory.
"""
import importlib.resources
from pathlib import Path

SUFFIX = ".yaml"


def shipped_folder():
    """The folder of the installed shipped scenarios."""
    return Path(str(importlib.resources.files("uq.shipped")))


def shipped_names():
    """Names of the shipped scenarios (file stems), sorted."""
    return sorted(path.stem for path in shipped_folder().glob(f"*{SUFFIX}"))


def shipped_path(name):
    """Path of the shipped scenario `name` (with or without ``.yaml``)."""
    return shipped_folder() / (name if name.endswith(SUFFIX) else name + SUFFIX)


def scenario_path(argument):
    """The file a command-line scenario argument names: an existing path as given, else
    a shipped scenario of that name, else the argument (whose reader then says that it
    cannot be read)."""
    path = Path(argument)
    if path.exists() or path.name != str(argument):
        return path
    shipped = shipped_path(str(argument))
    return shipped if shipped.is_file() else path
