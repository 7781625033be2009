//! Johnson-Cook thermo-viscoplasticity, eq. (3.7), with the radial return of
//! eqs. (3.11)-(3.21).
//!
//! Conventions (the usual ones of Johnson-Cook users, and documented in the
//! README): the rate term uses `max(eps_dot / eps_dot0, 1)`, so strain rates
//! below the reference rate give no softening; the homologous temperature
//! `T*` is clamped to `[0, 1]`, so the strength is zero at and above the melt
//! temperature and never exceeds its room-temperature value below room
//! temperature.

/// Johnson-Cook flow-stress model.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct JohnsonCook {
    /// a (Pa)
    pub a: f64,
    /// b (Pa)
    pub b: f64,
    /// n
    pub n: f64,
    /// c
    pub c: f64,
    /// m
    pub m: f64,
    /// Melt temperature (K).
    pub melt_temperature: f64,
    /// Room temperature (K).
    pub room_temperature: f64,
    /// Reference strain rate (1/s).
    pub ref_strain_rate: f64,
}

impl JohnsonCook {
    /// Flow stress for effective plastic strain `eps_p`, effective strain
    /// rate `rate` and temperature `temp`: the product of
    /// [`JohnsonCook::hardening`], [`JohnsonCook::rate_factor`] and
    /// [`JohnsonCook::thermal`]. Never negative, never NaN for finite
    /// non-negative inputs.
    #[inline]
    pub fn flow_stress(&self, eps_p: f64, rate: f64, temp: f64) -> f64 {
        self.strength(self.hardening(eps_p), rate, self.thermal(temp))
    }

    /// The flow stress from the hardening and thermal factors (which a
    /// caller may keep from step to step while `eps_p` and `temp` stay put).
    #[inline]
    pub fn strength(&self, hardening: f64, rate: f64, thermal: f64) -> f64 {
        (hardening * self.rate_factor(rate) * thermal).max(0.0)
    }

    /// Strain hardening `A + B eps_p^n`.
    #[inline]
    pub fn hardening(&self, eps_p: f64) -> f64 {
        if eps_p > 0.0 {
            self.a + self.b * eps_p.powf(self.n)
        } else {
            self.a
        }
    }

    /// Rate factor `1 + C ln(max(rate / rate_0, 1))`.
    #[inline]
    pub fn rate_factor(&self, rate: f64) -> f64 {
        let ratio = (rate / self.ref_strain_rate).max(1.0);
        if ratio == 1.0 {
            // ln 1 = 0 exactly: spare the logarithm.
            1.0
        } else {
            1.0 + self.c * ratio.ln()
        }
    }

    /// Thermal softening `1 - T*^m`, with `T*` clamped to `[0, 1]`.
    #[inline]
    pub fn thermal(&self, temp: f64) -> f64 {
        let t_star = ((temp - self.room_temperature)
            / (self.melt_temperature - self.room_temperature))
            .clamp(0.0, 1.0);
        if t_star > 0.0 {
            1.0 - t_star.powf(self.m)
        } else {
            1.0
        }
    }
}

/// Deviatoric stress in cylindrical components (RR, ZZ, theta-theta, RZ).
pub type Deviator = [f64; 4];

/// `sqrt(3/2 S:S)` for a deviator stored as (RR, ZZ, TT, RZ).
#[inline]
pub fn von_mises(s: &Deviator) -> f64 {
    (1.5 * (s[0] * s[0] + s[1] * s[1] + s[2] * s[2] + 2.0 * s[3] * s[3])).sqrt()
}

/// Result of a radial return.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Return {
    /// Deviatoric stress after the return.
    pub stress: Deviator,
    /// Effective plastic strain increment, eq. (3.21).
    pub plastic_strain: f64,
    /// Plastic work per unit volume, `S : d eps_p = sigma_y d eps_p`.
    pub plastic_work: f64,
}

/// Scales the trial deviator back to the yield surface, eqs. (3.12)-(3.21).
#[inline]
pub fn radial_return(trial: &Deviator, yield_stress: f64, shear_modulus: f64) -> Return {
    let s_eq = von_mises(trial);
    if s_eq <= yield_stress || s_eq == 0.0 {
        return Return {
            stress: *trial,
            plastic_strain: 0.0,
            plastic_work: 0.0,
        };
    }
    let f = yield_stress / s_eq;
    let deps = (1.0 - f) * s_eq / (3.0 * shear_modulus);
    Return {
        stress: trial.map(|x| f * x),
        plastic_strain: deps,
        plastic_work: yield_stress * deps,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steel() -> JohnsonCook {
        JohnsonCook {
            a: 792e6,
            b: 510e6,
            n: 0.26,
            c: 0.014,
            m: 1.03,
            melt_temperature: 1293.0,
            room_temperature: 293.0,
            ref_strain_rate: 1.0,
        }
    }

    #[test]
    fn flow_stress_limits() {
        let jc = steel();
        assert_eq!(jc.flow_stress(0.0, 1.0, 293.0), 792e6);
        // Below the reference rate and below room temperature: no change.
        assert_eq!(jc.flow_stress(0.0, 1e-3, 200.0), 792e6);
        // Hand-computed point: eps 0.5, rate 1e4, T 500 K.
        let t_star: f64 = 207.0 / 1000.0;
        let expected = (792e6 + 510e6 * 0.5f64.powf(0.26))
            * (1.0 + 0.014 * 1e4f64.ln())
            * (1.0 - t_star.powf(1.03));
        assert!((jc.flow_stress(0.5, 1e4, 500.0) - expected).abs() < 1e-6 * expected);
        // At and above melt: zero strength, no NaN.
        assert_eq!(jc.flow_stress(0.3, 1e5, 1293.0), 0.0);
        assert_eq!(jc.flow_stress(0.3, 1e5, 5000.0), 0.0);
    }

    #[test]
    fn radial_return_lands_on_the_yield_surface() {
        let mu = 82.9e9;
        let trial = [1.2e9, -0.7e9, -0.5e9, 0.4e9];
        let sy = 0.9e9;
        let r = radial_return(&trial, sy, mu);
        assert!((von_mises(&r.stress) - sy).abs() < 1e-6 * sy);
        // Direction preserved, deviator stays traceless.
        assert!((r.stress[0] / r.stress[3] - trial[0] / trial[3]).abs() < 1e-12);
        assert!((r.stress[0] + r.stress[1] + r.stress[2]).abs() < 1e-3);
        // eq. (3.21): d eps_p = (1 - f) S*/(3 mu), and the work is sigma_y d eps_p.
        let s_eq = von_mises(&trial);
        let expected = (1.0 - sy / s_eq) * s_eq / (3.0 * mu);
        assert!((r.plastic_strain - expected).abs() < 1e-15);
        assert!((r.plastic_work - sy * expected).abs() < 1e-6);
        // Inside the surface nothing changes.
        let e = radial_return(&[1e8, -1e8, 0.0, 0.0], sy, mu);
        assert_eq!(e.plastic_strain, 0.0);
        assert_eq!(e.stress, [1e8, -1e8, 0.0, 0.0]);
    }
}
