//! `meshless-impact run`: one scene to its end condition, with its
//! snapshots, histories and final values, and the summary on stdout.

use super::args::{RunArgs, apply_sets};
use super::output::{check_output_dir, check_output_file, final_json, write_json, write_profile};
use super::stop::{Stop, outcome, outln};
use indicatif::{ProgressBar, ProgressStyle};
use meshless_impact::{Error, Isa, Scene, Simulation};
use std::io::{IsTerminal, Write};
use std::time::{Duration, Instant};

pub(crate) fn fmt_duration(s: f64) -> String {
    if s < 1e-3 {
        format!("{:.2} us", s * 1e6)
    } else {
        format!("{s:.4} s")
    }
}

pub(crate) fn run(a: RunArgs) -> Result<(), Stop> {
    let mut scene = match &a.scene_file {
        Some(f) => Scene::from_file(f)?,
        None => Scene::builtin(&a.scene)?,
    };
    a.material.apply(&mut scene)?;
    apply_sets(&mut scene, &a.set)?;
    let mut sim = Simulation::new(scene)?;
    if let Some(name) = &a.isa {
        sim.set_isa(Isa::named(name).map_err(|e| Stop::failed(format!("--isa: {e}")))?);
    }
    let end_time = sim.end_time();
    // Every output is checked before the run, so that a typo does not cost
    // the results of a long run.
    let vtk_times = check_vtk_times(&a.vtk_times, end_time)?;
    if let Some(path) = &a.json {
        check_output_file("--json", path)?;
    }
    if let Some(path) = &a.csv {
        check_output_file("--csv", path)?;
    }
    if let Some(path) = &a.profile {
        check_output_file("--profile", path)?;
        if sim.rod_profile().is_none() {
            return Err(Stop::failed(format!(
                "--profile: scene `{}` has no rod to outline",
                sim.kind().name()
            )));
        }
    }
    if let Some(dir) = &a.vtk_dir {
        check_output_dir("--vtk-dir", dir, "particles.pvd")?;
    }
    let mut next_vtk = 0usize;
    // (time, file name) of the snapshots written so far; the collection
    // `particles.pvd` is rewritten after each one, so it is whole even when a
    // run stops early.
    let mut vtk_written: Vec<(f64, String)> = Vec::new();
    let write_vtk = |sim: &Simulation, written: &mut Vec<(f64, String)>| -> Result<(), Error> {
        if let Some(dir) = &a.vtk_dir {
            let name = format!("particles_{:04}.vtu", written.len());
            sim.snapshot().write_vtu(&dir.join(&name))?;
            written.push((sim.time(), name));
            meshless_impact::write_pvd(&dir.join("particles.pvd"), written)?;
        }
        Ok(())
    };
    // The first snapshot failure, reported after the run.
    let mut vtk_error = None;
    if a.vtk_dir.is_some() && vtk_times.first().is_some_and(|&t| t <= 0.0) {
        if let Err(e) = write_vtk(&sim, &mut vtk_written) {
            vtk_error = Some(e);
        }
        next_vtk = vtk_times.iter().take_while(|&&t| t <= 0.0).count();
    }

    let start = Instant::now();
    let show_bar = !a.quiet && std::io::stderr().is_terminal();
    let mut bar: Option<ProgressBar> = None;
    let mut last_draw = Instant::now();
    // Snapshots need the state between steps, so the loop is written out here.
    let mut status = Ok(());
    // The whole loop runs on a worker of the thread pool, so a step does not
    // wake a worker from this thread and wait to be woken in turn.
    rayon::scope(|_| {
        while !sim.finished() {
            if let Err(e) = sim.step() {
                status = Err(e);
                break;
            }
            while next_vtk < vtk_times.len() && sim.time() >= vtk_times[next_vtk] {
                if let Err(e) = write_vtk(&sim, &mut vtk_written) {
                    vtk_error.get_or_insert(e);
                }
                next_vtk += 1;
            }
            if show_bar
                && start.elapsed() > Duration::from_secs(1)
                && last_draw.elapsed() > Duration::from_millis(100)
            {
                let b = bar.get_or_insert_with(|| {
                    let b = ProgressBar::new(1000);
                    b.set_style(
                        ProgressStyle::with_template(
                            "{spinner} [{elapsed_precise}] {bar:30} {msg}",
                        )
                        .expect("valid template"),
                    );
                    b
                });
                b.set_position(((sim.time() / end_time) * 1000.0) as u64);
                b.set_message(format!(
                    "t = {}, {} steps, {} particles",
                    fmt_duration(sim.time()),
                    sim.steps(),
                    sim.particles()
                ));
                last_draw = Instant::now();
            }
        }
    });
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let wall = start.elapsed().as_secs_f64();

    // Every output is written, even when the run stopped early or another
    // output failed; the failures are reported together at the end.
    let mut failures = Vec::new();
    if let Err(e) = &status {
        failures.push(e.to_string());
    }
    if let Err(e) = write_vtk(&sim, &mut vtk_written) {
        vtk_error.get_or_insert(e);
    }
    if let Some(e) = vtk_error {
        failures.push(format!("--vtk-dir: {e}"));
    }
    if let Some(path) = &a.csv
        && let Err(e) = sim.history().write_csv(path)
    {
        failures.push(format!("--csv: {e}"));
    }
    if let Some(path) = &a.profile
        && let Err(e) = write_profile(path, &sim)
    {
        failures.push(format!("--profile: {e}"));
    }
    if let Some(path) = &a.json {
        let json = final_json(&sim, wall, status.as_ref().err());
        if let Err(e) = write_json(path, &json) {
            failures.push(format!("--json: {e}"));
        }
    }
    let printed = if a.quiet {
        Ok(())
    } else {
        print_summary(&sim, wall)
    };
    outcome(failures, printed)
}

