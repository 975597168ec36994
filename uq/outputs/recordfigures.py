"""Figures of a record-mode run (a ``turbulence`` section): the spectra of one record, the
variance budget of the apparent turbulence intensity, and the apparent against the true TI.

The spectra are those the run stored (the mean periodograms of its records,
:data:`uq.pipeline.records.SPECTRA_ATTRIBUTES`), at the scene as written in the file (the
``scenario`` attribute: swept keys at their file values; every swept correction a line);
a result written before runs stored them draws the file's scene's records again, and
says so. The budget is the spectral path of that scene with its contributions switched
off one at a time (about a second).

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
import sys

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr
import yaml

from uq.physics.lidarspectral import lidar_variances, probe_transfer_for
from uq.pipeline import records
from uq.pipeline.records import turbulence_model
from uq.pipeline.scenario import load_scenario
from uq.pipeline.turbulencesection import scan_geometry
from uq.outputs import layout
from uq.outputs.samples import scene_assignments
from uq.outputs.scenes import gate_words, swept_keys, value_text


def record_plan(dataset):
    """The record-mode figures a result supports: (file stem, function of the Dataset)."""
    if "turbulence_intensity_spectral" not in dataset:
        return []
    plan = [("record_spectra", record_spectra), ("ti_budget", ti_budget)]
    if "turbulence_v_ratio" in dataset:
        plan.append(("component_ratios", component_ratios))
    if any(dim == "turbulence_intensity" for dim in dataset.dims):
        plan.append(("apparent_against_true_ti", apparent_against_true))
    return plan


def shown_scene(dataset, lines=()):
    """The one scene a record figure shows, for every swept key but those in `lines`
    (dimensions drawn as a line each): a value selected with ``--select`` (a scalar
    coordinate), else the scenario's own value where it is one of the swept ones, else the
    first swept value.

    Returns
    -------
    settings : dict
        The validated settings of that scene (the keys in `lines` at the scenario's value).
    chosen : dict
        ``{dimension: value}`` to select the scene's data with.
    words : str
        The scene in words for a title (``turbulence.intensity = 0.06``), '' for none.
    """
    raw = yaml.safe_load(dataset.attrs["scenario"])
    raw.pop("sweep", None)
    file_values = load_scenario(raw).settings
    keys = swept_keys(dataset)
    chosen = {}
    for dim, key in keys.items():
        if dim in lines:
            continue
        own = _get(file_values, key)
        values = [v.item() if hasattr(v, "item") else v for v in dataset[dim].values]
        chosen[dim] = own if own in values else values[0]
    fixed = {keys[d]: _get(file_values, keys[d]) for d in lines if d in keys}
    assignments = scene_assignments(dataset.sel(chosen), fixed)
    words = ", ".join(f"{key} = {value_text(value)}" for key, value in assignments.items()
                      if key not in fixed)
    return load_scenario(raw, assignments).settings, chosen, words


def _get(settings, dotted):
    node = settings
    for part in dotted.split("."):
        node = node.get(part) if isinstance(node, dict) else None
    return node


def record_spectra_data(dataset, settings):
    """The records' spectra of a result: the variables the run stored
    (:data:`uq.pipeline.records.SPECTRA_ATTRIBUTES`), or, for a result written before
    the runs stored them (or of ``sampling.method: none``), the file's scene's records
    drawn now as a run draws them (one line on stderr says so): the scenario's
    correction and, where the platform moves, ``none``."""
    if "record_psd_wind_speed" in dataset:
        return dataset
    scenes = [settings]
    if settings.get("motion") and settings["correction"] != "none":
        scenes.append(records.at_correction(settings, "none"))
    why = ("written before uq stored them" if "turbulence_intensity_mc_mean" in dataset
           else "its run drew no Monte Carlo records")
    print(f"uq: {settings['name']} has no stored record spectra ({why}): drawing "
          f"{settings['record']['count']} records for {len(scenes)} scene(s) now; a run "
          f"with Monte Carlo records stores them", file=sys.stderr, flush=True)
    variables = records.spectra_variables(scenes, int(dataset.attrs.get("seed", 0)),
                                          moving=bool(settings.get("motion")))
    corrections = [scene["correction"] for scene in scenes]
    data = {name: (tuple("correction" if d == "scene" else d for d in dims), values)
            for name, (dims, values) in variables.items() if name != "record_frequency"}
    return xr.Dataset(data, coords={"correction": corrections,
                                    "record_frequency": variables["record_frequency"][1]})


def spectra_lines(data, chosen, settings):
    """(frequency [Hz], true u's PSD, {label: Vh's PSD}, {label: radial PSD}) at the
    first gate of the scene `chosen` (:func:`shown_scene`; every swept correction a line;
    the lidar at rest where the platform moves) [m2 s-2 Hz-1]."""
    names = [name for name in records.SPECTRA_ATTRIBUTES if name in data]
    data = data[names].sel({d: v for d, v in chosen.items() if d in data[names].dims})
    if "range" in data.dims:
        data = data.isel(range=0)
    moving = bool(settings.get("motion"))
    corrections = list(data["correction"].values) if "correction" in data.dims \
        else [settings["correction"]]

    def at(name, correction):
        values = data[name]
        return (values.sel(correction=correction) if "correction" in values.dims
                else values).values
    speeds, radials = {}, {}
    if moving and "record_psd_wind_speed_at_rest" in data:
        speeds["lidar, fixed"] = at("record_psd_wind_speed_at_rest", corrections[0])
        radials["lidar, fixed"] = at("record_psd_radial_velocity_at_rest", corrections[0])
    for correction in corrections:
        label = f"lidar, moving, correction {correction}" if moving else "lidar, fixed"
        speeds[label] = at("record_psd_wind_speed", correction)
        radials[label] = at("record_psd_radial_velocity", correction)
    return (data["record_frequency"].values, at("record_psd_u_true", corrections[0]),
            speeds, radials)


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
    point (sampled once a scan too), the mean over the run's records of each record's
    periodogram, as the run stored it (:func:`record_spectra_data`); the -5/3 slope, and
    the motion's peak where the scan's sampling aliases it (a DBS samples each beam once
    a scan: the wave motion folds below 1 / (2 T_s))."""
    settings, chosen, words = shown_scene(dataset, lines=("correction",))
    frequency, true, speeds, radials = spectra_lines(record_spectra_data(dataset, settings),
                                                     chosen, settings)
    period = records.spectrum_axis(settings)[0]
    figure, axes = plt.subplots(1, 2, figsize=(11.0, 4.4), constrained_layout=True,
                                sharey=True)
    speeds = {"true u at the reference point": true, **speeds}
    colours = {name: f"C{k}" for k, name in enumerate(speeds)}
    titles = (f"radial velocity of beam 0 (azimuth {settings['lidar']['azimuths'][0]:g})",
              "horizontal wind speed Vh")
    f = frequency[1:]
    for ax, series, title in zip(axes, (radials, speeds), titles):
        for name, psd in series.items():
            ax.loglog(f, psd[1:], color=colours[name],
                      lw=2.2 if name.startswith("true") else 1.2, label=name)
        _slope(ax, f, true[1:])
        _mark_motion(ax, settings, period)
        ax.set_xlabel(f"frequency [Hz] (scans of {period:.3g} s)")
        ax.set_title(title, fontsize=9)
        ax.grid(alpha=0.3, which="both")
    axes[0].set_ylabel("PSD [m$^2$ s$^{-2}$ Hz$^{-1}$]")
    axes[1].legend(fontsize=7, loc="lower left")
    layout.suptitle(figure, f"{dataset.attrs.get('title', '')}: "
                    + (f"{words}, " if words else "")
                    + f"range gate {settings['lidar']['ranges'][0]:g} m, mean of "
                    f"{settings['record']['count']} records", fontsize=9)
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
    ax.loglog(f[middle:], line, color="k", ls="--", lw=1,
              label="-5/3 slope (inertial range)")
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


