//! The FMI 3.0 Co-Simulation functions (all 75 `fmi3*` symbols of the
//! standard; the Model Exchange and Scheduled Execution ones report that this
//! FMU does not support them).
//!
//! The scene's end: when the rod comes to rest (or `end_time` passes)
//! `fmi3DoStep` returns OK with `terminateSimulation = false`, and so does
//! every later step; the outputs hold their final values for the rest of
//! the host's run. `terminateSimulation = true` would ask the importer to
//! stop the whole co-simulation (FMI 3.0.2, `fmi3DoStep`: "the FMU requests
//! to stop the simulation"), which the FMU has no reason to ask: a rod at
//! rest stays at rest. Without early return the step completes
//! (`earlyReturn = false`, `lastSuccessfulTime` the end of the step). When
//! the host allowed early return and the scene ends inside the step, the
//! FMU returns there (`earlyReturn = true`, `lastSuccessfulTime` the
//! scene's end): the standard's "request for a communication point at
//! lastSuccessfulTime for any other reason", here the moment the outputs
//! become final; the host steps on from it.

use super::fmu::Fmu;
use super::instance::{Instance, Standard, Status, call, mask, with_instance};
use super::log::{Fmi3Logger, LogSink};
use super::ops::values_of_type;
use super::state;
use crate::ffi::{c_string_lossy, guard};
use std::ffi::{c_char, c_int, c_void};

type Fmi3Status = c_int;
type Instance3 = *mut c_void;
type Vr = u32;

const VERSION: &[u8] = b"3.0\0";

/// `fmi3GetVersion`: "3.0".
#[unsafe(no_mangle)]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    VERSION.as_ptr() as *const c_char
}

/// `fmi3SetDebugLogging`.
///
/// # Safety
/// FMI 3.0 contract: a live instance; `categories` holds `n` strings.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetDebugLogging(
    instance: Instance3,
    logging_on: u8,
    n_categories: usize,
    categories: *const *const c_char,
) -> Fmi3Status {
    let function = "fmi3SetDebugLogging";
    // SAFETY: FMI 3.0 contract (see above).
    unsafe {
        call(instance, function, mask::SET_DEBUG_LOGGING, |inst| {
            inst.set_debug_logging(function, logging_on != 0, categories, n_categories)
        })
    }
}

/// `fmi3InstantiateModelExchange`: not supported (NULL).
#[unsafe(no_mangle)]
pub extern "C" fn fmi3InstantiateModelExchange(
    _instance_name: *const c_char,
    _token: *const c_char,
    _resource_path: *const c_char,
    _visible: u8,
    _logging_on: u8,
    _environment: *mut c_void,
    _log_message: Option<Fmi3Logger>,
) -> Instance3 {
    std::ptr::null_mut()
}

/// `fmi3InstantiateScheduledExecution`: not supported (NULL).
#[unsafe(no_mangle)]
pub extern "C" fn fmi3InstantiateScheduledExecution(
    _instance_name: *const c_char,
    _token: *const c_char,
    _resource_path: *const c_char,
    _visible: u8,
    _logging_on: u8,
    _environment: *mut c_void,
    _log_message: Option<Fmi3Logger>,
    _clock_update: *mut c_void,
    _lock_preemption: *mut c_void,
    _unlock_preemption: *mut c_void,
) -> Instance3 {
    std::ptr::null_mut()
}

