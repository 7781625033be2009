//! The parallel passes of one step of the axisymmetric solver: functions
//! over slices, each given what it reads and the chunks it writes, run by
//! the step's [`Team`] [`MIN_LEN`] particles (or a batch of [`W`]) at a time.
//! Each chunk's sums go to its own slot, added in index order afterwards,
//! so the results do not depend on the thread count.

use super::mirror::{Image, Mirrored, fill_images};
use super::workspace::{BatchTally, Compressed, KineticChange, Tally, Through};
use super::{MIN_LEN, kinetic1, wave_and_flow_speed};
use crate::isa::Isa;
use crate::lanes::W;
use crate::material::{Loading, Material, Point, PointState, Shield};
use crate::solver::axisymmetric::boundary::Stress;
use crate::solver::axisymmetric::pairs::{
    PairInputs, PairOutputs, PairPass, Rows, ScratchPool, laplacian, pair_batch, shepard_means,
    smooth, smooth2, velocity_gradients,
};
use crate::solver::axisymmetric::team::{Chunks, Team, named_parts};

/// What the passes after the pair pass read: the team, the copy of the hot
/// loops, the rows of the pair pass, the mirror images, the smoothing, and
/// the real particles' masses, axis flags and positions (images included).
#[derive(Clone, Copy)]
pub(super) struct Pass<'a> {
    pub team: &'a Team,
    pub isa: Isa,
    pub rows: Rows<'a>,
    /// Number of real particles.
    pub n: usize,
    pub images: &'a [Image],
    /// `α_cs` of the smoothing.
    pub alpha: f64,
    /// Whether the smoothing is of order 2 (the bi-Laplacian).
    pub order2: bool,
    pub mass: &'a [f64],
    pub on_axis: &'a [bool],
    /// Positions `x^n` of the particles and their images.
    pub pos: &'a [[f64; 2]],
    pub dt: f64,
}

named_parts! {
    /// The arrays the pair pass writes, cut into chunks of [`MIN_LEN`]
    /// particles (their padded rows, records, velocities and batch tallies).
    PairChunks,
    /// A chunk of [`PairChunks`].
    PairChunk {
        act: u32,
        wr: f64,
        wz: f64,
        wk: f64,
        part: PairPass,
        vel: [f64; 2],
        tallies: BatchTally,
    }
}

/// Steps 1-2, per particle: the MSPH moment matrix over the neighbours in the
/// support, the derivative and Shepard weights of each pair, and the
/// momentum equation `v^{n+1/2} = v^{n-1/2} + dt div(sigma) / rho`, [`W`]
/// particles at a time (src/solver/axisymmetric/pairs.rs); then `U_Z = 0` on the
/// particles touching the anvil (`contact`), the kinetic energy that takes
/// booked per batch.
#[allow(clippy::too_many_arguments)]
pub(super) fn pair_pass(
    team: &Team,
    isa: Isa,
    inputs: &PairInputs,
    out: PairChunks,
    scratch: &ScratchPool,
    mass: &[f64],
    contact: &[bool],
) {
    let stride = inputs.stride;
    team.run_parts(&out, |c, chunk| {
        let PairChunk {
            act,
            wr,
            wz,
            wk,
            part,
            vel,
            tallies,
        } = chunk;
        let mut scratch = scratch.get();
        let batch = W * stride;
        for (b, (((((act, wr), wz), wk), (part, vel)), tally)) in act
            .chunks_mut(batch)
            .zip(wr.chunks_mut(batch))
            .zip(wz.chunks_mut(batch))
            .zip(wk.chunks_mut(batch))
            .zip(part.chunks_mut(W).zip(vel.chunks_mut(W)))
            .zip(tallies)
            .enumerate()
        {
            let i0 = c * MIN_LEN + b * W;
            let out = PairOutputs {
                act,
                wr,
                wz,
                wk,
                part: &mut *part,
                vel: &mut *vel,
            };
            pair_batch(isa, inputs, i0, out, &mut scratch);
            let mut t = BatchTally::default();
            for (k, (p, v)) in part.iter().zip(vel.iter_mut()).enumerate() {
                let i = i0 + k;
                if p.condition != 0.0 && t.singular.is_none() {
                    t.singular = Some((i, p.condition));
                }
                t.min_d2 = t.min_d2.min(p.min_d2);
                if contact[i] {
                    t.held += 0.5 * mass[i] * v[1] * v[1];
                    v[1] = 0.0;
                }
            }
            *tally = t;
        }
    });
}

