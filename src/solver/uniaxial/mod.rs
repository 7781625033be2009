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

mod fields;
mod layer;
mod reading;
mod restore;
mod step;

use crate::error::{Error, Result};
use crate::material::rajendran_grove::CeramicPoint;
use crate::observe::FieldSpec;
use crate::solver::shared::{Clock, EnergyBook};

/// The place in the energy book of the energy lost at the contact.
const LOST_CONTACT: usize = 0;
pub use fields::PLATE_IMPACT_FIELDS;
use layer::CellState;
pub use layer::Layer;
pub use reading::FreeSurfaceReading;

/// A flyer plate striking a target plate in uniaxial strain: its setup, its
/// state and what it keeps for its caller, apart.
#[derive(Debug, Clone)]
pub struct PlateImpact {
    /// What the run is built from, and never changes.
    setup: SetupPlate,
    /// What the run changes: all that is saved.
    state: StatePlate,
    /// What the run keeps for its caller: rebuilt, never saved.
    pipe: PipelinePlate,
}

/// What a plate-impact run is built from, from its scene, and never
/// changes: the two plates, the cells' masses, lengths and densities at the
/// start, and the end time. Not saved.
#[derive(Debug, Clone)]
struct SetupPlate {
    layers: [Layer; 2],
    /// Flyer cells first; the flyer's last node and the target's first
    /// node are the contact pair.
    flyer_cells: usize,
    impact_speed: f64,
    mass: Vec<f64>,
    /// Per cell: initial length and initial density.
    length0: Vec<f64>,
    density0: Vec<f64>,
    /// Where [`PlateImpact::finished`] holds (s); infinite unless set by
    /// [`PlateImpact::until`].
    end_time: f64,
}

impl SetupPlate {
    /// The digest of what the setup is made from, the plates, the flyer's
    /// cells, the impact speed and the end time: the cells' masses, lengths
    /// and densities follow from them.
    fn digest(&self) -> u64 {
        crate::solver::shared::setup_digest(&(
            &self.layers,
            self.flyer_cells,
            self.impact_speed,
            self.end_time,
        ))
    }
}

/// What a plate-impact run changes, and all that it saves (format 2 of
/// `src/state_format.rs`).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct StatePlate {
    /// The digest of the setup of the run that made this state.
    setup_digest: u64,
    x: Vec<f64>,
    v: Vec<f64>,
    /// Per cell: the material's state, the total stress (tension positive,
    /// viscosity included), the specific internal energy.
    cells: Vec<CellState>,
    stress: Vec<f64>,
    specific_energy: Vec<f64>,
    clock: Clock,
    /// The impact's kinetic energy and the loss at the contact
    /// ([`LOST_CONTACT`]); the internal energy is summed from the cells.
    energy: EnergyBook<1>,
    reading: FreeSurfaceReading,
    /// The depth below the target's impact face of the first target cell
    /// that failed in tension, and when (m, s).
    spall: Option<(f64, f64)>,
}

/// What a plate-impact run keeps for its caller. Not saved.
#[derive(Debug, Clone, Default)]
struct PipelinePlate {
    /// Every step's `(t, u)` of the free surface since the run was made
    /// (not kept by a scene's run, whose histories record the observables:
    /// [`PlateImpact::without_history`]; a restored run keeps none).
    free_surface: Vec<(f64, f64)>,
    /// Whether `free_surface` is kept.
    keep_history: bool,
}

