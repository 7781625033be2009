//! Unit tests of the axisymmetric solver's passes (`passes.rs` and the
//! pair pass of `src/solver/axisymmetric/pairs.rs`), each on a small hand-made particle
//! set and against an analytic result, not a number recorded from a run
//! (issue 67, item 4).
//!
//! The particle set is a 9 × 8 lattice of rings of spacing [`D`] in
//! `R ∈ [10 D, 18 D]`, `Z ∈ [2 D, 9 D]`, each particle moved by up to
//! 0.15 D along each axis (a fixed draw): a piece of a thick tube, away from
//! the axis and the anvil, so it has no mirror images, and of 72 particles,
//! so the passes run over two chunks of [`MIN_LEN`]. Its candidate lists
//! are those the solver builds ([`padded_rows`] with the skin), and the
//! passes are called on hand-set fields.
//!
//! Tolerances are stated at each test: a bound of the round-off of the sums
//! the pass forms, relative to the size of their terms.

use super::passes::{
    ContinuityChunks, PairChunks, Pass, continuity, laplacians, pair_pass, smooth_velocity,
};
use super::workspace::{BatchTally, KineticChange};
use super::{MIN_LEN, SKIN};
use crate::isa::Isa;
use crate::kernel::SUPPORT;
use crate::lanes::W;
use crate::neighbours::padded_rows;
use crate::solver::axisymmetric::boundary::Stress;
use crate::solver::axisymmetric::pairs::{PairInputs, PairPass, Rows, ScratchPool};
use crate::solver::axisymmetric::team::{Chunks, Team};

/// The particle spacing (m).
const D: f64 = 1e-3;
/// The density (kg/m³).
const RHO: f64 = 7850.0;
/// The step (s).
const DT: f64 = 1e-8;
/// The machine epsilon.
const EPS: f64 = f64::EPSILON;

/// A hand-made particle set with its candidate neighbour lists.
struct Set {
    pos: Vec<[f64; 2]>,
    mass: Vec<f64>,
    rho: Vec<f64>,
    vol: Vec<f64>,
    on_axis: Vec<bool>,
    nbr: Vec<u32>,
    nbr_len: Vec<u32>,
    stride: usize,
    h: f64,
}

/// The 9 × 8 lattice of rings (module docs), `h = 1.5 D`, each ring of
/// mass `ρ 2π R D²` times 0.9 to 1.1.
fn lattice() -> Set {
    let mut rnd = crate::test_rng::rng(67);
    let mut pos = Vec::new();
    for k in 0..8 {
        for i in 0..9 {
            let p = [10.0 + i as f64, 2.0 + k as f64];
            pos.push(p.map(|c| (c + 0.3 * (rnd() - 0.5)) * D));
        }
    }
    let n = pos.len();
    let mass: Vec<f64> = pos
        .iter()
        .map(|x| RHO * 2.0 * std::f64::consts::PI * x[0] * D * D * (0.9 + 0.2 * rnd()))
        .collect();
    let rho = vec![RHO; n];
    let vol = mass.iter().zip(&rho).map(|(m, r)| m / r).collect();
    let h = 1.5 * D;
    let (mut nbr, mut nbr_len) = (Vec::new(), Vec::new());
    let stride = padded_rows(&pos, n, (SUPPORT + SKIN) * h, W, 0, &mut nbr, &mut nbr_len);
    Set {
        pos,
        mass,
        rho,
        vol,
        on_axis: vec![false; n],
        nbr,
        nbr_len,
        stride,
        h,
    }
}

/// What the pair pass writes: the rows of the passes after it, the
/// velocities `v^{n+1/2}` and the total of its batches' tallies.
struct PairOut {
    act: Vec<u32>,
    wr: Vec<f64>,
    wz: Vec<f64>,
    wk: Vec<f64>,
    part: Vec<PairPass>,
    vel: Vec<[f64; 2]>,
    tally: BatchTally,
    stride: usize,
}