/// `fmi3InstantiateCoSimulation`: a new instance with the default
/// parameters, or NULL (with a logged error) on a wrong token.
///
/// # Safety
/// FMI 3.0 contract: strings NUL-terminated or NULL; the logger (may be
/// NULL) and environment valid until `fmi3FreeInstance`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instance_name: *const c_char,
    instantiation_token: *const c_char,
    _resource_path: *const c_char,
    _visible: u8,
    logging_on: u8,
    _event_mode_used: u8,
    early_return_allowed: u8,
    _required_intermediate_variables: *const Vr,
    _n_required_intermediate_variables: usize,
    instance_environment: *mut c_void,
    log_message: Option<Fmi3Logger>,
    _intermediate_update: *mut c_void,
) -> Instance3 {
    guard(std::ptr::null_mut(), || {
        // SAFETY: NUL-terminated or NULL by the FMI contract.
        let token = unsafe { c_string_lossy(instantiation_token) };
        let found = Fmu::for_instantiation("fmi3InstantiateCoSimulation", token.as_deref());
        let fmu = found.clone().unwrap_or_else(|_| Fmu::all()[0]);
        // SAFETY: as above.
        let name = unsafe { c_string_lossy(instance_name) }
            .unwrap_or_else(|| fmu.identity().model_identifier.into());
        let log = match log_message {
            Some(callback) => LogSink::Fmi3 {
                callback,
                environment: instance_environment,
            },
            None => LogSink::None,
        };
        let mut inst = Instance::new(Standard::Fmi3, fmu, &name, log, logging_on != 0);
        inst.early_return_allowed = early_return_allowed != 0;
        if let Err(message) = found {
            inst.fail(&message);
            return std::ptr::null_mut();
        }
        Box::into_raw(Box::new(inst)) as Instance3
    })
}

/// `fmi3FreeInstance`: always works; NULL is ignored.
///
/// # Safety
/// `instance` is NULL or a live instance, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3FreeInstance(instance: Instance3) {
    if instance.is_null() {
        return;
    }
    guard((), || {
        // SAFETY: created by `Box::into_raw` in fmi3InstantiateCoSimulation and
        // not yet freed, by the FMI contract.
        drop(unsafe { Box::from_raw(instance as *mut Instance) });
    })
}

/// `fmi3EnterInitializationMode`: records the start time and, if defined,
/// the stop time (a later `fmi3DoStep` past it returns `fmi3Error`); a
/// non-finite time or a stop time before the start time is an Error.
///
/// # Safety
/// A live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    instance: Instance3,
    _tolerance_defined: u8,
    _tolerance: f64,
    start_time: f64,
    stop_time_defined: u8,
    stop_time: f64,
) -> Fmi3Status {
    // SAFETY: FMI 3.0 contract.
    unsafe {
        call(
            instance,
            "fmi3EnterInitializationMode",
            mask::ENTER_INITIALIZATION_MODE,
            |inst| {
                let stop = (stop_time_defined != 0).then_some(stop_time);
                match inst.set_experiment("fmi3EnterInitializationMode", start_time, stop) {
                    Status::Ok => inst.enter_initialization_mode(),
                    s => s,
                }
            },
        )
    }
}

/// `fmi3ExitInitializationMode`: builds the simulation from the parameters.
///
/// # Safety
/// A live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3ExitInitializationMode(instance: Instance3) -> Fmi3Status {
    // SAFETY: FMI 3.0 contract.
    unsafe {
        call(
            instance,
            "fmi3ExitInitializationMode",
            mask::EXIT_INITIALIZATION_MODE,
            |inst| inst.exit_initialization_mode(),
        )
    }
}

/// `fmi3Terminate`.
///
/// # Safety
/// A live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3Terminate(instance: Instance3) -> Fmi3Status {
    // SAFETY: FMI 3.0 contract.
    unsafe {
        call(instance, "fmi3Terminate", mask::TERMINATE, |inst| {
            inst.terminate()
        })
    }
}

/// `fmi3Reset`: back to Instantiated with the default parameters.
///
/// # Safety
/// A live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3Reset(instance: Instance3) -> Fmi3Status {
    // SAFETY: FMI 3.0 contract.
    unsafe { call(instance, "fmi3Reset", mask::RESET, |inst| inst.reset()) }
}

