"""A lidar's sampling of a turbulent field over a record, and the record's statistics.

The Monte Carlo path of turbulent records: a box of :mod:`uq.physics.turbulencebox` holds the
frozen field ``u'_0``; each beam of each scan sees, at its true (possibly moving) probe
points and times, the radial velocity ``v_r = sum_n W_n d . u'_0(p_n - U t e_x)``, averaged
over the beam's dwell (Taylor's hypothesis, :mod:`uq.physics.scangeometry`). The pipeline
adds these turbulent radial velocities to the measurement model as an additive radial
velocity, so the platform's motion, INS errors and correction stay the existing models'.

Conventions
-----------
* Mean-wind frame (x downwind, y left, z up) [m], times [s] from the start of the record;
  scan s starts at ``s scan_period``; a beam's time is its dwell's middle.
* A beam's dwell is a box-car in time, integrated by the midpoint rule on nodes no more
  than one cell's advection apart (``U dt <= dx``); ``dwell = 0`` is one instant.
* The probe's quadrature (offsets along the beam, weights per gate) is the geometry's.
* Between grid nodes the field is interpolated trilinearly (periodic where the box is).
* A moving beam: its lidar is at ``lidar_position + displacement`` and points along the
  given true direction; its gates keep their nominal ranges from the lidar.
"""
import numpy as np

from uq.constants import FULL_CIRCLE_DEG, SAMPLING_CHUNK_POINTS


def sample_velocity(box, points, times, speed, xp=np):
    """Turbulent velocity of a frozen field at points and times, trilinear.

    Parameters
    ----------
    box : TurbulenceBox
        The field at t = 0 (:mod:`uq.physics.turbulencebox`).
    points : array, shape (..., 3)
        Positions in the mean-wind frame relative to the reference point [m].
    times : array
        Times [s], broadcastable with ``points.shape[:-1]``.
    speed : float
        Mean wind speed U [m s-1] (Taylor: ``u'(r, t) = u'_0(r - U t e_x)``).
    xp : module
        The box's array namespace.

    Returns
    -------
    array, shape (broadcast of ``points.shape[:-1]`` and ``times.shape``) + (3,)
        (u', v', w') [m s-1].

    Raises
    ------
    ValueError
        A point outside a box that is not periodic in y and z.
    """
    grid = box.grid
    points, times = xp.asarray(points, dtype=float), xp.asarray(times, dtype=float)
    shape = np.broadcast_shapes(points.shape[:-1], times.shape)
    points = xp.broadcast_to(points, shape + (3,))
    times = xp.broadcast_to(times, shape)
    shift = xp.stack([speed * times, xp.zeros_like(times), xp.zeros_like(times)], axis=-1)
    cell = (points - shift - xp.asarray(grid.origin)) / xp.asarray(grid.spacing)
    _check_inside(cell, grid, xp)
    base = xp.floor(cell)
    frac = cell - base
    base = base.astype(xp.int64)
    shape = grid.shape
    flat = box.velocity.reshape(3, -1)
    total = 0.0
    for corner in range(8):
        offset = [(corner >> axis) & 1 for axis in range(3)]
        index = [(base[..., a] + offset[a]) % shape[a] for a in range(3)]
        weight = 1.0
        for a in range(3):
            weight = weight * (frac[..., a] if offset[a] else 1.0 - frac[..., a])
        linear = (index[0] * shape[1] + index[1]) * shape[2] + index[2]
        total = total + weight[..., None] * xp.moveaxis(flat[:, linear], 0, -1)
    return total


def _check_inside(cell, grid, xp):
    """Raise if a cell coordinate leaves a box that is not periodic in y and z."""
    if grid.periodic_yz:
        return
    for axis in (1, 2):
        low, high = float(xp.min(cell[..., axis])), float(xp.max(cell[..., axis]))
        if low < 0 or high > grid.shape[axis] - 1:
            raise ValueError(f"a probe point leaves the turbulence box along "
                             f"{'xyz'[axis]} (cells {low:.1f} to {high:.1f} of "
                             f"{grid.shape[axis] - 1}): size it with box_for")


