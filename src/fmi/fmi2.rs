//! The FMI 2.0 Co-Simulation functions (all 34 `fmi2*` symbols that a
//! Co-Simulation importer resolves).
//!
//! The scene's end: when the rod comes to rest (or `end_time` passes) during
//! a communication step, `fmi2DoStep` completes the step with `fmi2OK`, and
//! every later step too; the outputs hold their final values for the rest
//! of the host's run. No step is discarded: `fmi2Terminated` is false
//! (the FMU does not ask to end the co-simulation) and
//! `fmi2LastSuccessfulTime` is the FMU's time.

use super::fmu::Fmu;
use super::instance::{Instance, STEP_DISCARDED, Standard, Status, call, mask, with_instance};
use super::log::{Fmi2Logger, LogSink};
use super::ops::values_of_type;
use super::state::{
    deserialize, free_fmu_state, get_fmu_state, serialize, serialized_size, set_fmu_state,
};
use crate::ffi::{c_string_lossy, guard};
use std::ffi::{c_char, c_int, c_void};

type Fmi2Status = c_int;
type Component = *mut c_void;
type Vr = u32;

const VERSION: &[u8] = b"2.0\0";
const TYPES_PLATFORM: &[u8] = b"default\0";

const FMI2_COSIMULATION: c_int = 1;
const FMI2_DO_STEP_STATUS: c_int = 0;
const FMI2_PENDING_STATUS: c_int = 1;
const FMI2_LAST_SUCCESSFUL_TIME: c_int = 2;
const FMI2_TERMINATED: c_int = 3;

/// `fmi2CallbackFunctions`.
#[repr(C)]
pub struct CallbackFunctions {
    /// Logger (printf-style message).
    pub logger: Option<Fmi2Logger>,
    /// Not used: `canNotUseMemoryManagementFunctions="true"`.
    pub allocate_memory: *mut c_void,
    /// Not used.
    pub free_memory: *mut c_void,
    /// Not used (doStep is synchronous).
    pub step_finished: *mut c_void,
    /// Passed back to the logger.
    pub component_environment: *mut c_void,
}

/// `fmi2GetTypesPlatform`: "default".
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    TYPES_PLATFORM.as_ptr() as *const c_char
}

/// `fmi2GetVersion`: "2.0".
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    VERSION.as_ptr() as *const c_char
}

/// `fmi2SetDebugLogging`.
///
/// # Safety
/// FMI 2.0 contract: a live instance; `categories` holds `n` strings.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: Component,
    logging_on: c_int,
    n_categories: usize,
    categories: *const *const c_char,
) -> Fmi2Status {
    let function = "fmi2SetDebugLogging";
    // SAFETY: FMI 2.0 contract.
    unsafe {
        call(c, function, mask::SET_DEBUG_LOGGING, |inst| {
            inst.set_debug_logging(function, logging_on != 0, categories, n_categories)
        })
    }
}

/// `fmi2Instantiate`: a Co-Simulation instance with the default
/// parameters, or NULL on a wrong GUID or type.
///
/// # Safety
/// FMI 2.0 contract: strings NUL-terminated or NULL; `functions` valid
/// until `fmi2FreeInstance`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: *const c_char,
    fmu_type: c_int,
    fmu_guid: *const c_char,
    _fmu_resource_location: *const c_char,
    functions: *const CallbackFunctions,
    _visible: c_int,
    logging_on: c_int,
) -> Component {
    guard(std::ptr::null_mut(), || {
        // SAFETY: NUL-terminated or NULL by the FMI contract.
        let guid = unsafe { c_string_lossy(fmu_guid) };
        let found = Fmu::for_instantiation("fmi2Instantiate", guid.as_deref());
        let fmu = found.clone().unwrap_or_else(|_| Fmu::all()[0]);
        // SAFETY: as above.
        let name = unsafe { c_string_lossy(instance_name) }
            .unwrap_or_else(|| fmu.identity().model_identifier.into());
        // SAFETY: `functions` is NULL or a valid struct by the contract.
        let log = match unsafe { functions.as_ref() } {
            Some(CallbackFunctions {
                logger: Some(callback),
                component_environment,
                ..
            }) => LogSink::Fmi2 {
                callback: *callback,
                environment: *component_environment,
            },
            _ => LogSink::None,
        };
        let mut inst = Instance::new(Standard::Fmi2, fmu, &name, log, logging_on != 0);
        if fmu_type != FMI2_COSIMULATION {
            inst.fail(&format!(
                "fmi2Instantiate: {} supports only Co-Simulation (fmuType = fmi2CoSimulation)",
                fmu.identity().model_identifier
            ));
            return std::ptr::null_mut();
        }
        if let Err(message) = found {
            inst.fail(&message);
            return std::ptr::null_mut();
        }
        Box::into_raw(Box::new(inst)) as Component
    })
}