impl PairOut {
    fn rows(&self) -> Rows<'_> {
        Rows {
            act: &self.act,
            wr: &self.wr,
            wz: &self.wz,
            wk: &self.wk,
            part: &self.part,
            stride: self.stride,
        }
    }

    /// The neighbours in the support of particle `i` with their d/dR and
    /// d/dZ weights.
    fn row(&self, i: usize) -> impl Iterator<Item = (usize, f64, f64)> + '_ {
        let start = i * self.stride;
        (start..start + self.part[i].len as usize)
            .map(|q| (self.act[q] as usize, self.wr[q], self.wz[q]))
    }

    /// The size of the terms of the derivative sums of particle `i` of the
    /// field `f` (`Σ_j (|w_R| + |w_Z|) |f_j − f_i|`).
    fn scale<const K: usize>(&self, i: usize, f: &[[f64; K]]) -> f64 {
        self.row(i)
            .map(|(j, wr, wz)| {
                let df = (0..K)
                    .map(|k| (f[j][k] - f[i][k]).abs())
                    .fold(0.0, f64::max);
                (wr.abs() + wz.abs()) * df
            })
            .sum()
    }
}

/// The pair pass (steps 1-2) over the set `s`, with velocities `vel`,
/// stresses `sbc` and the particles touching the anvil `contact`.
fn run_pair_pass(s: &Set, vel: &[[f64; 2]], sbc: &[Stress], contact: &[bool]) -> PairOut {
    let n = s.pos.len();
    let rows = n.next_multiple_of(W) * s.stride;
    let mut out = PairOut {
        act: vec![0; rows],
        wr: vec![0.0; rows],
        wz: vec![0.0; rows],
        wk: vec![0.0; rows],
        part: vec![PairPass::default(); n],
        vel: vec![[0.0; 2]; n],
        tally: BatchTally::default(),
        stride: s.stride,
    };
    let mut batches = vec![BatchTally::default(); n.div_ceil(W)];
    let inputs = PairInputs {
        pos: &s.pos,
        vol: &s.vol,
        sbc,
        nbr: &s.nbr,
        nbr_len: &s.nbr_len,
        stride: s.stride,
        vel,
        rho: &s.rho,
        on_axis: &s.on_axis,
        h: s.h,
        dt: DT,
    };
    let mut scratch = ScratchPool::default();
    scratch.fit();
    let chunk = MIN_LEN * s.stride;
    Team::lead(|team| {
        let chunks = PairChunks {
            act: Chunks::new(&mut out.act, chunk),
            wr: Chunks::new(&mut out.wr, chunk),
            wz: Chunks::new(&mut out.wz, chunk),
            wk: Chunks::new(&mut out.wk, chunk),
            part: Chunks::new(&mut out.part, MIN_LEN),
            vel: Chunks::new(&mut out.vel, MIN_LEN),
            tallies: Chunks::new(&mut batches, MIN_LEN / W),
        };
        pair_pass(
            team,
            Isa::best(),
            &inputs,
            chunks,
            &scratch,
            &s.mass,
            contact,
        );
    });
    out.tally = BatchTally::total(&batches);
    assert!(
        out.tally.singular.is_none(),
        "a degenerate moment matrix: {:?}",
        out.tally.singular
    );
    assert!(out.part.iter().all(|p| p.len >= 6), "too few neighbours");
    out
}

/// The passes' common inputs over the rows of `out`.
fn pass<'a>(team: &'a Team, s: &'a Set, out: &'a PairOut, alpha: f64, order2: bool) -> Pass<'a> {
    Pass {
        team,
        isa: Isa::best(),
        rows: out.rows(),
        n: s.pos.len(),
        images: &[],
        alpha,
        order2,
        mass: &s.mass,
        on_axis: &s.on_axis,
        pos: &s.pos,
        dt: DT,
    }
}

