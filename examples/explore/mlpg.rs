//! Measurements behind the MLPG test spheres and damping (moved from
//! `tests/suite/mlpg.rs`).

use crate::bar::*;
use meshless_impact::internals::mlpg::{ALPHA, OMEGA_FACTOR};

/// The measurement behind `sphere::ALPHA`: for each α, κ and, over 5
/// periods at a third of the stable step, the period error and the largest
/// energy error, at 3 rings.
pub fn alpha_table() {
    let expected = love_period(2e-3, 20e-3);
    for alpha in [0.5, 0.6, 0.7, 0.8, 0.9, 0.99] {
        for rings in [2, 3] {
            let bar = Bar::new(rings, alpha);
            let (period, energy, _) = bar.fundamental_period(5.0, 0.3);
            println!(
                "alpha {alpha} rings {rings}: kappa {:.3}, period error {:.2e}, energy error {energy:.2e}",
                kappa(&bar),
                period / expected - 1.0
            );
        }
    }
}

/// The spectrum of the semi-discrete operator `ü = −K u` of the free bar
/// (dense, by nalgebra's Schur form): the eigenvalues `λ = ω²` that are not
/// real and positive, the growth rate `max |Im √λ|` they give, and where
/// the eigenvector of the fastest-growing one lives.
pub fn unstable_modes_of_the_bar() {
    use nalgebra::{Complex, DMatrix, DVector};
    for (rings, alpha) in [(2, 0.5), (2, 0.9), (3, 0.9)] {
        let bar = Bar::new(rings, alpha);
        let n = 3 * bar.len();
        let mut k = DMatrix::<f64>::zeros(n, n);
        let mut e = vec![0.0; n];
        let mut col = vec![0.0; n];
        for j in 0..n {
            e[j] = 1.0;
            bar.stiffness(&e, &mut col);
            e[j] = 0.0;
            for i in 0..n {
                k[(i, j)] = col[i];
            }
        }
        let eig = k.clone().complex_eigenvalues();
        let lmax = eig.iter().map(|l| l.norm()).fold(0.0, f64::max);
        let period = love_period(2e-3, 20e-3);
        let mut bad: Vec<(f64, Complex<f64>)> = eig
            .iter()
            .map(|l| (l.sqrt().im.abs(), *l))
            .filter(|(g, _)| *g * period > 1e-3)
            .collect();
        bad.sort_by(|a, b| b.0.total_cmp(&a.0));
        println!(
            "rings {rings}, alpha {alpha}: {} eigenvalues, |λ|max {lmax:.3e}, {} growing (growth × period > 1e-3); fastest:",
            eig.len(),
            bad.len()
        );
        for (g, l) in bad.iter().take(6) {
            println!(
                "  λ = {:.3e} {:+.3e}i, growth × period {:.3}",
                l.re,
                l.im,
                g * period
            );
        }
        // The eigenvector of the fastest: inverse iteration with its shift.
        let Some(&(_, shift)) = bad.first() else {
            continue;
        };
        let kc = k.map(|x| Complex::new(x, 0.0))
            - DMatrix::<Complex<f64>>::identity(n, n) * (shift * Complex::new(1.0 + 1e-9, 0.0));
        let lu = kc.lu();
        let mut x = DVector::<Complex<f64>>::from_element(n, Complex::new(1.0, 0.0));
        for _ in 0..3 {
            x = lu.solve(&x).unwrap();
            let norm = x.norm();
            x /= Complex::new(norm, 0.0);
        }
        let mut amp: Vec<(f64, usize)> = (0..bar.len())
            .map(|i| ((0..3).map(|d| x[3 * i + d].norm_sqr()).sum::<f64>(), i))
            .collect();
        amp.sort_by(|a, b| b.0.total_cmp(&a.0));
        let share: f64 = amp.iter().take(10).map(|a| a.0).sum();
        println!("  its ten largest nodes hold {:.1} % of it:", 100.0 * share);
        for (a, i) in amp.iter().take(10) {
            let p = bar.lattice.position[*i];
            println!(
                "    node {i} at ({:.2}, {:.2}, {:.2}) mm, {:?}, {:.1} %",
                p[0] * 1e3,
                p[1] * 1e3,
                p[2] * 1e3,
                bar.lattice.surfaces[*i],
                100.0 * a
            );
        }
    }
}

