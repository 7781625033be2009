//! The axisymmetric MSPH solver of the Taylor impact test (Batra & Zhang 2008,
//! section 3): balance laws (3.1)-(3.4) in cylindrical coordinates with their
//! axis limits, Johnson-Cook thermo-viscoplasticity with the Jaumann rate and
//! radial return, the linear EOS, adiabatic heating, central differences in
//! time with the Courant step (3.22), conservative smoothing (3.23), a
//! traction-free mantle and top, and a rigid smooth anvil at Z = 0.
//!
//! Particles are rings. They sit on a regular (R, Z) lattice, the axis and the
//! surfaces included: `particles_radial` across the radius at spacing
//! `D = R0 / (n_r - 1)`, and `round(L0 / D) + 1` along the axis. Each carries the
//! mass of its tributary ring.
//!
//! One step, from positions `x^n`, velocities `v^{n-1/2}` and stresses
//! `sigma^n` (with boundary conditions applied):
//! 0. with `shifting > 0`, particle shifting (src/solver/axisymmetric/shift.rs): pairs
//!    closer than half the initial spacing push apart, and the moved
//!    particles take the fields of their new place;
//! 1. neighbours and MSPH first-derivative weights at `x^n`;
//! 2. acceleration from the divergence of stress; `v^{n+1/2} = v^{n-1/2} + dt a`,
//!    then `U_R = 0` on the axis and `U_Z = 0` on particles touching the anvil;
//! 3. conservative smoothing of the velocity (boundary conditions re-applied):
//!    (3.23), or with `smoothing_order = 2` its bi-Laplacian
//!    `v - alpha L(L v)`, `L v` = Shepard mean minus value, which damps the
//!    particle-scale waves as (3.23) does and the resolved flow far less;
//! 4. velocity gradients, continuity, conservative smoothing of the density
//!    (of the same order as the velocity's);
//! 5. stress update by the material ([`Material::update`]: Jaumann rate, trial
//!    deviator, radial return of its strength model, heating from plastic
//!    work, its EOS), internal energy from stress power;
//! 6. `x^{n+1} = x^n + dt v^{n+1/2}`, contact with the anvil (touch on reaching
//!    Z = 0, release when sigma_ZZ turns tensile), traction-free stresses on
//!    the free surfaces, next time step.
//!
//! The files: the state and its accessors here, the
//! construction (`setup.rs`), the mirror images (`mirror.rs`), the
//! neighbour lists (`neighbours.rs`), the step's buffers (`workspace.rs`),
//! its passes as functions over slices (`passes.rs`) and their order with
//! the stops between them (`step.rs`), the surfaces' stress conditions
//! (`surfaces.rs`), particle shifting (`shifting.rs`), the checks of a
//! restored run (`restore.rs`) and the observables and fields
//! (`fields.rs`).

pub mod boundary;
mod fields;
mod mirror;
mod neighbours;
mod pairs;
#[cfg(test)]
mod pass_tests;
mod passes;
mod restore;
pub mod scheme;
mod setup;
mod shift;
mod shifting;
mod step;
mod surfaces;
// Shares disjoint chunks of the step's arrays between the threads of a
// team: the only unsafe code of the solver besides the AVX-512 kernels.
#[allow(unsafe_code)]
mod team;
mod workspace;

pub use fields::TAYLOR_FIELDS;
pub use setup::TaylorParams;

use crate::isa::Isa;
use crate::material::{Material, MaterialState};
use crate::observe::FieldSpec;
use crate::solver::shared::{Clock, EnergyBook, QuietEnd};
use scheme::MsphScheme;

/// The place in the energy book of the kinetic energy the smoothing removed.
const LOST_SMOOTHING: usize = 0;
/// The place in the energy book of the kinetic energy lost on the anvil.
const LOST_CONTACT: usize = 1;
use crate::solver::COURANT;
use crate::solver::axisymmetric::boundary::{Stress, Surface};
use workspace::Workspace;

/// Gap along the axis, relative to the initial spacing, below which an
/// axis particle may leave the axis (src/solver/axisymmetric/shift.rs, `leaving`).
pub const AXIS_CROWD: f64 = 0.3;

/// Distance from a surface particle, relative to the initial spacing,
/// within which a particle does not shift outward across the surface
/// (README, "Particle shifting").
pub const SURFACE_BAND: f64 = 1.0;

/// Distance from the axis, relative to the initial spacing, that a particle
/// leaving it is moved to: its mirror image is then twice that away, above
/// [`SPACING_COLLAPSE_BOUND`](crate::solver::shared::SPACING_COLLAPSE_BOUND).
pub const AXIS_LEAVE: f64 = 0.1;

