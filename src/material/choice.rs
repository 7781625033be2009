//! Choosing a material's models by name, and the parameter block of a
//! choice: the one vocabulary that scene files (`[material]`), the CLI
//! (`--strength`, `--eos`, `--preset`), the C ABI (`mi_sim_set_material`)
//! and the FMUs (one FMU per choice) share.
//!
//! - Strength: `johnson_cook` ([`super::johnson_cook`]) or `bilinear`
//!   ([`super::bilinear`]).
//! - Equation of state: `linear` ([`super::eos`]) or `mie_gruneisen`
//!   ([`super::mie_gruneisen`]).
//!
//! A choice lists only the parameters its models use ([`BLOCK`] filtered by
//! [`MaterialChoice::uses`]): `bulk_modulus` for the linear EOS, `eos_c0`,
//! `eos_s` and `gruneisen` for Mie-Grüneisen; the `jc_*` constants, the melt
//! and room temperatures and `ref_strain_rate` for Johnson-Cook,
//! `yield_stress` and `hardening_modulus` for bilinear. Every choice has
//! `density`, `shear_modulus`, `specific_heat`, `taylor_quinney` and
//! `initial_temperature` (the body's temperature at the start, the reference
//! state of the EOS's internal energy).
//!
//! **Two bodies.** A scene with two bodies embeds each body's block under a
//! [`Prefix`] (`projectile_`, `plate_`): `projectile_density`,
//! `plate_shear_modulus`, ... so that no two bodies share a name.
//! [`MaterialChoice::param_specs`] gives a block under a prefix and
//! [`MaterialChoice::material`] builds the [`Material`] from the values
//! under it.
//!
//! **Defaults.** The block's defaults are the house 4340 steel of the
//! `taylor` scene (preset `steel_4340_house`, [`super::presets`]); where
//! that steel has no constant, they are: the Mie-Grüneisen constants of
//! 4340 steel in Steinberg (1996, LLNL UCRL-MA-106439: `c0` = 4578 m/s,
//! `s` = 1.33, `Gamma` = 1.67), and for bilinear the Johnson-Cook curve of
//! the house steel made linear (`yield_stress` = `jc_a` = 792 MPa,
//! `hardening_modulus` = `jc_b` = 510 MPa, Johnson-Cook with n = 1).

use super::bilinear::Bilinear;
use super::eos::LinearEos;
use super::johnson_cook::JohnsonCook;
use super::mie_gruneisen::MieGruneisen;
use super::{Damage, Eos, Material, Strength};
use crate::error::{Error, Result};
use crate::params::{ParamSpec, Range};

/// A strength model, by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StrengthKind {
    /// `johnson_cook`: Johnson-Cook thermo-viscoplasticity.
    JohnsonCook,
    /// `bilinear`: bilinear J2 plasticity with linear isotropic hardening.
    Bilinear,
}

/// An equation of state, by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EosKind {
    /// `linear`: `P = K (rho / rho0 - 1)`.
    Linear,
    /// `mie_gruneisen`: Mie-Grüneisen with a linear `U_s`-`u_p` curve.
    MieGruneisen,
}

impl StrengthKind {
    /// Every strength model, in listing order.
    pub const ALL: [StrengthKind; 2] = [StrengthKind::JohnsonCook, StrengthKind::Bilinear];

    /// The name in scene files, on the command line, in the C ABI.
    pub const fn name(self) -> &'static str {
        match self {
            StrengthKind::JohnsonCook => "johnson_cook",
            StrengthKind::Bilinear => "bilinear",
        }
    }

    /// The model called `name`; otherwise an error listing the names.
    pub fn named(name: &str) -> Result<Self> {
        named("strength", name, &Self::ALL, Self::name)
    }
}

impl EosKind {
    /// Every equation of state, in listing order.
    pub const ALL: [EosKind; 2] = [EosKind::Linear, EosKind::MieGruneisen];

    /// The name in scene files, on the command line, in the C ABI.
    pub const fn name(self) -> &'static str {
        match self {
            EosKind::Linear => "linear",
            EosKind::MieGruneisen => "mie_gruneisen",
        }
    }

    /// The equation of state called `name`; otherwise an error listing the
    /// names.
    pub fn named(name: &str) -> Result<Self> {
        named("eos", name, &Self::ALL, Self::name)
    }
}

/// The entry of `all` called `name`, or [`Error::UnknownModel`].
fn named<T: Copy>(key: &str, name: &str, all: &[T], name_of: fn(T) -> &'static str) -> Result<T> {
    all.iter()
        .copied()
        .find(|k| name_of(*k) == name)
        .ok_or_else(|| Error::UnknownModel {
            key: key.to_string(),
            name: name.to_string(),
            allowed: all
                .iter()
                .map(|k| name_of(*k))
                .collect::<Vec<_>>()
                .join(", "),
        })
}

