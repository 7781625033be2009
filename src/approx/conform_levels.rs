//! A multilevel preconditioner for the conforming correction's system
//! ([`crate::approx::conform`]).
//!
//! The system `A μ = b` penalises, row by row, the part of the multipliers
//! that a linear fit over the row does not reproduce: a linear field (zero
//! on the surfaces) costs nothing inside the body, a smooth one costs the
//! square of its curvature. Jacobi's preconditioner sees one node at a
//! time, so the smooth modes converge slowly and the iterations grow as the
//! spacing shrinks (30, 64, 109, 173 from zero at 6, 10, 16, 20 nodes
//! across on `taylor3d`, BENCHMARKS.md).
//!
//! The levels take those modes. The inner nodes are grouped by the cells
//! of a grid (`CELL` row sizes a side): the first level's unknowns are, per
//! group, the linear functions over its nodes (1, x, y, z, orthonormal over
//! the nodes; fewer where the nodes do not span them), so that a linear
//! field, the near null space, is represented exactly. Each further level
//! groups the groups of the one before by a grid of twice the side, with
//! the linear functions of the larger group projected onto the smaller
//! groups' spaces. The operator of each level is the Galerkin product
//! `Pᵀ A P` of the level before (the first assembled from the rows of the
//! fine system without forming its entries); the last level, of at most
//! `COARSEST` groups, is factored by Cholesky.
//!
//! The preconditioner is `M⁻¹ r = D⁻¹ r + P₁ B₁ P₁ᵀ r`: Jacobi's diagonal on
//! the nodes plus the first level's correction. With one level, `B₁ =
//! A₁⁻¹` exactly (a fixed, symmetric, positive map: plain conjugate
//! gradients). With more, `B₁ r₁` comes from conjugate gradients on the
//! first level, stopped at `INNER_TOLERANCE` of the start, each preconditioned
//! by one symmetric V-cycle through the levels below (block-Jacobi
//! smoothing damped by Gershgorin's bound before and after the next
//! level's correction); the map is then not quite linear, and the outer
//! iterations take the flexible form of β (`conform`). Chosen by
//! measurement (docs/notes/2026-11-30-conforming-levels.md): the additive
//! sum of the levels took 36 iterations from zero at 10 across, V-cycles
//! alone 19-28, the inner iterations 16 (the exact first level: 15).
//!
//! The same scalar operator acts on each of the three components of the
//! multipliers, so one hierarchy serves the three. Every sum runs in a
//! fixed order: the same bits for any number of threads.

use crate::approx::buffers::filled;
use crate::approx::mls::NodalShapes;
use crate::approx::nodal::entry_parts;
use crate::approx::nodal::for_segments;
use crate::calibrate::linalg::{Mat, cholesky, cholesky_solve, symmetric_eigen};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering};

/// A 4 × 4 block: the linear functions of two groups.
type Block = [[f64; 4]; 4];

/// Three components of the four functions of a group.
type Coarse = [[f64; 3]; 4];

/// The grid cell of the first level, in row sizes (the median distance
/// from a node to the farthest node of its row).
const CELL: f64 = 2.0;

/// Where the first level's inner iterations stop: the residual's
/// preconditioned norm relative to its start.
const INNER_TOLERANCE: f64 = 0.1;

/// The most inner iterations of the first level.
const INNER_ITERATIONS: usize = 50;

/// The cycles of each coarse level's solve.
const CYCLES: usize = 1;

/// The smoothing's damping against Gershgorin's bound ([`omega`]).
const SMOOTHING: f64 = 1.5;

/// The most groups of the last level, factored by Cholesky.
const COARSEST: usize = 160;

/// The smallest eigenvalue kept, relative to the largest, when a group's
/// functions are made orthonormal: below it the group's nodes do not span
/// that function.
const RANK_FLOOR: f64 = 1e-8;

/// The fine system's parts that the levels are built from (those of
/// `conform::System`).
pub(crate) struct Fine<'a> {
    /// The rows and their nodes.
    pub shapes: &'a NodalShapes,
    /// The nodes' positions.
    pub points: &'a [[f64; 3]],
    /// The nodal volumes `V_i`.
    pub volume: &'a [f64],
    /// The nodes whose multipliers are unknowns.
    pub inner: &'a [bool],
    /// `G_i` of each row.
    pub g: &'a [Block],
    /// The transpose's column starts and entries (`q << 32 | i`).
    pub col_offsets: &'a [usize],
    /// The transpose's entries.
    pub col_entries: &'a [u64],
    /// `D_J = Σ_i V_i²` over column `J` (zero off the inner nodes).
    pub d: &'a [f64],
    /// The ranks that share the first level's operator
    /// ([`crate::ranks`]).
    pub ranks: &'a dyn crate::ranks::Ranks,
}

