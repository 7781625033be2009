//! The reference pages of the user guide, `docs/reference/SCENE.md`: one
//! Markdown page per built-in scene (its parameters, observables and
//! particle fields), rendered from the scene registry and never written by
//! hand. `meshless-impact params SCENE --markdown` prints one page, `cargo
//! xtask reference` writes them all, and `tests/suite/reference.rs` fails when a
//! committed page differs from its rendering.

use super::Scene;
use super::params::ParamSpec;
use crate::error::Result;
use std::fmt::Write as _;

/// The directory of the pages, relative to the workspace root.
pub const DIR: &str = "docs/reference";

/// The file name of the index page.
pub const INDEX: &str = "README.md";

/// The text of a parameter's value and of its allowed values, as the
/// parameter tables print them (`meshless-impact params`): for a parameter
/// with named levels, the level's name and `0=NAME,1=NAME,...`; for a
/// number, the number and its range (`[0.01, 10000]`).
pub fn value_and_allowed(spec: &ParamSpec, value: f64) -> (String, String) {
    match spec.level(value) {
        Some(level) => (
            level.name.to_string(),
            spec.levels
                .iter()
                .enumerate()
                .map(|(k, l)| format!("{k}={}", l.name))
                .collect::<Vec<_>>()
                .join(","),
        ),
        None => (value.to_string(), spec.range.to_string()),
    }
}

/// `text` as the content of a Markdown table cell: the characters that
/// would end the cell or start markup (`|`, `*`, `<`, `\`) escaped, line
/// breaks made spaces.
pub fn cell(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '|' | '*' | '<' | '\\' => {
                out.push('\\');
                out.push(c);
            }
            '\n' | '\r' => out.push(' '),
            _ => out.push(c),
        }
    }
    out
}

/// `text` as inline code in a table cell (`|` escaped, as a table needs
/// even inside code).
fn code(text: &str) -> String {
    format!("`{}`", text.replace('|', "\\|"))
}

