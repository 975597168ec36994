"""Quadrature rules of the spectral path: composite Gauss-Legendre panels, their weights
for an oscillating factor ``exp(i k delta)`` (Filon), and a record's high-pass.

The spectral path (:mod:`uq.physics.lidarspectral`) integrates, for each pair of beams b,
d, a smooth function of the wavenumber (the tensor, the probes' transfer functions, the
dwell) times ``exp(i k . delta_bd)``, with ``delta_bd`` the beams' separation including
the advection between their times. Where ``|k| |delta|`` is large the factor oscillates
faster than any fixed grid resolves (two beams of a 30 deg DBS 200 m up are 231 m
apart). Filon's method [1] removes the limit: on each panel ``[c - h, c + h]`` the smooth
part f is replaced by its interpolating polynomial at the panel's m Gauss-Legendre nodes,
and the product with the exponential is integrated exactly. With ``x = (k - c) / h``, the
Lagrange polynomial of node j is ``l_j(x) = sum_{n<m} (2n + 1)/2 w_j P_n(x_j) P_n(x)`` (the
m-node rule integrates ``l_j P_n``, of degree <= 2m - 2, exactly), and ``integral_{-1}^{1}
P_n(x) exp(i w x) dx = 2 i^n j_n(w)`` (Abramowitz and Stegun 10.1.14 [2], j_n the spherical
Bessel function), so::

    integral_panel f(k) exp(i k delta) dk ~ sum_j f(k_j) W_j,
    W_j = h exp(i c delta) w_j sum_{n<m} (2n + 1) i^n j_n(h delta) P_n(x_j)          (1)

exact for f a polynomial of degree < m whatever delta; at delta = 0 it is the
Gauss-Legendre rule (``W_j = h w_j``, exact to degree 2m - 1). The error is that of
interpolating f, which does not grow with delta.

The record's high-pass (Eq. 3 of :mod:`uq.physics.lidarspectral`) multiplies the
integrand by ``1 - |D_N(f)|^2``, ``f = k U / (2 pi)``; ``|D_N|^2`` has peaks of width
``1 / T`` (``T = N T_s``) at every multiple of the scan rate ``1 / T_s``, far narrower than
any panel: the peak at 0 is the record's mean, the others the scans' aliasing, which
removes ``1/N`` of the variance above the scan rate. They are integrated separately
(:func:`record_weights`) against the panel's interpolating polynomials:

* ``N <= RECORD_EXACT_SCANS``: exactly, from ``|D_N(f)|^2 = N^-2 sum_{|j|<N} (N - |j|)
  exp(2 pi i f j T_s)``: each term is Eq. (1) at ``delta + j U T_s``;
* larger N: the peak at 0 on a fine rule over its first ``RECORD_PEAK_WIDTHS`` widths,
  beyond them ``|D_N|^2`` by its mean over its fast oscillation, ``1 / (2 N^2 sin^2(pi f
  T_s))`` (the rest, ``cos(2 pi f T) / (2 N^2 sin^2)``, oscillates with period ``1/T`` and
  integrates to < 1e-3 of this part against a function smooth on that scale); every
  other peak m as its mass ``2 pi / (U N T_s)`` at its centre ``k_m = 2 pi m / (U T_s)``
  (the function varies by < 1e-3 across a peak's width: ``U T >> |delta|``), the peaks
  beyond ``RECORD_PEAK_COUNT`` by their mean, ``1/N`` of the integrand.

References
----------
.. [1] Iserles, A. and Norsett, S. P. (2004). On quadrature methods for highly
   oscillatory integrals and their implementation. BIT 44, 755-772 (Filon-type methods:
   the error of Eq. (1) is the interpolation error of f alone).
.. [2] Abramowitz, M. and Stegun, I. A. (1964). Handbook of Mathematical Functions,
   10.1.14 (the plane wave in Legendre polynomials), 25.4.29 (Gauss-Legendre).
"""
from dataclasses import dataclass, field

import numpy as np
from scipy import special

#: Scans of a record up to which the high-pass is integrated exactly term by term [1]:
#: ``2 N - 1`` shifted Filon rules per separation (cheap up to a few hundred).
RECORD_EXACT_SCANS = 64
#: Widths ``1 / T`` of the record-mean peak resolved by the fine rule beyond which its
#: mean envelope takes over [1]: the envelope's neglected oscillating part is < 1 /
#: (2 pi^2 RECORD_PEAK_WIDTHS) of the peak's mass (1.6e-3 at 32) and averages out.
RECORD_PEAK_WIDTHS = 32
#: Aliasing peaks (multiples of the scan rate) taken one by one [1]; beyond them each
#: removes its mean share 1/N of a smooth integrand.
RECORD_PEAK_COUNT = 2000


