//! The processes of one run (MPI's ranks) as the solver sees them: who I
//! am, how many we are, and the few collective exchanges the 3-D solver
//! needs. The core knows no MPI: the program built with the cargo feature
//! `mpi` supplies an implementation over MPICH (`src/cli/mpi.rs`), and
//! every other build runs [`Alone`].
//!
//! # Owner computes, the same bits on any number of ranks
//!
//! Every rank holds the whole state (replicated). A pass over the nodes
//! that writes one value per node (a row of the shapes, a node's velocity
//! gradient, its force) is split into contiguous shares of the rows,
//! [`share`]; each rank computes its own share, and the shares are then
//! gathered so that every rank holds every row ([`each_row`],
//! [`Ranks::all_gather`]). A row's value depends only on the replicated
//! state, never on who computed it, so a run gives the same bits on any
//! number of ranks (and of threads within each). Sums over the nodes are
//! taken after the gather, on every rank, in the fixed order of
//! `approx::sums`.
//!
//! One exception: the material's damage variables stay between steps with
//! the rank that stepped them, and every rank holds every point's few
//! marks (`material::Marks`), which is all the other passes read;
//! the variables are gathered only when something reads them all
//! (`MaterialState::share`, `Simulation::share`).
//!
//! # Errors never hang
//!
//! A pass that can fail at a row agrees on the first failing row over all
//! ranks ([`Ranks::all_min`]), and every rank then evaluates that row
//! itself, so that all stop with the same named error at the same step.

// The node fields travel as their bytes ([`Plain`]): two casts of a
// slice, kept here with the marker trait that makes them sound.
#![allow(unsafe_code)]

use std::fmt::Debug;
use std::ops::Range;

/// The ranks of a run: this process's place among them and the collective
/// exchanges. Every rank must make the same calls in the same order.
pub trait Ranks: Debug + Send + Sync {
    /// This rank, `0..size()`.
    fn rank(&self) -> usize;

    /// The number of ranks.
    fn size(&self) -> usize;

    /// Every rank's `local` bytes, concatenated in rank order into `out`,
    /// whose length is the sum of `counts` (rank `r` gives `counts[r]`
    /// bytes; `local.len() == counts[self.rank()]`).
    fn all_gather(&self, local: &[u8], counts: &[usize], out: &mut [u8]);

    /// [`Ranks::all_gather`] with this rank's bytes already in their place
    /// in `out` (after the bytes of the ranks before it). By default
    /// through a copy of them; an implementation may gather in place.
    fn all_gather_in_place(&self, counts: &[usize], out: &mut [u8]) {
        gather_through_copy(self, counts, out);
    }

    /// The smallest of every rank's `value`. (Signed: MPICH's reduction of
    /// `MPI_UINT64_T` through rsmpi took 2^64 − 1 for the minimum of 0 and
    /// 2^64 − 1, measured; `i64::MAX` is the "none" of a minimum here.)
    fn all_min(&self, value: i64) -> i64;

    /// The largest of every rank's `value`.
    fn all_max(&self, value: i64) -> i64;

    /// `bytes` of rank `root` on every rank (resized to its length).
    fn broadcast(&self, root: usize, bytes: &mut Vec<u8>);

    /// Names the line of the program whose collective comes next (the
    /// helpers below name their callers'), for the books an
    /// implementation may keep of its collectives by line (the program's
    /// `MI_MPI_STATS=2`). By default nothing.
    fn at(&self, _line: &'static std::panic::Location<'static>) {}
}

/// [`Ranks::all_gather_in_place`] through a copy of this rank's bytes
/// (the trait's default, and a fallback of an implementation's own).
pub fn gather_through_copy<R: Ranks + ?Sized>(ranks: &R, counts: &[usize], out: &mut [u8]) {
    let at: usize = counts[..ranks.rank()].iter().sum();
    let own = out[at..at + counts[ranks.rank()]].to_vec();
    ranks.all_gather(&own, counts, out);
}

/// One process alone: every exchange is the identity.
#[derive(Debug, Clone, Copy, Default)]
pub struct Alone;

impl Ranks for Alone {
    fn rank(&self) -> usize {
        0
    }
    fn size(&self) -> usize {
        1
    }
    fn all_gather(&self, local: &[u8], _counts: &[usize], out: &mut [u8]) {
        out.copy_from_slice(local);
    }
    fn all_min(&self, value: i64) -> i64 {
        value
    }
    fn all_max(&self, value: i64) -> i64 {
        value
    }
    fn broadcast(&self, _root: usize, _bytes: &mut Vec<u8>) {}
}

/// A shared handle on the ranks of a run, [`Alone`] by default: what a
/// solver's workspace holds (cloned with it, never saved).
#[derive(Debug, Clone)]
pub struct Handle(std::sync::Arc<dyn Ranks>);

impl Handle {
    /// A handle on `ranks`.
    pub fn new(ranks: std::sync::Arc<dyn Ranks>) -> Self {
        Handle(ranks)
    }
}

