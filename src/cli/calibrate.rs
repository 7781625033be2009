//! `meshless-impact calibrate`: fits named parameters of a scene to the
//! measured observables of a set of experiments, and writes the answer
//! (`calibration.json`), the calibrated material (`material.toml`) and a
//! picture of the fit (`fit.svg`).

use super::args::{CalibrateArgs, apply_sets};
use super::output::{check_output_dir, check_output_file, write_json};
use super::stop::{Stop, outcome, outln};
use indicatif::{ProgressBar, ProgressStyle};
use meshless_impact::calibrate::{
    Calibration, CalibrationResult, Event, Free, LeaveOneOutMethod, Options, Outcome, read_shots,
};
use meshless_impact::{Error, Scene};
use std::io::{IsTerminal, Write};
use std::path::Path;

pub(crate) fn calibrate(a: CalibrateArgs) -> Result<(), Stop> {
    let mut scene = match &a.scene_file {
        Some(f) => Scene::from_file(f)?,
        None => Scene::builtin(&a.scene)?,
    };
    a.material.apply(&mut scene)?;
    apply_sets(&mut scene, &a.set)?;
    let shots = read_shots(&a.shots, &scene)?;
    let mut free = Vec::new();
    for text in &a.free {
        let f = Free::parse(text, &scene)?;
        if let Some(s) = a
            .set
            .iter()
            .find(|s| s.split('=').next().map(str::trim) == Some(&f.name))
        {
            return Err(Stop::failed(format!(
                "`{}` is both free (--free {text}) and fixed (--set {s})",
                f.name
            )));
        }
        free.push(f);
    }
    let coarse = match &a.coarse {
        Some(text) => {
            let (name, value) = text.split_once('=').ok_or_else(|| Error::ParseValue {
                name: "--coarse".into(),
                text: format!("{text}: expected NAME=VALUE, for example particles_radial=10"),
            })?;
            let v = scene.spec(name.trim())?.parse(value)?;
            Some((name.trim().to_string(), v))
        }
        None => None,
    };
    let options = Options {
        max_runs: a.max_runs,
        max_wall_s: a.max_wall,
        coarse,
        fd_step: a.fd_step,
        xtol: a.xtol,
        broyden: a.method == "broyden",
        leave_one_out: a
            .leave_one_out
            .as_deref()
            .map(LeaveOneOutMethod::named)
            .transpose()?,
    };
    let problem = Calibration::new(scene, free, shots, options)?;
    for file in ["calibration.json", "material.toml"]
        .into_iter()
        .chain(cfg!(feature = "report").then_some("fit.svg"))
    {
        check_output_dir("--out", &a.out, file)?;
        check_output_file("--out", &a.out.join(file))?;
    }

    let bar = (!a.quiet && std::io::stderr().is_terminal()).then(|| {
        let b = ProgressBar::new(a.max_runs as u64);
        b.set_style(
            ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} runs {msg}",
            )
            .expect("valid template"),
        );
        b
    });
    let quiet = a.quiet;
    let say = |line: String| {
        if quiet {
            return;
        }
        match &bar {
            Some(b) => b.println(line),
            // A progress line that cannot be written is not worth stopping
            // the fit for; the summary's write is checked.
            None => {
                let _ = writeln!(std::io::stdout(), "{line}");
            }
        }
    };
    let on_event = |e: &Event| match e {
        Event::Stage(name) => say(format!("stage: {name}")),
        Event::Batch { runs } => {
            if let Some(b) = &bar {
                b.set_message(format!("(batch of {runs})"));
            }
        }
        Event::RunDone => {
            if let Some(b) = &bar {
                b.inc(1);
            }
        }
        Event::Iteration(it) => say(format!(
            "{:>6} {:>3}: objective {:.6e}, lambda {:.1e}, {}{}{} runs {}, {:.1} s",
            it.stage,
            it.number,
            it.objective,
            it.lambda,
            if it.accepted {
                "step taken"
            } else {
                "step refused"
            },
            if it.failed { " (a run failed)" } else { "" },
            if it.jacobian {
                ", Jacobian taken;"
            } else {
                ";"
            },
            it.runs,
            it.wall_s
        )),
    };
    let result = problem.run(&on_event)?;
    if let Some(b) = &bar {
        b.finish_and_clear();
    }

    let mut failures = Vec::new();
    if let Err(e) = write_json(&a.out.join("calibration.json"), &result.to_json()) {
        failures.push(format!("--out: {e}"));
    }
    let material = material_file(&result, &a);
    let path = a.out.join("material.toml");
    if let Err(e) = meshless_impact::files::write_whole_bytes(&path, material.as_bytes()) {
        failures.push(format!("--out: {e}"));
    }
    if let Err(e) = figure(&a.out.join("fit.svg"), &result) {
        failures.push(format!("--out: {e}"));
    }
    let printed = summary(&result, &a.out);
    match result.outcome {
        Outcome::RunCap => failures.push(format!(
            "the fit reached its cap of {} forward runs (--max-runs) before it converged; \
             the best point so far is written",
            result.options.max_runs
        )),
        Outcome::WallCap => failures.push(format!(
            "the fit reached its cap of {} s of wall time (--max-wall) before it converged; \
             the best point so far is written",
            result.options.max_wall_s
        )),
        _ => {}
    }
    outcome(failures, printed)
}

