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
//! 0. with `shifting > 0`, particle shifting (src/solver/shift.rs): pairs
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

use super::COURANT;
use super::boundary::{Stress, Surface, corner_free, traction_free};
use super::pairs::{
    PairInputs, PairOutputs, PairPass, Rows, ScratchPool, laplacian, pair_batch, shepard_means,
    smooth, smooth2, velocity_gradients,
};
use super::shift::{Candidates, Freedom, carry, leaving, shifts, surface_band};
use super::team::{Chunks, Team};
use crate::error::{Error, Result};
use crate::isa::Isa;
use crate::kernel::SUPPORT;
use crate::lanes::W;
use crate::material::choice::{MaterialChoice, Prefix};
use crate::material::{Damage, Loading, Material, MaterialState, Point};
use crate::neighbors::padded_rows;
use crate::observe::{FieldSpec, TAYLOR_OBSERVABLES};
use crate::rod::{self, RodSets};
use crate::run::{
    ENERGY_ERROR_BOUND, QUIET_FRACTION, QUIET_TRANSITS, SHIFT_CAP, SHIFT_RANGE,
    SPACING_COLLAPSE_BOUND, above, below, check_derived, check_time_step, json,
};
use crate::scene::taylor::TaylorParams;
use crate::solver::scheme::{MsphScheme, SmoothingOrder};

/// Gap along the axis, relative to the initial spacing, below which an
/// axis particle may leave the axis (src/solver/shift.rs, `leaving`).
pub const AXIS_CROWD: f64 = 0.3;

/// Distance from a surface particle, relative to the initial spacing,
/// within which a particle does not shift outward across the surface
/// (README, "Particle shifting").
pub const SURFACE_BAND: f64 = 1.0;

/// Distance from the axis, relative to the initial spacing, that a particle
/// leaving it is moved to: its mirror image is then twice that away, above
/// [`SPACING_COLLAPSE_BOUND`].
pub const AXIS_LEAVE: f64 = 0.1;

/// State of a Taylor impact run.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct TaylorSolver {
    p: TaylorParams,
    material: Material,
    /// Per-particle state of the material's models: its damage variables
    /// are saved (none for a material without damage), its caches rebuilt
    /// after a restore ([`MaterialState`]'s saved form).
    #[serde(default)]
    material_state: MaterialState,
    nr: usize,
    nz: usize,
    h: f64,
    r0: f64,
    // Particle fields (structure of arrays).
    pos: Vec<[f64; 2]>,
    vel: Vec<[f64; 2]>,
    mass: Vec<f64>,
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
    mantle: Surface,
    top: Surface,
    face: Surface,
    // Bookkeeping.
    time: f64,
    steps: u64,
    dt: f64,
    dt0: f64,
    initial_energy: f64,
    internal_energy: f64,
    smoothing_dissipation: f64,
    contact_dissipation: f64,
    at_rest: bool,
    /// Time since which the kinetic energy has stayed at or below
    /// [`QUIET_FRACTION`] of the impact energy (`None` while it is above).
    #[serde(default)]
    quiet_since: Option<f64>,
    /// Smallest spacing seen between neighbours, relative to the initial one.
    min_spacing: f64,
    #[serde(skip)]
    ws: Workspace,
    /// The compiled copy of the hot loops this run uses (not saved: a
    /// restored run uses the best its processor has).
    #[serde(skip)]
    isa: Isa,
}

/// Neighbour-list skin, in units of h: the candidate lists hold every pair
/// within `(2 + SKIN) h` and are rebuilt once a particle has moved more than
/// half the skin. Pairs outside the support contribute exactly nothing, so
/// the result does not depend on when the lists were rebuilt.
pub const SKIN: f64 = 0.3;

/// Smallest number of particles a thread takes at a time.
const MIN_LEN: usize = 64;

/// What the pair pass found in a batch of [`W`] particles.
#[derive(Debug, Clone, Copy)]
struct BatchTally {
    /// First particle with a degenerate moment matrix, and its condition.
    singular: Option<(usize, f64)>,
    /// Smallest squared distance between neighbours.
    min_d2: f64,
    /// Kinetic energy removed by holding particles on the anvil.
    held: f64,
}

impl Default for BatchTally {
    fn default() -> Self {
        BatchTally {
            singular: None,
            min_d2: f64::INFINITY,
            held: 0.0,
        }
    }
}

