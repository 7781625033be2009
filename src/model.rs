//! [`Model`]: what a solver offers to [`crate::Simulation`], whatever its
//! scene, dimension or method. A scene's registry row
//! ([`crate::scene::registry`]) builds one; the simulation, the CLI, the C
//! ABI and the FMUs use it only through this trait.

use crate::error::Result;
use crate::isa::Isa;
use crate::observe::{Field, FieldSpec, Snapshot};
use std::any::Any;

/// What every solver state offers alike: copies, saving, and its own type
/// (implemented for every `Clone + Serialize` [`Model`]).
pub trait ModelState {
    /// A copy of this run.
    fn boxed_clone(&self) -> Box<dyn Model>;

    /// The run's state, for any serde format (JSON in the C ABI's saved
    /// states, postcard in the FMU's), loaded by [`Model::load_state`].
    fn save(&self) -> &dyn erased_serde::Serialize;

    /// The run's state in postcard, encoded by its own type (no dynamic
    /// call per value): what the FMU state holds, loaded by
    /// [`Model::load_state`] from [`SavedSolver::Postcard`].
    fn save_compact(&self) -> Vec<u8>;

    /// This run as [`Any`], for [`Model::check_restored`] to reach `fresh`'s
    /// own type.
    fn as_any(&self) -> &dyn Any;
}

