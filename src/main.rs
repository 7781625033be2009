//! Command-line program of meshless-impact.

use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use meshless_impact::{Error, Isa, ObservableSpec, Scene, Simulation, Table1Row};
use rayon::prelude::*;
use std::fs::{File, OpenOptions};
use std::io::{ErrorKind, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

// The verification report, with its plotting dependency, is the program's
// alone: the library knows nothing of it. Cargo feature `report` (default).
#[cfg(feature = "report")]
mod report;

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
    /// List the parameters of a scene with units, defaults and allowed
    /// ranges: only those of its material models (see --strength, --eos,
    /// --preset).
    Params {
        /// Scene name.
        #[arg(default_value = "taylor")]
        scene: String,
        #[command(flatten)]
        material: ChoiceArgs,
        /// Print the scene's reference page in Markdown instead (as
        /// docs/reference/SCENE.md): its parameters, observables and fields.
        #[arg(long)]
        markdown: bool,
    },
    /// List the observables of a scene.
    Observables {
        /// Scene name.
        #[arg(default_value = "taylor")]
        scene: String,
    },
    /// Print a built-in scene as a TOML scene file.
    Scene {
        /// Scene name (`meshless-impact scenes` lists them).
        name: String,
        #[command(flatten)]
        material: ChoiceArgs,
    },
    /// List the built-in scenes with their titles.
    Scenes,
    /// List the material presets: name, models, constants and source
    /// (`[material] preset = "NAME"` in a scene file, `--preset NAME`).
    Materials,
}

/// The choice of the material models, as a scene file's `[material]` table
/// makes it, and of the numerical scheme.
#[derive(Args, Default)]
struct ChoiceArgs {
    /// Numerical scheme by name (`meshless-impact params SCENE` lists the
    /// scene's schemes and what each sets); --set may override its knobs.
    #[arg(long, value_name = "NAME")]
    scheme: Option<String>,
    /// Strength model: johnson_cook or bilinear.
    #[arg(long, value_name = "MODEL")]
    strength: Option<String>,
    /// Equation of state: linear or mie_gruneisen.
    #[arg(long, value_name = "EOS")]
    eos: Option<String>,
    /// A material preset (`meshless-impact materials` lists them): its
    /// models and constants; --set may override its constants.
    #[arg(long, value_name = "NAME")]
    preset: Option<String>,
}

impl ChoiceArgs {
    /// Applies the choices to `scene`, if any is made.
    fn apply(&self, scene: &mut Scene) -> Result<(), Error> {
        if let Some(name) = &self.scheme {
            scene.set_str("scheme", name)?;
        }
        if self.strength.is_none() && self.eos.is_none() && self.preset.is_none() {
            return Ok(());
        }
        scene.choose_material(
            self.strength.as_deref(),
            self.eos.as_deref(),
            self.preset.as_deref(),
        )
    }
}

#[derive(Args, Default)]
struct RunArgs {
    /// Built-in scene (`meshless-impact scenes` lists them).
    #[arg(default_value = "taylor", conflicts_with = "scene_file")]
    scene: String,
    /// Read the scene from a TOML file instead.
    #[arg(long, value_name = "FILE")]
    scene_file: Option<PathBuf>,
    #[command(flatten)]
    material: ChoiceArgs,
    /// Override a parameter, e.g. `--set impact_speed=200` (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    set: Vec<String>,
    /// Write the final observables as JSON.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Write the observable time histories as CSV.
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    /// Write the rod's final outline as CSV: axial position and radius (m) of
    /// one generator of the mantle, from the impact face to the free end
    /// (scenes with a rod).
    #[arg(long, value_name = "FILE")]
    profile: Option<PathBuf>,
    /// Directory for VTK (.vtu) particle snapshots.
    #[arg(long, value_name = "DIR")]
    vtk_dir: Option<PathBuf>,
    /// Times (s) of the snapshots, comma-separated, from 0 to the scene's end_time;
    /// the final state is always written when --vtk-dir is given.
    // Values may start with `-`, so that `--vtk-times -1e-6` reaches the range
    // check and its error instead of being taken for an option.
    #[arg(
        long,
        value_name = "T1,T2,...",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    vtk_times: Vec<f64>,
    /// Compiled copy of the hot loops: avx512, avx2+fma or baseline (default:
    /// the best this processor runs). Every copy gives the same bits; this is
    /// for measuring them.
    #[arg(long, value_name = "COPY")]
    isa: Option<String>,
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

/// Why the program stops before the end of `main`.
enum Stop {
    /// The reader of stdout or stderr went away (`... | head`): exit 0
    /// quietly, as Unix tools do.
    BrokenPipe,
    /// One or more failures, one line each: printed as `error: ...` on
    /// stderr, exit status 1.
    Failed(Vec<String>),
}

impl Stop {
    /// One failure.
    fn failed(message: String) -> Stop {
        Stop::Failed(vec![message])
    }

