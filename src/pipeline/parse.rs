//! RON parsing of pipeline files with compiler-style errors: `file:line:col: message`, the
//! offending line with a caret, and a hint. Range checks run inside deserialisation so that an
//! out-of-range knob is reported at its own position.

use super::Pipeline;
use crate::error::{Error, IoContext, Result};
use ron::extensions::Extensions;
use std::path::Path;

/// Stage names that belong to relume's design but are not implemented by this version. A
/// pipeline naming one is rejected as "not yet supported", never silently ignored.
pub const PLANNED_STAGES: &[&str] = &["SoftShadow", "Freeform", "Theme", "Atmosphere"];

/// Read and validate a pipeline file. Input paths are resolved against the file's directory.
pub fn parse_pipeline(path: &Path) -> Result<Pipeline> {
    let text = std::fs::read_to_string(path).at(path, "cannot read pipeline")?;
    let mut pipeline = parse_str(path, &text)?;
    let base = path.parent().unwrap_or(Path::new("."));
    pipeline.input.resolve(base);
    super::stage::check_order(path, &pipeline)?;
    Ok(pipeline)
}

/// Parse pipeline text; `path` is only used in messages.
pub fn parse_str(path: &Path, text: &str) -> Result<Pipeline> {
    let options = ron::Options::default()
        .with_default_extension(Extensions::IMPLICIT_SOME | Extensions::UNWRAP_VARIANT_NEWTYPES);
    options
        .from_str::<Pipeline>(text)
        .map_err(|e| describe(path, text, e))
}

fn describe(path: &Path, text: &str, e: ron::error::SpannedError) -> Error {
    use ron::Error as R;
    let pos = e.span.start;
    let (message, hint, unsupported) = match &e.code {
        R::NoSuchEnumVariant {
            found,
            outer,
            expected,
        } => {
            let is_stage = expected.contains(&"Stage") || outer.as_deref() == Some("Stage");
            if PLANNED_STAGES.contains(&found.as_str()) && !expected.contains(&found.as_str()) {
                (
                    format!(
                        "stage `{found}` is not yet supported by relume {}",
                        env!("CARGO_PKG_VERSION")
                    ),
                    "remove it from `stages`, or use a relume version that implements it"
                        .to_string(),
                    true,
                )
            } else {
                let what = if is_stage { "stage" } else { "variant" };
                (
                    format!(
                        "unknown {what} `{found}`{}",
                        outer
                            .as_ref()
                            .map(|o| format!(" in `{o}`"))
                            .unwrap_or_default()
                    ),
                    format!("expected one of: {}", list(expected)),
                    false,
                )
            }
        }
        R::NoSuchStructField {
            found,
            outer,
            expected,
        } => (
            format!(
                "unknown field `{found}`{}",
                outer
                    .as_ref()
                    .map(|o| format!(" in `{o}`"))
                    .unwrap_or_default()
            ),
            match closest(found, expected) {
                Some(c) => format!("did you mean `{c}`? expected one of: {}", list(expected)),
                None => format!("expected one of: {}", list(expected)),
            },
            false,
        ),
        R::MissingStructField { field, outer } => (
            format!(
                "missing field `{field}`{}",
                outer
                    .as_ref()
                    .map(|o| format!(" in `{o}`"))
                    .unwrap_or_default()
            ),
            "see the pipeline reference in README.md".to_string(),
            false,
        ),
        R::InvalidValueForType { expected, found } => (
            format!("wrong type: expected {expected}, found {found}"),
            "see the pipeline reference in README.md for each knob's type".to_string(),
            false,
        ),
        R::Message(m) => (
            m.clone(),
            "see the pipeline reference in README.md for valid ranges".to_string(),
            false,
        ),
        other => {
            let m = other.to_string();
            match m.strip_prefix("Expected ") {
                Some(rest) => (
                    format!("wrong type or syntax: expected {rest}"),
                    "each knob's type is in the pipeline reference (README.md); strings need quotes, floats a digit".to_string(),
                    false,
                ),
                None => (m, "check the RON syntax near this position".to_string(), false),
            }
        }
    };
    let snippet = text.lines().nth(pos.line.saturating_sub(1)).unwrap_or("");
    let caret = " ".repeat(pos.col.saturating_sub(1));
    let message = format!(
        "{message}\n{:>5} | {snippet}\n      | {caret}^\nhint: {hint}",
        pos.line
    );
    Error::Located {
        path: path.to_path_buf(),
        line: pos.line,
        col: pos.col,
        message,
        unsupported,
    }
}

fn list(names: &[&str]) -> String {
    names
        .iter()
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The expected name closest to `found` by edit distance, if it is close enough to be a typo.
fn closest<'a>(found: &str, expected: &[&'a str]) -> Option<&'a str> {
    fn distance(a: &str, b: &str) -> usize {
        let b: Vec<char> = b.chars().collect();
        let mut prev: Vec<usize> = (0..=b.len()).collect();
        for (i, ca) in a.chars().enumerate() {
            let mut cur = vec![i + 1];
            for (j, cb) in b.iter().enumerate() {
                cur.push(
                    (prev[j] + usize::from(ca != *cb))
                        .min(prev[j + 1] + 1)
                        .min(cur[j] + 1),
                );
            }
            prev = cur;
        }
        prev[b.len()]
    }
    expected
        .iter()
        .map(|e| (distance(found, e), *e))
        .filter(|(d, _)| *d <= 2.max(found.len() / 3))
        .min()
        .map(|(_, e)| e)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn typo_hint_names_the_closest_field() {
        assert_eq!(closest("scael", &["path", "scale"]), Some("scale"));
        assert_eq!(closest("zzzzzz", &["path", "scale"]), None);
    }

    #[test]
    fn errors_carry_line_and_column() {
        let text = "Pipeline(\n  input: Scene(path: \"a.obj\", scale: -1.0),\n)";
        let e = parse_str(Path::new("p.ron"), text).unwrap_err().to_string();
        assert!(e.starts_with("p.ron:2:"), "{e}");
        assert!(e.contains("out of range"), "{e}");
    }
}
