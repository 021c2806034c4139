//! relume's tracer against Embree 4 (`embreex` on PyPI, a cross-check tool) on the same rays,
//! written with the triangles to `.npy` and traced by both in the same run, Mrays/s at 1 and 2
//! threads:
//! - the exact hemisphere rays the form-factor stage casts (`hemisphere::rays`): closest hit,
//!   and occlusion to the closest hit's distance (so every occluded ray is also a hit for
//!   Embree, and its occluder lies at the segment's very end);
//! - the exact occlusion segments the pairwise estimator casts (`pairwise::pair_rays`, 16 point
//!   pairs per patch pair, four partner patches per patch spread over the scene): occlusion
//!   where the occluder, if any, lies anywhere between two surfaces.
//!
//! relume traces the same f32 rays Embree gets (`Ray::from_f32`: origin, direction and length
//! as written to the `.npy` files). A third table times the stage's own entry points on the
//! same rays, which take f64 origins and endpoints and round them per call.
//!
//! Scenes: the Cornell box (32 triangles), a random soup of 10,000 triangles and the bundled
//! furnished room (78,324 triangles, `scenes/generated/furnished-room.obj`).
//!
//! `cargo bench --bench visibility_embree` (needs python3 with numpy and embreex: `make deps`).
//! embreex's `scene.run` is single-threaded Embree behind a Python call: its rate includes
//! copying the rays in and the results out. Closest hits are timed returning primitive ids
//! only (`output=0`): returning t, u, v and the normal as well (`output=1`) measured 1.05-1.23x
//! slower, which is Python's copying, not Embree's tracing.

#[path = "../tests/support/embree_rays.rs"]
mod embree_rays;
#[path = "../tests/support/fixtures.rs"]
mod fixtures;

use embree_rays::{
    f32_rays, f32_segments, hemisphere_rays, pairwise_segments, write_for_embree, write_segments,
};
use rayon::prelude::*;
use relume::raytrace::visibility::Ray;
use std::path::Path;
use std::time::Instant;

const EMBREE: &str = r#"
import sys, time, numpy as np
from embreex import rtcore_scene as rtcs
from embreex.mesh_construction import TriangleMesh
d = sys.argv[1]
tris = np.load(d + '/tris.npy'); o = np.load(d + '/origins.npy'); v = np.load(d + '/dirs.npy')
scene = rtcs.EmbreeScene(); TriangleMesh(scene=scene, vertices=tris)
scene.run(o[:1000], v[:1000], output=1)  # warm-up
# Timed with output=0 (primitive ids only): output=1 also copies t, u, v and the normal out
# into numpy arrays, which measured 1.05-1.23x slower and is Python's cost, not Embree's.
best = 1e30
for _ in range(5):
    t = time.perf_counter(); scene.run(o, v, output=0); best = min(best, time.perf_counter() - t)
r = scene.run(o, v, output=1)
tfar = np.where(r['primID'] >= 0, r['tfar'], 1e30).astype(np.float32)
occ = 1e30
for _ in range(5):
    t = time.perf_counter(); scene.run(o, v, dists=np.minimum(tfar, 1e30), query='OCCLUDED'); occ = min(occ, time.perf_counter() - t)
so = np.load(d + '/seg_origins.npy'); sv = np.load(d + '/seg_dirs.npy'); sl = np.load(d + '/seg_lengths.npy')
seg = 1e30
for _ in range(5):
    t = time.perf_counter(); so_r = scene.run(so, sv, dists=sl, query='OCCLUDED'); seg = min(seg, time.perf_counter() - t)
print(len(o) / best / 1e6, len(o) / occ / 1e6, int((r['primID'] >= 0).sum()), len(so) / seg / 1e6, int((np.asarray(so_r) != -1).sum()))
"#;

