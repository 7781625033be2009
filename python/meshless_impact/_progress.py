"""The progress line of ``run(progress=True)`` and ``advance_to(t, progress=True)``."""

from __future__ import annotations

import sys


def show(time: float, end_time: float, steps: int) -> bool:
    """Rewrites the progress line on standard error; the run goes on."""
    sys.stderr.write(f"\rt = {time * 1e6:.3f} us of {end_time * 1e6:.3f} us, {steps} steps")
    sys.stderr.flush()
    return True


def done() -> None:
    """Ends the progress line."""
    sys.stderr.write("\n")
    sys.stderr.flush()
