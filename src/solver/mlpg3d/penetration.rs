//! Ballistic penetration by the 3-D MLPG mixed method (seed 004, section
//! 5.2): a cylindrical projectile striking a circular plate normally, both
//! on the ring lattice, in contact through [`crate::solver::mlpg3d::contact`], the plate
//! free at its rim.
//!
//! # The bodies
//!
//! The projectile (body 0, the rod of [`RodSetup`]) has `rings` rings
//! across its radius, spacing `Δ = R_p / rings`; the plate (body 1) has
//! `round(R_plate / Δ)` rings, so that both have the spacing `Δ` when the
//! radii are in a whole ratio (the seed's 5 and 40 mm are), and its rings
//! lie under the projectile's. The plate occupies `−h ≤ z ≤ 0`; the
//! projectile's face starts one contact reach above it (the nodes of the
//! two surfaces then just touch, [`crate::solver::mlpg3d::contact`]), moving at
//! `−impact_speed`. No anvil. The run ends at its end time.

use crate::approx::lattice::Cylinder;
use crate::error::Result;
use crate::material::Damage;
use crate::material::Material;
use crate::material::rajendran_grove::{CeramicVars, RajendranGrove};
use crate::observe::{FieldSpec, PENETRATION_OBSERVABLES};
use crate::solver::mlpg3d::failure::PlateNodes;
use crate::solver::mlpg3d::{Body, Energies, MLPG_FIELDS, Mlpg3d, RodSetup};

/// What a penetration run adds to its projectile's [`RodSetup`] (which
/// holds the projectile, its speed, the resolution and the end time): the
/// plate and how the run ends.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PenetrationSetup {
    /// The plate: its radius and thickness (m).
    pub plate: Cylinder,
    /// The run ends as soon as the shot's outcome is decided
    /// ([`Penetration::outcome`]), with `end_time` as its cap; false (the
    /// default): it runs to `end_time`.
    pub until_outcome: bool,
    /// The plate's rim is clamped (its outer ring of nodes held still,
    /// [`crate::solver::mlpg3d::Body::clamped_rim`]); false (the default,
    /// the seed's case): free.
    pub clamped_rim: bool,
    /// The order of the plate's nodes ([`crate::solver::mlpg3d::Body::node_order`]).
    pub node_order: crate::solver::mlpg3d::NodeOrder,
    /// The radius about the axis at which `radial_crack_count` counts the
    /// rear face's radial cracks (m); 0 (the default): the projectile's
    /// diameter, at most 0.8 of the plate's radius.
    pub radial_crack_radius: f64,
}

/// The JH-2 damage D at which a plate node counts as damaged: 1 % of the
/// full damage, as the Rajendran-Grove plate counts 1 % of the critical
/// crack density.
pub const JH2_DAMAGED: f64 = 0.01;

/// What a shot has come to ([`Penetration::outcome`]; the observable
/// `shot_outcome` is its number).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// 0: neither of the others yet.
    Undecided,
    /// 1: the projectile is through the plate and leaving it.
    Perforated,
    /// 2: the projectile moves no faster than the plate.
    Stopped,
}

/// A penetration run: the two-body MLPG run and what its observables need.
/// It saves its run's state alone (its setup follows from its scene).
#[derive(Debug, Clone)]
pub struct Penetration {
    setup: PenetrationSetup,
    run: Mlpg3d,
}

/// The run's state is all it saves.
impl serde::Serialize for Penetration {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        self.run.serialize(s)
    }
}

impl Penetration {
    /// The projectile of `projectile` material over the plate of `plate`
    /// material at the instant of impact; `numerics` is the projectile's
    /// rod (its cylinder, speed, rings and end time) with the solver's
    /// choices (damping, scheme, safety, rebuild strain).
    pub fn new(
        setup: PenetrationSetup,
        projectile: Material,
        plate: Material,
        numerics: RodSetup,
    ) -> Result<Self> {
        let rings = numerics.rings.max(1);
        let spacing = numerics.cylinder.radius / rings as f64;
        let plate_rings = ((setup.plate.radius / spacing).round() as usize).max(1);
        let reach = spacing.min(setup.plate.radius / plate_rings as f64);
        // Every choice of `numerics` (the weak form and the smoothing's
        // order too), on the projectile of `setup`.
        let rod = RodSetup {
            rings,
            base: reach,
            ..numerics
        };
        let plate_body = Body {
            cylinder: setup.plate,
            rings: plate_rings,
            base: -setup.plate.length,
            velocity: 0.0,
            material: plate,
            clamped_rim: setup.clamped_rim,
            node_order: setup.node_order,
        };
        let run = Mlpg3d::bodies(rod, projectile, vec![plate_body])?;
        Ok(Penetration { setup, run })
    }

