"""Turbulent wind fields in a box: Mann (1994, 1998) by FFT, and Kaimal with IEC coherence.

The Monte Carlo path of turbulent records samples a generated field along each beam
(:mod:`uq.physics.turbulencesampling`); this module generates the field.

Conventions
-----------
* Mean-wind frame (x downwind, y left, z up) and Taylor's frozen turbulence as in
  :mod:`uq.physics.scangeometry`: the box holds the turbulent velocity ``u'_0(r)`` at
  t = 0, and the velocity at point r and time t is ``u'_0(r - U t e_x)``.
* A box is ``velocity[c, i, j, l]`` [m s-1], c = 0, 1, 2 for (u, v, w) along (x, y, z), at
  the point ``origin + (i dx, j dy, l dz)`` [m]; periodic along x (both models) and along
  y and z (Mann only). The box's spatial mean is zero (the k = 0 mode is left out).
* Fourier convention ``u(x) = sum_k exp(i k . x) u_k`` with ``E[u_k u_k^*] = Phi(k) dk``,
  ``dk = (2 pi)^3 / (L_x L_y L_z)`` (Mann 1998 [2], Eq. 43); random numbers are real
  standard normals drawn in the box's C order (component, x, y, z) from one
  ``numpy.random.Generator`` on the host, so a seed gives the same box on any device
  and whatever the slab size of the factor's evaluation.

Choice of generator (measured here, 2-core machine shared with others, box 4096 x 32 x 32,
IEC parameters): hipersim 0.1.22 (MIT, pure numpy): 4.0 s CPU per box, 835 MB peak,
the same field for a seed, but its random numbers depend on its ``n_cpu`` (a sequential and
a parallel generator), no CuPy path, and it pulls in wetb, netCDF4, tqdm; mannrs 2.0.0 (MIT,
Rust): 7.3 s CPU to build its stencil then ~3 s CPU per box, 1.05 GB peak, the same field
for a seed, no CuPy path, needs pydantic and toml. Neither runs on a GPU, which this project
needs, so the generator is written here in ~100 lines against the numpy API that
CuPy mirrors (``xp``): the same algorithm as both (Mann 1998 [2], Sec. 3), and its
spectral factor is written from the paper, independently of the spectral path's tensor, so
that ``C C^T = Phi`` cross-checks the two (only the exact eddy lifetime, which the table
below interpolates, the von Karman energy spectrum and the Kaimal spectra and coherence are the
spectral path's own). The same box here: 1.3 s CPU, 0.6 GB peak
(numpy, scipy.fft on one thread); a ten-minute record: :mod:`uq.bench.turbulence`. The
GPU path (CuPy) is written but was not timed (no GPU in the session that wrote it).

Discretisation (Mann 1998 [2], Sec. 3). A box holds the variance of its discrete
wavenumbers: nothing above its Nyquist cube (``|k_i| < pi / d_i``) nor in its origin cell
(the box's mean), and its cells' tensor values stand for their cells' integrals. Mann's
tensor is integrably singular at k = 0 and along the k1 axis varies on the scale of k1,
far below a long box's ``dk2``, ``dk3``; sampled at the cells' centres it gives those
cells several times their share of the variance (w's above all), so near the k1 axis the
factor is the square root of the tensor averaged over the cell
(:func:`cell_averaged_factors`), as Mann (1998) averages it. :func:`box_variance` reports
what a box keeps (tested against the tensor integrated over the box's wavenumbers); with
IEC parameters and the spacing L / 8 of :func:`box_for` that is ~0.9 of u's and v's point
variance and ~0.83 of w's (the rest: scales below the spacing, and for u the eddies longer
than the box).

Mann model ([1], [2]). The von Karman energy spectrum ``E(k) = alpha eps^(2/3) L^(5/3)
(kL)^4 / (1 + (kL)^2)^(17/6)`` ([1], Sec. 3) is distorted by a uniform shear acting over
the eddy lifetime ``beta(k) = Gamma (kL)^(-2/3) 2F1(1/3, 17/6; 4/3; -(kL)^-2)^(-1/2)``
([1], Sec. 3.3, in units of the inverse shear). The field is ``u_k = i C(k) n_k
sqrt(dk)`` with the factor ([2], Sec. 3; [1], Sec. 3.2)::

    C = sqrt(E(k0) / (4 pi)) / k0^2 [[ k2 z1,       k30 - k1 z1, -k2],
                                     [-k30 + k2 z2, -k1 z2,       k1],
                                     [k0^2/k^2 k2, -k0^2/k^2 k1,  0 ]]

``k30 = k3 + beta k1``, ``k0 = (k1, k2, k30)``, ``z1 = C1 - k2 C2 / k1``, ``z2 = k2 C1 / k1
+ C2``, ``C1 = beta k1^2 (k0^2 - 2 k30^2 + beta k1 k30) / (k^2 (k1^2 + k2^2))``, ``C2 = k2
k0^2 (k1^2 + k2^2)^(-3/2) [atan(k30 / kh) - atan(k3 / kh)]`` with ``kh = (k1^2 +
k2^2)^(1/2)``. The printed ``C2`` writes the difference of the two arctangents as one,
``atan(beta k1 kh / (k0^2 - k30 k1 beta))``, which takes the wrong branch where the
denominator ``kh^2 + k30 k3`` is negative; the difference is the integral itself (tested
against the rapid-distortion equations integrated numerically). At ``k1 = 0`` the limits are
``z1 = -beta``, ``z2 = 0``. The factor ``i`` makes ``u_{-k} = u_k^*`` (C is real and odd),
so the field is real; ``C C^T = Phi`` (the sheared tensor of [1], Sec. 3.2).

Kaimal model (IEC 61400-1 [3], Annex B). One-sided spectra ``f S_k(f) / sigma_k^2 = 4 f
L_k / V / (1 + 6 f L_k / V)^(5/3)`` ([3], Annex B, Table B.1) with ``L_k = (8.1, 2.7,
0.66) Lambda_1`` and ``sigma_k = (1, 0.8, 0.5) sigma_u`` (Table B.1), and the coherence
``exp(-a r sqrt((f / V)^2 + (b / L_c)^2))``, ``a = 12``, ``b = 0.12``, ``L_c = 8.1
Lambda_1`` (the annex's exponential coherence model), here for all three components (the standard gives it for u; v and w
take the same form, an assumption, stated). The field is generated as Veers (1988) [4]
does, with x in place of time through Taylor (``f = V k1 / (2 pi)``): per wavenumber k1, a
Cholesky factor of the coherence matrix of the (y, z) grid's points colours independent
normals. The box is periodic along x only.

References
----------
.. [1] Mann, J. (1994). The spatial structure of neutral atmospheric surface-layer
   turbulence. J. Fluid Mech. 273:141-168.
.. [2] Mann, J. (1998). Wind field simulation. Prob. Eng. Mech. 13(4):269-282.
.. [3] IEC 61400-1:2005 (Ed. 3). Wind turbines - Part 1: Design requirements. Annex B
   (stochastic turbulence models: Mann's uniform shear model, the Kaimal spectra and
   the exponential coherence model), 6.3.1 (Lambda_1).
.. [4] Veers, P. S. (1988). Three-dimensional wind simulation. SAND88-0152, Sandia.
"""
import math
from dataclasses import dataclass

