//! Lists in the C header's comments that are generated from the library's
//! own tables, so that they cannot drift: the built-in scenes (from the
//! scene registry) and the stops of a run (from the table of result codes).
//!
//! A doc comment in `src/capi/` carries a placeholder alone on a line,
//! [`SCENES`] or [`STOPS`]; cbindgen copies it into the header as
//! ` * @SCENES@`, and [`expand_header`] replaces that line by the list, each
//! line with the placeholder's prefix. `cargo xtask header` writes the
//! expanded text, and `tests/suite/capi.rs` compares the committed header with it.

use super::error::RESULTS;
use crate::scene::registry;

/// Placeholder for the list of built-in scenes (names and titles).
pub const SCENES: &str = "@SCENES@";

/// Placeholder for the list of the codes that stop a run (names, values and
/// meanings).
pub const STOPS: &str = "@STOPS@";

/// The result codes that stop a run: the block 20 to 29 of
/// [`mi_result`](super::mi_result)
/// (solver stops and `MI_CANCELLED`), which holds nothing else.
pub const STOP_CODES: std::ops::Range<i32> = 20..30;

/// Width of the header's lines (`line_length` of `cbindgen.toml`).
const WIDTH: usize = 100;

/// The header text `text` (cbindgen's output) with every placeholder line
/// replaced by its list. A line holds a placeholder when, after its comment
/// prefix (spaces and `*` or `/`), the placeholder is all that is left.
pub fn expand_header(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 4096);
    for line in text.split_inclusive('\n') {
        let body = line.trim_end_matches(['\n', '\r']);
        let rest = body.trim_start_matches([' ', '\t', '*', '/']);
        let prefix = &body[..body.len() - rest.len()];
        let items = match rest.trim_end() {
            SCENES => scene_items(),
            STOPS => stop_items(),
            _ => {
                out.push_str(line);
                continue;
            }
        };
        for (head, text) in items {
            wrap(&mut out, prefix, &head, &text);
        }
    }
    out
}

/// The built-in scenes as list items, `(head, text)`: each scene kind of
/// the registry, followed by its named variants one level down.
pub fn scene_items() -> Vec<(String, String)> {
    let mut items = Vec::new();
    for row in registry::SCENES {
        items.push((format!("- `\"{}\"`:", row.name), row.title.to_string()));
        for (name, scene) in (row.variants)() {
            items.push((format!("  - `\"{name}\"`:"), scene.title));
        }
    }
    items
}

/// The codes that stop a run ([`STOP_CODES`]) as list items, `(head, text)`,
/// with the meaning that `mi_result_description` gives.
pub fn stop_items() -> Vec<(String, String)> {
    RESULTS
        .iter()
        .filter(|(code, _, _)| STOP_CODES.contains(&(*code as i32)))
        .map(|(code, name, desc)| {
            let head = format!("- `{}` ({}):", strip(name), *code as i32);
            (head, strip(desc).to_string())
        })
        .collect()
}

/// A name or meaning of [`RESULTS`] without its terminating NUL.
fn strip(s: &str) -> &str {
    s.trim_end_matches('\0')
}

