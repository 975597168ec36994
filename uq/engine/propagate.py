"""Model-agnostic propagation of distributions: Monte Carlo (JCGM 101) beside the GUM.

:func:`propagate` works for any vectorised model of named inputs. The lidar pipeline is
one such model (:mod:`uq.pipeline`); there is no second code path.

References
----------
.. [1] JCGM 101:2008, Supplement 1 to the GUM - Propagation of distributions using a
   Monte Carlo method: 7.7 (coverage intervals), 7.9 (adaptive procedure), 8
   (validation of the GUM framework).
"""
import logging
import sys
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import xarray as xr

from uq.engine import controlvariate

from uq.engine import gum
from uq.constants import (ADAPTIVE_MAX_SAMPLES, BATCH_SIZE, COVERAGE_PROBABILITY,
                        DEFAULT_BLOCKS_PER_CHUNK, DEFAULT_DIGITS, FULL_CIRCLE_DEG,
                        MIN_STANDARD_ERROR_BATCH, MODEL_SLICE_VALUES, RNG_BLOCK_SIZE,
                        STANDARD_ERROR_BATCHES, VALIDATION_TOLERANCE_FRACTION)
from uq.engine.inputs import input_set
from uq.engine.sampling import PROPAGATION_METHODS, new_seed, normal_scores
from uq.engine.stopping import STOPPING_RULES, coverage_factor, gum_validated, may_stop
from uq.engine.statistics import (INTERVALS, CoMoments, Moments, StreamingStatistics,
                                  tail_capacity)

_BATCH_KEYS = ("mean", "u", "low", "high")


log = logging.getLogger(__name__)


