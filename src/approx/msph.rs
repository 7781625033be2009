//! Modified SPH (MSPH) basis functions, eqs. (2.2)-(2.6) of Batra & Zhang (2008).
//!
//! For particle `i` the Taylor expansion of a field to second order, multiplied by
//! the kernel and its first and second derivatives and summed over the
//! neighbours with weights `V_j = m_j / rho_j`, gives the linear system
//! `B F = T` (6x6 in the R-Z plane, 3x3 on a line). Row `k` of `B^-1` turns the
//! neighbour values into the `k`-th entry of `F = (f, f_R, f_Z, f_RR, f_ZZ, f_RZ)`.
//!
//! The system is assembled in scaled variables (offsets divided by `h`, the
//! `k`-th derivative of the kernel multiplied by `h^k`) so that its entries are
//! of order one whatever the units; the kernel's normalising constant cancels.
//! A particle (a ring in the axisymmetric case) weighs `V_j = m_j / rho_j`.

use crate::isa::{Isa, hot};
use crate::kernel::{EXP_M4, SUPPORT};
use crate::lanes::{Lanes, W};

/// Largest 1-norm condition number of a scaled moment matrix that is accepted.
/// Beyond it the particle arrangement cannot support a second-order
/// expansion and the solver stops with a named error.
pub const MAX_CONDITION: f64 = 1e10;

/// Index of an entry of `F` in the 2-D system.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(usize)]
pub enum Row2 {
    /// f
    F = 0,
    /// df/dR
    R = 1,
    /// df/dZ
    Z = 2,
    /// d2f/dR2
    Rr = 3,
    /// d2f/dZ2
    Zz = 4,
    /// d2f/dRdZ
    Rz = 5,
}

impl Row2 {
    /// Order of the derivative this row estimates.
    fn order(self) -> i32 {
        match self {
            Row2::F => 0,
            Row2::R | Row2::Z => 1,
            _ => 2,
        }
    }
}

/// A moment matrix that could not be inverted: the neighbourhood of `particle`
/// is degenerate (too few or collinear neighbours).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Degenerate {
    /// Index of the particle.
    pub particle: usize,
    /// Estimated 1-norm condition number (infinite when singular).
    pub condition: f64,
}

/// Scaled test functions `Phi` (kernel and derivatives times powers of h) for a
/// scaled offset `s = (x_j - x_i)/h`: `None` outside the support. Entry 0 is
/// the kernel value up to its normalisation.
#[inline]
pub fn phi2(sr: f64, sz: f64) -> Option<[f64; 6]> {
    let q2 = sr * sr + sz * sz;
    if q2 > SUPPORT * SUPPORT {
        return None;
    }
    let e = (-q2).exp();
    // Derivatives are with respect to the evaluation point x_i, so d = -s.
    Some([
        e - EXP_M4,
        2.0 * e * sr,
        2.0 * e * sz,
        e * (4.0 * sr * sr - 2.0),
        e * (4.0 * sz * sz - 2.0),
        e * 4.0 * sr * sz,
    ])
}

#[inline]
fn theta2(sr: f64, sz: f64) -> [f64; 6] {
    [1.0, sr, sz, 0.5 * sr * sr, 0.5 * sz * sz, sr * sz]
}

/// The scaled 2-D moment matrix `B` of one particle, assembled one neighbour
/// at a time ([`Moments2::add`]) and solved for selected rows of its inverse
/// ([`Moments2::solve`]). Solvers that walk their neighbours themselves use it
/// to evaluate each pair's test functions once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Moments2 {
    /// Column-major entries: `b[c][a] = sum_j Phi_a(s_j) Theta_c(s_j) V_j`.
    b: [[f64; 6]; 6],
}

impl Default for Moments2 {
    fn default() -> Self {
        Moments2 { b: [[0.0; 6]; 6] }
    }
}

impl Moments2 {
    /// Adds the neighbour at scaled offset `(sr, sz)`, with test functions
    /// `phi` (from [`phi2`]) and weight `v`.
    #[inline]
    pub fn add(&mut self, phi: &[f64; 6], sr: f64, sz: f64, v: f64) {
        let th = theta2(sr, sz);
        let mut pv = [0.0; 6];
        for a in 0..6 {
            pv[a] = phi[a] * v;
        }
        for c in 0..6 {
            for a in 0..6 {
                self.b[c][a] += pv[a] * th[c];
            }
        }
    }

    /// Inverts the matrix of particle `i` (at `xi`, smoothing length `h`) and
    /// keeps the requested rows; a singular or ill-conditioned matrix is a
    /// [`Degenerate`] error.
    pub fn solve<const K: usize>(
        &self,
        i: usize,
        xi: [f64; 2],
        h: f64,
        which: [Row2; K],
    ) -> Result<Msph2Rows<K>, Degenerate> {
        let inv_h = 1.0 / h;
        let b: [[f64; 6]; 6] = std::array::from_fn(|a| std::array::from_fn(|c| self.b[c][a]));
        let inv = invert_checked(i, b)?;
        let rows = which.map(|r| inv[r as usize]);
        let scale = which.map(|r| inv_h.powi(r.order()));
        Ok(Msph2Rows {
            rows,
            scale,
            xi,
            inv_h,
        })
    }
}

