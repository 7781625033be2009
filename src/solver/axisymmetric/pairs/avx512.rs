//! AVX-512 versions of parts of the pair pass, called from the AVX-512 clone
//! of [`super::pair_batch`] only. Each gives the same result bit for bit as
//! the portable code it replaces (the same IEEE operations in the same order;
//! compaction and minima are exact); a test runs both on the same input.
//!
//! The vector loads, gathers and stores take raw pointers. Every gather
//! index is checked against the length of the slice it reads, and every
//! store against the room of the slice it writes, before the access.

use super::{Neighbourhood, PairInputs, Stress};
use crate::approx::msph::POWER_SUMS;
use crate::kernel::SUPPORT;
use crate::lanes::{Lanes, W};
use std::arch::x86_64::*;

/// `(1 << k) - 1`: the low `k` of [`W`] lanes.
#[inline(always)]
fn low_lanes(k: usize) -> u8 {
    (((1u32 << k) - 1) & 0xff) as u8
}

/// [`super::scan_candidates`] with AVX-512: the [`W`] candidates of a lane
/// are gathered, tested against the support and compressed into the
/// neighbourhood and the row `act` with `vcompresspd` / `vpcompressd`
/// instead of one scalar store per candidate.
#[target_feature(enable = "avx512f,avx512vl")]
pub(super) fn scan_candidates(
    inp: &PairInputs,
    i: usize,
    hood: &mut Neighbourhood,
    act: &mut [u32],
) -> f64 {
    let stride = inp.stride;
    let cand = &inp.nbr[i * stride..(i + 1) * stride];
    let n_cand = inp.nbr_len[i] as usize;
    assert!(n_cand <= stride && stride.is_multiple_of(W) && act.len() >= n_cand);
    hood.reserve(n_cand);
    let (out_r, out_z, out_v, len) = hood.buffers();
    assert!(out_r.len() >= n_cand && out_z.len() >= n_cand && out_v.len() >= n_cand);
    // Every particle's position (two doubles) and volume can be gathered.
    let reach = inp.pos.len().min(inp.vol.len());
    assert!(reach < (i32::MAX / 2) as usize);
    let reach = _mm256_set1_epi32(reach as i32);
    let pos = inp.pos.as_ptr().cast::<f64>();
    let inv_h = _mm512_set1_pd(1.0 / inp.h);
    let (xi, zi) = (_mm512_set1_pd(inp.pos[i][0]), _mm512_set1_pd(inp.pos[i][1]));
    let support2 = _mm512_set1_pd(SUPPORT * SUPPORT);
    let me = _mm256_set1_epi32(i as i32);
    let mut min_d2 = _mm512_set1_pd(f64::INFINITY);
    let mut k = *len;
    for c in (0..n_cand).step_by(W) {
        let valid = low_lanes((n_cand - c).min(W));
        // SAFETY: `c + W <= stride = cand.len()` (stride is whole lanes).
        let idx = unsafe { _mm256_loadu_si256(cand[c..c + W].as_ptr().cast()) };
        assert_eq!(
            _mm256_cmpge_epu32_mask(idx, reach),
            0,
            "candidate out of range"
        );
        let idx2 = _mm256_add_epi32(idx, idx);
        // SAFETY: every index is below the lengths of `pos` and `vol`
        // (checked above), so each gathered double lies inside them.
        let (xr, xz, v) = unsafe {
            (
                _mm512_i32gather_pd::<8>(idx2, pos),
                _mm512_i32gather_pd::<8>(idx2, pos.add(1)),
                _mm512_i32gather_pd::<8>(idx, inp.vol.as_ptr()),
            )
        };
        let (dr, dz) = (_mm512_sub_pd(xr, xi), _mm512_sub_pd(xz, zi));
        let (sr, sz) = (_mm512_mul_pd(dr, inv_h), _mm512_mul_pd(dz, inv_h));
        let q2 = _mm512_add_pd(_mm512_mul_pd(sr, sr), _mm512_mul_pd(sz, sz));
        let keep = _mm512_mask_cmp_pd_mask::<_CMP_LE_OQ>(valid, q2, support2);
        let d2 = _mm512_add_pd(_mm512_mul_pd(dr, dr), _mm512_mul_pd(dz, dz));
        let other = keep & _mm256_cmpneq_epi32_mask(idx, me);
        let closer = _mm512_mask_cmp_pd_mask::<_CMP_LT_OQ>(other, d2, min_d2);
        min_d2 = _mm512_mask_blend_pd(closer, min_d2, d2);
        let n = keep.count_ones() as usize;
        let room = low_lanes(n);
        assert!(k + n <= n_cand);
        // SAFETY: `k + n <= n_cand` and every output holds at least `n_cand`
        // entries (asserted above); the masked stores write `n` of them.
        unsafe {
            let at = |x: &mut [f64]| x[k..].as_mut_ptr();
            _mm512_mask_storeu_pd(at(out_r), room, _mm512_maskz_compress_pd(keep, sr));
            _mm512_mask_storeu_pd(at(out_z), room, _mm512_maskz_compress_pd(keep, sz));
            _mm512_mask_storeu_pd(at(out_v), room, _mm512_maskz_compress_pd(keep, v));
            _mm256_mask_storeu_epi32(
                act[k..].as_mut_ptr().cast(),
                room,
                _mm256_maskz_compress_epi32(keep, idx),
            );
        }
        k += n;
    }
    *len = k;
    _mm512_reduce_min_pd(min_d2)
}