/// The sums of a chunk of [`MIN_LEN`] particles at the end of a step, added
/// chunk by chunk in index order afterwards (so the totals do not depend on
/// the thread count).
#[derive(Debug, Clone, Copy, Default)]
struct Tally {
    /// Internal energy added by the stress power.
    internal: f64,
    /// Kinetic energy, and axial momentum `sum m U_Z`, at the end.
    kinetic: f64,
    momentum: f64,
    mass: f64,
    /// Kinetic energy removed by particles reaching the anvil.
    contact_lost: f64,
    /// Largest `c + |v|` (for the time step).
    worst_speed: f64,
    /// Largest `|v|^2`.
    fastest2: f64,
    /// Whether a particle touches the anvil.
    touching: bool,
    /// First particle through the anvil or the axis: (particle, boundary,
    /// position).
    through: Option<(usize, &'static str, f64)>,
    /// First particle with a non-finite field: (particle, field).
    non_finite: Option<(usize, &'static str)>,
    /// First particle compressed past the limit of the equation of state:
    /// (particle, compression, limit).
    compression: Option<(usize, f64, f64)>,
}

/// Buffers reused from step to step (no allocation in the time loop but when
/// the neighbour lists are rebuilt). Not part of the state: rebuilt from the
/// positions after a restore, and after a copy (see its `Clone`).
#[derive(Debug, Default)]
struct Workspace {
    /// Mirror images; image `k` has index `n + k`.
    images: Vec<Image>,
    /// Row length of the padded neighbour arrays.
    stride: usize,
    /// Candidate neighbours of particle `i`: `nbr[i * stride..][..nbr_len[i]]`,
    /// ascending, images included.
    nbr: Vec<u32>,
    nbr_len: Vec<u32>,
    /// Positions when the lists were built.
    built_at: Vec<[f64; 2]>,
    /// Contact flags of the impact-face particles when the images were made.
    face_contact: Vec<bool>,
    /// Particles on the axis when the images were made.
    axis_count: usize,
    /// Twice the farthest any particle moved since the pair pass of the last
    /// step: a particle whose closest neighbour then (`part[i].min_d2`) was
    /// farther than the shifting range plus this has no neighbour within
    /// the range now, and is left out of the shifting pass (which gives the
    /// same bits). None after a restore.
    shift_margin: Option<f64>,
    /// Per particle, the weights that turn a stress into the work it did in
    /// the last step, `dt/2 (m/rho) (D_RR, D_ZZ, D_TT, 2 D_RZ)`: the
    /// internal energy books the boundary conditions' change to the stress
    /// with them.
    rate: Vec<[f64; 4]>,
    /// The stress before the boundary conditions at the end of a step.
    raw_bc: Vec<Stress>,
    /// Fields of the particles and their images.
    pos: Vec<[f64; 2]>,
    vol: Vec<f64>,
    sbc: Vec<Stress>,
    vel: Vec<[f64; 2]>,
    vel_s: Vec<[f64; 2]>,
    /// The smoothing operator applied once to the velocity (the Shepard
    /// mean minus the value), for the smoothing of order 2.
    lap: Vec<[f64; 2]>,
    /// The same for the density (its smoothing follows the velocity's
    /// order).
    lap_rho: Vec<[f64; 1]>,
    rho: Vec<[f64; 1]>,
    /// Neighbours in the support this step, and their MSPH derivative
    /// weights (d/dR, d/dZ) and Shepard weights, in the padded layout.
    act: Vec<u32>,
    wr: Vec<f64>,
    wz: Vec<f64>,
    wk: Vec<f64>,
    part: Vec<PairPass>,
    grads: Vec<[f64; 4]>,
    /// Per batch of the pair pass, per chunk of the smoothing pass (kinetic
    /// energy before and after) and per chunk of the update pass.
    batches: Vec<BatchTally>,
    smoothing: Vec<[f64; 2]>,
    tallies: Vec<Tally>,
    /// Neighbourhoods of the pair pass, one set per thread.
    scratch: ScratchPool,
}

/// The plane or planes a mirror image is reflected across: the axis R = 0,
/// the anvil Z = 0, or both (an image of a particle near the axis and the
/// anvil).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mirror {
    Axis,
    Anvil,
    Both,
}

impl Mirror {
    /// Whether R (and the R components of vectors) change sign.
    fn flips_r(self) -> bool {
        self != Mirror::Anvil
    }
    /// Whether Z (and the Z components of vectors) change sign.
    fn flips_z(self) -> bool {
        self != Mirror::Axis
    }
}

/// A mirror image of a real particle.
#[derive(Debug, Clone, Copy)]
struct Image {
    source: u32,
    mirror: Mirror,
}

/// A field value as seen at a mirror image.
trait Mirrored: Copy {
    fn mirrored(self, m: Mirror) -> Self;
}

/// Scalars (volume, density) are even across both planes.
impl Mirrored for f64 {
    fn mirrored(self, _: Mirror) -> Self {
        self
    }
}

impl Mirrored for [f64; 1] {
    fn mirrored(self, _: Mirror) -> Self {
        self
    }
}

/// Vectors in (R, Z), positions and velocities: the component normal to the
/// plane changes sign.
impl Mirrored for [f64; 2] {
    fn mirrored(self, m: Mirror) -> Self {
        [
            if m.flips_r() { -self[0] } else { self[0] },
            if m.flips_z() { -self[1] } else { self[1] },
        ]
    }
}

/// Stresses (RR, ZZ, theta-theta, RZ): the shear changes sign across one
/// plane and is even across both.
impl Mirrored for Stress {
    fn mirrored(self, m: Mirror) -> Self {
        let odd = m.flips_r() != m.flips_z();
        [
            self[0],
            self[1],
            self[2],
            if odd { -self[3] } else { self[3] },
        ]
    }
}

/// Writes the image values `f[n + k] = f[images[k].source]` mirrored.
fn fill_images<T: Mirrored>(f: &mut [T], n: usize, images: &[Image]) {
    let (real, out) = f.split_at_mut(n);
    for (img, im) in out.iter_mut().zip(images) {
        *img = real[im.source as usize].mirrored(im.mirror);
    }
}

/// The smoothing operator `L f = (Shepard mean of f) − f` at the real
/// particles, `out[..n]`, and then at their images: the first pass of the
/// smoothing of order 2.
fn laplacians<const K: usize>(
    team: &Team,
    isa: Isa,
    rows: Rows,
    f: &[[f64; K]],
    out: &mut [[f64; K]],
    n: usize,
    images: &[Image],
) where
    [f64; K]: Mirrored,
{
    let parts = Chunks::new(&mut out[..n], MIN_LEN);
    team.run_parts(&parts, |c, out| {
        let i0 = c * MIN_LEN;
        shepard_means(isa, rows, f, i0, out);
        for (k, l) in out.iter_mut().enumerate() {
            *l = laplacian(f[i0 + k], *l);
        }
    });
    fill_images(out, n, images);
}

/// The outward normal of the top at the axis.
const TOP_ON_AXIS: [f64; 2] = [0.0, 1.0];
/// The outward normal of the impact face at the axis.
const FACE_ON_AXIS: [f64; 2] = [0.0, -1.0];

/// The outward normal at the `k`-th particle of a surface that starts on
/// the axis (the top or the face): `on_axis` for the particle on the axis,
/// where the surface is flat by symmetry, else [`Surface::normal`].
fn normal_from_axis(s: &Surface, k: usize, pos: &[[f64; 2]], on_axis: [f64; 2]) -> [f64; 2] {
    if k == 0 { on_axis } else { s.normal(k, pos) }
}

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

/// The first non-finite field of a particle, in the order position,
/// velocity, density, deviatoric stress, temperature.
fn non_finite(x: [f64; 2], v: [f64; 2], rho: f64, dev: Stress, temp: f64) -> Option<&'static str> {
    let finite = |x: &[f64]| x.iter().all(|v| v.is_finite());
    if !finite(&x) {
        Some("position")
    } else if !finite(&v) {
        Some("velocity")
    } else if !rho.is_finite() {
        Some("density")
    } else if !finite(&dev) {
        Some("deviatoric stress")
    } else if !temp.is_finite() {
        Some("temperature")
    } else {
        None
    }
}

impl TaylorSolver {
    /// Sets up the rod at the instant of impact, of the material the
    /// parameters describe ([`TaylorSolver::material_of`]). `p` must be
    /// validated.
    pub fn new(p: TaylorParams) -> Result<Self> {
        Self::with_material(p, Self::material_of(&p))
    }

    /// The material of the parameters: Johnson-Cook strength, the linear
    /// equation of state, no damage (the material block of
    /// [`MaterialChoice::JOHNSON_COOK_LINEAR`] read from `p`).
    pub fn material_of(p: &TaylorParams) -> Material {
        MaterialChoice::JOHNSON_COOK_LINEAR
            .material(Prefix::None, |name| {
                p.get(name)
                    .ok_or_else(|| Error::Inconsistent(format!("no parameter {name}")))
            })
            .expect("TaylorParams has every parameter of Johnson-Cook and the linear EOS")
    }

