//! The supports of the MLS approximation (module docs of [`super`], "Support
//! sizes"): each node's named neighbours and support radius, when they are
//! recomputed, and the candidate nodes of a point's covering supports.

use crate::Error;
use crate::approx::mls::BASIS;
use crate::approx::mls::distance;
use crate::error::Result;
use crate::neighbours::NeighbourList;
use crate::neighbours::cell_list_first;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
/// The choices behind the support sizes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SupportParams {
    /// Nearest neighbours each node names (k ≥ m − 1 = 3).
    pub neighbours: usize,
    /// Scale factor applied to the support sizes (> 1), the margin for the
    /// nodes' motion between recomputations.
    pub factor: f64,
}

impl Default for SupportParams {
    /// `k = 10`, factor 1.5: see the measurement in the module docs.
    fn default() -> Self {
        SupportParams {
            neighbours: 10,
            factor: 1.5,
        }
    }
}

/// Why the supports must be recomputed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Recompute {
    /// A named pair `(node, neighbour)` has stretched by `ratio` (> the
    /// limit) since the supports were computed: coverage is at risk.
    Stretched {
        /// The node that names the neighbour.
        node: usize,
        /// The named neighbour.
        neighbour: usize,
        /// Current distance over the distance at computation.
        ratio: f64,
    },
    /// A named pair has shrunk by `ratio` (< 1 / limit): the supports cover
    /// needlessly many nodes (locality and cost).
    Compressed {
        /// The node that names the neighbour.
        node: usize,
        /// The named neighbour.
        neighbour: usize,
        /// Current distance over the distance at computation.
        ratio: f64,
    },
}

/// Support radii of the nodes and what they were computed from.
#[derive(Debug, Clone, PartialEq)]
pub struct Supports {
    /// Support radius `r_J` of each node (m).
    pub radius: Vec<f64>,
    /// The `k` nearest other nodes named by each node, nearest first.
    pub named: NeighbourList,
    /// Distance of each named pair when the supports were computed.
    pub named_distance: Vec<f64>,
    /// The parameters used.
    pub params: SupportParams,
    /// The body of each node, for a run of several bodies (empty: one
    /// body): a node names, and is covered by, nodes of its own body only,
    /// so that the MLS fields of bodies in contact stay apart.
    pub group: Vec<u8>,
}

impl Supports {
    /// The supports of the nodes at `points` (seed section 3.1). Fails with
    /// [`Error::OutOfRange`] for `neighbours < 3`, a factor ≤ 1 or fewer
    /// than `neighbours + 1` nodes.
    pub fn compute(points: &[[f64; 3]], params: SupportParams) -> Result<Self> {
        Self::compute_grouped(points, &[], params)
    }

    /// The supports of nodes of several bodies: `group[i]` is the body of
    /// node `i` (empty: one body), and every node names its `k` nearest of
    /// its own body. Every body needs more than `k` nodes.
    pub fn compute_grouped(
        points: &[[f64; 3]],
        group: &[u8],
        params: SupportParams,
    ) -> Result<Self> {
        Self::compute_rows(points, group, points.len(), params)
    }

    /// The supports with only the first `rows` nodes naming their `k`
    /// nearest (of all `points`): the others (mirror images,
    /// `src/approx/mirror.rs`) are named, and get the radius of their largest
    /// naming distance only. [`Supports::named`] has `rows` rows.
    pub fn compute_rows(
        points: &[[f64; 3]],
        group: &[u8],
        rows: usize,
        params: SupportParams,
    ) -> Result<Self> {
        Self::compute_rows_on(points, group, rows, params, &crate::ranks::Alone)
    }

