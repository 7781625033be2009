#!/usr/bin/env bash
# FMU checks with fmpy: builds the FMUs (`cargo xtask fmu`) and runs the
# Python tests in this directory. Creates the virtual environment .venv at the
# repository root on first use (pinned versions below).
set -euo pipefail
cd "$(dirname "$0")/../.."
ROOT=$(pwd)
VENV="$ROOT/.venv"
PINS="fmpy==0.3.32 fmu-manipulation-toolbox==2.0 dask==2026.8.0 distributed==2026.8.0 pytest==9.2.0"
if [ ! -x "$VENV/bin/python" ] || ! "$VENV/bin/python" -c "import fmpy, fmu_manipulation_toolbox, dask.distributed, pytest" 2>/dev/null; then
  echo "== creating $VENV ($PINS)"
  python3 -m venv "$VENV"
  "$VENV/bin/pip" install --quiet --upgrade pip
  # shellcheck disable=SC2086
  "$VENV/bin/pip" install --quiet $PINS
fi
# The test command packages with the example it built beside the tests
# (MI_FMU_PACKAGER, examples/package_fmus.rs: the same code as xtask's);
# otherwise `cargo xtask fmu` builds the library and packages it.
if [ -n "${MI_FMU_PACKAGER:-}" ]; then
  echo "== $MI_FMU_PACKAGER"
  "$MI_FMU_PACKAGER"
else
  echo "== cargo xtask fmu"
  cargo xtask fmu
fi
echo "== pytest tests/fmu"
PATH="$VENV/bin:$PATH" "$VENV/bin/python" -m pytest -q -p no:cacheprovider tests/fmu "$@"
