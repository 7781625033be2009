#!/usr/bin/env python3
"""The Lambert-Jonas ballistic-limit curve, fitted to (impact speed, residual
speed) pairs with numpy.

    V_r = a (V^p - V_bl^p)^(1/p)   for V > V_bl,   V_r = 0 below it.

Lambert & Jonas (1976), "Towards standardization in terminal ballistics
testing: velocity representation", BRL report 1852. V_bl is the ballistic
limit, `a` at most 1 (the residual speed approaches a V far above the
limit), `p` typically 2 to 3.

The fit is nonlinear least squares over the residual speeds of all shots.
For a given (V_bl, p) the best `a` is linear least squares (variable
projection), so only (V_bl, p) are searched: first on a 40 x 41 grid,
evaluated at once over numpy arrays, then refined from the grid's best
point by Levenberg-Marquardt (numpy.linalg.solve on the damped normal
equations, the Jacobian by central differences). Shots that did not
perforate (V_r = 0) bound V_bl from below: V_bl is kept between the fastest
of them and the slowest perforating shot, p within `p_range`.

Uncertainty: the shots bracket V_bl (`bracket`: the fastest stopped shot
and the slowest perforating one, whatever the curve), and the jackknife
gives the standard errors of V_bl, a and p (`v_bl_err`, `a_err`, `p_err`:
the fit repeated with each shot left out, where at least two perforating
shots remain; sqrt((n - 1)/n sum (x_i - mean)^2) over the n refits).

This module is the one fit of the project: `meshless_impact.ballistic_limit`
calls it, and `examples/ballistic_limit.py` (the sweep of the penetration
FMU) loads it through `examples/lambert_jonas.py`. It needs numpy (a
dependency of the package, and pinned in the tests' venv). On its own:

    python examples/lambert_jonas.py shots.csv     # columns V_mps, Vr_mps
"""

from __future__ import annotations

import csv
import math
import sys
from dataclasses import dataclass
from typing import Iterable, Tuple

import numpy as np


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
    """(V^p - V_bl^p)^(1/p) where V > V_bl, else 0; numpy broadcasting
    over v (shots, last axis) and v_bl, p (candidates)."""
    u = np.power(v, p) - np.power(v_bl, p)
    return np.where(u > 0, np.power(np.maximum(u, 0.0), 1.0 / p), 0.0)


def _best_a(v, vr, v_bl, p):
    """The least-squares `a` for each candidate (v_bl, p) (arrays of the
    same shape) and its residual speeds (that shape plus the shots' axis)."""
    g = _g(v, np.asarray(v_bl, dtype=float)[..., None], np.asarray(p, dtype=float)[..., None])
    num = (g * vr).sum(axis=-1)
    den = (g * g).sum(axis=-1)
    a = np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
    return a, vr - a[..., None] * g


def _levenberg_marquardt(residuals, x0, lower, upper, iterations=200):
    """Minimises |residuals(x)|^2 over x in the box [lower, upper] from x0:
    damped Gauss-Newton steps on variables scaled to the box, the Jacobian
    by central differences, each step clipped to the box and taken only if
    it lowers the sum of squares."""
    scale = upper - lower
    x = np.clip(np.asarray(x0, dtype=float), lower, upper)
    r = residuals(x)
    sse = float(r @ r)
    damping = 1e-3
    for _ in range(iterations):
        jac = np.empty((r.size, x.size))
        for d in range(x.size):
            h = 1e-7 * scale[d]
            up = x.copy()
            down = x.copy()
            up[d] = min(x[d] + h, upper[d])
            down[d] = max(x[d] - h, lower[d])
            jac[:, d] = (residuals(up) - residuals(down)) / ((up[d] - down[d]) / scale[d])
        normal = jac.T @ jac
        gradient = jac.T @ r
        improved = False
        while damping < 1e12:
            lhs = normal + damping * np.diag(np.maximum(np.diag(normal), 1e-300))
            try:
                step = -np.linalg.solve(lhs, gradient)
            except np.linalg.LinAlgError:
                damping *= 10.0
                continue
            trial = np.clip(x + step * scale, lower, upper)
            rt = residuals(trial)
            st = float(rt @ rt)
            if np.isfinite(st) and st < sse:
                moved = np.max(np.abs(trial - x) / scale)
                x, r, sse = trial, rt, st
                damping = max(damping / 10.0, 1e-12)
                improved = True
                break
            damping *= 10.0
        if not improved or moved < 1e-13 or sse == 0.0:
            break
    return x, sse


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
        x = np.asarray(values)
        return float(np.sqrt((n - 1) / n * np.sum((x - x.mean()) ** 2)))

    best.v_bl_err = err([f.v_bl for f in refits])
    best.a_err = err([f.a for f in refits])
    best.p_err = err([f.p for f in refits])
    return best


def _fit(shots, p_range):
    """The least-squares curve of `shots` ([`fit`] without the errors)."""
    for v, vr in shots:
        if not (math.isfinite(v) and math.isfinite(vr)) or v <= 0 or vr < 0:
            raise ValueError(f"shot (V = {v}, V_r = {vr}): speeds must be finite, V > 0, V_r >= 0")
    v = np.array([s[0] for s in shots], dtype=float)
    vr = np.array([s[1] for s in shots], dtype=float)
    through = np.sort(v[vr > 0])
    stopped = v[vr == 0]
    if through.size < 2:
        raise ValueError(f"{through.size} perforating shots; the fit needs at least 2")
    lo = float(stopped.max()) if stopped.size else 0.0
    hi = float(through[0])
    if lo >= hi:
        raise ValueError(
            f"a stopped shot at {lo} m/s is faster than a perforating one at {hi} m/s"
        )
    plo, phi = p_range
    lower = np.array([lo, plo])
    upper = np.array([hi * (1 - 1e-12), phi])

    # The grid over (V_bl, p), all candidates at once, then
    # Levenberg-Marquardt from its best point.
    vb, pp = np.meshgrid(lo + (hi - lo) * np.arange(40) / 40, plo + (phi - plo) * np.arange(41) / 40,
                         indexing="ij")
    _, res = _best_a(v, vr, vb, pp)
    sse = np.sum(res * res, axis=-1)
    start = np.unravel_index(np.argmin(sse), sse.shape)
    x, _ = _levenberg_marquardt(lambda x: _best_a(v, vr, x[0], x[1])[1],
                                np.array([vb[start], pp[start]]), lower, upper)
    v_bl, p = float(x[0]), float(x[1])
    a, res = _best_a(v, vr, v_bl, p)
    sse = float(res @ res)
    return Fit(a=float(a), p=p, v_bl=v_bl, rms=math.sqrt(sse / len(shots)), bracket=(lo, hi))


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
