//! `meshless_impact._native`: the Python extension module of meshless-impact,
//! a thin layer over the core library's [`meshless_impact::Simulation`] and
//! scene registry. The Python package (`python/meshless_impact/`) wraps it;
//! users import `meshless_impact`, not this module.
//!
//! What this layer adds, and nothing else:
//!
//! - scenes built from a name or a TOML file, the material and scheme
//!   choices and the parameters, in the command line's order and with its
//!   messages (`build_scene`);
//! - the run with the interpreter lock released while the solver steps, on
//!   the global thread pool or on one of its own (`threads=`);
//! - results as dicts and numpy arrays;
//! - each core error raised as the exception class of its name
//!   (`meshless_impact.errors`), and a panic caught at the boundary
//!   (`guard`), as the C ABI does: none reaches Python.
//!
//! It holds no global state: separate `Simulation`s run in parallel.

mod calibrate;

use meshless_impact::checkpoint::CheckpointFault;
use meshless_impact::{Error, Scene, SceneKind, Simulation as Core};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PyString};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The module of the exception classes, one per [`Error::name`].
const ERRORS: &str = "meshless_impact.errors";

/// How often a run that holds no lock takes it back to check for Ctrl-C and
/// to call its progress callback.
const CHECK_EVERY: Duration = Duration::from_millis(100);

/// The exception of class `name` (in [`ERRORS`]) with `message`.
fn exception(py: Python<'_>, name: &str, message: String) -> PyErr {
    let made = py
        .import(ERRORS)
        .and_then(|m| m.getattr(name))
        .and_then(|class| class.call1((message.clone(),)));
    match made {
        Ok(value) => PyErr::from_value(value),
        // The package is broken (its errors module is missing): say so
        // rather than lose the message.
        Err(e) => PyValueError::new_err(format!("{message} (and {ERRORS}.{name}: {e})")),
    }
}

/// A core error as the exception of its name: `ValueError` subclasses for
/// bad input, a `SolverStop` subclass for a run that left its domain.
pub(crate) fn raise(py: Python<'_>, e: &Error) -> PyErr {
    exception(py, e.name(), e.to_string())
}

/// The message of a caught panic.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    let text = if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic payload".into()
    };
    format!("panic inside meshless-impact: {text}")
}

/// Runs `f`, turning a panic into `meshless_impact.errors.InternalError`:
/// nothing unwinds into Python (pyo3 would raise its `PanicException`, a
/// `BaseException` that `except Exception` does not catch).
pub(crate) fn guard<T>(py: Python<'_>, f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => Err(exception(
            py,
            "InternalError",
            panic_message(payload.as_ref()),
        )),
    }
}

/// A parameter value from Python: a number, or text (a level's name for a
/// scheme, or a number as the command line takes it).
pub(crate) enum Value {
    Number(f64),
    Text(String),
}

impl Value {
    fn of(name: &str, v: &Bound<'_, PyAny>) -> PyResult<Value> {
        if v.is_instance_of::<PyString>() {
            return Ok(Value::Text(v.extract::<String>()?));
        }
        v.extract::<f64>().map(Value::Number).map_err(|_| {
            PyTypeError::new_err(format!(
                "parameter `{name}`: expected a number or a name, got {}",
                v.get_type()
                    .name()
                    .map_or_else(|_| "?".into(), |n| n.to_string())
            ))
        })
    }
}

/// The scene named `scene` (a built-in name, or the path of a TOML scene
/// file: a name ending in `.toml`, or any `os.PathLike`), with the choices
/// and the parameters applied as the command line applies `--scheme`,
/// `--strength`, `--eos`, `--preset` and `--set`s: the scheme, then the
/// material, then the parameters (schemes first), then the whole scene is
/// checked. Errors carry the command line's messages.
pub(crate) fn build_scene(
    scene: &Bound<'_, PyAny>,
    choices: &Choices,
    params: &[(String, Value)],
) -> PyResult<Result<Scene, Error>> {
    let file = if scene.is_instance_of::<PyString>() {
        let s: String = scene.extract()?;
        if s.ends_with(".toml") {
            Some(std::path::PathBuf::from(s))
        } else {
            return Ok(apply(Scene::builtin(&s), choices, params));
        }
    } else {
        Some(scene.extract::<std::path::PathBuf>().map_err(|_| {
            PyTypeError::new_err("scene: expected a scene name or the path of a TOML scene file")
        })?)
    };
    let path = file.expect("a path when not a name");
    Ok(apply(Scene::from_file(path), choices, params))
}