def lidar_position(geometry):
    """The lidar's position: the point nearest to every beam's line [m], shape (3,).

    Least squares over the lines through each beam's gate centres along its direction;
    raises ValueError if the beams are parallel (one staring beam: give the position).
    """
    d = np.asarray(geometry.directions)
    projector = np.eye(3) - d[:, :, None] * d[:, None, :]           # (beams, 3, 3)
    anchors = np.asarray(geometry.gate_centres)[:, 0, :]
    matrix = projector.sum(axis=0)
    if np.linalg.matrix_rank(matrix) < 3:
        raise ValueError("the beams are parallel: give lidar_position explicitly")
    return np.linalg.solve(matrix, np.einsum("bij,bj->i", projector, anchors))


def gate_ranges(geometry, position):
    """Distance of each gate centre from the lidar along its beam [m], (n_beams, n_gates)."""
    relative = np.asarray(geometry.gate_centres) - np.asarray(position)
    return np.einsum("bgi,bi->bg", relative, np.asarray(geometry.directions))


def scan_times(geometry, n_scans, start_time=0.0):
    """Mid time of each scan [s], shape (n_scans,): its start plus its beams' mean time."""
    return start_time + np.arange(n_scans) * geometry.scan_period + np.mean(geometry.times)


def dwell_offsets(geometry, spacing):
    """Midpoint nodes of a beam's dwell, offsets from its mid time [s], shape (n,).

    ``n = ceil(U dwell / spacing)`` nodes (at least one), so consecutive nodes are at most
    one cell of advection apart.
    """
    count = max(1, int(np.ceil(geometry.speed * geometry.dwell / spacing)))
    return (np.arange(count) + 0.5) / count * geometry.dwell - geometry.dwell / 2.0


