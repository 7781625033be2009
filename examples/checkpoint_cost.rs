//! The cost of one checkpoint (`meshless_impact::checkpoint::save`, and
//! the load back) of the penetration scene at a given size, after one
//! step: `cargo run --release --example checkpoint_cost -- ACROSS [SYMMETRY]`
//! prints the nodes, the file's size and the seconds of the save and the
//! load (BENCHMARKS.md, "Checkpoints"); `parts` adds the time of a copy
//! of the run, of the JSON text alone and of its checksum.

use meshless_impact::{Scene, Simulation};
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let across: f64 = args.next().and_then(|a| a.parse().ok()).unwrap_or(6.0);
    let symmetry: f64 = args.next().and_then(|a| a.parse().ok()).unwrap_or(0.0);
    let mut scene = Scene::builtin("penetration").unwrap();
    scene.set("particles_radial", across).unwrap();
    scene.set("symmetry", symmetry).unwrap();
    let t = Instant::now();
    let mut sim = Simulation::new(scene).unwrap();
    let setup = t.elapsed().as_secs_f64();
    let t = Instant::now();
    sim.step().unwrap();
    let step = t.elapsed().as_secs_f64();
    let path = std::env::temp_dir().join(format!("mi-cost-{}.ckpt", std::process::id()));
    let mut saves = Vec::new();
    for _ in 0..3 {
        let t = Instant::now();
        meshless_impact::checkpoint::save(&path, &sim, &serde_json::Value::Null).unwrap();
        saves.push(t.elapsed().as_secs_f64());
    }
    let bytes = std::fs::metadata(&path).unwrap().len();
    let t = Instant::now();
    let (back, _) = meshless_impact::checkpoint::load(&path).unwrap();
    let load = t.elapsed().as_secs_f64();
    assert_eq!(back.steps(), sim.steps());
    std::fs::remove_file(&path).ok();
    if std::env::args().nth(3).as_deref() == Some("parts") {
        parts(&sim);
    }
    saves.sort_by(f64::total_cmp);
    println!(
        "across {across} symmetry {symmetry}: nodes {}, setup {setup:.2} s, first step {step:.3} s, \
         checkpoint {:.1} MB, save {:.3} s (median of 3), load {load:.3} s",
        sim.particles(),
        bytes as f64 / 1e6,
        saves[1]
    );
}

/// The parts of a save: a copy of the run (as a writer on another
/// thread would need), the JSON text alone, its checksum.
fn parts(sim: &Simulation) {
    let t = Instant::now();
    let copy = sim.clone();
    let clone = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let text = serde_json::to_vec(&copy).unwrap();
    let json = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let crc = crc32fast::hash(&text);
    let sum = t.elapsed().as_secs_f64();
    println!(
        "clone {clone:.3} s, JSON text {json:.3} s ({} MB), CRC {sum:.3} s ({crc:x})",
        text.len() / 1000000
    );
}
