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
two agree to 1e-12 for every correction model and error source. The numpy model stays
the reference: it alone runs complex-step (the GUM Jacobian), point-wise correction
(``ins.correlation: beam``), independent draws per scene, and the outputs
``radial_velocity`` and ``gate_height``; :func:`applicable` says when the fused loop
is used. A batch of scenes (a sweep's chunk) is evaluated scene after scene.

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
import dataclasses
import functools
import math

import numpy as np

from uq.physics import fusedkernels as kernels
from uq.physics.beams import least_squares_operator, slant_distances
from uq.constants import FULL_CIRCLE_DEG, FUSED_BLOCK_TRIALS, FUSED_MAX_SCENES
from uq.physics.correction import CORRECTION_MODELS
from uq.physics.scene import COMPILED_OUTPUTS, NAVIGATION, SCENE_FIELDS, sample_count
from uq.physics.rotation import attitude_matrix

#: Outputs the fused loop computes; any other requested output uses the numpy model.
FUSED_OUTPUTS = COMPILED_OUTPUTS
_INS_ANGLES = ("heading", "pitch", "roll", "cog")


def applicable(scene, outputs, errors, scene_draws=False):
    """Can the fused loop evaluate this call of the measurement model?

    At most :data:`~uq.constants.FUSED_MAX_SCENES` scenes, common draws for every
    scene of the batch (not ``scene_draws``), only
    :data:`FUSED_OUTPUTS`, real errors, one INS reading per scan (``scan``) and radial
    noise of shape (n, beams, gates) if any.
    """
    if scene_draws or scene.time_resolved is not None or \
            not set(outputs) <= set(FUSED_OUTPUTS) or \
            math.prod(scene.shape) > FUSED_MAX_SCENES:
        return False
    if any(np.iscomplexobj(value) for value in errors.values()):
        return False
    if any(np.ndim(errors.get(f"ins_{key}", 0.0)) > 1 and np.shape(errors[f"ins_{key}"])[1:] != (1,)
           for key in NAVIGATION):
        return False                                  # one reading per beam (``beam``)
    noise = errors.get("lidar_radial_velocity")
    return noise is None or np.ndim(noise) == 3


def measurement_model(scene, outputs, **errors):
    """The fused equivalent of :func:`uq.measurement.measurement_model` (same inputs,
    degrees for angular errors; same outputs, each shape (n, *S, n_gates) for a batch
    of scenes of shape S). The scenes of a batch are evaluated one after the other,
    each with the same draws (common random numbers)."""
    shape, gates = scene.shape, len(scene.ranges)
    n = sample_count(errors)
    result = {q: np.empty((n,) + shape + (gates,)) for q in FUSED_OUTPUTS if q in outputs}
    scratch = {q: np.empty((n, gates)) for q in FUSED_OUTPUTS if q not in outputs}
    for index in np.ndindex(*shape):
        into = {q: result[q][(slice(None),) + index] if q in result else scratch[q]
                for q in FUSED_OUTPUTS}                       # (n, gates) views
        evaluate = _Blocks(_one_scene(scene, index), errors, into, "wind_direction" in outputs)
        for start in range(0, n, FUSED_BLOCK_TRIALS):
            evaluate(start, min(n, start + FUSED_BLOCK_TRIALS))
    return {q: result[q] for q in outputs}


def _one_scene(scene, index):
    """Scene `index` of a batch, with float fields."""
    return dataclasses.replace(scene, **{
        name: float(np.broadcast_to(getattr(scene, name), scene.shape)[index])
        for name in SCENE_FIELDS})


class _Blocks:
    """One call of the model, evaluated block by block (the three kernels of
    :mod:`uq.physics.fusedkernels` and numpy's SIMD log/exp between them) into ``out``."""

    def __init__(self, scene, errors, out, want_direction):
        self.scene, self.out, self.want_direction = scene, out, want_direction
        self.constants = scene_constants(scene)
        self.column = {name: _column(errors.get(name)) for name in (
            "lidar_half_cone", "lidar_misalignment", "lidar_height", "ins_sog", "ins_heave",
            *(f"ins_{key}" for key in _INS_ANGLES))}
        noise = errors.get("lidar_radial_velocity")
        self.noise = np.zeros((1, scene.n_beams, len(scene.ranges))) if noise is None \
            else np.require(noise, dtype=float, requirements="W")
        # the truth (beams, gate heights) is common to all trials without geometry errors
        self.fixed_truth = all(len(self.column[name]) == 1 for name in (
            "lidar_half_cone", "lidar_misalignment", "lidar_height"))
        block = 1 if self.fixed_truth else FUSED_BLOCK_TRIALS
        self.geometry_trig = np.empty((2, 2, block))
        self.beams = np.empty((block, scene.n_beams, 3))
        self.profile = np.empty((block, scene.n_beams, len(scene.ranges)))
        self.trig = np.empty((4, 2, FUSED_BLOCK_TRIALS))
        self.from_east = np.empty((FUSED_BLOCK_TRIALS, len(scene.ranges)))
        self.from_north = np.empty_like(self.from_east)
        if self.fixed_truth:
            self._truth(0, 1)

    def __call__(self, start, stop):
        if not self.fixed_truth:
            self._truth(start, stop - start)
        scene = self.scene
        for k, key in enumerate(_INS_ANGLES):
            kernels.angle_trig(self.column[f"ins_{key}"], getattr(scene, key), start, stop,
                               self.trig[k, 0], self.trig[k, 1])
        kernels.wind(self.constants, self.beams, self.profile, len(self.beams), self.trig,
                     self.column["ins_sog"], self.column["ins_heave"], self.noise,
                     CORRECTION_MODELS.index(scene.correction), start, stop,
                     self.out["wind_speed"], self.out["vertical_wind"], self.from_north,
                     self.from_east)
        if self.want_direction:
            _direction(self.from_north[:stop - start], self.from_east[:stop - start],
                       self.out["wind_direction"][start:stop])

    def _truth(self, start, rows):
        """Beams and the power-law profile U(z) / U_ref of trials start .. start + rows."""
        scene, trig = self.scene, self.geometry_trig
        for k, (name, base) in enumerate((("lidar_half_cone", scene.half_cone),
                                          ("lidar_misalignment", scene.misalignment))):
            kernels.angle_trig(self.column[name], base, start, start + rows, trig[k, 0],
                               trig[k, 1])
        profile = self.profile[:rows]
        kernels.geometry(self.constants, trig[0], trig[1], self.column["lidar_height"], start,
                         rows, scene.shear != 0.0, self.beams, self.profile)
        if scene.shear != 0.0:                      # (z / z_ref)^alpha, SIMD; NaN stays NaN
            np.log(profile, out=profile)
            profile *= scene.shear
            np.exp(profile, out=profile)


def _direction(from_north, from_east, out):
    """Meteorological direction [deg] in [0, 360) of the "from" vector, into out
    (as :func:`uq.wind.wind_direction`)."""
    np.arctan2(from_east, from_north, out=out)
    np.multiply(out, 180.0 / math.pi, out=out)
    np.add(out, FULL_CIRCLE_DEG, out=out, where=out < 0.0)
    np.subtract(out, FULL_CIRCLE_DEG, out=out, where=out >= FULL_CIRCLE_DEG)   # -1e-17 + 360


def _column(value):
    """An error as a writable float array of length n (per trial, any stride) or 1
    (absent or constant: the kernels read element 0)."""
    if value is None:
        return np.zeros(1)
    value = np.asarray(value, dtype=float)
    value = value if value.ndim == 1 else np.atleast_1d(value).ravel()
    return value if value.flags.writeable else value.copy()


def scene_constants(scene):
    """The scene as one float vector (numba takes no dataclass); read by the accessors
    at the end of :mod:`uq.physics.fusedkernels`. Computed once per scene (a pseudo-inverse and
    a few rotations, ~0.4 ms: the model is called once per slice of trials)."""
    try:
        return _scene_constants(scene)
    except TypeError:                       # a field that cannot be hashed: no cache
        return _scene_constants.__wrapped__(scene)


@functools.lru_cache(maxsize=256)
def _scene_constants(scene):
    azimuths = np.asarray(scene.azimuths, dtype=float)
    operator = least_squares_operator(scene.nominal_unit_vectors())           # (3, b)
    slant = slant_distances(scene.ranges, scene.half_cone, len(azimuths),
                            scene.vertical_beam)                             # (b, g)
    head = {"n_slanted": len(azimuths), "vertical_beam": int(scene.vertical_beam),
            "n_gates": len(scene.ranges), "to_north": -math.cos(scene.wind_direction),
            "to_east": -math.sin(scene.wind_direction)}      # (wind "from": blows to -e)
    head = [head[name] if name in head else getattr(scene, name) for name in kernels.HEAD]
    attitude = attitude_matrix(scene.heading, scene.pitch, scene.roll)
    return np.concatenate([np.asarray(head, dtype=float), np.cos(azimuths),
                           np.sin(azimuths), attitude.ravel(),
                           operator.ravel(), slant.ravel()])
