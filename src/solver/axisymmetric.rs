//! The axisymmetric MSPH solver of the Taylor impact test (Batra & Zhang 2008,
//! section 3): balance laws (3.1)-(3.4) in cylindrical coordinates with their
//! axis limits, Johnson-Cook thermo-viscoplasticity with the Jaumann rate and
//! radial return, the linear EOS, adiabatic heating, central differences in
//! time with the Courant step (3.22), conservative smoothing (3.23), a
//! traction-free mantle and top, and a rigid smooth anvil at Z = 0.
//!
//! Particles are rings. They sit on a regular (R, Z) lattice, the axis and the
//! surfaces included: `particles_radial` across the radius at spacing
//! `D = R0 / (n_r - 1)`, and `round(L0 / D) + 1` along the axis. Each carries the
//! mass of its tributary ring.
//!
//! One step, from positions `x^n`, velocities `v^{n-1/2}` and stresses
//! `sigma^n` (with boundary conditions applied):
//! 1. neighbours and MSPH first-derivative weights at `x^n`;
//! 2. acceleration from the divergence of stress; `v^{n+1/2} = v^{n-1/2} + dt a`,
//!    then `U_R = 0` on the axis and `U_Z = 0` on particles touching the anvil;
//! 3. conservative smoothing of the velocity (boundary conditions re-applied);
//! 4. velocity gradients, continuity, conservative smoothing of the density;
//! 5. stress update (Jaumann rate, trial deviator, Johnson-Cook radial return,
//!    linear EOS), heating from plastic work, internal energy from stress power;
//! 6. `x^{n+1} = x^n + dt v^{n+1/2}`, contact with the anvil (touch on reaching
//!    Z = 0, release when sigma_ZZ turns tensile), traction-free stresses on
//!    the free surfaces, next time step.

use super::boundary::{Stress, Surface, corner_free, traction_free};
use super::{COURANT, check_time_step, first_degenerate, rows_mut, smooth, with_images};
use crate::error::{Error, Result};
use crate::material::eos::LinearEos;
use crate::material::johnson_cook::{JohnsonCook, radial_return};
use crate::msph::{Msph2Rows, Row2};
use crate::neighbors::{NeighborList, cell_list_first};
use crate::observe::{Field, Snapshot, TAYLOR_OBSERVABLES};
use crate::scene::taylor::TaylorParams;
use rayon::prelude::*;

/// Radial strain below which the rod counts as undeformed (0.2 %).
pub const UNDEFORMED_STRAIN: f64 = 0.002;

/// Energy error past which a run stops with [`Error::EnergyDrift`].
pub const ENERGY_ERROR_BOUND: f64 = 0.5;

/// State of a Taylor impact run.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct TaylorSolver {
    p: TaylorParams,
    jc: JohnsonCook,
    eos: LinearEos,
    nr: usize,
    nz: usize,
    h: f64,
    r0: f64,
    // Particle fields (structure of arrays).
    pos: Vec<[f64; 2]>,
    vel: Vec<[f64; 2]>,
    mass: Vec<f64>,
    rho: Vec<f64>,
    dev: Vec<Stress>,
    pressure: Vec<f64>,
    eps_p: Vec<f64>,
    temp: Vec<f64>,
    /// Stress with boundary conditions, used by the momentum equation.
    stress_bc: Vec<Stress>,
    contact: Vec<bool>,
    mantle: Surface,
    top: Surface,
    face: Surface,
    // Bookkeeping.
    time: f64,
    steps: u64,
    dt: f64,
    dt0: f64,
    initial_energy: f64,
    internal_energy: f64,
    smoothing_dissipation: f64,
    contact_dissipation: f64,
    at_rest: bool,
    /// Smallest spacing seen between neighbours, relative to the initial one.
    min_spacing: f64,
}

/// Per-pair weights: dW-based derivative weights (R, Z) and the Shepard
/// smoothing weight.
type PairWeights = [f64; 3];