values_of_type! {
    " FMI 3.0 contract.", [n_values];
    /// `fmi3GetFloat64`: `time`, the Float64 parameters and outputs.
    fmi3GetFloat64, f64, mut, Float64, get_values, |x| x;
    /// `fmi3GetInt32`: `particles_radial`.
    fmi3GetInt32, i32, mut, Int32, get_values, |x| x as i32;
    /// `fmi3GetBoolean`: `at_rest`.
    fmi3GetBoolean, u8, mut, Boolean, get_values, |x| (x != 0.0) as u8;
    /// `fmi3SetFloat64`: Float64 parameters, before the end of initialization.
    fmi3SetFloat64, f64, const, Float64, set_values, |x| x;
    /// `fmi3SetInt32`: `particles_radial`, before the end of initialization.
    fmi3SetInt32, i32, const, Int32, set_values, |x| x as f64;
    /// `fmi3GetInt64`: the Enumeration parameters (the `scheme`; FMI 3.0 reads
    /// and writes enumerations as Int64).
    fmi3GetInt64, i64, mut, Enumeration, get_values, |x| x as i64;
    /// `fmi3SetInt64`: the Enumeration parameters (the `scheme`), by the value
    /// of an item.
    fmi3SetInt64, i64, const, Enumeration, set_values, |x| x as f64;
    /// `fmi3SetBoolean`: there are no Boolean inputs or parameters.
    fmi3SetBoolean, u8, const, Boolean, set_values, |x| (x != 0) as u8 as f64;
}

/// Getters and setters of types this FMU has no variables of: OK for an
/// empty list in a state that allows the getters (setters), otherwise an
/// error.
macro_rules! no_variables_of_type {
    ($( $fname:ident, $mask:ident, ($($arg:ident: $t:ty),*); )*) => {$(
        #[doc = concat!("`", stringify!($fname), "`: this FMU has no variables of this type.")]
        ///
        /// # Safety
        /// FMI 3.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $fname(
            instance: Instance3,
            vrs: *const Vr,
            nvr: usize,
            $($arg: $t),*
        ) -> Fmi3Status {
            // SAFETY: FMI 3.0 contract.
            unsafe { no_such_type(instance, stringify!($fname), mask::$mask, vrs, nvr) }
        }
    )*};
}

/// See [`Instance::no_variables`].
///
/// # Safety
/// FMI 3.0 contract.
unsafe fn no_such_type(
    instance: Instance3,
    function: &str,
    mask: u32,
    vrs: *const Vr,
    nvr: usize,
) -> Fmi3Status {
    // SAFETY: forwarded.
    unsafe {
        with_instance(instance, |inst| {
            inst.no_variables(
                function,
                mask,
                (vrs, nvr),
                "a variable of this type (this FMU has Float64, Int32, Boolean and Enumeration (Int64) variables)",
            )
        }) as c_int
    }
}

no_variables_of_type! {
    fmi3GetFloat32, GET, (_values: *mut f32, _n_values: usize);
    fmi3GetInt8, GET, (_values: *mut i8, _n_values: usize);
    fmi3GetUInt8, GET, (_values: *mut u8, _n_values: usize);
    fmi3GetInt16, GET, (_values: *mut i16, _n_values: usize);
    fmi3GetUInt16, GET, (_values: *mut u16, _n_values: usize);
    fmi3GetUInt32, GET, (_values: *mut u32, _n_values: usize);
    fmi3GetUInt64, GET, (_values: *mut u64, _n_values: usize);
    fmi3GetString, GET, (_values: *mut *const c_char, _n_values: usize);
    fmi3SetFloat32, SET, (_values: *const f32, _n_values: usize);
    fmi3SetInt8, SET, (_values: *const i8, _n_values: usize);
    fmi3SetUInt8, SET, (_values: *const u8, _n_values: usize);
    fmi3SetInt16, SET, (_values: *const i16, _n_values: usize);
    fmi3SetUInt16, SET, (_values: *const u16, _n_values: usize);
    fmi3SetUInt32, SET, (_values: *const u32, _n_values: usize);
    fmi3SetUInt64, SET, (_values: *const u64, _n_values: usize);
    fmi3SetString, SET, (_values: *const *const c_char, _n_values: usize);
    fmi3GetBinary, GET, (_value_sizes: *mut usize, _values: *mut *const u8, _n_values: usize);
    fmi3SetBinary, SET, (_value_sizes: *const usize, _values: *const *const u8, _n_values: usize);
    fmi3GetClock, GET, (_values: *mut u8);
    fmi3SetClock, SET, (_values: *const u8);
}