def error_contributions(dataset, chosen):
    """The per-scan error variances of Vh [m2 s-2] at each gate, grouped (module
    docstring), from the result's GUM budget of the scene `chosen` (:func:`shown_scene`)."""
    if "wind_speed_budget" not in dataset:
        return [], []
    budget = dataset["wind_speed_budget"].sel(chosen)
    groups = {}
    for name in budget["input"].values:
        label = next((bar for prefix, bar in ERROR_GROUPS if str(name).startswith(prefix)),
                     "other")
        groups[label] = groups.get(label, 0.0) + np.nan_to_num(np.atleast_1d(
            budget.sel(input=name).values))
    names = [bar for _, bar in ERROR_GROUPS if bar in groups] + \
        (["other"] if "other" in groups else [])
    return names, [groups[n] for n in names]


def ti_budget(dataset):
    """Bars: the contributions to the variance of the record's Vh at each gate (module
    docstring), with the total, the spectral path's apparent variance."""
    settings, chosen, words = shown_scene(dataset)
    names, values = geometry_contributions(settings)
    more, errors = error_contributions(dataset, chosen)
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
    layout.title(ax, "variance budget of the lidar's apparent TI"
                 + (f" at {words}" if words else f", correction {settings['correction']}")
                 + " (spectral path and the GUM of a scan; the bars add up to the total)")
    ax.grid(alpha=0.3, axis="x")
    ax.legend(fontsize=7, loc="lower right")
    return figure