/// The models of a material: a strength model and an equation of state
/// (no damage model is choosable yet).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialChoice {
    /// Strength model.
    pub strength: StrengthKind,
    /// Equation of state.
    pub eos: EosKind,
}

/// Which choices use a parameter of the block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Uses {
    /// Every choice.
    All,
    /// The choices with this strength model.
    Strength(StrengthKind),
    /// The choices with this equation of state.
    Eos(EosKind),
}

/// One row of a material block: a parameter and the choices that use it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlockParam {
    /// The parameter's name without a prefix (`density`).
    pub base: &'static str,
    /// Which choices use it.
    pub uses: Uses,
    /// The parameter, its name under the block's prefix.
    pub spec: ParamSpec,
}

impl MaterialChoice {
    /// The choice of `strength` and `eos`.
    pub const fn new(strength: StrengthKind, eos: EosKind) -> Self {
        MaterialChoice { strength, eos }
    }
    /// Johnson-Cook strength with the linear EOS: the `taylor` scene's
    /// default.
    pub const JOHNSON_COOK_LINEAR: Self = Self::new(StrengthKind::JohnsonCook, EosKind::Linear);
    /// Bilinear strength with the linear EOS.
    pub const BILINEAR_LINEAR: Self = Self::new(StrengthKind::Bilinear, EosKind::Linear);
    /// Johnson-Cook strength with Mie-Grüneisen.
    pub const JOHNSON_COOK_MIE_GRUNEISEN: Self =
        Self::new(StrengthKind::JohnsonCook, EosKind::MieGruneisen);
    /// Bilinear strength with Mie-Grüneisen.
    pub const BILINEAR_MIE_GRUNEISEN: Self =
        Self::new(StrengthKind::Bilinear, EosKind::MieGruneisen);
    /// Every choice.
    pub const ALL: [MaterialChoice; 4] = [
        Self::JOHNSON_COOK_LINEAR,
        Self::BILINEAR_LINEAR,
        Self::JOHNSON_COOK_MIE_GRUNEISEN,
        Self::BILINEAR_MIE_GRUNEISEN,
    ];

    /// Whether this choice's models use a parameter of the block.
    pub(crate) const fn uses(self, uses: Uses) -> bool {
        match uses {
            Uses::All => true,
            Uses::Strength(s) => s as u8 == self.strength as u8,
            Uses::Eos(e) => e as u8 == self.eos as u8,
        }
    }

    /// The parameters of this choice under `prefix`, in block order.
    pub fn param_specs(self, prefix: Prefix) -> Vec<ParamSpec> {
        prefix
            .block()
            .iter()
            .filter(|p| self.uses(p.uses))
            .map(|p| p.spec)
            .collect()
    }

    /// The material of this choice from the values under `prefix`: `value`
    /// gives the value of a parameter by its full name (`projectile_density`),
    /// and is asked only for the parameters this choice uses.
    pub fn material(self, prefix: Prefix, value: impl Fn(&str) -> Result<f64>) -> Result<Material> {
        let v = |base: &str| value(&format!("{}{base}", prefix.as_str()));
        let density = v("density")?;
        let eos = match self.eos {
            EosKind::Linear => Eos::Linear(LinearEos {
                bulk_modulus: v("bulk_modulus")?,
                density,
            }),
            EosKind::MieGruneisen => Eos::MieGruneisen(MieGruneisen {
                density,
                c0: v("eos_c0")?,
                s: v("eos_s")?,
                gruneisen: v("gruneisen")?,
            }),
        };
        let strength = match self.strength {
            StrengthKind::JohnsonCook => Strength::JohnsonCook(JohnsonCook {
                a: v("jc_a")?,
                b: v("jc_b")?,
                n: v("jc_n")?,
                c: v("jc_c")?,
                m: v("jc_m")?,
                melt_temperature: v("melt_temperature")?,
                room_temperature: v("room_temperature")?,
                ref_strain_rate: v("ref_strain_rate")?,
            }),
            StrengthKind::Bilinear => Strength::Bilinear(Bilinear {
                yield_stress: v("yield_stress")?,
                hardening_modulus: v("hardening_modulus")?,
            }),
        };
        Ok(Material {
            eos,
            strength,
            damage: Damage::None,
            shear_modulus: v("shear_modulus")?,
            specific_heat: v("specific_heat")?,
            taylor_quinney: v("taylor_quinney")?,
            reference_temperature: v("initial_temperature")?,
        })
    }

