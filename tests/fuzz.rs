//! A seeded fuzzer over the boundaries: parameters, TOML scene texts, saved
//! states (edited, and loaded across scenes), call orders through the C ABI,
//! extreme physics within the documented ranges, and call orders through the
//! FMI 3.0 and FMI 2.0 functions of the FMUs ([`fmu`]). Each case runs under
//! a time limit; the run passes only with no panic, no hang, no NaN
//! observable on success, no error or status outside the documented tables,
//! and (FMU) Error wherever the standard requires it.
//!
//! It covers the registry, not a list: every built-in scene
//! ([`meshless_impact::builtin_names`], as `meshless-impact scenes` lists
//! them), every material choice and preset where a scene has a body, every
//! parameter of each scene's table, and every FMU the registry declares
//! (`Fmu::all` of the FMI glue). A new scene or FMU is fuzzed with no edit here: its
//! coarse resolution, its cost and its 3-D-ness are measured at start-up.
//!
//! The test command runs it for `MI_FUZZ_SECONDS` (default 60) from seed
//! `MI_FUZZ_SEED` (default 1); `scripts/fuzz.sh` runs it longer.

use meshless_impact::internals::capi::*;
use meshless_impact::materials::{EosKind, MaterialChoice, PRESETS, StrengthKind};
use meshless_impact::{ParamSpec, Scene, Simulation, builtin_names};
use std::cell::Cell;
use std::collections::BTreeMap;
use std::ffi::{CStr, CString, c_void};
use std::ptr::null_mut;
use std::sync::mpsc;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

// The FMU call orders, beside this file (tests/fmu/ holds the pytest suite).
#[path = "fuzz/fmu.rs"]
mod fmu;

/// Longest a single case may take before it counts as a hang.
const CASE_LIMIT: Duration = Duration::from_secs(30);

/// Steps a fuzzed run takes at most (bounded work per case).
const STEPS: usize = 4;

/// Estimated seconds a case may cost (build and [`STEPS`] steps) before the
/// cost guard skips it (see [`Entry::estimate`]).
const COST_BUDGET: f64 = 3.0;

/// Steps a C ABI `mi_sim_advance_to` or `mi_sim_run` may take before the
/// progress callback cancels it.
const ADVANCE_STEPS: u64 = 200;

/// Error names of the library (`Error::name`), the documented table. The
/// library exposes no list of them (an enum with a `name` method), so the
/// table is written out here.
const NAMES: [&str; 18] = [
    "OutOfRange",
    "UnknownParameter",
    "UnknownScene",
    "UnknownModel",
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

/// Result codes of the C ABI (`mi_result`), the documented table: every
/// code that `mi_result_name` names.
fn codes() -> &'static [i32] {
    static CODES: OnceLock<Vec<i32>> = OnceLock::new();
    CODES.get_or_init(|| {
        (-64..256)
            .filter(|&c| {
                // SAFETY: a static NUL-terminated string.
                let name = unsafe { CStr::from_ptr(mi_result_name(c)) };
                name.to_bytes() != b"MI_UNKNOWN_RESULT"
            })
            .collect()
    })
}

/// Codes of a solver stop (and a cancel): the run has ended, and every
/// later call that steps returns the same code.
fn is_stop(code: i32) -> bool {
    (20..30).contains(&code)
}

/// xorshift64*: a small, seeded, reproducible generator.
pub struct Rng(u64);

impl Rng {
    /// The next 64 random bits.
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    /// A number in `0..n`.
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    /// A number in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// An element of `v`.
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
    /// A value inside the range of `spec`, at its edges by preference: the
    /// ends (where allowed), just inside them, the smallest positive
    /// numbers where the range starts at 0, or anywhere between.
    fn extreme(&mut self, spec: &ParamSpec) -> f64 {
        let (lo, hi) = (spec.range.min, spec.range.max);
        let candidates = [
            lo,
            hi,
            lo * (1.0 + 1e-12) + if lo == 0.0 { 5e-324 } else { 0.0 },
            hi * (1.0 - 1e-12),
            5e-324,
            1e-310,
            f64::MIN_POSITIVE,
            lo + 1e-300,
            lo + (hi - lo) * self.unit(),
            spec.default,
        ];
        for _ in 0..16 {
            let v = *self.pick(&candidates);
            let v = if spec.range.integer { v.round() } else { v };
            if spec.range.contains(v) {
                return v;
            }
        }
        spec.default
    }
}

/// Case counts: by interface, and by scene and interface; cases the cost
/// guard skipped, by scene.
#[derive(Default)]
pub struct Tally {
    cases: BTreeMap<(String, &'static str), usize>,
    skipped: BTreeMap<String, usize>,
}

/// The tally of this run.
fn tally() -> &'static Mutex<Tally> {
    static T: OnceLock<Mutex<Tally>> = OnceLock::new();
    T.get_or_init(Default::default)
}

