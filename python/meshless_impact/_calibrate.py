"""Calibration from Python: :func:`calibrate`, the command line's
``meshless-impact calibrate`` on the same core, with the same answer bit for
bit (docs/guide/calibration.md)."""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Mapping, Optional, Tuple, Union

import numpy as np

from . import _native

PathLike = Union[str, "os.PathLike[str]"]


def calibrate(
    scene: Union[str, PathLike],
    shots: PathLike,
    free: Mapping[str, Tuple[float, float]],
    *,
    preset: Optional[str] = None,
    strength: Optional[str] = None,
    eos: Optional[str] = None,
    scheme: Optional[str] = None,
    preset_file: Optional[PathLike] = None,
    set: Optional[Mapping[str, Any]] = None,
    max_runs: int = 400,
    max_wall: float = 3600.0,
    coarse: Optional[Tuple[str, float]] = None,
    fd_step: float = 0.01,
    xtol: float = 1e-3,
    leave_one_out: Optional[str] = None,
    method: str = "broyden",
    out: Optional[PathLike] = None,
) -> Dict[str, Any]:
    """Fits the ``free`` parameters of ``scene`` to the experiments in the
    CSV file ``shots`` (one row per experiment; each column a parameter of
    the scene or an observable, with optional ``sigma_NAME``, ``shot``,
    ``outline`` and ``sigma_outline`` columns).

    ``free`` maps each free parameter to its bounds ``(lo, hi)``; it starts
    from the scene's value. ``preset``, ``strength``, ``eos``, ``scheme``,
    ``preset_file`` and ``set`` (a dict of fixed parameters) are the command
    line's ``--preset``, ``--strength``, ``--eos``, ``--scheme``,
    ``--preset-file`` and ``--set``; ``max_runs``, ``max_wall`` (s),
    ``coarse`` (``(name, value)``), ``fd_step``, ``xtol``, ``method``
    (``"broyden"`` or ``"plain"``) and ``leave_one_out`` (``None``,
    ``"linearised"`` or ``"refit"``) its options of the same names.

    Returns the fields of ``calibration.json`` as a dict: ``parameters``,
    ``std`` (``None`` where the data do not constrain a parameter),
    ``identifiable`` and ``not_identifiable_because`` (name to value),
    ``correlation`` (a numpy array in the order of ``names``; NaN beside an
    unconstrained parameter), ``experiments`` (settings, observed, before,
    fitted), ``runs``, ``wall_time_s``, ``outcome`` and the rest; plus
    ``material_toml``, the calibrated material as a ``[material]`` table
    (``Simulation(..., preset_file=...)`` and ``--preset-file`` take it).
    With ``out``, also writes ``calibration.json`` and ``material.toml``
    there.

    Bad input raises the command line's errors (:class:`~meshless_impact.errors.ShotsFile`,
    :class:`~meshless_impact.errors.OutOfRange`, ...). A fit that reaches a
    cap returns normally with ``outcome`` ``"run_cap"`` or ``"wall_cap"``
    and the best point so far.
    """
    bounds = [(str(name), float(lo), float(hi)) for name, (lo, hi) in free.items()]
    text, material = _native.calibrate(
        scene,
        os.fspath(shots),
        bounds,
        preset=preset,
        strength=strength,
        eos=eos,
        scheme=scheme,
        preset_file=None if preset_file is None else os.fspath(preset_file),
        max_runs=max_runs,
        max_wall=max_wall,
        coarse=None if coarse is None else (str(coarse[0]), float(coarse[1])),
        fd_step=fd_step,
        xtol=xtol,
        leave_one_out=leave_one_out,
        method=method,
        params=dict(set or {}),
    )
    result: Dict[str, Any] = json.loads(text)
    if out is not None:
        os.makedirs(out, exist_ok=True)
        with open(os.path.join(out, "calibration.json"), "w") as f:
            json.dump(result, f, indent=2)
            f.write("\n")
        with open(os.path.join(out, "material.toml"), "w") as f:
            f.write(material)
    result["correlation"] = np.array(
        [[np.nan if v is None else v for v in row] for row in result["correlation"]],
        dtype=float,
    )
    result["material_toml"] = material
    return result
