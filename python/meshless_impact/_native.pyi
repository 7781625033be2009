"""Types of the extension module meshless_impact._native (written in Rust,
python/src/lib.rs). Users import these names from meshless_impact."""

from os import PathLike
from typing import Any, Callable, Dict, List, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

VERSION: str

Progress = Callable[[float, float, int], Optional[bool]]

class Simulation:
    """One run of one scene.

    ``Simulation(scene_or_toml_path, *, preset=None, strength=None, eos=None,
    scheme=None, threads=None, preset_file=None, **params)``: a built-in scene by name
    (:func:`scenes`) or a TOML scene file (a path ending in ``.toml``, or
    any ``os.PathLike``), with the material choice, the numerical scheme and
    parameters by their names (SI units), applied as the command line's
    ``--scheme``, ``--strength``, ``--eos``, ``--preset``, ``--preset-file``
    (a material file, as ``calibrate`` writes) and ``--set``. A
    bad name or value raises a ``ValueError``
    (:class:`meshless_impact.errors.InputError`) with the command line's
    message. `threads`: solver threads of this run's own pool (default:
    the process's global pool, one thread per CPU); the results do not
    depend on it.

    The interpreter lock is released while the solver steps, so runs on
    separate Python threads run in parallel. A run that leaves the solver's
    domain of validity raises the :class:`~meshless_impact.errors.SolverStop`
    subclass that names it; the state at the stop stays readable.
    """

    def __init__(
        self,
        scene: Union[str, "PathLike[str]"],
        *,
        preset: Optional[str] = None,
        strength: Optional[str] = None,
        eos: Optional[str] = None,
        scheme: Optional[str] = None,
        threads: Optional[int] = None,
        preset_file: Union[str, "PathLike[str]", None] = None,
        **params: Union[float, str],
    ) -> None: ...
    def run(self, progress: Union[bool, Progress, None] = False) -> None:
        """Runs to the end condition. `progress`: True shows a progress
        line on standard error; a callable `progress(time, end_time, steps)`
        is called about every 0.1 s and at the end, and returning False
        cancels the run (:class:`~meshless_impact.errors.Cancelled`).
        Ctrl-C cancels it too."""
    def advance_to(self, t: float, progress: Union[bool, Progress, None] = False) -> None:
        """Steps until the time reaches `t` (s) or the end condition holds;
        the last step is not shortened."""
    def step(self) -> None:
        """Takes one step."""
    @property
    def time(self) -> float:
        """Simulated time (s)."""
    @property
    def finished(self) -> bool:
        """Whether the end condition holds, or the run stopped."""
    @property
    def steps(self) -> int:
        """Steps taken."""
    @property
    def particles(self) -> int:
        """Number of particles (nodes)."""
    @property
    def end_time(self) -> float:
        """The scene's end_time (s): the latest time the run may reach."""
    @property
    def scene(self) -> str:
        """The kind of scene."""
    @property
    def error(self) -> Optional[Exception]:
        """The exception that stopped the run, or None."""
    def params(self) -> Dict[str, Union[float, str]]:
        """Every parameter's value (a scheme's by its level's name)."""
    def observables(self) -> Dict[str, Union[float, bool]]:
        """The current observables by name (flags such as at_rest as bool)."""
    def history(self) -> Dict[str, npt.NDArray[np.float64]]:
        """The recorded histories: ``time`` and one array per observable."""
    def fields(self) -> Dict[str, Dict[str, Any]]:
        """The run's particle fields: name -> {"unit", "components"}."""
    def field(self, name: str) -> npt.NDArray[np.float64]:
        """One particle field now, shaped (nodes,) or (nodes, components)."""
    def positions(self) -> npt.NDArray[np.float64]:
        """The nodes' positions, shaped (nodes, 2) (R, Z) or (nodes, 3)."""
    def save(self, path: Union[str, "os.PathLike[str]"]) -> None:
        """Writes the whole run to the checkpoint file ``path``, whole (a
        temporary file renamed over it): what :meth:`load` and
        ``meshless-impact run --restart`` continue."""
    @staticmethod
    def load(path: Union[str, "os.PathLike[str]"], *, threads: Optional[int] = None) -> "Simulation":
        """The run saved in the checkpoint file ``path`` (by :meth:`save` or
        ``meshless-impact run --checkpoint``); a bad file raises the subclass
        of :class:`~meshless_impact.errors.BadCheckpoint` that names its
        fault."""
    def save_state(self) -> bytes:
        """The complete state of the run (solver, history, scene)."""
    def load_state(self, state: bytes) -> None:
        """Replaces the run by a state from :meth:`save_state` of the same
        kind of scene; anything else raises
        :class:`~meshless_impact.errors.InvalidState`."""
    def _debug_panic(self) -> None: ...

def scenes() -> List[str]:
    """The built-in scene names."""

def params(
    scene: str,
    *,
    preset: Optional[str] = None,
    strength: Optional[str] = None,
    eos: Optional[str] = None,
    scheme: Optional[str] = None,
) -> Dict[str, Dict[str, Any]]:
    """The parameters of `scene` with the choices made: name -> {"unit",
    "value", "default", "min", "max", "min_inclusive", "max_inclusive",
    "integer", "description", "levels"}."""

def observables(scene: str) -> Dict[str, Dict[str, str]]:
    """The observables of `scene`: name -> {"unit", "description"}."""

def fields(scene: str) -> Dict[str, Dict[str, Any]]:
    """The particle fields of `scene`: name -> {"unit", "components"}."""

def presets() -> Dict[str, Dict[str, Any]]:
    """The material presets: name -> {"models", "values", "source"}."""

def _error_samples() -> List[Tuple[str, str, Exception]]: ...
def _debug_panic() -> None: ...

def calibrate(
    scene: Union[str, "PathLike[str]"],
    shots: Union[str, "PathLike[str]"],
    free: List[Tuple[str, float, float]],
    *,
    preset: Optional[str] = None,
    strength: Optional[str] = None,
    eos: Optional[str] = None,
    scheme: Optional[str] = None,
    preset_file: Union[str, "PathLike[str]", None] = None,
    max_runs: int = 400,
    max_wall: float = 3600.0,
    coarse: Optional[Tuple[str, float]] = None,
    fd_step: float = 0.01,
    xtol: float = 1e-3,
    leave_one_out: Optional[str] = None,
    method: str = "broyden",
    params: Optional[Dict[str, Union[float, str]]] = None,
) -> Tuple[str, str]:
    """The calibration (``meshless_impact.calibrate`` wraps it): returns
    (``calibration.json``'s text, the material file's text)."""
