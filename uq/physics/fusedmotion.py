"""The time-resolved measurement model compiled (numba): beams at their own times, the
platform's motion, the INS read at the beams' stamps, point-wise correction.

:mod:`uq.physics.timeresolved` evaluates a scan in motion with numpy array passes over
(trials, beams, dwell nodes, gates, 3) and (..., 3, 3) stacks; this module computes the
same quantities in compiled loops over blocks of trials (:mod:`uq.physics.fusedmotionkernels`),
each loop over the block's trials innermost on rows of scratch that stay in the cache,
so the loops are SIMD code. What is the same for every trial is computed once per scene
(:func:`scene_plan`): the measurement and read times, the sines and cosines of
``w_k t + psi_dk`` there (only the unit phases c_k of the motion vary between trials),
the configured beams and least-squares operator, the slant ranges. Per trial remain the
motion sums, the sines and cosines of the attitude (SIMD polynomials), the rotations and
the least squares; the power law is numpy's SIMD ``log`` and ``exp`` on the block.

It is a second implementation of the physics, written from the conventions of
:mod:`uq.physics.rotation`, :mod:`uq.physics.motion`, :mod:`uq.physics.ins`,
:mod:`uq.physics.timing` and :mod:`uq.physics.correction` (rotations as products of the
elementary ones, the lever-arm velocity by the product rule, the INS time shift as a
turn of the phase vectors, Cholesky for the least squares), not from the array code;
``tests/physics/test_fusedmotion.py`` checks that the two agree to 1e-12 m/s. The numpy
model stays the reference and alone runs complex-step (the GUM Jacobian) and the outputs
``radial_velocity`` and ``gate_height``; a probe volume's quadrature is
:mod:`uq.physics.fusedprobe`'s (on the gate-centre heights kinematics writes);
:func:`applicable` says when
the compiled model is used. A batch of scenes is evaluated scene after scene.

Conventions: those of :mod:`uq.physics.timeresolved` (earth frame north, east, up; ship
frame bow, starboard, up; body-to-earth ``Rz(heading) Ry(pitch) Rx(roll)``; the INS read
at ``t + delta``, sampled at ``offset + i / rate``; its errors added to the Euler angles,
``sog`` along the static course, ``cog`` turning the horizontal velocity).
"""
import collections
import dataclasses
import functools
import math

import numpy as np

from uq.constants import (FULL_CIRCLE_DEG, MOTION_BLOCK_ROW_PAD, MOTION_BLOCK_TRIALS,
                          MOTION_BLOCK_VALUES)
from uq.physics import fusedmotionkernels as kernels
from uq.physics import fusedprobe
from uq.physics import probe as probe_volume
from uq.physics.beams import least_squares_operator, slant_distances
from uq.physics import modelinputs
from uq.physics.modelinputs import MOTION_COMPILED, Correction
from uq.physics import nacelle
from uq.physics.motion import DEGREES_OF_FREEDOM
from uq.physics.rotation import rotation_about_vertical, rotation_pitch, rotation_roll
from uq.physics.scene import HELD_WIND_SPEED, NACELLE_OUTPUTS, SCENE_FIELDS, sample_count
from uq.physics.timing import dwell_frequency

#: Outputs the compiled model computes; any other requested output uses the numpy model.
FUSED_OUTPUTS = ("wind_speed", "wind_direction", "vertical_wind")
_INS_MODES = {None: kernels.CONTINUOUS, "nearest": kernels.NEAREST, "linear": kernels.LINEAR}
#: Inputs per trial (n,) of the geometry.
_GEOMETRY = ("lidar_half_cone", "lidar_misalignment", "lidar_height")
#: Inputs per trial (n,) of a probe's parameters (:mod:`uq.physics.fusedprobe`).
PROBE_INPUTS = fusedprobe.INPUTS


