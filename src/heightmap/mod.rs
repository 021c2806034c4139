//! Height maps: a W×H grid of heights in metres with its cell size, loaded from 8/16-bit
//! grayscale PNG, RGB PNG/JPEG with equal channels, single-channel EXR, GeoTIFF
//! (int16/uint16/float32, cell size from a `.tfw` world file or the GeoTIFF pixel-scale tag) or raw
//! little-endian f32.
//!
//! Conventions (README "Conventions"): texel (column j, row i) covers [j, j+1) × [i, i+1) in texel
//! units and holds the height at its centre; column index = +x (east), row index = −y (row 0 is
//! the north edge); heights are file values × `height_scale`, in metres.
//!
//! No-data texels (NaN, ±∞, or the file's/knob's no-data value) follow [`NoDataPolicy`]: an error
//! by default, or filled with the minimum valid height or with the nearest valid height.

pub mod georef;
mod geotiff_common;
mod geotiff_stack;
mod geotiff_write;
pub mod minmax_mipmap;
mod readers;
pub use readers::{decode_exr, ExrImage};
pub mod utm;

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;
use std::path::Path;

/// A height field in metres.
#[derive(Clone, Debug, PartialEq)]
pub struct HeightMap {
    pub width: usize,
    pub height: usize,
    /// Row-major heights in metres (file value × `height_scale`), row 0 = north edge.
    pub heights: Vec<f32>,
    /// Metres per texel along x (east) and y (south).
    pub cell_size: [f64; 2],
    /// The factor that was applied to the file's values (metres per file unit).
    pub height_scale: f64,
}

/// What to do with no-data texels (NaN, infinities, or the no-data value).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum NoDataPolicy {
    /// Refuse the height map, naming the first no-data texel (the default).
    #[default]
    Error,
    /// Replace each no-data texel with the minimum valid height.
    FillMin,
    /// Replace each no-data texel with the height of the nearest valid texel (4-connected
    /// breadth-first distance; ties go to the earliest in scan order, so the result is
    /// deterministic).
    FillNearest,
}

/// Knobs for loading a height map. `None` means "what the file says, else the default".
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HeightMapOptions {
    /// Metres per texel (x, y). Default: the GeoTIFF world file or pixel-scale tag, else 1 m.
    pub cell_size: Option<[f64; 2]>,
    /// Metres per file unit. Default 1.
    pub height_scale: Option<f64>,
    /// Value that marks missing data, in file units (in addition to NaN and the GeoTIFF tag).
    pub nodata_value: Option<f64>,
    /// What to do with no-data texels.
    pub nodata: NoDataPolicy,
    /// Width and height of a raw little-endian f32 file (required for `.raw`/`.f32`).
    pub raw_size: Option<[usize; 2]>,
    /// Box-filter downsampling factor applied after loading (0 or 1: none).
    #[serde(default)]
    pub downsample: u32,
}

/// Facts about a loaded height map that are not part of the height field itself.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct HeightMapInfo {
    /// File format that was read (`png`, `jpeg`, `exr`, `geotiff`, `raw-f32`).
    pub format: String,
    /// Sample type in the file (`u8`, `u16`, `i16`, `f32`, ...).
    pub sample: String,
    /// How many texels were no-data (and filled by the policy).
    pub nodata_count: usize,
    /// Where the cell size came from (`option`, `world-file`, `geotiff-tag`, `default`).
    pub cell_size_source: String,
    /// Width and height of the file's grid (before `downsample`).
    pub source_size: [usize; 2],
    /// Where the grid lies (a GeoTIFF's georeference tags), for the loaded (downsampled) grid.
    pub georef: Option<georef::GeoReference>,
    /// Which texels of the loaded grid were no-data before the policy filled them (empty when
    /// none; a downsampled texel is no-data when any of its source texels was).
    #[serde(skip)]
    pub nodata_mask: Vec<bool>,
}

