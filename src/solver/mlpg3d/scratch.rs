//! The step's buffers, reused from step to step (not saved), and the sums
//! of one step.

use super::shift::Freedom;
use crate::Error;
use crate::approx::buffers::fit;
/// The buffers of a step, reused from step to step (not saved), one group
/// per pass.
#[derive(Debug, Clone, Default)]
pub(super) struct Scratch {
    /// The forces (step 1).
    pub(super) forces: ForceBuffers,
    /// What the velocity update saw at each node (step 2).
    pub(super) kicks: Vec<Kick>,
    /// The velocity smoothing's buffers.
    pub(super) smoothing: SmoothingBuffers,
    /// The contact's buffers.
    pub(super) contact: ContactBuffers,
    /// What the position update did at each node (step 3).
    pub(super) moves: Vec<Move>,
    /// The collocated velocity gradients (step 5).
    pub(super) grad: Vec<[[f64; 3]; 3]>,
    /// Each node's sums of the material pass, or its error.
    pub(super) results: Vec<std::result::Result<Tally, (usize, Error)>>,
    /// The shifting's buffers (sized only with `shifting > 0`).
    pub(super) shifting: ShiftBuffers,
    /// The quarter model's fields extended by the mirror images.
    pub(super) images: ImageBuffers,
}

/// The buffers of the forces.
#[derive(Debug, Clone, Default)]
pub(super) struct ForceBuffers {
    /// The total stress `σ + σ_v` at each node.
    pub(super) total: Vec<[f64; 6]>,
    /// The nodal forces (the real nodes', then the images' to fold).
    pub(super) force: Vec<[f64; 3]>,
    /// The nodal volumes `m / ρ` (the nodal form).
    pub(super) volume: Vec<f64>,
}

/// The buffers of the velocity smoothing.
#[derive(Debug, Clone, Default)]
pub(super) struct SmoothingBuffers {
    /// The smoothed velocities (swapped with the nodes').
    pub(super) smooth: Vec<[f64; 3]>,
    /// The smoothing's defect `H v` (order 2: `Hᵀ M H v`).
    pub(super) defect: Vec<[f64; 3]>,
    /// With order 2, the mass-weighted defect `M H v`.
    pub(super) pass: Vec<[f64; 3]>,
    /// Its rows as they travel among the ranks.
    pub(super) wire: Vec<[f64; 3]>,
}

/// The buffers of the contact between bodies and between pulverized nodes.
#[derive(Debug, Clone, Default)]
pub(super) struct ContactBuffers {
    /// The node pairs in contact.
    pub(super) pairs: Vec<(usize, usize)>,
    /// The velocities before the step's forces (runs of several bodies or
    /// with damage).
    pub(super) before: Vec<[f64; 3]>,
    /// Whether each node is pulverized (runs with damage).
    pub(super) loose: Vec<bool>,
}

/// The buffers of the node shifting.
#[derive(Debug, Clone, Default)]
pub(super) struct ShiftBuffers {
    /// Each node's shift.
    pub(super) shift: Vec<[f64; 3]>,
    /// The shifted nodes' shifts as they travel among the ranks.
    pub(super) shift_wire: Vec<[f64; 3]>,
    /// How each node may move.
    pub(super) free: Vec<Freedom>,
    /// The carried fields ([`CARRIED`]) before the carry (the columns:
    /// the nodes, then the mirror images; only those the carry reads are
    /// current) and after it.
    pub(super) carried: Vec<[f64; CARRIED]>,
    pub(super) carried_out: Vec<[f64; CARRIED]>,
    /// Which columns of `carried` are current (a buffer of the pack).
    pub(super) read: Vec<bool>,
    /// The shifted nodes' carried fields as they travel among the ranks.
    pub(super) wire: Vec<[f64; CARRIED]>,
    /// The change of each node's momentum in the conservative carry
    /// (images after the real nodes).
    pub(super) momentum: Vec<[f64; 3]>,
    /// The limits' shares of the conservative carry.
    pub(super) share: Vec<Option<[f64; 3]>>,
}

/// The quarter model's fields extended by the mirror images (each the
/// real nodes' values, then the images').
#[derive(Debug, Clone, Default)]
pub(super) struct ImageBuffers {
    pub(super) pos: Vec<[f64; 3]>,
    pub(super) built: Vec<[f64; 3]>,
    pub(super) vel: Vec<[f64; 3]>,
    pub(super) before: Vec<[f64; 3]>,
    pub(super) total: Vec<[f64; 6]>,
    pub(super) mass: Vec<f64>,
    pub(super) group: Vec<u8>,
    pub(super) loose: Vec<bool>,
}

/// What the velocity update saw at a node.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Kick {
    /// The kinetic energy a node held on the anvil lost toward it (J).
    pub(super) held: f64,
    /// The time of its release from the anvil in this step, if it let go.
    pub(super) released: Option<f64>,
}

/// What the position update did at a node.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Move {
    /// [`Kick::held`].
    pub(super) held: f64,
    /// The kinetic energy toward the anvil it lost on reaching it (J).
    pub(super) lost: f64,
    /// [`Kick::released`].
    pub(super) released: Option<f64>,
    /// Its height when it passed the anvil by more than half a spacing.
    pub(super) through: Option<f64>,
}

impl Scratch {
    /// Every buffer at `n` entries (allocates only when `n` grows).
    pub(super) fn fit(&mut self, n: usize) {
        fit(&mut self.forces.total, n, [0.0; 6]);
        fit(&mut self.forces.force, n, [0.0; 3]);
        fit(&mut self.kicks, n, Kick::default());
        fit(&mut self.smoothing.smooth, n, [0.0; 3]);
        fit(&mut self.smoothing.defect, n, [0.0; 3]);
        fit(&mut self.smoothing.pass, n, [0.0; 3]);
        fit(&mut self.moves, n, Move::default());
        fit(&mut self.grad, n, [[0.0; 3]; 3]);
        fit(&mut self.forces.volume, n, 0.0);
        fit(&mut self.results, n, Ok(Tally::default()));
    }

    /// The shifting buffers at `n` entries.
    pub(super) fn fit_shift(&mut self, n: usize) {
        let s = &mut self.shifting;
        fit(&mut s.shift, n, [0.0; 3]);
        fit(&mut s.free, n, Freedom::Fixed);
        fit(&mut s.carried_out, n, [0.0; CARRIED]);
    }

    /// The heap bytes of the buffers counted per node in the memory by
    /// part ([`Mlpg3d::memory`]; capacities, not lengths).
    pub(super) fn bytes(&self) -> usize {
        fn b<T>(v: &Vec<T>) -> usize {
            v.capacity() * std::mem::size_of::<T>()
        }
        let (f, s, h) = (&self.forces, &self.smoothing, &self.shifting);
        b(&f.total)
            + b(&f.force)
            + b(&self.kicks)
            + b(&s.smooth)
            + b(&s.defect)
            + b(&s.pass)
            + b(&self.moves)
            + b(&self.grad)
            + b(&f.volume)
            + b(&self.results)
            + b(&h.shift)
            + b(&h.free)
            + b(&h.carried)
            + b(&h.carried_out)
    }
}

/// The fields a shifted node carries: velocity (3), deviator (6), density,
/// plastic strain, temperature and the reference place (3).
pub(super) const CARRIED: usize = 15;

/// The sums of one step over the nodes.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Tally {
    pub(super) internal: f64,
    pub(super) plastic: f64,
    pub(super) damping: f64,
    pub(super) kinetic: f64,
    pub(super) momentum: f64,
    pub(super) mass: f64,
    pub(super) worst_speed: f64,
}
