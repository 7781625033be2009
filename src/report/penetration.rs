//! The seed's ballistic case (seed 004, section 5.2): a tungsten rod through
//! an AD85 plate, with the crack density of the plate in a slice through
//! the axis at 4, 8, 12 and 20 µs, and the projectile's velocity history.

use super::plot::{self, Axes, Plane, Series};
use super::runner::{Probe, run_case, run_parallel, scene};
use super::{Doc, Plan, Table, sig};
use meshless_impact::Result;
use meshless_impact::materials::RajendranGrove;

/// The seed's residual velocity (m/s).
const SEED_RESIDUAL: f64 = 1240.0;

/// Times of the damage pictures (s).
const TIMES: [f64; 4] = [4e-6, 8e-6, 12e-6, 20e-6];

/// Half-width of the pictures (m): the plate is 80 mm across, the damage
/// within a few projectile radii of the axis.
const HALF_WIDTH: f64 = 20e-3;

/// Half-width of the rear-face pictures (m): the whole plate's radius,
/// where radial cracks run to.
const RADIAL_HALF_WIDTH: f64 = 40e-3;

/// Critical crack density of pulverization (the top of the colour scale).
const PULVERIZED: f64 = 0.75;

pub(super) fn damage(plan: &Plan, doc: &mut Doc) -> Result<()> {
    // The scene's default (6 across) in the full plan; 4 across (7463
    // nodes, about 20 s) in the quick one.
    let across = if plan.quick { 4.0 } else { 6.0 };
    super::progress!("report: penetration, {across} nodes across");
    let probe = Probe {
        snapshot_times: TIMES.to_vec(),
        ..Probe::default()
    };
    let run = run_case(
        scene("penetration", &[("particles_radial", across)]),
        &probe,
    );
    // The node spacing of the run: the projectile's radius over its rings.
    let radius = run
        .scene
        .as_ref()
        .and_then(|s| s.get("projectile_diameter").ok())
        .map_or(f64::NAN, |d| 0.5 * d);
    let spacing = radius / (across - 1.0);
    let ceramic = run
        .scene
        .as_ref()
        .and_then(|s| s.level("plate_ceramic").ok().flatten())
        .map_or("?", |l| l.name);
    doc.para(&format!(
        "## 7. Ballistic penetration: the damage zones\n\n\
         The seed's case (004, section 5.2): a tungsten rod 10 mm long and 10 mm across at \
         1500 m/s through an AD85 plate 5 mm thick and 80 mm across, by the 3-D MLPG solver \
         with the scene's choices (README, \"Ballistic penetration\") and its default ceramic \
         (`plate_ceramic = {ceramic}`; `ad85_seed` is the seed's Table 1 as printed), at {across} nodes across \
         the projectile's radius ({} nodes): {} at {:.2} µs after {} steps in {:.1} s. \
         Projectile velocity at the end {:.1} m/s (the seed's residual velocity: \
         {SEED_RESIDUAL} m/s, {:+.1} %), energy error {}. The residual velocity under \
         refinement, 4 to 12 nodes across as a quarter model (runs of up to an hour, not \
         made by this report), its energy errors and the converged value with its \
         uncertainty are in VALIDATION.md (\"penetration\").",
        run.particles,
        run.outcome.label(),
        run.time * 1e6,
        run.steps,
        run.wall_s,
        run.get("projectile_velocity"),
        100.0 * (run.get("projectile_velocity") / SEED_RESIDUAL - 1.0),
        sig(run.get("energy_error"), 3),
    ));
    let h = &run.history;
    let col = |name: &str| h.column(name).expect("penetration observable");
    let t_us: Vec<f64> = h.times.iter().map(|t| t * 1e6).collect();
    let v: Vec<(f64, f64)> = t_us
        .iter()
        .zip(col("projectile_velocity"))
        .map(|(t, v)| (*t, v))
        .collect();
    doc.lines(
        "penetration_velocity.svg",
        Axes::linear(
            "Penetration: projectile velocity (centre of mass)",
            "time (µs)",
            "velocity (m/s)",
        ),
        &[
            Series::line("projectile_velocity", v),
            Series::line(
                "the seed's residual velocity",
                vec![
                    (0.0, SEED_RESIDUAL),
                    (t_us.last().copied().unwrap_or(20.0), SEED_RESIDUAL),
                ],
            ),
        ],
    )?;
    let mut zones = Table::new(
        "penetration_zones",
        &[
            "time_us",
            "projectile_velocity_mps",
            "hole_radius_mm",
            "damaged_fraction",
            "pulverized_fraction",
            "cone_half_angle_deg",
            "radial_crack_count",
            "comminuted_radius_mm",
            "energy_error",
        ],
    );
    // The record at or just after each picture's time.
    let at = |t: f64, name: &str| {
        let k = h.times.iter().position(|&s| s >= t).unwrap_or(h.len() - 1);
        col(name)[k]
    };
    let param = |name: &str| {
        run.scene
            .as_ref()
            .and_then(|s| s.get(name).ok())
            .unwrap_or(f64::NAN)
    };
    let thickness = param("plate_thickness");
    // The colour scale: log10 of the crack density, from the plate's
    // initial one to pulverization.
    let ceramic = RajendranGrove {
        flaw_density: param("plate_flaw_density"),
        initial_crack_size: param("plate_crack_size"),
        critical_damage: param("plate_critical_damage"),
        ..RajendranGrove::ad85()
    };
    let gamma0 = ceramic.crack_density(ceramic.initial_crack_size);
    let scale = (gamma0.log10().floor(), PULVERIZED.log10());
    let mut slices = Vec::new();
    for snap in &run.snapshots {
        let body = &snap.field("body").expect("penetration field").data;
        let gamma = &snap.field("damage").expect("penetration field").data;
        let place = &snap
            .field("place_at_impact")
            .expect("penetration field")
            .data;
        let (mut plate, mut values, mut projectile) = (Vec::new(), Vec::new(), Vec::new());
        let (mut rear, mut rear_values) = (Vec::new(), Vec::new());
        for (i, p) in snap.positions.iter().enumerate() {
            let z0 = place[3 * i + 2];
            if body[i] != 0.0 && (z0 + thickness).abs() < 0.5 * spacing {
                rear.push((place[3 * i], place[3 * i + 1]));
                rear_values.push(gamma[i]);
            }
            if p[1].abs() >= 0.5 * spacing {
                continue;
            }
            if body[i] == 0.0 {
                projectile.push((p[0], p[2]));
            } else {
                plate.push((p[0], p[2]));
                values.push(gamma[i]);
            }
        }
        let t = snap.time;
        zones.push(vec![
            sig(t * 1e6, 4),
            sig(at(t, "projectile_velocity"), 5),
            sig(at(t, "hole_radius") * 1e3, 4),
            sig(at(t, "damaged_fraction"), 3),
            sig(at(t, "pulverized_fraction"), 3),
            sig(at(t, "cone_half_angle"), 3),
            sig(at(t, "radial_crack_count"), 3),
            sig(at(t, "comminuted_radius") * 1e3, 3),
            sig(at(t, "energy_error"), 3),
        ]);
        slices.push((t, plate, values, projectile, rear, rear_values));
    }
    doc.para(&format!(
        "log10 of the crack density γ of the plate in the slice |y| < {:.2} mm through the \
         axis (x, z in mm; the plate's top face at z = 0), the projectile grey, from the \
         plate's initial γ0 = {} (log10 {:.0}) to γ = {PULVERIZED}, pulverized, so that \
         partial damage shows; beside each, the plate's rear face at the material's place at \
         impact (x0, y0 in mm), where radial cracks show. The table gives the observables of \
         the failure modes at each time (docs/methods/penetration.md, \"Failure modes\"): \
         `cone_half_angle` from the axis, fitted to the damage front of the layers from the \
         struck to the rear face (the classical ceramic-armour models put it at 60-70°; \
         Florence's a + 2h gives 63°; 0 where no front runs through the thickness, negative \
         for a crater), `radial_crack_count` on the rear face at the projectile's diameter, \
         and `comminuted_radius`, the pulverized zone about the axis. \
         The fields at each time, `log10_damage` and `crack_size` among them, are in \
         the VTK snapshots of `meshless-impact run penetration --vtk-dir DIR --vtk-times \
         4e-6,8e-6,12e-6`.",
        0.5e3 * spacing,
        sig(gamma0, 3),
        scale.0,
    ));
    let log10 = |gamma: &[f64]| -> Vec<f64> {
        gamma
            .iter()
            .map(|g| g.max(1e-300).log10().max(scale.0))
            .collect()
    };
    for (time, plate, gamma, projectile, rear, rear_gamma) in &slices {
        let mm = |q: &(f64, f64)| (q.0 * 1e3, q.1 * 1e3);
        let plate: Vec<(f64, f64)> = plate.iter().map(mm).collect();
        let projectile: Vec<(f64, f64)> = projectile.iter().map(mm).collect();
        let values = log10(gamma);
        let zs = plate.iter().chain(&projectile).map(|q| q.1);
        let (z0, z1) = zs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), z| {
            (a.min(z), b.max(z))
        });
        let label = format!("{:.0}us", (time * 1e6).round());
        let file = format!("penetration_damage_{label}.svg");
        let title = format!("Penetration, t = {:.1} µs: log10 crack density", time * 1e6);
        let w = HALF_WIDTH * 1e3;
        plot::plane(
            &doc.dir.join(&file),
            &Plane {
                title: &title,
                x: "x (mm)",
                y: "z (mm)",
                xs: (-w, w),
                ys: (z0 - 1.0, z1 + 1.0),
                values: scale,
            },
            &plate,
            &values,
            &projectile,
        )?;
        doc.image(&file, &title);
        let rear: Vec<(f64, f64)> = rear.iter().map(mm).collect();
        let file = format!("penetration_rear_{label}.svg");
        let title = format!("Rear face, t = {:.1} µs: log10 crack density", time * 1e6);
        let r = RADIAL_HALF_WIDTH * 1e3;
        plot::plane(
            &doc.dir.join(&file),
            &Plane {
                title: &title,
                x: "x0 (mm)",
                y: "y0 (mm)",
                xs: (-r, r),
                ys: (-r, r),
                values: scale,
            },
            &rear,
            &log10(rear_gamma),
            &[],
        )?;
        doc.image(&file, &title);
    }
    doc.table(&zones)?;
    Ok(())
}

