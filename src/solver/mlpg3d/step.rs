//! One step of the central-difference scheme (module docs of [`super`]):
//! the forces, then the passes of [`super::motion`] (velocities,
//! smoothing, contact, positions), the shifting, the geometry, the
//! material pass of [`super::update`], the checks and the next step.

use super::motion::{self, Frame};
use super::scratch::ForceBuffers;
use super::update::{self, MaterialFields, MaterialInputs};
use super::*;

impl Mlpg3d {
    /// The step with its buffers (reused from step to step: the step
    /// allocates nothing once they have their size).
    pub(super) fn step_with(&mut self, scratch: &mut Scratch, mut watch: Stopwatch) -> Result<()> {
        let dt = self.state.clock.dt;
        let nodal = self.setup.rod.scheme.forces.nodal();
        // 1. Forces from σ^n and the viscous stress.
        let g = self.pipe.geometry.as_ref().expect("built above");
        total_stress(
            &self.state.dev,
            &self.state.pressure,
            &self.state.visc,
            &mut scratch.forces.total,
        );
        forces(
            g,
            nodal,
            (&self.setup.mass, &self.state.rho),
            &mut scratch.forces,
            &mut scratch.images.total,
        );
        self.pipe.profile.lap(Phase::Force, &mut watch);
        // 2-3. Velocities, contact, positions.
        let damaging = self.damaging();
        if !self.setup.group.is_empty() || damaging {
            scratch.contact.before.clone_from(&self.state.vel);
        }
        let frame = Frame {
            dt,
            now: self.state.clock.time,
            nodal,
            spacing: self.setup.d_min0,
            reach: self.setup.reach,
            geometry: g,
            mass: &self.setup.mass,
            rho: &self.state.rho,
            group: &self.setup.group,
            plane: &self.setup.plane,
            held: &self.setup.held,
        };
        motion::kick(
            &frame,
            &scratch.forces.force,
            &mut self.state.vel,
            &mut self.state.contact,
            &mut self.state.reaction,
            &mut scratch.kicks,
        );
        self.pipe.profile.lap(Phase::Kick, &mut watch);
        // Velocity smoothing toward the MLS approximation at the node.
        let alpha = self.setup.rod.scheme.smoothing * self.setup.rod.step_scale();
        if alpha > 0.0 {
            self.state.energy.lost[LOST_SMOOTHING] += motion::smooth(
                &frame,
                (alpha, self.setup.rod.scheme.order.power()),
                &mut self.state.vel,
                &self.state.contact,
                &mut scratch.smoothing,
                &mut scratch.images.vel,
            );
        }
        self.pipe.profile.lap(Phase::Smoothing, &mut watch);
        // Contact between the bodies, then between pulverized nodes closer
        // than half a spacing.
        motion::collide(
            &frame,
            &self.state.pos,
            damaging.then(|| self.state.material_state.points()),
            &mut self.state.vel,
            &mut scratch.contact,
            &mut scratch.images,
            &mut self.state.energy.lost[LOST_CONTACT],
        );
        motion::clamp(
            &frame,
            &mut self.state.vel,
            &mut self.state.energy.lost[LOST_CONTACT],
        );
        motion::drift(
            &frame,
            self.setup.anvil,
            &mut self.state.vel,
            &mut self.state.pos,
            &mut self.state.contact,
            &scratch.kicks,
            &mut scratch.moves,
        );
        self.state.clock.time += dt;
        self.state.clock.steps += 1;
        motion::settle(
            &scratch.moves,
            &mut self.state.energy.lost[LOST_CONTACT],
            &mut self.state.last_release,
            self.state.clock.time,
        )?;
        motion::check_planes(&self.state.pos, &self.setup.plane, self.state.clock.time)?;
        self.pipe.profile.lap(Phase::Move, &mut watch);
        if self.setup.rod.scheme.shifting > 0.0 {
            let g = self.pipe.geometry.as_ref().expect("built before the step");
            shifting::shift(&self.setup, &mut self.state, g, scratch)?;
        }
        self.pipe.profile.lap(Phase::Shift, &mut watch);
        // 4. The geometry follows the body.
        let d_min = self.follow(scratch, &mut watch)?;
        // 5. Velocity gradients and the material.
        let g = self.pipe.geometry.as_ref().expect("built above");
        let vel_ext = extended(
            &g.mirror,
            &self.state.vel,
            &mut scratch.images.vel,
            mirror::vector,
        );
        g.shapes.velocity_gradients(vel_ext, &mut scratch.grad);
        self.pipe.profile.lap(Phase::Gradients, &mut watch);
        update::update_material(
            &MaterialInputs {
                dt,
                damping_time: self.setup.damping_time,
                rod: &self.setup.material,
                others: &self.setup.others,
                group: &self.setup.group,
                mass: &self.setup.mass,
                vel: &self.state.vel,
                grad: &scratch.grad,
            },
            MaterialFields {
                dev: &mut self.state.dev,
                pressure: &mut self.state.pressure,
                eps_p: &mut self.state.eps_p,
                temp: &mut self.state.temp,
                rho: &mut self.state.rho,
                visc: &mut self.state.visc,
                states: self.state.material_state.points_mut(),
            },
            &mut scratch.results,
        );
        let t = update::sum(&scratch.results, self.state.clock.time)?;
        self.pipe.profile.lap(Phase::Material, &mut watch);
        self.state.energy.internal += t.internal;
        self.state.plastic_work += t.plastic;
        self.state.energy.lost[LOST_DAMPING] += t.damping;
        // 6. Checks and the next step.
        self.end_step(&t, d_min)?;
        self.pipe.profile.lap(Phase::Checks, &mut watch);
        Ok(())
    }

