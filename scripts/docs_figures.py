"""Make the README's figures (docs/*.png) and tables again from the shipped scenarios, the
way a user makes them (``uq run``, ``uq plot``, ``uq fit``, ``uq golden``, ``uq bench``):

    python scripts/docs_figures.py            # every figure and table but the benchmark
    python scripts/docs_figures.py --bench    # also the guide's performance file (uq bench)
    python scripts/docs_figures.py --only rubio2022_case_i.png   # one figure (or table)

The runs go to a temporary folder that is removed afterwards; only the figures are copied
into docs/ and the tables written into README.md between their markers
``<!-- table: NAME -->`` and ``<!-- end table -->`` (both are the repository's own files).
``docs/figures.json`` records, for each figure, the commands that made it and its SHA-256;
``tests/test_docs.py`` reruns the tables' commands and fails when a README table differs
from what they give, and checks each README figure against the record.

``--bench`` runs ``uq bench --quick`` (or ``--bench-full``: ``uq bench``) and keeps its
result file as ``docs/data/bench.nc`` with the machine, the load average before and after
and the time it ran: the guide's performance page is generated from it, and the README's
speed table (``--only speed``: that table alone, from the file as it is).
"""
import argparse
import hashlib
import json
import math
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from uq.outputs import verdicts

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
README = ROOT / "README.md"
MANIFEST = DOCS / "figures.json"

#: run name -> the uq commands that make it, in a shared folder (each run made once)
RUNS = {
    "case_i": [["run", "rubio2022_case_i", "-o", "c.nc"]],
    "case_i_beam": [["run", "rubio2022_case_i", "--set", "ins.correlation=beam",
                     "-o", "cb.nc"]],
    "misalignment": [["run", "rubio2022_misalignment", "-o", "m.nc"]],
    "misalignment_gum": [["run", "rubio2022_misalignment", "--set", "sampling.method=none",
                          "-o", "mg.nc"]],
    "waves": [["run", "floating_lidar_waves", "-o", "w.nc"]],
    "ti": [["run", "floating_lidar_ti", "--set", "record.duration=300",
            "--set", "record.count=3",
            "--set", "sweep.turbulence.intensity=[0.04, 0.08, 0.14]", "-o", "ti.nc"]],
    "nacelle": [["run", "nacelle_floating", "-o", "n.nc"]],
    "nacelle_fixed": [["run", "nacelle_fixed", "-o", "nf.nc"]],
    "tiana": [["run", "tiana2017_vad", "-o", "t.nc"]],
    "probe": [["run", "probe_volume", "-o", "p.nc"]],
    "profile": [["run", "floating_lidar_profile", "-o", "f.nc"], ["fit", "f.nc"]],
    "golden": [["golden", "golden_campaign", "-o", "g"]],
    "campaign": [["campaign", "campaign_buoy", "-o", "cb"]],
}

#: docs figure -> (runs it needs, the plot commands, the figure they write in the folder)
PLOTTED = {
    "rubio2022_case_i.png": (["case_i"], [["plot", "c.nc"]],
                             "c_figures/uncertainty_against_direction.png"),
    "rubio2022_fig2.png": (["misalignment"], [["plot", "m.nc"]],
                           "m_figures/fig2_speed_maps.png"),
    "tiana2017_fig4a.png": (["tiana"], [["plot", "t.nc"]],
                            "t_figures/tiana2017_speed_error_map.png"),
    "floating_lidar_waves.png": (["waves"], [["plot", "w.nc"]],
                                 "w_figures/motion_correction_comparison.png"),
    "floating_lidar_ti.png": (["ti"], [["plot", "ti.nc"]],
                              "ti_figures/apparent_against_true_ti.png"),
    "nacelle_floating.png": (["nacelle"], [["plot", "n.nc"]],
                             "n_figures/uncertainty_against_preview.png"),
    "probe_volume.png": (["probe"], [["plot", "p.nc"]],
                         "p_figures/probe_bias_against_range.png"),
    "profile_fit.png": (["profile"], [], "f_fit_profile.png"),
    "golden_uncertainty_terms.png": (["golden"], [], "g/figures/uncertainty_terms.png"),
    "campaign_buoy_scatter.png": (["campaign"], [], "cb/figures/scatter.png"),
}


