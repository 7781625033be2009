"""Bit-for-bit comparison of C example output with the Rust CLI's JSON.

    python3 compare.py C_OUTPUT.txt RUST.json
        every `name = value` line of the C output whose name is in the JSON
        must hold exactly the JSON's number (booleans as 0/1).
    python3 compare.py --sweep SWEEP.txt SPEED C_OUTPUT.txt
        the sweep row of SPEED must equal the C output of a single run.
    python3 compare.py --fields3d C_OUTPUT.txt RUST.json
        the 3-D fields read by taylor3d.c: `position` has 3 components and
        `stress` 6, one value of each per node of the Rust run; the extent
        of the positions along z is the Rust run's rod_length, bit for bit,
        and below initial_length; no node lies nearer the axis than the
        face's mushroom_radius says; the mean normal stress is minus the
        pressure.
"""
import json
import sys


def read_lines(path):
    out = {}
    with open(path) as f:
        for line in f:
            if " = " in line:
                k, v = line.split(" = ", 1)
                out[k.strip()] = float(v)
    return out


def main():
    if sys.argv[1] == "--sweep":
        rows = open(sys.argv[2]).read().split("\n")
        header = rows[0].split()
        single = read_lines(sys.argv[4])
        row = [r.split() for r in rows[1:] if r and float(r.split()[0]) == float(sys.argv[3])]
        assert len(row) == 1, f"no row for speed {sys.argv[3]}"
        checked = 0
        for name, value in zip(header[1:], row[0][1:]):
            assert float(value) == single[name], f"{name}: sweep {value} != single {single[name]!r}"
            checked += 1
        print(f"sweep row {sys.argv[3]} m/s equals the single run ({checked} values)")
        return
    if sys.argv[1] == "--fields3d":
        fields3d(read_lines(sys.argv[2]), json.load(open(sys.argv[3])))
        return
    c = read_lines(sys.argv[1])
    rust = json.load(open(sys.argv[2]))
    checked = 0
    assert rust["outcome"] == "finished", rust.get("error")
    for name, value in rust.items():
        if name in ("wall_time_s", "particles", "end_time", "outcome") or isinstance(value, dict):
            continue  # run facts, and the references (objects by observable name)
        assert name in c, f"{name} missing from the C output"
        want = float(value) if not isinstance(value, bool) else float(value)
        assert c[name] == want, f"{name}: C {c[name]!r} != Rust {want!r}"
        checked += 1
    assert checked >= 12, checked  # penetration: 11 observables and steps
    print(f"{sys.argv[1]}: {checked} values equal the Rust API bit for bit")


def fields3d(c, rust):
    n = rust["particles"]
    assert c["nodes"] == n, (c["nodes"], n)
    assert c["position_components"] == 3 and c["stress_components"] == 6, c
    assert c["position_values"] == 3 * n, (c["position_values"], n)
    assert c["stress_values"] == 6 * n, (c["stress_values"], n)
    lf = rust["rod_length"]
    assert c["position_z_extent"] == lf, f"z extent {c['position_z_extent']!r} != rod_length {lf!r}"
    assert lf < c["initial_length"], (lf, c["initial_length"])
    assert c["position_max_radius"] >= rust["mushroom_radius"] * (1 - 1e-12), c
    assert c["stress_max_abs"] > 0
    assert c["stress_mean_plus_pressure_max"] <= 1e-9 * c["stress_max_abs"], c
    print(f"3-D fields of {n} nodes: position (x, y, z), stress (6); z extent = rod_length = {lf!r} m")


main()
