//! Small helpers of the 3-D solver's passes: the material of a node, the
//! quarter model's extended fields, the symmetry planes' pin, kinetic
//! energy.

use crate::Error;
use crate::approx::mirror;
use crate::approx::mirror::Mirror;
use crate::materials::Material;
use crate::solver::mlpg3d::Body;
/// The material of node `i`: the rod's, or that of its body in `others`.
#[inline]
pub(super) fn material_of<'a>(
    rod: &'a Material,
    others: &'a [Body],
    group: &[u8],
    i: usize,
) -> &'a Material {
    match group.get(i) {
        Some(&g) if g > 0 => &others[g as usize - 1].material,
        _ => rod,
    }
}

/// The first index of `items` where `bad` holds, or `None`: a check on the
/// pool (`any`), then the first one found serially where one exists.
/// Rayon's `position_first` gave the same index, but its ordered search
/// cost about 0.5 ms a call on 2 × 10^4 positions (one worker; the plain
/// `iter().position` 0.11 ms, `par_iter().any` 0.03 ms), twice a step.
pub(super) fn first_where<T: Sync>(items: &[T], bad: impl Fn(&T) -> bool + Sync) -> Option<usize> {
    use rayon::iter::{IntoParallelRefIterator, ParallelIterator};
    if items.par_iter().any(&bad) {
        items.iter().position(bad)
    } else {
        None
    }
}

/// `real` itself for the whole body; in the quarter model `real` and its
/// images' values (`reflect`), written into `buf`.
pub(super) fn extended<'a, T: Copy>(
    m: &Mirror,
    real: &'a [T],
    buf: &'a mut Vec<T>,
    reflect: impl Fn(&T, u8) -> T,
) -> &'a [T] {
    if m.is_empty() {
        real
    } else {
        m.extend(real, buf, reflect);
        buf
    }
}

/// The velocity of a node on the symmetry planes `on` (bits
/// [`mirror::X`], [`mirror::Y`]): no component across them.
#[inline]
pub(super) fn pin(v: &mut [f64; 3], on: u8) {
    if on & mirror::X != 0 {
        v[0] = 0.0;
    }
    if on & mirror::Y != 0 {
        v[1] = 0.0;
    }
}

pub(super) fn kinetic1(v: [f64; 3], m: f64) -> f64 {
    0.5 * m * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
}

/// The kinetic energy of the nodes, summed on the pool in the fixed order
/// of [`crate::approx::sums`].
pub(super) fn kinetic(v: &[[f64; 3]], m: &[f64]) -> f64 {
    crate::approx::sums::sum(v.len().min(m.len()), |i| kinetic1(v[i], m[i]))
}

pub(super) fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// The error `e` met at a node, stamped with the run's `time` (the passes
/// over the nodes and the builds of the geometry do not know the time).
pub(super) fn at_time(e: Error, time: f64) -> Error {
    match e {
        Error::NonFinite {
            field, particle, ..
        } => Error::NonFinite {
            field,
            particle,
            time,
        },
        Error::CompressionLimit {
            particle,
            compression,
            limit,
            ..
        } => Error::CompressionLimit {
            particle,
            time,
            compression,
            limit,
        },
        Error::SingularMomentMatrix {
            method,
            particle,
            condition,
            ..
        } => Error::SingularMomentMatrix {
            method,
            particle,
            time,
            condition,
        },
        e => e,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`first_where`] is its plain twin, the serial first position: none,
    /// the first, the last, and the first of several (a NaN among them),
    /// on 1, 2 and 3 threads.
    #[test]
    fn the_first_bad_item_is_the_serial_first() {
        let mut rng = crate::test_rng::rng(7);
        let n = 20_000;
        let clean: Vec<[f64; 3]> = (0..n).map(|_| [rng(), rng(), rng()]).collect();
        let bad = |x: &[f64; 3]| !x.iter().all(|v| v.is_finite()) || x[0] < 0.0;
        for marks in [vec![], vec![0], vec![n - 1], vec![17_333, 4_097, 9_000]] {
            let mut x = clean.clone();
            for (k, &i) in marks.iter().enumerate() {
                x[i][k % 3] = if k % 2 == 0 { f64::NAN } else { -1.0 };
                x[i][0] = if k == 1 { -1.0 } else { x[i][0] };
            }
            let plain = x.iter().position(bad);
            assert_eq!(plain, marks.iter().copied().min());
            for threads in [1, 2, 3] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                assert_eq!(pool.install(|| first_where(&x, bad)), plain);
            }
        }
    }
}
