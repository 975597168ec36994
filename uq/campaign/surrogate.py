"""The fast path: the model's terms tabulated once per campaign and interpolated for
every record.

What a record needs from the physics depends on its height, its mean speed U, the wind
direction relative to the lidar's heading theta, and its motion. The tables
(:class:`Tables`) hold, per campaign height:

* the spectral path (:mod:`uq.campaign.spectra`): the filtering factor F, the spread of
  the record variance and the point's record fraction, on :data:`SPEED_NODES` speeds
  (log-spaced over the campaign's) times :data:`SPECTRAL_DIRECTIONS` directions;
  interpolated by a Lagrange polynomial in log U and trigonometrically in theta (F has
  every harmonic of theta: a four-beam scan's fourth is the largest, the beams' timing
  adds the odd ones; 13 nodes are exact to the sixth, and the seventh and eighth of a
  pulsed DBS at 40-80 m hold below 1e-3 of F);
* the motion's response ``y_s(f)`` of each motion shape r_s (:mod:`uq.campaign.motion`;
  :func:`uq.campaign.adapter.motion_jacobian` of the component of amplitude r_s), its
  curvature ``g_s(f) = 2 r_s^H G(f) r_s`` (:func:`~uq.campaign.adapter.motion_shift`)
  and the per-scan noise variance, on :data:`MOTION_DIRECTIONS` directions, a uniform
  frequency grid and :data:`MOTION_SPEEDS` speeds. These are exact in U and theta by
  their form: the radial velocities are linear in the wind vector and in the platform's
  velocity, the reconstruction is linear in the radial velocities, and ``Vh = |u_h|`` is
  linearised about the mean wind, so that ``z = z0 + U z1`` with harmonics of theta up to
  2, the noise variance is a quadratic in U with harmonics up to 4, and ``G = U G1 + G0 +
  G_1 / U`` (the second order of ``|u_h + e|`` holds ``|e_perp|^2 / (2 U)``) with
  harmonics up to 4; nine directions hold harmonics up to 4. In frequency they are cubic
  Lagrange interpolants.

Each node of a table is an independent task (:func:`spectral_node`, :func:`motion_node`):
on a dask cluster they run on its workers, with the same numbers.

The tables' error is measured for every campaign (:func:`check_points`,
:func:`table_errors`): the spectral path run directly between the nodes (the middle of
each speed interval, half-way between two directions) and the motion's response at
frequencies half-way between its nodes, against the tables.
"""
import dataclasses

import numpy as np

from uq.campaign import adapter, spectra
from uq.campaign.interpolation import (lagrange_weights, log_lagrange_weights,
                                       periodic_nodes, periodic_weights)
from uq.constants import FULL_CIRCLE_DEG

#: Directions of the spectral tables over the circle [1] (odd: no Nyquist harmonic).
SPECTRAL_DIRECTIONS = 11
#: Directions of the motion tables [1]: nine hold harmonics up to 4, the highest the
#: motion's terms have (module docstring).
MOTION_DIRECTIONS = 9
#: Harmonics of theta each motion term has (module docstring).
RESPONSE_DEGREE, CURVATURE_DEGREE, NOISE_DEGREE = 2, 4, 4
#: Speed nodes of the spectral tables [1] (log-spaced over the campaign's speeds): F
#: changes with U only through the scan's timing and the record's high-pass, smoothly
#: in log U; the check points measure the cubic's error.
SPEED_NODES = 4
#: Speeds of the motion tables [1]: three fix the exact forms in U (module docstring).
MOTION_SPEEDS = 3
#: The motion tables' frequency grid [Hz]: step and highest frequency. The response
#: varies over ~1 / (the spread of the beams' times) ~ 0.25 Hz; the check points measure
#: the cubic's error. Motion above the highest frequency (periods under 0.5 s) is
#: outside the tables.
FREQUENCY_STEP, FREQUENCY_TOP = 0.01, 2.0
#: Step of the curvature's frequency grid [Hz]: the bias is a percent-level correction
#: of the mean and its terms are as smooth in f as the response.
CURVATURE_STEP = 0.04


def frequency_grid(step, top=FREQUENCY_TOP):
    """``step, 2 step, ..., top`` [Hz]."""
    return step * (1 + np.arange(int(round(top / step))))


