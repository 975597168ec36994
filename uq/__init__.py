"""Monte Carlo and GUM uncertainty quantification for ship-based and floating wind lidar."""
from .inputs import Input
from .propagate import propagate

__version__ = "0.1.0"

__all__ = ["Input", "propagate", "__version__"]
