"""The campaign's one door to the physics it stands on.

Everything :mod:`uq.campaign` takes from uq's physics passes through this module, so
that a change of the spectral path, of the time-resolved measurement model or of the
Monte Carlo records reaches the campaign here and nowhere else:

* :func:`gate_settings`: the lidar's scenario reduced to one range gate at a campaign
  height, in a given mean wind and turbulence model (validated settings).
* :func:`spectral_terms`: the spectral path of that gate
  (:func:`uq.physics.lidarspectral.mann_lidar_variances`), one k1 node of its wavenumber
  grid at a time and without the record's high-pass: the contribution of each k1 to the
  lidar's u-variance and to the point's. The record's variances, the filtering factor
  and the autocovariance of the lidar's series between scans all follow from these
  (:mod:`uq.campaign.spectra`); summed with the record's high-pass they are the spectral
  path's own record variances (tested).
* :func:`motion_jacobian`: the first derivatives of one scan's horizontal speed Vh with
  respect to the unit phase vector of a harmonic platform motion of given frequency and
  complex amplitude (the GUM's linearisation of the motion, Eq. 13 of JCGM 100 with the
  phase covariance I/2 of :mod:`uq.physics.motion`), by central differences of the
  compiled time-resolved model.
* :func:`motion_shift`: the phase-averaged second-order change of Vh under such a
  motion (the motion's bias of the mean speed).
* :func:`scan_noise_variance`: the GUM variance of one scan's Vh from every error that is
  not the motion (INS readings, radial noise), drawn independently scan by scan as the
  records draw them.
* :func:`monte_carlo_record`: one Monte Carlo record of the lidar
  (:func:`uq.pipeline.records.monte_carlo_record`): the turbulence box, the motion, the
  probe and the errors.

Conventions
-----------
A harmonic motion of frequency f [Hz] moves degree of freedom d
(:data:`uq.physics.motion.DEGREES_OF_FREEDOM`: roll, pitch, yaw [rad]; surge, sway, heave
[m]) as ``x_d(t) = A_d sin(w t + psi_d + phi)``; its *complex amplitude* is ``a_d = A_d
exp(i psi_d)``, and the phase phi of the whole component is uniform (the unit phase vector
``c = (cos phi, sin phi)`` of :mod:`uq.physics.motion`). Times run from the start of the
scan's first beam. The response of degree of freedom d at f is ``z_d = dVh/dc_1 + i
dVh/dc_2`` for ``a = e_d`` (unit amplitude, lag 0); for any a the two derivatives are
``dVh/dc_1 + i dVh/dc_2 = sum_d z_d conj(a_d)`` (linearity), so the component adds the
variance ``|sum_d z_d conj(a_d)|^2 / 2 = z^H M z`` with ``M = a a^H / 2``.
"""
import contextlib
import copy
import dataclasses
import functools
import logging
import threading

import numpy as np

from uq.physics.motion import DEGREES_OF_FREEDOM, Motion, MotionComponent

#: Step of the central differences of :func:`motion_jacobian` [unit phase]: the model is
#: smooth in the phases, so the O(h^2) error is ~1e-8 of the derivative (measured
#: against the numpy model's complex step: 2.5e-8 relative), far below any other error.
RESPONSE_STEP = 1e-4
#: Radius of the phase vectors of :func:`motion_shift` [1]: the motion is scaled by
#: it, so the second-order change is resolved (1e-6 of U) while the fourth order stays
#: 1e-6 of it.
CURVATURE_SCALE = 1e-3
#: Phases of the quadrature over a component's uniform phase [1]: equally spaced, they
#: average the first and third harmonics in the phase (odd orders) and the second
#: (the oscillating part of the second order) exactly; the fourth order, O(scale^4), is
#: what remains.
CURVATURE_PHASES = 8
#: Components of one call of the compiled model in :func:`motion_jacobian` and
#: :func:`motion_shift`: every trial holds every component of the call (one moved, the
#: others at rest), so a call costs ~ n^2; 64 keeps it at a few milliseconds.
MOTION_CHUNK = 64
#: The record of :func:`gate_settings` (the spectral path's record and the Monte Carlo
#: records) holds this many records per scene: the campaign draws them itself.
GATE_RECORDS = 2


