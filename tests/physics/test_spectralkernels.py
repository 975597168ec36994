"""The compiled pair sums against a numpy evaluation of the same sums."""
import numpy as np

from uq.physics import spectralkernels, turbulencebox
from uq.physics.lidarspectral import probe_transfer_for
from uq.physics.probe import ContinuousWaveProbe
from uq.physics.spectralquadrature import PanelRule, geometric_edges, symmetric_edges
from uq.physics.spectraltensor import MannTensor


def test_pair_sums_equal_the_numpy_sums():
    # three beams, two gates of a CW probe (complex transfers), a dwell; the numpy side
    # takes Phi from MannTensor.matrix (the exact eddy lifetime: the kernel's table is
    # within 3.4e-6 of it, which moves the sums by < 1e-5 relative) and the transfer by
    # the table's own interpolation (ProbeTransfer.__call__)
    rng = np.random.default_rng(5)
    tensor = MannTensor(33.6, 3.9, 0.05)
    directions = rng.normal(size=(3, 3))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    first, second = np.triu_indices(3)
    rule = PanelRule(geometric_edges(1e-3 / 33.6, 30.0 / 33.6, 1), 3)
    cross = PanelRule(symmetric_edges(rule.edges), 3)
    transfer = probe_transfer_for(ContinuousWaveProbe(1.565e-6, 0.028, 0.02), [60.0, 120.0])
    delta = rng.normal(scale=50.0, size=(2, first.size, 3))
    w2, w3 = cross.filon(delta[..., 1]), cross.filon(delta[..., 2])
    out = np.zeros((2, first.size, rule.size), dtype=complex)
    table = turbulencebox._TABLE
    spectralkernels.pair_sums(rule.nodes, cross.nodes, cross.nodes, tensor.alpha_epsilon,
                              33.6, 3.9, float(table[0][0]), float(table[0][1] - table[0][0]),
                              np.ascontiguousarray(table[1]), directions, first, second,
                              transfer.table, float(transfer.step), 0.0, 10.0 * 0.5, w2, w3,
                              out)
    k = np.stack(np.meshgrid(rule.nodes, cross.nodes, cross.nodes, indexing="ij"), axis=-1)
    phi = tensor.matrix(k[..., 0], k[..., 1], k[..., 2])                     # (i, j, m, 3, 3)
    dwell = np.sinc(k[..., 0] * 10.0 * 0.5 / (2 * np.pi)) ** 2
    probe = transfer(k @ directions.T)                                      # (G, i, j, m, B)
    expected = np.zeros_like(out)
    for p, (b, d) in enumerate(zip(first, second)):
        projection = np.einsum("i,...ij,j->...", directions[b], phi, directions[d]) * dwell
        for g in range(2):
            f = projection * probe[g, ..., b] * np.conj(probe[g, ..., d])
            expected[g, p] = np.einsum("ijm,j,m->i", f, w2[g, p], w3[g, p])
    np.testing.assert_allclose(out, expected, rtol=1e-5, atol=1e-5 * np.abs(expected).max())
