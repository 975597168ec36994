"""The orchestrator: scenario -> chunks of scenes of the sweep -> propagation -> Dataset.

The sweep's outer product is cut into chunks (:mod:`uq.pipeline.sweep`): scenes that differ only
in scene values are evaluated together as arrays; the measurement model runs through
:func:`uq.propagate`; the true values, the error-free reconstruction and the Rubio &
Gottschall (2022) model are added; the chunks are stacked back onto the grid. Every
scene uses the same seed, and so the same underlying draws (common random numbers).
Chunks can run on a dask cluster and be kept on disk for ``--resume``; neither changes
a number.
"""
import contextlib
import dataclasses
import logging
import threading
import time

import numpy as np
import xarray as xr

from uq._version import __version__
from uq.cpus import usable_cpus
from uq.compileguard import numpy_while_uncached
from uq.pipeline.distributions import error_distribution
from uq.engine.inputs import Input, moments
from uq.pipeline import probesection, records
from uq.pipeline.checkpoint import encode_chunk
from uq.pipeline.modelsetup import (MOTION_INPUTS, error_inputs, input_label, scene_from_settings,
                                    skipped_work)
from uq.physics.correction import describe_corrections
from uq.physics import probe as probe_volume
from uq.physics.measurement import measurement_model, true_values
from uq.physics.scene import (ALL_OUTPUTS, ANGULAR_NAVIGATION, HELD_WIND_SPEED, NAVIGATION,
                              OUTPUTS)
from uq.pipeline.metadata import (COORDINATES, QUANTITIES, ancillary_variables, cf_encode,
                                  history, swept_key_attributes, variable_attributes)
from uq.engine.propagate import propagate
from uq.physics.rubio2022 import rubio2022_scene_uncertainty
from uq.engine.sampling import new_seed
from uq.pipeline.scenario import load_scenario
from uq.engine.statistics import unwrap
from uq.engine.stopping import STOPPED_BY
from uq.interrupts import raise_if_stopped
from uq.pipeline.sweep import batch_scene, group_assignments, sweep_plan, vector_fields


log = logging.getLogger(__name__)

#: The values of ``uq run --model`` (and of :func:`run`'s `model`).
MODEL_CHOICES = ("compiled", "numpy", "auto")


def run(scenario, progress=None, *, client=None, checkpoint=None, model="compiled",
        kernels_ready=None, kernels_missing=None):
    """Run a scenario and return its results.

    Parameters
    ----------
    scenario : Scenario, dict, str or pathlib.Path
        Anything :func:`uq.load_scenario` accepts.
    progress : callable, optional
        Called as ``progress(done, total)`` after each chunk of scenes.
    client : dask.distributed.Client, optional
        Compute the chunks on this dask cluster; the result is identical to a local run.
    checkpoint : uq.pipeline.checkpoint.Checkpoint, optional
        Keeps finished chunks on disk and reuses those it already has (``--resume``).
    model : {"compiled", "numpy", "auto"}
        ``compiled`` (default): the compiled model wherever it applies (else numpy, logged
        at ``-v``), compiling what numba's cache does not hold; ``numpy``: the numpy
        reference model and statistics throughout, nothing compiled; ``auto``: each
        chunk the compiled model where numba's cache holds every kernel it calls, else
        the numpy model (nothing compiles in this process: a record's turbulence
        kernels too are numpy's until the cache holds them, :mod:`uq.compileguard`; on a
        cluster: ``compiled``). They give the
        same numbers to 1e-12 m/s (``tests/pipeline/test_model_switch.py``).
    kernels_ready : callable, optional
        Called with no argument before a chunk's model first runs, after its turbulence
        records are drawn: ``uq run`` waits there for the kernels it has a second process
        compile beside the boxes (:mod:`uq.cli.sidecompile`). Not called on a cluster.
    kernels_missing : callable, optional
        With ``auto``: called once, with the :class:`~uq.compileguard.KernelNotCached`,
        when a chunk finds a kernel missing from the cache; it may return a callable
        that says, before each later chunk, whether to try the compiled model again
        (``uq run``: once the kernels' compile in the background has ended,
        :mod:`uq.cli.firstrun`).

    Returns
    -------
    xarray.Dataset
        The variables listed in the README ("Results files").
    """
    started = time.perf_counter()
    if model not in MODEL_CHOICES:
        raise ValueError(f"model must be one of {', '.join(MODEL_CHOICES)}, not {model!r}")
    scenario = load_scenario(scenario)
    plan = sweep_plan(scenario)
    with (checkpoint.held() if checkpoint else contextlib.nullcontext()):
        seed = scenario.sampling["seed"]
        if seed is None:             # a resumed run keeps the seed its chunks were drawn with
            seed = checkpoint.seed if checkpoint and checkpoint.seed is not None else new_seed()
        if checkpoint:          # (auto's numpy chunks are the compiled ones' to 1e-12)
            checkpoint.start(scenario, seed, plan.chunks,
                             "compiled" if model == "auto" else model)
        choice = ModelChoice(model if client is None or model != "auto" else "compiled",
                             kernels_missing)
        # auto: a record's turbulence kernels too are numpy's until numba's cache holds
        # them (uq.compileguard.cached_kernels)
        with (numpy_while_uncached() if choice.model == "auto" else contextlib.nullcontext()):
            results = _compute(scenario, plan, seed, progress, client, checkpoint, choice,
                               kernels_ready)
    dataset = _assemble(scenario, plan, results)
    dataset.attrs.update(_global_attributes(scenario, seed, dataset, started, choice))
    said = {}                                 # one line for the outputs said alike
    for q, text in outside_domain(dataset, scenario.outputs):
        said.setdefault(text, []).append(q)
    for text, outputs in said.items():
        log.warning("%s: %s", ", ".join(outputs), text)
    return dataset


