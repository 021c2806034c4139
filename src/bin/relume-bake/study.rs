//! `relume-bake study radiosity|compression|terrain|atmosphere`: the speed/accuracy sweeps of docs/algorithms.md §7.
//! Thin: resolve the input (defaults: the bundled Cornell box and Puget Sound), pick the full or
//! quick configuration with the command line's overrides, run `relume::study`, write the report.

use crate::ui::Ui;
use clap::{Args, Subcommand};
use relume::error::exit;
use relume::pipeline::checks::arg;
use relume::study::{
    self, atmosphere, compression, inputs, radiosity, radiosity_objects, report, terrain, Study,
};
use relume::Result;
use std::path::PathBuf;

const STUDY_HELP: &str = "\
Writes DIR/study.json (every setting: knobs, errors, seconds, bytes), DIR/study.md (a table per
sweep with ratios against its baseline) and PNG plots (log axes). --quick uses small sizes (well
under a minute on 2 cores); the full study takes minutes. See docs/study.md.";

#[derive(Args)]
pub struct StudyArgs {
    #[command(subcommand)]
    pub which: Which,
}

#[derive(Subcommand)]
pub enum Which {
    /// Patch count, form-factor estimator × samples, bounces (error of B = S·E); per-object
    /// irradiance of uniform vs adaptive patches against a reference
    #[command(after_help = STUDY_HELP)]
    Radiosity(RadiosityArgs),
    /// Reorder passes, split percentage × dense encoding (error of the decoded S and of S·E)
    #[command(after_help = STUDY_HELP)]
    Compression(CompressionArgs),
    /// Hard shadows (exact vs accelerated), the min/max mipmap, soft shadows (every method vs exhaustive)
    #[command(after_help = STUDY_HELP)]
    Terrain(TerrainArgs),
    /// In-scattering error of the constant-density fog and Hillaire's tables against sun elevation
    #[command(after_help = STUDY_HELP)]
    Atmosphere(AtmosphereArgs),
}

#[derive(Args)]
pub struct AtmosphereArgs {
    #[command(flatten)]
    pub common: Common,
    /// Monte Carlo paths per view ray of the reference's multiple scattering (default 2,000;
    /// 1,000 with --quick). Its standard error falls as 1/√paths: 40,000 takes ~40 s on 2 cores
    /// and leaves it under 1 % above 5°
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=10_000_000))]
    pub paths: Option<u32>,
}

#[derive(Args)]
pub struct Common {
    /// Output directory (created if missing)
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Small sizes: well under a minute on 2 cores
    #[arg(long)]
    pub quick: bool,
}

#[derive(Args)]
pub struct SceneSource {
    /// Scene file (.obj .gltf .glb); default: the bundled Cornell box (scale 0.001)
    #[arg(long, value_name = "FILE", conflicts_with = "pipeline")]
    pub scene: Option<PathBuf>,
    /// Multiply the scene's positions by this (with --scene; default 1)
    #[arg(long, value_name = "S", requires = "scene")]
    pub scale: Option<f32>,
    /// Take the scene (and, for compression, the voxelize/form-factor/transport knobs) from a pipeline
    #[arg(long, value_name = "FILE")]
    pub pipeline: Option<PathBuf>,
}

#[derive(Args)]
pub struct RadiosityArgs {
    #[command(flatten)]
    pub common: Common,
    #[command(flatten)]
    pub source: SceneSource,
    /// Target patch counts of the patch sweep, e.g. 150,600,2400 (the largest is the
    /// reference), and of the per-object sweep
    #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub patches: Option<Vec<u32>>,
    /// Per-object irradiance of the scene by an independent renderer (JSON:
    /// {"object": {"mean": [r, g, b], "stderr": [r, g, b]}, ...}, as
    /// tests/support/mitsuba_objects.py writes it; or {"object": {"total": [r, g, b], ...}}
    /// with the punctual lights' direct light included, as tests/support/mitsuba_textured.py
    /// writes it): adds the per-object sweep, uniform vs adaptive patches
    #[arg(long, value_name = "FILE")]
    pub objects_reference: Option<PathBuf>,
    /// Sweeps to run (default: patches,estimator,bounces, and objects with --objects-reference)
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    pub sweeps: Option<Vec<SweepName>>,
}

