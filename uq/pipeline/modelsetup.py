"""The seam between validated settings and the physics: the nominal scene and the engine
inputs of a scenario, their budget labels, and what the model skipped.

Settings are in scenario units (degrees, the units of ``docs/scenario.md``); the
:class:`uq.physics.scene.Scene` they build is in SI units and radians. The engine inputs
are named and shaped as :mod:`uq.physics.modelinputs` declares them (every input is one
row there; this module reads the settings of each row).
"""
import numpy as np

from uq.engine.inputs import Input, UniformCircle
from uq.physics import modelinputs
from uq.physics.ins import gauss_markov_correlation
from uq.physics.scene import OUTPUTS, Scene
from uq.pipeline import motionsection, probesection
from uq.pipeline.distributions import error_distribution

#: Inputs that are the motion itself (random phases and when the INS samples it).
MOTION_INPUTS = ("motion_phases", "motion_window", "ins_sample_offset")


def scene_from_settings(settings):
    """The nominal :class:`Scene` (SI, radians) of validated settings (degrees).

    Examples
    --------
    >>> from uq.pipeline.scenario import load_scenario
    >>> scene = scene_from_settings(load_scenario({"wind": {"direction": 90.0}}).settings)
    >>> round(float(scene.wind_direction), 6), scene.n_beams, scene.correction
    (1.570796, 4, 'full')
    """
    w, s, lid = settings["wind"], settings["ship"], settings["lidar"]
    rad = np.deg2rad
    return Scene(
        wind_speed=w["speed"], wind_direction=rad(w["direction"]), vertical_wind=w["vertical"],
        shear=w["shear"], reference_height=w["reference_height"],
        sog=s["sog"], cog=rad(s["cog"]), heading=rad(s["heading"]), pitch=rad(s["pitch"]),
        roll=rad(s["roll"]), heave=s["heave"],
        lidar_height=lid["height"], ranges=tuple(lid["ranges"]), half_cone=rad(lid["half_cone"]),
        misalignment=rad(lid["misalignment"]), azimuths=tuple(rad(lid["azimuths"])),
        vertical_beam=lid["vertical_beam"], correction=settings["correction"],
        time_resolved=motionsection.time_resolved(settings),
        probe=probesection.make_probe(lid.get("probe")),
        tilt=rad(lid["mount"]["tilt"]) if "mount" in lid else 0.0)


def error_inputs(settings, n_beams, n_gates):
    """Engine inputs (name -> distribution, float or Input) of the declared errors, in
    the order of :data:`uq.physics.modelinputs.INPUTS` (which fixes the random streams).

    INS errors: one per scan (``scan``), one per beam (``beam``), or with a
    ``correlation_time`` tau a Gauss-Markov process over the beams' time stamps
    (correlation ``exp(-|t_k - t_l| / tau)``; tau = inf is one per scan). Time-resolved
    scans add the unit phases of the random-phase motion components
    (:class:`uq.engine.inputs.UniformCircle`), the clock offset and, for a sampled INS,
    the offset of its samples (uniform over one period). Errors of the probe's parameters
    (``lidar.errors.gate_length`` ...) are one draw per scan, in scenario units; those of
    a parameter the probe's kind does not use stay inputs without effect (so that every
    value of a swept ``lidar.probe.kind`` has the same inputs).
    """
    inputs = {}
    beam_mode = settings["ins"]["correlation"] == "beam"
    for key in modelinputs.error_keys("ins"):
        if key in settings["ins"]:
            inputs[f"ins_{key}"] = _ins_input(settings, key, n_beams, beam_mode)
    for key, spec in settings["lidar"]["errors"].items():
        dist = error_distribution(spec)
        shaped = modelinputs.input_named(f"lidar_{key}").shape == "beam_gate" and \
            not isinstance(dist, float)
        inputs[f"lidar_{key}"] = Input(dist, (n_beams, n_gates)) if shaped else dist
    inputs.update(_motion_inputs(settings))
    return inputs


def _ins_input(settings, key, n_beams, beam_mode):
    """One INS error: per scan, per beam, or Gauss-Markov over the beams' stamps."""
    spec = settings["ins"][key]
    dist = error_distribution({k: v for k, v in spec.items() if k != "correlation_time"})
    if isinstance(dist, float):
        return dist
    tau = spec.get("correlation_time")
    if tau is None:
        return Input(dist, (n_beams,)) if beam_mode else dist
    if tau == np.inf:
        return dist                                   # the limit: one error per scan
    stamps = motionsection.beam_stamps(settings, n_beams)
    return Input(dist, (n_beams,), correlation=gauss_markov_correlation(stamps, tau))


def _motion_inputs(settings):
    """The inputs of a time-resolved scan: phases, a record's window, INS timing."""
    inputs = {}
    random = motionsection.random_phase_count(settings)
    if random:
        inputs["motion_phases"] = Input(UniformCircle(1.0), (random, 2))
    series, window = motionsection.series_motion(settings.get("motion") or {})
    if series:
        inputs["motion_window"] = Input(window, (len(series), 2))
    ins = settings["ins"]
    if "clock_offset" in ins:
        inputs["ins_clock_offset"] = error_distribution(ins["clock_offset"])
    if "rate" in ins and motionsection.is_time_resolved(settings):
        period = 1.0 / ins["rate"]
        inputs["ins_sample_offset"] = error_distribution(
            {"dist": "uniform", "half_width": period / 2, "mean": period / 2})
    return inputs


def input_label(name):
    """Budget label of an engine input: its dotted scenario key (``ins_sog`` ->
    ``ins.sog``), or the label declared for it (``motion_phases`` -> ``motion (phases)``).

    Examples
    --------
    >>> input_label("ins_sog"), input_label("lidar_height"), input_label("motion_phases")
    ('ins.sog', 'lidar.errors.height', 'motion (phases)')
    """
    return modelinputs.input_named(name).label


def skipped_work(settings, outputs, probe_kinds=()):
    """What the model did not compute for this scenario, in words (the ``skipped``
    attribute): each line names a shortcut the measurement model took. `probe_kinds`: the
    values of a swept ``lidar.probe.kind`` (default: the scenario's kind)."""
    lidar, ins = settings["lidar"], settings["ins"]
    lines = [f"input not sampled (no error declared): {key}" for key in
             [f"ins.{k}" for k in modelinputs.error_keys("ins") if k not in ins]
             + [f"lidar.errors.{k}" for k in modelinputs.error_keys("lidar")
                if k not in lidar["errors"] and k not in probesection.PROBE_ERROR_KEYS]]
    if not ({"half_cone", "misalignment"} & set(lidar["errors"])):
        lines.append("true beams and true radial velocities computed once per scene, not "
                     "per trial (no geometry errors)")
    if settings["correction"] in ("none", "yaw"):
        lines.append(f"correction '{settings['correction']}': no pitch/roll rotation")
    lines += [f"output not requested, not computed: {q}" for q in OUTPUTS if q not in outputs]
    if "probe" in lidar:
        for kind in probe_kinds or (lidar["probe"]["kind"],):
            lines += [f"probe parameter error without effect where lidar.probe.kind is "
                      f"{kind} (it does not use it): lidar.errors.{key}"
                      for key in probesection.unused_errors(settings, kind)]
        lines.append("probe volume: evaluated by the numpy model (the compiled model is "
                     "point-wise)")
    return "; ".join(lines) or "nothing"