def gate_settings(lidar, heights, turbulence, record_duration, speed=10.0, direction=0.0,
                  intensity=0.1, motion=None):
    """Validated settings of the campaign lidar's gates at `heights` [m] above sea level.

    Parameters
    ----------
    lidar : dict
        Validated settings of the lidar's scenario (:class:`uq.pipeline.scenario.Scenario`
        ``.settings``): its geometry, probe, scan timing, INS, errors and correction;
        its ``motion`` and ``sweep`` are left out, its ``wind.shear`` kept.
    heights : sequence of float
        Gate heights [m]; a gate's range is ``height - lidar.height`` (an upward lidar).
        The first is the reference height of the wind (its speed and direction); the
        spectral path of each gate does not depend on it (a homogeneous field), the
        measurement model's wind does (the power law): give one height for that.
    turbulence : dict
        ``{model, length_scale, anisotropy}`` of the field (Mann).
    record_duration : float
        [s].
    speed, direction : float
        Mean wind at the gate [m s-1], "from" [deg].
    intensity : float
        The field's sigma_u / U [1] (the spectral path is linear in its square).
    motion : dict, optional
        A scenario ``motion`` section (the Monte Carlo records' sea state).
    """
    from uq.pipeline.scenario import load_scenario
    raw = copy.deepcopy(lidar)
    for key in ("motion", "sweep", "turbulence", "record"):
        raw.pop(key, None)
    heights = [float(h) for h in heights]
    raw["name"] = f"{lidar.get('name', 'lidar')}_at_{heights[0]:g}"
    raw["wind"] = {**raw["wind"], "speed": float(speed), "direction": float(direction) % 360.0,
                   "reference_height": heights[0]}
    raw["lidar"] = {**raw["lidar"], "ranges": [h - lidar["lidar"]["height"] for h in heights]}
    raw["turbulence"] = {**turbulence, "intensity": float(intensity)}
    raw["record"] = {"duration": float(record_duration), "count": GATE_RECORDS}
    raw["outputs"] = ["wind_speed"]
    if motion:
        raw["motion"] = motion
    return _quiet(load_scenario, raw).settings


#: Threads inside :func:`_quiet` (a thread-local flag: the campaign builds its scenes on
#: several threads at once, and a logger's level is the whole process's).
_QUIET = threading.local()


class _QuietFilter(logging.Filter):
    """Drops the scenario's warnings logged by a thread inside :func:`_quiet` (errors
    pass); other threads' are untouched."""

    def filter(self, record):
        return getattr(_QUIET, "depth", 0) == 0 or record.levelno >= logging.ERROR


_SCENARIO_LOGGER = logging.getLogger("uq.pipeline.scenario")
if not any(isinstance(f, _QuietFilter) for f in _SCENARIO_LOGGER.filters):
    _SCENARIO_LOGGER.addFilter(_QuietFilter())


def _quiet(function, *args):
    """`function(*args)` without the scenario's warnings about keys that have no effect
    in this reduced scene (an INS rate without motion: the campaign gives the motion),
    in this thread alone: the logger's level is left as it is (setting it, then putting
    it back, from threads at once could leave it raised for the whole process)."""
    _QUIET.depth = getattr(_QUIET, "depth", 0) + 1
    try:
        return function(*args)
    finally:
        _QUIET.depth -= 1


def default_length_scale(height):
    """IEC 61400-1's Mann length scale at `height` [m]: 0.8 Lambda_1 [m]
    (:func:`uq.pipeline.turbulencesection.default_length_scale`)."""
    from uq.pipeline.turbulencesection import default_length_scale as default
    return default("mann", height)


def with_wind(settings, speed, direction):
    """`settings` (validated) with another mean wind [m s-1, deg "from"] (a copy)."""
    out = dict(settings)
    out["wind"] = {**settings["wind"], "speed": float(speed),
                   "direction": float(direction) % 360.0}
    return out