@dataclass(frozen=True)
class PanelRule:
    """A composite Gauss-Legendre rule: `order` nodes on each panel between `edges`.

    Attributes
    ----------
    edges : ndarray, shape (n_panels + 1,)
        Increasing panel edges [rad m-1, or the variable's unit].
    order : int
        Nodes per panel.
    nodes, weights : ndarray, shape (n_panels * order,)
        The rule (panel by panel).
    """

    edges: np.ndarray
    order: int
    nodes: np.ndarray = field(init=False, repr=False)
    weights: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        edges = np.asarray(self.edges, dtype=float)
        if edges.ndim != 1 or edges.size < 2 or np.any(np.diff(edges) <= 0) or self.order < 1:
            raise ValueError("PanelRule: edges must increase, order >= 1")
        x, w = np.polynomial.legendre.leggauss(self.order)
        centres, halves = (edges[1:] + edges[:-1]) / 2, (edges[1:] - edges[:-1]) / 2
        object.__setattr__(self, "edges", edges)
        object.__setattr__(self, "nodes", (centres[:, None] + halves[:, None] * x).ravel())
        object.__setattr__(self, "weights", (halves[:, None] * w).ravel())

    @property
    def size(self):
        """Number of nodes."""
        return self.nodes.size

    def _reference(self):
        x, w = np.polynomial.legendre.leggauss(self.order)
        edges = self.edges
        return x, w, (edges[1:] + edges[:-1]) / 2, (edges[1:] - edges[:-1]) / 2

    def filon(self, delta):
        """Weights W (..., n) of Eq. (1) for each separation of `delta` (...,) [m]:
        ``sum_j f(k_j) W_j ~ integral f(k) exp(i k delta) dk`` over the rule's range."""
        x, w, centres, halves = self._reference()
        delta = np.asarray(delta, dtype=float)
        n = np.arange(self.order)
        legendre = np.stack([special.eval_legendre(order, x) for order in n])   # (n, j)
        omega = delta[..., None] * halves                                       # (..., P)
        bessel = special.spherical_jn(n, omega[..., None]) * ((2 * n + 1) * 1j ** n)
        series = bessel @ legendre                                              # (..., P, j)
        phase = np.exp(1j * delta[..., None] * centres)                        # (..., P)
        out = (halves * phase)[..., None] * w * series
        return out.reshape(delta.shape + (self.size,))

    def interpolation(self, points):
        """Matrix (len(points), n) of the nodes' Lagrange polynomials at `points` (each
        point reads its own panel's; 0 outside the rule's range): ``f(points) ~ matrix @
        f(nodes)`` for f smooth on the panels."""
        x, _, centres, halves = self._reference()
        points = np.asarray(points, dtype=float).ravel()
        panel = np.clip(np.searchsorted(self.edges, points, side="right") - 1, 0,
                        centres.size - 1)
        inside = (points >= self.edges[0]) & (points <= self.edges[-1])
        t = (points - centres[panel]) / halves[panel]
        basis = np.ones((points.size, self.order))
        for j in range(self.order):
            for i in range(self.order):
                if i != j:
                    basis[:, j] *= (t - x[i]) / (x[j] - x[i])
        out = np.zeros((points.size, self.size))
        columns = panel[:, None] * self.order + np.arange(self.order)
        np.put_along_axis(out, columns, basis * inside[:, None], axis=1)
        return out

    def coarser(self, drop=2):
        """The same panels with `drop` fewer nodes each (at least 1): the rule whose
        difference from this one estimates this one's error (one refinement)."""
        return PanelRule(self.edges, max(1, self.order - drop))


def geometric_edges(low, high, per_decade, zero=True, extra=()):
    """Panel edges from `low` to `high` (> 0) at `per_decade` panels a decade, with the
    panel [0, low] first (`zero`) and `extra` edges inserted (each within the range,
    splitting the panel it falls in)."""
    decades = np.log10(high / low)
    count = max(1, int(np.ceil(decades * per_decade - 1e-9)))
    edges = np.geomspace(low, high, count + 1)
    extra = [e for e in np.asarray(extra, float).ravel() if low < e < high]
    edges = np.union1d(edges, extra)
    return np.concatenate([[0.0], edges]) if zero else edges


