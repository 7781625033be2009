#!/usr/bin/env python3
"""Scripted sweep through the TaylorImpact FMU with fmpy.

Runs the House et al. (1995) Table 1 configurations (data/house1995_4340_table1.csv),
or any CSV of cases, through the FMU, one case per process: locally with a
process pool by default, or on a Dask cluster with --scheduler ADDRESS.
Writes a CSV with the final observables, the errors against the experiment
(where the case file has them) and the wall time of each run.

Case CSV: lines starting with '#' are comments. Recognised columns:
  test         case label (optional; the row number otherwise)
  D0_mm, L0_mm, V_mps   rod diameter, rod length (mm), impact speed (m/s)
  Lf_test_mm, Df_test_mm, Lu_test_mm   measured final length, face diameter,
               undeformed length (mm), optional
  any FMU parameter name (SI units, e.g. jc_a, initial_temperature)

Examples:
  python examples/sweep_fmu.py                                   # Table 1, local
  python examples/sweep_fmu.py --particles-radial 8 --cases 1,7 --out quick.csv
  python examples/sweep_fmu.py --scheduler tcp://10.0.0.5:8786   # on a Dask cluster
"""

import argparse
import csv
import multiprocessing
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_FMU = ROOT / "target" / "fmu" / "TaylorImpact.fmu"
DEFAULT_CASES = ROOT / "data" / "house1995_4340_table1.csv"

# Columns of the case file that map onto FMU parameters (mm -> m).
GEOMETRY = {"D0_mm": ("initial_diameter", 1e-3), "L0_mm": ("initial_length", 1e-3), "V_mps": ("impact_speed", 1.0)}
# Measured values and the observable each is compared with (observable in m,
# diameter = 2 x mushroom_radius).
EXPERIMENT = {
    "Lf_test_mm": ("rod_length", 1.0),
    "Df_test_mm": ("mushroom_radius", 2.0),
    "Lu_test_mm": ("undeformed_length", 1.0),
}


def read_cases(path):
    """Rows of a case CSV (comment lines dropped) as dicts of strings."""
    with open(path, newline="") as f:
        lines = [line for line in f if line.strip() and not line.lstrip().startswith("#")]
    rows = list(csv.DictReader(lines))
    for k, row in enumerate(rows, start=1):
        row.setdefault("test", str(k))
    return rows


def case_parameters(row, parameter_names):
    """FMU start values of one case."""
    params = {}
    for column, value in row.items():
        if value is None or value == "":
            continue
        if column in GEOMETRY:
            name, scale = GEOMETRY[column]
            params[name] = float(value) * scale
        elif column in parameter_names:
            params[column] = float(value)
    return params


def run_case(fmu_path, label, params, step):
    """Simulates one case; returns a result row. Runs in a worker process."""
    from fmpy import simulate_fmu

    start = time.perf_counter()
    row = {"test": label, **params}
    try:
        res = simulate_fmu(
            str(fmu_path),
            start_values=params,
            output=["rod_length", "mushroom_radius", "undeformed_length", "max_plastic_strain",
                    "max_temperature", "energy_error", "at_rest"],
            output_interval=step,
            early_return_allowed=True,
        )
        last = res[-1]
        for name in res.dtype.names:
            row[name] = bool(last[name]) if name == "at_rest" else float(last[name])
        # The FMU holds its outputs past the rod's rest and the run goes on
        # to the stop time; with early return allowed it returns at the
        # moment of rest: the first row at rest (docs/guide/fmu.md).
        rest = [t for t, r in zip(res["time"], res["at_rest"]) if r]
        row["end_time"] = float(rest[0]) if rest else row["time"]
        del row["time"]
        row["error"] = ""
    except Exception as e:  # a solver stop or a bad value: reported, not fatal
        row["error"] = str(e).replace("\n", " ")
    row["wall_time_s"] = time.perf_counter() - start
    return row


def add_errors(result, case):
    """Relative errors (%) of the final values against the experiment."""
    for column, (name, factor) in EXPERIMENT.items():
        if case.get(column) and name in result and not result.get("error"):
            measured = float(case[column])
            computed_mm = result[name] * factor * 1e3
            key = column.replace("_test_mm", "")
            result[f"{key}_mm"] = computed_mm
            result[f"{key}_test_mm"] = measured
            result[f"{key}_error_pct"] = 100.0 * (computed_mm - measured) / measured
    return result