/// Speeds of the ballistic-limit sweep (m/s): the full plan's and the
/// quick one's.
const SWEEP: [f64; 12] = [
    400.0, 500.0, 600.0, 700.0, 800.0, 900.0, 1000.0, 1100.0, 1200.0, 1300.0, 1400.0, 1500.0,
];
const QUICK_SWEEP: [f64; 3] = [500.0, 1000.0, 1500.0];

/// The cap of a shot's run (s): `run_until = outcome` ends it earlier.
const SWEEP_CAP: f64 = 6e-5;

/// The ballistic-limit sweep: the seed's case at a row of impact speeds,
/// each shot run until its outcome is decided (`run_until = outcome`,
/// README, "Ballistic limit"), as a quarter model at 4 nodes across (3 in
/// the quick plan). The table gives each shot's outcome and residual
/// velocity, the plot the residual velocity against the impact speed, and
/// the text the bracket of the ballistic limit (the fastest stopped shot
/// below the slowest perforating one). The Lambert-Jonas fit of the
/// shots, with its uncertainty, is `examples/ballistic_limit.py`'s
/// (VALIDATION.md gives it at the default resolution).
pub(super) fn ballistic_limit(plan: &Plan, doc: &mut Doc) -> Result<()> {
    let (across, speeds): (f64, &[f64]) = if plan.quick {
        (3.0, &QUICK_SWEEP)
    } else {
        (4.0, &SWEEP)
    };
    super::progress!(
        "report: ballistic limit, {} shots at {across} nodes across",
        speeds.len()
    );
    let scenes = speeds
        .iter()
        .map(|&v| {
            scene(
                "penetration",
                &[
                    ("particles_radial", across),
                    ("symmetry", 1.0),
                    ("impact_speed", v),
                    ("run_until", 1.0),
                    ("end_time", SWEEP_CAP),
                ],
            )
        })
        .collect();
    let runs = run_parallel(scenes, f64::INFINITY);
    let mut table = Table::new(
        "ballistic_limit",
        &[
            "impact_speed_mps",
            "outcome",
            "residual_velocity_mps",
            "decided_at_us",
            "hole_radius_mm",
            "energy_error",
        ],
    );
    let (mut stopped, mut through) = (f64::NEG_INFINITY, f64::INFINITY);
    let mut curve = Vec::new();
    for (&v, run) in speeds.iter().zip(&runs) {
        let outcome = if !run.finished() {
            run.outcome.label()
        } else {
            match run.get("shot_outcome") as u8 {
                1 => "perforated",
                2 => "stopped",
                _ => "undecided at the cap",
            }
        };
        let residual = match outcome {
            "perforated" => run.get("projectile_velocity"),
            "stopped" => 0.0,
            _ => f64::NAN,
        };
        if outcome == "stopped" {
            stopped = stopped.max(v);
        }
        if outcome == "perforated" {
            through = through.min(v);
        }
        if residual.is_finite() {
            curve.push((v, residual));
        }
        table.push(vec![
            sig(v, 4),
            outcome.to_string(),
            if residual.is_finite() {
                sig(residual, 5)
            } else {
                "—".into()
            },
            sig(run.time * 1e6, 4),
            sig(run.get("hole_radius") * 1e3, 4),
            sig(run.get("energy_error"), 3),
        ]);
    }
    let bracket = if stopped < through && stopped.is_finite() && through.is_finite() {
        format!("**the ballistic limit lies between {stopped} and {through} m/s**")
    } else {
        "the shots do not bracket the ballistic limit".to_string()
    };
    doc.para(&format!(
        "## 8. Ballistic penetration: the ballistic limit\n\n\
         The seed's case at each impact speed as a quarter model at {across} nodes across the \
         projectile's radius, each shot run until its outcome is decided by the state \
         (`run_until = outcome`, at most {:.0} µs; README, \"Ballistic limit\"); the plate's \
         rim is free. A stopped shot's residual velocity is 0. At this resolution {bracket} \
         (the fastest stopped shot and the slowest perforating one). The Lambert-Jonas fit \
         and its uncertainty at the default resolution are in VALIDATION.md (\"The ballistic \
         limit at the default resolution\"; `examples/ballistic_limit.py`).",
        SWEEP_CAP * 1e6,
    ));
    doc.table(&table)?;
    doc.lines(
        "ballistic_limit.svg",
        Axes::linear(
            "Ballistic limit: residual velocity against impact speed",
            "impact speed (m/s)",
            "residual velocity (m/s)",
        ),
        &[Series::markers("shots", curve)],
    )
}
