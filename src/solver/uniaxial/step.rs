//! The central-difference step of the plates and its stable size.

use super::layer::{CellState, Layer};
use super::{LOST_CONTACT, PlateImpact};
use crate::error::{Error, Result};
use crate::material::tensor::Full;
use crate::material::{Loading, Shield};

/// Artificial viscosity coefficients (quadratic, linear).
const VISCOSITY: (f64, f64) = (1.5, 0.06);

/// Fraction of the stable step taken.
const COURANT: f64 = 0.5;

impl PlateImpact {
    /// Runs to `end_time` (s).
    pub fn run(&mut self, end_time: f64) -> Result<()> {
        while self.state.clock.time < end_time {
            let dt = self.stable_step().min(end_time - self.state.clock.time);
            self.step(dt)?;
        }
        Ok(())
    }

    /// One stable step, ending at the end time at the latest.
    pub fn advance(&mut self) -> Result<()> {
        let dt = self
            .stable_step()
            .min(self.setup.end_time - self.state.clock.time);
        self.step(dt)
    }

    /// The stable time step of the cells now (s).
    pub fn stable_step(&self) -> f64 {
        (0..self.state.cells.len())
            .map(|c| {
                let (a, b) = self.nodes(c);
                let len = self.state.x[b] - self.state.x[a];
                let rho = self.setup.density0[c] * self.setup.length0[c] / len;
                COURANT * len / self.layer(c).wave_speed(rho, &self.state.cells[c])
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// One central-difference step of `dt`.
    pub fn step(&mut self, dt: f64) -> Result<()> {
        let n = self.state.cells.len();
        let (f, t) = (self.setup.flyer_cells, self.setup.flyer_cells + 1);
        let closing = self.state.v[f] - self.state.v[t];
        let materials = self.setup.layers.map(|l| l.material());
        // Each cell pulls its two nodes (tension positive).
        for c in 0..n {
            let (a, b) = self.nodes(c);
            self.state.v[a] += self.state.stress[c] / self.setup.mass[a] * dt;
            self.state.v[b] -= self.state.stress[c] / self.setup.mass[b] * dt;
        }
        // The contact pair moves as one node while pressed together. Pairs
        // that met with different velocities collide inelastically: the
        // kinetic energy of their relative motion is lost.
        let gap =
            (self.state.x[t] + self.state.v[t] * dt) - (self.state.x[f] + self.state.v[f] * dt);
        if gap < 0.0 {
            let (mf, mt) = (self.setup.mass[f], self.setup.mass[t]);
            let common = (mf * self.state.v[f] + mt * self.state.v[t]) / (mf + mt);
            self.state.v[f] = common;
            self.state.v[t] = common;
            self.state.energy.lost[LOST_CONTACT] += 0.5 * mf * mt / (mf + mt) * closing * closing;
        }
        for i in 0..self.state.x.len() {
            self.state.x[i] += self.state.v[i] * dt;
        }
        self.state.clock.time += dt;
        for c in 0..n {
            let (a, b) = self.nodes(c);
            let len = self.state.x[b] - self.state.x[a];
            if len.is_nan() || len <= 0.0 {
                return Err(Error::ThroughBoundary {
                    particle: c,
                    boundary: "neighbouring node (cell inverted)",
                    time: self.state.clock.time,
                    position: self.state.x[a],
                });
            }
            // The length at the middle of the step: the cell grew by
            // (v_b - v_a) dt.
            let d = (self.state.v[b] - self.state.v[a])
                / (len - 0.5 * (self.state.v[b] - self.state.v[a]) * dt);
            let rho = self.setup.density0[c] * self.setup.length0[c] / len;
            let load = Loading::<Full> {
                dt,
                rate: [d, 0.0, 0.0, 0.0, 0.0, 0.0],
                spin: [0.0; 3],
                density: rho,
                shield: Shield::NONE,
            };
            let k = usize::from(c >= self.setup.flyer_cells);
            let layer = self.setup.layers[k];
            let material = if let Layer::Jh2(j) = layer {
                let CellState::Jh2(p) = &mut self.state.cells[c] else {
                    unreachable!("a cell's state matches its layer")
                };
                let before = *p;
                j.step(p, &load.rate, dt);
                // The first target cell not yet fully fractured that was
                // pulled below the tensile limit of its damage at the start
                // of the step (its trial pressure `P(mu) + dP` there): it
                // fractured in tension, the spall. A cell already crushed
                // to D = 1 in compression and pulled apart does not count.
                let mu = p.density / j.constants().density - 1.0;
                if self.state.spall.is_none()
                    && k == 1
                    && before.damage < 1.0
                    && j.constants().eos_pressure(mu) + before.bulking
                        < j.tensile_limit(before.damage)
                {
                    let depth = (c - self.setup.flyer_cells) as f64;
                    self.state.spall =
                        Some(((depth + 0.5) * self.setup.length0[c], self.state.clock.time));
                }
                p.deviator[0] - p.pressure
            } else {
                let (old, mut point_state) = self.state.cells[c].point();
                let material_k = materials[k].expect("a ceramic or a metal has a material");
                let new = match layer {
                    // The ceramic's porous pressure takes the cell's specific
                    // internal energy.
                    Layer::Ceramic(_) => material_k.update_with_energy(
                        &load,
                        &old,
                        self.state.specific_energy[c],
                        &mut point_state,
                    ),
                    // A metal's pressure is at its temperature, as in the other
                    // solvers.
                    Layer::Solid(_) => material_k.update(&load, &old, &mut point_state),
                    Layer::Jh2(_) => unreachable!("stepped above"),
                }
                .map_err(|e| Error::CompressionLimit {
                    particle: c,
                    time: self.state.clock.time,
                    compression: e.compression,
                    limit: e.limit,
                })?;
                self.state.cells[c].set(new, point_state);
                // The first target cell pulverized in tension (its elastic
                // volumetric strain at pulverization, which the pulverized
                // state keeps, an expansion), or with a tensile crack plane
                // split: the spall.
                let split = |m: &crate::material::rajendran_grove::RajendranGrove| {
                    let planes = m.crack_planes();
                    point_state
                        .ceramic()
                        .and_then(|v| v.tensile.zip(planes))
                        .is_some_and(|(c, p)| c.size.iter().any(|&a| a >= p.split_size()))
                };
                if self.state.spall.is_none()
                    && k == 1
                    && matches!(layer, Layer::Ceramic(_))
                    && (point_state
                        .ceramic()
                        .and_then(|v| v.pulverized)
                        .is_some_and(|z| z.volumetric_strain > 0.0)
                        || matches!(layer, Layer::Ceramic(m) if split(&m)))
                {
                    let depth = (c - self.setup.flyer_cells) as f64;
                    self.state.spall =
                        Some(((depth + 0.5) * self.setup.length0[c], self.state.clock.time));
                }
                new.deviator[0] - new.pressure
            };
            let q = if d < 0.0 {
                let c_l = layer.wave_speed(rho, &self.state.cells[c]);
                let (cq, cl) = VISCOSITY;
                rho * (cq * cq * len * len * d * d - cl * c_l * len * d)
            } else {
                0.0
            };
            let stress = material - q;
            if !stress.is_finite() {
                return Err(Error::NonFinite {
                    field: "stress",
                    particle: c,
                    time: self.state.clock.time,
                });
            }
            self.state.specific_energy[c] += 0.5 * (self.state.stress[c] + stress) * d * dt / rho;
            self.state.stress[c] = stress;
        }
        if let Some(i) = self.state.v.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                field: "velocity",
                particle: i,
                time: self.state.clock.time,
            });
        }
        self.state.clock.steps += 1;
        self.record();
        Ok(())
    }
}
