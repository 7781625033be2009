//! The nodal Galerkin form of the 3-D solver's forces: the adjoint of the
//! collocated velocity gradients (eq. 4), an alternative to the seed's
//! local weak form over test spheres (eq. 10, [`crate::approx::weak`]).
//!
//! The velocity gradient at node `i` is `L_i = Σ_J v_J ⊗ ∇φ_J(x_i)`
//! (eq. 4). With the nodal volumes `V_i = m_i / ρ_i`, the stress power of
//! the body is `P = Σ_i V_i σ_i : L_i`, and the nodal forces are taken as
//! its derivative with respect to the nodal velocities,
//!
//! `F_J = −∂P/∂v_J = −Σ_i V_i σ_i · ∇φ_J(x_i)`,
//!
//! with the nodal mass `m_J` as the inertia. Then, whatever the shapes:
//!
//! - `Σ_J F_J · v_J = −P` exactly: the work of the forces is the stress
//!   power the material update books, so the discrete equations exchange
//!   kinetic and internal energy without creating either (the sphere form
//!   does not: its `F` is not the adjoint of its `L`);
//! - `Σ_J F_J = 0` to round-off, as the MLS derivatives sum to zero
//!   (partition of unity): momentum is conserved;
//! - the free surfaces are traction-free by construction (a natural
//!   boundary condition), with no test sphere to cut and no normal to
//!   estimate.
//!
//! This is direct nodal integration of the Galerkin weak form (Beissel &
//! Belytschko 1996; Chen et al. 2001, who stabilise it); its zero-energy
//! modes are those the velocity smoothing toward the MLS approximation
//! damps (README, "3-D MLPG mixed method": the weak form, measured).
//!
//! The operator is stored transposed (a row per node `J` listing the `i`
//! whose shapes name it), so that each force is a gather in a fixed order:
//! the same bits for any number of threads.

use crate::approx::buffers::refill;
use crate::approx::mls::NodalShapes;
use crate::approx::weak::VOIGT;
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

/// The transpose of the rows of `shapes` over `columns ≥ shapes.len()`
/// nodes, by a counting sort: column `J` is `offsets[J]..offsets[J + 1]`
/// of the entries `q << 32 | i` ([`entry_parts`]), `q` the entry of row
/// `i` that names `J`, in ascending `i`.
pub(crate) fn transpose(shapes: &NodalShapes, columns: usize) -> (Vec<usize>, Vec<u64>) {
    let mut offsets = Vec::new();
    column_offsets(shapes, 0..columns, &mut offsets);
    let entries = column_entries(shapes, &offsets, 0..columns);
    (offsets, entries)
}

/// The entry `q` and the row `i` of a transposed entry `q << 32 | i`.
#[inline(always)]
pub(crate) fn entry_parts(e: u64) -> (usize, usize) {
    ((e >> 32) as usize, (e & 0xffff_ffff) as usize)
}

/// Where each of the columns `held` of `shapes` starts among the entries
/// of the transpose of those columns: `held.len() + 1` offsets from 0,
/// written into `offsets`. The counts run on the pool (an atomic counter
/// per column; a count is the same in any order).
fn column_offsets(shapes: &NodalShapes, held: Range<usize>, offsets: &mut Vec<usize>) {
    let counts: Vec<AtomicUsize> = held
        .clone()
        .into_par_iter()
        .map(|_| AtomicUsize::new(0))
        .collect();
    shapes.nodes.par_chunks(1 << 14).for_each(|chunk| {
        for &j in chunk {
            if held.contains(&j) {
                counts[j - held.start].fetch_add(1, Ordering::Relaxed);
            }
        }
    });
    refill(offsets, held.len() + 1, 0);
    for (j, c) in counts.into_iter().enumerate() {
        offsets[j + 1] = offsets[j] + c.into_inner();
    }
}

