//! Theme textures: one small tileable T×T texture per theme with its mip chain, stored as
//! sRGB-encoded RGBA8 (what a GPU texture of a theme costs), decoded through a 256-entry table
//! that the GPU twin uploads as is, so both decode identically (and encoded by that table's
//! inverse, [`encode_srgb8`]). Filtering happens in linear
//! light and only within one theme (the class lookup picks the theme first).
//!
//! relume generates the bundled themes procedurally ([`Procedural`]) from periodic noise, so
//! they tile without a seam; a user may give PNGs instead (resampled to T by the loader).

use super::noise::{fractal, NoiseSettings};
use serde::{Deserialize, Serialize};

/// The procedural theme textures relume can make.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Procedural {
    Water,
    Sand,
    Grass,
    Forest,
    Rock,
    Snow,
    /// One colour (linear RGB) with a slight grain.
    Flat([f32; 3]),
}

/// All themes' textures with their mip chains, sRGB RGBA8.
#[derive(Clone, Debug, PartialEq)]
pub struct ThemeTextures {
    /// Texels per side of level 0 (a power of two).
    pub size: usize,
    pub levels: usize,
    /// Per theme, levels 0..levels concatenated; themes concatenated.
    pub texels: Vec<[u8; 4]>,
}

/// sRGB byte → linear, the table both twins use.
pub fn srgb_table() -> [f32; 256] {
    std::array::from_fn(|i| {
        let c = i as f64 / 255.0;
        let l = if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        };
        l as f32
    })
}

/// Linear → the sRGB byte whose decoded value ([`srgb_table`]) is nearest: the inverse of
/// the decoding table itself, so a texel decodes to the closest value a byte can hold.
pub fn encode_srgb8(table: &[f32; 256], v: f32) -> u8 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    let i = table.partition_point(|&t| t < v).min(255);
    if i > 0 && (v - table[i - 1]) <= (table[i] - v) {
        (i - 1) as u8
    } else {
        i as u8
    }
}

fn lerp3(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
    let t = t.clamp(0.0, 1.0);
    [0, 1, 2].map(|c| a[c] + (b[c] - a[c]) * t)
}

/// The level-0 texture (linear RGB, row-major T×T) of a procedural theme.
pub fn procedural(kind: Procedural, size: usize, seed: u64) -> Vec<[f32; 3]> {
    let noise = |base: u32, octaves: u32, channel: u64, u: f64, v: f64| {
        let s = NoiseSettings {
            size,
            octaves,
            base_period: base,
            seed,
        };
        fractal(u, v, &s, channel)
    };
    let mut out = Vec::with_capacity(size * size);
    for row in 0..size {
        for col in 0..size {
            let (u, v) = (
                (col as f64 + 0.5) / size as f64,
                (row as f64 + 0.5) / size as f64,
            );
            let rgb = match kind {
                Procedural::Water => {
                    let n = noise(4, 4, 0, u, v) + 0.5 * noise(16, 2, 1, u, v);
                    lerp3([0.015, 0.045, 0.09], [0.04, 0.11, 0.17], 0.5 + 0.6 * n)
                }
                Procedural::Sand => {
                    let n = noise(4, 3, 0, u, v) + 0.6 * noise(32, 2, 1, u, v);
                    lerp3([0.42, 0.35, 0.24], [0.62, 0.54, 0.40], 0.5 + 0.6 * n)
                }
                Procedural::Grass => {
                    let n = noise(4, 5, 0, u, v);
                    lerp3([0.07, 0.15, 0.04], [0.20, 0.28, 0.09], 0.5 + 0.8 * n)
                }
                Procedural::Forest => {
                    // Canopy clumps: thresholded mid-frequency noise over a dark floor.
                    let crowns = noise(8, 3, 0, u, v);
                    let t = ((crowns + 0.1) * 4.0).clamp(0.0, 1.0);
                    lerp3([0.02, 0.05, 0.02], [0.07, 0.15, 0.05], t)
                }
                Procedural::Rock => {
                    let n = noise(4, 5, 0, u, v);
                    let strata = (std::f64::consts::TAU * (v * 6.0 + 0.4 * n)).sin();
                    lerp3(
                        [0.20, 0.19, 0.18],
                        [0.42, 0.40, 0.37],
                        0.5 + 0.3 * strata + 0.4 * n,
                    )
                }
                Procedural::Snow => {
                    let n = noise(4, 4, 0, u, v);
                    lerp3([0.72, 0.76, 0.84], [0.90, 0.91, 0.94], 0.5 + 0.8 * n)
                }
                Procedural::Flat(c) => {
                    let n = noise(8, 3, 0, u, v);
                    c.map(|x| x as f64 * (1.0 + 0.1 * n))
                }
            };
            out.push(rgb.map(|x| x as f32));
        }
    }
    out
}

