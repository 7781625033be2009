//! FMU call orders: random sequences through the exported FMI 3.0 and FMI
//! 2.0 functions, checked against a model of the standards' state machines.
//!
//! Only sequences a host may legally make are memory-safe by the standards:
//! the fuzzer never uses a freed instance or a freed FMU state, and its
//! arrays always hold as many elements as the counts it passes (a wrong
//! `nValues` comes with an array long enough for either count). Everything
//! else is fair: calls in the wrong state, unknown and mistyped value
//! references, NULL arrays, NaN, negative and huge times and step sizes,
//! corrupted and forged serialized states. Every call must return a
//! documented status; Fatal, which the FMU returns only for a caught panic,
//! fails the run, as does any panic (a hook counts them, including those
//! `guard` swallows in `Instantiate` and `FreeInstance`), a non-finite value
//! read back with OK, and OK where the standard requires Error.

use super::{Entry, Rng, bounded, count, edit_leaf};
use meshless_impact::ParamSpec;
use meshless_impact::internals::fmi::{self, VarKind, VarType, fmi2, fmi3};
use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::ptr::{null, null_mut};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

const OK: c_int = 0;
const DISCARD: c_int = 2;
const ERROR: c_int = 3;
const FATAL: c_int = 4;

/// Calls a case makes at most after instantiation.
const CALLS: usize = 24;

/// The interval a case draws a parameter's value from (with the hostile
/// values around it): its range, but lengths (in m) within a factor of 2 of
/// the default. (A rod of 1e5 spacings, or a wide plate, builds and steps
/// for seconds: not fuzzed here, as the large lattices; tests/fuzz.rs's
/// parameter cases build them under its cost guard.)
fn draw_range(p: &ParamSpec) -> (f64, f64) {
    if p.unit == "m" {
        (p.default / 2.0, p.default * 2.0)
    } else {
        (p.range.min, p.range.max)
    }
}

/// One FMU of the registry, as the fuzzer drives it: what it measured of
/// its scene at start-up.
#[derive(Clone)]
pub struct Info {
    /// The FMU.
    pub fmu: fmi::Fmu,
    /// Its variables.
    vars: Vec<fmi::Variable>,
    /// The value reference of its `particles_radial`, the lattice's
    /// resolution, if its scene has one (a scene without one, such as
    /// `plate_impact`, is cheap at its default: tests/fuzz.rs measures it).
    pr: Option<u32>,
    /// The coarse `particles_radial` of its scene (tests/fuzz.rs's
    /// `coarse_radial`), and the default; 0 for a scene without one.
    radial: i32,
    default_radial: i32,
    /// Whether a coarse run to its end is cheap (steps of any size).
    to_end: bool,
    /// The longest step a case takes on a coarse run: about 0.2 s of work.
    h: f64,
    /// A serialized FMU state of a coarse run after three steps.
    reference: Option<Bytes>,
}

impl Info {
    /// `particles_radial` values a case sets: cheap lattices, and values
    /// out of range. (Large in-range lattices take seconds to build: not
    /// fuzzed here.)
    fn radial_values(&self) -> [i32; 9] {
        let r = self.radial;
        let spec = self
            .fmu
            .kind()
            .param_specs()
            .iter()
            .find(|p| p.name == "particles_radial")
            .unwrap();
        [
            r,
            r,
            r + 1,
            r + 1,
            i32::MIN,
            0,
            spec.range.min as i32 - 1,
            spec.range.max as i32 + 1,
            i32::MAX,
        ]
    }
}

/// The calls of the FMU case running (for the report of a hang).
static TRACE: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// The calls the FMU case made so far, as the last one that returned left
/// them: after a hang, the call that hangs is the next one.
pub fn trace() -> Vec<String> {
    TRACE.lock().unwrap().clone()
}

/// Panics anywhere in the process since the hook was installed.
static PANICS: AtomicUsize = AtomicUsize::new(0);

/// Installs a panic hook that counts panics (and still prints them), so a
/// panic the FMU catches and turns into a status is seen.
pub fn count_panics() {
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        PANICS.fetch_add(1, Ordering::SeqCst);
        previous(info);
    }));
}

/// What the FMI 3 logger received.
#[derive(Default)]
struct Log {
    /// Messages with status Error.
    errors: usize,
    /// Messages with status Fatal or naming a panic.
    alarming: Vec<String>,
}

unsafe extern "C" fn log3(
    env: *mut c_void,
    status: c_int,
    _category: *const c_char,
    message: *const c_char,
) {
    // SAFETY: `env` is the case's `Mutex<Log>`, alive until after
    // fmi3FreeInstance; the FMU passes a NUL-terminated message.
    let (log, msg) = unsafe {
        (
            &*(env as *const Mutex<Log>),
            CStr::from_ptr(message).to_string_lossy().into_owned(),
        )
    };
    let mut log = log.lock().unwrap();
    if status == ERROR {
        log.errors += 1;
    }
    if status == FATAL || msg.contains("panic") {
        log.alarming.push(msg);
    }
}

/// Instance states of the standards (FMI 2 stepComplete is `Step`; its
/// stepFailed is never reached: no step is discarded, issue 65).
#[derive(Debug, Clone, Copy, PartialEq)]
enum St {
    Instantiated,
    Init,
    Step,
    Terminated,
}

/// What the host knows about the instance. `st` is `None` after restoring
/// bytes the fuzzer corrupted: nothing is predicted until the next Reset.
#[derive(Debug, Clone, Copy)]
struct Model {
    st: Option<St>,
    /// FMI 2: the start time given to fmi2SetupExperiment.
    start: f64,
    stop: Option<f64>,
    /// The communication time, as the FMU must report it.
    time: f64,
    /// `particles_radial`, when known.
    radial: Option<i32>,
    /// A Float64 parameter may differ from its default (a stiff material,
    /// say, with a tiny time step).
    tuned: bool,
}

impl Model {
    fn new(info: &Info) -> Self {
        Model {
            st: Some(St::Instantiated),
            start: 0.0,
            stop: None,
            time: 0.0,
            radial: Some(info.default_radial),
            tuned: false,
        }
    }
    fn is(&self, states: &[St]) -> bool {
        self.st.is_some_and(|s| states.contains(&s))
    }
    /// A cheap run: a coarse lattice of the default body, to whose end
    /// (measured: seconds at most) steps of any size are affordable.
    fn cheap(&self, info: &Info) -> bool {
        info.to_end
            && self.st.is_some()
            && self.radial.is_some_and(|n| n <= info.radial)
            && !self.tuned
    }
}

/// A serialized FMU state with what the host knows about it.
#[derive(Clone)]
pub struct Bytes {
    data: Vec<u8>,
    model: Model,
}

