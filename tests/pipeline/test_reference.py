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


# --- every limit the validator enforces is written beside its key ---------------------
def documented_allowed():
    """Row key -> the 'allowed' column of docs/scenario.md, as a user reads it."""
    rows = {}
    for line in (ROOT / "docs" / "scenario.md").read_text().splitlines():
        cells = [cell.strip() for cell in line.strip("|").split("|")]
        if len(cells) == 6 and cells[0].startswith("`"):
            rows[cells[0].strip("`")] = cells[4]
    return rows


HARMONIC = {"amplitude": 1.0, "period": 8.0}


def _limit_cases(tmp_path):
    """(scenario mapping beyond one limit, the key its message names, the row of
    docs/scenario.md, what that row must say)."""
    from uq.constants import MAX_FIT_DRAWS, MAX_RECORD_SCANS, MAX_SERIES_ROWS
    times = [0.5 * i for i in range(64)]
    (tmp_path / "long.csv").write_text("time,roll\n" + "".join(f"{t},1\n" for t in times))
    turbulent = {"turbulence": {"intensity": 0.1}}
    return [
        ({"lidar": {"ranges": [float(i + 1) for i in range(1001)]}}, "lidar.ranges",
         "lidar.ranges", "at most 1000 gates"),
        ({"lidar": {"azimuths": {"start": 0, "stop": 360, "step": 0.3}}}, "lidar.azimuths",
         "lidar.azimuths", "at most 1000 beams"),
        ({"motion": {"pitch": [HARMONIC] * 257}}, "motion.pitch", "motion.<dof>.amplitude",
         "1 to 256 harmonics"),
        ({"motion": {"pitch": [{**HARMONIC, "amplitude": 45.0}] * 8}}, "motion.pitch",
         "motion.<dof>.amplitude", "at most 45 deg per rotation"),
        ({"ship": {"pitch": 86.0}, "motion": {"pitch": [HARMONIC] * 4}}, "motion.pitch",
         "motion.<dof>.amplitude", "89 with ship.pitch"),
        ({"motion": {"heave": [{**HARMONIC, "amplitude": 600.0}] * 2}}, "motion.heave",
         "motion.<dof>.amplitude", "1000 m per translation"),
        ({"motion": {"spectrum": {"hs": 1e6, "tp": 7.0}, "response": {"roll": {"factor": 2}}}},
         "motion.response.roll.factor", "motion.response.<dof>.factor", "45 deg"),
        ({"motion": {"series": {"file": str(tmp_path / "long.csv"),
                                "columns": {"roll": "roll"}}}},
         "motion.series.file", "motion.series.file", f"{MAX_SERIES_ROWS:,} rows"),
        ({**turbulent, "record": {"duration": 3600}, "lidar": {"scan": {"beam_duration":
                                                                        0.0005}}},
         "record.duration", "record.duration", f"at most {MAX_RECORD_SCANS} scans"),
        ({**turbulent, "record": {"count": 5}, "sampling": {"method": "none"}}, "record.count",
         "record.count", "only with sampling.method mc"),
        ({"sampling": {"method": "none", "n": 1000}}, "sampling.n", "sampling.n",
         "not with sampling.method none"),
        ({"fit": {"walkers": 1024, "ensembles": 64, "max_steps": 1000}}, "fit.max_steps",
         "fit.max_steps", f"at most {MAX_FIT_DRAWS:,}"),
        ({"motion": {"roll": {**HARMONIC, "period": 0.05}}, "ins": {"rate": 10},
          "lidar": {"scan": {"beam_duration": 100.0, "dwell_average": True}}},
         "lidar.scan.beam_duration", "lidar.scan.beam_duration", "at most 512 quadrature"),
        ({"lidar": {"probe": {"kind": "cw", "wavelength": 1.565, "beam_radius": 1.0,
                              "truncation": 0.02}}},
         "lidar.probe.beam_radius", "lidar.probe.beam_radius", "0.25 pi a^2 / lambda"),
        ({"sweep": {"wind.direction": [float(i % 360) for i in range(4000)],
                    "wind.speed": [float(i) for i in range(4000)]}}, "sweep", "sweep",
         "at most 10,000,000 scenes"),
    ]


def test_every_enforced_limit_is_written_beside_its_key(tmp_path, monkeypatch):
    """Each input beyond a limit is refused naming a key, and the row of that key in
    docs/scenario.md states the limit (the 2,000,000 rows of a motion record were
    enforced and documented nowhere). The motion record's row limit is lowered here to
    refuse a small file; the row states the real one."""
    from uq.errors import InputError
    from uq.pipeline import motionsection
    monkeypatch.setattr(motionsection, "MAX_SERIES_ROWS", 32)
    allowed = documented_allowed()
    for changes, key, row, said in _limit_cases(tmp_path):
        with pytest.raises(InputError) as refused:
            load_scenario({"name": "limits", **changes})
        assert refused.value.key == key, (key, str(refused.value))
        assert said in allowed[row], (row, said, allowed[row])
