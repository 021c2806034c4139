//! The hemisphere rays of the form-factor stage, with the BVH's triangles, written as `.npy`
//! for Embree (`embreex`): shared by `tests/visibility_embree.rs` (agreement) and
//! `benches/visibility_embree.rs` (speed).

use glam::DVec3;
use relume::radiosity::formfactor::{hemisphere, pairwise, Context};
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

/// The occlusion segments the pairwise estimator tests (`pairwise::pair_rays`, `k` point
/// pairs per patch pair, random stream `seed`) for `partners` pairs per patch: patch i with
/// the patches `(i + 1 + r·n / partners) mod n`, r = 0..partners — spread over the scene, the
/// same pairs on every run.
pub fn pairwise_segments(
    ctx: &Context,
    partners: usize,
    k: usize,
    seed: u64,
) -> Vec<(DVec3, DVec3)> {
    let n = ctx.samplers.len();
    (0..n)
        .flat_map(|i| {
            (0..partners).flat_map(move |r| {
                let j = (i + 1 + r * n / partners) % n;
                let (i, j) = (i.min(j), i.max(j));
                pairwise::pair_rays(ctx, i, j, k, seed)
                    .rays
                    .into_iter()
                    .map(|r| (r.from, r.to))
            })
        })
        .collect()
}

/// Write the segments as `seg_origins.npy`, `seg_dirs.npy` (unit, f32) and `seg_lengths.npy`
/// into `dir`, for Embree's occlusion query from the origin to the length.
pub fn write_segments(dir: &Path, segments: &[(DVec3, DVec3)]) {
    let mut o = Vec::new();
    let mut d = Vec::new();
    let mut l = Vec::new();
    for (from, to) in segments {
        let delta = *to - *from;
        o.extend(from.as_vec3().to_array());
        d.extend(delta.normalize().as_vec3().to_array());
        l.push(delta.length() as f32);
    }
    let n = segments.len() as u64;
    let write = |f: &str, shape: &[u64], v: &[f32]| {
        relume::baked::npy::write_npy_f32(&dir.join(f), shape, v).unwrap()
    };
    write("seg_origins.npy", &[n, 3], &o);
    write("seg_dirs.npy", &[n, 3], &d);
    write("seg_lengths.npy", &[n], &l);
}