/// The velocity smoothing (step 3) of `vel` of order 1 or 2: the smoothed
/// velocities and the kinetic energy before and after.
fn run_smoothing(
    s: &Set,
    out: &PairOut,
    vel: &[[f64; 2]],
    alpha: f64,
    order2: bool,
) -> (Vec<[f64; 2]>, KineticChange) {
    let n = s.pos.len();
    let mut lap = vec![[0.0; 2]; n];
    let mut smoothed = vec![[0.0; 2]; n];
    let mut ke = vec![KineticChange::default(); n.div_ceil(MIN_LEN)];
    let contact = vec![false; n];
    let total = Team::lead(|team| {
        let p = pass(team, s, out, alpha, order2);
        if order2 {
            laplacians(p, vel, &mut lap);
        }
        smooth_velocity(p, &contact, vel, &lap, &mut smoothed, &mut ke)
    });
    (smoothed, total)
}

/// The velocity gradients and continuity (step 4) of `vel`: the gradients
/// `(∂U_R/∂R, ∂U_R/∂Z, ∂U_Z/∂R, ∂U_Z/∂Z)` and the densities.
fn run_continuity(s: &Set, out: &PairOut, vel: &[[f64; 2]]) -> (Vec<[f64; 4]>, Vec<[f64; 1]>) {
    let n = s.pos.len();
    let mut grads = vec![[0.0; 4]; n];
    let mut rho = vec![[0.0]; n];
    Team::lead(|team| {
        let p = pass(team, s, out, 0.0, false);
        let chunks = ContinuityChunks {
            grads: Chunks::new(&mut grads, MIN_LEN),
            rho_out: Chunks::new(&mut rho, MIN_LEN),
        };
        continuity(p, vel, &s.rho, chunks);
    });
    (grads, rho)
}

/// A uniform velocity along the axis, `(0, U)` (the rigid motion an
/// axisymmetric body has), is carried unchanged: by the pair pass under a
/// uniform stress with `σ_RR = σ_θθ` and no shear (zero divergence, no hoop
/// force), so no particle's momentum changes, and by the velocity smoothing
/// of orders 1 and 2, which removes no kinetic energy; a particle touching
/// the anvil loses its axial velocity, booked as `½ m U²`.
///
/// Analytic result: `div σ = 0` for that stress; the Shepard mean of a
/// uniform field is the field (its weights sum to one).
///
/// Tolerance: the pair pass's sums are of exact zeros (`σ_j − σ_i = 0`,
/// `σ_RR − σ_θθ = 0`), so the velocities are kept exactly. The smoothing's
/// Shepard weights are normalised by their sum, so they sum to one to a
/// few ε over some 30 neighbours: the velocity moves by at most
/// `1e-13 |U|`, the kinetic energy by `1e-12` of itself (measured:
/// 1.1e-16 `|U|`, and no change of the energy). The anvil's
/// booking: one product of four factors per particle, `1e-15` relative.
#[test]
fn a_uniform_axial_velocity_is_carried_unchanged() {
    let s = lattice();
    let n = s.pos.len();
    let u = [0.0, -250.0];
    let vel = vec![u; n];
    let p = 2e9;
    let sbc = vec![[-p, -p, -p, 0.0]; n];
    let mut contact = vec![false; n];
    let out = run_pair_pass(&s, &vel, &sbc, &contact);
    for i in 0..n {
        assert_eq!(
            out.vel[i], u,
            "particle {i}: a uniform stress accelerated it"
        );
    }
    // Two particles on the anvil lose their axial velocity.
    contact[3] = true;
    contact[70] = true;
    let held = run_pair_pass(&s, &vel, &sbc, &contact);
    let booked = 0.5 * (s.mass[3] + s.mass[70]) * u[1] * u[1];
    assert!(
        (held.tally.held - booked).abs() <= 1e-15 * booked,
        "the anvil took {:e} J, not ½ m U² = {booked:e} J",
        held.tally.held
    );
    for i in 0..n {
        let want = if contact[i] { [u[0], 0.0] } else { u };
        assert_eq!(held.vel[i], want, "particle {i}");
    }
    // The smoothing of both orders.
    let energy: f64 = s.mass.iter().map(|m| 0.5 * m * u[1] * u[1]).sum();
    for order2 in [false, true] {
        let (smoothed, ke) = run_smoothing(&s, &out, &vel, 0.3, order2);
        let order = if order2 { 2 } else { 1 };
        let moved = smoothed
            .iter()
            .map(|v| (v[0] - u[0]).hypot(v[1] - u[1]))
            .fold(0.0, f64::max);
        assert!(
            moved <= 1e-13 * u[1].abs(),
            "order {order}: a uniform velocity moved by {moved:e} m/s"
        );
        assert!(
            (ke.before - ke.after).abs() <= 1e-12 * energy,
            "order {order}: the smoothing removed {:e} J of {energy:e} J",
            ke.before - ke.after
        );
        // The pass ran: a field with noise is changed.
        let mut rnd = crate::test_rng::rng(3);
        let noisy: Vec<[f64; 2]> = (0..n)
            .map(|_| [u[0] + rnd() - 0.5, u[1] + rnd() - 0.5])
            .collect();
        let (smoothed, _) = run_smoothing(&s, &out, &noisy, 0.3, order2);
        assert!(
            smoothed
                .iter()
                .zip(&noisy)
                .any(|(a, b)| (a[1] - b[1]).abs() > 1e-3)
        );
    }
}

