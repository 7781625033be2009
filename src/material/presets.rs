//! Material presets: named materials with their models and constants, for
//! `[material] preset = "NAME"` in a scene file, `--preset NAME` on the
//! command line and `mi_sim_set_material(sim, "preset", NAME)` in the C ABI.
//! `meshless-impact materials` lists them.
//!
//! Elastic constants given in a source as Young's modulus `E` and Poisson's
//! ratio `nu` become `G = E / (2 (1 + nu))` and `K = E / (3 (1 - 2 nu))`; a
//! tangent modulus `E_t` becomes the plastic modulus `H = E E_t / (E - E_t)`
//! ([`super::bilinear::Bilinear::from_tangent_modulus`]). The tests check
//! every such value against its formula.
//!
//! | preset | models | source |
//! |---|---|---|
//! | `steel_4340_house` | Johnson-Cook, linear | House et al. (1995) test 7 with the 4340 steel constants of Batra & Zhang (2008): the `taylor` scene's defaults, bit for bit |
//! | `aisi310_bilinear` | bilinear, linear | seed 004 (Han, Liu, Rajendran & Atluri), 3-D Taylor example: 8027 kg/m3, E = 199.95 GPa, nu = 0.28, yield 310.26 MPa, hardening slope (tangent modulus) 2.0 GPa |
//! | `tungsten_seed` | bilinear, linear | seed 004, penetration example: 16980 kg/m3, E = 299.6 GPa, nu = 0.21, yield 1.5 GPa, no hardening |
//! | `ofhc_copper_jc` | Johnson-Cook, linear | Johnson & Cook (1985; the same constants as their 1983 table): A = 90 MPa, B = 292 MPa, n = 0.31, C = 0.025, m = 1.09, T_m = 1356 K, 8960 kg/m3, 383 J/(kg K) |
//! | `aluminium_6061t6_jc` | Johnson-Cook, linear | the 6061-T6 constants attributed to Johnson & Cook (1985): A = 324 MPa, B = 114 MPa, n = 0.42, C = 0.002, m = 1.34, T_m = 925 K, 2703 kg/m3, 896 J/(kg K) |
//! | `copper_wilkins_bilinear` | bilinear, linear | the Wilkins copper bar (Wilkins & Guinan 1973; Simo 1992): 8930 kg/m3, E = 117 GPa, nu = 0.35, yield 400 MPa, H = 100 MPa |
//!
//! Choices where a source lacks a constant:
//!
//! - `taylor_quinney` = 0.9 (the usual fraction of plastic work that heats
//!   a metal) for every preset but the house steel, whose 1.0 is the
//!   solver's default; with the bilinear model and the linear EOS the heat
//!   acts on nothing but the reported temperature;
//! - specific heats: AISI 310 500 J/(kg K) and tungsten 134 J/(kg K)
//!   (handbook values at room temperature), Wilkins copper 385 J/(kg K) (as
//!   `scenes/wilkins_copper.toml`);
//! - elastic constants of the Johnson-Cook metals (the Johnson-Cook tables
//!   give none): OFHC copper E = 124 GPa, nu = 0.34; 6061-T6 E = 68.9 GPa,
//!   nu = 0.33 (handbook values);
//! - room and initial temperature 293 K, reference strain rate 1/s.

use super::choice::{MaterialChoice, Prefix};
use crate::error::{Error, Result};

/// A named material: its models and a value for every parameter they use.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Preset {
    /// Name, as `preset = "..."` takes it.
    pub name: &'static str,
    /// Its models.
    pub choice: MaterialChoice,
    /// A value for every parameter of the choice's block, by name without a
    /// prefix.
    pub values: &'static [(&'static str, f64)],
    /// Where the constants come from.
    pub source: &'static str,
}