/// `(1, (x − centre) / h)`.
#[inline(always)]
fn monomials(x: [f64; 3], centre: [f64; 3], h: f64) -> [f64; 4] {
    [
        1.0,
        (x[0] - centre[0]) / h,
        (x[1] - centre[1]) / h,
        (x[2] - centre[2]) / h,
    ]
}

fn transpose(a: &Block) -> Block {
    std::array::from_fn(|r| std::array::from_fn(|c| a[c][r]))
}

fn mul(a: &Block, b: &Block) -> Block {
    std::array::from_fn(|r| std::array::from_fn(|c| (0..4).map(|k| a[r][k] * b[k][c]).sum()))
}

/// `aᵀ b`.
fn tmul(a: &Block, b: &Block) -> Block {
    std::array::from_fn(|r| std::array::from_fn(|c| (0..4).map(|k| a[k][r] * b[k][c]).sum()))
}

fn add_to(a: &mut Block, b: &Block, f: f64) {
    for r in 0..4 {
        for c in 0..4 {
            a[r][c] += f * b[r][c];
        }
    }
}

/// `T` with `Tᵀ m T = I` on the functions that `m` (a Gram matrix) spans,
/// zero columns for the others, and the rank.
fn orthonormal(m: &Block) -> (Block, usize) {
    let mut mat = Mat::zeros(4, 4);
    for r in 0..4 {
        for c in 0..4 {
            mat[(r, c)] = m[r][c];
        }
    }
    let (values, vectors) = symmetric_eigen(&mat);
    let largest = values.iter().copied().fold(0.0, f64::max);
    let mut t = [[0.0; 4]; 4];
    let mut rank = 0;
    // The columns in the order of the eigenvalues, largest first.
    let mut order: Vec<usize> = (0..4).collect();
    order.sort_by(|&a, &b| values[b].total_cmp(&values[a]));
    for &k in &order {
        if largest > 0.0 && values[k] > RANK_FLOOR * largest {
            let s = 1.0 / values[k].sqrt();
            for (r, row) in t.iter_mut().enumerate() {
                row[rank] = vectors[(r, k)] * s;
            }
            rank += 1;
        }
    }
    (t, rank)
}

/// The inverse of a block whose unused functions (past `rank`) carry 1 on
/// the diagonal; `None` if it is not positive definite.
fn invert(b: &Block) -> Option<Block> {
    let mut m = Mat::zeros(4, 4);
    for r in 0..4 {
        for c in 0..4 {
            m[(r, c)] = b[r][c];
        }
    }
    let l = cholesky(&m)?;
    let mut inv = [[0.0; 4]; 4];
    for c in 0..4 {
        let e: Vec<f64> = (0..4).map(|r| if r == c { 1.0 } else { 0.0 }).collect();
        let x = cholesky_solve(&l, &e);
        for r in 0..4 {
            inv[r][c] = x[r];
        }
    }
    Some(inv)
}

/// Groups by the cells of side `h` of the points `x` (those with `Some`):
/// each point's group (`u32::MAX` for `None`), and the groups' members,
/// ascending, as offsets and indices. The groups are numbered in the order
/// of their cells.
fn group(x: &[Option<[f64; 3]>], h: f64) -> (Vec<u32>, Vec<usize>, Vec<usize>) {
    let lo = x.iter().flatten().fold([f64::INFINITY; 3], |m, p| {
        [m[0].min(p[0]), m[1].min(p[1]), m[2].min(p[2])]
    });
    let cell = |p: [f64; 3]| -> u64 {
        let k = |d: usize| (((p[d] - lo[d]) / h).floor().max(0.0) as u64).min(0x1f_ffff);
        (k(0) << 42) | (k(1) << 21) | k(2)
    };
    // Every point keyed (those without a cell last), so that the collect
    // is indexed and written on the pool; then the keyless cut off.
    let mut keys: Vec<(u64, usize)> = x
        .par_iter()
        .enumerate()
        .map(|(j, p)| (p.map_or(u64::MAX, cell), j))
        .collect();
    keys.par_sort_unstable();
    let with = keys.partition_point(|&(key, _)| key != u64::MAX);
    keys.truncate(with);
    // On the pool: at 10^6 nodes a serial numbering was a serial part of
    // every build (each entry is its own: the same result in any order).
    let mut offsets: Vec<usize> = (0..keys.len())
        .into_par_iter()
        .filter(|&k| k == 0 || keys[k].0 != keys[k - 1].0)
        .collect();
    if !keys.is_empty() {
        offsets.push(keys.len());
    } else {
        offsets.push(0);
    }
    let members: Vec<usize> = keys.par_iter().map(|&(_, j)| j).collect();
    let of: Vec<AtomicU32> = (0..x.len())
        .into_par_iter()
        .map(|_| AtomicU32::new(u32::MAX))
        .collect();
    offsets.par_windows(2).enumerate().for_each(|(g, w)| {
        for &j in &members[w[0]..w[1]] {
            of[j].store(g as u32, Ordering::Relaxed);
        }
    });
    let of = of.into_par_iter().map(AtomicU32::into_inner).collect();
    (of, offsets, members)
}

