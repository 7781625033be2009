//! The reference pages of the user guide, `docs/reference/`, are generated
//! from the scene registry (`cargo xtask reference`): each committed page is
//! byte for byte its rendering now, every built-in scene has one, and the
//! index lists them all.

use meshless_impact::reference::{DIR, INDEX, files};
use std::path::Path;

/// The directory of the pages in this checkout.
fn dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(DIR)
}

/// Every committed page, the index included, is exactly what the renderer
/// writes now; no page is missing, none is left over from a scene that no
/// longer exists.
#[test]
fn committed_pages_match_the_registry() {
    let files = files().unwrap();
    let mut stale = Vec::new();
    for (name, generated) in &files {
        let committed = std::fs::read_to_string(dir().join(name)).unwrap_or_default();
        if &committed != generated {
            stale.push(name.as_str());
        }
    }
    assert!(
        stale.is_empty(),
        "{DIR}/ is stale ({}): run `cargo xtask reference` and commit the pages",
        stale.join(", ")
    );
    let mut extra: Vec<String> = std::fs::read_dir(dir())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".md") && !files.iter().any(|(name, _)| name == n))
        .collect();
    extra.sort();
    assert!(
        extra.is_empty(),
        "{DIR}/ has pages of no built-in scene ({}): run `cargo xtask reference`",
        extra.join(", ")
    );
}

/// Every built-in scene has its page, titled with its name, and the index
/// links to it.
#[test]
fn every_scene_has_a_page_listed_in_the_index() {
    let files = files().unwrap();
    let index = &files.iter().find(|(n, _)| n == INDEX).unwrap().1;
    for name in meshless_impact::builtin_names() {
        let page = files
            .iter()
            .find(|(n, _)| *n == format!("{name}.md"))
            .map(|(_, text)| text)
            .unwrap_or_else(|| panic!("no page for scene `{name}`"));
        assert!(page.starts_with(&format!("# {name}\n")), "{name}");
        for section in ["## Parameters", "## Observables", "## Fields"] {
            assert!(
                page.contains(&format!("\n{section}\n")),
                "{name}: {section}"
            );
        }
        assert!(
            index.contains(&format!("- [`{name}`]({name}.md): ")),
            "the index does not list `{name}`"
        );
        assert!(
            dir().join(format!("{name}.md")).is_file(),
            "{DIR}/{name}.md"
        );
    }
    assert_eq!(files.len(), meshless_impact::builtin_names().len() + 1);
}

/// `meshless-impact params SCENE --markdown` prints the scene's page.
#[test]
fn the_cli_prints_the_page() {
    let page = meshless_impact::reference::builtin_page("penetration").unwrap();
    let out = crate::common::cli_stdout(["params", "penetration", "--markdown"]);
    assert_eq!(out, page);
}
