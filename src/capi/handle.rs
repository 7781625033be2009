//! The `mi_sim` handle: construction, destruction, the last error, the
//! parameters, and running.
//!
//! Life of a handle: it holds a scene, whose parameters may be read and set
//! until the run starts. The [`Simulation`] is built lazily from the scene the
//! first time it is needed (a step, an observable, a field...); setting a
//! parameter before the first step discards that initial state, which is built
//! again from the new scene when next needed. Once a step was taken, setting a
//! parameter is `MI_WRONG_ORDER`. Cross-parameter constraints are therefore
//! checked when the simulation is built (`MI_INCONSISTENT` from the first call
//! that needs it), while names and ranges are checked by the setter.

use super::error::{Fail, mi_result};
use super::panic::{Handle, get_into, guard, with_sim};
use super::ptr::{need_out, put, text};
use crate::error::Error;
use crate::scene::{Scene, SceneKind};
use crate::sim::Simulation;
use std::ffi::{CString, c_char, c_void};

/// Progress callback: called after every step of `mi_sim_run` and
/// `mi_sim_advance_to` with the caller's `user_data`, the simulated time, the
/// latest time the run may reach (`end_time`) and the steps taken. Return
/// `true` to go on, `false` to cancel: the run then stops with
/// `MI_CANCELLED`, for good. The callback must not call into the same handle
/// and must not unwind (no C++ exceptions, no longjmp).
#[allow(non_camel_case_types)]
pub type mi_progress_fn = Option<
    unsafe extern "C" fn(user_data: *mut c_void, time: f64, end_time: f64, steps: u64) -> bool,
>;

/// NUL-terminated copies of the names the `*_info` functions hand out, owned
/// by the handle.
#[derive(Debug, Default)]
pub(crate) struct Meta {
    pub params: Vec<[CString; 3]>,
    pub observables: Vec<[CString; 3]>,
    pub fields: Option<Vec<FieldMeta>>,
}

/// Names of one particle field.
#[derive(Debug)]
pub(crate) struct FieldMeta {
    pub name: CString,
    pub unit: CString,
    pub components: Vec<CString>,
    pub component_ptrs: Vec<*const c_char>,
}

fn c(s: &str) -> CString {
    CString::new(s).expect("library names hold no NUL")
}

impl Meta {
    fn of(kind: SceneKind) -> Meta {
        Meta {
            params: kind
                .param_specs()
                .iter()
                .map(|p| [c(p.name), c(p.unit), c(p.description)])
                .collect(),
            observables: kind
                .observable_specs()
                .iter()
                .map(|o| [c(o.name), c(o.unit), c(o.description)])
                .collect(),
            fields: None,
        }
    }
}

/// An opaque simulation handle: one scene and its run. Create it with
/// `mi_sim_new`, `mi_sim_new_toml` or `mi_sim_new_file`, release it with
/// `mi_sim_free`. A handle must not be used by two threads at once;
/// separate handles share nothing and may run on separate threads at once.
#[allow(non_camel_case_types)]
pub struct mi_sim {
    scene: Scene,
    sim: Option<Simulation>,
    /// A stop that the core does not record (a cancel inside
    /// `mi_sim_advance_to`).
    stopped: Option<Error>,
    progress: mi_progress_fn,
    progress_data: *mut c_void,
    last_error: String,
    pub(crate) poisoned: bool,
    pub(crate) meta: Meta,
}

impl Handle for mi_sim {
    fn poisoned(&self) -> bool {
        self.poisoned
    }
    fn poison(&mut self) {
        self.poisoned = true;
    }
    fn set_error(&mut self, message: String) {
        self.last_error = message;
    }
}

impl mi_sim {
    fn new(scene: Scene) -> Self {
        mi_sim {
            meta: Meta::of(scene.kind()),
            scene,
            sim: None,
            stopped: None,
            progress: None,
            progress_data: std::ptr::null_mut(),
            last_error: String::new(),
            poisoned: false,
        }
    }

    /// A new scene in place of the handle's (its run and names go; the
    /// progress callback stays).
    fn replace_scene(&mut self, scene: Scene) {
        *self = mi_sim {
            progress: self.progress,
            progress_data: self.progress_data,
            ..mi_sim::new(scene)
        };
    }

    /// The kind of scene (fixed for the handle's life, except by
    /// `mi_sim_load_toml`).
    pub(crate) fn kind(&self) -> SceneKind {
        self.scene.kind()
    }

