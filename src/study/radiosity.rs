//! Radiosity sweeps (docs/algorithms.md §7): patch count, form-factor estimator × samples, bounces.
//!
//! The light measured is the gathered indirect exitance `B = S·E` of the scene's own emitters
//! (`E_i = π·L_i` per channel, docs/algorithms.md §9), per patch and colour channel.
//!
//! - **patches**: `voxelize` at each target patch count, then hemisphere form factors and
//!   infinite bounces. Reference: the densest setting. Patch sets differ, so B is compared at
//!   the reference's direct-light sample points (`PatchSet::samples`, on the surfaces): each
//!   point takes the value of the patch that contains it in each setting ([`PatchLocator`]),
//!   weighted by its share of the reference patch's area.
//! - **estimator**: one patch set; hemisphere and pairwise form factors at several sample
//!   counts; infinite bounces. Reference: hemisphere at the most samples. Errors of F itself
//!   (the radiosity thesis's summed error included) and of B per patch (area-weighted).
//! - **bounces**: one patch set and F; `Finite(k)`, `Infinite`, `Auto(tol)`. Reference: the f64
//!   Gauss–Seidel solution of `B = E + diag(ρ) F B` ([`crate::radiosity::transport::reference`]).

use super::radiosity_objects::{objects_sweep, ObjectReference, ObjectsConfig};
use super::scene_bake::{bake_scene, emitted_exitance, gathered, transport_of, SceneBake};
use super::timing::timed;
use super::{Column, ErrorStats, Format, Measure, Setting, Sweep};
use crate::error::{Error, Result};
use crate::pipeline::knobs::{FormFactorsKnobs, TransportKnobs, VoxelizeKnobs};
use crate::progress::{Progress, Silent};
use crate::radiosity::formfactor::locate::PatchLocator;
use crate::radiosity::formfactor::{form_factors, Estimator, FormFactorParams, FormFactors};
use crate::radiosity::geometry::dominant_axis;
use crate::radiosity::patches::voxelize::{voxelize, Resolution, VoxelizeParams};
use crate::radiosity::transport::reference::{gauss_seidel, indirect};
use crate::radiosity::transport::Bounces;
use crate::radiosity::PatchSet;
use crate::scene::Scene;
use glam::DVec3;

/// What the radiosity sweeps run.
#[derive(Clone, Debug, PartialEq)]
pub struct RadiosityConfig {
    /// Target patch counts of the patch sweep (the largest is the reference).
    pub patch_targets: Vec<u32>,
    /// Hemisphere rays per patch in the patch sweep.
    pub patch_sweep_samples: u32,
    /// Target patch count of the estimator and bounces sweeps.
    pub fixed_patches: u32,
    /// Hemisphere rays per patch to sweep (the largest is the baseline, and its form factors
    /// feed the bounces sweep).
    pub hemisphere_samples: Vec<u32>,
    /// Pairwise point pairs per patch pair to sweep.
    pub pairwise_samples: Vec<u32>,
    /// Hemisphere rays per patch of the estimator sweep's reference.
    pub reference_samples: u32,
    pub bounces: Vec<Bounces>,
    /// Seed of the form-factor estimators.
    pub seed: u64,
    /// Which sweeps run, in this order.
    pub sweeps: Vec<RadiositySweep>,
    /// The per-object sweep's reference (and the file it came from) and knobs.
    pub objects: Option<ObjectsStudy>,
}

/// One sweep of the radiosity study.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RadiositySweep {
    Patches,
    Estimator,
    Bounces,
    /// Per-object irradiance against an independent renderer, uniform vs adaptive patches.
    Objects,
}

/// The per-object sweep's inputs.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectsStudy {
    pub reference: ObjectReference,
    pub source: std::path::PathBuf,
    pub config: ObjectsConfig,
}

impl RadiosityConfig {
    /// The full study (minutes on 2 cores for the Cornell box).
    pub fn full() -> Self {
        RadiosityConfig {
            patch_targets: vec![150, 600, 1000, 2400],
            patch_sweep_samples: 2048,
            fixed_patches: 600,
            hemisphere_samples: vec![256, 1024, 4096],
            pairwise_samples: vec![4, 16, 64],
            reference_samples: 16384,
            bounces: standard_bounces(),
            seed: 0,
            sweeps: standard_sweeps(),
            objects: None,
        }
    }