# --- the spectral path -----------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class SpectralTerms:
    """The spectral path of one gate, per k1 node, without the record's high-pass.

    Attributes
    ----------
    k1 : ndarray, shape (n,)
        Along-wind wavenumbers [rad m-1] (the grid's nodes, k1 > 0).
    lidar : ndarray, shape (n,) or (n, n_gates)
        Each node's contribution to the lidar's reconstructed u-variance [m2 s-2]
        (quadrature weight, the factor 2 of the even integrand and the tensor's cross
        section included), per gate.
    point : ndarray, shape (n,)
        The same for u at the reference point [m2 s-2].
    weight : ndarray, shape (n,)
        The nodes' quadrature weights in k1 [rad m-1], the factor 2 of the even
        integrand included (a term over its weight is the integrand at k1 > 0, half the
        one-sided density).
    speed : float
        Mean speed [m s-1]; ``f = k1 U / (2 pi)``.
    scan_period, record_duration : float
        [s].
    high_pass : ndarray, shape (n,), optional
        Each node's share of the record's high-pass ``1 - |D_N(f)|^2`` [1]: the weight
        of the node in the spectral path's record integral over its weight without the
        high-pass (:func:`spectral_terms`); None: the high-pass at the node
        (:func:`record_high_pass`).
    """

    k1: np.ndarray
    lidar: np.ndarray
    point: np.ndarray
    weight: np.ndarray
    speed: float
    scan_period: float
    record_duration: float
    high_pass: np.ndarray = None

    @property
    def frequency(self):
        """Frequencies of the nodes [Hz] (Taylor)."""
        return self.k1 * self.speed / (2.0 * np.pi)

    def gate(self, index):
        """The terms of one gate (``lidar`` of shape (n,))."""
        return dataclasses.replace(self, lidar=np.asarray(self.lidar)[:, index])


def spectral_terms(settings):
    """:class:`SpectralTerms` of validated gate `settings` (:func:`gate_settings`): the
    spectral path (:func:`uq.physics.lidarspectral.mann_lidar_variances`) per node of
    its own k1 rule, without the record's high-pass.

    A few beams (a DBS): the path integrates each beam pair's ``exp(i k . delta)`` on
    Cartesian Gauss-Legendre panels with Filon weights (k2, k3 in its compiled kernel,
    then k1). Here the kernel's (k2, k3) sums are taken as the path takes them, at the
    nodes of its k1 rule, and each k1 node's term is the pair's sum times the node's
    Filon weight in k1 (no high-pass): summed, the terms are the path's variance of an
    infinite record exactly. The record's high-pass is carried as each node's share of
    the path's record weights (:func:`~uq.physics.spectralquadrature.record_weights` at
    zero separation over the Filon weights: ``high_pass``), so that the terms summed
    with it are the path's record variances (to the phase of the pairs inside the
    record's peaks: tested against :func:`uq.pipeline.records.spectral_variances`). The
    rule is the path's first that meets :data:`~uq.constants.SPECTRAL_TOLERANCE`
    (the same estimate: two nodes fewer a panel), refined as the path refines it. The
    point's terms are its 1-D spectrum at the same nodes, the rule continued to the
    path's ``10^6 / L`` (the lidar's terms there are 0: beyond its probe's reach).

    Many beams (a VAD): the log-polar grid's k1 nodes, one call of the path's vector
    sums a node (the path's own chunks of k1), the high-pass at the nodes."""
    from uq.physics.lidarspectral import PAIR_BEAMS, as_transfer, probe_transfer_for
    from uq.pipeline import probesection
    from uq.pipeline.records import turbulence_model
    from uq.pipeline.turbulencesection import scan_geometry, slant_ranges
    geometry = scan_geometry(settings)
    lidar = settings["lidar"]
    tensor = turbulence_model(settings["turbulence"], settings["wind"]["speed"])
    if not hasattr(tensor, "anisotropy"):
        raise ValueError("campaign: the spectral terms need the Mann tensor "
                         "(turbulence.model: mann)")
    transfer = as_transfer(probe_transfer_for(probesection.make_probe(lidar.get("probe")),
                                              slant_ranges(lidar)),
                           geometry.n_gates, tensor.length_scale)
    if geometry.n_beams <= PAIR_BEAMS:
        k1, weight, lidar_terms, point_terms, high = _pair_terms(geometry, tensor, transfer)
    else:
        k1, weight, lidar_terms, point_terms, high = _vector_terms(geometry, tensor, transfer)
    return SpectralTerms(k1, lidar_terms, point_terms, weight, geometry.speed,
                         geometry.scan_period, geometry.record_duration, high)


