//! The time loop of the 3-D MLPG mixed method (seed sections 2-3): a rod on
//! the ring lattice striking a rigid smooth anvil at z = 0, or several
//! bodies on ring lattices in contact with each other ([`Mlpg3d::bodies`]:
//! the penetration run, `crate::solver::mlpg3d::penetration`).
//!
//! # One step
//!
//! Updated Lagrangian, central differences (Newmark β = 0, γ = 1/2, seed
//! section 3.4), from positions `x^n`, velocities `v^{n−1/2}` and nodal
//! stresses `σ^n`:
//!
//! 1. the traction of every node's test sphere, `F_i = ∫ (σ + σ_v)·n dS`
//!    ([`TractionOperator`], eq. 10), with `σ_v` the viscous stress of the
//!    damping ([`DAMPING`]); the acceleration `a_i = F_i / (ρ_i V_s,i)`
//!    (the Heaviside weak form: the sphere's inertia);
//! 2. `v^{n+1/2} = v^{n−1/2} + dt a_i`; a node on the anvil keeps `v_z = 0`
//!    while the anvil pushes it (`F_z ≤ 0`) and is released when its sphere
//!    pulls it away (`F_z > 0`: the contact force would be tensile), the
//!    release timed where `F_z`, linear between the steps, crosses zero; then
//!    the velocity smoothing `v ← v + α (Σ_J φ_J(x_i) v_J − v_i)`
//!    ([`SMOOTHING`]), its kinetic energy booked as `smoothing_dissipation`;
//!    in a run of several bodies, the contact impulses between them, and
//!    in a material with damage, between pulverized nodes closer than half
//!    a spacing ([`contact`]);
//! 3. `x^{n+1} = x^n + dt v^{n+1/2}`; a node that reaches z = 0 stops on
//!    the anvil (its kinetic energy toward the anvil is booked as
//!    `contact_dissipation`), one that passes it by half a spacing is the
//!    error [`Error::ThroughBoundary`]; with `shifting > 0`, node shifting
//!    ([`crate::solver::mlpg3d::shift`]): pairs closer than half the initial spacing push
//!    apart and the moved nodes take the fields of their new place;
//! 4. the geometry follows the body: supports recomputed by
//!    [`Supports::recompute_reason`], shape functions, test spheres and the
//!    traction operator rebuilt when a named pair has moved, relative to the
//!    other, by more than [`REBUILD_STRAIN`] of its length since the last
//!    build;
//! 5. nodal velocity gradients by collocation (eq. 4), the rate of
//!    deformation and spin, the density `ρ (1 − dt tr D)`, and the shared
//!    [`Material::update`] in the 3-D ([`Full`]) form: Jaumann rate, radial
//!    return, heating, equation of state;
//! 6. energies, the checks (non-finite fields, energy drift, spacing
//!    collapse, compression limit) and the next step, eq. (15).
//!
//! Every pass runs over nodes in parallel (rayon) and writes per node;
//! sums are taken serially in node order, so any number of threads gives
//! the same bits.
//!
//! # The deformed free boundary
//!
//! The cut planes of a boundary node's test sphere follow the body: the
//! outward normal of the deformed surface is Nanson's `n ∝ F⁻ᵀ N`, with
//! `N` the reference normal of the lattice (radial on the mantle, ∓z on
//! the face and the top) and `F⁻¹ = ∂X/∂x` the collocated gradient (eq. 4)
//! of the reference positions over the current nodes. On an edge (mantle
//! and face or top) the mantle normal is made orthogonal to the face's, as
//! the cut rule works in an orthonormal frame. A face node pressed on the
//! anvil has the anvil's normal. An interior node's test radius is shrunk
//! (eq. 12) to its distance from the tangent planes of the boundary nodes
//! it names.
//!
//! # Files
//!
//! - this file: the run's state ([`Mlpg3d`]) and its assembly;
//! - `setup.rs`: [`RodSetup`], [`WeakForm`], [`Body`] and the defaults;
//! - `step.rs`: the step in order, with the forces (step 1), the geometry
//!   following the body (step 4) and the checks (step 6);
//! - `motion.rs`: the passes of steps 2-3 (velocities, smoothing, contact,
//!   clamp, positions), functions over the node fields;
//! - `update.rs`: the material pass of step 5 and the step's sums;
//! - `shifting.rs`: node shifting and the carry of the moved nodes' fields,
//!   functions over the node fields;
//! - `geometry.rs` and `spheres.rs`: the supports, shapes, operator and
//!   test spheres of a build;
//! - `scratch.rs`: the step's named buffers;
//! - `observe.rs`: what a run reports; `restore.rs`: the checks of a
//!   restored run; `util.rs`: small shared helpers.

