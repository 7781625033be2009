//! The start of `meshless-impact run`: a new run from its scene, or a run
//! continued from its checkpoint (`--restart`), with what the program
//! keeps beside the run in every checkpoint ([`RunHost`]) so that the
//! continued run writes the same outputs as the run that was never
//! stopped.

use super::args::{RunArgs, apply_sets};
use super::stop::Stop;
use meshless_impact::checkpoint::{self, CheckpointFault};
use meshless_impact::{Scene, Simulation};
use std::path::{Path, PathBuf};

/// The program's name for its part of a checkpoint.
const PROGRAM: &str = "meshless-impact run";

/// Wall-clock seconds between checkpoints when `--checkpoint-every` is
/// not given.
pub(crate) const DEFAULT_EVERY: f64 = 300.0;

/// What `run` keeps in a checkpoint beside the run: its outputs (absolute
/// paths), its snapshots (the times asked for, the next one due, those
/// written), its checkpoints, and the wall time spent so far.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RunHost {
    /// [`PROGRAM`].
    pub(crate) program: String,
    /// `--json`.
    pub(crate) json: Option<PathBuf>,
    /// `--csv`.
    pub(crate) csv: Option<PathBuf>,
    /// `--profile`.
    pub(crate) profile: Option<PathBuf>,
    /// `--vtk-dir`.
    pub(crate) vtk_dir: Option<PathBuf>,
    /// `--vtk-times`, sorted.
    pub(crate) vtk_times: Vec<f64>,
    /// The index in `vtk_times` of the next snapshot due.
    pub(crate) vtk_next: usize,
    /// (time, file name) of the snapshots written.
    pub(crate) vtk_written: Vec<(f64, String)>,
    /// `--checkpoint`.
    pub(crate) checkpoint: Option<PathBuf>,
    /// `--checkpoint-every`.
    pub(crate) checkpoint_every: f64,
    /// `--checkpoint-steps`.
    pub(crate) checkpoint_steps: Option<u64>,
    /// Wall-clock seconds of the run before this process.
    pub(crate) wall_s: f64,
}

/// A path as given, made absolute (so that a restart from another folder
/// writes the same files).
fn absolute(option: &str, p: &Path) -> Result<PathBuf, Stop> {
    std::path::absolute(p).map_err(|e| Stop::failed(format!("{option} {}: {e}", p.display())))
}

fn absolute_opt(option: &str, p: &Option<PathBuf>) -> Result<Option<PathBuf>, Stop> {
    p.as_deref().map(|p| absolute(option, p)).transpose()
}

/// Whether the arguments name a scene or change one.
fn asks_a_scene(a: &RunArgs) -> bool {
    a.scene.is_some() || a.scene_file.is_some() || !a.set.is_empty() || a.material.any()
}

