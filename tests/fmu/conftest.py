"""Shared fixtures of the FMU tests: the two TaylorImpact FMUs (built by `cargo xtask fmu`,
see run.sh), extracted once, and helpers that drive them through fmpy's
low-level classes."""

import json
import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest
from fmpy import extract, read_model_description
from fmpy.validation import validate_fmu

ROOT = Path(__file__).resolve().parents[2]
FMU3 = ROOT / "target" / "fmu" / "TaylorImpact.fmu"
FMU2 = ROOT / "target" / "fmu" / "TaylorImpact_fmi2.fmu"
# The program of the same build as the FMUs (`MI_PROFILE`, default release).
CLI = ROOT / "target" / os.environ.get("MI_PROFILE", "release") / "meshless-impact"

# Coarse resolution for every test except the one CLI equality check at the
# defaults: about 1 s per run instead of about 25 s.
COARSE = 6


@dataclass
class Model:
    path: Path
    md: object
    unzipdir: str

    def vr(self, name):
        return next(v.valueReference for v in self.md.modelVariables if v.name == name)

    def var(self, name):
        return next(v for v in self.md.modelVariables if v.name == name)

    @property
    def outputs(self):
        return [v for v in self.md.modelVariables if v.causality == "output"]


@pytest.fixture(scope="session")
def fmu3():
    assert FMU3.exists(), "run `cargo xtask fmu` first (tests/fmu/run.sh does)"
    return Model(FMU3, read_model_description(str(FMU3)), extract(str(FMU3)))


@pytest.fixture(scope="session")
def fmu2():
    assert FMU2.exists(), "run `cargo xtask fmu` first (tests/fmu/run.sh does)"
    return Model(FMU2, read_model_description(str(FMU2)), extract(str(FMU2)))


def cli_run(tmp_path_factory, *sets):
    """Final observables of the command-line program (`taylor`) for `--set`
    pairs."""
    return cli_json(tmp_path_factory, *(a for s in sets for a in ("--set", s)))


_models = {}


def model(identifier, suffix=""):
    """The FMU `target/fmu/<identifier><suffix>.fmu` (suffix "" for FMI 3,
    "_fmi2" for FMI 2), read and extracted once."""
    key = identifier + suffix
    if key not in _models:
        path = ROOT / "target" / "fmu" / f"{key}.fmu"
        assert path.exists(), "run `cargo xtask fmu` first (tests/fmu/run.sh does)"
        _models[key] = Model(path, read_model_description(str(path)), extract(str(path)))
    return _models[key]


def cli(*args):
    """Standard output of the command-line program."""
    return subprocess.run([str(CLI), *args], check=True, capture_output=True, text=True).stdout


_runs = {}


def cli_json(tmp_path_factory, *args):
    """Final observables of `meshless-impact run ARGS --json`."""
    if args not in _runs:
        out = tmp_path_factory.mktemp("cli") / "out.json"
        cli("run", "-q", *args, "--json", str(out))
        _runs[args] = json.loads(out.read_text())
    return _runs[args]


def params_of(*args):
    """Names and values of `meshless-impact params ARGS`, in order: the table
    down to its first blank line (the schemes' listing follows). A scheme's
    value is its level's name, whose index the `allowed` column gives
    (`0=large_strain,1=paper`)."""
    lines = cli("params", *args).splitlines()[1:]
    rows = lines[: lines.index("")] if "" in lines else lines
    out = []
    for r in rows:
        name, _, value, allowed = r.split()[:4]
        try:
            out.append((name, float(value)))
        except ValueError:
            levels = [a.split("=", 1)[1] for a in allowed.split(",")]
            out.append((name, float(levels.index(value))))
    return out


def assert_simulated_equal_to_cli(r, ref, names):
    """The last row of `simulate_fmu`'s result `r` equals the CLI's final
    values `ref` for the outputs `names`, bit for bit."""
    for name in names:
        value = r[name][-1]
        if name == "at_rest":
            assert bool(value) == ref[name]
        else:
            assert value == ref[name], f"{name}: FMU {value!r} CLI {ref[name]!r}"


def assert_variables_are_the_scene_tables(identifier, scene):
    """Both FMUs of `identifier` have as parameters those of `meshless-impact
    params SCENE` (names and starts, in order; `particles_radial` an
    integer), as outputs those of `observables SCENE`, value references from
    `time` = 0 in that order, and one model identifier and GUID. Returns the
    FMI 3 model and the observable names."""
    m3, m2 = model(identifier), model(identifier, "_fmi2")
    want = params_of(scene)
    params = [v for v in m3.md.modelVariables if v.causality == "parameter"]
    assert [v.name for v in params] == [n for n, _ in want]
    assert [float(v.start) for v in params] == [v for _, v in want]
    assert [v.name for v in m2.md.modelVariables if v.causality == "parameter"] == [n for n, _ in want]
    if any(n == "particles_radial" for n, _ in want):
        assert m3.var("particles_radial").type == "Int32" and m2.var("particles_radial").type == "Integer"
    observables = [line.split()[0] for line in cli("observables", scene).splitlines()]
    assert [v.name for v in m3.outputs] == observables
    assert [v.name for v in m2.outputs] == observables
    # Value references: time 0 (FMI 3), the parameters from 1, then the outputs.
    assert [v.valueReference for v in m3.md.modelVariables] == list(range(len(m3.md.modelVariables)))
    assert m3.md.coSimulation.modelIdentifier == identifier == m2.md.coSimulation.modelIdentifier
    assert m3.md.guid == m2.md.guid
    return m3, observables


def check_fmu_file(path):
    """fmpy's validation (library and command line) and fmutool's check
    pass on the FMU at `path`."""
    assert validate_fmu(str(path)) == []
    bindir = Path(sys.executable).parent
    r = subprocess.run([str(bindir / "fmpy"), "validate", str(path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    r = subprocess.run([str(bindir / "fmutool"), "-input", str(path), "-check"], capture_output=True, text=True)
    log = r.stdout + r.stderr
    assert r.returncode == 0, log
    assert "seems to be compliant" in log and "No semantic error" in log, log
    assert "ERROR" not in log, log
