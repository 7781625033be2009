//! Plate impact in uniaxial strain: a flyer plate strikes a target plate,
//! both of infinite lateral extent, and the waves run through their
//! thickness. This is the experiment that calibrates a ceramic model (the
//! elastic precursor at the Hugoniot elastic limit, read from the target's
//! free-surface velocity as `sigma_HEL = rho0 C_L u_fs / 2`), and a 1-D
//! check of the shared materials.
//!
//! The method is the classic 1-D Lagrangian one (von Neumann & Richtmyer):
//! nodes carry velocities, cells carry stress, central differences in time,
//! and a quadratic plus linear artificial viscosity in compression
//! (`q = rho (Cq^2 L^2 d^2 - Cl c L d)`, `Cq = 1.5`, `Cl = 0.06`, the
//! LS-DYNA defaults) so that shocks spread over a few cells. Every cell is a
//! material point of the shared material code under `D = diag(d, 0, 0)`.
//! The flyer and the target meet at a node pair that moves as one while it
//! is pressed together (the two velocities are replaced by their
//! momentum-weighted mean, which conserves momentum) and separates freely
//! under tension. The kinetic energy of the pair's relative motion when it
//! meets (an inelastic collision of two nodes) is kept as contact loss, so
//! the energy balance closes.

use crate::error::{Error, Result};
use crate::material::rajendran_grove::{CeramicPoint, RajendranGrove};
use crate::material::tensor::Full;
use crate::material::{Loading, Material, Point, PointState};

/// The material of a plate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Layer {
    /// The Rajendran-Grove ceramic.
    Ceramic(RajendranGrove),
    /// A material of the shared material code (metals).
    Solid(Material),
}

impl Layer {
    fn density(&self) -> Result<f64> {
        match self {
            Layer::Ceramic(c) => Ok(c.density),
            Layer::Solid(m) => m.eos.reference_density().ok_or_else(|| {
                Error::Inconsistent(
                    "a plate needs an equation of state with a reference density".into(),
                )
            }),
        }
    }

    fn validate(&self) -> Result<()> {
        match self {
            Layer::Ceramic(c) => c.validate(),
            Layer::Solid(m) => m.validate(),
        }
    }

    fn initial_state(&self) -> CellState {
        match self {
            Layer::Ceramic(c) => CellState::Ceramic(c.initial_point()),
            Layer::Solid(m) => CellState::Solid(
                Point {
                    deviator: [0.0; 6],
                    pressure: 0.0,
                    plastic_strain: 0.0,
                    temperature: m.reference_temperature,
                },
                PointState::default(),
            ),
        }
    }

    /// The longitudinal wave speed at density `rho` in state `s`.
    fn wave_speed(&self, rho: f64, s: &CellState) -> f64 {
        match (self, s) {
            (Layer::Ceramic(c), CellState::Ceramic(p)) => {
                (c.longitudinal_modulus(rho, p.porosity) / rho).sqrt()
            }
            (Layer::Solid(m), CellState::Solid(p, _)) => {
                (m.longitudinal_modulus(rho, p.pressure) / rho).sqrt()
            }
            _ => unreachable!("a cell's state matches its layer"),
        }
    }
}

/// The state of a cell's material point.
#[derive(Debug, Clone, Copy)]
enum CellState {
    Ceramic(CeramicPoint),
    Solid(Point<Full>, PointState),
}

/// Artificial viscosity coefficients (quadratic, linear).
const VISCOSITY: (f64, f64) = (1.5, 0.06);

/// Fraction of the stable step taken.
const COURANT: f64 = 0.5;

/// A flyer plate striking a target plate in uniaxial strain.
#[derive(Debug, Clone)]
pub struct PlateImpact {
    layers: [Layer; 2],
    /// Flyer cells first; the flyer's last node and the target's first
    /// node are the contact pair.
    flyer_cells: usize,
    x: Vec<f64>,
    v: Vec<f64>,
    mass: Vec<f64>,
    /// Per cell: initial length, initial density, state, total stress
    /// (tension positive, viscosity included), specific internal energy.
    length0: Vec<f64>,
    density0: Vec<f64>,
    state: Vec<CellState>,
    stress: Vec<f64>,
    energy: Vec<f64>,
    time: f64,
    initial_kinetic: f64,
    contact_loss: f64,
    free_surface: Vec<(f64, f64)>,
}

