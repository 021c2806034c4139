//! `relume-bake study`: the speed/accuracy sweeps of docs/algorithms.md §7. Every knob that trades speed
//! for accuracy is run at several settings and measured against a reference computed in the
//! same run: error (mean, max, RMS, relative RMS and — for matrices — the radiosity thesis's summed absolute
//! error), wall time and bytes.
//!
//! - [`radiosity`]: patch count, form-factor estimator × samples, bounces (reference: the densest
//!   / most-sampled setting of the run, and the f64 Gauss–Seidel solver for the transport);
//!   per-object irradiance of uniform and adaptive patches ([`radiosity_objects`]; reference: an
//!   independent renderer's, read from a file);
//! - [`compression`]: reorder passes, split percentage × dense encoding (reference: the
//!   uncompressed transport and its dense mat-vec);
//! - [`terrain`]: exact vs accelerated hard shadows at several map sizes and sun elevations,
//!   min/max mipmap build (reference: the exact traversal); soft shadows ([`soft_shadows`]:
//!   uniform stepping, dynamic programming, branch-and-bound; reference: the exhaustive walk).
//!
//! Each sweep returns a [`Sweep`]: plain data that [`report`] writes as `study.json`, `study.md`
//! (a table per sweep with ratios against the sweep's baseline setting) and PNG plots
//! ([`plot`]). Everything in a report is deterministic except the measured times.

pub mod atmosphere;
pub mod compression;
pub mod inputs;
pub mod plot;
pub mod radiosity;
pub mod radiosity_objects;
pub mod report;
pub mod scene_bake;
pub mod soft_shadows;
pub mod terrain;
pub mod timing;

use serde::Serialize;
use std::collections::BTreeMap;

/// Error of an approximation against its reference, over the values of one quantity.
///
/// With weights `w` (areas, or 1) and differences `Δ = approx − reference`:
/// `mean = Σ w|Δ| / Σ w`, `max = max |Δ|`, `rms = sqrt(Σ w Δ² / Σ w)`,
/// `rms_rel = sqrt(Σ w Δ² / Σ w ref²)` (0 when both are zero), and `sum = Σ |Δ|` — the radiosity thesis's
/// summed absolute error, given for matrices only.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ErrorStats {
    pub mean: f64,
    pub max: f64,
    pub rms: f64,
    pub rms_rel: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sum: Option<f64>,
}

impl ErrorStats {
    /// Error of `approx` against `reference`, weighted by `weights` (`None`: all 1). Summed in
    /// index order (deterministic).
    pub fn of(approx: &[f64], reference: &[f64], weights: Option<&[f64]>) -> ErrorStats {
        assert_eq!(
            approx.len(),
            reference.len(),
            "error of vectors of unequal length"
        );
        let (mut wsum, mut abs, mut sq, mut ref_sq, mut max) = (0f64, 0f64, 0f64, 0f64, 0f64);
        for (k, (a, r)) in approx.iter().zip(reference).enumerate() {
            let w = weights.map_or(1.0, |w| w[k]);
            let d = a - r;
            wsum += w;
            abs += w * d.abs();
            sq += w * d * d;
            ref_sq += w * r * r;
            max = max.max(d.abs());
        }
        let wsum = wsum.max(f64::MIN_POSITIVE);
        ErrorStats {
            mean: abs / wsum,
            max,
            rms: (sq / wsum).sqrt(),
            rms_rel: relative(sq, ref_sq),
            sum: None,
        }
    }

    /// As [`ErrorStats::of`] over f32 matrix entries (weights 1), with the radiosity thesis's summed error.
    pub fn of_matrix(approx: &[f32], reference: &[f32]) -> ErrorStats {
        let a: Vec<f64> = approx.iter().map(|&v| v as f64).collect();
        let r: Vec<f64> = reference.iter().map(|&v| v as f64).collect();
        let mut e = ErrorStats::of(&a, &r, None);
        e.sum = Some(a.iter().zip(&r).map(|(a, r)| (a - r).abs()).sum());
        e
    }

    /// One of the metrics by name (`mean`, `max`, `rms`, `rms_rel`, `sum`).
    pub fn metric(&self, name: &str) -> Option<f64> {
        match name {
            "mean" => Some(self.mean),
            "max" => Some(self.max),
            "rms" => Some(self.rms),
            "rms_rel" => Some(self.rms_rel),
            "sum" => self.sum,
            _ => None,
        }
    }
}

