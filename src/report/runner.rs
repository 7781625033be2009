//! Runs one case through the public [`Simulation`] API and measures it: wall
//! time, steps, final observables, the largest speed and the smallest
//! particle spacing seen, snapshots at chosen times and, for the first
//! moments of a run, observables after every step.

use meshless_impact::{Error, History, Scene, Simulation, Snapshot};
use std::time::Instant;

/// What to collect besides the final state and the recorded histories.
#[derive(Debug, Clone, Default)]
pub struct Probe {
    /// Times at which to keep a particle snapshot (the first state at or past each).
    pub snapshot_times: Vec<f64>,
    /// Observables recorded after every step while the time is below `per_step_until`.
    pub per_step: Vec<&'static str>,
    /// End of the per-step record.
    pub per_step_until: f64,
    /// Wall-clock budget in seconds; a run still going then is reported as
    /// over budget (a hang, for the stability matrix).
    pub wall_budget: f64,
}

/// How a case ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// The run reached its end condition.
    Finished,
    /// The run started and stopped early with a named error.
    Stopped(Error),
    /// The input was refused before anything ran.
    Rejected(Error),
    /// The run was still going when its wall-clock budget ran out.
    OverBudget,
}

impl Outcome {
    /// `finished`, `over wall budget`, or the error's variant name.
    pub fn label(&self) -> &'static str {
        match self {
            Outcome::Finished => "finished",
            Outcome::Stopped(e) | Outcome::Rejected(e) => e.name(),
            Outcome::OverBudget => "over wall budget",
        }
    }

    /// The error's message, if any.
    pub fn message(&self) -> String {
        match self {
            Outcome::Stopped(e) | Outcome::Rejected(e) => e.to_string(),
            _ => String::new(),
        }
    }
}

/// A measured run.
#[derive(Debug, Clone)]
pub struct CaseRun {
    /// How it ended.
    pub outcome: Outcome,
    /// Particles (0 when rejected).
    pub particles: usize,
    /// Steps taken.
    pub steps: u64,
    /// Simulated time reached.
    pub time: f64,
    /// Wall time of the stepping, in seconds.
    pub wall_s: f64,
    /// Final observables by name.
    pub observables: Vec<(&'static str, f64)>,
    /// Recorded histories.
    pub history: History,
    /// Largest particle speed over the recorded times.
    pub max_speed: f64,
    /// Smallest neighbour distance over the initial spacing.
    pub min_spacing: f64,
    /// Snapshots at the probe's times (fewer if the run ended first).
    pub snapshots: Vec<Snapshot>,
    /// Per-step times and values of the probe's `per_step` observables.
    pub per_step: Vec<(f64, Vec<f64>)>,
    /// The scene that ran (or was refused).
    pub scene: Option<Scene>,
    /// Outputs holding a NaN or an infinity: final observables, history
    /// columns and fields of the final snapshot, by name. Empty when clean.
    pub non_finite: Vec<String>,
}

impl CaseRun {
    /// Final value of an observable (NaN if the scene has no such observable).
    pub fn get(&self, name: &str) -> f64 {
        self.observables
            .iter()
            .find(|(n, _)| *n == name)
            .map_or(f64::NAN, |(_, v)| *v)
    }

    /// Whether the run reached its end condition.
    pub fn finished(&self) -> bool {
        self.outcome == Outcome::Finished
    }

    fn rejected(e: Error) -> Self {
        CaseRun {
            outcome: Outcome::Rejected(e),
            particles: 0,
            steps: 0,
            time: 0.0,
            wall_s: 0.0,
            observables: Vec::new(),
            history: History::default(),
            max_speed: f64::NAN,
            min_spacing: f64::NAN,
            snapshots: Vec::new(),
            per_step: Vec::new(),
            scene: None,
            non_finite: Vec::new(),
        }
    }
}

/// A built-in scene with parameters set, validated.
pub fn scene(name: &str, sets: &[(&str, f64)]) -> meshless_impact::Result<Scene> {
    let mut s = Scene::builtin(name)?;
    for (k, v) in sets {
        s.set(k, *v)?;
    }
    s.validate()?;
    Ok(s)
}

/// Largest speed in a snapshot's `velocity` field.
fn max_speed(snap: &Snapshot) -> f64 {
    snap.field("velocity").map_or(f64::NAN, |f| {
        f.data
            .chunks(f.components.len())
            .map(|c| c.iter().map(|x| x * x).sum::<f64>().sqrt())
            .fold(0.0, f64::max)
    })
}

/// Smallest gap between consecutive radii (the Noh shells lie on a line).
fn min_radial_gap(snap: &Snapshot) -> f64 {
    let mut r: Vec<f64> = snap.positions.iter().map(|p| p[0]).collect();
    r.sort_by(f64::total_cmp);
    r.windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min)
}

