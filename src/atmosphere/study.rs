//! Error against sun elevation: every model against the reference (quadrature single
//! scattering + Monte Carlo orders ≥ 2) on terrain-like view segments and sky directions.

use super::fog::FogParams;
use super::lut::Luts;
use super::monte_carlo::{self, McOptions};
use super::reference::{self, ViewRay};
use super::twin::AtmosphereGpu;
use super::{direction, Atmosphere};
use glam::DVec3;
use serde::Serialize;

/// The views of one study: the eye, the terrain segments and the sky directions.
#[derive(Clone, Debug, PartialEq)]
pub struct Views {
    /// Eye altitude (m).
    pub eye_altitude: f64,
    /// Aerial perspective: (view elevation °, azimuth from the sun °, length m).
    pub segments: Vec<(f64, f64, f64)>,
    /// Sky: (view elevation °, azimuth from the sun °).
    pub sky: Vec<(f64, f64)>,
    /// Range of the aerial-perspective volume (m).
    pub aerial_range: f64,
    pub mc: McOptions,
}

impl Default for Views {
    /// Eye at 1.5 km; segments looking level and 5° down, toward, across and away from the
    /// sun, 1, 10 and 100 km long (cut at the ground); sky 5°, 20° and 60° up in the same
    /// azimuths.
    fn default() -> Self {
        let mut segments = Vec::new();
        for el in [0.0, -5.0] {
            for az in [0.0, 90.0, 180.0] {
                for s in [1_000.0, 10_000.0, 100_000.0] {
                    segments.push((el, az, s));
                }
            }
        }
        let mut sky = Vec::new();
        for el in [5.0, 20.0, 60.0] {
            for az in [0.0, 90.0, 180.0] {
                sky.push((el, az));
            }
        }
        Views {
            eye_altitude: 1_500.0,
            segments,
            sky,
            aerial_range: 128_000.0,
            mc: McOptions {
                paths: 2_000,
                ..McOptions::default()
            },
        }
    }
}

/// One sun elevation: the largest relative error of the in-scattered radiance (over RGB and
/// the views) of each model against the reference.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Row {
    pub sun_elevation_deg: f64,
    /// Hillaire: the aerial-perspective volume, on the segments.
    pub hillaire_aerial: f64,
    /// Hillaire's raymarch per segment (tables for T and Ψ_ms only), on the segments.
    pub hillaire_march: f64,
    /// Hillaire: the sky-view table, on the sky directions.
    pub hillaire_sky: f64,
    /// The constant-density fog of Vyatkin et al. 2018 (E_sun unattenuated), on the segments.
    pub fog: f64,
    /// The same with E_sun attenuated by the air between the eye and the sun.
    pub fog_attenuated_sun: f64,
    /// The constant-density fog against the reference's single scattering only (what the fog
    /// models: the error of its constant density and unattenuated sun alone).
    pub fog_vs_single: f64,
    /// The attenuated-sun variant against single scattering only.
    pub fog_attenuated_vs_single: f64,
    /// Single scattering alone (the reference without orders ≥ 2), on the segments.
    pub single_only: f64,
    /// Largest |transmittance error| of the fog model on the segments (absolute).
    pub fog_transmittance: f64,
    /// Largest relative standard error of the reference's Monte Carlo part (of the total).
    pub reference_rel_se: f64,
}

fn rel(model: [f64; 3], reference: [f64; 3]) -> f64 {
    (0..3)
        .map(|c| (model[c] - reference[c]).abs() / reference[c].abs().max(1e-30))
        .fold(0.0, f64::max)
}

