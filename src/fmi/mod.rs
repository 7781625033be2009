//! FMI 3.0 and FMI 2.0 Co-Simulation glue over the same core: one FMU per
//! kind of scene that the registry declares an FMU identity for
//! ([`crate::scene::registry::FmuIdentity`]; today `TaylorImpact`, the
//! `taylor` scene, and one FMU per other material choice of it:
//! `TaylorImpactBilinear`, `TaylorImpactMieGruneisen`,
//! `TaylorImpactBilinearMieGruneisen`; `Taylor3dImpact`, the `taylor3d`
//! scene; `BallisticImpact`, the `penetration` scene). One library serves
//! every FMU: an instance takes the FMU whose instantiation token the host
//! gives.
//!
//! An FMU exposes its scene: every parameter of the row's table as a fixed
//! parameter, every observable as an output. [`Fmu::variables`] derives the
//! variable list (and so the value references) from those tables;
//! [`model_description`] writes the `modelDescription.xml` from the same
//! list, so the glue and the packaged FMU can never disagree.
//!
//! Layout, after the Reference-FMUs:
//!
//! - this module: the variable table, the instance type shared by both
//!   standards, the mask of allowed states per function, logging, and the
//!   operations (set/get, step, state) written once;
//! - [`fmi3`] and [`fmi2`]: the exported C functions of each standard, thin
//!   wrappers that check pointers, catch panics and translate types.
//!
//! There is no global state: every instance owns its scene, its simulation
//! and its logger, so instances run in parallel.

pub mod fmi2;
pub mod fmi3;
pub mod model_description;

use crate::observe::ObservableSpec;
use crate::scene::params::ParamSpec;
use crate::scene::registry::{FmuIdentity, SceneRow};
use crate::{Scene, SceneKind, Simulation};
use std::ffi::{CString, c_char, c_int, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// One FMU: a kind of scene (a registry row and its material choice) with
/// an FMU identity.
#[derive(Clone, Copy)]
pub struct Fmu(SceneKind, FmuIdentity);

impl std::fmt::Debug for Fmu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Fmu({})", self.identity().model_identifier)
    }
}

impl PartialEq for Fmu {
    fn eq(&self, other: &Self) -> bool {
        self.0 == other.0
    }
}

impl Fmu {
    /// Every FMU the registry declares, in its order.
    pub fn all() -> Vec<Fmu> {
        crate::scene::registry::fmus()
            .into_iter()
            .map(|(kind, id)| Fmu(kind, id))
            .collect()
    }

    /// The FMU whose model identifier is `id`.
    pub fn named(id: &str) -> Option<Fmu> {
        Fmu::all()
            .into_iter()
            .find(|f| f.identity().model_identifier == id)
    }

    /// The FMU whose instantiation token (GUID) is `token`.
    pub fn with_token(token: &str) -> Option<Fmu> {
        Fmu::all().into_iter().find(|f| f.token() == token)
    }

    /// The model identifier, name and description.
    pub fn identity(self) -> FmuIdentity {
        self.1
    }

    /// The scene row it packages.
    pub fn row(self) -> &'static SceneRow {
        self.0.row()
    }

    /// The scene kind it runs (its material choice included).
    pub fn kind(self) -> SceneKind {
        self.0
    }

    /// Every variable of the FMU: `time` (value reference 0, listed only in
    /// the FMI 3 model description), then the scene's parameters in table
    /// order (value references 1, 2, ...), then its observables in table
    /// order. This is the single source of the value references.
    pub fn variables(self) -> Vec<Variable> {
        let mut out = vec![Variable {
            vr: VR_TIME,
            name: "time",
            ty: VarType::Float64,
            kind: VarKind::Time,
        }];
        let mut vr = 1;
        for p in self.0.param_specs() {
            out.push(Variable {
                vr,
                name: p.name,
                ty: if !p.levels.is_empty() {
                    VarType::Enumeration
                } else if p.range.integer {
                    VarType::Int32
                } else {
                    VarType::Float64
                },
                kind: VarKind::Parameter(p),
            });
            vr += 1;
        }
        for (k, o) in self.0.observable_specs().iter().enumerate() {
            out.push(Variable {
                vr,
                name: o.name,
                ty: if o.is_bool() {
                    VarType::Boolean
                } else {
                    VarType::Float64
                },
                kind: VarKind::Output(k, o),
            });
            vr += 1;
        }
        out
    }

    /// The instantiation token (FMI 3) / GUID (FMI 2): a deterministic hash
    /// of the model identifier, the crate version and the generated
    /// variable list, formatted as a GUID.
    pub fn token(self) -> String {
        // 128-bit FNV-1a over a canonical text of everything a host relies on.
        let mut text = format!("{} {}\n", self.identity().model_identifier, crate::VERSION);
        for v in self.variables() {
            text.push_str(&format!("{} {} {:?} {}", v.vr, v.name, v.ty, v.unit()));
            if let VarKind::Parameter(p) = v.kind {
                text.push_str(&format!(" {:e} {}", p.default, p.range));
            }
            text.push('\n');
        }
        let mut h: u128 = 0x6c62272e07bb014262b821756295c58d;
        for b in text.bytes() {
            h ^= b as u128;
            h = h.wrapping_mul(0x0000000001000000000000000000013B);
        }
        let s = format!("{h:032x}");
        format!(
            "{{{}-{}-{}-{}-{}}}",
            &s[0..8],
            &s[8..12],
            &s[12..16],
            &s[16..20],
            &s[20..32]
        )
    }

    /// A serialized state of this FMU (`fmi3SerializeFMUState`,
    /// `fmi2SerializeFMUstate`) as JSON, to read it, or to forge one in a
    /// test: decoded field by field, not checked. An error says why the
    /// bytes are not a state of this version of the FMU.
    pub fn state_to_json(self, bytes: &[u8]) -> Result<serde_json::Value, String> {
        let saved = Saved::decode(self, bytes)?;
        serde_json::to_value(&saved).map_err(|e| format!("the state as JSON: {e}"))
    }

    /// Serialized state bytes of this FMU from JSON of the shape
    /// [`Fmu::state_to_json`] gives, encoded as the FMU encodes them but not
    /// checked: `fmi3DeserializeFMUState` checks them. An error says which
    /// part does not have the type of its field.
    pub fn state_from_json(self, json: serde_json::Value) -> Result<Vec<u8>, String> {
        let saved: Saved =
            serde_json::from_value(json).map_err(|e| format!("not an FMU state: {e}"))?;
        Ok(saved.serialize(self))
    }

    /// The FMU an instantiation asks for: the one whose token it gives, or
    /// with no token the first FMU; otherwise a message for the log.
    pub(crate) fn for_instantiation(function: &str, token: Option<&str>) -> Result<Fmu, String> {
        let Some(token) = token else {
            return Ok(Fmu::all()[0]);
        };
        Fmu::with_token(token).ok_or_else(|| {
            let known: Vec<String> = Fmu::all()
                .into_iter()
                .map(|f| format!("`{}` ({})", f.token(), f.identity().model_identifier))
                .collect();
            format!(
                "{function}: instantiation token `{token}` is not one of this library's FMUs: {}",
                known.join(", ")
            )
        })
    }
}

/// Log categories declared in the model description, with their meaning.
pub const LOG_CATEGORIES: &[(&str, &str)] = &[
    (
        "logStatusError",
        "errors: bad parameter values, calls in a state that does not allow them, solver stops",
    ),
    ("logStatusWarning", "warnings"),
    (
        "logEvents",
        "events: initialization, the rod coming to rest, end_time reached, reset, state restored",
    ),
    (
        "logProgress",
        "progress after every doStep: simulated time, steps taken, rod length",
    ),
];

const CAT_ERROR: usize = 0;
const CAT_WARNING: usize = 1;
const CAT_EVENTS: usize = 2;
const CAT_PROGRESS: usize = 3;

