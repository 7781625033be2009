//! The pair pass of the axisymmetric solver, [`W`] particles at a time: each
//! particle's neighbours in the support, its MSPH moment matrix, the
//! [`W`] matrices inverted together in the lanes of one vector
//! ([`crate::approx::msph::inverse_moments_lanes`], or [`crate::lanes::invert`] for a
//! near-degenerate neighbourhood), then each pair's derivative and Shepard
//! weights and the momentum equation.
//!
//! The lane arithmetic ([`crate::lanes`]) is plain IEEE arithmetic in a
//! fixed order, so the results do not depend on the thread count or on the
//! vector width the compiler picks.

use super::boundary::Stress;
use crate::approx::msph::{
    MAX_CONDITION, Neighbourhood, POWER_SUMS, inverse_moments_lanes, moment_matrix_lanes,
};
use crate::isa::{hot, on_avx512};
use crate::kernel::SUPPORT;
use crate::lanes::{self, Lanes, W};
use std::sync::{Mutex, MutexGuard};

// AVX-512 versions of parts of the pair pass, chosen at run time (vector
// loads, gathers, stores; src/lib.rs lists every place with unsafe code).
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx512;
/// Per-particle results of the pair pass.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct PairPass {
    /// Neighbours in the support.
    pub len: u32,
    /// Condition number of a degenerate moment matrix, or zero.
    pub condition: f64,
    /// Smallest squared distance to another particle in the support, mirror
    /// images included.
    pub min_d2: f64,
}

/// What the pair pass reads: the particles followed by their mirror images.
pub(super) struct PairInputs<'a> {
    /// Positions, volumes `m / rho`, stresses with boundary conditions.
    pub pos: &'a [[f64; 2]],
    pub vol: &'a [f64],
    pub sbc: &'a [Stress],
    /// Candidate neighbours, padded rows of `stride`.
    pub nbr: &'a [u32],
    pub nbr_len: &'a [u32],
    pub stride: usize,
    /// Velocities `v^{n-1/2}` and densities of the real particles.
    pub vel: &'a [[f64; 2]],
    pub rho: &'a [f64],
    /// Whether each real particle lies on the axis.
    pub on_axis: &'a [bool],
    pub h: f64,
    pub dt: f64,
}

/// What the pair pass writes for a batch of up to [`W`] particles: their
/// padded rows of neighbours in the support and of weights, their
/// [`PairPass`] records and their velocities `v^{n+1/2}`.
pub(super) struct PairOutputs<'a> {
    pub act: &'a mut [u32],
    pub wr: &'a mut [f64],
    pub wz: &'a mut [f64],
    pub wk: &'a mut [f64],
    pub part: &'a mut [PairPass],
    pub vel: &'a mut [[f64; 2]],
}

/// One [`Neighbourhood`] per lane, reused from batch to batch (they grow to
/// the longest candidate row once and keep their room). Aligned to whole
/// cache-line pairs so the scratch of two threads never shares a line.
#[derive(Debug, Default)]
#[repr(align(128))]
pub(super) struct Scratch {
    hoods: [Neighbourhood; W],
    /// Lane partial sums of the power sums of each particle of a batch.
    partials: [[Lanes; POWER_SUMS]; W],
}

/// One [`Scratch`] per thread of the pool, kept from step to step so the
/// pair pass allocates nothing. A copy starts empty (scratch holds no state).
#[derive(Debug, Default)]
pub(super) struct ScratchPool {
    slots: Vec<Mutex<Scratch>>,
}

impl Clone for ScratchPool {
    fn clone(&self) -> Self {
        ScratchPool::default()
    }
}

/// A thread's scratch: its slot of the pool, or a fresh one when the slot
/// is missing or taken (which the pair pass does not cause: a thread holds
/// its slot only while it runs its share of batches, without nested
/// parallel work).
pub(super) enum ScratchRef<'a> {
    Kept(MutexGuard<'a, Scratch>),
    Fresh(Box<Scratch>),
}

