"""Record mode: the turbulence intensity a lidar reports over a record, by the spectral
path (:mod:`uq.physics.lidarspectral`), beside the per-scan results.

For each scene, ``turbulence_intensity_spectral`` at each gate is::

    TI_lidar = sqrt(var_turbulence + u_scan^2) / Vh_true

* ``var_turbulence`` [m2 s-2]: the expected record variance of the reconstructed
  along-wind component u_x from the turbulence alone, the spectral tensor filtered by the
  scan's transfer function (probe weighting, beam positions, beam times through Taylor's
  hypothesis, reconstruction, the record's high-pass; :func:`uq.physics.lidarspectral.
  lidar_variances` of :func:`uq.pipeline.turbulencesection.scan_geometry`). For the wind
  along x, ``var(Vh) = var(u_x)`` to O(sigma^4 / U^2).
* ``u_scan`` [m s-1]: the standard uncertainty of one scan's Vh from everything else
  (motion with its random phases, INS errors, noise; ``wind_speed_mc_u``, or
  ``wind_speed_gum_u`` where ``sampling.method`` is ``none``): these errors are drawn
  independently scan by scan and uncorrelated with the turbulence, so their variance
  adds (the record's high-pass takes 1/N of it, N the scans of a record, negligible).
* ``Vh_true``: the true horizontal speed at the gate (``wind_speed_true``).

Both are the expected sample variance of a record, as a lidar's software and the Monte
Carlo records reduce it (``N - 1`` in the denominator: ``N / (N - 1)`` times the spectral
path's variance about the record's mean).

``turbulence_intensity_true`` is the expected ``sigma_u / U`` of the field at the
reference point over the record (the same high-pass and scan sampling), so that
(``turbulence_intensity_spectral`` / ``turbulence_intensity_true``)^2 is the lidar's
u-variance ratio (Sathe et al. 2011) where motion and errors are absent and there is no
shear. ``turbulence_intensity_point`` is the scenario's intensity (no high-pass).

Unless ``sampling.method`` is ``none``, ``record.count`` Monte Carlo records per scene
give the distribution of the apparent TI and of the record mean
(:func:`monte_carlo_variables`).
"""
import collections
import copy
import dataclasses
import functools
import hashlib
import json
import math
import logging
import threading
import typing

import numpy as np
from scipy import signal

from uq.physics.lidarspectral import lidar_variances, probe_transfer_for
from uq.physics.spectraltensor import KaimalSpectra, mann_tensor_for_intensity
from uq.pipeline import probesection
from uq.pipeline.metadata import turbulence_intensity_attributes
from uq.constants import KAIMAL_LENGTH_FACTOR as LENGTH_FACTORS_KAIMAL
from uq.constants import (RECORD_BOX_SLAB_CELLS, RECORD_FFT_WORKERS, RECORD_SPECTRA_BYTES,
                          RECORD_MAX_BOX_CELLS,
                          SPECTRAL_REFINEMENTS, SPECTRAL_TOLERANCE,
                          SPECTRAL_PATHS_KEPT, UNIT_RECORD_CACHE_BYTES)
from uq.pipeline.turbulencesection import (record_points, scan_geometry, scans_per_record,
                                           slant_ranges)

log = logging.getLogger(__name__)

#: Attributes of the record-mode variables.
RECORD_ATTRIBUTES = {
    "turbulence_intensity_mc_mean": {
        "units": "1", "long_name": "Monte Carlo mean over records of the apparent "
        "turbulence intensity std(Vh) / mean(Vh) of a record"},
    "turbulence_intensity_mc_u": {
        "units": "1", "long_name": "Monte Carlo standard deviation over records of the "
        "apparent turbulence intensity"},
    "turbulence_intensity_mc_low": {
        "units": "1", "long_name": "lower end of the 95 % interval over records of the "
        "apparent turbulence intensity (2.5 % quantile)"},
    "turbulence_intensity_mc_high": {
        "units": "1", "long_name": "upper end of the 95 % interval over records of the "
        "apparent turbulence intensity (97.5 % quantile)"},
    "turbulence_intensity_true_mc_mean": {
        "units": "1", "long_name": "Monte Carlo mean over records of the field's std(u) / "
        "mean(u) at the reference point, sampled once a scan"},
    "turbulence_intensity_spectral_z": {
        "units": "1", "long_name": "spectral expected TI^2 minus the records' mean TI^2, "
        "in standard errors of that mean"},
    "turbulence_intensity_spectral_valid": {
        "units": "1", "long_name": "spectral path validated by the Monte Carlo records "
        "(|turbulence_intensity_spectral_z| within turbulence_intensity_spectral_z_limit)"},
    "turbulence_intensity_spectral_z_limit": {
        "units": "1", "long_name": "largest |z| of the path-to-path check: the 97.5 % "
        "quantile of Student's t with record.count - 1 degrees of freedom (a 5 % false "
        "alarm rate)"},
    "turbulence_intensity_check_resolution": {
        "units": "1", "long_name": "relative difference of the apparent TI the path-to-path "
        "check tells from none at this record count (half its TI^2 interval over the "
        "records' mean TI^2): a check that is to decide a difference needs it smaller"},
    "turbulence_intensity_box_kept": {
        "units": "1", "long_name": "u-variance the records' field keeps of the model's "
        "over a record (the record's high-pass) where the lidar's beams read it: the box's "
        "resolved scales, the scales below its cells (drawn at each beam and gate once a "
        "scan) and the band of the largest eddies the box cannot hold (longer than it "
        "along the wind, wider across it; drawn as one linear trend a record, the same at "
        "every beam and at the reference point): 1 where every band is drawn"},
    "turbulence_intensity_box_resolved": {
        "units": "1", "long_name": "u-variance the turbulence box alone resolves of the "
        "model's over a record (the record's high-pass): the rest, the scales below its "
        "cells and the band of eddies larger than the box, is drawn at the beams and the "
        "reference point"},
    "wind_speed_record_bias": {
        "units": "m s-1", "long_name": "Monte Carlo mean over records of the record's mean "
        "horizontal wind speed minus the field's true mean"},
    "wind_speed_record_u": {
        "units": "m s-1", "long_name": "Monte Carlo standard deviation over records of the "
        "record's mean horizontal wind speed minus the field's true mean"},
    "turbulence_intensity_true": {
        "units": "1", "long_name": "turbulence intensity sigma_u / U of the field at the "
        "reference point over a record (expected, spectral; the record's high-pass)"},
    "turbulence_intensity_spectral": {
        "units": "1", "long_name": "apparent turbulence intensity the lidar reports over a "
        "record: the spectral path's filtered turbulence variance plus the per-scan "
        "error variance, over the true horizontal speed"},
    "turbulence_intensity_spectral_turbulence": {
        "units": "1", "long_name": "apparent turbulence intensity from the filtered "
        "turbulence alone (spectral path), over the true horizontal speed"},
    "turbulence_intensity_u_ratio": {
        "units": "1", "long_name": "u-variance ratio of the lidar's filtered turbulence to "
        "the field's at the reference point over the record (spectral path)"},
    "turbulence_v_ratio": {
        "units": "1", "long_name": "lateral (v) variance ratio of the lidar's filtered "
        "turbulence to the field's at the reference point over the record (spectral "
        "path; v across the mean wind, horizontal)"},
    "turbulence_w_ratio": {
        "units": "1", "long_name": "vertical (w) variance ratio of the lidar's filtered "
        "turbulence to the field's at the reference point over the record (spectral path)"},
    "turbulence_intensity_u_ratio_error": {
        "units": "1", "long_name": "numerical error estimate of turbulence_intensity_u_ratio "
        "(the spectral path's quadrature against one with fewer nodes: an overstatement)"},
    "turbulence_v_ratio_error": {
        "units": "1", "long_name": "numerical error estimate of turbulence_v_ratio (the "
        "spectral path's quadrature against one with fewer nodes: an overstatement)"},
    "turbulence_w_ratio_error": {
        "units": "1", "long_name": "numerical error estimate of turbulence_w_ratio (the "
        "spectral path's quadrature against one with fewer nodes: an overstatement)"},
    "turbulence_intensity_spectral_error": {
        "units": "1", "long_name": "numerical error estimate of "
        "turbulence_intensity_spectral (the spectral path's quadrature)"},
    "turbulence_intensity_true_error": {
        "units": "1", "long_name": "numerical error estimate of turbulence_intensity_true "
        "(the spectral path's quadrature)"},
    "turbulence_intensity_v_true": {
        "units": "1", "long_name": "lateral turbulence intensity sigma_v / U of the field at "
        "the reference point over a record (expected, spectral; the record's high-pass)"},
    "turbulence_intensity_w_true": {
        "units": "1", "long_name": "vertical turbulence intensity sigma_w / U of the field "
        "at the reference point over a record (expected, spectral; the record's high-pass)"},
    "turbulence_intensity_v_spectral": {
        "units": "1", "long_name": "apparent lateral turbulence intensity std(v) / U the "
        "lidar reports over a record from the filtered turbulence alone (spectral path)"},
    "turbulence_intensity_w_spectral": {
        "units": "1", "long_name": "apparent vertical turbulence intensity std(w) / U the "
        "lidar reports over a record from the filtered turbulence alone (spectral path)"},
    "turbulence_spectral_converged": {
        "units": "1", "long_name": "the spectral path reached its tolerance (each ratio's "
        "estimated relative error within uq.constants.SPECTRAL_TOLERANCE)"},
    "turbulence_intensity_v_mc_mean": {
        "units": "1", "long_name": "Monte Carlo mean over records of the apparent lateral "
        "turbulence intensity std(v) / mean(Vh) of a record (v: the reconstructed wind "
        "across the record's mean direction; the scans' errors included)"},
    "turbulence_intensity_w_mc_mean": {
        "units": "1", "long_name": "Monte Carlo mean over records of the apparent vertical "
        "turbulence intensity std(w) / mean(Vh) of a record (the scans' errors included)"},
    "turbulence_intensity_v_true_mc_mean": {
        "units": "1", "long_name": "Monte Carlo mean over records of the field's std(v) / "
        "mean(u) at the reference point, sampled once a scan"},
    "turbulence_intensity_w_true_mc_mean": {
        "units": "1", "long_name": "Monte Carlo mean over records of the field's std(w) / "
        "mean(u) at the reference point, sampled once a scan"},
}


