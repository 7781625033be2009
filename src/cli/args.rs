//! The command line: the subcommands and their arguments, and how the
//! choices and `--set`s apply to a scene.

use clap::{Args, Parser, Subcommand};
use meshless_impact::{Error, Scene};
use std::path::PathBuf;

/// Meshless (MSPH) solver for high-speed impact of solids.
///
/// With no subcommand it runs the default scene, `taylor` (House et al. test
/// 7), and prints the final observables beside the experiment.
#[derive(Parser)]
#[command(version, about, long_about = None)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Option<Command>,
}

#[derive(Subcommand)]
pub(crate) enum Command {
    /// Run one scene to its end condition.
    Run(RunArgs),
    /// Run a family of scenes in parallel: `table1` is the twelve tests of Table 1.
    Sweep(SweepArgs),
    /// Fit named parameters of a scene (a material's constants) to the
    /// measured observables of a set of experiments: writes
    /// DIR/calibration.json, DIR/material.toml and DIR/fit.svg.
    Calibrate(CalibrateArgs),
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
        /// Print the code's physics digest (the bits of small runs of every
        /// solver, as the report records it) and write nothing.
        #[arg(long)]
        digest: bool,
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
pub(crate) struct ChoiceArgs {
    /// Numerical scheme by name (`meshless-impact params SCENE` lists the
    /// scene's schemes and what each sets); --set may override its knobs.
    #[arg(long, value_name = "NAME")]
    pub(crate) scheme: Option<String>,
    /// Strength model: johnson_cook or bilinear.
    #[arg(long, value_name = "MODEL")]
    pub(crate) strength: Option<String>,
    /// Equation of state: linear or mie_gruneisen.
    #[arg(long, value_name = "EOS")]
    pub(crate) eos: Option<String>,
    /// A material preset (`meshless-impact materials` lists them): its
    /// models and constants; --set may override its constants.
    #[arg(long, value_name = "NAME")]
    pub(crate) preset: Option<String>,
    /// A material file: a TOML `[material]` table as a scene file's (the
    /// `material.toml` that `calibrate` writes), applied after --preset;
    /// --set may override its constants.
    #[arg(long, value_name = "FILE")]
    pub(crate) preset_file: Option<PathBuf>,
}

impl ChoiceArgs {
    /// Whether any choice is made.
    pub(crate) fn any(&self) -> bool {
        self.scheme.is_some()
            || self.strength.is_some()
            || self.eos.is_some()
            || self.preset.is_some()
            || self.preset_file.is_some()
    }

    /// Applies the choices to `scene`, if any is made.
    pub(crate) fn apply(&self, scene: &mut Scene) -> Result<(), Error> {
        if let Some(name) = &self.scheme {
            scene.set_str("scheme", name)?;
        }
        if self.strength.is_some() || self.eos.is_some() || self.preset.is_some() {
            scene.choose_material(
                self.strength.as_deref(),
                self.eos.as_deref(),
                self.preset.as_deref(),
            )?;
        }
        if let Some(path) = &self.preset_file {
            scene.apply_material_file(path)?;
        }
        Ok(())
    }
}

#[derive(Args, Default)]
pub(crate) struct RunArgs {
    /// Built-in scene (`meshless-impact scenes` lists them; default
    /// `taylor`, or the checkpoint's with --restart).
    #[arg(conflicts_with = "scene_file")]
    pub(crate) scene: Option<String>,
    /// Read the scene from a TOML file instead.
    #[arg(long, value_name = "FILE")]
    pub(crate) scene_file: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) material: ChoiceArgs,
    /// Override a parameter, e.g. `--set impact_speed=200` (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub(crate) set: Vec<String>,
    /// Save the whole run (state, histories, snapshot times, outputs) to
    /// FILE every --checkpoint-every seconds and when stopped by SIGTERM or
    /// SIGINT; each write replaces the last whole (docs/guide/checkpoints.md).
    #[arg(long, value_name = "FILE")]
    pub(crate) checkpoint: Option<PathBuf>,
    /// Wall-clock seconds between checkpoints (default 300).
    #[arg(long, value_name = "SECONDS")]
    pub(crate) checkpoint_every: Option<f64>,
    /// Also checkpoint every N steps.
    #[arg(long, value_name = "N")]
    pub(crate) checkpoint_steps: Option<u64>,
    /// Continue the run saved in a checkpoint FILE, to the bits of the run
    /// that was never stopped, with its outputs and checkpoints unless
    /// given again; a scene or parameters given must agree with it.
    #[arg(long, value_name = "FILE")]
    pub(crate) restart: Option<PathBuf>,
    /// Write the final observables as JSON.
    #[arg(long, value_name = "FILE")]
    pub(crate) json: Option<PathBuf>,
    /// Write the observable time histories as CSV.
    #[arg(long, value_name = "FILE")]
    pub(crate) csv: Option<PathBuf>,
    /// Write the rod's final outline as CSV: axial position and radius (m) of
    /// one generator of the mantle, from the impact face to the free end
    /// (scenes with a rod).
    #[arg(long, value_name = "FILE")]
    pub(crate) profile: Option<PathBuf>,
    /// Directory for VTK (.vtu) particle snapshots.
    #[arg(long, value_name = "DIR")]
    pub(crate) vtk_dir: Option<PathBuf>,
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
    pub(crate) vtk_times: Vec<f64>,
    /// Compiled copy of the hot loops: avx512, avx2+fma or baseline (default:
    /// the best this processor runs). Every copy gives the same bits; this is
    /// for measuring them.
    #[arg(long, value_name = "COPY")]
    pub(crate) isa: Option<String>,
    /// No progress bar and no table on stdout (errors are still reported).
    #[arg(long, short)]
    pub(crate) quiet: bool,
    /// At the end, print the wall time of each phase of the solver's steps
    /// to stderr (the 3-D scenes; on MPI's ranks, each rank its own).
    #[arg(long)]
    pub(crate) phases: bool,
}

