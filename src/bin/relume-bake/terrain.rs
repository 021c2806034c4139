//! Terrain subcommands: `shadow` (hard relief shadows), `generate` (synthetic height maps) and
//! `softshadow` (sun-disc soft shadows). Thin: load, call the library, write images atomically.

use crate::sun_args::SunArgs;
use crate::ui::Ui;
use clap::{Args, ValueEnum};
use relume::baked::images::{self, check_extension};
use relume::baked::rasters;
use relume::error::exit;
use relume::heightmap::georef::TiffCompression;
use relume::heightmap::{HeightMap, HeightMapInfo};
use relume::pipeline::knobs;
use relume::progress::Progress;
use relume::terrain::generate::{generate, quantise_u16, Shape};
use relume::terrain::hard::relief::{self, HardMethod};
use relume::terrain::soft::model::SUN_RADIUS_DEG;
use relume::terrain::soft::{lit_summary, soft_shadow_map, SoftMethod, SoftShadowParams};
use relume::terrain::Sun;
use relume::Result;
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

const SUN_HELP: &str = "\
Sun convention: azimuth in degrees clockwise from north, where north is up the image (toward
row 0) and east is toward the last column: 0 = sun in the north, 90 = east, 180 = south,
270 = west. Elevation in degrees above the horizon (0 = on the horizon, 90 = zenith).
Or --date (ISO 8601 with a zone) and a place: --lat/--lon, or the centre of a GeoTIFF with a
geographic or UTM georeference; the sun then comes from NREL's SPA with refraction, its azimuth
turned from true north to the grid's (the meridian convergence on UTM).
Input: a height map (.png .jpg .exr .tif .raw) or a pipeline file (.ron), whose input and
its knobs (cell size, height scale, no-data policy) are used.
A .tif output is a GeoTIFF with the input's georeference; no-data texels of the input are
no-data there (mask: 128; lit fraction: -1) and are left out of the reported fractions.";

/// Where the height map comes from and how to scale it.
#[derive(Args, Clone)]
pub struct MapArgs {
    /// Height map (.png .jpg .exr .tif .raw) or pipeline file (.ron)
    pub input: PathBuf,
    /// Metres per texel (overrides the world file / GeoTIFF tags / pipeline)
    #[arg(long, value_name = "M")]
    pub cell_size: Option<f64>,
    /// Metres per file unit (overrides the pipeline)
    #[arg(long, value_name = "S")]
    pub height_scale: Option<f64>,
}

#[derive(Args)]
#[command(after_help = SUN_HELP)]
pub struct ShadowArgs {
    #[command(flatten)]
    pub map: MapArgs,
    #[command(flatten)]
    pub sun: SunArgs,
    /// Traversal method
    #[arg(long, value_enum, default_value_t = HardMethod::default())]
    pub method: HardMethod,
    /// Shadow mask to write (.png or GeoTIFF .tif: 255 = lit, 0 = shadow, .tif 128 = no-data)
    #[arg(long, value_name = "MASK.png|MASK.tif")]
    pub out: PathBuf,
    /// GeoTIFF compression (none: fastest, largest; deflate-small: smallest, slowest)
    #[arg(long, value_enum, value_name = "HOW", default_value_t = crate::horizon::DEFAULT_COMPRESS)]
    pub compress: TiffCompression,
    #[command(flatten)]
    pub relief: ReliefArgs,
}

/// The optional shaded relief of `shadow` and `softshadow`.
#[derive(Args)]
pub struct ReliefArgs {
    /// Also write a shaded relief (.png, sRGB): Lambert × (k_shadow + (1 − k_shadow)·lit)
    #[arg(long, value_name = "RELIEF.png")]
    pub shaded: Option<PathBuf>,
    /// Shadow brightness with the sun on the horizon
    #[arg(long, default_value_t = knobs::DEFAULT_K_DARK, value_name = "K")]
    pub k_dark: f64,
    /// Shadow brightness with the sun at the zenith
    #[arg(long, default_value_t = knobs::DEFAULT_K_BRIGHT, value_name = "K")]
    pub k_bright: f64,
}

impl ReliefArgs {
    /// Check the knobs before any work.
    fn check(&self) -> Result<()> {
        relief::check_k(self.k_dark, self.k_bright)?;
        match &self.shaded {
            Some(s) => check_extension(s, &["png"]),
            None => Ok(()),
        }
    }

    /// Write the relief when asked for; `shadow` is the shadowed fraction per texel.
    fn write(&self, map: &HeightMap, sun: &Sun, shadow: &[f32]) -> Result<()> {
        match &self.shaded {
            Some(p) => {
                rasters::write_shaded_relief(p, map, sun, shadow, self.k_dark, self.k_bright)
            }
            None => Ok(()),
        }
    }