impl TaylorSolver {
    /// Sets up the rod at the instant of impact. `p` must be validated.
    pub fn new(p: TaylorParams) -> Result<Self> {
        let nr = p.particles_radial as usize;
        let r0 = 0.5 * p.initial_diameter;
        let d = r0 / (nr - 1) as f64;
        let nz = (p.initial_length / d).round() as usize + 1;
        let dz = p.initial_length / (nz - 1) as f64;
        let h = p.smoothing_ratio * d;
        let n = nr * nz;
        let mut pos = Vec::with_capacity(n);
        let mut mass = Vec::with_capacity(n);
        for k in 0..nz {
            for i in 0..nr {
                let r = i as f64 * d;
                let r_in = (r - 0.5 * d).max(0.0);
                let r_out = (r + 0.5 * d).min(r0);
                let z_len = if k == 0 || k == nz - 1 { 0.5 * dz } else { dz };
                let vol = std::f64::consts::PI * (r_out * r_out - r_in * r_in) * z_len;
                pos.push([r, k as f64 * dz]);
                mass.push(p.density * vol);
            }
        }
        let mantle = Surface {
            particles: (0..nz).map(|k| k * nr + nr - 1).collect(),
            sign: 1.0,
        };
        let top = Surface {
            particles: (0..nr).map(|i| (nz - 1) * nr + i).collect(),
            sign: -1.0,
        };
        let face = Surface {
            particles: (0..nr).collect(),
            sign: 1.0,
        };
        let vel = vec![[0.0, -p.impact_speed]; n];
        let contact = (0..n).map(|i| i < nr).collect();
        let total_mass: f64 = mass.iter().sum();
        let eos = LinearEos {
            bulk_modulus: p.bulk_modulus,
            density: p.density,
        };
        let jc = JohnsonCook {
            a: p.jc_a,
            b: p.jc_b,
            n: p.jc_n,
            c: p.jc_c,
            m: p.jc_m,
            melt_temperature: p.melt_temperature,
            room_temperature: p.room_temperature,
            ref_strain_rate: p.ref_strain_rate,
        };
        let mut s = TaylorSolver {
            jc,
            eos,
            nr,
            nz,
            h,
            r0,
            vel,
            rho: vec![p.density; n],
            dev: vec![[0.0; 4]; n],
            pressure: vec![0.0; n],
            eps_p: vec![0.0; n],
            temp: vec![p.initial_temperature; n],
            stress_bc: vec![[0.0; 4]; n],
            contact,
            mantle,
            top,
            face,
            pos,
            mass,
            time: 0.0,
            steps: 0,
            dt: 0.0,
            dt0: 0.0,
            initial_energy: 0.5 * total_mass * p.impact_speed * p.impact_speed,
            internal_energy: 0.0,
            smoothing_dissipation: 0.0,
            contact_dissipation: 0.0,
            at_rest: false,
            min_spacing: 1.0,
            p,
        };
        s.dt = s.stable_dt();
        s.dt0 = s.dt;
        Ok(s)
    }

    /// Number of particles.
    pub fn particles(&self) -> usize {
        self.pos.len()
    }

    /// Particles across the radius and along the axis.
    pub fn lattice(&self) -> (usize, usize) {
        (self.nr, self.nz)
    }

    /// Smoothing length.
    pub fn smoothing_length(&self) -> f64 {
        self.h
    }

    /// Simulated time.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Current time step.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Whether the end condition holds: the rod is at rest, or `end_time` has
    /// been reached.
    pub fn finished(&self) -> bool {
        self.at_rest || self.time >= self.p.end_time
    }

    /// Smallest distance between neighbouring particles relative to the
    /// initial spacing, over the run so far.
    pub fn min_spacing_ratio(&self) -> f64 {
        self.min_spacing
    }

