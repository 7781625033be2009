//! Linear equation of state, eq. (3.17): `P = K (rho / rho0 - 1)`.

/// Linear (bulk-modulus) equation of state.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LinearEos {
    /// Bulk modulus K (Pa).
    pub bulk_modulus: f64,
    /// Reference density rho0 (kg/m3).
    pub density: f64,
}

impl LinearEos {
    /// Pressure at density `rho`, positive in compression.
    #[inline]
    pub fn pressure(&self, rho: f64) -> f64 {
        self.bulk_modulus * (rho / self.density - 1.0)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn compression_gives_positive_pressure() {
        let e = super::LinearEos {
            bulk_modulus: 2.0,
            density: 4.0,
        };
        assert_eq!(e.pressure(4.0), 0.0);
        assert_eq!(e.pressure(5.0), 0.5);
        assert_eq!(e.pressure(3.0), -0.5);
    }
}
