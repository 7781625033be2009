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
use super::{LOST_CONTACT, LOST_SMOOTHING, MIN_LEN, SetupAxi, StateAxi, TaylorSolver};
use super::{neighbours, shifting, surfaces};
use crate::error::{Error, Result};
use crate::isa::Isa;
use crate::lanes::W;
use crate::solver::COURANT;
use crate::solver::axisymmetric::pairs::{PairInputs, Rows};
use crate::solver::axisymmetric::scheme::SmoothingOrder;
use crate::solver::axisymmetric::team::{Chunks, Team};
use crate::solver::shared::{ENERGY_ERROR_BOUND, above, check_spacing};

impl TaylorSolver {
    /// Advances one step.
    pub fn step(&mut self) -> Result<()> {
        let mut ws = std::mem::take(&mut self.pipe.ws);
        // The whole step runs on one worker of the thread pool, which leads
        // a team of the others through its parallel passes
        // (src/solver/axisymmetric/team.rs). The neighbour rebuild comes first, with its
        // own parallel loops, so that no follower waits through it. Particle
        // shifting, if on, follows it, on lists that hold every pair in the
        // support (so that it does not depend on when they were built, and a
        // restored run shifts as the original did).
        let result = rayon::scope(|_| {
            let rebuilt = neighbours::needs_rebuild(&self.setup, &self.state, &ws);
            if rebuilt {
                neighbours::rebuild_neighbours(&self.setup, &self.state, &mut ws);
            }
            // New lists may bring new mirror images, and pairs with them.
            let margin = if rebuilt { None } else { ws.shift_margin };
            if self.setup.scheme.shifting > 0.0
                && shifting::shift(&self.setup, &mut self.state, &mut ws, margin)?
                && neighbours::needs_rebuild(&self.setup, &self.state, &ws)
            {
                neighbours::rebuild_neighbours(&self.setup, &self.state, &mut ws);
            }
            let isa = self.pipe.isa;
            Team::lead(|team| step_in(&self.setup, &mut self.state, isa, &mut ws, team))
        });
        self.pipe.ws = ws;
        result
    }
}

/// The step's passes, in order, once the neighbour lists (and the
/// shifting) are done: a function of the setup, the state, the compiled
/// copy and the workspace.
fn step_in(
    setup: &SetupAxi,
    state: &mut StateAxi,
    isa: Isa,
    ws: &mut Workspace,
    team: &Team,
) -> Result<()> {
    let n = state.pos.len();
    let dt = state.clock.dt;
    let scheme = setup.scheme;
    ws.rate.resize(n, [0.0; 4]);
    state.material_state.fit(n);
    ws.scratch.fit();
    let stride = ws.lists.stride.max(1);
    let images = &ws.lists.images;
    let f = &mut ws.fields;
    // Mirror images across the axis and the anvil of the particles near
    // them, so that those particles see a symmetric neighbourhood (the
    // anvil is rigid and smooth): the velocity component and the shear
    // stress odd across the plane, the rest even.
    f.pos[..n].copy_from_slice(&state.pos);
    fill_images(&mut f.pos, n, images);
    for ((v, m), r) in f.vol.iter_mut().zip(&setup.mass).zip(&state.rho) {
        *v = m / r;
    }
    fill_images(&mut f.vol, n, images);
    f.sbc[..n].copy_from_slice(&state.stress_bc);
    fill_images(&mut f.sbc, n, images);

    // 1-2. The pair pass and the momentum equation.
    let inputs = PairInputs {
        pos: &f.pos,
        vol: &f.vol,
        sbc: &f.sbc,
        nbr: &ws.lists.nbr,
        nbr_len: &ws.lists.nbr_len,
        stride,
        vel: &state.vel,
        rho: &state.rho,
        on_axis: &state.on_axis,
        h: setup.h,
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
        isa,
        &inputs,
        out,
        &ws.scratch,
        &setup.mass,
        &state.contact,
    );
    let a = BatchTally::total(&ws.sums.batches);
    if let Some((particle, condition)) = a.singular {
        return Err(Error::SingularMomentMatrix {
            method: crate::error::MomentMethod::Msph,
            particle,
            time: state.clock.time,
            condition,
        });
    }
    let d0 = setup.spacing();
    let ratio = a.min_d2.sqrt() / d0;
    state.min_spacing = state.min_spacing.min(ratio);
    check_spacing(
        ratio,
        state.clock.time,
        if setup.scheme.shifting == 0.0 {
            "; at large strain, use scheme = large_strain, the default (it sets \
                 smoothing_order = 2, smoothing_ratio = 2 and shifting = 0.1; README, \
                 \"Particle shifting\")"
        } else {
            ""
        },
    )?;
    state.energy.lost[LOST_CONTACT] += a.held;

    let p = Pass {
        team,
        isa,
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
        mass: &setup.mass,
        on_axis: &state.on_axis,
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
        &state.contact,
        &f.vel,
        &f.lap,
        &mut f.vel_s[..n],
        &mut ws.sums.smoothing,
    );
    state.energy.lost[LOST_SMOOTHING] += ke.before - ke.after;

    // 4. Velocity gradients and continuity.
    fill_images(&mut f.vel_s, n, images);
    let out = ContinuityChunks {
        grads: Chunks::new(&mut ws.grads, MIN_LEN),
        rho_out: Chunks::new(&mut f.rho[..n], MIN_LEN),
    };
    continuity(p, &f.vel_s, &state.rho, out);
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
        material: setup.material,
        h: setup.h,
    };
    let out = UpdateChunks {
        dev: Chunks::new(&mut state.dev, MIN_LEN),
        pressure: Chunks::new(&mut state.pressure, MIN_LEN),
        eps_p: Chunks::new(&mut state.eps_p, MIN_LEN),
        temp: Chunks::new(&mut state.temp, MIN_LEN),
        rho: Chunks::new(&mut state.rho, MIN_LEN),
        models: Chunks::new(state.material_state.points_mut(), MIN_LEN),
        pos: Chunks::new(&mut state.pos, MIN_LEN),
        vel: Chunks::new(&mut state.vel, MIN_LEN),
        contact: Chunks::new(&mut state.contact, MIN_LEN),
        stress_bc: Chunks::new(&mut state.stress_bc, MIN_LEN),
        tally: Chunks::new(&mut ws.sums.tallies, 1),
        work: Chunks::new(&mut ws.rate[..], MIN_LEN),
    };
    update(p, &inputs, out);
    let t = Tally::total(&ws.sums.tallies);
    end_step(setup, state, ws, &t, dt)
}

