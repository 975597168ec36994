"""Shared helpers for the tests."""
import numpy as np
import pytest

from uq.pipeline.runner import scene_from_settings
from uq.pipeline.scenario import load_scenario


def make_scene(**changes):
    """A Scene from the default scenario with dotted-key changes (degrees, as in YAML)."""
    return scene_from_settings(load_scenario({"name": "test", **_nest(changes)}).settings)


def _nest(changes):
    out = {}
    for dotted, value in changes.items():
        node = out
        parts = dotted.split(".")
        for part in parts[:-1]:
            node = node.setdefault(part, {})
        node[parts[-1]] = value
    return out


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
