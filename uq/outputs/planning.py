"""Campaign-planning answers from a finished results Dataset.

Pure functions of a Dataset (no I/O, no plotting) that return plain numbers and short
verdicts: the best misalignment, the largest velocity ratio that keeps u(Vh) under a
target, the dominant inputs of the uncertainty budget, where the paper's analytic model
and sampling disagree, the bias of the correction, and whether the stated findings of
Rubio & Gottschall (2022, Sec. 3) hold in each model. Averages over wind direction (and
over any other swept dimension not asked about) are plain means over the grid.

References
----------
.. [1] Rubio, H. and Gottschall, J. (2022). J. Phys.: Conf. Ser. 2362 012034.
"""
import numpy as np
import yaml

from uq.constants import FULL_CIRCLE_DEG, NUMERICAL_ZERO

MODEL_NAMES = {"paper_u": "paper (Rubio & Gottschall 2022)", "gum_u": "GUM, physical",
               "mc_u": "Monte Carlo, physical"}
#: Targets of the velocity-ratio answer when the user gives none [m s-1]: around the
#: u(Vh) of the paper's Table B2 set-up (0.045-0.07 m/s), so the answer is informative.
DEFAULT_TARGETS = (0.05, 0.06, 0.07)
#: Velocity ratios VR = sog / Vh of the paper's Fig. 4 [1].
VELOCITY_RATIOS = (0.5, 1.0, 2.0)
#: Standard errors of the Monte Carlo mean beyond which a bias counts as one (about a
#: 0.3 % chance per value for a normal mean without bias).
BIAS_STANDARD_ERRORS = 3
#: Relative size under which two uncertainties count as equal in a finding [1]: 0.5 %, far
#: above the GUM's rounding and below any effect the paper discusses (2 % and more).
EQUAL_WITHIN = 0.005


def uncertain(dataset, quantity):
    """Has `quantity` an uncertainty anywhere: some model's u above NUMERICAL_ZERO?"""
    return any(np.nanmax(np.abs(dataset[f"{quantity}_{m}"].values), initial=0.0) > NUMERICAL_ZERO
               for m in models(dataset, quantity))


def models(dataset, quantity):
    """Uncertainty variables of `quantity` present and not all NaN, as suffixes."""
    return [m for m in MODEL_NAMES if f"{quantity}_{m}" in dataset
            and np.isfinite(dataset[f"{quantity}_{m}"].values).any()]


def mean_over(dataset, name, keep):
    """Mean of `name` over every grid dimension except `keep` (and range gates)."""
    variable = dataset[name]
    drop = [d for d in variable.dims if d not in keep]
    return variable.mean(drop)


def misalignment_answer(dataset, quantity="wind_speed"):
    """Best and worst misalignment per model, from u averaged over everything else.

    Returns
    -------
    dict
        model -> {"best", "worst" [deg], "u_best", "u_worst", "gain" (1 - u_best/u_worst)}.
    """
    answer = {}
    for model in models(dataset, quantity):
        curve = mean_over(dataset, f"{quantity}_{model}", ("lidar_misalignment",))
        best, worst = int(np.argmin(curve.values)), int(np.argmax(curve.values))
        x = dataset["lidar_misalignment"].values
        answer[model] = {"best": float(x[best]), "worst": float(x[worst]),
                         "u_best": float(curve[best]), "u_worst": float(curve[worst]),
                         "gain": float(1 - curve[best] / curve[worst])}
    return answer


def velocity_ratio_answer(dataset, target, quantity="wind_speed"):
    """Largest velocity ratio VR = sog / Vh that keeps the direction-averaged u(Vh) at or
    under `target` for every swept wind speed (per model). The ratio is found on the
    swept sog grid: at each Vh, the largest swept sog up to which u stays <= target.

    Returns
    -------
    dict
        model -> {"ratio": float (inf if never exceeded, NaN if exceeded at sog 0),
        "limiting_speed": the Vh that sets it [m s-1]}.
    """
    answer = {}
    speeds, sogs = dataset["wind_speed"].values, dataset["ship_sog"].values
    for model in models(dataset, quantity):
        grid = mean_over(dataset, f"{quantity}_{model}", ("wind_speed", "ship_sog"))
        grid = grid.transpose("wind_speed", "ship_sog").values
        ratios = []
        for speed, row in zip(speeds, grid):
            over = np.flatnonzero(row > target)
            if over.size == 0:
                ratios.append(np.inf)
            else:
                ratios.append(np.nan if over[0] == 0 else sogs[over[0] - 1] / speed)
        ratios = np.array(ratios)
        limiting = int(np.nanargmin(ratios)) if np.isfinite(ratios).any() else 0
        answer[model] = {"ratio": float(np.min(ratios)), "limiting_speed": float(speeds[limiting])}
    return answer


