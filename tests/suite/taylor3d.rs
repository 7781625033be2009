//! House et al. test 7 in 3-D (`taylor3d`, MLPG mixed method, its default
//! scheme) against the experiment's length (34.6 mm), LS-DYNA's converged
//! face (10.62 mm) and the axisymmetric MSPH solver, and the 42CrMo4 bar
//! against its 3-D finite-element references, run through the scene
//! registry and `Simulation`.

use crate::common;

use common::{pct, run};
use meshless_impact::Scene;

/// The bounds on test 7 in 3-D with the default scheme (`large_strain`):
/// the final length within 1 % of the experiment's 34.6 mm, the face
/// diameter within 3 % of LS-DYNA's converged 10.62 mm (the continuum's
/// face is larger than the measured 9.5 mm; VALIDATION.md, "Right by
/// default"), the face's spread around the axis below 2 %, the energy error
/// below 5 %, the rod at rest. Returns (Lf, Df).
fn check(particles_radial: f64) -> (f64, f64) {
    let sim = run(
        Scene::builtin("taylor3d").unwrap(),
        &[("particles_radial", particles_radial)],
    );
    let o = |name: &str| sim.observable(name).unwrap();
    let (lf, df) = (o("rod_length"), 2.0 * o("mushroom_radius"));
    println!(
        "{} nodes: Lf {:.3} mm ({:+.2} %), Df {:.3} mm ({:+.2} % of 10.62 mm), spread {:.2e}, energy error {:.2e}, \
         smoothing dissipation {:.2} J",
        sim.particles(),
        lf * 1e3,
        pct(lf, 34.6e-3),
        1e3 * df,
        pct(df, 10.62e-3),
        o("mushroom_radius_spread"),
        o("energy_error"),
        o("smoothing_dissipation"),
    );
    assert_eq!(o("at_rest"), 1.0, "the rod came to rest");
    assert!(pct(lf, 34.6e-3).abs() < 1.0, "Lf {lf}");
    assert!(pct(df, 10.62e-3).abs() < 3.0, "Df {df}");
    assert!(o("mushroom_radius_spread") < 0.02);
    assert!(o("energy_error") < 0.05);
    (lf, df)
}

/// 6 nodes across the radius (about 20 s on two cores): measured Lf
/// 34.57 mm (−0.08 %), Df 10.45 mm (−1.6 %), spread 1.2 %, energy error
/// 0.18 %.
#[test]
fn test7_in_3d_coarse() {
    check(6.0);
}

/// Test 7 in 3-D at 6, 8 and 10 nodes across (the last the issue's
/// resolution; about 3 minutes on two cores, `scripts/validate.sh`): each
/// within the bounds of `check`, the finest two face diameters within 2 %
/// of each other, and the length at 10 across within 1 % of the
/// axisymmetric solver's at the matched spacing. Measured at 10 across:
/// Lf 34.55 mm (−0.14 %), Df 10.53 mm (−0.87 %), energy error 0.09 %.
#[test]
#[ignore = "heavy: 3 minutes; scripts/validate.sh"]
fn test7_in_3d_under_refinement() {
    let runs: Vec<(f64, f64)> = [6.0, 8.0, 10.0].iter().map(|&n| check(n)).collect();
    println!("(Lf, Df) at 6, 8, 10 across: {runs:?}");
    assert!(pct(runs[2].1, runs[1].1).abs() < 2.0, "{runs:?}");
    let msph = run(
        Scene::builtin("taylor").unwrap(),
        &[("particles_radial", 10.0)],
    );
    let l2 = msph.observable("rod_length").unwrap();
    println!("axisymmetric at the matched spacing: {:.3} mm", l2 * 1e3);
    assert!(
        pct(runs[2].0, l2).abs() < 1.0,
        "3-D {} against axisymmetric {l2}",
        runs[2].0
    );
}

