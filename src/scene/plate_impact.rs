//! The `plate_impact` scene: a flyer plate strikes a target plate in
//! uniaxial strain ([`crate::PlateImpact`], `src/solver/uniaxial/mod.rs`), the
//! experiment that ceramic models are calibrated with. Either plate is the
//! Rajendran-Grove ceramic (the `plate_` block, defaults AD85 as in
//! `penetration`), one of the metal presets ([`crate::Preset`]), or the
//! Johnson-Holmquist ceramic JH-2 (level `jh2`, the `jh_` block, defaults
//! the example ceramic of Johnson & Holmquist 1994; its precursor is read
//! at the knee of its ramped free-surface velocity). The
//! target's free-surface velocity is read as an experimenter reads a VISAR
//! record: the elastic precursor gives the Hugoniot elastic limit
//! `rho0 c_L u / 2`, and the pullback after the peak gives the spall
//! strength `rho0 c_B du / 2` once the target has failed in tension.
//!
//! The default is the symmetric spall experiment: AD85 2 mm thick on AD85
//! 4 mm thick at 300 m/s (about 4.4 GPa elastic, under the HEL), so that
//! the release waves from the two free faces meet mid-way through the
//! target.

use super::Scene;
use super::params::{Level, ParamSpec, Range, concat, levels_spec, spec as row};
use super::row::{FmuIdentity, SceneRow, no_variants};
use crate::budget::MemoryPerNode;
use crate::error::{Error, Result};
use crate::material::Damage;
use crate::material::ceramic_block::{PLATE_CERAMIC, ceramic_material};
use crate::material::jh2_block::{JH_BLOCK, jh2_model};
use crate::material::presets::Preset;
use crate::observe::PLATE_IMPACT_OBSERVABLES;
use crate::solver::uniaxial::{Layer, PlateImpact};
use std::collections::BTreeMap;

/// The registry row of the `plate_impact` scene.
pub static ROW: SceneRow = SceneRow {
    name: "plate_impact",
    title: "Plate impact in uniaxial strain: AD85 flyer (2 mm) on an AD85 target (4 mm) at 300 m/s",
    params: PLATE_IMPACT_PARAMS,
    material: None,
    observables: PLATE_IMPACT_OBSERVABLES,
    fields: crate::solver::uniaxial::PLATE_IMPACT_FIELDS,
    reference: BTreeMap::new,
    variants: no_variants,
    check: |s| setup(s).map(|_| ()),
    nodes: |s| {
        let v = |name: &str| s.get(name).expect("a plate_impact parameter");
        (v("flyer_thickness") + v("target_thickness")) / v("cell")
    },
    // A cell holds its node, its material point and its fields: about
    // 0.4 kB (the ceramic point is the largest part); twice that for room.
    memory: |_| MemoryPerNode { bytes: 1000.0 },
    build: |s: &Scene| Ok(Box::new(setup(s)?)),
    fmu: Some(FmuIdentity {
        model_identifier: "PlateImpact",
        model_name: "PlateImpact",
        description: "Plate impact in uniaxial strain: a flyer plate on a target plate, either the \
                      Rajendran-Grove ceramic or a metal preset; the target's free-surface velocity, \
                      its elastic precursor (HEL) and its spall strength",
    }),
};

/// The materials a plate can be made of: the ceramic of the `plate_` block,
/// then the metal presets in their listing order ([`PRESETS`]).
pub const LAYER_MATERIALS: &[Level] = &[
    Level {
        name: "ceramic",
        description: "the Rajendran-Grove ceramic of the plate_ parameters (defaults: AD85)",
        sets: &[],
    },
    Level {
        name: "steel_4340_house",
        description: "preset steel_4340_house",
        sets: &[],
    },
    Level {
        name: "aisi310_bilinear",
        description: "preset aisi310_bilinear",
        sets: &[],
    },
    Level {
        name: "tungsten_seed",
        description: "preset tungsten_seed",
        sets: &[],
    },
    Level {
        name: "ofhc_copper_jc",
        description: "preset ofhc_copper_jc",
        sets: &[],
    },
    Level {
        name: "aluminium_6061t6_jc",
        description: "preset aluminium_6061t6_jc",
        sets: &[],
    },
    Level {
        name: "copper_wilkins_bilinear",
        description: "preset copper_wilkins_bilinear",
        sets: &[],
    },
    Level {
        name: "jh2",
        description: "the Johnson-Holmquist ceramic (JH-2) of the jh_ parameters (defaults: the example \
                      ceramic of Johnson & Holmquist 1994 as commonly quoted)",
        sets: &[],
    },
];

