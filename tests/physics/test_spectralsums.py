"""The spectral path's numpy sums (uq.physics.spectralsums) against the compiled kernels
they stand in for (uq.physics.spectralkernels) on the same arguments.

Tolerance: both take the same products of the same float64 numbers (the eddy lifetime
from the same table, the transfer from the same nodes), but numpy's vectorised atan, exp
and log may differ from the C library's that the kernels call in the last bit, and the
zetas' difference of two arctangents, times k2 / k1 (up to 1e4 at the smallest k1),
magnifies that: measured 3e-10 of the largest sum. 1e-8 leaves a margin of 30 and still
fails at any difference of formula (the eddy lifetime's table against its exact value
alone moves the sums by 1e-6).
"""
import numpy as np
import pytest

from uq.physics import spectralkernels, spectralsums, turbulencebox
from uq.physics.lidarspectral import probe_transfer_for
from uq.physics.probe import ContinuousWaveProbe, PulsedProbe
from uq.physics.spectralquadrature import PanelRule, geometric_edges, symmetric_edges
from uq.physics.spectraltensor import MannTensor

RTOL = 1e-8
LENGTH, GAMMA = 33.6, 3.9


def _table():
    table = turbulencebox._TABLE
    return (float(table[0][0]), float(table[0][1] - table[0][0]),
            np.ascontiguousarray(table[1]))


def _beams(rng, n):
    directions = rng.normal(size=(n, 3))
    return directions / np.linalg.norm(directions, axis=1)[:, None]


PROBES = {
    # complex transfers, 1 beyond the table (a CW probe): every point sums
    "cw": (lambda: probe_transfer_for(ContinuousWaveProbe(1.565e-6, 0.028, 0.02),
                                      [60.0, 120.0]), 10.0 * 0.5),
    # real transfers, 0 beyond the table (a pulsed probe): points beyond it are skipped
    "pulsed": (lambda: probe_transfer_for(PulsedProbe(18.75, 24.75), [40.0, 100.0]), 0.0),
}


@pytest.mark.parametrize("probe", sorted(PROBES))
def test_numpy_pair_sums_are_the_kernels(probe):
    rng = np.random.default_rng(5)
    make, dwell_length = PROBES[probe]
    transfer = make()
    directions = _beams(rng, 4)
    first, second = np.triu_indices(4)
    rule = PanelRule(geometric_edges(1e-3 / LENGTH, 30.0 / LENGTH, 2), 3)
    cross = PanelRule(symmetric_edges(rule.edges), 3)
    delta = rng.normal(scale=50.0, size=(2, first.size, 3))
    w2 = np.ascontiguousarray(cross.filon(delta[..., 1]))
    w3 = np.ascontiguousarray(cross.filon(delta[..., 2]))
    outs = []
    for module in (spectralkernels, spectralsums):
        out = np.zeros((2, first.size, rule.size), dtype=complex)
        module.pair_sums(rule.nodes, cross.nodes, cross.nodes, 0.05, LENGTH, GAMMA, *_table(),
                         directions, first.astype(np.int64), second.astype(np.int64),
                         np.ascontiguousarray(transfer.table, dtype=complex),
                         float(transfer.step), float(transfer.tail), dwell_length, w2, w3, out)
        outs.append(out)
    compiled, numpy = outs
    assert np.abs(compiled).max() > 0
    assert np.abs(numpy - compiled).max() <= RTOL * np.abs(compiled).max()


@pytest.mark.parametrize("probe", sorted(PROBES))
def test_numpy_vector_sums_are_the_kernels(probe, monkeypatch):
    # in several parts of points (the numpy side's memory bound) as in one
    rng = np.random.default_rng(6)
    make, dwell_length = PROBES[probe]
    transfer = make()
    n_points, n_beams = 3000, 4
    k = rng.normal(scale=0.05, size=(3, n_points))
    k[0] = np.abs(k[0]) + 1e-4                          # k1 > 0
    weight = rng.uniform(size=n_points)
    centres = rng.normal(scale=40.0, size=(2, n_beams, 3))
    reconstruction = rng.normal(size=(2, 3, n_beams))
    times = np.arange(n_beams, dtype=float)
    outs = []
    for module in (spectralkernels, spectralsums):
        out = np.zeros((2, 3))
        module.vector_sums(*k, weight, 0.05, LENGTH, GAMMA, *_table(), _beams(rng, n_beams)
                           if module is None else _beams(np.random.default_rng(7), n_beams),
                           centres, times, 8.0, dwell_length, reconstruction,
                           np.ascontiguousarray(transfer.table, dtype=complex),
                           float(transfer.step), float(transfer.tail), out)
        outs.append(out)
    monkeypatch.setattr(spectralsums, "PAIR_SUM_ELEMENTS", 500)   # parts of ~20 points
    parts = np.zeros((2, 3))
    spectralsums.vector_sums(*k, weight, 0.05, LENGTH, GAMMA, *_table(),
                             _beams(np.random.default_rng(7), n_beams), centres, times, 8.0,
                             dwell_length, reconstruction,
                             np.ascontiguousarray(transfer.table, dtype=complex),
                             float(transfer.step), float(transfer.tail), parts)
    compiled, numpy = outs
    assert np.abs(compiled).max() > 0
    assert np.abs(numpy - compiled).max() <= RTOL * np.abs(compiled).max()
    assert np.abs(parts - compiled).max() <= RTOL * np.abs(compiled).max()
