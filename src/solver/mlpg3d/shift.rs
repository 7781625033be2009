//! Node shifting for the 3-D MLPG solver: the 3-D form of the axisymmetric
//! solver's particle shifting (`src/solver/axisymmetric/shift.rs`; README, "Particle
//! shifting"). Pairs of nodes closer than a fraction of the initial spacing
//! push each other apart, relative to the material, and a moved node takes
//! the fields of its new place by a first-order Taylor expansion with the
//! MLS gradients of the last build (exact for linear fields), each carried
//! value limited to the range of the values over the nodes that cover it.
//!
//! Lagrangian nodes follow the material's stretch, e^(−ε) along the axis at
//! the impact face, and the Wilkins copper bar (plastic strain near 2 at
//! the face) presses its second layer of nodes onto the face layer: the
//! continuum itself leaves e^(−1.93) = 0.145 of a layer spacing where the
//! spacing guard stops at 0.1. Shifting lets the crowded nodes rearrange
//! instead (README, "3-D MLPG mixed method").

use crate::approx::mls::NodalShapes;
use rayon::prelude::*;

/// The directions a node may shift in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Freedom {
    /// It stays where the material takes it (the surfaces, which carry the
    /// boundary conditions and the rod's outline).
    Fixed,
    /// Across the unit normal only (the component along it is removed): a
    /// node pressed on the anvil moves in the anvil's plane.
    InPlane([f64; 3]),
    /// In any direction; the node also sees its own mirror image across
    /// the anvil plane z = 0, which pushes it off the anvil as any other
    /// node would (the images of the other nodes are never closer to a node
    /// above the anvil than the nodes themselves, so they are left out).
    Free,
    /// In any direction, in a run with no anvil (no image, no plane).
    Unbounded,
}

/// [`shifts_on`] on one rank alone (the tests' form).
#[allow(clippy::too_many_arguments)]
#[cfg(test)]
pub fn shifts(
    pos: &[[f64; 3]],
    shapes: &NodalShapes,
    free: &[Freedom],
    spacing: f64,
    range: f64,
    beta: f64,
    cap: f64,
    out: &mut [[f64; 3]],
) {
    shifts_on(
        (&crate::ranks::Alone, std::slice::from_ref(&(0..out.len()))),
        pos,
        shapes,
        free,
        (spacing, range, beta, cap),
        (out, &mut Vec::new()),
    );
}

/// The shift of each node: `beta D Σ_j (1 − r_ij / l)² e_ij` over the nodes
/// `j` of row `i` of `shapes` (the nodes whose supports covered `x_i` at the
/// last build, a superset of those within `l`) closer than `l = range` now
/// (`e_ij` the unit vector from `j` to `i`, `D = spacing`; the tuple is `(spacing, range, beta, cap)`), projected on the
/// directions the node is free in, limited to `cap` in length and so that
/// the node does not pass below the anvil plane. Written into `out`; nodes
/// in parallel, each from the positions before any moves (the same bits for
/// any number of threads). Shared among `ranks`: each computes its part
/// of the nodes (`parts`, contiguous, in rank order, covering them), then
/// every rank holds them all (the same bits); only the shifts that are not
/// zero travel, through `wire` (kept by the caller), since few nodes shift
/// at a step ([`crate::ranks::each_row_sparse`]).
pub fn shifts_on(
    (ranks, parts): (&dyn crate::ranks::Ranks, &[std::ops::Range<usize>]),
    pos: &[[f64; 3]],
    shapes: &NodalShapes,
    free: &[Freedom],
    (spacing, range, beta, cap): (f64, f64, f64, f64),
    (out, wire): (&mut [[f64; 3]], &mut Vec<[f64; 3]>),
) {
    let range2 = range * range;
    crate::ranks::each_row_sparse(ranks, parts, (out, wire), |i, d| {
        *d = [0.0; 3];
        if free[i] == Freedom::Fixed {
            return;
        }
        let xi = pos[i];
        let mut push = |xj: [f64; 3]| {
            let a: [f64; 3] = std::array::from_fn(|k| xi[k] - xj[k]);
            let r2 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
            if r2 > 0.0 && r2 < range2 {
                let r = r2.sqrt();
                let w = beta * spacing * (1.0 - r / range).powi(2) / r;
                for k in 0..3 {
                    d[k] += w * a[k];
                }
            }
        };
        for q in shapes.row(i) {
            let j = shapes.nodes[q];
            if j != i {
                push(pos[j]);
            }
        }
        match free[i] {
            Freedom::Free => push([xi[0], xi[1], -xi[2]]),
            Freedom::InPlane(n) => {
                let dn = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
                for k in 0..3 {
                    d[k] -= dn * n[k];
                }
            }
            Freedom::Unbounded => {}
            Freedom::Fixed => unreachable!("returned above"),
        }
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if len > cap {
            *d = d.map(|x| x * cap / len);
        }
        if free[i] != Freedom::Unbounded && xi[2] + d[2] < 0.0 {
            d[2] = -xi[2];
        }
    });
}

