//! RON parsing of pipeline files with compiler-style errors: `file:line:col: message`, the
//! offending line with a caret, and a hint. Range checks run inside deserialisation so that an
//! out-of-range knob is reported at its own position.

use super::Pipeline;
use crate::error::ron_located::{located, RonFormat};
use crate::error::{IoContext, Result};
use ron::extensions::Extensions;
use std::path::Path;

/// Stage names that belong to relume's design but are not implemented by this version. A
/// pipeline naming one is rejected as "not yet supported", never silently ignored.
pub const PLANNED_STAGES: &[&str] = &["SoftShadow", "Freeform", "Atmosphere"];

const PIPELINE_FORMAT: RonFormat = RonFormat {
    reference: "the pipeline reference in README.md",
    planned: PLANNED_STAGES,
    variant_word: "stage",
    variant_enum: "Stage",
};

/// Read and validate a pipeline file. Input paths are resolved against the file's directory.
pub fn parse_pipeline(path: &Path) -> Result<Pipeline> {
    let text = std::fs::read_to_string(path).at(path, "cannot read pipeline")?;
    let mut pipeline = parse_str(path, &text)?;
    let base = path.parent().unwrap_or(Path::new("."));
    pipeline.input.resolve(base);
    for stage in &mut pipeline.stages {
        if let super::Stage::Themes(k) = stage {
            if k.file.is_relative() {
                k.file = base.join(&k.file);
            }
        }
    }
    super::stage::check_order(path, &pipeline)?;
    Ok(pipeline)
}

/// Parse pipeline text; `path` is only used in messages.
pub fn parse_str(path: &Path, text: &str) -> Result<Pipeline> {
    let options = ron::Options::default()
        .with_default_extension(Extensions::IMPLICIT_SOME | Extensions::UNWRAP_VARIANT_NEWTYPES);
    options
        .from_str::<Pipeline>(text)
        .map_err(|e| located(path, text, e, &PIPELINE_FORMAT))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_carry_line_and_column() {
        let text = "Pipeline(\n  input: Scene(path: \"a.obj\", scale: -1.0),\n)";
        let e = parse_str(Path::new("p.ron"), text).unwrap_err().to_string();
        assert!(e.starts_with("p.ron:2:"), "{e}");
        assert!(e.contains("out of range"), "{e}");
    }
}
