"""docs/scenario.md is generated from the validator, and the two cannot drift apart."""
import math
from pathlib import Path

import pytest

from uq.errors import ScenarioError
from uq.pipeline import reference
from uq.pipeline.scenario import DEFAULTS, load_scenario

ROOT = Path(__file__).resolve().parents[2]
ROWS = reference.documented_keys(reference.recorded_checks())


def test_the_shipped_reference_is_what_the_validator_says():
    assert (ROOT / "docs" / "scenario.md").read_text() == reference.render(), \
        "regenerate: python -m uq.pipeline.reference > docs/scenario.md"


def test_every_checked_key_has_a_meaning_and_every_meaning_a_key():
    assert [key for key in ROWS if reference.meaning(key) is None] == []
    patterns = set(reference.MEANINGS)
    used = {p for p in patterns for key in ROWS
            if reference.meaning(key) == reference.MEANINGS[p]}
    assert patterns - used == set()


def test_every_section_is_documented():
    sections = {key.split(".")[0] for key in ROWS}
    assert set(DEFAULTS) - {"sweep"} <= sections


BOUNDED = [(key, kind, limits) for key, (kind, _, limits) in ROWS.items()
           if kind in ("number", "integer") and key.count(".") == 1
           and key.split(".")[0] in ("wind", "ship", "lidar", "sampling")
           and (limits.get("low") is not None or limits.get("high") is not None)]


@pytest.mark.parametrize("key, kind, limits", BOUNDED, ids=[b[0] for b in BOUNDED])
def test_documented_bounds_are_the_enforced_ones(key, kind, limits):
    """Just outside a documented bound is refused naming the key; an open bound itself
    is refused, a closed one accepted."""
    for side, step in (("low", -1), ("high", 1)):
        bound = limits.get(side)
        if bound is None:
            continue
        outside = bound + step if kind == "integer" else bound + step * max(1e-6, abs(bound) * 1e-9)
        with pytest.raises(ScenarioError, match=key.replace(".", r"\.")):
            load_scenario(_with(key, int(outside) if kind == "integer" else outside))
        if limits.get(f"{side}_open"):
            with pytest.raises(ScenarioError, match=key.replace(".", r"\.")):
                load_scenario(_with(key, bound))
        elif math.isfinite(bound) and not (key == "sampling.n" and side == "high"):
            load_scenario(_with(key, int(bound) if kind == "integer" else bound))


def _with(key, value):
    section, name = key.split(".")
    mapping = {section: {name: value}}
    if key == "sampling.digits":
        mapping["sampling"]["method"] = "mc"
    return mapping


def test_bounded_keys_were_found():
    assert {"wind.speed", "wind.shear", "ship.pitch", "lidar.half_cone",
            "sampling.n"} <= {key for key, _, _ in BOUNDED}


def test_each_key_has_its_own_meaning():
    """Issue 27: no sentence shared by several keys (the per-degree-of-freedom rows of
    motion stand for every degree of freedom, one row each)."""
    meanings = {}
    for key in ROWS:
        meanings.setdefault(reference.meaning(key)[1], []).append(key)
    assert {text: keys for text, keys in meanings.items() if len(keys) > 1} == {}


def test_sweep_correlation_time_and_required_keys_are_in_the_table():
    text = reference.render()
    for key in ("sweep", "ins.<error>.correlation_time", "lidar.azimuths"):
        assert f"| `{key}` |" in text
    assert "| `motion.spectrum.hs` | number | m | **required** |" in text
    assert "Every key is optional" not in text
    assert "omega x r is not removed" in text and "Longuet-Higgins" in text


def test_every_key_without_required_is_optional():
    """What the reference calls optional is: the default scenario of the validator
    fills every key whose default is not **required** (an empty scenario is valid)."""
    assert load_scenario({}).settings["lidar"]["azimuths"] == DEFAULTS["lidar"]["azimuths"]
