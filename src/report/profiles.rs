//! The seed's 3-D Taylor case (004, section 5.1: AISI 310, bilinear J2,
//! 300 m/s; scene `taylor3d-aisi310`): the outline of the rod by the 3-D
//! MLPG solver against the axisymmetric MSPH solver's, with the same
//! material ([`meshless_impact::axisymmetric_twin`]).

use super::plot::{Axes, Series};
use super::{Doc, Plan, Table, sig};
use meshless_impact::{Result, Scene, Simulation, axisymmetric_twin, profile_deviation};
use std::time::Instant;

/// Heights at which the two outlines are compared.
pub(crate) const PROFILE_SAMPLES: usize = 40;

/// One finished run: its particles, observables, outline and wall time.
struct Outline {
    label: String,
    particles: usize,
    time: f64,
    rod_length: f64,
    mushroom_radius: f64,
    profile: Vec<[f64; 2]>,
    wall_s: f64,
}

fn run(label: String, scene: Scene) -> Result<Outline> {
    let mut sim = Simulation::new(scene)?;
    let start = Instant::now();
    sim.run()?;
    let get = |n: &str| sim.observable(n).expect("a rod observable");
    Ok(Outline {
        label,
        particles: sim.particles(),
        time: sim.time(),
        rod_length: get("rod_length"),
        mushroom_radius: get("mushroom_radius"),
        profile: sim.rod_profile().expect("a rod scene has an outline"),
        wall_s: start.elapsed().as_secs_f64(),
    })
}

/// The outlines of `taylor3d-aisi310` by both solvers: a table, the
/// deviations, and a figure.
pub(super) fn aisi310(plan: &Plan, doc: &mut Doc) -> Result<()> {
    let (n3, n2) = if plan.quick {
        (4.0, 11.0)
    } else {
        (11.0, 41.0)
    };
    let mut s3 = Scene::builtin("taylor3d-aisi310")?;
    s3.set("particles_radial", n3)?;
    let twin = axisymmetric_twin(&s3, n2)?;
    let mlpg = run(format!("3-D MLPG, {n3} nodes across"), s3)?;
    let msph = run(format!("axisymmetric MSPH, {n2} across"), twin)?;
    let deviation =
        profile_deviation(&mlpg.profile, &msph.profile, PROFILE_SAMPLES).unwrap_or(f64::NAN);
    doc.para(&format!(
        "## The seed's 3-D Taylor case: AISI 310 at 300 m/s, both solvers\n\n\
         Scene `taylor3d-aisi310` (seed 004, section 5.1; L0 = 12.7 mm and D0 = 7.62 mm \
         assumed, the seed misprints them), bilinear J2 (`aisi310_bilinear`), to 50 µs \
         or rest, by the 3-D MLPG solver and by the axisymmetric MSPH solver with the \
         same material. The outline is one generator of the mantle; the deviation is \
         the largest |r_3D(z) / r_axi(z) − 1| at {PROFILE_SAMPLES} heights over the \
         shared span. The issue's bounds: lengths within 1 %, radii within 3 %."
    ));
    let mut t = Table::new(
        "aisi310_outline",
        &[
            "solver",
            "particles",
            "end_us",
            "rod_length_mm",
            "mushroom_radius_mm",
            "wall_s",
        ],
    );
    for o in [&mlpg, &msph] {
        t.push(vec![
            o.label.clone(),
            o.particles.to_string(),
            sig(o.time * 1e6, 4),
            sig(o.rod_length * 1e3, 5),
            sig(o.mushroom_radius * 1e3, 5),
            sig(o.wall_s, 3),
        ]);
    }
    doc.table(&t)?;
    doc.para(&format!(
        "3-D against axisymmetric: rod length {:+.2} %, face radius {:+.2} %, outline \
         radius at most {:.2} % apart.",
        100.0 * (mlpg.rod_length / msph.rod_length - 1.0),
        100.0 * (mlpg.mushroom_radius / msph.mushroom_radius - 1.0),
        100.0 * deviation
    ));
    let mm = |o: &Outline| -> Vec<(f64, f64)> {
        o.profile.iter().map(|[z, r]| (r * 1e3, z * 1e3)).collect()
    };
    doc.lines(
        "aisi310_outline.svg",
        Axes::linear(
            "AISI 310 rod at rest (seed 004, 300 m/s)",
            "radius (mm)",
            "height above the anvil (mm)",
        ),
        &[
            Series::line(mlpg.label.clone(), mm(&mlpg)),
            Series::line(msph.label.clone(), mm(&msph)),
        ],
    )?;
    Ok(())
}
