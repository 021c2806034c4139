//! Radiosity subcommands: run `voxelize`, `form-factors` or `transport` alone on a baked
//! directory, and `export` patches (JSON) or matrices (.npy).

use clap::{Args, Subcommand};
use relume::bake::{run_stage_on_with, BakeOptions};
use relume::baked::export::ExportWhat;
use relume::baked::gltf::{export_lit_glb, LitExport};
use relume::error::exit;
use relume::pipeline::checks::arg;
use relume::pipeline::checks::arg as args;
use relume::pipeline::knobs::{FormFactorsKnobs, TransportKnobs, VoxelizeKnobs};
use relume::pipeline::Stage;
use relume::player::Sun;
use relume::radiosity::formfactor::Estimator;
use relume::radiosity::patches::adaptive::AdaptiveParams;
use relume::radiosity::patches::voxelize::Resolution;
use relume::radiosity::transport::{Bounces, Power};
use relume::render::mesh_reference::FrameSettings;
use relume::scene::generate::Generated;
use relume::scene::light_spec::parse_light;
use relume::scene::Light;
use relume::Result;
use std::path::{Path, PathBuf};

/// Each `Option` flag falls back to the pipeline default of its knob (`pipeline::knobs`).
#[derive(Subcommand)]
pub enum Command {
    /// Write one of the indoor scenes relume makes itself (OBJ + MTL beside it): the bundled
    /// copies in scenes/generated/ are this output
    GenerateScene {
        /// Which scene
        #[arg(value_enum)]
        scene: Generated,
        /// Output .obj file; the .mtl is written beside it with the same stem
        #[arg(long, value_name = "FILE")]
        out: PathBuf,
    },
    /// Run the `voxelize` stage alone on a baked directory (later stages are dropped)
    Voxelize {
        /// Baked directory of a scene
        baked_dir: PathBuf,
        /// Choose the voxel size so that about this many patches result (default 1000)
        #[arg(long, value_name = "N", value_parser = arg::at_least_one)]
        target_patches: Option<u32>,
        /// Voxel edge length in scene units
        #[arg(long, value_name = "S", conflicts_with = "target_patches", value_parser = arg::positive_f64)]
        voxel_size: Option<f64>,
        /// About N adaptive patches: refined where materials, geometry or light vary
        /// (`Adaptive(target: N)` with its other knobs at their defaults)
        #[arg(long, value_name = "N", conflicts_with_all = ["target_patches", "voxel_size"], value_parser = arg::at_least_one)]
        adaptive: Option<u32>,
        /// Points per patch stored for the runtime's direct light (default 4)
        #[arg(long, value_name = "K", value_parser = arg::at_least_one)]
        samples_per_patch: Option<u32>,
        #[command(flatten)]
        budget: Budget,
    },
    /// Run the `form_factors` stage alone on a baked directory (later stages are dropped)
    FormFactors {
        /// Baked directory with patches
        baked_dir: PathBuf,
        /// Estimator (default: hemisphere-reciprocal)
        #[arg(long, value_enum)]
        estimator: Option<Estimator>,
        /// Rays per patch (hemisphere, default 4096) or point pairs per patch pair (pairwise, default 16)
        #[arg(long, value_name = "N", value_parser = arg::at_least_one)]
        samples: Option<u32>,
        /// Seed of the random numbers (default 0)
        #[arg(long)]
        seed: Option<u64>,
        #[command(flatten)]
        budget: Budget,
    },
    /// Run the `transport` stage alone on a baked directory
    Transport {
        /// Baked directory with form factors
        baked_dir: PathBuf,
        /// Bounces: a count k ≥ 1, `inf` (default), or `auto:TOL` (stop when a bounce adds less than TOL)
        #[arg(long, value_parser = arg::bounces)]
        bounces: Option<Bounces>,
        /// How finite k is evaluated (default: auto)
        #[arg(long, value_enum)]
        power: Option<Power>,
        #[command(flatten)]
        budget: Budget,
    },
    /// Export patches as JSON, the form-factor / transport matrix as .npy, the scene with its
    /// baked light as binary glTF (gltf: per-vertex radiance for the scene's lights and
    /// emitters plus --light / --sun), or the mean irradiance per scene object (objects: JSON)
    Export {
        /// Baked directory
        baked_dir: PathBuf,
        /// What to export
        #[arg(value_enum)]
        what: ExportWhat,
        /// Output file (.json, .npy, or .glb for gltf)
        #[arg(long, short)]
        out: PathBuf,
        #[command(flatten)]
        lit: LitArgs,
    },
}

/// The light setup of `export gltf` (the player's flags).
#[derive(Args)]
pub struct LitArgs {
    /// gltf: add a punctual light (repeatable), as the player's --light:
    /// point:X,Y,Z[:I[:R,G,B]], spot:X,Y,Z:DX,DY,DZ:ANGLE[:I[:R,G,B]], dir:DX,DY,DZ[:I[:R,G,B]]
    #[arg(long, value_name = "SPEC", value_parser = parse_light, allow_hyphen_values = true)]
    light: Vec<Light>,
    /// gltf: add the sun at azimuth,elevation in degrees, as the player's --sun (e.g. 20,30)
    #[arg(long, value_name = "AZ,EL", value_parser = args::sun, allow_hyphen_values = true)]
    sun: Option<Sun>,
    /// gltf: multiply radiance by this before clamping into COLOR_0 [default: 1]
    #[arg(long, value_name = "X", value_parser = arg::positive_f32)]
    exposure: Option<f32>,
    /// gltf: split triangles longer than this (scene units) into a grid, so that direct light
    /// and shadows vary across them [default: 1/32 of the scene's diagonal]
    #[arg(long, value_name = "L", value_parser = arg::positive_f32)]
    max_edge: Option<f32>,
    /// gltf: no shadows for the punctual lights and the sun
    #[arg(long)]
    no_shadows: bool,
    /// gltf: leave out the baked indirect light (direct light and emission only)
    #[arg(long)]
    no_indirect: bool,
}