def _pair_terms(geometry, tensor, transfer):
    """(k1, weights, lidar terms (n, n_gates), point terms (n,), high-pass (n,)) of the
    beam-pair path (:func:`spectral_terms`)."""
    from uq.constants import SPECTRAL_REFINEMENTS, SPECTRAL_TOLERANCE
    from uq.physics.lidarspectral import PAIR_ERROR_FLOOR, PairResolution
    length = tensor.length_scale
    level = PairResolution()
    for attempt in range(SPECTRAL_REFINEMENTS + 1):
        found = _pair_level(geometry, tensor, transfer, level)
        fine = _summed(found, found[4])
        coarse_found = _pair_level(geometry, tensor, transfer, level, coarse=True)
        coarse = _summed(coarse_found, coarse_found[4])
        lidar_fine, point_fine = fine
        error = np.maximum(np.abs(lidar_fine - coarse[0]), PAIR_ERROR_FLOOR * np.abs(lidar_fine))
        if np.max(error / np.maximum(np.abs(lidar_fine), 0.05 * point_fine)) \
                <= SPECTRAL_TOLERANCE or attempt == SPECTRAL_REFINEMENTS:
            return found
        level = level.refined()
    return found                                                   # pragma: no cover


def _summed(found, high):
    """(lidar (n_gates,), point) record variances of :func:`_pair_level`'s terms."""
    _, _, lidar, point, _ = found
    return np.einsum("ng,n->g", lidar, high), float(np.sum(point * high))


def _pair_level(geometry, tensor, transfer, level, coarse=False):
    """The beam-pair path's terms per k1 node on the rules of `level`
    (:class:`~uq.physics.lidarspectral.PairResolution`; `coarse`: two nodes fewer a
    panel, the path's error estimate)."""
    from uq.physics import turbulencebox
    from uq.physics.lidarspectral import _pair_separations, spectral_sums
    from uq.physics.spectralquadrature import PanelRule, geometric_edges, record_weights
    length = tensor.length_scale
    first, second, delta = _pair_separations(geometry)
    colocated = None
    if np.isfinite(transfer.reach):        # as uq.physics.lidarspectral._pair_variances
        high = max(1e3, min(1e6, transfer.reach * length))
    else:
        distance = np.linalg.norm(delta, axis=-1)
        colocated = distance <= length * 1e-3
        apart = distance[~colocated]
        high = 1e3 if apart.size == 0 else float(np.clip(100 * length / apart.min(), 10, 1e3))
    order = max(1, level.order - 2) if coarse else level.order
    rule1, rule2, rule3 = level.rules(length, high, order)
    # the point's rule: the lidar's continued to 10^6 / L (mann_point_variances' reach)
    tail = PanelRule(geometric_edges(high / length, 1e6 / length, level.per_decade,
                                     zero=False), order) if high < 1e6 else None
    rules = [rule1] if tail is None else [rule1, tail]
    k1 = np.concatenate([r.nodes for r in rules])
    weight = 2.0 * np.concatenate([r.weights for r in rules])     # k1 > 0, doubled
    pairs = np.zeros((geometry.n_gates, first.size, k1.size))
    if colocated is None or not colocated.all():
        sums = np.zeros((geometry.n_gates, first.size, rule1.size), dtype=complex)
        table = turbulencebox._TABLE
        spectral_sums().pair_sums(
            rule1.nodes, rule2.nodes, rule3.nodes, tensor.alpha_epsilon, length,
            tensor.anisotropy, float(table[0][0]), float(table[0][1] - table[0][0]),
            np.ascontiguousarray(table[1]),
            np.ascontiguousarray(geometry.directions, dtype=float), first.astype(np.int64),
            second.astype(np.int64), np.ascontiguousarray(transfer.table, dtype=complex),
            float(transfer.step), float(transfer.tail), geometry.speed * geometry.dwell,
            np.ascontiguousarray(rule2.filon(delta[..., 1])),
            np.ascontiguousarray(rule3.filon(delta[..., 2])), sums)
        # beyond rule1 (the tail) the probes pass nothing: 0
        pairs[..., :rule1.size] = 2.0 * (sums * rule1.filon(delta[..., 0])).real
    directions = np.asarray(geometry.directions, dtype=float)
    spectra = tensor.alpha_epsilon * _unit_point_spectra(
        length, tensor.anisotropy, tuple(np.concatenate([r.edges for r in rules])), order,
        (8, 48) if coarse else (12, 64))                                  # (n, 3, 3)
    if colocated is not None and colocated.any():     # point probes: the whole rule
        dwell = np.sinc(k1 * geometry.speed * geometry.dwell / (2 * np.pi)) ** 2
        same = np.einsum("pi,nij,pj->pn", directions[first], spectra,
                         directions[second]) * dwell * weight
        pairs = np.where(colocated[..., None], same[None], pairs)
    matrix = np.zeros((geometry.n_gates, geometry.n_beams, geometry.n_beams, k1.size))
    matrix[:, first, second] = pairs
    matrix[:, second, first] = pairs
    reconstruction = np.asarray(geometry.reconstruction, dtype=float)[:, 0]   # u: (G, B)
    lidar = np.einsum("gb,gbdn,gd->ng", reconstruction, matrix, reconstruction)
    point = weight * spectra[:, 0, 0]
    high_pass = np.concatenate([
        record_weights(r, 0.0, geometry.speed, geometry.scan_period,
                       geometry.record_duration).real / r.weights for r in rules])
    return k1, weight, lidar, point, high_pass