# --- tables: each reads the runs' files and returns Markdown ---------------------------
def _open(folder, name):
    import xarray
    return xarray.load_dataset(Path(folder) / name)


def _row(*cells):
    return "| " + " | ".join(str(c) for c in cells) + " |"


def table_case_i(folder):
    """Rubio case i: the paper, the physical GUM (beam and scan) and Monte Carlo, averaged
    over the 36 wind directions; the clause-8 verdicts of the scan run."""
    scan, beam = _open(folder, "c.nc"), _open(folder, "cb.nc")

    def mean(ds, name):
        return float(ds[name].mean())
    lines = [_row("", "u(Vh) [m/s]", "u(direction) [deg]"), _row("---", "---", "---")]
    for label, ds, model in (("Rubio & Gottschall (2022)", scan, "paper_u"),
                             ("physical GUM, `ins.correlation: beam`", beam, "gum_u"),
                             ("physical GUM, `ins.correlation: scan`", scan, "gum_u"),
                             ("Monte Carlo, `scan`", scan, "mc_u")):
        lines.append(_row(label, f"{mean(ds, f'wind_speed_{model}'):.4f}",
                          f"{mean(ds, f'wind_direction_{model}'):.3f}"))
    ratio = mean(scan, "wind_speed_paper_u") / mean(scan, "wind_speed_gum_u")
    lines += ["", f"The paper's u(Vh) is {ratio:.3f} of the physical one with one INS reading "
              "per scan. Clause 8's verdicts on the GUM interval of Vh over the directions: "
              f"{verdicts.counts_text(scan, 'wind_speed')} (undecided: this number of trials "
              "cannot tell)."]
    return "\n".join(lines)


def table_misalignment(folder):
    """Fig. 2's finding: u(Vh) against the lidar's misalignment, GUM only, mean over the
    wind direction and the course."""
    ds = _open(folder, "mg.nc")
    lines = [_row("misalignment [deg]", "paper's model u(Vh) [m/s]",
                  "physical GUM u(Vh) [m/s]"), _row("---", "---", "---")]
    other = [d for d in ds["wind_speed_gum_u"].dims if d != "lidar_misalignment"]
    for value in (0.0, 45.0, 90.0):
        at = ds.sel(lidar_misalignment=value)
        lines.append(_row(f"{value:g}", f"{float(at['wind_speed_paper_u'].mean(other)):.4f}",
                          f"{float(at['wind_speed_gum_u'].mean(other)):.4f}"))
    return "\n".join(lines)


def table_waves(folder):
    """floating_lidar_waves: u, bias and the motion's TI increment per correction."""
    ds = _open(folder, "w.nc")
    lines = [_row("correction", "u(Vh) [m/s]", "bias of Vh [m/s]", "u(w) [m/s]",
                  "motion-induced TI increment"), _row("---", "---", "---", "---", "---")]
    for correction in ds["correction"].values:
        at = ds.sel(correction=correction).squeeze()
        lines.append(_row(f"`{correction}`", f"{float(at['wind_speed_mc_u']):.3f}",
                          f"{float(at['wind_speed_mc_bias']):+.3f}",
                          f"{float(at['vertical_wind_mc_u']):.3f}",
                          f"{100 * float(at['wind_speed_motion_ti']):.2f} %"))
    return "\n".join(lines)


def table_nacelle(folder):
    """nacelle_floating (none, pointwise) and nacelle_fixed at the nearest and farthest
    preview distance."""
    floating, fixed = _open(folder, "n.nc"), _open(folder, "nf.nc")
    near, far = float(floating["range"].min()), float(floating["range"].max())
    lines = [_row(f"preview distance {near:g} / {far:g} m", "u(Vh) [m/s]",
                  "u(yaw misalignment) [deg]", "u(shear exponent)"),
             _row("---", "---", "---", "---")]
    rows = [(f"floating, `{c}`", floating.sel(correction=c)) for c in floating["correction"].values]
    rows.append(("fixed turbine", fixed))
    for label, ds in rows:
        cells = []
        for name, digits in (("wind_speed", 3), ("yaw_misalignment", 2), ("shear_exponent", 3)):
            u = ds[f"{name}_mc_u"].squeeze()
            cells.append(f"{float(u.sel(range=near)):.{digits}f} / "
                         f"{float(u.sel(range=far)):.{digits}f}")
        lines.append(_row(label, *cells))
    return "\n".join(lines)