def applicable(scene, outputs, errors, scene_draws=False):
    """Can the compiled model evaluate this call of the time-resolved model?

    A time-resolved scene (with or without a probe volume), only :data:`FUSED_OUTPUTS`, real
    inputs (not the GUM's complex steps) that it implements
    (:data:`uq.physics.modelinputs.MOTION_COMPILED`), in the shapes the pipeline gives:
    INS errors (n,) or (n, k), phases (n, K, 2), radial noise (n, beams, gates) (each
    may also be a scalar or have one row). Any batch of scenes, common draws or
    ``scene_draws``. :func:`declined` says why not.
    """
    return not declined(scene, outputs, errors, scene_draws)


def declined(scene, outputs, errors, scene_draws=False):
    """Why the compiled model does not take this call, in words ('' where it does)."""
    if scene.time_resolved is None:
        return "a static scene"
    allowed = set(FUSED_OUTPUTS) | (set(NACELLE_OUTPUTS) if scene.tilt != 0 else set())
    if not set(outputs) <= allowed:
        return f"output(s) {', '.join(sorted(set(outputs) - allowed))}"
    if scene.horizontal_only and scene.correction == "tilt2d":
        return "tilt2d on two beams of a tilted mount (a 3-D correction)"
    if "shear_exponent" in outputs and nacelle.upper_lower(scene.azimuths) is None:
        return "shear_exponent without an upper and a lower beam"
    lacked = modelinputs.lacks(MOTION_COMPILED, errors)
    if lacked:
        return f"input(s) {', '.join(lacked)}"
    if any(np.iscomplexobj(value) for value in errors.values()):
        return "complex inputs (the GUM's complex steps)"
    dims = len(scene.shape) if scene_draws else 0          # the scene axes of the draws
    for name, value in errors.items():
        ndim = np.ndim(value) - (dims if np.ndim(value) > 1 else 0)
        if ndim > _MOST_AXES[modelinputs.input_named(name).shape] or \
                (ndim and ndim < _LEAST_AXES[modelinputs.input_named(name).shape]):
            return f"input {name} of {ndim} axes"
    return ""


#: Axes (trials first, scene axes not counted) the kernels take per shape of input
#: (:data:`uq.physics.modelinputs.SHAPES`): an INS reading (n,) or (n, k), a draw per
#: scan (n,), noise (n, beams, gates), phases (n, K, 2); 0 (a scalar) is always taken.
_MOST_AXES = {"reading": 2, "scan": 1, "beam_gate": 3, "phase": 3}
_LEAST_AXES = {"reading": 1, "scan": 1, "beam_gate": 3, "phase": 3}


def measurement_model(scene, outputs, scene_draws=False, held=None, **errors):
    """The compiled :func:`uq.physics.timeresolved.measurement_model` (same inputs and
    outputs: each (n, *S, n_gates) for a batch of scenes of shape S, evaluated one scene
    after the other; with `scene_draws` each scene takes its own slice of the inputs).
    `held` (inputs -> scalar): the wind speed of the same trials with these inputs
    replaced, ``wind_speed_held``; where the radial noise alone is held
    (:func:`shares_reading`) a second right-hand side of the same least squares in the
    same reconstruction, else where no input of the truth is held
    (:func:`shares_kinematics`) a second reconstruction per block on the same
    kinematics, else a second evaluation (:data:`HELD_PATHS` counts which)."""
    if scene.probe is not None:             # its node count (the scene itself if chosen)
        scene = probe_volume.resolve(scene)
    shape, gates = scene.shape, len(scene.ranges)
    n = sample_count(errors)
    result = {q: np.empty((n,) + shape + (gates,)) for q in FUSED_OUTPUTS + NACELLE_OUTPUTS
              if q in outputs}
    if held is not None:
        result[HELD_WIND_SPEED] = np.empty((n,) + shape + (gates,))
    layout = _mounted_layout(scene, outputs)           # the batch's beams: one layout
    for index in np.ndindex(*shape):
        mine = errors if not scene_draws else {
            name: value[(slice(None),) + index] if np.ndim(value) > 1 else value
            for name, value in errors.items()}
        into = {q: result[q][(slice(None),) + index] for q in result}      # (n, gates) views
        plan = scene_plan(_scene_at(scene, index))
        if held is None or shares_kinematics(held, mine):
            _evaluate(plan, mine, n, into, scene.probe, layout, held)
        else:
            HELD_PATHS["second evaluation"] += 1
            second = {"wind_speed": into.pop(HELD_WIND_SPEED)}
            _evaluate(plan, mine, n, into, scene.probe, layout)
            _evaluate(plan, {**mine, **held}, n, second, scene.probe, layout)
    return result