/// The FMI type of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VarType {
    /// `Float64` (FMI 3) / `Real` (FMI 2).
    Float64,
    /// `Int32` (FMI 3) / `Integer` (FMI 2).
    Int32,
    /// `Boolean`.
    Boolean,
    /// `Enumeration` (a parameter with named levels, the `scheme`): read and
    /// written as Int64 in FMI 3, declared as an `Integer` with its levels
    /// in the description in FMI 2 (read and written as Integer).
    Enumeration,
}

/// Where a variable's value lives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VarKind {
    /// The independent variable `time` (FMI 3 only).
    Time,
    /// A scene parameter: causality parameter, variability fixed.
    Parameter(&'static ParamSpec),
    /// An observable, by its index in the scene's observable table:
    /// causality output.
    Output(usize, &'static ObservableSpec),
}

/// One variable of the FMU.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Variable {
    /// Value reference.
    pub vr: u32,
    /// Name (the same as the CLI's).
    pub name: &'static str,
    /// FMI type.
    pub ty: VarType,
    /// What the variable is.
    pub kind: VarKind,
}

impl Variable {
    /// SI unit as written in the tables ("1" dimensionless, "bool" flag).
    pub fn unit(&self) -> &'static str {
        match self.kind {
            VarKind::Time => "s",
            VarKind::Parameter(p) => p.unit,
            VarKind::Output(_, o) => o.unit,
        }
    }

    /// One-line meaning.
    pub fn description(&self) -> &'static str {
        match self.kind {
            VarKind::Time => "simulated time",
            VarKind::Parameter(p) => p.description,
            VarKind::Output(_, o) => o.description,
        }
    }
}

/// Value reference of `time` (FMI 3).
pub const VR_TIME: u32 = 0;

/// Status codes; the numbers are those of `fmi3Status` and `fmi2Status`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[repr(i32)]
pub(crate) enum Status {
    Ok = 0,
    Warning = 1,
    Discard = 2,
    Error = 3,
    Fatal = 4,
}

// Instance states, one bit each, as in the Reference-FMUs.
pub(crate) const INSTANTIATED: u32 = 1 << 0;
pub(crate) const INITIALIZATION_MODE: u32 = 1 << 1;
/// FMI 3 step mode / FMI 2 stepComplete.
pub(crate) const STEP_MODE: u32 = 1 << 2;
/// FMI 2 stepFailed after a doStep that returned Discard (early stop).
pub(crate) const STEP_DISCARDED: u32 = 1 << 3;
pub(crate) const TERMINATED: u32 = 1 << 4;
pub(crate) const ANY_STATE: u32 =
    INSTANTIATED | INITIALIZATION_MODE | STEP_MODE | STEP_DISCARDED | TERMINATED;

/// Allowed states per function (both standards).
pub(crate) mod mask {
    use super::*;
    pub const SET_DEBUG_LOGGING: u32 = ANY_STATE;
    pub const SETUP_EXPERIMENT: u32 = INSTANTIATED;
    pub const ENTER_INITIALIZATION_MODE: u32 = INSTANTIATED;
    pub const EXIT_INITIALIZATION_MODE: u32 = INITIALIZATION_MODE;
    pub const TERMINATE: u32 = STEP_MODE | STEP_DISCARDED;
    pub const RESET: u32 = ANY_STATE;
    pub const GET: u32 = INITIALIZATION_MODE | STEP_MODE | STEP_DISCARDED | TERMINATED;
    pub const SET: u32 = INSTANTIATED | INITIALIZATION_MODE | STEP_MODE;
    pub const DO_STEP: u32 = STEP_MODE;
    pub const STATUS: u32 = STEP_MODE | STEP_DISCARDED | TERMINATED;
    pub const FMU_STATE: u32 = ANY_STATE;
}

fn state_name(state: u32) -> &'static str {
    match state {
        INSTANTIATED => "Instantiated",
        INITIALIZATION_MODE => "InitializationMode",
        STEP_MODE => "StepMode",
        STEP_DISCARDED => "StepDiscarded",
        TERMINATED => "Terminated",
        _ => "unknown",
    }
}

/// `fmi3LogMessageCallback`.
pub(crate) type Fmi3Logger = unsafe extern "C" fn(
    instance_environment: *mut c_void,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
);

/// `fmi2CallbackLogger` (the message is a printf format).
pub(crate) type Fmi2Logger = unsafe extern "C" fn(
    component_environment: *mut c_void,
    instance_name: *const c_char,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
    ...
);

/// The host's logger.
pub(crate) enum LogSink {
    None,
    Fmi3 {
        callback: Fmi3Logger,
        environment: *mut c_void,
    },
    Fmi2 {
        callback: Fmi2Logger,
        environment: *mut c_void,
    },
}

/// Which standard an instance was created through.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Standard {
    Fmi3,
    Fmi2,
}

/// What the last doStep reported.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct StepOutcome {
    pub terminate: bool,
    pub early_return: bool,
    pub last_successful_time: f64,
}

/// Rounding slack of a time computed from `a` and `b`: 1e-9 of |a| + |b|,
/// finite for any finite `a` and `b` (their sum may overflow: a slack of
/// infinity would accept any time).
fn slack(a: f64, b: f64) -> f64 {
    1e-9 * a.abs() + 1e-9 * b.abs()
}

/// Why a startTime and stopTime are not an experiment: startTime must be
/// finite, and a defined stopTime finite and not before it. A NaN stopTime
/// would disable the check of every step against it, one before startTime
/// would refuse every step.
fn experiment_error(start: f64, stop: Option<f64>) -> Option<String> {
    if !start.is_finite() {
        return Some(format!("startTime = {start} must be finite"));
    }
    match stop {
        Some(stop) if !(stop.is_finite() && stop >= start) => Some(format!(
            "stopTime = {stop} must be finite and not before startTime = {start}"
        )),
        _ => None,
    }
}

/// The part of an instance that a host saves and restores (FMU state).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub(crate) struct Saved {
    state: u32,
    scene: Scene,
    sim: Option<Simulation>,
    start_time: f64,
    /// The experiment's stopTime goes with its startTime: a host that
    /// restores a state after Reset, or in another instance, gets the
    /// experiment the run belongs to. (Absent in bytes from before: none.)
    #[serde(default)]
    stop_time: Option<f64>,
    time: f64,
    at_end: bool,
    last_successful_time: f64,
}

/// The first line of a serialized state, after the model identifier: the
/// version of its encoding. Version 2 is postcard; version 1 (JSON) is
/// refused with a message saying so.
const STATE_MAGIC: &[u8] = b" FMU state v2 postcard\n";

/// The first line of a version 1 (JSON) state, after the model identifier.
const STATE_MAGIC_V1: &[u8] = b" FMU state v1\n";

/// One FMU instance (FMI 3 or FMI 2).
pub(crate) struct Instance {
    pub standard: Standard,
    /// The FMU this instance is.
    pub fmu: Fmu,
    /// Its variables ([`Fmu::variables`]), made once.
    variables: Vec<Variable>,
    pub name: CString,
    log: LogSink,
    categories: [bool; 4],
    pub state: u32,
    /// Parameter values (set by the host before initialization).
    scene: Scene,
    /// The run; built lazily in initialization mode, always at its exit.
    sim: Option<Simulation>,
    /// Start time given by the host; simulated time 0 corresponds to it.
    pub start_time: f64,
    /// Stop time given by the host, if any; doStep refuses to go past it.
    pub stop_time: Option<f64>,
    /// Current communication point (host time).
    time: f64,
    /// The run has ended (rod at rest or end_time reached).
    at_end: bool,
    pub last_successful_time: f64,
    pub early_return_allowed: bool,
    /// Kept alive for `fmi2GetStringStatus`.
    pub status_string: CString,
}

impl Instance {
    pub(crate) fn new(
        standard: Standard,
        fmu: Fmu,
        name: &str,
        log: LogSink,
        logging_on: bool,
    ) -> Self {
        Instance {
            standard,
            fmu,
            variables: fmu.variables(),
            name: CString::new(name.replace('\0', "")).unwrap_or_default(),
            log,
            categories: [logging_on; 4],
            state: INSTANTIATED,
            scene: Scene::default_of(fmu.kind()),
            sim: None,
            start_time: 0.0,
            stop_time: None,
            time: 0.0,
            at_end: false,
            last_successful_time: 0.0,
            early_return_allowed: false,
            status_string: CString::default(),
        }
    }

