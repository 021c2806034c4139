//! Horizon maps (docs/terrain.md, "Horizon maps") on Puget Sound: the wall time of
//! `HorizonMap::build` for N directions at 1K/2K/4K; its accuracy against the exact per-pixel
//! horizon on a subsample (every 16th row and column at 4K, every 8th below); the cost per
//! direction (texels per period); and hard shadows from the map for suns between its azimuths
//! against the exact mask (the certified sweep, equal to the exact traversal on every pixel).
//!
//! `cargo bench --bench terrain_horizon` (env: RELUME_BENCH_SIZES, default "1024,2048,4096";
//! RELUME_BENCH_DIRECTIONS, default "16,32,64"; RELUME_BENCH_CHECK=0 checks one pixel only).

use rayon::prelude::*;
use relume::terrain::hard::relief::{shadow_mask, HardMethod};
use relume::terrain::horizon::horizon_exact;
use relume::terrain::horizon::map::{decode, HorizonMap, HorizonSettings};
use relume::terrain::Sun;
use std::time::Instant;
use util::{env_list, load};

#[allow(unused_imports)]
mod util;

fn main() {
    let full = load("puget-sound.ron");
    let sizes = env_list::<usize>("RELUME_BENCH_SIZES", "1024,2048,4096");
    let counts = env_list::<usize>("RELUME_BENCH_DIRECTIONS", "16,32,64");
    println!("## Horizon maps, Puget Sound\n");
    println!(
        "{} threads, wall time of one build (shared machine).\n",
        rayon::current_num_threads()
    );
    println!("| size | directions | build | per direction | mean texels per period | pixels checked | within 0.01° | max error |");
    println!("|---|---|---|---|---|---|---|---|");
    let mut kept = None;
    for &n in &sizes {
        let map = full.downsample(4096 / n);
        let (_, max) = map.min_max();
        for &k in &counts {
            let t = Instant::now();
            let hm = HorizonMap::build(&map, &HorizonSettings::flat(k));
            let secs = t.elapsed().as_secs_f64();
            // RELUME_BENCH_CHECK=0 skips the accuracy check (for profiling the build alone).
            let stride = if util::env("RELUME_BENCH_CHECK", 1) == 0 {
                usize::MAX / 2
            } else if n >= 4096 {
                16
            } else {
                8
            };
            let pixels: Vec<(usize, usize)> = (0..map.height)
                .step_by(stride)
                .flat_map(|r| (0..map.width).step_by(stride).map(move |c| (c, r)))
                .collect();
            let (ok, worst, total) = hm
                .directions
                .par_iter()
                .zip(&hm.angles)
                .map(|(d, plane)| {
                    let track = d.track(map.cell_size);
                    let mut acc = (0usize, 0.0f64, 0usize);
                    for &(c, r) in &pixels {
                        let e = horizon_exact(&map, &track, c, r, max);
                        let err = (decode(plane[r * map.width + c]) - e).abs();
                        acc.0 += (err <= 0.01) as usize;
                        acc.1 = acc.1.max(err);
                        acc.2 += 1;
                    }
                    acc
                })
                .reduce(|| (0, 0.0, 0), |a, b| (a.0 + b.0, a.1.max(b.1), a.2 + b.2));
            let period: f64 = hm
                .directions
                .iter()
                .map(|d| (d.a.abs() + d.b.abs()) as f64)
                .sum::<f64>()
                / hm.directions.len() as f64;
            println!(
                "| {n}² | {k} | {:.2} s | {:.0} ms | {period:.1} | {total} | {:.3} % | {worst:.2e}° |",
                secs,
                secs * 1e3 / k as f64,
                100.0 * ok as f64 / total as f64
            );
            if n == *sizes.last().unwrap() && k == *counts.last().unwrap() {
                kept = Some((map.clone(), hm));
            }
        }
    }
    let (map, hm) = kept.unwrap();
    println!(
        "\n### Shadows from the horizon map ({}², {} directions) vs the exact mask\n",
        map.width,
        hm.directions.len()
    );
    println!("| sun | O(1) mask | exact mask (sweep) | differing pixels |");
    println!("|---|---|---|---|");
    for (az, el) in [
        (300.0, 5.0),
        (300.0, 10.0),
        (123.4, 5.0),
        (123.4, 30.0),
        (47.0, 2.0),
    ] {
        let sun = Sun::new(az, el).unwrap();
        let t = Instant::now();
        let fast = hm.shadow_mask(&sun);
        let tf = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let exact = shadow_mask(
            &map,
            &sun,
            HardMethod::Sweep,
            None,
            &relume::progress::Silent,
        );
        let te = t.elapsed().as_secs_f64();
        let differ = exact.iter().zip(&fast).filter(|(a, b)| a != b).count();
        println!(
            "| {az}°/{el}° | {:.1} ms | {:.0} ms | {differ} ({:.3} %) |",
            tf * 1e3,
            te * 1e3,
            100.0 * differ as f64 / exact.len() as f64
        );
    }
    // Sunlight over a day from the same map (the goal: "a day at 10-minute steps costs little
    // more than one horizon pass"): Seattle's summer solstice, hours only and with the
    // clear-sky insolation.
    let date = relume::terrain::sun::solar::Instant::parse("2026-06-21T00:00:00Z").unwrap();
    let place = relume::terrain::sun::solar::Place::new(47.6, -122.3, 0.0).unwrap();
    let steps = relume::terrain::horizon::sunlight::day_steps(&date, &place, 600.0, 0.0).unwrap();
    println!(
        "\n### Sunlight over a day from the map ({} steps of 10 minutes)\n",
        steps.len()
    );
    println!("| output | time |");
    println!("|---|---|");
    for insolation in [false, true] {
        let t = Instant::now();
        let (hours, _) =
            relume::terrain::horizon::sunlight::sunlight(&map, &hm, &steps, insolation);
        let secs = t.elapsed().as_secs_f64();
        assert_eq!(hours.len(), map.width * map.height);
        println!(
            "| {} | {:.2} s |",
            if insolation {
                "hours + insolation"
            } else {
                "hours"
            },
            secs
        );
    }
}
