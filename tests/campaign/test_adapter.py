"""The campaign's door to the physics (uq.campaign.adapter), against the physics itself:
the spectral path summed node by node, the GUM's motion variance of ``uq run``, the
motion's second-order shift against a quadrature over its phase, the per-scan errors'
GUM, and the spectral identity of a lidar that is a point."""
import copy
from pathlib import Path

import numpy as np
import pytest

import uq
from uq.campaign import adapter, spectra
from uq.campaign.motion import response_shape
from uq.physics.waves import jonswap_components
from uq.pipeline.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]
LIDAR = load_scenario(ROOT / "scenarios" / "campaign_buoy_lidar.yaml").settings
TURBULENCE = {"model": "mann", "length_scale": 33.6, "anisotropy": 3.9}


def sea_components(settings):
    """Frequencies and complex amplitudes of the scenario's JONSWAP sea."""
    motion = settings["motion"]
    spectrum = motion["spectrum"]
    components = jonswap_components(
        spectrum["hs"], spectrum["tp"], spectrum["gamma"], spectrum["components"],
        tuple(spectrum["band"]), {d: (v["factor"], np.radians(v["lag"]))
                                  for d, v in motion["response"].items()})
    return (np.array([c.angular_frequency / (2 * np.pi) for c in components]),
            np.array([np.array(c.amplitudes) * np.exp(1j * np.array(c.lags))
                      for c in components]))


@pytest.mark.parametrize("correction", ["none", "pointwise"])
def test_the_motion_variance_is_the_pipelines_gum(correction):
    """sum |dVh/dc|^2 / 2 over the sea's components equals uq run's
    wind_speed_motion_ti_gum (times the true speed, squared): the same GUM, its Jacobian
    by complex step there and by central differences here (h = 1e-4: 1e-8 relative).
    Where the lidar corrects its motion (pointwise, a 10 Hz INS) the residual."""
    raw = copy.deepcopy(LIDAR)
    raw.update(correction=correction, sampling={"method": "none"})
    raw["ins"] = {"correlation": "scan", "rate": 10}
    run = uq.run(load_scenario(raw))
    expected = float((run["wind_speed_motion_ti_gum"] * run["wind_speed_true"]) ** 2)
    settings = adapter.gate_settings({**LIDAR, "correction": correction, "ins": raw["ins"]},
                                     [80.0], TURBULENCE, 600.0, 9.0, 250.0)
    frequency, amplitude = sea_components(LIDAR)
    found = np.sum(np.abs(adapter.motion_jacobian(settings, frequency, amplitude)) ** 2) / 2
    assert found == pytest.approx(expected, rel=1e-6)
    assert expected > 0


def test_the_response_is_linear_in_the_complex_amplitude(rng):
    """dVh/dc of a component of amplitude a = sum_d z_d conj(a_d) (module docstring),
    z_d the response of a unit, lag-free degree of freedom."""
    settings = adapter.gate_settings(LIDAR, [60.0], TURBULENCE, 600.0, 7.0, 100.0)
    frequency = np.array([0.11, 0.23])
    unit = adapter.motion_jacobian(settings, np.repeat(frequency, 6),
                                   np.tile(np.eye(6), (2, 1))).reshape(2, 6)
    amplitude = 0.05 * (rng.normal(size=(2, 6)) + 1j * rng.normal(size=(2, 6)))
    combined = adapter.motion_jacobian(settings, frequency, amplitude)
    np.testing.assert_allclose(combined, np.einsum("kd,kd->k", unit, np.conj(amplitude)),
                               rtol=1e-6)