def _profile_cells(folder):
    """The profile table's rows: (label, [(low, high, low's MCSE, high's MCSE) per fit],
    truth or None) of ``uq fit``'s result in `folder`."""
    ds = _open(folder, "f_fit.nc")
    rows = []
    for parameter, label in (("reference_speed", "U_ref [m/s]"), ("shear", "shear")):
        cells = []
        for fit in ("propagated", "naive"):
            at = ds.sel(fit=fit, parameter=parameter)
            cells.append(tuple(float(at[name]) for name in (
                "posterior_low95", "posterior_high95", "posterior_low95_mcse",
                "posterior_high95_mcse")))
        truth = ds.sel(parameter=parameter)["true_value"] if "true_value" in ds else None
        rows.append((label, cells, None if truth is None else float(truth.values.ravel()[0])))
    return rows


def table_profile(folder):
    """uq fit of floating_lidar_profile: 95 % credible intervals, propagated and naive."""
    lines = [_row("95 % interval", "propagated", "naive", "truth"), _row("---", "---", "---", "---")]
    for label, cells, truth in _profile_cells(folder):
        lines.append(_row(label, *(f"[{low:.3f}, {high:.3f}]" for low, high, *_ in cells),
                          "-" if truth is None else f"{truth:g}"))
    return "\n".join(lines)


#: Standard errors between two chains' quantiles before the profile table's numbers
#: count as different: 4 (a false alarm once in ~16,000 numbers for a normal error).
MCSE_SIGMAS = 4.0


def tolerances_profile(folder):
    """The absolute tolerance of each number of :func:`table_profile`, in its order: an
    interval's end is a quantile of a finite chain whose bits depend on the machine's
    floating point (another CPU's libm draws another chain), so two runs' ends differ
    by the chains' Monte Carlo error, ``MCSE_SIGMAS * sqrt(2) * MCSE`` (two independent
    chains), and one unit of the written last digit; None (the header's 95, the truth):
    the written digits."""
    out = [None]                                                      # "95 % interval"
    for _, cells, truth in _profile_cells(folder):
        for _, _, low_error, high_error in cells:
            out += [MCSE_SIGMAS * math.sqrt(2.0) * error + 1.01e-3
                    for error in (low_error, high_error)]
        out += [] if truth is None else [None]
    return out


def table_golden(folder):
    """uq golden golden_campaign: FLSa at 80 m, mean over the required bins."""
    ds = _open(folder, "g/golden_campaign.nc")
    required = ds["required"].values.astype(bool)
    lines = [_row("framework", "deviation term, ref. golden lidar", "ref. mast",
                  "unit's u_cal, ref. golden lidar", "ref. mast"),
             _row("---", "---", "---", "---", "---")]
    for framework, label in (("iec", "IEC 61400-12-1"), ("lusr", "LUSR")):
        cells = []
        for name in ("deviation", "calibration"):
            for comparison in ("flsa-flsb", "flsa-mast"):
                at = ds.sel(comparison=comparison, framework=framework, height=80.0)
                cells.append(f"{float(at[name].isel(bin=required).mean()):.4f}")
        lines.append(_row(label, *cells))
    return "\n".join(lines) + "\n\n(m/s; the unit FLSa at 80 m, mean over the required bins 4-16 m/s)"


def table_campaign(folder):
    """uq campaign campaign_buoy: per height, the records' mean TI of the reference, as
    measured and as corrected, the mean bias of each against the reference, and the
    corrected intervals' coverage of the reference's TI (binomial test)."""
    import numpy as np
    ds = _open(folder, "cb/campaign_buoy.nc")
    lines = [_row("height", "records", "TI mast", "TI buoy, measured", "TI buoy, corrected",
                  "MBE measured", "MBE corrected", "95 % intervals covering the mast's TI"),
             _row(*["---"] * 8)]
    for h, height in enumerate(ds["height"].values):
        at = ds.isel(height=h)
        ref, measured, corrected = (100 * at[f"turbulence_intensity_{name}"].values
                                    for name in ("reference", "measured", "corrected"))
        both = np.isfinite(ref) & np.isfinite(corrected)
        n, covered = int(at["coverage_n_records"]), int(at["coverage_n_covered"])
        lines.append(_row(f"{height:g} m", int(both.sum()), f"{ref[both].mean():.2f} %",
                          f"{measured[both].mean():.2f} %", f"{corrected[both].mean():.2f} %",
                          f"{(measured - ref)[both].mean():+.2f} %",
                          f"{(corrected - ref)[both].mean():+.2f} %",
                          f"{covered}/{n} = {100 * covered / n:.1f} % "
                          f"(p = {float(at['coverage_p_value']):.2f})"))
    return "\n".join(lines)


