//! Boundary conditions of the axisymmetric solver: the surfaces of the rod
//! (ordered lists of the particles that started on them, so that tangents
//! follow the deformed surface), the traction-free projection of the stress,
//! and the smooth rigid anvil.

/// Stress in cylindrical components (RR, ZZ, theta-theta, RZ).
pub type Stress = [f64; 4];

/// A surface of the rod: particles ordered along it, and the sign that turns
/// the tangent `x_next - x_prev` into the outward normal.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Surface {
    /// Particle indices in order along the surface.
    pub particles: Vec<usize>,
    /// +1 or -1: outward normal is `sign * (t_Z, -t_R)`.
    pub sign: f64,
}

impl Surface {
    /// Unit outward normal at the `k`-th particle of the surface, from the
    /// current positions (central differences along the surface, one-sided at
    /// its ends).
    pub fn normal(&self, k: usize, pos: &[[f64; 2]]) -> [f64; 2] {
        let a = self.particles[k.saturating_sub(1)];
        let b = self.particles[(k + 1).min(self.particles.len() - 1)];
        let (tr, tz) = (pos[b][0] - pos[a][0], pos[b][1] - pos[a][1]);
        let len = (tr * tr + tz * tz).sqrt();
        if len == 0.0 {
            return [0.0, 0.0];
        }
        [self.sign * tz / len, -self.sign * tr / len]
    }
}

/// Zeroes the normal and shear tractions on a surface of unit normal `n`:
/// rotate into (n, t) axes, set sigma_nn = sigma_nt = 0, rotate back. The hoop
/// stress is untouched.
#[inline]
pub fn traction_free(s: &Stress, n: [f64; 2]) -> Stress {
    let (tr, tz) = (-n[1], n[0]);
    let stt = tr * tr * s[0] + tz * tz * s[1] + 2.0 * tr * tz * s[3];
    [stt * tr * tr, stt * tz * tz, s[2], stt * tr * tz]
}

/// Zeroes the whole in-plane stress: a corner free on two surfaces.
#[inline]
pub fn corner_free(s: &Stress) -> Stress {
    [0.0, 0.0, s[2], 0.0]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn traction(s: &Stress, n: [f64; 2]) -> [f64; 2] {
        [s[0] * n[0] + s[3] * n[1], s[3] * n[0] + s[1] * n[1]]
    }

    #[test]
    fn traction_free_zeroes_traction_on_any_normal_and_keeps_tangential_stress() {
        let s = [3.0, -2.0, 1.5, 0.7];
        for ang in [0.0f64, 0.3, 1.0, 2.2, 4.0] {
            let n = [ang.cos(), ang.sin()];
            let out = traction_free(&s, n);
            let t = traction(&out, n);
            assert!(t[0].abs() < 1e-12 && t[1].abs() < 1e-12, "{ang}: {t:?}");
            let tv = [-n[1], n[0]];
            let stt = |x: &Stress| {
                tv[0] * tv[0] * x[0] + tv[1] * tv[1] * x[1] + 2.0 * tv[0] * tv[1] * x[3]
            };
            assert!((stt(&out) - stt(&s)).abs() < 1e-12);
            assert_eq!(out[2], s[2]);
        }
    }

    #[test]
    fn normals_of_a_straight_mantle_and_top() {
        let pos = vec![[1.0, 0.0], [1.0, 1.0], [1.0, 2.0], [0.0, 2.0], [0.5, 2.0]];
        let mantle = Surface {
            particles: vec![0, 1, 2],
            sign: 1.0,
        };
        assert_eq!(mantle.normal(1, &pos), [1.0, 0.0]);
        assert_eq!(mantle.normal(0, &pos), [1.0, 0.0]);
        let top = Surface {
            particles: vec![3, 4, 2],
            sign: -1.0,
        };
        let n = top.normal(1, &pos);
        assert!(n[0].abs() < 1e-15 && (n[1] - 1.0).abs() < 1e-15);
    }
}
