//! The `penetration` scene: a projectile perforating a plate in 3-D by the
//! MLPG mixed method (seed 004, section 5.2; [`crate::solver::mlpg3d::penetration`]).
//! Its defaults are the seed's case: a tungsten cylinder 10 mm long and
//! 10 mm in diameter at 1500 m/s, normal to an AD85 plate 5 mm thick and
//! 80 mm in diameter (free rim), run to 20 µs. The projectile is bilinear
//! J2 with the linear EOS (`projectile_` block, defaults the preset
//! `tungsten_seed`); the plate is the Rajendran-Grove ceramic (`plate_`
//! block, defaults AD85 of the seed's Table 1).

use super::Scene;
use super::params::{Level, ParamSpec, Range, concat, levels_spec, spec as row};
use super::row::{SceneRow, no_variants};
use super::taylor3d::{RingLattice, mlpg_memory};
use crate::approx::lattice::Cylinder;
use crate::error::{Error, Result};
use crate::material::Material;
use crate::material::ceramic_block::{PLATE_CERAMIC, ceramic_material};
use crate::material::choice::{MaterialChoice, Prefix};
use crate::material::jh2_block::{JH_BLOCK, jh2_model};
use crate::observe::PENETRATION_OBSERVABLES;
use crate::solver::mlpg3d::NodeOrder;
use crate::solver::mlpg3d::penetration::{Penetration, PenetrationSetup};
use crate::solver::mlpg3d::scheme::MlpgScheme;
use crate::solver::mlpg3d::{DAMPING, REBUILD_STRAIN, RodSetup};
use std::collections::BTreeMap;

/// The registry row of the `penetration` scene.
pub static ROW: SceneRow = SceneRow {
    name: "penetration",
    title: "Ballistic penetration in 3-D by MLPG: tungsten rod (10 x 10 mm, 1500 m/s) through a 5 mm AD85 plate",
    params: PENETRATION_PARAMS,
    material: None,
    observables: PENETRATION_OBSERVABLES,
    fields: crate::solver::mlpg3d::penetration::PENETRATION_FIELDS,
    reference: || BTreeMap::from([("projectile_velocity".to_string(), RESIDUAL_VELOCITY)]),
    variants: no_variants,
    check: |s| setup(s).map(|_| ()),
    nodes,
    // The 3-D MLPG solver's, by its forces: the contact and the damaged
    // plate add little to the heap (docs/notes/2026-11-29-memory-bounds.md).
    memory: mlpg_memory,
    build: |s: &Scene| Ok(Box::new(penetration(s)?)),
    fmu: Some(super::row::FmuIdentity {
        model_identifier: "BallisticImpact",
        model_name: "BallisticImpact",
        description: "Ballistic penetration in 3-D: a bilinear elastoplastic projectile through a Rajendran-Grove \
                      ceramic plate by the MLPG mixed method (Han, Liu, Rajendran & Atluri); defaults are the \
                      tungsten rod on AD85 at 1500 m/s",
    }),
};

/// The seed's residual velocity of its case (m/s; seed 004, section 5.2).
pub const RESIDUAL_VELOCITY: f64 = 1240.0;

