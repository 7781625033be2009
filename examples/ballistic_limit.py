#!/usr/bin/env python3
"""The ballistic limit through the BallisticImpact FMU (the `penetration`
scene) with fmpy: sweeps the impact speed, records each shot's residual
velocity, fits the Lambert-Jonas curve V_r = a (V^p - V_bl^p)^(1/p)
(examples/lambert_jonas.py), prints V_bl, a, p and the table of shots, and
plots them with the fit.

One shot per process: locally with a process pool by default, or on a Dask
cluster with --scheduler ADDRESS (as examples/sweep_fmu.py).

With --package the shots run through the Python package instead of the FMU
(`pip install ./python`; docs/guide/python.md): its
meshless_impact.ballistic_limit runs the sweep on a thread pool (or the
Dask cluster), decides each shot's status by the same rule and fits the
same curve, and this script prints, writes and plots what it returns.

Each shot runs with run_until = outcome: it ends as soon as the scene
decides its outcome from the state (the output shot_outcome; README,
"The shot's outcome"), with end_time as the cap. Its status:
  through    shot_outcome 1, perforated: wholly past the plate's original
             back face and faster along the flight than the intact plate
             material around the hole; its projectile_velocity then is the
             residual velocity V_r (near the ballistic limit the fragments
             ahead of it may still slow it a little: an upper bound);
  stopped    shot_outcome 2: not perforated, and no faster than the plate's
             centre of mass (with the free rim, the capture speed
             m_p V / (m_p + m_plate), at which projectile and plate move on
             together): V_r = 0;
  unsettled  shot_outcome 0 at end_time, the cap: neither yet. Left out of
             the fit unless --fit-unsettled is given (its V_r is then its
             velocity at the cap); with --extend K the script runs these
             shots again with twice the end time, up to K times (the
             column time_s is when the shot ended: the FMU returns early
             at its outcome, the host then runs on to end_time with the
             outputs held);
  error      the FMU run stopped with an error (for example a named solver
             stop such as a particle spacing collapse): reported with the
             message and left out of the fit; the CSV has the outputs at the
             stop.

Exit status 0 when every shot ran and the curve was fitted, 1 otherwise.

Examples:
  python examples/ballistic_limit.py --speeds 600:2000:200           # the seed's case
  python examples/ballistic_limit.py --speeds 800,1000,1200,1500 --particles-radial 4 \\
      --plate-thickness 0.004 --end-time 2e-5 --out shots.csv --plot shots.svg
  python examples/ballistic_limit.py --scheduler tcp://10.0.0.5:8786 --speeds 500:2500:100
  python examples/ballistic_limit.py --package --speeds 400:1600:150 --particles-radial 3 \\
      --set plate_diameter=0.02 --end-time 2e-5
"""

import argparse
import csv
import math
import os
import sys
import time
from pathlib import Path

import lambert_jonas
from sweep_fmu import parse_sets, run_jobs

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_FMU = ROOT / "target" / "fmu" / "BallisticImpact.fmu"
OUTPUTS = ["projectile_velocity", "projectile_extent", "hole_radius", "damaged_fraction",
           "pulverized_fraction", "max_damage", "energy_error", "projectile_clearance", "shot_outcome"]
# The scene's run_until levels: the sweep ends each shot at its outcome.
RUN_UNTIL_OUTCOME = 1
COLUMNS = ["V_mps", "status", "Vr_mps", "capture_speed_mps", "velocity_change_mps", *OUTPUTS,
           "time_s", "end_time_s", "error", "wall_time_s"]


def parse_speeds(text):
    """Impact speeds (m/s) from `A,B,C` or `START:STOP:STEP` (STOP
    included)."""
    if ":" in text:
        start, stop, step = (float(x) for x in text.split(":"))
        if not step > 0 or stop < start:
            raise ValueError(f"--speeds {text}: need START <= STOP and STEP > 0")
        n = int(math.floor((stop - start) / step + 1e-9))
        return [start + k * step for k in range(n + 1)]
    return [float(x) for x in text.split(",") if x.strip()]


