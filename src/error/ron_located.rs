//! Compiler-style errors for RON files (pipelines, freeform scenes): `file:line:col: message`,
//! the offending line with a caret, and a hint naming where the format is documented.

use super::Error;

/// What a RON format tells its users when a file is wrong: where its reference lives and which
/// variant names belong to the design but are not implemented by this version.
pub struct RonFormat {
    /// Where the format is documented, e.g. "the pipeline reference in README.md".
    pub reference: &'static str,
    /// Names (of stages, say) that are planned but not supported: reported as "not yet
    /// supported" (exit code 6), never as unknown.
    pub planned: &'static [&'static str],
    /// What a top-level variant is called in messages ("stage", "shape").
    pub variant_word: &'static str,
    /// The enum whose variants are called `variant_word`.
    pub variant_enum: &'static str,
}

/// A located [`Error`] for a RON deserialisation failure of `text` (read from `path`).
pub fn located(
    path: &std::path::Path,
    text: &str,
    e: ron::error::SpannedError,
    format: &RonFormat,
) -> Error {
    use ron::Error as R;
    let pos = e.span.start;
    let (message, hint, unsupported) = match &e.code {
        R::NoSuchEnumVariant {
            found,
            outer,
            expected,
        } => {
            let is_stage = expected.contains(&format.variant_enum)
                || outer.as_deref() == Some(format.variant_enum);
            if format.planned.contains(&found.as_str()) && !expected.contains(&found.as_str()) {
                (
                    format!(
                        "{} `{found}` is not yet supported by relume {}",
                        format.variant_word,
                        env!("CARGO_PKG_VERSION")
                    ),
                    format!(
                        "remove this {}, or use a relume version that implements it",
                        format.variant_word
                    ),
                    true,
                )
            } else {
                let what = if is_stage {
                    format.variant_word
                } else {
                    "variant"
                };
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
            format!("see {}", format.reference),
            false,
        ),
        R::InvalidValueForType { expected, found } => (
            format!("wrong type: expected {expected}, found {found}"),
            format!("see {} for each field's type", format.reference),
            false,
        ),
        R::Message(m) => (
            m.clone(),
            format!("see {} for valid ranges", format.reference),
            false,
        ),
        other => {
            let m = other.to_string();
            match m.strip_prefix("Expected ") {
                Some(rest) => (
                    format!("wrong type or syntax: expected {rest}"),
                    format!(
                        "each field's type is in {}; strings need quotes, floats a digit",
                        format.reference
                    ),
                    false,
                ),
                None => (
                    m,
                    "check the RON syntax near this position".to_string(),
                    false,
                ),
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
}