impl LitArgs {
    fn given(&self) -> bool {
        !self.light.is_empty()
            || self.sun.is_some()
            || self.exposure.is_some()
            || self.max_edge.is_some()
            || self.no_shadows
            || self.no_indirect
    }

    fn setup(&self) -> LitExport {
        LitExport {
            lights: self.light.clone(),
            sun: self.sun,
            max_edge: self.max_edge,
            settings: FrameSettings {
                exposure: self.exposure.unwrap_or(1.0),
                shadows: !self.no_shadows,
                indirect: !self.no_indirect,
                ..Default::default()
            },
        }
    }
}

#[derive(Args)]
pub struct Budget {
    /// Refuse work whose estimated memory exceeds this (e.g. 512M, 8G; default 75% of RAM)
    #[arg(long, value_name = "SIZE", value_parser = relume::limits::parse_bytes)]
    max_memory: Option<u64>,
}

/// Run a radiosity subcommand.
pub fn run(cmd: &Command, json: bool, quiet: bool, ui: &crate::ui::Ui) -> Result<i32> {
    let (dir, stage, budget) = match cmd {
        Command::GenerateScene { scene, out } => return generate_scene(*scene, out, json, quiet),
        Command::Voxelize {
            baked_dir,
            target_patches,
            voxel_size,
            adaptive,
            samples_per_patch,
            budget,
        } => {
            let d = VoxelizeKnobs::default();
            let resolution = match (voxel_size, target_patches, adaptive) {
                (Some(s), _, _) => Resolution::VoxelSize(*s),
                (None, Some(n), _) => Resolution::TargetPatches(*n),
                (None, None, Some(n)) => Resolution::Adaptive(AdaptiveParams::new(*n)),
                (None, None, None) => d.resolution,
            };
            let knobs = VoxelizeKnobs {
                resolution,
                samples_per_patch: samples_per_patch.unwrap_or(d.samples_per_patch),
            };
            (baked_dir, Stage::Voxelize(knobs), budget)
        }
        Command::FormFactors {
            baked_dir,
            estimator,
            samples,
            seed,
            budget,
        } => {
            let d = FormFactorsKnobs::default();
            let knobs = FormFactorsKnobs {
                estimator: estimator.unwrap_or(d.estimator),
                samples: samples.or(d.samples),
                seed: seed.unwrap_or(d.seed),
            };
            (baked_dir, Stage::FormFactors(knobs), budget)
        }
        Command::Transport {
            baked_dir,
            bounces,
            power,
            budget,
        } => {
            let d = TransportKnobs::default();
            let knobs = TransportKnobs {
                bounces: bounces.unwrap_or(d.bounces),
                power: power.unwrap_or(d.power),
            };
            (baked_dir, Stage::Transport(knobs), budget)
        }
        Command::Export {
            baked_dir,
            what,
            out,
            lit,
        } => {
            if *what == ExportWhat::Gltf {
                let report = export_lit_glb(baked_dir, &lit.setup(), out)?;
                if json {
                    println!("{}", serde_json::to_string_pretty(&report).expect("report"));
                } else if !quiet {
                    eprintln!(
                        "wrote {}: {} objects, {} triangles, {} lights, transport {} ({} bytes)",
                        report.out,
                        report.objects,
                        report.triangles,
                        report.lights,
                        report.transport,
                        report.bytes
                    );
                }
                return Ok(exit::OK);
            }
            if *what == ExportWhat::Objects {
                let objects = relume::baked::export::export_objects(baked_dir, &lit.setup(), out)?;
                if json {
                    println!(
                        "{}",
                        serde_json::json!({"exported": "objects", "out": out, "objects": objects.len()})
                    );
                } else if !quiet {
                    eprintln!(
                        "wrote {}: light of {} objects",
                        out.display(),
                        objects.len()
                    );
                }
                return Ok(exit::OK);
            }
            if lit.given() {
                return Err(relume::error::Error::knob(
                    "--light, --sun, --exposure, --max-edge, --no-shadows and --no-indirect apply to `export gltf` and `export objects` only",
                ));
            }
            let file = relume::baked::export::export(baked_dir, *what, out)?;
            if json {
                println!("{}", serde_json::json!({"exported": file, "out": out}));
            }
            return Ok(exit::OK);
        }
    };
    let mut opts = BakeOptions::default();
    if let Some(m) = budget.max_memory {
        opts.max_memory = m;
    }
    let report = run_stage_on_with(dir, stage, &opts, ui)?;
    crate::print_stage_report(&report, dir, json, quiet);
    Ok(exit::OK)
}

fn generate_scene(which: Generated, out: &Path, json: bool, quiet: bool) -> Result<i32> {
    relume::baked::images::check_extension(out, &["obj"])?;
    let (scene, mtl_path) = relume::baked::export::write_generated_scene(which, out)?;
    if json {
        println!(
            "{}",
            serde_json::json!({"scene": which.name(), "out": out, "mtl": mtl_path,
                "triangles": scene.triangles.len(), "vertices": scene.positions.len(),
                "objects": scene.objects.len(), "area": scene.total_area()})
        );
    } else if !quiet {
        eprintln!(
            "{} → {} ({} triangles, {} objects, {:.1} m² of surface)",
            which.name(),
            out.display(),
            scene.triangles.len(),
            scene.objects.len(),
            scene.total_area()
        );
    }
    Ok(exit::OK)
}
