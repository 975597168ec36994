"""The measurement model fused into compiled loops over trials (numba).

:func:`uq.measurement.measurement_model` is written with numpy array operations: every
step (beam vectors, heights, the power law, radial velocities, the correction) makes a
pass over arrays of shape (trials, beams, gates). For plain Monte Carlo those passes,
not the arithmetic, set the speed. This module computes the same quantities trial by
trial in compiled loops (:mod:`uq.physics.fusedkernels`), block by block
(:data:`~uq.constants.FUSED_BLOCK_TRIALS` trials, in the cache), so each trial's
intermediate values stay in registers. What is left is the transcendental functions:
sines and cosines of the angles come from SIMD polynomials, the power law from numpy's
SIMD ``log`` and ``exp`` on the whole block, the direction from numpy's SIMD ``arctan2``.

It is a second, independent implementation of the physics (scalar code, written from
the conventions of :mod:`uq.physics.rotation`, :mod:`uq.physics.beams`, :mod:`uq.physics.wind` and
:mod:`uq.physics.correction`, not from the array code); ``tests/physics/test_fused.py`` checks that the
two agree to 1e-12 for every correction model, error source and output, one INS reading
per scan or per beam (point-wise correction: ``ins.correlation: beam`` and errors with a
``correlation_time``, whose correlation the engine's copula imposes), independent draws
per scene and complex errors (the complex-step GUM Jacobian, in complex arithmetic). The
numpy model stays the reference, and is the model of a time-resolved scan
(:mod:`uq.physics.timeresolved`); :func:`applicable` says when the fused loop is used.

A batch of scenes (a sweep's chunk, a GUM grid) is evaluated in one compiled loop: the
scenes' constants are rows of a table (:func:`scene_table`), the work that depends only
on the draws (the errors' sines and cosines) is done once per block of trials and shared
by every scene that sees those draws; with independent draws per scene each scene has
its own. The truth (true beams, gate heights, power law) is computed once per scene
when no geometry error varies it, else per trial. With a probe volume the truth's
profile is the probe's weighted speed (:mod:`uq.physics.fusedprobe`, per trial where the
probe's parameters have errors); a probe's complex step stays with the numpy model.

Conventions (as in the modules named above): earth frame (north, east, up); ship frame
(bow, starboard, up); body-to-earth ``Rz(heading) Ry(pitch) Rx(roll)``, pitch positive
bow up, roll positive starboard down; beams ``(sin t cos(m + a), sin t sin(m + a), cos t)``;
wind direction "from", clockwise from north; radial velocity positive away from the lidar.

References
----------
.. [1] Rubio, H. and Gottschall, J. (2022). J. Phys.: Conf. Ser. 2362 012034.
.. [2] Lam, S. K., Pitrou, A. and Seibert, S. (2015). Numba: a LLVM-based Python JIT
   compiler. Proc. LLVM-HPC 2015.
"""
import math
import weakref

import numpy as np

from uq.physics import fusedkernels as kernels
from uq.physics import wind as wind_formulas
from uq.physics.beams import beam_unit_vectors, least_squares_operator, slant_distances
from uq.constants import COMPLEX_STEP_COMPILED_MIN_SCENES, FULL_CIRCLE_DEG, FUSED_BLOCK_TRIALS
from uq.physics import modelinputs
from uq.physics.modelinputs import STATIC_COMPILED, Correction
from uq.physics import nacelle
from uq.physics.scene import NACELLE_OUTPUTS, OUTPUTS

#: Outputs the fused loop computes: all of them (a tilted mount's also
#: :data:`~uq.physics.scene.NACELLE_OUTPUTS`).
FUSED_OUTPUTS = OUTPUTS
_INS = tuple(f"ins_{key}" for key in kernels.INS_ORDER)
_GEOMETRY = tuple(f"lidar_{key}" for key in kernels.GEO_ORDER)
_NOISE = "lidar_radial_velocity"
#: The errors of a probe's parameters (``lidar_gate_length`` ...), laid as the geometry's.
_PROBE = ("lidar_gate_length", "lidar_pulse_fwhm", "lidar_wavelength", "lidar_beam_radius")