#: Each turbulence intensity carries its one name (the field's point TI, the field's TI
#: over a record, the records' field TI, the lidar's apparent TI: spectral or records)
#: in its long_name and comment, the report's words.
RECORD_ATTRIBUTES = {name: turbulence_intensity_attributes(name, attributes)
                     for name, attributes in RECORD_ATTRIBUTES.items()}


def turbulence_model(turbulence, speed):
    """The spectral model of a validated ``turbulence`` section at `speed` [m s-1]: a
    :class:`~uq.physics.spectraltensor.MannTensor` whose point sigma_u / U is the
    intensity, or the IEC :class:`~uq.physics.spectraltensor.KaimalSpectra`."""
    if turbulence["model"] == "mann":
        return mann_tensor_for_intensity(turbulence["intensity"], speed,
                                         turbulence["length_scale"], turbulence["anisotropy"])
    return KaimalSpectra.iec(turbulence["intensity"], speed, turbulence["length_scale"])


def spectral_variances(settings, intensity=None):
    """The :class:`~uq.physics.lidarspectral.SpectralVariances` of validated `settings`
    (their lidar's u, v, w variance ratios: ``.ratios()``; their numerical errors:
    ``.ratio_errors()``), and the scan geometry: the probe's own transfer function
    (:func:`~uq.physics.lidarspectral.probe_transfer_for`) at each gate's slant
    distance; the field at `intensity` [1] (default the scene's ``turbulence.
    intensity``: the variances are proportional to its square)."""
    geometry = scan_geometry(settings)
    lidar = settings["lidar"]
    transfer = probe_transfer_for(probesection.make_probe(lidar.get("probe")),
                                  slant_ranges(lidar))
    turbulence = dict(settings["turbulence"])
    if intensity is not None:
        turbulence["intensity"] = intensity
    model = turbulence_model(turbulence, settings["wind"]["speed"])
    return lidar_variances(geometry, model, transfer), geometry


def spectral_ratios(settings):
    """The lidar's (u, v, w) variance ratios to the field's at the reference point over a
    record of validated `settings` [1], shape (n_gates, 3), and their numerical errors
    [1] (the same shape): the spectral path, computed once per lidar and record
    (:func:`unit_spectral_variances`; the ratios do not depend on the intensity)."""
    unit = unit_spectral_variances(settings)
    return unit.ratios(), unit.ratio_errors()


def chunk_fields(scenario, plan, chunk):
    """The swept scene values (:data:`~uq.pipeline.sweep.VECTOR_KEYS`) of a chunk's
    scenes in scenario units (degrees): dotted key -> array (n_chunk,), links included."""
    if not plan.vector_keys:
        return {}
    index = np.unravel_index(np.arange(chunk.start, chunk.stop), plan.vector_shape)
    fields = {key: np.asarray(values, dtype=float)[position] for key, values, position
              in zip(plan.vector_keys, plan.vector_values, index)}
    fields.update({f: fields[lead] for f, lead in scenario.links if lead in fields})
    return fields


def scene_settings(scenario, fields):
    """Settings of each scene of a chunk: `fields` maps a swept dotted key to the values
    of the chunk's scenes (scenario units)."""
    count = len(next(iter(fields.values()))) if fields else 1
    out = []
    for i in range(count):
        settings = copy.deepcopy(scenario.settings)
        for dotted, values in fields.items():
            section, key = dotted.split(".")
            settings[section][key] = float(values[i])
        out.append(settings)
    return out


