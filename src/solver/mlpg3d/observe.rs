//! What a run reports: its clock and fields, the energies, the rod's
//! observables, the node fields, the memory by part, and the [`crate::model::Model`]
//! seam.

use super::LOST_CONTACT;
use super::LOST_DAMPING;
use super::LOST_SMOOTHING;
use super::profile::PhaseTimes;
use super::util::kinetic;
use crate::FieldSpec;
use crate::Isa;
use crate::approx::lattice::NodeLattice;
use crate::approx::lattice::Surfaces;
use crate::material::tensor::Full;
use crate::materials::Material;
use crate::rod::RodObservables;
use crate::rod::radius;
use crate::solver::mlpg3d::Body;
use crate::solver::mlpg3d::Mlpg3d;
use crate::solver::mlpg3d::RodSetup;
use crate::solver::mlpg3d::TAYLOR3D_OBSERVABLES;
use crate::solver::shared::SolidNodes;

impl Mlpg3d {
    /// Number of nodes.
    pub fn particles(&self) -> usize {
        self.state.pos.len()
    }

    crate::solver::shared::clock_getters!(state.clock; dt);

    /// Builds of the operator so far (the first included).
    pub fn rebuilds(&self) -> u64 {
        self.state.rebuilds
    }

    /// The reference lattice.
    pub fn lattice(&self) -> &NodeLattice {
        &self.setup.lattice
    }

    /// Node positions (m).
    pub fn positions(&self) -> &[[f64; 3]] {
        &self.state.pos
    }

    /// The place at impact of the material each node is on (m), carried
    /// along when a node shifts.
    pub fn reference(&self) -> &[[f64; 3]] {
        &self.state.reference
    }

    /// Node velocities (m/s).
    pub fn velocities(&self) -> &[[f64; 3]] {
        &self.state.vel
    }

    /// Node masses (kg).
    pub fn masses(&self) -> &[f64] {
        &self.setup.mass
    }

    /// Whether each node is pressed on the anvil.
    pub fn in_contact(&self) -> &[bool] {
        &self.state.contact
    }

    /// Time of the last release of a node from the anvil (s): where the
    /// node's net axial force, linear between the last step it was held
    /// (pushed by the anvil) and the step it lets go (pulled away), crosses
    /// zero; the node leaves the anvil in that step.
    pub fn last_release(&self) -> f64 {
        self.state.last_release
    }

    /// Whether the end condition holds: the rod is at rest or has left the
    /// anvil, or `end_time` has been reached.
    pub fn finished(&self) -> bool {
        self.state.at_rest || self.state.clock.time >= self.setup.rod.end_time
    }

    /// Smallest distance between named neighbours relative to the initial
    /// smallest, over the run so far.
    pub fn min_spacing_ratio(&self) -> f64 {
        self.state.min_spacing
    }

    /// The energies: kinetic, internal (stress work), plastic work, damping
    /// and contact dissipation, and the relative energy error; the whole
    /// body's in the quarter model (four times the quarter's).
    pub fn energies(&self) -> Energies {
        let kinetic = kinetic(&self.state.vel, &self.setup.mass);
        let k = self.multiplicity();
        Energies {
            initial: k * self.state.energy.initial,
            kinetic: k * kinetic,
            internal: k * self.state.energy.internal,
            plastic_work: k * self.state.plastic_work,
            damping: k * self.state.energy.lost[LOST_DAMPING],
            contact: k * self.state.energy.lost[LOST_CONTACT],
            smoothing: k * self.state.energy.lost[LOST_SMOOTHING],
            error: self.state.energy.error(kinetic),
        }
    }

    /// The part of the smoothing dissipation ([`Energies::smoothing`]) that
    /// node shifting booked over the run so far (J; the whole body's in the
    /// quarter model): the kinetic energy that carrying the moved nodes'
    /// velocities changed.
    pub fn shift_dissipation(&self) -> f64 {
        self.multiplicity() * self.state.shift_dissipation
    }

    /// How many copies of the modelled part make the body: 4 in the quarter
    /// model, else 1.
    pub fn multiplicity(&self) -> f64 {
        if self.setup.plane.is_empty() {
            1.0
        } else {
            4.0
        }
    }

    /// The symmetry planes each node lies on in the quarter model (bits
    /// `X`, `Y` of `src/approx/mirror.rs`); empty for the whole body.
    pub fn planes(&self) -> &[u8] {
        &self.setup.plane
    }

