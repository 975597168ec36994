"""The scales a turbulence box does not resolve, as a lidar's beams would have seen them.

A Mann box (:mod:`uq.physics.turbulencebox`) of spacing d holds the field's wavenumbers
inside its Nyquist cube ``|k_a| < pi / d`` alone, and the sampler reads it between its
nodes by trilinear interpolation (:mod:`uq.physics.turbulencesampling`), which passes a
wavenumber's power only in part. What the beams of the Monte Carlo records miss is the
difference, for each beam b and gate g, between the lidar's radial-velocity variance in
the full field and its expectation in the interpolated box::

    V_bg = integral Phi_nn(k) [ |What_g(k.n)|^2 S(k1)
                                - 1_cube(k) I(k1 d) I(k2 d) I(k3 d) |Wq_g(k.n)|^2 S_q(k1) ] d^3k

``n`` the beam's direction, ``Phi_nn = n . Phi(k) n`` (Mann's tensor, the factor of
:func:`uq.physics.turbulencebox.mann1998_spectral_factor`), ``What`` the probe's own
transfer (the spectral path's), ``Wq(kappa) = sum_j w_gj exp(i kappa s_j)`` the
sampler's probe quadrature, ``S(k1) = sinc^2(k1 U D / 2)`` the dwell's box-car and
``S_q(k1) = |mean_m exp(-i k1 U t_m)|^2`` its midpoint nodes (:func:`uq.physics.
turbulencesampling.dwell_offsets`), and ``I(theta) = 2/3 + cos(theta) / 3`` the power
that linear interpolation passes of a wave ``exp(i k x)`` at a position uniform in its
cell: ``|(1 - s) + s exp(i theta)|^2`` averaged over s in [0, 1] (``theta = k d``; 1 at
theta = 0, 1/3 at the Nyquist wavenumber).

These scales are below a cell (wavelengths under 2 d) or passed in part by the
interpolation (a few cells): they decorrelate within a few cells, far less than the
beams' separation (tens of metres at the heights a lidar measures) or a scan's advection
``U T_s``, so the records draw them as values independent between beams, gates and scans
with the variance ``V_bg`` (:func:`uq.pipeline.records.beam_complement`). The
approximations, stated: the interpolation's power is its average over positions (the
probe's nodes and a record's scans sample the cell's positions evenly), and the box's
discrete wavenumbers are taken for the continuum inside the cube (the box's low
wavenumbers, where they differ, pass the interpolation and the probe whole: the integrand
vanishes there).

The integral is a tensor product of Gauss-Legendre panels on each axis, split at the
cube's faces ``+-pi / d`` and graded geometrically on either side; beyond ``K =``
:data:`~uq.constants.UNRESOLVED_REACH` ``pi / d`` the tensor's ``k^(-11/3)`` leaves a
share ``(pi / (d K))^(2/3)`` of the outer shell's variance (under 1 % of ``V``).

References
----------
.. [1] Mann, J. (1998). Wind field simulation. Prob. Eng. Mech. 13(4):269-282 (the box's
   discrete wavenumbers, Sec. 3).
.. [2] Mann, J. (1994). The spatial structure of neutral atmospheric surface-layer
   turbulence. J. Fluid Mech. 273:141-168 (the tensor).
"""
import numpy as np

from uq import constants


def interpolation_power(theta):
    """``I(theta) = 2/3 + cos(theta) / 3`` [1]: the power linear interpolation passes of
    ``exp(i k x)``, ``theta = k d``, averaged over the position in the cell (module
    docstring)."""
    return 2.0 / 3.0 + np.cos(theta) / 3.0


def axis_rule(nyquist, panels=constants.UNRESOLVED_PANELS,
              reach=constants.UNRESOLVED_REACH, order=constants.UNRESOLVED_ORDER):
    """Nodes [rad m-1] and weights [rad m-1] on ``[-reach nyquist, reach nyquist]``: Gauss-
    Legendre panels of `order` nodes, graded geometrically from the cube's face
    ``nyquist`` towards 0 (`panels` (count, smallest fraction) inside) and outwards to
    ``reach nyquist`` (`panels` count per decade), symmetric about 0."""
    count, smallest = panels
    inside = nyquist * np.concatenate([[0.0], np.geomspace(smallest, 1.0, count)])
    decades = np.log10(reach)
    outside = nyquist * np.geomspace(1.0, reach, int(np.ceil(decades * count)) + 1)[1:]
    edges = np.concatenate([inside, outside])
    x, w = np.polynomial.legendre.leggauss(order)
    half = (edges[1:] - edges[:-1]) / 2.0
    nodes = ((edges[1:] + edges[:-1]) / 2.0)[:, None] + half[:, None] * x
    weights = half[:, None] * w
    nodes, weights = nodes.ravel(), weights.ravel()
    return np.concatenate([-nodes[::-1], nodes]), np.concatenate([weights[::-1], weights])


def quadrature_power(offsets, weights, kappa):
    """``|sum_j w_gj exp(i kappa s_j)|^2`` [1] for each gate: the sampler's probe
    quadrature (offsets (n,) [m], weights (n_gates, n)) at wavenumbers `kappa` (...)
    [rad m-1]; shape (n_gates, ...)."""
    kappa = np.asarray(kappa, dtype=float)
    phases = np.exp(1j * np.multiply.outer(np.asarray(offsets, float), kappa))
    return np.abs(np.tensordot(np.asarray(weights, float), phases, axes=1)) ** 2


