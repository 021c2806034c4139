//! `horizon` (horizon maps and the sky-view factor) and `sunlight` (hours of direct sun over a
//! day). Thin: load, call the library, write images atomically.

use crate::terrain::{load_map, print_json, MapArgs};
use crate::ui::Ui;
use clap::Args;
use relume::baked::images::check_extension;
use relume::baked::rasters;
use relume::error::{exit, Error};
use relume::heightmap::georef::TiffCompression;
use relume::pipeline::checks::arg;
use relume::pipeline::knobs::{HorizonMapsKnobs, DEFAULT_HORIZON_DIRECTIONS};
use relume::progress::Progress;
use relume::terrain::horizon::map::{HorizonMap, HorizonSettings};
use relume::terrain::horizon::sunlight::{
    day_steps, daylight_hours, mean_hours, parse_day, parse_step, sunlight,
};
use relume::terrain::sun::spec::place_of;
use relume::Result;
use serde_json::json;
use std::path::PathBuf;

/// The horizon map's settings from the flags (checked by their parsers), else the stage's
/// defaults.
fn horizon_settings(directions: Option<u32>, planet_radius: Option<f64>) -> HorizonSettings {
    HorizonMapsKnobs {
        directions: directions.unwrap_or(DEFAULT_HORIZON_DIRECTIONS),
        planet_radius,
    }
    .settings()
}

/// The GeoTIFF compression of the terrain commands' outputs: deflate at zlib's fast level, 1.3x
/// the wall time of writing nothing on 64 horizon planes (measurements:
/// `relume::heightmap::georef::TiffCompression`).
pub const DEFAULT_COMPRESS: TiffCompression = TiffCompression::Deflate;

#[derive(Args)]
pub struct HorizonArgs {
    #[command(flatten)]
    pub map: MapArgs,
    /// Number of azimuths, 1..=360 (near-uniform rational directions; their exact azimuths are reported) [default: 64]
    #[arg(long, value_name = "N", value_parser = arg::horizon_directions)]
    pub directions: Option<u32>,
    /// Planet radius in metres for curved ground (Earth: 6371000; default: flat)
    #[arg(long, value_name = "M", value_parser = arg::positive_f64)]
    pub planet_radius: Option<f64>,
    /// Sky-view factor to write (.tif GeoTIFF f32, or .exr)
    #[arg(long, value_name = "SVF.tif")]
    pub sky_view: Option<PathBuf>,
    /// Directory for one horizon-angle GeoTIFF per azimuth (degrees, f32): horizon_AAA.AAA.tif
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// One GeoTIFF with a band per azimuth (degrees, f32; band descriptions name the azimuths),
    /// which GDAL and rasterio read as a stack
    #[arg(long, value_name = "STACK.tif")]
    pub stack: Option<PathBuf>,
    /// GeoTIFF compression (none: fastest, largest; deflate-small: smallest, slowest)
    #[arg(long, value_enum, value_name = "HOW", default_value_t = DEFAULT_COMPRESS)]
    pub compress: TiffCompression,
}

#[derive(Args)]
pub struct SunlightArgs {
    #[command(flatten)]
    pub map: MapArgs,
    /// The day (a date, 2026-06-21, or any instant of it with a zone); the local mean solar day
    #[arg(long, value_name = "DATE")]
    pub date: String,
    /// Time step: seconds, or with a unit (30s, 10m, 1h)
    #[arg(long, value_name = "STEP", default_value = "10m")]
    pub step: String,
    /// Latitude in degrees (default: the GeoTIFF's centre)
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    pub lat: Option<f64>,
    /// Longitude in degrees (default: the GeoTIFF's centre)
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    pub lon: Option<f64>,
    /// Horizon azimuths used for the shadows, 1..=360 [default: 64]
    #[arg(long, value_name = "N", value_parser = arg::horizon_directions)]
    pub directions: Option<u32>,
    /// Planet radius in metres for curved ground (Earth: 6371000; default: flat)
    #[arg(long, value_name = "M", value_parser = arg::positive_f64)]
    pub planet_radius: Option<f64>,
    /// Hours of direct sun to write (.tif GeoTIFF f32, or .exr)
    #[arg(long, value_name = "HOURS.tif")]
    pub out: PathBuf,
    /// Also the clear-sky direct-beam energy on the sloped surface, Wh/m² (.tif or .exr)
    #[arg(long, value_name = "WH.tif")]
    pub insolation: Option<PathBuf>,
    /// GeoTIFF compression (none: fastest, largest; deflate-small: smallest, slowest)
    #[arg(long, value_enum, value_name = "HOW", default_value_t = DEFAULT_COMPRESS)]
    pub compress: TiffCompression,
}

