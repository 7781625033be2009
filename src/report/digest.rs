//! The physics digest: a fingerprint of the bits of the solvers, written
//! into the report and printed by `meshless-impact report --digest`, so
//! that a committed report whose figures the code no longer gives is found
//! (`tests/suite/report.rs`).
//!
//! It is FNV-1a over the bits of every final observable of one small run
//! of each solver (the golden test's settings, a few seconds in all). A
//! change that moves any solver's bits changes it; a change of the code's
//! organisation that keeps the bits (the golden test's promise) does not.

use meshless_impact::{Result, Scene, Simulation};

/// The small runs: a scene and its settings.
const RUNS: &[(&str, &[(&str, f64)])] = &[
    (
        "taylor",
        &[
            ("particles_radial", 5.0),
            ("end_time", 10e-6),
            ("scheme", 1.0),
        ],
    ),
    ("taylor", &[("particles_radial", 5.0), ("end_time", 10e-6)]),
    ("noh", &[("particles_radial", 100.0), ("end_time", 0.1)]),
    (
        "taylor3d",
        &[
            ("particles_radial", 4.0),
            ("end_time", 5e-6),
            ("scheme", 1.0),
        ],
    ),
    ("taylor3d", &[("particles_radial", 4.0), ("end_time", 5e-6)]),
    (
        "penetration",
        &[
            ("particles_radial", 3.0),
            ("symmetry", 1.0),
            ("end_time", 2e-6),
        ],
    ),
    ("plate_impact", &[("plate_ceramic", 1.0)]),
];

/// The digest of the code's physics now.
pub fn physics_digest() -> Result<u64> {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for (name, sets) in RUNS {
        let mut scene = Scene::builtin(name)?;
        for (k, v) in *sets {
            scene.set(k, *v)?;
        }
        let mut sim = Simulation::new(scene)?;
        sim.run()?;
        for v in sim.observables() {
            for b in v.to_bits().to_le_bytes() {
                h ^= u64::from(b);
                h = h.wrapping_mul(0x0100_0000_01b3);
            }
        }
    }
    Ok(h)
}

/// The digest as the report writes it.
pub fn format(digest: u64) -> String {
    format!("{digest:#018x}")
}
