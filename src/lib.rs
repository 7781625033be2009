//! # meshless-impact
//!
//! Meshless particle solvers for high-speed impact of solids: the
//! axisymmetric Modified SPH (MSPH) method of Batra & Zhang (2008) for the
//! Taylor rod impact test with Johnson-Cook thermo-viscoplasticity and the
//! cylindrical Noh problem (scenes `taylor`, `table1-1` ... `table1-12`,
//! `noh`); the 3-D MLPG mixed method of Han, Liu, Rajendran & Atluri for the
//! Taylor test in 3-D (`taylor3d`, `taylor3d-aisi310`) and a projectile
//! perforating a Rajendran-Grove ceramic plate (`penetration`); and plate
//! impact in uniaxial strain (`plate_impact`), the ceramic's calibration
//! experiment.
//!
//! ```no_run
//! use meshless_impact::{Scene, Simulation};
//! let mut scene = Scene::builtin("taylor")?;
//! scene.set("impact_speed", 200.0)?;
//! let mut sim = Simulation::new(scene)?;
//! sim.run()?;
//! println!("final length {} m", sim.observable("rod_length").unwrap());
//! # Ok::<(), meshless_impact::Error>(())
//! ```
//!
//! ## The public API
//!
//! The crate's modules are private: the API is what this page re-exports.
//!
//! - Running: [`Scene`] (a kind of scene, [`SceneKind`], with a value for
//!   each of its parameters), [`builtin_names`], [`Simulation`] and its
//!   [`Progress`], [`Isa`] (the compiled copy of the hot loops to use).
//! - Parameters: [`ParamSpec`], [`Range`] and [`Level`] (a named level of a scheme); typed views of a scene's
//!   parameters, [`TaylorParams`], [`NohParams`] and [`Taylor3dParams`];
//!   [`Table1Row`], a row of House et al.'s Table 1.
//! - Results: [`ObservableSpec`] (with the tables [`TAYLOR_OBSERVABLES`] and
//!   [`NOH_OBSERVABLES`]), [`History`], [`Snapshot`], [`Field`],
//!   [`FieldSpec`], [`write_pvd`]; a rod's outline
//!   ([`Simulation::rod_profile`]) read at a height ([`profile_radius`]) and
//!   compared with another ([`profile_deviation`]), as the 3-D Taylor run
//!   with its axisymmetric twin ([`axisymmetric_twin`]).
//! - Errors: [`Error`] (with [`MomentMethod`]) and [`Result`]; the memory
//!   budget a run is checked against before it allocates
//!   ([`memory_budget`], [`MEMORY_BUDGET_VAR`], [`DEFAULT_MEMORY_BUDGET`]).
//! - The interface every solver implements: [`Model`], [`ModelState`].
//! - Plate impact in uniaxial strain: [`PlateImpact`] of [`Layer`]s, its
//!   free-surface reading [`FreeSurfaceReading`], the tables
//!   [`PLATE_IMPACT_OBSERVABLES`] and [`PLATE_IMPACT_FIELDS`], and the floor
//!   of the log10 crack-density fields, [`LOG10_NO_CRACKS`].
//! - [`materials`]: the models a [`materials::Material`] is composed of
//!   (equation of state, strength, damage), their choice by name, the
//!   presets, and the Rajendran-Grove ceramic.
//! - [`VERSION`].
//!
//! The C ABI (`mi_*`, `include/meshless_impact.h`) and the FMI 3.0 / 2.0
//! functions are symbols of the `cdylib` and `staticlib`, not Rust API.
//!
//! The module `internals`, hidden from this documentation, re-exports what
//! the integration tests, the benchmarks and `xtask` reach inside the crate
//! for (the C ABI and the FMI glue as Rust functions, the kernel, the
//! neighbour search, MSPH and MLPG parts, solver constants). It is **not**
//! part of the public API and may change in any release.
//!
//! The verification report (`meshless-impact report`) belongs to the
//! program, not to the library. It and its plotting dependency are the cargo
//! feature `report`, on by default; a library user who wants no plotting
//! crates depends with `default-features = false` (the library's API is the
//! same either way).
#![deny(unsafe_code)]
#![warn(missing_docs)]
// Index loops over fixed-size arrays read more clearly in numerical kernels.
#![allow(clippy::needless_range_loop)]

mod approx;
mod budget;
pub mod calibrate;
pub mod checkpoint;
// Unsafe code is allowed in these places only: the C ABI, the FMI glue and
// the pointer and panic helpers they share (here), the dispatch to the
// compiled copies of the hot loops (`hot!` in src/isa.rs), the team of
// threads sharing disjoint chunks of the axisymmetric step's arrays
// (src/solver/axisymmetric/team.rs, and the chunk sets `named_parts!` declares), the
// AVX-512 kernels of its pair pass (src/solver/axisymmetric/pairs/avx512.rs) and the
// read of the stepping thread's processor time (src/solver/mlpg3d/profile.rs).
#[allow(unsafe_code)]
mod capi;
mod error;
#[allow(unsafe_code)]
mod ffi;
pub mod files;
#[allow(unsafe_code)]
mod fmi;
mod isa;
mod kernel;
mod lanes;
mod material;
mod model;
mod neighbours;
mod observe;
mod params;
pub mod ranks;
mod rod;
mod scene;
mod sim;
mod solver;
mod state_format;
#[cfg(test)]
mod test_dir;
#[cfg(test)]
mod test_rng;

