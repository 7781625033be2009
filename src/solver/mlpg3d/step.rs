//! One step of the central-difference scheme (module docs of [`super`]):
//! the forces, then the passes of [`super::motion`] (velocities,
//! smoothing, contact, positions), the shifting, the geometry, the
//! material pass of [`super::update`], the checks and the next step.

use super::LOST_CONTACT;
use super::LOST_DAMPING;
use super::LOST_SMOOTHING;
use super::balance::GRANULE;
use super::geometry;
use super::geometry::Geometry;
use super::halo::HaloFields;
use super::motion::{self, Frame};
use super::profile::Phase;
use super::profile::Stopwatch;
use super::scratch::ForceBuffers;
use super::scratch::Scratch;
use super::scratch::Tally;
use super::shielding::Shielding;
use super::shifting;
use super::update::{self, MaterialFields, MaterialInputs};
use super::util::extended;
use super::util::first_where;
use super::wave_speed;
use crate::ENERGY_ERROR_BOUND;
use crate::Error;
use crate::approx::mirror;
use crate::error::Result;
use crate::material::tensor::Full;
use crate::solver::mlpg3d::Pipeline3d;
use crate::solver::mlpg3d::Setup3d;
use crate::solver::mlpg3d::State3d;
use crate::solver::shared::above;
use crate::solver::shared::check_spacing;
use rayon::iter::IndexedParallelIterator;
use rayon::iter::IntoParallelRefIterator;
use rayon::iter::IntoParallelRefMutIterator;
use rayon::iter::ParallelIterator;
use rayon::slice::ParallelSliceMut;