    /// The simulation, built from the scene when first needed.
    pub(crate) fn sim(&mut self) -> Result<&mut Simulation, Fail> {
        let sim = match self.sim.take() {
            Some(s) => s,
            None => Simulation::new(self.scene.clone())?,
        };
        Ok(self.sim.insert(sim))
    }

    /// Replaces the run by a restored one (same scene kind).
    pub(crate) fn restore(&mut self, sim: Simulation) {
        self.scene = sim.scene().clone();
        self.sim = Some(sim);
        self.stopped = None;
    }

    /// Whether the run has started (a step was taken, or it was stopped:
    /// also by a stop in its first step, before the step count left 0).
    fn started(&self) -> bool {
        self.stopped.is_some()
            || self
                .sim
                .as_ref()
                .is_some_and(|s| s.steps() > 0 || s.error().is_some())
    }

    /// Whether the run has ended: end condition, solver stop or cancel.
    pub(crate) fn finished(&mut self) -> Result<bool, Fail> {
        let stopped = self.stopped.is_some();
        Ok(stopped || self.sim()?.finished())
    }

    fn check_not_started(&self, what: &str) -> Result<(), Fail> {
        if self.started() {
            Err(Fail::new(
                mi_result::MI_WRONG_ORDER,
                format!("{what}: the run has started; parameters are fixed after the first step"),
            ))
        } else {
            Ok(())
        }
    }

    /// The stop that ended the run, if any.
    fn check_stop(&self) -> Result<(), Fail> {
        if let Some(e) = &self.stopped {
            return Err(e.clone().into());
        }
        if let Some(e) = self.sim.as_ref().and_then(|s| s.error()) {
            return Err(e.clone().into());
        }
        Ok(())
    }

    /// Steps toward `t` (or the end condition), calling the progress callback.
    fn advance(&mut self, t: Option<f64>) -> Result<(), Fail> {
        self.check_stop()?;
        let (cb, data) = (self.progress, self.progress_data);
        let sim = self.sim()?;
        let Some(cb) = cb else {
            return match t {
                Some(t) => sim.advance_to(t),
                None => sim.run(),
            }
            .map_err(Fail::from);
        };
        let end_time = sim.end_time();
        let call = |sim: &Simulation| {
            // SAFETY: the caller registered `cb` with `data` through
            // `mi_sim_set_progress` and guarantees it may be called with it.
            unsafe { cb(data, sim.time(), end_time, sim.steps()) }
        };
        match t {
            None => sim.run_with(|p| {
                // SAFETY: as above.
                unsafe { cb(data, p.time, p.end_time, p.steps) }
            })?,
            Some(t) => {
                // The loop of `Simulation::advance_to`, with the callback.
                while sim.time() < t && !sim.finished() {
                    sim.step()?;
                    if !call(sim) {
                        let e = Error::Cancelled { time: sim.time() };
                        self.stopped = Some(e.clone());
                        return Err(e.into());
                    }
                }
            }
        }
        Ok(())
    }
}

fn create(out: *mut *mut mi_sim, make: impl FnOnce() -> Result<Scene, Fail>) -> mi_result {
    guard(|| {
        let scene = match need_out(out, "out").and_then(|()| make()) {
            Ok(s) => s,
            Err(f) => return f.code,
        };
        let handle = Box::into_raw(Box::new(mi_sim::new(scene)));
        // SAFETY: `out` is non-NULL (checked above) and, by the entry point's
        // contract, valid for a write of one pointer.
        unsafe { out.write(handle) };
        mi_result::MI_OK
    })
}

/// Creates a handle for a built-in scene with default parameters. The
/// built-in scenes (the kinds of scene of the registry, each followed by its
/// named variants):
///
/// @SCENES@
///
/// On `MI_OK`, `*out` receives a new handle that the caller must release with
/// `mi_sim_free`; on failure `*out` is left unchanged (`MI_NULL_POINTER`,
/// `MI_INVALID_UTF8`, `MI_UNKNOWN_SCENE`).
///
/// # Safety
/// `scene` must be NULL or a NUL-terminated string; `out` must be NULL or
/// valid for a write of one pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_new(scene: *const c_char, out: *mut *mut mi_sim) -> mi_result {
    create(out, || {
        // SAFETY: forwarded contract on `scene`.
        let name = unsafe { text(scene, "scene") }?;
        Ok(Scene::builtin(name)?)
    })
}

