"""Wind conventions: cardinal directions, round trips, wrap at 0/360, power law."""
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from uq.physics.wind import power_law_speed, wind_components, wind_direction, wind_speed

# (direction "from" [deg], (north, east) of a 1 m/s wind)
CARDINAL = [(0, (-1, 0)), (90, (0, -1)), (180, (1, 0)), (270, (0, 1)),
            (45, (-np.sqrt(0.5), -np.sqrt(0.5))), (225, (np.sqrt(0.5), np.sqrt(0.5)))]


@pytest.mark.parametrize("direction, components", CARDINAL)
def test_cardinal_directions(direction, components):
    np.testing.assert_allclose(wind_components(1.0, direction), components, atol=1e-15)
    assert wind_direction(*components) == pytest.approx(direction)


@given(st.floats(0.01, 50), st.floats(0, 359.999))
def test_round_trip(speed, direction):
    north, east = wind_components(speed, direction)
    assert wind_speed(north, east) == pytest.approx(speed)
    difference = np.mod(wind_direction(north, east) - direction + 180, 360) - 180
    assert abs(difference) < 1e-9


@pytest.mark.parametrize("direction", [359.9999, 0.0, 0.0001, 360.0])
def test_directions_near_north_stay_in_range(direction):
    value = wind_direction(*wind_components(3.0, direction))
    assert 0 <= value < 360
    assert abs(np.mod(value - direction + 180, 360) - 180) < 1e-9


def test_power_law():
    assert power_law_speed(8.0, 200.0, 100.0, 0.2) == pytest.approx(8.0 * 2**0.2)
    assert power_law_speed(8.0, 100.0, 100.0, 0.3) == 8.0
    assert np.isnan(power_law_speed(8.0, -1.0, 100.0, 0.2))     # below the sea: no wind model


@pytest.mark.parametrize("scale", [1e-200, 1e-150, 1e-3, 1.0, 1e3, 1e150, 1e200])
def test_wind_speed_matches_numpy_hypot_at_every_scale(scale):
    """The fast sqrt(x^2 + y^2) path and the numpy.hypot fallback agree with libm's
    hypot to 2 ulp (4.5e-16 relative) from 1e-200 to 1e200, with NaN and zeros mixed in."""
    rng = np.random.default_rng(2)
    north, east = rng.normal(size=(2, 1000)) * scale
    north[:3], east[:3] = [0.0, np.nan, 0.0], [0.0, 1.0, np.nan]
    expected = np.hypot(north, east)
    np.testing.assert_allclose(wind_speed(north, east), expected, rtol=4.5e-16, atol=0)
    np.testing.assert_allclose(wind_speed(north[3:], east[3:]), expected[3:], rtol=4.5e-16,
                               atol=0)
    assert wind_speed(np.array([3.0]), np.array([np.inf]))[0] == np.inf
