//! Neighbour search: a uniform cell list producing a flat compressed-row (CSR)
//! neighbour list, and the naive O(N^2) search kept as the test oracle.
//!
//! Every particle is its own neighbour (the MSPH sums include `j = i`). The
//! neighbours of each particle are listed in increasing index order, so the
//! list, and everything computed from it, is independent of thread count.
//!
//! The search is generic in the dimension `D` of the points (2 for the
//! axisymmetric solver, 3 for the 3-D one).

use rayon::prelude::*;

/// A compressed-row neighbour list: the neighbours of particle `i` are
/// `indices[offsets[i]..offsets[i + 1]]`, sorted ascending.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct NeighbourList {
    /// Row offsets, `len = n + 1`.
    pub offsets: Vec<usize>,
    /// Neighbour indices.
    pub indices: Vec<usize>,
}

impl NeighbourList {
    /// Neighbours of particle `i`.
    #[inline]
    pub fn of(&self, i: usize) -> &[usize] {
        &self.indices[self.offsets[i]..self.offsets[i + 1]]
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// True when the list holds no particles.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Naive O(N^2) search: all `j` with `|x_i - x_j| <= radius`. Used as the
/// oracle in tests.
pub fn naive<const D: usize>(points: &[[f64; D]], radius: f64) -> NeighbourList {
    let r2 = radius * radius;
    let mut offsets = Vec::with_capacity(points.len() + 1);
    let mut indices = Vec::new();
    offsets.push(0);
    for p in points {
        for (j, q) in points.iter().enumerate() {
            if dist2(p, q) <= r2 {
                indices.push(j);
            }
        }
        offsets.push(indices.len());
    }
    NeighbourList { offsets, indices }
}

/// Squared distance, summed over the axes in order.
#[inline]
pub(crate) fn dist2<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    let mut s = 0.0;
    for d in 0..D {
        let x = a[d] - b[d];
        s += x * x;
    }
    s
}

/// Cell-list search with cells of side `radius`: all `j` with
/// `|x_i - x_j| <= radius`. Queries run in parallel; the result equals
/// [`naive`] exactly.
pub fn cell_list<const D: usize>(points: &[[f64; D]], radius: f64) -> NeighbourList {
    cell_list_first(points, points.len(), radius)
}

/// Like [`cell_list`], but lists neighbours (among all points) only for the
/// first `rows` points: the others are mirror images that are neighbours but
/// need no derivatives of their own.
pub fn cell_list_first<const D: usize>(
    points: &[[f64; D]],
    rows: usize,
    radius: f64,
) -> NeighbourList {
    let Some(cells) = Cells::new(points, radius) else {
        return NeighbourList {
            offsets: vec![0],
            indices: vec![],
        };
    };
    let lists: Vec<Vec<usize>> = points[..rows]
        .par_iter()
        .map(|p| {
            let mut row = Vec::with_capacity(32);
            cells.sorted_into(p, &mut row);
            row
        })
        .collect();
    let mut offsets = Vec::with_capacity(rows + 1);
    offsets.push(0);
    let total: usize = lists.iter().map(Vec::len).sum();
    let mut indices = Vec::with_capacity(total);
    for row in lists {
        indices.extend_from_slice(&row);
        offsets.push(indices.len());
    }
    NeighbourList { offsets, indices }
}

/// The neighbour lists of `cell_list_first` written straight into rows of
/// a fixed length: the neighbours of point `i` are
/// `rows[i * stride..][..len[i]]`, ascending, and `stride` is the longest
/// list rounded up to a multiple of `align`. The buffers are reused; a first
/// try uses `stride_hint` (the stride of the previous call) and is redone
/// with the true stride only when a list does not fit.
pub fn padded_rows<const D: usize>(
    points: &[[f64; D]],
    first: usize,
    radius: f64,
    align: usize,
    stride_hint: usize,
    rows: &mut Vec<u32>,
    len: &mut Vec<u32>,
) -> usize {
    let align = align.max(1);
    len.clear();
    len.resize(first, 0);
    let Some(cells) = Cells::new(points, radius) else {
        rows.clear();
        return align;
    };
    let mut stride = stride_hint.max(align).next_multiple_of(align);
    loop {
        rows.clear();
        rows.resize(first * stride, 0);
        rows.par_chunks_mut(stride)
            .zip(len.par_iter_mut())
            .zip(&points[..first])
            .with_min_len(64)
            .for_each(|((row, len), p)| {
                let mut k = 0;
                cells.visit(p, |j| {
                    if k < row.len() {
                        row[k] = j as u32;
                    }
                    k += 1;
                });
                if k <= row.len() {
                    row[..k].sort_unstable();
                }
                *len = k as u32;
            });
        let longest = len.iter().copied().max().unwrap_or(0) as usize;
        let fit = longest.next_multiple_of(align).max(align);
        if fit == stride {
            return stride;
        }
        // Too short a stride, or one longer than the lists need.
        stride = fit;
    }
}

/// A uniform grid of cells of side `radius` over a point set, with the
/// points of each cell in ascending index order. Cells are numbered with the
/// first axis fastest. [`Cells::sorted_into`] answers one point at a time,
/// for a caller that needs a point's neighbours only while it handles the
/// point (no list of every point's neighbours held at once).
pub(crate) struct Cells<'a, const D: usize> {
    points: &'a [[f64; D]],
    lo: [f64; D],
    cell: f64,
    dims: [usize; D],
    start: Vec<usize>,
    sorted: Vec<usize>,
    r2: f64,
}