/// A sweep of `study radiosity`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SweepName {
    Patches,
    Estimator,
    Bounces,
    Objects,
}

impl SweepName {
    fn sweep(self) -> radiosity::RadiositySweep {
        match self {
            SweepName::Patches => radiosity::RadiositySweep::Patches,
            SweepName::Estimator => radiosity::RadiositySweep::Estimator,
            SweepName::Bounces => radiosity::RadiositySweep::Bounces,
            SweepName::Objects => radiosity::RadiositySweep::Objects,
        }
    }
}

#[derive(Args)]
pub struct CompressionArgs {
    #[command(flatten)]
    pub common: Common,
    #[command(flatten)]
    pub source: SceneSource,
    /// Study the transport of an existing bake (transport.npy) instead of baking one
    #[arg(long, value_name = "DIR", conflicts_with_all = ["scene", "pipeline", "patches"])]
    pub baked: Option<PathBuf>,
    /// Target patch count of the matrix baked for the study (default 1000, quick 300)
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub patches: Option<u32>,
}

#[derive(Args)]
pub struct TerrainArgs {
    #[command(flatten)]
    pub common: Common,
    /// Height map (.png .jpg .exr .tif .raw); default: Puget Sound (pipelines/puget-sound.ron)
    #[arg(long, value_name = "FILE", conflicts_with = "pipeline")]
    pub heightmap: Option<PathBuf>,
    /// Take the height map and its knobs from a pipeline
    #[arg(long, value_name = "FILE")]
    pub pipeline: Option<PathBuf>,
    /// Metres per texel (overrides the file / pipeline)
    #[arg(long, value_name = "M", value_parser = arg::finite_positive)]
    pub cell_size: Option<f64>,
    /// Metres per file unit (overrides the pipeline)
    #[arg(long, value_name = "S", value_parser = arg::finite_positive)]
    pub height_scale: Option<f64>,
    /// Map sizes (longer side, texels), e.g. 1024,2048,4096
    #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = clap::value_parser!(u32).range(1..=65_536))]
    pub sizes: Option<Vec<u32>>,
    /// Sun elevations in degrees, e.g. 5,15,30,60
    #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = arg::elevation, allow_hyphen_values = true)]
    pub elevations: Option<Vec<f64>>,
    /// Sun azimuth, degrees clockwise from north
    #[arg(long, value_name = "DEG", allow_hyphen_values = true, value_parser = arg::finite)]
    pub azimuth: Option<f64>,
    /// Sun elevations of the soft-shadow sweep in degrees, e.g. 2,5,10
    #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = arg::elevation, allow_hyphen_values = true)]
    pub soft_elevations: Option<Vec<f64>>,
    /// Rows of each map the soft-shadow sweep times (evenly spaced; the exhaustive reference
    /// is slow at low sun)
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=65_536))]
    pub soft_rows: Option<u32>,
    /// Start levels of the dynamic-programming rows, e.g. 0,1,4 (default 0,1,2,3,4,8)
    #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = clap::value_parser!(i32).range(-1..=30), allow_hyphen_values = true)]
    pub dp_levels: Option<Vec<i32>>,
    /// Interval caps of the dynamic-programming rows, each with every start level, e.g.
    /// 0,4,16 (0 = as many as the track needs; default 0)
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    pub dp_intervals: Option<Vec<u32>>,
}

fn source(s: &SceneSource) -> inputs::SceneSource {
    inputs::SceneSource {
        pipeline: s.pipeline.clone(),
        scene: s.scene.clone(),
        scale: s.scale,
    }
}

