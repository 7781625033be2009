//! Unit tests of the 3-D solver's passes (`motion.rs`, `update.rs` and the
//! collocated gradient of eq. 4 they use), each on a small hand-made node
//! set and against an analytic result, not a number recorded from a run
//! (issue 67, item 4).
//!
//! The node set is a 4 × 4 × 4 cubic grid of spacing [`H`] with each node
//! moved by up to 0.2 H along each axis (a fixed draw), so that no moment
//! matrix is symmetric by accident; its supports, MLS shapes at the nodes
//! and their transpose are built by the constructors the solver's build
//! uses ([`Supports::compute`], [`NodalShapes::build`],
//! [`NodalOperator::build`]), and the passes are called on hand-set fields.
//!
//! Tolerances are stated at each test: a bound of the round-off of the
//! sums the pass forms, relative to the size of their terms.

use super::geometry::Geometry;
use super::motion::{self, Frame};
use super::scratch::{ContactBuffers, ImageBuffers, Kick, Move, SmoothingBuffers, Tally};
use super::spheres::cross;
use super::update::{MaterialFields, MaterialInputs, update_material};
use super::*;
use crate::approx::mls::NodalShapes;
use crate::approx::mls::SupportParams;
use crate::approx::mls::Supports;
use crate::approx::nodal::NodalOperator;
use crate::material::PointState;

/// The spacing of the hand-made grid (m).
const H: f64 = 1e-3;
/// The density of the nodes (kg/m³).
const RHO: f64 = 7830.0;
/// The step of the passes (s): a node at 300 m/s moves 0.03 H.
const DT: f64 = 1e-7;
/// The machine epsilon.
const EPS: f64 = f64::EPSILON;

/// The 4 × 4 × 4 grid of spacing `H` in [0, 3 H]³ raised by `H` (every node
/// above the anvil's plane z = 0 by at least 0.8 H), each node moved by up
/// to 0.2 H along each axis.
fn grid() -> Vec<[f64; 3]> {
    let mut rnd = crate::test_rng::rng(67);
    let mut pts = Vec::with_capacity(64);
    for k in 0..4 {
        for j in 0..4 {
            for i in 0..4 {
                let p = [i as f64, j as f64, k as f64 + 1.0];
                pts.push(p.map(|c| (c + 0.4 * (rnd() - 0.5)) * H));
            }
        }
    }
    pts
}

/// The nodes' masses, `ρ H³` times 0.9 to 1.1 (unequal, so that a pass
/// that confused two nodes' masses shows), and their densities.
fn masses(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut rnd = crate::test_rng::rng(4);
    let mass = (0..n)
        .map(|_| RHO * H * H * H * (0.9 + 0.2 * rnd()))
        .collect();
    (mass, vec![RHO; n])
}

/// The geometry of the nodes `pts` as the solver's build makes it for the
/// whole body in the nodal form: supports, MLS shapes at the nodes (with
/// their gradients) and their transpose (the order-2 smoothing's `Hᵀ`).
fn geometry(pts: &[[f64; 3]]) -> Geometry {
    let sup = Supports::compute(pts, SupportParams::default()).expect("supports");
    let shapes = NodalShapes::build(pts, &sup).expect("shapes");
    let nodal = NodalOperator::build(&shapes, pts.len());
    Geometry {
        supports: Some(sup),
        shapes,
        nodal,
        rows: std::iter::once(0..pts.len()).collect(),
        ..Geometry::default()
    }
}

/// The frame of the passes: the nodal form, spacing and reach `H`, no
/// symmetry planes, no held rim.
fn frame<'a>(g: &'a Geometry, mass: &'a [f64], rho: &'a [f64], group: &'a [u8]) -> Frame<'a> {
    Frame {
        dt: DT,
        now: 0.0,
        nodal: true,
        spacing: H,
        reach: H,
        geometry: g,
        mass,
        rho,
        group,
        plane: &[],
        held: &[],
        ranks: &crate::ranks::Alone,
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|d| a[d] - b[d])
}