mod balance;
pub mod contact;
pub mod failure;
mod geometry;
mod halo;
mod held;
mod motion;
mod observe;
#[cfg(test)]
mod pass_tests;
pub mod penetration;
pub mod profile;
mod restore;
pub mod scheme;
mod scratch;
mod setup;
mod shielding;
pub mod shift;
mod shifting;
mod spheres;
mod step;
#[cfg(test)]
mod tests;
mod update;
mod util;

use crate::approx::lattice::{NodeLattice, Surfaces};
use crate::approx::step::stable_step_with;
use crate::error::{Error, Result};
use crate::isa::Isa;
use crate::material::tensor::Full;
use crate::material::{Material, MaterialState};
use crate::observe::TAYLOR3D_OBSERVABLES;
/// The place in the energy book of the damping's loss.
const LOST_DAMPING: usize = 0;
/// The place in the energy book of the loss at the anvil or between bodies.
const LOST_CONTACT: usize = 1;
/// The place in the energy book of the smoothing's loss (node shifting's
/// included).
const LOST_SMOOTHING: usize = 2;

use crate::solver::shared::{Clock, EnergyBook, QuietEnd, check_derived};
use geometry::Geometry;
pub use observe::{Energies, MLPG_FIELDS};
use profile::PhaseTimes;
use scheme::Lattice;
use scratch::Scratch;
pub use setup::{Body, DAMPING, NodeOrder, REBUILD_STRAIN, RodSetup, SMOOTHING};
use util::{kinetic, kinetic1, norm};

/// A 3-D MLPG run of a rod striking a rigid smooth anvil, or of several
/// bodies: its setup, its state and its pipeline, apart.
#[derive(Debug, Clone)]
pub struct Mlpg3d {
    /// What the run is built from, and never changes.
    setup: Setup3d,
    /// What the run changes: all that is saved.
    state: State3d,
    /// The workspace of the step: rebuilt, never saved.
    pipe: Pipeline3d,
}

/// What a 3-D run is built from, from its scene, and never changes: the
/// rod's setup with its typed scheme, the bodies and their materials, the
/// lattice, the nodal masses and the quantities that follow from them.
/// Not saved: a restored run is built from its scene, and the state it
/// loads carries the digest of the setup that made it.
#[derive(Debug, Clone)]
struct Setup3d {
    /// The rod and the solver's choices.
    rod: RodSetup,
    /// The rod's material.
    material: Material,
    /// The reference lattice (positions at impact, volumes, surfaces, sets):
    /// the rod's nodes first, then those of each further body; the sets
    /// are the rod's.
    lattice: NodeLattice,
    /// The bodies after the rod (none for a Taylor run).
    others: Vec<Body>,
    /// The body of each node (0: the rod), empty for a run of one body.
    group: Vec<u8>,
    /// Whether the rigid anvil at z = 0 is there (a Taylor run).
    anvil: bool,
    /// Contact reach between the nodes of different bodies
    /// ([`contact`]): the smallest radial spacing of the bodies (m).
    reach: f64,
    /// The nodal masses (kg).
    mass: Vec<f64>,
    /// The symmetry planes each node lies on (bits `X`, `Y` of
    /// `src/approx/mirror.rs`) in the quarter model; empty for the whole
    /// body.
    plane: Vec<u8>,
    /// The nodes held still (a clamped rim, [`Body::clamped_rim`]); empty
    /// when none is.
    held: Vec<bool>,
    /// The smallest distance between named nodes at the start (m).
    d_min0: f64,
    /// Damping time `c = 2 ζ / ω_max` of the viscous stress (s).
    damping_time: f64,
}

impl Setup3d {
    /// The stable step of eq. (15) for the wave speed `c` and the smallest
    /// node distance `d`, times the safety factor, shortened for the
    /// damping: `(2 / ω_max)(√(1 + ζ²) − ζ)`.
    fn stable_dt(&self, c: f64, d: f64) -> f64 {
        let z = self.rod.damping;
        let kappa = self.rod.omega_factor();
        stable_step_with(kappa, c, d, self.rod.safety) * ((1.0 + z * z).sqrt() - z)
    }

