//! The buffers of the axisymmetric solver's step, reused from step to step
//! (no allocation in the time loop but when the neighbour lists are
//! rebuilt), and the per-chunk sums the passes write into them.

use super::mirror::Image;
use crate::solver::axisymmetric::boundary::Stress;
use crate::solver::axisymmetric::pairs::{PairPass, ScratchPool};

/// Buffers reused from step to step. Not part of the state: rebuilt from
/// the positions after a restore, and after a copy (see its `Clone`).
#[derive(Debug, Default)]
pub(super) struct Workspace {
    /// The mirror images and the candidate neighbour lists.
    pub lists: Lists,
    /// Twice the farthest any particle moved since the pair pass of the last
    /// step: a particle whose closest neighbour then (`part[i].min_d2`) was
    /// farther than the shifting range plus this has no neighbour within
    /// the range now, and is left out of the shifting pass (which gives the
    /// same bits). None after a restore.
    pub shift_margin: Option<f64>,
    /// Per particle, the weights that turn a stress into the work it did in
    /// the last step, `dt/2 (m/rho) (D_RR, D_ZZ, D_TT, 2 D_RZ)`: the
    /// internal energy books the boundary conditions' change to the stress
    /// with them.
    pub rate: Vec<[f64; 4]>,
    /// The stress before the boundary conditions at the end of a step.
    pub raw_bc: Vec<Stress>,
    /// Fields of the particles and their images.
    pub fields: ImageFields,
    /// The rows the pair pass writes for the passes after it.
    pub rows: PairRows,
    /// Velocity gradients `dU_R/dR, dU_R/dZ, dU_Z/dR, dU_Z/dZ` per particle.
    pub grads: Vec<[f64; 4]>,
    /// The per-chunk sums of the passes.
    pub sums: ChunkSums,
    /// Neighbourhoods of the pair pass, one set per thread.
    pub scratch: ScratchPool,
}

/// The mirror images and the candidate neighbour lists, and what they were
/// built from (to tell when they must be built again).
#[derive(Debug, Default)]
pub(super) struct Lists {
    /// Mirror images; image `k` has index `n + k`.
    pub images: Vec<Image>,
    /// Row length of the padded neighbour arrays.
    pub stride: usize,
    /// Candidate neighbours of particle `i`: `nbr[i * stride..][..nbr_len[i]]`,
    /// ascending, images included.
    pub nbr: Vec<u32>,
    /// Number of candidates of each particle.
    pub nbr_len: Vec<u32>,
    /// Positions when the lists were built.
    pub built_at: Vec<[f64; 2]>,
    /// Contact flags of the impact-face particles when the images were made.
    pub face_contact: Vec<bool>,
    /// Particles on the axis when the images were made.
    pub axis_count: usize,
}

/// Fields of the particles followed by their mirror images.
#[derive(Debug, Default)]
pub(super) struct ImageFields {
    /// Positions.
    pub pos: Vec<[f64; 2]>,
    /// Volumes `m / rho`.
    pub vol: Vec<f64>,
    /// Stresses with boundary conditions.
    pub sbc: Vec<Stress>,
    /// Velocities `v^{n+1/2}` from the momentum equation.
    pub vel: Vec<[f64; 2]>,
    /// The same, smoothed.
    pub vel_s: Vec<[f64; 2]>,
    /// The smoothing operator applied once to the velocity (the Shepard
    /// mean minus the value), for the smoothing of order 2.
    pub lap: Vec<[f64; 2]>,
    /// The same for the density (its smoothing follows the velocity's
    /// order).
    pub lap_rho: Vec<[f64; 1]>,
    /// Densities from the continuity equation, before smoothing.
    pub rho: Vec<[f64; 1]>,
}

/// Neighbours in the support this step, and their MSPH derivative weights
/// (d/dR, d/dZ) and Shepard weights, in the padded layout; and each
/// particle's record of the pair pass.
#[derive(Debug, Default)]
pub(super) struct PairRows {
    /// Neighbours in the support.
    pub act: Vec<u32>,
    /// Weights of d/dR.
    pub wr: Vec<f64>,
    /// Weights of d/dZ.
    pub wz: Vec<f64>,
    /// Shepard weights.
    pub wk: Vec<f64>,
    /// Per-particle records.
    pub part: Vec<PairPass>,
}