    /// Sets up the rod at the instant of impact, of `material`: its
    /// constants take the place of the material parameters of `p` (all but
    /// `density`, which must be the reference density of its equation of
    /// state, as the lattice masses use it). `p` must be validated.
    pub fn with_material(p: TaylorParams, material: Material) -> Result<Self> {
        material.validate()?;
        if material.eos.reference_density() != Some(p.density) {
            return Err(Error::Inconsistent(format!(
                "the reference density of the equation of state ({:?} kg/m3) is not the rod's \
                 density {} kg/m3",
                material.eos.reference_density(),
                p.density
            )));
        }
        let nr = p.particles_radial as usize;
        let r0 = 0.5 * p.initial_diameter;
        let d = r0 / (nr - 1) as f64;
        let nz = (p.initial_length / d).round() as usize + 1;
        let dz = p.initial_length / (nz - 1) as f64;
        let h = p.smoothing_ratio * d;
        let n = nr * nz;
        let mut pos = Vec::with_capacity(n);
        let mut mass = Vec::with_capacity(n);
        for k in 0..nz {
            for i in 0..nr {
                let r = i as f64 * d;
                let r_in = (r - 0.5 * d).max(0.0);
                let r_out = (r + 0.5 * d).min(r0);
                let z_len = if k == 0 || k == nz - 1 { 0.5 * dz } else { dz };
                let vol = std::f64::consts::PI * (r_out * r_out - r_in * r_in) * z_len;
                pos.push([r, k as f64 * dz]);
                mass.push(p.density * vol);
            }
        }
        let mantle = Surface {
            particles: (0..nz).map(|k| k * nr + nr - 1).collect(),
            sign: 1.0,
        };
        let top = Surface {
            particles: (0..nr).map(|i| (nz - 1) * nr + i).collect(),
            sign: -1.0,
        };
        let face = Surface {
            particles: (0..nr).collect(),
            sign: 1.0,
        };
        let vel = vec![[0.0, -p.impact_speed]; n];
        let contact = (0..n).map(|i| i < nr).collect();
        let total_mass: f64 = mass.iter().sum();
        let mut s = TaylorSolver {
            material,
            material_state: MaterialState::default(),
            nr,
            nz,
            h,
            r0,
            vel,
            rho: vec![p.density; n],
            dev: vec![[0.0; 4]; n],
            pressure: vec![0.0; n],
            eps_p: vec![0.0; n],
            temp: vec![p.initial_temperature; n],
            stress_bc: vec![[0.0; 4]; n],
            contact,
            on_axis: (0..n).map(|i| i.is_multiple_of(nr)).collect(),
            mantle,
            top,
            face,
            pos,
            mass,
            time: 0.0,
            steps: 0,
            dt: 0.0,
            dt0: 0.0,
            initial_energy: 0.5 * total_mass * p.impact_speed * p.impact_speed,
            internal_energy: 0.0,
            smoothing_dissipation: 0.0,
            contact_dissipation: 0.0,
            at_rest: false,
            quiet_since: None,
            min_spacing: 1.0,
            ws: Workspace::default(),
            isa: Isa::best(),
            p,
        };
        check_derived("wave speed", s.wave_speed(), " m/s")?;
        s.dt = s.stable_dt();
        check_derived("time step", s.dt, " s")?;
        s.dt0 = s.dt;
        Ok(s)
    }

    /// Number of particles.
    pub fn particles(&self) -> usize {
        self.pos.len()
    }

    /// Checks a restored state against `fresh`, a new run of the same
    /// parameters: what follows from the parameters (lattice, masses,
    /// material, surfaces, first step, impact energy) must be the same bits,
    /// and the evolving fields must have one finite, physical value per
    /// particle. A forged state that passes cannot index out of bounds or
    /// feed NaN into a step.
    pub(crate) fn check_restored(&self, fresh: &TaylorSolver) -> std::result::Result<(), String> {
        let same = |what: &str, a: String, b: String| {
            if a == b {
                Ok(())
            } else {
                Err(format!("its {what} does not follow from its parameters"))
            }
        };
        same("parameters", json(&self.p), json(&fresh.p))?;
        same("material", json(&self.material), json(&fresh.material))?;
        same(
            "lattice",
            json(&(self.nr, self.nz, self.h, self.r0)),
            json(&(fresh.nr, fresh.nz, fresh.h, fresh.r0)),
        )?;
        same("masses", json(&self.mass), json(&fresh.mass))?;
        same(
            "surfaces",
            json(&(&self.mantle, &self.top, &self.face)),
            json(&(&fresh.mantle, &fresh.top, &fresh.face)),
        )?;
        same(
            "first step and impact energy",
            json(&(self.dt0, self.initial_energy)),
            json(&(fresh.dt0, fresh.initial_energy)),
        )?;
        let n = fresh.particles();
        let lens = [
            ("positions", self.pos.len()),
            ("velocities", self.vel.len()),
            ("densities", self.rho.len()),
            ("deviatoric stresses", self.dev.len()),
            ("pressures", self.pressure.len()),
            ("plastic strains", self.eps_p.len()),
            ("temperatures", self.temp.len()),
            ("boundary stresses", self.stress_bc.len()),
            ("contact flags", self.contact.len()),
            ("axis flags", self.on_axis.len()),
        ];
        for (what, len) in lens {
            if len != n {
                return Err(format!("it holds {len} {what} for {n} particles"));
            }
        }
        if self.material_state.has_damage() && matches!(self.material.damage, Damage::None) {
            return Err("it holds damage variables, and its material has no damage model".into());
        }
        self.material_state.check_len(n)?;
        let finite = |what: &str, ok: bool| {
            if ok {
                Ok(())
            } else {
                Err(format!("its {what} are not all finite and in range"))
            }
        };
        let flat = |v: &[[f64; 2]]| v.iter().flatten().all(|x| x.is_finite());
        finite("positions", flat(&self.pos))?;
        finite("velocities", flat(&self.vel))?;
        finite(
            "densities",
            self.rho.iter().all(|&x| x.is_finite() && x > 0.0),
        )?;
        finite(
            "stresses",
            self.dev
                .iter()
                .chain(&self.stress_bc)
                .flatten()
                .chain(&self.pressure)
                .all(|x| x.is_finite()),
        )?;
        finite(
            "plastic strains",
            self.eps_p.iter().all(|&x| x.is_finite() && x >= 0.0),
        )?;
        finite(
            "temperatures",
            self.temp.iter().all(|&x| x.is_finite() && x > 0.0),
        )?;
        crate::run::check_restored_clock(
            self.time,
            self.dt,
            self.dt0,
            self.steps,
            &[
                self.internal_energy,
                self.smoothing_dissipation,
                self.contact_dissipation,
                self.min_spacing,
                self.quiet_since.unwrap_or(0.0),
            ],
        )?;
        // Finite is not enough: a velocity of 1e300 overflows the energies.
        let fastest = |v: &[f64; 2]| (v[0] * v[0] + v[1] * v[1]).sqrt();
        let bounds = crate::run::RestoreBounds::new(
            &fresh.pos,
            fresh.vel.iter().map(fastest).fold(0.0, f64::max) + fresh.wave_speed(),
            self.time,
        );
        bounds.speeds("velocities", &self.vel)?;
        bounds.places("positions", &self.pos)?;
        self.material_state.check_cracks(bounds.extent)
    }

    /// Particles across the radius and along the axis.
    pub fn lattice(&self) -> (usize, usize) {
        (self.nr, self.nz)
    }

    /// Smoothing length.
    pub fn smoothing_length(&self) -> f64 {
        self.h
    }

    /// Simulated time.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Current time step.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Whether the end condition holds: the rod is at rest, or `end_time` has
    /// been reached.
    pub fn finished(&self) -> bool {
        self.at_rest || self.time >= self.p.end_time
    }

    /// Smallest distance between neighbouring particles relative to the
    /// initial spacing, over the run so far.
    pub fn min_spacing_ratio(&self) -> f64 {
        self.min_spacing
    }

    /// Runs the hot loops in the copy `isa` from now on (the same bits in
    /// every copy).
    pub fn set_isa(&mut self, isa: Isa) {
        self.isa = isa;
    }

    /// Longitudinal elastic wave speed sqrt((K + 4 mu / 3) / rho0).
    pub fn wave_speed(&self) -> f64 {
        (self.material.longitudinal_modulus(self.p.density, 0.0) / self.p.density).sqrt()
    }

    fn stable_dt(&self) -> f64 {
        let m = &self.material;
        let worst = (0..self.particles())
            .map(|i| {
                let (rho, p) = (self.rho[i], self.pressure[i]);
                wave_and_flow_speed(m.longitudinal_modulus(rho, p), rho, self.vel[i])
            })
            .fold(0.0, f64::max);
        COURANT * self.h / worst
    }

    /// Initial particle spacing.
    fn spacing(&self) -> f64 {
        self.r0 / (self.nr - 1) as f64
    }