def outside_domain(dataset, outputs):
    """What of each output fell outside the model's domain (non-finite), in words: the
    scenes (and gates, beams) where every Monte Carlo trial did, whose mean, u and
    interval are NaN; the trials left out elsewhere (``q_mc_n_invalid``); without Monte
    Carlo, where the GUM value is NaN. A list of (output, text); empty where nothing
    did."""
    lines = []
    for q in outputs:
        if f"{q}_gum_value" not in dataset:
            continue
        value = dataset[f"{q}_gum_value"].values
        total = value.size
        if f"{q}_mc_n_invalid" not in dataset:
            bad = int(np.sum(~np.isfinite(value)))
            if bad:
                lines.append((q, f"outside the model's domain at the input means in {bad} "
                             f"of {total} scene(s) x gate(s): its GUM value and u there are "
                             "NaN"))
            continue
        invalid = dataset[f"{q}_mc_n_invalid"].values
        every = (invalid > 0) & ~np.isfinite(dataset[f"{q}_mc_mean"].values)
        some = (invalid > 0) & ~every
        if np.any(every):
            lines.append((q, "every Monte Carlo trial fell outside the model's domain "
                         f"(non-finite) in {int(np.sum(every))} of {total} scene(s) x "
                         "gate(s): its mean, u and interval there are NaN, not an estimate"))
        if np.any(some):
            lines.append((q, f"{int(np.sum(invalid[some]))} Monte Carlo trials in "
                         f"{int(np.sum(some))} of {total} scene(s) x gate(s) fell outside "
                         f"the model's domain (non-finite) and are left out of its "
                         f"statistics (<output>_mc_n_invalid)"))
    return lines




class ModelChoice:
    """Which model each chunk runs (:func:`run`'s `model`): :meth:`evaluate` calls
    ``work(compiled)`` with the model's flag; with ``auto``, inside
    :func:`uq.compileguard.cached_only`, and again with False where a kernel is
    missing from numba's cache (then `kernels_missing`, once; the compiled model is
    tried again only where what it returned says so)."""

    def __init__(self, model, kernels_missing=None):
        self.model = model
        self.kernels_missing = kernels_missing
        self.retry = None                    # after a miss: whether to try again
        self.numpy_chunks = 0                # chunks auto ran with the numpy model
        self.chunks = 0
        self.missing = None                  # the first kernel found missing
        self._lock = threading.Lock()        # (numpy chunks may run on threads)

    @property
    def compiled(self):
        """The flag of a chunk run without the guard (on a cluster, ``compiled`` for
        ``auto``)."""
        return self.model != "numpy"

    def evaluate(self, work):
        """``work(compiled)`` of one chunk with the model chosen for it."""
        with self._lock:
            self.chunks += 1
        if self.model != "auto":
            return work(self.model == "compiled")
        if self.missing is None or (self.retry is not None and self.retry()):
            from uq.compileguard import KernelNotCached, cached_only
            try:
                with cached_only():
                    return work(True)
            except KernelNotCached as error:
                with self._lock:
                    first = self.missing is None
                    self.missing = self.missing or str(error)
                    self.retry = None
                if first and self.kernels_missing is not None:
                    self.retry = self.kernels_missing(error)
        with self._lock:
            self.numpy_chunks += 1
        return work(False)