/// A Taylor impact run: its setup, its state and its pipeline, apart.
#[derive(Debug, Clone)]
pub struct TaylorSolver {
    /// What the run is built from, and never changes.
    setup: SetupAxi,
    /// What the run changes: all that is saved.
    state: StateAxi,
    /// The workspace of the step: rebuilt, never saved.
    pipe: PipelineAxi,
}

/// What a Taylor run is built from, from its scene, and never changes: the
/// parameters, the material, the lattice and its masses, the surfaces.
/// Not saved: a restored run is built from its scene, and the state it
/// loads carries the digest of the setup that made it.
#[derive(Debug, Clone)]
struct SetupAxi {
    /// The rod and the run's end, of the parameters (their material
    /// constants are the material's).
    rod: RodAxi,
    /// The scheme, typed, as the passes take it ([`MsphScheme::of`] the
    /// parameters).
    scheme: MsphScheme,
    /// The rod's material.
    material: Material,
    /// Particles across the radius and along the length.
    nr: usize,
    nz: usize,
    /// The smoothing length (m).
    h: f64,
    /// The rod's radius at impact (m).
    r0: f64,
    /// The particles' masses (kg).
    mass: Vec<f64>,
    /// The particles of the mantle, the top and the face.
    mantle: Surface,
    top: Surface,
    face: Surface,
}

impl SetupAxi {
    /// The digest of what the setup is made from, the rod, the scheme and
    /// the material: the lattice, masses and surfaces follow from them.
    fn digest(&self) -> u64 {
        crate::solver::shared::setup_digest(&(&self.rod, &self.scheme, &self.material))
    }
}

/// What the setup of a Taylor run keeps of its parameters besides the
/// scheme: the rod, its impact, its lattice's resolution and the run's end
/// (SI units; the material's constants are the material's).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
struct RodAxi {
    impact_speed: f64,
    initial_length: f64,
    initial_diameter: f64,
    density: f64,
    initial_temperature: f64,
    particles_radial: f64,
    end_time: f64,
}

impl RodAxi {
    /// The rod of the parameters `p`.
    fn of(p: &TaylorParams) -> RodAxi {
        RodAxi {
            impact_speed: p.impact_speed,
            initial_length: p.initial_length,
            initial_diameter: p.initial_diameter,
            density: p.density,
            initial_temperature: p.initial_temperature,
            particles_radial: p.particles_radial,
            end_time: p.end_time,
        }
    }
}

/// What a Taylor run changes, and all that it saves (format 2 of
/// `src/state_format.rs`): the particle fields (structure of arrays), the
/// clock, the energy book, the material state and the run's tallies.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct StateAxi {
    /// The digest of the setup of the run that made this state
    /// (`setup_digest` of `src/solver/shared/restore.rs`): a state loads
    /// only into a run of the same setup.
    setup_digest: u64,
    // Particle fields.
    pos: Vec<[f64; 2]>,
    vel: Vec<[f64; 2]>,
    rho: Vec<f64>,
    dev: Vec<Stress>,
    pressure: Vec<f64>,
    eps_p: Vec<f64>,
    temp: Vec<f64>,
    /// Stress with boundary conditions, used by the momentum equation.
    stress_bc: Vec<Stress>,
    contact: Vec<bool>,
    /// Whether each particle lies on the axis (a disc rather than a ring):
    /// the first of each lattice row at the start; shifting may move a
    /// crowded one off it.
    on_axis: Vec<bool>,
    /// Per-particle state of the material's models: its damage variables
    /// (none for a material without damage); its caches are rebuilt after a
    /// restore ([`MaterialState`]'s saved form).
    material_state: MaterialState,
    // Bookkeeping.
    clock: Clock,
    /// The impact's kinetic energy, the internal energy, and the losses to
    /// the smoothing ([`LOST_SMOOTHING`]) and the anvil ([`LOST_CONTACT`]).
    energy: EnergyBook<2>,
    at_rest: bool,
    /// The rest detector: the time since which the kinetic energy has
    /// stayed at or below [`QUIET_FRACTION`](crate::solver::shared::QUIET_FRACTION)
    /// of the impact energy (`None` while it is above).
    quiet_since: QuietEnd,
    /// Smallest spacing seen between neighbours, relative to the initial one.
    min_spacing: f64,
}

/// The workspace of a Taylor step: its buffers and the compiled copy of the
/// hot loops (a restored run uses the best its processor has). Rebuilt,
/// never saved.
#[derive(Debug, Clone, Default)]
struct PipelineAxi {
    ws: Workspace,
    isa: Isa,
}

