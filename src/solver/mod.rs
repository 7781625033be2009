//! Solvers. Each scene composes exactly the physics it needs: the
//! axisymmetric Taylor solver ([`axisymmetric`]) and the radial Noh solver
//! ([`radial`]) share the kernel, the neighbour search, the MSPH basis and the
//! helpers here (pair weights, conservative smoothing, central-difference
//! bookkeeping), but nothing else runs per step.

pub mod axisymmetric;
pub mod boundary;
mod pairs;
pub mod radial;
pub mod scheme;
mod shift;
// Shares disjoint chunks of the step's arrays between the threads of a
// team: the only unsafe code of the solver besides the AVX-512 kernels.
#[allow(unsafe_code)]
mod team;

/// Courant number of eq. (3.22).
pub const COURANT: f64 = 0.2;

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

/// The first degenerate moment matrix, in particle order, as the named error.
pub(crate) fn first_degenerate(
    status: Vec<std::result::Result<(), crate::msph::Degenerate>>,
    time: f64,
) -> crate::Result<()> {
    match status.into_iter().find_map(|s| s.err()) {
        Some(e) => Err(crate::Error::SingularMomentMatrix {
            method: crate::error::MomentMethod::Msph,
            particle: e.particle,
            time,
            condition: e.condition,
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_mut_splits_by_offsets() {
        let mut buf = [0, 1, 2, 3, 4, 5];
        let rows = rows_mut(&mut buf, &[0, 2, 2, 6]);
        assert_eq!(rows.len(), 3);
        assert_eq!(&*rows[0], &[0, 1]);
        assert!(rows[1].is_empty());
        assert_eq!(&*rows[2], &[2, 3, 4, 5]);
    }
}