/// The 42CrMo4 bar of `scenes/crmo4_dynela_3d.toml` in 3-D with the
/// default scheme at the default 6 nodes across: at rest, within 1 % in
/// length of 26.53 mm and 3 % in face diameter of 11.20 mm (the 3-D
/// references: DynELA 26.52 / 11.18 mm, Abaqus 26.55 / 11.22 mm), the
/// spread below 2 %, the energy error below 5 %. Measured: +0.11 % and
/// +0.49 %, energy error 0.18 % (28 s on one thread).
#[test]
fn crmo4_bar_in_3d_matches_the_converged_finite_element_results() {
    let sim = run(
        Scene::from_file(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenes/crmo4_dynela_3d.toml"
        ))
        .unwrap(),
        &[],
    );
    let o = |name: &str| sim.observable(name).unwrap();
    let (lf, df) = (o("rod_length"), 2.0 * o("mushroom_radius"));
    println!(
        "42CrMo4 in 3-D: Lf {lf}, Df {df}, energy error {}",
        o("energy_error")
    );
    assert_eq!(o("at_rest"), 1.0);
    assert!(pct(lf, 26.53e-3).abs() < 1.0, "Lf {lf}");
    assert!(pct(df, 11.20e-3).abs() < 3.0, "Df {df}");
    assert!(o("mushroom_radius_spread") < 0.02);
    assert!(o("energy_error") < 0.05);
}

/// The seed's own 3-D case (`taylor3d-aisi310`: AISI 310, bilinear J2,
/// 300 m/s, L0 = 12.7 mm and D0 = 7.62 mm assumed) against the axisymmetric
/// MSPH solver with the same material, at rest (both rest before the
/// seed's 50 µs): the bounds are lengths within 1 % and radii
/// within 3 %; the radii are the face's and the outline's at 40 heights.
/// Returns the three relative differences.
fn aisi310(n3: f64, n2: f64, sets: &[(&str, f64)]) -> [f64; 3] {
    use meshless_impact::{axisymmetric_twin, profile_deviation};
    let s3 = Scene::builtin("taylor3d-aisi310").unwrap();
    let twin = axisymmetric_twin(&s3, n2).unwrap();
    let mut sets3 = sets.to_vec();
    sets3.push(("particles_radial", n3));
    let (a, b) = (run(s3, &sets3), run(twin, sets));
    for sim in [&a, &b] {
        assert_eq!(sim.observable("at_rest"), Some(1.0), "at rest");
    }
    let o = |s: &meshless_impact::Simulation, n: &str| s.observable(n).unwrap();
    let dl = pct(o(&a, "rod_length"), o(&b, "rod_length"));
    let dr = pct(o(&a, "mushroom_radius"), o(&b, "mushroom_radius"));
    let dp = 100.0
        * profile_deviation(&a.rod_profile().unwrap(), &b.rod_profile().unwrap(), 40).unwrap();
    println!(
        "3-D at {n3} across ({} nodes): Lf {:.4} mm, face radius {:.4} mm; axisymmetric at {n2}: \
         {:.4} mm, {:.4} mm; length {dl:+.2} %, face radius {dr:+.2} %, outline within {dp:.2} %",
        a.particles(),
        o(&a, "rod_length") * 1e3,
        o(&a, "mushroom_radius") * 1e3,
        o(&b, "rod_length") * 1e3,
        o(&b, "mushroom_radius") * 1e3,
    );
    assert!(dl.abs() < 1.0, "length {dl} %");
    assert!(dr.abs() < 3.0, "face radius {dr} %");
    assert!(dp < 3.0, "outline {dp} %");
    [dl, dr, dp]
}

