//! Reading a run: time and status, observables (now and as histories),
//! particle fields, and the saved state.

use super::error::{Fail, mi_result};
use super::handle::{FieldMeta, index_error, mi_sim};
use super::panic::{get_into, with_sim};
use super::ptr::{check_buf, copy_out, need_out, put, room_for, text};
use crate::ffi::slice;
use crate::sim::Simulation;
use std::ffi::{CString, c_char};

/// Writes the simulated time (s) to `*time`.
///
/// # Safety
/// `sim` must be NULL or a live handle; `time` NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_time(sim: *mut mi_sim, time: *mut f64) -> mi_result {
    // SAFETY: forwarded contract on `time`.
    unsafe { get_into(sim, time, "time", |s| Ok(s.sim()?.time())) }
}

/// Writes the latest time the run may reach (the scene's `end_time`, s).
///
/// # Safety
/// `sim` must be NULL or a live handle; `time` NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_end_time(sim: *mut mi_sim, time: *mut f64) -> mi_result {
    // SAFETY: forwarded contract on `time`.
    unsafe { get_into(sim, time, "time", |s| Ok(s.sim()?.end_time())) }
}

/// Writes the number of steps taken.
///
/// # Safety
/// `sim` must be NULL or a live handle; `steps` NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_steps(sim: *mut mi_sim, steps: *mut u64) -> mi_result {
    // SAFETY: forwarded contract on `steps`.
    unsafe { get_into(sim, steps, "steps", |s| Ok(s.sim()?.steps())) }
}

/// Writes the number of particles.
///
/// # Safety
/// `sim` must be NULL or a live handle; `count` NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_particle_count(sim: *mut mi_sim, count: *mut usize) -> mi_result {
    // SAFETY: forwarded contract on `count`.
    unsafe { get_into(sim, count, "count", |s| Ok(s.sim()?.particles())) }
}

/// Writes whether the run has ended (end condition, solver stop or cancel).
///
/// # Safety
/// `sim` must be NULL or a live handle; `finished` NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_finished(sim: *mut mi_sim, finished: *mut bool) -> mi_result {
    // SAFETY: forwarded contract on `finished`.
    unsafe { get_into(sim, finished, "finished", |s| s.finished()) }
}

/// One observable of a scene. The strings belong to the handle and stay valid
/// until `mi_sim_free` (or `mi_sim_load_toml`).
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct mi_observable_info {
    /// Name, as used by `mi_sim_observable` and `mi_sim_history`.
    pub name: *const c_char,
    /// SI unit (`"1"` for dimensionless, `"bool"` for a 0/1 flag).
    pub unit: *const c_char,
    /// Meaning.
    pub description: *const c_char,
    /// Whether the value is a flag (0 or 1).
    pub is_bool: bool,
}

/// Writes the number of observables of the handle's scene.
///
/// # Safety
/// `sim` must be NULL or a live handle; `count` NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_observable_count(sim: *mut mi_sim, count: *mut usize) -> mi_result {
    // SAFETY: forwarded contract on `count`.
    unsafe {
        get_into(sim, count, "count", |s| {
            Ok(s.kind().observable_specs().len())
        })
    }
}

/// Describes the observable at `index` (0 .. count-1; else
/// `MI_OUT_OF_RANGE`). The order is the order of `mi_sim_observables`.
///
/// # Safety
/// `sim` must be NULL or a live handle; `info` NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_observable_info(
    sim: *mut mi_sim,
    index: usize,
    info: *mut mi_observable_info,
) -> mi_result {
    // SAFETY: forwarded contract on `info`.
    unsafe {
        get_into(sim, info, "info", |s| {
            let specs = s.kind().observable_specs();
            let (Some(o), Some(names)) = (specs.get(index), s.meta.observables.get(index)) else {
                return Err(index_error("observable", index, specs.len()));
            };
            Ok(mi_observable_info {
                name: names[0].as_ptr(),
                unit: names[1].as_ptr(),
                description: names[2].as_ptr(),
                is_bool: o.is_bool(),
            })
        })
    }
}

fn observable_index(s: &mi_sim, name: &str) -> Result<usize, Fail> {
    let specs = s.kind().observable_specs();
    specs.iter().position(|o| o.name == name).ok_or_else(|| {
        Fail::new(
            mi_result::MI_UNKNOWN_OBSERVABLE,
            format!(
                "unknown observable `{name}` for scene `{}`; allowed: {}",
                s.kind().name(),
                specs.iter().map(|o| o.name).collect::<Vec<_>>().join(", ")
            ),
        )
    })
}