/// The total momentum `Σ m v` and its scale `Σ m |v|`.
fn momentum(vel: &[[f64; 3]], mass: &[f64]) -> ([f64; 3], f64) {
    let mut p = [0.0; 3];
    let mut scale = 0.0;
    for (v, m) in vel.iter().zip(mass) {
        for d in 0..3 {
            p[d] += m * v[d];
        }
        scale += m * norm(*v);
    }
    (p, scale)
}

/// For each node, the scale of the sum of the collocated gradient (eq. 4)
/// of `vel`: `Σ_J |v_J| |∇φ_J(x_i)|`, the size of its terms.
fn gradient_scale(shapes: &NodalShapes, vel: &[[f64; 3]]) -> Vec<f64> {
    (0..shapes.len())
        .map(|i| {
            shapes
                .row(i)
                .map(|q| norm(vel[shapes.nodes[q]]) * norm(shapes.grad[q]))
                .sum()
        })
        .collect()
}

/// What the material pass wrote, from the reference state.
struct MaterialOut {
    dev: Vec<Full>,
    pressure: Vec<f64>,
    eps_p: Vec<f64>,
    temp: Vec<f64>,
    rho: Vec<f64>,
    visc: Vec<Full>,
    results: Vec<std::result::Result<Tally, (usize, Error)>>,
}

/// The material pass (`update_material`) of one step `DT` with the
/// velocity gradients `grad`, from the reference state: no stress, no
/// plastic strain, the reference temperature, the densities `rho0`.
fn material_pass(
    material: &Material,
    mass: &[f64],
    vel: &[[f64; 3]],
    grad: &[[[f64; 3]; 3]],
    rho0: &[f64],
    damping_time: f64,
) -> MaterialOut {
    let n = mass.len();
    let mut out = MaterialOut {
        dev: vec![[0.0; 6]; n],
        pressure: vec![0.0; n],
        eps_p: vec![0.0; n],
        temp: vec![material.reference_temperature; n],
        rho: rho0.to_vec(),
        visc: vec![[0.0; 6]; n],
        results: vec![Ok(Tally::default()); n],
    };
    let mut states = vec![PointState::default(); n];
    update_material(
        (&crate::ranks::Alone, &mut Default::default(), true),
        &MaterialInputs {
            dt: DT,
            damping_time,
            rod: material,
            others: &[],
            group: &[],
            mass,
            vel,
            grad,
            shielding: None,
        },
        MaterialFields {
            dev: &mut out.dev,
            pressure: &mut out.pressure,
            eps_p: &mut out.eps_p,
            temp: &mut out.temp,
            rho: &mut out.rho,
            visc: &mut out.visc,
            states: &mut states,
        },
        &mut out.results,
    );
    out
}