/// Appends `head text` as lines of at most [`WIDTH`] characters (where the
/// words allow), each starting with `prefix`; continuation lines are
/// indented under the item's text. A `*/` in the text, which would end
/// the C comment, is written `* /`; an equation `a = b` stays on one line.
fn wrap(out: &mut String, prefix: &str, head: &str, text: &str) {
    let indent = " ".repeat(head.len() - head.trim_start().len() + 2);
    let mut line = format!("{prefix}{head}");
    let text = text.replace("*/", "* /");
    let mut words: Vec<String> = Vec::new();
    let mut glue = false;
    for word in text.split_whitespace() {
        match words.last_mut() {
            Some(last) if glue || word == "=" => {
                last.push(' ');
                last.push_str(word);
            }
            _ => words.push(word.to_string()),
        }
        glue = word == "=";
    }
    for word in &words {
        if line.chars().count() + 1 + word.chars().count() > WIDTH {
            out.push_str(&line);
            out.push('\n');
            line = format!("{prefix}{indent}{word}");
        } else {
            line.push(' ');
            line.push_str(word);
        }
    }
    out.push_str(&line);
    out.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::capi::mi_result;

    /// The text's words, comment prefixes dropped, joined by single spaces.
    fn flat(text: &str) -> String {
        let words = text
            .lines()
            .flat_map(|l| l.trim_start_matches([' ', '*']).split_whitespace());
        words.collect::<Vec<_>>().join(" ")
    }

    const SAMPLE: &str =
        "/**\n * Scenes:\n *\n * @SCENES@\n *\n * Stops:\n * @STOPS@\n */\nint f(void);\n";

    #[test]
    fn lists_every_builtin_scene_and_every_stop_code() {
        let text = expand_header(SAMPLE);
        let listed = flat(&text);
        assert!(!text.contains(SCENES) && !text.contains(STOPS), "{text}");
        // Every built-in scene, with its title: a registry row's own name,
        // or a variant of a row.
        let names = crate::scene::builtin_names();
        assert!(names.len() >= 16, "{names:?}");
        for name in &names {
            let title = crate::scene::Scene::builtin(name).unwrap().title;
            let item = flat(&format!("- `\"{name}\"`: {title}"));
            assert!(
                listed.contains(&item),
                "{name} with its title is not listed:\n{text}"
            );
        }
        // Every code of the stop block with its value and meaning, and no
        // other code.
        let mut stops = 0;
        for (code, name, desc) in RESULTS {
            let head = format!("`{}` ({}):", strip(name), *code as i32);
            let is_stop = STOP_CODES.contains(&(*code as i32));
            assert_eq!(listed.contains(&head), is_stop, "{head}\n{text}");
            if is_stop {
                stops += 1;
                assert!(listed.contains(&flat(&format!("{head} {}", strip(desc)))));
            }
        }
        assert_eq!(
            stops,
            text.lines().filter(|l| l.starts_with(" * - `MI_")).count()
        );
        // The stops of the solver that the error conversion knows, and the
        // cancel: each one's code lies in the block.
        for code in [
            mi_result::MI_SINGULAR_MOMENT_MATRIX,
            mi_result::MI_NON_FINITE,
            mi_result::MI_THROUGH_BOUNDARY,
            mi_result::MI_TIME_STEP_COLLAPSE,
            mi_result::MI_ENERGY_DRIFT,
            mi_result::MI_CANCELLED,
            mi_result::MI_SPACING_COLLAPSE,
            mi_result::MI_COMPRESSION_LIMIT,
        ] {
            assert!(
                listed.contains(&format!("`{code:?}` ({}):", code as i32)),
                "{code:?}"
            );
        }
        // The rest of the text is untouched; list lines keep the
        // placeholder's prefix and the header's width.
        assert!(text.starts_with("/**\n * Scenes:\n *\n * - `\"taylor\"`: "));
        assert!(listed.contains("Stops: - `MI_SINGULAR_MOMENT_MATRIX` (20):"));
        assert!(text.ends_with(" */\nint f(void);\n"));
        for line in text.lines().skip(1).take_while(|l| *l != " */") {
            assert!(line == " *" || line.starts_with(" * "), "{line:?}");
            assert!(line.chars().count() <= WIDTH, "{line:?}");
        }
    }

    #[test]
    fn wraps_at_the_width_and_keeps_equations_whole() {
        let mut out = String::new();
        let text = "word ".repeat(30) + "a = b and V = 285 m/s";
        wrap(&mut out, " * ", "- `x`:", &text);
        let lines: Vec<&str> = out.lines().collect();
        assert!(
            lines.len() == 2 && lines[1].starts_with(" *   word"),
            "{out}"
        );
        assert!(lines.iter().all(|l| l.chars().count() <= WIDTH), "{out}");
        assert_eq!(flat(&out), flat(&format!("- `x`: {text}")));
        let mut out = String::new();
        wrap(&mut out, " * ", "-", &("x ".repeat(45) + "V = 285"));
        assert!(out.ends_with("\n *   V = 285\n"), "{out}");
    }

    #[test]
    fn text_without_placeholders_is_unchanged() {
        let text = "/**\n * @SCENES@ inside a sentence\n */\r\nint g(void);";
        assert_eq!(expand_header(text), text);
    }
}