    /// Runs the hot loops in the compiled copy `isa` from now on (by
    /// default the best this processor runs); every copy gives the same
    /// bits.
    pub fn set_isa(&mut self, isa: Isa) {
        self.pipe.isa = isa;
    }

    /// Shares the passes over the nodes among `ranks` ([`crate::ranks`]):
    /// the same bits on any number of ranks.
    pub fn set_ranks(&mut self, ranks: crate::ranks::Handle) {
        self.pipe.ranks = ranks;
        self.pipe.halo.forget();
        // Shapes built apart hold the rows of the old ranks' passes: the
        // next step builds them again from the state's record of the last
        // build (as a restored run does: the same bits).
        if self.pipe.geometry.as_ref().is_some_and(|g| g.held.apart()) {
            self.pipe.geometry = None;
        }
        // The nodal operator built before holds the columns of the ranks
        // it was built for; each rank now holds its share of them.
        if let Some(g) = self.pipe.geometry.as_mut() {
            // So do the shapes' rows.
            let rows = g.shapes.offsets.len().saturating_sub(1);
            g.rows = super::geometry::row_parts(&*self.pipe.ranks, &g.shapes, rows);
            if !g.nodal.offsets.is_empty() {
                let columns = g.nodal.columns;
                g.nodal.rebuild_on(&*self.pipe.ranks, &g.shapes, columns);
            }
            // The lists of the smoothing's first pass were made for the
            // old rows (none on one rank): until the next build, whole
            // gathers. (Making them here would be a collective call, which
            // a rank that fails at its start never makes: measured, the
            // other rank waited for it.)
            g.pass_send.clear();
        }
    }

    /// The heap bytes the run holds, by part (capacities, not lengths):
    /// node fields (with the reference lattice and the material state),
    /// the step's buffers, the supports, the shapes at the nodes, the test
    /// spheres and the traction operator. BENCHMARKS.md, "3-D MLPG speed".
    pub fn memory(&self) -> [(&'static str, usize); 6] {
        fn b<T>(v: &Vec<T>) -> usize {
            v.capacity() * std::mem::size_of::<T>()
        }
        let l = &self.setup.lattice;
        let fields = b(&self.state.pos)
            + b(&self.state.vel)
            + b(&self.setup.mass)
            + b(&self.state.rho)
            + b(&self.state.dev)
            + b(&self.state.pressure)
            + b(&self.state.eps_p)
            + b(&self.state.temp)
            + b(&self.state.visc)
            + b(&self.state.contact)
            + b(&self.state.supports_at)
            + b(&self.state.built_at)
            + b(&self.state.reference)
            + b(&self.state.built_reference)
            + b(&self.state.built_contact)
            + b(&self.state.built_rho)
            + b(&self.state.built_multipliers)
            + b(&self.state.reaction)
            + b(&l.position)
            + b(&l.volume)
            + b(&l.surfaces)
            + b(&l.sets.face)
            + b(&l.sets.mantle)
            + self.particles() * std::mem::size_of::<crate::material::PointState>();
        let scratch = self.pipe.scratch.bytes();
        let (mut supports, mut shapes, mut spheres, mut op) = (0, 0, 0, 0);
        if let Some(g) = &self.pipe.geometry {
            if let Some(s) = &g.supports {
                supports =
                    b(&s.radius) + b(&s.named.offsets) + b(&s.named.indices) + b(&s.named_distance);
            }
            let h = &g.shapes;
            shapes = b(&h.offsets) + b(&h.nodes) + b(&h.phi) + b(&h.grad) + b(&g.multipliers);
            spheres = b(&g.spheres);
            let o = &g.op;
            op = b(&o.offsets) + b(&o.nodes) + b(&o.b) + b(&o.volume) + g.nodal.bytes();
        }
        [
            ("node fields", fields),
            ("step buffers", scratch),
            ("supports", supports),
            ("shapes at the nodes", shapes),
            ("test spheres", spheres),
            ("traction operator (or the nodal one)", op),
        ]
    }

    /// Wall time per phase of the steps taken in this process (a restored
    /// run starts from zero), and the counts of the builds.
    pub fn profile(&self) -> &PhaseTimes {
        &self.pipe.profile
    }

    /// Turns on or off the counting of each phase's serial time in
    /// [`Mlpg3d::profile`] ([`PhaseTimes::count_serial`]).
    pub fn count_serial(&mut self, on: bool) {
        self.pipe.profile.count_serial(on);
    }

    /// The rod observables of the current state.
    pub fn rod(&self) -> RodObservables {
        RodObservables::of::<3>(
            &self.setup.lattice.sets,
            &self.state.pos,
            &self.state.vel,
            self.setup.rod.cylinder.radius,
        )
    }

    /// The distances from the axis of the face's outer ring (the nodes on
    /// both the face and the mantle), in node order.
    fn ring_radii(&self) -> impl Iterator<Item = f64> + '_ {
        self.setup
            .lattice
            .sets
            .face
            .iter()
            .filter(|&&i| self.setup.lattice.surfaces[i].has(Surfaces::MANTLE))
            .map(|&i| radius(&self.state.pos[i]))
    }

