//! The parameter block of a plate of Rajendran-Grove ceramic
//! ([`super::rajendran_grove`]) under the `plate_` prefix: every constant
//! of the model, its thermal constants and the plate's initial temperature,
//! for the `penetration` scene (a rod through a ceramic plate).
//!
//! [`PLATE_CERAMIC`] is a `const` table, to be concatenated into a scene's
//! `const` parameter table (as [`super::choice::compose`] takes a slice of
//! rows before and after a material block); [`ceramic_material`] builds the
//! [`Material`] from the values by their full names.
//!
//! **Names.** The constants that a metal's block also has keep its names
//! ([`super::choice::PLATE_BLOCK`]): `plate_density`, `plate_shear_modulus`,
//! `plate_gruneisen`, `plate_specific_heat`, `plate_taylor_quinney` and
//! `plate_initial_temperature`. The model's own constants carry `rg_`
//! where a bare name would mean something else in the metal's block
//! (`plate_rg_ref_strain_rate` is eq. 22's, not Johnson-Cook's).
//!
//! **Defaults: the seed's AD85 with tensile crack planes
//! (`ad85_planes_freund`).** The constants are AD85 alumina as
//! [`RajendranGrove::ad85`] holds it (seed 004, Table 1; the reference
//! strain rate 1/s of eq. 22 and the critical crack density 0.75 of
//! section 4.3 from the seed's text), plus the thermal constants below,
//! but for three knobs that the first row, `plate_ceramic`, sets by name
//! (a value set by hand overrides its level's):
//!
//! | level | `plate_crack_size` a0 | `plate_tensile_flaw_size` a_t | `plate_n2_open` n2+ |
//! |---|---|---|---|
//! | `ad85_seed` (Table 1 as printed) | 0.58 µm | 0 (no planes) | 0.07 |
//! | `ad85_spall` | [`SPALL_CRACK_SIZE`] = 100 µm | 0 | 0.07 |
//! | `ad85_planes` | 0.58 µm | [`PLANES_FLAW_SIZE`] = 188 µm | 0.07 |
//! | `ad85_planes_freund` (**the default**) | 0.58 µm | 188 µm | [`FREUND_N2`] = 1 |
//!
//! *Why the default is `ad85_planes_freund`* (issue 68; VALIDATION.md,
//! "Tensile crack planes"): with the seed's 0.58 µm a crack grows only
//! above 5.67 GPa in uniaxial strain, above the 5.3 GPa HEL, so the seed's
//! plate cannot crack in tension: a plate-impact target below the HEL
//! never spalls, and the ballistic plate shows no tensile failure.
//! `ad85_spall`'s larger a0 spalls, but the same flaws then slide in
//! compression and pulverize the ballistic plate to its rim (every shot
//! from 400 m/s perforates). The planes keep the seed's a0 for the cracks
//! that slide in compression, so the HEL and the compressive strength are
//! the seed's, and give each point three tensile crack planes from the
//! largest flaws, a_t = 188 µm, the penny crack that opens at 210 MPa
//! ([`PLANES_FLAW_SIZE`]). Their cracks grow by Freund's law (n2+ = 1,
//! [`FREUND_N2`]): with the seed's n2+ = 0.07 the plate-impact target's
//! spall strength lies at 0.97-1.68 GPa (100-300 m/s), above the band of
//! measured aluminas, and with n2+ = 1 at 0.25-0.26 GPa, inside it.
//! `ad85_seed` keeps the seed's case as printed.
//!
//! The thermal constants, which the seed does not give:
//!
//! - `plate_specific_heat` = 880 J/(kg K): a room-temperature value of
//!   engineering alumina, which the seed does not give. Handbook values of
//!   the alumina grades (85 % to 99.9 % Al2O3) lie between 870 and 940
//!   J/(kg K) (the alumina entries of MakeItFrom.com, after Shackelford &
//!   Doremus, *Ceramic and Glass Materials*, Springer 2008); dense
//!   alpha-alumina alone has 775 J/(kg K) at 298 K (79.0 J/(mol K), the
//!   NIST-JANAF table). With AD85's Gruneisen coefficient of 0 the heat
//!   does not reach the pressure (eq. 16); it sets the reported
//!   temperature.
//! - `plate_taylor_quinney` = 1 (all plastic work heats the plate) and
//!   `plate_initial_temperature` = 293 K, the reference state of the
//!   internal energy of eq. (16).
//!
//! The material presets ([`super::presets`]) are choices of a strength
//! model and an equation of state ([`super::choice::MaterialChoice`]) and
//! cannot hold a damage model, so AD85 is not one of them: the ceramic's
//! sets are the levels of `plate_ceramic`, and a scene's parameters
//! override single constants.
//!
//! **Ranges.** Each range lies inside what [`RajendranGrove::validate`]
//! accepts for that constant alone, so a value in range fails only the
//! checks that join constants: the matrix's Poisson's ratio from
//! `plate_rg_beta1` and `plate_shear_modulus` must lie in (0, 0.5], and the
//! initial crack density `plate_flaw_density * plate_crack_size^3` must not
//! pass `plate_critical_damage`. [`ceramic_material`] refuses both with
//! the parameters' names.