/// [`crate::lanes::totals`] of the power sums of a batch: lane `p` of sum
/// `k` is the total of `partials[p][k]`. The same additions in the same
/// order, with whole-register block shuffles (the portable loops compile to
/// two-lane pieces here, several times as many instructions).
#[target_feature(enable = "avx512f,avx512vl")]
pub(super) fn power_totals(partials: &[[Lanes; POWER_SUMS]; W]) -> [Lanes; POWER_SUMS] {
    let mut out = [[0.0; W]; POWER_SUMS];
    let even = _mm512_set_epi64(14, 12, 10, 8, 6, 4, 2, 0);
    let odd = _mm512_set_epi64(15, 13, 11, 9, 7, 5, 3, 1);
    // Plain loops, no closures (a closure left out of line would lose the
    // instruction set).
    for (k, o) in out.iter_mut().enumerate() {
        let mut x = [_mm512_setzero_pd(); W];
        for (xp, part) in x.iter_mut().zip(partials) {
            // SAFETY: a lane array is W = 8 doubles, one whole register.
            *xp = unsafe { _mm512_loadu_pd(part[k].as_ptr()) };
        }
        // Level 1: x[l] + x[l + 4] of two arrays per register.
        let mut h = [_mm512_setzero_pd(); 4];
        for (j, hj) in h.iter_mut().enumerate() {
            let (a, b) = (x[2 * j], x[2 * j + 1]);
            *hj = _mm512_add_pd(
                _mm512_shuffle_f64x2::<0x44>(a, b),
                _mm512_shuffle_f64x2::<0xEE>(a, b),
            );
        }
        // Level 2: pairs two apart, four arrays per register.
        let mut q = [_mm512_setzero_pd(); 2];
        for (j, qj) in q.iter_mut().enumerate() {
            let (a, b) = (h[2 * j], h[2 * j + 1]);
            *qj = _mm512_add_pd(
                _mm512_shuffle_f64x2::<0x88>(a, b),
                _mm512_shuffle_f64x2::<0xDD>(a, b),
            );
        }
        // Level 3: neighbouring pairs, all eight.
        let t = _mm512_add_pd(
            _mm512_permutex2var_pd(q[0], even, q[1]),
            _mm512_permutex2var_pd(q[0], odd, q[1]),
        );
        // SAFETY: `o` is W = 8 doubles.
        unsafe { _mm512_storeu_pd(o.as_mut_ptr(), t) };
    }
    out
}

/// [`super::stress_divergence`] with AVX-512: the stresses of the [`W`]
/// neighbours of a lane are loaded row by row and transposed with block
/// shuffles instead of being assembled two doubles at a time. The same
/// operations in the same order, bit for bit.
#[target_feature(enable = "avx512f,avx512vl")]
pub(super) fn stress_divergence(
    act: &[u32],
    wr: &[f64],
    wz: &[f64],
    sbc: &[Stress],
    si: Stress,
) -> [f64; 4] {
    let n = act.len();
    assert!(n.is_multiple_of(W) && wr.len() >= n && wz.len() >= n);
    assert!(sbc.len() < (i32::MAX as usize));
    let reach = _mm256_set1_epi32(sbc.len() as i32);
    let base = sbc.as_ptr().cast::<f64>();
    let (s0, s1, s3) = (
        _mm512_set1_pd(si[0]),
        _mm512_set1_pd(si[1]),
        _mm512_set1_pd(si[3]),
    );
    let mut acc = [_mm512_setzero_pd(); 4];
    for c in (0..n).step_by(W) {
        // SAFETY: `c + W <= n = act.len()`.
        let idx = unsafe { _mm256_loadu_si256(act[c..c + W].as_ptr().cast()) };
        assert_eq!(
            _mm256_cmpge_epu32_mask(idx, reach),
            0,
            "neighbour out of range"
        );
        // SAFETY: every index is below `sbc.len()` (checked above), so each
        // row of four doubles lies inside `sbc`.
        let row = |l: usize| unsafe { _mm256_loadu_pd(base.add(4 * act[c + l] as usize)) };
        let pair = |l: usize| _mm512_insertf64x4::<1>(_mm512_castpd256_pd512(row(l)), row(l + 2));
        let (a0, a1, a2, a3) = (pair(0), pair(1), pair(4), pair(5));
        let (t0, t1) = (_mm512_unpacklo_pd(a0, a1), _mm512_unpackhi_pd(a0, a1));
        let (t2, t3) = (_mm512_unpacklo_pd(a2, a3), _mm512_unpackhi_pd(a2, a3));
        // Components RR, ZZ and RZ of the eight neighbours.
        let rr = _mm512_shuffle_f64x2::<0x88>(t0, t2);
        let zz = _mm512_shuffle_f64x2::<0x88>(t1, t3);
        let rz = _mm512_shuffle_f64x2::<0xDD>(t1, t3);
        // SAFETY: `c + W <= n <= wr.len(), wz.len()`.
        let (gr, gz) = unsafe {
            (
                _mm512_loadu_pd(wr[c..].as_ptr()),
                _mm512_loadu_pd(wz[c..].as_ptr()),
            )
        };
        let drz = _mm512_sub_pd(rz, s3);
        acc[0] = _mm512_fmadd_pd(gr, _mm512_sub_pd(rr, s0), acc[0]);
        acc[1] = _mm512_fmadd_pd(gr, drz, acc[1]);
        acc[2] = _mm512_fmadd_pd(gz, drz, acc[2]);
        acc[3] = _mm512_fmadd_pd(gz, _mm512_sub_pd(zz, s1), acc[3]);
    }
    let mut out = [0.0; 4];
    for (o, a) in out.iter_mut().zip(acc) {
        let mut x = [0.0; W];
        // SAFETY: `x` is W = 8 doubles.
        unsafe { _mm512_storeu_pd(x.as_mut_ptr(), a) };
        *o = crate::lanes::total(x);
    }
    out
}