/// `fmi2FreeInstance`: always works; NULL is ignored.
///
/// # Safety
/// `c` NULL or a live instance, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: Component) {
    if c.is_null() {
        return;
    }
    guard((), || {
        // SAFETY: from `Box::into_raw` in fmi2Instantiate, freed once.
        drop(unsafe { Box::from_raw(c as *mut Instance) });
    })
}

/// `fmi2SetupExperiment`: records the start time and, if defined, the stop
/// time (a later `fmi2DoStep` past it returns `fmi2Error`); a non-finite
/// time or a stop time before the start time is an Error.
///
/// # Safety
/// A live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: Component,
    _tolerance_defined: c_int,
    _tolerance: f64,
    start_time: f64,
    stop_time_defined: c_int,
    stop_time: f64,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 contract.
    unsafe {
        call(c, "fmi2SetupExperiment", mask::SETUP_EXPERIMENT, |inst| {
            let stop = (stop_time_defined != 0).then_some(stop_time);
            inst.set_experiment("fmi2SetupExperiment", start_time, stop)
        })
    }
}

/// `fmi2EnterInitializationMode`.
///
/// # Safety
/// A live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: Component) -> Fmi2Status {
    // SAFETY: FMI 2.0 contract.
    unsafe {
        call(
            c,
            "fmi2EnterInitializationMode",
            mask::ENTER_INITIALIZATION_MODE,
            |inst| inst.enter_initialization_mode(),
        )
    }
}

/// `fmi2ExitInitializationMode`: builds the simulation from the parameters.
///
/// # Safety
/// A live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: Component) -> Fmi2Status {
    // SAFETY: FMI 2.0 contract.
    unsafe {
        call(
            c,
            "fmi2ExitInitializationMode",
            mask::EXIT_INITIALIZATION_MODE,
            |inst| inst.exit_initialization_mode(),
        )
    }
}

/// `fmi2Terminate`.
///
/// # Safety
/// A live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Terminate(c: Component) -> Fmi2Status {
    // SAFETY: FMI 2.0 contract.
    unsafe { call(c, "fmi2Terminate", mask::TERMINATE, |inst| inst.terminate()) }
}

/// `fmi2Reset`: back to Instantiated with the default parameters.
///
/// # Safety
/// A live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Reset(c: Component) -> Fmi2Status {
    // SAFETY: FMI 2.0 contract.
    unsafe { call(c, "fmi2Reset", mask::RESET, |inst| inst.reset()) }
}

values_of_type! {
    " FMI 2.0 contract.", [];
    /// `fmi2GetReal`: Real parameters and outputs.
    fmi2GetReal, f64, mut, Float64, get_values, |x| x;
    /// `fmi2GetInteger`: `particles_radial`.
    fmi2GetInteger, c_int, mut, Int32, get_values, |x| x as c_int;
    /// `fmi2GetBoolean`: `at_rest`.
    fmi2GetBoolean, c_int, mut, Boolean, get_values, |x| (x != 0.0) as c_int;
    /// `fmi2SetReal`: Real parameters, before the end of initialization.
    fmi2SetReal, f64, const, Float64, set_values, |x| x;
    /// `fmi2SetInteger`: `particles_radial`, before the end of initialization.
    fmi2SetInteger, c_int, const, Int32, set_values, |x| x as f64;
    /// `fmi2SetBoolean`: no Boolean parameters (the only Boolean is an output).
    fmi2SetBoolean, c_int, const, Boolean, set_values, |x| (x != 0) as u8 as f64;
}

