//! The shapes' rows each rank holds, on several ranks with the nodal
//! forces: not every row, only those its passes read.
//!
//! Each rank computes the rows of its share of the shapes
//! ([`NodalShapes::rebuild_share_on`]); every rank holds every row's length
//! (the offsets). The passes of a rank read the rows:
//!
//! - of its part of the shapes' rows `Geometry::rows` (the smoothing's
//!   defect, the shifts, the carry, the halo's lists);
//! - that name a column of its part of the nodal operator (the transpose
//!   it builds: the forces and the smoothing's transpose);
//! - of its part of the material's points (the velocity gradients), whose
//!   split moves every few steps ([`super::balance`]);
//! - with the conservative carry, of every node shifted in a step
//!   ([`super::shift::exchange`], made by every rank over all of them).
//!
//! At each build every rank sends, of its share, the rows that another
//! rank reads by the first three (the lists gathered once, the rows then
//! by [`crate::ranks::gather_listed`], which gives every listed row to
//! every rank; where those are more than a quarter of the rows, every
//! row goes, by the whole gather: [`WHOLE_PAST`]); when the material's
//! split moves, and where a step shifts
//! a node whose row no rank but its computer holds, those rows follow, by
//! lists every rank makes alike. Every other rank's row is marked unread:
//! its entries' nodes are [`UNHELD`], which no pass reads without stopping
//! (an index past every field), and which the transpose's count skips.
//!
//! What a pass reads is then what the whole gather gave: the same bits on
//! any number of ranks (`tests/mpi.rs`, and the halo's thread-rank tests,
//! which compare every field's bits with one rank).

use crate::approx::mls::NodalShapes;
use crate::ranks::Ranks;
use rayon::iter::IntoParallelIterator;
use rayon::iter::IntoParallelRefMutIterator;
use rayon::iter::ParallelIterator;
use std::ops::Range;

/// Where more than `1 / WHOLE_PAST` of the rows are read by a rank other
/// than the one that computed them, every row goes to every rank (the
/// whole gather, in place) rather than the listed rows (packed one entry
/// at a time). Measured on `penetration` at 8 across (a quarter, 2 ranks,
/// to 20 µs, 247 builds): with the plate's rings' order 52 % of the rows
/// are read elsewhere, and the listed rows took the shapes' phase from
/// 22.3 s to 25.0 s; with the bisection's order 9 %, and no difference
/// resolved (docs/notes/2026-12-02-mpi-eleventh-steps.md). A quarter lies
/// between the two.
const WHOLE_PAST: usize = 4;

/// The node of an entry of a row this rank does not hold.
pub(super) const UNHELD: usize = usize::MAX;

/// An entry as it travels: its node (the bits of the index), `φ` and
/// `∇φ`.
type Wire = [f64; 5];

/// Which of the shapes' rows this rank holds. Rebuilt, never saved.
#[derive(Debug, Clone, Default)]
pub(super) struct HeldRows {
    /// Every rank's share of the rows at the last build; empty where every
    /// rank holds every row (one rank, or a scheme that reads them all).
    shares: Vec<Range<usize>>,
    /// The rows sent since the last build: every rank holds them.
    common: Vec<bool>,
    /// The material's parts whose rows were sent.
    material: Vec<Range<usize>>,
    /// The entries as they travel, kept from one exchange to the next.
    wire: Vec<Wire>,
}

impl HeldRows {
    /// Every rank holds every row (a whole gather, or one rank).
    pub(super) fn whole() -> Self {
        HeldRows::default()
    }

    /// Whether this rank holds only some rows.
    pub(super) fn apart(&self) -> bool {
        !self.shares.is_empty()
    }

    /// After a build of each rank's share `shares` of the rows of `shapes`:
    /// the rows another rank reads go to every rank, the rows of the parts
    /// `rows` (the shapes' rows), `columns` (the nodal operator's) and
    /// `material` (the material's points), and every row still unheld is
    /// marked [`UNHELD`]; or, where more than a quarter of the rows would
    /// go ([`WHOLE_PAST`]) and not `listed` (a test's check), every row. A
    /// collective call (one gather of the lists, one of the rows).
    pub(super) fn after_build(
        (ranks, listed): (&dyn Ranks, bool),
        shapes: &mut NodalShapes,
        shares: Vec<Range<usize>>,
        [rows, columns, material]: [&[Range<usize>]; 3],
    ) -> Self {
        let me = ranks.rank();
        let n = shapes.len();
        let own = shares[me].clone();
        let reader = |parts: &[Range<usize>], i: usize| part_of(parts, i);
        // A row of this share that another rank reads: in its part of
        // the rows or of the points, or naming one of its columns.
        let mine: Vec<usize> = own
            .clone()
            .into_par_iter()
            .filter(|&i| {
                let other = |r: Option<usize>| r.is_some_and(|r| r != me);
                other(reader(rows, i))
                    || other(reader(material, i))
                    || shapes
                        .row(i)
                        .any(|q| other(reader(columns, shapes.nodes[q])))
            })
            .collect();
        let all = crate::ranks::all_gather_varying(ranks, &mine);
        if !listed && all.len() > n / WHOLE_PAST {
            // Most rows are read elsewhere: the whole gather in place.
            shapes.gather_shares(ranks, &shares);
            return HeldRows::whole();
        }
        let mut held = HeldRows {
            shares,
            common: vec![false; n],
            material: material.to_vec(),
            wire: Vec::new(),
        };
        // Every row but this rank's share unread, then the rows sent
        // written over (on the pool: a serial fill of the entries cost as
        // much as the gather it replaces).
        let (before, rest) = shapes.nodes.split_at_mut(shapes.offsets[own.start]);
        let after = &mut rest[shapes.offsets[own.end] - shapes.offsets[own.start]..];
        before.par_iter_mut().for_each(|j| *j = UNHELD);
        after.par_iter_mut().for_each(|j| *j = UNHELD);
        held.send(ranks, shapes, &all);
        held
    }

