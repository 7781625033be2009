#!/usr/bin/env bash
# The Python virtual environment of the tests, .venv at the repository root:
# created on first use with the pinned versions below, or completed when a
# pin is missing. tests/fmu/run.sh calls it; the test command (scripts/test.sh)
# starts it in the background at its beginning, so that the downloads
# overlap the compilation.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV="$PWD/.venv"
# The FMU checks: fmpy, fmutool, Dask, pytest, and two more FMI hosts
# (tests/fmu/test_hosts.py): ecos (ecospy; its library needs Debian's
# libtbb12, which scripts/test.sh installs) and libcosim (libcosimpy). The
# Python package
# (python/): its build backend (maturin, installed here so that the test
# command builds without isolation, on the tests' cargo build), numpy, and
# what its tests and walk-through use (pandas, matplotlib, mypy). SciPy:
# the least-squares fit of examples/calibrate_fmu.py
# (tests/fmu/test_calibrate_fmu.py).
PINS="fmpy==0.3.32 fmu-manipulation-toolbox==2.0 dask==2026.8.0 distributed==2026.8.0 pytest==9.2.0
ecospy==0.7.2 libcosimpy==0.0.6 maturin==1.16.0 numpy==2.4.6 pandas==3.1.1 matplotlib==3.11.2 mypy==2.4.1
scipy==1.17.1"
if [ -x "$VENV/bin/python" ] && "$VENV/bin/python" -c "import fmpy, fmu_manipulation_toolbox, dask.distributed, pytest, numpy, pandas, matplotlib, mypy, maturin, scipy
import importlib.util as u; assert u.find_spec('ecospy') and u.find_spec('libcosimpy')" 2>/dev/null; then
  exit 0
fi
echo "== creating $VENV ($(echo $PINS))"
[ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
"$VENV/bin/pip" install --quiet --upgrade pip
# No byte-code compiled at install: the tests import a small part of what
# is installed (pandas, matplotlib), and Python compiles that when imported.
# shellcheck disable=SC2086
"$VENV/bin/pip" install --quiet --no-compile $PINS
