//! Sums over the nodes on the pool, in a fixed order: the nodes in blocks
//! of [`BLOCK`], each block summed in node order by one thread, then the
//! blocks' sums pairwise over a fixed binary tree (the halves of the blocks,
//! then their halves, ...). Neither the blocks nor the tree depend on the
//! number of threads, so neither do the bits; nothing is allocated (a step
//! between rebuilds allocates nothing, `tests/mlpg_alloc.rs`), and the
//! serial part is one addition per level of the tree.

/// Nodes per block.
pub const BLOCK: usize = 1024;

/// `fold` of `f(i)` over `0..n` from `zero`, block by block on the pool,
/// then `join` of the blocks' results over the fixed tree, the left half
/// first (the first `Err` in node order wins where `T` is a `Result`, as a
/// serial pass would stop there).
pub(crate) fn ordered<T: Send>(
    n: usize,
    zero: impl Fn() -> T + Sync,
    fold: impl Fn(T, usize) -> T + Sync,
    join: impl Fn(T, T) -> T + Sync,
) -> T {
    fn tree<T: Send>(
        blocks: std::ops::Range<usize>,
        n: usize,
        zero: &(impl Fn() -> T + Sync),
        fold: &(impl Fn(T, usize) -> T + Sync),
        join: &(impl Fn(T, T) -> T + Sync),
    ) -> T {
        if blocks.len() <= 1 {
            let b = blocks.start;
            return (b * BLOCK..n.min((b + 1) * BLOCK)).fold(zero(), fold);
        }
        let mid = blocks.start + blocks.len() / 2;
        let (a, b) = rayon::join(
            || tree(blocks.start..mid, n, zero, fold, join),
            || tree(mid..blocks.end, n, zero, fold, join),
        );
        join(a, b)
    }
    tree(0..n.div_ceil(BLOCK).max(1), n, &zero, &fold, &join)
}

/// [`ordered`] shared among `ranks`: rank `r` folds its blocks `parts[r]`
/// (contiguous, in rank order, covering the blocks of [`BLOCK`] nodes:
/// `fold` need read only that rank's nodes), the blocks' results travel
/// as `to`'s plain values and come back by `from`, and every rank joins
/// them over the same tree. The same bits as [`ordered`] on any number of
/// ranks and for any parts.
pub(crate) fn ordered_on<T: Send, W: crate::ranks::Plain + Default>(
    ranks: &dyn crate::ranks::Ranks,
    n: usize,
    parts: &[std::ops::Range<usize>],
    (zero, fold, join): (
        impl Fn() -> T + Sync,
        impl Fn(T, usize) -> T + Sync,
        impl Fn(T, T) -> T + Sync,
    ),
    (to, from): (impl Fn(&T) -> W + Sync, impl Fn(&W) -> T),
) -> T {
    use rayon::iter::{IndexedParallelIterator, IntoParallelRefMutIterator, ParallelIterator};
    if ranks.size() == 1 {
        return ordered(n, zero, fold, join);
    }
    let blocks = n.div_ceil(BLOCK).max(1);
    debug_assert_eq!(parts.last().map(|p| p.end), Some(blocks));
    let own = parts[ranks.rank()].clone();
    let mut wire = vec![W::default(); blocks];
    let first = own.start;
    wire[own].par_iter_mut().enumerate().for_each(|(k, w)| {
        let b = first + k;
        *w = to(&(b * BLOCK..n.min((b + 1) * BLOCK)).fold(zero(), &fold));
    });
    crate::ranks::gather_parts(ranks, parts, &mut wire);
    let mut leaves: Vec<Option<T>> = wire.iter().map(|w| Some(from(w))).collect();
    // The tree of `ordered`, over the blocks' results.
    fn tree<T>(
        blocks: std::ops::Range<usize>,
        leaves: &mut [Option<T>],
        join: &impl Fn(T, T) -> T,
    ) -> T {
        if blocks.len() <= 1 {
            return leaves[blocks.start].take().expect("each block joined once");
        }
        let mid = blocks.start + blocks.len() / 2;
        let a = tree(blocks.start..mid, leaves, join);
        let b = tree(mid..blocks.end, leaves, join);
        join(a, b)
    }
    tree(0..blocks, &mut leaves, &join)
}