/// The smoothing operator `L f = (Shepard mean of f) − f` at the real
/// particles, `out[..n]`, and then at their images: the first pass of the
/// smoothing of order 2.
pub(super) fn laplacians<const K: usize>(p: Pass, f: &[[f64; K]], out: &mut [[f64; K]])
where
    [f64; K]: Mirrored,
{
    let (isa, rows, n) = (p.isa, p.rows, p.n);
    let parts = Chunks::new(&mut out[..n], MIN_LEN);
    p.team.run_parts(&parts, |c, out| {
        let i0 = c * MIN_LEN;
        shepard_means(isa, rows, f, i0, out);
        for (k, l) in out.iter_mut().enumerate() {
            *l = laplacian(f[i0 + k], *l);
        }
    });
    fill_images(out, n, p.images);
}

named_parts! {
    /// The arrays the velocity smoothing writes: the smoothed velocities of
    /// [`MIN_LEN`] particles and the kinetic energy of the chunk.
    SmoothChunks,
    /// A chunk of [`SmoothChunks`].
    SmoothChunk {
        out: [f64; 2],
        ke: KineticChange,
    }
}

/// Step 3, conservative smoothing of the velocity `vel` (images included; with
/// order 2, `lap` holds its [`laplacians`]) into `out`, the kinetic energy
/// of each chunk into `ke_chunks` (boundary
/// conditions re-applied: `U_R = 0` on the axis, `U_Z = 0` on the particles
/// touching the anvil); returns the kinetic energy before and after.
pub(super) fn smooth_velocity(
    p: Pass,
    contact: &[bool],
    vel: &[[f64; 2]],
    lap: &[[f64; 2]],
    out: &mut [[f64; 2]],
    ke_chunks: &mut [KineticChange],
) -> KineticChange {
    let (isa, rows, alpha, order2, mass) = (p.isa, p.rows, p.alpha, p.order2, p.mass);
    let axis = |i: usize| p.on_axis[i];
    let parts = SmoothChunks {
        out: Chunks::new(out, MIN_LEN),
        ke: Chunks::new(ke_chunks, 1),
    };
    p.team.run_parts(&parts, |c, SmoothChunk { out, ke }| {
        let ke = &mut ke[0];
        let i0 = c * MIN_LEN;
        *ke = KineticChange::default();
        if order2 {
            // v - alpha L(L v): the mean of L v is taken into `out`.
            shepard_means(isa, rows, lap, i0, out);
        } else {
            shepard_means(isa, rows, vel, i0, out);
        }
        for (k, v) in out.iter_mut().enumerate() {
            let i = i0 + k;
            *v = if order2 {
                smooth2(vel[i], lap[i], *v, alpha)
            } else {
                smooth(vel[i], *v, alpha)
            };
            if axis(i) {
                v[0] = 0.0;
            }
            if contact[i] {
                v[1] = 0.0;
            }
            ke.before += kinetic1(vel[i], mass[i]);
            ke.after += kinetic1(*v, mass[i]);
        }
    });
    KineticChange::total(ke_chunks)
}

named_parts! {
    /// The arrays the continuity pass writes for [`MIN_LEN`] particles.
    ContinuityChunks,
    /// A chunk of [`ContinuityChunks`].
    ContinuityChunk {
        grads: [f64; 4],
        rho_out: [f64; 1],
    }
}