impl PlateImpact {
    /// A flyer of thickness `flyer_thickness` (m) at `impact_speed` (m/s)
    /// touching a target of thickness `target_thickness` at rest, each cut
    /// into cells of about `cell` (m).
    pub fn new(
        flyer: Layer,
        flyer_thickness: f64,
        target: Layer,
        target_thickness: f64,
        impact_speed: f64,
        cell: f64,
    ) -> Result<Self> {
        flyer.validate()?;
        target.validate()?;
        for (name, value) in [
            ("flyer_thickness", flyer_thickness),
            ("target_thickness", target_thickness),
            ("cell", cell),
        ] {
            if !(value > 0.0 && value.is_finite()) {
                return Err(Error::OutOfRange {
                    name: name.into(),
                    value,
                    range: "(0, inf)".into(),
                });
            }
        }
        if !impact_speed.is_finite() || impact_speed.abs() > 1e4 {
            return Err(Error::OutOfRange {
                name: "impact_speed".into(),
                value: impact_speed,
                range: "[-1e4, 1e4]".into(),
            });
        }
        let counts =
            [flyer_thickness, target_thickness].map(|t| ((t / cell).round() as usize).max(2));
        if counts.iter().sum::<usize>() > 10_000_000 {
            return Err(Error::OutOfRange {
                name: "cell".into(),
                value: cell,
                range: "at most 1e7 cells in all".into(),
            });
        }
        let mut sim = PlateImpact {
            layers: [flyer, target],
            flyer_cells: counts[0],
            x: Vec::new(),
            v: Vec::new(),
            mass: Vec::new(),
            length0: Vec::new(),
            density0: Vec::new(),
            state: Vec::new(),
            stress: Vec::new(),
            energy: Vec::new(),
            time: 0.0,
            initial_kinetic: 0.0,
            contact_loss: 0.0,
            free_surface: Vec::new(),
        };
        let mut start = -flyer_thickness;
        for (k, (&n, thickness)) in counts
            .iter()
            .zip([flyer_thickness, target_thickness])
            .enumerate()
        {
            let layer = sim.layers[k];
            let rho = layer.density()?;
            let h = thickness / n as f64;
            let speed = if k == 0 { impact_speed } else { 0.0 };
            let first = sim.x.len();
            for i in 0..=n {
                sim.x.push(start + h * i as f64);
                sim.v.push(speed);
                sim.mass.push(0.0);
            }
            for i in 0..n {
                sim.length0.push(h);
                sim.density0.push(rho);
                sim.state.push(layer.initial_state());
                sim.stress.push(0.0);
                sim.energy.push(0.0);
                sim.mass[first + i] += 0.5 * rho * h;
                sim.mass[first + i + 1] += 0.5 * rho * h;
            }
            start = 0.0;
        }
        sim.initial_kinetic = sim.kinetic();
        sim.record();
        Ok(sim)
    }

    /// The two nodes of cell `c`.
    fn nodes(&self, c: usize) -> (usize, usize) {
        if c < self.flyer_cells {
            (c, c + 1)
        } else {
            (c + 1, c + 2)
        }
    }

    fn layer(&self, c: usize) -> &Layer {
        &self.layers[usize::from(c >= self.flyer_cells)]
    }

    fn kinetic(&self) -> f64 {
        self.v
            .iter()
            .zip(&self.mass)
            .map(|(v, m)| 0.5 * m * v * v)
            .sum()
    }

    fn record(&mut self) {
        let last = *self.v.last().expect("nodes");
        self.free_surface.push((self.time, last));
    }

    /// Simulated time (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The target's free-surface velocity history `(t, u)`, one entry per
    /// step.
    pub fn free_surface(&self) -> &[(f64, f64)] {
        &self.free_surface
    }

    /// The kinetic and internal energies and the kinetic energy lost in
    /// the contact's merging, per unit area (J/m2).
    pub fn energies(&self) -> [f64; 3] {
        let internal: f64 = (0..self.state.len())
            .map(|c| self.density0[c] * self.length0[c] * self.energy[c])
            .sum();
        [self.kinetic(), internal, self.contact_loss]
    }

    /// The relative energy error `|KE + IE + contact loss - KE0| / KE0`.
    pub fn energy_error(&self) -> f64 {
        let total: f64 = self.energies().iter().sum();
        (total - self.initial_kinetic).abs() / self.initial_kinetic
    }