    /// Longitudinal elastic wave speed sqrt((K + 4 mu / 3) / rho0).
    pub fn wave_speed(&self) -> f64 {
        ((self.p.bulk_modulus + 4.0 / 3.0 * self.p.shear_modulus) / self.p.density).sqrt()
    }

    fn stable_dt(&self) -> f64 {
        let m = self.p.bulk_modulus + 4.0 / 3.0 * self.p.shear_modulus;
        let worst = self
            .rho
            .iter()
            .zip(&self.vel)
            .map(|(rho, v)| (m / rho).sqrt() + (v[0] * v[0] + v[1] * v[1]).sqrt())
            .fold(0.0, f64::max);
        COURANT * self.h / worst
    }

    /// MSPH derivative weights and Shepard weights for every neighbour pair.
    fn pair_weights(
        &self,
        nl: &NeighborList,
        pos: &[[f64; 2]],
        vol: &[f64],
    ) -> Result<Vec<PairWeights>> {
        let mut w = vec![[0.0; 3]; nl.indices.len()];
        let rows = rows_mut(&mut w, &nl.offsets);
        let h = self.h;
        let status: Vec<std::result::Result<(), crate::msph::Degenerate>> = rows
            .into_par_iter()
            .enumerate()
            .map_init(Vec::new, |phi, (i, row)| {
                let nb = nl.of(i);
                let m = Msph2Rows::new_recording(i, nb, pos, vol, h, [Row2::R, Row2::Z], phi)?;
                let mut wsum = 0.0;
                for ((slot, &j), ph) in row.iter_mut().zip(nb).zip(phi.iter()) {
                    let g = m.weight_of(ph, vol[j]);
                    // Kernel value up to its normalisation, which cancels in
                    // the Shepard ratio.
                    let k = ph[0] * vol[j];
                    wsum += k;
                    *slot = [g[0], g[1], k];
                }
                for slot in row.iter_mut() {
                    slot[2] /= wsum;
                }
                Ok(())
            })
            .collect();
        first_degenerate(status, self.time)?;
        Ok(w)
    }

