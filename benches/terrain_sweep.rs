//! The certified sweep against the memory-read floor (docs/terrain.md, Measurements): for Puget
//! Sound at 1K/2K/4K and several sun elevations, the wall time of one pass summing the heights (the
//! floor, best of 5), of the sweep mask (best of 3, mipmap built beforehand and reported on its
//! own), and of the accelerated traversal (A2); the sweep/floor ratio; how the sweep decided
//! its pixels; and the pixels where the sweep differs from A2 (which equals the exact traversal
//! on every pixel, tests/terrain/exactness.rs) and, at 1K, from the exact traversal itself.
//!
//! `cargo bench --bench terrain_sweep` (env: RELUME_BENCH_SIZES, e.g. "1024,4096";
//! RELUME_BENCH_AZIMUTH, default 300; RELUME_BENCH_ELEVATIONS, default "2,5,10,30,60";
//! RELUME_BENCH_A2=0 skips the traversal and the comparisons, for profiling the sweep alone).

use rayon::prelude::*;
use relume::terrain::hard::relief::{shadow_mask, HardMethod};
use relume::terrain::hard::sweep::shadow_mask_sweep;
use relume::terrain::{MinMaxMipmap, Sun, Track};
use std::time::Instant;
use util::{env, env_list, load};

#[allow(unused_imports)]
mod util;

/// Best wall time of `reps` runs.
fn best<T>(reps: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut out = None;
    let mut t_best = f64::INFINITY;
    for _ in 0..reps {
        let t = Instant::now();
        let v = f();
        t_best = t_best.min(t.elapsed().as_secs_f64());
        out = Some(v);
    }
    (t_best, out.unwrap())
}

fn main() {
    let full = load("puget-sound.ron");
    let az: f64 = env("RELUME_BENCH_AZIMUTH", 300.0);
    let sizes = env_list::<f64>("RELUME_BENCH_SIZES", "1024,2048,4096");
    let elevations = env_list::<f64>("RELUME_BENCH_ELEVATIONS", "2,5,10,30,60");
    let with_a2 = env("RELUME_BENCH_A2", 1u32) != 0;
    println!("## Hard shadows: certified sweep vs the read floor, Puget Sound, azimuth {az}°\n");
    println!(
        "{} threads; wall times, best of 3 (floor: best of 5); shared machine: read the ratios.\n",
        rayon::current_num_threads()
    );
    println!("| size | elevation | read floor | sweep | sweep / floor | A2 | A2 / sweep | lit by bound | shadowed near | shadowed by witness | traversed (shadowed) | differing vs A2 | differing vs exact |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut builds = Vec::new();
    for &n in &sizes {
        let n = n as usize;
        let map = full.downsample(4096 / n);
        let (floor, sum) = best(5, || map.heights.par_iter().map(|&h| h as f64).sum::<f64>());
        assert!(sum.is_finite());
        let (build, mip) = best(1, || MinMaxMipmap::build(&map));
        builds.push((n, build, floor));
        for &el in &elevations {
            let sun = Sun::new(az, el).unwrap();
            let track = Track::new(&sun, map.cell_size);
            let (ts, (mask, stats)) = best(3, || shadow_mask_sweep(&map, &track));
            if !with_a2 {
                println!(
                    "| {n}² | {el}° | {:.2} ms | {:.1} ms | {:.1}x |",
                    floor * 1e3,
                    ts * 1e3,
                    ts / floor
                );
                continue;
            }
            let (ta, a2) = best(1, || {
                shadow_mask(
                    &map,
                    &sun,
                    HardMethod::Accelerated,
                    Some(&mip),
                    &relume::progress::Silent,
                )
            });
            let differ = mask.iter().zip(&a2).filter(|(a, b)| a != b).count();
            let exact = if n <= 1024 {
                let e = shadow_mask(
                    &map,
                    &sun,
                    HardMethod::Exact,
                    None,
                    &relume::progress::Silent,
                );
                mask.iter()
                    .zip(&e)
                    .filter(|(a, b)| a != b)
                    .count()
                    .to_string()
            } else {
                "—".into()
            };
            let px = mask.len() as f64;
            let pct = |v: u64| format!("{:.2} %", 100.0 * v as f64 / px);
            println!(
                "| {n}² | {el}° | {:.2} ms | {:.1} ms | {:.1}x | {:.1} ms | {:.1}x | {} | {} | {} | {} ({}) | {differ} | {exact} |",
                floor * 1e3,
                ts * 1e3,
                ts / floor,
                ta * 1e3,
                ta / ts,
                pct(stats.lit_by_bound),
                pct(stats.shadowed_near),
                pct(stats.shadowed_by_witness),
                pct(stats.traversed),
                pct(stats.traversed_shadowed),
            );
        }
    }
    println!("\n| size | mipmap build | build / floor |");
    println!("|---|---|---|");
    for (n, b, f) in builds {
        println!("| {n}² | {:.1} ms | {:.1}x |", b * 1e3, b / f);
    }
}