impl Default for Handle {
    fn default() -> Self {
        Handle(std::sync::Arc::new(Alone))
    }
}

impl std::ops::Deref for Handle {
    type Target = dyn Ranks;
    fn deref(&self) -> &(dyn Ranks + 'static) {
        &*self.0
    }
}

/// Values that travel between ranks as their bytes: plain numbers and
/// arrays of them, with no padding and no invalid bit patterns.
///
/// # Safety
///
/// Every bit pattern of `size_of::<Self>()` bytes must be a valid value,
/// and the type must have no padding.
pub unsafe trait Plain: Copy + Send + Sync + 'static {}

// SAFETY: integers and floats: every bit pattern is a value, no padding.
unsafe impl Plain for f64 {}
// SAFETY: as above.
unsafe impl Plain for u64 {}
// SAFETY: as above.
unsafe impl Plain for usize {}
// SAFETY: an array of a plain type has its elements' bytes, no padding.
unsafe impl<T: Plain, const N: usize> Plain for [T; N] {}
// SAFETY: two `f64` fields, `repr(C)`: no padding, every bit pattern a
// value.
unsafe impl Plain for crate::material::Marks {}

/// The bytes of `v`.
fn bytes<T: Plain>(v: &[T]) -> &[u8] {
    // SAFETY: a `Plain` type has no padding, so every byte of the slice is
    // initialized; the length is the slice's size in bytes.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
}

