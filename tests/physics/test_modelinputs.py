"""The one declaration of the model's inputs (:mod:`uq.physics.modelinputs`): every table
derives from it, every model refuses what it does not implement, every declared input
has an effect in every model that claims it, and adding one is a row plus its physics.

The sensitivity checks need no tolerance of their own: an input with an effect moves an
output by far more than rounding (each perturbation below is a sizeable error: 2 deg, 0.5
m s-1, 5 m, a quarter turn of a phase), and "no effect" is exact equality (an ignored
input changes no bit).
"""
import dataclasses
import logging

import numpy as np
import pytest

from uq.engine.inputs import input_set
from uq.errors import ScenarioError
from uq.physics import (fused, fusedkernels, fusedmotion, fusedmotionkernels, kernelbase,
                        modelinputs)
from uq.physics.measurement import measurement_model
from uq.physics.modelinputs import (INPUTS, MODELS, MOTION, MOTION_COMPILED, STATIC,
                                    STATIC_COMPILED, Correction, ModelInput)
from uq.pipeline import metadata, modelsetup, scenario as scenario_module
from uq.pipeline.modelsetup import error_inputs, input_label, scene_from_settings
from uq.pipeline.scenario import load_scenario

WIND = ("wind_speed", "wind_direction", "vertical_wind")
STATIC_BASE = {"wind": {"speed": 10.0, "direction": 200.0, "vertical": 0.2, "shear": 0.2},
               "ship": {"sog": 2.0, "cog": 40.0, "heading": 30.0, "pitch": 2.0, "roll": -1.5,
                        "heave": 0.3},
               "lidar": {"ranges": [60.0, 120.0]}, "correction": "full"}
MOTION_BASE = {**STATIC_BASE,
               "motion": {"roll": {"amplitude": 5.0, "period": 6.0, "phase": "random"},
                          "heave": {"amplitude": 1.0, "period": 7.0}},
               "lidar": {"ranges": [60.0, 120.0], "lever_arm": [1.0, 0.5, 3.0],
                         "scan": {"beam_duration": 1.0}},
               "ins": {"rate": 5.0}, "correction": "pointwise"}
#: Sections an input needs to have an effect (a probe of the kind that uses it).
PROBES = {"lidar_gate_length": {"kind": "pulsed", "gate_length": 30.0, "pulse_fwhm": 25.0},
          "lidar_pulse_fwhm": {"kind": "pulsed", "gate_length": 30.0, "pulse_fwhm": 25.0},
          "lidar_wavelength": {"kind": "cw", "wavelength": 1.565, "beam_radius": 28.0,
                               "truncation": 0.02},
          "lidar_beam_radius": {"kind": "cw", "wavelength": 1.565, "beam_radius": 28.0,
                                "truncation": 0.02}}


def _record(folder):
    """A measured motion record (roll and heave) in `folder`; its path."""
    times = np.arange(0.0, 120.0, 0.1)
    path = folder / "record.csv"
    rows = [f"{t},{4 * np.sin(2 * np.pi * t / 6)},{np.cos(t / 3)}" for t in times]
    path.write_text("t,r,h\n" + "\n".join(rows) + "\n")
    return path


def scene_for(name, model, folder):
    """A scene in which input `name` matters to `model` (scenario units)."""
    return setup_for(name, model, folder)[0]


def setup_for(name, model, folder):
    """(scene, settings) of :func:`scene_for`."""
    base = MOTION_BASE if model in (MOTION, MOTION_COMPILED) else STATIC_BASE
    settings = {key: (dict(value) if isinstance(value, dict) else value)
                for key, value in base.items()}
    if name in PROBES:
        settings["lidar"] = {**settings["lidar"], "probe": PROBES[name]}
        settings["lidar"]["ranges"] = [300.0] if PROBES[name]["kind"] == "cw" else [60.0, 120.0]
    if name == "motion_window":
        settings["motion"] = {"series": {"file": str(_record(folder)), "time": "t",
                                         "columns": {"roll": "r", "heave": "h"},
                                         "components": 16}}
    settings = load_scenario({"name": "t", **settings}).settings
    return scene_from_settings(settings), settings


def phase_columns(settings, name):
    """Components K of a phase input (n, K, 2) of the scenario's engine inputs."""
    return error_inputs(settings, 4, 2)[name].shape[0]