/// The sums of the passes, one per chunk, added chunk by chunk in index
/// order afterwards (so the totals do not depend on the thread count).
#[derive(Debug, Default)]
pub(super) struct ChunkSums {
    /// Per batch of the pair pass.
    pub batches: Vec<BatchTally>,
    /// Per chunk of the smoothing pass.
    pub smoothing: Vec<KineticChange>,
    /// Per chunk of the update pass.
    pub tallies: Vec<Tally>,
}

/// The kinetic energy of a chunk before and after the smoothing.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct KineticChange {
    /// Before.
    pub before: f64,
    /// After.
    pub after: f64,
}

impl KineticChange {
    /// The sums of `parts`, in order.
    pub fn total(parts: &[KineticChange]) -> KineticChange {
        parts
            .iter()
            .fold(KineticChange::default(), |a, k| KineticChange {
                before: a.before + k.before,
                after: a.after + k.after,
            })
    }
}

/// What the pair pass found in a batch of [`crate::lanes::W`] particles.
#[derive(Debug, Clone, Copy)]
pub(super) struct BatchTally {
    /// First particle with a degenerate moment matrix, and its condition.
    pub singular: Option<(usize, f64)>,
    /// Smallest squared distance between neighbours.
    pub min_d2: f64,
    /// Kinetic energy removed by holding particles on the anvil.
    pub held: f64,
}

impl Default for BatchTally {
    fn default() -> Self {
        BatchTally {
            singular: None,
            min_d2: f64::INFINITY,
            held: 0.0,
        }
    }
}

impl BatchTally {
    /// The tally of all `batches`, taken in order.
    pub fn total(batches: &[BatchTally]) -> BatchTally {
        let mut a = BatchTally::default();
        for t in batches {
            a.singular = a.singular.or(t.singular);
            a.min_d2 = a.min_d2.min(t.min_d2);
            a.held += t.held;
        }
        a
    }
}

/// A particle that went through the anvil or the axis.
#[derive(Debug, Clone, Copy)]
pub(super) struct Through {
    /// The particle.
    pub particle: usize,
    /// `"anvil"` or `"axis"`.
    pub boundary: &'static str,
    /// Its coordinate normal to the boundary.
    pub position: f64,
}

/// A particle compressed past the limit of the equation of state.
#[derive(Debug, Clone, Copy)]
pub(super) struct Compressed {
    /// The particle.
    pub particle: usize,
    /// Its compression.
    pub compression: f64,
    /// The limit.
    pub limit: f64,
}

/// The sums of a chunk of [`super::MIN_LEN`] particles at the end of a
/// step, added chunk by chunk in index order afterwards (so the totals do
/// not depend on the thread count).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Tally {
    /// Internal energy added by the stress power.
    pub internal: f64,
    /// Kinetic energy at the end.
    pub kinetic: f64,
    /// Axial momentum `sum m U_Z` at the end.
    pub momentum: f64,
    /// Mass.
    pub mass: f64,
    /// Kinetic energy removed by particles reaching the anvil.
    pub contact_lost: f64,
    /// Largest `c + |v|` (for the time step).
    pub worst_speed: f64,
    /// Largest `|v|^2`.
    pub fastest2: f64,
    /// Whether a particle touches the anvil.
    pub touching: bool,
    /// First particle through the anvil or the axis.
    pub through: Option<Through>,
    /// First particle with a non-finite field: (particle, field).
    pub non_finite: Option<(usize, &'static str)>,
    /// First particle compressed past the limit of the equation of state.
    pub compression: Option<Compressed>,
}

impl Tally {
    /// The tally of all `chunks`, taken in order.
    pub fn total(chunks: &[Tally]) -> Tally {
        let mut t = Tally::default();
        for c in chunks {
            t.internal += c.internal;
            t.kinetic += c.kinetic;
            t.momentum += c.momentum;
            t.mass += c.mass;
            t.contact_lost += c.contact_lost;
            t.worst_speed = t.worst_speed.max(c.worst_speed);
            t.fastest2 = t.fastest2.max(c.fastest2);
            t.touching |= c.touching;
            t.through = t.through.or(c.through);
            t.non_finite = t.non_finite.or(c.non_finite);
            t.compression = t.compression.or(c.compression);
        }
        t
    }
}

/// A copy of a run (an FMU state got to roll back to) starts with empty
/// buffers, as a restored run does, and rebuilds them at its next step with
/// the same bits: at 10^6 particles the buffers are 1.5 GB, the state
/// itself 0.14 GB (BENCHMARKS.md).
impl Clone for Workspace {
    fn clone(&self) -> Self {
        Workspace::default()
    }
}