/// The entries of the transpose of the columns `held` of `shapes`, whose
/// columns start at `offsets` ([`column_offsets`]), each `q << 32 | i`, in
/// ascending `i` within each column. The scatter runs on the pool, each
/// entry placed by its column's atomic cursor, and then each column is
/// sorted: a column's entries are distinct, and ascending `q` is ascending
/// `i` (the rows are stored in order), so the result is that of a serial
/// counting sort for any number of threads.
fn column_entries(shapes: &NodalShapes, offsets: &[usize], held: Range<usize>) -> Vec<u64> {
    let columns = offsets.len() - 1;
    let cursor: Vec<AtomicUsize> = offsets[..columns]
        .par_iter()
        .map(|&o| AtomicUsize::new(o))
        .collect();
    let slots: Vec<AtomicU64> = (0..offsets[columns])
        .into_par_iter()
        .map(|_| AtomicU64::new(0))
        .collect();
    (0..shapes.len()).into_par_iter().for_each(|i| {
        for q in shapes.row(i) {
            let j = shapes.nodes[q];
            if held.contains(&j) {
                let k = cursor[j - held.start].fetch_add(1, Ordering::Relaxed);
                slots[k].store((q as u64) << 32 | i as u64, Ordering::Relaxed);
            }
        }
    });
    // In place (the same size and alignment): no second buffer.
    let mut entries: Vec<u64> = slots.into_iter().map(AtomicU64::into_inner).collect();
    for_segments(&mut entries, offsets, &|_, column| column.sort_unstable());
    entries
}

/// Calls `f(j, segment)` on the pool for each segment `j` of `data`,
/// `offsets[j]..offsets[j + 1]` (`offsets` ascending, its last entry at
/// most `data.len()`), splitting the segments in halves recursively.
pub(crate) fn for_segments<T: Send>(
    data: &mut [T],
    offsets: &[usize],
    f: &(impl Fn(usize, &mut [T]) + Sync),
) {
    fn split<T: Send>(
        data: &mut [T],
        base: usize,
        first: usize,
        offsets: &[usize],
        f: &(impl Fn(usize, &mut [T]) + Sync),
    ) {
        // `data` holds segments first..first + offsets.len() - 1, starting
        // at `base` in the whole.
        let count = offsets.len() - 1;
        if count <= 256 {
            let mut rest = data;
            for j in 0..count {
                let (head, tail) = rest.split_at_mut(offsets[j + 1] - offsets[j]);
                f(first + j, head);
                rest = tail;
            }
            return;
        }
        let mid = count / 2;
        let (left, right) = data.split_at_mut(offsets[mid] - base);
        rayon::join(
            || split(left, base, first, &offsets[..=mid], f),
            || split(right, offsets[mid], first + mid, &offsets[mid..], f),
        );
    }
    let start = offsets[0];
    let end = offsets[offsets.len() - 1];
    split(&mut data[start..end], start, 0, offsets, f);
}

/// The transpose of the nodal shape functions and their gradients: for
/// each node `J` of [`NodalOperator::held`], the nodes `i` (ascending) with
/// `φ_J(x_i)` and `∇φ_J(x_i)`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct NodalOperator {
    /// The columns of the whole operator (the nodes and their mirror
    /// images).
    pub columns: usize,
    /// The columns held: every one, or on one of several ranks the rank's
    /// part of them ([`NodalOperator::parts`]), the columns its passes
    /// compute.
    pub held: Range<usize>,
    /// Every rank's columns: contiguous, in rank order, balanced by their
    /// entries (a column's pass costs in proportion to them), the same on
    /// every rank ([`crate::ranks::weighted_parts`] of the shapes, which
    /// every rank holds whole). One part, every column, alone.
    pub parts: Vec<Range<usize>>,
    /// Row `J` is `offsets[J - held.start]..offsets[J - held.start + 1]`.
    pub offsets: Vec<usize>,
    /// The nodes `i` whose shapes name `J`, ascending in each row.
    pub nodes: Vec<usize>,
    /// `∇φ_J(x_i)` (1/m).
    pub grad: Vec<[f64; 3]>,
    /// `φ_J(x_i)`.
    pub phi: Vec<f64>,
}

