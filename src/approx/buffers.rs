//! Buffers refilled build after build: the geometry's arrays keep their
//! room from one build to the next, so that a build allocates only when
//! its arrays outgrow it (BENCHMARKS.md, memory).

use rayon::prelude::*;

/// Empties `v` and fills it with `len` copies of `value`, on the pool (the
/// arrays of a build hold tens of bytes a neighbour: a serial fill was a
/// serial part of every build). When `v` has no room for `len`, its old
/// buffer is freed before the new one is allocated (no moment with both),
/// with an eighth more room than `len`: rows grow a little as a body is
/// compressed, and the doubling of `Vec`'s own growth would hold twice the
/// array.
pub(crate) fn refill<T: Clone + Send>(v: &mut Vec<T>, len: usize, value: T) {
    v.clear();
    if v.capacity() < len {
        *v = Vec::new();
        v.reserve_exact(len + len / 8);
    }
    v.par_extend(rayon::iter::repeat_n(value, len));
}

/// `v.resize(len, value)`, the new entries written on the pool: a large
/// buffer's first fill (and its pages' first touch) is not serial.
pub(crate) fn fit<T: Clone + Send>(v: &mut Vec<T>, len: usize, value: T) {
    if v.len() >= len {
        v.truncate(len);
        return;
    }
    let more = len - v.len();
    v.reserve(more);
    v.par_extend(rayon::iter::repeat_n(value, more));
}

/// `vec![value; len]`, written on the pool (a large buffer's pages are
/// first touched there, not on the calling thread).
pub(crate) fn filled<T: Clone + Send>(len: usize, value: T) -> Vec<T> {
    let mut v = Vec::new();
    fit(&mut v, len, value);
    v
}

/// `dst.clone_from(src)`, the copy made on the pool: a copy of a
/// node-wise array is a serial part of every build otherwise (a first
/// touch of fresh pages, or a memcpy of tens of megabytes at 10^6 nodes).
pub(crate) fn copy_from<T: Copy + Send + Sync>(dst: &mut Vec<T>, src: &[T]) {
    dst.clear();
    dst.reserve(src.len());
    dst.par_extend(src.par_iter().copied());
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A refill within the room keeps the buffer; one past it takes an
    /// eighth more, not double.
    #[test]
    fn a_refill_grows_by_an_eighth() {
        let mut v = vec![1u32; 800];
        let cap = v.capacity();
        refill(&mut v, 700, 7);
        assert_eq!((v.len(), v.capacity()), (700, cap));
        assert!(v.iter().all(|&x| x == 7));
        refill(&mut v, 801, 3);
        assert_eq!((v.len(), v.capacity()), (801, 901));
        assert!(v.iter().all(|&x| x == 3));
    }

    /// The parallel copy is the copy, in order, shorter or longer.
    #[test]
    fn a_copy_is_the_source() {
        let src: Vec<u64> = (0..100_000).map(|k| k * 7 + 1).collect();
        let mut dst = vec![5u64; 300_000];
        copy_from(&mut dst, &src);
        assert_eq!(dst, src);
        copy_from(&mut dst, &src[..10]);
        assert_eq!(dst, src[..10]);
    }
}