/// One standard's functions, as a host calls them. Values go in and come
/// out as f64; the implementations convert to the standard's C types.
///
/// Safety of every unsafe method: the instance is live (or NULL), every
/// pointer NULL or valid for the count passed with it, every FMU state NULL
/// or a live one of this instance.
trait Fmu: Sized {
    const NAME: &'static str;
    const FMI2: bool;
    /// Instantiates; the flag says whether the FMU must accept the arguments
    /// (`Some(true)`), must refuse them (`Some(false)`) or may do either.
    fn new(rng: &mut Rng, log: *const Mutex<Log>, fmu: fmi::Fmu) -> (Self, Option<bool>, bool);
    fn ptr(&self) -> *mut c_void;
    /// FMI 2 `fmi2SetupExperiment` (`None` for FMI 3).
    unsafe fn setup(&mut self, start: f64, stop: Option<f64>) -> Option<c_int>;
    unsafe fn enter_init(&mut self, start: f64, stop: Option<f64>) -> c_int;
    unsafe fn exit_init(&mut self) -> c_int;
    /// The standard's C type of a Boolean.
    type Bool: Copy + Default + From<bool> + Into<f64>;
    /// The setters and getters of Float64 (Real), Int32 (Integer) and
    /// Boolean: `vrs` has `nvr` elements, the values `max(nvr, n_values)`.
    unsafe fn set_f64(&mut self, vrs: *const u32, nvr: usize, v: *const f64, n: usize) -> c_int;
    unsafe fn set_i32(&mut self, vrs: *const u32, nvr: usize, v: *const i32, n: usize) -> c_int;
    unsafe fn set_bool(
        &mut self,
        vrs: *const u32,
        nvr: usize,
        v: *const Self::Bool,
        n: usize,
    ) -> c_int;
    unsafe fn get_f64(&mut self, vrs: *const u32, nvr: usize, v: *mut f64, n: usize) -> c_int;
    unsafe fn get_i32(&mut self, vrs: *const u32, nvr: usize, v: *mut i32, n: usize) -> c_int;
    /// The Int64 setter and getter (FMI 3's enumerations); FMI 2 reads and
    /// writes enumerations as Integer.
    unsafe fn set_i64(&mut self, vrs: *const u32, nvr: usize, v: *const i64, n: usize) -> c_int;
    unsafe fn get_i64(&mut self, vrs: *const u32, nvr: usize, v: *mut i64, n: usize) -> c_int;
    unsafe fn get_bool(
        &mut self,
        vrs: *const u32,
        nvr: usize,
        v: *mut Self::Bool,
        n: usize,
    ) -> c_int;
    /// Sets `values` (NULL for `None`) as the C type of `ty`.
    unsafe fn set(
        &mut self,
        ty: VarType,
        vrs: *const u32,
        nvr: usize,
        values: Option<&[f64]>,
        n_values: usize,
    ) -> c_int {
        // SAFETY: forwarded contract.
        unsafe {
            match ty {
                VarType::Float64 => {
                    let v = typed(values, |x| x);
                    self.set_f64(vrs, nvr, ptr_of(&v), n_values)
                }
                VarType::Int32 => {
                    let v = typed(values, |x| x as i32);
                    self.set_i32(vrs, nvr, ptr_of(&v), n_values)
                }
                VarType::Enumeration => {
                    let v = typed(values, |x| x as i64);
                    self.set_i64(vrs, nvr, ptr_of(&v), n_values)
                }
                VarType::Boolean => {
                    let v = typed(values, |x| Self::Bool::from(x != 0.0));
                    self.set_bool(vrs, nvr, ptr_of(&v), n_values)
                }
            }
        }
    }
    /// Gets `max(nvr, n_values)` values of the C type of `ty` into `out`
    /// as f64, or passes NULL (`null`).
    unsafe fn get(
        &mut self,
        ty: VarType,
        vrs: *const u32,
        nvr: usize,
        out: &mut Vec<f64>,
        null: bool,
        n_values: usize,
    ) -> c_int {
        let len = nvr.max(n_values);
        // SAFETY: forwarded contract; the buffer has `len` elements.
        unsafe {
            match ty {
                VarType::Float64 => read_into(
                    out,
                    null,
                    len,
                    |p| self.get_f64(vrs, nvr, p, n_values),
                    |x: f64| x,
                ),
                VarType::Int32 => read_into(
                    out,
                    null,
                    len,
                    |p| self.get_i32(vrs, nvr, p, n_values),
                    |x: i32| x as f64,
                ),
                VarType::Enumeration => read_into(
                    out,
                    null,
                    len,
                    |p| self.get_i64(vrs, nvr, p, n_values),
                    |x: i64| x as f64,
                ),
                VarType::Boolean => read_into(
                    out,
                    null,
                    len,
                    |p| self.get_bool(vrs, nvr, p, n_values),
                    |x: Self::Bool| x.into(),
                ),
            }
        }
    }
    /// The status and, on success, the new communication time and whether
    /// the FMU asked to terminate.
    unsafe fn do_step(&mut self, current: f64, h: f64, null_out: bool) -> (c_int, f64, bool);
    unsafe fn terminate(&mut self) -> c_int;
    unsafe fn reset(&mut self) -> c_int;
    unsafe fn logging(&mut self, on: bool, cats: *const *const c_char, n: usize) -> c_int;
    unsafe fn get_state(&mut self, s: *mut *mut c_void) -> c_int;
    unsafe fn set_state(&mut self, s: *mut c_void) -> c_int;
    unsafe fn free_state(&mut self, s: *mut *mut c_void) -> c_int;
    unsafe fn size(&mut self, s: *mut c_void, size: *mut usize) -> c_int;
    unsafe fn serialize(&mut self, s: *mut c_void, out: *mut u8, size: usize) -> c_int;
    unsafe fn deserialize(&mut self, data: *const u8, size: usize, s: *mut *mut c_void) -> c_int;
    /// A call that fails unless the state allows it and its arguments ask
    /// for nothing (a function this FMU does not support, a variable type it
    /// has none of, an FMI 2 status of a kind): its name, its status and
    /// whether it may return OK.
    unsafe fn other(&mut self, rng: &mut Rng, m: &Model) -> (String, c_int, bool);
    unsafe fn free(self);
}

/// Methods of [`Fmu`] that pass (some of) their arguments on to one
/// function of the standard, after the instance.
macro_rules! forward {
    ($( $method:ident ( $($arg:ident : $t:ty),* ) => $f:path [ $($pass:ident),* ]; )*) => {$(
        unsafe fn $method(&mut self $(, $arg: $t)*) -> c_int {
            // SAFETY: the contract of `Fmu`: a live instance or NULL, and
            // pointers NULL or valid for the counts passed with them.
            unsafe { $f(self.0 $(, $pass)*) }
        }
    )*};
}

/// The type through which standard `F` reads and writes a variable of type
/// `ty`: FMI 2 reads and writes an enumeration as an Integer.
fn ty_in<F: Fmu>(ty: VarType) -> VarType {
    if F::FMI2 && ty == VarType::Enumeration {
        VarType::Int32
    } else {
        ty
    }
}

struct Fmi3(*mut c_void);
struct Fmi2(*mut c_void);

fn typed<T>(values: Option<&[f64]>, f: impl Fn(f64) -> T) -> Option<Vec<T>> {
    values.map(|v| v.iter().map(|&x| f(x)).collect())
}

fn ptr_of<T>(v: &Option<Vec<T>>) -> *const T {
    v.as_ref().map_or(null(), |v| v.as_ptr())
}

/// Writes into a typed buffer of `n` elements (or passes NULL) and reads it
/// back as f64.
fn read_into<T: Copy + Default>(
    out: &mut Vec<f64>,
    null: bool,
    n: usize,
    call: impl FnOnce(*mut T) -> c_int,
    back: impl Fn(T) -> f64,
) -> c_int {
    let mut buf = vec![T::default(); n];
    let code = call(if null { null_mut() } else { buf.as_mut_ptr() });
    *out = buf.into_iter().map(back).collect();
    code
}

impl Fmu for Fmi3 {
    const NAME: &'static str = "FMI 3.0";
    const FMI2: bool = false;
    type Bool = u8;

