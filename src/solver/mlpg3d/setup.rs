//! The setup of a 3-D MLPG run: the rod and the solver's numerical
//! choices ([`RodSetup`], with its typed scheme), the further bodies of a run of
//! several ([`Body`]), and the defaults with the measurements behind them.

use crate::approx::lattice::Cylinder;
use crate::materials::Material;
use crate::solver::mlpg3d::scheme::MlpgScheme;
/// Default damping ratio ζ at the highest frequency `ω_max` of the
/// stiffness-proportional damping: none, as in the seed. Measured (README,
/// "3-D MLPG mixed method: the instability"): on the free bar ζ = 0.1
/// slows the growth of the unstable modes (2.0 → 0.44 e-folds per period
/// at 2 rings, 1.6 → 0.64 at 3) without removing it, as the remaining
/// growth is in low modes (λ ≈ 2 % of λ_max); in `taylor3d` at 6 nodes
/// across it dissipates 7.6 % of the impact energy and does not prevent
/// the spacing collapse, while without it the energy error stays at 2.2 %.
pub const DAMPING: f64 = 0.0;

/// Default safety factor on the stable step of eq. (15).
pub const SAFETY: f64 = 0.9;

/// Relative motion of a named pair since the last build of the operator
/// (`|Δ(x_i − x_j)| / |x_i − x_j|`) past which the shapes, test spheres
/// and traction operator are rebuilt.
/// 0.05: at 0.01 the plastic zone of `taylor3d` (strain rates near 1e5/s)
/// rebuilds every step (270 s for 447 steps at 6 nodes across, against
/// 99 s for 465 steps at 0.05; both runs stop early, at 27.7 and 28.6 µs,
/// with rod lengths 34.56 and 34.51 mm).
pub const REBUILD_STRAIN: f64 = 0.05;

/// Default α of the velocity smoothing toward the MLS approximation at the
/// node. The MLS approximation does not interpolate: a node can move
/// relative to its neighbours by a motion the collocated gradients (eq. 4)
/// barely see. Without smoothing `taylor3d` (6 nodes across) stops at
/// 28.6 µs with the spacing collapsed to 0.1 on the axis at the face (the
/// second node from the face 74 µm above the face centre, which had left
/// the anvil, while the largest plastic strain is 0.95); measured α (Lf,
/// face radius, energy error, smoothing work of 220 J): 0.02: at rest,
/// 34.56 mm, 5.27 mm, 4.7 %, 4.2 J; 0.05: 34.59 mm, 5.20 mm, 2.5 %,
/// 5.8 J; 0.1: 34.62 mm, 5.11 mm, 1.4 %, 8.7 J. The smoothing reproduces
/// linear velocity fields, so it leaves uniform straining alone; 0.1 is
/// chosen for the smallest energy error (README, "3-D MLPG").
pub const SMOOTHING: f64 = 0.1;

/// A rod on the ring lattice at the instant of impact, and the solver's
/// numerical choices.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RodSetup {
    /// The rod (axis along z, impact face at z = 0).
    pub cylinder: Cylinder,
    /// Rings across the radius (radial spacing `R0 / rings`).
    pub rings: usize,
    /// Speed toward the anvil (m/s).
    pub impact_speed: f64,
    /// Damping ratio ζ at `ω_max` of the stiffness-proportional damping.
    pub damping: f64,
    /// Safety factor on the stable step.
    pub safety: f64,
    /// Latest simulated time (s).
    pub end_time: f64,
    /// See `REBUILD_STRAIN`.
    pub rebuild_strain: f64,
    /// The scheme: the forces, the smoothing and its order, the shifting,
    /// the lattice ([`MlpgScheme`]; the seed's by default).
    pub scheme: MlpgScheme,
    /// Height of the rod's face at impact (m): 0, on the anvil, for a
    /// Taylor run; above the plate for a penetration run.
    pub base: f64,
    /// The quarter model: only the nodes with `x ≥ 0`, `y ≥ 0`, with the
    /// symmetry planes `x = 0` and `y = 0` by mirror images
    /// (`src/approx/mirror.rs`); false (the default): the whole body.
    pub quarter: bool,
    /// The shifting carries the velocities conservatively
    /// (`solver::mlpg3d::shift::exchange`): a moved node's momentum increment is
    /// drawn from the nodes around it, so that a shift changes the total
    /// momentum by round-off only; false (the default): a moved node takes
    /// the velocity of its new place (`solver::mlpg3d::shift::carry`). Either way
    /// the kinetic energy a shift changes is booked with the smoothing's.
    pub conservative_carry: bool,
}

impl RodSetup {
    /// `κ` of the highest frequency of the forces chosen, `ω_max = κ c_p /
    /// d_min` ([`MlpgScheme::omega_factor`]).
    pub fn omega_factor(&self) -> f64 {
        self.scheme.omega_factor()
    }

    /// The ratio of this setup's stable step to the seed's form's,
    /// `OMEGA_FACTOR / κ`: the factor on the per-step rates (the
    /// smoothing's α, the shifting's β and cap), so that they act at the
    /// same rate per unit time whatever the step.
    pub fn step_scale(&self) -> f64 {
        self.scheme.step_scale()
    }

    /// A rod with the default numerical choices ([`DAMPING`], [`SAFETY`],
    /// [`REBUILD_STRAIN`]).
    pub fn new(cylinder: Cylinder, rings: usize, impact_speed: f64, end_time: f64) -> Self {
        RodSetup {
            cylinder,
            rings,
            impact_speed,
            damping: DAMPING,
            safety: SAFETY,
            end_time,
            rebuild_strain: REBUILD_STRAIN,
            scheme: MlpgScheme::default(),
            base: 0.0,
            quarter: false,
            conservative_carry: false,
        }
    }
}

/// A further body of a run of several bodies (the first is the rod of the
/// [`RodSetup`]): a cylinder on the ring lattice with its face at
/// `z = base`, moving along z at `velocity`, of its own material.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Body {
    /// The cylinder (axis along z).
    pub cylinder: Cylinder,
    /// Rings across its radius.
    pub rings: usize,
    /// Height of its face, its lowest layer (m).
    pub base: f64,
    /// Velocity along z at the start (m/s).
    pub velocity: f64,
    /// Its material.
    pub material: Material,
    /// Whether its rim is clamped: the nodes of its outer ring are held
    /// still (their velocities zero, never shifted); a held node's
    /// reaction does no work. Default: free.
    pub clamped_rim: bool,
    /// The order of its nodes: the rings' layers (the default, not
    /// written, so that the setups saved before it keep their digests) or
    /// a recursive coordinate bisection, whose ranges are compact pieces
    /// of the body (the ranks' parts: [`NodeOrder`]).
    #[serde(default, skip_serializing_if = "NodeOrder::is_rings")]
    pub node_order: NodeOrder,
}

/// The order of a body's nodes. The ranks of a run share the nodes by
/// contiguous ranges of it, and every pass sums in it; the same order
/// gives the same bits on any number of ranks, another order other
/// round-off.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum NodeOrder {
    /// Layer by layer from the face, ring by ring from the axis
    /// (`NodeLattice::cylinder`): a range of a thin, wide plate is a few
    /// layers of its whole face.
    #[default]
    Rings,
    /// Recursive coordinate bisection (`approx::lattice::bisection_order`):
    /// a range is a few compact pieces.
    Bisection,
}

impl NodeOrder {
    /// Whether this is the rings' order (the default).
    pub fn is_rings(&self) -> bool {
        *self == NodeOrder::Rings
    }
}
