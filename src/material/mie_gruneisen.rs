//! Mie-Grüneisen equation of state with a linear shock-velocity reference
//! curve (`U_s = c0 + s u_p`), in the form of the LS-DYNA Keyword User's
//! Manual, `*EOS_GRUNEISEN` (with `S2 = S3 = a = 0`), and of the LS-DYNA
//! Theory Manual, "Equation of State Models", Gruneisen:
//!
//! - `mu = rho / rho0 - 1`;
//! - compression (`mu > 0`):
//!   `P = rho0 c0^2 mu [1 + (1 - Gamma/2) mu] / [1 - (s - 1) mu]^2 + Gamma rho0 e`;
//! - expansion (`mu <= 0`): `P = rho0 c0^2 mu + Gamma rho0 e`;
//!
//! with `e` the specific internal energy (J/kg) measured from the reference
//! state (`rho0 e` is LS-DYNA's energy per unit reference volume `E`). The
//! compression branch is the Hugoniot `P_H = rho0 c0^2 mu (1 + mu) / [1 -
//! (s - 1) mu]^2` with the Hugoniot energy removed at `Gamma rho =
//! Gamma rho0`: `P = P_H [1 - Gamma mu / (2 (1 + mu))] + Gamma rho0 e`.
//!
//! The ceramic of the MLPG seed (Han et al., Rajendran-Grove model, eq. 16)
//! has the same structure, a reference curve times a Grüneisen correction
//! plus `Gamma rho0 (I - I0)`, the energy from the initial state as here;
//! its AD85 has `Gamma = 0`, where only the reference curve counts (a cubic
//! polynomial in `mu` there, a curve of its own).
//!
//! `rho0 c0^2 mu` is computed as [`super::eos::LinearEos::pressure`]
//! computes `K (rho / rho0 - 1)`, with `K = rho0 c0^2` from
//! [`MieGruneisen::bulk_modulus`]: in expansion with `Gamma = 0` the two give
//! the same bits, and the compression factor multiplies that same product.
//! Unlike what the issue expected, `s = 0` does not make the compression
//! branch linear: the factor is then `1 / (1 + mu)` (a constant shock speed
//! gives `P = rho0 c0^2 (1 - rho0 / rho)`); it is exactly 1 at `s = 1`,
//! `Gamma = 2`.
//!
//! The branch is singular where `1 - (s - 1) mu` reaches zero, at `mu =
//! 1 / (s - 1)` for `s > 1`: there [`MieGruneisen::pressure`] returns
//! [`CompressionLimit`], never an infinite or NaN pressure.

use crate::error::{Error, Result};
use crate::params::Range;

/// Mie-Grüneisen equation of state (`U_s`-`u_p` reference curve).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MieGruneisen {
    /// Reference density rho0 (kg/m3).
    pub density: f64,
    /// Bulk sound speed c0 (m/s), `eos_c0`.
    pub c0: f64,
    /// Slope s of the shock velocity against the particle velocity (1),
    /// `eos_s`.
    pub s: f64,
    /// Grüneisen coefficient Gamma (1), `gruneisen`.
    pub gruneisen: f64,
}

/// A compression at or past the singular point of the Mie-Grüneisen
/// reference curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompressionLimit {
    /// The compression `mu = rho / rho0 - 1` reached.
    pub compression: f64,
    /// The singular compression `1 / (s - 1)`.
    pub limit: f64,
}

/// Refuses a parameter outside its range with the parameter's name.
pub(crate) fn check(name: &str, value: f64, range: Range) -> Result<()> {
    if range.contains(value) {
        Ok(())
    } else {
        Err(Error::OutOfRange {
            name: name.to_string(),
            value,
            range: range.to_string(),
        })
    }
}

impl MieGruneisen {
    /// Refuses parameters out of physical range: `density` and `eos_c0`
    /// must be positive and finite, `eos_s` in `[0, 10]` and `gruneisen` in
    /// `[0, 10]`.
    pub fn validate(&self) -> Result<()> {
        let positive = Range::open_closed(0.0, f64::MAX);
        check("density", self.density, positive)?;
        check("eos_c0", self.c0, positive)?;
        check("eos_s", self.s, Range::closed(0.0, 10.0))?;
        check("gruneisen", self.gruneisen, Range::closed(0.0, 10.0))?;
        check("bulk modulus rho0 c0^2", self.bulk_modulus(), positive)
    }

