//! What follows from the positions at the last build ([`Geometry`]): the
//! supports (with the quarter model's mirror images), the shapes at the
//! nodes, the traction operator, and the pass over the named pairs that
//! decides when they are rebuilt.

use super::held;
use super::held::HeldRows;
use super::profile::Phase;
use super::spheres;
use super::util::at_time;
use super::util::extended;
use super::util::norm;
use crate::Error;
use crate::approx::buffers::copy_from;
use crate::approx::conform::CONFORM_TOLERANCE;
use crate::approx::conform::{Stop, conform};
use crate::approx::mirror;
use crate::approx::mirror::Mirror;
use crate::approx::mls::NodalShapes;
use crate::approx::mls::SupportParams;
use crate::approx::mls::Supports;
use crate::approx::mls::distance;
use crate::approx::nodal::NodalOperator;
use crate::approx::sphere::BOUNDARY_RULE;
use crate::approx::sphere::DEFAULT_RULE;
use crate::approx::sphere::SphereRule;
use crate::approx::sphere::TestSphere;
use crate::approx::weak::TractionOperator;
use crate::error::Result;
use crate::solver::mlpg3d::Pipeline3d;
use crate::solver::mlpg3d::Setup3d;
use crate::solver::mlpg3d::State3d;
use crate::solver::mlpg3d::scheme::Forces;
use crate::solver::mlpg3d::scheme::SmoothingOrder;
use rayon::iter::IntoParallelIterator;
use rayon::iter::IntoParallelRefIterator;
use rayon::iter::ParallelIterator;
/// What follows from the positions at the last build: supports, nodal
/// shapes, test spheres and the traction operator. Rebuilt, never saved.
#[derive(Debug, Clone, Default)]
pub(super) struct Geometry {
    pub(super) supports: Option<Supports>,
    pub(super) shapes: NodalShapes,
    pub(super) spheres: Vec<TestSphere>,
    pub(super) op: TractionOperator,
    /// The transposed shapes: the nodal form's operator, and the order-2
    /// smoothing's `Hᵀ` (empty otherwise).
    pub(super) nodal: NodalOperator,
    /// The mirror images of the quarter model (none for the whole body),
    /// chosen with the supports.
    pub(super) mirror: Mirror,
    /// The conforming correction's multipliers at this build (empty
    /// without it): the next build starts from them.
    pub(super) multipliers: Vec<[f64; 3]>,
    /// The parts of the shapes' rows among the ranks, of about equal
    /// entries ([`row_parts`]): the rows each rank computes in the passes
    /// over them (the smoothing's defect, the shifts and the carry).
    pub(super) rows: Vec<std::ops::Range<usize>>,
    /// On several ranks with the order-2 smoothing, the rows of each
    /// rank's part of `rows` that another rank's columns of `nodal` read
    /// in the smoothing's transpose ([`pass_lists`]); empty otherwise.
    pub(super) pass_send: Vec<Vec<usize>>,
    /// The shapes' rows this rank holds (every row but on several ranks
    /// with the nodal forces: [`super::held`]).
    pub(super) held: HeldRows,
}

impl Geometry {
    /// Marks in `read` the nodes of the entries of the nodal operator's
    /// columns this rank holds: the rows its forces and its smoothing's
    /// transpose read.
    pub(super) fn mark_column_reads(&self, read: &mut [bool]) {
        for j in self.nodal.held.clone() {
            for q in self.nodal.column(j) {
                read[self.nodal.nodes[q]] = true;
            }
        }
    }
}