def run_shot(fmu_path, params, end_time, step):
    """Runs one shot through the FMU to `end_time`, recording every `step`;
    returns its row: the final outputs and the change of the projectile's
    velocity over the last tenth of the run, or the error (the messages the
    FMU logged) with the outputs at the stop. Runs in a worker process."""
    import shutil

    from fmpy import extract, instantiate_fmu, read_model_description, simulate_fmu

    start = time.perf_counter()
    md = read_model_description(fmu_path)
    errors = []

    # The FMU's log: errors are kept for the report (status 3 = Error).
    if md.fmiVersion.startswith("3"):
        def logger(env, status, category, message):
            if status >= 3:
                errors.append(message.decode())
    else:
        def logger(env, instance, status, category, message):
            if status >= 3:
                errors.append(message.decode())

    unzipdir = extract(fmu_path)
    fmu = instantiate_fmu(unzipdir, md, "CoSimulation", logger=logger, early_return_allowed=True)
    row = {"V_mps": params["impact_speed"]}
    try:
        res = simulate_fmu(unzipdir, model_description=md, fmu_instance=fmu, start_values=params,
                           output=OUTPUTS, stop_time=end_time, output_interval=step,
                           early_return_allowed=True)
        row.update({name: float(res[name][-1]) for name in OUTPUTS})
        # The FMU holds its outputs past the scene's end and the host runs
        # on to stop_time; with early return allowed it returned at the
        # shot's end: the first row with the outcome decided (or the last).
        t, v, outcome = res["time"], res["projectile_velocity"], res["shot_outcome"]
        end = next((i for i in range(len(t)) if outcome[i] != 0), len(t) - 1)
        k = next(i for i in range(end + 1) if t[i] >= 0.9 * t[end])
        row["velocity_change_mps"] = abs(float(v[end] - v[k]))
        row["time_s"] = float(t[end])
        row["error"] = ""
    except Exception as e:  # a solver stop or a bad value: reported, not fatal
        row["error"] = " | ".join(errors) or str(e)
        try:  # the outputs at the stop (the FMU is Terminated, reads work)
            variables = {v.name: v.valueReference for v in md.modelVariables}
            get = fmu.getFloat64 if hasattr(fmu, "getFloat64") else fmu.getReal
            row.update(zip(OUTPUTS, get([variables[n] for n in OUTPUTS])))
        except Exception:
            pass
    finally:
        fmu.freeInstance()
        shutil.rmtree(unzipdir, ignore_errors=True)
    row["wall_time_s"] = time.perf_counter() - start
    return row


def capture_speed(p):
    """m_p V / (m_p + m_plate): the speed of projectile and whole plate moving
    together, from the shot's parameters `p` (every parameter's value)."""
    mp = p["projectile_density"] * math.pi / 4 * p["projectile_diameter"] ** 2 * p["projectile_length"]
    mt = p["plate_density"] * math.pi / 4 * p["plate_diameter"] ** 2 * p["plate_thickness"]
    return mp * p["impact_speed"] / (mp + mt)


STATUS = {1: "through", 2: "stopped", 0: "unsettled"}


def classify(row, params):
    """Adds the status (from the shot's shot_outcome), V_r, the capture
    speed and the end time (the cap) to a shot's row (`params`: every
    parameter's value, end_time included)."""
    row["capture_speed_mps"] = capture_speed(params)
    row["end_time_s"] = params["end_time"]
    row["Vr_mps"] = ""
    if row["error"]:
        row["status"] = "error"
        return row
    row["status"] = STATUS[int(row["shot_outcome"])]
    row["Vr_mps"] = 0.0 if row["status"] == "stopped" else row["projectile_velocity"]
    return row


def print_table(rows):
    print(f"{'V (m/s)':>9} {'status':>9} {'V_r (m/s)':>10} {'v_end (m/s)':>11} {'dv last 10%':>11} "
          f"{'clear (mm)':>10} {'end (us)':>8} {'hole (mm)':>9} {'pulverized':>10} {'energy err':>10} {'wall (s)':>8}")
    for r in rows:
        vr = f"{r['Vr_mps']:.1f}" if r["Vr_mps"] != "" else "-"
        dv = f"{r['velocity_change_mps']:.1f}" if "velocity_change_mps" in r else "-"
        values = [r.get(n, math.nan) for n in ("projectile_velocity", "projectile_clearance", "hole_radius",
                                                "pulverized_fraction", "energy_error")]
        print(f"{r['V_mps']:9.1f} {r['status']:>9} {vr:>10} {values[0]:11.1f} {dv:>11} {1e3 * values[1]:10.2f} "
              f"{1e6 * r.get('time_s', r['end_time_s']):8.1f} {1e3 * values[2]:9.3f} {values[3]:10.4f} {values[4]:10.4f} "
              f"{r['wall_time_s']:8.1f}")