    /// Advances one step.
    pub fn step(&mut self) -> Result<()> {
        let n = self.particles();
        let dt = self.dt;
        let alpha = self.p.smoothing_coefficient;
        let vol: Vec<f64> = self
            .mass
            .iter()
            .zip(&self.rho)
            .map(|(m, r)| m / r)
            .collect();
        let nr = self.nr;
        let axis = |i: usize| i.is_multiple_of(nr);
        // Mirror images across the axis of the particles within one support
        // radius of it, so that particles near the axis see a symmetric
        // neighbourhood: U_R and sigma_RZ change sign, the rest is even.
        let ghosts: Vec<usize> = (0..n)
            .filter(|&i| !axis(i) && self.pos[i][0] < 2.0 * self.h)
            .collect();
        let pos_ext = with_images(&self.pos, &ghosts, |x| [-x[0], x[1]]);
        let vol_ext = with_images(&vol, &ghosts, |v| v);
        let nl = cell_list_first(&pos_ext, n, 2.0 * self.h);
        let w = self.pair_weights(&nl, &pos_ext, &vol_ext)?;

        // 2. Momentum: v^{n+1/2} = v^{n-1/2} + dt div(sigma) / rho.
        let sbc = with_images(&self.stress_bc, &ghosts, |s| [s[0], s[1], s[2], -s[3]]);
        let (pos, sbc, rho) = (&self.pos, &sbc, &self.rho);
        let mut vel: Vec<[f64; 2]> = (0..n)
            .into_par_iter()
            .map(|i| {
                let (a, b) = (nl.offsets[i], nl.offsets[i + 1]);
                let si = sbc[i];
                let (mut drr_r, mut drz_z, mut drz_r, mut dzz_z) = (0.0, 0.0, 0.0, 0.0);
                for (&j, g) in nl.indices[a..b].iter().zip(&w[a..b]) {
                    let sj = sbc[j];
                    drr_r += g[0] * (sj[0] - si[0]);
                    drz_r += g[0] * (sj[3] - si[3]);
                    drz_z += g[1] * (sj[3] - si[3]);
                    dzz_z += g[1] * (sj[1] - si[1]);
                }
                let v = self.vel[i];
                if axis(i) {
                    [0.0, v[1] + dt * (2.0 * drz_r + dzz_z) / rho[i]]
                } else {
                    let r = pos[i][0];
                    [
                        v[0] + dt * (drr_r + (si[0] - si[2]) / r + drz_z) / rho[i],
                        v[1] + dt * (drz_r + si[3] / r + dzz_z) / rho[i],
                    ]
                }
            })
            .collect();
        self.contact_dissipation += self.hold_on_anvil(&mut vel);

        // 3. Conservative smoothing of the velocity.
        let shepard: Vec<f64> = w.iter().map(|x| x[2]).collect();
        let ke = |v: &[[f64; 2]]| -> f64 {
            v.iter()
                .zip(&self.mass)
                .map(|(v, m)| 0.5 * m * (v[0] * v[0] + v[1] * v[1]))
                .sum()
        };
        let ke_before = ke(&vel);
        let mut vel = smooth(
            &nl,
            &shepard,
            &with_images(&vel, &ghosts, |v| [-v[0], v[1]]),
            alpha,
        );
        for i in (0..n).step_by(nr) {
            vel[i][0] = 0.0;
        }
        for (v, &c) in vel.iter_mut().zip(&self.contact) {
            if c {
                v[1] = 0.0;
            }
        }
        self.smoothing_dissipation += ke_before - ke(&vel);

        // 4. Velocity gradients and continuity.
        let vel_ext = with_images(&vel, &ghosts, |v| [-v[0], v[1]]);
        let grads: Vec<[f64; 4]> = (0..n)
            .into_par_iter()
            .map(|i| {
                let (a, b) = (nl.offsets[i], nl.offsets[i + 1]);
                let vi = vel[i];
                let mut gr = [0.0; 4]; // dvr/dR, dvr/dZ, dvz/dR, dvz/dZ
                for (&j, g) in nl.indices[a..b].iter().zip(&w[a..b]) {
                    let dv = [vel_ext[j][0] - vi[0], vel_ext[j][1] - vi[1]];
                    gr[0] += g[0] * dv[0];
                    gr[1] += g[1] * dv[0];
                    gr[2] += g[0] * dv[1];
                    gr[3] += g[1] * dv[1];
                }
                gr
            })
            .collect();
        let hoop_rate = |i: usize| -> f64 {
            if axis(i) {
                grads[i][0]
            } else {
                vel[i][0] / self.pos[i][0]
            }
        };
        let rho_new: Vec<[f64; 1]> = (0..n)
            .map(|i| {
                let div = grads[i][0] + grads[i][3] + hoop_rate(i);
                [self.rho[i] * (1.0 - dt * div)]
            })
            .collect();
        let rho_new = smooth(&nl, &shepard, &with_images(&rho_new, &ghosts, |r| r), alpha);

        // 5. Constitutive update.
        let (jc, eos, mu, cap) = (
            self.jc,
            self.eos,
            self.p.shear_modulus,
            self.p.specific_heat,
        );
        let updates: Vec<(Stress, f64, f64, f64, f64)> = (0..n)
            .into_par_iter()
            .map(|i| {
                let g = grads[i];
                let d_rr = g[0];
                let d_zz = g[3];
                let d_tt = hoop_rate(i);
                // On the axis, symmetry gives dU_R/dZ = dU_Z/dR = 0: no shear
                // and no spin (sigma_RZ is odd in R).
                let (d_rz, omega) = if axis(i) {
                    (0.0, 0.0)
                } else {
                    (0.5 * (g[1] + g[2]), 0.5 * (g[1] - g[2]))
                };
                let dvol = (d_rr + d_zz + d_tt) / 3.0;
                let s = self.dev[i];
                let trial = [
                    s[0] + dt * (2.0 * omega * s[3] + 2.0 * mu * (d_rr - dvol)),
                    s[1] + dt * (-2.0 * omega * s[3] + 2.0 * mu * (d_zz - dvol)),
                    s[2] + dt * (2.0 * mu * (d_tt - dvol)),
                    s[3] + dt * (omega * (s[1] - s[0]) + 2.0 * mu * d_rz),
                ];
                let rate = (d_rr * d_rr + d_zz * d_zz + d_tt * d_tt + 2.0 * d_rz * d_rz).sqrt();
                let sy = jc.flow_stress(self.eps_p[i], rate, self.temp[i]);
                let ret = radial_return(&trial, sy, mu);
                let rho = rho_new[i][0];
                let p_new = eos.pressure(rho);
                let dtemp = ret.plastic_work / (rho * cap);
                // Stress power with the mid-step stress, per unit mass.
                let p_old = self.pressure[i];
                let sm = |k: usize, p: f64| 0.5 * (s[k] + ret.stress[k]) - p;
                let pm = 0.5 * (p_old + p_new);
                let power = sm(0, pm) * d_rr
                    + sm(1, pm) * d_zz
                    + sm(2, pm) * d_tt
                    + 2.0 * 0.5 * (s[3] + ret.stress[3]) * d_rz;
                let de = dt * power * self.mass[i] / rho;
                (ret.stress, p_new, ret.plastic_strain, dtemp, de)
            })
            .collect();
        for (i, (s, p, deps, dtemp, de)) in updates.into_iter().enumerate() {
            self.dev[i] = s;
            self.pressure[i] = p;
            self.eps_p[i] += deps;
            self.temp[i] += dtemp;
            self.rho[i] = rho_new[i][0];
            self.internal_energy += de;
        }

        // 6. Positions, anvil contact.
        for (x, v) in self.pos.iter_mut().zip(&vel) {
            x[0] += dt * v[0];
            x[1] += dt * v[1];
        }
        self.vel = vel;
        self.time += dt;
        self.steps += 1;
        self.update_contact()?;
        self.check_finite()?;
        self.apply_stress_bc();
        self.track_spacing(&nl, &pos_ext);

        let e = self.energy_error();
        if e > ENERGY_ERROR_BOUND {
            return Err(Error::EnergyDrift {
                error: e,
                bound: ENERGY_ERROR_BOUND,
                time: self.time,
            });
        }
        self.dt = self.stable_dt();
        check_time_step(self.dt, self.dt0, self.time)?;
        self.update_at_rest();
        Ok(())
    }

