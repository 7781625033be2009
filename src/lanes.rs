//! Arithmetic on lanes of [`W`] values, written as plain loops over
//! fixed-size arrays that the compiler turns into vector instructions: the
//! Gaussian of many pairs at once ([`exp`]), the moment matrices of [`W`]
//! particles inverted together ([`invert`]), and sums over neighbours in
//! [`W`] partial sums ([`gather`], [`total`]).
//!
//! Every lane operation is an IEEE add, multiply, fused multiply-add
//! ([`mul_add`]), divide, compare or select, each correctly rounded, and
//! every sum runs in a fixed order, so the results are the same bit for bit
//! whatever instruction set runs them (BENCHMARKS.md). A clone without
//! hardware FMA computes the fused operation in software: the same bits,
//! slower.

/// Number of lanes: eight doubles, one AVX-512 register.
pub const W: usize = 8;

/// A lane of [`W`] doubles.
pub type Lanes = [f64; W];

/// `1.5 * 2^52`: adding it rounds a double of magnitude below `2^51` to the
/// nearest integer, which then sits in the low bits of the sum.
const ROUND_MAGIC: f64 = 6_755_399_441_055_744.0;

/// `ln 2` split so that `k * LN2_HI` is exact for `|k| < 2^11`.
const LN2_HI: f64 = 6.931_471_803_691_238e-1;
const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;

/// `1 / k!` for `k = 0..=13`, the Taylor coefficients of `exp` on the
/// reduced interval `|r| <= ln(2) / 2`, where the truncation error is below
/// `5e-18` relative.
const INV_FACTORIAL: [f64; 14] = [
    1.0,
    1.0,
    0.5,
    1.0 / 6.0,
    1.0 / 24.0,
    1.0 / 120.0,
    1.0 / 720.0,
    1.0 / 5040.0,
    1.0 / 40320.0,
    1.0 / 362_880.0,
    1.0 / 3_628_800.0,
    1.0 / 39_916_800.0,
    1.0 / 479_001_600.0,
    1.0 / 6_227_020_800.0,
];

/// `exp(x)` of each lane, for `-700 <= x <= 700` (the callers pass
/// `x = -|s|^2` with `|s| <= 2`). Within 2 ulp of the correctly rounded value
/// (tested against the standard library), branch-free: `x = k ln 2 + r` with
/// `k` the nearest integer to `x / ln 2`, a degree-13 Taylor polynomial of
/// `exp(r)` (Estrin's scheme), and `2^k` built in the exponent bits.
#[inline(always)]
pub fn exp(x: Lanes) -> Lanes {
    let mut out = [0.0; W];
    for l in 0..W {
        let t = x[l] * std::f64::consts::LOG2_E + ROUND_MAGIC;
        let k = t - ROUND_MAGIC;
        let r = (x[l] - k * LN2_HI) - k * LN2_LO;
        // Estrin's scheme: eight operations deep instead of Horner's 26.
        let c = &INV_FACTORIAL;
        let (r2, pair) = (r * r, |k: usize| c[k + 1].mul_add(r, c[k]));
        let r4 = r2 * r2;
        let lo = pair(6)
            .mul_add(r2, pair(4))
            .mul_add(r4, pair(2).mul_add(r2, pair(0)));
        let hi = pair(12).mul_add(r4, pair(10).mul_add(r2, pair(8)));
        let p = hi.mul_add(r4 * r4, lo);
        // The low bits of `t` hold `k` (two's complement over the magic).
        let ki = t.to_bits().wrapping_sub(ROUND_MAGIC.to_bits());
        let scale = f64::from_bits(ki.wrapping_add(1023) << 52);
        out[l] = p * scale;
    }
    out
}

/// `if m { a } else { b }` lane by lane.
#[inline(always)]
pub fn select(m: [bool; W], a: Lanes, b: Lanes) -> Lanes {
    std::array::from_fn(|l| if m[l] { a[l] } else { b[l] })
}

/// The `K` components of `f` at the [`W`] indices `idx`, one lane per
/// component.
#[inline(always)]
pub fn gather<const K: usize>(f: &[[f64; K]], idx: &[u32; W]) -> [Lanes; K] {
    let mut out = [[0.0; W]; K];
    for l in 0..W {
        let x = f[idx[l] as usize];
        for k in 0..K {
            out[k][l] = x[k];
        }
    }
    out
}

/// The values of `f` at the [`W`] indices `idx`.
#[inline(always)]
pub fn gather1(f: &[f64], idx: &[u32; W]) -> Lanes {
    idx.map(|j| f[j as usize])
}