impl NodalOperator {
    /// The transpose of `shapes` over `columns ≥ shapes.len()` nodes (more
    /// with mirror images, `src/approx/mirror.rs`): a counting sort, rows in node
    /// order, each in ascending `i`.
    pub fn build(shapes: &NodalShapes, columns: usize) -> Self {
        let mut op = NodalOperator::default();
        op.rebuild(shapes, columns);
        op
    }

    /// [`NodalOperator::build`] into this operator's buffers (reused: no
    /// allocation unless the operator grows). The counting sort of
    /// [`transpose`], written straight into the operator: no list of
    /// entries beside it (BENCHMARKS.md, memory).
    pub fn rebuild(&mut self, shapes: &NodalShapes, columns: usize) {
        self.rebuild_on(&crate::ranks::Alone, shapes, columns);
    }

    /// [`NodalOperator::rebuild`] of this rank's part of the columns only
    /// ([`NodalOperator::parts`]): the columns that
    /// [`NodalOperator::apply_on`] and
    /// [`NodalOperator::defect_transpose_on`] compute on this rank.
    pub fn rebuild_on(
        &mut self,
        ranks: &dyn crate::ranks::Ranks,
        shapes: &NodalShapes,
        columns: usize,
    ) {
        let parts = if ranks.size() == 1 {
            std::iter::once(0..columns).collect()
        } else {
            // Equal shares of the rows left one rank waiting for the other
            // (`penetration` 8 across, quarter, 2 ranks: rank 1 waited
            // 5.2 s of 100 s at the forces' and the smoothing's gathers).
            let mut weight = vec![0usize; columns];
            for &j in &shapes.nodes {
                weight[j] += 1;
            }
            crate::ranks::weighted_parts(&weight, ranks.size())
        };
        self.rebuild_parts_on(ranks, shapes, columns, parts);
    }

    /// [`NodalOperator::rebuild_on`] with every rank's columns `parts`
    /// given (contiguous, in rank order, covering the columns). `shapes`
    /// need hold only the rows that name this rank's columns: an entry
    /// naming a node past the columns (a row this rank does not hold,
    /// `solver::mlpg3d::held`) is skipped.
    pub fn rebuild_parts_on(
        &mut self,
        ranks: &dyn crate::ranks::Ranks,
        shapes: &NodalShapes,
        columns: usize,
        parts: Vec<Range<usize>>,
    ) {
        self.columns = columns;
        self.parts = parts;
        self.held = self.parts[ranks.rank()].clone();
        column_offsets(shapes, self.held.clone(), &mut self.offsets);
        let entries = column_entries(shapes, &self.offsets, self.held.clone());
        let total = entries.len();
        refill(&mut self.nodes, total, 0);
        refill(&mut self.grad, total, [0.0; 3]);
        refill(&mut self.phi, total, 0.0);
        (&mut self.nodes, &mut self.grad, &mut self.phi, &entries)
            .into_par_iter()
            .for_each(|(node, grad, phi, &e)| {
                let (q, i) = entry_parts(e);
                (*node, *grad, *phi) = (i, shapes.grad[q], shapes.phi[q]);
            });
    }

    /// `out = Hᵀ y`, the transpose of the defect operator `H = I − Φ` with
    /// `(Φ v)_i = Σ_J φ_J(x_i) v_J`: `out_J = y_J − Σ_i φ_J(x_i) y_i`
    /// (`y_J = 0` for a column past `y`, a mirror image).
    pub fn defect_transpose(&self, y: &[[f64; 3]], out: &mut [[f64; 3]]) {
        self.defect_transpose_on(&crate::ranks::Alone, y, out);
    }