    /// Checks what single ranges cannot: Johnson-Cook's melt temperature
    /// above its room temperature and above the initial temperature.
    pub fn check_consistency(
        self,
        prefix: Prefix,
        value: impl Fn(&str) -> Result<f64>,
    ) -> Result<()> {
        if self.strength != StrengthKind::JohnsonCook {
            return Ok(());
        }
        let p = prefix.as_str();
        let v = |base: &str| value(&format!("{p}{base}"));
        let (melt, room, initial) = (
            v("melt_temperature")?,
            v("room_temperature")?,
            v("initial_temperature")?,
        );
        if melt <= room {
            return Err(Error::Inconsistent(format!(
                "{p}melt_temperature = {melt} K must exceed {p}room_temperature = {room} K"
            )));
        }
        if initial >= melt {
            return Err(Error::Inconsistent(format!(
                "{p}initial_temperature = {initial} K must be below {p}melt_temperature = {melt} K"
            )));
        }
        Ok(())
    }
}

impl std::fmt::Display for MaterialChoice {
    /// `strength = bilinear, eos = linear`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "strength = {}, eos = {}",
            self.strength.name(),
            self.eos.name()
        )
    }
}

/// Where a material block sits in a scene's parameter table: alone (one
/// body: `density`) or under a body's prefix (`projectile_density`,
/// `plate_density`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Prefix {
    /// No prefix: the one body of a scene.
    None,
    /// `projectile_`.
    Projectile,
    /// `plate_`.
    Plate,
}

impl Prefix {
    /// Every prefix.
    pub const ALL: [Prefix; 3] = [Prefix::None, Prefix::Projectile, Prefix::Plate];

    /// The prefix of the names (`""`, `"projectile_"`, `"plate_"`).
    pub const fn as_str(self) -> &'static str {
        match self {
            Prefix::None => "",
            Prefix::Projectile => "projectile_",
            Prefix::Plate => "plate_",
        }
    }

    /// The block of every material parameter under this prefix.
    pub(crate) const fn block(self) -> &'static [BlockParam] {
        match self {
            Prefix::None => &BLOCK,
            Prefix::Projectile => &PROJECTILE_BLOCK,
            Prefix::Plate => &PLATE_BLOCK,
        }
    }
}