/// The scene the arguments ask for.
fn asked_scene(a: &RunArgs) -> Result<Scene, Stop> {
    let mut scene = match (&a.scene_file, &a.scene) {
        (Some(f), _) => Scene::from_file(f)?,
        (None, name) => Scene::builtin(name.as_deref().unwrap_or("taylor"))?,
    };
    a.material.apply(&mut scene)?;
    apply_sets(&mut scene, &a.set)?;
    Ok(scene)
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

/// The checkpointing options, checked; `base` holds what a checkpoint
/// recorded (or nothing).
fn checkpointing(a: &RunArgs, base: &mut RunHost) -> Result<(), Stop> {
    if let Some(p) = &a.checkpoint {
        base.checkpoint = Some(absolute("--checkpoint", p)?);
    }
    if let Some(every) = a.checkpoint_every {
        if !(every.is_finite() && every > 0.0) {
            return Err(Stop::failed(format!(
                "--checkpoint-every: {every} s is out of range: allowed (0, inf) s"
            )));
        }
        base.checkpoint_every = every;
    }
    if let Some(n) = a.checkpoint_steps {
        if n == 0 {
            return Err(Stop::failed(
                "--checkpoint-steps: 0 is out of range: allowed integers [1, inf)".into(),
            ));
        }
        base.checkpoint_steps = Some(n);
    }
    if base.checkpoint.is_none() && (a.checkpoint_every.is_some() || a.checkpoint_steps.is_some()) {
        return Err(Stop::failed(
            "--checkpoint-every and --checkpoint-steps need --checkpoint FILE".into(),
        ));
    }
    if base.checkpoint_every == 0.0 {
        base.checkpoint_every = DEFAULT_EVERY;
    }
    Ok(())
}

/// The run to step and what the program keeps beside it: a new run of the
/// scene asked for, or the run of `--restart`'s checkpoint.
pub(crate) fn begin(a: &RunArgs) -> Result<(Simulation, RunHost), Stop> {
    match &a.restart {
        None => {
            let sim = Simulation::new(asked_scene(a)?)?;
            let mut host = RunHost {
                program: PROGRAM.into(),
                json: absolute_opt("--json", &a.json)?,
                csv: absolute_opt("--csv", &a.csv)?,
                profile: absolute_opt("--profile", &a.profile)?,
                vtk_dir: absolute_opt("--vtk-dir", &a.vtk_dir)?,
                vtk_times: check_vtk_times(&a.vtk_times, sim.end_time())?,
                ..RunHost::default()
            };
            checkpointing(a, &mut host)?;
            Ok((sim, host))
        }
        Some(path) => restart(a, path),
    }
}

/// The run of the checkpoint `path`, with the arguments checked against it.
fn restart(a: &RunArgs, path: &Path) -> Result<(Simulation, RunHost), Stop> {
    let (sim, saved) = checkpoint::load(path)?;
    // A checkpoint written by Python or the C ABI holds no program part:
    // it continues with the outputs given now.
    let mut host: RunHost = if saved.is_null() {
        RunHost {
            program: PROGRAM.into(),
            ..RunHost::default()
        }
    } else {
        serde_json::from_value(saved).map_err(|e| {
            Stop::from(checkpoint::fault(
                path,
                CheckpointFault::NotACheckpoint,
                format!("its program part is not `{PROGRAM}`'s: {e}"),
            ))
        })?
    };
    if asks_a_scene(a) {
        // A scene named is built as a new run's; parameters alone change
        // the checkpoint's scene.
        let asked = if a.scene.is_some() || a.scene_file.is_some() {
            asked_scene(a)?
        } else {
            let mut scene = sim.scene().clone();
            a.material.apply(&mut scene)?;
            apply_sets(&mut scene, &a.set)?;
            scene
        };
        let found = checkpoint::contradictions(sim.scene(), &asked);
        if !found.is_empty() {
            let fault = if sim.scene().kind().name() != asked.kind().name() {
                CheckpointFault::OtherScene
            } else {
                CheckpointFault::Contradicts
            };
            return Err(checkpoint::fault(
                path,
                fault,
                format!(
                    "the run asked for differs from it: {} (give --restart alone to continue it)",
                    found.join("; ")
                ),
            )
            .into());
        }
    }
    let contradiction = |what: String| {
        Stop::from(checkpoint::fault(
            path,
            CheckpointFault::Contradicts,
            format!("{what} (give it as the checkpoint has it, or not at all)"),
        ))
    };
    if !a.vtk_times.is_empty() {
        let asked = check_vtk_times(&a.vtk_times, sim.end_time())?;
        if asked != host.vtk_times {
            return Err(contradiction(format!(
                "--vtk-times {asked:?} s, where the checkpoint's are {:?} s",
                host.vtk_times
            )));
        }
    }
    if let Some(dir) = absolute_opt("--vtk-dir", &a.vtk_dir)? {
        match &host.vtk_dir {
            Some(saved) if *saved != dir && !host.vtk_written.is_empty() => {
                return Err(contradiction(format!(
                    "--vtk-dir {}, where the checkpoint's snapshots so far are in {}",
                    dir.display(),
                    saved.display()
                )));
            }
            None if host.vtk_next > 0 => {
                return Err(contradiction(format!(
                    "--vtk-dir {}, where the checkpoint's run wrote no snapshots",
                    dir.display()
                )));
            }
            _ => host.vtk_dir = Some(dir),
        }
    }
    if let Some(p) = absolute_opt("--json", &a.json)? {
        host.json = Some(p);
    }
    if let Some(p) = absolute_opt("--csv", &a.csv)? {
        host.csv = Some(p);
    }
    if let Some(p) = absolute_opt("--profile", &a.profile)? {
        host.profile = Some(p);
    }
    checkpointing(a, &mut host)?;
    Ok((sim, host))
}
