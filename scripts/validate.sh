#!/usr/bin/env bash
# Heavy validation, beyond the test command: the refinement study of test 7
# (20, 31 and 41 particles across the radius), run as the ignored integration
# tests (about 2 minutes on two cores), and test 7 at 600 m/s with the
# large-strain scheme (173 s on one thread); House test 7 in 3-D (taylor3d) at
# 11 nodes across the radius (about 6 minutes on two shared cores; its Df is
# outside the issue's 8 %, VALIDATION.md) and the seed's AISI 310 rod at 11
# across against the axisymmetric solver at 41 (a few minutes); then the
# boundary costs at 10^6 particles (an FMU output read, a C field read, the
# FMU state; about a minute and 4 GB), whose figures are in BENCHMARKS.md;
# the seed's penetration case at the default 6 nodes across (about 90 s),
# its residual velocity within 10 % of the seed's; and the Wilkins copper bar
# in 3-D as its scene file sets it at 8 and 11 nodes across (about 9 minutes
# on two cores), within 2 % in length and 5 % in face radius of the converged
# references.
# Every step runs even when an earlier one fails (test 7 in 3-D at 11 across
# fails on its Df, as VALIDATION.md says); the failed steps are listed at the
# end and the exit status is 1 if any failed.
set -uo pipefail
cd "$(dirname "$0")/.."
failed=()
step() {
  echo "== $*"
  "$@" || failed+=("$*")
}
step cargo test --release --test taylor -- --ignored --nocapture
step cargo test --release --test taylor3d -- --ignored --nocapture
step cargo test --release --test penetration the_seed_case_at_the_default_resolution -- --ignored --nocapture
step cargo test --release --test boundary -- --ignored --nocapture
step cargo test --release --test mlpg_solver the_staggered_wilkins_bar_under_refinement -- --ignored --nocapture
if [ ${#failed[@]} -gt 0 ]; then
  echo "== failed:"
  printf '  %s\n' "${failed[@]}"
  exit 1
fi
echo "== validation passed"