/// A symmetric operator of 4 × 4 blocks, row by row (`cols` ascending).
struct Blocks {
    offsets: Vec<usize>,
    cols: Vec<usize>,
    blocks: Vec<Block>,
}

impl Blocks {
    fn rows(&self) -> usize {
        self.offsets.len() - 1
    }

    fn of(rows: Vec<Vec<(usize, Block)>>) -> Blocks {
        let mut offsets = Vec::with_capacity(rows.len() + 1);
        offsets.push(0);
        for row in &rows {
            offsets.push(offsets.last().copied().unwrap_or(0) + row.len());
        }
        // Filled on the pool, row by row (the first level's blocks are
        // tens of megabytes at 10^6 nodes).
        let total = offsets.last().copied().unwrap_or(0);
        let mut cols = filled(total, 0usize);
        let mut blocks = filled(total, [[0.0; 4]; 4]);
        for_segments(&mut cols, &offsets, &|r, out| {
            for (o, e) in out.iter_mut().zip(&rows[r]) {
                *o = e.0;
            }
        });
        for_segments(&mut blocks, &offsets, &|r, out| {
            for (o, e) in out.iter_mut().zip(&rows[r]) {
                *o = e.1;
            }
        });
        Blocks {
            offsets,
            cols,
            blocks,
        }
    }

    fn diagonal(&self, a: usize) -> &Block {
        let k = (self.offsets[a]..self.offsets[a + 1])
            .find(|&k| self.cols[k] == a)
            .expect("every group couples to itself");
        &self.blocks[k]
    }
}

/// One coarse level: its groups of the level before (or of the nodes),
/// the map from its unknowns to the level before's, and its operator.
struct Level {
    /// The members of each group (nodes, or groups of the level before).
    offsets: Vec<usize>,
    members: Vec<usize>,
    /// Each group's orthonormal basis `T` (the first level: over the
    /// monomials about its centre; further levels: the prolongation's
    /// blocks are in `to_finer`).
    t: Vec<Block>,
    /// Each group's centre and cell size (the first level's monomials).
    centre: Vec<[f64; 3]>,
    /// Further levels: the block `P_{a,A}` of each member `a` (by member
    /// position).
    to_finer: Vec<Block>,
    /// Further levels: each group of the level before, its parent and
    /// its position among the members.
    parent: Vec<(usize, usize)>,
    /// The operator.
    a: Blocks,
    /// The inverted diagonal blocks.
    dinv: Vec<Block>,
    /// The damping of the smoothing ([`omega`]).
    omega: f64,
    /// The last level: the Cholesky factor of the whole operator.
    factor: Option<Mat>,
}

/// The multilevel preconditioner of one build of the system.
pub(crate) struct Levels {
    levels: Vec<Level>,
    jacobi: Vec<f64>,
    /// Each node's group of the first level (`u32::MAX` off the inner
    /// nodes).
    group_of: Vec<u32>,
    /// Each inner node's monomials about its group's centre.
    mono: Vec<[f64; 4]>,
}

/// The first level's group-wise data: its groups of inner nodes, each
/// group's centre, node count, Gram `M_a` and `T_a`.
struct Grouping {
    of: Vec<u32>,
    offsets: Vec<usize>,
    members: Vec<usize>,
    centre: Vec<[f64; 3]>,
    count: Vec<f64>,
    gram: Vec<Block>,
    t: Vec<Block>,
    rank: Vec<usize>,
}

fn grouping(points: &[[f64; 3]], inner: &[bool], h: f64) -> Grouping {
    let x: Vec<Option<[f64; 3]>> = (0..inner.len())
        .into_par_iter()
        .map(|j| inner[j].then_some(points[j]))
        .collect();
    let (of, offsets, members) = group(&x, h);
    let groups = offsets.len().saturating_sub(1);
    let per: Vec<([f64; 3], f64, Block, Block, usize)> = (0..groups)
        .into_par_iter()
        .map(|a| {
            let m = &members[offsets[a]..offsets[a + 1]];
            let mut c = [0.0; 3];
            for &j in m {
                for d in 0..3 {
                    c[d] += points[j][d];
                }
            }
            let c = c.map(|v| v / m.len() as f64);
            let mut gram = [[0.0; 4]; 4];
            for &j in m {
                let u = monomials(points[j], c, h);
                for r in 0..4 {
                    for s in 0..4 {
                        gram[r][s] += u[r] * u[s];
                    }
                }
            }
            let (t, rank) = orthonormal(&gram);
            (c, m.len() as f64, gram, t, rank)
        })
        .collect();
    Grouping {
        of,
        offsets,
        members,
        centre: per.iter().map(|p| p.0).collect(),
        count: per.iter().map(|p| p.1).collect(),
        gram: per.iter().map(|p| p.2).collect(),
        t: per.iter().map(|p| p.3).collect(),
        rank: per.iter().map(|p| p.4).collect(),
    }
}