def _mounted_layout(scene, outputs):
    """The layout vector of a tilted mount (:data:`~uq.physics.fusedmotionkernels.
    MOUNTED_LAYOUT`), None for an upward lidar."""
    if scene.tilt == 0:
        return None
    upper_lower = nacelle.upper_lower(scene.azimuths) if "shear_exponent" in outputs else None
    return np.array([*(upper_lower or (-1, -1)), int("shear_exponent" in outputs)],
                    dtype=np.int64)


def _level_beams(scene):
    """The beams of a tilted mount's horizontal solve (HEAD ``level_first``,
    ``level_second``): its two beams, or the level pair (clock 90 and 270); (-1, -1)
    for none and for an upward lidar."""
    if scene.tilt == 0:
        return -1, -1
    if scene.horizontal_only:
        return 0, 1
    return nacelle.level_pair(scene.azimuths) or (-1, -1)


#: Inputs of the truth (:func:`uq.physics.fusedmotionkernels.kinematics` and a probe's
#: profile); the others enter the reconstruction alone.
KINEMATIC_INPUTS = _GEOMETRY + PROBE_INPUTS + ("motion_phases", "motion_window")


def shares_kinematics(held, errors):
    """Can the evaluation with `held` replacing inputs of `errors` reuse the truth of
    `errors`: is every held input of the truth given as that same scalar?"""
    return all(name not in KINEMATIC_INPUTS or
               (np.ndim(errors.get(name)) == 0 and errors.get(name) == value)
               for name, value in held.items())


#: The radial noise: the one input a held evaluation may replace and still share the
#: reading (:func:`shares_reading`).
NOISE_INPUT = "lidar_radial_velocity"


def shares_reading(held, errors):
    """Can the evaluation with `held` replacing inputs of `errors` reuse its truth and its
    INS reading too (the believed beams, the least-squares factor): does `held` replace
    the radial noise alone, every other held input given in `errors` as that same scalar
    (or absent there, which is 0, and held at 0)?"""
    return shares_kinematics(held, errors) and all(
        name == NOISE_INPUT or name in KINEMATIC_INPUTS or
        (np.ndim(errors.get(name, 0.0)) == 0 and errors.get(name, 0.0) == value)
        for name, value in held.items())


#: How each scene's held speed was evaluated, counted per :func:`_evaluate` call (for the
#: tests): "shared reading" (a second right-hand side on the same least-squares factor,
#: :func:`~uq.physics.fusedmotionkernels.reconstruct`), "second reconstruction" (on the
#: same truth) or "second evaluation".
HELD_PATHS = collections.Counter()


def _scene_at(scene, index):
    """Scene `index` of a batch, with float fields."""
    return dataclasses.replace(scene, **{
        name: float(np.broadcast_to(getattr(scene, name), scene.shape)[index])
        for name in SCENE_FIELDS})


