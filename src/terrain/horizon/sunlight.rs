//! Sunlight over a day (docs/algorithms.md §4.4): hours of direct sun per texel, and optionally
//! the clear-sky direct-beam energy on the sloped surface (Wh/m²), from a horizon map — each
//! time step is an O(1)-per-texel horizon test, so a day at 10-minute steps costs little more
//! than the horizon map itself.
//!
//! **The day.** Local mean solar time: from midnight at the place's longitude
//! (00:00 UTC − longitude/15 h) for 24 hours, sampled at the midpoints of `step`-long intervals;
//! each interval whose sun is above the horizon and above the texel's horizon counts `step`.
//! The sun of each step comes from [`crate::terrain::sun::solar`] (NREL's SPA with refraction), turned by the
//! grid's north bearing.
//!
//! **Insolation** (optional). Direct normal irradiance of a clear sky by Meinel & Meinel's
//! (1976) air-mass model, DNI = 1361 W/m² · 0.7^(AM^0.678), with Kasten & Young's (1989) air
//! mass; on the surface DNI · max(0, n·s), n from central differences of the heights. Diffuse
//! and reflected light are not modelled (GRASS r.sun and Whitebox add them).

use crate::error::{Error, Result};
use crate::heightmap::HeightMap;
use crate::terrain::horizon::map::{horizon_at, HorizonMap};
use crate::terrain::sun::solar::{solar_position, Instant, Place, SpaOptions};
use crate::terrain::sun::Sun;
use rayon::prelude::*;

/// One time step of the day: the sun in the grid and the step's length in hours.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    pub at: Instant,
    pub sun: Sun,
    pub hours: f64,
}

/// The steps of the local mean solar day of `date` at `place`, `step_s` seconds apart (at most
/// a day), the azimuths turned by `grid_north_bearing` degrees.
pub fn day_steps(
    date: &Instant,
    place: &Place,
    step_s: f64,
    grid_north_bearing: f64,
) -> Result<Vec<Step>> {
    if !(1.0..=86_400.0).contains(&step_s) {
        return Err(Error::knob(format!(
            "the time step must be between 1 s and 24 h, got {step_s} s"
        )));
    }
    let midnight = date
        .start_of_day()
        .plus_seconds(-place.longitude_deg / 15.0 * 3600.0);
    let n = (86_400.0 / step_s).round().max(1.0) as usize;
    let dt = 86_400.0 / n as f64;
    (0..n)
        .map(|i| {
            let at = midnight.plus_seconds((i as f64 + 0.5) * dt);
            let pos = solar_position(&at, place, &SpaOptions::default())?;
            let az = (pos.azimuth_deg - grid_north_bearing).rem_euclid(360.0);
            Ok(Step {
                at,
                sun: Sun::new(az, pos.elevation_deg)?,
                hours: dt / 3600.0,
            })
        })
        .collect()
}

/// Clear-sky direct normal irradiance (W/m²) for a sun at `elevation_deg` (Meinel & Meinel
/// with Kasten & Young's air mass); 0 below the horizon.
pub fn clear_sky_dni(elevation_deg: f64) -> f64 {
    if elevation_deg <= 0.0 {
        return 0.0;
    }
    let zenith = 90.0 - elevation_deg;
    let am = 1.0 / (zenith.to_radians().cos() + 0.50572 * (96.07995 - zenith).powf(-1.6364));
    1361.0 * 0.7f64.powf(am.powf(0.678))
}

/// Hours of direct sun per texel, and the direct-beam energy on the surface (Wh/m²) when
/// `insolation` is set: each step above the horizon is [`HorizonMap::shadow_mask`]'s test,
/// evaluated for a block of texels at a time over all steps (the planes of a block stay in
/// cache), summed in f64.
pub fn sunlight(
    map: &HeightMap,
    horizons: &HorizonMap,
    steps: &[Step],
    insolation: bool,
) -> (Vec<f32>, Option<Vec<f32>>) {
    /// A step with the sun up: its bracket in the map and its beam (DNI · hours · direction).
    struct Lit {
        k0: usize,
        k1: usize,
        w: f64,
        elevation: f64,
        hours: f64,
        beam: [f64; 3],
    }
    let lit: Vec<Lit> = steps
        .iter()
        .filter(|s| s.sun.elevation_deg > 0.0)
        .map(|s| {
            let (k0, k1, w) = horizons.bracket(s.sun.azimuth_deg);
            let d = s.sun.direction();
            let e = clear_sky_dni(s.sun.elevation_deg) * s.hours;
            Lit {
                k0,
                k1,
                w,
                elevation: s.sun.elevation_deg,
                hours: s.hours,
                beam: [d[0] * e, d[1] * e, d[2] * e],
            }
        })
        .collect();
    const BLOCK: usize = 4096;
    let n = map.width * map.height;
    let normals = insolation.then(|| normals(map));
    let blocks: Vec<(Vec<f32>, Vec<f32>)> = (0..n.div_ceil(BLOCK))
        .into_par_iter()
        .map(|b| {
            let range = b * BLOCK..((b + 1) * BLOCK).min(n);
            let len = range.len();
            let (mut hours, mut energy) = (vec![0.0f64; len], vec![0.0f64; len]);
            for s in &lit {
                let p0 = &horizons.angles[s.k0][range.clone()];
                let p1 = &horizons.angles[s.k1][range.clone()];
                for i in 0..len {
                    if s.elevation >= horizon_at(p0[i], p1[i], s.w) {
                        hours[i] += s.hours;
                        if let Some(nm) = &normals {
                            let v = nm[range.start + i];
                            let c = v[0] * s.beam[0] + v[1] * s.beam[1] + v[2] * s.beam[2];
                            energy[i] += c.max(0.0);
                        }
                    }
                }
            }
            let f = |v: Vec<f64>| v.into_iter().map(|x| x as f32).collect();
            (f(hours), f(energy))
        })
        .collect();
    let hours = blocks.iter().flat_map(|b| b.0.iter().copied()).collect();
    let energy = insolation.then(|| blocks.iter().flat_map(|b| b.1.iter().copied()).collect());
    (hours, energy)
}

