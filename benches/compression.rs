//! Compression study: prints Markdown tables.
//!
//! `cargo bench --bench compression` (n = 4056: a closed box with 26x26 patches per wall,
//! infinite bounces). Environment: `RELUME_BENCH_K` (patches per wall side, default 26),
//! `RELUME_BENCH_BOUNCES` (`inf` or a count, default `inf`), `RELUME_TRANSPORT_NPY` (use a
//! real bake's `transport.npy` instead; the box lights are then replaced by the standard ones).
//! Times are medians of 5 runs, reported as ratios to a dense f32 mat-vec in the same run.
#![allow(clippy::needless_range_loop)]

#[path = "../tests/support/transport_box.rs"]
mod transport_box;

use relume::compress::report::{self, rms_relative, standard_lights};
use relume::compress::{
    compress, gather, reorder, DenseEncoding, EncodeOptions, EncodedTransport, ReorderMetric,
    ReorderOptions,
};
use relume::radiosity::TransportMatrix;
use relume::study::timing::median_secs;
use std::time::Instant;

struct Ctx {
    s: TransportMatrix,
    lights: Vec<(String, Vec<f32>)>,
    exact: Vec<Vec<f32>>,
}

fn gather_errors(ctx: &Ctx, enc: &EncodedTransport) -> Vec<f64> {
    ctx.lights
        .iter()
        .zip(&ctx.exact)
        .map(|((_, e), x)| rms_relative(&gather(enc, e), x))
        .collect()
}