/// The level of [`LAYER_MATERIALS`] that is the JH-2 ceramic of the `jh_`
/// block.
const JH2_LEVEL: &str = "jh2";

/// The plates, the speed and the cells, before the ceramic's block.
const BEFORE: &[ParamSpec] = &[
    row(
        "impact_speed",
        "m/s",
        300.0,
        Range::closed(1.0, 1.0e4),
        "speed of the flyer toward the target",
    ),
    levels_spec(
        "flyer_material",
        0,
        LAYER_MATERIALS,
        "material of the flyer: 0 = ceramic (the plate_ parameters), a metal preset by name, or jh2 \
         (the JH-2 ceramic of the jh_ parameters)",
    ),
    row(
        "flyer_thickness",
        "m",
        0.002,
        Range::open_closed(0.0, 0.1),
        "thickness of the flyer plate",
    ),
    levels_spec(
        "target_material",
        0,
        LAYER_MATERIALS,
        "material of the target: 0 = ceramic (the plate_ parameters), a metal preset by name, or jh2 \
         (the JH-2 ceramic of the jh_ parameters)",
    ),
    row(
        "target_thickness",
        "m",
        0.004,
        Range::open_closed(0.0, 0.1),
        "thickness of the target plate (its back face is the free surface whose velocity is read)",
    ),
];

/// The resolution and the end time, after the ceramic's block.
const AFTER: &[ParamSpec] = &[
    row(
        "cell",
        "m",
        10.0e-6,
        Range::closed(1.0e-7, 1.0e-3),
        "length of a cell (each plate is cut into cells of about this length, at least two)",
    ),
    row(
        "end_time",
        "s",
        2.0e-6,
        Range::closed(1.0e-9, 1.0e-3),
        "simulated time at which the run ends",
    ),
];

const LEN: usize = BEFORE.len() + PLATE_CERAMIC.len() + AFTER.len() + JH_BLOCK.len();

/// Parameters of the plate-impact scene (SI units); the JH-2 block last, so
/// that the earlier rows keep their places.
pub const PLATE_IMPACT_PARAMS: &[ParamSpec] =
    &concat::<LEN>(&[BEFORE, &PLATE_CERAMIC, AFTER, &JH_BLOCK]);

/// The most cells a run may have: each step visits every cell, and a
/// longer run than this would take hours.
const MAX_CELLS: f64 = 1.0e6;

/// The plate made of material level `level`.
fn layer(level: f64, s: &Scene) -> Result<Layer> {
    let k = level as usize;
    if k == 0 {
        let material = ceramic_material(|name| s.get(name))?;
        return match material.damage {
            // A cell of the uniaxial target is a slab of the whole face: it has
            // no volume of its own to draw a strength for, and one weak draw
            // would be a weak plane across the whole target.
            Damage::RajendranGrove(c) if c.tensile_flaw_volume > 0.0 => Err(Error::OutOfRange {
                name: "plate_tensile_flaw_volume".to_string(),
                value: c.tensile_flaw_volume,
                range: "0 in plate_impact (its cells are slabs of the target's whole face, \
                        with no volume of their own; the volume effect is the 3-D scenes')"
                    .to_string(),
            }),
            Damage::RajendranGrove(c) if c.tensile_flaw_scatter > 0.0 => Err(Error::OutOfRange {
                name: "plate_tensile_flaw_scatter".to_string(),
                value: c.tensile_flaw_scatter,
                range: "0 in plate_impact (its cells are slabs of the target's whole face: \
                        a point's draw would make one weak plane across the target; the \
                        scatter is the 3-D scenes')"
                    .to_string(),
            }),
            Damage::RajendranGrove(c) => Ok(Layer::Ceramic(c)),
            _ => unreachable!("the ceramic block makes a Rajendran-Grove material"),
        };
    }
    if LAYER_MATERIALS[k].name == JH2_LEVEL {
        return jh2_model(|name| s.get(name)).map(Layer::Jh2);
    }
    let preset: &Preset = Preset::named(LAYER_MATERIALS[k].name)?;
    Ok(Layer::Solid(preset.material()?))
}