    /// Small sizes: seconds.
    pub fn quick() -> Self {
        RadiosityConfig {
            patch_targets: vec![50, 150, 400],
            patch_sweep_samples: 512,
            fixed_patches: 150,
            hemisphere_samples: vec![64, 256, 1024],
            pairwise_samples: vec![4, 16],
            reference_samples: 4096,
            bounces: standard_bounces(),
            seed: 0,
            sweeps: standard_sweeps(),
            objects: None,
        }
    }
}

fn standard_sweeps() -> Vec<RadiositySweep> {
    vec![
        RadiositySweep::Patches,
        RadiositySweep::Estimator,
        RadiositySweep::Bounces,
    ]
}

fn standard_bounces() -> Vec<Bounces> {
    vec![
        Bounces::Finite(1),
        Bounces::Finite(2),
        Bounces::Finite(3),
        Bounces::Finite(8),
        Bounces::Infinite,
        Bounces::Auto(1e-3),
    ]
}

/// Channel-major flattening of a per-patch RGB quantity, and the matching area weights.
fn flat(b: &[Vec<f64>; 3]) -> Vec<f64> {
    b.concat()
}

fn area_weights(set: &PatchSet) -> Vec<f64> {
    let a: Vec<f64> = set.patches.iter().map(|p| p.area as f64).collect();
    [a.clone(), a.clone(), a].concat()
}

/// The radiosity sweeps `cfg.sweeps` names on `scene` (the bounces sweep runs on the estimator
/// sweep's patches and form factors, so it runs that sweep too).
pub fn run(scene: &Scene, cfg: &RadiosityConfig, progress: &dyn Progress) -> Result<Vec<Sweep>> {
    let wants = |s| cfg.sweeps.contains(&s);
    let objects = match (&cfg.objects, wants(RadiositySweep::Objects)) {
        (Some(o), true) => Some(o),
        (None, true) => return Err(Error::knob(
            "the per-object sweep needs a reference of per-object irradiance (--objects-reference FILE)",
        )),
        _ => None,
    };
    let mut out = Vec::new();
    if wants(RadiositySweep::Patches) {
        out.push(patch_sweep(scene, cfg, progress)?);
    }
    if wants(RadiositySweep::Estimator) || wants(RadiositySweep::Bounces) {
        let (estimator, set, f) = estimator_sweep(scene, cfg, progress)?;
        if wants(RadiositySweep::Estimator) {
            out.push(estimator);
        }
        if wants(RadiositySweep::Bounces) {
            out.push(bounce_sweep(&set, &f, cfg, progress)?);
        }
    }
    if let Some(o) = objects {
        out.push(objects_sweep(
            scene,
            &o.reference,
            &o.source,
            &o.config,
            progress,
        )?);
    }
    Ok(out)
}

