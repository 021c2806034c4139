//! Compression sweeps (docs/algorithms.md §3 "Compression", §7): reorder passes, and split percentage ×
//! dense encoding. Reference: the uncompressed transport S (f32) and its dense mat-vec.
//!
//! Per setting: the radiosity thesis's three numbers for the decoded matrix (mean, max and summed absolute
//! error, [`crate::compress::report::entry_errors`]) plus its RMS, the error of the gathered
//! light `B = S·E` for the first light of the input (the scene's emitters when known) against
//! the dense f32 product, the RMS relative gather error of the standard lights
//! ([`crate::compress::report::standard_lights`]), bytes, encode time and the CPU gather time
//! as a ratio to the dense mat-vec of the same run.

use super::scene_bake::{bake_scene, emitted_exitance};
use super::timing::{median_secs, timed};
use super::{relative, Column, ErrorStats, Format, Measure, Setting, Sweep};
use crate::compress::report::{entry_errors, rms_relative, standard_lights};
use crate::compress::{
    compress, gather, reorder, DenseEncoding, EncodeOptions, EncodedTransport, ReorderMethod,
    ReorderMetric, ReorderOptions,
};
use crate::error::Result;
use crate::pipeline::knobs::{EncodeKnobs, ReorderKnobs};
use crate::progress::Progress;
use crate::radiosity::formfactor::FormFactorParams;
use crate::radiosity::patches::voxelize::Resolution;
use crate::radiosity::transport::Bounces;
use crate::radiosity::PatchSet;
use crate::radiosity::TransportMatrix;
use crate::scene::Scene;
use std::path::Path;

/// What the compression sweeps run.
#[derive(Clone, Debug, PartialEq)]
pub struct CompressionConfig {
    /// Greedy reorder passes to sweep (each also with the Log metric when > 0).
    pub passes: Vec<u8>,
    /// Split percentages to sweep for every encoding.
    pub split_percents: Vec<f64>,
    pub encodings: Vec<DenseEncoding>,
    /// Gather timings are the median of this many runs.
    pub gather_runs: usize,
}

impl CompressionConfig {
    pub fn full() -> Self {
        CompressionConfig {
            passes: vec![0, 1, 2],
            split_percents: vec![0.0, 1.0, 2.0, 4.0, 8.0],
            encodings: DenseEncoding::ALL.to_vec(),
            gather_runs: 5,
        }
    }

    /// The same knobs; the matrix is what makes it quick (the caller picks a small one).
    pub fn quick() -> Self {
        CompressionConfig {
            gather_runs: 3,
            ..Self::full()
        }
    }
}

/// The matrix to compress and the lights to gather, `[channels][n]` in original patch order.
/// The first light is the one the primary error is measured with.
pub struct CompressionInput {
    pub s: TransportMatrix,
    pub lights: Vec<(String, Vec<f32>)>,
    /// What the matrix is, in words.
    pub description: String,
}

/// The scene's emitters as a light of `channels` channels (a grey transport gets the mean of
/// R, G, B), or `None` when nothing emits.
pub fn emitter_light(set: &PatchSet, channels: usize) -> Option<Vec<f32>> {
    let e = emitted_exitance(set);
    let light: Vec<f32> = if channels == 3 {
        e.concat().into_iter().map(|v| v as f32).collect()
    } else {
        (0..set.len())
            .map(|i| ((e[0][i] + e[1][i] + e[2][i]) / 3.0) as f32)
            .collect()
    };
    light.iter().any(|&v| v > 0.0).then_some(light)
}

fn with_standard_lights(
    s: TransportMatrix,
    emitters: Option<Vec<f32>>,
    description: String,
) -> CompressionInput {
    let mut lights = Vec::new();
    if let Some(e) = emitters {
        lights.push(("emitters".to_string(), e));
    }
    lights.extend(standard_lights(s.channels, s.n));
    CompressionInput {
        s,
        lights,
        description,
    }
}

/// Bake a scene's transport for the study (hemisphere form factors, the given bounces).
pub fn input_from_scene(
    scene: &Scene,
    resolution: Resolution,
    ff: &FormFactorParams,
    bounces: Bounces,
    name: &str,
) -> Result<CompressionInput> {
    let b = bake_scene(scene, resolution, ff, bounces)?;
    let emitters = emitter_light(&b.set, b.transport.matrix.channels);
    let description = format!(
        "{name}: {} patches, {:?} form factors ({} samples), bounces {bounces:?}, {} channel(s)",
        b.set.len(),
        ff.estimator,
        ff.samples,
        b.transport.matrix.channels
    );
    Ok(with_standard_lights(
        b.transport.matrix,
        emitters,
        description,
    ))
}