/// `fmi2GetString`: there are no String variables.
///
/// # Safety
/// FMI 2.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetString(
    c: Component,
    vr: *const Vr,
    nvr: usize,
    _value: *mut *const c_char,
) -> Fmi2Status {
    // SAFETY: forwarded.
    unsafe { no_strings(c, "fmi2GetString", mask::GET, vr, nvr) }
}

/// `fmi2SetString`: there are no String variables.
///
/// # Safety
/// FMI 2.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetString(
    c: Component,
    vr: *const Vr,
    nvr: usize,
    _value: *const *const c_char,
) -> Fmi2Status {
    // SAFETY: forwarded.
    unsafe { no_strings(c, "fmi2SetString", mask::SET, vr, nvr) }
}

/// See [`Instance::no_variables`].
///
/// # Safety
/// FMI 2.0 contract.
unsafe fn no_strings(
    c: Component,
    function: &str,
    mask: u32,
    vr: *const Vr,
    nvr: usize,
) -> Fmi2Status {
    // SAFETY: forwarded.
    (unsafe {
        with_instance(c, |inst| {
            inst.no_variables(
                function,
                mask,
                (vr, nvr),
                "a String variable (this FMU has none)",
            )
        })
    }) as c_int
}

/// `fmi2GetFMUstate`.
///
/// # Safety
/// FMI 2.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetFMUstate(c: Component, state: *mut *mut c_void) -> Fmi2Status {
    // SAFETY: forwarded.
    unsafe { get_fmu_state(c, "fmi2GetFMUstate", state) }
}

/// `fmi2SetFMUstate`.
///
/// # Safety
/// FMI 2.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetFMUstate(c: Component, state: *mut c_void) -> Fmi2Status {
    // SAFETY: forwarded.
    unsafe { set_fmu_state(c, "fmi2SetFMUstate", state) }
}

/// `fmi2FreeFMUstate`.
///
/// # Safety
/// FMI 2.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeFMUstate(c: Component, state: *mut *mut c_void) -> Fmi2Status {
    // SAFETY: forwarded.
    unsafe { free_fmu_state(c, state) }
}

/// `fmi2SerializedFMUstateSize`.
///
/// # Safety
/// FMI 2.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: Component,
    state: *mut c_void,
    size: *mut usize,
) -> Fmi2Status {
    // SAFETY: forwarded.
    unsafe { serialized_size(c, "fmi2SerializedFMUstateSize", state, size) }
}

/// `fmi2SerializeFMUstate`.
///
/// # Safety
/// FMI 2.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: Component,
    state: *mut c_void,
    bytes: *mut u8,
    size: usize,
) -> Fmi2Status {
    // SAFETY: forwarded.
    unsafe { serialize(c, "fmi2SerializeFMUstate", state, bytes, size) }
}

/// `fmi2DeSerializeFMUstate`.
///
/// # Safety
/// FMI 2.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: Component,
    bytes: *const u8,
    size: usize,
    state: *mut *mut c_void,
) -> Fmi2Status {
    // SAFETY: forwarded.
    unsafe { deserialize(c, "fmi2DeSerializeFMUstate", bytes, size, state) }
}

/// # Safety
/// `c` NULL or live.
unsafe fn unsupported(c: Component, function: &str) -> Fmi2Status {
    // SAFETY: forwarded.
    (unsafe {
        with_instance(c, |inst| {
            inst.fail(&format!(
                "{function} is not supported: TaylorImpact provides no derivatives and has no inputs"
            ))
        })
    }) as c_int
}

/// `fmi2GetDirectionalDerivative`: not supported (Error).
///
/// # Safety
/// FMI 2.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: Component,
    _unknown: *const Vr,
    _n_unknown: usize,
    _known: *const Vr,
    _n_known: usize,
    _dv_known: *const f64,
    _dv_unknown: *mut f64,
) -> Fmi2Status {
    // SAFETY: forwarded.
    unsafe { unsupported(c, "fmi2GetDirectionalDerivative") }
}