impl ScratchPool {
    /// Makes a slot for every thread of the current pool.
    pub fn fit(&mut self) {
        let n = rayon::current_num_threads();
        if self.slots.len() < n {
            self.slots.resize_with(n, Mutex::default);
        }
    }

    /// The calling thread's scratch.
    pub fn get(&self) -> ScratchRef<'_> {
        rayon::current_thread_index()
            .and_then(|t| self.slots.get(t))
            .and_then(|slot| slot.try_lock().ok())
            .map_or_else(|| ScratchRef::Fresh(Box::default()), ScratchRef::Kept)
    }
}

impl std::ops::Deref for ScratchRef<'_> {
    type Target = Scratch;
    fn deref(&self) -> &Scratch {
        match self {
            ScratchRef::Kept(g) => g,
            ScratchRef::Fresh(s) => s,
        }
    }
}

impl std::ops::DerefMut for ScratchRef<'_> {
    fn deref_mut(&mut self) -> &mut Scratch {
        match self {
            ScratchRef::Kept(g) => g,
            ScratchRef::Fresh(s) => s,
        }
    }
}

/// The stress-divergence sums of the momentum equation over the padded row
/// `act` (padded slots have zero weight and a valid index): `sum_j g_j (s_j -
/// s_i)` for (`g`, `s`) = (`wr`, RR), (`wr`, RZ), (`wz`, RZ), (`wz`, ZZ). Fixed
/// order: lane partial sums (fused multiply-adds), then [`lanes::total`].
#[inline(always)]
fn stress_divergence(act: &[u32], wr: &[f64], wz: &[f64], sbc: &[Stress], si: Stress) -> [f64; 4] {
    let mut acc = [[0.0; W]; 4];
    for c in (0..act.len()).step_by(W) {
        let s = lanes::gather(sbc, act[c..c + W].try_into().expect("a whole lane"));
        let (gr, gz) = (&wr[c..c + W], &wz[c..c + W]);
        for l in 0..W {
            acc[0][l] = gr[l].mul_add(s[0][l] - si[0], acc[0][l]);
            acc[1][l] = gr[l].mul_add(s[3][l] - si[3], acc[1][l]);
            acc[2][l] = gz[l].mul_add(s[3][l] - si[3], acc[2][l]);
            acc[3][l] = gz[l].mul_add(s[1][l] - si[1], acc[3][l]);
        }
    }
    acc.map(lanes::total)
}

/// Appends the candidates of particle `i` that lie in its support to `hood`
/// (scaled offsets and volumes) and their indices to `act`, in candidate
/// order, and returns the smallest squared distance to another particle (or
/// image) in the support. [`avx512::scan_candidates`] is the same with
/// AVX-512 compress instructions, bit for bit.
#[inline(always)]
fn scan_candidates(inp: &PairInputs, i: usize, hood: &mut Neighbourhood, act: &mut [u32]) -> f64 {
    let stride = inp.stride;
    let xi = inp.pos[i];
    let inv_h = 1.0 / inp.h;
    let mut min_d2 = [f64::INFINITY; W];
    let cand = &inp.nbr[i * stride..(i + 1) * stride];
    let n_cand = inp.nbr_len[i] as usize;
    hood.reserve(n_cand);
    for c in (0..n_cand).step_by(W) {
        let idx: [u32; W] = cand[c..c + W].try_into().expect("a whole lane");
        let [xr, xz] = lanes::gather(inp.pos, &idx);
        let v = lanes::gather1(inp.vol, &idx);
        let mut keep = [false; W];
        let (mut sr, mut sz) = ([0.0; W], [0.0; W]);
        for l in 0..W {
            let (dr, dz) = (xr[l] - xi[0], xz[l] - xi[1]);
            (sr[l], sz[l]) = (dr * inv_h, dz * inv_h);
            keep[l] = sr[l] * sr[l] + sz[l] * sz[l] <= SUPPORT * SUPPORT && c + l < n_cand;
            let d2 = dr * dr + dz * dz;
            let other = keep[l] && idx[l] as usize != i;
            // Plain compare-and-select: one vector instruction.
            if other && d2 < min_d2[l] {
                min_d2[l] = d2;
            }
        }
        let mut k = hood.len();
        for l in 0..W {
            act[k] = idx[l];
            k += keep[l] as usize;
        }
        hood.push_lanes(keep, sr, sz, v);
    }
    min_d2.iter().fold(f64::INFINITY, |a, &b| a.min(b))
}

