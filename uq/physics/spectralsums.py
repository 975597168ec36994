"""The spectral path's sums in numpy: :func:`pair_sums` and :func:`vector_sums` with the
arguments and the arithmetic of the compiled kernels of :mod:`uq.physics.spectralkernels`
(the eddy lifetime from the same table and the zetas by the array code of
:mod:`uq.physics.turbulencebox`, the transfer interpolated on the same nodes), array by
array instead of point by point.

They stand in for the kernels while these are not in numba's cache (a first run after an
install, ``uq run --model auto``: :func:`uq.compileguard.cached_kernels`), so that the
run does not wait for their compile; the same numbers to rounding (the sums are taken
in another order; ``tests/physics/test_spectralsums.py``).

Conventions and equations: :mod:`uq.physics.spectralkernels`.

References
----------
.. [1] Mann, J. (1994). The spatial structure of neutral atmospheric surface-layer
   turbulence. J. Fluid Mech. 273:141-168.
"""
import numpy as np

from uq.constants import VON_KARMAN_EXPONENT
from uq.physics import turbulencebox

#: 4 pi [1] (the von Karman spectrum's normalisation).
FOUR_PI = 4.0 * np.pi
#: Elements of the largest temporary of :func:`pair_sums` and :func:`vector_sums` [1]
#: (2^20 complex: 16 MB; the pairs, or the points, are taken that many at a time).
PAIR_SUM_ELEMENTS = 2**20


def _transfer(table, kappa, step, tail):
    """P_g(kappa) of every gate, shape (G,) + kappa.shape: gate g's table on |kappa|,
    linear between nodes, `tail` from the last node on, conjugate for kappa < 0."""
    a = np.abs(kappa) / step
    n = table.shape[1]
    beyond = a >= n - 1
    i = np.where(beyond, 0, a).astype(np.int64)
    f = np.where(beyond, 0.0, a - i)
    value = (1.0 - f) * table[:, i] + f * table[:, i + 1]
    value = np.where(beyond, complex(tail, 0.0), value)
    return np.where(kappa >= 0.0, value, np.conj(value))


def _mann_scalars(a, b, c, alpha_epsilon, length_scale, anisotropy, table):
    """k0^2, k30, zeta_1, zeta_2, k0^2 / k^2 and E(k0) / (4 pi k0^4) at k = (a, b, c)
    [rad m-1] (arrays; k1^2 + k2^2 > 0): Mann (1994) Sec. 3.2-3.3 [1]."""
    energy_scale = alpha_epsilon * length_scale ** (5.0 / 3.0)
    ksq = a * a + b * b + c * c
    beta = turbulencebox.eddy_lifetime(np.sqrt(ksq) * length_scale, anisotropy, table=table)
    k30 = c + beta * a                                # Eq. 3.14 [1]
    k0sq = a * a + b * b + k30 * k30
    z1, z2 = turbulencebox._mann1994_zetas(a, b, c, k30, k0sq, ksq, beta, np)
    kl = np.sqrt(k0sq) * length_scale
    energy = energy_scale * kl ** 4 / (1.0 + kl * kl) ** VON_KARMAN_EXPONENT
    return k0sq, k30, z1, z2, k0sq / ksq, energy / (FOUR_PI * k0sq * k0sq)


