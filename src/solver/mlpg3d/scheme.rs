//! The numerical scheme of the 3-D MLPG solver, typed: the one decoder of
//! the knobs that a scene's `scheme` sets (`weak_form`, `smoothing_order`,
//! `smoothing_coefficient`, `shifting`, `lattice`) and the one check of
//! their combination with the model's `symmetry`, for every scene on this
//! solver (`taylor3d`, `penetration`).

use crate::approx::conform::Preconditioner;
use crate::approx::step::{OMEGA_FACTOR, OMEGA_FACTOR_CONFORMING, OMEGA_FACTOR_NODAL};
use crate::error::{Error, Result};

/// The forces of the MLPG solver (`weak_form`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Forces {
    /// 0: the seed's local weak form with the Heaviside test function over
    /// each node's test sphere (eq. 10, `TractionOperator`), the sphere's
    /// inertia `ρ V_s`.
    Sphere,
    /// 1: the nodal Galerkin form, the adjoint of the collocated gradients
    /// (eq. 4; `src/approx/nodal.rs`), the nodal mass as inertia: it
    /// conserves momentum and creates no energy, and node shifting also
    /// moves the nodes of the mantle in its tangent plane and the face
    /// nodes held on the anvil in its plane (README, "3-D MLPG mixed
    /// method").
    Nodal,
    /// 2: the nodal form with gradients corrected to meet the integration
    /// constraint at the surfaces (`src/approx/conform.rs`), so that a
    /// uniform stress leaves every node off the surfaces in equilibrium:
    /// the whole body only.
    Conforming,
}

impl Forces {
    /// Whether the forces are the nodal form's (with or without conforming
    /// gradients): the nodal mass as inertia.
    pub fn nodal(self) -> bool {
        self != Forces::Sphere
    }

    /// `κ` of the forces' highest frequency, `ω_max = κ c_p / d_min`
    /// (`src/approx/step.rs`, measured by power iteration on each form's
    /// elastic operator).
    pub fn omega_factor(self) -> f64 {
        match self {
            Forces::Sphere => OMEGA_FACTOR,
            Forces::Nodal => OMEGA_FACTOR_NODAL,
            Forces::Conforming => OMEGA_FACTOR_CONFORMING,
        }
    }
}

/// The velocity smoothing's order (`smoothing_order`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum SmoothingOrder {
    /// 1: `v ← v − α H v`.
    One,
    /// 2: `v ← v − α M⁻¹ Hᵀ M H v` (M the nodal masses), the symmetric
    /// square of order 1: it conserves momentum, only removes kinetic
    /// energy, and damps smooth fields far less than the modes the shapes
    /// cannot represent.
    Two,
}

impl SmoothingOrder {
    /// The power of `H = I − Φ` it applies: 1 or 2.
    pub fn power(self) -> u32 {
        match self {
            SmoothingOrder::One => 1,
            SmoothingOrder::Two => 2,
        }
    }
}

/// The node lattice of a rod (`lattice`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Lattice {
    /// 0: every layer's nodes on the same radial lines.
    Aligned,
    /// 1: the odd layers turned by half a node's angle.
    Staggered,
}

/// A scheme of the MLPG solver, decoded from a scene's knobs: it reaches
/// the passes as it is (in [`crate::solver::mlpg3d::RodSetup::scheme`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MlpgScheme {
    /// The forces.
    pub forces: Forces,
    /// The smoothing's order.
    pub order: SmoothingOrder,
    /// α of the velocity smoothing `v ← v − α (I − Φ)^k v` after each
    /// velocity update, with `(Φ v)_i = Σ_J φ_J(x_i) v_J` the MLS
    /// approximation at the node (`SMOOTHING`). α is per step of the
    /// seed's form; a form with a shorter stable step applies it in
    /// proportion to its step ([`MlpgScheme::step_scale`]), so that the
    /// smoothing per unit time does not depend on the form's step.
    pub smoothing: f64,
    /// β of the node shifting (`src/solver/mlpg3d/shift.rs`; the `taylor`
    /// scene's `shifting`): pairs closer than `SHIFT_RANGE` of the initial
    /// spacing push apart by up to β times the spacing per step
    /// (`SHIFT_CAP` at most; both per step of the seed's form, as the
    /// smoothing's α); 0: Lagrangian nodes.
    pub shifting: f64,
    /// The rod's lattice.
    pub lattice: Lattice,
    /// The preconditioner of the conforming correction (its forces
    /// only). Jacobi's, the default, is not written, so a setup without
    /// the option keeps its digest and the states saved before it existed
    /// read as Jacobi's.
    #[serde(default, skip_serializing_if = "Preconditioner::is_jacobi")]
    pub preconditioner: Preconditioner,
}

