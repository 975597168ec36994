"""Figures of a record-mode run (a ``turbulence`` section): the spectra of one record, the
variance budget of the apparent turbulence intensity, and the apparent against the true TI.

The spectra and the budget are drawn again from the scenario the result carries (its
``scenario`` attribute, the scene as written in the file: swept keys at their file values):
one record of the Monte Carlo path (one box) for the spectra, the spectral path with its
contributions switched off one at a time for the budget. Both take seconds.

Budget (variance of the record's Vh, [m2 s-2]; the bars add linearly to the total):

* *true*: the field's u-variance at the reference point over the record (sampled once a
  scan, the record's high-pass);
* *beam separation*: the lidar with a point probe and simultaneous beams, minus true;
* *scan timing*: the beams at their times, minus simultaneous (point probe);
* *probe volume*: the probe's weighting, minus the point probe;
* *motion*, *INS*, *noise*, *other*: the GUM budget of one scan's Vh (``wind_speed_budget``),
  its inputs grouped (motion phases and timing; ``ins.*``; ``lidar.errors.radial_velocity``;
  the rest), each scan's errors independent of the next's.
"""
import copy
import dataclasses

import matplotlib.pyplot as plt
import numpy as np
import yaml
from scipy import signal

from uq.physics.lidarspectral import lidar_variances, probe_transfer_for
from uq.pipeline.records import (monte_carlo_record, record_generator, turbulence_model)
from uq.pipeline.scenario import load_scenario
from uq.pipeline.turbulencesection import scan_geometry, scans_per_record

#: Records whose periodograms the spectra average [1]: 4 halve the scatter of one
#: periodogram's ordinates (to 1/sqrt(4)) at the record's full frequency resolution.
SPECTRUM_RECORDS = 4


def record_plan(dataset):
    """The record-mode figures a result supports: (file stem, function of the Dataset)."""
    if "turbulence_intensity_spectral" not in dataset:
        return []
    plan = [("record_spectra", record_spectra), ("ti_budget", ti_budget)]
    if any(dim == "turbulence_intensity" for dim in dataset.dims):
        plan.append(("apparent_against_true_ti", apparent_against_true))
    return plan


def file_settings(dataset):
    """The validated settings of the scene as written in the file (no sweep)."""
    raw = yaml.safe_load(dataset.attrs["scenario"])
    raw["sweep"] = {}
    return load_scenario(raw).settings


def _variant(settings, **changes):
    """Settings with top-level sections replaced (None removes one), validated."""
    raw = copy.deepcopy(settings)
    for key, value in changes.items():
        if value is None:
            raw.pop(key, None)
        else:
            raw[key] = value
    return load_scenario(raw).settings


def record_series(settings, seed=0, records=SPECTRUM_RECORDS):
    """Records of the field's u at the reference point, and of the lidar's Vh at the
    first gate and the radial velocity of its first beam there (corrected as the
    correction believes), once a scan, for the lidar fixed, moving uncorrected and moving
    corrected (the scenario's correction); the same boxes for all. Returns (scan period
    [s], {name: (records, n_scans) Vh or u}, {name: (records, n_scans) radial})."""
    geometry = scan_geometry(settings)
    n_scans = scans_per_record(settings)
    still = copy.deepcopy(settings["ins"])
    for key in ("rate", "interpolation", "clock_offset"):      # (nothing to sample at rest)
        still.pop(key, None)
    variants = {"lidar, fixed": _variant(settings, motion=None, correction="full", ins=still)}
    if settings.get("motion"):
        for correction in dict.fromkeys(("none", settings["correction"])):
            variants[f"lidar, moving, correction {correction}"] = _variant(
                settings, correction=correction)
    speeds, radials = {"true u at the reference point": []}, {}
    for name, variant in variants.items():
        for r in range(records):
            vh, reference, _, radial = monte_carlo_record(
                variant, geometry, n_scans, record_generator(seed, r), radial=True)
            if name == "lidar, fixed":
                speeds["true u at the reference point"].append(reference)
            speeds.setdefault(name, []).append(vh[:, 0])
            radials.setdefault(name, []).append(radial[:, 0, 0])
    return (geometry.scan_period, {k: np.array(v) for k, v in speeds.items()},
            {k: np.array(v) for k, v in radials.items()})


def motion_peak(settings):
    """Frequency [Hz] of the motion's strongest component (JONSWAP: 1 / tp; harmonics:
    the largest amplitude's), or None without motion."""
    motion = settings.get("motion") or {}
    if "spectrum" in motion:
        return 1.0 / motion["spectrum"]["tp"]
    harmonics = [(spec["amplitude"], 1.0 / spec["period"]) for key, spec in motion.items()
                 if isinstance(spec, dict) and "period" in spec]
    return max(harmonics)[1] if harmonics else None