def propagate(model, inputs, *, n=None, digits=None, method="mc", seed=None,
              correlation=None, circular=(), output_dims=None, interval="symmetric",
              chunk_size=None, control_variate=False, stopping="jcgm101", covariance=(),
              stop_when_gum_valid=False, auxiliary=(), compiled=True):
    """Propagate input distributions through `model` by Monte Carlo and by the GUM.

    Parameters
    ----------
    model : callable
        ``model(**arrays)``: every input by name as an array of shape (n, *shape);
        returns an array of shape (n, ...) or a dict of them (a single array is named
        ``y``). Must be complex-step safe for the GUM (:mod:`uq.engine.gum`). It is
        called on slices of ~MODEL_SLICE_VALUES random values (its temporaries stay in
        the cache), or once per chunk if it has the attribute ``whole_chunks = True``
        (a model that blocks its own trials; the results are the same).
    inputs : dict
        name -> scipy.stats frozen distribution, float (a constant) or
        :class:`uq.engine.inputs.Input` (a distribution with a shape).
    n : int, optional
        Number of Monte Carlo trials.
    digits : int, optional
        Instead of `n`: adaptive sampling until mean, u and both interval endpoints are
        stable to this many significant digits of u (JCGM 101, 7.9). Also the digits of
        the GUM validation (default 2). With neither `n` nor `digits`, adaptive with 2.
    method : {"mc", "lhs", "sobol", "none"}
        Sampler (:mod:`uq.engine.sampling`); ``none`` skips Monte Carlo (GUM results only).
    seed : int, numpy.random.Generator or None
        Same seed, same result, whatever `chunk_size`. None draws fresh entropy; the
        seed used is recorded in the result's ``seed`` attribute.
    correlation : dict, optional
        ``{(name_a, name_b): rho}`` between scalar inputs (Gaussian copula).
    circular : iterable of str
        Outputs that are angles in degrees, period 360 (statistics on the circle).
    output_dims : dict, optional
        Output name -> dimension names of one sample of it.
    interval : {"symmetric", "shortest"}
        Probabilistically symmetric (default) or shortest 95 % coverage interval.
    chunk_size : int, optional
        Samples evaluated at once (rounded up to whole RNG blocks); bounds memory.
    stopping : {"jcgm101", "confident"}
        Stopping rule of adaptive sampling (:mod:`uq.engine.stopping`): JCGM 101 7.9, or a
        rule that stops too early with probability at most 5 %.
    stop_when_gum_valid : bool
        Adaptive sampling for validating the GUM: Monte Carlo runs to a fifth of the
        tolerance of `digits` (JCGM 101 8.2), but stops as soon as the clause 8
        validation of every output's GUM interval is decided in its favour despite the
        Monte Carlo noise (:func:`uq.stopping.gum_validated`); a scene whose GUM fails
        gets the full precision. The attribute ``stopped_by`` says which rule stopped
        the run (``digits``, ``gum validated``, ``sample limit``, ``fixed n``).
    control_variate : bool
        Use the GUM linearisation as a control variate for the mean and u
        (:mod:`uq.engine.controlvariate`); the coverage interval stays plain Monte Carlo.
    covariance : iterable of str
        Outputs whose covariance along their last axis (e.g. between range gates) is
        kept: ``q_mc_covariance`` (complete trials; plain Monte Carlo, no control
        variate) and ``q_gum_covariance`` (J V J^T), last dimension ``<dim>_other``.
    auxiliary : iterable of str
        Outputs of the model of which only the Monte Carlo mean and u are kept
        (``q_mc_mean``, ``q_mc_u``; plain Monte Carlo from the same trials, merged batch by
        batch as the others): they take no part in the GUM, the stopping rule, the
        coverage interval, the control variate or the validation. The model may leave
        them out of a call with complex inputs (the GUM's).
    compiled : bool
        The statistics' compiled loops (numba, :mod:`uq.engine.statkernels`; default),
        or False: the same statistics in numpy (:mod:`uq.engine.statnumpy`, equal to
        rounding), nothing compiled.

    Returns
    -------
    xarray.Dataset
        For each output q: ``q_mc_mean``, ``q_mc_u``, ``q_mc_low``, ``q_mc_high``,
        ``q_mc_n_invalid`` (non-finite trials, excluded), ``q_mc_numerical_error``
        (the largest standard error of mean, u and the endpoints times
        max(2, t_{0.975}(h - 1)): JCGM 101 7.9's 2 s where the h batches are many,
        Student's t where they are few), ``q_gum_value`` (model at the
        input means), ``q_gum_u``, ``q_gum_valid`` (clause 8), ``q_gum_validation_conclusive`` (the Monte Carlo
        numerical error is within the tolerance of clause 8, so the verdict is not
        decided by sampling noise), ``q_budget`` (dimension
        ``input``), ``q_mc_u_standard_error`` (standard error of ``q_mc_u`` from its
        spread over independent batches, :func:`standard_error_batch`),
        ``q_mc_numerical_tolerance``
        (delta of the requested digits, JCGM 101 7.9.2); circular outputs also
        ``q_mc_circular_std``.

    Examples
    --------
    The sum of two independent normal errors of 1 and 2: u = sqrt(5) = 2.236 by the
    GUM (exact for a linear model), and the Monte Carlo u agrees within its own
    standard error (0.005 at 10^5 trials):

    >>> from scipy import stats
    >>> import uq
    >>> result = uq.propagate(lambda a, b: a + b,
    ...                       {"a": stats.norm(0, 1), "b": stats.norm(0, 2)},
    ...                       n=100_000, seed=2)
    >>> round(float(result["y_gum_u"]), 4)
    2.2361
    >>> abs(float(result["y_mc_u"]) - 5 ** 0.5) < 5 * float(result["y_mc_u_standard_error"])
    True
    """
    _check_arguments(n, digits, method, interval, stopping)
    if stop_when_gum_valid and n is not None:
        raise ValueError("stop_when_gum_valid needs adaptive sampling (digits), not a fixed n")
    seed = _entropy(seed)
    inputs_laid = input_set(inputs, correlation)
    circular = set(circular)
    wrapped = _named_outputs(model)
    auxiliary = tuple(auxiliary)
    main = _without(wrapped, auxiliary)
    try:
        gum_value, jacobian = gum.complex_step_jacobian(main, inputs_laid)
        gum_note = "exact Jacobian by complex-step differentiation"
    except gum.NotComplexStepSafe as error:
        gum_value, jacobian = _no_gum(main, inputs_laid)
        gum_note = f"no GUM: {error}"
    references = {q: _circular_reference(gum_value[q]) if q in circular else None
                  for q in gum_value}
    runner = _Runner(wrapped, inputs_laid, method, seed, references, interval, chunk_size,
                     covariance, auxiliary, compiled)
    if set(covariance) & circular:
        raise ValueError(f"no covariance of circular outputs: {sorted(set(covariance) & circular)}")
    if control_variate:
        if gum_note.startswith("no GUM"):
            raise ValueError(f"the control variate needs the GUM Jacobian, and there is {gum_note}")
        runner.control = {q: (jacobian[q], gum.combined_uncertainty(jacobian[q], inputs_laid))
                          for q in jacobian}
    if method != "none" and n is not None:
        runner.run_fixed(int(n))
    elif method != "none":
        targets = None
        if stop_when_gum_valid and not gum_note.startswith("no GUM"):
            targets = {q: (gum_value[q], gum.combined_uncertainty(jacobian[q], inputs_laid),
                           q in circular) for q in gum_value}
        runner.run_adaptive(digits or DEFAULT_DIGITS, stopping, targets)
    validation_digits = digits or DEFAULT_DIGITS
    gum_results = _gum_variables(gum_value, jacobian, inputs_laid, output_dims or {})
    data = {**gum_results, **_gum_covariances(jacobian, inputs_laid, gum_results, covariance)}
    if runner.stats is not None:
        data.update(_mc_variables(runner, gum_results, circular, validation_digits))
        data.update(_mc_covariances(runner, gum_results))
        data.update(_auxiliary_variables(runner, output_dims or {}))
    else:
        data.update(_not_validated(gum_results))
    # one Dataset of every variable (each assign of xarray's is a merge: ~1 ms)
    dataset = xr.Dataset(data, coords={"input": list(inputs_laid.names)})
    dataset.attrs.update(n_samples=runner.n_done, seed=seed, sampling_method=method,
                         digits=validation_digits, interval=interval,
                         coverage_probability=COVERAGE_PROBABILITY, gum=gum_note,
                         control_variate=int(bool(runner.control)),
                         stopping_rule=stopping if n is None and method != "none" else "fixed n",
                         stopped_by=runner.stopped_by)
    return dataset


