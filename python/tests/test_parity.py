"""Parity: the package's observables and histories are the command line's
JSON and CSV bit for bit, and its fields the C ABI's, for `taylor`,
`taylor3d` and `penetration` (coarse, short runs)."""

import json

import numpy as np
import pytest

import meshless_impact as mi
from conftest import CSim, cli_run

CASES = {
    "taylor": {"particles_radial": 4, "end_time": 2e-5},
    "taylor3d": {"particles_radial": 3, "end_time": 3e-6},
    "penetration": {"particles_radial": 2, "projectile_diameter": 0.002, "projectile_length": 0.002,
                    "plate_thickness": 0.002, "plate_diameter": 0.008, "end_time": 2e-6},
}


def bits(x):
    return np.asarray(x, dtype=np.float64).view(np.uint64)


@pytest.mark.parametrize("scene", CASES)
def test_observables_history_and_fields_are_the_cli_and_c_abi_bits(scene, tmp_path):
    params = CASES[scene]
    ref, columns, r = cli_run(tmp_path, scene, params)
    assert r.returncode == 0, r.stderr
    sim = mi.Simulation(scene, **params)
    sim.run()
    assert sim.finished and sim.error is None
    obs = sim.observables()
    assert list(obs) == list(mi.observables(scene))
    for name, value in obs.items():
        assert type(value) is type(ref[name]), name
        assert value == ref[name] and np.signbit(value) == np.signbit(ref[name]), f"{name}: {value!r} {ref[name]!r}"
    assert (sim.particles, sim.steps, sim.time) == (ref["particles"], ref["steps"], ref["end_time"])
    h = sim.history()
    assert list(h) == list(columns)
    for name, column in columns.items():
        assert h[name].dtype == np.float64 and np.array_equal(bits(h[name]), bits(column)), name
    # The fields: the C ABI's copy of the same run, shaped per component.
    c = CSim(scene, params)
    assert c.run() == 0
    assert c.particles() == sim.particles
    for name, spec in sim.fields().items():
        got = sim.field(name)
        k = len(spec["components"])
        assert got.shape == ((sim.particles,) if k == 1 else (sim.particles, k)), name
        assert np.array_equal(bits(got.ravel()), bits(c.field(name))), name
    assert np.array_equal(sim.positions(), sim.field("position"))
    assert sim.positions().shape[1] == (2 if scene == "taylor" else 3)


def test_a_run_divided_is_the_run_whole():
    params = CASES["taylor"]
    whole = mi.Simulation("taylor", **params)
    whole.run()
    parts = mi.Simulation("taylor", **params)
    parts.advance_to(5e-6)
    assert 5e-6 <= parts.time and not parts.finished
    t = parts.time
    parts.step()
    assert parts.time > t
    parts.run()
    assert parts.observables() == whole.observables()
    assert np.array_equal(parts.field("stress"), whole.field("stress"))


def test_discovery_is_the_cli_listing():
    from conftest import cli
    assert mi.scenes() == [line.split()[0] for line in cli("scenes").stdout.splitlines()]
    assert list(mi.observables("penetration")) == [line.split()[0] for line in cli("observables", "penetration").stdout.splitlines()]
    rows = cli("params", "taylor", "--strength", "bilinear").stdout.splitlines()[1:]
    rows = rows[: rows.index("")] if "" in rows else rows
    p = mi.params("taylor", strength="bilinear")
    assert list(p) == [r.split()[0] for r in rows]
    assert "yield_stress" in p and "jc_a" not in p
    assert p["impact_speed"]["value"] == 181.0 and p["impact_speed"]["unit"] == "m/s"
    assert p["scheme"]["levels"] and p["scheme"]["value"] in p["scheme"]["levels"]
    presets = mi.presets()
    assert list(presets) == [line.split()[0] for line in cli("materials").stdout.splitlines()
                             if line and not line.startswith((" ", "("))]
    assert set(mi.fields("taylor3d")) >= {"position", "velocity", "stress"}


def test_saved_state_continues_with_the_same_bits():
    params = CASES["taylor"]
    a = mi.Simulation("taylor", **params)
    a.advance_to(6e-6)
    state = a.save_state()
    assert isinstance(state, bytes)
    b = mi.Simulation("taylor", **params)
    b.load_state(state)
    assert b.time == a.time and b.steps == a.steps
    a.run()
    b.run()
    assert a.observables() == b.observables()
    assert np.array_equal(bits(a.field("velocity")), bits(b.field("velocity")))


def test_a_checkpoint_file_continues_with_the_same_bits_and_meets_the_cli(tmp_path):
    params = CASES["taylor"]
    a = mi.Simulation("taylor", **params)
    a.advance_to(6e-6)
    path = tmp_path / "run.ckpt"
    a.save(path)
    assert [p.name for p in tmp_path.iterdir()] == ["run.ckpt"], "no temporary file left"
    b = mi.Simulation.load(path, threads=1)
    assert b.time == a.time and b.steps == a.steps and b.params() == a.params()
    a.run()
    b.run()
    assert a.observables() == b.observables()
    assert np.array_equal(bits(a.field("velocity")), bits(b.field("velocity")))
    # The program continues a checkpoint that Python wrote, to the same end.
    from conftest import cli
    out = tmp_path / "out.json"
    cli("run", "--restart", str(path), "--json", str(out), "-q")
    final = json.loads(out.read_text())
    assert all(final[k] == v for k, v in a.observables().items())
    # A bad file raises the class of its fault.
    path.write_bytes(path.read_bytes()[:1000])
    with pytest.raises(mi.errors.CheckpointTruncated, match="run.ckpt is truncated"):
        mi.Simulation.load(path)
    with pytest.raises(mi.errors.NotACheckpoint):
        mi.Simulation.load(out)


def test_progress_true_shows_a_line_and_changes_nothing(capfd):
    params = CASES["taylor"]
    a = mi.Simulation("taylor", **params)
    a.run(progress=True)
    err = capfd.readouterr().err
    assert err.startswith("\rt = ") and err.endswith(f"{a.steps} steps\n"), err
    b = mi.Simulation("taylor", **params)
    b.run()
    assert a.observables() == b.observables()
