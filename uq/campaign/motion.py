"""Each record's platform motion as harmonic components, and what it does to the record.

Representation (:class:`MotionSet`). A record's motion is a sum of components, each of
frequency f [Hz] and complex amplitude ``a = A r_s`` (conventions of
:mod:`uq.campaign.adapter`: ``x_d(t) = Im(a_d exp(i (w t + phi)))``, roll, pitch, yaw in
rad, surge, sway, heave in m): a scalar amplitude A and one of a few *shapes* r_s shared
by the campaign (S, 6). A component enters through its *power* ``P = |A|^2 / 2`` (the
variance it gives a degree of freedom of unit shape); the phases of different components
are independent (uniform).

* A sea state (Hs, Tp) and the buoy's response: one shape, the response factors per
  metre of wave amplitude with their phase lags ``r_d = R_d exp(i lag_d)``; the JONSWAP
  components of :func:`uq.physics.waves.jonswap_components`, whose amplitudes scale
  with Hs and frequencies with 1/Tp (the spectrum normalised to Hs has the same shape in
  f / fp for every Tp, its band a multiple of fp).
* Per-record statistics of each degree of freedom (a standard deviation or an amplitude
  and a period): one shape per degree of freedom (the unit vector), one component each;
  the degrees of freedom are taken as independent (their relative phases unknown).
* Cross-spectra of an IMU log (:mod:`uq.campaign.imu`): the 6 x 6 Hermitian matrix
  ``M = sum a a^H / 2`` of each frequency bin, written in the 36 shapes of the
  polarisation basis (``e_d``, ``e_d + e_e``, ``e_d + i e_e``), whose powers may be
  negative (any Hermitian matrix is a real combination of them).

The record's motion variance and bias follow from the response ``y_s = r_s^H z`` and the
curvature ``g_s = 2 r_s^H G r_s`` of each shape at each component's frequency
(:mod:`uq.campaign.adapter`): ``var = sum_k P_k |y_k|^2 (1 - |D_N(f_k)|^2)`` (the GUM's
variance ``z^H M z``, the record's high-pass of Eq. 3 of :mod:`uq.physics.lidarspectral`)
and ``bias = sum_k P_k g_k`` (``a^H G a``).
"""
import dataclasses

import numpy as np

from uq.physics.motion import ANGULAR, DEGREES_OF_FREEDOM