/// Functions this Co-Simulation FMU does not provide: an error naming them.
///
/// # Safety
/// `instance` null or live.
unsafe fn unsupported(instance: Instance3, function: &str) -> Fmi3Status {
    // SAFETY: forwarded.
    unsafe {
        with_instance(instance, |inst| {
            inst.fail(&format!(
                "{function} is not supported: TaylorImpact is a Co-Simulation FMU without event mode, clocks or derivatives"
            ))
        }) as c_int
    }
}

macro_rules! unsupported_fns {
    ($( $fname:ident ( $($arg:ident : $t:ty),* ); )*) => {$(
        #[doc = concat!("`", stringify!($fname), "`: not supported by this Co-Simulation FMU (returns Error).")]
        ///
        /// # Safety
        /// FMI 3.0 contract.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $fname(instance: Instance3 $(, $arg: $t)*) -> Fmi3Status {
            $( let _ = $arg; )*
            // SAFETY: FMI 3.0 contract.
            unsafe { unsupported(instance, stringify!($fname)) }
        }
    )*};
}

unsupported_fns! {
    fmi3EnterEventMode();
    fmi3GetNumberOfVariableDependencies(vr: Vr, n: *mut usize);
    fmi3GetVariableDependencies(dependent: Vr, a: *mut usize, b: *mut Vr, c: *mut usize, d: *mut c_int, n: usize);
    fmi3GetDirectionalDerivative(u: *const Vr, nu: usize, k: *const Vr, nk: usize, s: *const f64, ns: usize, o: *mut f64, no: usize);
    fmi3GetAdjointDerivative(u: *const Vr, nu: usize, k: *const Vr, nk: usize, s: *const f64, ns: usize, o: *mut f64, no: usize);
    fmi3EnterConfigurationMode();
    fmi3ExitConfigurationMode();
    fmi3GetIntervalDecimal(v: *const Vr, n: usize, i: *mut f64, q: *mut c_int);
    fmi3GetIntervalFraction(v: *const Vr, n: usize, c: *mut u64, r: *mut u64, q: *mut c_int);
    fmi3GetShiftDecimal(v: *const Vr, n: usize, s: *mut f64);
    fmi3GetShiftFraction(v: *const Vr, n: usize, c: *mut u64, r: *mut u64);
    fmi3SetIntervalDecimal(v: *const Vr, n: usize, i: *const f64);
    fmi3SetIntervalFraction(v: *const Vr, n: usize, c: *const u64, r: *const u64);
    fmi3SetShiftDecimal(v: *const Vr, n: usize, s: *const f64);
    fmi3SetShiftFraction(v: *const Vr, n: usize, c: *const u64, r: *const u64);
    fmi3EvaluateDiscreteStates();
    fmi3UpdateDiscreteStates(a: *mut u8, b: *mut u8, c: *mut u8, d: *mut u8, e: *mut u8, t: *mut f64);
    fmi3EnterContinuousTimeMode();
    fmi3CompletedIntegratorStep(no_set: u8, enter: *mut u8, term: *mut u8);
    fmi3SetTime(time: f64);
    fmi3SetContinuousStates(x: *const f64, n: usize);
    fmi3GetContinuousStateDerivatives(x: *mut f64, n: usize);
    fmi3GetEventIndicators(x: *mut f64, n: usize);
    fmi3GetContinuousStates(x: *mut f64, n: usize);
    fmi3GetNominalsOfContinuousStates(x: *mut f64, n: usize);
    fmi3GetNumberOfEventIndicators(n: *mut usize);
    fmi3GetNumberOfContinuousStates(n: *mut usize);
    fmi3EnterStepMode();
    fmi3GetOutputDerivatives(v: *const Vr, n: usize, o: *const i32, x: *mut f64, nx: usize);
    fmi3ActivateModelPartition(clock: Vr, t: f64);
}

