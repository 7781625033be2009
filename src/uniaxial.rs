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
use crate::observe::{FieldSpec, LOG10_NO_CRACKS};

/// The material of a plate.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Layer {
    /// The Rajendran-Grove ceramic.
    Ceramic(RajendranGrove),
    /// A material of the shared material code (metals).
    Solid(Material),
}

impl Layer {
    /// The reference density (kg/m3).
    pub fn density(&self) -> Result<f64> {
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

    /// The longitudinal and bulk sound speeds `(c_L, c_B)` at the
    /// reference density, at rest (m/s).
    pub fn sound_speeds(&self) -> Result<(f64, f64)> {
        let rho = self.density()?;
        let (longitudinal, shear) = match self {
            Layer::Ceramic(c) => (
                c.longitudinal_modulus(rho, c.initial_porosity),
                c.porosity_factor(c.initial_porosity) * c.shear_modulus,
            ),
            Layer::Solid(m) => (m.longitudinal_modulus(rho, 0.0), m.shear_modulus),
        };
        Ok((
            (longitudinal / rho).sqrt(),
            ((longitudinal - 4.0 / 3.0 * shear) / rho).sqrt(),
        ))
    }
}

/// The state of a cell's material point. A metal's [`PointState`] holds
/// only caches (no damage), so it is not saved: it comes back empty and is
/// rebuilt at the next step with the same bits.
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
enum CellState {
    Ceramic(CeramicPoint),
    Solid(Point<Full>, #[serde(skip)] PointState),
}

/// Artificial viscosity coefficients (quadratic, linear).
const VISCOSITY: (f64, f64) = (1.5, 0.06);

/// Fraction of the stable step taken.
const COURANT: f64 = 0.5;

/// What the target's free-surface velocity has shown so far, read step by
/// step as an experimenter reads a VISAR record (see
/// [`PlateImpact::reading`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FreeSurfaceReading {
    /// When the first wave reached the free surface (s): the first step
    /// whose velocity passed 1 % of the impact speed.
    pub arrival: Option<f64>,
    /// The elastic precursor (m/s): the velocity at the first step after
    /// the arrival where the velocity stopped rising (its first local
    /// maximum). Above the Hugoniot elastic limit this is the top of the
    /// elastic wave; below it, the whole elastic pulse.
    pub precursor: Option<f64>,
    /// The peak of the first pulse (m/s): the highest velocity before the
    /// velocity first fell by more than 5 % of the impact speed below it (more than the ringing behind a front).
    pub peak: f64,
    /// The lowest velocity after the peak until the velocity first rose
    /// again by more than 5 % of the impact speed (m/s): the pullback's
    /// minimum, before the spall signal or the next pulse.
    pub pullback_minimum: f64,
    /// Where the reading stands: 0 on the first pulse's rise, 1 on the
    /// fall after its peak, 2 once the velocity has risen again from the
    /// pullback's minimum (the spall signal or the next pulse), when the
    /// peak and the minimum are read.
    pub phase: u8,
    /// The velocity read at the step before (m/s).
    pub last: f64,
}

/// A flyer plate striking a target plate in uniaxial strain.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct PlateImpact {
    layers: [Layer; 2],
    /// Flyer cells first; the flyer's last node and the target's first
    /// node are the contact pair.
    flyer_cells: usize,
    impact_speed: f64,
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
    steps: u64,
    /// Where [`PlateImpact::finished`] holds (s); infinite unless set by
    /// [`PlateImpact::until`].
    end_time: f64,
    initial_kinetic: f64,
    contact_loss: f64,
    reading: FreeSurfaceReading,
    /// The depth below the target's impact face of the first target cell
    /// that failed in tension, and when (m, s).
    spall: Option<(f64, f64)>,
    /// Every step's `(t, u)` of the free surface since the run was made
    /// (not part of the saved state; not kept by a scene's run, whose
    /// histories record the observables: [`PlateImpact::without_history`]).
    #[serde(skip)]
    free_surface: Vec<(f64, f64)>,
    /// Whether `free_surface` is kept (a restored run keeps none).
    #[serde(skip)]
    keep_history: bool,
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
            impact_speed,
            x: Vec::new(),
            v: Vec::new(),
            mass: Vec::new(),
            length0: Vec::new(),
            density0: Vec::new(),
            state: Vec::new(),
            stress: Vec::new(),
            energy: Vec::new(),
            time: 0.0,
            steps: 0,
            end_time: f64::INFINITY,
            initial_kinetic: 0.0,
            contact_loss: 0.0,
            reading: FreeSurfaceReading::default(),
            spall: None,
            free_surface: Vec::new(),
            keep_history: true,
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