    /// Whether a body's material has a damage model (no pass over the
    /// nodes: the step asks every time).
    /// Whether a body's material keeps damage variables at its points
    /// (Rajendran-Grove's or JH-2's): otherwise every point's
    /// [`crate::material::PointState`] holds none, and the passes that read
    /// them (the shifting's) need not visit the points.
    fn damage_vars(&self) -> bool {
        std::iter::once(&self.material)
            .chain(self.others.iter().map(|b| &b.material))
            .any(|m| !matches!(m.damage, crate::material::Damage::None))
    }

    fn damaging(&self) -> bool {
        std::iter::once(&self.material)
            .chain(self.others.iter().map(|b| &b.material))
            .any(|m| matches!(m.damage, crate::material::Damage::RajendranGrove(_)))
    }
}

/// Longitudinal elastic wave speed of the reference state (m/s), the
/// fastest of the bodies' (a body whose equation of state has no reference
/// density takes the first node's).
fn wave_speed(setup: &Setup3d, state: &State3d) -> f64 {
    let speed = |m: &Material| {
        let rho = m.eos.reference_density().unwrap_or(state.rho[0]);
        (m.longitudinal_modulus(rho, 0.0) / rho).sqrt()
    };
    setup
        .others
        .iter()
        .map(|b| speed(&b.material))
        .fold(speed(&setup.material), f64::max)
}

impl Setup3d {
    /// The digest of what the setup is made from, the rod's setup (its
    /// scheme included), the rod's material, the further bodies and the
    /// anvil: everything else in it follows from them.
    fn digest(&self) -> u64 {
        crate::solver::shared::setup_digest(&(&self.rod, &self.material, &self.others, self.anvil))
    }
}

/// What a 3-D run changes, and all that it saves (format 2 of
/// `src/state_format.rs`): the node fields (structure of arrays), the
/// record of the last build, the clock, the energy book, the material
/// state and the run's tallies.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct State3d {
    /// The digest of the setup of the run that made this state
    /// (`setup_digest` of `src/solver/shared/restore.rs`): a state loads
    /// only into a run of the same setup.
    setup_digest: u64,
    // Node fields.
    pos: Vec<[f64; 3]>,
    vel: Vec<[f64; 3]>,
    rho: Vec<f64>,
    dev: Vec<Full>,
    pressure: Vec<f64>,
    eps_p: Vec<f64>,
    temp: Vec<f64>,
    /// Viscous stress of the damping, from the last rate of deformation.
    visc: Vec<Full>,
    contact: Vec<bool>,
    /// The anvil's reaction on each node held on it at the last step's
    /// forces, `−F_z ≥ 0` (N; zero on a free node): a release is timed by
    /// the zero of the node's net axial force between that step and the
    /// next ([`Mlpg3d::last_release`]).
    reaction: Vec<f64>,
    /// The place at impact of the material each node is on: the lattice
    /// position, carried along when the node shifts (the reference map of
    /// the Nanson normals).
    reference: Vec<[f64; 3]>,
    /// The state of the material models at each node (the ceramic's
    /// damage variables).
    material_state: MaterialState,
    // The record of the last build, so that a restored run rebuilds its
    // geometry as it was.
    /// Positions the supports were computed from.
    supports_at: Vec<[f64; 3]>,
    /// Positions the operator was last built at.
    built_at: Vec<[f64; 3]>,
    /// `reference` at the last build of the operator (the test spheres'
    /// Nanson normals are built from it).
    built_reference: Vec<[f64; 3]>,
    /// `contact` at the last build of the operator (the test sphere of a
    /// face node held on the anvil is cut by the anvil's plane, of a free one
    /// by its Nanson plane).
    built_contact: Vec<bool>,
    /// `rho` at the last build of the operator (conforming gradients weigh
    /// the constraint by the nodal volumes `m / ρ` of the build).
    built_rho: Vec<f64>,
    /// The multipliers the conforming correction started from at the last
    /// build (those of the build before; empty: from zero) ([`conform`]'s
    /// warm start).
    built_multipliers: Vec<[f64; 3]>,
    // Bookkeeping.
    clock: Clock,
    /// The impact's kinetic energy, the internal energy and the losses to
    /// the damping ([`LOST_DAMPING`]), the anvil or the contact between
    /// bodies ([`LOST_CONTACT`]) and the smoothing ([`LOST_SMOOTHING`]).
    energy: EnergyBook<3>,
    plastic_work: f64,
    /// The part of the smoothing's loss that node shifting booked: the
    /// kinetic energy its carry of the velocities changed.
    shift_dissipation: f64,
    /// Smallest distance between named nodes so far, relative to `d_min0`.
    min_spacing: f64,
    /// Builds of the geometry so far.
    rebuilds: u64,
    at_rest: bool,
    /// The quiet end (saved as the time since which the run has been
    /// quiet).
    quiet_since: QuietEnd,
    /// Time of the last release of a node from the anvil.
    last_release: f64,
}