/// The choices of the material models, the preset and the scheme.
#[derive(Default)]
pub(crate) struct Choices {
    pub(crate) preset: Option<String>,
    pub(crate) strength: Option<String>,
    pub(crate) eos: Option<String>,
    pub(crate) scheme: Option<String>,
    /// A material file (the CLI's `--preset-file`), applied after the
    /// preset.
    pub(crate) preset_file: Option<std::path::PathBuf>,
}

/// [`build_scene`]'s steps after the scene is read.
fn apply(
    scene: Result<Scene, Error>,
    choices: &Choices,
    params: &[(String, Value)],
) -> Result<Scene, Error> {
    let mut scene = scene?;
    if let Some(name) = &choices.scheme {
        scene.set_str("scheme", name)?;
    }
    if choices.strength.is_some() || choices.eos.is_some() || choices.preset.is_some() {
        scene.choose_material(
            choices.strength.as_deref(),
            choices.eos.as_deref(),
            choices.preset.as_deref(),
        )?;
    }
    if let Some(path) = &choices.preset_file {
        scene.apply_material_file(path)?;
    }
    let pairs = scene.schemes_first(params.iter().map(|(n, v)| (n.as_str(), v)));
    for (name, value) in pairs {
        match value {
            Value::Number(x) => scene.set(name, *x)?,
            Value::Text(t) => scene.set_str(name, t)?,
        }
    }
    scene.validate()?;
    Ok(scene)
}