pub use budget::{DEFAULT_MEMORY_BUDGET, MEMORY_BUDGET_VAR, MemoryPerNode, memory_budget};
pub use error::{Error, MomentMethod, Result};
pub use isa::Isa;
pub use model::{Model, ModelState, SavedSolver};
pub use observe::{
    Field, FieldSpec, History, LOG10_NO_CRACKS, NOH_OBSERVABLES, ObservableSpec,
    PLATE_IMPACT_OBSERVABLES, Snapshot, TAYLOR_OBSERVABLES, write_pvd,
};
pub use params::{Level, ParamSpec, Range};
pub use rod::{profile_deviation, profile_radius};
pub use scene::noh::NohParams;
pub use scene::reference;
pub use scene::table1::Table1Row;
pub use scene::taylor::TaylorParams;
pub use scene::taylor3d::{Taylor3dParams, axisymmetric_twin};
pub use scene::{Scene, SceneKind, builtin_names};
pub use sim::{Progress, Simulation};
pub use solver::shared::ENERGY_ERROR_BOUND;
pub use solver::uniaxial::{FreeSurfaceReading, Layer, PLATE_IMPACT_FIELDS, PlateImpact};
pub use state_format::FORMAT as STATE_FORMAT;

/// Material models and their composition into a [`Material`](materials::Material):
/// an equation of state ([`Eos`](materials::Eos)), a strength model
/// ([`Strength`](materials::Strength)) and a damage model
/// ([`Damage`](materials::Damage)); the models by name
/// ([`MaterialChoice`](materials::MaterialChoice)) and the named materials
/// ([`PRESETS`](materials::PRESETS)); the Rajendran-Grove ceramic at a
/// material point, with its state ([`CeramicPoint`](materials::CeramicPoint)),
/// and the parameter block of a ceramic plate
/// ([`PLATE_CERAMIC`](materials::PLATE_CERAMIC),
/// [`ceramic_material`](materials::ceramic_material)).
pub mod materials {
    pub use crate::material::bilinear::Bilinear;
    pub use crate::material::ceramic_block::{PLATE_CERAMIC, ceramic_material};
    pub use crate::material::choice::{EosKind, MaterialChoice, Prefix, StrengthKind};
    pub use crate::material::eos::LinearEos;
    pub use crate::material::ideal_gas::IdealGas;
    pub use crate::material::johnson_cook::JohnsonCook;
    pub use crate::material::johnson_holmquist::{Failure, Jh2, Jh2Point, JohnsonHolmquist};
    pub use crate::material::mie_gruneisen::{CompressionLimit, MieGruneisen};
    pub use crate::material::presets::{PRESETS, Preset};
    pub use crate::material::rajendran_grove::{CeramicPoint, Pulverized, RajendranGrove};
    pub use crate::material::tensile_cracks::{CrackPlanes, TensileCracks};
    pub use crate::material::{Damage, Eos, Material, Strength};
}

/// **Not part of the public API**, and may change in any release: what the
/// integration tests, the benchmarks and `xtask` reach inside the crate for.
#[doc(hidden)]
pub mod internals {
    /// The C ABI, as C calls it.
    pub mod capi {
        pub use crate::capi::*;
    }
    /// The FMI glue, as hosts call it, and the model description.
    pub mod fmi {
        pub use crate::fmi::*;
    }
    /// The 3-D MLPG method's parts.
    pub mod mlpg {
        pub use crate::approx::conform::Preconditioner;
        pub use crate::approx::lattice::{Cylinder, NodeLattice, Surfaces};
        pub use crate::approx::mls::distance;
        pub use crate::approx::mls::{NodalShapes, SupportParams, Supports};
        pub use crate::approx::nodal::NodalOperator;
        pub use crate::approx::sphere::{ALPHA, BOUNDARY_RULE, DEFAULT_RULE, test_radii};
        pub use crate::approx::sphere::{SphereRule, TestSphere};
        pub use crate::approx::step::{
            OMEGA_FACTOR, OMEGA_FACTOR_NODAL, largest_eigenvalue, stable_step, stable_step_with,
        };
        pub use crate::approx::weak::TractionOperator;
        pub use crate::approx::weak::VOIGT;
        pub use crate::scene::penetration::penetration;
        pub use crate::solver::mlpg3d::SMOOTHING;
        pub use crate::solver::mlpg3d::penetration::{Penetration, PenetrationSetup};
        pub use crate::solver::mlpg3d::scheme::{Forces, Lattice, MlpgScheme, SmoothingOrder};
        pub use crate::solver::mlpg3d::{Body, Mlpg3d, NodeOrder, RodSetup};
    }
    pub use crate::approx::msph::{Neighbourhood, Row2};
    pub use crate::kernel::kernel2;
    pub use crate::lanes::W;
    pub use crate::neighbours::{cell_list, naive, padded_rows};
    pub use crate::solver::axisymmetric::TaylorSolver;
    pub use crate::solver::shared::SPACING_COLLAPSE_BOUND;
}

/// The library version (the crate version).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
