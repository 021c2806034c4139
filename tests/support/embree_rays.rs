//! The rays of the form-factor stage (hemisphere rays, pairwise segments), with the BVH's
//! triangles, written as `.npy` for Embree (`embreex`): shared by `tests/radiosity/visibility_embree.rs`
//! (agreement) and `benches/visibility_embree.rs` (speed).

use glam::DVec3;
use relume::radiosity::formfactor::{hemisphere, pairwise, Context};
use relume::radiosity::patches::voxelize::{voxelize, Resolution, VoxelizeParams};
use relume::scene::Scene;
use std::path::Path;

/// The form-factor context of `scene`'s patches (about `target`, one sample per patch).
pub fn context(scene: &Scene, target: u32) -> Context {
    let set = voxelize(
        scene,
        &VoxelizeParams {
            resolution: Resolution::TargetPatches(target),
            samples_per_patch: 1,
        },
    )
    .unwrap();
    Context::new(scene, &set)
}

/// The patches of `scene` (about `target`), their form-factor context and the `k` hemisphere
/// rays of every patch (`hemisphere::rays`, random stream `seed`).
pub fn hemisphere_rays(
    scene: &Scene,
    target: u32,
    k: usize,
    seed: u64,
) -> (Context, Vec<(DVec3, DVec3)>) {
    let ctx = context(scene, target);
    let rays = (0..ctx.samplers.len())
        .flat_map(|i| hemisphere::rays(&ctx, i, k, seed))
        .collect();
    (ctx, rays)
}

/// Write `v` (f32, shape `shape`) as `name` into `dir`.
fn write_f32(dir: &Path, name: &str, shape: &[u64], v: &[f32]) {
    relume::baked::npy::write_npy_f32(&dir.join(name), shape, v).unwrap()
}

/// Write `tris.npy` (`[m, 3, 3]`, the BVH's triangles in grid coordinates) into `dir`; returns
/// them as (scene index, vertices), in the order Embree numbers them.
pub fn write_triangles(dir: &Path, ctx: &Context) -> (Vec<u32>, Vec<[[f32; 3]; 3]>) {
    let (ids, tris): (Vec<u32>, Vec<[[f32; 3]; 3]>) = ctx.vis.triangles().unzip();
    let flat: Vec<f32> = tris.iter().flatten().flatten().copied().collect();
    write_f32(dir, "tris.npy", &[tris.len() as u64, 3, 3], &flat);
    (ids, tris)
}

/// Write the triangles ([`write_triangles`]), `origins.npy` and `dirs.npy` (`[n, 3]`, f32)
/// into `dir`; returns the triangles as [`write_triangles`] does.
pub fn write_for_embree(
    dir: &Path,
    ctx: &Context,
    rays: &[(DVec3, DVec3)],
) -> (Vec<u32>, Vec<[[f32; 3]; 3]>) {
    let triangles = write_triangles(dir, ctx);
    // Embree gets each ray from its origin in f32 (relume rounds its backed-off start to f32
    // separately: see tests/radiosity/visibility_embree.rs for what that allows).
    let f32_rays = f32_rays(rays);
    let o: Vec<f32> = f32_rays.iter().flat_map(|r| r.0).collect();
    let d: Vec<f32> = f32_rays.iter().flat_map(|r| r.1).collect();
    let n = rays.len() as u64;
    write_f32(dir, "origins.npy", &[n, 3], &o);
    write_f32(dir, "dirs.npy", &[n, 3], &d);
    triangles
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
    for (from, dir, len) in f32_segments(segments) {
        o.extend(from);
        d.extend(dir);
        l.push(len);
    }
    let n = segments.len() as u64;
    write_f32(dir, "seg_origins.npy", &[n, 3], &o);
    write_f32(dir, "seg_dirs.npy", &[n, 3], &d);
    write_f32(dir, "seg_lengths.npy", &[n], &l);
}

/// The rays as f32 (origin, unit direction): exactly what [`write_for_embree`] writes.
pub fn f32_rays(rays: &[(DVec3, DVec3)]) -> Vec<([f32; 3], [f32; 3])> {
    rays.iter()
        .map(|(o, d)| (o.as_vec3().to_array(), d.as_vec3().to_array()))
        .collect()
}

/// The segments as f32 (origin, unit direction, length): exactly what [`write_segments`]
/// writes.
pub fn f32_segments(segments: &[(DVec3, DVec3)]) -> Vec<([f32; 3], [f32; 3], f32)> {
    segments
        .iter()
        .map(|(from, to)| {
            let delta = *to - *from;
            (
                from.as_vec3().to_array(),
                delta.normalize().as_vec3().to_array(),
                delta.length() as f32,
            )
        })
        .collect()
}