/// The patch-count sweep.
pub fn patch_sweep(scene: &Scene, cfg: &RadiosityConfig, progress: &dyn Progress) -> Result<Sweep> {
    let mut targets = cfg.patch_targets.clone();
    targets.sort_unstable();
    targets.dedup();
    let ff = FormFactorParams {
        estimator: Estimator::Hemisphere,
        samples: cfg.patch_sweep_samples,
        seed: cfg.seed,
    };
    progress.begin("study: patches", targets.len() as u64);
    let mut bakes = Vec::new();
    for &t in &targets {
        let b = bake_scene(scene, Resolution::TargetPatches(t), &ff, Bounces::Infinite)?;
        let light = gathered(&b.transport, &emitted_exitance(&b.set));
        bakes.push((t, b, light));
        progress.advance(1);
    }
    progress.finish();
    // Reference points: the densest set's direct-light samples.
    let (_, reference, _) = bakes.last().expect("at least one patch target");
    let rset = &reference.set;
    let spp = rset.samples_per_patch.max(1) as usize;
    let points: Vec<(glam::Vec3, u8, f64)> = rset
        .samples
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let axis = dominant_axis(DVec3::from(s.normal.map(|v| v as f64)));
            let w = rset.patches[k / spp].area as f64 / spp as f64;
            (glam::Vec3::from(s.position), axis, w)
        })
        .collect();
    let values_at_points = |b: &SceneBake, light: &[Vec<f64>; 3]| -> Vec<Option<[f64; 3]>> {
        let loc = PatchLocator::new(&b.set, scene);
        let frame = b.set.frame();
        points
            .iter()
            .map(|(p, axis, _)| {
                loc.locate(frame.to_grid(p.to_array()), *axis)
                    .map(|i| std::array::from_fn(|c| light[c][i as usize]))
            })
            .collect()
    };
    let (_, rb, rl) = bakes.last().unwrap();
    let reference_values = values_at_points(rb, rl);
    let max_target = *targets.last().unwrap();
    let mut sweep = Sweep {
        name: "radiosity_patches".into(),
        title: "Radiosity: patch count".into(),
        description: format!(
            "voxelize TargetPatches(n) for n in {targets:?}; hemisphere form factors, {} rays per patch, seed {}; infinite bounces",
            cfg.patch_sweep_samples, cfg.seed
        ),
        reference: format!(
            "the densest setting (target {max_target}); B = S·E of the scene's emitters compared at the reference's {} direct-light sample points, each taking the value of the patch that contains it, weighted by area",
            points.len()
        ),
        baseline: String::new(),
        time: "voxelize + form factors + transport".into(),
        bytes: "transport.npy payload, channels·n²·4".into(),
        ..Default::default()
    };
    for (t, b, light) in &bakes {
        let values = values_at_points(b, light);
        let (mut a, mut r, mut w) = (vec![Vec::new(); 3], vec![Vec::new(); 3], Vec::new());
        let mut unlocated = 0u64;
        for ((v, rv), (_, _, wk)) in values.iter().zip(&reference_values).zip(&points) {
            match (v, rv) {
                (Some(v), Some(rv)) => {
                    for c in 0..3 {
                        a[c].push(v[c]);
                        r[c].push(rv[c]);
                    }
                    w.push(*wk);
                }
                _ => unlocated += 1,
            }
        }
        let weights = [w.clone(), w.clone(), w].concat();
        let mut s = Setting::new(format!("target {t}"), "hemisphere")
            .default_if(VoxelizeKnobs::default().resolution == Resolution::TargetPatches(*t))
            .knob("target_patches", *t)
            .knob("estimator", "Hemisphere")
            .knob("samples", cfg.patch_sweep_samples)
            .knob("bounces", "Infinite");
        s.reference = *t == max_target;
        s.errors.insert(
            "gathered_light".into(),
            ErrorStats::of(&a.concat(), &r.concat(), Some(&weights)),
        );
        s.seconds = b.voxelize_seconds + b.form_factor_seconds + b.transport_seconds;
        s.bytes = (b.transport.matrix.channels * b.set.len() * b.set.len() * 4) as u64;
        for (k, v) in [
            ("patches", b.set.len() as f64),
            ("rays", b.f.rays as f64),
            ("voxelize_seconds", b.voxelize_seconds),
            ("form_factor_seconds", b.form_factor_seconds),
            ("transport_seconds", b.transport_seconds),
            ("unlocated_points", unlocated as f64),
        ] {
            s.extra.insert(k.into(), v);
        }
        sweep.settings.push(s);
    }
    // Baseline: the middle setting (the bundled pipeline's size in the full study).
    sweep.baseline = sweep.settings[(sweep.settings.len() - 1) / 2].label.clone();
    sweep.columns = vec![
        Column::extra("patches", "patches", Format::Count, false),
        Column::gathered_light("B rms rel"),
        Column::error("B mean abs", "gathered_light", "mean", Format::Sci, false),
        Column::error("B max abs", "gathered_light", "max", Format::Sci, false),
        Column::new("time", Measure::Seconds, Format::Time, true),
        Column::new("bytes", Measure::Bytes, Format::Bytes, true),
    ];
    sweep.notes.push(
        "The error mixes discretisation (patches are flat-shaded) with the Monte Carlo noise of the form factors.".into(),
    );
    gathered_light_plots(&mut sweep);
    Ok(sweep)
}