/// The bytes of `v`, writable.
fn bytes_mut<T: Plain>(v: &mut [T]) -> &mut [u8] {
    // SAFETY: as in `bytes`; any bytes written make valid `T`s (`Plain`).
    unsafe { std::slice::from_raw_parts_mut(v.as_mut_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
}

/// Rank `rank`'s share of `n` rows among `size` ranks: contiguous, in rank
/// order, as equal as whole multiples of `align` rows allow (the last rank
/// takes the remainder).
pub fn share(n: usize, rank: usize, size: usize, align: usize) -> Range<usize> {
    let align = align.max(1);
    let units = n.div_ceil(align);
    let at = |r: usize| (units * r / size * align).min(n);
    at(rank)..at(rank + 1)
}

/// Every rank's share of `n` rows ([`share`]).
pub fn shares(ranks: &dyn Ranks, n: usize, align: usize) -> Vec<Range<usize>> {
    (0..ranks.size())
        .map(|r| share(n, r, ranks.size(), align))
        .collect()
}

/// Stops unless `parts` are contiguous, in rank order, and cover `0..len`
/// (a fault of the program: the counts of a gather must cover its buffer).
fn assert_covers(parts: &[Range<usize>], len: usize) {
    assert!(
        parts.first().is_some_and(|p| p.start == 0)
            && parts.windows(2).all(|w| w[0].end == w[1].start)
            && parts.last().is_some_and(|p| p.end == len),
        "the parts of a gather cover its buffer in order: {parts:?} over {len}"
    );
}

/// After each rank has written its own part `parts[rank]` of `out`, every
/// rank's parts gathered into `out` on every rank. `parts` are contiguous,
/// in rank order, and cover `out`.
#[track_caller]
pub fn gather_parts<T: Plain>(ranks: &dyn Ranks, parts: &[Range<usize>], out: &mut [T]) {
    if ranks.size() == 1 {
        return;
    }
    // Counts that do not cover `out` would have MPI write past it.
    assert_covers(parts, out.len());
    let size = std::mem::size_of::<T>();
    let counts: Vec<usize> = parts.iter().map(|p| p.len() * size).collect();
    ranks.at(std::panic::Location::caller());
    ranks.all_gather_in_place(&counts, bytes_mut(out));
}

/// [`gather_parts`] for values that are not [`Plain`]: each rank's part
/// travels as the postcard encoding of its values mapped by `to`, and is
/// written back on the other ranks by `from`.
#[track_caller]
pub fn gather_encoded<T, W>(
    ranks: &dyn Ranks,
    parts: &[Range<usize>],
    out: &mut [T],
    to: impl Fn(&T) -> W,
    from: impl Fn(&mut T, W),
) where
    W: serde::Serialize + serde::de::DeserializeOwned,
{
    if ranks.size() == 1 {
        return;
    }
    let me = ranks.rank();
    let wire: Vec<W> = out[parts[me].clone()].iter().map(to).collect();
    let own = postcard::to_allocvec(&wire).expect("values encode into a vector");
    let (all, counts) = all_gather_bytes(ranks, &own);
    let mut at = 0;
    for (r, part) in parts.iter().enumerate() {
        let bytes = &all[at..at + counts[r]];
        at += counts[r];
        if r == me {
            continue;
        }
        // The same program encoded them: a failure is a fault, not input.
        let values: Vec<W> = postcard::from_bytes(bytes).expect("a rank's values decode");
        for (slot, v) in out[part.clone()].iter_mut().zip(values) {
            from(slot, v);
        }
    }
}

/// The widest record [`gather_records`] takes: far more than a point's
/// damage variables encode into (at most a few dozen numbers).
pub const RECORD_MAX: usize = 4096;

/// [`gather_encoded`] in records of one width, gathered in place: each
/// value's postcard encoding (of its value mapped by `to`) is padded to the
/// widest of any rank's, the records of every part are gathered into
/// `wire` (kept by the caller from one call to the next, so that a call
/// allocates nothing once it has grown), and the other ranks' records are
/// written back by `from`. The values are encoded and decoded on the pool.
/// The same values on every rank as [`gather_encoded`] (the same
/// encoding): only the way they travel differs.
///
/// # Panics
///
/// If a value encodes into more than [`RECORD_MAX`] bytes (a fault of the
/// program, not of its input: the types that travel are of fixed size).
#[track_caller]
pub fn gather_records<T, W>(
    ranks: &dyn Ranks,
    parts: &[Range<usize>],
    out: &mut [T],
    wire: &mut Vec<u8>,
    to: impl Fn(&T) -> W + Sync,
    from: impl Fn(&mut T, W) + Sync,
) where
    T: Send + Sync,
    W: serde::Serialize + serde::de::DeserializeOwned,
{
    use rayon::prelude::*;
    if ranks.size() == 1 {
        return;
    }
    // Counts that do not cover `out` would have MPI write past `wire`.
    assert_covers(parts, out.len());
    let own = parts[ranks.rank()].clone();
    // The width: the longest encoding of any rank's values.
    let longest = out[own.clone()]
        .par_iter()
        .map(|v| encoded_len(&to(v)))
        .max()
        .unwrap_or(0);
    let width = record_width(ranks, longest);
    if width == 0 {
        return;
    }
    wire.resize(out.len() * width, 0);
    wire[own.start * width..own.end * width]
        .par_chunks_mut(width)
        .zip(&out[own.clone()])
        .for_each(|(slot, v)| {
            postcard::to_slice(&to(v), slot).expect("a record fits its width");
        });
    let counts: Vec<usize> = parts.iter().map(|p| p.len() * width).collect();
    ranks.at(std::panic::Location::caller());
    ranks.all_gather_in_place(&counts, &mut wire[..]);
    let wire: &[u8] = wire;
    out.par_iter_mut()
        .enumerate()
        .filter(|(i, _)| !own.contains(i))
        .for_each(|(i, slot)| {
            // The same program encoded them: a failure is a fault, not input.
            let w = postcard::from_bytes(&wire[i * width..(i + 1) * width])
                .expect("a rank's record decodes");
            from(slot, w);
        });
}

/// [`gather_records`] of listed rows: each rank's rows `lists[rank]` (no
/// row in two lists) travel to every rank, in records of one width (the
/// longest encoding of any listed value) through `wire`, and `from` writes
/// each other rank's; a row in no list is left as it was. The damage
/// variables of the points that change rank at a new split of the material
/// pass (`MaterialState::hand_over`). Nothing travels where no rank lists
/// a row.
///
/// # Panics
///
/// As [`gather_records`].
#[track_caller]
pub fn gather_records_listed<T, W>(
    ranks: &dyn Ranks,
    lists: &[Vec<usize>],
    out: &mut [T],
    wire: &mut Vec<u8>,
    to: impl Fn(&T) -> W + Sync,
    from: impl Fn(&mut T, W),
) where
    T: Send + Sync,
    W: serde::Serialize + serde::de::DeserializeOwned,
{
    use rayon::prelude::*;
    if ranks.size() == 1 {
        return;
    }
    let me = ranks.rank();
    let longest = lists[me]
        .par_iter()
        .map(|&i| encoded_len(&to(&out[i])))
        .max()
        .unwrap_or(0);
    let width = record_width(ranks, longest);
    if width == 0 {
        return;
    }
    let at = list_offsets(lists);
    wire.clear();
    wire.resize(at[lists.len()] * width, 0);
    let out_ref: &[T] = out;
    wire[at[me] * width..at[me + 1] * width]
        .par_chunks_mut(width)
        .zip(&lists[me])
        .for_each(|(slot, &i)| {
            postcard::to_slice(&to(&out_ref[i]), slot).expect("a record fits its width");
        });
    let counts: Vec<usize> = lists.iter().map(|l| l.len() * width).collect();
    ranks.at(std::panic::Location::caller());
    ranks.all_gather_in_place(&counts, &mut wire[..]);
    for (r, list) in lists.iter().enumerate().filter(|&(r, _)| r != me) {
        for (k, &i) in list.iter().enumerate() {
            let slot = &wire[(at[r] + k) * width..(at[r] + k + 1) * width];
            // The same program encoded them: a failure is a fault, not input.
            from(
                &mut out[i],
                postcard::from_bytes(slot).expect("a rank's record decodes"),
            );
        }
    }
}

/// Where each rank's list starts in the lists joined in rank order, and
/// (last) their total length.
fn list_offsets(lists: &[Vec<usize>]) -> Vec<usize> {
    let mut at = Vec::with_capacity(lists.len() + 1);
    at.push(0);
    for l in lists {
        at.push(at[at.len() - 1] + l.len());
    }
    at
}

/// The length of a value's encoding, at most [`RECORD_MAX`].
fn encoded_len<W: serde::Serialize>(w: &W) -> usize {
    let len = postcard::experimental::serialized_size(w).expect("a value encodes");
    assert!(len <= RECORD_MAX, "a record fits RECORD_MAX bytes: {len}");
    len
}

/// The records' width: the longest of each rank's `longest` encoding (a
/// collective call).
#[track_caller]
fn record_width(ranks: &dyn Ranks, longest: usize) -> usize {
    ranks.at(std::panic::Location::caller());
    usize::try_from(ranks.all_max(longest as i64)).unwrap_or(0)
}

/// Every rank's `mine`, of any length, joined in rank order, with each
/// rank's length (two exchanges).
#[track_caller]
pub fn all_gather_bytes(ranks: &dyn Ranks, mine: &[u8]) -> (Vec<u8>, Vec<usize>) {
    let counts: Vec<usize> = all_gather_one(ranks, mine.len() as u64)
        .into_iter()
        .map(|l| l as usize)
        .collect();
    let mut all = vec![0u8; counts.iter().sum()];
    ranks.at(std::panic::Location::caller());
    ranks.all_gather(mine, &counts, &mut all);
    (all, counts)
}

/// The largest of every rank's `value` by [`f64::max`] in rank order (a
/// NaN loses, as in a serial `fold` by `f64::max`).
#[track_caller]
pub fn all_max_f64(ranks: &dyn Ranks, value: f64) -> f64 {
    if ranks.size() == 1 {
        return value;
    }
    all_gather_one(ranks, value).into_iter().fold(0.0, f64::max)
}

/// `f(i, &mut out[i])` for the rows of this rank's share (on the pool),
/// then the shares gathered so that every rank holds every row.
#[track_caller]
pub fn each_row<T: Plain>(ranks: &dyn Ranks, out: &mut [T], f: impl Fn(usize, &mut T) + Sync) {
    use rayon::iter::{IndexedParallelIterator, IntoParallelRefMutIterator, ParallelIterator};
    if ranks.size() == 1 {
        // Alone: the plain pass, allocating nothing (a step between
        // rebuilds allocates nothing, tests/mlpg_alloc.rs).
        out.par_iter_mut().enumerate().for_each(|(i, v)| f(i, v));
        return;
    }
    each_row_in(ranks, &shares(ranks, out.len(), 1), out, f);
}

/// Every rank's `mine`, of any length, joined in rank order (two
/// exchanges: the lengths, then the values in place).
#[track_caller]
pub fn all_gather_varying<T: Plain + Default>(ranks: &dyn Ranks, mine: &[T]) -> Vec<T> {
    if ranks.size() == 1 {
        return mine.to_vec();
    }
    let mut parts = Vec::with_capacity(ranks.size());
    let mut at = 0;
    for c in all_gather_one(ranks, mine.len() as u64) {
        parts.push(at..at + c as usize);
        at += c as usize;
    }
    let mut all = vec![T::default(); at];
    all[parts[ranks.rank()].clone()].copy_from_slice(mine);
    gather_parts(ranks, &parts, &mut all);
    all
}

/// After each rank has written its listed rows `lists[rank]` (ascending;
/// no row in two lists), every rank's listed rows on every rank: each rank
/// packs its rows by `get`, the rows travel packed in rank order through
/// `wire` (kept by the caller from one call to the next, so that a call
/// allocates nothing once it has grown), and `put` writes each other
/// rank's rows; a row in no list is left as it was. The halo of a pass
/// whose readers read only some rows of the other ranks (the material
/// fields of the 3-D solver: `solver::mlpg3d::halo`). `get` and `put`
/// read and write the rows of `fields`.
#[track_caller]
pub fn gather_listed<T: Plain + Default, F: ?Sized>(
    ranks: &dyn Ranks,
    lists: &[Vec<usize>],
    wire: &mut Vec<T>,
    fields: &mut F,
    (get, put): (impl Fn(&F, usize) -> T, impl Fn(&mut F, usize, &T)),
) {
    if ranks.size() == 1 {
        return;
    }
    let me = ranks.rank();
    let at = list_offsets(lists);
    wire.clear();
    wire.resize(at[lists.len()], T::default());
    for (w, &i) in wire[at[me]..at[me + 1]].iter_mut().zip(&lists[me]) {
        *w = get(fields, i);
    }
    let size = std::mem::size_of::<T>();
    let counts: Vec<usize> = lists.iter().map(|l| l.len() * size).collect();
    ranks.at(std::panic::Location::caller());
    ranks.all_gather_in_place(&counts, bytes_mut(wire));
    for (r, list) in lists.iter().enumerate() {
        if r == me {
            continue;
        }
        for (w, &i) in wire[at[r]..at[r + 1]].iter().zip(list) {
            put(fields, i, w);
        }
    }
}

/// [`each_row`] over the given `parts` of the rows (contiguous, in rank
/// order, covering `out`) in place of equal shares: `f(i, &mut out[i])`
/// for the rows of this rank's part, then the parts gathered so that
/// every rank holds every row.
#[track_caller]
pub fn each_row_in<T: Plain>(
    ranks: &dyn Ranks,
    parts: &[Range<usize>],
    out: &mut [T],
    f: impl Fn(usize, &mut T) + Sync,
) {
    each_own_row(ranks, parts, out, f);
    gather_parts(ranks, parts, out);
}

/// Contiguous parts of the rows, in order, one for each of `parts`, each
/// with about an equal share of the total `weight` of its rows: part `r`
/// starts at the boundary between rows nearest to `r / parts` of the
/// total (never behind the one before), so that a part's weight is within
/// the heaviest row's of an equal share. With no weight at all the parts
/// are equal in rows ([`share`]).
pub fn weighted_parts(weight: &[usize], parts: usize) -> Vec<Range<usize>> {
    let n = weight.len();
    let total: usize = weight.iter().sum();
    if total == 0 {
        return (0..parts).map(|r| share(n, r, parts, 1)).collect();
    }
    let mut starts = Vec::with_capacity(parts + 1);
    let (mut row, mut before) = (0usize, 0usize);
    for r in 0..parts {
        // Past the rows whose middle lies before the goal `total r / parts`.
        while row < n && (2 * before + weight[row]) * parts < 2 * total * r {
            before += weight[row];
            row += 1;
        }
        starts.push(row);
    }
    starts.push(n);
    starts.windows(2).map(|w| w[0]..w[1]).collect()
}

/// Every rank's `value`, in rank order (one exchange).
#[track_caller]
pub fn all_gather_one<T: Plain + Default>(ranks: &dyn Ranks, value: T) -> Vec<T> {
    let mut all = vec![T::default(); ranks.size()];
    all[ranks.rank()] = value;
    let each: Vec<Range<usize>> = (0..ranks.size()).map(|r| r..r + 1).collect();
    gather_parts(ranks, &each, &mut all);
    all
}

/// [`each_row_in`] for a pass whose rows are mostly `T::default()`, bit
/// for bit (the shifts of the 3-D solver's nodes: a few dozen of 10^4
/// move at a step): `f(i, &mut out[i])` for the rows of this rank's part,
/// then only the rows whose bits differ from the default's travel, with
/// their indices (three exchanges: the counts, the indices, the rows,
/// through `wire`, kept by the caller), and every other row of the other
/// ranks' parts is set to the default. The bits of [`each_row_in`].
#[track_caller]
pub fn each_row_sparse<T: Plain + Default>(
    ranks: &dyn Ranks,
    parts: &[Range<usize>],
    (out, wire): (&mut [T], &mut Vec<T>),
    f: impl Fn(usize, &mut T) + Sync,
) {
    each_own_row(ranks, parts, out, f);
    if ranks.size() == 1 {
        return;
    }
    let own = parts[ranks.rank()].clone();
    let zero = T::default();
    let is_zero = |v: &T| bytes(std::slice::from_ref(v)) == bytes(std::slice::from_ref(&zero));
    let mine: Vec<usize> = own.clone().filter(|&i| !is_zero(&out[i])).collect();
    out[..own.start].fill(zero);
    out[own.end..].fill(zero);
    let all = all_gather_varying(ranks, &mine);
    // In rank order, each ascending: split by the parts.
    let mut lists = vec![Vec::new(); parts.len()];
    let mut r = 0;
    for i in all {
        while i >= parts[r].end {
            r += 1;
        }
        lists[r].push(i);
    }
    let get = |o: &[T], i: usize| o[i];
    let put = |o: &mut [T], i: usize, v: &T| o[i] = *v;
    gather_listed(ranks, &lists, wire, out, (get, put));
}

/// `f(i, &mut out[i])` for the rows of this rank's part `parts[rank]`
/// (`parts` contiguous, in rank order, covering `out`), on the pool; the
/// other rows are left as they were (a pass whose next reader reads only
/// this rank's rows of the same parts).
pub fn each_own_row<T: Send>(
    ranks: &dyn Ranks,
    parts: &[Range<usize>],
    out: &mut [T],
    f: impl Fn(usize, &mut T) + Sync,
) {
    use rayon::iter::{IndexedParallelIterator, IntoParallelRefMutIterator, ParallelIterator};
    assert_covers(parts, out.len());
    let own = parts[ranks.rank()].clone();
    let start = own.start;
    out[own]
        .par_iter_mut()
        .enumerate()
        .for_each(|(k, v)| f(start + k, v));
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::sync::{Arc, Barrier, Mutex};

    /// Ranks as threads of one process (a test's stand-in for MPI): each
    /// exchange puts every rank's part in a common slot between two
    /// barriers.
    #[derive(Debug)]
    struct Threads {
        rank: usize,
        size: usize,
        slots: Arc<(Mutex<Vec<Vec<u8>>>, Barrier)>,
    }

    impl Threads {
        /// Every rank's `mine`, in rank order.
        fn exchange(&self, mine: Vec<u8>) -> Vec<Vec<u8>> {
            let (slots, barrier) = &*self.slots;
            slots.lock().unwrap()[self.rank] = mine;
            barrier.wait();
            let all = slots.lock().unwrap().clone();
            barrier.wait();
            all
        }
    }

    impl Ranks for Threads {
        fn rank(&self) -> usize {
            self.rank
        }
        fn size(&self) -> usize {
            self.size
        }
        fn all_gather(&self, local: &[u8], counts: &[usize], out: &mut [u8]) {
            assert_eq!(local.len(), counts[self.rank]);
            let all = self.exchange(local.to_vec());
            assert_eq!(all.iter().map(Vec::len).collect::<Vec<_>>(), counts);
            out.copy_from_slice(&all.concat());
        }
        fn all_min(&self, value: i64) -> i64 {
            let all = self.exchange(value.to_le_bytes().to_vec());
            all.iter()
                .map(|b| i64::from_le_bytes(b[..8].try_into().unwrap()))
                .min()
                .unwrap()
        }
        fn all_max(&self, value: i64) -> i64 {
            -self.all_min(-value)
        }
        fn broadcast(&self, root: usize, bytes: &mut Vec<u8>) {
            let all = self.exchange(bytes.clone());
            *bytes = all[root].clone();
        }
    }

    /// `f()` on thread-rank `rank`; a panic aborts the test process: the
    /// other thread-ranks would wait at their next collective for ever (a
    /// test that planted a fault hung rather than failed).
    fn or_abort<R>(rank: usize, f: impl FnOnce() -> R) -> R {
        match std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)) {
            Ok(r) => r,
            Err(_) => {
                eprintln!(
                    "thread-rank {rank} panicked (above): aborting, as the others would wait"
                );
                std::process::abort()
            }
        }
    }

    /// [`on_threads`] with each rank as a [`Handle`] (what a solver's
    /// `set_ranks` takes).
    pub(crate) fn on_thread_handles<R: Send>(
        size: usize,
        f: impl Fn(Handle) -> R + Sync,
    ) -> Vec<R> {
        let slots = Arc::new((Mutex::new(vec![Vec::new(); size]), Barrier::new(size)));
        std::thread::scope(|s| {
            let handles: Vec<_> = (0..size)
                .map(|rank| {
                    let ranks = Handle::new(Arc::new(Threads {
                        rank,
                        size,
                        slots: slots.clone(),
                    }));
                    let f = &f;
                    s.spawn(move || or_abort(rank, || f(ranks)))
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        })
    }

    /// `f` on `size` ranks, each a thread; their results in rank order.
    pub(crate) fn on_threads<R: Send>(size: usize, f: impl Fn(&dyn Ranks) -> R + Sync) -> Vec<R> {
        let slots = Arc::new((Mutex::new(vec![Vec::new(); size]), Barrier::new(size)));
        std::thread::scope(|s| {
            let handles: Vec<_> = (0..size)
                .map(|rank| {
                    let ranks = Threads {
                        rank,
                        size,
                        slots: slots.clone(),
                    };
                    let f = &f;
                    s.spawn(move || or_abort(rank, || f(&ranks)))
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        })
    }

    /// On ranks as threads, a pass over the rows gives every rank every
    /// row, as the plain pass does; the largest and smallest agree.
    /// The weighted parts cover the rows in order, each within the
    /// heaviest row's weight of an equal share: one heavy row goes alone;
    /// no weight gives equal parts; more parts than rows leave some empty.
    #[test]
    fn weighted_parts_share_the_weight() {
        assert_eq!(
            weighted_parts(&[1, 1, 1, 1, 4, 4, 4, 4], 2),
            vec![0..5, 5..8]
        );
        assert_eq!(weighted_parts(&[8, 1, 1, 1, 1], 2), vec![0..1, 1..5]);
        assert_eq!(weighted_parts(&[0; 6], 3), vec![0..2, 2..4, 4..6]);
        let weight: Vec<usize> = (0..1000).map(|i| (i * 7919) % 61).collect();
        let total: usize = weight.iter().sum();
        let heaviest = *weight.iter().max().unwrap();
        for parts in 1..9 {
            let got = weighted_parts(&weight, parts);
            assert_eq!(got.len(), parts);
            assert_eq!((got[0].start, got[parts - 1].end), (0, 1000));
            assert!(got.windows(2).all(|w| w[0].end == w[1].start));
            for p in &got {
                let w: usize = weight[p.clone()].iter().sum();
                let share = total as f64 / parts as f64;
                assert!(
                    (w as f64 - share).abs() <= heaviest as f64,
                    "{parts}: {w} of {share}"
                );
            }
        }
        let got = weighted_parts(&[3, 5], 4);
        assert_eq!(got.iter().map(|r| r.len()).sum::<usize>(), 2);
    }

    #[test]
    fn on_threads_each_row_gives_every_rank_the_plain_pass() {
        for size in [2, 3] {
            let got = on_threads(size, |ranks| {
                let mut out = vec![0.0; 1001];
                each_row(ranks, &mut out, |i, v| *v = (i * i) as f64);
                let top = ranks.all_max(ranks.rank() as i64);
                let low = ranks.all_min(ranks.rank() as i64 - 5);
                (out, top, low)
            });
            for (out, top, low) in got {
                assert!(out.iter().enumerate().all(|(i, v)| *v == (i * i) as f64));
                assert_eq!((top, low), (size as i64 - 1, -5));
            }
        }
    }

    /// [`each_row_sparse`] gives every rank the bits of [`each_row_in`]:
    /// on 2-4 ranks as threads, parts of unequal length (one empty), rows
    /// that are zero, rows that are zero but for a sign (−0.0 travels: its
    /// bits are not the default's), rows of any value, and other ranks'
    /// rows holding stale values before the call.
    #[test]
    fn sparse_rows_give_the_bits_of_the_whole_gather() {
        let value = |i: usize| -> [f64; 3] {
            match i % 5 {
                0 => [i as f64, -1.5, 0.25],
                1 => [0.0, -0.0, 0.0],
                _ => [0.0; 3],
            }
        };
        for size in [2, 3, 4] {
            let parts: Vec<Range<usize>> = {
                let mut cuts: Vec<usize> = (0..=size).map(|r| r * 47 / size).collect();
                cuts[1] = cuts[0]; // rank 0 owns nothing
                cuts.windows(2).map(|w| w[0]..w[1]).collect()
            };
            let got = on_threads(size, |ranks| {
                let stale = |_: usize| [f64::NAN, 7.0, -(ranks.rank() as f64)];
                let mut whole: Vec<[f64; 3]> = (0..47).map(stale).collect();
                each_row_in(ranks, &parts, &mut whole, |i, v| *v = value(i));
                let mut sparse: Vec<[f64; 3]> = (0..47).map(stale).collect();
                let mut wire = Vec::new();
                each_row_sparse(ranks, &parts, (&mut sparse, &mut wire), |i, v| {
                    *v = value(i)
                });
                let bits = |v: &[[f64; 3]]| -> Vec<u64> {
                    v.iter().flatten().map(|x| x.to_bits()).collect()
                };
                (bits(&whole), bits(&sparse))
            });
            for (rank, (whole, sparse)) in got.iter().enumerate() {
                assert!(whole == sparse, "rank {rank} of {size}");
            }
        }
    }

    /// A gather of listed rows writes every rank's listed rows on every
    /// rank, and leaves each row in no list as the rank had it (on 2-4
    /// ranks as threads, some lists empty; a second call reuses the wire).
    #[test]
    fn listed_rows_travel_and_the_rest_stay() {
        for size in [2, 3, 4] {
            // Rank r lists the rows i with i % 7 == r (none for r >= 7).
            let lists: Vec<Vec<usize>> = (0..size)
                .map(|r| (0..50).filter(|i| i % 7 == r && r != 1).collect())
                .collect();
            let got = on_threads(size, |ranks| {
                let me = ranks.rank();
                // Each rank's own rows hold the true value; the others a
                // mark of the rank.
                let mut out: Vec<[f64; 2]> = (0..50)
                    .map(|i| {
                        if lists[me].contains(&i) {
                            [i as f64, 1.0]
                        } else {
                            [-(me as f64), 0.0]
                        }
                    })
                    .collect();
                let mut wire = Vec::new();
                let get = |o: &Vec<[f64; 2]>, i: usize| o[i];
                let put = |o: &mut Vec<[f64; 2]>, i: usize, v: &[f64; 2]| o[i] = *v;
                gather_listed(ranks, &lists, &mut wire, &mut out, (get, put));
                let grown = wire.capacity();
                gather_listed(ranks, &lists, &mut wire, &mut out, (get, put));
                (me, out, grown == wire.capacity())
            });
            for (me, out, kept) in got {
                assert!(kept);
                for (i, v) in out.iter().enumerate() {
                    let listed = lists.iter().any(|l| l.contains(&i));
                    let want = if listed {
                        [i as f64, 1.0]
                    } else {
                        [-(me as f64), 0.0]
                    };
                    assert_eq!(*v, want, "rank {me} of {size}, row {i}");
                }
            }
        }
    }

    /// The shares cover the rows once, in order, on their alignment, for
    /// every count of rows and ranks tried.
    #[test]
    fn the_shares_cover_every_row_once_in_order() {
        for size in 1..=5 {
            for n in [0, 1, 2, 7, 255, 256, 257, 1000, 4097] {
                for align in [1, 256] {
                    let s: Vec<_> = (0..size).map(|r| share(n, r, size, align)).collect();
                    assert_eq!(s[0].start, 0);
                    assert_eq!(s[size - 1].end, n, "n {n} size {size} align {align}");
                    for w in s.windows(2) {
                        assert_eq!(w[0].end, w[1].start);
                        assert!(w[0].end % align == 0 || w[0].end == n);
                    }
                }
            }
        }
        // Equal shares where the rows divide.
        assert_eq!(share(12, 1, 3, 1), 4..8);
    }

    /// Records of one width give every rank the values that the encoded
    /// gather gives (values whose encodings differ in length, NaN's bits
    /// and all, on parts of unequal length, some empty), and a second call
    /// reuses the wire without growing it.
    #[test]
    fn records_gather_the_values_of_the_encoded_gather() {
        type V = Option<(f64, [f64; 3])>;
        let value = |i: usize| -> V {
            (!i.is_multiple_of(3)).then(|| {
                let x = if i == 7 {
                    f64::from_bits(0x7ff8_dead_beef_0001)
                } else {
                    i as f64
                };
                (x, [0.5 * i as f64, -(i as f64), 1e300])
            })
        };
        let n = 1001;
        for size in [2, 3, 4] {
            let got = on_threads(size, |ranks| {
                // Unequal parts; with four ranks the last one's is empty.
                let cuts: &[usize] = match size {
                    2 => &[0, 333, n],
                    3 => &[0, 83, 333, n],
                    _ => &[0, 37, 148, n, n],
                };
                let parts: Vec<Range<usize>> = cuts.windows(2).map(|w| w[0]..w[1]).collect();
                let own = parts[ranks.rank()].clone();
                let start = |own: &Range<usize>| -> Vec<V> {
                    (0..n)
                        .map(|i| {
                            if own.contains(&i) {
                                value(i)
                            } else {
                                Some((-1.0, [0.0; 3]))
                            }
                        })
                        .collect()
                };
                let (mut a, mut b) = (start(&own), start(&own));
                gather_encoded(ranks, &parts, &mut a, |v| *v, |s, w| *s = w);
                let mut wire = Vec::new();
                gather_records(ranks, &parts, &mut b, &mut wire, |v| *v, |s, w| *s = w);
                let grown = wire.capacity();
                let mut c = start(&own);
                gather_records(ranks, &parts, &mut c, &mut wire, |v| *v, |s, w| *s = w);
                (a, b, c, grown == wire.capacity())
            });
            for (a, b, c, kept) in got {
                let bits = |v: &[V]| -> Vec<Option<(u64, [u64; 3])>> {
                    v.iter()
                        .map(|x| x.map(|(f, g)| (f.to_bits(), g.map(f64::to_bits))))
                        .collect()
                };
                let want: Vec<V> = (0..n).map(value).collect();
                assert_eq!(bits(&a), bits(&want), "{size} ranks: the encoded gather");
                assert_eq!(bits(&b), bits(&want), "{size} ranks: the records");
                assert_eq!(bits(&c), bits(&want), "{size} ranks: the records again");
                assert!(kept, "{size} ranks: the wire is reused");
            }
        }
    }

    /// A pass over this rank's own rows writes exactly the rows of its part
    /// of weighted parts (the shifting's freedoms and shifts go by the same
    /// parts), and a pass over the rows in those parts gives every rank
    /// every row; the rows outside a rank's part keep what they held.
    #[test]
    fn each_own_row_writes_the_rows_of_its_part() {
        let n = 1001;
        let weight: Vec<usize> = (0..n).map(|i| 1 + (i * 7919) % 61).collect();
        for size in 1..5 {
            let parts = weighted_parts(&weight, size);
            let got = on_threads(size, |ranks| {
                let mut own = vec![-1.0; n];
                each_own_row(ranks, &parts, &mut own, |i, v| *v = i as f64);
                let mut all = vec![-1.0; n];
                each_row_in(ranks, &parts, &mut all, |i, v| *v = 2.0 * i as f64);
                (ranks.rank(), own, all)
            });
            for (rank, own, all) in got {
                for i in 0..n {
                    let want = if parts[rank].contains(&i) {
                        i as f64
                    } else {
                        -1.0
                    };
                    assert_eq!(own[i], want, "{size} ranks, rank {rank}, row {i}");
                    assert_eq!(all[i], 2.0 * i as f64, "{size} ranks, rank {rank}, row {i}");
                }
            }
        }
    }

    /// Alone, a pass over the rows is the plain pass.
    #[test]
    fn alone_each_row_is_the_plain_pass() {
        let mut out = vec![[0.0; 2]; 1001];
        each_row(&Alone, &mut out, |i, v| *v = [i as f64, 2.0 * i as f64]);
        for (i, v) in out.iter().enumerate() {
            assert_eq!(*v, [i as f64, 2.0 * i as f64]);
        }
    }
}
