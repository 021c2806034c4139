//! Transport time at n ≈ 4096 (Cornell box) for k = 1, 3, 8, 16 (Horner and doubling) and
//! k = ∞ (LU), one channel, with the FLOP rate; baseline in the same run: numpy (OpenBLAS) GEMM
//! and solve on the same size, when Python with numpy is available.
//!
//! Run: `cargo bench --bench transport` (`-- --quick` uses n ≈ 1024).

use relume::progress::Silent;
use relume::radiosity::formfactor::{form_factors, Estimator, FormFactorParams};
use relume::radiosity::patches::voxelize::{voxelize, Resolution, VoxelizeParams};
use relume::radiosity::transport::{
    products, transport, Bounces, InfiniteSolver, Power, TransportParams,
};
use std::time::Instant;

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let target = if quick { 1024 } else { 4096 };
    let scene = relume::scene::load_scene(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes/cornell-box/cornell_box.obj"),
        relume::scene::SceneOptions { scale: 0.001 },
    )
    .unwrap()
    .0;
    let set = voxelize(
        &scene,
        &VoxelizeParams {
            resolution: Resolution::TargetPatches(target),
            samples_per_patch: 1,
        },
    )
    .unwrap();
    let f = form_factors(
        &scene,
        &set,
        &FormFactorParams {
            estimator: Estimator::Hemisphere,
            samples: 256,
            seed: 0,
        },
        &Silent,
    )
    .unwrap();
    let n = f.n;
    // One channel: the red albedo of every patch, as a grey scene.
    let albedo: Vec<[f32; 3]> = set.patches.iter().map(|p| [p.albedo[0]; 3]).collect();
    let n3 = (n as f64).powi(3);
    println!(
        "n = {n} patches, one channel, {} threads (shared machine)\n",
        rayon::current_num_threads()
    );
    println!("| bounces | method | matrix products | seconds | GFLOP/s |");
    println!("|---|---|---|---|---|");
    let run_with = |bounces: Bounces, power: Power, solver: InfiniteSolver, label: &str| {
        let t = Instant::now();
        let s = transport(
            &f.values,
            n,
            &albedo,
            &TransportParams {
                bounces,
                power,
                max_memory: u64::MAX,
                solver,
            },
            &Silent,
        )
        .unwrap();
        let secs = t.elapsed().as_secs_f64();
        let flops = match bounces {
            Bounces::Infinite => (2.0 / 3.0) * n3 + 2.0 * n3,
            _ => 2.0 * n3 * s.products as f64,
        };
        println!(
            "| {label} | {power:?} | {} | {secs:.2} | {:.1} |",
            s.products,
            flops / secs / 1e9
        );
        std::hint::black_box(s.data[0]);
        secs
    };
    let run = |bounces: Bounces, power: Power, label: &str| {
        run_with(bounces, power, InfiniteSolver::Auto, label)
    };
    // One f32 GEMM (faer, the transport's own) on matrices of this size, the best of three:
    // the unit of k = ∞.
    let gemm = {
        let a = faer::Mat::<f32>::from_fn(n, n, |i, j| f.values[i * n + j]);
        let mut c = faer::Mat::<f32>::zeros(n, n);
        let mut secs = f64::INFINITY;
        for _ in 0..3 {
            let t = Instant::now();
            faer::linalg::matmul::matmul(
                c.as_mut(),
                faer::Accum::Replace,
                a.as_ref(),
                a.as_ref(),
                1.0f32,
                faer::Par::rayon(0),
            );
            secs = secs.min(t.elapsed().as_secs_f64());
        }
        std::hint::black_box(c[(0, 0)]);
        println!(
            "| one f32 GEMM (faer) | — | 1 | {secs:.2} | {:.1} |",
            2.0 * n3 / secs / 1e9
        );
        secs
    };
    for k in [1u32, 3, 8, 16] {
        let (h, d) = products(k);
        run(Bounces::Finite(k), Power::Horner, &format!("k = {k}"));
        if d != h {
            run(Bounces::Finite(k), Power::Doubling, &format!("k = {k}"));
        }
    }
    // Best of two each, as the GEMM unit is a best of three.
    let best = |solver: InfiniteSolver, label: &str| {
        (0..2)
            .map(|_| run_with(Bounces::Infinite, Power::Auto, solver, label))
            .fold(f64::INFINITY, f64::min)
    };
    let f32_lu = best(
        InfiniteSolver::F32,
        "k = ∞ (LU, f32, the default when accurate)",
    );
    let f64_lu = best(InfiniteSolver::F64, "k = ∞ (LU, f64, the reference)");
    println!(
        "\nk = ∞ (best of two) in units of one f32 GEMM (faer, best of three) of this run: f32 LU {:.2}, f64 LU {:.2}\n",
        f32_lu / gemm,
        f64_lu / gemm
    );
    run(Bounces::Auto(1e-3), Power::Auto, "Auto(1e-3)");
    // Baseline: numpy / OpenBLAS on the same size.
    let code = format!(
        "import time, numpy as np\nn={n}\nrng=np.random.default_rng(0)\n\
         a=rng.random((n,n),dtype=np.float32); b=rng.random((n,n),dtype=np.float32)\n\
         t=time.perf_counter(); a@b; g32=time.perf_counter()-t\n\
         a=a.astype(np.float64); b=b.astype(np.float64)\n\
         t=time.perf_counter(); a@b; g64=time.perf_counter()-t\n\
         t=time.perf_counter(); np.linalg.solve(np.eye(n)*n - a, b); s64=time.perf_counter()-t\n\
         print(g32, g64, s64)"
    );
    match std::process::Command::new("python3")
        .args(["-c", &code])
        .output()
    {
        Ok(o) if o.status.success() => {
            let v: Vec<f64> = String::from_utf8_lossy(&o.stdout)
                .split_whitespace()
                .filter_map(|x| x.parse().ok())
                .collect();
            if v.len() == 3 {
                println!("\nBaseline, numpy (OpenBLAS) on the same n:\n");
                println!("| operation | seconds | GFLOP/s |");
                println!("|---|---|---|");
                println!("| f32 GEMM | {:.2} | {:.1} |", v[0], 2.0 * n3 / v[0] / 1e9);
                println!("| f64 GEMM | {:.2} | {:.1} |", v[1], 2.0 * n3 / v[1] / 1e9);
                println!(
                    "| f64 solve, n right-hand sides | {:.2} | {:.1} |",
                    v[2],
                    (2.0 / 3.0 + 2.0) * n3 / v[2] / 1e9
                );
            }
        }
        _ => println!("\n(numpy not available: no baseline)"),
    }
}
