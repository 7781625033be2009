//! A team of pool threads for the parallel passes of one step.
//!
//! On a virtual machine a rayon worker that has gone to sleep takes tens of
//! microseconds to wake, and a fork-join per pass pays that at its start and
//! at its join several times a step. A [`Team`] is set up once a step
//! instead: the thread running the step (the leader) spawns followers on the
//! pool, and every pass is shared out chunk by chunk through one atomic
//! claim word, the leader taking chunks from the front and the followers
//! from the back (so each thread keeps to the same particles, and finds
//! their rows in its own cache, from pass to pass); between passes the
//! followers spin, then yield.
//!
//! Guarantees:
//! - **Results do not depend on the team.** Each chunk is computed by
//!   whoever claims it, with the same operations; the leader alone adds up
//!   the per-chunk results afterwards, in chunk order.
//! - **No follower is needed for progress.** The leader claims chunks too
//!   and waits only for chunks that a running follower has claimed and is
//!   computing; a pass finishes with no follower at all. A follower that
//!   starts on the leader's own thread leaves at once, and one that finds no
//!   work for [`IDLE_LIMIT`] leaves too, so a follower never holds up the
//!   thread it runs on for long (on a pool busy with other simulations it may
//!   start late or never).
//! - **Panics are carried to the leader.** A panic in a chunk is caught,
//!   the pass is completed, and the panic resumes on the leader.