    /// Records the free surface's velocity and reads it.
    fn record(&mut self) {
        let u = *self.v.last().expect("nodes");
        if self.keep_history {
            self.free_surface.push((self.time, u));
        }
        let r = &mut self.reading;
        if r.arrival.is_none() {
            if u > 0.01 * self.impact_speed.abs() {
                r.arrival = Some(self.time);
            }
        } else if r.precursor.is_none() && u < r.last {
            r.precursor = Some(r.last);
        }
        r.last = u;
        let slack = 0.05 * self.impact_speed.abs();
        match r.phase {
            0 => {
                if u > r.peak {
                    r.peak = u;
                } else if u < r.peak - slack {
                    r.phase = 1;
                }
                r.pullback_minimum = r.peak.min(u);
            }
            1 => {
                if u < r.pullback_minimum {
                    r.pullback_minimum = u;
                } else if u > r.pullback_minimum + slack {
                    r.phase = 2;
                }
            }
            _ => {}
        }
    }

    /// Runs until `end_time` (s) from now on: [`PlateImpact::finished`]
    /// holds there.
    pub fn until(mut self, end_time: f64) -> Self {
        self.end_time = end_time;
        self
    }

    /// Keeps no per-step history of the free surface from now on (a long
    /// run's history would grow by 16 bytes a step; the reading and the
    /// observables do not need it).
    pub fn without_history(mut self) -> Self {
        self.keep_history = false;
        self.free_surface = Vec::new();
        self
    }

    /// Whether the run has reached its end time ([`PlateImpact::until`]).
    pub fn finished(&self) -> bool {
        self.time >= self.end_time
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The end time (s), infinite if none was set.
    pub fn end_time(&self) -> f64 {
        self.end_time
    }

    /// The flyer's and the target's layers.
    pub fn layers(&self) -> [Layer; 2] {
        self.layers
    }

    /// The impact speed (m/s).
    pub fn impact_speed(&self) -> f64 {
        self.impact_speed
    }

    /// What the free-surface velocity has shown so far.
    pub fn reading(&self) -> FreeSurfaceReading {
        self.reading
    }

    /// The depth below the target's impact face of the first target cell
    /// to fail in tension (a ceramic pulverized in expansion), and the time
    /// it failed: where the target spalled.
    pub fn spall(&self) -> Option<(f64, f64)> {
        self.spall
    }

    /// The target's current free-surface velocity (m/s).
    pub fn free_surface_velocity(&self) -> f64 {
        *self.v.last().expect("nodes")
    }

    /// Simulated time (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The target's free-surface velocity history `(t, u)`, one entry per
    /// step since the run was made (empty after
    /// [`PlateImpact::without_history`] and in a restored run).
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

    /// One stable step, ending at the end time at the latest.
    pub fn advance(&mut self) -> Result<()> {
        let dt = self.stable_step().min(self.end_time - self.time);
        self.step(dt)
    }

    /// The stable time step of the cells now (s).
    pub fn stable_step(&self) -> f64 {
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
                    // The first target cell pulverized in tension (its
                    // elastic volumetric strain at pulverization, which the
                    // pulverized state keeps, an expansion): the spall.
                    if self.spall.is_none()
                        && c >= self.flyer_cells
                        && p.pulverized.is_some_and(|z| z.volumetric_strain > 0.0)
                    {
                        let k = (c - self.flyer_cells) as f64;
                        self.spall = Some(((k + 0.5) * self.length0[c], self.time));
                    }
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
        self.steps += 1;
        self.record();
        Ok(())
    }
}

/// The fields of a plate-impact run, one value per cell (a material point
/// at the cell's centre), flyer cells first.
pub const PLATE_IMPACT_FIELDS: &[FieldSpec] = &[
    FieldSpec {
        name: "position",
        unit: "m",
        components: &["x"],
    },
    FieldSpec {
        name: "velocity",
        unit: "m/s",
        components: &["v"],
    },
    FieldSpec {
        name: "density",
        unit: "kg/m3",
        components: &["rho"],
    },
    FieldSpec {
        name: "stress",
        unit: "Pa",
        components: &["sigma_xx"],
    },
    FieldSpec {
        name: "pressure",
        unit: "Pa",
        components: &["P"],
    },
    FieldSpec {
        name: "plastic_strain",
        unit: "1",
        components: &["eps_p"],
    },
    FieldSpec {
        name: "crack_size",
        unit: "m",
        components: &["a"],
    },
    FieldSpec {
        name: "log10_crack_density",
        unit: "1",
        components: &["log10_gamma"],
    },
    FieldSpec {
        name: "porosity",
        unit: "1",
        components: &["f"],
    },
    FieldSpec {
        name: "pulverized",
        unit: "bool",
        components: &["pulverized"],
    },
];

impl PlateImpact {
    /// Cells (the material points).
    pub fn particles(&self) -> usize {
        self.state.len()
    }