/// The velocity smoothing (`motion::smooth`, orders 1 and 2) leaves a
/// uniform velocity field unchanged and removes no kinetic energy.
///
/// Analytic result: the smoothing moves `v_i` by `α (Φ v − v)_i` (order 1)
/// or `−α (M⁻¹ Hᵀ M H v)_i` (order 2), and `H v = v (1 − Σ_J φ_J(x_i)) = 0`
/// for a uniform `v` by the partition of unity of the MLS shapes.
///
/// Tolerance: the partition of unity holds to the round-off of the MLS
/// solve (the shapes' own test bounds `|Σ φ − 1|` by 1e-12), so each
/// velocity moves by at most `1e-12 |v|`, and the kinetic energy removed,
/// a sum of `m v·Δv` over 64 nodes, is at most `1e-12` of the kinetic
/// energy (measured: 4e-16 `|v|` and 3e-16 of the energy). A field with
/// noise is changed (the pass ran).
#[test]
fn smoothing_keeps_a_uniform_velocity_and_removes_no_energy() {
    let pts = grid();
    let n = pts.len();
    let g = geometry(&pts);
    let (mass, rho) = masses(n);
    let frame = frame(&g, &mass, &rho, &[]);
    let u = [12.0, -7.0, -300.0];
    let contact = vec![false; n];
    let energy = kinetic(&vec![u; n], &mass);
    let mut buffers = SmoothingBuffers {
        smooth: vec![[0.0; 3]; n],
        defect: vec![[0.0; 3]; n],
        pass: vec![[0.0; 3]; n],
        wire: Vec::new(),
    };
    let mut ext = Vec::new();
    for order in [1, 2] {
        let mut vel = vec![u; n];
        let removed = motion::smooth(
            &frame,
            (0.3, order),
            &mut vel,
            &contact,
            &mut buffers,
            &mut ext,
        );
        let moved = vel.iter().map(|v| norm(sub(*v, u))).fold(0.0, f64::max);
        assert!(
            moved <= 1e-12 * norm(u),
            "order {order}: a uniform velocity moved by {moved:e} m/s"
        );
        assert!(
            removed.abs() <= 1e-12 * energy,
            "order {order}: the smoothing removed {removed:e} J of {energy:e} J"
        );
        // The pass ran: a field with noise is changed.
        let mut rnd = crate::test_rng::rng(5);
        let noisy: Vec<[f64; 3]> = (0..n)
            .map(|_| std::array::from_fn(|d| u[d] + 10.0 * (rnd() - 0.5)))
            .collect();
        let mut vel = noisy.clone();
        motion::smooth(
            &frame,
            (0.3, order),
            &mut vel,
            &contact,
            &mut buffers,
            &mut ext,
        );
        assert!(vel.iter().zip(&noisy).any(|(a, b)| norm(sub(*a, *b)) > 0.1));
    }
}

/// The position update (`motion::drift`) moves every node by `dt v`, with
/// or without the anvil while no node reaches it, and keeps the
/// velocities; with the anvil, a node that reaches z = 0 stops on it, its
/// velocity toward the anvil gone and booked as `½ m v_z²`.
///
/// Tolerance: `x + dt v` rounded twice (product and sum), at most
/// `2 ε (|x| + dt |v|)` per component; the booked energy is one product
/// of three factors, `4 ε` relative.
#[test]
fn drift_moves_every_node_by_dt_times_its_velocity() {
    let pts = grid();
    let n = pts.len();
    let g = geometry(&pts);
    let (mass, rho) = masses(n);
    let frame = frame(&g, &mass, &rho, &[]);
    let mut rnd = crate::test_rng::rng(11);
    let vel0: Vec<[f64; 3]> = (0..n)
        .map(|_| std::array::from_fn(|_| 600.0 * (rnd() - 0.5)))
        .collect();
    let kicks = vec![Kick::default(); n];
    for anvil in [false, true] {
        let (mut pos, mut vel) = (pts.clone(), vel0.clone());
        let mut contact = vec![false; n];
        let mut moves = vec![Move::default(); n];
        motion::drift(
            &frame,
            anvil,
            &mut vel,
            &mut pos,
            &mut contact,
            &kicks,
            &mut moves,
        );
        for i in 0..n {
            for d in 0..3 {
                let want = pts[i][d] + DT * vel0[i][d];
                let tol = 2.0 * EPS * (pts[i][d].abs() + DT * vel0[i][d].abs());
                assert!(
                    (pos[i][d] - want).abs() <= tol,
                    "anvil {anvil}, node {i}, axis {d}: {:e} m, not {want:e} m",
                    pos[i][d]
                );
            }
            assert_eq!(vel[i], vel0[i], "node {i}: the drift changed a velocity");
            assert!(!contact[i] && moves[i].lost == 0.0 && moves[i].through.is_none());
        }
    }
    // A node 0.1 H above the anvil moving down by 0.15 H in the step.
    let (mut pos, mut vel) = (pts.clone(), vel0.clone());
    pos[0][2] = 0.1 * H;
    vel[0] = [30.0, -40.0, -0.15 * H / DT];
    let v = vel[0];
    let mut contact = vec![false; n];
    let mut moves = vec![Move::default(); n];
    motion::drift(
        &frame,
        true,
        &mut vel,
        &mut pos,
        &mut contact,
        &kicks,
        &mut moves,
    );
    assert_eq!(pos[0][2], 0.0, "the node stops on the anvil");
    for d in 0..2 {
        let want = pts[0][d] + DT * v[d];
        assert!((pos[0][d] - want).abs() <= 2.0 * EPS * (pts[0][d].abs() + DT * v[d].abs()));
    }
    assert_eq!(vel[0], [v[0], v[1], 0.0]);
    assert!(contact[0] && moves[0].through.is_none());
    let lost = 0.5 * mass[0] * v[2] * v[2];
    assert!(
        (moves[0].lost - lost).abs() <= 4.0 * EPS * lost,
        "booked {:e} J, not ½ m v_z² = {lost:e} J",
        moves[0].lost
    );
}

