//! Writing a study: `study.json` (everything, for machines), `study.md` (a table per sweep with
//! ratios against the sweep's baseline, for people) and the PNG plots. Each file is written
//! atomically; the directory is created when missing.

use super::{plot, Column, Format, Setting, Study, Sweep};
use crate::baked::images::write_atomic;
use crate::error::{Error, IoContext, Result};
use std::fmt::Write as _;
use std::path::Path;

/// The JSON file of a study.
pub const JSON_FILE: &str = "study.json";
/// The Markdown file of a study.
pub const MARKDOWN_FILE: &str = "study.md";

/// Refuse an output path that exists and is not a directory, and create it otherwise (before
/// any work starts).
pub fn prepare_dir(dir: &Path) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        return Err(Error::io(
            dir,
            "cannot write the study here: the output path is a file, not a directory",
            std::io::Error::from(std::io::ErrorKind::AlreadyExists),
        ));
    }
    std::fs::create_dir_all(dir).at(dir, "cannot create the output directory")
}

/// Write the plots, `study.md` and `study.json` into `dir`; fills `study.files`.
pub fn write(study: &mut Study, dir: &Path) -> Result<()> {
    prepare_dir(dir)?;
    let mut files = Vec::new();
    for sweep in &study.sweeps {
        for spec in &sweep.plots {
            let img = plot::draw(spec, sweep);
            let path = dir.join(&spec.file);
            write_atomic(&path, |tmp| {
                img.save_with_format(tmp, image::ImageFormat::Png)
                    .map_err(|e| match e {
                        image::ImageError::IoError(io) => Error::io(tmp, "cannot write image", io),
                        other => Error::Internal(format!("cannot encode a plot: {other}")),
                    })
            })?;
            files.push(spec.file.clone());
        }
    }
    files.push(MARKDOWN_FILE.into());
    files.push(JSON_FILE.into());
    study.files = files;
    let md = markdown(study);
    let md_path = dir.join(MARKDOWN_FILE);
    write_atomic(&md_path, |tmp| {
        std::fs::write(tmp, md).at(tmp, "cannot write")
    })?;
    let json = serde_json::to_string_pretty(study)
        .map_err(|e| Error::Internal(format!("study does not serialise: {e}")))?;
    let json_path = dir.join(JSON_FILE);
    write_atomic(&json_path, |tmp| {
        std::fs::write(tmp, json + "\n").at(tmp, "cannot write")
    })
}

/// A number as a column formats it; `—` when missing.
pub fn format_value(v: Option<f64>, f: Format) -> String {
    let Some(v) = v else {
        return "—".into();
    };
    if !v.is_finite() {
        return format!("{v}");
    }
    match f {
        Format::Sci if v == 0.0 => "0".into(),
        Format::Sci => format!("{v:.3e}"),
        Format::Percent if v != 0.0 && (100.0 * v).abs() < 0.01 => format!("{:.2e} %", 100.0 * v),
        Format::Percent => format!("{:.2} %", 100.0 * v),
        Format::Time if v < 1e-3 => format!("{:.1} µs", v * 1e6),
        Format::Time if v < 1.0 => format!("{:.1} ms", v * 1e3),
        Format::Time => format!("{v:.2} s"),
        Format::Bytes => crate::limits::human_bytes(v as u64),
        Format::Count => format!("{v:.0}"),
        Format::Fixed => format!("{v:.2}"),
    }
}

/// `value / baseline` as `1.23x`; `—` when either is missing or the baseline is 0.
pub fn format_ratio(v: Option<f64>, base: Option<f64>) -> String {
    match (v, base) {
        (Some(v), Some(b)) if b != 0.0 && v.is_finite() && b.is_finite() => {
            let r = v / b;
            if r == 0.0 {
                "0x".into()
            } else if (0.01..1000.0).contains(&r.abs()) {
                format!("{r:.2}x")
            } else {
                format!("{r:.2e}x")
            }
        }
        _ => "—".into(),
    }
}

fn row(sweep: &Sweep, s: &Setting, columns: &[Column]) -> String {
    let base = sweep.baseline_of(s);
    let mut cell = if s.reference {
        format!("**{}** (reference)", s.label)
    } else if base.is_some_and(|b| b.label == s.label) {
        format!("{} (baseline)", s.label)
    } else {
        s.label.clone()
    };
    if s.default {
        cell.push_str(" ◀ default");
    }
    let mut cells = vec![cell];
    for c in columns {
        let v = s.value(&c.measure);
        cells.push(format_value(v, c.format));
        if c.ratio {
            cells.push(format_ratio(v, base.and_then(|b| b.value(&c.measure))));
        }
    }
    format!("| {} |", cells.join(" | "))
}

/// The Markdown table of one sweep (header, separator, one row per setting).
pub fn table(sweep: &Sweep) -> String {
    let mut head = vec!["setting".to_string()];
    for c in &sweep.columns {
        head.push(c.header.clone());
        if c.ratio {
            head.push("× baseline".into());
        }
    }
    let mut out = format!("| {} |\n|{}\n", head.join(" | "), "---|".repeat(head.len()));
    for s in &sweep.settings {
        out.push_str(&row(sweep, s, &sweep.columns));
        out.push('\n');
    }
    out
}

/// The whole `study.md`.
pub fn markdown(study: &Study) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# relume study: {}\n", study.study);
    let _ = writeln!(
        md,
        "Input: {}. Mode: {}. {} worker threads, relume {}. Times are wall-clock seconds of this \
         run (noisy on a shared machine): compare the ratios within a table. Everything except \
         the times is deterministic.\n",
        study.input,
        if study.quick { "quick" } else { "full" },
        study.threads,
        study.relume_version
    );
    for sweep in &study.sweeps {
        let _ = writeln!(md, "## {}\n", sweep.title);
        let _ = writeln!(md, "{}.\n", sweep.description);
        let _ = writeln!(md, "- Reference: {}.", sweep.reference);
        if !sweep.baseline.is_empty() {
            let _ = writeln!(
                md,
                "- Baseline for the `× baseline` columns: `{}`.",
                sweep.baseline
            );
        }
        let _ = writeln!(md, "- Time: {}. Bytes: {}.\n", sweep.time, sweep.bytes);
        md.push_str(&table(sweep));
        md.push('\n');
        for n in &sweep.notes {
            let _ = writeln!(md, "{n}\n");
        }
        for p in &sweep.plots {
            let _ = writeln!(md, "![{}]({})\n", p.title, p.file);
        }
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_and_ratios_format() {
        assert_eq!(format_value(Some(0.0123), Format::Percent), "1.23 %");
        assert_eq!(format_value(Some(2e-7), Format::Percent), "2.00e-5 %");
        assert_eq!(format_value(Some(0.0), Format::Sci), "0");
        assert_eq!(format_value(Some(2.5e-4), Format::Time), "250.0 µs");
        assert_eq!(format_value(None, Format::Count), "—");
        assert_eq!(format_ratio(Some(2.0), Some(4.0)), "0.50x");
        assert_eq!(format_ratio(Some(2.0), Some(0.0)), "—");
        assert_eq!(format_ratio(Some(1e-5), Some(1.0)), "1.00e-5x");
    }
}
