"""Scenario keys of the probe volume: ``lidar.probe`` and the errors of its parameters
(``lidar.errors.<parameter>``); the physics is :mod:`uq.physics.probe`.

Absent (or ``{kind: point}``), the measurement is at the gate centre, as before the probe
existed: no key enters the validated settings unless given, so such a scenario is today's
bit for bit.

.. code-block:: yaml

    lidar:
      probe:
        kind: pulsed            # point | pulsed | cw
        gate_length: 30.0       # m, range-gate length (pulsed)
        pulse_fwhm: 22.5        # m, FWHM of the pulse in range (pulsed)
        wavelength: 1.565       # um (cw)
        beam_radius: 28.0       # mm, 1/e^2 radius of the beam at the lens (cw)
        truncation: 0.02        # the CW Lorentzian is cut where W < truncation W(0) (cw)
      errors:
        gate_length: {dist: normal, u: 1.0}      # m, one draw per scan
        beam_radius: {dist: uniform, half_width: 1.0}   # mm

The parameters of every kind may be given together, so that ``lidar.probe.kind`` can be
swept; a kind uses only its own (the ``skipped`` attribute of the results names any error
of a parameter the kind does not use: it stays an input, without effect, so that every
value of a swept kind has the same inputs).
"""
import math

from uq.physics.probe import PARAMETER_SCALE, PROBE_KINDS, ContinuousWaveProbe, PulsedProbe

#: Parameters each kind needs (scenario units: m, m; um, mm, 1).
KIND_PARAMETERS = {"point": (), "pulsed": ("gate_length", "pulse_fwhm"),
                   "cw": ("wavelength", "beam_radius", "truncation")}
PROBE_KEYS = ("kind",) + KIND_PARAMETERS["pulsed"] + KIND_PARAMETERS["cw"]
#: Probe parameters that may have an error distribution (``lidar.errors.<name>``).
PROBE_ERROR_KEYS = ("gate_length", "pulse_fwhm", "wavelength", "beam_radius")
#: Largest focus distance, as a fraction of ``pi a^2 / lambda`` (the Rayleigh length of
#: the collimated beam at the lens), for which ``z_R = lambda F^2 / (pi a^2)`` holds [1]:
#: the exact focused Gaussian beam has ``z_R / (1 + (F / (pi a^2 / lambda))^2)``, so at
#: this fraction the far-field Rayleigh length is 6 % too long (Siegman 1986, Lasers,
#: Sec. 17.1, focusing of a Gaussian beam by a thin lens).
MAX_FOCUS_FRACTION = 0.25


def validate_probe(check, value):
    """The validated ``lidar.probe`` mapping (scenario units)."""
    check.mapping(value, "lidar.probe")
    check.keys(value, "lidar.probe", PROBE_KEYS)
    kind = check.choice(value.get("kind", "point"), "lidar.probe.kind", PROBE_KINDS)
    check.required(value, "lidar.probe", KIND_PARAMETERS[kind],
                   f"kind {kind!r} needs {', '.join(KIND_PARAMETERS[kind])}")
    out = {"kind": kind}
    for name in ("gate_length", "pulse_fwhm", "wavelength", "beam_radius"):
        if name in value:
            out[name] = check.number(value[name], f"lidar.probe.{name}", low=0.0,
                                     low_open=True)
    if "truncation" in value:
        out["truncation"] = check.number(value["truncation"], "lidar.probe.truncation",
                                         low=0.0, high=1.0, low_open=True, high_open=True)
    return out


def check_probe(check, lidar):
    """Keys of the validated ``lidar`` section that only mean something together: an
    error of a probe parameter needs the parameter; a CW focus must lie in the far field
    of the lens (:data:`MAX_FOCUS_FRACTION`)."""
    probe = lidar.get("probe", {})
    check.limit("lidar.probe.beam_radius", f"a CW focus (the slant distance of the farthest "
                f"gate) at most {MAX_FOCUS_FRACTION:g} pi a^2 / lambda")
    for name in PROBE_ERROR_KEYS:
        if name in lidar["errors"] and name not in probe:
            check.fail(f"lidar.errors.{name}", f"an error of a probe parameter that "
                       f"lidar.probe does not give; allowed: give lidar.probe.{name}")
    if probe.get("kind") == "cw":
        radius = probe["beam_radius"] * PARAMETER_SCALE["beam_radius"]          # m
        reach = MAX_FOCUS_FRACTION * math.pi * radius ** 2 / (
            probe["wavelength"] * PARAMETER_SCALE["wavelength"])
        # the slanted beams' foci are the farthest (the vertical beam's is the range)
        farthest = max(lidar["ranges"]) / math.cos(math.radians(lidar["half_cone"]))
        if farthest > reach:
            check.fail("lidar.probe.beam_radius", f"the farthest focus ({farthest:.4g} m "
                       f"along the beam) is beyond {MAX_FOCUS_FRACTION:g} pi a^2 / lambda = "
                       f"{reach:.4g} m, where z_R = lambda F^2 / (pi a^2) no longer holds; "
                       "allowed: a larger beam radius or nearer ranges")


def unused_errors(settings, kind=None):
    """Errors of probe parameters that the probe's kind (or `kind`) does not use (they
    have no effect)."""
    lidar = settings["lidar"]
    kind = kind or lidar.get("probe", {}).get("kind", "point")
    return [name for name in PROBE_ERROR_KEYS
            if name in lidar["errors"] and name not in KIND_PARAMETERS[kind]]


def make_probe(settings):
    """The probe of a validated ``lidar.probe`` mapping (scenario units: m, m, um, mm), in
    SI units (:mod:`uq.physics.probe`), or None for a point (or absent) probe."""
    if not settings or settings["kind"] == "point":
        return None
    if settings["kind"] == "pulsed":
        return PulsedProbe(settings["gate_length"], settings["pulse_fwhm"])
    return ContinuousWaveProbe(settings["wavelength"] * PARAMETER_SCALE["wavelength"],
                               settings["beam_radius"] * PARAMETER_SCALE["beam_radius"],
                               settings["truncation"])


def describe(settings, swept=()):
    """The probe model in words (the results' ``probe`` attribute): each kind the
    scenario runs (``swept``: the values of a swept ``lidar.probe.kind``), with its
    parameters and, for CW, the truncation of the Lorentzian's tails."""
    probe = settings["lidar"].get("probe", {"kind": "point"})
    kinds = list(swept) or [probe["kind"]]
    lines = []
    for kind in kinds:
        if kind == "point":
            lines.append("point: the radial velocity at the gate centre")
        else:
            lines.append(make_probe({**probe, "kind": kind}).describe())
    return "; ".join(lines)