import numpy as np
import scipy.fft

from uq import constants
from uq.physics.spectraltensor import KaimalSpectra, mann_eddy_lifetime, von_karman_energy


def array_namespace(device="cpu"):
    """The array namespace of a device: numpy for ``"cpu"``, CuPy for ``"gpu"``.

    Raises ValueError with one line if CuPy or a GPU is missing.
    """
    if device == "cpu":
        return np
    if device != "gpu":
        raise ValueError(f"device must be 'cpu' or 'gpu', not {device!r}")
    try:
        import cupy
        cupy.cuda.runtime.getDeviceCount()
    except Exception as error:     # ImportError, or CUDA's own error without a device
        raise ValueError(f"device 'gpu' needs CuPy and a CUDA GPU ({error})") from None
    return cupy


def _fft(xp):
    """rfftn / irfftn of the namespace (scipy's for numpy: it runs on several threads)."""
    if xp is np:
        return scipy.fft
    return xp.fft


@dataclass(frozen=True)
class BoxGrid:
    """The grid of a turbulence box (module docstring for the conventions).

    Attributes
    ----------
    shape : tuple of int
        (nx, ny, nz) cells.
    spacing : tuple of float
        (dx, dy, dz) [m].
    origin : tuple of float
        Position of cell (0, 0, 0) in the mean-wind frame at t = 0, relative to the
        reference point [m].
    periodic_yz : bool
        Whether the field is periodic along y and z (Mann) or not (Kaimal).
    max_cells : int
        The most cells it may have (:func:`check_cells`).
    """

    shape: tuple
    spacing: tuple
    origin: tuple = (0.0, 0.0, 0.0)
    periodic_yz: bool = True
    max_cells: int = constants.MAX_BOX_CELLS

    def __post_init__(self):
        if len(self.shape) != 3 or min(self.shape) < 2 or len(self.spacing) != 3 \
                or min(self.spacing) <= 0 or len(self.origin) != 3:
            raise ValueError("BoxGrid: shape needs 3 sizes >= 2, spacing 3 values > 0, "
                             "origin 3 values")
        check_cells(self.shape, self.max_cells)

    @property
    def cells(self):
        """Number of cells [1]."""
        return int(np.prod(self.shape))

    @property
    def lengths(self):
        """(L_x, L_y, L_z) [m]: the periods of the box."""
        return tuple(n * d for n, d in zip(self.shape, self.spacing))


def check_cells(shape, max_cells=constants.MAX_BOX_CELLS):
    """Raise ValueError (one line) if a box of ``shape`` cells is above ``max_cells``."""
    cells = math.prod(int(n) for n in shape)           # Python integers: no overflow
    if cells > max_cells:
        raise ValueError(
            f"turbulence box of {' x '.join(str(int(n)) for n in shape)} = {cells} cells is "
            f"above the limit of {max_cells} cells (~{max_cells * 64 // 2**20} MB): shorten "
            f"record.duration, coarsen the spacing or lower the length scale's margin")


def check_kaimal_points(points, max_points=constants.MAX_KAIMAL_POINTS):
    """Raise ValueError (one line) if a Kaimal box's (y, z) grid has too many points."""
    if points > max_points:
        raise ValueError(
            f"a Kaimal box of {points} (y, z) points is above the limit of {max_points} "
            f"(one Cholesky factor of points x points per wavenumber): coarsen the spacing")


@dataclass(frozen=True)
class TurbulenceBox:
    """A generated field: ``velocity`` (3, nx, ny, nz) [m s-1] on ``grid``."""

    grid: BoxGrid
    velocity: object


def von_karman_energy_spectrum(k, alpha_epsilon, length_scale):
    """Von Karman energy spectrum E(k) [m3 s-2], Mann (1994) Sec. 3.

    Parameters
    ----------
    k : float or array (of any namespace)
        Wavenumber magnitude [rad m-1].
    alpha_epsilon : float
        alpha eps^(2/3) [m4/3 s-2].
    length_scale : float
        L [m].
    """
    return von_karman_energy(k, length_scale, alpha_epsilon)       # von Karman, Sec. 3 [1]


def _lifetime_table():
    """log(kL) nodes and log(beta / Gamma) on them (module constants)."""
    low, high = np.log10(constants.EDDY_LIFETIME_TABLE_RANGE)
    nodes = np.linspace(low, high, int((high - low) * constants.EDDY_LIFETIME_TABLE_PER_DECADE) + 1)
    return nodes * np.log(10.0), np.log(mann_eddy_lifetime(10.0**nodes, 1.0, 1.0))


_TABLE = _lifetime_table()


