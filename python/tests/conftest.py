"""Shared helpers of the Python package's tests: the command-line program
and the C library of the same build (`MI_PROFILE`, default release; the
test command builds `ci`), as the references the package is held to."""

import ctypes
import csv
import json
import os
import subprocess
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
PROFILE = os.environ.get("MI_PROFILE", "release")
CLI = ROOT / "target" / PROFILE / "meshless-impact"
CLIB = ROOT / "target" / PROFILE / "libmeshless_impact.so"

# The solver choices of the cheap penetration shots of the FMU tests
# (tests/fmu/test_ballistic.py): the plain scheme before 2026-11-26.
PLAIN = {"weak_form": 0, "smoothing_order": 1, "smoothing_coefficient": 0.0, "shifting": 0.0}


def sets(params):
    """`--set NAME=VALUE` arguments of `params` (values as Python writes them)."""
    return [a for name, value in params.items() for a in ("--set", f"{name}={value!r}")]


def cli(*args, check=True):
    """The program's completed process."""
    return subprocess.run([str(CLI), *args], check=check, capture_output=True, text=True)


def cli_run(tmp_path, scene, params):
    """`meshless-impact run SCENE --set ... --json --csv`: (the final
    values, the histories as columns of floats, the process). The run may
    stop with an error (exit status 1)."""
    out, hist = tmp_path / f"{scene}.json", tmp_path / f"{scene}.csv"
    r = cli("run", scene, "-q", *sets(params), "--json", str(out), "--csv", str(hist), check=False)
    assert out.exists(), r.stderr
    with open(hist, newline="") as f:
        rows = list(csv.reader(f))
    columns = {name: np.array([float(row[k]) for row in rows[1:]]) for k, name in enumerate(rows[0])}
    return json.loads(out.read_text()), columns, r


def cli_error(*args):
    """The message the program prints for a failure (after `error: `)."""
    r = cli(*args, check=False)
    assert r.returncode == 1, r.stdout + r.stderr
    return r.stderr.strip().removeprefix("error: ")


class CSim:
    """A run through the C ABI (ctypes over the library of the same build):
    the reference of `Simulation.field`."""

    lib = None

    def __init__(self, scene, params):
        if CSim.lib is None:
            lib = ctypes.CDLL(str(CLIB))
            lib.mi_sim_new.argtypes = [ctypes.c_char_p, ctypes.POINTER(ctypes.c_void_p)]
            lib.mi_sim_set_param.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_double]
            lib.mi_sim_run.argtypes = [ctypes.c_void_p]
            lib.mi_sim_advance_to.argtypes = [ctypes.c_void_p, ctypes.c_double]
            lib.mi_sim_free.argtypes = [ctypes.c_void_p]
            lib.mi_sim_particle_count.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_size_t)]
            lib.mi_sim_field.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.POINTER(ctypes.c_double),
                                         ctypes.c_size_t, ctypes.POINTER(ctypes.c_size_t)]
            CSim.lib = lib
        self.h = ctypes.c_void_p()
        assert CSim.lib.mi_sim_new(scene.encode(), ctypes.byref(self.h)) == 0
        for name, value in params.items():
            assert CSim.lib.mi_sim_set_param(self.h, name.encode(), float(value)) == 0, name

    def run(self):
        return CSim.lib.mi_sim_run(self.h)

    def field(self, name):
        """The field's doubles, interleaved per particle, as the C ABI copies them."""
        n = ctypes.c_size_t()
        assert CSim.lib.mi_sim_field(self.h, name.encode(), None, 0, ctypes.byref(n)) == 0
        buf = (ctypes.c_double * n.value)()
        assert CSim.lib.mi_sim_field(self.h, name.encode(), buf, n.value, None) == 0
        return np.frombuffer(buf, dtype=np.float64).copy()

    def particles(self):
        n = ctypes.c_size_t()
        assert CSim.lib.mi_sim_particle_count(self.h, ctypes.byref(n)) == 0
        return n.value

    def __del__(self):
        if CSim.lib is not None and self.h:
            CSim.lib.mi_sim_free(self.h)