    /// `(max − min) / mean` of the distance from the axis of the face's
    /// outer ring (the nodes on both the face and the mantle).
    pub fn mushroom_radius_spread(&self) -> f64 {
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for r in self.ring_radii() {
            lo = lo.min(r);
            hi = hi.max(r);
        }
        (hi - lo) / self.ring_radius()
    }

    /// The mean distance from the axis of the face's outer ring (m): the
    /// face radius that an axisymmetric solver measures (its ring is one
    /// particle), where `mushroom_radius`, the largest over the face, adds
    /// the ring's scatter by azimuth (the Wilkins bar at 11 across: 7.296
    /// mm against 7.353 mm, VALIDATION.md).
    pub fn ring_radius(&self) -> f64 {
        let (sum, k) = self
            .ring_radii()
            .fold((0.0, 0usize), |(s, k), r| (s + r, k + 1));
        sum / k as f64
    }

    /// Height of the centre of the impact face above the anvil (m).
    pub fn face_lift(&self) -> f64 {
        self.state.pos[0][2]
    }

    /// Largest effective plastic strain.
    pub fn max_plastic_strain(&self) -> f64 {
        self.state.eps_p.iter().copied().fold(0.0, f64::max)
    }

    /// Highest temperature (K).
    pub fn max_temperature(&self) -> f64 {
        self.state
            .temp
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Whether the rod has stopped or left the anvil.
    pub fn at_rest(&self) -> bool {
        self.state.at_rest
    }

    /// The node stresses `σ = S − p I` (Pa), `[xx, yy, zz, xy, yz, zx]`.
    pub fn stress(&self) -> Vec<Full> {
        self.state
            .dev
            .iter()
            .zip(&self.state.pressure)
            .map(|(d, p)| [d[0] - p, d[1] - p, d[2] - p, d[3], d[4], d[5]])
            .collect()
    }

    /// Density (kg/m³), pressure (Pa), plastic strain and temperature (K)
    /// of every node.
    pub fn scalars(&self) -> (&[f64], &[f64], &[f64], &[f64]) {
        (
            &self.state.rho,
            &self.state.pressure,
            &self.state.eps_p,
            &self.state.temp,
        )
    }

    /// The setup of this run.
    pub fn setup(&self) -> &RodSetup {
        &self.setup.rod
    }

    /// The material of the rod.
    pub fn material(&self) -> &Material {
        &self.setup.material
    }

    /// The bodies after the rod (none for a Taylor run).
    pub fn others(&self) -> &[Body] {
        &self.setup.others
    }

    /// The body of each node (0: the rod); empty for a run of one body.
    pub fn group(&self) -> &[u8] {
        &self.setup.group
    }

    /// The material state of each node (its damage variables; empty before
    /// the first step).
    pub fn material_points(&self) -> &[crate::material::PointState] {
        self.state.material_state.points()
    }

    /// The marks of each node's damage variables (empty before the first
    /// step): current on every rank after every step, where the variables
    /// themselves are whole only after [`Mlpg3d::share`].
    pub fn material_marks(&self) -> &[crate::material::Marks] {
        self.state.material_state.marks()
    }

    /// Makes every node's damage variables whole on every rank, where the
    /// ranks keep them apart between steps (each current on its own part):
    /// a collective call, made by every rank at the same point of a run
    /// before anything reads them ([`crate::material::MaterialState::share`]).
    pub fn share(&mut self) {
        let (ranks, wire) = (&*self.pipe.ranks, &mut self.pipe.balance.wire);
        self.state.material_state.share(ranks, wire);
        // So are the material fields, which each rank holds between steps
        // only where it reads them ([`super::halo`]).
        let n = self.state.pos.len();
        let parts = self.pipe.balance.parts(ranks, n).to_vec();
        self.pipe
            .halo
            .make_whole(ranks, &parts, super::halo::HaloFields::of(&mut self.state));
    }

    /// [`Mlpg3d::share`] for a record of the observables: the damage
    /// variables, and of the material fields only the plastic strain and
    /// the temperature, whose largest values the observables read (the
    /// rest stay apart until the next [`Mlpg3d::share`]).
    pub fn share_observed(&mut self) {
        let (ranks, wire) = (&*self.pipe.ranks, &mut self.pipe.balance.wire);
        self.state.material_state.share(ranks, wire);
        let n = self.state.pos.len();
        let parts = self.pipe.balance.parts(ranks, n).to_vec();
        self.pipe.halo.make_some_whole(
            ranks,
            &parts,
            &mut [&mut self.state.eps_p, &mut self.state.temp],
        );
    }

    /// The contact reach between the bodies (m; [`contact`]).
    pub fn contact_reach(&self) -> f64 {
        self.setup.reach
    }
}

/// The energies of a run (J) and its relative energy error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Energies {
    /// Kinetic energy at impact.
    pub initial: f64,
    /// Kinetic energy now.
    pub kinetic: f64,
    /// Stress work of the material (elastic plus plastic).
    pub internal: f64,
    /// The plastic part of `internal` (flow stress times plastic strain).
    pub plastic_work: f64,
    /// Work of the damping's viscous stress.
    pub damping: f64,
    /// Kinetic energy removed by the anvil when it stops nodes.
    pub contact: f64,
    /// Kinetic energy removed by the velocity smoothing.
    pub smoothing: f64,
    /// `|kinetic + internal + damping + contact + smoothing − initial| / initial`.
    pub error: f64,
}