/// [`carry_shifted_on`] on one rank alone, at every node (the tests'
/// form: a node without a shift keeps `f_i`).
#[cfg(test)]
pub fn carry<const K: usize>(
    shapes: &NodalShapes,
    f: &[[f64; K]],
    d: &[[f64; 3]],
    out: &mut [[f64; K]],
) {
    for (i, o) in out.iter_mut().enumerate() {
        *o = carried_at(shapes, f, d, i);
    }
}

/// `f_i + d_i · ∇f_i` for the nodes with a shift `d_i`, written into
/// `out`: `∇f_i = Σ_J ∇φ_J(x_i) f_J` over row `i` of `shapes` (the
/// collocated MLS gradient of eq. 4, exact for linear fields), each of the
/// `K` components limited to the range of its values over the node and the
/// nodes of its row. Without the limit an ill-conditioned gradient (a node
/// with its neighbours all to one side) extrapolates without bound, and
/// shifting repeats it step after step (the axisymmetric solver measured
/// 1060 plastic strain at one particle of test 7 at 600 m/s; README,
/// "Particle shifting"). Nodes in parallel, from `f` before any moves.
///
/// Only the shifted nodes (`d_i` not zero), the only rows a shift's
/// unpacking reads: each rank computes the shifted nodes of its part of
/// `parts` (as [`shifts_on`]'s), and only their rows travel among the
/// ranks ([`crate::ranks::gather_listed`], through `wire`, kept by the
/// caller from one call to the next); the other rows of `out` are left as
/// they were. Every rank holds every node's shift, so every rank makes the
/// same lists without a message, and the bits are those of one rank.
pub fn carry_shifted_on<const K: usize>(
    (ranks, parts): (&dyn crate::ranks::Ranks, &[std::ops::Range<usize>]),
    shapes: &NodalShapes,
    f: &[[f64; K]],
    d: &[[f64; 3]],
    (out, wire): (&mut [[f64; K]], &mut Vec<[f64; K]>),
) where
    [f64; K]: Default,
{
    let lists: Vec<Vec<usize>> = parts
        .iter()
        .map(|p| p.clone().filter(|&i| d[i] != [0.0; 3]).collect())
        .collect();
    let mine = &lists[ranks.rank()];
    let values: Vec<[f64; K]> = mine
        .par_iter()
        .map(|&i| carried_at(shapes, f, d, i))
        .collect();
    for (&i, v) in mine.iter().zip(values) {
        out[i] = v;
    }
    let get = |o: &[[f64; K]], i: usize| o[i];
    let put = |o: &mut [[f64; K]], i: usize, v: &[f64; K]| o[i] = *v;
    crate::ranks::gather_listed(ranks, &lists, wire, out, (get, put));
}

