//! The per-object sweep of the radiosity study: each object's mean irradiance against a
//! path tracer's, by patch count, for the uniform grid (`TargetPatches(n)`) and adaptive patches
//! (`Adaptive(target: n)` with its default knobs) side by side (docs/radiosity.md §"Adaptive
//! patches against the uniform grid").
//!
//! The reference is a JSON file of per-object irradiance measured by an independent renderer —
//! `{"object name": {"mean": [r, g, b], "stderr": [r, g, b], "area": A}, ...}` as
//! `tests/support/mitsuba_objects.py` (Mitsuba 3's irradiance meters) writes it; `stderr` and
//! `area` are optional. relume's side is [`object_light`]: the mean irradiance over each object
//! from the patches (the radiosity solution itself) and through the display mesh's corners (what
//! the player shows).
//!
//! An object's error is the mean over RGB of `relume / reference − 1`. Measured are the objects
//! the reference names whose area is at least `min_area_share` of the scene's and whose reference
//! irradiance is positive in every channel (a relative error of nothing is undefined; those are
//! listed in the notes). Errors are stats over the measured objects, each weighing 1: `max` is
//! the worst object, `mean` the mean absolute error.

use super::scene_bake::{bake_scene, emitted_exitance, gathered};
use super::{Column, ErrorStats, Format, Measure, Setting, Sweep};
use crate::error::{Error, Result};
use crate::pipeline::knobs::{FormFactorsKnobs, VoxelizeKnobs};
use crate::progress::Progress;
use crate::radiosity::mesh::objects::object_light;
use crate::radiosity::patches::adaptive::AdaptiveParams;
use crate::radiosity::patches::voxelize::Resolution;
use crate::radiosity::transport::Bounces;
use crate::scene::Scene;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

/// One object of a reference file.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ReferenceObject {
    /// Mean irradiance over the object, per channel (W/m² or the scene's units).
    pub mean: [f64; 3],
    /// Standard error of `mean` (0 when the file has none).
    #[serde(default)]
    pub stderr: [f64; 3],
    /// The object's area as the reference renderer saw it (informative).
    #[serde(default)]
    pub area: Option<f64>,
}

/// Per-object irradiance of a scene by an independent renderer.
pub type ObjectReference = BTreeMap<String, ReferenceObject>;

/// Read a reference file; errors name the file and what is wrong with it.
pub fn read_reference(path: &Path) -> Result<ObjectReference> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::io(path, "read the per-object reference", e))?;
    let r: ObjectReference = serde_json::from_str(&text).map_err(|e| {
        Error::input(
            path,
            format!("not a per-object irradiance reference ({e}); expected {{\"object\": {{\"mean\": [r, g, b], \"stderr\": [r, g, b], \"area\": A}}, ...}}"),
        )
    })?;
    if r.is_empty() {
        return Err(Error::input(path, "the reference names no object"));
    }
    for (name, o) in &r {
        if o.mean
            .iter()
            .chain(&o.stderr)
            .any(|v| !v.is_finite() || *v < 0.0)
        {
            return Err(Error::input(
                path,
                format!("object `{name}`: irradiance and standard error must be finite and non-negative"),
            ));
        }
    }
    Ok(r)
}

/// What the per-object sweep runs.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectsConfig {
    /// Target patch counts; each is baked uniform and adaptive.
    pub targets: Vec<u32>,
    /// Objects smaller than this share of the scene's area are not measured.
    pub min_area_share: f64,
    /// Error at or under which an object counts as matched (the `within` column).
    pub tolerance: f64,
}

impl ObjectsConfig {
    pub fn full() -> Self {
        ObjectsConfig {
            targets: vec![1000, 2000, 4000],
            min_area_share: 0.005,
            tolerance: 0.05,
        }
    }
    pub fn quick() -> Self {
        ObjectsConfig {
            targets: vec![300, 600],
            ..Self::full()
        }
    }
}

/// One object's error in one bake: (object, from the patches, through the display mesh's corners).
type ObjectError = (String, f64, f64);