use super::Material;
use super::rajendran_grove::RajendranGrove;
use crate::error::{Error, Result};
use crate::params::{Level, ParamSpec, Range, levels_spec, spec as row};

/// AD85, the source of the defaults.
const AD85: RajendranGrove = RajendranGrove::ad85();

/// The initial crack size a0 (m) of `ad85_spall`, 100 µm: the smallest
/// round a0 at which a plate-impact target of the seed's AD85 shows a spall
/// signal at every flyer speed from 100 to 500 m/s (the module
/// documentation). The seed prints 0.58 µm (`ad85_seed`, the default).
pub const SPALL_CRACK_SIZE: f64 = 1.0e-4;

/// The levels of `plate_ceramic`: the sets of constants by name. Each sets
/// `plate_crack_size`, `plate_tensile_flaw_size` and `plate_n2_open`;
/// [`DEFAULT_CERAMIC`] is the default.
pub const CERAMICS: &[Level] = &[
    Level {
        name: "ad85_seed",
        description: "AD85 alumina exactly as seed 004's Table 1 prints it (a0 = 0.58 um): the seed's \
                      penetration case as printed; its plate cannot crack in tension below the HEL",
        sets: &[
            ("plate_crack_size", AD85.initial_crack_size),
            ("plate_tensile_flaw_size", 0.0),
            ("plate_n2_open", AD85.opening[1]),
        ],
    },
    Level {
        name: "ad85_spall",
        description: "AD85 with the initial crack size a0 = 100 um, the smallest round a0 whose \
                      plate-impact target spalls at every flyer speed from 100 to 500 m/s \
                      (in the ballistic case its plate pulverizes to the rim)",
        sets: &[
            ("plate_crack_size", SPALL_CRACK_SIZE),
            ("plate_tensile_flaw_size", 0.0),
            ("plate_n2_open", AD85.opening[1]),
        ],
    },
    Level {
        name: "ad85_planes",
        description: "AD85 as the seed prints it (a0 = 0.58 um for the cracks that slide in compression) \
                      with tensile crack planes from flaws of a_t = 188 um, the penny crack that opens at \
                      210 MPa, the tensile strength of the weakest engineering alumina, growing by the \
                      seed's n2+ = 0.07",
        sets: &[
            ("plate_crack_size", AD85.initial_crack_size),
            ("plate_tensile_flaw_size", PLANES_FLAW_SIZE),
            ("plate_n2_open", AD85.opening[1]),
        ],
    },
    Level {
        name: "ad85_planes_freund",
        description: "the default: ad85_planes whose tensile cracks grow by Freund's equation of motion \
                      (n2+ = 1: a crack runs at c_R (1 - G_c / G)), so that a plane's crack, once past \
                      its onset, runs toward the Rayleigh speed as its release rate G grows (the \
                      seed's n2+ = 0.07 holds it far slower; issue 68)",
        sets: &[
            ("plate_crack_size", AD85.initial_crack_size),
            ("plate_tensile_flaw_size", PLANES_FLAW_SIZE),
            ("plate_n2_open", FREUND_N2),
        ],
    },
];

/// The index of the default level of `plate_ceramic`,
/// `ad85_planes_freund`.
pub const DEFAULT_CERAMIC: usize = 3;

/// The growth exponent n2+ of `ad85_planes_freund`'s opening cracks, 1:
/// eq. (24) with n1+ = 1 and n2+ = 1 is `da/dt = c_R (1 - G_c / G)`, the
/// equation of motion of a crack under a load that does not change as it
/// runs (Freund, *Dynamic Fracture Mechanics*, Cambridge 1990, ch. 5:
/// the release rate of a running crack is its static value times a
/// universal function of the speed, about `1 - v / c_R`). The seed's 0.07
/// is Rajendran and Grove's fit for their isotropic cracks from 0.58 µm
/// flaws; with it a tensile plane's crack runs at a few per cent of c_R
/// until G is many times G_c, and the plate-impact target carries 3.6-6
/// times Grady's spall tension (VALIDATION.md, "Tensile crack planes").
pub const FREUND_N2: f64 = 1.0;