/// The step with its buffers (reused from step to step: the step
/// allocates nothing once they have their size).
pub(super) fn step_with(
    setup: &Setup3d,
    state: &mut State3d,
    pipe: &mut Pipeline3d,
    scratch: &mut Scratch,
    mut watch: Stopwatch,
) -> Result<()> {
    let dt = state.clock.dt;
    let nodal = setup.rod.scheme.forces.nodal();
    // 1. Forces from σ^n and the viscous stress.
    let g = pipe.geometry.as_ref().expect("built above");
    total_stress(
        &state.dev,
        &state.pressure,
        &state.visc,
        &mut scratch.forces.total,
    );
    forces(
        (g, &*pipe.ranks),
        nodal,
        (&setup.mass, &state.rho),
        &mut scratch.forces,
        &mut scratch.images.total,
    );
    pipe.profile.lap(Phase::Force, &mut watch);
    // 2-3. Velocities, contact, positions.
    let damaging = setup.damaging();
    if !setup.group.is_empty() || damaging {
        scratch.contact.before.clone_from(&state.vel);
    }
    let frame = Frame {
        dt,
        now: state.clock.time,
        nodal,
        spacing: setup.d_min0,
        reach: setup.reach,
        geometry: g,
        mass: &setup.mass,
        rho: &state.rho,
        group: &setup.group,
        plane: &setup.plane,
        held: &setup.held,
        ranks: &*pipe.ranks,
    };
    motion::kick(
        &frame,
        &scratch.forces.force,
        &mut state.vel,
        &mut state.contact,
        &mut state.reaction,
        &mut scratch.kicks,
    );
    pipe.profile.lap(Phase::Kick, &mut watch);
    // Velocity smoothing toward the MLS approximation at the node.
    let alpha = setup.rod.scheme.smoothing * setup.rod.step_scale();
    if alpha > 0.0 {
        state.energy.lost[LOST_SMOOTHING] += motion::smooth(
            &frame,
            (alpha, setup.rod.scheme.order.power()),
            &mut state.vel,
            &state.contact,
            &mut scratch.smoothing,
            &mut scratch.images.vel,
        );
    }
    pipe.profile.lap(Phase::Smoothing, &mut watch);
    // Contact between the bodies, then between pulverized nodes closer
    // than half a spacing.
    motion::collide(
        &frame,
        &state.pos,
        damaging.then(|| state.material_state.marks()),
        &mut state.vel,
        &mut scratch.contact,
        &mut scratch.images,
        &mut state.energy.lost[LOST_CONTACT],
    );
    motion::clamp(&frame, &mut state.vel, &mut state.energy.lost[LOST_CONTACT]);
    motion::drift(
        &frame,
        setup.anvil,
        &mut state.vel,
        &mut state.pos,
        &mut state.contact,
        &scratch.kicks,
        &mut scratch.moves,
    );
    state.clock.time += dt;
    state.clock.steps += 1;
    motion::settle(
        &scratch.moves,
        &mut state.energy.lost[LOST_CONTACT],
        &mut state.last_release,
        state.clock.time,
    )?;
    motion::check_planes(&state.pos, &setup.plane, state.clock.time)?;
    pipe.profile.lap(Phase::Move, &mut watch);
    if setup.rod.scheme.shifting > 0.0 {
        let g = pipe.geometry.as_mut().expect("built before the step");
        shifting::shift(setup, state, (g, &*pipe.ranks), scratch)?;
    }
    pipe.profile.lap(Phase::Shift, &mut watch);
    // 4. The geometry follows the body.
    let d_min = follow(setup, state, pipe, scratch, &mut watch)?;
    // 5. Velocity gradients and the material. Each rank reads the rows of
    // its part of the points: where the split moved, they follow it.
    let n = state.pos.len();
    let parts = pipe.balance.parts(&*pipe.ranks, n);
    if let Some(g) = pipe.geometry.as_mut() {
        g.held.follow_material(&*pipe.ranks, &mut g.shapes, parts);
    }
    let g = pipe.geometry.as_ref().expect("built above");
    let vel_ext = extended(
        &g.mirror,
        &state.vel,
        &mut scratch.images.vel,
        mirror::vector,
    );
    // Each rank's rows of the material pass's part only (whole blocks of
    // its sums, balanced by cost: `balance.rs`).
    let ranks = &*pipe.ranks;
    let own = pipe.balance.parts(ranks, n)[ranks.rank()].clone();
    if ranks.size() == 1 {
        g.shapes
            .velocity_gradients_on(own, vel_ext, &mut scratch.grad);
    } else {
        // By granules, each booked with the material's cost of the
        // granule: a row's gradient costs by its entries, not as its
        // point's material does, and the split balances both (booked with
        // the material alone, rank 0 of `taylor3d` 10 across waited 1.0 s
        // at the material's gather).
        let first = own.start;
        scratch.grad[own.clone()]
            .par_chunks_mut(GRANULE)
            .zip(pipe.balance.costs_of(&own).par_iter_mut())
            .enumerate()
            .for_each(|(k, (rows, cost))| {
                let watch = std::time::Instant::now();
                let start = first + k * GRANULE;
                for (j, l) in rows.iter_mut().enumerate() {
                    *l = g.shapes.gradient(start + j, vel_ext);
                }
                *cost += watch.elapsed().as_secs_f64();
            });
    }
    pipe.profile.lap(Phase::Gradients, &mut watch);
    // The tensile cracks' shielding zones of the step's start, where a
    // ceramic's cracks shield (`shielding.rs`).
    let zones = Shielding::of(
        (&setup.material, &setup.others, &setup.group),
        state.material_state.points(),
        &state.pos,
        setup.reach,
        !setup.plane.is_empty(),
    );
    // On several ranks with the nodal forces, the deviator, the viscous
    // stress, the pressure, the plastic strain and the temperature go only
    // to the ranks that read them ([`super::halo`]), except where the
    // points' split moves at the end of this step (their next owners
    // read them): then, as with the seed's traction operator, whole.
    let by_halo = ranks.size() > 1 && nodal && !pipe.balance.splits_at_end(ranks);
    update::update_material(
        (ranks, &mut pipe.balance, !by_halo),
        &MaterialInputs {
            dt,
            damping_time: setup.damping_time,
            rod: &setup.material,
            others: &setup.others,
            group: &setup.group,
            mass: &setup.mass,
            vel: &state.vel,
            grad: &scratch.grad,
            shielding: zones.as_ref().map(|z| (&state.pos[..], z)),
        },
        MaterialFields {
            dev: &mut state.dev,
            pressure: &mut state.pressure,
            eps_p: &mut state.eps_p,
            temp: &mut state.temp,
            rho: &mut state.rho,
            visc: &mut state.visc,
            states: state.material_state.points_mut(),
        },
        &mut scratch.results,
    );
    if by_halo {
        let parts = pipe.balance.parts(ranks, n);
        pipe.halo.exchange(
            ranks,
            (g, setup.rod.scheme.shifting > 0.0),
            parts,
            HaloFields::of(state),
        );
    } else {
        pipe.halo.whole();
    }
    // The marks of the nodes on every rank; their damage variables stay
    // with the rank that stepped them (shared every step where the cracks
    // shield: the zones read every node's), and where the split of the
    // points among the ranks moves, the points that change rank go to
    // their new rank.
    // (The buffer taken out and put back: a step allocates nothing.)
    let splits = pipe.balance.splits_at_end(ranks);
    if setup.damage_vars() {
        let mut wire = std::mem::take(&mut pipe.balance.wire);
        let parts = pipe.balance.parts(ranks, n);
        state
            .material_state
            .after_pass(ranks, parts, zones.is_some(), &mut wire);
        pipe.balance.wire = wire;
    }
    let t = update::sum_on(
        (ranks, pipe.balance.parts(ranks, n)),
        &mut scratch.results,
        state.clock.time,
    );
    pipe.balance.end_step(ranks);
    if setup.damage_vars() && splits {
        let mut wire = std::mem::take(&mut pipe.balance.wire);
        let parts = pipe.balance.parts(ranks, n);
        state.material_state.hand_over(ranks, parts, &mut wire);
        pipe.balance.wire = wire;
    }
    let t = t?;
    pipe.profile.lap(Phase::Material, &mut watch);
    state.energy.internal += t.internal;
    state.plastic_work += t.plastic;
    state.energy.lost[LOST_DAMPING] += t.damping;
    // 6. Checks and the next step.
    end_step(setup, state, &t, d_min)?;
    pipe.profile.lap(Phase::Checks, &mut watch);
    Ok(())
}

