//! Node shifting in the run ([`super::super::shift`] holds the shifts and
//! the carry): who may move where, and the carry of the moved nodes'
//! fields.

use super::*;

impl Mlpg3d {
    /// Node shifting ([`super::shift`]): pushes apart the pairs closer than
    /// [`SHIFT_RANGE`] of the initial spacing and carries the fields of the
    /// moved nodes to their new places with the shapes of the last build.
    /// An interior node on the anvil moves in its plane. With the sphere
    /// form the surfaces (face, mantle, top) stay put (measured: letting
    /// the surface nodes move in their tangent planes, the face nodes on
    /// the anvil in its plane, made the Wilkins bar in 3-D stop earlier,
    /// EnergyDrift at 44.7 µs against 55.6 µs); with the nodal form, which
    /// has no test sphere to cut, a node of the mantle alone moves in the
    /// mantle's tangent plane (its Nanson normal, as the sphere form's cut
    /// planes) and a face node held on the anvil in the anvil's plane, while
    /// edges, the top and the free face stay put (measured: with the mantle
    /// fixed, two mantle nodes of the Wilkins bar's bulge close to the
    /// guard at 59.6 µs; README, "3-D MLPG mixed method"). The moved nodes
    /// take their stress, density, plastic strain, temperature and
    /// reference place by [`carry`], and their velocities by [`carry`] or,
    /// with [`RodSetup::conservative_carry`], by [`exchange`] (the momentum
    /// drawn from the nodes around). The kinetic energy the carrying
    /// changes is booked with the smoothing. Fails with the compression
    /// limit of the equation of state at a moved node.
    pub(super) fn shift(&mut self, scratch: &mut Scratch) -> Result<()> {
        let spacing = self.d_min0;
        let g = self.geometry.as_ref().expect("built before the step");
        let (surf, contact, anvil) = (&self.lattice.surfaces, &self.contact, self.anvil);
        let nodal = self.setup.weak_form == WeakForm::Nodal;
        let images = &g.mirror;
        let shapes = &g.shapes;
        let reference = extended(
            images,
            &self.reference,
            &mut scratch.images.built,
            mirror::vector,
        );
        let points = self.material_state.points();
        scratch
            .shifting
            .free
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, f)| {
                // A pulverized node stays put: its ceramic state (pulverized,
                // its porosity) is not carried, so carrying its neighbours'
                // stress and density to it created energy (the penetration at
                // 4 across: energy error 18.8 % against 0.46 % with it fixed;
                // README, "Ballistic penetration"); the contact of pulverized
                // nodes keeps them apart.
                let pulverized = points.get(i).is_some_and(|p| p.is_pulverized());
                *f = if pulverized {
                    Freedom::Fixed
                } else if !anvil {
                    Freedom::Unbounded
                } else if nodal && surf[i] == Surfaces(Surfaces::MANTLE) {
                    // F⁻¹ = ∂X/∂x at this node only (eq. 4 on the reference places).
                    let finv = shapes.gradient(i, reference);
                    Freedom::InPlane(nanson(&finv, radial(reference[i])))
                } else if nodal && surf[i] == Surfaces(Surfaces::FACE) && contact[i] {
                    Freedom::InPlane([0.0, 0.0, 1.0])
                } else if !surf[i].interior() {
                    Freedom::Fixed
                } else if contact[i] {
                    Freedom::InPlane([0.0, 0.0, 1.0])
                } else {
                    Freedom::Free
                };
            });
        let pos = extended(images, &self.pos, &mut scratch.images.pos, mirror::vector);
        let step_scale = self.setup.step_scale();
        shifts(
            pos,
            &g.shapes,
            &scratch.shifting.free,
            spacing,
            SHIFT_RANGE * spacing,
            self.setup.shifting * step_scale,
            SHIFT_CAP * spacing * step_scale,
            &mut scratch.shifting.shift,
        );
        // A node on a symmetry plane moves in it; a held node stays.
        for (d, &on) in scratch.shifting.shift.iter_mut().zip(&self.plane) {
            pin(d, on);
        }
        for (d, _) in scratch
            .shifting
            .shift
            .iter_mut()
            .zip(&self.held)
            .filter(|(_, h)| **h)
        {
            *d = [0.0; 3];
        }
        let d = &scratch.shifting.shift;
        if d.iter().all(|d| *d == [0.0; 3]) {
            return Ok(());
        }
        scratch
            .shifting
            .carried
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, f)| {
                let (v, s, x) = (self.vel[i], self.dev[i], self.reference[i]);
                *f = [
                    v[0],
                    v[1],
                    v[2],
                    s[0],
                    s[1],
                    s[2],
                    s[3],
                    s[4],
                    s[5],
                    self.rho[i],
                    self.eps_p[i],
                    self.temp[i],
                    x[0],
                    x[1],
                    x[2],
                ];
            });
        let carried = extended(
            images,
            &scratch.shifting.carried,
            &mut scratch.images.carried,
            reflect_carried,
        );
        carry(&g.shapes, carried, d, &mut scratch.shifting.carried_out);
        let conservative = self.setup.conservative_carry;
        let mut ke = [0.0; 2];
        if conservative {
            ke[0] = kinetic(&self.vel, &self.mass);
            let vel = extended(images, &self.vel, &mut scratch.images.vel, mirror::vector);
            let mass = extended(images, &self.mass, &mut scratch.images.mass, mirror::same);
            exchange(
                &g.shapes,
                vel,
                mass,
                d,
                &mut scratch.shifting.share,
                &mut scratch.shifting.momentum,
            );
            images.fold(self.pos.len(), &mut scratch.shifting.momentum);
            for (i, p) in scratch
                .shifting
                .momentum
                .iter()
                .enumerate()
                .take(self.pos.len())
            {
                if *p == [0.0; 3] {
                    continue;
                }
                let v = &mut self.vel[i];
                for k in 0..3 {
                    v[k] += p[k] / self.mass[i];
                }
                if self.contact[i] {
                    v[2] = 0.0;
                }
                if let Some(&on) = self.plane.get(i) {
                    pin(v, on);
                }
            }
        }
        for (i, (f, di)) in scratch.shifting.carried_out.iter().zip(d).enumerate() {
            if *di == [0.0; 3] {
                continue;
            }
            if !conservative {
                ke[0] += kinetic1(self.vel[i], self.mass[i]);
                let mut v = [f[0], f[1], f[2]];
                if self.contact[i] {
                    v[2] = 0.0;
                }
                if let Some(&on) = self.plane.get(i) {
                    pin(&mut v, on);
                }
                self.vel[i] = v;
                ke[1] += kinetic1(v, self.mass[i]);
            }
            // Each component was limited to its neighbours' range on its
            // own, which leaves a trace: the deviator is made trace-free
            // again (the mean normal stress stays −P).
            let m = (f[3] + f[4] + f[5]) / 3.0;
            self.dev[i] = [f[3] - m, f[4] - m, f[5] - m, f[6], f[7], f[8]];
            self.rho[i] = f[9];
            self.eps_p[i] = f[10];
            self.temp[i] = f[11];
            self.reference[i] = [f[12], f[13], f[14]];
            self.pressure[i] =
                self.material_of(i)
                    .pressure(f[9], f[11])
                    .map_err(|l| Error::CompressionLimit {
                        particle: i,
                        time: self.time,
                        compression: l.compression,
                        limit: l.limit,
                    })?;
            self.pos[i] = std::array::from_fn(|k| self.pos[i][k] + di[k]);
        }
        if conservative {
            ke[1] = kinetic(&self.vel, &self.mass);
        }
        self.smoothing_dissipation += ke[0] - ke[1];
        Ok(())
    }
}

/// The carried fields of a shifted node reflected ([`CARRIED`]).
pub(super) fn reflect_carried(f: &[f64; CARRIED], flip: u8) -> [f64; CARRIED] {
    let v = mirror::vector(&[f[0], f[1], f[2]], flip);
    let s = mirror::tensor(&[f[3], f[4], f[5], f[6], f[7], f[8]], flip);
    let x = mirror::vector(&[f[12], f[13], f[14]], flip);
    [
        v[0], v[1], v[2], s[0], s[1], s[2], s[3], s[4], s[5], f[9], f[10], f[11], x[0], x[1], x[2],
    ]
}