    /// The two-body run.
    pub fn run(&self) -> &Mlpg3d {
        &self.run
    }

    /// Turns on or off the counting of each phase's serial time in the
    /// run's profile ([`Mlpg3d::count_serial`]).
    pub fn count_serial(&mut self, on: bool) {
        self.run.count_serial(on);
    }

    /// The setup.
    pub fn setup(&self) -> &PenetrationSetup {
        &self.setup
    }

    /// Simulated time (s).
    pub fn time(&self) -> f64 {
        self.run.time()
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.run.steps()
    }

    /// Nodes of both bodies.
    pub fn particles(&self) -> usize {
        self.run.particles()
    }

    /// Whether the end time is reached, or, with
    /// [`PenetrationSetup::until_outcome`], the outcome is decided.
    pub fn finished(&self) -> bool {
        self.run.finished() || (self.setup.until_outcome && self.outcome() != Outcome::Undecided)
    }

    /// The shot's outcome, decided by the state, not by the clock:
    ///
    /// - **perforated**: the projectile's highest node is below the plate's
    ///   original back face (`projectile_clearance > 0`) and its centre of
    ///   mass moves faster along the flight than the intact plate material
    ///   around the hole (the mass-weighted mean over the plate nodes not
    ///   pulverized within two node spacings of `hole_radius`): it is
    ///   leaving the plate;
    /// - **stopped**: not perforated, and the projectile's centre of mass
    ///   moves no faster along the flight than the plate's centre of mass
    ///   (or than 0, where the plate moves back): it no longer gains on the
    ///   plate. With a free rim and momentum conserved this is the capture
    ///   speed `m_p V / (m_p + m_plate)`, at which projectile and plate
    ///   move on together;
    /// - otherwise **undecided**.
    pub fn outcome(&self) -> Outcome {
        let v_p = self.projectile_velocity();
        let (x, v, m) = (
            self.run.positions(),
            self.run.velocities(),
            self.run.masses(),
        );
        if self.projectile_clearance() > 0.0 {
            let rod = self.run.setup();
            let spacing = rod.cylinder.radius / rod.rings as f64;
            let reach = self.hole_radius() + 2.0 * spacing;
            // The marks: `finished` asks at every step, where the damage
            // variables may be apart among the ranks.
            let marks = self.run.material_marks();
            let (mut p, mut total) = (0.0, 0.0);
            for i in self.nodes(1) {
                let intact = marks.get(i).is_none_or(|m| !m.is_comminuted());
                if intact && (x[i][0] * x[i][0] + x[i][1] * x[i][1]).sqrt() <= reach {
                    p -= m[i] * v[i][2];
                    total += m[i];
                }
            }
            let around = if total > 0.0 { p / total } else { 0.0 };
            if v_p > around {
                return Outcome::Perforated;
            }
        }
        let (mut p, mut total) = (0.0, 0.0);
        for i in self.nodes(1) {
            p -= m[i] * v[i][2];
            total += m[i];
        }
        if v_p <= (p / total).max(0.0) {
            Outcome::Stopped
        } else {
            Outcome::Undecided
        }
    }

    /// One step.
    pub fn step(&mut self) -> Result<()> {
        self.run.step()
    }

    /// The energies of both bodies.
    pub fn energies(&self) -> Energies {
        self.run.energies()
    }

