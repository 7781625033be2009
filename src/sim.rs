//! [`Simulation`]: one run of one scene. The CLI, the C ABI and the FMU are
//! thin layers over this type. It holds no global state: separate instances
//! run in parallel, and the result of a run does not depend on the number of
//! threads.

use crate::error::{Error, Result};
use crate::isa::Isa;
use crate::model::{Model, SavedSolver};
use crate::observe::{FieldSpec, History, ObservableSpec, Snapshot};
use crate::scene::{Scene, SceneKind};
use std::sync::OnceLock;

/// Progress of a run, passed to the callback of [`Simulation::run_with`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Simulated time.
    pub time: f64,
    /// Latest time the run may reach (the scene's `end_time`).
    pub end_time: f64,
    /// Steps taken.
    pub steps: u64,
}

/// One run of one scene.
#[derive(Debug)]
pub struct Simulation {
    scene: Scene,
    solver: Box<dyn Model>,
    history: History,
    record_interval: f64,
    next_record: f64,
    error: Option<Error>,
    observed: Observed,
}

/// The observables of the current step, each computed when first read and
/// kept until the next step: a host that reads every output after every
/// communication step costs one evaluation of each (none after a step that
/// recorded the histories), and a read of one computes that one.
#[derive(Debug, Clone)]
struct Observed(Vec<OnceLock<f64>>);

impl Observed {
    /// Nothing computed yet, for a scene of `kind`.
    fn new(kind: SceneKind) -> Self {
        Observed(vec![OnceLock::new(); kind.observable_specs().len()])
    }

    /// Forgets every value (the run has stepped).
    fn clear(&mut self) {
        for cell in &mut self.0 {
            cell.take();
        }
    }
}

impl Clone for Simulation {
    fn clone(&self) -> Self {
        Simulation {
            scene: self.scene.clone(),
            solver: self.solver.boxed_clone(),
            history: self.history.clone(),
            record_interval: self.record_interval,
            next_record: self.next_record,
            error: self.error.clone(),
            observed: self.observed.clone(),
        }
    }
}

/// A [`Simulation`] as saved: the solver's state under its kind's key, as
/// the scene's parameters are (`{"Taylor": {...}}`). A stopped run's error
/// is not part of the state. The same shape in every serde format: JSON for
/// [`Simulation::serialize_state`], postcard inside the FMU state.
#[derive(serde::Serialize)]
struct SavedRef<'a> {
    /// [`crate::state_format::FORMAT`].
    format: u32,
    scene: &'a Scene,
    solver: SolverRef<'a>,
    history: &'a History,
    record_interval: f64,
    next_record: f64,
}

/// [`SavedRef`] read back.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Saved {
    format: u32,
    scene: Scene,
    solver: SolverState,
    history: History,
    record_interval: f64,
    next_record: f64,
}

/// A solver's state as a map of one entry, under its kind's key.
struct SolverRef<'a>(SceneKind, &'a dyn Model);

impl serde::Serialize for SolverRef<'_> {
    fn serialize<S: serde::Serializer>(
        &self,
        serializer: S,
    ) -> std::result::Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap as _;
        let human = serializer.is_human_readable();
        let mut map = serializer.serialize_map(Some(1))?;
        if human {
            map.serialize_entry(&self.0.saved_key(), self.1.save())?;
        } else {
            // A binary format (postcard, the FMU state): the solver's own
            // postcard bytes, encoded by its type.
            map.serialize_entry(&self.0.saved_key(), &Bytes(&self.1.save_compact()))?;
        }
        map.end()
    }
}

/// Bytes serialized as one byte string.
struct Bytes<'a>(&'a [u8]);

impl serde::Serialize for Bytes<'_> {
    fn serialize<S: serde::Serializer>(
        &self,
        serializer: S,
    ) -> std::result::Result<S::Ok, S::Error> {
        serializer.serialize_bytes(self.0)
    }
}

/// [`SolverRef`] read back: the kind its key names and its saved state,
/// not yet read (it is loaded into a new run of the scene,
/// [`Model::load_state`]).
struct SolverState(SceneKind, RawSolver);

/// A solver's saved state as it came: a JSON tree, or postcard bytes.
enum RawSolver {
    Json(serde_json::Value),
    Postcard(Vec<u8>),
}