    /// A failed write to `stream` (`stdout` or `stderr`).
    fn write(stream: &str, e: std::io::Error) -> Stop {
        if e.kind() == ErrorKind::BrokenPipe {
            Stop::BrokenPipe
        } else {
            Stop::failed(format!("writing to {stream}: {e}"))
        }
    }
}

impl From<Error> for Stop {
    fn from(e: Error) -> Stop {
        Stop::failed(e.to_string())
    }
}

/// `println!` that returns a [`Stop`] instead of panicking when stdout cannot
/// be written (closed pipe, full disk).
macro_rules! outln {
    ($($arg:tt)*) => {
        writeln!(std::io::stdout(), $($arg)*).map_err(|e| Stop::write("stdout", e))
    };
}

/// `eprintln!` that returns a [`Stop`] instead of panicking when stderr
/// cannot be written.
macro_rules! errln {
    ($($arg:tt)*) => {
        writeln!(std::io::stderr(), $($arg)*).map_err(|e| Stop::write("stderr", e))
    };
}

fn main() {
    let status = match try_main() {
        Ok(()) | Err(Stop::BrokenPipe) => 0,
        Err(Stop::Failed(messages)) => {
            for m in messages {
                // Nothing is left to tell if stderr itself fails.
                let _ = writeln!(std::io::stderr(), "error: {m}");
            }
            1
        }
    };
    std::process::exit(status);
}

fn try_main() -> Result<(), Stop> {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return usage_error(e),
    };
    match cli.command {
        None => run(RunArgs {
            scene: "taylor".into(),
            ..Default::default()
        })?,
        Some(Command::Run(a)) => run(a)?,
        Some(Command::Sweep(a)) => sweep(a)?,
        Some(Command::Report { out, quick }) => report(out, quick)?,
        Some(Command::Params {
            scene,
            material,
            markdown,
        }) => params(&scene, &material, markdown)?,
        Some(Command::Observables { scene }) => observables(&scene)?,
        Some(Command::Scenes) => scenes()?,
        Some(Command::Materials) => materials()?,
        Some(Command::Scene { name, material }) => {
            let mut scene = Scene::builtin(&name)?;
            material.apply(&mut scene)?;
            let toml = scene.to_toml();
            write!(std::io::stdout(), "{toml}").map_err(|e| Stop::write("stdout", e))?;
        }
    }
    // stdout is line-buffered: what is left must reach its reader, or fail here.
    std::io::stdout()
        .flush()
        .map_err(|e| Stop::write("stdout", e))
}

/// What clap reports instead of arguments: `--help` and `--version` go to
/// stdout and succeed; usage errors go to stderr with exit status 1 (clap's
/// own `exit` would use 2).
fn usage_error(e: clap::Error) -> Result<(), Stop> {
    if e.use_stderr() {
        // clap's message already starts with `error:`; whether or not stderr
        // takes it, the status is 1.
        let _ = e.print();
        return Err(Stop::Failed(Vec::new()));
    }
    e.print().map_err(|e| Stop::write("stdout", e))?;
    std::io::stdout()
        .flush()
        .map_err(|e| Stop::write("stdout", e))
}