def budget_answer(dataset, quantity="wind_speed"):
    """Each input's share of the GUM variance, averaged over the grid, largest first.

    Returns
    -------
    list of (input, share [1])
    """
    budget = dataset[f"{quantity}_budget"]
    total = budget.sum("input")
    share = (budget / total.where(total > 0)).mean([d for d in budget.dims if d != "input"])
    pairs = [(str(name), float(value)) for name, value in zip(dataset["input"].values, share.values)]
    return sorted(pairs, key=lambda pair: -np.nan_to_num(pair[1]))


def disagreement_answer(dataset, quantity="wind_speed", reference="mc_u"):
    """The paper's u against sampling (or the GUM): ratio paper / reference over the grid.

    Returns
    -------
    dict or None
        {"median", "min", "max" of the ratio, "where_max": {dim: value} of the largest
        |ratio - 1|, "scenes": number compared}; None outside the paper's model.
    """
    reference = reference if f"{quantity}_{reference}" in dataset else "gum_u"
    if "paper_u" not in models(dataset, quantity):
        return None
    ratio = dataset[f"{quantity}_paper_u"] / dataset[f"{quantity}_{reference}"]
    valid = np.isfinite(ratio.values)
    if not valid.any():
        return None
    flat = int(np.nanargmax(np.abs(np.where(valid, ratio.values, np.nan) - 1)))
    where = dict(zip(ratio.dims, np.unravel_index(flat, ratio.shape)))
    return {"reference": reference, "median": float(np.nanmedian(ratio.values)),
            "min": float(np.nanmin(ratio.values)), "max": float(np.nanmax(ratio.values)),
            "where_max": {d: _value(ratio[d].values[i]) if d in ratio.coords else int(i)
                          for d, i in where.items()},
            "scenes": int(valid.sum())}


def bias_answer(dataset, quantity="wind_speed"):
    """Systematic errors (the correction's, the probe volume's) and the Monte Carlo bias.

    Returns
    -------
    dict
        {"correction": largest |nominal - true| and where, with "zero" when it is within
        NUMERICAL_ZERO (rounding, not a systematic error); with a probe volume
        (``{quantity}_probe_bias``) the probe's share is taken out of it and reported as
        "probe" (largest |probe_bias| and where, with "zero"), "mc": largest |mc_bias| and
        where, "significant": share of the compared values (scenes x gates) where
        |mc_bias| > 3 standard errors (u / sqrt(N)) and > NUMERICAL_ZERO (a scene without
        uncertainty has a standard error of zero), "significant_count" and "compared"
        (their numbers), "mc_significant": the largest of those (None if there is none);
        the Monte Carlo keys are absent without Monte Carlo}.
    """
    truth, nominal = dataset[f"{quantity}_true"], dataset[f"{quantity}_nominal"]
    difference = nominal - truth
    if quantity == "wind_direction":
        difference = (difference + FULL_CIRCLE_DEG / 2) % FULL_CIRCLE_DEG - FULL_CIRCLE_DEG / 2
    systematic = {"correction": difference}
    if f"{quantity}_probe_bias" in dataset:         # nominal - true = probe + correction
        probe = dataset[f"{quantity}_probe_bias"]
        systematic = {"correction": difference - probe, "probe": probe}
    answer = {}
    for source, values in systematic.items():
        answer[source] = _largest(values)
        answer[source]["zero"] = bool(abs(answer[source]["value"]) <= NUMERICAL_ZERO) \
            if np.isfinite(answer[source]["value"]) else False
    if f"{quantity}_mc_bias" in dataset:
        bias = dataset[f"{quantity}_mc_bias"]
        error = dataset[f"{quantity}_mc_u"] / np.sqrt(dataset["mc_n_samples"])
        beyond = (np.abs(bias) > BIAS_STANDARD_ERRORS * error) & (np.abs(bias) > NUMERICAL_ZERO)
        answer["mc"] = _largest(bias)
        answer["significant"] = float(beyond.mean())
        answer["significant_count"] = int(beyond.sum())
        answer["compared"] = int(beyond.size)
        answer["mc_significant"] = _largest(bias.where(beyond)) if beyond.any() else None
    return answer


