//! The numerical scheme of the axisymmetric MSPH solver, typed: the one
//! decoder of the knobs that the `taylor` scene's `scheme` sets
//! (`smoothing_ratio`, `smoothing_coefficient`, `smoothing_order`,
//! `shifting`). Each knob's range is its whole check: no combination of
//! values in range is known to be unworkable (VALIDATION.md, "Right by
//! default", the schemes and their mixtures measured).

use crate::solver::axisymmetric::TaylorParams;

/// The velocity and density smoothing's order (`smoothing_order`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum SmoothingOrder {
    /// 1: the paper's conservative smoothing (3.23).
    Paper,
    /// 2: its bi-Laplacian, which spares smooth fields (large strain).
    BiLaplacian,
}

/// A scheme of the MSPH solver, decoded from a run's parameters.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct MsphScheme {
    /// `h` over the particle spacing.
    pub smoothing_ratio: f64,
    /// `α_cs` of the smoothing.
    pub smoothing: f64,
    /// The smoothing's order.
    pub order: SmoothingOrder,
    /// β of the particle shifting (0: Lagrangian particles).
    pub shifting: f64,
}

impl MsphScheme {
    /// The scheme of a run's parameters (each in its range).
    pub fn of(p: &TaylorParams) -> MsphScheme {
        MsphScheme {
            smoothing_ratio: p.smoothing_ratio,
            smoothing: p.smoothing_coefficient,
            order: if p.smoothing_order >= 1.5 {
                SmoothingOrder::BiLaplacian
            } else {
                SmoothingOrder::Paper
            },
            shifting: p.shifting,
        }
    }
}