def aliased(frequency, sampling):
    """Where a frequency [Hz] appears when sampled at `sampling` [Hz] (folded into
    [0, sampling / 2])."""
    folded = np.mod(frequency, sampling)
    return min(folded, sampling - folded)


def record_spectra(dataset):
    """PSD of the radial velocity of one beam and of the Vh a lidar reports, once a scan,
    fixed and moving, with and without correction, against the true u at the reference
    point (sampled once a scan too), averaged over :data:`SPECTRUM_RECORDS` records; the
    -5/3 slope, and the motion's peak where the scan's sampling aliases it (a DBS samples
    each beam once a scan: the wave motion folds below 1 / (2 T_s))."""
    settings = file_settings(dataset)
    period, speeds, radials = record_series(settings, int(dataset.attrs.get("seed", 0)))
    figure, axes = plt.subplots(1, 2, figsize=(11.0, 4.4), constrained_layout=True,
                                sharey=True)
    colours = {name: f"C{k}" for k, name in enumerate(speeds)}
    titles = (f"radial velocity of beam 0 (azimuth {settings['lidar']['azimuths'][0]:g})",
              "horizontal wind speed Vh")
    for ax, series, title in zip(axes, (radials, speeds), titles):
        for name, values in series.items():
            f, psd = signal.periodogram(values - values.mean(axis=1, keepdims=True),
                                        fs=1.0 / period, axis=1)
            ax.loglog(f[1:], psd.mean(axis=0)[1:], color=colours[name],
                      lw=2.2 if name.startswith("true") else 1.2, label=name)
        _slope(ax, f[1:], psd.mean(axis=0)[1:])
        _mark_motion(ax, settings, period)
        ax.set_xlabel(f"frequency [Hz] (scans of {period:.3g} s)")
        ax.set_title(title, fontsize=9)
        ax.grid(alpha=0.3, which="both")
    axes[0].set_ylabel("PSD [m$^2$ s$^{-2}$ Hz$^{-1}$]")
    axes[1].legend(fontsize=7, loc="lower left")
    figure.suptitle(f"{dataset.attrs.get('title', '')}: gate {settings['lidar']['ranges'][0]:g}"
                    f" m, mean of {SPECTRUM_RECORDS} records", fontsize=9)
    return figure


def _mark_motion(ax, settings, period):
    """A dotted line where the motion's peak appears in the once-a-scan sampling."""
    peak = motion_peak(settings)
    if not peak:
        return
    seen = aliased(peak, 1.0 / period)
    ax.axvline(seen, color="0.3", ls=":", lw=1)
    ax.text(seen, ax.get_ylim()[1], f" motion {peak:.3g} Hz\n seen at {seen:.3g} Hz",
            va="top", fontsize=7)


def _slope(ax, f, psd):
    """A -5/3 line through the upper part of the spectrum (the inertial range)."""
    middle = len(f) // 2
    anchor = f[middle], psd[middle] * 3
    line = anchor[1] * (f[middle:] / anchor[0]) ** (-5.0 / 3.0)
    ax.loglog(f[middle:], line, color="k", ls="--", lw=1)
    ax.text(f[-1], line[-1], " -5/3", fontsize=8, va="center")


def geometry_contributions(settings):
    """Variance of Vh [m2 s-2] of the turbulence seen through the scan, step by step:
    (true, beam separation, scan timing, probe volume) as differences of the spectral
    path with the scan's parts switched on one at a time (module docstring)."""
    geometry = scan_geometry(settings)
    lidar = settings["lidar"]
    focus = np.asarray(lidar["ranges"], float) / np.cos(np.radians(lidar["half_cone"]))
    model = turbulence_model(settings["turbulence"], settings["wind"]["speed"])
    point = probe_transfer_for(None, focus)
    simultaneous = dataclasses.replace(geometry, times=np.zeros(geometry.n_beams), dwell=0.0)
    steps = [lidar_variances(simultaneous, model, point),
             lidar_variances(geometry, model, point),
             lidar_variances(geometry, model, probe_transfer_for(
                 _probe(settings), focus))]
    true = steps[0].true[0]
    values = [true] + [steps[0].lidar[:, 0] - true, steps[1].lidar[:, 0] - steps[0].lidar[:, 0],
                       steps[2].lidar[:, 0] - steps[1].lidar[:, 0]]
    return ["true u (reference point)", "beam separation", "scan timing", "probe volume"], values


def _probe(settings):
    from uq.pipeline.probesection import make_probe
    return make_probe(settings["lidar"].get("probe"))


#: How the GUM budget's inputs are grouped in the TI budget (label prefix -> bar).
ERROR_GROUPS = (("motion", "motion"), ("ins.", "INS"), ("lidar.errors.radial_velocity", "noise"))