    /// Step 4: the spacing check over the named pairs, and the supports
    /// or the operator rebuilt when a pair has left its range or moved past
    /// [`RodSetup::rebuild_strain`] (the watch restarted after a rebuild,
    /// which books its own phases). Returns the smallest distance between
    /// named nodes.
    fn follow(&mut self, scratch: &mut Scratch, watch: &mut Stopwatch) -> Result<f64> {
        let images = &self.pipe.geometry.as_ref().expect("built above").mirror;
        let x = extended(
            images,
            &self.state.pos,
            &mut scratch.images.pos,
            mirror::vector,
        );
        let b = extended(
            images,
            &self.state.built_at,
            &mut scratch.images.built,
            mirror::vector,
        );
        let pairs = geometry::named_pairs(&self.setup, &self.state, &self.pipe, x, b);
        self.pipe.profile.lap(Phase::Pairs, watch);
        let d_min = pairs.nearest;
        let ratio = d_min / self.setup.d_min0;
        self.state.min_spacing = self.state.min_spacing.min(ratio);
        check_spacing(ratio, self.state.clock.time, "")?;
        let supports = pairs.recompute;
        if supports || pairs.strained {
            if supports {
                self.state.supports_at.clone_from(&self.state.pos);
            }
            self.state.built_at.clone_from(&self.state.pos);
            self.state.built_reference.clone_from(&self.state.reference);
            self.state.built_contact.clone_from(&self.state.contact);
            self.state.built_rho.clone_from(&self.state.rho);
            geometry::build_geometry(&self.setup, &mut self.state, &mut self.pipe, supports)?;
            *watch = self.pipe.profile.stopwatch();
        }
        Ok(d_min)
    }

    /// Step 6: the checks of the step (non-finite positions, energy drift),
    /// the next step (eq. 15) and its floor, and the end of a Taylor run:
    /// the rod has left the anvil, or it has been quiet for
    /// [`crate::solver::shared::QUIET_TRANSITS`] transits ([`QuietEnd`]).
    fn end_step(&mut self, t: &Tally, d_min: f64) -> Result<()> {
        if let Some(i) = self
            .state
            .pos
            .par_iter()
            .position_first(|x| !x.iter().all(|v| v.is_finite()))
        {
            return Err(Error::NonFinite {
                field: "position",
                particle: i,
                time: self.state.clock.time,
            });
        }
        let e = self.energy_error_with(t.kinetic);
        if above(e, ENERGY_ERROR_BOUND) {
            return Err(Error::EnergyDrift {
                error: e,
                bound: ENERGY_ERROR_BOUND,
                time: self.state.clock.time,
            });
        }
        self.state.clock.dt = self.stable_dt(t.worst_speed, d_min);
        self.state.clock.check_step(self.state.clock.dt)?;
        let touching = self.state.contact.par_iter().any(|&c| c);
        if self.setup.anvil && -t.momentum / t.mass <= 0.0 && !touching {
            self.state.at_rest = true;
        }
        // A run of several bodies (no anvil) ends at its end time.
        if self.setup.anvil
            && self.state.quiet_since.at_rest(
                self.state.clock.time,
                t.kinetic,
                self.state.energy.initial,
                self.setup.rod.cylinder.length,
                self.wave_speed(),
            )
        {
            self.state.at_rest = true;
        }
        Ok(())
    }
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
    g: &Geometry,
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
        g.nodal.apply(total, volume, force);
        images.fold(n, force);
    } else {
        let total = extended(images, total, ext_total, mirror::tensor);
        g.op.apply(total, &mut force[..n]);
    }
}