@dataclasses.dataclass(frozen=True)
class Plan:
    """What a scene's trials share (:func:`scene_plan`), as the kernels' arrays.

    Attributes
    ----------
    consts : ndarray
        The scalars of :data:`uq.physics.fusedmotionkernels.HEAD`.
    pairs : ndarray of int, shape (P, 2)
        (component, degree of freedom) of each moving pair, in the order of the components.
    amplitudes : ndarray, shape (P, 2)
        (A, A w) of each pair [rad or m; per s].
    components : ndarray, shape (K, 3)
        w [rad s-1] and the fixed unit phase (cos, sin) of each component (zeros if random).
    sources : ndarray of int, shape (K, 2)
        Where a component's phase comes from (0 fixed, 1 ``motion_phases``, 2
        ``motion_window``) and its column there.
    node_table, read_table : ndarray, shape (2, P, b q) and (2, P, k)
        sin and cos of ``w t + psi`` of every pair at the measurement times (beam-major,
        then dwell node) and at the INS read times (the beams' stamps, or the scan's mid).
    stamps : ndarray, shape (k,)
        The read times [s].
    weights : ndarray, shape (q,)
        Dwell-average weights (sum 1).
    azimuths : ndarray, shape (a, 2)
        cos and sin of the slanted beams' azimuths.
    beams : ndarray, shape (b, 3)
        Configured unit vectors in the ship frame.
    operator : ndarray, shape (3, b)
        Their least-squares operator A^+.
    slant : ndarray, shape (b, g)
        Slant distances of the gates [m].
    n_phases, n_window : int
        Columns the inputs ``motion_phases`` and ``motion_window`` need.
    at_nodes : bool
        The point-wise readings of a continuous INS are at the measurement times (no dwell
        average): without a clock offset the reading's motion is the truth's.
    """

    consts: np.ndarray
    pairs: np.ndarray
    amplitudes: np.ndarray
    components: np.ndarray
    sources: np.ndarray
    node_table: np.ndarray
    read_table: np.ndarray
    stamps: np.ndarray
    weights: np.ndarray
    azimuths: np.ndarray
    beams: np.ndarray
    operator: np.ndarray
    slant: np.ndarray
    n_phases: int
    n_window: int
    at_nodes: bool


def scene_plan(scene):
    """The :class:`Plan` of one scene (scalar fields); cached (a scene is called once per
    slice of trials)."""
    try:
        return _scene_plan(scene)
    except TypeError:                       # a field that cannot be hashed: no cache
        return _scene_plan.__wrapped__(scene)