def _compute(scenario, plan, seed, progress, client, checkpoint, choice,
             kernels_ready=None):
    """Results of every chunk, by index: from the checkpoint, else computed."""
    results = checkpoint.load() if checkpoint else {}
    todo = [chunk for chunk in plan.chunks if chunk.index not in results]
    if checkpoint:
        checkpoint.resumed(len(results), len(plan.chunks))
    finished = _local(scenario, plan, todo, seed, choice, kernels_ready) \
        if client is None else \
        _distributed(client, scenario, plan, todo, seed, choice.compiled,
                     checkpoint.digest if checkpoint else None)
    if progress and results:
        progress(len(results), len(plan.chunks))
    for index, dataset, encoded in finished:
        results[index] = dataset
        if checkpoint:
            checkpoint.save(index, dataset, encoded)
        raise_if_stopped()                   # a Ctrl-C some library code swallowed
        if progress:
            progress(len(results), len(plan.chunks))
    return results


#: Threads that evaluate ``auto``'s numpy chunks together (the cores this process may
#: use, at most 4): the numpy model is 1-4x slower than the compiled one per core, and
#: its ufuncs release the GIL; the background compile, at a low priority, waits.
NUMPY_CHUNK_THREADS = min(4, usable_cpus())


def _local(scenario, plan, chunks, seed, choice, kernels_ready=None):
    """Chunks in this process, yielded in order as ``(index, dataset, None)``. Once
    ``auto`` runs the numpy model (a kernel missing from numba's cache), the remaining
    chunks go to :data:`NUMPY_CHUNK_THREADS` threads (each chunk is the same whichever
    thread computes it: its draws come from the seed alone). In record mode the first
    chunk draws every scene's records (:func:`uq.pipeline.records.draw_first_records`,
    in sequence, its FFTs on the cores); the later chunks find them drawn and are the
    model's and the records' statistics: floating_lidar_ti's 11 later chunks in 6.2 s
    in sequence, 4.7 s on 2 threads (2 cores; the compiled model 3.5 s)."""
    chunks = list(chunks)
    while chunks:
        chunk = chunks.pop(0)
        yield chunk.index, run_chunk(scenario, plan, chunk, seed, choice, kernels_ready), None
        if choice.missing and len(chunks) > 1 and NUMPY_CHUNK_THREADS > 1:
            yield from _in_threads(scenario, plan, chunks, seed, choice)
            return


def _in_threads(scenario, plan, chunks, seed, choice):
    """:func:`_local`'s numpy chunks on threads, yielded in order; at a stop (Ctrl-C) the
    chunks not started are cancelled (those running end with their chunk)."""
    from concurrent.futures import ThreadPoolExecutor
    pool = ThreadPoolExecutor(NUMPY_CHUNK_THREADS, thread_name_prefix="uq-chunk")
    try:
        futures = [pool.submit(run_chunk, scenario, plan, chunk, seed, choice)
                   for chunk in chunks]
        for chunk, future in zip(chunks, futures):
            yield chunk.index, future.result(), None
    finally:
        pool.shutdown(wait=False, cancel_futures=True)


