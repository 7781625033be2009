//! A seeded fuzzer over the boundaries: parameters, TOML scene texts, saved
//! states, call orders through the C ABI, and call orders through the FMI
//! 3.0 and FMI 2.0 functions of the FMUs ([`fmu`]). Each case runs under a
//! time limit; the run passes only with no panic, no hang, no NaN observable
//! on success, no error or status outside the documented tables, and (FMU)
//! Error wherever the standard requires it.
//!
//! The test command runs it for `MI_FUZZ_SECONDS` (default 60) from seed
//! `MI_FUZZ_SEED` (default 1); `scripts/fuzz.sh` runs it longer.

use meshless_impact::internals::capi::*;
use meshless_impact::{Scene, Simulation};
use std::ffi::CString;
use std::ptr::null_mut;
use std::sync::Arc;
use std::sync::mpsc;
use std::time::{Duration, Instant};

// The FMU call orders, beside this file (tests/fmu/ holds the pytest suite).
#[path = "fuzz/fmu.rs"]
mod fmu;

/// Longest a single case may take before it counts as a hang.
const CASE_LIMIT: Duration = Duration::from_secs(30);

/// Steps a fuzzed run takes at most (bounded work per case).
const STEPS: usize = 4;

/// Error names of the library (`Error::name`), the documented table.
const NAMES: [&str; 17] = [
    "OutOfRange",
    "UnknownParameter",
    "UnknownScene",
    "ParseValue",
    "Inconsistent",
    "SceneFile",
    "SingularMomentMatrix",
    "NonFinite",
    "ThroughBoundary",
    "TimeStepCollapse",
    "EnergyDrift",
    "SpacingCollapse",
    "CompressionLimit",
    "MemoryBudget",
    "Cancelled",
    "InvalidState",
    "Io",
];

/// Result codes of the C ABI (`mi_result`), the documented table.
const CODES: [i32; 24] = [
    0, 1, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 16, 20, 21, 22, 23, 24, 25, 26, 27, 30,
];

/// xorshift64*: a small, seeded, reproducible generator.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn pick<'a, T>(&mut self, v: &'a [T]) -> &'a T {
        &v[self.below(v.len())]
    }
    /// A number a hostile caller might pass: range ends, signs, subnormals,
    /// huge values, NaN and infinities, or anything in between.
    fn number(&mut self, lo: f64, hi: f64) -> f64 {
        match self.below(10) {
            0 => *self.pick(&[f64::NAN, f64::INFINITY, f64::NEG_INFINITY]),
            1 => *self.pick(&[0.0, -0.0, 5e-324, -5e-324, 1e-300, 1e300, -1.0, f64::MAX]),
            2 => lo,
            3 => hi,
            4 => lo * (1.0 - 1e-12) - 1e-300,
            5 => hi * (1.0 + 1e-12) + 1e-300,
            6 => f64::from_bits(self.next()),
            _ => lo + (hi - lo) * self.unit(),
        }
    }
}

/// Runs `f` on its own thread under [`CASE_LIMIT`]; panics on a hang or a
/// panic inside, naming the case.
fn bounded<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let out = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
        let _ = tx.send(out);
    });
    match rx.recv_timeout(CASE_LIMIT) {
        Ok(Ok(v)) => v,
        Ok(Err(_)) => panic!("panic in case: {what}"),
        Err(_) => panic!("hang (over {CASE_LIMIT:?}) in case: {what}"),
    }
}

/// Builds and steps a scene; on success every observable must be finite,
/// on failure the error must be one of the documented names.
fn exercise(what: &str, scene: meshless_impact::Result<Scene>) {
    let what = what.to_string();
    let w = what.clone();
    bounded(&what, move || {
        let named = |e: meshless_impact::Error| {
            assert!(NAMES.contains(&e.name()), "{w}: undocumented error {e:?}");
            assert!(!e.to_string().is_empty(), "{w}: empty message");
        };
        let scene = match scene {
            Ok(s) => s,
            Err(e) => return named(e),
        };
        let mut sim = match Simulation::new(scene) {
            Ok(s) => s,
            Err(e) => return named(e),
        };
        for _ in 0..STEPS {
            if sim.finished() {
                break;
            }
            if let Err(e) = sim.step() {
                return named(e);
            }
            let o = sim.observables();
            assert!(o.iter().all(|v| v.is_finite()), "{w}: NaN on success {o:?}");
        }
    });
}

/// Coarse scenes, so that a case stays cheap unless the fuzzer raises the
/// resolution itself.
fn coarse(name: &str) -> Scene {
    let mut s = Scene::builtin(name).unwrap();
    let n = if name == "noh" { 100.0 } else { 4.0 };
    s.set("particles_radial", n).unwrap();
    s
}