def _planes(spacing, alpha_epsilon, length_scale, anisotropy, rule):
    """The rule's k1 nodes one at a time, each with its (k2, k3) plane: (k1 [rad m-1],
    its weight w1 [rad m-1], k2 (n, 1), k3 (1, n) [rad m-1], the plane's weights w2 w3
    (n, n) [rad2 m-2], Mann's factor C (3, 3, n, n), whether each node lies in the box's
    Nyquist cube (n, n))."""
    from uq.physics.turbulencebox import mann1998_spectral_factor
    nyquist = np.pi / spacing
    nodes, weights = axis_rule(nyquist) if rule is None else rule
    k2, k3 = nodes[:, None], nodes[None, :]
    cross = weights[:, None] * weights[None, :]
    inside_23 = (np.abs(k2) < nyquist) & (np.abs(k3) < nyquist)
    for k1, w1 in zip(nodes, weights):
        factor = mann1998_spectral_factor(k1, k2, k3, alpha_epsilon, length_scale, anisotropy)
        yield k1, w1, k2, k3, cross, factor, inside_23 & (abs(k1) < nyquist)


def unresolved_radial_variances(spacing, geometry, dwell_offsets, probe_transfer,
                                alpha_epsilon, length_scale, anisotropy, rule=None):
    """Each beam's and gate's radial-velocity variance the interpolated box misses
    [m2 s-2], shape (n_beams, n_gates): ``V_bg`` of the module docstring, negative
    values (the quadrature passing more than the probe: rounding) set to 0.

    Parameters
    ----------
    spacing : float
        The box's cell size d [m] (the same on each axis).
    geometry : ScanGeometry
        Beams (their nominal directions), probe quadrature, dwell and speed.
    dwell_offsets : ndarray
        The sampler's dwell nodes [s] (:func:`uq.physics.turbulencesampling.dwell_offsets`).
    probe_transfer : callable
        ``kappa -> (n_gates, *kappa.shape)`` the probe's own transfer What (a
        :class:`uq.physics.lidarspectral.ProbeTransfer`; None: a point probe).
    alpha_epsilon, length_scale, anisotropy : float
        Mann's parameters [m4/3 s-2], [m], [1].
    rule : (nodes, weights), optional
        The per-axis rule (default :func:`axis_rule` at the box's Nyquist wavenumber).
    """
    nyquist = np.pi / spacing
    directions = np.asarray(geometry.directions, dtype=float)
    offsets = np.asarray(geometry.probe_offsets, dtype=float)
    probe_weights = np.asarray(geometry.probe_weights, dtype=float)
    speed, dwell = geometry.speed, geometry.dwell
    dwell_offsets = np.atleast_1d(np.asarray(dwell_offsets, dtype=float))
    # the quadrature's power as a table in |kappa| up to the cube's corner (beyond it the
    # box holds nothing): sqrt(3) pi / d
    table_kappa = np.linspace(0.0, np.sqrt(3.0) * nyquist * 1.001,
                              constants.UNRESOLVED_QUADRATURE_TABLE)
    table = quadrature_power(offsets, probe_weights, table_kappa)       # (G, n)
    total = np.zeros((directions.shape[0], probe_weights.shape[0]))
    for k1, w1, k2, k3, cross, factor, inside in _planes(spacing, alpha_epsilon,
                                                          length_scale, anisotropy, rule):
        full_dwell = np.sinc(k1 * speed * dwell / (2.0 * np.pi)) ** 2
        box_dwell = np.abs(np.mean(np.exp(-1j * k1 * speed * dwell_offsets))) ** 2
        box = inside * (interpolation_power(k2 * spacing) * interpolation_power(k3 * spacing)) \
            * interpolation_power(k1 * spacing) * box_dwell
        for b, n in enumerate(directions):
            projected = np.einsum("i,ij...->j...", n, factor)
            phi = np.sum(projected ** 2, axis=0) * cross * w1              # (n, n)
            kappa = k1 * n[0] + k2 * n[1] + k3 * n[2]
            full = (np.ones((probe_weights.shape[0],) + kappa.shape) if probe_transfer is None
                    else np.abs(probe_transfer(kappa)) ** 2) * full_dwell
            quadrature = np.stack([np.interp(np.abs(kappa), table_kappa, row, right=0.0)
                                   for row in table])
            total[b] += np.sum(phi * (full - box * quadrature), axis=(1, 2))
    return np.maximum(total, 0.0)


def unresolved_point_covariance(spacing, alpha_epsilon, length_scale, anisotropy, rule=None):
    """The (u, v, w) covariance [m2 s-2] of the wavenumbers outside a box's Nyquist cube
    ``|k_a| < pi / d`` (at a node, where no interpolation is needed), shape (3, 3): the
    integral of Mann's ``C C^T`` there (its u-w covariance, -0.07 against u's 1.08 for
    IEC Mann at L / 8: the shear still shapes the smallest eddies the box leaves out)."""
    total = np.zeros((3, 3))
    for _, w1, _, _, cross, factor, inside in _planes(spacing, alpha_epsilon, length_scale,
                                                      anisotropy, rule):
        total += np.einsum("ikab,jkab,ab->ij", factor, factor, cross * w1 * ~inside)
    return total


def unresolved_point_variances(spacing, alpha_epsilon, length_scale, anisotropy, rule=None):
    """The (u, v, w) variances [m2 s-2] of the wavenumbers outside a box's Nyquist cube
    ``|k_a| < pi / d`` (at a node, where no interpolation is needed), shape (3,): the
    diagonal of :func:`unresolved_point_covariance`."""
    return np.diag(unresolved_point_covariance(spacing, alpha_epsilon, length_scale,
                                               anisotropy, rule)).copy()
