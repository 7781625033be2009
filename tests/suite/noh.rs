//! The cylindrical Noh problem against its exact solution (Noh 1987; Batra &
//! Zhang 2008, section 4.1): shock at r = t/3, density 16 behind it and
//! 1 + t/r ahead of it.

use meshless_impact::Simulation;

#[test]
fn noh_at_t06_matches_the_exact_solution() {
    let mut sim = Simulation::builtin("noh").unwrap();
    sim.run().unwrap();
    assert_eq!(sim.particles(), 800);
    assert!((sim.time() - 0.6).abs() < 1e-12, "ends at t = 0.6");
    let o = |n: &str| sim.observable(n).unwrap();
    let shock = o("shock_radius");
    assert!((shock - 0.2).abs() <= 0.01, "shock_radius {shock}");
    let post = o("post_shock_density");
    assert!((post - 16.0).abs() <= 1.6, "post_shock_density {post}");
    let pre = o("pre_shock_density_l1");
    assert!(pre <= 0.03, "pre_shock_density_l1 {pre}");
    let e = o("energy_error");
    assert!(e.is_finite() && e < 0.01, "energy_error {e}");
}

/// Only the Noh parameters exist for this scene, and the Noh observables.
#[test]
fn noh_exposes_only_its_own_variables() {
    let sim = Simulation::builtin("noh").unwrap();
    let names: Vec<&str> = sim.observable_specs().iter().map(|s| s.name).collect();
    assert!(names.contains(&"shock_radius") && !names.contains(&"rod_length"));
    assert!(sim.scene().get("jc_a").is_err());
}