    /// Height above the anvil below which a particle counts as on it and has
    /// no mirror image across it: half the spacing guard, so that a particle
    /// and its own image are never closer than the guard allows.
    fn anvil_gap(&self) -> f64 {
        0.5 * SPACING_COLLAPSE_BOUND * self.spacing()
    }

    /// Whether particle `i` is mirrored across the anvil: it lies within
    /// `reach` of it and above [`Self::anvil_gap`], it is neither in contact
    /// nor a particle of the impact face (the face row is the plane of
    /// symmetry itself), and the face particle nearest to it in R is pressed
    /// on the anvil. A mirror image carries tension as well as compression,
    /// so above a part of the face that has left the anvil there is none:
    /// that part is a free surface.
    fn anvil_image(&self, i: usize, reach: f64) -> bool {
        let [r, z] = self.pos[i];
        if i < self.nr || self.contact[i] || z < self.anvil_gap() || z >= reach {
            return false;
        }
        let nearest = (0..self.nr)
            .min_by(|&a, &b| {
                let (da, db) = ((self.pos[a][0] - r).abs(), (self.pos[b][0] - r).abs());
                da.total_cmp(&db)
            })
            .expect("a face row");
        self.contact[nearest]
    }

    /// Rebuilds the mirror images and the candidate neighbour lists, with a
    /// skin of [`SKIN`] h, from the current positions.
    fn rebuild_neighbours(&self, ws: &mut Workspace) {
        let n = self.particles();
        let nr = self.nr;
        let reach = (SUPPORT + SKIN) * self.h;
        ws.images.clear();
        for i in 0..n {
            let axis = !self.on_axis[i] && self.pos[i][0] < reach;
            let anvil = self.anvil_image(i, reach);
            let source = i as u32;
            for (yes, mirror) in [
                (axis, Mirror::Axis),
                (anvil, Mirror::Anvil),
                (axis && anvil, Mirror::Both),
            ] {
                if yes {
                    ws.images.push(Image { source, mirror });
                }
            }
        }
        let m = n + ws.images.len();
        ws.pos.resize(m, [0.0; 2]);
        ws.pos[..n].copy_from_slice(&self.pos);
        fill_images(&mut ws.pos, n, &ws.images);
        ws.stride = padded_rows(
            &ws.pos,
            n,
            reach,
            W,
            ws.stride,
            &mut ws.nbr,
            &mut ws.nbr_len,
        );
        let stride = ws.stride;
        ws.built_at.clear();
        ws.built_at.extend_from_slice(&self.pos);
        ws.face_contact.clear();
        ws.face_contact.extend_from_slice(&self.contact[..nr]);
        ws.axis_count = self.axis_count();
        // Whole batches of W rows.
        let rows = n.next_multiple_of(W) * stride;
        ws.act.resize(rows, 0);
        ws.wr.resize(rows, 0.0);
        ws.wz.resize(rows, 0.0);
        ws.wk.resize(rows, 0.0);
        ws.vol.resize(m, 0.0);
        ws.sbc.resize(m, [0.0; 4]);
        ws.vel.resize(m, [0.0; 2]);
        ws.vel_s.resize(m, [0.0; 2]);
        if MsphScheme::of(&self.p).order == SmoothingOrder::BiLaplacian {
            ws.lap.resize(m, [0.0; 2]);
            ws.lap_rho.resize(m, [0.0]);
        }
        ws.rho.resize(m, [0.0]);
        ws.part.resize(n, PairPass::default());
        ws.grads.resize(n, [0.0; 4]);
        ws.batches.resize(n.div_ceil(W), BatchTally::default());
        ws.smoothing.resize(n.div_ceil(MIN_LEN), [0.0; 2]);
        ws.tallies.resize(n.div_ceil(MIN_LEN), Tally::default());
    }

    /// Whether a particle moved more than half the skin since the lists were
    /// built (or they were never built), a particle mirrored across the
    /// anvil has come down onto it (its image would meet it), or a particle
    /// of the impact face has touched or left the anvil (which changes the
    /// images).
    fn needs_rebuild(&self, ws: &Workspace) -> bool {
        if ws.built_at.len() != self.particles()
            || ws.face_contact[..] != self.contact[..self.nr]
            || ws.axis_count != self.axis_count()
        {
            return true;
        }
        let gap = self.anvil_gap();
        if ws.images.iter().any(|im| {
            let i = im.source as usize;
            im.mirror == Mirror::Anvil && (self.contact[i] || self.pos[i][1] < gap)
        }) {
            return true;
        }
        let limit = 0.5 * SKIN * self.h;
        let limit2 = limit * limit;
        self.pos.iter().zip(&ws.built_at).any(|(x, x0)| {
            let (a, b) = (x[0] - x0[0], x[1] - x0[1]);
            a * a + b * b > limit2
        })
    }

    /// Number of particles on the axis (particles only ever leave it).
    fn axis_count(&self) -> usize {
        self.on_axis.iter().filter(|&&a| a).count()
    }

    /// Advances one step.
    pub fn step(&mut self) -> Result<()> {
        let mut ws = std::mem::take(&mut self.ws);
        // The whole step runs on one worker of the thread pool, which leads
        // a team of the others through its parallel passes
        // (src/solver/team.rs). The neighbour rebuild comes first, with its
        // own parallel loops, so that no follower waits through it. Particle
        // shifting, if on, follows it, on lists that hold every pair in the
        // support (so that it does not depend on when they were built, and a
        // restored run shifts as the original did).
        let result = rayon::scope(|_| {
            let rebuilt = self.needs_rebuild(&ws);
            if rebuilt {
                self.rebuild_neighbours(&mut ws);
            }
            // New lists may bring new mirror images, and pairs with them.
            let margin = if rebuilt { None } else { ws.shift_margin };
            if self.p.shifting > 0.0 && self.shift(&mut ws, margin)? && self.needs_rebuild(&ws) {
                self.rebuild_neighbours(&mut ws);
            }
            Team::lead(|team| self.step_in(&mut ws, team))
        });
        self.ws = ws;
        result
    }

    /// The directions each particle may shift in: along the surface on the
    /// mantle and the top (they carry the boundary conditions and the rod's
    /// outline, which sliding keeps), none on the face row, the corners and
    /// a surface particle on the anvil or the axis, along Z on the axis,
    /// along R on the anvil, none on both.
    fn freedoms(&self, normals: &[(usize, [f64; 2])]) -> Vec<Freedom> {
        let mut free: Vec<Freedom> = self
            .contact
            .iter()
            .enumerate()
            .map(|(i, &touch)| match (self.on_axis[i], touch) {
                (true, true) => Freedom::Fixed,
                (true, false) => Freedom::Across([1.0, 0.0]),
                (false, true) => Freedom::Across([0.0, 1.0]),
                (false, false) => Freedom::Both,
            })
            .collect();
        // The surfaces slide along themselves: a particle of the mantle or
        // the top (not a corner, nor on the anvil) moves across its normal
        // only, so that the outline stays while crowded surface particles
        // spread along it. The face row and the corners stay. The normals
        // are those of [`Self::surface_normals`] (mantle, then top).
        let m = self.mantle.particles.len();
        for (s, normals) in [(&self.mantle, &normals[..m]), (&self.top, &normals[m..])] {
            let last = s.particles.len() - 1;
            for (k, &i) in s.particles.iter().enumerate() {
                let n = normals[k].1;
                free[i] =
                    if k == 0 || k == last || self.contact[i] || self.on_axis[i] || n == [0.0; 2] {
                        Freedom::Fixed
                    } else {
                        Freedom::Across(n)
                    };
            }
        }
        for &i in &self.face.particles {
            free[i] = Freedom::Fixed;
        }
        free
    }