/// [`lanes::totals`] of the power sums of a batch: lane `p` of sum `k` is
/// the total of `partials[p][k]`. [`avx512::power_totals`] is the same with
/// AVX-512 block shuffles, bit for bit.
#[inline(always)]
fn power_totals(partials: &[[Lanes; POWER_SUMS]; W]) -> [Lanes; POWER_SUMS] {
    let mut sums = [[0.0; W]; POWER_SUMS];
    // Plain loops: a closure left out of line would lose the instruction set.
    for (k, s) in sums.iter_mut().enumerate() {
        let mut of_k = [[0.0; W]; W];
        for (x, part) in of_k.iter_mut().zip(partials.iter()) {
            *x = part[k];
        }
        *s = lanes::totals(&of_k);
    }
    sums
}

hot! {
/// The pair pass of the particles `i0 .. i0 + out.part.len()` (at most
/// [`W`]), in the copy `isa`. See the module documentation.
pub(super) fn pair_batch(inp: &PairInputs, i0: usize, out: PairOutputs, scratch: &mut Scratch) {
    let nb = out.part.len();
    let stride = inp.stride;
    let inv_h = 1.0 / inp.h;
    for p in 0..nb {
        let i = i0 + p;
        let hood = &mut scratch.hoods[p];
        hood.clear();
        let act = &mut out.act[p * stride..(p + 1) * stride];
        let min_d2 = on_avx512!(
            ISA,
            avx512::scan_candidates(inp, i, hood, act),
            scan_candidates(inp, i, hood, act)
        );
        let len = hood.len();
        // Padded slots: the particle itself, with zero weight.
        for a in &mut act[len..hood.padded_len()] {
            *a = i as u32;
        }
        out.part[p] = PairPass {
            len: len as u32,
            condition: 0.0,
            min_d2,
        };
        scratch.partials[p] = hood.power_partials();
    }
    // Kept in the scratch, not zeroed per batch: only the unused lanes are.
    let partials = &mut scratch.partials;
    for part in &mut partials[nb..] {
        *part = [[0.0; W]; POWER_SUMS];
    }
    // Each power sum of the eight particles at once (unused lanes zero).
    let sums = on_avx512!(ISA, avx512::power_totals(partials), power_totals(partials));
    let b = moment_matrix_lanes(&sums);
    // The Gram route without pivoting; unused lanes (zero sums) are not read.
    let (mut inv, elsewhere) = inverse_moments_lanes(&sums);
    let mut singular = [false; W];
    if elsewhere[..nb].iter().any(|&x| x) {
        // Rare (a neighbourhood near degenerate): Gauss-Jordan elimination
        // of B with pivoting for the lanes the Gram route cannot serve,
        // with the identity in the unused lanes.
        let mut bb = b;
        for p in nb..W {
            for (r, row) in bb.iter_mut().enumerate() {
                for (c, x) in row.iter_mut().enumerate() {
                    x[p] = if r == c { 1.0 } else { 0.0 };
                }
            }
        }
        let (gj, gj_singular) = lanes::invert(bb);
        for p in (0..nb).filter(|&p| elsewhere[p]) {
            for (row, gj_row) in inv.iter_mut().zip(&gj) {
                for (x, y) in row.iter_mut().zip(gj_row) {
                    x[p] = y[p];
                }
            }
            singular[p] = gj_singular[p];
        }
    }
    let (nb1, ni1) = (lanes::norm1(&b), lanes::norm1(&inv));
    for p in 0..nb {
        let i = i0 + p;
        let cond = nb1[p] * ni1[p];
        if singular[p] || !cond.is_finite() || cond > MAX_CONDITION {
            out.part[p].condition = if singular[p] { f64::INFINITY } else { cond };
            out.part[p].len = 0;
            out.vel[p] = inp.vel[i];
            continue;
        }
        let hood = &scratch.hoods[p];
        let padded = hood.padded_len();
        let row = p * stride..p * stride + padded;
        let (wr, wz, wk) = (
            &mut out.wr[row.clone()],
            &mut out.wz[row.clone()],
            &mut out.wk[row.clone()],
        );
        let rows: [[f64; 6]; 2] = [1, 2].map(|r| std::array::from_fn(|c| inv[r][c][p]));
        let wsum = hood.weights_of(&rows, &[inv_h; 2], [&mut *wr, &mut *wz], wk);
        // Shepard weights W_ij V_j / sum_j W_ij V_j (the kernel's
        // normalisation cancels).
        let inv_sum = 1.0 / wsum;
        for w in wk.iter_mut() {
            *w *= inv_sum;
        }
        // Momentum: v^{n+1/2} = v^{n-1/2} + dt div(sigma) / rho.
        let si = inp.sbc[i];
        let act = &out.act[row];
        let [drr_r, drz_r, drz_z, dzz_z] = on_avx512!(
            ISA,
            avx512::stress_divergence(act, wr, wz, inp.sbc, si),
            stress_divergence(act, wr, wz, inp.sbc, si)
        );
        let (v, rho, dt) = (inp.vel[i], inp.rho[i], inp.dt);
        out.vel[p] = if inp.on_axis[i] {
            [0.0, v[1] + dt * (2.0 * drz_r + dzz_z) / rho]
        } else {
            let r = inp.pos[i][0];
            [
                v[0] + dt * (drr_r + (si[0] - si[2]) / r + drz_z) / rho,
                v[1] + dt * (drz_r + si[3] / r + dzz_z) / rho,
            ]
        };
    }
}
}

