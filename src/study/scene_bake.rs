//! A scene baked in memory for a study: voxelize → form factors → transport, each step timed,
//! and the light of the scene's own emitters gathered through it (shared by the radiosity,
//! per-object and compression sweeps).

use super::timing::timed;
use crate::error::Result;
use crate::limits::default_max_memory;
use crate::progress::Silent;
use crate::radiosity::formfactor::{form_factors, FormFactorParams, FormFactors};
use crate::radiosity::patches::voxelize::{voxelize, Resolution, VoxelizeParams};
use crate::radiosity::transport::{transport, Bounces, Power, Transport, TransportParams};
use crate::radiosity::PatchSet;
use crate::scene::Scene;

/// Patches, form factors and transport of a scene, with the time of each step.
pub struct SceneBake {
    pub set: PatchSet,
    pub f: FormFactors,
    pub transport: Transport,
    pub voxelize_seconds: f64,
    pub form_factor_seconds: f64,
    pub transport_seconds: f64,
}

/// Voxelize (4 direct-light points per patch), estimate form factors and compute the transport.
pub fn bake_scene(
    scene: &Scene,
    resolution: Resolution,
    ff: &FormFactorParams,
    bounces: Bounces,
) -> Result<SceneBake> {
    let (set, voxelize_seconds) = timed(|| {
        voxelize(
            scene,
            &VoxelizeParams {
                resolution,
                samples_per_patch: 4,
            },
        )
    });
    let set = set?;
    let (f, form_factor_seconds) = timed(|| form_factors(scene, &set, ff, &Silent));
    let f = f?;
    let (t, transport_seconds) = timed(|| transport_of(&set, &f, bounces));
    Ok(SceneBake {
        transport: t?,
        set,
        f,
        voxelize_seconds,
        form_factor_seconds,
        transport_seconds,
    })
}

/// The transport of `f` over the patches of `set` (power Auto, the default memory budget).
pub fn transport_of(set: &PatchSet, f: &FormFactors, bounces: Bounces) -> Result<Transport> {
    let albedo: Vec<[f32; 3]> = set.patches.iter().map(|p| p.albedo).collect();
    transport(
        &f.values,
        f.n,
        &albedo,
        &TransportParams {
            bounces,
            power: Power::Auto,
            max_memory: default_max_memory(),
            solver: Default::default(),
        },
        &Silent,
    )
}

/// Emitted exitance `E = π·L` of every patch, `[3][n]`.
pub fn emitted_exitance(set: &PatchSet) -> [Vec<f64>; 3] {
    std::array::from_fn(|c| {
        set.patches
            .iter()
            .map(|p| std::f64::consts::PI * p.emission[c] as f64)
            .collect()
    })
}

/// Gathered indirect light `S·E` per channel, `[3][n]`.
pub fn gathered(t: &Transport, e: &[Vec<f64>; 3]) -> [Vec<f64>; 3] {
    std::array::from_fn(|c| t.matrix.apply(c, &e[c]))
}