/// The parameters of `**kwargs`, in their order.
pub(crate) fn kwargs(params: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<(String, Value)>> {
    let mut out = Vec::new();
    if let Some(d) = params {
        for (k, v) in d.iter() {
            let name: String = k.extract()?;
            let value = Value::of(&name, &v)?;
            out.push((name, value));
        }
    }
    Ok(out)
}

/// How a run driven from Python ended its loop.
enum Flow {
    /// Reached its time or its end condition.
    Done,
    /// The solver stopped with a named error.
    Stopped(Error),
    /// The progress callback returned `False`.
    Cancelled,
    /// Ctrl-C, or the progress callback raised.
    Python(PyErr),
}

/// One run of one scene (`meshless_impact.Simulation`; the package's
/// `__init__.py` documents it for users).
#[pyclass(name = "Simulation", module = "meshless_impact._native")]
struct Simulation {
    sim: Core,
    /// A stop that the core does not keep: a cancel, by the progress
    /// callback or by Ctrl-C.
    stopped: Option<Error>,
    /// The run's own thread pool (`threads=`), or the global one.
    pool: Option<Arc<rayon::ThreadPool>>,
    /// Set by a panic: the state may be half-updated, so every further
    /// call refuses.
    poisoned: bool,
}

impl Simulation {
    fn check(&self, py: Python<'_>) -> PyResult<()> {
        if self.poisoned {
            return Err(exception(
                py,
                "InternalError",
                "the simulation panicked earlier and is unusable".into(),
            ));
        }
        Ok(())
    }

    /// Runs `f` on the simulation inside the panic boundary; a panic
    /// poisons it.
    fn with<T>(&mut self, py: Python<'_>, f: impl FnOnce(&mut Self) -> PyResult<T>) -> PyResult<T> {
        self.check(py)?;
        match catch_unwind(AssertUnwindSafe(|| f(self))) {
            Ok(r) => r,
            Err(payload) => {
                self.poisoned = true;
                Err(exception(
                    py,
                    "InternalError",
                    format!(
                        "{} (the simulation is now unusable)",
                        panic_message(payload.as_ref())
                    ),
                ))
            }
        }
    }

    /// Steps until `until` (or the end condition) without the interpreter
    /// lock, taking it back every [`CHECK_EVERY`] for Ctrl-C and `progress`.
    fn drive(
        &mut self,
        py: Python<'_>,
        until: Option<f64>,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<()> {
        self.with(py, |s| {
            if let Some(e) = s.stopped.as_ref().or(s.sim.error()) {
                return Err(raise(py, e));
            }
            let sim = &mut s.sim;
            let pool = s.pool.clone();
            let flow = py.detach(|| {
                let mut body = || drive_loop(sim, until, progress.as_ref());
                catch_unwind(AssertUnwindSafe(|| match &pool {
                    Some(p) => p.install(body),
                    // On a worker of the global pool, as `Simulation::run`.
                    None => rayon::scope(|_| body()),
                }))
            });
            let flow = match flow {
                Ok(f) => f,
                Err(payload) => std::panic::resume_unwind(payload),
            };
            match flow {
                Flow::Done => Ok(()),
                Flow::Stopped(e) => Err(raise(py, &e)),
                Flow::Cancelled => {
                    let e = Error::Cancelled { time: s.sim.time() };
                    s.stopped = Some(e.clone());
                    Err(raise(py, &e))
                }
                Flow::Python(err) => {
                    s.stopped = Some(Error::Cancelled { time: s.sim.time() });
                    Err(err)
                }
            }
        })
    }
}

/// The `progress` argument of `run` and `advance_to`: `False` or `None`
/// (none), `True` (a line on standard error, `meshless_impact._progress`),
/// or a callable `progress(time, end_time, steps)`.
#[derive(FromPyObject)]
enum Progress {
    Flag(bool),
    Callback(Option<Py<PyAny>>),
}

impl From<bool> for Progress {
    fn from(b: bool) -> Self {
        Progress::Flag(b)
    }
}

impl Simulation {
    /// [`Simulation::drive`] with the `progress` argument resolved.
    fn drive_with(
        &mut self,
        py: Python<'_>,
        until: Option<f64>,
        progress: Progress,
    ) -> PyResult<()> {
        match progress {
            Progress::Flag(false) | Progress::Callback(None) => self.drive(py, until, None),
            Progress::Callback(Some(cb)) => self.drive(py, until, Some(cb)),
            Progress::Flag(true) => {
                let line = py.import("meshless_impact._progress")?;
                let r = self.drive(py, until, Some(line.getattr("show")?.unbind()));
                line.getattr("done")?.call0()?;
                r
            }
        }
    }
}

/// The loop of [`Simulation::drive`], run without the interpreter lock.
fn drive_loop(sim: &mut Core, until: Option<f64>, progress: Option<&Py<PyAny>>) -> Flow {
    let mut last = Instant::now();
    let end_time = sim.end_time();
    loop {
        let done = match until {
            Some(t) => sim.time() >= t || sim.finished(),
            None => sim.finished(),
        };
        if done {
            return Flow::Done;
        }
        if let Err(e) = sim.step() {
            return Flow::Stopped(e);
        }
        let finished = until.is_some_and(|t| sim.time() >= t) || sim.finished();
        if last.elapsed() < CHECK_EVERY && !(finished && progress.is_some()) {
            continue;
        }
        last = Instant::now();
        let (time, steps) = (sim.time(), sim.steps());
        let r = Python::attach(|py| -> PyResult<bool> {
            py.check_signals()?;
            match progress {
                Some(cb) => {
                    let ret = cb.call1(py, (time, end_time, steps))?;
                    // `None` (a callback that returns nothing) goes on.
                    Ok(ret.is_none(py) || ret.is_truthy(py)?)
                }
                None => Ok(true),
            }
        });
        match r {
            Ok(true) => {}
            Ok(false) => return Flow::Cancelled,
            Err(e) => return Flow::Python(e),
        }
    }
}

/// The thread pool of `threads` (None: the global pool).
fn pool_of(threads: Option<usize>) -> PyResult<Option<Arc<rayon::ThreadPool>>> {
    match threads {
        None => Ok(None),
        Some(0) => Err(PyValueError::new_err(
            "parameter `threads` = 0 is out of range: allowed [1, inf) or None (the global pool)",
        )),
        Some(n) => Ok(Some(Arc::new(
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| PyValueError::new_err(format!("threads = {n}: {e}")))?,
        ))),
    }
}

#[pymethods]
impl Simulation {
    /// See `meshless_impact.Simulation`.
    #[new]
    #[pyo3(signature = (scene, *, preset=None, strength=None, eos=None, scheme=None, threads=None, preset_file=None, **params))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        scene: &Bound<'_, PyAny>,
        preset: Option<String>,
        strength: Option<String>,
        eos: Option<String>,
        scheme: Option<String>,
        threads: Option<usize>,
        preset_file: Option<std::path::PathBuf>,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        guard(py, || {
            let choices = Choices {
                preset,
                strength,
                eos,
                scheme,
                preset_file,
            };
            let params = kwargs(params)?;
            let scene = build_scene(scene, &choices, &params)?.map_err(|e| raise(py, &e))?;
            let pool = pool_of(threads)?;
            // The setup (lattice, neighbours) can take a while in 3-D.
            let sim = py.detach(|| Core::new(scene)).map_err(|e| raise(py, &e))?;
            Ok(Simulation {
                sim,
                stopped: None,
                pool,
                poisoned: false,
            })
        })
    }

    /// Runs to the end condition (see the package's docs for `progress`).
    #[pyo3(signature = (progress = Progress::Flag(false)), text_signature = "(self, progress=False)")]
    fn run(&mut self, py: Python<'_>, progress: Progress) -> PyResult<()> {
        self.drive_with(py, None, progress)
    }

    /// Steps until the time reaches `t` or the end condition holds.
    #[pyo3(signature = (t, progress = Progress::Flag(false)), text_signature = "(self, t, progress=False)")]
    fn advance_to(&mut self, py: Python<'_>, t: f64, progress: Progress) -> PyResult<()> {
        self.drive_with(py, Some(t), progress)
    }

    /// Takes one step.
    fn step(&mut self, py: Python<'_>) -> PyResult<()> {
        self.with(py, |s| {
            if let Some(e) = &s.stopped {
                return Err(raise(py, e));
            }
            let sim = &mut s.sim;
            let pool = s.pool.clone();
            let r = py.detach(|| match &pool {
                Some(p) => p.install(|| sim.step()),
                None => sim.step(),
            });
            r.map_err(|e| raise(py, &e))
        })
    }

    /// Simulated time (s).
    #[getter]
    fn time(&self, py: Python<'_>) -> PyResult<f64> {
        self.check(py)?;
        Ok(self.sim.time())
    }

    /// Whether the end condition holds or the run stopped.
    #[getter]
    fn finished(&self, py: Python<'_>) -> PyResult<bool> {
        self.check(py)?;
        Ok(self.stopped.is_some() || self.sim.finished())
    }

    /// Steps taken.
    #[getter]
    fn steps(&self, py: Python<'_>) -> PyResult<u64> {
        self.check(py)?;
        Ok(self.sim.steps())
    }

    /// Number of particles (nodes).
    #[getter]
    fn particles(&self, py: Python<'_>) -> PyResult<usize> {
        self.check(py)?;
        Ok(self.sim.particles())
    }

    /// The scene's `end_time` (s).
    #[getter]
    fn end_time(&self, py: Python<'_>) -> PyResult<f64> {
        self.check(py)?;
        Ok(self.sim.end_time())
    }

    /// The kind of scene (`taylor`, `taylor3d`, `penetration`, ...).
    #[getter]
    fn scene(&self, py: Python<'_>) -> PyResult<&'static str> {
        self.check(py)?;
        Ok(self.sim.kind().name())
    }

    /// The exception that stopped the run, or `None`.
    #[getter]
    fn error(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        self.check(py)?;
        Ok(self
            .stopped
            .as_ref()
            .or(self.sim.error())
            .map(|e| raise(py, e).into_value(py).into_any()))
    }

    /// Every parameter's value (a scheme's by its level's name).
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.check(py)?;
        let d = PyDict::new(py);
        let scene = self.sim.scene();
        for (spec, v) in scene.param_specs().iter().zip(scene.values()) {
            match spec.level(*v) {
                Some(level) => d.set_item(spec.name, level.name)?,
                None => d.set_item(spec.name, *v)?,
            }
        }
        Ok(d)
    }

    /// The current observables by name (flags as `bool`).
    fn observables<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.check(py)?;
        let d = PyDict::new(py);
        for (spec, v) in self
            .sim
            .observable_specs()
            .iter()
            .zip(self.sim.observables())
        {
            if spec.is_bool() {
                d.set_item(spec.name, v != 0.0)?;
            } else {
                d.set_item(spec.name, v)?;
            }
        }
        Ok(d)
    }

    /// The recorded histories: `time` and one array per observable.
    fn history<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.check(py)?;
        let h = self.sim.history();
        let d = PyDict::new(py);
        d.set_item("time", PyArray1::from_slice(py, &h.times))?;
        let n = h.names.len();
        for (k, name) in h.names.iter().enumerate() {
            let column: Vec<f64> = h.values.iter().skip(k).step_by(n.max(1)).copied().collect();
            d.set_item(name, PyArray1::from_vec(py, column))?;
        }
        Ok(d)
    }

    /// The particle fields: name -> (unit, component names).
    fn fields<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.check(py)?;
        field_table(py, self.sim.field_specs())
    }

    /// One particle field as an array shaped (nodes,) or (nodes, components).
    fn field<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        self.check(py)?;
        guard(py, || {
            let specs = self.sim.field_specs();
            let Some(spec) = specs.iter().find(|f| f.name == name) else {
                let names: Vec<&str> = specs.iter().map(|f| f.name).collect();
                return Err(exception(
                    py,
                    "UnknownField",
                    format!(
                        "unknown particle field `{name}` for scene `{}`; allowed: {}",
                        self.sim.kind().name(),
                        names.join(", ")
                    ),
                ));
            };
            let values = self.sim.field(name).expect("a field of the run's specs");
            let array = PyArray1::from_vec(py, values);
            let c = spec.components.len();
            if c == 1 {
                Ok(array.into_any())
            } else {
                Ok(array.reshape([self.sim.particles(), c])?.into_any())
            }
        })
    }

    /// The nodes' positions, an array shaped (nodes, 2) (R, Z) or (nodes, 3)
    /// (x, y, z): the field `position`.
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "position")
    }

    /// The complete state of the run as bytes.
    fn save_state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        self.check(py)?;
        guard(py, || {
            self.sim.check_savable().map_err(|e| raise(py, &e))?;
            Ok(PyBytes::new(py, &self.sim.serialize_state()))
        })
    }

    /// Writes the whole run to the checkpoint file `path`, whole (a
    /// temporary file renamed over it): what `meshless-impact run --restart`
    /// and `Simulation.load` continue.
    fn save(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
        self.check(py)?;
        guard(py, || {
            let sim = &self.sim;
            py.detach(|| meshless_impact::checkpoint::save(&path, sim, &Default::default()))
                .map_err(|e| raise(py, &e))
        })
    }

    /// The run saved in the checkpoint file `path` (by `save`, or by the
    /// program's `--checkpoint`), to go on with; a bad file raises the
    /// subclass of `BadCheckpoint` that names its fault.
    #[staticmethod]
    #[pyo3(signature = (path, *, threads=None))]
    fn load(py: Python<'_>, path: std::path::PathBuf, threads: Option<usize>) -> PyResult<Self> {
        guard(py, || {
            let pool = pool_of(threads)?;
            let (sim, _) = py
                .detach(|| meshless_impact::checkpoint::load(&path))
                .map_err(|e| raise(py, &e))?;
            Ok(Simulation {
                sim,
                stopped: None,
                pool,
                poisoned: false,
            })
        })
    }

    /// Replaces the run by a saved state of the same kind of scene,
    /// checked as the C ABI's `mi_sim_state_load` checks it.
    fn load_state(&mut self, py: Python<'_>, state: &[u8]) -> PyResult<()> {
        self.with(py, |s| {
            let restored = py
                .detach(|| Core::deserialize_state(state))
                .map_err(|e| raise(py, &e))?;
            if restored.kind() != s.sim.kind() {
                let e = Error::InvalidState(format!(
                    "the state is of scene kind `{}`, the simulation of `{}`",
                    restored.kind(),
                    s.sim.kind()
                ));
                return Err(raise(py, &e));
            }
            s.sim = restored;
            s.stopped = None;
            Ok(())
        })
    }

    /// Panics inside the boundary (for the tests of the panic boundary, as
    /// the C ABI's `mi_sim_debug_panic`).
    fn _debug_panic(&mut self, py: Python<'_>) -> PyResult<()> {
        self.with(py, |_| panic!("mi debug panic"))
    }

    fn __repr__(&self) -> String {
        format!(
            "<meshless_impact.Simulation {} t={:e} s steps={} particles={}>",
            self.sim.kind().name(),
            self.sim.time(),
            self.sim.steps(),
            self.sim.particles()
        )
    }
}

