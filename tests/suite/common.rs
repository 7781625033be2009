//! Helpers shared by the integration tests.
#![allow(dead_code)]

use meshless_impact::{Scene, Simulation};

/// Runs a scene to its end condition and returns the simulation.
pub fn run(mut scene: Scene, sets: &[(&str, f64)]) -> Simulation {
    for (k, v) in sets {
        scene.set(k, *v).unwrap();
    }
    let mut sim = Simulation::new(scene).unwrap();
    sim.run().unwrap();
    sim
}

/// First recorded time at which the tail velocity falls below 99% of the
/// impact speed: when the tail starts to slow down.
pub fn tail_slowdown_time(sim: &Simulation) -> f64 {
    let v0 = sim.scene().get("impact_speed").unwrap();
    let h = sim.history();
    let tail = h.column("tail_velocity").unwrap();
    let k = tail
        .iter()
        .position(|&v| v < 0.99 * v0)
        .expect("tail slows down");
    h.times[k]
}

/// Relative error in percent.
pub fn pct(value: f64, reference: f64) -> f64 {
    100.0 * (value - reference) / reference
}

/// The data sets of a ParaView collection (`.pvd`): (time, file) each, in
/// order.
pub fn pvd_datasets(path: &std::path::Path) -> Vec<(f64, String)> {
    let pvd = std::fs::read_to_string(path).unwrap();
    let mut reader = quick_xml::Reader::from_str(&pvd);
    let mut sets = Vec::new();
    loop {
        match reader.read_event().unwrap() {
            quick_xml::events::Event::Empty(e) if e.name().as_ref() == b"DataSet" => {
                let attr = |k: &str| {
                    e.try_get_attribute(k)
                        .unwrap()
                        .unwrap()
                        .unescape_value()
                        .unwrap()
                        .into_owned()
                };
                sets.push((attr("timestep").parse::<f64>().unwrap(), attr("file")));
            }
            quick_xml::events::Event::Eof => break,
            _ => {}
        }
    }
    sets
}

/// The outputs of one command-line run: `--json`, `--csv` and `--vtk-dir`.
pub struct CliOutputs {
    /// The final observables (JSON).
    pub json: std::path::PathBuf,
    /// The histories (CSV).
    pub csv: std::path::PathBuf,
    /// The snapshots and their collection `particles.pvd`.
    pub vtk: std::path::PathBuf,
}

/// Runs `meshless-impact ARGS` with `--json`, `--csv` and `--vtk-dir`
/// into `dir` (snapshots at `vtk_times` and at the end) and asserts that it
/// succeeded.
pub fn run_cli_with_outputs(args: &[&str], dir: &std::path::Path, vtk_times: &str) -> CliOutputs {
    let o = CliOutputs {
        json: dir.join("out.json"),
        csv: dir.join("hist.csv"),
        vtk: dir.join("vtk"),
    };
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_meshless-impact"))
        .args(args)
        .arg("--json")
        .arg(&o.json)
        .arg("--csv")
        .arg(&o.csv)
        .arg("--vtk-dir")
        .arg(&o.vtk)
        .args(["--vtk-times", vtk_times])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    o
}

/// Runs the program with `args`, asserts that it succeeded (printing its
/// stderr if not) and returns its stdout.
pub fn cli_stdout<S: AsRef<std::ffi::OsStr>>(args: impl IntoIterator<Item = S>) -> String {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_meshless-impact"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Asserts that `run` gives the same result on one thread and on two.
pub fn same_on_one_thread_and_two<T: PartialEq + Send>(run: impl Fn() -> T + Sync) {
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(&run)
    };
    assert!(on(1) == on(2), "the thread count changed the result");
}

/// The largest |mean normal stress + pressure| over the nodes of a run, and
/// the largest stress component: the stress is `s − P I` with a trace-free
/// deviator `s`, so the first is round-off (`components` is 4 in 2-D, RR,
/// ZZ, TT, RZ; 6 in 3-D, xx, yy, zz, xy, yz, zx).
pub fn mean_stress_residual(sim: &Simulation, components: usize) -> (f64, f64) {
    let stress = sim.field("stress").unwrap();
    let pressure = sim.field("pressure").unwrap();
    let mut worst = (0.0f64, 0.0f64);
    for (s, p) in stress.chunks(components).zip(&pressure) {
        worst.0 = worst.0.max(((s[0] + s[1] + s[2]) / 3.0 + p).abs());
        worst.1 = s.iter().fold(worst.1, |m, x| m.max(x.abs()));
    }
    worst
}

/// The bits of everything a run shows: its clock, every observable, every
/// particle field and the recorded histories.
pub fn bits(s: &Simulation) -> Vec<u64> {
    let mut v = vec![s.time(), s.steps() as f64];
    v.extend(s.observables());
    for f in s.field_specs() {
        v.extend(s.field(f.name).unwrap());
    }
    v.extend(&s.history().times);
    v.extend(&s.history().values);
    v.iter().map(|x| x.to_bits()).collect()
}

/// The program, to run with arguments.
pub fn bin() -> std::process::Command {
    std::process::Command::new(env!("CARGO_BIN_EXE_meshless-impact"))
}

#[path = "../../src/test_dir.rs"]
mod test_dir;
pub(crate) use test_dir::TestDir;

/// A fresh, empty scratch folder for one test of the file `file`, removed
/// when the test passes.
pub(crate) fn scratch(file: &str, test: &str) -> TestDir {
    TestDir::new(&format!("{file}-{test}"))
}

/// A process's stderr as text.
pub fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The bits of every observable and every node field of a run.
pub fn all_bits(s: &Simulation) -> Vec<u64> {
    let mut v = s.observables();
    for f in s.field_specs() {
        v.extend(s.field(f.name).unwrap());
    }
    v.iter().map(|x| x.to_bits()).collect()
}
