//! `cargo xtask header`: regenerate the C header (issue: C ABI).

/// Regenerates `include/meshless_impact.h`.
pub fn run() -> Result<(), String> {
    Err("not implemented yet".into())
}
