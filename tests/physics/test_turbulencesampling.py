"""A lidar's sampling of a frozen field: Taylor's shift, projection, probe and dwell
averaging, moving beams, the point-probe limit, and the record's statistics."""
import numpy as np
import pytest

from uq.physics import turbulencebox as tb
from uq.physics import turbulencesampling as ts
from uq.physics.scangeometry import ScanGeometry

GAMMA = 3.9


def _grid_box(seed=3, shape=(64, 16, 16), spacing=2.0, origin=(-100.0, -16.0, -16.0)):
    grid = tb.BoxGrid(shape, (spacing,) * 3, origin)
    return tb.mann_box(grid, 0.1, 10.0, GAMMA, np.random.default_rng(seed))


def _point_geometry(directions, gates, times, speed=4.0, dwell=0.0, period=1.0):
    directions = np.asarray(directions, float)
    directions = directions / np.linalg.norm(directions, axis=-1, keepdims=True)
    n = len(directions)
    return ScanGeometry(directions=directions, gate_centres=np.asarray(gates, float)[:, None, :],
                        times=np.asarray(times, float), dwell=dwell, scan_period=period,
                        probe_offsets=np.zeros(1), probe_weights=np.ones((1, 1)),
                        reconstruction=np.linalg.pinv(directions)[None] if n >= 3
                        else np.zeros((1, 3, n)), speed=speed)


def _node_value(box, point, time, speed):
    """The box's value at the grid node that Taylor's shift brings the point to."""
    cell = (np.asarray(point) - [speed * time, 0, 0] - box.grid.origin) / box.grid.spacing
    index = np.round(cell).astype(int)
    assert np.allclose(cell, index, atol=1e-9)
    return box.velocity[(slice(None),) + tuple(index % box.grid.shape)]


def test_point_probe_on_nodes_is_the_projected_node_value():
    """Dwell 0, a point probe at grid nodes: the radial velocity is d . u'_0(r - U t e_x),
    exactly (trilinear weights 0 and 1), over scans that wrap around the periodic box."""
    box = _grid_box()
    speed, period = 4.0, 1.5                          # U period = 6 m = 3 cells per scan
    gates = [[10.0, 4.0, -2.0], [-6.0, 0.0, 8.0], [0.0, -10.0, 0.0]]
    directions = [[1.0, 2.0, 2.0], [-0.3, 0.4, 0.5], [0.0, 0.0, 1.0]]
    times = [0.0, 0.5, 1.0]                           # U t = 0, 2, 4 m: whole cells
    geometry = _point_geometry(directions, gates, times, speed, period=period)
    radial = ts.record_radial_velocities(box, geometry, n_scans=50)
    assert radial.shape == (50, 3, 1)
    for s in (0, 7, 49):                              # 49 scans advect 294 m > L_x = 128 m
        for b in range(3):
            t = s * period + times[b]
            expected = geometry.directions[b] @ _node_value(box, gates[b], t, speed)
            assert radial[s, b, 0] == pytest.approx(expected, abs=1e-13)


def test_trilinear_interpolation_is_exact_for_a_linear_field():
    grid = tb.BoxGrid((8, 8, 8), (1.5, 2.0, 2.5), (1.0, -3.0, 2.0))
    x = grid.origin[0] + np.arange(8) * 1.5
    y = grid.origin[1] + np.arange(8) * 2.0
    z = grid.origin[2] + np.arange(8) * 2.5
    xx, yy, zz = np.meshgrid(x, y, z, indexing="ij")
    box = tb.TurbulenceBox(grid, np.stack([0.3 * xx - yy + 2 * zz, yy, -zz + 0.1 * xx]))
    rng = np.random.default_rng(0)
    # interior points only (the field is periodic, a linear one is not)
    points = np.array(grid.origin) + rng.uniform(0, 6.9, (100, 3)) * grid.spacing
    got = ts.sample_velocity(box, points, 0.0, speed=10.0)
    px, py, pz = points.T
    np.testing.assert_allclose(got, np.stack([0.3 * px - py + 2 * pz, py, -pz + 0.1 * px], -1),
                               rtol=0, atol=1e-12)
    # Taylor: at time t the field at x is the t = 0 field at x - U t
    later = ts.sample_velocity(box, points + [10.0 * 0.05, 0, 0], 0.05, speed=10.0)
    np.testing.assert_allclose(later, got, rtol=0, atol=1e-12)