/// The estimator × samples sweep. Also returns the patch set and the baseline's form factors
/// (for the bounces sweep).
pub fn estimator_sweep(
    scene: &Scene,
    cfg: &RadiosityConfig,
    progress: &dyn Progress,
) -> Result<(Sweep, PatchSet, FormFactors)> {
    let set = voxelize(
        scene,
        &VoxelizeParams {
            resolution: Resolution::TargetPatches(cfg.fixed_patches),
            samples_per_patch: 4,
        },
    )?;
    let mut runs: Vec<(Estimator, u32, bool)> = Vec::new();
    let mut hemi = cfg.hemisphere_samples.clone();
    hemi.sort_unstable();
    hemi.dedup();
    hemi.retain(|&s| s != cfg.reference_samples);
    runs.extend(hemi.iter().map(|&s| (Estimator::Hemisphere, s, false)));
    runs.extend(
        hemi.iter()
            .map(|&s| (Estimator::HemisphereReciprocal, s, false)),
    );
    let mut pair = cfg.pairwise_samples.clone();
    pair.sort_unstable();
    pair.dedup();
    runs.extend(pair.iter().map(|&s| (Estimator::Pairwise, s, false)));
    runs.push((Estimator::Hemisphere, cfg.reference_samples, true));
    let e = emitted_exitance(&set);
    let weights = area_weights(&set);
    progress.begin("study: estimator", runs.len() as u64);
    let mut measured = Vec::new();
    for &(estimator, samples, is_ref) in &runs {
        let params = FormFactorParams {
            estimator,
            samples,
            seed: cfg.seed,
        };
        let (f, secs) = timed(|| form_factors(scene, &set, &params, &Silent));
        let f = f?;
        let (t, t_secs) = timed(|| transport_of(&set, &f, Bounces::Infinite));
        let light = flat(&gathered(&t?, &e));
        measured.push((estimator, samples, is_ref, f, secs, t_secs, light));
        progress.advance(1);
    }
    progress.finish();
    let (.., ref_f, _, _, ref_light) = measured.last().unwrap();
    let n = set.len();
    let mut sweep = Sweep {
        name: "radiosity_estimator".into(),
        title: "Radiosity: form-factor estimator".into(),
        description: format!(
            "{n} patches (target {}); hemisphere rays per patch {hemi:?} (plain and with reciprocity averaging), pairwise point pairs per patch pair {pair:?}, seed {}; infinite bounces",
            cfg.fixed_patches, cfg.seed
        ),
        reference: format!(
            "hemisphere with {} rays per patch; errors of F (all n² entries) and of B = S·E of the scene's emitters per patch (area-weighted)",
            cfg.reference_samples
        ),
        time: "form factors".into(),
        bytes: "form_factors.npy payload, n²·4".into(),
        ..Default::default()
    };
    for (estimator, samples, is_ref, f, secs, t_secs, light) in &measured {
        let name = match estimator {
            Estimator::HemisphereReciprocal => "hemisphere reciprocal".to_string(),
            e => format!("{e:?}").to_lowercase(),
        };
        let ff = FormFactorsKnobs::default();
        let mut s = Setting::new(format!("{name} {samples}"), name.clone())
            .default_if(*estimator == ff.estimator && *samples == ff.samples())
            .knob("estimator", format!("{estimator:?}"))
            .knob("samples", *samples)
            .knob("target_patches", cfg.fixed_patches)
            .knob("bounces", "Infinite");
        s.reference = *is_ref;
        s.errors.insert(
            "form_factors".into(),
            ErrorStats::of_matrix(&f.values, &ref_f.values),
        );
        s.errors.insert(
            "gathered_light".into(),
            ErrorStats::of(light, ref_light, Some(&weights)),
        );
        s.seconds = *secs;
        s.bytes = (n * n * 4) as u64;
        s.extra.insert("patches".into(), n as f64);
        s.extra.insert("rays".into(), f.rays as f64);
        s.extra.insert("transport_seconds".into(), *t_secs);
        sweep.settings.push(s);
    }
    sweep.baseline = match hemi.last() {
        Some(s) => format!("hemisphere {s}"),
        None => sweep.settings.last().unwrap().label.clone(),
    };
    let baseline_f = measured
        .iter()
        .find(|m| format!("{:?} {}", m.0, m.1).to_lowercase() == sweep.baseline)
        .map(|m| m.3.clone())
        .unwrap();
    sweep.columns = vec![
        Column::extra("rays", "rays", Format::Count, false),
        Column::gathered_light("B rms rel"),
        Column::error("F mean abs", "form_factors", "mean", Format::Sci, false),
        Column::error("F max abs", "form_factors", "max", Format::Sci, false),
        Column::error("F summed abs", "form_factors", "sum", Format::Sci, true),
        Column::new("time", Measure::Seconds, Format::Time, true),
    ];
    sweep.notes.push(
        "The reference is itself a Monte Carlo estimate: errors far below its own noise (about 1/sqrt(rays per patch)) are not resolved.".into(),
    );
    gathered_light_plots(&mut sweep);
    Ok((sweep, set, baseline_f))
}

