//! The named nodes of every row of [`super::Supports::compute_rows`]: each
//! row's `k` nearest of its body (and more where these are flat,
//! [`spanning`]), found from a grid of cells one search radius wide.
//!
//! A row that holds `k` others or fewer within the search radius is found
//! again at twice the radius, and so on. The rows were once all found
//! again at the radius the last row needed: in `penetration` one node at
//! the crater's edge doubled the radius for all, and every row's list grew
//! from about 90 candidates to about 600 (8 across, quarter model). Now
//! only the rows that need it are found again. A row found at a smaller
//! radius than the final one keeps that answer only where the final
//! radius could not change it: its named nodes lie strictly inside the
//! smaller radius (so every node beyond it sorts after them) and they
//! span the space (so [`spanning`] stopped within them). Any other
//! row is found again at the final radius. The rows are the ones the
//! search at the final radius gives, to the bit.

use super::supports::spanning;
use crate::Error;
use crate::approx::mls::ROWS_PER_BLOCK;
use crate::approx::mls::distance;
use crate::error::Result;
use crate::neighbours::Cells;
use crate::neighbours::NeighbourList;
use rayon::iter::IndexedParallelIterator;
use rayon::iter::IntoParallelIterator;
use rayon::iter::ParallelIterator;
use rayon::slice::ParallelSlice;
use rayon::slice::ParallelSliceMut;

/// The named pairs of every row, in row order.
pub(super) struct Named {
    /// Each row's `k`-th nearest distance.
    pub(super) kth: Vec<f64>,
    /// Each row's named nodes, nearest first.
    pub(super) named: NeighbourList,
    /// The distance of each named pair.
    pub(super) distance: Vec<f64>,
    /// The final search radius: the one at which the last row was found.
    #[cfg(test)]
    search: f64,
}

/// The rows of one block of a pass.
#[derive(Default)]
struct Found {
    /// The rows found, ascending; empty in the first pass, whose block
    /// holds an entry for each of its rows (a short row's of length 0).
    row: Vec<usize>,
    kth: Vec<f64>,
    len: Vec<usize>,
    pairs: Vec<(f64, usize)>,
    /// The rows that hold `k` others or fewer within the radius.
    short: Vec<usize>,
    /// The rows found here whose answer a larger radius could change.
    unsure: Vec<usize>,
}

/// How one row came out at one radius.
enum Row {
    /// `k` others or fewer of its body within the radius.
    Short,
    /// Found: its named count, and whether a larger radius gives the same.
    Named(usize, bool),
}

/// Below this fraction of the radius a named node lies strictly inside it,
/// far above the round-off of the distances (the nodes beyond the radius
/// are at least the radius away, to round-off).
const INSIDE: f64 = 1.0 - 1e-9;

/// The search at one radius: its grid over the points, each row's `k`
/// nearest of its body.
struct Radius<'a> {
    grid: Cells<'a, 3>,
    search: f64,
    points: &'a [[f64; 3]],
    group: &'a [u8],
    k: usize,
}

/// A row's buffers: the candidates, and the (distance, node) pairs.
type Scratch = (Vec<usize>, Vec<(f64, usize)>);

impl<'a> Radius<'a> {
    fn new(points: &'a [[f64; 3]], group: &'a [u8], k: usize, search: f64) -> Self {
        Radius {
            grid: Cells::new(points, search).expect("more than k points"),
            search,
            points,
            group,
            k,
        }
    }

