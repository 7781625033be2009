#!/usr/bin/env bash
# The boundary fuzzer of tests/fuzz.rs for longer than the test command's
# 60 s: parameters, TOML scene texts, saved states, C ABI call orders and
# FMI 3.0 / FMI 2.0 call orders through the FMU functions, each case under a
# time limit. Usage: bash scripts/fuzz.sh [SECONDS] [SEED] (default 600 s
# from seed 2). Prints the case counts; fails on any crash, hang, NaN on
# success, undocumented error or status, or FMU call the standard forbids
# that does not return Error.
set -euo pipefail
cd "$(dirname "$0")/.."
MI_FUZZ_SECONDS="${1:-600}" MI_FUZZ_SEED="${2:-2}" \
  cargo test --release --test fuzz -- --nocapture
