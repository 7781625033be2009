//! Project tasks, run as `cargo xtask <task>`:
//!
//! - `header`: regenerate `include/meshless_impact.h` with cbindgen;
//! - `fmu`: build the release library (or the profile `MI_PROFILE` names)
//!   and package the FMI 3.0 and 2.0 FMUs into `target/fmu/`;
//! - `reference`: regenerate the reference pages of the user guide,
//!   `docs/reference/`, from the scene registry.

mod fmu;
mod fmu_package;
mod header;
mod reference;

use std::path::PathBuf;

/// The workspace root (the directory holding the main crate).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives in the workspace")
        .to_path_buf()
}

fn main() {
    let task = std::env::args().nth(1).unwrap_or_default();
    let result = match task.as_str() {
        "header" => header::run(),
        "fmu" => fmu::run(),
        "reference" => reference::run(),
        _ => Err(format!(
            "unknown task `{task}`; tasks: header, fmu, reference"
        )),
    };
    if let Err(e) = result {
        eprintln!("xtask {task}: {e}");
        std::process::exit(1);
    }
}
