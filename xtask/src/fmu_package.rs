//! The packaging of the FMUs (`cargo xtask fmu`, module docs of
//! `xtask/src/fmu.rs`): given a built library, the two archives of every FMU
//! the registry declares. Shared, by its path, with the example
//! `examples/package_fmus.rs`, which the test command builds with the tests
//! and runs instead of `cargo xtask fmu` (so that the library and its
//! dependencies are not built once more for xtask).

use meshless_impact::internals::fmi::model_description::{
    FmiVersion, escape, full_description, is_declared_unit, model_description,
};
use meshless_impact::internals::fmi::{Fmu, LOG_CATEGORIES, VarKind, VarType};
use std::io::Write;
use std::path::Path;
use zip::write::SimpleFileOptions;

/// Packages the library `lib` (the cdylib) as the FMUs of the registry into
/// `out_dir`, with the documentation and licence of the workspace `root`.
pub fn package(root: &Path, lib: &Path, out_dir: &Path) -> Result<(), String> {
    if !(cfg!(target_os = "linux") && cfg!(target_arch = "x86_64")) {
        return Err("packaging is implemented for x86_64 Linux only".into());
    }
    let binary = std::fs::read(lib).map_err(|e| format!("{}: {e}", lib.display()))?;
    std::fs::create_dir_all(out_dir).map_err(|e| format!("{}: {e}", out_dir.display()))?;

    let licence = read(&root.join("fmu").join("LICENSE.txt"))?;

    for (fmu, version, suffix, platform) in Fmu::all().into_iter().flat_map(|fmu| {
        [
            (fmu, FmiVersion::Fmi3, "", "x86_64-linux"),
            (fmu, FmiVersion::Fmi2, "_fmi2", "linux64"),
        ]
    }) {
        let id = fmu.identity().model_identifier;
        let docs = documentation(root, fmu)?;
        let md = model_description(fmu, version)?;
        let path = out_dir.join(format!("{id}{suffix}.fmu"));
        let entries: Vec<(String, &[u8])> = vec![
            ("modelDescription.xml".into(), md.as_bytes()),
            (format!("binaries/{platform}/{id}.so"), &binary),
            ("documentation/index.html".into(), docs.as_bytes()),
            (
                "documentation/licenses/LICENSE.txt".into(),
                licence.as_bytes(),
            ),
        ];
        write_zip(&path, &entries)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

fn read(path: &Path) -> Result<String, String> {
    std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))
}

/// Writes a zip with fixed timestamps, so the archive depends only on its
/// contents; the file is written whole (an FMU half written is never
/// there: `meshless_impact::files::write_whole`).
fn write_zip(path: &Path, entries: &[(String, &[u8])]) -> Result<(), String> {
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .last_modified_time(zip::DateTime::default())
        .unix_permissions(0o644);
    for (name, data) in entries {
        zip.start_file(name.as_str(), options)
            .map_err(|e| format!("{name}: {e}"))?;
        zip.write_all(data).map_err(|e| format!("{name}: {e}"))?;
    }
    let bytes = zip
        .finish()
        .map_err(|e| format!("{}: {e}", path.display()))?
        .into_inner();
    meshless_impact::files::write_whole_bytes(path, &bytes).map_err(|e| e.to_string())
}

/// `documentation/index.html` of `fmu`: the template `fmu/index.html` with
/// the FMU's variable table, the log categories, its token, and the parts
/// of its scene's page `fmu/<scene>.html` (what it models, the model, the
/// validation summary) filled in.
fn documentation(root: &Path, fmu: Fmu) -> Result<String, String> {
    let template = read(&root.join("fmu").join("index.html"))?;
    let scene = fmu.row().name;
    let page_path = root.join("fmu").join(format!("{scene}.html"));
    let page = read(&page_path)?;
    let [what, model, summary] =
        scene_page(&page).ok_or_else(|| format!("{}: {SCENE_PAGE_FORMAT}", page_path.display()))?;
    let mut rows = String::new();
    for v in fmu.variables() {
        let (causality, ty) = match (v.kind, v.ty) {
            (VarKind::Time, _) => ("independent (FMI 3 only)", "Float64"),
            (VarKind::Parameter(_), VarType::Int32) => ("parameter, fixed", "Int32 / Integer"),
            (VarKind::Parameter(_), _) => ("parameter, fixed", "Float64 / Real"),
            (VarKind::Output(..), VarType::Boolean) => ("output", "Boolean"),
            (VarKind::Output(..), _) => ("output", "Float64 / Real"),
        };
        let start = match v.kind {
            VarKind::Parameter(p) if v.ty == VarType::Int32 => format!("{}", p.default as i64),
            VarKind::Parameter(p) => format!("{:?}", p.default),
            _ => String::new(),
        };
        let unit = match v.unit() {
            u if is_declared_unit(u) => u,
            _ => "",
        };
        rows.push_str(&format!(
            "<tr><td>{}</td><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
            v.vr,
            v.name,
            causality,
            ty,
            escape(unit),
            start,
            escape(&full_description(&v))
        ));
    }
    let categories: String = LOG_CATEGORIES
        .iter()
        .map(|(n, d)| format!("<li><code>{n}</code>: {}</li>\n", escape(d)))
        .collect();
    let validation_path = root.join("VALIDATION.md");
    let validation = if validation_path.exists() {
        format!(
            "<p>The full validation record (<code>VALIDATION.md</code> of the source repository) follows.</p>\n<pre>{}</pre>",
            escape(&read(&validation_path)?)
        )
    } else {
        String::new()
    };
    let mut out = template;
    for (key, value) in [
        ("{{MODEL_IDENTIFIER}}", fmu.identity().model_identifier),
        ("{{WHAT}}", what),
        ("{{MODEL}}", model),
        ("{{SCENE}}", scene),
        ("{{SUMMARY}}", summary),
        ("{{VARIABLES}}", rows.as_str()),
        ("{{LOG_CATEGORIES}}", categories.as_str()),
        ("{{TOKEN}}", fmu.token().as_str()),
        ("{{VERSION}}", meshless_impact::VERSION),
        ("{{VALIDATION_RECORD}}", validation.as_str()),
    ] {
        if !out.contains(key) {
            return Err(format!("fmu/index.html lacks the placeholder {key}"));
        }
        out = out.replace(key, value);
    }
    Ok(out)
}

/// What a scene's page `fmu/<scene>.html` holds.
const SCENE_PAGE_FORMAT: &str = "expected three parts, each after its marker line: \
                                 `<!-- what -->` (what the FMU models, a phrase), \
                                 `<!-- model -->` (the model section), \
                                 `<!-- validation -->` (the validation summary)";

/// The three parts of a scene's page: what it models (trimmed), the model
/// section and the validation summary; `None` unless the page is the three
/// marker lines in order, each followed by its part.
fn scene_page(page: &str) -> Option<[&str; 3]> {
    let rest = page.strip_prefix("<!-- what -->\n")?;
    let (what, rest) = rest.split_once("<!-- model -->\n")?;
    let (model, summary) = rest.split_once("<!-- validation -->\n")?;
    Some([what.trim(), model, summary])
}