def test_the_shift_is_the_second_order_of_a_quadrature_over_the_phase():
    """The mean over 64 phases of Vh under one component of amplitude s a, less Vh at
    rest, over s^2: q(a) + O(s^2). At s = 0.05 (a roll of 0.05 x 4 deg/m x 1 m) the
    fourth order is ~s^2 = 0.25 % of q: 2 % allowed."""
    settings = adapter.gate_settings(LIDAR, [80.0], TURBULENCE, 600.0, 9.0, 250.0)
    shape = response_shape({d: (v["factor"], v["lag"]) for d, v in
                            LIDAR["motion"]["response"].items()})
    q = adapter.motion_shift(settings, np.array([0.15]), shape[None])[0]
    components = adapter.components_of(np.array([0.15]), 0.05 * shape[None])
    angle = 2 * np.pi * np.arange(64) / 64
    phases = np.stack([np.cos(angle), np.sin(angle)], axis=-1)[:, None, :]
    speed = adapter.scan_speeds(settings, components, np.concatenate([phases, np.zeros((1, 1, 2))]))
    assert (speed[:-1].mean() - speed[-1]) / 0.05 ** 2 == pytest.approx(q, rel=0.02)
    assert q != 0


def test_the_scan_noise_variance_is_the_pipelines_gum_at_rest():
    """Without motion the GUM variance of the wind speed of uq run is that of the
    per-scan errors alone (here the radial noise of the lidar scenario)."""
    raw = copy.deepcopy(LIDAR)
    raw.pop("motion")
    raw["sampling"] = {"method": "none"}
    raw["wind"] = {**raw["wind"], "reference_height": 80.0}
    raw["lidar"] = {**raw["lidar"], "ranges": [77.0]}
    run = uq.run(load_scenario(raw))
    settings = adapter.gate_settings(LIDAR, [80.0], TURBULENCE, 600.0, 9.0, 250.0)
    assert adapter.scan_noise_variance(settings) == pytest.approx(
        float(run["wind_speed_gum_u"]) ** 2, rel=1e-10)


def test_the_terms_summed_are_the_spectral_paths_record_variances():
    """The node-by-node terms, summed with the record's high-pass, give the spectral
    path's own variances (uq.pipeline.records.spectral_variances). The lidar's terms are
    the path's own pair sums on its own rule; they differ from it only where the path
    integrates each pair's phase exp(i k1 delta_x) across the record's peaks (the terms
    carry the high-pass of delta = 0): over the mean's peak (width 2 pi / (U T) = 1.3e-3
    rad/m) a separation of <= 100 m turns the phase by < 0.13 rad, and the peaks hold a
    few % of the variance, so <= 2e-4 relative is allowed (3.5e-5 measured). The point's
    terms are its 1-D spectrum on that rule (from 0) where the path's point rule starts
    at 1e-6 / L: 1e-5 measured, 5e-5 allowed. Without the high-pass (an infinite record)
    the lidar's terms are the path's sums on the same rule: 1e-9 (rounding of sums of
    ~1e2 terms of both signs)."""
    import dataclasses
    from uq.physics.lidarspectral import mann_lidar_variances, probe_transfer_for
    from uq.pipeline import probesection
    from uq.pipeline.records import spectral_variances, turbulence_model
    from uq.pipeline.turbulencesection import scan_geometry, slant_ranges
    settings = adapter.gate_settings(LIDAR, [40.0, 80.0], TURBULENCE, 600.0, 8.0, 120.0)
    terms = adapter.spectral_terms(settings)
    direct = spectral_variances(settings)[0]
    for gate in range(2):
        lidar, point = spectra.record_variances(terms.gate(gate))
        assert lidar == pytest.approx(direct.lidar[gate, 0], rel=2e-4)
        assert point == pytest.approx(direct.true[0], rel=5e-5)
    np.testing.assert_allclose([spectra.filtering_factor(terms.gate(g)) for g in range(2)],
                               adapter.spectral_ratio(settings), rtol=2.5e-4)
    geometry = dataclasses.replace(scan_geometry(settings), record_duration=np.inf)
    infinite = mann_lidar_variances(
        geometry, turbulence_model(settings["turbulence"], settings["wind"]["speed"]),
        probe_transfer_for(probesection.make_probe(settings["lidar"]["probe"]),
                           slant_ranges(settings["lidar"])))
    np.testing.assert_allclose(terms.lidar.sum(axis=0), infinite.lidar[:, 0], rtol=1e-9)
    assert np.all(terms.high_pass[terms.k1 > 100 / (8.0 * 600.0)] > 0.9)   # beyond the peak


