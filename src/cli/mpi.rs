//! The program's ranks over MPI (cargo feature `mpi`: rsmpi over MPICH):
//! the library's [`Ranks`] on `MPI_COMM_WORLD`. Only the program knows
//! MPI; the library, the C ABI and the FMUs are built without it.

use meshless_impact::ranks::Ranks;
use mpi::collective::SystemOperation;
use mpi::datatype::Equivalence;
use mpi::datatype::PartitionMut;
use mpi::environment::Universe;
use mpi::raw::AsRaw;
use mpi::topology::SimpleCommunicator;
use mpi::traits::{Communicator, CommunicatorCollectives, Root};
use std::panic::Location;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

/// The bytes one rank sends in one round of [`Ranks::all_gather`]: MPI
/// counts and displacements are 32-bit, so a gather past 2^31 bytes (the
/// shapes of 10^6 nodes are about a gigabyte) goes in rounds through a
/// buffer; a smaller one goes in one call, straight into its place.
const ROUND_BYTES: usize = 1 << 28;

/// MPI_COMM_WORLD of an initialised MPI, with its universe (finalised when
/// dropped, at the end of `main`).
pub(crate) struct MpiRanks {
    world: SimpleCommunicator,
    rank: usize,
    size: usize,
    /// Collective calls made and bytes this rank received in gathers and
    /// broadcasts: the communication's measure (`MI_MPI_STATS=1` prints
    /// them at the end).
    calls: AtomicU64,
    received: AtomicU64,
    /// Nanoseconds spent in the collectives, and (with `MI_MPI_STATS=2`,
    /// which puts a barrier before each one) of those, waiting at the
    /// barrier for the slowest rank: the imbalance, apart from the transfer.
    spent: AtomicU64,
    waited: AtomicU64,
    /// `MI_MPI_STATS=2`: a barrier before each collective, and the books
    /// by the line of the program that called it.
    split_wait: bool,
    /// The line named for the next collective ([`Ranks::at`]; with
    /// `MI_MPI_STATS=2` only).
    line: Mutex<Option<&'static Location<'static>>>,
    /// The collectives by line (`None`: a line not named), in the order
    /// first met (with `MI_MPI_STATS=2` only).
    books: Mutex<Vec<(Option<&'static Location<'static>>, Book)>>,
    /// The library is MPICH, whose `MPI_IN_PLACE` is `(void *) -1`
    /// (`mpi.h`): rsmpi has no in-place gather and its bindings no
    /// `MPI_IN_PLACE`, so the gathers in place use that value, and only
    /// where the library says it is MPICH.
    mpich: bool,
    _universe: Universe,
}

/// The collectives of one line of the program (`MI_MPI_STATS=2`).
#[derive(Debug, Default, Clone, Copy)]
struct Book {
    calls: u64,
    received: u64,
    /// Seconds waiting at the barrier before them, and in them after it.
    waited: f64,
    transfer: f64,
}

/// `text` and a newline on stderr in one write: the ranks' lines reach
/// `mpiexec`'s stderr whole (a line of under `PIPE_BUF` bytes written at
/// once is not split), where `eprintln!` writes a line in pieces that
/// another rank's can come between.
fn line_out(text: &str) {
    use std::io::Write as _;
    let _ = std::io::stderr().write_all(format!("{text}\n").as_bytes());
}

impl Drop for MpiRanks {
    fn drop(&mut self) {
        if self.split_wait {
            let mut books = self.books.lock().map(|b| b.clone()).unwrap_or_default();
            books.sort_by(|a, b| {
                (b.1.waited + b.1.transfer).total_cmp(&(a.1.waited + a.1.transfer))
            });
            for (line, b) in books {
                let line = line.map_or("another line".to_string(), |l| {
                    format!("{}:{}", l.file(), l.line())
                });
                line_out(&format!(
                    "mpi: rank {}: {line}: {} calls, {} bytes received, {:.3} s waiting, {:.3} s in transfer",
                    self.rank, b.calls, b.received, b.waited, b.transfer
                ));
            }
        }
        if std::env::var_os("MI_MPI_STATS").is_some() {
            line_out(&format!(
                "mpi: rank {} of {}: {} collective calls, {} bytes received, {:.3} s in them{}",
                self.rank,
                self.size,
                self.calls.load(Ordering::Relaxed),
                self.received.load(Ordering::Relaxed),
                self.spent.load(Ordering::Relaxed) as f64 * 1e-9,
                if self.split_wait {
                    format!(
                        " ({:.3} s waiting at a barrier before them)",
                        self.waited.load(Ordering::Relaxed) as f64 * 1e-9
                    )
                } else {
                    String::new()
                }
            ));
        }
    }
}