    fn new(rng: &mut Rng, log: *const Mutex<Log>, fmu: fmi::Fmu) -> (Self, Option<bool>, bool) {
        let good = CString::new(fmu.token()).unwrap();
        let bad = CString::new("{00000000-0000-0000-0000-000000000000}").unwrap();
        let (token, expect) = match rng.below(10) {
            0 => (bad.as_ptr(), Some(false)),
            1 => (null(), None),
            _ => (good.as_ptr(), Some(true)),
        };
        let name = CString::new("fuzz").unwrap();
        // SAFETY: NUL-terminated strings or NULL; the logger and its
        // environment outlive the instance (freed after fmi3FreeInstance).
        let p = unsafe {
            fmi3::fmi3InstantiateCoSimulation(
                if rng.below(4) == 0 {
                    null()
                } else {
                    name.as_ptr()
                },
                token,
                null(),
                0,
                rng.below(2) as u8,
                0,
                rng.below(2) as u8,
                null(),
                0,
                log as *mut c_void,
                Some(log3),
                null_mut(),
            )
        };
        (Fmi3(p), expect, token.is_null())
    }
    fn ptr(&self) -> *mut c_void {
        self.0
    }
    unsafe fn setup(&mut self, _: f64, _: Option<f64>) -> Option<c_int> {
        None
    }
    unsafe fn enter_init(&mut self, start: f64, stop: Option<f64>) -> c_int {
        // SAFETY: a live instance or NULL.
        unsafe {
            fmi3::fmi3EnterInitializationMode(
                self.0,
                0,
                0.0,
                start,
                stop.is_some() as u8,
                stop.unwrap_or(f64::NAN),
            )
        }
    }
    forward! {
        exit_init() => fmi3::fmi3ExitInitializationMode[];
        terminate() => fmi3::fmi3Terminate[];
        reset() => fmi3::fmi3Reset[];
        set_f64(r: *const u32, n: usize, v: *const f64, m: usize) => fmi3::fmi3SetFloat64[r, n, v, m];
        set_i32(r: *const u32, n: usize, v: *const i32, m: usize) => fmi3::fmi3SetInt32[r, n, v, m];
        set_bool(r: *const u32, n: usize, v: *const u8, m: usize) => fmi3::fmi3SetBoolean[r, n, v, m];
        get_f64(r: *const u32, n: usize, v: *mut f64, m: usize) => fmi3::fmi3GetFloat64[r, n, v, m];
        get_i32(r: *const u32, n: usize, v: *mut i32, m: usize) => fmi3::fmi3GetInt32[r, n, v, m];
        set_i64(r: *const u32, n: usize, v: *const i64, m: usize) => fmi3::fmi3SetInt64[r, n, v, m];
        get_i64(r: *const u32, n: usize, v: *mut i64, m: usize) => fmi3::fmi3GetInt64[r, n, v, m];
        get_bool(r: *const u32, n: usize, v: *mut u8, m: usize) => fmi3::fmi3GetBoolean[r, n, v, m];
        get_state(s: *mut *mut c_void) => fmi3::fmi3GetFMUState[s];
        set_state(s: *mut c_void) => fmi3::fmi3SetFMUState[s];
        free_state(s: *mut *mut c_void) => fmi3::fmi3FreeFMUState[s];
        size(s: *mut c_void, n: *mut usize) => fmi3::fmi3SerializedFMUStateSize[s, n];
        serialize(s: *mut c_void, b: *mut u8, n: usize) => fmi3::fmi3SerializeFMUState[s, b, n];
        deserialize(b: *const u8, n: usize, s: *mut *mut c_void) => fmi3::fmi3DeserializeFMUState[b, n, s];
    }
    unsafe fn do_step(&mut self, current: f64, h: f64, null_out: bool) -> (c_int, f64, bool) {
        let (mut event, mut term, mut early, mut last) = (7u8, 7u8, 7u8, f64::NAN);
        // SAFETY: a live instance or NULL; the outputs writable or NULL.
        let code = unsafe {
            fmi3::fmi3DoStep(
                self.0,
                current,
                h,
                0,
                &mut event,
                if null_out { null_mut() } else { &mut term },
                &mut early,
                &mut last,
            )
        };
        if code == OK {
            // No event, and no request to stop: past the scene's end the
            // outputs hold (issue 65).
            assert!(
                event == 0 && term == 0 && early < 2,
                "DoStep flags {event} {term} {early}"
            );
            if early == 0 {
                assert_eq!(last, current + h, "lastSuccessfulTime without early return");
            }
        }
        (code, last, term == 1)
    }
    unsafe fn logging(&mut self, on: bool, cats: *const *const c_char, n: usize) -> c_int {
        // SAFETY: `cats` holds `n` strings or is NULL.
        unsafe { fmi3::fmi3SetDebugLogging(self.0, on as u8, n, cats) }
    }
    unsafe fn other(&mut self, rng: &mut Rng, m: &Model) -> (String, c_int, bool) {
        let vrs = [1u32, 2, 3];
        let n = rng.below(3);
        let mut f32s = [0f32; 3];
        let mut strs = [null::<c_char>(); 3];
        // SAFETY: arrays of three elements, `n` at most 2.
        unsafe {
            match rng.below(5) {
                0 => (
                    "fmi3EnterEventMode".into(),
                    fmi3::fmi3EnterEventMode(self.0),
                    false,
                ),
                1 => (
                    "fmi3EnterStepMode".into(),
                    fmi3::fmi3EnterStepMode(self.0),
                    false,
                ),
                2 => (
                    format!("fmi3GetFloat32 n={n}"),
                    fmi3::fmi3GetFloat32(self.0, vrs.as_ptr(), n, f32s.as_mut_ptr(), n),
                    n == 0 && !m.is(&[St::Instantiated]),
                ),
                3 => (
                    format!("fmi3SetFloat32 n={n}"),
                    fmi3::fmi3SetFloat32(self.0, vrs.as_ptr(), n, f32s.as_ptr(), n),
                    n == 0 && m.is(&[St::Instantiated, St::Init, St::Step]),
                ),
                _ => (
                    format!("fmi3GetString n={n}"),
                    fmi3::fmi3GetString(self.0, vrs.as_ptr(), n, strs.as_mut_ptr(), n),
                    n == 0 && !m.is(&[St::Instantiated]),
                ),
            }
        }
    }
    unsafe fn free(self) {
        // SAFETY: a live instance (or NULL), not used afterwards.
        unsafe { fmi3::fmi3FreeInstance(self.0) }
    }
}

impl Fmu for Fmi2 {
    const NAME: &'static str = "FMI 2.0";
    const FMI2: bool = true;
    type Bool = c_int;

