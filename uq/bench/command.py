"""``uq bench``: run the benchmarks of :mod:`uq.bench.methods`, print the figures, write
``bench.nc``, its plot and ``bench.json`` (:mod:`uq.bench.report`: the machine, its load,
the date and every figure with its target, for a documentation page)."""
import os
import re
import sys
from pathlib import Path

from uq.bench import methods as bench
from uq.bench import targets as speed
from uq.errors import ScenarioError
from uq.files import check_target, save_figure, write_netcdf
from uq.pipeline.metadata import cf_encode, flag_attributes, history


def run_bench(output, quick=False, sizes=None, repeats=None, scale=1):
    """Measure, print and write; returns the benchmark Dataset. `sizes` and `repeats`
    replace the defaults of a full or ``--quick`` run, `scale` shrinks the trial counts
    of the speed targets (:func:`uq.bench.targets.measure`; a small run for tests)."""
    from uq.bench import firstrun, records, report
    from uq.outputs.plots import plot_bench
    output = Path(output)
    if output.suffix != ".nc":
        raise ScenarioError("-o", str(output), "the output file must end in .nc")
    check_target(output)                           # before minutes of measuring
    check_target(output.with_suffix(".png"))
    check_target(output.with_suffix(".json"))
    started, loads = report.now(), {"start": list(os.getloadavg())}
    sizes = sizes or [2**k for k in ((10, 13, 16, 18) if quick else (10, 12, 14, 16, 18, 19))]
    repeats = repeats or (3 if quick else 8)
    dataset = bench.measure(sizes, repeats, progress=_say)
    floors = {name: bench.draw_floor(name, sizes[-1]) for name in bench.SCENES}
    median = dataset["time_s"].median("repeat")
    ratios = []
    for name, (floor, dimension) in floors.items():
        plain = float(median.sel({"scene": name, "method": "mc", "n": sizes[-1]}))
        ratios.append(plain / floor)
        dataset.attrs[f"{name}_mc_over_draw_floor"] = plain / floor
        print(f"{name}: plain mc at n = {sizes[-1]} takes {plain:.3f} s, drawing its "
              f"{dimension} normals per trial {floor:.3f} s: {plain / floor:.1f}x the floor")
    dataset["mc_over_draw_floor"] = ("scene", ratios, {
        "units": "1", "long_name": f"wall time of plain mc at n = {sizes[-1]} over the time "
        "to draw its standard normals alone"})
    targets = bench.time_to_target(dataset)
    _time_to_target(dataset, targets)
    best = {}
    for name in bench.SCENES:
        plain = targets[name, "mc"][0]
        for method in bench.METHODS:
            seconds, extrapolated = targets[name, method]
            dataset.attrs[attribute_name(f"{name}_{method}_time_to_1e-3_s")] = seconds
            print(f"{name:22s} {method:9s} time to 1e-3 in 95 % of runs: {seconds:9.3f} s"
                  f"{' (extrapolated)' if extrapolated else ''}  speed-up vs mc "
                  f"{plain / seconds:7.1f}x")
        best[f"{name}_best_speedup"] = max(plain / targets[name, method][0]
                                           for method in bench.METHODS if method != "mc")
    loads["methods_end"] = list(os.getloadavg())
    figures = speed.measure(quick, progress=_say, scale=scale)
    figures.update(best)
    for name, (value, _) in targets.items():
        figures[attribute_name(f"{name[0]}_{name[1]}_time_to_1e-3_s")] = value
    if not quick:
        figures.update(records.measure(progress=_say))
        figures.update(firstrun.measure(progress=_say))
    dataset.attrs.update({attribute_name(name): value for name, value in figures.items()})
    print("targets (each a ratio of two times measured in this run):")
    for line in speed.verdicts(figures):
        print(f"  {line}")
    if not quick:
        seconds, megabytes = bench.scale()
        figures.update(scale_1e8_s=seconds, scale_1e8_peak_rss_mb=megabytes)
        dataset.attrs.update(scale_1e8_s=seconds, scale_1e8_peak_rss_mb=megabytes)
        print(f"10^8 trials of the same scene: {seconds:.1f} s, peak resident memory "
              f"{megabytes:.0f} MB")
    loads["end"] = list(os.getloadavg())
    command = "uq bench" + (" --quick" if quick else "")
    rows = [(scene, method, seconds, extrapolated)
            for (scene, method), (seconds, extrapolated) in targets.items()]
    document = report.document(figures, speed.TARGETS, started, loads, rows, command)
    dataset.attrs.update(machine=document["machine"], load_average=document["load_average"],
                         measured_at=started, bench_command=command)
    write_netcdf(annotate(dataset), output)
    figure = plot_bench(dataset)
    save_figure(figure, output.with_suffix(".png"), dpi=120)
    report.write(output.with_suffix(".json"), document)
    print(f"wrote {output}, {output.with_suffix('.png')} and {output.with_suffix('.json')}")
    return dataset


def _say(text):
    """A progress line on stderr."""
    print(f"  {text}", file=sys.stderr)


#: Characters allowed in a netCDF/CF attribute name besides letters and digits (CF 2.3).
_NAME_CHARACTERS = re.compile(r"[^A-Za-z0-9_]")


def attribute_name(text):
    """A valid CF attribute name of `text`: each character other than a letter, digit or
    underscore becomes an underscore (``sobol+cv`` -> ``sobol_cv``)."""
    return _NAME_CHARACTERS.sub("_", text)


def _time_to_target(dataset, targets):
    """The time to the target error, per scene and method, as variables (in place)."""
    scenes, methods = list(dataset["scene"].values), list(dataset["method"].values)
    seconds = [[targets[s, m][0] for m in methods] for s in scenes]
    extrapolated = [[targets[s, m][1] for m in methods] for s in scenes]
    dataset["time_to_target"] = (("scene", "method"), seconds, {
        "units": "s", "long_name": f"median wall time to a relative error of u(wind speed) "
        f"<= {bench.TARGET_ERROR:g} in {100 * bench.TARGET_SHARE:g} % of runs"})
    dataset["time_to_target_extrapolated"] = (("scene", "method"), extrapolated, {
        "long_name": "the time to target is extrapolated as n^-1/2 from the largest n",
        **flag_attributes("measured extrapolated")})


#: long_name (and units) of the benchmark's coordinates and reference variables.
BENCH_METADATA = {"scene": ("", "benchmark scene (shipped scenario)"),
                  "method": ("", "sampling method (+cv: with the control variate)"),
                  "n": ("1", "Monte Carlo trials"),
                  "repeat": ("1", "repetition with an independent seed"),
                  "reference_u": ("m s-1", "reference u(wind speed): sobol with the "
                                  "control variate at 2^22 trials"),
                  "reference_relative_error": ("1", "relative standard error of the "
                                               "reference u")}


def annotate(dataset):
    """CF attributes of the benchmark Dataset, in place; returns it."""
    for name, (units, long_name) in BENCH_METADATA.items():
        if name in dataset.variables:
            dataset[name].attrs.update({"long_name": long_name,
                                        **({"units": units} if units else {})})
    dataset.attrs.update(Conventions="CF-1.10", title="uq bench: error of u(wind speed) "
                         "against wall time per sampling method", history=history("uq bench"))
    return cf_encode(dataset)