    /// The particles of the surfaces (mantle, top, face row) with their
    /// outward normals, as the traction-free condition takes them.
    fn surface_normals(&self) -> Vec<(usize, [f64; 2])> {
        let mut out = Vec::with_capacity(
            self.mantle.particles.len() + self.top.particles.len() + self.face.particles.len(),
        );
        for (k, &i) in self.mantle.particles.iter().enumerate() {
            out.push((i, self.mantle.normal(k, &self.pos)));
        }
        for (s, on_axis) in [(&self.top, TOP_ON_AXIS), (&self.face, FACE_ON_AXIS)] {
            for (k, &i) in s.particles.iter().enumerate() {
                out.push((i, normal_from_axis(s, k, &self.pos, on_axis)));
            }
        }
        out
    }

    /// Particle shifting (src/solver/shift.rs): pushes apart the pairs closer
    /// than [`SHIFT_RANGE`] and carries the fields of the moved particles
    /// along. The kinetic energy the carrying changes is booked with the
    /// smoothing. With a `margin` ([`Workspace::shift_margin`]) only the
    /// particles that may have a neighbour within the range are looked at.
    /// Returns whether a particle moved, or the compression limit of the
    /// equation of state at a moved particle.
    fn shift(&mut self, ws: &mut Workspace, margin: Option<f64>) -> Result<bool> {
        let n = self.particles();
        let spacing = self.spacing();
        let normals = self.surface_normals();
        let mut free = self.freedoms(&normals);
        if let Some(m) = margin {
            let reach = SHIFT_RANGE * spacing * (1.0 + 1e-9) + m;
            for (f, p) in free.iter_mut().zip(&ws.part) {
                if p.min_d2 > reach * reach {
                    *f = Freedom::Fixed;
                }
            }
            if free.iter().all(|f| *f == Freedom::Fixed) {
                return Ok(false);
            }
        }
        ws.pos[..n].copy_from_slice(&self.pos);
        fill_images(&mut ws.pos, n, &ws.images);
        let c = Candidates {
            pos: &ws.pos,
            nbr: &ws.nbr,
            nbr_len: &ws.nbr_len,
            stride: ws.stride,
        };
        let outward = surface_band(c, n, &normals, SURFACE_BAND * spacing);
        let mut d = shifts(
            c,
            &free,
            &outward,
            spacing,
            SHIFT_RANGE * spacing,
            self.p.shifting,
            SHIFT_CAP * spacing,
        );
        self.leave_axis(&free, spacing, &mut d);
        if d.iter().all(|d| *d == [0.0; 2]) {
            return Ok(false);
        }
        let mut f: Vec<[f64; 9]> = (0..n)
            .map(|i| {
                let (v, s) = (self.vel[i], self.dev[i]);
                [
                    v[0],
                    v[1],
                    s[0],
                    s[1],
                    s[2],
                    s[3],
                    self.rho[i],
                    self.eps_p[i],
                    self.temp[i],
                ]
            })
            .collect();
        carry(c, n, self.h, &mut f, &d);
        let mut ke = [0.0; 2];
        for (i, (fi, di)) in f.iter().zip(&d).enumerate() {
            if *di == [0.0; 2] {
                continue;
            }
            ke[0] += kinetic1(self.vel[i], self.mass[i]);
            self.vel[i] = [fi[0], fi[1]];
            ke[1] += kinetic1(self.vel[i], self.mass[i]);
            // Each component was limited to its neighbours' range on its
            // own, which leaves a trace: the deviator (RR, ZZ, TT, RZ) is
            // made trace-free again (the mean normal stress stays −P).
            let m = (fi[2] + fi[3] + fi[4]) / 3.0;
            self.dev[i] = [fi[2] - m, fi[3] - m, fi[4] - m, fi[5]];
            self.rho[i] = fi[6];
            self.eps_p[i] = fi[7].max(0.0);
            self.temp[i] = fi[8];
            let p = self
                .material
                .pressure(fi[6], fi[8])
                .map_err(|l| Error::CompressionLimit {
                    particle: i,
                    time: self.time,
                    compression: l.compression,
                    limit: l.limit,
                })?;
            self.pressure[i] = p;
            let s = self.dev[i];
            self.stress_bc[i] = [s[0] - p, s[1] - p, s[2] - p, s[3]];
            if self.contact[i] {
                self.stress_bc[i][3] = 0.0;
            }
            self.pos[i] = [self.pos[i][0] + di[0], self.pos[i][1] + di[1]];
        }
        self.smoothing_dissipation += ke[0] - ke[1];
        // A surface particle that slid carries the stress of its new place:
        // the traction-free condition again, on the new normals.
        let slid = |s: &Surface| s.particles.iter().any(|&i| d[i] != [0.0; 2]);
        if slid(&self.mantle) || slid(&self.top) {
            self.apply_surface_stress_bc();
        }
        Ok(true)
    }

    /// Moves crowded particles off the axis ([`leaving`]): each leaves by
    /// [`AXIS_LEAVE`] along R, on top of its shift along Z, and from then on
    /// is a ring with its own mirror image.
    fn leave_axis(&mut self, free: &[Freedom], spacing: f64, d: &mut [[f64; 2]]) {
        let column: Vec<usize> = (0..self.particles())
            .step_by(self.nr)
            .filter(|&i| self.on_axis[i])
            .collect();
        let z: Vec<f64> = column.iter().map(|&i| self.pos[i][1]).collect();
        let may: Vec<bool> = column
            .iter()
            .map(|&i| free[i] == Freedom::Across([1.0, 0.0]))
            .collect();
        for (&i, leaves) in column.iter().zip(leaving(&z, &may, AXIS_CROWD * spacing)) {
            if leaves {
                d[i] = [AXIS_LEAVE * spacing, d[i][1]];
                self.on_axis[i] = false;
            }
        }
    }