/// Raw decoded samples before scaling and no-data handling.
pub(crate) struct RawGrid {
    pub width: usize,
    pub height: usize,
    pub values: Vec<f64>,
    pub format: &'static str,
    pub sample: &'static str,
    pub nodata: Option<f64>,
    pub cell_size: Option<([f64; 2], &'static str)>,
    pub georef: Option<georef::GeoReference>,
}

/// Load a height map, choosing the reader by extension (`.png`, `.jpg`/`.jpeg`, `.exr`,
/// `.tif`/`.tiff`, `.raw`/`.f32`).
pub fn load_heightmap(path: &Path, opts: &HeightMapOptions) -> Result<(HeightMap, HeightMapInfo)> {
    if let Some([cx, cy]) = opts.cell_size {
        if !(cx.is_finite() && cy.is_finite() && cx > 0.0 && cy > 0.0) {
            return Err(Error::knob(format!(
                "cell size must be positive and finite, got [{cx}, {cy}]"
            )));
        }
    }
    let height_scale = opts.height_scale.unwrap_or(1.0);
    if !(height_scale.is_finite() && height_scale > 0.0) {
        return Err(Error::knob(format!(
            "height scale must be positive and finite, got {height_scale}"
        )));
    }
    let raw = readers::read(path, opts)?;
    if raw.width == 0 || raw.height == 0 {
        return Err(Error::input(
            path,
            format!(
                "the image is {}x{}: a height map needs at least one texel",
                raw.width, raw.height
            ),
        ));
    }
    if raw.values.len() != raw.width * raw.height {
        // Found by fuzzing: the TIFF decoder can return fewer samples than the header declares.
        return Err(Error::input(
            path,
            format!(
                "decoded {} samples for a {}x{} map: the file's data is incomplete",
                raw.values.len(),
                raw.width,
                raw.height
            ),
        ));
    }
    let (cell_size, cell_size_source) = match (opts.cell_size, raw.cell_size) {
        (Some(c), _) => (c, "option"),
        (None, Some((c, source))) => (c, source),
        (None, None) => ([1.0, 1.0], "default"),
    };
    let nodata_value = opts.nodata_value.or(raw.nodata);
    let invalid = |v: f64| !v.is_finite() || Some(v) == nodata_value;
    let mut heights: Vec<f32> = raw
        .values
        .iter()
        .map(|&v| (v * height_scale) as f32)
        .collect();
    let mut valid: Vec<bool> = raw.values.iter().map(|&v| !invalid(v)).collect();
    // A finite file value can still overflow f32 after scaling.
    for (h, ok) in heights.iter().zip(valid.iter_mut()) {
        *ok &= h.is_finite();
    }
    let nodata_count = valid.iter().filter(|v| !**v).count();
    if nodata_count > 0 {
        fill_nodata(
            path,
            raw.width,
            &mut heights,
            &valid,
            opts.nodata,
            nodata_count,
        )?;
    }
    let mut map = HeightMap {
        width: raw.width,
        height: raw.height,
        heights,
        cell_size,
        height_scale,
    };
    let mut nodata_mask = if nodata_count > 0 {
        valid.iter().map(|v| !v).collect()
    } else {
        Vec::new()
    };
    let mut georef = raw.georef;
    if opts.downsample > 1 {
        let f = opts.downsample as usize;
        map = map.downsample(f);
        georef = georef.map(|g| g.downsampled(f));
        if !nodata_mask.is_empty() {
            let (w, h) = (map.width, map.height);
            nodata_mask = (0..w * h)
                .map(|i| {
                    let (x, y) = (i % w, i / w);
                    (y * f..((y + 1) * f).min(raw.height)).any(|yy| {
                        (x * f..((x + 1) * f).min(raw.width))
                            .any(|xx| nodata_mask[yy * raw.width + xx])
                    })
                })
                .collect();
        }
    }
    let info = HeightMapInfo {
        format: raw.format.into(),
        sample: raw.sample.into(),
        nodata_count,
        cell_size_source: cell_size_source.into(),
        source_size: [raw.width, raw.height],
        georef,
        nodata_mask,
    };
    Ok((map, info))
}

fn fill_nodata(
    path: &Path,
    width: usize,
    heights: &mut [f32],
    valid: &[bool],
    policy: NoDataPolicy,
    count: usize,
) -> Result<()> {
    let first = valid.iter().position(|v| !*v).unwrap_or(0);
    if count == heights.len() {
        return Err(Error::input(
            path,
            "every texel is no-data (NaN, infinite or the no-data value)",
        ));
    }
    match policy {
        NoDataPolicy::Error => Err(Error::input(
            path,
            format!(
                "{count} no-data texel(s) (NaN, infinite or the no-data value), the first at column {}, row {}; \
                 choose a policy: `nodata: FillMin` / `FillNearest` in the pipeline, or `--nodata fill-min|fill-nearest`",
                first % width,
                first / width
            ),
        )),
        NoDataPolicy::FillMin => {
            let min = heights.iter().zip(valid).filter(|(_, v)| **v).map(|(h, _)| *h).fold(f32::INFINITY, f32::min);
            for (h, v) in heights.iter_mut().zip(valid) {
                if !*v {
                    *h = min;
                }
            }
            Ok(())
        }
        NoDataPolicy::FillNearest => {
            let height = heights.len() / width;
            let mut done = valid.to_vec();
            let mut queue: VecDeque<usize> = (0..heights.len()).filter(|&i| valid[i]).collect();
            while let Some(i) = queue.pop_front() {
                let (x, y) = (i % width, i / width);
                let mut visit = |j: usize| {
                    if !done[j] {
                        done[j] = true;
                        heights[j] = heights[i];
                        queue.push_back(j);
                    }
                };
                if y > 0 {
                    visit(i - width);
                }
                if x > 0 {
                    visit(i - 1);
                }
                if x + 1 < width {
                    visit(i + 1);
                }
                if y + 1 < height {
                    visit(i + width);
                }
            }
            Ok(())
        }
    }
}

impl HeightMap {
    /// A height map from row-major heights in metres. Panics if the sizes disagree.
    pub fn new(width: usize, height: usize, heights: Vec<f32>, cell_size: [f64; 2]) -> Self {
        assert_eq!(
            heights.len(),
            width * height,
            "heights must hold width*height values"
        );
        HeightMap {
            width,
            height,
            heights,
            cell_size,
            height_scale: 1.0,
        }
    }