    /// [`NodalOperator::defect_transpose`] shared among `ranks`: each
    /// computes its share of the columns, then every rank holds them all
    /// (the same bits).
    pub fn defect_transpose_on(
        &self,
        ranks: &dyn crate::ranks::Ranks,
        y: &[[f64; 3]],
        out: &mut [[f64; 3]],
    ) {
        self.check_held(ranks, out.len());
        crate::ranks::each_row_in(ranks, &self.parts, out, |j, o| {
            let mut m = [0.0; 3];
            for q in self.column(j) {
                let (yi, p) = (y[self.nodes[q]], self.phi[q]);
                for c in 0..3 {
                    m[c] += p * yi[c];
                }
            }
            let own = y.get(j).copied().unwrap_or([0.0; 3]);
            *o = std::array::from_fn(|c| own[c] - m[c]);
        });
    }

    /// The forces `F_J = −Σ_i V_i σ_i · ∇φ_J(x_i)` of the stresses
    /// `stress` (`[xx, yy, zz, xy, yz, zx]`) on the nodal volumes
    /// `volume`, written into `out`.
    pub fn apply(&self, stress: &[[f64; 6]], volume: &[f64], out: &mut [[f64; 3]]) {
        self.apply_on(&crate::ranks::Alone, stress, volume, out);
    }

    /// [`NodalOperator::apply`] shared among `ranks`: each computes its
    /// share of the columns, then every rank holds them all (the same bits).
    pub fn apply_on(
        &self,
        ranks: &dyn crate::ranks::Ranks,
        stress: &[[f64; 6]],
        volume: &[f64],
        out: &mut [[f64; 3]],
    ) {
        self.check_held(ranks, out.len());
        crate::ranks::each_row_in(ranks, &self.parts, out, |j, f| {
            *f = [0.0; 3];
            for q in self.column(j) {
                let i = self.nodes[q];
                let (s, g, v) = (&stress[i], self.grad[q], volume[i]);
                for c in 0..3 {
                    f[c] -=
                        v * (s[VOIGT[c][0]] * g[0] + s[VOIGT[c][1]] * g[1] + s[VOIGT[c][2]] * g[2]);
                }
            }
        });
    }

    /// The entries of column `j` (one of [`NodalOperator::held`]).
    #[inline(always)]
    pub fn column(&self, j: usize) -> Range<usize> {
        let c = j - self.held.start;
        self.offsets[c]..self.offsets[c + 1]
    }

    /// The columns a pass over `columns` rows computes on this rank are
    /// the ones held: a fault otherwise, not input.
    fn check_held(&self, ranks: &dyn crate::ranks::Ranks, columns: usize) {
        assert!(
            self.columns == columns
                && self.parts.len() == ranks.size()
                && self.held == self.parts[ranks.rank()],
            "the nodal operator holds the columns its pass computes"
        );
    }