    /// The target's cells from the impact face: `(position, stress)` with
    /// the stress tension-positive (Pa).
    pub fn target_stress(&self) -> Vec<(f64, f64)> {
        (self.flyer_cells..self.state.len())
            .map(|c| {
                let (a, b) = self.nodes(c);
                (0.5 * (self.x[a] + self.x[b]), self.stress[c])
            })
            .collect()
    }

    /// The ceramic states of the target's cells (empty for a metal target).
    pub fn target_ceramic(&self) -> Vec<CeramicPoint> {
        self.state[self.flyer_cells..]
            .iter()
            .filter_map(|s| match s {
                CellState::Ceramic(p) => Some(*p),
                CellState::Solid(..) => None,
            })
            .collect()
    }

    /// Runs to `end_time` (s).
    pub fn run(&mut self, end_time: f64) -> Result<()> {
        while self.time < end_time {
            let dt = self.stable_step().min(end_time - self.time);
            self.step(dt)?;
        }
        Ok(())
    }

    fn stable_step(&self) -> f64 {
        (0..self.state.len())
            .map(|c| {
                let (a, b) = self.nodes(c);
                let len = self.x[b] - self.x[a];
                let rho = self.density0[c] * self.length0[c] / len;
                COURANT * len / self.layer(c).wave_speed(rho, &self.state[c])
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// One central-difference step of `dt`.
    pub fn step(&mut self, dt: f64) -> Result<()> {
        let n = self.state.len();
        let (f, t) = (self.flyer_cells, self.flyer_cells + 1);
        let closing = self.v[f] - self.v[t];
        // Each cell pulls its two nodes (tension positive).
        for c in 0..n {
            let (a, b) = self.nodes(c);
            self.v[a] += self.stress[c] / self.mass[a] * dt;
            self.v[b] -= self.stress[c] / self.mass[b] * dt;
        }
        // The contact pair moves as one node while pressed together. Pairs
        // that met with different velocities collide inelastically: the
        // kinetic energy of their relative motion is lost.
        let gap = (self.x[t] + self.v[t] * dt) - (self.x[f] + self.v[f] * dt);
        if gap < 0.0 {
            let (mf, mt) = (self.mass[f], self.mass[t]);
            let common = (mf * self.v[f] + mt * self.v[t]) / (mf + mt);
            self.v[f] = common;
            self.v[t] = common;
            self.contact_loss += 0.5 * mf * mt / (mf + mt) * closing * closing;
        }
        for i in 0..self.x.len() {
            self.x[i] += self.v[i] * dt;
        }
        self.time += dt;
        for c in 0..n {
            let (a, b) = self.nodes(c);
            let len = self.x[b] - self.x[a];
            if len.is_nan() || len <= 0.0 {
                return Err(Error::ThroughBoundary {
                    particle: c,
                    boundary: "neighbouring node (cell inverted)",
                    time: self.time,
                    position: self.x[a],
                });
            }
            // The length at the middle of the step: the cell grew by
            // (v_b - v_a) dt.
            let d = (self.v[b] - self.v[a]) / (len - 0.5 * (self.v[b] - self.v[a]) * dt);
            let rho = self.density0[c] * self.length0[c] / len;
            let load = Loading::<Full> {
                dt,
                rate: [d, 0.0, 0.0, 0.0, 0.0, 0.0],
                spin: [0.0; 3],
                density: rho,
            };
            let layer = *self.layer(c);
            let material = match (&layer, &mut self.state[c]) {
                (Layer::Ceramic(m), CellState::Ceramic(p)) => {
                    m.update(&load, self.energy[c], p);
                    p.deviator[0] - p.pressure
                }
                (Layer::Solid(m), CellState::Solid(p, s)) => {
                    *p = m.update(&load, p, s).map_err(|e| Error::CompressionLimit {
                        particle: c,
                        time: self.time,
                        compression: e.compression,
                        limit: e.limit,
                    })?;
                    p.deviator[0] - p.pressure
                }
                _ => unreachable!("a cell's state matches its layer"),
            };
            let q = if d < 0.0 {
                let c_l = layer.wave_speed(rho, &self.state[c]);
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
                    time: self.time,
                });
            }
            self.energy[c] += 0.5 * (self.stress[c] + stress) * d * dt / rho;
            self.stress[c] = stress;
        }
        if let Some(i) = self.v.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                field: "velocity",
                particle: i,
                time: self.time,
            });
        }
        self.record();
        Ok(())
    }
}