def _distributed(client, scenario, plan, chunks, seed, compiled, digest):
    """Chunks on a dask cluster, yielded as ``(index, dataset, encoded)`` as they finish.

    What this process does per chunk is kept to receiving it and writing its checkpoint
    file (the serial share of a distributed sweep, ``uq.bench.sweep.serial_fraction``):
    the scenario and the plan are sent to the workers once (scattered), each task carries
    only its chunk, and the worker evaluates the chunk (its Monte Carlo, GUM and paper
    model) and encodes its checkpoint file (:func:`chunk_task`)."""
    from dask.distributed import as_completed
    shared = client.scatter([scenario, plan], broadcast=True, hash=False)
    futures = {client.submit(chunk_task, *shared, chunk, seed, compiled, digest,
                             pure=False): chunk.index for chunk in chunks}
    for future in as_completed(futures, loop=client.loop):
        dataset, encoded = future.result()
        yield futures.pop(future), dataset, encoded   # the cluster may forget it now


def chunk_task(scenario, plan, chunk, seed, compiled=True, digest=None):
    """One chunk on a dask worker: ``(dataset, encoded)``, its results
    (:func:`run_chunk`) and, with the checkpoint's `digest`, its checkpoint file
    (:func:`uq.pipeline.checkpoint.encode_chunk`), else None."""
    dataset = run_chunk(scenario, plan, chunk, seed, compiled)
    return dataset, None if digest is None else encode_chunk(dataset, digest)


def run_chunk(scenario, plan, chunk, seed, compiled=True, kernels_ready=None):
    """Results of one chunk of scenes: a Dataset with a ``scene`` dimension (`compiled`:
    the compiled model where it applies, else the numpy model throughout, or a
    :class:`ModelChoice`; `kernels_ready`: as :func:`run`'s)."""
    spectra_of = scenario.settings             # (the file's scene: the records' spectra)
    if plan.group_keys:
        scenario = scenario.with_values(group_assignments(scenario, plan, chunk.group))
    base = scene_from_settings(scenario.settings)
    fields = vector_fields(scenario, plan, chunk) or {"wind_speed": np.array([base.wind_speed])}
    record_fields = (records.chunk_fields(scenario, plan, chunk)
                     if "turbulence" in scenario.settings else None)   # record mode
    prepared = None
    if record_fields is not None and "wind_speed" in model_outputs(scenario.outputs):
        # the spectral path and the records' boxes before the per-scan kernels compile
        # (memory: numba keeps what it compiled)
        prepared = records.prepare_records(scenario, record_fields, seed, spectra_of)
    if kernels_ready is not None:
        kernels_ready()

    def evaluate(compiled):
        dataset = run_scene(scenario, batch_scene(base, fields), seed, compiled)
        if record_fields is not None and "wind_speed_true" in dataset:
            # the records' variables of each scene
            dataset = dataset.assign(records.record_variables(
                scenario, record_fields, dataset, seed, compiled, spectra_of, prepared))
        return dataset
    if isinstance(compiled, ModelChoice):
        return compiled.evaluate(evaluate)
    return evaluate(compiled)


def run_scene(scenario, scene, seed, compiled=True):
    """Results of a batch of scenes (dimension ``scene``) that share `scenario`'s structure."""
    settings = scenario.settings
    outputs = model_outputs(scenario.outputs)
    n_gates = len(scene.ranges)
    scene = probe_volume.resolve(scene)       # the probe's node count, once per batch
    inputs = error_inputs(settings, scene.n_beams, n_gates)
    held = _motion_held(settings, inputs) if wants_motion_ti(settings) else None
    engine = _propagate(scene, settings, outputs, inputs, seed, compiled, held)
    motion_u = None
    if held is not None:                # the motion alone: u of the held speed, then gone
        motion_u = engine[f"{HELD_WIND_SPEED}_mc_u"].values
        engine = engine.drop_vars([f"{HELD_WIND_SPEED}_mc_{key}" for key in ("mean", "u")])
    dataset = _scene_dataset(scene, settings, outputs, engine, compiled)
    if wants_motion_ti(settings):
        dataset = dataset.assign(_motion_ti(settings, inputs, motion_u, dataset))
    return dataset


def wants_motion_ti(settings):
    """``wind_speed_motion_ti`` is computed for every scenario with motion whose outputs
    include the wind speed (or that asks for it by name)."""
    outputs = settings["outputs"]
    return "wind_speed_motion_ti" in outputs or (bool(settings.get("motion"))
                                                 and "wind_speed" in outputs)


