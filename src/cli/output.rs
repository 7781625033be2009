//! The files a command writes, and the checks before a run that they can
//! be written.

use super::stop::Stop;
use meshless_impact::{Error, Simulation};
use std::fs::{File, OpenOptions};
use std::io::ErrorKind;
use std::path::Path;

/// The rod's outline as CSV, written whole (`z_m,r_m`, one row per point of the mantle's
/// generator, from the impact face up).
pub(crate) fn write_profile(path: &std::path::Path, sim: &Simulation) -> Result<(), Error> {
    use std::fmt::Write as _;
    let mut text = String::from("z_m,r_m\n");
    for [z, r] in sim.rod_profile().unwrap_or_default() {
        let _ = writeln!(text, "{z:e},{r:e}");
    }
    meshless_impact::files::write_whole_bytes(path, text.as_bytes())
}

/// Checks before a run that `path`, given to `option`, can be written: its
/// directory exists and the file opens for writing. Nothing that exists is
/// changed: an existing file is opened without truncating it, and a file
/// created for the test is removed again.
pub(crate) fn check_output_file(option: &str, path: &Path) -> Result<(), Stop> {
    let fail = |why: String| Stop::failed(format!("{option} {}: {why}", path.display()));
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    match std::fs::metadata(dir) {
        Err(e) if e.kind() == ErrorKind::NotFound => {
            return Err(fail(format!("directory {} does not exist", dir.display())));
        }
        Err(e) => return Err(fail(format!("directory {}: {e}", dir.display()))),
        Ok(m) if !m.is_dir() => {
            return Err(fail(format!("{} is not a directory", dir.display())));
        }
        Ok(_) => {}
    }
    if path.is_dir() {
        return Err(fail("is a directory".into()));
    }
    if path.exists() {
        OpenOptions::new()
            .write(true)
            .open(path)
            .map_err(|e| fail(e.to_string()))?;
    } else {
        File::create_new(path).map_err(|e| fail(e.to_string()))?;
        std::fs::remove_file(path).map_err(|e| fail(e.to_string()))?;
    }
    Ok(())
}

/// Creates the output directory `dir` of `option` before a run and checks
/// that `file`, one of the files the run writes there, can be written.
pub(crate) fn check_output_dir(option: &str, dir: &Path, file: &str) -> Result<(), Stop> {
    std::fs::create_dir_all(dir).map_err(|e| {
        Stop::failed(format!(
            "{option} {}: cannot create the directory: {e}",
            dir.display()
        ))
    })?;
    check_output_file(option, &dir.join(file))
}

/// Writes a CSV file of `header` and `records`, whole.
pub(crate) fn write_csv_records(
    out: &Path,
    header: &[&str],
    records: &[Vec<String>],
) -> Result<(), Error> {
    meshless_impact::files::write_whole(out, |o| {
        let mut w = csv::Writer::from_writer(o);
        w.write_record(header)?;
        for rec in records {
            w.write_record(rec)?;
        }
        w.flush()
    })
}

/// Final values of a run as a JSON object: every observable by name, plus
/// `particles`, `steps`, `end_time`, `wall_time_s`, and `outcome`:
/// `"finished"`, or the name of the error that stopped the run, whose
/// message is then `error` (the values are those of the state at the stop,
/// outside the solver's domain of validity). The scene's references of the
/// observables follow as objects by observable name: `reference`, or, where
/// the scene has a converged continuum reference beside the experiment's
/// (test 7), `reference_continuum` and `reference_experiment`.
pub(crate) fn final_json(
    sim: &Simulation,
    wall_time_s: f64,
    stopped: Option<&Error>,
) -> serde_json::Value {
    let (scene, specs, values) = (sim.scene(), sim.observable_specs(), sim.observables());
    let (particles, steps, end_time) = (sim.particles(), sim.steps(), sim.time());
    let mut m = serde_json::Map::new();
    for (s, v) in specs.iter().zip(&values) {
        let val = if s.is_bool() {
            serde_json::Value::Bool(*v != 0.0)
        } else {
            serde_json::json!(v)
        };
        m.insert(s.name.to_string(), val);
    }
    m.insert("particles".into(), particles.into());
    m.insert("steps".into(), steps.into());
    m.insert("end_time".into(), serde_json::json!(end_time));
    m.insert("wall_time_s".into(), serde_json::json!(wall_time_s));
    m.insert(
        "outcome".into(),
        stopped.map_or("finished", Error::name).into(),
    );
    if let Some(e) = stopped {
        m.insert("error".into(), e.to_string().into());
    }
    let of = |get: &dyn Fn(&str) -> Option<f64>| -> serde_json::Map<String, serde_json::Value> {
        specs
            .iter()
            .filter_map(|s| get(s.name).map(|r| (s.name.to_string(), serde_json::json!(r))))
            .collect()
    };
    let primary = of(&|name| scene.reference_of(name));
    if scene.has_continuum_reference() {
        let continuum = of(&|name| scene.continuum_reference_of(name));
        m.insert("reference_continuum".into(), continuum.into());
        m.insert("reference_experiment".into(), primary.into());
    } else if !primary.is_empty() {
        m.insert("reference".into(), primary.into());
    }
    serde_json::Value::Object(m)
}

/// Writes a JSON value to a file, pretty-printed, whole.
pub(crate) fn write_json(path: &Path, value: &serde_json::Value) -> Result<(), Error> {
    meshless_impact::files::write_whole(path, |f| {
        serde_json::to_writer_pretty(&mut *f, value)?;
        writeln!(f)
    })
}
