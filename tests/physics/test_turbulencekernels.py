"""The compiled turbulence kernels against the array code they replace on the host.

Tolerances: both sides are float64 FFTs and sums of the same numbers in another order,
whose relative rounding is ~1e-16 x log2(cells) (~3e-15 here); 1e-13 of the field's
largest value leaves a margin of 30 and still fails at any error of the physics.
"""
import types

import numpy as np
import pytest

from uq.physics import turbulencebox as tb
from uq.physics import turbulencesampling as ts
from uq.physics.scangeometry import conical_scan

RTOL = 1e-13
ALPHA_EPSILON, LENGTH, GAMMA = 0.05, 33.6, 3.9


def numpy_namespace():
    """numpy under another name: the functions take their array-code (CuPy) path."""
    return types.SimpleNamespace(**{k: getattr(np, k) for k in dir(np) if not k.startswith("__")})


@pytest.mark.parametrize("shape", [(64, 16, 12), (30, 9, 11)])
def test_host_box_is_the_reference_box(shape):
    grid = tb.BoxGrid(shape=shape, spacing=(4.2, 4.2, 4.2))
    host = tb.mann_box(grid, ALPHA_EPSILON, LENGTH, GAMMA, np.random.default_rng(5),
                       slab_cells=200).velocity
    reference = tb.mann_box_reference(grid, ALPHA_EPSILON, LENGTH, GAMMA,
                                      np.random.default_rng(5)).velocity
    assert np.max(np.abs(host - reference)) <= RTOL * np.max(np.abs(reference))


@pytest.mark.parametrize("parts", [1, 2, 3])
def test_windowed_box_is_the_box_on_its_window(parts):
    # the window of (y, z) lines, its half spectrum in parts: the box's values there,
    # the window's origin at its first cell, and the generator where one draw leaves it
    grid = tb.BoxGrid(shape=(48, 14, 13), spacing=(4.2, 4.2, 4.2), origin=(-9.0, -20.0, -30.0))
    first = np.random.default_rng(3)
    box = tb.mann_box(grid, ALPHA_EPSILON, LENGTH, GAMMA, first).velocity
    second = np.random.default_rng(3)
    window = tb.mann_box_window(grid, ALPHA_EPSILON, LENGTH, GAMMA, second, ((2, 11), (3, 9)),
                                parts, slab_cells=100)
    part = box[:, :, 2:11, 3:9]
    assert np.max(np.abs(window.velocity - part)) <= RTOL * np.max(np.abs(part))
    assert window.grid.origin == (-9.0, -20.0 + 2 * 4.2, -30.0 + 3 * 4.2)
    assert not window.grid.periodic_yz
    np.testing.assert_array_equal(first.standard_normal(4), second.standard_normal(4))


def test_box_window_holds_the_points_and_their_corners():
    grid = tb.BoxGrid(shape=(40, 30, 30), spacing=(2.0, 2.0, 2.0), origin=(0.0, -30.0, -30.0))
    points = np.array([[5.0, -3.1, 4.0], [9.0, 6.9, -7.5]])
    (j0, j1), (m0, m1) = tb.box_window(grid, points, margin=1.0)
    # y from -4.1 to 7.9 m: cells 12.95 to 18.95, so cells 12 to 19 (the upper corner)
    # and one more below: [11, 20); z from -8.5 to 5 m: cells 10.75 to 17.5: [9, 19)
    assert (j0, j1) == (11, 20) and (m0, m1) == (9, 19)


def _scan_and_box(periodic=True):
    # (a Kaimal box, not periodic in y and z, of one gate: a small coherent (y, z) grid)
    geometry = conical_scan([60.0, 100.0] if periodic else [60.0], vertical=periodic,
                            beam_duration=0.5, record=20.0, offsets=np.linspace(-10.0, 10.0, 5))
    model = "mann" if periodic else "kaimal"
    grid = tb.box_for(geometry, LENGTH, model, motion_margin=2.0)
    rng = np.random.default_rng(2)
    box = tb.mann_box(grid, ALPHA_EPSILON, LENGTH, GAMMA, rng) if periodic else \
        tb.kaimal_box(grid, 1.0, 10.0, LENGTH, rng)
    return geometry, box