/// A setting (errors, time, patches) and its per-object errors for one bake.
fn object_errors(
    scene: &Scene,
    resolution: Resolution,
    reference: &ObjectReference,
    measured: &[String],
) -> Result<(Setting, Vec<ObjectError>)> {
    let ff = FormFactorsKnobs::default().params();
    let b = bake_scene(scene, resolution, &ff, Bounces::Infinite)?;
    let light = gathered(&b.transport, &emitted_exitance(&b.set));
    let per_patch: Vec<[f32; 3]> = (0..b.set.len())
        .map(|i| std::array::from_fn(|c| light[c][i] as f32))
        .collect();
    let objects = object_light(scene, &b.set, &per_patch);
    let err = |got: [f64; 3], r: &ReferenceObject| {
        (0..3).map(|c| got[c] / r.mean[c] - 1.0).sum::<f64>() / 3.0
    };
    let rows: Vec<ObjectError> = measured
        .iter()
        .map(|name| {
            let o = objects.iter().find(|o| &o.name == name).expect("checked");
            let r = &reference[name];
            (
                name.clone(),
                err(o.irradiance_patches, r),
                err(o.irradiance, r),
            )
        })
        .collect();
    let mut s = Setting::default();
    let zeros = vec![0.0; rows.len()];
    let patches: Vec<f64> = rows.iter().map(|r| r.1).collect();
    let corners: Vec<f64> = rows.iter().map(|r| r.2).collect();
    s.errors.insert(
        "object_irradiance".into(),
        ErrorStats::of(&patches, &zeros, None),
    );
    s.errors.insert(
        "object_irradiance_corners".into(),
        ErrorStats::of(&corners, &zeros, None),
    );
    s.seconds = b.voxelize_seconds + b.form_factor_seconds + b.transport_seconds;
    s.bytes = (b.transport.matrix.channels * b.set.len() * b.set.len() * 4) as u64;
    s.extra.insert("patches".into(), b.set.len() as f64);
    s.extra
        .insert("voxelize_seconds".into(), b.voxelize_seconds);
    Ok((s, rows))
}

/// The objects of `reference` this sweep measures on `scene`, and the notes on those it skips.
/// An object the scene does not have is an error (the reference is of another scene).
pub fn measured_objects(
    scene: &Scene,
    reference: &ObjectReference,
    min_area_share: f64,
    source: &Path,
) -> Result<(Vec<String>, Vec<String>)> {
    let mut area = vec![0f64; scene.objects.len()];
    for (t, &o) in scene.triangle_object.iter().enumerate() {
        area[o as usize] += scene.triangle_area(t) as f64;
    }
    let total: f64 = area.iter().sum();
    let (mut measured, mut notes) = (Vec::new(), Vec::new());
    for (name, r) in reference {
        let Some(k) = scene.objects.iter().position(|o| o == name) else {
            return Err(Error::input(
                source,
                format!(
                    "object `{name}` is not in the scene (its objects: {}); is this the reference of another scene?",
                    scene.objects.join(", ")
                ),
            ));
        };
        let share = area[k] / total.max(f64::MIN_POSITIVE);
        if share < min_area_share {
            notes.push(format!(
                "`{name}` ({:.2} % of the area) is under the {:.1} % measured.",
                100.0 * share,
                100.0 * min_area_share
            ));
        } else if r.mean.iter().any(|&v| v <= 0.0) {
            notes.push(format!(
                "`{name}` gets no light in the reference in some channel: a relative error is undefined there."
            ));
        } else {
            measured.push(name.clone());
        }
    }
    if measured.is_empty() {
        return Err(Error::input(
            source,
            "no object of the reference is large enough and lit in every channel to be measured",
        ));
    }
    Ok((measured, notes))
}