/// Sets 1 on the diagonal of the unused functions of a group (past its
/// rank): they decouple, and their right-hand side is always zero.
fn pad(b: &mut Block, rank: usize) {
    for (k, row) in b.iter_mut().enumerate().skip(rank) {
        row[k] = 1.0;
    }
}

/// The first level's operator `P₁ᵀ A P₁`, block row by block row: for group
/// `a`, every row `i` that holds one of its nodes (ascending) adds
/// `−V_i² W_{i,a}ᵀ G_i W_{i,b}` for each group `b` of its inner nodes, with
/// `W_{i,b} = Σ_{J ∈ row i ∩ b} u_J^{(i)} m_b(J)ᵀ`; the diagonal block
/// adds `Σ_{J ∈ a} D_J m_a(J) m_a(J)ᵀ`; then each block is taken to the
/// orthonormal bases, `T_aᵀ (·) T_b`.
fn first_operator(f: &Fine, gr: &Grouping, h: f64) -> Blocks {
    let groups = gr.centre.len();
    let s = f.shapes;
    // Each rank builds the block rows of its share of the groups; the rows
    // then travel to every rank (the same bits).
    let ranks = f.ranks;
    let own = crate::ranks::share(groups, ranks.rank(), ranks.size(), 1);
    let mut rows: Vec<Vec<(usize, Block)>> = vec![Vec::new(); groups];
    let first = own.start;
    rows[own].par_iter_mut().enumerate().for_each(|(k, row)| {
        let a = first + k;
        *row = {
            let nodes = &gr.members[gr.offsets[a]..gr.offsets[a + 1]];
            let mut touching: Vec<usize> = nodes
                .iter()
                .flat_map(|&j| {
                    (f.col_offsets[j]..f.col_offsets[j + 1])
                        .map(|k| entry_parts(f.col_entries[k]).1)
                })
                .collect();
            touching.sort_unstable();
            touching.dedup();
            let mut acc: Vec<(usize, Block)> = vec![(a, [[0.0; 4]; 4])];
            let mut w: Vec<(usize, Block)> = Vec::new();
            for &i in &touching {
                w.clear();
                let xi = f.points[i];
                for q in s.row(i) {
                    let j = s.nodes[q];
                    let b = match gr.of.get(j) {
                        Some(&b) if b != u32::MAX => b as usize,
                        _ => continue,
                    };
                    let xj = f.points[j];
                    let u = [1.0, xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]];
                    let m = monomials(xj, gr.centre[b], h);
                    let k = match w.iter().position(|e| e.0 == b) {
                        Some(k) => k,
                        None => {
                            w.push((b, [[0.0; 4]; 4]));
                            w.len() - 1
                        }
                    };
                    let blk = &mut w[k].1;
                    for r in 0..4 {
                        for c in 0..4 {
                            blk[r][c] += u[r] * m[c];
                        }
                    }
                }
                let Some(wa) = w.iter().find(|e| e.0 == a).map(|e| e.1) else {
                    continue;
                };
                let v2 = f.volume[i] * f.volume[i];
                let y = mul(&f.g[i], &wa);
                for (b, wb) in &w {
                    let contribution = tmul(&y, wb);
                    let k = match acc.iter().position(|e| e.0 == *b) {
                        Some(k) => k,
                        None => {
                            acc.push((*b, [[0.0; 4]; 4]));
                            acc.len() - 1
                        }
                    };
                    add_to(&mut acc[k].1, &contribution, -v2);
                }
            }
            // The diagonal term.
            let mut diag = [[0.0; 4]; 4];
            for &j in nodes {
                let m = monomials(f.points[j], gr.centre[a], h);
                for r in 0..4 {
                    for c in 0..4 {
                        diag[r][c] += f.d[j] * m[r] * m[c];
                    }
                }
            }
            add_to(&mut acc[0].1, &diag, 1.0);
            acc.sort_by_key(|e| e.0);
            acc.into_iter()
                .map(|(b, raw)| {
                    let mut blk = tmul(&gr.t[a], &mul(&raw, &gr.t[b]));
                    if b == a {
                        pad(&mut blk, gr.rank[a]);
                    }
                    (b, blk)
                })
                .collect()
        };
    });
    if ranks.size() > 1 {
        let parts = crate::ranks::shares(ranks, groups, 1);
        crate::ranks::gather_encoded(ranks, &parts, &mut rows, Vec::clone, |slot, row| {
            *slot = row
        });
    }
    Blocks::of(rows)
}

