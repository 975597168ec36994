"""The INS as a sampled series (interpolation errors against their closed forms), the
Gauss-Markov correlation, and the dwell quadrature (its stated bound)."""
import numpy as np
import pytest

from conftest import make_scene
from uq.physics.ins import InsSampling, gauss_markov_correlation
from uq.physics.motion import DEGREES_OF_FREEDOM, Motion, MotionComponent
from uq.physics.scene import TimeResolved
from uq.physics.timeresolved import ins_state
from uq.physics.timing import ScanTiming, dwell_error_bound, dwell_node_count

AMPLITUDE, PERIOD, RATE = np.deg2rad(5.0), 5.0, 10.0
W, H = 2 * np.pi / PERIOD, 1 / RATE


def reading_error(interpolation):
    """Largest |pitch read - pitch true| over 360 phases x 200 read times in one period
    of the INS (the error is periodic in both)."""
    scene = make_scene()
    amplitudes = [0.0] * 6
    amplitudes[DEGREES_OF_FREEDOM.index("pitch")] = AMPLITUDE
    motion = Motion((MotionComponent(W, tuple(amplitudes), phase=None),))
    resolved = TimeResolved(motion, ScanTiming(), InsSampling(RATE, interpolation))
    phases = np.linspace(0, 2 * np.pi, 360, endpoint=False)
    unit = np.stack([np.cos(phases), np.sin(phases)], axis=-1)[:, None, :]
    read = np.broadcast_to(np.linspace(0, H, 200, endpoint=False)[None, :], (360, 200))
    state = ins_state(scene, resolved, motion.unit_phases(unit), read, np.zeros(360),
                      resolved.ins)
    truth = AMPLITUDE * np.sin(W * read + phases[:, None])
    return np.max(np.abs(state["pitch"] - truth))


def test_linear_interpolation_error_is_a_w2_h2_over_8():
    """Exact: A (1 - cos(w h / 2)); to leading order A w^2 h^2 / 8. The dense grid finds
    the maximum to ~(pi/200)^2 relative."""
    error = reading_error("linear")
    assert error == pytest.approx(AMPLITUDE * (1 - np.cos(W * H / 2)), rel=1e-3)
    assert error == pytest.approx(AMPLITUDE * W**2 * H**2 / 8, rel=(W * H) ** 2 / 12 + 1e-3)


def test_nearest_sample_error_is_a_w_h_over_2():
    """Exact: 2 A sin(w h / 4); to leading order A w h / 2."""
    error = reading_error("nearest")
    assert error == pytest.approx(2 * AMPLITUDE * np.sin(W * H / 4), rel=1e-3)
    assert error == pytest.approx(AMPLITUDE * W * H / 2, rel=(W * H) ** 2 / 24 + 1e-3)


def test_gauss_markov_limits():
    times = np.array([0.5, 1.5, 2.5, 3.5])
    np.testing.assert_array_equal(gauss_markov_correlation(times, 0.0), np.eye(4))
    np.testing.assert_array_equal(gauss_markov_correlation(times, 1e-12), np.eye(4))
    np.testing.assert_array_equal(gauss_markov_correlation(times, np.inf), np.ones((4, 4)))
    rho = gauss_markov_correlation(times, 2.0)
    assert rho[0, 1] == pytest.approx(np.exp(-0.5)) and rho[0, 3] == pytest.approx(np.exp(-1.5))
    assert np.all(np.linalg.eigvalsh(rho) > 0)          # a valid correlation


@pytest.mark.parametrize("span", [0.1, 1.0, 3.0, 8.0])
def test_dwell_quadrature_meets_its_bound(span):
    """The mean of sin(w t + phase) over a dwell of w D = span, by the chosen node count,
    against the closed form, for 50 phases: within the stated tolerance."""
    from uq.constants import DWELL_QUADRATURE_TOLERANCE
    timing = ScanTiming(beam_duration=1.0, dwell_average=True)
    times, weights = timing.nodes(1, fastest=span)             # dwell [0, 1], w = span
    q = dwell_node_count(span)
    assert len(weights) == q and abs(weights.sum() - 1) < 1e-15
    assert dwell_error_bound(span, q) <= DWELL_QUADRATURE_TOLERANCE
    for phase in np.linspace(0, 2 * np.pi, 50):
        numeric = np.sin(span * times[0] + phase) @ weights
        exact = (np.cos(phase) - np.cos(span + phase)) / span
        assert abs(numeric - exact) <= DWELL_QUADRATURE_TOLERANCE
    if q > 1:                                   # and one node fewer would not do
        assert dwell_error_bound(span, q - 1) > DWELL_QUADRATURE_TOLERANCE


def test_time_stamps_follow_the_convention():
    timing = ScanTiming(beam_duration=2.0, timestamp="start")
    np.testing.assert_array_equal(timing.stamps(3), [0.0, 2.0, 4.0])
    np.testing.assert_array_equal(ScanTiming(2.0, "mid").stamps(3), [1.0, 3.0, 5.0])
    np.testing.assert_array_equal(ScanTiming(2.0, "end").stamps(3), [2.0, 4.0, 6.0])
    assert ScanTiming(2.0).scan_mid_time(5) == 5.0
