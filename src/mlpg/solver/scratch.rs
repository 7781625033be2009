//! The step's buffers, reused from step to step (not saved), and the sums
//! of one step.

use super::*;

/// The buffers of a step, reused from step to step (not saved).
#[derive(Debug, Clone, Default)]
pub(super) struct Scratch {
    pub(super) total: Vec<[f64; 6]>,
    pub(super) force: Vec<[f64; 3]>,
    pub(super) kicked: Vec<(f64, Option<f64>)>,
    pub(super) smooth: Vec<[f64; 3]>,
    /// The smoothing's defect `H v` (order 2: `Hᵀ M H v`) and, with
    /// order 2, the mass-weighted defect `M H v`.
    pub(super) defect: Vec<[f64; 3]>,
    pub(super) pass: Vec<[f64; 3]>,
    pub(super) moved: Vec<(f64, f64, Option<f64>, Option<f64>)>,
    pub(super) grad: Vec<[[f64; 3]; 3]>,
    /// The nodal volumes `m / ρ` (the nodal form).
    pub(super) volume: Vec<f64>,
    pub(super) results: Vec<std::result::Result<Tally, (usize, Error)>>,
    /// The shifts and the carried fields (sized only with `shifting > 0`).
    pub(super) shift: Vec<[f64; 3]>,
    pub(super) free: Vec<Freedom>,
    pub(super) carried: Vec<[f64; CARRIED]>,
    pub(super) carried_out: Vec<[f64; CARRIED]>,
    /// The node pairs of different bodies in contact.
    pub(super) pairs: Vec<(usize, usize)>,
    /// The velocities before the step's forces (runs of several bodies).
    pub(super) before: Vec<[f64; 3]>,
    /// Whether each node is pulverized (runs with damage).
    pub(super) loose: Vec<bool>,
    /// The quarter model's fields extended by the mirror images.
    pub(super) ext_pos: Vec<[f64; 3]>,
    pub(super) ext_built: Vec<[f64; 3]>,
    pub(super) ext_vel: Vec<[f64; 3]>,
    pub(super) ext_before: Vec<[f64; 3]>,
    pub(super) ext_total: Vec<[f64; 6]>,
    pub(super) ext_mass: Vec<f64>,
    pub(super) ext_group: Vec<u8>,
    pub(super) ext_loose: Vec<bool>,
    pub(super) ext_carried: Vec<[f64; CARRIED]>,
    /// The change of each node's momentum in the conservative carry
    /// (images after the real nodes).
    pub(super) momentum: Vec<[f64; 3]>,
    /// The limits' shares of the conservative carry.
    pub(super) share: Vec<Option<[f64; 3]>>,
}

impl Scratch {
    /// Every buffer at `n` entries (allocates only when `n` grows).
    pub(super) fn fit(&mut self, n: usize) {
        self.total.resize(n, [0.0; 6]);
        self.force.resize(n, [0.0; 3]);
        self.kicked.resize(n, (0.0, None));
        self.smooth.resize(n, [0.0; 3]);
        self.defect.resize(n, [0.0; 3]);
        self.pass.resize(n, [0.0; 3]);
        self.moved.resize(n, (0.0, 0.0, None, None));
        self.grad.resize(n, [[0.0; 3]; 3]);
        self.volume.resize(n, 0.0);
        self.results.resize(n, Ok(Tally::default()));
    }

    /// The shifting buffers at `n` entries.
    pub(super) fn fit_shift(&mut self, n: usize) {
        self.shift.resize(n, [0.0; 3]);
        self.free.resize(n, Freedom::Fixed);
        self.carried.resize(n, [0.0; CARRIED]);
        self.carried_out.resize(n, [0.0; CARRIED]);
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