/// A square matrix of lanes: lane `l` of every entry is matrix `l`.
pub type LaneMatrix<const N: usize> = [[Lanes; N]; N];

/// True when every lane of `m` holds.
#[inline(always)]
fn all(m: [bool; W]) -> bool {
    m.iter().all(|&x| x)
}

/// Swaps `x` and `y` in the lanes where `m` holds.
#[inline(always)]
fn swap_where(m: [bool; W], x: &mut Lanes, y: &mut Lanes) {
    let (a, b) = (*x, *y);
    *x = select(m, b, a);
    *y = select(m, a, b);
}

/// Inverts the [`W`] matrices held in the lanes of `a` (row-major) in place
/// by Gauss-Jordan elimination with partial pivoting, each lane choosing its
/// own pivots (the row interchanges are undone on the columns at the end).
/// Returns the inverses and, per lane, whether a pivot vanished or was not
/// finite (the inverse of such a lane is meaningless).
#[inline(always)]
pub fn invert<const N: usize>(a: LaneMatrix<N>) -> (LaneMatrix<N>, [bool; W]) {
    let mut a = a;
    let mut pivot_row = [[0.0; W]; N];
    let mut singular = [false; W];
    for k in 0..N {
        // Pivot search: the first largest magnitude in the column.
        let mut best = a[k][k];
        let mut at = [k as f64; W];
        for r in k + 1..N {
            let x = a[r][k];
            let m: [bool; W] = std::array::from_fn(|l| x[l].abs() > best[l].abs());
            best = select(m, x, best);
            at = select(m, [r as f64; W], at);
        }
        pivot_row[k] = at;
        // Most batches keep the diagonal pivot in every lane.
        if !all(at.map(|x| x == k as f64)) {
            for r in k + 1..N {
                let m: [bool; W] = at.map(|x| x == r as f64);
                let (upper, lower) = a.split_at_mut(r);
                for c in 0..N {
                    swap_where(m, &mut upper[k][c], &mut lower[0][c]);
                }
            }
        }
        let mut d = [0.0; W];
        for l in 0..W {
            let bad = best[l] == 0.0 || !best[l].is_finite();
            singular[l] |= bad;
            // A failed lane goes on with a unit pivot; its result is unused.
            d[l] = 1.0 / if bad { 1.0 } else { best[l] };
        }
        a[k][k] = [1.0; W];
        for c in 0..N {
            for l in 0..W {
                a[k][c][l] *= d[l];
            }
        }
        for r in 0..N {
            if r == k {
                continue;
            }
            let f = a[r][k];
            a[r][k] = [0.0; W];
            for c in 0..N {
                for l in 0..W {
                    a[r][c][l] -= f[l] * a[k][c][l];
                }
            }
        }
    }
    // Undo the row interchanges on the columns, last first.
    for k in (0..N).rev() {
        let at = pivot_row[k];
        if all(at.map(|x| x == k as f64)) {
            continue;
        }
        for c in k + 1..N {
            let m: [bool; W] = at.map(|x| x == c as f64);
            for row in a.iter_mut() {
                let (left, right) = row.split_at_mut(c);
                swap_where(m, &mut left[k], &mut right[0]);
            }
        }
    }
    (a, singular)
}

/// `x` in every lane.
#[inline(always)]
pub fn splat(x: f64) -> Lanes {
    [x; W]
}

/// `a + b` lane by lane.
#[inline(always)]
pub fn add(a: Lanes, b: Lanes) -> Lanes {
    std::array::from_fn(|l| a[l] + b[l])
}

/// `a - b` lane by lane.
#[inline(always)]
pub fn sub(a: Lanes, b: Lanes) -> Lanes {
    std::array::from_fn(|l| a[l] - b[l])
}

/// `a * b` lane by lane.
#[inline(always)]
pub fn mul(a: Lanes, b: Lanes) -> Lanes {
    std::array::from_fn(|l| a[l] * b[l])
}

/// `a * b + c` lane by lane with a single rounding (a fused multiply-add,
/// an exactly specified IEEE operation: the same bits on every instruction
/// set, in hardware where the clone has FMA, in software otherwise).
#[inline(always)]
pub fn mul_add(a: Lanes, b: Lanes, c: Lanes) -> Lanes {
    std::array::from_fn(|l| a[l].mul_add(b[l], c[l]))
}