/// The node fields of the 3-D solver.
pub const MLPG_FIELDS: &[FieldSpec] =
    &crate::observe::rod_fields(&["x", "y", "z"], &["xx", "yy", "zz", "xy", "yz", "zx"]);

impl Mlpg3d {
    /// Current values of [`TAYLOR3D_OBSERVABLES`], in that order.
    pub fn observables(&self) -> Vec<f64> {
        let rod = self.rod();
        let e = self.energies();
        let values = [
            rod.rod_length,
            rod.mushroom_radius,
            rod.undeformed_length,
            rod.tail_velocity,
            self.face_lift(),
            self.max_plastic_strain(),
            self.max_temperature(),
            e.kinetic,
            e.internal,
            e.smoothing,
            e.contact,
            e.error,
            if self.state.at_rest { 1.0 } else { 0.0 },
            self.mushroom_radius_spread(),
            e.damping,
            e.plastic_work,
        ];
        debug_assert_eq!(values.len(), TAYLOR3D_OBSERVABLES.len());
        values.to_vec()
    }

    /// The values of the node field `name` (one of [`MLPG_FIELDS`]),
    /// interleaved per node.
    pub fn field(&self, name: &str) -> Option<Vec<f64>> {
        SolidNodes {
            pos: &self.state.pos,
            vel: &self.state.vel,
            rho: &self.state.rho,
            pressure: &self.state.pressure,
            eps_p: &self.state.eps_p,
            temp: &self.state.temp,
            contact: &self.state.contact,
        }
        .field(name, || self.stress().into_iter().flatten().collect())
    }
}

impl crate::model::Model for Mlpg3d {
    crate::model::inherent_basics!();
    fn field_specs(&self) -> &'static [FieldSpec] {
        MLPG_FIELDS
    }
    /// 64 records per elastic transit of the rod.
    fn record_interval(&self) -> f64 {
        self.setup.rod.cylinder.length / self.wave_speed() / 64.0
    }
    fn rod_profile(&self) -> Option<Vec<[f64; 2]>> {
        Some(crate::rod::profile(
            &self.setup.lattice.sets.mantle,
            &self.state.pos,
        ))
    }
    fn min_spacing_ratio(&self) -> Option<f64> {
        Some(self.min_spacing_ratio())
    }
    fn phase_table(&self) -> Option<String> {
        Some(self.profile().table())
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
    fn set_isa(&mut self, isa: Isa) {
        self.set_isa(isa);
    }
    fn set_ranks(&mut self, ranks: crate::ranks::Handle) -> std::result::Result<(), String> {
        self.set_ranks(ranks);
        Ok(())
    }
    fn share(&mut self) {
        self.share();
    }
    fn share_observed(&mut self) {
        self.share_observed();
    }
}