@dataclasses.dataclass(frozen=True)
class Tables:
    """The tabulated terms of a campaign (module docstring). Heights (n_h,) [m]; theta
    relative to the lidar's heading ``heading`` [deg]; S motion shapes."""

    heights: np.ndarray
    heading: float
    speeds: np.ndarray                 # spectral speed nodes (n_u,) [m s-1]
    filtering: np.ndarray              # F (n_h, n_u, n_theta) [1]
    spread: np.ndarray                 # (n_h, n_u, n_theta) [1]
    point_fraction: np.ndarray         # (n_h, n_u, n_theta) [1]
    cross: np.ndarray                  # cross response q (n_h, n_u, n_theta, n_q) [1]
    motion_speeds: np.ndarray          # (3,) [m s-1]
    response: np.ndarray               # y (n_h, 3, n_m, n_f, S) [m s-1 per amplitude]
    curvature: np.ndarray              # g (n_h, 3, n_m, n_g, S) [m s-1 per amplitude^2]
    noise: np.ndarray                  # per-scan noise variance (n_h, 3, n_m) [m2 s-2]
    cross_step: float                  # [Hz]: q's frequencies 0, step, ... 1 / (2 T_s)
    response_step: float               # [Hz]: the response's frequencies step, 2 step, ...
    curvature_step: float              # [Hz]: the curvature's
    n_scans: int
    scan_period: float
    record_duration: float

    @property
    def spectral_directions(self):
        return self.filtering.shape[2]

    @property
    def motion_directions(self):
        return self.noise.shape[2]


def speed_nodes(low, high, count=SPEED_NODES):
    """`count` log-spaced speeds from `low` to `high` [m s-1]."""
    return np.geomspace(low, high, count)


def cross_frequencies(scan_period, n_scans):
    """The cross response's frequencies [Hz]: 0 to half the scan rate, four a 1 / T (the
    response is smooth on the scale of the record's resolution 1 / T)."""
    return np.linspace(0.0, 0.5 / scan_period, 2 * n_scans + 1)


def spectral_node(lidar, heights, scales, turbulence, record_duration, speed, direction):
    """(F, spread and point fraction of each height, shape (3, n_h); the cross response
    of each height on :func:`cross_frequencies`, shape (n_h, n_q)) at one node; the
    heights grouped by their length scale `scales` [m] (one spectral path per group: the
    field is homogeneous, so a gate's variances do not depend on the reference point)."""
    out, cross = np.zeros((3, len(heights))), None
    for scale in sorted(set(scales)):
        group = [i for i, s in enumerate(scales) if s == scale]
        settings = adapter.gate_settings(lidar, [heights[i] for i in group],
                                         {**turbulence, "length_scale": scale},
                                         record_duration, speed, direction)
        terms = adapter.spectral_terms(settings)
        n = adapter.scans_per_record(settings)
        grid = cross_frequencies(terms.scan_period, n)
        cross = np.zeros((len(heights), grid.size)) if cross is None else cross
        for column, i in enumerate(group):
            gate = terms.gate(column)
            covariance = spectra.scan_covariance(gate, n)
            out[:, i] = (spectra.filtering_factor(gate), spectra.toeplitz_spread(covariance),
                         spectra.point_fraction(gate))
            cross[i] = spectra.cross_response(covariance, terms.scan_period, grid)
    return out, cross


def motion_node(lidar, height, scale, turbulence, record_duration, speed, direction,
                shapes, response_frequencies, curvature_frequencies):
    """(y (n_f, S), g (n_g, S), noise variance) of one height at one node."""
    settings = adapter.gate_settings(lidar, [height], {**turbulence, "length_scale": scale},
                                     record_duration, speed, direction)
    shapes = np.asarray(shapes, complex)
    return (_per_shape(adapter.motion_jacobian, settings, response_frequencies, shapes),
            2.0 * _per_shape(adapter.motion_shift, settings, curvature_frequencies, shapes),
            adapter.scan_noise_variance(settings))


def _per_shape(function, settings, frequency, shapes):
    """`function` (:func:`uq.campaign.adapter.motion_jacobian` or ``motion_shift``) of
    every shape at every frequency, shape (n_f, S): the component of amplitude r_s."""
    count = len(shapes)
    values = function(settings, np.repeat(frequency, count), np.tile(shapes, (len(frequency), 1)))
    return values.reshape(len(frequency), count)


