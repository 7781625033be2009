//! The golden test of the refactoring: small runs whose final observables
//! and histories must keep their exact bits while the core is reorganised
//! (scene registry, `Model` trait, composed materials). A change of any bit
//! fails it; the expected values were recorded from the code before the
//! refactoring began and are never re-recorded by it. One case was
//! re-recorded for a change of the scheme, not of the code's organisation:
//! the large-strain case on 2026-11-27, when the density's smoothing took
//! the velocity's order (README, "Smoothing at large strain"); the paper's
//! case and Noh keep the bits they were first recorded with.
//!
//! Each case is a digest: the bits of every final observable, and an FNV-1a
//! checksum over the bits of every recorded time and value. Every case runs
//! in each compiled copy of the hot loops this processor has (AVX-512,
//! AVX2+FMA, baseline; [`Isa`]). With `MI_REQUIRE_AVX512=1` the test fails
//! where the AVX-512 copy cannot run, rather than leaving it out.

use meshless_impact::{Isa, Scene, Simulation};

/// A golden case: scene, settings, and the digest it must reproduce.
struct Golden {
    name: &'static str,
    scene: &'static str,
    sets: &'static [(&'static str, f64)],
    /// Bits of the final observables, in the scene's order.
    finals: &'static [u64],
    /// FNV-1a of the history's times and values.
    history: u64,
    rows: usize,
}

/// The large-strain scheme of README "Particle shifting".
const LARGE: [(&str, f64); 3] = [
    ("smoothing_ratio", 2.0),
    ("smoothing_order", 2.0),
    ("shifting", 0.1),
];

fn fnv1a(words: impl IntoIterator<Item = u64>) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for w in words {
        for b in w.to_le_bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}

/// Runs a case and returns (final observable bits, history checksum, rows).
fn digest(scene: &str, sets: &[(&str, f64)], isa: Isa) -> (Vec<u64>, u64, usize) {
    let mut scene = Scene::builtin(scene).unwrap();
    for (k, v) in sets {
        scene.set(k, *v).unwrap();
    }
    let mut sim = Simulation::new(scene).unwrap();
    sim.set_isa(isa);
    sim.run().unwrap();
    let finals = sim.observables().iter().map(|v| v.to_bits()).collect();
    let h = sim.history();
    let words = h.times.iter().chain(&h.values).map(|v| v.to_bits());
    (finals, fnv1a(words), h.len())
}

fn cases() -> Vec<Golden> {
    vec![
        Golden {
            name: "taylor, 5 across, to 10 us",
            scene: "taylor",
            sets: &[("particles_radial", 5.0), ("end_time", 10e-6)],
            finals: &[
                0x3fa2_9745_b6f8_b2bc,
                0x3f71_d4ac_7a69_b8a6,
                0x3f90_c0fc_5bea_d9a5,
                0x4060_968a_10b3_22e2,
                0x0000_0000_0000_0000,
                0x3fd3_6d4d_69fb_4852,
                0x4078_8fb2_c9ea_c79f,
                0x4057_8a8c_e319_6a2f,
                0x4057_44d3_82fa_df93,
                0x403d_af54_6536_691c,
                0x4006_10bb_2aa2_0872,
                0x3f71_ac40_456b_bd72,
                0x0000_0000_0000_0000,
            ],
            history: 0xa357_db79_3b50_7d14,
            rows: 102,
        },
        Golden {
            name: "noh, 100 particles, to t = 0.1",
            scene: "noh",
            sets: &[("particles_radial", 100.0), ("end_time", 0.1)],
            finals: &[
                0x0000_0000_0000_0000,
                0x3fff_f254_d260_83db,
                0x3f33_97a2_400f_9461,
                0x3fa6_6d90_13eb_3b99,
                0x400b_9a08_3bff_e7b3,
                0x3fb5_3daa_3fc7_4ab4,
                0x3f32_e25c_e5db_6073,
            ],
            history: 0xf05b_05c4_3b89_29bf,
            rows: 102,
        },
        Golden {
            name: "taylor, large-strain scheme, 5 across, to 10 us",
            scene: "taylor",
            sets: &[
                ("particles_radial", 5.0),
                ("end_time", 10e-6),
                LARGE[0],
                LARGE[1],
                LARGE[2],
            ],
            finals: &[
                0x3fa2_9560_999b_ff2f,
                0x3f72_c01a_f233_f116,
                0x3f93_12a5_d01a_fd93,
                0x4060_b4b4_6252_c492,
                0x0000_0000_0000_0000,
                0x3fda_1bf9_4abc_c286,
                0x407a_c58b_9efd_da1f,
                0x405b_f6d8_fc28_0a4d,
                0x4058_3321_21f3_d982,
                0x4022_23d6_1524_e350,
                0x4006_135c_875e_aac8,
                0x3f46_44b6_b091_dc1e,
                0x0000_0000_0000_0000,
            ],
            history: 0x2e77_cdb5_89e0_b476,
            rows: 102,
        },
    ]
}

/// The copies to run: every one this processor has; all three when
/// `MI_REQUIRE_AVX512=1` (a copy it lacks then fails the test).
fn copies() -> Vec<Isa> {
    let required = std::env::var("MI_REQUIRE_AVX512").is_ok_and(|v| v == "1");
    if required {
        ["avx512", "avx2+fma", "baseline"]
            .map(|name| Isa::named(name).expect("MI_REQUIRE_AVX512=1"))
            .to_vec()
    } else {
        let available = Isa::available();
        if available.len() < 3 {
            eprintln!(
                "this processor runs only {:?}: the other copies are not compared",
                available.iter().map(|i| i.name()).collect::<Vec<_>>()
            );
        }
        available
    }
}

#[test]
fn golden_runs_keep_their_bits_in_every_copy() {
    let mut failed = Vec::new();
    for isa in copies() {
        for case in cases() {
            let (finals, history, rows) = digest(case.scene, case.sets, isa);
            println!(
                "{} [{}]: finals {:#018x?}, history {history:#018x}, rows {rows}",
                case.name,
                isa.name(),
                finals
            );
            if finals != case.finals || history != case.history || rows != case.rows {
                failed.push(format!("{} [{}]", case.name, isa.name()));
            }
        }
    }
    assert!(failed.is_empty(), "bits changed in: {failed:?}");
}