/// The tensile flaw size a_t (m) of `ad85_planes`, 188 µm: the radius of
/// the penny crack that opens under a normal tension of 210 MPa with the
/// seed's K_IC = 3.25 MPa m^1/2, `a_t = (pi / 4) (K_IC / sigma_t)^2`. 210 MPa
/// is the ultimate tensile strength of 93-95 % alumina (ASTM D2442 Type II),
/// the lowest of the engineering aluminas that MakeItFrom.com lists after
/// Shackelford & Doremus, *Ceramic and Glass Materials* (Springer 2008),
/// whose range is 210-290 MPa; AD85 (85 % alumina) is weaker than any of
/// them, so 210 MPa is an upper bound of its static tensile strength.
pub const PLANES_FLAW_SIZE: f64 = 188e-6;

/// Specific heat of the default plate (J/(kg K)): engineering alumina (see
/// the module documentation for the source).
const ALUMINA_SPECIFIC_HEAT: f64 = 880.0;

/// Every parameter of a plate of Rajendran-Grove ceramic, under `plate_`:
/// the set of constants by name (`plate_ceramic`), the model's constants in
/// the order of seed 004's Table 1, then the thermal constants and the
/// initial temperature. Defaults: AD85 ([`RajendranGrove::ad85`]), 880
/// J/(kg K), Taylor-Quinney 1, 293 K.
pub const PLATE_CERAMIC: [ParamSpec; 29] = [
    levels_spec(
        "plate_ceramic",
        DEFAULT_CERAMIC,
        CERAMICS,
        "the ceramic's set of constants, which sets plate_crack_size (a value set by hand overrides it): \
         0 = ad85_seed (the seed's Table 1 as printed, a0 = 0.58 um: it cannot crack in tension \
         below its HEL), \
         1 = ad85_spall (a0 = 100 um, the smallest round a0 whose plate-impact target spalls; README), \
         2 = ad85_planes (the seed's a0 with tensile crack planes from flaws of a_t = 188 um), \
         3 = ad85_planes_freund (the default: ad85_planes whose tensile cracks grow by Freund's law, n2+ = 1)",
    ),
    row(
        "plate_density",
        "kg/m3",
        AD85.density,
        Range::closed(100.0, 1.0e5),
        "initial density rho0 of the porous ceramic",
    ),
    row(
        "plate_shear_modulus",
        "Pa",
        AD85.shear_modulus,
        Range::closed(1.0e6, 1.0e14),
        "shear modulus G of the ceramic's dense matrix",
    ),
    row(
        "plate_porosity",
        "1",
        AD85.initial_porosity,
        Range::closed(0.0, 0.5),
        "initial porosity f0 (volume fraction of pores)",
    ),
    row(
        "plate_rg_c1",
        "Pa",
        AD85.c1,
        Range::open_closed(0.0, 1.0e11),
        "Rajendran-Grove strength constant C1 (flow stress Y = C1 (1 + C3 ln(rate/rate0)), eq. 22)",
    ),
    row(
        "plate_rg_c3",
        "1",
        AD85.c3,
        Range::closed(0.0, 1.0),
        "Rajendran-Grove strain-rate sensitivity C3 of eq. 22",
    ),
    row(
        "plate_rg_ref_strain_rate",
        "1/s",
        AD85.ref_strain_rate,
        Range::closed(1.0e-6, 1.0e12),
        "reference strain rate rate0 of eq. 22",
    ),
    row(
        "plate_rg_beta1",
        "Pa",
        AD85.beta[0],
        Range::closed(1.0e6, 1.0e15),
        "pressure polynomial beta1 (eq. 17): the bulk modulus K of the dense matrix",
    ),
    row(
        "plate_rg_beta2",
        "Pa",
        AD85.beta[1],
        Range::closed(0.0, 1.0e15),
        "pressure polynomial beta2 (eq. 17), of the squared matrix compression",
    ),
    row(
        "plate_rg_beta3",
        "Pa",
        AD85.beta[2],
        Range::closed(0.0, 1.0e15),
        "pressure polynomial beta3 (eq. 17), of the cubed matrix compression",
    ),
    row(
        "plate_gruneisen",
        "1",
        AD85.gruneisen,
        Range::closed(0.0, 10.0),
        "Gruneisen coefficient Gamma of the ceramic's pressure (eq. 16)",
    ),
    row(
        "plate_flaw_density",
        "1/m3",
        AD85.flaw_density,
        Range::open_closed(0.0, 1.0e20),
        "micro-flaws per unit volume N0* (crack density N0* a^3, eq. 23)",
    ),
    row(
        "plate_crack_size",
        "m",
        AD85.initial_crack_size,
        Range::open_closed(0.0, 1.0e-2),
        "initial micro-crack radius a0",
    ),
    row(
        "plate_friction",
        "1",
        AD85.friction,
        Range::closed(0.0, 10.0),
        "friction coefficient mu of closed (sliding) micro-cracks",
    ),
    row(
        "plate_n1_open",
        "1",
        AD85.opening[0],
        Range::open_closed(0.0, 1.0),
        "crack growth n1+ of opening cracks: their terminal speed in Rayleigh speeds (eq. 24)",
    ),
    row(
        "plate_n2_open",
        "1",
        FREUND_N2,
        Range::open_closed(0.0, 10.0),
        "crack growth exponent n2+ of opening cracks (eq. 24)",
    ),
    row(
        "plate_n1_sliding",
        "1",
        AD85.sliding[0],
        Range::open_closed(0.0, 1.0),
        "crack growth n1- of sliding cracks: their terminal speed in Rayleigh speeds (eq. 24)",
    ),
    row(
        "plate_n2_sliding",
        "1",
        AD85.sliding[1],
        Range::open_closed(0.0, 10.0),
        "crack growth exponent n2- of sliding cracks (eq. 24)",
    ),
    row(
        "plate_fracture_toughness",
        "Pa.m^(1/2)",
        AD85.fracture_toughness,
        Range::open_closed(0.0, 1.0e9),
        "fracture toughness K_IC of the matrix (critical release rate K_IC^2 (1 - nu^2) / E)",
    ),
    row(
        "plate_pulverized_cohesion",
        "Pa",
        AD85.pulverized_cohesion,
        Range::closed(0.0, 1.0e11),
        "cohesion alpha of the pulverized ceramic (strength alpha + beta P, eq. 25)",
    ),
    row(
        "plate_pulverized_friction",
        "1",
        AD85.pulverized_friction,
        Range::closed(0.0, 10.0),
        "pressure slope beta of the pulverized ceramic's strength (eq. 25)",
    ),
    row(
        "plate_critical_damage",
        "1",
        AD85.critical_damage,
        Range::open_closed(0.0, 1.0),
        "crack density N0* a^3 at which the ceramic pulverizes (section 4.3)",
    ),
    row(
        "plate_tensile_flaw_size",
        "m",
        PLANES_FLAW_SIZE,
        Range::closed(0.0, 0.01),
        "initial radius a_t of the flaws that open in tension, on three crack planes of each point \
         (0 = none, the seed's model: its isotropic cracks open in tension too)",
    ),
    row(
        "plate_tensile_flaw_scatter",
        "1",
        AD85.tensile_flaw_scatter,
        Range::closed(0.0, 100.0),
        "Weibull modulus m of the points' tensile strengths: each point draws its own tensile flaw \
         a_t / s^2, s = (ln(1/U) / ln 2)^(1/m) from its index (0 = one flaw size everywhere; \
         else at least 1)",
    ),
    row(
        "plate_tensile_flaw_volume",
        "m3",
        AD85.tensile_flaw_volume,
        Range::closed(0.0, 1.0),
        "reference volume V0 of the tensile strength a_t stands for: with a scatter, each point \
         draws its strength for its own volume V, s = ((V0 / V) ln(1/U) / ln 2)^(1/m), Weibull's \
         volume effect (0 = none; needs plate_tensile_flaw_scatter > 0; the 3-D solver only)",
    ),
    row(
        "plate_shield_radius",
        "m",
        AD85.shield_radius,
        Range::closed(0.0, 0.1),
        "largest radius of a tensile crack's shielding zone: a crack that has grown for a time t \
         keeps near-parallel flaws off its plane within min(n1+ C_R t, this) from starting \
         (Denoual-Hild obscuration; 3-D solver only; 0 = none)",
    ),
    row(
        "plate_specific_heat",
        "J/(kg.K)",
        ALUMINA_SPECIFIC_HEAT,
        Range::closed(1.0, 1.0e5),
        "specific heat C (default: engineering alumina, not given by the seed)",
    ),
    row(
        "plate_taylor_quinney",
        "1",
        1.0,
        Range::closed(0.0, 1.0),
        "Taylor-Quinney coefficient: the fraction of plastic work that becomes heat",
    ),
    row(
        "plate_initial_temperature",
        "K",
        293.0,
        Range::closed(1.0, 1.0e5),
        "plate temperature at impact, the reference state of the internal energy (eq. 16)",
    ),
];