/// The rows of each rank's part of the shapes' rows `g.rows` (of `n` real
/// nodes) that another rank reads in the order-2 smoothing's transpose
/// `Hᵀ` (`NodalOperator::defect_transpose_on`): the nodes of the entries
/// of the columns it holds, and those columns' own nodes (which the
/// entries hold too wherever a node lies in its own support: dropping
/// them failed no test, so they are kept as a superset); each ascending.
/// A collective call (one gather of each rank's reads), made at each
/// build.
/// Empty on one rank, or without the order-2 smoothing (`order2`).
fn pass_lists(
    ranks: &dyn crate::ranks::Ranks,
    g: &Geometry,
    n: usize,
    order2: bool,
) -> Vec<Vec<usize>> {
    if ranks.size() == 1 || !order2 {
        return Vec::new();
    }
    let own = g.rows[ranks.rank()].clone();
    let mut read = vec![false; n];
    g.mark_column_reads(&mut read);
    for j in g.nodal.held.clone().filter(|&j| j < n) {
        read[j] = true;
    }
    let mine: Vec<usize> = (0..n).filter(|&i| read[i] && !own.contains(&i)).collect();
    let mut wanted = vec![false; n];
    for i in crate::ranks::all_gather_varying(ranks, &mine) {
        wanted[i] = true;
    }
    g.rows
        .iter()
        .map(|p| p.clone().filter(|&i| wanted[i]).collect())
        .collect()
}

/// The parts of the first `n` rows of `shapes` among `ranks`: one part
/// alone; on several ranks, parts of about equal entries
/// ([`crate::ranks::weighted_parts`]), since a row's pass costs in
/// proportion to its entries (equal shares of the rows left rank 1
/// waiting 0.66 s of `taylor3d` 10 across at the shifts' gather).
pub(super) fn row_parts(
    ranks: &dyn crate::ranks::Ranks,
    shapes: &NodalShapes,
    n: usize,
) -> Vec<std::ops::Range<usize>> {
    if ranks.size() == 1 {
        return std::iter::once(0..n).collect();
    }
    let weight: Vec<usize> = (0..n).map(|i| shapes.row(i).len()).collect();
    crate::ranks::weighted_parts(&weight, ranks.size())
}

/// What [`Mlpg3d::named_pairs`] finds.
#[derive(Debug, Clone, Copy)]
pub(super) struct NamedPairs {
    /// The smallest distance between named nodes (its square while the
    /// pairs are visited).
    pub(super) nearest: f64,
    /// A pair has left the range of the supports.
    pub(super) recompute: bool,
    /// A pair has moved by more than [`RodSetup::rebuild_strain`] of its
    /// length at the last build.
    pub(super) strained: bool,
}

impl NamedPairs {
    const NONE: NamedPairs = NamedPairs {
        nearest: f64::INFINITY,
        recompute: false,
        strained: false,
    };

    pub(super) fn join(a: Self, b: Self) -> Self {
        NamedPairs {
            nearest: a.nearest.min(b.nearest),
            recompute: a.recompute || b.recompute,
            strained: a.strained || b.strained,
        }
    }
}

/// The margin of the squared pre-tests of [`Mlpg3d::named_pairs`]: far
/// above the round-off of the exact tests, so a pair the pre-test passes
/// passes them.
const PRE_TEST_MARGIN: f64 = 1e-9;

impl Pipeline3d {
    /// The mirror images of the last computation of the supports (none
    /// for the whole body).
    pub(super) fn mirror(&self) -> &Mirror {
        &self
            .geometry
            .as_ref()
            .expect("the geometry is built before use")
            .mirror
    }

    pub(super) fn supports(&self) -> &Supports {
        self.geometry
            .as_ref()
            .and_then(|g| g.supports.as_ref())
            .expect("the geometry is built before use")
    }
}

/// The smallest current distance between a node and one it names.
pub(super) fn nearest_distance(state: &State3d, pipe: &Pipeline3d) -> f64 {
    let sup = pipe.supports();
    let mut buf = Vec::new();
    let pos = extended(pipe.mirror(), &state.pos, &mut buf, mirror::vector);
    (0..state.pos.len())
        .into_par_iter()
        .map(|i| {
            sup.named
                .of(i)
                .iter()
                .map(|&j| distance(&pos[i], &pos[j]))
                .fold(f64::INFINITY, f64::min)
        })
        .collect::<Vec<f64>>()
        .into_iter()
        .fold(f64::INFINITY, f64::min)
}