/// The padded per-particle rows written by the pair pass, for the passes
/// that follow it.
#[derive(Clone, Copy)]
pub(super) struct Rows<'a> {
    pub act: &'a [u32],
    pub wr: &'a [f64],
    pub wz: &'a [f64],
    pub wk: &'a [f64],
    pub part: &'a [PairPass],
    pub stride: usize,
}

impl Rows<'_> {
    /// Slots of particle `i`: its neighbours in the support, padded to whole
    /// lanes with zero-weight slots.
    #[inline(always)]
    fn range(&self, i: usize) -> std::ops::Range<usize> {
        let start = i * self.stride;
        start..start + (self.part[i].len as usize).next_multiple_of(W)
    }
}

hot! {
/// Shepard means `sum_j s_ij f_j` of the particles `i0 .. i0 + out.len()`,
/// in the copy `isa`.
pub(super) fn shepard_means<const K: usize>(
    rows: Rows,
    f: &[[f64; K]],
    i0: usize,
    out: &mut [[f64; K]],
) {
    for (k, o) in out.iter_mut().enumerate() {
        let r = rows.range(i0 + k);
        let (act, wk) = (&rows.act[r.clone()], &rows.wk[r]);
        let mut acc = [[0.0; W]; K];
        for c in (0..act.len()).step_by(W) {
            let fj = lanes::gather(f, act[c..c + W].try_into().expect("a whole lane"));
            for m in 0..K {
                for l in 0..W {
                    acc[m][l] += wk[c + l] * fj[m][l];
                }
            }
        }
        *o = acc.map(lanes::total);
    }
}
}

hot! {
/// Velocity gradients (dU_R/dR, dU_R/dZ, dU_Z/dR, dU_Z/dZ) of the particles
/// `i0 .. i0 + out.len()`, in the copy `isa`.
pub(super) fn velocity_gradients(rows: Rows, vel: &[[f64; 2]], i0: usize, out: &mut [[f64; 4]]) {
    for (k, o) in out.iter_mut().enumerate() {
        let i = i0 + k;
        let vi = vel[i];
        let r = rows.range(i);
        let (act, wr, wz) = (&rows.act[r.clone()], &rows.wr[r.clone()], &rows.wz[r]);
        let mut acc = [[0.0; W]; 4];
        for c in (0..act.len()).step_by(W) {
            let [vr, vz] = lanes::gather(vel, act[c..c + W].try_into().expect("a whole lane"));
            for l in 0..W {
                let (dr, dz) = (vr[l] - vi[0], vz[l] - vi[1]);
                acc[0][l] += wr[c + l] * dr;
                acc[1][l] += wz[c + l] * dr;
                acc[2][l] += wr[c + l] * dz;
                acc[3][l] += wz[c + l] * dz;
            }
        }
        *o = acc.map(lanes::total);
    }
}
}

