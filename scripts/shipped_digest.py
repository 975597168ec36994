"""Digest of every shipped scenario's results, to show that a change alters no number.

    python scripts/shipped_digest.py > before.json      # on the old version
    python scripts/shipped_digest.py --compare before.json   # on the new one
    python scripts/shipped_digest.py --values-only > before.json   # values, not metadata
    python scripts/shipped_digest.py --model numpy --agree   # numpy against compiled
    python scripts/shipped_digest.py --save before/          # every value, one .nc each
    python scripts/shipped_digest.py --close before/         # largest relative difference


Each scenario runs as shipped (``uq run``'s code path, ``uq golden`` for golden
configurations, ``uq campaign`` for campaign configurations); the digest is a SHA-256 of every variable's and coordinate's bytes and
of the attributes that are not timings. Bit-identical results give identical digests.

``--values-only`` digests each variable's values alone (as float64 where numeric, so a
boolean stored as a 0/1 flag byte has the digest of the boolean; strings as Python
strings, however they are stored), without its attributes
and the global ones: a change of metadata (CF attributes, coordinates' encoding) then
shows no difference, a change of any number does. Variables that are new in the later
version are listed but do not count as differences.
"""
import argparse
import contextlib
import io
import hashlib
import json
import sys
import tempfile
from pathlib import Path

import numpy as np
import xarray as xr

SCENARIOS = Path(__file__).resolve().parent.parent / "scenarios"
VOLATILE = ("runtime_s", "history", "uq_version")


def digest(dataset):
    """Variable name -> SHA-256 of its dtype, shape and bytes (and its attributes)."""
    out = {}
    for name in sorted(dataset.variables):
        values = np.ascontiguousarray(dataset.variables[name].values)
        h = hashlib.sha256(f"{values.dtype}{values.shape}".encode())
        h.update(values.tobytes() if values.dtype != object else repr(values.tolist()).encode())
        h.update(repr(sorted(dataset.variables[name].attrs.items(), key=str)).encode())
        out[name] = h.hexdigest()[:16]
    attrs = {k: v for k, v in dataset.attrs.items() if k not in VOLATILE}
    out["attrs"] = hashlib.sha256(repr(sorted(attrs.items(), key=str)).encode()).hexdigest()[:16]
    return out


def values_digest(dataset):
    """Variable name -> SHA-256 of its shape and values alone (no dtype, no attributes)."""
    out = {}
    for name in sorted(dataset.variables):
        values = np.ascontiguousarray(dataset.variables[name].values)
        if values.dtype.kind in "biuf":
            values = values.astype(np.float64)
        elif values.dtype.kind in "US":         # strings stored as characters: as objects
            values = values.astype(object)
        h = hashlib.sha256(f"{values.shape}".encode())
        h.update(values.tobytes() if values.dtype != object else repr(values.tolist()).encode())
        out[name] = h.hexdigest()[:16]
    return out


def shipped(digest=digest, model="compiled"):
    """Name -> digest of every shipped scenario's results, run with `model` (``uq run
    --model``; golden reports run as ``uq golden`` does)."""
    import uq
    from uq.cli import main
    results = {}
    for path in sorted(SCENARIOS.glob("*.yaml")):
        text = path.read_text()
        command = "golden" if "golden:" in text else "campaign" if "\ncampaign:" in text \
            else None
        if command is not None:
            if command == "golden" and "synthetic" not in text and "comparisons" not in text:
                continue
            with tempfile.TemporaryDirectory() as folder:
                with contextlib.redirect_stdout(io.StringIO()):
                    main([command, str(path), "-o", str(Path(folder) / "g")])
                nc = next((Path(folder) / "g").glob("*.nc"))
                with xr.open_dataset(nc) as ds:
                    results[path.stem] = digest(ds.load())
            continue
        print(f"running {path.name}", file=sys.stderr)
        results[path.stem] = digest(uq.run(str(path), model=model))
    return results


def results(model="compiled"):
    """Name -> Dataset of every shipped scenario as :func:`shipped` runs it."""
    return shipped(lambda dataset: dataset, model)


