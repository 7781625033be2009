#!/usr/bin/env bash
# Heavy validation, beyond the test command; every check asserts the
# criteria of VALIDATION.md ("Right by default" and the sections it cites).
# About 35 minutes on two cores, plus 155 s for the five checks moved here
# from the test command on 2026-11-28 (measured together, ci profile):
# - the default scheme (large_strain) in 2-D: test 7 and the Wilkins bar at
#   20, 31 and 41 particles across (lengths within 1 %, the finest two faces
#   within 2 %), test 7 at 600 m/s, the soft and near-melt rods and the
#   copper and aluminium shots to rest with the energy within 5 %; the speed
#   ladder and test 7 at 800 m/s at 10 across, to rest;
# - the paper's scheme on Table 1 (lengths within 5 %, faces within 10 %);
# - the default scheme in 3-D: test 7 at 6, 8 and 10 nodes across (length
#   within 1 % of the experiment, face within 3 % of LS-DYNA's converged
#   10.62 mm, the finest two faces within 2 %), the Wilkins bar at 8 and
#   11 across, and on the staggered lattice against its references, the
#   conforming gradients against the axisymmetric solver, and the AISI 310
#   rod in 3-D against the axisymmetric solver;
# - the boundary costs at 10^6 particles (an FMU output read, a C field
#   read, the FMU state; about a minute and 4 GB), whose figures are in
#   BENCHMARKS.md;
# - the seed's penetration case at the default 6 nodes across (about 90 s),
#   its residual velocity within 10 % of the seed's;
# - kill at random (scripts/kill_restart.py, about 10 s): the penetration
#   case killed 20 times and sent SIGTERM once, restarted each time, ends
#   on the uninterrupted run's outputs byte for byte, every file whole
#   after every kill.
# Every step runs even when an earlier one fails; the failed steps are
# listed at the end and the exit status is 1 if any failed.
set -uo pipefail
cd "$(dirname "$0")/.."
# The cargo profile of the runs: `release` by default; MI_VALIDATE_PROFILE=ci
# runs the same checks on the test command's build (the same bits, the
# golden test's promise; 10 % slower, and no second build of everything).
profile=${MI_VALIDATE_PROFILE:-release}
failed=()
step() {
  echo "== $*"
  "$@" || failed+=("$*")
}
step cargo test --profile "$profile" --test suite taylor:: -- --ignored --nocapture
step cargo test --profile "$profile" --test suite taylor3d:: -- --ignored --nocapture
step cargo test --profile "$profile" --test suite penetration::the_seed_case_at_the_default_resolution -- --ignored --nocapture
step cargo test --profile "$profile" --test boundary -- --ignored --nocapture
step cargo test --profile "$profile" --test suite mlpg_solver::the_staggered_wilkins_bar_under_refinement -- --ignored --nocapture
step cargo test --profile "$profile" --test suite mlpg_solver::the_wilkins_bar_in_3d_meets_its_references_on_the_staggered_lattice -- --ignored --nocapture
step cargo test --profile "$profile" --test suite mlpg_solver::conforming_gradients_bring_the_wilkins_bar_to_the_axisymmetric_solver -- --ignored --nocapture
step cargo build --profile "$profile" --bin meshless-impact
step python3 scripts/kill_restart.py "target/$profile/meshless-impact"
if [ ${#failed[@]} -gt 0 ]; then
  echo "== failed:"
  printf '  %s\n' "${failed[@]}"
  exit 1
fi
echo "== validation passed"