def applicable(scene, outputs, errors, scene_draws=False):
    """Can the fused loop evaluate this call of the measurement model?

    Every static scene (not time-resolved: that is its own model), every output, real
    (Monte Carlo) or complex (complex-step GUM) errors in the shapes of
    :func:`uq.physics.measurement.measurement_model`: INS errors (n,), (n, 1) or
    (n, beams) (one reading per scan or per beam), geometry errors (n,), radial noise
    (n, beams, gates); with `scene_draws` each with the scene axes after the first.
    """
    return _prepared(scene, outputs, errors, scene_draws) is not None


def declined(scene, outputs, errors, scene_draws=False):
    """Why the compiled model does not take this call, in words ('' where it does): a
    time-resolved scene (a model of its own), an output or an input it does not
    implement, or an input of a shape it does not take (or a probe volume's complex
    step, which the numpy model differentiates)."""
    if scene.time_resolved is not None:
        return "a time-resolved scene"
    mounted = _mounted_decline(scene, outputs, errors)
    if mounted:
        return mounted
    allowed = _outputs_of(scene)
    if not set(outputs) <= allowed:
        return f"output(s) {', '.join(sorted(set(outputs) - allowed))}"
    if any(np.iscomplexobj(v) for v in errors.values()):
        if scene.probe is not None:
            return "a probe volume's complex step (the GUM)"
        if math.prod(scene.shape) < COMPLEX_STEP_COMPILED_MIN_SCENES:
            return (f"a complex step (the GUM) of fewer than "
                    f"{COMPLEX_STEP_COMPILED_MIN_SCENES} scenes")
    lacked = modelinputs.lacks(STATIC_COMPILED, errors)
    if lacked:
        return f"input(s) {', '.join(lacked)}"
    if _prepared(scene, outputs, errors, scene_draws) is None:
        return "an input of a shape it does not take"
    return ""


def _mounted_decline(scene, outputs, errors):
    """Why the compiled model does not take a tilted mount's call ('' where it does, or
    for an upward lidar)."""
    if scene.tilt == 0:
        return ""
    if any(np.iscomplexobj(value) for value in errors.values()):
        return "a tilted mount's complex step (the GUM)"
    if scene.vertical_beam or (scene.horizontal_only and scene.correction == "tilt2d"):
        return "a tilted mount with a vertical beam, or tilt2d on two beams"
    if "shear_exponent" in outputs and nacelle.upper_lower(scene.azimuths) is None:
        return "shear_exponent without an upper and a lower beam"
    return ""


def _outputs_of(scene):
    """The outputs the compiled model computes for `scene`."""
    return _OUTPUT_SET | set(NACELLE_OUTPUTS) if scene.tilt != 0 else _OUTPUT_SET


def _mounted_structure(scene, outputs):
    """The tail of a tilted mount's structure vector (:data:`~uq.physics.fusedkernels.
    MOUNTED_STRUCTURE`): the shear exponent wanted, the level pair, the upper and lower
    beams (-1 where there are none)."""
    pair = None if scene.horizontal_only else nacelle.level_pair(scene.azimuths)
    upper_lower = nacelle.upper_lower(scene.azimuths) if "shear_exponent" in outputs else None
    return [int("shear_exponent" in outputs), *(pair or (-1, -1)), *(upper_lower or (-1, -1))]


def measurement_model(scene, outputs, scene_draws=False, **errors):
    """The fused equivalent of :func:`uq.measurement.measurement_model` (same inputs,
    degrees for angular errors; same outputs, shape (n, *S, n_gates), radial velocity
    (n, *S, n_beams, n_gates)). Complex errors give complex outputs (complex step)."""
    result = evaluate(scene, outputs, scene_draws, errors)
    if result is None:
        raise ValueError(f"the compiled static model does not take this call: "
                         f"{declined(scene, outputs, errors, scene_draws)}")
    return result


