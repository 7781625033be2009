"""The walk-through of docs/guide/python.md: its Python blocks run in order
in one namespace (in a scratch directory, with matplotlib's file backend),
and the same code passes `mypy --strict` against the package's stubs."""

import os
import re
import subprocess
import sys
from pathlib import Path

from conftest import ROOT

PAGE = ROOT / "docs" / "guide" / "python.md"


def code():
    """The page's ```python blocks, in order, as one script."""
    blocks = re.findall(r"^```python\n(.*?)^```", PAGE.read_text(), flags=re.S | re.M)
    assert len(blocks) >= 4, "the walk-through has a block per step"
    return "\n".join(blocks)


def test_the_walkthrough_runs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    namespace = {"__name__": "__walkthrough__"}
    exec(compile(code(), str(PAGE), "exec"), namespace)
    # What the page shows: the plot written, a field read, a table, a limit.
    assert (tmp_path / "taylor_history.png").stat().st_size > 1000
    assert namespace["strain"].shape == (namespace["sim"].particles,)
    assert len(namespace["table"]) == 3
    limit = namespace["limit"]
    assert limit.bracket[0] <= limit.v_bl <= limit.bracket[1]


def test_the_walkthrough_passes_mypy_strict(tmp_path):
    script = tmp_path / "walkthrough.py"
    script.write_text(code())
    r = subprocess.run([sys.executable, "-m", "mypy", "--strict", "--no-incremental",
                        "--cache-dir", os.devnull, str(script)], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
