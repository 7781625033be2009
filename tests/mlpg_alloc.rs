//! The 3-D MLPG step allocates nothing between rebuilds of its geometry:
//! counted with a counting global allocator (this test binary's own).

use meshless_impact::Taylor3dParams;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU64, Ordering};

/// The system allocator, counting allocations and their bytes.
struct Counting;

static CALLS: AtomicU64 = AtomicU64::new(0);
static BYTES: AtomicU64 = AtomicU64::new(0);
/// Bytes live now and the most live at once since the last reset.
static LIVE: AtomicU64 = AtomicU64::new(0);
static PEAK: AtomicU64 = AtomicU64::new(0);

fn grow(by: u64) {
    let live = LIVE.fetch_add(by, Ordering::Relaxed) + by;
    PEAK.fetch_max(live, Ordering::Relaxed);
}

// SAFETY: forwards to the system allocator; only counts.
#[allow(unsafe_code)]
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        CALLS.fetch_add(1, Ordering::Relaxed);
        BYTES.fetch_add(layout.size() as u64, Ordering::Relaxed);
        grow(layout.size() as u64);
        // SAFETY: the caller's contract is passed on.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size() as u64, Ordering::Relaxed);
        // SAFETY: the caller's contract is passed on.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        CALLS.fetch_add(1, Ordering::Relaxed);
        BYTES.fetch_add(new_size as u64, Ordering::Relaxed);
        LIVE.fetch_sub(layout.size() as u64, Ordering::Relaxed);
        grow(new_size as u64);
        // SAFETY: the caller's contract is passed on.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn counts() -> (u64, u64) {
    (CALLS.load(Ordering::Relaxed), BYTES.load(Ordering::Relaxed))
}

/// `taylor3d` at 4 nodes across, its first 150 steps: every step that
/// rebuilds nothing allocates nothing (on one thread and on two); the
/// rebuilds are counted and printed.
#[test]
fn steps_between_rebuilds_allocate_nothing() {
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let p = Taylor3dParams {
                particles_radial: 4.0,
                ..Taylor3dParams::default()
            };
            let mut s = p.build().unwrap();
            s.step().unwrap();
            let (mut quiet, mut rebuilding) = (0, 0);
            let (mut calls, mut bytes) = (0, 0);
            for _ in 0..150 {
                let builds = s.rebuilds();
                let before = counts();
                s.step().unwrap();
                let after = counts();
                if s.rebuilds() == builds {
                    quiet += 1;
                    assert_eq!(
                        after.0 - before.0,
                        0,
                        "step {} allocated {} bytes",
                        s.steps(),
                        after.1 - before.1
                    );
                } else {
                    rebuilding += 1;
                    calls += after.0 - before.0;
                    bytes += after.1 - before.1;
                }
            }
            println!(
                "{threads} threads, {} nodes: {quiet} steps allocated nothing; {rebuilding} \
                 rebuilding steps allocated {calls} times, {bytes} bytes",
                s.particles()
            );
            assert!(quiet > 100 && rebuilding > 0);
        });
    }
}

/// Measurement: the heap of `taylor3d` (`PARTICLES_RADIAL`, default 10) by
/// part after its first step, and the most live at once over its first
/// `STEPS` (default 200) steps, which rebuild the geometry (BENCHMARKS.md,
/// "3-D MLPG speed"). Run alone (`--test-threads=1`): the counters are the
/// process's.
#[test]
#[ignore = "measurement: the heap of taylor3d by part"]
fn heap_by_part() {
    let across: f64 = std::env::var("PARTICLES_RADIAL")
        .map(|s| s.parse().unwrap())
        .unwrap_or(10.0);
    let steps: usize = std::env::var("STEPS")
        .map(|s| s.parse().unwrap())
        .unwrap_or(200);
    let base = LIVE.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let p = Taylor3dParams {
        particles_radial: across,
        ..Taylor3dParams::default()
    };
    let mut s = p.build().unwrap();
    let built = PEAK.load(Ordering::Relaxed) - base;
    s.step().unwrap();
    let n = s.particles() as f64;
    let kb = |b: u64| b as f64 / n / 1e3;
    println!(
        "most live at once in the construction: {:.2} kB a node",
        kb(built)
    );
    let live = LIVE.load(Ordering::Relaxed) - base;
    println!(
        "{} nodes; held after the first step: {:.2} kB a node",
        s.particles(),
        kb(live)
    );
    let mut parts = 0;
    for (part, bytes) in s.memory() {
        parts += bytes;
        println!("  {part:<22} {:>6.2} kB a node", kb(bytes as u64));
    }
    println!(
        "  {:<22} {:>6.2} kB a node",
        "other",
        kb(live - parts as u64)
    );
    // The largest rise of the heap within one step, and that step.
    let (mut rise, mut at) = (0u64, 0u64);
    for _ in 0..steps {
        let live = LIVE.load(Ordering::Relaxed);
        let peak = PEAK.swap(live, Ordering::Relaxed);
        s.step().unwrap();
        if PEAK.load(Ordering::Relaxed) - live > rise {
            (rise, at) = (PEAK.load(Ordering::Relaxed) - live, s.steps());
        }
        PEAK.fetch_max(peak, Ordering::Relaxed);
    }
    println!(
        "the largest rise within one step: {:.2} kB a node (step {at})",
        kb(rise)
    );
    println!(
        "most live at once over {} steps ({} builds): {:.2} kB a node, {:.1} MB",
        s.steps(),
        s.rebuilds(),
        kb(PEAK.load(Ordering::Relaxed) - base),
        (PEAK.load(Ordering::Relaxed) - base) as f64 / 1e6
    );
}
