//! Symmetric second-order tensors in the two forms the solvers use, and the
//! J2 radial return written once over both.
//!
//! - [`Axisymmetric`]: 4 components (RR, ZZ, theta-theta, RZ), the form of
//!   the axisymmetric Taylor solver; the spin is the one in-plane component
//!   `W_RZ`.
//! - [`Full`]: 6 components (XX, YY, ZZ, XY, YZ, ZX), the form of a 3-D
//!   solver; the spin is `(W_XY, W_YZ, W_ZX)`.
//!
//! In both forms the first three components are the diagonal and the rest
//! the off-diagonal (shear) ones, each standing for two entries of the
//! matrix. The spin is `W_ij = (dv_i/dx_j - dv_j/dx_i) / 2`.

/// A symmetric tensor stored as its independent components: the three
/// diagonal ones first, then the shear ones.
pub trait SymTensor: Copy + PartialEq + std::fmt::Debug + AsRef<[f64]> + AsMut<[f64]> {
    /// The antisymmetric spin tensor of the form.
    type Spin: Copy;

    /// `A : B`, the double contraction (each shear component counts twice),
    /// summed left to right (so that the axisymmetric form gives the bits it
    /// always gave).
    #[inline]
    fn double_dot(&self, other: &Self) -> f64 {
        let (a, b) = (self.as_ref(), other.as_ref());
        let mut sum = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        for c in 3..a.len() {
            sum += 2.0 * a[c] * b[c];
        }
        sum
    }

    /// Every component times `f`.
    #[inline]
    fn scaled(&self, f: f64) -> Self {
        let mut s = *self;
        for x in s.as_mut() {
            *x *= f;
        }
        s
    }

    /// The Jaumann-rate trial deviator of a hypoelastic step:
    /// `S + dt (W S - S W + 2 mu (D - tr(D) / 3 I))` for the deviator `S`
    /// (self), the rate of deformation `D`, the spin `W`, the shear modulus
    /// `mu` and the time step `dt`.
    fn jaumann_trial(&self, rate: &Self, spin: &Self::Spin, shear_modulus: f64, dt: f64) -> Self;

    /// The von Mises equivalent `sqrt(3/2 S : S)` of a deviator.
    #[inline]
    fn von_mises(&self) -> f64 {
        (1.5 * self.double_dot(self)).sqrt()
    }

    /// The norm `sqrt(A : A)`.
    #[inline]
    fn norm(&self) -> f64 {
        self.double_dot(self).sqrt()
    }

    /// The tensor in 3-D components. The axisymmetric form is the 3-D one
    /// with (R, Z, theta) as (X, Y, Z), whose shears YZ and ZX are zero by
    /// symmetry.
    fn to_full(&self) -> Full;

    /// The tensor from 3-D components: the inverse of [`Self::to_full`] on
    /// the tensors the form can hold (the axisymmetric form drops YZ and
    /// ZX).
    fn from_full(f: &Full) -> Self;

    /// The spin in 3-D components `(W_XY, W_YZ, W_ZX)`.
    fn spin_to_full(w: &Self::Spin) -> [f64; 3];
}

/// Axisymmetric components (RR, ZZ, theta-theta, RZ).
pub type Axisymmetric = [f64; 4];

/// 3-D components (XX, YY, ZZ, XY, YZ, ZX).
pub type Full = [f64; 6];

impl SymTensor for Axisymmetric {
    /// `W_RZ`.
    type Spin = f64;

    #[inline]
    fn jaumann_trial(&self, d: &Self, omega: &f64, mu: f64, dt: f64) -> Self {
        let (s, omega) = (self, *omega);
        let dvol = (d[0] + d[1] + d[2]) / 3.0;
        [
            s[0] + dt * (2.0 * omega * s[3] + 2.0 * mu * (d[0] - dvol)),
            s[1] + dt * (-2.0 * omega * s[3] + 2.0 * mu * (d[1] - dvol)),
            s[2] + dt * (2.0 * mu * (d[2] - dvol)),
            s[3] + dt * (omega * (s[1] - s[0]) + 2.0 * mu * d[3]),
        ]
    }

    #[inline]
    fn to_full(&self) -> Full {
        [self[0], self[1], self[2], self[3], 0.0, 0.0]
    }

    #[inline]
    fn from_full(f: &Full) -> Self {
        [f[0], f[1], f[2], f[3]]
    }

    /// `W_RZ` is `W_XY`.
    #[inline]
    fn spin_to_full(w: &f64) -> [f64; 3] {
        [*w, 0.0, 0.0]
    }
}

