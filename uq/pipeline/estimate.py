"""The size of a run and an estimate of its time, for ``uq check``: counted from the
validated scenario, never by running the model.

Size: scenes (the sweep's outer product), Monte Carlo trials per scene (``sampling.n``,
or the range adaptive sampling can take), range gates, beams, and in record mode the
records per scene and the scans per record.

Time: a sum of calibrated costs, each a CPU time per unit of work measured by
``scripts/calibrate_estimate.py`` (marginal costs: the difference of two runs of a
shipped scenario at two sizes, so that fixed costs cancel) on the project's 2-core
machine with numba's cache warm:

* a trial of the static compiled model, per range gate (:data:`COSTS` ``static``);
* a trial of a probe volume (pulsed or CW), per gate (``probe``);
* a trial of the time-resolved model, per gate (``motion``) and per beam and motion
  component (``component``: the attitude's sines and cosines);
* a scene's own work (the GUM, the paper's model, its part of the results), per beam
  and gate (``scene``; ``motion_scene`` for the time-resolved model, whose GUM the numpy
  model evaluates);
* a record of Mann turbulence, per second of record (``record``: its turbulence box,
  which grows with the record's length, dominates; Kaimal records are not estimated:
  their cost does not follow the same law);
* the command's fixed cost (``fixed``: start, imports, writing the file).

The estimate is CPU time: a run on an idle machine takes about as long on the clock, a
busy one longer; the first run after an install runs the numpy model while its kernels
compile in the background (``uq run --model auto``, :data:`FIRST_RUN_FACTOR`). It is
meant to tell a run of seconds from one of minutes or hours, within a factor of ~2.
"""
import math
from dataclasses import dataclass

from uq.constants import ADAPTIVE_MAX_SAMPLES, RNG_BLOCK_SIZE

#: Calibrated costs [s] per unit (see the module docstring); measured with
#: ``python scripts/calibrate_estimate.py`` on the 2-core development machine (CPU time,
#: cache warm, load ~10 from other work: the marginal costs of CPU time hold under load).
COSTS = {
    "static": 1.5e-7,        # per trial and gate (rubio2022_case_i; floating_lidar_full 2.8e-7)
    "probe": 1.3e-6,         # per trial and gate (probe_volume, pulsed, 9 gates)
    "motion": 7.0e-7,        # per trial and gate (nacelle_floating, less its components)
    "component": 9.5e-8,     # per trial, beam and motion component (floating_lidar_waves)
    "scene": 3.5e-6,         # per scene, beam and gate (tiana2017_vad_static, 50 beams)
    "motion_scene": 6.2e-5,  # per scene, beam and gate (tiana2017_vad)
    "record": 4.7e-3,        # per record and second of it (sathe2011_ti, Mann, pulsed)
    "fixed": 1.9,            # the command's start and imports (README: 1.87 s)
}
#: A first run's wall time over the same run's with numba's cache filled, at most [1]:
#: measured on an idle 2-core machine, 1.5x on the shipped scenarios
#: (floating_lidar_waves 4.4 s against 3.0 s, in uq bench) and 1.5-1.9x on
#: rubio2022_misalignment at 5 x 10^4 to 2 x 10^5 trials a scene (1.9x at 7.5 x 10^4,
#: where the compile ends a third of the way into the run; uq.constants.
#: BACKGROUND_BESIDE_MIN_MODEL_CPU_S).
FIRST_RUN_FACTOR = 2
#: Fewest RNG blocks adaptive sampling draws before its stopping rule can be met.
ADAPTIVE_MIN_BLOCKS = 2