/// Rebuilds the geometry of the pipeline at the state's `built_at`
/// (and the supports at `supports_at` when `supports` is true or none
/// exist); records the build in the state (`rebuilds`, the multipliers
/// the conforming correction started from).
pub(super) fn build_geometry(
    setup: &Setup3d,
    state: &mut State3d,
    pipe: &mut Pipeline3d,
    supports: bool,
) -> Result<()> {
    let time = state.clock.time;
    let stamp = |e: Error| at_time(e, time);
    let mut watch = pipe.profile.stopwatch();
    let mut g = pipe.geometry.take().unwrap_or_default();
    // New supports, rows and columns: new lists of what each rank reads.
    pipe.halo.forget();
    // The old traction operator goes before the new is built; the
    // shapes and the nodal operator are rebuilt in their own buffers.
    // They are most of the heap (BENCHMARKS.md, memory).
    g.op = TractionOperator::default();
    let n = state.pos.len();
    if supports || g.supports.is_none() {
        let (sup, mirror) = supports_with_images(setup, state, &*pipe.ranks).map_err(stamp)?;
        g.supports = Some(sup);
        g.mirror = mirror;
        pipe.profile.supports += 1;
    }
    pipe.profile.lap(Phase::Supports, &mut watch);
    let sup = g.supports.as_ref().expect("computed above");
    let mut buf = Vec::new();
    let pts = extended(&g.mirror, &state.built_at, &mut buf, mirror::vector);
    let ranks = &*pipe.ranks;
    // On several ranks with the nodal forces each rank keeps the rows it
    // reads ([`super::held`]); the other schemes read them all. (The
    // halo's wider check reads the rows of its reads' nodes: all.)
    let apart = ranks.size() > 1 && setup.rod.scheme.forces == Forces::Nodal && !pipe.halo.wider();
    let mut columns = None;
    if apart {
        let shares = g
            .shapes
            .rebuild_share_on(pts, sup, n, ranks)
            .map_err(stamp)?;
        g.rows = row_parts(ranks, &g.shapes, n);
        let weight =
            held::column_weights(ranks, &g.shapes, shares[ranks.rank()].clone(), pts.len());
        let parts = crate::ranks::weighted_parts(&weight, ranks.size());
        let material = pipe.balance.parts(ranks, n).to_vec();
        let listed = pipe.halo.poisons();
        g.held = HeldRows::after_build(
            (ranks, listed),
            &mut g.shapes,
            shares,
            [&g.rows, &parts, &material],
        );
        columns = Some(parts);
    } else {
        g.shapes
            .rebuild_rows_on(pts, sup, n, ranks)
            .map_err(stamp)?;
        g.held = HeldRows::whole();
    }
    pipe.profile.lap(Phase::Shapes, &mut watch);
    if setup.rod.scheme.forces == Forces::Conforming {
        // Node-wise arrays made on the pool: at 10^6 nodes a serial fill
        // is a serial part of every build.
        let volume: Vec<f64> = (0..n)
            .into_par_iter()
            .map(|i| setup.mass[i] / state.built_rho[i])
            .collect();
        let inner: Vec<bool> = setup
            .lattice
            .surfaces
            .par_iter()
            .map(|s| s.interior())
            .collect();
        // The start: the last build's multipliers in this process, or
        // the saved start of a restored run's last build.
        if !g.multipliers.is_empty() {
            copy_from(&mut state.built_multipliers, &g.multipliers);
        }
        copy_from(&mut g.multipliers, &state.built_multipliers);
        let c = conform(
            (pipe.isa, &*pipe.ranks),
            &mut g.shapes,
            pts,
            &volume,
            &inner,
            Stop {
                tolerance: CONFORM_TOLERANCE,
                preconditioner: setup.rod.scheme.preconditioner,
            },
            &mut g.multipliers,
        );
        pipe.profile.conform_iterations += c.iterations as u64;
    }
    g.rows = row_parts(&*pipe.ranks, &g.shapes, n);
    pipe.profile.lap(Phase::Conform, &mut watch);
    match setup.rod.scheme.forces {
        Forces::Sphere => {
            g.spheres = spheres::spheres(setup, state, pts, &g.mirror, sup, &g.shapes);
            pipe.profile.lap(Phase::Spheres, &mut watch);
            g.op = TractionOperator::build(
                pipe.isa,
                pts,
                sup,
                &g.spheres,
                &SphereRule::of(DEFAULT_RULE),
                &SphereRule::of(BOUNDARY_RULE),
            )
            .map_err(stamp)?;
        }
        Forces::Nodal | Forces::Conforming => {
            g.spheres.clear();
        }
    }
    if let Some(parts) = columns {
        g.nodal
            .rebuild_parts_on(&*pipe.ranks, &g.shapes, pts.len(), parts);
    } else if setup.rod.scheme.forces.nodal() || setup.rod.scheme.order == SmoothingOrder::Two {
        g.nodal.rebuild_on(&*pipe.ranks, &g.shapes, pts.len());
    } else {
        g.nodal = NodalOperator::default();
    }
    let order2 = setup.rod.scheme.order == SmoothingOrder::Two;
    g.pass_send = pass_lists(&*pipe.ranks, &g, n, order2);
    pipe.profile.lap(Phase::Operator, &mut watch);
    pipe.profile.operators += 1;
    pipe.geometry = Some(g);
    state.rebuilds += 1;
    Ok(())
}