    /// The bulk modulus at the reference state, `rho0 c0^2`.
    #[inline]
    pub fn bulk_modulus(&self) -> f64 {
        self.density * self.c0 * self.c0
    }

    /// Pressure (positive in compression) at density `rho` and specific
    /// internal energy `e` (J/kg, from the reference state).
    #[inline]
    pub fn pressure(&self, rho: f64, e: f64) -> std::result::Result<f64, CompressionLimit> {
        let mu = rho / self.density - 1.0;
        let linear = self.bulk_modulus() * mu;
        let thermal = self.gruneisen * self.density * e;
        if mu <= 0.0 {
            return Ok(linear + thermal);
        }
        let den = 1.0 - (self.s - 1.0) * mu;
        if den <= 0.0 {
            return Err(CompressionLimit {
                compression: mu,
                limit: 1.0 / (self.s - 1.0),
            });
        }
        let factor = (1.0 + (1.0 - 0.5 * self.gruneisen) * mu) / (den * den);
        Ok(linear * factor + thermal)
    }

    /// The bulk modulus that sets the sound speed,
    /// `rho c^2 = rho dP/drho|_e + (P / rho) dP/de|_rho`, at density `rho`
    /// and pressure `p` (never negative).
    pub fn tangent_bulk_modulus(&self, rho: f64, p: f64) -> f64 {
        let mu = rho / self.density - 1.0;
        let k = self.bulk_modulus();
        let dp_dmu = if mu <= 0.0 {
            k
        } else {
            // d/dmu of k mu (1 + b mu) / den^2, den = 1 - c mu.
            let (b, c) = (1.0 - 0.5 * self.gruneisen, self.s - 1.0);
            let den = 1.0 - c * mu;
            k * ((1.0 + 2.0 * b * mu) * den + 2.0 * c * mu * (1.0 + b * mu)) / (den * den * den)
        };
        ((1.0 + mu) * dp_dmu + self.gruneisen * self.density * p / rho).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::eos::LinearEos;

    fn copper() -> MieGruneisen {
        // LS-DYNA's copper (Steinberg): c0 3940 m/s, S1 1.489, gamma0 2.02.
        MieGruneisen {
            density: 8930.0,
            c0: 3940.0,
            s: 1.489,
            gruneisen: 2.02,
        }
    }

    /// Densities from 0.5 to 1.5 rho0, the reference density among them.
    fn densities(rho0: f64) -> impl Iterator<Item = f64> {
        (0..=10_000).map(move |k| rho0 * (0.5 + k as f64 * 1e-4))
    }

    /// In expansion with Gamma = 0 the equation of state is the linear one
    /// of `K = rho0 c0^2`, bit for bit, whatever s and the energy; in
    /// compression the factor is exactly 1 at s = 1, Gamma = 2 with no
    /// energy, and the two agree bit for bit there too.
    #[test]
    fn linear_limits_bit_for_bit() {
        for s in [0.0, 1.0, 1.489] {
            let mg = MieGruneisen {
                gruneisen: 0.0,
                s,
                ..copper()
            };
            let lin = LinearEos {
                bulk_modulus: mg.bulk_modulus(),
                density: mg.density,
            };
            for rho in densities(mg.density).filter(|&r| r <= mg.density) {
                let p = mg.pressure(rho, 1234.5).unwrap();
                assert_eq!(p.to_bits(), lin.pressure(rho).to_bits(), "s {s}, rho {rho}");
            }
        }
        let mg = MieGruneisen {
            s: 1.0,
            gruneisen: 2.0,
            ..copper()
        };
        let lin = LinearEos {
            bulk_modulus: mg.bulk_modulus(),
            density: mg.density,
        };
        for rho in densities(mg.density) {
            let p = mg.pressure(rho, 0.0).unwrap();
            assert_eq!(p.to_bits(), lin.pressure(rho).to_bits(), "rho {rho}");
        }
    }

    /// With Gamma = 0 the compression branch is the shock Hugoniot: the
    /// pressure `rho0 U_s u_p` of the shock with `U_s = c0 + s u_p` that
    /// carries the material to that density (`u_p / U_s = 1 - rho0 / rho`).
    #[test]
    fn compression_follows_the_hugoniot() {
        let mg = MieGruneisen {
            gruneisen: 0.0,
            ..copper()
        };
        for rho in [8930.0 * 1.01, 8930.0 * 1.1, 8930.0 * 1.3] {
            let eta = 1.0 - mg.density / rho;
            // U_s = c0 + s u_p and u_p = eta U_s give U_s = c0 / (1 - s eta).
            let us = mg.c0 / (1.0 - mg.s * eta);
            let hugoniot = mg.density * us * (eta * us);
            let p = mg.pressure(rho, 0.0).unwrap();
            assert!((p - hugoniot).abs() < 1e-12 * hugoniot, "{p} {hugoniot}");
        }
        // The energy term: Gamma rho0 e on top, in both branches.
        let mg = copper();
        let e = 5e4;
        for rho in [0.9 * mg.density, 1.2 * mg.density] {
            let cold = mg.pressure(rho, 0.0).unwrap();
            let hot = mg.pressure(rho, e).unwrap();
            assert!((hot - cold - mg.gruneisen * mg.density * e).abs() < 1e-6 * hot.abs());
        }
    }

    /// The tangent modulus is the slope of the pressure: at constant energy
    /// (Gamma = 0) a central difference of the pressure matches it.
    #[test]
    fn tangent_modulus_is_the_slope() {
        let mg = MieGruneisen {
            gruneisen: 0.0,
            ..copper()
        };
        assert_eq!(mg.tangent_bulk_modulus(mg.density, 0.0), mg.bulk_modulus());
        for rho in [0.95 * mg.density, 1.05 * mg.density, 1.3 * mg.density] {
            let d = 1e-6 * rho;
            let slope = (mg.pressure(rho + d, 0.0).unwrap() - mg.pressure(rho - d, 0.0).unwrap())
                / (2.0 * d);
            let k = mg.tangent_bulk_modulus(rho, mg.pressure(rho, 0.0).unwrap());
            assert!((rho * slope - k).abs() < 1e-6 * k, "{} {k}", rho * slope);
        }
    }

    /// Past the singular compression the pressure is refused, named, with
    /// the limit; out-of-range parameters are refused by name.
    #[test]
    fn singular_compression_and_bad_parameters_are_refused() {
        let mg = MieGruneisen { s: 3.0, ..copper() };
        // Singular at mu = 1 / (s - 1) = 0.5.
        assert!(mg.pressure(1.49 * mg.density, 0.0).unwrap().is_finite());
        let err = mg.pressure(1.5 * mg.density, 0.0).unwrap_err();
        assert_eq!(err.limit, 0.5);
        assert_eq!(err.compression, 0.5);
        assert!(mg.pressure(3.0 * mg.density, 0.0).is_err());
        assert!(copper().validate().is_ok());
        for (bad, name) in [
            (
                MieGruneisen {
                    c0: 0.0,
                    ..copper()
                },
                "eos_c0",
            ),
            (
                MieGruneisen {
                    c0: f64::NAN,
                    ..copper()
                },
                "eos_c0",
            ),
            (
                MieGruneisen {
                    s: -1.0,
                    ..copper()
                },
                "eos_s",
            ),
            (
                MieGruneisen {
                    gruneisen: -0.5,
                    ..copper()
                },
                "gruneisen",
            ),
            (
                MieGruneisen {
                    density: 0.0,
                    ..copper()
                },
                "density",
            ),
        ] {
            match bad.validate() {
                Err(Error::OutOfRange { name: n, .. }) => assert_eq!(n, name),
                other => panic!("{name}: {other:?}"),
            }
        }
    }
}