/// The workspace of a 3-D step: the geometry of the last build, the step's
/// buffers, the phase profile and the compiled copy of the hot loops.
/// Rebuilt, never saved.
#[derive(Debug, Clone, Default)]
struct Pipeline3d {
    /// The supports, shapes, test spheres and operator of the last build
    /// (`None`: rebuilt at the next step, as after a restore).
    geometry: Option<Geometry>,
    /// The buffers of the step.
    scratch: Scratch,
    /// Wall time per phase of this process's steps.
    profile: PhaseTimes,
    /// The compiled copy of the hot loops (the best one by default).
    isa: Isa,
    /// The ranks that share the passes over the nodes ([`crate::ranks`];
    /// one alone by default).
    ranks: crate::ranks::Handle,
    /// The material pass's shares among the ranks, by measured cost.
    balance: balance::Balance,
    /// What each rank sends of the material fields after the pass, and
    /// whether they are apart ([`halo`]).
    halo: halo::Halo,
}

/// The run's state is all it saves.
impl serde::Serialize for Mlpg3d {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        self.state.serialize(s)
    }
}

impl Mlpg3d {
    /// The rod of `setup` of `material` at the instant of impact: every
    /// node moving at `-impact_speed` along z, the face on the anvil.
    pub fn new(setup: RodSetup, material: Material) -> Result<Self> {
        Self::assemble(setup, material, Vec::new(), true)
    }

    /// A run of several bodies with no anvil: the rod of `setup` (its face
    /// at `setup.base`, moving at `-impact_speed`) and the `others`, in
    /// contact through [`contact`]. At most 255 bodies.
    pub fn bodies(setup: RodSetup, material: Material, others: Vec<Body>) -> Result<Self> {
        if others.len() > 254 {
            return Err(Error::OutOfRange {
                name: "bodies".into(),
                value: others.len() as f64 + 1.0,
                range: "[1, 255]".into(),
            });
        }
        Self::assemble(setup, material, others, false)
    }

