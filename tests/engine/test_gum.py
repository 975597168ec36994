"""Clause 8 validation of the GUM (uq.engine.gum) at the edges of its meaning."""
import logging

import numpy as np
import pytest
import scipy.stats as st

import uq
from uq.engine import gum

K95 = st.norm.ppf(0.975)        # the GUM's coverage factor at 95 %


def test_a_gum_interval_longer_than_the_circle_is_never_valid():
    """Wrapped modulo 360 deg, the endpoints of a 2 k u >= 360 deg interval can land
    exactly on Monte Carlo's: such a GUM cannot be validated."""
    u = 200.0                                   # 2 k u = 784 deg
    low, high = np.mod(0 - K95 * u, 360), np.mod(K95 * u, 360)   # the wrapped GUM ends
    assert gum.endpoint_differences(0.0, u, low, high, circular=True) == (0.0, 0.0)
    assert not gum.gum_interval_valid(0.0, u, low, high, digits=2, circular=True)
    just_inside = 359.0 / (2 * K95)
    assert gum.gum_interval_valid(0.0, just_inside, -K95 * just_inside, K95 * just_inside,
                                  digits=2, circular=True)


@pytest.mark.parametrize("speed", [1e-9, 0.0])
def test_the_direction_of_no_wind_is_not_validated(speed):
    """At 1e-9 m/s the direction's GUM u is ~2e8 deg (and 3e14 at 0): clause 8 must not
    call it valid, whatever Monte Carlo's wrapped endpoints are."""
    ds = uq.run({"wind": {"speed": speed}, "ship": {"sog": 2.0},
                 "ins": {"heading": {"dist": "normal", "u": 0.1},
                         "sog": {"dist": "normal", "u": 0.1}},
                 "sampling": {"n": 2000, "seed": 1}})
    assert float(ds["wind_direction_gum_u"]) > 1e6
    assert not bool(ds["wind_direction_gum_valid"])


def test_moments_that_overflow_are_reported(caplog):
    with caplog.at_level(logging.WARNING, logger="uq.engine.propagate"):
        ds = uq.propagate(lambda a: a * 1e200, {"a": st.norm(1, 1)}, n=2000, seed=1)
    assert not np.isfinite(ds["y_mc_u"]).any() and "overflowed" in caplog.text


def test_outside_the_domain_at_the_means_the_gum_is_nan_not_zero():
    """A model that is NaN at the input means (a power law of a negative height ratio,
    the shear exponent of a gate below the sea surface) has no first-order GUM there: u
    is NaN. The imaginary part of the complex step of a NaN read as 0, which gave u = 0,
    a reading of 'no uncertainty'."""
    def model(x, y):
        valid = uq.complexstep.real_part(x) > 0
        return np.where(valid, np.log(np.where(valid, x, 2.0)) * y, np.nan)
    inputs = {"x": st.norm(-1.0, 0.1), "y": st.norm(1.0, 0.1)}
    result = uq.propagate(model, inputs, n=1000, seed=1)
    assert np.isnan(float(result["y_gum_u"])) and np.isnan(float(result["y_gum_value"]))
    assert np.all(np.isnan(result["y_budget"].values))
    assert np.isnan(float(result["y_mc_u"])) and int(result["y_mc_n_invalid"]) == 1000
    inside = uq.propagate(model, {**inputs, "x": st.norm(1.0, 0.1)}, n=1000, seed=1)
    assert float(inside["y_gum_u"]) == pytest.approx(0.1, rel=1e-9)  # d(y ln x)/dx = y/x