def perturbation(row, scene, settings, n=3):
    """A sizeable value of the input of `row` for n trials, in its declared shape."""
    size = {"degree": 2.0, "m s-1": 0.5, "m": 5.0, "um": 0.05, "mm": 3.0, "s": 0.15}
    gates = len(scene.ranges)
    if row.shape == "phase":                                       # a quarter turn
        return np.broadcast_to([0.0, 1.0], (n, phase_columns(settings, row.name), 2)).copy()
    if row.shape == "beam_gate":
        return np.full((n, scene.n_beams, gates), size[row.unit])
    return np.full(n, size[row.unit])


def _evaluate(scene, model, errors):
    if model in (STATIC_COMPILED, MOTION_COMPILED):
        guard = fused if model == STATIC_COMPILED else fusedmotion
        assert guard.declined(scene, WIND, errors) == "", "the compiled model must take it"
        return measurement_model(scene, WIND, **errors)
    return measurement_model(scene, WIND, compiled=False, **errors)


def _claims():
    return [(row.name, model) for row in INPUTS for model in sorted(row.models)]


@pytest.mark.parametrize("name, model", _claims())
def test_every_declared_input_changes_the_outputs_of_every_model_that_claims_it(
        name, model, tmp_path):
    """A declared input without physics in a model that claims it would be ignored:
    perturbing it must move the wind (against the same call without it)."""
    row = modelinputs.input_named(name)
    scene, settings = setup_for(name, model, tmp_path)
    zero = {"lidar_radial_velocity": np.zeros((3, scene.n_beams, len(scene.ranges)))}
    for phases in ("motion_phases", "motion_window"):     # the platform moves: phase 0
        if model in (MOTION, MOTION_COMPILED) and phases in error_inputs(settings, 4, 2):
            zero[phases] = np.broadcast_to([1.0, 0.0], (3, phase_columns(settings, phases), 2))
    moved = {**zero, name: perturbation(row, scene, settings)}
    before, after = _evaluate(scene, model, zero), _evaluate(scene, model, moved)
    assert any(not np.array_equal(before[q], after[q]) for q in WIND), \
        f"{name} has no effect in the {model} model"


def test_models_are_the_declared_ones():
    for row in INPUTS:
        assert row.models <= set(MODELS) and row.models, row.name
        assert row.shape in modelinputs.SHAPES, row.name
        assert row.unit in {"degree", "m s-1", "m", "um", "mm", "s", "1"}, row.name
        assert row.angular == (row.unit == "degree"), row.name


def test_the_tables_derive_from_the_declaration():
    ins = [row.short_key for row in INPUTS if row.shape == "reading"]
    assert scenario_module.INS_KEYS == tuple(ins)
    assert set(scenario_module.LIDAR_ERROR_KEYS) | set(
        scenario_module.PROBE_ERROR_KEYS) == {row.short_key for row in INPUTS
                                               if row.key.startswith("lidar.errors.")}
    for row in INPUTS:
        assert input_label(row.name) == row.label
        if row.holds_distribution:
            assert metadata.scenario_key_units(f"{row.key}.u") == row.unit, row.name
    assert metadata.scenario_key_units("ins.clock_offset.u") == "s"


def test_the_kernels_take_exactly_the_declared_inputs():
    """The kernels' argument orders name the inputs their models declare."""
    static = {f"ins_{k}" for k in fusedkernels.INS_ORDER} | \
        {f"lidar_{k}" for k in fusedkernels.GEO_ORDER} | {"lidar_radial_velocity"} | \
        set(fused._PROBE)
    assert static == set(modelinputs.names(STATIC_COMPILED))
    motion = set(fusedmotionkernels.INPUTS) | set(fusedmotion._GEOMETRY) | \
        set(fusedmotion.PROBE_INPUTS) | \
        {"lidar_radial_velocity", "motion_phases", "motion_window"}
    assert motion == set(modelinputs.names(MOTION_COMPILED))


def test_correction_codes_are_named_and_refuse_unknown_ones():
    assert [m.key for m in Correction] == ["none", "yaw", "tilt2d", "full", "pointwise"]
    assert Correction.of("tilt2d") == 2 and Correction.of("pointwise") == 4
    assert kernelbase.NONE == Correction.NONE and kernelbase.FULL == Correction.FULL
    assert kernelbase.POINTWISE == Correction.POINTWISE
    with pytest.raises(ValueError, match="unknown correction model 'tilt3d'.*allowed"):
        Correction.of("tilt3d")