/// Writes the current value of the observable `name` (flags as 0 or 1).
///
/// # Safety
/// `sim` must be NULL or a live handle; `name` NULL or a NUL-terminated
/// string; `value` NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_observable(
    sim: *mut mi_sim,
    name: *const c_char,
    value: *mut f64,
) -> mi_result {
    with_sim(sim, |s| {
        // SAFETY: forwarded contract on `name`.
        let n = unsafe { text(name, "name") }?;
        need_out(value, "value")?;
        let k = observable_index(s, n)?;
        let v = s
            .sim()?
            .observable_at(k)
            .expect("an observable of the table");
        // SAFETY: forwarded contract on `value`.
        unsafe { put(value, v, "value") }
    })
}

/// Copies the current values of every observable, in `mi_sim_observable_info`
/// order, by the buffer convention (lengths in doubles).
///
/// # Safety
/// `sim` must be NULL or a live handle; `buf` NULL or valid for `len`
/// doubles; `needed` NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_observables(
    sim: *mut mi_sim,
    buf: *mut f64,
    len: usize,
    needed: *mut usize,
) -> mi_result {
    with_sim(sim, |s| {
        check_buf(buf, len, "buf")?;
        let v = s.sim()?.observables();
        // SAFETY: forwarded contract on `buf`, `len`, `needed`.
        unsafe { copy_out(&v, buf, len, needed, "buf") }
    })
}

/// Writes the number of recorded history rows (times). The history holds the
/// initial state, about 64 records per elastic transit of the rod (Taylor) or
/// 600 per run (Noh), and the final state.
///
/// # Safety
/// `sim` must be NULL or a live handle; `rows` NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_history_len(sim: *mut mi_sim, rows: *mut usize) -> mi_result {
    // SAFETY: forwarded contract on `rows`.
    unsafe { get_into(sim, rows, "rows", |s| Ok(s.sim()?.history().len())) }
}

/// Copies the recorded times (s) by the buffer convention.
///
/// # Safety
/// As `mi_sim_observables`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_history_times(
    sim: *mut mi_sim,
    buf: *mut f64,
    len: usize,
    needed: *mut usize,
) -> mi_result {
    with_sim(sim, |s| {
        check_buf(buf, len, "buf")?;
        let h = s.sim()?.history();
        // SAFETY: forwarded contract on `buf`, `len`, `needed`.
        unsafe { copy_out(&h.times, buf, len, needed, "buf") }
    })
}

/// Copies the recorded values of the observable `name`, one per recorded
/// time (as `mi_sim_history_times`), by the buffer convention.
///
/// # Safety
/// As `mi_sim_observables`; `name` NULL or a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_history(
    sim: *mut mi_sim,
    name: *const c_char,
    buf: *mut f64,
    len: usize,
    needed: *mut usize,
) -> mi_result {
    with_sim(sim, |s| {
        // SAFETY: forwarded contract on `name`.
        let n = unsafe { text(name, "name") }?;
        check_buf(buf, len, "buf")?;
        let k = observable_index(s, n)?;
        let h = s.sim()?.history();
        let column: Vec<f64> = (0..h.len()).map(|r| h.row(r)[k]).collect();
        // SAFETY: forwarded contract on `buf`, `len`, `needed`.
        unsafe { copy_out(&column, buf, len, needed, "buf") }
    })
}

/// One particle field. The strings belong to the handle and stay valid until
/// `mi_sim_free` (or `mi_sim_load_toml`).
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct mi_field_info {
    /// Name, as used by `mi_sim_field` (`"position"`, `"velocity"`, ...).
    pub name: *const c_char,
    /// SI unit.
    pub unit: *const c_char,
    /// Values per particle.
    pub components: usize,
    /// `components` names of the components, in storage order (for example
    /// `"R"`, `"Z"`).
    pub component_names: *const *const c_char,
}

fn field_meta(s: &mut mi_sim) -> Result<&[FieldMeta], Fail> {
    if s.meta.fields.is_none() {
        let specs = s.sim()?.field_specs();
        s.meta.fields = Some(
            specs
                .iter()
                .map(|f| meta(f.name, f.unit, f.components))
                .collect(),
        );
    }
    Ok(s.meta.fields.as_deref().expect("set above"))
}

