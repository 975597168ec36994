"""Motion of the platform during a scan: harmonic components, attitude and its rate, and
the lever arm from the motion reference point (the INS) to the lidar.

Conventions
-----------
* Time t [s] runs from the start of the scan's first beam (:mod:`uq.physics.timing`).
* Degrees of freedom (:data:`DEGREES_OF_FREEDOM`): ``roll``, ``pitch``, ``yaw`` [rad;
  roll positive starboard down, pitch positive bow up, yaw clockwise, as the marine
  attitude of :mod:`uq.physics.rotation`] and ``surge``, ``sway``, ``heave`` [m; along the
  bow, to starboard and up, in the level frame of the static heading]. The motion adds to
  the static attitude and velocity of the scene (``ship``): heading + yaw(t), pitch +
  pitch(t), roll + roll(t).
* A component k of angular frequency w_k moves each degree of freedom d as
  ``x_d(t) = A_dk sin(w_k t + psi_dk + phi_k)`` (amplitude A_dk, phase lag psi_dk of the
  degree of freedom, phase phi_k of the component). Phase 0 starts at the static
  attitude, moving in the positive sense. Written with the unit phase vector
  ``c_k = (cos phi_k, sin phi_k)``:
  ``x_d(t) = A_dk [sin(w_k t + psi_dk) c_k1 + cos(w_k t + psi_dk) c_k2]``, linear in c_k.
  A random phase (uniform over the cycle) makes c_k uniform on the unit circle: mean 0,
  covariance I/2, so that ``Cov(x(t), x(s)) = (A^2 / 2) cos(w (t - s))``, the covariance
  the GUM of :mod:`uq.physics.measurement` linearises with (about c = 0, the static
  attitude).
* Rates follow analytically: ``x_d'(t) = A_dk w_k [cos(.) c_k1 - sin(.) c_k2]``.
* Lever arm r [m] (bow, starboard, up) from the INS to the lidar, fixed in the ship
  frame: the lidar sits at ``R(t) r`` from the INS and moves with ``R'(t) r``
  (:func:`uq.physics.rotation.attitude_matrix_rate`), the omega x r of a rigid body.

References
----------
.. [1] Matavar, A. (2024). Wind field reconstruction from floating lidars. MSc thesis,
   TU Delft, Sec. 3.2, Eqs. 3.6-3.9.
.. [2] Tiana-Alsina, J., Rocadenbosch, F. and Gutierrez-Antunano, M. A. (2017). Vertical
   azimuth display simulator for wind-Doppler lidar error assessment. IGARSS 2017.
"""
from dataclasses import dataclass

import numpy as np

from uq.physics.rotation import attitude_matrix, attitude_matrix_rate, rotation_about_vertical

DEGREES_OF_FREEDOM = ("roll", "pitch", "yaw", "surge", "sway", "heave")
ANGULAR = DEGREES_OF_FREEDOM[:3]


@dataclass(frozen=True)
class MotionComponent:
    """One harmonic of the platform's motion.

    Attributes
    ----------
    angular_frequency : float
        w [rad s-1].
    amplitudes : tuple of float
        A_d per degree of freedom, in the order of :data:`DEGREES_OF_FREEDOM` [rad, m].
    lags : tuple of float
        psi_d per degree of freedom [rad].
    phase : float or None
        phi [rad]; None: random, uniform over the cycle (a Monte Carlo input).
    """

    angular_frequency: float
    amplitudes: tuple
    lags: tuple = (0.0,) * 6
    phase: float = None


@dataclass(frozen=True)
class Motion:
    """The platform's motion within a scan: harmonic components and the lever arm.

    Attributes
    ----------
    components : tuple of MotionComponent
    lever_arm : tuple of float
        (bow, starboard, up) [m] from the INS to the lidar.
    window : int
        How many of the last random-phase components are a measured record's harmonics,
        whose phases move together with the record's random start (input
        ``motion_window``); the others' phases are independent (``motion_phases``).
    """

    components: tuple = ()
    lever_arm: tuple = (0.0, 0.0, 0.0)
    window: int = 0

    @property
    def random_components(self):
        """Indices of the components with a random phase (in order)."""
        return tuple(i for i, c in enumerate(self.components) if c.phase is None)

    def unit_phases(self, random_phases=None):
        """c_k of every component, shape (n, K, 2): fixed phases as (cos, sin), random
        ones from `random_phases` (shape (n, K_random, 2), points on the unit circle;
        the GUM evaluates at their mean, 0); n = 1 without random phases."""
        fixed = [np.array([np.cos(c.phase), np.sin(c.phase)]) if c.phase is not None
                 else None for c in self.components]
        leading = (1,) if random_phases is None else np.shape(random_phases)[:-2]
        dtype = complex if np.iscomplexobj(random_phases) else float
        out = np.zeros(leading + (len(self.components), 2), dtype=dtype)
        for k, value in enumerate(fixed):
            if value is not None:
                out[..., k, :] = value
        if random_phases is not None and self.random_components:
            out[..., list(self.random_components), :] = random_phases
        return out