/// Node `i`'s carried value: `f_i + d_i · ∇f_i`, limited to the range
/// over its row ([`carry_shifted_on`]), or `f_i` where it has no shift.
fn carried_at<const K: usize>(
    shapes: &NodalShapes,
    f: &[[f64; K]],
    d: &[[f64; 3]],
    i: usize,
) -> [f64; K] {
    let di = d[i];
    if di == [0.0; 3] {
        return f[i];
    }
    let (mut lo, mut hi) = (f[i], f[i]);
    let mut g = [[0.0; 3]; K];
    for q in shapes.row(i) {
        let (fj, gq) = (&f[shapes.nodes[q]], shapes.grad[q]);
        for c in 0..K {
            lo[c] = lo[c].min(fj[c]);
            hi[c] = hi[c].max(fj[c]);
            for k in 0..3 {
                g[c][k] += fj[c] * gq[k];
            }
        }
    }
    std::array::from_fn(|c| {
        let step = di[0] * g[c][0] + di[1] * g[c][1] + di[2] * g[c][2];
        (f[i][c] + step).clamp(lo[c], hi[c])
    })
}

/// The conservative form of [`carry_shifted_on`] for a field whose amount at a node
/// is `w_i f_i` (the momentum: `w` the masses, `f` the velocities): the
/// increment a shifted node takes is drawn from the nodes of its row, pair
/// by pair, so that the field's total amount `Σ w f` stays what it was to
/// round-off. Node `i` with a shift `d_i` takes
/// `t_iJ = w_i θ_i (d_i · ∇φ_J(x_i)) (f_J − f_i)` from each node `J` of its
/// row: in all `w_i θ_i d_i · ∇f_i` (the limited Taylor increment of
/// [`carry_shifted_on`], `θ_i` in `[0, 1]` its limit's share, per component, and
/// `Σ_J ∇φ_J = 0`), and `J` gives up the same `t_iJ`. A node that does not
/// shift keeps its value in [`carry_shifted_on`]; here it pays its share of its
/// shifted neighbours' increments (at most `w_i / w_J` times theirs,
/// spread over the row). `f` and `w` cover the columns of `shapes` (real
/// nodes and mirror images), `d` its rows; `delta` (resized to the
/// columns) receives the change of each column's amount, the images' to be
/// folded back onto their nodes; `share` is a buffer for the `θ_i`, reused
/// from call to call. The rows' limits in parallel, the pairs in row order
/// (the same bits for any number of threads).
pub fn exchange<const K: usize>(
    shapes: &NodalShapes,
    f: &[[f64; K]],
    w: &[f64],
    d: &[[f64; 3]],
    share: &mut Vec<Option<[f64; K]>>,
    delta: &mut Vec<[f64; K]>,
) {
    d.par_iter()
        .enumerate()
        .map(|(i, di)| {
            if *di == [0.0; 3] {
                return None;
            }
            let (mut lo, mut hi) = (f[i], f[i]);
            let mut inc = [0.0; K];
            for q in shapes.row(i) {
                let fj = &f[shapes.nodes[q]];
                let a = dot(*di, shapes.grad[q]);
                for c in 0..K {
                    lo[c] = lo[c].min(fj[c]);
                    hi[c] = hi[c].max(fj[c]);
                    inc[c] += a * (fj[c] - f[i][c]);
                }
            }
            Some(std::array::from_fn(|c| {
                let limited = (f[i][c] + inc[c]).clamp(lo[c], hi[c]) - f[i][c];
                if inc[c] == 0.0 {
                    0.0
                } else {
                    (limited / inc[c]).clamp(0.0, 1.0)
                }
            }))
        })
        .collect_into_vec(share);
    delta.clear();
    delta.resize(f.len(), [0.0; K]);
    for (i, theta) in share.iter().enumerate() {
        let Some(theta) = theta else { continue };
        for q in shapes.row(i) {
            let j = shapes.nodes[q];
            let a = w[i] * dot(d[i], shapes.grad[q]);
            for c in 0..K {
                let t = a * theta[c] * (f[j][c] - f[i][c]);
                delta[i][c] += t;
                delta[j][c] -= t;
            }
        }
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::approx::mls::tests::jittered_cube;
    use crate::approx::mls::{SupportParams, Supports};

    fn shapes_of(pts: &[[f64; 3]]) -> NodalShapes {
        let sup = Supports::compute(pts, SupportParams::default()).unwrap();
        NodalShapes::build(pts, &sup).unwrap()
    }

    /// A linear field (and a vector of them) carried by a shift takes its
    /// value at the new place, to round-off, on a jittered lattice; the
    /// nodes without a shift keep theirs.
    #[test]
    fn a_linear_field_is_carried_exactly() {
        let pts = jittered_cube(6, 1.0, 0.2, 7);
        let shapes = shapes_of(&pts);
        let lin = |x: [f64; 3]| -> [f64; 2] {
            [
                2.0 + 3.0 * x[0] - 5.0 * x[1] + 0.5 * x[2],
                -x[0] + 0.25 * x[1] + 4.0 * x[2],
            ]
        };
        let f: Vec<[f64; 2]> = pts.iter().map(|&x| lin(x)).collect();
        let mut d = vec![[0.0; 3]; pts.len()];
        // Interior nodes (the ends of the range would be the limit).
        let moved = [43, 86, 129];
        for (k, &i) in moved.iter().enumerate() {
            d[i] = [0.03, -0.02 * k as f64, 0.04];
        }
        let mut out = vec![[0.0; 2]; pts.len()];
        carry(&shapes, &f, &d, &mut out);
        for i in 0..pts.len() {
            let x: [f64; 3] = std::array::from_fn(|k| pts[i][k] + d[i][k]);
            let want = lin(x);
            for c in 0..2 {
                if d[i] == [0.0; 3] {
                    assert_eq!(out[i][c], f[i][c]);
                } else {
                    assert!((out[i][c] - want[c]).abs() < 1e-12, "{i} {c}");
                    assert_ne!(out[i][c], f[i][c]);
                }
            }
        }
    }

    /// The carry of the shifted nodes only, on 1, 2 and 3 ranks (threads,
    /// parts unequal): every rank's shifted rows hold [`carry`]'s bits,
    /// and every other row keeps what the rank held (a mark of the rank).
    #[test]
    fn the_shifted_rows_carry_the_bits_of_one_rank_and_the_rest_stay() {
        let pts = jittered_cube(6, 1.0, 0.2, 7);
        let n = pts.len();
        let shapes = shapes_of(&pts);
        let mut rand = crate::test_rng::rng(99);
        let f: Vec<[f64; 2]> = (0..n).map(|_| [rand(), 10.0 * rand()]).collect();
        let d: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                if i % 7 == 3 {
                    std::array::from_fn(|_| 0.06 * (rand() - 0.5))
                } else {
                    [0.0; 3]
                }
            })
            .collect();
        let mut want = vec![[0.0; 2]; n];
        carry(&shapes, &f, &d, &mut want);
        for size in [1, 2, 3] {
            let parts: Vec<_> = (0..size)
                .map(|r| {
                    (r * n / (size + 1))..(if r + 1 == size {
                        n
                    } else {
                        (r + 1) * n / (size + 1)
                    })
                })
                .collect();
            let got = crate::ranks::tests::on_threads(size, |ranks| {
                let mark = -(ranks.rank() as f64) - 1.0;
                let mut out = vec![[mark; 2]; n];
                let mut wire = Vec::new();
                carry_shifted_on((ranks, &parts), &shapes, &f, &d, (&mut out, &mut wire));
                (mark, out)
            });
            for (mark, out) in got {
                for i in 0..n {
                    if d[i] == [0.0; 3] {
                        assert_eq!(out[i], [mark; 2], "{size} ranks, row {i}");
                    } else {
                        assert_eq!(out[i].map(f64::to_bits), want[i].map(f64::to_bits));
                        assert_ne!(out[i], f[i], "row {i} moved");
                    }
                }
            }
        }
    }

    /// The conservative carry moves momentum between nodes and creates
    /// none: a field with a nonzero total (a drift of 100 with ±30 of
    /// noise per component, masses 0.5 to 1.5), shifts at a fifth of the
    /// nodes (some at the cube's surface, where the limit acts), and the
    /// total `Σ m v` before and after agrees to round-off (1e-13 of
    /// `Σ m |v|`). Alone, an interior node of a linear field takes the
    /// Taylor increment of [`carry`] (to 1e-12), and a uniform field does
    /// not change at all.
    #[test]
    fn the_conservative_carry_keeps_the_total_to_round_off() {
        let pts = jittered_cube(6, 1.0, 0.2, 7);
        let n = pts.len();
        let shapes = shapes_of(&pts);
        let mut rand = crate::test_rng::rng(12345);
        let f: Vec<[f64; 3]> = (0..n)
            .map(|_| std::array::from_fn(|c| 100.0 * (c as f64 - 1.0) + 60.0 * (rand() - 0.5)))
            .collect();
        let w: Vec<f64> = (0..n).map(|_| 0.5 + rand()).collect();
        let d: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                if i % 5 == 0 {
                    std::array::from_fn(|_| 0.06 * (rand() - 0.5))
                } else {
                    [0.0; 3]
                }
            })
            .collect();
        let (mut share, mut delta) = (Vec::new(), Vec::new());
        exchange(&shapes, &f, &w, &d, &mut share, &mut delta);
        let scale: f64 = (0..n)
            .map(|i| w[i] * f[i].iter().map(|x| x.abs()).sum::<f64>())
            .sum();
        let moved: f64 = delta.iter().flatten().map(|x| x.abs()).sum();
        assert!(moved > 1e-3 * scale, "the shifts moved {moved} of {scale}");
        for c in 0..3 {
            let total: f64 = delta.iter().map(|p| p[c]).sum();
            assert!(
                total.abs() < 1e-13 * scale,
                "component {c}: {total} of {scale}"
            );
        }
        // One interior node of a linear field: the Taylor increment.
        let lin =
            |x: [f64; 3]| -> [f64; 3] { [2.0 + 3.0 * x[0] - 5.0 * x[1], -x[0] + 4.0 * x[2], 7.0] };
        let f: Vec<[f64; 3]> = pts.iter().map(|&x| lin(x)).collect();
        let i = 86;
        let mut d = vec![[0.0; 3]; n];
        d[i] = [0.03, -0.02, 0.04];
        exchange(&shapes, &f, &w, &d, &mut share, &mut delta);
        let x: [f64; 3] = std::array::from_fn(|k| pts[i][k] + d[i][k]);
        for c in 0..3 {
            let want = lin(x)[c] - f[i][c];
            assert!((delta[i][c] / w[i] - want).abs() < 1e-12, "{c}");
        }
        assert!(
            delta.iter().all(|p| p[2] == 0.0),
            "the uniform component moved"
        );
    }

    /// A kink with its minimum on a node: the one-sided gradient there would
    /// carry the value below every value around it; the limit keeps it at
    /// the smallest.
    #[test]
    fn a_carried_value_stays_within_the_range_around_it() {
        let pts = jittered_cube(7, 1.0, 0.0, 1);
        let shapes = shapes_of(&pts);
        let i = 3 + 7 * 3 + 49 * 3;
        let z0 = pts[i][2];
        let f: Vec<[f64; 1]> = pts
            .iter()
            .map(|x| {
                let dz = x[2] - z0;
                [if dz >= 0.0 { dz } else { -40.0 * dz }]
            })
            .collect();
        let mut d = vec![[0.0; 3]; pts.len()];
        d[i] = [0.0, 0.0, 0.05];
        let g: f64 = shapes
            .row(i)
            .map(|q| f[shapes.nodes[q]][0] * shapes.grad[q][2])
            .sum();
        assert!(f[i][0] + 0.05 * g < 0.0, "the gradient is one-sided: {g}");
        let mut out = vec![[0.0; 1]; pts.len()];
        carry(&shapes, &f, &d, &mut out);
        assert_eq!(out[i][0], 0.0);
    }

    /// On a lattice at its spacing nobody moves; a node brought to 0.2 of
    /// the spacing above another is pushed away by `beta D (1 − 0.2 / 0.5)²`
    /// and the other the opposite way; the cap, a fixed node and a node in
    /// the anvil's plane hold.
    #[test]
    fn close_pairs_push_apart_and_distant_ones_do_not() {
        let mut pts = jittered_cube(5, 1.0, 0.0, 1);
        for p in &mut pts {
            p[2] += 1.0;
        }
        let shapes = shapes_of(&pts);
        let n = pts.len();
        let free = vec![Freedom::Free; n];
        let (beta, range) = (0.1, 0.5);
        let mut d = vec![[1.0; 3]; n];
        shifts(&pts, &shapes, &free, 1.0, range, beta, 1.0, &mut d);
        assert!(d.iter().all(|d| *d == [0.0; 3]));
        // Node b = (2, 2, 3) brought to 0.2 above a = (2, 2, 2).
        let (a, b) = (2 + 5 * 2 + 25, 2 + 5 * 2 + 50);
        pts[b][2] = pts[a][2] + 0.2;
        shifts(&pts, &shapes, &free, 1.0, range, beta, 1.0, &mut d);
        let push = beta * (1.0f64 - 0.2 / 0.5).powi(2);
        assert!((d[b][2] - push).abs() < 1e-15 && d[b][0] == 0.0 && d[b][1] == 0.0);
        assert!((d[a][2] + push).abs() < 1e-15 && d[a][0] == 0.0 && d[a][1] == 0.0);
        assert!(
            d.iter()
                .enumerate()
                .all(|(i, d)| i == a || i == b || *d == [0.0; 3])
        );
        shifts(&pts, &shapes, &free, 1.0, range, beta, 0.01, &mut d);
        assert!((d[b][2] - 0.01).abs() < 1e-15);
        let mut some = free.clone();
        some[a] = Freedom::Fixed;
        some[b] = Freedom::InPlane([0.0, 0.0, 1.0]);
        shifts(&pts, &shapes, &some, 1.0, range, beta, 1.0, &mut d);
        assert_eq!((d[a], d[b]), ([0.0; 3], [0.0; 3]));
    }

    /// A free node near the anvil is pushed up by its own image, and a node
    /// pushed toward the anvil stops on its plane.
    #[test]
    fn the_anvil_pushes_by_the_image_and_is_not_passed() {
        let mut pts = jittered_cube(5, 1.0, 0.0, 1);
        let shapes = shapes_of(&pts);
        let n = pts.len();
        let mut free = vec![Freedom::Fixed; n];
        let (a, b) = (2 + 5 * 2, 2 + 5 * 2 + 25);
        free[a] = Freedom::Free;
        // a at 0.1 above the anvil: its image is 0.2 away.
        pts[a][2] = 0.1;
        let mut d = vec![[0.0; 3]; n];
        shifts(&pts, &shapes, &free, 1.0, 0.5, 0.1, 1.0, &mut d);
        let push = 0.1 * (1.0f64 - 0.2 / 0.5).powi(2);
        assert!((d[a][2] - push).abs() < 1e-15, "{:?}", d[a]);
        // b brought to 0.01 above a at 0.05: b pushes a down by 0.96 and
        // its image up by 0.64, past the plane, where it stops.
        pts[a][2] = 0.05;
        pts[b][2] = 0.06;
        shifts(&pts, &shapes, &free, 1.0, 0.5, 1.0, 1.0, &mut d);
        assert_eq!(d[a][2], -0.05);
    }
}
