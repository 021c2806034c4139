//! Soft shadows on Puget Sound at 1K, 2K and 4K (box-downsampled from the 4K file), sun
//! elevations 2°, 5°, 10°: time and error of uniform stepping (16/32/64/100/256 steps), the
//! soft-shadow paper's dynamic programming at several start levels, and branch-and-bound, against the
//! exhaustive reference. Time is CPU time as a ratio against uniform-100 in the same run;
//! errors are the mean and max absolute lit fraction. Prints a Markdown table.
//!
//! `cargo bench --bench terrain_softshadows`. The exhaustive reference walks the whole track at
//! low sun, so every method is timed on the same deterministic subset of rows: every
//! RELUME_BENCH_ROW_STEP_1K (default 4), _2K (8), _4K (16) rows, all columns.
//! RELUME_BENCH_SIZES (default "1024,2048,4096"), RELUME_BENCH_AZIMUTH (default 300).

mod util;

use relume::progress::Silent;
use relume::terrain::soft::{SoftContext, SoftMethod, SoftShadowParams};
use relume::terrain::{MinMaxMipmap, Sun};
use util::{cpu_seconds, env, load};

fn main() {
    let full = load("puget-sound.ron");
    let az: f64 = env("RELUME_BENCH_AZIMUTH", 300.0);
    let sizes: Vec<usize> = env::<String>("RELUME_BENCH_SIZES", "1024,2048,4096".into())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let mut methods: Vec<SoftMethod> = [16, 32, 64, 100, 256]
        .iter()
        .map(|&steps| SoftMethod::Uniform { steps })
        .collect();
    for start_level in [0, 2, 4, 6, 8] {
        methods.push(SoftMethod::DynamicProgramming {
            start_level,
            intervals: 0,
        });
    }
    methods.push(SoftMethod::DynamicProgramming {
        start_level: 4,
        intervals: 8,
    });
    methods.push(SoftMethod::BranchAndBound);
    println!("## Soft shadows: methods vs the exhaustive reference, Puget Sound, azimuth {az}°, sun radius 0.2666°, flat\n");
    println!(
        "{} threads, shared machine. Time = CPU seconds as a ratio against uniform-100 on the same pixels in the same run (< 1 is faster). \
         Error = |lit − lit_exhaustive| over the timed pixels.\n",
        rayon::current_num_threads()
    );
    println!("| size | elevation | pixels timed | method | time / uniform-100 | mean error | max error | penumbra pixels |");
    println!("|---|---|---|---|---|---|---|---|");
    for &n in &sizes {
        let map = full.downsample(4096 / n);
        let mip = MinMaxMipmap::build(&map);
        let step: usize = match n {
            1024 => env("RELUME_BENCH_ROW_STEP_1K", 4),
            2048 => env("RELUME_BENCH_ROW_STEP_2K", 8),
            _ => env("RELUME_BENCH_ROW_STEP_4K", 16),
        };
        let rows: Vec<usize> = (0..map.height).step_by(step.max(1)).collect();
        for el in [2.0, 5.0, 10.0] {
            let sun = Sun::new(az, el).unwrap();
            let run = |method: SoftMethod| {
                let p = SoftShadowParams {
                    method,
                    ..Default::default()
                };
                let ctx = SoftContext::new(&map, &mip, &sun, &p).unwrap();
                let c = cpu_seconds();
                let v = ctx.rows(&rows, &Silent);
                (cpu_seconds() - c, v)
            };
            let (t_ex, reference) = run(SoftMethod::Exhaustive);
            let (t_u100, _) = run(SoftMethod::Uniform { steps: 100 });
            let penumbra = reference.iter().filter(|&&l| l > 0.0 && l < 1.0).count();
            let px = format!("{} (every {step}th row)", reference.len());
            println!(
                "| {n}² | {el}° | {px} | exhaustive | {:.2} | 0 | 0 | {penumbra} |",
                t_ex / t_u100.max(0.01)
            );
            for &m in &methods {
                let (t, v) = run(m);
                let (mut sum, mut max) = (0.0f64, 0.0f64);
                for (a, b) in v.iter().zip(&reference) {
                    let e = (*a as f64 - *b as f64).abs();
                    sum += e;
                    max = max.max(e);
                }
                println!(
                    "| {n}² | {el}° | {px} | {} | {:.2} | {:.2e} | {:.3} | |",
                    m.label(),
                    t / t_u100.max(0.01),
                    sum / v.len() as f64,
                    max
                );
            }
        }
    }
}