fn meta(name: &str, unit: &str, comps: &[&str]) -> FieldMeta {
    let c = |t: &str| CString::new(t).expect("library names hold no NUL");
    let components: Vec<CString> = comps.iter().map(|t| c(t)).collect();
    let component_ptrs = components.iter().map(|t| t.as_ptr()).collect();
    FieldMeta {
        name: c(name),
        unit: c(unit),
        components,
        component_ptrs,
    }
}

/// Writes the number of particle fields of the scene, `"position"` included.
///
/// # Safety
/// `sim` must be NULL or a live handle; `count` NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_field_count(sim: *mut mi_sim, count: *mut usize) -> mi_result {
    // SAFETY: forwarded contract on `count`.
    unsafe { get_into(sim, count, "count", |s| Ok(field_meta(s)?.len())) }
}

/// Describes the particle field at `index` (0 .. count-1; else
/// `MI_OUT_OF_RANGE`). Field 0 is `"position"` (R, Z in m); the others
/// depend on the scene (Taylor: density, velocity, pressure, stress,
/// plastic_strain, temperature, in_contact; Noh: density, velocity,
/// pressure, specific_energy).
///
/// # Safety
/// `sim` must be NULL or a live handle; `info` NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_field_info(
    sim: *mut mi_sim,
    index: usize,
    info: *mut mi_field_info,
) -> mi_result {
    // SAFETY: forwarded contract on `info`.
    unsafe {
        get_into(sim, info, "info", |s| {
            let fields = field_meta(s)?;
            let Some(f) = fields.get(index) else {
                return Err(index_error("field", index, fields.len()));
            };
            Ok(mi_field_info {
                name: f.name.as_ptr(),
                unit: f.unit.as_ptr(),
                components: f.components.len(),
                component_names: f.component_ptrs.as_ptr(),
            })
        })
    }
}

/// Copies the current values of the particle field `name` by the buffer
/// convention: `particles * components` doubles, interleaved per particle
/// (for `"stress"` of `taylor`: RR, ZZ, TT, RZ of particle 0, then of particle
/// 1, ...; of `taylor3d`: xx, yy, zz, xy, yz, zx; `mi_sim_field_info` names them).
/// Only this field is made (not the whole snapshot), and a size query
/// (`buf` NULL) or a buffer too small makes none.
///
/// # Safety
/// As `mi_sim_history`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_field(
    sim: *mut mi_sim,
    name: *const c_char,
    buf: *mut f64,
    len: usize,
    needed: *mut usize,
) -> mi_result {
    with_sim(sim, |s| {
        // SAFETY: forwarded contract on `name`.
        let n = unsafe { text(name, "name") }?;
        check_buf(buf, len, "buf")?;
        let sim = s.sim()?;
        let components = sim
            .field_specs()
            .iter()
            .find(|f| f.name == n)
            .map(|f| f.components.len());
        let Some(components) = components else {
            let names: Vec<String> = field_meta(s)?
                .iter()
                .map(|f| f.name.to_string_lossy().into_owned())
                .collect();
            return Err(Fail::new(
                mi_result::MI_UNKNOWN_FIELD,
                format!(
                    "unknown particle field `{n}` for scene `{}`; allowed: {}",
                    s.kind().name(),
                    names.join(", ")
                ),
            ));
        };
        // A size query or a buffer too small is answered without making the
        // field; otherwise only this field is made, and copied once.
        let sim = s.sim()?;
        let count = sim.particles() * components;
        // SAFETY: forwarded contract on `buf`, `len`, `needed`.
        if !unsafe { room_for(count, buf, len, needed, "buf") }? {
            return Ok(());
        }
        let v = sim.field(n).expect("a field of the run's field specs");
        // SAFETY: forwarded contract on `buf`, `len`, `needed`.
        unsafe { copy_out(&v, buf, len, needed, "buf") }
    })
}