def test_a_vads_terms_summed_are_its_spectral_paths_record_variances():
    """Many beams (a CW VAD of 50 lines of sight): the path's vector sums on its log-polar
    grid, one k1 node at a time, with the high-pass at the nodes as the path takes it:
    the lidar's sum is the path's to rounding (1e-10 allowed; 2e-13 measured). The
    point's terms are its 1-D spectrum at the grid's k1 nodes (12 a decade, the
    high-pass at the nodes) where the path integrates it on Gauss-Legendre panels with
    the record's peaks resolved: 3.9e-5 measured, 2e-4 allowed (the nodes' sampling of
    the mean's peak, ~1e-3 of the few % of the variance it holds)."""
    from uq.pipeline.records import spectral_variances
    cw = load_scenario(ROOT / "scenarios" / "sathe2011_ti_cw.yaml").settings
    settings = adapter.gate_settings(cw, [80.0], TURBULENCE, 600.0, 10.0, 270.0)
    lidar, point = spectra.record_variances(adapter.spectral_terms(settings).gate(0))
    direct = spectral_variances(settings)[0]
    assert lidar == pytest.approx(direct.lidar[0, 0], rel=1e-10)
    assert point == pytest.approx(direct.true[0], rel=2e-4)


def test_a_lidar_that_is_a_point_does_not_filter():
    """The gate 10 um from the lidar, its beams read 1 ms apart in a wind of 1 cm/s (the
    field moves 10 um between them), a point probe: the scan samples one point at one
    time, and F = 1 to ``(k delta)^2`` of the scales that hold the record's variance
    (1e-4 allowed; 7e-6 measured). At 1 mm the beams' separation already filters (F - 1
    = 1.2e-2: the least-squares u of inclined beams amplifies the eddies smaller than
    their separation)."""
    raw = copy.deepcopy(LIDAR)
    raw["lidar"] = {**raw["lidar"], "height": 80.0 - 1e-5, "scan": {"beam_duration": 0.001}}
    raw["lidar"].pop("probe")
    settings = adapter.gate_settings(raw, [80.0], TURBULENCE, 600.0, 0.01, 30.0)
    assert spectra.filtering_factor(adapter.spectral_terms(settings).gate(0)) == \
        pytest.approx(1.0, abs=1e-4)


def test_the_scenes_quiet_warnings_are_their_threads_alone():
    # the campaign builds its gate scenes on several threads at once: their quieting of
    # the scenario's warnings must neither leave the logger's level raised for the whole
    # process (it did: save, raise, restore from threads at once) nor silence another
    # thread's warning while it runs
    import logging
    import threading
    from uq.campaign import adapter
    logger = logging.getLogger("uq.pipeline.scenario")
    level = logger.level
    logger.setLevel(logging.WARNING)        # (an earlier `uq ... -q` may have raised "uq")
    inside, release = threading.Barrier(5), threading.Event()

    def quiet_scene():
        adapter._quiet(lambda: (inside.wait(), release.wait(), logger.warning("hidden")))
    records = []

    class Keep(logging.Handler):
        def emit(self, record):
            records.append(record.getMessage())
    handler = Keep(level=logging.WARNING)
    logger.addHandler(handler)
    try:
        threads = [threading.Thread(target=quiet_scene) for _ in range(4)]
        for thread in threads:
            thread.start()
        inside.wait()                       # all four inside _quiet: this thread is not
        logger.warning("shown")
        release.set()
        for thread in threads:
            thread.join()
        assert logger.level == logging.WARNING          # the quiet threads left it alone
    finally:
        logger.removeHandler(handler)
        logger.setLevel(level)
    assert records == ["shown"]