def _largest(variable):
    values = np.abs(variable.values)
    if not np.isfinite(values).any():
        return {"value": float("nan"), "where": {}}
    flat = int(np.nanargmax(values))
    index = np.unravel_index(flat, variable.shape)
    return {"value": float(variable.values.flat[flat]),
            "where": {d: _value(variable[d].values[i]) if d in variable.coords else int(i)
                      for d, i in zip(variable.dims, index)}}


def _value(value):
    return float(value) if np.issubdtype(np.asarray(value).dtype, np.number) else str(value)


def paper_findings(dataset):
    """The findings of Rubio & Gottschall (2022, Sec. 3) that the result can test.

    Returns
    -------
    list of dict
        {"finding", "model", "holds" (bool), "evidence" (str)} per finding and model.
    """
    dims = set(dataset["mc_n_samples"].dims)
    rows = []
    if {"lidar_misalignment", "wind_direction"} <= dims:
        rows += _misalignment_findings(dataset)
    if {"wind_speed", "ship_sog", "wind_direction"} <= dims:
        rows += _velocity_ratio_findings(dataset)
    if {"ship_pitch", "ship_roll", "wind_direction"} <= dims:
        rows += _tilt_findings(dataset)
    if {"lidar_half_cone", "wind_direction"} <= dims:
        rows += _half_cone_findings(dataset)
    return rows


def _half_cone_findings(dataset):
    """Fig. 7 [1]: u(Vh) falls as the half-cone angle grows."""
    rows = []
    for model in models(dataset, "wind_speed"):
        curve = mean_over(dataset, f"wind_speed_{model}", ("lidar_half_cone",)).values
        change = curve[-1] / curve[0] - 1
        cones = dataset["lidar_half_cone"].values
        rows.append({"finding": "u(Vh) falls as the half-cone angle grows",
                     "model": MODEL_NAMES[model],
                     "holds": bool(np.all(np.diff(curve) <= 0) and change < -EQUAL_WITHIN),
                     "evidence": f"{curve[0]:.4g} m/s at {cones[0]:g} deg, {curve[-1]:.4g} m/s "
                     f"at {cones[-1]:g} deg ({100 * change:+.1f} %)"})
    return rows


def _misalignment_findings(dataset):
    """Fig. 2 [1]: per ship direction (each panel), the direction-averaged u(Vh) is lowest
    at misalignment 0/±90 deg and highest at ±45 deg."""
    rows = []
    x = dataset["lidar_misalignment"].values % FULL_CIRCLE_DEG
    on_beams, diagonal = np.isclose(x % 90.0, 0.0), np.isclose(x % 90.0, 45.0)
    if not (on_beams.any() and diagonal.any()):
        return rows
    for model in models(dataset, "wind_speed"):
        keep = ("lidar_misalignment", "ship_cog") if "ship_cog" in dataset.dims \
            else ("lidar_misalignment",)
        curves = mean_over(dataset, f"wind_speed_{model}", keep)
        curves = curves.transpose(..., "lidar_misalignment").values.reshape(-1, len(x))
        verdicts = [_extremes_on(curve, on_beams, diagonal) for curve in curves]
        spread = np.max([(c.max() - c.min()) / c.mean() for c in curves])
        rows.append({"finding": "u(Vh) averaged over wind direction is lowest at misalignment "
                     "0/±90 deg and highest at ±45 deg (every ship direction)",
                     "model": MODEL_NAMES[model],
                     "holds": bool(all(verdicts) and spread > EQUAL_WITHIN),
                     "evidence": (f"extremes as stated for {sum(verdicts)} of {len(verdicts)} "
                                  "ship directions; " if spread > EQUAL_WITHIN else
                                  "no effect: the same u at every misalignment; ")
                     + f"u = {curves[:, on_beams].mean():.4g} m/s at 0/±90 deg, "
                     f"{curves[:, diagonal].mean():.4g} m/s at ±45 deg; largest spread over "
                     f"misalignment {100 * spread:.2f} %"})
    return rows