def parse_sets(items, parameter_names, ap):
    """`--set NAME=VALUE` items as {NAME: float}; an unknown name is an
    error of the argument parser `ap`."""
    out = {}
    for item in items:
        name, _, value = item.partition("=")
        if name not in parameter_names:
            ap.error(f"unknown parameter {name!r}; allowed: {', '.join(sorted(parameter_names))}")
        out[name] = float(value)
    return out


def run_jobs(run, jobs, workers, scheduler):
    """`run(*job)` for every job, results in order: on the Dask cluster at
    `scheduler` when given, else on a local pool of `workers` processes.
    `run` must be a function of the script that is run (`__main__`), which
    travels to Dask workers by value, and open the FMU itself: the FMU must
    exist at its path on every worker (a shared file system or a copy), with
    fmpy installed."""
    if scheduler:
        from dask.distributed import Client

        with Client(scheduler) as client:
            futures = [client.submit(run, *job, pure=False) for job in jobs]
            return client.gather(futures)
    # "spawn": each worker starts clean (no inherited solver threads).
    with ProcessPoolExecutor(max_workers=max(1, min(workers or 1, len(jobs))),
                             mp_context=multiprocessing.get_context("spawn")) as pool:
        return list(pool.map(run, *zip(*jobs)))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--fmu", default=str(DEFAULT_FMU), help="FMU to run (FMI 3 or FMI 2); default %(default)s")
    ap.add_argument("--cases", default=str(DEFAULT_CASES),
                    help="case CSV, or a comma-separated list of test labels of the default Table 1 file")
    ap.add_argument("--out", default="sweep_fmu.csv", help="result CSV (default %(default)s)")
    ap.add_argument("--particles-radial", type=int, default=None,
                    help="particles across the radius for every case (default: the FMU's, 20)")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="an FMU parameter for every case (repeatable)")
    ap.add_argument("--step", type=float, default=1e-6, help="communication step in s (default %(default)s)")
    ap.add_argument("--workers", type=int, default=os.cpu_count(), help="local worker processes")
    ap.add_argument("--scheduler", default=None,
                    help="address of a Dask scheduler (e.g. tcp://host:8786); run there instead of locally")
    args = ap.parse_args(argv)

    from fmpy import read_model_description

    md = read_model_description(args.fmu)
    parameter_names = {v.name for v in md.modelVariables if v.causality == "parameter"}

    if Path(args.cases).exists():
        cases = read_cases(args.cases)
    else:
        wanted = [c.strip() for c in args.cases.split(",")]
        cases = [c for c in read_cases(DEFAULT_CASES) if c["test"] in wanted]
        missing = set(wanted) - {c["test"] for c in cases}
        if missing:
            ap.error(f"no case file {args.cases!r} and no Table 1 tests {sorted(missing)}")

    common = parse_sets(args.set, parameter_names, ap)
    if args.particles_radial is not None:
        common["particles_radial"] = args.particles_radial

    jobs = [(args.fmu, c["test"], {**case_parameters(c, parameter_names), **common}, args.step) for c in cases]
    t0 = time.perf_counter()
    results = run_jobs(run_case, jobs, args.workers, args.scheduler)
    wall = time.perf_counter() - t0

    rows = [add_errors(r, c) for r, c in zip(results, cases)]
    columns = []
    for r in rows:
        for k in r:
            if k not in columns:
                columns.append(k)
    with open(args.out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns)
        w.writeheader()
        w.writerows(rows)

    for r in rows:
        if r.get("error"):
            print(f"test {r['test']}: ERROR {r['error']}", file=sys.stderr)
        else:
            errs = ", ".join(f"{k} {r[k]:+.2f}%" for k in r if k.endswith("_error_pct"))
            print(f"test {r['test']}: rod_length {r['rod_length'] * 1e3:.3f} mm, "
                  f"face diameter {2e3 * r['mushroom_radius']:.3f} mm ({errs}), {r['wall_time_s']:.1f} s")
    print(f"{len(rows)} cases in {wall:.1f} s -> {args.out}")
    return 1 if any(r.get("error") for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
