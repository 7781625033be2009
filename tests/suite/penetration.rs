//! The penetration run (seed 004, section 5.2): a tungsten rod through an
//! AD85 plate by the 3-D MLPG mixed method, through the scene registry and
//! `Simulation`, and its solver directly for the explorations.

use crate::common;

use meshless_impact::{Scene, Simulation};

/// The default scene at 4 nodes across the projectile's radius (3 rings,
/// 7463 nodes), to `t`: the scene's solver choices (the nodal form, the
/// order-2 smoothing, node shifting).
fn coarse(t: f64) -> Simulation {
    coarse_with(t, &[])
}

/// The solver's choices of the scene before 2026-11-26: the seed's test
/// spheres, no smoothing, no shifting.
const PLAIN: &[(&str, f64)] = &[
    ("weak_form", 0.0),
    ("smoothing_order", 1.0),
    ("smoothing_coefficient", 0.0),
    ("shifting", 0.0),
];

/// The scene with the seed's AD85 as printed, named (`plate_ceramic =
/// ad85_seed`, a0 = 0.58 µm, the default): the constants the tests of the
/// seed's case below were measured with, whatever the default becomes.
fn seed_scene() -> Scene {
    let mut scene = Scene::builtin("penetration").unwrap();
    scene.set_str("plate_ceramic", "ad85_seed").unwrap();
    scene
}

/// [`coarse`] with parameters set.
fn coarse_with(t: f64, sets: &[(&str, f64)]) -> Simulation {
    let mut scene = seed_scene();
    scene.set("particles_radial", 4.0).unwrap();
    scene.set("end_time", t).unwrap();
    for (k, v) in sets {
        scene.set(k, *v).unwrap();
    }
    let mut sim = Simulation::new(scene).unwrap();
    sim.run().unwrap();
    sim
}

/// The seed's residual velocity (section 5.2), m/s.
const SEED_RESIDUAL: f64 = 1240.0;

/// The projectile's velocity at the end of a run and its change over the
/// last 5 µs.
fn residual(sim: &Simulation) -> (f64, f64) {
    let h = sim.history();
    let v = h.column("projectile_velocity").unwrap();
    let end = sim.time();
    let k = h.times.iter().position(|&t| t >= end - 5e-6).unwrap();
    let last = sim.observable("projectile_velocity").unwrap();
    (last, last - v[k])
}

/// The seed's case with the scene's choices at 4 nodes across (7463
/// nodes) runs to 20 µs with no named stop and the projectile through the
/// plate: every projectile node below the plate's top face, its centre of
/// mass past the back face (5 mm down). Its velocity, 1059.5 m/s, is
/// 14.6 % below the seed's 1240 m/s, within the 20 % this coarse spacing
/// gives, and still falls (VALIDATION.md, "Ballistic penetration": 1059.5,
/// 1095.3 and 1123.6 m/s at 4, 5 and 6 across, the last settled and within
/// the 10 %,
/// `the_seed_case_at_the_default_resolution_is_within_ten_percent`). The
/// energy error is within taylor3d's 5 % (measured 0.46 %; 6.8 % before the
/// pulverized nodes were kept out of the shifting, and 18.8 % at the nodal
/// form's own step with them in it). The quarter model of the same case is
/// within 1 % of it.
#[test]
fn the_seed_case_perforates_the_plate() {
    let sim = coarse(20e-6);
    let (v, change) = residual(&sim);
    let (x, body, m) = (
        sim.field("position").unwrap(),
        sim.field("body").unwrap(),
        node_masses(&sim),
    );
    let projectile: Vec<usize> = (0..sim.particles()).filter(|&i| body[i] == 0.0).collect();
    let top = projectile
        .iter()
        .map(|&i| x[3 * i + 2])
        .fold(f64::NEG_INFINITY, f64::max);
    let mass: f64 = projectile.iter().map(|&i| m[i]).sum();
    let z_cm = projectile.iter().map(|&i| m[i] * x[3 * i + 2]).sum::<f64>() / mass;
    println!(
        "4 across: residual {v:.1} m/s ({:+.2} % of the seed's), change over 5 us {change:.2} m/s, \
         energy error {:.4}, centre of mass at {:.2} mm, highest node at {:.2} mm",
        100.0 * (v / SEED_RESIDUAL - 1.0),
        sim.observable("energy_error").unwrap(),
        1e3 * z_cm,
        1e3 * top
    );
    assert!(top < 0.0 && z_cm < -5e-3, "top {top}, centre {z_cm}");
    assert!((v / SEED_RESIDUAL - 1.0).abs() < 0.20, "residual {v} m/s");
    let e = sim.observable("energy_error").unwrap();
    assert!(e < 0.05, "energy error {e}");
    // The quarter model (`symmetry = 1`, 1960 nodes): the 1 % of
    // the whole body's residual velocity (measured 1064.0 m/s, +0.43 %;
    // −0.35 % at 5 across).
    let quarter = coarse_with(20e-6, &[("symmetry", 1.0)]);
    let (vq, _) = residual(&quarter);
    println!(
        "quarter model: {} nodes, residual {vq:.1} m/s ({:+.2} % of the whole body's), energy error {:.4}",
        quarter.particles(),
        100.0 * (vq / v - 1.0),
        quarter.observable("energy_error").unwrap()
    );
    assert!(4 * quarter.particles() < sim.particles() + 400);
    // The seed's isotropic cracks lie in every orientation: a radial crack
    // reads the crack density itself.
    assert_eq!(
        quarter.field("radial_damage").unwrap(),
        quarter.field("damage").unwrap()
    );
    assert!(
        (vq / v - 1.0).abs() < 0.01,
        "quarter {vq} m/s, whole {v} m/s"
    );
}

