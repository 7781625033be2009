//! One run across MPI's ranks (cargo feature `mpi`; `mpiexec` from MPICH):
//! the same answer on any number of ranks, and a failure on one rank that
//! stops every rank with its named error. Built and run by the test
//! command as `cargo test --profile ci --features mpi --test mpi`; without
//! the feature this file is empty.
#![cfg(feature = "mpi")]

use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// The program, built with the feature.
const PROGRAM: &str = env!("CARGO_BIN_EXE_meshless-impact");

/// Longer than any case here takes oversubscribed (4 ranks on 2 cores:
/// 13 s measured): a hang fails the test rather than the suite.
const LIMIT: Duration = Duration::from_secs(240);

#[path = "../src/test_dir.rs"]
mod test_dir;
use test_dir::TestDir;

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
    let scratch = TestDir::new(&format!("mpi-{scene}-{ranks}-{tag}"));
    let json = scratch.join("out.json");
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
/// and 2 ranks repeat their own bits. The ranks share the passes over the
/// nodes; the state is replicated (src/ranks.rs).
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

/// The plate's nodes in the bisection's order (`plate_node_order=1`, the
/// order for runs on several ranks: each rank's range of the nodes is a
/// compact piece of the plate, and each rank holds only the shapes' rows
/// its passes read) give the same bits on 1, 2 and 3 ranks; the order
/// changes the sums' order only, so the residual velocity is the rings'
/// order's to round-off grown over the run.
#[test]
fn the_plate_in_bisection_order_gives_the_same_bits_on_one_to_three_ranks() {
    let sets: &[&str] = &[
        "particles_radial=4",
        "symmetry=1",
        "end_time=3e-6",
        "plate_node_order=1",
    ];
    let one = run("penetration", sets, 1, "bisection");
    for ranks in [2, 3] {
        let k = run("penetration", sets, ranks, "bisection");
        same_bits(&one, &k, &format!("bisection: 1 against {ranks} ranks"));
    }
    let rings = run("penetration", &sets[..3], 1, "rings");
    let v = |j: &serde_json::Value| j["projectile_velocity"].as_f64().unwrap();
    let gap = (v(&one) / v(&rings) - 1.0).abs();
    assert!(
        gap > 0.0 && gap < ORDER_GAP,
        "{} against {}",
        v(&one),
        v(&rings)
    );
}

/// The largest relative difference of the residual velocity between the
/// plate's two orders at 3 µs (4 across, quarter, 41 steps) taken as
/// round-off grown over the run: measured 7.5e-10 (1305.9734633201192
/// against 1305.973464299563 m/s; VALIDATION.md).
const ORDER_GAP: f64 = 1e-8;

/// The JH-2 plate (`plate_model=1`; its damage and bulking are each
/// point's variables, which the ranks exchange) gives the same bits on 1
/// and 2 ranks, the plate damaged. Before its variables were exchanged,
/// 2 ranks gave a damaged fraction of 0.098 against 0.185.
#[test]
fn the_jh2_plate_gives_the_same_bits_on_two_ranks() {
    let sets: &[&str] = &[
        "particles_radial=4",
        "symmetry=1",
        "plate_model=1",
        "end_time=5e-6",
    ];
    let one = run("penetration", sets, 1, "jh2");
    assert!(one["damaged_fraction"].as_f64().unwrap() > 0.05, "{one}");
    let two = run("penetration", sets, 2, "jh2");
    same_bits(&one, &two, "JH-2: 1 against 2 ranks");
}