@dataclass(frozen=True)
class RunSize:
    """What a run computes, and the estimate of its CPU time.

    Attributes
    ----------
    scenes : int
    trials : tuple of int
        (fewest, most) Monte Carlo trials per scene: equal for ``sampling.n``, the range
        of adaptive sampling, (0, 0) for ``sampling.method: none``.
    gates, beams : int
    records, scans : int
        Monte Carlo records per scene and scans per record (0 outside record mode, or
        with method none).
    seconds : tuple of float
        (fewest, most) estimated CPU seconds; NaN where a part is not estimated.
    parts : tuple of (str, float)
        What each cost contributes at the fewest trials [s], in words.
    """

    scenes: int
    trials: tuple
    gates: int
    beams: int
    records: int
    scans: int
    seconds: tuple
    parts: tuple

    def model_seconds(self):
        """Estimated CPU seconds of the run's model at the fewest trials: its parts but
        the command's start (``fixed``) and the records' boxes and statistics."""
        return sum(seconds for name, seconds in self.parts
                   if name not in ("fixed", "records"))

    def describe(self):
        """The size in words: ``36 scenes x 100000 trials, 1 gate``."""
        low, high = self.trials
        scenes = f"{self.scenes} scene{'s' * (self.scenes != 1)}"
        if high == 0:
            trials = f"{scenes}, no Monte Carlo (GUM only)"
        elif low == high:
            trials = f"{scenes} x {low} trials"
        else:
            trials = f"{scenes} x {low}-{high} trials (adaptive)"
        text = f"{trials}, {self.gates} gate{'s' * (self.gates != 1)}, {self.beams} beams"
        if self.records:
            text += f"; {self.scenes * self.records} records of {self.scans} scans"
        return text

    def estimate(self):
        """The estimate in words, with how it was made."""
        low, high = self.seconds
        if not math.isfinite(low):
            return ("run time not estimated (Kaimal records: no calibrated cost); "
                    + self._how())
        span = _duration(low) if high <= 1.5 * low else \
            f"{_duration(low)} to {_duration(high)}"
        return f"estimated run time ~{span} of CPU; {self._how()}"

    def _how(self):
        parts = ", ".join(f"{name} {_duration(seconds)}" for name, seconds in self.parts
                          if seconds >= 0.05 * max(s for _, s in self.parts))
        return (f"from calibrated per-trial costs, not by running the model ({parts}; "
                f"2-core machine; a busy machine takes longer, and the first run after an "
                f"install up to {FIRST_RUN_FACTOR:g}x longer: the numpy model runs until a "
                "background process has compiled the kernels)")


def _duration(seconds):
    if seconds < 90:
        return f"{seconds:.2g} s"
    if seconds < 5400:
        return f"{seconds / 60:.2g} min"
    return f"{seconds / 3600:.2g} h"


def run_size(scenario):
    """The :class:`RunSize` of a validated scenario (its settings as given; swept
    structural keys are costed as the scenario's own values)."""
    from uq.pipeline import motionsection
    from uq.pipeline.turbulencesection import scans_per_record
    settings = scenario.settings
    lidar = settings["lidar"]
    scenes = math.prod(len(values) for _, values in scenario.sweep)
    gates = len(lidar["ranges"])
    beams = len(lidar["azimuths"]) + int(lidar["vertical_beam"])
    sampling = settings["sampling"]
    if sampling["method"] == "none":
        trials = (0, 0)
    elif "digits" in sampling:
        trials = (ADAPTIVE_MIN_BLOCKS * RNG_BLOCK_SIZE, ADAPTIVE_MAX_SAMPLES)
    else:
        trials = (sampling["n"], sampling["n"])
    per_trial = []
    moving = motionsection.is_time_resolved(settings)
    if moving:
        components = len(motionsection.time_resolved(settings).motion.components)
        per_trial += [("time-resolved model", COSTS["motion"] * gates),
                      ("motion components", COSTS["component"] * beams * components)]
    else:
        per_trial.append(("static model", COSTS["static"] * gates))
    if (lidar.get("probe") or {}).get("kind", "point") != "point":
        per_trial.append(("probe volume", COSTS["probe"] * gates))
    records = scans = 0
    record_seconds = 0.0
    if "turbulence" in settings and sampling["method"] != "none":
        records, scans = settings["record"]["count"], scans_per_record(settings)
        record_seconds = math.nan if settings["turbulence"]["model"] != "mann" else \
            COSTS["record"] * records * settings["record"]["duration"]
    parts = [(name, scenes * trials[0] * cost) for name, cost in per_trial]
    parts += [("per scene", COSTS["motion_scene" if moving else "scene"] * scenes * beams
               * gates), ("fixed", COSTS["fixed"])]
    if records:
        parts.append(("records", scenes * record_seconds))
    trial_cost = sum(cost for _, cost in per_trial)
    low = sum(seconds for _, seconds in parts)
    high = low + scenes * (trials[1] - trials[0]) * trial_cost
    return RunSize(scenes=scenes, trials=trials, gates=gates, beams=beams, records=records,
                   scans=scans, seconds=(low, high),
                   parts=tuple((n, s) for n, s in parts if math.isfinite(s)))