use crossbeam_utils::Backoff;
use std::any::Any;
use std::marker::PhantomData;
use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::sync::Mutex;
use std::sync::atomic::{AtomicPtr, AtomicU64, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// How long a follower waits for work before it leaves the team.
const IDLE_LIMIT: Duration = Duration::from_millis(1);

/// The work of a pass: the function of a chunk index.
type Job<'a> = &'a (dyn Fn(usize) + Sync + 'a);

/// Bits of the claim word: pass number (16), end of the chunks left to
/// claim (24), start of them (24).
const INDEX_BITS: u32 = 24;
const INDEX_MASK: u64 = (1 << INDEX_BITS) - 1;
/// The pass number that means the step is over.
const END: u64 = 0xffff;

/// Most chunks a pass can have.
const MAX_CHUNKS: usize = INDEX_MASK as usize;

fn word(pass: u64, front: usize, back: usize) -> u64 {
    (pass << (2 * INDEX_BITS)) | ((back as u64) << INDEX_BITS) | front as u64
}

/// Pass number, start and end of the chunks left to claim.
fn fields(w: u64) -> (u64, usize, usize) {
    (
        w >> (2 * INDEX_BITS),
        (w & INDEX_MASK) as usize,
        ((w >> INDEX_BITS) & INDEX_MASK) as usize,
    )
}

/// The team of one step. See the module documentation.
pub(super) struct Team {
    /// The pass in progress and its chunks left to claim (see [`word`]).
    claim: AtomicU64,
    /// Chunks of the pass in progress that are complete.
    done: AtomicUsize,
    /// The [`Job`] of the pass in progress (a pointer to the leader's
    /// reference to it).
    job: AtomicPtr<()>,
    /// The first panic of a chunk in the pass in progress.
    panic: Mutex<Option<Box<dyn Any + Send>>>,
    /// The leader's index in the pool.
    leader: Option<usize>,
    /// Number of the last pass started.
    passes: AtomicU64,
}

impl Team {
    /// Runs `lead` on a worker of the pool, as the leader of a team with a
    /// follower for every other worker, and returns its result once it has
    /// returned and the followers have left. The followers are pushed with
    /// `rayon::join`, on the stack: nothing is allocated.
    pub fn lead<R: Send>(lead: impl FnOnce(&Team) -> R + Send) -> R {
        rayon::scope(|_| {
            let team = Team::new();
            team.with_followers(rayon::current_num_threads().saturating_sub(1), lead)
        })
    }

    /// `lead(self)` alongside `n` followers; the step ends when `lead`
    /// returns (or panics), before the joins wait for the followers.
    fn with_followers<R: Send>(&self, n: usize, lead: impl FnOnce(&Team) -> R + Send) -> R {
        if n == 0 {
            let _finish = Finish(self);
            return lead(self);
        }
        rayon::join(|| self.with_followers(n - 1, lead), || self.follow()).0
    }

    /// A team led by the calling thread.
    fn new() -> Self {
        Team {
            claim: AtomicU64::new(word(0, 0, 0)),
            done: AtomicUsize::new(0),
            job: AtomicPtr::new(std::ptr::null_mut()),
            panic: Mutex::new(None),
            leader: rayon::current_thread_index(),
            passes: AtomicU64::new(0),
        }
    }

    /// Claims a chunk of the pass described by `w`, if any is left: the
    /// first one left (the leader) or the last one (a follower). `Some` only
    /// if the claim word was still `w`. Leader and followers thus keep to
    /// the same ends of the arrays from pass to pass, and each finds the
    /// rows it wrote in an earlier pass in its own cache.
    #[inline]
    fn try_claim(&self, w: u64, from_front: bool) -> Option<usize> {
        let (_, front, back) = fields(w);
        if front >= back {
            return None;
        }
        let (new, c) = if from_front {
            (w + 1, front)
        } else {
            (w - (1 << INDEX_BITS), back - 1)
        };
        self.claim
            .compare_exchange(w, new, Ordering::AcqRel, Ordering::Relaxed)
            .ok()
            .map(|_| c)
    }

    /// Runs chunk `c` of `job`, keeping a panic for the leader, and counts
    /// it done.
    fn run_chunk(&self, job: Job, c: usize) {
        if let Err(p) = catch_unwind(AssertUnwindSafe(|| job(c))) {
            let mut slot = self.panic.lock().unwrap_or_else(|e| e.into_inner());
            slot.get_or_insert(p);
        }
        self.done.fetch_add(1, Ordering::Release);
    }

    /// Runs `job(c)` for every chunk `c` in `0..chunks`, shared with the
    /// followers present, and returns when all are complete. Called by the
    /// leader only, one pass at a time.
    pub fn run(&self, chunks: usize, job: Job) {
        assert!(chunks <= MAX_CHUNKS, "{chunks} chunks in a pass");
        let pass = self.passes.fetch_add(1, Ordering::Relaxed) % (END - 1) + 1;
        // The followers read the job through this pointer only after a
        // successful claim, that is while the pass is in progress and this
        // frame (which waits for every claimed chunk) is alive.
        let job_ref: &Job = &job;
        self.done.store(0, Ordering::Relaxed);
        self.job.store(
            std::ptr::from_ref(job_ref).cast_mut().cast(),
            Ordering::Relaxed,
        );
        self.claim.store(word(pass, 0, chunks), Ordering::Release);
        loop {
            let w = self.claim.load(Ordering::Acquire);
            let (_, front, back) = fields(w);
            if front >= back {
                break;
            }
            if let Some(c) = self.try_claim(w, true) {
                self.run_chunk(job, c);
            }
        }
        // Spins, then yields the processor (a follower's thread may have
        // been preempted in its chunk).
        let backoff = Backoff::new();
        while self.done.load(Ordering::Acquire) < chunks {
            backoff.snooze();
        }
        let panic = self.panic.lock().unwrap_or_else(|e| e.into_inner()).take();
        if let Some(p) = panic {
            resume_unwind(p);
        }
    }

    /// Ends the step: the followers leave.
    fn finish(&self) {
        self.claim.store(word(END, 0, 0), Ordering::Release);
    }

    /// A follower: claims chunks of the passes in progress until the step
    /// ends or it has waited [`IDLE_LIMIT`] for work.
    fn follow(&self) {
        if rayon::current_thread_index() == self.leader {
            return;
        }
        let mut idle = Instant::now();
        let mut backoff = Backoff::new();
        loop {
            let w = self.claim.load(Ordering::Acquire);
            let (pass, front, back) = fields(w);
            if pass == END {
                return;
            }
            if front < back {
                let job = self.job.load(Ordering::Relaxed);
                if let Some(c) = self.try_claim(w, false) {
                    // SAFETY: the claim succeeded, so the pass of `w` is in
                    // progress: `job` was stored before the claim word of
                    // this pass (release/acquire on `claim`), is not
                    // replaced before every chunk of the pass is done
                    // (this one included), and points at the leader's
                    // reference to the job, alive until then.
                    let job: Job = unsafe { *job.cast::<Job>() };
                    self.run_chunk(job, c);
                    idle = Instant::now();
                    backoff = Backoff::new();
                }
                continue;
            }
            backoff.snooze();
            if backoff.is_completed() && idle.elapsed() > IDLE_LIMIT {
                return;
            }
        }
    }
}

/// Ends the step of a [`Team`] when dropped, also on a panic.
struct Finish<'a>(&'a Team);

impl Drop for Finish<'_> {
    fn drop(&mut self) {
        self.0.finish();
    }
}

