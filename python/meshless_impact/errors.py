"""The exceptions of meshless_impact: one class per named error of the core
(``src/error.rs``; the class name is the error's name, as the command line's
JSON ``outcome`` and the C ABI's ``mi_result_name`` give it), all under
:class:`MeshlessImpactError`.

- Bad input (a name, a value out of range, a scene file, a saved state that
  does not load): subclasses of :class:`InputError`, which is also a
  :class:`ValueError`. The message is the command line's.
- A run that left the solver's domain of validity: subclasses of
  :class:`SolverStop`. The :class:`~meshless_impact.Simulation` keeps the
  state at the stop, still readable (observables, history, fields).
"""

from __future__ import annotations


class MeshlessImpactError(Exception):
    """Base class of every error meshless_impact raises."""


class InputError(MeshlessImpactError, ValueError):
    """Bad input: the message names the parameter, its value and what is allowed."""


class OutOfRange(InputError):
    """A parameter value outside its allowed range (or NaN, infinite)."""


class UnknownParameter(InputError):
    """A parameter name that the scene does not have."""


class UnknownScene(InputError):
    """A scene name that does not exist."""


class UnknownModel(InputError):
    """A strength model, equation of state or preset that does not exist, or that the scene cannot take."""


class ParseValue(InputError):
    """A parameter value that is not a number (or a scheme's level name)."""


class Inconsistent(InputError):
    """Parameters that are each in range but inconsistent together."""


class SceneFile(InputError):
    """A scene file that could not be read or parsed."""


class ShotsFile(InputError):
    """An experiments file of a calibration that cannot be read or does not fit the scene (the message names the file, line and column)."""


class InvalidState(InputError):
    """Bytes that are not a saved state of this kind of scene."""


class BadCheckpoint(InvalidState):
    """A file given as a checkpoint that cannot be continued; its subclass says why."""


class NotACheckpoint(BadCheckpoint):
    """A file that does not start as a checkpoint does."""


class CheckpointTruncated(BadCheckpoint):
    """A checkpoint cut short: it ends before its trailer."""


class CheckpointCorrupted(BadCheckpoint):
    """A checkpoint whose checksum or length disagrees with its content."""


class CheckpointNewerFormat(BadCheckpoint):
    """A checkpoint written by a newer build, in a format this one cannot read."""


class CheckpointOtherScene(BadCheckpoint):
    """A checkpoint of another scene than the one asked for."""


class CheckpointContradicts(BadCheckpoint):
    """Parameters asked for that contradict the checkpoint's."""


class UnknownField(InputError):
    """A particle field name that the scene does not have."""


class SolverStop(MeshlessImpactError):
    """The run left the solver's domain of validity and stopped; the state at the stop stays readable."""


class SingularMomentMatrix(SolverStop):
    """A particle's MSPH or MLS moment matrix became singular."""


class NonFinite(SolverStop):
    """A field became NaN or infinite."""


class ThroughBoundary(SolverStop):
    """A particle passed through a rigid boundary (the anvil, the axis)."""


class TimeStepCollapse(SolverStop):
    """The time step collapsed."""


class EnergyDrift(SolverStop):
    """The energy balance drifted past its bound."""


class SpacingCollapse(SolverStop):
    """Two neighbouring particles came too close: the particle arrangement collapsed."""


class CompressionLimit(SolverStop):
    """A particle reached the singular compression of the Mie-Grueneisen equation of state."""


class MemoryBudget(MeshlessImpactError):
    """The run would need more memory than the budget (``MI_MEMORY_BUDGET``): refused before it allocates."""


class Cancelled(MeshlessImpactError):
    """The run was cancelled: its progress callback returned False, or Ctrl-C."""


class Io(MeshlessImpactError, OSError):
    """An input/output failure."""


class InternalError(MeshlessImpactError):
    """A panic inside the library, caught at the boundary; the simulation that panicked is unusable."""


__all__ = [name for name, value in globals().items() if isinstance(value, type) and issubclass(value, Exception)]
