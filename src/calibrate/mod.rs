//! Calibration: fits named parameters of any scene (a material's
//! constants, usually) to the measured observables of a set of experiments.
//!
//! - The fixed part is a [`Scene`] (built in or from a file, with its
//!   material, scheme and `--set`s); each experiment ([`Shot`]) sets some of
//!   its parameters (`impact_speed`, `initial_length`, ...) and measures
//!   some of its observables (`rod_length`, `mushroom_radius`, ...).
//! - The fit is weighted least squares on the relative residuals
//!   `(simulated - measured) / measured`, each weighted by its relative
//!   uncertainty (`sigma / |measured|`; [`DEFAULT_RELATIVE_SIGMA`] where the
//!   file gives none), by Levenberg-Marquardt on a finite-difference
//!   Jacobian that Broyden's updates carry between trial points (`lsq.rs`;
//!   docs/guide/calibration.md compares it with the plain method).
//! - Forward runs go in parallel over the experiments and over the
//!   directions of a finite-difference step; a coarser resolution may go
//!   first ([`Options::coarse`]), whose Jacobian the fine stage starts from.
//! - A trial point whose run stops with a named error is a step that
//!   failed; the fit is bounded by a cap on forward runs and on wall time.
//! - The uncertainty comes from the Jacobian at the optimum scaled by the
//!   residual (`stats.rs`).

pub(crate) mod linalg;
mod lsq;
mod result;
mod shots;
mod stats;

pub use lsq::{GAIN_FRACTION, STD_FRACTION};
pub use result::{
    CalibrationResult, IterationRecord, LeaveOneOut, LeaveOneOutMethod, METHOD, METHOD_PLAIN,
    Outcome, ShotValues, UNCERTAINTY,
};
pub use shots::{Measured, Outline, Shot, parse as parse_shots, read as read_shots};
pub use stats::{MAX_CORRELATION, MAX_RELATIVE_STD};

use crate::error::{Error, Result};
use crate::scene::Scene;
use crate::sim::Simulation;
use rayon::prelude::*;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// The relative uncertainty of a measurement whose experiments file gives
/// no `sigma_NAME`: 1 %, about the precision of a length read off a
/// recovered Taylor rod (House et al. tabulate 0.1 mm on 10-50 mm).
pub const DEFAULT_RELATIVE_SIGMA: f64 = 0.01;

/// A free parameter and its bounds.
#[derive(Debug, Clone, PartialEq)]
pub struct Free {
    /// The parameter's name.
    pub name: String,
    /// Lower bound.
    pub lo: f64,
    /// Upper bound.
    pub hi: f64,
}

impl Free {
    /// Parses `NAME=LO:HI` (as `--free` takes it) against `scene`: the
    /// parameter must exist, be continuous (not an integer or a named
    /// level), and both bounds must lie in its allowed range, the lower
    /// below the upper.
    pub fn parse(text: &str, scene: &Scene) -> Result<Free> {
        let bad = |why: &str| {
            Error::Inconsistent(format!(
                "--free {text}: {why}; expected NAME=LO:HI, for example jc_a=600e6:1200e6"
            ))
        };
        let (name, bounds) = text.split_once('=').ok_or_else(|| bad("no bounds"))?;
        let (lo, hi) = bounds
            .split_once(':')
            .ok_or_else(|| bad("no `:` between the bounds"))?;
        let num = |t: &str| {
            t.trim()
                .parse::<f64>()
                .map_err(|_| bad(&format!("`{t}` is not a number")))
        };
        Free::new(name.trim(), num(lo)?, num(hi)?, scene)
    }

