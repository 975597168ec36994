"""The mean-wind frame's convention and the scan geometry's validation."""
import numpy as np
import pytest

from uq.physics.scangeometry import ScanGeometry, earth_to_wind_frame, wind_to_earth_frame


@pytest.mark.parametrize("direction, downwind", [(0.0, (-1, 0, 0)), (90.0, (0, -1, 0)),
                                                 (180.0, (1, 0, 0)), (270.0, (0, 1, 0))])
def test_the_wind_blows_along_x(direction, downwind):
    # a wind "from" D moves towards D + 180: that earth vector is +x, and the vector
    # 90 deg counter-clockwise from it (seen from above) is +y
    x = earth_to_wind_frame(np.array(downwind, dtype=float), direction)
    np.testing.assert_allclose(x, [1, 0, 0], atol=1e-15)   # rounding of cos/sin of 90k deg


def test_right_handed_and_inverse():
    rng = np.random.default_rng(1)
    v, d = rng.normal(size=(5, 3)), 123.4
    w = earth_to_wind_frame(v, d)
    np.testing.assert_allclose(wind_to_earth_frame(w, d), v, rtol=0, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(w, axis=-1), np.linalg.norm(v, axis=-1))
    # (east, north, up) is right-handed; x, y, z must be a proper rotation of it
    enu = v[:, [1, 0, 2]]
    rotation = np.linalg.lstsq(enu, w, rcond=None)[0]
    assert np.linalg.det(rotation) == pytest.approx(1.0, abs=1e-12)


def _geometry(**change):
    fields = dict(directions=np.eye(3), gate_centres=np.zeros((3, 2, 3)), times=np.zeros(3),
                  dwell=0.0, scan_period=1.0, probe_offsets=np.zeros(1),
                  probe_weights=np.ones((2, 1)), reconstruction=np.tile(np.eye(3), (2, 1, 1)),
                  speed=10.0)
    fields.update(change)
    return ScanGeometry(**fields)


def test_geometry_validates_shapes():
    g = _geometry()
    assert (g.n_beams, g.n_gates) == (3, 2)
    assert g.probe_points().shape == (3, 2, 1, 3)
    with pytest.raises(ValueError, match="reconstruction"):
        _geometry(reconstruction=np.eye(3))
    with pytest.raises(ValueError, match="unit"):
        _geometry(directions=2 * np.eye(3))


def test_conical_scan_of_the_tests_and_benchmarks():
    # a 4-beam DBS and its vertical beam at 30 deg: beam 0 along +x, the gates at the
    # given heights above the lidar, the reference point at the first one, the
    # reconstruction the directions' pseudo-inverse (so it returns a uniform wind)
    from uq.physics.scangeometry import conical_scan
    g = conical_scan([100.0, 150.0], vertical=True, beam_duration=1.0)
    np.testing.assert_allclose(g.directions[0], [0.5, 0.0, np.sqrt(3) / 2], atol=1e-15)
    np.testing.assert_allclose(g.gate_centres[:, :, 2], [[0.0, 50.0]] * 5, atol=1e-12)
    assert g.scan_period == 5.0 and g.times[-1] == 4.5 and g.speed == 10.0
    wind = np.array([3.0, -1.0, 0.5])
    np.testing.assert_allclose(g.reconstruction[1] @ (g.directions @ wind), wind, atol=1e-12)
