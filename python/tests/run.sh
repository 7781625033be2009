#!/usr/bin/env bash
# The Python package's checks: installs python/ into the virtual environment
# .venv (scripts/venv.sh) with pip and maturin, and runs its pytest tests.
#
# With MI_PROFILE set (the test command: `ci`), maturin builds in that
# profile into the workspace's target/, without build isolation: after the
# test command's `cargo test`, whose build resolved the workspace's features
# (the root Cargo.toml's default-members, python/Cargo.toml), the core and
# every dependency are already compiled, and only the extension is linked.
# Otherwise pip builds as a user's `pip install ./python` does (release).
set -euo pipefail
cd "$(dirname "$0")/../.."
VENV="$PWD/.venv"
bash scripts/venv.sh
start=$(date +%s)
if [ -n "${MI_PROFILE:-}" ]; then
  echo "== pip install ./python (maturin, profile $MI_PROFILE, on the tests' build)"
  PATH="$VENV/bin:$PATH" MATURIN_PEP517_ARGS="--profile $MI_PROFILE" CARGO_TARGET_DIR="$PWD/target" \
    "$VENV/bin/pip" install --quiet --no-build-isolation --no-deps --force-reinstall ./python
else
  echo "== pip install ./python"
  PATH="$VENV/bin:$PATH" "$VENV/bin/pip" install --quiet --force-reinstall ./python
fi
echo "(installed in $(( $(date +%s) - start )) s)"
echo "== pytest python/tests"
PATH="$VENV/bin:$PATH" "$VENV/bin/python" -m pytest -q -p no:cacheprovider python/tests "$@"