    /// Sends a message to the host's logger. Errors always go out; other
    /// categories only when logging is on for them.
    pub(crate) fn log(&self, status: Status, category: usize, message: &str) {
        if category != CAT_ERROR && !self.categories[category] {
            return;
        }
        let cat = CString::new(LOG_CATEGORIES[category].0).expect("no NUL in category names");
        match self.log {
            LogSink::None => {}
            LogSink::Fmi3 {
                callback,
                environment,
            } => {
                let msg = CString::new(message.replace('\0', " ")).unwrap_or_default();
                // SAFETY: the host gave this callback and environment at
                // instantiation and guarantees them valid for the instance's
                // lifetime; the strings are NUL-terminated and outlive the call.
                unsafe { callback(environment, status as c_int, cat.as_ptr(), msg.as_ptr()) }
            }
            LogSink::Fmi2 {
                callback,
                environment,
            } => {
                // The FMI 2 message is a printf format: escape '%'.
                let msg =
                    CString::new(message.replace('\0', " ").replace('%', "%%")).unwrap_or_default();
                // SAFETY: as above; the format has no conversions left, so no
                // variadic arguments are read.
                unsafe {
                    callback(
                        environment,
                        self.name.as_ptr(),
                        status as c_int,
                        cat.as_ptr(),
                        msg.as_ptr(),
                    )
                }
            }
        }
    }

    /// Logs an error, moves to Terminated (Error leads to Terminated) and
    /// returns `Status::Error`.
    pub(crate) fn fail(&mut self, message: &str) -> Status {
        self.log(Status::Error, CAT_ERROR, message);
        self.state = TERMINATED;
        Status::Error
    }

    /// Checks that `function` may be called in the current state.
    pub(crate) fn check_state(&mut self, function: &str, mask: u32) -> Result<(), Status> {
        if self.state & mask == 0 {
            let msg = format!(
                "{function}: not allowed in state {}",
                state_name(self.state)
            );
            return Err(self.fail(&msg));
        }
        Ok(())
    }

    /// A getter or setter of a type this FMU has no variables of (FMI 3
    /// Float32, Int8, ..., String, Binary, Clock; FMI 2 String). In a state
    /// that allows `function` (`mask`, that of the getters or the setters)
    /// an empty list is OK and anything else an Error naming the first value
    /// reference, which is not `what`; in any other state, Error.
    pub(crate) fn no_variables(
        &mut self,
        function: &str,
        mask: u32,
        vrs: Option<&[u32]>,
        what: &str,
    ) -> Status {
        if let Err(s) = self.check_state(function, mask) {
            return s;
        }
        match vrs {
            Some([]) => Status::Ok,
            Some([vr, ..]) => self.fail(&format!("{function}: value reference {vr} is not {what}")),
            None => self.fail(&format!("{function}: the value references are NULL")),
        }
    }

    /// `fmi3SetDebugLogging` / `fmi2SetDebugLogging`.
    pub(crate) fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> Status {
        if categories.is_empty() {
            self.categories = [on; 4];
            return Status::Ok;
        }
        for c in categories {
            match LOG_CATEGORIES.iter().position(|(n, _)| n == c) {
                Some(k) => self.categories[k] = on,
                None => {
                    let allowed: Vec<_> = LOG_CATEGORIES.iter().map(|(n, _)| *n).collect();
                    return self.fail(&format!(
                        "unknown log category `{c}`; allowed: {}",
                        allowed.join(", ")
                    ));
                }
            }
        }
        Status::Ok
    }

    /// Records the experiment (`fmi2SetupExperiment`, the times given to
    /// `fmi3EnterInitializationMode`), or refuses it with Error naming the
    /// value: see [`experiment_error`].
    pub(crate) fn set_experiment(
        &mut self,
        function: &str,
        start: f64,
        stop: Option<f64>,
    ) -> Status {
        if let Some(e) = experiment_error(start, stop) {
            return self.fail(&format!("{function}: {e}"));
        }
        self.start_time = start;
        self.stop_time = stop;
        Status::Ok
    }

    /// Enters initialization mode at the experiment's start time.
    pub(crate) fn enter_initialization_mode(&mut self) -> Status {
        self.time = self.start_time;
        self.last_successful_time = self.start_time;
        self.state = INITIALIZATION_MODE;
        Status::Ok
    }

    /// Builds the simulation from the current parameters if needed.
    fn ensure_sim(&mut self) -> Result<(), Status> {
        if self.sim.is_none() {
            match Simulation::new(self.scene.clone()) {
                Ok(s) => self.sim = Some(s),
                Err(e) => return Err(self.fail(&e.to_string())),
            }
        }
        Ok(())
    }

    pub(crate) fn exit_initialization_mode(&mut self) -> Status {
        if let Err(s) = self.ensure_sim() {
            return s;
        }
        let sim = self.sim.as_ref().expect("built above");
        let first = &self.scene.param_specs()[0];
        let msg = format!(
            "initialized: {} particles, {} = {} {}, end_time = {} s",
            sim.particles(),
            first.name,
            self.scene.get(first.name).unwrap_or(f64::NAN),
            first.unit,
            sim.end_time()
        );
        self.log(Status::Ok, CAT_EVENTS, &msg);
        if let Some(stop) = self.stop_time
            && stop - self.start_time > sim.end_time()
        {
            let msg = format!(
                "stopTime = {stop} s lies beyond end_time = {} s after the start: the run ends at end_time at the latest",
                sim.end_time()
            );
            self.log(Status::Warning, CAT_WARNING, &msg);
        }
        self.at_end = sim.finished();
        self.state = STEP_MODE;
        Status::Ok
    }

    pub(crate) fn terminate(&mut self) -> Status {
        self.state = TERMINATED;
        Status::Ok
    }

    pub(crate) fn reset(&mut self) -> Status {
        self.state = INSTANTIATED;
        self.scene = Scene::default_of(self.fmu.kind());
        self.sim = None;
        self.start_time = 0.0;
        self.stop_time = None;
        self.time = 0.0;
        self.at_end = false;
        self.last_successful_time = 0.0;
        self.log(Status::Ok, CAT_EVENTS, "reset to the default parameters");
        Status::Ok
    }

    /// Looks up `vr` and checks its type.
    fn lookup(&mut self, vr: u32, ty: VarType, function: &str) -> Result<Variable, Status> {
        // The table is small (tens of rows): a linear lookup in the
        // instance's copy of [`Fmu::variables`], which allocates nothing.
        // FMI 2 reads and writes an enumeration as an Integer.
        let fmi2 = self.standard == Standard::Fmi2;
        let ty = if fmi2 && ty == VarType::Int32 {
            match self.variables.iter().find(|v| v.vr == vr) {
                Some(v) if v.ty == VarType::Enumeration => VarType::Enumeration,
                _ => ty,
            }
        } else {
            ty
        };
        match self.variables.iter().find(|v| v.vr == vr).copied() {
            Some(v) if v.ty == ty && !(fmi2 && v.kind == VarKind::Time) => Ok(v),
            Some(v) if v.ty != ty => Err(self.fail(&format!(
                "{function}: variable `{}` (value reference {vr}) is of type {:?}, not {:?}",
                v.name, v.ty, ty
            ))),
            _ => Err(self.fail(&format!("{function}: unknown value reference {vr}"))),
        }
    }

    /// Value of a variable as f64 (booleans as 0/1).
    fn value(&mut self, v: &Variable) -> Result<f64, Status> {
        match v.kind {
            VarKind::Time => Ok(self.time),
            VarKind::Parameter(p) => Ok(self
                .scene
                .get(p.name)
                .expect("the table and the scene agree")),
            VarKind::Output(k, _) => {
                self.ensure_sim()?;
                let sim = self.sim.as_ref().expect("built above");
                Ok(sim
                    .observable_at(k)
                    .expect("an output of the scene's table"))
            }
        }
    }