def build_tables(lidar, heights, scales, turbulence, record_duration, speed_range, shapes,
                 submit=None):
    """:class:`Tables` of the campaign lidar (validated scenario settings) at `heights`
    [m] of length scales `scales` [m], Mann's `turbulence` (``model``, ``anisotropy``),
    over `speed_range` (low, high) [m s-1], for the motion `shapes` (S, 6). `submit`:
    ``(function, *args) -> future`` of a dask client, or None (here, in order); every
    node is the same computation either way."""
    heights, scales = [float(h) for h in heights], [float(s) for s in scales]
    heading = float(lidar["ship"]["heading"])
    speeds = speed_nodes(*speed_range)
    motion_speeds = speed_nodes(*speed_range, MOTION_SPEEDS)
    run = runner(submit)
    spectral = [[run(spectral_node, lidar, heights, scales, turbulence, record_duration, u,
                     heading + np.degrees(t)) for t in periodic_nodes(SPECTRAL_DIRECTIONS)]
                for u in speeds]
    grids = frequency_grid(FREQUENCY_STEP), frequency_grid(CURVATURE_STEP)
    motion = [[[run(motion_node, lidar, h, s, turbulence, record_duration, u,
                    heading + np.degrees(t), shapes, *grids)
                for t in periodic_nodes(MOTION_DIRECTIONS)] for u in motion_speeds]
              for h, s in zip(heights, scales)]
    spectral = [[result(task) for task in row] for row in spectral]
    cross = np.array([[node[1] for node in row] for row in spectral])       # (u, t, h, q)
    spectral = np.array([[node[0] for node in row] for row in spectral])    # (u, t, 3, h)
    motion = [[[result(task) for task in row] for row in rows] for rows in motion]
    probe = adapter.gate_settings(lidar, heights[:1], {**turbulence,
                                                       "length_scale": scales[0]},
                                  record_duration)
    return Tables(
        heights=np.array(heights), heading=heading, speeds=speeds,
        filtering=np.moveaxis(spectral[:, :, 0], -1, 0),
        spread=np.moveaxis(spectral[:, :, 1], -1, 0),
        point_fraction=np.moveaxis(spectral[:, :, 2], -1, 0),
        cross=np.moveaxis(cross, 2, 0),
        cross_step=0.5 / adapter.scan_period(probe) / (cross.shape[-1] - 1),
        motion_speeds=motion_speeds,
        response=np.array([[[node[0] for node in row] for row in rows] for rows in motion]),
        curvature=np.array([[[node[1] for node in row] for row in rows] for rows in motion]),
        noise=np.array([[[node[2] for node in row] for row in rows] for rows in motion]),
        response_step=FREQUENCY_STEP, curvature_step=CURVATURE_STEP,
        n_scans=adapter.scans_per_record(probe), scan_period=adapter.scan_period(probe),
        record_duration=float(record_duration))


def runner(submit):
    """`(function, *args) -> task` of a dask client's `submit`, or of a call here."""
    if submit is None:
        return lambda function, *args: function(*args)
    return submit


def result(task):
    """A task's value (a dask future's result, or the value itself)."""
    return task.result() if hasattr(task, "result") else task


# --- evaluation ------------------------------------------------------------------------

def relative_angle(heading, direction):
    """theta [rad] of wind directions [deg] relative to the lidar's `heading` [deg]."""
    return np.radians(np.mod(np.asarray(direction, float) - heading, FULL_CIRCLE_DEG))


def spectral_at(tables, height_index, speed, direction):
    """(F, spread, point fraction) [1] of records (height index, U [m s-1], direction
    [deg], each (n,)); speeds clamped into the table's range (the caller flags them)."""
    speed = np.clip(np.asarray(speed, float), tables.speeds[0], tables.speeds[-1])
    wu = log_lagrange_weights(speed, tables.speeds)                       # (n, u)
    wt = periodic_weights(relative_angle(tables.heading, direction),
                          tables.spectral_directions)
    return tuple(np.einsum("nut,nu,nt->n", table[height_index], wu, wt)
                 for table in (tables.filtering, tables.spread, tables.point_fraction))


def speed_weights(nodes, speed, powers):
    """Weights (n, len(nodes)) of the nodes' values that evaluate the least-squares fit
    ``sum_p c_p U^p`` (`powers`: the exact form in U) at `speed` (n,) [m s-1]."""
    basis = np.asarray(nodes, float)[:, None] ** np.asarray(powers, float)[None]
    return (np.asarray(speed, float)[:, None] ** np.asarray(powers, float)) @ \
        np.linalg.pinv(basis)


def _motion_weights(tables, speed, direction, powers, degree):
    return (speed_weights(tables.motion_speeds, speed, powers),
            periodic_weights(relative_angle(tables.heading, direction),
                             tables.motion_directions, degree))


def _at_components(table, step, height_index, wu, wt, frequency, shape):
    """A motion table (n_h, 3, n_m, n_f, S) at the records' components (frequency (n,
    K) [Hz], shape index (n, K)): cubic in f, the speed and direction weights given."""
    n, count = np.shape(frequency)
    index, wf = lagrange_weights(np.ravel(frequency), step, step, table.shape[3])
    index, wf = index.reshape(n, count, 4), wf.reshape(n, count, 4)
    rows, shape = np.asarray(height_index)[:, None], np.asarray(shape)
    out = 0.0
    for s in range(4):
        picked = table[rows, :, :, index[:, :, s], shape]                  # (n, K, 3, m)
        out = out + np.einsum("nkum,nu,nm,nk->nk", picked, wu, wt, wf[:, :, s])
    return out