/// The run's state is all it saves.
impl serde::Serialize for PlateImpact {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        self.state.serialize(s)
    }
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
            setup: SetupPlate {
                layers: [flyer, target],
                flyer_cells: counts[0],
                impact_speed,
                mass: Vec::new(),
                length0: Vec::new(),
                density0: Vec::new(),
                end_time: f64::INFINITY,
            },
            state: StatePlate {
                setup_digest: 0,
                x: Vec::new(),
                v: Vec::new(),
                cells: Vec::new(),
                stress: Vec::new(),
                specific_energy: Vec::new(),
                clock: Clock::default(),
                energy: EnergyBook::new(0.0),
                reading: FreeSurfaceReading::default(),
                spall: None,
            },
            pipe: PipelinePlate {
                free_surface: Vec::new(),
                keep_history: true,
            },
        };
        let mut start = -flyer_thickness;
        for (k, (&n, thickness)) in counts
            .iter()
            .zip([flyer_thickness, target_thickness])
            .enumerate()
        {
            let layer = sim.setup.layers[k];
            let rho = layer.density()?;
            let h = thickness / n as f64;
            let speed = if k == 0 { impact_speed } else { 0.0 };
            let first = sim.state.x.len();
            for i in 0..=n {
                sim.state.x.push(start + h * i as f64);
                sim.state.v.push(speed);
                sim.setup.mass.push(0.0);
            }
            for i in 0..n {
                sim.setup.length0.push(h);
                sim.setup.density0.push(rho);
                sim.state.cells.push(layer.initial_state());
                sim.state.stress.push(0.0);
                sim.state.specific_energy.push(0.0);
                sim.setup.mass[first + i] += 0.5 * rho * h;
                sim.setup.mass[first + i + 1] += 0.5 * rho * h;
            }
            start = 0.0;
        }
        sim.state.energy.initial = sim.kinetic();
        sim.state.setup_digest = sim.setup.digest();
        sim.record();
        Ok(sim)
    }

    /// The two nodes of cell `c`.
    fn nodes(&self, c: usize) -> (usize, usize) {
        if c < self.setup.flyer_cells {
            (c, c + 1)
        } else {
            (c + 1, c + 2)
        }
    }

    fn layer(&self, c: usize) -> &Layer {
        &self.setup.layers[usize::from(c >= self.setup.flyer_cells)]
    }

    fn kinetic(&self) -> f64 {
        self.state
            .v
            .iter()
            .zip(&self.setup.mass)
            .map(|(v, m)| 0.5 * m * v * v)
            .sum()
    }

    /// Records the free surface's velocity and reads it.
    fn record(&mut self) {
        let u = *self.state.v.last().expect("nodes");
        // A JH-2 target's precursor ramps on after its elastic front: read
        // at its knee.
        let knee = matches!(self.setup.layers[1], Layer::Jh2(_));
        if self.pipe.keep_history {
            self.pipe.free_surface.push((self.state.clock.time, u));
        }
        self.state
            .reading
            .read(self.state.clock.time, u, self.setup.impact_speed, knee);
    }

    /// Runs until `end_time` (s) from now on: [`PlateImpact::finished`]
    /// holds there.
    pub fn until(mut self, end_time: f64) -> Self {
        self.setup.end_time = end_time;
        self.state.setup_digest = self.setup.digest();
        self
    }

    /// Keeps no per-step history of the free surface from now on (a long
    /// run's history would grow by 16 bytes a step; the reading and the
    /// observables do not need it).
    pub fn without_history(mut self) -> Self {
        self.pipe.keep_history = false;
        self.pipe.free_surface = Vec::new();
        self
    }

    /// Whether the run has reached its end time ([`PlateImpact::until`]).
    pub fn finished(&self) -> bool {
        self.state.clock.time >= self.setup.end_time
    }

    crate::solver::shared::clock_getters!(state.clock);

    /// The end time (s), infinite if none was set.
    pub fn end_time(&self) -> f64 {
        self.setup.end_time
    }

    /// The flyer's and the target's layers.
    pub fn layers(&self) -> [Layer; 2] {
        self.setup.layers
    }

    /// The impact speed (m/s).
    pub fn impact_speed(&self) -> f64 {
        self.setup.impact_speed
    }

    /// What the free-surface velocity has shown so far.
    pub fn reading(&self) -> FreeSurfaceReading {
        self.state.reading
    }

    /// The depth below the target's impact face of the first target cell
    /// to fail in tension (a ceramic pulverized in expansion), and the time
    /// it failed: where the target spalled.
    pub fn spall(&self) -> Option<(f64, f64)> {
        self.state.spall
    }

    /// The target's current free-surface velocity (m/s).
    pub fn free_surface_velocity(&self) -> f64 {
        *self.state.v.last().expect("nodes")
    }

    /// The target's free-surface velocity history `(t, u)`, one entry per
    /// step since the run was made (empty after
    /// [`PlateImpact::without_history`] and in a restored run).
    pub fn free_surface(&self) -> &[(f64, f64)] {
        &self.pipe.free_surface
    }

    /// The kinetic and internal energies and the kinetic energy lost in
    /// the contact's merging, per unit area (J/m2).
    pub fn energies(&self) -> [f64; 3] {
        let internal: f64 = (0..self.state.cells.len())
            .map(|c| self.setup.density0[c] * self.setup.length0[c] * self.state.specific_energy[c])
            .sum();
        [
            self.kinetic(),
            internal,
            self.state.energy.lost[LOST_CONTACT],
        ]
    }

    /// The relative energy error `|KE + IE + contact loss - KE0| / KE0`.
    pub fn energy_error(&self) -> f64 {
        let [kinetic, internal, _] = self.energies();
        self.state.energy.error_given(kinetic, internal)
    }

    /// The target's cells from the impact face: `(position, stress)` with
    /// the stress tension-positive (Pa).
    pub fn target_stress(&self) -> Vec<(f64, f64)> {
        (self.setup.flyer_cells..self.state.cells.len())
            .map(|c| {
                let (a, b) = self.nodes(c);
                (
                    0.5 * (self.state.x[a] + self.state.x[b]),
                    self.state.stress[c],
                )
            })
            .collect()
    }

    /// The ceramic states of the target's cells (empty for a metal target).
    pub fn target_ceramic(&self) -> Vec<CeramicPoint> {
        self.state.cells[self.setup.flyer_cells..]
            .iter()
            .filter_map(|s| match s {
                CellState::Ceramic(p) => Some(*p),
                CellState::Solid(..) | CellState::Jh2(_) => None,
            })
            .collect()
    }
}

impl crate::model::Model for PlateImpact {
    fn time(&self) -> f64 {
        self.state.clock.time
    }
    fn steps(&self) -> u64 {
        self.state.clock.steps
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
        self.setup.end_time / 400.0
    }
    fn load_state(
        &mut self,
        saved: crate::model::SavedSolver<'_>,
    ) -> std::result::Result<(), String> {
        self.state = crate::solver::shared::read_state(
            saved,
            &[
                ("layers", "its plates"),
                ("flyer_cells", "its cells"),
                ("impact_speed", "its impact speed"),
                ("mass", "its masses"),
                ("length0", "its cells"),
                ("density0", "its cells"),
                ("end_time", "its end time"),
            ],
        )?;
        self.pipe = PipelinePlate::default();
        Ok(())
    }
    fn check_restored(&self, fresh: &dyn crate::model::Model) -> std::result::Result<(), String> {
        self.check_restored(crate::model::same_solver(fresh)?)
    }
}