def error_contributions(dataset, settings):
    """The per-scan error variances of Vh [m2 s-2] at each gate, grouped (module
    docstring), from the result's GUM budget of the file's scene."""
    if "wind_speed_budget" not in dataset:
        return [], []
    budget = file_scene(dataset["wind_speed_budget"], settings)
    groups = {}
    for name in budget["input"].values:
        label = next((bar for prefix, bar in ERROR_GROUPS if str(name).startswith(prefix)),
                     "other")
        groups[label] = groups.get(label, 0.0) + np.nan_to_num(np.atleast_1d(
            budget.sel(input=name).values))
    names = [bar for _, bar in ERROR_GROUPS if bar in groups] + \
        (["other"] if "other" in groups else [])
    return names, [groups[n] for n in names]


def file_scene(variable, settings):
    """`variable` at the scene of the file's values of the swept keys (the nearest swept
    value; the first where the key is not a number)."""
    for dim in [d for d in variable.dims if d not in ("input", "range", "beam")]:
        node = settings
        for part in dim.split("_", 1):
            node = node.get(part, {}) if isinstance(node, dict) else {}
        value = node if not isinstance(node, dict) else settings.get(dim)
        coordinate = variable[dim].values
        if isinstance(value, (int, float)) and coordinate.dtype.kind in "iuf":
            variable = variable.isel({dim: int(np.argmin(np.abs(coordinate - value)))})
        elif value in list(coordinate):
            variable = variable.isel({dim: list(coordinate).index(value)})
        else:
            variable = variable.isel({dim: 0})
    return variable


def ti_budget(dataset):
    """Bars: the contributions to the variance of the record's Vh at each gate (module
    docstring), with the total, the spectral path's apparent variance."""
    settings = file_settings(dataset)
    names, values = geometry_contributions(settings)
    more, errors = error_contributions(dataset, settings)
    names, values = names + more, values + errors
    ranges = settings["lidar"]["ranges"]
    figure, ax = plt.subplots(figsize=(7.0, 1.4 + 0.45 * len(names)), constrained_layout=True)
    height = 0.8 / len(ranges)
    for g, gate in enumerate(ranges):
        bars = [float(np.atleast_1d(v)[min(g, np.size(v) - 1)]) for v in values]
        ax.barh(np.arange(len(names)) + (g - (len(ranges) - 1) / 2) * height, bars,
                height=height, color=f"C{g}", label=f"{gate:g} m (total {sum(bars):.3g})")
    ax.axvline(0, color="k", lw=0.8)
    ax.set_yticks(np.arange(len(names)), names, fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("contribution to the record variance of Vh [m$^2$ s$^{-2}$]")
    ax.set_title(f"variance budget of the apparent TI, correction {settings['correction']} "
                 "(spectral path and the GUM of a scan; bars add up to the total)", fontsize=9)
    ax.grid(alpha=0.3, axis="x")
    ax.legend(fontsize=7, loc="lower right")
    return figure


def apparent_against_true(dataset):
    """The apparent TI (spectral, and Monte Carlo mean with its 95 % interval over
    records) against the true TI, a line per other swept value (e.g. the correction)."""
    figure, ax = plt.subplots(figsize=(6.2, 4.6), constrained_layout=True)
    data = dataset
    for dim in [d for d in data["turbulence_intensity_spectral"].dims
                if d not in ("turbulence_intensity",)]:
        if dim == "range":
            data = data.isel(range=0)
    others = [d for d in data["turbulence_intensity_spectral"].dims
              if d != "turbulence_intensity"]
    panels = [{}] if not others else [{others[0]: v} for v in data[others[0]].values]
    true = data["turbulence_intensity"].values
    for k, where in enumerate(panels):
        at = data.sel(where) if where else data
        label = ", ".join(f"{v}" for v in where.values()) or "lidar"
        ax.plot(true * 100, at["turbulence_intensity_spectral"].values * 100, color=f"C{k}",
                label=f"{label}: spectral")
        if "turbulence_intensity_mc_mean" in at:
            mean = at["turbulence_intensity_mc_mean"].values * 100
            ax.errorbar(true * 100, mean, yerr=[mean - at["turbulence_intensity_mc_low"].values
                                                * 100, at["turbulence_intensity_mc_high"].values
                                                * 100 - mean],
                        fmt="o", ms=4, color=f"C{k}", capsize=3,
                        label=f"{label}: Monte Carlo (95 % of records)")
    ax.plot(true * 100, true * 100, color="k", ls="--", lw=1, label="apparent = true")
    ax.set_xlabel("true TI at the reference point, turbulence.intensity [%]")
    ax.set_ylabel("apparent TI of the lidar [%]")
    ax.set_title(dataset.attrs.get("title", ""), fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return figure