/// The run's state is all it saves.
impl serde::Serialize for TaylorSolver {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        self.state.serialize(s)
    }
}

/// Neighbour-list skin, in units of h: the candidate lists hold every pair
/// within `(2 + SKIN) h` and are rebuilt once a particle has moved more than
/// half the skin. Pairs outside the support contribute exactly nothing, so
/// the result does not depend on when the lists were rebuilt.
pub const SKIN: f64 = 0.3;

/// Smallest number of particles a thread takes at a time.
const MIN_LEN: usize = 64;

/// Kinetic energy of a particle of mass `m` and velocity `v`.
#[inline]
fn kinetic1(v: [f64; 2], m: f64) -> f64 {
    0.5 * m * (v[0] * v[0] + v[1] * v[1])
}

/// Kinetic energy of particles of masses `m` and velocities `v`.
fn kinetic(v: &[[f64; 2]], m: &[f64]) -> f64 {
    v.iter().zip(m).map(|(v, m)| kinetic1(*v, *m)).sum()
}

/// The speed that bounds the time step at a particle: the longitudinal wave
/// speed `sqrt(modulus / rho)` plus the particle speed.
#[inline]
fn wave_and_flow_speed(modulus: f64, rho: f64, v: [f64; 2]) -> f64 {
    (modulus / rho).sqrt() + (v[0] * v[0] + v[1] * v[1]).sqrt()
}

impl TaylorSolver {
    /// Number of particles.
    pub fn particles(&self) -> usize {
        self.state.pos.len()
    }

    /// Particles across the radius and along the axis.
    pub fn lattice(&self) -> (usize, usize) {
        (self.setup.nr, self.setup.nz)
    }

    /// Smoothing length.
    pub fn smoothing_length(&self) -> f64 {
        self.setup.h
    }

    crate::solver::shared::clock_getters!(state.clock; dt);

    /// Whether the end condition holds: the rod is at rest, or `end_time` has
    /// been reached.
    pub fn finished(&self) -> bool {
        self.state.at_rest || self.state.clock.time >= self.setup.rod.end_time
    }

    /// Smallest distance between neighbouring particles relative to the
    /// initial spacing, over the run so far.
    pub fn min_spacing_ratio(&self) -> f64 {
        self.state.min_spacing
    }

    /// Runs the hot loops in the copy `isa` from now on (the same bits in
    /// every copy).
    pub fn set_isa(&mut self, isa: Isa) {
        self.pipe.isa = isa;
    }

    /// Longitudinal elastic wave speed sqrt((K + 4 mu / 3) / rho0).
    pub fn wave_speed(&self) -> f64 {
        self.setup.wave_speed()
    }

    fn stable_dt(&self) -> f64 {
        let m = &self.setup.material;
        let worst = (0..self.particles())
            .map(|i| {
                let (rho, p) = (self.state.rho[i], self.state.pressure[i]);
                wave_and_flow_speed(m.longitudinal_modulus(rho, p), rho, self.state.vel[i])
            })
            .fold(0.0, f64::max);
        COURANT * self.setup.h / worst
    }
}

impl SetupAxi {
    /// Longitudinal elastic wave speed of the reference state (m/s).
    fn wave_speed(&self) -> f64 {
        (self.material.longitudinal_modulus(self.rod.density, 0.0) / self.rod.density).sqrt()
    }

    /// Initial particle spacing.
    fn spacing(&self) -> f64 {
        self.r0 / (self.nr - 1) as f64
    }
}

impl crate::model::Model for TaylorSolver {
    crate::model::inherent_basics!();
    fn observable(&self, k: usize) -> Option<f64> {
        Self::observable(self, k)
    }
    fn field_specs(&self) -> &'static [FieldSpec] {
        TAYLOR_FIELDS
    }
    /// 64 records per elastic transit of the rod.
    fn record_interval(&self) -> f64 {
        self.setup.rod.initial_length / self.wave_speed() / 64.0
    }
    fn rod_profile(&self) -> Option<Vec<[f64; 2]>> {
        Some(crate::rod::profile(
            &self.rod_sets().mantle,
            &self.state.pos,
        ))
    }
    fn min_spacing_ratio(&self) -> Option<f64> {
        Some(self.min_spacing_ratio())
    }
    fn set_isa(&mut self, isa: Isa) {
        self.set_isa(isa);
    }
    fn load_state(
        &mut self,
        saved: crate::model::SavedSolver<'_>,
    ) -> std::result::Result<(), String> {
        Self::load_state(self, saved)
    }
    fn check_restored(&self, fresh: &dyn crate::model::Model) -> std::result::Result<(), String> {
        self.check_restored(crate::model::same_solver(fresh)?)
    }
}
