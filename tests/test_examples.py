"""The ``Examples`` sections of the public functions run as written (doctest)."""
import doctest
import importlib

import pytest

#: Modules whose docstrings carry runnable examples.
MODULES = ("uq.engine.propagate", "uq.engine.inputs", "uq.physics.wind",
           "uq.physics.correction", "uq.pipeline.modelsetup", "uq.physics.kernelbase",
           "uq.physics.scangeometry")


@pytest.mark.parametrize("name", MODULES)
def test_examples_run(name):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0, f"{name} has no example"
    assert result.failed == 0
