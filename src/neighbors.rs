//! Neighbour search: a uniform cell list producing a flat compressed-row (CSR)
//! neighbour list, and the naive O(N^2) search kept as the test oracle.
//!
//! Every particle is its own neighbour (the MSPH sums include `j = i`). The
//! neighbours of each particle are listed in increasing index order, so the
//! list, and everything computed from it, is independent of thread count.

use rayon::prelude::*;

/// A compressed-row neighbour list: the neighbours of particle `i` are
/// `indices[offsets[i]..offsets[i + 1]]`, sorted ascending.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct NeighborList {
    /// Row offsets, `len = n + 1`.
    pub offsets: Vec<usize>,
    /// Neighbour indices.
    pub indices: Vec<usize>,
}

impl NeighborList {
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
pub fn naive(points: &[[f64; 2]], radius: f64) -> NeighborList {
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
    NeighborList { offsets, indices }
}

#[inline]
fn dist2(a: &[f64; 2], b: &[f64; 2]) -> f64 {
    let dx = a[0] - b[0];
    let dy = a[1] - b[1];
    dx * dx + dy * dy
}

/// Cell-list search with cells of side `radius`: all `j` with
/// `|x_i - x_j| <= radius`. Queries run in parallel; the result equals
/// [`naive`] exactly.
pub fn cell_list(points: &[[f64; 2]], radius: f64) -> NeighborList {
    cell_list_first(points, points.len(), radius)
}

/// Like [`cell_list`], but lists neighbours (among all points) only for the
/// first `rows` points: the others are mirror images that are neighbours but
/// need no derivatives of their own.
pub fn cell_list_first(points: &[[f64; 2]], rows: usize, radius: f64) -> NeighborList {
    let n = points.len();
    if n == 0 {
        return NeighborList {
            offsets: vec![0],
            indices: vec![],
        };
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    let cell = radius.max(f64::MIN_POSITIVE);
    let dims = [
        (((hi[0] - lo[0]) / cell).floor() as usize + 1).max(1),
        (((hi[1] - lo[1]) / cell).floor() as usize + 1).max(1),
    ];
    let cell_of = |p: &[f64; 2]| -> [usize; 2] {
        [
            (((p[0] - lo[0]) / cell) as usize).min(dims[0] - 1),
            (((p[1] - lo[1]) / cell) as usize).min(dims[1] - 1),
        ]
    };
    // Counting sort of particles into cells: particles of a cell are stored in
    // ascending index order.
    let ncell = dims[0] * dims[1];
    let mut start = vec![0usize; ncell + 1];
    let cells: Vec<usize> = points
        .iter()
        .map(|p| {
            let c = cell_of(p);
            c[1] * dims[0] + c[0]
        })
        .collect();
    for &c in &cells {
        start[c + 1] += 1;
    }
    for c in 0..ncell {
        start[c + 1] += start[c];
    }
    let mut fill = start.clone();
    let mut sorted = vec![0usize; n];
    for (i, &c) in cells.iter().enumerate() {
        sorted[fill[c]] = i;
        fill[c] += 1;
    }
    let r2 = radius * radius;
    let lists: Vec<Vec<usize>> = points[..rows]
        .par_iter()
        .map(|p| {
            let c = cell_of(p);
            let mut row = Vec::with_capacity(32);
            for cy in c[1].saturating_sub(1)..=(c[1] + 1).min(dims[1] - 1) {
                for cx in c[0].saturating_sub(1)..=(c[0] + 1).min(dims[0] - 1) {
                    let id = cy * dims[0] + cx;
                    for &j in &sorted[start[id]..start[id + 1]] {
                        if dist2(p, &points[j]) <= r2 {
                            row.push(j);
                        }
                    }
                }
            }
            row.sort_unstable();
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
    NeighborList { offsets, indices }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic pseudo-random generator (xorshift) for test data.
    fn points(n: usize, seed: u64) -> Vec<[f64; 2]> {
        let mut s = seed;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n).map(|_| [next() * 3.0, next() * 7.0 - 2.0]).collect()
    }

    #[test]
    fn cell_list_equals_naive_oracle_on_random_points() {
        for (n, r, seed) in [(1, 0.3, 1), (500, 0.3, 7), (2000, 0.17, 99), (300, 5.0, 3)] {
            let p = points(n, seed);
            assert_eq!(cell_list(&p, r), naive(&p, r), "n={n} r={r}");
        }
    }

    #[test]
    fn cell_list_equals_naive_on_a_lattice_with_points_on_the_radius() {
        // Lattice spacing 0.1, radius exactly 3 spacings: pairs at the radius.
        let p: Vec<[f64; 2]> = (0..400)
            .map(|k| [(k % 20) as f64 * 0.1, (k / 20) as f64 * 0.1])
            .collect();
        assert_eq!(cell_list(&p, 0.3), naive(&p, 0.3));
    }

    #[test]
    fn first_rows_only_equal_the_oracle_rows() {
        let p = points(700, 11);
        let full = naive(&p, 0.25);
        let part = cell_list_first(&p, 300, 0.25);
        assert_eq!(part.len(), 300);
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
}
