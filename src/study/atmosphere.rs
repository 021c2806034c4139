//! Scattered-light study (docs/atmosphere.md): the in-scattering error of the constant-density
//! fog of Vyatkin et al. (2018) and of Hillaire's tables against sun elevation, from
//! `atmosphere::study::error_vs_elevation` (the reference: f64 quadrature single scattering + Monte
//! Carlo orders ≥ 2). One sweep; a setting per (model, sun elevation), its error the largest
//! relative error over the views and RGB. The plot is log–log like every study plot, so suns at or
//! below the horizon appear in the table only.

use super::{Column, Format, Measure, PlotSpec, Setting, Sweep};
use crate::atmosphere::study::{error_vs_elevation, Row, Views};
use crate::atmosphere::Atmosphere;

/// What the atmosphere study runs.
#[derive(Clone, Debug, PartialEq)]
pub struct AtmosphereConfig {
    /// Sun elevations (degrees).
    pub elevations: Vec<f64>,
    /// Monte Carlo paths per view ray of the reference.
    pub paths: usize,
}

impl AtmosphereConfig {
    /// The table of docs/atmosphere.md (2,000 paths per ray).
    pub fn full() -> Self {
        AtmosphereConfig {
            elevations: vec![90.0, 60.0, 30.0, 15.0, 10.0, 5.0, 2.0, 0.0, -2.0],
            paths: 2_000,
        }
    }

    /// Five suns above the horizon, 1,000 paths per ray (seconds on 2 cores).
    pub fn quick() -> Self {
        AtmosphereConfig {
            elevations: vec![90.0, 60.0, 30.0, 10.0, 2.0],
            paths: 1_000,
        }
    }
}

/// A row's error for one model.
type Metric = fn(&Row) -> f64;

/// The models plotted: (series, what it measures).
const MODELS: [(&str, Metric); 3] = [
    ("constant fog", |r| r.fog),
    ("Hillaire aerial", |r| r.hillaire_aerial),
    ("Hillaire sky", |r| r.hillaire_sky),
];

/// Run the study on Earth's air with the default views.
pub fn run(cfg: &AtmosphereConfig) -> Vec<Sweep> {
    let mut views = Views::default();
    views.mc.paths = cfg.paths;
    let rows = error_vs_elevation(&Atmosphere::earth(), &cfg.elevations, &views);
    vec![sweep(&rows, &views)]
}

/// The sweep of `rows`.
pub fn sweep(rows: &[Row], views: &Views) -> Sweep {
    let mut settings = Vec::new();
    for (series, metric) in MODELS {
        for r in rows {
            let el = r.sun_elevation_deg;
            let mut s = Setting::new(format!("{series} {el}°"), series)
                .knob("sun_elevation_deg", el)
                .default_if(series == "Hillaire aerial");
            s.extra.insert("sun_elevation_deg".into(), el);
            s.extra.insert("error".into(), metric(r));
            s.extra
                .insert("reference_mc_rel_se".into(), r.reference_rel_se);
            settings.push(s);
        }
    }
    Sweep {
        name: "atmosphere".into(),
        title: "Scattered light".into(),
        description: format!(
            "In-scattered radiance of each model by sun elevation: eye at {} m, {} segments \
             (aerial perspective, constant fog) and {} sky directions; error = the largest relative \
             error over the views and RGB",
            views.eye_altitude,
            views.segments.len(),
            views.sky.len()
        ),
        reference: format!(
            "f64 quadrature single scattering + Monte Carlo orders ≥ 2 ({} paths per ray)",
            views.mc.paths
        ),
        baseline: String::new(),
        time: "not timed".into(),
        bytes: "none".into(),
        settings,
        columns: vec![
            Column::extra("sun °", "sun_elevation_deg", Format::Fixed, false),
            Column::extra("max rel. error", "error", Format::Percent, false),
            Column::extra(
                "ref. MC rel. SE",
                "reference_mc_rel_se",
                Format::Percent,
                false,
            ),
        ],
        plots: vec![PlotSpec {
            file: "atmosphere_error_vs_elevation.png".into(),
            title: "Scattered light: error vs sun elevation".into(),
            x: Measure::extra("sun_elevation_deg"),
            y: Measure::extra("error"),
            x_label: "sun elevation (degrees, above 0)".into(),
            y_label: "max relative error".into(),
        }],
        notes: vec![
            "Hillaire aerial is relume's default model (ringed). Suns at or below the horizon \
             are in the table only (log axes)."
                .into(),
        ],
    }
}
