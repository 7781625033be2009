//! Boundary costs that must not grow with the particle count (issue 19,
//! item 12): an FMU output read, a C field read, the FMU state's size.
//!
//! Costs are counted, not timed: a counting allocator sees every byte that
//! a call allocates, and the FMU state's bytes are counted per particle.
//! The figures at 10^6 particles (times included) come from the ignored
//! test at the end, run by `scripts/validate.sh` and recorded in
//! BENCHMARKS.md; it uses only the C functions, so the same file measures
//! older builds too.

use meshless_impact::internals::capi::*;
use meshless_impact::internals::fmi::{Fmu, VarKind, fmi3::*};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::ffi::{CString, c_void};
use std::ptr::null_mut;
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};
use std::time::Instant;

/// The system allocator, counting: bytes allocated by each thread, and the
/// bytes live in the whole process with their peak.
struct Counting;

thread_local! {
    static ALLOCATED: Cell<usize> = const { Cell::new(0) };
}
static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator; the counters never allocate.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATED.try_with(|a| a.set(a.get() + layout.size()));
        let live = LIVE.fetch_add(layout.size(), Relaxed) + layout.size();
        PEAK.fetch_max(live, Relaxed);
        // SAFETY: the caller's layout, forwarded.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Relaxed);
        // SAFETY: allocated above with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

/// Bytes allocated by this thread during `f`, and its result.
fn allocated_by<R>(f: impl FnOnce() -> R) -> (usize, R) {
    let before = ALLOCATED.with(|a| a.get());
    let r = f();
    (ALLOCATED.with(|a| a.get()) - before, r)
}

/// A value reference of the Taylor FMU.
fn vr(name: &str) -> u32 {
    let vars = taylor().variables();
    vars[vars.iter().position(|v| v.name == name).unwrap()].vr
}

fn taylor() -> Fmu {
    Fmu::named("TaylorImpact").unwrap()
}

/// An FMI 3 instance of the Taylor FMU with `particles_radial` and
/// `initial_length` set, after one communication step short enough to be
/// one solver step.
fn stepped_fmu(particles_radial: i32, initial_length: f64) -> *mut c_void {
    fmu_at(particles_radial, initial_length, 1e-12)
}