/// Index of the monomial `s_R^p s_Z^q` among the 15 of degree at most 4,
/// ordered by degree, then by the power of `s_Z`.
const fn monomial(p: usize, q: usize) -> usize {
    let d = p + q;
    d * (d + 1) / 2 + q
}

/// `Theta_c` as (power of s_R, power of s_Z, coefficient).
const THETA: [(usize, usize, f64); 6] = [
    (0, 0, 1.0),
    (1, 0, 1.0),
    (0, 1, 1.0),
    (2, 0, 0.5),
    (0, 2, 0.5),
    (1, 1, 1.0),
];

/// `Phi_a / exp(-|s|^2)` as polynomial terms (power of s_R, power of s_Z,
/// coefficient); `Phi_0` also carries `-exp(-4)`.
const PHI: [&[(usize, usize, f64)]; 6] = [
    &[(0, 0, 1.0)],
    &[(1, 0, 2.0)],
    &[(0, 1, 2.0)],
    &[(2, 0, 4.0), (0, 0, -2.0)],
    &[(0, 2, 4.0), (0, 0, -2.0)],
    &[(1, 1, 4.0)],
];

/// Number of power sums behind a 2-D moment matrix: the 15 monomials
/// `s_R^p s_Z^q` (`p + q <= 4`) weighted by `V_j exp(-|s_j|^2)`, then the 6 of
/// degree at most 2 weighted by `V_j` alone.
pub const POWER_SUMS: usize = 21;

/// The scaled moment matrix `B` (row-major: `B[a][c] = sum_j V_j Phi_a(s_j)
/// Theta_c(s_j)`) from its power sums (see [`Neighbourhood::power_sums`]).
#[inline(always)]
pub fn moment_matrix(sums: &[f64; POWER_SUMS]) -> [[f64; 6]; 6] {
    moment_matrix_of(&sums.map(|x| [x])).map(|row| row.map(|[x]| x))
}

/// [`moment_matrix`] of [`W`] particles at once, lane `l` of the power sums
/// giving lane `l` of the matrix (the same operations in the same order).
#[inline(always)]
pub fn moment_matrix_lanes(sums: &[Lanes; POWER_SUMS]) -> crate::lanes::LaneMatrix<6> {
    moment_matrix_of(sums)
}

/// The moment matrices of `L` particles, one per lane.
#[inline(always)]
// The unrolled loops have empty ranges for the first constant.
#[allow(clippy::reversed_empty_ranges)]
fn moment_matrix_of<const L: usize>(sums: &[[f64; L]; POWER_SUMS]) -> [[[f64; L]; 6]; 6] {
    let (m, n) = sums.split_at(15);
    let mut b = [[[0.0; L]; 6]; 6];
    // Unrolled, so that every index below is a constant.
    crate::lanes::unroll!(c in [0, 1, 2, 3, 4, 5] {
        let (pc, qc, tc) = THETA[c];
        crate::lanes::unroll!(a in [0, 1, 2, 3, 4, 5] {
            let mut x = [0.0; L];
            for &(p, q, k) in PHI[a].iter() {
                let mk = &m[monomial(p + pc, q + qc)];
                for l in 0..L {
                    x[l] += k * tc * mk[l];
                }
            }
            if a == 0 {
                let nk = &n[monomial(pc, qc)];
                for l in 0..L {
                    x[l] -= EXP_M4 * tc * nk[l];
                }
            }
            b[a][c] = x;
        });
    });
    b
}

/// Smallest pivot of the `L D L^T` elimination of the Gram matrix, relative
/// to its diagonal entry, that [`inverse_moments_lanes`] accepts: below it
/// the Gram matrix is too close to singular for the factored inverse to be
/// as accurate as a pivoting elimination of `B` itself.
pub const MIN_GRAM_PIVOT: f64 = 1e-6;