impl ThemeTextures {
    /// Texels of one theme's whole chain.
    pub fn per_theme(&self) -> usize {
        (0..self.levels).map(|l| (self.size >> l).pow(2)).sum()
    }

    /// Offset of level `l` inside a theme's chain.
    pub fn level_offset(&self, l: usize) -> usize {
        (0..l).map(|k| (self.size >> k).pow(2)).sum()
    }

    /// Build the chains of `themes` (each a linear-RGB T×T level 0; T a power of two ≥ 1):
    /// box-filtered in linear light, then sRGB-encoded.
    pub fn build(size: usize, themes: &[Vec<[f32; 3]>]) -> ThemeTextures {
        assert!(size.is_power_of_two(), "theme textures are 2^k texels wide");
        let levels = size.trailing_zeros() as usize + 1;
        let table = srgb_table();
        let mut texels = Vec::new();
        for base in themes {
            assert_eq!(base.len(), size * size);
            let mut level = base.clone();
            let mut s = size;
            loop {
                texels.extend(level.iter().map(|c| {
                    let [r, g, b] = c.map(|v| encode_srgb8(&table, v));
                    [r, g, b, 255]
                }));
                if s == 1 {
                    break;
                }
                let h = s / 2;
                level = (0..h * h)
                    .map(|i| {
                        let (x, y) = (i % h * 2, i / h * 2);
                        let at = |dx: usize, dy: usize| level[(y + dy) * s + x + dx];
                        [0, 1, 2]
                            .map(|c| (at(0, 0)[c] + at(1, 0)[c] + at(0, 1)[c] + at(1, 1)[c]) * 0.25)
                    })
                    .collect();
                s = h;
            }
        }
        ThemeTextures {
            size,
            levels,
            texels,
        }
    }

    /// Bilinear sample (wrap-around) of theme `t` at level `l`, at (s, t) in repeats: twin of
    /// `theme_bilinear`.
    pub fn bilinear(&self, lut: &[f32; 256], theme: usize, l: usize, s: f32, t: f32) -> [f32; 3] {
        let n = (self.size >> l) as i32;
        let base = theme * self.per_theme() + self.level_offset(l);
        super::noise::wrap_bilinear(n, s, t, |c, r| {
            let p = self.texels[base + (r * n + c) as usize];
            [lut[p[0] as usize], lut[p[1] as usize], lut[p[2] as usize]]
        })
    }

    /// Trilinear sample at level of detail `lod` (log2 texels per pixel): twin of
    /// `theme_trilinear`.
    pub fn trilinear(&self, lut: &[f32; 256], theme: usize, lod: f32, s: f32, t: f32) -> [f32; 3] {
        let top = (self.levels - 1) as f32;
        // NaN (from a degenerate footprint) reads level 0, as the GPU's clamp may.
        let lod = if lod.is_nan() {
            0.0
        } else {
            lod.clamp(0.0, top)
        };
        let l0 = lod.floor();
        let f = lod - l0;
        let a = self.bilinear(lut, theme, l0 as usize, s, t);
        if f == 0.0 || l0 >= top {
            return a;
        }
        let b = self.bilinear(lut, theme, l0 as usize + 1, s, t);
        [0, 1, 2].map(|k| a[k] + (b[k] - a[k]) * f)
    }

    /// Bytes at RGBA8 (4 per texel, mips included).
    pub fn bytes(&self) -> usize {
        self.texels.len() * 4
    }
}