@functools.lru_cache(maxsize=32)
def _unit_point_spectra(length, anisotropy, edges, order, cross_section):
    """The 1-D cross-spectra (n, 3, 3) [m3 s-2] of the Mann tensor of unit alpha
    eps^(2/3), scale `length` [m] and `anisotropy`, at the nodes of the panels `edges`
    (the rules of :func:`_pair_level`, concatenated; `order` nodes each) on the log-polar
    cross-section (radial nodes a decade, angles) of ``mann_point_variances``: a function
    of these alone, so kept per process (a campaign's gates share L and Gamma whatever
    the wind)."""
    from uq.physics.lidarspectral import _one_dimensional_spectra
    from uq.physics.spectralquadrature import PanelRule
    from uq.physics.spectraltensor import MannTensor, WavenumberGrid
    edges = np.asarray(edges)
    breaks = np.flatnonzero(np.diff(edges) <= 0) + 1           # where a rule starts again
    k1 = np.concatenate([PanelRule(part, order).nodes for part in np.split(edges, breaks)])
    grid = WavenumberGrid(length, radius_per_decade=cross_section[0],
                          angle_nodes=cross_section[1])
    tensor = MannTensor(length, anisotropy)
    out = np.concatenate([_one_dimensional_spectra(tensor, grid, k1[s:s + 12])
                          for s in range(0, k1.size, 12)])
    out.flags.writeable = False
    return out


def _unit_tensor(tensor):
    """The Mann tensor of `tensor`'s L and Gamma at unit alpha eps^(2/3)."""
    from uq.physics.spectraltensor import MannTensor
    return MannTensor(tensor.length_scale, tensor.anisotropy)


@dataclasses.dataclass(frozen=True)
class _Nodes:
    """A :class:`~uq.physics.spectraltensor.WavenumberGrid` restricted to some of its k1
    nodes (their weights unchanged): the vector sums over those nodes alone."""

    grid: object
    nodes: tuple

    @property
    def length_scale(self):
        return self.grid.length_scale

    def k1(self):
        k1, weights = self.grid.k1()
        return k1[list(self.nodes)], weights[list(self.nodes)]

    def cross_section(self, k1):
        return self.grid.cross_section(k1)