/// The collocated velocity gradient (eq. 4) of a rigid rotation with a
/// translation, `v = u + ω × (x − c)`, has a zero symmetric part (no rate
/// of deformation) and the rotation's spin as its skew part; the material
/// pass (`update_material`) given it leaves the deviatoric stress, the
/// pressure, the plastic strain, the viscous stress and the temperature
/// at zero (or where they were) and the density unchanged.
///
/// Analytic result: `∇v = [ω]×` exactly (skew), and a material at rest in
/// its reference state spun rigidly stays there (the Jaumann rate of a zero
/// stress is zero).
///
/// Tolerance: the gradient is a sum over the covering nodes of terms of
/// size `s_i = Σ_J |v_J| |∇φ_J(x_i)|` whose exact sum has no symmetric
/// part, and the MLS shapes reproduce linear fields to the round-off of
/// their solve: `|sym ∇v| ≤ 1e-12 s_i` (measured 6e-16 `s_i`; `s_i` is up
/// to 8e5 1/s here, a hundred times `|ω|`: the translation's share). The
/// material's fields then move by what that round-off rate makes in one
/// step: `|ΔS| ≤ 2 μ dt D`, `|Δp| ≤ K dt 3 D`, `|Δρ| ≤ ρ dt 3 D` with
/// `D = 1e-12 max s_i` (measured: `|ΔS|` 3e-6 Pa against a bound of
/// 1.3e-2 Pa, `Δp` and `Δρ` zero), and a stress that far below yield makes
/// no plastic strain and no heat (exactly).
#[test]
fn a_rigid_rotation_makes_no_strain() {
    let pts = grid();
    let n = pts.len();
    let g = geometry(&pts);
    let (mass, rho0) = masses(n);
    let omega = [3e3, -5e3, 8e3];
    let (u, c) = ([5.0, -3.0, -200.0], [1.5 * H, 1.5 * H, 2.5 * H]);
    let vel: Vec<[f64; 3]> = pts
        .iter()
        .map(|x| {
            let w = cross(omega, sub(*x, c));
            std::array::from_fn(|d| u[d] + w[d])
        })
        .collect();
    let mut grad = vec![[[0.0; 3]; 3]; n];
    g.shapes.velocity_gradients(&vel, &mut grad);
    let scale = gradient_scale(&g.shapes, &vel);
    // ∂v_a/∂x_b of ω × x: [[0, −ω_z, ω_y], [ω_z, 0, −ω_x], [−ω_y, ω_x, 0]].
    let spin = [
        [0.0, -omega[2], omega[1]],
        [omega[2], 0.0, -omega[0]],
        [-omega[1], omega[0], 0.0],
    ];
    let mut worst_rate = 0.0f64;
    for i in 0..n {
        let l = grad[i];
        for a in 0..3 {
            for b in 0..3 {
                let d = 0.5 * (l[a][b] + l[b][a]);
                let w = 0.5 * (l[a][b] - l[b][a]);
                assert!(
                    d.abs() <= 1e-12 * scale[i],
                    "node {i}: D[{a}][{b}] = {d:e} 1/s of a rigid rotation (scale {:e})",
                    scale[i]
                );
                assert!(
                    (w - spin[a][b]).abs() <= 1e-12 * scale[i],
                    "node {i}: W[{a}][{b}] = {w:e} 1/s, not {:e}",
                    spin[a][b]
                );
                worst_rate = worst_rate.max(d.abs());
            }
        }
    }
    // The material pass on that gradient, from the reference state.
    let material = super::tests::plastic_steel();
    let rate = 1e-12 * scale.iter().copied().fold(0.0, f64::max);
    let damping_time = 1e-9;
    let MaterialOut {
        dev,
        pressure,
        eps_p,
        temp,
        rho,
        visc,
        results,
    } = material_pass(&material, &mass, &vel, &grad, &rho0, damping_time);
    let (mu, k) = (material.shear_modulus, 169.1e9);
    for i in 0..n {
        assert!(results[i].is_ok(), "node {i}: {:?}", results[i]);
        let s = dev[i].iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(
            s <= 2.0 * mu * DT * rate,
            "node {i}: a deviatoric stress of {s:e} Pa from a rigid rotation"
        );
        assert!(
            pressure[i].abs() <= k * DT * 3.0 * rate,
            "node {i}: a pressure of {:e} Pa",
            pressure[i]
        );
        assert!(
            (rho[i] - rho0[i]).abs() <= rho0[i] * DT * 3.0 * rate,
            "node {i}: the density moved from {:e} to {:e}",
            rho0[i],
            rho[i]
        );
        let v = visc[i].iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(
            v <= damping_time * (3.0 * k + 2.0 * mu) * rate,
            "node {i}: viscous stress {v:e} Pa"
        );
        assert_eq!(eps_p[i], 0.0, "node {i}: plastic strain");
        assert_eq!(temp[i], material.reference_temperature, "node {i}: heat");
    }
}

