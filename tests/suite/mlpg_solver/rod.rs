//! The elastic Taylor rod of the 3-D solver's tests (house test 7's
//! 4340 steel, elastic) and its rebound from the anvil, and the 3-D solver
//! of a `taylor3d` scene: shared by `tests/suite/mlpg_solver.rs` and the
//! explorations of `examples/explore/` (which include this file by its
//! path).

use meshless_impact::internals::mlpg::{Cylinder, Forces, Mlpg3d, RodSetup};
use meshless_impact::materials::{Bilinear, Damage, Eos, LinearEos, Material, Strength};
use meshless_impact::{Scene, Taylor3dParams};

/// House test 7's 4340 steel constants (Pa, kg/m³).
pub(crate) const K: f64 = 169.1e9;

pub(crate) const G: f64 = 82.9e9;

pub(crate) const RHO: f64 = 7830.0;

/// Young's modulus of K and G.
pub(crate) fn youngs() -> f64 {
    9.0 * K * G / (3.0 * K + G)
}

/// An elastic steel: a bilinear strength whose yield stress is never reached.
pub(crate) fn elastic() -> Material {
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

/// The fraction of a velocity step reached where the front of a 3-D bar
/// is at `z = c_bar t`: in Skalak's asymptotic solution of the
/// Pochhammer-Chree bar (1957), the step rises as `1/3 + ∫₀ˣ Ai(−s) ds`
/// with `x ∝ (c_bar t − z) / z^{1/3}`, so the level 1/3 moves at c_bar
/// while the mid-height lags behind by a distance growing as `z^{1/3}`.
pub(crate) const SKALAK: f64 = 1.0 / 3.0;

/// The short elastic rod of these checks: R0 = 2 mm, L0 = 20 mm.
pub(crate) const ROD: Cylinder = Cylinder {
    radius: 2e-3,
    length: 20e-3,
};

/// Runs an elastic impact of `ROD` at 10 m/s on `rings` rings with the
/// velocity smoothing `smoothing` (no damping) until it leaves the anvil; returns the run, the
/// times the mean axial velocity of the layers at L0/4 and 3 L0/4 first
/// fell by [`SKALAK`] of the impact speed (the front's passing), and the
/// time the anvil's pressure ([`face_traction`]) fell to zero after the
/// first transit (linear between steps).
pub(crate) fn elastic_rebound(rings: usize, smoothing: f64) -> (Mlpg3d, [f64; 2], f64) {
    elastic_rebound_with(rings, smoothing, Forces::Sphere)
}

/// [`elastic_rebound`] with the weak form `form`.
pub(crate) fn elastic_rebound_with(
    rings: usize,
    smoothing: f64,
    form: Forces,
) -> (Mlpg3d, [f64; 2], f64) {
    let v0 = 10.0;
    let mut setup = RodSetup::new(ROD, rings, v0, 40e-6);
    setup.scheme.smoothing = smoothing;
    setup.scheme.forces = form;
    let mut s = Mlpg3d::new(setup, elastic()).unwrap();
    let stations = [0.25 * ROD.length, 0.75 * ROD.length];
    let dz = s.lattice().axial_spacing;
    let layers: Vec<Vec<usize>> = stations
        .iter()
        .map(|&z| {
            let nearest = (z / dz).round() * dz;
            (0..s.particles())
                .filter(|&i| (s.lattice().position[i][2] - nearest).abs() < 1e-3 * dz)
                .collect()
        })
        .collect();
    let mean = |s: &Mlpg3d, l: &[usize]| -> f64 {
        let (m, v) = (s.masses(), s.velocities());
        let total: f64 = l.iter().map(|&i| m[i]).sum();
        -l.iter().map(|&i| m[i] * v[i][2]).sum::<f64>() / total
    };
    let mut passing = [f64::NAN; 2];
    let mut last = (0.0, [v0; 2]);
    let mut traction = (0.0, -1.0);
    let mut unloaded = f64::NAN;
    let transit = ROD.length / (youngs() / RHO).sqrt();
    while !s.finished() {
        s.step().unwrap();
        let now = [mean(&s, &layers[0]), mean(&s, &layers[1])];
        let t = face_traction(&s);
        if unloaded.is_nan() && s.time() > transit && t >= 0.0 && traction.1 < 0.0 {
            unloaded = traction.0 + (s.time() - traction.0) * traction.1 / (traction.1 - t);
        }
        traction = (s.time(), t);
        for k in 0..2 {
            if passing[k].is_nan() && now[k] <= (1.0 - SKALAK) * v0 {
                let (a, b) = (
                    last.1[k] - (1.0 - SKALAK) * v0,
                    now[k] - (1.0 - SKALAK) * v0,
                );
                passing[k] = last.0 + (s.time() - last.0) * a / (a - b);
            }
        }
        last = (s.time(), now);
    }
    assert!(s.at_rest() && s.time() < 40e-6, "the rod left the anvil");
    let z: Vec<f64> = layers
        .iter()
        .map(|l| s.lattice().position[l[0]][2])
        .collect();
    assert!((z[1] - z[0] - 0.5 * ROD.length).abs() < dz);
    (s, passing, unloaded)
}

/// The mean axial stress of the face nodes (the lattice's face set),
/// weighted by their masses (their shares of the face's area): the anvil's
/// pressure on the rod as its stresses give it (Pa, negative in
/// compression).
pub(crate) fn face_traction(s: &Mlpg3d) -> f64 {
    let face = &s.lattice().sets.face;
    let (m, stress) = (s.masses(), s.stress());
    let total: f64 = face.iter().map(|&i| m[i]).sum();
    face.iter().map(|&i| m[i] * stress[i][2]).sum::<f64>() / total
}

/// The relative errors of an elastic rebound ([`elastic_rebound`]): the
/// front's speed against c_bar = √(E/ρ), the contact time against
/// 2 L0 / c_bar, the length at release against L0.
pub(crate) fn rebound_errors(s: &Mlpg3d, passing: [f64; 2]) -> [f64; 3] {
    let cbar = (youngs() / RHO).sqrt();
    let dz = s.lattice().axial_spacing;
    let gap = ((0.75 * ROD.length / dz).round() - (0.25 * ROD.length / dz).round()) * dz;
    [
        gap / (passing[1] - passing[0]) / cbar - 1.0,
        s.last_release() / (2.0 * ROD.length / cbar) - 1.0,
        s.rod().rod_length / ROD.length - 1.0,
    ]
}

/// The 3-D solver of a `taylor3d` scene, with the scene's material choice.
pub(crate) fn build3d(scene: &Scene) -> Mlpg3d {
    let material = scene
        .kind()
        .material()
        .unwrap()
        .material(meshless_impact::materials::Prefix::None, |n| scene.get(n))
        .unwrap();
    Taylor3dParams::of(scene).build_with(material).unwrap()
}
