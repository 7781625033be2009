#!/usr/bin/env python3
"""The Lambert-Jonas ballistic-limit curve, fitted to (impact speed, residual
speed) pairs, in plain Python (no numpy or scipy).

    V_r = a (V^p - V_bl^p)^(1/p)   for V > V_bl,   V_r = 0 below it.

Lambert & Jonas (1976), "Towards standardization in terminal ballistics
testing: velocity representation", BRL report 1852. V_bl is the ballistic
limit, `a` at most 1 (the residual speed approaches a V far above the
limit), `p` typically 2 to 3.

The fit: for a given (V_bl, p), the best `a` is linear least squares over
the perforating shots; (V_bl, p) minimise the squared residual speeds by a
grid search refined with Nelder-Mead. Shots that did not perforate
(V_r = 0) bound V_bl from below: V_bl is searched between the fastest of
them and the slowest perforating shot.

Uncertainty: the shots bracket V_bl (`bracket`: the fastest stopped shot
and the slowest perforating one, whatever the curve), and the jackknife
gives the standard errors of V_bl, a and p (`v_bl_err`, `a_err`, `p_err`:
the fit repeated with each shot left out, where at least two perforating
shots remain; sqrt((n - 1)/n sum (x_i - mean)^2) over the n refits).

This module is the one fit of the project: `meshless_impact.ballistic_limit`
calls it, and `examples/ballistic_limit.py` (the sweep of the penetration
FMU) loads it through `examples/lambert_jonas.py`. It needs nothing but the
standard library. On its own:

    python examples/lambert_jonas.py shots.csv     # columns V_mps, Vr_mps
"""

from __future__ import annotations

import csv
import math
import sys
from dataclasses import dataclass
from typing import Iterable, Tuple


@dataclass
class Fit:
    """A fitted Lambert-Jonas curve, its residual and its uncertainty."""

    a: float
    p: float
    v_bl: float
    rms: float  # root-mean-square residual speed over all shots (m/s)
    # The fastest stopped shot (0 if none) and the slowest perforating one
    # (m/s): V_bl lies between them whatever the curve.
    bracket: Tuple[float, float] = (0.0, math.inf)
    # Jackknife standard errors (m/s, 1, 1); NaN with fewer than two refits.
    v_bl_err: float = math.nan
    a_err: float = math.nan
    p_err: float = math.nan

    def residual_speed(self, v: float) -> float:
        """V_r of the curve at impact speed v."""
        if v <= self.v_bl:
            return 0.0
        return self.a * (v**self.p - self.v_bl**self.p) ** (1.0 / self.p)


def _g(v, v_bl, p):
    return (v**p - v_bl**p) ** (1.0 / p) if v > v_bl else 0.0


def _best_a(shots, v_bl, p):
    """The least-squares `a` for (v_bl, p) and the sum of squared residuals."""
    num = sum(vr * _g(v, v_bl, p) for v, vr in shots)
    den = sum(_g(v, v_bl, p) ** 2 for v, vr in shots)
    a = num / den if den > 0 else 0.0
    sse = sum((vr - a * _g(v, v_bl, p)) ** 2 for v, vr in shots)
    return a, sse


def _nelder_mead(f, x0, step, iters=400, tol=1e-12):
    """Minimises f over 2-D points from x0 with initial steps `step`."""
    pts = [list(x0), [x0[0] + step[0], x0[1]], [x0[0], x0[1] + step[1]]]
    vals = [f(x) for x in pts]
    for _ in range(iters):
        order = sorted(range(3), key=lambda k: vals[k])
        pts = [pts[k] for k in order]
        vals = [vals[k] for k in order]
        if abs(vals[2] - vals[0]) <= tol * (1.0 + abs(vals[0])):
            break
        c = [(pts[0][d] + pts[1][d]) / 2 for d in range(2)]
        r = [c[d] + (c[d] - pts[2][d]) for d in range(2)]
        fr = f(r)
        if fr < vals[0]:
            e = [c[d] + 2 * (c[d] - pts[2][d]) for d in range(2)]
            fe = f(e)
            pts[2], vals[2] = (e, fe) if fe < fr else (r, fr)
        elif fr < vals[1]:
            pts[2], vals[2] = r, fr
        else:
            k = [c[d] + 0.5 * (pts[2][d] - c[d]) for d in range(2)]
            fk = f(k)
            if fk < vals[2]:
                pts[2], vals[2] = k, fk
            else:
                for j in (1, 2):
                    pts[j] = [pts[0][d] + 0.5 * (pts[j][d] - pts[0][d]) for d in range(2)]
                    vals[j] = f(pts[j])
    best = min(range(3), key=lambda k: vals[k])
    return pts[best], vals[best]