def _extremes_on(curve, minima, maxima):
    """Is the curve's minimum at one of `minima` and its maximum at one of `maxima`?"""
    return bool(np.isclose(curve.min(), curve[minima].min(), rtol=1e-9)
                and np.isclose(curve.max(), curve[maxima].max(), rtol=1e-9))


def velocity_ratio_line(dataset, name, ratio):
    """Direction-averaged `name` along sog = ratio * Vh (linear interpolation in sog), at
    the swept wind speeds whose sog stays inside the swept range: (speeds, values)."""
    grid = mean_over(dataset, name, ("wind_speed", "ship_sog"))
    speeds = dataset["wind_speed"].values
    speeds = speeds[ratio * speeds <= dataset["ship_sog"].values.max()]
    return speeds, np.array([float(grid.sel(wind_speed=v).interp(ship_sog=ratio * v))
                             for v in speeds])


def _velocity_ratio_findings(dataset):
    rows = []
    for model in models(dataset, "wind_speed"):
        lines = {ratio: velocity_ratio_line(dataset, f"wind_speed_{model}", ratio)
                 for ratio in VELOCITY_RATIOS}
        common = np.intersect1d(lines[0.5][0], lines[2.0][0])
        if common.size == 0:            # no swept Vh whose sog reaches VR = 2: not testable
            continue
        pick = lambda r: lines[r][1][np.isin(lines[r][0], common)]   # noqa: E731
        ordered = np.all(pick(0.5) <= pick(1.0)) and np.all(pick(1.0) <= pick(2.0))
        gain = float(np.mean(pick(2.0) / pick(0.5) - 1))
        rows.append({"finding": "a higher velocity ratio VR = sog/Vh gives a higher u(Vh)",
                     "model": MODEL_NAMES[model], "holds": bool(ordered and gain > EQUAL_WITHIN),
                     "evidence": f"u(VR = 2) / u(VR = 0.5) - 1 = {100 * gain:+.2f} % on average "
                     f"over Vh = {common.min():g}-{common.max():g} m/s"})
    return rows


def _tilt_findings(dataset):
    rows = []
    if not (np.isin(0.0, dataset["ship_pitch"].values) and np.isin(0.0, dataset["ship_roll"].values)):
        return rows                     # no level ship on the grid to compare with
    for quantity in ("wind_speed", "wind_direction"):
        for model in models(dataset, quantity):
            grid = mean_over(dataset, f"{quantity}_{model}", ("ship_pitch", "ship_roll"))
            level = float(grid.sel(ship_pitch=0.0, ship_roll=0.0))
            tilted = grid.where((grid["ship_pitch"] != 0) | (grid["ship_roll"] != 0))
            change = float(tilted.max() / level - 1), float(tilted.min() / level - 1)
            holds = change[0] < EQUAL_WITHIN and change[1] < -EQUAL_WITHIN
            symbol = "u(Vh)" if quantity == "wind_speed" else "u(Theta)"
            rows.append({"finding": f"tilt lowers {symbol}", "model": MODEL_NAMES[model],
                         "holds": bool(holds),
                         "evidence": f"level {level:.4g}; tilted scenes {100 * change[1]:+.1f} % "
                         f"to {100 * change[0]:+.1f} %"})
    return rows


def gum_validity_answer(dataset, quantity="wind_speed"):
    """Share (and number) of the values (scenes x range gates) whose GUM interval Monte
    Carlo validates (JCGM 101 clause 8), and of those where that verdict is conclusive;
    None without Monte Carlo."""
    if f"{quantity}_gum_valid" not in dataset or f"{quantity}_mc_u" not in dataset:
        return None
    valid = dataset[f"{quantity}_gum_valid"].values
    conclusive = dataset[f"{quantity}_gum_validation_conclusive"].values
    return {"valid": float(valid.mean()), "conclusive": float(conclusive.mean()),
            "valid_count": int(valid.sum()), "conclusive_count": int(conclusive.sum()),
            "compared": int(valid.size)}