def closeness(before, now, floor=0.01):
    """(scenario, variable, largest |now - before| / the variable's scale) of every float
    variable, the worst first; the scale is the largest |before| of the variable, at
    least `floor` of its unit (so a value that is zero up to rounding, the vertical wind
    of a level lidar at 1e-16 m s-1 or a direction of 1e-30 deg, is held to 1e-12 x 0.01
    = 1e-14 of its unit, not to itself); a direction [deg] compared on the circle."""
    rows = []
    for name, old in before.items():
        new = now.get(name)
        for variable in old.data_vars:
            a = old[variable].values
            if a.dtype.kind != "f" or new is None or variable not in new:
                continue
            b = new[variable].values
            if a.shape != b.shape:
                rows.append((name, variable, np.inf))
                continue
            both_nan = np.isnan(a) & np.isnan(b)
            gap = np.where(both_nan, 0.0, _gap(variable, a, b))
            scale = max(float(np.nanmax(np.abs(a), initial=0.0)), floor)
            worst = np.nanmax(np.where(np.isnan(gap), np.inf, gap / scale), initial=0.0)
            rows.append((name, variable, float(worst)))
    return sorted(rows, key=lambda row: -row[2])


def _gap(name, one, two):
    """|one - two|; for a direction [deg] on the circle (359.99... and 0 are 0.01 apart)."""
    gap = np.abs(one - two)
    return np.minimum(gap, 360.0 - gap) if name.startswith("wind_direction") else gap


def agreement(model="numpy"):
    """Name -> (variable, largest |difference|) between `model` and the compiled model on
    every shipped ``uq run`` scenario as shipped (the worst variable of each), and the
    overall largest difference of the wind outputs' values [m s-1 or deg]."""
    import uq
    worst = {}
    for path in sorted(SCENARIOS.glob("*.yaml")):
        text = path.read_text()
        if "golden:" in text or "\ncampaign:" in text:
            continue
        print(f"running {path.name} twice", file=sys.stderr)
        one, two = uq.run(str(path)), uq.run(str(path), model=model)
        gaps = {name: float(np.nanmax(_gap(name, one[name].values, two[name].values)))
                for name in one.data_vars if one[name].dtype.kind == "f"
                and np.any(np.isfinite(one[name].values))}
        name = max(gaps, key=gaps.get)
        worst[path.stem] = (name, gaps[name])
    return worst


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--compare", help="digest file of the earlier version")
    parser.add_argument("--values-only", action="store_true",
                        help="digest the values of the variables only, not their metadata")
    parser.add_argument("--model", choices=("compiled", "numpy"), default="compiled",
                        help="the measurement model of the runs (uq run --model)")
    parser.add_argument("--agree", action="store_true",
                        help="run every scenario with --model and with the compiled model "
                        "and print the largest difference of each")
    parser.add_argument("--save", help="write every scenario's results into this folder")
    parser.add_argument("--close", help="folder of --save: print the largest relative "
                        "difference of each float variable (exit 1 above --rtol)")
    parser.add_argument("--rtol", type=float, default=1e-12)
    parser.add_argument("--floor", type=float, default=0.01,
                        help="least scale of a variable, in its unit (see closeness)")
    args = parser.parse_args()
    if args.save:
        Path(args.save).mkdir(parents=True, exist_ok=True)
        for name, dataset in results(args.model).items():
            dataset.to_netcdf(Path(args.save) / f"{name}.nc")
        return 0
    if args.close:
        before = {path.stem: xr.load_dataset(path) for path in Path(args.close).glob("*.nc")}
        rows = closeness(before, results(args.model), args.floor)
        for name, variable, worst in rows[:15]:
            print(f"{name} {variable}: {worst:.3g}")
        bad = [row for row in rows if not row[2] <= args.rtol]
        print(f"{len(rows)} variables: {'all' if not bad else f'{len(bad)} not'} within "
              f"{args.rtol:g} relative")
        return 1 if bad else 0
    if args.agree:
        for name, (variable, gap) in agreement(args.model).items():
            print(f"{name}: largest difference {gap:.3g} ({variable})")
        return 0
    now = shipped(values_digest if args.values_only else digest, args.model)
    if not args.compare:
        json.dump(now, sys.stdout, indent=1)
        return 0
    before = json.loads(Path(args.compare).read_text())
    differ = [(s, v) for s in before for v in before[s]
              if now.get(s, {}).get(v) != before[s][v]]
    new = [(s, v) for s in now for v in now[s] if v not in before.get(s, {})]
    if args.values_only:
        for s, v in new:
            print(f"new: {s} {v}")
    else:
        differ += new
    for s, v in differ:
        print(f"differs: {s} {v}")
    print(f"{len(before)} scenarios, {sum(map(len, before.values()))} variables: "
          f"{'bit-identical' if not differ else f'{len(differ)} differ'}")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
