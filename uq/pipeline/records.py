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

``turbulence_intensity_true`` is the expected ``sigma_u / U`` of the field at the
reference point over the record (the same high-pass and scan sampling), so that
(``turbulence_intensity_spectral`` / ``turbulence_intensity_true``)^2 is the lidar's
u-variance ratio (Sathe et al. 2011) where motion and errors are absent and there is no
shear. ``turbulence_intensity_point`` is the scenario's intensity (no high-pass).

Not computed here: the Monte Carlo records (``turbulence_intensity_mc_*``,
``wind_speed_record_*``); the ``skipped`` attribute says so.
"""
import copy
import math

import numpy as np

from uq.physics.lidarspectral import lidar_variances, probe_transfer_for
from uq.physics.spectraltensor import KaimalSpectra, mann_tensor_for_intensity
from uq.pipeline import probesection
from uq.pipeline.turbulencesection import scan_geometry

#: Attributes of the record-mode variables.
RECORD_ATTRIBUTES = {
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
}


def turbulence_model(turbulence, speed):
    """The spectral model of a validated ``turbulence`` section at `speed` [m s-1]: a
    :class:`~uq.physics.spectraltensor.MannTensor` whose point sigma_u / U is the
    intensity, or the IEC :class:`~uq.physics.spectraltensor.KaimalSpectra`."""
    if turbulence["model"] == "mann":
        return mann_tensor_for_intensity(turbulence["intensity"], speed,
                                         turbulence["length_scale"], turbulence["anisotropy"])
    return KaimalSpectra.iec(turbulence["intensity"], speed, turbulence["length_scale"])


def spectral_variances(settings):
    """The :class:`~uq.physics.lidarspectral.SpectralVariances` of validated `settings`:
    the probe's own transfer function (:func:`~uq.physics.lidarspectral.
    probe_transfer_for`) at the slanted beams' focus of each gate."""
    geometry = scan_geometry(settings)
    lidar = settings["lidar"]
    focus = np.asarray(lidar["ranges"], float) / math.cos(math.radians(lidar["half_cone"]))
    transfer = probe_transfer_for(probesection.make_probe(lidar.get("probe")), focus)
    model = turbulence_model(settings["turbulence"], settings["wind"]["speed"])
    return lidar_variances(geometry, model, transfer), geometry


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


def record_variables(scenario, fields, dataset):
    """The record-mode variables of a chunk's scenes (dimension ``scene``, and ``range``):
    `fields` as :func:`scene_settings`; `dataset` the chunk's per-scan results."""
    scenes = scene_settings(scenario, fields)
    n_gates = len(scenario.settings["lidar"]["ranges"])
    lidar, true = np.full((len(scenes), n_gates), np.nan), np.full(len(scenes), np.nan)
    for i, settings in enumerate(scenes):
        if settings["wind"]["speed"] > 0:        # no frozen field without a mean wind: NaN
            variances = spectral_variances(settings)[0]
            lidar[i], true[i] = variances.lidar[:, 0], variances.true[0]
    speeds = np.array([s["wind"]["speed"] for s in scenes])
    truth = dataset["wind_speed_true"].values.reshape(len(scenes), n_gates)
    u_scan = _scan_uncertainty(dataset).reshape(len(scenes), n_gates)
    return {
        "turbulence_intensity_true": (("scene",), np.sqrt(true) / speeds),
        "turbulence_intensity_spectral": (("scene", "range"),
                                          np.sqrt(lidar + u_scan ** 2) / truth),
        "turbulence_intensity_spectral_turbulence": (("scene", "range"),
                                                     np.sqrt(lidar) / truth),
        "turbulence_intensity_u_ratio": (("scene", "range"), lidar / true[:, None]),
    }


def _scan_uncertainty(dataset):
    """u of one scan's Vh from the declared errors and the motion [m s-1]: Monte Carlo
    where it ran, else the GUM's (``sampling.method: none``)."""
    name = "wind_speed_mc_u" if "wind_speed_mc_u" in dataset else "wind_speed_gum_u"
    return dataset[name].values
