//! One step of the axisymmetric solver: the passes of
//! [`super::passes`] in order, with the stops between them (a degenerate
//! moment matrix, collapsed spacing, a particle through a boundary, a
//! compression past the equation of state, a non-finite field, energy
//! drift, a collapsed time step) and the end of the step (the stress
//! boundary conditions, the next time step, the rest test).

use super::mirror::fill_images;
use super::passes::{
    ContinuityChunks, PairChunks, Pass, UpdateChunks, UpdateInputs, continuity, laplacians,
    pair_pass, smooth_velocity, update,
};
use super::workspace::{BatchTally, Tally, Workspace};
use super::{LOST_CONTACT, LOST_SMOOTHING, MIN_LEN, TaylorSolver};
use crate::error::{Error, Result};
use crate::lanes::W;
use crate::solver::COURANT;
use crate::solver::axisymmetric::pairs::{PairInputs, Rows};
use crate::solver::axisymmetric::scheme::{MsphScheme, SmoothingOrder};
use crate::solver::axisymmetric::team::{Chunks, Team};
use crate::solver::shared::{ENERGY_ERROR_BOUND, above, check_spacing};

impl TaylorSolver {
    /// Advances one step.
    pub fn step(&mut self) -> Result<()> {
        let mut ws = std::mem::take(&mut self.ws);
        // The whole step runs on one worker of the thread pool, which leads
        // a team of the others through its parallel passes
        // (src/solver/axisymmetric/team.rs). The neighbour rebuild comes first, with its
        // own parallel loops, so that no follower waits through it. Particle
        // shifting, if on, follows it, on lists that hold every pair in the
        // support (so that it does not depend on when they were built, and a
        // restored run shifts as the original did).
        let result = rayon::scope(|_| {
            let rebuilt = self.needs_rebuild(&ws);
            if rebuilt {
                self.rebuild_neighbours(&mut ws);
            }
            // New lists may bring new mirror images, and pairs with them.
            let margin = if rebuilt { None } else { ws.shift_margin };
            if self.p.shifting > 0.0 && self.shift(&mut ws, margin)? && self.needs_rebuild(&ws) {
                self.rebuild_neighbours(&mut ws);
            }
            Team::lead(|team| self.step_in(&mut ws, team))
        });
        self.ws = ws;
        result
    }

    fn step_in(&mut self, ws: &mut Workspace, team: &Team) -> Result<()> {
        let n = self.particles();
        let dt = self.clock.dt;
        let scheme = MsphScheme::of(&self.p);
        ws.rate.resize(n, [0.0; 4]);
        self.material_state.fit(n);
        ws.scratch.fit();
        let stride = ws.lists.stride.max(1);
        let images = &ws.lists.images;
        let f = &mut ws.fields;
        // Mirror images across the axis and the anvil of the particles near
        // them, so that those particles see a symmetric neighbourhood (the
        // anvil is rigid and smooth): the velocity component and the shear
        // stress odd across the plane, the rest even.
        f.pos[..n].copy_from_slice(&self.pos);
        fill_images(&mut f.pos, n, images);
        for ((v, m), r) in f.vol.iter_mut().zip(&self.mass).zip(&self.rho) {
            *v = m / r;
        }
        fill_images(&mut f.vol, n, images);
        f.sbc[..n].copy_from_slice(&self.stress_bc);
        fill_images(&mut f.sbc, n, images);

        // 1-2. The pair pass and the momentum equation.
        let inputs = PairInputs {
            pos: &f.pos,
            vol: &f.vol,
            sbc: &f.sbc,
            nbr: &ws.lists.nbr,
            nbr_len: &ws.lists.nbr_len,
            stride,
            vel: &self.vel,
            rho: &self.rho,
            on_axis: &self.on_axis,
            h: self.h,
            dt,
        };
        let r = &mut ws.rows;
        let rows = MIN_LEN * stride;
        let out = PairChunks {
            act: Chunks::new(&mut r.act, rows),
            wr: Chunks::new(&mut r.wr, rows),
            wz: Chunks::new(&mut r.wz, rows),
            wk: Chunks::new(&mut r.wk, rows),
            part: Chunks::new(&mut r.part, MIN_LEN),
            vel: Chunks::new(&mut f.vel[..n], MIN_LEN),
            tallies: Chunks::new(&mut ws.sums.batches, MIN_LEN / W),
        };
        pair_pass(
            team,
            self.isa,
            &inputs,
            out,
            &ws.scratch,
            &self.mass,
            &self.contact,
        );
        let a = BatchTally::total(&ws.sums.batches);
        if let Some((particle, condition)) = a.singular {
            return Err(Error::SingularMomentMatrix {
                method: crate::error::MomentMethod::Msph,
                particle,
                time: self.clock.time,
                condition,
            });
        }
        let d0 = self.spacing();
        let ratio = a.min_d2.sqrt() / d0;
        self.min_spacing = self.min_spacing.min(ratio);
        check_spacing(
            ratio,
            self.clock.time,
            if self.p.shifting == 0.0 {
                "; at large strain, use scheme = large_strain, the default (it sets \
                 smoothing_order = 2, smoothing_ratio = 2 and shifting = 0.1; README, \
                 \"Particle shifting\")"
            } else {
                ""
            },
        )?;
        self.energy.lost[LOST_CONTACT] += a.held;

        let p = Pass {
            team,
            isa: self.isa,
            rows: Rows {
                act: &r.act,
                wr: &r.wr,
                wz: &r.wz,
                wk: &r.wk,
                part: &r.part,
                stride,
            },
            n,
            images,
            alpha: scheme.smoothing,
            order2: scheme.order == SmoothingOrder::BiLaplacian,
            mass: &self.mass,
            on_axis: &self.on_axis,
            pos: &f.pos,
            dt,
        };

        // 3. Conservative smoothing of the velocity.
        fill_images(&mut f.vel, n, images);
        if p.order2 {
            // Order 2: first the operator L v = (Shepard mean of v) - v.
            laplacians(p, &f.vel, &mut f.lap);
        }
        let ke = smooth_velocity(
            p,
            &self.contact,
            &f.vel,
            &f.lap,
            &mut f.vel_s[..n],
            &mut ws.sums.smoothing,
        );
        self.energy.lost[LOST_SMOOTHING] += ke.before - ke.after;

        // 4. Velocity gradients and continuity.
        fill_images(&mut f.vel_s, n, images);
        let out = ContinuityChunks {
            grads: Chunks::new(&mut ws.grads, MIN_LEN),
            rho_out: Chunks::new(&mut f.rho[..n], MIN_LEN),
        };
        continuity(p, &f.vel_s, &self.rho, out);
        fill_images(&mut f.rho, n, images);
        // With order 2 the density is smoothed by the same bi-Laplacian as
        // the velocity: first L ρ, then the Shepard mean of L ρ in the loop.
        if p.order2 {
            laplacians(p, &f.rho, &mut f.lap_rho);
        }

        // 5-6. The constitutive update, positions, contact and the sums.
        let inputs = UpdateInputs {
            vel: &f.vel_s,
            grads: &ws.grads,
            rho_raw: &f.rho,
            lap_rho: &f.lap_rho,
            material: self.material,
            h: self.h,
        };
        let out = UpdateChunks {
            dev: Chunks::new(&mut self.dev, MIN_LEN),
            pressure: Chunks::new(&mut self.pressure, MIN_LEN),
            eps_p: Chunks::new(&mut self.eps_p, MIN_LEN),
            temp: Chunks::new(&mut self.temp, MIN_LEN),
            rho: Chunks::new(&mut self.rho, MIN_LEN),
            models: Chunks::new(self.material_state.points_mut(), MIN_LEN),
            pos: Chunks::new(&mut self.pos, MIN_LEN),
            vel: Chunks::new(&mut self.vel, MIN_LEN),
            contact: Chunks::new(&mut self.contact, MIN_LEN),
            stress_bc: Chunks::new(&mut self.stress_bc, MIN_LEN),
            tally: Chunks::new(&mut ws.sums.tallies, 1),
            work: Chunks::new(&mut ws.rate[..], MIN_LEN),
        };
        update(p, &inputs, out);
        let t = Tally::total(&ws.sums.tallies);
        self.end_step(ws, &t, dt)
    }