/// The row of [`PLATE_CERAMIC`] called `name`.
fn spec(name: &str) -> Option<&'static ParamSpec> {
    PLATE_CERAMIC.iter().find(|s| s.name == name)
}

/// The ceramic plate's material from the values of [`PLATE_CERAMIC`]:
/// `value` gives the value of a parameter by its full name
/// (`plate_porosity`) and is asked for each row once. Each value is checked
/// against its row's range, then the material against
/// [`Material::validate`] (the checks that join constants: Poisson's ratio,
/// initial crack density); an error names the parameter (or the
/// parameters), the value and the allowed range. The reference temperature
/// of the internal energy is `plate_initial_temperature`.
pub fn ceramic_material(value: impl Fn(&str) -> Result<f64>) -> Result<Material> {
    let material = build(|name| {
        let v = value(name)?;
        if let Some(s) = spec(name) {
            s.check(v)?;
        }
        Ok(v)
    })?;
    material.validate().map_err(named)?;
    Ok(material)
}

/// [`Material::ceramic`] from the values by name, unchecked.
fn build(v: impl Fn(&str) -> Result<f64>) -> Result<Material> {
    let rg = RajendranGrove {
        density: v("plate_density")?,
        shear_modulus: v("plate_shear_modulus")?,
        initial_porosity: v("plate_porosity")?,
        c1: v("plate_rg_c1")?,
        c3: v("plate_rg_c3")?,
        ref_strain_rate: v("plate_rg_ref_strain_rate")?,
        beta: [
            v("plate_rg_beta1")?,
            v("plate_rg_beta2")?,
            v("plate_rg_beta3")?,
        ],
        gruneisen: v("plate_gruneisen")?,
        flaw_density: v("plate_flaw_density")?,
        initial_crack_size: v("plate_crack_size")?,
        friction: v("plate_friction")?,
        opening: [v("plate_n1_open")?, v("plate_n2_open")?],
        sliding: [v("plate_n1_sliding")?, v("plate_n2_sliding")?],
        fracture_toughness: v("plate_fracture_toughness")?,
        pulverized_cohesion: v("plate_pulverized_cohesion")?,
        pulverized_friction: v("plate_pulverized_friction")?,
        critical_damage: v("plate_critical_damage")?,
        tensile_flaw_size: v("plate_tensile_flaw_size")?,
        tensile_flaw_scatter: v("plate_tensile_flaw_scatter")?,
        tensile_flaw_volume: v("plate_tensile_flaw_volume")?,
        shield_radius: v("plate_shield_radius")?,
    };
    Ok(Material::ceramic(
        rg,
        v("plate_specific_heat")?,
        v("plate_taylor_quinney")?,
        v("plate_initial_temperature")?,
    ))
}