def evaluate(scene, outputs, scene_draws, errors):
    """:func:`measurement_model` where :func:`applicable`, else None (one pass over the
    arguments for both: the model is called once per slice of ~2^13 trials)."""
    if scene.tilt != 0 and _mounted_decline(scene, outputs, errors):
        return None
    if scene.probe is not None:             # its node count (the scene itself if chosen)
        from uq.physics import probe as probe_volume
        scene = probe_volume.resolve(scene)
    prepared = _prepared(scene, outputs, errors, scene_draws)
    return None if prepared is None else _run(scene, outputs, scene_draws, *prepared)


def _run(scene, outputs, scene_draws, shape, n, ins, geo, noise, dtype, probe_errors):
    n_gates, n_beams = len(scene.ranges), scene.n_beams
    scenes = math.prod(shape)
    (table, shapes), kept = scene_table(scene, shape)
    mounted = scene.tilt != 0
    directed = "wind_direction" in outputs or "yaw_misalignment" in outputs
    structure = np.array([len(scene.azimuths), int(scene.vertical_beam), n_gates,
                          Correction.of(scene.correction)]
                         + [int(q in outputs or (q == "wind_direction" and directed))
                            for q in OUTPUTS]
                         + (_mounted_structure(scene, outputs) if mounted else []),
                         dtype=np.int64)
    out = {q: np.empty((scenes,) + ((n_beams,) if q == "radial_velocity" else ())
                       + (n_gates, n), dtype=dtype) if q in outputs or (
                           q == "wind_direction" and directed) else _UNUSED[dtype][q]
           for q in OUTPUTS + ("shear_exponent",)}   # element-major: trials contiguous
    from_east = np.empty_like(out["wind_direction"])
    per_trial = any(g.shape[0] > 1 for g in geo) or (     # geometry or probe errors:
        scene.probe is not None and _probe_varies(scene.probe, probe_errors))  # per trial
    block = FUSED_BLOCK_TRIALS
    trials = min(n, block)
    group = max(1, block // trials) if (scene_draws or per_trial) else scenes
    rows = group * trials if scene_draws else trials
    cos_trig = np.empty((4, n_beams, rows), dtype=dtype)
    sin_trig = np.empty_like(cos_trig)
    scratch = np.empty(trials, dtype=dtype)
    truth_rows = group * trials if per_trial else scenes
    compiled = kernels.compiled(dtype)
    pointwise = any(error.shape[2] > 1 for error in ins)   # a reading per beam
    wind = compiled[("wind_mounted_" if mounted else "wind_") +
                    ("pointwise" if pointwise else "scan")]
    more = (out["shear_exponent"],) if mounted else ()
    exponent = np.empty(truth_rows)
    if per_trial:                           # geometry errors: the truth of each trial
        beams = np.empty((truth_rows, n_beams, 3), dtype=dtype)
        profile = np.empty((truth_rows, n_beams, n_gates), dtype=dtype)
    else:                                   # every scene's truth, common to its trials
        beams, profile = _scene_truth(table, shapes, structure, geo, scenes, dtype, kept,
                                      (scene.probe, probe_errors))
    for t0 in range(0, n, trials):
        t1 = min(n, t0 + trials)
        if not scene_draws:                 # the draws' trigonometry, shared by the scenes
            compiled["ins_trig"](ins, table, 0, 1, t0, t1, False, cos_trig, sin_trig, scratch)
        for s0 in range(0, scenes, group):
            s1 = min(scenes, s0 + group)
            if scene_draws:
                compiled["ins_trig"](ins, table, s0, s1, t0, t1, True, cos_trig, sin_trig,
                                     scratch)
            if per_trial:
                _truth(compiled, table, shapes, structure, geo, s0, s1, t0, t1, True, beams,
                       profile, exponent, (scene.probe, probe_errors))
            wind(table, shapes, structure, ins, noise, cos_trig, sin_trig, beams, profile, geo[2],
                 s0, s1, t0, t1, scene_draws, per_trial, out["wind_speed"],
                 out["vertical_wind"], out["wind_direction"], from_east,
                 out["radial_velocity"], out["gate_height"], *more)
    if directed:
        _direction(out["wind_direction"], from_east, out["wind_direction"])
    if "yaw_misalignment" in outputs:       # relative to the rotor axis, the heading
        heading = table[:, kernels.TABLE.index("heading")].reshape(scenes, 1, 1)
        out["yaw_misalignment"] = nacelle.yaw_misalignment(out["wind_direction"], heading)
    # (n, *S, ...) views of the element-major arrays
    return {q: np.moveaxis(out[q], -1, 0).reshape((n,) + shape + out[q].shape[1:-1])
            for q in outputs}


#: Placeholders of the outputs not requested, per dtype (the kernels write nothing there).
_UNUSED = {dtype: {q: np.empty((1, 1, 1) + ((1,) if q == "radial_velocity" else ()), dtype)
                   for q in OUTPUTS + ("shear_exponent",)} for dtype in (float, complex)}


def _scene_truth(table, shapes, structure, geo, scenes, dtype, kept, probe=(None, {})):
    """True beams and profile of every scene (no geometry error varies them over the
    trials). Errors that are constants (absent, or the GUM's real means): computed once
    in float64 and kept with the table (a GUM evaluates the same scenes three times); a
    complex-step call gets an exact complex copy (its geometry is not perturbed, so
    the imaginary parts are zero)."""
    n_beams, n_gates = structure[0] + structure[1], structure[2]
    constant = all(g.shape == (1, 1, 1) and g[0, 0, 0].imag == 0 for g in geo) and \
        all(e.shape == (1, 1, 1) for e in probe[1].values())
    key = tuple(float(g[0, 0, 0].real) for g in geo) + (tuple(
        float(e[0, 0, 0].real) for _, e in sorted(probe[1].items())) if probe[0] else ())
    if constant and key in kept:
        beams, profile = kept[key]
    else:
        real = constant or np.dtype(dtype).kind != "c"
        number = float if real else dtype
        beams = np.empty((scenes, n_beams, 3), dtype=number)
        profile = np.empty((scenes, n_beams, n_gates), dtype=number)
        _truth(kernels.compiled(number), table, shapes, structure,
               tuple(g.real.copy() for g in geo) if real else geo, 0, scenes, 0, 1, False,
               beams, profile, np.empty(scenes), probe)
        if constant:
            kept[key] = (beams, profile)
    if np.dtype(dtype).kind == "c" and beams.dtype.kind != "c":
        if constant and key + ("c",) in kept:
            return kept[key + ("c",)]
        beams, profile = beams.astype(complex), profile.astype(complex)
        if constant:
            kept[key + ("c",)] = (beams, profile)
    return beams, profile


def _truth(compiled, table, shapes, structure, geo, s0, s1, t0, t1, per_trial, beams,
           profile, exponent, probe=(None, {})):
    """True beams and the power-law profile U(z) / U_ref (z / z_ref)^alpha of the rows
    of a rectangle (:func:`uq.physics.fusedkernels.geometry`); the power by
    :func:`uq.physics.fusedkernels.power_near` (float64; a complex step: numpy's log and
    exp); NaN stays NaN (1 where there is no shear: the kernel set it)."""
    mounted = len(structure) == len(kernels.MOUNTED_STRUCTURE)   # a tilted mount's
    compiled["geometry_mounted" if mounted else "geometry"](
        table, shapes, structure, geo, s0, s1, t0, t1, per_trial, beams, profile, exponent)
    rows = (s1 - s0) * ((t1 - t0) if per_trial else 1)
    if probe[0] is not None:                # the weighted speed along the true beams
        _probe_truth(probe, table, shapes, structure, geo[2], s0, s1, t0, t1, per_trial,
                     beams, profile, exponent)
        return
    if not np.any(exponent[:rows]):         # no shear: the kernel set 1 (or NaN) already
        return
    ratio = profile[:rows]
    if ratio.dtype == np.float64 and ratio.flags.c_contiguous:
        # x0^a times a series in d = x / x0 - 1 (~4 ns a value, libm's log and exp ~12)
        compiled["power_near"](ratio.reshape(rows, -1), exponent[:rows])
        return
    np.log(ratio, out=ratio)
    if np.all(exponent[:rows] == exponent[0]):           # one scene's: a scalar product
        ratio *= exponent[0]
    else:
        ratio *= exponent[:rows, None, None]
    np.exp(ratio, out=ratio)


#: Doubles of the probe's node scratch per pass (items x nodes x rows, twice), and the
#: fewest and most rows of a pass (a pass costs ~30 us of calls; see _probe_truth).
PROBE_PASS_VALUES, PROBE_PASS_ROWS = 2**17, (32, 512)


def _probe_varies(probe, probe_errors):
    """Do the errors of the probe's own parameters vary over the trials?"""
    return any(probe_errors[name].shape[0] > 1 for name in probe.PARAMETERS
               if name in probe_errors)


def _probe_truth(probe, table, shapes, structure, height_error, s0, s1, t0, t1, per_trial,
                 beams, profile, exponent):
    """profile[row] = the probe-weighted U / U_ref of every beam and gate of the rows of
    a rectangle (:func:`geometry`'s rows and true beams), by
    :func:`uq.physics.fusedprobe.profile`, in passes of rows whose node scratch stays in
    the L2 cache (:data:`PROBE_PASS_VALUES`)."""
    from uq.physics import fusedprobe
    probe, errors = probe
    n_slanted, n_gates = int(structure[0]), int(structure[2])
    n_beams = n_slanted + int(structure[1])
    _, at_slant, _, _ = kernels.geometry_offsets(n_slanted, n_beams, n_gates)
    count = t1 - t0 if per_trial else 1
    rows = (s1 - s0) * count
    scene = s0 + np.arange(rows) // count                             # each row's
    trial = t0 + np.arange(rows) % count
    shape = table[scene, kernels.TABLE_WIDTH - 1].astype(np.intp)       # geometry row
    slant = shapes[shape, at_slant:at_slant + n_beams * n_gates]       # (rows, b g)
    base = table[scene, kernels.TABLE.index("lidar_height")] + _rows_of(height_error, scene,
                                                                        trial)
    reference = table[scene, kernels.TABLE.index("reference_height")]
    common = np.all(shape == shape[0])
    if common:                               # one geometry: the distinct focus values
        focus, item_focus = fusedprobe.distinct_focus(slant[0])
    else:
        focus, item_focus = None, np.arange(n_beams * n_gates, dtype=np.int64)
    per_pass = int(np.clip(PROBE_PASS_VALUES // (n_beams * n_gates * probe.nodes),
                           *PROBE_PASS_ROWS))
    for a in range(0, rows, per_pass):
        b = min(rows, a + per_pass)
        part = slice(a, b)
        centre = base[part, None] + slant[part] * np.repeat(beams[part, :, 2], n_gates, axis=1)
        vertical = np.repeat(beams[part, :, 2], n_gates, axis=1)
        first, second = (np.ascontiguousarray(_rows_of(errors.get(name), scene[part],
                                                       trial[part]) * scale + value)
                         for name, value, scale in _probe_parameters(probe))
        out = np.empty((n_beams * n_gates, b - a))
        fusedprobe.profile(probe, _compact(first), _compact(second),
                           np.ascontiguousarray(centre.T), np.ascontiguousarray(vertical.T),
                           focus if common else np.ascontiguousarray(slant[part].T),
                           item_focus, _compact(reference[part]), _compact(exponent[part]),
                           out)
        profile[part] = out.T.reshape(b - a, n_beams, n_gates)


def _probe_parameters(probe):
    """(name, configured value [SI], scale of its error) of the probe's parameters."""
    from uq.physics.probe import PARAMETER_SCALE
    return [(name, getattr(probe, name), PARAMETER_SCALE.get(name, 1.0))
            for name in probe.PARAMETERS]


def _rows_of(error, scene, trial):
    """The values of an error (n or 1, scenes or 1, 1) at rows (scene, trial); absent: 0."""
    if error is None:
        return np.zeros(len(scene))
    return error[trial if error.shape[0] > 1 else np.zeros_like(trial),
                 scene if error.shape[1] > 1 else np.zeros_like(scene), 0].real


def _compact(values):
    """A per-row array as (1,) where all rows hold the same value, else contiguous."""
    values = np.asarray(values, dtype=float)
    if values.size and np.all(values == values[0]):
        return values[:1].copy()
    return np.ascontiguousarray(values)


def _direction(from_north, from_east, out):
    """Meteorological direction [deg] in [0, 360) of the "from" vector, into out
    (as :func:`uq.wind.wind_direction`); complex-step safe for complex input."""
    if np.iscomplexobj(from_north):
        out[...] = wind_formulas.wind_direction(-from_north, -from_east)
        return
    np.arctan2(from_east, from_north, out=out)
    np.multiply(out, 180.0 / math.pi, out=out)
    np.add(out, FULL_CIRCLE_DEG, out=out, where=out < 0.0)
    np.subtract(out, FULL_CIRCLE_DEG, out=out, where=out >= FULL_CIRCLE_DEG)   # -1e-17 + 360


def _prepared(scene, outputs, errors, scene_draws):
    """(scene shape, trials, INS, geometry, noise, dtype) of a call the fused loop
    takes, else None. The errors as 3-D arrays (trials, scenes, k) for the kernels, any
    axis of length 1 broadcasting: INS (k = 1 or beams), geometry (k = 1), noise
    (k = beams x gates); complex128 if any error is complex, else float64."""
    if scene.time_resolved is not None or \
            not set(outputs) <= _outputs_of(scene) or \
            not set(errors) <= _ERROR_SET:
        return None
    shape = scene.shape
    scenes = math.prod(shape)
    s_axis = shape if scene_draws else ()
    values = {name: np.asarray(value) for name, value in errors.items() if value is not None}
    dtype = complex if any(v.dtype.kind == "c" for v in values.values()) else float
    if dtype is complex and (scene.probe is not None or
                             scenes < COMPLEX_STEP_COMPILED_MIN_SCENES):
        return None                 # a probe's or a small complex step: the numpy model
    beams, gates = scene.n_beams, len(scene.ranges)
    n = max([v.shape[0] for v in values.values() if v.ndim], default=1)
    laid = {}
    for name, value in values.items():
        if value.ndim == 0:
            laid[name] = np.full((1, 1, 1), value, dtype=dtype)
            continue
        if value.shape[1:1 + len(s_axis)] != s_axis:
            return None
        rest = value.shape[1 + len(s_axis):]
        if name.startswith("ins_"):
            allowed = ((), (1,), (beams,))
        elif name == _NOISE:
            allowed = ((beams, gates),)
        else:
            allowed = ((),)
        if rest not in allowed:
            return None
        k = math.prod(rest)
        array = value.reshape((value.shape[0], scenes if scene_draws else 1, k))
        if array.dtype != dtype or not array.flags.writeable:
            array = array.astype(dtype)
        laid[name] = array
    zero = _ZERO[dtype]
    probe = {name[len("lidar_"):]: laid[name] for name in _PROBE if name in laid}
    return (shape, n, tuple(laid.get(name, zero) for name in _INS),
            tuple(laid.get(name, zero) for name in _GEOMETRY), laid.get(_NOISE, zero), dtype,
            probe)


_OUTPUT_SET = set(FUSED_OUTPUTS)
#: The inputs the compiled static model implements (:mod:`uq.physics.modelinputs`); the
#: kernels' argument order (``INS_ORDER``, ``GEO_ORDER``) names the same inputs (tested).
_ERROR_SET = set(modelinputs.names(STATIC_COMPILED))
#: An absent error: zero, a (1, 1, 1) placeholder per dtype (the kernels only read it).
_ZERO = {float: np.zeros((1, 1, 1)), complex: np.zeros((1, 1, 1), dtype=complex)}


#: Tables of the scenes last evaluated: id -> (weak reference, tables, truths). The
#: engine calls the model many times with the same scene object (per batch of trials;
#: the GUM and the nominal three times); building a table costs ~0.3 ms for one scene.
#: Two are kept: a sweep's chunks come one after the other, and the memory of older ones
#: is then reused (fresh pages cost ~10 us each to fault in on this 2-core VM).
_TABLES = {}
_TABLES_KEPT = 2


def scene_table(scene, shape=None):
    """:func:`make_scene_table`, kept while `scene` (a frozen dataclass) lives; with a
    dict to keep the batch's truth in (:func:`_run`)."""
    kept = _TABLES.get(id(scene))
    if kept is not None and kept[0]() is scene:
        return kept[1], kept[2]
    tables = make_scene_table(scene, shape)
    if len(_TABLES) >= _TABLES_KEPT:
        _TABLES.pop(next(iter(_TABLES)))
    _TABLES[id(scene)] = (weakref.ref(scene), tables, {})
    return tables, _TABLES[id(scene)][2]


def make_scene_table(scene, shape=None):
    """The scenes of a batch as rows of one float table (numba takes no dataclass), and
    the table of their distinct beam geometries, as :mod:`uq.physics.fusedkernels` lays
    them out (``TABLE``, ``TRIG``, :func:`~uq.physics.fusedkernels.geometry_offsets`):
    per scene the scalars, the cos and sin of its angles and the row of its geometry;
    per distinct (half-cone, misalignment) the azimuths' cos and sin, the least-squares
    operator (a pseudo-inverse, ~20 us), the slant distances and the configured beams
    (a GUM grid of 518,400 scenes has 360 of them). Returns (table, geometry)."""
    shape = scene.shape if shape is None else shape
    scenes = math.prod(shape)
    fields = np.empty((len(kernels.TABLE), scenes))
    for row, name in enumerate(kernels.TABLE):
        fields[row] = np.broadcast_to(np.asarray(getattr(scene, name), dtype=float), shape
                                      ).reshape(scenes)
    field = dict(zip(kernels.TABLE, fields))
    azimuths = np.asarray(scene.azimuths, dtype=float)
    n_slanted = len(azimuths)
    key = field["half_cone"] + 1j * field["misalignment"]
    if np.all(key == key[0]):
        distinct, index = key[:1], np.zeros(scenes, dtype=np.intp)
    else:                    # complex numbers sort by real, then imaginary part
        distinct, index = np.unique(key, return_inverse=True)
    units = beam_unit_vectors(distinct.real, azimuths, distinct.imag,
                              scene.vertical_beam, scene.tilt)                 # (u, b, 3)
    if scene.horizontal_only:           # two beams of a tilted mount: w = 0, no A^+
        operator = np.zeros(units.shape[:-2] + (3, units.shape[-2]))
    else:
        operator = least_squares_operator(units)                              # (u, 3, b)
    slant = slant_distances(scene.ranges, distinct.real, n_slanted, scene.vertical_beam)
    u = len(distinct)
    geometry = np.concatenate([np.broadcast_to(np.cos(azimuths), (u, n_slanted)),
                               np.broadcast_to(np.sin(azimuths), (u, n_slanted)),
                               operator.reshape(u, -1), slant.reshape(u, -1),
                               units.reshape(u, -1)]
                              + ([np.full((u, 1), np.cos(scene.tilt)),     # a tilted mount's
                                  np.full((u, 1), np.sin(scene.tilt))] if scene.tilt != 0
                                 else []), axis=1)
    table = np.empty((scenes, kernels.TABLE_WIDTH))
    kernels.fill_table(fields, np.ascontiguousarray(index.reshape(-1), dtype=np.intp), table)
    return table, geometry