/// Step 4, velocity gradients of the smoothed velocity `vel` (images included)
/// and continuity: the density `rho` (of the real particles) carried to the
/// end of the step, before smoothing.
pub(super) fn continuity(p: Pass, vel: &[[f64; 2]], rho: &[f64], out: ContinuityChunks) {
    let (isa, rows, pos, dt) = (p.isa, p.rows, p.pos, p.dt);
    let axis = |i: usize| p.on_axis[i];
    p.team
        .run_parts(&out, |c, ContinuityChunk { grads, rho_out }| {
            let i0 = c * MIN_LEN;
            // dU_R/dR, dU_R/dZ, dU_Z/dR, dU_Z/dZ
            velocity_gradients(isa, rows, vel, i0, grads);
            for (k, (g, rho_out)) in grads.iter().zip(rho_out).enumerate() {
                let i = i0 + k;
                let hoop = if axis(i) { g[0] } else { vel[i][0] / pos[i][0] };
                let div = g[0] + g[3] + hoop;
                *rho_out = [rho[i] * (1.0 - dt * div)];
            }
        });
}

/// What the update pass reads besides its [`Pass`].
pub(super) struct UpdateInputs<'a> {
    /// Smoothed velocities `v^{n+1/2}`, images included.
    pub vel: &'a [[f64; 2]],
    /// Velocity gradients.
    pub grads: &'a [[f64; 4]],
    /// Densities from the continuity equation, images included, and with
    /// order 2 their [`laplacians`].
    pub rho_raw: &'a [[f64; 1]],
    pub lap_rho: &'a [[f64; 1]],
    pub material: Material,
    /// Smoothing length.
    pub h: f64,
}

named_parts! {
    /// The particle fields the update pass writes, and its per-chunk
    /// results, cut into chunks of [`MIN_LEN`] particles.
    UpdateChunks,
    /// A chunk of [`UpdateChunks`].
    UpdateChunk {
        dev: Stress,
        pressure: f64,
        eps_p: f64,
        temp: f64,
        rho: f64,
        models: PointState,
        pos: [f64; 2],
        vel: [f64; 2],
        contact: bool,
        stress_bc: Stress,
        /// One [`Tally`] per chunk.
        tally: Tally,
        /// The work weights of [`super::workspace::Workspace::rate`].
        work: [f64; 4],
    }
}

