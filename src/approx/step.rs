//! The stable time step, eq. (15): the Newmark method with `γ ≥ 1/2` and
//! `β ≤ 1/2` is stable for `Δt ≤ 1 / (ω_max √(γ/2 − β))`, which for the
//! central differences of the seed (`β = 0`, `γ = 1/2`) is `2 / ω_max`.
//!
//! # The highest frequency
//!
//! `ω_max` is estimated as `κ c_p / d_min`: the longitudinal wave speed
//! `c_p = √((K + 4G/3)/ρ)` over the smallest node distance, times the
//! factor [`OMEGA_FACTOR`] of the discrete MLPG operator, measured by power
//! iteration ([`largest_eigenvalue`]) on the linear elastic operator of a
//! free bar on the ring lattice (`tests/suite/mlpg.rs`,
//! `highest_frequency_of_the_elastic_operator`): κ = 1.448 at 2 and 1.451
//! at 3 rings across the radius (α = 0.9, k = 10, factor 1.5); κ grows as
//! α shrinks (2.01 at α = 0.5), as the cut spheres of the boundary nodes
//! weigh their traction by `1/r0`. A plain
//! `c_p / d_min` (κ = 1) would overstep; `2 c_p / d_min`, the bound of a
//! second-order central-difference Laplacian on a cubic lattice (κ = 2√3
//! in 3-D), would waste steps. The estimate is cheap (one pass for
//! `d_min`) and is recomputed as the nodes move; the safety factor covers
//! the change of κ with deformation and material state.

/// `κ` in `ω_max = κ c_p / d_min`: the largest measured value (1.451) with
/// a margin of 4.8 %; see the module docs.
pub const OMEGA_FACTOR: f64 = 1.52;

/// The bound of eq. (15) on the step of the Newmark method for the highest
/// frequency `omega_max` (rad/s), or `None` when the parameters make the
/// method unconditionally stable (`2β ≥ γ ≥ 1/2`, eq. (14)) or unstable
/// (`γ < 1/2`).
// The general bound, checked by the tests; the solver takes its
// central-difference case, [`stable_step`].
#[allow(dead_code)]
pub fn newmark_limit(omega_max: f64, beta: f64, gamma: f64) -> Option<f64> {
    if gamma < 0.5 || 2.0 * beta >= gamma {
        return None;
    }
    Some(1.0 / (omega_max * (0.5 * gamma - beta).sqrt()))
}

/// `κ` of the nodal Galerkin form (`weak_form = 1`, `src/approx/nodal.rs`):
/// the largest measured value, 1.862 (2 rings; 1.821, 1.792 and 1.805 at
/// 3, 4 and 5), with the margin of [`OMEGA_FACTOR`], 4.8 %. Its stiffness
/// `Gᵀ V C G` (G the collocated gradients) is stiffer at the top of its
/// spectrum than the seed's sphere form, by 28 %; at the sphere form's
/// step the nodal form's highest modes grow (VALIDATION.md, "The nodal
/// form's own stable step").
pub const OMEGA_FACTOR_NODAL: f64 = 1.95;

/// `κ` of the nodal form with conforming gradients (`weak_form = 2`,
/// `src/approx/conform.rs`): twice [`OMEGA_FACTOR_NODAL`], half its step. On
/// the undeformed rod the corrected operator is no stiffer (κ 1.850,
/// 1.816, 1.788 at 2, 3 and 4 rings, against 1.862, 1.821, 1.792), but its
/// highest frequency grows with the deformation where the layers over the
/// face are squashed: on the Wilkins bar at 8 across, `ω_max Δt / 2` at
/// the nodal form's step reaches 1.14 at 30 µs (0.44 for the plain
/// gradients), and the run stops with `EnergyDrift` at 27-32 µs. At half
/// the step it comes to rest, and at a third the length and face radius
/// are the same to four digits (VALIDATION.md, "Conforming gradients").
pub const OMEGA_FACTOR_CONFORMING: f64 = 2.0 * OMEGA_FACTOR_NODAL;

/// The stable step of the central differences (`β = 0`, `γ = 1/2`):
/// `safety · 2 / ω_max` with `ω_max = OMEGA_FACTOR · c_p / d_min`.
pub fn stable_step(wave_speed: f64, d_min: f64, safety: f64) -> f64 {
    stable_step_with(OMEGA_FACTOR, wave_speed, d_min, safety)
}

/// [`stable_step`] with the factor `kappa` of `ω_max = κ c_p / d_min`
/// ([`OMEGA_FACTOR`] or [`OMEGA_FACTOR_NODAL`]).
pub fn stable_step_with(kappa: f64, wave_speed: f64, d_min: f64, safety: f64) -> f64 {
    safety * 2.0 * d_min / (kappa * wave_speed)
}

/// The largest eigenvalue (in magnitude) of the linear operator `apply` on
/// vectors of length `n`, by `iterations` steps of power iteration from a
/// fixed, deterministic start; the Rayleigh quotient of the last iterate.
pub fn largest_eigenvalue(
    n: usize,
    iterations: usize,
    mut apply: impl FnMut(&[f64], &mut [f64]),
) -> f64 {
    // A start with every mode in it: a scrambled sequence.
    let mut x: Vec<f64> = (0..n)
        .map(|i| ((i as f64 * 0.618_033_988_749_895).fract() - 0.5) + 1e-3)
        .collect();
    let mut y = vec![0.0; n];
    let mut lambda = 0.0;
    for _ in 0..iterations {
        let norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        x.iter_mut().for_each(|v| *v /= norm);
        apply(&x, &mut y);
        lambda = x.iter().zip(&y).map(|(a, b)| a * b).sum::<f64>();
        std::mem::swap(&mut x, &mut y);
    }
    lambda
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn newmark_limits() {
        // Central differences: 2 / ω.
        assert_eq!(newmark_limit(1e6, 0.0, 0.5), Some(2e-6));
        // Fox-Goodwin (β = 1/12): √6 / ω.
        let fg = newmark_limit(1.0, 1.0 / 12.0, 0.5).unwrap();
        assert!((fg - 6f64.sqrt()).abs() < 1e-14);
        // Average acceleration: unconditionally stable; γ < 1/2: never.
        assert_eq!(newmark_limit(1.0, 0.25, 0.5), None);
        assert_eq!(newmark_limit(1.0, 0.0, 0.4), None);
        assert_eq!(stable_step(5000.0, 1e-3, 1.0), 2e-3 / (1.52 * 5000.0));
    }

    #[test]
    fn power_iteration_finds_the_largest_eigenvalue() {
        // The 1-D Laplacian with fixed ends: 4 sin²(π n / (2 (n + 1))).
        let n = 50;
        let lam = largest_eigenvalue(n, 4000, |x, y| {
            for i in 0..n {
                let l = if i > 0 { x[i - 1] } else { 0.0 };
                let r = if i + 1 < n { x[i + 1] } else { 0.0 };
                y[i] = 2.0 * x[i] - l - r;
            }
        });
        let exact = 4.0
            * (std::f64::consts::PI * n as f64 / (2.0 * (n as f64 + 1.0)))
                .sin()
                .powi(2);
        assert!((lam - exact).abs() < 1e-4 * exact, "{lam} {exact}");
    }
}
