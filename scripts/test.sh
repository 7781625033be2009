#!/usr/bin/env bash
# The whole test suite: formatting, lints, the doc links, Rust unit and
# integration tests (release-optimised physics), the C examples, the fmpy
# checks and the Python package's tests. Installs what it needs; run from
# anywhere.
#
# `bash scripts/test.sh --quick`: the fast tier for the edit-compile-test
# loop (formatting, the unit tests, and the golden bits, saved states,
# plate impact, the C ABI's boundary and the reference pages' drift), not a
# substitute for the whole suite, which CI runs.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "${1:-}" = "--quick" ]; then
  echo "== quick tier: cargo fmt --check, unit tests, golden, state, plate impact, capi, reference"
  cargo fmt --all -- --check
  cargo test --profile ci --lib
  cargo test --profile ci --test suite -- golden:: state:: plate_impact:: capi:: reference::
  echo "== quick tier passed (the whole suite: bash scripts/test.sh)"
  exit 0
fi

echo "== cargo fmt --check"
cargo fmt --all -- --check
# The Python virtual environment (.venv, scripts/venv.sh) is made in the
# background while cargo compiles: its downloads take a minute of mostly
# waiting. The FMU step waits for it. Its interpreter is made here first:
# every cargo build names it to pyo3 as maturin does when it builds the
# extension for it (python/tests/run.sh), so that pyo3's build
# configuration is the same in every build and maturin finds the
# extension built (measured: a 5.6 s install, against 18.5 s when maturin
# compiled pyo3 again).
[ -x .venv/bin/python3 ] || python3 -m venv .venv
export PYO3_PYTHON="$PWD/.venv/bin/python3"
export PYTHON_SYS_EXECUTABLE="$PYO3_PYTHON" PYO3_BUILD_EXTENSION_MODULE=1
PYO3_ENVIRONMENT_SIGNATURE=$("$PYO3_PYTHON" -c 'import platform, sys
print(f"{platform.python_implementation().lower()}-{sys.version_info[0]}.{sys.version_info[1]}-{64 if sys.maxsize > 2**32 else 32}bit")')
export PYO3_ENVIRONMENT_SIGNATURE
venv_log=$(mktemp)
# ecos, one of the FMI hosts of the FMU checks (tests/fmu/test_hosts.py),
# loads Debian's libtbb12 (measured: 6 s with `apt-get update`), installed
# beside the venv's downloads when missing and the command runs as root.
# MPICH for the run across ranks (cargo feature `mpi`, the last step),
# with libclang for its bindings (measured: 12 s once the lists are read).
debs=()
ldconfig -p | grep -q 'libtbb\.so\.12 ' || debs+=(libtbb12)
dpkg -s mpich libmpich-dev libclang-dev > /dev/null 2>&1 ||
  debs+=(mpich libmpich-dev libclang-dev)
( bash scripts/venv.sh
  if [ ${#debs[@]} -gt 0 ]; then
    echo "== apt-get install ${debs[*]}"
    if [ "$(id -u)" = 0 ]; then
      apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${debs[@]}" > /dev/null
    else
      echo "not root: install ${debs[*]} (apt-get install ${debs[*]})"
    fi
  fi ) > "$venv_log" 2>&1 &
venv_pid=$!
# Every step builds with the profile of the tests (`ci`), so that the build
# scripts and procedural macros are compiled once for all of them.
echo "== cargo clippy"
cargo clippy --all-targets --profile ci -- -D warnings
# The library and the program without the report (cargo feature `report`);
# the Python extension keeps its `extension-module`, so that pyo3 is checked
# once for both runs.
cargo clippy --all-targets --profile ci --no-default-features \
  --features meshless-impact-python/extension-module -- -D warnings
echo "== cargo doc (broken or private links fail)"
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --profile ci
echo "== cargo test (profile ci: release optimisation, fast build)"
# Where the processor has AVX-512, the tests that compare its copy of the hot
# loops with the portable one fail rather than skip if they cannot run it.
if grep -qw avx512f /proc/cpuinfo 2>/dev/null && grep -qw avx512vl /proc/cpuinfo; then
  export MI_REQUIRE_AVX512=1
  echo "(AVX-512 here: MI_REQUIRE_AVX512=1)"
fi
# The fuzzer runs for a fixed time (MI_FUZZ_SECONDS, default 60) on about
# one core: it runs below beside the C and FMU steps, not here.
# (the benchmarks' harness, criterion's, takes no `--skip`: they run apart).
cargo test --profile ci --lib --bins --tests --examples -- --skip fuzz_the_boundaries
cargo test --profile ci --bench '*'
cargo test --profile ci --doc
fuzz_bin=$(cargo test --profile ci --test fuzz --no-run --message-format=json |
  python3 -c 'import json, sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m.get("executable") and m["target"]["name"] == "fuzz":
        print(m["executable"])')
fuzz_log=$(mktemp)
echo "== fuzzer (beside the C and FMU steps; its log at the end)"
"$fuzz_bin" --nocapture > "$fuzz_log" 2>&1 &
fuzz_pid=$!
trap 'kill $fuzz_pid 2>/dev/null || true' EXIT
# The C examples and the FMUs link the library of the same `ci` build (the
# release optimisation without LTO: the same code, built once; what ships is
# built with `release`).
export MI_PROFILE=ci
# ... and with the tests' features (`--lib --bins --tests`), so that the library the tests
# built is reused rather than compiled once more for the features of a plain
# `cargo build` (the dev-dependencies turn on features of `either`,
# `num-traits` and the host `syn`: 57 s on two cores).
export MI_WITH_TESTS=1
if [ -f examples_c/Makefile ]; then
  echo "== C examples"
  make -j2 -C examples_c test
fi
if ! wait $venv_pid; then
  cat "$venv_log"
  echo "== the Python virtual environment (scripts/venv.sh) or the Debian packages failed"
  exit 1
fi
cat "$venv_log"
if [ -f tests/fmu/run.sh ]; then
  echo "== FMU checks (fmpy)"
  # Packaged by the example that shares the tests' build (xtask's code),
  # not by `cargo xtask fmu`, whose own build of the library and every
  # dependency took 3 min 19 s on two cores.
  cargo build --profile ci --example package_fmus
  export MI_FMU_PACKAGER="$PWD/target/ci/examples/package_fmus"
  bash tests/fmu/run.sh
fi
echo "== fuzzer"
if ! wait $fuzz_pid; then
  cat "$fuzz_log"
  echo "== the fuzzer failed"
  exit 1
fi
trap - EXIT
tail -n 5 "$fuzz_log"
# After the fuzzer, so that the thread-overlap test finds both cores free.
# The extension is built by maturin on the tests' build (MI_PROFILE=ci, the
# workspace's default members: python/tests/run.sh).
echo "== Python package"
bash python/tests/run.sh
# Last, as it builds the library once more with the feature `mpi` (the
# C examples, the FMUs and the Python package above link the one built
# without it): its lints, then the runs across 1 to 4 ranks (tests/mpi.rs).
echo "== MPI (cargo feature mpi: clippy, tests/mpi.rs)"
cargo clippy --all-targets --profile ci --features mpi -- -D warnings
cargo test --profile ci --features mpi --test mpi
echo "== all tests passed"