/// `fmi2SetRealInputDerivatives`: not supported (Error).
///
/// # Safety
/// FMI 2.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: Component,
    _vr: *const Vr,
    _nvr: usize,
    _order: *const c_int,
    _value: *const f64,
) -> Fmi2Status {
    // SAFETY: forwarded.
    unsafe { unsupported(c, "fmi2SetRealInputDerivatives") }
}

/// `fmi2GetRealOutputDerivatives`: not supported (Error).
///
/// # Safety
/// FMI 2.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: Component,
    _vr: *const Vr,
    _nvr: usize,
    _order: *const c_int,
    _value: *mut f64,
) -> Fmi2Status {
    // SAFETY: forwarded.
    unsafe { unsupported(c, "fmi2GetRealOutputDerivatives") }
}

/// `fmi2DoStep`: advances to `currentCommunicationPoint +
/// communicationStepSize`; `fmi2OK` also when the scene ends (rod at rest or
/// end_time) during the step or has already ended (the outputs then hold
/// their final values); `fmi2Error` when the step would end past a defined
/// stopTime or the solver stops.
///
/// # Safety
/// A live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DoStep(
    c: Component,
    current_communication_point: f64,
    communication_step_size: f64,
    _no_set_fmu_state_prior: c_int,
) -> Fmi2Status {
    // SAFETY: FMI 2.0 contract.
    (unsafe {
        with_instance(c, |inst| {
            match inst.do_step(
                "fmi2DoStep",
                current_communication_point,
                communication_step_size,
            ) {
                Ok(_) => Status::Ok,
                Err(s) => s,
            }
        })
    }) as c_int
}

/// `fmi2CancelStep`: doStep never returns Pending, so there is nothing to
/// cancel (Error).
///
/// # Safety
/// A live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CancelStep(c: Component) -> Fmi2Status {
    // SAFETY: FMI 2.0 contract.
    unsafe {
        call(c, "fmi2CancelStep", mask::DO_STEP, |inst| {
            inst.fail("fmi2CancelStep: fmi2DoStep never returns fmi2Pending, so there is no step to cancel")
        })
    }
}

/// # Safety
/// `out` NULL or writable.
unsafe fn status_query<T>(
    c: Component,
    function: &str,
    kind: c_int,
    out: *mut T,
    answer: impl FnOnce(&mut Instance, c_int) -> Option<T>,
) -> Fmi2Status {
    // SAFETY: forwarded.
    unsafe {
        call(c, function, mask::STATUS, |inst| {
            if out.is_null() {
                return inst.fail(&format!("{function}: value is NULL"));
            }
            match answer(inst, kind) {
                Some(v) => {
                    // SAFETY: non-null and writable by the contract.
                    *out = v;
                    Status::Ok
                }
                None => inst.fail(&format!("{function}: status kind {kind} is not available")),
            }
        })
    }
}

/// `fmi2GetStatus`: `fmi2DoStepStatus` (Discard only in StepDiscarded, which
/// a state saved by an earlier build of this FMU may restore).
///
/// # Safety
/// FMI 2.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStatus(c: Component, kind: c_int, value: *mut c_int) -> Fmi2Status {
    // SAFETY: forwarded.
    unsafe {
        status_query(c, "fmi2GetStatus", kind, value, |inst, k| {
            let status = if inst.state == STEP_DISCARDED {
                Status::Discard
            } else {
                Status::Ok
            };
            (k == FMI2_DO_STEP_STATUS).then_some(status as c_int)
        })
    }
}

/// `fmi2GetRealStatus`: `fmi2LastSuccessfulTime`.
///
/// # Safety
/// FMI 2.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: Component,
    kind: c_int,
    value: *mut f64,
) -> Fmi2Status {
    // SAFETY: forwarded.
    unsafe {
        status_query(c, "fmi2GetRealStatus", kind, value, |inst, k| {
            (k == FMI2_LAST_SUCCESSFUL_TIME).then_some(inst.last_successful_time)
        })
    }
}