def pair_sums(k1, k2, k3, alpha_epsilon, length_scale, anisotropy, table_start, table_step,
              table_values, directions, first, second, transfer, kappa_step, tail,
              dwell_length, w2, w3, out):
    """``out[g, p, i] += S[g, p, i]``: :func:`uq.physics.spectralkernels.pair_sums`
    (its parameters and shapes), one k1 node at a time over the whole (k2, k3) plane."""
    table = (table_start, table_step, table_values)
    reach = (transfer.shape[1] - 1) * kappa_step if tail == 0.0 else np.inf
    b, c = k2[:, None], k3[None, :]                                  # (n2, 1), (1, n3)
    for i, a in enumerate(k1):
        x = 0.5 * a * dwell_length
        dwell = 1.0 if x == 0.0 else (np.sin(x) / x) ** 2
        kappa = a * directions[:, 0] + b[..., None] * directions[:, 1] \
            + c[..., None] * directions[:, 2]                           # (n2, n3, B)
        passes = np.abs(kappa) < reach
        k0sq, k30, z1, z2, ratio, factor = _mann_scalars(
            a, b, c, alpha_epsilon, length_scale, anisotropy, table)    # (n2, n3)
        third = (z1[..., None] * directions[:, 0] + z2[..., None] * directions[:, 1]
                 + ratio[..., None] * directions[:, 2])                 # (n2, n3, B)
        m_vec = np.stack(np.broadcast_arrays(directions[:, 0], directions[:, 1], third),
                         axis=-1)                                       # (n2, n3, B, 3)
        along = directions[:, 0] * a + directions[:, 1] * b[..., None] \
            + third * k30[..., None]
        probe = _transfer(transfer, kappa, kappa_step, tail)            # (G, n2, n3, B)
        weighted = (factor * dwell)[..., None]
        step = max(1, PAIR_SUM_ELEMENTS // max(1, probe[..., 0].size))
        for start in range(0, first.size, step):                # pairs a few at a time
            u, v = first[start:start + step], second[start:start + step]
            dot = np.einsum("jmpx,jmpx->jmp", m_vec[:, :, u], m_vec[:, :, v])
            projection = weighted * (k0sq[..., None] * dot - along[..., u] * along[..., v])
            projection = np.where(passes[..., u] & passes[..., v], projection, 0.0)
            terms = projection * probe[..., u] * np.conj(probe[..., v])    # (G, n2, n3, p)
            out[:, start:start + step, i] += np.einsum(
                "gjmp,gpj,gpm->gp", terms, w2[:, start:start + step], w3[:, start:start + step])


def vector_sums(k1, k2, k3, weight, alpha_epsilon, length_scale, anisotropy, table_start,
                table_step, table_values, directions, centres, times, speed, dwell_length,
                reconstruction, transfer, kappa_step, tail, out):
    """``out[g, c] += sum_p w_p G_c Phi G_c^H``: :func:`uq.physics.spectralkernels.
    vector_sums` (its parameters and shapes), a few thousand points at a time."""
    step = max(1, PAIR_SUM_ELEMENTS // (centres.shape[0] * directions.shape[0] * 3))
    for start in range(0, k1.size, step):                     # points a few at a time
        part = slice(start, start + step)
        _vector_part(k1[part], k2[part], k3[part], weight[part], alpha_epsilon,
                     length_scale, anisotropy, (table_start, table_step, table_values),
                     directions, centres, times, speed, dwell_length, reconstruction,
                     transfer, kappa_step, tail, out)


def _vector_part(a, b, c, weight, alpha_epsilon, length_scale, anisotropy, table,
                 directions, centres, times, speed, dwell_length, reconstruction, transfer,
                 kappa_step, tail, out):
    """:func:`vector_sums` of the points (a, b, c) (P,)."""
    k0sq, k30, z1, z2, ratio, factor = _mann_scalars(
        a, b, c, alpha_epsilon, length_scale, anisotropy, table)
    x = 0.5 * a * dwell_length
    dwell = np.where(x == 0.0, 1.0, np.sin(x) / np.where(x == 0.0, 1.0, x))
    factor = factor * weight
    kappa = np.outer(a, directions[:, 0]) + np.outer(b, directions[:, 1]) \
        + np.outer(c, directions[:, 2])                                 # (P, B)
    probe = _transfer(transfer, kappa, kappa_step, tail)                # (G, P, B)
    phase = (a[None, :, None] * centres[:, None, :, 0] + b[None, :, None] * centres[:, None, :, 1]
             + c[None, :, None] * centres[:, None, :, 2]
             - (a[:, None] * speed * times[None, :])[None])            # (G, P, B)
    t = probe * dwell[None, :, None] * np.exp(1j * phase)
    vector = np.einsum("gcb,gpb,bx->gpcx", reconstruction, t, directions)   # (G, P, 3, 3)
    g0, g1 = vector[..., 0], vector[..., 1]
    q2 = z1[None, :, None] * g0 + z2[None, :, None] * g1 + ratio[None, :, None] * vector[..., 2]
    norm = np.abs(g0) ** 2 + np.abs(g1) ** 2 + np.abs(q2) ** 2
    along = np.abs(g0 * a[None, :, None] + g1 * b[None, :, None] + q2 * k30[None, :, None]) ** 2
    out += np.einsum("p,gpc->gc", factor, k0sq[None, :, None] * norm - along)