@pytest.mark.parametrize("periodic", [True, False])
def test_compiled_sampling_is_the_array_code(periodic):
    # nominal beams, and beams displaced and turned (a moving lidar), both ways
    geometry, box = _scan_and_box(periodic)
    n = 10
    rng = np.random.default_rng(4)
    moved = rng.normal(0.0, 1.0, (n, geometry.n_beams, 3))
    turned = geometry.directions + rng.normal(0.0, 0.01, (n, geometry.n_beams, 3))
    turned /= np.linalg.norm(turned, axis=-1, keepdims=True)
    for kwargs in ({}, {"displacements": moved, "directions": turned,
                        "position": np.array([0.0, 0.0, -60.0])}):
        compiled = ts.record_radial_velocities(box, geometry, n, **kwargs)
        reference = ts.record_radial_velocities(box, geometry, n, xp=numpy_namespace(),
                                                **kwargs)
        assert compiled.shape == (n, geometry.n_beams, geometry.n_gates)
        assert np.max(np.abs(compiled - reference)) <= RTOL * np.max(np.abs(reference))


def test_compiled_sampling_refuses_points_outside_a_window():
    geometry, box = _scan_and_box()
    window = tb.mann_box_window(box.grid, ALPHA_EPSILON, LENGTH, GAMMA, np.random.default_rng(2),
                                ((0, 3), (0, 3)))
    with pytest.raises(ValueError, match="leave the turbulence box along y or z"):
        ts.record_radial_velocities(window, geometry, 2)


def test_colouring_a_k2_with_its_negative_is_colouring_it_alone():
    # mann_colour computes the factor's scalars once for k2 and -k2 (zeta_2 odd, the rest
    # even): the same bits as each computed alone (signs are exact in IEEE arithmetic);
    # the unpaired k2 (0, and one without its negative) are coloured alone
    from uq.physics.turbulencekernels import _k2_partners, mann_colour
    k2 = np.array([0.0, 0.05, 0.1, -0.15, -0.1, -0.05, 0.2])
    np.testing.assert_array_equal(_k2_partners(k2), [-1, 5, 4, -1, -2, -2, -1])
    rng = np.random.default_rng(8)
    noise = [rng.standard_normal((6, k2.size, 5)) + 1j * rng.standard_normal((6, k2.size, 5))
             for _ in range(3)]
    table = (float(tb._TABLE[0][0]), float(tb._TABLE[0][1] - tb._TABLE[0][0]),
             np.ascontiguousarray(tb._TABLE[1]))
    k1 = np.array([-0.2, -0.1, 0.0, 0.1, 0.2, 0.3])   # with k1 = 0: the zetas' limit
    k3 = np.linspace(0.0, 0.4, 5)
    both = [n.copy() for n in noise]
    mann_colour(*both, k1, k2, k3, ALPHA_EPSILON, LENGTH, GAMMA, 2.0, *table)
    both = np.stack(both)
    for j in range(k2.size):
        single = [np.ascontiguousarray(n[:, j:j + 1]) for n in noise]
        mann_colour(*single, k1, k2[j:j + 1], k3, ALPHA_EPSILON, LENGTH, GAMMA, 2.0, *table)
        np.testing.assert_array_equal(np.stack(single)[:, :, 0], both[:, :, j])


def test_window_parts_add_up_to_the_window_in_the_spectra_memory():
    # the parts' fields sum to mann_box_window's field bit for bit (it is their sum), each
    # part's field lies in that part's half spectra where a slab's field fits there
    grid = tb.BoxGrid(shape=(48, 14, 13), spacing=(4.2, 4.2, 4.2))
    whole = tb.mann_box_window(grid, ALPHA_EPSILON, LENGTH, GAMMA, np.random.default_rng(3),
                               ((2, 11), (3, 9)), 2, slab_cells=100).velocity
    total = np.zeros_like(whole)
    for part in tb.mann_box_window_parts(grid, ALPHA_EPSILON, LENGTH, GAMMA,
                                         np.random.default_rng(3), ((2, 11), (3, 9)), 2,
                                         slab_cells=100):
        # 9 x 6 window values per (x, part of 4 or 3 z wavenumbers x 14 y): it fits
        assert part.velocity.base is not None and part.velocity[0].flags.c_contiguous
        total += part.velocity
    np.testing.assert_array_equal(total, whole)