/// The inverses of the moment matrices of [`W`] particles from their power
/// sums (lane `l` of each sum for particle `l`), without pivoting.
///
/// With `Phi_a = exp(-|s|^2) sum_c P[a][c] Theta_c - exp(-4) [a = 0]`, where
/// `Theta = (1, s_R, s_Z, s_R^2 / 2, s_Z^2 / 2, s_R s_Z)` and `P` is lower
/// triangular with the diagonal (1, 2, 2, 8, 8, 4) and -2 in column 0 of rows
/// 3 and 4, the moment matrix factors as
/// `B = P G - exp(-4) e_0 u^T` with the Gram matrix `G = sum_j V_j
/// exp(-|s_j|^2) Theta(s_j) Theta(s_j)^T` (symmetric, positive definite for a
/// neighbourhood that supports a quadratic fit) and `u = sum_j V_j
/// Theta(s_j)`. So `B^-1` is `A^-1 = G^-1 P^-1` ([`crate::lanes::invert_spd6`])
/// corrected by the Sherman-Morrison formula for the rank-one term.
///
/// Returns the inverses and, per lane, whether this route does not apply:
/// a pivot of `G` at or below [`MIN_GRAM_PIVOT`] of its diagonal entry, or a
/// Sherman-Morrison denominator below 1/2 (or NaN). `B` may still be
/// invertible then (it can be even when `G` is singular), so such a lane
/// must be inverted by an elimination of `B` with pivoting
/// ([`crate::lanes::invert`]); its result here is meaningless.
#[inline(always)]
// The unrolled loops have empty ranges for the first constant.
#[allow(clippy::reversed_empty_ranges)]
pub fn inverse_moments_lanes(
    sums: &[Lanes; POWER_SUMS],
) -> (crate::lanes::LaneMatrix<6>, [bool; W]) {
    use crate::lanes::{add, mul, mul_add, splat, unroll};
    let (m, n) = sums.split_at(15);
    // Plain loops, not array::from_fn: a closure the compiler leaves out of
    // line would lose the caller's instruction set.
    let mut g = [[[0.0; W]; 6]; 6];
    unroll!(c in [0, 1, 2, 3, 4, 5] {
        for d in 0..=c {
            let ((pc, qc, tc), (pd, qd, td)) = (THETA[c], THETA[d]);
            g[c][d] = mul(splat(tc * td), m[monomial(pc + pd, qc + qd)]);
        }
    });
    let (ginv, mut elsewhere) = crate::lanes::invert_spd6(&g, MIN_GRAM_PIVOT);
    // A^-1 = G^-1 P^-1, column by column of P^-1.
    let mut a = [[[0.0; W]; 6]; 6];
    unroll!(i in [0, 1, 2, 3, 4, 5] {
        let r = &ginv[i];
        a[i][0] = add(r[0], mul(splat(0.25), add(r[3], r[4])));
        a[i][1] = mul(splat(0.5), r[1]);
        a[i][2] = mul(splat(0.5), r[2]);
        a[i][3] = mul(splat(0.125), r[3]);
        a[i][4] = mul(splat(0.125), r[4]);
        a[i][5] = mul(splat(0.25), r[5]);
    });
    // Sherman-Morrison: B^-1 = A^-1 + (A^-1 e_0)(w^T A^-1) / (1 - w^T A^-1 e_0)
    // with w = exp(-4) u.
    let mut w = [[0.0; W]; 6];
    for c in 0..6 {
        let (pc, qc, tc) = THETA[c];
        w[c] = mul(splat(EXP_M4 * tc), n[monomial(pc, qc)]);
    }
    let mut b = [[0.0; W]; 6];
    unroll!(j in [0, 1, 2, 3, 4, 5] {
        b[j] = mul(w[0], a[0][j]);
        for i in 1..6 {
            b[j] = mul_add(w[i], a[i][j], b[j]);
        }
    });
    let mut scale = [0.0; W];
    for l in 0..W {
        let gamma = 1.0 - b[0][l];
        // w = exp(-4) u is small next to the Gram terms, so gamma stays near
        // 1; far from it the correction would amplify rounding errors.
        let bad = gamma.is_nan() || gamma.abs() < 0.5;
        elsewhere[l] |= bad;
        scale[l] = 1.0 / if bad { 1.0 } else { gamma };
    }
    unroll!(i in [0, 1, 2, 3, 4, 5] {
        let c0 = mul(a[i][0], scale);
        for j in 0..6 {
            a[i][j] = mul_add(c0, b[j], a[i][j]);
        }
    });
    (a, elsewhere)
}

/// The neighbours of one particle in structure-of-arrays form (scaled
/// offsets, weights and Gaussians), for a vectorised assembly of the moment
/// matrix and of the shape-function weights, [`W`] pairs at a time.
///
/// The kernel is a Gaussian times a polynomial, so every entry of `B` is a
/// combination of the power sums `sum_j V_j exp(-|s_j|^2) s_R^p s_Z^q`
/// (`p + q <= 4`) and `sum_j V_j s_R^p s_Z^q` (`p + q <= 2`): 21 sums per
/// pair instead of 36 products.
#[derive(Debug, Clone, Default)]
pub struct Neighbourhood {
    sr: Vec<f64>,
    sz: Vec<f64>,
    v: Vec<f64>,
    e: Vec<f64>,
    len: usize,
}

/// The lane of `x` that starts at `c`.
#[inline(always)]
fn lane(x: &[f64], c: usize) -> Lanes {
    x[c..c + W].try_into().expect("a whole lane")
}

impl Neighbourhood {
    /// An empty neighbourhood with room for `n` neighbours (it grows when
    /// needed).
    pub fn with_capacity(n: usize) -> Self {
        let mut hood = Neighbourhood::default();
        hood.reserve(n);
        hood
    }

    /// Makes room for `n` neighbours and a whole lane more.
    #[inline(always)]
    pub fn reserve(&mut self, n: usize) {
        if self.sr.len() < n + W {
            self.grow(n);
        }
    }

    #[cold]
    fn grow(&mut self, n: usize) {
        let cap = (n + W).next_multiple_of(W);
        for x in [&mut self.sr, &mut self.sz, &mut self.v, &mut self.e] {
            x.resize(cap, 0.0);
        }
    }

    /// Forgets every neighbour.
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// Number of neighbours.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Number of neighbours rounded up to whole lanes of [`W`].
    pub fn padded_len(&self) -> usize {
        self.len.next_multiple_of(W)
    }

    /// True when there is no neighbour.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Adds a neighbour at scaled offset `(sr, sz) = (x_j - x_i) / h`, which
    /// must lie in the support, with weight `v = m_j / rho_j`.
    #[inline]
    pub fn push(&mut self, sr: f64, sz: f64, v: f64) {
        self.reserve(self.len + 1);
        let k = self.len;
        self.sr[k] = sr;
        self.sz[k] = sz;
        self.v[k] = v;
        self.len = k + 1;
    }