/// The supports at `supports_at` and, in the quarter model, the mirror
/// images they take (`src/approx/mirror.rs`). An image can matter to a real
/// row only if it is among the `k` nearest of a real node (within the
/// largest `k`-th distance `d_k` of the plane) or covers a point of a
/// real node's test sphere (within `r_J + d_k` of the quarter, the test
/// radius being below the nearest distance); so the supports are
/// computed with the images within a layer of the planes at least as
/// wide as the largest `r_J + d_k` (from six spacings, widened until
/// it is), and the images farther than their `r_J + d_k` are then
/// dropped: the rows are the same.
pub(super) fn supports_with_images(
    setup: &Setup3d,
    state: &State3d,
    ranks: &dyn crate::ranks::Ranks,
) -> Result<(Supports, Mirror)> {
    let n = state.pos.len();
    let at = &state.supports_at;
    if setup.plane.is_empty() {
        let sup = Supports::compute_rows_on(at, &setup.group, n, SupportParams::default(), ranks)?;
        return Ok((sup, Mirror::default()));
    }
    let mut layer = 6.0 * setup.reach;
    let (mut sup, m, dk) = loop {
        let m = Mirror::choose(at, &setup.plane, layer);
        let (mut pts, mut group) = (Vec::new(), Vec::new());
        m.extend(at, &mut pts, mirror::vector);
        if !setup.group.is_empty() {
            m.extend(&setup.group, &mut group, mirror::same);
        }
        let mut sup = Supports::compute_rows_on(&pts, &group, n, SupportParams::default(), ranks)?;
        // A node's radius covers what its images' do (their namers are
        // the images of its own), and its images have its radius.
        for (k, &j) in m.source.iter().enumerate() {
            sup.radius[j] = sup.radius[j].max(sup.radius[n + k]);
        }
        for (k, &j) in m.source.iter().enumerate() {
            sup.radius[n + k] = sup.radius[j];
        }
        let widest = sup.radius[..n].iter().copied().fold(0.0, f64::max);
        let dk = sup.named_distance.iter().copied().fold(0.0, f64::max);
        if !(widest + dk).is_finite() {
            // Only positions that overflow get here: never grow for ever.
            return Err(Error::NonFinite {
                field: "support radius",
                particle: sup.radius.iter().position(|r| !r.is_finite()).unwrap_or(0),
                time: state.clock.time,
            });
        }
        if widest + dk < layer {
            break (sup, m, dk);
        }
        layer = 1.25 * (widest + dk);
    };
    // Drop the images that no real row can see.
    let at_ext = |k: usize| mirror::vector(&at[m.source[k]], m.flip[k]);
    let keep: Vec<bool> = (0..m.len())
        .map(|k| {
            let x = at_ext(k);
            // Distance to the quarter x ≥ 0, y ≥ 0.
            let d = (x[0].min(0.0).powi(2) + x[1].min(0.0).powi(2)).sqrt();
            d < sup.radius[n + k] + dk
        })
        .collect();
    let mut index: Vec<usize> = (0..n).collect();
    let mut kept = Mirror::default();
    for (k, &keep) in keep.iter().enumerate() {
        if keep {
            index.push(n + kept.len());
            kept.source.push(m.source[k]);
            kept.flip.push(m.flip[k]);
        } else {
            index.push(usize::MAX);
        }
    }
    for j in &mut sup.named.indices {
        *j = index[*j];
        debug_assert!(*j != usize::MAX, "a named image is kept");
    }
    /// The entries of the kept nodes.
    fn compact<T: Copy>(v: &[T], index: &[usize]) -> Vec<T> {
        v.iter()
            .zip(index)
            .filter(|(_, i)| **i != usize::MAX)
            .map(|(x, _)| *x)
            .collect()
    }
    sup.radius = compact(&sup.radius, &index);
    if !sup.group.is_empty() {
        sup.group = compact(&sup.group, &index);
    }
    Ok((sup, kept))
}

