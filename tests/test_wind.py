"""Wind conventions: cardinal directions, round trips, wrap at 0/360, power law."""
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from uq.wind import power_law_speed, wind_components, wind_direction, wind_speed

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