def model_outputs(outputs):
    """The per-trial outputs the model evaluates (derived ones need wind_speed)."""
    model = [q for q in outputs if q in ALL_OUTPUTS]
    derived = ("wind_speed_motion_ti", "turbulence_intensity")
    if any(q in outputs for q in derived) and "wind_speed" not in model:
        model.insert(0, "wind_speed")
    return tuple(model)


def _motion_held(settings, inputs):
    """The inputs held for the motion alone: every input but the motion's, at its mean
    (None without Monte Carlo or without a motion input)."""
    if settings["sampling"]["method"] == "none" or not any(n in inputs for n in MOTION_INPUTS):
        return None
    return {name: _mean_of(spec) for name, spec in inputs.items() if name not in MOTION_INPUTS}


def _motion_ti(settings, inputs, motion_u, dataset):
    """``wind_speed_motion_ti``: u of the scan's Vh from the motion alone (every other
    error at its mean), over the true Vh: the Monte Carlo u of the run's own trials'
    speeds reconstructed again with every input but the motion's held at its mean
    (`motion_u`, :func:`_motion_held`: the same draws of the motion, common random
    numbers); and ``wind_speed_motion_ti_gum`` from the motion inputs' share of the GUM
    budget."""
    truth = dataset["wind_speed_true"].values
    if not any(n in inputs for n in MOTION_INPUTS):
        u_motion = np.zeros_like(truth)
    elif settings["sampling"]["method"] == "none":
        u_motion = np.full_like(truth, np.nan)
    else:
        u_motion = motion_u
    dims = dataset["wind_speed_true"].dims
    budget = dataset["wind_speed_budget"]
    labels = [input_label(name) for name in MOTION_INPUTS]
    motion_variance = budget.sel(input=[i for i in budget["input"].values if i in labels]
                                 ).sum("input", skipna=False).values   # NaN stays NaN
    return {"wind_speed_motion_ti": (dims, u_motion / truth),
            "wind_speed_motion_ti_gum": (dims, np.sqrt(motion_variance) / truth)}


def _mean_of(spec):
    """An input held at its mean (a float; the model broadcasts it)."""
    distribution = spec.distribution if isinstance(spec, Input) else spec
    if isinstance(distribution, float):
        return distribution
    return moments(distribution)[0]


def _propagate(scene, settings, outputs, inputs, seed, compiled, held=None):
    """:func:`uq.propagate` of the scene's model; with `held` (inputs -> value) also the
    Monte Carlo mean and u of the speed with those inputs held (auxiliary
    ``wind_speed_held``, from the same trials)."""
    sampling = settings["sampling"]
    n_gates = len(scene.ranges)

    def model(**errors):
        # the GUM's complex steps need no held speed (it is Monte Carlo's alone)
        real = held is not None and not any(np.iscomplexobj(v) for v in errors.values())
        return measurement_model(scene, outputs, compiled=compiled,
                                 held=held if real else None, **errors)
    model.whole_chunks = compiled and scene.time_resolved is None  # blocks its own trials

    return propagate(model, inputs,
                       n=sampling.get("n"), digits=sampling.get("digits"),
                       method=sampling["method"], seed=seed, circular=("wind_direction",),
                       output_dims={q: _dims(q) for q in ALL_OUTPUTS + (HELD_WIND_SPEED,)},
                       interval=sampling["interval"], chunk_size=sampling.get("chunk_size"),
                       control_variate=sampling["control_variate"],
                       stopping=sampling["stopping"],
                       stop_when_gum_valid=sampling["stop_when_gum_valid"],
                       covariance=profile_covariances(outputs, n_gates),
                       auxiliary=(HELD_WIND_SPEED,) if held is not None else (),
                       compiled=compiled)


def profile_covariances(outputs, n_gates):
    """Outputs whose gate-to-gate covariance is kept: wind speed and gate height, when
    ``gate_height`` is requested (the inputs of ``uq fit``) and there are several gates."""
    if "gate_height" not in outputs or n_gates < 2:
        return ()
    return tuple(q for q in ("wind_speed", "gate_height") if q in outputs)


def _dims(quantity):
    return ("scene", "beam", "range") if quantity == "radial_velocity" else ("scene", "range")


