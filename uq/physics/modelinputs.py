"""The model's random inputs and correction models, declared once.

Every random input of the measurement model is one row of :data:`INPUTS`: its engine
name (the keyword of :func:`uq.physics.measurement.measurement_model`), the scenario key
that declares it, its unit, the shape of its draws, whether it is an angle, its label in
the uncertainty budget, and the models that implement it. Every other table of inputs is
derived from these rows: the scenario validator's key lists, the engine inputs of a
scenario (:mod:`uq.pipeline.modelsetup`), the budget labels, the units in the results'
metadata and in ``docs/scenario.md``, the names each model accepts, and the parameters of
the tests. A model refuses a name it does not implement (:func:`check_names`), and the
compiled models decline one they lack (the numpy model then evaluates it).

The correction models are :class:`Correction`, an ``IntEnum`` whose values are the codes
of both compiled kernel modules (:mod:`uq.physics.fusedkernels`,
:mod:`uq.physics.fusedmotionkernels`).

Shapes of the draws (n trials; ``k`` = 1 for INS errors shared by the beams of a scan,
the number of beams for one reading per beam):

============  =======================  ==================================================
shape         array                    meaning
============  =======================  ==================================================
``reading``   (n,) or (n, k)           an INS reading's error: per scan, or per beam
``scan``      (n,)                     one draw per scan
``beam_gate`` (n, beams, gates)        one draw per beam and range gate
``phase``     (n, K, 2)                unit phase vectors of K motion components
============  =======================  ==================================================

Adding an error input is a row here plus its physics in the numpy model(s) it names
(README, "Developer notes"); ``tests/physics/test_modelinputs.py`` checks that every
declared input changes the outputs of every model that claims it.
"""
import enum
import logging
from dataclasses import dataclass

log = logging.getLogger(__name__)

#: The models (the values of :attr:`ModelInput.models`): the static and the time-resolved
#: measurement model, each in numpy (the reference) and compiled (numba).
STATIC, STATIC_COMPILED = "static", "static compiled"
MOTION, MOTION_COMPILED = "time-resolved", "time-resolved compiled"
MODELS = (STATIC, STATIC_COMPILED, MOTION, MOTION_COMPILED)
#: The two numpy reference models and the two compiled ones.
NUMPY_MODELS, COMPILED_MODELS = (STATIC, MOTION), (STATIC_COMPILED, MOTION_COMPILED)
#: The kinds of draw shape (module docstring).
SHAPES = ("reading", "scan", "beam_gate", "phase")

_ALL = frozenset(MODELS)
_NUMPY = frozenset(NUMPY_MODELS)
_MOTION = frozenset((MOTION, MOTION_COMPILED))


class Correction(enum.IntEnum):
    """Motion-correction models (:mod:`uq.physics.correction`); the value is the code the
    compiled kernels take. ``Correction.of("full")`` -> ``Correction.FULL``."""

    NONE = 0          # no correction: the lidar frame assumed level, at the nominal heading
    YAW = 1           # the INS heading only
    TILT2D = 2        # Rubio & Gottschall (2022) Eq. 13: the mean pitch/roll reading
    FULL = 3          # one INS reading per scan: attitude and ship velocity
    POINTWISE = 4     # each beam at its own reading, lever arm included (Matavar 2024)

    @property
    def key(self):
        """The scenario's name of the model (``correction: full``)."""
        return self.name.lower()

    @classmethod
    def of(cls, name):
        """The model called `name` in a scenario; ValueError naming the allowed ones."""
        for model in cls:
            if model.key == name:
                return model
        raise ValueError(f"unknown correction model {name!r}; allowed: "
                         f"{', '.join(m.key for m in cls)}")


@dataclass(frozen=True)
class ModelInput:
    """One random input of the measurement model.

    Attributes
    ----------
    name : str
        Engine input name, the model's keyword (``ins_heading``).
    key : str
        Scenario key that declares it (``ins.heading``); for an input that a section makes
        (the motion's phases), that section's key.
    unit : str
        Unit of the draws and of the scenario's error sizes, in UDUNITS (``degree``).
    shape : str
        One of :data:`SHAPES`.
    angular : bool
        An angle in degrees (the model turns it into radians).
    label : str
        Its line in the uncertainty budget (the ``input`` coordinate).
    models : frozenset of str
        The models of :data:`MODELS` that implement it.
    meaning : str
        What it is, in words (``docs/scenario.md``).
    """

    name: str
    key: str
    unit: str
    shape: str
    angular: bool
    label: str
    models: frozenset
    meaning: str

    @property
    def section(self):
        """``ins``, ``lidar`` or ``motion``: the scenario section of :attr:`key`."""
        return self.key.split(".")[0]

    @property
    def holds_distribution(self):
        """Its scenario key holds its error distribution (``ins.heading: {dist: ...}``),
        rather than a setting it is derived from (``ins.rate``, ``motion``)."""
        return self.name.split("_", 1)[1] == self.short_key and self.section != "motion"

    @property
    def short_key(self):
        """The key within its section's error mapping (``ins.heading`` -> ``heading``,
        ``lidar.errors.height`` -> ``height``)."""
        return self.key.split(".")[-1]


def _row(name, key, unit, shape, angular, models, meaning, label=None):
    return ModelInput(name, key, unit, shape, angular, label or key, models, meaning)


