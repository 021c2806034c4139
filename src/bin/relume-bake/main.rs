//! `relume-bake`: the offline toolchain. Thin: parse arguments into a validated plan, call the
//! library, show progress, print errors with their cause chain, exit with a code per cause.

mod compress;
mod radiosity;
mod study;
mod terrain;
mod ui;

use clap::{Args, Parser, Subcommand};
use relume::error::exit;
use relume::heightmap::{HeightMapOptions, NoDataPolicy};
use relume::load::{load_any, summarize_heightmap, summarize_scene, LoadedInput};
use relume::scene::SceneOptions;
use relume::{Error, Result};
use serde::Serialize;
use std::path::{Path, PathBuf};
use ui::Ui;

const EXIT_CODES: &str = "\
Exit codes:
  0  success
  1  internal error (a bug in relume: please report it)
  2  usage error (bad command line)
  3  invalid input (malformed file, NaN height, out-of-range knob)
  4  I/O error (cannot read or write a file)
  5  over a resource limit (e.g. --max-memory)
  6  unsupported (valid input that this version cannot handle)
  7  verification failed (inspect: a missing, truncated or altered file)";

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
        #[arg(long, value_name = "SIZE", value_parser = parse_size)]
        max_memory: Option<u64>,
    },
    /// Show the stages a pipeline would run, with estimated peak memory and output size; writes nothing
    Plan {
        /// Pipeline file (RON)
        pipeline: PathBuf,
        /// Output directory to report (default as for `run`)
        #[arg(short, long, value_name = "DIR")]
        out: Option<PathBuf>,
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
    /// Soft shadows of the sun's disc (penumbrae, curved planets): lit fraction and shaded relief
    #[command(after_help = EXIT_CODES)]
    Softshadow(terrain::SoftShadowArgs),
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
    /// Height map: what to do with no-data texels
    #[arg(long, value_enum, default_value_t = NoDataArg::Error)]
    nodata: NoDataArg,
    /// Height map: extra value (in file units) that marks missing data
    #[arg(long, value_name = "V")]
    nodata_value: Option<f64>,
    /// Height map: box-filter down by this integer factor after loading (cell size grows)
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=4096))]
    downsample: u32,
    /// Height map: size of a raw little-endian f32 file, WIDTHxHEIGHT
    #[arg(long, value_name = "WxH", value_parser = parse_wxh)]
    raw_size: Option<(usize, usize)>,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum NoDataArg {
    Error,
    FillMin,
    FillNearest,
}

impl LoadKnobs {
    fn heightmap_options(&self) -> HeightMapOptions {
        HeightMapOptions {
            cell_size: self.cell_size.map(|c| [c, c]),
            height_scale: self.height_scale,
            nodata_value: self.nodata_value,
            nodata: match self.nodata {
                NoDataArg::Error => NoDataPolicy::Error,
                NoDataArg::FillMin => NoDataPolicy::FillMin,
                NoDataArg::FillNearest => NoDataPolicy::FillNearest,
            },
            raw_size: self.raw_size.map(|(w, h)| [w, h]),
            downsample: self.downsample,
        }
    }
}

fn parse_size(s: &str) -> std::result::Result<u64, String> {
    relume::limits::parse_bytes(s)
}

