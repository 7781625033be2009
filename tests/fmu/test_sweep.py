"""examples/sweep_fmu.py: Table 1 cases through the FMU, on a local Dask
cluster (two workers) and on the default process pool, checked against the
command-line program on the same parameters."""

import csv
import importlib.util
import subprocess
import sys

import pytest
from dask.distributed import LocalCluster

from conftest import COARSE, ROOT, cli_run

spec = importlib.util.spec_from_file_location("sweep_fmu", ROOT / "examples" / "sweep_fmu.py")
sweep = importlib.util.module_from_spec(spec)
sys.modules["sweep_fmu"] = sweep
spec.loader.exec_module(sweep)


TABLE1 = ROOT / "data" / "house1995_4340_table1.csv"
SCRIPT = ROOT / "examples" / "sweep_fmu.py"


def table1(test):
    return next(r for r in sweep.read_cases(TABLE1) if r["test"] == test)


def run_script(*args):
    """Runs the sweep as users do: `python examples/sweep_fmu.py ...`."""
    r = subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True, timeout=300)
    return r.returncode, r.stdout + r.stderr


def reference(tmp_path_factory, test):
    row = table1(test)
    sets = [f"initial_diameter={float(row['D0_mm']) * 1e-3!r}", f"initial_length={float(row['L0_mm']) * 1e-3!r}",
            f"impact_speed={float(row['V_mps'])!r}", f"particles_radial={COARSE}"]
    return cli_run(tmp_path_factory, *sets)


def read(path):
    with open(path, newline="") as f:
        return {r["test"]: r for r in csv.DictReader(f)}


def check(rows, tests, tmp_path_factory):
    assert sorted(rows) == sorted(tests)
    for test in tests:
        r, ref, case = rows[test], reference(tmp_path_factory, test), table1(test)
        assert r["error"] == ""
        assert float(r["rod_length"]) == ref["rod_length"]
        assert float(r["mushroom_radius"]) == ref["mushroom_radius"]
        assert float(r["end_time"]) == ref["end_time"]
        lf = ref["rod_length"] * 1e3
        assert float(r["Lf_error_pct"]) == pytest.approx(100 * (lf - float(case["Lf_test_mm"])) / float(case["Lf_test_mm"]),
                                                         rel=1e-12)
        df = 2e3 * ref["mushroom_radius"]
        assert float(r["Df_error_pct"]) == pytest.approx(100 * (df - float(case["Df_test_mm"])) / float(case["Df_test_mm"]),
                                                         rel=1e-12)
        assert float(r["wall_time_s"]) > 0


def test_sweep_on_a_local_dask_cluster(tmp_path, tmp_path_factory):
    out = tmp_path / "dask.csv"
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster:
        code, log = run_script("--scheduler", cluster.scheduler_address, "--cases", "1,7,12",
                               "--particles-radial", str(COARSE), "--out", str(out))
    assert code == 0, log
    assert "3 cases in" in log
    check(read(out), ["1", "7", "12"], tmp_path_factory)


def test_sweep_on_the_local_process_pool(tmp_path, tmp_path_factory):
    out = tmp_path / "local.csv"
    code, log = run_script("--cases", "7", "--particles-radial", str(COARSE), "--workers", "2", "--out", str(out))
    assert code == 0, log
    check(read(out), ["7"], tmp_path_factory)


def test_sweep_reports_a_bad_case_without_stopping(tmp_path):
    cases = tmp_path / "cases.csv"
    cases.write_text("# two cases, one impossible\ntest,D0_mm,L0_mm,V_mps\nok,7.595,37.97,181\nbad,7.595,37.97,-5\n")
    out = tmp_path / "bad.csv"
    code, log = run_script("--cases", str(cases), "--particles-radial", "4", "--workers", "2", "--out", str(out))
    assert code == 1, log
    assert "test bad: ERROR" in log
    rows = read(out)
    assert rows["ok"]["error"] == "" and float(rows["ok"]["rod_length"]) < 0.03797
    assert rows["bad"]["error"] != ""