/// `fmi3DoStep`: advances to `currentCommunicationPoint +
/// communicationStepSize`, taking as many solver steps as needed, also
/// past the scene's end (the outputs hold); `fmi3Error` when the step would
/// end past a defined stopTime or the solver stops.
///
/// # Safety
/// FMI 3.0 contract: a live instance; the output pointers writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3DoStep(
    instance: Instance3,
    current_communication_point: f64,
    communication_step_size: f64,
    _no_set_fmu_state_prior_to_current_point: u8,
    event_handling_needed: *mut u8,
    terminate_simulation: *mut u8,
    early_return: *mut u8,
    last_successful_time: *mut f64,
) -> Fmi3Status {
    // SAFETY: FMI 3.0 contract.
    unsafe {
        with_instance(instance, |inst| {
            if event_handling_needed.is_null()
                || terminate_simulation.is_null()
                || early_return.is_null()
                || last_successful_time.is_null()
            {
                return inst.fail("fmi3DoStep: an output argument is NULL");
            }
            match inst.do_step(
                "fmi3DoStep",
                current_communication_point,
                communication_step_size,
            ) {
                Ok(reached) => {
                    // SAFETY (covered by the enclosing block): checked non-null
                    // above; writable by the contract. No event and no
                    // request to stop; an early return only at the scene's
                    // end inside the step, when the host allowed it.
                    *event_handling_needed = 0;
                    *terminate_simulation = 0;
                    *early_return =
                        (reached != current_communication_point + communication_step_size) as u8;
                    *last_successful_time = reached;
                    Status::Ok
                }
                Err(s) => s,
            }
        }) as c_int
    }
}

/// `fmi3GetFMUState`: a copy of the instance's state (a new one, or
/// overwriting `*state` when it is not NULL).
///
/// # Safety
/// FMI 3.0 contract: `state` writable; `*state` NULL or a state of this FMU.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetFMUState(
    instance: Instance3,
    state: *mut *mut c_void,
) -> Fmi3Status {
    // SAFETY: FMI 3.0 contract.
    unsafe { state::get_fmu_state(instance, "fmi3GetFMUState", state) }
}

/// `fmi3SetFMUState`: restores a state from `fmi3GetFMUState` or
/// `fmi3DeserializeFMUState`.
///
/// # Safety
/// FMI 3.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetFMUState(instance: Instance3, state: *mut c_void) -> Fmi3Status {
    // SAFETY: forwarded.
    unsafe { state::set_fmu_state(instance, "fmi3SetFMUState", state) }
}

/// `fmi3FreeFMUState`.
///
/// # Safety
/// FMI 3.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3FreeFMUState(
    instance: Instance3,
    state: *mut *mut c_void,
) -> Fmi3Status {
    // SAFETY: forwarded.
    unsafe { state::free_fmu_state(instance, state) }
}

/// `fmi3SerializedFMUStateSize`.
///
/// # Safety
/// FMI 3.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(
    instance: Instance3,
    state: *mut c_void,
    size: *mut usize,
) -> Fmi3Status {
    // SAFETY: forwarded.
    unsafe { state::serialized_size(instance, "fmi3SerializedFMUStateSize", state, size) }
}

/// `fmi3SerializeFMUState`.
///
/// # Safety
/// FMI 3.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SerializeFMUState(
    instance: Instance3,
    state: *mut c_void,
    bytes: *mut u8,
    size: usize,
) -> Fmi3Status {
    // SAFETY: forwarded.
    unsafe { state::serialize(instance, "fmi3SerializeFMUState", state, bytes, size) }
}

/// `fmi3DeserializeFMUState`.
///
/// # Safety
/// FMI 3.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3DeserializeFMUState(
    instance: Instance3,
    bytes: *const u8,
    size: usize,
    state: *mut *mut c_void,
) -> Fmi3Status {
    // SAFETY: forwarded.
    unsafe { state::deserialize(instance, "fmi3DeserializeFMUState", bytes, size, state) }
}

#[cfg(test)]
mod tests {
    use super::super::{VR_TIME, taylor_fmu};
    use super::*;