def fit(given: Iterable[Tuple[float, float]], p_range: Tuple[float, float] = (1.0, 6.0)) -> Fit:
    """Fits the curve to `given`, a list of (V, V_r) in m/s (V_r = 0 where
    the plate stopped the projectile), with its bracket and jackknife
    standard errors. Needs at least two perforating shots; raises
    ValueError otherwise or when a speed is negative or not finite."""
    shots = [(float(v), float(vr)) for v, vr in given]
    best = _fit(shots, p_range)
    refits = []
    for k in range(len(shots)):
        rest = shots[:k] + shots[k + 1:]
        if sum(1 for _, vr in rest if vr > 0) >= 2:
            refits.append(_fit(rest, p_range))
    n = len(refits)

    def err(values):
        if n < 2:
            return math.nan
        mean = sum(values) / n
        return math.sqrt((n - 1) / n * sum((x - mean) ** 2 for x in values))

    best.v_bl_err = err([f.v_bl for f in refits])
    best.a_err = err([f.a for f in refits])
    best.p_err = err([f.p for f in refits])
    return best


def _fit(shots, p_range):
    """The least-squares curve of `shots` ([`fit`] without the errors)."""
    shots = [(float(v), float(vr)) for v, vr in shots]
    for v, vr in shots:
        if not (math.isfinite(v) and math.isfinite(vr)) or v <= 0 or vr < 0:
            raise ValueError(f"shot (V = {v}, V_r = {vr}): speeds must be finite, V > 0, V_r >= 0")
    through = sorted(v for v, vr in shots if vr > 0)
    stopped = [v for v, vr in shots if vr == 0]
    if len(through) < 2:
        raise ValueError(f"{len(through)} perforating shots; the fit needs at least 2")
    lo = max(stopped, default=0.0)
    hi = through[0]
    if lo >= hi:
        raise ValueError(
            f"a stopped shot at {lo} m/s is faster than a perforating one at {hi} m/s"
        )
    plo, phi = p_range

    def clamp(x):
        return [min(max(x[0], lo), hi * (1 - 1e-12)), min(max(x[1], plo), phi)]

    def cost(x):
        x = clamp(x)
        return _best_a(shots, x[0], x[1])[1]

    # A grid over (V_bl, p), then Nelder-Mead from its best point.
    grid = [
        [lo + (hi - lo) * i / 40, plo + (phi - plo) * j / 40]
        for i in range(40)
        for j in range(41)
    ]
    start = min(grid, key=cost)
    x, _ = _nelder_mead(cost, start, [(hi - lo) / 40, (phi - plo) / 40])
    v_bl, p = clamp(x)
    a, sse = _best_a(shots, v_bl, p)
    return Fit(a=a, p=p, v_bl=v_bl, rms=math.sqrt(sse / len(shots)), bracket=(lo, hi))


def main(argv):
    if len(argv) != 2:
        print(__doc__)
        return 2
    with open(argv[1], newline="") as f:
        rows = [r for r in csv.DictReader(f)]
    shots = [(float(r["V_mps"]), float(r["Vr_mps"])) for r in rows]
    result = fit(shots)
    print(
        f"ballistic limit V_bl = {result.v_bl:.1f} +- {result.v_bl_err:.1f} m/s "
        f"(shots bracket {result.bracket[0]:.1f}-{result.bracket[1]:.1f}), "
        f"a = {result.a:.4f} +- {result.a_err:.4f}, p = {result.p:.3f} +- {result.p_err:.3f}, "
        f"rms residual {result.rms:.2f} m/s ({len(shots)} shots)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