/// The seed's case as the scene sets it (6 across, 30 527 nodes; about
/// 100 s on two cores): the residual velocity within the 10 % of
/// the seed's 1240 m/s (measured 1123.6 m/s, −9.4 %, settled over the
/// last 5 µs to −1.5 m/s; 1127.0 m/s with the trace-free carry and 1126.4
/// m/s with the conservative carry, both 2026-11-28). Run by
/// `scripts/validate.sh`.
#[test]
#[ignore = "slow: run by scripts/validate.sh"]
fn the_seed_case_at_the_default_resolution_is_within_ten_percent() {
    let mut sim = Simulation::new(Scene::builtin("penetration").unwrap()).unwrap();
    sim.run().unwrap();
    let (v, change) = residual(&sim);
    println!(
        "default: {} nodes, residual {v:.1} m/s ({:+.2} %), change over 5 us {change:.2} m/s, energy error {:.4}",
        sim.particles(),
        100.0 * (v / SEED_RESIDUAL - 1.0),
        sim.observable("energy_error").unwrap()
    );
    assert!(change.abs() < 0.01 * v, "still changing: {change} m/s");
    assert!((v / SEED_RESIDUAL - 1.0).abs() < 0.10, "residual {v} m/s");
}

/// Total axial momentum `Σ m v_z` of a run (kg m/s).
fn momentum(sim: &Simulation, masses: &[f64]) -> f64 {
    let v = sim.field("velocity").unwrap();
    masses
        .iter()
        .enumerate()
        .map(|(i, m)| m * v[3 * i + 2])
        .sum()
}

/// The seed's case, coarse, to 2 µs, with the seed's test spheres and no
/// smoothing or shifting ([`PLAIN`]): the projectile has slowed and the
/// plate has taken up the momentum it lost. The contact's impulses conserve
/// momentum exactly; the MLPG forces (the Heaviside weak form, eq. 10:
/// a node's sphere, not its mass, takes the force) do not, and over the
/// first 3 µs measured drifts of at most 1.5 % (0.85 % at 2 µs, 0.43 % at
/// 1 µs). Measured at 2 µs: projectile 1346.1 m/s, momentum drift
/// −0.85 %, energy error 0.90 %; the ceramic has begun to pulverize under
/// the projectile (0.89 % of the plate, at the critical crack density), the
/// projectile has shortened to 9.57 mm.
#[test]
fn the_seed_case_transfers_momentum_to_the_plate() {
    let start = coarse_with(1e-9, PLAIN);
    let sim = coarse_with(2e-6, PLAIN);
    let n = sim.particles();
    let body = sim.field("body").unwrap();
    let o = |name: &str| sim.observable(name).unwrap();
    let v0 = 1500.0;
    let mp = 16980.0 * std::f64::consts::PI * 25e-6 * 0.01;
    // The projectile's share of the initial momentum is all of it.
    let masses = node_masses(&start);
    assert_eq!(masses.len(), n);
    let p0 = momentum(&start, &masses);
    assert!((p0 / (-mp * v0) - 1.0).abs() < 1e-12, "{p0}");
    let p = momentum(&sim, &masses);
    println!(
        "2 us: projectile {:.1} m/s, momentum drift {:+.3e}, energy error {:.4}, pulverized {:.4}, max damage {:.3}, length {:.3} mm",
        o("projectile_velocity"),
        p / p0 - 1.0,
        o("energy_error"),
        o("pulverized_fraction"),
        o("max_damage"),
        o("projectile_extent") * 1e3
    );
    assert!(
        (p / p0 - 1.0).abs() < 0.01,
        "momentum drift {}",
        p / p0 - 1.0
    );
    let v = o("projectile_velocity");
    assert!(v < 0.95 * v0 && v > 0.8 * v0, "{v}");
    let plate: f64 = (0..n)
        .filter(|&i| body[i] == 1.0)
        .map(|i| masses[i] * sim.field("velocity").unwrap()[3 * i + 2])
        .sum();
    assert!(
        plate < 0.0 && (plate - (p - (-mp * v))).abs() < 1e-9 * p.abs(),
        "{plate}"
    );
    assert!(o("pulverized_fraction") > 0.0 && o("pulverized_fraction") < 0.05);
    assert!(
        (o("max_damage") - 0.75).abs() < 1e-12,
        "pulverized at the critical crack density"
    );
    assert!(o("projectile_extent") < 0.01);
    assert!(o("energy_error") < 0.05, "{}", o("energy_error"));
}