impl std::fmt::Debug for MpiRanks {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "MpiRanks {{ rank: {}, size: {} }}", self.rank, self.size)
    }
}

// SAFETY: MPI is initialised with `Threading::Serialized` or more (checked
// in `init`), and the solver calls the collectives from one thread at a
// time (the step's sequential parts, never inside a parallel pass), which
// is what that level allows.
unsafe impl Send for MpiRanks {}
// SAFETY: as above.
unsafe impl Sync for MpiRanks {}

/// MPI initialised for calls from one thread at a time (the run loop runs
/// on a worker of the thread pool); `None` when it was already initialised
/// or refuses that level.
pub(crate) fn init() -> Result<MpiRanks, String> {
    let (universe, level) = mpi::initialize_with_threading(mpi::Threading::Serialized)
        .ok_or("MPI was initialised twice")?;
    if level < mpi::Threading::Serialized {
        return Err(format!(
            "MPI gives threading level {level:?}; the solver needs Serialized (one thread at a time)"
        ));
    }
    let world = universe.world();
    let (rank, size) = (world.rank() as usize, world.size() as usize);
    let mpich = mpi::environment::library_version().is_ok_and(|v| v.starts_with("MPICH"))
        && std::env::var_os("MI_NO_IN_PLACE").is_none();
    Ok(MpiRanks {
        world,
        rank,
        size,
        calls: AtomicU64::new(0),
        received: AtomicU64::new(0),
        spent: AtomicU64::new(0),
        waited: AtomicU64::new(0),
        split_wait: std::env::var("MI_MPI_STATS").is_ok_and(|v| v == "2"),
        line: Mutex::new(None),
        books: Mutex::new(Vec::new()),
        mpich,
        _universe: universe,
    })
}

impl MpiRanks {
    /// `value` reduced by `op` over every rank.
    fn reduce(&self, value: i64, op: SystemOperation) -> i64 {
        let _t = self.timed();
        let mut out = 0i64;
        self.world.all_reduce_into(&value, &mut out, op);
        out
    }

    /// Starts timing a collective (the time is added when the guard
    /// drops); with `MI_MPI_STATS=2`, first waits at a barrier and counts
    /// that wait apart.
    fn timed(&self) -> Timed<'_> {
        let start = std::time::Instant::now();
        let mut waited = 0;
        let mut line = None;
        if self.split_wait {
            line = self.line.lock().ok().and_then(|mut l| l.take());
            self.world.barrier();
            waited = start.elapsed().as_nanos() as u64;
            self.waited.fetch_add(waited, Ordering::Relaxed);
        }
        Timed {
            ranks: self,
            start,
            waited,
            line,
            calls: 1,
            received: 0,
        }
    }
}

/// The guard of [`MpiRanks::timed`]: one collective call.
struct Timed<'a> {
    ranks: &'a MpiRanks,
    start: std::time::Instant,
    /// Nanoseconds at the barrier before it (`MI_MPI_STATS=2`).
    waited: u64,
    /// The line that called it (`MI_MPI_STATS=2`).
    line: Option<&'static Location<'static>>,
    /// MPI calls it makes, and the bytes this rank receives in them.
    calls: u64,
    received: u64,
}

impl Timed<'_> {
    /// Books `bytes` received by this rank.
    fn receive(&mut self, bytes: u64) {
        self.received += bytes;
        self.ranks.received.fetch_add(bytes, Ordering::Relaxed);
    }
}

impl Drop for Timed<'_> {
    fn drop(&mut self) {
        let spent = self.start.elapsed().as_nanos() as u64;
        self.ranks.spent.fetch_add(spent, Ordering::Relaxed);
        self.ranks.calls.fetch_add(self.calls, Ordering::Relaxed);
        if !self.ranks.split_wait {
            return;
        }
        let Ok(mut books) = self.ranks.books.lock() else {
            return;
        };
        let same = |l: &Option<&Location>| match (l, self.line) {
            (Some(a), Some(b)) => {
                (a.file(), a.line(), a.column()) == (b.file(), b.line(), b.column())
            }
            (None, None) => true,
            _ => false,
        };
        let at = match books.iter().position(|(l, _)| same(l)) {
            Some(at) => at,
            None => {
                books.push((self.line, Book::default()));
                books.len() - 1
            }
        };
        let b = &mut books[at].1;
        b.calls += self.calls;
        b.received += self.received;
        b.waited += self.waited as f64 * 1e-9;
        b.transfer += spent.saturating_sub(self.waited) as f64 * 1e-9;
    }
}

