//! Bilinear J2 plasticity with isotropic hardening, as LS-DYNA's
//! plastic-kinematic model (`*MAT_PLASTIC_KINEMATIC` with `BETA = 1`)
//! without its rate term: the flow stress grows linearly with the effective
//! plastic strain, `sigma_y = yield_stress + hardening_modulus * eps_p`, with
//! no effect of strain rate or temperature.
//!
//! `hardening_modulus` is the plastic modulus `H`, the slope of the flow
//! stress against the *plastic* strain. LS-DYNA's input is the tangent
//! modulus `E_t`, the slope of the uniaxial stress-strain curve against the
//! *total* strain; for Young's modulus `E` the two are related by
//! `H = E E_t / (E - E_t)` ([`Bilinear::from_tangent_modulus`]).
//!
//! With linear hardening the radial return of a proportional step is exact
//! in one step ([`super::tensor::radial_return`] with `hardening =
//! hardening_modulus`): `d eps_p = (sigma* - sigma_y) / (3 G + H)`.

/// Bilinear isotropic-hardening flow stress.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Bilinear {
    /// Initial yield stress (Pa).
    pub yield_stress: f64,
    /// Plastic hardening modulus `H` (Pa): the slope of the flow stress
    /// against the effective plastic strain.
    pub hardening_modulus: f64,
}

impl Bilinear {
    /// Flow stress `yield_stress + hardening_modulus * eps_p`.
    #[inline]
    pub fn flow_stress(&self, eps_p: f64) -> f64 {
        self.yield_stress + self.hardening_modulus * eps_p
    }

    /// The model from a tangent modulus `E_t` of the uniaxial curve and
    /// Young's modulus `E`: `H = E E_t / (E - E_t)` (a plastic strain
    /// increment `d eps_p` adds `d sigma / E_t - d sigma / E` to the strain,
    /// so `H = d sigma / d eps_p = 1 / (1 / E_t - 1 / E)`).
    pub fn from_tangent_modulus(yield_stress: f64, youngs_modulus: f64, tangent: f64) -> Self {
        Bilinear {
            yield_stress,
            hardening_modulus: youngs_modulus * tangent / (youngs_modulus - tangent),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::tensor::{Axisymmetric, Full, SymTensor, radial_return};

    /// A uniaxial test in the plastic range: the total strain grows by
    /// d eps, of which d sigma / E is elastic and d sigma / H plastic, so
    /// that the tangent is E_t again.
    #[test]
    fn tangent_modulus_conversion() {
        let (e, et) = (200e9, 2e9);
        let b = Bilinear::from_tangent_modulus(300e6, e, et);
        let d_sigma = 1e6;
        let d_eps = d_sigma / e + d_sigma / b.hardening_modulus;
        assert!((d_sigma / d_eps - et).abs() < 1e-6 * et);
        assert_eq!(b.flow_stress(0.0), 300e6);
    }

    /// Pure shear in the 3-D form: a trial shear stress tau* (von Mises
    /// sqrt(3) tau*) above the yield stress returns in one step to the
    /// hardened surface, `eps_p = (sigma* - sigma_y0) / (3 G + H)` and
    /// `sigma_eq = sigma_y0 + H eps_p`, exactly as the analytic return of
    /// linear hardening gives; a second load step continues from there.
    #[test]
    fn pure_shear_return_is_exact() {
        let (g, b) = (
            80e9,
            Bilinear {
                yield_stress: 400e6,
                hardening_modulus: 1e9,
            },
        );
        let h = b.hardening_modulus;
        // Engineering shear strain increment gamma: trial tau = G gamma.
        let gamma = 0.02;
        let tau = g * gamma;
        let trial: Full = [0.0, 0.0, 0.0, tau, 0.0, 0.0];
        let s_trial = 3f64.sqrt() * tau;
        let r = radial_return(&trial, b.flow_stress(0.0), g, h);
        let eps_p = (s_trial - b.yield_stress) / (3.0 * g + h);
        assert!((r.plastic_strain - eps_p).abs() < 1e-14, "{r:?}");
        assert!((r.stress.von_mises() - b.flow_stress(eps_p)).abs() < 1e-6);
        // The shear stress carries it all; no normal stress appears.
        assert_eq!(&r.stress[..3], &[0.0; 3]);
        // Plastic work: the area under the flow stress over the increment.
        let work = b.yield_stress * eps_p + 0.5 * h * eps_p * eps_p;
        assert!((r.plastic_work - work).abs() < 1e-9 * work);
        // A second increment from the returned state.
        let trial2: Full = [0.0, 0.0, 0.0, r.stress[3] + tau, 0.0, 0.0];
        let r2 = radial_return(&trial2, b.flow_stress(eps_p), g, h);
        let eps_p2 = (trial2.von_mises() - b.flow_stress(eps_p)) / (3.0 * g + h);
        assert!((r2.plastic_strain - eps_p2).abs() < 1e-14);
        assert!((r2.stress.von_mises() - b.flow_stress(eps_p + eps_p2)).abs() < 1e-6);
    }

    /// Uniaxial strain in the axisymmetric form (compression along Z, no
    /// lateral strain): the deviator of a strain increment d eps along Z is
    /// (-1, 2, -1) d eps / 3, so the trial von Mises stress is 2 G |d eps|
    /// and the exact return gives `eps_p = (2 G |d eps| - sigma_y0) / (3 G + H)`.
    #[test]
    fn uniaxial_strain_return_is_exact() {
        let (g, b) = (
            43.3e9,
            Bilinear {
                yield_stress: 400e6,
                hardening_modulus: 100e6,
            },
        );
        let d_eps = -0.01;
        let rate: Axisymmetric = [0.0, d_eps, 0.0, 0.0];
        let trial = [0.0; 4].jaumann_trial(&rate, &0.0, g, 1.0);
        let s_trial = 2.0 * g * d_eps.abs();
        assert!((trial.von_mises() - s_trial).abs() < 1e-6 * s_trial);
        let r = radial_return(&trial, b.yield_stress, g, b.hardening_modulus);
        let eps_p = (s_trial - b.yield_stress) / (3.0 * g + b.hardening_modulus);
        assert!((r.plastic_strain - eps_p).abs() < 1e-12 * eps_p);
        let sy = b.flow_stress(eps_p);
        assert!((r.stress.von_mises() - sy).abs() < 1e-9 * sy);
        // The axial deviator is -2/3 of the equivalent stress (compression).
        assert!((r.stress[1] + 2.0 / 3.0 * sy).abs() < 1e-9 * sy);
    }
}
