"""Make the README's figures (docs/*.png) again from the shipped scenarios, the way a user
makes them (``uq run``, ``uq plot``, ``uq fit``, ``uq golden``, ``uq bench``):

    python scripts/docs_figures.py            # every figure but the benchmark (~1 min)
    python scripts/docs_figures.py --bench    # also docs/bench.png (a full uq bench, ~6 min)
    python scripts/docs_figures.py --only rubio2022_case_i.png   # one figure

The runs go to a temporary folder that is removed afterwards; only the figures are copied
into docs/ (they are the repository's own files, so they are replaced). Each figure is the
one ``uq plot`` (or ``uq fit`` / ``uq golden``) writes for that scenario.
"""
import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

DOCS = Path(__file__).resolve().parent.parent / "docs"

#: docs figure -> (uq commands, the figure they write, relative to the run folder)
PLOTTED = {
    "rubio2022_case_i.png": ([["run", "rubio2022_case_i", "-o", "c.nc"], ["plot", "c.nc"]],
                             "c_figures/uncertainty_against_direction.png"),
    "rubio2022_fig2.png": ([["run", "rubio2022_misalignment", "-o", "m.nc"], ["plot", "m.nc"]],
                           "m_figures/fig2_speed_maps.png"),
    "tiana2017_fig4a.png": ([["run", "tiana2017_vad", "-o", "t.nc"], ["plot", "t.nc"]],
                            "t_figures/tiana2017_speed_error_map.png"),
    "floating_lidar_waves.png": ([["run", "floating_lidar_waves", "-o", "w.nc"],
                                  ["plot", "w.nc"]],
                                 "w_figures/motion_correction_comparison.png"),
    "probe_volume.png": ([["run", "probe_volume", "-o", "p.nc"], ["plot", "p.nc"]],
                         "p_figures/probe_bias_against_range.png"),
    "profile_fit.png": ([["run", "floating_lidar_profile", "-o", "f.nc"], ["fit", "f.nc"]],
                        "f_fit_profile.png"),
    "golden_uncertainty_terms.png": ([["golden", "golden_campaign", "-o", "g"]],
                                     "g/figures/uncertainty_terms.png"),
}


def uq(arguments, folder):
    """Run the ``uq`` command (this interpreter's) in `folder`; stop on failure."""
    subprocess.run([sys.executable, "-m", "uq.cli", *arguments, "-q"], cwd=folder,
                   check=True)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bench", action="store_true", help="also run uq bench (~6 min)")
    parser.add_argument("--only", action="append", choices=sorted(PLOTTED), metavar="FIGURE",
                        help="make only this figure of docs/ (repeatable)")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        for name, (commands, made) in PLOTTED.items():
            if args.only and name not in args.only:
                continue
            for command in commands:
                uq(command, folder)
            shutil.copyfile(Path(folder) / made, DOCS / name)
            print(f"docs/{name}")
        if args.bench:
            uq(["bench", "-o", "bench.nc"], folder)
            shutil.copyfile(Path(folder) / "bench.png", DOCS / "bench.png")
            print("docs/bench.png")


if __name__ == "__main__":
    main()
