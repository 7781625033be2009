//! The 3-D MLPG solver's time loop (`src/mlpg/solver.rs`): elastic waves
//! in a rod on the rigid anvil against the wave speeds of elasticity, the
//! elastic rebound of a Taylor rod, and the determinism of the loop.

use meshless_impact::material::bilinear::Bilinear;
use meshless_impact::material::eos::LinearEos;
use meshless_impact::material::{Damage, Eos, Material, Strength};
use meshless_impact::mlpg::{Cylinder, Mlpg3d, RodSetup};

/// House test 7's 4340 steel constants (Pa, kg/m³).
const K: f64 = 169.1e9;
const G: f64 = 82.9e9;
const RHO: f64 = 7830.0;

/// Young's modulus of K and G.
fn youngs() -> f64 {
    9.0 * K * G / (3.0 * K + G)
}

/// An elastic steel: a bilinear strength whose yield stress is never reached.
fn elastic() -> Material {
    Material {
        eos: Eos::Linear(LinearEos {
            bulk_modulus: K,
            density: RHO,
        }),
        strength: Strength::Bilinear(Bilinear {
            yield_stress: 1e15,
            hardening_modulus: 0.0,
        }),
        damage: Damage::None,
        shear_modulus: G,
        specific_heat: 460.0,
        taylor_quinney: 0.0,
        reference_temperature: 293.0,
    }
}

/// Exploration: an elastic Taylor impact at 10 m/s, printed.
#[test]
#[ignore = "exploration"]
fn explore_elastic_rebound() {
    let rings: usize = std::env::var("RINGS")
        .map(|s| s.parse().unwrap())
        .unwrap_or(3);
    let zeta: f64 = std::env::var("ZETA")
        .map(|s| s.parse().unwrap())
        .unwrap_or(0.1);
    let cyl = Cylinder {
        radius: 2e-3,
        length: 20e-3,
    };
    let mut setup = RodSetup::new(cyl, rings, 10.0, 40e-6);
    setup.damping = zeta;
    let mut s = Mlpg3d::new(setup, elastic()).unwrap();
    let cbar = (youngs() / RHO).sqrt();
    let t0 = std::time::Instant::now();
    let mut k = 0;
    while !s.finished() {
        if let Err(e) = s.step() {
            println!("error {e}");
            break;
        }
        k += 1;
        if k % 20 == 0 {
            let e = s.energies();
            let r = s.rod();
            println!(
                "t {:.3} us len/L0-1 {:.3e} tail {:.3} KE {:.3e} int {:.3e} damp {:.3e} cont {:.3e} err {:.3e} rebuilds {} contact {}",
                s.time() * 1e6,
                r.rod_length / cyl.length - 1.0,
                r.tail_velocity,
                e.kinetic / e.initial,
                e.internal / e.initial,
                e.damping / e.initial,
                e.contact / e.initial,
                e.error,
                s.rebuilds(),
                s.in_contact().iter().filter(|&&c| c).count()
            );
        }
    }
    let e = s.energies();
    let r = s.rod();
    println!(
        "{} nodes, {} steps, {:.2} s; release {:.4} us vs 2L/cbar {:.4} us; length/L0-1 {:.3e}; tail {:.3}; energy error {:.3e}, damping {:.3e}, contact {:.3e}",
        s.particles(),
        s.steps(),
        t0.elapsed().as_secs_f64(),
        s.last_release() * 1e6,
        2.0 * cyl.length / cbar * 1e6,
        r.rod_length / cyl.length - 1.0,
        r.tail_velocity,
        e.error,
        e.damping / e.initial,
        e.contact / e.initial
    );
}