    fn new(rng: &mut Rng, _log: *const Mutex<Log>, fmu: fmi::Fmu) -> (Self, Option<bool>, bool) {
        let good = CString::new(fmu.token()).unwrap();
        let bad = CString::new("{00000000-0000-0000-0000-000000000000}").unwrap();
        let (guid, mut expect) = match rng.below(10) {
            0 => (bad.as_ptr(), Some(false)),
            1 => (null(), None),
            _ => (good.as_ptr(), Some(true)),
        };
        // fmi2CoSimulation = 1; Model Exchange (0) and nonsense are refused.
        let kind = *rng.pick(&[1, 1, 1, 1, 1, 1, 1, 0, 2, -1]);
        if kind != 1 {
            expect = Some(false);
        }
        // The logger is C-variadic, which stable Rust cannot define: FMI 2
        // instances log nowhere, and panics are seen by the hook and Fatal.
        let functions = fmi2::CallbackFunctions {
            logger: None,
            allocate_memory: null_mut(),
            free_memory: null_mut(),
            step_finished: null_mut(),
            component_environment: null_mut(),
        };
        let name = CString::new("fuzz").unwrap();
        // SAFETY: NUL-terminated strings or NULL; `functions` is read during
        // the call only (no logger).
        let p = unsafe {
            fmi2::fmi2Instantiate(
                name.as_ptr(),
                kind,
                guid,
                null(),
                if rng.below(4) == 0 {
                    null()
                } else {
                    &functions
                },
                0,
                rng.below(2) as c_int,
            )
        };
        (Fmi2(p), expect, guid.is_null())
    }
    fn ptr(&self) -> *mut c_void {
        self.0
    }
    unsafe fn setup(&mut self, start: f64, stop: Option<f64>) -> Option<c_int> {
        // SAFETY: a live instance or NULL.
        Some(unsafe {
            fmi2::fmi2SetupExperiment(
                self.0,
                0,
                0.0,
                start,
                stop.is_some() as c_int,
                stop.unwrap_or(f64::NAN),
            )
        })
    }
    unsafe fn enter_init(&mut self, _: f64, _: Option<f64>) -> c_int {
        // SAFETY: a live instance or NULL.
        unsafe { fmi2::fmi2EnterInitializationMode(self.0) }
    }
    unsafe fn set_i64(&mut self, _: *const u32, _: usize, _: *const i64, _: usize) -> c_int {
        unreachable!("FMI 2 writes enumerations as Integer (`ty_in`)")
    }
    unsafe fn get_i64(&mut self, _: *const u32, _: usize, _: *mut i64, _: usize) -> c_int {
        unreachable!("FMI 2 reads enumerations as Integer (`ty_in`)")
    }
    forward! {
        exit_init() => fmi2::fmi2ExitInitializationMode[];
        terminate() => fmi2::fmi2Terminate[];
        reset() => fmi2::fmi2Reset[];
        set_f64(r: *const u32, n: usize, v: *const f64, _m: usize) => fmi2::fmi2SetReal[r, n, v];
        set_i32(r: *const u32, n: usize, v: *const i32, _m: usize) => fmi2::fmi2SetInteger[r, n, v];
        set_bool(r: *const u32, n: usize, v: *const c_int, _m: usize) => fmi2::fmi2SetBoolean[r, n, v];
        get_f64(r: *const u32, n: usize, v: *mut f64, _m: usize) => fmi2::fmi2GetReal[r, n, v];
        get_i32(r: *const u32, n: usize, v: *mut i32, _m: usize) => fmi2::fmi2GetInteger[r, n, v];
        get_bool(r: *const u32, n: usize, v: *mut c_int, _m: usize) => fmi2::fmi2GetBoolean[r, n, v];
        get_state(s: *mut *mut c_void) => fmi2::fmi2GetFMUstate[s];
        set_state(s: *mut c_void) => fmi2::fmi2SetFMUstate[s];
        free_state(s: *mut *mut c_void) => fmi2::fmi2FreeFMUstate[s];
        size(s: *mut c_void, n: *mut usize) => fmi2::fmi2SerializedFMUstateSize[s, n];
        serialize(s: *mut c_void, b: *mut u8, n: usize) => fmi2::fmi2SerializeFMUstate[s, b, n];
        deserialize(b: *const u8, n: usize, s: *mut *mut c_void) => fmi2::fmi2DeSerializeFMUstate[b, n, s];
    }
    unsafe fn do_step(&mut self, current: f64, h: f64, _null_out: bool) -> (c_int, f64, bool) {
        // SAFETY: a live instance or NULL.
        let code = unsafe { fmi2::fmi2DoStep(self.0, current, h, 0) };
        match code {
            OK => (code, current + h, false),
            _ => (code, f64::NAN, false),
        }
    }
    unsafe fn logging(&mut self, on: bool, cats: *const *const c_char, n: usize) -> c_int {
        // SAFETY: `cats` holds `n` strings or is NULL.
        unsafe { fmi2::fmi2SetDebugLogging(self.0, on as c_int, n, cats) }
    }
    unsafe fn other(&mut self, rng: &mut Rng, m: &Model) -> (String, c_int, bool) {
        let vrs = [1u32, 2, 3];
        let n = rng.below(3);
        let mut strs = [null::<c_char>(); 3];
        let kind = rng.below(6) as c_int - 1;
        let queried = m.is(&[St::Step, St::Terminated]);
        let (mut i, mut r, mut s) = (0 as c_int, 0.0, null::<c_char>());
        // SAFETY: arrays of three elements, `n` at most 2; writable outputs.
        unsafe {
            match rng.below(8) {
                0 => ("fmi2CancelStep".into(), fmi2::fmi2CancelStep(self.0), false),
                1 => (
                    format!("fmi2GetString n={n}"),
                    fmi2::fmi2GetString(self.0, vrs.as_ptr(), n, strs.as_mut_ptr()),
                    n == 0 && !m.is(&[St::Instantiated]),
                ),
                2 => (
                    format!("fmi2SetString n={n}"),
                    fmi2::fmi2SetString(self.0, vrs.as_ptr(), n, strs.as_ptr()),
                    n == 0 && m.is(&[St::Instantiated, St::Init, St::Step]),
                ),
                3 => (
                    format!("fmi2GetStatus {kind}"),
                    fmi2::fmi2GetStatus(self.0, kind, &mut i),
                    kind == 0 && queried,
                ),
                4 => {
                    let code = fmi2::fmi2GetRealStatus(self.0, kind, &mut r);
                    if code == OK {
                        assert!(r.is_finite(), "fmi2GetRealStatus {kind}: {r} with OK");
                    }
                    (
                        format!("fmi2GetRealStatus {kind}"),
                        code,
                        kind == 2 && queried,
                    )
                }
                5 => (
                    format!("fmi2GetIntegerStatus {kind}"),
                    fmi2::fmi2GetIntegerStatus(self.0, kind, &mut i),
                    false,
                ),
                6 => (
                    format!("fmi2GetBooleanStatus {kind}"),
                    fmi2::fmi2GetBooleanStatus(self.0, kind, &mut i),
                    kind == 3 && queried,
                ),
                _ => (
                    format!("fmi2GetStringStatus {kind}"),
                    fmi2::fmi2GetStringStatus(self.0, kind, &mut s),
                    kind == 1 && queried,
                ),
            }
        }
    }
    unsafe fn free(self) {
        // SAFETY: a live instance (or NULL), not used afterwards.
        unsafe { fmi2::fmi2FreeInstance(self.0) }
    }
}