/// The node masses of a run (its `mass` field).
fn node_masses(sim: &Simulation) -> Vec<f64> {
    sim.field("mass")
        .expect("the penetration scene has a mass field")
}

/// A run saved mid-way (1 µs, the ceramic cracking) as JSON and restored
/// resumes to the bits of the run that was not interrupted, damage
/// included; a state whose damage variables are cut short is refused.
#[test]
fn a_penetration_run_saved_mid_way_resumes_to_the_same_bits() {
    let whole = coarse(1.5e-6);
    let mut scene = seed_scene();
    scene.set("particles_radial", 4.0).unwrap();
    scene.set("end_time", 1.5e-6).unwrap();
    let mut mid = Simulation::new(scene).unwrap();
    mid.advance_to(1e-6).unwrap();
    assert!(
        mid.observable("max_damage").unwrap() > 0.1,
        "cracks have grown"
    );
    let state: serde_json::Value = serde_json::from_slice(&mid.serialize_state()).unwrap();
    let mut back = Simulation::deserialize_state(&serde_json::to_vec(&state).unwrap()).unwrap();
    back.run().unwrap();
    assert_eq!(common::all_bits(&back), common::all_bits(&whole));
    // Cut the damage variables short: refused by name.
    let mut forged = state.clone();
    let damage = &mut forged["solver"]["Penetration"]["material_state"];
    let list = damage
        .as_array_mut()
        .expect("the damage variables are saved");
    list.pop();
    let e = Simulation::deserialize_state(&serde_json::to_vec(&forged).unwrap()).unwrap_err();
    assert_eq!(e.name(), "InvalidState", "{e}");
}

/// The quarter model saved mid-way resumes to the same bits; a saved state
/// with a node moved off or across a symmetry plane, or holding planes of
/// its own (they follow from the scene), is refused.
#[test]
fn a_quarter_model_saved_mid_way_resumes_and_a_forged_one_is_refused() {
    let whole = coarse_with(1.5e-6, &[("symmetry", 1.0)]);
    let mut scene = seed_scene();
    scene.set("particles_radial", 4.0).unwrap();
    scene.set("end_time", 1.5e-6).unwrap();
    scene.set("symmetry", 1.0).unwrap();
    let mut mid = Simulation::new(scene).unwrap();
    mid.advance_to(1e-6).unwrap();
    let state: serde_json::Value = serde_json::from_slice(&mid.serialize_state()).unwrap();
    let mut back = Simulation::deserialize_state(&serde_json::to_vec(&state).unwrap()).unwrap();
    back.run().unwrap();
    let bits = |s: &Simulation| {
        let mut v = s.observables();
        v.extend(s.field("position").unwrap());
        v.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
    };
    assert_eq!(bits(&back), bits(&whole));
    // The planes follow from the scene (the state holds none): a node on
    // x = 0 is on its plane, one off both planes is free.
    let pos = state["solver"]["Penetration"]["pos"]
        .as_array()
        .expect("the positions are saved");
    let at = |i: usize, d: usize| pos[i][d].as_f64().unwrap();
    let on = (0..pos.len())
        .find(|&i| at(i, 0) == 0.0 && at(i, 1) > 0.0)
        .expect("a node on x = 0");
    let free = (0..pos.len())
        .find(|&i| at(i, 0) > 0.0 && at(i, 1) > 0.0)
        .unwrap();
    let mut off = state.clone();
    off["solver"]["Penetration"]["pos"][on][0] = serde_json::json!(1e-4);
    let mut across = state.clone();
    across["solver"]["Penetration"]["pos"][free][1] = serde_json::json!(-1e-4);
    let mut given = state.clone();
    given["solver"]["Penetration"]["plane"] = serde_json::json!([]);
    for (what, forged) in [
        ("off its plane", off),
        ("across a plane", across),
        ("planes given", given),
    ] {
        let e = Simulation::deserialize_state(&serde_json::to_vec(&forged).unwrap()).unwrap_err();
        assert_eq!(e.name(), "InvalidState", "{what}: {e}");
    }
}