@functools.lru_cache(maxsize=256)
def _scene_plan(scene):
    resolved = scene.time_resolved
    motion, timing, ins = resolved.motion, resolved.timing, resolved.ins
    n_beams, components = scene.n_beams, motion.components
    fastest = dwell_frequency(components)
    times, weights = timing.nodes(n_beams, fastest)                      # (b, q), (q,)
    pointwise = scene.correction == "pointwise"
    stamps = timing.stamps(n_beams) if pointwise else \
        np.array([timing.scan_mid_time(n_beams)])
    pairs = [(k, d) for k, c in enumerate(components) for d in range(len(DEGREES_OF_FREEDOM))
             if c.amplitudes[d] != 0]
    amplitudes = np.array([(components[k].amplitudes[d],
                            components[k].amplitudes[d] * components[k].angular_frequency)
                           for k, d in pairs], dtype=float).reshape(-1, 2)

    def table(at):                          # sin, cos(w t + psi) of every pair, (2, P, T)
        angles = np.array([components[k].angular_frequency * at + components[k].lags[d]
                           for k, d in pairs], dtype=float).reshape(len(pairs), len(at))
        return np.ascontiguousarray(np.stack([np.sin(angles), np.cos(angles)]))

    random = motion.random_components
    n_window = motion.window
    n_phases = len(random) - n_window
    sources = np.zeros((len(components), 2), dtype=np.int64)
    fixed = np.zeros((len(components), 3))
    for k, c in enumerate(components):
        fixed[k, 0] = c.angular_frequency
        if c.phase is None:
            order = random.index(k)
            sources[k] = (1, order) if order < n_phases else (2, order - n_phases)
        else:
            fixed[k, 1:] = math.cos(c.phase), math.sin(c.phase)
    moves = [any(d == dof for _, d in pairs) for dof in range(3)]      # roll, pitch, yaw
    arm = np.asarray(motion.lever_arm, dtype=float)
    static = rotation_about_vertical(scene.heading) @ rotation_pitch(scene.pitch) \
        @ rotation_roll(scene.roll) @ arm                                # R r at rest
    beams = scene.nominal_unit_vectors()
    azimuths = np.asarray(scene.azimuths, dtype=float)
    head = {"n_beams": n_beams, "n_gates": len(scene.ranges), "n_nodes": times.shape[1],
            "n_slanted": len(azimuths), "model": Correction.of(scene.correction),
            "ins_mode": _INS_MODES[ins.rate and ins.interpolation],
            "rate": ins.rate or 0.0, "to_north": -math.cos(scene.wind_direction),
            "to_east": -math.sin(scene.wind_direction),        # (wind "from": blows to -e)
            "vertical_wind": scene.vertical_wind,
            "ship_north": scene.sog * math.cos(scene.cog),
            "ship_east": scene.sog * math.sin(scene.cog), "ship_up": scene.heave,
            "level_cos": math.cos(scene.heading), "level_sin": math.sin(scene.heading),
            "course_cos": math.cos(scene.cog), "course_sin": math.sin(scene.cog),
            "arm_bow": arm[0], "arm_starboard": arm[1], "arm_up": arm[2],
            "static_arm_up": static[2], "moves_yaw": moves[2],
            "has_arm": bool(np.any(arm != 0)), "probe": scene.probe is not None,
            "mounted": scene.tilt != 0, "tilt_cos": math.cos(scene.tilt),
            "tilt_sin": math.sin(scene.tilt)}
    head["level_first"], head["level_second"] = _level_beams(scene)
    consts = np.array([head[name] if name in head else getattr(scene, name)
                       for name in kernels.HEAD], dtype=float)
    return Plan(consts=consts, pairs=np.array(pairs, dtype=np.int64).reshape(-1, 2),
                amplitudes=np.ascontiguousarray(amplitudes), components=fixed,
                sources=sources, node_table=table(times.ravel()), read_table=table(stamps),
                stamps=np.asarray(stamps, dtype=float), weights=np.asarray(weights, float),
                azimuths=np.ascontiguousarray(np.stack([np.cos(azimuths), np.sin(azimuths)],
                                                       axis=-1).reshape(-1, 2)),
                beams=np.ascontiguousarray(beams),
                operator=np.zeros((3, n_beams)) if scene.horizontal_only   # (w = 0)
                else np.ascontiguousarray(least_squares_operator(beams)),
                slant=np.ascontiguousarray(slant_distances(
                    scene.ranges, scene.half_cone, len(azimuths), scene.vertical_beam)),
                n_phases=n_phases, n_window=n_window,
                at_nodes=pointwise and ins.rate is None and times.shape[1] == 1
                and bool(np.array_equal(times[:, 0], stamps)))


