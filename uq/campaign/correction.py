"""One record corrected: its turbulence intensity freed of the platform's motion and of
the lidar's filtering, with its uncertainty and interval, and its mean speed freed of the
motion's bias.

Model of a record (N scans of period T_s, the lidar's horizontal speed once a scan):
its variance about its own mean ``s^2 = (1/N) sum (Vh_m - mean)^2`` has the expectation
(Eq. 3 of :mod:`uq.physics.lidarspectral`, the terms independent)::

    <s^2> = F V + V_m + (N - 1) / N sigma^2                                       (1)

* V [m2 s-2]: the field's u-variance at the gate over the record, the quantity sought
  (a point sampled once a scan, the record's high-pass; :mod:`uq.campaign.spectra`);
* F [1]: the lidar's filtering factor of it (probe volume, beam separation, scan
  timing; the spectral path);
* V_m [m2 s-2]: the motion's variance (the GUM of the time-resolved model, the record's
  high-pass; :mod:`uq.campaign.motion`); where the lidar corrects its motion, what its
  correction leaves;
* sigma^2 [m2 s-2]: every other error of a scan (INS readings, radial noise), drawn
  independently scan by scan.

The estimate inverts (1): ``V = (s^2 - V_m - (N-1)/N sigma^2) / F``, with the mean
speed ``U_c = Vh_mean - b`` freed of the motion's bias b (its second-order shift of Vh,
:mod:`uq.campaign.motion`). The lidar reports its standard deviation over ``N - ddof``
scans; its variance is turned into (1) by ``(N - ddof) / N``, and the corrected TI is
given back on the lidar's own convention, ``TI = sqrt(V N / (N - ddof)) / U_c``, so that
a record without motion, filtering or scan errors is unchanged (the identity).

Interval. The turbulence's and the noise's part of s^2 is distributed as a scaled
chi-square (:mod:`uq.campaign.spectra`: ``x = s^2 - V_m ~ E chi2_nu / nu`` with ``E = F V
+ (N-1)/N sigma^2`` and nu from E and ``var(s^2)``, which both depend on V; the variance
holds the motion's cross terms with the turbulence and the scan errors). The interval
of V holds every V under which the observed x lies within the central ``p`` of its
distribution (Neyman's construction: it covers the true V with probability p, as far
as the chi-square holds), found by a fixed-point iteration on each end; the relative
standard uncertainties of F and of V_m that the configuration states widen each side
in quadrature (at ``k = Phi^-1((1+p)/2)``). ``TI_low, TI_high = sqrt(V_low, V_high) / U_c``.
A record whose x lies below the lower ``(1-p)/2`` quantile even at V = 0 (the motion
and noise alone predict more variance than it has) has no consistent V: NaN, flagged.

Standard uncertainty: ``u(V)^2 = var(s^2) / F^2 + (V u_F)^2 + (u_m V_m / F)^2`` at the
estimate, and ``u(TI) = u(V) / (2 U_c^2 TI_*)`` with ``TI_* = sqrt(max(V, u(V))) / U_c``
(the delta method, its V held away from zero by its own uncertainty).

References
----------
.. [1] Neyman, J. (1937). Outline of a theory of statistical estimation based on the
   classical theory of probability. Phil. Trans. R. Soc. A 236, 333-380.
.. [2] Sathe, A., Mann, J., Gottschall, J. and Courtney, M. S. (2011). J. Atmos. Oceanic
   Technol. 28, 853-868.
.. [3] JCGM 101:2008, 7.9.2 (numerical tolerance) and clause 8.
"""
import numpy as np
from scipy import special

from uq.campaign import spectra
from uq.constants import COVERAGE_PROBABILITY

#: Fixed-point iterations of each interval end [1]: nu changes slowly with V, so the
#: iteration contracts quickly (1e-10 relative in ~10 steps on the tests' cases); the
#: remaining step is checked against :data:`INTERVAL_TOLERANCE`.
INTERVAL_ITERATIONS = 60
#: Relative change of an interval end taken as converged [1].
INTERVAL_TOLERANCE = 1e-9
#: Significant digits of the motion's u at which its clause-8 tolerance is read (JCGM
#: 101 7.9.2 takes one or two): one, since a record's motion (a sea state and a flat
#: response, or a ten-minute IMU spectrum) is known to no better than some 10 %.
CLAUSE8_DIGITS = 1