def _no_gum(model, inputs):
    """NaN GUM results (shapes from one real evaluation) for models that are not
    complex-step safe."""
    means = {name: value[None] for name, value in inputs.means().items()}
    outputs = model(**means, **inputs.constants)
    value = {q: np.full(np.shape(v)[1:], np.nan) for q, v in outputs.items()}
    return value, {q: np.full((inputs.dimension,) + np.shape(v)[1:], np.nan)
                   for q, v in outputs.items()}


def _without(model, names):
    """`model` without the outputs `names` (the GUM's model: no auxiliary outputs)."""
    if not names:
        return model

    def main(**arrays):
        return {q: v for q, v in model(**arrays).items() if q not in names}
    main.whole_chunks = model.whole_chunks
    return main


def _circular_reference(value):
    """Unwrapping reference of a circular output: the GUM value, or north if unknown."""
    return np.where(np.isfinite(value), value, 0.0)


def _check_arguments(n, digits, method, interval, stopping):
    if n is not None and digits is not None:
        raise ValueError("give either n or digits, not both")
    if n is not None and int(n) < 2:
        raise ValueError(f"n must be >= 2, got {n}")
    if digits is not None and not 1 <= int(digits) <= 6:
        raise ValueError(f"digits must be an integer from 1 to 6, got {digits}")
    if method not in PROPAGATION_METHODS:
        raise ValueError(f"method must be one of {PROPAGATION_METHODS}, got {method!r}")
    if interval not in INTERVALS:
        raise ValueError(f"interval must be one of {INTERVALS}, got {interval!r}")
    if stopping not in STOPPING_RULES:
        raise ValueError(f"stopping must be one of {STOPPING_RULES}, got {stopping!r}")


