//! Soft-shadow sweep (docs/algorithms.md §5, §7): uniform stepping, the soft-shadow paper's dynamic
//! programming and branch-and-bound against the exhaustive reference (every texel on the sun
//! track), on the maps the terrain study already built.
//!
//! The exhaustive reference walks the whole track at low sun, so every method runs on the same
//! deterministic subset of rows (`rows` evenly spaced rows, all columns). Error = the lit
//! fraction's absolute difference (mean, max, RMS). Baseline of each row: uniform-100 of the
//! same size and elevation (the soft-shadow paper's baseline).

use super::timing::timed_cpu;
use super::{Column, ErrorStats, Format, Measure, Setting, Sweep};
use crate::error::Result;
use crate::heightmap::HeightMap;
use crate::progress::{Progress, Silent};
use crate::terrain::soft::{SoftContext, SoftMethod, SoftShadowParams};
use crate::terrain::{MinMaxMipmap, Sun};

/// What the soft-shadow sweep runs.
#[derive(Clone, Debug, PartialEq)]
pub struct SoftConfig {
    /// Sun elevations in degrees (low suns have long tracks: where the methods differ).
    pub elevations: Vec<f64>,
    /// Rows timed per map (evenly spaced; all columns).
    pub rows: usize,
    /// The methods compared with the exhaustive reference.
    pub methods: Vec<SoftMethod>,
}

impl SoftConfig {
    pub fn full() -> Self {
        SoftConfig {
            elevations: vec![2.0, 5.0, 10.0],
            rows: 128,
            methods: methods(&[32, 100, 256], &[0, 1, 2, 3, 4, 8], &[0]),
        }
    }

    pub fn quick() -> Self {
        SoftConfig {
            elevations: vec![5.0],
            rows: 32,
            methods: methods(&[32, 100], &[0, 4], &[0]),
        }
    }
}

impl SoftConfig {
    /// Replace the dynamic-programming rows by every start level of `levels` with every
    /// interval cap of `intervals` (0 = as many as the track needs).
    pub fn set_dp(&mut self, levels: &[i32], intervals: &[u32]) {
        self.methods
            .retain(|m| !matches!(m, SoftMethod::DynamicProgramming { .. }));
        let bnb = self.methods.pop();
        self.methods.extend(dp(levels, intervals));
        self.methods.extend(bnb);
    }

    /// The start levels and interval caps of the dynamic-programming rows.
    pub fn dp_knobs(&self) -> (Vec<i32>, Vec<u32>) {
        let (mut levels, mut intervals) = (Vec::new(), Vec::new());
        for m in &self.methods {
            if let SoftMethod::DynamicProgramming {
                start_level,
                intervals: k,
            } = *m
            {
                if !levels.contains(&start_level) {
                    levels.push(start_level);
                }
                if !intervals.contains(&k) {
                    intervals.push(k);
                }
            }
        }
        (levels, intervals)
    }
}

/// Dynamic programming from every start level with every interval cap.
fn dp<'a>(levels: &'a [i32], intervals: &'a [u32]) -> impl Iterator<Item = SoftMethod> + 'a {
    levels.iter().flat_map(move |&start_level| {
        intervals
            .iter()
            .map(move |&intervals| SoftMethod::DynamicProgramming {
                start_level,
                intervals,
            })
    })
}

/// Uniform stepping at `steps`, dynamic programming from `levels` with each interval cap of
/// `intervals`, and branch-and-bound.
fn methods(steps: &[u32], levels: &[i32], intervals: &[u32]) -> Vec<SoftMethod> {
    let mut m: Vec<SoftMethod> = steps
        .iter()
        .map(|&steps| SoftMethod::Uniform { steps })
        .collect();
    m.extend(dp(levels, intervals));
    m.push(SoftMethod::BranchAndBound);
    m
}

/// The uniform-100 baseline must be part of every comparison.
const BASELINE: SoftMethod = SoftMethod::Uniform { steps: 100 };