    /// The free parameter `name` between `lo` and `hi`, checked as
    /// [`Free::parse`] does.
    pub fn new(name: &str, lo: f64, hi: f64, scene: &Scene) -> Result<Free> {
        let spec = scene.spec(name)?;
        if spec.range.integer || !spec.levels.is_empty() {
            return Err(Error::Inconsistent(format!(
                "--free {name}: only a continuous parameter can be fitted; `{name}` takes {}",
                if spec.levels.is_empty() {
                    spec.range.to_string()
                } else {
                    spec.level_names()
                }
            )));
        }
        for (which, v) in [("lower", lo), ("upper", hi)] {
            spec.check(v).map_err(|_| Error::OutOfRange {
                name: format!("{name} ({which} bound of --free)"),
                value: v,
                range: spec.range.to_string(),
            })?;
        }
        if lo >= hi {
            return Err(Error::Inconsistent(format!(
                "--free {name}={lo}:{hi}: the lower bound must be below the upper"
            )));
        }
        Ok(Free {
            name: name.to_string(),
            lo,
            hi,
        })
    }
}

/// Settings of a fit.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Cap on forward runs (one run is one experiment at one point).
    pub max_runs: usize,
    /// Cap on wall time (s): runs under way when it passes are cancelled.
    pub max_wall_s: f64,
    /// A coarser resolution to fit at first: a parameter and its value
    /// (`particles_radial=10`); the fine stage starts from its answer and
    /// its Jacobian.
    pub coarse: Option<(String, f64)>,
    /// Finite-difference step, relative to a parameter's value.
    pub fd_step: f64,
    /// Converged when a step moves each parameter by less than this
    /// fraction of its value, or by less than a tenth of its standard error
    /// (`STD_FRACTION`) while it would lower the objective by less than a
    /// quarter of the residual's scale (`GAIN_FRACTION`).
    pub xtol: f64,
    /// The method: Levenberg-Marquardt with the Jacobian carried by
    /// Broyden's updates (`true`, the default) or taken afresh by finite
    /// differences at every accepted point (`false`).
    pub broyden: bool,
    /// After the fit, predict each experiment from the constants fitted to
    /// the others, by the method given (its runs are counted apart).
    pub leave_one_out: Option<LeaveOneOutMethod>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            max_runs: 400,
            max_wall_s: 3600.0,
            coarse: None,
            fd_step: 0.01,
            xtol: 1e-3,
            broyden: true,
            leave_one_out: None,
        }
    }
}

/// What a fit reports while it goes.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// A stage starts: `"coarse"` or `"fine"`, with its resolution.
    Stage(String),
    /// A batch of forward runs starts.
    Batch {
        /// Its runs.
        runs: usize,
    },
    /// A forward run finished.
    RunDone,
    /// An iteration finished.
    Iteration(IterationRecord),
}

/// A calibration problem: the fixed part, the free parameters, the
/// experiments and the settings.
#[derive(Debug, Clone)]
pub struct Calibration {
    base: Scene,
    free: Vec<Free>,
    shots: Vec<Shot>,
    options: Options,
}

/// A stage of the fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Level {
    Coarse,
    Fine,
}

impl Calibration {
    /// Checks the problem: free parameters named once, not also set by an
    /// experiment; at least as many measurements as free parameters; the
    /// coarse resolution a parameter of the scene; the caps positive.
    pub fn new(base: Scene, free: Vec<Free>, shots: Vec<Shot>, options: Options) -> Result<Self> {
        if free.is_empty() {
            return Err(Error::Inconsistent(
                "no free parameter: give at least one --free NAME=LO:HI".into(),
            ));
        }
        for (k, f) in free.iter().enumerate() {
            if free[..k].iter().any(|g| g.name == f.name) {
                return Err(Error::Inconsistent(format!(
                    "--free {} is given twice",
                    f.name
                )));
            }
            if let Some(s) = shots
                .iter()
                .find(|s| s.settings.iter().any(|(n, _)| *n == f.name))
            {
                return Err(Error::Inconsistent(format!(
                    "`{}` is free and also a setting of the experiments file (shot {}, line {})",
                    f.name, s.label, s.line
                )));
            }
        }
        let measurements: usize = shots.iter().map(Shot::measurements).sum();
        if measurements < free.len() {
            return Err(Error::Inconsistent(format!(
                "{measurements} measurements cannot determine {} free parameters: give at least as many measurements as free parameters",
                free.len()
            )));
        }
        if let Some((name, v)) = &options.coarse {
            base.spec(name)?.check(*v)?;
        }
        if options.max_runs == 0 || options.max_wall_s.is_nan() || options.max_wall_s <= 0.0 {
            return Err(Error::OutOfRange {
                name: "max_runs / max_wall_s".into(),
                value: if options.max_runs == 0 {
                    0.0
                } else {
                    options.max_wall_s
                },
                range: "positive".into(),
            });
        }
        let fd_ok = options.fd_step > 0.0 && options.fd_step < 0.5;
        if !(fd_ok && options.xtol > 0.0 && options.xtol < 1.0) {
            return Err(Error::Inconsistent(format!(
                "fd_step = {} must lie in (0, 0.5) and xtol = {} in (0, 1)",
                options.fd_step, options.xtol
            )));
        }
        Ok(Calibration {
            base,
            free,
            shots,
            options,
        })
    }