/// An FMI 3 instance of the Taylor FMU with `particles_radial` and
/// `initial_length` set, after one communication step to `time`.
fn fmu_at(particles_radial: i32, initial_length: f64, time: f64) -> *mut c_void {
    let name = CString::new("boundary").unwrap();
    let token = CString::new(taylor().token()).unwrap();
    // SAFETY: valid strings; no callbacks; the instance is live until freed.
    unsafe {
        let inst = fmi3InstantiateCoSimulation(
            name.as_ptr(),
            token.as_ptr(),
            std::ptr::null(),
            0,
            0,
            0,
            0,
            std::ptr::null(),
            0,
            null_mut(),
            None,
            null_mut(),
        );
        assert!(!inst.is_null());
        let pr = vr("particles_radial");
        assert_eq!(fmi3SetInt32(inst, &pr, 1, &particles_radial, 1), 0);
        let length = vr("initial_length");
        assert_eq!(fmi3SetFloat64(inst, &length, 1, &initial_length, 1), 0);
        assert_eq!(fmi3EnterInitializationMode(inst, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi3ExitInitializationMode(inst), 0);
        let (mut event, mut terminate, mut early, mut last) = (0u8, 0u8, 0u8, 0.0);
        let status = fmi3DoStep(
            inst,
            0.0,
            time,
            0,
            &mut event,
            &mut terminate,
            &mut early,
            &mut last,
        );
        assert_eq!(status, 0);
        inst
    }
}

/// The value references of the Taylor FMU's Float64 outputs, and that of
/// one read alone (`tail_velocity`).
fn float_outputs() -> Vec<u32> {
    taylor()
        .variables()
        .iter()
        .filter(|v| matches!(v.kind, VarKind::Output(_, o) if !o.is_bool()))
        .map(|v| v.vr)
        .collect()
}

/// Reads `vrs` with `fmi3GetFloat64`.
fn get(inst: *mut c_void, vrs: &[u32]) -> Vec<f64> {
    let mut out = vec![0.0; vrs.len()];
    // SAFETY: a live instance; arrays of the lengths given.
    let status =
        unsafe { fmi3GetFloat64(inst, vrs.as_ptr(), vrs.len(), out.as_mut_ptr(), out.len()) };
    assert_eq!(status, 0);
    out
}

/// The serialized FMU state of `inst` now.
fn serialized_state(inst: *mut c_void) -> Vec<u8> {
    let mut state = null_mut();
    let mut size = 0;
    // SAFETY: a live instance; the state freed once.
    unsafe {
        assert_eq!(fmi3GetFMUState(inst, &mut state), 0);
        assert_eq!(fmi3SerializedFMUStateSize(inst, state, &mut size), 0);
        let mut data = vec![0u8; size];
        assert_eq!(
            fmi3SerializeFMUState(inst, state, data.as_mut_ptr(), size),
            0
        );
        assert_eq!(fmi3FreeFMUState(inst, &mut state), 0);
        data
    }
}

/// A C ABI Taylor run of `particles_radial` and `initial_length`, one step
/// taken, and its particle count.
fn stepped_capi(particles_radial: f64, initial_length: f64) -> (*mut mi_sim, usize) {
    let scene = CString::new("taylor").unwrap();
    let mut sim = null_mut();
    // SAFETY: valid strings and out-pointers; the handle is live until freed.
    unsafe {
        assert_eq!(mi_sim_new(scene.as_ptr(), &mut sim), mi_result::MI_OK);
        for (name, v) in [
            ("particles_radial", particles_radial),
            ("initial_length", initial_length),
        ] {
            let name = CString::new(name).unwrap();
            assert_eq!(mi_sim_set_param(sim, name.as_ptr(), v), mi_result::MI_OK);
        }
        assert_eq!(mi_sim_step(sim), mi_result::MI_OK);
        let mut n = 0;
        assert_eq!(mi_sim_particle_count(sim, &mut n), mi_result::MI_OK);
        (sim, n)
    }
}

/// Reads the particle field `name` into a buffer of the right size.
fn field(sim: *mut mi_sim, name: &str, len: usize) -> Vec<f64> {
    let name = CString::new(name).unwrap();
    let mut buf = vec![0.0; len];
    let mut needed = 0;
    // SAFETY: a live handle; a buffer of `len` doubles.
    let r = unsafe { mi_sim_field(sim, name.as_ptr(), buf.as_mut_ptr(), len, &mut needed) };
    assert_eq!(r, mi_result::MI_OK);
    assert_eq!(needed, len);
    buf
}

/// The particle count of a default rod with `particles_radial` and
/// `initial_length` (the lattice of the Taylor builder).
fn particles(particles_radial: i32, initial_length: f64) -> usize {
    let spacing = 0.5 * 0.007595 / (particles_radial - 1) as f64;
    particles_radial as usize * ((initial_length / spacing).round() as usize + 1)
}

/// Rods of growing particle counts: (particles_radial, initial_length).
/// From 124 to 19,872 particles (160 times as many).
const RODS: [(i32, f64); 3] = [(4, 0.03797), (8, 0.0759), (32, 0.0759)];

#[test]
fn an_fmu_output_read_allocates_nothing_that_grows_with_the_particles() {
    let mut costs = Vec::new();
    for (pr, length) in RODS {
        let inst = stepped_fmu(pr, length);
        let all = float_outputs();
        let tail = [vr("tail_velocity")];
        // The first read after a step computes; the values are those the
        // whole set gives, bit for bit.
        let (one, first) = allocated_by(|| get(inst, &tail));
        let (every, values) = allocated_by(|| get(inst, &all));
        let (again, repeat) = allocated_by(|| get(inst, &all));
        let k = all.iter().position(|v| *v == tail[0]).unwrap();
        assert_eq!(first[0].to_bits(), values[k].to_bits());
        assert_eq!(values, repeat);
        assert!(values.iter().all(|x| x.is_finite()), "{values:?}");
        costs.push((one, every, again));
        // SAFETY: a live instance, not used afterwards.
        unsafe { fmi3FreeInstance(inst) };
    }
    // The same bytes at every size (the values read, and their copy in
    // the FMI type: two doubles an output), and no more.
    assert!(costs.iter().all(|c| *c == costs[0]), "{costs:?}");
    assert_eq!(costs[0], (2 * 8, 2 * 8 * 12, 2 * 8 * 12), "{costs:?}");
}

#[test]
fn a_c_field_read_makes_that_field_alone() {
    for (pr, length) in RODS {
        let (sim, n) = stepped_capi(pr as f64, length);
        assert_eq!(n, particles(pr, length));
        let density = vec![0.0; n];
        // A size query makes nothing.
        let name = CString::new("stress").unwrap();
        let mut needed = 0;
        let (query, r) = allocated_by(|| {
            // SAFETY: a live handle; a NULL buffer of length 0.
            unsafe { mi_sim_field(sim, name.as_ptr(), null_mut(), 0, &mut needed) }
        });
        assert_eq!((r, needed), (mi_result::MI_OK, 4 * n));
        assert!(query < 256, "{query} bytes to answer a size query");
        // A read makes one field's values (8 bytes a double), once: not
        // the snapshot (13 doubles a particle).
        for (name, components) in [("density", 1), ("stress", 4), ("position", 2)] {
            let len = components * n;
            let mut buf = vec![0.0; len];
            let (bytes, r) = allocated_by(|| {
                let c = CString::new(name).unwrap();
                // SAFETY: a live handle; a buffer of `len` doubles.
                unsafe { mi_sim_field(sim, c.as_ptr(), buf.as_mut_ptr(), len, &mut needed) }
            });
            assert_eq!(r, mi_result::MI_OK);
            assert!(
                bytes >= 8 * len && bytes < 8 * len + 256,
                "{name}: {bytes} bytes for {len} doubles"
            );
        }
        let rho = field(sim, "density", n);
        assert_ne!(rho, density);
        assert!(rho.iter().all(|&x| x > 7000.0 && x < 9000.0));
        // SAFETY: a live handle, not used afterwards.
        unsafe { mi_sim_free(sim) };
    }
}

/// The FMU state holds the run's doubles at 8 bytes each: its size per
/// particle is that of the solver's per-particle doubles and flags, a
/// constant, whatever the count (JSON took 2.45 times as much for test 7
/// at 20 us, once the fields are no longer round numbers).
#[test]
fn the_fmu_state_is_compact() {
    let mut per_particle = Vec::new();
    for (pr, length) in RODS {
        let inst = stepped_fmu(pr, length);
        let data = serialized_state(inst);
        let n = particles(pr, length);
        // Per particle: position 2, velocity 2, density, deviatoric stress
        // 4, pressure, plastic strain, temperature, boundary stress 4
        // doubles, and two flags: 16 doubles + 2 bytes (the masses and the
        // surfaces are the setup's, built from the scene, not saved).
        let floor = n * (16 * 8 + 2);
        assert!(data.len() > floor, "{} bytes, {n} particles", data.len());
        per_particle.push((data.len() - floor) as f64 / n as f64);
        // SAFETY: a live instance, not used afterwards.
        unsafe { fmi3FreeInstance(inst) };
    }
    // Beyond the floor: the histories and the scene, a few bytes a
    // particle at most and fewer as the rod grows.
    assert!(
        per_particle.windows(2).all(|w| w[1] < w[0]),
        "{per_particle:?}"
    );
    assert!(per_particle[2] < 4.0, "{per_particle:?}");
}

/// Figures at 10^6 particles (200 across, a rod 2.5 times the default
/// length: 200 x 5000): time, bytes allocated and peak memory of one FMU
/// output read, one C field read, and the FMU state's get, size, serialize
/// and deserialize. `cargo test --release --test boundary -- --ignored
/// --nocapture`; about a minute on two cores, 4 GB. `MI_BOUNDARY_RADIAL`,
/// `MI_BOUNDARY_LENGTH` and `MI_BOUNDARY_TIME` choose another rod and the
/// time of the first communication step (one solver step by default).
/// Asserted: every output read allocates at most 16 bytes and 8 a value
/// read, whatever the size, a C field read no more than the field asked
/// for, and the state round-trips; the times
/// are printed for BENCHMARKS.md (a benchmark, not a timed test).
#[test]
#[ignore = "heavy: about a minute and 4 GB; scripts/validate.sh"]
fn figures_at_a_million_particles() {
    let pr = std::env::var("MI_BOUNDARY_RADIAL")
        .map(|s| s.parse().unwrap())
        .unwrap_or(200);
    let length = std::env::var("MI_BOUNDARY_LENGTH")
        .map(|s| s.parse().unwrap())
        .unwrap_or(0.0954);
    let time = std::env::var("MI_BOUNDARY_TIME")
        .map(|s| s.parse().unwrap())
        .unwrap_or(1e-12);
    /// Wall time, bytes allocated and extra peak live bytes of `f`.
    fn measure<R>(what: &str, f: impl FnOnce() -> R) -> R {
        measured(what, f).1
    }
    /// As `measure`, with the bytes allocated.
    fn measured<R>(what: &str, f: impl FnOnce() -> R) -> (usize, R) {
        let live = LIVE.load(Relaxed);
        PEAK.store(live, Relaxed);
        let t = Instant::now();
        let (bytes, r) = allocated_by(f);
        let dt = t.elapsed();
        let peak = PEAK.load(Relaxed) - live;
        println!(
            "| {what} | {:.3} ms | {bytes} | {peak} |",
            dt.as_secs_f64() * 1e3
        );
        (bytes, r)
    }
    /// The boundary's claim (BENCHMARKS.md, "Boundaries at 10^6
    /// particles"): a read allocates a few bytes a value read whatever the
    /// number of particles (measured 8 bytes a value for an output read,
    /// 96 for all 12 outputs), where a copy of the particles would take
    /// megabytes; a C field read makes the field asked for once (8 MB for
    /// `density` at 10^6 particles) and no more.
    const READ_BYTES: usize = 16;
    const READ_BYTES_A_VALUE: usize = 8;
    println!("particles_radial = {pr}, initial_length = {length} m, first step to {time} s");
    println!("| operation | wall time | bytes allocated (this thread) | extra peak live bytes |");
    println!("|---|---|---|---|");
    let inst = measure("FMU: instantiate, initialize, first step", || {
        fmu_at(pr, length, time)
    });
    let all = float_outputs();
    let tail = [vr("tail_velocity")];
    let rod = [vr("rod_length")];
    for (what, refs) in [
        (
            "fmi3GetFloat64 tail_velocity (first read after the step)",
            &tail[..],
        ),
        ("fmi3GetFloat64 tail_velocity (again)", &tail[..]),
        ("fmi3GetFloat64 rod_length (first read)", &rod[..]),
        ("fmi3GetFloat64 all 12 Float64 outputs", &all[..]),
        ("fmi3GetFloat64 all 12 Float64 outputs (again)", &all[..]),
    ] {
        let mut out = vec![0.0; refs.len()];
        // SAFETY: a live instance; arrays of the lengths given.
        let (bytes, status) = measured(what, || unsafe {
            fmi3GetFloat64(inst, refs.as_ptr(), refs.len(), out.as_mut_ptr(), out.len())
        });
        assert_eq!(status, 0);
        assert!(out.iter().all(|x| x.is_finite()), "{what}: {out:?}");
        assert!(
            bytes <= READ_BYTES + READ_BYTES_A_VALUE * refs.len(),
            "{what}: {bytes} bytes allocated"
        );
    }
    let mut state = null_mut();
    let mut size = 0;
    // SAFETY: a live instance; the states freed once.
    unsafe {
        measure("fmi3GetFMUState", || fmi3GetFMUState(inst, &mut state));
        measure("fmi3SerializedFMUStateSize", || {
            fmi3SerializedFMUStateSize(inst, state, &mut size)
        });
        let mut data = vec![0u8; size];
        let status = measure("fmi3SerializeFMUState", || {
            fmi3SerializeFMUState(inst, state, data.as_mut_ptr(), size)
        });
        assert_eq!(status, 0);
        println!("serialized FMU state: {size} bytes");
        let mut back = null_mut();
        let status = measure("fmi3DeserializeFMUState (checks included)", || {
            fmi3DeserializeFMUState(inst, data.as_ptr(), size, &mut back)
        });
        assert_eq!(status, 0);
        assert_eq!(fmi3FreeFMUState(inst, &mut back), 0);
        assert_eq!(fmi3FreeFMUState(inst, &mut state), 0);
        fmi3FreeInstance(inst);
    }
    let (sim, n) = measure("C ABI: create, one step", || {
        stepped_capi(pr as f64, length)
    });
    if time > 1e-12 {
        // SAFETY: a live handle.
        let r = unsafe { mi_sim_advance_to(sim, time) };
        assert_eq!(r, mi_result::MI_OK);
    }
    println!("particles: {n}");
    for (name, components) in [("density", 1), ("stress", 4)] {
        let len = components * n;
        let mut buf = vec![0.0; len];
        let c = CString::new(name).unwrap();
        let mut needed = 0;
        let (bytes, r) = measured(
            &format!("mi_sim_field {name} (into the caller's buffer)"),
            || {
                // SAFETY: a live handle; a buffer of `len` doubles.
                unsafe { mi_sim_field(sim, c.as_ptr(), buf.as_mut_ptr(), len, &mut needed) }
            },
        );
        assert_eq!(r, mi_result::MI_OK);
        // The field asked for is made once (8 bytes a value), never a
        // snapshot of every field (13 doubles a particle).
        assert!(
            bytes <= READ_BYTES + 8 * len,
            "mi_sim_field {name}: {bytes} bytes for {len} values"
        );
    }
    let mut needed = 0;
    // SAFETY: a live handle, freed once.
    unsafe {
        measure("mi_sim_state_save size query (JSON)", || {
            mi_sim_state_save(sim, null_mut(), 0, &mut needed)
        });
        println!("C ABI saved state (JSON): {needed} bytes");
        mi_sim_free(sim);
    }
}
