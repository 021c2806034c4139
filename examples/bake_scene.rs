//! Bake a scene with a pipeline file and read the light each of its objects receives — the
//! library without the command line.
//!
//! ```sh
//! cargo run --release --example bake_scene                     # pipelines/cornell.ron
//! cargo run --release --example bake_scene -- PIPELINE.ron OUT_DIR
//! ```
//!
//! The pipeline is parsed and checked (`pipeline`), baked into `OUT_DIR` atomically (`bake`),
//! and the baked directory is read back and lit by the scene's own emitters (`baked::gltf`):
//! per object, the mean irradiance of light reflected at least once or emitted (the same
//! numbers as `relume-bake export OUT_DIR objects`).

use relume::bake::{run_pipeline, BakeOptions};
use relume::baked::gltf::{lit_patches, LitExport};
use relume::pipeline::parse::parse_pipeline;
use relume::progress::Silent;
use relume::radiosity::mesh::objects::object_light;
use std::path::PathBuf;

fn main() -> relume::error::Result<()> {
    let mut args = std::env::args().skip(1);
    let pipeline_path = PathBuf::from(args.next().unwrap_or("pipelines/cornell.ron".into()));
    let out = args
        .next()
        .map(PathBuf::from)
        .unwrap_or_else(|| std::env::temp_dir().join("relume-example-bake"));

    let pipeline = parse_pipeline(&pipeline_path)?;
    let report = run_pipeline(&pipeline, &out, &BakeOptions::default(), &Silent)?;
    for stage in &report.stages {
        println!("{:<12} {:>8.2} s", stage.stage, stage.seconds);
    }

    let lit = lit_patches(&out, &LitExport::default())?;
    println!(
        "\n{:<24} {:>10}  mean irradiance (R, G, B)",
        "object", "area"
    );
    for o in object_light(&lit.scene, &lit.set, &lit.b) {
        let [r, g, b] = o.irradiance_patches;
        println!("{:<24} {:>10.4}  {r:.4} {g:.4} {b:.4}", o.name, o.area);
    }
    Ok(())
}
