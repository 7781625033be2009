//! Explorations of the heap, counted by the counting allocator
//! (`tests/heap/mod.rs`, this binary's global allocator): a scene's peak
//! per node against its memory estimate (BENCHMARKS.md, the memory rows;
//! the bounds that `tests/mlpg_alloc.rs` asserts), and `taylor3d`'s heap by
//! part.

use crate::heap;
use meshless_impact::{Scene, Simulation, Taylor3dParams};

/// Exploration: the built-in scene `MI_SCENE` (default `taylor3d`) with the
/// overrides `MI_SET` ("name=value,..."), run to its end (or `STEPS`
/// steps) through [`Simulation`] as the CLI runs it, its heap counted:
/// the most live at once in the construction and over the run, per node,
/// against the memory budget's estimate ([`Scene::memory_estimate`]); the
/// step in which the peak was reached; and the heap live and the most live
/// within each tenth of the run's time (or
/// 5 µs), to show where the heap grows.
pub fn heap_peak() {
    let name = std::env::var("MI_SCENE").unwrap_or_else(|_| "taylor3d".into());
    let mut scene = Scene::builtin(&name).unwrap();
    for kv in std::env::var("MI_SET").unwrap_or_default().split(',') {
        if let Some((k, v)) = kv.split_once('=') {
            scene.set(k.trim(), v.trim().parse().unwrap()).unwrap();
        }
    }
    let steps: Option<u64> = std::env::var("STEPS").ok().map(|s| s.parse().unwrap());
    // The thread pool first, so that it is in the base.
    rayon::broadcast(|_| ());
    let base = heap::live();
    heap::reset_peak();
    let wall = std::time::Instant::now();
    let mut sim = Simulation::new(scene.clone()).unwrap();
    let construction = heap::peak() - base;
    let n = sim.particles() as f64;
    let kb = |b: u64| b as f64 / n / 1e3;
    let estimate = scene.memory_estimate();
    println!(
        "{name} {}: {} nodes (estimated {:.0}); estimate {:.1} MB ({:.2} kB a node)",
        std::env::var("MI_SET").unwrap_or_default(),
        sim.particles(),
        scene.estimated_nodes(),
        estimate / 1e6,
        estimate / n / 1e3
    );
    println!(
        "construction: most live at once {:.1} MB ({:.2} kB a node), held after it {:.2} kB a node",
        construction as f64 / 1e6,
        kb(construction),
        kb(heap::live() - base)
    );
    // Spans of a tenth of the end time, or of 5 us where the run stops
    // at rest long before its end time.
    let span = (sim.end_time() / 10.0).min(5e-6);
    let (mut top, mut at, mut at_time) = (heap::peak(), 0, 0.0);
    let mut tenth = 1;
    heap::reset_peak();
    let mut in_tenth = 0;
    while !sim.finished() && steps.is_none_or(|s| sim.steps() < s) {
        sim.step().unwrap();
        let now = heap::peak();
        in_tenth = in_tenth.max(now);
        if now > top {
            (top, at, at_time) = (now, sim.steps(), sim.time());
        }
        if sim.time() >= tenth as f64 * span || sim.finished() {
            println!(
                "  to {:7.3} us (step {:5}): live {:6.2} kB a node, most live in the span {:6.2} kB a node",
                sim.time() * 1e6,
                sim.steps(),
                kb(heap::live().saturating_sub(base)),
                kb(in_tenth.saturating_sub(base))
            );
            while sim.time() >= tenth as f64 * span {
                tenth += 1;
            }
            heap::reset_peak();
            in_tenth = 0;
        }
    }
    heap::keep_peak(top);
    let peak = heap::peak() - base;
    println!(
        "most live at once over {} steps to {:.3} us: {:.1} MB, {:.2} kB a node (reached in step {at}, at {:.3} us); \
         estimate / peak {:.2}; {:.1} s",
        sim.steps(),
        sim.time() * 1e6,
        peak as f64 / 1e6,
        kb(peak),
        at_time * 1e6,
        estimate / peak as f64,
        wall.elapsed().as_secs_f64()
    );
    for o in ["rod_length", "mushroom_radius", "projectile_velocity"] {
        if let Some(v) = sim.observable(o) {
            println!("{o} {v}");
        }
    }
}

/// Exploration (was the ignored test `heap_by_part` of
/// `tests/mlpg_alloc.rs`): the heap of `taylor3d` (`PARTICLES_RADIAL`,
/// default 10) by part after its first step, and the most live at once
/// over its first `STEPS` (default 200) steps, which rebuild the geometry
/// (BENCHMARKS.md, "3-D MLPG speed").
pub fn heap_by_part() {
    let across: f64 = std::env::var("PARTICLES_RADIAL")
        .map(|s| s.parse().unwrap())
        .unwrap_or(10.0);
    let steps: usize = std::env::var("STEPS")
        .map(|s| s.parse().unwrap())
        .unwrap_or(200);
    rayon::broadcast(|_| ());
    let base = heap::live();
    heap::reset_peak();
    let p = Taylor3dParams {
        particles_radial: across,
        ..Taylor3dParams::default()
    };
    let mut s = p.build().unwrap();
    let built = heap::peak() - base;
    s.step().unwrap();
    let n = s.particles() as f64;
    let kb = |b: u64| b as f64 / n / 1e3;
    println!(
        "most live at once in the construction: {:.2} kB a node",
        kb(built)
    );
    let live = heap::live() - base;
    println!(
        "{} nodes; held after the first step: {:.2} kB a node",
        s.particles(),
        kb(live)
    );
    let mut parts = 0;
    for (part, bytes) in s.memory() {
        parts += bytes;
        println!("  {part:<22} {:>6.2} kB a node", kb(bytes as u64));
    }
    println!(
        "  {:<22} {:>6.2} kB a node",
        "other",
        kb(live - parts as u64)
    );
    // The largest rise of the heap within one step, and that step.
    let (mut rise, mut at) = (0u64, 0u64);
    for _ in 0..steps {
        let live = heap::live();
        let peak = heap::reset_peak();
        s.step().unwrap();
        if heap::peak() - live > rise {
            (rise, at) = (heap::peak() - live, s.steps());
        }
        heap::keep_peak(peak);
    }
    println!(
        "the largest rise within one step: {:.2} kB a node (step {at})",
        kb(rise)
    );
    println!(
        "most live at once over {} steps ({} builds): {:.2} kB a node, {:.1} MB",
        s.steps(),
        s.rebuilds(),
        kb(heap::peak() - base),
        (heap::peak() - base) as f64 / 1e6
    );
}
