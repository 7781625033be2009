//! Moving least squares (MLS) interpolation, eq. (1) of the seed, with the
//! linear basis `p = [1, x, y, z]` (m = 4, eq. (11) with t = 1) and the
//! quartic spline weight of Atluri & Zhu (1998) (the seed names no weight;
//! this is the one of its reference Atluri (2004)):
//!
//! `W(s) = 1 − 6 s² + 8 s³ − 3 s⁴` for `s = |x − x_J| / r_J ≤ 1`, else 0.
//!
//! # Support sizes (seed section 3.1)
//!
//! Each node `I` names its `k` nearest other nodes as its neighbours. The
//! support radius of a node `J` is the scale factor times the largest
//! distance from `J` to a node that names it (or to its own `k`-th
//! nearest, whichever is larger): so at every node, at least `k + 1`
//! supports (its own and those of its `k` named neighbours) cover it, as
//! eq. (11) asks for `k + 1 ≥ m`. A node whose `k` nearest lie in a plane
//! through it (nodes held in a symmetry plane can crowd so) names further
//! nodes, nearest first, until one lies off the plane, so that the supports
//! covering it are not all centred in that plane ([`supports::spanning`]).
//! [`Supports::recompute_reason`] says when the supports are recomputed.
//!
//! # The choice of `k` and the factor, by measurement
//!
//! RMS error of the collocated gradient (eq. 4) of a quadratic velocity
//! field on the unit cube jittered by 0.3 h, over the nodes in [0.3, 0.7]³,
//! relative to the largest gradient, and the mean number of nodes covering
//! a node (the cost of every MLS evaluation is proportional to it;
//! `approx::measure::the_default_supports_are_the_tables_choice`):
//!
//! | k | factor | h = 1/8 | h = 1/16 | covering |
//! |---|---|---|---|---|
//! | 6 | 1.5 | 1.25e-2 | 5.76e-3 | 23.8 |
//! | 6 | 2.0 | 7.25e-3 | 3.20e-3 | 55.1 |
//! | 10 | 1.25 | 1.29e-2 | 6.32e-3 | 22.5 |
//! | 10 | 1.5 | 1.05e-2 | 4.43e-3 | 37.1 |
//! | 10 | 2.0 | 6.97e-3 | 2.43e-3 | 83.6 |
//! | 14 | 1.5 | 9.68e-3 | 3.54e-3 | 53.1 |
//! | 18 | 1.5 | 7.87e-3 | 3.03e-3 | 69.5 |
//! | 26 | 1.5 | 6.97e-3 | 2.39e-3 | 103.5 |
//!
//! The error depends weakly on the choice (within a factor 2 over a
//! five-fold range of cost); the factor also sets the margin for motion
//! between recomputations (pairs may stretch by `(1 + factor)/2`). Chosen:
//! `k = 10`, factor 1.5 ([`SupportParams::default`]): 37 covering nodes,
//! within 1.25× the error of `k = 14` at 70 % of its cost, and a 25 %
//! stretch before recomputing.
//!
//! # Shape functions
//!
//! With the basis centred at the evaluation point `x` and scaled by a length
//! `h` (the largest covering support), `A = Σ w_J p_J p_Jᵀ`,
//! `γ = A⁻¹ e₁`, `φ_J = w_J γ·p_J`, and
//! `∂φ_J/∂x_k = w_J γ_k·p_J + ∂w_J/∂x_k γ·p_J` with
//! `γ_k = A⁻¹ (e_{k+1} / h − A_{,k} γ)`. A moment matrix that is singular
//! or whose 1-norm condition number passes [`crate::approx::msph::MAX_CONDITION`]
//! (too few, coplanar or collinear covering nodes) is the named error
//! [`crate::Error::SingularMomentMatrix`], never a NaN.

use crate::approx::buffers::refill;
use crate::approx::msph::{MAX_CONDITION, invert};
use crate::isa::{Isa, hot};
use crate::{Error, Result};
use rayon::prelude::*;

mod covers;
mod nearest;
mod supports;
pub(crate) use covers::Covers;
#[cfg(test)]
use supports::Recompute;
#[cfg(test)]
use supports::spanning_count;
pub use supports::{SupportParams, Supports, candidates_first};

/// Number of basis functions of the linear basis in 3-D, eq. (11), t = 1.
pub const BASIS: usize = 4;

/// The quartic spline weight `W(s)` and `W'(s) / s` (finite at s = 0), for
/// `s = d / r` (zero outside the support).
#[inline]
pub fn quartic_spline(s: f64) -> (f64, f64) {
    if s >= 1.0 {
        return (0.0, 0.0);
    }
    let t = 1.0 - s;
    (1.0 - s * s * (6.0 - 8.0 * s + 3.0 * s * s), -12.0 * t * t)
}