#: The records' flags (bit, name, meaning, whether the record's values are NaN).
FLAGS = (
    (1, "missing", "no record, or its speed, standard deviation or direction missing",
     True),
    (2, "low_availability", "availability below the configured minimum", True),
    (4, "low_speed", "mean speed below the configured minimum (no frozen-turbulence "
     "record)", True),
    (8, "no_motion_data", "the platform's motion of the record is unknown", True),
    (16, "variance_below_model", "the motion and the scan errors alone predict more "
     "variance than the record has (no turbulence is consistent with it)", True),
    (32, "motion_outside_band", "over 1 % of the motion's power lies outside the "
     "tables' frequencies (left out)", False),
    (64, "motion_clause8", "the GUM's clause 8 would fail for the motion (its "
     "second-order shift of the mean exceeds the tolerance of its u)", False),
)
FLAG_BITS = {name: bit for bit, name, _, _ in FLAGS}
#: Flags that make a record's corrected values NaN.
INVALIDATING = sum(bit for bit, _, _, invalid in FLAGS if invalid)
#: Share of a record's motion power outside the tables above which it is flagged [1]:
#: the variance left out is at most that share of the motion's (a 1 % share moves a
#: corrected TI by at most 0.5 % of the motion's part).
OUTSIDE_SHARE = 0.01


def lidar_part(std, motion_variance, noise_variance, n_scans, ddof):
    """``x = s^2 - V_m`` [m2 s-2] from the reported standard deviation (ddof) and the
    expected noise part ``(N-1)/N sigma^2`` [m2 s-2] (Eq. 1)."""
    n = float(n_scans)
    variance = np.asarray(std, float) ** 2 * (n - ddof) / n
    return variance - motion_variance, (n - 1.0) / n * np.asarray(noise_variance, float)


def chi_square_quantile(probability, dof):
    """``chi2_nu(p) / nu`` [1] (vectorised; nu may be non-integer)."""
    return 2.0 * special.gammaincinv(np.asarray(dof, float) / 2.0, probability) / dof


def _distribution(lidar_variance, noise_part, spread, noise_variance, n_scans, motion=(0, 0)):
    """(E, nu) of x under the lidar variance F V (arrays); `motion`: (the motion's cross
    term sum V_k q_k, its record variance) [m2 s-2]."""
    mean = lidar_variance + noise_part
    var = spectra.variance_of_variance(lidar_variance, spread, noise_variance, n_scans,
                                       *motion)
    with np.errstate(divide="ignore", invalid="ignore"):
        dof = np.where(var > 0, spectra.degrees_of_freedom(mean, var), np.inf)
    return mean, dof


def interval_end(x, noise_part, spread, noise_variance, n_scans, probability, motion=(0, 0)):
    """The lidar variance F V [m2 s-2] under which x is the `probability` quantile of
    its distribution (fixed point of ``FV = x / q(nu(FV)) - noise``), NaN where there
    is none above 0 (x below that quantile at F V = 0); `motion` as
    :func:`_distribution`'s."""
    x = np.asarray(x, float)
    zero_mean, zero_dof = _distribution(0.0 * x, noise_part, spread, noise_variance, n_scans,
                                        motion)
    below = x < zero_mean * _quantile(probability, zero_dof)
    value = np.maximum(x - noise_part, 0.0)
    for _ in range(INTERVAL_ITERATIONS):
        _, dof = _distribution(value, noise_part, spread, noise_variance, n_scans, motion)
        new = np.maximum(x / _quantile(probability, dof) - noise_part, 0.0)
        done = np.all(np.abs(new - value) <= INTERVAL_TOLERANCE * np.maximum(new, 1e-300))
        value = new
        if done:
            break
    return np.where(below, np.nan, value)


