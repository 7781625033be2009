//! Explorations and measurements behind constants and choices of the 3-D
//! solver, runnable but not tests: each prints a table or a trace for a
//! person to read (the measured figures are in the docs they cite) and
//! asserts nothing. Moved out of the test suite (issue 51).
//!
//! `cargo run --release --example explore -- NAME`; with no name, the list.

use std::process::ExitCode;

mod heap_peak;
mod mlpg;
mod penetration;
mod solver;

// The counting allocator of `tests/mlpg_alloc.rs`: the heap explorations
// read its counters (relaxed atomics; the 3-D steps allocate nothing
// between rebuilds, so the others run as fast).
#[path = "../../tests/heap/mod.rs"]
#[allow(dead_code)]
mod heap;
#[global_allocator]
static GLOBAL: heap::Counting = heap::Counting;

// The fixtures the explorations share with the test suite, by their path.
#[path = "../../tests/suite/mlpg/bar.rs"]
#[allow(dead_code)]
mod bar;
#[path = "../../tests/suite/mlpg_solver/rod.rs"]
#[allow(dead_code)]
mod rod;

/// Every exploration: its name and what it prints.
const EXPLORATIONS: &[(&str, &str, fn())] = &[
    (
        "alpha_table",
        "the table behind sphere::ALPHA (kappa, period and energy errors per alpha)",
        mlpg::alpha_table,
    ),
    (
        "unstable_modes_of_the_bar",
        "the complex eigenvalues of the free bar's operator and their growth",
        mlpg::unstable_modes_of_the_bar,
    ),
    (
        "damping_table",
        "the table behind the solver's damping (MLPG_ZETA, MLPG_PERIODS, ...)",
        mlpg::damping_table,
    ),
    (
        "elastic_rebound",
        "an elastic Taylor impact at 10 m/s, printed (RINGS, ZETA, WEAK, ALPHA, EVERY, HELD)",
        solver::explore_elastic_rebound,
    ),
    (
        "taylor3d_stop",
        "taylor3d without smoothing until it stops: the closest pair (MI_SCENE_FILE, MI_SET)",
        solver::explore_taylor3d_stop,
    ),
    (
        "taylor3d_profile",
        "the phase profile of taylor3d, CPU per node-step (PARTICLES_RADIAL, MI_SCENE_FILE, MI_SET)",
        solver::explore_taylor3d_profile,
    ),
    (
        "penetration_profile",
        "the phase profile of the penetration scene, with serial time (MI_SET, STEPS)",
        solver::explore_penetration_profile,
    ),
    (
        "wilkins3d_face",
        "the face region of the Wilkins bar in 3-D every 2.5 us (MI_SET)",
        solver::explore_wilkins3d_face,
    ),
    (
        "wilkins3d_ring",
        "the Wilkins bar in 3-D to rest: its face's largest radius and its outer ring's mean (MI_SET)",
        solver::explore_wilkins3d_ring,
    ),
    (
        "energy_jump",
        "where a jump of the energy error comes from (MI_SCENE_FILE, MI_SET, MI_JUMP)",
        solver::explore_energy_jump,
    ),
    (
        "contact_by_rings",
        "the elastic rebound's contact time by rings, both forms (RINGS)",
        solver::explore_contact_by_rings,
    ),
    (
        "heap_peak",
        "a scene's heap peak per node against its memory estimate, and where (MI_SCENE, MI_SET, STEPS)",
        heap_peak::heap_peak,
    ),
    (
        "heap_by_part",
        "the heap of taylor3d by part after its first step and its peak (PARTICLES_RADIAL, STEPS)",
        heap_peak::heap_by_part,
    ),
    (
        "seed_case",
        "the seed's penetration case printed as it runs (MI_RINGS, MI_ALPHA, MI_SHIFT, MI_END, ...)",
        penetration::explore_seed_case,
    ),
];

fn main() -> ExitCode {
    let name = std::env::args().nth(1);
    match EXPLORATIONS
        .iter()
        .find(|(n, ..)| Some(*n) == name.as_deref())
    {
        Some((_, _, run)) => {
            run();
            ExitCode::SUCCESS
        }
        None => {
            if let Some(n) = name {
                eprintln!("error: unknown exploration `{n}`");
            }
            eprintln!("usage: cargo run --release --example explore -- NAME\n\nNAME:");
            for (n, what, _) in EXPLORATIONS {
                eprintln!("  {n:26} {what}");
            }
            ExitCode::FAILURE
        }
    }
}
