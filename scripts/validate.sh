#!/usr/bin/env bash
# Heavy validation, beyond the test command: the refinement study of test 7
# (20, 31 and 41 particles across the radius), run as the ignored integration
# tests. About 2 minutes on two cores.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --release --test taylor -- --ignored --nocapture