/// The inverted diagonal blocks of `a` (a block that is not positive
/// definite, which round-off could make of a nearly dependent group, is
/// left out: zero).
fn diagonal_inverses(a: &Blocks) -> Vec<Block> {
    (0..a.rows())
        .into_par_iter()
        .map(|r| invert(a.diagonal(r)).unwrap_or([[0.0; 4]; 4]))
        .collect()
}

/// The Cholesky factor of the whole of `a` (small), or `None` if it is not
/// positive definite.
fn factor(a: &Blocks) -> Option<Mat> {
    let n = 4 * a.rows();
    let mut m = Mat::zeros(n, n);
    for r in 0..a.rows() {
        for k in a.offsets[r]..a.offsets[r + 1] {
            let c = a.cols[k];
            for x in 0..4 {
                for y in 0..4 {
                    m[(4 * r + x, 4 * c + y)] = a.blocks[k][x][y];
                }
            }
        }
    }
    // Symmetrise: the two triangles were summed in different orders.
    for r in 0..n {
        for c in 0..r {
            let v = 0.5 * (m[(r, c)] + m[(c, r)]);
            m[(r, c)] = v;
            m[(c, r)] = v;
        }
    }
    cholesky(&m)
}

/// The next level from `a` (its groups' centres, node counts, Grams in
/// their own spaces `C_aᵀ`-form, and side `h`): groups of groups by cells of
/// side `2h`, the prolongation's blocks and the Galerkin operator. Returns
/// the level and the new groups' centres, counts and `C` (the coefficients
/// of each group's monomials in its basis, `Tᵀ M`).
fn coarsen(
    a: &Blocks,
    centre: &[[f64; 3]],
    count: &[f64],
    c: &[Block],
    h: f64,
) -> (Level, Vec<[f64; 3]>, Vec<f64>, Vec<Block>) {
    let hc = 2.0 * h;
    let x: Vec<Option<[f64; 3]>> = centre.iter().map(|&p| Some(p)).collect();
    let (of, offsets, members) = group(&x, hc);
    let parents = offsets.len() - 1;
    // Per parent: its centre (the node-weighted mean of its children's),
    // node count, the children's `Ĉ = C_a Lᵀ`, `M_A = Σ Ĉᵀ Ĉ`, `T_A`, `C_A`.
    type Parent = ([f64; 3], f64, Vec<Block>, Block, usize, Block);
    let per: Vec<Parent> = (0..parents)
        .into_par_iter()
        .map(|p| {
            let kids = &members[offsets[p]..offsets[p + 1]];
            let n: f64 = kids.iter().map(|&k| count[k]).sum();
            let mut xc = [0.0; 3];
            for &k in kids {
                for d in 0..3 {
                    xc[d] += count[k] * centre[k][d];
                }
            }
            let xc = xc.map(|v| v / n);
            let hats: Vec<Block> = kids
                .iter()
                .map(|&k| {
                    // u_A = L u_a.
                    let mut l = [[0.0; 4]; 4];
                    l[0][0] = 1.0;
                    for d in 0..3 {
                        l[1 + d][0] = (centre[k][d] - xc[d]) / hc;
                        l[1 + d][1 + d] = h / hc;
                    }
                    mul(&c[k], &transpose(&l))
                })
                .collect();
            let mut gram = [[0.0; 4]; 4];
            for hat in &hats {
                add_to(&mut gram, &tmul(hat, hat), 1.0);
            }
            let (t, rank) = orthonormal(&gram);
            let cc = tmul(&t, &gram);
            let p_blocks = hats.iter().map(|hat| mul(hat, &t)).collect();
            (xc, n, p_blocks, t, rank, cc)
        })
        .collect();
    let mut to_finer = vec![[[0.0; 4]; 4]; members.len()];
    for (p, (_, _, blocks, _, _, _)) in per.iter().enumerate() {
        to_finer[offsets[p]..offsets[p + 1]].copy_from_slice(blocks);
    }
    // Where each child sits among its parent's members.
    let mut position = vec![0usize; centre.len()];
    for (k, &m) in members.iter().enumerate() {
        position[m] = k;
    }
    let rows: Vec<Vec<(usize, Block)>> = (0..parents)
        .into_par_iter()
        .map(|p| {
            let mut acc: Vec<(usize, Block)> = Vec::new();
            for k in offsets[p]..offsets[p + 1] {
                let child = members[k];
                let pa = &to_finer[k];
                for e in a.offsets[child]..a.offsets[child + 1] {
                    let b = a.cols[e];
                    let parent_b = of[b] as usize;
                    let contribution = tmul(pa, &mul(&a.blocks[e], &to_finer[position[b]]));
                    match acc.iter_mut().find(|x| x.0 == parent_b) {
                        Some(x) => add_to(&mut x.1, &contribution, 1.0),
                        None => acc.push((parent_b, contribution)),
                    }
                }
            }
            acc.sort_by_key(|e| e.0);
            for e in acc.iter_mut() {
                if e.0 == p {
                    pad(&mut e.1, per[p].4);
                }
            }
            acc
        })
        .collect();
    let op = Blocks::of(rows);
    let level = Level {
        offsets,
        members,
        t: per.iter().map(|p| p.3).collect(),
        centre: per.iter().map(|p| p.0).collect(),
        parent: (0..centre.len())
            .map(|k| (of[k] as usize, position[k]))
            .collect(),
        to_finer,
        dinv: Vec::new(),
        omega: 0.0,
        a: op,
        factor: None,
    };
    let centres = per.iter().map(|p| p.0).collect();
    let counts = per.iter().map(|p| p.1).collect();
    let cs = per.iter().map(|p| p.5).collect();
    (level, centres, counts, cs)
}

