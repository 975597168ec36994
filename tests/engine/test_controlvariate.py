"""The GUM linearisation as control variate, and honest error estimates of every sampler.

Reference: y = x1 x2 with independent normal inputs has the exact variance
mu2^2 s1^2 + mu1^2 s2^2 + s1^2 s2^2 (Goodman 1960), which the first-order GUM misses by
the last term: a model with a known non-linear remainder.
"""
import numpy as np
import pytest
import scipy.stats as st

import uq

MU1, S1, MU2, S2 = 3.0, 0.3, 2.0, 0.4
INPUTS = {"x1": st.norm(MU1, S1), "x2": st.norm(MU2, S2)}
EXACT_U = np.sqrt(MU2**2 * S1**2 + MU1**2 * S2**2 + S1**2 * S2**2)
N = 2**18
SEEDS = range(24)


def product(x1, x2):
    return x1 * x2


def test_linear_model_is_exact_with_the_control_variate():
    """For a linear model Y = L + const: S^2(Y) - S^2(L) = 0 up to rounding, so u is u_GUM
    whatever the draws (relative 1e-12: sums of 2^17 squares in double precision)."""
    out = uq.propagate(lambda x1, x2: 2 * x1 - 3 * x2, INPUTS, n=2**17, seed=1,
                       control_variate=True)
    assert float(out["y_mc_u"]) == pytest.approx(np.hypot(2 * S1, 3 * S2), rel=1e-12)
    assert float(out["y_mc_mean"]) == pytest.approx(2 * MU1 - 3 * MU2, rel=1e-12)
    assert float(out["y_mc_u_standard_error"]) < 1e-12


@pytest.fixture(scope="module")
def replicates():
    runs = {}
    for method in ("mc", "lhs", "sobol"):
        for cv in (False, True):
            results = [uq.propagate(product, INPUTS, n=N, seed=s, method=method,
                                    control_variate=cv) for s in SEEDS]
            runs[method, cv] = (np.array([float(r["y_mc_u"]) for r in results]),
                                np.array([float(r["y_mc_u_standard_error"]) for r in results]))
    return runs


@pytest.mark.parametrize("method", ["mc", "lhs", "sobol"])
@pytest.mark.parametrize("cv", [False, True])
def test_reported_standard_error_is_honest(replicates, method, cv):
    """Over 24 independent seeds, the observed spread of u matches the reported standard
    error. The sample std of 24 values has a relative error of 1/sqrt(46) = 15 %; the
    reported error is itself estimated from 4 (lhs, sobol: blocks) to 16 batches, which
    scatters it by up to 1/sqrt(6) = 40 %; a factor 2.5 either way is > 2 sigma of both."""
    u, error = replicates[method, cv]
    ratio = np.std(u - EXACT_U, ddof=1) / np.sqrt(np.mean(error**2))
    assert 1 / 2.5 < ratio < 2.5, ratio
    # and unbiased: the mean of 24 runs lies within 4 standard errors of the exact u
    assert abs(np.mean(u) - EXACT_U) < 4 * np.std(u, ddof=1) / np.sqrt(len(u)) + 1e-12


def test_control_variate_and_sobol_reduce_the_error(replicates):
    """Same trials, smaller error: the control variate removes the linear part's noise
    (here 4x, the remainder s1 s2 x1' x2' being a sizeable part of this model), and
    randomised Sobol' converges faster than 1/sqrt(N) (here > 50x)."""
    spread = {key: np.std(u - EXACT_U, ddof=1) for key, (u, _) in replicates.items()}
    assert spread["mc", False] / spread["mc", True] > 3
    assert spread["mc", False] / spread["sobol", False] > 50


def test_pipeline_accepts_the_control_variate():
    scenario = {"name": "cv", "ins": {"heading": {"dist": "normal", "u": 0.5},
                                      "sog": {"dist": "normal", "u": 0.1}},
                "ship": {"sog": 3.0}, "correction": "yaw",
                "sampling": {"n": 2**17, "seed": 3, "control_variate": True}}
    result = uq.run(scenario)
    plain = uq.run({**scenario, "sampling": {"n": 2**17, "seed": 3}})
    assert result.attrs["sampling_method"] == "mc"
    assert float(result["wind_speed_mc_u_standard_error"]) < \
        float(plain["wind_speed_mc_u_standard_error"]) / 5
    # both estimate the same u: within 4 combined standard errors
    difference = float(result["wind_speed_mc_u"] - plain["wind_speed_mc_u"])
    assert abs(difference) < 4 * float(plain["wind_speed_mc_u_standard_error"])


def test_control_variate_without_a_jacobian_is_refused():
    """A model that rejects complex input has no GUM, so no control variate: a clear error,
    not NaN results."""
    def not_complex_safe(x1, x2):
        return np.floor(x1) + x1 * x2          # floor rejects complex input
    with pytest.raises(ValueError, match="control variate needs the GUM Jacobian"):
        uq.propagate(not_complex_safe, INPUTS, n=2**10, seed=1, control_variate=True)