/// The geometry and the projectile's material, before the plate's block.
const BEFORE: &[ParamSpec] = &[
    row(
        "impact_speed",
        "m/s",
        1500.0,
        Range::closed(0.01, 1.0e4),
        "speed of the projectile toward the plate, normal to it",
    ),
    row(
        "projectile_length",
        "m",
        0.01,
        Range::open_closed(0.0, 1.0),
        "length of the cylindrical projectile",
    ),
    row(
        "projectile_diameter",
        "m",
        0.01,
        Range::open_closed(0.0, 1.0),
        "diameter of the cylindrical projectile",
    ),
    row(
        "plate_thickness",
        "m",
        0.005,
        Range::open_closed(0.0, 1.0),
        "thickness of the plate",
    ),
    row(
        "plate_diameter",
        "m",
        0.08,
        Range::open_closed(0.0, 10.0),
        "diameter of the circular plate (its rim is free)",
    ),
    row(
        "projectile_density",
        "kg/m3",
        16980.0,
        Range::closed(100.0, 1.0e5),
        "projectile: reference mass density",
    ),
    row(
        "projectile_shear_modulus",
        "Pa",
        123801652892.56198,
        Range::closed(1.0e6, 1.0e14),
        "projectile: shear modulus mu",
    ),
    row(
        "projectile_bulk_modulus",
        "Pa",
        172183908045.977,
        Range::closed(1.0e6, 1.0e15),
        "projectile: bulk modulus K of the linear EOS P = K(rho/rho0 - 1)",
    ),
    row(
        "projectile_specific_heat",
        "J/(kg.K)",
        134.0,
        Range::closed(1.0, 1.0e5),
        "projectile: specific heat C",
    ),
    row(
        "projectile_taylor_quinney",
        "1",
        0.9,
        Range::closed(0.0, 1.0),
        "projectile: Taylor-Quinney coefficient, the fraction of plastic work that becomes heat",
    ),
    row(
        "projectile_yield_stress",
        "Pa",
        1.5e9,
        Range::closed(0.0, 1.0e11),
        "projectile: bilinear J2 initial yield stress",
    ),
    row(
        "projectile_hardening_modulus",
        "Pa",
        0.0,
        Range::closed(0.0, 1.0e12),
        "projectile: bilinear J2 plastic hardening modulus H",
    ),
    row(
        "projectile_initial_temperature",
        "K",
        293.0,
        Range::closed(1.0, 1.0e5),
        "projectile: temperature at impact",
    ),
];

/// The resolution, the solver's choices and the end time, after the
/// plate's block.
const AFTER: &[ParamSpec] = &[
    row(
        "particles_radial",
        "1",
        6.0,
        Range::integer(2.0, 60.0),
        "nodes across the projectile's radius, axis and mantle included (rings + 1); the plate has the same spacing",
    ),
    row(
        "smoothing_coefficient",
        "1",
        0.1,
        Range::closed(0.0, 0.5),
        "alpha of the MLPG velocity smoothing (smoothing_order) at each node (README, penetration) (scheme)",
    ),
    // The order-2 smoothing, the nodal form and node shifting: the only
    // choices measured to run the seed's case to 20 µs (README,
    // "Ballistic penetration"; the scheme `ballistic`).
    super::taylor3d::SMOOTHING_ORDER_SPEC,
    super::taylor3d::SHIFTING,
    ParamSpec {
        default: 1.0,
        ..super::taylor3d::WEAK_FORM
    },
    super::taylor3d::CONFORM_PRECONDITIONER,
    super::taylor3d::SYMMETRY,
    ParamSpec {
        default: 0.0,
        ..super::taylor3d::LATTICE
    },
    row(
        "end_time",
        "s",
        20.0e-6,
        Range::closed(1.0e-9, 1.0e-3),
        "simulated time at which the run ends",
    ),
    levels_spec(
        "scheme",
        0,
        SCHEMES,
        "numerical scheme by name, which sets the knobs marked (scheme); a knob set by hand overrides it: \
         0 = ballistic (the default, measured on the seed's case), 1 = paper (the seed's MLPG mixed method exactly)",
    ),
    levels_spec(
        "run_until",
        0,
        RUN_UNTIL,
        "when the run ends: 0 = end_time (the default: at end_time, whatever the shot's outcome), \
         1 = outcome (as soon as shot_outcome is decided, perforated or stopped, with end_time as the cap; \
         README, \"Ballistic limit\")",
    ),
    levels_spec(
        "plate_model",
        0,
        PLATE_MODEL,
        "the plate's ceramic model: 0 = rajendran_grove (the default, the seed's: the plate_ parameters), \
         1 = jh2 (Johnson-Holmquist JH-2 of the jh_ parameters, with the plate's specific heat, \
         Taylor-Quinney coefficient and initial temperature; defaults: the example ceramic of \
         Johnson & Holmquist 1994)",
    ),
    row(
        "radial_crack_radius",
        "m",
        0.0,
        Range::closed(0.0, 10.0),
        "radius about the axis of the rear-face ring in which radial_crack_count counts the radial cracks: \
         0 = the projectile's diameter (two projectile radii, at most 0.8 of the plate's radius; the default), \
         else this radius, inside the plate",
    ),
    levels_spec(
        "plate_rim",
        0,
        PLATE_RIM,
        "the plate's rim: 0 = free (the default, the seed's case: momentum is shared by projectile and plate \
         alone), 1 = clamped (the outer ring of plate nodes held still; README, \"Ballistic penetration\")",
    ),
    levels_spec(
        "plate_node_order",
        0,
        PLATE_NODE_ORDER,
        "the order of the plate's nodes: 0 = rings, layer by layer (the default), 1 = recursive coordinate \
         bisection, whose ranges are compact pieces of the plate: the ranks of an MPI run share the nodes by ranges, \
         so with 1 they exchange a fifth to a sixth of what they do with 0 (docs/guide/mpi.md); the two orders \
         sum in another order, so their answers differ by round-off grown over the run",
    ),
];

