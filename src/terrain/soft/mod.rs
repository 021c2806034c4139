//! Soft shadows of the sun's disc on (optionally curved) terrain (docs/algorithms.md §5; the soft-shadow paper, Jung,
//! Schrempp & Son 2020): the model in [`model`], four ways to find the most occluding point:
//!
//! - [`exhaustive`]: every texel on the track — the reference;
//! - [`uniform`]: `steps` evenly spaced samples — the soft-shadow paper's baseline;
//! - [`dynamic_programming`]: the soft-shadow paper's method over the mipmap, greedy and approximate;
//! - [`branch_and_bound`]: the exact maximum over the mipmap, pruning blocks by bounds.
//!
//! Per-pixel kernels are plain loops over flat arrays, like the hard-shadow ones.

pub mod branch_and_bound;
pub mod dynamic_programming;
pub mod exhaustive;
pub mod model;
pub mod uniform;

use crate::error::{Error, Result};
use crate::heightmap::HeightMap;
use crate::progress::Progress;
use crate::terrain::minmax_mipmap::MinMaxMipmap;
use crate::terrain::sun::{Sun, Track};
use model::{SoftSun, SUN_RADIUS_DEG};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How the most occluding point is found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SoftMethod {
    /// Every texel on the track (the reference).
    Exhaustive,
    /// `steps` evenly spaced samples (the soft-shadow paper's baseline uses 100).
    Uniform { steps: u32 },
    /// The soft-shadow paper's dynamic programming from `start_level` (−1 = texels; clamped to the top
    /// level) over `intervals` intervals (0 = as many as the track needs).
    DynamicProgramming { start_level: i32, intervals: u32 },
    /// The exact maximum by branch-and-bound over the mipmap.
    BranchAndBound,
}

impl SoftMethod {
    /// A short label for tables and reports.
    pub fn label(&self) -> String {
        match self {
            SoftMethod::Exhaustive => "exhaustive".into(),
            SoftMethod::Uniform { steps } => format!("uniform {steps}"),
            SoftMethod::DynamicProgramming {
                start_level,
                intervals: 0,
            } => format!("dynamic programming, start level {start_level}"),
            SoftMethod::DynamicProgramming {
                start_level,
                intervals,
            } => format!("dynamic programming, start level {start_level}, {intervals} intervals"),
            SoftMethod::BranchAndBound => "branch and bound".into(),
        }
    }
}

/// Soft-shadow knobs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftShadowParams {
    /// Angular radius of the sun disc, degrees (default the Sun's, 0.2666).
    pub sun_radius_deg: f64,
    /// Planet radius in metres; `None` = flat ground.
    pub planet_radius_m: Option<f64>,
    pub method: SoftMethod,
}

impl Default for SoftShadowParams {
    fn default() -> Self {
        SoftShadowParams {
            sun_radius_deg: SUN_RADIUS_DEG,
            planet_radius_m: None,
            method: SoftMethod::BranchAndBound,
        }
    }
}

impl SoftShadowParams {
    /// Check the knobs' ranges.
    pub fn check(&self) -> Result<()> {
        let a = self.sun_radius_deg;
        if !(a.is_finite() && a > 0.0 && a <= 45.0) {
            return Err(Error::knob(format!(
                "sun radius must be in (0, 45] degrees, got {a}"
            )));
        }
        if let Some(r) = self.planet_radius_m {
            if !(r.is_finite() && r > 0.0) {
                return Err(Error::knob(format!(
                    "planet radius must be a positive number of metres, got {r}"
                )));
            }
        }
        if let SoftMethod::Uniform { steps: 0 } = self.method {
            return Err(Error::knob("uniform stepping needs at least 1 step"));
        }
        Ok(())
    }

    fn soft_sun(&self, sun: &Sun) -> SoftSun {
        SoftSun {
            sun: *sun,
            alpha: self.sun_radius_deg.to_radians(),
            radius: self.planet_radius_m.unwrap_or(f64::INFINITY),
        }
    }
}

