"""Sweeps: a table of final observables, one row per run, locally on a
thread pool and on a (local) Dask cluster, each row the bits of the run
alone; and the ballistic limit: the shots' statuses by the sweep's rule,
and the project's Lambert-Jonas fit, exact on synthetic shots."""

import math

import pytest

import meshless_impact as mi
from meshless_impact import _sweep, lambert_jonas
from conftest import PLAIN, cli_run

CASE = {"particles_radial": 4, "end_time": 1e-5}


def alone(**params):
    sim = mi.Simulation("taylor", **params)
    sim.run()
    return sim.observables()


def test_a_grid_sweeps_every_combination_with_the_bits_of_each_run():
    rows = mi.sweep("taylor", {"impact_speed": [150.0, 200.0], "jc_a": [700e6, 792e6]}, frame=False, **CASE)
    assert [(r["impact_speed"], r["jc_a"]) for r in rows] == [
        (150.0, 700e6), (150.0, 792e6), (200.0, 700e6), (200.0, 792e6)]
    for r in rows:
        ref = alone(impact_speed=r["impact_speed"], jc_a=r["jc_a"], **CASE)
        assert all(r[k] == v for k, v in ref.items())
        assert r["outcome"] == "finished" and r["error"] == ""
    # A stop is a row, named; bad input raises.
    rows = mi.sweep("taylor", [{"smoothing_coefficient": 0.0}], frame=False, particles_radial=6)
    assert rows[0]["outcome"] == "EnergyDrift" and "energy error" in rows[0]["error"]
    with pytest.raises(mi.errors.OutOfRange, match="impact_speed"):
        mi.sweep("taylor", {"impact_speed": [150.0, -1.0]}, **CASE)


def test_the_table_is_a_dataframe_with_pandas():
    pandas = pytest.importorskip("pandas")
    table = mi.sweep("taylor", {"impact_speed": [150.0, 200.0]}, **CASE)
    assert isinstance(table, pandas.DataFrame) and list(table["impact_speed"]) == [150.0, 200.0]
    assert list(table["rod_length"]) == [alone(impact_speed=v, **CASE)["rod_length"] for v in (150.0, 200.0)]


def test_a_sweep_on_a_dask_cluster_is_the_local_sweep():
    from dask.distributed import Client, LocalCluster

    grid = {"impact_speed": [150.0, 180.0, 200.0]}
    local = mi.sweep("taylor", grid, frame=False, **CASE)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        remote = mi.sweep("taylor", grid, client=client, frame=False, **CASE)
    strip = [{k: v for k, v in r.items() if k != "wall_time_s"} for r in remote]
    assert strip == [{k: v for k, v in r.items() if k != "wall_time_s"} for r in local]


# Cheap shots of the FMU tests' sweep (tests/fmu/test_ballistic_limit.py):
# they stop, stay in the plate or stop with an error.
SHOTS = {"particles_radial": 3, "plate_diameter": 0.02, "end_time": 1e-5, **PLAIN}


def test_the_ballistic_limit_of_a_coarse_sweep_is_the_rule_and_the_fit(tmp_path):
    speeds = [800.0, 1200.0]
    result = mi.ballistic_limit(speeds, frame=False, fit_unsettled=True, **SHOTS)
    assert [s["V_mps"] for s in result.shots] == speeds
    data = []
    for shot in result.shots:
        ref, _, _ = cli_run(tmp_path, "penetration", {**SHOTS, "run_until": 1, "impact_speed": shot["V_mps"]})
        assert shot["projectile_velocity"] == ref["projectile_velocity"]
        assert shot["shot_outcome"] == ref["shot_outcome"]
        if ref["outcome"] != "finished":
            want = ("error", None)
        else:
            want = {1: ("through", ref["projectile_velocity"]), 2: ("stopped", 0.0),
                    0: ("unsettled", ref["projectile_velocity"])}[int(ref["shot_outcome"])]
        assert (shot["status"], shot["Vr_mps"]) == want
        if shot["status"] != "error":
            data.append((shot["V_mps"], shot["Vr_mps"]))
    try:
        fit = lambert_jonas.fit(data)
    except ValueError as e:
        assert math.isnan(result.v_bl) and result.message == f"no fit: {e}"
    else:
        assert (result.v_bl, result.a, result.p, result.v_bl_err) == (fit.v_bl, fit.a, fit.p, fit.v_bl_err)