impl Ranks for MpiRanks {
    fn at(&self, line: &'static Location<'static>) {
        if self.split_wait
            && let Ok(mut l) = self.line.lock()
        {
            *l = Some(line);
        }
    }
    fn all_gather_in_place(&self, counts: &[usize], out: &mut [u8]) {
        if !self.mpich || out.len() > i32::MAX as usize {
            return meshless_impact::ranks::gather_through_copy(self, counts, out);
        }
        let mut t = self.timed();
        t.receive((out.len() - counts[self.rank]) as u64);
        let counts32: Vec<i32> = counts.iter().map(|&c| c as i32).collect();
        let displs: Vec<i32> = counts
            .iter()
            .scan(0i32, |s, &c| {
                let at = *s;
                *s += c as i32;
                Some(at)
            })
            .collect();
        let byte = u8::equivalent_datatype().as_raw();
        // MPICH's MPI_IN_PLACE (`mpi.h`: `(void *) -1`), checked in `init`.
        let in_place = usize::MAX as *const std::ffi::c_void;
        // SAFETY: `out` holds the sum of `counts` bytes (the caller's
        // contract), `counts32` and `displs` have one entry per rank, the
        // communicator is this world's, and with MPI_IN_PLACE the send
        // arguments are ignored. MPI is called from one thread at a time
        // (see the `Send` impl).
        let rc = unsafe {
            mpi::ffi::MPI_Allgatherv(
                in_place,
                0,
                byte,
                out.as_mut_ptr().cast(),
                counts32.as_ptr(),
                displs.as_ptr(),
                byte,
                self.world.as_raw(),
            )
        };
        // MPI's default handler aborts the job on an error: a return is a
        // success.
        debug_assert_eq!(rc, 0);
    }
    fn rank(&self) -> usize {
        self.rank
    }
    fn size(&self) -> usize {
        self.size
    }
    fn all_gather(&self, local: &[u8], counts: &[usize], out: &mut [u8]) {
        debug_assert_eq!(local.len(), counts[self.rank]);
        let mut t = self.timed();
        t.receive((out.len() - local.len()) as u64);
        let starts: Vec<usize> = counts
            .iter()
            .scan(0, |s, &c| {
                let at = *s;
                *s += c;
                Some(at)
            })
            .collect();
        if out.len() <= i32::MAX as usize {
            // One call, straight into `out`.
            let counts32: Vec<i32> = counts.iter().map(|&c| c as i32).collect();
            let displs: Vec<i32> = starts.iter().map(|&s| s as i32).collect();
            let mut part = PartitionMut::new(out, &counts32[..], &displs[..]);
            self.world.all_gather_varcount_into(local, &mut part);
            return;
        }
        let rounds = counts
            .iter()
            .map(|c| c.div_ceil(ROUND_BYTES))
            .max()
            .unwrap_or(0);
        let mut buf = Vec::new();
        for k in 0..rounds {
            let piece = |c: usize| (k * ROUND_BYTES).min(c)..((k + 1) * ROUND_BYTES).min(c);
            let sizes: Vec<usize> = counts.iter().map(|&c| piece(c).len()).collect();
            let displs: Vec<i32> = sizes
                .iter()
                .scan(0usize, |s, &c| {
                    let at = *s;
                    *s += c;
                    Some(at as i32)
                })
                .collect();
            let total: usize = sizes.iter().sum();
            buf.clear();
            buf.resize(total, 0u8);
            let counts32: Vec<i32> = sizes.iter().map(|&c| c as i32).collect();
            {
                let mut part = PartitionMut::new(&mut buf[..], &counts32[..], &displs[..]);
                self.world
                    .all_gather_varcount_into(&local[piece(local.len())], &mut part);
            }
            for (r, &c) in counts.iter().enumerate() {
                let p = piece(c);
                let from = displs[r] as usize;
                out[starts[r] + p.start..starts[r] + p.end]
                    .copy_from_slice(&buf[from..from + p.len()]);
            }
        }
    }
    fn all_min(&self, value: i64) -> i64 {
        self.reduce(value, SystemOperation::min())
    }
    fn all_max(&self, value: i64) -> i64 {
        self.reduce(value, SystemOperation::max())
    }
    fn broadcast(&self, root: usize, bytes: &mut Vec<u8>) {
        let mut t = self.timed();
        let root = self.world.process_at_rank(root as i32);
        let mut len = bytes.len() as u64;
        root.broadcast_into(&mut len);
        bytes.resize(len as usize, 0);
        root.broadcast_into(&mut bytes[..]);
        // Two calls: the length, then the bytes.
        t.calls = 2;
        t.receive(bytes.len() as u64);
    }
}
