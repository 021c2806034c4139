//! The sun of the terrain commands: `--sun-azimuth/--sun-elevation`, or `--date` with a place
//! (`--lat/--lon`, else the GeoTIFF's georeference) through NREL's SPA.

use clap::Args;
use relume::terrain::sun::spec::SunSpec;

/// The sun's direction, given or computed.
#[derive(Args, Clone)]
pub struct SunArgs {
    /// Degrees clockwise from north (0 = north = up the image, 90 = east)
    #[arg(
        long,
        value_name = "DEG",
        allow_hyphen_values = true,
        required_unless_present = "date"
    )]
    pub sun_azimuth: Option<f64>,
    /// Degrees above the horizon
    #[arg(
        long,
        value_name = "DEG",
        allow_hyphen_values = true,
        required_unless_present = "date"
    )]
    pub sun_elevation: Option<f64>,
    /// Instead of the angles: when (ISO 8601 with a zone, e.g. 2026-06-21T05:30:00Z); the sun
    /// by NREL's SPA with refraction, turned from true north to the grid's north
    #[arg(long, value_name = "WHEN", conflicts_with_all = ["sun_azimuth", "sun_elevation"])]
    pub date: Option<String>,
    /// Latitude in degrees, north positive (default: the GeoTIFF's centre)
    #[arg(
        long,
        value_name = "DEG",
        allow_hyphen_values = true,
        requires = "date"
    )]
    pub lat: Option<f64>,
    /// Longitude in degrees, east positive (default: the GeoTIFF's centre)
    #[arg(
        long,
        value_name = "DEG",
        allow_hyphen_values = true,
        requires = "date"
    )]
    pub lon: Option<f64>,
}

impl SunArgs {
    /// The sun as given, for `terrain::sun::spec` to check and resolve.
    pub fn spec(&self) -> SunSpec {
        SunSpec {
            azimuth: self.sun_azimuth,
            elevation: self.sun_elevation,
            date: self.date.clone(),
            lat: self.lat,
            lon: self.lon,
        }
    }
}