@pytest.mark.parametrize("model", MODELS)
def test_an_invented_input_is_refused_by_every_model_path_with_its_name(model, tmp_path):
    scene = scene_for("ins_heading", model, tmp_path)
    errors = {"lidar_range_offset": np.ones(3)}
    if model in (STATIC, MOTION):
        with pytest.raises(ValueError, match="lidar_range_offset.*not a declared model input"):
            measurement_model(scene, WIND, compiled=False, **errors)
    else:
        guard = fused if model == STATIC_COMPILED else fusedmotion
        assert guard.declined(scene, WIND, errors) == "input(s) lidar_range_offset"
        assert not guard.applicable(scene, WIND, errors)
        with pytest.raises(ValueError, match="lidar_range_offset"):   # falls back: refused
            measurement_model(scene, WIND, **errors)


def test_an_invented_scenario_key_is_refused_with_its_name():
    with pytest.raises(ScenarioError, match="lidar.errors.*range_offset"):
        load_scenario({"lidar": {"errors": {"range_offset": {"dist": "normal", "u": 1.0}}}})


def test_a_static_model_refuses_an_input_of_the_time_resolved_model():
    scene = scene_for("ins_heading", STATIC, None)
    with pytest.raises(ValueError, match="static model does not implement.*ins_clock_offset"):
        measurement_model(scene, WIND, compiled=False, ins_clock_offset=np.ones(3))


#: The compiled paths' fall-backs: (model, scene kind, outputs, inputs) -> the reason.
FALLBACKS = [
    (STATIC_COMPILED, "probe", WIND, {}, ""),
    (STATIC_COMPILED, "static", WIND, {"lidar_gate_length": np.ones(3)}, ""),
    (STATIC_COMPILED, "probe", WIND, {"lidar_gate_length": np.ones(3) * 1j},
     "a probe volume's complex step (the GUM)"),
    (STATIC_COMPILED, "static", WIND, {"ins_heading": np.ones((3, 2, 2))},
     "an input of a shape it does not take"),
    (STATIC_COMPILED, "static", WIND + ("gate_height",), {}, ""),
    (STATIC_COMPILED, "static", WIND, {"ins_heading": np.ones(3) * 1j},
     "a complex step (the GUM) of fewer than 16384 scenes"),
    (MOTION_COMPILED, "motion", WIND, {}, ""),
    (MOTION_COMPILED, "motion", WIND + ("radial_velocity",), {}, "output(s) radial_velocity"),
    (MOTION_COMPILED, "motion", ("gate_height",), {}, "output(s) gate_height"),
    (MOTION_COMPILED, "motion", WIND, {"ins_sog": np.ones(3) * 1j},
     "complex inputs (the GUM's complex steps)"),
    (MOTION_COMPILED, "motion", WIND, {"lidar_wavelength": np.ones(3)}, ""),
    (MOTION_COMPILED, "motion probe", WIND, {}, ""),
    (MOTION_COMPILED, "motion", WIND, {"lidar_height": np.ones((3, 2))},
     "input lidar_height of 2 axes"),
]


@pytest.mark.parametrize("model, kind, outputs, errors, reason", FALLBACKS)
def test_the_compiled_paths_fall_backs(model, kind, outputs, errors, reason, caplog):
    """Which calls the compiled models decline, and that the numpy model then evaluates
    them (said once at INFO, the CLI's -v)."""
    name = "lidar_gate_length" if "probe" in kind else "ins_heading"
    scene = scene_for(name, MOTION if "motion" in kind else STATIC, None)
    guard = fused if model == STATIC_COMPILED else fusedmotion
    assert guard.declined(scene, outputs, errors) == reason
    if not reason or "shape" in reason or "axes" in reason:
        return
    modelinputs._LOGGED.clear()
    with caplog.at_level(logging.INFO, logger="uq.physics.modelinputs"):
        result = measurement_model(scene, outputs, **errors)
    assert set(result) == set(outputs)
    assert f"the {model} model does not take this call ({reason})" in caplog.text


