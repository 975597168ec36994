"""The INS as a sampled series (interpolation errors against their closed forms), the
Gauss-Markov correlation, and the dwell quadrature (its stated bound)."""
import time

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


def dwell_mean(span, phase, fastest=None):
    """The dwell average of sin(w t + phase) over a dwell of w D = span (D = 1 s)."""
    timing = ScanTiming(beam_duration=1.0, dwell_average=True)
    times, weights = timing.nodes(1, fastest=span if fastest is None else fastest)
    return np.sin(span * times[0] + phase) @ weights, len(weights)


#: Dwells of a harmonic, in its radians: short, 100 whole periods (the aliasing case of
#: issue 28: 32 nodes gave a mean of ~0.09 per unit amplitude), non-integer numbers of
#: periods, and the longest dwell the node bound allows.
SPANS = [0.05, 2.0, 70.0, 2 * np.pi * 100, 2 * np.pi * 37.3, 2 * np.pi * 11.5, 1130.0]


@pytest.mark.parametrize("span", SPANS)
def test_the_dwell_average_is_its_closed_form_at_any_dwell_length(span):
    """Against (cos(phase) - cos(span + phase)) / span for 24 phases: within the stated
    tolerance (per unit amplitude), plus the rounding of a weighted sum of at most 512
    terms of size <= 1 (512 x 2.2e-16 ~ 1e-13)."""
    from uq.constants import DWELL_QUADRATURE_TOLERANCE
    for phase in np.linspace(0, 2 * np.pi, 24, endpoint=False):
        numeric, nodes = dwell_mean(span, phase)
        exact = (np.cos(phase) - np.cos(span + phase)) / span
        assert abs(numeric - exact) <= DWELL_QUADRATURE_TOLERANCE + 1e-13, (span, nodes)


def test_composite_panels_only_where_one_panel_does_not_do():
    """Up to PANEL_SPAN one panel of dwell_node_count nodes (the rule as before: the
    nodes of a dwell it resolved are unchanged); beyond, equal panels of <= 32 nodes."""
    from uq.constants import MAX_DWELL_NODES
    from uq.physics.timing import PANEL_SPAN, dwell_rule
    for span in (0.1, 1.0, 8.0, 30.0, PANEL_SPAN):
        assert dwell_rule(span) == (1, dwell_node_count(span))
    panels, q = dwell_rule(2 * np.pi * 100)
    assert panels == int(np.ceil(2 * np.pi * 100 / PANEL_SPAN)) and q <= MAX_DWELL_NODES
    assert dwell_error_bound(2 * np.pi * 100 / panels, q) <= 1e-9


def test_a_dwell_beyond_the_node_bound_is_refused_before_allocating():
    """beam_duration 1e9 s of a 1 s motion: DwellTooLong from the span alone (the rule
    would need ~3e9 nodes); an infinite span is a ValueError, not an OverflowError."""
    import resource
    from uq.physics.timing import DwellTooLong, dwell_rule
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(DwellTooLong, match="at most 512"):
        ScanTiming(beam_duration=1e9, dwell_average=True).nodes(5, fastest=2 * np.pi)
    with pytest.raises(ValueError):
        dwell_rule(np.inf)
    started = time.process_time()
    for span in (1e300, 1e16, 1134.5):          # spans where panels + 1 == panels in floats
        with pytest.raises(DwellTooLong):
            dwell_rule(span)
    assert time.process_time() - started < 1.0  # CPU s: a few arithmetic steps, no loop
    # (kB) nothing of the size of the rule's ~3e9 nodes was allocated: 10 MB of slack
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 10_000


@pytest.mark.parametrize("span", [1.0, 2 * np.pi * 20, 2 * np.pi * 13.7])
def test_the_attitude_harmonics_are_resolved(span):
    """The beam turns through cos and sin of the attitude: the dwell mean of
    cos(A sin(w t + phi)) against Jacobi-Anger, J0(A) + 2 sum_k J_2k(A) <cos 2k theta>,
    with the nodes the model takes for a roll of amplitude A (dwell_frequency). Within
    the tolerance times the sum of the harmonics' amplitudes (<= e^(A/2) < 1.5), plus
    rounding (1e-13, as above)."""
    from scipy.special import jv
    from uq.constants import DWELL_QUADRATURE_TOLERANCE
    from uq.physics.timing import dwell_frequency
    amplitude = np.deg2rad(10.0)
    roll = MotionComponent(span, (amplitude, 0, 0, 0, 0, 0))
    timing = ScanTiming(beam_duration=1.0, dwell_average=True)
    times, weights = timing.nodes(1, fastest=dwell_frequency([roll]))
    assert dwell_frequency([roll]) >= 4 * span                 # harmonics above w
    for phase in np.linspace(0, 2 * np.pi, 12, endpoint=False):
        numeric = np.cos(amplitude * np.sin(span * times[0] + phase)) @ weights
        k = np.arange(1, 20)[:, None]
        means = (np.sin(2 * k * (span + phase)) - np.sin(2 * k * phase)) / (2 * k * span)
        exact = jv(0, amplitude) + 2 * np.sum(jv(2 * k, amplitude) * means)
        assert abs(numeric - exact) <= 1.5 * DWELL_QUADRATURE_TOLERANCE + 1e-13


def test_a_spectrum_takes_its_highest_frequency():
    """A JONSWAP heave of 32 components: the dwell rule follows its highest component
    (translations: order 1), and the dwell mean of the sum over a 60 s dwell equals the
    sum of the closed forms to the tolerance times the sum of the amplitudes."""
    from uq.constants import DWELL_QUADRATURE_TOLERANCE
    from uq.physics.timing import dwell_frequency
    from uq.physics.waves import jonswap_components
    components = jonswap_components(2.0, 8.0, 3.3, 32, (0.0625, 0.5), {"heave": (1.0, 0.0)})
    highest = max(c.angular_frequency for c in components)
    assert dwell_frequency(components) == highest
    timing = ScanTiming(beam_duration=60.0, dwell_average=True)
    times, weights = timing.nodes(1, fastest=dwell_frequency(components))
    rng = np.random.default_rng(5)
    phases = rng.uniform(0, 2 * np.pi, len(components))
    w = np.array([c.angular_frequency for c in components])
    a = np.array([c.amplitudes[5] for c in components])
    numeric = (a * np.sin(w * times[0][:, None] + phases)).sum(axis=1) @ weights
    exact = np.sum(a * (np.cos(phases) - np.cos(w * 60.0 + phases)) / (w * 60.0))
    assert abs(numeric - exact) <= DWELL_QUADRATURE_TOLERANCE * a.sum() + 1e-13