/// Mrays/s of `f` over rays `0..count`, best of five: one thread runs a plain loop (as
/// Embree's one thread does), more split the rays into chunks of 1,024 over a pool.
fn rate(threads: usize, count: usize, f: impl Fn(usize) + Sync + Send) -> f64 {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let secs = (0..5)
        .map(|_| {
            let t = Instant::now();
            if threads == 1 {
                (0..count).for_each(&f);
            } else {
                pool.install(|| {
                    (0..count.div_ceil(1024)).into_par_iter().for_each(|c| {
                        (c * 1024..(c * 1024 + 1024).min(count)).for_each(&f);
                    })
                });
            }
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min);
    count as f64 / secs / 1e6
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = std::env::temp_dir().join(format!("relume-embree-bench-{}", std::process::id()));
    let (cornell, _) = relume::scene::load_scene(
        &root.join("scenes/cornell-box/cornell_box.obj"),
        relume::scene::SceneOptions { scale: 0.001 },
    )
    .unwrap();
    let scenes = [
        ("Cornell box", cornell, 1024u32),
        ("soup 10k", fixtures::random_soup(10_000, 5), 4000),
        (
            "furnished room",
            relume::scene::load_scene(
                &root.join("scenes/generated/furnished-room.obj"),
                Default::default(),
            )
            .unwrap()
            .0,
            4000,
        ),
    ];
    println!("Hemisphere rays of the form-factor stage, 64 per patch; best of 5; Mrays/s\n");
    println!("| scene | triangles | rays | hits | relume closest 1 / 2 threads | Embree closest 1 thread | relume occlusion 1 / 2 threads | Embree occlusion 1 thread | relume / Embree per core (closest, occlusion) |");
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut pairs = Vec::new();
    let mut stage = Vec::new();
    for (name, scene, target) in scenes {
        let (ctx, rays) = hemisphere_rays(&scene, target, 64, 3);
        let dir = tmp.join(name.replace(' ', "-"));
        std::fs::create_dir_all(&dir).unwrap();
        let (_, tris) = write_for_embree(&dir, &ctx, &rays);
        let segments = pairwise_segments(&ctx, 4, 16, 3);
        write_segments(&dir, &segments);
        let n = rays.len() as u64;
        // The f32 rays as Embree gets them; occlusion up to relume's own closest hit (Embree's
        // occlusion goes up to its own).
        let f32_rays = f32_rays(&rays);
        let rays32: Vec<Ray> = f32_rays
            .iter()
            .map(|&(o, d)| Ray::from_f32(o, d, f32::INFINITY))
            .collect();
        let hits: Vec<Option<f32>> = rays32
            .par_iter()
            .map(|r| ctx.vis.trace_closest(r).map(|h| h.t))
            .collect();
        let hit_count = hits.iter().flatten().count();
        let cut32: Vec<Ray> = f32_rays
            .iter()
            .zip(&hits)
            .map(|(&(o, d), h)| Ray::from_f32(o, d, h.unwrap_or(1e3)))
            .collect();
        let segs32: Vec<Ray> = f32_segments(&segments)
            .into_iter()
            .map(|(o, d, l)| Ray::from_f32(o, d, l))
            .collect();
        let closest = |i: usize| {
            std::hint::black_box(ctx.vis.trace_closest(&rays32[i]));
        };
        let occlusion = |i: usize| {
            std::hint::black_box(ctx.vis.trace_occluded(&cut32[i]));
        };
        let pair = |i: usize| {
            std::hint::black_box(ctx.vis.trace_occluded(&segs32[i]));
        };
        let (c1, c2) = (rate(1, rays.len(), closest), rate(2, rays.len(), closest));
        let (o1, o2) = (
            rate(1, rays.len(), occlusion),
            rate(2, rays.len(), occlusion),
        );
        let (p1, p2) = (rate(1, segments.len(), pair), rate(2, segments.len(), pair));
        let occluded = segs32
            .par_iter()
            .filter(|r| ctx.vis.trace_occluded(r))
            .count();
        // The stage's entry points on the same rays: f64 origins and endpoints, one thread.
        let stage_closest = |i: usize| {
            std::hint::black_box(ctx.vis.closest_hit(rays[i].0, rays[i].1));
        };
        let stage_occlusion = |i: usize| {
            let (o, d) = rays[i];
            let end = o + d * hits[i].map_or(1e3, |t| t as f64);
            std::hint::black_box(ctx.vis.occluded(o, end));
        };
        let stage_pair = |i: usize| {
            std::hint::black_box(ctx.vis.occluded(segments[i].0, segments[i].1));
        };
        stage.push(format!(
            "| {name} | {:.2} | {:.2} | {:.2} |",
            rate(1, rays.len(), stage_closest),
            rate(1, rays.len(), stage_occlusion),
            rate(1, segments.len(), stage_pair)
        ));
        let out = std::process::Command::new("python3")
            .args(["-c", EMBREE, dir.to_str().unwrap()])
            .output();
        let embree: Vec<f64> = match out {
            Ok(o) if o.status.success() => String::from_utf8_lossy(&o.stdout)
                .split_whitespace()
                .filter_map(|x| x.parse().ok())
                .collect(),
            _ => Vec::new(),
        };
        let (ec, eo, ep, eocc) = match embree.as_slice() {
            [c, o, _, p, occ] => (*c, *o, *p, *occ),
            _ => {
                println!("| {name} | (embreex not available: `make deps-py`) |");
                continue;
            }
        };
        println!(
            "| {name} | {} | {n} | {hit_count} | {c1:.2} / {c2:.2} | {ec:.2} | {o1:.2} / {o2:.2} | {eo:.2} | {:.2}x, {:.2}x |",
            tris.len(),
            c1 / ec,
            o1 / eo
        );
        pairs.push(format!(
            "| {name} | {} | {occluded} ({eocc}) | {p1:.2} / {p2:.2} | {ep:.2} | {:.2}x |",
            segments.len(),
            p1 / ep
        ));
    }
    println!("\nThe pairwise estimator's occlusion segments (16 point pairs per patch pair, 4 partners per patch); Mrays/s\n");
    println!("| scene | segments | occluded relume (Embree) | relume 1 / 2 threads | Embree 1 thread | relume / Embree per core |");
    println!("|---|---|---|---|---|---|");
    for p in &pairs {
        println!("{p}");
    }
    println!("\nThe stage's entry points on the same rays (f64 origins and endpoints: `closest_hit`, `occluded`), one thread; Mrays/s\n");
    println!("| scene | closest | occlusion (cut rays) | pairwise segments |");
    println!("|---|---|---|---|");
    for p in &stage {
        println!("{p}");
    }
    let _ = std::fs::remove_dir_all(&tmp);
}