def _quantile(probability, dof):
    """chi2_nu(p) / nu, 1 for an infinite nu (no spread)."""
    dof = np.asarray(dof, float)
    finite = np.isfinite(dof) & (dof > 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(finite, chi_square_quantile(probability, np.where(finite, dof, 1.0)),
                        1.0)


def correct(speed, std, filtering, spread, motion_variance, motion_bias, noise_variance,
            n_scans, ddof=1, coverage=COVERAGE_PROBABILITY, filtering_u=0.0, motion_u=0.0,
            motion_cross=0.0):
    """Correct records (arrays (n,), module docstring).

    Parameters
    ----------
    speed, std : ndarray
        The lidar's mean horizontal speed and its standard deviation over the record
        [m s-1] (the standard deviation with `ddof`).
    filtering, spread : ndarray
        F and the spread of the record variance [1] (:mod:`uq.campaign.spectra`).
    motion_variance, motion_bias, noise_variance : ndarray
        V_m [m2 s-2], b [m s-1], sigma^2 [m2 s-2].
    n_scans : int
    ddof : int
    coverage : float
        p of the interval.
    filtering_u, motion_u : float
        Relative standard uncertainties of F and of V_m [1].
    motion_cross : ndarray
        The motion's cross term with the turbulence ``sum_k V_k q(f_k)`` [m2 s-2]
        (:mod:`uq.campaign.spectra`).

    Returns
    -------
    dict of ndarray
        ``wind_speed_corrected`` [m s-1], ``turbulence_intensity_measured``,
        ``turbulence_intensity_corrected``, ``_u``, ``_low``, ``_high`` [1],
        ``variance_corrected`` (V) and its ``_low``, ``_high`` [m2 s-2].
    """
    speed, std = np.asarray(speed, float), np.asarray(std, float)
    corrected_speed = speed - motion_bias
    x, noise_part = lidar_part(std, motion_variance, noise_variance, n_scans, ddof)
    lidar = x - noise_part
    variance = lidar / filtering
    tail = (1.0 - coverage) / 2.0
    motion = (motion_cross, motion_variance)
    high = interval_end(x, noise_part, spread, noise_variance, n_scans, tail, motion) / \
        filtering
    low = interval_end(x, noise_part, spread, noise_variance, n_scans, 1.0 - tail, motion)
    low = np.where(np.isnan(low) & np.isfinite(high), 0.0, low) / filtering
    estimate = np.maximum(variance, 0.0)
    k = special.ndtri(1.0 - tail)
    extra = np.hypot(estimate * filtering_u, motion_u * motion_variance / filtering)
    low = np.maximum(estimate - np.hypot(estimate - np.minimum(low, estimate), k * extra), 0.0)
    high = estimate + np.hypot(np.maximum(high, estimate) - estimate, k * extra)
    spread_var = spectra.variance_of_variance(np.maximum(lidar, 0.0), spread, noise_variance,
                                              n_scans, motion_cross, motion_variance)
    u_variance = np.sqrt(spread_var / filtering ** 2 + extra ** 2)
    consistent = np.isfinite(high)
    with np.errstate(invalid="ignore", divide="ignore"):
        ti = np.sqrt(estimate) / corrected_speed
        ti_floor = np.sqrt(np.maximum(estimate, u_variance)) / corrected_speed
        u_ti = u_variance / (2.0 * corrected_speed ** 2 * ti_floor)
        measured = std / speed
    nan = np.where(consistent, 1.0, np.nan)
    convention = np.sqrt(float(n_scans) / (n_scans - ddof))       # the lidar's N - ddof
    return {"wind_speed_corrected": corrected_speed,
            "turbulence_intensity_measured": measured,
            "turbulence_intensity_corrected": ti * convention * nan,
            "turbulence_intensity_corrected_u": u_ti * convention * nan,
            "turbulence_intensity_corrected_low": np.sqrt(low) / corrected_speed * convention
            * nan,
            "turbulence_intensity_corrected_high": np.sqrt(high) / corrected_speed * convention
            * nan,
            "variance_corrected": variance * nan,
            "consistent": consistent}