/// The per-object sweep: uniform and adaptive at every target.
pub fn objects_sweep(
    scene: &Scene,
    reference: &ObjectReference,
    reference_name: &Path,
    cfg: &ObjectsConfig,
    progress: &dyn Progress,
) -> Result<Sweep> {
    let (measured, skipped) =
        measured_objects(scene, reference, cfg.min_area_share, reference_name)?;
    let mut targets = cfg.targets.clone();
    targets.sort_unstable();
    targets.dedup();
    let default_resolution = VoxelizeKnobs::default().resolution;
    let mut sweep = Sweep {
        name: "radiosity_objects".into(),
        title: "Radiosity: per-object irradiance, uniform vs adaptive patches".into(),
        description: format!(
            "voxelize TargetPatches(n) and Adaptive(target: n) (default knobs) for n in {targets:?}; the default form factors; infinite bounces; {} objects measured",
            measured.len()
        ),
        reference: format!(
            "{}: per-object mean irradiance of an independent renderer; error = mean over RGB of relume/reference − 1 per object (patches: the radiosity solution; corners: the display mesh the player draws); stats over objects",
            reference_name.display()
        ),
        time: "voxelize + form factors + transport".into(),
        bytes: "transport.npy payload, channels·n²·4".into(),
        ..Default::default()
    };
    progress.begin("study: objects", 2 * targets.len() as u64);
    let mut table: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for &t in &targets {
        for (series, resolution) in [
            ("uniform", Resolution::TargetPatches(t)),
            ("adaptive", Resolution::Adaptive(AdaptiveParams::new(t))),
        ] {
            let (mut s, rows) = object_errors(scene, resolution, reference, &measured)?;
            s.label = format!("{series} {t}");
            s.series = series.into();
            s.default = resolution == default_resolution;
            s = s.knob("resolution", format!("{resolution:?}"));
            let within = rows.iter().filter(|r| r.1.abs() <= cfg.tolerance).count();
            s.extra.insert("objects_within".into(), within as f64);
            for (name, ep, ec) in &rows {
                s.extra.insert(format!("error:{name}"), *ep);
                s.extra.insert(format!("error_corners:{name}"), *ec);
                table.entry(name.clone()).or_default().push(format!(
                    "{:+.1} / {:+.1}",
                    100.0 * ep,
                    100.0 * ec
                ));
            }
            sweep.settings.push(s);
            progress.advance(1);
        }
    }
    progress.finish();
    sweep.baseline = format!("uniform {}", targets[0]);
    for s in &mut sweep.settings {
        // Adaptive at n against uniform at the same n.
        if s.series == "adaptive" {
            s.baseline = Some(s.label.replacen("adaptive", "uniform", 1));
        }
    }
    sweep.columns = vec![
        Column::extra("patches", "patches", Format::Count, false),
        Column::error(
            "worst object",
            "object_irradiance",
            "max",
            Format::Percent,
            true,
        ),
        Column::error(
            "mean object",
            "object_irradiance",
            "mean",
            Format::Percent,
            false,
        ),
        Column::error(
            "worst (corners)",
            "object_irradiance_corners",
            "max",
            Format::Percent,
            true,
        ),
        Column::extra(
            &format!("within {:.0} %", 100.0 * cfg.tolerance),
            "objects_within",
            Format::Count,
            false,
        ),
        Column::new("time", Measure::Seconds, Format::Time, true),
    ];
    sweep.notes.push(format!(
        "Adaptive settings take their ratios against the uniform grid at the same target. Per object (patches / corners, %), settings in the order {}:",
        sweep.settings.iter().map(|s| s.label.as_str()).collect::<Vec<_>>().join(", ")
    ));
    for (name, cells) in &table {
        let r = &reference[name];
        let se = (0..3).map(|c| r.stderr[c] / r.mean[c]).sum::<f64>() / 3.0;
        sweep.notes.push(format!(
            "`{name}` (reference ± {:.2} %): {}",
            100.0 * se,
            cells.join(" | ")
        ));
    }
    sweep.notes.extend(skipped);
    sweep.plots.push(super::PlotSpec {
        file: "radiosity_objects_error_vs_patches.png".into(),
        title: "Radiosity: worst object vs patches".into(),
        x: Measure::extra("patches"),
        y: Measure::error("object_irradiance", "max"),
        x_label: "patches".into(),
        y_label: "worst object, irradiance error (relative)".into(),
    });
    sweep.error_plots(
        Measure::error("object_irradiance", "max"),
        "worst object, irradiance error (relative)",
    );
    Ok(sweep)
}
