"""``uq bench``: run the benchmarks of :mod:`uq.bench.methods`, print the figures, write
``bench.nc`` and its plot."""
import sys
from pathlib import Path

from uq.bench import methods as bench
from uq.errors import ScenarioError
from uq.files import check_target, save_figure, write_netcdf


def run_bench(output, quick=False):
    """Measure, print and write; returns the benchmark Dataset."""
    from uq.outputs.plots import plot_bench
    output = Path(output)
    if output.suffix != ".nc":
        raise ScenarioError("-o", str(output), "the output file must end in .nc")
    check_target(output)                           # before minutes of measuring
    check_target(output.with_suffix(".png"))
    sizes = [2**k for k in ((10, 13, 16, 18) if quick else (10, 12, 14, 16, 18, 19))]
    repeats = 3 if quick else 8
    dataset = bench.measure(sizes, repeats,
                            progress=lambda text: print(f"  {text}", file=sys.stderr))
    floors = {name: bench.draw_floor(name, sizes[-1]) for name in bench.SCENES}
    median = dataset["time_s"].median("repeat")
    for name, (floor, dimension) in floors.items():
        plain = float(median.sel({"scene": name, "method": "mc", "n": sizes[-1]}))
        dataset.attrs[f"{name}_mc_over_draw_floor"] = plain / floor
        print(f"{name}: plain mc at n = {sizes[-1]} takes {plain:.3f} s, drawing its "
              f"{dimension} normals per trial {floor:.3f} s: {plain / floor:.1f}x the floor")
    targets = bench.time_to_target(dataset)
    for name in bench.SCENES:
        plain = targets[name, "mc"][0]
        for method in bench.METHODS:
            seconds, extrapolated = targets[name, method]
            dataset.attrs[f"{name}_{method}_time_to_1e-3_s"] = seconds
            print(f"{name:22s} {method:9s} time to 1e-3 in 95 % of runs: {seconds:9.3f} s"
                  f"{' (extrapolated)' if extrapolated else ''}  speed-up vs mc "
                  f"{plain / seconds:7.1f}x")
    scans = bench.scan_throughput()
    dataset.attrs["scans_1e6_s"] = scans
    print(f"10^6 four-beam scans with radial noise: {scans:.3f} s")
    if not quick:
        seconds, megabytes = bench.scale()
        dataset.attrs.update(scale_1e8_s=seconds, scale_1e8_peak_rss_mb=megabytes)
        print(f"10^8 trials of the same scene: {seconds:.1f} s, peak resident memory "
              f"{megabytes:.0f} MB")
    write_netcdf(dataset, output)
    figure = plot_bench(dataset)
    save_figure(figure, output.with_suffix(".png"), dpi=120)
    print(f"wrote {output} and {output.with_suffix('.png')}")
    return dataset