/// A rigid translation makes no strain, and a uniform stretch the exact
/// rate of deformation: through the velocity gradients and continuity
/// (step 4), `v = (0, U)` gives zero gradients and the density unchanged;
/// `v = (a R, U + b Z)` (a radial and an axial stretch) gives
/// `∂U_R/∂R = a`, `∂U_Z/∂Z = b`, no shear, the hoop rate `U_R / R = a`
/// and the density `ρ (1 − dt (2a + b))`.
///
/// (A rotation in the (R, Z) plane is no motion of an axisymmetric body:
/// the rigid motions it has are the translation along the axis and the
/// spin about it, which has no (R, Z) velocity.)
///
/// Analytic result: the MSPH derivative weights of the second-order basis
/// reproduce the derivatives of linear (and quadratic) fields exactly.
///
/// Tolerance: the translation's sums are of exact zeros (`v_j − v_i = 0`),
/// so its gradients are exactly zero and its density exactly kept. The
/// stretch's gradients: `1e-12 s_i`, with `s_i = Σ_j (|w_R| + |w_Z|) |v_j −
/// v_i|` the size of the terms summed (the weights exact to the round-off
/// of the 6 × 6 moment solve; measured 2e-15 `s_i`); the density to
/// `ρ dt 3e-12 s_i` plus the roundings of `ρ (1 − dt div)`.
#[test]
fn a_rigid_translation_makes_no_strain_and_a_stretch_the_exact_rate() {
    let s = lattice();
    let n = s.pos.len();
    let sbc = vec![[0.0; 4]; n];
    let contact = vec![false; n];
    let translation = vec![[0.0, -250.0]; n];
    let out = run_pair_pass(&s, &translation, &sbc, &contact);
    let (grads, rho) = run_continuity(&s, &out, &translation);
    for i in 0..n {
        assert_eq!(
            grads[i], [0.0; 4],
            "particle {i}: a translation strained it"
        );
        assert_eq!(
            rho[i],
            [s.rho[i]],
            "particle {i}: a translation compressed it"
        );
    }
    let (a, b) = (3e3, -8e3);
    let stretch: Vec<[f64; 2]> = s
        .pos
        .iter()
        .map(|x| [a * x[0], -250.0 + b * x[1]])
        .collect();
    let (grads, rho) = run_continuity(&s, &out, &stretch);
    for i in 0..n {
        let scale = out.scale(i, &stretch);
        let want = [a, 0.0, 0.0, b];
        for k in 0..4 {
            assert!(
                (grads[i][k] - want[k]).abs() <= 1e-12 * scale,
                "particle {i}: gradient {k} is {:e} 1/s, not {:e} (scale {scale:e})",
                grads[i][k],
                want[k]
            );
        }
        let want = s.rho[i] * (1.0 - DT * (2.0 * a + b));
        let tol = s.rho[i] * DT * 3e-12 * scale + 4.0 * EPS * s.rho[i];
        assert!(
            (rho[i][0] - want).abs() <= tol,
            "particle {i}: ρ = {:e} kg/m³, not ρ (1 − dt (2a + b)) = {want:e}",
            rho[i][0]
        );
    }
}