    /// The observables of [`crate::observe::PLATE_IMPACT_OBSERVABLES`], in
    /// order.
    pub fn observables(&self) -> Vec<f64> {
        let target = self.layers[1];
        let rho0 = target.density().unwrap_or(f64::NAN);
        let (c_l, c_b) = target.sound_speeds().unwrap_or((f64::NAN, f64::NAN));
        let r = self.reading;
        let precursor = r.precursor.unwrap_or(0.0);
        let pullback = r.peak - r.pullback_minimum;
        let spall_strength = if self.spall.is_some() {
            0.5 * rho0 * c_b * pullback
        } else {
            0.0
        };
        let max_damage = match &self.layers[1] {
            Layer::Ceramic(m) => self
                .target_ceramic()
                .iter()
                .map(|p| m.crack_density(p.crack_size))
                .fold(0.0, f64::max),
            Layer::Solid(_) => 0.0,
        };
        let [kinetic, internal, contact] = self.energies();
        vec![
            self.free_surface_velocity(),
            precursor,
            0.5 * rho0 * c_l * precursor,
            r.peak,
            pullback,
            spall_strength,
            self.spall.map_or(0.0, |s| s.0),
            max_damage,
            kinetic,
            internal,
            contact,
            self.energy_error(),
        ]
    }

    /// The values of the field `name` ([`PLATE_IMPACT_FIELDS`]), one per
    /// cell, or `None` for another name.
    pub fn field(&self, name: &str) -> Option<Vec<f64>> {
        let cells = 0..self.state.len();
        let ceramic = |c: usize| match (&self.state[c], self.layer(c)) {
            (CellState::Ceramic(p), Layer::Ceramic(m)) => Some((p, m)),
            _ => None,
        };
        let values: Vec<f64> = match name {
            "position" => cells
                .map(|c| {
                    let (a, b) = self.nodes(c);
                    0.5 * (self.x[a] + self.x[b])
                })
                .collect(),
            "velocity" => cells
                .map(|c| {
                    let (a, b) = self.nodes(c);
                    0.5 * (self.v[a] + self.v[b])
                })
                .collect(),
            "density" => cells
                .map(|c| {
                    let (a, b) = self.nodes(c);
                    self.density0[c] * self.length0[c] / (self.x[b] - self.x[a])
                })
                .collect(),
            "stress" => self.stress.clone(),
            "pressure" => self
                .state
                .iter()
                .map(|s| match s {
                    CellState::Ceramic(p) => p.pressure,
                    CellState::Solid(p, _) => p.pressure,
                })
                .collect(),
            "plastic_strain" => self
                .state
                .iter()
                .map(|s| match s {
                    CellState::Ceramic(p) => p.plastic_strain,
                    CellState::Solid(p, _) => p.plastic_strain,
                })
                .collect(),
            "crack_size" => cells
                .map(|c| ceramic(c).map_or(0.0, |(p, _)| p.crack_size))
                .collect(),
            "log10_crack_density" => cells
                .map(|c| {
                    ceramic(c).map_or(LOG10_NO_CRACKS, |(p, m)| {
                        m.crack_density(p.crack_size).log10().max(LOG10_NO_CRACKS)
                    })
                })
                .collect(),
            "porosity" => cells
                .map(|c| ceramic(c).map_or(0.0, |(p, _)| p.porosity))
                .collect(),
            "pulverized" => cells
                .map(|c| {
                    ceramic(c).map_or(0.0, |(p, _)| f64::from(u8::from(p.pulverized.is_some())))
                })
                .collect(),
            _ => return None,
        };
        Some(values)
    }