/// One thread and two give the same bits (contact pairs are resolved in
/// node order, sums taken serially).
#[test]
fn same_bits_on_one_thread_and_two() {
    common::same_on_one_thread_and_two(|| {
        let s = coarse(0.6e-6);
        (s.field("position"), s.field("damage"), s.observables())
    });
    // The quarter model, whose images are folded back in a fixed order.
    common::same_on_one_thread_and_two(|| {
        let s = coarse_with(2e-6, &[("symmetry", 1.0)]);
        (s.field("position"), s.field("velocity"), s.observables())
    });
    // Tensile planes whose flaws scatter by the node's index.
    common::same_on_one_thread_and_two(|| {
        let s = coarse_with(
            5e-6,
            &[
                ("symmetry", 1.0),
                ("plate_tensile_flaw_size", 188e-6),
                ("plate_tensile_flaw_scatter", 10.0),
            ],
        );
        (s.field("position"), s.field("damage"), s.observables())
    });
    // Cracks that shield their neighbours: the zones of the step's start,
    // each node's step tried again with the planes its zones hold.
    common::same_on_one_thread_and_two(|| {
        let s = coarse_with(
            5e-6,
            &[
                ("symmetry", 1.0),
                ("plate_tensile_flaw_size", 188e-6),
                ("plate_shield_radius", 5e-3),
                ("plate_tensile_flaw_scatter", 10.0),
            ],
        );
        (s.field("position"), s.field("damage"), s.observables())
    });
}

/// The seed's case at 3 nodes across, as a quarter model, at `speed`,
/// with `run_until` and `end_time`, the seed's AD85 (`ad85_seed`).
fn shot(speed: f64, until: &str, end_time: f64) -> Simulation {
    let mut scene = seed_scene();
    scene.set("particles_radial", 3.0).unwrap();
    scene.set("symmetry", 1.0).unwrap();
    scene.set("impact_speed", speed).unwrap();
    scene.set_str("run_until", until).unwrap();
    scene.set("end_time", end_time).unwrap();
    let mut sim = Simulation::new(scene).unwrap();
    sim.run().unwrap();
    sim
}

/// The shot's outcome is decided by the state and is final. At 3 across
/// (quarter model) a 1000 m/s shot perforates slowly: at 20 µs it is
/// still above the back face and undecided (measured: clearance −3.63 mm
/// at 456.3 m/s); with `run_until = outcome` the run goes on and ends when
/// the projectile is through and leaving (measured 29.06 µs, 378.4 m/s),
/// never as stopped. The oracle is the run continued 8 µs past that
/// decision with `run_until = end_time`: the projectile has gone further
/// below the back face (2.79 mm), still moves along its flight (332.4 m/s:
/// the fragments ahead of it still slow it), and is still perforated. A
/// 600 m/s shot stops (measured 40.67 µs, 78.4 m/s against the capture
/// speed `m_p V / (m_p + m_plate)` = 80.6 m/s); continued 10 µs it has not
/// crossed the back face (−6.76 mm, rebounding at 30.0 m/s) and is still
/// stopped.
#[test]
fn a_slow_perforation_is_not_called_stopped() {
    let o = |sim: &Simulation, name: &str| sim.observable(name).unwrap();
    let at_20 = shot(1000.0, "end_time", 20e-6);
    println!(
        "1000 m/s at 20 us: outcome {}, clearance {:.3} mm, {:.1} m/s",
        o(&at_20, "shot_outcome"),
        o(&at_20, "projectile_clearance") * 1e3,
        o(&at_20, "projectile_velocity")
    );
    assert_eq!(o(&at_20, "shot_outcome"), 0.0);
    assert!(o(&at_20, "projectile_clearance") < 0.0);
    for (speed, outcome, more) in [(1000.0, 1.0, 8e-6), (600.0, 2.0, 10e-6)] {
        let decided = shot(speed, "outcome", 1e-4);
        let t = decided.time();
        println!(
            "{speed} m/s: outcome {} at {:.2} us, clearance {:.3} mm, {:.1} m/s",
            o(&decided, "shot_outcome"),
            t * 1e6,
            o(&decided, "projectile_clearance") * 1e3,
            o(&decided, "projectile_velocity")
        );
        assert_eq!(o(&decided, "shot_outcome"), outcome, "{speed} m/s");
        assert!(t < 1e-4, "{speed} m/s decided at the cap");
        let later = shot(speed, "end_time", t + more);
        println!(
            "  {:.2} us later: outcome {}, clearance {:.3} mm, {:.1} m/s",
            more * 1e6,
            o(&later, "shot_outcome"),
            o(&later, "projectile_clearance") * 1e3,
            o(&later, "projectile_velocity")
        );
        assert_eq!(o(&later, "shot_outcome"), outcome, "{speed} m/s");
        if outcome == 1.0 {
            assert!(o(&later, "projectile_clearance") > o(&decided, "projectile_clearance"));
            assert!(o(&later, "projectile_velocity") > 0.0);
        } else {
            assert!(o(&later, "projectile_clearance") < 0.0);
        }
    }
}