def plot(path, rows, fit, title):
    """The shots and the fitted curve: with matplotlib when it is installed,
    else an SVG written here (only for a .svg path). Returns a message."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        if Path(path).suffix.lower() != ".svg":
            return f"no plot: matplotlib is not installed and {path} is not an .svg"
        Path(path).write_text(svg(rows, fit, title))
        return f"plot (SVG written without matplotlib) -> {path}"
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for status, style in MARKERS.items():
        pts = [(r["V_mps"], r["Vr_mps"] if r["Vr_mps"] != "" else 0.0) for r in rows if r["status"] == status]
        if pts:
            ax.plot(*zip(*pts), style["mpl"], color=style["color"], label=status, linestyle="none")
    if fit:
        xs, ys = curve(fit, rows)
        ax.plot(xs, ys, "-", color="black", label=fit_label(fit))
        ax.axvline(fit.v_bl, color="grey", linestyle="--")
    ax.set_xlabel("impact speed V (m/s)")
    ax.set_ylabel("residual speed V_r (m/s)")
    ax.set_title(title)
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=0)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path)
    return f"plot -> {path}"


MARKERS = {
    "through": {"mpl": "o", "color": "#1f77b4", "svg": "filled"},
    "stopped": {"mpl": "s", "color": "#2ca02c", "svg": "filled"},
    "unsettled": {"mpl": "^", "color": "#ff7f0e", "svg": "open"},
    "error": {"mpl": "x", "color": "#d62728", "svg": "cross"},
}


def fit_label(fit):
    return f"Lambert-Jonas: V_bl = {fit.v_bl:.1f} +- {fit.v_bl_err:.1f} m/s, a = {fit.a:.4f}, p = {fit.p:.3f}"


def curve(fit, rows):
    """Points of the fitted curve from 0 to the fastest shot."""
    top = max(r["V_mps"] for r in rows)
    xs = [top * k / 200 for k in range(201)]
    return xs, [fit.residual_speed(x) for x in xs]


def nice_ticks(top, n=5):
    """Round tick values from 0 to at least `top`."""
    raw = max(top, 1e-9) / n
    mag = 10 ** math.floor(math.log10(raw))
    step = next(m * mag for m in (1, 2, 2.5, 5, 10) if m * mag >= raw)
    return [k * step for k in range(int(math.ceil(top / step)) + 1)]


def svg(rows, fit, title):
    """The plot as SVG text, without matplotlib."""
    w, h, left, right, top, bottom = 640, 420, 70, 20, 40, 55
    speeds = [r["V_mps"] for r in rows]
    residuals = [r["Vr_mps"] for r in rows if r["Vr_mps"] != ""] + (curve(fit, rows)[1] if fit else [])
    xt = nice_ticks(max(speeds) * 1.05)
    yt = nice_ticks(max(residuals + [1.0]) * 1.1)

    def x(v):
        return left + (w - left - right) * v / xt[-1]

    def y(v):
        return h - bottom - (h - top - bottom) * v / yt[-1]

    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" '
           f'font-size="12">',
           f'<rect width="{w}" height="{h}" fill="white"/>',
           f'<text x="{w / 2}" y="20" text-anchor="middle" font-size="14">{escape(title)}</text>',
           f'<line x1="{x(0)}" y1="{y(0)}" x2="{x(xt[-1])}" y2="{y(0)}" stroke="black"/>',
           f'<line x1="{x(0)}" y1="{y(0)}" x2="{x(0)}" y2="{y(yt[-1])}" stroke="black"/>']
    for t in xt:
        out.append(f'<line x1="{x(t):.1f}" y1="{y(0)}" x2="{x(t):.1f}" y2="{y(0) + 5}" stroke="black"/>'
                   f'<text x="{x(t):.1f}" y="{y(0) + 18}" text-anchor="middle">{t:g}</text>')
    for t in yt:
        out.append(f'<line x1="{x(0) - 5}" y1="{y(t):.1f}" x2="{x(0)}" y2="{y(t):.1f}" stroke="black"/>'
                   f'<text x="{x(0) - 8}" y="{y(t) + 4:.1f}" text-anchor="end">{t:g}</text>')
    out.append(f'<text x="{(x(0) + x(xt[-1])) / 2}" y="{h - 15}" text-anchor="middle">impact speed V (m/s)</text>')
    out.append(f'<text transform="translate(18 {(y(0) + y(yt[-1])) / 2}) rotate(-90)" text-anchor="middle">'
               'residual speed V_r (m/s)</text>')
    if fit:
        xs, ys = curve(fit, rows)
        pts = " ".join(f"{x(a):.1f},{y(b):.1f}" for a, b in zip(xs, ys))
        out.append(f'<polyline points="{pts}" fill="none" stroke="black"/>')
        out.append(f'<line x1="{x(fit.v_bl):.1f}" y1="{y(0)}" x2="{x(fit.v_bl):.1f}" y2="{y(yt[-1])}" '
                   'stroke="grey" stroke-dasharray="4 3"/>')
        out.append(f'<text x="{x(0) + 10}" y="{top + 14}">{escape(fit_label(fit))}</text>')
    for r in rows:
        style = MARKERS[r["status"]]
        cx, cy = x(r["V_mps"]), y(r["Vr_mps"] if r["Vr_mps"] != "" else 0.0)
        if style["svg"] == "cross":
            out.append(f'<path d="M{cx - 5:.1f},{cy - 5:.1f} l10,10 m0,-10 l-10,10" stroke="{style["color"]}" '
                       'stroke-width="2"/>')
        else:
            fill = style["color"] if style["svg"] == "filled" else "white"
            out.append(f'<circle cx="{cx:.1f}" cy="{cy:.1f}" r="4.5" fill="{fill}" stroke="{style["color"]}"/>')
    for k, (status, style) in enumerate(MARKERS.items()):
        out.append(f'<text x="{x(0) + 10}" y="{top + 34 + 16 * k}" fill="{style["color"]}">{status}</text>')
    out.append("</svg>")
    return "\n".join(out) + "\n"


def escape(text):
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def run_package(speeds, common, args):
    """The sweep through the Python package (--package): the rows of
    meshless_impact.ballistic_limit in this script's columns, and its fit
    (None where it could not fit)."""
    import meshless_impact as mi

    client = None
    if args.scheduler:
        from dask.distributed import Client

        client = Client(args.scheduler)
    defaults = {name: p["value"] for name, p in mi.params("penetration").items()}
    result = mi.ballistic_limit(speeds, client=client, workers=args.workers, fit_unsettled=args.fit_unsettled,
                                frame=False, **common)
    if client is not None:
        client.close()
    for r in result.shots:
        params = {**defaults, **common, "impact_speed": r["V_mps"]}
        r["capture_speed_mps"] = capture_speed(params)
        r["end_time_s"] = params["end_time"]
        r["time_s"] = r["time"]
        if r["Vr_mps"] is None:
            r["Vr_mps"] = ""
    return result.shots, result.fit


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--fmu", default=str(DEFAULT_FMU), help="FMU to run (FMI 3 or FMI 2); default %(default)s")
    ap.add_argument("--speeds", default="600:2000:200",
                    help="impact speeds in m/s: A,B,C or START:STOP:STEP (default %(default)s)")
    ap.add_argument("--particles-radial", type=int, default=None,
                    help="nodes across the projectile's radius (default: the FMU's, 5)")
    ap.add_argument("--end-time", type=float, default=None, help="end_time in s (default: the FMU's, 20e-6)")
    ap.add_argument("--plate-thickness", type=float, default=None,
                    help="plate_thickness in m (default: the FMU's, 0.005)")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="an FMU parameter for every shot (repeatable)")
    ap.add_argument("--step", type=float, default=None,
                    help="communication step in s, the resolution of the recorded velocity (default end_time/100)")
    ap.add_argument("--extend", type=int, default=0, metavar="K",
                    help="run the unsettled shots (no outcome by end_time, the cap) again with twice the end time, "
                         "up to K times (default %(default)s)")
    ap.add_argument("--fit-unsettled", action="store_true",
                    help="fit the unsettled shots too (their velocities are not residual velocities)")
    ap.add_argument("--workers", type=int, default=os.cpu_count(), help="local worker processes (default: one per CPU)")
    ap.add_argument("--scheduler", default=None,
                    help="address of a Dask scheduler (e.g. tcp://host:8786); run there instead of locally")
    ap.add_argument("--out", default="ballistic_limit.csv", help="table of shots, CSV (default %(default)s)")
    ap.add_argument("--plot", default="ballistic_limit.svg",
                    help="plot path (default %(default)s; any format with matplotlib, .svg without)")
    ap.add_argument("--no-plot", action="store_true", help="no plot")
    ap.add_argument("--package", action="store_true",
                    help="run the shots through the Python package (meshless_impact.ballistic_limit), not the FMU")
    args = ap.parse_args(argv)
    if args.package:
        return main_package(args, ap)

    from fmpy import read_model_description

    md = read_model_description(args.fmu)
    defaults = {v.name: float(v.start) for v in md.modelVariables if v.causality == "parameter"}
    common, speeds = shot_settings(args, set(defaults), ap)
    common = {"run_until": RUN_UNTIL_OUTCOME, **common}
    end_time = common.get("end_time", defaults["end_time"])
    step = args.step or end_time / 100
    shots = [{**common, "impact_speed": v} for v in speeds]

    t0 = time.perf_counter()
    rows = run_jobs(run_shot, [(args.fmu, p, end_time, step) for p in shots], args.workers, args.scheduler)
    wall = time.perf_counter() - t0
    rows = [classify(r, {**defaults, **p}) for r, p in zip(rows, shots)]
    if args.extend < 0:
        ap.error(f"--extend {args.extend}: need K >= 0")
    for _ in range(args.extend):
        again = [k for k, r in enumerate(rows) if r["status"] == "unsettled"]
        if not again:
            break
        longer = [{**shots[k], "end_time": 2 * rows[k]["end_time_s"]} for k in again]
        print("running again with twice the end time: "
              + ", ".join(f"{p['impact_speed']:g} m/s to {p['end_time']:g} s" for p in longer), file=sys.stderr)
        t1 = time.perf_counter()
        redone = run_jobs(run_shot, [(args.fmu, p, p["end_time"], args.step or p["end_time"] / 100) for p in longer],
                          args.workers, args.scheduler)
        wall += time.perf_counter() - t1
        for k, r, p in zip(again, redone, longer):
            shots[k] = p
            rows[k] = classify(r, {**defaults, **p})

    return report(rows, args, wall, title=f"Ballistic limit, {Path(args.fmu).stem}")


def shot_settings(args, names, ap):
    """The settings every shot shares (--set over the parameters `names`,
    then --particles-radial, --end-time, --plate-thickness) and the speeds."""
    common = parse_sets(args.set, names, ap)
    for name, value in (("particles_radial", args.particles_radial), ("end_time", args.end_time),
                        ("plate_thickness", args.plate_thickness)):
        if value is not None:
            common[name] = value
    try:
        speeds = parse_speeds(args.speeds)
    except ValueError as e:
        ap.error(str(e))
    return common, speeds


def main_package(args, ap):
    """main() with --package: the shots through meshless_impact."""
    import meshless_impact as mi

    common, speeds = shot_settings(args, set(mi.params("penetration")), ap)
    t0 = time.perf_counter()
    rows, fit = run_package(speeds, common, args)
    return report(rows, args, time.perf_counter() - t0, title="Ballistic limit, meshless_impact", fit=fit)


def report(rows, args, wall, title, fit=False):
    """Prints the table, writes the CSV, fits (unless `fit` is given: the
    package's) and plots; the exit status."""
    print_table(rows)
    print(f"{len(rows)} shots in {wall:.1f} s -> {args.out}")
    with open(args.out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)

    for r in rows:
        if r["status"] == "error":
            print(f"shot at {r['V_mps']:g} m/s: ERROR (left out of the fit): {r['error']}", file=sys.stderr)
    unsettled = [r for r in rows if r["status"] == "unsettled"]
    if unsettled:
        what = "fitted anyway (--fit-unsettled)" if args.fit_unsettled else "left out of the fit"
        times = sorted({r["end_time_s"] for r in unsettled})
        at = f"end_time = {times[0]:g} s" if len(times) == 1 else f"end_time = {times[0]:g} to {times[-1]:g} s"
        print(f"warning: {len(unsettled)} shots unsettled at {at} (neither perforated nor stopped by then: "
              f"not residual velocities; run longer with --end-time or --extend), {what}: "
              + ", ".join(f"{r['V_mps']:g} m/s" for r in unsettled), file=sys.stderr)
    fitted = {"through", "stopped"} | ({"unsettled"} if args.fit_unsettled else set())
    data = [(r["V_mps"], r["Vr_mps"]) for r in rows if r["status"] in fitted]
    try:
        if fit is False:
            fit = lambert_jonas.fit(data)
        elif fit is None:
            lambert_jonas.fit(data)  # the package could not fit: the reason
        print(f"ballistic limit V_bl = {fit.v_bl:.1f} +- {fit.v_bl_err:.1f} m/s (shots bracket "
              f"{fit.bracket[0]:.1f}-{fit.bracket[1]:.1f}), a = {fit.a:.4f} +- {fit.a_err:.4f}, "
              f"p = {fit.p:.3f} +- {fit.p_err:.3f}, "
              f"rms residual {fit.rms:.2f} m/s ({len(data)} shots fitted)")
    except ValueError as e:
        fit = None
        print(f"no fit: {e} ({len(data)} shots fitted)", file=sys.stderr)
    if args.no_plot:
        print("no plot (--no-plot)")
    else:
        if args.fit_unsettled and unsettled:
            title += " (unsettled shots fitted: not residual velocities)"
        print(plot(args.plot, rows, fit, title))
    return 0 if fit is not None and not any(r["status"] == "error" for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
