//! # meshless-impact
//!
//! A meshless particle solver for high-speed impact of solids. This release
//! implements the axisymmetric Modified SPH (MSPH) method of Batra & Zhang
//! (2008): the Taylor rod impact test with Johnson-Cook thermo-viscoplasticity,
//! and the cylindrical Noh problem.
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
#![deny(unsafe_code)]
#![warn(missing_docs)]
// Index loops over fixed-size arrays read more clearly in numerical kernels.
#![allow(clippy::needless_range_loop)]

// The C ABI and the FMI glue are the only places with unsafe code.
#[allow(unsafe_code)]
pub mod capi;
pub mod error;
#[allow(unsafe_code)]
pub mod fmi;
pub mod isa;
pub mod kernel;
pub mod lanes;
pub mod material;
pub mod mlpg;
pub mod model;
pub mod msph;
pub mod neighbors;
pub mod observe;
pub mod report;
pub mod rod;
pub mod scene;
mod sim;
pub mod solver;
pub mod uniaxial;

pub use error::{Error, Result};
pub use isa::Isa;
pub use model::{Model, ModelState};
pub use observe::{Field, History, NOH_OBSERVABLES, ObservableSpec, Snapshot, TAYLOR_OBSERVABLES};
pub use scene::params::{ParamSpec, Range};
pub use scene::table1::Table1Row;
pub use scene::{Scene, SceneKind};
pub use sim::{Progress, Simulation};

/// The library version (the crate version).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
