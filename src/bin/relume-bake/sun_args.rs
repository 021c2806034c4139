//! The sun of the terrain commands: `--sun-azimuth/--sun-elevation`, or `--date` with a place
//! (`--lat/--lon`, else the GeoTIFF's georeference) through NREL's SPA.

use clap::Args;
use relume::error::Error;
use relume::heightmap::{HeightMap, HeightMapInfo};
use relume::terrain::sun::solar::{solar_position, Instant, Place, SpaOptions};
use relume::terrain::Sun;
use relume::Result;
use serde_json::{json, Value};

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
    /// The given angles, before any loading (None with `--date`).
    pub fn given(&self) -> Result<Option<Sun>> {
        match (self.sun_azimuth, self.sun_elevation) {
            (Some(a), Some(e)) => Sun::new(a, e).map(Some),
            _ => Ok(None),
        }
    }

    /// Check what can be checked before loading the map.
    pub fn check(&self) -> Result<()> {
        self.given()?;
        if let Some(d) = &self.date {
            Instant::parse(d)?;
            if self.lat.is_some() != self.lon.is_some() {
                return Err(Error::knob(
                    "give both --lat and --lon, or neither (the GeoTIFF's centre)",
                ));
            }
            if let (Some(la), Some(lo)) = (self.lat, self.lon) {
                Place::new(la, lo, 0.0)?;
            }
        }
        Ok(())
    }

    /// The sun in the map's grid, and a JSON account of where it came from.
    pub fn resolve(&self, map: &HeightMap, info: &HeightMapInfo) -> Result<(Sun, Value)> {
        if let Some(sun) = self.given()? {
            return Ok((sun, json!({"source": "angles"})));
        }
        let date = self
            .date
            .as_deref()
            .expect("clap requires --date without the angles");
        let at = Instant::parse(date)?;
        let (place, up) = place_of(map, info, self.lat.zip(self.lon), "--date")?;
        let (lat, lon) = (place.latitude_deg, place.longitude_deg);
        let pos = solar_position(&at, &place, &SpaOptions::default())?;
        let sun = Sun::new((pos.azimuth_deg - up).rem_euclid(360.0), pos.elevation_deg)?;
        Ok((
            sun,
            json!({
                "source": "spa", "date": at.to_string(), "latitude": lat, "longitude": lon,
                "true_azimuth": pos.azimuth_deg, "apparent_elevation": pos.elevation_deg,
                "grid_north_bearing": up,
            }),
        ))
    }
}

/// Where a height map lies for the sun: `given` (latitude, longitude), else the centre of its
/// geographic or UTM georeference, at the centre texel's height; and the true bearing of the
/// grid's up there (the meridian convergence on UTM; 0 without a georeference). `what` names
/// the option that needs the place, for the error.
pub fn place_of(
    map: &HeightMap,
    info: &HeightMapInfo,
    given: Option<(f64, f64)>,
    what: &str,
) -> Result<(Place, f64)> {
    let (cx, cy) = (map.width as f64 / 2.0, map.height as f64 / 2.0);
    let geo = info.georef.as_ref();
    let (lat, lon) =
        match given.or_else(|| geo.and_then(|g| g.lat_lon(cx, cy)).map(|[a, b]| (a, b))) {
            Some(p) => p,
            None => {
                return Err(Error::knob(format!(
                "{what} needs a place: give --lat and --lon (this height map has no geographic \
                 or UTM georeference)"
            )))
            }
        };
    let centre = map.heights[(map.height / 2) * map.width + map.width / 2] as f64;
    let up = geo
        .and_then(|g| g.grid_north_bearing(cx, cy))
        .unwrap_or(0.0);
    Ok((Place::new(lat, lon, centre)?, up))
}