/// A serialized FMU state of a coarse FMI 3 run of `info`'s FMU after
/// three steps, made once, for cases that deserialize before they serialize
/// anything.
fn reference_state(info: &Info) -> Bytes {
    let log = Mutex::new(Log::default());
    let mut rng = Rng(2);
    let mut f = loop {
        match Fmi3::new(&mut rng, &log, info.fmu) {
            (f, Some(true), _) => break f,
            // SAFETY: NULL or a live instance, freed once.
            (f, _, _) => unsafe { f.free() },
        }
    };
    let mut m = Model::new(info);
    let mut s = null_mut();
    let mut size = 0;
    // SAFETY: a live instance; valid arrays and outputs; the state freed once.
    let data = unsafe {
        if let Some(pr) = info.pr {
            assert_eq!(
                f.set(VarType::Int32, &pr, 1, Some(&[info.radial as f64]), 1),
                OK
            );
        }
        assert_eq!(f.enter_init(0.0, None), OK);
        assert_eq!(f.exit_init(), OK);
        for _ in 0..3 {
            let (code, t, _) = f.do_step(m.time, info.h.min(1e-6), false);
            assert_eq!(code, OK);
            m.time = t;
        }
        assert_eq!(f.get_state(&mut s), OK);
        assert_eq!(f.size(s, &mut size), OK);
        let mut data = vec![0; size];
        assert_eq!(f.serialize(s, data.as_mut_ptr(), size), OK);
        assert_eq!(f.free_state(&mut s), OK);
        f.free();
        data
    };
    m.st = Some(St::Step);
    m.radial = Some(info.radial);
    Bytes { data, model: m }
}

/// Mangles serialized bytes: a byte changed, a cut, a leaf of the typed
/// state edited, a field replaced by a forged one (another run's simulation
/// or scene, an impossible instance state, a hostile time) or a wrong
/// header. The typed edits decode the state ([`fmi::Fmu::state_to_json`]),
/// edit its JSON form and encode it again; an edit that the state's types
/// cannot hold changes a byte instead. Returns what was done.
fn corrupt(rng: &mut Rng, data: &mut Vec<u8>, sims: &[serde_json::Value], fmu: fmi::Fmu) -> String {
    let header = data
        .iter()
        .enumerate()
        .filter(|(_, b)| **b == b'\n')
        .nth(1)
        .map_or(0, |(k, _)| k + 1);
    let json = fmu.state_to_json(data).ok();
    let edit = match (rng.below(6), json) {
        (0, _) | (_, None) if !data.is_empty() => {
            let at = rng.below(data.len());
            data[at] = rng.next() as u8;
            return format!("byte {at} changed");
        }
        (1, _) => {
            data.truncate(rng.below(data.len() + 1));
            return format!("cut to {} bytes", data.len());
        }
        (2, _) => {
            let at = rng.below(header.max(1));
            data.insert(at.min(data.len()), b'x');
            return format!("header byte inserted at {at}");
        }
        (3, Some(mut v)) => {
            let e = edit_leaf(rng, &mut v);
            (v, e)
        }
        (_, Some(mut v)) => {
            let sim = rng.pick(sims);
            let (key, new) = match rng.below(6) {
                0 => ("sim", sim.clone()),
                1 => ("sim", serde_json::Value::Null),
                2 => ("scene", sim["scene"].clone()),
                3 => (
                    "state",
                    serde_json::json!(*rng.pick(&[0u32, 3, 6, 32, 64, u32::MAX])),
                ),
                4 => ("stop_time", serde_json::json!(rng.number(-1e-3, 1e-3))),
                _ => (
                    *rng.pick(&["time", "start_time", "last_successful_time"]),
                    serde_json::json!(rng.number(-1e-3, 1e-3)),
                ),
            };
            let e = format!("{key} forged");
            v[key] = new;
            (v, e)
        }
        _ => return "nothing to corrupt".into(),
    };
    match fmu.state_from_json(edit.0) {
        Ok(bytes) => {
            *data = bytes;
            edit.1
        }
        Err(e) => {
            let at = rng.below(data.len());
            data[at] = rng.next() as u8;
            format!("{} ({e}): byte {at} changed instead", edit.1)
        }
    }
}

/// One case: instantiate, up to [`CALLS`] random calls, free.
struct Case<F: Fmu> {
    fmu: F,
    m: Model,
    /// FMU states the host holds, with what it knows of them.
    slots: [(*mut c_void, Model); 3],
    bytes: Vec<Bytes>,
    log: *const Mutex<Log>,
    calls: Vec<String>,
    /// The FMU.
    info: Info,
}

impl<F: Fmu> Case<F> {
    fn errors_logged(&self) -> usize {
        // SAFETY: the case's log, alive for the case.
        unsafe { (*self.log).lock().unwrap().errors }
    }

    /// Checks a status: documented, never Fatal, Error when `must_fail`,
    /// OK when `must_work`; an FMI 3 Error comes with a logged message.
    /// The model follows: an Error leaves the instance Terminated.
    fn check(
        &mut self,
        what: String,
        code: c_int,
        must_fail: bool,
        must_work: bool,
        logged: usize,
    ) {
        let live = !self.fmu.ptr().is_null();
        self.calls.push(format!("{what} -> {code}"));
        *TRACE.lock().unwrap() = self.calls.clone();
        let calls = &self.calls[self.calls.len().saturating_sub(12)..];
        assert!((0..=4).contains(&code), "undocumented status: {calls:?}");
        assert_ne!(code, FATAL, "Fatal (a caught panic): {calls:?}");
        if must_fail {
            assert_eq!(code, ERROR, "must be Error: {calls:?}");
        }
        if must_work && live {
            assert_eq!(code, OK, "must be OK: {calls:?}");
        }
        if code == ERROR {
            if !F::FMI2 && live {
                assert!(
                    self.errors_logged() > logged,
                    "Error without a message: {calls:?}"
                );
            }
            if self.m.st.is_some() {
                self.m.st = Some(St::Terminated);
            }
        }
    }

    /// A random experiment time: usually 0 or small, sometimes hostile.
    fn time(rng: &mut Rng) -> f64 {
        match rng.below(4) {
            0 | 1 => 0.0,
            _ => rng.number(-1e-3, 1e-3),
        }
    }

    fn stop(rng: &mut Rng, start: f64) -> Option<f64> {
        match rng.below(4) {
            0 => None,
            1 => Some(start + 1e-4),
            _ => Some(rng.number(start - 1e-6, start + 1e-4)),
        }
    }

    /// A bad stopTime the FMU must refuse.
    fn bad_stop(start: f64, stop: Option<f64>) -> bool {
        stop.is_some_and(|s| !s.is_finite() || s < start)
    }