#: Every random input, in the order the engine draws them (the order fixes the streams of
#: random numbers: a new row goes at the end of its section, never between old ones).
INPUTS = (
    _row("ins_heading", "ins.heading", "degree", "reading", True, _ALL,
         "error of the INS heading: turns the whole corrected wind"),
    _row("ins_pitch", "ins.pitch", "degree", "reading", True, _ALL,
         "error of the INS pitch (bow up): tilts the corrected beams about the "
         "athwartship axis"),
    _row("ins_roll", "ins.roll", "degree", "reading", True, _ALL,
         "error of the INS roll (starboard down): tilts the corrected beams about the "
         "fore-and-aft axis"),
    _row("ins_sog", "ins.sog", "m s-1", "reading", False, _ALL,
         "error of the INS speed over ground, along the course: enters the wind whole "
         "where the correction removes the platform velocity"),
    _row("ins_cog", "ins.cog", "degree", "reading", True, _ALL,
         "error of the INS course over ground: turns the removed horizontal velocity "
         "(matters in proportion to sog)"),
    _row("ins_heave", "ins.heave", "m s-1", "reading", False, _ALL,
         "error of the INS vertical velocity (positive up): enters the vertical wind of "
         "full and pointwise"),
    _row("lidar_half_cone", "lidar.errors.half_cone", "degree", "scan", True, _ALL,
         "true minus configured half-cone angle (common to all beams: the scanner)"),
    _row("lidar_misalignment", "lidar.errors.misalignment", "degree", "scan", True, _ALL,
         "true minus configured misalignment, the lidar's heading relative to the bow "
         "(the mounting)"),
    _row("lidar_radial_velocity", "lidar.errors.radial_velocity", "m s-1", "beam_gate",
         False, _ALL, "noise of each radial velocity"),
    _row("lidar_height", "lidar.errors.height", "m", "scan", False, _ALL,
         "true minus configured height of the lidar above sea level (draft, ballast, tide)"),
    _row("lidar_gate_length", "lidar.errors.gate_length", "m", "scan", False, _ALL,
         "true minus configured range-gate length of a pulsed probe"),
    _row("lidar_pulse_fwhm", "lidar.errors.pulse_fwhm", "m", "scan", False, _ALL,
         "true minus configured pulse FWHM of a pulsed probe"),
    _row("lidar_wavelength", "lidar.errors.wavelength", "um", "scan", False, _ALL,
         "true minus configured wavelength of a CW probe"),
    _row("lidar_beam_radius", "lidar.errors.beam_radius", "mm", "scan", False, _ALL,
         "true minus configured beam radius at the lens of a CW probe"),
    _row("motion_phases", "motion", "1", "phase", False, _MOTION,
         "unit phase vectors of the random-phase motion components (uniform on the circle)",
         label="motion (phases)"),
    _row("motion_window", "motion.series", "1", "phase", False, _MOTION,
         "where in a measured motion record the scan falls (a unit phase per period)",
         label="motion.series (window)"),
    _row("ins_clock_offset", "ins.clock_offset", "s", "scan", False, _MOTION,
         "INS clock minus lidar clock"),
    _row("ins_sample_offset", "ins.rate", "s", "scan", False, _MOTION,
         "time of the INS's first sample in the scan, uniform over one sampling period",
         label="ins.rate (sampling)"),
)

def input_named(name):
    """The row of engine input `name`; KeyError naming the declared ones."""
    for row in INPUTS:
        if row.name == name:
            return row
    raise KeyError(f"{name!r} is not a declared model input (uq.physics.modelinputs."
                   f"INPUTS: {', '.join(r.name for r in INPUTS)})")


def names(model):
    """Engine names of the inputs `model` implements, in declaration order."""
    return tuple(row.name for row in INPUTS if model in row.models)


def error_keys(section):
    """Short keys of a scenario section's error distributions, in declaration order:
    ``ins`` -> the INS readings' errors (``ins.heading`` ... ``ins.heave``), ``lidar`` ->
    the keys of ``lidar.errors``."""
    if section == "ins":
        return navigation_keys()
    return tuple(row.short_key for row in INPUTS if row.key.startswith(f"{section}.errors."))


def navigation_keys(angular_only=False):
    """The quantities the INS reports with an error (``heading`` ... ``heave``), or the
    angles among them."""
    return tuple(row.short_key for row in INPUTS if row.shape == "reading"
                 and (row.angular or not angular_only))


def error_units():
    """Short key -> unit of every error distribution of ``ins`` and ``lidar.errors``
    (``heading`` -> ``degree``, ``clock_offset`` -> ``s``): the inputs whose scenario key
    holds their distribution (not ``ins.rate``, whose input is derived from it)."""
    return {row.short_key: row.unit for row in INPUTS if row.holds_distribution}


def label(name):
    """Budget label of engine input `name` (its scenario key unless declared otherwise)."""
    return input_named(name).label


def check_names(model, given):
    """Refuse input names `model` does not implement: ValueError naming them and the
    model (a name no model knows is named as such)."""
    unknown = lacks(model, given)
    if unknown:
        known = names(model)
        declared = {row.name for row in INPUTS}
        what = ", ".join(f"{name!r}" + ("" if name in declared else " (not a declared "
                                         "model input)") for name in unknown)
        raise ValueError(f"the {model} model does not implement the input(s) {what}; it "
                         f"takes {', '.join(sorted(known))}")


def lacks(model, given):
    """Names among `given` that `model` does not implement (empty: it takes them all)."""
    known = set(names(model))
    return tuple(name for name in given if name not in known)


#: (model, reason) pairs already logged: a fall-back is said once per process.
_LOGGED = set()


def log_fallback(model, reason):
    """Say at ``-v`` (INFO) that the compiled `model` declined a call and why, once per
    reason (the numpy model then evaluates it)."""
    if reason and (model, reason) not in _LOGGED:
        _LOGGED.add((model, reason))
        log.info("the %s model does not take this call (%s): the numpy model evaluates it",
                 model, reason)
