"""meshless_impact.calibrate against the command line's calibrate, bit for
bit, on the small twin (tests/suite/calibrate.rs): shots made by the solver
with Johnson-Cook A and B moved, two free constants, a coarse resolution."""

import json

import numpy as np
import pytest

import meshless_impact as mi
from conftest import cli

COARSE = {"particles_radial": 8}
TRUTH = {"jc_a": 900e6, "jc_b": 450e6}
SHOTS = [(180.0, 0.02529), (240.0, 0.02529), (280.0, 0.01519)]
FREE = {"jc_a": (600e6, 1200e6), "jc_b": (200e6, 900e6)}


@pytest.fixture(scope="module")
def shots(tmp_path_factory):
    path = tmp_path_factory.mktemp("twin") / "shots.csv"
    lines = ["shot,impact_speed,initial_length,rod_length,mushroom_radius"]
    for k, (v, length) in enumerate(SHOTS):
        sim = mi.Simulation("taylor", impact_speed=v, initial_length=length, **COARSE, **TRUTH)
        sim.run()
        o = sim.observables()
        lines.append(f"s{k},{v!r},{length!r},{o['rod_length']!r},{o['mushroom_radius']!r}")
    path.write_text("\n".join(lines) + "\n")
    return path


def test_python_and_the_cli_agree_bit_for_bit(shots, tmp_path):
    py = mi.calibrate("taylor", shots, FREE, set=COARSE, out=tmp_path / "py")
    args = [a for name, (lo, hi) in FREE.items() for a in ("--free", f"{name}={lo!r}:{hi!r}")]
    r = cli("calibrate", "taylor", "--shots", str(shots), *args, "--set", "particles_radial=8",
            "--out", str(tmp_path / "cli"), "-q")
    assert r.returncode == 0, r.stderr
    c = json.loads((tmp_path / "cli" / "calibration.json").read_text())
    assert py["outcome"] == c["outcome"] == "converged"
    for name, truth in TRUTH.items():
        assert py["parameters"][name] == c["parameters"][name]
        assert abs(py["parameters"][name] / truth - 1) < 5e-3
        assert py["std"][name] == c["std"][name]
    assert np.array_equal(py["correlation"], np.array(c["correlation"], dtype=float))
    for e_py, e_cli in zip(py["experiments"], c["experiments"]):
        assert e_py["fitted"] == e_cli["fitted"] and e_py["before"] == e_cli["before"]
    assert py["runs"] == c["runs"]
    # The material file of the CLI is Python's table under a comment.
    assert (tmp_path / "cli" / "material.toml").read_text().endswith(py["material_toml"])


def test_the_material_runs_as_it_was_fitted(shots, tmp_path):
    py = mi.calibrate("taylor", shots, FREE, set=COARSE, out=tmp_path)
    e = py["experiments"][0]
    sim = mi.Simulation("taylor", preset_file=tmp_path / "material.toml", **COARSE, **e["settings"])
    sim.run()
    for name, value in e["fitted"].items():
        assert sim.observables()[name] == value


def test_bad_input_raises_by_name(shots, tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("impact_speed,rod_lenght\n181,0.0346\n")
    with pytest.raises(mi.errors.ShotsFile, match="rod_lenght"):
        mi.calibrate("taylor", bad, FREE, set=COARSE)
    with pytest.raises(mi.errors.OutOfRange, match="jc_n"):
        mi.calibrate("taylor", shots, {"jc_n": (0.0, 0.5)}, set=COARSE)