def _scene_dataset(scene, settings, outputs, engine, compiled):
    truth = true_values(scene, outputs)
    nominal = measurement_model(scene, outputs, compiled=compiled)
    paper = _paper_uncertainty(scene, settings, truth["wind_speed"])
    data = {}
    for q in outputs:
        dims = _dims(q)
        data[f"{q}_true"] = (dims, truth[q])
        data[f"{q}_nominal"] = (dims, np.real(nominal[q][0]))
        data[f"{q}_paper_u"] = (dims, paper[q])
        if f"{q}_mc_mean" in engine:
            bias = engine[f"{q}_mc_mean"].values - truth[q]
            if q == "wind_direction":
                bias = unwrap(bias, 0.0)
            data[f"{q}_mc_bias"] = (dims, bias)
    if "probe" in settings["lidar"]:
        data.update(_probe_variables(scene, outputs, nominal))
    data["mc_n_samples"] = ("scene", np.full(scene.shape, engine.attrs["n_samples"]))
    data["mc_stopped_by"] = ("scene", np.full(scene.shape, STOPPED_BY.index(
        engine.attrs["stopped_by"]), dtype=np.int8))
    coords = {"input": [input_label(name) for name in engine["input"].values],
              "range": list(scene.ranges)}
    if "range_other" in engine.dims:
        coords["range_other"] = list(scene.ranges)
    if "beam" in engine.dims:
        coords.update(_beam_coordinates(scene))
    variables = {name: engine.variables[name] for name in engine.data_vars}
    return xr.Dataset({**variables, **data},                # one construction, no merge
                      coords={**{name: engine.variables[name] for name in engine.coords},
                              **coords}, attrs=engine.attrs)


#: Outputs whose systematic error from the probe volume is reported (``{q}_probe_bias``).
PROBE_BIAS_OUTPUTS = ("wind_speed", "wind_direction", "vertical_wind", "radial_velocity")


def _probe_variables(scene, outputs, nominal):
    """``{q}_probe_bias``: the error-free reconstruction with the probe volume minus the
    same at the gate centre (zero for a point probe), so that ``q_nominal - q_true`` is
    this plus the correction's own systematic error; ``probe_nodes`` and
    ``probe_quadrature_error``: the quadrature along the beams (:mod:`uq.physics.probe`)."""
    point = nominal if scene.probe is None else measurement_model(
        dataclasses.replace(scene, probe=None), outputs, compiled=False)
    data = {}
    for q in outputs:
        if q not in PROBE_BIAS_OUTPUTS:
            continue
        bias = np.real(nominal[q][0]) - np.real(point[q][0])
        if q == "wind_direction":
            bias = unwrap(bias, 0.0)
        data[f"{q}_probe_bias"] = (_dims(q), bias)
    probe = scene.probe
    data["probe_nodes"] = ("scene", np.full(scene.shape, probe.nodes if probe else 1,
                                            dtype=np.int32))
    data["probe_quadrature_error"] = ("scene", np.full(
        scene.shape, probe.quadrature_error if probe else 0.0))
    return data


def _beam_coordinates(scene):
    """The beam number and its auxiliary coordinates (:mod:`uq.pipeline.metadata`)."""
    vertical = int(scene.vertical_beam)
    azimuths = list(np.rad2deg(scene.azimuths)) + [np.nan] * vertical
    return {"beam": np.arange(len(azimuths)),
            "beam_azimuth": ("beam", azimuths),
            "beam_vertical": ("beam", [False] * len(scene.azimuths) + [True] * vertical)}


def _paper_uncertainty(scene, settings, gate_speeds):
    """Rubio & Gottschall (2022) u per output; NaN outside their model."""
    ins = settings["ins"]
    u = {key: _standard_uncertainty(ins.get(key)) for key in NAVIGATION}
    u = {key: np.deg2rad(value) if key in ANGULAR_NAVIGATION else value
         for key, value in u.items()}
    per_gate = [rubio2022_scene_uncertainty(scene, gate_speeds[..., i], u["heading"],
                                            u["pitch"], u["roll"], u["sog"], u["cog"])
                for i in range(gate_speeds.shape[-1])]
    return {q: np.stack([g[q] for g in per_gate], axis=-1) if q in per_gate[0]
            else np.full(gate_speeds.shape, np.nan) for q in ALL_OUTPUTS}


