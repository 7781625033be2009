//! The result of a fit: the fitted values with their uncertainty, the
//! experiments before and after, what the fit cost, and how it is written
//! as `calibration.json`.

use super::shots::Shot;
use super::{DEFAULT_RELATIVE_SIGMA, Free, Options, outline_radius};
use crate::error::{Error, Result};

/// One iteration of the fit.
#[derive(Debug, Clone, PartialEq)]
pub struct IterationRecord {
    /// `"coarse"` or `"fine"`.
    pub stage: &'static str,
    /// Its number within the stage (from 1).
    pub number: usize,
    /// The objective after it: the sum of squared weighted residuals.
    pub objective: f64,
    /// The damping it used.
    pub lambda: f64,
    /// Whether its trial point was accepted.
    pub accepted: bool,
    /// Whether the trial point's runs failed.
    pub failed: bool,
    /// Whether it took a finite-difference Jacobian.
    pub jacobian: bool,
    /// Forward runs so far.
    pub runs: usize,
    /// Wall time so far (s).
    pub wall_s: f64,
}

/// How a fit ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// The last step was below the tolerance, with a Jacobian taken at the
    /// optimum.
    Converged,
    /// No step reduced the objective any more.
    NoProgress,
    /// The iteration cap.
    IterationCap,
    /// The cap on forward runs; the best point so far is kept.
    RunCap,
    /// The cap on wall time; the best point so far is kept.
    WallCap,
}

impl Outcome {
    /// Its name in `calibration.json`.
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Converged => "converged",
            Outcome::NoProgress => "no_progress",
            Outcome::IterationCap => "iteration_cap",
            Outcome::RunCap => "run_cap",
            Outcome::WallCap => "wall_cap",
        }
    }
}

/// What the simulation gave for one experiment.
#[derive(Debug, Clone, PartialEq)]
pub struct ShotValues {
    /// The simulated value of each measurement, in the shot's order.
    pub values: Vec<f64>,
    /// The simulated outline, where the shot has a measured one.
    pub outline: Option<Vec<[f64; 2]>>,
}

/// The result of a fit.
#[derive(Debug, Clone)]
pub struct CalibrationResult {
    /// The scene's kind.
    pub scene: String,
    /// The free parameters.
    pub free: Vec<Free>,
    /// The starting values.
    pub start: Vec<f64>,
    /// The fitted values.
    pub parameters: Vec<f64>,
    /// Their standard errors (`None` where the data do not constrain one).
    pub std: Vec<Option<f64>>,
    /// Their correlations.
    pub correlation: Vec<Vec<Option<f64>>>,
    /// Whether the data determine each, with the reason where they do not.
    pub identifiable: Vec<std::result::Result<(), String>>,
    /// The experiments.
    pub shots: Vec<Shot>,
    /// The simulated values at the start (fine resolution).
    pub before: Vec<ShotValues>,
    /// The simulated values at the fitted point.
    pub fitted: Vec<ShotValues>,
    /// The objective at the start and at the fitted point.
    pub objective: (f64, f64),
    /// Degrees of freedom (measurements less free parameters).
    pub dof: usize,
    /// Forward runs, all stages.
    pub runs: usize,
    /// Forward runs at the coarse resolution.
    pub runs_coarse: usize,
    /// Forward runs that stopped with a named error.
    pub failed_runs: usize,
    /// Trial points rejected because a run failed.
    pub failed_points: usize,
    /// The named errors of the failed runs, with how many of each.
    pub failures: Vec<(String, usize)>,
    /// The iterations.
    pub iterations: Vec<IterationRecord>,
    /// Wall time (s).
    pub wall_time_s: f64,
    /// Where the runs and the wall time went: per purpose (`start`,
    /// `jacobian`, `trial`), its forward runs and the wall time (s) of their
    /// batches; the rest of `wall_time_s` is the fit's own arithmetic and
    /// bookkeeping.
    pub spent: Vec<(&'static str, usize, f64)>,
    /// How it ended.
    pub outcome: Outcome,
    /// Whether the uncertainty's Jacobian was taken at the optimum by
    /// finite differences (otherwise it is Broyden's update, the cap having
    /// come first).
    pub jacobian_at_optimum: bool,
    /// The Jacobian of the weighted residuals at the end (one row per
    /// measurement, in the experiments' order; one column per free
    /// parameter, per unit of it): the sensitivities behind `std`.
    pub jacobian: Vec<Vec<f64>>,
    /// The settings.
    pub options: Options,
    /// The calibrated material as a `[material]` table (`material.toml`).
    pub material_toml: String,
    /// Each experiment predicted from the constants fitted to the others,
    /// where asked for ([`Options::leave_one_out`]).
    pub leave_one_out: Option<LeaveOneOut>,
}

/// How the constants fitted to all experiments but one are found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LeaveOneOutMethod {
    /// One Gauss-Newton step from the whole fit's answer with its Jacobian
    /// less the experiment's rows: the linearised refit, no runs.
    Linearised,
    /// The search from the whole fit's answer, to its first small step.
    Refit,
}

