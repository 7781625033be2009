//! Solvers. Each scene composes exactly the physics it needs: the
//! axisymmetric Taylor solver ([`axisymmetric`]) and the radial Noh solver
//! ([`radial`]) share the kernel, the neighbour search, the MSPH basis and the
//! helpers here (pair weights, conservative smoothing, central-difference
//! bookkeeping), but nothing else runs per step.

pub mod axisymmetric;
pub mod boundary;
pub mod radial;

/// Courant number of eq. (3.22).
pub const COURANT: f64 = 0.2;

/// The smallest accepted step, as a fraction of the first step: below it the
/// run stops with [`crate::Error::TimeStepCollapse`].
pub const MIN_DT_FRACTION: f64 = 1e-4;

/// Splits a CSR-aligned buffer into one mutable slice per particle so that
/// rows can be filled in parallel.
pub(crate) fn rows_mut<'a, T>(mut buf: &'a mut [T], offsets: &[usize]) -> Vec<&'a mut [T]> {
    let mut rows = Vec::with_capacity(offsets.len().saturating_sub(1));
    for w in offsets.windows(2) {
        let (head, tail) = std::mem::take(&mut buf).split_at_mut(w[1] - w[0]);
        rows.push(head);
        buf = tail;
    }
    rows
}

/// `sum_k term(k)` over `k < n`, component by component, in two interleaved
/// partial sums (even and odd `k`) added at the end: a fixed order, so the
/// result does not depend on the thread, and two independent chains of
/// additions instead of one long one.
#[inline(always)]
pub(crate) fn pair_sum<const K: usize>(
    n: usize,
    mut term: impl FnMut(usize) -> [f64; K],
) -> [f64; K] {
    let (mut even, mut odd) = ([0.0; K], [0.0; K]);
    let mut k = 0;
    while k + 1 < n {
        let (x, y) = (term(k), term(k + 1));
        for c in 0..K {
            even[c] += x[c];
            odd[c] += y[c];
        }
        k += 2;
    }
    if k < n {
        let x = term(k);
        for c in 0..K {
            even[c] += x[c];
        }
    }
    for c in 0..K {
        even[c] += odd[c];
    }
    even
}

/// Conservative smoothing, eq. (3.23), of particle `i`'s value:
/// `f_i + alpha (sum_j s_ij f_j - f_i)`, where `s_ij` are the Shepard weights
/// `W_ij V_j / sum_j W_ij V_j` of its neighbours `nbrs` (indices into `f`,
/// which may extend past the particles with mirror images). With
/// `alpha = 0` the value is returned unchanged.
#[inline]
pub(crate) fn smoothed<const K: usize>(
    i: usize,
    nbrs: &[u32],
    shepard: &[f64],
    f: &[[f64; K]],
    alpha: f64,
) -> [f64; K] {
    let mut out = f[i];
    if alpha == 0.0 {
        return out;
    }
    let n = nbrs.len().min(shepard.len());
    let mean = pair_sum(n, |k| {
        let fj = f[nbrs[k] as usize];
        fj.map(|x| shepard[k] * x)
    });
    for k in 0..K {
        out[k] += alpha * (mean[k] - out[k]);
    }
    out
}

/// The first degenerate moment matrix, in particle order, as the named error.
pub(crate) fn first_degenerate(
    status: Vec<std::result::Result<(), crate::msph::Degenerate>>,
    time: f64,
) -> crate::Result<()> {
    match status.into_iter().find_map(|s| s.err()) {
        Some(e) => Err(crate::Error::SingularMomentMatrix {
            particle: e.particle,
            time,
            condition: e.condition,
        }),
        None => Ok(()),
    }
}

/// Stops a run whose stable step fell below [`MIN_DT_FRACTION`] of the first.
pub(crate) fn check_time_step(dt: f64, dt0: f64, time: f64) -> crate::Result<()> {
    if dt < MIN_DT_FRACTION * dt0 {
        Err(crate::Error::TimeStepCollapse {
            dt,
            time,
            min: MIN_DT_FRACTION * dt0,
        })
    } else {
        Ok(())
    }
}

/// Index and field of the first non-finite value, if any.
pub(crate) fn first_non_finite(fields: &[(&'static str, &[f64])]) -> Option<(&'static str, usize)> {
    fields
        .iter()
        .find_map(|(name, v)| v.iter().position(|x| !x.is_finite()).map(|i| (*name, i)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::neighbors::cell_list;

    #[test]
    fn rows_mut_splits_by_offsets() {
        let mut buf = [0, 1, 2, 3, 4, 5];
        let rows = rows_mut(&mut buf, &[0, 2, 2, 6]);
        assert_eq!(rows.len(), 3);
        assert_eq!(&*rows[0], &[0, 1]);
        assert!(rows[1].is_empty());
        assert_eq!(&*rows[2], &[2, 3, 4, 5]);
    }

    #[test]
    fn smoothing_keeps_constants_and_damps_a_spike() {
        let p: Vec<[f64; 2]> = (0..20).map(|k| [k as f64, 0.0]).collect();
        let nl = cell_list(&p, 1.0);
        // Equal weights among the (up to three) neighbours.
        let smooth_all = |f: &[[f64; 1]]| -> Vec<[f64; 1]> {
            (0..p.len())
                .map(|i| {
                    let nb: Vec<u32> = nl.of(i).iter().map(|&j| j as u32).collect();
                    let s = vec![1.0 / nb.len() as f64; nb.len()];
                    smoothed(i, &nb, &s, f, 0.3)
                })
                .collect()
        };
        let c = vec![[3.0]; 20];
        for (a, b) in smooth_all(&c).iter().zip(&c) {
            assert!((a[0] - b[0]).abs() < 1e-14);
        }
        let mut spike = vec![[0.0]; 20];
        spike[10] = [3.0];
        let out = smooth_all(&spike);
        assert!((out[10][0] - (3.0 + 0.3 * (1.0 - 3.0))).abs() < 1e-12);
        assert!((out[9][0] - 0.3).abs() < 1e-12);
        assert_eq!(
            smoothed(4, &[3, 4, 5], &[0.2, 0.5, 0.3], &spike, 0.0),
            spike[4]
        );
    }
}