/// Euclidean distance.
#[inline]
pub fn distance(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

/// The MLS shape functions at one point: the covering nodes, `φ_J` and,
/// when asked for, `∇φ_J`. The buffers are reused between points.
#[derive(Debug, Clone, Default)]
pub struct ShapeRow {
    /// Covering nodes, in the order of the candidates given.
    pub nodes: Vec<usize>,
    /// Position of each covering node in the candidate list.
    pub slot: Vec<usize>,
    /// `φ_J(x)`.
    pub phi: Vec<f64>,
    /// `∂φ_J/∂x_k (x)` (empty unless gradients were asked for).
    pub grad: Vec<[f64; 3]>,
    basis: Vec<[f64; BASIS]>,
    weight: Vec<f64>,
    dweight: Vec<[f64; 3]>,
}

impl ShapeRow {
    /// Evaluates the shape functions at `x` over the `candidates` (node
    /// indices; those whose support covers `x` are kept). `node` labels
    /// the error. Fails with [`Error::SingularMomentMatrix`] (time 0: the
    /// caller knows the clock) when fewer than 4 supports cover `x` or the
    /// moment matrix is singular or too ill-conditioned.
    pub fn evaluate(
        &mut self,
        x: [f64; 3],
        candidates: &[usize],
        points: &[[f64; 3]],
        radius: &[f64],
        gradient: bool,
        node: usize,
    ) -> Result<()> {
        self.nodes.clear();
        self.slot.clear();
        self.phi.clear();
        self.grad.clear();
        self.basis.clear();
        self.weight.clear();
        self.dweight.clear();
        let mut h = 0.0f64;
        for (slot, &j) in candidates.iter().enumerate() {
            let r = radius[j];
            let (d, s) = scaled_offset(x, points[j], r);
            if s < 1.0 {
                let (w, dw_s) = quartic_spline(s);
                self.nodes.push(j);
                self.slot.push(slot);
                self.weight.push(w);
                // ∂w/∂x_k = W'(s)/s · s_{,k}·s = (W'(s)/s) d_k / r².
                let c = dw_s / (r * r);
                self.dweight.push([c * d[0], c * d[1], c * d[2]]);
                h = h.max(r);
            }
        }
        let singular = |condition| Error::SingularMomentMatrix {
            method: crate::error::MomentMethod::Mls,
            particle: node,
            time: 0.0,
            condition,
        };
        if self.nodes.len() < BASIS {
            return Err(singular(f64::INFINITY));
        }
        let mut a = [[0.0; BASIS]; BASIS];
        for &j in &self.nodes {
            let p = [
                1.0,
                (points[j][0] - x[0]) / h,
                (points[j][1] - x[1]) / h,
                (points[j][2] - x[2]) / h,
            ];
            self.basis.push(p);
        }
        for (p, &w) in self.basis.iter().zip(&self.weight) {
            add_outer(&mut a, p, w);
        }
        let inv = invert(a).ok_or_else(|| singular(f64::INFINITY))?;
        let condition = norm1(&a) * norm1(&inv);
        if !condition.is_finite() || condition > MAX_CONDITION {
            return Err(singular(condition));
        }
        let gamma: [f64; BASIS] = std::array::from_fn(|r| inv[r][0]);
        for (p, &w) in self.basis.iter().zip(&self.weight) {
            self.phi.push(w * dot(&gamma, p));
        }
        if gradient {
            // γ_k = A⁻¹ (e_{k+1} / h − A_{,k} γ).
            let mut gk = [[0.0; BASIS]; 3];
            for k in 0..3 {
                let mut ak = [[0.0; BASIS]; BASIS];
                for (p, dw) in self.basis.iter().zip(&self.dweight) {
                    add_outer(&mut ak, p, dw[k]);
                }
                let mut rhs: [f64; BASIS] = std::array::from_fn(|r| -dot(&ak[r], &gamma));
                rhs[k + 1] += 1.0 / h;
                gk[k] = std::array::from_fn(|r| dot(&inv[r], &rhs));
            }
            for ((p, &w), dw) in self.basis.iter().zip(&self.weight).zip(&self.dweight) {
                let gp = dot(&gamma, p);
                self.grad
                    .push(std::array::from_fn(|k| w * dot(&gk[k], p) + dw[k] * gp));
            }
        }
        Ok(())
    }
}

/// The offset `x − p` and the distance in units of the support radius `r`
/// (`< 1`: the support covers `x`), as [`ShapeRow::evaluate`] decides.
#[inline]
fn scaled_offset(x: [f64; 3], p: [f64; 3], r: f64) -> ([f64; 3], f64) {
    let d = [x[0] - p[0], x[1] - p[1], x[2] - p[2]];
    (d, (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() / r)
}

/// The MLS shape functions, without gradients, at the many points of one
/// node's test sphere, over candidates gathered once per node: the fast
/// twin of [`ShapeRow::evaluate`] (with `gradient` false) for the traction
/// operator ([`crate::approx::weak::TractionOperator::build`]).
///
/// The same operations in the same order as [`ShapeRow::evaluate`] on the
/// candidates that cover the point, hence the same bits; what is saved is
/// the work on the others: a squared distance against `r_J²` (with a
/// margin) rules them out before any root or division. The buffers are
/// reused from point to point and node to node.
#[derive(Debug, Clone, Default)]
pub struct PointShapes {
    // The candidates, structure of arrays.
    node: Vec<usize>,
    cx: Vec<f64>,
    cy: Vec<f64>,
    cz: Vec<f64>,
    r: Vec<f64>,
    /// `r_J²` with a margin: a candidate farther than this covers nothing.
    r2: Vec<f64>,
    /// Per candidate, the sum over the points so far of `w φ_J n`.
    acc: Vec<[f64; 3]>,
    /// Per candidate, whether it covered any point so far.
    touched: Vec<bool>,
    // At the current point: squared distances, the candidates that may
    // cover it, those that do, and their weights, basis and shapes.
    dist2: Vec<f64>,
    maybe: Vec<u32>,
    cover: Vec<u32>,
    s: Vec<f64>,
    w: Vec<f64>,
    p1: Vec<f64>,
    p2: Vec<f64>,
    p3: Vec<f64>,
    phi: Vec<f64>,
    /// How many candidates cover the current point.
    covering: usize,
}

impl PointShapes {
    /// Takes the candidate nodes `nodes` (in the order the plain
    /// evaluation would see them) and clears the accumulated operator row.
    pub fn gather(
        &mut self,
        nodes: impl Iterator<Item = usize>,
        points: &[[f64; 3]],
        radius: &[f64],
    ) {
        self.node.clear();
        self.node.extend(nodes);
        let gather = |v: &mut Vec<f64>, f: &dyn Fn(usize) -> f64, node: &[usize]| {
            v.clear();
            v.extend(node.iter().map(|&j| f(j)));
        };
        gather(&mut self.cx, &|j| points[j][0], &self.node);
        gather(&mut self.cy, &|j| points[j][1], &self.node);
        gather(&mut self.cz, &|j| points[j][2], &self.node);
        gather(&mut self.r, &|j| radius[j], &self.node);
        gather(
            &mut self.r2,
            &|j| radius[j] * radius[j] * (1.0 + 1e-9),
            &self.node,
        );
        let k = self.node.len();
        self.acc.clear();
        self.acc.resize(k, [0.0; 3]);
        self.touched.clear();
        self.touched.resize(k, false);
        self.dist2.resize(k, 0.0);
        self.maybe.resize(k, 0);
        self.cover.resize(k, 0);
        for v in [
            &mut self.s,
            &mut self.w,
            &mut self.p1,
            &mut self.p2,
            &mut self.p3,
            &mut self.phi,
        ] {
            v.resize(k, 0.0);
        }
    }

    /// The shape functions at `x` of the gathered candidates that cover it
    /// (see [`ShapeRow::evaluate`]: the same errors, `node` labels them).
    pub fn evaluate(&mut self, isa: Isa, x: [f64; 3], node: usize) -> Result<()> {
        match point_shapes(isa, self, x) {
            Ok(()) => Ok(()),
            Err(condition) => Err(Error::SingularMomentMatrix {
                method: crate::error::MomentMethod::Mls,
                particle: node,
                time: 0.0,
                condition,
            }),
        }
    }

    /// Adds the quadrature point with outward normal `n` and weight `w`
    /// (m²) of the last [`PointShapes::evaluate`] to the operator row:
    /// `B_J += w φ_J n`.
    pub fn accumulate(&mut self, n: [f64; 3], w: f64) {
        for q in 0..self.covering {
            let c = self.cover[q] as usize;
            self.touched[c] = true;
            for d in 0..3 {
                self.acc[c][d] += w * self.phi[q] * n[d];
            }
        }
    }

    /// Number of candidates gathered.
    #[cfg(test)]
    pub fn candidates(&self) -> usize {
        self.node.len()
    }

    /// Number of candidates covering the point of the last
    /// [`PointShapes::evaluate`].
    #[cfg(test)]
    pub fn covering(&self) -> usize {
        self.covering
    }

    /// The operator row accumulated since [`PointShapes::gather`]: the
    /// candidates that covered a point, in order, and their `B_J`.
    pub fn row(&self) -> (Vec<usize>, Vec<[f64; 3]>) {
        let keep = || (0..self.node.len()).filter(|&c| self.touched[c]);
        (
            keep().map(|c| self.node[c]).collect(),
            keep().map(|c| self.acc[c]).collect(),
        )
    }
}

hot! {
    /// The body of [`PointShapes::evaluate`]; the error is the condition
    /// number (infinite when too few nodes cover `x` or `A` is singular).
    fn point_shapes(ps: &mut PointShapes, x: [f64; 3]) -> std::result::Result<(), f64> {
        let k = ps.node.len();
        // Squared distances, summed as ShapeRow::evaluate sums them.
        let (cx, cy, cz, r, r2) = (&ps.cx[..k], &ps.cy[..k], &ps.cz[..k], &ps.r[..k], &ps.r2[..k]);
        let dist2 = &mut ps.dist2[..k];
        for (d2, ((&cx, &cy), &cz)) in dist2.iter_mut().zip(cx.iter().zip(cy).zip(cz)) {
            let d = [x[0] - cx, x[1] - cy, x[2] - cz];
            *d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        }
        // Those within r_J (with the margin), in candidate order: their
        // index, squared distance and radius.
        let (maybe, md2, mr) = (&mut ps.maybe[..k], &mut ps.s[..k], &mut ps.w[..k]);
        let mut m = 0;
        for c in 0..k {
            maybe[m] = c as u32;
            md2[m] = dist2[c];
            mr[m] = r[c];
            m += (dist2[c] <= r2[c]) as usize;
        }
        // The exact test of ShapeRow::evaluate: s = |x − x_J| / r_J < 1.
        for (d2, &r) in md2[..m].iter_mut().zip(&mr[..m]) {
            *d2 = d2.sqrt() / r;
        }
        let ms = &ps.s[..m];
        let (cover, s, cr) = (&mut ps.cover[..m], &mut ps.phi[..m], &mut ps.dist2[..m]);
        let (px, py, pz) = (&mut ps.p1[..m], &mut ps.p2[..m], &mut ps.p3[..m]);
        let mut covering = 0;
        for q in 0..m {
            let c = ps.maybe[q] as usize;
            cover[covering] = c as u32;
            s[covering] = ms[q];
            cr[covering] = r[c];
            px[covering] = cx[c];
            py[covering] = cy[c];
            pz[covering] = cz[c];
            covering += (ms[q] < 1.0) as usize;
        }
        if covering < BASIS {
            return Err(f64::INFINITY);
        }
        let m = covering;
        let h = cr[..m].iter().fold(0.0f64, |h, &r| h.max(r));
        // Weights and the scaled basis.
        let w = &mut ps.w[..m];
        for ((((w, &s), p1), p2), p3) in w
            .iter_mut()
            .zip(&s[..m])
            .zip(&mut px[..m])
            .zip(&mut py[..m])
            .zip(&mut pz[..m])
        {
            *w = 1.0 - s * s * (6.0 - 8.0 * s + 3.0 * s * s);
            *p1 = (*p1 - x[0]) / h;
            *p2 = (*p2 - x[1]) / h;
            *p3 = (*p3 - x[2]) / h;
        }
        // The moment matrix, each entry summed in candidate order; its
        // first row and column are the same sums.
        let mut a0 = [0.0; BASIS];
        let mut a = [[0.0; 3]; 3];
        for q in 0..m {
            let w = ps.w[q];
            let p = [ps.p1[q], ps.p2[q], ps.p3[q]];
            a0[0] += w;
            for r in 0..3 {
                let wp = w * p[r];
                a0[r + 1] += wp;
                for c in 0..3 {
                    a[r][c] += wp * p[c];
                }
            }
        }
        let a: [[f64; BASIS]; BASIS] = std::array::from_fn(|r| {
            std::array::from_fn(|c| match (r, c) {
                (0, c) => a0[c],
                (r, 0) => a0[r],
                (r, c) => a[r - 1][c - 1],
            })
        });
        let inv = invert(a).ok_or(f64::INFINITY)?;
        let condition = norm1(&a) * norm1(&inv);
        if !condition.is_finite() || condition > MAX_CONDITION {
            return Err(condition);
        }
        let g: [f64; BASIS] = std::array::from_fn(|r| inv[r][0]);
        for ((((phi, &w), &p1), &p2), &p3) in ps.phi[..m]
            .iter_mut()
            .zip(&ps.w[..m])
            .zip(&ps.p1[..m])
            .zip(&ps.p2[..m])
            .zip(&ps.p3[..m])
        {
            *phi = w * dot(&g, &[1.0, p1, p2, p3]);
        }
        ps.covering = m;
        Ok(())
    }
}

#[inline]
fn dot(a: &[f64; BASIS], b: &[f64; BASIS]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

#[inline]
fn add_outer(a: &mut [[f64; BASIS]; BASIS], p: &[f64; BASIS], w: f64) {
    for r in 0..BASIS {
        for c in 0..BASIS {
            a[r][c] += w * p[r] * p[c];
        }
    }
}

/// Largest absolute column sum.
fn norm1(m: &[[f64; BASIS]; BASIS]) -> f64 {
    (0..BASIS)
        .map(|c| m.iter().map(|row| row[c].abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// Rows of [`NodalShapes::rebuild_rows`] handled as one task.
const ROWS_PER_BLOCK: usize = 256;

/// The shape functions and their gradients at the nodes themselves, in
/// compressed rows: row `i` lists the nodes covering `x_i`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct NodalShapes {
    /// Row `i` is `offsets[i]..offsets[i + 1]`.
    pub offsets: Vec<usize>,
    /// Covering nodes `J`, ascending in each row.
    pub nodes: Vec<usize>,
    /// `φ_J(x_i)`.
    pub phi: Vec<f64>,
    /// `∇φ_J(x_i)`.
    pub grad: Vec<[f64; 3]>,
}

impl NodalShapes {
    /// The shape functions at every node (in parallel; the same bits for
    /// any number of threads). The first failing node, in index order,
    /// names the error.
    pub fn build(points: &[[f64; 3]], supports: &Supports) -> Result<Self> {
        Self::build_rows(points, supports, points.len())
    }

    /// The shape functions at the first `rows` nodes only (the real nodes;
    /// the others, mirror images, are only covering nodes).
    pub fn build_rows(points: &[[f64; 3]], supports: &Supports, rows: usize) -> Result<Self> {
        let mut shapes = NodalShapes::default();
        shapes.rebuild_rows(points, supports, rows)?;
        Ok(shapes)
    }

    /// [`NodalShapes::build_rows`] into these shapes' buffers (reused: no
    /// allocation unless the rows grow). Each row's candidates (the rows
    /// of `candidates_first` with no reach: within the largest support
    /// radius, of the node's own body, ascending) are found while the row
    /// is handled, and a first pass counts each row's covering nodes so
    /// that the second writes the shapes in place: nothing is held beside
    /// the shapes (BENCHMARKS.md, memory). On an error the shapes are left
    /// partly written.
    pub fn rebuild_rows(
        &mut self,
        points: &[[f64; 3]],
        supports: &Supports,
        rows: usize,
    ) -> Result<()> {
        self.rebuild_rows_on(points, supports, rows, &crate::ranks::Alone)
    }

    /// [`NodalShapes::rebuild_rows`] shared among `ranks`: each computes
    /// the rows of its share ([`crate::ranks::share`], whole blocks of
    /// rows), and the rows are gathered so that every rank holds them all,
    /// with the same bits as one rank. A failing row is agreed over the
    /// ranks: the first in index order, which every rank then evaluates
    /// itself, names the error on all.
    pub fn rebuild_rows_on(
        &mut self,
        points: &[[f64; 3]],
        supports: &Supports,
        rows: usize,
        ranks: &dyn crate::ranks::Ranks,
    ) -> Result<()> {
        let shares = self.rebuild_share_on(points, supports, rows, ranks)?;
        self.gather_shares(ranks, &shares);
        Ok(())
    }

    /// Every rank's share `shares` of the rows (contiguous, in rank order,
    /// covering the rows; each rank holding its own) to every rank, in
    /// place. Nothing on one rank.
    pub fn gather_shares(
        &mut self,
        ranks: &dyn crate::ranks::Ranks,
        shares: &[std::ops::Range<usize>],
    ) {
        if ranks.size() == 1 {
            return;
        }
        let entries: Vec<std::ops::Range<usize>> = shares
            .iter()
            .map(|r| self.offsets[r.start]..self.offsets[r.end])
            .collect();
        crate::ranks::gather_parts(ranks, &entries, &mut self.nodes);
        crate::ranks::gather_parts(ranks, &entries, &mut self.phi);
        crate::ranks::gather_parts(ranks, &entries, &mut self.grad);
    }

    /// [`NodalShapes::rebuild_rows_on`] without the gather of the rows:
    /// every rank holds every row's length (`offsets`, whole) but the
    /// entries of its own share only; the entries of the other rows are
    /// left as they were (the caller sends the rows each rank reads:
    /// `solver::mlpg3d::held`). Returns every rank's share.
    pub fn rebuild_share_on(
        &mut self,
        points: &[[f64; 3]],
        supports: &Supports,
        rows: usize,
        ranks: &dyn crate::ranks::Ranks,
    ) -> Result<Vec<std::ops::Range<usize>>> {
        refill(&mut self.offsets, rows + 1, 0);
        let shares = crate::ranks::shares(ranks, rows, ROWS_PER_BLOCK);
        if points.is_empty() {
            self.offsets.truncate(1);
            self.nodes.clear();
            self.phi.clear();
            self.grad.clear();
            return Ok(shares);
        }
        // The nodes of a row's body whose supports cover its node, by
        // class of radius: the test is ShapeRow::evaluate's own.
        let covers = Covers::new(points, &supports.radius, &supports.group, 0.0);
        let radius = &supports.radius;
        let covering =
            |i: usize| move |j: usize| scaled_offset(points[i], points[j], radius[j]).1 < 1.0;
        let candidates =
            |i: usize, out: &mut Vec<usize>| covers.sorted_into(&points[i], i, covering(i), out);
        // Pass 1: each row's length, into offsets[i + 1] (this rank's
        // share, then every rank's).
        let own = shares[ranks.rank()].clone();
        self.offsets[1 + own.start..1 + own.end]
            .par_iter_mut()
            .enumerate()
            .with_min_len(ROWS_PER_BLOCK)
            .for_each(|(k, len)| {
                let i = own.start + k;
                *len = covers.count(&points[i], i, covering(i));
            });
        crate::ranks::gather_parts(ranks, &shares, &mut self.offsets[1..]);
        for i in 0..rows {
            self.offsets[i + 1] += self.offsets[i];
        }
        let total = self.offsets[rows];
        refill(&mut self.nodes, total, 0);
        refill(&mut self.phi, total, 0.0);
        refill(&mut self.grad, total, [0.0; 3]);
        // Pass 2: the rows, a block at a time, each into its own entries.
        let mut blocks = Vec::with_capacity(rows.div_ceil(ROWS_PER_BLOCK));
        let (mut nodes, mut phi, mut grad) =
            (&mut self.nodes[..], &mut self.phi[..], &mut self.grad[..]);
        for b in 0..rows.div_ceil(ROWS_PER_BLOCK) {
            let (first, last) = (b * ROWS_PER_BLOCK, rows.min((b + 1) * ROWS_PER_BLOCK));
            let len = self.offsets[last] - self.offsets[first];
            let (n, rest_n) = nodes.split_at_mut(len);
            let (p, rest_p) = phi.split_at_mut(len);
            let (g, rest_g) = grad.split_at_mut(len);
            if own.contains(&first) {
                blocks.push((first..last, n, p, g));
            }
            (nodes, phi, grad) = (rest_n, rest_p, rest_g);
        }
        let offsets = &self.offsets;
        let errors: Vec<Option<(usize, Error)>> = blocks
            .into_par_iter()
            .map_init(
                || (ShapeRow::default(), Vec::new()),
                |(row, list), (range, nodes, phi, grad)| {
                    let base = offsets[range.start];
                    for i in range {
                        candidates(i, list);
                        if let Err(e) =
                            row.evaluate(points[i], list, points, &supports.radius, true, i)
                        {
                            return Some((i, e));
                        }
                        let at = offsets[i] - base..offsets[i + 1] - base;
                        debug_assert_eq!(at.len(), row.nodes.len());
                        nodes[at.clone()].copy_from_slice(&row.nodes);
                        phi[at.clone()].copy_from_slice(&row.phi);
                        grad[at].copy_from_slice(&row.grad);
                    }
                    None
                },
            )
            .collect();
        let first = errors.into_iter().flatten().next();
        if ranks.size() == 1 {
            return first.map_or(Ok(shares), |(_, e)| Err(e));
        }
        // The first failing row over the ranks, evaluated by every rank.
        let failing = ranks.all_min(first.as_ref().map_or(i64::MAX, |(i, _)| *i as i64));
        if failing != i64::MAX {
            let i = failing as usize;
            if let Some((j, e)) = first
                && j == i
            {
                return Err(e);
            }
            let mut list = Vec::new();
            candidates(i, &mut list);
            let mut row = ShapeRow::default();
            return Err(row
                .evaluate(points[i], &list, points, &supports.radius, true, i)
                .err()
                .unwrap_or(Error::NonFinite {
                    field: "shape row (agreed over the ranks)",
                    particle: i,
                    time: 0.0,
                }));
        }
        Ok(shares)
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    /// True when there are no nodes.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The range of row `i` in `nodes`, `phi` and `grad`.
    pub fn row(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i]..self.offsets[i + 1]
    }

    /// Nodal velocity gradients by collocation, eq. (4):
    /// `L_i[a][b] = ∂v_a/∂x_b (x_i) = Σ_J v_J[a] ∂φ_J/∂x_b (x_i)`, written
    /// into `out` (one per node), in parallel.
    pub fn velocity_gradients(&self, velocity: &[[f64; 3]], out: &mut [[[f64; 3]; 3]]) {
        out.par_iter_mut()
            .enumerate()
            .for_each(|(i, l)| *l = self.gradient(i, velocity));
    }

    /// [`NodalShapes::velocity_gradients`] of the rows `own` only (a rank's
    /// part of the material pass), the other rows of `out` left as they
    /// were (their reader, the material pass, reads the same part).
    pub fn velocity_gradients_on(
        &self,
        own: std::ops::Range<usize>,
        velocity: &[[f64; 3]],
        out: &mut [[[f64; 3]; 3]],
    ) {
        let start = own.start;
        out[own]
            .par_iter_mut()
            .enumerate()
            .for_each(|(k, l)| *l = self.gradient(start + k, velocity));
    }

    /// The collocated gradient (eq. 4) of the nodal vector field `field`
    /// at node `i`: `Σ_J f_J ⊗ ∇φ_J(x_i)`.
    pub fn gradient(&self, i: usize, field: &[[f64; 3]]) -> [[f64; 3]; 3] {
        let mut l = [[0.0; 3]; 3];
        for q in self.row(i) {
            let (v, g) = (field[self.nodes[q]], self.grad[q]);
            for a in 0..3 {
                for b in 0..3 {
                    l[a][b] += v[a] * g[b];
                }
            }
        }
        l
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A node in a crowded plane names nodes until one lies off the plane,
    /// and then the moment matrix at it is regular; a neighbourhood that
    /// spans the space keeps its `k`, and a flat set stays at `k`.
    #[test]
    fn a_node_in_a_crowded_plane_names_a_node_off_it() {
        let h = 1.0;
        // A 7 x 7 patch of the plane z = 0 at spacing h / 2 around the
        // origin, and the nearest nodes off the plane two spacings away.
        let mut points = vec![[0.0, 0.0, 0.0]];
        for a in -3i32..=3 {
            for b in -3i32..=3 {
                if (a, b) != (0, 0) {
                    points.push([0.5 * h * a as f64, 0.5 * h * b as f64, 0.0]);
                }
            }
        }
        let off = points.len();
        points.push([0.1 * h, 0.0, 2.0 * h]);
        points.push([-0.1 * h, 0.0, -2.0 * h]);
        let mut row: Vec<(f64, usize)> = (1..points.len())
            .map(|j| (distance(&points[0], &points[j]), j))
            .collect();
        row.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let k = 10;
        let named = spanning_count(&points[0], &row, k, |j| points[j]);
        let first_off = row.iter().position(|&(_, j)| j >= off).unwrap() + 1;
        assert!(first_off > k, "the k nearest are in the plane");
        assert_eq!(named, first_off);
        // The supports over the whole set: the node at the origin names the
        // node off the plane, whose support then covers it.
        let sup = Supports::compute(&points, SupportParams::default()).unwrap();
        assert!(sup.named.of(0).iter().any(|&j| j >= off));
        let all: Vec<usize> = (0..points.len()).collect();
        let mut shape = ShapeRow::default();
        shape
            .evaluate(points[0], &all, &points, &sup.radius, true, 0)
            .unwrap();
        let sum: f64 = shape.phi.iter().sum();
        assert!((sum - 1.0).abs() < 1e-12, "partition of unity: {sum}");
        // Without the node off the plane, every cover is flat: the named
        // error, and the node names its k nearest only.
        let flat = &points[..off];
        let mut flat_row = row.clone();
        flat_row.retain(|&(_, j)| j < off);
        assert_eq!(spanning_count(&flat[0], &flat_row, k, |j| flat[j]), k);
        // A cubic lattice: its k nearest span the space.
        let cube = jittered_cube(5, h, 0.0, 1);
        let c = 62; // the centre of the 5³ lattice
        let mut cube_row: Vec<(f64, usize)> = (0..cube.len())
            .filter(|&j| j != c)
            .map(|j| (distance(&cube[c], &cube[j]), j))
            .collect();
        cube_row.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        assert_eq!(spanning_count(&cube[c], &cube_row, k, |j| cube[j]), k);
    }

    /// A deterministic uniform number in [0, 1) (xorshift).
    pub(crate) fn uniform(seed: &mut u64) -> f64 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    /// An `n³` cubic lattice of spacing `h` in [0, (n-1) h]³, each point
    /// moved by up to `jitter · h` along each axis.
    pub(crate) fn jittered_cube(n: usize, h: f64, jitter: f64, seed: u64) -> Vec<[f64; 3]> {
        let mut s = seed;
        let mut pts = Vec::with_capacity(n * n * n);
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let mut p = [i as f64 * h, j as f64 * h, k as f64 * h];
                    for x in &mut p {
                        *x += (2.0 * uniform(&mut s) - 1.0) * jitter * h;
                    }
                    pts.push(p);
                }
            }
        }
        pts
    }

    #[test]
    fn quartic_spline_values_and_slope() {
        assert_eq!(quartic_spline(0.0), (1.0, -12.0));
        assert_eq!(quartic_spline(1.0), (0.0, 0.0));
        assert_eq!(quartic_spline(2.0), (0.0, 0.0));
        // W'(s)/s against a central difference of W.
        for s in [0.1, 0.37, 0.5, 0.83, 0.99] {
            let e = 1e-6;
            let fd = (quartic_spline(s + e).0 - quartic_spline(s - e).0) / (2.0 * e);
            assert!((quartic_spline(s).1 * s - fd).abs() < 1e-8, "{s}");
        }
    }

    /// A place that is not a number stops the search of the supports with
    /// `NonFinite`, naming the node, instead of doubling the radius for ever
    /// (issue 48: a forged place of 1e300 hung a step).
    #[test]
    fn a_place_that_is_not_a_number_stops_the_support_search() {
        let mut pts = jittered_cube(5, 1e-3, 0.1, 3);
        pts[17][1] = f64::NAN;
        match Supports::compute(&pts, SupportParams::default()) {
            Err(Error::NonFinite { particle, .. }) => assert_eq!(particle, 17),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn mls_reproduces_linear_fields_on_a_jittered_set() {
        let h = 1e-3;
        let pts = jittered_cube(7, h, 0.3, 7);
        let sup = Supports::compute(&pts, SupportParams::default()).unwrap();
        let shapes = NodalShapes::build(&pts, &sup).unwrap();
        // f = 3 + 2x − 5y + 7z (x in units of h).
        let c = [2.0 / h, -5.0 / h, 7.0 / h];
        let f = |p: &[f64; 3]| 3.0 + c[0] * p[0] + c[1] * p[1] + c[2] * p[2];
        let mut worst = [0.0f64; 4];
        for i in 0..pts.len() {
            let r = shapes.row(i);
            let sum: f64 = shapes.phi[r.clone()].iter().sum();
            worst[0] = worst[0].max((sum - 1.0).abs());
            let mut x = [0.0; 3];
            let mut fx = 0.0;
            let mut g = [0.0; 3];
            let mut gsum = [0.0; 3];
            for q in r {
                let pj = pts[shapes.nodes[q]];
                for d in 0..3 {
                    x[d] += shapes.phi[q] * pj[d];
                    g[d] += shapes.grad[q][d] * f(&pj);
                    gsum[d] += shapes.grad[q][d];
                }
                fx += shapes.phi[q] * f(&pj);
            }
            for d in 0..3 {
                worst[1] = worst[1].max((x[d] - pts[i][d]).abs() / h);
                worst[3] = worst[3].max((g[d] - c[d]).abs() / 7.0 * h + gsum[d].abs() * h);
            }
            worst[2] = worst[2].max((fx - f(&pts[i])).abs() / 30.0);
        }
        // Σφ = 1, Σφ x_J = x, the field and its gradient: round-off.
        assert!(worst.iter().all(|&w| w < 1e-12), "{worst:?}");
    }

    #[test]
    fn mls_at_an_arbitrary_point_matches_linear_fields() {
        let h = 0.5;
        let pts = jittered_cube(5, h, 0.25, 11);
        let sup = Supports::compute(&pts, SupportParams::default()).unwrap();
        let list: Vec<usize> = (0..pts.len()).collect();
        let mut row = ShapeRow::default();
        let x = [0.93, 1.07, 1.21];
        row.evaluate(x, &list, &pts, &sup.radius, true, 0).unwrap();
        let f = |p: &[f64; 3]| 1.0 - p[0] + 4.0 * p[1] + 0.5 * p[2];
        let fx: f64 = row
            .nodes
            .iter()
            .zip(&row.phi)
            .map(|(&j, &p)| p * f(&pts[j]))
            .sum();
        assert!((fx - f(&x)).abs() < 1e-13, "{fx} {}", f(&x));
        let gy: f64 = row
            .nodes
            .iter()
            .zip(&row.grad)
            .map(|(&j, g)| g[1] * f(&pts[j]))
            .sum();
        assert!((gy - 4.0).abs() < 1e-12, "{gy}");
        // Covering nodes only: their number is what the supports give.
        assert!(row.nodes.len() > BASIS);
    }

    #[test]
    fn a_singular_moment_matrix_is_a_named_error() {
        // Coplanar nodes (z = 0): the z column of A vanishes.
        let mut pts = Vec::new();
        for j in 0..5 {
            for i in 0..5 {
                pts.push([i as f64, j as f64, 0.0]);
            }
        }
        let sup = Supports::compute(&pts, SupportParams::default()).unwrap();
        let err = NodalShapes::build(&pts, &sup).unwrap_err();
        assert_eq!(err.name(), "SingularMomentMatrix");
        assert!(matches!(
            err,
            Error::SingularMomentMatrix { particle: 0, .. }
        ));
        // Too few covering nodes: three points and a far one.
        let pts = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let mut row = ShapeRow::default();
        let err = row
            .evaluate([9.0, 9.0, 9.0], &[0, 1, 2, 3], &pts, &[1.5; 4], true, 7)
            .unwrap_err();
        assert!(matches!(
            err,
            Error::SingularMomentMatrix { particle: 7, condition, .. } if condition.is_infinite()
        ));
        // Bad parameters are range errors.
        let bad = SupportParams {
            neighbours: 2,
            factor: 1.5,
        };
        assert_eq!(
            Supports::compute(&pts, bad).unwrap_err().name(),
            "OutOfRange"
        );
        let bad = SupportParams {
            neighbours: 3,
            factor: 1.0,
        };
        assert_eq!(
            Supports::compute(&pts, bad).unwrap_err().name(),
            "OutOfRange"
        );
    }

    #[test]
    fn supports_cover_the_named_neighbours_and_the_recompute_rule() {
        let pts = jittered_cube(6, 1.0, 0.3, 3);
        let p = SupportParams::default();
        let sup = Supports::compute(&pts, p).unwrap();
        for i in 0..pts.len() {
            assert_eq!(sup.named.of(i).len(), p.neighbours);
            for &j in sup.named.of(i) {
                assert!(distance(&pts[i], &pts[j]) * p.factor <= sup.radius[j]);
            }
        }
        assert_eq!(sup.recompute_reason(&pts), None);
        // A uniform stretch of 20 % is within λ = 1.25; 30 % is not.
        let scaled = |s: f64| pts.iter().map(|x| x.map(|c| c * s)).collect::<Vec<_>>();
        assert_eq!(sup.recompute_reason(&scaled(1.2)), None);
        assert!(matches!(
            sup.recompute_reason(&scaled(1.3)),
            Some(Recompute::Stretched { node: 0, ratio, .. }) if (ratio - 1.3).abs() < 1e-12
        ));
        assert!(matches!(
            sup.recompute_reason(&scaled(0.75)),
            Some(Recompute::Compressed { node: 0, .. })
        ));
        // A rigid motion (rotation and translation) never asks for one.
        let (c, s) = (0.6f64, 0.8f64);
        let moved: Vec<[f64; 3]> = pts
            .iter()
            .map(|x| {
                [
                    c * x[0] - s * x[1] + 5.0,
                    s * x[0] + c * x[1] - 2.0,
                    x[2] + 9.0,
                ]
            })
            .collect();
        assert_eq!(sup.recompute_reason(&moved), None);
        // Up to the limit, every node stays covered by k + 1 supports.
        let stretched = scaled(1.24);
        let shapes = NodalShapes::build(&stretched, &sup).unwrap();
        assert!((0..pts.len()).all(|i| shapes.row(i).len() > p.neighbours));
    }

    /// Two bodies touching (a cube on a cube, one spacing apart): grouped
    /// supports name and cover only nodes of the node's own body, each
    /// body's supports are those it has alone, and a body with no more than
    /// `k` nodes is refused by name.
    #[test]
    fn grouped_supports_keep_the_bodies_apart() {
        let a = jittered_cube(5, 1.0, 0.2, 7);
        let b: Vec<[f64; 3]> = jittered_cube(5, 1.0, 0.2, 8)
            .iter()
            .map(|x| [x[0], x[1], x[2] + 5.0])
            .collect();
        let pts: Vec<[f64; 3]> = a.iter().chain(&b).copied().collect();
        let group: Vec<u8> = (0..pts.len()).map(|i| (i >= a.len()) as u8).collect();
        let p = SupportParams::default();
        let sup = Supports::compute_grouped(&pts, &group, p).unwrap();
        let alone = Supports::compute(&a, p).unwrap();
        for i in 0..a.len() {
            assert_eq!(sup.named.of(i), alone.named.of(i));
            assert_eq!(sup.radius[i], alone.radius[i]);
        }
        for i in 0..pts.len() {
            assert!(sup.named.of(i).iter().all(|&j| group[j] == group[i]));
        }
        // Ungrouped, some node of one body names a node of the other.
        let mixed = Supports::compute(&pts, p).unwrap();
        assert!((0..pts.len()).any(|i| mixed.named.of(i).iter().any(|&j| group[j] != group[i])));
        // The shapes at a node of the lower body use only its body's nodes,
        // and reproduce a linear field there.
        let shapes = NodalShapes::build(&pts, &sup).unwrap();
        for i in 0..pts.len() {
            let row = shapes.row(i);
            assert!(row.clone().all(|q| group[shapes.nodes[q]] == group[i]));
            let f: f64 = row
                .map(|q| shapes.phi[q] * (2.0 * pts[shapes.nodes[q]][2] + 1.0))
                .sum();
            assert!((f - (2.0 * pts[i][2] + 1.0)).abs() < 1e-10, "{i}: {f}");
        }
        // A body of k nodes cannot name k others.
        let few = &pts[..a.len() + p.neighbours];
        let e = Supports::compute_grouped(few, &group[..few.len()], p).unwrap_err();
        assert!(e.to_string().contains("nodes of a body"), "{e}");
    }
}