/// The snapshot times of `--vtk-times`, sorted. Each must be finite and
/// between 0 and the scene's `end_time`: a time outside never comes.
fn check_vtk_times(times: &[f64], end_time: f64) -> Result<Vec<f64>, Stop> {
    if let Some(t) = times.iter().find(|t| !(0.0..=end_time).contains(*t)) {
        return Err(Stop::failed(format!(
            "--vtk-times: {t:e} s is out of range: allowed [0, {end_time:e}] s \
             (0 to the scene's end_time)"
        )));
    }
    let mut sorted = times.to_vec();
    sorted.sort_by(f64::total_cmp);
    Ok(sorted)
}

/// What the two columns of references mean, printed under a table that
/// has both.
const CONTINUUM_NOTE: &str = "continuum: the converged solution with the scene's material constants \
(LS-DYNA, Batra & Zhang 2008), which the default scheme converges to; experiment: House et al. (1995). \
They differ because the constants come from other tests (docs/guide/materials.md).";

fn print_summary(sim: &Simulation, wall: f64) -> Result<(), Stop> {
    outln!("scene: {}", sim.scene().title)?;
    outln!(
        "particles {}, steps {}, end time {}, wall time {:.2} s",
        sim.particles(),
        sim.steps(),
        fmt_duration(sim.time()),
        wall
    )?;
    if let Some(e) = sim.error() {
        outln!("stopped early: {e}")?;
    }
    let scene = sim.scene();
    let both = scene.has_continuum_reference();
    let against = |r: Option<f64>, v: f64| match r {
        Some(r) if r != 0.0 => (format!("{r:.6}"), format!("{:+.2}%", 100.0 * (v - r) / r)),
        _ => (String::new(), String::new()),
    };
    if both {
        outln!(
            "{:<24} {:>14} {:>14} {:>9} {:>14} {:>9}  unit",
            "observable",
            "value",
            "continuum",
            "error",
            "experiment",
            "error"
        )?;
    } else {
        outln!(
            "{:<24} {:>14} {:>14} {:>9}  unit",
            "observable",
            "value",
            "reference",
            "error"
        )?;
    }
    for (s, v) in sim.observable_specs().iter().zip(sim.observables()) {
        let (r, e) = against(scene.reference_of(s.name), v);
        let val = if s.is_bool() {
            (v != 0.0).to_string()
        } else {
            format!("{v:.6}")
        };
        if both {
            let (c, ce) = against(scene.continuum_reference_of(s.name), v);
            outln!(
                "{:<24} {:>14} {:>14} {:>9} {:>14} {:>9}  {}",
                s.name,
                val,
                c,
                ce,
                r,
                e,
                s.unit
            )?;
        } else {
            outln!("{:<24} {:>14} {:>14} {:>9}  {}", s.name, val, r, e, s.unit)?;
        }
    }
    if both {
        outln!("{CONTINUUM_NOTE}")?;
    }
    Ok(())
}