    /// The end of a step from the sums of its update pass: the energy books,
    /// the clock, the stops, the stress boundary conditions (and the work
    /// they take), the next time step and the rest test.
    fn end_step(&mut self, ws: &mut Workspace, t: &Tally, dt: f64) -> Result<()> {
        self.energy.internal += t.internal;
        self.energy.lost[LOST_CONTACT] += t.contact_lost;
        ws.shift_margin = Some(2.0 * dt * t.fastest2.sqrt());
        self.clock.time += dt;
        self.clock.steps += 1;
        if let Some(b) = t.through {
            return Err(Error::ThroughBoundary {
                particle: b.particle,
                boundary: b.boundary,
                time: self.clock.time,
                position: b.position,
            });
        }
        if let Some(c) = t.compression {
            return Err(Error::CompressionLimit {
                particle: c.particle,
                time: self.clock.time,
                compression: c.compression,
                limit: c.limit,
            });
        }
        if let Some((field, particle)) = t.non_finite.map(|(i, f)| (f, i)) {
            return Err(Error::NonFinite {
                field,
                particle,
                time: self.clock.time,
            });
        }
        // The boundary conditions on the new stress, and the work they take
        // from the new half of the step's stress power.
        ws.raw_bc.clear();
        ws.raw_bc.extend_from_slice(&self.stress_bc);
        self.apply_surface_stress_bc();
        let mut booked = 0.0;
        for ((bc, raw), w) in self.stress_bc.iter().zip(&ws.raw_bc).zip(&ws.rate) {
            for c in 0..4 {
                booked += (bc[c] - raw[c]) * w[c];
            }
        }
        self.energy.internal += booked;

        let e = self.energy_error_with(t.kinetic);
        if above(e, ENERGY_ERROR_BOUND) {
            return Err(Error::EnergyDrift {
                error: e,
                bound: ENERGY_ERROR_BOUND,
                time: self.clock.time,
            });
        }
        self.clock.dt = COURANT * self.h / t.worst_speed;
        self.clock.check_step(self.clock.dt)?;
        // The rod is at rest once its momentum toward the anvil is spent: the
        // centre of mass no longer moves toward the anvil.
        if -t.momentum / t.mass <= 0.0 && !t.touching {
            self.at_rest = true;
        }
        // Or once it is quiet: a flange pressed flat on the anvil never
        // leaves it, and the rod rings elastically on it for ever. Its impact
        // energy is spent once the kinetic energy has stayed below
        // QUIET_FRACTION of it for QUIET_TRANSITS elastic transits L0/Ce.
        let (length, speed) = (self.p.initial_length, self.wave_speed());
        if self.quiet_since.at_rest(
            self.clock.time,
            t.kinetic,
            self.energy.initial,
            length,
            speed,
        ) {
            self.at_rest = true;
        }
        Ok(())
    }
}
