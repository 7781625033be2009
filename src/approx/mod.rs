//! The approximation layer: the MSPH basis of Batra & Zhang ([`msph`],
//! seed `000`) for the axisymmetric solver, and the numerical foundations
//! of the 3-D MLPG mixed method of Han, Liu,
//! Rajendran & Atluri (seed `004`, sections 2 and 3): the node lattice of a
//! cylinder, MLS interpolation with its supports, the nodal velocity
//! gradients by collocation (eq. 4), the sphere quadrature and test radii
//! of the local weak form with the Heaviside test function (eqs. 10, 12),
//! its traction residual, and the stable time step (eq. 15).
//!
//! The choices the seed leaves open, each measured where it is defined:
//!
//! - **Lattice** ([`lattice`]): concentric rings of `6 k` nodes in equally
//!   spaced layers; nodes on the mantle, face and top; lumped volumes that
//!   sum to `π R0² L0` to one ulp (a clipped cubic lattice misses by up to
//!   7 %).
//! - **MLS** ([`mls`]): linear basis, quartic spline weight; each node names
//!   its `k = 10` nearest, supports are 1.5 × the largest naming distance
//!   and are recomputed when a named pair stretches or shrinks by 1.25.
//! - **Quadrature** ([`sphere`]): whole spheres by the icosahedron with 3
//!   points a face (60 points); spheres of boundary nodes cut by the
//!   boundary planes through them, by the octahedron with f = 3 and 3
//!   points (108 points on a half). Test radius by eq. (12) with α = 0.9.
//! - **Time step** ([`step`]): eq. (15) with `ω_max = 1.52 c_p / d_min`,
//!   the factor from power iteration on the elastic operator (1.95 for the
//!   nodal Galerkin form, whose operator is stiffer at the top).
//!
//! The pieces together integrate a free elastic bar's fundamental mode to
//! within 0.8 % (2 rings) and 0.2 % (3 rings) of its period
//! (`tests/suite/mlpg.rs`), but the plain scheme is not stable over long runs:
//! see [`sphere::ALPHA`]. The time loops with materials, the contact
//! and the scenes are the solvers' (`src/solver/`), built on these pieces;
//! nothing here imports a solver, a material or a scene.

pub(crate) mod buffers;
pub mod conform;
mod conform_levels;
pub mod lattice;
#[cfg(test)]
mod measure;
pub mod mirror;
pub mod mls;
pub mod msph;
pub mod nodal;
pub mod sphere;
pub mod step;
pub(crate) mod sums;
pub mod weak;