fn fuzz_params(rng: &mut Rng) -> String {
    let name = *rng.pick(&["taylor", "noh", "table1-4"]);
    let mut scene = coarse(name);
    let specs = scene.param_specs();
    let mut sets = Vec::new();
    let mut result = Ok(());
    for _ in 0..1 + rng.below(3) {
        let spec = rng.pick(specs);
        let mut v = rng.number(spec.range.min, spec.range.max);
        if spec.name == "particles_radial" && rng.below(4) != 0 {
            // Keep most cases cheap: the largest lattices take seconds.
            v = v.min(if name == "noh" { 400.0 } else { 8.0 });
        }
        sets.push((spec.name, v));
        if let Err(e) = scene.set(spec.name, v) {
            result = Err(e);
            break;
        }
    }
    let what = format!("params {name} {sets:?}");
    exercise(&what, result.map(|_| scene));
    what
}

fn fuzz_toml(rng: &mut Rng) -> String {
    let mut text: Vec<u8> = coarse(rng.pick(&["taylor", "noh"]).to_owned())
        .to_toml()
        .into_bytes();
    let noise: &[&[u8]] = &[
        b"nan",
        b"inf",
        b"-1",
        b"1e999",
        b"\"x\"",
        b"[",
        b"]",
        b"=",
        b"\n",
        b"#",
        b"0",
        b"5e-324",
        b"particles_radial = 1e9\n",
        b"scene = \"noh\"\n",
        b"\xff",
    ];
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(text.len() + 1);
        match rng.below(3) {
            0 if at < text.len() => {
                let end = (at + 1 + rng.below(8)).min(text.len());
                text.drain(at..end);
            }
            _ => {
                let piece = rng.pick(noise);
                text.splice(at..at, piece.iter().copied());
            }
        }
    }
    let text = String::from_utf8_lossy(&text).into_owned();
    let what = format!("toml {text:?}");
    exercise(&what, Scene::from_toml_str(&text));
    what
}

/// Saved states of short coarse runs, taken once.
fn states() -> Vec<serde_json::Value> {
    ["taylor", "noh"]
        .iter()
        .map(|name| {
            let mut sim = Simulation::new(coarse(name)).unwrap();
            for _ in 0..3 {
                sim.step().unwrap();
            }
            serde_json::from_slice(&sim.serialize_state()).unwrap()
        })
        .collect()
}

/// A random leaf of a JSON value (by a random walk), for editing.
fn leaf<'a>(rng: &mut Rng, v: &'a mut serde_json::Value) -> &'a mut serde_json::Value {
    let len = match v {
        serde_json::Value::Array(a) => a.len(),
        serde_json::Value::Object(o) => o.len(),
        _ => 0,
    };
    if len == 0 || rng.below(8) == 0 {
        return v;
    }
    let k = rng.below(len);
    match v {
        serde_json::Value::Array(a) => leaf(rng, &mut a[k]),
        serde_json::Value::Object(o) => {
            let key = o.keys().nth(k).unwrap().clone();
            leaf(rng, o.get_mut(&key).unwrap())
        }
        _ => unreachable!(),
    }
}

/// Replaces a random leaf of `v` by a hostile value (a number, a count, -1,
/// a cut array, a boolean); returns the edit for the case's name.
fn edit_leaf(rng: &mut Rng, v: &mut serde_json::Value) -> String {
    let target = leaf(rng, v);
    let new = match rng.below(5) {
        0 => serde_json::json!(rng.number(-1e6, 1e6)),
        1 => serde_json::json!(rng.below(1_000_000)),
        2 => serde_json::json!(-1),
        3 => match target {
            serde_json::Value::Array(a) if !a.is_empty() => {
                let mut a = a.clone();
                a.truncate(rng.below(a.len()));
                serde_json::Value::Array(a)
            }
            _ => serde_json::json!(0.0),
        },
        _ => serde_json::json!(true),
    };
    let edit = format!("{target} -> {new}");
    *target = new;
    edit
}

fn fuzz_state(rng: &mut Rng, saved: &[serde_json::Value]) -> String {
    let mut state = rng.pick(saved).clone();
    let edits: Vec<String> = (0..1 + rng.below(3))
        .map(|_| edit_leaf(rng, &mut state))
        .collect();
    let bytes = serde_json::to_vec(&state).unwrap();
    let what = format!("state edits {edits:?}");
    let w = what.clone();
    bounded(&what, move || {
        let mut sim = match Simulation::deserialize_state(&bytes) {
            Ok(s) => s,
            Err(e) => {
                assert_eq!(e.name(), "InvalidState", "{w}: {e}");
                return;
            }
        };
        // An accepted state steps like any run: finite or a named stop.
        for _ in 0..STEPS {
            if sim.finished() {
                break;
            }
            if let Err(e) = sim.step() {
                assert!(NAMES.contains(&e.name()), "{w}: {e:?}");
                return;
            }
            let o = sim.observables();
            assert!(o.iter().all(|v| v.is_finite()), "{w}: NaN on success");
        }
    });
    what
}