    /// Reads `vrs` of type `ty` as f64.
    pub(crate) fn get(
        &mut self,
        function: &str,
        vrs: &[u32],
        ty: VarType,
    ) -> Result<Vec<f64>, Status> {
        self.check_state(function, mask::GET)?;
        let mut out = Vec::with_capacity(vrs.len());
        for &vr in vrs {
            let v = self.lookup(vr, ty, function)?;
            out.push(self.value(&v)?);
        }
        Ok(out)
    }

    /// Sets `vrs` of type `ty` from f64 values.
    pub(crate) fn set(
        &mut self,
        function: &str,
        vrs: &[u32],
        values: &[f64],
        ty: VarType,
    ) -> Status {
        if let Err(s) = self.check_state(function, mask::SET) {
            return s;
        }
        for (&vr, &value) in vrs.iter().zip(values) {
            let v = match self.lookup(vr, ty, function) {
                Ok(v) => v,
                Err(s) => return s,
            };
            match v.kind {
                VarKind::Time => {
                    return self.fail(&format!(
                        "{function}: `time` is the independent variable and cannot be set"
                    ));
                }
                VarKind::Output(..) => {
                    return self.fail(&format!(
                        "{function}: `{}` is an output and cannot be set",
                        v.name
                    ));
                }
                VarKind::Parameter(p) => {
                    if self.state == STEP_MODE {
                        return self.fail(&format!(
                            "{function}: `{}` is a fixed parameter and cannot be changed after initialization",
                            p.name
                        ));
                    }
                    if let Err(e) = self.scene.set(p.name, value) {
                        return self.fail(&e.to_string());
                    }
                    // Rebuilt from the new parameters when next needed.
                    self.sim = None;
                }
            }
        }
        Status::Ok
    }

    /// Advances to `current + h`. Errors have been logged and moved the
    /// instance to Terminated.
    pub(crate) fn do_step(
        &mut self,
        function: &str,
        current: f64,
        h: f64,
    ) -> Result<StepOutcome, Status> {
        self.check_state(function, mask::DO_STEP)?;
        if h.is_nan() || h <= 0.0 || h.is_infinite() {
            return Err(self.fail(&format!(
                "{function}: communicationStepSize = {h} must be positive and finite"
            )));
        }
        // Hosts add up communication times in floating point: the current
        // time may differ from the FMU's in the last digits of the times
        // added (the start and the steps so far, not this step's size: a
        // huge step must not excuse any current time).
        let tol = slack(self.time, self.start_time);
        if !current.is_finite() || (current - self.time).abs() > tol {
            return Err(self.fail(&format!(
                "{function}: currentCommunicationPoint = {current} s does not match the FMU's time {} s",
                self.time
            )));
        }
        let target = current + h;
        // A step must end at a finite time after the current one: not at
        // infinity (a huge step from a huge time), not lost in rounding (a
        // small step from a huge time).
        if !target.is_finite() || target <= current {
            return Err(self.fail(&format!(
                "{function}: the step would end at t = {target} s (currentCommunicationPoint = {current} s + communicationStepSize = {h} s), not a finite time after the current one"
            )));
        }
        // FMI 2.0 (fmi2SetupExperiment) and FMI 3.0
        // (fmi3EnterInitializationMode): computing past a defined stopTime
        // is an error. Rounding slack: 1e-9 of |stopTime| + step size.
        if let Some(stop) = self.stop_time
            && target > stop + slack(stop, h)
        {
            return Err(self.fail(&format!(
                "{function}: the step would end at t = {target} s (currentCommunicationPoint = {current} s + communicationStepSize = {h} s), past stopTime = {stop} s"
            )));
        }
        if self.at_end {
            // The rod is at rest (or end_time passed): outputs hold.
            self.time = target;
            return Ok(StepOutcome {
                terminate: true,
                early_return: false,
                last_successful_time: target,
            });
        }
        let sim = self.sim.as_mut().expect("built at initialization");
        let result = sim.advance_to(target - self.start_time);
        if let Err(e) = result {
            let msg = format!("{function}: the solver stopped: {e}");
            return Err(self.fail(&msg));
        }
        let sim = self.sim.as_ref().expect("built at initialization");
        let sim_time = self.start_time + sim.time();
        let steps = sim.steps();
        let finished = sim.finished();
        if self.categories[CAT_PROGRESS] {
            // The scene's first observable (for a rod, its length), computed
            // only for a host that listens.
            let first = &sim.observable_specs()[0];
            let value = sim.observable_at(0).expect("every scene has observables");
            self.log(
                Status::Ok,
                CAT_PROGRESS,
                &format!(
                    "t = {sim_time:.6e} s, {steps} steps, {} = {value:.6e} {}",
                    first.name, first.unit
                ),
            );
        }
        if !finished {
            self.time = target;
            self.last_successful_time = target;
            return Ok(StepOutcome {
                terminate: false,
                early_return: false,
                last_successful_time: target,
            });
        }
        self.at_end = true;
        let sim = self.sim.as_ref().expect("built at initialization");
        let at_rest = sim.observable("at_rest").unwrap_or(0.0) != 0.0;
        let why = if at_rest {
            "the rod is at rest"
        } else {
            "end_time reached"
        };
        self.log(
            Status::Ok,
            CAT_EVENTS,
            &format!(
                "{why} at t = {sim_time:.6e} s after {steps} steps; outputs hold their final values"
            ),
        );
        // The run ended before the end of the step (beyond rounding).
        let early = sim_time < target - slack(current, h);
        let last = if early { sim_time } else { target };
        self.last_successful_time = last;
        Ok(StepOutcome {
            terminate: true,
            early_return: early,
            last_successful_time: last,
        })
    }

    /// Moves the communication time after a step (FMI 3: to the last
    /// successful time when returning early).
    pub(crate) fn set_time(&mut self, t: f64) {
        self.time = t;
    }

    /// Whether the run has ended (rod at rest or end_time).
    pub(crate) fn at_end(&self) -> bool {
        self.at_end
    }

    pub(crate) fn save(&self) -> Saved {
        Saved {
            state: self.state,
            scene: self.scene.clone(),
            sim: self.sim.clone(),
            start_time: self.start_time,
            stop_time: self.stop_time,
            time: self.time,
            at_end: self.at_end,
            last_successful_time: self.last_successful_time,
        }
    }

    pub(crate) fn restore(&mut self, s: &Saved) {
        self.state = s.state;
        self.scene = s.scene.clone();
        self.sim = s.sim.clone();
        self.start_time = s.start_time;
        self.stop_time = s.stop_time;
        self.time = s.time;
        self.at_end = s.at_end;
        self.last_successful_time = s.last_successful_time;
        self.log(
            Status::Ok,
            CAT_EVENTS,
            &format!("FMU state restored at t = {} s", self.time),
        );
    }
}

/// The first two lines of a serialized state of `fmu`: the model
/// identifier and [`STATE_MAGIC`], then the instantiation token.
fn state_header(fmu: Fmu) -> Vec<u8> {
    let mut out = fmu.identity().model_identifier.as_bytes().to_vec();
    out.extend_from_slice(STATE_MAGIC);
    out.extend_from_slice(fmu.token().as_bytes());
    out.push(b'\n');
    out
}

impl Saved {
    /// Bytes of this state of an instance of `fmu`: a magic line (the model
    /// identifier and the version of the encoding), the instantiation
    /// token, then the state in postcard (8 bytes per double, lengths and
    /// counts as varints; the same fields as [`Fmu::state_to_json`] shows).
    pub(crate) fn serialize(&self, fmu: Fmu) -> Vec<u8> {
        let mut out = state_header(fmu);
        postcard::to_io(self, &mut out).expect("a state encodes into a vector");
        out
    }

    /// The length of [`Saved::serialize`]'s bytes, counted without making
    /// them.
    pub(crate) fn serialized_len(&self, fmu: Fmu) -> usize {
        state_header(fmu).len() + crate::model::postcard_len(self)
    }