    /// Height at column `x`, row `y` (no bounds clamping).
    #[inline]
    pub fn at(&self, x: usize, y: usize) -> f32 {
        self.heights[y * self.width + x]
    }

    /// (∂z/∂x east, ∂z/∂y north) at texel (x, y) in metres per metre: central differences,
    /// one-sided at the border, 0 along an axis one texel wide (the shaders' `lambert_at`).
    pub fn gradient(&self, x: usize, y: usize) -> (f64, f64) {
        let (w, h) = (self.width, self.height);
        let [cx, cy] = self.cell_size;
        let (c0, c1) = (x.saturating_sub(1), (x + 1).min(w - 1));
        let (r0, r1) = (y.saturating_sub(1), (y + 1).min(h - 1));
        let dzdx = if c1 > c0 {
            (self.at(c1, y) as f64 - self.at(c0, y) as f64) / ((c1 - c0) as f64 * cx)
        } else {
            0.0
        };
        // Rows go south: north is r0.
        let dzdy = if r1 > r0 {
            (self.at(x, r0) as f64 - self.at(x, r1) as f64) / ((r1 - r0) as f64 * cy)
        } else {
            0.0
        };
        (dzdx, dzdy)
    }

    /// Minimum and maximum height.
    pub fn min_max(&self) -> (f32, f32) {
        self.heights
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &h| {
                (lo.min(h), hi.max(h))
            })
    }

    /// Bilinear height at texel-space position (px, py) — texel centres at half-integers,
    /// clamped at the border (docs/algorithms.md §4).
    pub fn bilinear(&self, px: f64, py: f64) -> f64 {
        let fx = (px - 0.5).clamp(0.0, (self.width - 1) as f64);
        let fy = (py - 0.5).clamp(0.0, (self.height - 1) as f64);
        let x0 = (fx.floor() as usize).min(self.width - 1);
        let y0 = (fy.floor() as usize).min(self.height - 1);
        let x1 = (x0 + 1).min(self.width - 1);
        let y1 = (y0 + 1).min(self.height - 1);
        let tx = fx - x0 as f64;
        let ty = fy - y0 as f64;
        let h = |x, y| self.at(x, y) as f64;
        let top = h(x0, y0) + (h(x1, y0) - h(x0, y0)) * tx;
        let bottom = h(x0, y1) + (h(x1, y1) - h(x0, y1)) * tx;
        top + (bottom - top) * ty
    }

    /// Box-filter downsampling by an integer factor (e.g. 4096 → 1024 with factor 4); the cell
    /// size grows by the same factor. Edge blocks of sizes not divisible by `factor` average the
    /// texels they have.
    pub fn downsample(&self, factor: usize) -> HeightMap {
        assert!(factor >= 1);
        let w = self.width.div_ceil(factor);
        let h = self.height.div_ceil(factor);
        let mut out = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                let (mut sum, mut n) = (0.0f64, 0usize);
                for yy in y * factor..((y + 1) * factor).min(self.height) {
                    for xx in x * factor..((x + 1) * factor).min(self.width) {
                        sum += self.at(xx, yy) as f64;
                        n += 1;
                    }
                }
                out.push((sum / n as f64) as f32);
            }
        }
        HeightMap {
            width: w,
            height: h,
            heights: out,
            cell_size: [
                self.cell_size[0] * factor as f64,
                self.cell_size[1] * factor as f64,
            ],
            height_scale: self.height_scale,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fill_nearest_copies_the_closest_valid_texel() {
        let mut h = vec![1.0, f32::NAN, f32::NAN, 4.0, f32::NAN, f32::NAN];
        let valid: Vec<bool> = h.iter().map(|v| v.is_finite()).collect();
        fill_nodata(
            Path::new("x"),
            3,
            &mut h,
            &valid,
            NoDataPolicy::FillNearest,
            4,
        )
        .unwrap();
        // Each hole takes the value of the valid texel fewest 4-connected steps away.
        assert_eq!(h, vec![1.0, 1.0, 1.0, 4.0, 4.0, 4.0]);
    }

    #[test]
    fn fill_min_uses_the_smallest_valid_height() {
        let mut h = vec![3.0, f32::NAN, 2.0, 5.0];
        let valid: Vec<bool> = h.iter().map(|v| v.is_finite()).collect();
        fill_nodata(Path::new("x"), 2, &mut h, &valid, NoDataPolicy::FillMin, 1).unwrap();
        assert_eq!(h, vec![3.0, 2.0, 2.0, 5.0]);
    }

    #[test]
    fn bilinear_is_exact_at_centres_and_clamped_outside() {
        let m = HeightMap::new(2, 2, vec![0.0, 1.0, 2.0, 3.0], [1.0, 1.0]);
        assert_eq!(m.bilinear(0.5, 0.5), 0.0);
        assert_eq!(m.bilinear(1.5, 1.5), 3.0);
        assert_eq!(m.bilinear(1.0, 1.0), 1.5);
        assert_eq!(m.bilinear(-10.0, -10.0), 0.0);
        assert_eq!(m.bilinear(10.0, 0.0), 1.0);
    }
}
