//! The particle fields that every solid run offers alike, from its node
//! arrays: one `field()` for the axisymmetric and the 3-D solvers.

/// The node arrays of a solid run in `D` dimensions that its fields read.
pub(crate) struct SolidNodes<'a, const D: usize> {
    /// Positions (m).
    pub pos: &'a [[f64; D]],
    /// Velocities (m/s).
    pub vel: &'a [[f64; D]],
    /// Densities (kg/m³).
    pub rho: &'a [f64],
    /// Pressures (Pa).
    pub pressure: &'a [f64],
    /// Equivalent plastic strains.
    pub eps_p: &'a [f64],
    /// Temperatures (K).
    pub temp: &'a [f64],
    /// Whether each node is on the anvil.
    pub contact: &'a [bool],
}

impl<const D: usize> SolidNodes<'_, D> {
    /// The values of the field `name` (of `crate::observe::rod_fields`),
    /// interleaved per node, with the stress from `stress` (its components
    /// are the solver's); `None` for another name.
    pub fn field(&self, name: &str, stress: impl FnOnce() -> Vec<f64>) -> Option<Vec<f64>> {
        Some(match name {
            "position" => self.pos.iter().flatten().copied().collect(),
            "density" => self.rho.to_vec(),
            "velocity" => self.vel.iter().flatten().copied().collect(),
            "pressure" => self.pressure.to_vec(),
            "stress" => stress(),
            "plastic_strain" => self.eps_p.to_vec(),
            "temperature" => self.temp.to_vec(),
            "in_contact" => self.contact.iter().map(|&c| c as u8 as f64).collect(),
            _ => return None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each field is its array, interleaved, and the contact flags are 0 or
    /// 1; an unknown name is none.
    #[test]
    fn fields_are_the_arrays_interleaved() {
        let nodes = SolidNodes::<2> {
            pos: &[[1.0, 2.0], [3.0, 4.0]],
            vel: &[[5.0, 6.0], [7.0, 8.0]],
            rho: &[9.0, 10.0],
            pressure: &[11.0, 12.0],
            eps_p: &[0.0, 0.5],
            temp: &[300.0, 301.0],
            contact: &[true, false],
        };
        let f = |name| nodes.field(name, || vec![-1.0]);
        assert_eq!(f("position"), Some(vec![1.0, 2.0, 3.0, 4.0]));
        assert_eq!(f("velocity"), Some(vec![5.0, 6.0, 7.0, 8.0]));
        assert_eq!(f("density"), Some(vec![9.0, 10.0]));
        assert_eq!(f("pressure"), Some(vec![11.0, 12.0]));
        assert_eq!(f("stress"), Some(vec![-1.0]));
        assert_eq!(f("plastic_strain"), Some(vec![0.0, 0.5]));
        assert_eq!(f("temperature"), Some(vec![300.0, 301.0]));
        assert_eq!(f("in_contact"), Some(vec![1.0, 0.0]));
        assert_eq!(f("damage"), None);
    }
}
