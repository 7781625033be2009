//! The numerical scheme of the 3-D MLPG solver, typed: the one decoder of
//! the knobs that a scene's `scheme` sets (`weak_form`, `smoothing_order`,
//! `smoothing_coefficient`, `shifting`, `lattice`) and the one check of
//! their combination with the model's `symmetry`, for every scene on this
//! solver (`taylor3d`, `penetration`).

use crate::error::{Error, Result};
use crate::solver::mlpg3d::{RodSetup, WeakForm};

/// The forces of the MLPG solver (`weak_form`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Forces {
    /// 0: the seed's local weak form over test spheres (eq. 10).
    Sphere,
    /// 1: the nodal Galerkin form, the adjoint of the collocated gradients.
    Nodal,
    /// 2: the nodal form with conforming gradients (`src/approx/conform.rs`):
    /// the whole body only.
    Conforming,
}

/// The velocity smoothing's order (`smoothing_order`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SmoothingOrder {
    /// 1: `v ← v − α H v`.
    One,
    /// 2: `v ← v − α M⁻¹ Hᵀ M H v`, which spares smooth fields.
    Two,
}

/// The node lattice of a rod (`lattice`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lattice {
    /// 0: every layer's nodes on the same radial lines.
    Aligned,
    /// 1: the odd layers turned by half a node's angle.
    Staggered,
}

/// A scheme of the MLPG solver, decoded from a scene's knobs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MlpgScheme {
    /// The forces.
    pub forces: Forces,
    /// The smoothing's order.
    pub order: SmoothingOrder,
    /// α of the velocity smoothing.
    pub smoothing: f64,
    /// β of the node shifting (0: Lagrangian nodes).
    pub shifting: f64,
    /// The rod's lattice.
    pub lattice: Lattice,
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
        let symmetry = get("symmetry")?;
        if forces == Forces::Conforming && symmetry >= 0.5 {
            return Err(Error::Inconsistent(format!(
                "weak_form = {weak_form} (conforming gradients) needs the whole body, but symmetry = {symmetry} \
                 asks for the quarter model: set weak_form = 1 (the nodal form, which the quarter model \
                 runs) or symmetry = 0 (scheme large_strain sets weak_form = 2)"
            )));
        }
        Ok(MlpgScheme {
            forces,
            order,
            smoothing: get("smoothing_coefficient")?,
            shifting: get("shifting")?,
            lattice,
        })
    }

    /// Puts the scheme into a run's setup.
    pub fn apply(&self, setup: &mut RodSetup) {
        setup.weak_form = match self.forces {
            Forces::Sphere => WeakForm::Sphere,
            Forces::Nodal | Forces::Conforming => WeakForm::Nodal,
        };
        setup.conforming = self.forces == Forces::Conforming;
        setup.smoothing_order = match self.order {
            SmoothingOrder::One => 1,
            SmoothingOrder::Two => 2,
        };
        setup.smoothing = self.smoothing;
        setup.shifting = self.shifting;
        setup.staggered = self.lattice == Lattice::Staggered;
    }
}
