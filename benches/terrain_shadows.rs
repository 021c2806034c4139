//! Hard relief shadows on Puget Sound at 1K, 2K and 4K (box-downsampled from the 4K file):
//! Mpixels/s of the exact traversal (A1) and the accelerated one (A2 over the min/max mipmap)
//! for sun elevations 5°, 15°, 30°, 60°, the speed-up, the number of differing pixels, and the
//! mipmap build time. Prints Markdown tables.
//!
//! `cargo bench --bench terrain_shadows` (env: RELUME_BENCH_ROW_STEP=k times every k-th row
//! only at 4K, default 1 = every pixel; RELUME_BENCH_AZIMUTH, default 300; RELUME_BENCH_SIZES,
//! e.g. "1024,2048").

use rayon::prelude::*;
use relume::heightmap::HeightMap;
use relume::terrain::hard::accelerated_traversal::shadowed_accelerated;
use relume::terrain::hard::exact_traversal::shadowed_exact;
use relume::terrain::{MinMaxMipmap, Sun, Track};
use std::time::Instant;
use util::{cpu_seconds, env, load};

mod util;

/// (wall seconds, CPU seconds, mask) over the given rows.
fn run(
    map: &HeightMap,
    rows: &[usize],
    f: &(dyn Fn(usize, usize) -> bool + Sync),
) -> (f64, f64, Vec<bool>) {
    let (t, c) = (Instant::now(), cpu_seconds());
    let mask: Vec<bool> = rows
        .par_iter()
        .flat_map_iter(|&r| (0..map.width).map(move |c| f(c, r)))
        .collect();
    (t.elapsed().as_secs_f64(), cpu_seconds() - c, mask)
}

fn main() {
    let full = load("puget-sound.ron");
    let az: f64 = env("RELUME_BENCH_AZIMUTH", 300.0);
    let row_step: usize = env("RELUME_BENCH_ROW_STEP", 1);
    let sizes: Vec<usize> = env::<String>("RELUME_BENCH_SIZES", "1024,2048,4096".into())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    println!("## Hard shadows: exact (A1) vs accelerated (A2), Puget Sound, azimuth {az}°\n");
    println!(
        "{} threads, shared machine: compare ratios, not absolute times. Cell 40 m at 4K (160 m at 1K), height scale 10 m/unit.\n",
        rayon::current_num_threads()
    );
    println!("Mpx/s = million pixels per CPU-second (process user+system time; wall-time speed-up in brackets).\n");
    println!("| size | elevation | pixels timed | exact Mpx/s | accelerated Mpx/s | speed-up (CPU) | speed-up (wall) | differing pixels | in shadow |");
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut builds = Vec::new();
    for &n in &sizes {
        let map = full.downsample(4096 / n);
        let t = Instant::now();
        let mip = MinMaxMipmap::build(&map);
        let build = t.elapsed().as_secs_f64();
        builds.push((n, build, mip.levels.len(), mip.bytes()));
        let step = if n == 4096 { row_step } else { 1 };
        let rows: Vec<usize> = (0..map.height).step_by(step).collect();
        let (_, max) = map.min_max();
        for el in [5.0, 15.0, 30.0, 60.0] {
            let track = Track::new(&Sun::new(az, el).unwrap(), map.cell_size);
            let (we, te, exact) = run(&map, &rows, &|c, r| shadowed_exact(&map, &track, c, r, max));
            let (wa, ta, fast) = run(&map, &rows, &|c, r| {
                shadowed_accelerated(&map, &mip, &track, c, r)
            });
            let (te, ta) = (te.max(0.01), ta.max(0.01));
            let differ = exact.iter().zip(&fast).filter(|(a, b)| a != b).count();
            let shadowed = exact.iter().filter(|s| **s).count() as f64 / exact.len() as f64;
            let px = exact.len() as f64;
            println!(
                "| {n}² | {el}° | {}{} | {:.2} | {:.2} | {:.1}x | {:.1}x | {differ} | {:.1} % |",
                exact.len(),
                if step > 1 {
                    format!(" (every {step}th row)")
                } else {
                    String::new()
                },
                px / te / 1e6,
                px / ta / 1e6,
                te / ta,
                we / wa,
                100.0 * shadowed
            );
        }
    }
    println!("\n| size | mipmap levels | mipmap bytes | build time |");
    println!("|---|---|---|---|");
    for (n, s, l, b) in builds {
        println!("| {n}² | {l} | {b} | {:.1} ms |", s * 1e3);
    }
}
