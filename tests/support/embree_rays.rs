//! The hemisphere rays of the form-factor stage, with the BVH's triangles, written as `.npy`
//! for Embree (`embreex`): shared by `tests/visibility_embree.rs` (agreement) and
//! `benches/visibility_embree.rs` (speed).

use glam::DVec3;
use relume::radiosity::formfactor::{hemisphere, Context};
use relume::radiosity::voxelize::{voxelize, Resolution, VoxelizeParams};
use relume::scene::Scene;
use std::path::Path;

/// The patches of `scene` (about `target`), their form-factor context and the `k` hemisphere
/// rays of every patch (`hemisphere::rays`, random stream `seed`).
pub fn hemisphere_rays(
    scene: &Scene,
    target: u32,
    k: usize,
    seed: u64,
) -> (Context, Vec<(DVec3, DVec3)>) {
    let set = voxelize(
        scene,
        &VoxelizeParams {
            resolution: Resolution::TargetPatches(target),
            samples_per_patch: 1,
        },
    )
    .unwrap();
    let ctx = Context::new(scene, &set);
    let rays = (0..set.len())
        .flat_map(|i| hemisphere::rays(&ctx, i, k, seed))
        .collect();
    (ctx, rays)
}

/// Write `tris.npy` (`[m, 3, 3]`, the BVH's triangles in grid coordinates), `origins.npy` and
/// `dirs.npy` (`[n, 3]`, f32) into `dir`; returns the BVH's triangles as (scene index,
/// vertices), in the order Embree numbers them.
pub fn write_for_embree(
    dir: &Path,
    ctx: &Context,
    rays: &[(DVec3, DVec3)],
) -> (Vec<u32>, Vec<[[f32; 3]; 3]>) {
    let write = |f: &str, shape: &[u64], v: &[f32]| {
        relume::baked::npy::write_npy_f32(&dir.join(f), shape, v).unwrap()
    };
    let (ids, tris): (Vec<u32>, Vec<[[f32; 3]; 3]>) = ctx.vis.triangles().unzip();
    let flat: Vec<f32> = tris.iter().flatten().flatten().copied().collect();
    write("tris.npy", &[tris.len() as u64, 3, 3], &flat);
    // Embree gets each ray from its origin in f32 (relume rounds its backed-off start to f32
    // separately: see tests/visibility_embree.rs for what that allows).
    let o: Vec<f32> = rays
        .iter()
        .flat_map(|(o, _)| o.as_vec3().to_array())
        .collect();
    let d: Vec<f32> = rays
        .iter()
        .flat_map(|(_, d)| d.as_vec3().to_array())
        .collect();
    let n = rays.len() as u64;
    write("origins.npy", &[n, 3], &o);
    write("dirs.npy", &[n, 3], &d);
    (ids, tris)
}
