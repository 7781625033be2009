//! FMI 3.0 and FMI 2.0 Co-Simulation glue over the same core: one FMU per
//! kind of scene that the registry declares an FMU identity for
//! ([`crate::scene::registry::FmuIdentity`]; today `TaylorImpact`, the
//! `taylor` scene, and one FMU per other material choice of it:
//! `TaylorImpactBilinear`, `TaylorImpactMieGruneisen`,
//! `TaylorImpactBilinearMieGruneisen`; `Taylor3dImpact`, the `taylor3d`
//! scene; `BallisticImpact`, the `penetration` scene). One library serves
//! every FMU: an instance takes the FMU whose instantiation token the host
//! gives.
//!
//! An FMU exposes its scene: every parameter of the row's table as a fixed
//! parameter, every observable as an output. [`Fmu::variables`] derives the
//! variable list (and so the value references) from those tables;
//! [`model_description`] writes the `modelDescription.xml` from the same
//! list, so the glue and the packaged FMU can never disagree.
//!
//! Layout, after the Reference-FMUs:
//!
//! - `fmu`: the FMU description, the variable table and the value
//!   references, the instantiation token;
//! - `instance`: the instance type shared by both standards, its states and
//!   the mask of allowed states per function, its life cycle, and the panic
//!   boundary around every call on it;
//! - `log`: the log categories and the host's logger;
//! - `state`: the FMU state, its bytes and their checks;
//! - `ops`: the operations (get/set with the checks of the host's arrays,
//!   step) written once;
//! - [`fmi3`] and [`fmi2`]: the exported C functions of each standard, thin
//!   wrappers that translate types and names.
//!
//! The pointer and panic helpers are the crate's, shared with the C ABI
//! ([`crate::ffi`]).
//!
//! There is no global state: every instance owns its scene, its simulation
//! and its logger, so instances run in parallel.

pub mod fmi2;
pub mod fmi3;
mod fmu;
mod instance;
mod log;
pub mod model_description;
mod ops;
mod state;

pub use fmu::{Fmu, VR_TIME, VarKind, VarType, Variable};
pub use log::LOG_CATEGORIES;

/// The Taylor FMU, for the tests of this module and its children.
#[cfg(test)]
pub(crate) fn taylor_fmu() -> Fmu {
    Fmu::named("TaylorImpact").expect("the registry declares the Taylor FMU")
}

/// The value reference of a variable of the Taylor FMU.
#[cfg(test)]
fn vr_of(name: &str) -> u32 {
    vr_in(taylor_fmu(), name)
}

/// The value reference of a variable of `fmu`.
#[cfg(test)]
fn vr_in(fmu: Fmu, name: &str) -> u32 {
    fmu.variables().iter().find(|v| v.name == name).unwrap().vr
}

/// A new instance of the Taylor FMU at 4 particles across the radius (cheap
/// steps).
#[cfg(test)]
fn coarse(standard: instance::Standard) -> instance::Instance {
    use instance::{Instance, Status};
    let mut inst = Instance::new(standard, taylor_fmu(), "t", log::LogSink::None, false);
    let pr = vr_of("particles_radial");
    assert_eq!(inst.set("set", &[pr], &[4.0], VarType::Int32), Status::Ok);
    inst
}