/// The page of the scene `scene`, called `name` (a built-in name, which
/// `meshless-impact params` takes): a title with the scene's title, its
/// material models where it has a choice of them, then the tables of its
/// parameters (with the values of `scene`), of the levels of each
/// parameter with named levels, of its observables and of its particle
/// fields. The fields are those of a run of `scene`, which is therefore
/// built (not run).
pub fn page(name: &str, scene: &Scene) -> Result<String> {
    let kind = scene.kind();
    let mut out = String::new();
    // Writing to a String cannot fail.
    let w = &mut out;
    let _ = writeln!(w, "# {name}\n\n{}\n", scene.title);
    let _ = writeln!(
        w,
        "<!-- Generated from the scene registry (`meshless-impact params {name} --markdown`); \
         do not edit: run `cargo xtask reference`. -->\n"
    );
    if kind.name() != name {
        let _ = writeln!(
            w,
            "A built-in variant of the scene `{}` (`scene = \"{}\"` in a scene file), with \
             its own parameter values.\n",
            kind.name(),
            kind.name()
        );
    }
    if let (Some(choice), Some(slot)) = (kind.material(), kind.row().material.as_ref()) {
        let which = if choice == slot.default {
            "the default choice".to_string()
        } else {
            format!("the default of `{}` is {}", kind.name(), slot.default)
        };
        let _ = writeln!(
            w,
            "Material models: {choice} ({which}); the parameter table lists only the \
             parameters these models use. `meshless-impact params {name} --preset NAME` \
             (or `--strength MODEL --eos EOS`) shows the table of another choice, and \
             `meshless-impact materials` lists the presets.\n"
        );
    }

    let _ = writeln!(w, "## Parameters\n");
    let _ = writeln!(w, "| name | unit | default | allowed | meaning |");
    let _ = writeln!(w, "|---|---|---|---|---|");
    for spec in scene.param_specs() {
        let (value, allowed) = value_and_allowed(spec, scene.get(spec.name)?);
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} | {} |",
            code(spec.name),
            cell(spec.unit),
            cell(&value),
            cell(&allowed),
            cell(spec.description)
        );
    }
    for spec in scene.param_specs().iter().filter(|p| !p.levels.is_empty()) {
        let flag = if spec.name == "scheme" {
            "`--scheme NAME`, "
        } else {
            ""
        };
        let sets = spec.levels.iter().any(|l| !l.sets.is_empty());
        let _ = writeln!(
            w,
            "\n### `{n}`\n\nChosen by name: {flag}`--set {n}=NAME`, or `{n} = \"NAME\"` in a \
             scene file's `[parameters]`.{}\n",
            if sets {
                " Each level sets other parameters; a value set by hand overrides it."
            } else {
                ""
            },
            n = spec.name,
        );
        let chosen = scene.level(spec.name)?.map(|l| l.name);
        if sets {
            let _ = writeln!(w, "| level | meaning | sets |\n|---|---|---|");
        } else {
            let _ = writeln!(w, "| level | meaning |\n|---|---|");
        }
        for level in spec.levels {
            let mark = if Some(level.name) == chosen {
                " (chosen)"
            } else {
                ""
            };
            let _ = write!(
                w,
                "| {}{mark} | {} |",
                code(level.name),
                cell(level.description)
            );
            if sets {
                let values: Vec<String> = level
                    .sets
                    .iter()
                    .map(|(n, x)| code(&format!("{n} = {x}")))
                    .collect();
                let _ = write!(w, " {} |", values.join(", "));
            }
            let _ = writeln!(w);
        }
    }

    let _ = writeln!(w, "\n## Observables\n");
    let _ = writeln!(w, "| name | unit | meaning |\n|---|---|---|");
    for o in kind.observable_specs() {
        let _ = writeln!(
            w,
            "| {} | {} | {} |",
            code(o.name),
            cell(o.unit),
            cell(o.description)
        );
    }

    let fields = scene.kind().field_specs();
    let _ = writeln!(w, "\n## Fields\n");
    let _ = writeln!(
        w,
        "Particle (node) fields of a run, as written to VTK snapshots (`--vtk-dir`) and read \
         through the C ABI (`mi_sim_field`).\n"
    );
    let _ = writeln!(w, "| name | unit | components |\n|---|---|---|");
    for f in fields {
        let components: Vec<String> = f.components.iter().map(|c| code(c)).collect();
        let _ = writeln!(
            w,
            "| {} | {} | {} |",
            code(f.name),
            cell(f.unit),
            components.join(", ")
        );
    }
    Ok(out)
}

/// The page of the built-in scene `name` ([`crate::builtin_names`]), with
/// its default material models and parameter values.
pub fn builtin_page(name: &str) -> Result<String> {
    page(name, &Scene::builtin(name)?)
}

/// The index page, `README.md`: one line per built-in scene, a link to its
/// page with its title.
pub fn index() -> Result<String> {
    let mut out = String::new();
    let w = &mut out;
    let _ = writeln!(w, "# Reference\n");
    let _ = writeln!(
        w,
        "<!-- Generated from the scene registry; do not edit: run `cargo xtask reference`. -->\n"
    );
    let _ = writeln!(
        w,
        "One page per built-in scene: its parameters (units, defaults, allowed values), \
         observables and particle fields. The pages are generated from the scene registry \
         (`cargo xtask reference`; `meshless-impact params SCENE --markdown` prints one), \
         and `tests/suite/reference.rs` fails when one is stale.\n"
    );
    for name in crate::builtin_names() {
        let title = Scene::builtin(&name)?.title;
        let _ = writeln!(w, "- [`{name}`]({name}.md): {title}");
    }
    Ok(out)
}

/// Every file of [`DIR`]: its name and text, the index ([`INDEX`]) first,
/// then `SCENE.md` for each built-in scene in [`crate::builtin_names`]
/// order.
pub fn files() -> Result<Vec<(String, String)>> {
    let mut out = vec![(INDEX.to_string(), index()?)];
    for name in crate::builtin_names() {
        out.push((format!("{name}.md"), builtin_page(&name)?));
    }
    Ok(out)
}