    /// Adds the candidates of a lane where `keep` holds, in lane order,
    /// without a branch.
    #[inline(always)]
    pub fn push_lanes(&mut self, keep: [bool; W], sr: Lanes, sz: Lanes, v: Lanes) {
        self.reserve(self.len + W);
        let (out_r, out_z, out_v) = (
            &mut self.sr[self.len..self.len + 2 * W],
            &mut self.sz[self.len..self.len + 2 * W],
            &mut self.v[self.len..self.len + 2 * W],
        );
        let mut k = 0;
        for l in 0..W {
            out_r[k] = sr[l];
            out_z[k] = sz[l];
            out_v[k] = v[l];
            k += keep[l] as usize;
        }
        self.len += k;
    }

    /// The offset and weight buffers (`sr`, `sz`, `v`, each with room for
    /// what [`Neighbourhood::reserve`] asked) and the neighbour count, for a
    /// caller that appends neighbours with its own vector code. Entries
    /// `0..len` must be set when `len` is raised.
    pub(crate) fn buffers(&mut self) -> (&mut [f64], &mut [f64], &mut [f64], &mut usize) {
        (&mut self.sr, &mut self.sz, &mut self.v, &mut self.len)
    }

    /// Zero-weight lanes after the last neighbour up to a whole lane, and
    /// the Gaussians `exp(-|s|^2)` of every neighbour.
    #[inline(always)]
    fn gaussians(&mut self) -> usize {
        let padded = self.padded_len();
        for k in self.len..padded {
            self.sr[k] = 0.0;
            self.sz[k] = 0.0;
            self.v[k] = 0.0;
        }
        for c in (0..padded).step_by(W) {
            let (sr, sz) = (lane(&self.sr, c), lane(&self.sz, c));
            let e = crate::lanes::exp(std::array::from_fn(|l| -(sr[l] * sr[l] + sz[l] * sz[l])));
            self.e[c..c + W].copy_from_slice(&e);
        }
        padded
    }

    /// Evaluates the Gaussians and returns the [`POWER_SUMS`] power sums of
    /// the moment matrix (for [`moment_matrix`]). Each sum runs in a fixed
    /// order ([`W`] lane partial sums, then [`crate::lanes::total`]), so the
    /// result does not depend on the thread or the instruction set.
    pub fn power_sums(&mut self) -> [f64; POWER_SUMS] {
        power_sums_of(Isa::best(), self)
    }

    /// The [`W`] lane partial sums of each power sum (see
    /// [`Neighbourhood::power_sums`], which totals them).
    #[inline(always)]
    pub fn power_partials(&mut self) -> [Lanes; POWER_SUMS] {
        let padded = self.gaussians();
        let mut acc = [[0.0; W]; POWER_SUMS];
        for c in (0..padded).step_by(W) {
            let (sr, sz, v, e) = (
                lane(&self.sr, c),
                lane(&self.sz, c),
                lane(&self.v, c),
                lane(&self.e, c),
            );
            for l in 0..W {
                let (r, z) = (sr[l], sz[l]);
                let ev = e[l] * v[l];
                let (r2, rz, z2) = (r * r, r * z, z * z);
                let mons = [
                    1.0,
                    r,
                    z,
                    r2,
                    rz,
                    z2,
                    r2 * r,
                    r2 * z,
                    rz * z,
                    z2 * z,
                    r2 * r2,
                    r2 * rz,
                    r2 * z2,
                    rz * z2,
                    z2 * z2,
                ];
                for k in 0..15 {
                    acc[k][l] = ev.mul_add(mons[k], acc[k][l]);
                }
                for k in 0..6 {
                    acc[15 + k][l] = v[l].mul_add(mons[k], acc[15 + k][l]);
                }
            }
        }
        acc
    }

    /// Assembles the moment matrix (see [`Neighbourhood::power_sums`]).
    pub fn moments(&mut self) -> Moments2 {
        let b = moment_matrix(&self.power_sums());
        Moments2 {
            b: std::array::from_fn(|c| std::array::from_fn(|a| b[a][c])),
        }
    }

    /// Shape-function weights of every neighbour for each row of `rows`
    /// (after [`Neighbourhood::moments`]), and the kernel value times `V_j`
    /// up to its normalisation in `kernel`. Each output must hold the padded
    /// length ([`Neighbourhood::padded_len`]); the padded lanes get zero.
    pub fn weights<const K: usize>(
        &self,
        rows: &Msph2Rows<K>,
        out: [&mut [f64]; K],
        kernel: &mut [f64],
    ) {
        weights_with(Isa::best(), self, rows, out, kernel);
    }