/// name -> {"unit", "components"} of a field table.
fn field_table<'py>(
    py: Python<'py>,
    specs: &[meshless_impact::FieldSpec],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for f in specs {
        let row = PyDict::new(py);
        row.set_item("unit", f.unit)?;
        row.set_item("components", PyList::new(py, f.components)?)?;
        d.set_item(f.name, row)?;
    }
    Ok(d)
}

/// The built-in scene names, each kind followed by its named variants.
#[pyfunction]
fn scenes(py: Python<'_>) -> PyResult<Vec<String>> {
    guard(py, || Ok(meshless_impact::builtin_names()))
}

/// The kind of a built-in scene.
fn kind_of(py: Python<'_>, scene: &str) -> PyResult<SceneKind> {
    Scene::builtin(scene)
        .map(|s| s.kind())
        .map_err(|e| raise(py, &e))
}

/// The parameter table of `scene` with the choices made, as `meshless-impact
/// params SCENE [--scheme ...]` prints it.
#[pyfunction]
#[pyo3(signature = (scene, *, preset=None, strength=None, eos=None, scheme=None))]
fn params<'py>(
    py: Python<'py>,
    scene: &str,
    preset: Option<String>,
    strength: Option<String>,
    eos: Option<String>,
    scheme: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    guard(py, || {
        let choices = Choices {
            preset,
            strength,
            eos,
            scheme,
            preset_file: None,
        };
        let s = apply(Scene::builtin(scene), &choices, &[]).map_err(|e| raise(py, &e))?;
        let d = PyDict::new(py);
        for (p, v) in s.param_specs().iter().zip(s.values()) {
            let row = PyDict::new(py);
            row.set_item("unit", p.unit)?;
            match p.level(*v) {
                Some(level) => row.set_item("value", level.name)?,
                None => row.set_item("value", *v)?,
            }
            row.set_item("default", p.default)?;
            row.set_item("min", p.range.min)?;
            row.set_item("max", p.range.max)?;
            row.set_item("min_inclusive", p.range.min_inclusive)?;
            row.set_item("max_inclusive", p.range.max_inclusive)?;
            row.set_item("integer", p.range.integer)?;
            row.set_item("description", p.description)?;
            let levels: Vec<&str> = p.levels.iter().map(|l| l.name).collect();
            row.set_item("levels", levels)?;
            d.set_item(p.name, row)?;
        }
        Ok(d)
    })
}