    /// A new instance with the right token and no logger.
    fn instance() -> Instance3 {
        let token = std::ffi::CString::new(taylor_fmu().token()).unwrap();
        // SAFETY: NUL-terminated strings or NULL, no logger.
        let inst = unsafe {
            fmi3InstantiateCoSimulation(
                std::ptr::null(),
                token.as_ptr(),
                std::ptr::null(),
                0,
                0,
                0,
                0,
                std::ptr::null(),
                0,
                std::ptr::null_mut(),
                None,
                std::ptr::null_mut(),
            )
        };
        assert!(!inst.is_null());
        inst
    }

    /// A NaN stopTime disabled the check of every step against it; now it
    /// is refused, as are infinite ones and one before startTime. An
    /// undefined stopTime is not looked at.
    #[test]
    fn bad_stop_times_are_refused() {
        let error = Status::Error as c_int;
        for (start, stop) in [(0.0, f64::NAN), (0.0, f64::INFINITY), (1.0, 0.5)] {
            let inst = instance();
            // SAFETY: a live instance, freed once.
            unsafe {
                assert_eq!(
                    fmi3EnterInitializationMode(inst, 0, 0.0, start, 1, stop),
                    error
                );
                assert_eq!(fmi3ExitInitializationMode(inst), error, "left Terminated");
                fmi3FreeInstance(inst);
            }
        }
        let inst = instance();
        // SAFETY: a live instance, freed once.
        unsafe {
            assert_eq!(
                fmi3EnterInitializationMode(inst, 0, 0.0, 1.0, 0, f64::NAN),
                0
            );
            fmi3FreeInstance(inst);
        }
    }

    /// Status, terminateSimulation and lastSuccessfulTime of a doStep.
    fn step(inst: Instance3, t: f64, h: f64) -> (c_int, u8, f64) {
        let (mut event, mut terminate, mut early, mut last) = (0, 0, 0, f64::NAN);
        // SAFETY: a live instance; writable outputs.
        let s = unsafe {
            fmi3DoStep(
                inst,
                t,
                h,
                0,
                &mut event,
                &mut terminate,
                &mut early,
                &mut last,
            )
        };
        (s, terminate, last)
    }

    /// A coarse instance (4 particles across) in step mode from `start`.
    fn stepping(start: f64) -> Instance3 {
        let inst = instance();
        let pr = taylor_fmu()
            .variables()
            .iter()
            .find(|v| v.name == "particles_radial")
            .unwrap()
            .vr;
        // SAFETY: a live instance; one value reference and one value.
        unsafe {
            assert_eq!(fmi3SetInt32(inst, &pr, 1, &4, 1), 0);
            assert_eq!(fmi3EnterInitializationMode(inst, 0, 0.0, start, 0, 0.0), 0);
            assert_eq!(fmi3ExitInitializationMode(inst), 0);
        }
        inst
    }

    /// Found by the FMU call-order fuzzer: a step from a huge time ended at
    /// infinity (OK, lastSuccessfulTime = inf and the time variable inf
    /// from then on) or was lost in rounding (OK, time unchanged).
    #[test]
    fn a_step_must_end_at_a_finite_later_time() {
        let error = Status::Error as c_int;
        let inst = stepping(0.0);
        // To the end of the run and far beyond: the step completes (no
        // request to stop) and the outputs hold.
        assert_eq!(step(inst, 0.0, f64::MAX), (0, 0, f64::MAX));
        assert_eq!(step(inst, f64::MAX, f64::MAX).0, error);
        let mut time = f64::NAN;
        // SAFETY: a live instance, freed once; one value reference and value.
        unsafe {
            // Values may be read after an Error.
            assert_eq!(fmi3GetFloat64(inst, &VR_TIME, 1, &mut time, 1), 0);
            assert_eq!(time, f64::MAX);
            fmi3FreeInstance(inst);
        }
        // From a huge start time a small step is lost in rounding.
        let inst = stepping(1e300);
        assert_eq!(step(inst, 1e300, 1e-6).0, error);
        // SAFETY: a live instance, freed once.
        unsafe { fmi3FreeInstance(inst) };
    }

