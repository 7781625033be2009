//! `cargo xtask fmu`: package the FMUs (issue: FMI Co-Simulation FMUs).

/// Builds and packages the FMUs into `target/fmu/`.
pub fn run() -> Result<(), String> {
    Err("not implemented yet".into())
}