/// The observables of `scene`: name -> {"unit", "description"}.
#[pyfunction]
fn observables<'py>(py: Python<'py>, scene: &str) -> PyResult<Bound<'py, PyDict>> {
    guard(py, || {
        let d = PyDict::new(py);
        for o in kind_of(py, scene)?.observable_specs() {
            let row = PyDict::new(py);
            row.set_item("unit", o.unit)?;
            row.set_item("description", o.description)?;
            d.set_item(o.name, row)?;
        }
        Ok(d)
    })
}

/// The particle fields of `scene`: name -> {"unit", "components"}.
#[pyfunction]
fn fields<'py>(py: Python<'py>, scene: &str) -> PyResult<Bound<'py, PyDict>> {
    guard(py, || field_table(py, kind_of(py, scene)?.field_specs()))
}

/// The material presets: name -> {"models", "values", "source"}.
#[pyfunction]
fn presets(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    guard(py, || {
        let d = PyDict::new(py);
        for p in meshless_impact::materials::PRESETS {
            let row = PyDict::new(py);
            row.set_item("models", p.choice.to_string())?;
            let values = PyDict::new(py);
            for (name, v) in p.values {
                values.set_item(*name, *v)?;
            }
            row.set_item("values", values)?;
            row.set_item("source", p.source)?;
            d.set_item(p.name, row)?;
        }
        Ok(d)
    })
}