/// The material file: a comment that says where it came from, then the
/// calibrated `[material]` table.
fn material_file(r: &CalibrationResult, a: &CalibrateArgs) -> String {
    let mut out = format!(
        "# Calibrated by `meshless-impact calibrate {}` on {} ({} experiments, outcome {}).\n\
         # Use it as it is: `meshless-impact run --preset-file material.toml ...`, or as a scene file's\n\
         # [material] table. Fitted: {}.\n",
        a.scene_file
            .as_ref()
            .map_or(a.scene.clone(), |f| format!("--scene-file {}", f.display())),
        a.shots.display(),
        r.shots.len(),
        r.outcome.name(),
        r.free
            .iter()
            .zip(&r.parameters)
            .zip(&r.std)
            .map(|((f, v), s)| match s {
                Some(s) => format!("{} = {v:e} +- {s:.2e}", f.name),
                None => format!("{} = {v:e} (undetermined)", f.name),
            })
            .collect::<Vec<_>>()
            .join(", ")
    );
    if !a.set.is_empty() || a.material.scheme.is_some() {
        out += &format!(
            "# The fit's fixed part also had: {}{}\n",
            a.material
                .scheme
                .as_ref()
                .map_or(String::new(), |s| format!("--scheme {s} ")),
            a.set
                .iter()
                .map(|s| format!("--set {s}"))
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
    out + &r.material_toml
}

/// The table of the fitted parameters and of the errors before and after.
fn summary(r: &CalibrationResult, out: &Path) -> Result<(), Stop> {
    outln!(
        "calibration of `{}` on {} experiments ({} measurements): {}",
        r.scene,
        r.shots.len(),
        r.shots.iter().map(|s| s.measurements()).sum::<usize>(),
        r.outcome.name()
    )?;
    outln!(
        "{:<24} {:>14} {:>14} {:>12} {:>8}  determined by the data",
        "parameter",
        "start",
        "fitted",
        "std",
        "std %"
    )?;
    for (k, f) in r.free.iter().enumerate() {
        let (v, std) = (r.parameters[k], r.std[k]);
        let ident = match &r.identifiable[k] {
            Ok(()) => "yes".to_string(),
            Err(why) => format!("NO: {why}"),
        };
        let fitted = if r.identifiable[k].is_ok() {
            format!("{v:.6e}")
        } else {
            format!("({v:.4e})")
        };
        outln!(
            "{:<24} {:>14.6e} {:>14} {:>12} {:>8}  {ident}",
            f.name,
            r.start[k],
            fitted,
            std.map_or("-".into(), |s| format!("{s:.3e}")),
            std.map_or("-".into(), |s| format!("{:.2}", 100.0 * s / v.abs())),
        )?;
    }
    // Mean |relative error| per observable, before and after.
    let mut names: Vec<&str> = Vec::new();
    for s in &r.shots {
        for m in &s.observed {
            if !names.contains(&m.name.as_str()) {
                names.push(&m.name);
            }
        }
    }
    for name in names {
        let errs = |values: &[meshless_impact::calibrate::ShotValues]| {
            let e: Vec<f64> = r
                .shots
                .iter()
                .zip(values)
                .filter_map(|(s, v)| {
                    let k = s.observed.iter().position(|m| m.name == name)?;
                    Some(100.0 * (v.values[k] - s.observed[k].value) / s.observed[k].value)
                })
                .collect();
            let n = e.len().max(1) as f64;
            (
                e.iter().map(|x| x.abs()).sum::<f64>() / n,
                e.iter().sum::<f64>() / n,
                e.iter().fold(0.0f64, |m, x| m.max(x.abs())),
            )
        };
        let (b, f) = (errs(&r.before), errs(&r.fitted));
        outln!(
            "{name}: mean |error| {:.2}% -> {:.2}% (mean {:+.2}% -> {:+.2}%, largest {:.2}% -> {:.2}%)",
            b.0,
            f.0,
            b.1,
            f.1,
            b.2,
            f.2
        )?;
        if let Some(l) = &r.leave_one_out {
            let e: Vec<f64> = r
                .shots
                .iter()
                .zip(&l.predictions)
                .filter_map(|(s, p)| {
                    let (_, v) = p.as_ref().ok()?;
                    let k = s.observed.iter().position(|m| m.name == name)?;
                    Some(100.0 * (v.values[k] - s.observed[k].value) / s.observed[k].value)
                })
                .collect();
            let n = e.len().max(1) as f64;
            outln!(
                "{name}, each experiment predicted from the others' fit: mean |error| {:.2}% (mean {:+.2}%, largest {:.2}%)",
                e.iter().map(|x| x.abs()).sum::<f64>() / n,
                e.iter().sum::<f64>() / n,
                e.iter().fold(0.0f64, |m, x| m.max(x.abs()))
            )?;
        }
    }
    if let Some(l) = &r.leave_one_out {
        outln!(
            "leave-one-out ({}): {} forward runs, {:.1} s{}",
            l.method.name(),
            l.runs,
            l.wall_time_s,
            match l.predictions.iter().filter(|p| p.is_err()).count() {
                0 => String::new(),
                k => format!(", {k} predictions failed (calibration.json names the errors)"),
            }
        )?;
    }
    outln!(
        "objective {:.4e} -> {:.4e}; {} forward runs ({} coarse, {} failed, {} trial points rejected), wall time {:.1} s",
        r.objective.0,
        r.objective.1,
        r.runs,
        r.runs_coarse,
        r.failed_runs,
        r.failed_points,
        r.wall_time_s
    )?;
    if cfg!(feature = "report") {
        outln!(
            "written: {0}/calibration.json, {0}/material.toml, {0}/fit.svg",
            out.display()
        )
    } else {
        outln!(
            "written: {0}/calibration.json, {0}/material.toml (no fit.svg: this program was built \
             without the `report` feature, which plots)",
            out.display()
        )
    }
}

/// `fit.svg`: measured against simulated (before and fitted) for each
/// experiment, the relative errors shot by shot, and the outlines where
/// given.
#[cfg(feature = "report")]
fn figure(path: &Path, r: &CalibrationResult) -> Result<(), Error> {
    use crate::report::plot::{Axes, Series, panels};
    let mut names: Vec<String> = Vec::new();
    for s in &r.shots {
        for m in &s.observed {
            if !names.contains(&m.name) {
                names.push(m.name.clone());
            }
        }
    }
    let pick = |name: &str, values: &[meshless_impact::calibrate::ShotValues], rel: bool| {
        r.shots
            .iter()
            .zip(values)
            .enumerate()
            .filter_map(|(i, (s, v))| {
                let k = s.observed.iter().position(|m| m.name == name)?;
                let (m, sim) = (s.observed[k].value, v.values[k]);
                Some(if rel {
                    ((i + 1) as f64, 100.0 * (sim - m) / m)
                } else {
                    (m, sim)
                })
            })
            .collect::<Vec<_>>()
    };
    let mut parity = Vec::new();
    let mut errors = Vec::new();
    for name in &names {
        parity.push(Series::markers(
            format!("{name}, start"),
            pick(name, &r.before, false),
        ));
        parity.push(Series::markers(
            format!("{name}, fitted"),
            pick(name, &r.fitted, false),
        ));
        errors.push(Series::markers(
            format!("{name}, start"),
            pick(name, &r.before, true),
        ));
        errors.push(Series::markers(
            format!("{name}, fitted"),
            pick(name, &r.fitted, true),
        ));
    }
    let mut ax = Axes::linear("measured and simulated", "measured (SI units)", "simulated");
    ax.diagonal = true;
    let ax_err = Axes::linear(
        "relative error per experiment",
        "experiment (row of the file)",
        "(simulated - measured) / measured, %",
    );
    let mut charts: Vec<(Axes, &[Series])> = vec![(ax, &parity), (ax_err, &errors)];
    let mut outlines = Vec::new();
    for (s, f) in r.shots.iter().zip(&r.fitted) {
        if let (Some(o), Some(sim)) = (&s.outline, &f.outline) {
            let mm = |p: &[[f64; 2]]| p.iter().map(|[z, r]| (z * 1e3, r * 1e3)).collect();
            outlines.push(Series::markers(
                format!("{}, measured", s.label),
                mm(&o.points),
            ));
            outlines.push(Series::line(format!("{}, fitted", s.label), mm(sim)));
        }
    }
    if !outlines.is_empty() {
        charts.push((Axes::linear("outlines", "z (mm)", "r (mm)"), &outlines));
    }
    panels(path, &charts)
}

/// Without the `report` feature there is no plotting: `fit.svg` is not
/// written, and the summary says so (the fit's own outputs are whole).
#[cfg(not(feature = "report"))]
fn figure(_path: &Path, _r: &CalibrationResult) -> Result<(), Error> {
    Ok(())
}