/// `sqrt(num / den)`, 0 when both are zero, ∞ when only the denominator is.
pub fn relative(num: f64, den: f64) -> f64 {
    if den > 0.0 {
        (num / den).sqrt()
    } else if num == 0.0 {
        0.0
    } else {
        f64::INFINITY
    }
}

/// One measured setting of a sweep.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Setting {
    /// Short unique name within the sweep, e.g. `hemisphere 1024`.
    pub label: String,
    /// Points of the same series are joined in the plots (e.g. the estimator).
    pub series: String,
    /// The knob values of this setting.
    pub knobs: BTreeMap<String, serde_json::Value>,
    /// This setting is the sweep's reference (its errors are 0 by construction).
    pub reference: bool,
    /// This setting is what relume does by default (the knob defaults of `pipeline::knobs` or
    /// the command's default method): marked in tables and ringed in plots.
    pub default: bool,
    /// Label of the setting its ratios are taken against, when not the sweep's baseline.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub baseline: Option<String>,
    /// Error per measured quantity (e.g. `gathered_light`, `form_factors`).
    pub errors: BTreeMap<String, ErrorStats>,
    /// Wall time of what the sweep's `time` describes.
    pub seconds: f64,
    /// Bytes of what the sweep's `bytes` describes.
    pub bytes: u64,
    /// Other numbers (patch counts, rays, speed-ups, per-phase times ...).
    pub extra: BTreeMap<String, f64>,
}

impl Setting {
    pub fn new(label: impl Into<String>, series: impl Into<String>) -> Self {
        Setting {
            label: label.into(),
            series: series.into(),
            ..Default::default()
        }
    }

    /// Mark this setting as relume's default when `is_default`.
    pub fn default_if(mut self, is_default: bool) -> Self {
        self.default = is_default;
        self
    }

    /// Add a knob value.
    pub fn knob(mut self, name: &str, value: impl Into<serde_json::Value>) -> Self {
        self.knobs.insert(name.into(), value.into());
        self
    }

    /// The value of a measure for this setting (None when it has no such value).
    pub fn value(&self, m: &Measure) -> Option<f64> {
        match m {
            Measure::Seconds => Some(self.seconds),
            Measure::Bytes => Some(self.bytes as f64),
            Measure::Error(q, metric) => self.errors.get(q).and_then(|e| e.metric(metric)),
            Measure::Extra(name) => self.extra.get(name).copied(),
        }
    }
}

/// A number every setting of a sweep may have: what tables and plots show.
#[derive(Clone, Debug, PartialEq)]
pub enum Measure {
    Seconds,
    Bytes,
    /// (quantity, metric), e.g. `("gathered_light", "rms_rel")`.
    Error(String, String),
    Extra(String),
}

impl Measure {
    pub fn error(quantity: &str, metric: &str) -> Measure {
        Measure::Error(quantity.into(), metric.into())
    }
    pub fn extra(name: &str) -> Measure {
        Measure::Extra(name.into())
    }
    /// Dotted name used in JSON (`seconds`, `bytes`, `gathered_light.rms_rel`, `extra.rays`).
    pub fn name(&self) -> String {
        match self {
            Measure::Seconds => "seconds".into(),
            Measure::Bytes => "bytes".into(),
            Measure::Error(q, m) => format!("{q}.{m}"),
            Measure::Extra(n) => format!("extra.{n}"),
        }
    }
}

impl Serialize for Measure {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.name())
    }
}

/// How a table column prints its number.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Format {
    /// 3 significant digits in scientific notation.
    Sci,
    /// Percent with 2 decimals.
    Percent,
    /// Seconds, adaptive (µs/ms/s).
    Time,
    /// Bytes, binary units.
    Bytes,
    /// Integer.
    Count,
    /// 2 decimals.
    Fixed,
}

/// A column of a sweep's Markdown table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Column {
    pub header: String,
    pub measure: Measure,
    pub format: Format,
    /// Add a `× baseline` column after it.
    pub ratio: bool,
}

impl Column {
    /// A column of an error metric (`quantity.metric`).
    pub fn error(header: &str, quantity: &str, metric: &str, format: Format, ratio: bool) -> Self {
        Column::new(header, Measure::error(quantity, metric), format, ratio)
    }

    /// A column of an extra measure (`Setting::extra[name]`).
    pub fn extra(header: &str, name: &str, format: Format, ratio: bool) -> Self {
        Column::new(header, Measure::extra(name), format, ratio)
    }

    /// The RMS relative error of the gathered light, with a ratio column: every scene sweep's
    /// headline number.
    pub fn gathered_light(header: &str) -> Self {
        Column::error(header, "gathered_light", "rms_rel", Format::Percent, true)
    }