    /// [`Supports::compute_rows`] shared among `ranks`: each finds the
    /// named nodes of its share of the rows, and every rank then holds
    /// them all (the same bits on any number of ranks).
    pub fn compute_rows_on(
        points: &[[f64; 3]],
        group: &[u8],
        rows: usize,
        params: SupportParams,
        ranks: &dyn crate::ranks::Ranks,
    ) -> Result<Self> {
        let k = params.neighbours;
        // A place that is not a number is never within a radius: the search
        // below would double it for ever.
        if let Some(particle) = points.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
            return Err(Error::NonFinite {
                field: "position",
                particle,
                time: f64::NAN,
            });
        }
        if k < BASIS - 1 || k >= points.len() {
            return Err(Error::OutOfRange {
                name: "support neighbours".into(),
                value: k as f64,
                range: format!("[{}, {}]", BASIS - 1, points.len().saturating_sub(1)),
            });
        }
        if !group.is_empty() {
            let mut count = [0usize; 256];
            for &g in group {
                count[g as usize] += 1;
            }
            if group.len() != points.len() || group.iter().any(|&g| count[g as usize] <= k) {
                return Err(Error::OutOfRange {
                    name: "nodes of a body".into(),
                    value: group.iter().map(|&g| count[g as usize]).min().unwrap_or(0) as f64,
                    range: format!("[{}, inf)", k + 1),
                });
            }
        }
        if params.factor.is_nan() || params.factor <= 1.0 || !params.factor.is_finite() {
            return Err(Error::OutOfRange {
                name: "support factor".into(),
                value: params.factor,
                range: "(1, inf)".into(),
            });
        }
        // A search radius whose cube holds k + 1 nodes of an evenly filled
        // bounding box (its sphere about 4 k in the bulk, k on an edge), then
        // doubled until every node has k others. Any radius that does gives
        // the same k nearest: only the cost changes (a flat or thin set
        // starts from its longest extent).
        let (lo, hi) = bounds(points);
        let extents: [f64; 3] = std::array::from_fn(|d| (hi[d] - lo[d]).max(0.0));
        let extent: f64 = extents.iter().copied().fold(0.0, f64::max);
        let fill = (k + 1) as f64 / points.len() as f64;
        let bulk = (extents[0] * extents[1] * extents[2] * fill).cbrt();
        let search = if bulk > 1e-3 * extent {
            bulk
        } else {
            thin_start(extents, fill)
        }
        .max(1e-300);
        // Each row is found from the grid while it is handled, a block of
        // rows at a time: no list of every node's candidates is held
        // (BENCHMARKS.md, memory). A row with k others or fewer within
        // the search radius is found again at twice the radius
        // (`nearest.rs`).
        let found = super::nearest::named_rows(points, group, rows, k, search, ranks)?;
        let (named, named_distance) = (found.named, found.distance);
        // Each node's radius reaches every node that names it: maxima of
        // distances (not negative: their bits order as they do), taken on
        // the pool, the same in any order.
        let radius: Vec<AtomicU64> = (0..points.len())
            .into_par_iter()
            .map(|j| AtomicU64::new(found.kth.get(j).map_or(0, |r| r.to_bits())))
            .collect();
        named
            .indices
            .par_iter()
            .zip(&named_distance)
            .for_each(|(&j, &d)| {
                radius[j].fetch_max(d.to_bits(), Ordering::Relaxed);
            });
        let mut radius: Vec<f64> = radius
            .into_par_iter()
            .map(|r| f64::from_bits(r.into_inner()))
            .collect();
        radius.par_iter_mut().for_each(|r| *r *= params.factor);
        Ok(Supports {
            radius,
            named,
            named_distance,
            params,
            group: group.to_vec(),
        })
    }

    /// The rule for recomputing the supports: `Some(reason)` when a named
    /// pair has stretched or shrunk by more than `λ = (1 + factor) / 2`
    /// since the computation (half the margin the factor leaves: a pair
    /// stays covered until it stretches by `factor`), `None` otherwise. The
    /// first offending pair in node order is reported. Cost: one pass over
    /// the `k N` named pairs; call it every step and recompute on `Some`.
    pub fn recompute_reason(&self, points: &[[f64; 3]]) -> Option<Recompute> {
        let limit = 0.5 * (1.0 + self.params.factor);
        (0..self.named.len()).find_map(|i| {
            let lo = self.named.offsets[i];
            self.named.of(i).iter().enumerate().find_map(|(q, &j)| {
                let ratio = distance(&points[i], &points[j]) / self.named_distance[lo + q];
                if ratio > limit {
                    Some(Recompute::Stretched {
                        node: i,
                        neighbour: j,
                        ratio,
                    })
                } else if ratio < 1.0 / limit {
                    Some(Recompute::Compressed {
                        node: i,
                        neighbour: j,
                        ratio,
                    })
                } else {
                    None
                }
            })
        })
    }

    /// The largest support radius.
    pub fn max_radius(&self) -> f64 {
        self.radius.iter().copied().fold(0.0, f64::max)
    }
}

/// How flat a node's named neighbourhood may be, as the determinant of the
/// second moment `M = Σ d dᵀ` of the offsets `d` to its named nodes over
/// `(tr M / 3)³` (1 for an isotropic set, 0 for a coplanar one).
const FLAT: f64 = 1e-9;