#: The benchmark result the guide's performance page and the README's speed table read.
BENCH_FILE = DOCS / "data" / "bench.nc"


def _verdict(figures, name, unit="x"):
    """``<= 3x: met`` of a figure with a target (:data:`uq.bench.targets.TARGETS`)."""
    from uq.bench.targets import TARGETS
    limit, sense = TARGETS[name]
    met = figures[name] <= limit if sense == "max" else figures[name] >= limit
    return f"{'<=' if sense == 'max' else '>='} {limit:g}{unit}: {'met' if met else 'NOT met'}"


def table_speed(path=BENCH_FILE):
    """The speed targets a user notices, from one ``uq bench`` result file: each figure a
    ratio of two wall times from the same run (or a difference), with its target."""
    import xarray
    with xarray.open_dataset(path) as dataset:
        figures = dict(dataset.attrs)
    methods = ("lhs", "sobol", "mc_cv", "sobol_cv")
    best = min(methods, key=lambda m: figures[f"rubio2022_case_i_{m}_time_to_1e_3_s"])
    records = " / ".join(f"{figures[f'records_per_second_{name}']:.3g}" for name in
                         ("sathe2011_ti", "sathe2011_ti_cw", "floating_lidar_ti"))
    loads = [float(value) for value in re.findall(r"\d+\.\d+", figures["load_average"])]
    ended = figures["history"].split()[0]
    machine = ", ".join(figures["machine"].split(", ")[:3])      # processor, cores, memory
    worst = figures["first_run_worst_name"]
    pairs = int(figures.get(f"first_run_{worst}_pairs", 1))
    worst_pairs = f", median of {pairs} pairs" if pairs > 1 else ""
    lines = [_row("what a user runs", "against", "measured", "target"),
             _row("---", "---", "---", "---"),
             _row(f"`floating_lidar_full` as shipped, {figures['floating_lidar_full_mc_n']:,}"
                  " trials", "drawing its normals alone",
                  f"{figures['floating_lidar_full_mc_over_draw_floor']:.2f}x "
                  f"({figures['floating_lidar_full_mc_s']:.2f} s, "
                  f"{figures['floating_lidar_full_draw_floor_s']:.2f} s)",
                  _verdict(figures, "floating_lidar_full_mc_over_draw_floor")),
             _row("10^6 point-wise corrected scans in roll and pitch", "10^6 static scans",
                  f"{figures['pointwise_motion_over_static']:.2f}x",
                  _verdict(figures, "pointwise_motion_over_static")),
             _row("time to 1e-3 in u(Vh), `rubio2022_case_i`, fastest method "
                  f"({best.replace('_', '+')})", "plain Monte Carlo's",
                  f"{figures['rubio2022_case_i_best_speedup']:.1f}x faster",
                  _verdict(figures, "rubio2022_case_i_best_speedup")),
             _row("first run of every shipped file, numba's cache empty (worst: "
                  f"`{worst}`{worst_pairs})", "the same once the cache is filled",
                  f"{figures['first_run_worst_over_warm_s']:+.1f} s",
                  _verdict(figures, "first_run_worst_over_warm_s", " s")),
             _row("record mode: `sathe2011_ti` / `sathe2011_ti_cw` / `floating_lidar_ti`",
                  "", f"{records} records/s", "stated"), "",
             f"(`{figures['bench_command']}`, {figures['measured_at'][:16].replace('T', ' ')} to "
             f"{ended[11:16]} UTC; {machine}; load average at most {max(loads):.1f}; every "
             "figure on the [performance](docs/performance.md) page)"]
    return "\n".join(lines)


#: README table name -> the absolute tolerance of each of its numbers, where it is not
#: one unit of the written last digit (a Markov chain's quantiles)
TOLERANCES = {"profile_fit": tolerances_profile}

