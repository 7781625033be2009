//! Gradients that conform to the nodal quadrature at the surfaces.
//!
//! Direct nodal integration of the Galerkin form ([`crate::approx::nodal`]) gives
//! node `J` the force `F_J = −Σ_i V_i σ_i · ∇φ_J(x_i)`. Under a uniform
//! stress `σ` this is `−σ · a_J` with `a_J = Σ_i V_i ∇φ_J(x_i)`, which must
//! vanish at every node off the boundary for the uniform stress to be in
//! equilibrium (the integration constraint of Chen et al. 2001). MLS
//! gradients at the nodes do not meet it near a surface: on the Wilkins bar
//! the layer above the face and the nodes inside the mantle carry spurious
//! forces of a few per cent of the surface load (VALIDATION.md).
//!
//! The correction changes each gradient `G_iJ = ∇φ_J(x_i)` by the least
//! `δ_iJ` (in the sum of squares) such that
//!
//! - each row still reproduces linear fields: `Σ_J δ_iJ = 0` and
//!   `Σ_J δ_iJ ⊗ (x_J − x_i) = 0`, so the collocated velocity gradient
//!   (eq. 4) stays exact for linear velocities;
//! - `Σ_i V_i (G_iJ + δ_iJ) = 0` at every node `J` that lies on no
//!   surface.
//!
//! By Lagrange multipliers, `δ_iJ = V_i (μ_J − λ_iᵀ p_J)` with
//! `p_J = (1, (x_J − x_i) / h_i)`, `λ_i = M_i⁻¹ Σ_K p_K μ_K` (`M_i = Σ_K p_K
//! p_Kᵀ` over row `i`, `μ_K = 0` on the surfaces), and the multipliers `μ`
//! solve the symmetric positive system `Σ_i V_i δ_iJ(μ) = −a_J` over the
//! inner nodes, by conjugate gradients, preconditioned by Jacobi's
//! diagonal or, as an option, by levels of groups of nodes as well
//! ([`Preconditioner`]; `src/approx/conform_levels.rs`). Each
//! iteration applies the system in two passes, one over the rows (the
//! `λ_i`) and one over the columns, without forming the entries `δ_iJ`
//! (`Fused`; its plain twin, the entries and then their column sums,
//! serves the preconditioner and the final correction, and a test pins the
//! two together). The corrected gradients serve both
//! the velocity gradients and the forces, so the forces stay the adjoint of
//! the stress power.
//!
//! Every sum runs in a fixed order: the same bits for any number of
//! threads.

use crate::approx::buffers::{filled, fit};
use crate::approx::conform_levels::{Fine, Levels};
use crate::approx::mls::NodalShapes;
use crate::approx::nodal::{entry_parts, for_segments, transpose};
use crate::isa::{Isa, hot};
use rayon::prelude::*;

/// Where the solver stops the conjugate gradients: when the largest inner
/// `|a_J|` is below this fraction of the largest `|a_J|` over all nodes.
///
/// Chosen by measurement (docs/notes/2026-11-28-conforming-stop-and-serial.md,
/// docs/notes/2026-11-29-cell-grids-and-the-iterations.md): on `taylor3d`
/// to rest at 6 and 10 nodes across, 1e-4 against 1e-5 moves the length by
/// at most 4.7e-7 and the face radius by at most 1.6e-5 of their values
/// (the scheme's own errors there are 0.1-0.9 %; 1e-5 against 1e-8 moved
/// them by 7.3e-6 and 4.8e-5), and takes 32 iterations a build at 10
/// across against 74 (a run 15 % shorter).
pub const CONFORM_TOLERANCE: f64 = 1e-4;

/// The most conjugate-gradient iterations; past them the correction is
/// the partial one reached ([`Conformed::after`] says how far).
pub const CONFORM_ITERATIONS: usize = 2000;

/// The preconditioner of the conjugate gradients.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Preconditioner {
    /// The diagonal of the system (Jacobi's): the iterations grow as the
    /// spacing shrinks.
    #[default]
    Jacobi,
    /// The diagonal and the levels of groups of nodes
    /// (`src/approx/conform_levels.rs`): the smooth modes too.
    Levels,
}

impl Preconditioner {
    /// Whether this is Jacobi's (the default, which a saved setup omits).
    pub fn is_jacobi(&self) -> bool {
        *self == Preconditioner::Jacobi
    }
}

/// How the conjugate gradients run: where they stop and their
/// preconditioner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stop {
    /// The stop: the largest inner `|a_J|` below this fraction of the
    /// largest `|a_J|` over all nodes ([`CONFORM_TOLERANCE`] in the solver).
    pub tolerance: f64,
    /// The preconditioner.
    pub preconditioner: Preconditioner,
}

#[cfg(test)]
impl Stop {
    /// The stop at `tolerance` with Jacobi's preconditioner.
    pub fn jacobi(tolerance: f64) -> Stop {
        Stop {
            tolerance,
            preconditioner: Preconditioner::Jacobi,
        }
    }
}

/// What the correction did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Conformed {
    /// Conjugate-gradient iterations.
    pub iterations: usize,
    /// The largest `|a_J|` over the inner nodes before (m²).
    pub before: f64,
    /// The largest inner residual of the system at the start of the
    /// iterations: `before` from zero multipliers, less from a warm start
    /// (m²).
    pub start: f64,
    /// The largest `|a_J|` over the inner nodes after (m²).
    pub after: f64,
    /// The groups of each level of the preconditioner (empty with
    /// Jacobi's).
    pub levels: Vec<usize>,
}