    /// The scene of experiment `shot` at the free values `x`.
    pub fn shot_scene(&self, shot: &Shot, x: &[f64]) -> Result<Scene> {
        self.scene_at(shot, x, Level::Fine)
    }

    fn scene_at(&self, shot: &Shot, x: &[f64], level: Level) -> Result<Scene> {
        let mut s = self.base.clone();
        for (name, v) in &shot.settings {
            s.set(name, *v)?;
        }
        for (f, v) in self.free.iter().zip(x) {
            s.set(&f.name, *v)?;
        }
        if let (Level::Coarse, Some((name, v))) = (level, &self.options.coarse) {
            s.set(name, *v)?;
        }
        s.title = format!("{} (shot {})", s.title, shot.label);
        s.validate()?;
        Ok(s)
    }

    /// The starting values: the fixed part's, moved into the bounds.
    pub fn start(&self) -> Vec<f64> {
        self.free
            .iter()
            .map(|f| {
                let v = self.base.get(&f.name).expect("checked name");
                v.clamp(f.lo, f.hi)
            })
            .collect()
    }

    /// Runs the fit; `on_event` hears of its progress (from any thread).
    pub fn run(&self, on_event: &(dyn Fn(&Event) + Sync)) -> Result<CalibrationResult> {
        let clock = Instant::now();
        let names: Vec<String> = self.free.iter().map(|f| f.name.clone()).collect();
        let bounds: Vec<(f64, f64)> = self.free.iter().map(|f| (f.lo, f.hi)).collect();
        let book = Book::new();
        let x0 = self.start();
        on_event(&Event::Stage("fine".into()));
        let before = match self.evaluate(
            std::slice::from_ref(&x0),
            Level::Fine,
            lsq::Purpose::Start,
            &book,
            on_event,
        ) {
            Ok(mut v) => v.pop().expect("one point"),
            Err(cap) => {
                return Err(Error::Inconsistent(
                    format!(
                        "the caps (--max-runs {}, --max-wall {} s) leave no room for the starting point's {} runs",
                        self.options.max_runs,
                        self.options.max_wall_s,
                        self.shots.len()
                    ) + if cap == lsq::Cap::Wall {
                        " in time"
                    } else {
                        ""
                    },
                ));
            }
        };
        let (r_before, values_before) = match before {
            Ok(v) => v,
            Err((label, e)) => {
                return Err(Error::Inconsistent(format!(
                    "the run of shot {label} at the starting point stopped ({e}): nothing to fit from; \
                     change the starting values or the fixed part"
                )));
            }
        };
        let opts = lsq::Options {
            fd_step: self.options.fd_step,
            xtol: self.options.xtol,
            max_iterations: 40,
            fresh_at_end: true,
            carry: self.options.broyden,
        };
        let iterations_cell = Mutex::new(Vec::new());
        let mut failed_points = 0;
        let hook_for = |stage: &'static str| {
            let book = &book;
            let cell = &iterations_cell;
            let mut number = 0;
            move |it: &lsq::Iteration| {
                number += 1;
                let rec = IterationRecord {
                    stage,
                    number,
                    objective: it.objective,
                    lambda: it.lambda,
                    accepted: it.accepted,
                    failed: it.failed,
                    jacobian: it.jacobian,
                    runs: book.runs.load(Ordering::SeqCst),
                    wall_s: book.clock.elapsed().as_secs_f64(),
                };
                on_event(&Event::Iteration(rec.clone()));
                cell.lock().expect("no panics hold it").push(rec);
            }
        };
        // The coarse stage, if any: its answer and Jacobian start the fine one.
        let mut start = (x0.clone(), r_before.clone(), None);
        let mut capped = None;
        if let Some((name, v)) = &self.options.coarse {
            on_event(&Event::Stage(format!("coarse ({name} = {v})")));
            let r0 = self.evaluate(
                std::slice::from_ref(&x0),
                Level::Coarse,
                lsq::Purpose::Start,
                &book,
                on_event,
            );
            match r0.map(|mut v| v.pop().expect("one point")) {
                Ok(Ok((r0, _))) => {
                    let coarse_opts = lsq::Options {
                        xtol: 10.0 * opts.xtol,
                        fresh_at_end: false,
                        ..opts
                    };
                    let mut eval = |pts: &[Vec<f64>], why| {
                        self.residuals(pts, Level::Coarse, why, &book, on_event)
                    };
                    let mut hook = hook_for("coarse");
                    let out =
                        lsq::minimise(&x0, r0, None, &bounds, &coarse_opts, &mut eval, &mut hook);
                    failed_points += out.failed_points;
                    if let lsq::Stop::Capped(c) = out.stop {
                        capped = Some(c);
                    }
                    on_event(&Event::Stage("fine".into()));
                    if out.x != x0 && capped.is_none() {
                        match self.evaluate(
                            std::slice::from_ref(&out.x),
                            Level::Fine,
                            lsq::Purpose::Start,
                            &book,
                            on_event,
                        ) {
                            Ok(mut v) => {
                                if let Ok((r, _)) = v.pop().expect("one point") {
                                    start = (out.x, r, Some(out.j));
                                } else {
                                    failed_points += 1;
                                }
                            }
                            Err(c) => capped = Some(c),
                        }
                    } else if capped.is_none() {
                        start.2 = Some(out.j);
                    }
                }
                Ok(Err(_)) => failed_points += 1,
                Err(c) => capped = Some(c),
            }
        }
        let (xs, rs, js) = start;
        let out = match capped {
            Some(c) => lsq::Outcome {
                x: xs,
                r: rs,
                j: js.unwrap_or_else(|| linalg::Mat::zeros(r_before.len(), x0.len())),
                j_fresh: false,
                stop: lsq::Stop::Capped(c),
                failed_points: 0,
            },
            None => {
                let mut eval =
                    |pts: &[Vec<f64>], why| self.residuals(pts, Level::Fine, why, &book, on_event);
                let mut hook = hook_for("fine");
                lsq::minimise(&xs, rs, js, &bounds, &opts, &mut eval, &mut hook)
            }
        };
        failed_points += out.failed_points;
        let fitted = book
            .fine
            .lock()
            .expect("no panics hold it")
            .iter()
            .rev()
            .find(|(x, _)| *x == out.x)
            .map(|(_, v)| v.clone())
            .expect("the best point was run at the fine resolution");
        let u = stats::uncertainty(&names, &out.x, &out.j, &out.r);
        let outcome = match out.stop {
            lsq::Stop::Converged => Outcome::Converged,
            lsq::Stop::NoProgress => Outcome::NoProgress,
            lsq::Stop::Iterations => Outcome::IterationCap,
            lsq::Stop::Capped(lsq::Cap::Runs) => Outcome::RunCap,
            lsq::Stop::Capped(lsq::Cap::Wall) => Outcome::WallCap,
        };
        let mut at_fit = self.base.clone();
        for (f, v) in self.free.iter().zip(&out.x) {
            at_fit.set(&f.name, *v)?;
        }
        let spent = book.spent();
        let failures = book.failures.into_inner().expect("no panics hold it");
        let failed_runs = failures.iter().map(|(_, n)| n).sum();
        let iterations = iterations_cell.into_inner().expect("no panics hold it");
        Ok(CalibrationResult {
            scene: self.base.kind().name().to_string(),
            free: self.free.clone(),
            start: x0,
            parameters: out.x.clone(),
            std: u.std,
            correlation: u.correlation,
            identifiable: u.identifiable,
            shots: self.shots.clone(),
            before: values_before,
            fitted,
            objective: (lsq::objective(&r_before), lsq::objective(&out.r)),
            dof: u.dof,
            runs: book.runs.load(Ordering::SeqCst),
            runs_coarse: book.runs_coarse.load(Ordering::SeqCst),
            failed_runs,
            failed_points,
            failures,
            iterations,
            wall_time_s: clock.elapsed().as_secs_f64(),
            spent,
            outcome,
            jacobian_at_optimum: out.j_fresh,
            jacobian: (0..out.j.rows)
                .map(|i| (0..out.j.cols).map(|k| out.j[(i, k)]).collect())
                .collect(),
            options: self.options.clone(),
            material_toml: at_fit.material_toml(),
            leave_one_out: self
                .options
                .leave_one_out
                .map(|m| self.leave_one_out(m, &out.x, &out.j, &out.r, &bounds, &opts)),
        })
    }

    /// Each experiment predicted from the constants fitted to the others.
    /// Each such fit starts at the whole fit's answer `x` with its Jacobian
    /// `j` and residuals `r` less the experiment's rows: linearised, it is
    /// one Gauss-Newton step from there (no runs); refitted, the search
    /// goes on to its first small step (no fresh Jacobian: only the
    /// constants are wanted). The experiments are then run at their
    /// constants in one parallel batch.
    fn leave_one_out(
        &self,
        method: LeaveOneOutMethod,
        x: &[f64],
        j: &linalg::Mat,
        r: &[f64],
        bounds: &[(f64, f64)],
        opts: &lsq::Options,
    ) -> LeaveOneOut {
        let clock = Instant::now();
        let mut runs = 0;
        let mut constants = Vec::new();
        let mut first_row = 0;
        for (k, left) in self.shots.iter().enumerate() {
            let rows = left.measurements();
            let keep: Vec<usize> = (0..r.len())
                .filter(|i| !(first_row..first_row + rows).contains(i))
                .collect();
            first_row += rows;
            let mut jk = linalg::Mat::zeros(keep.len(), x.len());
            for (a, &i) in keep.iter().enumerate() {
                for b in 0..x.len() {
                    jk[(a, b)] = j[(i, b)];
                }
            }
            let rk: Vec<f64> = keep.iter().map(|&i| r[i]).collect();
            constants.push(match method {
                LeaveOneOutMethod::Linearised => {
                    let step = lsq::gauss_newton_step(&jk, &rk, x, bounds);
                    x.iter()
                        .zip(&step)
                        .map(|(x, d)| x + d)
                        .collect::<Vec<f64>>()
                }
                LeaveOneOutMethod::Refit => {
                    let mut sub = self.clone();
                    sub.shots.remove(k);
                    sub.options.leave_one_out = None;
                    let book = Book::new();
                    let mut eval = |pts: &[Vec<f64>], why| {
                        sub.residuals(pts, Level::Fine, why, &book, &|_| {})
                    };
                    let sub_opts = lsq::Options {
                        fresh_at_end: false,
                        ..*opts
                    };
                    let out =
                        lsq::minimise(x, rk, Some(jk), bounds, &sub_opts, &mut eval, &mut |_| {});
                    runs += book.runs.load(Ordering::SeqCst);
                    out.x
                }
            });
        }
        let book = Book::new();
        let predictions: Vec<_> = self
            .shots
            .par_iter()
            .zip(constants)
            .map(|(shot, xk)| {
                self.run_shot(shot, &xk, Level::Fine, &book)
                    .map(|v| (xk, v))
                    .map_err(|e| e.to_string())
            })
            .collect();
        LeaveOneOut {
            method,
            predictions,
            runs: runs + self.shots.len(),
            wall_time_s: clock.elapsed().as_secs_f64(),
        }
    }

    /// The weighted residuals of each point (for the search).
    fn residuals(
        &self,
        points: &[Vec<f64>],
        level: Level,
        purpose: lsq::Purpose,
        book: &Book,
        on_event: &(dyn Fn(&Event) + Sync),
    ) -> lsq::Batch {
        Ok(self
            .evaluate(points, level, purpose, book, on_event)?
            .into_iter()
            .map(|r| r.ok().map(|(r, _)| r))
            .collect())
    }

    /// Runs every experiment at every point, in parallel: per point, the
    /// weighted residuals and the simulated values, or the first shot whose
    /// run failed with its error.
    #[allow(clippy::type_complexity)]
    fn evaluate(
        &self,
        points: &[Vec<f64>],
        level: Level,
        purpose: lsq::Purpose,
        book: &Book,
        on_event: &(dyn Fn(&Event) + Sync),
    ) -> std::result::Result<
        Vec<std::result::Result<(Vec<f64>, Vec<ShotValues>), (String, Error)>>,
        lsq::Cap,
    > {
        let n = points.len() * self.shots.len();
        if book.runs.load(Ordering::SeqCst) + n > self.options.max_runs {
            return Err(lsq::Cap::Runs);
        }
        if book.clock.elapsed().as_secs_f64() >= self.options.max_wall_s {
            return Err(lsq::Cap::Wall);
        }
        book.runs.fetch_add(n, Ordering::SeqCst);
        if level == Level::Coarse {
            book.runs_coarse.fetch_add(n, Ordering::SeqCst);
        }
        on_event(&Event::Batch { runs: n });
        let batch_clock = Instant::now();
        let ns = self.shots.len();
        let results: Vec<Result<ShotValues>> = (0..n)
            .into_par_iter()
            .map(|k| {
                let (point, shot) = (&points[k / ns], &self.shots[k % ns]);
                let r = self.run_shot(shot, point, level, book);
                on_event(&Event::RunDone);
                r
            })
            .collect();
        book.tally(purpose, n, batch_clock.elapsed().as_secs_f64());
        if results
            .iter()
            .any(|r| matches!(r, Err(Error::Cancelled { .. })))
        {
            return Err(lsq::Cap::Wall);
        }
        let mut out = Vec::new();
        for (p, chunk) in results.chunks(ns).enumerate() {
            let mut failed = None;
            let mut values = Vec::new();
            for (shot, r) in self.shots.iter().zip(chunk) {
                match r {
                    Ok(v) => values.push(v.clone()),
                    Err(e) => {
                        let mut f = book.failures.lock().expect("no panics hold it");
                        match f.iter_mut().find(|(name, _)| name == e.name()) {
                            Some((_, k)) => *k += 1,
                            None => f.push((e.name().to_string(), 1)),
                        }
                        failed.get_or_insert_with(|| (shot.label.clone(), e.clone()));
                    }
                }
            }
            out.push(match failed {
                Some(f) => Err(f),
                None => {
                    if level == Level::Fine {
                        book.fine
                            .lock()
                            .expect("no panics hold it")
                            .push((points[p].clone(), values.clone()));
                    }
                    Ok((self.weighted_residuals(&values), values))
                }
            });
        }
        Ok(out)
    }

    /// One experiment at one point.
    fn run_shot(&self, shot: &Shot, x: &[f64], level: Level, book: &Book) -> Result<ShotValues> {
        let scene = self.scene_at(shot, x, level)?;
        let mut sim = Simulation::new(scene)?;
        let cap = self.options.max_wall_s;
        sim.run_with(|_| book.clock.elapsed().as_secs_f64() < cap)?;
        let values = shot
            .observed
            .iter()
            .map(|m| {
                sim.observable(&m.name)
                    .ok_or_else(|| Error::Inconsistent(format!("no observable {}", m.name)))
            })
            .collect::<Result<Vec<f64>>>()?;
        let outline = match &shot.outline {
            Some(_) => Some(sim.rod_profile().ok_or_else(|| {
                Error::Inconsistent(format!(
                    "shot {} has an outline, but scene `{}` has no rod to outline",
                    shot.label,
                    self.base.kind().name()
                ))
            })?),
            None => None,
        };
        Ok(ShotValues { values, outline })
    }

    /// The weighted residuals of simulated values, shot by shot in order:
    /// each measurement's `(simulated - measured) / sigma`, with `sigma` the
    /// file's or [`DEFAULT_RELATIVE_SIGMA`] of the measured value; then each
    /// outline point's radius the same way.
    fn weighted_residuals(&self, values: &[ShotValues]) -> Vec<f64> {
        let mut r = Vec::new();
        for (shot, v) in self.shots.iter().zip(values) {
            for (m, sim) in shot.observed.iter().zip(&v.values) {
                let sigma = m.sigma.unwrap_or(DEFAULT_RELATIVE_SIGMA * m.value.abs());
                r.push((sim - m.value) / sigma);
            }
            if let (Some(o), Some(sim)) = (&shot.outline, &v.outline) {
                for [z, radius] in &o.points {
                    let sigma = o.sigma.unwrap_or(DEFAULT_RELATIVE_SIGMA * radius);
                    r.push((outline_radius(sim, *z) - radius) / sigma);
                }
            }
        }
        r
    }
}