/// Counts a case of `interface` on `scene`.
pub fn count(scene: &str, interface: &'static str) {
    *tally()
        .lock()
        .unwrap()
        .cases
        .entry((scene.to_string(), interface))
        .or_insert(0) += 1;
}

/// Runs `f` on its own thread under [`CASE_LIMIT`]; panics on a hang or a
/// panic inside, naming the case.
pub fn bounded<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let out = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
        let _ = tx.send(out);
    });
    match rx.recv_timeout(CASE_LIMIT) {
        Ok(Ok(v)) => v,
        Ok(Err(_)) => panic!("panic in case: {what}"),
        Err(_) => panic!(
            "hang (over {CASE_LIMIT:?}) in case: {what}; FMU calls that returned: {:?}",
            fmu::trace()
        ),
    }
}

/// What the fuzzer measured of one built-in scene at start-up.
pub struct Entry {
    /// The built-in name (`taylor`, `table1-4`, `taylor3d-aisi310`, ...).
    pub name: String,
    /// The scene at its coarse resolution ([`coarse_radial`]).
    pub coarse: Scene,
    /// Its `particles_radial` (NaN for a scene without one).
    pub radial: f64,
    /// Exponent of the particle count in `particles_radial - 1`, measured
    /// between the coarse resolution and twice as many spacings (about 1
    /// for a line of particles, 2 for a plane, 2.5 to 3 for a 3-D body).
    pub dim: f64,
    /// Seconds to build the coarse run and take [`STEPS`] steps.
    pub secs: f64,
    /// Seconds per step of the coarse run.
    pub step_secs: f64,
    /// Mean time step of the coarse run (s).
    pub dt: f64,
    /// A saved state of the coarse run after three steps.
    pub state: serde_json::Value,
    /// Whether the coarse run of a registry row's own scene runs to its end
    /// within [`TO_END`] (not measured for the named variants).
    pub to_end: bool,
}

/// Wall time within which a coarse run to its end counts as cheap.
const TO_END: Duration = Duration::from_secs(1);

impl Entry {
    /// A 3-D scene (its particle count grows as the cube of the
    /// resolution).
    pub fn three_d(&self) -> bool {
        self.dim > 2.2
    }

    /// Estimated seconds to build `scene` (of this entry's kind) and take
    /// [`STEPS`] steps, scaled from the coarse run: by the resolution to
    /// the measured power, and by the spread of the lengths (parameters in
    /// m) against the coarse scene's, to one power less (a long thin rod
    /// has as many layers more; a wide plate, the square).
    ///
    /// The cost guard keeps each case bounded in time: a scene within the
    /// memory budget can still take minutes to build (400 000 nodes). A
    /// scene over the budget is refused by the library before it builds,
    /// and is exercised here whatever its estimate.
    pub fn estimate(&self, scene: &Scene) -> f64 {
        let k = |s: &Scene| s.get("particles_radial").map(|v| (v - 1.0).max(1.0));
        let resolution = match (k(scene), k(&self.coarse)) {
            (Ok(a), Ok(b)) => (a / b).powf(self.dim),
            _ => 1.0,
        };
        let ratios: Vec<f64> = scene
            .param_specs()
            .iter()
            .filter(|p| p.unit == "m")
            .filter_map(|p| Some(scene.get(p.name).ok()? / self.coarse.get(p.name).ok()?))
            .filter(|r| r.is_finite() && *r > 0.0)
            .collect();
        let spread = match (
            ratios.iter().copied().reduce(f64::max),
            ratios.iter().copied().reduce(f64::min),
        ) {
            (Some(hi), Some(lo)) => (hi / lo).powf((self.dim - 1.0).max(1.0)),
            _ => 1.0,
        };
        self.secs * resolution * spread
    }
}

/// A built-in scene: a registry row, each as likely (so that the twelve
/// `table1-N` variants of `taylor` do not crowd out the other rows), then
/// one of its built-in scenes.
fn pick_entry<'a>(rng: &mut Rng, entries: &'a [Entry]) -> &'a Entry {
    let mut rows: Vec<&str> = entries.iter().map(|e| e.coarse.kind().name()).collect();
    rows.sort_unstable();
    rows.dedup();
    let row = *rng.pick(&rows);
    let of_row: Vec<&Entry> = entries
        .iter()
        .filter(|e| e.coarse.kind().name() == row)
        .collect();
    let entry: &&Entry = rng.pick(&of_row);
    entry
}

/// The smallest `particles_radial` at which the default scene `name` builds
/// and takes [`STEPS`] steps, from `max(min, 3, default / 8)` up: coarse and
/// cheap, whatever the scene (3 across a 3-D rod, 100 for Noh).
fn coarse_radial(scene: &Scene) -> Option<f64> {
    let spec = scene
        .param_specs()
        .iter()
        .find(|p| p.name == "particles_radial")?;
    let start = spec.range.min.max(3.0).max((spec.default / 8.0).ceil());
    (0..40).map(|k| start + k as f64).find(|&n| {
        let mut s = scene.clone();
        s.set("particles_radial", n).is_ok()
            && Simulation::new(s).is_ok_and(|mut sim| (0..STEPS).all(|_| sim.step().is_ok()))
    })
}