/// The collocated gradient (eq. 4) of a linear velocity field
/// `v = a + B x` is `B` at every node, and the material pass given it
/// carries the density by the continuity equation, `ρ (1 − dt tr B)`.
///
/// Analytic result: the MLS shapes of a linear basis reproduce linear
/// fields and their gradients exactly.
///
/// Tolerance: as for the rigid rotation, `1e-12 s_i` per entry with `s_i`
/// the size of the gradient's terms (measured 6e-16 `s_i`); the
/// density to `ρ dt 3e-12 max s_i` plus the two roundings of
/// `ρ (1 − dt tr)`.
#[test]
fn the_collocated_gradient_of_a_linear_field_is_exact() {
    let pts = grid();
    let n = pts.len();
    let g = geometry(&pts);
    let (mass, rho0) = masses(n);
    // A general gradient (1/s): neither symmetric nor traceless.
    let b = [[2e3, -7e3, 1e3], [4e3, -3e3, 6e3], [-5e3, 8e3, 9e3]];
    let a = [10.0, -20.0, -300.0];
    let vel: Vec<[f64; 3]> = pts
        .iter()
        .map(|x| std::array::from_fn(|r| a[r] + (0..3).map(|c| b[r][c] * x[c]).sum::<f64>()))
        .collect();
    let mut grad = vec![[[0.0; 3]; 3]; n];
    g.shapes.velocity_gradients(&vel, &mut grad);
    let scale = gradient_scale(&g.shapes, &vel);
    for i in 0..n {
        for r in 0..3 {
            for c in 0..3 {
                assert!(
                    (grad[i][r][c] - b[r][c]).abs() <= 1e-12 * scale[i],
                    "node {i}: ∂v_{r}/∂x_{c} = {:e} 1/s, not {:e} (scale {:e})",
                    grad[i][r][c],
                    b[r][c],
                    scale[i]
                );
            }
        }
    }
    // The continuity equation of the material pass.
    let material = super::tests::plastic_steel();
    let MaterialOut { rho, results, .. } = material_pass(&material, &mass, &vel, &grad, &rho0, 0.0);
    let trace = b[0][0] + b[1][1] + b[2][2];
    let worst = scale.iter().copied().fold(0.0, f64::max);
    for i in 0..n {
        assert!(results[i].is_ok(), "node {i}: {:?}", results[i]);
        let want = rho0[i] * (1.0 - DT * trace);
        let tol = rho0[i] * DT * 3e-12 * worst + 2.0 * EPS * rho0[i];
        assert!(
            (rho[i] - want).abs() <= tol,
            "node {i}: ρ = {:e} kg/m³, not ρ (1 − dt tr B) = {want:e}",
            rho[i]
        );
    }
}