fn parse_wxh(s: &str) -> std::result::Result<(usize, usize), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{s}` is not WIDTHxHEIGHT (e.g. 1024x512)"))?;
    let w: usize = w.parse().map_err(|_| format!("`{w}` is not a width"))?;
    let h: usize = h.parse().map_err(|_| format!("`{h}` is not a height"))?;
    if w == 0 || h == 0 {
        return Err("width and height must be at least 1".into());
    }
    Ok((w, h))
}

fn main() {
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
        } => {
            let p = relume::pipeline::parse_pipeline(pipeline)?;
            let out = output_dir(pipeline, &p, out.as_deref());
            let mut opts = relume::bake::BakeOptions::default();
            if let Some(m) = max_memory {
                opts.max_memory = *m;
            }
            let report = relume::bake::run_pipeline(&p, &out, &opts, ui)?;
            if json {
                print_json(&report);
            } else if !cli.global.quiet {
                let bytes: u64 = report.files.iter().map(|f| f.bytes).sum();
                eprintln!(
                    "baked {} ({} files, {})",
                    out.display(),
                    report.files.len() + 1,
                    relume::limits::human_bytes(bytes)
                );
            }
            Ok(exit::OK)
        }
        Command::Plan { pipeline, out } => {
            let p = relume::pipeline::parse_pipeline(pipeline)?;
            let out = output_dir(pipeline, &p, out.as_deref());
            let input = relume::load::load_input(&p.input)?;
            let plan = relume::pipeline::plan(&p, &input, &out);
            if json {
                print_json(&plan);
            } else {
                println!(
                    "pipeline {}: {} input {}",
                    pipeline.display(),
                    plan.input_kind,
                    plan.input
                );
                println!("output   {}", plan.output.display());
                println!(
                    "{:<16} {:>12} {:>12}  notes",
                    "stage", "peak memory", "writes"
                );
                for s in &plan.stages {
                    println!(
                        "{:<16} {:>12} {:>12}  {}",
                        s.stage,
                        relume::limits::human_bytes(s.peak_bytes),
                        relume::limits::human_bytes(s.output_bytes),
                        s.notes
                    );
                }
                println!(
                    "total: peak {} (budget {}), writes {}",
                    relume::limits::human_bytes(plan.peak_bytes),
                    relume::limits::human_bytes(relume::limits::default_max_memory()),
                    relume::limits::human_bytes(plan.output_bytes)
                );
            }
            Ok(exit::OK)
        }
        Command::Inspect { baked_dir } => inspect(baked_dir, json),
        Command::Radiosity(c) => radiosity::run(c, json, cli.global.quiet, ui),
        Command::Compress(c) => compress::run(c, ui, json, cli.global.quiet),
        Command::Study(a) => study::run(a, ui, json, cli.global.quiet),
        Command::Shadow(a) => terrain::shadow(a, ui, cli.global.quiet, json),
        Command::Softshadow(a) => terrain::softshadow(a, ui, cli.global.quiet, json),
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
                        println!("scene      {}", s.path);
                        println!(
                            "triangles  {} ({} degenerate), vertices {}",
                            s.triangles, s.degenerate_triangles, s.vertices
                        );
                        println!("objects    {}", s.objects.join(", "));
                        println!("materials  {}", s.materials.len());
                        for m in &s.materials {
                            println!(
                                "  {:<16} albedo {:?}  emission {:?}",
                                m.name, m.albedo, m.emission
                            );
                        }
                        println!("lights     {}", s.lights.len());
                        for l in &s.lights {
                            println!(
                                "  {:<16} {:?} intensity {} colour {:?}",
                                l.name, l.kind, l.intensity, l.color
                            );
                        }
                        println!("bounds     {:?} .. {:?}", s.bounds_min, s.bounds_max);
                        println!("area       {:.6}", s.total_area);
                        println!("grey       {}", s.grey);
                    }
                }
                LoadedInput::HeightMap(map, info) => {
                    let s = summarize_heightmap(file, &map, &info);
                    if json {
                        print_json(&s);
                    } else {
                        println!("height map {} ({} {})", s.path, s.format, s.sample);
                        println!("size       {} x {}", s.width, s.height);
                        println!(
                            "cell size  {} x {} m ({})",
                            s.cell_size[0], s.cell_size[1], s.cell_size_source
                        );
                        println!(
                            "heights    {} .. {} m (height scale {})",
                            s.min, s.max, s.height_scale
                        );
                        println!("no-data    {}", s.nodata_count);
                    }
                }
            }
            Ok(exit::OK)
        }
    }
}

/// `--out`, else the pipeline's `output`, else `out/<pipeline file stem>`.
fn output_dir(pipeline_path: &Path, p: &relume::pipeline::Pipeline, out: Option<&Path>) -> PathBuf {
    if let Some(o) = out {
        return o.to_path_buf();
    }
    if let Some(o) = &p.output {
        return o.clone();
    }
    let stem = pipeline_path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "bake".into());
    PathBuf::from("out").join(stem)
}

#[derive(Serialize)]
struct InspectReport<'a> {
    dir: String,
    ok: bool,
    manifest: &'a relume::baked::Manifest,
    problems: Vec<relume::baked::VerifyProblem>,
}

fn inspect(dir: &Path, json: bool) -> Result<i32> {
    let manifest = relume::baked::Manifest::read(dir)?;
    let problems = relume::baked::verify(dir, &manifest);
    let ok = problems.is_empty();
    if json {
        print_json(&InspectReport {
            dir: dir.display().to_string(),
            ok,
            manifest: &manifest,
            problems: problems.clone(),
        });
    } else {
        println!("baked dir  {}", dir.display());
        println!(
            "format     v{} (relume {})",
            manifest.format_version, manifest.relume_version
        );
        println!(
            "input      {} ({} bytes, sha256 {})",
            manifest.input.name,
            manifest.input.bytes,
            &manifest.input.sha256[..16]
        );
        for s in &manifest.stages {
            println!("stage      {}  → {}", s.stage, s.outputs.join(", "));
            for (k, v) in &s.report {
                println!("  {k:<28} {v}");
            }
            for (k, v) in &s.facts {
                println!("  {k:<28} {v}");
            }
        }
        for f in &manifest.files {
            let status = problems
                .iter()
                .find(|p| p.file == f.name)
                .map(|p| p.problem.as_str())
                .unwrap_or("ok");
            println!(
                "file       {:<28} {:>12} bytes  {}",
                f.name, f.bytes, status
            );
        }
    }
    if ok {
        Ok(exit::OK)
    } else {
        let first = &problems[0];
        Err(Error::verify(
            dir.join(&first.file),
            format!(
                "{} ({} problem(s) in this bake)",
                first.problem,
                problems.len()
            ),
        ))
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