def _standard_uncertainty(spec):
    if spec is None:
        return 0.0
    dist = error_distribution(spec)
    return 0.0 if isinstance(dist, float) else moments(dist)[1]


def _assemble(scenario, plan, results):
    """Chunks (flat scenes, group-major) -> the grid, sweep dimensions in file order
    first (each variable's other dimensions after them, in their order), a range of one
    gate squeezed to a scalar coordinate. The variables are laid out in numpy and the
    Dataset built once (xarray's transpose and squeeze rebuild it: ~1 ms each)."""
    first = results[plan.chunks[0].index]
    names = {key: key.replace(".", "_") for key, _ in scenario.sweep}
    grid_dims = tuple(names[k] for k in plan.group_keys + plan.vector_keys)
    grid_shape = plan.group_shape + plan.vector_shape
    order = [names[key] for key, _ in scenario.sweep]
    squeeze = first.sizes.get("range", 0) == 1
    chunks = [results[c.index].variables for c in plan.chunks]
    data = {}
    for var in first.data_vars:
        template = first.variables[var]
        axis = template.dims.index("scene")
        values = np.concatenate([chunk[var].values for chunk in chunks], axis=axis)
        shape = values.shape[:axis] + grid_shape + values.shape[axis + 1:]
        data[var] = _laid_out(template.dims[:axis] + grid_dims + template.dims[axis + 1:],
                              values.reshape(shape), template.attrs, order, squeeze)
    coords = {names[key]: list(values) for key, values in scenario.sweep}
    coords.update({c: _laid_out(first.variables[c].dims, first.variables[c].values,
                                first.variables[c].attrs, order, squeeze)
                   for c in first.coords})
    coords.update({follower.replace(".", "_"): (names[leader], list(dict(scenario.sweep)[leader]))
                   for follower, leader in scenario.links})
    return _annotate(xr.Dataset(data, coords=coords), scenario)


def _laid_out(dims, values, attrs, order, squeeze):
    """A Variable of `values` with the dimensions of `order` first (as xarray's
    ``transpose(*order, ...)``) and, with `squeeze`, without its ``range`` axis of one
    (as ``squeeze("range")``)."""
    dims = tuple(dims)
    if squeeze and "range" in dims:
        values = np.take(values, 0, axis=dims.index("range"))
        dims = tuple(d for d in dims if d != "range")
    laid = [d for d in order if d in dims] + [d for d in dims if d not in order]
    if laid != list(dims):
        values = np.transpose(values, [dims.index(d) for d in laid])
    return xr.Variable(tuple(laid), values, attrs)


#: Attributes of the derived outputs.
DERIVED_ATTRIBUTES = {
    "wind_speed_motion_ti": {"units": "1", "long_name": "motion-induced turbulence-intensity "
                             "increment: Monte Carlo u of the horizontal wind speed from the "
                             "platform motion alone, over the true speed"},
    "wind_speed_motion_ti_gum": {"units": "1", "long_name": "motion-induced turbulence-"
                                 "intensity increment from the motion inputs' share of the "
                                 "GUM variance, over the true speed"},
}


#: Attributes of the probe's quadrature variables.
PROBE_ATTRIBUTES = {
    "probe_nodes": {"units": "1", "long_name": "Gauss-Legendre nodes per beam and range gate "
                    "of the probe-volume quadrature (1: a point probe)"},
    "probe_quadrature_error": {"units": "1", "long_name": "relative error of the probe "
                               "quadrature at the nominal geometry, against a 128-node rule"},
}


