#!/usr/bin/env python3
"""The default scheme's validation matrix (issue "right by default").

Runs every case the default scheme must bring to rest, with the
`meshless-impact` binary, two at a time on one thread each, and prints a
Markdown table: outcome, at-rest time, Lf and Df (or face radius) against
their references, energy error, wall time.

    python3 scripts/scheme_matrix.py [--bin target/release/meshless-impact]
        [--only SUBSTRING|2d] [--set k=v ...] [--jobs 2] [--csv FILE]

`--set` is passed to every run (for example `--set scheme=paper`).
"""
import argparse
import concurrent.futures as cf
import json
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# (name, args, references {observable: value}); Lf is rod_length, Df twice
# mushroom_radius. Table 1's experiments come from the scene itself.
T7 = {"rod_length": 34.6e-3, "Df": 10.62e-3}
WILKINS = {"rod_length": 21.42e-3, "Df": 2 * 7.15e-3}
CRMO4 = {"rod_length": 26.54e-3, "Df": 11.16e-3}
CRMO4_3D = {"rod_length": 26.53e-3, "Df": 11.20e-3}


def cases():
    out = []
    for v in (181, 400, 600):
        out.append((f"test7-{v}", ["taylor", "--set", f"impact_speed={v}"], T7 if v == 181 else {}))
    for k in range(1, 13):
        out.append((f"table1-{k}", [f"table1-{k}"], "table1"))
    out.append(("soft-rod", ["taylor", "--set", "jc_a=50e6", "--set", "jc_b=0"], {}))
    out.append(("near-melt-rod", ["taylor", "--set", "initial_temperature=1243"], {}))
    out.append(("wilkins", ["--scene-file", "scenes/wilkins_copper.toml"], WILKINS))
    out.append(("crmo4", ["--scene-file", "scenes/crmo4_dynela.toml"], CRMO4))
    # Published copper and aluminium shots: Johnson & Cook's cylinder
    # geometry (L0 = 25.4 mm, D0 = 7.62 mm) over the speeds of their
    # cylinder tests, with the presets' constants.
    for preset, speeds in (("ofhc_copper_jc", (130, 146, 190, 210)),
                           ("aluminium_6061t6_jc", (150, 200, 250, 300))):
        for v in speeds:
            out.append((f"{preset}-{v}", ["taylor", "--preset", preset,
                                          "--set", "initial_length=0.0254",
                                          "--set", "initial_diameter=0.00762",
                                          "--set", f"impact_speed={v}"], {}))
    out.append(("3d-test7-10", ["taylor3d", "--set", "particles_radial=10"], T7))
    out.append(("3d-wilkins", ["--scene-file", "scenes/wilkins_copper_3d.toml"], WILKINS))
    out.append(("3d-crmo4", ["--scene-file", "scenes/crmo4_dynela_3d.toml"], CRMO4_3D))
    out.append(("3d-aisi310", ["taylor3d-aisi310"], {}))
    return out


def run(binary, name, args, refs, extra):
    with tempfile.TemporaryDirectory() as d:
        js = os.path.join(d, "out.json")
        cmd = [binary, "run", *args, *extra, "-q", "--json", js]
        env = dict(os.environ, RAYON_NUM_THREADS="1")
        t0 = time.time()
        p = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
        wall = time.time() - t0
        try:
            with open(js) as f:
                r = json.load(f)
        except (OSError, ValueError):
            r = {"outcome": "no output: " + p.stderr.strip().splitlines()[-1] if p.stderr.strip() else "no output"}
        r["wall"] = wall
        r["stderr"] = p.stderr.strip()
        if refs == "table1":
            refs = {}
            scene = subprocess.run([binary, "scene", args[0]], cwd=ROOT, capture_output=True, text=True).stdout
            ref = scene.split("[reference]")[-1]
            for line in ref.splitlines():
                if "=" in line:
                    k, v = line.split("=")
                    k = k.strip()
                    v = float(v.split("#")[0])
                    if k == "rod_length":
                        refs["rod_length"] = v
                    if k == "mushroom_radius":
                        refs["Df"] = 2 * v
        return name, r, refs


def pct(a, b):
    return 100.0 * (a - b) / b


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default=os.path.join(ROOT, "target/release/meshless-impact"))
    ap.add_argument("--only", default="")
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--csv", default="")
    a = ap.parse_args()
    extra = [x for s in a.set for x in ("--set", s)]
    todo = [c for c in cases()
            if (a.only == "2d" and not c[0].startswith("3d-")) or (a.only != "2d" and a.only in c[0])]
    rows = []
    with cf.ThreadPoolExecutor(a.jobs) as ex:
        futs = [ex.submit(run, a.bin, n, args, refs, extra) for n, args, refs in todo]
        for f in futs:
            name, r, refs = f.result()
            lf = r.get("rod_length")
            df = 2 * r["mushroom_radius"] if "mushroom_radius" in r else None
            lf_s = f"{lf*1e3:.2f}" if lf else ""
            df_s = f"{df*1e3:.2f}" if df else ""
            if lf and "rod_length" in refs:
                lf_s += f" ({pct(lf, refs['rod_length']):+.2f}%)"
            if df and "Df" in refs:
                df_s += f" ({pct(df, refs['Df']):+.2f}%)"
            e = r.get("energy_error")
            t = r.get("end_time")
            row = (name, r.get("outcome"), "yes" if r.get("at_rest") else "no",
                   f"{t*1e6:.1f}" if t else "", lf_s, df_s,
                   f"{e:.4f}" if e is not None else "", f"{r['wall']:.1f}")
            rows.append(row)
            print("| " + " | ".join(row) + " |", flush=True)
            if r.get("outcome") != "finished":
                print("   " + r["stderr"][-400:], file=sys.stderr, flush=True)
    if a.csv:
        with open(a.csv, "w") as f:
            f.write("case,outcome,at_rest,t_us,Lf,Df,energy_error,wall_s\n")
            for row in rows:
                f.write(",".join(x.replace(",", ";") for x in row) + "\n")


if __name__ == "__main__":
    main()