    fn random_call(&mut self, rng: &mut Rng, sims: &[serde_json::Value]) {
        let logged = self.errors_logged();
        let st = self.m.st;
        // Two times in three the next call of an ordinary run, or of a
        // host recovering from an Error (Reset, or a saved state restored).
        let op = match (rng.below(3), st) {
            (0, _) => rng.below(16),
            (_, Some(St::Instantiated)) => *rng.pick(&[0, 1, 1, 2]),
            (_, Some(St::Init)) => *rng.pick(&[2, 3, 4, 4]),
            (_, Some(St::Step)) => *rng.pick(&[5, 5, 5, 5, 3, 7, 8, 9, 10]),
            _ => *rng.pick(&[11, 16, 16]),
        };
        // SAFETY (the unsafe calls below): the instance is live, every
        // array holds the elements its count says, every FMU state passed is
        // live or NULL and is freed once (the FMU sets the slot to NULL).
        match op {
            0 => {
                let start = Self::time(rng);
                let stop = Self::stop(rng, start);
                let Some(code) = (unsafe { self.fmu.setup(start, stop) }) else {
                    return self.random_call(rng, sims);
                };
                let fail = self.m.st.is_some()
                    && (!self.m.is(&[St::Instantiated])
                        || !start.is_finite()
                        || Self::bad_stop(start, stop));
                self.check(
                    format!("setup {start:?} {stop:?}"),
                    code,
                    fail,
                    false,
                    logged,
                );
                if code == OK {
                    (self.m.start, self.m.stop) = (start, stop);
                }
            }
            1 => {
                let start = if F::FMI2 {
                    self.m.start
                } else {
                    Self::time(rng)
                };
                let stop = if F::FMI2 {
                    self.m.stop
                } else {
                    Self::stop(rng, start)
                };
                let code = unsafe { self.fmu.enter_init(start, stop) };
                let fail = self.m.st.is_some()
                    && (!self.m.is(&[St::Instantiated])
                        || !start.is_finite()
                        || Self::bad_stop(start, stop));
                self.check(
                    format!("enter {start:?} {stop:?}"),
                    code,
                    fail,
                    false,
                    logged,
                );
                if code == OK {
                    self.m.st = Some(St::Init);
                    (self.m.start, self.m.stop, self.m.time) = (start, stop, start);
                }
            }
            2 => self.set(rng, logged),
            3 => self.get(rng, logged),
            4 => {
                let code = unsafe { self.fmu.exit_init() };
                let fail = self.m.st.is_some() && !self.m.is(&[St::Init]);
                self.check("exit".into(), code, fail, false, logged);
                if code == OK {
                    self.m.st = self.m.st.map(|_| St::Step);
                }
            }
            5 | 6 => self.step(rng, logged),
            7 => self.states(rng, logged),
            8 => self.serialize(rng, logged),
            9 => self.deserialize(rng, sims, logged),
            10 => {
                let code = unsafe { self.fmu.terminate() };
                let fail = self.m.is(&[St::Instantiated, St::Init, St::Terminated]);
                self.check("terminate".into(), code, fail, false, logged);
                if code == OK {
                    self.m.st = self.m.st.map(|_| St::Terminated);
                }
            }
            11 => self.reset(rng, logged),
            16 => self.restore(rng, logged),
            12 => {
                let names = ["logStatusError", "logEvents", "logProgress", "bogus", ""];
                let n = rng.below(3);
                let picked: Vec<&str> = (0..n).map(|_| *rng.pick(&names)).collect();
                let owned: Vec<CString> =
                    picked.iter().map(|s| CString::new(*s).unwrap()).collect();
                let ptrs: Vec<*const c_char> = owned.iter().map(|s| s.as_ptr()).collect();
                let no_array = n > 0 && rng.below(6) == 0;
                let on = rng.below(2) == 0;
                let code = unsafe {
                    self.fmu
                        .logging(on, if no_array { null() } else { ptrs.as_ptr() }, n)
                };
                let bad = no_array || picked.iter().any(|c| !c.starts_with("log"));
                self.check(
                    format!("logging {on} {picked:?} null={no_array}"),
                    code,
                    bad,
                    !bad,
                    logged,
                );
            }
            _ => {
                let m = self.m;
                let (what, code, may_work) = unsafe { self.fmu.other(rng, &m) };
                let fail = self.m.st.is_some() && !may_work;
                self.check(what, code, fail, false, logged);
            }
        }
    }

    /// A list of value references: the variables of the table, and some
    /// that are not.
    fn refs(&self, rng: &mut Rng) -> Vec<u32> {
        let n = self.info.vars.len() as u32;
        (0..rng.below(4))
            .map(|_| match rng.below(8) {
                0 => *rng.pick(&[n, n + 1, 999, u32::MAX]),
                _ => rng.below(n as usize) as u32,
            })
            .collect()
    }

    fn set(&mut self, rng: &mut Rng, logged: usize) {
        let vars = self.info.vars.clone();
        let ty = ty_in::<F>(*rng.pick(&[
            VarType::Float64,
            VarType::Float64,
            VarType::Int32,
            VarType::Int32,
            VarType::Boolean,
            VarType::Enumeration,
        ]));
        let mut vrs = self.refs(rng);
        if let Some(pr) = self.info.pr
            && ty == VarType::Int32
            && rng.below(2) == 0
        {
            vrs = vec![pr];
        } else if rng.below(2) == 0 {
            // Only parameters of this type: the sets that may work.
            vrs.retain(|&r| {
                vars.get(r as usize).is_some_and(|v| {
                    ty_in::<F>(v.ty) == ty && matches!(v.kind, VarKind::Parameter(_))
                })
            });
        }
        let nvr = vrs.len();
        let n = if !F::FMI2 && rng.below(8) == 0 {
            rng.below(4)
        } else {
            nvr
        };
        let values: Vec<f64> = (0..nvr.max(n))
            .map(|k| match vrs.get(k).and_then(|&r| vars.get(r as usize)) {
                Some(v) if v.name == "particles_radial" => {
                    *rng.pick(&self.info.radial_values()) as f64
                }
                Some(fmi::Variable {
                    kind: VarKind::Parameter(p),
                    ty: VarType::Int32 | VarType::Enumeration,
                    ..
                }) => *rng.pick(&[
                    p.range.min,
                    p.range.max,
                    p.default,
                    p.range.min - 1.0,
                    p.range.max + 1.0,
                    i32::MIN as f64,
                    i32::MAX as f64,
                ]),
                Some(fmi::Variable {
                    kind: VarKind::Parameter(p),
                    ..
                }) => {
                    let (lo, hi) = draw_range(p);
                    rng.number(lo, hi)
                }
                _ => rng.number(0.0, 1.0),
            })
            .collect();
        let (null_vrs, null_vals) = (nvr > 0 && rng.below(10) == 0, nvr > 0 && rng.below(10) == 0);
        let code = unsafe {
            self.fmu.set(
                ty,
                if null_vrs { null() } else { vrs.as_ptr() },
                nvr,
                if null_vals { None } else { Some(&values) },
                n,
            )
        };
        // Values as the FMU receives them in its C type.
        let received = |x: f64| match ty {
            VarType::Float64 => x,
            VarType::Int32 => x as i32 as f64,
            VarType::Enumeration => x as i64 as f64,
            VarType::Boolean => (x != 0.0) as u8 as f64,
        };
        let settable = vrs.iter().zip(&values).all(|(&r, &x)| {
            matches!(vars.get(r as usize), Some(v) if ty_in::<F>(v.ty) == ty
                && matches!(v.kind, VarKind::Parameter(p) if p.range.contains(received(x))))
        });
        let typed_params = vrs.iter().all(|&r| {
            matches!(vars.get(r as usize), Some(v) if ty_in::<F>(v.ty) == ty && matches!(v.kind, VarKind::Parameter(_)))
        });
        let arrays = !null_vrs && !null_vals && n == nvr;
        let allowed = self.m.is(&[St::Instantiated, St::Init]);
        let fail = self.m.st.is_some()
            && (!arrays
                || (nvr > 0 && (!typed_params || !self.m.is(&[St::Instantiated, St::Init])))
                || !self.m.is(&[St::Instantiated, St::Init, St::Step]));
        let work = allowed && arrays && settable;
        self.check(
            format!("set {ty:?} {vrs:?} {values:?} n={n} null={null_vrs},{null_vals}"),
            code,
            fail,
            work,
            logged,
        );
        if ty == VarType::Float64 && nvr > 0 {
            self.m.tuned = true;
        }
        if let Some(pr) = self.info.pr
            && let Some(k) = vrs.iter().rposition(|&r| r == pr)
        {
            self.m.radial = if code == OK {
                Some(values[k] as i32)
            } else {
                None
            };
        }
    }