/// A mutable slice cut into chunks of `size` that the chunks of a pass take
/// one each, from any thread of the team.
pub(super) struct Chunks<'a, T> {
    ptr: *mut T,
    len: usize,
    size: usize,
    _slice: PhantomData<&'a mut [T]>,
}

// SAFETY: a `Chunks` hands out disjoint parts of a slice it borrows
// mutably, each to one thread at a time (the contract of `Chunks::take`).
unsafe impl<T: Send> Sync for Chunks<'_, T> {}
unsafe impl<T: Send> Send for Chunks<'_, T> {}

impl<'a, T> Chunks<'a, T> {
    /// Cuts `slice` into chunks of `size` (the last may be shorter).
    pub fn new(slice: &'a mut [T], size: usize) -> Self {
        assert!(size > 0);
        Chunks {
            ptr: slice.as_mut_ptr(),
            len: slice.len(),
            size,
            _slice: PhantomData,
        }
    }
}

/// Arrays cut into chunks that a [`Team`] pass takes one index at a time:
/// a [`Chunks`], or a tuple of them (nested tuples too), all with the same
/// number of chunks.
pub(super) trait Parts: Sync {
    /// Chunk `c` of each array.
    type Part;
    /// Number of chunks.
    fn count(&self) -> usize;
    /// Chunk `c` of each array.
    ///
    /// # Safety
    /// No other reference to chunk `c` may be alive: each index is taken at
    /// most once ([`Team::run_parts`] gives each index to one call).
    unsafe fn part(&self, c: usize) -> Self::Part;
}

impl<'a, T: Send> Parts for Chunks<'a, T> {
    type Part = &'a mut [T];

    fn count(&self) -> usize {
        self.len.div_ceil(self.size)
    }

    unsafe fn part(&self, c: usize) -> &'a mut [T] {
        let start = (c * self.size).min(self.len);
        let end = (start + self.size).min(self.len);
        // SAFETY: `start..end` lies in the borrowed slice, and by the
        // contract no other reference to it is alive.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(start), end - start) }
    }
}

macro_rules! tuple_parts {
    ($first:ident $(, $rest:ident)*) => {
        impl<$first: Parts $(, $rest: Parts)*> Parts for ($first, $($rest,)*) {
            type Part = ($first::Part, $($rest::Part,)*);

            fn count(&self) -> usize {
                #[allow(non_snake_case)]
                let ($first, $($rest,)*) = self;
                let n = $first.count();
                $(assert_eq!($rest.count(), n, "arrays with different chunk counts");)*
                n
            }

            unsafe fn part(&self, c: usize) -> Self::Part {
                #[allow(non_snake_case)]
                let ($first, $($rest,)*) = self;
                // SAFETY: the caller's contract, for each member.
                unsafe { ($first.part(c), $($rest.part(c),)*) }
            }
        }
    };
}