/// The end of a step from the sums of its update pass: the energy books,
/// the clock, the stops, the stress boundary conditions (and the work
/// they take), the next time step and the rest test.
/// The end of a step: the boundary stresses, the energies, the guards,
/// the next step and the rest detector.
fn end_step(
    setup: &SetupAxi,
    state: &mut StateAxi,
    ws: &mut Workspace,
    t: &Tally,
    dt: f64,
) -> Result<()> {
    state.energy.internal += t.internal;
    state.energy.lost[LOST_CONTACT] += t.contact_lost;
    ws.shift_margin = Some(2.0 * dt * t.fastest2.sqrt());
    state.clock.time += dt;
    state.clock.steps += 1;
    if let Some(b) = t.through {
        return Err(Error::ThroughBoundary {
            particle: b.particle,
            boundary: b.boundary,
            time: state.clock.time,
            position: b.position,
        });
    }
    if let Some(c) = t.compression {
        return Err(Error::CompressionLimit {
            particle: c.particle,
            time: state.clock.time,
            compression: c.compression,
            limit: c.limit,
        });
    }
    if let Some((field, particle)) = t.non_finite.map(|(i, f)| (f, i)) {
        return Err(Error::NonFinite {
            field,
            particle,
            time: state.clock.time,
        });
    }
    // The boundary conditions on the new stress, and the work they take
    // from the new half of the step's stress power.
    ws.raw_bc.clear();
    ws.raw_bc.extend_from_slice(&state.stress_bc);
    surfaces::apply_surface_stress_bc(setup, state);
    let mut booked = 0.0;
    for ((bc, raw), w) in state.stress_bc.iter().zip(&ws.raw_bc).zip(&ws.rate) {
        for c in 0..4 {
            booked += (bc[c] - raw[c]) * w[c];
        }
    }
    state.energy.internal += booked;

    let e = state.energy.error(t.kinetic);
    if above(e, ENERGY_ERROR_BOUND) {
        return Err(Error::EnergyDrift {
            error: e,
            bound: ENERGY_ERROR_BOUND,
            time: state.clock.time,
        });
    }
    state.clock.dt = COURANT * setup.h / t.worst_speed;
    state.clock.check_step(state.clock.dt)?;
    // The rod is at rest once its momentum toward the anvil is spent: the
    // centre of mass no longer moves toward the anvil.
    if -t.momentum / t.mass <= 0.0 && !t.touching {
        state.at_rest = true;
    }
    // Or once it is quiet: a flange pressed flat on the anvil never
    // leaves it, and the rod rings elastically on it for ever. Its impact
    // energy is spent once the kinetic energy has stayed below
    // QUIET_FRACTION of it for QUIET_TRANSITS elastic transits L0/Ce.
    let (length, speed) = (setup.rod.initial_length, setup.wave_speed());
    if state.quiet_since.at_rest(
        state.clock.time,
        t.kinetic,
        state.energy.initial,
        length,
        speed,
    ) {
        state.at_rest = true;
    }
    Ok(())
}