impl Levels {
    /// The hierarchy of one build of the fine system `f`, with its Jacobi
    /// diagonal `jacobi` (`A_JJ`, zero off the inner nodes); `None` when it
    /// has no inner node or a level's operator is not positive definite
    /// (the solver then keeps Jacobi's preconditioner).
    pub(crate) fn new(f: &Fine, jacobi: Vec<f64>) -> Option<Levels> {
        let n = f.shapes.len();
        // The median row size.
        let mut sizes: Vec<f64> = (0..n)
            .into_par_iter()
            .map(|i| {
                let xi = f.points[i];
                f.shapes
                    .row(i)
                    .map(|q| {
                        let x = f.points[f.shapes.nodes[q]];
                        let d = [x[0] - xi[0], x[1] - xi[1], x[2] - xi[2]];
                        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
                    })
                    .fold(0.0, f64::max)
            })
            .collect();
        if sizes.is_empty() || !f.inner.iter().any(|&b| b) {
            return None;
        }
        sizes.par_sort_unstable_by(f64::total_cmp);
        let h = CELL * sizes[sizes.len() / 2];
        if !(h > 0.0 && h.is_finite()) {
            return None;
        }
        let gr = grouping(f.points, f.inner, h);
        let a1 = first_operator(f, &gr, h);
        let c1: Vec<Block> = gr.t.iter().zip(&gr.gram).map(|(t, m)| tmul(t, m)).collect();
        let group_of = gr.of;
        let mut levels = vec![Level {
            offsets: gr.offsets,
            members: gr.members,
            t: gr.t,
            centre: gr.centre.clone(),
            to_finer: Vec::new(),
            parent: Vec::new(),
            dinv: Vec::new(),
            omega: 0.0,
            a: a1,
            factor: None,
        }];
        let (mut centre, mut count, mut c, mut side) = (gr.centre, gr.count, c1, h);
        while levels.last().expect("one level").a.rows() > COARSEST {
            let last = levels.last().expect("one level");
            let (next, centres, counts, cs) = coarsen(&last.a, &centre, &count, &c, side);
            if next.a.rows() >= last.a.rows() {
                break;
            }
            levels.push(next);
            centre = centres;
            count = counts;
            c = cs;
            side *= 2.0;
        }
        let k = levels.len();
        for (l, level) in levels.iter_mut().enumerate() {
            if l + 1 == k {
                level.factor = Some(factor(&level.a)?);
            } else {
                level.dinv = diagonal_inverses(&level.a);
                level.omega = omega(&level.a, &level.dinv);
            }
        }
        let first = &levels[0];
        let mono = (0..n)
            .into_par_iter()
            .map(|j| match group_of.get(j) {
                Some(&a) if a != u32::MAX => monomials(f.points[j], first.centre[a as usize], h),
                _ => [0.0; 4],
            })
            .collect();
        Some(Levels {
            levels,
            jacobi,
            group_of,
            mono,
        })
    }

    /// The groups of each level, the first level's first.
    pub(crate) fn sizes(&self) -> Vec<usize> {
        self.levels.iter().map(|l| l.a.rows()).collect()
    }

    /// Whether the map is linear (one level); otherwise the outer
    /// conjugate gradients must be flexible.
    pub(crate) fn linear(&self) -> bool {
        self.levels.len() == 1
    }