/// `relume-bake study ...`.
pub fn run(args: &StudyArgs, ui: &Ui, json: bool, quiet: bool) -> Result<i32> {
    let (out, quick) = match &args.which {
        Which::Radiosity(a) => (&a.common.out, a.common.quick),
        Which::Compression(a) => (&a.common.out, a.common.quick),
        Which::Terrain(a) => (&a.common.out, a.common.quick),
        Which::Atmosphere(a) => (&a.common.out, a.common.quick),
    };
    // Refuse an unusable output path before minutes of work.
    report::prepare_dir(out)?;
    let mut study = match &args.which {
        Which::Radiosity(a) => {
            let (scene, name, _) = inputs::scene(&source(&a.source))?;
            let mut cfg = if quick {
                radiosity::RadiosityConfig::quick()
            } else {
                radiosity::RadiosityConfig::full()
            };
            if let Some(p) = &a.patches {
                cfg.patch_targets = p.clone();
            }
            if let Some(path) = &a.objects_reference {
                let mut config = if quick {
                    radiosity_objects::ObjectsConfig::quick()
                } else {
                    radiosity_objects::ObjectsConfig::full()
                };
                if let Some(p) = &a.patches {
                    config.targets = p.clone();
                }
                cfg.objects = Some(radiosity::ObjectsStudy {
                    reference: radiosity_objects::read_reference(path)?,
                    source: path.clone(),
                    config,
                });
                cfg.sweeps.push(radiosity::RadiositySweep::Objects);
            }
            if let Some(s) = &a.sweeps {
                cfg.sweeps = s.iter().map(|s| s.sweep()).collect();
            }
            Study::new("radiosity", name, quick, radiosity::run(&scene, &cfg, ui)?)
        }
        Which::Compression(a) => {
            let input = inputs::compression_input(
                a.baked.as_deref(),
                &source(&a.source),
                a.patches,
                quick,
            )?;
            let cfg = if quick {
                compression::CompressionConfig::quick()
            } else {
                compression::CompressionConfig::full()
            };
            let sweeps = compression::run(&input, &cfg, ui)?;
            Study::new("compression", input.description.clone(), quick, sweeps)
        }
        Which::Terrain(a) => {
            let (map, name) = inputs::heightmap(
                a.heightmap.as_deref(),
                a.pipeline.as_deref(),
                a.cell_size,
                a.height_scale,
            )?;
            let mut cfg = if quick {
                terrain::TerrainConfig::quick()
            } else {
                terrain::TerrainConfig::full()
            };
            if let Some(s) = &a.sizes {
                cfg.sizes = s.iter().map(|&v| v as usize).collect();
            }
            if let Some(e) = &a.elevations {
                cfg.elevations = e.clone();
            }
            if let Some(az) = a.azimuth {
                cfg.azimuth = az;
            }
            if let Some(e) = &a.soft_elevations {
                cfg.soft.elevations = e.clone();
            }
            if let Some(r) = a.soft_rows {
                cfg.soft.rows = r as usize;
            }
            if a.dp_levels.is_some() || a.dp_intervals.is_some() {
                let (levels, intervals) = cfg.soft.dp_knobs();
                cfg.soft.set_dp(
                    a.dp_levels.as_deref().unwrap_or(&levels),
                    a.dp_intervals.as_deref().unwrap_or(&intervals),
                );
            }
            Study::new("terrain", name, quick, terrain::run(&map, &cfg, ui)?)
        }
        Which::Atmosphere(a) => {
            let mut cfg = if quick {
                atmosphere::AtmosphereConfig::quick()
            } else {
                atmosphere::AtmosphereConfig::full()
            };
            if let Some(n) = a.paths {
                cfg.paths = n as usize;
            }
            let input = format!(
                "Earth's air (Atmosphere::earth), eye at 1.5 km, {} reference paths per ray",
                cfg.paths
            );
            Study::new("atmosphere", input, quick, atmosphere::run(&cfg))
        }
    };
    study::report::write(&mut study, out)?;
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(&study).expect("study serialises")
        );
    } else if !quiet {
        println!("{}", report::markdown(&study));
        eprintln!(
            "wrote {} ({} files: {})",
            out.display(),
            study.files.len(),
            study.files.join(", ")
        );
    }
    Ok(exit::OK)
}