/// Applies `--set NAME=VALUE`s: a scheme first (`--set scheme=paper`),
/// then the other parameters, which override its knobs.
fn apply_sets(scene: &mut Scene, sets: &[String]) -> Result<(), Error> {
    let mut pairs = Vec::with_capacity(sets.len());
    for s in sets {
        let (name, value) = s.split_once('=').ok_or_else(|| Error::ParseValue {
            name: s.clone(),
            text: "expected NAME=VALUE".into(),
        })?;
        pairs.push((name.trim(), value));
    }
    for (name, value) in scene.schemes_first(pairs) {
        scene.set_str(name, value)?;
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

fn run(a: RunArgs) -> Result<(), Stop> {
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
        let json = final_json(
            sim.observable_specs(),
            &sim.observables(),
            sim.particles(),
            sim.steps(),
            sim.time(),
            wall,
            status.as_ref().err(),
        );
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

/// The rod's outline as CSV (`z_m,r_m`, one row per point of the mantle's
/// generator, from the impact face up).
fn write_profile(path: &std::path::Path, sim: &Simulation) -> std::io::Result<()> {
    use std::fmt::Write as _;
    let mut text = String::from("z_m,r_m\n");
    for [z, r] in sim.rod_profile().unwrap_or_default() {
        let _ = writeln!(text, "{z:e},{r:e}");
    }
    std::fs::write(path, text)
}

/// The end of a command that attempted all its outputs: `failures` (one line
/// each) and the result of printing to stdout. A closed stdout ends quietly
/// only when nothing else failed.
fn outcome(mut failures: Vec<String>, printed: Result<(), Stop>) -> Result<(), Stop> {
    match printed {
        Err(Stop::Failed(m)) => failures.extend(m),
        Err(Stop::BrokenPipe) if failures.is_empty() => return Err(Stop::BrokenPipe),
        _ => {}
    }
    if failures.is_empty() {
        Ok(())
    } else {
        Err(Stop::Failed(failures))
    }
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

/// Checks before a run that `path`, given to `option`, can be written: its
/// directory exists and the file opens for writing. Nothing that exists is
/// changed: an existing file is opened without truncating it, and a file
/// created for the test is removed again.
fn check_output_file(option: &str, path: &Path) -> Result<(), Stop> {
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
fn check_output_dir(option: &str, dir: &Path, file: &str) -> Result<(), Stop> {
    std::fs::create_dir_all(dir).map_err(|e| {
        Stop::failed(format!(
            "{option} {}: cannot create the directory: {e}",
            dir.display()
        ))
    })?;
    check_output_file(option, &dir.join(file))
}

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
    outln!(
        "{:<24} {:>14} {:>14} {:>9}  unit",
        "observable",
        "value",
        "reference",
        "error"
    )?;
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
        outln!("{:<24} {:>14} {:>14} {:>9}  {}", s.name, val, r, e, s.unit)?;
    }
    Ok(())
}

#[cfg(feature = "report")]
fn report(out: PathBuf, quick: bool) -> Result<(), Stop> {
    check_output_dir("--out", &out, "index.md")?;
    let r = report::generate(&report::ReportOptions {
        out: out.clone(),
        quick,
    })?;
    outln!(
        "report written to {} ({} files, {:.1} s)",
        out.join("index.md").display(),
        r.files.len(),
        r.wall_s
    )
}

#[cfg(not(feature = "report"))]
fn report(_out: PathBuf, _quick: bool) -> Result<(), Stop> {
    Err(Stop::failed(
        "this program was built without the report (cargo feature `report`)".into(),
    ))
}

/// `meshless-impact params`: the parameter table of a scene, or with
/// `markdown` its reference page (`docs/reference/SCENE.md`).
fn params(scene: &str, material: &ChoiceArgs, markdown: bool) -> Result<(), Stop> {
    use meshless_impact::internals::reference;
    let mut s = Scene::builtin(scene)?;
    material.apply(&mut s)?;
    if markdown {
        let page = reference::page(scene, &s)?;
        return write!(std::io::stdout(), "{page}").map_err(|e| Stop::write("stdout", e));
    }
    outln!(
        "{:<24} {:<10} {:>12}  {:<28} meaning",
        "name",
        "unit",
        "default",
        "allowed"
    )?;
    for p in s.param_specs() {
        let (value, allowed) = reference::value_and_allowed(p, s.get(p.name)?);
        outln!(
            "{:<24} {:<10} {:>12}  {:<28} {}",
            p.name,
            p.unit,
            value,
            allowed,
            p.description
        )?;
    }
    for p in s.param_specs().iter().filter(|p| !p.levels.is_empty()) {
        let flag = if p.name == "scheme" {
            "--scheme NAME, ".to_string()
        } else {
            String::new()
        };
        let sets = p.levels.iter().any(|l| !l.sets.is_empty());
        outln!(
            "\n{} ({flag}--set {}=NAME, or `{} = \"NAME\"` in a scene file's [parameters]){}:",
            p.name,
            p.name,
            p.name,
            if sets { "; each sets" } else { "" }
        )?;
        let chosen = s.level(p.name)?.map(|l| l.name);
        for level in p.levels {
            let sets: Vec<String> = level
                .sets
                .iter()
                .map(|(n, x)| format!("{n} = {x}"))
                .collect();
            let mark = if Some(level.name) == chosen {
                " (chosen)"
            } else {
                ""
            };
            outln!("  {}{mark}: {}", level.name, level.description)?;
            if !sets.is_empty() {
                outln!("      {}", sets.join(", "))?;
            }
        }
    }
    Ok(())
}

fn scenes() -> Result<(), Stop> {
    let names = meshless_impact::builtin_names();
    let width = names.iter().map(|n| n.len()).max().unwrap_or(0);
    for name in names {
        outln!("{:<width$} {}", name, Scene::builtin(&name)?.title)?;
    }
    Ok(())
}

fn materials() -> Result<(), Stop> {
    use meshless_impact::materials::{PRESETS, Prefix};
    for p in PRESETS {
        outln!("{:<24} {}", p.name, p.choice)?;
        let values: Vec<String> = p
            .choice
            .param_specs(Prefix::None)
            .iter()
            .map(|spec| {
                let v = p
                    .value(spec.name)
                    .expect("a preset gives every parameter of its models");
                let unit = if spec.unit == "1" { "" } else { spec.unit };
                if v.abs() >= 1e5 {
                    format!("{} = {v:.4e} {unit}", spec.name)
                } else {
                    format!("{} = {v} {unit}", spec.name)
                }
            })
            .collect();
        for chunk in values.chunks(4) {
            outln!("    {}", chunk.join(", "))?;
        }
        outln!("    source: {}", p.source)?;
    }
    outln!("(values rounded; `meshless-impact params --preset NAME` prints them in full)")?;
    Ok(())
}

fn observables(scene: &str) -> Result<(), Stop> {
    let s = Scene::builtin(scene)?;
    for o in s.kind().observable_specs() {
        outln!("{:<24} {:<6} {}", o.name, o.unit, o.description)?;
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

fn sweep(a: SweepArgs) -> Result<(), Stop> {
    if a.name != "table1" {
        return Err(Error::UnknownScene {
            name: a.name,
            allowed: "table1".into(),
        }
        .into());
    }
    let rows = Table1Row::all();
    let mut scenes = Vec::new();
    for r in &rows {
        let mut s = r.scene();
        apply_sets(&mut s, &a.set)?;
        scenes.push(s);
    }
    check_output_file("--out", &a.out)?;
    let start = Instant::now();
    errln!(
        "running {} Table 1 configurations in parallel...",
        scenes.len()
    )?;
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

/// Columns of the sweep's CSV table.
const SWEEP_HEADER: [&str; 20] = [
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

/// Writes the sweep's results: the CSV table to `out` first, then the table
/// and the error statistics on stdout (printed even when the CSV failed).
fn write_sweep(out: &Path, results: &[SweepRow], wall: f64) -> Result<(), Stop> {
    let pct = |sim: f64, exp: f64| 100.0 * (sim - exp) / exp;
    let (mut lf_err, mut df_err) = (Vec::new(), Vec::new());
    // CSV records and the lines of the table on stdout.
    let (mut records, mut lines) = (Vec::new(), Vec::new());
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
                lines.push(format!("{line} | {energy:>6.4} {secs:>7.1}"));
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
                records.push(rec);
            }
            Err(e) => {
                lines.push(format!(
                    "{:>4} {:>5} {:>6.2} | failed: {e}",
                    t.test,
                    t.v,
                    t.l0 * 1e3
                ));
                let mut rec = vec![String::new(); SWEEP_HEADER.len()];
                rec[0] = t.test.to_string();
                rec[SWEEP_HEADER.len() - 1] = e.to_string();
                records.push(rec);
            }
        }
    }
    let written = write_csv_records(out, &SWEEP_HEADER, &records);

    let print = || -> Result<(), Stop> {
        outln!(
            "test     V     L0 |     Lf   test   MSPH    err% |     Lu   test   MSPH    err% \
             |     Df   test   MSPH    err% |  E err  wall s"
        )?;
        for line in &lines {
            outln!("{line}")?;
        }
        let stat = |v: &[f64]| {
            (
                v.iter().sum::<f64>() / v.len().max(1) as f64,
                v.iter().copied().fold(0.0, f64::max),
            )
        };
        let (lm, lx) = stat(&lf_err);
        let (dm, dx) = stat(&df_err);
        outln!(
            "final length |error|: mean {lm:.2}%, max {lx:.2}% (paper max 4.3%); \
             impact-face diameter |error|: mean {dm:.2}%, max {dx:.2}% (paper max 9.0%)"
        )?;
        if written.is_ok() {
            outln!("wall time {wall:.1} s; table written to {}", out.display())
        } else {
            outln!("wall time {wall:.1} s; table not written")
        }
    };
    let printed = print();

    let mut failures = Vec::new();
    if let Err(e) = written {
        failures.push(format!("--out: {e}"));
    }
    if lf_err.len() != results.len() {
        failures.push(format!(
            "{} of {} configurations failed",
            results.len() - lf_err.len(),
            results.len()
        ));
    }
    outcome(failures, printed)
}

/// Writes a CSV file of `header` and `records`.
fn write_csv_records(out: &Path, header: &[&str], records: &[Vec<String>]) -> Result<(), Error> {
    let mut w = csv::Writer::from_path(out).map_err(|e| Error::io(out, e))?;
    w.write_record(header).map_err(|e| Error::io(out, e))?;
    for rec in records {
        w.write_record(rec).map_err(|e| Error::io(out, e))?;
    }
    w.flush().map_err(|e| Error::io(out, e))
}

/// Final values of a run as a JSON object: every observable by name, plus
/// `particles`, `steps`, `end_time`, `wall_time_s`, and `outcome`:
/// `"finished"`, or the name of the error that stopped the run, whose
/// message is then `error` (the values are those of the state at the stop,
/// outside the solver's domain of validity).
fn final_json(
    specs: &[ObservableSpec],
    values: &[f64],
    particles: usize,
    steps: u64,
    end_time: f64,
    wall_time_s: f64,
    stopped: Option<&Error>,
) -> serde_json::Value {
    let mut m = serde_json::Map::new();
    for (s, v) in specs.iter().zip(values) {
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
    serde_json::Value::Object(m)
}

/// Writes a JSON value to a file, pretty-printed.
fn write_json(path: &Path, value: &serde_json::Value) -> Result<(), Error> {
    let mut f = std::fs::File::create(path).map_err(|e| Error::io(path, e))?;
    serde_json::to_writer_pretty(&mut f, value).map_err(|e| Error::io(path, e))?;
    writeln!(f).map_err(|e| Error::io(path, e))
}