    fn step_in(&mut self, ws: &mut Workspace, team: &Team) -> Result<()> {
        let n = self.particles();
        let dt = self.dt;
        let alpha = self.p.smoothing_coefficient;
        let isa = self.isa;
        let on_axis = &self.on_axis;
        let axis = |i: usize| on_axis[i];
        let Workspace {
            images,
            stride,
            nbr,
            nbr_len,
            pos,
            vol,
            sbc,
            vel,
            vel_s,
            lap,
            lap_rho,
            rho: rho_raw,
            act,
            wr,
            wz,
            wk,
            part,
            grads,
            batches,
            smoothing,
            tallies,
            scratch,
            rate,
            ..
        } = ws;
        rate.resize(n, [0.0; 4]);
        self.material_state.fit(n);
        scratch.fit();
        let stride = (*stride).max(1);
        // Mirror images across the axis and the anvil of the particles near
        // them, so that those particles see a symmetric neighbourhood (the
        // anvil is rigid and smooth): the velocity component and the shear
        // stress odd across the plane, the rest even.
        pos[..n].copy_from_slice(&self.pos);
        fill_images(pos, n, images);
        for ((v, m), r) in vol.iter_mut().zip(&self.mass).zip(&self.rho) {
            *v = m / r;
        }
        fill_images(vol, n, images);
        sbc[..n].copy_from_slice(&self.stress_bc);
        fill_images(sbc, n, images);

        // 1-2. Per particle: the MSPH moment matrix over the neighbours in
        // the support, the derivative and Shepard weights of each pair, and
        // the momentum equation v^{n+1/2} = v^{n-1/2} + dt div(sigma) / rho,
        // W particles at a time (src/solver/pairs.rs); then U_Z = 0 on the
        // particles touching the anvil.
        let inputs = PairInputs {
            pos,
            vol,
            sbc,
            nbr,
            nbr_len,
            stride,
            vel: &self.vel,
            rho: &self.rho,
            on_axis: &self.on_axis,
            h: self.h,
            dt,
        };
        let (mass, contact) = (&self.mass, &self.contact);
        {
            let rows = MIN_LEN * stride;
            let parts = (
                Chunks::new(act, rows),
                Chunks::new(wr, rows),
                Chunks::new(wz, rows),
                Chunks::new(wk, rows),
                Chunks::new(part, MIN_LEN),
                Chunks::new(&mut vel[..n], MIN_LEN),
                Chunks::new(batches, MIN_LEN / W),
            );
            team.run_parts(&parts, |c, (act, wr, wz, wk, part, vel, tallies)| {
                let mut scratch = scratch.get();
                let batch = W * stride;
                for (b, (((((act, wr), wz), wk), (part, vel)), tally)) in act
                    .chunks_mut(batch)
                    .zip(wr.chunks_mut(batch))
                    .zip(wz.chunks_mut(batch))
                    .zip(wk.chunks_mut(batch))
                    .zip(part.chunks_mut(W).zip(vel.chunks_mut(W)))
                    .zip(tallies)
                    .enumerate()
                {
                    let i0 = c * MIN_LEN + b * W;
                    let out = PairOutputs {
                        act,
                        wr,
                        wz,
                        wk,
                        part: &mut *part,
                        vel: &mut *vel,
                    };
                    pair_batch(isa, &inputs, i0, out, &mut scratch);
                    let mut t = BatchTally::default();
                    for (k, (p, v)) in part.iter().zip(vel.iter_mut()).enumerate() {
                        let i = i0 + k;
                        if p.condition != 0.0 && t.singular.is_none() {
                            t.singular = Some((i, p.condition));
                        }
                        t.min_d2 = t.min_d2.min(p.min_d2);
                        if contact[i] {
                            t.held += 0.5 * mass[i] * v[1] * v[1];
                            v[1] = 0.0;
                        }
                    }
                    *tally = t;
                }
            });
        }
        let mut a = BatchTally::default();
        for t in batches.iter() {
            a.singular = a.singular.or(t.singular);
            a.min_d2 = a.min_d2.min(t.min_d2);
            a.held += t.held;
        }
        if let Some((particle, condition)) = a.singular {
            return Err(Error::SingularMomentMatrix {
                method: crate::error::MomentMethod::Msph,
                particle,
                time: self.time,
                condition,
            });
        }
        let d0 = self.spacing();
        let ratio = a.min_d2.sqrt() / d0;
        self.min_spacing = self.min_spacing.min(ratio);
        if below(ratio, SPACING_COLLAPSE_BOUND) {
            return Err(Error::SpacingCollapse {
                ratio,
                bound: SPACING_COLLAPSE_BOUND,
                time: self.time,
                hint: if self.p.shifting == 0.0 {
                    "; at large strain, use scheme = large_strain, the default (it sets \
                     smoothing_order = 2, smoothing_ratio = 2 and shifting = 0.1; README, \
                     \"Particle shifting\")"
                } else {
                    ""
                },
            });
        }
        self.contact_dissipation += a.held;

        // 3. Conservative smoothing of the velocity.
        fill_images(vel, n, images);
        let rows = Rows {
            act,
            wr,
            wz,
            wk,
            part,
            stride,
        };
        let order2 = MsphScheme::of(&self.p).order == SmoothingOrder::BiLaplacian;
        if order2 {
            // Order 2: first the operator L v = (Shepard mean of v) - v.
            laplacians(team, isa, rows, vel, lap, n, images);
        }
        {
            let (vel, lap) = (&*vel, &*lap);
            let parts = (
                Chunks::new(&mut vel_s[..n], MIN_LEN),
                Chunks::new(smoothing, 1),
            );
            team.run_parts(&parts, |c, (out, ke)| {
                let ke = &mut ke[0];
                let i0 = c * MIN_LEN;
                *ke = [0.0; 2];
                if order2 {
                    // v - alpha L(L v): the mean of L v is taken into `out`.
                    shepard_means(isa, rows, lap, i0, out);
                } else {
                    shepard_means(isa, rows, vel, i0, out);
                }
                for (k, v) in out.iter_mut().enumerate() {
                    let i = i0 + k;
                    *v = if order2 {
                        smooth2(vel[i], lap[i], *v, alpha)
                    } else {
                        smooth(vel[i], *v, alpha)
                    };
                    if axis(i) {
                        v[0] = 0.0;
                    }
                    if contact[i] {
                        v[1] = 0.0;
                    }
                    ke[0] += kinetic1(vel[i], mass[i]);
                    ke[1] += kinetic1(*v, mass[i]);
                }
            });
        }
        let ke = smoothing
            .iter()
            .fold([0.0; 2], |a, k| [a[0] + k[0], a[1] + k[1]]);
        self.smoothing_dissipation += ke[0] - ke[1];

        // 4. Velocity gradients and continuity.
        fill_images(vel_s, n, images);
        let vel = &*vel_s;
        {
            let parts = (
                Chunks::new(grads, MIN_LEN),
                Chunks::new(&mut rho_raw[..n], MIN_LEN),
            );
            team.run_parts(&parts, |c, (grads, rho_out)| {
                let i0 = c * MIN_LEN;
                // dU_R/dR, dU_R/dZ, dU_Z/dR, dU_Z/dZ
                velocity_gradients(isa, rows, vel, i0, grads);
                for (k, (g, rho_out)) in grads.iter().zip(rho_out).enumerate() {
                    let i = i0 + k;
                    let hoop = if axis(i) { g[0] } else { vel[i][0] / pos[i][0] };
                    let div = g[0] + g[3] + hoop;
                    *rho_out = [self.rho[i] * (1.0 - dt * div)];
                }
            });
        }
        fill_images(rho_raw, n, images);
        // With order 2 the density is smoothed by the same bi-Laplacian as
        // the velocity: first L ρ, then the Shepard mean of L ρ in the loop.
        if order2 {
            laplacians(team, isa, rows, rho_raw, lap_rho, n, images);
        }

        // 5-6. Per particle: conservative smoothing of the density, the
        // constitutive update, positions x^{n+1} = x^n + dt v^{n+1/2}, anvil
        // contact, the generic stress boundary condition, and the sums of the
        // step, MIN_LEN particles at a time.
        let material = self.material;
        let (grads, rho_raw) = (&*grads, &*rho_raw);
        let (h, mass) = (self.h, &self.mass);
        {
            let parts = (
                (
                    Chunks::new(&mut self.dev, MIN_LEN),
                    Chunks::new(&mut self.pressure, MIN_LEN),
                    Chunks::new(&mut self.eps_p, MIN_LEN),
                    Chunks::new(&mut self.temp, MIN_LEN),
                    Chunks::new(&mut self.rho, MIN_LEN),
                    Chunks::new(self.material_state.points_mut(), MIN_LEN),
                ),
                (
                    Chunks::new(&mut self.pos, MIN_LEN),
                    Chunks::new(&mut self.vel, MIN_LEN),
                    Chunks::new(&mut self.contact, MIN_LEN),
                    Chunks::new(&mut self.stress_bc, MIN_LEN),
                    Chunks::new(tallies, 1),
                    Chunks::new(&mut rate[..], MIN_LEN),
                ),
            );
            team.run_parts(
                &parts,
                |c, ((dev, pressure, eps_p, temp, rho, models), (x, v, touch, sbc, tally, work))| {
                    let tally = &mut tally[0];
                    let i0 = c * MIN_LEN;
                    let mut means = [[0.0]; MIN_LEN];
                    let means = &mut means[..dev.len()];
                    if order2 {
                        shepard_means(isa, rows, lap_rho, i0, means);
                    } else {
                        shepard_means(isa, rows, rho_raw, i0, means);
                    }
                    let mut t = Tally::default();
                    for k in 0..dev.len() {
                        let i = i0 + k;
                        let [rho_new] = if order2 {
                            smooth2(rho_raw[i], lap_rho[i], means[k], alpha)
                        } else {
                            smooth(rho_raw[i], means[k], alpha)
                        };
                        let g = grads[i];
                        let d_rr = g[0];
                        let d_zz = g[3];
                        let d_tt = if axis(i) { g[0] } else { vel[i][0] / pos[i][0] };
                        // On the axis, symmetry gives dU_R/dZ = dU_Z/dR = 0: no
                        // shear and no spin (sigma_RZ is odd in R).
                        let (d_rz, omega) = if axis(i) {
                            (0.0, 0.0)
                        } else {
                            (0.5 * (g[1] + g[2]), 0.5 * (g[1] - g[2]))
                        };
                        let load = Loading {
                            dt,
                            rate: [d_rr, d_zz, d_tt, d_rz],
                            spin: omega,
                            density: rho_new,
                        };
                        let before = Point {
                            deviator: dev[k],
                            pressure: pressure[k],
                            plastic_strain: eps_p[k],
                            temperature: temp[k],
                        };
                        let new = match material.update(&load, &before, &mut models[k]) {
                            Ok(new) => new,
                            Err(l) => {
                                // The step stops with the named error.
                                t.compression =
                                    t.compression.or(Some((i, l.compression, l.limit)));
                                continue;
                            }
                        };
                        let p_new = new.pressure;
                        // Stress power with the mid-step stress: the mean of
                        // the stress the momentum equation used (boundary
                        // conditions applied) and the new one (whose
                        // conditions the end of the step books), per unit
                        // mass.
                        let old = sbc[k];
                        let s = new.deviator;
                        let sm = |k: usize, p: f64| 0.5 * (old[k] + s[k] - p);
                        let power = sm(0, p_new) * d_rr
                            + sm(1, p_new) * d_zz
                            + sm(2, p_new) * d_tt
                            + 2.0 * 0.5 * (old[3] + s[3]) * d_rz;
                        let w = 0.5 * dt * mass[i] / rho_new;
                        work[k] = [w * d_rr, w * d_zz, w * d_tt, w * 2.0 * d_rz];
                        dev[k] = s;
                        pressure[k] = p_new;
                        eps_p[k] = new.plastic_strain;
                        temp[k] = new.temperature;
                        rho[k] = rho_new;
                        t.internal += dt * power * mass[i] / rho_new;

                        // Positions and anvil contact.
                        let mut vi = vel[i];
                        let mut xi = [x[k][0] + dt * vi[0], x[k][1] + dt * vi[1]];
                        if touch[k] {
                            // Released when the normal stress turns tensile.
                            if dev[k][1] - pressure[k] > 0.0 {
                                touch[k] = false;
                            }
                        } else if xi[1] < 0.0 {
                            if xi[1] < -0.5 * h && t.through.is_none() {
                                t.through = Some((i, "anvil", xi[1]));
                            }
                            xi[1] = 0.0;
                            t.contact_lost += 0.5 * mass[i] * vi[1] * vi[1];
                            vi[1] = 0.0;
                            touch[k] = true;
                        }
                        if !axis(i) && xi[0] <= 0.0 && t.through.is_none() {
                            t.through = Some((i, "axis", xi[0]));
                        }
                        x[k] = xi;
                        v[k] = vi;
                        if t.non_finite.is_none() {
                            t.non_finite = non_finite(xi, vi, rho_new, dev[k], temp[k])
                                .map(|field| (i, field));
                        }
                        let p = pressure[k];
                        let d = dev[k];
                        sbc[k] = [d[0] - p, d[1] - p, d[2] - p, d[3]];

                        // The sums of the step.
                        t.kinetic += kinetic1(vi, mass[i]);
                        t.momentum += mass[i] * vi[1];
                        t.mass += mass[i];
                        t.touching |= touch[k];
                        let modulus = material.longitudinal_modulus(rho_new, p_new);
                        t.worst_speed =
                            t.worst_speed.max(wave_and_flow_speed(modulus, rho_new, vi));
                        // The velocity the particle moved with (before
                        // a contact stopped it).
                        let moved = vel[i];
                        t.fastest2 = t.fastest2.max(moved[0] * moved[0] + moved[1] * moved[1]);
                    }
                    *tally = t;
                },
            );
        }
        let mut t = Tally::default();
        for c in tallies.iter() {
            t.internal += c.internal;
            t.kinetic += c.kinetic;
            t.momentum += c.momentum;
            t.mass += c.mass;
            t.contact_lost += c.contact_lost;
            t.worst_speed = t.worst_speed.max(c.worst_speed);
            t.fastest2 = t.fastest2.max(c.fastest2);
            t.touching |= c.touching;
            t.through = t.through.or(c.through);
            t.non_finite = t.non_finite.or(c.non_finite);
            t.compression = t.compression.or(c.compression);
        }
        self.internal_energy += t.internal;
        self.contact_dissipation += t.contact_lost;
        ws.shift_margin = Some(2.0 * dt * t.fastest2.sqrt());
        self.time += dt;
        self.steps += 1;
        if let Some((particle, boundary, position)) = t.through {
            return Err(Error::ThroughBoundary {
                particle,
                boundary,
                time: self.time,
                position,
            });
        }
        if let Some((particle, compression, limit)) = t.compression {
            return Err(Error::CompressionLimit {
                particle,
                time: self.time,
                compression,
                limit,
            });
        }
        if let Some((field, particle)) = t.non_finite.map(|(i, f)| (f, i)) {
            return Err(Error::NonFinite {
                field,
                particle,
                time: self.time,
            });
        }
        // The boundary conditions on the new stress, and the work they take
        // from the new half of the step's stress power.
        ws.raw_bc.clear();
        ws.raw_bc.extend_from_slice(&self.stress_bc);
        self.apply_surface_stress_bc();
        let mut booked = 0.0;
        for ((bc, raw), w) in self.stress_bc.iter().zip(&ws.raw_bc).zip(&ws.rate) {
            for c in 0..4 {
                booked += (bc[c] - raw[c]) * w[c];
            }
        }
        self.internal_energy += booked;

        let e = self.energy_error_with(t.kinetic);
        if above(e, ENERGY_ERROR_BOUND) {
            return Err(Error::EnergyDrift {
                error: e,
                bound: ENERGY_ERROR_BOUND,
                time: self.time,
            });
        }
        self.dt = COURANT * self.h / t.worst_speed;
        check_time_step(self.dt, self.dt0, self.time)?;
        // The rod is at rest once its momentum toward the anvil is spent: the
        // centre of mass no longer moves toward the anvil.
        if -t.momentum / t.mass <= 0.0 && !t.touching {
            self.at_rest = true;
        }
        // Or once it is quiet: a flange pressed flat on the anvil never
        // leaves it, and the rod rings elastically on it for ever. Its impact
        // energy is spent once the kinetic energy has stayed below
        // QUIET_FRACTION of it for QUIET_TRANSITS elastic transits L0/Ce.
        if t.kinetic <= QUIET_FRACTION * self.initial_energy {
            let since = *self.quiet_since.get_or_insert(self.time);
            let window = QUIET_TRANSITS * self.p.initial_length / self.wave_speed();
            if self.time - since >= window {
                self.at_rest = true;
            }
        } else {
            self.quiet_since = None;
        }
        Ok(())
    }

