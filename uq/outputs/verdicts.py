"""The JCGM 101 clause 8 verdicts of a result, in words a reader can act on.

Clause 8 compares the GUM's 95 % interval y +- k u with the Monte Carlo one: the GUM is
validated where both endpoint differences d_low, d_high are within the tolerance delta,
half a unit of the last of the validation's significant digits of u (JCGM 101 7.9.2,
8.2). That comparison decides only where Monte Carlo's own numerical error of the
endpoints is within delta too (``q_gum_validation_conclusive``). So a scene is one of

* **validated**: both ends within delta, and Monte Carlo precise enough to say so;
* **not validated**: an end differs by more than delta, and Monte Carlo precise enough
  to say so: the GUM's Gaussian interval is not good to the digits asked, even where
  the GUM's u agrees closely with Monte Carlo's (the interval's centre or shape differs:
  a second-order bias of the mean, a skewed or heavy-tailed distribution);
* **undecided**: Monte Carlo's numerical error exceeds delta, so the run cannot tell
  (more trials, or ``sampling.digits`` with ``stop_when_gum_valid``, decide it).

Every number here is read from the results (``q_gum_valid``,
``q_gum_validation_conclusive``, ``q_gum_validation_tolerance``, the intervals); results
written before the tolerance was stored get it from the same rule (the GUM u at the
scenario's ``sampling.digits``, else :data:`uq.constants.DEFAULT_DIGITS`).

References
----------
.. [1] JCGM 101:2008, Evaluation of measurement data - Supplement 1 to the GUM:
   propagation of distributions using a Monte Carlo method, clauses 7.9 and 8.
"""
import numpy as np
import yaml

from uq.constants import DEFAULT_DIGITS
from uq.engine.gum import endpoint_differences, numerical_tolerance

VALIDATED, NOT_VALIDATED, UNDECIDED = "validated", "not validated", "undecided"
#: The verdicts in the order the text lists them.
VERDICTS = (VALIDATED, NOT_VALIDATED, UNDECIDED)
#: Quantities compared modulo 360 deg.
CIRCULAR = ("wind_direction", "yaw_misalignment")


def has_verdicts(dataset, quantity):
    """Can clause 8 be read for `quantity`: a GUM and a Monte Carlo interval?"""
    return all(f"{quantity}_{s}" in dataset for s in ("gum_valid", "mc_low", "mc_high",
                                                       "gum_value", "gum_u"))


def validation_digits(dataset):
    """Significant digits of u the validation used (``sampling.digits``, else the
    default of a fixed-n run)."""
    try:
        sampling = (yaml.safe_load(dataset.attrs.get("scenario", "")) or {}).get("sampling")
    except yaml.YAMLError:
        sampling = None
    digits = sampling.get("digits") if isinstance(sampling, dict) else None
    return int(digits) if digits else DEFAULT_DIGITS


