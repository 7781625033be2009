//! The 3-D MLPG step allocates nothing between rebuilds of its geometry:
//! counted with a counting global allocator (this test binary's own).

use meshless_impact::scene::taylor3d::Taylor3dParams;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU64, Ordering};

/// The system allocator, counting allocations and their bytes.
struct Counting;

static CALLS: AtomicU64 = AtomicU64::new(0);
static BYTES: AtomicU64 = AtomicU64::new(0);

// SAFETY: forwards to the system allocator; only counts.
#[allow(unsafe_code)]
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        CALLS.fetch_add(1, Ordering::Relaxed);
        BYTES.fetch_add(layout.size() as u64, Ordering::Relaxed);
        // SAFETY: the caller's contract is passed on.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract is passed on.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        CALLS.fetch_add(1, Ordering::Relaxed);
        BYTES.fetch_add(new_size as u64, Ordering::Relaxed);
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
