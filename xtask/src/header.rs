//! `cargo xtask header`: regenerate the C header `include/meshless_impact.h`
//! from `src/capi/` with the settings of `cbindgen.toml`. `tests/capi.rs`
//! generates it the same way and fails when the committed file differs.

/// Regenerates `include/meshless_impact.h`.
pub fn run() -> Result<(), String> {
    let root = crate::root();
    let config = cbindgen::Config::from_file(root.join("cbindgen.toml"))
        .map_err(|e| format!("cbindgen.toml: {e}"))?;
    let bindings = cbindgen::Builder::new()
        .with_config(config)
        .with_src(root.join("src/capi/mod.rs"))
        .generate()
        .map_err(|e| format!("cbindgen: {e}"))?;
    let out = root.join("include/meshless_impact.h");
    std::fs::create_dir_all(root.join("include")).map_err(|e| e.to_string())?;
    bindings.write_to_file(&out);
    println!("wrote {}", out.display());
    Ok(())
}
