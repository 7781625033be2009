"""Sweeps of many runs, and the ballistic limit from the penetration sweep."""

from __future__ import annotations

import itertools
import math
import os
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

from . import lambert_jonas
from ._native import Simulation
from .errors import InputError, MeshlessImpactError

Row = Dict[str, Any]
Grid = Union[Mapping[str, Any], Iterable[Mapping[str, Any]]]


def _cases(grid_or_list: Grid) -> List[Dict[str, Any]]:
    """The runs of a sweep: every combination of a grid (a dict of name ->
    values; a single value is one value), in the grid's order with the last
    name varying fastest, or the dicts of a list as they are."""
    if isinstance(grid_or_list, Mapping):
        names = list(grid_or_list)
        axes = []
        for name in names:
            values = grid_or_list[name]
            if isinstance(values, (str, bytes)) or not isinstance(values, Iterable):
                values = [values]
            axes.append(list(values))
        return [dict(zip(names, combo)) for combo in itertools.product(*axes)]
    return [dict(case) for case in grid_or_list]


def _run_case(scene: str, case: Mapping[str, Any], threads: Optional[int] = 1) -> Row:
    """One run of a sweep to its end condition (on `threads` solver threads):
    the case's parameters, the final observables, `particles`, `steps`,
    `time`, `wall_time_s`, and `outcome` ("finished", or the name of the
    solver stop, whose message is then `error`; the values are those at the
    stop), as the command line's `--json`. Bad input raises."""
    start = time.perf_counter()
    sim = Simulation(scene, threads=threads, **case)
    outcome, error = "finished", ""
    try:
        sim.run()
    except InputError:
        raise
    except MeshlessImpactError as e:
        outcome, error = type(e).__name__, str(e)
    row: Row = {**case, **sim.observables()}
    row.update(particles=sim.particles, steps=sim.steps, time=sim.time,
               wall_time_s=time.perf_counter() - start, outcome=outcome, error=error)
    return row


def _table(rows: List[Row], frame: Optional[bool]) -> Any:
    """`rows` as a pandas DataFrame when pandas is installed (or `frame` is
    True), else the list itself (`frame` False, or no pandas)."""
    if frame is False:
        return rows
    try:
        import pandas
    except ImportError:
        if frame:
            raise
        return rows
    return pandas.DataFrame(rows)


def sweep(scene: str, grid_or_list: Grid, *, client: Any = None, workers: Optional[int] = None,
          frame: Optional[bool] = None, **common: Any) -> Any:
    """Runs `scene` once per case and returns a table of the final
    observables, one row per run (a pandas DataFrame when pandas is
    installed, else a list of dicts; `frame` forces either).

    `grid_or_list`: a dict of parameter name -> values, run as every
    combination (``{"impact_speed": [150, 200], "particles_radial": 6}``),
    or a list of dicts, one per run. A case may also choose ``preset``,
    ``strength``, ``eos`` or ``scheme``. `common`: parameters of every run.

    Each row holds the case's parameters, the final observables,
    ``particles``, ``steps``, ``time``, ``wall_time_s``, and ``outcome``:
    "finished", or the name of the error that stopped the run (its message
    in ``error``; the values are those at the stop). Bad input raises the
    :class:`~meshless_impact.errors.InputError` of the first bad case.

    Locally the runs share a thread pool of `workers` threads (default: one
    per CPU), one solver thread each. Given a Dask `client`
    (``dask.distributed.Client``), they run on its cluster, one task per
    run (the workers need the package installed), as the FMU sweeps do.
    """
    cases = [{**common, **case} for case in _cases(grid_or_list)]
    if client is not None:
        futures = client.map(_run_case, [scene] * len(cases), cases, pure=False)
        rows = list(client.gather(futures))
    else:
        n = workers or os.cpu_count() or 1
        with ThreadPoolExecutor(max_workers=n) as pool:
            rows = list(pool.map(lambda case: _run_case(scene, case), cases))
    return _table(rows, frame)


def shot_status(row: Mapping[str, Any]) -> Tuple[str, Optional[float]]:
    """The status of one penetration shot and its residual speed V_r, by the
    rule of the ballistic-limit sweep (examples/ballistic_limit.py, README
    "Ballistic limit"): a shot stopped by an error is ``"error"`` (no V_r);
    else its ``shot_outcome`` decides: 1 ``"through"`` (perforated, V_r =
    its ``projectile_velocity``), 2 ``"stopped"`` (V_r = 0), 0
    ``"unsettled"`` (neither by end_time, the cap; V_r = its velocity then,
    not a residual velocity)."""
    if row.get("outcome", "finished") != "finished":
        return "error", None
    status = {1: "through", 2: "stopped", 0: "unsettled"}[int(row["shot_outcome"])]
    return status, 0.0 if status == "stopped" else float(row["projectile_velocity"])


@dataclass
class BallisticLimit:
    """The ballistic limit of a penetration sweep: the Lambert-Jonas curve
    V_r = a (V^p - V_bl^p)^(1/p) fitted to the shots (NaN where it could
    not be fitted: `message` says why), with the jackknife standard errors
    and the bracket of the shots (the fastest stopped and the slowest
    perforating one), and the table of shots (each with ``status`` and
    ``Vr_mps``)."""

    v_bl: float
    a: float
    p: float
    v_bl_err: float
    a_err: float
    p_err: float
    bracket: Tuple[float, float]
    rms: float
    shots: Any
    fitted: int
    message: str = ""
    fit: Optional[lambert_jonas.Fit] = field(default=None, repr=False)


def ballistic_limit(speeds: Sequence[float], *, client: Any = None, workers: Optional[int] = None,
                    fit_unsettled: bool = False, frame: Optional[bool] = None,
                    **scene_params: Any) -> BallisticLimit:
    """Runs the `penetration` scene at each impact speed in `speeds` (m/s),
    each shot ending at its outcome (``run_until = "outcome"``, with
    ``end_time`` as the cap), decides each shot's status with
    :func:`shot_status`, and fits the Lambert-Jonas curve to the through
    and stopped shots (the unsettled ones too with `fit_unsettled`) with the
    project's fit (:mod:`meshless_impact.lambert_jonas`, the one
    examples/ballistic_limit.py uses).

    `scene_params`: the scene's parameters for every shot
    (``particles_radial=4, plate_thickness=0.004, end_time=2e-5``, or the
    choices ``preset``, ``scheme``, ...). `client`, `workers`, `frame`: as
    :func:`sweep`.
    """
    params = {"run_until": "outcome", **scene_params}
    rows = sweep("penetration", [{"impact_speed": float(v)} for v in speeds], client=client,
                 workers=workers, frame=False, **params)
    for row in rows:
        row["V_mps"] = row["impact_speed"]
        row["status"], row["Vr_mps"] = shot_status(row)
    use = {"through", "stopped"} | ({"unsettled"} if fit_unsettled else set())
    data = [(r["V_mps"], r["Vr_mps"]) for r in rows if r["status"] in use]
    nan = math.nan
    try:
        f = lambert_jonas.fit(data)
    except ValueError as e:
        return BallisticLimit(nan, nan, nan, nan, nan, nan, (nan, nan), nan, _table(rows, frame),
                              len(data), f"no fit: {e}")
    return BallisticLimit(f.v_bl, f.a, f.p, f.v_bl_err, f.a_err, f.p_err, f.bracket, f.rms,
                          _table(rows, frame), len(data), "", f)
