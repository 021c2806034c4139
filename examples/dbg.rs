use relume::radiosity::fixtures;
use relume::radiosity::formfactor::{analytic, Context};
use relume::radiosity::geometry::{item_rng, point_to_triangle};
use relume::radiosity::patches::{voxelize, Resolution, VoxelizeParams};
fn main() {
    let scene = fixtures::perpendicular_rectangles(0.5, 2.0, 1.0);
    let set = voxelize(
        &scene,
        &VoxelizeParams {
            resolution: Resolution::VoxelSize(8.0),
            samples_per_patch: 4,
        },
    )
    .unwrap();
    let ctx = Context::new(&scene, &set);
    let first = set.patches.iter().position(|p| p.objects == [0]).unwrap();
    let (si, sj) = (&ctx.samplers[first], &ctx.samplers[1 - first]);
    let mut rng = item_rng(3, 0, 0);
    let m = 100000;
    let mut sum = 0.0;
    for _ in 0..m {
        let (x, n) = si.sample(rng.f64(), rng.f64(), rng.f64());
        let f: f64 = sj
            .triangles()
            .iter()
            .map(|&(a, b, c, tn)| point_to_triangle(x, n, [a, b, c], tn))
            .sum();
        sum += f;
    }
    println!(
        "MC unoccluded {} exact {}",
        sum / m as f64,
        analytic::perpendicular_rectangles(0.5, 2.0, 1.0)
    );
    println!("areas {} {}", si.area, sj.area);
    let lift = ctx.vis.epsilon as f64;
    let (mut occ, mut tot) = (0, 0);
    for _ in 0..20000 {
        let (x, nx) = si.sample(rng.f64(), rng.f64(), rng.f64());
        let (y, ny) = sj.sample(rng.f64(), rng.f64(), rng.f64());
        tot += 1;
        if ctx.vis.occluded(x + nx * lift, y + ny * lift) {
            occ += 1;
            if occ < 5 {
                println!("occluded {x:?} {y:?}");
            }
        }
    }
    println!("occluded {occ}/{tot} eps {lift}");
    for seed in 0..4 {
        let mut r = item_rng(seed, 9, 9);
        for m in [64usize, 256, 1024] {
            let pts = r.jittered(m);
            let a: f64 = pts
                .iter()
                .map(|&(u, v)| {
                    let (x, n) = si.sample_square(u, v);
                    sj.triangles()
                        .iter()
                        .map(|&(a, b, c, tn)| point_to_triangle(x, n, [a, b, c], tn))
                        .sum::<f64>()
                })
                .sum::<f64>()
                / m as f64;
            let b: f64 = pts
                .iter()
                .map(|&(u, v)| {
                    let (x, n) = sj.sample_square(u, v);
                    si.triangles()
                        .iter()
                        .map(|&(a, b, c, tn)| point_to_triangle(x, n, [a, b, c], tn))
                        .sum::<f64>()
                })
                .sum::<f64>()
                / m as f64
                * sj.area
                / si.area;
            println!("seed {seed} m {m}: forward {a:.5} reverse {b:.5}");
        }
        for k in [1024, 16384, 65536] {
            let g = relume::radiosity::formfactor::pairwise::throughput(
                &ctx,
                first.min(1 - first),
                first.max(1 - first),
                k,
                seed,
            );
            println!("seed {seed} k {k}: F01 {}", g / si.area);
        }
    }
    println!(
        "reverse exact {}",
        analytic::perpendicular_rectangles(0.5, 2.0, 1.0) * si.area / sj.area
    );
}
#[allow(dead_code)]
fn _x() {}