    /// Holds particles touching the anvil at `U_Z = 0` and returns the kinetic
    /// energy that removes.
    fn hold_on_anvil(&self, vel: &mut [[f64; 2]]) -> f64 {
        let mut lost = 0.0;
        for i in 0..vel.len() {
            if self.contact[i] {
                lost += 0.5 * self.mass[i] * vel[i][1] * vel[i][1];
                vel[i][1] = 0.0;
            }
        }
        lost
    }

    fn update_contact(&mut self) -> Result<()> {
        for i in 0..self.particles() {
            let z = self.pos[i][1];
            if self.contact[i] {
                // Released when the normal stress turns tensile.
                if self.dev[i][1] - self.pressure[i] > 0.0 {
                    self.contact[i] = false;
                }
            } else if z < 0.0 {
                if z < -0.5 * self.h {
                    return Err(Error::ThroughBoundary {
                        particle: i,
                        boundary: "anvil",
                        time: self.time,
                        position: z,
                    });
                }
                self.pos[i][1] = 0.0;
                self.contact_dissipation += 0.5 * self.mass[i] * self.vel[i][1].powi(2);
                self.vel[i][1] = 0.0;
                self.contact[i] = true;
            }
            if !i.is_multiple_of(self.nr) && self.pos[i][0] <= 0.0 {
                return Err(Error::ThroughBoundary {
                    particle: i,
                    boundary: "axis",
                    time: self.time,
                    position: self.pos[i][0],
                });
            }
        }
        Ok(())
    }

