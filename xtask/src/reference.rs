//! `cargo xtask reference`: regenerate the reference pages of the user
//! guide, `docs/reference/README.md` and `docs/reference/SCENE.md` for every
//! built-in scene, from the scene registry
//! (`meshless_impact::reference`, the renderer of `meshless-impact
//! params SCENE --markdown`). Pages of scenes that no longer exist are
//! removed. `tests/suite/reference.rs` renders them the same way and fails when a
//! committed page differs.

use meshless_impact::reference::{DIR, files};
use std::collections::BTreeSet;

/// Regenerates `docs/reference/`.
pub fn run() -> Result<(), String> {
    let dir = crate::root().join(DIR);
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let files = files().map_err(|e| e.to_string())?;
    let names: BTreeSet<&str> = files.iter().map(|(name, _)| name.as_str()).collect();
    for entry in std::fs::read_dir(&dir).map_err(|e| format!("{}: {e}", dir.display()))? {
        let path = entry.map_err(|e| e.to_string())?.path();
        let stale = path.extension().is_some_and(|x| x == "md")
            && path
                .file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| !names.contains(n));
        if stale {
            std::fs::remove_file(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            println!("removed {}", path.display());
        }
    }
    for (name, text) in &files {
        let path = dir.join(name);
        meshless_impact::files::write_whole_bytes(&path, text.as_bytes())
            .map_err(|e| e.to_string())?;
    }
    println!("wrote {} files to {}", files.len(), dir.display());
    Ok(())
}