/// The seed's case at 3 nodes across as the whole body (2546 nodes), run
/// to 20 µs with the scene's default scheme: the plate's rim is free, so
/// nothing outside acts on the two bodies, and the projectile, the plate's
/// pulverized fragments and the plate's remainder carry the impact
/// momentum between them, with either set of the ceramic's constants (the
/// nodal form's forces, the contact's impulses and the shifting's
/// conservative carry each conserve momentum); the issue asks 1 %, this
/// test 1e-9. Measured, of −20.004 kg m/s:
///
/// - the default, `ad85_seed`: −12.695, −3.179 and −4.130 kg m/s, the sum
///   to 3e-16; 8 % of the plate pulverized, energy error 0.43 %, through
///   at 951.9 m/s;
/// - `ad85_spall` (a0 = 100 µm): −15.861, −4.163 and +0.019 kg m/s, the
///   sum exact to round-off; 85 % of the plate pulverized, the remainder a
///   rim that springs back; energy error 0.50 %, through at 1189.3 m/s.
///
/// The energy errors are within taylor3d's 5 %.
#[test]
fn the_momentum_of_the_impact_is_shared_by_projectile_fragments_and_plate() {
    for seed in [true, false] {
        let mut scene = seed_scene();
        if !seed {
            scene.set_str("plate_ceramic", "ad85_spall").unwrap();
        }
        scene.set("particles_radial", 3.0).unwrap();
        let mut sim = Simulation::new(scene).unwrap();
        sim.run().unwrap();
        let o = |name: &str| sim.observable(name).unwrap();
        let (m, v) = (node_masses(&sim), sim.field("velocity").unwrap());
        let (body, loose) = (sim.field("body").unwrap(), sim.field("pulverized").unwrap());
        let mut parts = [0.0; 3];
        for i in 0..m.len() {
            let part = if body[i] == 0.0 {
                0
            } else if loose[i] == 1.0 {
                1
            } else {
                2
            };
            parts[part] += m[i] * v[3 * i + 2];
        }
        let mp = 16980.0 * std::f64::consts::PI * 25e-6 * 0.01;
        let impact = -mp * 1500.0;
        let sum: f64 = parts.iter().sum();
        println!(
            "{}: projectile {:.4}, fragments {:.4}, plate {:.4}: sum {sum:.6} of {impact:.6} kg m/s ({:+.2e}); \
             energy error {:.4}, pulverized {:.4}, outcome {}, {:.1} m/s",
            if seed { "ad85_seed" } else { "ad85_spall" },
            parts[0],
            parts[1],
            parts[2],
            sum / impact - 1.0,
            o("energy_error"),
            o("pulverized_fraction"),
            o("shot_outcome"),
            o("projectile_velocity")
        );
        assert!(
            (sum / impact - 1.0).abs() < 1e-9,
            "{parts:?} against {impact}"
        );
        // The projectile and the fragments move on along the shot; the
        // seed's plate, barely damaged, carries its share the same way.
        assert!(parts[0] < 0.0 && parts[1] < 0.0, "{parts:?}");
        if seed {
            assert!(parts[2] < 0.0, "{parts:?}");
        }
        assert!(o("energy_error") < 0.05);
        assert_eq!(o("shot_outcome"), 1.0);
    }
}