/// `fmi2GetIntegerStatus`: no integer status kinds exist (Error).
///
/// # Safety
/// FMI 2.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: Component,
    kind: c_int,
    value: *mut c_int,
) -> Fmi2Status {
    // SAFETY: forwarded.
    unsafe { status_query(c, "fmi2GetIntegerStatus", kind, value, |_, _| None) }
}

/// `fmi2GetBooleanStatus`: `fmi2Terminated` (the rod is at rest or
/// end_time passed).
///
/// # Safety
/// FMI 2.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: Component,
    kind: c_int,
    value: *mut c_int,
) -> Fmi2Status {
    // SAFETY: forwarded.
    unsafe {
        status_query(c, "fmi2GetBooleanStatus", kind, value, |inst, k| {
            // True only in StepDiscarded, which a state saved by an earlier
            // build of this FMU (its early stop) may restore.
            (k == FMI2_TERMINATED).then_some((inst.state == STEP_DISCARDED) as c_int)
        })
    }
}

/// `fmi2GetStringStatus`: `fmi2PendingStatus` ("" since doStep is
/// synchronous).
///
/// # Safety
/// FMI 2.0 contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: Component,
    kind: c_int,
    value: *mut *const c_char,
) -> Fmi2Status {
    // SAFETY: forwarded.
    unsafe {
        status_query(c, "fmi2GetStringStatus", kind, value, |inst, k| {
            (k == FMI2_PENDING_STATUS).then(|| inst.status_string.as_ptr())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::taylor_fmu;
    use super::*;

    /// A new Co-Simulation instance with the right GUID and no logger.
    fn instance() -> Component {
        let guid = std::ffi::CString::new(taylor_fmu().token()).unwrap();
        // SAFETY: NUL-terminated strings or NULL; no callbacks.
        let c = unsafe {
            fmi2Instantiate(
                std::ptr::null(),
                FMI2_COSIMULATION,
                guid.as_ptr(),
                std::ptr::null(),
                std::ptr::null(),
                0,
                0,
            )
        };
        assert!(!c.is_null());
        c
    }

    /// A NaN stopTime disabled the check of every step against it; now it
    /// is refused, as are infinite ones and one before startTime. An
    /// undefined stopTime is not looked at; one equal to startTime is fine.
    #[test]
    fn bad_stop_times_are_refused() {
        let error = Status::Error as c_int;
        for (start, stop) in [(0.0, f64::NAN), (0.0, f64::NEG_INFINITY), (1.0, 0.5)] {
            let c = instance();
            // SAFETY: a live instance, freed once.
            unsafe {
                assert_eq!(fmi2SetupExperiment(c, 0, 0.0, start, 1, stop), error);
                assert_eq!(fmi2EnterInitializationMode(c), error, "left Terminated");
                fmi2FreeInstance(c);
            }
        }
        let c = instance();
        // SAFETY: a live instance, freed once.
        unsafe {
            assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 1.0, 0, f64::NAN), 0);
            assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 1.0, 1, 1.0), 0);
            assert_eq!(fmi2EnterInitializationMode(c), 0);
            fmi2FreeInstance(c);
        }
    }

    /// Found by the fuzzer: fmi2GetString returned OK for an empty list in
    /// Instantiated, fmi2SetString in Terminated.
    #[test]
    fn empty_string_lists_follow_the_state_machine() {
        let c = instance();
        let vr = [1u32];
        let mut out = [std::ptr::null::<c_char>()];
        let error = Status::Error as c_int;
        // SAFETY: a live instance; empty lists.
        unsafe {
            assert_eq!(fmi2GetString(c, vr.as_ptr(), 0, out.as_mut_ptr()), error);
            assert_eq!(fmi2Reset(c), 0);
            assert_eq!(fmi2SetString(c, vr.as_ptr(), 0, out.as_ptr()), 0);
            assert_eq!(fmi2Terminate(c), error, "not allowed in Instantiated");
            assert_eq!(fmi2GetString(c, vr.as_ptr(), 0, out.as_mut_ptr()), 0);
            assert_eq!(fmi2SetString(c, vr.as_ptr(), 0, out.as_ptr()), error);
            fmi2FreeInstance(c);
        }
    }
}