def block_trials(plan, probe_nodes=0):
    """Trials per block: :data:`~uq.constants.MOTION_BLOCK_VALUES` doubles of a block's
    scratch (per trial: the work rows, a platform state per beam, the true beams, beams x
    nodes x (gates + 2) of node rows, with a probe of `probe_nodes` nodes twice that many
    per beam, node and gate more, the least squares and the outputs, the phase vectors),
    a power of two within :data:`~uq.constants.MOTION_BLOCK_TRIALS`."""
    beams, gates = plan.slant.shape
    nodes = plan.node_table.shape[2]
    per_trial = (kernels.WORK_ROWS + beams * (kernels.STATE_ROWS + 3)
                 + nodes * (gates * (1 + 2 * probe_nodes) + 2) + 6 + 8 * gates
                 + 4 * max(1, len(plan.components))
                 + (5 * beams + beams * gates if plan.consts[kernels.HEAD.index("mounted")]
                    else 0))                # a tilted mount's kept readings
    low, high = MOTION_BLOCK_TRIALS
    size = 2 ** int(math.floor(math.log2(max(1, MOTION_BLOCK_VALUES // per_trial))))
    return int(np.clip(size, low, high))


def _reconstruction_inputs(errors, n):
    """(INS inputs, which are given, radial noise) of :func:`kernels.reconstruct`."""
    ins = tuple(_ins_input(errors.get(name), n) for name in kernels.INPUTS)
    has = np.array([name in errors and not (np.ndim(errors[name]) == 0 and errors[name] == 0)
                    for name in kernels.INPUTS], dtype=np.int64)
    noise = errors.get("lidar_radial_velocity")
    noise = np.zeros((1, 1, 1)) if noise is None else \
        np.require(np.reshape(noise, (1, 1, 1)) if np.ndim(noise) == 0 else noise,
                   dtype=float, requirements="W")
    return ins, has, noise


def _evaluate(plan, errors, n, into, probe=None, layout=None, held=None):
    """The outputs of one scene into `into` (name -> (n, gates) view), block by block
    (with a `probe` volume: its weighted speed, :mod:`uq.physics.fusedprobe`; a tilted
    mount's `layout`: its horizontal wind in :func:`~uq.physics.fusedmotionkernels.
    reconstruct`, its shear exponent by :func:`~uq.physics.fusedmotionkernels.
    mounted_wind`); with `held` (inputs of the reconstruction alone -> scalar) the
    speed reconstructed from the same truth with those inputs replaced, into
    ``into["wind_speed_held"]``: with the reading shared (:func:`shares_reading`) in
    the same reconstruction, as a second right-hand side of its least
    squares, else by a second reconstruction."""
    consts = plan.consts
    if layout is not None and layout[-1]:   # the shear exponent: the believed lift too
        consts = consts.copy()
        consts[kernels.HEAD.index("mounted")] = 2.0
    # a tilted mount's shear exponent (its horizontal wind is reconstruct's): one pass
    mounted = kernels.compiled_mounted_wind() if layout is not None and layout[-1] else None
    n_beams, n_gates = plan.slant.shape
    n_nodes = len(plan.weights)
    ins, has, noise = _reconstruction_inputs(errors, n)
    second = None if held is None else _reconstruction_inputs({**errors, **held}, n)
    shared = second is not None and shares_reading(held, errors)
    if second is not None:
        HELD_PATHS["shared reading" if shared else "second reconstruction"] += 1
    phases = _phase_input(errors.get("motion_phases"), plan.n_phases)
    window = _phase_input(errors.get("motion_window"), plan.n_window)
    geometry = [_column(errors.get(name)) for name in _GEOMETRY]
    m = min(block_trials(plan, probe.nodes if probe is not None else 0), max(n, 1))
    n_components = max(1, len(plan.components))
    at_nodes = plan.at_nodes and not has[kernels.INPUTS.index("ins_clock_offset")]
    shear_rows = layout is not None and layout[-1]
    (work, c, turned, states, ship_beams, parts, ratio, out, speed, vertical, *rest,
     normal) = block_scratch(m, [
        (kernels.WORK_ROWS,), (2, n_components), (2, n_components),
        (n_beams if at_nodes else 1, kernels.STATE_ROWS), (n_beams, 3),
        (2, n_beams * n_nodes), (n_beams * n_nodes, n_gates), (3, n_gates), (n_gates,),
        (n_gates,), *([(3, n_gates)] if shared else []), *([(n_gates,)] if shear_rows else []),
        (6 + 3 * n_gates + (0 if layout is None else       # (reconstruct's rows)
                            5 * n_beams + n_beams * n_gates * (2 if shared else 1))
         + (3 * n_gates if shared else 0),)])
    held_out = rest.pop(0) if shared else np.empty((0, 1, 1))
    shear_out = rest.pop(0) if shear_rows else None
    held_noise = second[2] if shared else noise
    shear = consts[kernels.HEAD.index("shear")]
    beam_up = np.empty((n_beams * n_nodes, m)) if probe is not None else np.empty((1, 1))
    if probe is not None:
        focus, item_focus = fusedprobe.distinct_focus(np.repeat(plan.slant, n_nodes,
                                                                axis=0).ravel())
        reference = np.array([consts[kernels.HEAD.index("reference_height")]])
    # the horizontal wind of every trial, its direction taken once after the blocks: a
    # numpy call per block of 256 trials cost more in calls than in arctan2 (4.6 ms of a
    # 30 ms model at 2^17 trials, 1.3 ms once)
    horizontal = np.empty((2, n, n_gates)) if "wind_direction" in into or \
        "yaw_misalignment" in into else None
    for start in range(0, n, m):
        count = min(m, n - start)
        kernels.kinematics(consts, plan.pairs, plan.amplitudes, plan.components, plan.sources,
                           phases, window, plan.node_table, plan.azimuths, plan.beams,
                           plan.slant, *geometry, start, count, work, c, states, ship_beams,
                           parts, ratio, beam_up)
        if probe is not None:                       # the weighted U / U_ref at each node
            _probe_profile(probe, errors, start, count, ratio, beam_up, focus, item_focus,
                           reference, shear)
        elif shear != 0.0:                          # (z / z_ref)^alpha, SIMD; NaN stays NaN
            block = ratio[:, :, :count]
            np.log(block, out=block)
            block *= shear
            np.exp(block, out=block)
        kernels.reconstruct(consts, plan.pairs, plan.amplitudes, plan.components,
                            plan.read_table, plan.stamps, plan.beams, plan.operator,
                            plan.weights, ins, has, noise, start, count, work, c, turned,
                            states, parts, ratio, normal, out, held_noise, held_out)
        if mounted is not None:                     # a tilted mount's shear exponent
            mounted(consts, layout, plan.slant, normal, count, out, shear_out, speed,
                    vertical)
        else:
            kernels.wind_speed(out, count, speed, vertical)
        stop = start + count
        if "wind_speed" in into:
            into["wind_speed"][start:stop] = speed[:, :count].T
        if "vertical_wind" in into:
            into["vertical_wind"][start:stop] = vertical[:, :count].T
        if horizontal is not None:
            horizontal[:, start:stop] = out[:2, :, :count].transpose(0, 2, 1)
        if shear_out is not None and "shear_exponent" in into:
            into["shear_exponent"][start:stop] = shear_out[:, :count].T
        if shared:                         # the same reading, the held noise's wind
            kernels.wind_speed(held_out, count, speed, vertical)
            into[HELD_WIND_SPEED][start:stop] = speed[:, :count].T
        elif second is not None:           # the same truth, the held inputs' reading
            kernels.reconstruct(consts, plan.pairs, plan.amplitudes, plan.components,
                                plan.read_table, plan.stamps, plan.beams, plan.operator,
                                plan.weights, *second, start, count, work, c, turned,
                                states, parts, ratio, normal, out, noise, _NO_HELD)
            if mounted is not None:                 # (the shear row is stored already)
                mounted(consts, layout, plan.slant, normal, count, out, speed, speed,
                        vertical)
            else:
                kernels.wind_speed(out, count, speed, vertical)
            into[HELD_WIND_SPEED][start:stop] = speed[:, :count].T
    if horizontal is not None:
        direction = _direction(horizontal[0], horizontal[1])
        if "wind_direction" in into:
            into["wind_direction"][...] = direction
        if "yaw_misalignment" in into:              # from the rotor axis, the heading
            into["yaw_misalignment"][...] = nacelle.yaw_misalignment(
                direction, consts[kernels.HEAD.index("heading")])


def block_scratch(m, shapes):
    """The block scratch of :func:`_evaluate`: an array (*shape, m + pad) per shape, one
    after the other in one buffer whose first row is 64-byte aligned, each row
    :data:`~uq.constants.MOTION_BLOCK_ROW_PAD` values longer than the block's m trials
    (the loops use the first m): rows of 2^k values let a store and a later load of
    another row meet at the same address modulo 4 KiB, which the CPU takes for a
    dependence (4K aliasing), at places that depended on where each array happened to
    be allocated. The same placement in every process; with m a power of two, rows
    fewer than 64 apart never share their address modulo 4 KiB."""
    width = m + MOTION_BLOCK_ROW_PAD
    sizes = [math.prod(shape) * width for shape in shapes]
    buffer = np.empty(sum(sizes) + 8)
    at = (-buffer.ctypes.data // 8) % 8                 # to the 64-byte line
    arrays = []
    for shape, size in zip(shapes, sizes):
        arrays.append(buffer[at:at + size].reshape(*shape, width))
        at += size
    return arrays


#: ``held_out`` of :func:`~uq.physics.fusedmotionkernels.reconstruct` without a held side.
_NO_HELD = np.empty((0, 1, 1))


def _probe_profile(probe, errors, start, count, ratio, beam_up, focus, item_focus,
                   reference, shear):
    """ratio[node, g, :count] = the probe-weighted U / U_ref at the gate-centre heights
    kinematics wrote there (:func:`uq.physics.fusedprobe.profile`); a parameter's error
    (n,) is one per scan."""
    nodes, gates = ratio.shape[:2]
    centre = np.ascontiguousarray(ratio[:, :, :count].reshape(nodes * gates, count))
    up = np.ascontiguousarray(np.repeat(beam_up[:, :count], gates, axis=0))
    given = {name: np.reshape(errors[f"lidar_{name}"], -1) for name in probe.PARAMETERS
             if f"lidar_{name}" in errors}
    rows = slice(start, start + count)
    first, second = fusedprobe.parameters(probe, {name: value if value.shape[0] > 1 else
                                                  value[0] for name, value in given.items()},
                                          rows)
    out = np.empty((nodes * gates, count))
    with np.errstate(invalid="ignore", divide="ignore"):
        fusedprobe.profile(probe, first, second, centre, up, focus, item_focus, reference,
                           shear, out)
    ratio[:, :, :count] = out.reshape(nodes, gates, count)


def _direction(north, east):
    """Meteorological ("from") direction [deg] in [0, 360) of (north, east) [m s-1]
    (as :func:`uq.physics.wind.wind_direction`)."""
    angle = np.arctan2(-east, -north)
    np.multiply(angle, 180.0 / math.pi, out=angle)
    np.add(angle, FULL_CIRCLE_DEG, out=angle, where=angle < 0.0)
    np.subtract(angle, FULL_CIRCLE_DEG, out=angle, where=angle >= FULL_CIRCLE_DEG)
    return angle


def _column(value):
    """A per-trial input as a writable float array of length n or 1 (absent: 0)."""
    if value is None:
        return np.zeros(1)
    value = np.asarray(value, dtype=float)
    value = value if value.ndim == 1 else np.atleast_1d(value).ravel()
    return value if value.flags.writeable else value.copy()


def _ins_input(value, n):
    """An INS input as a writable float array (n or 1, k or 1): one per scan (n,) is
    (n, 1); absent is zero."""
    if value is None:
        return np.zeros((1, 1))
    value = np.asarray(value, dtype=float)
    value = value.reshape(-1, 1) if value.ndim < 2 else value
    return value if value.flags.writeable else value.copy()


def _phase_input(value, columns):
    """Unit phases (n or 1, columns, 2) as a writable float array; absent: zeros (their
    mean, the error-free reconstruction)."""
    if value is None or np.ndim(value) == 0:
        return np.zeros((1, max(columns, 1), 2))
    value = np.asarray(value, dtype=float)
    value = np.broadcast_to(value, (value.shape[0], max(columns, value.shape[1]), 2))
    return value if value.flags.writeable else value.copy()