/// `plate_rim = clamped`: the plate's outer ring of nodes stays where it
/// started with zero velocity, the clamp takes part of the impact's
/// momentum (the free rim's bodies keep all of it), the energy balance
/// still closes, and the slow shot that the free plate carries away is
/// held back more by the clamped one. 3 nodes across, a plate 30 mm
/// across, 600 m/s, 15 us, the seed's AD85 (`ad85_seed`).
#[test]
fn a_clamped_rim_holds_its_ring_still() {
    let run = |rim: &str| {
        let mut scene = seed_scene();
        scene.set("particles_radial", 3.0).unwrap();
        scene.set("plate_diameter", 0.03).unwrap();
        scene.set("impact_speed", 600.0).unwrap();
        scene.set("end_time", 15e-6).unwrap();
        scene.set_str("plate_rim", rim).unwrap();
        let mut sim = Simulation::new(scene).unwrap();
        let start = sim.field("position").unwrap();
        sim.run().unwrap();
        (sim, start)
    };
    let (free, _) = run("free");
    let (clamped, start) = run("clamped");
    let (x, v) = (
        clamped.field("position").unwrap(),
        clamped.field("velocity").unwrap(),
    );
    let body = clamped.field("body").unwrap();
    // The plate's nodes within half a spacing of its rim (spacing 2.5 mm).
    let rim: Vec<usize> = (0..body.len())
        .filter(|&i| body[i] == 1.0 && start[3 * i].hypot(start[3 * i + 1]) >= 0.015 - 1.25e-3)
        .collect();
    assert!(rim.len() > 20, "{}", rim.len());
    for &i in &rim {
        assert_eq!(&x[3 * i..3 * i + 3], &start[3 * i..3 * i + 3], "node {i}");
        assert_eq!(&v[3 * i..3 * i + 3], &[0.0; 3], "node {i}");
    }
    let momentum = |sim: &Simulation| {
        let (m, v) = (node_masses(sim), sim.field("velocity").unwrap());
        (0..m.len()).map(|i| m[i] * v[3 * i + 2]).sum::<f64>()
    };
    let mp = 16980.0 * std::f64::consts::PI * 25e-6 * 0.01;
    let impact = -mp * 600.0;
    let (pf, pc) = (momentum(&free), momentum(&clamped));
    let o = |sim: &Simulation, name: &str| sim.observable(name).unwrap();
    println!(
        "free: momentum {pf:.5} of {impact:.5} kg m/s, projectile {:.1} m/s, energy error {:.4}; \
         clamped: {pc:.5} kg m/s, projectile {:.1} m/s, energy error {:.4}; {} rim nodes",
        o(&free, "projectile_velocity"),
        o(&free, "energy_error"),
        o(&clamped, "projectile_velocity"),
        o(&clamped, "energy_error"),
        rim.len()
    );
    assert!((pf / impact - 1.0).abs() < 1e-9);
    assert!(pc / impact < 0.99, "{pc} {impact}");
    assert!(o(&clamped, "projectile_velocity") < o(&free, "projectile_velocity"));
    assert!(o(&clamped, "energy_error") < 0.05);
}

/// What node shifting books over a run with the conservative carry (the
/// seed's case at 4 across to 8 µs: the projectile through the plate's
/// front half, the nodes of the crater shifting): the kinetic energy that
/// the carry changed, a part of the smoothing dissipation, is at most
/// 1e-3 of the impact energy and smaller than the run's energy error
/// (what the balance fails to account for), so the booking hides no loss
/// of energy larger than the balance's own error. Measured (153 steps):
/// −6.41 J, −4.27e-4 of the 15.0 kJ impact energy (the carry created a
/// little energy, net), at most 8.0e-6 of it in one step, against the
/// run's energy error of 4.73e-3 (0.09 of it) and the smoothing's 7.4 %.
#[test]
fn what_shifting_books_over_a_run_is_bounded() {
    use meshless_impact::internals::mlpg::penetration;
    let mut scene = seed_scene();
    scene.set("particles_radial", 4.0).unwrap();
    scene.set("end_time", 8e-6).unwrap();
    let mut run = penetration(&scene).unwrap();
    let initial = run.energies().initial;
    let (mut most, mut steps) = (0.0f64, 0u64);
    while !run.finished() {
        let before = run.run().shift_dissipation();
        run.step().unwrap();
        most = most.max((run.run().shift_dissipation() - before).abs());
        steps += 1;
    }
    let e = run.energies();
    let booked = run.run().shift_dissipation();
    println!(
        "{steps} steps: shifting booked {booked:e} J = {:e} of the impact energy {initial:e} J \
         (largest in one step {:e}); smoothing {:e}; energy error {:e}",
        booked / initial,
        most / initial,
        e.smoothing / initial,
        e.error
    );
    assert!(booked.abs() <= 1e-3 * initial, "{booked} J of {initial} J");
    assert!(
        booked.abs() < e.error * initial,
        "{booked} J against the energy error {} of {initial} J",
        e.error
    );
}