def _vector_terms(geometry, tensor, transfer):
    """(k1, weights, lidar terms, point terms, high-pass) of the vector path (many
    beams: :func:`spectral_terms`) on the log-polar grid the path accepts (its own
    estimate and refinements: :func:`uq.physics.lidarspectral.mann_lidar_variances`);
    the path takes the record's high-pass at the grid's k1 nodes, and so do the terms."""
    from uq.constants import SPECTRAL_REFINEMENTS, SPECTRAL_TOLERANCE
    from uq.physics.lidarspectral import (_one_dimensional_spectra, _refined_polar,
                                          _relative_error, _vector_sum, _vector_variances,
                                          mann_point_variances)
    from uq.physics.spectraltensor import WavenumberGrid
    grid = WavenumberGrid(tensor.length_scale)
    true = mann_point_variances(geometry, tensor)[0]
    for attempt in range(SPECTRAL_REFINEMENTS):
        lidar, error = _vector_variances(geometry, tensor, transfer, grid)
        if _relative_error(lidar, error, true) <= SPECTRAL_TOLERANCE:
            break
        grid = _refined_polar(grid)
    unfiltered = dataclasses.replace(geometry, record_duration=np.inf)
    k1, weight = grid.k1()
    lidar = np.stack([_vector_sum(unfiltered, tensor, transfer, _Nodes(grid, (node,)))[:, 0]
                      for node in range(k1.size)])
    point = weight * tensor.alpha_epsilon * np.concatenate(
        [_one_dimensional_spectra(_unit_tensor(tensor), grid, k1[s:s + 12])[:, 0, 0]
         for s in range(0, k1.size, 12)])
    high = record_high_pass(k1 * geometry.speed / (2 * np.pi), geometry.scan_period,
                            geometry.record_duration)
    return k1, weight, lidar, point, high


def record_high_pass(frequency, scan_period, record_duration):
    """``1 - |D_N(f)|^2`` [1] of a record of `record_duration` [s] sampled every
    `scan_period` [s] at `frequency` [Hz]: the spectral path's own high-pass
    (:func:`uq.physics.lidarspectral.record_filter`)."""
    from uq.physics.lidarspectral import record_filter
    return record_filter(frequency, scan_period, record_duration)


def spectral_ratio(settings):
    """The spectral path's u-variance ratio of each gate (its record's high-pass
    included), as ``uq run`` computes it (:func:`uq.pipeline.records.spectral_variances`),
    shape (n_gates,)."""
    from uq.pipeline.records import spectral_variances
    return np.asarray(spectral_variances(settings)[0].ratio(), float)


def point_record_variance(length_scale, anisotropy, intensity, speed, scan_period,
                          record_duration):
    """Expected variance [m2 s-2] of u at a point sampled once a scan over a record
    (the record's high-pass), for a Mann field of point sigma_u / U = `intensity`."""
    from uq.physics.lidarspectral import record_filter
    from uq.physics.spectraltensor import mann_tensor_for_intensity, point_variances
    tensor = mann_tensor_for_intensity(intensity, speed, length_scale, anisotropy)
    return float(point_variances(tensor, spectral_filter=lambda k1: record_filter(
        k1 * speed / (2 * np.pi), scan_period, record_duration))[0])


# --- the motion ------------------------------------------------------------------------

def motion_scene(settings, components=()):
    """The time-resolved scene of validated `settings` with the harmonic `components`
    (:class:`uq.physics.motion.MotionComponent`, random phases) as its motion, its
    lever arm, scan timing and INS sampling the scenario's (defaults where it gives none);
    the probe resolved."""
    from uq.physics import probe
    from uq.physics.ins import InsSampling
    from uq.physics.scene import TimeResolved
    from uq.physics.timing import ScanTiming
    from uq.pipeline.modelsetup import scene_from_settings
    from uq.pipeline.motionsection import SCAN_DEFAULTS
    lidar, ins = settings["lidar"], settings["ins"]
    motion = Motion(tuple(components), tuple(lidar.get("lever_arm", (0.0, 0.0, 0.0))))
    resolved = TimeResolved(motion, ScanTiming(**{**SCAN_DEFAULTS, **lidar.get("scan", {})}),
                            InsSampling(ins.get("rate"), ins.get("interpolation", "linear")))
    scene = dataclasses.replace(scene_from_settings(settings), time_resolved=resolved)
    return probe.resolve(scene)


