//! Solvers. Each scene composes exactly the physics it needs: the
//! axisymmetric Taylor solver ([`axisymmetric`]) and the radial Noh solver
//! ([`radial`]) share the kernel, the neighbour search, the MSPH basis and the
//! helpers here (pair weights, conservative smoothing, central-difference
//! bookkeeping), but nothing else runs per step.

pub mod axisymmetric;
pub mod boundary;
pub mod radial;

use crate::neighbors::NeighborList;
use rayon::prelude::*;

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

/// Conservative smoothing, eq. (3.23): `f_i + alpha (sum_j s_ij f_j - f_i)`,
/// where `s_ij` are the Shepard weights `W_ij V_j / sum_j W_ij V_j` stored in
/// CSR order, for the particles that have rows in `nl` (`f` may extend past
/// them with mirror images). Runs in parallel; the result does not depend on
/// thread count.
pub(crate) fn smooth<const K: usize>(
    nl: &NeighborList,
    shepard: &[f64],
    f: &[[f64; K]],
    alpha: f64,
) -> Vec<[f64; K]> {
    (0..nl.len())
        .into_par_iter()
        .map(|i| {
            if alpha == 0.0 {
                return f[i];
            }
            let (a, b) = (nl.offsets[i], nl.offsets[i + 1]);
            let mut mean = [0.0; K];
            for (&j, &s) in nl.indices[a..b].iter().zip(&shepard[a..b]) {
                for k in 0..K {
                    mean[k] += s * f[j][k];
                }
            }
            let mut out = f[i];
            for k in 0..K {
                out[k] += alpha * (mean[k] - f[i][k]);
            }
            out
        })
        .collect()
}

/// Values of the real particles followed by those of their mirror images
/// across the axis: `ghosts[k]` is the real particle the `k`-th image copies,
/// and `mirror` maps a value to its image.
pub(crate) fn with_images<T: Copy>(f: &[T], ghosts: &[usize], mirror: impl Fn(T) -> T) -> Vec<T> {
    let mut out = Vec::with_capacity(f.len() + ghosts.len());
    out.extend_from_slice(f);
    out.extend(ghosts.iter().map(|&i| mirror(f[i])));
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
        let s: Vec<f64> = (0..p.len())
            .flat_map(|i| {
                let n = nl.of(i).len() as f64;
                std::iter::repeat_n(1.0 / n, nl.of(i).len())
            })
            .collect();
        let c = vec![[3.0]; 20];
        assert_eq!(smooth(&nl, &s, &c, 0.3), c);
        let mut spike = vec![[0.0]; 20];
        spike[10] = [3.0];
        let out = smooth(&nl, &s, &spike, 0.3);
        assert!((out[10][0] - (3.0 + 0.3 * (1.0 - 3.0))).abs() < 1e-12);
        assert!((out[9][0] - 0.3).abs() < 1e-12);
    }
}
