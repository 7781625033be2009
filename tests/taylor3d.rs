//! House et al. test 7 in 3-D (`taylor3d`, MLPG mixed method) against the
//! experiment (Lf = 34.6 mm, Df = 9.5 mm) and the axisymmetric MSPH solver,
//! run through the scene registry and `Simulation`.

mod common;

use common::{pct, run};
use meshless_impact::Scene;

/// The bounds on test 7 in 3-D: the final length within 2 % of the
/// experiment, the face diameter within 8 %, the face's spread around the
/// axis below 2 %, the energy error below 5 %, the rod at rest.
fn check(particles_radial: f64) -> f64 {
    let sim = run(
        Scene::builtin("taylor3d").unwrap(),
        &[("particles_radial", particles_radial)],
    );
    let o = |name: &str| sim.observable(name).unwrap();
    let (lf, rf) = (o("rod_length"), o("mushroom_radius"));
    println!(
        "{} nodes: Lf {:.3} mm ({:+.2} %), Df {:.3} mm ({:+.2} %), spread {:.2e}, energy error {:.2e}, \
         smoothing dissipation {:.2} J",
        sim.particles(),
        lf * 1e3,
        pct(lf, 34.6e-3),
        2e3 * rf,
        pct(2.0 * rf, 9.5e-3),
        o("mushroom_radius_spread"),
        o("energy_error"),
        o("smoothing_dissipation"),
    );
    assert_eq!(o("at_rest"), 1.0, "the rod came to rest");
    assert!(pct(lf, 34.6e-3).abs() < 2.0, "Lf {lf}");
    assert!(pct(2.0 * rf, 9.5e-3).abs() < 8.0, "Df {}", 2.0 * rf);
    assert!(o("mushroom_radius_spread") < 0.02);
    assert!(o("energy_error") < 0.05);
    lf
}

/// 6 nodes across the radius (4641 nodes, about 20 s on two cores):
/// measured Lf 34.62 mm (+0.05 %), Df 10.22 mm (+7.6 %), spread 0.31 %,
/// energy error 1.4 %.
#[test]
fn test7_in_3d_coarse() {
    check(6.0);
}

/// 11 nodes across (10 rings, 33431 nodes; 358 s wall on two shared cores
/// before the speed work, which kept the bits; `scripts/validate.sh`): measured Lf 34.57 mm (−0.08 %), Df 10.34 mm
/// (+8.8 %: outside the 8 %, so this test fails on Df), spread 0.14 %,
/// energy error 0.85 %; the axisymmetric solver at the matched spacing
/// (`particles_radial` = 11) gives 34.84 mm, 0.76 % longer (within 1 %).
#[test]
#[ignore = "heavy: 6 minutes; scripts/validate.sh"]
fn test7_in_3d_at_11_across() {
    let lf = check(11.0);
    let msph = run(
        Scene::builtin("taylor").unwrap(),
        &[("particles_radial", 11.0)],
    );
    let l2 = msph.observable("rod_length").unwrap();
    println!("axisymmetric at the matched spacing: {:.3} mm", l2 * 1e3);
    assert!(
        pct(lf, l2).abs() < 1.0,
        "3-D {lf} against axisymmetric {l2}"
    );
}

/// The seed's own 3-D case (`taylor3d-aisi310`: AISI 310, bilinear J2,
/// 300 m/s, L0 = 12.7 mm and D0 = 7.62 mm assumed) against the axisymmetric
/// MSPH solver with the same material, at rest (both rest before the
/// seed's 50 µs): the bounds are lengths within 1 % and radii
/// within 3 %; the radii are the face's and the outline's at 40 heights.
/// Returns the three relative differences.
fn aisi310(n3: f64, n2: f64) -> [f64; 3] {
    use meshless_impact::{axisymmetric_twin, profile_deviation};
    let s3 = Scene::builtin("taylor3d-aisi310").unwrap();
    let twin = axisymmetric_twin(&s3, n2).unwrap();
    let (a, b) = (run(s3, &[("particles_radial", n3)]), run(twin, &[]));
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

/// 6 nodes across (1638 nodes, about 8 s) against 31 across: measured
/// length −0.51 %, face radius +0.83 %, outline within 1.41 %.
#[test]
fn aisi310_in_3d_against_the_axisymmetric_solver() {
    aisi310(6.0, 31.0);
}

/// 11 nodes across (11254 nodes; about a minute) against 41 across:
/// measured length −0.42 %, face radius +1.50 %, outline within 1.78 %.
#[test]
#[ignore = "heavy: a few minutes; scripts/validate.sh"]
fn aisi310_in_3d_at_11_across() {
    aisi310(11.0, 41.0);
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