    pub fn new(header: &str, measure: Measure, format: Format, ratio: bool) -> Self {
        Column {
            header: header.into(),
            measure,
            format,
            ratio,
        }
    }
}

/// A log-log plot of a sweep (drawn by [`plot`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlotSpec {
    /// File name inside the output directory.
    pub file: String,
    pub title: String,
    pub x: Measure,
    pub y: Measure,
    pub x_label: String,
    pub y_label: String,
}

/// One sweep: several settings of some knobs against one reference.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Sweep {
    /// Machine name, e.g. `radiosity_patches`.
    pub name: String,
    pub title: String,
    /// What was varied, what was held fixed.
    pub description: String,
    /// What the errors are measured against.
    pub reference: String,
    /// Label of the setting ratios are taken against.
    pub baseline: String,
    /// What `seconds` and `bytes` measure.
    pub time: String,
    pub bytes: String,
    pub settings: Vec<Setting>,
    pub columns: Vec<Column>,
    pub plots: Vec<PlotSpec>,
    /// Remarks printed under the table.
    pub notes: Vec<String>,
}

impl Sweep {
    /// The setting called `label`.
    pub fn setting(&self, label: &str) -> Option<&Setting> {
        self.settings.iter().find(|s| s.label == label)
    }

    /// The baseline of `s` (its own, else the sweep's).
    pub fn baseline_of(&self, s: &Setting) -> Option<&Setting> {
        self.setting(s.baseline.as_deref().unwrap_or(&self.baseline))
    }

    /// Add the standard pair of plots: `error` against time and against bytes (the bytes plot
    /// only when the bytes differ between settings).
    pub fn error_plots(&mut self, error: Measure, error_label: &str) {
        let stem = self.name.clone();
        self.plots.push(PlotSpec {
            file: format!("{stem}_error_vs_time.png"),
            title: format!("{}: error vs time", self.title),
            x: Measure::Seconds,
            y: error.clone(),
            x_label: format!("seconds ({})", self.time),
            y_label: error_label.into(),
        });
        // The reference may store nothing (a solver, an exact traversal): judge the others.
        let measured: Vec<u64> = self
            .settings
            .iter()
            .filter(|s| !s.reference)
            .map(|s| s.bytes)
            .collect();
        let first = measured.first().copied();
        if measured.iter().any(|&b| Some(b) != first) {
            self.plots.push(PlotSpec {
                file: format!("{stem}_error_vs_bytes.png"),
                title: format!("{}: error vs bytes", self.title),
                x: Measure::Bytes,
                y: error,
                x_label: format!("bytes ({})", self.bytes),
                y_label: error_label.into(),
            });
        } else {
            self.notes.push(format!(
                "Every setting has the same bytes ({}), so there is no error-vs-bytes plot.",
                first.unwrap_or(0)
            ));
        }
    }
}

/// A whole study run: what `study.json` holds.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Study {
    /// `radiosity`, `compression` or `terrain`.
    pub study: String,
    /// What was studied (scene, bake or height map) in words.
    pub input: String,
    pub quick: bool,
    pub threads: usize,
    pub relume_version: String,
    pub sweeps: Vec<Sweep>,
    /// Files written next to `study.json`.
    pub files: Vec<String>,
}

impl Study {
    pub fn new(study: &str, input: String, quick: bool, sweeps: Vec<Sweep>) -> Study {
        Study {
            study: study.into(),
            input,
            quick,
            threads: rayon::current_num_threads(),
            relume_version: env!("CARGO_PKG_VERSION").into(),
            sweeps,
            files: Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_stats_of_known_vectors() {
        let e = ErrorStats::of(&[1.0, 2.0, 5.0], &[1.0, 3.0, 3.0], Some(&[1.0, 1.0, 2.0]));
        assert_eq!(e.max, 2.0);
        assert!((e.mean - (1.0 + 4.0) / 4.0).abs() < 1e-15);
        assert!((e.rms - ((1.0 + 8.0) / 4.0f64).sqrt()).abs() < 1e-15);
        assert!((e.rms_rel - (9.0f64 / (1.0 + 9.0 + 18.0)).sqrt()).abs() < 1e-15);
        let z = ErrorStats::of_matrix(&[0.5, 0.25], &[0.5, 0.25]);
        assert_eq!(
            z,
            ErrorStats {
                sum: Some(0.0),
                ..Default::default()
            }
        );
        assert_eq!(relative(0.0, 0.0), 0.0);
        assert_eq!(relative(1.0, 0.0), f64::INFINITY);
    }
}