@dataclasses.dataclass(frozen=True)
class MotionSet:
    """Components of each record's motion (module docstring).

    Attributes
    ----------
    shapes : ndarray, shape (S, 6), complex
        r_s per unit of A [rad or m per unit].
    frequency : ndarray, shape (n, K)
        [Hz]; zero power pads a record with fewer components.
    shape : ndarray of int, shape (n, K)
        Shape index of each component.
    power : ndarray, shape (n, K)
        ``P = |A|^2 / 2`` [unit of A squared].
    valid : ndarray of bool, shape (n,)
        Records whose motion is known (the others are NaN in the results).
    labels : tuple of str
        A name of each shape, for the report.
    random_phases : bool
        Whether the components' phases are unknown and independent (a sea state,
        statistics): the record's sample variance of the motion then spreads
        (:func:`uq.campaign.spectra.phase_variance`); an IMU log's are what they were.
    """

    shapes: np.ndarray
    frequency: np.ndarray
    shape: np.ndarray
    power: np.ndarray
    valid: np.ndarray
    labels: tuple
    random_phases: bool = True

    @property
    def count(self):
        return int(np.shape(self.frequency)[0])

    def take(self, index):
        """The records at `index` (an integer array)."""
        return dataclasses.replace(self, frequency=self.frequency[index],
                                   shape=self.shape[index], power=self.power[index],
                                   valid=self.valid[index])

    def within(self, low, high):
        """(the set with only the components of frequency in [low, high] [Hz], the share
        of each record's motion power left out [1])."""
        inside = (self.frequency >= low) & (self.frequency <= high)
        total = np.sum(np.abs(self.power), axis=1)
        dropped = np.sum(np.abs(np.where(inside, 0.0, self.power)), axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            share = np.where(total > 0, dropped / total, 0.0)
        kept = dataclasses.replace(self, frequency=np.where(inside, self.frequency, low),
                                   power=np.where(inside, self.power, 0.0))
        return kept, share


def no_motion(count):
    """A set of `count` records without motion (every record valid)."""
    return MotionSet(np.zeros((0, len(DEGREES_OF_FREEDOM)), complex), np.zeros((count, 0)),
                     np.zeros((count, 0), int), np.zeros((count, 0)),
                     np.ones(count, bool), ())


def response_shape(response):
    """The shape ``r_d = R_d exp(i lag_d)`` of a buoy's response, shape (6,): `response`
    maps a degree of freedom to (factor per metre of wave amplitude [deg m-1 or m m-1],
    lag [deg])."""
    shape = np.zeros(len(DEGREES_OF_FREEDOM), complex)
    for dof, (factor, lag) in response.items():
        scale = np.radians(1.0) if dof in ANGULAR else 1.0
        shape[DEGREES_OF_FREEDOM.index(dof)] = factor * scale * np.exp(1j * np.radians(lag))
    return shape


def sea_state(hs, tp, response, gamma, components, band):
    """:class:`MotionSet` of JONSWAP seas (module docstring).

    Parameters
    ----------
    hs, tp : ndarray, shape (n,)
        Significant wave height [m] and peak period [s] of each record (NaN: unknown).
    response : dict
        dof -> (factor [deg m-1 or m m-1], lag [deg]).
    gamma : float
        Peak enhancement [1].
    components : int
        Frequency bins of the spectrum.
    band : tuple
        (lowest, highest) frequency in multiples of the peak frequency 1 / tp [1].
    """
    from uq.physics.waves import jonswap_components
    unit = jonswap_components(4.0, 1.0, gamma, components, tuple(band), {"heave": (1.0, 0.0)})
    relative = np.array([c.angular_frequency / (2 * np.pi) for c in unit])   # f / fp
    heave = DEGREES_OF_FREEDOM.index("heave")
    amplitude = np.array([c.amplitudes[heave] for c in unit])               # Hs = 4 m
    hs, tp = np.asarray(hs, float), np.asarray(tp, float)
    valid = np.isfinite(hs) & np.isfinite(tp) & (tp > 0) & (hs >= 0)
    safe_tp = np.where(valid, tp, 1.0)
    power = (np.where(valid, hs, 0.0)[:, None] / 4.0 * amplitude[None]) ** 2 / 2.0
    return MotionSet(response_shape(response)[None], relative[None] / safe_tp[:, None],
                     np.zeros(power.shape, int), power, valid, ("sea state",))


def statistics(amplitude, period):
    """:class:`MotionSet` of per-record harmonics of each degree of freedom: `amplitude`
    and `period` map a dof to arrays (n,) [rad or m; s] (module docstring)."""
    dofs = [d for d in DEGREES_OF_FREEDOM if d in amplitude]
    a = np.array([np.asarray(amplitude[d], float) for d in dofs]).T           # (n, K)
    t = np.array([np.asarray(period[d], float) for d in dofs]).T
    valid = np.all(np.isfinite(a) & np.isfinite(t) & (t > 0) & (a >= 0), axis=1)
    frequency = np.where(valid[:, None], 1.0 / np.where(t > 0, t, 1.0), 0.0)
    shapes = np.eye(len(DEGREES_OF_FREEDOM), dtype=complex)[
        [DEGREES_OF_FREEDOM.index(d) for d in dofs]]
    return MotionSet(shapes, frequency, np.tile(np.arange(len(dofs)), (a.shape[0], 1)),
                     np.where(valid[:, None], a ** 2 / 2.0, 0.0), valid, tuple(dofs))


def polarisation_shapes(dofs):
    """The polarisation basis of the given degrees of freedom (indices): ``e_d``, then
    ``e_d + e_e`` and ``e_d + i e_e`` for d < e, shape (m^2, 6), and their labels."""
    eye = np.eye(len(DEGREES_OF_FREEDOM))
    pairs = [(d, e) for i, d in enumerate(dofs) for e in dofs[i + 1:]]
    shapes = [eye[d] for d in dofs] + [eye[d] + eye[e] for d, e in pairs] + \
        [eye[d] + 1j * eye[e] for d, e in pairs]
    names = [DEGREES_OF_FREEDOM[d] for d in dofs]
    labels = names + [f"{DEGREES_OF_FREEDOM[d]}+{DEGREES_OF_FREEDOM[e]}" for d, e in pairs] \
        + [f"{DEGREES_OF_FREEDOM[d]}+i{DEGREES_OF_FREEDOM[e]}" for d, e in pairs]
    return np.array(shapes, complex), tuple(labels)


def polarisation_powers(matrix, dofs):
    """Powers (..., m^2) of the polarisation shapes whose sum ``sum P_s r_s r_s^H``
    equals the Hermitian `matrix` (..., 6, 6) on the given degrees of freedom: with
    ``Q_de = r^H M r``-free algebra, ``M_dd = sum over shapes holding d``: solved as
    ``P(e_d + e_e) = Re M_de``, ``P(e_d + i e_e) = Im M_ed`` (so that the pair's terms
    give ``M_de`` and ``M_ed``), ``P(e_d) = M_dd - sum_e (Re M_de + Im M_ed)``."""
    matrix = np.asarray(matrix, complex)
    pairs = [(d, e) for i, d in enumerate(dofs) for e in dofs[i + 1:]]
    real = [np.real(matrix[..., d, e]) for d, e in pairs]
    imaginary = [np.imag(matrix[..., e, d]) for d, e in pairs]
    diagonal = []
    for d in dofs:
        own = np.real(matrix[..., d, d])
        for (p, q), re, im in zip(pairs, real, imaginary):
            if d in (p, q):
                own = own - re - im
        diagonal.append(own)
    return np.stack(diagonal + real + imaginary, axis=-1)


def motion_variance(response, power, high_pass):
    """``sum_k P_k |y_k|^2 (1 - |D_N(f_k)|^2)`` [m2 s-2] of each record (n,) from the
    responses (n, K), powers (n, K) and high-pass (n, K) at its components."""
    return np.sum(power * np.abs(response) ** 2 * high_pass, axis=-1)


def motion_bias(curvature, power):
    """``sum_k P_k g_k`` [m s-1]: the motion's shift of the record's mean speed (n,)."""
    return np.sum(power * curvature, axis=-1)