/// [`spanning`] with its `k` for a flat row.
#[cfg(test)]
pub(super) fn spanning_count(
    x: &[f64; 3],
    row: &[(f64, usize)],
    k: usize,
    at: impl Fn(usize) -> [f64; 3],
) -> usize {
    spanning(x, row, k, at).unwrap_or(k)
}

/// How many of the `row` (distance, node) pairs, nearest first, a node at
/// `x` names: its `k` nearest, and, when these lie in a plane or on a line
/// through it ([`FLAT`]), as many more as it takes to name a node off
/// that plane; `None` if the row holds none (the caller names `k`: a flat
/// set of nodes stays flat, and its moment matrices are the named error).
///
/// Nodes held in a plane, those of a quarter model's symmetry planes, can
/// crowd together while the nodes beside the plane draw away from it: the
/// penetration run at 12 nodes across as a quarter stopped at 6.80 us
/// with a singular moment matrix at a pulverized plate node on the plane
/// y = 0, whose 17 nearest nodes (to 0.90 mm, at a spacing of 0.45 mm) lay
/// in the plane, the first off it at 0.97 mm. Every support that covered
/// it was then centred in the plane. Naming a node off the plane stretches
/// that node's support over it ([`Supports`]: a node's radius reaches every
/// node that names it), so the node's moment matrix is regular again. A
/// neighbourhood that spans the space keeps its `k`: no other run changes.
pub(super) fn spanning(
    x: &[f64; 3],
    row: &[(f64, usize)],
    k: usize,
    at: impl Fn(usize) -> [f64; 3],
) -> Option<usize> {
    let mut m = [[0.0f64; 3]; 3];
    for (count, &(_, j)) in row.iter().enumerate() {
        let p = at(j);
        let d = [p[0] - x[0], p[1] - x[1], p[2] - x[2]];
        for r in 0..3 {
            for c in 0..3 {
                m[r][c] += d[r] * d[c];
            }
        }
        if count + 1 >= k {
            let trace = (m[0][0] + m[1][1] + m[2][2]) / 3.0;
            let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
            if det > FLAT * trace * trace * trace {
                return Some(count + 1);
            }
        }
    }
    None
}

/// Componentwise bounds of a point set.
pub(super) fn bounds(points: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    points.iter().fold(
        ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
        |(lo, hi), p| {
            (
                std::array::from_fn(|d| lo[d].min(p[d])),
                std::array::from_fn(|d| hi[d].max(p[d])),
            )
        },
    )
}

/// The first search radius of the k nearest for a set whose box is thin in
/// some direction (a long rod, a flat plate, a line): the radius whose
/// d-dimensional box holds `fill` of the set, for the largest dimension d of
/// three, two or one at which the set is still d-dimensional at that scale
/// (the radius is within its d-th largest extent). A long rod 3.38 m by
/// 7.6 mm started from its length's share, 0.14 m or 190 spacings, and
/// listed about 17 000 candidates a node (13.7 GB at 400 000 nodes); it
/// starts at 3 spacings now. Only the cost depends on the start: any radius
/// that holds the k nearest names the same ones.
pub(super) fn thin_start(extents: [f64; 3], fill: f64) -> f64 {
    let mut e = extents;
    e.sort_unstable_by(|a, b| b.total_cmp(a));
    for d in [3usize, 2] {
        let r = (e[..d].iter().product::<f64>() * fill).powf(1.0 / d as f64);
        if r > 0.0 && r <= e[d - 1] {
            return r;
        }
    }
    e[0] * fill
}

/// Candidate nodes for points within `reach` of each node: the cell-list
/// neighbours within `reach + max r_J`, a superset of the nodes whose
/// supports cover any point within `reach` of the node.
/// With several bodies ([`Supports::group`]) only the node's own body's.
///
/// Lists only the first `rows` points (the real nodes; the others are
/// mirror images, `src/approx/mirror.rs`).
pub fn candidates_first(
    points: &[[f64; 3]],
    rows: usize,
    supports: &Supports,
    reach: f64,
) -> NeighbourList {
    let list = cell_list_first(points, rows, reach + supports.max_radius());
    let g = &supports.group;
    if g.is_empty() {
        return list;
    }
    let mut out = NeighbourList {
        offsets: Vec::with_capacity(list.offsets.len()),
        indices: Vec::with_capacity(list.indices.len()),
    };
    out.offsets.push(0);
    for i in 0..list.len() {
        out.indices
            .extend(list.of(i).iter().copied().filter(|&j| g[j] == g[i]));
        out.offsets.push(out.indices.len());
    }
    out
}
