//! `relume-bake`: the offline toolchain. Thin: parse arguments into a validated plan, call the
//! library, show progress, print errors with their cause chain, exit with a code per cause.

mod compress;
mod freeform;
mod horizon;
mod radiosity;
mod scale;
mod study;
mod sun_args;
mod terrain;
mod theme;
mod ui;

use clap::{Args, Parser, Subcommand};
use relume::bake::report;
use relume::error::exit;
use relume::heightmap::{HeightMapOptions, NoDataPolicy};
use relume::load::{load_any, summarize_heightmap, summarize_scene, LoadedInput};
use relume::scene::SceneOptions;
use relume::Result;
use serde::Serialize;
use std::path::{Path, PathBuf};
use ui::Ui;

const EXIT_CODES: &str = exit::HELP;

#[derive(Parser)]
#[command(
    name = "relume-bake",
    version,
    about = "Bake light offline: radiosity transfer for meshes, shadows for height maps",
    long_about = "Bake light offline. `relume-bake run PIPELINE` runs a pipeline file (pipelines/*.ron) \
                  and writes a verified baked directory that relume-player renders.",
    after_help = EXIT_CODES
)]
struct Cli {
    #[command(flatten)]
    global: Global,
    #[command(subcommand)]
    command: Command,
}

#[derive(Args)]
struct Global {
    /// No progress output (errors are still printed)
    #[arg(short, long, global = true)]
    quiet: bool,
    /// Print a machine-readable JSON report on stdout
    #[arg(long, global = true)]
    json: bool,
    /// Worker threads (default: all cores). Output is identical for any count
    #[arg(short = 'j', long, global = true, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: Option<u32>,
}

#[derive(Subcommand)]
enum Command {
    /// Run a pipeline file and write its baked directory
    #[command(after_help = EXIT_CODES)]
    Run {
        /// Pipeline file (RON), e.g. pipelines/cornell.ron
        pipeline: PathBuf,
        /// Output directory (default: the pipeline's `output`, else out/<pipeline name>)
        #[arg(short, long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Refuse to start when the estimated peak memory exceeds this (e.g. 512M, 8G; default 75% of RAM)
        #[arg(long, value_name = "SIZE", value_parser = relume::limits::parse_bytes)]
        max_memory: Option<u64>,
        /// Stage cache: finished stages are kept here, and a re-run redoes only the stages whose
        /// inputs or knobs changed (default: .relume-cache beside the output)
        #[arg(long, value_name = "DIR", conflicts_with = "no_cache")]
        cache: Option<PathBuf>,
        /// Neither read nor write the stage cache
        #[arg(long)]
        no_cache: bool,
        /// Run every stage, even when the output is up to date or the cache holds them
        #[arg(long)]
        force: bool,
        #[command(flatten)]
        shard: scale::ShardArgs,
    },
    /// Assemble the shards of a bake (`run --shard I/N`) into its baked directory, byte for byte
    /// what a single `run` writes
    #[command(after_help = EXIT_CODES)]
    Merge(scale::MergeArgs),
    /// Show the stages a pipeline would run, with estimated peak memory and output size; writes nothing
    Plan {
        /// Pipeline file (RON)
        pipeline: PathBuf,
        /// Output directory to report (default as for `run`)
        #[arg(short, long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Also plan the bake split into N shards: per-shard and merge peak memory, shard sizes
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=65536))]
        shards: Option<u32>,
    },
    /// Show a baked directory's manifest and verify every file's size and hash
    #[command(after_help = EXIT_CODES)]
    Inspect {
        /// Baked directory
        baked_dir: PathBuf,
    },
    #[command(flatten)]
    Radiosity(radiosity::Command),
    /// Hard relief shadows of a height map for one sun: shadow mask and shaded relief (PNG)
    #[command(after_help = EXIT_CODES)]
    Shadow(terrain::ShadowArgs),
    /// Horizon angles for N azimuths and the sky-view factor of a height map (GeoTIFF)
    Horizon(horizon::HorizonArgs),
    /// Hours of direct sun over a day (and clear-sky direct insolation) of a height map
    Sunlight(horizon::SunlightArgs),
    /// Soft shadows of the sun's disc (penumbrae, curved planets): lit fraction and shaded relief
    #[command(after_help = EXIT_CODES)]
    Softshadow(terrain::SoftShadowArgs),
    /// Compose a theme set's albedo (thematic textures with fractal borders) at any resolution
    #[command(after_help = EXIT_CODES)]
    Theme(theme::ThemeArgs),
    /// Write a synthetic height map: stress maps (spikes, steps) and analytic shapes
    Generate(terrain::GenerateArgs),
    /// Load a scene (.obj .gltf .glb) or height map (.png .jpg .exr .tif .raw) and summarise it
    Load {
        /// Scene or height-map file
        file: PathBuf,
        #[command(flatten)]
        knobs: LoadKnobs,
    },
    #[command(flatten)]
    Compress(compress::CompressCommand),
    /// Function-based geometry: render freeform scenes (quadrics + perturbations, CSG)
    #[command(subcommand, after_help = EXIT_CODES)]
    Freeform(freeform::FreeformCommand),
    /// Speed/accuracy sweeps: error vs time vs bytes for every knob (JSON, Markdown, PNG plots)
    #[command(after_help = EXIT_CODES)]
    Study(study::StudyArgs),
}

