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

Interval. ``x = s^2 - V_m`` has the mean ``E = F V + (N-1)/N sigma^2`` and the variance
``var(s^2)`` of :mod:`uq.campaign.spectra` (the turbulence's and the scan errors', the
motion's cross terms with them, the spread of the motion's own sample variance where its
phases are unknown), both depending on V. The turbulence and the scan errors are a
scaled chi-square (a Gaussian quadratic form, Satterthwaite's approximation), the
motion's terms symmetric about zero; x is taken as the Pearson type III distribution of
their sum's mean, variance and skewness (:func:`quantile`: the scaled chi-square where
there is no motion, near the normal where the motion's terms dominate). The interval of
V holds every V under which the observed x lies within the central ``p`` of its
distribution (Neyman's construction: it covers the true V with probability p, as far
as that distribution holds), each end found by bisection; the relative
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
   classical theory of probability. Phil. Trans. R. Soc. A 236, 333-380; Johnson, N. L.,
   Kotz, S. and Balakrishnan, N. (1994). Continuous Univariate Distributions, vol. 1,
   Wiley, Ch. 17 (the gamma distribution shifted and scaled: Pearson type III).
.. [2] Sathe, A., Mann, J., Gottschall, J. and Courtney, M. S. (2011). J. Atmos. Oceanic
   Technol. 28, 853-868.
.. [3] JCGM 101:2008, 7.9.2 (numerical tolerance) and clause 8.
"""
import numpy as np
from scipy import special

from uq.campaign import spectra
from uq.constants import COVERAGE_PROBABILITY

#: Steps of each interval end's bracketing and bisection [1] (60 halvings: 1e-18 of the
#: bracket; the bisection stops at :data:`INTERVAL_TOLERANCE`).
INTERVAL_ITERATIONS = 60
#: Relative width of an interval end's bracket taken as converged [1].
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


def moments(lidar_variance, noise_part, spread, noise_variance, n_scans, motion=(0, 0, 0)):
    """(mean, variance, skewness) of x under the lidar variance F V [m2 s-2] (arrays):
    the turbulence and the scan errors a scaled chi-square (third cumulant ``2 var_t^2 /
    E``), the motion's terms symmetric about zero; `motion`: (its cross term sum V_k
    q_k [m2 s-2], its record variance [m2 s-2], the spread of its sample variance [m4
    s-4]) (:mod:`uq.campaign.spectra`)."""
    mean = lidar_variance + noise_part
    alone = spectra.variance_of_variance(lidar_variance, spread, noise_variance, n_scans)
    total = spectra.variance_of_variance(lidar_variance, spread, noise_variance, n_scans,
                                         *motion)
    with np.errstate(divide="ignore", invalid="ignore"):
        skew = np.where((total > 0) & (mean > 0), 2.0 * alone ** 2 / (mean * total ** 1.5),
                        0.0)
    return mean, total, skew


#: Skewness below which :func:`quantile` takes the normal's [1] (a chi-square of 8e8
#: degrees of freedom: its quantiles are the normal's to 1e-4 of sigma).
SKEW_FLOOR = 1e-4


def quantile(probability, mean, variance, skew):
    """The `probability` quantile of the Pearson type III distribution of the given mean,
    variance and skewness (a shifted, scaled chi-square of ``k = 8 / skew^2`` degrees of
    freedom: ``mean + (sigma skew / 4) (chi2_k(p) - k)``); the normal's where the
    skewness vanishes, the scaled chi-square's where the motion's terms do."""
    sigma = np.sqrt(np.maximum(variance, 0.0))
    normal = mean + sigma * special.ndtri(probability)
    big = skew > SKEW_FLOOR
    k = 8.0 / np.where(big, skew, 1.0) ** 2
    with np.errstate(invalid="ignore", over="ignore"):
        gamma = mean + sigma * np.where(big, skew, 0.0) / 4.0 * (
            2.0 * special.gammaincinv(k / 2.0, probability) - k)
    return np.where(big, gamma, normal)


def interval_end(x, noise_part, spread, noise_variance, n_scans, probability,
                 motion=(0, 0, 0)):
    """The lidar variance F V [m2 s-2] under which x is the `probability` quantile of
    its distribution (:func:`moments`, :func:`quantile`; the quantile grows with F V:
    bisection), NaN where there is none at or above 0 (x below that quantile at F V =
    0)."""
    x = np.asarray(x, float)

    def gap(value):
        return quantile(probability, *moments(value, noise_part, spread, noise_variance,
                                              n_scans, motion)) - x
    below = gap(np.zeros_like(x)) > 0
    low, high = np.zeros_like(x), np.maximum(np.abs(x), noise_part) + 1e-12
    for _ in range(INTERVAL_ITERATIONS):           # bracket the root: double the upper end
        short = ~below & (gap(high) < 0)
        if not short.any():
            break
        high = np.where(short, 2.0 * high, high)
    for _ in range(INTERVAL_ITERATIONS):
        middle = (low + high) / 2.0
        up = gap(middle) < 0
        low, high = np.where(up, middle, low), np.where(up, high, middle)
        if np.all(high - low <= INTERVAL_TOLERANCE * np.maximum(high, 1e-300)):
            break
    return np.where(below, np.nan, (low + high) / 2.0)


def predicted_measured(truth, speed, filtering, spread, motion_variance, noise_variance,
                       n_scans, ddof=1, motion_cross=0.0, motion_phase=0.0):
    """(mean, standard deviation) from record to record of the TI the lidar reports
    (its standard deviation over N - ddof scans over its mean speed `speed`) for a field
    of true TI `truth` (on the lidar's convention) at the corrected speed: s^2's mean and
    variance from Eq. 1 and :mod:`uq.campaign.spectra`, and ``E[sqrt(X)] = sqrt(mu) (1 -
    var / (8 mu^2))``, ``sd = sqrt(var) / (2 sqrt(mu))`` (the second-order delta method)."""
    n = float(n_scans)
    convention = n / (n - ddof)
    lidar = filtering * (np.asarray(truth, float) * speed) ** 2 / convention
    mean = lidar + motion_variance + (n - 1.0) / n * noise_variance
    var = spectra.variance_of_variance(lidar, spread, noise_variance, n_scans, motion_cross,
                                       motion_variance, motion_phase)
    with np.errstate(invalid="ignore", divide="ignore"):
        root = np.sqrt(mean * convention) * (1.0 - var / (8.0 * mean ** 2))
        spread_of_root = np.sqrt(var * convention) / (2.0 * np.sqrt(mean))
    return root / speed, spread_of_root / speed


def correct(speed, std, filtering, spread, motion_variance, motion_bias, noise_variance,
            n_scans, ddof=1, coverage=COVERAGE_PROBABILITY, filtering_u=0.0, motion_u=0.0,
            motion_cross=0.0, motion_phase=0.0):
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
    motion_cross, motion_phase : ndarray
        The motion's cross term with the turbulence ``sum_k V_k q(f_k)`` [m2 s-2] and the
        spread of its own sample variance [m4 s-4] (:mod:`uq.campaign.spectra`).

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
    motion = (motion_cross, motion_variance, motion_phase)
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
                                              n_scans, *motion)
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
