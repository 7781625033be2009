//! The C ABI, exercised from Rust through the same `extern "C"` functions C
//! calls: the committed header matches cbindgen's output, results are
//! bit-identical to the Rust API, every result code is produced, buffers
//! follow the documented convention, and handles run on separate threads.

use meshless_impact::internals::capi::*;
use meshless_impact::{Scene, Simulation};
use std::ffi::{CStr, CString, c_void};
use std::ptr::{null, null_mut};

/// The committed header is exactly what cbindgen generates from `src/capi/`
/// with `cbindgen.toml` now, with the lists that come from the library's
/// tables filled in (`expand_header`: the built-in scenes at `mi_sim_new`,
/// the stop codes at `mi_sim_run`), as `cargo xtask header` writes it.
#[test]
fn header_matches_cbindgen() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(root.join("cbindgen.toml")).unwrap();
    let bindings = cbindgen::Builder::new()
        .with_config(config)
        .with_src(root.join("src/capi/mod.rs"))
        .generate()
        .unwrap();
    let mut generated = Vec::new();
    bindings.write(&mut generated);
    let generated = expand_header(&String::from_utf8(generated).unwrap());
    let committed =
        std::fs::read_to_string(root.join("include/meshless_impact.h")).unwrap_or_default();
    if generated != committed {
        if std::env::var_os("MI_BLESS_HEADER").is_some() {
            std::fs::write(root.join("include/meshless_impact.h"), &generated).unwrap();
        }
        panic!(
            "include/meshless_impact.h differs from cbindgen's output: run `cargo xtask header` \
             (or this test with MI_BLESS_HEADER=1) and commit the header"
        );
    }
    // The version macros are in the header and agree with the crate.
    let v: Vec<&str> = meshless_impact::VERSION.split('.').collect();
    for (name, value) in ["MAJOR", "MINOR", "PATCH"].iter().zip(v) {
        assert!(
            committed.contains(&format!("#define MI_VERSION_{name} {value}\n")),
            "MI_VERSION_{name}"
        );
    }
    assert!(committed.contains("#define MI_VERSION "));
    assert!(committed.contains("extern \"C\" {"));
    // The generated lists are there, whole: every built-in scene and every
    // code of the stop block, and no placeholder is left.
    assert!(!committed.contains("@SCENES@") && !committed.contains("@STOPS@"));
    for name in meshless_impact::builtin_names() {
        assert!(
            committed.contains(&format!(" * - `\"{name}\"`"))
                || committed.contains(&format!(" *   - `\"{name}\"`")),
            "scene {name}"
        );
    }
    for code in 20..30 {
        // SAFETY: mi_result_name returns a static NUL-terminated string.
        let name = unsafe { CStr::from_ptr(mi_result_name(code)) }
            .to_str()
            .unwrap();
        if name != "MI_UNKNOWN_RESULT" {
            assert!(
                committed.contains(&format!(" * - `{name}` ({code}):")),
                "{name}"
            );
        }
    }
}

#[test]
fn version_is_the_crate_version() {
    // SAFETY: mi_version returns a static NUL-terminated string.
    let v = unsafe { CStr::from_ptr(mi_version()) }.to_str().unwrap();
    assert_eq!(v, meshless_impact::VERSION);
    assert_eq!(v, MI_VERSION);
}

/// The numeric values are part of the ABI: this table must never change
/// (new codes may only be added).
#[test]
fn result_codes_are_fixed() {
    use mi_result::*;
    let fixed = [
        (MI_OK, 0, "MI_OK"),
        (MI_NULL_POINTER, 1, "MI_NULL_POINTER"),
        (MI_INVALID_UTF8, 2, "MI_INVALID_UTF8"),
        (MI_UNKNOWN_SCENE, 3, "MI_UNKNOWN_SCENE"),
        (MI_UNKNOWN_PARAMETER, 4, "MI_UNKNOWN_PARAMETER"),
        (MI_UNKNOWN_OBSERVABLE, 5, "MI_UNKNOWN_OBSERVABLE"),
        (MI_UNKNOWN_FIELD, 6, "MI_UNKNOWN_FIELD"),
        (MI_OUT_OF_RANGE, 7, "MI_OUT_OF_RANGE"),
        (MI_INCONSISTENT, 8, "MI_INCONSISTENT"),
        (MI_PARSE_VALUE, 9, "MI_PARSE_VALUE"),
        (MI_SCENE_FILE, 10, "MI_SCENE_FILE"),
        (MI_IO, 11, "MI_IO"),
        (MI_INVALID_STATE, 12, "MI_INVALID_STATE"),
        (MI_BUFFER_TOO_SMALL, 13, "MI_BUFFER_TOO_SMALL"),
        (MI_WRONG_ORDER, 14, "MI_WRONG_ORDER"),
        (MI_UNKNOWN_MATERIAL, 15, "MI_UNKNOWN_MATERIAL"),
        (MI_MEMORY_BUDGET, 16, "MI_MEMORY_BUDGET"),
        (MI_SINGULAR_MOMENT_MATRIX, 20, "MI_SINGULAR_MOMENT_MATRIX"),
        (MI_NON_FINITE, 21, "MI_NON_FINITE"),
        (MI_THROUGH_BOUNDARY, 22, "MI_THROUGH_BOUNDARY"),
        (MI_TIME_STEP_COLLAPSE, 23, "MI_TIME_STEP_COLLAPSE"),
        (MI_ENERGY_DRIFT, 24, "MI_ENERGY_DRIFT"),
        (MI_CANCELLED, 25, "MI_CANCELLED"),
        (MI_SPACING_COLLAPSE, 26, "MI_SPACING_COLLAPSE"),
        (MI_COMPRESSION_LIMIT, 27, "MI_COMPRESSION_LIMIT"),
        (MI_PANIC, 30, "MI_PANIC"),
        (MI_BAD_CHECKPOINT, 17, "MI_BAD_CHECKPOINT"),
    ];
    for (code, value, name) in fixed {
        assert_eq!(code as i32, value, "{name}");
        // SAFETY: static NUL-terminated strings.
        let n = unsafe { CStr::from_ptr(mi_result_name(value)) };
        assert_eq!(n.to_str().unwrap(), name);
        let d = unsafe { CStr::from_ptr(mi_result_description(value)) };
        assert!(!d.to_bytes().is_empty());
    }
    let n = unsafe { CStr::from_ptr(mi_result_name(18)) };
    assert_eq!(n.to_str().unwrap(), "MI_UNKNOWN_RESULT");
}