/// The 3x3 matrix of 3-D components.
pub(crate) fn matrix(s: &Full) -> [[f64; 3]; 3] {
    [[s[0], s[3], s[5]], [s[3], s[1], s[4]], [s[5], s[4], s[2]]]
}

impl SymTensor for Full {
    /// `(W_XY, W_YZ, W_ZX)`.
    type Spin = [f64; 3];

    fn jaumann_trial(&self, d: &Self, w: &[f64; 3], mu: f64, dt: f64) -> Self {
        let s = matrix(self);
        let w = [[0.0, w[0], -w[2]], [-w[0], 0.0, w[1]], [w[2], -w[1], 0.0]];
        // W S - S W, symmetric for a symmetric S and an antisymmetric W.
        let rot = |i: usize, j: usize| -> f64 {
            (0..3).map(|k| w[i][k] * s[k][j] - s[i][k] * w[k][j]).sum()
        };
        let dvol = (d[0] + d[1] + d[2]) / 3.0;
        let pairs = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)];
        std::array::from_fn(|c| {
            let (i, j) = pairs[c];
            let dev = if c < 3 { d[c] - dvol } else { d[c] };
            self[c] + dt * (rot(i, j) + 2.0 * mu * dev)
        })
    }

    #[inline]
    fn to_full(&self) -> Full {
        *self
    }

    #[inline]
    fn from_full(f: &Full) -> Self {
        *f
    }

    #[inline]
    fn spin_to_full(w: &[f64; 3]) -> [f64; 3] {
        *w
    }
}

/// Result of a radial return.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Return<T> {
    /// Deviatoric stress after the return.
    pub stress: T,
    /// Effective plastic strain increment.
    pub plastic_strain: f64,
    /// Plastic work per unit volume over the increment,
    /// `(sigma_y + sigma_y') / 2 * d eps_p` (exact for linear hardening).
    pub plastic_work: f64,
}