/// The levels of `plate_node_order`.
const PLATE_NODE_ORDER: &[Level] = &[
    Level {
        name: "rings",
        description: "the plate's nodes layer by layer, ring by ring (the default)",
        sets: &[],
    },
    Level {
        name: "bisection",
        description: "the plate's nodes in the order of a recursive coordinate bisection (for runs on several ranks)",
        sets: &[],
    },
];

/// The levels of `plate_model`.
const PLATE_MODEL: &[Level] = &[
    Level {
        name: "rajendran_grove",
        description: "the Rajendran-Grove ceramic of the plate_ parameters (the seed's model; plate_ceramic names its set)",
        sets: &[],
    },
    Level {
        name: "jh2",
        description: "the Johnson-Holmquist ceramic JH-2 of the jh_ parameters",
        sets: &[],
    },
];

/// The levels of `plate_rim`.
const PLATE_RIM: &[Level] = &[
    Level {
        name: "free",
        description: "the plate's rim is free (the seed's case)",
        sets: &[],
    },
    Level {
        name: "clamped",
        description: "the plate's outer ring of nodes is held still (a plate clamped at its rim)",
        sets: &[],
    },
];

/// The levels of `run_until`.
const RUN_UNTIL: &[Level] = &[
    Level {
        name: "end_time",
        description: "the run ends at end_time, whatever the shot's outcome (the residual velocity of the seed's case at 20 us)",
        sets: &[],
    },
    Level {
        name: "outcome",
        description: "the run ends as soon as the shot is perforated or stopped (shot_outcome), at end_time at the latest \
                      (shot_outcome 0 then): the ballistic-limit sweep's choice",
        sets: &[],
    },
];

/// The schemes of the penetration scene, by name (the `scheme` row;
/// [`MlpgScheme`] decodes the knobs they set). The first is the default.
pub const SCHEMES: &[Level] = &[
    Level {
        name: "ballistic",
        description: "the default: the nodal form, the order-2 smoothing with alpha = 0.1, node shifting \
                      beta = 0.1, the aligned lattice: the only choices measured to run the seed's case to \
                      20 us (README, \"Ballistic penetration\")",
        sets: &[
            ("smoothing_coefficient", 0.1),
            ("smoothing_order", 2.0),
            ("shifting", 0.1),
            ("weak_form", 1.0),
            ("lattice", 0.0),
        ],
    },
    super::taylor3d::PAPER_3D,
];

const LEN: usize = BEFORE.len() + PLATE_CERAMIC.len() + AFTER.len() + JH_BLOCK.len();