#: README table name -> (runs it needs, the function that renders it)
TABLES = {
    "rubio2022_case_i": (["case_i", "case_i_beam"], table_case_i),
    "rubio2022_misalignment": (["misalignment_gum"], table_misalignment),
    "floating_lidar_waves": (["waves"], table_waves),
    "nacelle_floating": (["nacelle", "nacelle_fixed"], table_nacelle),
    "profile_fit": (["profile"], table_profile),
    "golden_campaign": (["golden"], table_golden),
    "campaign_buoy": (["campaign"], table_campaign),
}

BLOCK = re.compile(r"(<!-- table: (?P<name>[\w.-]+) -->\n)(?P<body>.*?)(\n?<!-- end table -->)",
                   re.S)


def readme_tables(text):
    """{name: the text between its markers} of the README's generated tables."""
    return {m.group("name"): m.group("body") for m in BLOCK.finditer(text)}


def replace_tables(text, tables):
    """The README text with the named tables replaced."""
    def swap(match):
        name = match.group("name")
        if name not in tables:
            return match.group(0)
        return match.group(1) + tables[name].strip("\n") + "\n<!-- end table -->"
    return BLOCK.sub(swap, text)


def uq(arguments, folder):
    """Run the ``uq`` command (this interpreter's) in `folder`; stop on failure."""
    subprocess.run([sys.executable, "-m", "uq.cli", *arguments, "-q"], cwd=folder,
                   check=True)


def make_runs(names, folder, done=None):
    """Make the named runs in `folder` (each once; `done` records what exists)."""
    done = set() if done is None else done
    for name in names:
        if name in done:
            continue
        for command in RUNS[name]:
            uq(command, folder)
        done.add(name)
    return done


def sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _load_average():
    return ", ".join(f"{x:.2f}" for x in os.getloadavg())


def bench(folder, full=False):
    """uq bench into docs/data/bench.nc, with the machine, load and time it ran."""
    import xarray
    before, started = _load_average(), time.strftime("%Y-%m-%d %H:%M", time.gmtime())
    uq(["bench", "-o", "bench.nc"] + ([] if full else ["--quick"]), folder)
    ended = time.strftime("%H:%M UTC", time.gmtime())
    dataset = xarray.load_dataset(Path(folder) / "bench.nc")
    dataset.attrs.update(
        machine=f"{os.cpu_count()} cores ({platform.machine()}), {platform.system()}, "
                f"Python {platform.python_version()}",
        load_average=f"{before} before; {_load_average()} after",
        measured_at=f"{started}-{ended}",
        bench_command="uq bench" if full else "uq bench --quick")
    (DOCS / "data").mkdir(exist_ok=True)
    dataset.to_netcdf(DOCS / "data" / "bench.nc")
    print("docs/data/bench.nc")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bench", action="store_true",
                        help="also run uq bench --quick for the performance page")
    parser.add_argument("--bench-full", action="store_true",
                        help="also run the full uq bench for the performance page")
    parser.add_argument("--only", action="append",
                        choices=sorted(PLOTTED) + sorted(TABLES) + ["speed"],
                        metavar="NAME", help="make only this figure or table (repeatable)")
    args = parser.parse_args(argv)
    manifest = json.loads(MANIFEST.read_text()) if MANIFEST.exists() else {}
    tables = {}
    with tempfile.TemporaryDirectory() as folder:
        done = set()
        for name, (runs, commands, made) in PLOTTED.items():
            if args.only and name not in args.only:
                continue
            make_runs(runs, folder, done)
            for command in commands:
                uq(command, folder)
            shutil.copyfile(Path(folder) / made, DOCS / name)
            manifest[name] = {"commands": [" ".join(["uq", *c]) for run in runs
                                           for c in RUNS[run]] +
                              [" ".join(["uq", *c]) for c in commands],
                              "file": made, "sha256": sha256(DOCS / name)}
            print(f"docs/{name}")
        for name, (runs, render) in TABLES.items():
            if args.only and name not in args.only:
                continue
            make_runs(runs, folder, done)
            tables[name] = render(folder)
            print(f"README.md table {name}")
        if args.bench or args.bench_full:
            bench(folder, full=args.bench_full)
        if args.bench or args.bench_full or (args.only and "speed" in args.only):
            tables["speed"] = table_speed()
            print("README.md table speed")
    MANIFEST.write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n")
    if tables:
        README.write_text(replace_tables(README.read_text(), tables))


if __name__ == "__main__":
    main()