    fn get(&mut self, rng: &mut Rng, logged: usize) {
        let vars = self.info.vars.clone();
        let ty = ty_in::<F>(*rng.pick(&[
            VarType::Float64,
            VarType::Float64,
            VarType::Int32,
            VarType::Boolean,
            VarType::Enumeration,
        ]));
        let mut vrs = self.refs(rng);
        if rng.below(2) == 0 {
            // Only variables of this type: the reads that must work.
            vrs.retain(|&r| {
                vars.get(r as usize)
                    .is_some_and(|v| ty_in::<F>(v.ty) == ty && !(F::FMI2 && r == fmi::VR_TIME))
            });
        }
        let nvr = vrs.len();
        let n = if !F::FMI2 && rng.below(8) == 0 {
            rng.below(4)
        } else {
            nvr
        };
        let (null_vrs, null_out) = (nvr > 0 && rng.below(10) == 0, nvr > 0 && rng.below(10) == 0);
        let mut out = Vec::new();
        let code = unsafe {
            self.fmu.get(
                ty,
                if null_vrs { null() } else { vrs.as_ptr() },
                nvr,
                &mut out,
                null_out,
                n,
            )
        };
        let typed = vrs.iter().all(|&r| {
            vars.get(r as usize)
                .is_some_and(|v| ty_in::<F>(v.ty) == ty && !(F::FMI2 && r == fmi::VR_TIME))
        });
        let fail = self.m.st.is_some()
            && (self.m.is(&[St::Instantiated]) || null_vrs || null_out || n != nvr || !typed);
        self.check(
            format!("get {ty:?} {vrs:?} n={n} null={null_vrs},{null_out}"),
            code,
            fail,
            false,
            logged,
        );
        if code != OK {
            return;
        }
        for (&r, &x) in vrs.iter().zip(&out) {
            let what = format!(
                "{} = {x} with OK after {:?}",
                vars[r as usize].name, self.calls
            );
            assert!(x.is_finite(), "{what}");
            if self.m.st.is_none() {
                continue;
            }
            if r == fmi::VR_TIME {
                assert_eq!(x, self.m.time, "{what}");
            }
            if Some(r) == self.info.pr
                && let Some(n) = self.m.radial
            {
                assert_eq!(x, n as f64, "{what}");
            }
        }
    }

    fn step(&mut self, rng: &mut Rng, logged: usize) {
        let t = self.m.time;
        let current = if rng.below(6) == 0 {
            rng.number(t - 1e-6, t + 1e-6)
        } else {
            t
        };
        let h = match rng.below(8) {
            // Any size: to the end of the run, or far past it.
            0 if self.m.cheap(&self.info) => {
                let any = rng.number(0.0, 1e-3);
                *rng.pick(&[any, any, 1.0, 1e300, f64::MAX])
            }
            1 => rng.number(-1e-6, 1e-6),
            _ => (1e-7 + 2e-6 * rng.unit()).min(self.info.h),
        };
        // With a stiff or light material the time step is tiny and a
        // microsecond takes long: short steps there (and when the lattice
        // is not known), and no longer than the measured budget of the
        // coarse run.
        let cap = if self.m.st.is_some()
            && self.m.radial.is_some_and(|n| n <= self.info.radial + 1)
            && !self.m.tuned
        {
            self.info.h
        } else {
            1e-8
        };
        let h = if self.m.cheap(&self.info) || h.is_nan() || h <= cap {
            h
        } else {
            cap
        };
        let null_out = !F::FMI2 && rng.below(16) == 0;
        let (code, last, terminate) = unsafe { self.fmu.do_step(current, h, null_out) };
        let target = current + h;
        let off = (current - t).abs() > 1e-6 * (t.abs() + h.abs());
        let past = self
            .m
            .stop
            .is_some_and(|s| target > s + 1e-6 * (s.abs() + h.abs()));
        let valid = h > 0.0
            && h.is_finite()
            && current.is_finite()
            && target.is_finite()
            && target > current;
        let fail =
            self.m.st.is_some() && (!self.m.is(&[St::Step]) || !valid || off || past || null_out);
        self.check(
            format!("step {current:?} {h:?} null={null_out}"),
            code,
            fail,
            false,
            logged,
        );
        // The scene's end completes the step: never Discard, never a
        // request to stop (issue 65).
        assert!(
            code != DISCARD && !terminate,
            "a step answered {code} (terminate {terminate}): {:?}",
            self.calls
        );
        if code == OK {
            assert!(
                last.is_finite(),
                "lastSuccessfulTime {last} with {code}: {:?}",
                self.calls
            );
            if self.m.st.is_some() {
                assert!(
                    current <= last && last <= target,
                    "lastSuccessfulTime {last} outside [{current}, {target}]"
                );
            }
            self.m.time = last;
        }
    }

    /// Get, set or free an FMU state in a random slot.
    fn states(&mut self, rng: &mut Rng, logged: usize) {
        let k = rng.below(self.slots.len());
        let null_slot = rng.below(12) == 0;
        match rng.below(3) {
            0 => {
                let p: *mut *mut c_void = if null_slot {
                    null_mut()
                } else {
                    &mut self.slots[k].0
                };
                let code = unsafe { self.fmu.get_state(p) };
                self.check(
                    format!("get state {k} null={null_slot}"),
                    code,
                    null_slot,
                    !null_slot,
                    logged,
                );
                if code == OK {
                    self.slots[k].1 = self.m;
                }
            }
            1 if !self.slots[k].0.is_null() || null_slot => {
                let s = if null_slot {
                    null_mut()
                } else {
                    self.slots[k].0
                };
                let code = unsafe { self.fmu.set_state(s) };
                self.check(
                    format!("set state {k}"),
                    code,
                    null_slot,
                    !null_slot,
                    logged,
                );
                if code == OK {
                    self.m = self.slots[k].1;
                }
            }
            _ => {
                let code = unsafe { self.fmu.free_state(&mut self.slots[k].0) };
                self.check(format!("free state {k}"), code, false, true, logged);
                assert!(self.slots[k].0.is_null(), "FreeFMUState left the pointer");
            }
        }
    }

    fn serialize(&mut self, rng: &mut Rng, logged: usize) {
        let k = rng.below(self.slots.len());
        let (s, model) = self.slots[k];
        if s.is_null() {
            return;
        }
        let mut size = 0;
        if rng.below(16) == 0 {
            let code = unsafe { self.fmu.size(null_mut(), &mut size) };
            return self.check("size of NULL".into(), code, true, false, logged);
        }
        let null_size = rng.below(12) == 0;
        let code = unsafe {
            self.fmu
                .size(s, if null_size { null_mut() } else { &mut size })
        };
        self.check(format!("size {k}"), code, null_size, !null_size, logged);
        if code != OK {
            return;
        }
        let wrong = match rng.below(8) {
            0 => size.saturating_sub(1 + rng.below(size.max(1))),
            1 => size + 1 + rng.below(64),
            _ => size,
        };
        let null_out = rng.below(12) == 0;
        let mut data = vec![0; wrong];
        let code = unsafe {
            self.fmu.serialize(
                s,
                if null_out {
                    null_mut()
                } else {
                    data.as_mut_ptr()
                },
                wrong,
            )
        };
        let bad = wrong != size || (null_out && size > 0);
        self.check(
            format!("serialize {k} {wrong} of {size}"),
            code,
            bad,
            !bad,
            logged,
        );
        if code == OK {
            self.bytes.push(Bytes { data, model });
        }
    }

