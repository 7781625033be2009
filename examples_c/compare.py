"""Bit-for-bit comparison of C example output with the Rust CLI's JSON.

    python3 compare.py C_OUTPUT.txt RUST.json
        every `name = value` line of the C output whose name is in the JSON
        must hold exactly the JSON's number (booleans as 0/1).
    python3 compare.py --sweep SWEEP.txt SPEED C_OUTPUT.txt
        the sweep row of SPEED must equal the C output of a single run.
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
    c = read_lines(sys.argv[1])
    rust = json.load(open(sys.argv[2]))
    checked = 0
    for name, value in rust.items():
        if name in ("wall_time_s", "particles", "end_time"):
            continue
        assert name in c, f"{name} missing from the C output"
        want = float(value) if not isinstance(value, bool) else float(value)
        assert c[name] == want, f"{name}: C {c[name]!r} != Rust {want!r}"
        checked += 1
    assert checked >= 13, checked
    print(f"{sys.argv[1]}: {checked} values equal the Rust API bit for bit")


main()