def test_adding_an_input_is_one_row_plus_its_physics(monkeypatch):
    """The guide's worked example (docs/contributing.md): a radial-velocity bias of the lidar, one draw per
    scan. One row makes it a scenario key with its unit and budget label, an engine input
    the compiled model declines; the declaration-driven sensitivity check then fails until
    its physics is in the numpy model, and passes after."""
    from uq.physics import measurement
    row = ModelInput("lidar_radial_bias", "lidar.errors.radial_bias", "m s-1", "scan", False,
                     "lidar.errors.radial_bias", frozenset({STATIC}),
                     "a bias of every radial velocity of the scan")
    monkeypatch.setattr(modelinputs, "INPUTS", INPUTS + (row,))
    settings = load_scenario({"lidar": {"errors": {
        "radial_bias": {"dist": "normal", "u": 0.05}}}}).settings
    scene = scene_from_settings(settings)
    inputs = error_inputs(settings, scene.n_beams, len(scene.ranges))
    assert list(inputs) == ["lidar_radial_bias"]
    assert input_label("lidar_radial_bias") == "lidar.errors.radial_bias"
    assert metadata.scenario_key_units("lidar.errors.radial_bias.u") == "m s-1"
    assert fused.declined(scene, WIND, {"lidar_radial_bias": np.ones(3)}) == \
        "input(s) lidar_radial_bias"
    bias = {"lidar_radial_bias": np.full(3, 0.5)}
    without = measurement_model(scene, WIND, compiled=False, lidar_radial_bias=np.zeros(3))
    with_row_only = measurement_model(scene, WIND, compiled=False, **bias)
    assert all(np.array_equal(without[q], with_row_only[q]) for q in WIND)   # no physics yet
    measure = measurement._measure

    def with_physics(scene, err, batch):                 # the one line of physics
        measured, navigation, beams = measure(scene, err, batch)
        return measured + measurement._trailing(err["lidar_radial_bias"], 2), navigation, beams
    monkeypatch.setattr(measurement, "_measure", with_physics)
    biased = measurement_model(scene, WIND, compiled=False, **bias)
    # a common bias b on every beam of a level DBS with a 28 deg half-cone reads as a
    # vertical wind b / cos(28 deg) and leaves the horizontal wind alone (to rounding)
    np.testing.assert_allclose(biased["vertical_wind"] - without["vertical_wind"],
                               0.5 / np.cos(np.deg2rad(28.0)), rtol=1e-12)
    np.testing.assert_allclose(biased["wind_speed"], without["wind_speed"], atol=1e-12)


def test_engine_inputs_follow_the_declaration_order():
    """The order of the engine inputs fixes the random streams: it is the declaration's."""
    settings = load_scenario({**MOTION_BASE, "ins": {
        "rate": 5.0, "clock_offset": {"dist": "normal", "u": 0.01},
        "cog": {"dist": "normal", "u": 1.0}, "heading": {"dist": "normal", "u": 1.0}},
        "lidar": {**MOTION_BASE["lidar"], "errors": {
            "height": {"dist": "normal", "u": 0.1},
            "half_cone": {"dist": "normal", "u": 0.1}}}}).settings
    names = list(error_inputs(settings, 4, 2))
    declared = [row.name for row in INPUTS if row.name in names]
    assert names == declared


def test_the_scratch_rows_of_the_compiled_motion_model_do_not_overlap():
    """Each named block of the kernels' scratch has rows of its own, and the arrays have
    exactly the rows the blocks need."""
    for blocks, starts, total in (
            (fusedmotionkernels.WORK_BLOCKS, fusedmotionkernels.WORK,
             fusedmotionkernels.WORK_ROWS),
            (fusedmotionkernels.STATE_BLOCKS, dict(zip(("value", "rate", "trig"), (
                fusedmotionkernels._VALUE, fusedmotionkernels._RATE_ROW,
                fusedmotionkernels._TRIG))), fusedmotionkernels.STATE_ROWS)):
        assert kernelbase.overlapping(blocks, starts) == []
        assert total == sum(rows for _, rows in blocks)
        used = sorted(r for name, rows in blocks for r in range(starts[name],
                                                                  starts[name] + rows))
        assert used == list(range(total))
    bad = (("a", 2), ("b", 1))
    assert kernelbase.overlapping(bad, {"a": 0, "b": 1}) == [("a", "b")]
    with pytest.raises(ValueError, match="'a': a name used twice"):
        kernelbase.row_layout((("a", 1), ("a", 2)))


def test_the_static_kernel_refuses_an_unknown_correction_code():
    """A model code outside NONE..FULL (pointwise is the time-resolved model's) fails in
    the kernel instead of running some branch."""
    scene = scene_for("ins_heading", STATIC, None)
    table, shapes = fused.make_scene_table(scene)
    structure = np.array([4, 0, 2, kernelbase.POINTWISE, 1, 0, 0, 0, 0], dtype=np.int64)
    zero = np.zeros((1, 1, 1))
    kernels = fusedkernels.compiled(float)
    out = np.empty((1, 2, 1))
    with pytest.raises(ValueError, match="unknown correction model code"):
        kernels["wind_scan"](table, shapes, structure, (zero,) * 6, zero,
                             np.ones((4, 4, 1)), np.zeros((4, 4, 1)), np.zeros((1, 4, 3)),
                             np.ones((1, 4, 2)), zero, 0, 1, 0, 1, False, False, out, out,
                             out, out, np.empty((1, 1, 1, 1)), out)
