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
//! A scene lit by punctual lights (a sun) is compared on the **total** irradiance, as
//! `tests/support/mitsuba_textured.py` writes it (`{"object": {"direct": …, "indirect": …,
//! "indirect_stderr": …, "total": …}}`): relume's light vector is then the lights' direct
//! exitance at the patches' sample points (shadow rays, [`patch_exitance`]) plus emission, and
//! each object's value is its mean direct irradiance ([`object_direct`], computed once: it does
//! not depend on the patches) plus the indirect part. Objects of one name (an OBJ's three
//! `walls`) are merged by area, as a path tracer's meter over the name sees them.
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
use crate::render::direct::{object_direct, patch_exitance};
use crate::render::lights::GpuLight;
use crate::render::mesh_reference::FrameSettings;
use crate::render::raycast::RaycastScene;
use crate::scene::Scene;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

/// One object of a reference file.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ReferenceObject {
    /// Mean irradiance over the object from other surfaces and emitters, per channel (W/m² or
    /// the scene's units).
    #[serde(default)]
    pub mean: Option<[f64; 3]>,
    /// Standard error of `mean` (0 when the file has none).
    #[serde(default)]
    pub stderr: [f64; 3],
    /// Mean total irradiance (punctual lights' direct light included): compared instead of
    /// `mean` when given.
    #[serde(default)]
    pub total: Option<[f64; 3]>,
    /// The parts of `total`, informative.
    #[serde(default)]
    pub direct: Option<[f64; 3]>,
    #[serde(default)]
    pub indirect: Option<[f64; 3]>,
    /// Standard error of the indirect part (the direct part is exact up to its sampling).
    #[serde(default)]
    pub indirect_stderr: Option<[f64; 3]>,
    /// The object's area as the reference renderer saw it (informative).
    #[serde(default)]
    pub area: Option<f64>,
}

impl ReferenceObject {
    /// The irradiance compared: `total` when given, else `mean`.
    pub fn value(&self) -> [f64; 3] {
        self.total.or(self.mean).unwrap_or_default()
    }