    /// Writes [`Saved::serialize`]'s bytes into `out` (a host's buffer),
    /// or says why not if it is not exactly their length.
    pub(crate) fn serialize_into(&self, fmu: Fmu, out: &mut [u8]) -> Result<(), String> {
        let len = self.serialized_len(fmu);
        if out.len() != len {
            return Err(format!(
                "size = {} but the serialized state has {len} bytes",
                out.len()
            ));
        }
        let header = state_header(fmu);
        let (head, body) = out.split_at_mut(header.len());
        head.copy_from_slice(&header);
        postcard::to_slice(self, body).expect("the length counted above");
        Ok(())
    }

    /// The state in [`Saved::serialize`] bytes of an instance of `fmu`,
    /// decoded but not checked: a message for the log if the bytes are not
    /// such a state of this version of `fmu`.
    fn decode(fmu: Fmu, bytes: &[u8]) -> Result<Saved, String> {
        let id = fmu.identity().model_identifier;
        let after_id = bytes.strip_prefix(id.as_bytes());
        if after_id.is_some_and(|r| r.starts_with(STATE_MAGIC_V1)) {
            return Err(format!(
                "the bytes are a version 1 (JSON) {id} FMU state of an older build; this one reads version 2 (postcard)"
            ));
        }
        let rest = after_id
            .and_then(|r| r.strip_prefix(STATE_MAGIC))
            .ok_or_else(|| format!("the bytes are not a serialized {id} FMU state"))?;
        let rest = rest
            .strip_prefix(fmu.token().as_bytes())
            .and_then(|r| r.strip_prefix(b"\n"))
            .ok_or("the serialized state comes from a different version of the FMU")?;
        let (saved, left) = postcard::take_from_bytes::<Saved>(rest)
            .map_err(|e| format!("invalid serialized state: {e}"))?;
        if !left.is_empty() {
            return Err(format!(
                "invalid serialized state: {} bytes follow its end",
                left.len()
            ));
        }
        Ok(saved)
    }

    /// Parses [`Saved::serialize`] bytes of an instance of `fmu`, and checks
    /// the state as a new instance's values and run are checked.
    pub(crate) fn deserialize(fmu: Fmu, bytes: &[u8]) -> Result<Saved, String> {
        let saved = Saved::decode(fmu, bytes)?;
        if saved.state & ANY_STATE == 0 || saved.state.count_ones() != 1 {
            return Err("invalid serialized state: unknown instance state".into());
        }
        // Checked as a new instance's values and run are: a forged state is
        // refused here, not found out by a later step.
        saved
            .scene
            .validate()
            .map_err(|e| format!("invalid serialized state: its parameters: {e}"))?;
        let times = [saved.start_time, saved.time, saved.last_successful_time];
        if !times.iter().all(|t| t.is_finite()) || saved.time < saved.start_time {
            return Err("invalid serialized state: its communication times are not valid".into());
        }
        if let Some(e) = experiment_error(saved.start_time, saved.stop_time) {
            return Err(format!("invalid serialized state: its experiment: {e}"));
        }
        if saved.scene.kind() != fmu.kind() {
            return Err(format!(
                "invalid serialized state: its parameters are not the `{}` scene's",
                fmu.kind().name()
            ));
        }
        // An FMU's scene keeps the reference values of its kind (no
        // variable sets them): anything else, a NaN say, is forged.
        if saved.scene.reference != Scene::default_of(fmu.kind()).reference {
            return Err(
                "invalid serialized state: its reference values are not the scene's".into(),
            );
        }
        // The run is there exactly when an instance in that state has one,
        // and it is the run of the instance's parameters (those it reports).
        let run = match (&saved.sim, saved.state) {
            (None, STEP_MODE | STEP_DISCARDED) => Err("it is past initialization but holds no run"),
            (Some(_), INSTANTIATED) => Err("it holds a run before initialization"),
            (Some(sim), _) if sim.scene() != &saved.scene => {
                Err("its run is not one of its parameters")
            }
            (Some(sim), INITIALIZATION_MODE) if sim.steps() != 0 => {
                Err("its run has stepped before the end of initialization")
            }
            _ => Ok(()),
        };
        run.map_err(|e| format!("invalid serialized state: {e}"))?;
        if let Some(sim) = &saved.sim {
            sim.check_restored()
                .map_err(|e| format!("invalid serialized state: {e}"))?;
        }
        Ok(saved)
    }
}

/// Runs `f`, turning a panic into `fallback`: nothing unwinds into the host.
pub(crate) fn guard<R>(fallback: R, f: impl FnOnce() -> R) -> R {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or(fallback)
}

/// Runs `f` on the instance behind `ptr` with a panic boundary. A null
/// instance gives `Status::Error`; a panic is logged as Fatal, drops the
/// (possibly inconsistent) simulation and leaves the instance Terminated.
///
/// # Safety
/// `ptr` must be null or an instance created by this library and not freed.
pub(crate) unsafe fn with_instance(
    ptr: *mut c_void,
    f: impl FnOnce(&mut Instance) -> Status,
) -> Status {
    if ptr.is_null() {
        return Status::Error;
    }
    // SAFETY: by the contract above, a non-null `ptr` is a live
    // `Box<Instance>` from `into_raw`; FMI forbids concurrent calls on one
    // instance, so this is the only reference.
    let inst = unsafe { &mut *(ptr as *mut Instance) };
    match catch_unwind(AssertUnwindSafe(|| f(&mut *inst))) {
        Ok(s) => s,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            let _ = catch_unwind(AssertUnwindSafe(|| {
                inst.sim = None;
                inst.state = TERMINATED;
                inst.log(
                    Status::Fatal,
                    CAT_ERROR,
                    &format!("internal error (panic): {what}"),
                );
            }));
            Status::Fatal
        }
    }
}

/// Reads a C array; an empty slice when `n == 0`.
///
/// # Safety
/// `p` must point to `n` readable elements when `n > 0`.
pub(crate) unsafe fn slice<'a, T>(p: *const T, n: usize) -> Option<&'a [T]> {
    if n == 0 {
        return Some(&[]);
    }
    if p.is_null() {
        return None;
    }
    // SAFETY: non-null and, by the contract, valid for `n` elements.
    Some(unsafe { std::slice::from_raw_parts(p, n) })
}

