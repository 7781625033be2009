//! Command-line program of meshless-impact.

use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use meshless_impact::{Error, Scene, Simulation, Table1Row, observe};
use rayon::prelude::*;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Meshless (MSPH) solver for high-speed impact of solids.
///
/// With no subcommand it runs the default scene, `taylor` (House et al. test
/// 7), and prints the final observables beside the experiment.
#[derive(Parser)]
#[command(version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Run one scene to its end condition.
    Run(RunArgs),
    /// Run a family of scenes in parallel: `table1` is the twelve tests of Table 1.
    Sweep(SweepArgs),
    /// Regenerate the verification report (error against run time,
    /// sensitivity, Table 1, figures, stability matrix) as DIR/index.md with
    /// CSV tables and SVG figures.
    Report {
        /// Output directory.
        #[arg(long, value_name = "DIR", default_value = "report")]
        out: PathBuf,
        /// Coarse resolutions and a reduced stability matrix (about a minute).
        #[arg(long)]
        quick: bool,
    },
    /// List the parameters of a scene with units, defaults and allowed ranges.
    Params {
        /// Scene name.
        #[arg(default_value = "taylor")]
        scene: String,
    },
    /// List the observables of a scene.
    Observables {
        /// Scene name.
        #[arg(default_value = "taylor")]
        scene: String,
    },
    /// Print a built-in scene as a TOML scene file.
    Scene {
        /// Scene name (`taylor`, `noh`, `table1-1` ... `table1-12`).
        name: String,
    },
}

#[derive(Args, Default)]
struct RunArgs {
    /// Built-in scene: taylor, noh, table1-1 ... table1-12.
    #[arg(default_value = "taylor", conflicts_with = "scene_file")]
    scene: String,
    /// Read the scene from a TOML file instead.
    #[arg(long, value_name = "FILE")]
    scene_file: Option<PathBuf>,
    /// Override a parameter, e.g. `--set impact_speed=200` (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    set: Vec<String>,
    /// Write the final observables as JSON.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Write the observable time histories as CSV.
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    /// Directory for VTK (.vtu) particle snapshots.
    #[arg(long, value_name = "DIR")]
    vtk_dir: Option<PathBuf>,
    /// Times (s) of the snapshots, comma-separated; the final state is always written
    /// when --vtk-dir is given.
    #[arg(long, value_name = "T1,T2,...", value_delimiter = ',')]
    vtk_times: Vec<f64>,
    /// No progress bar and no table on stdout (errors are still reported).
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Args)]
struct SweepArgs {
    /// The sweep to run: `table1`.
    name: String,
    /// CSV file for the results table.
    #[arg(long, default_value = "table1_sweep.csv")]
    out: PathBuf,
    /// Override a parameter in every case, e.g. `--set particles_radial=10`.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    set: Vec<String>,
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        None => run(RunArgs {
            scene: "taylor".into(),
            ..Default::default()
        }),
        Some(Command::Run(a)) => run(a),
        Some(Command::Sweep(a)) => sweep(a),
        Some(Command::Report { out, quick }) => report(out, quick),
        Some(Command::Params { scene }) => params(&scene),
        Some(Command::Observables { scene }) => observables(&scene),
        Some(Command::Scene { name }) => Scene::builtin(&name).map(|s| print!("{}", s.to_toml())),
    };
    if let Err(e) = result {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn apply_sets(scene: &mut Scene, sets: &[String]) -> Result<(), Error> {
    for s in sets {
        let (name, value) = s.split_once('=').ok_or_else(|| Error::ParseValue {
            name: s.clone(),
            text: "expected NAME=VALUE".into(),
        })?;
        scene.set_str(name.trim(), value)?;
    }
    scene.validate()
}

fn fmt_duration(s: f64) -> String {
    if s < 1e-3 {
        format!("{:.2} us", s * 1e6)
    } else {
        format!("{s:.4} s")
    }
}

fn run(a: RunArgs) -> Result<(), Error> {
    let mut scene = match &a.scene_file {
        Some(f) => Scene::from_file(f)?,
        None => Scene::builtin(&a.scene)?,
    };
    apply_sets(&mut scene, &a.set)?;
    let mut sim = Simulation::new(scene)?;
    if let Some(dir) = &a.vtk_dir {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    }
    let mut vtk_times = a.vtk_times.clone();
    vtk_times.sort_by(f64::total_cmp);
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
            observe::write_pvd(&dir.join("particles.pvd"), written)?;
        }
        Ok(())
    };
    if a.vtk_dir.is_some() && vtk_times.first().is_some_and(|&t| t <= 0.0) {
        write_vtk(&sim, &mut vtk_written)?;
        next_vtk = vtk_times.iter().take_while(|&&t| t <= 0.0).count();
    }

    let start = Instant::now();
    let show_bar = !a.quiet && std::io::stderr().is_terminal();
    let mut bar: Option<ProgressBar> = None;
    let end_time = sim.end_time();
    let mut last_draw = Instant::now();
    let mut vtk_error = None;
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
                    vtk_error = Some(e);
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
    if let Some(e) = vtk_error {
        return Err(e);
    }
    write_vtk(&sim, &mut vtk_written)?;
    if let Some(path) = &a.csv {
        sim.history().write_csv(path)?;
    }
    let json = observe::final_json(
        sim.observable_specs(),
        &sim.observables(),
        sim.particles(),
        sim.steps(),
        sim.time(),
        wall,
    );
    if let Some(path) = &a.json {
        observe::write_json(path, &json)?;
    }
    if !a.quiet {
        print_summary(&sim, wall);
    }
    status
}

