//! The small dense linear algebra of the calibration (a few parameters by a
//! few dozen residuals): a row-major matrix, Cholesky solves and the
//! symmetric eigenproblem by Jacobi rotations. The tests check them against
//! nalgebra.

/// A dense row-major matrix.
#[derive(Debug, Clone, PartialEq)]
pub struct Mat {
    /// Rows.
    pub rows: usize,
    /// Columns.
    pub cols: usize,
    data: Vec<f64>,
}

impl std::ops::Index<(usize, usize)> for Mat {
    type Output = f64;
    fn index(&self, (i, k): (usize, usize)) -> &f64 {
        &self.data[i * self.cols + k]
    }
}

impl std::ops::IndexMut<(usize, usize)> for Mat {
    fn index_mut(&mut self, (i, k): (usize, usize)) -> &mut f64 {
        &mut self.data[i * self.cols + k]
    }
}

impl Mat {
    /// A matrix of zeros.
    pub fn zeros(rows: usize, cols: usize) -> Mat {
        Mat {
            rows,
            cols,
            data: vec![0.0; rows * cols],
        }
    }

    /// The product with a vector.
    pub fn times(&self, x: &[f64]) -> Vec<f64> {
        (0..self.rows)
            .map(|i| (0..self.cols).map(|k| self[(i, k)] * x[k]).sum())
            .collect()
    }

    /// The transpose's product with a vector.
    pub fn transpose_times(&self, y: &[f64]) -> Vec<f64> {
        (0..self.cols)
            .map(|k| (0..self.rows).map(|i| self[(i, k)] * y[i]).sum())
            .collect()
    }

    /// The normal matrix `A^T A`.
    pub fn gram(&self) -> Mat {
        let mut g = Mat::zeros(self.cols, self.cols);
        for a in 0..self.cols {
            for b in 0..self.cols {
                g[(a, b)] = (0..self.rows).map(|i| self[(i, a)] * self[(i, b)]).sum();
            }
        }
        g
    }
}

/// Solves `a x = b` for a symmetric positive definite `a` by Cholesky;
/// `None` where `a` is not positive definite.
pub fn solve_spd(a: &Mat, b: &[f64]) -> Option<Vec<f64>> {
    Some(cholesky_solve(&cholesky(a)?, b))
}

/// The lower Cholesky factor `l` of a symmetric positive definite `a`
/// (`a = l lᵀ`); `None` where `a` is not positive definite.
pub fn cholesky(a: &Mat) -> Option<Mat> {
    let n = a.rows;
    let mut l = Mat::zeros(n, n);
    for i in 0..n {
        for k in 0..=i {
            let s: f64 = a[(i, k)] - (0..k).map(|m| l[(i, m)] * l[(k, m)]).sum::<f64>();
            if i == k {
                if s.is_nan() || s <= 0.0 || s.is_infinite() {
                    return None;
                }
                l[(i, i)] = s.sqrt();
            } else {
                l[(i, k)] = s / l[(k, k)];
            }
        }
    }
    Some(l)
}

/// Solves `l lᵀ x = b` with the factor `l` of [`cholesky`].
pub fn cholesky_solve(l: &Mat, b: &[f64]) -> Vec<f64> {
    let n = l.rows;
    let mut y = vec![0.0; n];
    for i in 0..n {
        y[i] = (b[i] - (0..i).map(|m| l[(i, m)] * y[m]).sum::<f64>()) / l[(i, i)];
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        x[i] = (y[i] - (i + 1..n).map(|m| l[(m, i)] * x[m]).sum::<f64>()) / l[(i, i)];
    }
    x
}

/// The eigenvalues and eigenvectors (columns of the returned matrix) of a
/// symmetric matrix, by cyclic Jacobi rotations.
pub fn symmetric_eigen(a: &Mat) -> (Vec<f64>, Mat) {
    let n = a.rows;
    let mut m = a.clone();
    let mut v = Mat::zeros(n, n);
    for i in 0..n {
        v[(i, i)] = 1.0;
    }
    for _sweep in 0..100 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&k| k != i).map(move |k| (i, k)))
            .map(|(i, k)| m[(i, k)] * m[(i, k)])
            .sum();
        let diag: f64 = (0..n).map(|i| m[(i, i)] * m[(i, i)]).sum();
        if off <= 1e-30 * diag || off == 0.0 {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                if m[(p, q)] == 0.0 {
                    continue;
                }
                let theta = (m[(q, q)] - m[(p, p)]) / (2.0 * m[(p, q)]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..n {
                    let (mkp, mkq) = (m[(k, p)], m[(k, q)]);
                    m[(k, p)] = c * mkp - s * mkq;
                    m[(k, q)] = s * mkp + c * mkq;
                }
                for k in 0..n {
                    let (mpk, mqk) = (m[(p, k)], m[(q, k)]);
                    m[(p, k)] = c * mpk - s * mqk;
                    m[(q, k)] = s * mpk + c * mqk;
                }
                for k in 0..n {
                    let (vkp, vkq) = (v[(k, p)], v[(k, q)]);
                    v[(k, p)] = c * vkp - s * vkq;
                    v[(k, q)] = s * vkp + c * vkq;
                }
            }
        }
    }
    ((0..n).map(|i| m[(i, i)]).collect(), v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Mat {
        let mut a = Mat::zeros(3, 3);
        let rows = [[4.0, 1.0, 0.5], [1.0, 3.0, -0.2], [0.5, -0.2, 2.0]];
        for i in 0..3 {
            for k in 0..3 {
                a[(i, k)] = rows[i][k];
            }
        }
        a
    }

    #[test]
    fn cholesky_solves_as_nalgebra() {
        let a = sample();
        let b = [1.0, -2.0, 0.5];
        let x = solve_spd(&a, &b).unwrap();
        let na = nalgebra::Matrix3::from_fn(|i, k| a[(i, k)]);
        let nx = na.lu().solve(&nalgebra::Vector3::from(b)).unwrap();
        for i in 0..3 {
            assert!((x[i] - nx[i]).abs() < 1e-14, "{x:?} {nx:?}");
        }
        let mut not_pd = sample();
        not_pd[(2, 2)] = -1.0;
        assert_eq!(solve_spd(&not_pd, &b), None);
    }

    #[test]
    fn eigen_as_nalgebra() {
        let a = sample();
        let (mut w, v) = symmetric_eigen(&a);
        for k in 0..3 {
            let col: Vec<f64> = (0..3).map(|i| v[(i, k)]).collect();
            let av = a.times(&col);
            for i in 0..3 {
                assert!((av[i] - w[k] * col[i]).abs() < 1e-12);
            }
        }
        w.sort_by(f64::total_cmp);
        let na = nalgebra::Matrix3::from_fn(|i, k| a[(i, k)]);
        let mut nw: Vec<f64> = na.symmetric_eigenvalues().iter().copied().collect();
        nw.sort_by(f64::total_cmp);
        for i in 0..3 {
            assert!((w[i] - nw[i]).abs() < 1e-12, "{w:?} {nw:?}");
        }
    }

    #[test]
    fn products() {
        let mut j = Mat::zeros(3, 2);
        for i in 0..3 {
            for k in 0..2 {
                j[(i, k)] = (i * 2 + k) as f64 + 1.0;
            }
        }
        assert_eq!(j.times(&[1.0, 2.0]), vec![5.0, 11.0, 17.0]);
        assert_eq!(j.transpose_times(&[1.0, 0.0, 1.0]), vec![6.0, 8.0]);
        let g = j.gram();
        assert_eq!((g[(0, 0)], g[(0, 1)], g[(1, 1)]), (35.0, 44.0, 56.0));
    }
}