/// Declares the block of every material parameter under a prefix: one
/// source for the names, units, defaults, ranges and meanings.
macro_rules! material_block {
    ($prefix:literal) => {
        material_block!(@rows $prefix;
            "density", All, "kg/m3", 7830.0, Range::closed(100.0, 1.0e5),
                "reference mass density";
            "shear_modulus", All, "Pa", 82.9e9, Range::closed(1.0e6, 1.0e14),
                "shear modulus mu";
            "bulk_modulus", Eos(EosKind::Linear), "Pa", 169.1e9, Range::closed(1.0e6, 1.0e15),
                "bulk modulus K of the linear EOS P = K(rho/rho0 - 1)";
            "eos_c0", Eos(EosKind::MieGruneisen), "m/s", 4578.0, Range::closed(1.0, 1.0e5),
                "Mie-Gruneisen: bulk sound speed c0";
            "eos_s", Eos(EosKind::MieGruneisen), "1", 1.33, Range::closed(0.0, 10.0),
                "Mie-Gruneisen: slope s of the shock-particle velocity line U_s = c0 + s u_p";
            "gruneisen", Eos(EosKind::MieGruneisen), "1", 1.67, Range::closed(0.0, 10.0),
                "Mie-Gruneisen: Gruneisen parameter Gamma";
            "specific_heat", All, "J/(kg.K)", 460.0, Range::closed(1.0, 1.0e5),
                "specific heat C";
            "taylor_quinney", All, "1", 1.0, Range::closed(0.0, 1.0),
                "Taylor-Quinney coefficient: the fraction of plastic work that becomes heat";
            "jc_a", Strength(StrengthKind::JohnsonCook), "Pa", 792.0e6, Range::closed(0.0, 1.0e11),
                "Johnson-Cook a (initial yield stress)";
            "jc_b", Strength(StrengthKind::JohnsonCook), "Pa", 510.0e6, Range::closed(0.0, 1.0e11),
                "Johnson-Cook b (hardening modulus)";
            "jc_n", Strength(StrengthKind::JohnsonCook), "1", 0.26, Range::open_closed(0.0, 5.0),
                "Johnson-Cook n (hardening exponent)";
            "jc_c", Strength(StrengthKind::JohnsonCook), "1", 0.014, Range::closed(0.0, 1.0),
                "Johnson-Cook c (strain-rate sensitivity)";
            "jc_m", Strength(StrengthKind::JohnsonCook), "1", 1.03, Range::open_closed(0.0, 10.0),
                "Johnson-Cook m (thermal softening exponent)";
            "yield_stress", Strength(StrengthKind::Bilinear), "Pa", 792.0e6, Range::closed(0.0, 1.0e11),
                "bilinear J2: initial yield stress";
            "hardening_modulus", Strength(StrengthKind::Bilinear), "Pa", 510.0e6, Range::closed(0.0, 1.0e12),
                "bilinear J2: plastic hardening modulus H, yield = yield_stress + H eps_p (from a tangent modulus E_t: H = E E_t / (E - E_t))";
            "melt_temperature", Strength(StrengthKind::JohnsonCook), "K", 1293.0, Range::closed(1.0, 1.0e5),
                "melting temperature T_M";
            "room_temperature", Strength(StrengthKind::JohnsonCook), "K", 293.0, Range::closed(1.0, 1.0e5),
                "room temperature T_room";
            "initial_temperature", All, "K", 293.0, Range::closed(1.0, 1.0e5),
                "rod temperature at impact";
            "ref_strain_rate", Strength(StrengthKind::JohnsonCook), "1/s", 1.0, Range::closed(1.0e-6, 1.0e12),
                "reference strain rate of Johnson-Cook";
        )
    };
    (@rows $prefix:literal; $( $base:literal, $uses:expr, $unit:literal, $default:expr, $range:expr, $desc:literal; )*) => {
        [ $( BlockParam {
            base: $base,
            uses: { #[allow(unused_imports)] use Uses::*; $uses },
            spec: ParamSpec {
                name: concat!($prefix, $base),
                unit: $unit,
                default: $default,
                range: $range,
                description: $desc,
                levels: &[],
            },
        }, )* ]
    };
}

/// Every material parameter, no prefix, in the order scene tables list
/// them; a choice keeps the rows it uses ([`MaterialChoice::uses`]).
pub const BLOCK: [BlockParam; 19] = material_block!("");
/// [`BLOCK`] under `projectile_`.
pub const PROJECTILE_BLOCK: [BlockParam; 19] = material_block!("projectile_");
/// [`BLOCK`] under `plate_`.
pub const PLATE_BLOCK: [BlockParam; 19] = material_block!("plate_");

/// The number of rows of [`BLOCK`] that `choice` uses.
pub const fn block_len(choice: MaterialChoice) -> usize {
    let mut n = 0;
    let mut i = 0;
    while i < BLOCK.len() {
        if choice.uses(BLOCK[i].uses) {
            n += 1;
        }
        i += 1;
    }
    n
}

/// A scene's parameter table at compile time: `before`, the rows of
/// [`BLOCK`] that `choice` uses, then `after`. `N` is the total length
/// (`before.len() + block_len(choice) + after.len()`); a wrong `N` stops
/// the build.
pub const fn compose<const N: usize>(
    before: &[ParamSpec],
    choice: MaterialChoice,
    after: &[ParamSpec],
) -> [ParamSpec; N] {
    let mut out = [BLOCK[0].spec; N];
    let mut n = 0;
    let mut i = 0;
    while i < before.len() {
        out[n] = before[i];
        n += 1;
        i += 1;
    }
    i = 0;
    while i < BLOCK.len() {
        if choice.uses(BLOCK[i].uses) {
            out[n] = BLOCK[i].spec;
            n += 1;
        }
        i += 1;
    }
    i = 0;
    while i < after.len() {
        out[n] = after[i];
        n += 1;
        i += 1;
    }
    assert!(n == N, "N is the length of the composed table");
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    /// Two blocks under `projectile_` and `plate_` share no name, each
    /// round-trips its values into the material it builds, and a block
    /// lists exactly the parameters its models use.
    #[test]
    fn prefixed_blocks_are_disjoint_and_round_trip() {
        let projectile = MaterialChoice::BILINEAR_LINEAR;
        let plate = MaterialChoice::JOHNSON_COOK_MIE_GRUNEISEN;
        let a = projectile.param_specs(Prefix::Projectile);
        let b = plate.param_specs(Prefix::Plate);
        for p in &a {
            assert!(p.name.starts_with("projectile_"), "{}", p.name);
            assert!(b.iter().all(|q| q.name != p.name), "{} in both", p.name);
        }
        assert!(b.iter().all(|q| q.name.starts_with("plate_")));
        // Distinct values for every parameter of both blocks: each one's
        // default times a factor of its own.
        let mut values = BTreeMap::new();
        for (k, p) in a.iter().chain(&b).enumerate() {
            let v = if p.range.contains(p.default * 1.001) {
                p.default * (1.0 + 1e-3 * (k as f64 + 1.0) / 64.0)
            } else {
                p.default
            };
            values.insert(p.name, v);
        }
        let get = |name: &str| {
            values
                .get(name)
                .copied()
                .ok_or_else(|| Error::Inconsistent(format!("asked for {name}")))
        };
        let m = projectile.material(Prefix::Projectile, get).unwrap();
        let n = plate.material(Prefix::Plate, get).unwrap();
        // Back to values by name, through the material.
        let back_a = [
            ("projectile_density", m.eos.reference_density().unwrap()),
            ("projectile_shear_modulus", m.shear_modulus),
            ("projectile_specific_heat", m.specific_heat),
            ("projectile_taylor_quinney", m.taylor_quinney),
            ("projectile_initial_temperature", m.reference_temperature),
        ];
        let Strength::Bilinear(bl) = m.strength else {
            panic!("{m:?}")
        };
        let Eos::Linear(lin) = m.eos else {
            panic!("{m:?}")
        };
        let Strength::JohnsonCook(jc) = n.strength else {
            panic!("{n:?}")
        };
        let Eos::MieGruneisen(mg) = n.eos else {
            panic!("{n:?}")
        };
        let back_b = [
            ("plate_density", mg.density),
            ("plate_shear_modulus", n.shear_modulus),
            ("plate_eos_c0", mg.c0),
            ("plate_eos_s", mg.s),
            ("plate_gruneisen", mg.gruneisen),
            ("plate_specific_heat", n.specific_heat),
            ("plate_taylor_quinney", n.taylor_quinney),
            ("plate_jc_a", jc.a),
            ("plate_jc_b", jc.b),
            ("plate_jc_n", jc.n),
            ("plate_jc_c", jc.c),
            ("plate_jc_m", jc.m),
            ("plate_melt_temperature", jc.melt_temperature),
            ("plate_room_temperature", jc.room_temperature),
            ("plate_initial_temperature", n.reference_temperature),
            ("plate_ref_strain_rate", jc.ref_strain_rate),
        ];
        let back_a: Vec<_> = back_a
            .into_iter()
            .chain([
                ("projectile_bulk_modulus", lin.bulk_modulus),
                ("projectile_yield_stress", bl.yield_stress),
                ("projectile_hardening_modulus", bl.hardening_modulus),
            ])
            .collect();
        assert_eq!(back_a.len(), a.len());
        assert_eq!(back_b.len(), b.len());
        for (name, v) in back_a.iter().chain(&back_b) {
            assert_eq!(values[name].to_bits(), v.to_bits(), "{name}");
        }
        // The values differ from block to block and from the defaults.
        assert_ne!(m.shear_modulus, n.shear_modulus);
        assert_ne!(m.shear_modulus, BLOCK[1].spec.default);
    }

    /// Each choice lists its own models' parameters and none of the other
    /// models'.
    #[test]
    fn a_choice_lists_only_what_its_models_use() {
        let names = |c: MaterialChoice| -> Vec<&str> {
            c.param_specs(Prefix::None).iter().map(|p| p.name).collect()
        };
        let jc = names(MaterialChoice::JOHNSON_COOK_LINEAR);
        assert!(jc.contains(&"jc_a") && jc.contains(&"bulk_modulus"));
        assert!(!jc.contains(&"yield_stress") && !jc.contains(&"eos_c0"));
        let bl = names(MaterialChoice::BILINEAR_MIE_GRUNEISEN);
        assert!(bl.contains(&"yield_stress") && bl.contains(&"hardening_modulus"));
        assert!(bl.contains(&"eos_c0") && bl.contains(&"eos_s") && bl.contains(&"gruneisen"));
        for gone in ["jc_a", "jc_n", "melt_temperature", "bulk_modulus"] {
            assert!(!bl.contains(&gone), "{gone}");
        }
        for c in MaterialChoice::ALL {
            assert_eq!(names(c).len(), block_len(c), "{c}");
        }
    }

    #[test]
    fn unknown_names_list_the_known_ones() {
        let e = StrengthKind::named("plastic").unwrap_err().to_string();
        assert!(
            e.contains("`plastic`") && e.contains("johnson_cook, bilinear"),
            "{e}"
        );
        let e = EosKind::named("gruneisen").unwrap_err().to_string();
        assert!(e.contains("linear, mie_gruneisen"), "{e}");
        assert_eq!(EosKind::named("mie_gruneisen"), Ok(EosKind::MieGruneisen));
    }
}