def eddy_lifetime(kl, anisotropy, xp=np, table=None):
    """Mann's eddy lifetime by log-log interpolation of a table, on any array namespace.

    Outside the table's kL range the asymptotes ``beta ~ (kL)^-1`` (kL -> 0) and ``beta ~
    (kL)^(-2/3)`` (kL -> inf) continue it. Same parameters as
    :func:`uq.physics.spectraltensor.mann_eddy_lifetime`; ``kl`` is an array of ``xp``.
    `table`: (first node, step, values) of log(kL) and log(beta / Gamma), as the
    compiled kernels take it; default this module's.
    """
    if table is None:
        table = (float(_TABLE[0][0]), float(_TABLE[0][1] - _TABLE[0][0]), _TABLE[1])
    start, step, log_values = table[0], table[1], xp.asarray(table[2])
    n = log_values.size
    x = xp.log(kl)
    position = (x - start) / step
    inside = xp.clip(position, 0.0, n - 1.0)
    index = xp.clip(xp.floor(inside).astype(xp.int64), 0, n - 2)
    frac = inside - index
    log_beta = (1.0 - frac) * log_values[index] + frac * log_values[index + 1]
    below = xp.minimum(position, 0.0) * step          # log(kL / kL_min) where below
    above = xp.maximum(position - (n - 1.0), 0.0) * step
    log_beta = log_beta - below - (2.0 / 3.0) * above  # asymptotes (kL)^-1, (kL)^(-2/3)
    return anisotropy * xp.exp(log_beta)


def mann1998_spectral_factor(k1, k2, k3, alpha_epsilon, length_scale, anisotropy, xp=np):
    """Mann's spectral factor C(k), with ``C C^T = Phi(k)``, Mann (1998) Sec. 3.

    Parameters
    ----------
    k1, k2, k3 : arrays of ``xp``, broadcastable
        Wavenumber components along x, y, z [rad m-1].
    alpha_epsilon : float
        alpha eps^(2/3) [m4/3 s-2].
    length_scale, anisotropy : float
        L [m] and Gamma [1].

    Returns
    -------
    array, shape (3, 3) + broadcast shape
        C [m5/2 s-1]; zero at k = 0.
    """
    k1, k2, k3 = xp.broadcast_arrays(k1, k2, k3)
    ksq = k1**2 + k2**2 + k3**2
    zero = ksq == 0
    ksq = xp.where(zero, 1.0, ksq)
    beta = eddy_lifetime(xp.sqrt(ksq) * length_scale, anisotropy, xp)
    k30 = k3 + beta * k1                          # k at the start of the distortion [1]
    k0sq = xp.where(zero, 1.0, k1**2 + k2**2 + k30**2)
    z1, z2 = _mann1994_zetas(k1, k2, k3, k30, k0sq, ksq, beta, xp)
    amplitude = xp.sqrt(von_karman_energy_spectrum(xp.sqrt(k0sq), alpha_epsilon, length_scale)
                        / (4.0 * np.pi)) / k0sq
    amplitude = xp.where(zero, 0.0, amplitude)
    ratio = k0sq / ksq
    rows = ((k2 * z1, k30 - k1 * z1, -k2),                       # C(k), Sec. 3 [2]
            (-k30 + k2 * z2, -k1 * z2, k1),
            (ratio * k2, -ratio * k1, xp.zeros_like(k1)))
    return xp.stack([xp.stack([amplitude * c for c in row]) for row in rows])


def _mann1994_zetas(k1, k2, k3, k30, k0sq, ksq, beta, xp):
    """zeta_1, zeta_2 of Mann (1994) Sec. 3.2 (module docstring for the branch)."""
    khsq = k1**2 + k2**2
    flat = khsq == 0                       # k along z: zeta multiplies zero there
    khsq = xp.where(flat, 1.0, khsq)
    kh = xp.sqrt(khsq)
    c1 = beta * k1**2 * (k0sq - 2.0 * k30**2 + beta * k1 * k30) / (ksq * khsq)
    angle = xp.arctan(k30 / kh) - xp.arctan(k3 / kh)
    c2 = k2 * k0sq / (khsq * kh) * angle
    along = k1 == 0
    k1_safe = xp.where(along, 1.0, k1)
    z1 = xp.where(along, -beta, c1 - k2 / k1_safe * c2)         # limit k1 -> 0: -beta
    z2 = xp.where(along, 0.0, k2 / k1_safe * c1 + c2)
    return xp.where(flat, 0.0, z1), xp.where(flat, 0.0, z2)


def box_wavenumbers(grid, xp=np):
    """k1 (nx, 1, 1), k2 (1, ny, 1), k3 (1, 1, nz // 2 + 1) [rad m-1] of the box's half
    spectrum (the real FFT halves z)."""
    (nx, ny, nz), (dx, dy, dz) = grid.shape, grid.spacing
    k1 = 2.0 * np.pi * np.fft.fftfreq(nx, dx)
    k2 = 2.0 * np.pi * np.fft.fftfreq(ny, dy)
    k3 = 2.0 * np.pi * np.fft.rfftfreq(nz, dz)
    return (xp.asarray(k1)[:, None, None], xp.asarray(k2)[None, :, None],
            xp.asarray(k3)[None, None, :])


