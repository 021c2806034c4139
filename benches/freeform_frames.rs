//! Frame times of the freeform casters — the timing table of Vyatkin et al. (2018), whose values
//! the extracted text lost: a plane with 16, 64 and 256 perturbations
//! (`scenes/freeform/bench/terrain-N.ron`) at 640x480 (and, with `--all`, 1280x720 and 1920x1080),
//! by the exact CPU reference, the CPU multilevel caster (affine bound) and the GPU kernel
//! (`shaders/freeform.wgsl`). Primary rays only (no shading, no shadows), as ratios against the
//! reference in the same run. On Mesa's lavapipe the "GPU" time is a software rasteriser's CPU
//! time.
//!
//! `cargo bench --bench freeform_frames [-- --all] [-- --cpu-only] [-- --perturbations N]`
//! (`--cpu-only` skips the GPU: a 256-perturbation frame at 640x480 takes 20 minutes on
//! lavapipe; `--perturbations N` runs only the scene with N of them).

use relume::freeform::rmlrc::{camera_outside, cast, RmlrcParams};
use relume::freeform::shade::primary;
use relume::freeform::twin::{GpuField, View32};
use relume::freeform::{Bound, Field, Method, View};
use relume::gpu::freeform_caster::FreeformCaster;
use relume::gpu::Gpu;
use relume::scene::freeform::FreeformScene;
use std::path::Path;
use std::time::Instant;

fn seconds(f: impl FnOnce()) -> f64 {
    let t = Instant::now();
    f();
    t.elapsed().as_secs_f64()
}

fn main() {
    let all = std::env::args().any(|a| a == "--all");
    let cpu_only = std::env::args().any(|a| a == "--cpu-only");
    let args: Vec<String> = std::env::args().collect();
    let only: Option<u32> = args
        .iter()
        .position(|a| a == "--perturbations")
        .and_then(|i| args.get(i + 1))
        .map(|v| v.parse().expect("--perturbations takes 16, 64 or 256"));
    let sizes: &[(u32, u32)] = if all {
        &[(640, 480), (1280, 720), (1920, 1080)]
    } else {
        &[(640, 480)]
    };
    let gpu = if cpu_only { None } else { Gpu::new(None).ok() };
    let caster = gpu
        .as_ref()
        .map(|g| FreeformCaster::new(g).expect("kernel compiles"));
    let adapter = gpu
        .as_ref()
        .map(|g| g.info.name.clone())
        .unwrap_or_else(|| "none".into());
    println!("GPU adapter: {adapter}\n");
    println!(
        "| perturbations | size | reference s | RMLRC CPU s (÷ ref) | GPU s (÷ ref), GPU hits | reference hits |"
    );
    println!("|---|---|---|---|---|---|");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for n in [16, 64, 256]
        .into_iter()
        .filter(|n| only.is_none_or(|o| o == *n))
    {
        let scene =
            FreeformScene::load(&root.join(format!("scenes/freeform/bench/terrain-{n}.ron")))
                .unwrap();
        let field = Field::compile(&scene.shape).unwrap();
        for &(w, h) in sizes {
            let view = View::new(scene.camera.as_ref().unwrap(), w, h);
            let params = RmlrcParams::default();
            let mut hits = 0;
            let reference = seconds(|| {
                hits = primary(&field, &view, &Method::Reference)
                    .0
                    .iter()
                    .filter(|h| h.is_some())
                    .count();
            });
            let rmlrc = seconds(|| {
                cast(&field, &view, &params);
            });
            let gpu_s = match (&gpu, &caster) {
                (Some(g), Some(c)) => {
                    let gf = GpuField::upload(&field, view.eye).unwrap();
                    let v32 = View32::of(&view);
                    let prune = camera_outside(&field, &view, Bound::Affine);
                    // Warm-up at a small size (the kernels are compiled already; this runs
                    // the first dispatches and buffer creations).
                    let small = View32::of(&View::new(scene.camera.as_ref().unwrap(), 32, 24));
                    c.cast(g, &gf, &small, params.top_level, params.refine, prune)
                        .unwrap();
                    let mut gpu_hits = 0;
                    let s = seconds(|| {
                        let out = c
                            .cast(g, &gf, &v32, params.top_level, params.refine, prune)
                            .unwrap();
                        gpu_hits = out.iter().filter(|h| h[0] >= 0.0).count();
                    });
                    format!("{s:.3} ({:.2}), {gpu_hits} hits", s / reference)
                }
                _ if cpu_only => "not run (--cpu-only)".into(),
                _ => "no adapter".into(),
            };
            println!(
                "| {n} | {w}x{h} | {reference:.3} | {rmlrc:.3} ({:.2}) | {gpu_s} | {hits} |",
                rmlrc / reference
            );
        }
    }
}