/// The measurement behind the solver's damping (`solver::mlpg3d::DAMPING`):
/// stiffness-proportional (Rayleigh) damping `σ_v = c C : D` with
/// `c = 2 ζ / ω_max`, ζ the damping ratio at the solver's `ω_max`. Each
/// eigenvalue `λ` of the undamped operator `K` gives the modes
/// `s² + c λ s + λ = 0` of `ü = −K u − c K u̇`; the table prints the
/// fastest growth `max Re s` times the fundamental period, then, from 5
/// periods of the fundamental mode at 0.9 of the damped stable step, the
/// period error, the largest energy error (dissipation booked) and the
/// fraction dissipated.
pub fn damping_table() {
    use nalgebra::{Complex, DMatrix};
    let period = love_period(2e-3, 20e-3);
    let (lambda, mu) = lame();
    let cp = ((lambda + 2.0 * mu) / RHO).sqrt();
    let project = std::env::var("MLPG_PROJECT").is_ok();
    let smoothing: f64 = std::env::var("MLPG_SMOOTH")
        .map(|s| s.parse().unwrap())
        .unwrap_or(0.0);
    let periods: f64 = std::env::var("MLPG_PERIODS")
        .map(|s| s.parse().unwrap())
        .unwrap_or(5.0);
    let zetas: Vec<f64> = match std::env::var("MLPG_ZETA") {
        Ok(z) => z.split(',').map(|x| x.parse().unwrap()).collect(),
        Err(_) => vec![0.0, 0.02, 0.04, 0.06, 0.08, 0.1, 0.15],
    };
    let eigen = std::env::var("MLPG_NOEIG").is_err();
    let ring_list: Vec<usize> = if std::env::var("MLPG_RINGS2").is_ok() {
        vec![2]
    } else {
        vec![2, 3]
    };
    for rings in ring_list {
        let mut bar = Bar::new(rings, ALPHA);
        bar.project = project;
        bar.smoothing = smoothing;
        let n = if eigen { 3 * bar.len() } else { 0 };
        let mut k = DMatrix::<f64>::zeros(n, n);
        let mut e = vec![0.0; n];
        let mut col = vec![0.0; n];
        for j in 0..n {
            e[j] = 1.0;
            bar.stiffness(&e, &mut col);
            e[j] = 0.0;
            for i in 0..n {
                k[(i, j)] = col[i];
            }
        }
        let eig = if eigen {
            k.complex_eigenvalues().iter().copied().collect()
        } else {
            Vec::<Complex<f64>>::new()
        };
        let omega_max = OMEGA_FACTOR * cp / bar.d_min;
        for &zeta in &zetas {
            let c = 2.0 * zeta / omega_max;
            let growth = eig
                .iter()
                .map(|l| {
                    // s = (−cλ ± √(c²λ² − 4λ)) / 2
                    let root = (l * l * (c * c) - l * 4.0).sqrt();
                    let a = (-l * c + root) * 0.5;
                    let b = (-l * c - root) * 0.5;
                    a.re.max(b.re)
                })
                .fold(f64::NEG_INFINITY, f64::max);
            if eigen && zeta == *zetas.last().unwrap() {
                let mut worst: Vec<(f64, Complex<f64>)> = eig
                    .iter()
                    .map(|l| {
                        let root = (l * l * (c * c) - l * 4.0).sqrt();
                        let a = (-l * c + root) * 0.5;
                        let b = (-l * c - root) * 0.5;
                        (a.re.max(b.re), *l)
                    })
                    .collect();
                worst.sort_by(|a, b| b.0.total_cmp(&a.0));
                let lmax = eig.iter().map(|l| l.norm()).fold(0.0, f64::max);
                for (g, l) in worst.iter().take(8) {
                    println!(
                        "   growth x period {:.3}: lambda/|lambda|max = {:.3e} {:+.3e}i",
                        g * period,
                        l.re / lmax,
                        l.im / lmax
                    );
                }
            }
            let (p, energy, _, lost) = bar.damped_period(periods, 0.9, zeta);
            let _ = Complex::new(0.0, 0.0);
            println!(
                "rings {rings} zeta {zeta}: c {c:.3e} s, growth x period {:.3}, period error {:.2e}, \
                 energy error {energy:.2e}, dissipated {lost:.2e}",
                growth * period,
                p / period - 1.0
            );
        }
    }
}
