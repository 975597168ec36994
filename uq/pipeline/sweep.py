"""How a sweep's grid is cut into vectorised chunks of scenes.

A sweep is the outer product of its swept keys (one dimension per key, file order).
Keys that only change numbers of the :class:`uq.physics.scene.Scene` (wind, ship motion,
lidar height, half-cone and misalignment: :data:`VECTOR_KEYS`) are evaluated together:
the measurement model takes arrays of them, and every scene of a chunk sees the same
error draws (common random numbers). Every other swept key (an error's size, the
correction model, the range gates, ...) changes the structure of the model; each of its
values is a *group* with its own validated scenario, and still the same seed.

The chunks are a fixed function of the scenario: they do not depend on the number of
workers, the sampling chunk size or on which chunks a resumed run already has, so every
way of running a sweep gives the same numbers bit for bit.
"""
import dataclasses
import itertools
import math

import numpy as np

from uq.pipeline import motionsection
from uq.constants import (DEFAULT_BLOCKS_PER_CHUNK, FUSED_MAX_SCENES, RNG_BLOCK_SIZE,
                        SWEEP_CHUNK_ELEMENTS, SWEEP_CHUNK_ELEMENTS_COMPILED)

#: Swept keys that are evaluated as arrays: dotted key -> Scene field.
VECTOR_KEYS = {
    "wind.speed": "wind_speed", "wind.direction": "wind_direction",
    "wind.vertical": "vertical_wind", "wind.shear": "shear",
    "wind.reference_height": "reference_height",
    "ship.sog": "sog", "ship.cog": "cog", "ship.heading": "heading", "ship.pitch": "pitch",
    "ship.roll": "roll", "ship.heave": "heave",
    "lidar.height": "lidar_height", "lidar.half_cone": "half_cone",
    "lidar.misalignment": "misalignment",
}
#: Vector keys given in degrees (Scene fields are radians).
ANGLE_KEYS = ("wind.direction", "ship.cog", "ship.heading", "ship.pitch", "ship.roll",
              "lidar.half_cone", "lidar.misalignment")


@dataclasses.dataclass(frozen=True)
class Chunk:
    """Scenes ``start:stop`` (flat, C order) of the vector grid of group ``group``."""

    index: int
    group: tuple
    start: int
    stop: int


@dataclasses.dataclass(frozen=True)
class SweepPlan:
    """The grid of a scenario, split into structural groups and vector chunks.

    Attributes
    ----------
    group_keys, vector_keys : tuple of str
        Swept keys (file order within each).
    group_values, vector_values : tuple of tuple
        Their values.
    chunks : tuple of Chunk
    """

    group_keys: tuple
    group_values: tuple
    vector_keys: tuple
    vector_values: tuple
    chunks: tuple

    @property
    def group_shape(self):
        return tuple(len(v) for v in self.group_values)

    @property
    def vector_shape(self):
        return tuple(len(v) for v in self.vector_values)

    @property
    def n_scenes(self):
        return math.prod(self.group_shape) * math.prod(self.vector_shape)


def sweep_plan(scenario):
    """Split the scenario's sweep into groups and chunks; see the module docstring."""
    sweep = dict(scenario.sweep)
    vector = tuple(key for key in sweep if key in VECTOR_KEYS)
    group = tuple(key for key in sweep if key not in VECTOR_KEYS)
    n_vector = math.prod(len(sweep[key]) for key in vector)
    per_chunk = scenes_per_chunk(scenario)
    chunks = []
    for point in itertools.product(*[range(len(sweep[key])) for key in group]):
        for start in range(0, n_vector, per_chunk):
            chunks.append(Chunk(len(chunks), point, start, min(start + per_chunk, n_vector)))
    return SweepPlan(group, tuple(sweep[k] for k in group), vector,
                     tuple(sweep[k] for k in vector), tuple(chunks))


def scenes_per_chunk(scenario):
    """Scenes evaluated at once, so that one evaluation holds about
    :data:`SWEEP_CHUNK_ELEMENTS` trial x scene x beam x gate elements.

    Adaptive sampling (``digits``) runs scene by scene: each scene stops on its own.
    With the compiled model the element is trial x scene x gate x output.
    """
    sampling = scenario.sampling
    if "digits" in sampling:
        return 1
    lidar = scenario.settings["lidar"]
    beams = len(lidar["azimuths"]) + int(lidar["vertical_beam"])
    gates = len(lidar["ranges"])
    if sampling["method"] == "none":                # GUM only: one row per input element
        ins = scenario.settings["ins"]
        per_reading = beams if ins["correlation"] == "beam" else 1
        rows = 1 + (len(ins) - 1) * per_reading + len(lidar["errors"]) * beams * gates
    else:
        rows = min(sampling["n"], DEFAULT_BLOCKS_PER_CHUNK * RNG_BLOCK_SIZE)
        if _compiled(scenario):          # no (trial, scene, beam, gate) temporaries
            values = sum(beams * gates if q == "radial_velocity" else gates
                         for q in scenario.settings["outputs"])
            return int(np.clip(SWEEP_CHUNK_ELEMENTS_COMPILED // (rows * values),
                               1, FUSED_MAX_SCENES))
    return max(1, SWEEP_CHUNK_ELEMENTS // (rows * beams * gates))


def _compiled(scenario):
    """Will the Monte Carlo trials run the compiled model (:func:`uq.fused.applicable`:
    every static scene; a time-resolved scan runs the numpy model)?"""
    return not motionsection.is_time_resolved(scenario.settings)


def group_assignments(scenario, plan, group):
    """``{dotted: value}`` of the structural keys of a group (links included)."""
    values = {key: plan.group_values[i][j] for i, (key, j) in
              enumerate(zip(plan.group_keys, group))}
    values.update({f: values[lead] for f, lead in scenario.links if lead in values})
    return values


def vector_fields(scenario, plan, chunk):
    """Scene fields (SI, radians) of the chunk's scenes: field -> array (n_chunk,)."""
    if not plan.vector_keys:
        return {}
    index = np.unravel_index(np.arange(chunk.start, chunk.stop), plan.vector_shape)
    fields = {}
    for key, values, position in zip(plan.vector_keys, plan.vector_values, index):
        fields[key] = np.asarray(values, dtype=float)[position]
    fields.update({f: fields[lead] for f, lead in scenario.links if lead in fields})
    return {VECTOR_KEYS[key]: np.deg2rad(value) if key in ANGLE_KEYS else value
            for key, value in fields.items()}


def batch_scene(scene, fields):
    """`scene` with the given fields replaced by arrays (a batch of scenes)."""
    return dataclasses.replace(scene, **fields)