/// Step 4: the spacing check over the named pairs, and the supports
/// or the operator rebuilt when a pair has left its range or moved past
/// [`RodSetup::rebuild_strain`] (the watch restarted after a rebuild,
/// which books its own phases). Returns the smallest distance between
/// named nodes.
fn follow(
    setup: &Setup3d,
    state: &mut State3d,
    pipe: &mut Pipeline3d,
    scratch: &mut Scratch,
    watch: &mut Stopwatch,
) -> Result<f64> {
    let images = &pipe.geometry.as_ref().expect("built above").mirror;
    let x = extended(images, &state.pos, &mut scratch.images.pos, mirror::vector);
    let b = extended(
        images,
        &state.built_at,
        &mut scratch.images.built,
        mirror::vector,
    );
    let pairs = geometry::named_pairs(setup, state, pipe, x, b);
    pipe.profile.lap(Phase::Pairs, watch);
    let d_min = pairs.nearest;
    let ratio = d_min / setup.d_min0;
    state.min_spacing = state.min_spacing.min(ratio);
    check_spacing(ratio, state.clock.time, "")?;
    let supports = pairs.recompute;
    if supports || pairs.strained {
        // The build reads every node's density (its copy, `built_rho`, is
        // saved and read by the conforming correction's volumes), which
        // the ranks hold between passes only where they read it.
        let n = state.pos.len();
        let parts = pipe.balance.parts(&*pipe.ranks, n);
        pipe.halo
            .make_some_whole(&*pipe.ranks, parts, &mut [&mut state.rho]);
        if supports {
            state.supports_at.clone_from(&state.pos);
        }
        state.built_at.clone_from(&state.pos);
        state.built_reference.clone_from(&state.reference);
        state.built_contact.clone_from(&state.contact);
        state.built_rho.clone_from(&state.rho);
        geometry::build_geometry(setup, state, pipe, supports)?;
        *watch = pipe.profile.stopwatch();
    }
    Ok(d_min)
}

/// Step 6: the checks of the step (non-finite positions, energy drift),
/// the next step (eq. 15) and its floor, and the end of a Taylor run:
/// the rod has left the anvil, or it has been quiet for
/// [`crate::solver::shared::QUIET_TRANSITS`] transits ([`QuietEnd`]).
fn end_step(setup: &Setup3d, state: &mut State3d, t: &Tally, d_min: f64) -> Result<()> {
    if let Some(i) = first_where(&state.pos, |x| !x.iter().all(|v| v.is_finite())) {
        return Err(Error::NonFinite {
            field: "position",
            particle: i,
            time: state.clock.time,
        });
    }
    let e = state.energy.error(t.kinetic);
    if above(e, ENERGY_ERROR_BOUND) {
        return Err(Error::EnergyDrift {
            error: e,
            bound: ENERGY_ERROR_BOUND,
            time: state.clock.time,
        });
    }
    state.clock.dt = setup.stable_dt(t.worst_speed, d_min);
    state.clock.check_step(state.clock.dt)?;
    let touching = state.contact.par_iter().any(|&c| c);
    if setup.anvil && -t.momentum / t.mass <= 0.0 && !touching {
        state.at_rest = true;
    }
    // A run of several bodies (no anvil) ends at its end time.
    if setup.anvil
        && state.quiet_since.at_rest(
            state.clock.time,
            t.kinetic,
            state.energy.initial,
            setup.rod.cylinder.length,
            wave_speed(setup, state),
        )
    {
        state.at_rest = true;
    }
    Ok(())
}

/// The total stress `σ + σ_v = S − p I + σ_v` at each node.
fn total_stress(dev: &[Full], pressure: &[f64], visc: &[Full], total: &mut [[f64; 6]]) {
    total.par_iter_mut().enumerate().for_each(|(i, t)| {
        let (d, p, v) = (dev[i], pressure[i], visc[i]);
        *t = [
            d[0] - p + v[0],
            d[1] - p + v[1],
            d[2] - p + v[2],
            d[3] + v[3],
            d[4] + v[4],
            d[5] + v[5],
        ];
    });
}

/// The nodal forces of the total stresses in `buffers.total`: by the nodal
/// form (the adjoint of the gradients, the images' columns folded onto
/// their nodes) or the seed's traction operator over the test spheres.
fn forces(
    (g, ranks): (&Geometry, &dyn crate::ranks::Ranks),
    nodal: bool,
    (mass, rho): (&[f64], &[f64]),
    buffers: &mut ForceBuffers,
    ext_total: &mut Vec<[f64; 6]>,
) {
    let n = mass.len();
    let images = &g.mirror;
    buffers.force.resize(n + images.len(), [0.0; 3]);
    let ForceBuffers {
        total,
        force,
        volume,
    } = buffers;
    if nodal {
        volume
            .par_iter_mut()
            .zip(mass.par_iter().zip(rho.par_iter()))
            .for_each(|(v, (m, r))| *v = m / r);
        g.nodal.apply_on(ranks, total, volume, force);
        images.fold(n, force);
    } else {
        let total = extended(images, total, ext_total, mirror::tensor);
        g.op.apply(total, &mut force[..n]);
    }
}