def symmetric_edges(edges):
    """Edges of a rule over ``[-K, K]`` from those of ``[0, K]`` (starting at 0)."""
    edges = np.asarray(edges, dtype=float)
    return np.concatenate([-edges[:0:-1], edges])


# --- the record's high-pass ------------------------------------------------------------------

def record_scans(scan_period, record_duration):
    """Scans N = floor(T_rec / T_s) in a record (at least 1); 0 means no high-pass (inf)."""
    if not np.isfinite(record_duration):
        return 0
    return max(1, int(np.floor(record_duration / scan_period + 1e-9)))


def mean_window(frequency, scan_period, scans):
    """``|D_N(f)|^2 = sin^2(pi f N T_s) / (N sin(pi f T_s))^2`` [1] (1 at the peaks)."""
    f = np.abs(np.asarray(frequency, dtype=float))
    x = np.pi * f * scan_period
    denominator = scans * np.sin(x)
    small = np.abs(denominator) < 1e-12 * scans
    ratio = np.where(small, 1.0, np.sin(scans * x) / np.where(small, 1.0, denominator))
    return ratio ** 2


def record_weights(rule, delta, speed, scan_period, record_duration):
    """Weights V (..., n) with ``sum_j f(k_j) V_j ~ integral f(k) exp(i k delta) (1 -
    |D_N(k U / 2 pi)|^2) dk`` over the rule's range (module docstring), for each of
    `delta` (...,) [m]; `speed` U [m s-1], `scan_period` T_s and `record_duration` [s]
    (inf: no high-pass, the Filon weights)."""
    delta = np.asarray(delta, dtype=float)
    weights = rule.filon(delta)
    scans = record_scans(scan_period, record_duration)
    if scans == 0:
        return weights
    step = speed * scan_period                          # advection of one scan [m]
    if scans <= RECORD_EXACT_SCANS:
        lags = np.arange(-(scans - 1), scans)
        share = (scans - np.abs(lags)) / scans ** 2
        shifted = rule.filon(delta[..., None] + lags * step)          # (..., 2N-1, n)
        return weights - np.einsum("l,...ln->...n", share, shifted)
    points, masses, beyond = _mean_points(rule, speed, scan_period, scans)
    matrix = rule.interpolation(points)                              # (Q, n)
    phases = np.exp(1j * delta[..., None] * points) * masses         # (..., Q)
    out = weights - phases @ matrix
    if beyond is not None:          # beyond the peaks taken one by one: 1/N of the rest
        out = out - np.where(rule.nodes > beyond, weights / scans, 0.0)
    return out


def _mean_points(rule, speed, scan_period, scans):
    """Points [rad m-1] and masses [rad m-1] discretising ``|D_N|^2 dk`` over the rule's
    range (module docstring), and the wavenumber beyond which the peaks are taken by
    their mean (None if none is)."""
    period = 2 * np.pi / (speed * scan_period)           # the scan rate's wavenumber
    width = period / scans                               # a peak's width, 2 pi / (U T)
    top = rule.edges[-1]
    fine_end = min(RECORD_PEAK_WIDTHS * width, period / 2, top)
    x, w = np.polynomial.legendre.leggauss(4)
    edges = np.arange(0.0, fine_end + width / 8, width / 4)
    edges[-1] = fine_end
    halves, centres = np.diff(edges) / 2, (edges[1:] + edges[:-1]) / 2
    fine = (centres[:, None] + halves[:, None] * x).ravel()
    fine_mass = (halves[:, None] * w).ravel() * mean_window(
        fine * speed / (2 * np.pi), scan_period, scans)
    points, masses = [fine], [fine_mass]
    end = min(period / 2, top)
    if end > fine_end:           # the peak's envelope, 1 / (2 N^2 sin^2), in log k
        u, wu = np.polynomial.legendre.leggauss(24)
        a, b = np.log(fine_end), np.log(end)
        k = np.exp((a + b) / 2 + (b - a) / 2 * u)
        envelope = 0.5 / (scans * np.sin(np.pi * k * speed * scan_period / (2 * np.pi))) ** 2
        points.append(k)
        masses.append((b - a) / 2 * wu * k * envelope)
    count = int(np.floor(top / period + 1e-9))
    beyond = None
    if count > RECORD_PEAK_COUNT:
        count, beyond = RECORD_PEAK_COUNT, (RECORD_PEAK_COUNT + 0.5) * period
    if count > 0:
        points.append(period * np.arange(1, count + 1))
        masses.append(np.full(count, width))
    return np.concatenate(points), np.concatenate(masses), beyond