    /// Bytes held by the operator.
    pub fn bytes(&self) -> usize {
        self.offsets.capacity() * std::mem::size_of::<usize>()
            + self.nodes.capacity() * std::mem::size_of::<usize>()
            + self.grad.capacity() * std::mem::size_of::<[f64; 3]>()
            + self.phi.capacity() * std::mem::size_of::<f64>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::approx::mls::tests::{jittered_cube, uniform};
    use crate::approx::mls::{SupportParams, Supports};

    /// A jittered cube, its nodal shapes, random stresses, velocities and
    /// volumes.
    #[allow(clippy::type_complexity)]
    fn setup() -> (NodalShapes, Vec<[f64; 6]>, Vec<[f64; 3]>, Vec<f64>) {
        let pts = jittered_cube(6, 1e-3, 0.3, 11);
        let sup = Supports::compute(&pts, SupportParams::default()).unwrap();
        let shapes = NodalShapes::build(&pts, &sup).unwrap();
        let mut seed = 7u64;
        let mut r = |scale: f64| scale * (2.0 * uniform(&mut seed) - 1.0);
        let n = pts.len();
        let stress: Vec<[f64; 6]> = (0..n).map(|_| std::array::from_fn(|_| r(1e9))).collect();
        let vel: Vec<[f64; 3]> = (0..n).map(|_| std::array::from_fn(|_| r(100.0))).collect();
        let vol: Vec<f64> = (0..n).map(|_| 1e-9 * (1.0 + 0.5 * r(1.0))).collect();
        (shapes, stress, vel, vol)
    }

    /// The work of the forces is minus the stress power of the collocated
    /// gradients (eq. 4), to round-off: the operator is their adjoint.
    #[test]
    fn the_forces_do_the_work_of_the_stress_power() {
        let (shapes, stress, vel, vol) = setup();
        let n = vel.len();
        let op = NodalOperator::build(&shapes, shapes.len());
        let mut f = vec![[0.0; 3]; n];
        op.apply(&stress, &vol, &mut f);
        let mut l = vec![[[0.0; 3]; 3]; n];
        shapes.velocity_gradients(&vel, &mut l);
        let power: f64 = (0..n)
            .map(|i| {
                let s = &stress[i];
                let mut p = 0.0;
                for a in 0..3 {
                    for b in 0..3 {
                        p += s[VOIGT[a][b]] * l[i][a][b];
                    }
                }
                vol[i] * p
            })
            .sum();
        let work: f64 = (0..n)
            .map(|j| (0..3).map(|c| f[j][c] * vel[j][c]).sum::<f64>())
            .sum();
        // The scale of the terms summed: Σ V |σ| |L|.
        let scale: f64 = (0..n)
            .map(|i| {
                let s: f64 = stress[i].iter().map(|x| x * x).sum::<f64>().sqrt();
                let g: f64 = l[i].iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
                vol[i] * s * g
            })
            .sum();
        assert!(
            (work + power).abs() < 1e-12 * scale,
            "work {work:e}, stress power {power:e}, scale {scale:e}"
        );
        assert!(
            power.abs() > 1e-3 * scale,
            "a power far from zero is tested"
        );
    }

    /// The forces sum to zero (momentum is conserved), to round-off.
    #[test]
    fn the_forces_sum_to_zero() {
        let (shapes, stress, vel, vol) = setup();
        let n = vel.len();
        let op = NodalOperator::build(&shapes, shapes.len());
        let mut f = vec![[0.0; 3]; n];
        op.apply(&stress, &vol, &mut f);
        let largest = f.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        for c in 0..3 {
            let sum: f64 = f.iter().map(|x| x[c]).sum();
            assert!(sum.abs() < 1e-12 * largest * n as f64, "Σ F_{c} = {sum:e}");
        }
        assert!(largest > 0.0);
    }

    /// The transpose holds every entry of the shapes once, each row in
    /// ascending order.
    #[test]
    fn the_transpose_holds_the_shapes() {
        let (shapes, _, vel, _) = setup();
        let n = vel.len();
        let op = NodalOperator::build(&shapes, shapes.len());
        assert_eq!(op.nodes.len(), shapes.nodes.len());
        for j in 0..n {
            let row = op.column(j);
            assert!(op.nodes[row.clone()].windows(2).all(|w| w[0] < w[1]));
            for q in row {
                let i = op.nodes[q];
                let k = shapes
                    .row(i)
                    .find(|&k| shapes.nodes[k] == j)
                    .expect("the entry is in row i of the shapes");
                assert_eq!(shapes.grad[k], op.grad[q]);
                assert_eq!(shapes.phi[k], op.phi[q]);
            }
        }
    }

    /// The plain twin of [`transpose`]: the serial counting sort.
    fn serial_transpose(shapes: &NodalShapes, columns: usize) -> (Vec<usize>, Vec<u64>) {
        let mut offsets = vec![0; columns + 1];
        for &j in &shapes.nodes {
            offsets[j + 1] += 1;
        }
        for j in 0..columns {
            offsets[j + 1] += offsets[j];
        }
        let mut next = offsets.clone();
        let mut entries = vec![0; shapes.nodes.len()];
        for i in 0..shapes.len() {
            for q in shapes.row(i) {
                let j = shapes.nodes[q];
                entries[next[j]] = (q as u64) << 32 | i as u64;
                next[j] += 1;
            }
        }
        (offsets, entries)
    }

    /// The transpose on the pool (atomic cursors, then each column sorted)
    /// is its serial twin exactly, on 1, 2 and 5 threads, with columns past
    /// the rows (mirror images) left empty; the operator built from it
    /// holds the same entries.
    #[test]
    fn the_parallel_transpose_is_the_serial_one_on_any_threads() {
        let (shapes, _, _, _) = setup();
        let columns = shapes.len() + 7;
        let want = serial_transpose(&shapes, columns);
        for threads in [1, 2, 5] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let (got, op) = pool.install(|| {
                (
                    transpose(&shapes, columns),
                    NodalOperator::build(&shapes, columns),
                )
            });
            assert!(got == want, "{threads} threads");
            assert_eq!(op.offsets, want.0, "{threads} threads");
            for (k, &e) in want.1.iter().enumerate() {
                let (q, i) = entry_parts(e);
                assert_eq!(
                    (op.nodes[k], op.grad[k], op.phi[k]),
                    (i, shapes.grad[q], shapes.phi[q])
                );
            }
        }
    }