    /// The row of node `i`: its others of the same body by (distance,
    /// index) into `row`.
    fn find(&self, i: usize, (list, row): &mut Scratch) -> Row {
        let (points, k) = (self.points, self.k);
        let same = |j: usize| self.group.is_empty() || self.group[i] == self.group[j];
        self.grid.sorted_into(&points[i], list);
        if list.iter().filter(|&&j| same(j)).count() <= k {
            return Row::Short;
        }
        row.clear();
        row.extend(
            list.iter()
                .filter(|&&j| j != i && same(j))
                .map(|&j| (distance(&points[i], &points[j]), j)),
        );
        row.sort_unstable_by(|a: &(f64, usize), b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        match spanning(&points[i], row, k, |j| points[j]) {
            Some(named) => Row::Named(named, row[named - 1].0 < INSIDE * self.search),
            None => Row::Named(k, false),
        }
    }

    /// One block of rows; `first`: the first pass's block (an entry for
    /// every row).
    fn block(
        &self,
        rows: impl Iterator<Item = usize>,
        first: bool,
        scratch: &mut Scratch,
    ) -> Found {
        let mut f = Found::default();
        for i in rows {
            match self.find(i, scratch) {
                Row::Short => {
                    f.short.push(i);
                    if first {
                        f.kth.push(f64::NAN);
                        f.len.push(0);
                    }
                }
                Row::Named(named, sure) => {
                    if !sure {
                        f.unsure.push(i);
                    }
                    if !first {
                        f.row.push(i);
                    }
                    let row = &scratch.1;
                    f.kth.push(row[self.k - 1].0);
                    f.len.push(named);
                    f.pairs.extend_from_slice(&row[..named]);
                }
            }
        }
        f
    }

    /// The rows `rows` (ascending), a block at a time on the pool.
    fn again(&self, rows: &[usize]) -> Vec<Found> {
        rows.par_chunks(ROWS_PER_BLOCK)
            .map_init(
                || (Vec::new(), Vec::new()),
                |scratch, chunk| self.block(chunk.iter().copied(), false, scratch),
            )
            .collect()
    }
}

/// Visits the answers of block `b`'s rows in order (`visit(found, entry,
/// start of its pairs)`): from the first pass (`block`), or a row's last
/// from `later` (`over`: by row, (row, found, entry, start)). `start` runs
/// through the block's pairs (a row found again still holds its first
/// entry there).
fn walk(
    b: usize,
    rows: usize,
    block: &Found,
    later: &[Found],
    over: &[(usize, u32, u32, usize)],
    mut visit: impl FnMut(&Found, usize, usize),
) {
    let (first, last) = (b * ROWS_PER_BLOCK, rows.min((b + 1) * ROWS_PER_BLOCK));
    let mut next = over.partition_point(|o| o.0 < first);
    let mut start = 0;
    for i in first..last {
        let e = i - first;
        let s = start;
        start += block.len[e];
        match over.get(next) {
            Some(&(row, f, e, s)) if row == i => {
                next += 1;
                visit(&later[f as usize], e as usize, s);
            }
            _ => visit(block, e, s),
        }
    }
}

/// The named pairs of the first `rows` of `points` (each of its body),
/// starting from the radius `search`. Fails when the radius overflows
/// (a place that is not a number).
///
/// Shared among `ranks`: each finds the rows of its share (whole blocks),
/// the radius doubles in step on every rank until no rank has a short row
/// left, each rank's unsure rows are found again at that common final
/// radius, and then every rank holds every row: the rows of one rank, to
/// the bit.
pub(super) fn named_rows(
    points: &[[f64; 3]],
    group: &[u8],
    rows: usize,
    k: usize,
    mut search: f64,
    ranks: &dyn crate::ranks::Ranks,
) -> Result<Named> {
    let shares = crate::ranks::shares(ranks, rows, ROWS_PER_BLOCK);
    let own = shares[ranks.rank()].clone();
    let own_blocks = if own.is_empty() {
        0..0
    } else {
        own.start / ROWS_PER_BLOCK..own.end.div_ceil(ROWS_PER_BLOCK)
    };
    // This rank's blocks of the first pass, from `own_blocks.start`.
    let blocks: Vec<Found> = {
        let at = Radius::new(points, group, k, search);
        own_blocks
            .clone()
            .into_par_iter()
            .map_init(
                || (Vec::new(), Vec::new()),
                |scratch, b| {
                    let rows = b * ROWS_PER_BLOCK..rows.min((b + 1) * ROWS_PER_BLOCK);
                    at.block(rows, true, scratch)
                },
            )
            .collect()
    };
    let mut todo: Vec<usize> = blocks
        .iter()
        .flat_map(|f| f.short.iter().copied())
        .collect();
    let mut unsure: Vec<(usize, usize)> = blocks
        .iter()
        .flat_map(|f| f.unsure.iter().map(|&i| (i, 0)))
        .collect();
    // Whether any rank has a short row left.
    let short_anywhere = |todo: &[usize]| ranks.all_max(i64::from(!todo.is_empty())) > 0;
    // The rows found at larger radii, pass by pass.
    let mut later: Vec<Found> = Vec::new();
    let mut level = 0;
    let mut more = short_anywhere(&todo);
    while more {
        search *= 2.0;
        level += 1;
        // Every body holds more than k nodes (checked by the caller), so
        // a radius past the box finds them, unless a place is not a
        // number or overflows: then stop rather than double for ever
        // (on every rank at once: the radius is the same on all).
        if !search.is_finite() {
            let particle = points
                .iter()
                .position(|p| !p.iter().all(|x| x.is_finite()))
                .unwrap_or(0);
            return Err(Error::NonFinite {
                field: "position",
                particle,
                time: f64::NAN,
            });
        }
        // The grid at this radius, built only where a row needs it.
        let at = (!todo.is_empty()).then(|| Radius::new(points, group, k, search));
        let found = at.as_ref().map_or_else(Vec::new, |at| at.again(&todo));
        todo = found.iter().flat_map(|f| f.short.iter().copied()).collect();
        unsure.extend(
            found
                .iter()
                .flat_map(|f| f.unsure.iter().map(|&i| (i, level))),
        );
        later.extend(found);
        more = short_anywhere(&todo);
        // The rows a larger radius could change, found again at the
        // final one.
        if !more {
            let mut redo: Vec<usize> = unsure
                .iter()
                .filter(|&&(_, l)| l < level)
                .map(|&(i, _)| i)
                .collect();
            redo.sort_unstable();
            if !redo.is_empty() {
                let at = at.unwrap_or_else(|| Radius::new(points, group, k, search));
                later.extend(at.again(&redo));
            }
        }
    }
    // The rows found later, by row, the last answer of each: (row,
    // block, entry, start of its pairs).
    let mut over: Vec<(usize, u32, u32, usize)> = Vec::new();
    for (f, found) in later.iter().enumerate() {
        let mut start = 0;
        for (e, (&i, &len)) in found.row.iter().zip(&found.len).enumerate() {
            over.push((i, f as u32, e as u32, start));
            start += len;
        }
    }
    over.sort_by_key(|o| o.0);
    let over: Vec<(usize, u32, u32, usize)> = over
        .iter()
        .enumerate()
        .filter(|&(q, o)| over.get(q + 1).is_none_or(|next| next.0 != o.0))
        .map(|(_, o)| *o)
        .collect();
    // Each row's answer: from the first pass, or its last from later.
    // This rank's rows' lengths and k-th distances, then every rank's.
    let mut named = Named {
        kth: vec![0.0; rows],
        named: NeighbourList {
            offsets: vec![0; rows + 1],
            indices: Vec::new(),
        },
        distance: Vec::new(),
        #[cfg(test)]
        search,
    };
    // The answers of this rank's `c`-th block.
    let walk_own = |c: usize, block: &Found, visit: &mut dyn FnMut(&Found, usize, usize)| {
        walk(own_blocks.start + c, rows, block, &later, &over, visit)
    };
    named.kth[own.clone()]
        .par_chunks_mut(ROWS_PER_BLOCK)
        .zip(named.named.offsets[1 + own.start..1 + own.end].par_chunks_mut(ROWS_PER_BLOCK))
        .zip(&blocks)
        .enumerate()
        .for_each(|(c, ((kth, lens), block))| {
            let mut r = 0;
            walk_own(c, block, &mut |found, e, _| {
                kth[r] = found.kth[e];
                lens[r] = found.len[e];
                r += 1;
            });
        });
    crate::ranks::gather_parts(ranks, &shares, &mut named.kth);
    let offsets = &mut named.named.offsets;
    crate::ranks::gather_parts(ranks, &shares, &mut offsets[1..]);
    for i in 0..rows {
        offsets[i + 1] += offsets[i];
    }
    let entries = offsets[rows];
    named.named.indices = vec![0; entries];
    named.distance = vec![0.0; entries];
    // This rank's rows' pairs, a block at a time, then every rank's.
    let offsets = &named.named.offsets;
    let mut parts = Vec::with_capacity(blocks.len());
    let (mut indices, mut distance) = (
        &mut named.named.indices[offsets[own.start]..offsets[own.end]],
        &mut named.distance[offsets[own.start]..offsets[own.end]],
    );
    for b in own_blocks.clone() {
        let (first, last) = (b * ROWS_PER_BLOCK, rows.min((b + 1) * ROWS_PER_BLOCK));
        let count = offsets[last] - offsets[first];
        let (i, rest_i) = indices.split_at_mut(count);
        let (d, rest_d) = distance.split_at_mut(count);
        parts.push((i, d));
        (indices, distance) = (rest_i, rest_d);
    }
    parts
        .into_par_iter()
        .zip(&blocks)
        .enumerate()
        .for_each(|(c, ((indices, distance), block))| {
            let mut at = 0;
            walk_own(c, block, &mut |found, e, s| {
                let len = found.len[e];
                for (q, &(d, j)) in found.pairs[s..s + len].iter().enumerate() {
                    indices[at + q] = j;
                    distance[at + q] = d;
                }
                at += len;
            });
        });
    let entry_parts: Vec<std::ops::Range<usize>> = shares
        .iter()
        .map(|r| offsets[r.start]..offsets[r.end])
        .collect();
    crate::ranks::gather_parts(ranks, &entry_parts, &mut named.named.indices);
    crate::ranks::gather_parts(ranks, &entry_parts, &mut named.distance);
    Ok(named)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cube of `cube` random nodes, `plane` nodes crowded in z = 0 beside
    /// it (flat rows), and 12 nodes far off (they double the radius several
    /// times), in that order.
    fn cube_plane_and_far(
        next: &mut impl FnMut() -> f64,
        cube: usize,
        plane: usize,
    ) -> Vec<[f64; 3]> {
        let mut points: Vec<[f64; 3]> = (0..cube).map(|_| [next(), next(), next()]).collect();
        points.extend((0..plane).map(|_| [1.2 + 0.3 * next(), 0.3 * next(), 0.0]));
        points.extend((0..12).map(|q| [5.0 + q as f64 * 0.4, 3.0, -2.0]));
        points
    }

    /// Against the search of every row at the final radius (the rows as
    /// they were found before): a cube of nodes, a plane of nodes crowded
    /// in z = 0 beside it (flat rows), and a few nodes far off (they
    /// double the radius several times), in two bodies.
    #[test]
    fn the_rows_are_those_of_the_final_radius_to_the_bit() {
        let mut next = crate::test_rng::rng(11);
        let mut points = cube_plane_and_far(&mut next, 2000, 400);
        // Interleaved, so that the rows found again lie among others in
        // their blocks.
        for q in (1..points.len()).rev() {
            points.swap(q, (next() * (q + 1) as f64) as usize);
        }
        let group: Vec<u8> = (0..points.len()).map(|j| u8::from(j % 5 == 0)).collect();
        let k = 10;
        for group in [&group[..], &[][..]] {
            let start = 0.15;
            let got =
                named_rows(&points, group, points.len(), k, start, &crate::ranks::Alone).unwrap();
            assert!(got.search >= 8.0 * start, "the far nodes double the radius");
            let want = named_rows(
                &points,
                group,
                points.len(),
                k,
                got.search,
                &crate::ranks::Alone,
            )
            .unwrap();
            assert_eq!(want.search, got.search);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got.kth), bits(&want.kth));
            assert_eq!(got.named, want.named);
            assert!(
                (0..got.named.len()).any(|i| got.named.of(i).len() > k),
                "some rows are flat and name more"
            );
            assert_eq!(bits(&got.distance), bits(&want.distance));
        }
    }

    /// Shared among 2, 3 and 5 ranks (threads standing in for MPI), the
    /// rows are those of one rank, to the bit: the same point set, whose
    /// far nodes double the radius on one rank's share only.
    #[test]
    fn the_rows_on_any_number_of_ranks_are_those_of_one() {
        let mut next = crate::test_rng::rng(5);
        let points = cube_plane_and_far(&mut next, 1500, 300);
        let group: Vec<u8> = (0..points.len()).map(|j| u8::from(j % 5 == 0)).collect();
        let k = 10;
        let want =
            named_rows(&points, &group, points.len(), k, 0.15, &crate::ranks::Alone).unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for size in [2, 3, 5] {
            let got = crate::ranks::tests::on_threads(size, |ranks| {
                named_rows(&points, &group, points.len(), k, 0.15, ranks).unwrap()
            });
            for g in got {
                assert_eq!(g.search, want.search, "{size} ranks");
                assert_eq!(bits(&g.kth), bits(&want.kth), "{size} ranks");
                assert_eq!(g.named, want.named, "{size} ranks");
                assert_eq!(bits(&g.distance), bits(&want.distance), "{size} ranks");
            }
        }
    }
}