/// Runs `scene` (or reports why it was refused) and measures it.
pub fn run_case(scene: meshless_impact::Result<Scene>, probe: &Probe) -> CaseRun {
    let scene = match scene {
        Ok(s) => s,
        Err(e) => return CaseRun::rejected(e),
    };
    let mut sim = match Simulation::new(scene.clone()) {
        Ok(s) => s,
        Err(e) => return CaseRun::rejected(e),
    };
    let first = sim.snapshot();
    let mut max_v = max_speed(&first);
    // Noh: the solver does not track spacing; measure it at the records.
    let gap0 = min_radial_gap(&first);
    let mut noh_gap = gap0;
    let mut snapshots = Vec::new();
    let mut next_snap = 0;
    let mut per_step = Vec::new();
    let record = |sim: &Simulation, per_step: &mut Vec<(f64, Vec<f64>)>| {
        let v = probe
            .per_step
            .iter()
            .map(|n| sim.observable(n).unwrap_or(f64::NAN))
            .collect();
        per_step.push((sim.time(), v));
    };
    if !probe.per_step.is_empty() {
        record(&sim, &mut per_step);
    }
    let start = Instant::now();
    let mut outcome = Outcome::Finished;
    let mut records = sim.history().len();
    while !sim.finished() {
        if let Err(e) = sim.step() {
            outcome = Outcome::Stopped(e);
            break;
        }
        if sim.time() < probe.per_step_until {
            record(&sim, &mut per_step);
        }
        while next_snap < probe.snapshot_times.len()
            && sim.time() >= probe.snapshot_times[next_snap]
        {
            snapshots.push(sim.snapshot());
            next_snap += 1;
        }
        if sim.history().len() > records {
            records = sim.history().len();
            let snap = sim.snapshot();
            max_v = max_v.max(max_speed(&snap));
            noh_gap = noh_gap.min(min_radial_gap(&snap));
        }
        if probe.wall_budget > 0.0 && start.elapsed().as_secs_f64() > probe.wall_budget {
            outcome = Outcome::OverBudget;
            break;
        }
    }
    let wall_s = start.elapsed().as_secs_f64();
    let last = sim.snapshot();
    max_v = max_v.max(max_speed(&last));
    noh_gap = noh_gap.min(min_radial_gap(&last));
    let observables: Vec<(&'static str, f64)> = sim
        .observable_specs()
        .iter()
        .zip(sim.observables())
        .map(|(s, v)| (s.name, v))
        .collect();
    let history = sim.history().clone();
    let mut non_finite: Vec<String> = observables
        .iter()
        .filter(|(_, v)| !v.is_finite())
        .map(|(n, _)| n.to_string())
        .collect();
    for name in &history.names {
        let col = history.column(name).expect("own column");
        if col.iter().any(|v| !v.is_finite()) {
            non_finite.push(format!("history {name}"));
        }
    }
    for f in &last.fields {
        if f.data.iter().any(|v| !v.is_finite()) {
            non_finite.push(format!("field {}", f.name));
        }
    }
    CaseRun {
        outcome,
        particles: sim.particles(),
        steps: sim.steps(),
        time: sim.time(),
        wall_s,
        observables,
        history,
        max_speed: max_v,
        min_spacing: sim.min_spacing_ratio().unwrap_or(noh_gap / gap0),
        snapshots,
        per_step,
        scene: Some(scene),
        non_finite,
    }
}

/// Runs cases side by side (they share the cores) with the given wall budget.
pub fn run_parallel(scenes: Vec<meshless_impact::Result<Scene>>, wall_budget: f64) -> Vec<CaseRun> {
    use rayon::prelude::*;
    let probe = Probe {
        wall_budget,
        ..Probe::default()
    };
    scenes
        .into_par_iter()
        .map(|s| run_case(s, &probe))
        .collect()
}