def test_a_kaimal_box_refuses_points_outside_it():
    grid = tb.BoxGrid((16, 4, 4), (2.0, 2.0, 2.0), (0.0, 0.0, 0.0), periodic_yz=False)
    box = tb.kaimal_box(grid, 1.0, 10.0, 42.0, np.random.default_rng(0))
    ts.sample_velocity(box, [[5.0, 6.0, 6.0]], 0.0, 10.0)         # on the last node: inside
    with pytest.raises(ValueError, match="leaves the turbulence box along y"):
        ts.sample_velocity(box, [[5.0, 6.5, 1.0]], 0.0, 10.0)


def test_point_probe_simultaneous_beams_see_the_variance_of_their_component():
    """Limit: point probes, dwell 0, all beams at one time, no motion: the radial
    velocity's variance over records is d^T R d, R the box's covariance (box_variance)."""
    grid = tb.BoxGrid((128, 32, 32), (2.0,) * 3, (-128.0, -32.0, -32.0))
    directions = np.array([[0.5, 0.0, np.sqrt(0.75)], [0.0, -0.5, np.sqrt(0.75)],
                           [-0.5, 0.0, np.sqrt(0.75)], [0.0, 0.0, 1.0]])
    gates = [[20.0, 0.0, 0.0], [0.0, -20.0, 0.0], [-20.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
    geometry = _point_geometry(directions, gates, np.zeros(4), speed=8.0, period=2.0)
    var = tb.box_variance(grid, 0.1, 10.0, GAMMA)
    covariance = np.array([[var[0], 0, var[3]], [0, var[1], 0], [var[3], 0, var[2]]])
    expected = np.einsum("bi,ij,bj->b", directions, covariance, directions)
    seeds = range(16)
    per_seed = np.array([np.mean(ts.record_radial_velocities(
        tb.mann_box(grid, 0.1, 10.0, GAMMA, np.random.default_rng(s)), geometry, 16)[..., 0] ** 2,
        axis=0) for s in seeds])                          # 16 scans cover the box's x once
    # each seed's mean square over its 16 scans: a random variable with expectation
    # d^T R d (homogeneity); 16 seeds, 4 standard errors from their scatter
    error = per_seed.std(axis=0, ddof=1) / np.sqrt(len(seeds))
    assert np.all(np.abs(per_seed.mean(axis=0) - expected) < 4 * error), (per_seed.mean(0), expected)


def _dbs(dwell=1.0, speed=10.0):
    a = np.radians(30.0)
    az = np.radians([0.0, 90.0, 180.0, 270.0])
    d = np.array([[np.sin(a) * np.cos(q), np.sin(a) * np.sin(q), np.cos(a)] for q in az]
                 + [[0.0, 0.0, 1.0]])
    ranges = np.r_[[100.0 / np.cos(a)] * 4, 100.0]
    gates = (np.array([0.0, 0.0, -100.0]) + ranges[:, None] * d)[:, None, :]
    offsets = np.linspace(-30.0, 30.0, 13)
    weights = np.exp(-((offsets - 5.0) / 15.0) ** 2)     # off-centre: the order matters
    return ScanGeometry(directions=d, gate_centres=gates, times=np.arange(5) * dwell + dwell / 2,
                        dwell=dwell, scan_period=5 * dwell, probe_offsets=offsets,
                        probe_weights=(weights / weights.sum())[None], speed=speed,
                        reconstruction=np.linalg.pinv(d)[None], record_duration=60.0)


@pytest.fixture(scope="module")
def dbs_box():
    geometry = _dbs()
    grid = tb.box_for(geometry, 33.6, spacing=8.0)
    return geometry, tb.mann_box(grid, 0.1, 33.6, GAMMA, np.random.default_rng(5))


def test_lidar_position_and_ranges(dbs_box):
    geometry, _ = dbs_box
    np.testing.assert_allclose(ts.lidar_position(geometry), [0, 0, -100.0], atol=1e-9)
    np.testing.assert_allclose(ts.gate_ranges(geometry, [0, 0, -100.0])[:, 0],
                               np.r_[[100 / np.cos(np.radians(30))] * 4, 100.0], rtol=1e-12)
    with pytest.raises(ValueError, match="parallel"):
        ts.lidar_position(_point_geometry([[0, 0, 1.0]], [[0, 0, 0.0]], [0.0]))


def test_probe_and_dwell_averaging_is_the_weighted_mean_of_points(dbs_box):
    geometry, box = dbs_box
    radial = ts.record_radial_velocities(box, geometry, 3)
    nodes = ts.dwell_offsets(geometry, min(box.grid.spacing))
    assert nodes.size == 2 and np.allclose(nodes, [-0.25, 0.25])   # U dwell = 10 m, dx = 8 m
    s, b = 2, 3
    points = geometry.probe_points()[b, 0]                             # (nodes, 3)
    t = s * geometry.scan_period + geometry.times[b] + nodes
    u = ts.sample_velocity(box, points[:, None, :], t[None, :], geometry.speed)   # (n, j, 3)
    expected = geometry.probe_weights[0] @ (u @ geometry.directions[b]).mean(axis=1)
    assert radial[s, b, 0] == pytest.approx(expected, rel=1e-12)


def test_moving_beams(dbs_box):
    geometry, box = dbs_box
    n = 4
    nominal = ts.record_radial_velocities(box, geometry, n)
    # the nominal directions given explicitly: the same beams
    same = ts.record_radial_velocities(box, geometry, n, directions=geometry.directions)
    np.testing.assert_allclose(same, nominal, rtol=0, atol=1e-12)
    # a displacement of U dt downwind at a start dt later: the same air (Taylor)
    later = ts.record_radial_velocities(box, geometry, n, start_time=0.7,
                                        displacements=[geometry.speed * 0.7, 0.0, 0.0])
    np.testing.assert_allclose(later, nominal, rtol=0, atol=1e-12)
    # a tilted beam: its probe points move with the tilt about the lidar
    rng = np.random.default_rng(2)
    tilted = geometry.directions + rng.normal(0, 0.02, (n, 5, 3))
    tilted /= np.linalg.norm(tilted, axis=-1, keepdims=True)
    moved = rng.normal(0, 0.5, (n, 5, 3))
    got = ts.record_radial_velocities(box, geometry, n, displacements=moved, directions=tilted)
    s, b = 3, 1
    rng_b = 100 / np.cos(np.radians(30))
    points = ([0, 0, -100.0] + moved[s, b] + (rng_b + geometry.probe_offsets)[:, None]
              * tilted[s, b])
    nodes = ts.dwell_offsets(geometry, min(box.grid.spacing))
    t = s * geometry.scan_period + geometry.times[b] + nodes
    u = ts.sample_velocity(box, points[:, None, :], t[None, :], geometry.speed)
    expected = geometry.probe_weights[0] @ (u @ tilted[s, b]).mean(axis=1)
    assert got[s, b, 0] == pytest.approx(expected, rel=1e-12)


def test_reference_series_and_reconstruction(dbs_box):
    geometry, box = dbs_box
    times = ts.scan_times(geometry, 12)
    np.testing.assert_allclose(times, np.arange(12) * 5.0 + 2.5)
    series = ts.reference_series(box, geometry.speed, times)
    assert series.shape == (12, 3)
    np.testing.assert_allclose(series[4], ts.sample_velocity(box, [0.0, 0, 0], times[4], 10.0))
    # a uniform wind is reconstructed exactly by the pseudo-inverse of the directions
    wind = np.array([10.0, -1.0, 0.3])
    radial = np.broadcast_to((geometry.directions @ wind)[None, :, None], (6, 5, 1))
    np.testing.assert_allclose(ts.reconstruct_scans(radial, geometry), np.tile(wind, (6, 1, 1)),
                               rtol=0, atol=1e-12)


def test_record_statistics():
    # directions 0.5 deg either side of +x: the circular mean is +x, not 180
    angles = np.radians([0.5, -0.5, 0.5, -0.5])
    wind = np.stack([10 * np.cos(angles), 10 * np.sin(angles), [0.1, -0.1, 0.2, 0.0]], -1)
    stats = ts.record_statistics(wind)
    assert stats["direction_mean"] % 360 == pytest.approx(0.0, abs=1e-9) or \
        stats["direction_mean"] == pytest.approx(360.0, abs=1e-9)
    # circular std sqrt(-2 ln R), R = cos(0.5 deg), against the 0.5 deg the angles spread
    assert stats["direction_std"] == pytest.approx(0.5, rel=1e-4)
    assert stats["speed_mean"] == pytest.approx(10.0)
    assert stats["w_std"] == pytest.approx(np.std([0.1, -0.1, 0.2, 0.0], ddof=1))
    # meteorological: a wind from 270 (towards east = +x) turned towards the left (+y,
    # north) comes from west-south-west, 270 - angle
    turned = np.array([[np.cos(np.radians(20)), np.sin(np.radians(20)), 0.0]] * 3)
    assert ts.record_statistics(turned, mean_direction=270.0)["direction_mean"] == pytest.approx(250.0)
    across = np.array([[np.cos(np.radians(a)), np.sin(np.radians(a)), 0.0] for a in (170, -170)])
    assert ts.record_statistics(across, mean_direction=10.0)["direction_mean"] == pytest.approx(190.0)