/// The seed's scheme: its weak form, the smoothing of order 1 with
/// `SMOOTHING`, Lagrangian nodes, the layers aligned.
impl Default for MlpgScheme {
    fn default() -> Self {
        MlpgScheme {
            forces: Forces::Sphere,
            order: SmoothingOrder::One,
            smoothing: crate::solver::mlpg3d::SMOOTHING,
            shifting: 0.0,
            lattice: Lattice::Aligned,
            preconditioner: Preconditioner::Jacobi,
        }
    }
}

impl MlpgScheme {
    /// Decodes the knobs read by `get` (each already in its range) and
    /// checks them with the scene's `symmetry`: conforming gradients on the
    /// quarter model are refused, naming both parameters.
    pub fn decode(get: impl Fn(&str) -> Result<f64>) -> Result<MlpgScheme> {
        let weak_form = get("weak_form")?;
        let forces = match weak_form as i64 {
            0 => Forces::Sphere,
            1 => Forces::Nodal,
            _ => Forces::Conforming,
        };
        let order = if get("smoothing_order")? >= 1.5 {
            SmoothingOrder::Two
        } else {
            SmoothingOrder::One
        };
        let lattice = if get("lattice")? >= 0.5 {
            Lattice::Staggered
        } else {
            Lattice::Aligned
        };
        let scheme = MlpgScheme {
            forces,
            order,
            smoothing: get("smoothing_coefficient")?,
            shifting: get("shifting")?,
            lattice,
            // Only the conforming correction has iterations to precondition:
            // with the other forms the scheme keeps Jacobi's, the value that
            // is not written, so their setups' digests do not depend on a
            // parameter they do not read.
            preconditioner: if forces == Forces::Conforming && get("conform_preconditioner")? >= 0.5
            {
                Preconditioner::Levels
            } else {
                Preconditioner::Jacobi
            },
        };
        scheme.check(get("symmetry")? >= 0.5)?;
        Ok(scheme)
    }

    /// The one check of the scheme's combination with the model: the
    /// conforming gradients need the whole body, so on the quarter model
    /// they are refused, naming both parameters.
    pub fn check(&self, quarter: bool) -> Result<()> {
        if self.forces == Forces::Conforming && quarter {
            return Err(Error::Inconsistent(
                "weak_form = 2 (conforming gradients) needs the whole body, but symmetry = 1 \
                 asks for the quarter model: set weak_form = 1 (the nodal form, which the quarter \
                 model runs) or symmetry = 0 (scheme large_strain sets weak_form = 2)"
                    .into(),
            ));
        }
        Ok(())
    }

    /// `κ` of the highest frequency of the forces, `ω_max = κ c_p / d_min`
    /// ([`Forces::omega_factor`]).
    pub fn omega_factor(&self) -> f64 {
        self.forces.omega_factor()
    }

    /// The ratio of this scheme's stable step to the seed's form's,
    /// `OMEGA_FACTOR / κ`: the factor on the per-step rates (the
    /// smoothing's α, the shifting's β and cap), so that they act at the
    /// same rate per unit time whatever the step.
    pub fn step_scale(&self) -> f64 {
        OMEGA_FACTOR / self.omega_factor()
    }
}