    /// The nodes of body `b` (0: projectile, 1: plate).
    fn nodes(&self, b: u8) -> impl Iterator<Item = usize> + '_ {
        self.run
            .group()
            .iter()
            .enumerate()
            .filter(move |(_, g)| **g == b)
            .map(|(i, _)| i)
    }

    /// Axial velocity of the projectile's centre of mass, positive in its
    /// direction of flight (m/s).
    pub fn projectile_velocity(&self) -> f64 {
        let (m, v) = (self.run.masses(), self.run.velocities());
        let (mut p, mut total) = (0.0, 0.0);
        for i in self.nodes(0) {
            p += m[i] * v[i][2];
            total += m[i];
        }
        -p / total
    }

    /// Extent of the projectile along the axis (m).
    pub fn projectile_extent(&self) -> f64 {
        let x = self.run.positions();
        let (lo, hi) = self
            .nodes(0)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), i| {
                (lo.min(x[i][2]), hi.max(x[i][2]))
            });
        hi - lo
    }

    /// Depth of the projectile's highest node below the plate's original
    /// back face, `z = −plate_thickness` (m): positive once the whole
    /// projectile has passed that plane, negative while any of it is above.
    pub fn projectile_clearance(&self) -> f64 {
        let x = self.run.positions();
        let hi = self
            .nodes(0)
            .map(|i| x[i][2])
            .fold(f64::NEG_INFINITY, f64::max);
        -self.setup.plate.length - hi
    }

    /// The plate's ceramic, if it is one.
    fn ceramic(&self) -> Option<&RajendranGrove> {
        match &self.run.others()[0].material.damage {
            Damage::RajendranGrove(c) => Some(c),
            Damage::None | Damage::Jh2(_) => None,
        }
    }

    /// Whether the plate is of JH-2.
    fn jh2_plate(&self) -> bool {
        matches!(self.run.others()[0].material.damage, Damage::Jh2(_))
    }

    /// The damage at which a plate node counts as damaged: the ceramic's
    /// [`RajendranGrove::damaged_threshold`], JH-2's [`JH2_DAMAGED`],
    /// infinite for a plate without damage.
    fn damaged_threshold(&self) -> f64 {
        match &self.run.others()[0].material.damage {
            Damage::RajendranGrove(c) => c.damaged_threshold(),
            Damage::Jh2(_) => JH2_DAMAGED,
            Damage::None => f64::INFINITY,
        }
    }

    /// The damage of plate node `i` and whether it is comminuted: the
    /// crack density γ and pulverization of a Rajendran-Grove ceramic (the
    /// initial γ before its first step), JH-2's damage D and D = 1; zero
    /// for a plate without damage.
    fn node_damage(&self, i: usize) -> (f64, bool) {
        let point = self.run.material_points().get(i);
        if let Some(c) = self.ceramic() {
            return match point.and_then(|p| p.ceramic()) {
                Some(v) => (v.crack_density(c), v.pulverized.is_some()),
                None => (c.crack_density(c.initial_crack_size), false),
            };
        }
        match point.and_then(|p| p.jh2()) {
            Some(j) => (j.damage, j.damage >= 1.0),
            None => (0.0, false),
        }
    }

    /// Damage and comminution of each plate node ([`Penetration::node_damage`]),
    /// with its mass: `(γ or D, comminuted, mass)`.
    fn plate_damage(&self) -> Vec<(f64, bool, f64)> {
        let m = self.run.masses();
        self.nodes(1)
            .map(|i| {
                let (g, p) = self.node_damage(i);
                (g, p, m[i])
            })
            .collect()
    }

    /// The crack density across the hoop direction of each node of the
    /// plate, in the order of [`Penetration::nodes`]: what a radial crack
    /// reads ([`CeramicVars::crack_density_across`] at the node's place
    /// about the axis; its crack density on the axis, where no hoop
    /// direction is, and for a ceramic without tensile planes, whose
    /// cracks lie in every orientation).
    fn plate_radial_damage(&self) -> Vec<f64> {
        let points = self.run.material_points();
        let x = self.run.positions();
        let Some(c) = self.ceramic() else {
            // JH-2's damage has no orientation.
            return self.nodes(1).map(|i| self.node_damage(i).0).collect();
        };
        self.nodes(1)
            .map(|i| match points.get(i).and_then(|p| p.ceramic()) {
                Some(v) => Self::radial_density(c, v, x[i]),
                None => c.crack_density(c.initial_crack_size),
            })
            .collect()
    }

    /// [`Penetration::plate_radial_damage`] of one point at `x`.
    fn radial_density(c: &RajendranGrove, v: &CeramicVars, x: [f64; 3]) -> f64 {
        let r = x[0].hypot(x[1]);
        if r == 0.0 {
            v.crack_density(c)
        } else {
            v.crack_density_across(c, [-x[1] / r, x[0] / r, 0.0])
        }
    }

    /// A node field of a JH-2 plate: `f` of each plate node's JH-2 point
    /// (0 before its first step and at the projectile's nodes).
    fn jh2_field(
        &self,
        f: impl Fn(&crate::material::johnson_holmquist::Jh2Point) -> f64,
    ) -> Vec<f64> {
        let points = self.run.material_points();
        let group = self.run.group();
        (0..self.particles())
            .map(|i| match points.get(i).and_then(|p| p.jh2()) {
                Some(j) if group[i] == 1 => f(j),
                _ => 0.0,
            })
            .collect()
    }

    /// The normal of the point's split tensile plane of lowest index (plane
    /// 0 lies across the largest principal tension when the planes formed)
    /// in the cylindrical frame at `x`, `(n_r, |n_theta|, n_z)` with the
    /// sign that makes `n_z >= 0`; zero when no plane has split.
    fn split_normal(c: &RajendranGrove, v: &CeramicVars, x: [f64; 3]) -> [f64; 3] {
        let (Some(t), Some(planes)) = (v.tensile, c.crack_planes()) else {
            return [0.0; 3];
        };
        let split = planes.split_size();
        let Some(k) = (0..3).find(|&k| t.size[k] >= split) else {
            return [0.0; 3];
        };
        let n = t.normals[k];
        let r = x[0].hypot(x[1]);
        let (cos, sin) = if r > 0.0 {
            (x[0] / r, x[1] / r)
        } else {
            (1.0, 0.0)
        };
        let sign = if n[2] < 0.0 { -1.0 } else { 1.0 };
        [
            sign * (n[0] * cos + n[1] * sin),
            (n[1] * cos - n[0] * sin).abs(),
            sign * n[2],
        ]
    }

    /// Radius of the channel about the axis free of intact plate material
    /// within the plate's original thickness (m): the smallest distance
    /// from the axis of a plate node there that is not pulverized.
    pub fn hole_radius(&self) -> f64 {
        let x = self.run.positions();
        let h = self.setup.plate.length;
        let points = self.run.material_points();
        self.nodes(1)
            .filter(|&i| x[i][2] >= -h && x[i][2] <= 0.0)
            .filter(|&i| points.get(i).is_none_or(|p| !p.is_comminuted()))
            .map(|i| (x[i][0] * x[i][0] + x[i][1] * x[i][1]).sqrt())
            .fold(f64::INFINITY, f64::min)
            .min(self.setup.plate.radius)
    }

    /// `(damaged_fraction, pulverized_fraction, max_damage)` of the plate.
    pub fn damage(&self) -> (f64, f64, f64) {
        let threshold = self.damaged_threshold();
        let (mut damaged, mut pulverized, mut total, mut max) = (0.0, 0.0, 0.0, 0.0f64);
        for (g, p, m) in self.plate_damage() {
            total += m;
            if g >= threshold {
                damaged += m;
            }
            if p {
                pulverized += m;
            }
            max = max.max(g);
        }
        (damaged / total, pulverized / total, max)
    }

    /// The plate's failure modes ([`super::failure`]):
    /// `(cone_half_angle, radial_crack_count, comminuted_radius)`; zeros
    /// for a plate without damage. The radial cracks are counted at
    /// [`PenetrationSetup::radial_crack_radius`], by default at the
    /// projectile's diameter from the axis (at most 0.8 of the plate's
    /// radius).
    pub fn failure_modes(&self) -> (f64, f64, f64) {
        if self.ceramic().is_none() && !self.jh2_plate() {
            return (0.0, 0.0, 0.0);
        }
        let at = self.run.reference();
        let plate: Vec<usize> = self.nodes(1).collect();
        let reference: Vec<[f64; 3]> = plate.iter().map(|&i| at[i]).collect();
        let (gamma, mut pulverized): (Vec<f64>, Vec<bool>) =
            self.plate_damage().iter().map(|&(g, p, _)| (g, p)).unzip();
        // A node split on all three tensile planes is comminuted too.
        let points = self.run.material_points();
        if let Some(c) = self.ceramic() {
            for (k, i) in plate.iter().enumerate() {
                if let Some(v) = points.get(*i).and_then(|p| p.ceramic()) {
                    pulverized[k] |= v.split_planes(c) == 3;
                }
            }
        }
        let radial = self.plate_radial_damage();
        let rod = self.run.setup();
        let nodes = PlateNodes {
            reference: &reference,
            gamma: &gamma,
            radial: &radial,
            pulverized: &pulverized,
            damaged: self.damaged_threshold(),
            thickness: self.setup.plate.length,
            spacing: rod.cylinder.radius / rod.rings as f64,
            quarter: rod.quarter,
        };
        let radius = if self.setup.radial_crack_radius > 0.0 {
            self.setup.radial_crack_radius
        } else {
            (2.0 * rod.cylinder.radius).min(0.8 * self.setup.plate.radius)
        };
        (
            nodes.cone_half_angle(),
            nodes.radial_crack_count(radius),
            nodes.comminuted_radius(),
        )
    }

    /// Current values of [`PENETRATION_OBSERVABLES`], in that order.
    pub fn observables(&self) -> Vec<f64> {
        let e = self.energies();
        let (damaged, pulverized, max) = self.damage();
        let (cone, cracks, comminuted) = self.failure_modes();
        let values = vec![
            self.projectile_velocity(),
            self.projectile_extent(),
            self.projectile_clearance(),
            self.hole_radius(),
            damaged,
            pulverized,
            max,
            e.kinetic,
            e.internal,
            e.contact,
            e.smoothing,
            e.error,
            self.outcome() as u8 as f64,
            cone,
            cracks,
            comminuted,
        ];
        debug_assert_eq!(values.len(), PENETRATION_OBSERVABLES.len());
        values
    }

    /// The node field `name` (one of [`PENETRATION_FIELDS`]).
    pub fn field(&self, name: &str) -> Option<Vec<f64>> {
        let n = self.particles();
        let damage = || {
            let points = self.run.material_points();
            let c = self.ceramic();
            (0..n).map(move |i| {
                let vars = points.get(i).and_then(|p| p.ceramic());
                (c, vars, self.run.group()[i])
            })
        };
        Some(match name {
            "body" => self.run.group().iter().map(|&g| g as f64).collect(),
            "mass" => self.run.masses().to_vec(),
            "damage" if self.jh2_plate() => self.jh2_field(|j| j.damage),
            "damage" => damage()
                .map(|(c, v, g)| match (c, v) {
                    (Some(c), Some(v)) if g == 1 => v.crack_density(c),
                    _ => 0.0,
                })
                .collect(),
            "log10_damage" if self.jh2_plate() => {
                self.jh2_field(|j| j.damage.log10().max(crate::observe::LOG10_NO_CRACKS))
            }
            "radial_damage" if self.jh2_plate() => self.jh2_field(|j| j.damage),
            "pulverized" if self.jh2_plate() => {
                self.jh2_field(|j| f64::from(u8::from(j.damage >= 1.0)))
            }
            "log10_damage" => damage()
                .map(|(c, v, g)| match (c, v) {
                    (Some(c), Some(v)) if g == 1 => v
                        .crack_density(c)
                        .log10()
                        .max(crate::observe::LOG10_NO_CRACKS),
                    _ => crate::observe::LOG10_NO_CRACKS,
                })
                .collect(),
            "radial_damage" => damage()
                .zip(self.run.positions())
                .map(|((c, v, g), x)| match (c, v) {
                    (Some(c), Some(v)) if g == 1 => Self::radial_density(c, v, *x),
                    _ => 0.0,
                })
                .collect(),
            "split_planes" => damage()
                .map(|(c, v, g)| match (c, v) {
                    (Some(c), Some(v)) if g == 1 => v.split_planes(c) as f64,
                    _ => 0.0,
                })
                .collect(),
            "split_normal" => damage()
                .zip(self.run.positions())
                .flat_map(|((c, v, g), x)| match (c, v) {
                    (Some(c), Some(v)) if g == 1 => Self::split_normal(c, v, *x),
                    _ => [0.0; 3],
                })
                .collect(),
            "crack_size" => damage()
                .map(|(_, v, g)| match v {
                    Some(v) if g == 1 => v.crack_size,
                    _ => 0.0,
                })
                .collect(),
            "pulverized" => damage()
                .map(|(_, v, _)| v.is_some_and(|v| v.pulverized.is_some()) as u8 as f64)
                .collect(),
            "porosity" => damage()
                .map(|(_, v, _)| v.map_or(0.0, |v| v.porosity))
                .collect(),
            "place_at_impact" => self.run.reference().iter().flatten().copied().collect(),
            _ => return self.run.field(name),
        })
    }
}