    /// `z = M⁻¹ r` on the inner nodes (`z_J = 0` elsewhere).
    pub(crate) fn apply(&self, r: &[[f64; 3]], z: &mut [[f64; 3]]) {
        let first = &self.levels[0];
        // r₁ = P₁ᵀ r: per group, T_aᵀ Σ_J m_a(J) r_Jᵀ.
        let groups = first.a.rows();
        let r1: Vec<Coarse> = (0..groups)
            .into_par_iter()
            .map(|a| {
                let mut s = [[0.0; 3]; 4];
                for &j in &first.members[first.offsets[a]..first.offsets[a + 1]] {
                    let m = self.mono[j];
                    for (b, sb) in s.iter_mut().enumerate() {
                        for d in 0..3 {
                            sb[d] += m[b] * r[j][d];
                        }
                    }
                }
                times_t(&first.t[a], &s)
            })
            .collect();
        let z1 = if self.levels.len() == 1 {
            self.solve(0, &r1)
        } else {
            self.inner_cg(&r1)
        };
        // z = D⁻¹ r, then z += P₁ z₁ (T_a z₁ per group, read at each node).
        let tz: Vec<Coarse> = (0..groups)
            .into_par_iter()
            .map(|a| times(&first.t[a], &z1[a]))
            .collect();
        let group_of = &self.group_of;
        z.par_iter_mut().enumerate().for_each(|(j, zj)| {
            let a = group_of[j];
            if a == u32::MAX || self.jacobi[j].is_nan() || self.jacobi[j] <= 0.0 {
                *zj = [0.0; 3];
                return;
            }
            let a = a as usize;
            let m = self.mono[j];
            *zj = std::array::from_fn(|d| {
                r[j][d] / self.jacobi[j] + (0..4).map(|b| m[b] * tz[a][b][d]).sum::<f64>()
            });
        });
    }

    /// `B_l r` of level `l`: `CYCLES` iterations of the symmetric V-cycle
    /// from zero (the last level solved exactly). Each cycle smooths with
    /// `ω D_l⁻¹` before and after the next level's correction: a fixed,
    /// symmetric and positive map that approximates `A_l⁻¹` (the first
    /// level's inner iterations are preconditioned by it).
    fn solve(&self, l: usize, r: &[Coarse]) -> Vec<Coarse> {
        let level = &self.levels[l];
        if let Some(factor) = &level.factor {
            let n = r.len();
            let mut out = vec![[[0.0; 3]; 4]; n];
            for d in 0..3 {
                let b: Vec<f64> = (0..4 * n).map(|k| r[k / 4][k % 4][d]).collect();
                let x = cholesky_solve(factor, &b);
                for (k, v) in x.into_iter().enumerate() {
                    out[k / 4][k % 4][d] = v;
                }
            }
            return out;
        }
        let mut x = filled(r.len(), [[0.0; 3]; 4]);
        for cycle in 0..CYCLES {
            let res = if cycle == 0 {
                copied(r)
            } else {
                level.residual(r, &x)
            };
            let dx = self.cycle(l, &res);
            add_coarse(&mut x, &dx, 1.0);
        }
        x
    }

    /// The first level's system solved by conjugate gradients, each
    /// iteration preconditioned by [`Levels::solve`], until the residual
    /// falls below `INNER_TOLERANCE` of the start (or `INNER_ITERATIONS`):
    /// close to `A₁⁻¹ r`, though no longer a fixed linear map (the outer
    /// iterations are flexible).
    fn inner_cg(&self, r: &[Coarse]) -> Vec<Coarse> {
        let level = &self.levels[0];
        // Summed on the pool in a fixed order (`crate::approx::sums`).
        let dot = |a: &[Coarse], b: &[Coarse]| -> f64 {
            crate::approx::sums::sum(a.len().min(b.len()), |g| {
                let (x, y) = (&a[g], &b[g]);
                (0..4)
                    .map(|k| (0..3).map(|d| x[k][d] * y[k][d]).sum::<f64>())
                    .sum::<f64>()
            })
        };
        // The level's vectors are made on the pool (copies of a few
        // megabytes at 10^6 nodes, several an outer iteration).
        let mut x = filled(r.len(), [[0.0; 3]; 4]);
        let mut res = copied(r);
        let mut z = self.solve(0, &res);
        let mut p = copied(&z);
        let mut rz = dot(&res, &z);
        let start = rz;
        for _ in 0..INNER_ITERATIONS {
            if rz.is_nan() || rz <= INNER_TOLERANCE * INNER_TOLERANCE * start {
                break;
            }
            let ap = level.product(&p);
            let pap = dot(&p, &ap);
            if pap.is_nan() || pap <= 0.0 {
                break;
            }
            let alpha = rz / pap;
            add_coarse(&mut x, &p, alpha);
            add_coarse(&mut res, &ap, -alpha);
            z = self.solve(0, &res);
            let rz_new = dot(&res, &z);
            let beta = rz_new / rz;
            rz = rz_new;
            p.par_iter_mut().zip(&z).for_each(|(p, z)| {
                for k in 0..4 {
                    for d in 0..3 {
                        p[k][d] = z[k][d] + beta * p[k][d];
                    }
                }
            });
        }
        x
    }

