"""meshless-impact from Python: meshless solvers for high-speed impact of
solids (the Taylor test in 2-D and 3-D, ballistic penetration of a ceramic
plate, plate impact), numpy in and out.

The names are the project's one vocabulary (docs/guide/python.md, DESIGN.md):
the same scenes, parameters, observables, fields, materials and schemes as
the command line, the C ABI and the FMUs, in SI units.

- Discovery: :func:`scenes`, :func:`params`, :func:`observables`,
  :func:`fields`, :func:`presets`.
- One run: :class:`Simulation` (``run``, ``advance_to``, ``step``; the
  interpreter lock is released while the solver steps).
- Many runs: :func:`sweep` (a thread pool, or a Dask cluster) and
  :func:`ballistic_limit` (the penetration sweep and the Lambert-Jonas fit).
- Calibration: :func:`calibrate` fits a material's constants to impact
  tests, with their uncertainty.
- Errors: :mod:`meshless_impact.errors`, one class per named error.
"""

from __future__ import annotations

from . import errors
from ._native import VERSION as __version__
from ._calibrate import calibrate
from ._native import Simulation, fields, observables, params, presets, scenes
from ._sweep import BallisticLimit, ballistic_limit, shot_status, sweep
from .errors import InputError, MeshlessImpactError, SolverStop

__all__ = [
    "BallisticLimit",
    "InputError",
    "MeshlessImpactError",
    "Simulation",
    "SolverStop",
    "ballistic_limit",
    "calibrate",
    "errors",
    "fields",
    "observables",
    "params",
    "presets",
    "scenes",
    "shot_status",
    "sweep",
]
