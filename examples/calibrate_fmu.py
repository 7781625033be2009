#!/usr/bin/env python3
"""Calibration through an FMU with fmpy and SciPy: fits FMU parameters (a
material's constants, usually) to the measured outputs of a set of
experiments, by weighted least squares (scipy.optimize.least_squares).

The same problem as `meshless-impact calibrate` (its --help), by an
independent path: any FMI host can do this with the FMU alone. Each
experiment (shot) is one run of the FMU (fmpy.simulate_fmu) with its
settings as start values; its measurements are compared with the final
values of the FMU's outputs.

Experiments file (the CLI's format): a CSV, one row per shot; lines that
start with '#' are comments. Columns:
  shot          a label (optional; the row number otherwise)
  NAME          an FMU parameter (a setting of the shot: impact_speed,
                initial_length, ...), in the FMU's units (SI)
  NAME          an FMU output (a measurement: rod_length, mushroom_radius,
                ...); an empty cell means "not measured in this shot"
  sigma_NAME    the uncertainty of the measurement NAME, in its unit
                (optional; 1 % of |measured| where not given)

The fit: residual (simulated - measured) / sigma for each measurement, the
free parameters within their bounds, starting from the FMU's start values
(moved into the bounds). The standard errors come from the Jacobian at the
optimum scaled by the residual, s^2 (J^T J)^-1 with s^2 the sum of squared
residuals over (measurements - free parameters): the CLI's formula.

Examples:
  python examples/calibrate_fmu.py --shots shots.csv \\
      --free jc_a=600e6:1200e6 --free jc_b=200e6:900e6 --set particles_radial=8
  python examples/calibrate_fmu.py --fmu target/fmu/TaylorImpact_fmi2.fmu \\
      --shots data/calibration/house1995_4340_shots.csv --free jc_a=600e6:1200e6 --out fit.json
"""

import argparse
import csv
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_FMU = ROOT / "target" / "fmu" / "TaylorImpact.fmu"

# The relative uncertainty of a measurement without sigma_NAME (the CLI's
# DEFAULT_RELATIVE_SIGMA).
DEFAULT_RELATIVE_SIGMA = 0.01
# A parameter is "determined by the data" when its relative standard error
# is at most 50 % and its correlation with every other at most 0.95 in
# absolute value (the CLI's MAX_RELATIVE_STD, MAX_CORRELATION).
MAX_RELATIVE_STD = 0.5
MAX_CORRELATION = 0.95
# Eigenvalues of the unit-diagonal normal matrix below this are directions
# the data do not see (the CLI's threshold).
NULL_EIGENVALUE = 1e-10


class Fmu:
    """The FMU, read and extracted once; `run` simulates one shot."""

    def __init__(self, path):
        from fmpy import extract, read_model_description

        self.path = str(path)
        self.md = read_model_description(self.path)
        self.unzipdir = extract(self.path)
        self.variables = {v.name: v for v in self.md.modelVariables}
        self.parameters = {n for n, v in self.variables.items() if v.causality == "parameter"}
        self.outputs = [n for n, v in self.variables.items() if v.causality == "output"]
        # What a shot can measure: the continuous outputs (not at_rest).
        self.measurable = [n for n in self.outputs if self.is_continuous(n)]
        self.runs = 0

    def is_integer(self, name):
        return self.variables[name].type in ("Int32", "Int64", "Integer", "UInt32", "UInt64")

    def is_continuous(self, name):
        return self.variables[name].type in ("Float64", "Float32", "Real")

    def start(self, name):
        return float(self.variables[name].start)

    def value(self, name, text):
        """A start value for the parameter `name` from text: an int for an
        integer variable."""
        v = float(text)
        if self.is_integer(name):
            if v != int(v):
                raise ValueError(f"`{name}` is an integer, not {text}")
            return int(v)
        return v

    def run(self, start_values, outputs):
        """The final values of `outputs` of one run from `start_values`."""
        from fmpy import simulate_fmu

        self.runs += 1
        stop_at_rest = None
        if "at_rest" in self.outputs:
            # A rod at rest stays at rest and the FMU holds its outputs to the
            # host's stop time (docs/guide/fmu.md): stop at the first
            # communication point at rest, whose outputs are the final ones
            # (about 40 % of a small run's time saved). step_finished is fmpy's
            # hook; the recorder's last row is the point just sampled.
            outputs = list(outputs) + ["at_rest"]

            def stop_at_rest(_time, recorder):
                names = [c[0] for c in recorder.cols]
                return not recorder.rows[-1][names.index("at_rest")]

        r = simulate_fmu(self.unzipdir, model_description=self.md, start_values=start_values,
                         output=outputs, step_finished=stop_at_rest)
        return {name: float(r[name][-1]) for name in outputs if name != "at_rest"}