def apparent_against_true(dataset):
    """The lidar's apparent TI against the field's TI over a record, the one it is
    compared with: the spectral path's expectation against the field's expected record TI
    (a line), the Monte Carlo records' mean with the 95 % of records against the records'
    own field TI (markers with bars); a colour per value of the other swept key (e.g. the
    correction), at the first range gate. The scenario's point TI (the input,
    ``turbulence.intensity``) is each point's label on the top axis."""
    figure, ax = plt.subplots(figsize=(6.4, 4.8), constrained_layout=True)
    data = dataset.isel(range=0) if "range" in dataset["turbulence_intensity_spectral"].dims \
        else dataset
    others = [d for d in data["turbulence_intensity_spectral"].dims
              if d != "turbulence_intensity"]
    panels = [{}] if not others else [{others[0]: v} for v in data[others[0]].values]
    for k, where in enumerate(panels):
        at = data.sel(where) if where else data
        label = ", ".join(f"{v}" for v in where.values()) or "lidar"
        field = at["turbulence_intensity_true"].values * 100
        ax.plot(field, at["turbulence_intensity_spectral"].values * 100, color=f"C{k}",
                marker=".", label=f"{label}: spectral path")
        if "turbulence_intensity_mc_mean" in at:
            mean = at["turbulence_intensity_mc_mean"].values * 100
            ax.errorbar(at["turbulence_intensity_true_mc_mean"].values * 100, mean,
                        yerr=[mean - at["turbulence_intensity_mc_low"].values * 100,
                              at["turbulence_intensity_mc_high"].values * 100 - mean],
                        fmt="o", ms=4, color=f"C{k}", capsize=3, linestyle="none",
                        label=f"{label}: Monte Carlo records (mean, 95 % of records)")
    field = data["turbulence_intensity_true"]
    field = (field.isel({others[0]: 0}) if others else field).values * 100
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    low, high = max(x0, y0), min(x1, y1)           # where the identity is in view
    if low < high:
        identity = np.linspace(low, high, 101)
        ax.plot(identity, identity, color="k", ls="--", lw=1, label="apparent = field")
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_xlabel("the field's TI over a record [%]")
    ax.set_ylabel("the lidar's apparent TI [%]")
    top = ax.secondary_xaxis("top")
    top.set_ticks(field, [f"{100 * v:g}" for v in data["turbulence_intensity"].values])
    top.set_xlabel("the field's point TI, turbulence.intensity [%]", fontsize=8)
    top.tick_params(labelsize=7)
    layout.title(ax, dataset.attrs.get("title", ""))
    ax.grid(alpha=0.3)
    layout.legend_below(figure, *ax.get_legend_handles_labels(), fontsize=7)
    return figure


#: The components of the records' figures and tables: (name, variance-ratio variable,
#: its error, spectral apparent TI, Monte Carlo mean, true TI).
COMPONENTS = (
    ("u (along the wind)", "turbulence_intensity_u_ratio", "turbulence_intensity_u_ratio_error",
     "turbulence_intensity_spectral_turbulence", "turbulence_intensity_mc_mean",
     "turbulence_intensity_true"),
    ("v (lateral)", "turbulence_v_ratio", "turbulence_v_ratio_error",
     "turbulence_intensity_v_spectral", "turbulence_intensity_v_mc_mean",
     "turbulence_intensity_v_true"),
    ("w (vertical)", "turbulence_w_ratio", "turbulence_w_ratio_error",
     "turbulence_intensity_w_spectral", "turbulence_intensity_w_mc_mean",
     "turbulence_intensity_w_true"))


def component_ratios(dataset):
    """The lidar's u, v, w against its range gates, at the scene :func:`shown_scene`
    picks: (left) the variance ratios of its filtered turbulence to the field's (spectral
    path, with the quadrature's stated error), (right) the apparent TIs of each component
    from the turbulence alone (spectral: lines) and the Monte Carlo records' mean (points,
    the scans' errors included), with the field's TIs over a record dashed."""
    settings, chosen, words = shown_scene(dataset)
    data = dataset.sel(chosen)
    gates = np.atleast_1d(data["range"].values)
    gate = gate_words(dataset)
    figure, (left, right) = plt.subplots(1, 2, figsize=(10, 4.4), constrained_layout=True)
    for k, (label, ratio, error, spectral, mc, true) in enumerate(COMPONENTS):
        values = np.atleast_1d(data[ratio].values)
        left.errorbar(gates, values, yerr=np.atleast_1d(data[error].values), fmt="o-",
                      color=f"C{k}", capsize=3, label=label)
        right.plot(gates, 100 * np.atleast_1d(data[spectral].values), "s-", color=f"C{k}",
                   mfc="none", label=f"{label}: spectral (turbulence)")
        if mc in data:
            right.plot(gates, 100 * np.atleast_1d(data[mc].values), "o", color=f"C{k}",
                       label=f"{label}: Monte Carlo records")
        right.axhline(100 * float(np.atleast_1d(data[true].values)[0]), color=f"C{k}",
                      ls="--", lw=1, label=f"{label}: the field over a record")
    left.axhline(1.0, color="k", lw=0.8)
    left.set_xlabel(f"{gate} [m]")
    left.set_ylabel("variance ratio lidar / field [1]")
    layout.title(left, "variance ratios (spectral path, numerical error bars)")
    left.set_yscale("log")
    right.set_xlabel(f"{gate} [m]")
    right.set_ylabel("apparent TI [%]")
    layout.title(right, "apparent TI of each component over a record")
    for ax in (left, right):
        ax.grid(alpha=0.3, which="both")
    left.legend(fontsize=7)
    layout.suptitle(figure, f"{dataset.attrs.get('title', '')}: the lidar's u, v and w"
                    + (f" at {words}" if words else ""))
    layout.legend_below(figure, *right.get_legend_handles_labels(), fontsize=7)
    return figure
