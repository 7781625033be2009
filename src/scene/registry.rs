//! The scene registry: one row per kind of scene. The CLI, TOML scene files,
//! the C ABI, the FMU glue and `cargo xtask fmu` read it, so a new kind of
//! scene is one new row (in its own module) plus its solver.

use super::SceneKind;
pub use super::row::{FmuIdentity, SceneRow};
use crate::error::{Error, Result};

/// Every FMU the registry declares, with the kind of scene (material choice
/// included) each one runs, in registry order.
pub fn fmus() -> Vec<(SceneKind, FmuIdentity)> {
    let mut out = Vec::new();
    for row in SCENES {
        let kind = SceneKind::default_of_row(row);
        if let Some(id) = row.fmu {
            out.push((kind, id));
        }
        for (choice, id) in row.material.iter().flat_map(|m| m.fmus) {
            let kind = kind
                .with_material(*choice)
                .expect("a row's FMU choices are its own");
            out.push((kind, *id));
        }
    }
    out
}

/// Every kind of scene, in the order they are listed.
pub static SCENES: &[&SceneRow] = &[
    &super::taylor::ROW,
    &super::noh::ROW,
    &super::taylor3d::ROW,
    &super::penetration::ROW,
    &super::plate_impact::ROW,
];

/// The row called `name`.
pub fn row(name: &str) -> Result<&'static SceneRow> {
    SCENES
        .iter()
        .copied()
        .find(|r| r.name == name)
        .ok_or_else(|| Error::UnknownScene {
            name: name.to_string(),
            allowed: SCENES.iter().map(|r| r.name).collect::<Vec<_>>().join(", "),
        })
}