def record_radial_velocities(box, geometry, n_scans, displacements=None, directions=None,
                             position=None, start_time=0.0, xp=np):
    """Turbulent radial velocity of every beam and gate of every scan of a record.

    Parameters
    ----------
    box : TurbulenceBox
        The frozen field (sized with :func:`uq.physics.turbulencebox.box_for`).
    geometry : ScanGeometry
        The scan (nominal beams, gates, times, dwell, probe quadrature, speed).
    n_scans : int
        Scans in the record.
    displacements : array_like, broadcastable to (n_scans, n_beams, 3), optional
        The lidar's displacement from its nominal position during each beam [m]
        (platform motion), mean-wind frame.
    directions : array_like, broadcastable to (n_scans, n_beams, 3), optional
        True unit vector of each beam [1] (platform attitude); default the nominal ones.
    position : array_like, shape (3,), optional
        Nominal lidar position [m]; default :func:`lidar_position` (needed only with
        ``directions``).
    start_time : float
        Time of the record's first scan start [s].
    xp : module
        The box's array namespace.

    Returns
    -------
    array of ``xp``, shape (n_scans, n_beams, n_gates)
        Radial velocity [m s-1], positive away from the lidar, of the turbulence alone
        (on the box's device: ``.get()`` a CuPy array for numpy).
    """
    nominal = np.asarray(geometry.directions)
    true_dirs = np.broadcast_to(nominal if directions is None else directions,
                                (n_scans, geometry.n_beams, 3))
    moved = np.broadcast_to(0.0 if displacements is None else displacements,
                            (n_scans, geometry.n_beams, 3))
    if directions is None:
        lidar, ranges = np.zeros(3), None
    else:
        lidar = lidar_position(geometry) if position is None else np.asarray(position, float)
        ranges = gate_ranges(geometry, lidar)
    dwell = dwell_offsets(geometry, min(box.grid.spacing))
    if xp is np:                    # compiled, unless a first run leaves it to numpy
        from uq.compileguard import cached_kernels
        kernels = cached_kernels("uq.physics.turbulencekernels")
        if kernels is not None:
            return _compiled_scans(box, geometry, n_scans, true_dirs, moved, lidar, ranges,
                                   dwell, start_time, kernels.radial_samples)
    per_scan = geometry.n_beams * geometry.n_gates * np.size(geometry.probe_offsets) * dwell.size
    step = max(1, SAMPLING_CHUNK_POINTS // per_scan)
    parts = [_scans(box, geometry, s, min(s + step, n_scans), true_dirs, moved, lidar, ranges,
                    dwell, start_time, xp) for s in range(0, n_scans, step)]
    return xp.concatenate(parts, axis=0)


def _compiled_scans(box, geometry, n_scans, directions, moved, lidar, ranges, dwell, start,
                    radial_samples):
    """:func:`record_radial_velocities` on the host by the compiled
    :func:`uq.physics.turbulencekernels.radial_samples` (the same points, times and
    sums as :func:`_scans`, without its temporaries; nodes of zero weight skipped)."""
    grid, offsets = box.grid, np.asarray(geometry.probe_offsets, dtype=float)
    shape = (geometry.n_beams, geometry.n_gates, offsets.size)
    if ranges is None:                  # nominal directions: move the nominal points
        fixed, anchor, along = geometry.probe_points(), moved, np.zeros(shape)
    else:
        fixed = np.zeros(shape + (3,))
        anchor = lidar + moved
        along = ranges[:, :, None] + offsets[None, None, :]
    times = (start + np.arange(n_scans)[:, None] * geometry.scan_period
             + np.asarray(geometry.times)[None, :])                     # (S, B)
    out = np.empty((n_scans, geometry.n_beams, geometry.n_gates))
    def c(array):                       # the kernel's types: float64, C order, writable
        return np.require(array, np.float64, ("C", "W"))
    outside = radial_samples(
        *(c(box.velocity[k]) for k in range(3)), c(grid.origin), c(grid.spacing),
        bool(grid.periodic_yz), c(fixed), c(anchor), c(directions), c(along), c(times),
        c(dwell), c(geometry.probe_weights), float(geometry.speed), out)
    if outside:
        raise ValueError(f"{outside} probe point(s) leave the turbulence box along y or z: "
                         "size it with box_for")
    return out


def _scans(box, geometry, first, last, directions, moved, lidar, ranges, dwell, start, xp):
    """Radial velocities of scans first..last-1, shape (last - first, n_beams, n_gates)."""
    d = directions[first:last]                                          # (S, B, 3)
    offsets = np.asarray(geometry.probe_offsets)
    if ranges is None:                  # nominal directions: move the nominal points
        points = geometry.probe_points()[None] + moved[first:last, :, None, None, :]
    else:
        along = ranges[None, :, :, None] + offsets[None, None, None, :]   # (1, B, G, N)
        points = (lidar + moved[first:last, :, None, None, :]
                  + along[..., None] * d[:, :, None, None, :])
    times = (start + np.arange(first, last)[:, None] * geometry.scan_period
             + np.asarray(geometry.times)[None, :])                     # (S, B)
    node_times = times[:, :, None, None, None] + dwell                 # (S, B, 1, 1, J)
    velocity = sample_velocity(box, xp.asarray(points)[..., None, :],
                               xp.asarray(node_times), geometry.speed, xp)  # (S,B,G,N,J,3)
    radial = xp.sum(velocity * xp.asarray(d)[:, :, None, None, None, :], axis=-1)
    weights = xp.asarray(geometry.probe_weights)[None, None, :, :]       # (1, 1, G, N)
    return xp.sum(xp.mean(radial, axis=-1) * weights, axis=-1)


def reference_series(box, speed, times, point=(0.0, 0.0, 0.0), xp=np):
    """The field's turbulent velocity at the reference point [m s-1], shape (n_times, 3).

    ``times`` [s], shape (n_times,); the true series whose statistics are
    ``turbulence_intensity_true`` (u = U + u').
    """
    times = xp.asarray(times, dtype=float)
    points = xp.broadcast_to(xp.asarray(point, dtype=float), times.shape + (3,))
    return sample_velocity(box, points, times, speed, xp)


def reference_line_series(box, speed, times, xp=np):
    """The field's turbulent velocity at the reference point (0, 0, 0) [m s-1], shape
    (n_times, 3), read on its line of nodes along x (:func:`uq.physics.turbulencebox.
    box_for` puts it on one) by Fourier interpolation of that line: exact for the box's
    field, which is periodic along x and holds no wavenumber above its Nyquist's (the
    trilinear interpolation of :func:`reference_series` between nodes loses variance,
    up to 2/3 of it at the Nyquist wavenumber per direction).

    ``x = -U t`` (Taylor) in cells of the line: ``u(x) = (1/n) sum_q U_q exp(2 pi i q x /
    n)`` over the line's discrete Fourier coefficients, the Nyquist term as its cosine."""
    grid = box.grid
    velocity = xp.asarray(box.velocity)
    j, m = (int(round((0.0 - grid.origin[a]) / grid.spacing[a])) for a in (1, 2))
    line = velocity[:, :, j, m]                                       # (3, nx)
    n = line.shape[1]
    coefficients = xp.fft.rfft(line, axis=1) / n                     # (3, n // 2 + 1)
    scale = xp.full(coefficients.shape[1], 2.0)
    scale[0] = 1.0
    if n % 2 == 0:
        scale[-1] = 1.0
    coefficients = coefficients * scale
    position = (-speed * xp.asarray(times, dtype=float) - grid.origin[0]) / grid.spacing[0]
    q = xp.arange(coefficients.shape[1])
    out = xp.empty((position.size, 3))
    for start in range(0, position.size, 4096):
        phase = xp.exp(2j * np.pi * xp.outer(position[start:start + 4096], q) / n)
        out[start:start + 4096] = (phase @ coefficients.T).real
    return out


def reconstruct_scans(radial, geometry):
    """Apply the geometry's reconstruction operator to each scan.

    Parameters
    ----------
    radial : array, shape (n_scans, n_beams, n_gates)
        Radial velocities [m s-1].
    geometry : ScanGeometry

    Returns
    -------
    array, shape (n_scans, n_gates, 3)
        Reconstructed (x, y, z) wind [m s-1].
    """
    return np.einsum("gib,sbg->sgi", np.asarray(geometry.reconstruction), np.asarray(radial))


def record_statistics(wind, mean_direction=None, axis=0, ddof=1):
    """A record's statistics as a lidar's software reduces its scans.

    Parameters
    ----------
    wind : array_like, shape (..., 3)
        Reconstructed wind per scan, (u, v, w) along (x, y, z) of the mean-wind frame
        [m s-1] (u includes the mean speed), scans along ``axis``.
    mean_direction : float, optional
        Meteorological direction of the mean wind (from, clockwise from north) [deg]:
        the directions are then meteorological; without it, the angle of the horizontal
        wind from +x, counter-clockwise [deg].
    axis : int
        The scans' axis of ``wind`` (not the last).
    ddof : int
        Delta degrees of freedom of the standard deviations (1: the sample's).

    Returns
    -------
    dict of ndarray
        ``speed_mean``, ``speed_std`` (horizontal speed Vh [m s-1]), ``u_mean``,
        ``u_std``, ``v_mean``, ``v_std``, ``w_mean``, ``w_std`` [m s-1],
        ``direction_mean`` [deg] (circular mean, in [0, 360)) and ``direction_std``
        [deg] (circular standard deviation sqrt(-2 ln R), Mardia & Jupp (2000) Eq. 2.3.11).
    """
    wind = np.asarray(wind, dtype=float)
    u, v, w = wind[..., 0], wind[..., 1], wind[..., 2]
    speed = np.hypot(u, v)
    angle = np.arctan2(v, u)
    resultant = np.mean(np.exp(1j * angle), axis=axis)
    mean_angle = np.degrees(np.angle(resultant))
    spread = np.degrees(np.sqrt(-2.0 * np.log(np.minimum(np.abs(resultant), 1.0))))
    # counter-clockwise from x is clockwise "from" D: D - angle (scangeometry's frame)
    direction = mean_angle if mean_direction is None else mean_direction - mean_angle
    out = {"speed_mean": speed.mean(axis=axis), "speed_std": speed.std(axis=axis, ddof=ddof),
           "direction_mean": np.mod(direction, FULL_CIRCLE_DEG), "direction_std": spread}
    for name, values in (("u", u), ("v", v), ("w", w)):
        out[f"{name}_mean"] = values.mean(axis=axis)
        out[f"{name}_std"] = values.std(axis=axis, ddof=ddof)
    return out
