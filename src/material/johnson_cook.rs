//! Johnson-Cook thermo-viscoplasticity, eq. (3.7); its radial return, eqs.
//! (3.11)-(3.21), is [`super::tensor::radial_return`].
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
}
