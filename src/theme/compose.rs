//! The thematic-texture lookup, in f32: the twin of `theme_class` / `theme_albedo` in
//! `shaders/theme.wgsl`, and the albedo composed at any resolution ([`compose`]).
//!
//! Coordinates p are in level-0 index-map texels (x east, y south). `footprint` is how many
//! index texels one output pixel spans (≤ 1 when magnifying): it picks the index level
//! (nearest, never blended) and the theme texture's level of detail (trilinear within the
//! theme).

use super::{Border, ThemeSet};

/// log2 of a footprint, never below 0.
fn lod(footprint: f32) -> f32 {
    footprint.max(1.0).log2()
}

/// The blend zone's taps: eight directions 45° apart, then the centre (constants, so that
/// both twins use the same bits).
pub const BLEND_TAPS: [[f32; 2]; 9] = [
    [1.0, 0.0],
    [0.707_106_77, 0.707_106_77],
    [0.0, 1.0],
    [-0.707_106_77, 0.707_106_77],
    [-1.0, 0.0],
    [-0.707_106_77, -0.707_106_77],
    [0.0, -1.0],
    [0.707_106_77, -0.707_106_77],
    [0.0, 0.0],
];

/// Per-lookup constants shared by every texel of a frame.
pub struct Lookup<'a> {
    pub set: &'a ThemeSet,
    pub lut: [f32; 256],
    /// The border noise's shift this frame (noise periods, in [0, 1)).
    pub shift: [f32; 2],
}

impl ThemeSet {
    /// The border-noise shift of animation frame `frame` (fractional part taken in f64 so long
    /// animations keep their precision on the GPU).
    pub fn shift(&self, frame: u32) -> [f32; 2] {
        self.drift
            .map(|d| ((frame as f64 * d as f64).rem_euclid(1.0)) as f32)
    }

    /// The lookup constants for animation frame `frame`.
    pub fn lookup(&self, frame: u32) -> Lookup<'_> {
        Lookup {
            set: self,
            lut: super::textures::srgb_table(),
            shift: self.shift(frame),
        }
    }
}

impl Lookup<'_> {
    /// The index level for a footprint.
    pub fn level(&self, footprint: f32) -> usize {
        let top = self.set.index.levels.len() - 1;
        ((lod(footprint) + 0.5).floor() as usize).min(top)
    }

    /// The class at p (level-0 texels, clamped to the map) on index level `level`.
    pub fn class_at(&self, level: usize, p: [f32; 2]) -> u8 {
        let m = &self.set.index.levels[level];
        let scale = (1u32 << level) as f32;
        let col = (p[0] / scale).floor().clamp(0.0, (m.width - 1) as f32) as usize;
        let row = (p[1] / scale).floor().clamp(0.0, (m.height - 1) as f32) as usize;
        m.at(col, row)
    }

    /// The border-perturbed lookup position for a fractal border, else p.
    fn perturbed(&self, border: Border, p: [f32; 2]) -> [f32; 2] {
        match border {
            Border::Fractal { amplitude, scale } => {
                let n = self
                    .set
                    .noise
                    .sample(p[0] / scale + self.shift[0], p[1] / scale + self.shift[1]);
                [p[0] + amplitude * n[0], p[1] + amplitude * n[1]]
            }
            _ => p,
        }
    }

    /// The class shown at p: the border traits of the class at p decide how the lookup is
    /// perturbed (blend zones answer their centre's class).
    pub fn class(&self, p: [f32; 2], footprint: f32) -> u8 {
        let level = self.level(footprint);
        let c0 = self.class_at(level, p);
        let border = self.set.classes[c0 as usize].border;
        self.class_at(level, self.perturbed(border, p))
    }

    /// The texel of class `c`'s theme at p: the texture repeats every `tile` index texels,
    /// displaced by the static in-region noise.
    pub fn theme_texel(&self, c: u8, p: [f32; 2], footprint: f32) -> [f32; 3] {
        let class = &self.set.classes[c as usize];
        let t = class.tiling;
        let n = self
            .set
            .noise
            .sample(p[0] / t.warp_scale + 0.37, p[1] / t.warp_scale + 0.61);
        let s = p[0] / t.tile + t.warp * n[0];
        let u = p[1] / t.tile + t.warp * n[1];
        let tex = &self.set.textures;
        let lod_tex = (footprint * tex.size as f32 / t.tile).max(1.0).log2();
        tex.trilinear(&self.lut, class.theme as usize, lod_tex, s, u)
    }

    /// Linear-RGB albedo at p.
    pub fn albedo(&self, p: [f32; 2], footprint: f32) -> [f32; 3] {
        let level = self.level(footprint);
        let c0 = self.class_at(level, p);
        let border = self.set.classes[c0 as usize].border;
        if let Border::Blend { width } = border {
            // Nine taps: the centre and eight around it at the zone's width.
            let mut sum = [0.0f32; 3];
            for d in BLEND_TAPS {
                let q = [p[0] + width * d[0], p[1] + width * d[1]];
                let rgb = self.theme_texel(self.class_at(level, q), p, footprint);
                sum = [0, 1, 2].map(|i| sum[i] + rgb[i]);
            }
            return sum.map(|v| v / 9.0);
        }
        let c = self.class_at(level, self.perturbed(border, p));
        self.theme_texel(c, p, footprint)
    }
}

/// The albedo (linear RGB, row-major) of the whole map at `width`×`height` pixels, animation
/// frame `frame`.
pub fn compose(set: &ThemeSet, width: usize, height: usize, frame: u32) -> Vec<[f32; 3]> {
    use rayon::prelude::*;
    let lookup = set.lookup(frame);
    let base = &set.index.levels[0];
    let (sx, sy) = (
        base.width as f32 / width as f32,
        base.height as f32 / height as f32,
    );
    let footprint = sx.max(sy);
    let mut out = vec![[0.0f32; 3]; width * height];
    out.par_chunks_mut(width)
        .enumerate()
        .for_each(|(row, line)| {
            for (col, o) in line.iter_mut().enumerate() {
                let p = [(col as f32 + 0.5) * sx, (row as f32 + 0.5) * sy];
                *o = lookup.albedo(p, footprint);
            }
        });
    out
}