/// Conservative smoothing, eq. (3.23): `f_i + alpha (mean - f_i)` with the
/// Shepard mean of the neighbours; with `alpha = 0` the value is returned
/// unchanged.
#[inline]
pub(super) fn smooth<const K: usize>(fi: [f64; K], mean: [f64; K], alpha: f64) -> [f64; K] {
    if alpha == 0.0 {
        return fi;
    }
    std::array::from_fn(|k| fi[k] + alpha * (mean[k] - fi[k]))
}

/// The smoothing operator `L f = mean - f` of the neighbours' Shepard mean.
#[inline]
pub(super) fn laplacian<const K: usize>(fi: [f64; K], mean: [f64; K]) -> [f64; K] {
    std::array::from_fn(|k| mean[k] - fi[k])
}

/// Smoothing of order 2, the bi-Laplacian of (3.23): `f_i - alpha L(L f)_i`,
/// from `L f` at the particle (`li`) and the Shepard mean of `L f` over its
/// neighbours (`mean_l`). A mode that (3.23) multiplies by `1 + alpha l`
/// (with `l` in [-2, 0] the eigenvalue of `L`) is multiplied by
/// `1 - alpha l^2`: the shortest waves are damped about as much, long waves
/// far less.
#[inline]
pub(super) fn smooth2<const K: usize>(
    fi: [f64; K],
    li: [f64; K],
    mean_l: [f64; K],
    alpha: f64,
) -> [f64; K] {
    std::array::from_fn(|k| fi[k] - alpha * (mean_l[k] - li[k]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::isa::Isa;

    /// Padded rows of `n` particles on a line, particle `i` with the
    /// neighbours `nb(i)` at equal Shepard weights (no derivative weights).
    struct Line {
        act: Vec<u32>,
        wk: Vec<f64>,
        zeros: Vec<f64>,
        part: Vec<PairPass>,
    }

    impl Line {
        fn new(n: usize, nb: impl Fn(usize) -> Vec<usize>) -> Line {
            let stride = W;
            let (mut act, mut wk) = (vec![0u32; n * stride], vec![0.0; n * stride]);
            let mut part = vec![PairPass::default(); n];
            for i in 0..n {
                let nb = nb(i);
                for (k, &j) in nb.iter().enumerate() {
                    act[i * stride + k] = j as u32;
                    wk[i * stride + k] = 1.0 / nb.len() as f64;
                }
                for k in nb.len()..stride {
                    act[i * stride + k] = i as u32;
                }
                part[i].len = nb.len() as u32;
            }
            let zeros = vec![0.0; n * stride];
            Line {
                act,
                wk,
                zeros,
                part,
            }
        }

        fn rows(&self) -> Rows<'_> {
            Rows {
                act: &self.act,
                wr: &self.zeros,
                wz: &self.zeros,
                wk: &self.wk,
                part: &self.part,
                stride: W,
            }
        }
    }

    #[test]
    fn smoothing_of_order_two_damps_each_fourier_mode_by_one_minus_alpha_l_squared() {
        // A periodic line of n particles, each with its two neighbours and
        // itself at equal Shepard weights: the mode cos(theta i) is an
        // eigenvector of L with l = (2 cos theta - 2) / 3.
        let n = 40;
        let line = Line::new(n, |i| vec![(i + n - 1) % n, i, (i + 1) % n]);
        let rows = line.rows();
        let alpha = 0.2;
        for waves in [1, 4, 20] {
            let theta = 2.0 * std::f64::consts::PI * waves as f64 / n as f64;
            let f: Vec<[f64; 1]> = (0..n).map(|i| [(theta * i as f64).cos()]).collect();
            let mut mean = vec![[0.0]; n];
            shepard_means(Isa::best(), rows, &f, 0, &mut mean);
            let lf: Vec<[f64; 1]> = (0..n).map(|i| laplacian(f[i], mean[i])).collect();
            let mut mean_l = vec![[0.0]; n];
            shepard_means(Isa::best(), rows, &lf, 0, &mut mean_l);
            let l = (2.0 * theta.cos() - 2.0) / 3.0;
            for i in 0..n {
                let one = smooth(f[i], mean[i], alpha)[0];
                let two = smooth2(f[i], lf[i], mean_l[i], alpha)[0];
                assert!(
                    (one - (1.0 + alpha * l) * f[i][0]).abs() < 1e-13,
                    "{waves} {i}"
                );
                assert!(
                    (two - (1.0 - alpha * l * l) * f[i][0]).abs() < 1e-13,
                    "{waves} {i}"
                );
            }
        }
    }

    #[test]
    fn smoothing_keeps_constants_and_damps_a_spike() {
        // Twenty particles on a line, each with its (up to three) nearest
        // neighbours at equal Shepard weights, in padded rows.
        let n = 20;
        let line = Line::new(n, |i| (i.saturating_sub(1)..(i + 2).min(n)).collect());
        let rows = line.rows();
        let smooth_all = |f: &[[f64; 1]], alpha: f64| -> Vec<[f64; 1]> {
            let mut means = vec![[0.0]; n];
            shepard_means(Isa::best(), rows, f, 0, &mut means);
            (0..n).map(|i| smooth(f[i], means[i], alpha)).collect()
        };
        let c = vec![[3.0]; n];
        for (a, b) in smooth_all(&c, 0.3).iter().zip(&c) {
            assert!((a[0] - b[0]).abs() < 1e-14);
        }
        let mut spike = vec![[0.0]; n];
        spike[10] = [3.0];
        let out = smooth_all(&spike, 0.3);
        assert!((out[10][0] - (3.0 + 0.3 * (1.0 - 3.0))).abs() < 1e-12);
        assert!((out[9][0] - 0.3).abs() < 1e-12);
        assert_eq!(smooth_all(&spike, 0.0), spike);
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod avx512_tests {
    use super::*;
    use crate::neighbours::cell_list_first;

    /// A pseudo-random number in [0, 1) from a linear congruential step.
    fn uniform(seed: &mut u64) -> f64 {
        *seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A pseudo-random number in [-0.5, 0.5) times a power of ten from
    /// 1e-6 to 1e6, so that sums round.
    fn spread(seed: &mut u64) -> f64 {
        let x = uniform(seed) - 0.5;
        x * 10f64.powi((uniform(seed) * 12.0) as i32 - 6)
    }

    /// Whether this CPU runs the AVX-512 code (said on stderr when not). With
    /// `MI_REQUIRE_AVX512=1` (the test command sets it where the processor
    /// has AVX-512) a processor without it fails the test instead.
    fn avx512_here() -> bool {
        let here = is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512vl");
        let required = std::env::var("MI_REQUIRE_AVX512").is_ok_and(|v| v == "1");
        assert!(
            here || !required,
            "MI_REQUIRE_AVX512=1 but this processor has no AVX-512 F and VL"
        );
        if !here {
            eprintln!("no AVX-512 on this machine: nothing to compare");
        }
        here
    }

    /// The AVX-512 batched totals of the power sums and stress divergence
    /// equal the portable ones bit for bit.
    #[test]
    #[allow(unsafe_code)]
    fn avx512_sums_equal_portable_sums() {
        if !avx512_here() {
            return;
        }
        let mut seed = 11u64;
        for _ in 0..200 {
            let mut partials = [[[0.0; W]; POWER_SUMS]; W];
            for x in partials.iter_mut().flatten().flatten() {
                *x = spread(&mut seed);
            }
            let a = power_totals(&partials);
            // SAFETY: the CPU has AVX-512F and VL (checked above).
            let b = unsafe { avx512::power_totals(&partials) };
            for (ra, rb) in a.iter().zip(&b) {
                for (x, y) in ra.iter().zip(rb) {
                    assert_eq!(x.to_bits(), y.to_bits());
                }
            }
        }
        let sbc: Vec<Stress> = (0..97)
            .map(|_| std::array::from_fn(|_| spread(&mut seed)))
            .collect();
        for len in [W, 2 * W, 5 * W] {
            for _ in 0..50 {
                let act: Vec<u32> = (0..len)
                    .map(|_| (spread(&mut seed).abs() * 1e6) as u32 % sbc.len() as u32)
                    .collect();
                let wr: Vec<f64> = (0..len).map(|_| spread(&mut seed)).collect();
                let wz: Vec<f64> = (0..len).map(|_| spread(&mut seed)).collect();
                let si = sbc[act[0] as usize];
                let a = stress_divergence(&act, &wr, &wz, &sbc, si);
                // SAFETY: as above.
                let b = unsafe { avx512::stress_divergence(&act, &wr, &wz, &sbc, si) };
                assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "{len} slots");
            }
        }
    }

    /// The AVX-512 candidate scan gives the portable scan's neighbourhoods,
    /// rows and minimum distances bit for bit, on a jittered lattice.
    #[test]
    #[allow(unsafe_code)]
    fn avx512_scan_equals_portable_scan() {
        if !avx512_here() {
            return;
        }
        let (nr, nz, h) = (9, 14, 1.3);
        let mut seed = 7u64;
        let mut jitter = || (uniform(&mut seed) - 0.5) * 0.6;
        let pos: Vec<[f64; 2]> = (0..nr * nz)
            .map(|k| [(k % nr) as f64 + jitter(), (k / nr) as f64 + jitter()])
            .collect();
        let n = pos.len();
        let vol: Vec<f64> = (0..n).map(|k| 1.0 + 0.01 * k as f64).collect();
        let nl = cell_list_first(&pos, n, (SUPPORT + 0.3) * h);
        let stride = (0..n)
            .map(|i| nl.of(i).len())
            .max()
            .unwrap()
            .next_multiple_of(W);
        let mut nbr = vec![0u32; n * stride];
        let mut nbr_len = vec![0u32; n];
        for i in 0..n {
            for (k, &j) in nl.of(i).iter().enumerate() {
                nbr[i * stride + k] = j as u32;
            }
            nbr_len[i] = nl.of(i).len() as u32;
        }
        let zeros = vec![[0.0; 4]; n];
        let inp = PairInputs {
            pos: &pos,
            vol: &vol,
            sbc: &zeros,
            nbr: &nbr,
            nbr_len: &nbr_len,
            stride,
            vel: &[],
            rho: &[],
            on_axis: &[],
            h,
            dt: 0.0,
        };
        let (mut kept, mut candidates) = (0, 0);
        for i in 0..n {
            let (mut a, mut b) = (
                Neighbourhood::with_capacity(stride),
                Neighbourhood::with_capacity(stride),
            );
            let (mut act_a, mut act_b) = (vec![0u32; stride], vec![0u32; stride]);
            let ma = scan_candidates(&inp, i, &mut a, &mut act_a);
            // SAFETY: the CPU has AVX-512F and VL (checked above).
            let mb = unsafe { avx512::scan_candidates(&inp, i, &mut b, &mut act_b) };
            assert_eq!(ma.to_bits(), mb.to_bits(), "particle {i}");
            assert!(ma > 0.0 && ma.is_finite());
            let len = a.len();
            assert_eq!(len, b.len());
            assert!(
                len >= 4 && len <= nbr_len[i] as usize,
                "particle {i}: {len}"
            );
            (kept, candidates) = (kept + len, candidates + nbr_len[i] as usize);
            assert_eq!(act_a[..len], act_b[..len]);
            let (ra, za, va, _) = a.buffers();
            let (rb, zb, vb, _) = b.buffers();
            assert_eq!(ra[..len], rb[..len]);
            assert_eq!(za[..len], zb[..len]);
            assert_eq!(va[..len], vb[..len]);
        }
        // The skin holds candidates outside the support: some were dropped.
        assert!(kept < candidates * 9 / 10, "{kept} of {candidates}");
    }
}