/// The velocity update (`motion::kick`, nodal form) by forces that sum to
/// zero changes no component of the total momentum, and gives each node
/// `dt F / m`.
///
/// Analytic result: `Σ m Δv = dt Σ F = 0`.
///
/// Tolerance: each `m (v + dt F / m) − m v` is off by the rounding of the
/// sum (`ε |v|`) and of the quotient (`ε dt |F| / m`), times `m`, and the
/// forces' own sum is zero to `ε Σ |F|`: so the change is at most
/// `1e-14 (Σ m |v| + dt Σ |F|)` (64 nodes, a few roundings each;
/// measured 3.7e-16 of it). Each node's change: `2 ε (|v| + dt |F| / m)`
/// per component.
#[test]
fn a_kick_by_forces_summing_to_zero_keeps_the_momentum() {
    let pts = grid();
    let n = pts.len();
    let g = geometry(&pts);
    let (mass, rho) = masses(n);
    let frame = frame(&g, &mass, &rho, &[]);
    let mut rnd = crate::test_rng::rng(23);
    let mut force: Vec<[f64; 3]> = (0..n)
        .map(|_| std::array::from_fn(|_| 200.0 * (rnd() - 0.5)))
        .collect();
    let rest: [f64; 3] = std::array::from_fn(|d| force[..n - 1].iter().map(|f| f[d]).sum());
    force[n - 1] = rest.map(|x| -x);
    let vel0: Vec<[f64; 3]> = (0..n)
        .map(|_| std::array::from_fn(|d| 50.0 * (rnd() - 0.5) - if d == 2 { 300.0 } else { 0.0 }))
        .collect();
    let mut vel = vel0.clone();
    let mut contact = vec![false; n];
    let mut reaction = vec![0.0; n];
    let mut kicks = vec![Kick::default(); n];
    motion::kick(
        &frame,
        &force,
        &mut vel,
        &mut contact,
        &mut reaction,
        &mut kicks,
    );
    let (p0, scale) = momentum(&vel0, &mass);
    let (p1, _) = momentum(&vel, &mass);
    let forces: f64 = force.iter().map(|f| norm(*f)).sum();
    let tol = 1e-14 * (scale + DT * forces);
    for d in 0..3 {
        assert!(
            (p1[d] - p0[d]).abs() <= tol,
            "axis {d}: the momentum changed by {:e} kg m/s (bound {tol:e}, the kick {:e})",
            p1[d] - p0[d],
            DT * forces
        );
    }
    for i in 0..n {
        for d in 0..3 {
            let want = DT * force[i][d] / mass[i];
            let tol = 2.0 * EPS * (vel0[i][d].abs() + want.abs());
            assert!(
                (vel[i][d] - vel0[i][d] - want).abs() <= tol,
                "node {i}, axis {d}: Δv = {:e} m/s, not dt F / m = {want:e}",
                vel[i][d] - vel0[i][d]
            );
        }
        assert!(kicks[i].held == 0.0 && kicks[i].released.is_none());
    }
}

