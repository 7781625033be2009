//! One run across MPI's ranks (cargo feature `mpi`; `mpiexec` from MPICH):
//! the same answer on any number of ranks, and a failure on one rank that
//! stops every rank with its named error. Built and run by the test
//! command as `cargo test --profile ci --features mpi --test mpi`; without
//! the feature this file is empty.
#![cfg(feature = "mpi")]

use std::path::PathBuf;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// The program, built with the feature.
const PROGRAM: &str = env!("CARGO_BIN_EXE_meshless-impact");

/// Longer than any case here takes oversubscribed (4 ranks on 2 cores:
/// 13 s measured): a hang fails the test rather than the suite.
const LIMIT: Duration = Duration::from_secs(240);

fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("mi-mpi-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `mpiexec` with `args`, one thread a rank (the ranks share two cores),
/// killed past [`LIMIT`].
fn mpiexec(args: &[&str]) -> Output {
    let start = Instant::now();
    // SIGTERM at the limit, which a rank stuck in a collective cannot
    // act on, then SIGKILL.
    let child = Command::new("timeout")
        .args(["-k", "10"])
        .arg(LIMIT.as_secs().to_string())
        .arg("mpiexec")
        .args(args)
        .env("RAYON_NUM_THREADS", "1")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("mpiexec (MPICH) is installed: scripts/test.sh installs it");
    let output = child.wait_with_output().unwrap();
    assert!(
        start.elapsed() < LIMIT,
        "mpiexec {args:?} ran past {LIMIT:?}: a hang"
    );
    output
}

/// The final JSON of `scene` with `sets` on `ranks` ranks.
fn run(scene: &str, sets: &[&str], ranks: usize, tag: &str) -> serde_json::Value {
    let json = dir().join(format!("{scene}-{ranks}-{tag}.json"));
    let n = ranks.to_string();
    let mut args = vec!["-n", &n, PROGRAM, "run", scene, "-q"];
    for s in sets {
        args.extend(["--set", s]);
    }
    let path = json.to_str().unwrap().to_string();
    args.extend(["--json", &path]);
    let out = mpiexec(&args);
    assert!(
        out.status.success(),
        "{scene} on {ranks} ranks: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap()
}

/// Every value of `a` but the wall time, bit for bit in `b` (the JSON
/// numbers round-trip exactly: serde_json's `float_roundtrip`).
fn same_bits(a: &serde_json::Value, b: &serde_json::Value, what: &str) {
    let (a, b) = (a.as_object().unwrap(), b.as_object().unwrap());
    assert_eq!(a.len(), b.len(), "{what}: the same keys");
    for (k, v) in a {
        if k == "wall_time_s" {
            continue;
        }
        assert_eq!(Some(v), b.get(k), "{what}: `{k}`");
        if let Some(x) = v.as_f64() {
            assert_eq!(
                Some(x.to_bits()),
                b[k].as_f64().map(f64::to_bits),
                "{what}: `{k}`"
            );
        }
    }
}

/// `taylor3d` (4 across, 61 steps, three geometry builds) and `penetration`
/// (quarter, 4 across, to 3 µs) give the same bits on 1, 2, 3 and 4 ranks,
/// and 2 ranks repeat their own bits. The ranks share the MLS shapes'
/// rows, the velocity gradients and the nodal forces; the rest is
/// replicated (src/ranks.rs).
#[test]
fn the_same_bits_on_one_to_four_ranks() {
    let cases: [(&str, &[&str]); 2] = [
        ("taylor3d", &["particles_radial=4", "end_time=5e-6"]),
        (
            "penetration",
            &["particles_radial=4", "symmetry=1", "end_time=3e-6"],
        ),
    ];
    for (scene, sets) in cases {
        let one = run(scene, sets, 1, "a");
        assert!(one["steps"].as_u64().unwrap() > 30, "{scene}: a real run");
        for ranks in [2, 3, 4] {
            let k = run(scene, sets, ranks, "a");
            same_bits(&one, &k, &format!("{scene}: 1 against {ranks} ranks"));
        }
        let again = run(scene, sets, 2, "b");
        same_bits(&one, &again, &format!("{scene}: 2 ranks again"));
    }
}

/// A run that fails on one rank only (rank 1's memory budget is out of
/// range) stops both ranks with that rank's named error and exit status 1,
/// printed once (by rank 0), and writes no outputs.
#[test]
fn a_failure_on_one_rank_stops_every_rank_with_its_error() {
    let json = dir().join("failed.json");
    let path = json.to_str().unwrap().to_string();
    let run = [
        PROGRAM,
        "run",
        "taylor3d",
        "-q",
        "--set",
        "particles_radial=4",
        "--json",
        &path,
    ];
    let mut args = vec!["-n", "1"];
    args.extend(run);
    args.extend([":", "-n", "1", "-env", "MI_MEMORY_BUDGET", "1K"]);
    args.extend(run);
    let out = mpiexec(&args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert_eq!(
        err.matches("error: parameter `MI_MEMORY_BUDGET` = 1024 is out of range")
            .count(),
        1,
        "{err}"
    );
    assert!(err.contains("(rank 1)"), "{err}");
    assert!(!json.exists(), "no output from a failed start");
}

/// A scene whose solver runs on one rank refuses several, by name, on
/// every rank.
#[test]
fn a_scene_on_one_rank_only_refuses_several() {
    let out = mpiexec(&["-n", "2", PROGRAM, "run", "noh", "-q"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("scene `noh`: this solver runs on one rank only, not on 2"),
        "{err}"
    );
}