/// Why a solver state is refused when its key does not name one kind.
const NOT_THE_SCENES: &str = "its solver is not its scene's";

impl<'de> serde::Deserialize<'de> for SolverState {
    fn deserialize<D: serde::Deserializer<'de>>(
        deserializer: D,
    ) -> std::result::Result<Self, D::Error> {
        deserializer.deserialize_map(SolverVisitor)
    }
}

/// Reads the one entry of a [`SolverRef`] map.
struct SolverVisitor;

impl<'de> serde::de::Visitor<'de> for SolverVisitor {
    type Value = SolverState;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a solver state under its scene kind's key")
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(
        self,
        mut map: A,
    ) -> std::result::Result<SolverState, A::Error> {
        use serde::de::Error as _;
        let kind = map
            .next_key::<String>()?
            .and_then(|key| SceneKind::with_saved_key(&key))
            .ok_or_else(|| A::Error::custom(NOT_THE_SCENES))?;
        let raw = map.next_value_seed(Raw)?;
        if map.next_key::<serde::de::IgnoredAny>()?.is_some() {
            return Err(A::Error::custom(NOT_THE_SCENES));
        }
        Ok(SolverState(kind, raw))
    }
}

/// Reads a solver's state as it came, in either format.
struct Raw;

impl<'de> serde::de::DeserializeSeed<'de> for Raw {
    type Value = RawSolver;

    fn deserialize<D: serde::Deserializer<'de>>(
        self,
        deserializer: D,
    ) -> std::result::Result<RawSolver, D::Error> {
        use serde::Deserialize as _;
        if deserializer.is_human_readable() {
            serde_json::Value::deserialize(deserializer).map(RawSolver::Json)
        } else {
            deserializer.deserialize_bytes(self)
        }
    }
}

/// The solver's postcard bytes inside a binary format.
impl<'de> serde::de::Visitor<'de> for Raw {
    type Value = RawSolver;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("the bytes of a solver state")
    }

    fn visit_bytes<E: serde::de::Error>(self, bytes: &[u8]) -> std::result::Result<RawSolver, E> {
        Ok(RawSolver::Postcard(bytes.to_vec()))
    }
}

impl RawSolver {
    /// Loads the state into `solver`, a new run of its scene.
    fn load_into(self, solver: &mut dyn Model) -> std::result::Result<(), String> {
        match self {
            RawSolver::Json(value) => solver.load_state(SavedSolver::Json(value)),
            RawSolver::Postcard(bytes) => solver.load_state(SavedSolver::Postcard(&bytes)),
        }
    }
}

impl serde::Serialize for Simulation {
    fn serialize<S: serde::Serializer>(
        &self,
        serializer: S,
    ) -> std::result::Result<S::Ok, S::Error> {
        SavedRef {
            format: crate::state_format::FORMAT,
            scene: &self.scene,
            solver: SolverRef(self.scene.kind(), self.solver.as_ref()),
            history: &self.history,
            record_interval: self.record_interval,
            next_record: self.next_record,
        }
        .serialize(serializer)
    }
}

/// The run as saved: a new run of its scene with the saved solver state
/// loaded into it ([`Model::load_state`]), not yet checked:
/// [`Simulation::deserialize_state`] checks it ([`Simulation::check_restored`]),
/// and so must every other reader.
impl<'de> serde::Deserialize<'de> for Simulation {
    fn deserialize<D: serde::Deserializer<'de>>(
        deserializer: D,
    ) -> std::result::Result<Self, D::Error> {
        use serde::de::Error as _;
        let saved = Saved::deserialize(deserializer)?;
        if saved.format != crate::state_format::FORMAT {
            return Err(D::Error::custom(format!(
                "its format {} is not this build's {} (a state of an older format is read by \
                 Simulation::deserialize_state)",
                saved.format,
                crate::state_format::FORMAT
            )));
        }
        let SolverState(solver_kind, raw) = saved.solver;
        // The key names the row; the material choice is the scene's.
        if solver_kind.saved_key() != saved.scene.kind().saved_key() {
            return Err(D::Error::custom(NOT_THE_SCENES));
        }
        // A new run of the scene, and the saved state loaded into it.
        let mut sim = Simulation::new(saved.scene)
            .map_err(|e| D::Error::custom(format!("the state is not valid: its scene: {e}")))?;
        raw.load_into(sim.solver.as_mut())
            .map_err(D::Error::custom)?;
        // The new run's observables were read at its start.
        sim.observed.clear();
        sim.history = saved.history;
        sim.record_interval = saved.record_interval;
        sim.next_record = saved.next_record;
        Ok(sim)
    }
}