/// `relume-bake horizon`.
pub fn horizon(args: &HorizonArgs, ui: &Ui, quiet: bool, json: bool) -> Result<i32> {
    if let Some(p) = &args.sky_view {
        check_extension(p, &["tif", "tiff", "exr"])?;
    }
    if let Some(p) = &args.stack {
        check_extension(p, &["tif", "tiff"])?;
    }
    if args.sky_view.is_none() && args.out.is_none() && args.stack.is_none() {
        return Err(Error::knob(
            "nothing to write: give --sky-view SVF.tif, --out DIR and/or --stack STACK.tif",
        ));
    }
    let settings = horizon_settings(args.directions, args.planet_radius);
    ui.begin("load", 0);
    let (map, info) = load_map(&args.map)?;
    ui.finish();
    ui.begin("horizon", 0);
    let t0 = std::time::Instant::now();
    let hm = HorizonMap::build(&map, &settings);
    let seconds = t0.elapsed().as_secs_f64();
    ui.finish();
    if let Some(p) = &args.sky_view {
        rasters::write_float_raster(p, &map, &info, &hm.sky_view(), args.compress)?;
    }
    if let Some(dir) = &args.out {
        rasters::write_horizon_planes(dir, &map, &info, &hm, args.compress)?;
    }
    if let Some(p) = &args.stack {
        rasters::write_horizon_stack(p, &map, &info, &hm, args.compress)?;
    }
    if json {
        print_json(&json!({
                "input": args.map.input.display().to_string(),
                "width": map.width, "height": map.height,
                "directions": hm.directions, "planet_radius": hm.planet_radius,
                "seconds": seconds,
                "sky_view": args.sky_view.as_ref().map(|p| p.display().to_string()),
                "out": args.out.as_ref().map(|p| p.display().to_string()),
        }));
    } else if !quiet {
        eprintln!(
            "{}x{}: {} horizon directions in {seconds:.2} s",
            map.width,
            map.height,
            hm.directions.len()
        );
    }
    Ok(exit::OK)
}

/// `relume-bake sunlight`.
pub fn sunlight_cmd(args: &SunlightArgs, ui: &Ui, quiet: bool, json: bool) -> Result<i32> {
    check_extension(&args.out, &["tif", "tiff", "exr"])?;
    if let Some(p) = &args.insolation {
        check_extension(p, &["tif", "tiff", "exr"])?;
    }
    let step = parse_step(&args.step)?;
    let settings = horizon_settings(args.directions, args.planet_radius);
    let date = parse_day(&args.date)?;
    if args.lat.is_some() != args.lon.is_some() {
        return Err(Error::knob(
            "give both --lat and --lon, or neither (the GeoTIFF's centre)",
        ));
    }
    ui.begin("load", 0);
    let (map, info) = load_map(&args.map)?;
    ui.finish();
    let (place, up) = place_of(&map, &info, args.lat.zip(args.lon), "sunlight")?;
    let (lat, lon) = (place.latitude_deg, place.longitude_deg);
    let steps = day_steps(&date, &place, step, up)?;
    let t0 = std::time::Instant::now();
    ui.begin("horizon", 0);
    let hm = HorizonMap::build(&map, &settings);
    ui.finish();
    let horizon_s = t0.elapsed().as_secs_f64();
    let t1 = std::time::Instant::now();
    ui.begin("sunlight", 0);
    let (hours, energy) = sunlight(&map, &hm, &steps, args.insolation.is_some());
    ui.finish();
    let day_s = t1.elapsed().as_secs_f64();
    rasters::write_float_raster(&args.out, &map, &info, &hours, args.compress)?;
    if let (Some(p), Some(e)) = (&args.insolation, &energy) {
        rasters::write_float_raster(p, &map, &info, e, args.compress)?;
    }
    let daylight = daylight_hours(&steps);
    let mean = mean_hours(&hours, &info.nodata_mask);
    if json {
        print_json(&json!({
                "input": args.map.input.display().to_string(),
                "width": map.width, "height": map.height,
                "latitude": lat, "longitude": lon, "grid_north_bearing": up,
                "steps": steps.len(), "step_seconds": 86_400.0 / steps.len() as f64,
                "day_start_utc": steps.first().map(|s| s.at.to_string()),
                "daylight_hours": daylight, "mean_sun_hours": mean,
                "horizon_seconds": horizon_s, "sunlight_seconds": day_s,
                "directions": hm.directions.len(),
                "out": args.out.display().to_string(),
                "insolation": args.insolation.as_ref().map(|p| p.display().to_string()),
        }));
    } else if !quiet {
        eprintln!(
            "{}x{}: {:.2} h of daylight, {mean:.2} h of direct sun on average; horizons {horizon_s:.2} s, day {day_s:.2} s → {}",
            map.width,
            map.height,
            daylight,
            args.out.display()
        );
    }
    Ok(exit::OK)
}
