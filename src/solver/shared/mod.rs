//! What every particle solver shares, written once: the clock
//! ([`Clock`]), the energy book ([`EnergyBook`]), the fields of a solid
//! run ([`SolidNodes`]), the guards of a run (energy drift, spacing
//! collapse, time-step collapse, the quiet end; `guards.rs`) and the checks
//! of a restored run (`restore.rs`). It imports nothing of a solver.

mod clock;
mod energy;
mod fields;
mod guards;
mod restore;

pub use clock::Clock;
pub(crate) use clock::clock_getters;
pub use energy::EnergyBook;
pub(crate) use fields::SolidNodes;
pub use guards::*;
pub(crate) use restore::*;