/// `Σ f(i)` over `0..n` in the order of [`ordered`].
pub(crate) fn sum(n: usize, f: impl Fn(usize) -> f64 + Sync) -> f64 {
    ordered(n, || 0.0, |s, i| s + f(i), |a, b| a + b)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The blocked sum is its plain twin: the same bits on 1, 2 and 3
    /// threads, equal to the serial blocks' sums added pairwise over the
    /// same halves, and within round-off of the serial sum in node order.
    #[test]
    fn the_blocked_sum_has_the_same_bits_on_any_threads() {
        let mut rng = crate::test_rng::rng(3);
        let x: Vec<f64> = (0..5 * BLOCK + 17).map(|_| rng() - 0.3).collect();
        // The plain twin: the serial blocks' sums, then pairwise over the
        // same halves.
        fn pairwise(s: &[f64]) -> f64 {
            match s.len() {
                0 => 0.0,
                1 => s[0],
                k => pairwise(&s[..k / 2]) + pairwise(&s[k / 2..]),
            }
        }
        let blocks: Vec<f64> = x.chunks(BLOCK).map(|c| c.iter().sum::<f64>()).collect();
        let plain = pairwise(&blocks);
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let got = pool.install(|| sum(x.len(), |i| x[i]));
            assert_eq!(got.to_bits(), plain.to_bits(), "{threads} threads");
        }
        let serial: f64 = x.iter().sum();
        assert!((plain - serial).abs() < 1e-12 * x.len() as f64);
        assert_eq!(sum(0, |i| x[i]), 0.0);
    }

    /// Shared among ranks (each a thread with a share of the blocks, its
    /// blocks' results through their wire form), the sum has the bits of
    /// the plain one, and the first error in node order still wins.
    #[test]
    fn the_sum_shared_among_ranks_has_the_bits_of_the_plain_one() {
        let mut rng = crate::test_rng::rng(5);
        for n in [0, 17, BLOCK, 5 * BLOCK + 17, 9 * BLOCK] {
            let x: Vec<f64> = (0..n).map(|_| rng() - 0.3).collect();
            let plain = sum(n, |i| x[i]);
            let blocks = n.div_ceil(BLOCK).max(1);
            for size in [1, 2, 3, 4] {
                // Equal parts, and parts growing with the rank (the first
                // empty when there are few blocks).
                let skewed: Vec<std::ops::Range<usize>> = (0..size)
                    .map(|r| {
                        blocks * r * r / (size * size)..blocks * (r + 1) * (r + 1) / (size * size)
                    })
                    .collect();
                for parts in [None, Some(&skewed)] {
                    let got = crate::ranks::tests::on_threads(size, |ranks| {
                        let equal = crate::ranks::shares(ranks, blocks, 1);
                        ordered_on(
                            ranks,
                            n,
                            parts.unwrap_or(&equal),
                            (|| 0.0, |s, i| s + x[i], |a, b| a + b),
                            (|s: &f64| [*s], |w: &[f64; 1]| w[0]),
                        )
                    });
                    for g in got {
                        assert_eq!(
                            g.to_bits(),
                            plain.to_bits(),
                            "n {n}, {size} ranks, {parts:?}"
                        );
                    }
                }
            }
        }
        let n = 5 * BLOCK;
        let bad = [BLOCK + 3, 3 * BLOCK + 1];
        let got = crate::ranks::tests::on_threads(3, |ranks| {
            ordered_on(
                ranks,
                n,
                &crate::ranks::shares(ranks, n.div_ceil(BLOCK), 1),
                (
                    || Ok(0.0),
                    |s: Result<f64, usize>, i| {
                        let s = s?;
                        if bad.contains(&i) {
                            Err(i)
                        } else {
                            Ok(s + 1.0)
                        }
                    },
                    |a, b| a.and_then(|a| b.map(|b| a + b)),
                ),
                (
                    |r: &Result<f64, usize>| match r {
                        Ok(v) => [0.0, *v],
                        Err(i) => [1.0, *i as f64],
                    },
                    |w: &[f64; 2]| {
                        if w[0] == 0.0 {
                            Ok(w[1])
                        } else {
                            Err(w[1] as usize)
                        }
                    },
                ),
            )
        });
        assert!(got.iter().all(|g| *g == Err(bad[0])), "{got:?}");
    }

    /// The first error in node order wins, as in a serial pass.
    #[test]
    fn the_first_error_in_node_order_wins() {
        let n = 3 * BLOCK;
        for bad in [[5, 2 * BLOCK + 1], [BLOCK + 3, BLOCK + 900]] {
            let got = ordered(
                n,
                || Ok(0usize),
                |s: Result<usize, usize>, i| {
                    let s = s?;
                    if bad.contains(&i) { Err(i) } else { Ok(s + 1) }
                },
                |a, b| a.and_then(|a| b.map(|b| a + b)),
            );
            assert_eq!(got, Err(bad[0]));
        }
        let all = ordered(
            n,
            || Ok::<usize, usize>(0),
            |s, _| s.map(|s| s + 1),
            |a, b| a.and_then(|a| b.map(|b| a + b)),
        );
        assert_eq!(all, Ok(n));
    }
}