fn print_summary(sim: &Simulation, wall: f64) {
    println!("scene: {}", sim.scene().title);
    println!(
        "particles {}, steps {}, end time {}, wall time {:.2} s",
        sim.particles(),
        sim.steps(),
        fmt_duration(sim.time()),
        wall
    );
    if let Some(e) = sim.error() {
        println!("stopped early: {e}");
    }
    println!(
        "{:<24} {:>14} {:>14} {:>9}  unit",
        "observable", "value", "reference", "error"
    );
    for (s, v) in sim.observable_specs().iter().zip(sim.observables()) {
        let reference = sim.scene().reference.get(s.name).copied();
        let (r, e) = match reference {
            Some(r) if r != 0.0 => (format!("{r:.6}"), format!("{:+.2}%", 100.0 * (v - r) / r)),
            _ => (String::new(), String::new()),
        };
        let val = if s.is_bool() {
            (v != 0.0).to_string()
        } else {
            format!("{v:.6}")
        };
        println!("{:<24} {:>14} {:>14} {:>9}  {}", s.name, val, r, e, s.unit);
    }
}

fn report(out: PathBuf, quick: bool) -> Result<(), Error> {
    let r = meshless_impact::report::generate(&meshless_impact::report::ReportOptions {
        out: out.clone(),
        quick,
    })?;
    println!(
        "report written to {} ({} files, {:.1} s)",
        out.join("index.md").display(),
        r.files.len(),
        r.wall_s
    );
    Ok(())
}

fn params(scene: &str) -> Result<(), Error> {
    let s = Scene::builtin(scene)?;
    println!(
        "{:<24} {:<10} {:>12}  {:<28} meaning",
        "name", "unit", "default", "allowed"
    );
    for p in s.param_specs() {
        println!(
            "{:<24} {:<10} {:>12}  {:<28} {}",
            p.name,
            p.unit,
            s.get(p.name)?,
            p.range.to_string(),
            p.description
        );
    }
    Ok(())
}

fn observables(scene: &str) -> Result<(), Error> {
    let s = Scene::builtin(scene)?;
    for o in s.kind().observable_specs() {
        println!("{:<24} {:<6} {}", o.name, o.unit, o.description);
    }
    Ok(())
}

/// Simulated values of one configuration: final length, undeformed length,
/// impact-face diameter, energy error, particles, steps, wall time.
type SweepValues = (f64, f64, f64, f64, usize, u64, f64);

/// One row of the Table 1 sweep.
struct SweepRow {
    row: Table1Row,
    result: Result<SweepValues, Error>,
}

fn sweep(a: SweepArgs) -> Result<(), Error> {
    if a.name != "table1" {
        return Err(Error::UnknownScene {
            name: a.name,
            allowed: "table1".into(),
        });
    }
    let rows = Table1Row::all();
    let mut scenes = Vec::new();
    for r in &rows {
        let mut s = r.scene();
        apply_sets(&mut s, &a.set)?;
        scenes.push(s);
    }
    let start = Instant::now();
    eprintln!(
        "running {} Table 1 configurations in parallel...",
        scenes.len()
    );
    let results: Vec<SweepRow> = rows
        .par_iter()
        .zip(scenes)
        .map(|(row, scene)| {
            let t0 = Instant::now();
            let result = Simulation::new(scene).and_then(|mut sim| {
                sim.run()?;
                let o = |n: &str| sim.observable(n).expect("taylor observable");
                Ok((
                    o("rod_length"),
                    o("undeformed_length"),
                    2.0 * o("mushroom_radius"),
                    o("energy_error"),
                    sim.particles(),
                    sim.steps(),
                    t0.elapsed().as_secs_f64(),
                ))
            });
            SweepRow { row: *row, result }
        })
        .collect();
    write_sweep(&a.out, &results, start.elapsed().as_secs_f64())
}