    /// One symmetric V-cycle of level `l` on `r` from zero.
    fn cycle(&self, l: usize, r: &[Coarse]) -> Vec<Coarse> {
        let level = &self.levels[l];
        let next = &self.levels[l + 1];
        let smooth = |res: &[Coarse]| -> Vec<Coarse> {
            (0..res.len())
                .into_par_iter()
                .map(|a| times(&level.dinv[a], &res[a]).map(|v| v.map(|x| level.omega * x)))
                .collect()
        };
        let mut x = smooth(r);
        let res = level.residual(r, &x);
        // The next level's right-hand side: Σ over each parent's members
        // of P_{a,A}ᵀ res_a.
        let parents = next.a.rows();
        let rc: Vec<Coarse> = (0..parents)
            .into_par_iter()
            .map(|p| {
                let mut s = [[0.0; 3]; 4];
                for k in next.offsets[p]..next.offsets[p + 1] {
                    let t = times_t(&next.to_finer[k], &res[next.members[k]]);
                    for b in 0..4 {
                        for d in 0..3 {
                            s[b][d] += t[b][d];
                        }
                    }
                }
                s
            })
            .collect();
        let zc = self.solve(l + 1, &rc);
        // The correction: each member a of parent A gets P_{a,A} z_A.
        x.par_iter_mut().enumerate().for_each(|(a, xa)| {
            let (p, k) = next.parent[a];
            let add = times(&next.to_finer[k], &zc[p]);
            for b in 0..4 {
                for d in 0..3 {
                    xa[b][d] += add[b][d];
                }
            }
        });
        let res = level.residual(r, &x);
        let dx = smooth(&res);
        add_coarse(&mut x, &dx, 1.0);
        x
    }
}

impl Level {
    /// `A x`, row by row (the negative of [`Level::residual`] from zero,
    /// to the bit: each sum is the same sum of the same terms).
    fn product(&self, x: &[Coarse]) -> Vec<Coarse> {
        let a = &self.a;
        (0..a.rows())
            .into_par_iter()
            .map(|i| {
                let mut y = [[0.0; 3]; 4];
                for k in a.offsets[i]..a.offsets[i + 1] {
                    let ax = times(&a.blocks[k], &x[a.cols[k]]);
                    for b in 0..4 {
                        for d in 0..3 {
                            y[b][d] += ax[b][d];
                        }
                    }
                }
                y
            })
            .collect()
    }

    /// `r − A x`, row by row.
    fn residual(&self, r: &[Coarse], x: &[Coarse]) -> Vec<Coarse> {
        let a = &self.a;
        (0..a.rows())
            .into_par_iter()
            .map(|i| {
                let mut y = r[i];
                for k in a.offsets[i]..a.offsets[i + 1] {
                    let ax = times(&a.blocks[k], &x[a.cols[k]]);
                    for b in 0..4 {
                        for d in 0..3 {
                            y[b][d] -= ax[b][d];
                        }
                    }
                }
                y
            })
            .collect()
    }
}

/// A copy of `x`, made on the pool.
fn copied(x: &[Coarse]) -> Vec<Coarse> {
    x.par_iter().copied().collect()
}

/// `x += f y`.
fn add_coarse(x: &mut [Coarse], y: &[Coarse], f: f64) {
    x.par_iter_mut().zip(y).for_each(|(x, y)| {
        for b in 0..4 {
            for d in 0..3 {
                x[b][d] += f * y[b][d];
            }
        }
    });
}

/// The damping of the block-Jacobi smoothing: `SMOOTHING / ρ` with `ρ`
/// Gershgorin's bound on the spectral radius of `D⁻¹ A` (the largest sum
/// of the absolute values of a row of `D_a⁻¹ A_ab`), so that the smoothing
/// contracts in the energy norm.
fn omega(a: &Blocks, dinv: &[Block]) -> f64 {
    let rho = (0..a.rows())
        .into_par_iter()
        .map(|r| {
            let mut sums = [0.0f64; 4];
            for k in a.offsets[r]..a.offsets[r + 1] {
                let m = mul(&dinv[r], &a.blocks[k]);
                for (x, row) in m.iter().enumerate() {
                    sums[x] += row.iter().map(|v| v.abs()).sum::<f64>();
                }
            }
            sums.into_iter().fold(0.0, f64::max)
        })
        .reduce(|| 0.0, f64::max);
    if rho > 0.0 && rho.is_finite() {
        SMOOTHING / rho
    } else {
        0.0
    }
}

/// `t x`.
fn times(t: &Block, x: &Coarse) -> Coarse {
    std::array::from_fn(|r| std::array::from_fn(|d| (0..4).map(|k| t[r][k] * x[k][d]).sum()))
}

/// `tᵀ x`.
fn times_t(t: &Block, x: &Coarse) -> Coarse {
    std::array::from_fn(|r| std::array::from_fn(|d| (0..4).map(|k| t[k][r] * x[k][d]).sum()))
}