/// Parameters of the penetration scene (SI units): the geometry, the
/// projectile's block (bilinear, linear EOS; `tungsten_seed`), the plate's
/// ceramic block (AD85), the resolution and the solver's choices.
pub const PENETRATION_PARAMS: &[ParamSpec] =
    &concat::<LEN>(&[BEFORE, &PLATE_CERAMIC, AFTER, &JH_BLOCK]);

/// The nodes of a run: the ring lattices of the projectile and the plate at
/// the projectile's radial spacing (their quarters in the quarter model).
fn nodes(s: &Scene) -> f64 {
    let v = |name: &str| s.get(name).expect("a penetration parameter");
    let radius = 0.5 * v("projectile_diameter");
    let spacing = radius / (v("particles_radial") - 1.0);
    let lattice = RingLattice::of(s);
    // The plate's lattice is aligned whatever `lattice` says.
    let plate = RingLattice {
        staggered: false,
        ..lattice
    };
    lattice.nodes(radius, v("projectile_length"), spacing)
        + plate.nodes(0.5 * v("plate_diameter"), v("plate_thickness"), spacing)
}

/// The run of a `penetration` scene (its registry row's build, typed).
pub fn penetration(s: &Scene) -> Result<Penetration> {
    let (setup, (projectile, plate), numerics) = setup(s)?;
    Penetration::new(setup, projectile, plate, numerics)
}