/// Creates a handle from a TOML scene text (`scene = "taylor"`, an optional
/// `[parameters]` table and an optional `[reference]` table, as the files in
/// `scenes/`); `scene =` names a kind of scene, the first level of the list
/// at `mi_sim_new`. Codes as `mi_sim_new`, plus `MI_SCENE_FILE`,
/// `MI_PARSE_VALUE`, `MI_UNKNOWN_PARAMETER`, `MI_OUT_OF_RANGE` and
/// `MI_INCONSISTENT`. For the message of a failure, create a handle and use
/// `mi_sim_load_toml`.
///
/// # Safety
/// As `mi_sim_new`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_new_toml(toml: *const c_char, out: *mut *mut mi_sim) -> mi_result {
    create(out, || {
        // SAFETY: forwarded contract on `toml`.
        let t = unsafe { text(toml, "toml") }?;
        Ok(Scene::from_toml_str(t)?)
    })
}

/// Creates a handle from a TOML scene file. Codes as `mi_sim_new_toml`, plus
/// `MI_IO` when the file cannot be read.
///
/// # Safety
/// As `mi_sim_new`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_new_file(path: *const c_char, out: *mut *mut mi_sim) -> mi_result {
    create(out, || {
        // SAFETY: forwarded contract on `path`.
        let p = unsafe { text(path, "path") }?;
        Ok(Scene::from_file(p)?)
    })
}

/// Releases a handle and everything it owns. NULL is allowed and does
/// nothing. The handle, and every string pointer obtained from it, must not be
/// used afterwards.
///
/// # Safety
/// `sim` must be NULL or a handle from `mi_sim_new*` not yet freed.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_free(sim: *mut mi_sim) {
    if sim.is_null() {
        return;
    }
    guard(|| {
        // SAFETY: `sim` came from `Box::into_raw` in `create` and, by the
        // contract, is freed once.
        drop(unsafe { Box::from_raw(sim) });
        mi_result::MI_OK
    });
}

/// Copies the message of the last failed call on this handle (an empty
/// string if none failed) into `buf`, by the buffer convention (`len` and
/// `*needed` count bytes, the terminating NUL included). A successful call
/// does not clear the message. Works on a handle poisoned by a panic.
///
/// # Safety
/// `sim` must be NULL or a live handle; `buf` must be NULL or valid for `len`
/// bytes; `needed` must be NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_last_error(
    sim: *const mi_sim,
    buf: *mut c_char,
    len: usize,
    needed: *mut usize,
) -> mi_result {
    guard(|| {
        // SAFETY: by the contract, a non-NULL `sim` is a live handle.
        let Some(s) = (unsafe { sim.as_ref() }) else {
            return mi_result::MI_NULL_POINTER;
        };
        // SAFETY: forwarded contract on `buf`, `len`, `needed`.
        match unsafe { super::ptr::copy_str(&s.last_error, buf, len, needed, "buf") } {
            Ok(()) => mi_result::MI_OK,
            Err(f) => f.code,
        }
    })
}

/// Replaces the handle's scene by a TOML scene text (before the run starts;
/// afterwards `MI_WRONG_ORDER`). The scene kind may change; string pointers
/// from the `*_info` functions are then invalid. On failure the handle keeps
/// its scene and `mi_sim_last_error` explains the problem.
///
/// # Safety
/// `sim` must be NULL or a live handle; `toml` NULL or a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_load_toml(sim: *mut mi_sim, toml: *const c_char) -> mi_result {
    with_sim(sim, |s| {
        // SAFETY: forwarded contract on `toml`.
        let t = unsafe { text(toml, "toml") }?;
        s.check_not_started("mi_sim_load_toml")?;
        let scene = Scene::from_toml_str(t)?;
        s.replace_scene(scene);
        Ok(())
    })
}

/// Chooses the material of the handle's scene by the names of a scene
/// file's `[material]` table, before the run starts: `key` is `"strength"`
/// (`"johnson_cook"`, `"bilinear"`), `"eos"` (`"linear"`,
/// `"mie_gruneisen"`) or `"preset"` (a material preset, for example
/// `"copper_wilkins_bilinear"`; `meshless-impact materials` lists them).
/// The parameter list then holds only the parameters of the chosen models
/// (`mi_sim_param_count`, `mi_sim_param_info`); a parameter both models
/// share keeps its value, a new one starts at its default, and a preset
/// sets every parameter of its models. Call it before setting the
/// material's parameters. String pointers from `mi_sim_param_info` are
/// invalid afterwards. Errors: `MI_UNKNOWN_MATERIAL` (an unknown key or
/// name, listing the known ones, or a scene with no material to choose),
/// `MI_WRONG_ORDER` after the first step; on failure nothing changes.
///
/// # Safety
/// `sim` must be NULL or a live handle; `key` and `value` NULL or
/// NUL-terminated strings.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_set_material(
    sim: *mut mi_sim,
    key: *const c_char,
    value: *const c_char,
) -> mi_result {
    with_sim(sim, |s| {
        // SAFETY: forwarded contract on `key` and `value`.
        let (k, v) = unsafe { (text(key, "key")?, text(value, "value")?) };
        s.check_not_started("mi_sim_set_material")?;
        let mut scene = s.scene.clone();
        match k {
            "strength" => scene.choose_material(Some(v), None, None),
            "eos" => scene.choose_material(None, Some(v), None),
            "preset" => scene.choose_material(None, None, Some(v)),
            _ => Err(Error::UnknownModel {
                key: "material key".into(),
                name: k.into(),
                allowed: "strength, eos, preset".into(),
            }),
        }?;
        s.replace_scene(scene);
        Ok(())
    })
}