def read_shots(path, fmu):
    """The experiments file: a list of shots, each {label, settings:
    {name: value}, observed: [(name, value, sigma or None)]}. An unknown
    column or a bad cell is an error naming the line and column."""
    with open(path, newline="") as f:
        lines = [(k, line) for k, line in enumerate(f, start=1)
                 if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise ValueError(f"{path}: no header")
    rows = list(csv.reader([line for _, line in lines]))
    header = [h.strip() for h in rows[0]]

    def where(i, c):
        return f"{path}, line {lines[i][0]}, column {c + 1}"

    for c, name in enumerate(header):
        if name == "shot" or name in fmu.parameters or name in fmu.measurable:
            continue
        if name.startswith("sigma_") and name[6:] in fmu.measurable:
            continue
        if name in ("outline", "sigma_outline"):
            raise ValueError(f"{where(0, c)}: measured outlines are the CLI's alone; this example fits outputs")
        raise ValueError(f"{where(0, c)}: `{name}` is neither a parameter nor an output of the FMU "
                         f"(nor shot or sigma_NAME); outputs: {', '.join(fmu.measurable)}")
    shots = []
    for i, row in enumerate(rows[1:], start=1):
        if len(row) != len(header):
            raise ValueError(f"{path}, line {lines[i][0]}: {len(row)} cells, the header has {len(header)}")
        cells = {h: (c, v.strip()) for c, (h, v) in enumerate(zip(header, row))}
        shot = {"label": cells["shot"][1] if "shot" in cells else str(i), "line": lines[i][0],
                "settings": {}, "observed": []}

        def number(name):
            c, text = cells[name]
            try:
                v = float(text)
            except ValueError:
                raise ValueError(f"{where(i, c)}: `{text}` is not a number") from None
            if not math.isfinite(v):
                raise ValueError(f"{where(i, c)}: `{text}` is not a finite number")
            return v

        for name in header:
            if name in fmu.parameters:
                c, text = cells[name]
                try:
                    shot["settings"][name] = fmu.value(name, text)
                except ValueError as e:
                    raise ValueError(f"{where(i, c)}: {e}") from None
            elif name in fmu.measurable and cells[name][1] != "":
                sigma = None
                if f"sigma_{name}" in cells and cells[f"sigma_{name}"][1] != "":
                    sigma = number(f"sigma_{name}")
                    if sigma <= 0:
                        raise ValueError(f"{where(i, cells[f'sigma_{name}'][0])}: sigma must be positive")
                shot["observed"].append((name, number(name), sigma))
        shots.append(shot)
    return shots


def parse_free(text, fmu):
    """`NAME=LO:HI` as (name, lo, hi)."""
    name, eq, bounds = text.partition("=")
    lo, colon, hi = bounds.partition(":")
    name = name.strip()
    if not eq or not colon:
        raise ValueError(f"--free {text}: expected NAME=LO:HI, for example jc_a=600e6:1200e6")
    if name not in fmu.parameters:
        raise ValueError(f"--free {text}: `{name}` is not a parameter of the FMU")
    if not fmu.is_continuous(name):
        raise ValueError(f"--free {text}: only a continuous (Float) parameter can be fitted")
    try:
        lo, hi = float(lo), float(hi)
    except ValueError:
        raise ValueError(f"--free {text}: a bound is not a number") from None
    if not lo < hi:
        raise ValueError(f"--free {text}: the lower bound must be below the upper")
    return name, lo, hi


def parse_set(text, fmu):
    name, eq, value = text.partition("=")
    name = name.strip()
    if not eq or name not in fmu.parameters:
        raise ValueError(f"--set {text}: expected NAME=VALUE with NAME a parameter of the FMU")
    return name, fmu.value(name, value)


def weighted_residuals(shots, simulated):
    """(simulated - measured) / sigma for every measurement, shot by shot,
    with sigma the file's or 1 % of |measured|."""
    r = []
    for shot, sim in zip(shots, simulated):
        for name, measured, sigma in shot["observed"]:
            s = sigma if sigma is not None else DEFAULT_RELATIVE_SIGMA * abs(measured)
            r.append((sim[name] - measured) / s)
    return np.array(r)


def uncertainty(names, x, jac, r):
    """Standard errors, correlations and identifiability of the parameters
    `names` at `x` from the Jacobian `jac` (d residual / d x, physical units) of the
    weighted residuals `r` at the optimum: covariance s^2 (J^T J)^+ with
    s^2 = |r|^2 / (m - p), the pseudo-inverse taken on the normal matrix
    scaled to a unit diagonal over the directions the data see (the CLI's
    src/calibrate/stats.rs)."""
    m, p = jac.shape
    dof = m - p
    s2 = float(r @ r) / dof if dof > 0 else None
    g = jac.T @ jac
    d = np.sqrt(np.diag(g))
    c = np.zeros((p, p))
    seen = d > 0
    c[np.ix_(seen, seen)] = g[np.ix_(seen, seen)] / np.outer(d[seen], d[seen])
    w, v = np.linalg.eigh(c)
    unseen = ~seen
    cinv = np.zeros((p, p))
    for k in range(p):
        if w[k] < NULL_EIGENVALUE:
            unseen |= np.abs(v[:, k]) > 1e-6
        else:
            cinv += np.outer(v[:, k], v[:, k]) / w[k]
    std = [None if unseen[a] or s2 is None else math.sqrt(s2 * cinv[a, a]) / d[a] for a in range(p)]
    corr = [[None if unseen[a] or unseen[b] else (1.0 if a == b else cinv[a, b] / math.sqrt(cinv[a, a] * cinv[b, b]))
             for b in range(p)] for a in range(p)]
    why = []
    for a in range(p):
        if unseen[a]:
            why.append("the data do not depend on it (or only through a combination of the others)")
        elif std[a] is None:
            why.append(f"{m} measurements for {p} free parameters leave no residual to scale its uncertainty")
        elif not std[a] / abs(x[a]) <= MAX_RELATIVE_STD:
            why.append(f"relative standard error {100 * std[a] / abs(x[a]):.0f} % (over {100 * MAX_RELATIVE_STD:.0f} %)")
        else:
            others = [(abs(corr[a][b]), b) for b in range(p) if b != a and corr[a][b] is not None]
            worst = max(others, default=(0.0, None))
            why.append(f"correlation {corr[a][worst[1]]:+.3f} with {names[worst[1]]}: the data cannot tell them apart"
                       if worst[0] > MAX_CORRELATION else None)
    return std, corr, why, dof, s2


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--fmu", default=str(DEFAULT_FMU), help="FMU to run (FMI 3 or FMI 2); default %(default)s")
    ap.add_argument("--shots", required=True, metavar="FILE.csv", help="the experiments (the CLI's format)")
    ap.add_argument("--free", action="append", required=True, metavar="NAME=LO:HI",
                    help="a free parameter and its bounds (repeatable); it starts from the FMU's start value")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="a parameter fixed in every shot (repeatable), e.g. particles_radial=8")
    ap.add_argument("--diff-step", type=float, default=0.01,
                    help="finite-difference step, relative (default %(default)s, the CLI's --fd-step)")
    ap.add_argument("--xtol", type=float, default=1e-6,
                    help="least_squares' xtol, on the norm of a step of the parameters scaled by their "
                         "start values (default %(default)s)")
    ap.add_argument("--max-nfev", type=int, default=100,
                    help="cap on evaluations of all shots, Jacobians excluded (default %(default)s)")
    ap.add_argument("--out", metavar="FILE.json", help="write the answer as JSON")
    ap.add_argument("-q", "--quiet", action="store_true", help="no line per evaluation")
    args = ap.parse_args(argv)

    try:
        fmu = Fmu(args.fmu)
        fixed = dict(parse_set(s, fmu) for s in args.set)
        free = [parse_free(f, fmu) for f in args.free]
        shots = read_shots(args.shots, fmu)
    except (ValueError, OSError) as e:
        ap.error(str(e))
    names = [n for n, _, _ in free]
    for n in names:
        if n in fixed:
            ap.error(f"`{n}` is both free (--free) and fixed (--set)")
        if any(n in s["settings"] for s in shots):
            ap.error(f"`{n}` is free and a column of {args.shots}")
    m = sum(len(s["observed"]) for s in shots)
    if m < len(free):
        ap.error(f"{m} measurements cannot determine {len(free)} free parameters")
    lo = np.array([f[1] for f in free])
    hi = np.array([f[2] for f in free])
    x0 = np.clip([fmu.start(n) for n in names], lo, hi)
    # Scaled unknowns u = x / scale, of order 1: least_squares' diff_step is
    # relative to max(1, |u|), so with u near 1 it is a step relative to the
    # parameter's own size whatever its unit (jc_a in Pa, jc_c about 0.01).
    scale = np.where(x0 != 0, np.abs(x0), np.maximum(np.abs(lo), np.abs(hi)))

    t0 = time.perf_counter()

    def simulate(x):
        out = []
        for s in shots:
            start = {**fixed, **s["settings"], **dict(zip(names, map(float, x)))}
            out.append(fmu.run(start, [o[0] for o in s["observed"]]))
        return out

    cache = {}  # each point's values: least_squares asks again for x0, and the report for its answer

    def evaluate(x):
        key = np.asarray(x, dtype=float).tobytes()
        if key not in cache:
            cache[key] = simulate(x)
        return cache[key]

    def residuals(u):
        x = u * scale
        try:
            r = weighted_residuals(shots, evaluate(x))
        except Exception as e:  # a solver stop (fmpy raises on the FMU's Error)
            # Not finite: least_squares' "trf" refuses such a trial point and
            # shrinks its trust region, as the CLI refuses a failed step. At
            # the start point (checked below), or while differencing for a
            # Jacobian, it ends the fit with an error instead.
            if not args.quiet:
                print(f"  a run failed at {dict(zip(names, x))}: {e}", file=sys.stderr)
            return np.full(m, np.nan)
        if not args.quiet:
            print(f"  {fmu.runs:4d} runs: objective {r @ r:.6e} at "
                  + ", ".join(f"{n}={v:.6e}" for n, v in zip(names, x)), flush=True)
        return r

    from scipy.optimize import least_squares

    r_before = residuals(x0 / scale)
    if not np.all(np.isfinite(r_before)):
        print("the runs at the starting point failed: nothing to fit from", file=sys.stderr)
        return 1
    # method="trf": the trust-region reflective method, least_squares' one
    # for bounds ("lm", MINPACK's Levenberg-Marquardt, takes no bounds).
    # jac="2-point": forward differences, one run of every shot per free
    # parameter (p+1 evaluations per Jacobian; "3-point" would cost 2p).
    # diff_step=0.01: a 1 % relative forward step, the CLI's default. The
    # solver's final values are not smooth on a fine scale, though not from
    # round-off: they are piecewise smooth, with small jumps (discrete events
    # of a particle run). On the small twin of tests/fmu/test_calibrate_fmu.py
    # (particles_radial=8, jc_a 900 MPa), rod_length is a sawtooth in jc_a:
    # a slope within a tooth about 1.5 times the trend, and a drop of about
    # 5.6e-5 of itself every 0.1 to 0.25 % of jc_a (mushroom_radius jumps
    # too). A step near sqrt(machine epsilon), least_squares' default,
    # differences within one tooth: a consistent slope, but the tooth's, not
    # the trend's (standard errors 22 % smaller for jc_a than the CLI's). A
    # 1 % step spans several teeth and measures the trend to within about
    # 10 % (the tooth over the trend's change in 1 %: the secants over 0.5 to
    # 2 % vary so); with the same step as the CLI's the two standard errors
    # can be compared. Its truncation error only slows the last Gauss-Newton
    # steps: the error shrinks about 3.5 times an iteration on the twin.
    # xtol: stop when a step moves the scaled parameters by less than xtol
    # of their norm (1e-6 by default: far inside the standard errors of 1 %
    # measurements); ftol and gtol are least_squares' defaults (1e-8).
    res = least_squares(residuals, x0 / scale, bounds=(lo / scale, hi / scale), method="trf", jac="2-point",
                        diff_step=args.diff_step, x_scale=1.0, xtol=args.xtol, max_nfev=args.max_nfev)
    wall = time.perf_counter() - t0
    x = res.x * scale
    # The Jacobian at the optimum (res.jac is taken at res.x), in physical
    # units: d r / d x = (d r / d u) / scale.
    jac = res.jac / scale
    std, corr, why, dof, s2 = uncertainty(names, x, jac, res.fun)
    fitted = evaluate(x)  # the answer's values, for the report (already run)
    r_after = weighted_residuals(shots, fitted)

    print(f"calibration through {Path(args.fmu).name} on {len(shots)} experiments ({m} measurements): "
          f"{'converged' if res.status > 0 else 'not converged'} ({res.message})")
    print(f"{'parameter':<24} {'start':>14} {'fitted':>14} {'std':>12} {'std %':>8}  determined by the data")
    for k, n in enumerate(names):
        rel = "-" if std[k] is None else f"{100 * std[k] / abs(x[k]):.2f}"
        print(f"{n:<24} {x0[k]:>14.6e} {x[k]:>14.6e} {'-' if std[k] is None else format(std[k], '.3e'):>12} "
              f"{rel:>8}  {'yes' if why[k] is None else 'NO: ' + why[k]}")
    for name in dict.fromkeys(o[0] for s in shots for o in s["observed"]):
        e = [100 * (f[name] - v) / v for s, f in zip(shots, fitted) for n, v, _ in s["observed"] if n == name]
        print(f"{name}: mean |error| {np.mean(np.abs(e)):.3f}%, largest {np.max(np.abs(e)):.3f}%")
    print(f"objective {r_before @ r_before:.4e} -> {r_after @ r_after:.4e}; {fmu.runs} FMU runs "
          f"({res.nfev} evaluations, {res.njev} Jacobians), wall time {wall:.1f} s")

    if args.out:
        answer = {
            "fmu": str(args.fmu),
            "names": names,
            "start": dict(zip(names, x0.tolist())),
            "bounds": {n: [lo_, hi_] for n, lo_, hi_ in free},
            "parameters": dict(zip(names, x.tolist())),
            "std": dict(zip(names, std)),
            "correlation": corr,
            "identifiable": {n: w is None for n, w in zip(names, why)},
            "not_identifiable_because": {n: w for n, w in zip(names, why) if w is not None},
            "degrees_of_freedom": dof,
            "scale": s2,
            "objective_before": float(r_before @ r_before),
            "objective_fitted": float(r_after @ r_after),
            "jacobian": jac.tolist(),
            "experiments": [{"shot": s["label"], "line": s["line"], "settings": s["settings"],
                             "measured": {n: v for n, v, _ in s["observed"]},
                             "fitted": {n: f[n] for n, _, _ in s["observed"]}} for s, f in zip(shots, fitted)],
            "method": {"least_squares": "trf", "jac": "2-point", "diff_step": args.diff_step, "xtol": args.xtol},
            "status": int(res.status),
            "message": res.message,
            "converged": bool(res.status > 0),
            "nfev": int(res.nfev),
            "njev": int(res.njev),
            "runs": fmu.runs,
            "wall_time_s": wall,
        }
        Path(args.out).write_text(json.dumps(answer, indent=2) + "\n")
        print(f"written: {args.out}")
    return 0 if res.status > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