/// The run of a scene, with the cross-parameter checks.
fn setup(s: &Scene) -> Result<PlateImpact> {
    let v = |name: &str| s.get(name);
    let (flyer_thickness, target_thickness, cell) =
        (v("flyer_thickness")?, v("target_thickness")?, v("cell")?);
    let cells = (flyer_thickness + target_thickness) / cell;
    if cells > MAX_CELLS {
        return Err(Error::Inconsistent(format!(
            "flyer_thickness + target_thickness = {} m over cell = {cell} m makes {cells:.0} cells, \
             more than {MAX_CELLS:.0}; raise cell",
            flyer_thickness + target_thickness
        )));
    }
    let flyer = layer(v("flyer_material")?, s)?;
    let target = layer(v("target_material")?, s)?;
    Ok(PlateImpact::new(
        flyer,
        flyer_thickness,
        target,
        target_thickness,
        v("impact_speed")?,
        cell,
    )?
    .without_history()
    .until(v("end_time")?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::jh2_block::NO_SFMAX;
    use crate::material::johnson_holmquist::JohnsonHolmquist;
    use crate::material::presets::PRESETS;

    /// The levels after the ceramic are the presets, in their order.
    #[test]
    fn the_metal_levels_are_the_presets() {
        let names: Vec<&str> = LAYER_MATERIALS[1..=PRESETS.len()]
            .iter()
            .map(|l| l.name)
            .collect();
        let presets: Vec<&str> = PRESETS.iter().map(|p| p.name).collect();
        assert_eq!(names, presets);
        assert_eq!(LAYER_MATERIALS[PRESETS.len() + 1..].len(), 1);
        assert_eq!(LAYER_MATERIALS[PRESETS.len() + 1].name, JH2_LEVEL);
    }

    /// The jh_ defaults are the example ceramic (the cap on the fractured
    /// strength aside: 1e10 for none), and a JH-2 flyer and target build;
    /// a HEL out of reach is refused by its jh_ name.
    #[test]
    fn the_jh2_block_is_the_example_ceramic() {
        let mut s = Scene::builtin("plate_impact").unwrap();
        let level = LAYER_MATERIALS
            .iter()
            .position(|l| l.name == JH2_LEVEL)
            .unwrap() as f64;
        s.set("flyer_material", level).unwrap();
        s.set("target_material", level).unwrap();
        let Layer::Jh2(j) = layer(level, &s).unwrap() else {
            panic!("a JH-2 layer")
        };
        let mut expected = JohnsonHolmquist::example_ceramic();
        expected.sfmax = NO_SFMAX;
        assert_eq!(*j.constants(), expected);
        (ROW.check)(&s).unwrap();
        s.set("jh_hel", 1.0e12).unwrap();
        let e = (ROW.check)(&s).unwrap_err().to_string();
        assert!(e.contains("jh_hel"), "{e}");
    }

    /// Every name is unique, every default in range, and the default scene
    /// builds.
    #[test]
    fn the_table_is_consistent() {
        let mut names: Vec<_> = PLATE_IMPACT_PARAMS.iter().map(|p| p.name).collect();
        names.sort_unstable();
        let n = names.len();
        names.dedup();
        assert_eq!(names.len(), n);
        for p in PLATE_IMPACT_PARAMS {
            p.check(p.default).unwrap();
        }
        let s = Scene::builtin("plate_impact").unwrap();
        (ROW.check)(&s).unwrap();
    }

    /// Too many cells is refused by name before anything is allocated.
    #[test]
    fn too_many_cells_are_refused() {
        let mut s = Scene::builtin("plate_impact").unwrap();
        s.set("target_thickness", 0.1).unwrap();
        s.set("cell", 1.0e-7).unwrap();
        let e = s.validate().unwrap_err().to_string();
        assert!(e.contains("cell") && e.contains("cells"), "{e}");
    }
}