/// The transport of an existing bake (`transport.npy`; the emitters from `patches.bin` when it
/// is there).
pub fn input_from_bake(dir: &Path) -> Result<CompressionInput> {
    let s = crate::baked::transport::read(dir)?;
    let patches = dir.join(crate::baked::patches::FILE);
    let emitters = if patches.exists() {
        let set = crate::baked::patches::read(dir)?;
        (set.len() == s.n)
            .then(|| emitter_light(&set, s.channels))
            .flatten()
    } else {
        None
    };
    let description = format!(
        "the bake {}: n = {}, {} channel(s)",
        dir.display(),
        s.n,
        s.channels
    );
    Ok(with_standard_lights(s, emitters, description))
}

/// Exact gathers of every light and Σ S² (for relative errors), computed once.
struct Exact<'a> {
    input: &'a CompressionInput,
    gathers: Vec<Vec<f32>>,
    sum_sq: f64,
}

impl Exact<'_> {
    /// Errors and extras of one encoded transport.
    fn measure(&self, s_perm: &TransportMatrix, enc: &EncodedTransport, s: &mut Setting) {
        let m = entry_errors(s_perm, enc);
        let count = (s_perm.channels * s_perm.n * s_perm.n).max(1) as f64;
        s.errors.insert(
            "matrix".into(),
            ErrorStats {
                mean: m.mean,
                max: m.max,
                rms: m.rms,
                rms_rel: relative(m.rms * m.rms * count, self.sum_sq),
                sum: Some(m.sum),
            },
        );
        let mut worst_standard = 0f64;
        for (k, ((name, e), exact)) in self.input.lights.iter().zip(&self.gathers).enumerate() {
            let approx = gather(enc, e);
            if k == 0 {
                s.errors
                    .insert("gathered_light".into(), f32_stats(&approx, exact));
            }
            let r = rms_relative(&approx, exact);
            if name != "emitters" {
                worst_standard = worst_standard.max(r);
            }
            s.extra.insert(format!("gather_rms_rel_{name}"), r);
        }
        s.extra
            .insert("gather_rms_rel_worst_standard".into(), worst_standard);
        s.extra
            .insert("dense_bytes".into(), enc.dense.bytes() as f64);
        s.extra
            .insert("sidecar_bytes".into(), enc.sidecar.byte_len() as f64);
        s.bytes = enc.bytes() as u64;
    }
}

fn f32_stats(approx: &[f32], exact: &[f32]) -> ErrorStats {
    let a: Vec<f64> = approx.iter().map(|&v| v as f64).collect();
    let x: Vec<f64> = exact.iter().map(|&v| v as f64).collect();
    ErrorStats::of(&a, &x, None)
}

/// The radiosity thesis's scheme: Bc1Log, zeroed holes, no feedback, with a 4 % split.
fn seed_options() -> EncodeOptions {
    EncodeOptions::default()
}

/// The `encode` stage's defaults for `encoding` (filled holes, no feedback, range 25).
fn product_options(encoding: DenseEncoding) -> EncodeOptions {
    EncodeOptions {
        encoding,
        fill_holes: true,
        ..EncodeOptions::default()
    }
}