/// A validation error of a ceramic material, with the names of
/// [`PLATE_CERAMIC`] in place of the fields' names (`initial_porosity` is
/// `plate_porosity`; the slots of [`Material::ceramic`] that hold `beta1`
/// and `C1` are checked as `bulk_modulus` and `yield_stress`).
fn named(e: Error) -> Error {
    if let Error::Inconsistent(text) = &e
        && text.starts_with("tensile_flaw_volume")
    {
        return Error::Inconsistent(text.replace("tensile_flaw_", "plate_tensile_flaw_"));
    }
    let Error::OutOfRange { name, value, range } = e else {
        return e;
    };
    let full = match name.as_str() {
        "initial_porosity" => "plate_porosity".to_string(),
        "ref_strain_rate" => "plate_rg_ref_strain_rate".to_string(),
        "bulk_modulus" => "plate_rg_beta1".to_string(),
        "yield_stress" => "plate_rg_c1".to_string(),
        "initial_crack_size" => "plate_crack_size".to_string(),
        "crack_friction" => "plate_friction".to_string(),
        "reference_temperature" => "plate_initial_temperature".to_string(),
        n if n.starts_with("poisson ratio") => "Poisson's ratio of the matrix \
             (3 plate_rg_beta1 - 2 plate_shear_modulus) / (6 plate_rg_beta1 + 2 plate_shear_modulus)"
            .to_string(),
        n if n.starts_with("initial crack density") => "initial crack density \
             plate_flaw_density * plate_crack_size^3 (at most plate_critical_damage)"
            .to_string(),
        n if spec(&format!("plate_{n}")).is_some() => format!("plate_{n}"),
        n => format!("plate ceramic's {n}"),
    };
    Error::OutOfRange {
        name: full,
        value,
        range,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::choice::{MaterialChoice, PLATE_BLOCK, block_len, compose};
    use std::collections::{BTreeMap, BTreeSet};

    /// The values of the table by name, `changes` applied.
    fn values(changes: &[(&str, f64)]) -> BTreeMap<&'static str, f64> {
        let mut v: BTreeMap<_, _> = PLATE_CERAMIC.iter().map(|s| (s.name, s.default)).collect();
        for (name, x) in changes {
            *v.get_mut(*name).unwrap_or_else(|| panic!("no row {name}")) = *x;
        }
        v
    }

    /// A lookup of `values` that refuses a name it does not hold.
    fn lookup<'a>(values: &'a BTreeMap<&'static str, f64>) -> impl Fn(&str) -> Result<f64> + 'a {
        |name| {
            values
                .get(name)
                .copied()
                .ok_or_else(|| Error::Inconsistent(format!("asked for {name}")))
        }
    }

    /// The material of the defaults with `changes`.
    fn material(changes: &[(&str, f64)]) -> Result<Material> {
        ceramic_material(lookup(&values(changes)))
    }

    /// The defaults are seed 004's Table 1 (typed out here from the seed)
    /// but for the three knobs of the default level `ad85_planes_freund`
    /// (tensile flaws of 188 µm whose cracks grow with n2+ = 1); the level
    /// `ad85_seed` gives back exactly `Material::ceramic(RajendranGrove::
    /// ad85(), 880, 1, 293)`, `ad85_spall` AD85 with a0 = 100 µm, and every
    /// level sets the same three knobs.
    #[test]
    fn defaults_are_the_seed_ad85_with_the_default_levels_knobs() {
        let table1: [(&str, f64); 29] = [
            ("plate_ceramic", 3.0),
            ("plate_density", 3.42e3),
            ("plate_shear_modulus", 88.0e9),
            ("plate_porosity", 0.10),
            ("plate_rg_c1", 4.0e9),
            ("plate_rg_c3", 0.029),
            ("plate_rg_ref_strain_rate", 1.0),
            ("plate_rg_beta1", 150.0e9),
            ("plate_rg_beta2", 150.0e9),
            ("plate_rg_beta3", 150.0e9),
            ("plate_gruneisen", 0.0),
            ("plate_flaw_density", 1.83e10),
            ("plate_crack_size", 0.58e-6),
            ("plate_friction", 0.72),
            ("plate_n1_open", 1.0),
            ("plate_n2_open", 1.0),
            ("plate_n1_sliding", 0.1),
            ("plate_n2_sliding", 0.07),
            ("plate_fracture_toughness", 3.25e6),
            ("plate_pulverized_cohesion", 0.1e9),
            ("plate_pulverized_friction", 0.1),
            ("plate_critical_damage", 0.75),
            ("plate_tensile_flaw_size", 188e-6),
            ("plate_tensile_flaw_scatter", 0.0),
            ("plate_tensile_flaw_volume", 0.0),
            ("plate_shield_radius", 0.0),
            ("plate_specific_heat", 880.0),
            ("plate_taylor_quinney", 1.0),
            ("plate_initial_temperature", 293.0),
        ];
        assert_eq!(table1.len(), PLATE_CERAMIC.len());
        for ((name, v), s) in table1.iter().zip(&PLATE_CERAMIC) {
            assert_eq!(*name, s.name);
            assert_eq!(v.to_bits(), s.default.to_bits(), "{name}");
        }
        let default = RajendranGrove {
            opening: [1.0, 1.0],
            tensile_flaw_size: 188e-6,
            ..RajendranGrove::ad85()
        };
        assert_eq!(
            material(&[]).unwrap(),
            Material::ceramic(default, 880.0, 1.0, 293.0)
        );
        let names = [
            "ad85_seed",
            "ad85_spall",
            "ad85_planes",
            "ad85_planes_freund",
        ];
        let sets: [[f64; 3]; 4] = [
            [0.58e-6, 0.0, 0.07],
            [100e-6, 0.0, 0.07],
            [0.58e-6, 188e-6, 0.07],
            [0.58e-6, 188e-6, 1.0],
        ];
        for ((level, name), want) in CERAMICS.iter().zip(names).zip(sets) {
            assert_eq!(level.name, name);
            let knobs = [
                "plate_crack_size",
                "plate_tensile_flaw_size",
                "plate_n2_open",
            ];
            let got: Vec<(&str, f64)> = knobs.iter().copied().zip(want).collect();
            assert_eq!(level.sets, got.as_slice(), "{name}");
        }
        assert_eq!(CERAMICS[DEFAULT_CERAMIC].name, "ad85_planes_freund");
        // The seed's Table 1 as printed, bit for bit through the saved form.
        let seed = material(CERAMICS[0].sets).unwrap();
        let want = Material::ceramic(RajendranGrove::ad85(), 880.0, 1.0, 293.0);
        assert_eq!(seed, want);
        assert_eq!(
            serde_json::to_string(&seed).unwrap(),
            serde_json::to_string(&want).unwrap()
        );
        let chosen = RajendranGrove {
            initial_crack_size: 100e-6,
            ..RajendranGrove::ad85()
        };
        assert_eq!(
            material(CERAMICS[1].sets).unwrap(),
            Material::ceramic(chosen, 880.0, 1.0, 293.0)
        );
    }

    /// Every name is under `plate_` and unique; the constants a metal's
    /// block also has carry its names and units, and no other name is one
    /// of the metal block's.
    #[test]
    fn names_are_plate_unique_and_share_the_block_meanings() {
        let names: BTreeSet<_> = PLATE_CERAMIC.iter().map(|s| s.name).collect();
        assert_eq!(names.len(), PLATE_CERAMIC.len(), "a name twice");
        assert!(names.iter().all(|n| n.starts_with("plate_")), "{names:?}");
        let shared = [
            "plate_density",
            "plate_shear_modulus",
            "plate_gruneisen",
            "plate_specific_heat",
            "plate_taylor_quinney",
            "plate_initial_temperature",
        ];
        for s in &PLATE_CERAMIC {
            let metal = PLATE_BLOCK.iter().find(|b| b.spec.name == s.name);
            if shared.contains(&s.name) {
                let metal = metal.unwrap_or_else(|| panic!("{} not in the block", s.name));
                assert_eq!(metal.spec.unit, s.unit, "{}", s.name);
            } else {
                assert!(metal.is_none(), "{} is a metal's name", s.name);
            }
        }
        for name in shared {
            assert!(names.contains(name), "{name}");
        }
    }

    /// Each default lies in its range; each range lies within what the
    /// model accepts for that constant alone: a material with one constant
    /// at either end of its range (just inside an open end) is valid, or
    /// fails only a check that joins it with others, naming them.
    #[test]
    fn defaults_and_ranges_agree_with_the_model() {
        for s in &PLATE_CERAMIC {
            assert!(s.range.contains(s.default), "{}", s.name);
            s.check(s.default).unwrap();
            let r = s.range;
            let lo = if r.min_inclusive {
                r.min
            } else {
                r.min + 1e-9 * (r.max - r.min)
            };
            for x in [lo, r.max] {
                assert!(r.contains(x), "{} {x}", s.name);
                match material(&[(s.name, x)]) {
                    Ok(m) => m.validate().unwrap(),
                    Err(Error::OutOfRange { name, .. }) => {
                        let joined = name.starts_with("Poisson's ratio")
                            || name.starts_with("initial crack density");
                        assert!(joined && name.contains(s.name), "{} = {x}: {name}", s.name);
                    }
                    // A volume needs a scatter, which is 0 by default.
                    Err(Error::Inconsistent(text)) if s.name == "plate_tensile_flaw_volume" => {
                        assert!(
                            text.starts_with("plate_tensile_flaw_volume = 1 m3")
                                && text.contains("plate_tensile_flaw_scatter is 0"),
                            "{text}"
                        );
                        let both = [(s.name, x), ("plate_tensile_flaw_scatter", 10.0)];
                        material(&both).unwrap().validate().unwrap();
                    }
                    Err(e) => panic!("{} = {x}: {e}", s.name),
                }
            }
        }
        // The joined checks do fire at the ends of some ranges.
        assert!(material(&[("plate_crack_size", 1e-2)]).is_err());
        assert!(material(&[("plate_shear_modulus", 1e14)]).is_err());
    }

    /// A value out of its range is refused by the range check, naming the
    /// parameter, the value and the range; values in range that fail a
    /// check joining constants are refused naming the parameters.
    #[test]
    fn bad_values_are_refused_by_name() {
        // A Weibull modulus in (0, 1): in the table's range, refused by the
        // model with its name.
        match material(&[("plate_tensile_flaw_scatter", 0.5)]) {
            Err(Error::OutOfRange { name, value, range }) => {
                assert_eq!(name, "plate_tensile_flaw_scatter");
                assert_eq!(value, 0.5);
                assert_eq!(range, "0 (none) or [1, 100]");
            }
            other => panic!("{other:?}"),
        }
        match material(&[("plate_porosity", 1.5)]) {
            Err(Error::OutOfRange { name, value, range }) => {
                assert_eq!(name, "plate_porosity");
                assert_eq!(value, 1.5);
                assert_eq!(range, "[0, 0.5]");
            }
            other => panic!("{other:?}"),
        }
        let e = material(&[("plate_porosity", f64::NAN)]).unwrap_err();
        assert!(e.to_string().contains("`plate_porosity`"), "{e}");
        // 1 mm cracks: N0 a0^3 = 1.83e10 * 1e-9 = 18.3, past 0.75.
        assert!(spec("plate_crack_size").unwrap().range.contains(1e-3));
        match material(&[("plate_crack_size", 1e-3)]) {
            Err(Error::OutOfRange { name, value, range }) => {
                assert!(name.contains("plate_crack_size"), "{name}");
                assert!(name.contains("plate_flaw_density"), "{name}");
                assert!((value - 18.3).abs() < 1e-12, "{value}");
                assert_eq!(range, "[0, 0.75]");
            }
            other => panic!("{other:?}"),
        }
        // G = 400 GPa over K = 150 GPa: nu = (450 - 800) / (900 + 800).
        match material(&[("plate_shear_modulus", 400e9)]) {
            Err(Error::OutOfRange { name, value, .. }) => {
                assert!(name.contains("plate_shear_modulus"), "{name}");
                assert!(name.contains("plate_rg_beta1"), "{name}");
                assert!((value + 350.0 / 1700.0).abs() < 1e-15, "{value}");
            }
            other => panic!("{other:?}"),
        }
        // A name the lookup does not have stops the build with its error.
        let partial: BTreeMap<&'static str, f64> = values(&[])
            .into_iter()
            .filter(|(n, _)| *n != "plate_friction")
            .collect();
        let e = ceramic_material(lookup(&partial)).unwrap_err();
        assert!(e.to_string().contains("plate_friction"), "{e}");
    }

    /// Each parameter reaches its own constant of the material: with one
    /// value NaN (past the range check), the material's validation names
    /// that parameter and no other. (`plate_ceramic` reaches the material
    /// through the crack size it sets.)
    #[test]
    fn each_parameter_reaches_its_constant() {
        for s in PLATE_CERAMIC.iter().filter(|s| s.levels.is_empty()) {
            let v = values(&[(s.name, f64::NAN)]);
            let m = build(lookup(&v)).unwrap();
            match m.validate().map_err(named) {
                Err(Error::OutOfRange { name, value, .. }) => {
                    assert_eq!(name, s.name);
                    assert!(value.is_nan());
                }
                other => panic!("{}: {other:?}", s.name),
            }
        }
    }

    /// The table goes into a scene's `const` table, after a metal's block.
    #[test]
    fn the_table_composes_in_const() {
        const BEFORE: [ParamSpec; 1] = [row(
            "impact_speed",
            "m/s",
            1500.0,
            Range::closed(0.0, 1.0e4),
            "speed",
        )];
        const CHOICE: MaterialChoice = MaterialChoice::BILINEAR_LINEAR;
        const N: usize = BEFORE.len() + block_len(CHOICE) + PLATE_CERAMIC.len();
        const TABLE: [ParamSpec; N] = compose::<N>(&BEFORE, CHOICE, &PLATE_CERAMIC);
        assert_eq!(N, 1 + 8 + 29);
        assert_eq!(TABLE[0].name, "impact_speed");
        assert_eq!(TABLE[1].name, "density");
        assert_eq!(&TABLE[9..], &PLATE_CERAMIC[..]);
    }
}