/// The contact pass (`motion::collide`, two bodies) stops each approaching
/// pair of nodes of different bodies within reach: their relative velocity
/// along the line of centres ends at zero, the tangential one is kept,
/// the total momentum is kept, the kinetic energy falls by exactly
/// `Σ ½ μ v_n²` (μ the pair's reduced mass), which the pass books, and a
/// separating pair and the nodes out of reach are left alone.
///
/// The node set: a 3 × 3 layer of body 0 at z = 0 and one of body 1 at
/// z = 0.8 H, shifted by 0.3 H along x: each node of body 1 is within
/// reach (0.85 H) of the one below it only (the next is 1.06 H away), so
/// the pairs are disjoint and each is resolved alone.
///
/// Tolerance: the pairs' normal relative velocity to `1e-14` of the
/// approach (a few roundings of a 3-term dot product), the momentum to
/// `1e-14 Σ m |v|`, the energies to `1e-14` of the kinetic energy (a
/// difference of sums of squares over 18 nodes, each sum good to about
/// `18 ε`; measured: 4e-16 of the approach, 1e-16 of the momentum's
/// scale, 1.2e-16 of the energy).
#[test]
fn a_contact_pass_stops_an_approaching_pair() {
    let mut pos = Vec::new();
    let mut group = Vec::new();
    for (b, z, dx) in [(0u8, 0.0, 0.0), (1u8, 0.8 * H, 0.3 * H)] {
        for j in 0..3 {
            for i in 0..3 {
                pos.push([i as f64 * H + dx, j as f64 * H, z]);
                group.push(b);
            }
        }
    }
    let n = pos.len();
    let (mass, rho) = masses(n);
    let mut rnd = crate::test_rng::rng(31);
    let vel0: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let toward = if group[i] == 0 { 40.0 } else { -60.0 };
            std::array::from_fn(|d| 20.0 * (rnd() - 0.5) + if d == 2 { toward } else { 0.0 })
        })
        .collect();
    // Pair 4-13 (the middle) separates: its upper node moves up faster.
    let mut vel0 = vel0;
    vel0[13][2] = 100.0;
    let g = Geometry::default();
    let frame = frame(&g, &mass, &rho, &group);
    let mut vel = vel0.clone();
    let mut buffers = ContactBuffers {
        pairs: Vec::new(),
        before: vel0.clone(),
        loose: Vec::new(),
    };
    let mut ext = ImageBuffers::default();
    let mut dissipation = 0.0;
    motion::collide(
        &frame,
        &pos,
        None,
        &mut vel,
        &mut buffers,
        &mut ext,
        &mut dissipation,
    );
    let pairs: Vec<(usize, usize)> = (0..9).map(|i| (i, i + 9)).collect();
    assert_eq!(buffers.pairs, pairs, "the pairs within reach");
    let mut lost = 0.0;
    for &(i, j) in &pairs {
        let d = norm(sub(pos[j], pos[i]));
        let nrm = sub(pos[j], pos[i]).map(|c| c / d);
        let along = |v: &[[f64; 3]]| (0..3).map(|k| (v[j][k] - v[i][k]) * nrm[k]).sum::<f64>();
        let (vn0, vn1) = (along(&vel0), along(&vel));
        if vn0 >= 0.0 {
            assert_eq!(
                (vel[i], vel[j]),
                (vel0[i], vel0[j]),
                "pair {i}-{j} separates"
            );
            continue;
        }
        assert!(
            vn1.abs() <= 1e-14 * vn0.abs(),
            "pair {i}-{j}: relative normal velocity {vn1:e} m/s after, {vn0:e} before"
        );
        let tangential = |v: &[[f64; 3]]| {
            let r = sub(v[j], v[i]);
            let a = along(v);
            std::array::from_fn::<f64, 3, _>(|k| r[k] - a * nrm[k])
        };
        let (t0, t1) = (tangential(&vel0), tangential(&vel));
        assert!(norm(sub(t0, t1)) <= 1e-13 * norm(sub(vel0[j], vel0[i])));
        let reduced = mass[i] * mass[j] / (mass[i] + mass[j]);
        lost += 0.5 * reduced * vn0 * vn0;
    }
    assert!(lost > 0.0, "some pairs approach");
    let (p0, scale) = momentum(&vel0, &mass);
    let (p1, _) = momentum(&vel, &mass);
    for d in 0..3 {
        assert!(
            (p1[d] - p0[d]).abs() <= 1e-14 * scale,
            "axis {d}: the momentum changed by {:e} kg m/s",
            p1[d] - p0[d]
        );
    }
    let (e0, e1) = (kinetic(&vel0, &mass), kinetic(&vel, &mass));
    assert!(
        e1 <= e0,
        "the contact added kinetic energy: {e0:e} J to {e1:e} J"
    );
    assert!(
        ((e0 - e1) - lost).abs() <= 1e-14 * e0,
        "the kinetic energy fell by {:e} J, not Σ ½ μ v_n² = {lost:e} J",
        e0 - e1
    );
    assert!(
        (dissipation - lost).abs() <= 1e-14 * e0,
        "the pass booked {dissipation:e} J, not {lost:e} J"
    );
}

