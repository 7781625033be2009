//! The uncertainty of a fit from the Jacobian at the optimum: the
//! covariance `s^2 (J^T J)^+` scaled by the residual (`s^2`, the weighted
//! sum of squares over the degrees of freedom), standard errors,
//! correlations, and which parameters the data determine.

use super::linalg::{Mat, symmetric_eigen};

/// Relative standard error above which a parameter is not determined.
pub const MAX_RELATIVE_STD: f64 = 0.5;

/// Correlation (in absolute value) with another parameter above which a
/// parameter is not determined.
pub const MAX_CORRELATION: f64 = 0.95;

/// Eigenvalues of the scaled normal matrix below this (its trace is the
/// number of parameters) count as a direction the data do not see.
const NULL_EIGENVALUE: f64 = 1e-10;

/// The uncertainty of the fitted parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Uncertainty {
    /// Standard error of each parameter; `None` where the data do not
    /// constrain it at all (or no residual is left to scale by).
    pub std: Vec<Option<f64>>,
    /// Correlations, row by row; `None` beside an unconstrained parameter.
    pub correlation: Vec<Vec<Option<f64>>>,
    /// Whether the data determine each parameter, with the reason where
    /// they do not.
    pub identifiable: Vec<Result<(), String>>,
    /// Degrees of freedom: residuals less parameters.
    pub dof: usize,
    /// The residual's scale `s^2`.
    pub scale: Option<f64>,
}

/// The uncertainty of parameters `x` (named `names`) from the Jacobian `j`
/// of the weighted residuals `r` at the optimum.
pub fn uncertainty(names: &[String], x: &[f64], j: &Mat, r: &[f64]) -> Uncertainty {
    let p = x.len();
    let m = r.len();
    let dof = m.saturating_sub(p);
    let scale = (dof > 0).then(|| r.iter().map(|v| v * v).sum::<f64>() / dof as f64);
    let g = j.gram();
    let d: Vec<f64> = (0..p).map(|k| g[(k, k)].sqrt()).collect();
    // The normal matrix scaled to a unit diagonal (a column of zeros, a
    // parameter the residuals do not depend on, stays zero).
    let mut c = Mat::zeros(p, p);
    for a in 0..p {
        for b in 0..p {
            if d[a] > 0.0 && d[b] > 0.0 {
                c[(a, b)] = g[(a, b)] / (d[a] * d[b]);
            }
        }
    }
    let (w, v) = symmetric_eigen(&c);
    // Pseudo-inverse over the directions the data see; a parameter with a
    // part in a null direction is unconstrained.
    let mut unseen = vec![false; p];
    let mut cinv = Mat::zeros(p, p);
    for (k, &wk) in w.iter().enumerate() {
        if wk < NULL_EIGENVALUE {
            for a in 0..p {
                if v[(a, k)].abs() > 1e-6 {
                    unseen[a] = true;
                }
            }
            continue;
        }
        for a in 0..p {
            for b in 0..p {
                cinv[(a, b)] += v[(a, k)] * v[(b, k)] / wk;
            }
        }
    }
    for a in 0..p {
        if d[a] == 0.0 {
            unseen[a] = true;
        }
    }
    let cov = |a: usize, b: usize| cinv[(a, b)] / (d[a] * d[b]);
    let std: Vec<Option<f64>> = (0..p)
        .map(|a| match (unseen[a], scale) {
            (false, Some(s2)) => Some((s2 * cov(a, a)).sqrt()),
            _ => None,
        })
        .collect();
    let correlation: Vec<Vec<Option<f64>>> = (0..p)
        .map(|a| {
            (0..p)
                .map(|b| {
                    if unseen[a] || unseen[b] {
                        None
                    } else if a == b {
                        Some(1.0)
                    } else {
                        Some(cinv[(a, b)] / (cinv[(a, a)] * cinv[(b, b)]).sqrt())
                    }
                })
                .collect()
        })
        .collect();
    let identifiable = (0..p)
        .map(|a| {
            if unseen[a] {
                return Err(format!(
                    "the data do not depend on {} (or only through a combination of the others)",
                    names[a]
                ));
            }
            let Some(sd) = std[a] else {
                return Err(format!(
                    "{m} measurements for {p} free parameters leave no residual to scale its uncertainty"
                ));
            };
            let rel = sd / x[a].abs();
            if rel.is_nan() || rel > MAX_RELATIVE_STD {
                return Err(format!(
                    "relative standard error {:.0} % (over {:.0} %)",
                    100.0 * rel,
                    100.0 * MAX_RELATIVE_STD
                ));
            }
            let worst = (0..p)
                .filter(|&b| b != a)
                .filter_map(|b| Some((b, correlation[a][b]?)))
                .max_by(|(_, x), (_, y)| x.abs().total_cmp(&y.abs()));
            match worst {
                Some((b, rho)) if rho.abs() > MAX_CORRELATION => Err(format!(
                    "correlation {rho:+.3} with {}: the data cannot tell them apart",
                    names[b]
                )),
                _ => Ok(()),
            }
        })
        .collect();
    Uncertainty {
        std,
        correlation,
        identifiable,
        dof,
        scale,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(n: usize) -> Vec<String> {
        (0..n).map(|k| format!("p{k}")).collect()
    }

    /// A straight line y = a + b t fitted to noisy points: the standard
    /// errors and the correlation of the textbook formulas.
    #[test]
    fn straight_line_as_the_textbook() {
        let t = [0.0, 1.0, 2.0, 3.0, 4.0];
        let r = [0.1, -0.2, 0.05, 0.15, -0.1];
        let mut j = Mat::zeros(5, 2);
        for i in 0..5 {
            j[(i, 0)] = 1.0;
            j[(i, 1)] = t[i];
        }
        let u = uncertainty(&names(2), &[1.0, 2.0], &j, &r);
        let s2 = r.iter().map(|v| v * v).sum::<f64>() / 3.0;
        let (n, st, stt) = (5.0, 10.0, 30.0);
        let det = n * stt - st * st;
        let (var_a, var_b, cov_ab) = (s2 * stt / det, s2 * n / det, -s2 * st / det);
        assert!((u.std[0].unwrap() - var_a.sqrt()).abs() < 1e-12);
        assert!((u.std[1].unwrap() - var_b.sqrt()).abs() < 1e-12);
        let rho = cov_ab / (var_a * var_b).sqrt();
        assert!((u.correlation[0][1].unwrap() - rho).abs() < 1e-12);
        assert_eq!(u.dof, 3);
    }

    /// Two parameters that act only through their sum are not determined.
    #[test]
    fn a_combination_is_flagged() {
        let mut j = Mat::zeros(4, 3);
        for i in 0..4 {
            j[(i, 0)] = 1.0 + i as f64;
            j[(i, 1)] = 1.0 + i as f64;
            j[(i, 2)] = (i * i) as f64;
        }
        let u = uncertainty(&names(3), &[1.0, 1.0, 1.0], &j, &[0.01, -0.01, 0.02, 0.0]);
        assert!(u.identifiable[0].is_err() && u.identifiable[1].is_err());
        assert!(u.std[0].is_none());
        // Nearly so: correlated beyond the bound.
        j[(3, 1)] = 4.05;
        let small = [1e-5, -1e-5, 2e-5, 0.0];
        let u = uncertainty(&names(3), &[1.0, 1.0, 1.0], &j, &small);
        let e = u.identifiable[0].clone().unwrap_err();
        assert!(e.contains("correlation") && e.contains("p1"), "{e}");
    }
}