def _half_weights(nz, xp):
    """Multiplicity of each half-spectrum z-plane in the full spectrum (1 or 2)."""
    weights = np.full(nz // 2 + 1, 2.0)
    weights[0] = 1.0
    if nz % 2 == 0:
        weights[-1] = 1.0
    return xp.asarray(weights)


def _x_slabs(grid, slab_cells):
    """Slices of the k1 axis, each of at most ``slab_cells`` half-spectrum cells."""
    nx, ny, nz = grid.shape
    per_slab = max(1, slab_cells // (ny * (nz // 2 + 1)))
    return [slice(a, min(a + per_slab, nx)) for a in range(0, nx, per_slab)]


def _gauss_rule(centre, half_width, nodes):
    """Gauss-Legendre nodes and weights (summing to 1) on [centre -+ half_width]."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    return centre + half_width * x, w / 2.0


def _graded_rule(half_width):
    """Nodes and weights (summing to 1) on [-h, h], graded geometrically towards 0.

    Panels [h r^(j+1), h r^j] (r = 1/4, j < J) and [0, h r^J] on each side, each with a
    two-point Gauss rule: the cell average of a tensor that varies on the scale of k1
    near the k1 axis (module docstring).
    """
    ratio, panels = constants.CELL_AVERAGE_GRADING
    edges = half_width * np.concatenate([ratio ** np.arange(panels + 1), [0.0]])
    nodes, weights = [], []
    for outer, inner in zip(edges[:-1], edges[1:]):
        x, w = _gauss_rule((outer + inner) / 2.0, (outer - inner) / 2.0, 2)
        nodes += [x, -x]
        weights += [w * (outer - inner), w * (outer - inner)]
    return np.concatenate(nodes), np.concatenate(weights) / (2.0 * half_width)


def _axis_cells(grid):
    """Half-spectrum indices of the cells whose tensor is cell-averaged (near the k1 axis).

    |i2| <= 1, i3 in {0, 1}, |k1| <= CELL_AVERAGE_K1 max(dk2, dk3); the origin's cell
    (the box's mean) is left out.
    """
    (nx, ny, nz), lengths = grid.shape, grid.lengths
    dk = 2.0 * np.pi / np.asarray(lengths)
    reach = min(nx // 2, int(np.ceil(constants.CELL_AVERAGE_K1 * max(dk[1], dk[2]) / dk[0])))
    cells = [(i1, i2, i3) for i1 in range(-reach, reach + 1) for i2 in (-1, 0, 1)
             for i3 in (0, 1) if (i1, i2, i3) != (0, 0, 0)]
    return np.array(cells), dk


def cell_averaged_factors(grid, alpha_epsilon, length_scale, anisotropy):
    """Square roots of the cell-averaged tensor near the k1 axis (Mann 1998, Sec. 3).

    Mann's tensor is integrably singular at k = 0, and along the k1 axis it varies on
    the scale of k1, far below a long box's dk2, dk3: sampled at the cells' centres it
    gives the k1-axis cells many times their share of the variance (w's above all). In
    those cells the generator uses the symmetric square root of the tensor averaged over
    the cell (graded quadrature), as Mann (1998) averages it over each cell.

    Returns
    -------
    cells : ndarray of int, shape (n, 3)
        (i1, i2, i3) wavenumber indices (negative ones count from the end).
    factors : ndarray, shape (3, 3, n)
        Symmetric square root of the cell average of Phi [m5/2 s-1].
    """
    cells, dk = _axis_cells(grid)
    graded = _graded_rule(0.5)
    factors = np.empty((3, 3, len(cells)))
    for on_axis in ((True, True), (True, False), (False, True), (False, False)):
        group = np.flatnonzero(((cells[:, 1] == 0) == on_axis[0]) & ((cells[:, 2] == 0) == on_axis[1]))
        if group.size == 0:
            continue
        rules = [_gauss_rule(0.0, 0.5, constants.CELL_AVERAGE_K1_NODES)]
        rules += [graded if axis else _gauss_rule(0.0, 0.5, 4) for axis in on_axis]
        k = [(cells[group, 0, None, None, None] + rules[0][0][None, :, None, None]) * dk[0],
             (cells[group, 1, None, None, None] + rules[1][0][None, None, :, None]) * dk[1],
             (cells[group, 2, None, None, None] + rules[2][0][None, None, None, :]) * dk[2]]
        weight = (rules[0][1][:, None, None] * rules[1][1][None, :, None]
                  * rules[2][1][None, None, :])
        c = mann1998_spectral_factor(*k, alpha_epsilon, length_scale, anisotropy)
        phi = np.einsum("iknabc,jknabc,abc->nij", c, c, weight)
        values, vectors = np.linalg.eigh(phi)
        roots = np.einsum("nik,nk,njk->ijn", vectors, np.sqrt(np.maximum(values, 0.0)), vectors)
        factors[:, :, group] = roots
    return cells, factors


def box_variance(grid, alpha_epsilon, length_scale, anisotropy,
                 slab_cells=constants.BOX_SLAB_CELLS, spectral_filter=None):
    """Expected variances of (u, v, w) and the u-w covariance of a Mann box [m2 s-2].

    The sum of ``Phi(k) dk`` over the box's discrete wavenumbers (k = 0 left out): what a
    box keeps of the tensor's integral, the point variance (a too small or coarse box
    loses the rest); with `spectral_filter` ``H(k1)`` (of an array of k1 [rad m-1], e.g.
    a record's high-pass) each wavenumber weighted by it. Other parameters as
    :func:`mann_box`.

    Returns
    -------
    ndarray, shape (4,)
        (var u, var v, var w, cov uw) [m2 s-2].
    """
    k1, k2, k3 = box_wavenumbers(grid)
    weights = _half_weights(grid.shape[2], np)
    filtered = (np.ones(grid.shape[0]) if spectral_filter is None
                else np.asarray(spectral_filter(np.abs(k1[:, 0, 0])), dtype=float))
    dk = (2.0 * np.pi) ** 3 / np.prod(grid.lengths)
    cells, factors = cell_averaged_factors(grid, alpha_epsilon, length_scale, anisotropy)
    pairs = ((0, 0), (1, 1), (2, 2), (0, 2))
    total = np.zeros(4)
    for slab in _x_slabs(grid, slab_cells):
        c = mann1998_spectral_factor(k1[slab], k2, k3, alpha_epsilon, length_scale, anisotropy)
        phi = np.einsum("ik...,jk...->ij...", c, c) * filtered[slab, None, None]
        total += [np.sum(phi[i, j] * weights) for i, j in pairs]
    index = tuple(cells.T)
    point = mann1998_spectral_factor(k1[index[0], 0, 0], k2[0, index[1], 0], k3[0, 0, index[2]],
                                     alpha_epsilon, length_scale, anisotropy)
    point_phi = np.einsum("ikn,jkn->ijn", point, point)
    averaged_phi = np.einsum("ikn,jkn->ijn", factors, factors)
    total += [np.sum((averaged_phi[i, j] - point_phi[i, j]) * weights[index[2]]
                     * filtered[index[0]]) for i, j in pairs]
    return total * dk


def white_noise(rng, shape, xp=np):
    """Real standard normals of ``shape`` (3, nx, ny, nz), drawn on the host in C order
    component by component (the same numbers as one draw of ``shape``), on ``xp``'s
    device."""
    if xp is np:
        out = np.empty(shape)
        for c in range(shape[0]):
            rng.standard_normal(out=out[c])
        return out
    return xp.stack([xp.asarray(rng.standard_normal(shape[1:])) for _ in range(shape[0])])


def mann_box(grid, alpha_epsilon, length_scale, anisotropy, rng, xp=np,
             slab_cells=constants.BOX_SLAB_CELLS, workers=None):
    """A Mann (1998) turbulence box by FFT.

    Parameters
    ----------
    grid : BoxGrid
        The box (periodic in x, y, z).
    alpha_epsilon : float
        alpha eps^(2/3) [m4/3 s-2], which sets the variance (the box is linear in its
        square root).
    length_scale, anisotropy : float
        Mann's L [m] and Gamma [1].
    rng : numpy.random.Generator
        Source of the random numbers (drawn on the host).
    xp : module
        numpy, or cupy (:func:`array_namespace`).
    slab_cells : int
        Cells transformed at a time (memory; the box does not depend on it).
    workers : int or None
        Threads of scipy's FFT (numpy only).

    Returns
    -------
    TurbulenceBox
        ``velocity`` (3, nx, ny, nz) [m s-1] on ``xp``'s device; on the host each
        component is C-contiguous, the three held in the memory of their half spectra
        (:func:`_mann_box_host`).
    """
    if xp is np:
        return _mann_box_host(grid, alpha_epsilon, length_scale, anisotropy, rng,
                              slab_cells, workers)
    return mann_box_reference(grid, alpha_epsilon, length_scale, anisotropy, rng, xp,
                              slab_cells, workers)


def _mann_box_host(grid, alpha_epsilon, length_scale, anisotropy, rng, slab_cells, workers):
    """:func:`mann_box` on the host in the memory of the three half spectra alone.

    The same field as :func:`mann_box_reference` to rounding (the same random numbers,
    drawn slab by slab along x in the same C order; the 3-D real FFT taken as a 2-D one
    per slab and a 1-D one along x; the factor applied by the compiled
    :func:`uq.physics.turbulencekernels.mann_colour`), in about half its memory and a
    third of its time: each component's half spectrum (nx, ny, nz // 2 + 1) complex
    holds, after the inverse transform, that component's real field (nx, ny, nz) at its
    start (slab i's output goes where slabs <= i were read from).
    """
    (nx, ny, nz), half = grid.shape, grid.shape[2] // 2 + 1
    spectra = np.empty((3, nx, ny, half), dtype=complex)
    slabs = _x_slabs(grid, slab_cells)
    for c in range(3):
        for slab in slabs:              # C order: component, then x, y, z (white_noise)
            noise = rng.standard_normal((slab.stop - slab.start, ny, nz))
            spectra[c, slab] = scipy.fft.rfft2(noise, workers=workers)
        _in_place(scipy.fft.fft, spectra[c], workers)
    k1, k2, k3 = (k.ravel() for k in box_wavenumbers(grid))
    scale = np.sqrt((2.0 * np.pi) ** 3 / np.prod(grid.spacing))    # sqrt(N dk)
    cells, factors = cell_averaged_factors(grid, alpha_epsilon, length_scale, anisotropy)
    index = (slice(None),) + tuple(cells.T)
    noise_cells = spectra[index]                                    # (3, n): a copy
    mann_colour(spectra[0], spectra[1], spectra[2], k1, k2, k3, alpha_epsilon, length_scale,
                anisotropy, scale, slab_cells)                      # u_k = i C n
    # near the k1 axis: u_k = C_avg n, C_avg even, so u_-k = u_k^* (module docstring)
    spectra[index] = scale * np.einsum("ijn,jn->in", factors, noise_cells)
    size = nx * ny * nz
    for c in range(3):
        _in_place(scipy.fft.ifft, spectra[c], workers)
        field = spectra[c].reshape(-1).view(np.float64)[:size].reshape(nx, ny, nz)
        for slab in slabs:
            field[slab] = scipy.fft.irfft2(spectra[c, slab], s=(ny, nz), workers=workers)
    velocity = spectra.reshape(3, -1).view(np.float64)[:, :size].reshape(3, nx, ny, nz)
    return TurbulenceBox(grid=grid, velocity=velocity)


def mann_box_window(grid, alpha_epsilon, length_scale, anisotropy, rng, window, parts=1,
                    slab_cells=constants.BOX_SLAB_CELLS, workers=None):
    """The field of :func:`mann_box` on a window of its (y, z) cells, in the memory of
    1 / `parts` of its half spectra (on the host): the sum of
    :func:`mann_box_window_parts`.

    The same random numbers and the same field as :func:`mann_box` to rounding (the
    transforms are linear: the half spectrum's z wavenumbers are taken in `parts` parts,
    each drawn from the same noise again, coloured, transformed back and added); only
    the window's (y, z) lines are transformed back along z and kept. `rng` is left where
    one draw of the box leaves it.

    Parameters
    ----------
    grid, alpha_epsilon, length_scale, anisotropy, rng, slab_cells, workers
        As :func:`mann_box` (scipy's FFTs on `workers` threads give the same bits: they
        share out independent 1-D transforms).
    window : ((int, int), (int, int))
        The cells [j0, j1) along y and [m0, m1) along z kept (each at least 2 wide).
    parts : int
        Parts of the half spectrum held at a time: the memory of the spectra is divided
        by it, the noise is drawn and its 2-D transforms taken that many times.

    Returns
    -------
    TurbulenceBox
        On the window: ``grid`` of shape (nx, j1 - j0, m1 - m0) with its origin moved to
        cell (0, j0, m0), periodic along x only (``periodic_yz`` False: a point outside
        the window is refused, not wrapped).
    """
    return box_sum(mann_box_window_parts(grid, alpha_epsilon, length_scale, anisotropy,
                                         rng, window, parts, slab_cells, workers))


def box_sum(parts):
    """The box whose field is the sum of `parts`' (an iterable of
    :class:`TurbulenceBox` on one grid, each used before the next is taken)."""
    velocity = None
    for part in parts:
        if velocity is None:
            velocity = np.zeros(part.velocity.shape)
        velocity += part.velocity
    return TurbulenceBox(grid=part.grid, velocity=velocity)


def mann_box_window_parts(grid, alpha_epsilon, length_scale, anisotropy, rng, window,
                          parts=1, slab_cells=constants.BOX_SLAB_CELLS, workers=None):
    """The field of :func:`mann_box_window` as `parts` fields whose sum it is, one at a
    time (a generator): each part's field of the half spectrum's z wavenumbers
    [a, b) (parameters and the window's grid as :func:`mann_box_window`).

    Each part's field is held in the memory of that part's half spectra (a window's line
    of slab i, transformed back, is written where slabs <= i were read from, where it
    fits; else in an array of its own), so that it is valid until the next part is
    asked for: what the field is sampled for (it is linear) is taken part by part, in
    the memory of one part's spectra alone. `rng` is left where one draw of the box
    leaves it once the last part has been taken.
    """
    (nx, ny, nz), half = grid.shape, grid.shape[2] // 2 + 1
    (j0, j1), (m0, m1) = window
    wy, wz = j1 - j0, m1 - m0
    slabs = _x_slabs(grid, slab_cells)
    k1, k2, k3 = (np.ascontiguousarray(k.ravel()) for k in box_wavenumbers(grid))
    scale = np.sqrt((2.0 * np.pi) ** 3 / np.prod(grid.spacing))    # sqrt(N dk)
    cells, factors = cell_averaged_factors(grid, alpha_epsilon, length_scale, anisotropy)
    (dx, dy, dz), origin = grid.spacing, grid.origin
    window_grid = BoxGrid(shape=(nx, wy, wz), spacing=grid.spacing,
                          origin=(origin[0], origin[1] + j0 * dy, origin[2] + m0 * dz),
                          periodic_yz=False)
    start = rng.bit_generator.state
    edges = np.linspace(0, half, max(1, min(parts, half)) + 1).round().astype(int)
    for a, b in zip(edges[:-1], edges[1:]):
        rng.bit_generator.state = start
        spectra = np.empty((3, nx, ny, b - a), dtype=complex)
        for c in range(3):
            for slab in slabs:          # C order: component, then x, y, z (white_noise)
                noise = rng.standard_normal((slab.stop - slab.start, ny, nz))
                spectra[c, slab] = scipy.fft.rfft2(noise, workers=workers)[..., a:b]
            _in_place(scipy.fft.fft, spectra[c], workers)
        here = (cells[:, 2] >= a) & (cells[:, 2] < b)
        index = (slice(None), cells[here, 0], cells[here, 1], cells[here, 2] - a)
        noise_cells = spectra[index]                                # (3, n): a copy
        mann_colour(spectra[0], spectra[1], spectra[2], k1, k2, np.ascontiguousarray(k3[a:b]),
                    alpha_epsilon, length_scale, anisotropy, scale, slab_cells)  # u_k = i C n
        # near the k1 axis: u_k = C_avg n, C_avg even, so u_-k = u_k^* (module docstring)
        spectra[index] = scale * np.einsum("ijn,jn->in", factors[:, :, here], noise_cells)
        velocity = _part_field(spectra, (nx, wy, wz))
        for c in range(3):
            _in_place(scipy.fft.ifft, spectra[c], workers)
            for slab in slabs:
                rows = scipy.fft.ifft(spectra[c, slab], axis=1, workers=workers)[:, j0:j1]
                padded = np.zeros(rows.shape[:2] + (half,), dtype=complex)
                padded[..., a:b] = rows
                velocity[c, slab] = scipy.fft.irfft(padded, n=nz, axis=2,
                                                    workers=workers)[..., m0:m1]
        yield TurbulenceBox(grid=window_grid, velocity=velocity)
        del spectra, velocity


def mann_colour(n0, n1, n2, k1, k2, k3, alpha_epsilon, length_scale, anisotropy, scale,
                slab_cells=constants.BOX_SLAB_CELLS):
    """Colour the noise spectra of a slab in place: ``n <- i scale C(k) n`` (Mann 1998,
    Sec. 3 [2]), ``C`` of :func:`mann1998_spectral_factor`.

    By the compiled :func:`uq.physics.turbulencekernels.mann_colour` where it may be
    used (:func:`uq.compileguard.cached_kernels`: a first run after an install takes
    numpy while it compiles in the background), else by :func:`mann1998_spectral_factor`
    a few x rows at a time (at most `slab_cells` cells: nine float64 arrays of that
    size): the same numbers to rounding (``tests/physics/test_turbulencekernels.py``).

    Parameters
    ----------
    n0, n1, n2, k1, k2, k3, alpha_epsilon, length_scale, anisotropy, scale
        As :func:`uq.physics.turbulencekernels.mann_colour` (the slab's three complex128
        noise spectra (n1, n2, n3) in C order, its wavenumbers [rad m-1], alpha
        eps^(2/3) [m4/3 s-2], L [m], Gamma [1], sqrt(N dk) [m-3/2]).
    slab_cells : int
        Cells coloured at a time by numpy.
    """
    from uq.compileguard import cached_kernels
    kernels = cached_kernels("uq.physics.turbulencekernels")
    if kernels is not None:
        kernels.mann_colour(n0, n1, n2, k1, k2, k3, alpha_epsilon, length_scale, anisotropy,
                            scale, float(_TABLE[0][0]), float(_TABLE[0][1] - _TABLE[0][0]),
                            np.ascontiguousarray(_TABLE[1]))
        return
    rows = max(1, slab_cells // max(1, n0.shape[1] * n0.shape[2]))
    for start in range(0, n0.shape[0], rows):
        s = slice(start, start + rows)
        c = mann1998_spectral_factor(k1[s, None, None], k2[None, :, None], k3[None, None, :],
                                     alpha_epsilon, length_scale, anisotropy)
        noise = (n0[s].copy(), n1[s].copy(), n2[s].copy())
        for row, out in enumerate((n0, n1, n2)):              # u_k = i C n, Sec. 3 [2]
            out[s] = (1j * scale) * (c[row, 0] * noise[0] + c[row, 1] * noise[1]
                                     + c[row, 2] * noise[2])


def _part_field(spectra, shape):
    """Where a part's field of `shape` (nx, ny', nz') goes: each component at the start
    of its half spectra (3, nx, ny, n) when a slab's field is no longer than its spectra
    (slab i's field then overwrites only what slabs <= i were read from), else new."""
    nx, ny, n = spectra.shape[1:]
    size = int(np.prod(shape))
    if shape[1] * shape[2] > 2 * ny * n:           # float64 (8 bytes) per complex (16)
        return np.empty((3,) + tuple(shape))
    return spectra.reshape(3, -1).view(np.float64)[:, :size].reshape((3,) + tuple(shape))


def box_window(grid, points, margin=0.0):
    """The (y, z) cells of `grid` that hold `points` (..., 3) [m] each moved by up to
    `margin` [m], with the corners trilinear interpolation reads: ((j0, j1), (m0, m1))."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    out = []
    for axis in (1, 2):
        low = (points[:, axis].min() - margin - grid.origin[axis]) / grid.spacing[axis]
        high = (points[:, axis].max() + margin - grid.origin[axis]) / grid.spacing[axis]
        first = max(0, int(np.floor(low)) - 1)
        out.append((first, min(grid.shape[axis], max(int(np.floor(high)) + 2, first + 2))))
    return tuple(out)


def _in_place(transform, array, workers):
    """``array <- transform(array, axis=0)``, in its own memory."""
    out = transform(array, axis=0, overwrite_x=True, workers=workers)
    if out.ctypes.data != array.ctypes.data:      # (scipy writes in place; if not, copy)
        array[...] = out


def mann_box_reference(grid, alpha_epsilon, length_scale, anisotropy, rng, xp=np,
                       slab_cells=constants.BOX_SLAB_CELLS, workers=None):
    """:func:`mann_box` in array code (numpy or CuPy) throughout: the reference the
    host's compiled path is tested against, and the GPU's path. Parameters as
    :func:`mann_box`."""
    fft = _fft(xp)
    kwargs = {"workers": workers} if xp is np else {}
    axes = (1, 2, 3)
    noise = white_noise(rng, (3,) + tuple(grid.shape), xp)
    spectrum = fft.rfftn(noise, axes=axes, **kwargs)
    del noise
    k1, k2, k3 = box_wavenumbers(grid, xp)
    scale = np.sqrt((2.0 * np.pi) ** 3 / np.prod(grid.spacing))    # sqrt(N dk)
    cells, factors = cell_averaged_factors(grid, alpha_epsilon, length_scale, anisotropy)
    index = (slice(None),) + tuple(xp.asarray(i) for i in cells.T)
    noise_cells = spectrum[index]                                   # (3, n): a copy
    for slab in _x_slabs(grid, slab_cells):
        c = mann1998_spectral_factor(k1[slab], k2, k3, alpha_epsilon, length_scale,
                                     anisotropy, xp)
        coloured = sum(c[:, j] * spectrum[j, slab] for j in range(3))   # u_k = i C n
        spectrum[:, slab] = (1j * scale) * coloured
    # near the k1 axis: u_k = C_avg n, C_avg even, so u_-k = u_k^* (module docstring)
    spectrum[index] = scale * xp.einsum("ijn,jn->in", xp.asarray(factors), noise_cells)
    if xp is np:
        kwargs["overwrite_x"] = True
    velocity = fft.irfftn(spectrum, s=tuple(grid.shape), axes=axes, **kwargs)
    return TurbulenceBox(grid=grid, velocity=velocity)


def kaimal_nodes(grid, points, margin=0.0):
    """The (y, z) nodes of a Kaimal box that trilinear sampling of `points` (..., 3) [m],
    each moved by up to `margin` [m], reads: a mask (ny, nz) of the corners of every
    point's cell, widened by the margin's cells. Veers' method needs the field only
    there (the coherence is defined point to point), and its cost grows as the cube of
    their count."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    (ny, nz), (dy, dz) = grid.shape[1:], grid.spacing[1:]
    mask = np.zeros((ny, nz), dtype=bool)
    y = (points[:, 1] - grid.origin[1]) / dy
    z = (points[:, 2] - grid.origin[2]) / dz
    wy, wz = int(np.ceil(margin / dy)), int(np.ceil(margin / dz))
    j0 = np.clip(np.floor(y).astype(int), 0, ny - 1)
    m0 = np.clip(np.floor(z).astype(int), 0, nz - 1)
    for dj in range(-wy, wy + 2):
        for dm in range(-wz, wz + 2):
            mask[np.clip(j0 + dj, 0, ny - 1), np.clip(m0 + dm, 0, nz - 1)] = True
    return mask


def kaimal_box(grid, sigma_u, speed, scale_parameter, rng, xp=np,
               slab_cells=constants.BOX_SLAB_CELLS, nodes=None):
    """A Kaimal field with IEC coherence on a box periodic along x (Veers' method).

    Parameters
    ----------
    grid : BoxGrid
        The box, ``periodic_yz=False``; its (y, z) grid is the set of coherent points.
    nodes : ndarray of bool, shape (ny, nz), optional
        The (y, z) nodes to make the field at (:func:`kaimal_nodes`: those a record
        reads); the others hold 0. Default all.
    sigma_u : float
        Standard deviation of u [m s-1] (v and w: IEC ratios).
    speed : float
        Mean wind speed [m s-1] (Taylor: f = speed k1 / (2 pi)).
    scale_parameter : float
        IEC turbulence scale parameter Lambda_1 [m] (L_u = 8.1 Lambda_1).
    rng : numpy.random.Generator
    xp : module
    slab_cells : int
        Entries of the Cholesky factors computed at a time (memory; the box does not
        depend on it).

    Returns
    -------
    TurbulenceBox
    """
    (nx, ny, nz), (dx, dy, dz) = grid.shape, grid.spacing
    if grid.periodic_yz:
        raise ValueError("kaimal_box: the grid must have periodic_yz=False")
    nodes = np.ones((ny, nz), dtype=bool) if nodes is None else np.asarray(nodes, bool)
    y, z = np.meshgrid(np.arange(ny) * dy, np.arange(nz) * dz, indexing="ij")
    points = np.stack([y[nodes], z[nodes]], axis=-1)
    count = points.shape[0]
    separation = np.linalg.norm(points[:, None] - points[None], axis=-1)
    k1 = 2.0 * np.pi * np.fft.rfftfreq(nx, dx)
    frequency = speed * k1 / (2.0 * np.pi)
    spectra = KaimalSpectra(tuple(np.multiply(constants.IEC_KAIMAL_SIGMA_RATIOS, sigma_u)),
                            tuple(np.multiply(constants.IEC_KAIMAL_LENGTH_FACTORS, scale_parameter)),
                            constants.IEC_COHERENCE_LENGTH_FACTOR * scale_parameter, speed)
    check_kaimal_points(count)
    fft = _fft(xp)
    noise = white_noise(rng, (3, nx, count), xp)
    half = fft.rfft(noise, axis=1)                                    # (3, k1, points)
    del noise
    # two-sided densities in k1 [m3 s-2]: S(f) df / dk1 / 2, Table B.1 [3] via Taylor
    density = np.stack([spectra.spectrum(c, frequency) for c in range(3)]) * speed / (4 * np.pi)
    density[:, 0] = 0.0                                                # the box's mean is zero
    amplitude = xp.asarray(np.sqrt(density * 2.0 * np.pi / dx))        # sqrt(nx dk1 F)
    per_slab = max(1, slab_cells // count ** 2)
    for a in range(0, k1.size, per_slab):
        part = slice(a, min(a + per_slab, k1.size))
        # one coherence, so one Cholesky factor, for the three components
        coherence = spectra.coherence(separation, frequency[part, None, None])
        factor = xp.asarray(np.linalg.cholesky(coherence))
        half[:, part] = xp.einsum("fpq,cfq->cfp", factor, half[:, part]) * amplitude[:, part, None]
    velocity = xp.zeros((3, nx, ny, nz))
    velocity[:, :, xp.asarray(nodes)] = fft.irfft(half, n=nx, axis=1)
    return TurbulenceBox(grid=grid, velocity=velocity)


def box_extent(geometry, length_scale, model="mann", spacing=None, record_duration=None,
               motion_margin=0.0, margin=constants.BOX_MARGIN_LENGTH_SCALES):
    """The cells of :func:`box_for`'s box, counted without allocating anything: (shape,
    spacing [m], (low, high) corners of the probe points with the motion's margin [m],
    record duration [s]). Parameters as :func:`box_for`; the shape is that of a box of
    any size (:func:`check_cells` refuses it)."""
    if model not in ("mann", "kaimal"):
        raise ValueError(f"box_for: model must be 'mann' or 'kaimal', not {model!r}")
    duration = geometry.record_duration if record_duration is None else record_duration
    if not np.isfinite(duration) or duration <= 0:
        raise ValueError("box_for: a record needs a finite duration > 0 [s]")
    step = length_scale / constants.BOX_DEFAULT_CELLS_PER_LENGTH if spacing is None else spacing
    points = np.vstack([np.asarray(geometry.probe_points()).reshape(-1, 3), np.zeros(3)])
    low, high = points.min(axis=0) - motion_margin, points.max(axis=0) + motion_margin
    pad = margin * length_scale if model == "mann" else step
    advected = geometry.speed * (duration + geometry.dwell) + (high[0] - low[0]) + 2 * step
    extent = np.array([advected, high[1] - low[1] + 2 * pad, high[2] - low[2] + 2 * pad])
    cells = np.ceil(extent / step) + 1
    if np.any(cells > 2.0 ** 52):              # beyond any box: no fast length looked for
        shape = tuple(float(c) for c in cells)
    else:
        shape = tuple(int(scipy.fft.next_fast_len(int(c), real=True)) for c in cells)
    return shape, step, (low, high), duration


def box_for(geometry, length_scale, model="mann", spacing=None, record_duration=None,
            motion_margin=0.0, margin=constants.BOX_MARGIN_LENGTH_SCALES,
            max_cells=constants.MAX_BOX_CELLS):
    """Size a box that holds every probe point of a record, refusing one above ``max_cells``.

    The box holds the reference point (0, 0, 0) too, on a line of nodes along x (its
    series is read there without interpolation across the wind). A box narrower than the
    scan or shorter than the large eddies removes variance the lidar would see: a
    periodic (Mann) box extends ``margin`` length scales beyond the probe points on each
    side in y and z (its discrete wavenumbers then keep the variance
    :func:`box_variance` reports); a Kaimal box is not periodic in y and z and
    covers the points with one cell to spare. Along x the box is at least the record's
    advected length ``U T`` plus the points' x extent, so no part of the field is met
    twice in a record.

    Parameters
    ----------
    geometry : ScanGeometry
        The scan (its probe points, speed and record duration).
    length_scale : float
        Mann's L, or the Kaimal model's Lambda_1 [m].
    model : {"mann", "kaimal"}
    spacing : float, optional
        Cell size in x, y and z [m]; default L / 8 (:data:`BOX_DEFAULT_CELLS_PER_LENGTH`).
    record_duration : float, optional
        Record length T [s]; default ``geometry.record_duration`` (must be finite).
    motion_margin : float
        Largest displacement of a probe point by the platform's motion [m].
    margin : float
        Periodic box's margin in y and z on each side [length scales].
    max_cells : int
        Refusal limit [cells].

    Returns
    -------
    BoxGrid

    Raises
    ------
    ValueError
        One line naming the box's size and the limit, before anything is allocated.
    """
    shape, step, (low, high), duration = box_extent(geometry, length_scale, model, spacing,
                                                    record_duration, motion_margin, margin)
    check_cells(shape, max_cells)
    centre = (low + high) / 2.0
    # the reference point (0, 0, 0) on a line of nodes along x: its series is read
    # without interpolating across the wind (the box moves by at most half a cell, inside
    # its margins: 3 L for Mann, a cell for Kaimal)
    across = [-step * round((centre[a] - (shape[a] - 1) * step / 2.0) / -step) for a in (1, 2)]
    origin = (float(low[0] - geometry.speed * (duration + geometry.dwell) - step),
              float(across[0]), float(across[1]))
    return BoxGrid(shape=shape, spacing=(step, step, step), origin=origin,
                   periodic_yz=model == "mann", max_cells=max_cells)