    /// The rows of the material's `parts` go to every rank where the
    /// split moved since they were sent (every rank makes the same lists:
    /// a collective call only then).
    pub(super) fn follow_material(
        &mut self,
        ranks: &dyn Ranks,
        shapes: &mut NodalShapes,
        parts: &[Range<usize>],
    ) {
        if !self.apart() || self.material == parts {
            return;
        }
        let (shares, common) = (&self.shares, &self.common);
        let rows: Vec<usize> = (0..shapes.len())
            .filter(|&i| !common[i] && part_of(parts, i).is_some_and(|r| !shares[r].contains(&i)))
            .collect();
        self.material = parts.to_vec();
        self.send(ranks, shapes, &rows);
    }

    /// The rows of the nodes with a non-zero `shift` go to every rank
    /// (the conservative carry reads them all; every rank makes the same
    /// lists from the whole shifts: a collective call where one is
    /// unheld somewhere).
    pub(super) fn follow_shifted(
        &mut self,
        ranks: &dyn Ranks,
        shapes: &mut NodalShapes,
        shift: &[[f64; 3]],
    ) {
        if !self.apart() {
            return;
        }
        let common = &self.common;
        let rows: Vec<usize> = (0..shapes.len())
            .filter(|&i| shift[i] != [0.0; 3] && !common[i])
            .collect();
        if !rows.is_empty() {
            self.send(ranks, shapes, &rows);
        }
    }

    /// Rows `rows` (ascending, not yet common) of `shapes` from the ranks
    /// that computed them to every rank.
    fn send(&mut self, ranks: &dyn Ranks, shapes: &mut NodalShapes, rows: &[usize]) {
        // Each rank's rows, split by the shares, as the entries they hold.
        let mut lists = vec![Vec::new(); self.shares.len()];
        for &i in rows {
            let r = part_of(&self.shares, i).expect("the shares cover the rows");
            lists[r].extend(shapes.offsets[i]..shapes.offsets[i + 1]);
            self.common[i] = true;
        }
        let get = |s: &NodalShapes, q: usize| -> Wire {
            let g = s.grad[q];
            [
                f64::from_bits(s.nodes[q] as u64),
                s.phi[q],
                g[0],
                g[1],
                g[2],
            ]
        };
        let put = |s: &mut NodalShapes, q: usize, w: &Wire| {
            s.nodes[q] = w[0].to_bits() as usize;
            s.phi[q] = w[1];
            s.grad[q] = [w[2], w[3], w[4]];
        };
        crate::ranks::gather_listed(ranks, &lists, &mut self.wire, shapes, (get, put));
    }
}

/// The part of `parts` (contiguous, ascending) that holds `i`, if any.
fn part_of(parts: &[Range<usize>], i: usize) -> Option<usize> {
    let r = parts.partition_point(|p| p.end <= i);
    parts.get(r).filter(|p| p.contains(&i)).map(|_| r)
}

/// The entries of each column of the operator over `columns` columns:
/// every rank counts those of the rows of its share `own`, and the counts
/// are summed over the ranks (the weights of the nodal operator's parts,
/// [`crate::approx::nodal::NodalOperator::rebuild_parts_on`]: the same as
/// counted over the whole shapes). A collective call.
pub(super) fn column_weights(
    ranks: &dyn Ranks,
    shapes: &NodalShapes,
    own: Range<usize>,
    columns: usize,
) -> Vec<usize> {
    let mut count = vec![0usize; columns];
    for q in shapes.offsets[own.start]..shapes.offsets[own.end] {
        count[shapes.nodes[q]] += 1;
    }
    let pairs: Vec<[usize; 2]> = (0..columns)
        .filter(|&j| count[j] > 0)
        .map(|j| [j, count[j]])
        .collect();
    let mut weight = vec![0usize; columns];
    for [j, c] in crate::ranks::all_gather_varying(ranks, &pairs) {
        weight[j] += c;
    }
    weight
}