    fn json(&self) -> Option<String> {
        self.shaded.as_ref().map(|p| p.display().to_string())
    }
}

#[derive(Args)]
pub struct GenerateArgs {
    /// Which map
    #[arg(value_enum)]
    pub shape: Shape,
    /// Width and height in texels (cell size 1 m; feature heights scale with it)
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=32768))]
    pub size: u32,
    /// Output: .exr (f32 metres) or .png (16-bit; prints the height scale to load it with)
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum SoftMethodArg {
    /// Every texel on the track (the reference; slow at low sun)
    Exhaustive,
    /// --steps evenly spaced samples (the soft-shadow paper's baseline)
    Uniform,
    /// The soft-shadow paper's dynamic programming over the mipmap (--start-level, --intervals)
    DynamicProgramming,
    /// The exact answer by branch-and-bound over the mipmap
    BranchAndBound,
}

#[derive(Args)]
#[command(after_help = SUN_HELP)]
pub struct SoftShadowArgs {
    #[command(flatten)]
    pub map: MapArgs,
    #[command(flatten)]
    pub sun: SunArgs,
    /// Angular radius of the sun disc in degrees (the Sun: 0.2666)
    #[arg(long, value_name = "DEG", default_value_t = SUN_RADIUS_DEG)]
    pub sun_radius: f64,
    /// Planet radius in metres for curved terrain (Moon 1737400, Earth 6371000); default flat
    #[arg(long, value_name = "M")]
    pub planet_radius: Option<f64>,
    /// How the most occluding point is found
    #[arg(long, value_enum, default_value_t = SoftMethodArg::BranchAndBound)]
    pub method: SoftMethodArg,
    /// Uniform: number of samples along the track
    #[arg(long, value_name = "N", default_value_t = knobs::DEFAULT_SOFT_STEPS, value_parser = clap::value_parser!(u32).range(1..))]
    pub steps: u32,
    /// Dynamic programming: mipmap level to start from (-1 = texels; clamped to the top)
    #[arg(
        long,
        value_name = "L",
        default_value_t = knobs::DEFAULT_SOFT_START_LEVEL,
        allow_hyphen_values = true
    )]
    pub start_level: i32,
    /// Dynamic programming: intervals along the track (0 = as many as it needs)
    #[arg(long, value_name = "K", default_value_t = knobs::DEFAULT_SOFT_INTERVALS)]
    pub intervals: u32,
    /// Lit fraction to write: .png (16-bit, 65535 = fully lit), .exr (f32) or GeoTIFF .tif (f32)
    #[arg(long, value_name = "LIT.png|LIT.exr|LIT.tif")]
    pub out: PathBuf,
    /// GeoTIFF compression (none: fastest, largest; deflate-small: smallest, slowest)
    #[arg(long, value_enum, value_name = "HOW", default_value_t = crate::horizon::DEFAULT_COMPRESS)]
    pub compress: TiffCompression,
    #[command(flatten)]
    pub relief: ReliefArgs,
}

/// `relume-bake softshadow`.
pub fn softshadow(args: &SoftShadowArgs, ui: &Ui, quiet: bool, json: bool) -> Result<i32> {
    args.sun.spec().check()?;
    check_extension(&args.out, &["png", "exr", "tif", "tiff"])?;
    args.relief.check()?;
    let method = match args.method {
        SoftMethodArg::Exhaustive => SoftMethod::Exhaustive,
        SoftMethodArg::Uniform => SoftMethod::Uniform { steps: args.steps },
        SoftMethodArg::DynamicProgramming => SoftMethod::DynamicProgramming {
            start_level: args.start_level,
            intervals: args.intervals,
        },
        SoftMethodArg::BranchAndBound => SoftMethod::BranchAndBound,
    };
    let params = SoftShadowParams {
        sun_radius_deg: args.sun_radius,
        planet_radius_m: args.planet_radius,
        method,
    };
    params.check()?;
    ui.begin("load", 0);
    let (map, info) = load_map(&args.map)?;
    ui.finish();
    let (sun, sun_json) = args.sun.spec().resolve(&map, &info)?;
    let t0 = Instant::now();
    let lit = soft_shadow_map(&map, &sun, &params, None, ui)?;
    let seconds = t0.elapsed().as_secs_f64();
    rasters::write_lit_fraction(&args.out, &map, &info, &lit, args.compress)?;
    if args.relief.shaded.is_some() {
        let shadow: Vec<f32> = lit.iter().map(|l| 1.0 - l).collect();
        args.relief.write(&map, &sun, &shadow)?;
    }
    let (mean, penumbra) = lit_summary(&lit, &info.nodata_mask);
    let mpix = lit.len() as f64 / seconds.max(1e-9) / 1e6;
    if json {
        print_json(&json!({
            "input": args.map.input.display().to_string(),
            "width": map.width, "height": map.height,
            "cell_size": map.cell_size, "height_scale": map.height_scale,
            "sun_azimuth": sun.azimuth_deg, "sun_elevation": sun.elevation_deg,
            "sun": sun_json, "nodata_texels": info.nodata_count,
            "sun_radius": args.sun_radius, "planet_radius": args.planet_radius,
            "method": method.label(),
            "mean_lit": mean, "penumbra_fraction": penumbra,
            "seconds": seconds, "mpixels_per_second": mpix,
            "out": args.out.display().to_string(),
            "shaded": args.relief.json(),
        }));
    } else if !quiet {
        eprintln!(
            "{}x{} ({}): mean lit {:.3}, {:.1} % in penumbra, {:.3} s ({:.1} Mpixel/s) → {}",
            map.width,
            map.height,
            method.label(),
            mean,
            100.0 * penumbra,
            seconds,
            mpix,
            args.out.display()
        );
    }
    Ok(exit::OK)
}