/// `c - a * b` lane by lane with a single rounding.
#[inline(always)]
pub fn neg_mul_add(a: Lanes, b: Lanes, c: Lanes) -> Lanes {
    std::array::from_fn(|l| (-a[l]).mul_add(b[l], c[l]))
}

/// Runs `$body` once for each listed value, with `$v` a constant of that
/// value, so that the loops inside have constant bounds and unroll.
macro_rules! unroll {
    ($v:ident in [$($n:literal),*] $body:block) => {
        $({
            #[allow(non_upper_case_globals)]
            const $v: usize = $n;
            $body
        })*
    };
}
pub(crate) use unroll;

/// `d` where it exceeds `floor`, else 1; and whether it did not (including a
/// NaN).
#[inline(always)]
fn pivot_above(d: Lanes, floor: Lanes) -> (Lanes, [bool; W]) {
    let ok: [bool; W] = std::array::from_fn(|l| d[l] > floor[l]);
    (select(ok, d, [1.0; W]), ok.map(|x| !x))
}

/// Inverts the [`W`] symmetric positive definite 6×6 matrices held in the
/// lanes of `g` (only the lower triangle, `g[r][c]` with `r >= c`, is read) by
/// an `L D L^T` factorisation without pivoting, then `G^-1 = L^-T D^-1 L^-1`.
/// No lane needs a row interchange, so the elimination has no branch.
///
/// Returns the (full, symmetric) inverses and, per lane, whether a pivot
/// `D_j` failed to exceed `min_pivot` times its diagonal entry `G_jj`: the
/// matrix is then not positive definite, too close to singular for this
/// elimination to be accurate, or holds a NaN, and the inverse of that lane
/// is meaningless (a failed lane goes on with a unit pivot).
#[inline(always)]
// The unrolled loops have empty ranges for the first constant.
#[allow(clippy::reversed_empty_ranges)]
pub fn invert_spd6(g: &LaneMatrix<6>, min_pivot: f64) -> (LaneMatrix<6>, [bool; W]) {
    const N: usize = 6;
    // l[i][j] (i > j): the unit lower factor; ld[i][j] = l[i][j] d_j.
    let mut l = [[[0.0; W]; N]; N];
    let mut ld = [[[0.0; W]; N]; N];
    let mut dinv = [[0.0; W]; N];
    let mut singular = [false; W];
    unroll!(j in [0, 1, 2, 3, 4, 5] {
        let mut d = g[j][j];
        for k in 0..j {
            d = neg_mul_add(l[j][k], ld[j][k], d);
        }
        let (d, bad) = pivot_above(d, mul(splat(min_pivot), g[j][j]));
        for x in 0..W {
            singular[x] |= bad[x];
            dinv[j][x] = 1.0 / d[x];
        }
        for i in j + 1..N {
            let mut t = g[i][j];
            for k in 0..j {
                t = neg_mul_add(l[i][k], ld[j][k], t);
            }
            ld[i][j] = t;
            l[i][j] = mul(t, dinv[j]);
        }
    });
    // y = L^-1 (unit lower triangular), column by column.
    let mut y = [[[0.0; W]; N]; N];
    unroll!(j in [0, 1, 2, 3, 4, 5] {
        y[j][j] = [1.0; W];
        for i in j + 1..N {
            let mut t = l[i][j];
            for k in j + 1..i {
                t = mul_add(l[i][k], y[k][j], t);
            }
            y[i][j] = sub([0.0; W], t);
        }
    });
    // G^-1[i][j] = sum_{k >= i} (y[k][i] / d_k) y[k][j] for i >= j.
    let mut inv = [[[0.0; W]; N]; N];
    unroll!(i in [0, 1, 2, 3, 4, 5] {
        let mut yd = [[0.0; W]; N];
        for k in i..N {
            yd[k] = mul(y[k][i], dinv[k]);
        }
        for j in 0..=i {
            let mut s = mul(yd[i], y[i][j]);
            for k in i + 1..N {
                s = mul_add(yd[k], y[k][j], s);
            }
            inv[i][j] = s;
            inv[j][i] = s;
        }
    });
    (inv, singular)
}

/// The 1-norm (largest absolute column sum) of each lane's matrix.
#[inline(always)]
pub fn norm1<const N: usize>(m: &LaneMatrix<N>) -> Lanes {
    let mut out: Lanes = [0.0; W];
    for c in 0..N {
        let mut s = [0.0; W];
        for row in m {
            for l in 0..W {
                s[l] += row[c][l].abs();
            }
        }
        for l in 0..W {
            if s[l] > out[l] {
                out[l] = s[l];
            }
        }
    }
    out
}