/// Most cells in the grid (4 Mi: 32 MiB of cell starts).
const MAX_CELLS: f64 = 4_194_304.0;

/// Most cells a member of a grid over some of the points
/// ([`Cells::members`]).
const MEMBER_CELLS: f64 = 2.0;

/// The fewest cells [`Cells::members`] may always use.
const FEW_CELLS: f64 = 64.0;

/// Points per task of the grid's parallel passes.
const BLOCK: usize = 4096;

/// Cells per task of the parallel fill of the cell starts.
const CELL_CHUNK: usize = 1 << 16;

impl<'a, const D: usize> Cells<'a, D> {
    /// The grid, or `None` for no points.
    pub(crate) fn new(points: &'a [[f64; D]], radius: f64) -> Option<Self> {
        Self::build(points, None, radius, MAX_CELLS)
    }

    /// The grid over the points `members` (ascending indices into
    /// `points`) only, or `None` for no members: its queries answer
    /// indices into `points`. At most [`MEMBER_CELLS`] cells a member
    /// (and never fewer than [`FEW_CELLS`] allowed): a few members far
    /// apart with a small radius make the cells coarser, not the grid
    /// large.
    pub(crate) fn members(points: &'a [[f64; D]], members: &[usize], radius: f64) -> Option<Self> {
        let most = (MEMBER_CELLS * members.len() as f64).clamp(FEW_CELLS, MAX_CELLS);
        Self::build(points, Some(members), radius, most)
    }

    fn build(
        points: &'a [[f64; D]],
        members: Option<&[usize]>,
        radius: f64,
        most: f64,
    ) -> Option<Self> {
        let count = members.map_or(points.len(), <[usize]>::len);
        if count == 0 {
            return None;
        }
        let member = |k: usize| members.map_or(k, |m| m[k]);
        // The bounding box, on the pool (min and max are exact in any order).
        let (lo, hi) = (0..count)
            .into_par_iter()
            .with_min_len(BLOCK)
            .map(|k| &points[member(k)])
            .fold(
                || ([f64::INFINITY; D], [f64::NEG_INFINITY; D]),
                |(mut lo, mut hi), p| {
                    for d in 0..D {
                        lo[d] = lo[d].min(p[d]);
                        hi[d] = hi[d].max(p[d]);
                    }
                    (lo, hi)
                },
            )
            .reduce(
                || ([f64::INFINITY; D], [f64::NEG_INFINITY; D]),
                |a, b| {
                    (
                        std::array::from_fn(|d| a.0[d].min(b.0[d])),
                        std::array::from_fn(|d| a.1[d].max(b.1[d])),
                    )
                },
            );
        // Cells no smaller than the radius (so the block of 3^D cells around
        // a point holds all its neighbours), and no more than MAX_CELLS in
        // all: one particle flung far away makes the cells coarser (more
        // candidates), not the grid too large to allocate. At most about a
        // thousand doublings, from the smallest positive radius to 1e308.
        let mut cell = radius.max(f64::MIN_POSITIVE);
        let cells = |cell: f64| {
            (0..D)
                .map(|d| (hi[d] - lo[d]) / cell + 1.0)
                .product::<f64>()
        };
        while cells(cell) > most {
            cell *= 2.0;
        }
        let dims: [usize; D] =
            std::array::from_fn(|d| (((hi[d] - lo[d]) / cell).floor() as usize + 1).max(1));
        let total: usize = dims.iter().product();
        let mut grid = Cells {
            points,
            lo,
            cell,
            dims,
            start: Vec::new(),
            sorted: Vec::new(),
            r2: radius * radius,
        };
        // The points sorted by (cell, index), on the pool: the keys are
        // distinct, so the order is the one a serial counting sort gives.
        // A cell number and a point index each fit in 32 bits (at most
        // MAX_CELLS cells; the callers' node counts are far below 2^32).
        assert!(
            points.len() < 1 << 32,
            "Cells: {} points, at most 2^32",
            points.len()
        );
        let mut keys: Vec<u64> = (0..count)
            .into_par_iter()
            .with_min_len(BLOCK)
            .map(|k| {
                let i = member(k);
                (grid.id(grid.cell_of(&points[i])) as u64) << 32 | i as u64
            })
            .collect();
        keys.par_sort_unstable();
        grid.sorted = keys
            .par_iter()
            .with_min_len(BLOCK)
            .map(|&k| (k & 0xffff_ffff) as usize)
            .collect();
        // start[c]: the number of points in cells before c, by chunks of
        // cells, each from a binary search for its first cell.
        let cell_of_key = |k: u64| (k >> 32) as usize;
        grid.start = vec![0; total + 1];
        grid.start
            .par_chunks_mut(CELL_CHUNK)
            .enumerate()
            .for_each(|(chunk, start)| {
                let first = chunk * CELL_CHUNK;
                let mut k = keys.partition_point(|&key| cell_of_key(key) < first);
                for (c, s) in (first..).zip(start.iter_mut()) {
                    while k < keys.len() && cell_of_key(keys[k]) < c {
                        k += 1;
                    }
                    *s = k;
                }
            });
        Some(grid)
    }