/// The entries `(q, i)` of each column `J` of `shapes`
/// ([`crate::approx::nodal::transpose`]).
struct Columns {
    offsets: Vec<usize>,
    entries: Vec<u64>,
}

impl Columns {
    fn of(shapes: &NodalShapes, columns: usize) -> Self {
        let (offsets, entries) = transpose(shapes, columns);
        Columns { offsets, entries }
    }

    /// The entry `q` and the row `i` of the `k`-th entry.
    #[inline(always)]
    fn at(&self, k: usize) -> (usize, usize) {
        entry_parts(self.entries[k])
    }
}

/// `(1, x − centre)`: the linear basis at `x` about `centre`, unscaled
/// (`u_J` of [`System`]).
#[inline(always)]
fn offset(x: [f64; 3], centre: [f64; 3]) -> [f64; 4] {
    [1.0, x[0] - centre[0], x[1] - centre[1], x[2] - centre[2]]
}

/// `(1, (x − centre) / h)`: the linear basis scaled by the row's size, for
/// a well-conditioned moment matrix.
fn basis(x: [f64; 3], centre: [f64; 3], h: f64) -> [f64; 4] {
    [
        1.0,
        (x[0] - centre[0]) / h,
        (x[1] - centre[1]) / h,
        (x[2] - centre[2]) / h,
    ]
}