#[derive(Args, Clone)]
struct LoadKnobs {
    /// Scene: multiply positions by this factor (0.001: millimetres → metres)
    #[arg(long, default_value_t = 1.0)]
    scale: f32,
    /// Height map: metres per texel (overrides the file's world file / GeoTIFF tags)
    #[arg(long, value_name = "M")]
    cell_size: Option<f64>,
    /// Height map: metres per file unit
    #[arg(long, value_name = "S")]
    height_scale: Option<f64>,
    /// Height map: what to do with no-data texels (default: error)
    #[arg(long, value_enum)]
    nodata: Option<NoDataPolicy>,
    /// Height map: extra value (in file units) that marks missing data
    #[arg(long, value_name = "V")]
    nodata_value: Option<f64>,
    /// Height map: box-filter down by this integer factor after loading (cell size grows)
    #[arg(long, value_parser = relume::pipeline::checks::arg::at_least_one)]
    downsample: Option<u32>,
    /// Height map: size of a raw little-endian f32 file, WIDTHxHEIGHT
    #[arg(long, value_name = "WxH", value_parser = relume::pipeline::checks::arg::wxh)]
    raw_size: Option<(usize, usize)>,
}

impl LoadKnobs {
    fn heightmap_options(&self) -> HeightMapOptions {
        let d = HeightMapOptions::default();
        HeightMapOptions {
            cell_size: self.cell_size.map(|c| [c, c]),
            height_scale: self.height_scale,
            nodata_value: self.nodata_value,
            nodata: self.nodata.unwrap_or(d.nodata),
            raw_size: self.raw_size.map(|(w, h)| [w, h]),
            downsample: self.downsample.unwrap_or(d.downsample),
        }
    }
}

fn main() {
    relume::limits::tune_allocator();
    restore_sigpipe();
    let cli = Cli::parse();
    if let Some(n) = cli.global.threads {
        // Only fails if a pool exists already, which cannot happen this early.
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(n as usize)
            .build_global();
    }
    let ui = Ui::new(cli.global.quiet || cli.global.json);
    let code = match dispatch(&cli, &ui) {
        Ok(code) => code,
        Err(e) => {
            ui::print_error(&e);
            if cli.global.json {
                let j = serde_json::json!({"error": {"class": e.class(), "message": e.to_string(), "exit_code": e.exit_code()}});
                println!("{j}");
            }
            e.exit_code()
        }
    };
    std::process::exit(code);
}

