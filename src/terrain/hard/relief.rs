//! Whole-image hard shadows and shaded relief (docs/algorithms.md §4): a shadow mask from the exact or
//! the accelerated traversal, parallel over rows, and a Lambert-shaded relief darkened by the
//! relief-shadow paper's shadow brightness (eq. 4) k_shadow = k_dark + (k_bright − k_dark)·(s·up).

use crate::error::{Error, Result};
use crate::heightmap::HeightMap;
use crate::progress::Progress;
use crate::terrain::hard::accelerated_traversal::shadowed_accelerated;
use crate::terrain::hard::exact_traversal::shadowed_exact;
use crate::terrain::hard::sweep::shadow_mask_sweep;
use crate::terrain::minmax_mipmap::MinMaxMipmap;
use crate::terrain::sun::{Sun, Track};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How hard shadows are computed. All give the same mask.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "snake_case")]
pub enum HardMethod {
    /// Every texel on the track (algorithm A1), stopping once the ray is above the map's maximum.
    Exact,
    /// Over the min/max mipmap (algorithm A2).
    Accelerated,
    /// A certified sweep along the sun's azimuth; undecided pixels line by line (no mipmap).
    #[default]
    Sweep,
}

impl HardMethod {
    pub fn label(&self) -> &'static str {
        match self {
            HardMethod::Exact => "exact",
            HardMethod::Accelerated => "accelerated",
            HardMethod::Sweep => "sweep",
        }
    }
}

/// Shadow mask of `map` (row-major, `true` = in shadow). `mip` is used by `Accelerated` (built
/// on the fly when `None`); the others ignore it. Deterministic for any thread count.
pub fn shadow_mask(
    map: &HeightMap,
    sun: &Sun,
    method: HardMethod,
    mip: Option<&MinMaxMipmap>,
    progress: &dyn Progress,
) -> Vec<bool> {
    let track = Track::new(sun, map.cell_size);
    if method == HardMethod::Sweep {
        progress.begin("shadow", 0);
        let (mask, _) = shadow_mask_sweep(map, &track);
        progress.finish();
        return mask;
    }
    let built;
    let mip = match (method, mip) {
        (HardMethod::Accelerated, None) => {
            built = MinMaxMipmap::build(map);
            Some(&built)
        }
        (_, m) => m,
    };
    let (_, max_height) = map.min_max();
    progress.begin("shadow", map.height as u64);
    let rows: Vec<Vec<bool>> = (0..map.height)
        .into_par_iter()
        .map(|row| {
            let r = (0..map.width)
                .map(|col| match (method, mip) {
                    (HardMethod::Accelerated, Some(m)) => {
                        shadowed_accelerated(map, m, &track, col, row)
                    }
                    _ => shadowed_exact(map, &track, col, row, max_height),
                })
                .collect();
            progress.advance(1);
            r
        })
        .collect();
    progress.finish();
    rows.concat()
}

/// The relief-shadow paper's shadow brightness (eq. 4): k_dark + (k_bright − k_dark)·(s·up), s·up = sin(elevation)
/// (clamped at 0 for a sun below the horizon).
pub fn k_shadow(sun: &Sun, k_dark: f64, k_bright: f64) -> f64 {
    k_dark + (k_bright - k_dark) * sun.up_component().max(0.0)
}

/// Check shadow brightness knobs: each in [0, 1].
pub fn check_k(k_dark: f64, k_bright: f64) -> Result<()> {
    for (name, k) in [("k-dark", k_dark), ("k-bright", k_bright)] {
        if !(0.0..=1.0).contains(&k) {
            return Err(Error::knob(format!("{name} must be in [0, 1], got {k}")));
        }
    }
    Ok(())
}

/// Lambert term max(0, n·s) per texel, n from central differences (one-sided at the border)
/// in world units (x east, y north, z up).
pub fn lambert(map: &HeightMap, sun: &Sun) -> Vec<f32> {
    let s = sun.direction();
    let (w, h) = (map.width, map.height);
    (0..h)
        .into_par_iter()
        .flat_map_iter(|r| {
            (0..w).map(move |c| {
                let (dzdx, dzdy) = map.gradient(c, r);
                let n = [-dzdx, -dzdy, 1.0];
                let len = (n[0] * n[0] + n[1] * n[1] + 1.0).sqrt();
                let l = (n[0] * s[0] + n[1] * s[1] + n[2] * s[2]) / len;
                if l.is_finite() {
                    l.max(0.0) as f32
                } else {
                    0.0
                }
            })
        })
        .collect()
}

/// Shaded relief in linear [0, 1]: Lambert × (1 − (1 − k_shadow)·shadow), where `shadow` is the
/// shadowed fraction of the sun per texel (1 for a hard shadow, 1 − lit for soft shadows).
pub fn shaded_relief(
    map: &HeightMap,
    sun: &Sun,
    shadow: &[f32],
    k_dark: f64,
    k_bright: f64,
) -> Vec<f32> {
    let k = k_shadow(sun, k_dark, k_bright) as f32;
    lambert(map, sun)
        .into_iter()
        .zip(shadow)
        .map(|(l, &s)| l * (1.0 - (1.0 - k) * s))
        .collect()
}

/// The fraction of shadowed texels of `mask` among those `nodata` (one flag per texel, or empty
/// for none) does not mark; 0 when none is valid.
pub fn shadowed_fraction(mask: &[bool], nodata: &[bool]) -> f64 {
    let nd = |i: usize| nodata.get(i).copied().unwrap_or(false);
    let valid = (0..mask.len()).filter(|&i| !nd(i)).count().max(1);
    let shadowed = (0..mask.len()).filter(|&i| mask[i] && !nd(i)).count();
    shadowed as f64 / valid as f64
}