/// [`total`] of each of the [`W`] lane arrays `x`, lane `p` of the result
/// for `x[p]`, with the same additions in the same order: a transposing
/// reduction (three levels of shuffles and additions for all eight) instead
/// of eight separate ones.
#[inline(always)]
pub fn totals(x: &[Lanes; W]) -> Lanes {
    // Plain loops, no closures: a closure left out of line would lose the
    // caller's instruction set.
    // Level 1: h[l] = x[l] + x[l + 4], two arrays per vector.
    let mut h = [[0.0; W]; 4];
    for (j, hj) in h.iter_mut().enumerate() {
        let (a, b) = (&x[2 * j], &x[2 * j + 1]);
        for l in 0..4 {
            hj[l] = a[l] + a[l + 4];
            hj[l + 4] = b[l] + b[l + 4];
        }
    }
    // Level 2: (h0 + h2, h1 + h3) of each array, four per vector.
    let mut q = [[0.0; W]; 2];
    for (j, qj) in q.iter_mut().enumerate() {
        let (a, b) = (&h[2 * j], &h[2 * j + 1]);
        for l in 0..4 {
            let m = l / 2 * 4 + l % 2;
            qj[l] = a[m] + a[m + 2];
            qj[l + 4] = b[m] + b[m + 2];
        }
    }
    // Level 3: (h0 + h2) + (h1 + h3), all eight.
    let mut out = [0.0; W];
    for l in 0..4 {
        out[l] = q[0][2 * l] + q[0][2 * l + 1];
        out[l + 4] = q[1][2 * l] + q[1][2 * l + 1];
    }
    out
}