fn write_sweep(out: &Path, results: &[SweepRow], wall: f64) -> Result<(), Error> {
    let mut w = csv::Writer::from_path(out).map_err(|e| Error::io(out, e))?;
    let header = [
        "test",
        "V_mps",
        "L0_mm",
        "Lf_sim_mm",
        "Lf_test_mm",
        "Lf_msph_mm",
        "Lf_err_pct",
        "Lu_sim_mm",
        "Lu_test_mm",
        "Lu_msph_mm",
        "Lu_err_pct",
        "Df_sim_mm",
        "Df_test_mm",
        "Df_msph_mm",
        "Df_err_pct",
        "energy_error",
        "particles",
        "steps",
        "wall_s",
        "error",
    ];
    w.write_record(header).map_err(|e| Error::io(out, e))?;
    println!(
        "test     V     L0 |     Lf   test   MSPH    err% |     Lu   test   MSPH    err% \
         |     Df   test   MSPH    err% |  E err  wall s"
    );
    let pct = |sim: f64, exp: f64| 100.0 * (sim - exp) / exp;
    let (mut lf_err, mut df_err) = (Vec::new(), Vec::new());
    for r in results {
        let t = &r.row;
        match &r.result {
            Ok((lf, lu, df, energy, n, steps, secs)) => {
                let (el, eu, ed) = (
                    pct(*lf, t.lf_test),
                    pct(*lu, t.lu_test),
                    pct(*df, t.df_test),
                );
                lf_err.push(el.abs());
                df_err.push(ed.abs());
                // Groups of (simulated, test, paper MSPH) in mm with the error in %.
                let groups = [
                    [lf * 1e3, t.lf_test * 1e3, t.lf_msph * 1e3, el],
                    [lu * 1e3, t.lu_test * 1e3, t.lu_msph * 1e3, eu],
                    [df * 1e3, t.df_test * 1e3, t.df_msph * 1e3, ed],
                ];
                let mut line = format!("{:>4} {:>5} {:>6.2}", t.test, t.v, t.l0 * 1e3);
                for g in &groups {
                    line += &format!(
                        " | {:>6.2} {:>6.2} {:>6.2} {:>+7.2}",
                        g[0], g[1], g[2], g[3]
                    );
                }
                println!("{line} | {energy:>6.4} {secs:>7.1}");
                let mut rec = vec![
                    t.test.to_string(),
                    t.v.to_string(),
                    (t.l0 * 1e3).to_string(),
                ];
                rec.extend(groups.iter().flatten().map(|x| x.to_string()));
                rec.extend([
                    energy.to_string(),
                    n.to_string(),
                    steps.to_string(),
                    secs.to_string(),
                    String::new(),
                ]);
                w.write_record(&rec).map_err(|e| Error::io(out, e))?;
            }
            Err(e) => {
                println!("{:>4} {:>5} {:>6.2} | failed: {e}", t.test, t.v, t.l0 * 1e3);
                let mut rec = vec![String::new(); header.len()];
                rec[0] = t.test.to_string();
                rec[header.len() - 1] = e.to_string();
                w.write_record(&rec).map_err(|e| Error::io(out, e))?;
            }
        }
    }
    w.flush().map_err(|e| Error::io(out, e))?;
    let stat = |v: &[f64]| {
        (
            v.iter().sum::<f64>() / v.len().max(1) as f64,
            v.iter().copied().fold(0.0, f64::max),
        )
    };
    let (lm, lx) = stat(&lf_err);
    let (dm, dx) = stat(&df_err);
    println!(
        "final length |error|: mean {lm:.2}%, max {lx:.2}% (paper max 4.3%); \
         impact-face diameter |error|: mean {dm:.2}%, max {dx:.2}% (paper max 9.0%)"
    );
    println!("wall time {wall:.1} s; table written to {}", out.display());
    if lf_err.len() != results.len() {
        return Err(Error::Inconsistent(format!(
            "{} of {} configurations failed",
            results.len() - lf_err.len(),
            results.len()
        )));
    }
    Ok(())
}