/// The node fields of a penetration run: those of the 3-D solver, then the
/// body of each node (0 projectile, 1 plate), the crack density γ, the
/// pulverized flag, the porosity, the node mass, and, so that partial
/// damage shows, log10 γ (floored at [`crate::LOG10_NO_CRACKS`],
/// its value at the projectile's nodes), the crack radius a (m; 0 at
/// the projectile's nodes), and the place at impact of the material each
/// node is on (m; the plate's rear face is the nodes whose `z0` is the
/// plate's `-thickness`), and the crack density across the hoop direction,
/// that of a radial crack (the crack density where the cracks lie in every
/// orientation; 0 at the projectile's nodes), and the number of tensile
/// planes split at each node (0 to 3; 0 without planes and at the
/// projectile's nodes) with the normal of its first split plane in the
/// cylindrical frame (`(n_r, |n_theta|, n_z)`, `n_z >= 0`; zero where none
/// has split).
pub const PENETRATION_FIELDS: &[FieldSpec] = &{
    const fn scalar(
        name: &'static str,
        unit: &'static str,
        component: &'static [&'static str],
    ) -> FieldSpec {
        FieldSpec {
            name,
            unit,
            components: component,
        }
    }
    let own = [
        scalar("body", "1", &["body"]),
        scalar("damage", "1", &["gamma"]),
        scalar("pulverized", "bool", &["pulverized"]),
        scalar("porosity", "1", &["f"]),
        scalar("mass", "kg", &["m"]),
        scalar("log10_damage", "1", &["log10_gamma"]),
        scalar("crack_size", "m", &["a"]),
        scalar("place_at_impact", "m", &["x0", "y0", "z0"]),
        scalar("radial_damage", "1", &["gamma_hoop"]),
        scalar("split_planes", "1", &["split_planes"]),
        scalar("split_normal", "1", &["nr", "nt", "nz"]),
    ];
    let mut out = [own[0]; MLPG_FIELDS.len() + 11];
    let mut i = 0;
    while i < out.len() {
        out[i] = if i < MLPG_FIELDS.len() {
            MLPG_FIELDS[i]
        } else {
            own[i - MLPG_FIELDS.len()]
        };
        i += 1;
    }
    out
};

