//! The instance life cycle, shared by both standards: the [`Instance`] a
//! host holds, its states (one bit each) and the mask of states each
//! function is allowed in, the [`Status`] codes, the experiment, entering
//! and leaving initialization, terminate and reset; and [`with_instance`],
//! the panic boundary around every call on an instance.

use super::fmu::{Fmu, Variable};
use super::log::{CAT_ERROR, CAT_EVENTS, CAT_WARNING, LogSink, category_names, set_categories};
use crate::ffi::panic_text;
use crate::{Scene, Simulation};
use std::ffi::{CString, c_char, c_int, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};

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
/// FMI 2 stepFailed: reached only by restoring a state saved by an earlier
/// build of this FMU, whose doStep returned Discard at the scene's end.
pub(crate) const STEP_DISCARDED: u32 = 1 << 3;
pub(crate) const TERMINATED: u32 = 1 << 4;
pub(crate) const ANY_STATE: u32 =
    INSTANTIATED | INITIALIZATION_MODE | STEP_MODE | STEP_DISCARDED | TERMINATED;

/// Allowed states per function (both standards).
pub(crate) mod mask {
    use super::{
        ANY_STATE, INITIALIZATION_MODE, INSTANTIATED, STEP_DISCARDED, STEP_MODE, TERMINATED,
    };
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

/// Which standard an instance was created through.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Standard {
    Fmi3,
    Fmi2,
}

/// Why a startTime and stopTime are not an experiment: startTime must be
/// finite, and a defined stopTime finite and not before it. A NaN stopTime
/// would disable the check of every step against it, one before startTime
/// would refuse every step.
pub(super) fn experiment_error(start: f64, stop: Option<f64>) -> Option<String> {
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

/// One FMU instance (FMI 3 or FMI 2).
pub(crate) struct Instance {
    pub standard: Standard,
    /// The FMU this instance is.
    pub fmu: Fmu,
    /// Its variables ([`Fmu::variables`]), made once.
    pub(super) variables: Vec<Variable>,
    pub name: CString,
    pub(super) log: LogSink,
    pub(super) categories: [bool; 4],
    pub state: u32,
    /// Parameter values (set by the host before initialization).
    pub(super) scene: Scene,
    /// The run; built lazily in initialization mode, always at its exit.
    pub(super) sim: Option<Simulation>,
    /// Start time given by the host; simulated time 0 corresponds to it.
    pub start_time: f64,
    /// Stop time given by the host, if any; doStep refuses to go past it.
    pub stop_time: Option<f64>,
    /// Current communication point (host time).
    pub(super) time: f64,
    /// The run has ended (rod at rest or end_time reached).
    pub(super) at_end: bool,
    pub last_successful_time: f64,
    /// FMI 3 `earlyReturnAllowed` (always false in FMI 2): return at the
    /// scene's end when it lies inside a step.
    pub early_return_allowed: bool,
    /// Kept alive for `fmi2GetStringStatus`.
    pub status_string: CString,
}

impl Instance {
    /// Sends a message to the host's logger. Errors always go out; other
    /// categories only when logging is on for them.
    pub(crate) fn log(&self, status: Status, category: usize, message: &str) {
        if category != CAT_ERROR && !self.categories[category] {
            return;
        }
        self.log
            .emit(&self.name, status as c_int, category, message);
    }

    /// `fmi3SetDebugLogging` / `fmi2SetDebugLogging`: logging `on` or off
    /// for the host's `n` categories (all of them when `n` is 0).
    ///
    /// # Safety
    /// `categories` must be NULL or hold `n` pointers, each NULL or a
    /// NUL-terminated string.
    pub(crate) unsafe fn set_debug_logging(
        &mut self,
        function: &str,
        on: bool,
        categories: *const *const c_char,
        n: usize,
    ) -> Status {
        // SAFETY: forwarded contract.
        let Some(names) = (unsafe { category_names(categories, n) }) else {
            return self.fail(&format!("{function}: categories is NULL"));
        };
        match set_categories(&mut self.categories, on, &names) {
            Ok(()) => Status::Ok,
            Err(e) => self.fail(&e),
        }
    }

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
    pub(super) fn ensure_sim(&mut self) -> Result<(), Status> {
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
                "stopTime = {stop} s lies beyond end_time = {} s after the start: the run ends at end_time at the latest, and the outputs hold their final values from then on",
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
            let what = panic_text(payload.as_ref());
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

/// Runs `f` on the instance behind `ptr` (see [`with_instance`]) if
/// `function` may be called in its state (`mask`), as a status code of
/// either standard.
///
/// # Safety
/// As [`with_instance`].
pub(crate) unsafe fn call(
    ptr: *mut c_void,
    function: &str,
    mask: u32,
    f: impl FnOnce(&mut Instance) -> Status,
) -> c_int {
    // SAFETY: forwarded contract.
    (unsafe {
        with_instance(ptr, |inst| match inst.check_state(function, mask) {
            Ok(()) => f(inst),
            Err(s) => s,
        })
    }) as c_int
}

#[cfg(test)]
mod tests {
    use super::super::taylor_fmu;
    use super::*;
    use std::ffi::c_char;

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
}