/// The setup, the two materials and the solver's choices of a scene, with
/// the cross-parameter checks.
fn setup(s: &Scene) -> Result<(PenetrationSetup, (Material, Material), RodSetup)> {
    let v = |name: &str| s.get(name);
    let projectile = Cylinder {
        radius: 0.5 * v("projectile_diameter")?,
        length: v("projectile_length")?,
    };
    let plate = Cylinder {
        radius: 0.5 * v("plate_diameter")?,
        length: v("plate_thickness")?,
    };
    let rings = v("particles_radial")? as usize - 1;
    let spacing = projectile.radius / rings as f64;
    if plate.radius < projectile.radius + 2.0 * spacing {
        return Err(Error::Inconsistent(format!(
            "plate_diameter = {} must exceed projectile_diameter = {} by at least four node spacings ({} m)",
            2.0 * plate.radius,
            2.0 * projectile.radius,
            4.0 * spacing
        )));
    }
    for (name, length) in [
        ("projectile_length", projectile.length),
        ("plate_thickness", plate.length),
    ] {
        if length < 2.0 * spacing {
            return Err(Error::Inconsistent(format!(
                "{name} = {length} m holds fewer than three layers of nodes at the spacing {spacing} m \
                 (projectile_diameter / 2 / (particles_radial - 1)); raise particles_radial"
            )));
        }
    }
    let quarter = v("symmetry")? >= 0.5;
    let projectile_material = MaterialChoice::BILINEAR_LINEAR.material(Prefix::Projectile, v)?;
    // The plate's model: the Rajendran-Grove ceramic of the plate_ block,
    // or JH-2 of the jh_ block with the plate's thermal constants.
    let plate_material = if v("plate_model")? >= 0.5 {
        let checked = |name: &str| -> Result<f64> {
            let x = v(name)?;
            if let Some(spec) = PENETRATION_PARAMS.iter().find(|r| r.name == name) {
                spec.check(x)?;
            }
            Ok(x)
        };
        Material::jh2(
            jh2_model(v)?,
            checked("plate_specific_heat")?,
            checked("plate_taylor_quinney")?,
            checked("plate_initial_temperature")?,
        )
    } else {
        ceramic_material(v)?
    };
    let end_time = v("end_time")?;
    let setup = PenetrationSetup {
        plate,
        until_outcome: v("run_until")? >= 0.5,
        clamped_rim: v("plate_rim")? >= 0.5,
        node_order: if v("plate_node_order")? >= 0.5 {
            NodeOrder::Bisection
        } else {
            NodeOrder::Rings
        },
        radial_crack_radius: v("radial_crack_radius")?,
    };
    // False-safe: a radius that is not a number is refused too.
    if setup.radial_crack_radius.is_nan() || setup.radial_crack_radius >= plate.radius {
        return Err(Error::Inconsistent(format!(
            "radial_crack_radius = {} m must lie inside the plate: below plate_diameter / 2 = {} m \
             (0 counts at the projectile's diameter)",
            setup.radial_crack_radius, plate.radius
        )));
    }
    let mut numerics = RodSetup::new(projectile, rings, v("impact_speed")?, end_time);
    numerics.damping = DAMPING;
    numerics.rebuild_strain = REBUILD_STRAIN;
    numerics.quarter = quarter;
    // Two free bodies conserve momentum, and so does the shifting's carry
    // here (issue 50; README, "Ballistic penetration").
    numerics.conservative_carry = true;
    numerics.scheme = MlpgScheme::decode(v)?;
    Ok((setup, (projectile_material, plate_material), numerics))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::presets::Preset;
    use crate::solver::mlpg3d::scheme::{Forces, SmoothingOrder};

    /// The projectile's defaults are the preset `tungsten_seed`, by value.
    #[test]
    fn projectile_defaults_are_the_tungsten_preset() {
        let preset = Preset::named("tungsten_seed").unwrap();
        for p in BEFORE.iter().filter(|p| p.name.starts_with("projectile_")) {
            let base = &p.name["projectile_".len()..];
            if let Some(v) = preset.value(base) {
                assert_eq!(p.default, v, "{}", p.name);
            }
        }
        let s = Scene::builtin("penetration").unwrap();
        let (_, (w, _), _) = setup(&s).unwrap();
        assert_eq!(w, preset.material().unwrap());
    }

    /// Every name is unique, and the default scene passes its checks.
    #[test]
    fn the_table_is_consistent() {
        let mut names: Vec<_> = PENETRATION_PARAMS.iter().map(|p| p.name).collect();
        names.sort_unstable();
        let n = names.len();
        names.dedup();
        assert_eq!(names.len(), n);
        for p in PENETRATION_PARAMS {
            p.check(p.default).unwrap();
        }
        let s = Scene::builtin("penetration").unwrap();
        (ROW.check)(&s).unwrap();
    }

    /// A plate no wider than the projectile, and a run too big, are refused
    /// by name.
    /// The weak form and the smoothing's order reach the run (the weak
    /// form was once dropped on the way, and `weak_form = 1` ran the
    /// spheres).
    #[test]
    fn the_solver_choices_reach_the_run() {
        let mut s = Scene::builtin("penetration").unwrap();
        s.set("particles_radial", 3.0).unwrap();
        s.set("weak_form", 1.0).unwrap();
        s.set("smoothing_order", 2.0).unwrap();
        s.set("smoothing_coefficient", 0.3).unwrap();
        let (setup, (projectile, plate), numerics) = setup(&s).unwrap();
        let run = Penetration::new(setup, projectile, plate, numerics).unwrap();
        let chosen = run.run().setup();
        assert_eq!(chosen.scheme.forces, Forces::Nodal);
        assert_eq!(chosen.scheme.order, SmoothingOrder::Two);
        assert_eq!(chosen.scheme.smoothing, 0.3);
        assert_eq!(chosen.impact_speed, 1500.0);
    }

    #[test]
    fn inconsistent_scenes_are_refused() {
        let mut s = Scene::builtin("penetration").unwrap();
        s.set("plate_diameter", 0.01).unwrap();
        let e = (ROW.check)(&s).unwrap_err().to_string();
        assert!(e.contains("plate_diameter"), "{e}");
        let mut s = Scene::builtin("penetration").unwrap();
        s.set("particles_radial", 60.0).unwrap();
        s.set("plate_diameter", 1.0).unwrap();
        let e = s.validate().unwrap_err().to_string();
        assert!(e.contains("nodes") && e.contains("memory budget"), "{e}");
    }
}
