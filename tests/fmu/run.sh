#!/usr/bin/env bash
# FMU checks with fmpy: builds the FMUs (`cargo xtask fmu`) and runs the
# Python tests in this directory, in the virtual environment .venv at the
# repository root (scripts/venv.sh creates it on first use, pinned).
set -euo pipefail
cd "$(dirname "$0")/../.."
ROOT=$(pwd)
VENV="$ROOT/.venv"
bash scripts/venv.sh
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