    /// Found by the FMU call-order fuzzer: the tolerance on the current time
    /// grew with the step size, so a step of 1e300 s accepted a current time
    /// of 2.8e30 s at an FMU time of microseconds (and returned, with early
    /// return, a lastSuccessfulTime before the current time). Rounding of
    /// the times a host adds up is still accepted.
    #[test]
    fn a_huge_step_does_not_excuse_a_wrong_current_time() {
        let error = Status::Error as c_int;
        let inst = stepping(0.0);
        assert_eq!(step(inst, 0.0, 1e-6).0, 0);
        assert_eq!(step(inst, 1e-6 * (1.0 + 1e-12), 1e-6).0, 0, "rounding");
        assert_eq!(step(inst, 1e30, 1e300).0, error);
        // SAFETY: a live instance, freed once.
        unsafe { fmi3FreeInstance(inst) };
        // Found by the ten-minute fuzz: from startTime = f64::MAX the
        // tolerance overflowed to infinity and accepted any current time.
        let inst = stepping(f64::MAX);
        assert_eq!(step(inst, 1.0, 1e-6).0, error);
        // SAFETY: a live instance, freed once.
        unsafe { fmi3FreeInstance(inst) };
        let inst = stepping(-1.0);
        // Near t = 0 from startTime = -1 s, a host's sums carry the rounding
        // of 1 s.
        assert_eq!(step(inst, -1.0, 1.0 - 1e-12).0, 0);
        assert_eq!(
            step(inst, -1e-12 + 1e-16, 1e-6).0,
            0,
            "rounding of |startTime|"
        );
        // SAFETY: a live instance, freed once.
        unsafe { fmi3FreeInstance(inst) };
    }

    /// Found by the fuzzer: a getter of a type without variables returned OK
    /// for an empty list in Instantiated, a setter in Terminated.
    #[test]
    fn empty_lists_of_absent_types_follow_the_state_machine() {
        let inst = instance();
        let vrs = [0u32; 1];
        let pr = taylor_fmu()
            .variables()
            .iter()
            .find(|v| v.name == "particles_radial")
            .unwrap()
            .vr;
        let get = |inst| {
            let mut out = [0f32; 1];
            // SAFETY: a live instance; an empty list.
            unsafe { fmi3GetFloat32(inst, vrs.as_ptr(), 0, out.as_mut_ptr(), 0) }
        };
        let set = |inst| {
            // SAFETY: a live instance; an empty list.
            unsafe { fmi3SetString(inst, vrs.as_ptr(), 0, std::ptr::null(), 0) }
        };
        let error = Status::Error as c_int;
        assert_eq!(get(inst), error, "no getter in Instantiated");
        // SAFETY: a live instance; one value reference and one value.
        unsafe {
            assert_eq!(fmi3Reset(inst), 0);
            assert_eq!(set(inst), 0, "setters are allowed in Instantiated");
            assert_eq!(fmi3SetInt32(inst, &pr, 1, &4, 1), 0);
            assert_eq!(fmi3EnterInitializationMode(inst, 0, 0.0, 0.0, 0, 0.0), 0);
            assert_eq!(get(inst), 0, "getters are allowed in InitializationMode");
            assert_eq!(fmi3ExitInitializationMode(inst), 0);
            assert_eq!(fmi3Terminate(inst), 0);
            assert_eq!(get(inst), 0, "getters are allowed in Terminated");
            assert_eq!(set(inst), error, "no setter in Terminated");
            fmi3FreeInstance(inst);
        }
    }

    #[test]
    fn version_and_null_instance() {
        // SAFETY: a static NUL-terminated string.
        let v = unsafe { std::ffi::CStr::from_ptr(fmi3GetVersion()) };
        assert_eq!(v.to_str().unwrap(), "3.0");
        // SAFETY: NULL is allowed and refused.
        unsafe {
            assert_eq!(fmi3Terminate(std::ptr::null_mut()), Status::Error as c_int);
            fmi3FreeInstance(std::ptr::null_mut());
        }
    }
}
