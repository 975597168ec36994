"""A JONSWAP sea as motion components (uq.physics.waves) and its scenario section."""
import numpy as np
import pytest

import uq
from uq.errors import ScenarioError
from uq.physics.waves import jonswap_components, significant_height

RESPONSE = {"roll": (4.0, np.pi / 2), "heave": (1.0, 0.0)}


def test_the_components_carry_the_significant_wave_height():
    """4 sqrt(sum a_j^2 / 2) = Hs for the wave (read through a heave response of 1 m/m),
    exactly (to rounding), whatever the bin count; roll's is the factor times it."""
    for n in (8, 24, 64):
        components = jonswap_components(2.5, 7.0, 3.3, n, (0.5 / 7.0, 4.0 / 7.0), RESPONSE)
        assert len(components) == n and all(c.phase is None for c in components)
        assert significant_height(components, "heave") == pytest.approx(2.5, rel=1e-12)
        assert significant_height(components, "roll") == pytest.approx(
            np.deg2rad(4.0) * 2.5, rel=1e-12)


def test_the_spectrum_peaks_at_the_peak_period_with_the_jonswap_shape():
    """Amplitudes peak in the bin of fp = 1/Tp; the ratio of the peak to the same spectrum
    without enhancement (gamma = 1, Pierson-Moskowitz shape) is ~gamma at fp (Hasselmann
    et al. 1973: the enhancement factor is gamma^exp(0) = gamma at the peak), within the
    bin's offset from fp and the renormalisation to Hs."""
    band = (0.05, 0.5)
    peaked = jonswap_components(2.0, 8.0, 3.3, 90, band, {"heave": (1.0, 0.0)})
    flat = jonswap_components(2.0, 8.0, 1.0, 90, band, {"heave": (1.0, 0.0)})
    amplitude = np.array([c.amplitudes[5] for c in peaked])
    frequency = np.array([c.angular_frequency / (2 * np.pi) for c in peaked])
    assert abs(frequency[np.argmax(amplitude)] - 1 / 8.0) <= (band[1] - band[0]) / 90
    energy = amplitude**2
    flat_energy = np.array([c.amplitudes[5] for c in flat]) ** 2
    k = np.argmin(np.abs(frequency - 1 / 8.0))
    ratio = (energy[k] / energy.sum()) / (flat_energy[k] / flat_energy.sum())
    assert 1.5 < ratio < 3.3            # gamma at fp, less the share the peak takes from m0


def test_a_sea_in_a_scenario():
    ds = uq.run({"motion": {"spectrum": {"hs": 2.0, "tp": 7.0, "components": 12},
                            "response": {"pitch": {"factor": 2.0}, "heave": {"factor": 1.0}}},
                 "correction": "none", "sampling": {"n": 2000, "seed": 1},
                 "outputs": ["wind_speed", "wind_speed_motion_ti"]})
    assert float(ds["wind_speed_motion_ti"]) > 0
    assert "motion (phases)" in ds["input"].values


@pytest.mark.parametrize("motion, key", [
    ({"spectrum": {"hs": 2.0, "tp": 7.0}}, "motion.response"),
    ({"response": {"roll": {"factor": 1.0}}}, "motion.spectrum"),
    ({"spectrum": {"hs": 2.0}, "response": {"roll": {"factor": 1.0}}}, "motion.spectrum.tp"),
    ({"spectrum": {"hs": 2.0, "tp": 7.0, "components": 10_000},
      "response": {"roll": {"factor": 1.0}}}, "motion.spectrum.components"),
    ({"spectrum": {"hs": 2.0, "tp": 7.0, "band": [0.5, 0.1]},
      "response": {"roll": {"factor": 1.0}}}, "motion.spectrum.band"),
    ({"spectrum": {"hs": 2.0, "tp": 7.0}, "response": {"wobble": {"factor": 1.0}}},
     "motion.response.wobble"),
    ({"roll": {"amplitude": 60.0, "period": 5.0}}, "motion.roll.amplitude"),
    ({"roll": {"amplitude": 5.0}}, "motion.roll.period"),
])
def test_bad_motion_sections(motion, key):
    with pytest.raises(ScenarioError, match=key.replace(".", r"\.")):
        uq.load_scenario({"motion": motion})


def test_band_energy_is_zero_only_where_the_spectrum_underflows():
    """The default band [0.5, 4] / tp holds nearly all of the energy of a unit-height sea
    (m0 = (Hs / 4)^2 = 1/16 m2, to 1 %: the f^-5 tail beyond 4 fp holds < 1e-3 of it, and
    the 256 midpoint bins of the peak (gamma 3.3) miss ~0.3 %); a band at 1/1000 of the
    peak frequency holds none (exp(-1.25 (fp/f)^4) underflows), which validation
    refuses."""
    from uq.physics.waves import band_energy
    assert band_energy(8.0, 3.3, 256, (0.5 / 8, 4 / 8)) == pytest.approx(1 / 16, rel=1e-2)
    assert not band_energy(8.0, 3.3, 32, (1e-4, 2e-4)) > 0        # 0 or NaN (0 / 0)


def test_a_spectrum_asked_for_again_is_not_computed_again(monkeypatch):
    """wavespectra's scaling reads the whole call stack (0.1-0.2 s a call deep in a run):
    the same bins of the same sea are computed once, and give the same components."""
    import wavespectra.construct.frequency as frequency
    from uq.physics import waves
    calls, original = [], frequency.jonswap
    monkeypatch.setattr(frequency, "jonswap", lambda *a, **k: calls.append(1) or original(*a, **k))
    waves._jonswap_bins.cache_clear()
    response = {"roll": (4.0, 1.5), "heave": (1.0, 0.0)}
    first = waves.jonswap_components(2.5, 7.0, 3.3, 24, (0.5 / 7, 4 / 7), response)
    again = waves.jonswap_components(2.5, 7.0, 3.3, 24, (0.5 / 7, 4 / 7), response)
    other = waves.jonswap_components(3.0, 7.0, 3.3, 24, (0.5 / 7, 4 / 7), response)
    assert first == again and len(calls) == 2            # (the second sea: its own call)
    assert waves.significant_height(other, "heave") == pytest.approx(3.0, rel=1e-12)
    waves._jonswap_bins.cache_clear()