/// Both compression sweeps.
pub fn run(
    input: &CompressionInput,
    cfg: &CompressionConfig,
    progress: &dyn Progress,
) -> Result<Vec<Sweep>> {
    let s = &input.s;
    let exact = Exact {
        input,
        gathers: input.lights.iter().map(|(_, e)| s.mat_vec(e)).collect(),
        sum_sq: s.data.iter().map(|&v| (v as f64) * (v as f64)).sum(),
    };
    let primary = input
        .lights
        .first()
        .map(|l| l.0.clone())
        .unwrap_or_default();

    // 1. Reorder passes, with the radiosity thesis's encoding.
    // Every pass count with the thesis's full distance matrix (Linear and Log), then the
    // bounded walk (Linear): the same permutations, at different cost.
    let mut runs: Vec<(u8, ReorderMetric, ReorderMethod)> = Vec::new();
    let mut passes = cfg.passes.clone();
    passes.sort_unstable();
    passes.dedup();
    for &p in &passes {
        runs.push((p, ReorderMetric::Linear, ReorderMethod::Full));
        if p > 0 {
            runs.push((p, ReorderMetric::Log, ReorderMethod::Full));
        }
    }
    for &p in passes.iter().filter(|&&p| p > 0) {
        runs.push((p, ReorderMetric::Linear, ReorderMethod::Bounded));
        runs.push((p, ReorderMetric::Linear, ReorderMethod::Budgeted));
    }
    let mut reorder_sweep = Sweep {
        name: "compression_reorder".into(),
        title: "Compression: reorder passes".into(),
        description: format!(
            "{}; greedy passes {passes:?} with the Linear (radiosity thesis) and Log metrics; encoded with the thesis's scheme (Bc1Log, p = 4 %, zeroed holes)",
            input.description
        ),
        reference: format!(
            "the uncompressed matrix S: errors of the decoded entries (the radiosity thesis's mean, max, sum) and of the gathered light B = S·E for the `{primary}` light against the dense f32 product"
        ),
        baseline: "0 passes".into(),
        time: "reorder".into(),
        bytes: "dense texture + sidecar".into(),
        ..Default::default()
    };
    progress.begin("study: reorder", runs.len() as u64);
    let mut default_perm = None;
    // The bounded reorder transposes the matrix in place and back: it works on a copy here.
    let mut scratch = s.clone();
    for (p, metric, method) in runs {
        let opts = ReorderOptions {
            passes: p,
            metric,
            method,
        };
        let (perm, secs) = timed(|| reorder(&mut scratch, opts));
        let sp = s.permuted(&perm);
        let (enc, enc_secs) = timed(|| compress(&sp, perm.clone(), 4.0, &seed_options()));
        let enc = enc?;
        let full = method == ReorderMethod::Full;
        let suffix = match method {
            ReorderMethod::Full => "",
            ReorderMethod::Bounded => " bounded",
            ReorderMethod::Budgeted => " budgeted",
        };
        let label = if p == 0 {
            "0 passes".to_string()
        } else {
            format!("{p} passes {metric:?}{suffix}")
        };
        let series = if p == 0 {
            "Linear".into()
        } else {
            format!("{metric:?}{suffix}")
        };
        let d = ReorderKnobs::default();
        let mut st = Setting::new(label, series)
            .default_if(p == d.passes && metric == d.metric && method == d.method)
            .knob("passes", p)
            .knob("metric", format!("{metric:?}"))
            .knob("method", format!("{method:?}"))
            .knob("encoding", DenseEncoding::Bc1Log.name())
            .knob("split_percent", 4.0)
            .knob("fill_holes", false);
        exact.measure(&sp, &enc, &mut st);
        st.seconds = secs;
        st.extra.insert("encode_seconds".into(), enc_secs);
        reorder_sweep.settings.push(st);
        // The product default (2 Linear passes, or the most passes swept) feeds sweep 2.
        if metric == ReorderMetric::Linear && full {
            default_perm = Some((p, perm, sp));
        }
        progress.advance(1);
    }
    progress.finish();
    // Passes 0 takes no time: the Linear series starts at its first pass in the plot.
    reorder_sweep.columns = vec![
        Column::error("mean abs error", "matrix", "mean", Format::Sci, false),
        Column::error("max abs error", "matrix", "max", Format::Sci, false),
        Column::error("summed abs error", "matrix", "sum", Format::Sci, true),
        Column::gathered_light(&format!("gather rms rel ({primary})")),
        Column::new("reorder time", Measure::Seconds, Format::Time, false),
    ];
    reorder_sweep.notes.push(
        "The radiosity thesis (Shcherbakov 2017, §4.2) reports mean 5.88e-7, max 0.1524, sum 9.40 after reordering vs 1.28e-6, 0.4622, 47.12 without (its own scene): reordering should cut the summed error about 5x.".into(),
    );
    reorder_sweep.error_plots(
        Measure::error("matrix", "sum"),
        "summed abs error of the decoded matrix",
    );

    // 2. Split percentage × encoding, on the reordered matrix.
    let (passes_used, perm, sp) = match default_perm {
        Some(d) => d,
        None => {
            let perm = reorder(
                &mut scratch,
                ReorderOptions {
                    passes: 2,
                    ..Default::default()
                },
            );
            let sp = s.permuted(&perm);
            (2, perm, sp)
        }
    };
    let e0 = &input.lights[0].1;
    let dense_secs = median_secs(cfg.gather_runs, || {
        std::hint::black_box(s.mat_vec(e0));
    });
    let mut rows: Vec<(String, String, f64, EncodeOptions)> = Vec::new();
    for &enc in &cfg.encodings {
        for &p in &cfg.split_percents {
            rows.push((
                format!("{} p={p}", enc.name()),
                enc.name().into(),
                p,
                product_options(enc),
            ));
        }
    }
    let seed_label = "seed: bc1_log p=4 zeroed holes".to_string();
    rows.push((
        seed_label.clone(),
        "radiosity thesis".into(),
        4.0,
        seed_options(),
    ));
    let mut enc_sweep = Sweep {
        name: "compression_encoding".into(),
        title: "Compression: encoding and split".into(),
        description: format!(
            "{}; {passes_used} Linear reorder passes; encodings {} × split p {:?} % with filled holes (the encode stage's default), plus the radiosity thesis's scheme",
            input.description,
            cfg.encodings.iter().map(|e| e.name()).collect::<Vec<_>>().join(", "),
            cfg.split_percents
        ),
        reference: format!(
            "the uncompressed f32 matrix and its dense mat-vec (the `uncompressed f32` row); gathered light for the `{primary}` light"
        ),
        baseline: seed_label,
        time: format!("CPU gather B = S·E, median of {}", cfg.gather_runs),
        bytes: "dense texture + sidecar".into(),
        ..Default::default()
    };
    let mut reference = Setting::new("uncompressed f32", "reference")
        .knob("encoding", "none")
        .knob("split_percent", 0.0);
    reference.reference = true;
    let g0 = &exact.gathers[0];
    reference
        .errors
        .insert("matrix".into(), ErrorStats::of_matrix(&s.data, &s.data));
    reference
        .errors
        .insert("gathered_light".into(), f32_stats(g0, g0));
    reference.seconds = dense_secs;
    reference.bytes = (s.data.len() * 4) as u64;
    reference.extra.insert("gather_over_dense".into(), 1.0);
    reference
        .extra
        .insert("gather_rms_rel_worst_standard".into(), 0.0);
    for (name, _) in &input.lights {
        reference
            .extra
            .insert(format!("gather_rms_rel_{name}"), 0.0);
    }
    enc_sweep.settings.push(reference);
    progress.begin("study: encodings", rows.len() as u64);
    for (label, series, p, o) in rows {
        let (enc, enc_secs) = timed(|| compress(&sp, perm.clone(), p, &o));
        let enc = enc?;
        let d = EncodeKnobs::default();
        let mut st = Setting::new(label, series)
            .default_if(
                o.encoding == d.encoding
                    && p == d.split_percent
                    && o.fill_holes == d.fill_holes
                    && o.feedback == d.feedback
                    && o.log_range == d.log_range,
            )
            .knob("encoding", o.encoding.name())
            .knob("split_percent", p)
            .knob("fill_holes", o.fill_holes)
            .knob("feedback", o.feedback)
            .knob("passes", passes_used);
        exact.measure(&sp, &enc, &mut st);
        st.seconds = median_secs(cfg.gather_runs, || {
            std::hint::black_box(gather(&enc, e0));
        });
        st.extra.insert("encode_seconds".into(), enc_secs);
        st.extra.insert(
            "gather_over_dense".into(),
            st.seconds / dense_secs.max(1e-12),
        );
        enc_sweep.settings.push(st);
        progress.advance(1);
    }
    progress.finish();
    enc_sweep.columns = vec![
        Column::gathered_light(&format!("gather rms rel ({primary})")),
        Column::extra(
            "worst standard light",
            "gather_rms_rel_worst_standard",
            Format::Percent,
            false,
        ),
        Column::error("summed abs error", "matrix", "sum", Format::Sci, true),
        Column::error("max abs error", "matrix", "max", Format::Sci, false),
        Column::new("bytes", Measure::Bytes, Format::Bytes, true),
        Column::extra("encode time", "encode_seconds", Format::Time, false),
        Column::new("gather time", Measure::Seconds, Format::Time, false),
        Column::extra(
            "gather / dense mat-vec",
            "gather_over_dense",
            Format::Fixed,
            false,
        ),
    ];
    enc_sweep.notes.push(format!(
        "Dense f32 mat-vec (the reference's time): {:.3} ms. Gather times are single CPU gathers straight from the compressed form.",
        dense_secs * 1e3
    ));
    enc_sweep.error_plots(
        Measure::error("gathered_light", "rms_rel"),
        "gathered light RMS relative error",
    );
    Ok(vec![reorder_sweep, enc_sweep])
}