    /// Stress used by the momentum equation: the traction-free and
    /// smooth-contact conditions applied on the surfaces to the constitutive
    /// stress `dev - p I` (which the update pass writes for every particle).
    fn apply_surface_stress_bc(&mut self) {
        let n = self.particles();
        let (nr, nz) = (self.nr, self.nz);
        for (k, &i) in self.mantle.particles.iter().enumerate() {
            let s = &self.stress_bc[i];
            self.stress_bc[i] = if k == nz - 1 || (k == 0 && !self.contact[i]) {
                corner_free(s)
            } else {
                traction_free(s, self.mantle.normal(k, &self.pos))
            };
        }
        for (k, &i) in self.top.particles.iter().enumerate().take(nr - 1) {
            let n = normal_from_axis(&self.top, k, &self.pos, TOP_ON_AXIS);
            self.stress_bc[i] = traction_free(&self.stress_bc[i], n);
        }
        for (k, &i) in self.face.particles.iter().enumerate().take(nr - 1) {
            if self.contact[i] {
                // Smooth anvil: no shear traction.
                self.stress_bc[i][3] = 0.0;
            } else {
                let n = normal_from_axis(&self.face, k, &self.pos, FACE_ON_AXIS);
                self.stress_bc[i] = traction_free(&self.stress_bc[i], n);
            }
        }
        // Particles that started elsewhere but touch the anvil (a folded
        // mantle) carry no shear there either.
        for i in 0..n {
            if self.contact[i] && i >= self.nr {
                self.stress_bc[i][3] = 0.0;
            }
        }
    }