fn pct(x: f64) -> String {
    format!("{:.2} %", 100.0 * x)
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let k: usize = std::env::var("RELUME_BENCH_K")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(26);
    let bounces = match std::env::var("RELUME_BENCH_BOUNCES").as_deref() {
        Ok("inf") | Err(_) => None,
        Ok(b) => Some(b.parse::<usize>().expect("RELUME_BENCH_BOUNCES")),
    };
    let t0 = Instant::now();
    let s = transport_box::transport_or_env(k, bounces);
    let lights = if std::env::var("RELUME_TRANSPORT_NPY").is_ok() {
        standard_lights(s.channels, s.n)
    } else {
        let mut l = transport_box::box_lights(&transport_box::closed_box(k, 7));
        l.extend(
            standard_lights(3, s.n)
                .into_iter()
                .filter(|(n, _)| n == "random"),
        );
        l
    };
    let exact: Vec<Vec<f32>> = lights.iter().map(|(_, e)| s.mat_vec(e)).collect();
    let ctx = Ctx { s, lights, exact };
    let n = ctx.s.n;
    println!(
        "# relume compression study\n\nMatrix: {}, n = {n}, {} channels ({:.1} s to build or load). \
         Machine: 2 cores shared with other builds; times are ratios within this run.\n",
        if std::env::var("RELUME_TRANSPORT_NPY").is_ok() {
            "RELUME_TRANSPORT_NPY".to_string()
        } else {
            format!(
                "closed box, {k}x{k} patches per wall, shuffled, {} bounces",
                bounces.map(|b| b.to_string()).unwrap_or("∞".into())
            )
        },
        ctx.s.channels,
        t0.elapsed().as_secs_f64()
    );
    let light_names: Vec<&str> = ctx.lights.iter().map(|l| l.0.as_str()).collect();

    // 1. The radiosity thesis's table (its §4.2): passes 0/1/2.
    println!("## Reordering (Bc1Log, p = 4 %)\n");
    println!("| passes | metric | mean abs error | max abs error | summed abs error | gather RMS rel ({}) | reorder time |", light_names.join(" / "));
    println!("|---|---|---|---|---|---|---|");
    let mut perms = std::collections::HashMap::new();
    for (passes, metric) in [
        (0u8, ReorderMetric::Linear),
        (1, ReorderMetric::Linear),
        (2, ReorderMetric::Linear),
        (1, ReorderMetric::Log),
        (2, ReorderMetric::Log),
    ] {
        let t = Instant::now();
        let perm = reorder(
            &mut ctx.s.clone(),
            ReorderOptions {
                passes,
                metric,
                ..Default::default()
            },
        );
        let secs = t.elapsed().as_secs_f64();
        let sp = ctx.s.permuted(&perm);
        let enc = compress(&sp, perm.clone(), 4.0, &EncodeOptions::default()).unwrap();
        let e = report::entry_errors(&sp, &enc);
        let g = gather_errors(&ctx, &enc);
        println!(
            "| {passes} | {metric:?} | {:.3e} | {:.4} | {:.2} | {} | {:.1} s |",
            e.mean,
            e.max,
            e.sum,
            g.iter().map(|x| pct(*x)).collect::<Vec<_>>().join(" / "),
            secs
        );
        perms.insert((passes, metric), (perm, sp));
    }
    let (perm, sp) = perms.remove(&(2, ReorderMetric::Log)).unwrap();
    let (perm_lin, sp_lin) = perms.remove(&(2, ReorderMetric::Linear)).unwrap();

    // 2. Error vs p.
    let candidates: Vec<(&str, EncodeOptions)> = vec![
        ("Bc1Log (thesis)", EncodeOptions::default()),
        (
            "Bc1Log + fill + feedback",
            EncodeOptions {
                fill_holes: true,
                feedback: true,
                ..Default::default()
            },
        ),
        (
            "Bc4Log + fill + feedback",
            EncodeOptions {
                encoding: DenseEncoding::Bc4Log,
                fill_holes: true,
                feedback: true,
                ..Default::default()
            },
        ),
        (
            "Bc6h + fill",
            EncodeOptions {
                encoding: DenseEncoding::Bc6h,
                fill_holes: true,
                ..Default::default()
            },
        ),
    ];
    println!("\n## Split percentage p (2 passes, Log metric)\n");
    println!("| encoding | p | summed abs error | max abs error | gather RMS rel ({}) | dense + sidecar bytes |", light_names.join(" / "));
    println!("|---|---|---|---|---|---|");
    for (name, o) in &candidates {
        for p in [0.0, 1.0, 2.0, 4.0, 8.0] {
            let enc = compress(&sp, perm.clone(), p, o).unwrap();
            let e = report::entry_errors(&sp, &enc);
            let g = gather_errors(&ctx, &enc);
            println!(
                "| {name} | {p} | {:.2} | {:.4} | {} | {} + {} |",
                e.sum,
                e.max,
                g.iter().map(|x| pct(*x)).collect::<Vec<_>>().join(" / "),
                enc.dense.bytes(),
                enc.sidecar.byte_len()
            );
        }
    }

    // 3. Every encoding, with bytes and gather time.
    let seed = compress(&sp_lin, perm_lin.clone(), 4.0, &EncodeOptions::default()).unwrap();
    let seed_bytes = seed.bytes() as f64;
    let e_dense = &ctx.lights[0].1;
    let dense_secs = median_secs(5, || {
        std::hint::black_box(ctx.s.mat_vec(e_dense));
    });
    println!("\n## Encodings (2 passes Log metric, unless noted)\n");
    println!(
        "Dense f32 mat-vec: {:.1} ms (median of 5). Thesis scheme (Bc1Log, p = 4 %, 2 Linear passes): {} bytes.\n",
        1e3 * dense_secs,
        seed.bytes()
    );
    println!("| encoding | p | fill | feedback | summed abs error | gather RMS rel ({}) | worst | dense bytes | sidecar bytes | total / thesis | gather time / dense mat-vec |", light_names.join(" / "));
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let mut rows: Vec<(String, f64, EncodeOptions, bool)> = Vec::new();
    for enc in DenseEncoding::ALL {
        for (fill, fb) in [(false, false), (true, false), (true, true)] {
            if !enc.is_log() && fb && enc != DenseEncoding::Bc6h {
                continue;
            }
            for p in [1.0, 4.0] {
                rows.push((
                    enc.name().to_string(),
                    p,
                    EncodeOptions {
                        encoding: enc,
                        fill_holes: fill,
                        feedback: fb,
                        ..Default::default()
                    },
                    false,
                ));
            }
        }
    }
    rows.push((
        "bc1_log (thesis, Linear passes)".into(),
        4.0,
        EncodeOptions::default(),
        true,
    ));
    for (name, p, o, linear) in rows {
        let (pp, sps) = if linear {
            (&perm_lin, &sp_lin)
        } else {
            (&perm, &sp)
        };
        let enc = compress(sps, pp.clone(), p, &o).unwrap();
        let e = report::entry_errors(sps, &enc);
        let g = gather_errors(&ctx, &enc);
        let worst = g.iter().take(3).cloned().fold(0.0, f64::max);
        let secs = median_secs(5, || {
            std::hint::black_box(gather(&enc, e_dense));
        });
        println!(
            "| {name} | {p} | {} | {} | {:.2} | {} | {} | {} | {} | {:.2} | {:.2} |",
            o.fill_holes,
            o.feedback,
            e.sum,
            g.iter().map(|x| pct(*x)).collect::<Vec<_>>().join(" / "),
            pct(worst),
            enc.dense.bytes(),
            enc.sidecar.byte_len(),
            enc.bytes() as f64 / seed_bytes,
            secs / dense_secs
        );
    }
    println!("\n`worst` is the largest of the first three light columns (the geometric lights of the box).");
    println!("Total time: {:.0} s", t0.elapsed().as_secs_f64());
}