def degrees_of_freedom(motion, unit_phases, times):
    """Displacement and rate of every degree of freedom at `times`.

    Parameters
    ----------
    motion : Motion
    unit_phases : ndarray, shape (n, K, 2)
        c_k of every component (:meth:`Motion.unit_phases`).
    times : ndarray, shape (n, *T) or (1, *T)
        [s] from the start of the scan; the leading axis is the trials'.

    Returns
    -------
    value, rate : dict
        dof -> ndarray of shape (n, *T) [rad or m, rad s-1 or m s-1] (0.0 for a degree
        of freedom no component moves).

    Notes
    -----
    With the lag moved onto the unit phase (``sin(w t + psi) c1 + cos(w t + psi) c2 =
    sin(w t) a + cos(w t) b``, a = c1 cos psi - c2 sin psi, b = c1 sin psi + c2 cos psi;
    the rate ``w (cos(w t) a - sin(w t) b)``), each component's sine and cosine are
    taken once for every degree of freedom, and only at the times given (once for all
    trials where the times are common), and the sum over components is a product of
    matrices.
    """
    c = np.asarray(unit_phases)
    n = c.shape[0]
    times = np.asarray(times)
    value = {d: 0.0 for d in DEGREES_OF_FREEDOM}
    rate = {d: 0.0 for d in DEGREES_OF_FREEDOM}
    components = motion.components
    if not components:
        return value, rate
    w = np.array([component.angular_frequency for component in components])    # (K,)
    amplitudes = np.array([component.amplitudes for component in components])   # (K, 6)
    lags = np.array([component.lags for component in components])               # (K, 6)
    angle = np.moveaxis(w.reshape((-1,) + (1,) * times.ndim) * times, 0, 1)  # (n|1, K, *T)
    sine, cosine = np.sin(angle), np.cos(angle)
    shape = (n,) + times.shape[1:]
    for d, name in enumerate(DEGREES_OF_FREEDOM):
        amplitude = amplitudes[:, d]
        if not np.any(amplitude):
            continue
        cos_lag, sin_lag = np.cos(lags[:, d]), np.sin(lags[:, d])
        a = amplitude * (c[:, :, 0] * cos_lag - c[:, :, 1] * sin_lag)     # (n, K)
        b = amplitude * (c[:, :, 0] * sin_lag + c[:, :, 1] * cos_lag)
        value[name] = _over_components(a, sine, shape) + _over_components(b, cosine, shape)
        rate[name] = _over_components(a * w, cosine, shape) - \
            _over_components(b * w, sine, shape)
    return value, rate


def _over_components(weights, basis, shape):
    """sum_k weights[i, k] basis[i, k, ...] of weights (n, K) and basis (n or 1, K, *T),
    shape (n, *T): one product of matrices where the basis is common to the trials."""
    if basis.shape[0] == 1:
        return (weights @ basis[0].reshape(basis.shape[1], -1)).reshape(shape)
    return np.einsum("ik,ik...->i...", weights, basis)


def platform_kinematics(scene, motion, unit_phases, times):
    """Attitude, its rate and the lidar's position and velocity at `times`.

    Parameters
    ----------
    scene : uq.physics.scene.Scene
        One scene (scalar fields): the static attitude and ship velocity.
    motion : Motion
    unit_phases : ndarray, shape (n, K, 2)
    times : ndarray, shape (n, *T) or (1, *T) [s]

    Returns
    -------
    dict
        ``heading``, ``pitch``, ``roll`` [rad] and their ``*_rate`` [rad s-1], shape
        (n, *T); ``attitude`` (n, *T, 3, 3); ``lidar_offset`` (n, *T, 3): the lidar's
        displacement from its static position (translation and lever arm) [m];
        ``lidar_velocity`` (n, *T, 3) [m s-1] (earth frame north, east, up): static ship
        velocity + translational motion + lever-arm velocity; ``ins_velocity`` (n, *T,
        3): the INS's velocity (without the lever arm).
    """
    value, rate = degrees_of_freedom(motion, unit_phases, times)
    zero = np.zeros(_time_grid(times, np.shape(unit_phases)[0]).shape)
    angles = {"heading": scene.heading + value["yaw"] + zero,
              "pitch": scene.pitch + value["pitch"] + zero,
              "roll": scene.roll + value["roll"] + zero}
    rates = {"heading_rate": rate["yaw"] + zero, "pitch_rate": rate["pitch"] + zero,
             "roll_rate": rate["roll"] + zero}
    attitude = attitude_matrix(angles["heading"], angles["pitch"], angles["roll"])
    attitude_rate = attitude_matrix_rate(angles["heading"], angles["pitch"], angles["roll"],
                                         rates["heading_rate"], rates["pitch_rate"],
                                         rates["roll_rate"])
    level = rotation_about_vertical(scene.heading)                      # static heading
    translation = _stack(value["surge"], value["sway"], value["heave"], zero) @ level.T
    translation_rate = _stack(rate["surge"], rate["sway"], rate["heave"], zero) @ level.T
    arm = np.asarray(motion.lever_arm, dtype=float)
    static = attitude_matrix(scene.heading, scene.pitch, scene.roll) @ arm
    ship = np.array([scene.sog * np.cos(scene.cog), scene.sog * np.sin(scene.cog),
                     scene.heave])
    ins_velocity = ship + translation_rate
    return {**angles, **rates, "attitude": attitude,
            "lidar_offset": translation + attitude @ arm - static,
            "ins_velocity": ins_velocity,
            "lidar_velocity": ins_velocity + attitude_rate @ arm}


def _time_grid(times, n):
    """`times` (n, *T) or (1, *T) broadcast to (n, *T)."""
    times = np.asarray(times)
    return np.broadcast_to(times, (n,) + times.shape[1:])


def _stack(x, y, z, zero):
    return np.stack(np.broadcast_arrays(x + zero, y + zero, z + zero), axis=-1)
