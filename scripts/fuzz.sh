#!/usr/bin/env bash
# The boundary fuzzer of tests/fuzz.rs for longer than the test command's
# 60 s, over every scene, material choice and FMU of the registry:
# parameters, extreme physics, TOML scene texts, saved states (edited, and
# loaded across scenes), C ABI call orders and FMI 3.0 / FMI 2.0 call orders
# through the FMU functions, each case under a time limit. Usage:
# bash scripts/fuzz.sh [SECONDS] [SEED] (default 600 s from seed 2).
# Prints the case counts by interface and by scene; fails on any crash,
# hang, NaN on success, undocumented error or status, or FMU call the
# standard forbids that does not return Error.
# Then 1,000 load/unload cycles of every FMU, FMI 3.0 and FMI 2.0, with flat
# memory (tests/fmu/load_cycles.py: the RSS may grow by at most 4 MiB and no
# thread may be left over 950 cycles after a warm-up of 50; 92 s for the
# seven FMUs on the 2-core machine, 2026-11-29).
set -euo pipefail
cd "$(dirname "$0")/.."
MI_FUZZ_SECONDS="${1:-600}" MI_FUZZ_SEED="${2:-2}" \
  cargo test --release --test fuzz -- --nocapture
echo "== FMU load/unload cycles"
# run.sh creates the virtual environment (its pinned fmpy) and builds the
# FMUs (`cargo xtask fmu`); --collect-only runs none of its tests.
bash tests/fmu/run.sh --collect-only -q > /dev/null
.venv/bin/python tests/fmu/load_cycles.py --cycles 1000 --warmup 50
