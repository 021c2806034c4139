//! Headless frame times of the player, split by pass (GPU timestamp queries), for the Cornell
//! box, the furnished room (78k triangles, 4,000 patches) and Puget Sound 2K at 640x480 and
//! 1920x1080 (`PIPELINES=furnished-room,cornell` runs some). On Mesa's lavapipe/llvmpipe these "GPU"
//! times are CPU times of a software rasteriser, not GPU times.
//!
//! The terrain frame is one render pass with the relief shadows traced per pixel inside it: the
//! shadows' cost is the difference between the "shadows" and "no shadows" rows; the thematic
//! textures' cost the difference between the horizon-map rows with and without themes, each
//! atmosphere model's the difference against "air: none" (rows without an "air:" label use
//! Hillaire's, the default; its tables are rebuilt every frame here, as the sun turns).
//!
//! `cargo bench --bench player_frames [-- --frames N]`

use relume::atmosphere::Model;
use relume::bake::{run_pipeline, BakeOptions};
use relume::gpu::Gpu;
use relume::pipeline::knobs::HorizonMapsKnobs;
use relume::pipeline::{parse_pipeline, Stage};
use relume::player::headless::{render_frames, HeadlessPlan};
use relume::player::{PlayerOptions, Sun};
use relume::render::mesh_reference::FrameSettings;
use std::collections::BTreeMap;
use std::path::Path;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

/// The shadows of a row.
#[derive(Clone, Copy, PartialEq)]
enum Shadows {
    None,
    /// Shadow maps (mesh) or the accelerated traversal (terrain).
    Hard,
    /// Terrain: the baked horizon maps.
    Horizon,
    Soft,
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let frames: usize = args
        .iter()
        .position(|a| a == "--frames")
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(5);
    let gpu = match Gpu::new(None) {
        Ok(g) => g,
        Err(e) => {
            eprintln!("SKIP: {e}");
            return;
        }
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = std::env::temp_dir().join(format!("relume-player-bench-{}", std::process::id()));
    println!(
        "adapter: {} ({}, {}); median of {frames} frames after one warm-up frame\n",
        gpu.info.name, gpu.info.backend, gpu.info.device_type
    );
    println!("| scene | size | settings | frame wall ms | GPU ms per pass |");
    println!("|---|---|---|---|---|");
    for (pipeline, configs) in [
        (
            "pipelines/cornell.ron",
            vec![
                ("emitter + sun, shadows", Shadows::Hard),
                ("emitter + sun, no shadows", Shadows::None),
            ],
        ),
        (
            "pipelines/furnished-room.ron",
            vec![
                ("emitters + sun, shadows", Shadows::Hard),
                ("emitters + sun, no shadows", Shadows::None),
            ],
        ),
        (
            "pipelines/puget-sound-2k.ron",
            vec![
                ("no shadows", Shadows::None),
                ("hard shadows (traversal)", Shadows::Hard),
                ("hard shadows (horizon maps, 64)", Shadows::Horizon),
                (
                    "horizon maps, hypsometric tint (no themes)",
                    Shadows::Horizon,
                ),
                ("horizon maps, themes, air: none", Shadows::Horizon),
                (
                    "horizon maps, themes, air: fog per vertex",
                    Shadows::Horizon,
                ),
                ("horizon maps, themes, air: fog per pixel", Shadows::Horizon),
                ("soft shadows", Shadows::Soft),
            ],
        ),
    ] {
        let name = pipeline
            .trim_start_matches("pipelines/")
            .trim_end_matches(".ron");
        if let Ok(only) = std::env::var("PIPELINES") {
            if !only.split(',').any(|o| o.trim() == name) {
                continue;
            }
        }
        let mut p = parse_pipeline(&root.join(pipeline)).expect("pipeline");
        if p.input.kind() == "heightmap"
            && !p.stages.iter().any(|s| matches!(s, Stage::HorizonMaps(_)))
        {
            // The player's horizon-map shadows need them baked (64 directions, 512 MiB at 2K).
            p.stages
                .push(Stage::HorizonMaps(HorizonMapsKnobs::default()));
        }
        let dir = tmp.join(Path::new(pipeline).file_stem().unwrap());
        run_pipeline(&p, &dir, &BakeOptions::default(), &relume::progress::Silent).expect("bake");
        for (w, h) in [(640u32, 480u32), (1920, 1080)] {
            for (label, shadows) in &configs {
                // The headless loop of relume-player itself; frame 0 is the warm-up. The sun
                // turns 360°/frames per frame, so horizon maps upload a new pair of planes
                // every frame (their worst case).
                let plan = HeadlessPlan {
                    dir: dir.clone(),
                    out: tmp.join("frames"),
                    size: (w, h),
                    frames: frames as u32 + 1,
                    sun: Some(Sun {
                        azimuth_deg: 300.0,
                        elevation_deg: 12.0,
                    }),
                    lights: Vec::new(),
                    camera: None,
                    settings: FrameSettings {
                        shadows: *shadows != Shadows::None,
                        soft_shadows: *shadows == Shadows::Soft,
                        horizon_shadows: *shadows == Shadows::Horizon,
                        themes: !label.contains("no themes"),
                        // The default is Hillaire's model.
                        atmosphere: if label.ends_with("air: none") {
                            Model::None
                        } else if label.ends_with("per vertex") {
                            Model::Fog
                        } else if label.ends_with("per pixel") {
                            Model::FogPerPixel
                        } else {
                            Model::Hillaire
                        },
                        exposure: 2.0,
                        ..Default::default()
                    },
                    exposure: relume::render::exposure::Exposure::Fixed(2.0),
                    options: PlayerOptions::default(),
                };
                let report = render_frames(&gpu, &plan).expect("frames");
                let mut wall = Vec::new();
                let mut passes: BTreeMap<String, Vec<f64>> = BTreeMap::new();
                for f in &report.frames[1..] {
                    wall.push(f.cpu_ms);
                    for (n, t) in &f.gpu_ms {
                        passes.entry(n.clone()).or_default().push(*t);
                    }
                }
                let per_pass: Vec<String> = passes
                    .into_iter()
                    .map(|(n, v)| format!("{n} {:.1}", median(v)))
                    .collect();
                println!(
                    "| {name} | {w}x{h} | {label} | {:.1} | {} |",
                    median(wall),
                    per_pass.join(", ")
                );
            }
        }
    }
    let _ = std::fs::remove_dir_all(&tmp);
}