def fixed_phase_note(dataset):
    """Why the motion-induced TI increment of a run is (near) zero although the platform
    moves: every harmonic motion component has a fixed phase (no ``random``, no wave
    spectrum or record), so every scan sees the same motion and its scatter over scans is
    not sampled; the motion shows as a systematic error of the wind speed instead.
    Returns the sentence, or '' when some phase is sampled (or there is no motion)."""
    try:
        raw = yaml.safe_load(dataset.attrs.get("scenario", "")) or {}
    except yaml.YAMLError:
        return ""
    motion = raw.get("motion") if isinstance(raw, dict) else None
    if not isinstance(motion, dict) or not motion:
        return ""
    harmonic = {k: v for k, v in motion.items() if isinstance(v, dict) and "amplitude" in v}
    if len(harmonic) != len(motion) or any(str(v.get("phase", "random")) == "random"
                                           for v in harmonic.values()):
        return ""                      # a random phase, a spectrum or a record: sampled
    phases = ", ".join(f"motion.{k}.phase: {v['phase']:g}" for k, v in harmonic.items())
    text = (f"every motion phase is fixed ({phases}): each scan sees the same motion, so "
            "its scatter over scans (the TI increment) is not sampled")
    if "wind_speed_nominal" in dataset and "wind_speed_true" in dataset:
        largest = _largest(dataset["wind_speed_nominal"] - dataset["wind_speed_true"])
        text += ("; the motion shows as the systematic error of the wind speed instead "
                 f"(error-free reconstruction minus true up to {largest['value']:+.3g} m/s)")
    return text + "; set the phases to random to sample the scatter over the motion's phase"


def scene_uncertainty(dataset, quantity):
    """u of `quantity` in every scene and gate as a reader gets it: Monte Carlo where the
    run sampled it, else the GUM. Returns (DataArray, model suffix)."""
    name = f"{quantity}_mc_u"
    if name in dataset and np.isfinite(dataset[name].values).any():
        return dataset[name], "mc_u"
    return dataset[f"{quantity}_gum_u"], "gum_u"


def categorical_dimensions(dataset):
    """The swept dimensions whose values are names (a correction model, a probe kind):
    a target's answer is given for each of their values."""
    return [d for d in dataset["mc_n_samples"].dims if dataset[d].dtype.kind in "OUS"]


def target_answer(dataset, quantity, target):
    """Which swept values and range gates keep u(`quantity`) at or under `target`.

    For each value of each categorical swept key (one group without any), and for each
    numeric swept key and the range gate: the values at which every scene of the group
    keeps u <= target ("always", whatever the other keys), and those at which some scene
    does ("somewhere"); the scenes meeting the target out of all; the best scene. u is
    Monte Carlo's where sampled, else the GUM's (:func:`scene_uncertainty`).

    Returns
    -------
    dict
        {"model": suffix, "groups": [{"group": {dim: value}, "meeting": int, "total": int,
        "keys": {dim: {"always": [...], "somewhere": [...]}}, "best": {"value", "where"}},
        ...]}
    """
    u, model = scene_uncertainty(dataset, quantity)
    categorical = categorical_dimensions(dataset)
    groups = [dict(zip(categorical, values)) for values in
              np.ndindex(*[dataset.sizes[d] for d in categorical])]
    answer = []
    for index in groups:
        group = {d: _value(dataset[d].values[i]) for d, i in index.items()}
        at = u.isel(index) if index else u
        keys = {}
        for dim in [d for d in at.dims if d != "input"]:
            others = [d for d in at.dims if d != dim]
            worst = at.max(others) if others else at
            best = at.min(others) if others else at
            values = [_value(v) for v in at[dim].values] if dim in at.coords else \
                list(range(at.sizes[dim]))
            keys[dim] = {"always": [v for v, w in zip(values, worst.values) if w <= target],
                         "somewhere": [v for v, b in zip(values, best.values) if b <= target]}
        meeting = int(np.sum(at.values <= target))
        smallest = {"value": float("nan"), "where": {}} if not np.isfinite(at.values).any() \
            else _smallest(at)
        answer.append({"group": group, "meeting": meeting, "total": int(at.size),
                       "keys": keys, "best": smallest})
    return {"model": model, "groups": answer}


def _smallest(variable):
    flat = int(np.nanargmin(variable.values))
    index = np.unravel_index(flat, variable.shape)
    return {"value": float(variable.values.flat[flat]),
            "where": {d: _value(variable[d].values[i]) if d in variable.coords else int(i)
                      for d, i in zip(variable.dims, index)}}
