//! Criterion benches of the hot parts of the MSPH solver: the kernel, the
//! MSPH moment matrix of one neighbourhood, the neighbour search on the
//! particles of Taylor test 7, and one whole step of test 7 at the paper's
//! resolution on one and on two threads.
//!
//! `cargo bench --bench solver`; figures in BENCHMARKS.md.

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use meshless_impact::internals::{Neighbourhood, Row2, cell_list, kernel2, naive, padded_rows};
use meshless_impact::{Scene, Simulation};
use std::hint::black_box;

/// Scaled offsets of the neighbours of an interior particle of a square
/// lattice with h = 1.5 spacings (the default), slightly sheared so the
/// arrangement is not perfectly symmetric.
fn lattice_neighbourhood() -> Vec<[f64; 2]> {
    let h = 1.5;
    let mut out = Vec::new();
    for i in -4i32..=4 {
        for k in -4i32..=4 {
            let (r, z) = (i as f64 + 0.01 * k as f64, k as f64);
            if r * r + z * z <= (2.0 * h) * (2.0 * h) {
                out.push([r / h, z / h]);
            }
        }
    }
    out
}

/// The (R, Z) positions of the particles of test 7 at 20 across the radius.
fn test7_points() -> Vec<[f64; 2]> {
    let sim = Simulation::builtin("taylor").unwrap();
    sim.snapshot()
        .positions
        .iter()
        .map(|p| [p[0], p[1]])
        .collect()
}

fn kernel(c: &mut Criterion) {
    let s = lattice_neighbourhood();
    c.bench_function(
        &format!("kernel2 x neighbourhood ({} pairs)", s.len()),
        |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for x in &s {
                    let k = kernel2(black_box(x[0]), x[1], 1.0);
                    acc += k.w + k.w_r + k.w_z;
                }
                acc
            })
        },
    );
    let mut hood = Neighbourhood::with_capacity(s.len());
    let mut wr = vec![0.0; s.len().next_multiple_of(meshless_impact::internals::W)];
    let mut wz = wr.clone();
    let mut wk = wr.clone();
    let name = format!("msph moments + solve + weights ({} pairs)", s.len());
    c.bench_function(&name, |b| {
        b.iter(|| {
            hood.clear();
            for x in &s {
                hood.push(black_box(x[0]), x[1], 1.0);
            }
            let m = hood
                .moments()
                .solve(0, [0.0, 0.0], 1.0, [Row2::R, Row2::Z])
                .unwrap();
            hood.weights(&m, [&mut wr, &mut wz], &mut wk);
            wr[3]
        })
    });
}

fn neighbours(c: &mut Criterion) {
    let p = test7_points();
    let spacing = 0.5 * 0.007595 / 19.0;
    let reach = 2.3 * 1.5 * spacing;
    c.bench_function("cell list, test 7 (3820 points)", |b| {
        b.iter(|| cell_list(black_box(&p), reach))
    });
    // What the solver runs at a rebuild: the same lists straight into padded
    // rows, reusing the buffers and the stride of the previous rebuild.
    let (mut rows, mut len) = (Vec::new(), Vec::new());
    let stride = padded_rows(&p, p.len(), reach, 8, 0, &mut rows, &mut len);
    c.bench_function("padded rows, test 7 (3820 points)", |b| {
        b.iter(|| {
            padded_rows(
                black_box(&p),
                p.len(),
                reach,
                8,
                stride,
                &mut rows,
                &mut len,
            )
        })
    });
    let mut g = c.benchmark_group("oracle");
    g.sample_size(10);
    g.bench_function("naive O(N^2), test 7 (3820 points)", |b| {
        b.iter(|| naive(black_box(&p), reach))
    });
    g.finish();
}

fn step(c: &mut Criterion) {
    let mut scene = Scene::builtin("taylor").unwrap();
    scene.set("end_time", 1.0).unwrap();
    let mut sim = Simulation::new(scene).unwrap();
    sim.advance_to(5e-6).unwrap();
    let mut g = c.benchmark_group("taylor test 7 step (3820 particles)");
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        g.bench_function(format!("{threads} thread(s)"), |b| {
            b.iter_batched(
                || sim.clone(),
                |mut s| pool.install(|| s.step().unwrap()),
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, kernel, neighbours, step);
criterion_main!(benches);