/// One error of each kind, with made-up values: the tests check that each
/// is raised as the class of its name. Adding a kind of error breaks the
/// build here ([`every_error_is_listed`]) until it is listed.
fn sample_errors() -> Vec<Error> {
    use meshless_impact::MomentMethod;
    vec![
        Error::OutOfRange {
            name: "impact_speed".into(),
            value: -1.0,
            range: "(0, 3000]".into(),
        },
        Error::UnknownParameter {
            name: "speed".into(),
            scene: "taylor".into(),
            allowed: "impact_speed".into(),
        },
        Error::UnknownScene {
            name: "tayl".into(),
            allowed: "taylor".into(),
        },
        Error::UnknownModel {
            key: "eos".into(),
            name: "x".into(),
            allowed: "linear".into(),
        },
        Error::ParseValue {
            name: "impact_speed".into(),
            text: "fast".into(),
        },
        Error::Inconsistent("a and b".into()),
        Error::SceneFile("x.toml".into()),
        Error::ShotsFile("shots.csv, line 2, column 3: `x` is not a number".into()),
        Error::SingularMomentMatrix {
            method: MomentMethod::Msph,
            particle: 1,
            time: 1e-6,
            condition: 1e16,
        },
        Error::NonFinite {
            field: "stress",
            particle: 2,
            time: 1e-6,
        },
        Error::ThroughBoundary {
            particle: 3,
            boundary: "anvil",
            time: 1e-6,
            position: -1e-4,
        },
        Error::TimeStepCollapse {
            dt: 1e-15,
            time: 1e-6,
            min: 1e-12,
        },
        Error::EnergyDrift {
            error: 0.2,
            bound: 0.1,
            time: 1e-6,
        },
        Error::SpacingCollapse {
            ratio: 0.01,
            bound: 0.05,
            time: 1e-6,
            hint: "",
        },
        Error::CompressionLimit {
            particle: 4,
            time: 1e-6,
            compression: 0.5,
            limit: 0.4,
        },
        Error::MemoryBudget {
            nodes: 1e9,
            estimate: 1e12,
            budget: 1e10,
            per_node: 1000.0,
        },
        Error::Cancelled { time: 1e-6 },
        Error::InvalidState("not a state".into()),
        Error::Checkpoint {
            path: "run.ckpt".into(),
            fault: CheckpointFault::NotACheckpoint,
            detail: "it does not start as one".into(),
        },
        Error::Checkpoint {
            path: "run.ckpt".into(),
            fault: CheckpointFault::Truncated,
            detail: "it ends after 10 bytes".into(),
        },
        Error::Checkpoint {
            path: "run.ckpt".into(),
            fault: CheckpointFault::Corrupted,
            detail: "its CRC-32 disagrees".into(),
        },
        Error::Checkpoint {
            path: "run.ckpt".into(),
            fault: CheckpointFault::NewerFormat,
            detail: "format 9".into(),
        },
        Error::Checkpoint {
            path: "run.ckpt".into(),
            fault: CheckpointFault::OtherScene,
            detail: "scene: `noh`".into(),
        },
        Error::Checkpoint {
            path: "run.ckpt".into(),
            fault: CheckpointFault::Contradicts,
            detail: "impact_speed".into(),
        },
        Error::Io {
            path: "out.csv".into(),
            message: "denied".into(),
        },
    ]
}