/// Measures every built-in scene: its coarse resolution, its dimension, its
/// cost and a saved state.
fn measure() -> Vec<Entry> {
    builtin_names()
        .into_iter()
        .map(|name| {
            let mut coarse = Scene::builtin(&name).unwrap();
            let radial = coarse_radial(&coarse).unwrap_or(f64::NAN);
            if radial.is_finite() {
                coarse.set("particles_radial", radial).unwrap();
            }
            let t = Instant::now();
            let mut sim = Simulation::new(coarse.clone()).unwrap();
            let built = t.elapsed().as_secs_f64();
            for _ in 0..STEPS {
                sim.step().unwrap();
            }
            let secs = t.elapsed().as_secs_f64().max(1e-3);
            let step_secs = ((secs - built) / STEPS as f64).max(1e-5);
            let dt = sim.time() / STEPS as f64;
            let mut fresh = Simulation::new(coarse.clone()).unwrap();
            for _ in 0..3 {
                fresh.step().unwrap();
            }
            let state = serde_json::from_slice(&fresh.serialize_state()).unwrap();
            let dim = if radial.is_finite() {
                let mut fine = coarse.clone();
                let k0 = radial - 1.0;
                fine.set("particles_radial", 2.0 * k0 + 1.0).unwrap();
                let n0 = sim.particles() as f64;
                let n1 = Simulation::new(fine).unwrap().particles() as f64;
                ((n1 / n0).ln() / 2f64.ln()).max(1.0)
            } else {
                1.0
            };
            let to_end = Scene::default_of(coarse.kind()).title == coarse.title && {
                let mut sim = Simulation::new(coarse.clone()).unwrap();
                let t = Instant::now();
                let _ = sim.run_with(|_| t.elapsed() < TO_END);
                sim.finished() && sim.error().is_none()
            };
            Entry {
                name,
                to_end,
                coarse,
                radial,
                dim,
                secs,
                step_secs,
                dt,
                state,
            }
        })
        .collect()
}

/// The name of the material choice, preset or model names of a scene file's
/// `[material]` table: the registry's names and some that are not.
fn material_names(rng: &mut Rng, key: &str) -> String {
    let hostile = ["", "bogus", "Bilinear", "johnson-cook", "linear\u{1}"];
    if rng.below(6) == 0 {
        return rng.pick(&hostile).to_string();
    }
    match key {
        "strength" => rng.pick(&StrengthKind::ALL).name().to_string(),
        "eos" => rng.pick(&EosKind::ALL).name().to_string(),
        _ => rng.pick(PRESETS).name.to_string(),
    }
}

/// Chooses material models for `scene` as a scene file's `[material]`
/// table, the CLI and the C ABI do: a preset, a strength model, an EOS, or
/// two of them. A name the registry lists must be accepted where the scene
/// has a body (unless a strength or EOS contradicts the preset); a scene
/// without one refuses every choice with `UnknownModel`. Returns the names.
fn choose(rng: &mut Rng, scene: &mut Scene) -> String {
    let mut pick = |key: &str| (rng.below(2) == 0).then(|| material_names(rng, key));
    let (mut s, mut e, mut p) = (pick("strength"), pick("eos"), pick("preset"));
    if s.is_none() && e.is_none() && p.is_none() {
        p = Some(material_names(rng, "preset"));
    }
    if p.is_some() && rng.below(2) == 0 {
        (s, e) = (None, None);
    }
    let names = format!("material {s:?} {e:?} {p:?}");
    let has_body = scene.kind().material().is_some();
    let known = s.as_deref().is_none_or(|n| StrengthKind::named(n).is_ok())
        && e.as_deref().is_none_or(|n| EosKind::named(n).is_ok())
        && p.as_deref()
            .is_none_or(|n| PRESETS.iter().any(|q| q.name == n));
    let consistent = match p
        .as_deref()
        .and_then(|n| PRESETS.iter().find(|q| q.name == n))
    {
        Some(q) => {
            s.as_deref().is_none_or(|n| n == q.choice.strength.name())
                && e.as_deref().is_none_or(|n| n == q.choice.eos.name())
        }
        None => true,
    };
    let r = scene.choose_material(s.as_deref(), e.as_deref(), p.as_deref());
    match &r {
        Ok(()) => assert!(has_body && known && consistent, "{names}: accepted"),
        Err(err) => {
            assert!(NAMES.contains(&err.name()), "{names}: {err:?}");
            if !has_body {
                assert_eq!(err.name(), "UnknownModel", "{names}: {err}");
            }
            assert!(
                !(has_body && known && consistent),
                "{names}: refused: {err}"
            );
        }
    }
    names
}