    /// [`Neighbourhood::weights`] for rows of the inverse moment matrix
    /// given as they are, each with its scale (`h^-order`). Returns the sum
    /// of the kernel values (lane partial sums, then
    /// [`crate::lanes::total`]).
    #[inline(always)]
    pub fn weights_of<const K: usize>(
        &self,
        rows: &[[f64; 6]; K],
        scale: &[f64; K],
        out: [&mut [f64]; K],
        kernel: &mut [f64],
    ) -> f64 {
        let mut sum = [0.0; W];
        for c in (0..self.padded_len()).step_by(W) {
            let (sr, sz, v, e) = (
                lane(&self.sr, c),
                lane(&self.sz, c),
                lane(&self.v, c),
                lane(&self.e, c),
            );
            let mut w = [[0.0; W]; K];
            let mut kern = [0.0; W];
            for l in 0..W {
                let (r, z, e) = (sr[l], sz[l], e[l]);
                let phi = [
                    e - EXP_M4,
                    2.0 * e * r,
                    2.0 * e * z,
                    e * (4.0 * r * r - 2.0),
                    e * (4.0 * z * z - 2.0),
                    4.0 * e * r * z,
                ];
                for k in 0..K {
                    let mut s = rows[k][0] * phi[0];
                    for a in 1..6 {
                        s = rows[k][a].mul_add(phi[a], s);
                    }
                    w[k][l] = s * v[l] * scale[k];
                }
                kern[l] = phi[0] * v[l];
                sum[l] += kern[l];
            }
            for k in 0..K {
                out[k][c..c + W].copy_from_slice(&w[k]);
            }
            kernel[c..c + W].copy_from_slice(&kern);
        }
        crate::lanes::total(sum)
    }
}

hot! {
/// [`Neighbourhood::power_sums`], compiled for each instruction set (the
/// baseline computes the fused multiply-adds in software: the same bits,
/// several times slower).
fn power_sums_of(hood: &mut Neighbourhood) -> [f64; POWER_SUMS] {
    let partials = hood.power_partials();
    let mut out = [0.0; POWER_SUMS];
    for (o, p) in out.iter_mut().zip(partials) {
        *o = crate::lanes::total(p);
    }
    out
}
}

hot! {
/// [`Neighbourhood::weights`], compiled like [`power_sums_of`].
fn weights_with<const K: usize>(
    hood: &Neighbourhood,
    rows: &Msph2Rows<K>,
    out: [&mut [f64]; K],
    kernel: &mut [f64],
) {
    hood.weights_of(&rows.rows, &rows.scale, out, kernel);
}
}

/// Selected rows of the inverse of the scaled 2-D moment matrix of particle
/// `i`, ready to form shape functions with [`Msph2Rows::weight`].
#[derive(Debug, Clone, Copy)]
pub struct Msph2Rows<const K: usize> {
    rows: [[f64; 6]; K],
    scale: [f64; K],
    xi: [f64; 2],
    inv_h: f64,
}

impl<const K: usize> Msph2Rows<K> {
    /// Solves the 2-D MSPH system of particle `i` for the requested rows.
    /// `pos` are the (R, Z) positions, `vol` the weights `m_j / rho_j`.
    pub fn new(
        i: usize,
        neighbours: &[usize],
        pos: &[[f64; 2]],
        vol: &[f64],
        h: f64,
        which: [Row2; K],
    ) -> Result<Self, Degenerate> {
        let xi = pos[i];
        let inv_h = 1.0 / h;
        let mut b = Moments2::default();
        for &j in neighbours {
            let sr = (pos[j][0] - xi[0]) * inv_h;
            let sz = (pos[j][1] - xi[1]) * inv_h;
            if let Some(phi) = phi2(sr, sz) {
                b.add(&phi, sr, sz, vol[j]);
            }
        }
        b.solve(i, xi, h, which)
    }

    /// Shape-function weights of neighbour `xj` with weight `vj` for each
    /// requested row: `d^k f(x_i) = sum_j weight_k(j) f_j`.
    #[inline]
    pub fn weight(&self, xj: [f64; 2], vj: f64) -> [f64; K] {
        let sr = (xj[0] - self.xi[0]) * self.inv_h;
        let sz = (xj[1] - self.xi[1]) * self.inv_h;
        match phi2(sr, sz) {
            Some(phi) => {
                let mut out = [0.0; K];
                for k in 0..K {
                    let r = &self.rows[k];
                    let mut s = 0.0;
                    for a in 0..6 {
                        s += r[a] * phi[a];
                    }
                    out[k] = s * vj * self.scale[k];
                }
                out
            }
            None => [0.0; K],
        }
    }
}

/// Inverse of `a` (row-major) by Gauss-Jordan elimination with partial
/// pivoting, or `None` when a pivot vanishes.
pub fn invert<const N: usize>(a: [[f64; N]; N]) -> Option<[[f64; N]; N]> {
    let mut a = a;
    let mut inv: [[f64; N]; N] =
        std::array::from_fn(|r| std::array::from_fn(|c| if r == c { 1.0 } else { 0.0 }));
    for col in 0..N {
        let mut p = col;
        for r in col + 1..N {
            if a[r][col].abs() > a[p][col].abs() {
                p = r;
            }
        }
        let pivot = a[p][col];
        if pivot == 0.0 || !pivot.is_finite() {
            return None;
        }
        a.swap(col, p);
        inv.swap(col, p);
        let d = 1.0 / pivot;
        for c in 0..N {
            a[col][c] *= d;
            inv[col][c] *= d;
        }
        for r in 0..N {
            let f = a[r][col];
            if r != col && f != 0.0 {
                for c in 0..N {
                    a[r][c] -= f * a[col][c];
                    inv[r][c] -= f * inv[col][c];
                }
            }
        }
    }
    Some(inv)
}

