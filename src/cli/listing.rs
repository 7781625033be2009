//! The listing commands: `params`, `observables`, `scene`, `scenes` and
//! `materials`.

use super::args::ChoiceArgs;
use super::stop::{Stop, outln};
use meshless_impact::Scene;
use std::io::Write;

/// `meshless-impact params`: the parameter table of a scene, or with
/// `markdown` its reference page (`docs/reference/SCENE.md`).
pub(crate) fn params(scene: &str, material: &ChoiceArgs, markdown: bool) -> Result<(), Stop> {
    use meshless_impact::reference;
    let mut s = Scene::builtin(scene)?;
    material.apply(&mut s)?;
    if markdown {
        let page = reference::page(scene, &s)?;
        return write!(std::io::stdout(), "{page}").map_err(|e| Stop::write("stdout", e));
    }
    outln!(
        "{:<24} {:<10} {:>12}  {:<28} meaning",
        "name",
        "unit",
        "default",
        "allowed"
    )?;
    for p in s.param_specs() {
        let (value, allowed) = reference::value_and_allowed(p, s.get(p.name)?);
        outln!(
            "{:<24} {:<10} {:>12}  {:<28} {}",
            p.name,
            p.unit,
            value,
            allowed,
            p.description
        )?;
    }
    for p in s.param_specs().iter().filter(|p| !p.levels.is_empty()) {
        let flag = if p.name == "scheme" {
            "--scheme NAME, ".to_string()
        } else {
            String::new()
        };
        let sets = p.levels.iter().any(|l| !l.sets.is_empty());
        outln!(
            "\n{} ({flag}--set {}=NAME, or `{} = \"NAME\"` in a scene file's [parameters]){}:",
            p.name,
            p.name,
            p.name,
            if sets { "; each sets" } else { "" }
        )?;
        let chosen = s.level(p.name)?.map(|l| l.name);
        for level in p.levels {
            let sets: Vec<String> = level
                .sets
                .iter()
                .map(|(n, x)| format!("{n} = {x}"))
                .collect();
            let mark = if Some(level.name) == chosen {
                " (chosen)"
            } else {
                ""
            };
            outln!("  {}{mark}: {}", level.name, level.description)?;
            if !sets.is_empty() {
                outln!("      {}", sets.join(", "))?;
            }
        }
    }
    Ok(())
}

/// `meshless-impact scene NAME`: a built-in scene, with the material
/// choices, as a TOML scene file.
pub(crate) fn scene(name: &str, material: &ChoiceArgs) -> Result<(), Stop> {
    let mut scene = Scene::builtin(name)?;
    material.apply(&mut scene)?;
    let toml = scene.to_toml();
    write!(std::io::stdout(), "{toml}").map_err(|e| Stop::write("stdout", e))
}

pub(crate) fn scenes() -> Result<(), Stop> {
    let names = meshless_impact::builtin_names();
    let width = names.iter().map(|n| n.len()).max().unwrap_or(0);
    for name in names {
        outln!("{:<width$} {}", name, Scene::builtin(&name)?.title)?;
    }
    Ok(())
}

pub(crate) fn materials() -> Result<(), Stop> {
    use meshless_impact::materials::{PRESETS, Prefix};
    for p in PRESETS {
        outln!("{:<24} {}", p.name, p.choice)?;
        let values: Vec<String> = p
            .choice
            .param_specs(Prefix::None)
            .iter()
            .map(|spec| {
                let v = p
                    .value(spec.name)
                    .expect("a preset gives every parameter of its models");
                let unit = if spec.unit == "1" { "" } else { spec.unit };
                if v.abs() >= 1e5 {
                    format!("{} = {v:.4e} {unit}", spec.name)
                } else {
                    format!("{} = {v} {unit}", spec.name)
                }
            })
            .collect();
        for chunk in values.chunks(4) {
            outln!("    {}", chunk.join(", "))?;
        }
        outln!("    source: {}", p.source)?;
    }
    outln!("(values rounded; `meshless-impact params --preset NAME` prints them in full)")?;
    Ok(())
}

pub(crate) fn observables(scene: &str) -> Result<(), Stop> {
    let s = Scene::builtin(scene)?;
    for o in s.kind().observable_specs() {
        outln!("{:<24} {:<6} {}", o.name, o.unit, o.description)?;
    }
    Ok(())
}
