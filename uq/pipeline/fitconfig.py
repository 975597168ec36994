"""The ``fit`` section of a scenario or fit configuration: a validated, frozen FitConfig.

.. code-block:: yaml

    fit:
      profile: power_law          # power_law | log_law (uq.physics.profiles.PROFILES)
      reference_height: 100.0     # m, z_ref of the power law
      scatter: true               # free extra scatter ln_sigma (turbulence)
      priors:                     # per parameter; defaults: uq.fit.bayesfit.DEFAULT_PRIORS
        shear: {dist: uniform, low: -0.5, high: 1.0}
        roughness_length: {dist: log_uniform, low: 1.0e-6, high: 1.0}
        reference_speed: {dist: normal, mean: 9.0, u: 2.0}
      walkers: 32                 # 32 to 1024
      ensembles: 4                # independent ensembles for R-hat, 2 to 64
      max_steps: 50000            # per ensemble (100 to 10^6); not converged -> error
                                  # walkers x ensembles x max_steps <= 10^7
      seed: 1                     # emcee State random_state; same seed, same chains
      columns: {height: height, speed: speed}   # CSV input: column names
                                                # (optional: speed_u, height_u)
"""
from dataclasses import dataclass, field

from uq.constants import (MAX_ENSEMBLES, MAX_FIT_DRAWS, MAX_FIT_STEPS, MAX_WALKERS,
                          MIN_WALKERS)
from uq.physics.profiles import PROFILES

PRIOR_KINDS = ("uniform", "log_uniform", "normal")
FIT_KEYS = ("profile", "reference_height", "scatter", "priors", "walkers", "ensembles",
            "max_steps", "seed", "columns")
COLUMN_KEYS = ("height", "speed", "speed_u", "height_u")
DEFAULT_COLUMNS = {"height": "height", "speed": "speed"}


@dataclass(frozen=True)
class FitConfig:
    """Settings of ``uq fit`` (see the module docstring for units and meaning)."""

    profile: str = "power_law"
    reference_height: float = 100.0
    scatter: bool = True
    priors: dict = field(default_factory=dict)
    walkers: int = MIN_WALKERS
    ensembles: int = 4
    max_steps: int = 50_000
    seed: int = 1
    columns: dict = field(default_factory=lambda: dict(DEFAULT_COLUMNS))

    @property
    def fixed(self):
        """Fixed keyword arguments of the profile function."""
        return {"reference_height": self.reference_height} if self.profile == "power_law" else {}

    def to_dict(self):
        """The YAML form (validate_fit of it gives the same config)."""
        priors = {name: {"dist": kind, "mean": a, "u": b} if kind == "normal"
                  else {"dist": kind, "low": a, "high": b}
                  for name, (a, b, kind) in self.priors.items()}
        return {"profile": self.profile, "reference_height": self.reference_height,
                "scatter": self.scatter, "priors": priors,
                "walkers": self.walkers, "ensembles": self.ensembles,
                "max_steps": self.max_steps, "seed": self.seed, "columns": dict(self.columns)}


def validate_fit(check, value):
    """FitConfig from a ``fit`` mapping; `check` is the scenario checker (errors name
    the file and the key)."""
    value = {} if value is None else value
    check.mapping(value, "fit")
    check.keys(value, "fit", FIT_KEYS)
    profile = check.choice(value.get("profile", "power_law"), "fit.profile", tuple(PROFILES))
    parameters = PROFILES[profile][1] + (("ln_sigma",) if value.get("scatter", True) else ())
    priors = value.get("priors") or {}
    check.mapping(priors, "fit.priors")
    check.keys(priors, "fit.priors", parameters)
    columns = value.get("columns") or {}
    check.mapping(columns, "fit.columns")
    check.keys(columns, "fit.columns", COLUMN_KEYS)
    walkers = check.integer(value.get("walkers", MIN_WALKERS), "fit.walkers", low=MIN_WALKERS,
                            high=MAX_WALKERS)
    ensembles = check.integer(value.get("ensembles", 4), "fit.ensembles", low=2,
                              high=MAX_ENSEMBLES)
    max_steps = check.integer(value.get("max_steps", 50_000), "fit.max_steps", low=100,
                              high=MAX_FIT_STEPS)
    check.limit("fit.max_steps", f"walkers x ensembles x max_steps at most {MAX_FIT_DRAWS:,}")
    if walkers * ensembles * max_steps > MAX_FIT_DRAWS:
        check.fail("fit.max_steps", f"walkers x ensembles x max_steps = {walkers} x "
                   f"{ensembles} x {max_steps} draws; allowed: at most {MAX_FIT_DRAWS} (the "
                   "chains are kept in memory)")
    return FitConfig(
        profile=profile,
        reference_height=check.number(value.get("reference_height", 100.0),
                                      "fit.reference_height", low=0.0, low_open=True),
        scatter=check.boolean(value.get("scatter", True), "fit.scatter"),
        priors={name: _prior(check, spec, f"fit.priors.{name}") for name, spec in priors.items()},
        walkers=walkers, ensembles=ensembles, max_steps=max_steps,
        seed=check.integer(value.get("seed", 1), "fit.seed", low=0),
        columns={**DEFAULT_COLUMNS, **{k: check.text(v, f"fit.columns.{k}")
                                       for k, v in columns.items()}})


def _prior(check, spec, key):
    """(low, high, kind) for uniform / log_uniform, (mean, u, "normal") for normal."""
    check.mapping(spec, key)
    kind = check.choice(spec.get("dist"), f"{key}.dist", PRIOR_KINDS)
    if kind == "normal":
        check.keys(spec, key, ("dist", "mean", "u"))
        return (check.number(spec.get("mean"), f"{key}.mean"),
                check.number(spec.get("u"), f"{key}.u", low=0.0, low_open=True), kind)
    check.keys(spec, key, ("dist", "low", "high"))
    low = check.number(spec.get("low"), f"{key}.low", low=0.0 if kind == "log_uniform" else None,
                       low_open=kind == "log_uniform")
    high = check.number(spec.get("high"), f"{key}.high")
    if high <= low:
        check.fail(key, f"high ({high:g}) must be above low ({low:g})")
    return (low, high, kind)


__all__ = ["FitConfig", "validate_fit"]