/// The seed's case with tensile crack planes (`plate_tensile_flaw_size` =
/// 188 µm, issue 68), quarter model at 4 across to 20 µs: it finishes
/// within taylor3d's 5 % energy bound (measured 0.76 %; EnergyDrift at
/// 8.9 µs while the shifted nodes whose cracks stand open took their
/// neighbours' stress and density), the projectile perforates, and the plate's
/// tensile planes split (crack density at the critical one) without the
/// plate pulverizing: a plate cracked in tension still holds compression.
/// `ad85_planes` at 800 m/s, quarter model at 6 across, to 8 µs: split
/// nodes under the rod's edge shift and keep their own stress, density
/// and openings, so the run passes the spacing collapse that stopped it at
/// 6.44 µs while they were held still, and stays within taylor3d's 5 %
/// energy bound (to 20 µs: 0.05 %; with the neighbours' stress and density
/// carried to them, EnergyDrift at 15.4 µs).
#[test]
fn split_nodes_shift_without_collapse_or_drift() {
    let mut scene = seed_scene();
    for (k, v) in [
        ("particles_radial", 6.0),
        ("symmetry", 1.0),
        ("impact_speed", 800.0),
        ("end_time", 8e-6),
    ] {
        scene.set(k, v).unwrap();
    }
    scene.set_str("plate_ceramic", "ad85_planes").unwrap();
    let mut sim = Simulation::new(scene).unwrap();
    sim.run().unwrap();
    let e = sim.observable("energy_error").unwrap();
    println!("ad85_planes, 800 m/s, 6 across: energy error {e:.5} at 8 us");
    assert!(e < 0.05, "{e}");
    let open = sim
        .field("damage")
        .unwrap()
        .iter()
        .filter(|g| **g >= 0.75)
        .count();
    assert!(open > 0, "no split node");
}

#[test]
fn a_plate_with_tensile_planes_cracks_and_conserves_energy() {
    let sim = coarse_with(
        20e-6,
        &[("symmetry", 1.0), ("plate_tensile_flaw_size", 188e-6)],
    );
    let o = |name: &str| sim.observable(name).unwrap();
    println!(
        "tensile planes: projectile {:.1} m/s, energy error {:.4}, damaged {:.3}, pulverized {:.3}, max damage {:.3}",
        o("projectile_velocity"),
        o("energy_error"),
        o("damaged_fraction"),
        o("pulverized_fraction"),
        o("max_damage")
    );
    assert!(o("energy_error") < 0.05, "{}", o("energy_error"));
    assert_eq!(o("shot_outcome"), 1.0);
    assert!((o("max_damage") - 0.75).abs() < 1e-12);
    assert!(o("damaged_fraction") > 0.5);
    assert_eq!(o("pulverized_fraction"), 0.0);
    // A crack across the hoop direction is one of the point's cracks: the
    // radial crack density never passes the crack density, and the planes'
    // orientation shows (some split node is split across another
    // direction than the hoop).
    let damage = sim.field("damage").unwrap();
    let radial = sim.field("radial_damage").unwrap();
    assert!(damage.iter().zip(&radial).all(|(g, r)| r <= g));
    assert!(
        damage
            .iter()
            .zip(&radial)
            .any(|(g, r)| *g >= 0.75 && *r < 0.75)
    );
    // Each node with a split plane gives the unit normal of its first one
    // (n_z >= 0, the hoop part >= 0), the others zero; some nodes split on
    // all three planes, none on more.
    let split = sim.field("split_planes").unwrap();
    let normal = sim.field("split_normal").unwrap();
    assert_eq!(normal.len(), 3 * split.len());
    for (k, n) in normal.chunks(3).enumerate() {
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if split[k] > 0.0 {
            assert!(
                (len - 1.0).abs() < 1e-9 && n[1] >= 0.0 && n[2] >= 0.0,
                "{n:?}"
            );
        } else {
            assert_eq!(len, 0.0, "{n:?}");
        }
    }
    assert!(split.contains(&3.0) && split.iter().all(|&s| s <= 3.0));
}

/// The radius of the radial-crack count must lie inside the plate: one at
/// or past the plate's radius is refused with an error that names it and
/// its value, and one past the range's 10 m when it is set.
#[test]
fn a_radial_crack_radius_outside_the_plate_is_refused_by_name() {
    let mut scene = seed_scene();
    scene.set("radial_crack_radius", 0.05).unwrap();
    let err = Simulation::new(scene).unwrap_err();
    assert_eq!(err.name(), "Inconsistent", "{err}");
    let text = err.to_string();
    assert!(
        text.contains("radial_crack_radius = 0.05") && text.contains("0.04"),
        "{text}"
    );
    let mut scene = seed_scene();
    let err = scene.set("radial_crack_radius", 10.5).unwrap_err();
    assert!(err.to_string().contains("radial_crack_radius"), "{err}");
}