/// Every preset, in listing order.
pub static PRESETS: &[Preset] = &[
    Preset {
        name: "steel_4340_house",
        choice: MaterialChoice::JOHNSON_COOK_LINEAR,
        values: &[
            ("density", 7830.0),
            ("shear_modulus", 82.9e9),
            ("bulk_modulus", 169.1e9),
            ("specific_heat", 460.0),
            ("taylor_quinney", 1.0),
            ("jc_a", 792.0e6),
            ("jc_b", 510.0e6),
            ("jc_n", 0.26),
            ("jc_c", 0.014),
            ("jc_m", 1.03),
            ("melt_temperature", 1293.0),
            ("room_temperature", 293.0),
            ("initial_temperature", 293.0),
            ("ref_strain_rate", 1.0),
        ],
        source: "House et al. (1995) test 7, 4340 steel constants of Batra & Zhang (2008): the taylor scene's defaults",
    },
    Preset {
        name: "aisi310_bilinear",
        choice: MaterialChoice::BILINEAR_LINEAR,
        values: &[
            ("density", 8027.0),
            // E = 199.95 GPa, nu = 0.28.
            ("shear_modulus", 78105468750.0),
            ("bulk_modulus", 151477272727.27274),
            ("specific_heat", 500.0),
            ("taylor_quinney", 0.9),
            ("yield_stress", 310.26e6),
            // E_t = 2.0 GPa.
            ("hardening_modulus", 2020207123.0108614),
            ("initial_temperature", 293.0),
        ],
        source: "seed 004 (Han et al.), 3-D Taylor example: E = 199.95 GPa, nu = 0.28, tangent modulus 2.0 GPa",
    },
    Preset {
        name: "tungsten_seed",
        choice: MaterialChoice::BILINEAR_LINEAR,
        values: &[
            ("density", 16980.0),
            // E = 299.6 GPa, nu = 0.21.
            ("shear_modulus", 123801652892.56198),
            ("bulk_modulus", 172183908045.977),
            ("specific_heat", 134.0),
            ("taylor_quinney", 0.9),
            ("yield_stress", 1.5e9),
            ("hardening_modulus", 0.0),
            ("initial_temperature", 293.0),
        ],
        source: "seed 004 (Han et al.), penetration example: E = 299.6 GPa, nu = 0.21, yield 1.5 GPa",
    },
    Preset {
        name: "ofhc_copper_jc",
        choice: MaterialChoice::JOHNSON_COOK_LINEAR,
        values: &[
            ("density", 8960.0),
            // E = 124 GPa, nu = 0.34 (handbook).
            ("shear_modulus", 46268656716.41791),
            ("bulk_modulus", 129166666666.66669),
            ("specific_heat", 383.0),
            ("taylor_quinney", 0.9),
            ("jc_a", 90.0e6),
            ("jc_b", 292.0e6),
            ("jc_n", 0.31),
            ("jc_c", 0.025),
            ("jc_m", 1.09),
            ("melt_temperature", 1356.0),
            ("room_temperature", 293.0),
            ("initial_temperature", 293.0),
            ("ref_strain_rate", 1.0),
        ],
        source: "Johnson & Cook (1985), OFHC copper; E = 124 GPa, nu = 0.34 (handbook)",
    },
    Preset {
        name: "aluminium_6061t6_jc",
        choice: MaterialChoice::JOHNSON_COOK_LINEAR,
        values: &[
            ("density", 2703.0),
            // E = 68.9 GPa, nu = 0.33 (handbook).
            ("shear_modulus", 25902255639.097744),
            ("bulk_modulus", 67549019607.84314),
            ("specific_heat", 896.0),
            ("taylor_quinney", 0.9),
            ("jc_a", 324.0e6),
            ("jc_b", 114.0e6),
            ("jc_n", 0.42),
            ("jc_c", 0.002),
            ("jc_m", 1.34),
            ("melt_temperature", 925.0),
            ("room_temperature", 293.0),
            ("initial_temperature", 293.0),
            ("ref_strain_rate", 1.0),
        ],
        source: "6061-T6 constants attributed to Johnson & Cook (1985); E = 68.9 GPa, nu = 0.33 (handbook)",
    },
    Preset {
        name: "copper_wilkins_bilinear",
        choice: MaterialChoice::BILINEAR_LINEAR,
        values: &[
            ("density", 8930.0),
            // E = 117 GPa, nu = 0.35, as scenes/wilkins_copper.toml.
            ("shear_modulus", 43333333333.33333),
            ("bulk_modulus", 130.0e9),
            ("specific_heat", 385.0),
            ("taylor_quinney", 0.9),
            ("yield_stress", 400.0e6),
            ("hardening_modulus", 100.0e6),
            ("initial_temperature", 293.0),
        ],
        source: "Wilkins copper bar (Wilkins & Guinan 1973; Simo 1992): E = 117 GPa, nu = 0.35, 400 MPa + 100 MPa eps_p",
    },
];