impl Simulation {
    /// Validates the scene and sets up the initial state.
    pub fn new(scene: Scene) -> Result<Self> {
        scene.validate()?;
        let solver = (scene.kind().row().build)(&scene)?;
        let record_interval = solver.record_interval();
        crate::solver::shared::check_derived("record interval", record_interval, "")?;
        let mut sim = Simulation {
            history: History::new(scene.kind().observable_specs()),
            observed: Observed::new(scene.kind()),
            scene,
            solver,
            record_interval,
            next_record: 0.0,
            error: None,
        };
        sim.record();
        Ok(sim)
    }

    /// Runs the hot loops in the compiled copy `isa` from now on (by default
    /// the best this processor has, [`Isa::best`]). Every copy gives the same
    /// bits; this is for testing that, and for measuring the copies. A
    /// restored state starts again with the best copy.
    pub fn set_isa(&mut self, isa: Isa) {
        self.solver.set_isa(isa);
    }

    /// Shares the run's passes over its particles among `ranks` (the
    /// processes of an MPI run, [`crate::ranks`]); the same bits on any
    /// number of ranks. Refused, with the reason, by the scenes whose
    /// solver runs on one rank only (all but `taylor3d` and `penetration`).
    pub fn set_ranks(&mut self, ranks: crate::ranks::Handle) -> std::result::Result<(), String> {
        self.solver
            .set_ranks(ranks)
            .map_err(|e| format!("scene `{}`: {e}", self.kind().name()))
    }

    /// A built-in scene by name with default parameters.
    pub fn builtin(name: &str) -> Result<Self> {
        Simulation::new(Scene::builtin(name)?)
    }

    /// The scene this run was built from.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The kind of scene.
    pub fn kind(&self) -> SceneKind {
        self.scene.kind()
    }

    /// Simulated time.
    pub fn time(&self) -> f64 {
        self.solver.time()
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.solver.steps()
    }

    /// Number of particles.
    pub fn particles(&self) -> usize {
        self.solver.particles()
    }

    /// Latest time the run may reach.
    pub fn end_time(&self) -> f64 {
        self.scene
            .get("end_time")
            .expect("every scene has end_time")
    }

    /// Whether the end condition holds (or the run stopped on an error).
    pub fn finished(&self) -> bool {
        self.error.is_some() || self.solver.finished()
    }

    /// The error that stopped the run, if any.
    pub fn error(&self) -> Option<&Error> {
        self.error.as_ref()
    }

    /// The rod's outline now, `(axial, radius)` from the impact face to the
    /// free end along one generator of the mantle, for the scenes that have
    /// a rod.
    pub fn rod_profile(&self) -> Option<Vec<[f64; 2]>> {
        self.solver.rod_profile()
    }

    /// Smallest distance between neighbouring particles over the run so far,
    /// relative to the initial spacing, where the solver tracks it (Taylor).
    pub fn min_spacing_ratio(&self) -> Option<f64> {
        self.solver.min_spacing_ratio()
    }

    /// The wall time of each phase of the steps taken in this process, as a
    /// table, where the solver keeps it (the 3-D scenes).
    pub fn phase_table(&self) -> Option<String> {
        self.solver.phase_table()
    }