/// Radial cracks on the rear face (issue 68): `ad85_planes` with a Weibull
/// scatter of m = 10, 4 across (whole body), 1500 m/s, to 8 µs, counted
/// outside the cone's footprint (`radial_crack_radius` = 25 mm, five
/// projectile radii): at least the four radial cracks that the issue asks
/// of a ceramic plate (measured 12; at 6 across 21, 26 and 9 at 800, 1500
/// and 2500 m/s by 12 µs, VALIDATION.md). Under the rod the plate is
/// comminuted, split on all three planes, over at least the projectile's
/// radius (measured 16.7 mm; 13 mm at 6 across), though no node
/// pulverizes.
#[test]
fn a_plate_with_tensile_planes_cracks_radially_outside_the_cone() {
    let count = |radius: f64| {
        let mut scene = seed_scene();
        scene.set_str("plate_ceramic", "ad85_planes").unwrap();
        for (k, v) in [
            ("particles_radial", 4.0),
            ("plate_tensile_flaw_scatter", 10.0),
            ("end_time", 8e-6),
            ("radial_crack_radius", radius),
        ] {
            scene.set(k, v).unwrap();
        }
        let mut sim = Simulation::new(scene).unwrap();
        sim.run().unwrap();
        let o = |name: &str| sim.observable(name).unwrap();
        assert!(o("energy_error") < 0.05, "{}", o("energy_error"));
        assert_eq!(o("pulverized_fraction"), 0.0);
        (o("radial_crack_count"), o("comminuted_radius"))
    };
    let (outside, comminuted) = count(0.025);
    println!("radial cracks at 25 mm: {outside}; comminuted radius {comminuted} m");
    assert!(outside >= 4.0, "{outside}");
    assert!(comminuted >= 5e-3, "{comminuted}");
}

/// The plate of JH-2 (`plate_model = jh2`, the 1994 example ceramic of the
/// `jh_` block; issue 68), quarter model at 4 across to 20 µs at 1500 m/s:
/// the rod perforates within taylor3d's 5 % energy bound (measured
/// 1291.4 m/s, 0.75 %), the damage D stays in [0, 1] and reaches 1 under
/// the rod, where the fractured nodes make a comminuted zone; a run saved
/// mid-way (in JSON, with its JH-2 points) resumes to the bits of the run
/// that was not stopped; a JH-2 constant out of its range is refused by its
/// `jh_` name.
#[test]
fn a_jh2_plate_is_perforated_damaged_and_resumes_to_the_same_bits() {
    let scene_until = |t: f64| {
        let mut scene = seed_scene();
        scene.set_str("plate_model", "jh2").unwrap();
        for (k, v) in [
            ("particles_radial", 4.0),
            ("symmetry", 1.0),
            ("end_time", t),
        ] {
            scene.set(k, v).unwrap();
        }
        scene
    };
    let mut sim = Simulation::new(scene_until(20e-6)).unwrap();
    sim.run().unwrap();
    let o = |name: &str| sim.observable(name).unwrap();
    println!(
        "JH-2 plate: {:.1} m/s, energy {:.4}, damaged {:.3}, comminuted {:.4} m",
        o("projectile_velocity"),
        o("energy_error"),
        o("damaged_fraction"),
        o("comminuted_radius")
    );
    assert_eq!(o("shot_outcome"), 1.0);
    assert!(o("energy_error") < 0.05, "{}", o("energy_error"));
    assert_eq!(o("max_damage"), 1.0);
    assert!(o("comminuted_radius") >= 5e-3, "{}", o("comminuted_radius"));
    let d = sim.field("damage").unwrap();
    assert!(d.iter().all(|x| (0.0..=1.0).contains(x)));
    // Saved mid-way and resumed: the same bits.
    let mut whole = Simulation::new(scene_until(3e-6)).unwrap();
    whole.run().unwrap();
    let mut mid = Simulation::new(scene_until(3e-6)).unwrap();
    mid.advance_to(1.5e-6).unwrap();
    assert!(mid.observable("max_damage").unwrap() > 0.0);
    let mut back = Simulation::deserialize_state(&mid.serialize_state()).unwrap();
    back.run().unwrap();
    assert_eq!(common::all_bits(&back), common::all_bits(&whole));
    // A constant out of range, by name.
    let mut bad = scene_until(1e-6);
    let e = bad.set("jh_d1", -1.0).unwrap_err();
    assert!(e.to_string().contains("jh_d1"), "{e}");
}
