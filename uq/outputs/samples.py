"""The Monte Carlo trials of a single-scene result, drawn again (for its histogram).

A results file keeps statistics, not trials. Its scenario (the ``scenario`` attribute,
as run) and seed give the trials back: the same random numbers block by block
(:func:`uq.engine.sampling.normal_scores`), the same inputs and the same measurement
model, so the first n trials are the run's own first n trials (to the 1e-12 m/s at which
the compiled and the numpy model agree). The trials go through the compiled model, a
probe volume's too (:mod:`uq.physics.fusedprobe`), with the probe's node count the run
stored (``probe_nodes``), not chosen again.
"""
import dataclasses

import numpy as np
import yaml

from uq.constants import RNG_BLOCK_SIZE
from uq.engine.inputs import input_set
from uq.engine.sampling import normal_scores
from uq.physics.measurement import measurement_model
from uq.pipeline.modelsetup import error_inputs, scene_from_settings
from uq.pipeline.scenario import load_scenario

#: Trials drawn again for a histogram: 2^17 put ~3,000 draws in each 2.5 % tail.
HISTOGRAM_TRIALS = 2**17


def can_redraw(dataset):
    """Does the result hold what :func:`scene_trials` needs (one scene, sampled)?
    A sweep's result qualifies once one scene is selected (``--select``, every swept
    dimension a scalar coordinate: :func:`scene_assignments`)."""
    attrs = dataset.attrs
    return ("scenario" in attrs and "seed" in attrs and attrs.get("sampling_method") != "none"
            and dataset["mc_n_samples"].ndim == 0 and int(dataset["mc_n_samples"]) > 0)


def scene_assignments(dataset, fixed=None):
    """``{dotted key: value}`` of the scene `dataset` holds: every swept key of its
    scenario (links included) at the value of its coordinate, which must be a scalar
    (one scene, e.g. picked by ``--select``), except the keys in `fixed`, which are
    given. The trials of :func:`trials_with` are then exactly that scene's.

    Raises
    ------
    ValueError
        A swept key that is neither fixed nor a scalar coordinate (several scenes).
    """
    fixed = dict(fixed or {})
    sweep = (yaml.safe_load(dataset.attrs["scenario"]) or {}).get("sweep") or {}
    values = {}
    for key in sweep:
        if key in fixed:
            continue
        coordinate = dataset[key.replace(".", "_")]
        if coordinate.ndim:
            raise ValueError(f"the result holds {coordinate.size} values of the swept key "
                             f"{key}: select one scene to draw its trials")
        values[key] = _plain(coordinate.values.item())
    return {**values, **fixed}


def _plain(value):
    """A coordinate's value as the scenario file writes it (text from bytes)."""
    return value.decode() if isinstance(value, bytes) else value


def scene_trials(dataset, outputs, n_max=HISTOGRAM_TRIALS):
    """The first min(n, n_max) Monte Carlo trials of a single-scene result.

    Parameters
    ----------
    dataset : xarray.Dataset
        A result of ``uq run`` without a sweep (:func:`can_redraw`).
    outputs : tuple of str
        Outputs to evaluate (e.g. ``("wind_speed", "wind_direction")``).

    Returns
    -------
    dict
        output -> real array of shape (n, n_gates) (radial velocity (n, beams, gates)).
    """
    return trials_with(dataset, scene_assignments(dataset), outputs, n_max)


def trials_with(dataset, assignments, outputs, n_max=HISTOGRAM_TRIALS):
    """The first min(n, n_max) trials of one scene of a result: its scenario with the
    swept keys set to `assignments` (``{dotted key: value}``, every swept key:
    :func:`scene_assignments`) and no sweep; the run's seed and sampler (every scene of
    a sweep draws the same numbers)."""
    raw = yaml.safe_load(dataset.attrs["scenario"])
    missing = set(raw.pop("sweep", None) or {}) - set(assignments)
    if missing:                 # else the trials would be the file's default scene's
        raise ValueError(f"no value for the swept keys {', '.join(sorted(missing))}")
    scenario = load_scenario(raw, assignments)
    settings = scenario.settings
    scene = _stored_nodes(scene_from_settings(settings), dataset)
    inputs = input_set(error_inputs(settings, scene.n_beams, len(scene.ranges)))
    n = min(int(np.max(dataset["mc_n_samples"])), n_max)
    scores = np.empty((n, inputs.dimension))
    for block, start in enumerate(range(0, n, RNG_BLOCK_SIZE)):
        rows = min(RNG_BLOCK_SIZE, n - start)
        normal_scores(dataset.attrs["sampling_method"], int(dataset.attrs["seed"]), block,
                      inputs.dimension, out=scores[start:start + rows], rows=rows)
    values = inputs.values(scores, overwrite=True)
    with np.errstate(all="ignore"):                 # out-of-domain trials become NaN
        result = measurement_model(scene, tuple(outputs), **values, **inputs.constants)
    return {q: np.real(np.asarray(result[q])) for q in outputs}


def _stored_nodes(scene, dataset):
    """The scene with the probe's node count its single-scene run used (``probe_nodes``,
    ``probe_quadrature_error``) instead of searching it again (a numpy quadrature search,
    ~1 s); a sweep's scenes (one count per scene) are resolved as the run resolved them."""
    if scene.probe is None or "probe_nodes" not in dataset or dataset["probe_nodes"].ndim:
        return scene
    nodes = int(dataset["probe_nodes"])
    error = float(dataset["probe_quadrature_error"]) if "probe_quadrature_error" in \
        dataset else 0.0
    return dataclasses.replace(scene, probe=scene.probe.with_nodes(nodes, error))