    /// Names, units and meanings of this scene's observables.
    pub fn observable_specs(&self) -> &'static [ObservableSpec] {
        self.kind().observable_specs()
    }

    /// Current values of the observables, in [`Simulation::observable_specs`] order.
    pub fn observables(&self) -> Vec<f64> {
        let cells = &self.observed.0;
        if let Some(values) = cells.iter().map(|c| c.get().copied()).collect() {
            return values;
        }
        let values = self.solver.observables();
        for (cell, v) in cells.iter().zip(&values) {
            // The same bits as a value computed alone.
            let _ = cell.set(*v);
        }
        values
    }

    /// Current value of one observable.
    pub fn observable(&self, name: &str) -> Option<f64> {
        let k = self
            .observable_specs()
            .iter()
            .position(|s| s.name == name)?;
        self.observable_at(k)
    }

    /// Current value of the `k`-th observable (`None` past the table). Only
    /// that one is computed ([`Model::observable`]), at most once per step:
    /// the bits of `observables()[k]`.
    pub fn observable_at(&self, k: usize) -> Option<f64> {
        let cell = self.observed.0.get(k)?;
        if let Some(v) = cell.get() {
            return Some(*v);
        }
        let v = self.solver.observable(k)?;
        Some(*cell.get_or_init(|| v))
    }

    /// The particle fields of this run, `position` first.
    pub fn field_specs(&self) -> &'static [FieldSpec] {
        self.solver.field_specs()
    }

    /// The current values of one particle field, interleaved per particle;
    /// only that field is computed.
    pub fn field(&self, name: &str) -> Option<Vec<f64>> {
        self.solver.field(name)
    }

    /// Recorded time histories of the observables.
    pub fn history(&self) -> &History {
        &self.history
    }

    /// Particle positions and fields now.
    pub fn snapshot(&self) -> Snapshot {
        Snapshot::of(self.solver.as_ref())
    }

    fn record(&mut self) {
        let t = self.time();
        let values = self.observables();
        self.history.push(t, &values);
        self.next_record = next_record_after(self.next_record, self.record_interval, t);
    }

    /// Takes one step. After an error the run is stopped and every further
    /// call returns that error.
    pub fn step(&mut self) -> Result<()> {
        let stepped = self.step_apart();
        self.share();
        stepped
    }

    /// [`Simulation::step`], leaving apart what the ranks of a run on
    /// several ([`Simulation::set_ranks`]) keep apart between steps (the 3-D
    /// solver's damage variables: each rank's current on its own part).
    /// A loop of steps calls [`Simulation::share`] before it reads the
    /// run's fields, reads its observables between records, saves its
    /// state or ends; the records and [`Simulation::finished`] need no
    /// share (a record makes whole what the observables read:
    /// [`crate::model::Model::share_observed`]). On one rank the same as
    /// [`Simulation::step`].
    pub fn step_apart(&mut self) -> Result<()> {
        if let Some(e) = &self.error {
            return Err(e.clone());
        }
        let stepped = self.solver.step();
        self.observed.clear();
        if let Err(e) = stepped {
            self.solver.share();
            self.record();
            self.error = Some(e.clone());
            return Err(e);
        }
        if self.time() >= self.next_record || self.finished() {
            self.solver.share_observed();
            self.record();
        }
        Ok(())
    }

    /// Makes whole on every rank what the ranks keep apart between steps
    /// ([`Simulation::step_apart`]): a collective call, which every rank
    /// makes at the same point of the run. Nothing on one rank, or where
    /// nothing is apart.
    pub fn share(&mut self) {
        self.solver.share();
    }

    /// Steps until the simulated time reaches `t` or the end condition holds.
    /// The last step is not shortened, so the time may pass `t` by less than
    /// one step; results therefore do not depend on how a run is divided.
    pub fn advance_to(&mut self, t: f64) -> Result<()> {
        // On a worker of the thread pool: see `Simulation::run`.
        let stepped = rayon::scope(|_| {
            while self.time() < t && !self.finished() {
                self.step_apart()?;
            }
            Ok(())
        });
        self.share();
        stepped?;
        match &self.error {
            Some(e) => Err(e.clone()),
            None => Ok(()),
        }
    }

    /// Whether the run's state can be saved: not after a stop that left
    /// numbers that are not finite in its fields (a `NonFinite` stop, or an
    /// energy balance that overflowed), which no state can hold and
    /// [`Simulation::deserialize_state`] would refuse. The error is that
    /// stop. Every other state, stopped or not, saves and loads back.
    pub fn check_savable(&self) -> Result<()> {
        match &self.error {
            Some(e @ Error::NonFinite { .. }) => Err(e.clone()),
            Some(e @ Error::EnergyDrift { error, .. }) if !error.is_finite() => Err(e.clone()),
            _ => Ok(()),
        }
    }

    /// The complete state of the run (solver, history, scene) as bytes, for
    /// hosts that roll back (FMI `fmi3SerializeFMUState`). A stopped run's
    /// error is not part of the state. Check [`Simulation::check_savable`]
    /// first: the state of a run stopped on a non-finite field holds no
    /// numbers, and does not load back.
    pub fn serialize_state(&self) -> Vec<u8> {
        serde_json::to_vec(self).expect("the state holds only finite numbers")
    }

    /// Restores a run from [`Simulation::serialize_state`] bytes, of this
    /// build's format ([`crate::STATE_FORMAT`]) or an older one, which is
    /// brought up to this one first; a newer or unknown format is refused
    /// with [`Error::InvalidState`], naming it. The state is checked as a new run is, and refused with
    /// [`Error::InvalidState`] unless it is one that a run of its scene can
    /// reach: see [`Simulation::check_restored`].
    pub fn deserialize_state(bytes: &[u8]) -> Result<Self> {
        let saved: serde_json::Value =
            serde_json::from_slice(bytes).map_err(|e| Error::InvalidState(e.to_string()))?;
        Simulation::from_saved(saved)
    }

    /// [`Simulation::deserialize_state`] of the state already read as a
    /// JSON tree (a checkpoint's run, [`crate::checkpoint`]).
    pub fn from_saved(mut saved: serde_json::Value) -> Result<Self> {
        let invalid = |e: String| Error::InvalidState(e);
        crate::state_format::upgrade(&mut saved)
            .map_err(|e| invalid(format!("the state cannot be read: {e}")))?;
        let mut sim: Simulation =
            serde_json::from_value(saved).map_err(|e| invalid(e.to_string()))?;
        // A state saved before the scene's later observables were (the
        // failure modes of `penetration`, 2026-11-29) reads them as 0
        // before the restart.
        sim.history.adopt_later_observables(sim.observable_specs());
        sim.check_restored()
            .map_err(|e| Error::InvalidState(format!("the state is not valid: {e}")))?;
        Ok(sim)
    }

    /// Checks a restored run: its solver and history agree with a new run
    /// of its scene (what follows from the parameters the same, bit for
    /// bit; one finite value per particle in every field; histories of the
    /// scene's observables with finite values at increasing times). Its
    /// scene passed the checks of a new run when it was read.
    pub fn check_restored(&self) -> std::result::Result<(), String> {
        let fresh = Simulation::new(self.scene.clone()).map_err(|e| format!("its scene: {e}"))?;
        self.solver.check_restored(fresh.solver.as_ref())?;
        // After every record the next one is due within one interval.
        let t = self.time();
        if self.record_interval.to_bits() != fresh.record_interval.to_bits()
            || !(self.next_record > t && self.next_record <= t + 1.5 * self.record_interval)
        {
            return Err("its record times do not follow from its scene".into());
        }
        let h = &self.history;
        let rows = h.times.len();
        if h.names != fresh.history.names
            || h.values.len() != rows * h.names.len()
            || !h.values.iter().chain(&h.times).all(|x| x.is_finite())
            || h.times.windows(2).any(|w| w[1] < w[0])
        {
            return Err("its history is not one of the scene's observables".into());
        }
        Ok(())
    }

    /// Runs to the end condition.
    pub fn run(&mut self) -> Result<()> {
        // The whole loop runs on a worker of the thread pool, so a step does
        // not wake a worker from the calling thread and wait to be woken in
        // turn (test 7 to 10 us on one thread: 1.71 s -> 1.58 s).
        rayon::scope(|_| self.run_with(|_| true))
    }

    /// Runs to the end condition, calling `progress` after every step; the
    /// run is cancelled (with [`Error::Cancelled`]) when it returns `false`.
    pub fn run_with(&mut self, mut progress: impl FnMut(&Progress) -> bool) -> Result<()> {
        let end_time = self.end_time();
        while !self.finished() {
            self.step()?;
            let p = Progress {
                time: self.time(),
                end_time,
                steps: self.steps(),
            };
            if !progress(&p) {
                let e = Error::Cancelled { time: p.time };
                self.error = Some(e.clone());
                return Err(e);
            }
        }
        match &self.error {
            Some(e) => Err(e.clone()),
            None => Ok(()),
        }
    }
}

