//! The material pass's shares among the ranks, balanced by its measured
//! cost: a point of a damaged ceramic or in plastic flow costs several
//! times an elastic one, so equal shares of the points leave one rank
//! waiting for another (`penetration` 8 across, quarter, to 8 µs: the
//! material update took 2.08 s on one rank and 1.49 s on the other).
//!
//! Each rank times the granules of its share ([`GRANULE`] points), and
//! every [`EVERY`] steps the granules' times are gathered and the granules
//! split again so that each rank gets an equal part of their total. Every
//! rank computes the split from the same gathered times, so the ranks
//! agree on it. The shares change only who computes which points: the sums
//! go by the blocks of [`crate::approx::sums::BLOCK`] points over a fixed
//! tree ([`crate::approx::sums::ordered_on`]; a block cut by a share's end
//! is summed by the rank that holds its first point, from the results of
//! its other points sent to it: `update::sum_on`), so the bits do not
//! depend on the split.
//!
//! The granule is an eighth of a block: by whole blocks of 1024 points the
//! 20 216 points of `penetration` at 8 across (a quarter) give 16 ranks one
//! or two blocks each, and 2 ranks a split no nearer than 5 % of the pass.

use crate::ranks::Ranks;
use std::ops::Range;

/// Steps between two splits.
const EVERY: usize = 10;

/// Points a granule: the unit of the split and of its timing.
pub(super) const GRANULE: usize = crate::approx::sums::BLOCK / 8;

/// The current split of the material pass's points among the ranks, and
/// the time of this rank's blocks since it was made.
#[derive(Debug, Default, Clone)]
pub(super) struct Balance {
    /// The points of each rank (whole granules, contiguous, in rank order).
    parts: Vec<Range<usize>>,
    /// Seconds spent on each granule since the last split (this rank's
    /// granules only; the others are zero).
    cost: Vec<f64>,
    /// Steps since the last split.
    steps: usize,
    /// The damage variables' records as they travel between the ranks
    /// after the pass ([`crate::material::MaterialState::gather`]), kept
    /// from step to step so that a step allocates none.
    pub(super) wire: Vec<u8>,
}

impl Balance {
    /// The points of each rank for a pass over `n` points (equal shares of
    /// the granules at first, or when `n` or the ranks changed).
    pub(super) fn parts(&mut self, ranks: &dyn Ranks, n: usize) -> &[Range<usize>] {
        if self.parts.len() != ranks.size() || self.parts.last().map(|p| p.end) != Some(n) {
            self.parts = crate::ranks::shares(ranks, n, GRANULE);
            self.cost = vec![0.0; n.div_ceil(GRANULE)];
            self.steps = 0;
        }
        &self.parts
    }

    /// Books `seconds` spent on granule `g`.
    #[cfg(test)]
    pub(super) fn book(&mut self, g: usize, seconds: f64) {
        self.cost[g] += seconds;
    }

    /// The times of the granules of `own` (a part of [`Balance::parts`]),
    /// to which a pass adds what each of them took.
    pub(super) fn costs_of(&mut self, own: &Range<usize>) -> &mut [f64] {
        &mut self.cost[granules_of(own)]
    }

    /// Whether [`Balance::end_step`] of this step will split the points
    /// again (the same answer on every rank).
    pub(super) fn splits_at_end(&self, ranks: &dyn Ranks) -> bool {
        ranks.size() > 1 && !self.cost.is_empty() && self.steps + 1 >= EVERY
    }

    /// Ends a step: every [`EVERY`] steps the granules' times are gathered
    /// and the granules split again ([`split`]). A collective call: every
    /// rank calls it at every step.
    pub(super) fn end_step(&mut self, ranks: &dyn Ranks) {
        if ranks.size() == 1 || self.cost.is_empty() {
            return;
        }
        self.steps += 1;
        if self.steps < EVERY {
            return;
        }
        let n = self.parts.last().map_or(0, |p| p.end);
        let granules: Vec<_> = self.parts.iter().map(granules_of).collect();
        crate::ranks::gather_parts(ranks, &granules, &mut self.cost);
        self.parts = split(&self.cost, ranks.size())
            .into_iter()
            .map(|g| (g.start * GRANULE).min(n)..(g.end * GRANULE).min(n))
            .collect();
        self.cost.iter_mut().for_each(|c| *c = 0.0);
        self.steps = 0;
    }
}

