//! Bake a bundled room scene in memory at a patch target (voxelize → reciprocal hemisphere form
//! factors, 4096 rays → infinite bounces) and return its per-object light; shared by
//! `tests/radiosity/rooms.rs` and `benches/rooms_mitsuba.rs`.
#![allow(dead_code)]

use relume::progress::Silent;
use relume::radiosity::formfactor::{form_factors, Estimator, FormFactorParams};
use relume::radiosity::mesh::objects::{object_light, ObjectLight};
use relume::radiosity::patches::voxelize::{voxelize, Resolution, VoxelizeParams};
use relume::radiosity::transport::{transport, Bounces, Power, TransportParams};
use relume::render::direct::gather_dense;
use relume::scene::Scene;

/// The scene `scenes/generated/NAME.obj`, or the Cornell box (in metres) for "cornell".
pub fn room(name: &str) -> Scene {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let (path, scale) = match name {
        "cornell" => (root.join("scenes/cornell-box/cornell_box.obj"), 0.001),
        _ => (root.join(format!("scenes/generated/{name}.obj")), 1.0),
    };
    relume::scene::load_scene(&path, relume::scene::SceneOptions { scale })
        .unwrap()
        .0
}

/// Per-object light of `scene` lit by its emitters, and the patch count.
pub fn object_light_at(scene: &Scene, target: u32) -> (Vec<ObjectLight>, usize) {
    object_light_with(scene, Resolution::TargetPatches(target))
}

/// [`object_light_at`] with any voxel resolution (e.g. adaptive patches).
pub fn object_light_with(scene: &Scene, resolution: Resolution) -> (Vec<ObjectLight>, usize) {
    object_light_by(
        scene,
        resolution,
        &FormFactorParams {
            estimator: Estimator::HemisphereReciprocal,
            samples: 4096,
            seed: 0,
        },
    )
}

/// [`object_light_with`] with any form-factor estimator.
pub fn object_light_by(
    scene: &Scene,
    resolution: Resolution,
    ff: &FormFactorParams,
) -> (Vec<ObjectLight>, usize) {
    let set = voxelize(
        scene,
        &VoxelizeParams {
            resolution,
            samples_per_patch: 1,
        },
    )
    .unwrap();
    let f = form_factors(scene, &set, ff, &Silent).unwrap();
    let albedo: Vec<[f32; 3]> = set.patches.iter().map(|p| p.albedo).collect();
    let s = transport(
        &f.values,
        f.n,
        &albedo,
        &TransportParams {
            bounces: Bounces::Infinite,
            power: Power::Auto,
            max_memory: u64::MAX,
            solver: Default::default(),
        },
        &Silent,
    )
    .unwrap();
    let e: Vec<[f32; 3]> = set
        .patches
        .iter()
        .map(|p| p.emission.map(|l| std::f32::consts::PI * l))
        .collect();
    let b = gather_dense(&s.matrix.data, s.matrix.channels, f.n, &e);
    (object_light(scene, &set, &b), set.patches.len())
}

/// Relative error of `got` against a Mitsuba reference entry, per channel.
pub fn relative_error(got: [f64; 3], reference: &serde_json::Value) -> [f64; 3] {
    std::array::from_fn(|c| got[c] / reference["mean"][c].as_f64().unwrap() - 1.0)
}