def components_of(frequency, amplitude):
    """MotionComponents (random phases) of frequencies [Hz], shape (K,), and complex
    amplitudes ``A exp(i psi)`` per degree of freedom, shape (K, 6) [rad, m]."""
    amplitude = np.asarray(amplitude, complex)
    return tuple(MotionComponent(2.0 * np.pi * float(f), tuple(np.abs(a).tolist()),
                                 tuple(np.angle(a).tolist()), None)
                 for f, a in zip(np.asarray(frequency, float), amplitude))


def scan_speeds(settings, components, phases):
    """Vh [m s-1] of the gate's scan under `components` with the unit phase vectors
    `phases` (n, K, 2) (the compiled model; the numpy model within
    :func:`numpy_motion_model`), every other input at its mean."""
    from uq.physics.measurement import measurement_model
    scene = motion_scene(settings, components)
    fixed = _mean_errors(settings, scene)
    return np.real(measurement_model(scene, ("wind_speed",), motion_phases=phases,
                                     compiled=not _NUMPY_MOTION[0],
                                     **fixed)["wind_speed"])[:, 0]


_NUMPY_MOTION = [0]                      # numpy_motion_model entered and not left


@contextlib.contextmanager
def numpy_motion_model():
    """Within (process-wide, every thread): :func:`scan_speeds` evaluates the numpy
    model (the compiled model's numbers to rounding; a first campaign after an install,
    while the compiled one's kernels are not in numba's cache)."""
    _NUMPY_MOTION[0] += 1
    try:
        yield
    finally:
        _NUMPY_MOTION[0] -= 1


def motion_kernels_missing(settings):
    """The :class:`~uq.compileguard.KernelNotCached` of the first kernel of the compiled
    motion model that numba's cache lacks (one scan of gate `settings` evaluated with
    nothing compiled), else None."""
    from uq.compileguard import KernelNotCached, cached_only
    try:
        with cached_only():
            scan_speeds(settings, components_of([0.1], [[1.0, 0, 0, 0, 0, 0]]),
                        np.zeros((1, 1, 2)))
    except KernelNotCached as error:
        return error
    return None


#: The motion's own inputs: the phases the derivatives are taken in (every other input,
#: the INS's sampling offset among them, is held at its mean, where the GUM linearises).
PHASE_INPUTS = ("motion_phases", "motion_window")


def _mean_errors(settings, scene):
    """Every input of the scene but the phases at its mean (floats): the bias an error
    declares, zero otherwise; the INS's sampling offset half its period."""
    from uq.pipeline.modelsetup import error_inputs
    from uq.engine.inputs import Input
    out = {}
    for name, spec in error_inputs(settings, scene.n_beams, 1).items():
        if name in PHASE_INPUTS:
            continue
        dist = spec.distribution if isinstance(spec, Input) else spec
        out[name] = dist if isinstance(dist, float) else float(dist.mean())
    return out


def motion_jacobian(settings, frequency, amplitude):
    """``dVh/dc_1 + i dVh/dc_2`` [m s-1] of each component (frequencies [Hz] (K,),
    complex amplitudes (K, 6)) at rest (c = 0), shape (K,): central differences of the
    compiled model, one component moved at a time (:data:`MOTION_CHUNK` components a
    call)."""
    return np.concatenate([_jacobian(settings, frequency[i:i + MOTION_CHUNK],
                                     amplitude[i:i + MOTION_CHUNK])
                           for i in range(0, len(frequency), MOTION_CHUNK)]) \
        if len(frequency) else np.zeros(0, complex)


def _jacobian(settings, frequency, amplitude):
    components = components_of(frequency, amplitude)
    count = len(components)
    phases = np.zeros((4 * count, count, 2))
    index = np.arange(count)
    for sign, offset in ((1.0, 0), (-1.0, 1)):
        phases[4 * index + offset, index, 0] = sign * RESPONSE_STEP
        phases[4 * index + 2 + offset, index, 1] = sign * RESPONSE_STEP
    speed = scan_speeds(settings, components, phases)
    first = (speed[0::4] - speed[1::4]) / (2 * RESPONSE_STEP)
    second = (speed[2::4] - speed[3::4]) / (2 * RESPONSE_STEP)
    return first + 1j * second