/// The granules of a part of the points that starts on a granule's start
/// or at the end (an empty part at the end holds none).
fn granules_of(p: &Range<usize>) -> Range<usize> {
    p.start.div_ceil(GRANULE)..p.end.div_ceil(GRANULE)
}

/// The blocks of the ordered sums ([`crate::approx::sums::BLOCK`] points)
/// each part of the points sums: those whose first point it holds.
/// Contiguous, in order, covering every block; a part that holds no
/// block's first point sums none.
pub(super) fn blocks_of(parts: &[Range<usize>]) -> Vec<Range<usize>> {
    use crate::approx::sums::BLOCK;
    parts
        .iter()
        .map(|p| p.start.div_ceil(BLOCK)..p.end.div_ceil(BLOCK))
        .collect()
}

/// Contiguous ranges of the granules of `cost`, one per part, in order,
/// covering them all: part `r` starts at the granule boundary nearest to
/// where `r / parts` of the total cost lies. Granules of no measured cost
/// (none measured) count as equal.
pub(super) fn split(cost: &[f64], parts: usize) -> Vec<Range<usize>> {
    let total: f64 = cost.iter().sum();
    let weight = |b: usize| if total > 0.0 { cost[b] } else { 1.0 };
    let total = if total > 0.0 {
        total
    } else {
        cost.len() as f64
    };
    let mut starts = Vec::with_capacity(parts + 1);
    let (mut b, mut before) = (0, 0.0);
    for r in 0..parts {
        let goal = total * r as f64 / parts as f64;
        // The boundary nearest the goal, never behind the last one.
        while b < cost.len() && before + 0.5 * weight(b) < goal {
            before += weight(b);
            b += 1;
        }
        starts.push(b);
    }
    starts.push(cost.len());
    starts.windows(2).map(|w| w[0]..w[1]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::approx::sums::BLOCK;

    /// The parts cover the blocks in order, and each holds about its share
    /// of the cost: one costly block at the start goes alone to the first
    /// rank; no cost measured gives equal parts.
    #[test]
    fn the_split_gives_each_part_its_share_of_the_cost() {
        let cost = [1.0, 1.0, 1.0, 1.0, 4.0, 4.0, 4.0, 4.0];
        assert_eq!(split(&cost, 2), vec![0..5, 5..8]);
        assert_eq!(split(&[8.0, 1.0, 1.0, 1.0, 1.0], 2), vec![0..1, 1..5]);
        assert_eq!(split(&[0.0; 6], 3), vec![0..2, 2..4, 4..6]);
        for parts in 1..6 {
            let got = split(&cost, parts);
            assert_eq!(got.len(), parts);
            assert_eq!(got[0].start, 0);
            assert_eq!(got[parts - 1].end, cost.len());
            assert!(got.windows(2).all(|w| w[0].end == w[1].start));
        }
        // More parts than blocks: some are empty.
        let got = split(&[1.0, 1.0], 4);
        assert_eq!(got.iter().map(|r| r.len()).sum::<usize>(), 2);
    }

    /// The blocks of the parts of the points cover the blocks once, an
    /// empty part at the end (where the last block is short) holding none:
    /// 4 ranks on 1960 points once gave that part a block, and the gather
    /// overran its buffer.
    #[test]
    fn the_blocks_of_the_parts_cover_the_blocks_once() {
        let n = BLOCK + 936;
        let parts = [0..BLOCK, BLOCK..n, n..n, n..n];
        assert_eq!(blocks_of(&parts), vec![0..1, 1..2, 2..2, 2..2]);
        let parts = [0..0, 0..BLOCK, BLOCK..BLOCK, BLOCK..n];
        assert_eq!(blocks_of(&parts), vec![0..0, 0..1, 1..1, 1..2]);
        // Parts cut by granules: a block goes to the part that holds its
        // first point, and a part within one block sums none.
        let g = GRANULE;
        let parts = [0..3 * g, 3 * g..5 * g, 5 * g..BLOCK + g, BLOCK + g..n];
        assert_eq!(blocks_of(&parts), vec![0..1, 1..1, 1..2, 2..2]);
        assert_eq!(granules_of(&parts[2]), 5..9);
        assert_eq!(granules_of(&(n..n)), n.div_ceil(g)..n.div_ceil(g));
    }
}