    /// Built on 2 and 3 ranks (threads standing in for MPI), each rank
    /// holds its share of the columns, as the whole operator has them, and
    /// the forces and the smoothing's transpose come out with the bits of
    /// one rank.
    #[test]
    fn each_rank_holds_its_columns_and_the_passes_keep_their_bits() {
        let (shapes, stress, vel, vol) = setup();
        let n = vel.len();
        let whole = NodalOperator::build(&shapes, n);
        let mut want_f = vec![[0.0; 3]; n];
        whole.apply(&stress, &vol, &mut want_f);
        let mut want_d = vec![[0.0; 3]; n];
        whole.defect_transpose(&vel, &mut want_d);
        for size in [2, 3] {
            crate::ranks::tests::on_threads(size, |ranks| {
                let mut op = NodalOperator::default();
                op.rebuild_on(ranks, &shapes, n);
                // Contiguous parts covering the columns, each within one
                // column's entries of an equal share of them.
                assert_eq!(op.held, op.parts[ranks.rank()]);
                assert_eq!(op.parts.len(), size);
                assert_eq!(op.parts[0].start, 0);
                assert_eq!(op.parts[size - 1].end, n);
                assert!(op.parts.windows(2).all(|w| w[0].end == w[1].start));
                let longest = (0..n).map(|j| whole.column(j).len()).max().unwrap();
                let share = whole.nodes.len() as f64 / size as f64;
                for p in &op.parts {
                    let entries = whole.offsets[p.end] - whole.offsets[p.start];
                    assert!(
                        (entries as f64 - share).abs() <= longest as f64,
                        "{size} ranks: {entries} entries against {share}"
                    );
                }
                assert_eq!(op.columns, n);
                for j in op.held.clone() {
                    let (mine, all) = (op.column(j), whole.column(j));
                    assert_eq!(op.nodes[mine.clone()], whole.nodes[all.clone()]);
                    assert_eq!(op.grad[mine.clone()], whole.grad[all.clone()]);
                    assert_eq!(op.phi[mine], whole.phi[all]);
                }
                let mut f = vec![[0.0; 3]; n];
                op.apply_on(ranks, &stress, &vol, &mut f);
                assert_eq!(f, want_f, "{size} ranks");
                let mut d = vec![[0.0; 3]; n];
                op.defect_transpose_on(ranks, &vel, &mut d);
                assert_eq!(d, want_d, "{size} ranks");
            });
        }
    }

    /// Each segment is visited once, with its index, whatever its length
    /// (empty ones included) and however many there are.
    #[test]
    fn every_segment_is_visited_once() {
        for count in [0usize, 1, 3, 256, 257, 1000] {
            // Lengths 0, 1, 2, 0, 1, 2, ...
            let offsets: Vec<usize> = (0..=count)
                .scan(0, |at, j| {
                    let start = *at;
                    *at += j % 3;
                    Some(start)
                })
                .collect();
            let mut data = vec![usize::MAX; offsets[count]];
            for_segments(&mut data, &offsets, &|j, seg| {
                assert_eq!(seg.len(), offsets[j + 1] - offsets[j]);
                seg.iter_mut().for_each(|x| *x = j);
            });
            for j in 0..count {
                assert!(data[offsets[j]..offsets[j + 1]].iter().all(|&x| x == j));
            }
        }
    }

