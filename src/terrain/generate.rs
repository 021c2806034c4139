//! Synthetic height maps: the relief-shadow paper's stress maps ("spikes": thin tall cones; "steps": sharp
//! terraces) and analytic shapes whose shadows have closed forms (wall, cone, hemisphere,
//! crater). All are N×N texels of 1 m with heights in metres; the feature scale is
//! H = N/4 m (so shapes keep their proportions at any size).

use crate::heightmap::HeightMap;
use serde::{Deserialize, Serialize};

/// Which map to generate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// Five thin cones (base radius N/64, heights N/8..N/4) on flat ground.
    Spikes,
    /// Eight terraces rising west to east with vertical cliffs, N/32 m each.
    Steps,
    /// Zero everywhere.
    Flat,
    /// A north–south wall of height N/8, N/32 texels thick (at least 1), its west face at x = N/2.
    Wall,
    /// A cone of height N/4 and base radius N/4 at the centre (the centre of texel (N/2, N/2)).
    Cone,
    /// A hemisphere of radius N/4 at the centre on flat ground at 0.
    Hemisphere,
    /// A hemispherical bowl of radius N/4 sunk into flat ground at 0.
    Crater,
}

impl Shape {
    pub const ALL: [Shape; 7] = [
        Shape::Spikes,
        Shape::Steps,
        Shape::Flat,
        Shape::Wall,
        Shape::Cone,
        Shape::Hemisphere,
        Shape::Crater,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Shape::Spikes => "spikes",
            Shape::Steps => "steps",
            Shape::Flat => "flat",
            Shape::Wall => "wall",
            Shape::Cone => "cone",
            Shape::Hemisphere => "hemisphere",
            Shape::Crater => "crater",
        }
    }
}

/// The (x, y) texel-space centre of the analytic shapes for a map of side `n`: the centre of
/// texel (n/2, n/2), so that apexes are sampled exactly.
pub fn centre(n: usize) -> (f64, f64) {
    let c = (n / 2) as f64 + 0.5;
    (c, c)
}

/// The continuous height of `shape` at texel-space (x, y) for a map of side `n` (what the
/// texels sample at their centres).
pub fn height_at(shape: Shape, n: usize, x: f64, y: f64) -> f64 {
    let nf = n as f64;
    let big = nf / 4.0;
    let (cx, cy) = centre(n);
    let r = (x - cx).hypot(y - cy);
    match shape {
        Shape::Flat => 0.0,
        Shape::Wall => {
            let west = (n / 2) as f64;
            let thick = (n / 32).max(1) as f64;
            if x >= west && x < west + thick {
                nf / 8.0
            } else {
                0.0
            }
        }
        Shape::Cone => (big * (1.0 - r / big)).max(0.0),
        Shape::Hemisphere => (big * big - r * r).max(0.0).sqrt(),
        Shape::Crater => -(big * big - r * r).max(0.0).sqrt(),
        Shape::Steps => {
            let step = ((8.0 * x / nf).floor()).clamp(0.0, 7.0);
            step * nf / 32.0
        }
        Shape::Spikes => {
            let radius = (nf / 64.0).max(1.0);
            SPIKES
                .iter()
                .map(|&(fx, fy, rel)| {
                    let d = (x - fx * nf).hypot(y - fy * nf);
                    rel * big * (1.0 - d / radius).max(0.0)
                })
                .fold(0.0, f64::max)
        }
    }
}

/// Spike positions (as fractions of N) and relative heights.
pub const SPIKES: [(f64, f64, f64); 5] = [
    (0.25, 0.25, 1.0),
    (0.70, 0.20, 0.8),
    (0.50, 0.55, 0.6),
    (0.20, 0.75, 0.9),
    (0.80, 0.80, 0.5),
];

/// Generate an `n`×`n` map (cell size 1 m): [`height_at`] sampled at the texel centres.
pub fn generate(shape: Shape, n: usize) -> HeightMap {
    let mut heights = vec![0.0f32; n * n];
    for row in 0..n {
        for col in 0..n {
            heights[row * n + col] = height_at(shape, n, col as f64 + 0.5, row as f64 + 0.5) as f32;
        }
    }
    HeightMap::new(n, n, heights, [1.0, 1.0])
}

/// Quantise heights to 16 bits for PNG: value = round((h − min) / scale) with
/// scale = (max − min)/65535 (1 for a flat map). Returns (values, scale in metres per unit,
/// offset = min). Loading the PNG with `--height-scale scale` restores the heights up to the
/// constant offset (which shadows do not depend on) and 16-bit rounding.
pub fn quantise_u16(map: &HeightMap) -> (Vec<u16>, f64, f64) {
    let (lo, hi) = map.min_max();
    let (lo, hi) = (lo as f64, hi as f64);
    let scale = if hi > lo { (hi - lo) / 65535.0 } else { 1.0 };
    let v = map
        .heights
        .iter()
        .map(|&h| ((h as f64 - lo) / scale).round().clamp(0.0, 65535.0) as u16)
        .collect();
    (v, scale, lo)
}