def _entropy(seed):
    if seed is None:
        return new_seed()
    if isinstance(seed, np.random.Generator):
        return int(seed.integers(2**63))
    return int(seed)


def _named_outputs(model):
    def wrapped(**arrays):
        out = model(**arrays)
        return out if isinstance(out, dict) else {"y": out}
    wrapped.whole_chunks = bool(getattr(model, "whole_chunks", False))
    return wrapped


def model_slice_size(dimension):
    """Trials per model call: about MODEL_SLICE_VALUES random values, a power of two
    from 2^10 to RNG_BLOCK_SIZE. Small enough that the model's intermediate arrays stay
    in the cache, large enough that numpy's per-call overhead stays small."""
    size = 2 ** int(np.log2(max(MODEL_SLICE_VALUES // max(dimension, 1), 1)))
    return int(np.clip(size, 2**10, RNG_BLOCK_SIZE))


def standard_error_batch(n, method="mc"):
    """Trials per batch of the standard errors of a fixed-n run: BATCH_SIZE, or the
    largest power of two that gives STANDARD_ERROR_BATCHES batches of n trials (not
    below MIN_STANDARD_ERROR_BATCH). lhs and sobol: whole RNG blocks (within a block the
    points are not independent); they have few batches, and Student's t then."""
    if method != "mc":
        return RNG_BLOCK_SIZE
    size = 2 ** int(np.floor(np.log2(max(n // STANDARD_ERROR_BATCHES, 1))))
    return int(np.clip(size, MIN_STANDARD_ERROR_BATCH, BATCH_SIZE))


def _joined(pieces):
    """Dicts of arrays, joined along the trials."""
    if len(pieces) == 1:
        return pieces[0]
    return {q: np.concatenate([p[q] for p in pieces]) for q in pieces[0]}


def _in_dask_worker():
    """Whether this code runs in a task of a dask worker."""
    distributed = sys.modules.get("distributed")
    if distributed is None:
        return False
    try:
        distributed.get_worker()
    except ValueError:
        return False
    return True


class _Accumulator:
    """A fixed-n run's statistics accumulated on a thread of their own, piece after
    piece in the order given, while the model evaluates the next piece (the statistics'
    compiled kernels and numpy's loops run without the GIL): the same merges in the same
    order as in the run's own thread, so the same bits. At most one piece waits (its
    outputs are the model's, made anew each call). Where this process may use one CPU,
    or is a dask worker (one thread a worker: a cluster's cores are its workers'), the
    pieces are accumulated in the caller's thread."""

    def __init__(self, runner):
        self.runner, self.pool, self.pending = runner, None, None

    def __enter__(self):
        from uq.cpus import usable_cpus
        if usable_cpus() > 1 and not _in_dask_worker():
            self.pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="uq-statistics")
        return self

    def add(self, outputs, linear):
        """Accumulate a piece (after the previous one)."""
        if self.pool is None:
            self.runner._accumulate(outputs, linear)
            return
        submitted = self.pool.submit(self.runner._accumulate, outputs, linear)
        self.wait()                          # the one before: one piece waits at most
        self.pending = submitted

    def wait(self):
        """Until every piece given is accumulated (its error raised here)."""
        if self.pending is not None:
            pending, self.pending = self.pending, None
            pending.result()

    def __exit__(self, kind, error, trace):
        try:
            if kind is None:
                self.wait()
        finally:
            if self.pool is not None:
                self.pool.shutdown(wait=True, cancel_futures=True)
        return False


class _Runner:
    """Draws blocks, evaluates the model chunk by chunk, accumulates statistics."""

    def __init__(self, model, inputs, method, seed, references, interval, chunk_size,
                 covariance=(), auxiliary=(), compiled=True):
        self.model, self.inputs, self.method, self.seed = model, inputs, method, seed
        self.references, self.interval = references, interval
        blocks = DEFAULT_BLOCKS_PER_CHUNK if chunk_size is None else -(-int(chunk_size) // RNG_BLOCK_SIZE)
        self.blocks_per_chunk = max(1, blocks)
        # independent batches: within an lhs or sobol block the points are not independent
        self.batch_size = BATCH_SIZE if method == "mc" else RNG_BLOCK_SIZE
        # batches of the summaries (standard errors, stopping): the moments' batches,
        # or smaller ones in a fixed-n run (standard_error_batch)
        self.summary_size = self.batch_size
        self.stats, self.batches, self.n_done = None, {}, 0
        self.stopped_by = "fixed n"
        self.control, self.linear = None, {}
        self.covariance, self.comoments = tuple(covariance), {}
        self.auxiliary, self.moments = tuple(auxiliary), {}
        self.compiled = compiled                     # the statistics' loops

    def _start(self, capacity, shapes, expected=None):
        self.moments = {q: Moments(shapes[q]) for q in self.auxiliary}
        shapes = {q: shape for q, shape in shapes.items() if q not in self.auxiliary}
        self.stats = {q: StreamingStatistics(shape, capacity, self.references[q],
                                             expected=expected, compiled=self.compiled)
                      for q, shape in shapes.items()}
        self.batches = {q: {key: [] for key in _BATCH_KEYS} for q in shapes}
        self.linear = {q: Moments(shape) for q, shape in shapes.items()}
        self.comoments = {q: CoMoments(shapes[q], self.compiled) for q in self.covariance}

    def _pieces(self, first_block, n_blocks, n_samples, drawn=None):
        """Outputs (and linear deviations, with a control variate) of n_samples trials
        from the blocks first_block .., in pieces to accumulate. A model that blocks its
        own trials (``whole_chunks``, e.g. a compiled loop) is called once per statistics
        batch, and each batch is yielded while its outputs are still in the cache; any
        other model's slices are joined into one piece per chunk (batches may span its
        slices). `drawn`: the chunk's inputs, already made (:meth:`_drawn`)."""
        if drawn is None:
            drawn = self._drawn(first_block, n_blocks, n_samples)
        whole = self.model.whole_chunks
        pieces, linear = [], []
        for values, size in drawn:
            pieces.append(self._model(values, size))
            if self.control:
                columns = controlvariate.input_columns(values, self.inputs)
                linear.append({q: controlvariate.linear_deviation(self.control[q][0], columns)
                               for q in pieces[-1] if q not in self.auxiliary})
            if whole:
                yield pieces.pop(), (linear.pop() if self.control else None)
        if not whole:
            yield _joined(pieces), (_joined(linear) if self.control else None)

    def _drawn(self, first_block, n_blocks, n_samples):
        """The inputs of the chunk, ``[(values, size), ...]`` per model slice (a
        statistics batch for a self-blocking model): the normal scores of the blocks
        first_block .. (the last block only as far as needed), turned into input values
        in place, slice by slice."""
        scores = np.empty((n_samples, self.inputs.dimension))
        for k in range(n_blocks):
            rows = min(RNG_BLOCK_SIZE, n_samples - k * RNG_BLOCK_SIZE)
            normal_scores(self.method, self.seed, first_block + k, self.inputs.dimension,
                          out=scores[k * RNG_BLOCK_SIZE:k * RNG_BLOCK_SIZE + rows], rows=rows)
        step = self.batch_size if self.model.whole_chunks else \
            model_slice_size(self.inputs.dimension)
        return [(self.inputs.values(scores[start:start + step], overwrite=True),
                 min(step, n_samples - start)) for start in range(0, n_samples, step)]

    def _model(self, values, size):
        """The model on one slice of `size` trials; slices start on block boundaries, so
        they do not depend on the chunk size."""
        with np.errstate(all="ignore"):           # out-of-domain trials become NaN, counted
            outputs = self.model(**values, **self.inputs.constants)
        # outputs that do not depend on any random input may come back with one row
        outputs = {q: np.real(np.asarray(v, dtype=float)) for q, v in outputs.items()}
        return {q: v if len(v) == size else np.broadcast_to(v, (size,) + v.shape[1:])
                for q, v in outputs.items()}

    def _accumulate(self, outputs, linear):
        """Statistics batch by batch; chunks start on block boundaries, so the sequence of
        floating-point merges, and the result, is the same for every chunk size."""
        for q, values in outputs.items():
            if q in self.moments:                 # auxiliary: the moments alone
                for start in range(0, len(values), self.batch_size):
                    self.moments[q].update(values[start:start + self.batch_size])
                continue
            summaries = self.stats[q].add(values, self.batch_size, summarize=True,
                                          kind=self.interval, summary_size=self.summary_size)
            if q in self.comoments or linear is not None:
                for start in range(0, len(values), self.batch_size):
                    batch = values[start:start + self.batch_size]
                    if q in self.comoments:
                        self.comoments[q].update(batch)
                    if linear is not None:
                        self.linear[q].update(linear[q][start:start + self.batch_size],
                                              np.isfinite(batch))
            size = self.summary_size
            for start, summary in summaries:
                if linear is not None:
                    batch = values[start:start + size]
                    summary.update(self._controlled(q, summary, batch,
                                                    linear[q][start:start + size]))
                for key in _BATCH_KEYS:
                    self.batches[q][key].append(summary[key])
        self.n_done += len(next(iter(outputs.values())))

    def _controlled(self, q, summary, batch, lin):
        """Control-variate mean and u of one batch (:mod:`uq.engine.controlvariate`)."""
        variance, mean = controlvariate.masked_variance(lin, np.isfinite(batch))
        return {"mean": summary["mean"] - mean,
                "u": controlvariate.controlled_u(self.control[q][1], summary["u"] ** 2, variance)}

    def result(self, q):
        """Final statistics of output q, with the control variate applied to mean and u."""
        result = self.stats[q].result(kind=self.interval)
        if self.control:
            moments = self.linear[q]
            result["u"] = self.u(q)
            result["mean"] = result["mean"] - moments.mean
            if self.references[q] is not None:
                result["mean"] = np.mod(result["mean"], FULL_CIRCLE_DEG)
        return result

    def u(self, q):
        """u of output q so far (control variate applied), from the moments alone: no
        coverage interval (its order statistics cost a pass over every kept value)."""
        u = np.sqrt(self.stats[q].moments.variance())
        if self.control:
            u = controlvariate.controlled_u(self.control[q][1], u ** 2,
                                            self.linear[q].variance())
        return u

    def u_standard_error(self, q):
        """Standard error of u from its spread over the h independent batches (NaN < 2)."""
        h = len(self.batches[q]["u"])
        if h < 2:
            return np.full(self.stats[q].shape, np.nan)
        return np.std(np.array(self.batches[q]["u"]), axis=0, ddof=1) / np.sqrt(h)

    def run_fixed(self, n):
        """n trials, chunk by chunk; the next chunk's inputs are drawn and made in a
        second thread while this one is evaluated (numpy's generators and ufuncs, and the
        compiled kernels, run without the GIL).
        Each block has its own generator and the chunks are accumulated in order, so the
        result is the same as drawing them in turn (and for any chunk size)."""
        total_blocks = -(-n // RNG_BLOCK_SIZE)
        self.summary_size = standard_error_batch(n, self.method)
        chunks = [(first, min(self.blocks_per_chunk, total_blocks - first),
                   min(n - first * RNG_BLOCK_SIZE, self.blocks_per_chunk * RNG_BLOCK_SIZE))
                  for first in range(0, total_blocks, self.blocks_per_chunk)]
        if len(chunks) == 1:                 # nothing to draw ahead: no second thread
            self._fixed_chunk(chunks[0], n)
            return
        with ThreadPoolExecutor(max_workers=1, thread_name_prefix="uq-draws") as drawer, \
                _Accumulator(self) as accumulator:
            pending = drawer.submit(self._drawn, *chunks[0])
            for index, chunk in enumerate(chunks):
                drawn = pending.result()
                if index + 1 < len(chunks):
                    pending = drawer.submit(self._drawn, *chunks[index + 1])
                self._fixed_chunk(chunk, n, drawn, accumulator)

    def _fixed_chunk(self, chunk, n, drawn=None, accumulator=None):
        """Evaluate and accumulate one chunk of a run of n trials (`drawn`: its inputs,
        made ahead, else made here; `accumulator`: an :class:`_Accumulator` that
        accumulates each piece on its thread, else here)."""
        for outputs, linear in self._pieces(*chunk, drawn):
            if self.stats is None:
                self._start(tail_capacity(n, kind=self.interval) + 1,
                            {q: v.shape[1:] for q, v in outputs.items()}, expected=n)
            if accumulator is None:
                self._accumulate(outputs, linear)
            else:
                accumulator.add(outputs, linear)

    def run_adaptive(self, digits, stopping="jcgm101", gum_targets=None):
        """JCGM 101:2008, 7.9.4: batches of M >= 10^4 trials, one RNG block per step, until
        the stopping rule (:mod:`uq.engine.stopping`) is met, the GUM is validated (with
        `gum_targets`: output -> (GUM value, GUM u, circular)) or ADAPTIVE_MAX_SAMPLES is
        reached."""
        block = 0
        while True:
            for outputs, linear in self._pieces(block, 1, RNG_BLOCK_SIZE):
                if self.stats is None:
                    self._start(tail_capacity(ADAPTIVE_MAX_SAMPLES, kind=self.interval) + 1,
                                {q: v.shape[1:] for q, v in outputs.items()})
                self._accumulate(outputs, linear)
            block += 1
            # validating the GUM: Monte Carlo to delta/5 (JCGM 101 8.2), unless the GUM
            # is validated beyond the noise first
            fraction = VALIDATION_TOLERANCE_FRACTION if gum_targets else 1.0
            if self._stable(digits, stopping, check=block, fraction=fraction):
                self.stopped_by = "digits"
            elif gum_targets and self._gum_decided(gum_targets, digits, stopping, block):
                self.stopped_by = "gum validated"
            elif self.n_done + RNG_BLOCK_SIZE > ADAPTIVE_MAX_SAMPLES:
                self.stopped_by = "sample limit"
            else:
                continue
            return

    def _gum_decided(self, targets, digits, stopping, check):
        """Every output's GUM interval validated beyond the Monte Carlo noise."""
        for q, (value, u, circular) in targets.items():
            if circular and not np.all(gum.interval_within_circle(u)):
                return False                        # cannot be validated (clause 8)
            result = self.result(q)
            differences = gum.endpoint_differences(value, u, result["low"], result["high"],
                                                   circular)
            endpoints = tuple(np.array(self.batches[q][key]) for key in ("low", "high"))
            if not gum_validated(stopping, differences, endpoints,
                                 gum.numerical_tolerance(u, digits), check):
                return False
        return True

    def _stable(self, digits, stopping, check, fraction=1.0):
        """Every output's mean, u and endpoints stable to `fraction` of the tolerance of
        `digits` under the rule."""
        return all(may_stop(stopping, [np.array(self.batches[q][key]) for key in _BATCH_KEYS],
                            fraction * gum.numerical_tolerance(self.u(q), digits),
                            check)
                   for q in self.stats)

    def numerical_error(self, q):
        """2 s of JCGM 101 7.9.4 f), the largest over mean, u and endpoints (NaN < 2 batches)."""
        batches = self.batches[q]
        h = len(batches["mean"])
        if h < 2:
            return np.full(self.stats[q].shape, np.nan)
        spread = [np.std(np.array(batches[key]), axis=0, ddof=1) / np.sqrt(h)
                  for key in _BATCH_KEYS]
        return coverage_factor(h) * np.max(spread, axis=0)


def _gum_variables(gum_value, jacobian, inputs, output_dims):
    """GUM value, u and budget of every output: {name: (dims, values)}."""
    data = {}
    for q, value in gum_value.items():
        dims = tuple(output_dims.get(q, [f"{q}_dim{i}" for i in range(np.ndim(value))]))
        data.update({
            f"{q}_gum_value": (dims, value),
            f"{q}_gum_u": (dims, gum.combined_uncertainty(jacobian[q], inputs)),
            f"{q}_budget": (("input",) + dims, gum.variance_budget(jacobian[q], inputs)),
        })
    return data


def _mc_variables(runner, gum_results, circular, digits):
    """Monte Carlo statistics of every output, and the clause 8 validation of the GUM
    (`gum_results`: :func:`_gum_variables`)."""
    data = {}
    for q, stats in runner.stats.items():
        dims, u_gum = gum_results[f"{q}_gum_u"]
        value = gum_results[f"{q}_gum_value"][1]
        result = runner.result(q)
        error = runner.numerical_error(q)
        delta = gum.numerical_tolerance(u_gum, digits)    # clause 8's delta (JCGM 101 8.2)
        _warn_overflow(q, result)
        data.update({
            f"{q}_mc_mean": (dims, result["mean"]),
            f"{q}_mc_u": (dims, result["u"]),
            f"{q}_mc_low": (dims, result["low"]),
            f"{q}_mc_high": (dims, result["high"]),
            f"{q}_mc_n_invalid": (dims, runner.n_done - result["n_valid"]),
            f"{q}_mc_numerical_error": (dims, error),
            f"{q}_mc_u_standard_error": (dims, runner.u_standard_error(q)),
            f"{q}_mc_numerical_tolerance": (dims, gum.numerical_tolerance(result["u"], digits)),
            f"{q}_gum_valid": (dims, gum.gum_interval_valid(
                value, u_gum, result["low"], result["high"], digits, q in circular)),
            f"{q}_gum_validation_tolerance": (dims, delta),
            f"{q}_gum_validation_conclusive": (dims, error <= delta),
        })
        if q in circular:
            data[f"{q}_mc_circular_std"] = (dims, result["circular_std"])
    return data


def _auxiliary_variables(runner, output_dims):
    """``q_mc_mean`` and ``q_mc_u`` of the auxiliary outputs (NaN below two values)."""
    data = {}
    for q, moments in runner.moments.items():
        dims = tuple(output_dims.get(q, [f"{q}_dim{i}" for i in range(len(moments.shape))]))
        data[f"{q}_mc_mean"] = (dims, np.where(moments.count > 0, moments.mean, np.nan))
        data[f"{q}_mc_u"] = (dims, np.sqrt(moments.variance()))
    return data


def _not_validated(gum_results):
    """Without Monte Carlo (method ``none``) the GUM is not validated: ``q_gum_valid``
    and ``q_gum_validation_conclusive`` are False (present, as every results file has
    them; there is no ``q_mc_u`` to validate against)."""
    data = {}
    for name, (dims, values) in gum_results.items():
        if name.endswith("_gum_u"):
            q, shape = name[:-len("_gum_u")], np.shape(values)
            data[f"{q}_gum_valid"] = (dims, np.zeros(shape, dtype=bool))
            data[f"{q}_gum_validation_conclusive"] = (dims, np.zeros(shape, dtype=bool))
    return data


def _warn_overflow(quantity, result):
    """Say so when finite outputs gave a non-finite u: their squares overflowed (|y| of
    ~1e154 and more). The scenario layer bounds inputs far below (MAX_MAGNITUDE)."""
    with np.errstate(invalid="ignore"):
        overflowed = ~np.isfinite(result["u"]) & np.isfinite(result["mean"]) & \
            (np.asarray(result["n_valid"]) > 1)
    if np.any(overflowed):
        log.warning("%s: the Monte Carlo moments overflowed in %d element(s) (outputs of "
                    "magnitude ~1e154 or more); u there is not an estimate",
                    quantity, int(np.sum(overflowed)))


def _other(dims):
    """Dimensions of a covariance along the last of `dims`."""
    return tuple(dims) + (f"{dims[-1]}_other",)


def _gum_covariances(jacobian, inputs, gum_results, names):
    return {f"{q}_gum_covariance": (_other(gum_results[f"{q}_gum_u"][0]),
                                    gum.output_covariance(jacobian[q], inputs)) for q in names}


def _mc_covariances(runner, gum_results):
    return {f"{q}_mc_covariance": (_other(gum_results[f"{q}_gum_u"][0]), moments.covariance())
            for q, moments in runner.comoments.items()}