/// An owned handle for the tests.
struct Sim(*mut mi_sim);
// SAFETY: a handle is used by one thread at a time; the tests move it, never share it.
unsafe impl Send for Sim {}

impl Drop for Sim {
    fn drop(&mut self) {
        // SAFETY: the handle came from mi_sim_new* and is freed once.
        unsafe { mi_sim_free(self.0) }
    }
}

fn c(s: &str) -> CString {
    CString::new(s).unwrap()
}

fn new_sim(scene: &str) -> Sim {
    let mut p = null_mut();
    // SAFETY: valid string and out pointer.
    assert_eq!(
        unsafe { mi_sim_new(c(scene).as_ptr(), &mut p) },
        mi_result::MI_OK
    );
    Sim(p)
}

impl Sim {
    fn set(&self, name: &str, v: f64) -> mi_result {
        // SAFETY: live handle, valid string.
        unsafe { mi_sim_set_param(self.0, c(name).as_ptr(), v) }
    }
    fn material(&self, key: &str, value: &str) -> mi_result {
        // SAFETY: live handle, valid strings.
        unsafe { mi_sim_set_material(self.0, c(key).as_ptr(), c(value).as_ptr()) }
    }
    fn error(&self) -> String {
        let mut n = 0usize;
        // SAFETY: live handle; size query, then a buffer of that size.
        unsafe {
            assert_eq!(
                mi_sim_last_error(self.0, null_mut(), 0, &mut n),
                mi_result::MI_OK
            );
            let mut buf = vec![0 as std::ffi::c_char; n];
            assert_eq!(
                mi_sim_last_error(self.0, buf.as_mut_ptr(), n, null_mut()),
                mi_result::MI_OK
            );
            CStr::from_ptr(buf.as_ptr()).to_str().unwrap().to_string()
        }
    }
    fn run(&self) -> mi_result {
        // SAFETY: live handle.
        unsafe { mi_sim_run(self.0) }
    }
    /// Copies an array by the buffer convention (size query first).
    fn array(
        &self,
        f: unsafe extern "C" fn(*mut mi_sim, *mut f64, usize, *mut usize) -> mi_result,
    ) -> Vec<f64> {
        let mut n = 0usize;
        // SAFETY: live handle; buffers of the queried size.
        unsafe {
            assert_eq!(f(self.0, null_mut(), 0, &mut n), mi_result::MI_OK);
            let mut v = vec![f64::NAN; n];
            let mut m = 0usize;
            assert_eq!(f(self.0, v.as_mut_ptr(), n, &mut m), mi_result::MI_OK);
            assert_eq!(m, n);
            v
        }
    }
    fn named(
        &self,
        f: unsafe extern "C" fn(
            *mut mi_sim,
            *const std::ffi::c_char,
            *mut f64,
            usize,
            *mut usize,
        ) -> mi_result,
        name: &str,
    ) -> Vec<f64> {
        let name = c(name);
        let mut n = 0usize;
        // SAFETY: live handle; buffers of the queried size.
        unsafe {
            assert_eq!(
                f(self.0, name.as_ptr(), null_mut(), 0, &mut n),
                mi_result::MI_OK
            );
            let mut v = vec![f64::NAN; n];
            assert_eq!(
                f(self.0, name.as_ptr(), v.as_mut_ptr(), n, null_mut()),
                mi_result::MI_OK
            );
            v
        }
    }
    fn observable(&self, name: &str) -> f64 {
        let mut v = f64::NAN;
        // SAFETY: live handle, valid string and out pointer.
        assert_eq!(
            unsafe { mi_sim_observable(self.0, c(name).as_ptr(), &mut v) },
            mi_result::MI_OK
        );
        v
    }
}

