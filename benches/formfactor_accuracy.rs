//! Error of each form-factor estimator against Howell's analytic configuration factors, vs the
//! number of samples. Prints a Markdown table: mean and max |F − F_exact| over 8 seeds, and the
//! time per estimate.
//!
//! Run: `cargo bench --bench formfactor_accuracy` (add `-- --quick` for fewer seeds).

use relume::progress::Silent;
#[path = "../tests/support/fixtures.rs"]
mod fixtures;
use relume::radiosity::formfactor::{analytic, form_factors, Estimator, FormFactorParams};
use relume::radiosity::patches::voxelize::{voxelize, Resolution, VoxelizeParams};
use relume::scene::Scene;
use std::time::Instant;

fn f01(scene: &Scene, estimator: Estimator, samples: u32, seed: u64) -> f64 {
    let (lo, hi) = scene.bounds();
    let set = voxelize(
        scene,
        &VoxelizeParams {
            resolution: Resolution::VoxelSize(4.0 * (hi - lo).max_element() as f64),
            samples_per_patch: 1,
        },
    )
    .unwrap();
    let f = form_factors(
        scene,
        &set,
        &FormFactorParams {
            estimator,
            samples,
            seed,
        },
        &Silent,
    )
    .unwrap();
    let first = set.patches.iter().position(|p| p.objects == [0]).unwrap();
    f.get(first, 1 - first) as f64
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let seeds: u64 = if quick { 3 } else { 8 };
    let seg = 256;
    let cases: Vec<(String, Scene, f64)> = vec![
        (
            "C-11 parallel 1×1 at 1".into(),
            fixtures::parallel_rectangles(1.0, 1.0, 1.0),
            analytic::parallel_rectangles(1.0, 1.0, 1.0),
        ),
        (
            "C-11 parallel 1×1 at 0.25".into(),
            fixtures::parallel_rectangles(1.0, 1.0, 0.25),
            analytic::parallel_rectangles(1.0, 1.0, 0.25),
        ),
        (
            "C-14 perpendicular 1,1,1".into(),
            fixtures::perpendicular_rectangles(1.0, 1.0, 1.0),
            analytic::perpendicular_rectangles(1.0, 1.0, 1.0),
        ),
        (
            "C-14 perpendicular 2,1,0.5".into(),
            fixtures::perpendicular_rectangles(2.0, 1.0, 0.5),
            analytic::perpendicular_rectangles(2.0, 1.0, 0.5),
        ),
        (
            "coaxial discs 1,1,1".into(),
            fixtures::coaxial_discs(1.0, 1.0, 1.0, seg),
            analytic::coaxial_discs(
                fixtures::equal_area_radius(1.0, seg),
                fixtures::equal_area_radius(1.0, seg),
                1.0,
            ),
        ),
        (
            "B-3 element to rectangle 1,1,1".into(),
            fixtures::element_and_rectangle(1e-3, 1.0, 1.0, 1.0),
            analytic::element_to_corner_rectangle(1.0, 1.0, 1.0),
        ),
    ];
    println!("| case | F exact | estimator | samples | mean abs error | max abs error | ms per estimate |");
    println!("|---|---|---|---|---|---|---|");
    let only = std::env::var("ESTIMATOR").ok();
    for (name, scene, exact) in &cases {
        for (estimator, counts) in [
            (
                Estimator::Hemisphere,
                [64u32, 256, 1024, 4096, 16384, 65536],
            ),
            (Estimator::Pairwise, [16u32, 64, 256, 1024, 4096, 16384]),
        ] {
            if only
                .as_ref()
                .is_some_and(|o| !format!("{estimator:?}").eq_ignore_ascii_case(o))
            {
                continue;
            }
            for samples in counts {
                let t = Instant::now();
                let errs: Vec<f64> = (0..seeds)
                    .map(|s| (f01(scene, estimator, samples, s) - exact).abs())
                    .collect();
                let ms = t.elapsed().as_secs_f64() * 1e3 / seeds as f64;
                let mean = errs.iter().sum::<f64>() / errs.len() as f64;
                let max = errs.iter().copied().fold(0.0, f64::max);
                println!(
                    "| {name} | {exact:.5} | {estimator:?} | {samples} | {mean:.2e} | {max:.2e} | {ms:.2} |"
                );
            }
        }
    }
}
