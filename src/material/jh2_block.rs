//! The parameters of a JH-2 ceramic (the `jh_` block, the fields of
//! LS-DYNA's MAT_110 in SI units) and the model they make, for every scene
//! with a JH-2 plate (`plate_impact`'s level `jh2`, `penetration`'s
//! `plate_ceramic = jh2`).

use super::johnson_holmquist::{Failure, Jh2, JohnsonHolmquist};
use crate::error::{Error, Result};
use crate::params::{ParamSpec, Range};
use crate::scene::params::spec as row;

/// The example ceramic of JH94 ([`JohnsonHolmquist::example_ceramic`]),
/// the defaults of the `jh_` block.
const JH: JohnsonHolmquist = JohnsonHolmquist::example_ceramic();

/// The largest `jh_sfmax`, and its default: a cap no pressure reaches
/// (MAT_110's default is none).
pub const NO_SFMAX: f64 = 1.0e10;

/// The JH-2 ceramic of a plate of level `jh2`, under `jh_`: the constants
/// of [`JohnsonHolmquist`] (JH94; the fields of LS-DYNA's MAT_110), in SI
/// units. Defaults: the example ceramic of Johnson & Holmquist (1994), "An
/// improved computational constitutive model for brittle materials", AIP
/// Conf. Proc. 309, as commonly quoted ([`JohnsonHolmquist::example_ceramic`]).
pub const JH_BLOCK: [ParamSpec; 18] = [
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

/// The JH-2 model of the `jh_` block: each value checked against its row,
/// then the constants together ([`JohnsonHolmquist::validate`]: a HEL that
/// the compression reaches, a positive P_HEL), errors by the `jh_` names.
pub fn jh2_model(value: impl Fn(&str) -> Result<f64>) -> Result<Jh2> {
    let v = |name: &str| -> Result<f64> {
        let x = value(name)?;
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