/// Cracks that shield their neighbours (`plate_shield_radius`; the zones
/// are built from every node's state, which each rank holds) give the same
/// bits on 1 and 2 ranks, and shield: the damage differs from the run
/// without them.
#[test]
fn shielding_cracks_give_the_same_bits_on_two_ranks() {
    let plain: &[&str] = &["particles_radial=4", "symmetry=1", "end_time=5e-6"];
    let sets: &[&str] = &[
        "particles_radial=4",
        "symmetry=1",
        "end_time=5e-6",
        "plate_shield_radius=0.005",
    ];
    let one = run("penetration", sets, 1, "shield");
    let unshielded = run("penetration", plain, 1, "unshielded");
    let damaged = |v: &serde_json::Value| v["damaged_fraction"].as_f64().unwrap();
    assert!(damaged(&one) > 0.05, "{one}");
    assert_ne!(damaged(&one), damaged(&unshielded));
    let two = run("penetration", sets, 2, "shield");
    same_bits(&one, &two, "shielding: 1 against 2 ranks");
}

/// A run that fails on one rank only (rank 1's memory budget is out of
/// range) stops both ranks with that rank's named error and exit status 1,
/// printed once (by rank 0), and writes no outputs.
#[test]
fn a_failure_on_one_rank_stops_every_rank_with_its_error() {
    let scratch = TestDir::new("mpi-failed");
    let json = scratch.join("failed.json");
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

/// A checkpoint written mid-run on two ranks (every 37 steps: off the
/// histories' records and the 10 steps between the splits of the
/// material pass, where the ranks keep the damage variables apart)
/// continues on one rank to the bits of the run never stopped: the ranks
/// share the state before rank 0 saves it. Without that share the
/// restarted run's observables differed (measured: the projectile
/// velocity 1177.5999 against 1177.5975 m/s).
#[test]
fn a_checkpoint_of_two_ranks_restarts_to_the_bits_of_one() {
    let sets = ["particles_radial=3", "symmetry=1", "end_time=8e-6"];
    let one = run("penetration", &sets, 1, "whole");
    let scratch = TestDir::new("mpi-checkpoint");
    let checkpoint = scratch.join("two.ckpt");
    let path = checkpoint.to_str().unwrap().to_string();
    let mut args = vec!["-n", "2", PROGRAM, "run", "penetration", "-q"];
    for s in &sets {
        args.extend(["--set", s]);
    }
    args.extend(["--checkpoint", &path, "--checkpoint-steps", "37"]);
    let out = mpiexec(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json = scratch.join("restarted.json");
    let restarted = json.to_str().unwrap().to_string();
    let out = mpiexec(&[
        "-n",
        "1",
        PROGRAM,
        "run",
        "-q",
        "--restart",
        &path,
        "--json",
        &restarted,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let again: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    same_bits(&one, &again, "restarted from two ranks' checkpoint");
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

/// `taylor3d` at 3 across to 1 µs on 2 ranks, with `mpiexec`'s `options`
/// before the program and the run's `extra` arguments after it: its
/// stderr, the run having succeeded.
fn small_taylor3d_on_two(options: &[&str], extra: &[&str]) -> String {
    let mut args = options.to_vec();
    args.extend(["-n", "2", PROGRAM, "run", "taylor3d", "-q"]);
    args.extend(["--set", "particles_radial=3", "--set", "end_time=1e-6"]);
    args.extend(extra);
    let out = mpiexec(&args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{err}");
    err
}

/// With `MI_MPI_STATS=2` each rank books its collectives by the line of
/// the program that called them: the lines add up to the rank's totals of
/// calls and bytes, and the shared passes are named by their own lines
/// (the material's fields' halo, the nodal forces').
#[test]
fn the_collectives_are_booked_by_the_lines_that_called_them() {
    let err = small_taylor3d_on_two(&["-genv", "MI_MPI_STATS", "2"], &[]);
    let number = |w: &str| -> u64 { w.parse().unwrap_or_else(|_| panic!("{w}: {err}")) };
    for rank in 0..2 {
        let head = format!("mpi: rank {rank} of 2: ");
        let total = err
            .lines()
            .find_map(|l| l.strip_prefix(&head))
            .unwrap_or_else(|| panic!("no totals of rank {rank}: {err}"));
        let words: Vec<&str> = total.split_whitespace().collect();
        let (calls, bytes) = (number(words[0]), number(words[3]));
        let mine = format!("mpi: rank {rank}: ");
        let books: Vec<(&str, u64, u64)> = err
            .lines()
            .filter_map(|l| l.strip_prefix(&mine))
            .map(|l| {
                let (line, rest) = l.split_once(": ").expect(l);
                let words: Vec<&str> = rest.split_whitespace().collect();
                (line, number(words[0]), number(words[2]))
            })
            .collect();
        assert_eq!(books.iter().map(|b| b.1).sum::<u64>(), calls, "{err}");
        assert_eq!(books.iter().map(|b| b.2).sum::<u64>(), bytes, "{err}");
        // (A rank may receive nothing at the material's exchange: at 3
        // across its points are one block, which one rank steps.)
        for file in ["src/solver/mlpg3d/halo.rs:", "src/approx/nodal.rs:"] {
            assert!(
                books.iter().any(|b| b.0.starts_with(file) && b.1 > 0),
                "rank {rank}: no gather booked at {file}: {err}"
            );
        }
    }
}

/// `--phases` on 2 ranks: rank 0 prints both ranks' tables, whole and in
/// rank order (each rank printing its own interleaved them on the
/// terminal: `phases of rank 0 of 2phases of rank 1 of 2:`), each adding
/// up to its total as the one-rank table does.
#[test]
fn the_phases_of_every_rank_are_printed_whole_in_rank_order() {
    let err = small_taylor3d_on_two(&[], &["--phases"]);
    let lines: Vec<&str> = err.lines().collect();
    let heads: Vec<usize> = (0..lines.len())
        .filter(|&k| lines[k].starts_with("phases of rank"))
        .collect();
    assert_eq!(heads.len(), 2, "{err}");
    for (rank, &at) in heads.iter().enumerate() {
        assert_eq!(lines[at], format!("phases of rank {rank} of 2:"), "{err}");
        // The table's rows up to its total: seconds that add up to it.
        let rows: Vec<&str> = lines[at + 1..]
            .iter()
            .take_while(|l| !l.starts_with("phases of rank"))
            .copied()
            .collect();
        // The number before the first word `s`.
        let seconds = |l: &str| -> f64 {
            let words: Vec<&str> = l.split_whitespace().collect();
            let at = words.iter().position(|w| *w == "s").expect(l);
            words[at - 1].parse().expect(l)
        };
        let total = rows.iter().find(|l| l.starts_with("total")).expect(&err);
        let sum: f64 = rows
            .iter()
            .take_while(|l| !l.starts_with("total"))
            .map(|l| seconds(l))
            .sum();
        // Each row is rounded to 1 ms.
        assert!(
            (sum - seconds(total)).abs() <= 0.001 * rows.len() as f64,
            "rank {rank}: rows add up to {sum} s against {total}"
        );
    }
}

/// The points (x, y, z interleaved) and the point arrays (name, values) of
/// a `.vtu` or `.pvtu` file as vtkio's reader sees it, the pieces of a
/// parallel file loaded and joined in their order.
fn read_vtk(path: &std::path::Path) -> (Vec<f64>, Vec<(String, Vec<f64>)>) {
    use vtkio::model::{Attribute, DataSet, Piece};
    let mut vtk = vtkio::Vtk::import(path).unwrap();
    vtk.load_all_pieces().unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("{}: not an unstructured grid", path.display());
    };
    let (mut points, mut arrays) = (Vec::new(), Vec::<(String, Vec<f64>)>::new());
    for piece in pieces {
        let Piece::Inline(piece) = piece else {
            panic!("{}: a piece not loaded", path.display());
        };
        points.extend(piece.points.cast_into::<f64>().unwrap());
        for (k, a) in piece.data.point.into_iter().enumerate() {
            let Attribute::DataArray(a) = a else {
                panic!("not a data array");
            };
            let values: Vec<f64> = a.data.cast_into().unwrap();
            match arrays.get_mut(k) {
                Some((name, all)) => {
                    assert_eq!(*name, a.name);
                    all.extend(values);
                }
                None => arrays.push((a.name.clone(), values)),
            }
        }
    }
    (points, arrays)
}

/// On two ranks each snapshot is a piece per rank and a `.pvtu` that
/// joins them: read back by vtkio's reader, the joined pieces hold the
/// one-rank snapshot's points and fields, in order, bit for bit; the
/// collection lists the `.pvtu` files. So for the ceramic plate's damage
/// fields mid-run, whose variables the ranks keep apart between steps
/// (shared before each snapshot): some node's damage has grown by then.
#[test]
fn the_vtk_pieces_join_into_the_snapshot_of_one_rank() {
    vtk_pieces_join(
        "taylor3d",
        &["particles_radial=3", "end_time=2e-6"],
        "0,1e-6",
    );
    vtk_pieces_join(
        "penetration",
        &["particles_radial=3", "symmetry=1", "end_time=8e-6"],
        "0,5.1e-6",
    );
}

/// [`the_vtk_pieces_join_into_the_snapshot_of_one_rank`] for `scene`.
fn vtk_pieces_join(scene: &str, sets: &[&str], times: &str) {
    let scratch = TestDir::new(&format!("mpi-vtk-{scene}"));
    let mut written = Vec::new();
    for ranks in [1, 2] {
        let vtk = scratch.join(format!("{ranks}"));
        let n = ranks.to_string();
        let path = vtk.to_str().unwrap().to_string();
        let mut args = vec!["-n", &n, PROGRAM, "run", scene, "-q"];
        for s in sets {
            args.extend(["--set", s]);
        }
        args.extend(["--vtk-dir", &path, "--vtk-times", times]);
        let out = mpiexec(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        written.push(vtk);
    }
    let pvd = std::fs::read_to_string(written[1].join("particles.pvd")).unwrap();
    for k in 0..3 {
        let one = read_vtk(&written[0].join(format!("particles_{k:04}.vtu")));
        let two = written[1].join(format!("particles_{k:04}.pvtu"));
        assert!(
            pvd.contains(&format!("file=\"particles_{k:04}.pvtu\"")),
            "{pvd}"
        );
        for r in 0..2 {
            assert!(
                written[1]
                    .join(format!("particles_{k:04}_{r}.vtu"))
                    .exists()
            );
        }
        let two = read_vtk(&two);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert!(!one.0.is_empty());
        assert_eq!(bits(&one.0), bits(&two.0), "snapshot {k}: points");
        assert_eq!(one.1.len(), two.1.len(), "snapshot {k}: arrays");
        for ((a, x), (b, y)) in one.1.iter().zip(&two.1) {
            assert_eq!(a, b);
            assert_eq!(bits(x), bits(y), "snapshot {k}: `{a}`");
            if scene == "penetration" && a == "damage" && k == 1 {
                let seed = 1.83e10 * 0.58e-6_f64.powi(3);
                assert!(
                    x.iter().any(|&d| d > 10.0 * seed),
                    "{scene}: no damage grew"
                );
            }
        }
    }
}

/// An output that cannot be written on one rank only (its `--vtk-dir`
/// under a file) stops every rank before the run, with that rank's
/// error, printed once; no rank waits for it.
#[test]
fn an_output_that_fails_on_one_rank_stops_every_rank() {
    let scratch = TestDir::new("mpi-vtk-good");
    let good = scratch.join("vtk");
    let good = good.to_str().unwrap();
    let run = |vtk| {
        let set = ["--set", "particles_radial=3", "--vtk-dir", vtk];
        [PROGRAM, "run", "taylor3d", "-q"].into_iter().chain(set)
    };
    let args: Vec<&str> = ["-n", "1"]
        .into_iter()
        .chain(run(good))
        .chain([":", "-n", "1"])
        .chain(run("/dev/null/vtk"))
        .collect();
    let out = mpiexec(&args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert_eq!(
        err.matches("error: --vtk-dir /dev/null/vtk").count(),
        1,
        "{err}"
    );
    assert!(err.contains("(rank 1)"), "{err}");
}