/// Chooses the numerical scheme by name (`large_strain`, `paper`, ...; the
/// scene's `scheme` parameter, whose description lists its levels), before
/// the run starts. The scheme sets its knobs (`smoothing_order`,
/// `shifting`, ...) except those already set by hand with
/// `mi_sim_set_param`, which keep their values; a knob set afterwards
/// overrides it. `mi_sim_set_param(sim, "scheme", k)` chooses the k-th level
/// the same way. Errors: `MI_UNKNOWN_MATERIAL` (an unknown name, listing the
/// known ones), `MI_UNKNOWN_PARAMETER` (a scene with no scheme),
/// `MI_WRONG_ORDER` after the first step; on failure nothing changes.
///
/// # Safety
/// `sim` must be NULL or a live handle; `name` NULL or a NUL-terminated
/// string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_set_scheme(sim: *mut mi_sim, name: *const c_char) -> mi_result {
    with_sim(sim, |s| {
        // SAFETY: forwarded contract on `name`.
        let n = unsafe { text(name, "name") }?;
        s.check_not_started("mi_sim_set_scheme")?;
        s.scene.set_str("scheme", n)?;
        s.sim = None;
        Ok(())
    })
}

/// Sets a parameter by name (SI units), before the run starts. Errors:
/// `MI_UNKNOWN_PARAMETER`, `MI_OUT_OF_RANGE` (outside the allowed range, NaN,
/// infinite, or not a whole number where one is required), `MI_WRONG_ORDER`
/// after the first step. Cross-parameter constraints are checked when the
/// simulation is built (`MI_INCONSISTENT`).
///
/// # Safety
/// `sim` must be NULL or a live handle; `name` NULL or a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_set_param(
    sim: *mut mi_sim,
    name: *const c_char,
    value: f64,
) -> mi_result {
    with_sim(sim, |s| {
        // SAFETY: forwarded contract on `name`.
        let n = unsafe { text(name, "name") }?;
        s.check_not_started("mi_sim_set_param")?;
        s.scene.set(n, value)?;
        s.sim = None;
        Ok(())
    })
}

/// Reads a parameter by name into `*value`.
///
/// # Safety
/// `sim` must be NULL or a live handle; `name` NULL or a NUL-terminated
/// string; `value` NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_get_param(
    sim: *mut mi_sim,
    name: *const c_char,
    value: *mut f64,
) -> mi_result {
    with_sim(sim, |s| {
        // SAFETY: forwarded contract on `name`.
        let n = unsafe { text(name, "name") }?;
        need_out(value, "value")?;
        let v = s.scene.get(n)?;
        // SAFETY: forwarded contract on `value`.
        unsafe { put(value, v, "value") }
    })
}

/// One parameter of a scene: name, unit, meaning, default and allowed range.
/// The strings belong to the handle and stay valid until `mi_sim_free` (or
/// `mi_sim_load_toml`).
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct mi_param_info {
    /// Name, as used by `mi_sim_set_param`.
    pub name: *const c_char,
    /// SI unit (`"1"` for dimensionless).
    pub unit: *const c_char,
    /// One-line meaning.
    pub description: *const c_char,
    /// Default value.
    pub default_value: f64,
    /// Lower bound of the allowed range.
    pub min: f64,
    /// Upper bound of the allowed range.
    pub max: f64,
    /// Whether `min` itself is allowed.
    pub min_inclusive: bool,
    /// Whether `max` itself is allowed.
    pub max_inclusive: bool,
    /// Whether the value must be a whole number.
    pub integer: bool,
}