/// Steps 5-6, per particle: conservative smoothing of the density, the
/// constitutive update, positions `x^{n+1} = x^n + dt v^{n+1/2}`, anvil
/// contact, the generic stress boundary condition, and the sums of the
/// step, [`MIN_LEN`] particles at a time.
pub(super) fn update(p: Pass, inp: &UpdateInputs, out: UpdateChunks) {
    let (isa, rows, alpha, order2, pos, dt) = (p.isa, p.rows, p.alpha, p.order2, p.pos, p.dt);
    let axis = |i: usize| p.on_axis[i];
    let UpdateInputs {
        vel,
        grads,
        rho_raw,
        lap_rho,
        material,
        h,
    } = *inp;
    let mass = p.mass;
    p.team.run_parts(
        &out,
        |c,
         UpdateChunk {
             dev,
             pressure,
             eps_p,
             temp,
             rho,
             models,
             pos: x,
             vel: v,
             contact: touch,
             stress_bc: sbc,
             tally,
             work,
         }| {
            let tally = &mut tally[0];
            let i0 = c * MIN_LEN;
            let mut means = [[0.0]; MIN_LEN];
            let means = &mut means[..dev.len()];
            if order2 {
                shepard_means(isa, rows, lap_rho, i0, means);
            } else {
                shepard_means(isa, rows, rho_raw, i0, means);
            }
            let mut t = Tally::default();
            for k in 0..dev.len() {
                let i = i0 + k;
                let [rho_new] = if order2 {
                    smooth2(rho_raw[i], lap_rho[i], means[k], alpha)
                } else {
                    smooth(rho_raw[i], means[k], alpha)
                };
                let g = grads[i];
                let d_rr = g[0];
                let d_zz = g[3];
                let d_tt = if axis(i) { g[0] } else { vel[i][0] / pos[i][0] };
                // On the axis, symmetry gives dU_R/dZ = dU_Z/dR = 0: no
                // shear and no spin (sigma_RZ is odd in R).
                let (d_rz, omega) = if axis(i) {
                    (0.0, 0.0)
                } else {
                    (0.5 * (g[1] + g[2]), 0.5 * (g[1] - g[2]))
                };
                let load = Loading {
                    dt,
                    rate: [d_rr, d_zz, d_tt, d_rz],
                    spin: omega,
                    density: rho_new,
                    shield: Shield::NONE,
                };
                let before = Point {
                    deviator: dev[k],
                    pressure: pressure[k],
                    plastic_strain: eps_p[k],
                    temperature: temp[k],
                };
                let new = match material.update(&load, &before, &mut models[k]) {
                    Ok(new) => new,
                    Err(l) => {
                        // The step stops with the named error.
                        t.compression = t.compression.or(Some(Compressed {
                            particle: i,
                            compression: l.compression,
                            limit: l.limit,
                        }));
                        continue;
                    }
                };
                let p_new = new.pressure;
                // Stress power with the mid-step stress: the mean of
                // the stress the momentum equation used (boundary
                // conditions applied) and the new one (whose
                // conditions the end of the step books), per unit
                // mass.
                let old = sbc[k];
                let s = new.deviator;
                let sm = |k: usize, p: f64| 0.5 * (old[k] + s[k] - p);
                let power = sm(0, p_new) * d_rr
                    + sm(1, p_new) * d_zz
                    + sm(2, p_new) * d_tt
                    + 2.0 * 0.5 * (old[3] + s[3]) * d_rz;
                let w = 0.5 * dt * mass[i] / rho_new;
                work[k] = [w * d_rr, w * d_zz, w * d_tt, w * 2.0 * d_rz];
                dev[k] = s;
                pressure[k] = p_new;
                eps_p[k] = new.plastic_strain;
                temp[k] = new.temperature;
                rho[k] = rho_new;
                t.internal += dt * power * mass[i] / rho_new;

                // Positions and anvil contact.
                let mut vi = vel[i];
                let mut xi = [x[k][0] + dt * vi[0], x[k][1] + dt * vi[1]];
                if touch[k] {
                    // Released when the normal stress turns tensile.
                    if dev[k][1] - pressure[k] > 0.0 {
                        touch[k] = false;
                    }
                } else if xi[1] < 0.0 {
                    if xi[1] < -0.5 * h && t.through.is_none() {
                        t.through = Some(Through {
                            particle: i,
                            boundary: "anvil",
                            position: xi[1],
                        });
                    }
                    xi[1] = 0.0;
                    t.contact_lost += 0.5 * mass[i] * vi[1] * vi[1];
                    vi[1] = 0.0;
                    touch[k] = true;
                }
                if !axis(i) && xi[0] <= 0.0 && t.through.is_none() {
                    t.through = Some(Through {
                        particle: i,
                        boundary: "axis",
                        position: xi[0],
                    });
                }
                x[k] = xi;
                v[k] = vi;
                if t.non_finite.is_none() {
                    t.non_finite =
                        non_finite(xi, vi, rho_new, dev[k], temp[k]).map(|field| (i, field));
                }
                let p = pressure[k];
                let d = dev[k];
                sbc[k] = [d[0] - p, d[1] - p, d[2] - p, d[3]];

                // The sums of the step.
                t.kinetic += kinetic1(vi, mass[i]);
                t.momentum += mass[i] * vi[1];
                t.mass += mass[i];
                t.touching |= touch[k];
                let modulus = material.longitudinal_modulus(rho_new, p_new);
                t.worst_speed = t.worst_speed.max(wave_and_flow_speed(modulus, rho_new, vi));
                // The velocity the particle moved with (before
                // a contact stopped it).
                let moved = vel[i];
                t.fastest2 = t.fastest2.max(moved[0] * moved[0] + moved[1] * moved[1]);
            }
            *tally = t;
        },
    );
}

/// The first non-finite field of a particle, in the order position,
/// velocity, density, deviatoric stress, temperature.
fn non_finite(x: [f64; 2], v: [f64; 2], rho: f64, dev: Stress, temp: f64) -> Option<&'static str> {
    let finite = |x: &[f64]| x.iter().all(|v| v.is_finite());
    if !finite(&x) {
        Some("position")
    } else if !finite(&v) {
        Some("velocity")
    } else if !rho.is_finite() {
        Some("density")
    } else if !finite(&dev) {
        Some("deviatoric stress")
    } else if !temp.is_finite() {
        Some("temperature")
    } else {
        None
    }
}