fn dispatch(cli: &Cli, ui: &Ui) -> Result<i32> {
    let json = cli.global.json;
    match &cli.command {
        Command::Run {
            pipeline,
            out,
            max_memory,
            cache,
            no_cache,
            force,
            shard,
        } => {
            let p = relume::pipeline::parse_pipeline(pipeline)?;
            let out = relume::pipeline::output_dir(pipeline, &p, out.as_deref());
            let mut opts = relume::bake::BakeOptions::default();
            if let Some(m) = max_memory {
                opts.max_memory = *m;
            }
            opts.force = *force;
            if !no_cache {
                opts.cache = Some(cache.clone().unwrap_or_else(|| report::default_cache(&out)));
            }
            let (sharding, note) = shard.sharding(&out)?;
            let sharded = !matches!(sharding, relume::bake::Sharding::Whole);
            opts.sharding = sharding;
            if let Some(note) = note {
                ui.note(&note);
            }
            let report = relume::bake::run_pipeline(&p, &out, &opts, ui)?;
            if json {
                print_json(&report);
            } else if !cli.global.quiet {
                match report::shard_summary(&report, &out) {
                    Some(s) => eprint!("{s}"),
                    None if sharded => eprint!("{}", report::nothing_to_shard(&out)),
                    None => eprint!("{}", report::bake_summary(&report)),
                }
            }
            Ok(exit::OK)
        }
        Command::Merge(m) => {
            let set = relume::bake::shard::ShardSet::scan(&m.shard_dirs)?;
            let p = set.pipeline().clone();
            let mut opts = relume::bake::BakeOptions::default();
            if let Some(mm) = m.max_memory {
                opts.max_memory = mm;
            }
            opts.cache = Some(
                m.cache
                    .clone()
                    .unwrap_or_else(|| report::default_cache(&m.output)),
            );
            opts.sharding = relume::bake::Sharding::Merge {
                dirs: m.shard_dirs.clone(),
            };
            let report = relume::bake::run_pipeline(&p, &m.output, &opts, ui)?;
            if json {
                print_json(&report);
            } else if !cli.global.quiet {
                match report::shard_summary(&report, &m.output) {
                    Some(s) => eprint!("{s}"),
                    None => eprint!("{}", report::bake_summary(&report)),
                }
            }
            Ok(exit::OK)
        }
        Command::Plan {
            pipeline,
            out,
            shards,
        } => {
            let p = relume::pipeline::parse_pipeline(pipeline)?;
            let out = relume::pipeline::output_dir(pipeline, &p, out.as_deref());
            relume::limits::baseline_rss();
            let input = relume::load::load_input(&p.input)?;
            let plan = relume::bake::plan(&p, &input, &out);
            let split = shards.map(|n| {
                relume::bake::plan::plan_shards(
                    &p,
                    &relume::bake::plan::PlanInput::of(&input),
                    &Default::default(),
                    n as usize,
                )
            });
            if json {
                print_json(&serde_json::json!({"plan": plan, "shards": split}));
            } else {
                print!("{}", plan.to_text(pipeline));
                if let Some(s) = &split {
                    print!("{}", s.to_text());
                }
            }
            Ok(exit::OK)
        }
        Command::Inspect { baked_dir } => {
            let i = relume::baked::manifest::Inspection::of(baked_dir)?;
            if json {
                print_json(&i);
            } else {
                print!("{}", i.to_text());
            }
            i.result()?;
            Ok(exit::OK)
        }
        Command::Radiosity(c) => radiosity::run(c, json, cli.global.quiet, ui),
        Command::Compress(c) => compress::run(c, ui, json, cli.global.quiet),
        Command::Freeform(c) => freeform::run(c, json, cli.global.quiet),
        Command::Study(a) => study::run(a, ui, json, cli.global.quiet),
        Command::Shadow(a) => terrain::shadow(a, ui, cli.global.quiet, json),
        Command::Softshadow(a) => terrain::softshadow(a, ui, cli.global.quiet, json),
        Command::Horizon(a) => horizon::horizon(a, ui, cli.global.quiet, json),
        Command::Sunlight(a) => horizon::sunlight_cmd(a, ui, cli.global.quiet, json),
        Command::Theme(a) => theme::run(a, ui, json),
        Command::Generate(a) => terrain::generate_cmd(a, cli.global.quiet, json),
        Command::Load { file, knobs } => {
            let loaded = load_any(
                file,
                SceneOptions { scale: knobs.scale },
                &knobs.heightmap_options(),
            )?;
            match loaded {
                LoadedInput::Scene(scene, warnings) => {
                    for w in &warnings.messages {
                        relume::progress::Progress::warn(ui, w);
                    }
                    let s = summarize_scene(file, &scene, &warnings);
                    if json {
                        print_json(&s);
                    } else {
                        print!("{}", s.to_text());
                    }
                }
                LoadedInput::HeightMap(map, info) => {
                    let s = summarize_heightmap(file, &map, &info);
                    if json {
                        print_json(&s);
                    } else {
                        print!("{}", s.to_text());
                    }
                }
            }
            Ok(exit::OK)
        }
    }
}

/// What a stage run alone on a bake did: JSON, or one line per stage with its measurements.
fn print_stage_report(report: &relume::bake::BakeReport, dir: &Path, json: bool, quiet: bool) {
    if json {
        print_json(report);
    } else if !quiet {
        eprint!("{}", report::stage_lines(report, dir));
    }
}

fn print_json<T: Serialize>(value: &T) {
    println!(
        "{}",
        serde_json::to_string_pretty(value).expect("report serialises")
    );
}

/// Die quietly on a closed pipe (`relume-bake inspect DIR | head`) like other Unix tools,
/// instead of panicking on the failed write.
fn restore_sigpipe() {
    #[cfg(unix)]
    // SAFETY: setting a signal disposition to its default before any threads exist.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
