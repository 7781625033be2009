//! One step of the central-difference scheme (module docs of [`super`]):
//! forces, velocities, smoothing, contact, positions, the geometry, the
//! material, the checks and the next step.

use super::*;

impl Mlpg3d {
    /// The step with its buffers (reused from step to step: the step
    /// allocates nothing once they have their size).
    pub(super) fn step_with(
        &mut self,
        scratch: &mut Scratch,
        mut clock: std::time::Instant,
    ) -> Result<()> {
        let dt = self.dt;
        // 1. Forces from σ^n and the viscous stress.
        let total = &mut scratch.total;
        total.par_iter_mut().enumerate().for_each(|(i, t)| {
            let (d, p, v) = (self.dev[i], self.pressure[i], self.visc[i]);
            *t = [
                d[0] - p + v[0],
                d[1] - p + v[1],
                d[2] - p + v[2],
                d[3] + v[3],
                d[4] + v[4],
                d[5] + v[5],
            ];
        });
        let g = self.geometry.as_ref().expect("built above");
        let n = self.pos.len();
        let images = &g.mirror;
        let columns = n + images.len();
        scratch.force.resize(columns, [0.0; 3]);
        let force = &mut scratch.force;
        let nodal = self.setup.weak_form == WeakForm::Nodal;
        if nodal {
            let volume = &mut scratch.volume;
            volume
                .par_iter_mut()
                .zip(self.mass.par_iter().zip(self.rho.par_iter()))
                .for_each(|(v, (m, r))| *v = m / r);
            g.nodal.apply(total, volume, force);
            images.fold(n, force);
        } else {
            let total = extended(images, total, &mut scratch.ext_total, mirror::tensor);
            g.op.apply(total, &mut force[..n]);
        }
        self.profile.lap(Phase::Force, &mut clock);
        // 2-3. Velocities, contact, positions.
        if !self.group.is_empty() || self.damaging() {
            scratch.before.clone_from(&self.vel);
        }
        let d0 = self.d_min0;
        let (volume, rho, mass) = (&g.op.volume, &self.rho, &self.mass);
        let plane = &self.plane;
        let still = &self.held;
        let kicked = &mut scratch.kicked;
        let now = self.time;
        self.vel
            .par_iter_mut()
            .zip(self.contact.par_iter_mut())
            .zip(self.reaction.par_iter_mut())
            .zip(kicked.par_iter_mut())
            .enumerate()
            .for_each(|(i, (((v, touch), reaction), out))| {
                let f = force[i];
                let inertia = if nodal { mass[i] } else { rho[i] * volume[i] };
                // A node held on the anvil loses the speed it had toward it
                // (only at impact: afterwards it is zero); the anvil's
                // reaction on a node at rest does no work.
                let held = if *touch {
                    0.5 * mass[i] * v[2] * v[2]
                } else {
                    0.0
                };
                for d in 0..3 {
                    v[d] += dt * f[d] / inertia;
                }
                // The release is timed where the net axial force, linear
                // between the last step's (−reaction ≤ 0) and this one's
                // (> 0), crosses zero (the last step's length taken as this
                // one's: they differ only at a rebuild).
                let mut released = None;
                if *touch {
                    if f[2] > 0.0 {
                        *touch = false;
                        released = Some(now - dt * f[2] / (f[2] + *reaction));
                        *reaction = 0.0;
                    } else {
                        v[2] = 0.0;
                        *reaction = -f[2];
                    }
                }
                if let Some(&on) = plane.get(i) {
                    pin(v, on);
                }
                // A node of a clamped rim: the clamp's reaction cancels the
                // force, and does no work on a node that does not move.
                if still.get(i) == Some(&true) {
                    *v = [0.0; 3];
                }
                *out = (held, released);
            });
        self.profile.lap(Phase::Kick, &mut clock);
        // Velocity smoothing toward the MLS approximation at the node.
        let alpha = self.setup.smoothing * self.setup.step_scale();
        if alpha > 0.0 {
            let shapes = &g.shapes;
            let vel = &self.vel;
            let vel_ext = extended(images, vel, &mut scratch.ext_vel, mirror::vector);
            let smooth = &mut scratch.smooth;
            // The defect `w = H v = (I − Φ) v`; with order 2 the filter
            // is `M⁻¹ Hᵀ M H v`, symmetric in the mass inner product: `M w`
            // goes straight to `pass`, `Hᵀ M w` to `defect`, and `M⁻¹` is
            // applied in the update.
            let order2 = self.setup.smoothing_order >= 2;
            let weighted = if order2 {
                &mut scratch.pass
            } else {
                &mut scratch.defect
            };
            weighted.par_iter_mut().enumerate().for_each(|(i, out)| {
                let mut m = [0.0; 3];
                for q in shapes.row(i) {
                    let vj = vel_ext[shapes.nodes[q]];
                    for d in 0..3 {
                        m[d] += shapes.phi[q] * vj[d];
                    }
                }
                let w: [f64; 3] = std::array::from_fn(|d| vel[i][d] - m[d]);
                *out = if order2 { w.map(|c| mass[i] * c) } else { w };
            });
            if order2 {
                scratch.defect.resize(columns, [0.0; 3]);
                g.nodal.defect_transpose(&scratch.pass, &mut scratch.defect);
                images.fold(n, &mut scratch.defect);
            }
            let defect = &scratch.defect;
            smooth.par_iter_mut().enumerate().for_each(|(i, out)| {
                let mut v: [f64; 3] = if order2 {
                    std::array::from_fn(|d| vel[i][d] - alpha * (defect[i][d] / mass[i]))
                } else {
                    std::array::from_fn(|d| vel[i][d] - alpha * defect[i][d])
                };
                if self.contact[i] {
                    v[2] = 0.0;
                }
                if let Some(&on) = plane.get(i) {
                    pin(&mut v, on);
                }
                *out = v;
            });
            let before = kinetic(&self.vel, mass);
            std::mem::swap(&mut self.vel, smooth);
            self.smoothing_dissipation += before - kinetic(&self.vel, mass);
        }
        self.profile.lap(Phase::Smoothing, &mut clock);
        // Contact between the bodies, then between pulverized nodes closer
        // than half a spacing.
        // In the quarter model on the nodes and their images: the pairs with
        // a real node, each resolved on the images' velocities too, and
        // only the real nodes' kept.
        scratch.pairs.clear();
        let damaging = self.damaging();
        // No contact pass in a run of one body without damage: no copy.
        let pos: &[[f64; 3]] = if self.group.is_empty() && !damaging {
            &self.pos
        } else {
            extended(images, &self.pos, &mut scratch.ext_pos, mirror::vector)
        };
        let group: &[u8] = if self.group.is_empty() {
            &[]
        } else {
            extended(images, &self.group, &mut scratch.ext_group, mirror::same)
        };
        if !self.group.is_empty() {
            contact::pairs(pos, group, self.reach, &mut scratch.pairs);
        }
        if damaging {
            let points = self.material_state.points();
            scratch.loose.clear();
            scratch
                .loose
                .extend(points.iter().map(|p| p.is_pulverized()));
            let loose = extended(images, &scratch.loose, &mut scratch.ext_loose, mirror::same);
            contact::loose_pairs(
                pos,
                group,
                loose,
                SHIFT_RANGE * self.d_min0,
                &mut scratch.pairs,
            );
        }
        if !images.is_empty() {
            scratch.pairs.retain(|&(i, _)| i < n);
        }
        if !scratch.pairs.is_empty() {
            if images.is_empty() {
                self.contact_dissipation += contact::resolve(
                    &scratch.pairs,
                    &self.pos,
                    &self.mass,
                    &scratch.before,
                    &mut self.vel,
                );
            } else {
                let mass = extended(images, &self.mass, &mut scratch.ext_mass, mirror::same);
                let before = extended(
                    images,
                    &scratch.before,
                    &mut scratch.ext_before,
                    mirror::vector,
                );
                images.extend(&self.vel, &mut scratch.ext_vel, mirror::vector);
                self.contact_dissipation += contact::resolve_with_images(
                    &scratch.pairs,
                    pos,
                    mass,
                    before,
                    &mut scratch.ext_vel,
                    n,
                );
                self.vel.copy_from_slice(&scratch.ext_vel[..n]);
                // What an impulse gave a node on a plane across it, its
                // image's impulse takes back in the whole body.
                for ((v, &on), &m) in self.vel.iter_mut().zip(plane).zip(&self.mass) {
                    if on != 0 {
                        let before = kinetic1(*v, m);
                        pin(v, on);
                        self.contact_dissipation += before - kinetic1(*v, m);
                    }
                }
            }
        }
        // A held node (a clamped rim) stays still: what the smoothing and
        // the contact gave it this step (the forces' share the clamp took
        // at once, above) the clamp takes back, booked with the contact's
        // dissipation.
        for ((v, &m), _) in self
            .vel
            .iter_mut()
            .zip(&self.mass)
            .zip(&self.held)
            .filter(|(_, h)| **h)
        {
            self.contact_dissipation += kinetic1(*v, m);
            *v = [0.0; 3];
        }
        let anvil = self.anvil;
        let moved = &mut scratch.moved;
        self.vel
            .par_iter_mut()
            .zip(self.pos.par_iter_mut())
            .zip(self.contact.par_iter_mut())
            .zip(kicked.par_iter())
            .zip(moved.par_iter_mut())
            .enumerate()
            .for_each(|(i, ((((v, x), touch), &(held, released)), out))| {
                let mut through = None;
                for d in 0..3 {
                    x[d] += dt * v[d];
                }
                let mut lost = 0.0;
                if anvil && !*touch && x[2] < 0.0 {
                    if x[2] < -0.5 * d0 {
                        through = Some(x[2]);
                    }
                    x[2] = 0.0;
                    lost = 0.5 * mass[i] * v[2] * v[2];
                    v[2] = 0.0;
                    *touch = true;
                }
                *out = (held, lost, released, through);
            });
        self.time += dt;
        self.steps += 1;
        for (i, &(held, lost, released, through)) in moved.iter().enumerate() {
            self.contact_dissipation += held + lost;
            if let Some(t) = released {
                self.last_release = self.last_release.max(t);
            }
            if let Some(z) = through {
                return Err(Error::ThroughBoundary {
                    particle: i,
                    boundary: "anvil",
                    time: self.time,
                    position: z,
                });
            }
        }
        if !self.plane.is_empty() {
            // A node crossing a symmetry plane has passed its own image.
            if let Some((i, x)) = self
                .pos
                .iter()
                .enumerate()
                .find(|(_, x)| x[0] < 0.0 || x[1] < 0.0)
            {
                return Err(Error::ThroughBoundary {
                    particle: i,
                    boundary: "symmetry plane",
                    time: self.time,
                    position: x[0].min(x[1]),
                });
            }
        }
        self.profile.lap(Phase::Move, &mut clock);
        if self.setup.shifting > 0.0 {
            self.shift(scratch)?;
        }
        self.profile.lap(Phase::Shift, &mut clock);
        // 4. The geometry follows the body.
        let images = &self.geometry.as_ref().expect("built above").mirror;
        let x = extended(images, &self.pos, &mut scratch.ext_pos, mirror::vector);
        let b = extended(
            images,
            &self.built_at,
            &mut scratch.ext_built,
            mirror::vector,
        );
        let pairs = self.named_pairs(x, b);
        self.profile.lap(Phase::Pairs, &mut clock);
        let d_min = pairs.nearest;
        let ratio = d_min / self.d_min0;
        self.min_spacing = self.min_spacing.min(ratio);
        if below(ratio, SPACING_COLLAPSE_BOUND) {
            return Err(Error::SpacingCollapse {
                ratio,
                bound: SPACING_COLLAPSE_BOUND,
                time: self.time,
                hint: "",
            });
        }
        if pairs.recompute {
            self.supports_at.clone_from(&self.pos);
            self.built_at.clone_from(&self.pos);
            self.built_reference.clone_from(&self.reference);
            self.built_contact.clone_from(&self.contact);
            self.built_rho.clone_from(&self.rho);
            self.build_geometry(true)?;
            clock = std::time::Instant::now();
        } else if pairs.strain > self.setup.rebuild_strain {
            self.built_at.clone_from(&self.pos);
            self.built_reference.clone_from(&self.reference);
            self.built_contact.clone_from(&self.contact);
            self.built_rho.clone_from(&self.rho);
            self.build_geometry(false)?;
            clock = std::time::Instant::now();
        }
        // 5. Velocity gradients and the material.
        let g = self.geometry.as_ref().expect("built above");
        let grad = &mut scratch.grad;
        let vel_ext = extended(&g.mirror, &self.vel, &mut scratch.ext_vel, mirror::vector);
        g.shapes.velocity_gradients(vel_ext, grad);
        self.profile.lap(Phase::Gradients, &mut clock);
        let (rod_material, others, group) = (&self.material, &self.others, &self.group);
        let c = self.damping_time;
        let (mass, vel) = (&self.mass, &self.vel);
        let results = &mut scratch.results;
        self.dev
            .par_iter_mut()
            .zip(self.pressure.par_iter_mut())
            .zip(self.eps_p.par_iter_mut())
            .zip(self.temp.par_iter_mut())
            .zip(self.rho.par_iter_mut())
            .zip(self.visc.par_iter_mut())
            .zip(self.material_state.points_mut().par_iter_mut())
            .zip(results.par_iter_mut())
            .enumerate()
            .for_each(
                |(i, (((((((dev, p), eps), temp), rho), visc), state), out))| {
                    *out = (|| {
                        let material = material_of(rod_material, others, group, i);
                        let l = &grad[i];
                        let d = |a: usize, b: usize| 0.5 * (l[a][b] + l[b][a]);
                        let w = |a: usize, b: usize| 0.5 * (l[a][b] - l[b][a]);
                        let rate: Full = [d(0, 0), d(1, 1), d(2, 2), d(0, 1), d(1, 2), d(2, 0)];
                        let tr = rate[0] + rate[1] + rate[2];
                        let rho_new = *rho * (1.0 - dt * tr);
                        let load = Loading {
                            dt,
                            rate,
                            spin: [w(0, 1), w(1, 2), w(2, 0)],
                            density: rho_new,
                        };
                        let before = Point {
                            deviator: *dev,
                            pressure: *p,
                            plastic_strain: *eps,
                            temperature: *temp,
                        };
                        let new = material.update(&load, &before, state).map_err(|l| {
                            (
                                i,
                                Error::CompressionLimit {
                                    particle: i,
                                    time: 0.0,
                                    compression: l.compression,
                                    limit: l.limit,
                                },
                            )
                        })?;
                        let stress = |s: &Full, p: f64| -> Full {
                            [s[0] - p, s[1] - p, s[2] - p, s[3], s[4], s[5]]
                        };
                        let mid: Full = {
                            let (a, b) = (stress(dev, *p), stress(&new.deviator, new.pressure));
                            std::array::from_fn(|k| 0.5 * (a[k] + b[k]))
                        };
                        let volume = mass[i] / rho_new;
                        let bulk = material.eos.bulk_modulus(rho_new, new.pressure);
                        let mu = material.shear_modulus;
                        let v: Full = std::array::from_fn(|k| {
                            let dev_rate = if k < 3 { rate[k] - tr / 3.0 } else { rate[k] };
                            let vol = if k < 3 { bulk * tr } else { 0.0 };
                            c * (vol + 2.0 * mu * dev_rate)
                        });
                        let t = Tally {
                            internal: dt * volume * mid.double_dot(&rate),
                            plastic: volume
                                * new.deviator.von_mises()
                                * (new.plastic_strain - *eps),
                            damping: dt * volume * v.double_dot(&rate),
                            kinetic: kinetic1(vel[i], mass[i]),
                            momentum: mass[i] * vel[i][2],
                            mass: mass[i],
                            worst_speed: (material.wave_modulus(rho_new, new.pressure, state)
                                / rho_new)
                                .sqrt()
                                + norm(vel[i]),
                        };
                        *dev = new.deviator;
                        *p = new.pressure;
                        *eps = new.plastic_strain;
                        *temp = new.temperature;
                        *rho = rho_new;
                        *visc = v;
                        let finite = |x: &[f64]| x.iter().all(|v| v.is_finite());
                        let bad = if !finite(&vel[i]) {
                            Some("velocity")
                        } else if !rho_new.is_finite() {
                            Some("density")
                        } else if !finite(dev) || !p.is_finite() {
                            Some("stress")
                        } else if !temp.is_finite() {
                            Some("temperature")
                        } else {
                            None
                        };
                        if let Some(field) = bad {
                            return Err((
                                i,
                                Error::NonFinite {
                                    field,
                                    particle: i,
                                    time: 0.0,
                                },
                            ));
                        }
                        Ok(t)
                    })();
                },
            );
        let mut t = Tally::default();
        for r in results.iter() {
            let s = r
                .as_ref()
                .map_err(|(_, e)| with_time(e.clone(), self.time))?;
            t.internal += s.internal;
            t.plastic += s.plastic;
            t.damping += s.damping;
            t.kinetic += s.kinetic;
            t.momentum += s.momentum;
            t.mass += s.mass;
            t.worst_speed = t.worst_speed.max(s.worst_speed);
        }
        self.profile.lap(Phase::Material, &mut clock);
        self.internal_energy += t.internal;
        self.plastic_work += t.plastic;
        self.damping_dissipation += t.damping;
        // 6. Checks and the next step.
        if let Some(i) = self
            .pos
            .iter()
            .position(|x| !x.iter().all(|v| v.is_finite()))
        {
            return Err(Error::NonFinite {
                field: "position",
                particle: i,
                time: self.time,
            });
        }
        let e = self.energy_error_with(t.kinetic);
        if above(e, ENERGY_ERROR_BOUND) {
            return Err(Error::EnergyDrift {
                error: e,
                bound: ENERGY_ERROR_BOUND,
                time: self.time,
            });
        }
        self.dt = self.stable_dt(t.worst_speed, d_min);
        check_time_step(self.dt, self.dt0, self.time)?;
        let touching = self.contact.iter().any(|&c| c);
        if self.anvil && -t.momentum / t.mass <= 0.0 && !touching {
            self.at_rest = true;
        }
        if !self.anvil {
            // A run of several bodies ends at its end time.
        } else if t.kinetic <= QUIET_FRACTION * self.initial_energy {
            let since = *self.quiet_since.get_or_insert(self.time);
            let window = QUIET_TRANSITS * self.setup.cylinder.length / self.wave_speed();
            if self.time - since >= window {
                self.at_rest = true;
            }
        } else {
            self.quiet_since = None;
        }
        self.profile.lap(Phase::Checks, &mut clock);
        Ok(())
    }
}

pub(super) fn with_time(e: Error, time: f64) -> Error {
    match e {
        Error::NonFinite {
            field, particle, ..
        } => Error::NonFinite {
            field,
            particle,
            time,
        },
        Error::CompressionLimit {
            particle,
            compression,
            limit,
            ..
        } => Error::CompressionLimit {
            particle,
            time,
            compression,
            limit,
        },
        e => e,
    }
}