def details(dataset, quantity):
    """Arrays (the shape of ``q_gum_valid``) of each value's clause 8 numbers.

    Returns
    -------
    dict
        ``verdict`` (object array of :data:`VERDICTS`), ``delta``, ``d_low``, ``d_high``
        (GUM minus Monte Carlo endpoints), ``error`` (Monte Carlo's numerical error),
        ``u_ratio`` (GUM u over Monte Carlo u), ``shift`` ((d_low + d_high) / 2: the
        intervals' centres apart), ``width`` ((d_high - d_low) / 2: half the difference of
        their widths), all in the quantity's units but ``verdict`` and ``u_ratio``.
    """
    at = {s: np.asarray(dataset[f"{quantity}_{s}"].values) for s in
          ("gum_value", "gum_u", "mc_low", "mc_high", "gum_valid")}
    d_low, d_high = endpoint_differences(at["gum_value"], at["gum_u"], at["mc_low"],
                                         at["mc_high"], circular=quantity in CIRCULAR)
    name = f"{quantity}_gum_validation_tolerance"
    delta = np.asarray(dataset[name].values) if name in dataset else \
        numerical_tolerance(at["gum_u"], validation_digits(dataset))
    conclusive = np.asarray(dataset[f"{quantity}_gum_validation_conclusive"].values,
                            dtype=bool)
    valid = at["gum_valid"].astype(bool)
    verdict = np.where(~conclusive, UNDECIDED, np.where(valid, VALIDATED, NOT_VALIDATED))
    error = dataset.get(f"{quantity}_mc_numerical_error")
    mc_u = dataset.get(f"{quantity}_mc_u")
    with np.errstate(divide="ignore", invalid="ignore"):
        u_ratio = at["gum_u"] / np.asarray(mc_u.values) if mc_u is not None else \
            np.full(valid.shape, np.nan)
    return {"verdict": verdict.astype(object), "delta": delta, "d_low": d_low,
            "d_high": d_high, "shift": (d_low + d_high) / 2, "width": (d_high - d_low) / 2,
            "error": np.asarray(error.values) if error is not None else
            np.full(valid.shape, np.nan), "u_ratio": u_ratio}


def counts(dataset, quantity):
    """``{verdict: count}`` over every value (scenes x range gates), in VERDICTS order."""
    verdict = details(dataset, quantity)["verdict"].reshape(-1)
    return {v: int(np.sum(verdict == v)) for v in VERDICTS}


def counts_text(dataset, quantity):
    """``2 validated, 4 not validated, 30 undecided of 36``: the verdicts counted."""
    found = counts(dataset, quantity)
    total = sum(found.values())
    parts = [f"{count} {verdict}" for verdict, count in found.items() if count]
    return f"{', '.join(parts)} of {total}"


def one(at, quantity, unit=""):
    """The verdict of one value (a Dataset of one scene and gate) and its numbers in
    one sentence: verdict, delta with its digits, the endpoint differences, Monte
    Carlo's numerical error, and what a refusal means where the u agree."""
    found = {k: np.asarray(v).reshape(-1)[0] for k, v in details(at, quantity).items()}
    unit = f" {unit}" if unit else ""
    digits = validation_digits(at)
    numbers = (f"delta {found['delta']:.2g}{unit} ({digits} significant digits of u); "
               f"GUM minus Monte Carlo ends {found['d_low']:+.2g}, {found['d_high']:+.2g}"
               f"{unit}; Monte Carlo's numerical error {found['error']:.2g}{unit}")
    verdict = found["verdict"]
    if verdict == VALIDATED:
        return f"validated: both ends within delta ({numbers})"
    if verdict == UNDECIDED:
        lean = "within" if max(abs(found["d_low"]), abs(found["d_high"])) <= found["delta"] \
            else "beyond"
        return (f"undecided: Monte Carlo's numerical error exceeds delta, so the ends, "
                f"{lean} delta at this sample, do not decide; more trials would "
                f"({numbers})")
    return f"not validated: {meaning(found, unit)} ({numbers})"


def meaning(found, unit=""):
    """What a conclusive refusal means, from the intervals' centre shift and width."""
    ratio = found["u_ratio"]
    agree = (f"the GUM's u is {100 * abs(ratio - 1):.2g} % from Monte Carlo's, but "
             if np.isfinite(ratio) else "")
    if abs(found["shift"]) > abs(found["width"]):
        return (f"{agree}the intervals' centres are {abs(found['shift']):.2g}{unit} apart "
                "(more than delta): the Monte Carlo distribution is shifted or skewed "
                "against the GUM's Gaussian (a second-order effect the first-order GUM "
                "leaves out)")
    wider = "wider" if found["width"] > 0 else "narrower"
    return (f"{agree}the GUM interval is {2 * abs(found['width']):.2g}{unit} {wider} than "
            "Monte Carlo's (more than delta): the distribution's tails are not Gaussian")