def test_the_ballistic_limit_recovers_an_exact_curve(monkeypatch):
    """On synthetic shots of V_r = a (V^p - V_bl^p)^(1/p) (a = 0.92, p =
    2.4, V_bl = 820 m/s; stopped below), as the sweep would return them."""
    a, p, v_bl = 0.92, 2.4, 820.0
    speeds = [600.0, 700.0, 800.0, 900.0, 1000.0, 1200.0, 1500.0, 2000.0]

    def fake_sweep(scene, cases, **kwargs):
        assert scene == "penetration" and kwargs["run_until"] == "outcome" and kwargs["particles_radial"] == 4
        rows = []
        for case in cases:
            v = case["impact_speed"]
            vr = a * (v**p - v_bl**p) ** (1 / p) if v > v_bl else 0.0
            rows.append({"impact_speed": v, "outcome": "finished", "shot_outcome": 1.0 if vr > 0 else 2.0,
                         "projectile_velocity": vr if vr > 0 else 50.0})
        return rows

    monkeypatch.setattr(_sweep, "sweep", fake_sweep)
    r = mi.ballistic_limit(speeds, particles_radial=4, frame=False)
    assert [s["status"] for s in r.shots] == ["stopped"] * 3 + ["through"] * 5
    assert r.v_bl == pytest.approx(v_bl, rel=1e-4) and r.a == pytest.approx(a, rel=1e-4)
    assert r.p == pytest.approx(p, rel=1e-3) and r.bracket == (800.0, 900.0) and r.fitted == 8
    assert r.v_bl_err < 1.0 and r.rms < 1e-2


def test_the_shot_rule():
    assert mi.shot_status({"outcome": "finished", "shot_outcome": 1.0, "projectile_velocity": 310.0}) == ("through", 310.0)
    assert mi.shot_status({"outcome": "finished", "shot_outcome": 2.0, "projectile_velocity": 12.0}) == ("stopped", 0.0)
    assert mi.shot_status({"outcome": "finished", "shot_outcome": 0.0, "projectile_velocity": 90.0}) == ("unsettled", 90.0)
    assert mi.shot_status({"outcome": "SpacingCollapse", "shot_outcome": 1.0, "projectile_velocity": 1.0}) == ("error", None)


def test_the_example_script_runs_the_sweep_through_the_package(tmp_path):
    """examples/ballistic_limit.py --package: its table is the package's
    shots, and its fit the package's."""
    import csv
    import subprocess
    import sys

    from conftest import ROOT
    speeds = [400.0, 1000.0, 1300.0, 1600.0]
    args = ["--package", "--speeds", ",".join(map(str, speeds)), "--particles-radial", "3",
            "--set", "plate_diameter=0.02", "--end-time", "2e-5", "--workers", "2",
            "--out", str(tmp_path / "shots.csv"), "--no-plot"]
    r = subprocess.run([sys.executable, str(ROOT / "examples" / "ballistic_limit.py"), *args],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    limit = mi.ballistic_limit(speeds, particles_radial=3, plate_diameter=0.02, end_time=2e-5, frame=False)
    with open(tmp_path / "shots.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [(float(x["V_mps"]), x["status"], float(x["projectile_velocity"])) for x in rows] == [
        (s["V_mps"], s["status"], s["projectile_velocity"]) for s in limit.shots]
    assert f"ballistic limit V_bl = {limit.v_bl:.1f} +- {limit.v_bl_err:.1f} m/s" in r.stdout