/// Unit surface normals (x east, y north, z up) from central differences (one-sided at the
/// border).
pub fn normals(map: &HeightMap) -> Vec<[f64; 3]> {
    let (w, h) = (map.width, map.height);
    let [cx, cy] = map.cell_size;
    (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let (l, r) = (x.saturating_sub(1), (x + 1).min(w - 1));
            let (n, s) = (y.saturating_sub(1), (y + 1).min(h - 1));
            let dzdx = if r > l {
                (map.at(r, y) - map.at(l, y)) as f64 / ((r - l) as f64 * cx)
            } else {
                0.0
            };
            // Rows go south: north is row − 1.
            let dzdy = if s > n {
                (map.at(x, n) - map.at(x, s)) as f64 / ((s - n) as f64 * cy)
            } else {
                0.0
            };
            let len = (dzdx * dzdx + dzdy * dzdy + 1.0).sqrt();
            [-dzdx / len, -dzdy / len, 1.0 / len]
        })
        .collect()
}

/// Seconds from a duration as `--step` spells it: `30`, `30s`, `10m` (or `min`), `1h`; refuses
/// unknown units and anything not a positive finite number.
pub fn parse_step(text: &str) -> Result<f64> {
    let t = text.trim();
    let (num, unit) = match t.char_indices().find(|(_, c)| c.is_ascii_alphabetic()) {
        Some((i, _)) => (&t[..i], &t[i..]),
        None => (t, "s"),
    };
    let k = match unit {
        "s" => 1.0,
        "m" | "min" => 60.0,
        "h" => 3600.0,
        _ => {
            return Err(Error::knob(format!(
                "--step `{text}`: unknown unit `{unit}` (use s, m or h, e.g. 10m)"
            )))
        }
    };
    match num.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v * k),
        _ => Err(Error::knob(format!(
            "--step `{text}`: not a positive duration (e.g. 10m)"
        ))),
    }
}

/// The instant a day is given by: a bare date (`2026-06-21`, taken at 00:00 UTC) or any instant
/// of it with a zone (ISO 8601).
pub fn parse_day(text: &str) -> Result<Instant> {
    if text.len() == 10 {
        Instant::parse(&format!("{text}T00:00:00Z"))
    } else {
        Instant::parse(text)
    }
}

/// Hours of the day with the sun above the horizon: the lengths of the steps whose sun is up.
pub fn daylight_hours(steps: &[Step]) -> f64 {
    steps
        .iter()
        .filter(|s| s.sun.elevation_deg > 0.0)
        .map(|s| s.hours)
        .sum()
}

/// The mean of `hours` over the texels `nodata` (one flag per texel, or empty for none) does
/// not mark; 0 when none is valid.
pub fn mean_hours(hours: &[f32], nodata: &[bool]) -> f64 {
    let valid: Vec<f64> = (0..hours.len())
        .filter(|&i| !nodata.get(i).copied().unwrap_or(false))
        .map(|i| hours[i] as f64)
        .collect();
    valid.iter().sum::<f64>() / valid.len().max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clear_sky_dni_is_about_a_kilowatt_at_the_zenith_and_falls_toward_the_horizon() {
        // Meinel: 1361 · 0.7^1 = 952.7 W/m² at air mass 1.
        assert!((clear_sky_dni(90.0) - 952.7).abs() < 1.0);
        assert!(clear_sky_dni(10.0) < clear_sky_dni(30.0));
        assert_eq!(clear_sky_dni(-1.0), 0.0);
    }
}