    /// The standard error of [`Self::value`] as far as the file gives it.
    pub fn value_stderr(&self) -> [f64; 3] {
        self.indirect_stderr.unwrap_or(self.stderr)
    }
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
        if o.mean.is_none() && o.total.is_none() {
            return Err(Error::input(
                path,
                format!("object `{name}` has neither `mean` nor `total` irradiance"),
            ));
        }
        if o.value()
            .iter()
            .chain(&o.value_stderr())
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

/// The scene's punctual lights and what they give each object directly (by object name, merged
/// by area), when the reference compares total irradiance.
pub struct DirectLight {
    lights: Vec<GpuLight>,
    raycast: RaycastScene,
    per_object: BTreeMap<String, [f64; 3]>,
}

impl DirectLight {
    /// The direct part of `scene`'s lights, or None for a scene without punctual lights.
    pub fn of(scene: &Scene) -> Option<Self> {
        if scene.lights.is_empty() {
            return None;
        }
        let lights: Vec<GpuLight> = scene
            .lights
            .iter()
            .map(|l| GpuLight::from_light(l, 1.0, 0))
            .collect();
        let raycast = RaycastScene::for_visibility(scene);
        let direct = object_direct(scene, &lights, &raycast.visible(&lights));
        let area = object_areas(scene);
        let per_object = by_name(scene, &area, |o| direct[o]);
        Some(DirectLight {
            lights,
            raycast,
            per_object,
        })
    }
}

/// Each object's area.
fn object_areas(scene: &Scene) -> Vec<f64> {
    let mut area = vec![0f64; scene.objects.len()];
    for (t, &o) in scene.triangle_object.iter().enumerate() {
        area[o as usize] += scene.triangle_area(t) as f64;
    }
    area
}

/// Area-weighted means of `value(object)` over the objects of each name.
fn by_name(
    scene: &Scene,
    area: &[f64],
    value: impl Fn(usize) -> [f64; 3],
) -> BTreeMap<String, [f64; 3]> {
    let mut sums: BTreeMap<String, (f64, [f64; 3])> = BTreeMap::new();
    for (o, name) in scene.objects.iter().enumerate() {
        let e = sums.entry(name.clone()).or_default();
        let v = value(o);
        e.0 += area[o];
        for (acc, x) in e.1.iter_mut().zip(v) {
            *acc += area[o] * x;
        }
    }
    sums.into_iter()
        .map(|(k, (a, v))| (k, v.map(|x| x / a.max(f64::MIN_POSITIVE))))
        .collect()
}

/// A setting (errors, time, patches) and its per-object errors for one bake.
fn object_errors(
    scene: &Scene,
    resolution: Resolution,
    reference: &ObjectReference,
    measured: &[String],
    direct: Option<&DirectLight>,
) -> Result<(Setting, Vec<ObjectError>)> {
    let ff = FormFactorsKnobs::default().params();
    let b = bake_scene(scene, resolution, &ff, Bounces::Infinite)?;
    let e = match direct {
        None => emitted_exitance(&b.set),
        Some(d) => {
            let e = patch_exitance(
                &b.set,
                &d.lights,
                &FrameSettings::default(),
                &d.raycast.visible(&d.lights),
            );
            std::array::from_fn(|c| e.iter().map(|v| v[c] as f64).collect())
        }
    };
    let light = gathered(&b.transport, &e);
    let per_patch: Vec<[f32; 3]> = (0..b.set.len())
        .map(|i| std::array::from_fn(|c| light[c][i] as f32))
        .collect();
    let objects = object_light(scene, &b.set, &per_patch);
    let area = object_areas(scene);
    let corners = by_name(scene, &area, |o| objects[o].irradiance);
    let patches = by_name(scene, &area, |o| objects[o].irradiance_patches);
    let err = |got: [f64; 3], name: &str| {
        let r = reference[name].value();
        let d = match (direct, reference[name].total) {
            (Some(d), Some(_)) => d.per_object[name],
            _ => [0.0; 3],
        };
        (0..3).map(|c| (got[c] + d[c]) / r[c] - 1.0).sum::<f64>() / 3.0
    };
    let rows: Vec<ObjectError> = measured
        .iter()
        .map(|name| {
            (
                name.clone(),
                err(patches[name], name),
                err(corners[name], name),
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
    let area = object_areas(scene);
    let total: f64 = area.iter().sum();
    let (mut measured, mut notes) = (Vec::new(), Vec::new());
    for (name, r) in reference {
        if !scene.objects.iter().any(|o| o == name) {
            return Err(Error::input(
                source,
                format!(
                    "object `{name}` is not in the scene (its objects: {}); is this the reference of another scene?",
                    scene.objects.join(", ")
                ),
            ));
        }
        let named: f64 = (0..area.len())
            .filter(|&o| &scene.objects[o] == name)
            .map(|o| area[o])
            .sum();
        let share = named / total.max(f64::MIN_POSITIVE);
        if share < min_area_share {
            notes.push(format!(
                "`{name}` ({:.2} % of the area) is under the {:.1} % measured.",
                100.0 * share,
                100.0 * min_area_share
            ));
        } else if r.value().iter().any(|&v| v <= 0.0) {
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
    // Punctual lights count only against a reference of total irradiance.
    let direct = if reference.values().any(|r| r.total.is_some()) {
        DirectLight::of(scene)
    } else {
        None
    };
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
            let (mut s, rows) =
                object_errors(scene, resolution, reference, &measured, direct.as_ref())?;
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
            "RMS over objects",
            "object_irradiance",
            "rms",
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
        let (v, e) = (r.value(), r.value_stderr());
        let se = (0..3).map(|c| e[c] / v[c]).sum::<f64>() / 3.0;
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