def _annotate(ds, scenario):
    # attributes set on the Variables in place (ds[name] would build a DataArray each)
    for name in ds.data_vars:
        quantity = next((q for q in QUANTITIES if name.startswith(q + "_")), None)
        if name in DERIVED_ATTRIBUTES:
            ds.variables[name].attrs.update(DERIVED_ATTRIBUTES[name])
        elif name in records.RECORD_ATTRIBUTES:
            ds.variables[name].attrs.update(records.RECORD_ATTRIBUTES[name])
        elif name in records.SPECTRA_ATTRIBUTES:
            ds.variables[name].attrs.update(records.SPECTRA_ATTRIBUTES[name][2])
        elif quantity:
            ds.variables[name].attrs.update(
                variable_attributes(quantity, name[len(quantity) + 1:]))
    ds.variables["mc_n_samples"].attrs.update(units="1", long_name="Monte Carlo trials used")
    for name, attrs in PROBE_ATTRIBUTES.items():
        if name in ds.variables:
            ds.variables[name].attrs.update(attrs)
    ds.variables["mc_stopped_by"].attrs.update(  # a CF flag variable (CF 1.10, 3.5)
        units="1", long_name="what stopped Monte Carlo sampling",
        flag_values=np.arange(len(STOPPED_BY), dtype=np.int8),
        flag_meanings=" ".join(name.replace(" ", "_") for name in STOPPED_BY))
    for quantity in QUANTITIES:
        for name, links in ancillary_variables(ds, quantity).items():
            ds.variables[name].attrs["ancillary_variables"] = links
    for name, attrs in COORDINATES.items():
        if name in ds.coords:
            ds.variables[name].attrs.update(attrs)
    if "record_frequency" in ds.coords:
        ds.variables["record_frequency"].attrs.update(records.FREQUENCY_ATTRIBUTES)
    for key, _ in scenario.sweep:
        ds.variables[key.replace(".", "_")].attrs.update(swept_key_attributes(key))
    for follower, leader in scenario.links:
        ds.variables[follower.replace(".", "_")].attrs.update(
            swept_key_attributes(follower, linked_to=leader))
    return cf_encode(ds)


def _model_attribute(choice):
    """The ``model`` attribute: said where the numpy model ran (none: compiled)."""
    if choice.model == "numpy":
        return {"model": "numpy: the numpy reference model throughout (uq run --model "
                         "numpy)"}
    if choice.numpy_chunks:
        return {"model": f"numpy for {choice.numpy_chunks} of {choice.chunks} chunks: "
                         "numba's cache did not hold the compiled model's kernels "
                         f"({choice.missing}; uq run --model auto); the same numbers "
                         "to 1e-12"}
    return {}


def _global_attributes(scenario, seed, dataset, started, choice):
    return {"title": f"uq results: {scenario.name}",
            "skipped": skipped_work(scenario.settings, scenario.outputs,
                                    dict(scenario.sweep).get("lidar.probe.kind", ())),
            "Conventions": "CF-1.10",
            "history": history(f"uq run, scenario {scenario.name}"),
            "scenario": scenario.text,
            "uq_version": __version__,
            "sampling_method": scenario.sampling["method"],
            "n_samples": int(np.max(dataset["mc_n_samples"].values)),
            "scenes": int(dataset["mc_n_samples"].size),
            "seed": seed,
            "correction": _swept_or(scenario, "correction", scenario.settings["correction"]),
            "correction_description": describe_corrections(
                dict(scenario.sweep).get("correction", (scenario.settings["correction"],))),
            "ins_correlation": _swept_or(scenario, "ins.correlation",
                                         scenario.settings["ins"]["correlation"]),
            "runtime_s": time.perf_counter() - started, **_probe_attributes(scenario),
            **_model_attribute(choice)}


def _swept_or(scenario, key, value):
    """A global attribute of a scenario key: its value, or "swept: a, b, c" where the
    sweep varies it (its coordinate holds the value of each scene)."""
    swept = dict(scenario.sweep).get(key)
    return value if swept is None else "swept: " + ", ".join(str(v) for v in swept)


def _probe_attributes(scenario):
    """``probe``: the probe model in words, with the truncation of the CW Lorentzian
    (part of the model: its variance is infinite); ``probe_truncation`` [1] when a CW
    probe runs; nothing for a scenario without ``lidar.probe``."""
    lidar = scenario.settings["lidar"]
    if "probe" not in lidar:
        return {}
    swept = dict(scenario.sweep).get("lidar.probe.kind", ())
    attributes = {"probe": probesection.describe(scenario.settings, swept)}
    kinds = set(swept) or {lidar["probe"]["kind"]}
    if "cw" in kinds:
        attributes["probe_truncation"] = lidar["probe"]["truncation"]
    return attributes