    fn check_finite(&self) -> Result<()> {
        let finite = |x: &[f64]| x.iter().all(|v| v.is_finite());
        let bad = (0..self.particles()).find_map(|i| {
            if !finite(&self.pos[i]) {
                Some("position")
            } else if !finite(&self.vel[i]) {
                Some("velocity")
            } else if !self.rho[i].is_finite() {
                Some("density")
            } else if !finite(&self.dev[i]) {
                Some("deviatoric stress")
            } else if !self.temp[i].is_finite() {
                Some("temperature")
            } else {
                None
            }
            .map(|field| (field, i))
        });
        match bad {
            Some((field, particle)) => Err(Error::NonFinite {
                field,
                particle,
                time: self.time,
            }),
            None => Ok(()),
        }
    }

    /// Stress used by the momentum equation: the constitutive stress with the
    /// traction-free and smooth-contact conditions applied on the surfaces.
    fn apply_stress_bc(&mut self) {
        let n = self.particles();
        for i in 0..n {
            let p = self.pressure[i];
            let d = self.dev[i];
            self.stress_bc[i] = [d[0] - p, d[1] - p, d[2] - p, d[3]];
        }
        let (nr, nz) = (self.nr, self.nz);
        for (k, &i) in self.mantle.particles.iter().enumerate() {
            let s = &self.stress_bc[i];
            self.stress_bc[i] = if k == nz - 1 || (k == 0 && !self.contact[i]) {
                corner_free(s)
            } else {
                traction_free(s, self.mantle.normal(k, &self.pos))
            };
        }
        for (k, &i) in self.top.particles.iter().enumerate().take(nr - 1) {
            let n = if k == 0 {
                [0.0, 1.0]
            } else {
                self.top.normal(k, &self.pos)
            };
            self.stress_bc[i] = traction_free(&self.stress_bc[i], n);
        }
        for (k, &i) in self.face.particles.iter().enumerate().take(nr - 1) {
            if self.contact[i] {
                // Smooth anvil: no shear traction.
                self.stress_bc[i][3] = 0.0;
            } else {
                let n = if k == 0 {
                    [0.0, -1.0]
                } else {
                    self.face.normal(k, &self.pos)
                };
                self.stress_bc[i] = traction_free(&self.stress_bc[i], n);
            }
        }
        // Particles that started elsewhere but touch the anvil (a folded
        // mantle) carry no shear there either.
        for i in 0..n {
            if self.contact[i] && i >= self.nr {
                self.stress_bc[i][3] = 0.0;
            }
        }
    }

    fn track_spacing(&mut self, nl: &NeighborList, pos: &[[f64; 2]]) {
        let d0 = self.r0 / (self.nr - 1) as f64;
        let min2 = (0..nl.len())
            .into_par_iter()
            .map(|i| {
                nl.of(i)
                    .iter()
                    .filter(|&&j| j != i)
                    .map(|&j| {
                        let (a, b) = (pos[i][0] - pos[j][0], pos[i][1] - pos[j][1]);
                        a * a + b * b
                    })
                    .fold(f64::INFINITY, f64::min)
            })
            .reduce(|| f64::INFINITY, f64::min);
        self.min_spacing = self.min_spacing.min(min2.sqrt() / d0);
    }

    fn kinetic_energy(&self) -> f64 {
        self.vel
            .iter()
            .zip(&self.mass)
            .map(|(v, m)| 0.5 * m * (v[0] * v[0] + v[1] * v[1]))
            .sum()
    }

    fn energy_error(&self) -> f64 {
        (self.kinetic_energy()
            + self.internal_energy
            + self.smoothing_dissipation
            + self.contact_dissipation
            - self.initial_energy)
            .abs()
            / self.initial_energy
    }