/// The bounces sweep on a given patch set and form factors.
pub fn bounce_sweep(
    set: &PatchSet,
    f: &FormFactors,
    cfg: &RadiosityConfig,
    progress: &dyn Progress,
) -> Result<Sweep> {
    let n = set.len();
    let e = emitted_exitance(set);
    let weights = area_weights(set);
    progress.begin("study: bounces", cfg.bounces.len() as u64 + 1);
    // Reference: Gauss–Seidel in f64, per channel.
    let (reference, gs_seconds) = timed(|| -> Result<(Vec<f64>, u32)> {
        let mut out = Vec::with_capacity(3 * n);
        let mut sweeps = 0;
        for (c, ec) in e.iter().enumerate() {
            let rho: Vec<f64> = set.patches.iter().map(|p| p.albedo[c] as f64).collect();
            let sol = gauss_seidel(&f.values, &rho, ec, 1e-12, 100_000)?;
            sweeps = sweeps.max(sol.sweeps);
            out.extend(indirect(&sol, ec));
        }
        Ok((out, sweeps))
    });
    let (reference, gs_sweeps) = reference?;
    progress.advance(1);
    let mut sweep = Sweep {
        name: "radiosity_bounces".into(),
        title: "Radiosity: bounces".into(),
        description: format!(
            "{n} patches, the estimator sweep's baseline form factors; transport with bounces {}",
            cfg.bounces
                .iter()
                .map(|b| format!("{b:?}"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        reference: "B − E of the f64 Gauss–Seidel solution of B = E + diag(ρ) F B (relative tolerance 1e-12) for the scene's emitters, per patch, area-weighted".into(),
        baseline: "k = inf".into(),
        time: "transport (Gauss–Seidel: the solve for this one E)".into(),
        bytes: "transport.npy payload, channels·n²·4".into(),
        ..Default::default()
    };
    let mut gs = Setting::new("gauss-seidel f64", "reference").knob("bounces", "reference");
    gs.reference = true;
    gs.errors.insert(
        "gathered_light".into(),
        ErrorStats::of(&reference, &reference, Some(&weights)),
    );
    gs.seconds = gs_seconds;
    gs.extra
        .insert("gauss_seidel_sweeps".into(), gs_sweeps as f64);
    sweep.settings.push(gs);
    for &b in &cfg.bounces {
        let (t, secs) = timed(|| transport_of(set, f, b));
        let t = t?;
        let light = flat(&gathered(&t, &e));
        let (label, series) = match b {
            Bounces::Finite(k) => (format!("k = {k}"), "finite"),
            Bounces::Infinite => ("k = inf".to_string(), "infinite"),
            Bounces::Auto(tol) => (format!("auto {tol:e}"), "auto"),
        };
        let mut s = Setting::new(label, series)
            .default_if(b == TransportKnobs::default().bounces)
            .knob("bounces", format!("{b:?}"));
        s.errors.insert(
            "gathered_light".into(),
            ErrorStats::of(&light, &reference, Some(&weights)),
        );
        s.seconds = secs;
        s.bytes = (t.matrix.channels * n * n * 4) as u64;
        s.extra.insert("products".into(), t.products as f64);
        s.extra.insert(
            "bounces_accumulated".into(),
            t.bounces.iter().copied().max().unwrap_or(0) as f64,
        );
        sweep.settings.push(s);
        progress.advance(1);
    }
    progress.finish();
    sweep.columns = vec![
        Column::error("B rms rel", "gathered_light", "rms_rel", Format::Sci, true),
        Column::error("B max abs", "gathered_light", "max", Format::Sci, false),
        Column::extra("GEMMs", "products", Format::Count, false),
        Column::new("time", Measure::Seconds, Format::Time, true),
    ];
    sweep.notes.push(
        "k = inf is exact up to f32 rounding of S; finite k misses the light of the bounces it leaves out (bounces_accumulated is 0 for k = inf).".into(),
    );
    gathered_light_plots(&mut sweep);
    Ok(sweep)
}

/// Error of the gathered light against time (and bytes, where they differ).
fn gathered_light_plots(sweep: &mut Sweep) {
    sweep.error_plots(
        Measure::error("gathered_light", "rms_rel"),
        "B = S.E RMS relative error",
    );
}