def motion_shift(settings, frequency, amplitude):
    """The phase-averaged second-order change of Vh [m s-1] under each component alone
    (frequencies [Hz] (K,), complex amplitudes (K, 6)): ``(mean over the phases of
    Vh(s c) - Vh(0)) / s^2`` with s = :data:`CURVATURE_SCALE`, :data:`CURVATURE_PHASES`
    equally spaced phases (module constants): ``a^H G a`` at unit scale, G the Hermitian
    form of the second derivatives averaged over the phase."""
    return np.concatenate([_shift(settings, frequency[i:i + MOTION_CHUNK],
                                  amplitude[i:i + MOTION_CHUNK])
                           for i in range(0, len(frequency), MOTION_CHUNK)]) \
        if len(frequency) else np.zeros(0)


def _shift(settings, frequency, amplitude):
    components = components_of(frequency, amplitude)
    count, p = len(components), CURVATURE_PHASES
    angle = 2.0 * np.pi * np.arange(p) / p
    phases = np.zeros((count * p + 1, count, 2))
    rows = np.arange(count * p)
    which = rows // p
    phases[rows, which, 0] = CURVATURE_SCALE * np.cos(angle[rows % p])
    phases[rows, which, 1] = CURVATURE_SCALE * np.sin(angle[rows % p])
    speed = scan_speeds(settings, components, phases)           # last row: at rest
    return (speed[:-1].reshape(count, p).mean(axis=1) - speed[-1]) / CURVATURE_SCALE ** 2


def scan_noise_variance(settings):
    """The GUM variance [m2 s-2] of one scan's Vh from every input that is not the
    motion (INS errors, radial noise, the probe's parameters), the platform at rest
    (complex-step Jacobian, JCGM 100 Eq. 13 with the inputs' correlations)."""
    from uq.engine.gum import combined_uncertainty, complex_step_jacobian
    from uq.engine.inputs import input_set
    from uq.physics.measurement import measurement_model
    from uq.pipeline.modelsetup import MOTION_INPUTS, error_inputs
    scene = motion_scene(settings)
    inputs = {name: spec for name, spec in error_inputs(settings, scene.n_beams, 1).items()
              if name not in MOTION_INPUTS}
    layout = input_set(inputs)
    if layout.dimension == 0:
        return 0.0
    _, jacobian = complex_step_jacobian(
        lambda **errors: measurement_model(scene, ("wind_speed",),
                                           compiled=not _NUMPY_MOTION[0], **errors), layout)
    return float(combined_uncertainty(jacobian["wind_speed"], layout)[0] ** 2)


# --- Monte Carlo records -----------------------------------------------------------------

def monte_carlo_record(settings, rng):
    """One Monte Carlo record of validated gate `settings` (with its ``motion`` and
    ``turbulence``): Vh once a scan [m s-1], shape (n_scans,), and the field's u at the
    reference point once a scan [m s-1], shape (n_scans,), the mean speed included
    (:func:`uq.pipeline.records.monte_carlo_record`'s
    :class:`~uq.pipeline.records.RecordSeries`; `rng` the record's generator)."""
    from uq.pipeline.records import monte_carlo_record as record
    from uq.pipeline.turbulencesection import scan_geometry, scans_per_record
    series = record(settings, scan_geometry(settings), scans_per_record(settings), rng)
    return np.asarray(series.speed)[:, 0], np.asarray(series.reference)[:, 0]


def scans_per_record(settings):
    """Whole scans in one record of validated `settings` [1]."""
    from uq.pipeline.turbulencesection import scans_per_record as scans
    return scans(settings)


def scan_period(settings):
    """The scan's period [s] (beams times the beam duration)."""
    from uq.pipeline.turbulencesection import beam_duration
    lidar = settings["lidar"]
    return (len(lidar["azimuths"]) + int(lidar["vertical_beam"])) * beam_duration(lidar)