    /// The centre-of-mass axial velocity toward the anvil.
    pub fn centre_of_mass_speed(&self) -> f64 {
        let (mut mv, mut m) = (0.0, 0.0);
        for (v, mi) in self.vel.iter().zip(&self.mass) {
            mv -= mi * v[1];
            m += mi;
        }
        mv / m
    }

    fn update_at_rest(&mut self) {
        // The rod is at rest once its momentum toward the anvil is spent: the
        // centre of mass no longer moves toward the anvil.
        if self.centre_of_mass_speed() <= 0.0 && !self.contact.iter().any(|&c| c) {
            self.at_rest = true;
        }
    }

    /// Current values of [`TAYLOR_OBSERVABLES`], in that order.
    pub fn observables(&self) -> Vec<f64> {
        let (nr, nz) = (self.nr, self.nz);
        let (zmin, zmax) = self
            .pos
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x[1]), hi.max(x[1]))
            });
        let mushroom = self
            .face
            .particles
            .iter()
            .map(|&i| self.pos[i][0])
            .fold(0.0, f64::max);
        // Undeformed length: walk down the mantle from the free end.
        let strain = |k: usize| self.pos[k * nr + nr - 1][0] / self.r0 - 1.0;
        let z_of = |k: usize| self.pos[k * nr + nr - 1][1];
        let z_top = z_of(nz - 1);
        let mut undeformed = z_top - z_of(0);
        for k in (0..nz - 1).rev() {
            if strain(k) >= UNDEFORMED_STRAIN {
                let (s0, s1) = (strain(k + 1), strain(k));
                let frac = ((UNDEFORMED_STRAIN - s0) / (s1 - s0)).clamp(0.0, 1.0);
                let z = z_of(k + 1) + frac * (z_of(k) - z_of(k + 1));
                undeformed = z_top - z;
                break;
            }
        }
        let tail = (nz - 1) * nr;
        let values = [
            zmax - zmin,
            mushroom,
            undeformed,
            -self.vel[tail][1],
            self.pos[0][1],
            self.eps_p.iter().copied().fold(0.0, f64::max),
            self.temp.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            self.kinetic_energy(),
            self.internal_energy,
            self.smoothing_dissipation,
            self.contact_dissipation,
            self.energy_error(),
            if self.at_rest { 1.0 } else { 0.0 },
        ];
        debug_assert_eq!(values.len(), TAYLOR_OBSERVABLES.len());
        values.to_vec()
    }

    /// Particle positions and fields.
    pub fn snapshot(&self) -> Snapshot {
        let stress: Vec<f64> = self
            .dev
            .iter()
            .zip(&self.pressure)
            .flat_map(|(d, p)| [d[0] - p, d[1] - p, d[2] - p, d[3]])
            .collect();
        Snapshot {
            time: self.time,
            positions: self.pos.clone(),
            fields: vec![
                Field {
                    name: "density",
                    components: &["rho"],
                    unit: "kg/m3",
                    data: self.rho.clone(),
                },
                Field {
                    name: "velocity",
                    components: &["R", "Z"],
                    unit: "m/s",
                    data: self.vel.iter().flat_map(|v| *v).collect(),
                },
                Field {
                    name: "pressure",
                    components: &["P"],
                    unit: "Pa",
                    data: self.pressure.clone(),
                },
                Field {
                    name: "stress",
                    components: &["RR", "ZZ", "TT", "RZ"],
                    unit: "Pa",
                    data: stress,
                },
                Field {
                    name: "plastic_strain",
                    components: &["eps_p"],
                    unit: "1",
                    data: self.eps_p.clone(),
                },
                Field {
                    name: "temperature",
                    components: &["T"],
                    unit: "K",
                    data: self.temp.clone(),
                },
                Field {
                    name: "in_contact",
                    components: &["contact"],
                    unit: "bool",
                    data: self.contact.iter().map(|&c| c as u8 as f64).collect(),
                },
            ],
        }
    }
}