def test_a_windowed_box_is_the_same_bits_on_several_fft_threads():
    # scipy's FFTs share independent 1-D transforms out among their threads: the record
    # box on RECORD_FFT_WORKERS threads is the serial box, bit for bit (cold and warm runs,
    # and machines of any core count, give the same records)
    from uq.constants import RECORD_FFT_WORKERS
    grid = tb.BoxGrid(shape=(64, 16, 14), spacing=(4.2, 4.2, 4.2))
    boxes = [tb.mann_box_window(grid, ALPHA_EPSILON, LENGTH, GAMMA, np.random.default_rng(6),
                                ((2, 13), (1, 12)), 2, slab_cells=300, workers=workers)
             for workers in (None, RECORD_FFT_WORKERS, 3)]
    for box in boxes[1:]:
        np.testing.assert_array_equal(box.velocity, boxes[0].velocity)


@pytest.fixture
def numpy_kernels(monkeypatch):
    """The records' kernels taken as missing from numba's cache (a first run after an
    install, uq.compileguard.cached_kernels): their numpy equivalents run."""
    import uq.compileguard
    monkeypatch.setattr(uq.compileguard, "cached_kernels", lambda name: None)


def test_numpy_colouring_is_the_kernels(numpy_kernels):
    # the host box (whole and windowed, in parts) coloured by numpy a few rows at a time
    # equals the reference box (the same factor, by slabs) and the compiled kernel's box
    grid = tb.BoxGrid(shape=(30, 9, 11), spacing=(4.2, 4.2, 4.2))
    reference = tb.mann_box_reference(grid, ALPHA_EPSILON, LENGTH, GAMMA,
                                      np.random.default_rng(5)).velocity
    numpy_box = tb.mann_box(grid, ALPHA_EPSILON, LENGTH, GAMMA, np.random.default_rng(5),
                            slab_cells=100).velocity
    assert np.max(np.abs(numpy_box - reference)) <= RTOL * np.max(np.abs(reference))
    window = tb.mann_box_window(grid, ALPHA_EPSILON, LENGTH, GAMMA, np.random.default_rng(5),
                                ((2, 8), (3, 9)), 2, slab_cells=100).velocity
    part = reference[:, :, 2:8, 3:9]
    assert np.max(np.abs(window - part)) <= RTOL * np.max(np.abs(part))


def test_compiled_colouring_is_the_numpy_colouring(monkeypatch):
    grid = tb.BoxGrid(shape=(30, 9, 11), spacing=(4.2, 4.2, 4.2))
    compiled = tb.mann_box(grid, ALPHA_EPSILON, LENGTH, GAMMA, np.random.default_rng(5),
                           slab_cells=100).velocity
    import uq.compileguard
    monkeypatch.setattr(uq.compileguard, "cached_kernels", lambda name: None)
    numpy_box = tb.mann_box(grid, ALPHA_EPSILON, LENGTH, GAMMA, np.random.default_rng(5),
                            slab_cells=100).velocity
    assert np.max(np.abs(numpy_box - compiled)) <= RTOL * np.max(np.abs(compiled))


@pytest.mark.parametrize("periodic", [True, False])
def test_numpy_sampling_is_the_kernels(periodic, monkeypatch):
    # the records' sampling along the beams with its kernel missing (numpy's array code)
    # equals the compiled kernel's, nominal and moving beams
    geometry, box = _scan_and_box(periodic)
    rng = np.random.default_rng(4)
    n = 5
    moved = rng.normal(0.0, 0.5, (n, geometry.n_beams, 3))
    turned = geometry.directions + rng.normal(0.0, 0.01, (n, geometry.n_beams, 3))
    turned /= np.linalg.norm(turned, axis=-1, keepdims=True)
    cases = ({}, {"displacements": moved, "directions": turned,
                  "position": np.array([0.0, 0.0, -60.0])})
    compiled = [ts.record_radial_velocities(box, geometry, n, **kwargs) for kwargs in cases]
    import uq.compileguard
    monkeypatch.setattr(uq.compileguard, "cached_kernels", lambda name: None)
    for kwargs, expected in zip(cases, compiled):
        numpy_scans = ts.record_radial_velocities(box, geometry, n, **kwargs)
        assert np.max(np.abs(numpy_scans - expected)) <= RTOL * np.max(np.abs(expected))