/// `sum_l x[l]` in a fixed pairwise order.
#[inline(always)]
pub fn total(x: Lanes) -> f64 {
    let mut h = [0.0; W / 2];
    for l in 0..W / 2 {
        h[l] = x[l] + x[l + W / 2];
    }
    (h[0] + h[2]) + (h[1] + h[3])
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::test_rng::rng;

    #[test]
    fn exp_is_within_two_ulp_of_the_standard_library() {
        let mut next = rng(7);
        let mut worst = 0.0f64;
        let mut check = |x: Lanes| {
            let e = exp(x);
            for l in 0..W {
                let want = x[l].exp();
                let ulp = f64::from_bits(want.to_bits() + 1) - want;
                worst = worst.max((e[l] - want).abs() / ulp);
            }
        };
        // The kernel's range, densely, then the whole documented domain.
        for _ in 0..20_000 {
            check(std::array::from_fn(|_| -5.0 * next()));
        }
        for _ in 0..5_000 {
            check(std::array::from_fn(|_| 1400.0 * next() - 700.0));
        }
        check([0.0, -0.0, 1.0, -1.0, -4.0, 700.0, -700.0, 1e-300]);
        assert!(worst <= 2.0, "worst error {worst} ulp");
        assert_eq!(exp([0.0; W]), [1.0; W]);
    }

    #[test]
    fn lane_inverse_equals_the_scalar_gauss_jordan_lane_by_lane() {
        let mut next = rng(11);
        for _ in 0..100 {
            let a: LaneMatrix<6> = std::array::from_fn(|_| {
                std::array::from_fn(|_| std::array::from_fn(|_| next() - 0.5))
            });
            let (inv, singular) = invert(a);
            assert_eq!(singular, [false; W]);
            for l in 0..W {
                let one: [[f64; 6]; 6] =
                    std::array::from_fn(|r| std::array::from_fn(|c| a[r][c][l]));
                let want = crate::approx::msph::invert(one).unwrap();
                let scale = want.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
                for r in 0..6 {
                    for c in 0..6 {
                        assert!(
                            (inv[r][c][l] - want[r][c]).abs() <= 1e-12 * scale,
                            "lane {l} ({r}, {c}): {} vs {}",
                            inv[r][c][l],
                            want[r][c]
                        );
                    }
                }
            }
        }
    }

    /// 2 on the diagonal and 0.5 elsewhere in every lane: well conditioned,
    /// for tests that spoil some lanes.
    fn dominant<const N: usize>() -> LaneMatrix<N> {
        std::array::from_fn(|r| std::array::from_fn(|c| [if r == c { 2.0 } else { 0.5 }; W]))
    }

    #[test]
    fn singular_lanes_are_flagged_and_do_not_spoil_the_others() {
        let mut a: LaneMatrix<3> = dominant();
        // Lane 3: two equal rows. Lane 5: a NaN entry.
        for c in 0..3 {
            a[1][c][3] = a[0][c][3];
        }
        a[2][2][5] = f64::NAN;
        let (inv, singular) = invert(a);
        let flagged: Vec<usize> = (0..W).filter(|&l| singular[l]).collect();
        assert_eq!(flagged, vec![3, 5]);
        let m = [[2.0, 0.5, 0.5], [0.5, 2.0, 0.5], [0.5, 0.5, 2.0]];
        let want = crate::approx::msph::invert(m).unwrap();
        for l in [0, 1, 2, 4, 6, 7] {
            for r in 0..3 {
                for c in 0..3 {
                    assert!((inv[r][c][l] - want[r][c]).abs() < 1e-15);
                }
            }
        }
    }

    /// Random symmetric positive definite matrices `M M^T + I / 2`, one per
    /// lane: the inverse equals nalgebra's, lane by lane.
    #[test]
    fn spd_inverse_equals_nalgebra_lane_by_lane() {
        let mut next = rng(11);
        for _ in 0..100 {
            let m: [[Lanes; 6]; 6] = std::array::from_fn(|_| {
                std::array::from_fn(|_| std::array::from_fn(|_| next() - 0.5))
            });
            let g: LaneMatrix<6> = std::array::from_fn(|r| {
                std::array::from_fn(|c| {
                    std::array::from_fn(|l| {
                        (0..6).map(|k| m[r][k][l] * m[c][k][l]).sum::<f64>()
                            + if r == c { 0.5 } else { 0.0 }
                    })
                })
            });
            let (inv, singular) = invert_spd6(&g, 1e-6);
            assert_eq!(singular, [false; W]);
            for l in 0..W {
                let want = nalgebra::Matrix6::from_fn(|r, c| g[r][c][l])
                    .try_inverse()
                    .unwrap();
                let scale = want.amax();
                for r in 0..6 {
                    for c in 0..6 {
                        assert!(
                            (inv[r][c][l] - want[(r, c)]).abs() <= 1e-12 * scale,
                            "lane {l} ({r}, {c}): {} vs {}",
                            inv[r][c][l],
                            want[(r, c)]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn non_positive_definite_lanes_are_flagged_and_do_not_spoil_the_others() {
        let mut g: LaneMatrix<6> = dominant();
        // Lane 3: two equal rows (singular). Lane 5: a NaN entry. Lane 6: a
        // negative eigenvalue (its third pivot is 0.1 - 0.2). Lane 7: nearly
        // singular (its third pivot is 1e-7 of the diagonal entry).
        for c in 0..6 {
            g[1][c][3] = g[0][c][3];
            g[c][1][3] = g[c][0][3];
        }
        g[1][1][3] = g[0][0][3];
        g[4][2][5] = f64::NAN;
        g[2][2][6] = 0.1;
        g[2][2][7] = 0.2 + 2e-8;
        let (inv, singular) = invert_spd6(&g, 1e-6);
        let flagged: Vec<usize> = (0..W).filter(|&l| singular[l]).collect();
        assert_eq!(flagged, vec![3, 5, 6, 7]);
        let want = nalgebra::Matrix6::from_fn(|r, c| if r == c { 2.0 } else { 0.5 })
            .try_inverse()
            .unwrap();
        for l in [0, 1, 2, 4] {
            for r in 0..6 {
                for c in 0..6 {
                    assert!((inv[r][c][l] - want[(r, c)]).abs() < 1e-14);
                }
            }
        }
    }

    #[test]
    fn totals_of_eight_equal_eight_totals_bit_for_bit() {
        let mut next = rng(5);
        for _ in 0..1000 {
            let x: [Lanes; W] = std::array::from_fn(|_| {
                std::array::from_fn(|_| (next() - 0.5) * 10f64.powi((next() * 20.0) as i32 - 10))
            });
            let t = totals(&x);
            for p in 0..W {
                assert_eq!(t[p].to_bits(), total(x[p]).to_bits(), "array {p}");
            }
        }
    }

    #[test]
    fn norm1_and_total() {
        let m: LaneMatrix<2> = [[[1.0; W], [-2.0; W]], [[3.0; W], [0.5; W]]];
        assert_eq!(norm1(&m), [4.0; W]);
        let x: Lanes = std::array::from_fn(|l| l as f64);
        assert_eq!(total(x), 28.0);
    }
}