/// The material pass gives each node of a ceramic whose tensile flaws
/// scatter for a volume its own flaw, drawn for its index and its volume
/// `m / rho` before its first step
/// ([`crate::material::rajendran_grove::RajendranGrove::tensile_flaw_of`]),
/// bit for bit; nodes of unequal volumes draw unequal strengths from the
/// same uniform number (a node of half the volume is `2^(1/m)` times
/// stronger for the same draw).
#[test]
fn the_material_pass_draws_each_flaw_for_its_nodes_volume() {
    use crate::material::rajendran_grove::RajendranGrove;
    let c = RajendranGrove {
        tensile_flaw_size: 188e-6,
        tensile_flaw_scatter: 10.0,
        tensile_flaw_volume: 1e-6,
        ..RajendranGrove::ad85()
    };
    let material = Material::ceramic(c, 880.0, 1.0, 293.0);
    let n = 8;
    let rho = vec![c.density; n];
    let mass: Vec<f64> = (0..n)
        .map(|i| c.density * H * H * H * (1.0 + i as f64))
        .collect();
    let mut states = vec![PointState::default(); n];
    let mut results = vec![Ok(Tally::default()); n];
    let (mut dev, mut pressure, mut eps_p) = (vec![[0.0; 6]; n], vec![0.0; n], vec![0.0; n]);
    let (mut temp, mut rho1, mut visc) = (vec![293.0; n], rho.clone(), vec![[0.0; 6]; n]);
    update_material(
        (&crate::ranks::Alone, &mut Default::default(), true),
        &MaterialInputs {
            dt: DT,
            damping_time: 0.0,
            rod: &material,
            others: &[],
            group: &[],
            mass: &mass,
            vel: &vec![[0.0; 3]; n],
            grad: &vec![[[0.0; 3]; 3]; n],
            shielding: None,
        },
        MaterialFields {
            dev: &mut dev,
            pressure: &mut pressure,
            eps_p: &mut eps_p,
            temp: &mut temp,
            rho: &mut rho1,
            visc: &mut visc,
            states: &mut states,
        },
        &mut results,
    );
    for (i, s) in states.iter().enumerate() {
        let got = s
            .ceramic()
            .expect("a ceramic point after a step")
            .tensile_flaw;
        let want = c.tensile_flaw_of(i as u64, Some(mass[i] / rho[i]));
        assert_eq!(got.to_bits(), want.to_bits(), "node {i}");
        // The same draw for the reference volume: the node's volume V
        // = (1 + i) H^3 makes it (V0 / V)^(1/m) stronger, a_t smaller by
        // the square of that.
        let at_v0 = c.tensile_flaw_of(i as u64, None);
        let ratio = (at_v0 / got).sqrt();
        let expected = (1e-6 / (H * H * H * (1.0 + i as f64))).powf(0.1);
        assert!((ratio / expected - 1.0).abs() < 1e-12, "{ratio} {expected}");
    }
}