    /// Writes into `out` (cleared first) every point within the radius of
    /// `p`, ascending: the row of `p` in [`cell_list_first`].
    pub(crate) fn sorted_into(&self, p: &[f64; D], out: &mut Vec<usize>) {
        out.clear();
        self.visit(p, |j| out.push(j));
        out.sort_unstable();
    }

    fn cell_of(&self, p: &[f64; D]) -> [usize; D] {
        std::array::from_fn(|d| (((p[d] - self.lo[d]) / self.cell) as usize).min(self.dims[d] - 1))
    }

    /// The number of a cell, first axis fastest.
    fn id(&self, c: [usize; D]) -> usize {
        (0..D).rev().fold(0, |id, d| id * self.dims[d] + c[d])
    }

    /// Calls `f(j)` for every point `j` within the radius of `p`, cell by
    /// cell (not in index order). The cells next to each other along the
    /// first axis are numbered in a row, so their points are one slice.
    #[inline]
    pub(crate) fn visit(&self, p: &[f64; D], mut f: impl FnMut(usize)) {
        let c = self.cell_of(p);
        let lo: [usize; D] = std::array::from_fn(|d| c[d].saturating_sub(1));
        let hi: [usize; D] = std::array::from_fn(|d| (c[d] + 1).min(self.dims[d] - 1));
        // Odometer over the other axes; the first axis is the run.
        let mut at = lo;
        loop {
            let first = self.id(at);
            let last = first + (hi[0] - lo[0]);
            for &j in &self.sorted[self.start[first]..self.start[last + 1]] {
                if dist2(p, &self.points[j]) <= self.r2 {
                    f(j);
                }
            }
            let mut d = 1;
            loop {
                if d == D {
                    return;
                }
                if at[d] < hi[d] {
                    at[d] += 1;
                    break;
                }
                at[d] = lo[d];
                d += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` deterministic pseudo-random points (xorshift) in a box that is
    /// longer along some axes than others.
    fn points<const D: usize>(n: usize, seed: u64) -> Vec<[f64; D]> {
        let mut s = seed;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let side = [3.0, 7.0, 2.0];
        (0..n)
            .map(|_| std::array::from_fn(|d| next() * side[d % 3] - d as f64))
            .collect()
    }

    /// A lattice of spacing 0.1 with `k` points along each axis.
    fn lattice<const D: usize>(k: usize) -> Vec<[f64; D]> {
        (0..k.pow(D as u32))
            .map(|m| std::array::from_fn(|d| ((m / k.pow(d as u32)) % k) as f64 * 0.1))
            .collect()
    }

    #[test]
    fn cell_list_equals_naive_oracle_on_random_points() {
        for (n, r, seed) in [(1, 0.3, 1), (500, 0.3, 7), (2000, 0.17, 99), (300, 5.0, 3)] {
            let p = points::<2>(n, seed);
            assert_eq!(cell_list(&p, r), naive(&p, r), "2-D n={n} r={r}");
        }
        for (n, r, seed) in [(1, 0.3, 1), (800, 0.4, 7), (3000, 0.3, 99), (300, 5.0, 3)] {
            let p = points::<3>(n, seed);
            assert_eq!(cell_list(&p, r), naive(&p, r), "3-D n={n} r={r}");
        }
        let p = points::<1>(400, 5);
        assert_eq!(cell_list(&p, 0.02), naive(&p, 0.02), "1-D");
    }

    #[test]
    fn cell_list_equals_naive_on_a_lattice_with_points_on_the_radius() {
        // Lattice spacing 0.1, radius exactly 3 spacings: pairs at the radius.
        let p = lattice::<2>(20);
        assert_eq!(cell_list(&p, 0.3), naive(&p, 0.3));
        let p = lattice::<3>(9);
        assert_eq!(cell_list(&p, 0.3), naive(&p, 0.3));
        // In 3-D the centre of the lattice has the 179 lattice points of the
        // ball of radius 3.5 spacings as neighbours (none on its surface).
        let centre = 4 + 9 * 4 + 81 * 4;
        assert_eq!(cell_list(&p, 0.35).of(centre).len(), 179);
    }

    #[test]
    fn first_rows_only_equal_the_oracle_rows() {
        let p = points::<2>(700, 11);
        let full = naive(&p, 0.25);
        let part = cell_list_first(&p, 300, 0.25);
        assert_eq!(part.len(), 300);
        for i in 0..300 {
            assert_eq!(part.of(i), full.of(i));
        }
        let p = points::<3>(700, 11);
        let full = naive(&p, 0.5);
        let part = cell_list_first(&p, 300, 0.5);
        for i in 0..300 {
            assert_eq!(part.of(i), full.of(i));
        }
    }

    #[test]
    fn one_dimensional_points() {
        let p: Vec<[f64; 2]> = (0..100).map(|k| [k as f64 * 0.01, 0.0]).collect();
        let nl = cell_list(&p, 0.035);
        assert_eq!(nl, naive(&p, 0.035));
        assert_eq!(nl.of(50), &[47, 48, 49, 50, 51, 52, 53]);
    }

    #[test]
    fn a_point_flung_far_away_coarsens_the_grid_and_the_lists_stay_exact() {
        // At the radius the grid would need 1e22 cells; capped, it is
        // coarser and the lists still equal the oracle's.
        let mut p = points::<2>(200, 7);
        p.push([1e8, -1e8]);
        p.push([f64::MAX / 4.0, 0.0]);
        let nl = cell_list(&p, 0.05);
        assert_eq!(nl, naive(&p, 0.05));
        let mut p = points::<3>(300, 7);
        p.push([1e8, -1e8, 1e8]);
        p.push([0.0, f64::MAX / 4.0, -f64::MAX / 4.0]);
        let nl = cell_list(&p, 0.1);
        assert_eq!(nl, naive(&p, 0.1));
    }

    /// [`padded_rows`] against [`cell_list_first`] for points of any
    /// dimension.
    fn padded_rows_match<const D: usize>(p: &[[f64; D]], r: f64) {
        let want = cell_list_first(p, 600, r);
        let (mut rows, mut len) = (Vec::new(), Vec::new());
        // No rows at all.
        assert_eq!(padded_rows(p, 0, r, 8, 64, &mut rows, &mut len), 8);
        assert!(rows.is_empty() && len.is_empty());
        // Too short a hint, too long a hint, and the right one.
        for hint in [1, 200, 0] {
            let stride = padded_rows(p, 600, r, 8, hint, &mut rows, &mut len);
            let longest = (0..600).map(|i| want.of(i).len()).max().unwrap();
            assert_eq!(stride, longest.next_multiple_of(8), "hint {hint}");
            for i in 0..600 {
                let got: Vec<usize> = rows[i * stride..][..len[i] as usize]
                    .iter()
                    .map(|&j| j as usize)
                    .collect();
                assert_eq!(got, want.of(i), "hint {hint}, point {i}");
            }
        }
    }

    #[test]
    fn padded_rows_equal_the_cell_list_rows() {
        padded_rows_match(&points::<2>(900, 5), 0.3);
        padded_rows_match(&points::<3>(900, 5), 0.6);
    }
}
