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
from uq.stopping import may_stop, upper_bound_factor

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
