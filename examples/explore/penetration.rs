//! The seed's penetration case traced (moved from
//! `tests/suite/penetration.rs`).

use meshless_impact::internals::mlpg::{Cylinder, Penetration, PenetrationSetup, RodSetup};
use meshless_impact::materials::{Material, PRESETS, RajendranGrove};

/// Exploration: the seed's case, printed as it runs (`MI_RINGS` rings,
/// `MI_ALPHA` smoothing, `MI_SHIFT` shifting, `MI_END` end time,
/// `MI_WEAK=1` the nodal weak form, `MI_ORDER` the smoothing's order,
/// `MI_QUARTER=1` the quarter model); with
/// `MI_DIAGNOSE=e`, the nodes that gain the most kinetic energy in the
/// first three steps past the energy error `e`; at a stop, the closest
/// pair of one body.
/// `MI_RINGS=4 cargo test --release --test suite penetration:: -- --ignored --nocapture explore`
pub fn explore_seed_case() {
    let rings = std::env::var("MI_RINGS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(4);
    let end = std::env::var("MI_END")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20e-6);
    let alpha = std::env::var("MI_ALPHA")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0.1);
    let mut run = seed_case(rings, end, alpha);
    println!(
        "nodes {} reach {:e}",
        run.particles(),
        run.run().contact_reach()
    );
    let clock = std::time::Instant::now();
    let mut next = 0.0;
    let diagnose: f64 = std::env::var("MI_DIAGNOSE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(f64::INFINITY);
    let mut shown = 0;
    while !run.finished() {
        let v_before = run.run().velocities().to_vec();
        let step = run.step();
        if step.is_ok() && run.energies().error > diagnose && shown < 3 {
            shown += 1;
            let (x, v, m) = (
                run.run().positions(),
                run.run().velocities(),
                run.run().masses(),
            );
            let g = run.run().group();
            let pul = run.field("pulverized").unwrap();
            let surf = &run.run().lattice().surfaces;
            let mut gain: Vec<(f64, usize)> = (0..x.len())
                .map(|i| {
                    let ke = |u: &[f64; 3]| 0.5 * m[i] * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
                    (ke(&v[i]) - ke(&v_before[i]), i)
                })
                .collect();
            let total: f64 = gain.iter().map(|g| g.0).sum();
            gain.sort_by(|a, b| b.0.total_cmp(&a.0));
            println!(
                "t {:.3} us: KE change of the step {total:.2} J; largest gains:",
                run.time() * 1e6
            );
            for &(d, i) in gain.iter().take(8) {
                let r = (x[i][0] * x[i][0] + x[i][1] * x[i][1]).sqrt();
                println!(
                    "  node {i} body {} surf {} pulv {} r {:.2} mm z {:.2} mm |v| {:.0} m/s dKE {d:.3} J",
                    g[i],
                    surf[i].0,
                    pul[i],
                    r * 1e3,
                    x[i][2] * 1e3,
                    (v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2]).sqrt()
                );
            }
        }
        if let Err(e) = step {
            println!("stopped: {e}");
            let x = run.run().positions();
            let g = run.run().group();
            let pul = run.field("pulverized").unwrap();
            let mut best = (f64::INFINITY, 0, 0);
            for i in 0..x.len() {
                for j in i + 1..x.len() {
                    if g[i] == g[j] {
                        let d = meshless_impact::internals::mlpg::distance(&x[i], &x[j]);
                        if d < best.0 {
                            best = (d, i, j);
                        }
                    }
                }
            }
            let (d, i, j) = best;
            println!(
                "closest pair {i} {j} body {} d {d:e}: {:?} {:?} pulverized {} {}",
                g[i], x[i], x[j], pul[i], pul[j]
            );
            break;
        }
        if run.time() >= next {
            next += 1e-6;
            let o = run.observables();
            println!(
                "t {:6.2} us  v {:8.1}  L {:6.3} mm  hole {:6.3} mm  dmg {:.3} pulv {:.3} max {:.3}  KE {:8.1} IE {:8.1} C {:8.1} S {:6.1} err {:.4}  ({:.1} s)",
                run.time() * 1e6,
                o[0],
                o[1] * 1e3,
                o[2] * 1e3,
                o[3],
                o[4],
                o[5],
                o[6],
                o[7],
                o[8],
                o[9],
                o[10],
                clock.elapsed().as_secs_f64()
            );
        }
    }
    println!(
        "final: {:?} after {} steps, {:.1} s\n{}",
        run.observables(),
        run.steps(),
        clock.elapsed().as_secs_f64(),
        run.run().profile().table()
    );
}

fn tungsten() -> Material {
    PRESETS
        .iter()
        .find(|p| p.name == "tungsten_seed")
        .expect("the tungsten preset")
        .material()
        .expect("a valid preset")
}

fn seed_case(rings: usize, end_time: f64, smoothing: f64) -> Penetration {
    let setup = PenetrationSetup {
        plate: Cylinder {
            radius: 40e-3,
            length: 5e-3,
        },
        until_outcome: false,
        clamped_rim: false,
        node_order: meshless_impact::internals::mlpg::NodeOrder::Rings,
        radial_crack_radius: 0.0,
    };
    let projectile = Cylinder {
        radius: 5e-3,
        length: 10e-3,
    };
    let mut numerics = RodSetup::new(projectile, rings, 1500.0, end_time);
    numerics.scheme.smoothing = smoothing;
    numerics.scheme.shifting = std::env::var("MI_SHIFT")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0.0);
    if std::env::var("MI_WEAK").is_ok_and(|w| w == "1") {
        numerics.scheme.forces = meshless_impact::internals::mlpg::Forces::Nodal;
    }
    if std::env::var("MI_ORDER").is_ok_and(|o| o == "2") {
        numerics.scheme.order = meshless_impact::internals::mlpg::SmoothingOrder::Two;
    }
    numerics.quarter = std::env::var("MI_QUARTER").is_ok_and(|w| w == "1");
    Penetration::new(
        setup,
        tungsten(),
        Material::ceramic(RajendranGrove::ad85(), 880.0, 1.0, 293.0),
        numerics,
    )
    .expect("the seed's case builds")
}
