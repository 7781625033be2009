//! The integration tests, one test crate: one binary to build and link, whose
//! tests the harness runs side by side across the files.
//!
//! Each module is the file of one subject (`cargo test --test suite golden::`
//! runs one file, `cargo test --test suite NAME` one test). Three tests stay
//! crates of their own, because each installs something for the whole
//! process that would see the other tests' work: `tests/boundary.rs` and
//! `tests/mlpg_alloc.rs` a counting global allocator, `tests/fuzz.rs` a panic
//! hook that counts every panic.

mod calibrate;
mod capi;
mod checkpoint;
mod cli;
mod common;
mod golden;
mod materials;
mod mlpg;
mod mlpg_solver;
mod noh;
mod penetration;
mod plate_impact;
mod ranges;
mod reference;
#[cfg(feature = "report")]
mod report;
mod state;
mod state_files;
mod taylor;
mod taylor3d;
mod vtu;