/// Largest absolute column sum.
fn norm1<const N: usize>(m: &[[f64; N]; N]) -> f64 {
    (0..N)
        .map(|c| m.iter().map(|row| row[c].abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// The inverse of the moment matrix `b` of particle `i`, or [`Degenerate`]
/// when it is singular or its 1-norm condition number passes
/// [`MAX_CONDITION`].
fn invert_checked<const N: usize>(i: usize, b: [[f64; N]; N]) -> Result<[[f64; N]; N], Degenerate> {
    let inv = invert(b).ok_or(Degenerate {
        particle: i,
        condition: f64::INFINITY,
    })?;
    let cond = norm1(&b) * norm1(&inv);
    if !cond.is_finite() || cond > MAX_CONDITION {
        return Err(Degenerate {
            particle: i,
            condition: cond,
        });
    }
    Ok(inv)
}

/// Index of an entry of `F = (f, f_R, f_RR)` in the 1-D system.
// The Noh solver asks for `R` only; the tests check every row.
#[allow(dead_code)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(usize)]
pub enum Row1 {
    /// f
    F = 0,
    /// df/dR
    R = 1,
    /// d2f/dR2
    Rr = 2,
}

#[inline]
fn phi1(s: f64) -> Option<[f64; 3]> {
    let q2 = s * s;
    if q2 > SUPPORT * SUPPORT {
        return None;
    }
    let e = (-q2).exp();
    Some([e - EXP_M4, 2.0 * e * s, e * (4.0 * s * s - 2.0)])
}

/// Selected rows of the inverse of the scaled 1-D (radial) moment matrix.
#[derive(Debug, Clone, Copy)]
pub struct Msph1Rows<const K: usize> {
    rows: [[f64; 3]; K],
    scale: [f64; K],
    xi: f64,
    inv_h: f64,
}

impl<const K: usize> Msph1Rows<K> {
    /// Solves the 3x3 MSPH system (f, f_R, f_RR) of particle `i` on a line.
    pub fn new(
        i: usize,
        neighbours: &[usize],
        pos: &[f64],
        vol: &[f64],
        h: f64,
        which: [Row1; K],
    ) -> Result<Self, Degenerate> {
        let xi = pos[i];
        let inv_h = 1.0 / h;
        let mut b = [[0.0; 3]; 3];
        for &j in neighbours {
            let s = (pos[j] - xi) * inv_h;
            let Some(phi) = phi1(s) else { continue };
            let th = [1.0, s, 0.5 * s * s];
            for a in 0..3 {
                for c in 0..3 {
                    b[a][c] += phi[a] * vol[j] * th[c];
                }
            }
        }
        let inv = invert_checked(i, b)?;
        let rows = which.map(|r| inv[r as usize]);
        let scale = which.map(|r| inv_h.powi(r as i32));
        Ok(Self {
            rows,
            scale,
            xi,
            inv_h,
        })
    }

    /// Shape-function weights of the neighbour at `xj` with weight `vj`.
    #[inline]
    pub fn weight(&self, xj: f64, vj: f64) -> [f64; K] {
        let Some(phi) = phi1((xj - self.xi) * self.inv_h) else {
            return [0.0; K];
        };
        let mut out = [0.0; K];
        for k in 0..K {
            let r = &self.rows[k];
            out[k] = (r[0] * phi[0] + r[1] * phi[1] + r[2] * phi[2]) * vj * self.scale[k];
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::neighbours::cell_list;

    /// A jittered lattice of ring particles in a rectangle touching the axis,
    /// with ring volumes as weights.
    fn cloud() -> (Vec<[f64; 2]>, Vec<f64>, f64) {
        let d = 0.1;
        let mut p = Vec::new();
        let mut v = Vec::new();
        let mut s = 12345u64;
        for k in 0..15 {
            for i in 0..10 {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let jr = ((s >> 33) as f64 / (1u64 << 31) as f64 - 0.5) * 0.3 * d;
                let jz = ((s >> 17 & 0xffff) as f64 / 65536.0 - 0.5) * 0.3 * d;
                let r = if i == 0 { 0.0 } else { i as f64 * d + jr };
                p.push([r, k as f64 * d + jz]);
                v.push(2.0 * std::f64::consts::PI * r.max(d / 4.0) * d * d);
            }
        }
        (p, v, 1.5 * d)
    }

    #[test]
    fn reproduces_quadratic_fields_and_their_derivatives_exactly() {
        let (p, v, h) = cloud();
        let nl = cell_list(&p, 2.0 * h);
        let f = |x: &[f64; 2]| {
            1.5 - 2.0 * x[0] + 0.7 * x[1] + 3.0 * x[0] * x[0] - 1.1 * x[1] * x[1]
                + 0.4 * x[0] * x[1]
        };
        let exact = |x: &[f64; 2]| {
            [
                f(x),
                -2.0 + 6.0 * x[0] + 0.4 * x[1],
                0.7 - 2.2 * x[1] + 0.4 * x[0],
                6.0,
                -2.2,
                0.4,
            ]
        };
        let all = [Row2::F, Row2::R, Row2::Z, Row2::Rr, Row2::Zz, Row2::Rz];
        // Every particle, including those on the axis, the corners and the edges.
        for i in 0..p.len() {
            let m = Msph2Rows::new(i, nl.of(i), &p, &v, h, all).unwrap();
            let mut est = [0.0; 6];
            for &j in nl.of(i) {
                let w = m.weight(p[j], v[j]);
                for k in 0..6 {
                    est[k] += w[k] * f(&p[j]);
                }
            }
            let ex = exact(&p[i]);
            for k in 0..6 {
                assert!(
                    (est[k] - ex[k]).abs() < 1e-7 * (1.0 + ex[k].abs()),
                    "particle {i} row {k}: {} vs {}",
                    est[k],
                    ex[k]
                );
            }
        }
    }

    #[test]
    fn vectorised_neighbourhood_equals_the_direct_assembly() {
        let (p, v, h) = cloud();
        let nl = cell_list(&p, 2.0 * h);
        let all = [Row2::F, Row2::R, Row2::Z, Row2::Rr, Row2::Zz, Row2::Rz];
        let mut hood = Neighbourhood::with_capacity(8);
        for i in 0..p.len() {
            let direct = Msph2Rows::new(i, nl.of(i), &p, &v, h, all).unwrap();
            hood.clear();
            let mut inside = Vec::new();
            for &j in nl.of(i) {
                let (sr, sz) = ((p[j][0] - p[i][0]) / h, (p[j][1] - p[i][1]) / h);
                if sr * sr + sz * sz <= SUPPORT * SUPPORT {
                    hood.push(sr, sz, v[j]);
                    inside.push(j);
                }
            }
            let m = hood.moments().solve(i, p[i], h, all).unwrap();
            let padded = hood.padded_len();
            let mut out = [(); 6].map(|_| vec![f64::NAN; padded]);
            let mut kern = vec![f64::NAN; padded];
            let [o0, o1, o2, o3, o4, o5] = &mut out;
            hood.weights(&m, [o0, o1, o2, o3, o4, o5], &mut kern);
            for (k, &j) in inside.iter().enumerate() {
                let w = direct.weight(p[j], v[j]);
                for r in 0..6 {
                    let scale = 1.0 + w[r].abs();
                    assert!(
                        (out[r][k] - w[r]).abs() < 1e-9 * scale,
                        "particle {i}, neighbour {j}, row {r}: {} vs {}",
                        out[r][k],
                        w[r]
                    );
                }
                let (sr, sz) = ((p[j][0] - p[i][0]) / h, (p[j][1] - p[i][1]) / h);
                let k_direct = phi2(sr, sz).unwrap()[0] * v[j];
                assert!((kern[k] - k_direct).abs() < 1e-14 * (1.0 + k_direct.abs()));
            }
            // Padded lanes carry zero weight.
            for k in inside.len()..padded {
                assert_eq!(kern[k], 0.0);
            }
        }
    }

    /// The lane inverse from the Gram factorisation equals the scalar
    /// Gauss-Jordan inverse with pivoting of the assembled moment matrix, on
    /// every particle of the jittered cloud (edge and axis particles
    /// included), eight at a time. Lanes it cannot serve are flagged without
    /// spoiling the others: a collinear neighbourhood, a NaN, and five
    /// neighbours, whose Gram matrix is singular while `B` is not.
    #[test]
    fn lane_inverse_of_the_moments_equals_gauss_jordan() {
        let (p, v, h) = cloud();
        let nl = cell_list(&p, 2.0 * h);
        let mut sums: Vec<[f64; POWER_SUMS]> = (0..p.len())
            .map(|i| {
                let mut hood = Neighbourhood::with_capacity(8);
                for &j in nl.of(i) {
                    let (sr, sz) = ((p[j][0] - p[i][0]) / h, (p[j][1] - p[i][1]) / h);
                    if sr * sr + sz * sz <= SUPPORT * SUPPORT {
                        hood.push(sr, sz, v[j]);
                    }
                }
                hood.power_sums()
            })
            .collect();
        // Particle 150: ten neighbours on a line. 151: a NaN sum. 152: five.
        let mut line = Neighbourhood::with_capacity(8);
        for k in -5..5 {
            line.push(0.3 * k as f64, 0.0, 1.0);
        }
        sums.push(line.power_sums());
        let mut nan = sums[40];
        nan[7] = f64::NAN;
        sums.push(nan);
        let mut five = Neighbourhood::with_capacity(8);
        for (r, z) in [
            (0.0, 0.0),
            (0.7, 0.1),
            (-0.2, 0.8),
            (-0.9, -0.3),
            (0.4, -1.1),
        ] {
            five.push(r, z, 1.0);
        }
        sums.push(five.power_sums());
        assert!(invert(moment_matrix(&sums[152])).is_some());
        let (mut checked, mut worst) = (0, 0.0f64);
        for (batch, chunk) in sums.chunks(W).enumerate() {
            let lanes: [Lanes; POWER_SUMS] = std::array::from_fn(|k| {
                std::array::from_fn(|l| chunk.get(l).map_or(0.0, |s| s[k]))
            });
            let (inv, elsewhere) = inverse_moments_lanes(&lanes);
            let norm_b = crate::lanes::norm1(&moment_matrix_lanes(&lanes));
            for (l, s) in chunk.iter().enumerate() {
                let i = batch * W + l;
                let b = moment_matrix(s);
                if i >= p.len() {
                    assert!(elsewhere[l], "lane {l}");
                    continue;
                }
                assert!(!elsewhere[l], "particle {i}");
                let want = invert(b).unwrap();
                assert_eq!(norm_b[l], norm1(&b));
                let scale = want.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
                for r in 0..6 {
                    for c in 0..6 {
                        let d = (inv[r][c][l] - want[r][c]).abs() / scale;
                        worst = worst.max(d);
                        assert!(
                            d <= 1e-12,
                            "particle {i} ({r}, {c}): {} vs {}",
                            inv[r][c][l],
                            want[r][c]
                        );
                    }
                }
                checked += 1;
            }
        }
        assert_eq!(checked, p.len());
        assert!(
            worst > 0.0,
            "two different algorithms agree to the last bit?"
        );
    }

    #[test]
    fn partition_of_unity_and_linear_reproduction() {
        let (p, v, h) = cloud();
        let nl = cell_list(&p, 2.0 * h);
        for i in 0..p.len() {
            let m = Msph2Rows::new(i, nl.of(i), &p, &v, h, [Row2::F, Row2::R, Row2::Z]).unwrap();
            let (mut s0, mut sr, mut sz) = ([0.0; 3], [0.0; 3], [0.0; 3]);
            for &j in nl.of(i) {
                let w = m.weight(p[j], v[j]);
                for k in 0..3 {
                    s0[k] += w[k];
                    sr[k] += w[k] * p[j][0];
                    sz[k] += w[k] * p[j][1];
                }
            }
            // f = 1: value 1, derivatives 0.
            assert!((s0[0] - 1.0).abs() < 1e-10 && s0[1].abs() < 1e-6 && s0[2].abs() < 1e-6);
            // f = R and f = Z.
            assert!((sr[0] - p[i][0]).abs() < 1e-10 && (sr[1] - 1.0).abs() < 1e-8);
            assert!((sz[0] - p[i][1]).abs() < 1e-10 && (sz[2] - 1.0).abs() < 1e-8);
        }
    }

    #[test]
    fn one_dimensional_system_reproduces_quadratics() {
        let d = 0.01;
        let p: Vec<f64> = (0..60).map(|k| k as f64 * d).collect();
        let v: Vec<f64> = p
            .iter()
            .map(|r| 2.0 * std::f64::consts::PI * r.max(d / 4.0) * d)
            .collect();
        let h = 1.5 * d;
        let pts: Vec<[f64; 2]> = p.iter().map(|&r| [r, 0.0]).collect();
        let nl = cell_list(&pts, 2.0 * h);
        for i in 0..p.len() {
            let m = Msph1Rows::new(i, nl.of(i), &p, &v, h, [Row1::F, Row1::R, Row1::Rr]).unwrap();
            let mut e = [0.0; 3];
            for &j in nl.of(i) {
                let w = m.weight(p[j], v[j]);
                let f = 2.0 - 3.0 * p[j] + 5.0 * p[j] * p[j];
                for k in 0..3 {
                    e[k] += w[k] * f;
                }
            }
            let x = p[i];
            assert!((e[0] - (2.0 - 3.0 * x + 5.0 * x * x)).abs() < 1e-9);
            assert!((e[1] - (-3.0 + 10.0 * x)).abs() < 1e-6);
            assert!((e[2] - 10.0).abs() < 1e-4, "{}", e[2]);
        }
    }

    #[test]
    fn gauss_jordan_inverse_equals_nalgebra() {
        let mut uniform = crate::test_rng::rng(99);
        let mut next = || uniform() - 0.5;
        for _ in 0..200 {
            let a: [[f64; 6]; 6] = std::array::from_fn(|_| std::array::from_fn(|_| next()));
            let ours = invert(a).unwrap();
            let m = nalgebra::Matrix6::from_fn(|r, c| a[r][c]);
            let theirs = m.try_inverse().unwrap();
            let scale = theirs.abs().max();
            for r in 0..6 {
                for c in 0..6 {
                    assert!((ours[r][c] - theirs[(r, c)]).abs() < 1e-10 * scale);
                }
            }
        }
        let a3 = [[2.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 4.0]];
        let inv3 = invert(a3).unwrap();
        let theirs = nalgebra::Matrix3::from_fn(|r, c| a3[r][c])
            .try_inverse()
            .unwrap();
        for r in 0..3 {
            for c in 0..3 {
                assert!((inv3[r][c] - theirs[(r, c)]).abs() < 1e-14);
            }
        }
        // A repeated row: singular.
        let sing = [[1.0, 2.0, 3.0], [1.0, 2.0, 3.0], [0.0, 1.0, 5.0]];
        assert!(invert(sing).is_none());
    }

    #[test]
    fn collinear_neighbourhood_is_reported_degenerate() {
        // Points on a line cannot support derivatives across it.
        let p: Vec<[f64; 2]> = (0..10).map(|k| [k as f64 * 0.1, 0.0]).collect();
        let v = vec![1.0; 10];
        let nl = cell_list(&p, 0.3);
        let e = Msph2Rows::new(5, nl.of(5), &p, &v, 0.15, [Row2::R]).unwrap_err();
        assert_eq!(e.particle, 5);
    }
}