#[derive(Args)]
pub(crate) struct SweepArgs {
    /// The sweep to run: `table1`.
    pub(crate) name: String,
    /// CSV file for the results table.
    #[arg(long, default_value = "table1_sweep.csv")]
    pub(crate) out: PathBuf,
    /// Override a parameter in every case, e.g. `--set particles_radial=10`.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub(crate) set: Vec<String>,
}

#[derive(Args)]
pub(crate) struct CalibrateArgs {
    /// Built-in scene (`meshless-impact scenes` lists them).
    #[arg(default_value = "taylor", conflicts_with = "scene_file")]
    pub(crate) scene: String,
    /// Read the scene (the fixed part of the fit) from a TOML file instead.
    #[arg(long, value_name = "FILE")]
    pub(crate) scene_file: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) material: ChoiceArgs,
    /// Fix a parameter in every experiment, e.g. `--set particles_radial=20`
    /// (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub(crate) set: Vec<String>,
    /// The experiments: a CSV file, one row per experiment; each column a
    /// parameter of the scene (a setting) or an observable (a measurement),
    /// with optional `sigma_NAME`, `shot`, `outline` and `sigma_outline`
    /// columns (docs/guide/calibration.md).
    #[arg(long, value_name = "FILE.csv")]
    pub(crate) shots: PathBuf,
    /// A free parameter and its bounds, e.g. `--free jc_a=600e6:1200e6`
    /// (repeatable); it starts from the scene's value.
    #[arg(long = "free", value_name = "NAME=LO:HI", required = true)]
    pub(crate) free: Vec<String>,
    /// Output directory: calibration.json, material.toml, fit.svg.
    #[arg(long, value_name = "DIR")]
    pub(crate) out: PathBuf,
    /// Cap on forward runs (one experiment at one point is one run).
    #[arg(long, value_name = "N", default_value_t = 400)]
    pub(crate) max_runs: usize,
    /// Cap on wall time, seconds.
    #[arg(long, value_name = "SECONDS", default_value_t = 3600.0)]
    pub(crate) max_wall: f64,
    /// Fit at a coarser resolution first, e.g. `--coarse particles_radial=10`;
    /// the fine stage starts from its answer and its Jacobian.
    #[arg(long, value_name = "NAME=VALUE")]
    pub(crate) coarse: Option<String>,
    /// Finite-difference step, relative to a parameter's value.
    #[arg(long, value_name = "FRACTION", default_value_t = 0.01)]
    pub(crate) fd_step: f64,
    /// Converged when a step moves each parameter by less than this
    /// fraction of its value, or by less than a tenth of its standard error
    /// while it would lower the objective by less than a quarter of the
    /// residual's scale.
    #[arg(long, value_name = "FRACTION", default_value_t = 1e-3)]
    pub(crate) xtol: f64,
    /// The method: `broyden` (the default: the finite-difference Jacobian
    /// carried from point to point by Broyden's updates) or `plain` (taken
    /// afresh at every accepted point).
    #[arg(long, value_name = "METHOD", default_value = "broyden", value_parser = ["broyden", "plain"])]
    pub(crate) method: String,
    /// After the fit, predict each experiment from the constants fitted to
    /// the others (cross-validation; its runs are counted apart):
    /// `linearised` (the default: one Gauss-Newton step from the whole
    /// fit's answer, then one run per experiment) or `refit` (the search
    /// from there for each experiment left out).
    #[arg(long, value_name = "METHOD", num_args = 0..=1, default_missing_value = "linearised",
          value_parser = ["linearised", "refit"])]
    pub(crate) leave_one_out: Option<String>,
    /// No progress bar and no iteration lines (the summary is printed).
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

/// Applies `--set NAME=VALUE`s: a scheme first (`--set scheme=paper`),
/// then the other parameters, which override its knobs.
pub(crate) fn apply_sets(scene: &mut Scene, sets: &[String]) -> Result<(), Error> {
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