/// The soft-shadow sweep over `maps` (each with its min/max mipmap), sun azimuth `azimuth`.
pub fn soft_shadow_sweep(
    maps: &[(HeightMap, MinMaxMipmap)],
    azimuth: f64,
    cfg: &SoftConfig,
    progress: &dyn Progress,
) -> Result<Sweep> {
    let suns = cfg
        .elevations
        .iter()
        .map(|&e| Sun::new(azimuth, e))
        .collect::<Result<Vec<_>>>()?;
    let mut methods = vec![SoftMethod::Exhaustive];
    if !cfg.methods.contains(&BASELINE) {
        methods.push(BASELINE);
    }
    methods.extend(cfg.methods.iter().copied());
    let mut sweep = Sweep {
        name: "terrain_soft_shadows".into(),
        title: "Terrain: soft shadows".into(),
        description: format!(
            "sun azimuth {azimuth}°, elevations {:?}°, sun radius 0.2666°, flat ground; {} evenly spaced rows of each map, all columns",
            cfg.elevations, cfg.rows
        ),
        reference: "the exhaustive walk over every texel of the track (error exactly 0)".into(),
        time: "the timed rows, wall".into(),
        bytes: "extra memory: the min/max mipmap (dynamic programming, branch-and-bound)".into(),
        ..Default::default()
    };
    progress.begin("study: soft shadows", (maps.len() * suns.len()) as u64);
    for (map, mip) in maps {
        let (w, h) = (map.width, map.height);
        let count = cfg.rows.clamp(1, h);
        let rows: Vec<usize> = (0..count).map(|k| k * h / count).collect();
        let pixels = (rows.len() * w) as f64;
        for sun in &suns {
            let el = sun.elevation_deg;
            let label = |m: &SoftMethod| format!("{w}x{h} {el}° {}", m.label());
            let mut reference = Vec::new();
            for m in &methods {
                let params = SoftShadowParams {
                    method: *m,
                    ..Default::default()
                };
                let ctx = SoftContext::new(map, mip, sun, &params)?;
                let (lit, wall, cpu) = timed_cpu(|| ctx.rows(&rows, &Silent));
                let lit: Vec<f64> = lit.iter().map(|&v| v as f64).collect();
                if *m == SoftMethod::Exhaustive {
                    reference = lit.clone();
                }
                let mut s = Setting::new(label(m), m.label())
                    .default_if(*m == SoftShadowParams::default().method)
                    .knob("width", w)
                    .knob("height", h)
                    .knob("sun_elevation", el)
                    .knob("sun_azimuth", azimuth)
                    .knob("method", m.label());
                s.reference = *m == SoftMethod::Exhaustive;
                s.baseline = Some(label(&BASELINE));
                s.errors.insert(
                    "lit_fraction".into(),
                    ErrorStats::of(&lit, &reference, None),
                );
                s.seconds = wall;
                s.bytes = match m {
                    SoftMethod::Exhaustive | SoftMethod::Uniform { .. } => 0,
                    _ => mip.bytes() as u64,
                };
                let penumbra = reference.iter().filter(|&&l| l > 0.0 && l < 1.0).count();
                for (k, v) in [
                    ("pixels", pixels),
                    ("cpu_seconds", cpu),
                    ("us_per_pixel", wall / pixels * 1e6),
                    ("penumbra_fraction", penumbra as f64 / pixels),
                ] {
                    s.extra.insert(k.into(), v);
                }
                sweep.settings.push(s);
            }
            progress.advance(1);
        }
    }
    progress.finish();
    sweep.columns = vec![
        Column::error("mean error", "lit_fraction", "mean", Format::Sci, false),
        Column::error("max error", "lit_fraction", "max", Format::Sci, false),
        Column::extra("in penumbra", "penumbra_fraction", Format::Percent, false),
        Column::new("time", Measure::Seconds, Format::Time, true),
        Column::extra("µs/pixel", "us_per_pixel", Format::Fixed, false),
        Column::new("bytes", Measure::Bytes, Format::Bytes, false),
    ];
    sweep.notes.push(
        "Ratios are against uniform stepping with 100 steps (the soft-shadow paper's baseline) on the same rows, size and elevation. Branch-and-bound finds the exact maximum, so its error is 0 up to f32 rounding of the lit fraction.".into(),
    );
    sweep.error_plots(
        Measure::error("lit_fraction", "mean"),
        "mean |lit - lit_exhaustive|",
    );
    Ok(sweep)
}