/// Everything the per-pixel kernels share for one map and sun.
pub struct SoftContext<'a> {
    pub map: &'a HeightMap,
    pub mip: &'a MinMaxMipmap,
    pub track: Track,
    pub soft_sun: SoftSun,
    pub method: SoftMethod,
}

impl<'a> SoftContext<'a> {
    /// Set up for `map` (with its mipmap) and `sun`; checks `params`.
    pub fn new(
        map: &'a HeightMap,
        mip: &'a MinMaxMipmap,
        sun: &Sun,
        params: &SoftShadowParams,
    ) -> Result<Self> {
        params.check()?;
        Ok(SoftContext {
            map,
            mip,
            track: Track::new(sun, map.cell_size),
            soft_sun: params.soft_sun(sun),
            method: params.method,
        })
    }

    /// Lit fraction of one pixel.
    pub fn lit(&self, col: usize, row: usize) -> f32 {
        let map = self.map;
        let zp = map.heights[row * map.width + col] as f64;
        let ps = self
            .soft_sun
            .at_pixel(zp, col, row, map.width, map.height, map.cell_size);
        let range = (self.mip.max_height, self.mip.min_height);
        match self.method {
            SoftMethod::Exhaustive => {
                exhaustive::lit_exhaustive(map, &self.track, &ps, col, row, range, true)
            }
            SoftMethod::Uniform { steps } => {
                uniform::lit_uniform(map, &self.track, &ps, col, row, steps, range.0)
            }
            SoftMethod::DynamicProgramming {
                start_level,
                intervals,
            } => dynamic_programming::lit_dynamic_programming(
                map,
                self.mip,
                &self.track,
                &ps,
                col,
                row,
                start_level as i64,
                intervals,
            ),
            SoftMethod::BranchAndBound => {
                branch_and_bound::lit_branch_and_bound(map, self.mip, &self.track, &ps, col, row)
            }
        }
    }

    /// Lit fractions of the given rows (row-major, in the order given), parallel over rows.
    pub fn rows(&self, rows: &[usize], progress: &dyn Progress) -> Vec<f32> {
        let w = self.map.width;
        rows.par_iter()
            .flat_map_iter(|&r| {
                let v: Vec<f32> = (0..w).map(|c| self.lit(c, r)).collect();
                progress.advance(1);
                v
            })
            .collect()
    }
}

/// The lit fraction of every pixel (row-major), in [0, 1]. `mip` is built when `None`.
/// Deterministic for any thread count.
pub fn soft_shadow_map(
    map: &HeightMap,
    sun: &Sun,
    params: &SoftShadowParams,
    mip: Option<&MinMaxMipmap>,
    progress: &dyn Progress,
) -> Result<Vec<f32>> {
    let built;
    let mip = match mip {
        Some(m) => m,
        None => {
            built = MinMaxMipmap::build(map);
            &built
        }
    };
    let ctx = SoftContext::new(map, mip, sun, params)?;
    progress.begin("softshadow", map.height as u64);
    let rows: Vec<usize> = (0..map.height).collect();
    let out = ctx.rows(&rows, progress);
    progress.finish();
    Ok(out)
}

/// The mean lit fraction and the fraction of texels in penumbra (lit strictly between 0 and 1)
/// over the texels of `lit` that `nodata` (one flag per texel, or empty for none) does not mark.
/// Both are 0 when no texel is valid.
pub fn lit_summary(lit: &[f32], nodata: &[bool]) -> (f64, f64) {
    let valid = || {
        (0..lit.len())
            .filter(|&i| !nodata.get(i).copied().unwrap_or(false))
            .map(|i| lit[i])
    };
    let n = valid().count().max(1) as f64;
    let mean = valid().map(|l| l as f64).sum::<f64>() / n;
    let penumbra = valid().filter(|&l| l > 0.0 && l < 1.0).count() as f64 / n;
    (mean, penumbra)
}