/// One pass over the named pairs at the current positions `x` (the
/// positions at the last build `b`; both the real nodes', then their
/// images'): the smallest distance (the spacing check), whether a pair
/// has left the range of [`Supports::recompute_reason`] (the supports
/// are recomputed), and whether a pair has moved since the last build
/// by more than [`RodSetup::rebuild_strain`] of its length then
/// ([`REBUILD_STRAIN`]). Minima and "any"s: the same for any number of
/// threads.
///
/// The two tests compare squares first, with a margin
/// ([`PRE_TEST_MARGIN`]): only a pair near a bound (or one with a
/// non-finite position) takes the exact test's square root and
/// division, so the answers are the exact tests' (the smallest
/// distance is the root of the smallest square: the root is monotone
/// and correctly rounded).
pub(super) fn named_pairs(
    setup: &Setup3d,
    state: &State3d,
    pipe: &Pipeline3d,
    x: &[[f64; 3]],
    b: &[[f64; 3]],
) -> NamedPairs {
    let sup = pipe.supports();
    let limit = 0.5 * (1.0 + sup.params.factor);
    let rebuild = setup.rod.rebuild_strain;
    let (within, beyond) = (
        limit * limit * (1.0 - PRE_TEST_MARGIN),
        (1.0 + PRE_TEST_MARGIN) / (limit * limit),
    );
    let still = rebuild * rebuild * (1.0 - PRE_TEST_MARGIN);
    let dot = |a: [f64; 3]| a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
    // Each rank visits its share of the nodes; the smallest and the flags
    // are the same in any order.
    let ranks = &*pipe.ranks;
    let own = crate::ranks::share(state.pos.len(), ranks.rank(), ranks.size(), 1);
    let pairs = own
        .into_par_iter()
        .map(|i| {
            let lo = sup.named.offsets[i];
            let mut out = NamedPairs::NONE;
            for (q, &j) in sup.named.of(i).iter().enumerate() {
                let now: [f64; 3] = std::array::from_fn(|d| x[i][d] - x[j][d]);
                let d2 = dot(now);
                out.nearest = out.nearest.min(d2);
                let named = sup.named_distance[lo + q];
                let n2 = named * named;
                // Inside the squared bounds (false for a NaN).
                let inside = d2 <= within * n2 && d2 >= beyond * n2;
                if !out.recompute && !inside {
                    let ratio = distance(&x[i], &x[j]) / named;
                    out.recompute = ratio > limit || ratio < 1.0 / limit;
                }
                let then: [f64; 3] = std::array::from_fn(|d| b[i][d] - b[j][d]);
                let moved: [f64; 3] = std::array::from_fn(|d| now[d] - then[d]);
                let small = dot(moved) <= still * dot(then);
                if !out.strained && !small {
                    out.strained = norm(moved) / norm(then) > rebuild;
                }
            }
            out
        })
        .reduce(|| NamedPairs::NONE, NamedPairs::join);
    let pairs = if ranks.size() == 1 {
        pairs
    } else {
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        let mine = [pairs.nearest, flag(pairs.recompute), flag(pairs.strained)];
        crate::ranks::all_gather_one(ranks, mine)
            .into_iter()
            .map(|[nearest, recompute, strained]| NamedPairs {
                nearest,
                recompute: recompute != 0.0,
                strained: strained != 0.0,
            })
            .fold(NamedPairs::NONE, NamedPairs::join)
    };
    NamedPairs {
        nearest: pairs.nearest.sqrt(),
        ..pairs
    }
}