/// The inverse of a symmetric positive 4 × 4 matrix by Gauss-Jordan with
/// partial pivoting.
fn invert4(m: [[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let mut a = m;
    let mut inv = [[0.0; 4]; 4];
    for (k, row) in inv.iter_mut().enumerate() {
        row[k] = 1.0;
    }
    for c in 0..4 {
        let p = (c..4)
            .max_by(|&x, &y| a[x][c].abs().total_cmp(&a[y][c].abs()))
            .unwrap_or(c);
        a.swap(c, p);
        inv.swap(c, p);
        let d = a[c][c];
        for k in 0..4 {
            a[c][k] /= d;
            inv[c][k] /= d;
        }
        for r in 0..4 {
            if r != c {
                let f = a[r][c];
                for k in 0..4 {
                    a[r][k] -= f * a[c][k];
                    inv[r][k] -= f * inv[c][k];
                }
            }
        }
    }
    inv
}

/// `a · b`, summed on the pool in the fixed order of [`crate::approx::sums`].
fn dot(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    crate::approx::sums::sum(a.len().min(b.len()), |j| {
        let (x, y) = (a[j], b[j]);
        x[0] * y[0] + x[1] * y[1] + x[2] * y[2]
    })
}

fn norm3(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// `e_q = μ_J [J inner] − λ_iᵀ p_J` of one entry `q = (i, J)`, with
/// `p = u_J` in row `i`'s basis and `lambda` = `G_i T_i` ([`System`]).
fn entry(p: [f64; 4], inner: bool, mu: [f64; 3], lambda: &[[f64; 3]; 4]) -> [f64; 3] {
    let own = if inner { mu } else { [0.0; 3] };
    std::array::from_fn(|c| own[c] - (0..4).map(|a| p[a] * lambda[a][c]).sum::<f64>())
}

/// The operator of the multipliers.
///
/// With `u_J = (1, x_J − x_i)` and `D_i = diag(1, 1/h_i, 1/h_i, 1/h_i)`,
/// `p_J = D_i u_J`, so `λ_iᵀ p_J = (G_i T_i)ᵀ u_J` with
/// `G_i = D_i M_i⁻¹ D_i` and `T_i = Σ_K u_K μ_Kᵀ`: the system holds `G_i`
/// (the inverse taken of the scaled, well-conditioned `M_i`), and the
/// iterations divide by nothing.
struct System<'a> {
    shapes: &'a NodalShapes,
    points: &'a [[f64; 3]],
    volume: &'a [f64],
    inner: &'a [bool],
    g: Vec<[[f64; 4]; 4]>,
    columns: &'a Columns,
}

impl<'a> System<'a> {
    /// The system of `shapes` (rows over the first `shapes.len()` of
    /// `points`) with its columns: each row's `G_i`, from the row's size
    /// `h_i` (its farthest node) and `M_i⁻¹`.
    fn new(
        ranks: &dyn crate::ranks::Ranks,
        shapes: &'a NodalShapes,
        points: &'a [[f64; 3]],
        volume: &'a [f64],
        inner: &'a [bool],
        columns: &'a Columns,
    ) -> Self {
        let n = shapes.len();
        let mut g = filled(n, [[0.0; 4]; 4]);
        crate::ranks::each_row(ranks, &mut g, |i, out| {
            *out = {
                let h = shapes
                    .row(i)
                    .map(|q| {
                        let (a, b) = (points[shapes.nodes[q]], points[i]);
                        norm3([a[0] - b[0], a[1] - b[1], a[2] - b[2]])
                    })
                    .fold(0.0, f64::max)
                    .max(f64::MIN_POSITIVE);
                let mut m = [[0.0; 4]; 4];
                for q in shapes.row(i) {
                    let p = basis(points[shapes.nodes[q]], points[i], h);
                    for a in 0..4 {
                        for b in 0..4 {
                            m[a][b] += p[a] * p[b];
                        }
                    }
                }
                let minv = invert4(m);
                let d = [1.0, 1.0 / h, 1.0 / h, 1.0 / h];
                std::array::from_fn(|a| std::array::from_fn(|b| d[a] * minv[a][b] * d[b]))
            };
        });
        System {
            shapes,
            points,
            volume,
            inner,
            g,
            columns,
        }
    }

    /// `G_i T_i` with `T_i = Σ_J u_J μ_Jᵀ` over the inner nodes of row `i`:
    /// `λ_iᵀ p_J = (G_i T_i)ᵀ u_J`. The sum runs in two halves (the
    /// row's even and odd entries, added at the end), four basis values
    /// to a vector: two chains of additions instead of one.
    #[inline(always)]
    fn lambda(&self, i: usize, mu: &[[f64; 3]]) -> [[f64; 3]; 4] {
        let s = self.shapes;
        let xi = self.points[i];
        // t[c][a]: component c of the multipliers, basis value a.
        let add = |t: &mut [[f64; 4]; 3], j: usize| {
            if self.inner[j] {
                let (u, m) = (offset(self.points[j], xi), mu[j]);
                for c in 0..3 {
                    for a in 0..4 {
                        t[c][a] += u[a] * m[c];
                    }
                }
            }
        };
        let (mut even, mut odd) = ([[0.0; 4]; 3], [[0.0; 4]; 3]);
        let pairs = s.nodes[s.row(i)].chunks_exact(2);
        if let [j] = pairs.remainder() {
            add(&mut even, *j);
        }
        for pair in pairs {
            add(&mut even, pair[0]);
            add(&mut odd, pair[1]);
        }
        let g = &self.g[i];
        std::array::from_fn(|a| {
            std::array::from_fn(|c| (0..4).map(|b| g[a][b] * (even[c][b] + odd[c][b])).sum())
        })
    }

    /// `e_q = μ_J [J inner] − λ_iᵀ p_J` for every entry `q = (i, J)`.
    #[cfg(test)]
    fn entries(&self, mu: &[[f64; 3]], e: &mut [[f64; 3]]) {
        let s = self.shapes;
        let rows: Vec<(usize, &mut [[f64; 3]])> = {
            let mut out = Vec::with_capacity(s.len());
            let mut rest = e;
            for i in 0..s.len() {
                let (head, tail) = rest.split_at_mut(s.row(i).len());
                out.push((i, head));
                rest = tail;
            }
            out
        };
        rows.into_par_iter().for_each(|(i, out)| {
            let xi = self.points[i];
            let lambda = self.lambda(i, mu);
            for (k, q) in s.row(i).enumerate() {
                let j = s.nodes[q];
                let p = offset(self.points[j], xi);
                out[k] = entry(p, self.inner[j], mu[j], &lambda);
            }
        });
    }

    /// The Jacobi preconditioner `A_JJ = Σ_i V_i² (1 − p_Jᵀ M_i⁻¹ p_J)`
    /// (`p_Jᵀ M_i⁻¹ p_J = u_Jᵀ G_i u_J`)
    /// (inner `J` only; the same three values for each axis): the sums of
    /// [`System::gather`] with power 2 over the entries `1 − p_Jᵀ M_i⁻¹ p_J`,
    /// each computed where it is summed (no buffer of `3 nnz` values).
    fn diagonal(&self, ranks: &dyn crate::ranks::Ranks) -> Vec<[f64; 3]> {
        let c = self.columns;
        let mut out = filled(self.shapes.len(), [0.0; 3]);
        crate::ranks::each_row(ranks, &mut out, |j, yj| {
            *yj = [0.0; 3];
            if !self.inner[j] {
                return;
            }
            for k in c.offsets[j]..c.offsets[j + 1] {
                let i = c.at(k).1;
                let p = offset(self.points[j], self.points[i]);
                let m = &self.g[i];
                let pmp: f64 = (0..4)
                    .map(|x| (0..4).map(|y| p[x] * m[x][y] * p[y]).sum::<f64>())
                    .sum();
                let v = self.volume[i].powi(2);
                for d in yj.iter_mut() {
                    *d += v * (1.0 - pmp);
                }
            }
        });
        out
    }

    /// `y_J = Σ_i V_i^power w_q` over column `J` (inner `J` only).
    #[cfg(test)]
    fn gather(&self, w: &[[f64; 3]], power: i32, y: &mut [[f64; 3]]) {
        let c = &self.columns;
        y.par_iter_mut().enumerate().for_each(|(j, yj)| {
            *yj = [0.0; 3];
            if !self.inner[j] {
                return;
            }
            for k in c.offsets[j]..c.offsets[j + 1] {
                let (q, i) = c.at(k);
                let v = self.volume[i].powi(power);
                for d in 0..3 {
                    yj[d] += v * w[q][d];
                }
            }
        });
    }
}

/// The operator `A μ` of the multipliers in two passes, without the
/// entries: with `D_J = Σ_i V_i²` over column `J` (inner `J`) and
/// `w_i = V_i² λ_i(μ)` per row,
/// `(A μ)_J = [J inner] (D_J μ_J − Σ_i p_iJᵀ w_i)`: the same sums as
/// [`System::entries`] followed by [`System::gather`] (its plain twin; a
/// test pins the two), in another order, with no buffer of `3 nnz` values
/// written and read back.
struct Fused {
    /// `D_J` (zero off the inner nodes).
    diag: Vec<f64>,
    /// The rows whose `w_i` this rank's columns read (every row alone):
    /// each rank computes those itself rather than receive them.
    rows: std::ops::Range<usize>,
    /// `w_i` (4 × 3 per row, each basis value's three components padded
    /// to four: one vector).
    w: Vec<[[f64; 4]; 4]>,
}

impl Fused {
    fn new(ranks: &dyn crate::ranks::Ranks, sys: &System) -> Self {
        let c = sys.columns;
        let mut diag = filled(sys.shapes.len(), 0.0);
        crate::ranks::each_row(ranks, &mut diag, |j, d| {
            *d = if !sys.inner[j] {
                0.0
            } else {
                (c.offsets[j]..c.offsets[j + 1])
                    .map(|k| sys.volume[c.at(k).1].powi(2))
                    .sum()
            };
        });
        let n = sys.shapes.len();
        let rows = if ranks.size() == 1 {
            0..n
        } else {
            // The rows of the entries of this rank's inner columns.
            let own = crate::ranks::share(n, ranks.rank(), ranks.size(), ROWS);
            let (lo, hi) = own
                .into_par_iter()
                .filter(|&j| sys.inner[j])
                .flat_map_iter(|j| (c.offsets[j]..c.offsets[j + 1]).map(|k| c.at(k).1))
                .fold(|| (usize::MAX, 0), |(lo, hi), i| (lo.min(i), hi.max(i + 1)))
                .reduce(|| (usize::MAX, 0), |a, b| (a.0.min(b.0), a.1.max(b.1)));
            lo.min(hi)..hi
        };
        Fused {
            diag,
            rows,
            w: filled(n, [[0.0; 4]; 4]),
        }
    }

    /// `y = A mu`, in the compiled copy `isa` (every copy gives the same
    /// bits: [`crate::isa`]).
    #[cfg(test)]
    fn apply(&mut self, isa: Isa, sys: &System, mu: &[[f64; 3]], y: &mut [[f64; 3]]) {
        self.apply_on(&crate::ranks::Alone, isa, sys, mu, y);
    }

    /// [`Fused::apply`] shared among `ranks`: each computes the rows its
    /// columns read ([`Fused::rows`]: its own share's and the rows about
    /// it; no rows travel), then its share of the columns (whole tasks of
    /// [`ROWS`]), and the columns are gathered (the same bits on any
    /// number of ranks).
    fn apply_on(
        &mut self,
        ranks: &dyn crate::ranks::Ranks,
        isa: Isa,
        sys: &System,
        mu: &[[f64; 3]],
        y: &mut [[f64; 3]],
    ) {
        let n = self.w.len();
        let parts = if ranks.size() == 1 {
            Vec::new()
        } else {
            crate::ranks::shares(ranks, n, ROWS)
        };
        let own = parts.get(ranks.rank()).cloned().unwrap_or(0..n);
        let rows = self.rows.clone();
        let start = rows.start;
        self.w[rows]
            .par_chunks_mut(ROWS)
            .enumerate()
            .for_each(|(k, w)| row_pass(isa, sys, mu, start + k * ROWS, w));
        let first = own.start;
        let (diag, w) = (&self.diag[..], &self.w[..]);
        y[own]
            .par_chunks_mut(ROWS)
            .enumerate()
            .for_each(|(k, y)| column_pass(isa, sys, diag, w, mu, first + k * ROWS, y));
        if !parts.is_empty() {
            crate::ranks::gather_parts(ranks, &parts, y);
        }
    }
}

/// Rows (and columns) per task of [`Fused::apply`].
const ROWS: usize = 256;

hot! {
    /// `w_i = V_i² λ_i(μ)` for the rows `first..first + w.len()`: the
    /// first pass of [`Fused::apply`].
    fn row_pass(sys: &System<'_>, mu: &[[f64; 3]], first: usize, w: &mut [[[f64; 4]; 4]]) {
        for (i, wi) in (first..).zip(w.iter_mut()) {
            let (lambda, v2) = (sys.lambda(i, mu), sys.volume[i].powi(2));
            *wi = std::array::from_fn(|a| {
                let l = lambda[a];
                [v2 * l[0], v2 * l[1], v2 * l[2], 0.0]
            });
        }
    }
}

hot! {
    /// `y_J = [J inner] (D_J μ_J − Σ_i u_iJᵀ w_i)` for the columns
    /// `first..first + y.len()`: the second pass of [`Fused::apply`]. The
    /// sum runs in two halves (the column's even and odd entries, added at
    /// the end), the three components (and a padding lane) in one vector.
    fn column_pass(
        sys: &System<'_>,
        diag: &[f64],
        w: &[[[f64; 4]; 4]],
        mu: &[[f64; 3]],
        first: usize,
        y: &mut [[f64; 3]],
    ) {
        let c = sys.columns;
        for (j, yj) in (first..).zip(y.iter_mut()) {
            *yj = [0.0; 3];
            if !sys.inner[j] {
                continue;
            }
            let xj = sys.points[j];
            let add = |t: &mut [f64; 4], e: u64| {
                let i = entry_parts(e).1;
                let (p, wi) = (offset(xj, sys.points[i]), &w[i]);
                for l in 0..4 {
                    t[l] += (p[0] * wi[0][l] + p[1] * wi[1][l]) + (p[2] * wi[2][l] + p[3] * wi[3][l]);
                }
            };
            let (mut even, mut odd) = ([0.0; 4], [0.0; 4]);
            let pairs = c.entries[c.offsets[j]..c.offsets[j + 1]].chunks_exact(2);
            if let [e] = pairs.remainder() {
                add(&mut even, *e);
            }
            for pair in pairs {
                add(&mut even, pair[0]);
                add(&mut odd, pair[1]);
            }
            *yj = std::array::from_fn(|d| diag[j] * mu[j][d] - (even[d] + odd[d]));
        }
    }
}

/// Corrects the gradients of `shapes` (rows over the first
/// `shapes.len()` of `points`, with the nodal volumes `volume`) so that
/// `Σ_i V_i ∇φ_J(x_i) = 0` at every node `J` with `inner[J]`, keeping
/// every row linearly exact (module docs). Stops when the largest inner
/// `|a_J|` is below `stop.tolerance` times the largest `|a_J|` over all
/// nodes.
///
/// `mu` holds the multipliers the iterations start from (one per node;
/// any other length starts from zero) and returns the solution. The
/// solver starts each build from the last build's multipliers: the nodes
/// have moved little between builds, so the system's solution has too
/// (on `taylor3d` at 10 across the start's residual is on average a sixth
/// of the cold one, from 0.02 to 0.93 of it).
pub fn conform(
    (isa, ranks): (Isa, &dyn crate::ranks::Ranks),
    shapes: &mut NodalShapes,
    points: &[[f64; 3]],
    volume: &[f64],
    inner: &[bool],
    stop: Stop,
    mu: &mut Vec<[f64; 3]>,
) -> Conformed {
    let Stop {
        tolerance,
        preconditioner,
    } = stop;
    let n = shapes.len();
    // The sparsity is the same before and after: one transpose serves both.
    let columns = Columns::of(shapes, n);
    let sys = System::new(ranks, shapes, points, volume, inner, &columns);
    // a_J over every node, for the scale of the stop.
    let mut a = filled(n, [0.0; 3]);
    {
        let c = &sys.columns;
        crate::ranks::each_row(ranks, &mut a, |j, aj| {
            for k in c.offsets[j]..c.offsets[j + 1] {
                let (q, i) = c.at(k);
                for d in 0..3 {
                    aj[d] += volume[i] * shapes.grad[q][d];
                }
            }
        });
    }
    let largest = a.par_iter().map(|&v| norm3(v)).reduce(|| 0.0, f64::max);
    // The loops of the conjugate gradients run on the pool: each entry is
    // its own, and a largest value is the same in any order; only the dot
    // products stay in order (their sums would move the bits).
    let inner_max = |r: &[[f64; 3]]| {
        (0..n)
            .into_par_iter()
            .filter(|&j| inner[j])
            .map(|j| norm3(r[j]))
            .reduce(|| 0.0, f64::max)
    };
    let before = inner_max(&a);
    let goal = tolerance * largest;
    // Jacobi preconditioner: A_JJ = Σ_i V_i² (1 − p_Jᵀ M_i⁻¹ p_J).
    let diag = sys.diagonal(ranks);
    let mut fused = Fused::new(ranks, &sys);
    let levels = match preconditioner {
        Preconditioner::Jacobi => None,
        Preconditioner::Levels => {
            let jacobi: Vec<f64> = diag.par_iter().map(|d| d[0]).collect();
            Levels::new(
                &Fine {
                    shapes: sys.shapes,
                    points,
                    volume,
                    inner,
                    g: &sys.g,
                    col_offsets: &columns.offsets,
                    col_entries: &columns.entries,
                    d: &fused.diag,
                    ranks,
                },
                jacobi,
            )
        }
    };
    let precond = |r: &[[f64; 3]], z: &mut [[f64; 3]]| match &levels {
        Some(l) => l.apply(r, z),
        None => z.par_iter_mut().enumerate().for_each(|(j, zj)| {
            *zj = if inner[j] && diag[j][0] > 0.0 {
                std::array::from_fn(|d| r[j][d] / diag[j][d])
            } else {
                [0.0; 3]
            };
        }),
    };
    // r = b − A μ: b_J = −a_J on the inner nodes (and A μ = 0 when the
    // start is zero).
    if mu.len() != n {
        mu.clear();
        fit(mu, n, [0.0; 3]);
    }
    let mut r: Vec<[f64; 3]> = (0..n)
        .into_par_iter()
        .map(|j| {
            if inner[j] {
                [-a[j][0], -a[j][1], -a[j][2]]
            } else {
                [0.0; 3]
            }
        })
        .collect();
    let mut ap = filled(n, [0.0; 3]);
    if mu.par_iter().any(|m| m.iter().any(|&m| m != 0.0)) {
        fused.apply_on(ranks, isa, &sys, mu, &mut ap);
        let warm: Vec<[f64; 3]> = r
            .par_iter()
            .zip(&ap)
            .map(|(r, ap)| std::array::from_fn(|d| r[d] - ap[d]))
            .collect();
        // A start no better than zero (or not finite: a garbled saved
        // state) is dropped.
        if warm.par_iter().all(|w| w.iter().all(|x| x.is_finite())) && inner_max(&warm) < before {
            r = warm;
        } else {
            mu.par_iter_mut().for_each(|m| *m = [0.0; 3]);
        }
    }
    let start = inner_max(&r);
    let mut z = filled(n, [0.0; 3]);
    precond(&r, &mut z);
    let mut p: Vec<[f64; 3]> = z.par_iter().copied().collect();
    let mut rz = dot(&r, &z);
    let mut iterations = 0;
    let flexible = levels.as_ref().is_some_and(|l| !l.linear());
    while inner_max(&r) > goal && iterations < CONFORM_ITERATIONS {
        fused.apply_on(ranks, isa, &sys, &p, &mut ap);
        let pap = dot(&p, &ap);
        if pap <= 0.0 {
            break;
        }
        let alpha = rz / pap;
        (&mut mu[..], &mut r, &p, &ap)
            .into_par_iter()
            .for_each(|(mu, r, p, ap)| {
                for d in 0..3 {
                    mu[d] += alpha * p[d];
                    r[d] -= alpha * ap[d];
                }
            });
        precond(&r, &mut z);
        let rz_new = dot(&r, &z);
        // A preconditioner that is not one linear map (the levels' inner
        // iterations) needs the flexible form of β (Polak-Ribière's, with
        // the change of the residual: Notay 2000),
        // With r_old = r + α A p: β = −α (A p · z) / rz.
        let beta = if flexible {
            -alpha * dot(&ap, &z) / rz
        } else {
            rz_new / rz
        };
        rz = rz_new;
        p.par_iter_mut().zip(&z).for_each(|(p, z)| {
            for d in 0..3 {
                p[d] = z[d] + beta * p[d];
            }
        });
        iterations += 1;
    }
    drop(fused);
    let levels = levels.map(|l| l.sizes()).unwrap_or_default();
    // g_q += V_i e_q, row by row in place (no buffer of the 3 nnz e_q):
    // the λ_i first, while the system holds the shapes.
    // Shared among the ranks: each corrects the rows of its share, the
    // rows' entries are gathered, and each measures its share of the
    // columns (the largest over the ranks' largest).
    let parts = if ranks.size() == 1 {
        Vec::new()
    } else {
        crate::ranks::shares(ranks, n, ROWS)
    };
    let own = parts.get(ranks.rank()).cloned().unwrap_or(0..n);
    let lambda: Vec<[[f64; 3]; 4]> = own
        .clone()
        .into_par_iter()
        .map(|i| sys.lambda(i, mu))
        .collect();
    let (offsets, nodes) = (&shapes.offsets, &shapes.nodes);
    let first = own.start;
    for_segments(
        &mut shapes.grad,
        &offsets[own.start..=own.end],
        &|k, grad| {
            let i = first + k;
            let v = volume[i];
            for (g, q) in grad.iter_mut().zip(offsets[i]..offsets[i + 1]) {
                let j = nodes[q];
                let p = offset(points[j], points[i]);
                let e = entry(p, inner[j], mu[j], &lambda[k]);
                for d in 0..3 {
                    g[d] += v * e[d];
                }
            }
        },
    );
    if !parts.is_empty() {
        let entries: Vec<std::ops::Range<usize>> = parts
            .iter()
            .map(|r| shapes.offsets[r.start]..shapes.offsets[r.end])
            .collect();
        crate::ranks::gather_parts(ranks, &entries, &mut shapes.grad);
    }
    // The constraint after, measured afresh (the largest is the same in
    // any order).
    let cols = &columns;
    let grad = &shapes.grad;
    let after = own
        .clone()
        .into_par_iter()
        .filter(|&j| inner[j])
        .map(|j| {
            let mut s = [0.0; 3];
            for k in cols.offsets[j]..cols.offsets[j + 1] {
                let (q, i) = cols.at(k);
                for d in 0..3 {
                    s[d] += volume[i] * grad[q][d];
                }
            }
            norm3(s)
        })
        .reduce(|| 0.0, f64::max);
    let after = crate::ranks::all_max_f64(ranks, after);
    Conformed {
        iterations,
        before,
        start,
        after,
        levels,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::approx::lattice::{Cylinder, NodeLattice};
    use crate::approx::mls::{SupportParams, Supports};
    use crate::approx::nodal::NodalOperator;

    /// The largest force on a node off the surfaces under a uniform stress
    /// (1 Pa in every component), relative to a face node's load `Δ²`.
    fn inner_force(shapes: &NodalShapes, lat: &NodeLattice) -> f64 {
        let n = shapes.len();
        let op = NodalOperator::build(shapes, n);
        let mut f = vec![[0.0; 3]; n];
        op.apply(&vec![[1.0; 6]; n], &lat.volume, &mut f);
        let area = lat.radial_spacing * lat.radial_spacing;
        (0..n)
            .filter(|&j| lat.surfaces[j].interior())
            .map(|j| norm3(f[j]) / area)
            .fold(0.0, f64::max)
    }

    /// The fused operator of the conjugate gradients is its plain twin
    /// (the entries, then the column sums) to round-off, on a 4-ring rod
    /// with pseudo-random multipliers, and each compiled copy of it gives
    /// the same bits.
    #[test]
    fn the_fused_operator_is_the_plain_one() {
        let lat = NodeLattice::cylinder_with(
            Cylinder {
                radius: 0.0032,
                length: 0.0324,
            },
            4,
            true,
        );
        let pts = &lat.position;
        let sup = Supports::compute(pts, SupportParams::default()).unwrap();
        let shapes = NodalShapes::build(pts, &sup).unwrap();
        let n = shapes.len();
        let inner: Vec<bool> = lat.surfaces.iter().map(|s| s.interior()).collect();
        let columns = Columns::of(&shapes, n);
        let sys = System::new(
            &crate::ranks::Alone,
            &shapes,
            pts,
            &lat.volume,
            &inner,
            &columns,
        );
        let mut uniform = crate::test_rng::rng(11);
        let mu: Vec<[f64; 3]> = (0..n)
            .map(|_| std::array::from_fn(|_| uniform() - 0.5))
            .collect();
        let mut e = vec![[0.0; 3]; shapes.nodes.len()];
        sys.entries(&mu, &mut e);
        let mut plain = vec![[0.0; 3]; n];
        sys.gather(&e, 2, &mut plain);
        let mut fused = vec![[0.0; 3]; n];
        Fused::new(&crate::ranks::Alone, &sys).apply(Isa::BASELINE, &sys, &mu, &mut fused);
        // Every compiled copy gives the baseline's bits.
        for isa in Isa::available() {
            let mut copy = vec![[0.0; 3]; n];
            Fused::new(&crate::ranks::Alone, &sys).apply(isa, &sys, &mu, &mut copy);
            assert_eq!(copy, fused, "the {} copy", isa.name());
        }
        let scale = plain.iter().map(|&v| norm3(v)).fold(0.0, f64::max);
        assert!(scale > 0.0);
        for j in 0..n {
            let d = norm3(std::array::from_fn(|k| fused[j][k] - plain[j][k]));
            assert!(
                d < 1e-12 * scale,
                "node {j}: {:?} against {:?}",
                fused[j],
                plain[j]
            );
        }
    }

    /// On the ring lattice of a rod (4 rings): the plain MLS gradients
    /// leave nodes off the surfaces with a force under a uniform stress
    /// (measured up to 1.30 Δ² under 1 Pa in every component, Δ the
    /// radial spacing: more than a face node's load); the corrected ones
    /// leave none, to round-off, and every row still reproduces linear
    /// fields exactly.
    #[test]
    fn the_inner_nodes_carry_no_load_of_a_uniform_stress_and_rows_stay_linear() {
        let lat = NodeLattice::cylinder(
            Cylinder {
                radius: 0.0032,
                length: 0.0324,
            },
            4,
        );
        let pts = &lat.position;
        let sup = Supports::compute(pts, SupportParams::default()).unwrap();
        let mut shapes = NodalShapes::build(pts, &sup).unwrap();
        let plain = inner_force(&shapes, &lat);
        let inner: Vec<bool> = lat.surfaces.iter().map(|s| s.interior()).collect();
        let c = conform(
            (Isa::best(), &crate::ranks::Alone),
            &mut shapes,
            pts,
            &lat.volume,
            &inner,
            Stop::jacobi(1e-12),
            &mut Vec::new(),
        );
        let corrected = inner_force(&shapes, &lat);
        assert!(plain > 0.1, "plain {plain:e}");
        assert!(corrected < 1e-9, "corrected {corrected:e} ({c:?})");
        assert!(c.after < 1e-9 * c.before, "{c:?}");
        let h = lat.radial_spacing;
        for i in 0..shapes.len() {
            let mut s0 = [0.0; 3];
            let mut s1 = [[0.0; 3]; 3];
            for q in shapes.row(i) {
                let (g, x) = (shapes.grad[q], pts[shapes.nodes[q]]);
                for a in 0..3 {
                    s0[a] += g[a];
                    for b in 0..3 {
                        s1[a][b] += x[a] * g[b];
                    }
                }
            }
            for a in 0..3 {
                assert!(s0[a].abs() * h < 1e-10, "row {i}: {s0:?}");
                for b in 0..3 {
                    let want = if a == b { 1.0 } else { 0.0 };
                    assert!((s1[a][b] - want).abs() < 1e-10, "row {i}: {s1:?}");
                }
            }
        }
    }

    /// A warm start: the rod deformed smoothly as between two builds of a
    /// Taylor impact (shortened by 1 %, its foot widened by up to 2 %) and
    /// solved from the multipliers of the rod as it was. It starts from a smaller residual, takes
    /// fewer iterations than from zero and meets the same stop; from the
    /// solution itself it takes none.
    #[test]
    fn a_warm_start_meets_the_stop_in_fewer_iterations() {
        let lat = NodeLattice::cylinder(
            Cylinder {
                radius: 0.0032,
                length: 0.0324,
            },
            4,
        );
        let inner: Vec<bool> = lat.surfaces.iter().map(|s| s.interior()).collect();
        let tol = CONFORM_TOLERANCE;
        // The supports of the rod as it was, as the solver keeps them
        // between their recomputations.
        let sup = Supports::compute(&lat.position, SupportParams::default()).unwrap();
        let solve = |pts: &[[f64; 3]], mu: &mut Vec<[f64; 3]>| {
            let mut shapes = NodalShapes::build(pts, &sup).unwrap();
            let c = conform(
                (Isa::best(), &crate::ranks::Alone),
                &mut shapes,
                pts,
                &lat.volume,
                &inner,
                Stop::jacobi(tol),
                mu,
            );
            (c, inner_force(&shapes, &lat))
        };
        let mut mu = Vec::new();
        let (first, _) = solve(&lat.position, &mut mu);
        assert_eq!(first.start, first.before, "{first:?}");
        let mut again = mu.clone();
        let (same, _) = solve(&lat.position, &mut again);
        assert_eq!(same.iterations, 0, "{same:?}");
        let moved: Vec<[f64; 3]> = lat
            .position
            .iter()
            .map(|x| {
                let widen = 1.0 + 0.02 * (-3.0 * x[2] / 0.0324).exp();
                [x[0] * widen, x[1] * widen, 0.99 * x[2]]
            })
            .collect();
        let (cold, cold_force) = solve(&moved, &mut Vec::new());
        let (warm, warm_force) = solve(&moved, &mut mu);
        assert!(warm.start < 0.5 * cold.start, "{warm:?} against {cold:?}");
        assert!(
            warm.iterations < cold.iterations,
            "{warm:?} against {cold:?}"
        );
        // Both meet the stop: the inner nodes' load under a uniform stress,
        // over 1 Δ² under 1 Pa (1.30 before the correction), is the inner
        // residual, at most the stop times the largest |a_J| (a surface
        // node's, a few Δ²): measured 2.41 and 2.38 times the stop from
        // zero and from the warm start (and below 1e-4 at a stop of 1e-5).
        assert!(
            cold_force < 10.0 * tol && warm_force < 10.0 * tol,
            "{cold_force:e} {warm_force:e}"
        );
        // A start that is not finite, or worse than zero, is dropped: the
        // same bits as from zero.
        for bad in [f64::NAN, 1e300] {
            let mut start = vec![[bad; 3]; lat.position.len()];
            let (c, force) = solve(&moved, &mut start);
            assert_eq!((c, force), (cold.clone(), cold_force), "start {bad:e}");
        }
    }

    /// The corrected gradients of a rod of `rings` rings (the staggered
    /// lattice of `taylor3d`) solved from zero to `tol` with
    /// `preconditioner`, on a pool of `threads` threads.
    fn solved(
        rings: usize,
        tol: f64,
        preconditioner: Preconditioner,
        threads: usize,
    ) -> (Conformed, Vec<[f64; 3]>) {
        let lat = NodeLattice::cylinder_with(
            Cylinder {
                radius: 0.0032,
                length: 0.0324,
            },
            rings,
            true,
        );
        let pts = &lat.position;
        let sup = Supports::compute(pts, SupportParams::default()).unwrap();
        let mut shapes = NodalShapes::build(pts, &sup).unwrap();
        let inner: Vec<bool> = lat.surfaces.iter().map(|s| s.interior()).collect();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let c = pool.install(|| {
            conform(
                (Isa::best(), &crate::ranks::Alone),
                &mut shapes,
                pts,
                &lat.volume,
                &inner,
                Stop {
                    tolerance: tol,
                    preconditioner,
                },
                &mut Vec::new(),
            )
        });
        (c, shapes.grad)
    }

    /// The levels: on the rods of `taylor3d` at 6 and 10 nodes across
    /// (one level of 44 groups; two levels, of 336 and 44 groups, the first
    /// solved by flexible iterations), solved tightly they give Jacobi's
    /// gradients (the same system's solution) to 1e-9 of the largest; at
    /// the solver's stop they take at most 1.5 times the iterations at 10
    /// across as at 6 (measured 16 and 11; Jacobi's 66 and 29), fewer
    /// than a third of Jacobi's, and the same bits on one thread and two.
    #[test]
    fn the_levels_solve_the_system_in_iterations_that_do_not_grow() {
        for rings in [5, 9] {
            let (jacobi, g_jacobi) = solved(rings, 1e-10, Preconditioner::Jacobi, 2);
            let (levels, g_levels) = solved(rings, 1e-10, Preconditioner::Levels, 2);
            assert!(
                !levels.levels.is_empty() && jacobi.levels.is_empty(),
                "{levels:?}"
            );
            let scale = g_jacobi.iter().map(|&g| norm3(g)).fold(0.0, f64::max);
            for (q, (a, b)) in g_jacobi.iter().zip(&g_levels).enumerate() {
                let d = norm3(std::array::from_fn(|k| a[k] - b[k]));
                assert!(d < 1e-9 * scale, "entry {q}: {a:?} against {b:?}");
            }
        }
        let (six, _) = solved(5, CONFORM_TOLERANCE, Preconditioner::Levels, 2);
        let (ten, g2) = solved(9, CONFORM_TOLERANCE, Preconditioner::Levels, 2);
        let (ten_jacobi, _) = solved(9, CONFORM_TOLERANCE, Preconditioner::Jacobi, 2);
        assert_eq!(six.levels.len(), 1, "{six:?}");
        assert_eq!(ten.levels.len(), 2, "{ten:?}");
        assert!(
            2 * ten.iterations <= 3 * six.iterations,
            "{ten:?} against {six:?}"
        );
        assert!(
            3 * ten.iterations < ten_jacobi.iterations,
            "{ten:?} against {ten_jacobi:?}"
        );
        let (_, g1) = solved(9, CONFORM_TOLERANCE, Preconditioner::Levels, 1);
        assert!(
            g1.iter()
                .zip(&g2)
                .all(|(a, b)| a.map(f64::to_bits) == b.map(f64::to_bits))
        );
    }
}
