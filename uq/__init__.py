"""Monte Carlo and GUM uncertainty quantification for ship-based and floating wind lidar.

Public API (``docs/scenario.md`` and the README): :func:`load_scenario`, :func:`run`,
:func:`propagate`, :class:`Input`, the module :mod:`uq.complexstep` and the error
:class:`ScenarioError`.

The package face is lazy: ``import uq`` loads none of numpy's heavier companions
(scipy.stats, xarray, pandas, matplotlib, numba); each name is imported on first use.
The layers, lowest first: :mod:`uq.physics` and :mod:`uq.engine` (independent of each
other), :mod:`uq.pipeline`, :mod:`uq.outputs`, the wings :mod:`uq.fit`,
:mod:`uq.golden` and :mod:`uq.bench`, and the command line :mod:`uq.cli`; below them
all the base modules :mod:`uq.constants`, :mod:`uq.errors`, :mod:`uq.files`,
:mod:`uq.numbacache` and :mod:`uq.complexstep`. No module imports this face.
"""
import importlib

from uq import interrupts

interrupts.hold_while_starting()  # the command: a Ctrl-C while importing, one line (first)

from uq import numbacache  # noqa: E402
from uq._version import __version__  # noqa: E402

numbacache.configure()          # before any kernel is compiled (a read-only install)

#: Public name -> (module, attribute); attribute None means the module itself.
_PUBLIC = {
    "run": ("uq.pipeline.runner", "run"),
    "load_scenario": ("uq.pipeline.scenario", "load_scenario"),
    "propagate": ("uq.engine.propagate", "propagate"),
    "Input": ("uq.engine.inputs", "Input"),
    "complexstep": ("uq.complexstep", None),
    "ScenarioError": ("uq.errors", "ScenarioError"),
    "InputError": ("uq.errors", "InputError"),
}

__all__ = sorted(_PUBLIC) + ["__version__"]


def __getattr__(name):
    """Import a public name on first use (PEP 562)."""
    if name not in _PUBLIC:
        raise AttributeError(f"module 'uq' has no attribute {name!r}")
    module, attribute = _PUBLIC[name]
    value = importlib.import_module(module)
    value = value if attribute is None else getattr(value, attribute)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_PUBLIC))
