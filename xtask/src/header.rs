//! `cargo xtask header`: regenerate the C header `include/meshless_impact.h`
//! from `src/capi/` with the settings of `cbindgen.toml`, then fill in the
//! lists that come from the library's tables (the built-in scenes, the stop
//! codes: `meshless_impact::internals::capi::expand_header`). `tests/suite/capi.rs`
//! generates it the same way and fails when the committed file differs.

use meshless_impact::internals::capi::expand_header;

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
    let mut text = Vec::new();
    bindings.write(&mut text);
    let text = String::from_utf8(text).map_err(|e| format!("cbindgen's output: {e}"))?;
    let out = root.join("include/meshless_impact.h");
    std::fs::create_dir_all(root.join("include")).map_err(|e| e.to_string())?;
    meshless_impact::files::write_whole_bytes(&out, expand_header(&text).as_bytes())
        .map_err(|e| e.to_string())?;
    println!("wrote {}", out.display());
    Ok(())
}
