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

/// Critical crack density of pulverization (the top of the colour scale).
const PULVERIZED: f64 = 0.75;

/// The half-angle from the axis (degrees) of the cone the damaged plate
/// nodes fill (`points` (x, z) in m of the slice, `gamma` their crack
/// densities, `damaged` the crack density past which a node counts as
/// damaged, as the observable `damaged_fraction` counts it): the reach of
/// the damaged zone around the hole in the plate's back layer (z within
/// half a spacing of `-thickness`) less that in its top layer (z within
/// half a spacing of 0), over the thickness. A layer's reach is the
/// distance from the axis of the last node of the unbroken run of damaged
/// nodes that starts at the layer's innermost node, so that damage apart
/// from the hole (rings where the waves reflected from the rim meet) does
/// not count as the cone. `None` when either layer's innermost node is
/// intact, or the layer is empty.
fn cone_half_angle(
    points: &[(f64, f64)],
    gamma: &[f64],
    damaged: f64,
    thickness: f64,
    spacing: f64,
) -> Option<f64> {
    let reach = |z0: f64| {
        let mut layer: Vec<(f64, bool)> = points
            .iter()
            .zip(gamma)
            .filter(|((_, z), _)| (z - z0).abs() < 0.5 * spacing)
            .map(|((x, _), g)| (x.abs(), *g >= damaged))
            .collect();
        layer.sort_by(|a, b| a.0.total_cmp(&b.0));
        layer.iter().take_while(|(_, d)| *d).last().map(|(x, _)| *x)
    };
    let (top, back) = (reach(0.0)?, reach(-thickness)?);
    Some(((back - top) / thickness).atan().to_degrees())
}

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
    doc.para(&format!(
        "## 7. Ballistic penetration: the damage zones\n\n\
         The seed's case (004, section 5.2): a tungsten rod 10 mm long and 10 mm across at \
         1500 m/s through an AD85 plate 5 mm thick and 80 mm across, by the 3-D MLPG solver \
         with the scene's choices (README, \"Ballistic penetration\"), at {across} nodes across \
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
    let damaged = ceramic.damaged_threshold();
    let scale = (gamma0.log10().floor(), PULVERIZED.log10());
    let mut slices = Vec::new();
    for snap in &run.snapshots {
        let body = &snap.field("body").expect("penetration field").data;
        let gamma = &snap.field("damage").expect("penetration field").data;
        let (mut plate, mut values, mut projectile) = (Vec::new(), Vec::new(), Vec::new());
        for (i, p) in snap.positions.iter().enumerate() {
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
        let cone = cone_half_angle(&plate, &values, damaged, thickness, spacing);
        let t = snap.time;
        zones.push(vec![
            sig(t * 1e6, 4),
            sig(at(t, "projectile_velocity"), 5),
            sig(at(t, "hole_radius") * 1e3, 4),
            sig(at(t, "damaged_fraction"), 3),
            sig(at(t, "pulverized_fraction"), 3),
            cone.map_or("none".into(), |a| sig(a, 3)),
            sig(at(t, "energy_error"), 3),
        ]);
        slices.push((t, plate, values, projectile));
    }
    doc.para(&format!(
        "log10 of the crack density γ of the plate in the slice |y| < {:.2} mm through the \
         axis (x, z in mm; the plate's top face at z = 0), the projectile grey, from the \
         plate's initial γ0 = {} (log10 {:.0}) to γ = {PULVERIZED}, pulverized, so that \
         partial damage shows. The table's cone half-angle is measured from the axis: the \
         reach of the damaged zone (γ ≥ {}: 1 % of pulverization and twice γ0) around the \
         hole, the unbroken run of damaged nodes from the layer's innermost one, in the back \
         layer less that in the top layer, over the thickness (\"none\" when a layer's \
         innermost node is intact); damage apart from the hole does not count. \
         the classical ceramic-armour models put it at 60-70° (Florence's a + 2h gives \
         63°). The fields at each time, `log10_damage` and `crack_size` among them, are in \
         the VTK snapshots of `meshless-impact run penetration --vtk-dir DIR --vtk-times \
         4e-6,8e-6,12e-6`.",
        0.5e3 * spacing,
        sig(gamma0, 3),
        scale.0,
        sig(damaged, 3),
    ));
    for (time, plate, gamma, projectile) in &slices {
        let mm = |q: &(f64, f64)| (q.0 * 1e3, q.1 * 1e3);
        let plate: Vec<(f64, f64)> = plate.iter().map(mm).collect();
        let projectile: Vec<(f64, f64)> = projectile.iter().map(mm).collect();
        let values: Vec<f64> = gamma
            .iter()
            .map(|g| g.max(1e-300).log10().max(scale.0))
            .collect();
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

#[cfg(test)]
mod tests {
    use super::cone_half_angle;

    /// A slice with a damaged cone from 5 mm (top) to 15 mm (back) across
    /// a 5 mm plate, plus a damaged ring at 30 mm in both layers that the
    /// measure must not count: atan(10 / 5) = 63.4 degrees.
    #[test]
    fn the_cone_is_the_damaged_run_around_the_hole() {
        let (h, t) = (1e-3, 5e-3);
        let mut points = Vec::new();
        let mut gamma = Vec::new();
        for (z, edge) in [(0.0, 5e-3), (-t, 15e-3)] {
            for k in 1..=40 {
                let x = k as f64 * h;
                points.push((x, z));
                let ring = (x - 30e-3).abs() < 1.5e-3;
                gamma.push(if x <= edge + 1e-9 || ring { 0.75 } else { 1e-5 });
            }
        }
        let a = cone_half_angle(&points, &gamma, 0.0075, t, h).unwrap();
        assert!((a - (2.0f64).atan().to_degrees()).abs() < 1e-9, "{a}");
        // An intact innermost node in the top layer: no cone.
        gamma[0] = 1e-5;
        assert_eq!(cone_half_angle(&points, &gamma, 0.0075, t, h), None);
    }
}