    fn deserialize(&mut self, rng: &mut Rng, sims: &[serde_json::Value], logged: usize) {
        let Some(b) = self.bytes.get(rng.below(self.bytes.len())).cloned() else {
            return;
        };
        let mut data = b.data;
        let mut model = b.model;
        let edit = if rng.below(2) == 0 {
            corrupt(rng, &mut data, sims, self.info.fmu)
        } else {
            String::new()
        };
        if !edit.is_empty() {
            model.st = None;
        }
        let k = rng.below(self.slots.len());
        let null_slot = rng.below(12) == 0;
        let p: *mut *mut c_void = if null_slot {
            null_mut()
        } else {
            &mut self.slots[k].0
        };
        let null_data = !data.is_empty() && rng.below(16) == 0;
        let from = if null_data { null() } else { data.as_ptr() };
        let code = unsafe { self.fmu.deserialize(from, data.len(), p) };
        let must = edit.is_empty() && !null_slot && !null_data;
        self.check(
            format!("deserialize into {k}: {edit:?} null={null_slot},{null_data}"),
            code,
            null_slot || null_data,
            must,
            logged,
        );
        if code == OK {
            self.slots[k].1 = model;
        }
    }

    /// Restores a saved FMU state, if the host holds one; else Reset.
    fn restore(&mut self, rng: &mut Rng, logged: usize) {
        let live: Vec<usize> = (0..self.slots.len())
            .filter(|&k| !self.slots[k].0.is_null())
            .collect();
        let Some(&k) = live.get(rng.below(live.len().max(1))) else {
            return self.reset(rng, logged);
        };
        let code = unsafe { self.fmu.set_state(self.slots[k].0) };
        self.check(format!("restore state {k}"), code, false, true, logged);
        self.m = self.slots[k].1;
    }

    fn reset(&mut self, rng: &mut Rng, logged: usize) {
        let code = unsafe { self.fmu.reset() };
        self.check("reset".into(), code, false, true, logged);
        self.m = Model::new(&self.info);
        self.cheapen(rng);
    }

    /// Sets `particles_radial` to a cheap value (at the default, 20, a
    /// thin rod takes minutes per microsecond).
    fn cheapen(&mut self, rng: &mut Rng) {
        let Some(pr) = self.info.pr else {
            return;
        };
        let logged = self.errors_logged();
        let n = self.info.radial + rng.below(2) as i32;
        let code = unsafe { self.fmu.set(VarType::Int32, &pr, 1, Some(&[n as f64]), 1) };
        self.check(
            format!("set particles_radial {n}"),
            code,
            false,
            true,
            logged,
        );
        self.m.radial = Some(n);
    }
}

/// One FMU case of standard `F` from `seed`, on the FMU `pool.fmus[k]`.
fn run<F: Fmu>(seed: u64, pool: &Pool, k: usize) {
    let mut rng = Rng(seed | 1);
    let panics = PANICS.load(Ordering::SeqCst);
    let log = Box::new(Mutex::new(Log::default()));
    let (fmu, expect, no_token) = F::new(&mut rng, &*log, pool.fmus[k].fmu);
    if let Some(e) = expect {
        assert_eq!(!fmu.ptr().is_null(), e, "instantiation accepted: {}", !e);
    }
    // Without a token, an instance is of the first FMU of the registry.
    let info = if no_token {
        pool.fmus[0].clone()
    } else {
        pool.fmus[k].clone()
    };
    let reference = info.reference.clone().expect("made by Pool::new");
    let mut case = Case {
        fmu,
        m: Model::new(&info),
        slots: [(null_mut(), Model::new(&info)); 3],
        bytes: vec![reference],
        log: &*log,
        calls: Vec::new(),
        info,
    };
    let sims = &pool.sims;
    if case.fmu.ptr().is_null() {
        // Every function refuses a NULL instance.
        case.m.st = None;
        for _ in 0..rng.below(4) {
            let before = case.calls.len();
            case.random_call(&mut rng, sims);
            if let Some(c) = case.calls.get(before) {
                assert!(c.ends_with("-> 3"), "NULL instance: {:?}", case.calls);
            }
        }
        return;
    }
    case.cheapen(&mut rng);
    for _ in 0..rng.below(CALLS + 1) {
        case.random_call(&mut rng, sims);
    }
    for k in 0..case.slots.len() {
        // SAFETY: a live instance; the slot NULL or a live state, freed once.
        let code = unsafe { case.fmu.free_state(&mut case.slots[k].0) };
        assert_eq!(code, OK, "free state at the end: {:?}", case.calls);
    }
    // SAFETY: a live instance, not used afterwards.
    unsafe { case.fmu.free() };
    let alarming = std::mem::take(&mut log.lock().unwrap().alarming);
    assert!(alarming.is_empty(), "{alarming:?} after {:?}", case.calls);
    assert_eq!(
        PANICS.load(Ordering::SeqCst),
        panics,
        "a panic inside the FMU: {:?}",
        case.calls
    );
}

/// Shared inputs of the FMU cases.
pub struct Pool {
    /// Saved simulations of every built-in scene to forge FMU states from.
    pub sims: Vec<serde_json::Value>,
    /// Every FMU of the registry ([`fmi::Fmu::all`]), in its order.
    pub fmus: Vec<Info>,
}

impl Pool {
    /// The FMUs of the registry, each with what tests/fuzz.rs measured of
    /// the built-in scene of its kind, and its reference state.
    pub fn new(entries: &[Entry]) -> Pool {
        let fmus = fmi::Fmu::all()
            .into_iter()
            .map(|fmu| {
                let kind = fmu.kind();
                // The built-in scene of the FMU's row (its material choice
                // costs about the same).
                let e = entries
                    .iter()
                    .find(|e| e.name == kind.name())
                    .expect("every FMU's row is a built-in scene");
                let default_radial = kind
                    .param_specs()
                    .iter()
                    .find(|p| p.name == "particles_radial")
                    .map_or(0, |p| p.default as i32);
                let vars = fmu.variables();
                let pr = vars
                    .iter()
                    .find(|v| v.name == "particles_radial")
                    .map(|v| v.vr);
                let steps_per_second = 1.0 / e.step_secs;
                let mut info = Info {
                    fmu,
                    vars,
                    pr,
                    radial: if pr.is_some() { e.radial as i32 } else { 0 },
                    default_radial,
                    to_end: e.to_end,
                    h: (e.dt * 0.1 * steps_per_second).clamp(e.dt, 2.1e-6),
                    reference: None,
                };
                info.reference = Some(reference_state(&info));
                info
            })
            .collect();
        Pool {
            sims: entries.iter().map(|e| e.state.clone()).collect(),
            fmus,
        }
    }
}

/// A random FMI 3.0 (`fmi2 == false`) or FMI 2.0 call order on a random
/// FMU of the registry; returns its name.
pub fn fuzz(rng: &mut Rng, pool: &Arc<Pool>, fmi2: bool) -> String {
    let seed = rng.next();
    let k = rng.below(pool.fmus.len());
    let id = pool.fmus[k].fmu.identity().model_identifier;
    let standard = if fmi2 { Fmi2::NAME } else { Fmi3::NAME };
    count(
        id,
        if fmi2 {
            "FMI 2.0 call order"
        } else {
            "FMI 3.0 call order"
        },
    );
    let what = format!("{standard} call order on {id}, seed {seed}");
    let pool = Arc::clone(pool);
    TRACE.lock().unwrap().clear();
    bounded(&what, move || {
        if fmi2 {
            run::<Fmi2>(seed, &pool, k)
        } else {
            run::<Fmi3>(seed, &pool, k)
        }
    });
    what
}