/// Load the input of a terrain command: a height map, or a pipeline's height-map input.
pub fn load_map(args: &MapArgs) -> Result<(HeightMap, HeightMapInfo)> {
    relume::load::heightmap_input_with_info(&args.input, args.cell_size, args.height_scale)
}

pub fn print_json(v: &serde_json::Value) {
    println!("{}", serde_json::to_string_pretty(v).expect("json"));
}

/// `relume-bake shadow`.
pub fn shadow(args: &ShadowArgs, ui: &Ui, quiet: bool, json: bool) -> Result<i32> {
    args.sun.spec().check()?;
    check_extension(&args.out, &["png", "tif", "tiff"])?;
    args.relief.check()?;
    ui.begin("load", 0);
    let (map, info) = load_map(&args.map)?;
    ui.finish();
    let (sun, sun_json) = args.sun.spec().resolve(&map, &info)?;
    let method = args.method;
    let t0 = Instant::now();
    let mask = relief::shadow_mask(&map, &sun, method, None, ui);
    let seconds = t0.elapsed().as_secs_f64();
    rasters::write_shadow_mask(&args.out, &map, &info, &mask, args.compress)?;
    if args.relief.shaded.is_some() {
        let shadow: Vec<f32> = mask.iter().map(|&s| s as u8 as f32).collect();
        args.relief.write(&map, &sun, &shadow)?;
    }
    let fraction = relief::shadowed_fraction(&mask, &info.nodata_mask);
    let mpix = mask.len() as f64 / seconds.max(1e-9) / 1e6;
    if json {
        print_json(&json!({
            "input": args.map.input.display().to_string(),
            "width": map.width, "height": map.height,
            "cell_size": map.cell_size, "height_scale": map.height_scale,
            "sun_azimuth": sun.azimuth_deg, "sun_elevation": sun.elevation_deg,
            "sun": sun_json, "nodata_texels": info.nodata_count,
            "method": method.label(),
            "shadowed_fraction": fraction,
            "seconds": seconds, "mpixels_per_second": mpix,
            "out": args.out.display().to_string(),
            "shaded": args.relief.json(),
        }));
    } else if !quiet {
        eprintln!(
            "{}x{}: {:.1} % in shadow, {:.3} s ({:.1} Mpixel/s) → {}",
            map.width,
            map.height,
            100.0 * fraction,
            seconds,
            mpix,
            args.out.display()
        );
    }
    Ok(exit::OK)
}

/// `relume-bake generate`.
pub fn generate_cmd(args: &GenerateArgs, quiet: bool, json: bool) -> Result<i32> {
    check_extension(&args.out, &["png", "exr"])?;
    let shape = args.shape;
    let n = args.size as usize;
    relume::limits::check_memory(
        "this height map",
        (n * n * 8) as u64,
        relume::limits::default_max_memory(),
    )?;
    let map = generate(shape, n);
    let (lo, hi) = map.min_max();
    let (scale, offset) = if images::is_exr(&args.out) {
        images::write_exr_gray(&args.out, n, n, &map.heights)?;
        (1.0, 0.0)
    } else {
        let (values, scale, offset) = quantise_u16(&map);
        images::write_png_gray16(&args.out, n, n, values)?;
        (scale, offset)
    };
    if json {
        print_json(&json!({
            "shape": shape.name(), "size": n, "out": args.out.display().to_string(),
            "min_height": lo, "max_height": hi, "cell_size": 1.0,
            "height_scale": scale, "height_offset": offset,
        }));
    } else if !quiet {
        eprintln!(
            "{} {n}x{n} (cell 1 m, heights {lo} .. {hi} m) → {}{}",
            shape.name(),
            args.out.display(),
            if images::is_exr(&args.out) {
                String::new()
            } else {
                format!(" (16-bit: load with --height-scale {scale}; offset {offset} m dropped)")
            }
        );
    }
    Ok(exit::OK)
}