    /// Checks a restored run against `fresh`, a new run of the same
    /// parameters: the same layers, cells, masses and end time, finite
    /// fields, cells of positive length, speeds and cracks a run can reach,
    /// and a clock within the run.
    pub fn check_restored(&self, fresh: &PlateImpact) -> std::result::Result<(), String> {
        let same = self.layers == fresh.layers
            && self.flyer_cells == fresh.flyer_cells
            && self.impact_speed.to_bits() == fresh.impact_speed.to_bits()
            && self.mass == fresh.mass
            && self.length0 == fresh.length0
            && self.density0 == fresh.density0
            && self.end_time.to_bits() == fresh.end_time.to_bits()
            && self.initial_kinetic.to_bits() == fresh.initial_kinetic.to_bits();
        if !same {
            return Err("its plates, cells or masses do not follow from its parameters".into());
        }
        let (nodes, cells) = (fresh.x.len(), fresh.state.len());
        for (what, f, n) in [
            ("positions", &self.x, nodes),
            ("velocities", &self.v, nodes),
            ("stresses", &self.stress, cells),
            ("specific energies", &self.energy, cells),
        ] {
            if f.len() != n || !f.iter().all(|x| x.is_finite()) {
                return Err(format!("its {what} are not {n} finite numbers"));
            }
        }
        if self.state.len() != cells {
            return Err(format!(
                "it holds {} cell states for {cells} cells",
                self.state.len()
            ));
        }
        // The fastest a run can move: the impact speed plus twice the
        // fastest wave, with room.
        let c_max = self
            .layers
            .iter()
            .filter_map(|l| l.sound_speeds().ok())
            .map(|(c, _)| c)
            .fold(0.0, f64::max);
        let bound = 10.0 * (self.impact_speed.abs() + c_max);
        if self.v.iter().any(|v| v.abs() > bound) {
            return Err(format!("a node moves faster than {bound} m/s"));
        }
        let thickness: f64 = fresh.length0.iter().sum();
        for c in 0..cells {
            let (a, b) = self.nodes(c);
            let length = self.x[b] - self.x[a];
            // NaN fails the range (the positions are finite, checked above).
            if !(length > 0.0 && length <= 100.0 * self.length0[c]) {
                return Err(format!("its cell {c} has an impossible length"));
            }
            let ok = match (&self.state[c], self.layer(c)) {
                (CellState::Ceramic(p), Layer::Ceramic(_)) => {
                    p.crack_size.is_finite()
                        && p.crack_size > 0.0
                        && p.crack_size <= thickness
                        && (0.0..1.0).contains(&p.porosity)
                        && p.pressure.is_finite()
                        && p.plastic_strain.is_finite()
                        && p.deviator
                            .iter()
                            .chain(&p.elastic_strain)
                            .all(|x| x.is_finite())
                }
                (CellState::Solid(p, _), Layer::Solid(_)) => {
                    p.pressure.is_finite()
                        && p.plastic_strain.is_finite()
                        && p.temperature.is_finite()
                        && p.deviator.iter().all(|x| x.is_finite())
                }
                _ => false,
            };
            if !ok {
                return Err(format!(
                    "its cell {c}'s material state is not one a run can reach"
                ));
            }
        }
        let clock = self.time.is_finite()
            && self.time >= 0.0
            && self.time <= self.end_time
            && ((self.steps == 0) == (self.time == 0.0));
        if !clock {
            return Err(format!(
                "its clock (t = {}, {} steps) is not valid",
                self.time, self.steps
            ));
        }
        let r = self.reading;
        let finite = r.peak.is_finite()
            && r.pullback_minimum.is_finite()
            && r.last.abs() <= bound
            && r.phase <= 2
            && r.arrival.is_none_or(|t| t.is_finite() && t <= self.time)
            && r.precursor
                .is_none_or(|u| u.is_finite() && u.abs() <= bound)
            && r.peak.abs() <= bound
            && r.pullback_minimum.abs() <= bound
            && self.contact_loss.is_finite()
            && self.contact_loss >= 0.0
            && self
                .spall
                .is_none_or(|(d, t)| d >= 0.0 && d <= thickness && t >= 0.0 && t <= self.time);
        if !finite {
            return Err("its free-surface reading or spall is not one a run can reach".into());
        }
        Ok(())
    }
}

impl crate::model::Model for PlateImpact {
    fn time(&self) -> f64 {
        self.time
    }
    fn steps(&self) -> u64 {
        self.steps
    }
    fn particles(&self) -> usize {
        Self::particles(self)
    }
    fn finished(&self) -> bool {
        Self::finished(self)
    }
    fn step(&mut self) -> Result<()> {
        self.advance()
    }
    fn observables(&self) -> Vec<f64> {
        Self::observables(self)
    }
    fn field(&self, name: &str) -> Option<Vec<f64>> {
        Self::field(self, name)
    }
    fn field_specs(&self) -> &'static [FieldSpec] {
        PLATE_IMPACT_FIELDS
    }
    /// 400 records over the run.
    fn record_interval(&self) -> f64 {
        self.end_time / 400.0
    }
    fn check_restored(&self, fresh: &dyn crate::model::Model) -> std::result::Result<(), String> {
        self.check_restored(crate::model::same_solver(fresh)?)
    }
}
