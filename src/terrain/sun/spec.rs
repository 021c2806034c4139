//! The sun of the terrain commands as given: angles, or a date with a place (else the height
//! map's georeference) through NREL's SPA; checked before loading, resolved against the map.

use crate::error::{Error, Result};
use crate::heightmap::{HeightMap, HeightMapInfo};
use crate::terrain::sun::solar::{solar_position, Instant, Place, SpaOptions};
use crate::terrain::sun::Sun;
use serde_json::{json, Value};

/// A sun as the command line gives it: both angles in degrees, or `date` (ISO 8601 with a
/// zone) with an optional place (`lat` and `lon` in degrees, both or neither).
#[derive(Clone, Debug, Default)]
pub struct SunSpec {
    pub azimuth: Option<f64>,
    pub elevation: Option<f64>,
    pub date: Option<String>,
    pub lat: Option<f64>,
    pub lon: Option<f64>,
}

impl SunSpec {
    /// The given angles, checked by [`Sun::new`] (None unless both are given).
    pub fn given(&self) -> Result<Option<Sun>> {
        match (self.azimuth, self.elevation) {
            (Some(a), Some(e)) => Sun::new(a, e).map(Some),
            _ => Ok(None),
        }
    }

    /// Check what can be checked before loading the map: the angles, the date's syntax, both
    /// or neither of `lat`/`lon`, and the place's ranges.
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

    /// The sun in the map's grid, and a JSON account of where it came from (`"angles"`, or
    /// `"spa"` with the date, place, true azimuth and the grid's north bearing). Precondition:
    /// the angles or a date are given.
    pub fn resolve(&self, map: &HeightMap, info: &HeightMapInfo) -> Result<(Sun, Value)> {
        if let Some(sun) = self.given()? {
            return Ok((sun, json!({"source": "angles"})));
        }
        let date = self
            .date
            .as_deref()
            .ok_or_else(|| Error::knob("give the sun's angles or --date"))?;
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
    let (lat, lon) = given
        .or_else(|| geo.and_then(|g| g.lat_lon(cx, cy)).map(|[a, b]| (a, b)))
        .ok_or_else(|| {
            Error::knob(format!(
                "{what} needs a place: give --lat and --lon (this height map has no geographic \
                 or UTM georeference)"
            ))
        })?;
    let centre = map.heights[(map.height / 2) * map.width + map.width / 2] as f64;
    let up = geo
        .and_then(|g| g.grid_north_bearing(cx, cy))
        .unwrap_or(0.0);
    Ok((Place::new(lat, lon, centre)?, up))
}