/// The pair pass's derivatives of linear fields are exact: the velocity
/// gradients of `v = (c₀ + c₁ R + c₂ Z, c₃ + c₄ R + c₅ Z)` are
/// `(c₁, c₂, c₄, c₅)` at every particle, and under a linear stress field
/// `σ_k = s_k + r_k R + z_k Z` the momentum equation gives every particle
/// the exact acceleration of the axisymmetric divergence,
/// `a_R = (r_RR + z_RZ + (σ_RR − σ_θθ) / R) / ρ`,
/// `a_Z = (r_RZ + z_ZZ + σ_RZ / R) / ρ`.
///
/// Analytic result: the MSPH derivative weights reproduce the derivatives
/// of linear fields exactly.
///
/// Tolerance: the gradients to `1e-12 s_i` (as the stretch's); the
/// accelerations to `1e-12 s_i / ρ` with `s_i` the size of the stress
/// differences' terms, plus `1e-15` of the hoop terms (a quotient and a
/// sum), and the update `v + dt a` to `2 ε |v|` (measured: the gradients
/// 2e-15 `s_i`, the velocities within 0.5 % of their bound).
#[test]
fn the_pair_pass_derivatives_of_linear_fields_are_exact() {
    let s = lattice();
    let n = s.pos.len();
    let c = [5.0, 2e3, -4e3, -250.0, 7e3, -1e3];
    let vel: Vec<[f64; 2]> = s
        .pos
        .iter()
        .map(|x| {
            [
                c[0] + c[1] * x[0] + c[2] * x[1],
                c[3] + c[4] * x[0] + c[5] * x[1],
            ]
        })
        .collect();
    // Stresses (RR, ZZ, θθ, RZ): a constant part with σ_RR ≠ σ_θθ and
    // slopes of order 1 GPa per millimetre.
    let s0 = [-1e9, -3e9, 2e8, 5e8];
    let r1 = [4e11, -2e11, 1e12, 3e11];
    let z1 = [-6e11, 8e11, 2e11, -5e11];
    let sbc: Vec<Stress> = s
        .pos
        .iter()
        .map(|x| std::array::from_fn(|k| s0[k] + r1[k] * x[0] + z1[k] * x[1]))
        .collect();
    let contact = vec![false; n];
    let out = run_pair_pass(&s, &vel, &sbc, &contact);
    let (grads, _) = run_continuity(&s, &out, &vel);
    for i in 0..n {
        let scale = out.scale(i, &vel);
        let want = [c[1], c[2], c[4], c[5]];
        for k in 0..4 {
            assert!(
                (grads[i][k] - want[k]).abs() <= 1e-12 * scale,
                "particle {i}: gradient {k} is {:e} 1/s, not {:e} (scale {scale:e})",
                grads[i][k],
                want[k]
            );
        }
        let (r, sig) = (s.pos[i][0], sbc[i]);
        let hoop = [(sig[0] - sig[2]) / r, sig[3] / r];
        let accel = [
            (r1[0] + z1[3] + hoop[0]) / RHO,
            (r1[3] + z1[1] + hoop[1]) / RHO,
        ];
        let scale = out.scale(i, &sbc);
        for k in 0..2 {
            let want = vel[i][k] + DT * accel[k];
            let tol =
                DT * (1e-12 * scale + 1e-15 * hoop[k].abs()) / RHO + 2.0 * EPS * vel[i][k].abs();
            assert!(
                (out.vel[i][k] - want).abs() <= tol,
                "particle {i}, component {k}: v = {:e} m/s, not v + dt div σ / ρ = {want:e} \
                 (bound {tol:e})",
                out.vel[i][k]
            );
        }
    }
}