def record_variables(scenario, fields, dataset, seed=0, compiled=True, spectra_of=None,
                     prepared=None):
    """The record-mode variables of a chunk's scenes (dimension ``scene``, and ``range``):
    `fields` as :func:`scene_settings`; `dataset` the chunk's per-scan results; the
    Monte Carlo records (unless ``sampling.method`` is ``none``) from `seed`; with
    `spectra_of` (the validated settings of the run's file, the same for every chunk)
    also the records' spectra on its frequencies (:data:`SPECTRA_ATTRIBUTES`);
    `prepared`: :func:`prepare_records` of the same arguments (else done here)."""
    scenes = scene_settings(scenario, fields)
    n_gates = len(scenario.settings["lidar"]["ranges"])
    paths = prepared if prepared is not None else scene_spectral_paths(scenes, n_gates)
    speeds = np.array([s["wind"]["speed"] for s in scenes])
    truth = dataset["wind_speed_true"].values.reshape(len(scenes), n_gates)
    u_scan = _scan_uncertainty(dataset).reshape(len(scenes), n_gates)
    # the records' sample variance (N - 1): N / (N - 1) times the spectral path's (1 / N)
    sample = np.array([_sample_factor(scans_per_record(scene)) for scene in scenes])
    lidar, true = paths["lidar"] * sample[:, None, None], paths["true"] * sample[:, None]
    lidar_error = paths["lidar_error"] * sample[:, None, None]
    true_error = paths["true_error"] * sample[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratios = lidar / true[:, None, :]
        ratio_errors = (np.abs(lidar_error) + np.abs(ratios) * true_error[:, None, :]) \
            / true[:, None, :]
        spectral = np.sqrt(lidar[..., 0] + u_scan ** 2) / truth
        out = {
            "turbulence_intensity_true": (("scene",), np.sqrt(true[:, 0]) / speeds),
            "turbulence_intensity_true_error": (("scene",), true_error[:, 0] / (
                2 * np.sqrt(true[:, 0]) * speeds)),
            "turbulence_intensity_spectral": (("scene", "range"), spectral),
            "turbulence_intensity_spectral_error": (("scene", "range"), lidar_error[..., 0] / (
                2 * spectral * truth ** 2)),
            "turbulence_intensity_spectral_turbulence": (("scene", "range"),
                                                         np.sqrt(lidar[..., 0]) / truth),
            "turbulence_intensity_u_ratio": (("scene", "range"), ratios[..., 0]),
            "turbulence_v_ratio": (("scene", "range"), ratios[..., 1]),
            "turbulence_w_ratio": (("scene", "range"), ratios[..., 2]),
            "turbulence_intensity_u_ratio_error": (("scene", "range"), ratio_errors[..., 0]),
            "turbulence_v_ratio_error": (("scene", "range"), ratio_errors[..., 1]),
            "turbulence_w_ratio_error": (("scene", "range"), ratio_errors[..., 2]),
            "turbulence_intensity_v_true": (("scene",), np.sqrt(true[:, 1]) / speeds),
            "turbulence_intensity_w_true": (("scene",), np.sqrt(true[:, 2]) / speeds),
            "turbulence_intensity_v_spectral": (("scene", "range"),
                                                np.sqrt(lidar[..., 1]) / truth),
            "turbulence_intensity_w_spectral": (("scene", "range"),
                                                np.sqrt(lidar[..., 2]) / truth),
            "turbulence_spectral_converged": (("scene",), paths["converged"]),
        }
    if scenario.sampling["method"] != "none":
        out.update(monte_carlo_variables(
            scenes, truth, seed, compiled, out["turbulence_intensity_spectral"][1],
            spectrum_axis(spectra_of) if spectra_of else None,
            bool(spectra_of and spectra_of.get("motion"))))
    return out


def _sample_factor(scans):
    """``N / (N - 1)`` [1]: the expected sample variance (a lidar's standard deviation
    over a record's N scans, N - 1 in the denominator, as the records reduce it) over the
    variance about the record's mean that the spectral path gives (1 / N); NaN for one
    scan."""
    return scans / (scans - 1) if scans > 1 else np.nan


def prepare_records(scenario, fields, seed, spectra_of=None):
    """What :func:`record_variables` (same arguments) computes before the chunk's
    per-scan Monte Carlo: the first scene's record boxes (:func:`draw_first_records`)
    and every scene's spectral path (:func:`scene_spectral_paths`), returned, so that
    neither adds its memory to what numba keeps of the kernels that the per-scan run
    compiles (~100-170 MB); the same numbers whenever computed."""
    draw_first_records(scenario, fields, seed, spectra_of)
    return scene_spectral_paths(scene_settings(scenario, fields),
                                len(scenario.settings["lidar"]["ranges"]))


def scene_spectral_paths(scenes, n_gates):
    """The spectral path of each scene's settings (:func:`unit_spectral_variances`
    times the square of its intensity): a dict of the lidar's filtered (u, v, w)
    variances per gate ``lidar`` (n_scenes, n_gates, 3) and their errors
    ``lidar_error``, the field's at the reference point ``true`` (n_scenes, 3) and
    ``true_error`` [m2 s-2], and ``converged`` (n_scenes,); NaN without a mean wind (no
    frozen field).

    Each lidar is computed once at unit intensity and scaled by the square of the
    scene's, the same bits whichever scenes a process computes first (a run resumed
    after any chunk gives the uninterrupted run's numbers)."""
    out = {"lidar": np.full((len(scenes), n_gates, 3), np.nan),
           "lidar_error": np.full((len(scenes), n_gates, 3), np.nan),
           "true": np.full((len(scenes), 3), np.nan),
           "true_error": np.full((len(scenes), 3), np.nan),
           "converged": np.ones(len(scenes), dtype=bool)}
    for i, settings in enumerate(scenes):
        if settings["wind"]["speed"] > 0:
            unit = unit_spectral_variances(settings)
            square = settings["turbulence"]["intensity"] ** 2
            out["lidar"][i], out["lidar_error"][i] = unit.lidar * square, \
                unit.lidar_error * square
            out["true"][i], out["true_error"][i] = unit.true * square, unit.true_error * square
            out["converged"][i] = unit.converged
    return out


#: Spectral paths kept for the run's other chunks, by :func:`spectral_key` (the oldest
#: dropped beyond :data:`~uq.constants.SPECTRAL_PATHS_KEPT`).
_SPECTRAL_PATHS = collections.OrderedDict()
_SPECTRAL_PATHS_LOCK = threading.Lock()


def unit_spectral_variances(settings):
    """The :class:`~uq.physics.lidarspectral.SpectralVariances` of `settings` at unit
    ``turbulence.intensity``, computed once per :func:`spectral_key` in a process (the
    variances of any intensity are these times its square, exactly: Mann's alpha
    eps^(2/3) and the Kaimal spectra are proportional to (I U)^2, the lidar's variances
    linear in them)."""
    key = spectral_key(settings)
    with _SPECTRAL_PATHS_LOCK:
        if key in _SPECTRAL_PATHS:
            _SPECTRAL_PATHS.move_to_end(key)
            return _SPECTRAL_PATHS[key]
    found = spectral_variances(settings, intensity=1.0)[0]
    if not found.converged:
        log.warning("%s: the spectral path did not reach its tolerance (%g) in %d "
                    "refinements; its stated errors say by how much",
                    settings.get("name", "scenario"), SPECTRAL_TOLERANCE, SPECTRAL_REFINEMENTS)
    with _SPECTRAL_PATHS_LOCK:
        _SPECTRAL_PATHS[key] = found
        while len(_SPECTRAL_PATHS) > SPECTRAL_PATHS_KEPT:
            _SPECTRAL_PATHS.popitem(last=False)
    return found


#: The sections :func:`spectral_variances` reads (its scan geometry, probe and spectra).
SPECTRAL_SECTIONS = ("lidar", "ship", "wind", "turbulence", "record")


def spectral_key(settings):
    """What the spectral path of validated `settings` depends on besides the intensity,
    as a hashable key (:data:`SPECTRAL_SECTIONS`): scenes that differ only elsewhere
    (``correction``, the INS, the motion) or in ``turbulence.intensity`` share one
    computation, scaled by the square of the intensities' ratio (the Mann tensor's
    alpha eps^(2/3) and the Kaimal spectra are proportional to (I U)^2, and the lidar's
    variances linear in them; ``turbulence.intensity`` is validated positive:
    :func:`unit_spectral_variances`)."""
    sections = {name: settings.get(name) for name in SPECTRAL_SECTIONS}
    sections["turbulence"] = {**sections["turbulence"], "intensity": None}
    return json.dumps(sections, sort_keys=True, default=repr)


def _scan_uncertainty(dataset):
    """u of one scan's Vh from the declared errors and the motion [m s-1]: Monte Carlo
    where it ran, else the GUM's (``sampling.method: none``)."""
    name = "wind_speed_mc_u" if "wind_speed_mc_u" in dataset else "wind_speed_gum_u"
    return dataset[name].values


# --- Monte Carlo records --------------------------------------------------------------------

#: Two-sided probability of the path-to-path check [1]: the spectral path is taken as
#: validated where |z| is within the (1 - VALID_LEVEL / 2) quantile of Student's t with
#: count - 1 degrees of freedom (the records' mean TI^2 against its own standard error:
#: with the normal's 1.96 ~ 2 instead, a check of 5 records fails 12-13 % of the
#: time where the paths agree, measured on chi-square-like records: tests/pipeline/
#: test_records.py).
VALID_LEVEL = 0.05


def valid_z(count):
    """The largest |z| of the path-to-path check with `count` records [1]."""
    from scipy import stats
    return float(stats.t.ppf(1 - VALID_LEVEL / 2, count - 1))
#: Spawn key of the records' random streams (apart from the per-scan engine's blocks).
RECORD_STREAM = 24
#: Inputs of a time-resolved scan that record mode sets itself: the motion's phases
#: advance coherently from scan to scan within a record.
PHASE_INPUTS = ("motion_phases",)


def record_generator(seed, record):
    """The independent generator of record `record` of a run seeded with `seed`: the same
    records for every scene (common random numbers) and whatever the chunking."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(RECORD_STREAM,
                                                                         record)))


def turbulence_box(settings, geometry, rng, motion_margin=0.0):
    """A box of the scenario's turbulence holding every probe point of a record, each
    moved by up to `motion_margin` [m] by the platform's motion
    (:func:`uq.physics.turbulencebox.box_for`), and the variance of u the records' field
    keeps of the model's at the record's scales [1] (:func:`reference_complement`).
    The box is :func:`unit_box` times :func:`field_scale`."""
    box, kept = unit_box(settings, geometry, rng, motion_margin, window=False)
    box.velocity[...] *= field_scale(settings)
    return box, kept


def field_scale(settings):
    """What the unit field of :func:`unit_box` is multiplied by: the square root of Mann's
    alpha eps^(2/3) [m2/3 s-1] (the field is linear in it, Mann 1998 Sec. 3), or the
    Kaimal field's sigma_u = intensity x speed [m s-1]."""
    turbulence, speed = settings["turbulence"], settings["wind"]["speed"]
    if turbulence["model"] == "mann":          # I U sqrt(unit alpha eps^(2/3)): no underflow
        return turbulence["intensity"] * speed * math.sqrt(
            turbulence_model({**turbulence, "intensity": 1.0}, 1.0).alpha_epsilon)
    return turbulence["intensity"] * speed


def unit_box(settings, geometry, rng, motion_margin=0.0, window=True):
    """:func:`turbulence_box` of unit :func:`field_scale` (the same random numbers; the
    box of any intensity is this one times its scale), and the variance of u it keeps of
    the model's point variance [1]. With `window` a Mann box holds only the (y, z) lines
    that the probe points (and the reference point) read
    (:func:`uq.physics.turbulencebox.mann_box_window`), its half spectra in parts of at
    most :data:`~uq.constants.RECORD_SPECTRA_BYTES`: the sum of :func:`unit_box_parts`."""
    from uq.physics import turbulencebox
    turbulence = settings["turbulence"]
    if turbulence["model"] == "mann" and not window:
        grid = record_grid(settings, geometry, motion_margin)
        kept = reference_complement(settings, geometry, grid).kept
        return turbulencebox.mann_box(grid, 1.0, turbulence["length_scale"],
                                      turbulence["anisotropy"], rng,
                                      slab_cells=RECORD_BOX_SLAB_CELLS), kept
    parts, kept = unit_box_parts(settings, geometry, rng, motion_margin)
    return turbulencebox.box_sum(parts), kept


def unit_box_parts(settings, geometry, rng, motion_margin=0.0):
    """The windowed unit box of :func:`unit_box` as fields whose sum it is, and the
    variance of u the records' field keeps [1] (:func:`reference_complement`): a Mann
    box's parts of its half spectra (:func:`uq.physics.turbulencebox.
    mann_box_window_parts`, each valid until the next is taken; `rng` is left where the
    box's draw leaves it once the last is taken), a Kaimal box whole (one part)."""
    from uq.physics import turbulencebox
    turbulence, speed = settings["turbulence"], settings["wind"]["speed"]
    grid = record_grid(settings, geometry, motion_margin)
    kept = reference_complement(settings, geometry, grid).kept   # (first: not beside the box)
    if turbulence["model"] == "mann":
        points = record_points(geometry)
        nx, ny, nz = grid.shape
        parts = math.ceil(3 * nx * ny * (nz // 2 + 1) * 16 / RECORD_SPECTRA_BYTES)
        return turbulencebox.mann_box_window_parts(
            grid, 1.0, turbulence["length_scale"], turbulence["anisotropy"], rng,
            turbulencebox.box_window(grid, points, motion_margin), parts,
            slab_cells=RECORD_BOX_SLAB_CELLS, workers=RECORD_FFT_WORKERS), kept
    scale = turbulence["length_scale"] / LENGTH_FACTORS_KAIMAL
    nodes = turbulencebox.kaimal_nodes(grid, record_points(geometry), motion_margin)
    return [turbulencebox.kaimal_box(grid, 1.0, speed, scale, rng, nodes=nodes)], kept


class Complement(typing.NamedTuple):
    """What the records draw beside the box (:func:`reference_complement`).

    Attributes
    ----------
    factor : ndarray, shape (3, 3)
        Lower Cholesky factor of the covariance drawn at the reference point once a scan,
        white [m s-1 per unit field scale].
    kept : float
        u-variance share of the field's at the record's scales the beams read [1]
        (``turbulence_intensity_box_kept``).
    resolved : float
        The box's alone [1] (``turbulence_intensity_box_resolved``).
    band : ndarray, shape (3, 3), or None
        Lower Cholesky factor of the record covariance of the band of eddies larger than
        the box [m s-1 per unit field scale], drawn as one trend a record
        (:func:`band_trend`); None where none is drawn (a Kaimal box).
    band_share : float
        The band's share of the field's u-variance over a record [1] (0 where none is
        drawn).
    """

    factor: np.ndarray
    kept: float
    resolved: float
    band: object = None
    band_share: float = 0.0


def reference_complement(settings, geometry, grid):
    """What the records' field adds to the box's (:class:`Complement`), per unit
    field_scale^2: the field's (u, v, w) record covariance [m2 s-2] minus the box's on its
    line of nodes (:func:`uq.physics.turbulencebox.box_variance` with the record's
    high-pass; Kaimal: the box's spectra at its discrete k1), in two parts.

    - The scales below the box's cells (5 % of u's variance, 10 % of v's, 17 % of w's at
      L / 8 for IEC Mann; :func:`uq.physics.unresolved.unresolved_point_covariance`).
      They decorrelate within a few cells (~1/k at k above the Nyquist wavenumber
      pi / dx), far less than a scan's advection apart, so the records draw them at the
      reference point as independent values once a scan (their record variance about its
      mean is (1 - 1/N) of theirs) and at each beam and gate (:func:`beam_complement`).
    - The band of eddies larger than the box (longer than it along the wind, wider
      across it: 0.3-1.9 % of u's variance over ten minutes, the most at low speeds):
      scales far above the scan's size and a record's slowest, so every beam and the
      reference point read them together as one slow change over the record, drawn as
      a linear trend of that record covariance (:func:`band_trend`).

    Negative eigenvalues of either (the box holding more than the field: rounding) are
    set to zero. A Kaimal box (made on its nodes across the wind) draws its whole
    complement at the reference point, white, and nothing at the beams
    (kept = resolved)."""
    turbulence, speed = settings["turbulence"], settings["wind"]["speed"]
    if turbulence["model"] == "mann":
        return _mann_complement(grid, turbulence["length_scale"], turbulence["anisotropy"],
                                speed, geometry.scan_period, geometry.record_duration)
    return _kaimal_complement(grid, turbulence["length_scale"], speed, geometry.scan_period,
                              geometry.record_duration)


def _nonnegative(covariance):
    """A symmetric matrix with its negative eigenvalues set to zero."""
    values, vectors = np.linalg.eigh(covariance)
    return (vectors * np.maximum(values, 0.0)) @ vectors.T


def _cholesky(covariance):
    """A factor L of a nonnegative covariance (3, 3), ``L L^T`` = it: the lower Cholesky
    factor (a vanishing ridge for one that is singular), or where rounding leaves it
    indefinite (a band of a short record, near zero in some direction) its eigenvectors
    times the roots of its eigenvalues, negative ones set to zero."""
    try:
        return np.linalg.cholesky(covariance + 1e-300 * np.eye(3))
    except np.linalg.LinAlgError:
        values, vectors = np.linalg.eigh(covariance)
        return vectors * np.sqrt(np.maximum(values, 0.0))


def _complement_factor(field, box, scans, unresolved=None):
    """:class:`Complement` of a field's and a box's record covariances (3, 3); with
    `unresolved` (the covariance of the scales below the box's cells) the band of eddies
    larger than the box is ``field - box - unresolved``, drawn as a trend."""
    missing = _nonnegative(field - box)
    white_share = max(1.0 - 1.0 / scans, 1e-12)
    resolved = float(box[0, 0] / field[0, 0])
    if unresolved is None:
        return Complement(_cholesky(missing / white_share), resolved, resolved)
    band = _nonnegative(missing - unresolved)
    white = _nonnegative(missing - band)
    return Complement(_cholesky(white / white_share),
                      float((box[0, 0] + unresolved[0, 0] + band[0, 0]) / field[0, 0]),
                      resolved, _cholesky(band), float(band[0, 0] / field[0, 0]))


def band_trend(n_scans):
    """The shape of the band of eddies larger than the box over a record: a linear trend
    in the scan index, of zero mean and unit variance over the record's N scans
    (``(i - (N - 1) / 2) sqrt(12 / (N^2 - 1))``; zeros for one scan), shape (N,). A
    band's draw ``a = L z`` (L its factor, z three standard normals) times it has the
    band's record covariance exactly in expectation: ``E[a a^T] = L L^T``."""
    if n_scans < 2:
        return np.zeros(max(int(n_scans), 0))
    index = np.arange(n_scans, dtype=float) - (n_scans - 1) / 2.0
    return index * math.sqrt(12.0 / (n_scans ** 2 - 1.0))


@functools.lru_cache(maxsize=8)
def _mann_complement(grid, length_scale, anisotropy, speed, scan_period, duration):
    """:func:`reference_complement` of a Mann box of unit alpha eps^(2/3) (a function of
    the grid, the model and the record alone, kept per run)."""
    from uq.physics import turbulencebox
    from uq.physics.lidarspectral import _point_matrix, record_filter
    from uq.physics.scangeometry import ScanGeometry
    from uq.physics.spectraltensor import MannTensor
    from uq.physics.spectralquadrature import record_scans
    from uq.physics.unresolved import unresolved_point_covariance
    point = ScanGeometry(np.array([[1.0, 0, 0]]), np.zeros((1, 1, 3)), np.zeros(1), 0.0,
                         scan_period, np.zeros(1), np.ones((1, 1)), np.ones((1, 3, 1)),
                         speed, duration)
    field = _point_matrix(point, MannTensor(length_scale, anisotropy), dwell=False)
    u, v, w, uw = turbulencebox.box_variance(
        grid, 1.0, length_scale, anisotropy, slab_cells=RECORD_BOX_SLAB_CELLS,
        spectral_filter=lambda k1: record_filter(k1 * speed / (2 * np.pi), scan_period,
                                                 duration))
    box = np.array([[u, 0.0, uw], [0.0, v, 0.0], [uw, 0.0, w]])
    # the scales below the box's cells, which the beams get too (beam_complement); the
    # record's high-pass is 1 there (their wavenumbers are far above 1 / (U T)); the rest
    # of field - box is the band of eddies larger than the box
    unresolved = unresolved_point_covariance(grid.spacing[0], 1.0, length_scale, anisotropy)
    return _complement_factor(field, box, record_scans(scan_period, duration), unresolved)


@functools.lru_cache(maxsize=8)
def _kaimal_complement(grid, length_u, speed, scan_period, duration):
    """:func:`reference_complement` of a Kaimal box of unit sigma_u: its point spectra
    (Veers: the IEC spectra, two-sided in k1 ``S(f) U / (4 pi)``) at its discrete k1
    against the spectra's record integral (the spectral path's)."""
    from uq.physics.lidarspectral import _kaimal_true, record_filter
    from uq.physics.scangeometry import ScanGeometry
    from uq.physics.spectralquadrature import PanelRule, geometric_edges, record_scans
    spectra = KaimalSpectra.iec(1.0 / speed, speed, length_u)
    point = ScanGeometry(np.array([[1.0, 0, 0]]), np.zeros((1, 1, 3)), np.zeros(1), 0.0,
                         scan_period, np.zeros(1), np.ones((1, 1)), np.ones((1, 3, 1)),
                         speed, duration)
    scale = speed / spectra.lengths[0]
    field = np.diag(_kaimal_true(point, spectra, PanelRule(geometric_edges(
        1e-5 * scale, 1e5 * scale, 4), 8)))
    k1 = np.abs(2 * np.pi * np.fft.fftfreq(grid.shape[0], grid.spacing[0]))[1:]
    f = speed * k1 / (2 * np.pi)
    dk = 2 * np.pi / grid.lengths[0]
    highpass = record_filter(f, scan_period, duration)
    box = np.diag([np.sum(spectra.spectrum(c, f) * speed / (4 * np.pi) * highpass) * dk
                   for c in range(3)])
    return _complement_factor(field, box, record_scans(scan_period, duration))


_BEAM_COMPLEMENTS = {}
_BEAM_COMPLEMENTS_LOCK = threading.Lock()


def beam_complement(settings, geometry, grid):
    """The standard deviation [m s-1 per unit field scale] of the scales a Mann box does
    not resolve, as each beam and gate of `geometry` reads them (the probe's own
    weighting, the dwell), less what the box's interpolation passes of them: shape
    (n_beams, n_gates), :func:`uq.physics.unresolved.unresolved_radial_variances`. The
    records draw them independent between beams, gates and scans (their scales are
    below a few cells; the module docstring there). None for a Kaimal box (its field is
    made on the box's nodes across the wind; what it lacks along the wind is stated,
    not drawn). Kept per grid, model, probe and geometry (~2 s CPU each)."""
    from uq.physics import turbulencesampling
    from uq.physics.unresolved import unresolved_radial_variances
    turbulence = settings["turbulence"]
    if turbulence["model"] != "mann":
        return None
    lidar = settings["lidar"]
    key = (grid, turbulence["length_scale"], turbulence["anisotropy"],
           repr(lidar.get("probe")), repr(lidar["ranges"]), lidar["half_cone"],
           _arrays_digest(getattr(geometry, f.name) for f in dataclasses.fields(geometry)))
    with _BEAM_COMPLEMENTS_LOCK:
        found = _BEAM_COMPLEMENTS.get(key)
    if found is None:
        transfer = probe_transfer_for(probesection.make_probe(lidar.get("probe")),
                                      slant_ranges(lidar))
        spacing = grid.spacing[0]
        found = np.sqrt(unresolved_radial_variances(
            spacing, geometry, turbulencesampling.dwell_offsets(geometry, min(grid.spacing)),
            transfer, 1.0, turbulence["length_scale"], turbulence["anisotropy"]))
        with _BEAM_COMPLEMENTS_LOCK:
            if len(_BEAM_COMPLEMENTS) >= 16:
                _BEAM_COMPLEMENTS.pop(next(iter(_BEAM_COMPLEMENTS)))
            _BEAM_COMPLEMENTS[key] = found
    return found


def record_grid(settings, geometry, motion_margin=0.0):
    """The grid of a record's box (:func:`uq.physics.turbulencebox.box_for`: Mann's L,
    or the Kaimal model's Lambda_1 = L_u / 8.1), the probe points moved by up to
    `motion_margin` [m]. A record whose motion reached further than its validation
    allowed for (:func:`uq.pipeline.turbulencesection.motion_reach`) and whose box is
    above the limit is refused in one line (:class:`uq.errors.ScenarioError`), before
    anything is allocated."""
    from uq.errors import ScenarioError
    from uq.physics import turbulencebox
    turbulence = settings["turbulence"]
    mann = turbulence["model"] == "mann"
    scale = turbulence["length_scale"] / (1.0 if mann else LENGTH_FACTORS_KAIMAL)
    try:
        return turbulencebox.box_for(geometry, scale, turbulence["model"],
                                     motion_margin=motion_margin,
                                     max_cells=RECORD_MAX_BOX_CELLS)
    except ValueError as error:
        raise ScenarioError(settings.get("name", "scenario"), "record.duration",
                            f"a record's motion moved the probes {motion_margin:.3g} m, "
                            f"further than validation allowed for, and {error}") from None


@dataclasses.dataclass(frozen=True)
class UnitRecord:
    """The turbulence of one record for a field of unit scale (:func:`unit_record`).

    Attributes
    ----------
    radial : ndarray, shape (n_scans, n_beams, n_gates)
        The turbulence's radial velocity of each beam and gate [m s-1 per unit scale],
        at the beams' true (moving) positions.
    reference : ndarray, shape (n_scans, 3)
        The field at the reference point once a scan [m s-1 per unit scale].
    at_rest : ndarray or None
        ``radial`` at the nominal positions (the lidar at rest), where asked for.
    kept : float
        u-variance fraction the records' beams keep [1] (the box and the scales below
        its cells, :func:`beam_complement`).
    state : dict
        The record generator's state after the box's draw.
    resolved : float
        u-variance fraction the box alone resolves [1].
    """

    radial: np.ndarray
    reference: np.ndarray
    at_rest: object
    kept: float
    state: dict
    resolved: float = float("nan")

    @property
    def nbytes(self):
        return sum(a.nbytes for a in (self.radial, self.reference, self.at_rest)
                   if a is not None)


_UNIT_RECORDS = collections.OrderedDict()
_UNIT_RECORDS_LOCK = threading.Lock()


def forget_kept():
    """Drop the records and spectral paths this process keeps for reuse
    (:func:`unit_record`, :data:`_SPECTRAL_PATHS`): the next run makes them as a new
    ``uq run`` process does (the benchmark times that)."""
    with _UNIT_RECORDS_LOCK:
        _UNIT_RECORDS.clear()
    with _SPECTRAL_PATHS_LOCK:
        _SPECTRAL_PATHS.clear()
    with _BEAM_COMPLEMENTS_LOCK:
        _BEAM_COMPLEMENTS.clear()


def unit_record(settings, geometry, n_scans, rng, moving, margin, at_rest=False):
    """The turbulence of one record, for a field of unit :func:`field_scale`, drawn from
    `rng` as :func:`unit_box` draws it (`rng` is left where the box's draw leaves it).

    The field is linear in its scale, so every scene that draws the same box (the same
    generator state, grid, length scale, anisotropy) and samples it at the same points
    (geometry, motion) shares it: a sweep of ``turbulence.intensity`` or of the
    correction generates each record's box once. Such records are kept for reuse
    (:data:`~uq.constants.UNIT_RECORD_CACHE_BYTES`, the least recently used dropped
    first); a record is the same whether generated or reused, so results do not depend
    on which scenes a process ran before, nor on the chunking.

    Parameters
    ----------
    moving, margin
        :func:`moving_probes`' keyword arguments and margin [m].
    at_rest : bool
        Also sample the box at the nominal positions (:attr:`UnitRecord.at_rest`).
    """
    key = _unit_key(settings, geometry, n_scans, rng, moving, margin, at_rest)
    with _UNIT_RECORDS_LOCK:
        found = _UNIT_RECORDS.get(key)
        if found is not None:
            _UNIT_RECORDS.move_to_end(key)
    if found is None:
        found = _draw_unit_record(settings, geometry, n_scans, rng, moving, margin, at_rest)
        _keep(key, found)
    rng.bit_generator.state = found.state
    return found


def _draw_unit_record(settings, geometry, n_scans, rng, moving, margin, at_rest):
    """:func:`unit_record` generated: the box, sampled, then freed, part by part
    (:func:`unit_box_parts`: the sampling is linear in the field, so the record is the
    sum of its parts' samples, in the memory of one part)."""
    from uq.physics import turbulencesampling
    parts, _ = unit_box_parts(settings, geometry, rng, margin)
    times = turbulencesampling.scan_times(geometry, n_scans)
    found = None
    for box in parts:
        samples = (
            np.asarray(turbulencesampling.record_radial_velocities(box, geometry, n_scans,
                                                                   **moving)),
            np.asarray(turbulencesampling.reference_line_series(box, geometry.speed,
                                                                times)),
            np.asarray(turbulencesampling.record_radial_velocities(box, geometry, n_scans))
            if at_rest else None)
        found = samples if found is None else tuple(
            None if a is None else a + b for a, b in zip(found, samples))
        del box
    radial, reference, rest = found
    # the scales below the box's cells at the reference point, once a scan, drawn after
    # the box (reference_complement), then at each beam and gate (beam_complement)
    grid = record_grid(settings, geometry, margin)
    complement = reference_complement(settings, geometry, grid)
    reference = reference + rng.standard_normal((n_scans, 3)) @ complement.factor.T
    deviation = beam_complement(settings, geometry, grid)
    if deviation is not None:
        unresolved = rng.standard_normal(radial.shape) * deviation
        radial = radial + unresolved
        # the lidar at rest reads the same small scales (the same field, its probes
        # displaced by the motion alone)
        rest = None if rest is None else rest + unresolved
    if complement.band is not None:
        # the band of eddies larger than the box: one trend a record, the same (u, v, w)
        # at the reference point and at every beam and gate, each reading it along its
        # nominal direction (a tilt of a few degrees changes that by under 0.5 % of a
        # band of 1-2 % of the variance)
        trend = np.outer(band_trend(n_scans), complement.band @ rng.standard_normal(3))
        reference = reference + trend
        along = (trend @ np.asarray(geometry.directions, dtype=float).T)[:, :, None]
        radial = radial + along
        rest = None if rest is None else rest + along
    return UnitRecord(radial, reference, rest, complement.kept, rng.bit_generator.state,
                      complement.resolved)


def _unit_key(settings, geometry, n_scans, rng, moving, margin, at_rest):
    """What a unit record depends on, as a hashable key."""
    turbulence = settings["turbulence"]
    digest = _arrays_digest((*(getattr(geometry, f.name) for f in dataclasses.fields(geometry)),
                             *(moving[name] for name in sorted(moving))))
    return (repr(rng.bit_generator.state), turbulence["model"], turbulence["length_scale"],
            turbulence["anisotropy"], n_scans, float(margin), bool(at_rest), digest)


def _arrays_digest(values):
    """SHA-256 (hex) of numeric values, each as a float array: its shape and bytes."""
    digest = hashlib.sha256()
    for value in values:
        array = np.ascontiguousarray(value, dtype=float)
        digest.update(repr(array.shape).encode())
        digest.update(array.tobytes())
    return digest.hexdigest()


def draw_first_records(scenario, fields, seed, spectra_of=None):
    """Draw the unit records (:func:`unit_record`) of the chunk's first scene with wind
    now, as :func:`record_variables` (same arguments) will draw them, into the
    unit-record cache where its records' loop finds them: called before the chunk's
    per-scan Monte Carlo, so that the boxes are made before that compiles its kernels
    (numba keeps ~170 MB of what it compiled: a box made after it peaks that much
    higher). Results do not depend on it (a record is the same whenever it is drawn).
    Stops once the records drawn hold half of :data:`~uq.constants.
    UNIT_RECORD_CACHE_BYTES` (none is dropped before use); draws nothing where the
    run has no records (``sampling.method`` none, no scene with wind)."""
    if scenario.sampling["method"] == "none":
        return
    scenes = [s for s in scene_settings(scenario, fields) if s["wind"]["speed"] > 0]
    if not scenes:
        return
    settings = scenes[0]
    geometry, n_scans = scan_geometry(settings), scans_per_record(settings)
    axis = spectrum_axis(spectra_of) if spectra_of else None
    spectra = axis is not None and RecordSpectra(axis, 1, 1).fits(geometry.scan_period,
                                                                  n_scans)
    held = 0
    for record in range(settings["record"]["count"]):
        if held >= UNIT_RECORD_CACHE_BYTES // 2:
            return
        rng = record_generator(seed, record)
        scene, phases, moving, margin = record_motion(settings, geometry, n_scans, rng)
        held += unit_record(settings, geometry, n_scans, rng, moving, margin,
                            at_rest=spectra and phases is not None).nbytes


def _keep(key, record):
    """Keep a unit record, dropping the least recently used beyond the byte limit."""
    with _UNIT_RECORDS_LOCK:
        _UNIT_RECORDS[key] = record
        total = sum(r.nbytes for r in _UNIT_RECORDS.values())
        while total > UNIT_RECORD_CACHE_BYTES and len(_UNIT_RECORDS) > 1:
            total -= _UNIT_RECORDS.popitem(last=False)[1].nbytes


def coherent_phases(scene, n_scans, scan_period, rng):
    """The scene with every motion component's phase an input, and the unit phases
    (n_scans, K, 2) that advance each component by ``w T_s`` from scan to scan: a
    record's scans are consecutive in time. Random phases are drawn once per record
    (uniform), fixed ones start at their value; None where the scan has no motion."""
    import dataclasses
    resolved = scene.time_resolved
    if resolved is None or not resolved.motion.components:
        return scene, None
    components = resolved.motion.components
    start = np.array([rng.uniform(0, 2 * np.pi) if c.phase is None else c.phase
                      for c in components])
    omega = np.array([c.angular_frequency for c in components])
    phase = start + omega * scan_period * np.arange(n_scans)[:, None]     # (S, K)
    free = tuple(dataclasses.replace(c, phase=None) for c in components)
    motion = dataclasses.replace(resolved.motion, components=free)
    scene = dataclasses.replace(scene, time_resolved=dataclasses.replace(resolved,
                                                                         motion=motion))
    return scene, np.stack([np.cos(phase), np.sin(phase)], axis=-1)


def scan_errors(settings, scene, n_scans, rng):
    """The declared errors of each scan of a record (n_scans trials, drawn independently
    scan by scan from ``rng``), the motion's phases apart."""
    from uq.engine.inputs import input_set
    from uq.pipeline.modelsetup import error_inputs
    inputs = {name: spec for name, spec in error_inputs(
        settings, scene.n_beams, len(scene.ranges)).items() if name not in PHASE_INPUTS}
    layout = input_set(inputs)
    values = layout.values(rng.standard_normal((n_scans, layout.dimension)))
    values.update(layout.constants)
    return values


def monte_carlo_record(settings, geometry, n_scans, rng, compiled=True, spectra=None):
    """One record: the per-scan horizontal speed [m s-1] at each gate (n_scans, n_gates),
    the field's u at the reference point once a scan (n_scans,) [m s-1] (mean speed
    included) and the u-variance fraction the box keeps [1].

    The turbulence's radial velocity along each beam at its beam time
    (:func:`uq.physics.turbulencesampling.record_radial_velocities`) enters the
    measurement model as an additive radial velocity per beam and gate, as the radial
    noise does; the scenario's motion, INS errors and correction act as in a single
    scan. With motion, the turbulence is sampled at the beams' true positions and
    directions (:func:`uq.pipeline.beammotion.moving_beams`: the lidar displaced by the
    platform's translation and its attitude times the lever arm, each beam turned by the
    attitude, at the middle of its dwell, with the same phases as the measurement
    model's); the box is widened by the largest displacement of a probe point. Without
    motion, at the nominal points (the random streams are then drawn as before: the
    phases draw nothing). The box is the unit box of :func:`unit_record` times
    :func:`field_scale`.

    With `spectra` (a generator: :func:`rest_generator`) a fourth item, the series the
    record spectra are taken of (:func:`record_spectra_series`).
    """
    from uq.physics.measurement import measurement_model
    scene, phases, moving, margin = record_motion(settings, geometry, n_scans, rng)
    unit = unit_record(settings, geometry, n_scans, rng, moving, margin,
                       at_rest=spectra is not None and phases is not None)
    scale = field_scale(settings)
    errors = scan_errors(settings, scene, n_scans, rng)
    errors["lidar_radial_velocity"] = errors.get("lidar_radial_velocity", 0.0) \
        + scale * unit.radial
    if phases is not None:
        errors["motion_phases"] = phases
    result = measurement_model(scene, ("wind_speed", "wind_direction", "vertical_wind"),
                               compiled=compiled, **errors)
    speed = np.real(result["wind_speed"]).reshape(n_scans, -1)
    reference = scale * unit.reference
    reference[:, 0] += geometry.speed
    return RecordSeries(
        speed, lateral_series(speed, np.real(result["wind_direction"]).reshape(n_scans, -1)),
        np.real(result["vertical_wind"]).reshape(n_scans, -1), reference, unit.kept,
        None if spectra is None else record_spectra_series(
            settings, scene, errors, unit, scale, n_scans, spectra, compiled), unit.resolved)


@dataclasses.dataclass(frozen=True)
class RecordSeries:
    """One Monte Carlo record (:func:`monte_carlo_record`), once a scan.

    Attributes
    ----------
    speed, lateral, vertical : ndarray, shape (n_scans, n_gates)
        The lidar's horizontal speed, its wind across the record's mean direction
        (:func:`lateral_series`) and its vertical wind [m s-1].
    reference : ndarray, shape (n_scans, 3)
        The field's (u, v, w) at the reference point, the mean speed in u [m s-1].
    kept : float
        The u-variance fraction the records' beams keep [1]
        (``turbulence_intensity_box_kept``).
    spectra : dict or None
        The series the record spectra are taken of (:func:`record_spectra_series`).
    resolved : float
        The u-variance fraction the box alone resolves [1]
        (``turbulence_intensity_box_resolved``).
    """

    speed: np.ndarray
    lateral: np.ndarray
    vertical: np.ndarray
    reference: np.ndarray
    kept: float
    spectra: object = None
    resolved: float = float("nan")


def lateral_series(speed, direction):
    """The wind across the record's mean direction [m s-1], ``Vh sin(D - D_mean)`` (D the
    meteorological direction [deg], its circular mean over the record per gate): the
    lateral component v of the mean-wind frame, to first order."""
    radians = np.radians(direction)
    mean = np.arctan2(np.sin(radians).mean(axis=0), np.cos(radians).mean(axis=0))
    return speed * np.sin(radians - mean)


def record_motion(settings, geometry, n_scans, rng):
    """What a record's box and its sampling depend on besides the field: the scene (its
    probe resolved), the record's coherent motion phases (:func:`coherent_phases`, drawn
    from `rng`), and :func:`moving_probes`' keyword arguments and margin [m]."""
    from uq.pipeline.modelsetup import scene_from_settings
    scene = probe_volume_resolved(scene_from_settings(settings))
    scene, phases = coherent_phases(scene, n_scans, geometry.scan_period, rng)
    moving, margin = moving_probes(settings, scene, phases, geometry)
    return scene, phases, moving, margin


def record_spectra_series(settings, scene, errors, unit, scale, n_scans, rng, compiled):
    """The series of a record whose spectra the run keeps (:data:`SPECTRA_ATTRIBUTES`),
    each (n_scans, n_gates) once a scan: the corrected radial velocity of beam 0 (the
    same trials as the record's Vh) and, where the platform moves, the Vh and radial
    velocity of the lidar at rest (:func:`at_rest`) in the same box, its own errors
    drawn from `rng`."""
    from uq.physics.measurement import measurement_model
    from uq.pipeline.modelsetup import scene_from_settings
    radial = measurement_model(scene, ("radial_velocity",), compiled=compiled, **errors)
    series = {"radial_velocity": np.real(radial["radial_velocity"]).reshape(
        n_scans, scene.n_beams, -1)[:, 0]}
    if unit.at_rest is None:
        return series
    rest = at_rest(settings)
    still = probe_volume_resolved(scene_from_settings(rest))
    draws = scan_errors(rest, still, n_scans, rng)
    draws["lidar_radial_velocity"] = draws.get("lidar_radial_velocity", 0.0) \
        + scale * unit.at_rest
    result = measurement_model(still, ("wind_speed", "radial_velocity"), compiled=compiled,
                               **draws)
    series["wind_speed_at_rest"] = np.real(result["wind_speed"]).reshape(n_scans, -1)
    series["radial_velocity_at_rest"] = np.real(result["radial_velocity"]).reshape(
        n_scans, still.n_beams, -1)[:, 0]
    return series


def at_correction(settings, correction):
    """The validated settings with another ``correction``."""
    from uq.pipeline.scenario import load_scenario
    return load_scenario({**copy.deepcopy(settings), "correction": correction,
                          "sweep": {}}).settings


def spectra_variables(scenes, seed, compiled=True, moving=False):
    """The records' spectra alone (:class:`RecordSpectra`'s variables, dimension
    ``scene``) of validated `scenes` of one scan, their records drawn from `seed` as a
    run draws them: for a result written before runs stored them."""
    spectra = RecordSpectra(spectrum_axis(scenes[0]), len(scenes),
                            len(scenes[0]["lidar"]["ranges"]))
    for i, settings in enumerate(scenes):
        geometry, count = scan_geometry(settings), settings["record"]["count"]
        for r in range(count):
            found = monte_carlo_record(settings, geometry, spectra.n_scans,
                                       record_generator(seed, r), compiled,
                                       rest_generator(seed, r))
            spectra.add(i, {"wind_speed": found.speed, "u_true": found.reference[:, 0],
                            **found.spectra}, count)
    return spectra.variables(moving)


def at_rest(settings):
    """The validated settings of the lidar at rest: no motion, the full correction (of a
    level lidar at rest: its reconstruction), the INS's errors without its sampling
    (nothing moves between its readings)."""
    from uq.pipeline.scenario import load_scenario
    raw = {**copy.deepcopy(settings), "sweep": {}}       # (this scene alone)
    raw.pop("motion", None)
    raw["correction"] = "full"
    for key in ("rate", "interpolation", "clock_offset"):
        raw.get("ins", {}).pop(key, None)
    return load_scenario(raw).settings


def moving_probes(settings, scene, phases, geometry):
    """The keyword arguments of :func:`~uq.physics.turbulencesampling.
    record_radial_velocities` that move its beams with the platform (``displacements``,
    ``directions``, ``position``: the nominal lidar, on the reference point's vertical
    at ``lidar.height``), and the largest displacement of a probe point [m]; ({}, 0.0)
    where the scan has no motion (`phases` None, :func:`coherent_phases`)."""
    if phases is None:
        return {}, 0.0
    from uq.pipeline import beammotion
    position = np.array([0.0, 0.0, settings["lidar"]["height"]
                         - settings["wind"]["reference_height"]])
    displacements, directions = beammotion.moving_beams(
        scene, scene.time_resolved.motion.unit_phases(phases), geometry,
        settings["wind"]["direction"])
    margin = beammotion.motion_margin(geometry, position, displacements, directions)
    return {"displacements": displacements, "directions": directions,
            "position": position}, margin


def probe_volume_resolved(scene):
    """The scene with its probe's node count chosen (:func:`uq.physics.probe.resolve`)."""
    from uq.physics import probe
    return probe.resolve(scene)


def monte_carlo_variables(scenes, truth, seed, compiled, spectral, axis=None, moving=False):
    """The Monte Carlo records of each scene (``record.count`` records, the same random
    streams for every scene), reduced per record as a lidar's software reduces it (the
    record's mean and sample standard deviation of Vh), then over the records.

    ``turbulence_intensity_mc_*``: mean, standard deviation and 95 % interval (the 2.5 %
    and 97.5 % quantiles, probabilistically symmetric, JCGM 101 7.7) over the records of
    ``std(Vh) / mean(Vh)``. ``turbulence_intensity_true_mc_mean``: the mean over the records
    of the field's ``std(u) / mean(u)`` at the reference point, sampled once a scan.
    ``wind_speed_record_bias`` and ``_u``: mean and standard deviation over the records of
    the record's mean Vh minus the true mean (``wind_speed_true`` at the gate plus the
    record's mean u' at the reference point). ``turbulence_intensity_spectral_z``: the
    spectral expected variance against the records' mean variance, in standard errors
    of that mean (clause 8 in spirit: the spectral path is validated where |z| is within
    Student's t quantile of the records' count, :func:`valid_z`,
    ``turbulence_intensity_spectral_valid``); ``turbulence_intensity_box_kept``: the
    u-variance the records' beams keep of the model's (the box and the scales below its
    cells; where the two paths part by design), ``turbulence_intensity_box_resolved``:
    the box's alone.

    With `axis` (:func:`spectrum_axis`: the run's scan period [s] and scans per record)
    also the records' mean spectra (:data:`SPECTRA_ATTRIBUTES`) on its frequencies, NaN
    for a scene whose records are of other scans; with `moving` (the run's file has
    motion) also those of the lidar at rest.
    """
    records = [scene["record"] for scene in scenes]
    count = records[0]["count"]
    n_gates = truth.shape[1]
    apparent = np.full((len(scenes), count, n_gates), np.nan)
    components = np.full((len(scenes), count, n_gates, 2), np.nan)     # v, w
    true_ti = np.full((len(scenes), count, 3), np.nan)
    error = np.full((len(scenes), count, n_gates), np.nan)
    kept = np.full(len(scenes), np.nan)
    resolved = np.full(len(scenes), np.nan)
    spectra = RecordSpectra(axis, len(scenes), n_gates) if axis else None
    for i, settings in enumerate(scenes):
        if not settings["wind"]["speed"] > 0:
            continue
        geometry = scan_geometry(settings)
        n_scans = scans_per_record(settings)
        wanted = spectra is not None and spectra.fits(geometry.scan_period, n_scans)
        for r in range(count):
            found = monte_carlo_record(settings, geometry, n_scans, record_generator(seed, r),
                                       compiled, rest_generator(seed, r) if wanted else None)
            vh, reference, kept[i] = found.speed, found.reference, found.kept
            resolved[i] = found.resolved
            mean = vh.mean(axis=0)
            apparent[i, r] = vh.std(axis=0, ddof=1) / mean
            components[i, r, :, 0] = found.lateral.std(axis=0, ddof=1) / mean
            components[i, r, :, 1] = found.vertical.std(axis=0, ddof=1) / mean
            true_ti[i, r] = reference.std(axis=0, ddof=1) / reference[:, 0].mean()
            error[i, r] = mean - truth[i] - (reference[:, 0].mean() - settings["wind"]["speed"])
            if wanted:
                spectra.add(i, {"wind_speed": vh, "u_true": reference[:, 0], **found.spectra},
                            count)
    squares = apparent ** 2
    standard_error = squares.std(axis=1, ddof=1) / np.sqrt(count)
    z = (spectral ** 2 - squares.mean(axis=1)) / standard_error
    limit = valid_z(count)
    low, high = np.quantile(apparent, [0.025, 0.975], axis=1)
    out = {
        "turbulence_intensity_mc_mean": (("scene", "range"), apparent.mean(axis=1)),
        "turbulence_intensity_mc_u": (("scene", "range"), apparent.std(axis=1, ddof=1)),
        "turbulence_intensity_mc_low": (("scene", "range"), low),
        "turbulence_intensity_mc_high": (("scene", "range"), high),
        "turbulence_intensity_true_mc_mean": (("scene",), true_ti[..., 0].mean(axis=1)),
        "turbulence_intensity_v_true_mc_mean": (("scene",), true_ti[..., 1].mean(axis=1)),
        "turbulence_intensity_w_true_mc_mean": (("scene",), true_ti[..., 2].mean(axis=1)),
        "turbulence_intensity_v_mc_mean": (("scene", "range"), components[..., 0].mean(axis=1)),
        "turbulence_intensity_w_mc_mean": (("scene", "range"), components[..., 1].mean(axis=1)),
        "turbulence_intensity_spectral_z": (("scene", "range"), z),
        "turbulence_intensity_spectral_valid": (("scene", "range"), np.abs(z) <= limit),
        "turbulence_intensity_spectral_z_limit": (("scene",), np.full(len(scenes), limit)),
        "turbulence_intensity_check_resolution": (("scene", "range"), 0.5 * limit
                                                  * standard_error / squares.mean(axis=1)),
        "turbulence_intensity_box_kept": (("scene",), kept),
        "turbulence_intensity_box_resolved": (("scene",), resolved),
        "wind_speed_record_bias": (("scene", "range"), error.mean(axis=1)),
        "wind_speed_record_u": (("scene", "range"), error.std(axis=1, ddof=1)),
    }
    if spectra is not None:
        out.update(spectra.variables(moving))
    return out


# --- The records' spectra -------------------------------------------------------------------

#: Spawn key of the random streams of the lidar at rest in the records' spectra (apart
#: from the records' own, :data:`RECORD_STREAM`, so that they draw what they drew).
REST_STREAM = 25
#: The spectra a record-mode run keeps (the mean over its records of each record's
#: periodogram, once a scan), for ``uq plot`` and ``uq report`` (:mod:`uq.outputs.
#: recordfigures`): name -> (series of :func:`record_spectra_series`, dimensions after
#: the scene's, attributes). The ``*_at_rest`` ones only where the platform moves.
SPECTRA_ATTRIBUTES = {
    "record_psd_u_true": ("u_true", ("record_frequency",), {
        "units": "m2 s-2 Hz-1", "long_name": "power spectral density of the field's u at "
        "the reference point sampled once a scan, mean over the records of each record's "
        "periodogram (one-sided, record mean removed)"}),
    "record_psd_wind_speed": ("wind_speed", ("range", "record_frequency"), {
        "units": "m2 s-2 Hz-1", "long_name": "power spectral density of the horizontal "
        "wind speed the lidar reports once a scan, mean over the records of each record's "
        "periodogram (one-sided, record mean removed)"}),
    "record_psd_radial_velocity": ("radial_velocity", ("range", "record_frequency"), {
        "units": "m2 s-2 Hz-1", "long_name": "power spectral density of the corrected "
        "radial velocity of beam 0 once a scan, mean over the records of each record's "
        "periodogram (one-sided, record mean removed)"}),
    "record_psd_wind_speed_at_rest": ("wind_speed_at_rest", ("range", "record_frequency"), {
        "units": "m2 s-2 Hz-1", "long_name": "power spectral density of the horizontal "
        "wind speed once a scan of the same lidar at rest (no motion, full correction) "
        "in the same fields, mean over the records (one-sided, record mean removed)"}),
    "record_psd_radial_velocity_at_rest": (
        "radial_velocity_at_rest", ("range", "record_frequency"), {
            "units": "m2 s-2 Hz-1", "long_name": "power spectral density of the radial "
            "velocity of beam 0 once a scan of the same lidar at rest in the same fields, "
            "mean over the records (one-sided, record mean removed)"}),
}
#: Attributes of the spectra's frequency coordinate.
FREQUENCY_ATTRIBUTES = {"units": "Hz", "long_name": "frequency of the records' spectra "
                        "(the record's scans: 0 to half the scan rate)"}


def rest_generator(seed, record):
    """The generator of the errors of the lidar at rest in record `record`'s spectra."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(REST_STREAM,
                                                                         record)))


def spectrum_axis(settings):
    """(scan period [s], scans per record) of validated `settings`: the frequencies of a
    run's record spectra (the file's scene's; a scene of other scans has none)."""
    return scan_geometry(settings).scan_period, scans_per_record(settings)


class RecordSpectra:
    """The mean periodograms of each scene's records on one frequency axis."""

    def __init__(self, axis, n_scenes, n_gates):
        self.period, self.n_scans = axis
        self.frequency = np.fft.rfftfreq(self.n_scans, self.period)
        shapes = {"u_true": (n_scenes, self.frequency.size)}
        self.sums = {name: np.full(shapes.get(series, (n_scenes, n_gates,
                                                      self.frequency.size)), np.nan)
                     for name, (series, _, _) in SPECTRA_ATTRIBUTES.items()}

    def fits(self, period, n_scans):
        """Whether a scene's records are on this axis."""
        return n_scans == self.n_scans and n_scans > 1 and math.isclose(period, self.period)

    def add(self, scene, series, count):
        """Add 1/count of a record's periodograms (`series`: name -> (n_scans, ...))."""
        for name, (key, _, _) in SPECTRA_ATTRIBUTES.items():
            if key not in series:
                continue
            _, density = signal.periodogram(series[key], fs=1.0 / self.period, axis=0)
            part = np.moveaxis(density, 0, -1) / count
            total = self.sums[name][scene]
            self.sums[name][scene] = np.where(np.isnan(total), part, total + part)

    def variables(self, moving):
        """The variables (scene first) and the frequency coordinate."""
        out = {"record_frequency": (("record_frequency",), self.frequency)}
        for name, (_, dims, _) in SPECTRA_ATTRIBUTES.items():
            if moving or not name.endswith("_at_rest"):
                out[name] = (("scene",) + dims, self.sums[name])
        return out
