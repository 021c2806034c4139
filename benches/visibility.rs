//! Visibility and form-factor speed on the Cornell box at n ≈ 256, 1024 and 4096 patches.
//! Prints Markdown tables. Baseline in the same run: the same rays tested against every triangle
//! without the BVH (brute force).
//!
//! Run: `cargo bench --bench visibility` (`-- --quick` skips n ≈ 4096 and pairwise at 1024).

use rayon::prelude::*;
use relume::progress::Silent;
use relume::radiosity::formfactor::{form_factors, Context, Estimator, FormFactorParams};
use relume::radiosity::geometry::{cosine_direction, item_rng};
use relume::radiosity::patches::voxelize::{voxelize, Resolution, VoxelizeParams};
use std::time::Instant;

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let scene = relume::scene::load_scene(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes/cornell-box/cornell_box.obj"),
        relume::scene::SceneOptions { scale: 0.001 },
    )
    .unwrap()
    .0;
    let threads = rayon::current_num_threads();
    println!("Cornell box, {} triangles, {threads} threads (shared machine: compare ratios within a row)\n", scene.triangles.len());
    println!("| target | patches | voxelize ms | closest-hit Mrays/s, 1 thread | closest-hit Mrays/s, {threads} threads | brute-force Mrays/s, 1 thread | BVH speed-up | occlusion Mrays/s, {threads} threads |");
    println!("|---|---|---|---|---|---|---|---|");
    let targets: &[u32] = if quick {
        &[256, 1024]
    } else {
        &[256, 1024, 4096]
    };
    let mut sets = Vec::new();
    for &target in targets {
        let t = Instant::now();
        let set = voxelize(
            &scene,
            &VoxelizeParams {
                resolution: Resolution::TargetPatches(target),
                samples_per_patch: 4,
            },
        )
        .unwrap();
        let vox_ms = t.elapsed().as_secs_f64() * 1e3;
        let ctx = Context::new(&scene, &set);
        let n = set.len();
        // Rays: 64 cosine-distributed rays from random points of every patch.
        let rays: Vec<_> = (0..n)
            .flat_map(|i| {
                let mut rng = item_rng(9, i as u64, 0);
                let s = &ctx.samplers[i];
                (0..64)
                    .map(move |_| {
                        let (o, nrm) = s.sample_square(rng.f64(), rng.f64());
                        (o + nrm * 1e-4, cosine_direction(nrm, rng.f64(), rng.f64()))
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let rate = |f: &(dyn Fn() -> usize + Sync), pool: Option<&rayon::ThreadPool>| {
            let t = Instant::now();
            let hits = match pool {
                Some(p) => p.install(f),
                None => f(),
            };
            std::hint::black_box(hits);
            rays.len() as f64 / t.elapsed().as_secs_f64() / 1e6
        };
        let closest = || {
            rays.par_iter()
                .filter(|(o, d)| ctx.vis.closest_hit(*o, *d).is_some())
                .count()
        };
        let brute = || {
            rays.par_iter()
                .take(rays.len().min(200_000))
                .filter(|(o, d)| ctx.vis.closest_hit_brute_force(*o, *d).is_some())
                .count()
        };
        let occl = || {
            rays.par_iter()
                .filter(|(o, d)| ctx.vis.occluded(*o, *o + *d * 0.5))
                .count()
        };
        let c1 = rate(&closest, Some(&one));
        let cn = rate(&closest, None);
        let t = Instant::now();
        let b = one.install(brute);
        std::hint::black_box(b);
        let b1 = rays.len().min(200_000) as f64 / t.elapsed().as_secs_f64() / 1e6;
        let on = rate(&occl, None);
        println!(
            "| {target} | {n} | {vox_ms:.0} | {c1:.2} | {cn:.2} | {b1:.2} | {:.1}x | {on:.2} |",
            c1 / b1
        );
        sets.push(set);
    }
    println!("\n| patches | estimator | samples | rays | seconds | Mrays/s (whole stage) |");
    println!("|---|---|---|---|---|---|");
    for set in &sets {
        let n = set.len();
        let mut runs = vec![
            (Estimator::Hemisphere, 1024u32),
            (Estimator::Hemisphere, 4096),
        ];
        if n <= 300 || (n <= 1100 && !quick) {
            runs.push((Estimator::Pairwise, 16));
        }
        for (estimator, samples) in runs {
            let t = Instant::now();
            let f = form_factors(
                &scene,
                set,
                &FormFactorParams {
                    estimator,
                    samples,
                    seed: 0,
                },
                &Silent,
            )
            .unwrap();
            let secs = t.elapsed().as_secs_f64();
            println!(
                "| {n} | {estimator:?} | {samples} | {} | {secs:.2} | {:.2} |",
                f.rays,
                f.rays as f64 / secs / 1e6
            );
        }
    }
}