impl Preset {
    /// The preset called `name`; otherwise an error listing the presets.
    pub fn named(name: &str) -> Result<&'static Preset> {
        PRESETS
            .iter()
            .find(|p| p.name == name)
            .ok_or_else(|| Error::UnknownModel {
                key: "preset".into(),
                name: name.into(),
                allowed: PRESETS
                    .iter()
                    .map(|p| p.name)
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }

    /// The value of the parameter `base` (no prefix), if its models use it.
    pub fn value(&self, base: &str) -> Option<f64> {
        self.values
            .iter()
            .find(|(n, _)| *n == base)
            .map(|(_, v)| *v)
    }

    /// The material of the preset.
    pub fn material(&self) -> Result<super::Material> {
        self.choice.material(Prefix::None, |name| {
            self.value(name)
                .ok_or_else(|| Error::Inconsistent(format!("preset {} has no {name}", self.name)))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::bilinear::Bilinear;
    use crate::material::choice::BLOCK;

    /// Each preset gives exactly the parameters its models use, each in its
    /// range, and makes a valid material.
    #[test]
    fn presets_are_complete_in_range_and_valid() {
        for p in PRESETS {
            let specs = p.choice.param_specs(Prefix::None);
            assert_eq!(p.values.len(), specs.len(), "{}", p.name);
            for s in &specs {
                let v = p
                    .value(s.name)
                    .unwrap_or_else(|| panic!("{}: {}", p.name, s.name));
                s.check(v).unwrap();
            }
            p.material().unwrap().validate().unwrap();
            assert_eq!(Preset::named(p.name), Ok(p));
        }
        let e = Preset::named("ofhc_copper").unwrap_err().to_string();
        assert!(
            e.contains("`ofhc_copper`") && e.contains("ofhc_copper_jc"),
            "{e}"
        );
    }

    /// The house steel is the block's defaults, bit for bit.
    #[test]
    fn house_steel_is_the_default() {
        let p = Preset::named("steel_4340_house").unwrap();
        for b in BLOCK.iter().filter(|b| p.choice.uses(b.uses)) {
            assert_eq!(
                p.value(b.base).map(f64::to_bits),
                Some(b.spec.default.to_bits())
            );
        }
    }

    /// The elastic and hardening moduli follow from the sources' E, nu and
    /// E_t by their formulas.
    #[test]
    fn derived_moduli_follow_from_the_sources() {
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
        for (name, e, nu) in [
            ("aisi310_bilinear", 199.95e9, 0.28),
            ("tungsten_seed", 299.6e9, 0.21),
            ("ofhc_copper_jc", 124e9, 0.34),
            ("aluminium_6061t6_jc", 68.9e9, 0.33),
            ("copper_wilkins_bilinear", 117e9, 0.35),
        ] {
            let p = Preset::named(name).unwrap();
            let (g, k) = (
                p.value("shear_modulus").unwrap(),
                p.value("bulk_modulus").unwrap(),
            );
            assert!(close(g, e / (2.0 * (1.0 + nu))), "{name}: G = {g}");
            assert!(close(k, e / (3.0 * (1.0 - 2.0 * nu))), "{name}: K = {k}");
        }
        let aisi = Preset::named("aisi310_bilinear").unwrap();
        let h = Bilinear::from_tangent_modulus(310.26e6, 199.95e9, 2.0e9).hardening_modulus;
        assert_eq!(aisi.value("hardening_modulus"), Some(h));
    }
}
