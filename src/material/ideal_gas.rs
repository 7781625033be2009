//! Ideal gas, eq. (4.4): `P = (gamma - 1) rho e`.

/// Ideal-gas equation of state.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct IdealGas {
    /// Ratio of specific heats.
    pub gamma: f64,
}

impl IdealGas {
    /// Pressure from density and specific internal energy.
    #[inline]
    pub fn pressure(&self, rho: f64, e: f64) -> f64 {
        (self.gamma - 1.0) * rho * e
    }

    /// Adiabatic sound speed `sqrt(gamma P / rho)` (zero for a cold gas).
    #[inline]
    pub fn sound_speed(&self, rho: f64, p: f64) -> f64 {
        (self.gamma * p.max(0.0) / rho).sqrt()
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn noh_post_shock_state() {
        let g = super::IdealGas { gamma: 5.0 / 3.0 };
        // Behind the Noh shock: rho 16, e 0.5, P 16/3.
        assert!((g.pressure(16.0, 0.5) - 16.0 / 3.0).abs() < 1e-12);
        assert!((g.sound_speed(16.0, 16.0 / 3.0) - (5.0f64 / 9.0).sqrt()).abs() < 1e-12);
    }
}
