//! Packages the FMUs from the library a build has made, as `cargo xtask fmu`
//! does but without building: the test command builds this with its tests
//! (`cargo build --profile ci --example package_fmus`, sharing their build of
//! the library) and runs it instead of `cargo xtask fmu`, which would build
//! the library and every dependency once more for xtask. The packaging is
//! xtask's own code (`xtask/src/fmu_package.rs`), included by its path.
//!
//! Reads the library of the profile `MI_PROFILE` names (default `release`)
//! under `CARGO_TARGET_DIR` (default `target/`) and writes `target/fmu/`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[path = "../xtask/src/fmu_package.rs"]
mod fmu_package;

fn main() -> ExitCode {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let profile = std::env::var("MI_PROFILE").unwrap_or_else(|_| "release".into());
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"));
    let lib = target.join(&profile).join("libmeshless_impact.so");
    match fmu_package::package(root, &lib, &target.join("fmu")) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("package_fmus: {e}");
            ExitCode::FAILURE
        }
    }
}