tuple_parts!(A);
tuple_parts!(A, B);
tuple_parts!(A, B, C);
tuple_parts!(A, B, C, D);
tuple_parts!(A, B, C, D, E);
tuple_parts!(A, B, C, D, E, F);
tuple_parts!(A, B, C, D, E, F, G);

/// Declares a named set of arrays cut into chunks, and the named chunk of
/// each that a pass gets: `$chunks` holds a [`Chunks`] per field, `$part` a
/// `&mut [T]` per field, and `$chunks` is [`Parts`] with `Part = $part`
/// (the named form of a tuple of [`Chunks`]). The unsafe code it writes is
/// the tuples' own: each field's chunk under the caller's contract.
macro_rules! named_parts {
    (
        $(#[$chunks_meta:meta])* $chunks:ident,
        $(#[$part_meta:meta])* $part:ident {
            $( $(#[$field_meta:meta])* $field:ident : $ty:ty ),+ $(,)?
        }
    ) => {
        $(#[$chunks_meta])*
        pub(super) struct $chunks<'a> {
            $( $(#[$field_meta])* pub $field: $crate::solver::axisymmetric::team::Chunks<'a, $ty>, )+
        }

        $(#[$part_meta])*
        pub(super) struct $part<'a> {
            $( $(#[$field_meta])* pub $field: &'a mut [$ty], )+
        }

        #[allow(unsafe_code)]
        impl<'a> $crate::solver::axisymmetric::team::Parts for $chunks<'a> {
            type Part = $part<'a>;

            fn count(&self) -> usize {
                let counts = [$( $crate::solver::axisymmetric::team::Parts::count(&self.$field), )+];
                assert!(
                    counts.iter().all(|&c| c == counts[0]),
                    "arrays with different chunk counts"
                );
                counts[0]
            }

            unsafe fn part(&self, c: usize) -> $part<'a> {
                // SAFETY: the caller's contract, for each member.
                unsafe {
                    $part { $( $field: $crate::solver::axisymmetric::team::Parts::part(&self.$field, c), )+ }
                }
            }
        }
    };
}
pub(super) use named_parts;

impl Team {
    /// Runs `job(c, chunk c of parts)` for every chunk of `parts` (see
    /// [`Team::run`]).
    pub fn run_parts<P: Parts>(&self, parts: &P, job: impl Fn(usize, P::Part) + Sync) {
        self.run(parts.count(), &|c| {
            // SAFETY: `run` gives each index in `0..count` to one call.
            job(c, unsafe { parts.part(c) })
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_chunk_runs_once_with_or_without_followers() {
        for threads in [1, 2, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut out = vec![0u64; 1000];
                Team::lead(|team| {
                    for pass in 1..=20u64 {
                        team.run_parts(&Chunks::new(&mut out, 7), |c, chunk| {
                            for (k, x) in chunk.iter_mut().enumerate() {
                                *x += pass * (c * 7 + k) as u64;
                            }
                        });
                    }
                });
                for (i, x) in out.iter().enumerate() {
                    assert_eq!(*x, 210 * i as u64, "element {i}, {threads} threads");
                }
            });
        }
    }

    #[test]
    fn a_panic_in_a_chunk_reaches_the_leader_after_the_pass() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        pool.install(|| {
            let count = AtomicUsize::new(0);
            let r = catch_unwind(AssertUnwindSafe(|| {
                Team::lead(|team| {
                    team.run(50, &|c| {
                        count.fetch_add(1, Ordering::Relaxed);
                        assert!(c != 17, "chunk 17 fails");
                    });
                })
            }));
            assert!(r.is_err());
            assert_eq!(count.load(Ordering::Relaxed), 50);
        });
    }
}