/// Fails to compile when the core gains a kind of error that
/// [`sample_errors`] does not list.
#[allow(dead_code)]
fn every_error_is_listed(e: &Error) {
    match e {
        Error::OutOfRange { .. }
        | Error::UnknownParameter { .. }
        | Error::UnknownScene { .. }
        | Error::UnknownModel { .. }
        | Error::ParseValue { .. }
        | Error::Inconsistent(_)
        | Error::SceneFile(_)
        | Error::ShotsFile(_)
        | Error::SingularMomentMatrix { .. }
        | Error::NonFinite { .. }
        | Error::ThroughBoundary { .. }
        | Error::TimeStepCollapse { .. }
        | Error::EnergyDrift { .. }
        | Error::SpacingCollapse { .. }
        | Error::CompressionLimit { .. }
        | Error::MemoryBudget { .. }
        | Error::Cancelled { .. }
        | Error::InvalidState(_)
        | Error::Checkpoint { .. }
        | Error::Io { .. } => {}
    }
}

/// Every kind of core error: (name, message of a sample, the exception it
/// raises). For the tests.
#[pyfunction]
fn _error_samples(py: Python<'_>) -> PyResult<Vec<(String, String, Py<PyAny>)>> {
    guard(py, || {
        Ok(sample_errors()
            .iter()
            .map(|e| {
                let exc = raise(py, e).into_value(py).into_any();
                (e.name().to_string(), e.to_string(), exc)
            })
            .collect())
    })
}

/// Panics inside the boundary of a module function (for the tests).
#[pyfunction]
fn _debug_panic(py: Python<'_>) -> PyResult<()> {
    guard(py, || panic!("mi debug panic"))
}

/// The extension module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Simulation>()?;
    m.add_function(wrap_pyfunction!(scenes, m)?)?;
    m.add_function(wrap_pyfunction!(params, m)?)?;
    m.add_function(wrap_pyfunction!(observables, m)?)?;
    m.add_function(wrap_pyfunction!(fields, m)?)?;
    m.add_function(wrap_pyfunction!(presets, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate::calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(_error_samples, m)?)?;
    m.add_function(wrap_pyfunction!(_debug_panic, m)?)?;
    m.add("VERSION", meshless_impact::VERSION)?;
    Ok(())
}