/// The J2 radial return (Batra & Zhang 2008, eqs. (3.11)-(3.21)) with linear
/// isotropic hardening of modulus `hardening` (Pa): a trial deviator of von
/// Mises stress `s*` above the yield stress `sigma_y` yields by
/// `d eps_p = (s* - sigma_y) / (3 mu + H)`, written `(1 - f) s* / (3 mu + H)`
/// with `f = sigma_y / s*`, and is scaled onto the new yield surface
/// `sigma_y + H d eps_p`. With `H` the slope of the flow stress this is the
/// exact return of a proportional step; with `H = 0` it is the return of the
/// paper, with the yield stress of the start of the step.
#[inline]
pub fn radial_return<T: SymTensor>(
    trial: &T,
    yield_stress: f64,
    shear_modulus: f64,
    hardening: f64,
) -> Return<T> {
    let s_eq = trial.von_mises();
    if s_eq <= yield_stress || s_eq == 0.0 {
        return Return {
            stress: *trial,
            plastic_strain: 0.0,
            plastic_work: 0.0,
        };
    }
    let deps = (1.0 - yield_stress / s_eq) * s_eq / (3.0 * shear_modulus + hardening);
    let new_yield = yield_stress + hardening * deps;
    Return {
        stress: trial.scaled(new_yield / s_eq),
        plastic_strain: deps,
        plastic_work: 0.5 * (yield_stress + new_yield) * deps,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radial_return_lands_on_the_yield_surface() {
        let mu = 82.9e9;
        let trial = [1.2e9, -0.7e9, -0.5e9, 0.4e9];
        let sy = 0.9e9;
        let r = radial_return(&trial, sy, mu, 0.0);
        assert!((r.stress.von_mises() - sy).abs() < 1e-6 * sy);
        // Direction preserved, deviator stays traceless.
        assert!((r.stress[0] / r.stress[3] - trial[0] / trial[3]).abs() < 1e-12);
        assert!((r.stress[0] + r.stress[1] + r.stress[2]).abs() < 1e-3);
        // eq. (3.21): d eps_p = (1 - f) S*/(3 mu), and the work is sigma_y d eps_p.
        let s_eq = trial.von_mises();
        let expected = (1.0 - sy / s_eq) * s_eq / (3.0 * mu);
        assert!((r.plastic_strain - expected).abs() < 1e-15);
        assert!((r.plastic_work - sy * expected).abs() < 1e-6);
        // Inside the surface nothing changes.
        let e = radial_return(&[1e8, -1e8, 0.0, 0.0], sy, mu, 0.0);
        assert_eq!(e.plastic_strain, 0.0);
        assert_eq!(e.stress, [1e8, -1e8, 0.0, 0.0]);
    }

    /// The 3-D form returns a general deviator (all six components) onto
    /// the yield surface along its own direction, and agrees bit for bit
    /// with the axisymmetric form on an axisymmetric state.
    #[test]
    fn full_form_returns_a_general_deviator() {
        let (mu, sy, hard) = (80e9, 0.5e9, 2e9);
        let trial: Full = [0.9e9, -0.2e9, -0.7e9, 0.3e9, -0.25e9, 0.15e9];
        let r = radial_return(&trial, sy, mu, hard);
        let s_eq = trial.von_mises();
        let deps = (s_eq - sy) / (3.0 * mu + hard);
        assert!((r.plastic_strain - deps).abs() < 1e-12 * deps);
        let new_yield = sy + hard * deps;
        assert!((r.stress.von_mises() - new_yield).abs() < 1e-9 * new_yield);
        for c in 0..6 {
            assert!(
                (r.stress[c] * s_eq / new_yield - trial[c]).abs() < 1e-6,
                "{c}"
            );
        }
        assert!((r.stress[0] + r.stress[1] + r.stress[2]).abs() < 1e-3);
        // S : S counts each shear component twice: von Mises of pure shear
        // tau is sqrt(3) tau.
        let tau = 1e8;
        let shear: Full = [0.0, 0.0, 0.0, 0.0, tau, 0.0];
        assert!((shear.von_mises() - 3f64.sqrt() * tau).abs() < 1e-6);

        let axi: Axisymmetric = [1.2e9, -0.7e9, -0.5e9, 0.4e9];
        let (a, b) = (
            radial_return(&axi, sy, mu, hard),
            radial_return(&axi.to_full(), sy, mu, hard),
        );
        assert_eq!(a.stress.to_full(), b.stress);
        assert_eq!(a.plastic_strain, b.plastic_strain);
        assert_eq!(a.plastic_work, b.plastic_work);
    }

    /// The 3-D Jaumann step agrees with the axisymmetric one on an
    /// axisymmetric state (spin W_RZ as W_XY), to rounding.
    #[test]
    fn full_jaumann_step_matches_the_axisymmetric_one() {
        let s: Axisymmetric = [2e8, -1.5e8, -0.5e8, 0.7e8];
        let d: Axisymmetric = [3e3, -5e3, 1e3, 2e3];
        let (omega, mu, dt) = (4e3, 40e9, 1e-8);
        let a = s.jaumann_trial(&d, &omega, mu, dt);
        let b =
            s.to_full()
                .jaumann_trial(&d.to_full(), &Axisymmetric::spin_to_full(&omega), mu, dt);
        for c in 0..4 {
            assert!(
                (a[c] - b[c]).abs() <= 1e-15 * s[c].abs().max(a[c].abs()),
                "{c}"
            );
        }
        assert_eq!([b[4], b[5]], [0.0, 0.0]);
    }

    /// A pure spin rotates the stress: about Z by an angle theta = w dt, the
    /// XY block turns as `R S R^T` to first order in theta, and the 3-D step
    /// keeps the Z components; over many small steps the rotation is exact
    /// to O(dt).
    #[test]
    fn full_jaumann_step_rotates_with_the_spin() {
        // Uniaxial stress along X, spun about Z by W_XY = -w (dv_x/dy = -w,
        // dv_y/dx = w: a counter-clockwise rotation at rate w).
        let sigma = 1e8;
        let w = 1e4;
        let steps = 10_000;
        let quarter = std::f64::consts::FRAC_PI_2;
        let dt = quarter / (w * steps as f64);
        let mut s: Full = [sigma, 0.0, 0.0, 0.0, 0.0, 0.0];
        for _ in 0..steps {
            s = s.jaumann_trial(&[0.0; 6], &[-w, 0.0, 0.0], 1e10, dt);
        }
        // A quarter turn carries the X stress onto Y, with the first-order
        // error of forward Euler (relative growth ~ theta^2 / (2 steps)).
        let tol = 1e-3 * sigma;
        assert!((s[1] - sigma).abs() < tol, "{s:?}");
        assert!(s[0].abs() < tol && s[3].abs() < tol, "{s:?}");
        assert_eq!([s[2], s[4], s[5]], [0.0; 3]);
        // The deviatoric part of D, and only it, loads the stress.
        let vol = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0];
        assert_eq!(
            [0.0; 6].jaumann_trial(&vol, &[0.0; 3], 1e10, 1e-6),
            [0.0; 6]
        );
        let shear = [0.0, 0.0, 0.0, 0.0, 0.0, 2.0];
        let t = [0.0; 6].jaumann_trial(&shear, &[0.0; 3], 1e10, 1e-6);
        assert_eq!(t, [0.0, 0.0, 0.0, 0.0, 0.0, 2.0 * 1e10 * 2.0 * 1e-6]);
    }
}