/// Writes the number of parameters of the handle's scene to `*count`.
///
/// # Safety
/// `sim` must be NULL or a live handle; `count` NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_param_count(sim: *mut mi_sim, count: *mut usize) -> mi_result {
    // SAFETY: forwarded contract on `count`.
    unsafe { get_into(sim, count, "count", |s| Ok(s.kind().param_specs().len())) }
}

/// Describes the parameter at `index` (0 .. count-1; else `MI_OUT_OF_RANGE`).
///
/// # Safety
/// `sim` must be NULL or a live handle; `info` NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_param_info(
    sim: *mut mi_sim,
    index: usize,
    info: *mut mi_param_info,
) -> mi_result {
    // SAFETY: forwarded contract on `info`.
    unsafe {
        get_into(sim, info, "info", |s| {
            let specs = s.kind().param_specs();
            let (Some(p), Some(names)) = (specs.get(index), s.meta.params.get(index)) else {
                return Err(index_error("parameter", index, specs.len()));
            };
            Ok(mi_param_info {
                name: names[0].as_ptr(),
                unit: names[1].as_ptr(),
                description: names[2].as_ptr(),
                default_value: p.default,
                min: p.range.min,
                max: p.range.max,
                min_inclusive: p.range.min_inclusive,
                max_inclusive: p.range.max_inclusive,
                integer: p.range.integer,
            })
        })
    }
}

pub(crate) fn index_error(what: &str, index: usize, count: usize) -> Fail {
    Fail::new(
        mi_result::MI_OUT_OF_RANGE,
        format!("{what} index {index} is out of range: the scene has {count}"),
    )
}

/// Registers (or, with `callback = NULL`, removes) the progress callback used
/// by `mi_sim_run` and `mi_sim_advance_to`. `user_data` is passed back
/// unchanged; the library never dereferences it.
///
/// # Safety
/// `sim` must be NULL or a live handle; `callback` must be safe to call with
/// `user_data` for as long as it stays registered.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_set_progress(
    sim: *mut mi_sim,
    callback: mi_progress_fn,
    user_data: *mut c_void,
) -> mi_result {
    with_sim(sim, |s| {
        s.progress = callback;
        s.progress_data = user_data;
        Ok(())
    })
}

/// Takes one time step. `MI_WRONG_ORDER` when the run has already ended; a
/// solver stop returns its code (`MI_SINGULAR_MOMENT_MATRIX` ...), and every
/// later call that steps returns the same code.
///
/// # Safety
/// `sim` must be NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_step(sim: *mut mi_sim) -> mi_result {
    with_sim(sim, |s| {
        s.check_stop()?;
        if s.finished()? {
            return Err(Fail::new(
                mi_result::MI_WRONG_ORDER,
                "mi_sim_step: the run has ended (the end condition holds)",
            ));
        }
        Ok(s.sim()?.step()?)
    })
}

/// Steps until the simulated time reaches `time` or the end condition holds
/// (whichever comes first). The last step is not shortened, so the time may
/// pass `time` by less than one step, and a run divided into several calls
/// gives bit-identical results to one call. A `time` already passed does
/// nothing. `MI_OUT_OF_RANGE` for a NaN or infinite `time`; solver stops and
/// `MI_CANCELLED` as `mi_sim_run`.
///
/// # Safety
/// `sim` must be NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_advance_to(sim: *mut mi_sim, time: f64) -> mi_result {
    with_sim(sim, |s| {
        if !time.is_finite() {
            return Err(Fail::new(
                mi_result::MI_OUT_OF_RANGE,
                format!("mi_sim_advance_to: time = {time} must be finite"),
            ));
        }
        s.advance(Some(time))
    })
}

/// Runs to the end condition (the rod at rest, or the scene's `end_time`).
/// Returns `MI_OK`, or the code of the stop that ended the run (a solver
/// stop, or `MI_CANCELLED` from the progress callback):
///
/// @STOPS@
///
/// After a stop the observables, history and fields still read the state at
/// the stop.
///
/// # Safety
/// `sim` must be NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_run(sim: *mut mi_sim) -> mi_result {
    with_sim(sim, |s| s.advance(None))
}

/// Triggers a panic inside the library, for testing bindings: the boundary
/// catches it, the call returns `MI_PANIC`, and the handle is poisoned (every
/// later call but `mi_sim_last_error` and `mi_sim_free` returns `MI_PANIC`).
/// A message is printed on stderr by the Rust runtime.
///
/// # Safety
/// `sim` must be NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_debug_panic(sim: *mut mi_sim) -> mi_result {
    with_sim(sim, |_| panic!("mi_sim_debug_panic was called"))
}