impl crate::model::Model for Penetration {
    crate::model::inherent_basics!();
    fn field_specs(&self) -> &'static [FieldSpec] {
        PENETRATION_FIELDS
    }
    /// 40 records over the run.
    fn record_interval(&self) -> f64 {
        self.run.setup().end_time / 40.0
    }
    fn min_spacing_ratio(&self) -> Option<f64> {
        Some(self.run.min_spacing_ratio())
    }
    fn phase_table(&self) -> Option<String> {
        Some(self.run.profile().table())
    }
    fn load_state(
        &mut self,
        saved: crate::model::SavedSolver<'_>,
    ) -> std::result::Result<(), String> {
        self.run.load_state(saved)
    }
    fn check_restored(&self, fresh: &dyn crate::model::Model) -> std::result::Result<(), String> {
        let fresh: &Penetration = crate::model::same_solver(fresh)?;
        self.run.check_restored(&fresh.run)
    }
    fn set_isa(&mut self, isa: crate::isa::Isa) {
        self.run.set_isa(isa);
    }
    fn set_ranks(&mut self, ranks: crate::ranks::Handle) -> std::result::Result<(), String> {
        self.run.set_ranks(ranks);
        Ok(())
    }
    fn share(&mut self) {
        self.run.share();
    }
    fn share_observed(&mut self) {
        self.run.share_observed();
    }
}
