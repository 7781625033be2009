//! The seed's ballistic case (seed 004, section 5.2): a tungsten rod through
//! an AD85 plate, with the crack density of the plate in a slice through
//! the axis at 4, 8, 12 and 20 µs, and the projectile's velocity history.

use super::plot::{self, Axes, Plane, Series};
use super::runner::{Probe, run_case, scene};
use super::{Doc, Plan, Table, sig};
use meshless_impact::Result;

/// The seed's residual velocity (m/s).
const SEED_RESIDUAL: f64 = 1240.0;

/// Times of the damage pictures (s).
const TIMES: [f64; 4] = [4e-6, 8e-6, 12e-6, 20e-6];

/// Half-width of the pictures (m): the plate is 80 mm across, the damage
/// within a few projectile radii of the axis.
const HALF_WIDTH: f64 = 20e-3;

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
    doc.para(&format!(
        "## 7. Ballistic penetration: the damage zones\n\n\
         The seed's case (004, section 5.2): a tungsten rod 10 mm long and 10 mm across at \
         1500 m/s through an AD85 plate 5 mm thick and 80 mm across, by the 3-D MLPG solver \
         with the scene's choices (README, \"Ballistic penetration\"), at {across} nodes across \
         the projectile's radius ({} nodes): {} at {:.2} µs after {} steps in {:.1} s. \
         Projectile velocity at the end {:.1} m/s (the seed's residual velocity: \
         {SEED_RESIDUAL} m/s, {:+.1} %), energy error {}.",
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
            "energy_error",
        ],
    );
    // The record at or just after each picture's time.
    let at = |t: f64, name: &str| {
        let k = h.times.iter().position(|&s| s >= t).unwrap_or(h.len() - 1);
        col(name)[k]
    };
    for snap in &run.snapshots {
        let t = snap.time;
        zones.push(vec![
            sig(t * 1e6, 4),
            sig(at(t, "projectile_velocity"), 5),
            sig(at(t, "hole_radius") * 1e3, 4),
            sig(at(t, "damaged_fraction"), 3),
            sig(at(t, "pulverized_fraction"), 3),
            sig(at(t, "energy_error"), 3),
        ]);
    }
    doc.para(&format!(
        "Crack density γ of the plate in the slice |y| < {:.2} mm through the axis (x, z in \
         mm; the plate's top face at z = 0), the projectile grey; γ = {PULVERIZED} is \
         pulverized. The fields at each time are in the VTK snapshots of \
         `meshless-impact run penetration --vtk-dir DIR --vtk-times 4e-6,8e-6,12e-6`.",
        0.5e3 * spacing
    ));
    for snap in &run.snapshots {
        let body = &snap.field("body").expect("penetration field").data;
        let gamma = &snap.field("damage").expect("penetration field").data;
        let mut plate = Vec::new();
        let mut values = Vec::new();
        let mut projectile = Vec::new();
        for (i, p) in snap.positions.iter().enumerate() {
            if p[1].abs() >= 0.5 * spacing {
                continue;
            }
            let q = (p[0] * 1e3, p[2] * 1e3);
            if body[i] == 0.0 {
                projectile.push(q);
            } else {
                plate.push(q);
                values.push(gamma[i]);
            }
        }
        let zs = plate.iter().chain(&projectile).map(|q| q.1);
        let (z0, z1) = zs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), z| {
            (a.min(z), b.max(z))
        });
        let label = format!("{:.0}us", (snap.time * 1e6).round());
        let file = format!("penetration_damage_{label}.svg");
        let title = format!("Penetration, t = {:.1} µs: crack density", snap.time * 1e6);
        let w = HALF_WIDTH * 1e3;
        plot::plane(
            &doc.dir.join(&file),
            &Plane {
                title: &title,
                x: "x (mm)",
                y: "z (mm)",
                xs: (-w, w),
                ys: (z0 - 1.0, z1 + 1.0),
                values: (0.0, PULVERIZED),
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