/// The default schemes (3-D and 2-D `large_strain`), 11 nodes across
/// (11254 nodes; about 50 s on two cores) against 41 across: measured
/// length −0.20 %, face radius +0.71 %, outline within 1.19 %. This is the
/// lowest resolution that meets the bounds: at 6 and 8 across the 3-D
/// outline lies 4.6 % and 5.0 % inside the axisymmetric one 0.22 mm above
/// the face, within the first layer of 3-D nodes (0.76 and 0.54 mm apart),
/// whose outline cannot follow the face's rounded corner (the axisymmetric
/// outline there is converged: 31, 41 and 61 across agree within 0.16 %;
/// VALIDATION.md, "Right by default").
#[test]
#[ignore = "heavy: about 2 minutes on two cores; scripts/validate.sh"]
fn aisi310_in_3d_against_the_axisymmetric_solver() {
    aisi310(11.0, 41.0, &[]);
}

/// The paper's schemes in 3-D and 2-D (`scheme = paper`, the defaults
/// before 2026-11-28), 6 nodes across (1638 nodes, about 8 s) against 31
/// across: measured length −0.52 %, face radius +0.84 %, outline within
/// 1.46 % (the paper's 2-D face corner is rounder than the converged
/// default's, as the coarse 3-D one is).
#[test]
fn aisi310_with_the_papers_schemes() {
    aisi310(6.0, 31.0, &[("scheme", 1.0)]);
}

/// The material's cross-checks hold in 3-D as in `taylor`: a melt
/// temperature not above the room temperature, or a rod hotter than its
/// melt, is refused before anything runs (before, the 3-D row checked only
/// the geometry, and such a rod ran until its energy error passed the
/// bound).
#[test]
fn temperatures_are_checked_as_in_taylor() {
    for (name, value, says) in [
        ("melt_temperature", 293.0, "must exceed room_temperature"),
        (
            "initial_temperature",
            1500.0,
            "must be below melt_temperature",
        ),
    ] {
        for kind in ["taylor", "taylor3d"] {
            let mut scene = Scene::builtin(kind).unwrap();
            scene.set(name, value).unwrap();
            let e = meshless_impact::Simulation::new(scene).unwrap_err();
            assert_eq!(e.name(), "Inconsistent", "{kind}: {e}");
            assert!(e.to_string().contains(says), "{kind}: {e}");
        }
    }
}

/// The levels' preconditioner (`conform_preconditioner = 1`, issue 69) on
/// test 7 at 10 across (two levels: the flexible iterations), to 5 µs:
/// the length and face radius within 1e-4 of Jacobi's (the stop's
/// tolerance moves them, not the method; measured to rest 3.0e-6 and
/// 1.2e-5: docs/notes/2026-11-30-conforming-levels.md), and a run saved
/// at 2.5 µs resumes to the uninterrupted run's bits.
#[test]
fn the_levels_keep_test7_and_resume_to_the_same_bits() {
    use meshless_impact::Simulation;
    let scene = |p: f64| {
        let mut s = Scene::builtin("taylor3d").unwrap();
        for (k, v) in [
            ("particles_radial", 10.0),
            ("end_time", 5e-6),
            ("conform_preconditioner", p),
        ] {
            s.set(k, v).unwrap();
        }
        s
    };
    let mut jacobi = Simulation::new(scene(0.0)).unwrap();
    jacobi.run().unwrap();
    let mut levels = Simulation::new(scene(1.0)).unwrap();
    levels.run().unwrap();
    for name in ["rod_length", "mushroom_radius"] {
        let (a, b) = (
            jacobi.observable(name).unwrap(),
            levels.observable(name).unwrap(),
        );
        println!("{name}: Jacobi {a:e}, levels {b:e} ({:+.2e})", (b - a) / a);
        assert!(((b - a) / a).abs() < 1e-4, "{name}: {a} against {b}");
    }
    let mut mid = Simulation::new(scene(1.0)).unwrap();
    mid.advance_to(2.5e-6).unwrap();
    let mut back = Simulation::deserialize_state(&mid.serialize_state()).unwrap();
    back.run().unwrap();
    assert_eq!(common::all_bits(&back), common::all_bits(&levels));
}