    fn assemble(
        setup: RodSetup,
        material: Material,
        others: Vec<Body>,
        anvil: bool,
    ) -> Result<Self> {
        let density_of = |m: &Material| {
            m.validate()?;
            m.eos.reference_density().ok_or_else(|| {
                Error::Inconsistent("a body's equation of state has no reference density".into())
            })
        };
        let density = density_of(&material)?;
        setup.scheme.check(setup.quarter)?;
        let mut lattice = NodeLattice::cylinder_with(
            setup.cylinder,
            setup.rings,
            setup.scheme.lattice == Lattice::Staggered,
        );
        let mut plane = Vec::new();
        if setup.quarter {
            (lattice, plane) = lattice.quarter();
        }
        if setup.base != 0.0 {
            for x in &mut lattice.position {
                x[2] += setup.base;
            }
        }
        let v0 = setup.impact_speed;
        let n0 = lattice.len();
        let mut mass: Vec<f64> = lattice.volume.iter().map(|v| density * v).collect();
        let mut vel = vec![[0.0, 0.0, -v0]; n0];
        let mut rho = vec![density; n0];
        let mut temp = vec![material.reference_temperature; n0];
        let mut group = Vec::new();
        let mut reach = lattice.radial_spacing;
        if !others.is_empty() {
            group = vec![0u8; n0];
        }
        let mut held = Vec::new();
        for (b, body) in others.iter().enumerate() {
            let d = density_of(&body.material)?;
            let mut l = NodeLattice::cylinder(body.cylinder, body.rings);
            let mut on = Vec::new();
            if setup.quarter {
                (l, on) = l.quarter();
            }
            if body.node_order == NodeOrder::Bisection {
                (l, on) = l.bisected(&on);
            }
            plane.extend(on);
            reach = reach.min(l.radial_spacing);
            let k = l.len();
            if body.clamped_rim {
                // The outer ring: within half a spacing of the rim.
                let rim = body.cylinder.radius - 0.5 * l.radial_spacing;
                held.resize(lattice.len(), false);
                held.extend(l.position.iter().map(|x| x[0].hypot(x[1]) >= rim));
            } else if !held.is_empty() {
                held.resize(lattice.len() + k, false);
            }
            lattice
                .position
                .extend(l.position.iter().map(|x| [x[0], x[1], x[2] + body.base]));
            lattice.volume.extend_from_slice(&l.volume);
            lattice.surfaces.extend_from_slice(&l.surfaces);
            mass.extend(l.volume.iter().map(|v| d * v));
            vel.extend(std::iter::repeat_n([0.0, 0.0, body.velocity], k));
            rho.extend(std::iter::repeat_n(d, k));
            temp.extend(std::iter::repeat_n(body.material.reference_temperature, k));
            group.extend(std::iter::repeat_n(b as u8 + 1, k));
        }
        let n = lattice.len();
        let pos = lattice.position.clone();
        // One body: its impact energy as it always was (the same bits).
        let initial_energy = if others.is_empty() {
            0.5 * mass.iter().sum::<f64>() * v0 * v0
        } else {
            kinetic(&vel, &mass)
        };
        let contact: Vec<bool> = lattice
            .surfaces
            .iter()
            .enumerate()
            .map(|(i, s)| anvil && i < n0 && s.has(Surfaces::FACE))
            .collect();
        let mut s = Mlpg3d {
            setup: Setup3d {
                rod: setup,
                material,
                lattice,
                others,
                group,
                anvil,
                reach,
                mass,
                plane,
                held,
                d_min0: 0.0,
                damping_time: 0.0,
            },
            state: State3d {
                setup_digest: 0,
                vel,
                built_rho: rho.clone(),
                built_multipliers: Vec::new(),
                rho,
                dev: vec![[0.0; 6]; n],
                pressure: vec![0.0; n],
                eps_p: vec![0.0; n],
                temp,
                visc: vec![[0.0; 6]; n],
                built_contact: contact.clone(),
                reaction: vec![0.0; n],
                contact,
                material_state: MaterialState::default(),
                supports_at: pos.clone(),
                built_at: pos.clone(),
                reference: pos.clone(),
                built_reference: pos.clone(),
                pos,
                clock: Clock::default(),
                energy: EnergyBook::new(initial_energy),
                plastic_work: 0.0,
                shift_dissipation: 0.0,
                min_spacing: 1.0,
                rebuilds: 0,
                at_rest: false,
                quiet_since: QuietEnd::default(),
                last_release: 0.0,
            },
            pipe: Pipeline3d::default(),
        };
        geometry::build_geometry(&s.setup, &mut s.state, &mut s.pipe, true)?;
        s.setup.d_min0 = geometry::nearest_distance(&s.state, &s.pipe);
        let cp = s.wave_speed();
        check_derived("wave speed", cp, " m/s")?;
        s.setup.damping_time = 2.0 * setup.damping * s.setup.d_min0 / (setup.omega_factor() * cp);
        // The bound of every later step: the wave speed plus the nodes'
        // own speed, so that no body crosses a spacing (and past a contact)
        // in the first step.
        let fastest = s.state.vel.iter().map(|v| norm(*v)).fold(0.0, f64::max);
        s.state.clock = Clock::start(s.setup.stable_dt(cp + fastest, s.setup.d_min0));
        check_derived("time step", s.state.clock.dt, " s")?;
        s.state.setup_digest = s.setup.digest();
        Ok(s)
    }

    /// Longitudinal elastic wave speed of the reference state (m/s), the
    /// fastest of the bodies'.
    pub fn wave_speed(&self) -> f64 {
        wave_speed(&self.setup, &self.state)
    }

    /// One step (see the module docs).
    pub fn step(&mut self) -> Result<()> {
        if self.pipe.geometry.is_none() {
            let fresh = self.state.supports_at == self.state.built_at;
            geometry::build_geometry(&self.setup, &mut self.state, &mut self.pipe, fresh)?;
            self.state.rebuilds -= 1;
        }
        let n = self.particles();
        let watch = self.pipe.profile.stopwatch();
        self.state.material_state.fit(n);
        let mut scratch = std::mem::take(&mut self.pipe.scratch);
        scratch.fit(n);
        if self.setup.rod.scheme.shifting > 0.0 {
            scratch.fit_shift(n);
        }
        let result = step::step_with(
            &self.setup,
            &mut self.state,
            &mut self.pipe,
            &mut scratch,
            watch,
        );
        self.pipe.scratch = scratch;
        result
    }
}
