"""Stopping rules of adaptive sampling: JCGM 101 7.9 can stop early; ours does not.

The rules are driven with simulated batch values of known spread (normal, as batch
averages of >= 10^4 trials are), so thousands of adaptive runs take milliseconds and the
probability of stopping early is measured, not assumed. "Early" means the true standard
deviation of the average, sigma / sqrt(h), is still above delta / 2 when the rule stops.
"""
import numpy as np
import pytest
import scipy.stats as st

import uq
from uq.engine.stopping import may_stop, upper_bound_factor

SIGMA, DELTA, BATCHES_PER_CHECK, RUNS = 1.0, 0.5, 4, 2000


def early_fraction(rule, rng):
    early = 0
    for _ in range(RUNS):
        values, check = [], 0
        while True:
            values.extend(rng.normal(0.0, SIGMA, BATCHES_PER_CHECK))
            check += 1
            if may_stop(rule, [np.array(values)], np.array(DELTA), check):
                break
        early += 2 * SIGMA / np.sqrt(len(values)) > DELTA
    return early / RUNS


def test_jcgm101_stops_early_and_confident_does_not():
    rng = np.random.default_rng(2024)
    jcgm, confident = early_fraction("jcgm101", rng), early_fraction("confident", rng)
    # 2000 runs: a binomial proportion's standard error is at most sqrt(.25/2000) = 1.1 %.
    assert jcgm > 0.25                      # JCGM 7.9 stops too early in a quarter of runs
    assert confident <= 0.05 + 3 * np.sqrt(0.05 * 0.95 / RUNS)


def test_upper_bound_factor_levels():
    # alpha_1 = 0.025: the 2.5 % chi-square quantile with 7 dof is 1.690 (tables)
    assert upper_bound_factor(8, 1) == pytest.approx(np.sqrt(7 / 1.68987), rel=1e-4)
    assert upper_bound_factor(8, 5) > upper_bound_factor(8, 1) > 1


def test_adaptive_run_records_rule_tolerance_and_samples():
    inputs = {"x1": st.norm(3.0, 0.3), "x2": st.norm(2.0, 0.4)}
    exact = np.sqrt(2**2 * 0.3**2 + 3**2 * 0.4**2 + 0.3**2 * 0.4**2)
    out = uq.propagate(lambda x1, x2: x1 * x2, inputs, digits=2, seed=5, stopping="confident")
    assert out.attrs["stopping_rule"] == "confident"
    assert out.attrs["n_samples"] % 2**16 == 0 and out.attrs["n_samples"] >= 2 * 2**16
    assert float(out["y_mc_numerical_error"]) <= float(out["y_mc_numerical_tolerance"])
    # two significant digits of u: within the tolerance delta (0.005 for u = 1.3)
    assert abs(float(out["y_mc_u"]) - exact) <= float(out["y_mc_numerical_tolerance"])


LINEAR = {"a": st.norm(1.0, 0.1), "b": st.norm(0.2, 0.1)}
PRODUCT = {"a": st.norm(0.1, 1.0), "b": st.norm(0.2, 1.0)}


@pytest.mark.parametrize("seed", range(6))
def test_a_valid_gum_stops_sampling_early(seed):
    """a + b: the GUM is exact, so clause 8 validates it as soon as the endpoints' noise
    allows: about the trials of a plain 2-digit run (2^17-2^18), not the ~25x of the
    delta/5 precision a validation asks for (JCGM 101 8.2) when the GUM is not valid."""
    ds = uq.propagate(lambda a, b: a + b, LINEAR, digits=2, seed=seed, stopping="confident",
                      stop_when_gum_valid=True)
    assert ds.attrs["stopped_by"] == "gum validated"
    assert ds.attrs["n_samples"] <= 2 ** 19
    assert bool(ds["y_gum_valid"])


@pytest.mark.parametrize("seed", range(3))
def test_an_invalid_gum_gets_the_full_validation_precision(seed):
    """a b of two unit normals near zero: the GUM u is 0.22, the true u about 1, so the
    validation can never pass; sampling goes on to delta / 5."""
    plain = uq.propagate(lambda a, b: a * b, PRODUCT, digits=2, seed=seed,
                         stopping="confident")
    ds = uq.propagate(lambda a, b: a * b, PRODUCT, digits=2, seed=seed, stopping="confident",
                      stop_when_gum_valid=True)
    assert ds.attrs["stopped_by"] == "digits" and not bool(ds["y_gum_valid"])
    # a tolerance 5x smaller needs ~25x the trials; 4x leaves room for the batch noise
    assert ds.attrs["n_samples"] >= 4 * plain.attrs["n_samples"]
    assert float(ds["y_mc_numerical_error"]) <= 0.2 * float(ds["y_mc_numerical_tolerance"])


def test_stop_when_gum_valid_needs_adaptive_sampling():
    with pytest.raises(ValueError, match="needs adaptive sampling"):
        uq.propagate(lambda a, b: a + b, LINEAR, n=1000, stop_when_gum_valid=True)
    with pytest.raises(uq.ScenarioError, match="sampling.stop_when_gum_valid: needs adaptive"):
        uq.load_scenario({"name": "x", "sampling": {"n": 1000, "stop_when_gum_valid": True}})


def test_sweep_scene_says_what_stopped_it():
    ds = uq.run(uq.load_scenario({
        "name": "x", "wind": {"speed": 8.0},
        "ins": {"sog": {"dist": "normal", "u": 0.1}, "heading": {"dist": "normal", "u": 0.5}},
        "sampling": {"digits": 2, "stop_when_gum_valid": True, "stopping": "confident"},
        "sweep": {"wind.direction": [0.0, 180.0]}}))   # along the track: GUM valid
    flag = ds["mc_stopped_by"]
    meanings = flag.attrs["flag_meanings"].split()
    assert meanings == ["digits", "gum_validated", "sample_limit", "fixed_n"]
    assert list(flag.attrs["flag_values"]) == [0, 1, 2, 3]
    assert [meanings[v] for v in flag.values] == ["gum_validated"] * 2


def test_gum_validated_needs_the_noise_inside_the_tolerance():
    """|d| + 2 s_e <= delta under jcgm101 (f = 1): batches 0, 1 of the endpoint have
    s_e = sd / sqrt(h) = 0.5 exactly, so 2 s_e = 1."""
    batches = (np.array([[0.0], [1.0]]),) * 2
    small, large = (np.array([0.4]),) * 2, (np.array([0.6]),) * 2
    assert uq.engine.stopping.gum_validated("jcgm101", small, batches, 1.5, check=1)
    assert not uq.engine.stopping.gum_validated("jcgm101", large, batches, 1.5, check=1)
    # confident needs at least CONFIDENT_MIN_BATCHES batches before it decides anything
    assert not uq.engine.stopping.gum_validated("confident", small, batches, 1e9, check=1)
