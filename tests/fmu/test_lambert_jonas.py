"""examples/lambert_jonas.py: the Lambert-Jonas fit recovers the constants of
curves it is given (the formula itself is the oracle), with and without
scatter, and refuses shot lists it cannot fit."""

import importlib.util
import math
import subprocess
import sys

import pytest

from conftest import ROOT

spec = importlib.util.spec_from_file_location("lambert_jonas", ROOT / "examples" / "lambert_jonas.py")
lj = importlib.util.module_from_spec(spec)
sys.modules["lambert_jonas"] = lj
spec.loader.exec_module(lj)

# A tungsten-on-ceramic-like curve: V_bl = 820 m/s, a = 0.92, p = 2.4.
TRUE = lj.Fit(a=0.92, p=2.4, v_bl=820.0, rms=0.0)
SPEEDS = [500, 700, 800, 900, 1000, 1200, 1500, 1800, 2100]


def shots(curve, scatter=()):
    """(V, V_r) of `curve` at SPEEDS, V_r scaled by 1 + scatter[k]."""
    out = []
    for k, v in enumerate(SPEEDS):
        vr = curve.residual_speed(v)
        if scatter:
            vr *= 1.0 + scatter[k]
        out.append((v, vr))
    return out


def test_exact_shots_give_back_the_curve():
    f = lj.fit(shots(TRUE))
    assert abs(f.v_bl / TRUE.v_bl - 1) < 1e-3, f
    assert abs(f.a / TRUE.a - 1) < 1e-3, f
    assert abs(f.p / TRUE.p - 1) < 1e-2, f
    assert f.rms < 0.05, f


def test_scatter_of_two_percent_moves_the_limit_little():
    # Deterministic scatter of +-2 % on the perforating shots.
    scatter = [0.0, 0.0, 0.0, 0.02, -0.02, 0.015, -0.01, 0.02, -0.015]
    f = lj.fit(shots(TRUE, scatter))
    assert abs(f.v_bl / TRUE.v_bl - 1) < 0.03, f
    assert abs(f.a / TRUE.a - 1) < 0.03, f
    # The fitted curve passes within the scatter of every shot.
    for v, vr in shots(TRUE, scatter):
        assert abs(f.residual_speed(v) - vr) < 0.03 * max(TRUE.residual_speed(v), 1.0) + 5.0


def test_the_fit_is_the_least_squares_minimum():
    """An independent oracle: the sum of squared residual speeds, computed
    here point by point in plain Python, is nowhere smaller on a fine grid
    of (V_bl, a, p) around the fit of the scattered shots."""
    scatter = [0.0, 0.0, 0.0, 0.02, -0.02, 0.015, -0.01, 0.02, -0.015]
    data = shots(TRUE, scatter)
    f = lj.fit(data)

    def sse(v_bl, a, p):
        c = lj.Fit(a=a, p=p, v_bl=v_bl, rms=0.0)
        return sum((vr - c.residual_speed(v)) ** 2 for v, vr in data)

    best = sse(f.v_bl, f.a, f.p)
    assert math.isclose(best, len(data) * f.rms**2, rel_tol=1e-9)
    for i in range(-4, 5):
        for j in range(-4, 5):
            for k in range(-4, 5):
                v_bl = f.v_bl * (1 + 2e-3 * i)
                if not f.bracket[0] <= v_bl < f.bracket[1]:
                    continue
                other = sse(v_bl, f.a * (1 + 2e-3 * j), f.p * (1 + 5e-3 * k))
                assert other >= best * (1 - 1e-9), (i, j, k, other, best)


def test_the_errors_are_nil_for_exact_shots_and_cover_the_truth_with_scatter():
    """Exact shots: the jackknife errors vanish (to the fit's own
    tolerance) and the shots bracket the limit. With +-2 % scatter the
    true V_bl lies within three standard errors of the fit, and within
    the bracket."""
    exact = lj.fit(shots(TRUE))
    assert exact.v_bl_err < 1e-3 and exact.a_err < 1e-6, exact
    lo, hi = exact.bracket
    assert lo < TRUE.v_bl < hi
    scatter = [0.0, 0.0, 0.0, 0.02, -0.02, 0.015, -0.01, 0.02, -0.015]
    f = lj.fit(shots(TRUE, scatter))
    assert f.v_bl_err > 0 and math.isfinite(f.v_bl_err), f
    assert abs(f.v_bl - TRUE.v_bl) < 3 * f.v_bl_err + 1e-9, f
    assert f.bracket[0] < f.v_bl < f.bracket[1]


def test_shot_lists_it_cannot_fit_are_refused():
    with pytest.raises(ValueError, match="at least 2"):
        lj.fit([(500, 0.0), (1000, 300.0)])
    with pytest.raises(ValueError, match="faster than a perforating"):
        lj.fit([(1200, 0.0), (1000, 300.0), (1500, 700.0)])
    with pytest.raises(ValueError, match="finite"):
        lj.fit([(math.nan, 10.0), (1000, 300.0), (1500, 700.0)])


def test_command_line_prints_the_limit(tmp_path):
    path = tmp_path / "shots.csv"
    path.write_text("V_mps,Vr_mps\n" + "".join(f"{v},{vr!r}\n" for v, vr in shots(TRUE)))
    out = subprocess.run(
        [sys.executable, str(ROOT / "examples" / "lambert_jonas.py"), str(path)],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    assert "ballistic limit V_bl = 820." in out, out