impl LeaveOneOutMethod {
    /// Its name (`linearised`, `refit`).
    pub fn name(self) -> &'static str {
        match self {
            LeaveOneOutMethod::Linearised => "linearised",
            LeaveOneOutMethod::Refit => "refit",
        }
    }

    /// The method called `name`.
    pub fn named(name: &str) -> Result<Self> {
        match name {
            "linearised" => Ok(LeaveOneOutMethod::Linearised),
            "refit" => Ok(LeaveOneOutMethod::Refit),
            other => Err(Error::UnknownModel {
                key: "leave_one_out".into(),
                name: other.into(),
                allowed: "linearised, refit".into(),
            }),
        }
    }
}

/// Each experiment predicted from the constants fitted to the others.
#[derive(Debug, Clone)]
pub struct LeaveOneOut {
    /// How the constants were found.
    pub method: LeaveOneOutMethod,
    /// Per experiment: the constants fitted without it, and its predicted
    /// values (`Err` with the error's message where a run failed).
    pub predictions: Vec<std::result::Result<(Vec<f64>, ShotValues), String>>,
    /// Forward runs of the leave-one-out fits and predictions.
    pub runs: usize,
    /// Their wall time (s).
    pub wall_time_s: f64,
}

/// The method, as the result records it.
pub const METHOD: &str = "Levenberg-Marquardt (Marquardt scaling, box bounds by projection) on a forward-difference \
Jacobian carried between trial points by Broyden's rank-one updates, refreshed by finite differences when a step fails \
and at the optimum";

/// The plain method (`broyden: false`), as the result records it.
pub const METHOD_PLAIN: &str = "Levenberg-Marquardt (Marquardt scaling, box bounds by projection) on a forward-difference \
Jacobian taken afresh at every accepted point";

/// How the uncertainty is computed, as the result records it.
pub const UNCERTAINTY: &str = "covariance s^2 (J^T J)^-1 from the Jacobian J of the weighted residuals at the optimum, \
scaled by the residual s^2 = (sum of squared weighted residuals) / (measurements - free parameters)";

