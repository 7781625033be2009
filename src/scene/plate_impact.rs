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
use crate::material::johnson_holmquist::{Failure, Jh2, JohnsonHolmquist};
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

/// The example ceramic of JH94 ([`JohnsonHolmquist::example_ceramic`]),
/// the defaults of the `jh_` block.
const JH: JohnsonHolmquist = JohnsonHolmquist::example_ceramic();

/// The largest `jh_sfmax`, and its default: a cap no pressure reaches
/// (MAT_110's default is none).
const NO_SFMAX: f64 = 1.0e10;

/// The JH-2 ceramic of a plate of level `jh2`, under `jh_`: the constants
/// of [`JohnsonHolmquist`] (JH94; the fields of LS-DYNA's MAT_110), in SI
/// units. Defaults: the example ceramic of Johnson & Holmquist (1994), "An
/// improved computational constitutive model for brittle materials", AIP
/// Conf. Proc. 309, as commonly quoted ([`JohnsonHolmquist::example_ceramic`]).
const JH_BLOCK: [ParamSpec; 18] = [
    row(
        "jh_density",
        "kg/m3",
        JH.density,
        Range::closed(100.0, 1.0e5),
        "JH-2: initial density rho0 (RO)",
    ),
    row(
        "jh_shear_modulus",
        "Pa",
        JH.shear_modulus,
        Range::closed(1.0e6, 1.0e14),
        "JH-2: shear modulus G",
    ),
    row(
        "jh_a",
        "1",
        JH.a,
        Range::open_closed(0.0, 100.0),
        "JH-2: intact strength constant A of sigma_i* = A (P* + T*)^N (1 + C ln eps_dot*)",
    ),
    row(
        "jh_b",
        "1",
        JH.b,
        Range::closed(0.0, 100.0),
        "JH-2: fractured strength constant B of sigma_f* = B (P*)^M (1 + C ln eps_dot*)",
    ),
    row(
        "jh_c",
        "1",
        JH.c,
        Range::closed(0.0, 1.0),
        "JH-2: strain-rate constant C",
    ),
    row(
        "jh_m",
        "1",
        JH.m,
        Range::closed(0.0, 10.0),
        "JH-2: fractured strength exponent M",
    ),
    row(
        "jh_n",
        "1",
        JH.n,
        Range::closed(0.0, 10.0),
        "JH-2: intact strength exponent N",
    ),
    row(
        "jh_ref_strain_rate",
        "1/s",
        JH.ref_strain_rate,
        Range::closed(1.0e-9, 1.0e9),
        "JH-2: reference strain rate EPSI of eps_dot* = eps_dot / EPSI",
    ),
    row(
        "jh_tensile_strength",
        "Pa",
        JH.tensile_strength,
        Range::closed(0.0, 1.0e11),
        "JH-2: hydrostatic tensile strength T (the pressure is at least -T (1 - D))",
    ),
    row(
        "jh_sfmax",
        "1",
        NO_SFMAX,
        Range::open_closed(0.0, NO_SFMAX),
        "JH-2: largest normalized fractured strength SFMAX (the default 1e10 stands for none, \
         MAT_110's default)",
    ),
    row(
        "jh_hel",
        "Pa",
        JH.hel,
        Range::closed(1.0e6, 1.0e12),
        "JH-2: Hugoniot elastic limit HEL, the axial stress of uniaxial strain at the elastic limit \
         (P_HEL and sigma_HEL are derived from it, G and the pressure polynomial: MAT_110 with PHEL = 0)",
    ),
    row(
        "jh_beta",
        "1",
        JH.beta,
        Range::closed(0.0, 1.0),
        "JH-2: fraction beta of the elastic energy released by damage that goes into bulking pressure",
    ),
    row(
        "jh_d1",
        "1",
        JH.d1,
        Range::open_closed(0.0, 10.0),
        "JH-2: failure-strain constant D1 of eps_p^f = D1 (P* + T*)^D2",
    ),
    row(
        "jh_d2",
        "1",
        JH.d2,
        Range::closed(0.0, 10.0),
        "JH-2: failure-strain exponent D2",
    ),
    row(
        "jh_k1",
        "Pa",
        JH.k[0],
        Range::closed(1.0e6, 1.0e14),
        "JH-2: bulk modulus K1 of the pressure K1 mu + K2 mu^2 + K3 mu^3 + dP (K1 mu + dP in tension)",
    ),
    row(
        "jh_k2",
        "Pa",
        JH.k[1],
        Range::closed(-1.0e14, 1.0e14),
        "JH-2: pressure constant K2",
    ),
    row(
        "jh_k3",
        "Pa",
        JH.k[2],
        Range::closed(-1.0e14, 1.0e14),
        "JH-2: pressure constant K3",
    ),
    row(
        "jh_fs",
        "1",
        0.0,
        Range::closed(-1.0, 10.0),
        "JH-2: failure FS of MAT_110: 0 = never (the default), < 0 = once the trial pressure passes \
         -T, > 0 = once the equivalent plastic strain exceeds FS; a failed cell carries no stress",
    ),
];

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
            Damage::RajendranGrove(c) => Ok(Layer::Ceramic(c)),
            _ => unreachable!("the ceramic block makes a Rajendran-Grove material"),
        };
    }
    if LAYER_MATERIALS[k].name == JH2_LEVEL {
        return jh2(s).map(Layer::Jh2);
    }
    let preset: &Preset = Preset::named(LAYER_MATERIALS[k].name)?;
    Ok(Layer::Solid(preset.material()?))
}

/// The JH-2 model of the `jh_` block: each value checked against its row,
/// then the constants together ([`JohnsonHolmquist::validate`]: a HEL that
/// the compression reaches, a positive P_HEL), errors by the `jh_` names.
fn jh2(s: &Scene) -> Result<Jh2> {
    let v = |name: &str| -> Result<f64> {
        let x = s.get(name)?;
        if let Some(r) = JH_BLOCK.iter().find(|r| r.name == name) {
            r.check(x)?;
        }
        Ok(x)
    };
    let fs = v("jh_fs")?;
    let constants = JohnsonHolmquist {
        density: v("jh_density")?,
        shear_modulus: v("jh_shear_modulus")?,
        a: v("jh_a")?,
        b: v("jh_b")?,
        c: v("jh_c")?,
        m: v("jh_m")?,
        n: v("jh_n")?,
        ref_strain_rate: v("jh_ref_strain_rate")?,
        tensile_strength: v("jh_tensile_strength")?,
        sfmax: v("jh_sfmax")?,
        hel: v("jh_hel")?,
        beta: v("jh_beta")?,
        d1: v("jh_d1")?,
        d2: v("jh_d2")?,
        k: [v("jh_k1")?, v("jh_k2")?, v("jh_k3")?],
        failure: if fs == 0.0 {
            Failure::Never
        } else if fs < 0.0 {
            Failure::InTension
        } else {
            Failure::AtStrain(fs)
        },
    };
    constants.model().map_err(|e| match e {
        Error::OutOfRange { name, value, range } => Error::OutOfRange {
            name: match name.as_str() {
                "hel" => "jh_hel (no compression up to mu = 1 reaches it)".to_string(),
                "p_hel" => {
                    "P_HEL derived from jh_hel, jh_shear_modulus and jh_k1..jh_k3".to_string()
                }
                n if n.starts_with("jh_") => n.to_string(),
                n => format!("jh_{n}"),
            },
            value,
            range,
        },
        e => e,
    })
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