/// Copies the complete state of the run (solver, history, scene) as bytes,
/// by the buffer convention, for hosts that save and roll back. The bytes are
/// read by `mi_sim_state_load`: they carry their format's number (JSON key
/// `format`, 2 today), and a build reads its own format and every older
/// one, and refuses a newer one with `MI_INVALID_STATE`. Every
/// state saved loads back, stopped or not; a run stopped on a non-finite
/// field has none to save, and returns its stop (`MI_NON_FINITE`, or
/// `MI_ENERGY_DRIFT` when its energy overflowed).
///
/// # Safety
/// `sim` must be NULL or a live handle; `buf` NULL or valid for `len` bytes;
/// `needed` NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_state_save(
    sim: *mut mi_sim,
    buf: *mut u8,
    len: usize,
    needed: *mut usize,
) -> mi_result {
    with_sim(sim, |s| {
        check_buf(buf, len, "buf")?;
        let sim = s.sim()?;
        sim.check_savable()?;
        let bytes = sim.serialize_state();
        // SAFETY: forwarded contract on `buf`, `len`, `needed`.
        unsafe { copy_out(&bytes, buf, len, needed, "buf") }
    })
}

/// Replaces the run by a state saved with `mi_sim_state_save` of the same
/// scene kind. The run then continues from the saved time, with the saved
/// parameters. Anything else is `MI_INVALID_STATE` and the handle keeps its
/// run: bytes that are not a state, a state of another scene kind, or a
/// forged or inconsistent one (checked as a new run is).
///
/// # Safety
/// `sim` must be NULL or a live handle; `buf` NULL or valid for reads of
/// `len` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_state_load(
    sim: *mut mi_sim,
    buf: *const u8,
    len: usize,
) -> mi_result {
    with_sim(sim, |s| {
        if buf.is_null() {
            return Err(super::ptr::null("buf"));
        }
        // SAFETY: `buf` is non-NULL and, by the contract, valid for `len` bytes.
        let bytes = unsafe { slice(buf, len) }.unwrap_or_default();
        let restored = Simulation::deserialize_state(bytes)?;
        if restored.kind() != s.kind() {
            return Err(Fail::new(
                mi_result::MI_INVALID_STATE,
                format!(
                    "the state is of scene kind `{}`, the handle of `{}`",
                    restored.kind(),
                    s.kind()
                ),
            ));
        }
        s.restore(restored);
        Ok(())
    })
}

/// Writes the whole run (state, histories, scene) to the checkpoint file
/// `path` (UTF-8): the file that `meshless-impact run --restart FILE`,
/// Python's `Simulation.load` and `mi_sim_checkpoint_load` continue, to
/// the bits of the run that was never stopped. The file is written whole:
/// a temporary file in the same folder is flushed to the disk and renamed
/// over `path`, so that a kill during the write leaves the previous
/// checkpoint. For checkpoints every N steps or seconds, call it between
/// `mi_sim_step`s. Codes: `MI_IO` (the folder is missing or not
/// writable), and the stops of `mi_sim_state_save`.
///
/// # Safety
/// `sim` must be NULL or a live handle; `path` NULL or a NUL-terminated
/// string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_checkpoint_save(
    sim: *mut mi_sim,
    path: *const c_char,
) -> mi_result {
    with_sim(sim, |s| {
        // SAFETY: forwarded contract on `path`.
        let p = unsafe { text(path, "path") }?;
        let sim = s.sim()?;
        crate::checkpoint::save(std::path::Path::new(p), sim, &serde_json::Value::Null)?;
        Ok(())
    })
}

/// Replaces the run by the one saved in the checkpoint file `path`
/// (`mi_sim_checkpoint_save`, or the program's `--checkpoint`), of the
/// same scene kind; it continues from there. A file that cannot be
/// continued is `MI_BAD_CHECKPOINT`, and the message
/// (`mi_sim_last_error`) says which fault: not a checkpoint, truncated,
/// corrupted (its CRC-32 or length disagrees), of a newer format; a
/// checkpoint of another scene kind, or whose state is not one its scene
/// reaches, is `MI_INVALID_STATE`; an unreadable file `MI_IO`. On failure
/// the handle keeps its run.
///
/// # Safety
/// `sim` must be NULL or a live handle; `path` NULL or a NUL-terminated
/// string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mi_sim_checkpoint_load(
    sim: *mut mi_sim,
    path: *const c_char,
) -> mi_result {
    with_sim(sim, |s| {
        // SAFETY: forwarded contract on `path`.
        let p = unsafe { text(path, "path") }?;
        let (restored, _) = crate::checkpoint::load(std::path::Path::new(p))?;
        if restored.kind() != s.kind() {
            return Err(Fail::new(
                mi_result::MI_INVALID_STATE,
                format!(
                    "the checkpoint {p} is of scene kind `{}`, the handle of `{}`",
                    restored.kind(),
                    s.kind()
                ),
            ));
        }
        s.restore(restored);
        Ok(())
    })
}