impl<T: Model + Clone + serde::Serialize> ModelState for T {
    fn boxed_clone(&self) -> Box<dyn Model> {
        Box::new(self.clone())
    }
    fn save(&self) -> &dyn erased_serde::Serialize {
        self
    }
    fn save_compact(&self) -> Vec<u8> {
        // Counted first, so that the vector is made once at its size.
        let mut out = Vec::with_capacity(postcard_len(self));
        postcard::to_io(self, &mut out).expect("a state encodes into a vector");
        out
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
}

/// The number of bytes of `value` in postcard, counted without making them.
pub(crate) fn postcard_len<T: serde::Serialize + ?Sized>(value: &T) -> usize {
    /// Counts what is written.
    struct Count(usize);
    impl std::io::Write for Count {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            self.0 += buf.len();
            Ok(buf.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }
    let mut count = Count(0);
    postcard::to_io(value, &mut count).expect("a value encodes into a counter");
    count.0
}

/// One solver's run of one scene.
pub trait Model: ModelState + std::fmt::Debug + Send + Sync + Any {
    /// Simulated time.
    fn time(&self) -> f64;

    /// Steps taken.
    fn steps(&self) -> u64;

    /// Number of particles (or nodes).
    fn particles(&self) -> usize;

    /// Whether the scene's end condition holds.
    fn finished(&self) -> bool;

    /// Takes one step; an error stops the run.
    fn step(&mut self) -> Result<()>;

    /// Current values of the scene's observables, in the order of its
    /// observable table.
    fn observables(&self) -> Vec<f64>;

    /// The current value of the `k`-th observable of the table alone, or
    /// `None` past the table; the bits of `observables()[k]`. A solver
    /// whose observables cost a pass over the particles each answers this
    /// without computing the others (an FMU output read, `mi_sim_observable`);
    /// by default it computes them all.
    fn observable(&self, k: usize) -> Option<f64> {
        self.observables().get(k).copied()
    }

    /// The particle fields this run offers, `position` first.
    fn field_specs(&self) -> &'static [FieldSpec];

    /// The current values of the particle field `name`, interleaved per
    /// particle (`particles * components`), or `None` for a name not in
    /// [`Model::field_specs`]. Only that field is computed.
    fn field(&self, name: &str) -> Option<Vec<f64>>;

    /// Simulated time between two records of the observables' histories.
    fn record_interval(&self) -> f64;

    /// The outline of a rod, `(axial, radius)` along one generator of its
    /// mantle from the impact face to the free end,
    /// for the scenes that have a rod.
    fn rod_profile(&self) -> Option<Vec<[f64; 2]>> {
        None
    }

    /// Smallest distance between neighbouring particles over the run so
    /// far, relative to the initial spacing, where the solver tracks it.
    fn min_spacing_ratio(&self) -> Option<f64> {
        None
    }

    /// The wall time of each phase of the steps taken in this process, as a
    /// table, where the solver keeps it (the 3-D solver).
    fn phase_table(&self) -> Option<String> {
        None
    }

    /// Runs the hot loops in the compiled copy `isa` from now on; a solver
    /// without compiled copies ignores it.
    fn set_isa(&mut self, _isa: Isa) {}

    /// Makes whole on every rank what a run's ranks keep apart between
    /// steps (the 3-D solver's damage variables, each rank's current on its
    /// own part): a collective call, which every rank makes at the same
    /// point of a run, before anything reads the whole state. Nothing on
    /// one process, and by default.
    fn share(&mut self) {}

    /// Makes whole on every rank what [`Model::observables`] reads of what
    /// the ranks keep apart between steps (a collective call, as
    /// [`Model::share`]); the rest may stay apart. By default
    /// [`Model::share`].
    fn share_observed(&mut self) {
        self.share();
    }

    /// Shares this run's passes over its particles among `ranks` (the
    /// processes of an MPI run, [`crate::ranks`]), with the same bits on
    /// any number of ranks. A solver that runs on one process only refuses
    /// more than one rank.
    fn set_ranks(&mut self, ranks: crate::ranks::Handle) -> std::result::Result<(), String> {
        if ranks.size() > 1 {
            return Err(format!(
                "this solver runs on one rank only, not on {}: the 3-D scenes (taylor3d, penetration) run on several",
                ranks.size()
            ));
        }
        Ok(())
    }

    /// Replaces the state of this run, a new run of its scene, with the
    /// saved one (of [`ModelState::save`] or [`ModelState::save_compact`]),
    /// read but not yet checked ([`Model::check_restored`]). The message
    /// says why it cannot be read; on an error this run is left as it was.
    fn load_state(&mut self, saved: SavedSolver<'_>) -> std::result::Result<(), String>;

    /// Checks a restored run against `fresh`, a new run of the same scene
    /// built by the same row: what follows from the parameters the same,
    /// bit for bit, one finite value per particle in every field, and a
    /// clock, places and speeds a run of this scene can reach.
    fn check_restored(&self, fresh: &dyn Model) -> std::result::Result<(), String>;
}

/// `fresh` as the solver type `T`, or a message saying that the restored
/// solver is not its scene's.
pub(crate) fn same_solver<T: 'static>(fresh: &dyn Model) -> std::result::Result<&T, String> {
    fresh
        .as_any()
        .downcast_ref::<T>()
        .ok_or_else(|| "its solver is not its scene's".to_string())
}

/// A solver's saved state as [`Model::load_state`] reads it.
pub enum SavedSolver<'a> {
    /// As a JSON tree ([`crate::Simulation::serialize_state`]).
    Json(serde_json::Value),
    /// The postcard bytes of [`ModelState::save_compact`], decoded by the
    /// solver's own type (no dynamic call per value).
    Postcard(&'a [u8]),
}

/// `saved` read as a `T` (not yet checked).
pub(crate) fn read_saved<T: serde::de::DeserializeOwned>(
    saved: SavedSolver<'_>,
) -> std::result::Result<T, String> {
    match saved {
        SavedSolver::Json(value) => serde_json::from_value(value).map_err(|e| e.to_string()),
        SavedSolver::Postcard(bytes) => match postcard::take_from_bytes::<T>(bytes) {
            Ok((value, [])) => Ok(value),
            Ok((_, left)) => Err(format!("{} bytes follow its solver", left.len())),
            Err(e) => Err(e.to_string()),
        },
    }
}

/// Inside `impl Model for T`: the methods that call `T`'s inherent methods
/// of the same names (`time`, `steps`, `particles`, `finished`, `step`,
/// `observables`, `field`).
macro_rules! inherent_basics {
    () => {
        fn time(&self) -> f64 {
            Self::time(self)
        }
        fn steps(&self) -> u64 {
            Self::steps(self)
        }
        fn particles(&self) -> usize {
            Self::particles(self)
        }
        fn finished(&self) -> bool {
            Self::finished(self)
        }
        fn step(&mut self) -> $crate::error::Result<()> {
            Self::step(self)
        }
        fn observables(&self) -> Vec<f64> {
            Self::observables(self)
        }
        fn field(&self, name: &str) -> Option<Vec<f64>> {
            Self::field(self, name)
        }
    };
}
pub(crate) use inherent_basics;

/// A snapshot of a run (written here, with the interface it reads, so that
/// `src/observe.rs` knows nothing of the models).
impl Snapshot {
    /// Every field of a run now: `position` as the positions (its
    /// components padded with zeros to three), the others as fields.
    pub fn of(model: &dyn Model) -> Snapshot {
        let specs = model.field_specs();
        let value = |name| model.field(name).expect("a field the model lists");
        let (position, rest) = specs.split_first().expect("every scene has positions");
        let k = position.components.len();
        Snapshot {
            time: model.time(),
            positions: value(position.name)
                .chunks(k)
                .map(|c| std::array::from_fn(|k| c.get(k).copied().unwrap_or(0.0)))
                .collect(),
            fields: rest
                .iter()
                .map(|f| Field {
                    name: f.name,
                    components: f.components,
                    unit: f.unit,
                    data: value(f.name),
                })
                .collect(),
        }
    }
}