fn small_taylor() -> Scene {
    let mut scene = Scene::builtin("taylor").unwrap();
    scene.set("particles_radial", 5.0).unwrap();
    scene
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// A run through the C ABI gives the Rust API's numbers bit for bit: final
/// observables, histories and every particle field.
#[test]
fn c_abi_equals_rust_api_bit_for_bit() {
    let mut rust = Simulation::new(small_taylor()).unwrap();
    rust.run().unwrap();

    let s = new_sim("taylor");
    assert_eq!(s.set("particles_radial", 5.0), mi_result::MI_OK);
    assert_eq!(s.run(), mi_result::MI_OK);

    assert_eq!(
        bits(&s.array(mi_sim_observables)),
        bits(&rust.observables())
    );
    for spec in rust.observable_specs() {
        let v = rust.observable(spec.name).unwrap();
        assert_eq!(
            s.observable(spec.name).to_bits(),
            v.to_bits(),
            "{}",
            spec.name
        );
        let h = s.named(mi_sim_history, spec.name);
        assert_eq!(bits(&h), bits(&rust.history().column(spec.name).unwrap()));
    }
    assert_eq!(
        bits(&s.array(mi_sim_history_times)),
        bits(&rust.history().times)
    );
    let snap = rust.snapshot();
    let pos: Vec<f64> = snap
        .positions
        .iter()
        .flat_map(|p| &p[..2])
        .copied()
        .collect();
    assert_eq!(bits(&s.named(mi_sim_field, "position")), bits(&pos));
    for f in &snap.fields {
        assert_eq!(
            bits(&s.named(mi_sim_field, f.name)),
            bits(&f.data),
            "{}",
            f.name
        );
    }
    let (mut t, mut steps, mut n) = (0.0, 0u64, 0usize);
    let mut fin = false;
    // SAFETY: live handle, valid out pointers.
    unsafe {
        assert_eq!(mi_sim_time(s.0, &mut t), mi_result::MI_OK);
        assert_eq!(mi_sim_steps(s.0, &mut steps), mi_result::MI_OK);
        assert_eq!(mi_sim_particle_count(s.0, &mut n), mi_result::MI_OK);
        assert_eq!(mi_sim_finished(s.0, &mut fin), mi_result::MI_OK);
    }
    assert_eq!(t.to_bits(), rust.time().to_bits());
    assert_eq!(steps, rust.steps());
    assert_eq!(n, rust.particles());
    assert!(fin);
    assert_eq!(s.observable("at_rest"), 1.0);
}

/// Advancing in pieces with a progress callback gives the same run; a
/// callback that returns false cancels it for good.
#[test]
fn progress_callback_and_cancel() {
    unsafe extern "C" fn count(user: *mut c_void, time: f64, end: f64, steps: u64) -> bool {
        // SAFETY: user is the &mut u64 registered below.
        let n = unsafe { &mut *(user as *mut u64) };
        *n += 1;
        assert!(time > 0.0 && end == 400e-6 && steps == *n);
        true
    }
    unsafe extern "C" fn stop_at_10(_: *mut c_void, _: f64, _: f64, steps: u64) -> bool {
        steps < 10
    }
    let mut rust = Simulation::new(small_taylor()).unwrap();
    rust.run().unwrap();

    let s = new_sim("taylor");
    s.set("particles_radial", 5.0);
    let mut calls = 0u64;
    // SAFETY: live handle; `calls` outlives the runs below.
    unsafe {
        let ud = &mut calls as *mut u64 as *mut c_void;
        assert_eq!(mi_sim_set_progress(s.0, Some(count), ud), mi_result::MI_OK);
        assert_eq!(mi_sim_advance_to(s.0, 5e-6), mi_result::MI_OK);
        assert_eq!(mi_sim_advance_to(s.0, f64::NAN), mi_result::MI_OUT_OF_RANGE);
        assert_eq!(s.run(), mi_result::MI_OK);
    }
    assert_eq!(calls, rust.steps());
    assert_eq!(
        bits(&s.array(mi_sim_observables)),
        bits(&rust.observables())
    );
    // Stepping a finished run is a wrong-order call.
    assert_eq!(unsafe { mi_sim_step(s.0) }, mi_result::MI_WRONG_ORDER);

    for advance in [false, true] {
        let s = new_sim("taylor");
        s.set("particles_radial", 5.0);
        // SAFETY: live handle; the callback ignores user data.
        unsafe {
            mi_sim_set_progress(s.0, Some(stop_at_10), null_mut());
            let r = if advance {
                mi_sim_advance_to(s.0, 1e-3)
            } else {
                s.run()
            };
            assert_eq!(r, mi_result::MI_CANCELLED);
            assert!(s.error().contains("cancelled"), "{}", s.error());
            let mut steps = 0;
            mi_sim_steps(s.0, &mut steps);
            assert_eq!(steps, 10);
            assert_eq!(s.run(), mi_result::MI_CANCELLED);
            assert_eq!(mi_sim_step(s.0), mi_result::MI_CANCELLED);
            let mut fin = false;
            mi_sim_finished(s.0, &mut fin);
            assert!(fin);
        }
    }
}

/// Parameters: set and get by name, the listing matches the table, setting
/// before the first step rebuilds the initial state, after it is refused.
#[test]
fn parameters_and_wrong_order() {
    let s = new_sim("taylor");
    let specs = Scene::builtin("taylor").unwrap().param_specs();
    let mut n = 0usize;
    // SAFETY: live handle, valid pointers; info strings live as long as the handle.
    unsafe {
        assert_eq!(mi_sim_param_count(s.0, &mut n), mi_result::MI_OK);
        assert_eq!(n, specs.len());
        for (k, spec) in specs.iter().enumerate() {
            let mut info = std::mem::zeroed::<mi_param_info>();
            assert_eq!(mi_sim_param_info(s.0, k, &mut info), mi_result::MI_OK);
            assert_eq!(CStr::from_ptr(info.name).to_str().unwrap(), spec.name);
            assert_eq!(CStr::from_ptr(info.unit).to_str().unwrap(), spec.unit);
            assert_eq!(info.default_value, spec.default);
            assert_eq!(info.min, spec.range.min);
            assert_eq!(info.max, spec.range.max);
            assert_eq!(info.integer, spec.range.integer);
            let mut v = 0.0;
            assert_eq!(mi_sim_get_param(s.0, info.name, &mut v), mi_result::MI_OK);
            assert_eq!(v, spec.default);
        }
        let mut info = std::mem::zeroed::<mi_param_info>();
        assert_eq!(
            mi_sim_param_info(s.0, n, &mut info),
            mi_result::MI_OUT_OF_RANGE
        );
        assert!(info.name.is_null(), "no output on failure");
        let mut no = 0usize;
        mi_sim_observable_count(s.0, &mut no);
        assert_eq!(no, 13);
        let mut oi = std::mem::zeroed::<mi_observable_info>();
        assert_eq!(mi_sim_observable_info(s.0, 12, &mut oi), mi_result::MI_OK);
        assert_eq!(CStr::from_ptr(oi.name).to_str().unwrap(), "at_rest");
        assert!(oi.is_bool);
    }
    // Reading the initial state, then setting, rebuilds from the new scene.
    let mut n0 = 0usize;
    unsafe { mi_sim_particle_count(s.0, &mut n0) };
    assert_eq!(n0, 20 * 191);
    assert_eq!(s.set("particles_radial", 5.0), mi_result::MI_OK);
    assert_eq!(s.set("impact_speed", 200.0), mi_result::MI_OK);
    let mut v = 0.0;
    unsafe { mi_sim_get_param(s.0, c("impact_speed").as_ptr(), &mut v) };
    assert_eq!(v, 200.0);
    assert_eq!(s.observable("tail_velocity"), 200.0);
    unsafe { mi_sim_particle_count(s.0, &mut n0) };
    assert_eq!(n0, Simulation::new(small_taylor()).unwrap().particles());
    assert_eq!(unsafe { mi_sim_step(s.0) }, mi_result::MI_OK);
    assert_eq!(s.set("impact_speed", 100.0), mi_result::MI_WRONG_ORDER);
    assert!(s.error().contains("the run has started"), "{}", s.error());
    unsafe { mi_sim_get_param(s.0, c("impact_speed").as_ptr(), &mut v) };
    assert_eq!(v, 200.0);
    let toml = c("scene = \"noh\"\n");
    assert_eq!(
        unsafe { mi_sim_load_toml(s.0, toml.as_ptr()) },
        mi_result::MI_WRONG_ORDER
    );
}

/// The buffer convention: NULL/0 asks for the length; too small is refused
/// with the length written and the buffer untouched; NULL with a length is a
/// NULL-pointer error.
#[test]
fn buffer_convention() {
    let s = new_sim("taylor");
    s.set("particles_radial", 5.0);
    let name = c("stress");
    let mut n = 0usize;
    // SAFETY: live handle; buffers are at least as long as passed.
    unsafe {
        assert_eq!(
            mi_sim_field(s.0, name.as_ptr(), null_mut(), 0, &mut n),
            mi_result::MI_OK
        );
        let particles = Simulation::new(small_taylor()).unwrap().particles();
        assert_eq!(n, 4 * particles);
        let mut buf = vec![-1.0; n - 1];
        let mut m = 0usize;
        let r = mi_sim_field(s.0, name.as_ptr(), buf.as_mut_ptr(), n - 1, &mut m);
        assert_eq!(r, mi_result::MI_BUFFER_TOO_SMALL);
        assert_eq!(m, n);
        assert!(buf.iter().all(|&x| x == -1.0), "untouched on failure");
        assert!(s.error().contains("needed"), "{}", s.error());
        assert_eq!(
            mi_sim_field(s.0, name.as_ptr(), null_mut(), 3, &mut m),
            mi_result::MI_NULL_POINTER
        );
        let mut small = [0 as std::ffi::c_char; 4];
        let r = mi_sim_last_error(s.0, small.as_mut_ptr(), 4, &mut m);
        assert_eq!(r, mi_result::MI_BUFFER_TOO_SMALL);
        assert_eq!(m, s.error().len() + 1);
        let mut fi = std::mem::zeroed::<mi_field_info>();
        let mut nf = 0usize;
        assert_eq!(mi_sim_field_count(s.0, &mut nf), mi_result::MI_OK);
        assert_eq!(nf, 8);
        assert_eq!(mi_sim_field_info(s.0, 4, &mut fi), mi_result::MI_OK);
        assert_eq!(CStr::from_ptr(fi.name).to_str().unwrap(), "stress");
        assert_eq!(fi.components, 4);
        let comps: Vec<&str> = (0..4)
            .map(|k| CStr::from_ptr(*fi.component_names.add(k)).to_str().unwrap())
            .collect();
        assert_eq!(comps, ["RR", "ZZ", "TT", "RZ"]);
        assert_eq!(
            mi_sim_field_info(s.0, nf, &mut fi),
            mi_result::MI_OUT_OF_RANGE
        );
    }
}

fn run_code(scene: &str, set: &[(&str, f64)]) -> (mi_result, String) {
    let s = new_sim(scene);
    for (k, v) in set {
        assert_eq!(s.set(k, *v), mi_result::MI_OK, "{k}");
    }
    let r = s.run();
    (r, s.error())
}

/// A forged state (a parameter out of its range, the solver's own copy
/// edited, a particle removed) is refused with `MI_INVALID_STATE` and a
/// message saying what is wrong, and the handle keeps its run.
#[test]
fn forged_states_are_refused_and_the_handle_keeps_its_run() {
    let base = coarse_state_at_1us();
    // SAFETY: live handles; buffers of the right length.
    unsafe {
        type Forgery = (fn(&mut serde_json::Value), &'static str);
        let forgeries: [Forgery; 3] = [
            (
                |j| j["scene"]["params"]["Taylor"]["density"] = (-5.0).into(),
                "density",
            ),
            (
                |j| j["solver"]["Taylor"]["p"]["density"] = 8000.0.into(),
                "parameters",
            ),
            (
                |j| {
                    j["solver"]["Taylor"]["pos"].as_array_mut().unwrap().pop();
                },
                "positions",
            ),
        ];
        let t = new_sim("taylor");
        t.set("particles_radial", 5.0);
        let before = mi_sim_steps_of(&t);
        for (edit, says) in forgeries {
            let mut j = base.clone();
            edit(&mut j);
            let forged = serde_json::to_vec(&j).unwrap();
            assert_eq!(
                mi_sim_state_load(t.0, forged.as_ptr(), forged.len()),
                mi_result::MI_INVALID_STATE
            );
            let msg = t.error();
            assert!(msg.contains(says), "{msg}");
        }
        assert_eq!(mi_sim_steps_of(&t), before);
        assert_eq!(t.run(), mi_result::MI_OK);
        // The code's description covers forged states too (it said "not a
        // saved state of this scene kind").
        let d = CStr::from_ptr(mi_result_description(mi_result::MI_INVALID_STATE as i32));
        assert_eq!(
            d.to_str().unwrap(),
            "not a valid saved state of this scene kind (not a state, another kind, forged or inconsistent)"
        );
    }
}

/// Steps taken by a handle.
fn mi_sim_steps_of(s: &Sim) -> u64 {
    let mut n = 0u64;
    // SAFETY: live handle, valid out pointer.
    assert_eq!(unsafe { mi_sim_steps(s.0, &mut n) }, mi_result::MI_OK);
    n
}

/// The saved state, as JSON, of test 7 at 5 particles across advanced to
/// 1 us through the C ABI.
fn coarse_state_at_1us() -> serde_json::Value {
    let s = new_sim("taylor");
    s.set("particles_radial", 5.0);
    let mut n = 0usize;
    // SAFETY: live handle; a buffer of the queried size.
    unsafe {
        assert_eq!(mi_sim_advance_to(s.0, 1e-6), mi_result::MI_OK);
        mi_sim_state_save(s.0, null_mut(), 0, &mut n);
        let mut bytes = vec![0u8; n];
        assert_eq!(
            mi_sim_state_save(s.0, bytes.as_mut_ptr(), n, null_mut()),
            mi_result::MI_OK
        );
        serde_json::from_slice(&bytes).unwrap()
    }
}

/// A saved state whose `vel[particle][component]` is replaced by `value`,
/// loaded into a fresh handle: the code and message of the load.
fn patched_load_code(particle: usize, component: usize, value: f64) -> (mi_result, String) {
    let mut json = coarse_state_at_1us();
    json["solver"]["Taylor"]["vel"][particle][component] = value.into();
    let bytes = serde_json::to_vec(&json).unwrap();
    let t = new_sim("taylor");
    // SAFETY: live handle; a buffer of the right length.
    let r = unsafe { mi_sim_state_load(t.0, bytes.as_ptr(), bytes.len()) };
    (r, t.error())
}

/// [`patched_load_code`] loaded, then stepped: the solver's own checks
/// stop the step.
fn patched_state_code(particle: usize, component: usize, value: f64) -> (mi_result, String) {
    let mut json = coarse_state_at_1us();
    // SAFETY: live handle; buffers of the right length.
    unsafe {
        json["solver"]["Taylor"]["vel"][particle][component] = value.into();
        let bytes = serde_json::to_vec(&json).unwrap();
        let t = new_sim("taylor");
        assert_eq!(
            mi_sim_state_load(t.0, bytes.as_ptr(), bytes.len()),
            mi_result::MI_OK,
            "{}",
            t.error()
        );
        let r = mi_sim_step(t.0);
        (r, t.error())
    }
}

/// Every result code is produced through the ABI, with a message that names
/// the problem, and none crashes.
#[test]
fn every_error_code_is_produced() {
    use mi_result::*;
    let mut seen = std::collections::BTreeSet::new();
    let mut check = |r: mi_result, want: mi_result, msg: &str, needle: &str| {
        assert_eq!(r, want, "{msg}");
        assert!(msg.contains(needle), "{want:?}: `{msg}` lacks `{needle}`");
        seen.insert(want as i32);
    };
    let mut p = null_mut();
    // SAFETY: every pointer passed is NULL or valid; strings NUL-terminated.
    unsafe {
        check(
            mi_sim_new(c("taylor").as_ptr(), null_mut()),
            MI_NULL_POINTER,
            "",
            "",
        );
        check(mi_sim_new(null(), &mut p), MI_NULL_POINTER, "", "");
        assert!(p.is_null());
        check(
            mi_sim_new(c("tailor").as_ptr(), &mut p),
            MI_UNKNOWN_SCENE,
            "",
            "",
        );
        assert!(p.is_null(), "no output on failure");
        let bad = [0xffu8, 0xfe, 0];
        check(
            mi_sim_new(bad.as_ptr().cast(), &mut p),
            MI_INVALID_UTF8,
            "",
            "",
        );
        check(
            mi_sim_new_toml(c("scene = ").as_ptr(), &mut p),
            MI_SCENE_FILE,
            "",
            "",
        );
        let t = c("scene = \"taylor\"\n[parameters]\nimpact_speed = \"fast\"\n");
        check(mi_sim_new_toml(t.as_ptr(), &mut p), MI_PARSE_VALUE, "", "");
        check(
            mi_sim_new_file(c("/nonexistent/x.toml").as_ptr(), &mut p),
            MI_IO,
            "",
            "",
        );
        assert!(p.is_null());
        check(mi_sim_run(null_mut()), MI_NULL_POINTER, "", "");

        let s = new_sim("taylor");
        check(
            s.set("impact_sped", 1.0),
            MI_UNKNOWN_PARAMETER,
            &s.error(),
            "impact_speed",
        );
        check(
            s.set("impact_speed", -1.0),
            MI_OUT_OF_RANGE,
            &s.error(),
            "[0.01, 2000]",
        );
        check(
            s.set("impact_speed", f64::NAN),
            MI_OUT_OF_RANGE,
            &s.error(),
            "NaN",
        );
        check(
            s.set("particles_radial", 5.5),
            MI_OUT_OF_RANGE,
            &s.error(),
            "integers",
        );
        let mut v = 0.0;
        check(
            mi_sim_observable(s.0, c("rod_lenght").as_ptr(), &mut v),
            MI_UNKNOWN_OBSERVABLE,
            &s.error(),
            "rod_length",
        );
        check(
            mi_sim_field(s.0, c("strain").as_ptr(), null_mut(), 0, null_mut()),
            MI_UNKNOWN_FIELD,
            &s.error(),
            "plastic_strain",
        );
        check(
            mi_sim_get_param(s.0, c("density").as_ptr(), null_mut()),
            MI_NULL_POINTER,
            &s.error(),
            "value",
        );
        check(
            mi_sim_state_load(s.0, b"not a state".as_ptr(), 11),
            MI_INVALID_STATE,
            &s.error(),
            "invalid",
        );
        let not_one = std::env::temp_dir().join(format!("mi-capi-{}.ckpt", std::process::id()));
        std::fs::write(&not_one, b"{\"format\": 2}").unwrap();
        check(
            mi_sim_checkpoint_load(s.0, c(not_one.to_str().unwrap()).as_ptr()),
            MI_BAD_CHECKPOINT,
            &s.error(),
            "is not a checkpoint",
        );
        std::fs::remove_file(&not_one).ok();
        let mut small = [0.0; 2];
        check(
            mi_sim_observables(s.0, small.as_mut_ptr(), 2, null_mut()),
            MI_BUFFER_TOO_SMALL,
            &s.error(),
            "13 needed",
        );
        s.set("room_temperature", 1300.0);
        check(s.run(), MI_INCONSISTENT, &s.error(), "melt_temperature");
        // Wrong order: a finished run cannot step; a started one cannot be reconfigured.
        let w = new_sim("taylor");
        w.set("particles_radial", 5.0);
        mi_sim_step(w.0);
        check(w.set("jc_a", 1e9), MI_WRONG_ORDER, &w.error(), "started");

        let (r, m) = run_code(
            "taylor",
            &[("particles_radial", 5.0), ("smoothing_ratio", 0.6)],
        );
        check(r, MI_SINGULAR_MOMENT_MATRIX, &m, "singular");
        let (r, m) = run_code(
            "taylor",
            &[("particles_radial", 6.0), ("smoothing_coefficient", 0.0)],
        );
        check(r, MI_ENERGY_DRIFT, &m, "energy error");
        // The paper's scheme at 600 m/s (the default brings it to rest).
        let (r, m) = run_code(
            "taylor",
            &[
                ("scheme", 1.0),
                ("particles_radial", 6.0),
                ("impact_speed", 600.0),
            ],
        );
        check(r, MI_SPACING_COLLAPSE, &m, "spacing");
        let noh = [
            ("particles_radial", 50.0),
            ("viscosity_quadratic", 0.0),
            ("viscosity_linear", 0.0),
            ("smoothing_coefficient", 0.0),
        ];
        let (r, m) = run_code("noh", &noh);
        check(r, MI_TIME_STEP_COLLAPSE, &m, "time step collapsed");
        // The material chosen by name: unknown names list the known ones.
        let s = new_sim("taylor");
        check(
            s.material("strength", "plastic"),
            MI_UNKNOWN_MATERIAL,
            &s.error(),
            "johnson_cook, bilinear",
        );
        check(
            s.material("preset", "ofhc_copper"),
            MI_UNKNOWN_MATERIAL,
            &s.error(),
            "ofhc_copper_jc",
        );
        check(
            s.material("model", "bilinear"),
            MI_UNKNOWN_MATERIAL,
            &s.error(),
            "strength, eos, preset",
        );
        let n = new_sim("noh");
        check(
            n.material("eos", "mie_gruneisen"),
            MI_UNKNOWN_MATERIAL,
            &n.error(),
            "no material",
        );
        // Mie-Grueneisen with a soft, steep curve (c0 = 500 m/s, s = 10) hit
        // at 2000 m/s: the face reaches the singular compression 1/(s - 1).
        assert_eq!(s.material("eos", "mie_gruneisen"), MI_OK);
        check(
            s.set("bulk_modulus", 1e11),
            MI_UNKNOWN_PARAMETER,
            &s.error(),
            "eos_c0",
        );
        for (k, v) in [
            ("particles_radial", 5.0),
            ("eos_c0", 500.0),
            ("eos_s", 10.0),
            ("impact_speed", 2000.0),
        ] {
            assert_eq!(s.set(k, v), MI_OK, "{k}");
        }
        check(s.run(), MI_COMPRESSION_LIMIT, &s.error(), "Mie-Gr");
        // 50 km/s toward the anvil: within the bound of a restored state
        // (ten times impact plus wave speed), through the anvil in a step.
        let (r, m) = patched_state_code(6, 1, -5e4);
        check(r, MI_THROUGH_BOUNDARY, &m, "through the anvil");
        // Soft, heavy bodies at 10 km/s: a temperature overflows within
        // 1 us (issue 48's extreme physics).
        let s = new_sim("penetration");
        for (k, v) in [
            ("particles_radial", 3.0),
            ("impact_speed", 1e4),
            ("end_time", 1e-6),
            ("projectile_density", 1e5),
            ("plate_density", 1e5),
            ("projectile_shear_modulus", 1e6),
            ("projectile_bulk_modulus", 1e6),
            ("plate_shear_modulus", 1e6),
            ("projectile_yield_stress", 0.0),
        ] {
            assert_eq!(s.set(k, v), MI_OK, "{k}");
        }
        check(s.run(), MI_NON_FINITE, &s.error(), "non-finite");
        // Such a run has no state to save: its stop is returned.
        let mut n = 0usize;
        check(
            mi_sim_state_save(s.0, null_mut(), 0, &mut n),
            MI_NON_FINITE,
            &s.error(),
            "non-finite",
        );
        // A forged velocity of 1e308 (once MI_NON_FINITE at the next step)
        // is refused on loading.
        let (r, m) = patched_load_code(11, 0, 1e308);
        check(r, MI_INVALID_STATE, &m, "faster than");

        unsafe extern "C" fn no(_: *mut c_void, _: f64, _: f64, _: u64) -> bool {
            false
        }
        let s = new_sim("taylor");
        s.set("particles_radial", 5.0);
        mi_sim_set_progress(s.0, Some(no), null_mut());
        check(s.run(), MI_CANCELLED, &s.error(), "cancelled");

        // 6.3 million nodes: refused before anything is allocated.
        let s = new_sim("taylor3d");
        assert_eq!(s.set("particles_radial", 60.0), MI_OK);
        check(s.run(), MI_MEMORY_BUDGET, &s.error(), "memory budget");

        let s = new_sim("taylor");
        check(
            mi_sim_debug_panic(s.0),
            MI_PANIC,
            &s.error(),
            "mi_sim_debug_panic",
        );
        check(s.run(), MI_PANIC, &s.error(), "unusable");
        check(s.set("jc_a", 1e9), MI_PANIC, &s.error(), "unusable");
    }
    // Every code but MI_OK was produced.
    let all: std::collections::BTreeSet<i32> = (1..=30)
        .filter(|k| {
            // SAFETY: static string.
            let n = unsafe { CStr::from_ptr(mi_result_name(*k)) };
            n.to_bytes() != b"MI_UNKNOWN_RESULT"
        })
        .collect();
    assert_eq!(seen, all);
}

/// Each invalid input of the stability matrix (docs/report) is refused
/// through the C ABI with its named code and a message that names it.
#[test]
fn invalid_inputs_are_refused_with_named_codes() {
    use mi_result::*;
    for (name, value, code, needle) in [
        ("density", -7830.0, MI_OUT_OF_RANGE, "`density` = -7830"),
        (
            "initial_diameter",
            0.0,
            MI_OUT_OF_RANGE,
            "`initial_diameter` = 0",
        ),
        (
            "impact_speed",
            f64::NAN,
            MI_OUT_OF_RANGE,
            "`impact_speed` = NaN",
        ),
        (
            "impact_speed",
            f64::INFINITY,
            MI_OUT_OF_RANGE,
            "`impact_speed` = inf",
        ),
        (
            "particles_radial",
            0.0,
            MI_OUT_OF_RANGE,
            "`particles_radial` = 0",
        ),
        (
            "impact_sped",
            200.0,
            MI_UNKNOWN_PARAMETER,
            "unknown parameter `impact_sped`",
        ),
    ] {
        let s = new_sim("taylor");
        assert_eq!(s.set(name, value), code, "{name} = {value}");
        let msg = s.error();
        assert!(msg.contains(needle), "{name}: `{msg}`");
    }
    // melt_temperature <= room_temperature: each value is in range, the pair
    // is refused when the simulation is built.
    let s = new_sim("taylor");
    assert_eq!(s.set("melt_temperature", 293.0), MI_OK);
    assert_eq!(s.run(), MI_INCONSISTENT);
    assert!(
        s.error().contains("must exceed room_temperature"),
        "{}",
        s.error()
    );
}

/// `mi_sim_new` takes only the documented scene names, spelled exactly:
/// near misses get `MI_UNKNOWN_SCENE` ("unknown scene name") and no handle;
/// every documented name gives the Rust API's scene.
#[test]
fn only_the_documented_scene_names_are_accepted() {
    use mi_result::*;
    for name in [
        "table1-01",
        "table1-+1",
        "table1-0",
        "table1-13",
        "table1- 1",
        "TAYLOR",
    ] {
        let mut p = null_mut();
        // SAFETY: valid string and out pointer.
        let r = unsafe { mi_sim_new(c(name).as_ptr(), &mut p) };
        assert_eq!(r, MI_UNKNOWN_SCENE, "`{name}`");
        assert!(p.is_null(), "`{name}`: no handle on failure");
        // SAFETY: static NUL-terminated strings.
        let (n, d) = unsafe {
            (
                CStr::from_ptr(mi_result_name(r as i32)),
                CStr::from_ptr(mi_result_description(r as i32)),
            )
        };
        assert_eq!(n.to_str().unwrap(), "MI_UNKNOWN_SCENE");
        assert_eq!(d.to_str().unwrap(), "unknown scene name");
    }
    let names = meshless_impact::builtin_names();
    assert_eq!(names.len(), 18);
    assert_eq!(names[3], "penetration");
    assert_eq!(names[4], "plate_impact");
    assert_eq!(names[16], "table1-12");
    assert_eq!(names[17], "taylor3d-aisi310");
    for name in &names {
        let s = new_sim(name);
        let scene = Scene::builtin(name).unwrap();
        for spec in scene.param_specs() {
            let mut v = f64::NAN;
            // SAFETY: live handle, valid string and out pointer.
            let r = unsafe { mi_sim_get_param(s.0, c(spec.name).as_ptr(), &mut v) };
            assert_eq!(r, MI_OK, "{name}: {}", spec.name);
            assert_eq!(v.to_bits(), scene.get(spec.name).unwrap().to_bits());
        }
    }
}

/// A scene from TOML text equals the built-in scene with the same
/// parameters, and `mi_sim_load_toml` reports a parse error with its message.
#[test]
fn toml_scenes() {
    let toml = c("scene = \"taylor\"\n[parameters]\nparticles_radial = 5\nimpact_speed = 200.0\n");
    let mut p = null_mut();
    // SAFETY: valid strings and out pointer.
    assert_eq!(
        unsafe { mi_sim_new_toml(toml.as_ptr(), &mut p) },
        mi_result::MI_OK
    );
    let a = Sim(p);
    let b = new_sim("taylor");
    b.set("particles_radial", 5.0);
    b.set("impact_speed", 200.0);
    // SAFETY: live handles.
    unsafe {
        mi_sim_advance_to(a.0, 3e-6);
        mi_sim_advance_to(b.0, 3e-6);
    }
    assert_eq!(
        bits(&a.array(mi_sim_observables)),
        bits(&b.array(mi_sim_observables))
    );
    let s = new_sim("noh");
    let bad = c("scene = \"taylor\"\n[parameters]\nimpact_speed = 3000\n");
    // SAFETY: live handle, valid string.
    assert_eq!(
        unsafe { mi_sim_load_toml(s.0, bad.as_ptr()) },
        mi_result::MI_OUT_OF_RANGE
    );
    assert!(s.error().contains("impact_speed"), "{}", s.error());
    assert_eq!(
        unsafe { mi_sim_load_toml(s.0, toml.as_ptr()) },
        mi_result::MI_OK
    );
    assert_eq!(s.observable("tail_velocity"), 200.0);
}

/// Handles on separate threads at once give the same numbers as the same
/// runs one after another.
#[test]
fn threads_equal_sequential() {
    let speeds = [150.0, 181.0, 220.0];
    let one = |v: f64| {
        let s = new_sim("taylor");
        assert_eq!(s.set("particles_radial", 5.0), mi_result::MI_OK);
        assert_eq!(s.set("impact_speed", v), mi_result::MI_OK);
        assert_eq!(s.run(), mi_result::MI_OK);
        bits(&s.array(mi_sim_observables))
    };
    let sequential: Vec<_> = speeds.iter().map(|&v| one(v)).collect();
    let threaded: Vec<_> = std::thread::scope(|sc| {
        let hs: Vec<_> = speeds.iter().map(|&v| sc.spawn(move || one(v))).collect();
        hs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert_eq!(sequential, threaded);
    assert_ne!(sequential[0], sequential[1]);
}

/// The material chosen through the C ABI: the parameter list then holds
/// only the chosen models' parameters, as the scene's table lists them
/// (shared ones keep their values, a preset sets its own), a bilinear run
/// saved and loaded into a handle of the same choice goes on with the same
/// bits, and a handle of another choice refuses it, naming both.
#[test]
fn material_choice_lists_only_its_parameters_and_round_trips_a_state() {
    let s = new_sim("taylor");
    assert_eq!(s.set("particles_radial", 5.0), mi_result::MI_OK);
    assert_eq!(s.material("strength", "bilinear"), mi_result::MI_OK);
    let mut want = Scene::builtin("taylor").unwrap();
    want.set("particles_radial", 5.0).unwrap();
    want.choose_material(Some("bilinear"), None, None).unwrap();
    let names = |s: &Sim| -> Vec<String> {
        let mut n = 0usize;
        // SAFETY: live handle, valid pointers; strings live with the handle.
        unsafe {
            assert_eq!(mi_sim_param_count(s.0, &mut n), mi_result::MI_OK);
            (0..n)
                .map(|k| {
                    let mut info = std::mem::zeroed::<mi_param_info>();
                    assert_eq!(mi_sim_param_info(s.0, k, &mut info), mi_result::MI_OK);
                    CStr::from_ptr(info.name).to_str().unwrap().to_string()
                })
                .collect()
        }
    };
    let listed = names(&s);
    let table: Vec<String> = want
        .param_specs()
        .iter()
        .map(|p| p.name.to_string())
        .collect();
    assert_eq!(listed, table);
    assert!(listed.iter().any(|n| n == "hardening_modulus"));
    assert!(!listed.iter().any(|n| n.starts_with("jc_")));
    let get = |s: &Sim, name: &str| {
        let mut v = f64::NAN;
        // SAFETY: live handle, valid pointers.
        let r = unsafe { mi_sim_get_param(s.0, c(name).as_ptr(), &mut v) };
        (r, v)
    };
    assert_eq!(get(&s, "particles_radial"), (mi_result::MI_OK, 5.0));
    assert_eq!(get(&s, "yield_stress"), (mi_result::MI_OK, 792e6));
    assert_eq!(get(&s, "jc_a").0, mi_result::MI_UNKNOWN_PARAMETER);
    // A preset sets every parameter of its models.
    assert_eq!(
        s.material("preset", "copper_wilkins_bilinear"),
        mi_result::MI_OK
    );
    assert_eq!(get(&s, "density"), (mi_result::MI_OK, 8930.0));
    assert_eq!(get(&s, "hardening_modulus"), (mi_result::MI_OK, 100e6));
    // Save at 1 us, go on to 2 us; the saved state loaded into a handle of
    // the same choice goes on to the same bits.
    let state = |s: &Sim| {
        let mut n = 0usize;
        // SAFETY: live handle; a buffer of the queried size.
        unsafe {
            mi_sim_state_save(s.0, null_mut(), 0, &mut n);
            let mut bytes = vec![0u8; n];
            assert_eq!(
                mi_sim_state_save(s.0, bytes.as_mut_ptr(), n, null_mut()),
                mi_result::MI_OK
            );
            bytes
        }
    };
    // SAFETY: live handles; buffers of the right length.
    unsafe {
        assert_eq!(mi_sim_advance_to(s.0, 1e-6), mi_result::MI_OK);
        let saved = state(&s);
        assert_eq!(mi_sim_advance_to(s.0, 2e-6), mi_result::MI_OK);
        let same = new_sim("taylor");
        assert_eq!(same.material("strength", "bilinear"), mi_result::MI_OK);
        assert_eq!(
            mi_sim_state_load(same.0, saved.as_ptr(), saved.len()),
            mi_result::MI_OK,
            "{}",
            same.error()
        );
        assert_eq!(get(&same, "density"), (mi_result::MI_OK, 8930.0));
        assert_eq!(mi_sim_advance_to(same.0, 2e-6), mi_result::MI_OK);
        let bits = |s: &Sim| -> Vec<u64> {
            s.array(mi_sim_observables)
                .iter()
                .map(|v| v.to_bits())
                .collect()
        };
        assert_eq!(bits(&same), bits(&s));
        let other = new_sim("taylor");
        assert_eq!(
            mi_sim_state_load(other.0, saved.as_ptr(), saved.len()),
            mi_result::MI_INVALID_STATE
        );
        let e = other.error();
        assert!(
            e.contains("`taylor (strength = bilinear, eos = linear)`") && e.contains("`taylor`"),
            "{e}"
        );
    }
}

/// Issue 48, failure 7: a run that stopped in its first step (before its
/// step count left 0) took the next `mi_sim_set_param` and the next step
/// with `MI_OK`. Its stop is sticky from the first step: parameters are
/// fixed and every later step returns the same code. The case: a lattice
/// of 4 across with h equal to the spacing, whose moment matrix is
/// singular at the first step.
#[test]
fn a_stop_in_the_first_step_is_sticky() {
    use mi_result::*;
    let s = new_sim("taylor");
    assert_eq!(s.set("particles_radial", 4.0), MI_OK);
    assert_eq!(s.set("smoothing_ratio", 1.0), MI_OK);
    // SAFETY: live handle.
    let step = || unsafe { mi_sim_step(s.0) };
    assert_eq!(step(), MI_SINGULAR_MOMENT_MATRIX, "{}", s.error());
    assert_eq!(mi_sim_steps_of(&s), 0);
    assert_eq!(
        s.set("smoothing_ratio", 1.5),
        MI_WRONG_ORDER,
        "{}",
        s.error()
    );
    assert_eq!(step(), MI_SINGULAR_MOMENT_MATRIX);
    assert_eq!(s.run(), MI_SINGULAR_MOMENT_MATRIX);
}

/// The scheme chosen by name through the C ABI gives the bits of the Rust
/// API with the same choice (and of `mi_sim_set_param("scheme", 1)`), its
/// knobs set by hand override it whatever the order, and an unknown name
/// is refused with the known ones, changing nothing.
#[test]
fn the_scheme_by_name_gives_the_bits_of_the_rust_api() {
    let rust = |scheme: &str, sets: &[(&str, f64)]| -> Vec<u64> {
        let mut s = Scene::builtin("taylor").unwrap();
        s.set_str("scheme", scheme).unwrap();
        for (k, v) in [("particles_radial", 5.0), ("end_time", 10e-6)]
            .iter()
            .chain(sets)
        {
            s.set(k, *v).unwrap();
        }
        let mut sim = Simulation::new(s).unwrap();
        sim.run().unwrap();
        sim.observables().iter().map(|v| v.to_bits()).collect()
    };
    let scheme = |s: &Sim, name: &str| {
        // SAFETY: live handle, valid string.
        unsafe { mi_sim_set_scheme(s.0, c(name).as_ptr()) }
    };
    let capi = |s: &Sim| -> Vec<u64> {
        assert_eq!(s.set("particles_radial", 5.0), mi_result::MI_OK);
        assert_eq!(s.set("end_time", 10e-6), mi_result::MI_OK);
        assert_eq!(s.run(), mi_result::MI_OK, "{}", s.error());
        s.array(mi_sim_observables)
            .iter()
            .map(|v| v.to_bits())
            .collect()
    };
    let paper = rust("paper", &[]);
    assert_ne!(paper, rust("large_strain", &[]));
    let a = new_sim("taylor");
    assert_eq!(scheme(&a, "paper"), mi_result::MI_OK);
    assert_eq!(capi(&a), paper);
    let b = new_sim("taylor");
    assert_eq!(b.set("scheme", 1.0), mi_result::MI_OK);
    assert_eq!(capi(&b), paper);
    // A knob by hand, before and after the scheme.
    let shifted = rust("paper", &[("shifting", 0.05)]);
    let d = new_sim("taylor");
    assert_eq!(d.set("shifting", 0.05), mi_result::MI_OK);
    assert_eq!(scheme(&d, "paper"), mi_result::MI_OK);
    assert_eq!(capi(&d), shifted);
    let e = new_sim("taylor");
    assert_eq!(scheme(&e, "paper"), mi_result::MI_OK);
    assert_eq!(e.set("shifting", 0.05), mi_result::MI_OK);
    assert_eq!(capi(&e), shifted);
    // Unknown name; a scene with no scheme; after the first step.
    let f = new_sim("taylor");
    assert_eq!(scheme(&f, "fast"), mi_result::MI_UNKNOWN_MATERIAL);
    let msg = f.error();
    assert!(
        msg.contains("fast") && msg.contains("large_strain, paper"),
        "{msg}"
    );
    assert_eq!(capi(&f), rust("large_strain", &[]));
    assert_eq!(scheme(&f, "paper"), mi_result::MI_WRONG_ORDER);
    let n = new_sim("noh");
    assert_eq!(scheme(&n, "paper"), mi_result::MI_UNKNOWN_PARAMETER);
}