/// Builds and steps a scene (unless the cost guard skips it); on success
/// every observable must be finite, on failure the error must be one of the
/// documented names.
fn exercise(what: &str, entry: &Entry, scene: meshless_impact::Result<Scene>) {
    if let Ok(s) = &scene
        && entry.estimate(s) > COST_BUDGET
        && s.validate().is_ok()
    {
        *tally()
            .lock()
            .unwrap()
            .skipped
            .entry(entry.name.clone())
            .or_insert(0) += 1;
        return;
    }
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

/// A value for `spec` from the hostile [`Rng::number`], but a cheap
/// resolution most of the time (the cost guard bounds the rest).
fn draw(rng: &mut Rng, entry: &Entry, spec: &ParamSpec) -> f64 {
    let v = rng.number(spec.range.min, spec.range.max);
    if spec.name == "particles_radial" && rng.below(4) != 0 {
        v.min(2.0 * entry.radial)
    } else {
        v
    }
}

/// Parameter sets: a built-in scene, maybe another material, one to three
/// parameters of its table at hostile values.
fn fuzz_params(rng: &mut Rng, entries: &Arc<Vec<Entry>>) -> String {
    let entry = pick_entry(rng, entries);
    let mut scene = entry.coarse.clone();
    let mut sets = Vec::new();
    let mut result = Ok(());
    let has_body = scene.kind().material().is_some();
    if rng.below(if has_body { 3 } else { 12 }) == 0 {
        sets.push((choose(rng, &mut scene), f64::NAN));
    }
    for _ in 0..1 + rng.below(3) {
        let spec = rng.pick(scene.param_specs());
        let v = draw(rng, entry, spec);
        sets.push((spec.name.to_string(), v));
        if let Err(e) = scene.set(spec.name, v) {
            assert!(!spec.range.contains(v), "{}: {v} refused: {e}", spec.name);
            result = Err(e);
            break;
        }
        assert!(spec.range.contains(v), "{} = {v} accepted", spec.name);
    }
    count(&entry.name, "parameters");
    let what = format!("params {} {sets:?}", entry.name);
    exercise(&what, entry, result.map(|_| scene));
    what
}

/// Extreme physics: range ends and the values just inside them, subnormal
/// but allowed values, and soft heavy bodies (every density at its
/// maximum, every modulus at its minimum) at the highest speed. Every value
/// is in range, so it must be accepted; the run must build and take its
/// steps with finite observables, or stop with a named error.
fn fuzz_extreme(rng: &mut Rng, entries: &Arc<Vec<Entry>>) -> String {
    let entry = pick_entry(rng, entries);
    let mut scene = entry.coarse.clone();
    let mut sets = Vec::new();
    if scene.kind().material().is_some() && rng.below(3) == 0 {
        let p = rng.pick(PRESETS).name;
        scene.choose_material(None, None, Some(p)).unwrap();
        sets.push((format!("preset {p}"), f64::NAN));
    }
    let specs = scene.param_specs();
    let mut chosen: Vec<(&ParamSpec, f64)> = Vec::new();
    if rng.below(3) == 0 {
        // A soft, heavy body, fast.
        for p in specs {
            if p.name.contains("density") {
                chosen.push((p, p.range.max));
            } else if p.name.contains("modulus") {
                chosen.push((p, p.range.min.max(p.range.min * (1.0 + 1e-12))));
            } else if p.unit == "m/s" {
                chosen.push((p, rng.extreme(p)));
            }
        }
    }
    // Speeds, times and sizes above all.
    let physical: Vec<&ParamSpec> = specs
        .iter()
        .filter(|p| matches!(p.unit, "m/s" | "s" | "m"))
        .collect();
    for _ in 0..1 + rng.below(3) {
        let p = if !physical.is_empty() && rng.below(4) != 0 {
            *rng.pick(&physical)
        } else {
            rng.pick(specs)
        };
        chosen.push((p, rng.extreme(p)));
    }
    for (p, v) in chosen {
        if !p.range.contains(v) {
            continue;
        }
        sets.push((p.name.to_string(), v));
        if let Err(e) = scene.set(p.name, v) {
            panic!(
                "extreme {}: {} = {v} is in range but refused: {e}",
                entry.name, p.name
            );
        }
    }
    count(&entry.name, "extreme physics");
    let what = format!("extreme {} {sets:?}", entry.name);
    let checked = scene.validate().map(|()| scene);
    exercise(&what, entry, checked);
    what
}

fn fuzz_toml(rng: &mut Rng, entries: &Arc<Vec<Entry>>) -> String {
    let entry = pick_entry(rng, entries);
    let mut scene = entry.coarse.clone();
    if scene.kind().material().is_some() && rng.below(3) == 0 {
        let c = rng.pick(&MaterialChoice::ALL);
        scene.set_material(*c).unwrap();
    }
    let mut text: Vec<u8> = scene.to_toml().into_bytes();
    let other = format!("scene = \"{}\"\n", rng.pick(entries).coarse.kind().name());
    let material = format!(
        "[material]\n{} = \"{}\"\n",
        ["strength", "eos", "preset", "bogus"][rng.below(4)],
        {
            let key = *rng.pick(&["strength", "eos", "preset"]);
            material_names(rng, key)
        }
    );
    let param = format!(
        "{} = {:?}\n",
        rng.pick(scene.param_specs()).name,
        rng.number(-1.0, 1e3)
    );
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
        other.as_bytes(),
        material.as_bytes(),
        param.as_bytes(),
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
    count(&entry.name, "TOML");
    let what = format!("toml {text:?}");
    let parsed = Scene::from_toml_str(&text);
    // The cost guard is that of the scene the text names.
    let entry = match &parsed {
        Ok(s) => entries
            .iter()
            .find(|e| e.name == s.kind().name())
            .unwrap_or(entry),
        Err(_) => entry,
    };
    exercise(&what, entry, parsed);
    what
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
pub fn edit_leaf(rng: &mut Rng, v: &mut serde_json::Value) -> String {
    let target = leaf(rng, v);
    let new = match rng.below(6) {
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
        4 => serde_json::json!(*rng.pick(&[1e300, -1e300, 5e-324, 1e-300, 1e30])),
        _ => serde_json::json!(true),
    };
    let edit = format!("{target} -> {new}");
    *target = new;
    edit
}

/// The key a saved state gives its scene (`{"scene": {"params": {KEY:
/// ...}}}`): the saved form of its kind.
fn saved_key(state: &serde_json::Value) -> Option<String> {
    state["scene"]["params"]
        .as_object()?
        .keys()
        .next()
        .map(|k| k.to_string())
}

/// Renames every object key `from` to `to`, at any depth.
fn rename_keys(v: &mut serde_json::Value, from: &str, to: &str) {
    match v {
        serde_json::Value::Object(o) => {
            if let Some(x) = o.remove(from) {
                o.insert(to.to_string(), x);
            }
            o.values_mut().for_each(|x| rename_keys(x, from, to));
        }
        serde_json::Value::Array(a) => a.iter_mut().for_each(|x| rename_keys(x, from, to)),
        _ => {}
    }
}

/// Steps an accepted state like any run: finite or a named stop.
fn step_restored(w: &str, mut sim: Simulation) {
    for _ in 0..STEPS {
        if sim.finished() {
            break;
        }
        if let Err(e) = sim.step() {
            assert!(NAMES.contains(&e.name()), "{w}: {e:?}");
            return;
        }
        let o = sim.observables();
        assert!(o.iter().all(|v| v.is_finite()), "{w}: NaN on success {o:?}");
    }
}

/// Saved states: a state of any built-in scene with hostile leaves, and
/// maybe its scene key swapped for another scene's (the solver's and the
/// scene's, or only one of them).
fn fuzz_state(rng: &mut Rng, entries: &Arc<Vec<Entry>>) -> String {
    let entry = pick_entry(rng, entries);
    let mut state = entry.state.clone();
    let mut edits: Vec<String> = Vec::new();
    let swap = rng.below(4) == 0;
    if swap {
        let other = pick_entry(rng, entries);
        let (Some(from), Some(to)) = (saved_key(&state), saved_key(&other.state)) else {
            panic!("a saved state names its scene");
        };
        match rng.below(3) {
            0 => rename_keys(&mut state, &from, &to),
            1 => rename_keys(&mut state["scene"], &from, &to),
            _ => rename_keys(&mut state["solver"], &from, &to),
        }
        edits.push(format!("key {from} -> {to}"));
    }
    for _ in 0..rng.below(if swap { 2 } else { 3 }) + usize::from(!swap) {
        edits.push(edit_leaf(rng, &mut state));
    }
    let bytes = serde_json::to_vec(&state).unwrap();
    count(&entry.name, "saved state");
    let what = format!("state of {} edits {edits:?}", entry.name);
    let w = what.clone();
    bounded(&what, move || match Simulation::deserialize_state(&bytes) {
        Ok(sim) => step_restored(&w, sim),
        Err(e) => assert_eq!(e.name(), "InvalidState", "{w}: {e}"),
    });
    what
}

/// A C ABI handle (freed on drop).
struct Handle(*mut mi_sim);

impl Drop for Handle {
    fn drop(&mut self) {
        // SAFETY: NULL or a live handle, freed once.
        unsafe { mi_sim_free(self.0) };
    }
}

/// The progress callback of the C ABI cases: cancels after
/// [`ADVANCE_STEPS`] steps of one call (`user_data` counts them).
unsafe extern "C" fn budget(data: *mut c_void, _time: f64, _end: f64, _steps: u64) -> bool {
    // SAFETY: `data` is the case's live counter.
    let n = unsafe { &*(data as *const Cell<u64>) };
    n.set(n.get() + 1);
    n.get() <= ADVANCE_STEPS
}

/// Creates a handle of built-in scene `name` at the coarse resolution `n`.
fn handle(name: &str, n: f64) -> (Handle, i32) {
    let scene = CString::new(name).unwrap();
    let mut sim = null_mut();
    // SAFETY: valid NUL-terminated string and out pointer.
    let code = unsafe { mi_sim_new(scene.as_ptr(), &mut sim) } as i32;
    if !sim.is_null() && n.is_finite() {
        let p = CString::new("particles_radial").unwrap();
        // SAFETY: live handle, valid name.
        let c = unsafe { mi_sim_set_param(sim, p.as_ptr(), n) };
        assert_eq!(c, mi_result::MI_OK, "{name}: particles_radial = {n}");
    }
    (Handle(sim), code)
}

/// Cross-scene loads through the C ABI: the state of scene A (edited or
/// not) into a handle of scene B. A state of another kind must be refused
/// with `MI_INVALID_STATE` and the handle keep its run; an unedited state of
/// the same kind must load.
fn fuzz_cross(rng: &mut Rng, entries: &Arc<Vec<Entry>>) -> String {
    let a = pick_entry(rng, entries);
    let b = pick_entry(rng, entries);
    let mut state = a.state.clone();
    let edit = if rng.below(3) == 0 {
        edit_leaf(rng, &mut state)
    } else {
        String::new()
    };
    let same = a.coarse.kind() == b.coarse.kind();
    let bytes = serde_json::to_vec(&state).unwrap();
    let (bname, bn) = (b.name.clone(), b.radial);
    count(&a.name, "C ABI cross-scene load");
    let what = format!("C ABI load of a {} state into {} {edit:?}", a.name, b.name);
    let w = what.clone();
    bounded(&what, move || {
        let (h, code) = handle(&bname, bn);
        assert_eq!(code, 0, "{w}: mi_sim_new");
        // SAFETY: a live handle; `bytes` valid for its length.
        let code = unsafe { mi_sim_state_load(h.0, bytes.as_ptr(), bytes.len()) } as i32;
        assert!(codes().contains(&code), "{w}: {code}");
        if !same {
            assert_eq!(code, mi_result::MI_INVALID_STATE as i32, "{w}");
        } else if edit.is_empty() {
            assert_eq!(code, 0, "{w}");
        } else {
            assert!(code == 0 || code == 12, "{w}: {code}");
        }
        let steps = Cell::new(0u64);
        // SAFETY: a live handle; the counter outlives the calls.
        unsafe {
            mi_sim_set_progress(h.0, Some(budget), &steps as *const Cell<u64> as *mut c_void);
        }
        for _ in 0..2 {
            // SAFETY: a live handle.
            let c = unsafe { mi_sim_step(h.0) } as i32;
            assert!(c == 0 || c == 14 || is_stop(c), "{w}: step {c}");
            let mut v = 0.0;
            let obs = CString::new(b_observable(&bname)).unwrap();
            // SAFETY: a live handle, valid name and output.
            let c2 = unsafe { mi_sim_observable(h.0, obs.as_ptr(), &mut v) } as i32;
            if c == 0 && c2 == 0 {
                assert!(v.is_finite(), "{w}: observable {v} with MI_OK");
            }
        }
    });
    what
}

/// The first observable of built-in scene `name`.
fn b_observable(name: &str) -> String {
    Scene::builtin(name).unwrap().kind().observable_specs()[0]
        .name
        .to_string()
}

/// The names of the parameters of a handle, from `mi_sim_param_info`.
fn param_names(sim: *mut mi_sim) -> Vec<String> {
    let mut n = 0;
    // SAFETY: NULL or a live handle; valid outputs.
    if unsafe { mi_sim_param_count(sim, &mut n) } != mi_result::MI_OK {
        return Vec::new();
    }
    (0..n)
        .filter_map(|k| {
            let mut info = std::mem::MaybeUninit::<mi_param_info>::uninit();
            // SAFETY: a live handle; `info` valid for one write.
            let c = unsafe { mi_sim_param_info(sim, k, info.as_mut_ptr()) };
            (c == mi_result::MI_OK).then(|| {
                // SAFETY: written on MI_OK; the name is the handle's.
                unsafe { CStr::from_ptr(info.assume_init().name) }
                    .to_string_lossy()
                    .into_owned()
            })
        })
        .collect()
}

/// A C ABI call order on a handle of a built-in scene (or a hostile name):
/// parameters of that scene's table, materials, steps, advances, runs,
/// observables, saves and loads. A solver stop must be sticky: every later
/// call that steps returns it, and parameters are then fixed.
fn fuzz_capi(rng: &mut Rng, entries: &Arc<Vec<Entry>>) -> String {
    let seed = rng.next();
    let hostile = [
        "table1-01",
        "table1-+1",
        "TAYLOR",
        "",
        "taylor\u{1}",
        "noh ",
    ];
    let (name, radial) = if rng.below(4) == 0 {
        (rng.pick(&hostile).to_string(), f64::NAN)
    } else {
        let e = pick_entry(rng, entries);
        (e.name.clone(), e.radial)
    };
    count(&name, "C ABI call order");
    let what = format!("C ABI call order on {name:?}, seed {seed}");
    let w = what.clone();
    bounded(&what, move || {
        let mut rng = Rng(seed | 1);
        let mut calls: Vec<(String, i32)> = Vec::new();
        let (h, code) = handle(&name, radial);
        calls.push(("new".into(), code));
        let sim = h.0;
        assert_eq!(sim.is_null(), code != 0, "{w}: {calls:?}");
        let steps = Cell::new(0u64);
        // SAFETY: NULL or a live handle; the counter outlives the handle.
        unsafe {
            mi_sim_set_progress(sim, Some(budget), &steps as *const Cell<u64> as *mut c_void)
        };
        let mut saved: Vec<u8> = Vec::new();
        // The stop that ended the run: (code, whether in the first step).
        let mut stop: Option<(i32, bool)> = None;
        let mut names = param_names(sim);
        for _ in 0..rng.below(14) {
            let pname = if names.is_empty() || rng.below(8) == 0 {
                rng.pick(&["bogus", "", "particles_radial "]).to_string()
            } else {
                rng.pick(&names).clone()
            };
            let cname = CString::new(pname.clone()).unwrap();
            let mut v = 0.0;
            let mut n = 0usize;
            steps.set(0);
            let op = rng.below(10);
            // SAFETY: `sim` is NULL or live; pointers are valid for the call.
            let (call, code) = unsafe {
                match op {
                    0 => {
                        let value = if pname == "particles_radial" && rng.below(4) != 0 {
                            radial + rng.below(2) as f64
                        } else {
                            rng.number(-10.0, 1e3)
                        };
                        let c = mi_sim_set_param(sim, cname.as_ptr(), value);
                        (format!("set {pname} {value:?}"), c)
                    }
                    1 => ("get".into(), mi_sim_get_param(sim, cname.as_ptr(), &mut v)),
                    2 => ("step".into(), mi_sim_step(sim)),
                    3 => {
                        let t = rng.number(0.0, 2e-6);
                        (format!("advance {t:?}"), mi_sim_advance_to(sim, t))
                    }
                    4 => {
                        let obs = sim_observable(&mut rng, sim);
                        let o = CString::new(obs.clone()).unwrap();
                        let c = mi_sim_observable(sim, o.as_ptr(), &mut v);
                        if c == mi_result::MI_OK {
                            assert!(v.is_finite(), "{w}: NaN {obs} with MI_OK: {calls:?}");
                        }
                        (format!("observable {obs}"), c)
                    }
                    5 => {
                        let c = mi_sim_state_save(sim, null_mut(), 0, &mut n);
                        if c == mi_result::MI_BUFFER_TOO_SMALL {
                            saved = vec![0; n];
                            let c = mi_sim_state_save(sim, saved.as_mut_ptr(), n, &mut n);
                            ("save".into(), c)
                        } else {
                            ("save-size".into(), c)
                        }
                    }
                    6 => {
                        let mut bytes = saved.clone();
                        if !bytes.is_empty() && rng.below(2) == 0 {
                            let at = rng.below(bytes.len());
                            bytes[at] = rng.next() as u8;
                        }
                        let c = mi_sim_state_load(sim, bytes.as_ptr(), bytes.len());
                        if c == mi_result::MI_OK {
                            stop = None;
                        }
                        ("load".into(), c)
                    }
                    7 => {
                        let key = *rng.pick(&["strength", "eos", "preset", "preset", "bogus"]);
                        let value = material_names(&mut rng, key);
                        let (k, val) = (CString::new(key).unwrap(), CString::new(value.clone()));
                        let val = val.unwrap();
                        let c = mi_sim_set_material(sim, k.as_ptr(), val.as_ptr());
                        names = param_names(sim);
                        (format!("material {key} {value}"), c)
                    }
                    8 => ("run".into(), mi_sim_run(sim)),
                    _ => {
                        let mut done = false;
                        ("finished".into(), mi_sim_finished(sim, &mut done))
                    }
                }
            };
            let code = code as i32;
            calls.push((call, code));
            assert!(codes().contains(&code), "{w}: {calls:?}");
            assert_ne!(code, 30, "{w}: a caught panic: {calls:?}");
            if sim.is_null() {
                assert_eq!(code, 1, "{w}: NULL handle: {calls:?}");
                continue;
            }
            let steps_op = matches!(op, 2 | 3 | 8);
            let fixing = matches!(op, 0 | 7);
            if let Some((s, first)) = stop {
                // (`mi_sim_advance_to` checks its time first.)
                let sticky = if steps_op {
                    code == s || (op == 3 && code == 7)
                } else if fixing {
                    code == 14
                } else {
                    true
                };
                if !sticky {
                    panic!(
                        "{w}: the stop {s} (in the first step: {first}) is not sticky: {calls:?}"
                    );
                }
            } else if steps_op && is_stop(code) {
                let mut taken = 0u64;
                // SAFETY: a live handle; a valid output.
                assert_eq!(mi_result::MI_OK, unsafe { mi_sim_steps(sim, &mut taken) });
                stop = Some((code, taken == 0));
            }
        }
    });
    what
}

/// An observable name of the handle's scene (or not one).
fn sim_observable(rng: &mut Rng, sim: *mut mi_sim) -> String {
    let mut n = 0;
    // SAFETY: NULL or a live handle; valid output.
    let c = unsafe { mi_sim_observable_count(sim, &mut n) };
    if c != mi_result::MI_OK || n == 0 || rng.below(8) == 0 {
        return "bogus".into();
    }
    let mut info = std::mem::MaybeUninit::<mi_observable_info>::uninit();
    // SAFETY: a live handle, an index below the count, a valid output.
    let c = unsafe { mi_sim_observable_info(sim, rng.below(n), info.as_mut_ptr()) };
    assert_eq!(c, mi_result::MI_OK);
    // SAFETY: written on MI_OK; the name is the handle's.
    unsafe { CStr::from_ptr(info.assume_init().name) }
        .to_string_lossy()
        .into_owned()
}

/// The case kinds, by interface name.
const KINDS: [&str; 9] = [
    "parameters",
    "TOML",
    "saved state",
    "C ABI cross-scene load",
    "C ABI call order",
    "extreme physics",
    "FMI 3.0 call order",
    "FMI 2.0 call order",
    "FMI 3.0 call order (again)",
];

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
    let t = Instant::now();
    let entries = Arc::new(measure());
    let pool = Arc::new(fmu::Pool::new(&entries));
    println!(
        "fuzz: measured {} scenes and {} FMUs in {:.1} s",
        entries.len(),
        pool.fmus.len(),
        t.elapsed().as_secs_f64()
    );
    for e in entries.iter() {
        println!(
            "  {:<18} particles_radial {:>4} dim {:.2} cost {:.3} s, {:.2e} s/step, dt {:.2e} s{}",
            e.name,
            e.radial,
            e.dim,
            e.secs,
            e.step_secs,
            e.dt,
            if e.to_end {
                ", runs to its end cheaply"
            } else {
                ""
            }
        );
    }
    let start = Instant::now();
    let mut per_kind = [0usize; KINDS.len()];
    while start.elapsed().as_secs_f64() < seconds {
        let k = rng.below(KINDS.len());
        match k {
            0 => fuzz_params(&mut rng, &entries),
            1 => fuzz_toml(&mut rng, &entries),
            2 => fuzz_state(&mut rng, &entries),
            3 => fuzz_cross(&mut rng, &entries),
            4 => fuzz_capi(&mut rng, &entries),
            5 => fuzz_extreme(&mut rng, &entries),
            6 | 8 => fmu::fuzz(&mut rng, &pool, false),
            _ => fmu::fuzz(&mut rng, &pool, true),
        };
        per_kind[k] += 1;
    }
    let tally = tally().lock().unwrap();
    let mut by_interface: BTreeMap<&str, usize> = BTreeMap::new();
    for ((_, i), n) in &tally.cases {
        *by_interface.entry(i).or_insert(0) += n;
    }
    println!(
        "fuzz: seed {seed}, {:.0} s, {} cases; 0 crashes, 0 hangs, 0 NaN on success, \
         0 undocumented errors or statuses, 0 forbidden FMU calls answered OK",
        start.elapsed().as_secs_f64(),
        per_kind.iter().sum::<usize>()
    );
    println!("cases by interface:");
    for (i, n) in &by_interface {
        println!("  {i:<24} {n}");
    }
    println!("cases by scene (or FMU) and interface:");
    let mut scenes: Vec<&String> = tally.cases.keys().map(|(s, _)| s).collect();
    scenes.dedup();
    for s in scenes {
        let row: Vec<String> = tally
            .cases
            .iter()
            .filter(|((t, _), _)| t == s)
            .map(|((_, i), n)| format!("{i} {n}"))
            .collect();
        println!("  {:<26} {}", format!("{s:?}"), row.join(", "));
    }
    for (s, n) in &tally.skipped {
        println!("  skipped by the cost guard (over {COST_BUDGET} s estimated): {s} {n}");
    }
    // Every built-in scene and every FMU was reached by a long enough run.
    if seconds >= 60.0 {
        for e in entries.iter() {
            assert!(
                tally.cases.keys().any(|(s, _)| *s == e.name),
                "scene {} never fuzzed",
                e.name
            );
        }
        for f in &pool.fmus {
            let id = f.fmu.identity().model_identifier;
            assert!(
                tally.cases.keys().any(|(s, _)| s == id),
                "FMU {id} never fuzzed"
            );
        }
    }
    assert!(per_kind.iter().all(|&c| c > 0), "{per_kind:?}");
}