/// The simulated outline's radius at height `z`: the first point's below
/// it, 0 above the rod's end.
pub fn outline_radius(outline: &[[f64; 2]], z: f64) -> f64 {
    match (outline.first(), outline.last()) {
        (Some(first), _) if z <= first[0] => first[1],
        (_, Some(last)) if z > last[0] => 0.0,
        _ => crate::rod::profile_radius(outline, z).unwrap_or(0.0),
    }
}

/// What a fit books while it runs.
struct Book {
    runs: AtomicUsize,
    runs_coarse: AtomicUsize,
    failures: Mutex<Vec<(String, usize)>>,
    /// Every point run at the fine resolution, with its values.
    #[allow(clippy::type_complexity)]
    fine: Mutex<Vec<(Vec<f64>, Vec<ShotValues>)>>,
    clock: Instant,
    /// Runs and wall time (s) of the batches, by purpose.
    spent: Mutex<Vec<(lsq::Purpose, usize, f64)>>,
}

impl Book {
    fn new() -> Book {
        Book {
            runs: AtomicUsize::new(0),
            runs_coarse: AtomicUsize::new(0),
            failures: Mutex::new(Vec::new()),
            fine: Mutex::new(Vec::new()),
            clock: Instant::now(),
            spent: Mutex::new(Vec::new()),
        }
    }

    /// Books a batch of `runs` that took `wall` seconds, for `purpose`.
    fn tally(&self, purpose: lsq::Purpose, runs: usize, wall: f64) {
        let mut spent = self.spent.lock().expect("no panics hold it");
        match spent.iter_mut().find(|(p, _, _)| *p == purpose) {
            Some((_, n, w)) => {
                *n += runs;
                *w += wall;
            }
            None => spent.push((purpose, runs, wall)),
        }
    }

    /// What was booked, in [`lsq::Purpose::ALL`]'s order.
    fn spent(&self) -> Vec<(&'static str, usize, f64)> {
        let spent = self.spent.lock().expect("no panics hold it");
        lsq::Purpose::ALL
            .iter()
            .filter_map(|p| spent.iter().find(|(q, _, _)| q == p))
            .map(|(p, n, w)| (p.name(), *n, *w))
            .collect()
    }
}