    /// `H v = v − Φ v` at every node, by the shapes' rows.
    fn defect(shapes: &NodalShapes, v: &[[f64; 3]]) -> Vec<[f64; 3]> {
        (0..v.len())
            .map(|i| {
                let mut m = [0.0; 3];
                for q in shapes.row(i) {
                    for c in 0..3 {
                        m[c] += shapes.phi[q] * v[shapes.nodes[q]][c];
                    }
                }
                std::array::from_fn(|c| v[i][c] - m[c])
            })
            .collect()
    }

    fn dot(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (0..3).map(|c| x[c] * y[c]).sum::<f64>())
            .sum()
    }

    /// The order-2 smoothing's `Hᵀ` is the adjoint of `H`
    /// (`⟨Hᵀ y, v⟩ = ⟨y, H v⟩` to round-off), its columns sum to zero (the
    /// filter `M⁻¹ Hᵀ M H` conserves momentum), and the filter is zero on
    /// linear fields (the shapes reproduce them) and removes kinetic
    /// energy from any other: `⟨v, Hᵀ M H v⟩ = |H v|²_M ≥ 0`.
    #[test]
    fn the_smoothing_transpose_is_the_adjoint_of_the_defect() {
        let (shapes, _, vel, vol) = setup();
        let n = vel.len();
        let op = NodalOperator::build(&shapes, shapes.len());
        let mass: Vec<f64> = vol.iter().map(|v| 8000.0 * v).collect();
        let y: Vec<[f64; 3]> = (0..n).map(|i| vel[(7 * i + 3) % n]).collect();
        let mut hty = vec![[0.0; 3]; n];
        op.defect_transpose(&y, &mut hty);
        let hv = defect(&shapes, &vel);
        let (left, right) = (dot(&hty, &vel), dot(&y, &hv));
        let scale = dot(&y, &y).sqrt() * dot(&vel, &vel).sqrt();
        assert!(
            (left - right).abs() < 1e-12 * scale,
            "{left:e} against {right:e} (scale {scale:e})"
        );
        assert!(right.abs() > 1e-3 * scale, "a product far from zero");
        let largest = hty.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        for c in 0..3 {
            let sum: f64 = hty.iter().map(|x| x[c]).sum();
            assert!(
                sum.abs() < 1e-12 * largest * n as f64,
                "Σ (Hᵀ y)_{c} = {sum:e}"
            );
        }
        // A linear field: zero defect, so no change.
        let pts: Vec<[f64; 3]> = crate::approx::mls::tests::jittered_cube(6, 1e-3, 0.3, 11);
        let linear: Vec<[f64; 3]> = pts
            .iter()
            .map(|x| {
                [
                    3.0 + 2e3 * x[0] - 1e3 * x[2],
                    -1.0 + 5e2 * x[1],
                    4e3 * x[0] + 7e2 * x[1],
                ]
            })
            .collect();
        let h_lin = defect(&shapes, &linear);
        let top = linear.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(h_lin.iter().flatten().all(|x| x.abs() < 1e-10 * top));
        // The kinetic energy removed to first order in α.
        let mhv: Vec<[f64; 3]> = hv
            .iter()
            .zip(&mass)
            .map(|(w, m)| w.map(|c| m * c))
            .collect();
        op.defect_transpose(&mhv, &mut hty);
        let removed = dot(&vel, &hty);
        let norm: f64 = hv
            .iter()
            .zip(&mass)
            .map(|(w, m)| m * dot(&[*w], &[*w]))
            .sum();
        assert!(removed > 0.0 && (removed - norm).abs() < 1e-12 * norm);
    }
}