    fn kinetic_energy(&self) -> f64 {
        kinetic(&self.vel, &self.mass)
    }

    fn energy_error(&self) -> f64 {
        self.energy_error_with(self.kinetic_energy())
    }

    /// The energy error with the kinetic energy given (the update pass sums
    /// it in chunks).
    fn energy_error_with(&self, kinetic: f64) -> f64 {
        (kinetic + self.internal_energy + self.smoothing_dissipation + self.contact_dissipation
            - self.initial_energy)
            .abs()
            / self.initial_energy
    }

    /// The centre-of-mass axial velocity toward the anvil.
    pub fn centre_of_mass_speed(&self) -> f64 {
        let (mut mv, mut m) = (0.0, 0.0);
        for (v, mi) in self.vel.iter().zip(&self.mass) {
            mv -= mi * v[1];
            m += mi;
        }
        mv / m
    }

    /// The rod's particle sets: the face row, the mantle column from the
    /// face up, and the tail on the axis.
    pub fn rod_sets(&self) -> RodSets {
        let (nr, nz) = (self.nr, self.nz);
        RodSets {
            face: self.face.particles.clone(),
            mantle: (0..nz).map(|k| k * nr + nr - 1).collect(),
            tail: (nz - 1) * nr,
        }
    }

    /// Current values of [`TAYLOR_OBSERVABLES`], in that order.
    pub fn observables(&self) -> Vec<f64> {
        (0..TAYLOR_OBSERVABLES.len())
            .map(|k| self.observable(k).expect("one value per row of the table"))
            .collect()
    }

    /// The current value of the `k`-th of [`TAYLOR_OBSERVABLES`] alone
    /// (`None` past the table): the rod's length and the largest plastic
    /// strain and temperature take one pass over the particles, the
    /// kinetic energy and the energy error one sum; the others read the
    /// face, the mantle generator, the tail or a total kept by the step.
    /// Nothing is allocated; the bits are those of
    /// [`TaylorSolver::observables`].
    pub fn observable(&self, k: usize) -> Option<f64> {
        Some(match TAYLOR_OBSERVABLES.get(k)?.name {
            "rod_length" => rod::rod_length(&self.pos),
            "mushroom_radius" => rod::mushroom_radius(&self.face.particles, &self.pos),
            "undeformed_length" => {
                rod::undeformed_length(&self.mantle.particles, &self.pos, self.r0)
            }
            "tail_velocity" => rod::tail_velocity((self.nz - 1) * self.nr, &self.vel),
            "face_lift" => self.pos[0][1],
            "max_plastic_strain" => self.eps_p.iter().copied().fold(0.0, f64::max),
            "max_temperature" => self.temp.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            "kinetic_energy" => self.kinetic_energy(),
            "internal_energy" => self.internal_energy,
            "smoothing_dissipation" => self.smoothing_dissipation,
            "contact_dissipation" => self.contact_dissipation,
            "energy_error" => self.energy_error(),
            "at_rest" => {
                if self.at_rest {
                    1.0
                } else {
                    0.0
                }
            }
            other => unreachable!("the Taylor observable `{other}` has no formula"),
        })
    }

    /// The values of the particle field `name` (one of [`TAYLOR_FIELDS`]),
    /// interleaved per particle.
    pub fn field(&self, name: &str) -> Option<Vec<f64>> {
        Some(match name {
            "position" => self.pos.iter().flatten().copied().collect(),
            "density" => self.rho.clone(),
            "velocity" => self.vel.iter().flatten().copied().collect(),
            "pressure" => self.pressure.clone(),
            "stress" => self
                .dev
                .iter()
                .zip(&self.pressure)
                .flat_map(|(d, p)| [d[0] - p, d[1] - p, d[2] - p, d[3]])
                .collect(),
            "plastic_strain" => self.eps_p.clone(),
            "temperature" => self.temp.clone(),
            "in_contact" => self.contact.iter().map(|&c| c as u8 as f64).collect(),
            _ => return None,
        })
    }
}

/// The particle fields of the Taylor solver.
pub const TAYLOR_FIELDS: &[FieldSpec] =
    &crate::observe::rod_fields(&["R", "Z"], &["RR", "ZZ", "TT", "RZ"]);

/// A copy of a run (an FMU state got to roll back to) starts with empty
/// buffers, as a restored run does, and rebuilds them at its next step with
/// the same bits: at 10^6 particles the buffers are 1.5 GB, the state
/// itself 0.14 GB (BENCHMARKS.md).
impl Clone for Workspace {
    fn clone(&self) -> Self {
        Workspace::default()
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
        self.p.initial_length / self.wave_speed() / 64.0
    }
    fn rod_profile(&self) -> Option<Vec<[f64; 2]>> {
        Some(crate::rod::profile(&self.rod_sets().mantle, &self.pos))
    }
    fn min_spacing_ratio(&self) -> Option<f64> {
        Some(self.min_spacing_ratio())
    }
    fn set_isa(&mut self, isa: Isa) {
        self.set_isa(isa);
    }
    fn check_restored(&self, fresh: &dyn crate::model::Model) -> std::result::Result<(), String> {
        self.check_restored(crate::model::same_solver(fresh)?)
    }
}
