//! The numerical foundations of the 3-D MLPG mixed method of Han, Liu,
//! Rajendran & Atluri (seed `004`, sections 2 and 3): the node lattice of a
//! cylinder, MLS interpolation with its supports, the nodal velocity
//! gradients by collocation (eq. 4), the sphere quadrature and test radii
//! of the local weak form with the Heaviside test function (eqs. 10, 12),
//! its traction residual, and the stable time step (eq. 15).
//!
//! The time loop with materials, the anvil contact and the scene are the
//! solver's, built on these pieces.

pub mod lattice;
pub mod mls;
pub mod sphere;
pub mod step;
pub mod weak;

#[cfg(test)]
mod measure;

pub use lattice::{Cylinder, NodeLattice, Surfaces};
pub use mls::{NodalShapes, Recompute, ShapeRow, SupportParams, Supports};
pub use sphere::{SphereRule, TestSphere};
pub use weak::TractionOperator;