/// The first record time after `t` on the grid `next + k * interval`. A step
/// that crossed a few record times advances one interval at a time (the
/// bits the runs were recorded with); a step that crossed more (a record
/// interval far below the step) jumps there at once, so no input makes this
/// loop for long; and the result is always above `t`.
fn next_record_after(next: f64, interval: f64, t: f64) -> f64 {
    const STEPWISE: usize = 64;
    let mut n = next;
    for _ in 0..STEPWISE {
        if n > t {
            return n;
        }
        n += interval;
    }
    if n <= t {
        n += (((t - n) / interval).floor() + 1.0) * interval;
    }
    if n > t && n.is_finite() {
        n
    } else {
        t.next_up()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::{Arc, Mutex};

    /// A Taylor run that notes which observables it is asked for: `Some(k)`
    /// for one, `None` for all.
    #[derive(Debug, Clone, serde::Serialize)]
    struct Counting {
        inner: crate::solver::axisymmetric::TaylorSolver,
        #[serde(skip)]
        asked: Arc<Mutex<Vec<Option<usize>>>>,
    }

    impl Model for Counting {
        fn time(&self) -> f64 {
            self.inner.time()
        }
        fn steps(&self) -> u64 {
            self.inner.steps()
        }
        fn particles(&self) -> usize {
            self.inner.particles()
        }
        fn finished(&self) -> bool {
            self.inner.finished()
        }
        fn step(&mut self) -> Result<()> {
            self.inner.step()
        }
        fn observables(&self) -> Vec<f64> {
            self.asked.lock().unwrap().push(None);
            self.inner.observables()
        }
        fn observable(&self, k: usize) -> Option<f64> {
            self.asked.lock().unwrap().push(Some(k));
            self.inner.observable(k)
        }
        fn field_specs(&self) -> &'static [FieldSpec] {
            Model::field_specs(&self.inner)
        }
        fn field(&self, name: &str) -> Option<Vec<f64>> {
            self.inner.field(name)
        }
        fn record_interval(&self) -> f64 {
            Model::record_interval(&self.inner)
        }
        fn load_state(&mut self, saved: SavedSolver<'_>) -> std::result::Result<(), String> {
            Model::load_state(&mut self.inner, saved)
        }
        fn check_restored(&self, fresh: &dyn Model) -> std::result::Result<(), String> {
            Model::check_restored(&self.inner, fresh)
        }
    }

    /// A coarse Taylor run (4 particles across) whose solver counts.
    fn counting() -> (Simulation, Arc<Mutex<Vec<Option<usize>>>>) {
        let mut scene = Scene::builtin("taylor").unwrap();
        scene.set("particles_radial", 4.0).unwrap();
        let mut sim = Simulation::new(scene).unwrap();
        let asked = Arc::new(Mutex::new(Vec::new()));
        let inner = sim
            .solver
            .as_any()
            .downcast_ref::<crate::solver::axisymmetric::TaylorSolver>()
            .unwrap()
            .clone();
        sim.solver = Box::new(Counting {
            inner,
            asked: Arc::clone(&asked),
        });
        (sim, asked)
    }

    #[test]
    fn a_read_of_one_observable_computes_that_one_once_per_step() {
        let (mut sim, asked) = counting();
        let n = sim.observable_specs().len();
        // At this resolution every step records the histories (and so
        // computes the whole set); forget it, as a step between two records
        // does.
        sim.step().unwrap();
        sim.observed.clear();
        asked.lock().unwrap().clear();
        let tail = sim.observable_at(3).unwrap();
        assert_eq!(*asked.lock().unwrap(), [Some(3)], "one asked, alone");
        assert_eq!(sim.observable("tail_velocity"), Some(tail));
        assert_eq!(sim.observable_at(3), Some(tail));
        assert_eq!(*asked.lock().unwrap(), [Some(3)], "then kept");
        assert_eq!(sim.observable_at(n), None);
        // Every value read alone has the bits of the whole set; with all of
        // them known, the set asks the solver for nothing.
        let alone: Vec<u64> = (0..n)
            .map(|k| sim.observable_at(k).unwrap().to_bits())
            .collect();
        // Each asked once: 3 before, the others now.
        let asked_alone: Vec<Option<usize>> = std::iter::once(3)
            .chain((0..n).filter(|&k| k != 3))
            .map(Some)
            .collect();
        assert_eq!(*asked.lock().unwrap(), asked_alone, "each once");
        let all: Vec<u64> = sim.observables().iter().map(|x| x.to_bits()).collect();
        assert_eq!(alone, all);
        assert_eq!(*asked.lock().unwrap(), asked_alone, "all known: none asked");
        // The next step forgets them (and computes the set to record it).
        sim.step().unwrap();
        asked.lock().unwrap().clear();
        sim.observed.clear();
        let fresh: Vec<u64> = sim.observables().iter().map(|x| x.to_bits()).collect();
        assert_ne!(fresh, all, "the rod moved");
        assert_eq!(*asked.lock().unwrap(), [None]);
        for k in 0..n {
            assert_eq!(sim.observable_at(k).unwrap().to_bits(), fresh[k]);
        }
        assert_eq!(asked.lock().unwrap().len(), 1, "kept from the set");
    }

    /// A copy (an FMU state got to roll back to) holds no solver buffers,
    /// and steps on with the bits of the original.
    #[test]
    fn a_copy_steps_on_with_the_bits_of_the_original() {
        let mut scene = Scene::builtin("taylor").unwrap();
        scene.set("particles_radial", 5.0).unwrap();
        let mut sim = Simulation::new(scene).unwrap();
        sim.advance_to(4e-6).unwrap();
        let mut copy = sim.clone();
        for s in [&mut sim, &mut copy] {
            s.advance_to(12e-6).unwrap();
        }
        let bits = |s: &Simulation| -> Vec<u64> {
            let mut v = s.observables();
            for f in s.field_specs() {
                v.extend(s.field(f.name).unwrap());
            }
            v.iter().map(|x| x.to_bits()).collect()
        };
        assert_eq!(sim.steps(), copy.steps());
        assert_eq!(bits(&sim), bits(&copy));
    }

    /// Along a run, each Taylor observable computed alone has the bits of
    /// the set computed together, and every row of the table has one.
    #[test]
    fn taylor_observables_alone_have_the_bits_of_the_set() {
        let mut scene = Scene::builtin("taylor").unwrap();
        scene.set("particles_radial", 5.0).unwrap();
        let mut sim = Simulation::new(scene).unwrap();
        let solver = sim
            .solver
            .as_any()
            .downcast_ref::<crate::solver::axisymmetric::TaylorSolver>()
            .unwrap();
        let n = crate::TAYLOR_OBSERVABLES.len();
        assert_eq!(solver.observable(n), None);
        for t in [0.0, 2e-6, 8e-6, 30e-6] {
            sim.advance_to(t).unwrap();
            let solver = sim
                .solver
                .as_any()
                .downcast_ref::<crate::solver::axisymmetric::TaylorSolver>()
                .unwrap();
            let all = solver.observables();
            assert_eq!(all.len(), n);
            for (k, v) in all.iter().enumerate() {
                let one = solver.observable(k).unwrap();
                assert_eq!(
                    one.to_bits(),
                    v.to_bits(),
                    "{} at {t}",
                    crate::TAYLOR_OBSERVABLES[k].name
                );
            }
        }
        assert!(sim.observable("max_plastic_strain").unwrap() > 0.0);
    }

    /// The next record time is the first grid point past `t`: the bits of
    /// one addition per interval when a step crossed a few, and at once,
    /// still past `t`, when it crossed 10^290 of them (the penetration
    /// scene's `end_time = 1e-300` looped for ever here).
    #[test]
    fn the_next_record_is_found_in_bounded_work() {
        let mut stepwise = 0.0f64;
        while stepwise <= 1.3e-6 {
            stepwise += 1e-7 / 3.0;
        }
        assert_eq!(next_record_after(0.0, 1e-7 / 3.0, 1.3e-6), stepwise);
        for (next, interval, t) in [
            (0.0, 2.5e-302, 1e-7),
            (0.0, 1e-12, 1.0),
            (1.0, 1e-30, 1.0),
            (0.0, 5e-324, 3e-7),
        ] {
            let n = next_record_after(next, interval, t);
            assert!(n > t && n.is_finite(), "{next} {interval} {t}: {n}");
        }
    }
}