def response_at(tables, height_index, speed, direction, frequency, shape):
    """y (n, K) [m s-1 per amplitude] at the records' components."""
    wu, wt = _motion_weights(tables, speed, direction, (0, 1), RESPONSE_DEGREE)
    return _at_components(tables.response, tables.response_step, height_index, wu, wt,
                          frequency, shape)


def curvature_at(tables, height_index, speed, direction, frequency, shape):
    """g (n, K) [m s-1 per amplitude^2] at the records' components."""
    wu, wt = _motion_weights(tables, speed, direction, (-1, 0, 1), CURVATURE_DEGREE)
    return _at_components(tables.curvature, tables.curvature_step, height_index, wu, wt,
                          frequency, shape)


def cross_at(tables, height_index, speed, direction, frequency):
    """The cross response q (n, K) [1] at the records' components (frequencies (n, K)
    [Hz], folded into the scan's band), linear in frequency."""
    speed = np.clip(np.asarray(speed, float), tables.speeds[0], tables.speeds[-1])
    wu = log_lagrange_weights(speed, tables.speeds)                       # (n, u)
    wt = periodic_weights(relative_angle(tables.heading, direction),
                          tables.spectral_directions)                     # (n, t)
    f = spectra.folded(frequency, tables.scan_period) / tables.cross_step
    lower = np.clip(np.floor(f).astype(int), 0, tables.cross.shape[-1] - 2)
    weight = f - lower
    rows = np.asarray(height_index)[:, None]
    out = 0.0
    for index, w in ((lower, 1.0 - weight), (lower + 1, weight)):
        picked = tables.cross[rows, :, :, index]                          # (n, K, u, t)
        out = out + np.einsum("nkut,nu,nt->nk", picked, wu, wt) * w
    return out


def noise_at(tables, height_index, speed, direction):
    """Per-scan noise variance [m2 s-2] of records (n,)."""
    wu, wt = _motion_weights(tables, speed, direction, (0, 1, 2), NOISE_DEGREE)
    return np.einsum("num,nu,nm->n", tables.noise[np.asarray(height_index)], wu, wt)


# --- the tables' error ------------------------------------------------------------------

def check_points(tables):
    """(speed [m s-1], direction [deg]) pairs between the spectral nodes: the geometric
    middle of each speed interval at directions half-way between two table directions
    (the worst places of both interpolants), alternating along the circle."""
    middles = np.sqrt(tables.speeds[:-1] * tables.speeds[1:])
    step = FULL_CIRCLE_DEG / tables.spectral_directions
    return [(float(u), tables.heading + step * (0.5 + 5 * i) % FULL_CIRCLE_DEG)
            for i, u in enumerate(middles)]


def spectral_errors(tables, lidar, scales, turbulence, submit=None):
    """Largest relative error of the tables' F, as that of the TI it corrects (``|sqrt(F_
    table / F_direct) - 1|``), and of the spread, over the check points and heights,
    against the spectral path run there (:func:`spectral_node`)."""
    run = runner(submit)
    points = check_points(tables)
    direct = [run(spectral_node, lidar, list(tables.heights), scales, turbulence,
                  tables.record_duration, u, d) for u, d in points]
    ti, spread = 0.0, 0.0
    for (u, d), task in zip(points, direct):
        value = result(task)[0]
        for i in range(len(tables.heights)):
            f, s, _ = spectral_at(tables, np.array([i]), np.array([u]), np.array([d]))
            ti = max(ti, abs(float(np.sqrt(f[0] / value[0, i])) - 1.0))
            spread = max(spread, abs(float(s[0] / value[1, i]) - 1.0))
    return ti, spread


def motion_errors(tables, lidar, scales, turbulence, shapes):
    """Largest error of the tables' motion response at frequencies half-way between
    their nodes, at a check point, relative to the response's largest magnitude over the
    frequencies (the motion variance's relative error is at most twice it), per
    height: the largest."""
    u, d = check_points(tables)[0]
    middle = frequency_grid(tables.response_step)[:-1] + tables.response_step / 2.0
    worst = 0.0
    for i, (h, scale) in enumerate(zip(tables.heights, scales)):
        settings = adapter.gate_settings(lidar, [h], {**turbulence, "length_scale": scale},
                                         tables.record_duration, u, d)
        direct = _per_shape(adapter.motion_jacobian, settings, middle, shapes)
        count = len(shapes)
        table = response_at(tables, np.full(middle.size, i), np.full(middle.size, u),
                            np.full(middle.size, d), np.repeat(middle[:, None], count, 1),
                            np.tile(np.arange(count), (middle.size, 1)))
        scale_y = np.max(np.abs(direct), axis=0)
        worst = max(worst, float(np.max(np.abs(table - direct) / np.where(scale_y > 0, scale_y, 1))))
    return worst