impl CalibrationResult {
    /// The result as `calibration.json` holds it.
    pub fn to_json(&self) -> serde_json::Value {
        use serde_json::{Map, Value, json};
        let names: Vec<&str> = self.free.iter().map(|f| f.name.as_str()).collect();
        let by_name = |v: &[f64]| -> Value {
            Value::Object(
                names
                    .iter()
                    .zip(v)
                    .map(|(n, v)| (n.to_string(), json!(v)))
                    .collect(),
            )
        };
        let opt = |v: &Option<f64>| v.map_or(Value::Null, |v| json!(v));
        let std: Map<String, Value> = names
            .iter()
            .zip(&self.std)
            .map(|(n, v)| (n.to_string(), opt(v)))
            .collect();
        let identifiable: Map<String, Value> = names
            .iter()
            .zip(&self.identifiable)
            .map(|(n, v)| (n.to_string(), json!(v.is_ok())))
            .collect();
        let notes: Map<String, Value> = names
            .iter()
            .zip(&self.identifiable)
            .filter_map(|(n, v)| Some((n.to_string(), json!(v.clone().err()?))))
            .collect();
        let correlation: Vec<Value> = self
            .correlation
            .iter()
            .map(|row| Value::Array(row.iter().map(opt).collect()))
            .collect();
        let experiments: Vec<Value> = self
            .shots
            .iter()
            .zip(self.before.iter().zip(&self.fitted))
            .map(|(shot, (b, f))| {
                let measured = |vals: &ShotValues| -> Map<String, Value> {
                    shot.observed
                        .iter()
                        .zip(&vals.values)
                        .map(|(m, v)| (m.name.clone(), json!(v)))
                        .collect()
                };
                let rel = |vals: &ShotValues| -> Map<String, Value> {
                    shot.observed
                        .iter()
                        .zip(&vals.values)
                        .map(|(m, v)| (m.name.clone(), json!((v - m.value) / m.value)))
                        .collect()
                };
                let mut e = Map::new();
                e.insert("shot".into(), json!(shot.label));
                e.insert("line".into(), json!(shot.line));
                e.insert(
                    "settings".into(),
                    Value::Object(
                        shot.settings
                            .iter()
                            .map(|(n, v)| (n.clone(), json!(v)))
                            .collect(),
                    ),
                );
                e.insert(
                    "observed".into(),
                    Value::Object(
                        shot.observed
                            .iter()
                            .map(|m| (m.name.clone(), json!(m.value)))
                            .collect(),
                    ),
                );
                e.insert(
                    "sigma".into(),
                    Value::Object(
                        shot.observed
                            .iter()
                            .map(|m| {
                                let s = m.sigma.unwrap_or(DEFAULT_RELATIVE_SIGMA * m.value.abs());
                                (m.name.clone(), json!(s))
                            })
                            .collect(),
                    ),
                );
                e.insert("before".into(), Value::Object(measured(b)));
                e.insert("fitted".into(), Value::Object(measured(f)));
                e.insert("relative_error_before".into(), Value::Object(rel(b)));
                e.insert("relative_error_fitted".into(), Value::Object(rel(f)));
                if let Some(o) = &shot.outline {
                    let dev = |vals: &ShotValues| {
                        vals.outline.as_ref().map(|sim| {
                            o.points
                                .iter()
                                .map(|[z, r]| ((outline_radius(sim, *z) - r) / r).abs())
                                .fold(0.0, f64::max)
                        })
                    };
                    e.insert(
                        "outline".into(),
                        json!({
                            "file": o.path.display().to_string(),
                            "points": o.points.len(),
                            "largest_relative_error_before": dev(b),
                            "largest_relative_error_fitted": dev(f),
                            "fitted": f.outline,
                        }),
                    );
                }
                Value::Object(e)
            })
            .collect();
        let iterations: Vec<Value> = self
            .iterations
            .iter()
            .map(|it| {
                json!({
                    "stage": it.stage, "iteration": it.number, "objective": it.objective,
                    "lambda": it.lambda, "accepted": it.accepted, "failed": it.failed,
                    "jacobian": it.jacobian, "runs": it.runs, "wall_time_s": it.wall_s,
                })
            })
            .collect();
        json!({
            "scene": self.scene,
            "names": names,
            "parameters": by_name(&self.parameters),
            "std": std,
            "correlation": correlation,
            "identifiable": identifiable,
            "not_identifiable_because": notes,
            "start": by_name(&self.start),
            "bounds": Value::Object(self.free.iter().map(|f| (f.name.clone(), json!([f.lo, f.hi]))).collect()),
            "experiments": experiments,
            "objective_before": self.objective.0,
            "objective_fitted": self.objective.1,
            "measurements": self.shots.iter().map(Shot::measurements).sum::<usize>(),
            "degrees_of_freedom": self.dof,
            "runs": self.runs,
            "runs_coarse": self.runs_coarse,
            "failed_runs": self.failed_runs,
            "failed_points": self.failed_points,
            "failures": Value::Object(self.failures.iter().map(|(n, k)| (n.clone(), json!(k))).collect()),
            "iterations": iterations,
            "wall_time_s": self.wall_time_s,
            "spent": Value::Object(
                self.spent
                    .iter()
                    .map(|(p, n, w)| (p.to_string(), json!({ "runs": n, "wall_time_s": w })))
                    .collect()
            ),
            "max_runs": self.options.max_runs,
            "max_wall_s": self.options.max_wall_s,
            "coarse": self.options.coarse.as_ref().map(|(n, v)| json!({ n.clone(): v })),
            "outcome": self.outcome.name(),
            "method": if self.options.broyden { METHOD } else { METHOD_PLAIN },
            "uncertainty": UNCERTAINTY,
            "jacobian_matrix": self.jacobian,
            "jacobian": if self.jacobian_at_optimum {
                "finite differences at the optimum"
            } else {
                "Broyden's update of a finite-difference Jacobian (the caps left no room for a fresh one at the optimum)"
            },
            "default_relative_sigma": DEFAULT_RELATIVE_SIGMA,
            "leave_one_out": self.leave_one_out.as_ref().map(|l| self.leave_one_out_json(l)),
        })
    }

    /// The leave-one-out predictions as `calibration.json` holds them.
    fn leave_one_out_json(&self, l: &LeaveOneOut) -> serde_json::Value {
        use serde_json::{Value, json};
        let experiments: Vec<Value> = self
            .shots
            .iter()
            .zip(&l.predictions)
            .map(|(shot, p)| match p {
                Ok((x, v)) => json!({
                    "shot": shot.label,
                    "parameters": Value::Object(
                        self.free.iter().zip(x).map(|(f, v)| (f.name.clone(), json!(v))).collect()
                    ),
                    "predicted": Value::Object(
                        shot.observed.iter().zip(&v.values).map(|(m, v)| (m.name.clone(), json!(v))).collect()
                    ),
                    "relative_error": Value::Object(
                        shot.observed
                            .iter()
                            .zip(&v.values)
                            .map(|(m, v)| (m.name.clone(), json!((v - m.value) / m.value)))
                            .collect()
                    ),
                }),
                Err(e) => json!({ "shot": shot.label, "error": e }),
            })
            .collect();
        json!({
            "method": l.method.name(),
            "experiments": experiments,
            "runs": l.runs,
            "wall_time_s": l.wall_time_s,
        })
    }
}