fn fuzz_capi(rng: &mut Rng) -> String {
    let seed = rng.next();
    let what = format!("C ABI call order, seed {seed}");
    bounded(&what.clone(), move || {
        let mut rng = Rng(seed | 1);
        let mut calls = Vec::new();
        let names = [
            "taylor",
            "noh",
            "table1-4",
            "table1-01",
            "table1-+1",
            "TAYLOR",
            "",
            "taylor\u{1}",
        ];
        let params = [
            "impact_speed",
            "density",
            "particles_radial",
            "end_time",
            "bogus",
            "",
        ];
        let scene = CString::new(*rng.pick(&names)).unwrap();
        let mut sim = null_mut();
        // SAFETY: valid NUL-terminated string and out pointer.
        let code = unsafe { mi_sim_new(scene.as_ptr(), &mut sim) };
        calls.push(("new", code as i32));
        if !sim.is_null() {
            let p = CString::new("particles_radial").unwrap();
            // SAFETY: live handle, valid name.
            unsafe { mi_sim_set_param(sim, p.as_ptr(), 4.0) };
        }
        let mut saved: Vec<u8> = Vec::new();
        for _ in 0..rng.below(12) {
            let name = CString::new(*rng.pick(&params)).unwrap();
            let mut v = 0.0;
            let mut n = 0usize;
            // SAFETY: `sim` is NULL or live; pointers are valid for the call.
            let code = unsafe {
                match rng.below(7) {
                    0 => (
                        "set",
                        mi_sim_set_param(sim, name.as_ptr(), rng.number(-10.0, 1e3)),
                    ),
                    1 => ("get", mi_sim_get_param(sim, name.as_ptr(), &mut v)),
                    2 => ("step", mi_sim_step(sim)),
                    3 => ("advance", mi_sim_advance_to(sim, rng.number(0.0, 2e-6))),
                    4 => {
                        let obs = CString::new("energy_error").unwrap();
                        let c = mi_sim_observable(sim, obs.as_ptr(), &mut v);
                        if c == mi_result::MI_OK {
                            assert!(v.is_finite(), "NaN observable with MI_OK");
                        }
                        ("observable", c)
                    }
                    5 => {
                        let c = mi_sim_state_save(sim, null_mut(), 0, &mut n);
                        if c == mi_result::MI_BUFFER_TOO_SMALL {
                            saved = vec![0; n];
                            let c = mi_sim_state_save(sim, saved.as_mut_ptr(), n, &mut n);
                            ("save", c)
                        } else {
                            ("save-size", c)
                        }
                    }
                    _ => {
                        let mut bytes = saved.clone();
                        if !bytes.is_empty() && rng.below(2) == 0 {
                            let at = rng.below(bytes.len());
                            bytes[at] = rng.next() as u8;
                        }
                        ("load", mi_sim_state_load(sim, bytes.as_ptr(), bytes.len()))
                    }
                }
            };
            calls.push((code.0, code.1 as i32));
            assert!(CODES.contains(&(code.1 as i32)), "{calls:?}");
            assert_ne!(code.1 as i32, 30, "a caught panic: {calls:?}");
        }
        // SAFETY: NULL or a live handle, freed once.
        unsafe { mi_sim_free(sim) };
    });
    what
}

#[test]
fn fuzz_the_boundaries() {
    let seconds: f64 = std::env::var("MI_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(60.0);
    let seed: u64 = std::env::var("MI_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let mut rng = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
    fmu::count_panics();
    let saved = states();
    let pool = Arc::new(fmu::Pool {
        sims: saved.clone(),
        reference: fmu::reference_state(),
    });
    let start = Instant::now();
    let mut counts = [0usize; 6];
    while start.elapsed().as_secs_f64() < seconds {
        let k = rng.below(6);
        match k {
            0 => fuzz_params(&mut rng),
            1 => fuzz_toml(&mut rng),
            2 => fuzz_state(&mut rng, &saved),
            3 => fuzz_capi(&mut rng),
            4 => fmu::fuzz(&mut rng, &pool, false),
            _ => fmu::fuzz(&mut rng, &pool, true),
        };
        counts[k] += 1;
    }
    println!(
        "fuzz: seed {seed}, {:.0} s: {} parameter sets, {} TOML texts, {} saved states, \
         {} C ABI call orders, {} FMI 3.0 call orders, {} FMI 2.0 call orders; \
         0 crashes, 0 hangs, 0 NaN on success, 0 undocumented errors or statuses, \
         0 forbidden FMU calls answered OK",
        start.elapsed().as_secs_f64(),
        counts[0],
        counts[1],
        counts[2],
        counts[3],
        counts[4],
        counts[5]
    );
    assert!(counts.iter().all(|&c| c > 0), "{counts:?}");
}