/// Writes into a C array.
///
/// # Safety
/// `p` must point to `n` writable elements when `n > 0`.
pub(crate) unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Option<&'a mut [T]> {
    if n == 0 {
        return Some(&mut []);
    }
    if p.is_null() {
        return None;
    }
    // SAFETY: non-null and, by the contract, valid for `n` elements with no
    // other live reference.
    Some(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

/// Reads a C string (lossy UTF-8); `None` for null.
///
/// # Safety
/// `p` must be null or a NUL-terminated string.
pub(crate) unsafe fn c_str(p: *const c_char) -> Option<String> {
    if p.is_null() {
        return None;
    }
    // SAFETY: non-null and NUL-terminated by the contract.
    Some(
        unsafe { std::ffi::CStr::from_ptr(p) }
            .to_string_lossy()
            .into_owned(),
    )
}

/// The Taylor FMU, for the tests of this module and its children.
#[cfg(test)]
pub(crate) fn taylor_fmu() -> Fmu {
    Fmu::named("TaylorImpact").expect("the registry declares the Taylor FMU")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::observe::TAYLOR_OBSERVABLES;
    use crate::scene::taylor::TAYLOR_PARAMS;

    #[test]
    fn variables_follow_the_tables() {
        let vars = taylor_fmu().variables();
        assert_eq!(
            vars.len(),
            1 + TAYLOR_PARAMS.len() + TAYLOR_OBSERVABLES.len()
        );
        assert_eq!(vars[0].name, "time");
        for (k, v) in vars.iter().enumerate() {
            assert_eq!(v.vr as usize, k, "value references are dense");
        }
        let pr = vars.iter().find(|v| v.name == "particles_radial").unwrap();
        assert_eq!(pr.ty, VarType::Int32);
        let rest = vars.iter().find(|v| v.name == "at_rest").unwrap();
        assert_eq!(rest.ty, VarType::Boolean);
        assert!(
            vars.iter()
                .all(|v| !matches!(v.name, "shock_radius" | "post_shock_density"))
        );
    }

    #[test]
    fn one_library_serves_every_fmu_of_the_registry() {
        let all = Fmu::all();
        assert!(all.contains(&taylor_fmu()));
        for (k, f) in all.iter().enumerate() {
            let id = f.identity().model_identifier;
            assert_eq!(Fmu::named(id), Some(*f), "{id}");
            assert_eq!(Fmu::with_token(&f.token()), Some(*f), "{id}");
            assert_eq!(Fmu::for_instantiation("x", Some(&f.token())), Ok(*f));
            for g in &all[k + 1..] {
                assert_ne!(id, g.identity().model_identifier);
                assert_ne!(f.token(), g.token());
            }
            // Its variables are its scene's tables.
            let n = 1 + f.kind().param_specs().len() + f.row().observables.len();
            assert_eq!(f.variables().len(), n, "{id}");
            assert_eq!(
                Instance::new(Standard::Fmi3, *f, "t", LogSink::None, false)
                    .scene
                    .kind(),
                f.kind()
            );
        }
        // No token: the first FMU; an unknown one: an error naming the known.
        assert_eq!(Fmu::for_instantiation("x", None), Ok(all[0]));
        let e = Fmu::for_instantiation("fmi3InstantiateCoSimulation", Some("{nope}")).unwrap_err();
        assert!(
            e.contains("`{nope}`") && e.contains(&taylor_fmu().token()),
            "{e}"
        );
        assert!(e.contains("TaylorImpact"), "{e}");
    }

    #[test]
    fn token_is_deterministic_and_guid_shaped() {
        let t = taylor_fmu().token();
        assert_eq!(t, taylor_fmu().token());
        assert_eq!(t.len(), 38);
        assert!(t.starts_with('{') && t.ends_with('}'));
    }

    /// The value reference of a variable of the Taylor FMU.
    fn vr_of(name: &str) -> u32 {
        vr_in(taylor_fmu(), name)
    }

    /// The value reference of a variable of `fmu`.
    fn vr_in(fmu: Fmu, name: &str) -> u32 {
        fmu.variables().iter().find(|v| v.name == name).unwrap().vr
    }

    /// A new instance at 4 particles across the radius (cheap steps).
    fn coarse(standard: Standard) -> Instance {
        let mut inst = Instance::new(standard, taylor_fmu(), "t", LogSink::None, false);
        let pr = vr_of("particles_radial");
        assert_eq!(inst.set("set", &[pr], &[4.0], VarType::Int32), Status::Ok);
        inst
    }

    #[test]
    fn fixed_parameter_refused_after_initialization_and_bad_values_named() {
        let mut inst = Instance::new(Standard::Fmi3, taylor_fmu(), "t", LogSink::None, false);
        let density = vr_of("density");
        assert_eq!(
            inst.set("fmi3SetFloat64", &[density], &[-5.0], VarType::Float64),
            Status::Error
        );
        assert_eq!(inst.state, TERMINATED);
        inst.reset();
        let pr = vr_of("particles_radial");
        assert_eq!(
            inst.set("fmi3SetInt32", &[pr], &[5.0], VarType::Int32),
            Status::Ok
        );
        assert_eq!(inst.enter_initialization_mode(), Status::Ok);
        assert_eq!(inst.exit_initialization_mode(), Status::Ok);
        assert_eq!(
            inst.set("fmi3SetFloat64", &[density], &[7000.0], VarType::Float64),
            Status::Error
        );
        assert_eq!(inst.state, TERMINATED);
    }

    /// A logger that keeps the messages (environment: a `Vec<String>`).
    unsafe extern "C" fn keep(
        env: *mut c_void,
        _status: c_int,
        _category: *const c_char,
        message: *const c_char,
    ) {
        // SAFETY: the test's vector, not otherwise borrowed during the call;
        // a NUL-terminated message.
        unsafe {
            (*(env as *mut Vec<String>)).push(
                std::ffi::CStr::from_ptr(message)
                    .to_string_lossy()
                    .into_owned(),
            )
        }
    }

    #[test]
    fn experiment_times_are_checked_and_named() {
        let bad = [
            (0.0, Some(f64::NAN), "stopTime = NaN"),
            (0.0, Some(f64::INFINITY), "stopTime = inf"),
            (0.0, Some(f64::NEG_INFINITY), "stopTime = -inf"),
            (
                2e-6,
                Some(1e-6),
                "stopTime = 0.000001 must be finite and not before startTime = 0.000002",
            ),
            (f64::NAN, None, "startTime = NaN"),
        ];
        for (start, stop, named) in bad {
            let mut messages: Vec<String> = Vec::new();
            let log = LogSink::Fmi3 {
                callback: keep,
                environment: &mut messages as *mut Vec<String> as *mut c_void,
            };
            let mut inst = Instance::new(Standard::Fmi3, taylor_fmu(), "t", log, false);
            assert_eq!(inst.set_experiment("f", start, stop), Status::Error);
            assert_eq!(inst.state, TERMINATED);
            assert_eq!(inst.stop_time, None, "{named}: not recorded");
            drop(inst);
            assert_eq!(messages.len(), 1);
            assert!(
                messages[0].contains(named),
                "{messages:?} should name {named}"
            );
        }
        let mut inst = Instance::new(Standard::Fmi3, taylor_fmu(), "t", LogSink::None, false);
        assert_eq!(inst.set_experiment("f", 1e-6, Some(1e-6)), Status::Ok);
        assert_eq!((inst.start_time, inst.stop_time), (1e-6, Some(1e-6)));
    }

    #[test]
    fn step_past_stop_time_is_an_error() {
        let start = |stop: Option<f64>| {
            let mut inst = coarse(Standard::Fmi2);
            inst.stop_time = stop;
            assert_eq!(inst.enter_initialization_mode(), Status::Ok);
            assert_eq!(inst.exit_initialization_mode(), Status::Ok);
            inst
        };
        // Six steps of 0.3 us end one ulp past 1.8 us: rounding, accepted.
        let mut inst = start(Some(1.8e-6));
        let mut t = 0.0;
        for _ in 0..6 {
            inst.do_step("doStep", t, 3e-7).unwrap();
            t += 3e-7;
        }
        assert!(t > 1.8e-6, "the sum overshoots, so the tolerance is used");
        assert_eq!(inst.state, STEP_MODE);
        // One more step goes past stopTime.
        assert_eq!(inst.do_step("doStep", t, 3e-7).unwrap_err(), Status::Error);
        assert_eq!(inst.state, TERMINATED);
        // A single step just past it (1e-6 of stopTime), from the start.
        let mut inst = start(Some(1.8e-6));
        assert_eq!(
            inst.do_step("doStep", 0.0, 1.8e-6 * (1.0 + 1e-6))
                .unwrap_err(),
            Status::Error
        );
        // Without a stop time the same step is fine.
        let mut inst = start(None);
        assert!(inst.do_step("doStep", 0.0, 1.8e-6 * (1.0 + 1e-6)).is_ok());
    }

    /// Serialized state bytes decoded to the typed state, edited by `edit`
    /// in its JSON form, and encoded again (unchecked).
    fn forge(bytes: &[u8], edit: impl FnOnce(&mut serde_json::Value)) -> Vec<u8> {
        let mut json = taylor_fmu().state_to_json(bytes).unwrap();
        edit(&mut json);
        taylor_fmu().state_from_json(json).unwrap()
    }

    /// Found by the FMU call-order fuzzer: a state in step mode without its
    /// run was accepted, and the next doStep panicked (Fatal). A run and
    /// parameters that do not belong together are refused as well: the
    /// outputs would not be those of the parameters, and a Noh run or scene
    /// has none of the Taylor variables.
    #[test]
    fn states_whose_run_does_not_fit_are_refused() {
        let mut inst = coarse(Standard::Fmi3);
        inst.enter_initialization_mode();
        let init = inst.save().serialize(taylor_fmu());
        inst.exit_initialization_mode();
        inst.do_step("doStep", 0.0, 1e-6).unwrap();
        let stepped = inst.save().serialize(taylor_fmu());
        let mut other = Scene::builtin("taylor").unwrap();
        other.set("particles_radial", 5.0).unwrap();
        let other = serde_json::to_value(Simulation::new(other).unwrap()).unwrap();
        let mut noh = Scene::builtin("noh").unwrap();
        noh.set("particles_radial", 100.0).unwrap();
        let noh = serde_json::to_value(Simulation::new(noh).unwrap()).unwrap();
        let refused = |bytes: &[u8], why: &str| {
            let e = Saved::deserialize(taylor_fmu(), bytes).unwrap_err();
            assert!(e.contains(why), "{e} should say {why}");
        };
        refused(
            &forge(&stepped, |j| j["sim"] = serde_json::Value::Null),
            "holds no run",
        );
        let mut done = forge(&stepped, |j| j["sim"] = serde_json::Value::Null);
        done = forge(&done, |j| j["state"] = serde_json::json!(STEP_DISCARDED));
        refused(&done, "holds no run");
        refused(
            &forge(&stepped, |j| j["state"] = serde_json::json!(INSTANTIATED)),
            "before initialization",
        );
        refused(
            &forge(&stepped, |j| {
                j["state"] = serde_json::json!(INITIALIZATION_MODE)
            }),
            "stepped",
        );
        refused(
            &forge(&stepped, |j| j["sim"] = other.clone()),
            "not one of its parameters",
        );
        refused(
            &forge(&stepped, |j| j["sim"] = noh.clone()),
            "not one of its parameters",
        );
        refused(
            &forge(&init, |j| j["scene"] = noh["scene"].clone()),
            "not the `taylor` scene's",
        );
        // The honest states load, and one without a run where that is right.
        assert!(Saved::deserialize(taylor_fmu(), &stepped).is_ok());
        assert!(Saved::deserialize(taylor_fmu(), &init).is_ok());
        let ended = forge(&stepped, |j| {
            j["sim"] = serde_json::Value::Null;
            j["state"] = serde_json::json!(TERMINATED);
        });
        assert!(Saved::deserialize(taylor_fmu(), &ended).is_ok());
    }

    /// Found by the FMU call-order fuzzer: the stopTime was not part of the
    /// FMU state, so a state restored after Reset (or deserialized into a
    /// new instance) stepped past the stopTime of its experiment.
    #[test]
    fn the_stop_time_is_part_of_the_state() {
        let mut inst = coarse(Standard::Fmi3);
        assert_eq!(inst.set_experiment("f", 0.0, Some(2e-6)), Status::Ok);
        inst.enter_initialization_mode();
        inst.exit_initialization_mode();
        inst.do_step("doStep", 0.0, 1e-6).unwrap();
        let saved = inst.save();
        let bytes = saved.serialize(taylor_fmu());
        inst.reset();
        assert_eq!(inst.stop_time, None);
        inst.restore(&saved);
        assert_eq!(inst.stop_time, Some(2e-6));
        assert_eq!(
            inst.do_step("doStep", 1e-6, 2e-6).unwrap_err(),
            Status::Error
        );
        let mut other = Instance::new(Standard::Fmi2, taylor_fmu(), "u", LogSink::None, false);
        other.restore(&Saved::deserialize(taylor_fmu(), &bytes).unwrap());
        assert_eq!(other.stop_time, Some(2e-6));
        assert!(
            other.do_step("doStep", 1e-6, 1e-6).is_ok(),
            "up to stopTime"
        );
        assert_eq!(
            other.do_step("doStep", 2e-6, 1e-6).unwrap_err(),
            Status::Error
        );
        // A forged experiment is refused; bytes without a stopTime (as
        // before) load without one.
        let before = forge(&bytes, |j| j["stop_time"] = serde_json::json!(-1e-6));
        let e = Saved::deserialize(taylor_fmu(), &before).unwrap_err();
        assert!(
            e.contains("stopTime = -0.000001 must be finite and not before"),
            "{e}"
        );
        let old = forge(&bytes, |j| {
            j.as_object_mut().unwrap().remove("stop_time");
        });
        assert_eq!(
            Saved::deserialize(taylor_fmu(), &old).unwrap().stop_time,
            None
        );
    }

    /// The bytes of a coarse FMI 3 state after one step.
    fn stepped_bytes() -> Vec<u8> {
        let mut inst = coarse(Standard::Fmi3);
        inst.enter_initialization_mode();
        inst.exit_initialization_mode();
        inst.do_step("doStep", 0.0, 1e-6).unwrap();
        inst.save().serialize(taylor_fmu())
    }

    #[test]
    fn cut_lengthened_foreign_and_old_states_are_refused() {
        let fmu = taylor_fmu();
        let bytes = stepped_bytes();
        let header = state_header(fmu).len();
        assert!(bytes.starts_with(b"TaylorImpact FMU state v2 postcard\n{"));
        assert_eq!(
            Saved::serialize(&Saved::deserialize(fmu, &bytes).unwrap(), fmu),
            bytes
        );
        let cuts = (0..bytes.len())
            .step_by(37)
            .chain(bytes.len() - 40..bytes.len());
        for len in cuts {
            let e = Saved::deserialize(fmu, &bytes[..len]).unwrap_err();
            let named = if len < header {
                e == "the bytes are not a serialized TaylorImpact FMU state"
                    || e == "the serialized state comes from a different version of the FMU"
            } else {
                e.starts_with("invalid serialized state: ")
            };
            assert!(named, "cut to {len}: {e}");
        }
        let mut longer = bytes.clone();
        longer.push(0);
        let e = Saved::deserialize(fmu, &longer).unwrap_err();
        assert!(e.contains("1 bytes follow its end"), "{e}");
        // A state of another FMU, of another build, of the JSON encoding.
        let foreign = [b"NohImpact".as_slice(), &bytes[12..]].concat();
        let e = Saved::deserialize(fmu, &foreign).unwrap_err();
        assert_eq!(e, "the bytes are not a serialized TaylorImpact FMU state");
        let mut other = bytes.clone();
        other[header - 3] ^= 1;
        let e = Saved::deserialize(fmu, &other).unwrap_err();
        assert!(e.contains("different version"), "{e}");
        let json = fmu.state_to_json(&bytes).unwrap();
        let v1 = format!("TaylorImpact FMU state v1\n{}\n{json}", fmu.token());
        let e = Saved::deserialize(fmu, v1.as_bytes()).unwrap_err();
        assert!(e.contains("version 1 (JSON)"), "{e}");
    }

    /// The forgeries the fmpy tests made when the state was JSON, now made
    /// on the typed state: each refused, naming what is wrong.
    #[test]
    fn forged_parameters_masses_particles_and_records_are_refused() {
        let bytes = stepped_bytes();
        type Edit = fn(&mut serde_json::Value);
        let edits: [(Edit, &str); 4] = [
            (
                |j| j["scene"]["params"]["Taylor"]["density"] = serde_json::json!(-5.0),
                "density",
            ),
            (
                |j| j["sim"]["solver"]["Taylor"]["mass"][0] = serde_json::json!(1.0),
                "masses",
            ),
            (
                |j| {
                    j["sim"]["solver"]["Taylor"]["vel"]
                        .as_array_mut()
                        .unwrap()
                        .pop();
                },
                "velocities",
            ),
            (
                |j| j["sim"]["record_interval"] = serde_json::json!(0.0),
                "record",
            ),
        ];
        for (edit, why) in edits {
            match Saved::deserialize(taylor_fmu(), &forge(&bytes, edit)) {
                Ok(_) => panic!("{why}: the forged state was accepted"),
                Err(e) => assert!(e.contains(why), "{e} should name {why}"),
            }
        }
        assert!(Saved::deserialize(taylor_fmu(), &forge(&bytes, |_| {})).is_ok());
    }

    /// Doubles can be NaN or infinite in postcard (not in JSON): each of a
    /// state's doubles, replaced by one of them wherever its bits stand,
    /// makes a state that is refused.
    #[test]
    fn non_finite_numbers_anywhere_in_a_state_are_refused() {
        let fmu = taylor_fmu();
        let bytes = stepped_bytes();
        let header = state_header(fmu).len();
        fn floats(v: &serde_json::Value, out: &mut Vec<f64>) {
            match v {
                serde_json::Value::Number(n) if n.is_f64() => out.push(n.as_f64().unwrap()),
                serde_json::Value::Array(a) => a.iter().for_each(|x| floats(x, out)),
                serde_json::Value::Object(o) => o.values().for_each(|x| floats(x, out)),
                _ => {}
            }
        }
        let mut values = Vec::new();
        floats(&fmu.state_to_json(&bytes).unwrap(), &mut values);
        // Whole numbers (0, 1, ...) also stand in the bytes of larger ones.
        values.retain(|x| x.fract() != 0.0);
        values.sort_by(f64::total_cmp);
        values.dedup();
        assert!(values.len() > 500, "{}", values.len());
        let mut forged = 0;
        for (k, v) in values.iter().enumerate() {
            let bad = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY][k % 3];
            let pattern = v.to_le_bytes();
            let mut data = bytes.clone();
            let mut at = header;
            let mut found = false;
            while at + 8 <= data.len() {
                if data[at..at + 8] == pattern {
                    data[at..at + 8].copy_from_slice(&bad.to_le_bytes());
                    found = true;
                    at += 8;
                } else {
                    at += 1;
                }
            }
            assert!(found, "{v} is in the bytes");
            forged += 1;
            match Saved::deserialize(fmu, &data) {
                Ok(_) => panic!("{v} -> {bad}: the state was accepted"),
                Err(e) => assert!(
                    e.starts_with("invalid serialized state: "),
                    "{v} -> {bad}: {e}"
                ),
            }
        }
        assert_eq!(forged, values.len());
    }

    /// An initialized FMI 3 instance of the 3-D FMU at 3 nodes across the
    /// radius.
    fn taylor3d_instance() -> Instance {
        let fmu = Fmu::named("Taylor3dImpact").expect("the registry declares the 3-D FMU");
        let mut inst = Instance::new(Standard::Fmi3, fmu, "t3d", LogSink::None, false);
        let pr = vr_in(fmu, "particles_radial");
        assert_eq!(inst.set("set", &[pr], &[3.0], VarType::Int32), Status::Ok);
        assert_eq!(inst.enter_initialization_mode(), Status::Ok);
        assert_eq!(inst.exit_initialization_mode(), Status::Ok);
        inst
    }

    /// Steps `inst` from `t` by 1 us until the run ends; the bits of its
    /// outputs, its clock and every particle field then.
    fn bits_at_the_end(inst: &mut Instance, mut t: f64) -> Vec<u64> {
        while !inst.do_step("doStep", t, 1e-6).unwrap().terminate {
            t += 1e-6;
        }
        run_bits(inst.sim.as_ref().unwrap())
    }

    /// The bits of a run's clock, outputs and particle fields.
    fn run_bits(sim: &Simulation) -> Vec<u64> {
        let mut v = vec![sim.time(), sim.steps() as f64];
        v.extend(sim.observables());
        for f in sim.field_specs() {
            v.extend(sim.field(f.name).unwrap());
        }
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// The 3-D FMU's state: a run saved mid-way (its postcard bytes),
    /// restored into another instance and stepped to the end, gives the
    /// bits of the run that was not interrupted, and of `Simulation` on
    /// the same scene; forged states are refused with what is wrong.
    #[test]
    fn taylor3d_fmu_state_resumes_to_the_bits_of_the_whole_run() {
        let mut whole = taylor3d_instance();
        let fmu = whole.fmu;
        let whole_bits = bits_at_the_end(&mut whole, 0.0);
        let mut scene = Scene::builtin("taylor3d").unwrap();
        scene.set("particles_radial", 3.0).unwrap();
        let mut sim = Simulation::new(scene).unwrap();
        sim.run().unwrap();
        assert_eq!(sim.observable("at_rest"), Some(1.0));
        assert_eq!(whole_bits, run_bits(&sim), "the FMU runs the scene's run");
        let mut inst = taylor3d_instance();
        let mut t = 0.0;
        for _ in 0..10 {
            inst.do_step("doStep", t, 1e-6).unwrap();
            t += 1e-6;
        }
        let bytes = inst.save().serialize(fmu);
        assert!(bytes.starts_with(b"Taylor3dImpact FMU state v2 postcard\n{"));
        let mut other = Instance::new(Standard::Fmi2, fmu, "u", LogSink::None, false);
        other.restore(&Saved::deserialize(fmu, &bytes).unwrap());
        assert_eq!(bits_at_the_end(&mut other, t), whole_bits, "restored");
        assert_eq!(bits_at_the_end(&mut inst, t), whole_bits, "not saved");

        // Forged: each refused, naming what is wrong; a Taylor state too.
        let forge = |edit: fn(&mut serde_json::Value)| {
            let mut json = fmu.state_to_json(&bytes).unwrap();
            edit(&mut json);
            fmu.state_from_json(json).unwrap()
        };
        type Edit = fn(&mut serde_json::Value);
        let edits: [(Edit, &str); 4] = [
            (
                |j| j["sim"]["solver"]["Taylor3d"]["mass"][0] = serde_json::json!(1.0),
                "masses",
            ),
            (
                |j| {
                    j["sim"]["solver"]["Taylor3d"]["pos"]
                        .as_array_mut()
                        .unwrap()
                        .pop();
                },
                "positions",
            ),
            (
                |j| j["sim"]["solver"]["Taylor3d"]["temp"][4] = serde_json::json!(-1.0),
                "temperatures",
            ),
            (
                |j| j["scene"]["params"]["Taylor3d"]["damping"] = serde_json::json!(0.9),
                "damping",
            ),
        ];
        for (edit, why) in edits {
            match Saved::deserialize(fmu, &forge(edit)) {
                Ok(_) => panic!("{why}: the forged state was accepted"),
                Err(e) => assert!(e.contains(why), "{e} should name {why}"),
            }
        }
        assert!(Saved::deserialize(fmu, &forge(|_| {})).is_ok());
        let e = Saved::deserialize(fmu, &stepped_bytes()).unwrap_err();
        assert_eq!(e, "the bytes are not a serialized Taylor3dImpact FMU state");
        let e = Saved::deserialize(taylor_fmu(), &bytes).unwrap_err();
        assert_eq!(e, "the bytes are not a serialized TaylorImpact FMU state");
        // A NaN or an infinity in place of the internal energy (postcard
        // holds them; JSON cannot).
        let energy =
            fmu.state_to_json(&bytes).unwrap()["sim"]["solver"]["Taylor3d"]["internal_energy"]
                .as_f64()
                .unwrap();
        assert!(energy > 0.0);
        for bad in [f64::NAN, f64::INFINITY] {
            let mut data = bytes.clone();
            let at = data
                .windows(8)
                .position(|w| w == energy.to_le_bytes())
                .expect("the energy is in the bytes");
            data[at..at + 8].copy_from_slice(&bad.to_le_bytes());
            let e = Saved::deserialize(fmu, &data).unwrap_err();
            assert!(e.contains("clock and energies"), "{bad}: {e}");
        }
    }

    #[test]
    fn state_round_trips_through_bytes() {
        let mut inst = coarse(Standard::Fmi3);
        inst.enter_initialization_mode();
        inst.exit_initialization_mode();
        inst.do_step("doStep", 0.0, 1e-6).unwrap();
        let bytes = inst.save().serialize(taylor_fmu());
        let saved = Saved::deserialize(taylor_fmu(), &bytes).unwrap();
        let out = inst.do_step("doStep", 1e-6, 1e-6).unwrap();
        let a = inst.sim.as_ref().unwrap().observables();
        inst.restore(&saved);
        let out2 = inst.do_step("doStep", 1e-6, 1e-6).unwrap();
        assert_eq!(out.last_successful_time, out2.last_successful_time);
        let b = inst.sim.as_ref().unwrap().observables();
        assert_eq!(
            a.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            b.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
        assert!(Saved::deserialize(taylor_fmu(), b"nonsense").is_err());
    }
}
