"""Monte Carlo and GUM uncertainty quantification for ship-based and floating wind lidar.

Public API (CONTRACT.md): :func:`load_scenario`, :func:`run`, :func:`propagate`.
"""
__version__ = "0.1.0"

from . import complexstep  # noqa: E402
from .errors import ScenarioError  # noqa: E402
from .inputs import Input  # noqa: E402
from .pipeline import run  # noqa: E402
from .propagate import propagate  # noqa: E402
from .scenario import load_scenario  # noqa: E402

__all__ = ["Input", "ScenarioError", "load_scenario", "propagate", "run", "__version__"]