fn f32x3(v: glam::Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

/// The reference in-scattering of a view ray: (value, largest relative standard error).
pub fn reference_inscatter(atm: &Atmosphere, ray: &ViewRay, mc: &McOptions) -> ([f64; 3], f64) {
    let ss = reference::single_scattering(atm, ray);
    let ms = monte_carlo::trace(atm, ray, mc);
    let total: [f64; 3] = std::array::from_fn(|c| ss.inscatter[c] + ms.multiple[c]);
    let se = (0..3)
        .map(|c| ms.multiple_se[c] / total[c].max(1e-30))
        .fold(0.0, f64::max);
    (total, se)
}

/// The error table for `elevations` (degrees; the sun at azimuth 0).
pub fn error_vs_elevation(atm: &Atmosphere, elevations: &[f64], views: &Views) -> Vec<Row> {
    elevations.iter().map(|&el| row(atm, el, views)).collect()
}

fn row(atm: &Atmosphere, sun_el: f64, views: &Views) -> Row {
    let sun = direction(sun_el, 0.0);
    let p = AtmosphereGpu::new(atm, views.eye_altitude, sun, views.aerial_range);
    let luts = Luts::build(&p);
    let fog = FogParams::new(atm, views.eye_altitude, sun, false);
    let fog_t = FogParams::new(atm, views.eye_altitude, sun, true);
    let mut out = Row {
        sun_elevation_deg: sun_el,
        ..Row::default()
    };
    let eye = super::eye_position(atm, views.eye_altitude);
    for &(el, az, s) in &views.segments {
        let dir = direction(el, az);
        let ray = ViewRay {
            eye_altitude: views.eye_altitude,
            dir,
            sun,
            length: Some(s),
        };
        let (_, s) = ray.start_and_length(atm);
        let ss = reference::single_scattering(atm, &ray);
        let (want, se) = reference_inscatter(atm, &ray, &views.mc);
        out.reference_rel_se = out.reference_rel_se.max(se);
        let d32 = dir.as_vec3();
        let (ap, _) = luts.aerial_perspective(d32, (s / 1000.0) as f32);
        out.hillaire_aerial = out.hillaire_aerial.max(rel(f32x3(ap), want));
        let (mr, _) = luts.march_segment(d32, (s / 1000.0) as f32, 64);
        out.hillaire_march = out.hillaire_march.max(rel(f32x3(mr), want));
        let end = eye + s * dir;
        let (f, ft) = fog.segment(eye, end);
        out.fog = out.fog.max(rel(f, want));
        out.fog_attenuated_sun = out
            .fog_attenuated_sun
            .max(rel(fog_t.segment(eye, end).0, want));
        out.fog_vs_single = out.fog_vs_single.max(rel(f, ss.inscatter));
        let fa = fog_t.segment(eye, end).0;
        out.fog_attenuated_vs_single = out.fog_attenuated_vs_single.max(rel(fa, ss.inscatter));
        out.single_only = out.single_only.max(rel(ss.inscatter, want));
        let dt = (0..3)
            .map(|c| (ft[c] - ss.transmittance[c]).abs())
            .fold(0.0, f64::max);
        out.fog_transmittance = out.fog_transmittance.max(dt);
    }
    for &(el, az) in &views.sky {
        let dir = direction(el, az);
        let ray = ViewRay {
            eye_altitude: views.eye_altitude,
            dir,
            sun,
            length: None,
        };
        let (want, se) = reference_inscatter(atm, &ray, &views.mc);
        out.reference_rel_se = out.reference_rel_se.max(se);
        let got = luts.sky_radiance(dir.as_vec3());
        out.hillaire_sky = out.hillaire_sky.max(rel(f32x3(got), want));
    }
    out
}

/// The lowest elevation of `rows` from which up every row's `metric` stays within `limit`
/// (None when even the highest sun exceeds it).
pub fn lowest_within(rows: &[Row], metric: impl Fn(&Row) -> f64, limit: f64) -> Option<f64> {
    let mut sorted: Vec<&Row> = rows.iter().collect();
    sorted.sort_by(|a, b| b.sun_elevation_deg.total_cmp(&a.sun_elevation_deg));
    let mut lowest = None;
    for r in sorted {
        if metric(r) > limit {
            break;
        }
        lowest = Some(r.sun_elevation_deg);
    }
    lowest
}

/// The table as Markdown.
pub fn markdown(rows: &[Row]) -> String {
    let mut s = String::from(
        "| sun ° | Hillaire aerial | Hillaire march | Hillaire sky | constant fog | fog, sun attenuated | constant fog vs single | attenuated vs single | single only | fog ΔT | ref. MC rel. SE |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let pc = |x: f64| {
        if x > 100.0 {
            "> 10⁴ %".to_string()
        } else {
            format!("{:.1} %", 100.0 * x)
        }
    };
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.3} | {} |\n",
            r.sun_elevation_deg,
            pc(r.hillaire_aerial),
            pc(r.hillaire_march),
            pc(r.hillaire_sky),
            pc(r.fog),
            pc(r.fog_attenuated_sun),
            pc(r.fog_vs_single),
            pc(r.fog_attenuated_vs_single),
            pc(r.single_only),
            r.fog_transmittance,
            pc(r.reference_rel_se),
        ));
    }
    s
}

/// A sun direction helper for callers: elevation ° at azimuth 0.
pub fn sun_at(elevation_deg: f64) -> DVec3 {
    direction(elevation_deg, 0.0)
}
